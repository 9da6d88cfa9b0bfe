"""Frame rates: resampling a skeleton stream to a model's rate, and back.

Every model counts time in frames (the paper's Gaussian of 5 frames, windows
of 9, periods of at least 12, steps of 2 to 4), so a model trained at one rate
(PRECOG at 30 fps, ChaLearn at 20) sees another gesture in a recording made at
another rate. A model therefore knows the rate it was trained at
(:class:`~skgesture.GesturePipeline`'s ``fps_``) and resamples its input to it;
this module holds the one rule, offline and live (docs/streaming.md, "Frame
rates").

**The rule.** Input frame ``i`` is at time ``i / from_fps``, model-rate frame
``j`` at ``j / to_fps``, that is at input position ``p = j * from_fps /
to_fps``. A model-rate frame is the linear interpolation of the input frames
``floor(p)`` and ``floor(p) + 1`` (a copy of frame ``p`` when ``p`` is a whole
number, so taking every 2nd or 3rd frame of a tracked recording copies them bit
for bit). Model-rate frames stop at the last input frame (nothing is
extrapolated), so a recording of ``n`` frames gives
``floor((n - 1) * to_fps / from_fps) + 1`` of them.

**Back.** Every input frame takes the value (label, probabilities) of the
model-rate frame nearest in time, ties going to the earlier one, so the output
has exactly one label per input frame; a segment ``[start, end)`` of model-rate
frames becomes the input frames that take their label from it.

**Untracked frames stay untracked** (all zeros, or a NaN; docs/design.md §1.1).
A model-rate frame is untracked (all zeros) when one of its neighbouring input
frames is: one it is interpolated from (nothing is interpolated across a gap),
or one that takes its label from it (so a lost frame of a 60 fps stream is not
dropped by taking every 2nd frame). Every untracked input frame therefore gets
the label of an untracked model-rate frame: rest, as the data contract wants.

**Live.** :class:`FrameResampler` is the incremental step of the rule: it
takes input frames as they come and hands on each model-rate frame once the
next one is complete (then no later input frame can take its label), with the
input frame that completed it; the end of the stream hands on the last one.
:func:`resample` is that step over a whole sequence, so offline and live are
one implementation. :class:`RateMap` holds the index arithmetic between the
two rates, shared by both directions.

**Timestamps.** :class:`FrameClock` is the rule of every live source: a frame
``k`` nominal periods after the previous one is preceded by ``k - 1``
untracked frames (gaps are lost frames, not squeezed time), and
:func:`frames_from_timestamps` applies it to a recording with timestamps.

At equal rates nothing is resampled: :func:`resample` returns its input
itself, and a model predicts exactly as without a rate.
"""

# SPDX-License-Identifier: BSD-3-Clause

import math
import warnings
from numbers import Real

import numpy as np

from skgesture._stream import Rows
from skgesture.utils._validation import (
    MAX_COORDINATE,
    _as_real_array,
    _check_values,
    missing_frames,
)

__all__ = [
    "DEFAULT_FPS",
    "MAX_GAP_SECONDS",
    "FrameClock",
    "FrameResampler",
    "RateMap",
    "check_fps",
    "estimate_fps",
    "frames_back",
    "frames_from_timestamps",
    "resample",
    "same_rate",
    "segments_back",
]

DEFAULT_FPS = 30.0  # the Kinect rate: a model fitted without a rate assumes it
MAX_GAP_SECONDS = 10.0  # longest gap in timestamps filled with untracked frames
# Positions closer than this to a whole frame are that frame: 29.97 / 30 * j
# computed in floating point must not turn a copy into an interpolation.
SNAP = 1e-6


def check_fps(fps, name="fps"):
    """A frame rate as a float, or a ValueError naming ``name``.

    Parameters
    ----------
    fps : float
        Frames per second: a positive finite real number (not a bool).
    name : str, default="fps"
        Name used in the error message.

    Returns
    -------
    float
        ``fps``.

    Raises
    ------
    ValueError
        When ``fps`` is not a positive finite number.

    Examples
    --------
    >>> from skgesture._rate import check_fps
    >>> check_fps(15)
    15.0
    >>> check_fps(0)
    Traceback (most recent call last):
    ...
    ValueError: fps must be a positive finite number of frames per second, got 0
    """
    if (
        isinstance(fps, (bool, np.bool_))
        or not isinstance(fps, Real)
        or not 0 < float(fps) < math.inf
    ):
        raise ValueError(
            f"{name} must be a positive finite number of frames per second, got {fps!r}"
        )
    return float(fps)


def same_rate(a, b):
    """Whether two frame rates are the same (up to floating-point rounding).

    Parameters
    ----------
    a, b : float
        Frame rates.

    Returns
    -------
    bool
        True when nothing needs resampling between them.

    Examples
    --------
    >>> from skgesture._rate import same_rate
    >>> same_rate(30, 30.0), same_rate(30, 1 / (1 / 30)), same_rate(29.97, 30)
    (True, True, False)
    """
    return math.isclose(float(a), float(b), rel_tol=1e-9)


def _snap(x):
    """``x`` with the values within ``SNAP`` of a whole number made whole."""
    x = np.asarray(x, dtype=np.float64)
    r = np.rint(x)
    return np.where(np.abs(x - r) < SNAP, r, x)


class RateMap:
    """Frame indices between an input rate and a model rate.

    Input frame ``i`` is at time ``i / from_fps``, model-rate frame ``j`` at
    ``j / to_fps`` (module docstring). Every method takes arrays of indices.

    Parameters
    ----------
    from_fps : float
        Rate of the input frames.
    to_fps : float
        Rate of the model-rate frames.

    Attributes
    ----------
    ratio : float
        Input frames per model-rate frame, ``from_fps / to_fps``.

    Examples
    --------
    >>> from skgesture._rate import RateMap
    >>> rates = RateMap(15, 30)  # a 15 fps input, a 30 fps model
    >>> rates.n_out(4), rates.positions([0, 1, 2]).tolist()
    (7, [0.0, 0.5, 1.0])
    >>> rates.nearest([0, 1, 2, 3], 7).tolist()
    [0, 2, 4, 6]
    >>> rates.first_input([0, 1, 2, 7]).tolist()
    [0, 1, 1, 4]
    """

    def __init__(self, from_fps, to_fps):
        self.from_fps = check_fps(from_fps, "from_fps")
        self.to_fps = check_fps(to_fps, "to_fps")
        self.ratio = self.from_fps / self.to_fps

    def positions(self, j):
        """Input positions (fractional frames) of model-rate frames ``j``."""
        return _snap(np.asarray(j, dtype=np.float64) * self.from_fps / self.to_fps)

    def ready_at(self, j):
        """The input frame at whose arrival a stream hands on model-rate frame ``j``.

        That which completes frame ``j + 1`` (:class:`FrameResampler`): every
        input frame nearest to ``j`` has come by then.
        """
        j = np.asarray(j, dtype=np.int64)
        return np.ceil(self.positions(j + 1)).astype(np.int64)

    def n_out(self, n_in):
        """Model-rate frames of ``n_in`` input frames (none after the last one)."""
        if n_in <= 0:
            return 0
        last = n_in - 1
        j = int(math.floor(last * self.to_fps / self.from_fps + SNAP))
        while self.positions(j + 1) <= last:
            j += 1
        while j >= 0 and self.positions(j) > last:
            j -= 1
        return j + 1

    def _nearest(self, i):
        q = np.asarray(i, dtype=np.float64) * self.to_fps / self.from_fps
        # round half down: a tie goes to the earlier model-rate frame
        return np.ceil(_snap(q - 0.5)).astype(np.int64)

    def nearest(self, i, n_out):
        """The model-rate frame nearest in time to each input frame ``i``.

        Ties go to the earlier frame; the result is clipped to the
        ``n_out`` model-rate frames that exist.
        """
        return np.clip(self._nearest(i), 0, max(n_out - 1, 0))

    def first_input(self, j):
        """The first input frame nearest to model-rate frame ``j`` or a later one."""
        j = np.atleast_1d(np.asarray(j, dtype=np.int64))
        base = np.floor((j - 0.5) * self.ratio).astype(np.int64) - 1
        cand = base[:, None] + np.arange(4)
        ok = self._nearest(cand) >= j[:, None]
        return np.maximum(cand[np.arange(len(j)), np.argmax(ok, axis=1)], 0)


def _interpolate(buf, untracked, lo, w):
    """The model-rate frames at positions ``lo + w`` of the frames ``buf``.

    ``lo`` indexes ``buf``, ``w`` in ``[0, 1)``; ``untracked`` flags the frames
    of ``buf``. A frame at ``w == 0`` is a copy; one interpolated from an
    untracked frame is untracked. Returns the frames and their untracked flags.
    """
    out = buf[lo].astype(np.float64, copy=True)
    mix = w > 0
    if mix.any():
        k = np.flatnonzero(mix)
        a, b = buf[lo[k]], buf[lo[k] + 1]
        wk = w[k].reshape((-1,) + (1,) * (buf.ndim - 1))
        gap = untracked[lo[k]] | untracked[lo[k] + 1]
        with np.errstate(invalid="ignore"):
            mixed = (1.0 - wk) * a + wk * b
        mixed[gap] = 0.0
        out[k] = mixed
        mask = untracked[lo].copy()
        mask[k] = gap
    else:
        mask = untracked[lo].copy()
    return out, mask


class FrameResampler:
    """The incremental step of the resampling rule: input frames in, model-rate
    frames out.

    ``push(frames)`` takes the next input frames of a stream and returns the
    model-rate frames handed on with them: a model-rate frame goes once the
    next one is complete, when no later input frame can be nearest to it (and
    make it untracked); :meth:`flush` hands on the last one.
    :func:`resample` is this step over a whole sequence. Only the last input
    frame and the last model-rate frame are kept.

    Parameters
    ----------
    from_fps : float
        Rate of the input frames.
    to_fps : float
        Rate of the model (of the frames handed on).
    max_abs : float, default=1e5
        Largest coordinate accepted (``MAX_COORDINATE``, the raw skeletons'
        bound of docs/design.md §1.2).

    Attributes
    ----------
    rates : RateMap
        The index arithmetic.
    n_in : int
        Input frames pushed.
    n_out : int
        Model-rate frames handed on.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._rate import FrameResampler
    >>> step = FrameResampler(from_fps=15, to_fps=30)
    >>> x = np.arange(1.0, 5.0).reshape(4, 1, 1)  # frames 1, 2, 3, 4
    >>> out = step.push(x[:2])
    >>> out.data[:, 0, 0].tolist(), out.time.tolist()
    ([1.0, 1.5], [1, 1])
    >>> out = step.push(x[2:])
    >>> out.data[:, 0, 0].tolist(), out.time.tolist()
    ([2.0, 2.5, 3.0, 3.5], [2, 2, 3, 3])
    >>> out = step.flush()
    >>> out.data[:, 0, 0].tolist(), out.time.tolist(), step.n_out
    ([4.0], [3], 7)
    """

    def __init__(self, from_fps, to_fps, *, max_abs=MAX_COORDINATE):
        self.rates = RateMap(from_fps, to_fps)
        self.max_abs = max_abs
        self.n_in = 0
        self.n_out = 0
        self._n_made = 0  # model-rate frames made (handed on, and the held one)
        self._last = None  # the last input frame, and whether it was untracked
        self._last_untracked = None
        self._held = None  # the last model-rate frame made, and its flag

    @property
    def lookahead(self):
        """Input frames after a model-rate frame's time before it is handed on."""
        return math.ceil(self.rates.ratio) + 1

    def check(self, frames, name=None):
        """The frames as a float array, checked (real, finite or NaN, bounded).

        A ``numpy.ma.MaskedArray``'s masked values become NaN (untracked).

        Parameters
        ----------
        frames : array-like of shape (n, ...)
            The next input frames.
        name : str or None, default=None
            The name of a whole sequence in error messages (``"X[3]"``); None
            names a bad frame by its index in the stream.

        Returns
        -------
        ndarray of shape (n, ...)
            float64.

        Raises
        ------
        ValueError
            For frames that are not real numbers, finite or NaN, at most
            ``max_abs`` in magnitude, or not an array of frames.
        """
        if isinstance(frames, np.ma.MaskedArray):
            frames = np.ma.filled(np.ma.asarray(frames, dtype=float), np.nan)
        where = name or f"frames {self.n_in}.. of the stream"
        arr = _as_real_array(frames, where)
        if arr.ndim < 2:
            raise ValueError(
                f"{where} has shape {arr.shape}; expected (n_frames, n_joints, 3) "
                f"frames"
            )
        _check_values(arr, where, True, self.max_abs, None if name else self.n_in)
        return np.ascontiguousarray(arr, dtype=np.float64)

    def push(self, frames, *, checked=False):
        """Take the next input frames; return the model-rate frames handed on.

        Parameters
        ----------
        frames : array-like of shape (n, ...)
            The next input frames (``n >= 0``); untracked ones are all zeros or
            hold a NaN.
        checked : bool, default=False
            Whether ``frames`` went through :meth:`check` already.

        Returns
        -------
        Rows
            ``data``: the model-rate frames (float64, all zeros where
            untracked), ``mask``: which are untracked, ``time``: the input
            frame at which each was handed on. Empty when none is.
        """
        x = frames if checked else self.check(frames)
        n = len(x)
        if n == 0:
            return Rows(x.astype(np.float64), np.zeros(0, bool), np.zeros(0, np.int64))
        first = self.n_in
        untracked = missing_frames(x)
        if self._last is not None:
            buf = np.concatenate([self._last[None], x])
            flags = np.concatenate([[self._last_untracked], untracked])
            offset = first - 1
        else:
            buf, flags, offset = x, untracked, first
        self.n_in += n
        stop = self.rates.n_out(self.n_in)  # model-rate frames complete now
        j = np.arange(self._n_made, stop)
        p = self.rates.positions(j)
        lo = np.floor(p).astype(np.int64)
        data, mask = _interpolate(buf, flags, lo - offset, p - lo)
        j0 = self._n_made
        if self._held is not None:
            data = np.concatenate([self._held[0][None], data])
            mask = np.concatenate([[self._held[1]], mask])
            j0 -= 1
        # an untracked input frame makes its nearest model-rate frame untracked
        # (that frame is the held one or a new one: never one handed on)
        lost = first + np.flatnonzero(untracked)
        if len(lost):
            mask[self.rates.nearest(lost, stop) - j0] = True
        data[mask] = 0.0
        self._n_made = stop
        self._last, self._last_untracked = x[-1].copy(), bool(untracked[-1])
        self._held = (data[-1], bool(mask[-1]))
        self.n_out = stop - 1
        out = np.arange(j0, stop - 1)
        return Rows(data[:-1], mask[:-1], self.rates.ready_at(out))

    def flush(self):
        """The end of the stream: the last model-rate frame (none is extrapolated).

        Returns
        -------
        Rows or None
            The last model-rate frame, handed on at the last input frame;
            None when nothing was pushed. The state is then spent.
        """
        if self._held is None:
            return None
        data, mask = self._held
        self._held = None
        self.n_out = self._n_made
        return Rows(data[None], np.array([mask]), np.array([self.n_in - 1]))

    def held(self):
        """Frames held, by buffer.

        Returns
        -------
        dict of str to int
            ``{"last_frame": 0 or 1, "model_frame": 0 or 1}``: the last input
            frame and the last model-rate frame.
        """
        return {
            "last_frame": int(self._last is not None),
            "model_frame": int(self._held is not None),
        }


def resample(X, from_fps, to_fps):
    """One skeleton sequence at another frame rate (the module's rule).

    Linear interpolation of the coordinates at the times of the new frames; a
    new frame next to an untracked input frame (one it is interpolated from, or
    one nearest to it) is untracked, all zeros, so no gap is interpolated
    across and none disappears. At equal rates ``X`` itself is returned.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_joints, 3)
        One sequence (any frame shape works); an untracked frame is all zeros
        or holds a NaN, and a masked value of a ``numpy.ma.MaskedArray`` is NaN.
    from_fps : float
        Its frame rate.
    to_fps : float
        The rate wanted (a model's ``fps_``).

    Returns
    -------
    ndarray of shape (n_out, n_joints, 3)
        float64, ``n_out = floor((n_frames - 1) * to_fps / from_fps) + 1``
        frames (none after the last input frame); ``X`` unchanged (the same
        object) when the rates are the same.

    Raises
    ------
    ValueError
        For a bad rate, or a frame that is not finite numbers or NaN (the
        message names the frame).

    See Also
    --------
    FrameResampler : The same rule, one block of frames at a time.
    frames_back : Model-rate labels back to the input's frames.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._rate import resample
    >>> x = np.arange(1.0, 7.0).reshape(6, 1, 1); x[3] = 0  # frame 3 untracked
    >>> resample(x, 30, 60)[:, 0, 0].tolist()  # no interpolation across frame 3
    [1.0, 1.5, 2.0, 2.5, 3.0, 0.0, 0.0, 0.0, 5.0, 5.5, 6.0]
    >>> resample(x, 30, 15)[:, 0, 0].tolist()  # every 2nd frame; 3 is kept lost
    [1.0, 0.0, 5.0]
    >>> resample(x[:3], 30, 15)[:, 0, 0].tolist()  # a tracked one: copies
    [1.0, 3.0]
    >>> resample(x, 30, 30) is x
    True
    """
    from_fps, to_fps = check_fps(from_fps, "from_fps"), check_fps(to_fps, "to_fps")
    step = FrameResampler(from_fps, to_fps)
    checked = step.check(X, name="X")
    if same_rate(from_fps, to_fps):
        return X
    parts = [step.push(checked, checked=True), step.flush()]
    return np.concatenate([r.data for r in parts if r is not None])


def frames_back(values, from_fps, to_fps, n_frames):
    """Per-frame values at the model's rate back at the input's frames.

    The inverse map of :func:`resample`: input frame ``i`` takes the row of
    the model-rate frame nearest in time (ties: the earlier one), so labels
    come back with exactly one label per input frame.

    Parameters
    ----------
    values : ndarray of shape (n_out, ...)
        One row per model-rate frame (labels, probabilities) of a sequence
        resampled from ``from_fps`` to ``to_fps``.
    from_fps : float
        The input's rate.
    to_fps : float
        The model's rate.
    n_frames : int
        Input frames of the sequence.

    Returns
    -------
    ndarray of shape (n_frames, ...)
        One row per input frame; ``values`` itself at equal rates.

    Raises
    ------
    ValueError
        When ``values`` has another number of rows than :func:`resample`
        gives for ``n_frames`` input frames.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._rate import frames_back
    >>> frames_back(np.array([5, 6, 7]), 15, 30, 2).tolist()
    [5, 7]
    >>> frames_back(np.array([0, 1, 2]), 60, 30, 6).tolist()
    [0, 0, 1, 1, 2, 2]
    """
    if same_rate(from_fps, to_fps):
        return values
    rates = RateMap(from_fps, to_fps)
    n_out = rates.n_out(int(n_frames))
    if len(values) != n_out:
        raise ValueError(
            f"{len(values)} model-rate rows for {n_frames} input frames; resampling "
            f"{n_frames} frames from {rates.from_fps:g} to {rates.to_fps:g} fps "
            f"gives {n_out}"
        )
    if n_frames == 0:
        return values[:0]
    return values[rates.nearest(np.arange(int(n_frames)), n_out)]


def segments_back(segments, from_fps, to_fps, n_frames, *, n_out=None):
    """Segments in model-rate frames back in the input's frames.

    A segment ``[start, end)`` of model-rate frames becomes the input frames
    that take their label from it under :func:`frames_back`; one that no
    input frame takes is dropped.

    Parameters
    ----------
    segments : ndarray of shape (n_segments, >= 3)
        Rows ``(class, start, end, ...)`` in model-rate frames, ``end``
        exclusive (``predict_segments`` rows, with their confidence).
    from_fps : float
        The input's rate.
    to_fps : float
        The model's rate.
    n_frames : int
        Input frames of the sequence.
    n_out : int or None, default=None
        Model-rate frames of the sequence (None: those of ``n_frames``); a
        segment ending there ends at the last input frame.

    Returns
    -------
    ndarray of shape (n_kept, >= 3)
        Same columns and dtype; ``segments`` itself at equal rates.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._rate import segments_back
    >>> segments_back(np.array([[3, 2, 6]]), 15, 30, 4).tolist()  # frames 1-2
    [[3, 1, 3]]
    >>> segments_back(np.array([[1, 5, 10, 0.9]]), 60, 30, 20).tolist()
    [[1.0, 10.0, 20.0, 0.9]]
    """
    if same_rate(from_fps, to_fps):
        return segments
    segments = np.asarray(segments)
    rates = RateMap(from_fps, to_fps)
    n_out = rates.n_out(int(n_frames)) if n_out is None else int(n_out)
    if len(segments) == 0:
        return segments.copy()
    start = rates.first_input(segments[:, 1].astype(np.int64))
    end_model = segments[:, 2].astype(np.int64)
    end = np.where(end_model >= n_out, n_frames, rates.first_input(end_model))
    start, end = np.minimum(start, n_frames), np.minimum(end, n_frames)
    out = segments.copy()
    out[:, 1], out[:, 2] = start, end
    return out[start < end]


# -- timestamps --------------------------------------------------------------------


class FrameClock:
    """The dropped-frame rule of timestamped frames (module docstring).

    A frame that comes ``k`` nominal periods (``round((t - t_previous) *
    fps)``) after the previous one is preceded by ``k - 1`` untracked frames,
    at most ``max_gap`` seconds worth; a frame whose timestamp is not after
    the previous one is to be dropped. Every live source of
    :mod:`skgesture.streaming` and :func:`frames_from_timestamps` use it.

    Parameters
    ----------
    fps : float
        Nominal frame rate.
    max_gap : float, default=MAX_GAP_SECONDS
        Longest gap, in seconds, that is filled with untracked frames.

    Attributes
    ----------
    last : float or None
        The timestamp of the last frame kept.

    Examples
    --------
    >>> from skgesture._rate import FrameClock
    >>> clock = FrameClock(fps=10.0)
    >>> clock.gap(0.0), clock.gap(0.1), clock.gap(0.4), clock.gap(0.4)
    ((0, 0), (0, 0), (2, 0), None)
    """

    def __init__(self, fps, max_gap=MAX_GAP_SECONDS):
        self.fps = fps
        self.max_fill = int(round(max_gap * fps))
        self.last = None

    def gap(self, t):
        """Untracked frames due before a frame stamped ``t`` (seconds).

        Parameters
        ----------
        t : float
            The frame's timestamp.

        Returns
        -------
        tuple of (int, int) or None
            ``(n_fill, n_cut)``: the untracked frames to put before the
            frame, and the ones beyond the cap that are left out; None when
            the frame must be dropped (``t`` is not after the previous
            timestamp).
        """
        if self.last is not None and not t > self.last:
            return None
        n = 0 if self.last is None else max(round((t - self.last) * self.fps) - 1, 0)
        self.last = t
        return min(n, self.max_fill), max(n - self.max_fill, 0)


def frames_from_timestamps(frames, timestamps, fps, *, max_gap=MAX_GAP_SECONDS):
    """Timestamped frames as frames at a nominal rate, gaps as untracked frames.

    The rule of :class:`FrameClock` (that of the live sources) on a whole
    recording: a gap of ``k`` nominal periods between two frames becomes
    ``k - 1`` untracked (all-zero) frames, not squeezed time; a frame stamped
    at or before the previous one is dropped, and a gap beyond ``max_gap``
    seconds is cut there, each with a warning.

    Parameters
    ----------
    frames : array-like of shape (n_frames, n_joints, 3)
        The frames, in the order they were recorded.
    timestamps : array-like of shape (n_frames,)
        Their timestamps in seconds, on any clock (only differences matter).
    fps : float
        The nominal rate of the output frames (the sensor's rate).
    max_gap : float, default=MAX_GAP_SECONDS
        Longest gap, in seconds, filled with untracked frames.

    Returns
    -------
    frames : ndarray of shape (n_out, n_joints, 3)
        The frames at ``fps``, untracked frames where frames were lost.
    source : ndarray of int64 of shape (n_out,)
        For each output frame the index of its input frame, -1 for a filled
        one.

    Raises
    ------
    ValueError
        For a bad rate, timestamps that are not finite, or not one per frame.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._rate import frames_from_timestamps
    >>> x = np.ones((3, 20, 3))
    >>> out, source = frames_from_timestamps(x, [0.0, 0.05, 0.2], fps=20)
    >>> len(out), source.tolist(), bool(out[2].any())
    (5, [0, 1, -1, -1, 2], False)
    """
    fps = check_fps(fps)
    x = np.asarray(frames)
    t = np.asarray(timestamps, dtype=np.float64)
    if t.ndim != 1 or len(t) != len(x):
        raise ValueError(
            f"timestamps must hold one time per frame: got shape {t.shape} for "
            f"{len(x)} frames"
        )
    if not np.isfinite(t).all():
        i = int(np.flatnonzero(~np.isfinite(t))[0])
        raise ValueError(
            f"timestamp {i} is {float(t[i])!r}, not a finite number of seconds"
        )
    clock = FrameClock(fps, max_gap=max_gap)
    source, n_dropped, n_cut = [], 0, 0
    for i, ti in enumerate(t.tolist()):
        gap = clock.gap(ti)
        if gap is None:
            n_dropped += 1
            continue
        n_fill, cut = gap
        n_cut += cut
        source += [-1] * n_fill + [i]
    if n_dropped:
        warnings.warn(
            f"dropped {n_dropped} frame(s) stamped at or before the previous one "
            f"(out of order or duplicates)",
            UserWarning,
            stacklevel=2,
        )
    if n_cut:
        warnings.warn(
            f"{n_cut} lost frame(s) left out: gaps longer than {max_gap:g} s are "
            f"filled with {max_gap:g} s of untracked frames",
            UserWarning,
            stacklevel=2,
        )
    source = np.asarray(source, dtype=np.int64)
    out = np.zeros((len(source), *x.shape[1:]), dtype=np.result_type(x, np.float64))
    kept = source >= 0
    out[kept] = x[source[kept]]
    return out, source


def estimate_fps(timestamps):
    """The frame rate that timestamps suggest: one over their median interval.

    Parameters
    ----------
    timestamps : array-like of shape (n,)
        Times of consecutive frames in seconds (frame numbers divided by the
        counter's rate give them too).

    Returns
    -------
    float or None
        The rate, or None with fewer than two increasing timestamps.

    Examples
    --------
    >>> from skgesture._rate import estimate_fps
    >>> estimate_fps([0.0, 0.1, 0.2, 0.4, 0.5])
    10.0
    """
    t = np.asarray(timestamps, dtype=np.float64).ravel()
    steps = np.diff(t[np.isfinite(t)])
    steps = steps[steps > 0]
    if not len(steps):
        return None
    return float(1.0 / np.median(steps))
