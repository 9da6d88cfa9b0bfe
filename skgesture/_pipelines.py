"""The paper's pipelines with the paper's numbers as defaults."""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture._augment import SkeletonAugmenter
from skgesture._concat import ConcatFeatures
from skgesture._descriptor._estimator import PoseDescriptor
from skgesture._features import JointFeatures
from skgesture._gesture_pipeline import GesturePipeline
from skgesture._multiscale._classifier import (
    MultiScaleClassifier,
    default_window_network,
)
from skgesture._segmenter import ActivitySegmenter, default_frame_network
from skgesture._taggers._bilstm import BiLSTMTagger
from skgesture._taggers._sequence import SequenceTagger
from skgesture._windows import STEPS_A, STEPS_B, DynamicPoseWindow
from skgesture.datasets._background import BACKGROUND_SEQUENCES, SyntheticBackground

__all__ = [
    "GesturePipeline",
    "make_method_a",
    "make_method_b",
    "make_method_c",
    "make_recommended",
]

# make_recommended's defaults (docs/choosing.md, docs/safety.md)
LOOKAHEAD = 8  # frames of future the tagger reads
TCN_CHANNELS = (48,)  # the TCN's width (docs/benchmarks.md, "Fewer, wider layers")
TCN_LAYERS = 8  # dilated layers a stage (dilations 1 to 128)
TCN_STAGES = 2  # stages, each refining the one before
FEATURES = ("descriptor", "joints", "descriptor+joints")  # make_recommended's
SMOOTHING_MARGIN = 4  # frames each side of a true boundary the smoothing loss spares
MIN_DURATION = 0.5  # runs shorter than this fraction of their class's short gesture
MAX_DURATION = 2.5  # or longer than this multiple of its long gesture are rest
VITERBI_PENALTY = 5.0  # the duration-aware path: nats to enter a gesture
VITERBI_DECISION = "run"  # a gesture's frames decided once it ends (docs/design.md)
VITERBI_LAG = 4  # frames between a rest frame and its decision
MAX_NOVELTY = 1.5  # runs whose poses are this far from their class's are rest
NAMER_WEIGHT = 0.75  # the run namer's share of a run's name (docs/design.md)
NAMER_UNITS = (128,)  # the run namer's GRU: one layer of 128 units a direction
NAMER_STRIDE = 2  # reading every second frame (docs/design.md, "The run namer")
MAX_NAMER_REST = 0.5  # a run the namer calls rest at more than this is rest
# BACKGROUND_SEQUENCES: synthetic negatives made at every fit (from datasets)

# docs/method.md §6.3
WEIGHTS_B = (0.4895, 0.4576, 0.0529)
THRESHOLD_SHORT_B = 0.6014
THRESHOLD_LONG_B = 0.6033


_DOC_COMMON = """
    Parameters
    ----------
    joints : {"paper11", "full20"} or DescriptorJoints, default="paper11"
        Joint set of the :class:`PoseDescriptor`.
    segment : bool, default=True
        Put an :class:`ActivitySegmenter` in front of the classifier. Without
        it every sequence is one period (pre-cut clips).
    memory : None, str or joblib.Memory, default=None
        Cache of the trained networks (see :class:`ActivitySegmenter`), so
        decision parameters can be searched without retraining.
    random_state : int, RandomState instance or None, default=None
        Seeds every network.
    verbose : int, default=0
        0 is silent; 1 shows progress bars (the segmenter's network, the
        classifier's scales and their networks); 2 prints one line per epoch
        of every network.
"""


def _multiscale_pipeline(
    steps, classifier_kwargs, *, joints, segment, memory, random_state, verbose
):
    stages = [("descriptor", PoseDescriptor(joints=joints))]
    if segment:
        stages.append(
            (
                "segmenter",
                ActivitySegmenter(
                    default_frame_network(),
                    memory=memory,
                    random_state=random_state,
                    verbose=verbose,
                ),
            )
        )
    stages += [
        ("windows", DynamicPoseWindow(steps=steps, lazy=True)),
        (
            "classifier",
            MultiScaleClassifier(
                default_window_network(),
                steps=steps,
                memory=memory,
                random_state=random_state,
                verbose=verbose,
                **classifier_kwargs,
            ),
        ),
    ]
    return GesturePipeline(stages)


def make_method_a(
    *, joints="paper11", segment=True, memory=None, random_state=None, verbose=0
):
    """Method A: descriptor, segmenter, single-scale dynamic-pose classifier.

    PoseDescriptor -> ActivitySegmenter -> DynamicPoseWindow(steps=(4,)) ->
    MultiScaleClassifier with thresholds 0.8717 (short periods) and 0.6255
    (long periods), docs/method.md §5.
    {common}
    Returns
    -------
    GesturePipeline
        The unfitted pipeline; ``predict`` gives per-frame labels.

    Examples
    --------
    >>> from skgesture import make_method_a
    >>> [name for name, _ in make_method_a().steps]
    ['descriptor', 'segmenter', 'windows', 'classifier']
    """
    return _multiscale_pipeline(
        STEPS_A,
        {},
        joints=joints,
        segment=segment,
        memory=memory,
        random_state=random_state,
        verbose=verbose,
    )


def make_method_b(
    *, joints="paper11", segment=True, memory=None, random_state=None, verbose=0
):
    """Method B: three time scales (steps 4, 3, 2) with fused scores.

    As :func:`make_method_a` with ``steps=(4, 3, 2)``, fusion weights
    (0.4895, 0.4576, 0.0529) and thresholds 0.6014 / 0.6033, docs/method.md §6.
    {common}
    Returns
    -------
    GesturePipeline
        The unfitted pipeline.

    Examples
    --------
    >>> from skgesture import make_method_b
    >>> make_method_b().named_steps["classifier"].weights
    (0.4895, 0.4576, 0.0529)
    """
    kwargs = {
        "weights": WEIGHTS_B,
        "threshold_short": THRESHOLD_SHORT_B,
        "threshold_long": THRESHOLD_LONG_B,
    }
    return _multiscale_pipeline(
        STEPS_B,
        kwargs,
        joints=joints,
        segment=segment,
        memory=memory,
        random_state=random_state,
        verbose=verbose,
    )


make_method_a.__doc__ = make_method_a.__doc__.format(common=_DOC_COMMON)
make_method_b.__doc__ = make_method_b.__doc__.format(common=_DOC_COMMON)


def make_method_c(
    *,
    joints="paper11",
    memory=None,
    random_state=None,
    verbose=0,
    paper=False,
    device="cpu",
):
    """Method C: descriptor and bidirectional LSTM tagger, no segmentation stage.

    PoseDescriptor -> BiLSTMTagger: every frame gets one of K + 1 classes,
    probabilities are loess-smoothed and gesture runs shorter than 15 frames
    become rest (docs/method.md §7).

    Parameters
    ----------
    joints : {"paper11", "full20"} or DescriptorJoints, default="paper11"
        Joint set of the :class:`PoseDescriptor`.
    memory : None, str or joblib.Memory, default=None
        Cache of the trained network, so ``tagger__smooth_span``,
        ``tagger__min_run`` and ``tagger__overlap`` can be searched without
        retraining.
    random_state : int, RandomState instance or None, default=None
        Seeds the network.
    verbose : int, default=0
        Verbosity of the training (1: one line per epoch).
    paper : bool, default=False
        Use the paper's network (:meth:`BiLSTMTagger.paper`: 1024-1024-512
        units, dropout 0.6, 150 epochs) instead of the CPU-sized default.
    device : str, default="cpu"
        Torch device of the training; ``"cuda"`` is advised with ``paper=True``.

    Returns
    -------
    GesturePipeline
        The unfitted pipeline; ``predict`` gives per-frame labels.

    Examples
    --------
    >>> from skgesture import make_method_c
    >>> pipe = make_method_c(paper=True, device="cuda")
    >>> [name for name, _ in pipe.steps], pipe.named_steps["tagger"].hidden_sizes
    (['descriptor', 'tagger'], (1024, 1024, 512))
    """
    params = {
        "memory": memory,
        "random_state": random_state,
        "verbose": verbose,
        "device": device,
    }
    tagger = BiLSTMTagger.paper(**params) if paper else BiLSTMTagger(**params)
    return GesturePipeline(
        [("descriptor", PoseDescriptor(joints=joints)), ("tagger", tagger)]
    )


def make_recommended(
    *,
    joints="paper11",
    features="descriptor",
    lookahead=LOOKAHEAD,
    background="synthetic",
    background_for="namer",
    memory=None,
    random_state=None,
    verbose=0,
    device="cpu",
):
    """The model we recommend: a temporal convolutional tagger that streams exactly.

    ``PoseDescriptor -> SequenceTagger(architecture="tcn", lookahead=8,
    namer="gru")``: the paper's pose descriptor of every frame, read by a
    two-stage dilated temporal convolutional network (48 channels, 8 layers a
    stage, a smoothing loss that spares 4 frames each side of a true boundary,
    ``tagger__smoothing_margin``; Farha & Gall's MS-TCN) whose convolutions are
    causal and whose output for a frame is read 8 frames later, trained with
    AdamW and a warm-up cosine schedule on augmented 256-frame crops (time
    warp, noise); a small bidirectional GRU (128 units a direction, reading
    every second frame) trained on the gestures and on windows of rest names
    every run once it has ended (the run namer). What it predicts
    offline is what :class:`~skgesture.streaming.StreamingRecognizer` gives
    live, to the frame, so an offline benchmark of it is the live robot's.

    It is chosen by its worst case: of the models that stream exactly, it has
    the best margin over the best practitioner's peer on the worst of the
    benchmark's datasets (PRECOG and UTKinect, leave one subject out, and
    synthetic separated gestures); docs/choosing.md gives the numbers and the
    other variants, among them the best offline model on PRECOG
    (``features="joints", lookahead=None``).

    Parameters
    ----------
    joints : {"paper11", "full20"} or sequence of str, default="paper11"
        Joints of the features: the paper's 11 upper-body joints or all 20
        (better whenever the legs move, e.g. kicks).
    features : {"descriptor", "joints", "descriptor+joints"}, \
default="descriptor"
        ``"descriptor"``: the paper's :class:`PoseDescriptor` (angles and
        distance ratios), with time warp and noise as the only augmentations.
        ``"joints"``: :class:`JointFeatures`, joint positions relative to the
        hip in trunk lengths with their velocities, augmented also by a
        rotation about the vertical axis and a scale; with
        ``lookahead=None`` the best offline model on PRECOG, and worse than
        the descriptor on separated gestures and when streamed.
        ``"descriptor+joints"``: both side by side (:class:`ConcatFeatures`,
        183 + 66 values a frame for the paper's 11 joints), augmented as the
        descriptor; docs/choosing.md gives its scores.
    lookahead : int or None, default=8
        An int ``L``: the model that streams exactly. The TCN's convolutions
        are causal, its output for a frame read ``L`` frames later
        (``tagger__lookahead``), and the features are computed as live: an
        untracked frame takes the last tracked pose (``features__fill="hold"``)
        and the joint features take running statistics
        (``features__statistics="running"``), so that
        :class:`~skgesture.streaming.StreamingRecognizer` gives the offline
        events, ``L`` plus the decoding's look-ahead frames behind. None: the
        TCN reads whole sequences, better offline on PRECOG; live it runs on a
        trailing window and its events differ from offline ones
        (docs/streaming.md, "Exact streaming").
    background : None, "synthetic" or object with ``make(X, y)``, \
default="synthetic"
        Negatives made at every ``fit`` from its training recordings and
        learnt as rest (the pipeline's ``background``), by whom
        ``background_for`` says: ``"synthetic"`` is
        :class:`~skgesture.datasets.SyntheticBackground` (24 sequences of
        random joint motion, reversed gestures, fragments and concatenations,
        seeded by ``random_state``); None trains on the given data alone.
        Recordings of your own ordinary work, added to ``X`` with all-zero
        labels, are the stronger lever (docs/safety.md).
    background_for : {"namer", "model"}, default="namer"
        Who learns ``background`` (the pipeline's ``background_for``).
        ``"namer"``: the run namer alone, whose ``tagger__max_namer_rest``
        rule then rejects the runs that look like the negatives, the network
        being the one fitted without them: 35 % fewer false events on
        everyday motion (11.8 to 7.7 a minute; MSR Action3D's clips 10.9 to
        0.2) for at most 0.008 Jaccard on the gesture datasets (3 seeds;
        docs/safety.md, "Synthetic negatives for the namer"). ``"model"``:
        the network learns them too, which removes about as many false
        events and costs 0.016-0.045 Jaccard.
    memory : None, str or joblib.Memory, default=None
        Cache of the trained network, so that the decoding parameters
        (``tagger__smooth_span``, ``tagger__min_run``, ``tagger__max_gap``,
        ``tagger__min_confidence``, ``tagger__min_duration``,
        ``tagger__max_duration``, ``tagger__max_novelty``,
        ``tagger__viterbi_penalty``, ``tagger__namer_weight``,
        ``tagger__max_namer_rest``) can be
        searched without retraining.
    random_state : int, RandomState instance or None, default=None
        Seeds the network, the crops, the augmentation and the background.
    verbose : int, default=0
        0 silent, 1 a progress bar over epochs, 2 one line per epoch.
    device : str, default="cpu"
        Torch device of the training.

    Returns
    -------
    GesturePipeline
        The unfitted pipeline; ``predict`` gives per-frame labels.

    Notes
    -----
    The decoding was chosen by its worst case over the benchmark's datasets
    (docs/safety.md, "The decoding rules"). The labels are the duration-aware
    Viterbi path (``tagger__viterbi_penalty=5``: entering a gesture costs 5
    nats, a gesture lasts at least 0.7 of its class's short gesture, the 10th
    percentile of the class's lengths in ``fit``), offline as live: a rest
    frame is decided 4 frames after it (``tagger__viterbi_lag``), and the
    frames of a gesture together once it has ended, from the path that has
    read all of it (``tagger__viterbi_decision="run"``; docs/design.md,
    "Duration-aware decoding"). Untracked frames take the last tracked pose
    (``features__fill="hold"``), as they must live. Then a run shorter
    than 0.5 of its class's short gesture (``tagger__min_duration``) or
    longer than 2.5 times its long gesture (``tagger__max_duration``; the
    90th percentile) is rest, and so is a run whose poses are far from the
    training poses of its class (``tagger__max_novelty=1.5``: the median
    distance of its frames to the nearest training frame of the class, in
    units of how far a held-out training sequence's gestures lie; with the
    smoothing margin above, 8 % fewer false events on everyday motion than
    before both, and a higher Jaccard on every benchmark dataset).
    Before those rules, every run is named by the tagger's and the run
    namer's mean probabilities over its frames (``tagger__namer_weight=0.75``,
    the namer's share; docs/design.md, "The run namer"), and a run to which
    the namer, trained on rest too, gives a mean probability of rest above
    0.5 is rest (``tagger__max_namer_rest``; with the synthetic negatives
    that the namer learns, ``background_for="namer"``, 35 % fewer false
    events on everyday motion, at most 0.008 Jaccard; docs/safety.md). A
    confidence floor
    (``tagger__min_confidence``) is left at 0: the floor that suits one
    dataset costs another much (docs/safety.md,
    "Choosing the confidence floor"). The rules judge a run once it has
    ended, so the model still streams exactly.

    Examples
    --------
    >>> from skgesture import make_recommended
    >>> model = make_recommended(joints="full20")
    >>> [name for name, _ in model.steps], model.named_steps["tagger"].lookahead
    (['features', 'tagger'], 8)
    >>> offline = make_recommended(features="joints", lookahead=None)
    >>> type(offline.named_steps["features"]).__name__
    'JointFeatures'
    """
    if features not in FEATURES:
        raise ValueError(
            f"features must be one of {', '.join(map(repr, FEATURES))}, got "
            f"{features!r}"
        )
    live = {} if lookahead is None else {"statistics": "running", "fill": "hold"}
    if features == "joints":
        step = JointFeatures(joints=joints, **live)
        augment = SkeletonAugmenter(
            rotation=20.0, scale=0.15, time_warp=0.2, noise=0.02
        )
    else:
        # The descriptor is built from angles and distances: rotating or
        # scaling its 183/426 values as coordinates would be meaningless (and
        # beside it, a rotated joints' block would disagree with it).
        # Live, an untracked frame is the last tracked one (the future is
        # unknown): offline does the same, so that the stream is exact.
        step = PoseDescriptor(joints=joints, fill=live.get("fill", "linear"))
        augment = SkeletonAugmenter(rotation=0.0, scale=0.0, time_warp=0.2, noise=0.02)
        if features == "descriptor+joints":
            step = ConcatFeatures(
                [("descriptor", step), ("joints", JointFeatures(joints=joints, **live))]
            )
    tagger = SequenceTagger(
        architecture="tcn",
        hidden_sizes=TCN_CHANNELS,
        tcn_layers=TCN_LAYERS,
        tcn_stages=TCN_STAGES,
        dropout=0.3,
        smoothing_weight=0.15,
        smoothing_margin=SMOOTHING_MARGIN,
        crop_length=256,
        batch_size=16,
        steps_per_epoch=20,
        max_epochs=30,
        learning_rate=3e-3,
        augment=augment,
        lookahead=lookahead,
        min_duration=MIN_DURATION,
        max_duration=MAX_DURATION,
        max_novelty=MAX_NOVELTY,
        viterbi_penalty=VITERBI_PENALTY,
        viterbi_decision=VITERBI_DECISION,
        viterbi_lag=VITERBI_LAG,
        namer="gru",
        namer_weight=NAMER_WEIGHT,
        max_namer_rest=MAX_NAMER_REST,
        namer_hidden_sizes=NAMER_UNITS,
        namer_stride=NAMER_STRIDE,
        fit_threads="all",
        memory=memory,
        device=device,
        random_state=random_state,
        verbose=verbose,
    )
    if isinstance(background, str) and background == "synthetic":
        background = SyntheticBackground(
            BACKGROUND_SEQUENCES, random_state=random_state
        )
    elif background is not None and not hasattr(background, "make"):
        raise ValueError(
            f"background must be 'synthetic', None or an object with make(X, y) "
            f"(e.g. skgesture.datasets.SyntheticBackground), got {background!r}"
        )
    return GesturePipeline(
        [("features", step), ("tagger", tagger)],
        background=background,
        background_for=background_for,
    )
