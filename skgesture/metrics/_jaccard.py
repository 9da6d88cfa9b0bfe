"""The ChaLearn LAP 2014 Track 3 Jaccard index, as the official script computes it.

One private function, :func:`_jaccard_from_lines`, holds the formula. It works on
the lines of the label and prediction files (``class, start, end``, 1-based,
end inclusive by the file format) and reproduces the official script's quirks
(docs/method.md §2.1-§2.2). :func:`jaccard_index_segments` exposes it for one
sequence given as lines; :func:`jaccard_index` turns per-frame labels into lines
(one line per maximal run of a gesture label, docs/method.md §1.7) and averages over
sequences.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numbers
import warnings

import numpy as np
from sklearn.exceptions import UndefinedMetricWarning

from skgesture.metrics._segmental import REST, _check_label_pairs
from skgesture.utils._segments import check_segments, labels_to_segments, to_file_lines

__all__ = ["jaccard_index", "jaccard_index_segments"]

N_OFFICIAL_CLASSES = 20  # docs/method.md §2.1: the script's 20 x n frame matrices
JACCARD_MODES = ("official_2014", "fp_penalised", "inclusive")  # docs/method.md §2.3


def _check_mode(mode):
    if not isinstance(mode, str) or mode not in JACCARD_MODES:
        raise ValueError(
            f"mode must be one of {', '.join(repr(m) for m in JACCARD_MODES)}; "
            f"got {mode!r}"
        )


def _check_positive_int(value, name):
    if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _check_lines(lines, name, n_classes):
    """Validate file lines ``(class, start, end)`` and return an int64 array."""
    if lines is None:
        return np.zeros((0, 3), dtype=np.int64)
    arr = np.asarray(lines)
    if arr.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(
            f"{name} must have shape (n_lines, 3) with rows (class, start, end); "
            f"got shape {arr.shape}"
        )
    if not np.issubdtype(arr.dtype, np.integer):
        if (
            not np.issubdtype(arr.dtype, np.number)
            or not np.all(np.isfinite(arr))
            or np.any(arr != np.round(arr))
        ):
            raise ValueError(f"{name} must hold integers, got dtype {arr.dtype}")
    arr = arr.astype(np.int64)
    for row, (c, s, e) in enumerate(arr.tolist()):
        if c > n_classes:
            raise ValueError(
                f"{name} row {row} = ({c}, {s}, {e}) has class {c} > n_classes="
                f"{n_classes} (the official script fails with an IndexError)"
            )
        if c < 0:
            raise ValueError(
                f"{name} row {row} = ({c}, {s}, {e}) has a negative class id"
            )
    lossy = [tuple(r) for r in arr.tolist() if r[0] == 0 or r[1] < 1]
    if lossy:
        warnings.warn(
            f"{name} has lines with class 0 or start frame < 1: {lossy}. They are "
            f"scored as the official script does: class 0 is written into the "
            f"row of class {n_classes} and a start frame s < 1 indexes from the end "
            f"of the sequence (start 0 usually loses the gesture). Writers should "
            f"clamp 1 <= class and 1 <= start <= end <= n_frames.",
            UserWarning,
            stacklevel=3,
        )
    return arr


def _jaccard_from_lines(gt, pred, n_frames, mode, n_rows):
    """Score of one sequence from validated lines (docs/method.md §2.1, §2.3).

    Parameters
    ----------
    gt, pred : ndarray of shape (n_lines, 3)
        Rows ``(class, start, end)``, 1-based, as in the files.
    n_frames : int
        Number of frames of the sequence.
    mode : str
        One of ``JACCARD_MODES``.
    n_rows : int
        Rows of the frame matrices (20 in the official script).

    Returns
    -------
    score : float
        The sequence score; NaN when ``gt`` has no line (the official script
        divides by zero).
    degenerate : list of int
        Ground-truth classes with an empty union (no frame in either matrix),
        scored 0 instead of the script's NaN.
    """
    # The official script slices [s - 1, e - 1): the labelled end frame is dropped.
    # Plain Python slicing reproduces its clipping and negative-start behaviour.
    # Only the rows of the ground-truth classes are built, one at a time, so the
    # memory is O(n_frames) whatever the class ids (the script's matrices have
    # n_rows x n_frames cells; a class id of 1e9 would ask for 93 GiB).
    stop_shift = 0 if mode == "inclusive" else 1

    def row_frames(lines, row):
        """Frames of matrix row ``row``: class c is written in row c - 1, so
        class 0 lands in row -1, the last one, as in the script."""
        frames = np.zeros(n_frames, dtype=bool)
        for c, s, e in lines[(lines[:, 0] - 1) % n_rows == row].tolist():
            frames[s - 1 : e - stop_shift] = True
        return frames

    gt_classes = np.unique(gt[:, 0])
    if gt_classes.size == 0:
        return float("nan"), []
    overlaps, degenerate = [], []
    for c in gt_classes.tolist():
        row = (c - 1) % n_rows
        g, p = row_frames(gt, row), row_frames(pred, row)
        union = int(np.count_nonzero(g | p))
        if union == 0:
            degenerate.append(c)
            overlaps.append(0.0)
        else:
            overlaps.append(int(np.count_nonzero(g & p)) / union)
    n_false_pos = 0
    if mode == "fp_penalised":
        n_false_pos = np.setdiff1d(np.unique(pred[:, 0]), gt_classes).size
    # The script's own "false positives", setdiff(gt, union(gt, pred)), are always
    # empty (docs/method.md §2.1 step 5), so official and inclusive add nothing.
    return sum(overlaps) / (len(overlaps) + n_false_pos), degenerate


def _warn_degenerate(degenerate, where):
    warnings.warn(
        f"{where}: ground-truth class(es) {degenerate} have no frame left after "
        f"the end-frame exclusion and are not predicted; the official script "
        f"gives 0/0 = NaN, scored here as 0",
        UndefinedMetricWarning,
        stacklevel=3,
    )


def jaccard_index_segments(
    gt_segments, pred_segments, n_frames, *, mode="official_2014", n_classes=20
):
    """Jaccard index of one sequence from the lines of its label/prediction files.

    Reproduces the ChaLearn LAP 2014 Track 3 scorer on one sequence, quirks
    included: a line ``c, s, e`` marks frames ``s .. e-1`` (the labelled end
    frame is dropped) in the row of class ``c``; instances of one class are
    OR-ed; the score is the mean, over the classes present in the ground truth,
    of ``|G_c & P_c| / |G_c | P_c|``.

    Parameters
    ----------
    gt_segments : array-like of shape (n_gt_lines, 3)
        Ground-truth lines ``(class, start, end)``, 1-based frames, exactly as
        in ``SampleXXXX_labels.csv``. Overlapping lines are allowed.
    pred_segments : array-like of shape (n_pred_lines, 3)
        Predicted lines in the same format (``SampleXXXX_prediction.csv``). An
        empty array (or ``None``) is an empty prediction.
    n_frames : int
        Number of frames of the sequence (``numFrames`` of ``_data.csv``).
    mode : {"official_2014", "fp_penalised", "inclusive"}, default="official_2014"
        ``"official_2014"``: the script as it is; predicted classes absent from
        the ground truth are not penalised. ``"fp_penalised"``: each such class
        adds 1 to the denominator (the challenge web page's definition).
        ``"inclusive"``: frames ``s .. e`` including the end frame, otherwise
        official.
    n_classes : int, default=20
        Number of rows of the frame matrices; a class id above it raises a
        ``ValueError`` (the official script, with 20, fails with an
        ``IndexError``).

    Returns
    -------
    float
        The sequence score in [0, 1], or NaN (with an ``UndefinedMetricWarning``)
        when ``gt_segments`` is empty: the official script raises
        ``ZeroDivisionError`` there.

    See Also
    --------
    jaccard_index : The mean score over sequences given as per-frame labels.

    Notes
    -----
    Out-of-range frames are clipped at ``n_frames`` silently, as numpy slicing
    does in the script. A start frame ``s < 1`` gives the slice ``[s-1, e-1)``
    with a negative start, which counts from the end of the sequence: with
    ``s = 0`` the gesture is lost unless ``e - 1 >= n_frames``. Class 0 is
    written into row -1, i.e. shares the row of class ``n_classes``. Both are
    reproduced, with a ``UserWarning``. A ground-truth class with no frame left
    and not predicted (0/0 in the script) scores 0, with an
    ``UndefinedMetricWarning`` (docs/method.md §2.2).

    References
    ----------
    .. [1] S. Escalera et al., "ChaLearn Looking at People Challenge 2014:
       Dataset and Results", ECCV Workshops 2014.

    Examples
    --------
    The worked example of docs/method.md §2.4 (10 frames):

    >>> from skgesture.metrics import jaccard_index_segments
    >>> gt = [[3, 2, 6], [5, 7, 10]]
    >>> pred = [[3, 3, 6], [8, 7, 9]]
    >>> jaccard_index_segments(gt, pred, 10)
    0.375
    >>> jaccard_index_segments(gt, pred, 10, mode="fp_penalised")
    0.25
    >>> jaccard_index_segments(gt, pred, 10, mode="inclusive")
    0.4
    """
    _check_mode(mode)
    n_classes = _check_positive_int(n_classes, "n_classes")
    if (
        not isinstance(n_frames, numbers.Integral)
        or isinstance(n_frames, bool)
        or n_frames < 0
    ):
        raise ValueError(f"n_frames must be a non-negative integer, got {n_frames!r}")
    gt = _check_lines(gt_segments, "gt_segments", n_classes)
    pred = _check_lines(pred_segments, "pred_segments", n_classes)
    score, degenerate = _jaccard_from_lines(gt, pred, int(n_frames), mode, n_classes)
    if not gt.size:
        warnings.warn(
            "gt_segments is empty: the Jaccard index is undefined without a "
            "ground-truth gesture (the official script divides by zero); "
            "returning NaN",
            UndefinedMetricWarning,
            stacklevel=2,
        )
    if degenerate:
        _warn_degenerate(degenerate, "jaccard_index_segments")
    return score


def _labels_to_lines(y):
    """File lines of a per-frame labelling: one per maximal gesture run (§1.7)."""
    return to_file_lines(labels_to_segments(y, rest=REST))


def _true_segment_lines(true_segments, y_true):
    """File lines (1-based start, end inclusive) of ``true_segments``, or None."""
    if true_segments is None:
        return None
    if isinstance(true_segments, (str, bytes)) or not hasattr(true_segments, "__len__"):
        raise TypeError(
            f"true_segments must be a list of (n_i, 3) segment arrays, one per "
            f"sequence, got {type(true_segments).__name__}"
        )
    if len(true_segments) != len(y_true):
        raise ValueError(
            f"true_segments has {len(true_segments)} sequences but y_true has "
            f"{len(y_true)}: give one segment array per sequence"
        )
    lines = []
    for i, (seg, yt) in enumerate(zip(true_segments, y_true)):
        seg = check_segments(seg, len(yt), name=f"true_segments[{i}]")
        lines.append(to_file_lines(seg))
    return lines


def jaccard_index(
    y_true,
    y_pred,
    *,
    mode="official_2014",
    per_sequence=False,
    n_classes=None,
    true_segments=None,
):
    """Mean ChaLearn LAP 2014 Jaccard index over sequences of per-frame labels.

    Every maximal run of one gesture label, frames ``s .. e`` (1-based,
    inclusive), becomes the file line ``c, s, e`` that the challenge's writer
    produces (docs/method.md §1.7), for the ground truth and the prediction alike.
    Each sequence is then scored by :func:`jaccard_index_segments`, and the
    scores are averaged with equal weight per sequence, as the official script
    does. In the official mode the last frame of every run is therefore not
    counted, in the ground truth as in the prediction.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest, 1..K gesture classes.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels, as returned by an estimator's ``predict``.
    mode : {"official_2014", "fp_penalised", "inclusive"}, default="official_2014"
        ``"official_2014"``: the official script (headline number; predicted
        classes absent from the ground truth cost nothing). ``"fp_penalised"``:
        each predicted class absent from the ground truth adds 1 to the
        denominator. ``"inclusive"``: runs count all their frames.
    per_sequence : bool, default=False
        Return the array of sequence scores instead of their mean.
    n_classes : int, default=None
        Largest valid class id; a larger label raises a ``ValueError``. ``None``
        accepts any label (the scores do not depend on it).
    true_segments : list of array-like of shape (n_gestures_i, 3) or None, \
            default=None
        The ground-truth instances as the label files list them, rows
        ``(class, start, end)``, 0-based, ``end`` exclusive (the ``segments``
        of every loader's Bunch). When given, they are scored instead of the
        runs of ``y_true`` (which still gives the sequence lengths): this is
        the official score exactly, also where two instances of one class
        touch (see Notes). ``None``: the runs of ``y_true``.

    Returns
    -------
    float or ndarray of shape (n_sequences,)
        The mean score in [0, 1], or with ``per_sequence=True`` the score of each
        sequence, NaN for the skipped ones.

    Raises
    ------
    ValueError
        If the two lists differ in length, a sequence differs in length between
        them, a label is negative or not an integer, or ``mode`` is unknown.

    See Also
    --------
    jaccard_index_segments : The same on the lines of the challenge files.
    segmental_f1, edit_score : Segment-level metrics of action segmentation.

    Notes
    -----
    **Where this differs from the official score.** Per-frame labels cannot say
    where one instance ends and the next begins when two instances of one class
    touch: their frames form one run, hence one line, and only the last frame of
    the merged run is dropped instead of the last frame of each instance. With
    ground-truth lines ``3,11,40`` and ``3,41,70`` and the prediction
    ``3,11,70``, the official script gives 58/59 = 0.98305, the per-frame
    version 1.0 (docs/method.md §2.2). Elsewhere the two agree. The
    estimators' ``score`` and the scorers use the per-frame version; to score
    against label files, pass their instances as ``true_segments`` (or score
    the lines with :func:`jaccard_index_segments`).

    A sequence without any ground-truth gesture is undefined (the official script
    divides by zero): it is skipped with an ``UndefinedMetricWarning``. If every
    sequence is skipped the result is NaN, with a second warning. Within a
    sequence a ground-truth class with no frame left after the end-frame
    exclusion (a 1-frame run) and not predicted scores 0, with a warning.
    Evaluation choice D19 of docs/method.md: report ``"official_2014"`` as the
    headline, ``"fp_penalised"`` and ``"inclusive"`` beside it.

    References
    ----------
    .. [1] S. Escalera et al., "ChaLearn Looking at People Challenge 2014:
       Dataset and Results", ECCV Workshops 2014.

    Examples
    --------
    >>> from skgesture.metrics import jaccard_index
    >>> y_true = [[0, 3, 3, 3, 3, 3, 5, 5, 5, 5]]
    >>> y_pred = [[0, 0, 3, 3, 3, 3, 8, 8, 8, 0]]
    >>> jaccard_index(y_true, y_pred)
    0.375
    >>> jaccard_index(y_true, y_pred, mode="fp_penalised")
    0.25
    >>> jaccard_index(y_true + y_true, [y_true[0], y_pred[0]], per_sequence=True)
    array([1.   , 0.375])

    Two touching instances of class 3 (frames 10-39 and 40-69, 0-based):

    >>> import numpy as np
    >>> y = np.zeros(80, int); y[10:70] = 3
    >>> jaccard_index([y], [y])
    1.0
    >>> round(jaccard_index([y], [y], true_segments=[[[3, 10, 40], [3, 40, 70]]]), 5)
    0.98305
    """
    _check_mode(mode)
    if n_classes is not None:
        n_classes = _check_positive_int(n_classes, "n_classes")
    y_true, y_pred = _check_label_pairs(y_true, y_pred, n_classes=n_classes)
    gt_lines = _true_segment_lines(true_segments, y_true)
    if n_classes is None:
        largest = max((int(y.max()) for y in y_true + y_pred if y.size), default=0)
        for g in gt_lines or []:
            largest = max(largest, int(g[:, 0].max()) if len(g) else 0)
        n_rows = max(N_OFFICIAL_CLASSES, largest)
    else:
        n_rows = n_classes
    scores = np.full(len(y_true), np.nan)
    skipped = []
    for i, (yt, yp) in enumerate(zip(y_true, y_pred)):
        gt = _labels_to_lines(yt) if gt_lines is None else gt_lines[i]
        if not len(gt):
            skipped.append(i)
            continue
        scores[i], degenerate = _jaccard_from_lines(
            gt, _labels_to_lines(yp), len(yt), mode, n_rows
        )
        if degenerate:
            _warn_degenerate(degenerate, f"sequence {i}")
    if skipped:
        warnings.warn(
            f"{len(skipped)} sequence(s) without any ground-truth gesture skipped "
            f"(Jaccard undefined): indices {skipped}",
            UndefinedMetricWarning,
            stacklevel=2,
        )
    if per_sequence:
        return scores
    kept = scores[~np.isnan(scores)].tolist()
    if not kept:
        warnings.warn(
            "no sequence has a ground-truth gesture: the Jaccard index is "
            "undefined, returning NaN",
            UndefinedMetricWarning,
            stacklevel=2,
        )
        return float("nan")
    return sum(kept) / len(kept)
