"""MultiScaleClassifier: one window network per time scale, fused, then the
paper's decision rules inside every period of activity (Methods A and B)."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, _fit_context
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions
from sklearn.utils.validation import check_is_fitted

from skgesture._mlp import TorchMLPClassifier
from skgesture._networks import fit_inner_estimator
from skgesture._windows import N_POSES, STEPS_A, check_steps, dynamic_poses
from skgesture.utils._resize import resize_frames
from skgesture.utils._segments import labels_to_segments, runs
from skgesture.utils._validation import check_sequence_labels, check_sequences

__all__ = ["MultiScaleClassifier", "decide_period", "period_windows"]

# METHOD_SPEC §5.4
WINDOW_HIDDEN = (300, 100)
WINDOW_ACTIVATIONS = ("tanh", "tanh")
# METHOD_SPEC §5.2-5.5 (Method A numbers; Method B in the factory)
STRIDE = 2
MIN_WINDOWS = 5
SHORT_LENGTH = 55
THRESHOLD_SHORT_A = 0.8717
THRESHOLD_LONG_A = 0.6255
MIN_CONSECUTIVE = 3


def _row_mask(x):
    """Per-row rest mask of a masked sequence, or None for a plain array."""
    mask = np.ma.getmask(x)
    if mask is np.ma.nomask:
        return None if not isinstance(x, np.ma.MaskedArray) else np.zeros(len(x), bool)
    return mask.reshape(len(x), -1)[:, 0].copy()


def default_window_network():
    """The paper's window network: 300 (tanh) - 100 (tanh) - K (softmax)."""
    return TorchMLPClassifier(
        hidden_layer_sizes=WINDOW_HIDDEN, activations=WINDOW_ACTIVATIONS
    )


def period_windows(
    W,
    start,
    end,
    steps,
    *,
    n_poses=N_POSES,
    stride=STRIDE,
    min_windows=MIN_WINDOWS,
    resize="bicubic",
):
    """Windows of one period ``[start, end)`` at the centres the paper uses.

    Centres run from ``start + h`` to ``end - 1 - h`` every ``stride`` frames, with
    ``h`` the half span of the widest scale (METHOD_SPEC §5.2, §6.2). A period
    with fewer than ``min_windows`` centres is resized along time (cubic, §5.3)
    to the shortest length that has ``min_windows``, and its windows are taken
    there.

    Parameters
    ----------
    W : ndarray of shape (n_frames, n_scales, n_poses * n_features)
        Dynamic poses of every frame of the sequence.
    start, end : int
        The period, ``end`` exclusive.
    steps : tuple of int
        Time step of each scale (as used to build ``W``).
    n_poses, stride, min_windows : int
        Window layout.
    resize : {"bicubic", "pchip", "spline"}, default="bicubic"
        Resampling of short periods (decision D15).

    Returns
    -------
    windows : ndarray of shape (n_windows, n_scales, n_poses * n_features)
        The windows.
    centres : ndarray of shape (n_windows,)
        Their centre frames (in the resized period for a short one).
    resized : bool
        Whether the period was resized.
    """
    h = max(steps) * (n_poses - 1) // 2
    centres = np.arange(start + h, end - h, stride)
    if len(centres) >= min_windows:
        return np.asarray(W[centres]), centres, False
    n_features = W.shape[2] // n_poses
    middle = (n_poses - 1) // 2
    # Every row holds its own frame's descriptor as the middle pose.
    D = np.asarray(W[start:end, 0, middle * n_features : (middle + 1) * n_features])
    n_target = 2 * h + 1 + stride * (min_windows - 1)
    D = resize_frames(D.astype(np.float64), n_target, method=resize)
    centres = h + stride * np.arange(min_windows)
    return dynamic_poses(D, steps, n_poses, centres), centres, True


def decide_period(
    scores,
    centres,
    length,
    *,
    short_length=SHORT_LENGTH,
    threshold_short=THRESHOLD_SHORT_A,
    threshold_long=THRESHOLD_LONG_A,
    min_consecutive=MIN_CONSECUTIVE,
    half_span=4,
):
    """The paper's decision rule for one period of activity (METHOD_SPEC §5.5).

    * Short period (``length < short_length``): every window whose best score
      exceeds ``threshold_short`` votes for its best class; a class with strictly
      more than half the votes labels the whole period, otherwise (no votes,
      ties) the period stays rest.
    * Long period: a window counts for its best class when its score exceeds
      ``threshold_long``; each run of at least ``min_consecutive`` consecutive
      windows of one class labels the frames from its first window's start to
      its last window's end (``centre -+ half_span``). A frame claimed by two
      runs goes to the run with the nearest window centre, the earlier one on
      ties (decision D17).

    Parameters
    ----------
    scores : ndarray of shape (n_windows, n_classes)
        Fused class scores of the windows, in time order.
    centres : ndarray of shape (n_windows,)
        Window centres, relative to the period start.
    length : int
        Number of frames in the period.
    short_length : int, default=55
        Periods shorter than this get one label.
    threshold_short, threshold_long : float
        Score thresholds of the two rules.
    min_consecutive : int, default=3
        Shortest run of windows in a long period.
    half_span : int, default=4
        Half the span of a window, in frames.

    Returns
    -------
    labels : ndarray of shape (length,)
        Per-frame class index + 1 (0 = rest).
    segments : list of tuple
        ``(class index + 1, start, end, confidence)`` for every labelled run,
        relative to the period start, ``end`` exclusive; the confidence is the
        mean best score of the windows behind it.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._multiscale import decide_period
    >>> scores = np.array([[0.9, 0.1], [0.95, 0.05], [0.2, 0.8]])
    >>> labels, segs = decide_period(scores, np.array([4, 6, 8]), 20,
    ...                              threshold_short=0.7)
    >>> labels.tolist() == [1] * 20, segs[0][:3]
    (True, (1, 0, 20))
    """
    labels = np.zeros(length, dtype=np.int64)
    if len(scores) == 0:
        return labels, []
    best = np.argmax(scores, axis=1)
    top = scores[np.arange(len(scores)), best]
    if length < short_length:
        votes = best[top > threshold_short]
        if len(votes) == 0:
            return labels, []
        counts = np.bincount(votes)
        winner = int(np.argmax(counts))
        if counts[winner] * 2 <= len(votes):
            return labels, []  # no absolute majority (ties included)
        labels[:] = winner + 1
        conf = float(top[top > threshold_short][votes == winner].mean())
        return labels, [(winner + 1, 0, length, conf)]
    rec = np.where(top > threshold_long, best, -1)
    starts, ends, vals = runs(rec)
    owner_dist = np.full(length, np.inf)
    owner = np.full(length, -1)
    kept = []
    for s, e, v in zip(starts, ends, vals):
        if v < 0 or e - s < min_consecutive:
            continue
        c = centres[s:e]
        lo, hi = max(int(c[0]) - half_span, 0), min(int(c[-1]) + half_span + 1, length)
        frames = np.arange(lo, hi)
        dist = np.abs(frames[:, None] - c[None, :]).min(axis=1)
        win = dist < owner_dist[lo:hi]  # strict: the earlier run keeps ties
        owner[lo:hi][win] = len(kept)
        owner_dist[lo:hi][win] = dist[win]
        kept.append((int(v) + 1, float(top[s:e].mean())))
    # Segments are read off the final ownership, so they agree with the labels.
    segments = []
    o_starts, o_ends, o_vals = runs(owner)
    for a, b, r in zip(o_starts, o_ends, o_vals):
        if r >= 0:
            cls, conf = kept[r]
            labels[a:b] = cls
            segments.append((cls, int(a), int(b), conf))
    return labels, segments


class MultiScaleClassifier(ClassifierMixin, BaseEstimator):
    """Dynamic-pose classifier at one or more time scales, with the paper's rules.

    Fits one clone of ``estimator`` per time scale on the windows of every
    training gesture instance, fuses the scales' class probabilities with
    ``weights`` and labels each period of activity with the paper's short/long
    rules. With one scale and the default numbers it is Method A; with
    ``steps=(4, 3, 2)``, ``weights=(0.4895, 0.4576, 0.0529)`` and thresholds
    0.6014 / 0.6033 it is Method B (METHOD_SPEC §5-6).

    Periods of activity are the runs of unmasked rows of a masked input (from
    :class:`ActivitySegmenter`); a plain array is one period, so pre-cut clips
    work without a segmenter.

    Parameters
    ----------
    estimator : classifier or None, default=None
        2-D classifier with ``predict_proba``, cloned for each scale. ``None``
        uses the paper's network, :class:`TorchMLPClassifier` 300 (tanh) - 100
        (tanh) - K (softmax) trained with scaled conjugate gradient.
    steps : tuple of int, default=(4,)
        Time step of each scale; must match the :class:`DynamicPoseWindow`
        that built the input.
    weights : tuple of float or None, default=None
        Fusion weight of each scale, normalised to sum to 1; equal when None.
    n_poses : int, default=3
        Descriptors per dynamic pose.
    stride : int, default=2
        Frames between window centres.
    min_windows : int, default=5
        Periods with fewer windows are resized along time first.
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
        Verbosity.

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
        "steps": [tuple, list],
        "weights": [tuple, list, np.ndarray, None],
        "n_poses": [Interval(Integral, 1, None, closed="left")],
        "stride": [Interval(Integral, 1, None, closed="left")],
        "min_windows": [Interval(Integral, 1, None, closed="left")],
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
            a training instance.

        Returns
        -------
        self : MultiScaleClassifier
            The fitted classifier.
        """
        steps = self._check_steps()
        X = check_sequences(X, ndim=3, estimator=self, reset=True, dtype=np.float32)
        self._check_layout(X[0], steps)
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
        wins = np.concatenate(wins)
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
                self.estimator, default, wins[:, k], labels, rng=rng, memory=self.memory
            )
            for k in range(len(steps))
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
        steps = check_steps(self.steps, self.n_poses)
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=float)
            if w.shape != (len(steps),):
                raise ValueError(
                    f"weights has {w.size} values but steps has {len(steps)} scales"
                )
            if np.any(w < 0) or w.sum() <= 0:
                raise ValueError(
                    f"weights must be non-negative and not all 0, got {self.weights}"
                )
        return steps

    def _fusion_weights(self, n_scales):
        if self.weights is None:
            return np.full(n_scales, 1.0 / n_scales)
        w = np.asarray(self.weights, dtype=float)
        return w / w.sum()

    def _check_layout(self, W, steps):
        """The input must come from windows with this classifier's steps."""
        if W.shape[1] != len(steps):
            raise ValueError(
                f"X has {W.shape[1]} scales per frame but steps={tuple(steps)} has "
                f"{len(steps)}: build X with DynamicPoseWindow(steps={tuple(steps)})"
            )
        F = W.shape[2] // self.n_poses
        if W.shape[2] != F * self.n_poses:
            raise ValueError(
                f"window width {W.shape[2]} is not a multiple of n_poses={self.n_poses}"
            )
        T = len(W)
        mid = (self.n_poses - 1) // 2
        for k, s in enumerate(steps):
            t = min(max(steps), T - 1)
            if t - s < 0 or T <= max(steps) * 2:
                continue
            first = np.asarray(W[t, k, :F])
            expect = np.asarray(W[t - s * mid, 0, mid * F : (mid + 1) * F])
            if not np.allclose(first, expect, atol=1e-6):
                raise ValueError(
                    f"X does not look like dynamic poses with steps={tuple(steps)} "
                    f"(scale {k}): use the same steps in DynamicPoseWindow and "
                    f"MultiScaleClassifier"
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
        # A row is rest when it is masked (the first value of a row decides).
        masks = [_row_mask(x) for x in X]
        X = check_sequences(X, ndim=3, estimator=self, reset=False, dtype=np.float32)
        # Gather the windows of every period of every sequence, score them in
        # one call per scale, then apply the decision rules period by period.
        periods, wins = [], []
        for i, (W, rest) in enumerate(zip(X, masks)):
            if rest is None:
                bounds = [(0, len(W))]
            else:
                starts, ends, vals = runs(rest)
                bounds = [(s, e) for s, e, v in zip(starts, ends, vals) if not v]
            for s, e in bounds:
                w, centres, resized = self._windows(W, s, e, steps)
                periods.append((i, s, e, centres - (0 if resized else s), len(w)))
                wins.append(w)
        scores = np.zeros((0, len(self.classes_)))
        if wins:
            allw = np.concatenate(wins)
            fused = self._fusion_weights(len(steps))
            scores = sum(
                wk * est.predict_proba(allw[:, k])
                for k, (wk, est) in enumerate(zip(fused, self.estimators_))
            )
        half = max(steps) * (self.n_poses - 1) // 2
        out = [(np.zeros(len(W), dtype=np.int64), []) for W in X]
        pos = 0
        for i, s, e, centres, n in periods:
            lab, segs = decide_period(
                scores[pos : pos + n],
                centres,
                e - s,
                short_length=self.short_length,
                threshold_short=self.threshold_short,
                threshold_long=self.threshold_long,
                min_consecutive=self.min_consecutive,
                half_span=half,
            )
            pos += n
            nz = lab > 0
            out[i][0][s:e][nz] = self.classes_[lab[nz] - 1]
            out[i][1].extend(
                (self.classes_[c - 1], s + a, s + b, conf) for c, a, b, conf in segs
            )
        return [(lab, np.array(segs, dtype=float).reshape(-1, 4)) for lab, segs in out]

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        return tags
