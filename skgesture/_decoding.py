"""Decoding of per-frame class probabilities into labels, shared by every tagger.

One path for :class:`~skgesture.BiLSTMTagger` (Method C),
:class:`~skgesture.SequenceTagger` and :class:`~skgesture.VotingTagger`:
smooth every class track, take the arg-max per frame, merge runs of one class
split by a short rest gap, set gesture runs shorter than ``min_run`` to rest,
and force untracked frames to rest. Only the network depends on the training,
so every decoding parameter can be changed after ``fit`` (and searched without
retraining when the network is cached).
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
from scipy.ndimage import uniform_filter1d

from skgesture.utils._segments import labels_to_segments, remove_short_runs, runs
from skgesture.utils._smoothing import loess_smooth

__all__ = ["decode", "fill_short_gaps", "segments_with_confidence", "smooth_proba"]

SMOOTHINGS = {"loess", "mean", "none"}


def smooth_proba(proba, span, smoothing="loess"):
    """Smooth every class track of ``(n_frames, n_classes)`` probabilities.

    Parameters
    ----------
    proba : ndarray of shape (n_frames, n_classes)
        Per-frame probabilities.
    span : int or float
        Window in frames (a float below 1 is a fraction of the sequence, for
        ``"loess"``); 1 or less leaves ``proba`` unchanged.
    smoothing : {"loess", "mean", "none"}, default="loess"
        MATLAB-style loess (Method C), a centred moving average (edges
        replicated), or nothing.

    Returns
    -------
    ndarray of shape (n_frames, n_classes)
        Smoothed probabilities.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._decoding import smooth_proba
    >>> p = np.array([[1.0, 0], [0, 1], [1, 0]])
    >>> smooth_proba(p, 3, "mean").round(3).tolist()
    [[0.667, 0.333], [0.667, 0.333], [0.667, 0.333]]
    """
    if smoothing == "none" or len(proba) == 0:
        return proba
    if smoothing == "loess":
        return np.asarray(loess_smooth(proba, span, axis=0))
    size = int(span)
    if size <= 1:
        return proba
    return uniform_filter1d(proba, size, axis=0, mode="nearest")


def fill_short_gaps(labels, max_gap, *, rest=0):
    """Merge two runs of one class separated by at most ``max_gap`` rest frames.

    Parameters
    ----------
    labels : ndarray of shape (n_frames,)
        Per-frame labels.
    max_gap : int
        Longest rest gap filled; 0 changes nothing.
    rest : int, default=0
        The rest label.

    Returns
    -------
    ndarray of shape (n_frames,)
        Labels with the short gaps given the class around them.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._decoding import fill_short_gaps
    >>> fill_short_gaps(np.array([2, 2, 0, 2, 0, 0, 0, 2]), 2).tolist()
    [2, 2, 2, 2, 0, 0, 0, 2]
    """
    labels = np.array(labels, copy=True)
    if max_gap <= 0:
        return labels
    starts, ends, values = runs(labels)
    for k in range(1, len(values) - 1):
        if (
            values[k] == rest
            and ends[k] - starts[k] <= max_gap
            and values[k - 1] == values[k + 1] != rest
        ):
            labels[starts[k] : ends[k]] = values[k - 1]
    return labels


def decode(
    proba,
    classes,
    *,
    smooth_span=1,
    smoothing="loess",
    min_run=1,
    max_gap=0,
    untracked=None,
):
    """Per-frame labels of one sequence from its class probabilities.

    Parameters
    ----------
    proba : ndarray of shape (n_frames, n_classes)
        Raw per-frame probabilities, columns in ``classes`` order.
    classes : ndarray of shape (n_classes,)
        Labels of the columns, rest (0) first.
    smooth_span : int or float, default=1
        Span of :func:`smooth_proba`.
    smoothing : {"loess", "mean", "none"}, default="loess"
        Smoothing method.
    min_run : int, default=1
        Shortest gesture run kept; shorter runs become rest.
    max_gap : int, default=0
        Rest gaps of at most this many frames between two runs of one class
        are filled before the ``min_run`` filter.
    untracked : ndarray of bool of shape (n_frames,) or None, default=None
        Frames forced to rest (lost tracking is never a gesture).

    Returns
    -------
    ndarray of shape (n_frames,)
        Labels from ``classes``.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._decoding import decode
    >>> p = np.array([[0.9, 0.1]] * 3 + [[0.2, 0.8]] * 4 + [[0.9, 0.1]])
    >>> decode(p, np.array([0, 5]), min_run=3).tolist()
    [0, 0, 0, 5, 5, 5, 5, 0]
    >>> decode(p, np.array([0, 5]), min_run=5).tolist()
    [0, 0, 0, 0, 0, 0, 0, 0]
    """
    smoothed = smooth_proba(proba, smooth_span, smoothing)
    labels = np.asarray(classes)[np.argmax(smoothed, axis=1)]
    if untracked is not None and np.any(untracked):
        labels[untracked] = 0
    labels = fill_short_gaps(labels, max_gap)
    labels = remove_short_runs(labels, min_run)
    if untracked is not None and np.any(untracked):
        labels[untracked] = 0
    return labels


def segments_with_confidence(labels, proba, classes):
    """Gesture instances of decoded labels, with the mean probability of each.

    Parameters
    ----------
    labels : ndarray of shape (n_frames,)
        Decoded labels.
    proba : ndarray of shape (n_frames, n_classes)
        Raw probabilities, columns in ``classes`` order.
    classes : ndarray of shape (n_classes,)
        Labels of the columns.

    Returns
    -------
    ndarray of shape (n_segments, 4)
        Rows ``(class, start, end, confidence)``, 0-based, ``end`` exclusive.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._decoding import segments_with_confidence
    >>> p = np.array([[1.0, 0.0], [0.2, 0.8], [0.4, 0.6]])
    >>> segments_with_confidence(np.array([0, 3, 3]), p, np.array([0, 3])).tolist()
    [[3.0, 1.0, 3.0, 0.7]]
    """
    rows = [
        (c, s, e, float(proba[s:e, np.searchsorted(classes, c)].mean()))
        for c, s, e in labels_to_segments(labels)
    ]
    return np.array(rows, dtype=float).reshape(-1, 4)
