"""Frame-level and segment-level metrics for per-frame label sequences.

Frame accuracy, the frame confusion matrix and the per-class report pool every
frame of every sequence. The segmental F1@k and edit score are the
temporal-action-segmentation standard (Lea et al. 2017; MS-TCN, Farha & Gall
2019): rest (label 0) is background and forms no segment.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numbers
import warnings

import numpy as np
from sklearn.exceptions import UndefinedMetricWarning
from sklearn.metrics import confusion_matrix
from sklearn.utils import Bunch

from skgesture.utils._segments import labels_to_segments
from skgesture.utils._validation import check_sequence_labels

__all__ = [
    "frame_accuracy",
    "frame_confusion_matrix",
    "per_class_report",
    "segmental_f1",
    "edit_score",
]

REST = 0  # docs/design.md §1: label 0 is rest / background
EDIT_SCALE = 100.0  # MS-TCN reports the edit score in percent


def _check_label_pairs(y_true, y_pred, *, n_classes=None):
    """Validate two lists of per-frame labels that must match sequence by sequence.

    Parameters
    ----------
    y_true, y_pred : list of array-like of shape (n_frames_i,)
        Per-frame labels, 0 = rest.
    n_classes : int or None, default=None
        If given, labels must lie in ``0..n_classes``.

    Returns
    -------
    y_true, y_pred : list of ndarray of shape (n_frames_i,)
        The labels as int64 arrays.
    """
    for name, y in (("y_true", y_true), ("y_pred", y_pred)):
        if y is None or isinstance(y, (str, bytes)) or not hasattr(y, "__len__"):
            raise TypeError(
                f"{name} must be a list of per-frame label arrays (one per "
                f"sequence), got {type(y).__name__}"
            )
    if len(y_true) != len(y_pred):
        raise ValueError(
            f"y_true has {len(y_true)} sequences but y_pred has {len(y_pred)}: "
            f"give one label array per sequence in both"
        )
    y_true = check_sequence_labels(y_true, n_classes=n_classes, name="y_true")
    y_pred = check_sequence_labels(y_pred, n_classes=n_classes, name="y_pred")
    for i, (yt, yp) in enumerate(zip(y_true, y_pred)):
        if len(yt) != len(yp):
            raise ValueError(
                f"sequence {i}: y_true[{i}] has {len(yt)} frames but y_pred[{i}] "
                f"has {len(yp)}; predictions must have one label per frame"
            )
    return y_true, y_pred


def _segment_f1_counts(y_true, y_pred, overlap):
    """TP, FP, FN of one sequence, matched as MS-TCN's ``f_score`` does.

    Each predicted segment, in temporal order, takes the ground-truth segment of
    the same class with the highest IoU (first one on ties). It is a true positive
    if that IoU reaches ``overlap`` and that ground-truth segment is not matched
    yet, otherwise a false positive. Unmatched ground-truth segments are misses.
    """
    gt = labels_to_segments(y_true, rest=REST)
    pred = labels_to_segments(y_pred, rest=REST)
    if len(gt) == 0:
        return 0, len(pred), 0
    matched = np.zeros(len(gt), dtype=bool)
    tp = 0
    for c, s, e in pred:
        inter = np.minimum(e, gt[:, 2]) - np.maximum(s, gt[:, 1])
        hull = np.maximum(e, gt[:, 2]) - np.minimum(s, gt[:, 1])
        iou = np.where(gt[:, 0] == c, inter / hull, 0.0)
        best = int(np.argmax(iou))
        if iou[best] >= overlap and not matched[best]:
            matched[best] = True
            tp += 1
    return tp, len(pred) - tp, len(gt) - tp


def _levenshtein(a, b):
    """Edit distance (insertions, deletions, substitutions of cost 1)."""
    prev = list(range(len(b) + 1))
    for i, ai in enumerate(a, start=1):
        cur = [i]
        for j, bj in enumerate(b, start=1):
            cur.append(min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (ai != bj)))
        prev = cur
    return prev[-1]


def frame_accuracy(y_true, y_pred):
    """Fraction of frames whose predicted label is right, pooled over sequences.

    Rest frames count like any other label, so every sequence weighs in
    proportion to its length.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest, 1..K gesture classes.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels, as returned by an estimator's ``predict``.

    Returns
    -------
    float
        Correct frames divided by all frames, in [0, 1].

    See Also
    --------
    frame_confusion_matrix : Where the wrong frames went.

    Examples
    --------
    >>> from skgesture.metrics import frame_accuracy
    >>> frame_accuracy([[0, 1, 1, 0], [2, 2]], [[0, 1, 0, 0], [2, 2]])
    0.8333333333333334
    """
    y_true, y_pred = _check_label_pairs(y_true, y_pred)
    n = sum(len(yt) for yt in y_true)
    if n == 0:
        raise ValueError(
            "frame_accuracy needs at least one frame; all sequences are empty"
        )
    correct = sum(int(np.count_nonzero(yt == yp)) for yt, yp in zip(y_true, y_pred))
    return correct / n


def frame_confusion_matrix(y_true, y_pred, labels=None, *, normalize=None):
    """Confusion matrix of per-frame labels, pooled over sequences.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest, 1..K gesture classes.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels.
    labels : array-like of shape (n_labels,), default=None
        Labels indexing the rows and columns, in this order. ``None`` uses every
        label present in ``y_true`` or ``y_pred``, sorted (rest first).
    normalize : {"true", "pred", "all"}, default=None
        Normalise over the true labels (rows), the predicted labels (columns) or
        all frames, as :func:`sklearn.metrics.confusion_matrix` does.

    Returns
    -------
    ndarray of shape (n_labels, n_labels)
        Entry ``[i, j]`` counts frames of true label ``labels[i]`` predicted as
        ``labels[j]``.

    See Also
    --------
    sklearn.metrics.confusion_matrix : The same on flat label arrays.

    Examples
    --------
    >>> from skgesture.metrics import frame_confusion_matrix
    >>> frame_confusion_matrix([[0, 1, 1, 0], [2, 2]], [[0, 1, 0, 0], [2, 1]])
    array([[2, 0, 0],
           [1, 1, 0],
           [0, 1, 1]])
    """
    y_true, y_pred = _check_label_pairs(y_true, y_pred)
    flat_true = np.concatenate(y_true)
    flat_pred = np.concatenate(y_pred)
    if labels is None and flat_true.size == 0:
        raise ValueError("frame_confusion_matrix needs at least one frame")
    return confusion_matrix(flat_true, flat_pred, labels=labels, normalize=normalize)


def _check_report_labels(labels):
    """The ``labels`` of a report as int64: 1-D, non-empty, unique integers."""
    arr = np.asarray(labels)
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(
            f"labels must be a non-empty 1-D array of class labels, got shape "
            f"{arr.shape}"
        )
    if arr.dtype == bool or not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"labels must hold integers, got dtype {arr.dtype}")
    if not np.issubdtype(arr.dtype, np.integer) and not (
        np.all(np.isfinite(arr)) and np.all(arr == np.round(arr))
    ):
        raise ValueError(f"labels must hold integers, got {arr.tolist()!r}")
    arr = arr.astype(np.int64)
    values, counts = np.unique(arr, return_counts=True)
    if np.any(counts > 1):
        raise ValueError(f"labels lists {values[counts > 1].tolist()} more than once")
    return arr


def per_class_report(y_true, y_pred, *, labels=None):
    """Per-class frame precision, recall and F1, with the gestures of each class.

    Every frame of every sequence is pooled, as in
    :func:`frame_confusion_matrix`: for class ``c``, precision is the fraction
    of the frames predicted ``c`` that are ``c``, recall the fraction of the
    frames of ``c`` predicted ``c``. Beside them the report counts the
    gestures (maximal runs of one gesture label, as in :func:`segmental_f1`)
    of each class in the truth and in the prediction, which shows over- and
    under-segmentation that the frame scores hide.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest, 1..K gesture classes.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels.
    labels : array-like of shape (n_labels,), default=None
        The classes to report, in this order (rest, 0, may be one of them).
        ``None`` uses every label present in ``y_true`` or ``y_pred``, sorted
        (rest first). A label that no frame has gets zeros.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys, each an ndarray of shape
        ``(n_labels,)`` in the order of ``labels``:

        labels : ndarray of int64
            The classes.
        precision, recall, f1 : ndarray of float64
            Frame precision, recall and their harmonic mean, in [0, 1].
        support : ndarray of int64
            Frames of each class in ``y_true``.
        true_gestures, predicted_gestures : ndarray of int64
            Gestures of each class in ``y_true`` and in ``y_pred``; always 0
            for rest, which forms no gesture.

    See Also
    --------
    frame_confusion_matrix : The counts the frame scores come from.
    sklearn.metrics.precision_recall_fscore_support : The frame scores alone,
        on flat label arrays.
    segmental_f1 : Gestures matched by overlap rather than counted.

    Notes
    -----
    An undefined score is 0, without a warning (``zero_division=0`` in
    scikit-learn's terms): precision when no frame is predicted ``c``, recall
    when no frame is ``c``, and F1 when no frame of ``c`` is predicted right.
    ``skgesture evaluate`` prints this report as its per-class table.

    Examples
    --------
    >>> from skgesture.metrics import per_class_report
    >>> report = per_class_report([[0, 1, 1, 0, 2, 2]], [[0, 1, 0, 0, 2, 1]])
    >>> report.labels.tolist(), report.support.tolist()
    ([0, 1, 2], [2, 2, 2])
    >>> report.precision.round(3).tolist(), report.recall.tolist()
    ([0.667, 0.5, 1.0], [1.0, 0.5, 0.5])
    >>> report.f1.round(3).tolist()
    [0.8, 0.5, 0.667]
    >>> report.true_gestures.tolist(), report.predicted_gestures.tolist()
    ([0, 1, 1], [0, 2, 1])
    """
    y_true, y_pred = _check_label_pairs(y_true, y_pred)
    if sum(len(yt) for yt in y_true) == 0:
        raise ValueError("per_class_report needs at least one frame")
    present = np.unique(np.concatenate([*y_true, *y_pred]))
    labels = present if labels is None else _check_report_labels(labels)
    # Count over every label, listed or not, so that a frame of a listed class
    # predicted as an unlisted one still counts in its support.
    every = np.union1d(present, labels)
    cm = frame_confusion_matrix(y_true, y_pred, labels=every)
    rows = np.searchsorted(every, labels)
    tp = np.diag(cm)[rows]
    support = cm.sum(axis=1)[rows]
    predicted = cm.sum(axis=0)[rows]
    zeros = np.zeros(len(labels))
    precision = np.divide(tp, predicted, out=zeros.copy(), where=predicted > 0)
    recall = np.divide(tp, support, out=zeros.copy(), where=support > 0)
    f1 = np.divide(
        2 * precision * recall, precision + recall, out=zeros.copy(), where=tp > 0
    )
    index = {int(c): k for k, c in enumerate(labels)}
    counts = np.zeros((2, len(labels)), dtype=np.int64)
    for row, sequences in enumerate((y_true, y_pred)):
        for y in sequences:
            for c in labels_to_segments(y, rest=REST)[:, 0].tolist():
                if c in index:
                    counts[row, index[c]] += 1
    return Bunch(
        labels=labels,
        precision=precision,
        recall=recall,
        f1=f1,
        support=support.astype(np.int64),
        true_gestures=counts[0],
        predicted_gestures=counts[1],
    )


def segmental_f1(y_true, y_pred, *, overlap=0.1):
    """Segmental F1 score at an IoU threshold (F1@k), pooled over sequences.

    Each maximal run of one gesture label is a segment; rest (0) is background
    and forms none. Predicted segments are matched greedily, in temporal order,
    to ground-truth segments of the same class whose intersection over union
    (IoU) reaches ``overlap``; each ground-truth segment is matched at most once.
    True positives, false positives and misses are summed over all sequences
    before the F1 is computed, as in MS-TCN.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest, 1..K gesture classes.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels.
    overlap : float, default=0.1
        IoU threshold in (0, 1]; the literature reports 0.1, 0.25 and 0.5
        (F1@10, F1@25, F1@50).

    Returns
    -------
    float
        ``2 TP / (2 TP + FP + FN)`` in [0, 1]. When neither ``y_true`` nor
        ``y_pred`` has any segment the score is undefined: 0.0 is returned with
        a warning (MS-TCN's ``nan_to_num`` gives the same 0).

    See Also
    --------
    edit_score : Order of the segments, regardless of their timing.
    jaccard_index : The ChaLearn LAP 2014 frame-overlap score.

    Notes
    -----
    The matching follows MS-TCN's ``f_score`` exactly: a predicted segment is
    compared with the ground-truth segment of highest IoU (the first on ties),
    and counts as a false positive if that one is already matched, even when
    another unmatched segment would also pass the threshold. The score is
    returned in [0, 1], not in percent. Segment ends are exclusive; MS-TCN's
    helper cuts the last frame of a segment that ends the sequence, which is
    not reproduced.

    References
    ----------
    .. [1] C. Lea, M. D. Flynn, R. Vidal, A. Reiter and G. D. Hager, "Temporal
       Convolutional Networks for Action Segmentation and Detection", CVPR 2017.
    .. [2] Y. A. Farha and J. Gall, "MS-TCN: Multi-Stage Temporal Convolutional
       Network for Action Segmentation", CVPR 2019.

    Examples
    --------
    >>> from skgesture.metrics import segmental_f1
    >>> y_true = [[0, 1, 1, 1, 1, 0, 2, 2, 0, 0]]
    >>> y_pred = [[0, 0, 1, 1, 0, 2, 2, 2, 2, 2]]
    >>> segmental_f1(y_true, y_true, overlap=0.5)
    1.0
    >>> segmental_f1(y_true, y_pred, overlap=0.1)
    1.0
    >>> segmental_f1(y_true, y_pred, overlap=0.5)
    0.5
    """
    if (
        not isinstance(overlap, numbers.Real)
        or isinstance(overlap, bool)
        or not 0 < overlap <= 1
    ):
        raise ValueError(f"overlap must be a real number in (0, 1], got {overlap!r}")
    y_true, y_pred = _check_label_pairs(y_true, y_pred)
    tp = fp = fn = 0
    for yt, yp in zip(y_true, y_pred):
        t, p, n = _segment_f1_counts(yt, yp, overlap)
        tp, fp, fn = tp + t, fp + p, fn + n
    if tp + fp + fn == 0:
        warnings.warn(
            "segmental_f1 is undefined without any gesture segment in y_true or "
            "y_pred; returning 0.0",
            UndefinedMetricWarning,
            stacklevel=2,
        )
        return 0.0
    return 2 * tp / (2 * tp + fp + fn)


def edit_score(y_true, y_pred):
    """Segmental edit score, the mean over sequences, in percent.

    Each sequence becomes the ordered list of its segment labels (maximal runs
    of one gesture label, rest excluded). The score of a sequence is
    ``100 * (1 - d / max(len_true, len_pred))`` with ``d`` the Levenshtein
    distance between the two lists; it rewards the right gestures in the right
    order and penalises over-segmentation, whatever the timing.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest, 1..K gesture classes.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels.

    Returns
    -------
    float
        Mean edit score over sequences, in [0, 100].

    See Also
    --------
    segmental_f1 : Segment matching with an IoU threshold.

    Notes
    -----
    As MS-TCN's ``edit_score``, and therefore in percent, unlike the other
    metrics of this module. A sequence where neither labelling has a segment
    scores 100 (MS-TCN divides by zero there).

    References
    ----------
    .. [1] C. Lea, R. Vidal and G. D. Hager, "Learning Convolutional Action
       Primitives for Fine-grained Action Recognition", ICRA 2016.
    .. [2] Y. A. Farha and J. Gall, "MS-TCN: Multi-Stage Temporal Convolutional
       Network for Action Segmentation", CVPR 2019.

    Examples
    --------
    >>> from skgesture.metrics import edit_score
    >>> edit_score([[0, 1, 1, 0, 2, 2, 0]], [[0, 1, 0, 1, 2, 2, 2]])
    66.66666666666667
    """
    y_true, y_pred = _check_label_pairs(y_true, y_pred)
    scores = []
    for yt, yp in zip(y_true, y_pred):
        a = labels_to_segments(yt, rest=REST)[:, 0].tolist()
        b = labels_to_segments(yp, rest=REST)[:, 0].tolist()
        longest = max(len(a), len(b))
        if longest == 0:
            scores.append(EDIT_SCALE)
        else:
            scores.append(EDIT_SCALE * (1 - _levenshtein(a, b) / longest))
    return sum(scores) / len(scores)
