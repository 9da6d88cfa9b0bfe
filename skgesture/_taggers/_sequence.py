"""SequenceTagger: GRU, LSTM or MS-TCN tagger of whole sequences.

The tagger of the recommended model (:func:`~skgesture.make_recommended`).
"""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context, clone
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions

from skgesture._augment import SkeletonAugmenter
from skgesture._nn._modules import (
    RecurrentTaggerModule,
    TemporalConvModule,
)
from skgesture._nn._sequence_net import _CropNet, predict_whole
from skgesture._nn._training import IGNORE_INDEX, torch_threads
from skgesture._taggers._base import (
    _DECODING_CONSTRAINTS,
    _STREAM_CONSTRAINTS,
    _BaseTagger,
    _untracked,
)
from skgesture._taggers._namer import (
    MIN_REST,
    NAMER_HIDDEN,
    NAMER_NEGATIVES,
    NAMER_REST,
    NAMER_TRAINING,
    gesture_windows,
    rest_windows,
    strided,
)
from skgesture.utils import PoseNovelty, check_sequence_labels, check_sequences
from skgesture.utils._fitting import fit_cached, seed_from

__all__ = ["SequenceTagger"]


class SequenceTagger(_BaseTagger):
    """Network labelling every frame of whole sequences (the recommended tagger).

    A bidirectional GRU (or LSTM, or an MS-TCN temporal convolutional network)
    reads each whole sequence and gives every frame one of K + 1 classes (rest
    included). Unlike Method C, which reads 10-frame chunks with a fresh state,
    it sees the whole context of every frame.

    Training draws random ``crop_length``-frame crops of the training
    sequences, perturbs them with ``augment`` (rotation about the vertical
    axis, scaling, time warping, noise), standardises the features with the
    training statistics, and minimises the framewise cross-entropy (plus the
    MS-TCN smoothing loss if ``smoothing_weight > 0``) with AdamW, a
    one-cycle learning-rate schedule and gradient-norm clipping, for
    ``max_epochs`` epochs of ``steps_per_epoch`` batches; with
    ``early_stopping`` whole sequences are held out and the best epoch kept.

    Prediction runs the network over each whole sequence, then decodes the
    probabilities: smoothing of every class track, arg-max, rest gaps of at
    most ``max_gap`` frames between runs of one class filled, gesture runs
    shorter than ``min_run`` set to rest. Decoding never retrains: with
    ``memory`` a search over it trains once per fold.

    Parameters
    ----------
    architecture : {"gru", "lstm", "tcn"}, default="gru"
        Bidirectional GRU, bidirectional LSTM, or MS-TCN.
    hidden_sizes : tuple of int, default=(64, 64)
        Units per direction of each recurrent layer; for ``"tcn"`` the first
        entry is the channel count of every layer.
    dropout : float, default=0.0
        Drop probability between recurrent layers / inside the TCN layers.
    tcn_layers : int, default=8
        Dilated residual layers per MS-TCN stage (dilations 1, 2, 4, ...; a
        stage sees ``2 ** (tcn_layers + 1) - 1`` frames).
    tcn_stages : int, default=2
        Stages of the MS-TCN (ignored by the recurrent architectures).
    lookahead : int or None, default=None
        ``"tcn"`` only. None: every convolution sees both sides, far into the
        future (the network reads whole sequences; live, it runs on a window,
        ``stream_past`` and ``stream_future``, and its events differ from
        offline ones). An int ``L``: causal convolutions whose output for a
        frame is read ``L`` frames later: the probabilities of a frame depend
        on the frames up to ``L`` after it and on no later one, offline as
        live, so the stream gives exactly the offline events (to float
        rounding in the probabilities), ``L`` frames plus the decoding's
        look-ahead behind (docs/streaming.md, "Exact streaming").
    smoothing_weight : float, default=0.0
        Weight of the MS-TCN smoothing loss (0.15 in Farha & Gall 2019).
    smoothing_margin : int, default=0
        Frames on each side of a true boundary of a training crop that the
        smoothing loss leaves out, so that it smooths within gestures and rest
        without holding back their onsets and ends; 0: every frame.
    crop_length : int, default=128
        Frames per training crop.
    batch_size : int, default=32
        Crops per batch.
    steps_per_epoch : int, default=20
        Batches per epoch.
    max_epochs : int, default=15
        Epochs; the one-cycle schedule spans ``max_epochs * steps_per_epoch``
        steps.
    learning_rate : float, default=3e-3
        Peak learning rate of the one-cycle schedule.
    weight_decay : float, default=1e-4
        AdamW weight decay.
    clip_norm : float or None, default=1.0
        Largest gradient norm; None disables clipping.
    class_weight : None, "balanced" or float, default=None
        Cross-entropy weight per class: none, inverse class frequency
        (``"balanced"``), or inverse frequency raised to this power (0.5 is a
        milder balance).
    augment : SkeletonAugmenter or None, default=None
        Augmentation of the training crops (needs xyz-triple features such as
        :class:`JointFeatures`'s when it rotates or scales).
    standardize : bool, default=True
        Z-score every feature with the training mean and standard deviation.
    early_stopping : bool, default=False
        Hold out ``validation_fraction`` of the training sequences, stop after
        ``n_iter_no_change`` epochs without a lower validation loss, and keep
        the best epoch's weights.
    validation_fraction : float, default=0.15
        Share of the sequences held out with ``early_stopping``.
    n_iter_no_change : int, default=5
        Patience of the early stopping, in epochs.
    smooth_span : int or float, default=1
        Window of the probability smoothing, in frames (1: none).
    smoothing : {"loess", "mean", "none"}, default="mean"
        Smoothing method.
    min_run : int, default=1
        Shortest gesture run kept, in frames.
    max_gap : int, default=0
        Longest rest gap filled between two runs of one class.
    min_confidence : float, default=0.0
        Gesture runs whose mean raw probability of their class (the
        confidence of ``predict_segments``) is lower become rest; in [0, 1].
    min_duration : float, default=0.0
        Gesture runs shorter than this fraction of their class's short
        gesture (``class_lengths_``: the 10th percentile of its run lengths
        in ``fit``) become rest. Everyday motion that the network takes for a
        gesture is mostly briefer than the gesture.
    max_duration : float or None, default=None
        Gesture runs longer than this multiple of their class's long gesture
        (``class_long_lengths_``: the 90th percentile of its run lengths in
        ``fit``) become rest: a "gesture" that goes on for several times its
        usual length is walking, carrying or another activity. None: no
        limit.
    max_novelty : float or None, default=None
        Gesture runs whose poses are far from the training poses of their
        class become rest: the median, over the run, of each frame's
        distance to the nearest training frame of the class
        (``novelty_``, fitted in ``fit`` from the features), in units of
        the distance at which the class's training runs lie from the other
        training sequences (its 95th percentile). A person walking, sitting
        down or picking something up passes through poses no gesture has.
        None: no limit (docs/safety.md, "The decoding rules").
    viterbi_penalty : float or None, default=None
        None: the labels are the arg-max of every frame. A float: they are
        the duration-aware Viterbi path (a gesture lasts at least
        ``viterbi_duration`` of its class's short gesture, entering one costs
        this many nats of log probability), decided ``viterbi_lag`` frames
        after each frame, offline as live; one doubtful frame then neither
        splits a gesture nor starts a brief false one (docs/design.md,
        "Duration-aware decoding").
    viterbi_duration : float, default=0.7
        Shortest run of the path, as a fraction of ``class_lengths_``.
    viterbi_lag : int, default=6
        Frames between a frame and the path's decision on it (added to the
        stream's delay).
    viterbi_decision : {"frame", "run"}, default="frame"
        When the path decides a frame (with ``viterbi_penalty``).
        ``"frame"``: ``viterbi_lag`` frames after it. ``"run"``: a frame the
        path reads as rest then, but the frames of a gesture together, once
        the path reads a frame after them as rest, from the best path of that
        moment, which has read the whole gesture: its class no longer changes
        midway because its first frames looked like another gesture. A
        gesture's event waits for its end either way, so the stream's delay
        is the same (docs/design.md, "Duration-aware decoding").
    namer : {"gru"} or None, default=None
        ``"gru"``: also train a run namer, a bidirectional GRU
        (``namer_hidden_sizes``, reading every ``namer_stride``-th frame) on
        the training gestures (each gesture and
        copies of it with jittered ends) and on windows of rest (one for
        every four gesture windows, from the rest of the training sequences
        and of any background recording; see ``max_namer_rest``), for half
        the tagger's epochs, in batches of 32 windows of at most 64 frames
        read as the namer reads a run (the padding packed away). It names
        every gesture run once it has ended, from all of its frames (see
        ``namer_weight``). A network with a bounded look-ahead names the
        first frames of a gesture before its end is seen; the namer reads the
        end, and the run rules judge a run only once it has ended, so the
        stream stays exact (a gesture followed at once by another is emitted
        when the second ends). About 12 s more per fit of the recommended
        model on 2 cores (docs/design.md, "The run namer"). None: no namer.
    namer_weight : float, default=0.75
        Decision parameter of the namer: a run is named by the gesture class
        with the highest ``(1 - namer_weight) * log(the tagger's mean
        probability over the run) + namer_weight * log(the namer's)``; two
        touching runs named alike are one gesture. 0: the runs keep the
        path's labels (as without a namer); in [0, 1].
    max_namer_rest : float or None, default=None
        Decision parameter of the namer: a gesture run to which the namer
        gives a mean probability of rest above ``max_namer_rest`` becomes
        rest (motion unlike every gesture, read from all of its frames); in
        (0, 1]. None: the namer's rest is not read. Needs ``namer``.
    namer_hidden_sizes : tuple of int, default=(64,)
        Units per direction of each of the namer's GRU layers (the
        recommended model's namer has one layer of 128). Needs ``namer``.
    namer_stride : int, default=1
        The namer reads every ``namer_stride``-th frame of a gesture: each
        training window is thinned from a random first frame (an
        augmentation), and a run is read from its first frame (frames ``0,
        stride, 2 * stride, ...``), offline as live. At 30 frames a second,
        consecutive frames are nearly alike: the recommended model's 2
        halves the namer's training and prediction time at no measured
        cost, which pays for a namer twice as wide (docs/design.md, "The run
        namer"). Needs ``namer``.
    stream_past : int, default=32
        Streaming only (:class:`~skgesture.streaming.StreamingRecognizer`):
        frames before a frame that a network reading a window (the TCN, or
        any other) sees; a recurrent network carries its forward state from
        the start of the stream instead (docs/streaming.md, "The recommended
        model").
    stream_future : int, default=8
        Streaming only: frames after a frame that the network sees before
        its probabilities are computed; the stage's delay is ``stream_future``
        plus the smoothing's half span plus ``max_gap`` plus 1.
    memory : None, str or joblib.Memory, default=None
        Caches the trained network keyed on the training data and the network
        and training parameters only.
    device : str, default="cpu"
        Torch device of the training; a fitted tagger predicts on the CPU of a
        machine without CUDA.
    n_threads : int or None, default=1
        Torch intra-op threads while predicting, and while fitting unless
        ``fit_threads`` says otherwise, and numpy's BLAS threads while
        decoding (both restored afterwards); None keeps their settings.
    fit_threads : int, "all" or None, default=None
        Torch intra-op threads while fitting: a number, every core of the
        machine (``"all"``; training is the one place where several threads
        pay: about 1.5 times faster on 2 cores for the recommended model), or
        ``n_threads`` (None). Use 1 when fits run in parallel processes
        (``GridSearchCV(n_jobs=...)``). It never changes the cache key.
    random_state : int, RandomState instance or None, default=None
        Seeds the initialisation, the crops, the augmentation, the dropout and
        the validation split; an int gives identical results on the CPU.
    verbose : int, default=0
        0 silent, 1 a progress bar over epochs, 2 one line per epoch.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Labels seen in ``fit``, rest (0) first.
    class_lengths_ : ndarray of shape (n_classes,)
        The 10th percentile of every class's run lengths in ``fit``, in
        frames (0 for rest), the unit of ``min_duration``.
    class_long_lengths_ : ndarray of shape (n_classes,)
        The 90th percentile of every class's run lengths in ``fit``, in
        frames (0 for rest), the unit of ``max_duration``.
    novelty_ : PoseNovelty
        The training frames of every class (a bank of at most 256 of them,
        standardised, on 24 principal components) and the unit of every
        class's distance, read by ``max_novelty``.
    net_ : skorch.NeuralNet
        The trained network (``net_.history`` holds the losses).
    namer_ : skorch.NeuralNet
        With ``namer``: the trained run namer.
    namer_mean_, namer_scale_ : ndarray of shape (n_features,)
        With ``namer``: the standardisation of the namer's inputs (the
        statistics of the frames of its training windows).
    namer_rest_ : int
        With ``namer``: the rest windows the namer was trained on (0 when
        the training data had no rest).
    namer_stride_ : int
        With ``namer``: the ``namer_stride`` the namer was trained with, the
        one its decoding reads (changing ``namer_stride`` needs a refit).
    mean_ : ndarray of shape (n_features,)
        Training mean of every feature.
    scale_ : ndarray of shape (n_features,)
        Training standard deviation of every feature.
    n_features_in_ : int
        Number of features per frame.
    frame_shape_in_ : tuple of int
        Shape of one input frame, ``(n_features_in_,)``.

    See Also
    --------
    make_recommended : The pipeline built around this tagger.
    BiLSTMTagger : Method C, the paper's chunked BiLSTM.
    VotingTagger : Soft voting over several taggers.

    Notes
    -----
    Frames of an input ``numpy.ma.MaskedArray`` that are masked (untracked
    skeletons) are left out of the loss in ``fit`` and are rest at
    prediction. A sequence of any length >= 1 can be predicted.

    Background recordings (a few minutes of ordinary work, no command in it)
    are training sequences whose labels are all 0: add them to ``X`` and
    ``y`` and the network learns that such motion is rest. Crops are drawn
    from a uniformly chosen sequence, so each sequence, background or not,
    gets the same share of them whatever its length: cut a long background
    recording into pieces of about the length of the other sequences to give
    it its weight. :func:`~skgesture.datasets.make_background` makes
    synthetic ones from the training recordings. A fit whose every label is
    0 is an error.

    References
    ----------
    .. [1] Farha & Gall, "MS-TCN: Multi-Stage Temporal Convolutional Network
       for Action Segmentation", CVPR 2019.

    Examples
    --------
    >>> from skgesture import JointFeatures, SequenceTagger
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> F = JointFeatures().fit_transform([X])
    >>> tagger = SequenceTagger(hidden_sizes=(16,), max_epochs=2, random_state=0)
    >>> tagger = tagger.fit(F, [y])
    >>> tagger.classes_.tolist()
    [0, 1, 2, 3]
    >>> tagger.predict(F)[0].shape == y.shape
    True
    """

    # namer_only is requested by default, so a router hands it on
    # (GesturePipeline(background_for="namer") with metadata routing on)
    __metadata_request__fit = {"namer_only": True}

    _parameter_constraints: dict = {
        "architecture": [StrOptions({"gru", "lstm", "tcn"})],
        "hidden_sizes": [tuple, list],
        "dropout": [Interval(Real, 0, 1, closed="left")],
        "tcn_layers": [Interval(Integral, 1, None, closed="left")],
        "tcn_stages": [Interval(Integral, 1, None, closed="left")],
        "smoothing_weight": [Interval(Real, 0, None, closed="left")],
        "smoothing_margin": [Interval(Integral, 0, None, closed="left")],
        "crop_length": [Interval(Integral, 2, None, closed="left")],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "steps_per_epoch": [Interval(Integral, 1, None, closed="left")],
        "max_epochs": [Interval(Integral, 1, None, closed="left")],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
        "weight_decay": [Interval(Real, 0, None, closed="left")],
        "clip_norm": [Interval(Real, 0, None, closed="neither"), None],
        "class_weight": [
            StrOptions({"balanced"}),
            Interval(Real, 0, None, closed="left"),
            None,
        ],
        "augment": [SkeletonAugmenter, None],
        "max_novelty": [None, Interval(Real, 0, None, closed="neither")],
        "standardize": ["boolean"],
        "early_stopping": ["boolean"],
        "validation_fraction": [Interval(Real, 0, 1, closed="neither")],
        "n_iter_no_change": [Interval(Integral, 1, None, closed="left")],
        "lookahead": [Interval(Integral, 0, None, closed="left"), None],
        "namer": [StrOptions({"gru"}), None],
        "namer_weight": [Interval(Real, 0, 1, closed="both")],
        "max_namer_rest": [Interval(Real, 0, 1, closed="right"), None],
        "namer_hidden_sizes": [tuple, list],
        "namer_stride": [Interval(Integral, 1, None, closed="left")],
        **_DECODING_CONSTRAINTS,
        **_STREAM_CONSTRAINTS,
        "memory": [None, str, HasMethods(["cache"])],
        "device": [str],
        "n_threads": [Interval(Integral, 1, None, closed="left"), None],
        "fit_threads": [
            Interval(Integral, 1, None, closed="left"),
            StrOptions({"all"}),
            None,
        ],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        *,
        architecture="gru",
        hidden_sizes=(64, 64),
        dropout=0.0,
        tcn_layers=8,
        tcn_stages=2,
        lookahead=None,
        smoothing_weight=0.0,
        smoothing_margin=0,
        crop_length=128,
        batch_size=32,
        steps_per_epoch=20,
        max_epochs=15,
        learning_rate=3e-3,
        weight_decay=1e-4,
        clip_norm=1.0,
        class_weight=None,
        augment=None,
        standardize=True,
        early_stopping=False,
        validation_fraction=0.15,
        n_iter_no_change=5,
        smooth_span=1,
        smoothing="mean",
        min_run=1,
        max_gap=0,
        min_confidence=0.0,
        min_duration=0.0,
        max_duration=None,
        max_novelty=None,
        viterbi_penalty=None,
        viterbi_duration=0.7,
        viterbi_lag=6,
        viterbi_decision="frame",
        namer=None,
        namer_weight=0.75,
        max_namer_rest=None,
        namer_hidden_sizes=NAMER_HIDDEN,
        namer_stride=1,
        stream_past=32,
        stream_future=8,
        memory=None,
        device="cpu",
        n_threads=1,
        fit_threads=None,
        random_state=None,
        verbose=0,
    ):
        self.architecture = architecture
        self.hidden_sizes = hidden_sizes
        self.dropout = dropout
        self.tcn_layers = tcn_layers
        self.tcn_stages = tcn_stages
        self.lookahead = lookahead
        self.smoothing_weight = smoothing_weight
        self.smoothing_margin = smoothing_margin
        self.crop_length = crop_length
        self.batch_size = batch_size
        self.steps_per_epoch = steps_per_epoch
        self.max_epochs = max_epochs
        self.learning_rate = learning_rate
        self.weight_decay = weight_decay
        self.clip_norm = clip_norm
        self.class_weight = class_weight
        self.augment = augment
        self.standardize = standardize
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.smooth_span = smooth_span
        self.smoothing = smoothing
        self.min_run = min_run
        self.max_gap = max_gap
        self.min_confidence = min_confidence
        self.min_duration = min_duration
        self.max_duration = max_duration
        self.max_novelty = max_novelty
        self.viterbi_penalty = viterbi_penalty
        self.viterbi_duration = viterbi_duration
        self.viterbi_lag = viterbi_lag
        self.viterbi_decision = viterbi_decision
        self.namer = namer
        self.namer_weight = namer_weight
        self.max_namer_rest = max_namer_rest
        self.namer_hidden_sizes = namer_hidden_sizes
        self.namer_stride = namer_stride
        self.stream_past = stream_past
        self.stream_future = stream_future
        self.memory = memory
        self.device = device
        self.n_threads = n_threads
        self.fit_threads = fit_threads
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y, namer_only=None):
        """Train the network on random crops of the sequences.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features (e.g. from :class:`JointFeatures`).
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels, 0 = rest, 1..K gesture classes; both rest and
            gesture frames must occur. A sequence whose labels are all 0 is a
            background recording (see Notes).
        namer_only : array-like of bool of shape (n_sequences,) or None, \
default=None
            Background sequences (all labels 0) that the run namer alone
            learns, as rest, and the network does not: the
            ``GesturePipeline(background_for="namer")`` route of synthetic
            negatives (see Notes). Needs ``namer``. None: every sequence
            trains both.

        Returns
        -------
        self : SequenceTagger
            The fitted tagger.
        """
        for name in ("hidden_sizes", "namer_hidden_sizes"):
            hidden = getattr(self, name)
            if len(hidden) == 0 or not all(
                isinstance(h, Integral) and not isinstance(h, bool) and h >= 1
                for h in hidden
            ):
                raise ValueError(
                    f"{name} must be a non-empty tuple of positive ints, got {hidden!r}"
                )
        if self.lookahead is not None and self.architecture != "tcn":
            raise ValueError(
                f"lookahead={self.lookahead} bounds the look-ahead of a temporal "
                f"convolutional network: use architecture='tcn' (a bidirectional "
                f"{self.architecture.upper()} reads to the end of the sequence), or "
                f"lookahead=None"
            )
        if self.max_namer_rest is not None and self.namer is None:
            raise ValueError(
                f"max_namer_rest={self.max_namer_rest} reads the run namer's rest: "
                f"set namer='gru', or max_namer_rest=None"
            )
        X, y, negatives = self._split_namer_only(X, y, namer_only)
        X, y_idx, classes = self._validate_fit(X, y)
        self.novelty_ = PoseNovelty().fit(
            X,
            [classes[np.maximum(v, 0)] for v in y_idx],
            classes,
            tracked=[v != IGNORE_INDEX for v in y_idx],
        )
        self._class_weight = _class_weights(self.class_weight, y_idx, len(classes))
        X = [x.astype(np.float32) for x in X]
        self._fit_network(X, y_idx, classes)
        for name in (
            "namer_",
            "namer_mean_",
            "namer_scale_",
            "namer_rest_",
            "namer_stride_",
        ):
            self.__dict__.pop(name, None)  # a refit without a namer
        if self.namer is not None:
            self._fit_namer(X, y_idx, classes, negatives)
        return self

    def _split_namer_only(self, X, y, namer_only):
        """``(X, y, negatives)``: the sequences that train the network, and
        ``(rows, labels)`` of the ``namer_only`` ones (float32 rows; labels 0,
        ``IGNORE_INDEX`` on untracked rows; an empty list without them),
        after checking every sequence as ``fit`` checks them."""
        if namer_only is None:
            return X, y, []
        if self.namer is None:
            raise ValueError(
                "namer_only sequences are learnt by the run namer alone: set "
                "namer='gru', or give them to fit as background (all-rest "
                "sequences without namer_only)"
            )
        data = check_sequences(X, ndim=2, estimator=self, reset=True)
        labels = check_sequence_labels(y, data)
        flags = np.asarray(namer_only)
        if flags.shape != (len(data),) or flags.dtype != bool:
            raise ValueError(
                f"namer_only must be a boolean array of shape ({len(data)},), "
                f"one flag per sequence, got {flags.dtype} of shape {flags.shape}"
            )
        if flags.all():
            raise ValueError(
                f"namer_only flags all {len(flags)} sequences: the network needs "
                f"recordings of the gestures that are not namer_only"
            )
        for i in np.flatnonzero(flags).tolist():
            if labels[i].any():
                frame = int(np.flatnonzero(labels[i])[0])
                raise ValueError(
                    f"namer_only sequence X[{i}] has gesture label "
                    f"{labels[i][frame]} at frame {frame}: the namer learns these "
                    f"sequences as rest, so their labels must all be 0"
                )
        negatives = [  # (rows, labels): untracked rows IGNORE_INDEX, others rest
            (x.astype(np.float32), np.where(u, IGNORE_INDEX, 0))
            for x, u, flag in zip(data, _untracked(X, data), flags)
            if flag
        ]
        keep = np.flatnonzero(~flags).tolist()
        return [X[i] for i in keep], [y[i] for i in keep], negatives

    def _fit_namer(self, X, y_idx, classes, negatives=()):
        """Train the run namer on the training gestures (``namer_``,
        ``namer_mean_``, ``namer_scale_``), cached by ``memory`` as the
        tagger's network is; ``negatives`` (``(rows, labels)`` pairs of
        :meth:`_split_namer_only`) give it rest windows of their own
        (``NAMER_NEGATIVES`` per gesture window)."""
        params = {**self._training_params(), **NAMER_TRAINING}
        params["max_epochs"] = max(1, self.max_epochs // 2)
        params["steps_per_epoch"] = self.steps_per_epoch
        params["early_stopping"] = False  # the namer's schedule is fixed
        seed = seed_from(params["random_state"])
        windows, labels = gesture_windows(X, y_idx, seed)
        lengths = [len(w) for w in windows]  # the rest windows' lengths
        rest, rest_labels = rest_windows(
            X, y_idx, lengths, int(round(NAMER_REST * len(windows))), seed + 1
        )
        if negatives:
            more, more_labels = rest_windows(
                *zip(*negatives),
                lengths,
                int(round(NAMER_NEGATIVES * len(windows))),
                seed + 2,
            )
            rest, rest_labels = rest + more, rest_labels + more_labels
        stride = int(self.namer_stride)
        windows, labels = strided(windows, labels, stride, seed + 3)
        rest, rest_labels = strided(rest, rest_labels, stride, seed + 4)
        if not rest and self.max_namer_rest is not None:
            warnings.warn(
                f"max_namer_rest={self.max_namer_rest} reads the run namer's rest, "
                f"but the training sequences have no run of rest of at least "
                f"{MIN_REST} frames: the namer learns no rest and the rule will "
                f"remove no run. Add recordings of rest or background to fit, or "
                f"set max_namer_rest=None",
                UserWarning,
                stacklevel=3,
            )
        network = _CropNet(
            n_classes=len(classes),
            architecture=self.namer,
            hidden_sizes=tuple(int(h) for h in self.namer_hidden_sizes),
            augmenter=None if self.augment is None else clone(self.augment),
            standardize=True,
            **params,
        )
        with torch_threads(self._fit_threads()):
            fitted = fit_cached(
                self.memory, network, windows + rest, labels + rest_labels
            )
        self.namer_ = fitted.net_
        self.namer_rest_ = len(rest)
        self.namer_stride_ = stride
        self.namer_mean_ = fitted.mean_
        self.namer_scale_ = fitted.scale_

    def _network(self, n_classes):
        return _CropNet(
            n_classes=n_classes,
            architecture=self.architecture,
            hidden_sizes=tuple(int(h) for h in self.hidden_sizes),
            dropout=float(self.dropout),
            tcn_layers=self.tcn_layers,
            tcn_stages=self.tcn_stages,
            lookahead=self.lookahead,
            smoothing_weight=self.smoothing_weight,
            smoothing_margin=self.smoothing_margin,
            crop_length=self.crop_length,
            steps_per_epoch=self.steps_per_epoch,
            clip_norm=self.clip_norm,
            class_weight=self._class_weight,
            augmenter=None if self.augment is None else clone(self.augment),
            standardize=self.standardize,
            **self._training_params(),
        )

    def _adopt(self, fitted):
        self.net_ = fitted.net_
        self.mean_ = fitted.mean_
        self.scale_ = fitted.scale_

    def _raw_proba(self, X):
        return predict_whole(
            self.net_.module_, X, self.mean_, self.scale_, len(self.classes_)
        )

    def _stream_future(self):
        """``lookahead`` for a bounded TCN (its probabilities are final then),
        else ``stream_future``."""
        if hasattr(self, "net_"):
            if _bounded(self.net_.module_):
                return int(self.net_.module_.lookahead)
        elif getattr(self, "lookahead", None) is not None:
            return int(self.lookahead)
        return super()._stream_future()

    def _stream_scorer(self, past):
        """The recurrent network with its forward states carried along the
        stream, else the network on a window of ``past`` frames (the MS-TCN
        in numpy: :class:`~skgesture._nn._fast.TemporalConvProba`)."""
        from skgesture._nn._fast import (
            CausalConvScorer,
            RecurrentScorer,
            TemporalConvProba,
        )
        from skgesture._taggers._stream import WindowScorer

        module = self.net_.module_
        on_cpu = next(module.parameters()).device.type == "cpu"
        if _bounded(module):
            return CausalConvScorer(module, self.mean_, self.scale_)
        if type(module) is RecurrentTaggerModule and on_cpu:
            return RecurrentScorer(module, self.mean_, self.scale_)
        if type(module) is TemporalConvModule and on_cpu:
            proba = TemporalConvProba(module, self.mean_, self.scale_)
            return WindowScorer(proba, past)
        n_classes = len(self.classes_)

        def proba(rows):
            return predict_whole(module, [rows], self.mean_, self.scale_, n_classes)[0]

        return WindowScorer(proba, past)


def _bounded(module):
    """Whether ``module`` is a TCN with a bounded look-ahead (it streams exactly)."""
    return (
        type(module) is TemporalConvModule
        and getattr(module, "lookahead", None) is not None
    )


def _class_weights(class_weight, y_idx, n_classes):
    """Per-class cross-entropy weights (a list, for a stable cache key)."""
    if class_weight is None:
        return None
    labels = np.concatenate(y_idx)
    counts = np.bincount(labels[labels >= 0], minlength=n_classes).astype(float)
    balanced = counts.sum() / (n_classes * np.maximum(counts, 1.0))
    power = 1.0 if class_weight == "balanced" else float(class_weight)
    return [float(w) for w in balanced**power]
