"""BiLSTMTagger: framewise bidirectional LSTM tagger of every frame (Method C).

What is Method C's own lives here: the paper's training windows (the sampler),
its SGD optimiser and step schedule, and its chunked inference. The rest is
shared with the other taggers: the network is a
:class:`~skgesture._nn._modules.RecurrentTaggerModule`, the training loop is
:class:`~skgesture._nn._training.FramewiseNetwork`'s, and input checks, untracked
rows and the decoding come from :class:`~skgesture._taggers._base._BaseTagger`.
"""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
import torch
from sklearn.base import _fit_context
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions
from sklearn.utils.validation import check_is_fitted
from skorch.callbacks import LRScheduler

from skgesture._nn._modules import (
    CPU_DROPOUT,
    CPU_HIDDEN_SIZES,
    PAPER_MODULE,
    RecurrentTaggerModule,
    frame_probabilities,
)
from skgesture._nn._training import (
    IGNORE_INDEX,
    FramewiseLoss,
    FramewiseNetwork,
    SequenceSplit,
)
from skgesture._stream import DEFAULT_MAX_PERIOD
from skgesture._taggers._base import _BaseTagger, _rest_where
from skgesture._taggers._decoding import smooth_proba
from skgesture._taggers._stream import TaggerStream
from skgesture.utils._fitting import seed_from
from skgesture.utils._segments import _chunks
from skgesture.utils._validation import SequenceOf

__all__ = ["BiLSTMTagger", "sample_windows"]

# docs/method.md §7.1: training windows
WINDOW = 10
REST_STEP = 5
GESTURE_STEP = 2
# docs/method.md §7.2: network, a RecurrentTaggerModule of BiLSTMs with LeakyReLU
# (0.01) and dropout between them, initialised as MATLAB does
PAPER_HIDDEN_SIZES = (1024, 1024, 512)
PAPER_DROPOUT = 0.6
# docs/method.md §7.3: optimiser and schedule
LEARNING_RATE = 0.01
MOMENTUM = 0.9
WEIGHT_DECAY = 1e-4
LR_DROP_FACTOR = 0.85
LR_DROP_PERIOD = 10
BATCH_SIZE = 128
PAPER_MAX_EPOCHS = 150
# docs/method.md §7.4 and decision D12: decision rules
MIN_RUN = 15
SMOOTH_SPAN = 15
# CPU-sized default network (measured in the BiLSTMTagger Notes)
CPU_MAX_EPOCHS = 40

VALIDATION_FRACTION = 0.1
N_ITER_NO_CHANGE = 10
PREDICT_BATCH = 4096  # chunks per forward pass at prediction


def sample_windows(y, window=WINDOW, rest_step=REST_STEP, gesture_step=GESTURE_STEP):
    """Start frames of the training windows of one sequence (docs/method.md §7.1).

    The first window starts at frame 0. After the window starting at ``t``, the
    next one starts at ``t + rest_step`` if all its ``window`` frames are rest
    (label 0), else at ``t + gesture_step``; windows that would run past the end
    are not taken. A sequence shorter than ``window`` gives the single start 0
    (one shorter window).

    Parameters
    ----------
    y : array-like of shape (n_frames,)
        Per-frame labels of the sequence, 0 = rest.
    window : int, default=10
        Window length in frames.
    rest_step : int, default=5
        Step after an all-rest window.
    gesture_step : int, default=2
        Step after a window holding at least one gesture frame.

    Returns
    -------
    ndarray of int64 of shape (n_windows,)
        Start frames, increasing.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._bilstm import sample_windows
    >>> y = np.r_[np.zeros(20, int), np.ones(10, int), np.zeros(20, int)]
    >>> sample_windows(y).tolist()
    [0, 5, 10, 15, 17, 19, 21, 23, 25, 27, 29, 31, 36]
    """
    y = np.asarray(y)
    n = len(y)
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    if n < window:
        return np.zeros(1, dtype=np.int64)
    gesture = np.concatenate(([0], np.cumsum(y != 0)))
    starts, t = [], 0
    while t + window <= n:
        starts.append(t)
        t += gesture_step if gesture[t + window] > gesture[t] else rest_step
    return np.asarray(starts, dtype=np.int64)


def _training_windows(X, y, window, rest_step, gesture_step):
    """Stacked windows, their per-frame targets and the sequence of each window.

    A sequence shorter than ``window`` gives one window padded on the right with
    zero frames whose targets are ``IGNORE_INDEX`` (MATLAB pads with 0 on the
    right, docs/method.md §7.3; the loss skips the padding).
    """
    n_features = X[0].shape[1]
    Xw, yw, seq = [], [], []
    for i, (x, lab) in enumerate(zip(X, y)):
        starts = sample_windows(lab, window, rest_step, gesture_step)
        if len(x) < window:
            xs = np.zeros((1, window, n_features), dtype=np.float32)
            ys = np.full((1, window), IGNORE_INDEX, dtype=np.int64)
            xs[0, : len(x)] = x
            ys[0, : len(x)] = lab
        else:
            idx = starts[:, None] + np.arange(window)
            xs, ys = x[idx].astype(np.float32), lab[idx].astype(np.int64)
        Xw.append(xs)
        yw.append(ys)
        seq.append(np.full(len(xs), i, dtype=np.int64))
    return np.concatenate(Xw), np.concatenate(yw), np.concatenate(seq)


def _predict_chunks(module, X, window, overlap, n_classes):
    """Per-frame softmax probabilities of ``module`` on chunks of every sequence.

    Each chunk is run with a fresh LSTM state; chunks of equal length are batched
    together. Frames covered by several chunks (``overlap=True``) average them.
    """
    module.eval()
    groups = {}
    for i, x in enumerate(X):
        for s, e in _chunks(len(x), window, overlap):
            groups.setdefault(e - s, []).append((i, s, e))
    sums = [np.zeros((len(x), n_classes)) for x in X]
    counts = [np.zeros((len(x), 1)) for x in X]
    for items in groups.values():
        for b in range(0, len(items), PREDICT_BATCH):
            batch = items[b : b + PREDICT_BATCH]
            xb = np.stack([X[i][s:e] for i, s, e in batch]).astype(np.float32)
            for (i, s, e), p in zip(batch, frame_probabilities(module, xb)):
                sums[i][s:e] += p
                counts[i][s:e] += 1
    return [s / c for s, c in zip(sums, counts)]


class _StepCrossEntropy(FramewiseLoss):
    """Method C's loss as saved before it became a
    :class:`~skgesture._nn._training.FramewiseLoss`; kept so that those files
    load."""

    def __setstate__(self, state):
        super().__setstate__(state)
        self._buffers.setdefault("weight", None)


class _BiLSTMNet(FramewiseNetwork):
    """The trainable part of :class:`BiLSTMTagger`, cached by ``fit_cached``.

    Its parameters are the network and training parameters only, so decision
    parameters of the tagger never change the cache key. ``fit`` takes the
    validated sequences and the labels encoded as class indices, and sets
    ``net_`` (the trained skorch ``NeuralNet``) and ``n_windows_``. The
    training loop is :class:`FramewiseNetwork`'s; the sampler gives the
    paper's windows (docs/method.md §7.1), the optimiser is SGD with momentum
    and a step schedule (§7.3).
    """

    _epoch_lines_from = 1  # verbose >= 1 prints one line per epoch

    def __init__(
        self,
        *,
        n_classes=2,
        hidden_sizes=CPU_HIDDEN_SIZES,
        dropout=CPU_DROPOUT,
        window=WINDOW,
        rest_step=REST_STEP,
        gesture_step=GESTURE_STEP,
        max_epochs=CPU_MAX_EPOCHS,
        batch_size=BATCH_SIZE,
        learning_rate=LEARNING_RATE,
        momentum=MOMENTUM,
        weight_decay=WEIGHT_DECAY,
        lr_drop_factor=LR_DROP_FACTOR,
        lr_drop_period=LR_DROP_PERIOD,
        time_reduction="sum",
        early_stopping=False,
        validation_fraction=VALIDATION_FRACTION,
        n_iter_no_change=N_ITER_NO_CHANGE,
        device="cpu",
        random_state=None,
        verbose=0,
    ):
        self.n_classes = n_classes
        self.hidden_sizes = hidden_sizes
        self.dropout = dropout
        self.window = window
        self.rest_step = rest_step
        self.gesture_step = gesture_step
        self.max_epochs = max_epochs
        self.batch_size = batch_size
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.weight_decay = weight_decay
        self.lr_drop_factor = lr_drop_factor
        self.lr_drop_period = lr_drop_period
        self.time_reduction = time_reduction
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.device = device
        self.random_state = random_state
        self.verbose = verbose

    def fit(self, X, y):
        Xw, yw, seq = _training_windows(
            X, y, self.window, self.rest_step, self.gesture_step
        )
        seed = seed_from(self.random_state)
        schedule = [
            (
                "lr_scheduler",
                LRScheduler(
                    policy=torch.optim.lr_scheduler.StepLR,
                    step_size=self.lr_drop_period,
                    gamma=self.lr_drop_factor,
                ),
            ),
        ]
        self.net_ = self._train(
            RecurrentTaggerModule,
            Xw,
            yw,
            seed=seed,
            n_sequences=len(X),
            train_split=SequenceSplit(self.validation_fraction, seed, seq),
            callbacks=schedule,
            module_params={
                "n_inputs": Xw.shape[2],
                "n_outputs": self.n_classes,
                "hidden_sizes": tuple(self.hidden_sizes),
                "dropout": self.dropout,
                **PAPER_MODULE,
            },
            criterion_params={"time_reduction": self.time_reduction},
            optimizer=torch.optim.SGD,
            optimizer__momentum=self.momentum,
            optimizer__weight_decay=self.weight_decay,
            # L2 on weights only: MATLAB's bias L2 factor is 0 (docs/method.md §7.3)
            optimizer__param_groups=[("*bias*", {"weight_decay": 0.0})],
            iterator_train__shuffle=True,
        )
        self.n_windows_ = len(Xw)
        return self


class BiLSTMTagger(_BaseTagger):
    """Bidirectional LSTM labelling every frame of a stream (Method C).

    Segments and names gestures in one pass, without a segmentation stage
    (docs/method.md §7). Training cuts every sequence into windows of ``window``
    frames (the next window starts ``rest_step`` frames later after an all-rest
    window, ``gesture_step`` otherwise) and trains stacked bidirectional LSTMs,
    each but the last followed by LeakyReLU(0.01) and dropout, with a linear
    read-out and cross-entropy at every time step. The optimiser is SGD with
    momentum, L2 on the weights and a learning rate dropped by
    ``lr_drop_factor`` every ``lr_drop_period`` epochs.

    Prediction runs consecutive ``window``-frame chunks of each sequence with a
    fresh state, smooths every class probability track with MATLAB-style loess,
    takes the arg-max per frame and sets gesture runs shorter than ``min_run``
    frames to rest. Only the network depends on the training: ``smooth_span``,
    ``min_run`` and ``overlap`` can be changed after ``fit``, and with ``memory``
    a search over them trains once per fold.

    The default network is sized for a small CPU; :meth:`paper` gives the
    paper's network (1024-1024-512 units, dropout 0.6, 150 epochs), meant for
    ``device="cuda"``.

    Parameters
    ----------
    hidden_sizes : tuple of int, default=(64, 64)
        Units per direction of each BiLSTM, input side first.
    dropout : float, default=0.3
        Drop probability after every BiLSTM but the last.
    window : int, default=10
        Length of the training windows and of the inference chunks, in frames.
    rest_step : int, default=5
        Start of the next training window after an all-rest window.
    gesture_step : int, default=2
        Start of the next training window after one holding a gesture frame.
    max_epochs : int, default=40
        Training epochs (the paper: 150).
    batch_size : int, default=128
        Windows per mini-batch.
    learning_rate : float, default=0.01
        Initial SGD learning rate.
    momentum : float, default=0.9
        SGD momentum.
    weight_decay : float, default=1e-4
        L2 penalty on the weights (not on the biases).
    lr_drop_factor : float, default=0.85
        Factor applied to the learning rate every ``lr_drop_period`` epochs.
    lr_drop_period : int, default=10
        Epochs between two learning-rate drops.
    time_reduction : {"sum", "mean"}, default="sum"
        Loss of a mini-batch: cross-entropy summed over the time steps of each
        window and averaged over windows (MATLAB), or averaged over all steps
        (10 times smaller with 10-frame windows).
    early_stopping : bool, default=False
        Hold out ``validation_fraction`` of the training sequences, stop after
        ``n_iter_no_change`` epochs without a lower validation loss, and keep
        the weights of the best epoch.
    validation_fraction : float, default=0.1
        Share of the sequences held out when ``early_stopping`` is on.
    n_iter_no_change : int, default=10
        Patience of the early stopping, in epochs.
    smooth_span : int or float, default=15
        Loess span of the probability smoothing, in frames (a float below 1 is
        a fraction of the sequence; 5 leaves interior frames unchanged).
    min_run : int, default=15
        Shortest gesture run kept, in frames; shorter runs become rest.
    overlap : bool, default=False
        Predict over windows overlapping by half (step ``window // 2``) and
        average the frames' probabilities, instead of non-overlapping chunks.
    memory : None, str or joblib.Memory, default=None
        Caches the trained network keyed on the training data and the network
        and training parameters only.
    device : str, default="cpu"
        Torch device of the training (``"cuda"`` for :meth:`paper`). A fitted
        tagger loads and predicts on a machine without CUDA.
    n_threads : int or None, default=1
        Torch intra-op CPU threads while fitting and predicting, and numpy's
        BLAS threads while decoding (the previous settings are restored
        afterwards); ``None`` keeps their settings. One
        thread is fastest for the small default network and immune to
        oversubscription (see Notes); raise it for large networks on a CPU.
    random_state : int, RandomState instance or None, default=None
        Seeds the initialisation, the dropout, the window shuffling and the
        validation split; an int gives identical results on the CPU for a given
        ``n_threads`` (the thread count changes the floating-point sums).
    verbose : int, default=0
        0 is silent; 1 or more prints one line per epoch.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Labels seen in ``fit``, rest (0) first.
    class_lengths_ : ndarray of shape (n_classes,)
        The 10th percentile of every class's run lengths in ``fit``, in
        frames (0 for rest); Method C keeps every run of ``min_run`` frames
        or more, whatever its class's length.
    class_long_lengths_ : ndarray of shape (n_classes,)
        The 90th percentile of the same lengths, unused by Method C.
    net_ : skorch.NeuralNet
        The trained network; ``net_.history`` holds the losses and learning
        rates (``"event_lr"``) of every epoch.
    n_windows_ : int
        Number of training windows.
    n_features_in_ : int
        Number of features per frame.
    frame_shape_in_ : tuple of int
        Shape of one input frame, ``(n_features_in_,)``.

    See Also
    --------
    PoseDescriptor : Gives the per-frame features.
    MultiScaleClassifier : Methods A and B, on periods of activity.

    Notes
    -----
    The rules follow docs/method.md §7: windows §7.1, network §7.2, optimiser
    §7.3, inference §7.4 (per-frame output, last chunk shorter: decision D18),
    smoothing span decision D12. Differences from MATLAB: torch's SGD keeps
    its momentum buffer in gradient units, so after a learning-rate drop the
    old velocity shrinks with the rate; windows are reshuffled every epoch
    (MATLAB shuffles once).

    A training sequence shorter than ``window`` gives one window padded with
    zero frames on the right, the padding being left out of the loss (MATLAB
    pads on the right too); prediction takes sequences of any length >= 1.

    Cost of the CPU default: fitting ``make_method_c(random_state=0)`` on the 48
    bundled PRECOG sequences (12,269 frames, 9 classes, 183-D descriptors, 5,402
    training windows, 40 epochs) took 40-53 s on a 2-core CPU shared with other
    jobs (load 3-5; torch 2.13), predicting them 0.2-0.3 s. The same fit with
    two torch threads (``n_threads=None``) took 696 s on that busy machine:
    for this network size one thread is the better default. Reproduce with::

        python -c "import time; from skgesture import make_method_c; \\
        from skgesture.datasets import load_precog; d = load_precog(); \\
        t = time.time(); make_method_c(random_state=0).fit(d.X, d.y); \\
        print(time.time() - t)"

    References
    ----------
    .. [1] Brás, Simão & Neto, "Gesture Recognition from Skeleton Data for
       Intuitive Human-Machine Interaction".

    Examples
    --------
    >>> from skgesture import BiLSTMTagger, PoseDescriptor
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> D = PoseDescriptor().fit_transform([X])
    >>> tagger = BiLSTMTagger(hidden_sizes=(16,), max_epochs=20, random_state=0)
    >>> tagger = tagger.fit(D, [y])
    >>> tagger.classes_.tolist()
    [0, 1, 2, 3]
    >>> proba = tagger.predict_proba(D)[0]
    >>> proba.shape == (len(X), 4), bool(abs(proba.sum(axis=1) - 1).max() < 1e-6)
    (True, True)
    >>> tagger.predict(D)[0].shape == y.shape
    True
    """

    _parameter_constraints: dict = {
        "hidden_sizes": [SequenceOf.ints(1)],
        "dropout": [Interval(Real, 0, 1, closed="left")],
        "window": [Interval(Integral, 1, None, closed="left")],
        "rest_step": [Interval(Integral, 1, None, closed="left")],
        "gesture_step": [Interval(Integral, 1, None, closed="left")],
        "max_epochs": [Interval(Integral, 1, None, closed="left")],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
        "momentum": [Interval(Real, 0, 1, closed="left")],
        "weight_decay": [Interval(Real, 0, None, closed="left")],
        "lr_drop_factor": [Interval(Real, 0, 1, closed="right")],
        "lr_drop_period": [Interval(Integral, 1, None, closed="left")],
        "time_reduction": [StrOptions({"sum", "mean"})],
        "early_stopping": ["boolean"],
        "validation_fraction": [Interval(Real, 0, 1, closed="neither")],
        "n_iter_no_change": [Interval(Integral, 1, None, closed="left")],
        "smooth_span": [Interval(Real, 0, None, closed="neither")],
        "min_run": [Interval(Integral, 1, None, closed="left")],
        "overlap": ["boolean"],
        "memory": [None, str, HasMethods(["cache"])],
        "device": [str],
        "n_threads": [Interval(Integral, 1, None, closed="left"), None],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        *,
        hidden_sizes=CPU_HIDDEN_SIZES,
        dropout=CPU_DROPOUT,
        window=WINDOW,
        rest_step=REST_STEP,
        gesture_step=GESTURE_STEP,
        max_epochs=CPU_MAX_EPOCHS,
        batch_size=BATCH_SIZE,
        learning_rate=LEARNING_RATE,
        momentum=MOMENTUM,
        weight_decay=WEIGHT_DECAY,
        lr_drop_factor=LR_DROP_FACTOR,
        lr_drop_period=LR_DROP_PERIOD,
        time_reduction="sum",
        early_stopping=False,
        validation_fraction=VALIDATION_FRACTION,
        n_iter_no_change=N_ITER_NO_CHANGE,
        smooth_span=SMOOTH_SPAN,
        min_run=MIN_RUN,
        overlap=False,
        memory=None,
        device="cpu",
        n_threads=1,
        random_state=None,
        verbose=0,
    ):
        self.hidden_sizes = hidden_sizes
        self.dropout = dropout
        self.window = window
        self.rest_step = rest_step
        self.gesture_step = gesture_step
        self.max_epochs = max_epochs
        self.batch_size = batch_size
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.weight_decay = weight_decay
        self.lr_drop_factor = lr_drop_factor
        self.lr_drop_period = lr_drop_period
        self.time_reduction = time_reduction
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.smooth_span = smooth_span
        self.min_run = min_run
        self.overlap = overlap
        self.memory = memory
        self.device = device
        self.n_threads = n_threads
        self.random_state = random_state
        self.verbose = verbose

    @classmethod
    def paper(cls, **overrides):
        """The paper's network: BiLSTM 1024-1024-512, dropout 0.6, 150 epochs.

        Parameters
        ----------
        **overrides
            Any other constructor parameter, e.g. ``device="cuda"``, which this
            size needs in practice (the default device stays ``"cpu"``).

        Returns
        -------
        BiLSTMTagger
            The unfitted tagger.

        Examples
        --------
        >>> from skgesture import BiLSTMTagger
        >>> BiLSTMTagger.paper(device="cuda").hidden_sizes
        (1024, 1024, 512)
        """
        params = {
            "hidden_sizes": PAPER_HIDDEN_SIZES,
            "dropout": PAPER_DROPOUT,
            "max_epochs": PAPER_MAX_EPOCHS,
        }
        params.update(overrides)
        return cls(**params)

    # Decoding rules Method C fixes (read by the shared decoding path).
    smoothing = "loess"  # MATLAB-style loess of span smooth_span
    max_gap = 0  # no merging of split runs
    min_confidence = 0.0  # and the paper's rules only: no run rejected for
    min_duration = 0.0  # its confidence or its class's length (short
    max_duration = None  # or long),
    viterbi_penalty = None  # and the arg-max of every frame

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y):
        """Train the network on windows of every sequence.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features (e.g. from :class:`PoseDescriptor`).
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels, 0 = rest, 1..K gesture classes; both rest and
            gesture frames must occur. A sequence whose labels are all 0 is a
            background recording (ordinary motion, no command in it): its
            windows are rest windows like any other.

        Returns
        -------
        self : BiLSTMTagger
            The fitted tagger.
        """
        # The paper trains on every frame: untracked ones keep their labels.
        X, y_idx, classes = self._validate_fit(X, y, ignore_untracked=False)
        return self._fit_network(X, y_idx, classes)

    def _network(self, n_classes):
        return _BiLSTMNet(
            n_classes=n_classes,
            hidden_sizes=tuple(int(h) for h in self.hidden_sizes),
            dropout=self.dropout,
            window=self.window,
            rest_step=self.rest_step,
            gesture_step=self.gesture_step,
            momentum=self.momentum,
            lr_drop_factor=self.lr_drop_factor,
            lr_drop_period=self.lr_drop_period,
            time_reduction=self.time_reduction,
            **self._training_params(),
        )

    def _adopt(self, fitted):
        self.net_ = fitted.net_
        self.n_windows_ = fitted.n_windows_

    def _raw_proba(self, X):
        return _predict_chunks(
            self.net_.module_, X, self.window, self.overlap, len(self.classes_)
        )

    def decision_function(self, X):
        """Loess-smoothed per-frame class probabilities.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_classes)
            Every class track smoothed with span ``smooth_span``; the arg-max
            of a row is the frame's label before the ``min_run`` filter. An
            untracked row is rest with score 1 (set after the smoothing).
        """
        proba, untracked = self._proba(X)
        return [
            _rest_where(smooth_proba(p, self.smooth_span, self.smoothing), rows)
            for p, rows in zip(proba, untracked)
        ]

    # -- incremental step (docs/design.md, "Incremental steps") ----------------
    # The state (skgesture/_taggers/_stream.py, TaggerStream) runs the network on
    # the chunks of predict_proba as they complete and applies the same loess,
    # rest rule and minimum run.

    _stream_options = ("max_period",)

    def _stream_state(self, *, max_period=DEFAULT_MAX_PERIOD):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Descriptor rows in, the gestures decided out: the network runs on the
        chunks of :meth:`predict_proba` as they complete, then the same
        loess, rest rule and minimum run as :meth:`predict_segments`.

        Parameters
        ----------
        max_period : int, default=1200
            A run of one label this long (frames) is decided as if the stream
            ended there, which bounds memory on a stream that never rests
            (offline has no cap).

        Returns
        -------
        TaggerStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        check_is_fitted(self)
        return TaggerStream(self, max_run=max_period)

    @property
    def stream_lookahead(self):
        """Frames between a gesture's last frame and its event, at most.

        ``(smooth_span - 1) // 2 + window`` (17 with the defaults).
        """
        from skgesture.utils._smoothing import check_stream_span

        return (check_stream_span(self.smooth_span, "smooth_span") - 1) // 2 + int(
            self.window
        )
