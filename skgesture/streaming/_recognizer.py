"""StreamingRecognizer: causal, incremental gesture recognition on a live stream.

The recogniser keeps short ring buffers instead of re-running ``predict`` on a
growing buffer. Per pushed frame ``t`` it

1. fills an untracked frame by holding the last tracked one (causal; offline
   :class:`~skgesture.PoseDescriptor` interpolates linearly by default);
2. computes the descriptor of frame ``t - a`` (``a = 4``: 5-tap Gaussian then
   central differences) with the fitted descriptor's own ``_describe`` on the
   last ``2a + 1`` frames, and standardises it with ``mean_`` / ``scale_``;
3. Methods A/B: scores that one descriptor with the segmenter network, smooths
   the score of frame ``t - a - h`` with the interior loess kernel
   (``h = (span - 1) / 2``), thresholds it, tracks runs of activity (a period
   opens once ``min_length`` frames are active and closes at the first rest
   frame), scores the dynamic-pose windows of the open period as their centres
   become available, and at period close runs only
   :func:`~skgesture._multiscale.decide_period` (plus the cubic resizing of
   :func:`~skgesture._multiscale.period_windows` for short periods);
4. Method C: runs the tagger on every completed 10-frame chunk, smooths each
   class track with the same causal loess and emits each run of one gesture
   label of at least ``min_run`` frames when it ends.

Timing, memory bounds and the differences from offline ``predict`` are in the
class docstring and in ``docs/streaming.md``.
"""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from skgesture._descriptor import GAUSSIAN_SIZE, _fill_missing
from skgesture._windows import check_steps, dynamic_poses
from skgesture.utils._smoothing import loess_kernel, loess_smooth
from skgesture.utils._validation import missing_frames

__all__ = ["GestureEvent", "StreamingRecognizer"]

# Look-ahead of the descriptor (METHOD_SPEC §3.6-3.7): the Gaussian reaches 2
# frames ahead and the acceleration P~(t + 2) 2 more, so the descriptor of
# frame t is final once frame t + 4 is known.
DERIVATIVE_REACH = 2  # METHOD_SPEC §3.7: velocity t +- 1, acceleration t +- 2
DEFAULT_MAX_PERIOD = 1200  # frames (60 s at 20 fps) before a period is force-closed
BLOCK = 16  # descriptors handled per step when many frames arrive at once
MAX_BATCH = 1024  # frames described in one call by push_many
RING_MARGIN = 4  # spare rows in every ring buffer


class _Ring:
    """Fixed-capacity ring of rows addressed by their global (ever-growing) index."""

    def __init__(self, capacity, row_shape, dtype=np.float64):
        self.capacity = int(capacity)
        self.data = np.zeros((self.capacity, *row_shape), dtype=dtype)
        self.count = 0  # rows ever appended

    def __len__(self):
        return min(self.count, self.capacity)

    @property
    def first(self):
        """Global index of the oldest row still held."""
        return self.count - len(self)

    def extend(self, rows):
        rows = np.asarray(rows)
        n = len(rows)
        keep = min(n, self.capacity)
        # Row g lives at g % capacity; only the last ``capacity`` rows are kept.
        idx = (self.count + n - keep + np.arange(keep)) % self.capacity
        self.data[idx] = rows[n - keep :]
        self.count += n

    def get(self, lo, hi):
        """Rows ``lo .. hi - 1`` (global indices) as a new array."""
        if lo < self.first or hi > self.count:
            raise IndexError(
                f"rows {lo}..{hi - 1} are not held (ring holds {self.first}.."
                f"{self.count - 1}); this is a bug in StreamingRecognizer"
            )
        return self.data[np.arange(lo, hi) % self.capacity]

    def set(self, lo, rows):
        """Overwrite held rows from global index ``lo`` on."""
        self.data[np.arange(lo, lo + len(rows)) % self.capacity] = rows


@dataclass(frozen=True)
class GestureEvent:
    """One recognised gesture, as emitted by :class:`StreamingRecognizer`.

    Frames are 0-based indices of the stream (the first pushed frame is 0).

    Parameters
    ----------
    label : int
        Gesture class, as in the training labels ``y`` (never 0).
    start : int
        First frame of the gesture.
    end : int
        One past its last frame (exclusive, like a Python slice).
    confidence : float
        Mean best fused window score of the windows behind it (Methods A/B),
        or the mean raw tagger probability of the class over the run
        (Method C).
    emitted_at : int
        Index of the pushed frame whose ``push`` (or ``flush``) returned it.
    name : str or None, default=None
        Class name when the recogniser was given ``target_names``.

    Examples
    --------
    >>> from skgesture.streaming import GestureEvent
    >>> ev = GestureEvent(label=3, start=10, end=50, confidence=0.9, emitted_at=62)
    >>> ev.delay, ev.n_frames
    (13, 40)
    """

    label: int
    start: int
    end: int
    confidence: float
    emitted_at: int
    name: str | None = None

    @property
    def delay(self):
        """Frames between the gesture's last frame and its emission."""
        return self.emitted_at - (self.end - 1)

    @property
    def n_frames(self):
        """Length of the gesture in frames."""
        return self.end - self.start

    def to_segment(self):
        """The ``(class, start, end, confidence)`` row of ``predict_segments``.

        Returns
        -------
        tuple
            ``(label, start, end, confidence)``.
        """
        return (self.label, self.start, self.end, self.confidence)


def _check_span(span, owner):
    """Odd integer span of a causal loess; fractions depend on the stream length."""
    if isinstance(span, Real) and not isinstance(span, Integral) and 0 < span < 1:
        raise ValueError(
            f"{owner}.smooth_span={span!r} is a fraction of the sequence length, "
            f"which a stream does not know in advance; use an integer span"
        )
    kernel = loess_kernel(span)
    return len(kernel), kernel


def _proba_function(estimator):
    """``predict_proba`` of a fitted 2-D classifier, as a fast callable.

    For a :class:`~skgesture.TorchMLPClassifier` on the CPU the module is called
    directly: the same float32 forward pass and output map as
    ``predict_proba`` (hence the same numbers), without its per-call input
    validation and ``eval()`` walk, which cost more than the forward pass of one
    row.
    """
    import torch

    from skgesture._mlp import TorchMLPClassifier

    if not isinstance(estimator, TorchMLPClassifier):
        return estimator.predict_proba
    module = estimator.net_.module_
    if next(module.parameters()).device.type != "cpu":
        return estimator.predict_proba
    module.eval()
    binary = len(estimator.classes_) == 2

    def proba(X):
        with torch.inference_mode():
            logits = module(torch.from_numpy(np.asarray(X, dtype=np.float32)))
            if binary:
                p = torch.sigmoid(logits)[:, 0].numpy().astype(np.float64)
                return np.column_stack([1.0 - p, p])
            return torch.softmax(logits, dim=1).numpy().astype(np.float64)

    return proba


class StreamingRecognizer:
    """Recognise gestures frame by frame on a live skeleton stream.

    Wraps a fitted Method A or B pipeline (:func:`~skgesture.make_method_a`,
    :func:`~skgesture.make_method_b`: descriptor, segmenter, windows,
    multi-scale classifier) or Method C pipeline
    (:func:`~skgesture.make_method_c`: descriptor, BiLSTM tagger). Each
    :meth:`push` takes one Kinect v1 frame and returns the gestures that became
    certain with it; :meth:`flush` ends the stream. It only ever looks at frames
    already pushed, and the work per frame is constant: the descriptor of one
    frame from the last ``2a + 1`` frames, one segmenter row, at most one
    window every ``stride`` frames (Methods A/B) or one tagger chunk every
    ``window`` frames (Method C).

    Parameters
    ----------
    pipeline : sklearn.pipeline.Pipeline
        A fitted pipeline: ``PoseDescriptor -> ActivitySegmenter ->
        DynamicPoseWindow -> MultiScaleClassifier`` (Methods A/B) or
        ``PoseDescriptor -> BiLSTMTagger`` (Method C). Its decision parameters
        (thresholds, spans, minimum lengths) are read when the recogniser is
        built; build a new one after ``set_params``.
    max_period : int, default=1200
        Methods A/B: an activity period this long (in frames) is closed and
        decided, and activity that continues opens a new period. This bounds
        memory and delay on a stream that never rests; offline ``predict``
        has no such cap.
    target_names : sequence of str or None, default=None
        ``target_names[k - 1]`` names class ``k`` in the events (as the
        dataset loaders' ``target_names``).
    schedule : {"eager", "balanced"}, default="eager"
        ``"eager"`` does all the work a frame allows in its own :meth:`push`.
        ``"balanced"`` spreads it to lower the worst push: the descriptors of
        two frames are computed every other push, and the decisions they lead
        to (windows, periods, events) on the push in between. Same events,
        emitted up to 2 frames later; :meth:`push_many` stays eager.

    Attributes
    ----------
    method : {"multiscale", "tagger"}
        Which kind of pipeline is wrapped.
    lookahead : int
        ``a + h``: frames between a frame and the moment its smoothed score is
        known (``a = 4`` descriptor frames, ``h = (span - 1) / 2`` smoothing
        frames; 11 with the paper's span 15).
    max_delay : int
        Frames between the last frame of a gesture and its event, at most,
        once its period is known to be short or long (see Notes):
        ``lookahead + 2 hw + stride`` for Methods A/B (21 with the paper's
        numbers; ``hw`` is the half span of the widest window), ``lookahead +
        window`` for Method C.
    max_backfill : int
        Untracked frames at the start of a stream that are replaced by copies
        of the first tracked frame, as offline filling does (``2 span + 2a +
        1``, 39 with span 15); earlier ones are rest.
    classes_ : ndarray
        Gesture classes of the wrapped classifier (rest excluded).
    n_frames_seen : int
        Frames pushed in the current stream.

    See Also
    --------
    ActionMap : Turns events into robot commands.
    ReplaySource : Replays a recorded stream frame by frame.

    Notes
    -----
    **Timing** (``a = 4``, ``h = (span - 1) // 2``, ``L = a + h``). The
    smoothed score of frame ``u`` is known with frame ``u + L``, so:

    * a *short* period ``[s, e)`` (fewer than ``short_length`` frames) is
      decided with frame ``e + L`` (``e`` = first rest frame): the event is
      emitted ``L + 1`` frames after the gesture's last frame (12 with span 15);
    * in a *long* period, a run of at least ``min_consecutive`` windows of one
      class is emitted as soon as no later window can change its frames. A
      frame goes to the run with the nearest window centre (decision D17) and
      a run only claims frames within ``hw`` of its centres, so a run whose
      last centre is ``c`` is final once the next window that could start a
      qualifying run is centred at ``c + 2 hw`` or later: at most
      ``L + 2 hw + stride`` frames (21) after the run's last frame, 17 when
      rest follows. It is never emitted before the period is known to be long
      (frame ``s + short_length - 1 + L``): until then the period could still
      end short and be decided by majority vote;
    * Method C: a frame's probabilities are final when its 10-frame chunk is
      complete, so an event comes ``L + 1`` to ``L + window`` frames after the
      gesture's last frame.

    **Agreement with offline predict.** The events equal the rows of
    ``predict_segments`` on the whole recorded stream (same classes, frames
    and confidences up to float rounding of one-row versus batched network
    calls) when the offline descriptor fills untracked frames the same way
    (``descriptor__fill="hold"``) and no period reaches ``max_period``. The
    remaining differences: (1) untracked frames are held, not linearly
    interpolated, so windows over a dropout differ; (2) a frame whose torso is
    degenerate reuses the basis of the last good frame among the previous 8,
    not of any earlier frame; (3) of the untracked frames at the start of a
    stream, only the last ``max_backfill`` become copies of the first tracked
    frame (offline: all of them), so when that pose counts as active the
    period starts later and its window grid may shift.

    **Memory.** Ring buffers of raw frames (``2a + 2``), descriptors and scores
    (a few dozen rows), the window scores of the open period (at most
    ``max_period / stride``) and one running sum (Method C): a stream of any
    length uses the same memory (:meth:`buffer_lengths`).

    The recogniser is a runtime object, not an estimator: its parameters are
    checked when it is built.

    Examples
    --------
    >>> from sklearn.linear_model import LogisticRegression
    >>> from skgesture import make_method_a
    >>> from skgesture.datasets import make_gesture_streams
    >>> from skgesture.streaming import StreamingRecognizer
    >>> data = make_gesture_streams(n_sequences=4, n_classes=3, random_state=0)
    >>> pipe = make_method_a(random_state=0).set_params(
    ...     segmenter__estimator=LogisticRegression(),
    ...     classifier__estimator=LogisticRegression())
    >>> pipe = pipe.fit(data.X[:3], data.y[:3])
    >>> rec = StreamingRecognizer(pipe)
    >>> rec.lookahead, rec.max_delay
    (11, 21)
    >>> events = []
    >>> for frame in data.X[3]:
    ...     events += rec.push(frame)
    >>> events += rec.flush()
    >>> all(0 <= ev.delay <= rec.max_delay + 55 for ev in events)
    True
    """

    def __init__(
        self,
        pipeline,
        *,
        max_period=DEFAULT_MAX_PERIOD,
        target_names=None,
        schedule="eager",
    ):
        self.pipeline = pipeline
        self.max_period = max_period
        self.target_names = target_names
        self.schedule = schedule
        self._inspect()
        self.reset()

    # -- public API ------------------------------------------------------------

    def push(self, frame):
        """Feed one frame; return the gestures that became certain with it.

        Parameters
        ----------
        frame : array-like of shape (20, 3) or (60,)
            Joint positions in metres, Kinect v1 order (see
            :mod:`skgesture.streaming` adapters for other layouts). An
            untracked frame is all zeros or holds a NaN.

        Returns
        -------
        list of GestureEvent
            Possibly empty, in the order the gestures were decided.
        """
        frame = self._check_frame(frame)
        return self._ingest(frame[None])

    def push_many(self, frames):
        """Feed several frames at once; same events as pushing them one by one.

        Descriptors and segmenter scores are computed in blocks (faster for
        replaying recordings); every event keeps the ``emitted_at`` frame it
        would have with :meth:`push`. Only float rounding of batched network
        calls can differ.

        Parameters
        ----------
        frames : array-like of shape (n_frames, 20, 3)
            Consecutive frames.

        Returns
        -------
        list of GestureEvent
            Events decided while these frames arrived.
        """
        frames = np.asarray(frames, dtype=np.float64)
        if frames.ndim != 3 or frames.shape[1:] != self._frame_shape:
            raise ValueError(
                f"frames must have shape (n_frames, {self._frame_shape[0]}, "
                f"{self._frame_shape[1]}), got {frames.shape}"
            )
        events = []
        for lo in range(0, len(frames), MAX_BATCH):
            events += self._ingest(frames[lo : lo + MAX_BATCH])
        return events

    def flush(self):
        """End the stream: decide everything still open, then reset.

        The last ``lookahead`` frames are completed with the offline end rules
        (replicate padding of the descriptor, end-point loess fits), exactly
        as ``predict`` treats the end of a sequence. The recogniser is then
        ready for a new stream.

        Returns
        -------
        list of GestureEvent
            The remaining events; ``emitted_at`` is the last frame pushed.
        """
        events = []
        if self._last_tracked is not None:
            self._events = events
            self._finish()
        self.reset()
        return events

    def recognize(self, stream):
        """Push a whole recorded stream and flush it.

        Parameters
        ----------
        stream : array-like of shape (n_frames, 20, 3)
            The recording.

        Returns
        -------
        list of GestureEvent
            All its events, in emission order.
        """
        self.reset()
        return self.push_many(stream) + self.flush()

    def reset(self):
        """Forget the current stream (nothing is emitted)."""
        self.n_frames_seen = 0
        self._n_leading = 0  # untracked frames before the first tracked one
        self._origin = 0  # stream index of local frame 0
        self._floor = 0  # events found while back-filling are emitted here
        self._last_tracked = None
        # 2a frames of context, +2 for the frames a balanced push describes late.
        self._raw = _Ring(2 * self._reach + 2, self._frame_shape)
        self._desc = _Ring(self._desc_capacity, (self._n_features,))
        self._scores = _Ring(self._score_capacity, (self._n_tracks,))
        self._score_time = _Ring(self._score_capacity, (), dtype=np.int64)
        self._n_smoothed = 0
        self._events = []
        self._deferred = []  # smoothed blocks awaiting their decisions (balanced)
        self._deferring = False
        if self.method == "multiscale":
            self._reset_run()
        else:
            self._chunk_sum = np.zeros(
                (self._window + self._chunk_step, self._n_tracks)
            )
            self._chunk_count = np.zeros(self._window + self._chunk_step)
            self._chunk_base = 0  # local frame of _chunk_sum[0]
            self._next_chunk = 0  # start of the next regular chunk
            self._label = 0
            self._label_start = 0
            self._label_sum = 0.0

    def buffer_lengths(self):
        """Number of rows currently held by each internal buffer.

        Returns
        -------
        dict of str to int
            ``raw`` frames, ``descriptors``, ``scores`` (segmenter or tagger
            rows awaiting smoothing), ``windows`` (window scores of the open
            period, Methods A/B) and ``emitted`` (events of the open period
            already sent). Each stays below a bound fixed when the recogniser
            is built, whatever the stream length.
        """
        out = {
            "raw": len(self._raw),
            "descriptors": len(self._desc),
            "scores": len(self._scores),
        }
        if self.method == "multiscale":
            out["windows"] = len(self._win_scores)
            out["emitted"] = len(self._emitted)
        return out

    def buffer_capacities(self):
        """Upper bound of every entry of :meth:`buffer_lengths`.

        Returns
        -------
        dict of str to int
            The fixed bounds.
        """
        out = {
            "raw": self._raw.capacity,
            "descriptors": self._desc.capacity,
            "scores": self._scores.capacity,
        }
        if self.method == "multiscale":
            n_windows = self.max_period // self._stride + 1
            out["windows"] = n_windows
            out["emitted"] = n_windows
        return out

    # -- set-up ----------------------------------------------------------------

    def _inspect(self):
        """Find the stages of the pipeline and read their decision parameters."""
        from sklearn.utils.validation import check_is_fitted

        from skgesture._descriptor import PoseDescriptor

        steps = getattr(self.pipeline, "steps", None)
        if not steps:
            raise TypeError(
                "pipeline must be a fitted sklearn Pipeline (make_method_a/b/c), got "
                f"{type(self.pipeline).__name__}"
            )
        stages = [est for _, est in steps if est not in (None, "passthrough")]
        desc = stages[0]
        if not isinstance(desc, PoseDescriptor):
            raise ValueError(
                "the pipeline must start with a PoseDescriptor, got "
                f"{type(desc).__name__}"
            )
        for est in stages:
            check_is_fitted(est)
        if self.schedule not in ("eager", "balanced"):
            raise ValueError(
                f"schedule must be 'eager' or 'balanced', got {self.schedule!r}"
            )
        if not isinstance(self.max_period, Integral) or self.max_period < 1:
            raise ValueError(
                f"max_period must be a positive int, got {self.max_period!r}"
            )
        self._descriptor = desc
        self._spec = desc._spec()
        self._frame_shape = tuple(desc.frame_shape_in_)
        self._n_features = desc.n_features_out_
        gauss_reach = (GAUSSIAN_SIZE - 1) // 2 if desc.sigma > 0 else 0
        self._reach = gauss_reach + DERIVATIVE_REACH  # a
        # Leading untracked frames copied from the first tracked one.
        self.max_backfill = 0
        rest = stages[1:]
        kinds = [type(est).__name__ for est in rest]
        if kinds == ["BiLSTMTagger"]:
            self._inspect_tagger(rest[0])
        elif kinds == [
            "ActivitySegmenter",
            "DynamicPoseWindow",
            "MultiScaleClassifier",
        ]:
            self._inspect_multiscale(*rest)
        elif kinds == ["DynamicPoseWindow", "MultiScaleClassifier"]:
            raise ValueError(
                "the pipeline has no ActivitySegmenter (make_method_a/b with "
                "segment=False): it treats a whole sequence as one period, which a "
                "stream never completes; fit it with segment=True"
            )
        else:
            raise ValueError(
                "unsupported pipeline: expected PoseDescriptor -> ActivitySegmenter -> "
                "DynamicPoseWindow -> MultiScaleClassifier (Methods A/B) or "
                f"PoseDescriptor -> BiLSTMTagger (Method C), got {kinds}"
            )
        self.max_backfill = 2 * self._span + 2 * self._reach + 1
        if self.target_names is not None and len(self.target_names) < max(
            self.classes_
        ):
            raise ValueError(
                f"target_names has {len(self.target_names)} names but the classes go "
                f"up to {max(self.classes_)}"
            )

    def _inspect_multiscale(self, seg, windows, clf):
        self.method = "multiscale"
        self._span, self._kernel = _check_span(seg.smooth_span, "ActivitySegmenter")
        self._h = (self._span - 1) // 2
        self._threshold = seg.threshold
        self._min_length = seg.min_length
        self._seg_est = seg.estimator_
        self._seg_proba = _proba_function(seg.estimator_)
        self._seg_column = list(seg.estimator_.classes_).index(1)
        steps = check_steps(clf.steps, clf.n_poses)
        if check_steps(windows.steps, windows.n_poses) != steps or (
            windows.n_poses != clf.n_poses
        ):
            raise ValueError(
                f"DynamicPoseWindow(steps={tuple(windows.steps)}, n_poses="
                f"{windows.n_poses}) does not match MultiScaleClassifier(steps="
                f"{tuple(clf.steps)}, n_poses={clf.n_poses})"
            )
        self._clf = clf
        self._steps = steps
        self._n_poses = clf.n_poses
        self._half = max(steps) * (clf.n_poses - 1) // 2  # hw: window half span
        self._stride = clf.stride
        self._min_windows = clf.min_windows
        # A period shorter than this has fewer than min_windows windows and is
        # resized (METHOD_SPEC §5.3, period_windows).
        self._n_resize = 2 * self._half + 1 + self._stride * (self._min_windows - 1)
        self._fusion = clf._fusion_weights(len(steps))
        self._win_proba = [_proba_function(est) for est in clf.estimators_]
        self._decide_kwargs = {
            "short_length": clf.short_length,
            "threshold_short": clf.threshold_short,
            "threshold_long": clf.threshold_long,
            "min_consecutive": clf.min_consecutive,
            "half_span": self._half,
        }
        self.classes_ = np.asarray(clf.classes_)
        if self.max_period < max(self._n_resize, self._min_length):
            raise ValueError(
                f"max_period={self.max_period} is shorter than a period needs "
                f"({max(self._n_resize, self._min_length)} frames)"
            )
        self._n_tracks = 1
        need = max(self._min_length, self._n_resize, 2 * self._half + 1)
        self._desc_capacity = BLOCK + self._h + need + RING_MARGIN
        self._score_capacity = BLOCK + 2 * self._span + 2 * self._reach + RING_MARGIN
        self.lookahead = self._reach + self._h
        # A run is final once no window within 2 hw of its end can still join a
        # qualifying run (see _scan_runs); short periods need only L + 1.
        self.max_delay = self.lookahead + 2 * self._half + self._stride

    def _inspect_tagger(self, tagger):
        from skgesture._bilstm import _chunks

        self.method = "tagger"
        self._span, self._kernel = _check_span(tagger.smooth_span, "BiLSTMTagger")
        self._h = (self._span - 1) // 2
        self._tagger = tagger
        self._chunks = _chunks
        self._window = int(tagger.window)
        self._overlap = bool(tagger.overlap) and self._window > 1
        self._chunk_step = max(self._window // 2, 1) if self._overlap else self._window
        self._min_run = tagger.min_run
        self._tagger_classes = np.asarray(tagger.classes_)
        self.classes_ = self._tagger_classes[self._tagger_classes != 0]
        self._n_tracks = len(self._tagger_classes)
        self._desc_capacity = BLOCK + self._window + self._chunk_step + RING_MARGIN
        self._score_capacity = (
            BLOCK + 2 * self._span + 2 * self._reach + 2 * self._window + RING_MARGIN
        )
        self.lookahead = self._reach + self._h
        self.max_delay = self.lookahead + self._window

    def _check_frame(self, frame):
        frame = np.asarray(frame, dtype=np.float64)
        if frame.shape != self._frame_shape:
            if frame.size == np.prod(self._frame_shape):
                return frame.reshape(self._frame_shape)
            raise ValueError(
                f"a frame must have shape {self._frame_shape} (Kinect v1 joints x "
                f"xyz, metres), got {frame.shape}; map other layouts with an adapter "
                f"from skgesture.streaming"
            )
        return frame

    # -- ingestion -------------------------------------------------------------

    def _ingest(self, frames):
        """Fill, describe and score new frames; return the events they decide."""
        self._events = []
        first_index = self.n_frames_seen
        self.n_frames_seen += len(frames)
        if len(frames) == 1:  # push(): the rule of missing_frames, for one frame
            frame = frames[0]
            missing = np.array([bool(np.isnan(frame).any() or not frame.any())])
        else:
            missing = missing_frames(frames)
        if self._last_tracked is None:
            if missing.all():
                self._n_leading += len(frames)
                return []
            k = int(np.argmax(~missing))
            self._n_leading += k
            frames, missing = frames[k:], missing[k:]
            # Offline fill copies the first tracked frame backwards; copy up to
            # _max_backfill of the leading untracked frames, older ones are rest.
            n_copies = min(self._n_leading, self.max_backfill)
            self._origin = self._n_leading - n_copies
            self._floor = first_index + k
            frames = np.concatenate([np.repeat(frames[:1], n_copies, axis=0), frames])
            missing = np.concatenate([np.zeros(n_copies, dtype=bool), missing])
            self._last_tracked = frames[0]
        # Causal fill: hold the last tracked frame (offline default: linear).
        if len(frames) == 1:  # push(): no need for the general fill
            held = self._last_tracked[None] if missing[0] else frames
        else:
            held = _fill_missing(
                np.concatenate([self._last_tracked[None], frames]),
                np.concatenate([[False], missing]),
                "hold",
            )[1:]
        self._last_tracked = held[-1]
        context = self._raw.get(self._raw.first, self._raw.count)
        base = self._raw.first
        self._raw.extend(held)
        now = self._raw.count - 1
        n_final = self._raw.count - self._reach  # descriptors final: frames < n_final
        if self._deferred and (len(held) > 1 or self.schedule == "eager"):
            self._drain(now)
        elif self._deferred:  # balanced: this push makes the deferred decisions
            self._drain(now)
            return self._events
        if n_final > self._desc.count:
            self._deferring = self.schedule == "balanced" and len(held) == 1
            try:
                self._describe(np.concatenate([context, held]), base, n_final)
            finally:
                self._deferring = False
        return self._events

    def _drain(self, now):
        """Make the decisions deferred by a balanced push, as of frame ``now``."""
        deferred, self._deferred = self._deferred, []
        for lo, values, times, raw in deferred:
            self._decide_smoothed(lo, values, np.maximum(times, now), raw)

    def _describe(self, seq, base, stop):
        """Descriptors of local frames ``self._desc.count .. stop - 1`` from ``seq``
        (local frames ``base ..``), processed in blocks of ``BLOCK``."""
        desc = self._descriptor
        raw = desc._describe(seq, self._spec)
        rows = (raw[self._desc.count - base : stop - base] - desc.mean_) / desc.scale_
        for lo in range(0, len(rows), BLOCK):
            block = rows[lo : lo + BLOCK]
            first = self._desc.count
            self._desc.extend(block)
            # Descriptor of local frame u is known with local frame u + a.
            self._on_descriptors(block, first)

    def _on_descriptors(self, D, first):
        if self.method == "multiscale":
            p = self._seg_proba(D)[:, self._seg_column]
            times = np.arange(first, first + len(D)) + self._reach
            self._add_scores(p[:, None], np.minimum(times, self._raw.count - 1))
        else:
            self._run_chunks()

    def _add_scores(self, rows, times):
        self._scores.extend(rows)
        self._score_time.extend(times)
        self._advance_smoothing()

    # -- causal loess ----------------------------------------------------------

    def _advance_smoothing(self):
        """Smooth every frame whose loess window is complete (METHOD_SPEC §8.1)."""
        h, n = self._h, self._scores.count
        if h == 0:
            if n > self._n_smoothed:
                lo = self._n_smoothed
                self._on_smoothed(
                    lo, self._scores.get(lo, n), self._score_time.get(lo, n)
                )
            return
        if self._n_smoothed == 0 and n >= 2 * h:
            # Start of the stream: MATLAB's end-point fits on the first 2h
            # scores, as loess_smooth does at the start of a sequence.
            head = loess_smooth(self._scores.get(0, 2 * h), self._span, axis=0)[:h]
            t = int(self._score_time.get(2 * h - 1, 2 * h)[0])
            self._on_smoothed(0, head, np.full(h, t))
        lo = max(self._n_smoothed, h)
        stop = n - h  # frames lo .. stop - 1 have all their neighbours
        if self._n_smoothed >= h and stop > lo:
            m = stop - lo
            window = self._scores.get(lo - h, stop + h)
            # Same accumulation order as loess_smooth (bitwise equal values).
            acc = np.zeros((m, self._n_tracks))
            for k in range(1, self._span - 1):
                acc += self._kernel[k] * window[k : k + m]
            self._on_smoothed(lo, acc, self._score_time.get(lo + h, stop + h))

    def _finish_smoothing(self):
        """Smooth the remaining frames with the end-point rule (end of stream)."""
        n = self._scores.count
        if n <= self._n_smoothed:
            return
        first = self._scores.first
        smoothed = loess_smooth(self._scores.get(first, n), self._span, axis=0)
        lo = self._n_smoothed
        self._on_smoothed(
            lo, smoothed[lo - first :], np.full(n - lo, self._raw.count - 1)
        )

    def _on_smoothed(self, lo, values, times):
        self._n_smoothed = lo + len(values)
        raw = None
        if self.method == "tagger":
            raw = self._scores.get(lo, lo + len(values))
        if self._deferring:
            self._deferred.append((lo, values, times, raw))
        else:
            self._decide_smoothed(lo, values, times, raw)

    def _decide_smoothed(self, lo, values, times, raw):
        if self.method == "multiscale":
            active = values[:, 0] > self._threshold
            for i in range(len(values)):
                self._on_activity(lo + i, bool(active[i]), int(times[i]))
        else:
            labels = self._tagger_classes[np.argmax(values, axis=1)]
            for i in range(len(values)):
                self._on_label(lo + i, labels[i], raw[i], int(times[i]))

    # -- Methods A/B: periods, windows, decisions -------------------------------

    def _reset_run(self):
        self._run_start = None
        self._length = 0
        self._open = False
        self._long = False
        self._next_centre = 0
        self._win_scores = []
        self._win_centres = []
        self._rec = []
        self._scan_pos = 0
        self._run_first = 0
        self._pending = []  # finished runs (first, end window) not yet final
        self._emitted = set()

    def _on_activity(self, u, active, now):
        if not active:
            if self._run_start is not None:
                if self._open:
                    self._close(u, now)
                self._reset_run()
            return
        if self._run_start is None:
            self._run_start = u
            self._next_centre = u + self._half
        n_active = self._length = u - self._run_start + 1
        if not self._open and n_active >= self._min_length:
            self._open = True
        if not self._open:
            return
        self._score_windows(u)
        if not self._long and n_active >= self._decide_kwargs["short_length"]:
            self._long = True
        if self._long:
            self._scan_runs(now)
        if n_active >= self.max_period:
            self._close(u + 1, now)
            self._reset_run()

    def _fused_scores(self, wins):
        """Fused class scores of windows ``(n, n_scales, width)``, as offline."""
        return sum(
            wk * proba(wins[:, k])
            for k, (wk, proba) in enumerate(zip(self._fusion, self._win_proba))
        )

    def _score_windows(self, u):
        """Score the windows whose frames are all known to be in the period."""
        hw, stride = self._half, self._stride
        last = u - hw  # largest centre whose window ends inside the period
        if self._next_centre > last:
            return
        centres = np.arange(self._next_centre, last + 1, stride)
        D = self._desc.get(centres[0] - hw, centres[-1] + hw + 1)
        wins = dynamic_poses(D, self._steps, self._n_poses, centres - centres[0] + hw)
        scores = self._fused_scores(wins)
        self._next_centre = int(centres[-1]) + stride
        best = np.argmax(scores, axis=1)
        top = scores[np.arange(len(scores)), best]
        thr = self._decide_kwargs["threshold_long"]
        self._win_scores.extend(scores)
        self._win_centres.extend(int(c) - self._run_start for c in centres)
        self._rec.extend(np.where(top > thr, best, -1).tolist())

    def _scan_runs(self, now):
        """Long period: emit the runs of windows that no later window can change.

        A frame belongs to a run only inside the run's extent (its centres
        +- ``hw``) and goes to the nearest centre, the earlier run on ties
        (METHOD_SPEC §5.5, decision D17). A finished run whose last centre is
        ``c`` is therefore final once every window that could still join a
        qualifying run is centred at ``c + 2 hw`` or later: the next window to
        come, or the first window of a trailing run of one class still shorter
        than ``min_consecutive``.
        """
        rec, n = self._rec, len(self._rec)
        min_run = self._decide_kwargs["min_consecutive"]
        for i in range(self._scan_pos, n):
            if i > 0 and rec[i] != rec[i - 1]:
                a = self._run_first
                if rec[a] >= 0 and i - a >= min_run:
                    self._pending.append((a, i))
                self._run_first = i
        self._scan_pos = n
        if not self._pending:
            return
        first = self._run_first
        if rec[first] >= 0 and n - first < min_run:
            frontier = self._win_centres[first]
        else:
            frontier = self._win_centres[-1] + self._stride
        while self._pending:
            a, b = self._pending[0]
            if self._win_centres[b - 1] + 2 * self._half > frontier:
                break
            self._pending.pop(0)
            self._emit_run(a, now)

    def _emit_run(self, a, now):
        """Emit the segment of the run starting at window ``a``, decided with
        the offline rule on every window of the period so far."""
        from skgesture._multiscale import decide_period

        _, segs = decide_period(
            np.asarray(self._win_scores), np.asarray(self._win_centres),
            self._length, **self._decide_kwargs,
        )  # fmt: skip
        c0 = self._win_centres[a]
        for seg in segs:
            if seg[1] <= c0 < seg[2]:
                self._emit_segment(seg, now)

    def _emit_segment(self, seg, now):
        cls, lo, hi, conf = seg
        key = (int(cls), int(lo), int(hi))
        if key in self._emitted:
            return
        self._emitted.add(key)
        label = int(self.classes_[cls - 1])
        start = self._origin + self._run_start + int(lo)
        self._emit(label, start, self._origin + self._run_start + int(hi), conf, now)

    def _emit(self, label, start, end, confidence, now):
        name = None
        if self.target_names is not None:
            name = self.target_names[label - 1]
        self._events.append(
            GestureEvent(
                label=label,
                start=int(start),
                end=int(end),
                confidence=float(confidence),
                emitted_at=max(self._origin + int(now), self._floor),
                name=name,
            )
        )

    def _close(self, end, now):
        """Decide the period ``[run_start, end)`` with the offline rule."""
        from skgesture._multiscale import decide_period, period_windows

        s = self._run_start
        length = end - s
        if length >= self._n_resize:
            scores = np.asarray(self._win_scores)
            centres = np.asarray(self._win_centres)
        else:
            # Too short for min_windows windows: resize it (METHOD_SPEC §5.3).
            D = self._desc.get(s, end)
            W = dynamic_poses(D, self._steps, self._n_poses)
            wins, centres, _ = period_windows(
                W, 0, length, self._steps, n_poses=self._n_poses,
                stride=self._stride, min_windows=self._min_windows,
                resize=self._clf.resize,
            )  # fmt: skip
            scores = self._fused_scores(wins)
        _, segs = decide_period(scores, centres, length, **self._decide_kwargs)
        final = {(int(c), int(lo), int(hi)) for c, lo, hi, _ in segs}
        if not self._emitted <= final:
            warnings.warn(
                "StreamingRecognizer emitted a gesture that the offline decision "
                "rule no longer gives at the end of its period; the rule of "
                "decide_period changed in a way the early emission does not know",
                RuntimeWarning,
                stacklevel=2,
            )
        for seg in segs:
            self._emit_segment(seg, now)

    # -- Method C: chunks and label runs ---------------------------------------

    def _run_chunks(self):
        """Run the tagger on every regular chunk whose descriptors are known."""
        W, step = self._window, self._chunk_step
        while self._next_chunk + W <= self._desc.count:
            s = self._next_chunk
            self._add_chunk(s, s + W)
            # Frames s .. s + step - 1 are covered by no later regular chunk.
            self._release_frames(
                s + step, min(s + W - 1 + self._reach, self._raw.count - 1)
            )
            self._next_chunk += step

    def _add_chunk(self, s, e):
        D = self._desc.get(s, e)
        proba = self._tagger.predict_proba([D])[0]
        i = s - self._chunk_base
        self._chunk_sum[i : i + (e - s)] += proba
        self._chunk_count[i : i + (e - s)] += 1

    def _release_frames(self, stop, now):
        """Hand the averaged probabilities of frames ``chunk_base .. stop - 1`` on."""
        n = stop - self._chunk_base
        if n <= 0:
            return
        rows = self._chunk_sum[:n] / self._chunk_count[:n, None]
        self._chunk_sum = np.roll(self._chunk_sum, -n, axis=0)
        self._chunk_count = np.roll(self._chunk_count, -n)
        self._chunk_sum[-n:] = 0.0
        self._chunk_count[-n:] = 0
        self._chunk_base = stop
        self._add_scores(rows, np.full(n, now))

    def _finish_chunks(self):
        """End of stream: the chunks the offline tagger adds at the end."""
        T = self._desc.count
        W, step = self._window, self._chunk_step
        extra = [
            (s, e) for s, e in self._chunks(T, W, self._overlap)
            if e - s < W or s % step
        ]  # fmt: skip
        for s, e in extra:
            D = self._desc.get(s, e)
            proba = self._tagger.predict_proba([D])[0]
            # Frames already handed on (still unsmoothed) get the extra chunk too.
            done = max(min(self._chunk_base, e) - s, 0)
            if done:
                held = self._scores.get(s, s + done)
                counts = self._released_counts(s, s + done)
                self._scores.set(
                    s, (held * counts[:, None] + proba[:done]) / (counts[:, None] + 1)
                )
            i = max(s - self._chunk_base, 0)
            self._chunk_sum[i : i + (e - s - done)] += proba[done:]
            self._chunk_count[i : i + (e - s - done)] += 1
        self._release_frames(T, self._raw.count - 1)

    def _released_counts(self, lo, hi):
        """Regular chunks that covered frames ``lo .. hi - 1``."""
        W, step = self._window, self._chunk_step
        u = np.arange(lo, hi)
        last = (u // step) * step  # start of the last regular chunk over u
        first = np.maximum(u - W + 1 + step - 1, 0) // step * step
        return ((last - first) // step + 1).astype(float)

    def _on_label(self, u, label, raw, now):
        if label == self._label:
            if label != 0:
                self._label_sum += raw[self._column(label)]
            return
        self._end_label_run(u, now)
        self._label, self._label_start = label, u
        self._label_sum = raw[self._column(label)] if label != 0 else 0.0

    def _column(self, label):
        return int(np.searchsorted(self._tagger_classes, label))

    def _end_label_run(self, end, now):
        length = end - self._label_start
        if self._label != 0 and length >= self._min_run:
            self._emit(
                int(self._label), self._origin + self._label_start, self._origin + end,
                self._label_sum / length, now,
            )  # fmt: skip

    # -- end of stream -----------------------------------------------------------

    def _finish(self):
        n = self._raw.count
        self._drain(n - 1)
        if n > self._desc.count:
            self._describe(self._raw.get(self._raw.first, n), self._raw.first, n)
        if self.method == "tagger":
            self._finish_chunks()
        self._finish_smoothing()
        now = n - 1
        if self.method == "multiscale":
            if self._run_start is not None and self._open:
                self._close(self._n_smoothed, now)
            self._reset_run()
        else:
            self._end_label_run(self._n_smoothed, now)
