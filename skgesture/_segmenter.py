"""ActivitySegmenter: framewise gesture-vs-rest network, smoothing and periods."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, TransformerMixin, _fit_context
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import HasMethods, Interval
from sklearn.utils.validation import _check_feature_names_in, check_is_fitted

from skgesture._nn._mlp import TorchMLPClassifier, fast_proba
from skgesture._stream import Rows, StreamableMixin
from skgesture.utils._buffers import RowBuffer, _concat_rows
from skgesture.utils._fitting import fit_inner_estimator
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._segments import remove_short_runs, runs
from skgesture.utils._smoothing import LoessStepper, loess_smooth
from skgesture.utils._validation import (
    SequenceOutputMixin,
    check_sequence_labels,
    check_sequences,
    sequence_tags,
    untracked_rows,
)

__all__ = ["ActivitySegmenter"]

# docs/method.md §4
SEGMENTER_HIDDEN = (100, 100)
SEGMENTER_ACTIVATIONS = ("relu", "tanh")
N_CONTEXT = 10  # rest frames before and after each gesture (decision D13)
THRESHOLD = 0.4
MIN_LENGTH = 12
SMOOTH_SPAN = 15  # decision D12


def default_frame_network():
    """The paper's segmentation network: 100 (ReLU) - 100 (tanh) - 1 (sigmoid)."""
    return TorchMLPClassifier(
        hidden_layer_sizes=SEGMENTER_HIDDEN, activations=SEGMENTER_ACTIVATIONS
    )


def context_mask(y, n_context):
    """Training frames of the segmenter in one sequence (docs/method.md §4.1).

    Every gesture frame, plus up to ``n_context`` rest frames right before and
    right after each gesture (all rest frames when ``n_context`` is None). A
    sequence without any gesture is a background recording (ordinary motion,
    no command in it): all its frames are taken, as negatives.

    Parameters
    ----------
    y : ndarray of shape (n_frames,)
        Per-frame labels, 0 = rest.
    n_context : int or None
        Rest frames taken on each side of a gesture.

    Returns
    -------
    ndarray of bool of shape (n_frames,)
        Frames to train on.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._segmenter import context_mask
    >>> context_mask(np.array([0, 0, 0, 5, 5, 0, 0, 0]), 2).astype(int).tolist()
    [0, 1, 1, 1, 1, 1, 1, 0]
    >>> context_mask(np.zeros(4, int), 2).astype(int).tolist()  # background
    [1, 1, 1, 1]
    """
    gesture = y > 0
    if n_context is None or not gesture.any():
        return np.ones_like(gesture)
    keep = gesture.copy()
    starts, ends, vals = runs(gesture)
    T = len(y)
    for s, e in zip(starts[vals], ends[vals]):
        keep[max(0, s - n_context) : s] = True
        keep[e : min(T, e + n_context)] = True
    return keep


class ActivitySegmenter(
    NewParamsMixin,
    StreamableMixin,
    ClassifierMixin,
    SequenceOutputMixin,
    TransformerMixin,
    BaseEstimator,
    auto_wrap_output_keys=None,
):
    """Framewise gesture-vs-rest detector giving the periods of activity.

    A network scores every frame's descriptor; the score track is smoothed with
    MATLAB-style loess, thresholded, and runs of active frames shorter than
    ``min_length`` are dropped (docs/method.md §4). ``predict`` gives per-frame 0/1;
    ``transform`` hands the features on as masked arrays whose masked rows are
    rest, which is how :class:`DynamicPoseWindow` and
    :class:`MultiScaleClassifier` learn where the periods are.

    Parameters
    ----------
    estimator : classifier or None, default=None
        A 2-D classifier with ``predict_proba`` trained on single frames. ``None``
        uses the paper's network: :class:`TorchMLPClassifier` 100 (ReLU) - 100
        (tanh) - 1 (sigmoid), trained with scaled conjugate gradient.
    n_context : int or None, default=10
        Rest frames taken as negatives before and after each gesture; ``None``
        takes every rest frame (decision D13). Every frame of a background
        sequence (one without gestures) is taken whatever ``n_context`` is.
    threshold : float, default=0.4
        A frame is active when its smoothed score exceeds this.
    min_length : int, default=12
        Shortest period of activity kept, in frames.
    smooth_span : int or float, default=15
        Loess span in frames (a float below 1 is a fraction of the sequence);
        5 leaves interior frames unchanged (decision D12).
    memory : None, str or joblib.Memory, default=None
        Caches the trained network keyed on the training frames and the
        network's parameters only, so a search over ``threshold``,
        ``min_length`` or ``smooth_span`` trains once per fold.
    random_state : int, RandomState instance or None, default=None
        Seeds the network (overrides the estimator's own ``random_state``).
    verbose : int, default=0
        0 is silent; 1 shows the network's progress bar over its epochs, 2 one
        line per epoch (handed on to the network's own ``verbose``).

    Attributes
    ----------
    estimator_ : classifier
        The fitted frame classifier.
    classes_ : ndarray of shape (2,)
        ``[0, 1]``: rest and gesture.
    n_features_in_ : int
        Descriptor width.
    frame_shape_in_ : tuple of int
        Shape of one input frame.

    See Also
    --------
    PoseDescriptor : Gives the per-frame features.
    DynamicPoseWindow : Builds the windows classified inside each period.

    Notes
    -----
    ``predict_proba`` is the network's raw per-frame output; ``decision_function``
    is the smoothed score that ``threshold`` applies to.

    Untracked frames are rest by construction (docs/design.md §1.1):
    a masked row of the input (:class:`PoseDescriptor` masks the
    untracked frames) or an all-zero row of a plain array gets probability and
    score 0, so it is never active. The smoothing still runs over the
    network's output on every frame, so the scores of tracked frames are
    those of the paper's pipeline. ``fit`` trains on every frame, as before.

    Background recordings are training sequences like the others, with every
    label 0: record a few minutes of ordinary work (no command in it) and add
    the recordings to ``X`` with all-zero labels in ``y``. All their frames
    are negatives, so they teach the network that everyday motion is rest;
    without them the negatives are only the rest frames next to gestures, as
    in the paper, and the fit is unchanged. A background frame weighs as much
    as a gesture frame, so a long background shifts the balance towards rest.
    A fit whose every label is 0 is an error.

    Examples
    --------
    >>> from skgesture import ActivitySegmenter, PoseDescriptor, TorchMLPClassifier
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> D = PoseDescriptor().fit_transform([X])
    >>> net = TorchMLPClassifier(hidden_layer_sizes=(16,), activations=("tanh",),
    ...                          max_epochs=40)
    >>> seg = ActivitySegmenter(estimator=net, random_state=0).fit(D, [y])
    >>> seg.predict(D)[0].shape == y.shape
    True
    """

    _parameter_constraints: dict = {
        "estimator": [HasMethods(["fit", "predict_proba"]), None],
        "n_context": [Interval(Integral, 0, None, closed="left"), None],
        "threshold": [Interval(Real, 0, 1, closed="both")],
        "min_length": [Interval(Integral, 1, None, closed="left")],
        "smooth_span": [Interval(Real, 0, None, closed="neither")],
        "memory": [None, str, HasMethods(["cache"])],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        estimator=None,
        *,
        n_context=N_CONTEXT,
        threshold=THRESHOLD,
        min_length=MIN_LENGTH,
        smooth_span=SMOOTH_SPAN,
        memory=None,
        random_state=None,
        verbose=0,
    ):
        self.estimator = estimator
        self.n_context = n_context
        self.threshold = threshold
        self.min_length = min_length
        self.smooth_span = smooth_span
        self.memory = memory
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y):
        """Train the frame network on gesture frames and the rest around them.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features (e.g. from :class:`PoseDescriptor`).
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels; every label > 0 counts as gesture. A sequence
            whose labels are all 0 is a background recording: all its frames
            are negatives. At least one gesture frame must occur.

        Returns
        -------
        self : ActivitySegmenter
            The fitted segmenter.
        """
        X = check_sequences(X, ndim=2, estimator=self, reset=True)
        y = check_sequence_labels(y, X)
        keep = [context_mask(lab, self.n_context) for lab in y]
        Xf = np.concatenate([x[k] for x, k in zip(X, keep)])
        yf = np.concatenate([(lab[k] > 0).astype(np.int64) for lab, k in zip(y, keep)])
        n_pos = int(yf.sum())
        if n_pos == 0:
            raise ValueError(
                "y has no gesture frame (every label is 0): the segmenter needs "
                "gesture and rest frames"
            )
        if n_pos == len(yf):
            raise ValueError(
                "y has no rest frame near any gesture (label 0): the segmenter "
                "needs gesture and rest frames"
            )
        rng = (
            check_random_state(self.random_state)
            if self.random_state is not None
            else None
        )
        default = default_frame_network()
        self.estimator_ = fit_inner_estimator(
            self.estimator,
            default,
            Xf,
            yf,
            rng=rng,
            memory=self.memory,
            verbose=self.verbose,
        )
        self.classes_ = np.array([0, 1])
        return self

    def predict_proba(self, X):
        """Raw per-frame probabilities of rest and gesture (before smoothing).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of ndarray of shape (n_frames_i, 2)
            Columns: rest, gesture; ``[1, 0]`` on untracked rows.
        """
        scores = []
        for p, rest in zip(*self._raw_scores(X)):
            p = np.where(rest, 0.0, p)
            scores.append(np.column_stack([1.0 - p, p]))
        return scores

    def _raw_scores(self, X):
        """The network's gesture probability of every frame, and the untracked rows."""
        check_is_fitted(self)
        data = check_sequences(X, ndim=2, estimator=self, reset=False)
        rest = [
            untracked_rows(x if isinstance(x, np.ma.MaskedArray) else d)
            for x, d in zip(X, data)
        ]
        lengths = [len(x) for x in data]
        proba = self.estimator_.predict_proba(np.concatenate(data))
        pos = proba[:, list(self.estimator_.classes_).index(1)]
        return np.split(pos, np.cumsum(lengths)[:-1]), rest

    def decision_function(self, X):
        """Smoothed gesture score of every frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of ndarray of shape (n_frames_i,)
            Loess-smoothed gesture probability; 0 on untracked rows (set after
            the smoothing).
        """
        return [
            np.where(rest, 0.0, self._smooth(p))
            for p, rest in zip(*self._raw_scores(X))
        ]

    def predict(self, X):
        """Per-frame activity: 1 inside a period of activity, else 0.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of ndarray of shape (n_frames_i,)
            0/1 labels.
        """
        return [self._periods(s) for s in self.decision_function(X)]

    def transform(self, X):
        """The features with rest frames masked.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of numpy.ma.MaskedArray of shape (n_frames_i, n_features)
            Same values; rows outside every period of activity are masked.
        """
        active = self.predict(X)
        X = check_sequences(X, ndim=2, estimator=self, reset=False)
        return [
            np.ma.MaskedArray(
                x, mask=np.broadcast_to(~a.astype(bool)[:, None], x.shape)
            )
            for x, a in zip(X, active)
        ]

    def score(self, X, y, sample_weight=None):
        """Frame accuracy of the gesture-vs-rest decision.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels; every label > 0 counts as gesture.
        sample_weight : None
            Not supported.

        Returns
        -------
        float
            Share of frames whose activity is predicted correctly.
        """
        y = check_sequence_labels(y, X)
        pred = np.concatenate(self.predict(X))
        return float(np.mean(pred == (np.concatenate(y) > 0)))

    def get_feature_names_out(self, input_features=None):
        """Names of the output features: the input features, unchanged.

        Parameters
        ----------
        input_features : array-like of str or None, default=None
            Names of the input features; ``None`` gives ``x0, x1, ...``.

        Returns
        -------
        ndarray of str of shape (n_features_in_,)
            The names (``transform`` only masks rows).
        """
        check_is_fitted(self)
        return _check_feature_names_in(self, input_features)

    def _smooth(self, score):
        return np.asarray(loess_smooth(score, self.smooth_span))

    def _periods(self, smoothed):
        active = (smoothed > self.threshold).astype(np.int64)
        return remove_short_runs(active, self.min_length)

    def __sklearn_tags__(self):
        return sequence_tags(super().__sklearn_tags__())

    # -- incremental step (docs/design.md, "Incremental steps") ----------------
    # The state (skgesture/_segmenter.py, SegmenterStream) uses the same
    # network, loess and rules as predict; tests/test_streaming.py checks it.

    _stream_options = ()

    def _stream_state(self):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Descriptor rows in, the rows whose activity became final out. A row is
        scored by the network, its smoothed score is known ``h = (smooth_span -
        1) / 2`` rows later (:attr:`stream_lookahead`), and an active row is
        handed on once its run of active rows reaches ``min_length``. The
        output is the rows of :meth:`transform`: the descriptors, masked where
        at rest (untracked rows included); at the end, loess end-point fits.

        Returns
        -------
        SegmenterStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        check_is_fitted(self)
        return SegmenterStream(self)

    @property
    def stream_lookahead(self):
        """Frames of smoothing look-ahead, ``(smooth_span - 1) // 2`` (7)."""
        from skgesture.utils._smoothing import check_stream_span

        return (check_stream_span(self.smooth_span, "smooth_span") - 1) // 2


class SegmenterStream:
    """State of :meth:`ActivitySegmenter.stream_step` for one stream.

    Scores every descriptor row, smooths the score track with the causal
    loess (:class:`LoessStepper`), thresholds it and keeps the runs of active
    frames of at least ``min_length`` frames (``remove_short_runs``). An
    active row is handed on once its run reaches ``min_length`` frames, a rest
    row at once; the rows are the descriptors, masked where at rest.
    Untracked (masked) rows are rest.
    """

    def __init__(self, seg):
        self.proba = fast_proba(seg.estimator_)
        self.column = list(seg.estimator_.classes_).index(1)
        self.smoother = LoessStepper(
            seg.smooth_span, 1, owner="ActivitySegmenter.smooth_span"
        )
        self.threshold = seg.threshold
        self.min_length = seg.min_length
        self.rows = None  # descriptor rows not yet handed on
        self.n_out = 0
        self.run_start = None  # first row of the current run of active rows
        self.last_time = 0

    def step(self, rows):
        if self.rows is None:
            self.rows = RowBuffer(rows.data.shape[1:], capacity=64)
        self.rows.append(rows.data, rows.mask, rows.time)
        self.last_time = int(rows.time[-1])
        score = self.proba(rows.data)[:, self.column]
        lo, smoothed, times = self.smoother.step(score[:, None], rows.time)
        return self._decide(lo, smoothed[:, 0], times)

    def flush(self):
        if self.rows is None:
            return None
        lo, smoothed, times = self.smoother.flush(self.last_time)
        out = self._decide(lo, smoothed[:, 0], times)
        # A run still shorter than min_length at the end is rest.
        tail = self._hand_on(self.rows.stop, False, self.last_time)
        return _concat_rows([out, tail], self.rows._data.shape[1:])

    def _decide(self, lo, smoothed, times):
        untracked = self.rows.mask(lo, lo + len(smoothed))
        active = (smoothed > self.threshold) & ~untracked
        out = []
        for i, on in enumerate(active.tolist()):
            u = lo + i
            if on:
                if self.run_start is None:
                    self.run_start = u
                if u + 1 - self.run_start >= self.min_length:
                    out.append(self._hand_on(u + 1, True, times[i]))
            else:
                # A run shorter than min_length is rest, with this row.
                self.run_start = None
                out.append(self._hand_on(u + 1, False, times[i]))
        return _concat_rows(out, self.rows._data.shape[1:])

    def _hand_on(self, stop, active, time):
        lo = self.n_out
        if stop <= lo:
            return Rows.empty(self.rows._data.shape[1:])
        block = self.rows.rows(lo, stop)
        block.mask = np.full(stop - lo, not active)
        block.time = np.full(stop - lo, time, dtype=np.int64)
        self.n_out = stop
        self.rows.drop(stop)
        return block

    def held(self):
        return {"scores": self.smoother.held(), "pending": len(self.rows or ())}
