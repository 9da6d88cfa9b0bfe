"""Skeleton sources: a recording replayed, and live input over UDP, stdin and LSL.

A :class:`SkeletonSource` yields Kinect v1 frames ``(20, 3)`` for
:class:`~skgesture.streaming.StreamingRecognizer`. :class:`ReplaySource`
replays a recording; :class:`UDPSource` (JSON datagrams), :class:`StdinSource`
(CSV rows, for pipes) and :class:`LSLSource` (Lab Streaming Layer, the ``lsl``
extra) read a live stream.

Live sources keep time: each frame carries a timestamp, and a gap in the
timestamps is frames the sensor or the network lost, which come out as
untracked (all-zero) frames, the toolkit's convention for "nobody tracked"
(docs/design.md §1.1), rather than as squeezed time. The rule is
:class:`skgesture._rate.FrameClock`'s, shared by every live source and by
:func:`skgesture._rate.frames_from_timestamps` (recordings): a frame that comes
``k`` nominal periods (``round((t - t_previous) * fps)``) after the previous
one is preceded by ``k - 1`` untracked frames, at most ``MAX_GAP_SECONDS``
worth (a longer gap is cut there, with a warning); a frame whose timestamp is not
after the previous one (out of order, or a duplicate) is dropped with a warning
and counted in ``n_out_of_order_``. Input that cannot be read as a frame is
skipped with a warning that says what was wrong, and counted in
``n_dropped_``: a live stream never stops on one bad message.
"""

# SPDX-License-Identifier: BSD-3-Clause

import json
import math
import socket
import sys
import time
import warnings
from abc import ABC, abstractmethod
from numbers import Real

import numpy as np

from skgesture._rate import MAX_GAP_SECONDS, FrameClock
from skgesture.layouts import KINECT_V1, N_COORDS
from skgesture.streaming._adapters import (
    KinectV1Adapter,
    SkeletonAdapter,
    _as_positions,
    get_adapter,
)
from skgesture.utils._validation import MAX_COORDINATE

__all__ = [
    "SkeletonSource",
    "ReplaySource",
    "UDPSource",
    "StdinSource",
    "LSLSource",
]

MAX_WARNINGS = 10  # warnings of one kind per source; later ones are only counted
MAX_DATAGRAM = 65_535  # bytes, the largest UDP payload
UDP_RECEIVE_BUFFER = 1 << 22  # bytes asked of the OS (it may grant less)
POLL_SECONDS = 0.2  # how often a blocked read checks close() and the timeout

_UNTRACKED = np.zeros((KINECT_V1.n_joints, N_COORDS))


class SkeletonSource(ABC):
    """A source of Kinect v1 frames for :class:`StreamingRecognizer`.

    Implement :meth:`frames` to yield one ``(20, 3)`` array (metres, Kinect v1
    order; all zeros when nobody is tracked) per sensor frame. A live source
    wraps a sensor SDK: read its joints, pass them through the matching
    :class:`SkeletonAdapter`, yield. Iterating the source iterates
    :meth:`frames`.

    Attributes
    ----------
    fps : float
        Nominal frame rate.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import SkeletonSource
    >>> class StillSource(SkeletonSource):
    ...     fps = 20.0
    ...     def frames(self):
    ...         for _ in range(3):
    ...             yield np.ones((20, 3))
    >>> [f.shape for f in StillSource()]
    [(20, 3), (20, 3), (20, 3)]
    """

    fps = 20.0

    @abstractmethod
    def frames(self):
        """Yield Kinect v1 frames of shape ``(20, 3)``."""

    def __iter__(self):
        return iter(self.frames())


class ReplaySource(SkeletonSource):
    """Replays a recorded sequence frame by frame, optionally in real time.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_joints, 3)
        The recording, in the layout of ``adapter``.
    adapter : SkeletonAdapter, str or None, default=None
        Maps the frames to Kinect v1 (an adapter, or a layout name for
        :func:`get_adapter`); None when ``X`` is already Kinect v1.
    fps : float, default=20.0
        Frame rate of the recording.
    realtime : bool, default=False
        Wait between frames so that they come at ``fps``.
    clock : callable, default=time.monotonic
        Clock used with ``realtime`` (seconds).
    sleep : callable, default=time.sleep
        Sleep function used with ``realtime``.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import ReplaySource
    >>> X = np.zeros((4, 25, 3)); X[:, 0] = [0.1, 0.0, 2.0]
    >>> frames = list(ReplaySource(X, adapter="kinect_v2"))
    >>> len(frames), frames[0].shape, frames[0][0].tolist()
    (4, (20, 3), [0.1, 0.0, 2.0])
    """

    def __init__(
        self,
        X,
        *,
        adapter=None,
        fps=20.0,
        realtime=False,
        clock=time.monotonic,
        sleep=time.sleep,
    ):
        if isinstance(adapter, str):
            adapter = get_adapter(adapter)
        if adapter is not None and not isinstance(adapter, SkeletonAdapter):
            raise TypeError(
                "adapter must be a SkeletonAdapter, a layout name (see get_adapter) "
                f"or None, got {type(adapter).__name__}"
            )
        self.adapter = adapter or KinectV1Adapter()
        self.X = _as_positions(X, "ReplaySource X")
        if self.X.ndim != 3:
            raise ValueError(
                f"X must have shape (n_frames, n_joints, 3), got {self.X.shape}"
            )
        if isinstance(fps, bool) or not isinstance(fps, Real) or not 0 < fps < np.inf:
            raise ValueError(f"fps must be a positive finite number, got {fps!r}")
        self.fps = float(fps)
        self.realtime = realtime
        self.clock = clock
        self.sleep = sleep

    def frames(self):
        """Yield the adapted frames, paced at ``fps`` when ``realtime``.

        Yields
        ------
        ndarray of shape (20, 3)
            The next frame.
        """
        adapted = self.adapter(self.X)
        start = self.clock()
        for i, frame in enumerate(adapted):
            if self.realtime:
                wait = start + i / self.fps - self.clock()
                if wait > 0:
                    self.sleep(wait)
            yield frame


# --------------------------------------------------------------------------
# Live sources: timestamps, dropped frames, bad input
# --------------------------------------------------------------------------


# The dropped-frame rule (skgesture._rate.FrameClock), shared with
# skgesture._rate.frames_from_timestamps for recordings with timestamps.
_FrameClock = FrameClock


def _check_fps(fps, what="fps"):
    if isinstance(fps, bool) or not isinstance(fps, Real) or not 0 < fps < np.inf:
        raise ValueError(f"{what} must be a positive finite number, got {fps!r}")
    return float(fps)


def _check_seconds(value, name):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, Real) or not value > 0:
        raise ValueError(f"{name} must be a positive number of seconds or None, "
                         f"got {value!r}")  # fmt: skip
    return float(value)


def _check_max_frames(max_frames):
    if max_frames is None:
        return None
    if isinstance(max_frames, bool) or not isinstance(max_frames, (int, np.integer)):
        raise TypeError(f"max_frames must be an int or None, got {max_frames!r}")
    if max_frames < 0:
        raise ValueError(f"max_frames must be >= 0, got {max_frames}")
    return int(max_frames)


def _layout_adapter(layout):
    if isinstance(layout, SkeletonAdapter):
        return layout
    if not isinstance(layout, str):
        raise TypeError(
            "layout must be a layout name (see get_adapter) or a SkeletonAdapter, "
            f"got {type(layout).__name__}"
        )
    return get_adapter(layout)


class _LiveSource(SkeletonSource):
    """Shared state of the live sources: adapter, clock, counters, warnings."""

    def _setup(self, fps, layout, max_frames=None):
        self.fps = _check_fps(fps)
        self.layout = layout
        self.adapter = _layout_adapter(layout)
        self.max_frames = _check_max_frames(max_frames)
        self._clock = _FrameClock(self.fps)
        self._warned = {}
        self._closed = False
        self.n_frames_ = 0
        self.n_filled_ = 0
        self.n_out_of_order_ = 0
        self.n_dropped_ = 0

    def _warn(self, kind, message):
        """Warn, at most MAX_WARNINGS times per kind (later ones are only counted)."""
        n = self._warned[kind] = self._warned.get(kind, 0) + 1
        if n > MAX_WARNINGS:
            return
        if n == MAX_WARNINGS:
            message += (
                f" (warning {MAX_WARNINGS} of this kind: further ones are only "
                "counted, in the n_dropped_, n_out_of_order_ and n_filled_ "
                "attributes)"
            )
        warnings.warn(f"{type(self).__name__}: {message}", UserWarning, stacklevel=4)

    def _drop(self, what):
        self.n_dropped_ += 1
        self._warn("dropped", f"skipped {what}")

    def _to_frame(self, values, allow_nan):
        """One Kinect v1 frame from the joints of a message, or a ValueError."""
        n_joints = self.adapter.n_joints
        try:
            arr = np.asarray(values, dtype=np.float64)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(
                f"the joints are not {n_joints} [x, y, z] lists of numbers nor "
                f"{n_joints * N_COORDS} numbers"
            ) from None
        if arr.shape == (n_joints * N_COORDS,):
            arr = arr.reshape(n_joints, N_COORDS)
        if arr.ndim != 2 or arr.shape[0] != n_joints or arr.shape[1] < N_COORDS:
            raise ValueError(
                f"the joints have shape {arr.shape}, but layout "
                f"{self.adapter.name!r} has {n_joints} joints: expected "
                f"{n_joints} [x, y, z] lists or {n_joints * N_COORDS} numbers"
            )
        xyz = arr[:, :N_COORDS]
        bad = np.isinf(xyz) if allow_nan else ~np.isfinite(xyz)
        if bad.any():
            j = int(np.argwhere(bad)[0][0])
            raise ValueError(f"joint {j} holds {xyz[j].tolist()}, not finite numbers")
        huge = np.abs(np.nan_to_num(xyz)) > MAX_COORDINATE
        if huge.any():
            j = int(np.argwhere(huge)[0][0])
            raise ValueError(
                f"joint {j} holds {xyz[j].tolist()}, beyond {MAX_COORDINATE:g} in "
                "magnitude"
            )
        return self.adapter(arr)

    def _timed(self, t, frame, where=""):
        """Yield a frame stamped ``t`` after the untracked frames of its gap."""
        previous = self._clock.last
        gap = self._clock.gap(t)
        if gap is None:
            self.n_out_of_order_ += 1
            self._warn(
                "order",
                f"{where}dropped a frame stamped {t!r} s, not after the previous frame "
                f"({previous!r} s): out of order or a duplicate",
            )
            return
        n_fill, n_cut = gap
        if n_cut:
            self._warn(
                "gap",
                f"{where}a gap of {t - previous:.3f} s before the frame stamped "
                f"{t!r} s: "
                f"filled with {n_fill} untracked frames ({MAX_GAP_SECONDS:g} s, "
                f"the most filled), {n_cut} more left out",
            )
        for _ in range(n_fill):
            if self._full():
                return
            self.n_filled_ += 1
            self.n_frames_ += 1
            yield np.zeros_like(_UNTRACKED)
        if not self._full():
            self.n_frames_ += 1
            yield frame

    def _full(self):
        return self.max_frames is not None and self.n_frames_ >= self.max_frames

    def _wait(self, last_data, timeout):
        """Seconds to block for the next message, or None once ``timeout`` is over."""
        if timeout is None:
            return POLL_SECONDS
        left = last_data + timeout - time.monotonic()
        return None if left <= 0 else min(POLL_SECONDS, left)

    def close(self):
        """Stop the stream; an iteration in progress ends at its next read."""
        self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()


class UDPSource(_LiveSource):
    """Live frames from JSON datagrams on a UDP socket (standard library only).

    Each datagram holds one frame, as one JSON object (UTF-8)::

        {"t": 12.345, "joints": [[x, y, z], [x, y, z], ...]}

    * ``"t"``: the frame's timestamp in seconds, a finite number on any clock
      that increases (the sensor's, ``Time.time`` in Unity,
      ``time.monotonic()``); only differences matter.
    * ``"joints"``: the joints in the order of ``layout`` (20 for Kinect v1,
      25 for Kinect v2, ...; :func:`get_adapter`), in its units and axes, as
      ``[x, y, z]`` lists (further values per joint, such as a confidence,
      are ignored) or as one flat list ``[x0, y0, z0, x1, ...]`` (easier from
      Unity's ``JsonUtility``).
    * ``"tracked": false`` (optional, default true): nobody is tracked; the
      frame is untracked (all zeros) and ``"joints"`` may be left out.

    Timestamps keep time: a frame ``k`` nominal periods after the previous one
    is preceded by ``k - 1`` untracked frames (at most 10 s worth, with a
    warning beyond), and a frame stamped at or before the previous one is
    dropped with a warning (``n_out_of_order_``). A datagram that is not such
    an object (not JSON, no finite ``"t"``, the wrong number of joints, a
    non-finite or absurd coordinate) is skipped with a warning that says what
    was wrong and counted in ``n_dropped_``; the stream goes on. The socket is
    bound when the source is made, so no datagram sent after that is missed
    (up to the operating system's receive buffer while nothing reads).

    Parameters
    ----------
    host : str, default="127.0.0.1"
        Address to listen on; ``"0.0.0.0"`` listens on every interface.
    port : int, default=9000
        UDP port; 0 picks a free one (see ``bound_address``).
    fps : float, default=30.0
        Nominal frame rate of the sender.
    layout : str or SkeletonAdapter, default="kinect_v1"
        Layout of the joints (a name for :func:`get_adapter`, or an adapter);
        the frames are mapped to Kinect v1 by it.
    timeout : float or None, default=None
        End the stream after this many seconds without a datagram; None waits
        for ever (stop with :meth:`close` or Ctrl-C).
    max_frames : int or None, default=None
        End the stream after this many frames (untracked fill included).

    Attributes
    ----------
    bound_address : tuple
        ``(host, port)`` the socket listens on.
    adapter : SkeletonAdapter
        The adapter of ``layout``.
    n_frames_ : int
        Frames yielded so far, untracked fill included.
    n_filled_ : int
        Untracked frames yielded for gaps in the timestamps.
    n_out_of_order_ : int
        Frames dropped because their timestamp was not after the previous one.
    n_dropped_ : int
        Malformed datagrams skipped.

    See Also
    --------
    StdinSource : Live frames from CSV rows, for pipes.
    LSLSource : A Lab Streaming Layer stream.

    Notes
    -----
    A sender in Python (any language that can write JSON to a UDP socket
    will do, e.g. C# ``UdpClient`` in Unity):

    .. code-block:: python

        import json
        import socket
        import time

        FPS = 30.0
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        address = ("127.0.0.1", 9000)          # where UDPSource listens

        def read_joints():
            # your sensor here: 20 (x, y, z) positions in metres, Kinect v1
            # order, or None when nobody is tracked
            return [[0.0, 0.1 * k, 2.0] for k in range(20)]

        start = time.monotonic()
        while True:
            joints = read_joints()
            message = {"t": time.monotonic() - start}
            if joints is None:
                message["tracked"] = False
            else:
                message["joints"] = joints
            sock.sendto(json.dumps(message).encode(), address)
            time.sleep(1.0 / FPS)

    Examples
    --------
    >>> import json, socket
    >>> from skgesture.streaming import UDPSource
    >>> source = UDPSource(port=0, fps=30.0, timeout=1.0, max_frames=4)
    >>> sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    >>> joints = [[0.0, 1.0, 2.0]] * 20  # Kinect v1 order, metres
    >>> for t in (0.0, 1 / 30, 3 / 30):  # the frame at 2/30 s was lost
    ...     message = json.dumps({"t": t, "joints": joints}).encode()
    ...     _ = sender.sendto(message, source.bound_address)
    >>> with source:
    ...     frames = list(source)
    >>> [float(f.sum()) for f in frames], source.n_filled_
    ([60.0, 60.0, 0.0, 60.0], 1)
    >>> sender.close()
    """

    def __init__(
        self,
        host="127.0.0.1",
        port=9000,
        *,
        fps=30.0,
        layout="kinect_v1",
        timeout=None,
        max_frames=None,
    ):
        self._sock = None
        self._setup(fps, layout, max_frames)
        self.timeout = _check_seconds(timeout, "timeout")
        self.host, self.port = host, port
        try:
            family, _, _, _, address = socket.getaddrinfo(
                host, port, type=socket.SOCK_DGRAM
            )[0]
            sock = socket.socket(family, socket.SOCK_DGRAM)
        except (OSError, OverflowError, TypeError) as exc:
            raise ValueError(
                f"UDPSource cannot listen on {host!r} port {port!r}: {exc}"
            ) from None
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, UDP_RECEIVE_BUFFER)
        except OSError:  # pragma: no cover - the OS keeps its default
            pass
        try:
            sock.bind(address)
        except OSError as exc:
            sock.close()
            raise OSError(
                exc.errno, f"UDPSource cannot listen on {host}:{port}: {exc.strerror}"
            ) from None
        self._sock = sock
        self.bound_address = sock.getsockname()[:2]

    def frames(self):
        """Yield the frames of the datagrams as they come.

        Yields
        ------
        ndarray of shape (20, 3)
            The next frame (Kinect v1, all zeros when untracked).
        """
        last_data = time.monotonic()
        while not self._closed and not self._full():
            wait = self._wait(last_data, self.timeout)
            if wait is None:
                return
            try:
                self._sock.settimeout(wait)
                data, _ = self._sock.recvfrom(MAX_DATAGRAM)
            except TimeoutError:
                continue
            except OSError:
                if self._closed:
                    return
                raise
            last_data = time.monotonic()
            parsed = self._parse(data)
            if parsed is not None:
                yield from self._timed(*parsed)

    def _parse(self, data):
        """``(t, frame)`` of one datagram, or None (skipped, with a warning)."""
        try:
            message = json.loads(data)
        except (ValueError, RecursionError) as exc:
            return self._drop(f"a datagram that is not JSON ({exc})")
        if not isinstance(message, dict):
            return self._drop(
                f"a datagram holding a JSON {type(message).__name__}, not an object "
                'with "t" and "joints"'
            )
        t = message.get("t")
        try:
            t_ok = not isinstance(t, bool) and math.isfinite(t)
        except (TypeError, OverflowError):
            t_ok = False
        if not t_ok:
            return self._drop(
                f'a datagram whose "t" is {t!r}, not a finite number of seconds'
            )
        tracked = message.get("tracked", True)
        if tracked is False:
            return float(t), np.zeros_like(_UNTRACKED)
        if tracked is not True:
            return self._drop(
                f'the datagram at t={t}: "tracked" is {tracked!r}, not true or false'
            )
        if "joints" not in message:
            return self._drop(f'the datagram at t={t}: no "joints"')
        try:
            return float(t), self._to_frame(message["joints"], allow_nan=False)
        except ValueError as exc:
            return self._drop(f"the datagram at t={t}: {exc}")

    def close(self):
        """Close the socket; an iteration in progress ends at its next read."""
        self._closed = True
        if self._sock is not None:
            self._sock.close()


class StdinSource(_LiveSource):
    """Live frames from CSV rows on a text stream (stdin by default), for pipes.

    One frame per line, values separated by commas (or by white space):

    * ``x0, y0, z0, x1, ...``: ``3 * n_joints`` values, the joints in the
      order of ``layout``; the frames are ``1 / fps`` apart;
    * ``t, x0, y0, z0, ...``: a timestamp in seconds first; gaps in the
      timestamps become untracked frames, as in :class:`UDPSource`.

    Blank lines, ``#`` comments (whole lines or trailing) and a header (a
    first row that is not numbers) are skipped. An all-zero row, or one
    holding a NaN (``nan``), is an untracked frame.

    With ``timestamps=None`` the first row decides: ``3 * n_joints`` values
    have no timestamp and ``3 * n_joints + 1`` values one. The leading
    column of a file written with a frame counter would then be read as
    seconds; so when the first two rows both start with a whole number
    (``0, 1, ...``: a frame counter, or seconds at 1 fps?), the source
    raises a ValueError asking for ``timestamps=True`` (it is seconds). A
    first row with any other count raises a ValueError naming the line and
    the counts that would fit (probably the wrong ``layout``).

    After the first row, a bad line (another count, a value that is not a
    number, an infinite or absurd one) is skipped with a warning naming its
    line number and what was wrong, and counted in ``n_dropped_``: a live
    pipe does not stop on one bad line. A skipped row without timestamp
    becomes an untracked frame (it was a frame period); with timestamps the
    gap rule does the same.

    Parameters
    ----------
    stream : file-like or None, default=None
        Text stream to read lines from; None reads ``sys.stdin`` (looked up
        when the iteration starts).
    fps : float, default=30.0
        Nominal frame rate.
    layout : str or SkeletonAdapter, default="kinect_v1"
        Layout of the joints (a name for :func:`get_adapter`, or an adapter).
    timestamps : bool or None, default=None
        Whether each row starts with a timestamp; None decides by the count.

    Attributes
    ----------
    adapter : SkeletonAdapter
        The adapter of ``layout``.
    timestamps_ : bool or None
        Whether the rows have timestamps, once the first row has decided.
    n_frames_ : int
        Frames yielded so far, untracked fill included.
    n_filled_ : int
        Untracked frames yielded for gaps and for skipped rows.
    n_out_of_order_ : int
        Rows dropped because their timestamp was not after the previous one.
    n_dropped_ : int
        Bad lines skipped.

    See Also
    --------
    UDPSource : Live frames from JSON datagrams on a UDP socket.

    Examples
    --------
    >>> import io
    >>> from skgesture.streaming import StdinSource
    >>> row = ",".join(["0.5"] * 60)
    >>> text = f"# t, then 20 joints\\n0.0,{row}\\n0.05,{row}\\n0.15,{row}\\n"
    >>> source = StdinSource(io.StringIO(text), fps=20.0)
    >>> [float(f.sum()) for f in source], source.timestamps_
    ([30.0, 30.0, 0.0, 30.0], True)
    """

    def __init__(self, stream=None, *, fps=30.0, layout="kinect_v1", timestamps=None):
        self._setup(fps, layout)
        if timestamps not in (None, True, False):
            raise ValueError(f"timestamps must be True, False or None, got "
                             f"{timestamps!r}")  # fmt: skip
        self.stream = stream
        self.timestamps = timestamps
        self.timestamps_ = timestamps

    def close(self):
        """End the stream at the next line (the text stream is left open)."""
        self._closed = True

    def frames(self):
        """Yield one frame per data line, as the lines come.

        Yields
        ------
        ndarray of shape (20, 3)
            The next frame (Kinect v1, all zeros when untracked).

        Raises
        ------
        ValueError
            When the first row has a count that fits no format, or the first
            two rows start with whole numbers and ``timestamps`` is None.
        """
        stream = sys.stdin if self.stream is None else self.stream
        n_values = self.adapter.n_joints * N_COORDS
        pending = None  # first timestamped row, while its format is undecided
        seen_data = False
        for lineno, line in enumerate(stream, 1):
            if self._closed or self._full():
                return
            values = self._split(line)
            if values is None:
                continue
            numbers = self._numbers(values)
            if not seen_data and numbers is None:
                seen_data = True  # a header
                continue
            seen_data = True
            if self.timestamps_ is None:
                if pending is None:
                    pending = self._first_row(lineno, values, numbers, n_values)
                    if pending is not None:
                        continue
                else:
                    self._decide(pending, lineno, numbers, n_values)
                    yield from self._row(*pending[:2], n_values)
                    pending = None
            yield from self._row(lineno, numbers, n_values, line=values)
        if pending is not None:
            self.timestamps_ = True
            yield from self._row(*pending[:2], n_values)

    @staticmethod
    def _split(line):
        text = line.split("#", 1)[0].strip()
        if not text:
            return None
        sep = "," if "," in text else None
        return [v.strip() for v in text.split(sep)]

    @staticmethod
    def _numbers(values):
        try:
            return [float(v) for v in values]
        except ValueError:
            return None

    def _first_row(self, lineno, values, numbers, n_values):
        """Decide the format from the first row; the row itself when still open."""
        if len(values) == n_values:
            self.timestamps_ = False
            return None
        if len(values) == n_values + 1:
            if numbers is not None and float(numbers[0]).is_integer():
                return lineno, numbers  # wait for the second row
            self.timestamps_ = True
            return None
        raise ValueError(
            f"line {lineno} has {len(values)} values, but layout "
            f"{self.adapter.name!r} has {self.adapter.n_joints} joints: expected "
            f"{n_values} (x, y, z per joint) or {n_values + 1} (a timestamp in "
            "seconds, then x, y, z per joint)"
        )

    def _decide(self, pending, lineno, numbers, n_values):
        if (
            numbers is not None
            and len(numbers) == n_values + 1
            and float(numbers[0]).is_integer()
        ):
            raise ValueError(
                f"lines {pending[0]} and {lineno} start with the whole numbers "
                f"{pending[1][0]:g} and {numbers[0]:g}: a frame counter, or "
                "timestamps in seconds? Pass timestamps=True if the first column "
                "is seconds; drop a frame-counter column (e.g. cut -d, -f2-) and "
                "pass timestamps=False"
            )
        self.timestamps_ = True

    def _row(self, lineno, numbers, n_values, line=None):
        """Yield the frames of one data row (or skip it, with a warning)."""
        expect = n_values + 1 if self.timestamps_ else n_values
        index = self.n_frames_ + self.n_out_of_order_
        try:
            if numbers is None:
                bad = next(v for v in line if self._numbers([v]) is None)
                raise ValueError(f"{bad!r} is not a number")
            if len(numbers) != expect:
                raise ValueError(f"{len(numbers)} values, expected {expect}")
            if self.timestamps_ and not math.isfinite(numbers[0]):
                raise ValueError(f"the timestamp {numbers[0]!r} is not finite")
            frame = self._to_frame(numbers[-n_values:], allow_nan=True)
        except ValueError as exc:
            self._drop(f"line {lineno}: {exc}")
            if not self.timestamps_ and not self._full():
                self.n_filled_ += 1
                self.n_frames_ += 1
                self._clock.last = index / self.fps
                yield np.zeros_like(_UNTRACKED)
            return
        t = numbers[0] if self.timestamps_ else index / self.fps
        yield from self._timed(t, frame, where=f"line {lineno}: ")


def _import_pylsl():
    try:
        import pylsl
    except Exception as exc:  # ImportError, or RuntimeError without liblsl
        raise ImportError(
            "LSLSource needs pylsl and its liblsl: pip install 'skgesture[lsl]' "
            f"(or pip install pylsl). Importing pylsl failed: {exc}"
        ) from exc
    return pylsl


class LSLSource(_LiveSource):
    """Live frames from a Lab Streaming Layer stream (the ``lsl`` extra).

    Research labs stream Kinect, Azure Kinect and motion capture into LSL. The
    stream must have ``3 * n_joints`` numeric channels (``n_joints * C`` with
    ``C >= 3`` values per joint also works: the first 3 of each are x, y, z),
    one sample per frame, the joints in the order of ``layout``. LSL's sample
    timestamps keep time: gaps become untracked frames and out-of-order
    samples are dropped, as in :class:`UDPSource`. A sample holding a NaN, or
    all zeros, is an untracked frame; one holding an infinite or absurd value
    is skipped with a warning and counted in ``n_dropped_``.

    ``pylsl`` is imported when the source is made: ``pip install
    'skgesture[lsl]'`` (its wheels bundle liblsl).

    Parameters
    ----------
    name : str
        Name of the LSL stream (``StreamInfo.name()``).
    fps : float or None, default=None
        Nominal frame rate; None takes the stream's nominal rate (an error for
        an irregular stream, whose rate is 0).
    layout : str or SkeletonAdapter, default="kinect_v1"
        Layout of the joints (a name for :func:`get_adapter`, or an adapter).
    timeout : float or None, default=None
        End the stream after this many seconds without a sample; None waits
        for ever (stop with :meth:`close` or Ctrl-C).
    resolve_timeout : float, default=5.0
        Seconds to wait for the stream to be found and opened.
    max_frames : int or None, default=None
        End the stream after this many frames (untracked fill included).

    Attributes
    ----------
    info : pylsl.StreamInfo
        The stream's description.
    adapter : SkeletonAdapter
        The adapter of ``layout``.
    n_frames_ : int
        Frames yielded so far, untracked fill included.
    n_filled_ : int
        Untracked frames yielded for gaps in the timestamps.
    n_out_of_order_ : int
        Samples dropped because their timestamp was not after the previous one.
    n_dropped_ : int
        Bad samples skipped.

    Raises
    ------
    ImportError
        When pylsl (or liblsl) cannot be loaded.
    LookupError
        When no stream of that name is found within ``resolve_timeout``.

    See Also
    --------
    UDPSource : Live frames from JSON datagrams on a UDP socket.

    Examples
    --------
    >>> import pylsl  # doctest: +SKIP
    >>> from skgesture.streaming import LSLSource
    >>> info = pylsl.StreamInfo("kinect", "Mocap", 60, 30.0)  # doctest: +SKIP
    >>> outlet = pylsl.StreamOutlet(info)  # doctest: +SKIP
    >>> source = LSLSource("kinect", timeout=1.0)  # doctest: +SKIP
    >>> outlet.push_sample([0.5] * 60)  # doctest: +SKIP
    >>> with source:  # doctest: +SKIP
    ...     frames = list(source)
    >>> len(frames)  # doctest: +SKIP
    1
    """

    def __init__(
        self,
        name,
        *,
        fps=None,
        layout="kinect_v1",
        timeout=None,
        resolve_timeout=5.0,
        max_frames=None,
    ):
        self._inlet = None
        if not isinstance(name, str):
            raise TypeError(f"name must be a str, got {type(name).__name__}")
        timeout = _check_seconds(timeout, "timeout")
        resolve_timeout = _check_seconds(resolve_timeout, "resolve_timeout")
        adapter = _layout_adapter(layout)
        pylsl = _import_pylsl()
        found = pylsl.resolve_byprop("name", name, 1, resolve_timeout)
        if not found:
            raise LookupError(
                f"no LSL stream named {name!r} found within {resolve_timeout:g} s"
            )
        info = found[0]
        if fps is None:
            fps = info.nominal_srate()
            if not fps > 0:
                raise ValueError(
                    f"the LSL stream {name!r} has no nominal rate (irregular): pass fps"
                )
        self._setup(fps, adapter, max_frames)
        self.layout = layout
        self.name, self.timeout, self.resolve_timeout = name, timeout, resolve_timeout
        n_channels, n_joints = info.channel_count(), adapter.n_joints
        if info.channel_format() == pylsl.cf_string:
            raise ValueError(f"the LSL stream {name!r} holds strings, not numbers")
        if n_channels % n_joints or n_channels < n_joints * N_COORDS:
            raise ValueError(
                f"the LSL stream {name!r} has {n_channels} channels, but layout "
                f"{adapter.name!r} has {n_joints} joints: expected "
                f"{n_joints * N_COORDS} (x, y, z per joint)"
            )
        self._width = n_channels // n_joints
        self.info = info
        self._inlet = pylsl.StreamInlet(info)
        self._inlet.open_stream(timeout=resolve_timeout)

    def frames(self):
        """Yield the frames of the samples as they come.

        Yields
        ------
        ndarray of shape (20, 3)
            The next frame (Kinect v1, all zeros when untracked).
        """
        last_data = time.monotonic()
        while not self._closed and not self._full():
            wait = self._wait(last_data, self.timeout)
            if wait is None:
                return
            sample, t = self._inlet.pull_sample(timeout=wait)
            if sample is None:
                continue
            last_data = time.monotonic()
            samples, stamps = self._inlet.pull_chunk(timeout=0.0)
            for sample, t in zip([sample, *samples], [t, *stamps]):
                try:
                    shape = (self.adapter.n_joints, self._width)
                    frame = self._to_frame(np.reshape(sample, shape), allow_nan=True)
                except ValueError as exc:
                    self._drop(f"the sample stamped {t!r} s: {exc}")
                    continue
                yield from self._timed(float(t), frame)

    def close(self):
        """Close the inlet; an iteration in progress ends at its next read."""
        self._closed = True
        if self._inlet is not None:
            self._inlet.close_stream()
