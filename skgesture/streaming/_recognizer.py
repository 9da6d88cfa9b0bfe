"""StreamingRecognizer: causal, incremental gesture recognition on a live stream.

The recogniser composes the incremental steps of the stages of a fitted
pipeline (docs/design.md, "Incremental steps"): each pushed frame goes through
``stage.stream_step`` of every stage in turn, and the gestures the last stage
decides come back as :class:`GestureEvent` objects. It knows nothing of the
stages' internals: any pipeline whose stages implement the protocol streams,
and each stage's step uses the stage's own offline rules, so the events are
the rows of ``predict_segments`` on the whole recording (docs/streaming.md,
"Agreement with offline predict"). At an input rate other than the model's
(``fps=``), :class:`skgesture._rate.FrameResampler` comes first, and the events'
frames are mapped back to the input's (docs/streaming.md, "Frame rates").
"""

# SPDX-License-Identifier: BSD-3-Clause

import math
from dataclasses import dataclass
from numbers import Integral

import numpy as np

from skgesture._rate import FrameResampler, check_fps, same_rate
from skgesture._stream import (
    DEFAULT_MAX_BACKFILL,
    DEFAULT_MAX_PERIOD,
    missing_stream_methods,
    stream_frames,
)
from skgesture.utils._buffers import _concat_rows

__all__ = ["GestureEvent", "StreamingRecognizer"]

MAX_BATCH = 1024  # frames handed to the stages in one step by push_many
# Input frames added to the delays when resampling: ceil(ratio / 2) + 2, the
# frame a model-rate frame waits for before it is handed on (the next one must
# be complete) and the rounding of the map back to input frames
# (skgesture._rate), ratio being input frames per model-rate frame.
RESAMPLE_DELAY = 2


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


class StreamingRecognizer:
    """Recognise gestures frame by frame on a live skeleton stream.

    Wraps a fitted pipeline whose stages implement the incremental protocol
    of docs/design.md ("Incremental steps"): every stage of skgesture does, so
    Methods A and B (:func:`~skgesture.make_method_a`,
    :func:`~skgesture.make_method_b`), Method C (:func:`~skgesture.make_method_c`)
    and any other chain of the toolkit's stages stream. Each :meth:`push`
    takes one Kinect v1 frame and returns the gestures that became certain
    with it; :meth:`flush` ends the stream. Only frames already pushed are
    looked at, and the work per frame is bounded: the descriptor of one frame,
    one segmenter row, one window every ``stride`` frames of a period (Methods
    A/B), one tagger chunk every ``window`` frames (Method C).

    Parameters
    ----------
    pipeline : sklearn.pipeline.Pipeline
        A fitted pipeline, starting with a :class:`~skgesture.PoseDescriptor`
        and ending with a stage that gives gesture segments
        (``predict_segments``). The stages' parameters are read when the
        recogniser is built; build a new one after ``set_params``.
    max_period : int, default=1200
        Methods A/B: an activity period this long (in frames) is closed and
        decided, and activity that continues opens a new one. This bounds
        memory and delay on a stream that never rests; offline ``predict``
        has no such cap.
    max_backfill : int, default=64
        Untracked frames at the start of a stream that wait for the first
        tracked frame and become copies of it, as offline filling does;
        earlier ones are handed on at once as rest.
    early_decision : bool, default=False
        Methods A/B: decide runs of windows without waiting for a period to be
        known long (``short_length`` frames). Shorter delays in periods that
        hold several gestures, at the price of events that may differ from
        offline ``predict`` (docs/streaming.md, "Delay").
    target_names : sequence of str or None, default=None
        ``target_names[k - 1]`` names class ``k`` in the events (as the
        dataset loaders' ``target_names``).
    n_threads : int or None, default=1
        Torch intra-op threads while a frame is processed (the previous
        setting is restored after each call); ``None`` leaves torch as it is.
        One thread is fastest for the small networks and never oversubscribes
        a busy machine (docs/design.md §6).
    fps : float or None, default=None
        Frame rate of the pushed frames (a live source's ``fps``). When it
        differs from the rate the pipeline was trained at (its ``fps_``, see
        :class:`~skgesture.GesturePipeline`), the frames are resampled to
        that rate before the stages, by the rule of offline
        ``predict(X, fps=...)``, and the events' frames (``start``, ``end``,
        ``emitted_at``) are input frames. None: the frames are taken as they
        come, at the model's rate. ``max_period`` and ``max_backfill`` count
        frames at the model's rate.

    Attributes
    ----------
    delays : dict of str to int
        Look-ahead of every stage (``stream_lookahead``), in input frames;
        when resampling, the stages' look-aheads converted to the input's
        rate (rounded up) after ``"resample"`` (``ceil(ratio / 2) + 2``
        frames: a frame at the model's rate waits for the next one, and the
        rounding between the rates).
    lookahead : int
        Frames between a frame and the moment the last stage sees it: the sum
        of the look-aheads of the stages before the last (11 for Methods A/B
        with the paper's span 15: 4 descriptor frames, 7 smoothing frames).
    max_delay : int
        Frames between the last frame of a gesture and its event, at most,
        apart from the waits listed in the Notes: the sum of all look-aheads
        (21 for Methods A/B and C with the paper's numbers).
    classes_ : ndarray
        Gesture classes of the last stage (rest excluded).
    n_frames_seen : int
        Frames pushed in the current stream.
    ratio : float
        Input frames per frame at the model's rate (1.0 without
        resampling).

    See Also
    --------
    ActionMap : Turns events into robot commands.
    ReplaySource : Replays a recorded stream frame by frame.

    Notes
    -----
    **Timing.** The descriptor of frame ``t`` is final with frame ``t + 4``
    and the segmenter's smoothed score ``(span - 1) / 2`` frames later, so a
    short period ``[s, e)`` is decided with frame ``e + lookahead``: its event
    comes ``lookahead + 1`` frames (12) after the gesture's last frame. In a
    long period a run of windows is emitted once no later window can change
    it, at most ``max_delay`` frames after its last frame, but never before
    the period is known to be long (``short_length`` frames after its start;
    ``early_decision=True`` drops that wait). Method C: an event comes
    ``lookahead + h + 1`` to ``max_delay`` frames after the gesture's last
    frame. A period reaching ``max_period`` and :meth:`flush` decide at once.

    **Agreement with offline predict.** The events equal the rows of
    ``predict_segments`` on the whole recorded stream (same classes and
    frames, confidences up to float rounding of one-row versus batched network
    calls) when the offline descriptor fills untracked frames the same way
    (``descriptor__fill="hold"``), no period reaches ``max_period``, fewer
    than ``max_backfill`` untracked frames start the stream and
    ``early_decision`` is off (docs/streaming.md).

    **Safety.** Every frame is checked as offline prediction checks it (shape
    ``(20, 3)``, real numbers, finite or NaN, at most 1e5 in magnitude); a bad
    frame raises a ``ValueError`` naming its index in the stream and leaves
    the recogniser as it was, so the stream can go on. Untracked frames (all
    zeros or NaN) are rest: lost tracking never looks like a gesture.

    **Memory.** Every stage keeps only the rows it still needs (a few dozen,
    plus the window scores of an open period, at most ``max_period /
    stride``): a stream of any length uses the same memory
    (:meth:`buffer_lengths`).

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
    >>> rec.delays
    {'descriptor': 4, 'segmenter': 7, 'windows': 0, 'classifier': 10}
    >>> rec.lookahead, rec.max_delay
    (11, 21)
    >>> events = []
    >>> for frame in data.X[3]:
    ...     events += rec.push(frame)
    >>> events += rec.flush()
    >>> all(0 <= ev.start < ev.end <= ev.emitted_at + 1 for ev in events)
    True
    """

    def __init__(
        self,
        pipeline,
        *,
        max_period=DEFAULT_MAX_PERIOD,
        max_backfill=DEFAULT_MAX_BACKFILL,
        early_decision=False,
        target_names=None,
        n_threads=1,
        fps=None,
    ):
        self.pipeline = pipeline
        self.max_period = max_period
        self.max_backfill = max_backfill
        self.early_decision = early_decision
        self.target_names = target_names
        self.n_threads = n_threads
        self.fps = fps
        self._inspect()
        self.reset()

    # -- public API ------------------------------------------------------------

    def push(self, frame):
        """Feed one frame; return the gestures that became certain with it.

        Parameters
        ----------
        frame : array-like of shape (20, 3)
            Joint positions in metres, Kinect v1 order (see the adapters of
            :mod:`skgesture.streaming` for other layouts). An untracked frame
            is all zeros or holds a NaN.

        Returns
        -------
        list of GestureEvent
            Possibly empty, in the order the gestures were decided.

        Raises
        ------
        TypeError, ValueError
            For a frame offline prediction would refuse (wrong shape, not a
            number, infinite, beyond 1e5 in magnitude); the message names the
            frame's index in the stream. The recogniser is left unchanged.
        """
        frames = self._as_frames(frame, single=True)
        return self._ingest(frames)

    def push_many(self, frames):
        """Feed several frames at once; same events as pushing them one by one.

        The stages handle the frames in blocks (faster for replaying
        recordings); every event keeps the ``emitted_at`` frame it would have
        with :meth:`push`. Only float rounding of batched network calls can
        differ.

        Parameters
        ----------
        frames : array-like of shape (n_frames, 20, 3)
            Consecutive frames.

        Returns
        -------
        list of GestureEvent
            Events decided while these frames arrived.
        """
        frames = self._as_frames(frames, single=False)
        events = []
        for lo in range(0, len(frames), MAX_BATCH):
            events += self._ingest(frames[lo : lo + MAX_BATCH])
        return events

    def flush(self):
        """End the stream: decide everything still open, then reset.

        The last frames are completed with the offline end rules (replicate
        padding of the descriptor, end-point loess fits, the final chunk of a
        tagger), exactly as ``predict`` treats the end of a sequence. The
        recogniser is then ready for a new stream.

        Returns
        -------
        list of GestureEvent
            The remaining events; ``emitted_at`` is the last frame pushed.
        """
        segments = []
        if self.n_frames_seen:
            with self._threads():
                rows = None
                if self._resampler is not None:  # its last model-rate frame
                    last = self._resampler.flush()
                    if last is not None:
                        rows = stream_frames(last.data, self._n_model)
                        self._n_model += len(last)
                for k, (_, stage) in enumerate(self._stages):
                    state = self._states[k]
                    out = None
                    if rows is not None and len(rows):
                        out, state = stage.stream_step(state, rows)
                    tail, state = stage.stream_flush(state)
                    self._states[k] = state
                    if k == len(self._stages) - 1:
                        segments = list(out or []) + list(tail or [])
                    else:
                        rows = _concat_rows([out, tail], (0,))
        events = self._events(segments, flush=True)
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
        self._n_model = 0  # frames handed to the stages (model rate)
        self._resampler = None
        if self._rates is not None:
            self._resampler = FrameResampler(self.fps, self._model_fps)
        self._states = [
            stage.stream_init(**options)
            for (_, stage), options in zip(self._stages, self._options)
        ]

    def buffer_lengths(self):
        """Count the rows held by each stage's buffers.

        Returns
        -------
        dict of str to int
            ``"step.buffer"``: rows held. Each stays below a bound fixed by the
            pipeline's parameters and ``max_period``, whatever the stream
            length.
        """
        out = {}
        if self._resampler is not None:
            for key, n in self._resampler.held().items():
                out[f"resample.{key}"] = int(n)
        for (name, _), state in zip(self._stages, self._states):
            held = getattr(state, "held", None)
            for key, n in (held() if held else {}).items():
                out[f"{name}.{key}"] = int(n)
        return out

    # -- set-up ----------------------------------------------------------------

    def _route_options(self, stages):
        """The options of each stage's ``stream_init``: each recogniser option
        goes to the stages that declare it (``_stream_options``); one set away
        from its default that no stage declares is an error."""
        options = {
            "max_period": (self.max_period, DEFAULT_MAX_PERIOD),
            "max_backfill": (self.max_backfill, DEFAULT_MAX_BACKFILL),
            "early_decision": (bool(self.early_decision), False),
        }
        declared = [tuple(getattr(stage, "_stream_options", ())) for _, stage in stages]
        for key, (value, default) in options.items():
            if value != default and not any(key in d for d in declared):
                names = ", ".join(type(stage).__name__ for _, stage in stages)
                raise ValueError(
                    f"{key}={value!r} is an option of no stage of this pipeline "
                    f"({names}); leave it at its default {default!r}"
                )
        return [
            {key: value for key, (value, _) in options.items() if key in d}
            for d in declared
        ]

    def _inspect(self):
        """Check the pipeline and the options; read the stages' look-aheads."""
        from sklearn.utils.validation import check_is_fitted

        steps = getattr(self.pipeline, "steps", None)
        if not isinstance(steps, list) or not steps:
            raise TypeError(
                "pipeline must be a fitted sklearn Pipeline (e.g. make_method_a/b/c)"
                f", got {type(self.pipeline).__name__}"
            )
        stages = [(n, est) for n, est in steps if est not in (None, "passthrough")]
        for name, est in stages:
            missing = missing_stream_methods(est)
            if missing:
                raise TypeError(
                    f"step {name!r} ({type(est).__name__}) cannot run on a stream: "
                    f"it has no {', '.join(missing)} (the incremental protocol of "
                    f"docs/design.md, 'Incremental steps')"
                )
            check_is_fitted(est)
        last_name, last = stages[-1]
        if not hasattr(last, "predict_segments"):
            raise TypeError(
                f"the last step {last_name!r} ({type(last).__name__}) gives no gesture "
                f"segments (predict_segments): a streamed pipeline must end with a "
                f"classifier or tagger such as MultiScaleClassifier or BiLSTMTagger"
            )
        if self.n_threads is not None and (
            isinstance(self.n_threads, bool)
            or not isinstance(self.n_threads, Integral)
            or self.n_threads < 1
        ):
            raise ValueError(
                f"n_threads must be a positive int or None, got {self.n_threads!r}"
            )
        if (
            isinstance(self.max_backfill, bool)
            or not isinstance(self.max_backfill, Integral)
            or self.max_backfill < 0
        ):
            raise ValueError(
                f"max_backfill must be a non-negative int, got {self.max_backfill!r}"
            )
        self._stages = stages
        self._options = self._route_options(stages)
        # Building the states checks the options against every stage.
        for (_, stage), options in zip(stages, self._options):
            stage.stream_init(**options)
        self._check_rate()
        delays = {name: int(est.stream_lookahead) for name, est in stages}
        if self._rates is not None:  # in input frames
            delays = {
                "resample": math.ceil(self.ratio / 2) + RESAMPLE_DELAY,
                **{k: math.ceil(d * self.ratio) for k, d in delays.items()},
            }
        self.delays = delays
        self.lookahead = sum(list(self.delays.values())[:-1])
        self.max_delay = sum(self.delays.values())
        classes = np.asarray(last.classes_)
        self.classes_ = classes[classes != 0]
        self._frame_shape = tuple(getattr(stages[0][1], "frame_shape_in_", ()))
        if self.target_names is not None:
            if isinstance(self.target_names, str) or len(self.target_names) < max(
                self.classes_
            ):
                raise ValueError(
                    f"target_names must name every class 1..{max(self.classes_)} "
                    f"(target_names[k - 1] names class k), got {self.target_names!r}"
                )

    def _check_rate(self):
        """The input rate against the pipeline's: set ``_rates`` and ``ratio``."""
        self._rates, self._model_fps, self.ratio = None, None, 1.0
        if self.fps is None:
            return
        fps = check_fps(self.fps)
        model_fps = getattr(self.pipeline, "fps_", None)
        if model_fps is None:
            raise ValueError(
                f"fps={fps:g} is given, but the pipeline does not know the rate it "
                f"was trained at (no fps_): fit a GesturePipeline (make_method_a/b/"
                f"c, make_recommended) with fit(X, y, fps=...), or leave fps=None"
            )
        model_fps = check_fps(model_fps, "the pipeline's fps_")
        if same_rate(fps, model_fps):
            return
        self._model_fps = model_fps
        self._rates = FrameResampler(fps, model_fps).rates
        self.ratio = self._rates.ratio

    def _threads(self):
        import contextlib
        import sys

        if "torch" not in sys.modules:  # no torch network runs (Methods A, B)
            return contextlib.nullcontext()
        from skgesture._nn._training import torch_threads

        return torch_threads(self.n_threads)

    def _as_frames(self, frames, single):
        """Frames as an ndarray of ``(n, *frame_shape)``; shape and type checked."""
        first = self.n_frames_seen
        what = f"frame {first} of the stream" if single else "frames"
        if isinstance(frames, (str, bytes)) or (
            not isinstance(frames, np.ndarray) and not hasattr(frames, "__len__")
        ):
            raise TypeError(
                f"{what} must be an array of joint positions of shape "
                f"{self._frame_shape}, got {type(frames).__name__}"
            )
        if isinstance(frames, np.ma.MaskedArray):
            arr = frames  # masked values mark untracked joints (PoseDescriptor)
        else:
            arr = np.asarray(frames)
        shape = self._frame_shape
        expect = shape if single else (None, *shape)
        ok = arr.ndim == len(expect) and all(
            e is None or e == a for e, a in zip(expect, arr.shape)
        )
        if not ok:
            layout = (
                f"{shape}" if single else f"(n_frames, {', '.join(map(str, shape))})"
            )
            hint = ""
            if single and arr.size == int(np.prod(shape)):
                hint = (
                    "; a frame of the right size but another shape (transposed, or "
                    "flat) is refused rather than guessed: reshape it yourself"
                )
            raise ValueError(
                f"{what} has shape {arr.shape}; expected {layout} (Kinect v1 joints "
                f"x xyz, metres{hint}); map other layouts with an adapter from "
                f"skgesture.streaming"
            )
        return arr[None] if single else arr

    # -- ingestion -------------------------------------------------------------

    def _ingest(self, frames):
        """Run new frames through every stage; return the events they decide."""
        if self._resampler is not None:
            # Checked before the resampler changes (a refused frame changes
            # nothing), then the frames at the model's rate that are complete.
            checked = self._resampler.check(frames)
            frames_in = len(frames)
            frames = self._resampler.push(checked, checked=True).data
            if not len(frames):
                self.n_frames_seen += frames_in
                return []
        else:
            frames_in = len(frames)
        rows = stream_frames(frames, self._n_model)
        segments = []
        with self._threads():
            states = list(self._states)
            for k, (_, stage) in enumerate(self._stages):
                out, states[k] = stage.stream_step(states[k], rows)
                if k == len(self._stages) - 1:
                    segments = out
                elif out is None or not len(out):
                    break
                else:
                    rows = out
        # The first stage validates the frames before changing anything.
        self._states = states
        self.n_frames_seen += frames_in
        self._n_model += len(frames)
        return self._events(segments)

    def _input_frames(self, seg, flush):
        """``(start, end, emitted_at)`` of a segment, in input frames.

        The rule of offline ``predict_segments(X, fps=...)``
        (:func:`skgesture._rate.segments_back`): the input frames whose nearest
        model-rate frame is in the segment; an event is emitted at the input
        frame that completed the model-rate frame deciding it (at a flush, the
        last frame pushed).
        """
        if self._rates is None:
            return int(seg.start), int(seg.end), int(seg.time)
        rates, n_in = self._rates, self.n_frames_seen
        start = int(rates.first_input(int(seg.start))[0])
        if flush and seg.end >= self._n_model:
            end = n_in
        else:
            end = int(rates.first_input(int(seg.end))[0])
        if flush:
            emitted = n_in - 1
        else:
            emitted = int(rates.ready_at(int(seg.time)))
        return min(start, n_in), end, emitted

    def _events(self, segments, flush=False):
        events = []
        for seg in segments:
            start, end, emitted = self._input_frames(seg, flush)
            if start >= end:
                continue  # no input frame takes its label (offline drops it too)
            name = None
            if self.target_names is not None:
                name = self.target_names[int(seg.label) - 1]
            events.append(
                GestureEvent(
                    label=int(seg.label),
                    start=start,
                    end=end,
                    confidence=float(seg.confidence),
                    emitted_at=emitted,
                    name=name,
                )
            )
        return events
