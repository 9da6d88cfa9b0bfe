"""Decoding of per-frame class probabilities into labels, shared by every tagger.

One path for :class:`~skgesture.BiLSTMTagger` (Method C),
:class:`~skgesture.SequenceTagger` and :class:`~skgesture.VotingTagger`:
smooth every class track, take the arg-max per frame (or the duration-aware
Viterbi path of :mod:`skgesture._taggers._viterbi`), merge runs of one class
split by a short rest gap, set gesture runs shorter than ``min_run`` to rest,
and force untracked frames to rest. Only the network depends on the training,
so every decoding parameter can be changed after ``fit`` (and searched without
retraining when the network is cached).
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
from scipy.ndimage import uniform_filter1d

from skgesture._stream import StreamSegment
from skgesture._taggers._namer import name_run, namer_of
from skgesture._taggers._viterbi import ViterbiPath, log_scores
from skgesture.utils._buffers import RowBuffer
from skgesture.utils._segments import labels_to_segments, remove_short_runs, runs
from skgesture.utils._smoothing import LoessStepper, MeanStepper, loess_smooth

__all__ = [
    "ViterbiRule",
    "apply_run_rules",
    "best_path",
    "class_lengths",
    "decode",
    "fill_short_gaps",
    "reject_runs",
    "segments_with_confidence",
    "smooth_proba",
]

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
    >>> from skgesture._taggers._decoding import smooth_proba
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
    >>> from skgesture._taggers._decoding import fill_short_gaps
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


LENGTH_QUANTILE = 10  # percentile of a class's training lengths: its "short" gesture
LONG_QUANTILE = 90  # and its "long" gesture


def class_lengths(y, classes, *, quantile=LENGTH_QUANTILE):
    """The length of a short gesture of every class: a percentile of its runs.

    Parameters
    ----------
    y : list of ndarray of shape (n_frames_i,)
        Per-frame training labels (0 = rest; negative labels, the ignored
        rows, end a run as rest does).
    classes : ndarray of shape (n_classes,)
        The classes, rest (0) first.
    quantile : float, default=10
        The percentile of every class's run lengths.

    Returns
    -------
    ndarray of shape (n_classes,)
        Frames; 0 for rest and for a class without a run.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._decoding import class_lengths
    >>> y = [np.array([0, 1, 1, 1, 1, 0, 2, 2, 0, 1, 1, 0])]
    >>> class_lengths(y, np.array([0, 1, 2]), quantile=50).tolist()
    [0.0, 3.0, 2.0]
    """
    classes = np.asarray(classes)
    lengths = {int(c): [] for c in classes}
    for labels in y:
        starts, ends, values = runs(np.asarray(labels))
        for s, e, v in zip(starts.tolist(), ends.tolist(), values.tolist()):
            if v > 0 and v in lengths:
                lengths[v].append(e - s)
    return np.array(
        [
            float(np.percentile(lengths[int(c)], quantile))
            if c != 0 and lengths[int(c)]
            else 0.0
            for c in classes
        ]
    )


def reject_runs(
    labels,
    raw,
    classes,
    *,
    min_confidence=0.0,
    min_lengths=None,
    max_lengths=None,
    novelty=None,
    max_novelty=None,
    namer=None,
    namer_weight=0.0,
    max_namer_rest=None,
):
    """Name every gesture run, then set to rest the runs too short or too long
    for their class, too unsure, or unlike its training poses.

    The last rules of the decoding, applied to every run on its own (so a
    stream decides a run as soon as it ends). With ``namer``, a run first
    takes the name of :func:`~skgesture._taggers._namer.name_run` (the
    tagger's and the namer's scores of the run's rows; two touching runs that
    take one name are one gesture), and with ``max_namer_rest`` a run
    to which the namer gives a mean probability of rest above it becomes
    rest. Then a run of class ``c`` shorter
    than ``min_lengths[c]`` frames, longer than ``max_lengths[c]`` frames,
    whose mean raw probability of ``c`` is below ``min_confidence``, or whose
    median novelty for ``c`` is above ``max_novelty``, becomes rest.

    Parameters
    ----------
    labels : ndarray of shape (n_frames,)
        Decoded labels.
    raw : ndarray of shape (n_frames, n_classes)
        Raw (unsmoothed) probabilities, columns in ``classes`` order.
    classes : ndarray of shape (n_classes,)
        Labels of the columns.
    min_confidence : float, default=0.0
        Lowest mean probability of a run kept (the confidence of
        :func:`segments_with_confidence`).
    min_lengths : ndarray of shape (n_classes,) or None, default=None
        Shortest run kept per class, in frames; None keeps every length.
    max_lengths : ndarray of shape (n_classes,) or None, default=None
        Longest run kept per class, in frames (``inf``: no limit); None
        keeps every length.
    novelty : callable or None, default=None
        ``novelty(start, end, k)``: the novelty of rows ``start .. end - 1``
        for the class of column ``k``
        (:meth:`skgesture.utils.PoseNovelty.score`); needed when
        ``max_novelty`` is set.
    max_novelty : float or None, default=None
        Highest median novelty of a run kept; None keeps every run.
    namer : callable or None, default=None
        ``namer(start, end)``: the namer's log mean probabilities of rows
        ``start .. end - 1`` (:func:`~skgesture._taggers._namer.namer_of`);
        None keeps the runs' labels.
    namer_weight : float, default=0.0
        Weight of the namer's scores against the tagger's, in [0, 1] (0:
        the runs keep their labels).
    max_namer_rest : float or None, default=None
        Highest mean probability of rest that the namer may give a run kept;
        None: the namer's rest is not read.

    Returns
    -------
    ndarray of shape (n_frames,)
        A filtered copy.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._decoding import reject_runs
    >>> lab = np.array([0, 1, 1, 0, 2, 2, 2, 0])
    >>> raw = np.eye(3)[lab] * 0.9 + 0.1 / 3
    >>> reject_runs(lab, raw, np.arange(3), min_lengths=np.array([0, 3, 3])).tolist()
    [0, 0, 0, 0, 2, 2, 2, 0]
    >>> reject_runs(lab, raw, np.arange(3), max_lengths=np.array([0, 9, 2])).tolist()
    [0, 1, 1, 0, 0, 0, 0, 0]
    >>> reject_runs(lab, raw, np.arange(3), min_confidence=0.95).tolist()
    [0, 0, 0, 0, 0, 0, 0, 0]
    """
    labels = np.array(labels, copy=True)
    if namer_weight <= 0 and max_namer_rest is None:
        namer = None  # no rule reads its scores
    if (
        min_confidence <= 0
        and min_lengths is None
        and max_lengths is None
        and max_novelty is None
        and namer is None
    ):
        return labels
    rest_floor = None if max_namer_rest is None else np.log(max_namer_rest)
    if max_novelty is not None and novelty is None:
        raise ValueError("max_novelty needs the novelty of the rows (novelty=)")
    classes = np.asarray(classes)
    starts, ends, values = runs(labels)
    for s, e, v in zip(starts.tolist(), ends.tolist(), values.tolist()):
        if v == 0:
            continue
        k = int(np.searchsorted(classes, v))
        if namer is not None:
            scores = namer(s, e)
            if namer_weight > 0:
                k = name_run(raw[s:e], scores, namer_weight)
                labels[s:e] = classes[k]
            if rest_floor is not None and scores[0] > rest_floor:
                labels[s:e] = 0
                continue
        too_short = min_lengths is not None and e - s < min_lengths[k]
        too_long = max_lengths is not None and e - s > max_lengths[k]
        if (
            too_short
            or too_long
            or (min_confidence > 0 and raw[s:e, k].mean() < min_confidence)
            or (max_novelty is not None and np.median(novelty(s, e, k)) > max_novelty)
        ):
            labels[s:e] = 0
    return labels


def best_path(smoothed, classes, *, untracked=None, viterbi=None):
    """The labels of every frame before the run rules: the arg-max of every
    frame, or the duration-aware Viterbi path of ``viterbi``.

    Parameters
    ----------
    smoothed : ndarray of shape (n_frames, n_classes)
        (Smoothed) probabilities, columns in ``classes`` order.
    classes : ndarray of shape (n_classes,)
        Labels of the columns, rest (0) first.
    untracked : ndarray of bool of shape (n_frames,) or None, default=None
        Frames the Viterbi path keeps at rest.
    viterbi : ViterbiRule or None, default=None
        None: the arg-max.

    Returns
    -------
    ndarray of shape (n_frames,)
        Labels from ``classes``.
    """
    classes = np.asarray(classes)
    if viterbi is None:
        return classes[np.argmax(smoothed, axis=1)]
    return classes[viterbi.path().run(log_scores(smoothed, untracked))]


def apply_run_rules(
    labels,
    raw,
    classes,
    *,
    untracked=None,
    min_run=1,
    max_gap=0,
    min_confidence=0.0,
    min_lengths=None,
    max_lengths=None,
    novelty=None,
    max_novelty=None,
    namer=None,
    namer_weight=0.0,
    max_namer_rest=None,
):
    """The rules of :func:`decode` that follow the path, on its labels.

    Untracked frames become rest, rest gaps of at most ``max_gap`` frames
    between two runs of one class are filled, gesture runs shorter than
    ``min_run`` become rest, untracked frames are rest again, and
    :func:`reject_runs` names (with ``namer``) and judges every run (``raw``:
    the raw probabilities).

    Returns
    -------
    ndarray of shape (n_frames,)
        A filtered copy of ``labels``.
    """
    return reject_runs(
        prepare_runs(labels, untracked=untracked, min_run=min_run, max_gap=max_gap),
        raw,
        classes,
        min_confidence=min_confidence,
        min_lengths=min_lengths,
        max_lengths=max_lengths,
        novelty=novelty,
        max_novelty=max_novelty,
        namer=namer,
        namer_weight=namer_weight,
        max_namer_rest=max_namer_rest,
    )


def prepare_runs(labels, *, untracked=None, min_run=1, max_gap=0):
    """The first rules of :func:`apply_run_rules`, which give the runs that
    :func:`reject_runs` judges: untracked frames become rest, rest gaps of at
    most ``max_gap`` frames between two runs of one class are filled, gesture
    runs shorter than ``min_run`` become rest, untracked frames are rest
    again.

    Returns
    -------
    ndarray of shape (n_frames,)
        A filtered copy of ``labels``.
    """
    labels = np.array(labels, copy=True)
    if untracked is not None and np.any(untracked):
        labels[untracked] = 0
    labels = fill_short_gaps(labels, max_gap)
    labels = remove_short_runs(labels, min_run)
    if untracked is not None and np.any(untracked):
        labels[untracked] = 0
    return labels


def path_runs(
    proba,
    classes,
    *,
    smooth_span=1,
    smoothing="loess",
    min_run=1,
    max_gap=0,
    untracked=None,
    viterbi=None,
):
    """The runs that :func:`decode` judges: the path of the smoothed
    probabilities (:func:`best_path`) with the rules of :func:`prepare_runs`.

    Returns
    -------
    ndarray of shape (n_frames,)
        Labels from ``classes``.
    """
    smoothed = smooth_proba(proba, smooth_span, smoothing)
    labels = best_path(smoothed, classes, untracked=untracked, viterbi=viterbi)
    return prepare_runs(labels, untracked=untracked, min_run=min_run, max_gap=max_gap)


def novelty_of(rows, score=None):
    """The ``novelty(start, end, k)`` of :func:`reject_runs`.

    ``score(rows[start:end], k)`` (feature rows and a scorer, offline:
    :meth:`skgesture.utils.PoseNovelty.score`), or with ``score`` None
    column ``k`` of ``rows``, scores computed already (a stream's).
    """
    if score is None:
        return lambda s, e, k: rows[s:e, k]
    return lambda s, e, k: score(rows[s:e], k)


class ViterbiRule:
    """The parameters of the duration-aware path (:mod:`._viterbi`).

    Parameters
    ----------
    durations : ndarray of int of shape (n_classes,)
        Shortest run of every class, in frames (rest first, 1).
    penalty : float
        Log score of entering a gesture.
    lag : int
        Frames between a frame and its decision.
    decision : {"frame", "run"}, default="frame"
        When a gesture's frames are decided
        (:class:`~skgesture._taggers._viterbi.ViterbiPath`).
    """

    def __init__(self, durations, penalty, lag, decision="frame"):
        self.durations = np.asarray(durations, dtype=np.int64)
        self.penalty = float(penalty)
        self.lag = int(lag)
        self.decision = decision

    def path(self):
        """A fresh :class:`~skgesture._taggers._viterbi.ViterbiPath`."""
        return ViterbiPath(self.durations, self.penalty, self.lag, self.decision)


def decode(
    proba,
    classes,
    *,
    smooth_span=1,
    smoothing="loess",
    min_run=1,
    max_gap=0,
    untracked=None,
    min_confidence=0.0,
    min_lengths=None,
    max_lengths=None,
    viterbi=None,
    raw=None,
    novelty=None,
    max_novelty=None,
    namer=None,
    namer_weight=0.0,
    max_namer_rest=None,
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
    min_confidence : float, default=0.0
        Gesture runs whose mean raw probability is lower become rest
        (:func:`reject_runs`), after the ``min_run`` filter.
    min_lengths : ndarray of shape (n_classes,) or None, default=None
        Shortest run kept per class (:func:`reject_runs`).
    max_lengths : ndarray of shape (n_classes,) or None, default=None
        Longest run kept per class (:func:`reject_runs`).
    viterbi : ViterbiRule or None, default=None
        The labels before the rules: None, the arg-max of every frame; a
        rule, the duration-aware Viterbi path decided at its lag
        (:mod:`skgesture._taggers._viterbi`).
    raw : ndarray of shape (n_frames, n_classes) or None, default=None
        The raw probabilities of those two rules when ``proba`` is already
        smoothed (a stream's); None: ``proba``.
    novelty : callable or None, default=None
        ``novelty(start, end, k)``, the novelty of rows ``start .. end - 1``
        for column ``k`` (:func:`reject_runs`).
    max_novelty : float or None, default=None
        Gesture runs whose median novelty for their class is higher become
        rest (:func:`reject_runs`).
    namer : callable or None, default=None
        ``namer(start, end)``, the run namer's scores of rows ``start .. end
        - 1``; every gesture run is named with them first (:func:`reject_runs`).
    namer_weight : float, default=0.0
        Weight of the namer's scores against the tagger's.
    max_namer_rest : float or None, default=None
        Gesture runs to which the namer gives a higher mean probability of
        rest become rest (:func:`reject_runs`).

    Returns
    -------
    ndarray of shape (n_frames,)
        Labels from ``classes``.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._decoding import decode
    >>> p = np.array([[0.9, 0.1]] * 3 + [[0.2, 0.8]] * 4 + [[0.9, 0.1]])
    >>> decode(p, np.array([0, 5]), min_run=3).tolist()
    [0, 0, 0, 5, 5, 5, 5, 0]
    >>> decode(p, np.array([0, 5]), min_run=5).tolist()
    [0, 0, 0, 0, 0, 0, 0, 0]
    """
    labels = path_runs(
        proba,
        classes,
        smooth_span=smooth_span,
        smoothing=smoothing,
        min_run=min_run,
        max_gap=max_gap,
        untracked=untracked,
        viterbi=viterbi,
    )
    return reject_runs(
        labels,
        proba if raw is None else raw,
        classes,
        min_confidence=min_confidence,
        min_lengths=min_lengths,
        max_lengths=max_lengths,
        novelty=novelty,
        max_novelty=max_novelty,
        namer=namer,
        namer_weight=namer_weight,
        max_namer_rest=max_namer_rest,
    )


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
    >>> from skgesture._taggers._decoding import segments_with_confidence
    >>> p = np.array([[1.0, 0.0], [0.2, 0.8], [0.4, 0.6]])
    >>> segments_with_confidence(np.array([0, 3, 3]), p, np.array([0, 3])).tolist()
    [[3.0, 1.0, 3.0, 0.7]]
    """
    rows = [
        (c, s, e, float(proba[s:e, np.searchsorted(classes, c)].mean()))
        for c, s, e in labels_to_segments(labels)
    ]
    return np.array(rows, dtype=float).reshape(-1, 4)


def make_smoother(smoothing, span, n_tracks, owner="smooth_span"):
    """The stepper of ``smooth_proba(proba, span, smoothing)`` for a stream.

    Parameters
    ----------
    smoothing : {"loess", "mean", "none"}
        As :func:`skgesture._taggers._decoding.smooth_proba`.
    span : int or float
        Its span (a loess fraction of the sequence is refused: a stream has no
        length).
    n_tracks : int
        Class tracks.
    owner : str, default="smooth_span"
        Parameter name for error messages.

    Returns
    -------
    LoessStepper or MeanStepper
        With ``step(values, times)``, ``flush(now)``, ``held()`` and ``h``,
        the rows of look-ahead.
    """
    if smoothing == "none":
        return LoessStepper(1, n_tracks, owner=owner)  # span 1: rows pass through
    if smoothing == "mean":
        return MeanStepper(span, n_tracks)
    return LoessStepper(span, n_tracks, owner=owner)


class LabelRuns:
    """The decoding of a tagger's smoothed scores, one stretch at a time.

    The offline rules of :func:`skgesture._taggers._decoding.decode`: the
    path (:func:`best_path`: the arg-max of every row, or the duration-aware
    Viterbi path, whose steps are the offline ones and decide a row ``lag``
    rows after it), then the rules on its labels (:func:`apply_run_rules`:
    rest on masked rows, rest gaps of at most ``max_gap`` frames between two
    runs of one class filled, gesture runs shorter than ``min_run`` set to
    rest, :func:`reject_runs`) and the segments and confidences of
    :func:`skgesture._taggers._decoding.segments_with_confidence`, applied by
    calling those functions on stretches of rows that no later row can
    change: the stream is cut where the labels before and after cannot
    interact, i.e. between two different gesture labels (but with a
    ``namer``), before a gesture
    whose preceding rest gap cannot be filled, and inside a rest run longer
    than ``max_gap``. A run of one gesture is therefore emitted once ``max_gap
    + 1`` rest rows follow it (its first rest row for ``max_gap=0``) or
    another gesture starts, and those rows are decided; the segments equal
    the offline ones on the whole stream.

    Parameters
    ----------
    classes : ndarray
        Class of every score column, rest (0) first.
    min_run : int
        Shortest run kept.
    max_gap : int, default=0
        Longest rest gap filled between two runs of one class.
    max_run : int or None, default=None
        A stretch this long without a cut is decided as if the stream ended
        there (bounds memory on a stream that never rests; offline has no
        such cap). None: no cap.
    min_confidence : float, default=0.0
    min_lengths, max_lengths : ndarray of shape (n_classes,) or None, default=None
    max_novelty : float or None, default=None
        The run rules of :func:`reject_runs`: they judge each run on its own,
        so they move no cut. With ``max_novelty``, :meth:`feed` takes the
        novelty of every row too.
    viterbi : ViterbiRule or None, default=None
        The path (:func:`best_path`); None: the arg-max.
    namer : callable or None, default=None
        ``namer(rows) -> (n_classes,)``, the run namer's scores of a run's
        feature rows (:func:`~skgesture._taggers._namer.namer_scores`); with
        it, :meth:`feed` takes the feature rows too, kept until their
        stretch is decided, and the stream is not cut between two touching
        gestures (two touching runs named alike are one gesture, as
        offline): a gesture followed at once by another is emitted when the
        second ends.
    namer_weight : float, default=0.0
        Weight of the namer (:func:`reject_runs`).
    max_namer_rest : float or None, default=None
        The namer's rest rule (:func:`reject_runs`).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._decoding import decode
    >>> from skgesture._taggers._decoding import LabelRuns
    >>> lab = np.array([0, 0, 1, 1, 0, 1, 1, 0, 0, 0, 2, 2, 2, 0])
    >>> p = np.eye(3)[lab]
    >>> runs = LabelRuns(np.arange(3), min_run=3, max_gap=1)
    >>> segs = []
    >>> for t in range(len(p)):
    ...     segs += runs.feed(t, p[t : t + 1], p[t : t + 1], [False], [t])
    >>> segs += runs.end(len(p), len(p) - 1)
    >>> [(s.label, s.start, s.end, s.time) for s in segs]
    [(1, 2, 7, 8), (2, 10, 13, 13)]
    >>> decode(p, np.arange(3), min_run=3, max_gap=1, smoothing="none").tolist()
    [0, 0, 1, 1, 1, 1, 1, 0, 0, 0, 2, 2, 2, 0]
    """

    def __init__(
        self,
        classes,
        min_run,
        max_gap=0,
        max_run=None,
        min_confidence=0.0,
        min_lengths=None,
        max_lengths=None,
        viterbi=None,
        max_novelty=None,
        namer=None,
        namer_weight=0.0,
        max_namer_rest=None,
    ):
        self.classes = np.asarray(classes)
        self.namer = namer
        self.namer_weight = float(namer_weight)
        self.max_namer_rest = max_namer_rest
        self.feature_rows = None  # with a namer: the stretch's feature rows
        self.min_run = int(min_run)
        self.max_gap = int(max_gap)
        self.min_confidence = float(min_confidence)
        self.min_lengths = min_lengths
        self.max_lengths = max_lengths
        self.max_novelty = max_novelty
        self.viterbi = viterbi
        self.path = None if viterbi is None else viterbi.path()
        self.lag = 0 if viterbi is None else viterbi.lag
        self.max_run = None if max_run is None else max(int(max_run), 1)
        n = len(self.classes)
        self.labels = RowBuffer((), dtype=self.classes.dtype, capacity=64)
        self.raw = RowBuffer((n,), capacity=64)
        self.novelty = RowBuffer((n,), capacity=64)
        self.rest = RowBuffer((), dtype=bool, capacity=64)
        self.cs = 0  # first row of the stretch not yet decided
        self.n = 0  # rows labelled by the path
        self.fed = 0  # rows fed
        self.gestures = 0  # gesture labels in the stretch
        self.label = 0  # label of the current run
        self.start = 0  # its first row
        self.before = 0  # label of the run before it

    def feed(self, lo, smoothed, raw, rest, times, novelty=None, rows=None):
        """Rows ``lo ..`` in (smoothed and raw scores, rest flags, times, with
        ``max_novelty`` their novelty, with ``namer`` their feature rows);
        the segments of the stretches they close out."""
        smoothed = np.asarray(smoothed)
        rest = np.asarray(rest, dtype=bool)
        if lo != self.fed:
            raise IndexError(f"rows fed out of order: {lo}, expected {self.fed}")
        if self.max_novelty is not None:
            if novelty is None:
                raise ValueError("max_novelty is set: feed the rows' novelty too")
            self.novelty.append(novelty)
        if self.namer is not None:
            if rows is None:
                raise ValueError("namer is set: feed the feature rows too")
            rows = np.asarray(rows)
            if self.feature_rows is None:
                self.feature_rows = RowBuffer(rows.shape[1:], capacity=64)
            self.feature_rows.append(rows)
        self.fed = lo + len(smoothed)
        self.raw.append(raw, rest)
        self.rest.append(rest)
        if self.path is None:
            labels = best_path(smoothed, self.classes)
        else:  # the rows decided by these (lag rows earlier, or held)
            decided, owner = self.path.feed_owned(log_scores(smoothed, rest))
            labels = self.classes[decided]
            times = np.asarray(times)[owner]
        return self._label(labels, times)

    def _label(self, labels, times):
        """Labels of the next rows of the path in; the closed segments out."""
        lo = self.n
        labels = np.array(labels, copy=True)
        labels[self.rest.data(lo, lo + len(labels))] = 0
        self.labels.append(labels)
        out = []
        gap = self.max_gap
        for i, lab in enumerate(labels.tolist()):
            j = lo + i
            self.n = j + 1
            if lab != self.label:
                if lab != 0 and (
                    # between two different gestures (not with a namer: their
                    # new names may make them one)
                    (self.label != 0 and self.namer is None)
                    or (
                        self.label == 0
                        and (
                            self.start <= self.cs  # after a rest run already cut
                            or j - self.start > gap  # after a long rest gap
                            or self.before != lab  # between two different classes
                        )
                    )
                ):
                    self._cut(j, int(times[i]), out)
                self.before, self.label, self.start = self.label, lab, j
            if lab != 0:
                self.gestures += 1
            elif j + 1 - self.start > gap:
                self._cut(j + 1, int(times[i]), out)  # inside a long rest run
            if self.max_run is not None and j + 1 - self.cs >= self.max_run:
                self._cut(j + 1, int(times[i]), out)
        return out

    def end(self, stop, now):
        """The stream ends at row ``stop``: the segments of the last stretch."""
        out = []
        if self.path is not None:
            last = self.classes[self.path.finish()]
            out += self._label(last, np.full(len(last), int(now)))
        self._cut(stop, int(now), out)
        self.label, self.start, self.before = 0, stop, 0
        return out

    def _cut(self, b, now, out):
        """Decide rows ``cs .. b - 1`` with the offline functions."""
        cs = self.cs
        if b <= cs:
            return
        if self.gestures:
            raw = self.raw.data(cs, b)
            novelty = namer = None
            if self.max_novelty is not None:
                novelty = novelty_of(self.novelty.data(cs, b))
            if self.namer is not None:
                namer = namer_of(self.feature_rows.data(cs, b), self.namer)
            labels = apply_run_rules(
                self.labels.data(cs, b),
                raw,
                self.classes,
                untracked=self.rest.data(cs, b),
                min_run=self.min_run,
                max_gap=self.max_gap,
                min_confidence=self.min_confidence,
                min_lengths=self.min_lengths,
                max_lengths=self.max_lengths,
                novelty=novelty,
                max_novelty=self.max_novelty,
                namer=namer,
                namer_weight=self.namer_weight,
                max_namer_rest=self.max_namer_rest,
            )
            for cls, s, e, conf in segments_with_confidence(
                labels, raw, self.classes
            ).tolist():
                out.append(StreamSegment(int(cls), cs + int(s), cs + int(e), conf, now))
        self.cs = b
        self.gestures = 0
        for buf in (self.labels, self.raw, self.rest):
            buf.drop(b)
        if self.max_novelty is not None:
            self.novelty.drop(b)
        if self.feature_rows is not None:
            self.feature_rows.drop(b)

    def held(self):
        """Rows of the stretch not yet decided."""
        return self.fed - self.cs
