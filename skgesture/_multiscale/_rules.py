"""The paper's decision rules of Methods A and B (docs/method.md §5).

Windows of a period of activity (with the cubic resizing of a short period),
and the decision of a period from its windows' fused scores."""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture._windows import (
    N_POSES,
    DynamicPoses,
    PeriodWindows,
    dynamic_poses,
)
from skgesture.utils._resize import resize_frames
from skgesture.utils._segments import runs

# docs/method.md §5.2-5.5 (Method A numbers; Method B in the factory)
STRIDE = 2


MIN_WINDOWS = 5


SHORT_LENGTH = 55


THRESHOLD_SHORT_A = 0.8717


THRESHOLD_LONG_A = 0.6255


MIN_CONSECUTIVE = 3


# Bounds that keep a resized short period small (docs/design.md §1.2).
MAX_MIN_WINDOWS = 1000


MAX_RESIZED_LENGTH = 10_000


def _resized_frames(n_frames, n_resized, method):
    """Position in a period resized to ``n_resized`` frames of each original frame.

    The inverse of the resampling's coordinate map, rounded to the nearest
    resized frame: ``imresize``'s pixel-centre map for ``"bicubic"``, the
    end-to-end ``linspace`` map for ``"pchip"`` and ``"spline"``.
    """
    t = np.arange(n_frames, dtype=float)
    if method == "bicubic":
        u = (t + 0.5) * (n_resized / n_frames) - 0.5
    elif n_frames > 1:
        u = t * (n_resized - 1) / (n_frames - 1)
    else:
        u = np.full(n_frames, (n_resized - 1) / 2)
    return np.clip(np.rint(u), 0, n_resized - 1).astype(np.intp)


def _map_back(labels, segments, where):
    """Labels and segments of a resized period on its original frames.

    ``where[t]`` is the resized frame of original frame ``t`` (non-decreasing).
    """
    out = labels[where]
    mapped = []
    for cls, a, b, conf in segments:
        lo, hi = np.searchsorted(where, [a, b], side="left")
        if hi > lo:
            mapped.append((cls, int(lo), int(hi), conf))
    return out, mapped


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
    ``h`` the half span of the widest scale (docs/method.md §5.2, §6.2). A period
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
    lazy = isinstance(W, DynamicPoses)  # windows gathered later (scale_matrix)
    if len(centres) >= min_windows:
        if lazy:
            return PeriodWindows(W.descriptors, centres, steps, n_poses), centres, False
        return np.asarray(W[centres]), centres, False
    n_features = W.shape[2] // n_poses
    middle = (n_poses - 1) // 2
    # Every row holds its own frame's descriptor as the middle pose.
    if lazy:
        D = W.descriptors[start:end]
    else:
        D = np.asarray(W[start:end, 0, middle * n_features : (middle + 1) * n_features])
    n_target = 2 * h + 1 + stride * (min_windows - 1)
    D = resize_frames(D.astype(np.float64), n_target, method=resize)
    centres = h + stride * np.arange(min_windows)
    if lazy:
        return PeriodWindows(D, centres, steps, n_poses), centres, True
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
    original_length=None,
):
    """The paper's decision rule for one period of activity (docs/method.md §5.5).

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
    original_length : int or None, default=None
        For a period resized to ``length`` frames: its original length, which
        decides between the short and the long rule (``None``: ``length``).
        Everything else stays in the resized frames.

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
    >>> from skgesture._multiscale._rules import decide_period
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
    if (length if original_length is None else original_length) < short_length:
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
