"""MultiScaleClassifier: one window network per time scale, fused, then the
paper's decision rules inside every period of activity (Methods A and B)."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
from sklearn import config_context
from sklearn.base import BaseEstimator, ClassifierMixin, _fit_context
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions
from sklearn.utils.validation import check_is_fitted
from tqdm.auto import tqdm

from skgesture._multiscale._rules import (
    MAX_MIN_WINDOWS,
    MAX_RESIZED_LENGTH,
    MIN_CONSECUTIVE,
    MIN_WINDOWS,
    SHORT_LENGTH,
    STRIDE,
    THRESHOLD_LONG_A,
    THRESHOLD_SHORT_A,
    _map_back,
    _resized_frames,
    decide_period,
    period_windows,
)
from skgesture._multiscale._stream import MultiScaleStream
from skgesture._nn._mlp import TorchMLPClassifier
from skgesture._stream import DEFAULT_MAX_PERIOD, StreamableMixin
from skgesture._windows import (
    N_POSES,
    STEPS_A,
    check_lazy_windows,
    check_steps,
    scale_matrix,
)
from skgesture.utils._fitting import fit_inner_estimator
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._segments import labels_to_segments, runs
from skgesture.utils._validation import (
    SequenceOf,
    check_sequence_labels,
    check_sequences,
    sequence_tags,
    untracked_rows,
)

__all__ = ["MultiScaleClassifier", "decide_period", "period_windows"]

# docs/method.md §5.4
WINDOW_HIDDEN = (300, 100)
WINDOW_ACTIVATIONS = ("tanh", "tanh")
N_LAYOUT_CHECKS = 16  # frames per sequence at which the window steps are checked


def _is_weight(w):
    return isinstance(w, Real) and not isinstance(w, bool) and 0 <= w < np.inf


WEIGHTS_CONSTRAINT = SequenceOf(
    _is_weight,
    "a non-empty tuple of finite weights >= 0, not all 0",
    whole=lambda w: sum(w) > 0,
    arrays=True,
)


def default_window_network():
    """The paper's window network: 300 (tanh) - 100 (tanh) - K (softmax)."""
    return TorchMLPClassifier(
        hidden_layer_sizes=WINDOW_HIDDEN, activations=WINDOW_ACTIVATIONS
    )


def _guess_step(W, D, t, k, j, mid, F):
    """``"; they look built with step s"`` if one step explains pose ``j`` of
    scale ``k`` at the frames ``t``, else ``""`` (for an error message)."""
    if j == mid:
        return ""
    T = len(W)
    pose = W[t, k, j * F : (j + 1) * F]
    for s in range(1, T):
        if np.array_equal(pose, D[np.clip(t + (j - mid) * s, 0, T - 1)]):
            return f"; they look built with step {s} there"
    return ""


class MultiScaleClassifier(
    NewParamsMixin, StreamableMixin, ClassifierMixin, BaseEstimator
):
    """Dynamic-pose classifier at one or more time scales, with the paper's rules.

    Fits one clone of ``estimator`` per time scale on the windows of every
    training gesture instance, fuses the scales' class probabilities with
    ``weights`` and labels each period of activity with the paper's short/long
    rules. With one scale and the default numbers it is Method A; with
    ``steps=(4, 3, 2)``, ``weights=(0.4895, 0.4576, 0.0529)`` and thresholds
    0.6014 / 0.6033 it is Method B (docs/method.md §5-6).

    Periods of activity are the runs of unmasked rows of a masked input (from
    :class:`ActivitySegmenter`); a plain array is one period, so pre-cut clips
    work without a segmenter. Untracked frames are rest by construction: a
    masked row (from :class:`PoseDescriptor` or the segmenter) and an all-zero
    row of a plain array are outside every period.

    The windows carry their steps (the middle pose of every scale is the
    frame's own descriptor), and ``fit`` and ``predict`` check at 16 frames of
    every sequence that they were built with this classifier's ``steps``, so
    a window stage whose steps changed (``set_params(windows__steps=...)``)
    raises instead of giving different labels.

    Parameters
    ----------
    estimator : classifier or None, default=None
        2-D classifier with ``predict_proba``, cloned for each scale. ``None``
        uses the paper's network, :class:`TorchMLPClassifier` 300 (tanh) - 100
        (tanh) - K (softmax) trained with scaled conjugate gradient.
    steps : tuple of int, default=(4,)
        Time step of each scale; must match the :class:`DynamicPoseWindow`
        that built the input (checked on the data).
    weights : tuple of float or None, default=None
        Fusion weight of each scale, finite and >= 0 (not all 0), normalised to
        sum to 1; equal when None. A negative weight is refused: it would turn
        a scale's evidence into evidence against, and the fused score would no
        longer be a probability the thresholds apply to.
    n_poses : int, default=3
        Descriptors per dynamic pose.
    stride : int, default=2
        Frames between window centres.
    min_windows : int, default=5
        Periods with fewer windows are resized along time first (at most
        1000; the resized length ``2 h + 1 + stride * (min_windows - 1)``,
        with ``h`` the half span of the widest scale, at most 10,000 frames).
    short_length : int, default=55
        Periods shorter than this get a single label by majority vote.
    threshold_short : float, default=0.8717
        Score a window needs to vote in a short period.
    threshold_long : float, default=0.6255
        Score a window needs to count in a long period.
    min_consecutive : int, default=3
        Consecutive windows of one class needed in a long period.
    resize : {"bicubic", "pchip", "spline"}, default="bicubic"
        Resampling of short periods (decision D15).
    memory : None, str or joblib.Memory, default=None
        Caches each scale's trained network keyed on its training windows and
        the network's parameters only: a search over ``weights``, thresholds,
        ``short_length`` or ``min_consecutive`` trains once per fold.
    random_state : int, RandomState instance or None, default=None
        Seeds the networks (overrides the estimator's own ``random_state``).
    verbose : int, default=0
        0 is silent; 1 shows a progress bar over the scales and the network's
        bar over its epochs; 2 prints one line per epoch of every network.

    Attributes
    ----------
    estimators_ : list of classifier
        The fitted classifier of each scale.
    classes_ : ndarray of shape (n_classes,)
        Gesture classes seen in training (rest excluded).
    n_features_in_ : int
        Values per input frame.
    frame_shape_in_ : tuple of int
        Shape of one input frame, ``(n_scales, n_poses * n_features)``.

    See Also
    --------
    DynamicPoseWindow : Builds the input windows.
    make_method_a, make_method_b : The paper's full pipelines.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn.linear_model import LogisticRegression
    >>> from skgesture import DynamicPoseWindow, MultiScaleClassifier
    >>> rng = np.random.RandomState(0)
    >>> clips = [rng.normal(c, 0.3, (30, 4)) for c in (0, 3, 0, 3)]
    >>> y = [np.full(30, c) for c in (1, 2, 1, 2)]
    >>> W = DynamicPoseWindow(steps=(4, 2)).fit_transform(clips)
    >>> clf = MultiScaleClassifier(LogisticRegression(), steps=(4, 2),
    ...                            threshold_short=0.5).fit(W, y)
    >>> [int(p[0]) for p in clf.predict(W)]
    [1, 2, 1, 2]
    """

    _parameter_constraints: dict = {
        "estimator": [HasMethods(["fit", "predict_proba"]), None],
        "steps": [SequenceOf.ints(1)],
        "weights": [WEIGHTS_CONSTRAINT, None],
        "n_poses": [Interval(Integral, 1, None, closed="left")],
        "stride": [Interval(Integral, 1, None, closed="left")],
        "min_windows": [Interval(Integral, 1, MAX_MIN_WINDOWS, closed="both")],
        "short_length": [Interval(Integral, 1, None, closed="left")],
        "threshold_short": [Interval(Real, 0, 1, closed="both")],
        "threshold_long": [Interval(Real, 0, 1, closed="both")],
        "min_consecutive": [Interval(Integral, 1, None, closed="left")],
        "resize": [StrOptions({"bicubic", "pchip", "spline"})],
        "memory": [None, str, HasMethods(["cache"])],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        estimator=None,
        *,
        steps=STEPS_A,
        weights=None,
        n_poses=N_POSES,
        stride=STRIDE,
        min_windows=MIN_WINDOWS,
        short_length=SHORT_LENGTH,
        threshold_short=THRESHOLD_SHORT_A,
        threshold_long=THRESHOLD_LONG_A,
        min_consecutive=MIN_CONSECUTIVE,
        resize="bicubic",
        memory=None,
        random_state=None,
        verbose=0,
    ):
        self.estimator = estimator
        self.steps = steps
        self.weights = weights
        self.n_poses = n_poses
        self.stride = stride
        self.min_windows = min_windows
        self.short_length = short_length
        self.threshold_short = threshold_short
        self.threshold_long = threshold_long
        self.min_consecutive = min_consecutive
        self.resize = resize
        self.memory = memory
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y):
        """Train one network per scale on the windows of every gesture instance.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_scales, n_poses * n_features)
            Dynamic poses of every frame (from :class:`DynamicPoseWindow`).
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels, 0 = rest; each maximal run of one gesture label is
            a training instance. A sequence whose labels are all 0 (a
            background recording) gives no window: the classifier learns the
            gesture classes only, and background recordings teach the
            :class:`ActivitySegmenter` in front of it.

        Returns
        -------
        self : MultiScaleClassifier
            The fitted classifier.
        """
        steps = self._check_steps()
        if not check_lazy_windows(X, steps, self.n_poses, self, reset=True):
            X = check_sequences(X, ndim=3, estimator=self, reset=True, dtype=np.float32)
            self._check_layout(X, steps)
        y = check_sequence_labels(y, X)
        wins, labels = [], []
        for W, lab in zip(X, y):
            for c, s, e in labels_to_segments(lab):
                w, _, _ = self._windows(W, s, e, steps)
                wins.append(w)
                labels.append(np.full(len(w), c))
        if not wins:
            raise ValueError(
                "y has no gesture instance (every label is 0): nothing to train "
                "the window classifier on"
            )
        labels = np.concatenate(labels)
        self.classes_ = np.unique(labels)
        if len(self.classes_) < 2:
            raise ValueError(
                f"y has a single gesture class ({self.classes_[0]}); at least 2 "
                f"are needed to train a classifier"
            )
        rng = (
            check_random_state(self.random_state)
            if self.random_state is not None
            else None
        )
        default = default_window_network()
        self.estimators_ = [
            fit_inner_estimator(
                self.estimator,
                default,
                scale_matrix(wins, k),  # one scale's windows at a time
                labels,
                rng=rng,
                memory=self.memory,
                verbose=self.verbose,
            )
            for k in tqdm(
                range(len(steps)),
                desc=f"{type(self).__name__}: networks of steps {steps}",
                unit="scale",
                disable=self.verbose < 1,
            )
        ]
        return self

    def predict(self, X):
        """Per-frame gesture labels.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_scales, n_poses * n_features)
            Dynamic poses; masked rows (rest) are outside every period.

        Returns
        -------
        list of ndarray of shape (n_frames_i,)
            Gesture class per frame, 0 = rest.
        """
        return [labels for labels, _ in self._decide(X)]

    def predict_segments(self, X):
        """Gesture instances with their confidence.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_scales, n_poses * n_features)
            Dynamic poses, as for :meth:`predict`.

        Returns
        -------
        list of ndarray of shape (n_segments_i, 4)
            Rows ``(class, start, end, confidence)``, 0-based, ``end`` exclusive.
        """
        return [segs for _, segs in self._decide(X)]

    def score(self, X, y, sample_weight=None):
        """Mean official ChaLearn 2014 Jaccard index.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_scales, n_poses * n_features)
            Dynamic poses.
        y : list of ndarray of shape (n_frames_i,)
            True per-frame labels.
        sample_weight : None
            Not supported.

        Returns
        -------
        float
            Mean Jaccard index.
        """
        from skgesture.metrics import jaccard_index

        return jaccard_index(y, self.predict(X))

    # -- internals -------------------------------------------------------------

    def _check_steps(self):
        """Parameters that constrain each other (also checked by ``predict``)."""
        steps = check_steps(self.steps, self.n_poses)
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=float)
            if w.shape != (len(steps),):
                raise ValueError(
                    f"weights has {w.size} values but steps has {len(steps)} scales"
                )
            if not (np.all(np.isfinite(w)) and np.all(w >= 0) and w.sum() > 0):
                raise ValueError(
                    f"weights must be finite, non-negative and not all 0, got "
                    f"{self.weights}"
                )
        h = max(steps) * (self.n_poses - 1) // 2
        n_resized = 2 * h + 1 + self.stride * (self.min_windows - 1)
        if n_resized > MAX_RESIZED_LENGTH:
            raise ValueError(
                f"steps={steps}, n_poses={self.n_poses}, stride={self.stride} and "
                f"min_windows={self.min_windows} would resize every short period "
                f"to {n_resized} frames (2 * {h} + 1 + stride * (min_windows - 1)); "
                f"at most {MAX_RESIZED_LENGTH} are allowed"
            )
        return steps

    def _fusion_weights(self, n_scales):
        if self.weights is None:
            return np.full(n_scales, 1.0 / n_scales)
        w = np.asarray(self.weights, dtype=float)
        return w / w.sum()

    def _check_layout(self, X, steps):
        """The windows must be dynamic poses built with this classifier's steps.

        Pose ``j`` of scale ``k`` at frame ``t`` must be the descriptor of frame
        ``clip(t + (j - middle) * steps[k])``, i.e. the middle pose of the first
        scale at that frame. Checked exactly (both are float32 copies of one
        descriptor) at ``N_LAYOUT_CHECKS`` frames spread over every sequence.
        """
        n_scales, width = X[0].shape[1:]
        if n_scales != len(steps):
            raise ValueError(
                f"X has {n_scales} scales per frame but steps={tuple(steps)} has "
                f"{len(steps)}: build X with DynamicPoseWindow(steps={tuple(steps)})"
            )
        F = width // self.n_poses
        if width != F * self.n_poses:
            raise ValueError(
                f"window width {width} is not a multiple of n_poses={self.n_poses}"
            )
        mid = (self.n_poses - 1) // 2
        for i, W in enumerate(X):
            T = len(W)
            t = np.unique(np.linspace(0, T - 1, min(T, N_LAYOUT_CHECKS)).astype(int))
            D = W[:, 0, mid * F : (mid + 1) * F]  # every frame's own descriptor
            for k, s in enumerate(steps):
                for j in range(self.n_poses):
                    pose = W[t, k, j * F : (j + 1) * F]
                    src = np.clip(t + (j - mid) * s, 0, T - 1)
                    if np.array_equal(pose, D[src]):
                        continue
                    bad = int(t[np.flatnonzero((pose != D[src]).any(axis=1))[0]])
                    raise ValueError(
                        f"X[{i}] does not hold dynamic poses with steps="
                        f"{tuple(steps)}: scale {k} disagrees at frame {bad}"
                        f"{_guess_step(W, D, t, k, j, mid, F)}. The window stage "
                        f"and the classifier must use the same steps, e.g. "
                        f"pipe.set_params(windows__steps=s, classifier__steps=s)"
                    )

    def _windows(self, W, s, e, steps):
        return period_windows(
            W,
            s,
            e,
            steps,
            n_poses=self.n_poses,
            stride=self.stride,
            min_windows=self.min_windows,
            resize=self.resize,
        )

    def _decide(self, X):
        check_is_fitted(self)
        steps = self._check_steps()
        if check_lazy_windows(X, steps, self.n_poses, self, reset=False):
            masks = [W.rest_rows() for W in X]  # as untracked_rows of the dense
        else:
            data = check_sequences(
                X, ndim=3, estimator=self, reset=False, dtype=np.float32
            )
            self._check_layout(data, steps)
            # A row is rest when it is masked or untracked (all zeros).
            masks = [
                untracked_rows(x if isinstance(x, np.ma.MaskedArray) else W)
                for x, W in zip(X, data)
            ]
            X = data
        # Gather the windows of every period of every sequence, score them in
        # one call per scale, then apply the decision rules period by period.
        periods, wins = [], []
        for i, (W, rest) in enumerate(zip(X, masks)):
            starts, ends, vals = runs(rest)
            bounds = [(s, e) for s, e, v in zip(starts, ends, vals) if not v]
            for s, e in bounds:
                w, centres, resized = self._windows(W, s, e, steps)
                # A resized period's centres are in its resized frames (§5.3).
                periods.append(
                    (i, s, e, centres - (0 if resized else s), len(w), resized)
                )
                wins.append(w)
        scores = np.zeros((0, len(self.classes_)))
        if wins:
            fused = self._fusion_weights(len(steps))
            # The windows hold validated (finite) descriptors: the networks
            # need not scan them again.
            with config_context(assume_finite=True):
                scores = sum(
                    wk * est.predict_proba(scale_matrix(wins, k))
                    for k, (wk, est) in enumerate(zip(fused, self.estimators_))
                )
        out = [(np.zeros(len(W), dtype=np.int64), []) for W in X]
        pos = 0
        for i, s, e, centres, n, resized in periods:
            segs = self._period_segments(scores[pos : pos + n], centres, e - s, resized)
            pos += n
            # The labels of a period are its segments (decide_period reads the
            # segments off its labels, which are rest elsewhere).
            for c, a, b, conf in segs:
                label = self.classes_[c - 1]
                out[i][0][s + a : s + b] = label
                out[i][1].append((label, s + a, s + b, conf))
        return [(lab, np.array(segs, dtype=float).reshape(-1, 4)) for lab, segs in out]

    def __sklearn_tags__(self):
        return sequence_tags(super().__sklearn_tags__())

    # -- incremental step (docs/design.md, "Incremental steps") ----------------
    # The state (skgesture/_multiscale/_stream.py, MultiScaleStream) tracks periods,
    # scores windows as they complete and decides each period with
    # _period_segments, the decision of one period that _decide uses too.

    def _period_segments(self, scores, centres, length, resized, short_length=None):
        """Segments of one period: the paper's rules, as :meth:`predict` applies
        them (a resized period is decided on its resized frames and mapped
        back). ``short_length`` overrides the parameter (0: the long rule)."""
        steps = check_steps(self.steps, self.n_poses)
        half = max(steps) * (self.n_poses - 1) // 2
        n_resized = (
            2 * int(centres[0]) + 1 + self.stride * (len(centres) - 1)
            if resized
            else None
        )
        lab, segs = decide_period(
            scores,
            centres,
            length if n_resized is None else n_resized,
            short_length=self.short_length if short_length is None else short_length,
            threshold_short=self.threshold_short,
            threshold_long=self.threshold_long,
            min_consecutive=self.min_consecutive,
            half_span=half,
            original_length=length,
        )
        if n_resized is not None:  # back from the resized frames (§5.3)
            where = _resized_frames(length, n_resized, self.resize)
            lab, segs = _map_back(lab, segs, where)
        return segs

    _stream_options = ("max_period", "early_decision")

    def _stream_state(self, *, max_period=DEFAULT_MAX_PERIOD, early_decision=False):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Descriptor rows (masked at rest) with their lazy windows in; the
        gestures decided out. Periods are the runs of unmasked rows. The
        window centred at ``c`` is scored once frame ``c + hw`` is known to be
        in the period; a period is decided with the rules of :meth:`predict`
        when it ends, and in a period known to be long a run of windows is
        emitted as soon as no later window can change it (docs/streaming.md,
        "Delay").

        Parameters
        ----------
        max_period : int, default=1200
            A period this long (in frames) is closed and decided, and activity
            that continues opens a new one: it bounds memory and delay on a
            stream that never rests (offline ``predict`` has no cap).
        early_decision : bool, default=False
            Treat every period as long from its start: runs of windows are
            emitted without waiting ``short_length`` frames, and a period that
            ends short gets its majority vote only if nothing was emitted in
            it. Less delay, but the events may differ from ``predict``.

        Returns
        -------
        MultiScaleStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        check_is_fitted(self)
        steps = self._check_steps()
        return MultiScaleStream(
            self,
            steps,
            self._fusion_weights(len(steps)),
            self._period_segments,
            max_period=max_period,
            early_decision=early_decision,
        )

    @property
    def stream_lookahead(self):
        """Frames between a gesture's last frame and its decision, at most.

        Once the period is known to be long: ``2 hw + stride`` (10), ``hw`` the
        half span of the widest window (docs/streaming.md, "Delay").
        """
        steps = check_steps(self.steps, self.n_poses)
        return max(steps) * (self.n_poses - 1) + self.stride
