"""Conversions between per-frame labels and gesture instances (segments).

A segment is one row ``(class, start, end)`` of an integer array of shape
``(n_segments, 3)``: 0-based ``start``, **exclusive** ``end`` (a Python slice),
``class >= 1``. The ChaLearn files use 1-based inclusive frames; the loaders and
the writer convert (``start + 1``, ``end``).
"""

# SPDX-License-Identifier: BSD-3-Clause

import numbers
import warnings

import numpy as np

__all__ = [
    "labels_to_segments",
    "segments_to_labels",
    "check_segments",
    "runs",
    "remove_short_runs",
]


def _integral(arr):
    """Mask of the entries of a numeric array that are whole numbers."""
    if np.issubdtype(arr.dtype, np.integer) or arr.dtype == bool:
        return np.ones(arr.shape, dtype=bool)
    with np.errstate(invalid="ignore"):
        return np.isfinite(arr) & (arr == np.round(arr))


def _as_numbers(values, name):
    arr = np.asarray(values)
    if (
        arr.dtype == object
        or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool)
        or np.iscomplexobj(arr)
    ):
        raise ValueError(f"{name} must hold integers, got dtype {arr.dtype}")
    return arr


def _check_n_frames(n_frames):
    if (
        not isinstance(n_frames, numbers.Integral)
        or isinstance(n_frames, bool)
        or n_frames < 0
    ):
        raise ValueError(f"n_frames must be a non-negative integer, got {n_frames!r}")
    return int(n_frames)


def check_segments(segments, n_frames, *, name="segments"):
    """Validate segments ``(class, start, end)`` of a sequence of ``n_frames``.

    Parameters
    ----------
    segments : array-like of shape (n_segments, 3)
        Rows ``(class, start, end)``, 0-based, ``end`` exclusive; floats are
        accepted when they are whole numbers.
    n_frames : int
        Length of the sequence.
    name : str, default="segments"
        Name used in error messages.

    Returns
    -------
    ndarray of int64 of shape (n_segments, 3)
        A validated copy.

    Raises
    ------
    ValueError
        Naming the row, for a shape other than ``(n, 3)``, a value that is not
        a whole number, a class below 1 or bounds outside
        ``0 <= start < end <= n_frames``.

    Examples
    --------
    >>> from skgesture.utils._segments import check_segments
    >>> check_segments([[3, 1.0, 3]], 8).tolist()
    [[3, 1, 3]]
    """
    n_frames = _check_n_frames(n_frames)
    arr = _as_numbers(segments, name)
    if arr.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(
            f"{name} must have shape (n_segments, 3) with rows (class, start, end); "
            f"got shape {arr.shape}"
        )
    whole = _integral(arr).all(axis=1)
    if not whole.all():
        row = int(np.argmin(whole))
        raise ValueError(
            f"{name} row {row} = {tuple(arr[row].tolist())} holds a value that is "
            f"not a whole number (class, start and end are integers)"
        )
    if np.abs(arr).max() > np.iinfo(np.int64).max:
        row = int(np.argmax(np.abs(arr).max(axis=1)))
        raise ValueError(f"{name} row {row} = {tuple(arr[row].tolist())} overflows")
    seg = arr.astype(np.int64)
    for row, (c, s, e) in enumerate(seg.tolist()):
        if c < 1:
            raise ValueError(
                f"{name} row {row} has class {c}; gesture classes are >= 1"
            )
        if s < 0 or e > n_frames or s >= e:
            raise ValueError(
                f"{name} row {row} = ({c}, {s}, {e}) is outside 0 <= start < end <= "
                f"{n_frames}"
            )
    return seg


def runs(values):
    """Maximal runs of equal values in a 1-D array.

    Parameters
    ----------
    values : array-like of shape (n,)
        The values.

    Returns
    -------
    starts, ends, vals : ndarray
        Run starts (inclusive), ends (exclusive) and their values.

    Examples
    --------
    >>> from skgesture.utils import runs
    >>> [a.tolist() for a in runs([0, 0, 2, 2, 2, 0])]
    [[0, 2, 5], [2, 5, 6], [0, 2, 0]]
    """
    v = np.asarray(values)
    if v.size == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, v[:0]
    change = np.flatnonzero(v[1:] != v[:-1]) + 1
    starts = np.concatenate(([0], change))
    ends = np.concatenate((change, [v.size]))
    return starts, ends, v[starts]


def labels_to_segments(y, *, rest=0):
    """Turn per-frame labels into gesture instances.

    Each maximal run of one non-rest label becomes one segment.

    Parameters
    ----------
    y : array-like of shape (n_frames,)
        Per-frame labels.
    rest : int, default=0
        The rest label.

    Returns
    -------
    ndarray of shape (n_segments, 3)
        Rows ``(class, start, end)``, 0-based, ``end`` exclusive, sorted by start.

    Raises
    ------
    ValueError
        If ``y`` is not 1-D or holds a value that is not a whole number (NaN,
        1.7), naming the frame.

    Examples
    --------
    >>> from skgesture.metrics import labels_to_segments
    >>> labels_to_segments([0, 3, 3, 0, 5, 5, 5]).tolist()
    [[3, 1, 3], [5, 4, 7]]
    """
    arr = _as_numbers(y, "y")
    if arr.ndim != 1:
        raise ValueError(f"y must be 1-D (one label per frame), got shape {arr.shape}")
    whole = _integral(arr)
    if not whole.all():
        frame = int(np.argmin(whole))
        raise ValueError(
            f"y must hold integer class labels: frame {frame} has {arr[frame]!r}"
        )
    starts, ends, vals = runs(arr.astype(np.int64))
    keep = vals != rest
    return np.stack([vals[keep], starts[keep], ends[keep]], axis=1).reshape(-1, 3)


def segments_to_labels(segments, n_frames, *, on_overlap="raise"):
    """Turn gesture instances into per-frame labels.

    Parameters
    ----------
    segments : array-like of shape (n_segments, 3)
        Rows ``(class, start, end)``, 0-based, ``end`` exclusive.
    n_frames : int
        Length of the sequence.
    on_overlap : {"raise", "warn", "later"}, default="raise"
        What to do with frames claimed by two segments: raise a ``ValueError``,
        warn and let the later segment win, or let it win silently.

    Returns
    -------
    ndarray of shape (n_frames,)
        Per-frame labels, 0 outside every segment.

    Raises
    ------
    ValueError
        For a negative or non-integer ``n_frames``, or a bad row (see
        :func:`check_segments`): a shape other than ``(n, 3)``, a bound that is
        not a whole number, a class below 1, bounds outside
        ``0 <= start < end <= n_frames``, or (``on_overlap="raise"``) an overlap.

    Examples
    --------
    >>> from skgesture.metrics import segments_to_labels
    >>> segments_to_labels([[3, 1, 3], [5, 4, 7]], 8).tolist()
    [0, 3, 3, 0, 5, 5, 5, 0]
    """
    if on_overlap not in ("raise", "warn", "later"):
        raise ValueError(
            f"on_overlap must be 'raise', 'warn' or 'later', got {on_overlap!r}"
        )
    seg = check_segments(segments, n_frames, name="segments")
    y = np.zeros(int(n_frames), dtype=np.int64)
    claimed = np.zeros(int(n_frames), dtype=bool)
    for row, (c, s, e) in enumerate(seg.tolist()):
        if claimed[s:e].any():
            frame = s + int(np.argmax(claimed[s:e]))
            msg = (
                f"segment {row} = ({c}, {s}, {e}) overlaps an earlier segment at "
                f"frame {frame}"
            )
            if on_overlap == "raise":
                raise ValueError(msg)
            if on_overlap == "warn":
                warnings.warn(msg + "; the later segment wins", stacklevel=2)
        y[s:e] = c
        claimed[s:e] = True
    return y


def remove_short_runs(labels, min_length, *, rest=0):
    """Set every run of one non-rest label shorter than ``min_length`` to ``rest``.

    Parameters
    ----------
    labels : array-like of shape (n_frames,)
        Per-frame labels.
    min_length : int
        Shortest run kept.
    rest : int, default=0
        The rest label.

    Returns
    -------
    ndarray of shape (n_frames,)
        A filtered copy.

    Examples
    --------
    >>> from skgesture.utils import remove_short_runs
    >>> remove_short_runs([0, 2, 2, 0, 3, 3, 3, 3], 3).tolist()
    [0, 0, 0, 0, 3, 3, 3, 3]
    """
    out = np.array(labels, copy=True)
    starts, ends, vals = runs(out)
    for s, e, v in zip(starts, ends, vals):
        if v != rest and e - s < min_length:
            out[s:e] = rest
    return out


def _chunks(n_frames, window, overlap):
    """``(start, end)`` of the inference chunks of a sequence (docs/method.md §7.4).

    Without overlap: consecutive non-overlapping chunks, the last one shorter.
    With overlap: full windows every ``window // 2`` frames plus one ending at
    the last frame, so that every frame is covered (one chunk if the sequence
    is shorter than a window).
    """
    if not overlap or n_frames <= window:
        starts = np.arange(0, n_frames, window)
        return [(int(s), int(min(s + window, n_frames))) for s in starts]
    step = max(window // 2, 1)
    starts = list(range(0, n_frames - window + 1, step))
    if starts[-1] != n_frames - window:
        starts.append(n_frames - window)
    return [(s, s + window) for s in starts]


def to_file_lines(segments):
    """The ``(class, start, end)`` lines of a label file, from segments.

    The package's segments are 0-based with an exclusive end; the ChaLearn
    label and prediction files are 1-based with an inclusive end
    (docs/method.md §1.7), so the start gains one and the end stays (the
    exclusive 0-based end is the 1-based number of the last frame). The one
    conversion of the package; :func:`from_file_lines` is its inverse.

    Parameters
    ----------
    segments : array-like of int of shape (n, 3)
        ``(class, start, end)`` rows, 0-based, end exclusive.

    Returns
    -------
    ndarray of int64 of shape (n, 3)
        A new array of 1-based inclusive rows.

    Examples
    --------
    >>> from skgesture.utils._segments import from_file_lines, to_file_lines
    >>> to_file_lines([[3, 0, 10]]).tolist()
    [[3, 1, 10]]
    >>> from_file_lines([[3, 1, 10]]).tolist()
    [[3, 0, 10]]
    """
    lines = np.array(segments, dtype=np.int64).reshape(-1, 3)
    lines[:, 1] += 1
    return lines


def from_file_lines(lines):
    """Segments (0-based, end exclusive) from 1-based inclusive file lines.

    The inverse of :func:`to_file_lines`.

    Parameters
    ----------
    lines : array-like of int of shape (n, 3)
        ``(class, start, end)`` lines, 1-based, end inclusive.

    Returns
    -------
    ndarray of int64 of shape (n, 3)
        A new array of 0-based rows with an exclusive end.
    """
    segments = np.array(lines, dtype=np.int64).reshape(-1, 3)
    segments[:, 1] -= 1
    return segments
