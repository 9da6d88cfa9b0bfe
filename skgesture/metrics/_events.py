"""Event-level metrics: gestures found, and false events on motion that is no gesture.

What decides whether a robot can be commanded by gestures is not a frame score but
two event counts: of the gestures a person makes, how many are recognised (recall),
and while the person does something else, how many commands fire (false events per
minute). Both depend on the confidence floor of the events that count
(``ActionMap(min_confidence=...)``); :func:`rejection_curve` gives both at every
floor, so the floor is chosen by the numbers (docs/safety.md).

Events are the rows ``(class, start, end, confidence)`` of ``predict_segments``
(0-based frames, ``end`` exclusive); true gestures are the rows ``(class, start,
end)`` of a dataset's ``segments``.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numbers

import numpy as np
from sklearn.utils import Bunch

__all__ = ["event_misses", "event_recall", "rejection_curve"]

DEFAULT_THRESHOLDS = tuple(np.round(np.arange(0.0, 1.0, 0.05), 2))
# What became of each true gesture (event_misses), in this order of precedence.
OUTCOMES = ("found", "wrong_class", "merged", "boundaries", "no_event")


def _rows(value, width, what, index):
    """``value`` as a float array of shape (n, width), or a clear error."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what}[{index}]: not numeric ({exc})") from None
    if arr.size == 0:
        return arr.reshape(0, width)
    if arr.ndim != 2 or arr.shape[1] < width:
        raise ValueError(
            f"{what}[{index}]: expected rows of {width} values "
            f"(class, start, end{', confidence' if width == 4 else ''}), "
            f"got shape {arr.shape}"
        )
    arr = arr[:, :width]
    if not np.all(np.isfinite(arr[:, :3])):
        raise ValueError(f"{what}[{index}]: class, start and end must be finite")
    bad = np.flatnonzero(arr[:, 2] <= arr[:, 1])
    if bad.size:
        raise ValueError(
            f"{what}[{index}], row {bad[0]}: end {arr[bad[0], 2]:g} is not after "
            f"start {arr[bad[0], 1]:g}"
        )
    return arr


def _per_sequence(value, name):
    """``value`` as a list of one array per sequence; one array is refused."""
    if isinstance(value, np.ndarray):
        raise TypeError(
            f"{name} must be lists of rows (one array per sequence), not one array"
        )
    return list(value)


def _check_lists(true_segments, events):
    true_segments = _per_sequence(true_segments, "true_segments")
    events = _per_sequence(events, "events")
    if len(true_segments) != len(events):
        raise ValueError(
            f"true_segments has {len(true_segments)} sequences, events "
            f"{len(events)}: they must match sequence by sequence"
        )
    return true_segments, events


def _best_match(true, pred, min_iou):
    """Per true gesture, the highest confidence of a same-class event that
    overlaps it with IoU >= ``min_iou`` (``-inf`` when none does)."""
    out = np.full(len(true), -np.inf)
    for i, (c, s, e) in enumerate(true):
        same = pred[pred[:, 0] == c]
        ok = _finds(s, e, same, min_iou)
        if ok.any():
            out[i] = same[ok, 3].max()
    return out


def _overlaps(s, e, rows):
    """Intersection and union, in frames, of ``[s, e)`` with every row
    ``(class, start, end, ...)``."""
    inter = np.minimum(e, rows[:, 2]) - np.maximum(s, rows[:, 1])
    return inter, (e - s) + (rows[:, 2] - rows[:, 1]) - inter


def _finds(s, e, rows, min_iou):
    """Which rows overlap ``[s, e)`` with an IoU of at least ``min_iou``."""
    inter, union = _overlaps(s, e, rows)
    return (inter > 0) & (inter >= min_iou * union)


def _check_threshold_like(value, name):
    if not isinstance(value, numbers.Real) or not 0 < value <= 1:
        raise ValueError(f"{name} must be a number in (0, 1], got {value!r}")


def event_recall(true_segments, events, *, min_confidence=0.0, min_iou=0.5):
    """Fraction of true gestures found by an event of the same class.

    A true gesture is found when an event of its class with a confidence of at
    least ``min_confidence`` overlaps it with an intersection over union of at
    least ``min_iou`` (both as frame intervals).

    Parameters
    ----------
    true_segments : list of array-like of shape (n_gestures_i, 3)
        Rows ``(class, start, end)`` per sequence, ``end`` exclusive.
    events : list of array-like of shape (n_events_i, 4)
        Rows ``(class, start, end, confidence)`` per sequence, as
        ``predict_segments`` returns them.
    min_confidence : float, default=0.0
        Events below this confidence do not count.
    min_iou : float, default=0.5
        The overlap an event needs to find a gesture.

    Returns
    -------
    float
        Found gestures over true gestures (NaN when there is no true gesture).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.metrics import event_recall
    >>> true = [np.array([[1, 10, 40], [2, 60, 90]])]
    >>> events = [np.array([[1, 12, 42, 0.9], [1, 60, 90, 0.8]])]
    >>> event_recall(true, events)
    0.5
    """
    curve = rejection_curve(
        true_segments, events, thresholds=[min_confidence], min_iou=min_iou
    )
    return float(curve.recall[0])


def event_misses(true_segments, events, *, min_confidence=0.0, min_iou=0.5):
    """What became of every true gesture: found, or why it was missed.

    :func:`event_recall` counts the gestures found; this says why the others
    were not, which tells what to improve: the naming (``"wrong_class"``)
    or the segmentation (``"merged"``, ``"boundaries"``), or the detection
    (``"no_event"``). Each true gesture gets the first outcome that holds:

    * ``"found"``: an event of its class overlaps it with an intersection
      over union of at least ``min_iou`` (as :func:`event_recall`);
    * ``"wrong_class"``: events overlap it, none of its class;
    * ``"merged"``: an event of its class overlaps it, below ``min_iou``, and
      that event (the one of highest overlap) overlaps another true gesture
      too: two gestures read as one;
    * ``"boundaries"``: an event of its class overlaps it, below ``min_iou``,
      and overlaps no other true gesture: its ends are too far off, or the
      gesture is split into pieces;
    * ``"no_event"``: no event overlaps it.

    Events below ``min_confidence`` do not count.

    Parameters
    ----------
    true_segments : list of array-like of shape (n_gestures_i, 3)
        Rows ``(class, start, end)`` per sequence, ``end`` exclusive.
    events : list of array-like of shape (n_events_i, 4)
        Rows ``(class, start, end, confidence)`` per sequence, as
        ``predict_segments`` returns them.
    min_confidence : float, default=0.0
        Events below this confidence do not count.
    min_iou : float, default=0.5
        The overlap an event needs to find a gesture.

    Returns
    -------
    dict
        The count of true gestures of every outcome, in the order above.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.metrics import event_misses
    >>> true = [np.array([[1, 10, 40], [2, 60, 90], [1, 100, 110],
    ...                   [1, 112, 122], [2, 150, 200], [1, 300, 330]])]
    >>> events = [np.array([[1, 12, 42, 0.9], [1, 60, 90, 0.8],
    ...                     [1, 100, 122, 0.7], [2, 150, 160, 0.6]])]
    >>> event_misses(true, events)
    {'found': 1, 'wrong_class': 1, 'merged': 2, 'boundaries': 1, 'no_event': 1}
    """
    _check_threshold_like(min_iou, "min_iou")
    true_segments, events = _check_lists(true_segments, events)
    counts = dict.fromkeys(OUTCOMES, 0)
    for i, (t, p) in enumerate(zip(true_segments, events)):
        true, pred = _rows(t, 3, "true_segments", i), _rows(p, 4, "events", i)
        pred = pred[pred[:, 3] >= min_confidence]
        for c, s, e in true:
            over = pred[_overlaps(s, e, pred)[0] > 0]
            same = over[over[:, 0] == c]
            if not len(over):
                counts["no_event"] += 1
                continue
            if not len(same):
                counts["wrong_class"] += 1
                continue
            if _finds(s, e, same, min_iou).any():  # event_recall's rule
                counts["found"] += 1
                continue
            inter, union = _overlaps(s, e, same)
            _, bs, be, _ = same[np.argmax(inter / union)]
            others = (_overlaps(bs, be, true)[0] > 0).sum()
            counts["merged" if others > 1 else "boundaries"] += 1
    return counts


def rejection_curve(
    true_segments,
    events,
    background_events=None,
    background_minutes=None,
    *,
    thresholds=DEFAULT_THRESHOLDS,
    min_iou=0.5,
):
    """Recall of true gestures and false events per minute at confidence floors.

    Raising the confidence floor of the events that count removes false
    commands and loses true ones; this gives both at every floor, to choose
    ``ActionMap(min_confidence=...)`` on recordings of your own (held-out
    subjects for the gestures, ordinary work for the background).

    Parameters
    ----------
    true_segments : list of array-like of shape (n_gestures_i, 3)
        True gestures ``(class, start, end)`` of the gesture recordings.
    events : list of array-like of shape (n_events_i, 4)
        The model's events ``(class, start, end, confidence)`` on the same
        recordings (``model.predict_segments(X)``).
    background_events : list of array-like of shape (n_events_i, 4), default=None
        The model's events on recordings without any command in them: each one
        is a false event.
    background_minutes : float, default=None
        The duration of those recordings in minutes (their frames over their
        frame rate); required with ``background_events``.
    thresholds : sequence of float, default=0, 0.05, ..., 0.95
        The confidence floors.
    min_iou : float, default=0.5
        The overlap an event needs to find a true gesture (same class).

    Returns
    -------
    Bunch
        ``thresholds``, ``recall`` (found over true gestures), ``n_gestures``,
        and with background: ``false_per_minute`` and ``n_false`` (arrays
        aligned with ``thresholds``), ``minutes``.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.metrics import rejection_curve
    >>> true = [np.array([[1, 10, 40], [2, 60, 90]])]
    >>> events = [np.array([[1, 12, 42, 0.9], [2, 58, 88, 0.55]])]
    >>> background = [np.array([[1, 0, 30, 0.7], [2, 100, 120, 0.4]])]
    >>> curve = rejection_curve(true, events, background, 2.0,
    ...                         thresholds=[0.0, 0.5, 0.6, 0.8])
    >>> curve.recall.tolist()
    [1.0, 1.0, 0.5, 0.5]
    >>> curve.false_per_minute.tolist()
    [1.0, 0.5, 0.5, 0.0]
    """
    _check_threshold_like(min_iou, "min_iou")
    true_segments, events = _check_lists(true_segments, events)
    thresholds = np.asarray(thresholds, dtype=float).ravel()
    if thresholds.size == 0 or not np.all(np.isfinite(thresholds)):
        raise ValueError("thresholds must be a non-empty sequence of finite numbers")
    best = [
        _best_match(_rows(t, 3, "true_segments", i), _rows(p, 4, "events", i), min_iou)
        for i, (t, p) in enumerate(zip(true_segments, events))
    ]
    best = np.concatenate(best) if best else np.zeros(0)
    recall = np.array([np.mean(best >= t) if best.size else np.nan for t in thresholds])
    out = Bunch(thresholds=thresholds, recall=recall, n_gestures=int(best.size))
    if background_events is None:
        if background_minutes is not None:
            raise ValueError("background_minutes is given without background_events")
        return out
    background_events = _per_sequence(background_events, "background_events")
    if not isinstance(background_minutes, numbers.Real) or not (
        background_minutes > 0 and np.isfinite(background_minutes)
    ):
        raise ValueError(
            "background_minutes must be a positive number (the duration of the "
            f"background recordings), got {background_minutes!r}"
        )
    conf = [
        _rows(p, 4, "background_events", i)[:, 3]
        for i, p in enumerate(background_events)
    ]
    conf = np.concatenate(conf) if conf else np.zeros(0)
    n_false = np.array([int(np.sum(conf >= t)) for t in thresholds])
    out.update(
        n_false=n_false,
        false_per_minute=n_false / float(background_minutes),
        minutes=float(background_minutes),
    )
    return out
