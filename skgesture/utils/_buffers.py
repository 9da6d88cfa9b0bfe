"""Buffers of a stream: rows by stream index, held raw frames, running medians."""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture._stream import Rows
from skgesture.utils._validation import missing_frames


class RowBuffer:
    """Rows addressed by their stream index, kept contiguous, appended in order.

    Holds the rows ``start .. stop - 1``; :meth:`drop` forgets old ones. The
    storage grows only when more rows are held than ever before, so a stage
    that drops what it no longer needs keeps a fixed footprint.

    Parameters
    ----------
    row_shape : tuple of int
        Shape of one row.
    dtype : dtype, default=np.float64
        Row dtype.
    capacity : int, default=32
        Initial storage, in rows.
    """

    def __init__(self, row_shape=(), dtype=np.float64, capacity=32):
        self._data = np.empty((capacity, *row_shape), dtype=dtype)
        self._mask = np.zeros(capacity, dtype=bool)
        self._time = np.zeros(capacity, dtype=np.int64)
        self._off = 0
        self.start = 0
        self.stop = 0

    def __len__(self):
        return self.stop - self.start

    @property
    def capacity(self):
        """Rows the storage can hold."""
        return len(self._data)

    def append(self, data, mask=None, time=None):
        """Append rows (with their mask and time) after the last one."""
        k = len(data)
        n = self.stop - self.start
        if self._off + n + k > len(self._data):
            self._make_room(n, k)
        lo = self._off + n
        self._data[lo : lo + k] = data
        self._mask[lo : lo + k] = False if mask is None else mask
        self._time[lo : lo + k] = 0 if time is None else time
        self.stop += k

    def _make_room(self, n, k):
        cap = len(self._data)
        keep = slice(self._off, self._off + n)
        if n + k > cap // 2:
            new = max(2 * cap, n + k)
            data = np.empty((new, *self._data.shape[1:]), dtype=self._data.dtype)
            mask = np.zeros(new, dtype=bool)
            time = np.zeros(new, dtype=np.int64)
            data[:n], mask[:n], time[:n] = (
                self._data[keep],
                self._mask[keep],
                self._time[keep],
            )
            self._data, self._mask, self._time = data, mask, time
        else:
            self._data[:n] = self._data[keep].copy()
            self._mask[:n] = self._mask[keep].copy()
            self._time[:n] = self._time[keep].copy()
        self._off = 0

    def _slice(self, lo, hi):
        if lo < self.start or hi > self.stop or lo > hi:
            raise IndexError(
                f"rows {lo}..{hi - 1} are not held (held: {self.start}.."
                f"{self.stop - 1}); this is a bug in skgesture's streaming"
            )
        return slice(self._off + lo - self.start, self._off + hi - self.start)

    def data(self, lo, hi):
        """Rows ``lo .. hi - 1`` (a view, valid until the next append)."""
        return self._data[self._slice(lo, hi)]

    def mask(self, lo, hi):
        """Masks of rows ``lo .. hi - 1`` (a view)."""
        return self._mask[self._slice(lo, hi)]

    def time(self, lo, hi):
        """Times of rows ``lo .. hi - 1`` (a view)."""
        return self._time[self._slice(lo, hi)]

    def rows(self, lo, hi):
        """Rows ``lo .. hi - 1`` as a :class:`Rows` block (copies)."""
        s = self._slice(lo, hi)
        return Rows(self._data[s].copy(), self._mask[s].copy(), self._time[s].copy())

    def restart(self, at):
        """Forget every row; the next one appended is row ``at`` (>= stop)."""
        self._off = 0
        self.start = self.stop = at

    def drop(self, until):
        """Forget the rows before ``until``."""
        d = min(until, self.stop) - self.start
        if d > 0:
            self._off += d
            self.start += d


class HeldFrames:
    """The raw frames of a stream, untracked ones held, leading ones backfilled.

    The intake of every stage that reads raw skeletons live (``PoseDescriptor``,
    ``JointFeatures``), one rule for both: an untracked frame repeats the last
    tracked one (offline ``fill="hold"``: the future is unknown), and the
    untracked frames that start a stream wait for the first tracked frame and
    become copies of it, as offline filling does; only the last
    ``max_backfill`` of them wait, earlier ones are handed on at once (as rest)
    by the stage's ``hand_on``.

    Parameters
    ----------
    max_backfill : int
        Leading untracked frames that may wait for the first tracked one.
    frame_shape : tuple, default=(20, 3)
        Shape of one raw frame.

    Attributes
    ----------
    frames : RowBuffer
        The filled raw frames, from ``p0`` on.
    untracked : RowBuffer
        Whether each frame pushed was untracked (all zeros or a NaN).
    times : RowBuffer
        The stream time of each frame pushed.
    n_in : int
        Frames pushed.
    p0 : int or None
        First frame held (``None`` until a tracked frame arrives).
    first_tracked : int or None
        First tracked frame.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils._buffers import HeldFrames
    >>> held = HeldFrames(max_backfill=1, frame_shape=(1,))
    >>> x = np.array([[0.0], [0.0], [2.0], [0.0], [3.0]])
    >>> handed = []
    >>> out, first, untracked = held.push(x, np.arange(5), 0, handed.append)
    >>> handed, held.p0, held.frames.data(1, 5)[:, 0].tolist(), untracked.tolist()
    ([1], 1, [2.0, 2.0, 2.0, 3.0], [True, True, False, True, False])
    """

    def __init__(self, max_backfill, frame_shape=(20, 3)):
        self.max_backfill = int(max_backfill)
        self.frames = RowBuffer(frame_shape, capacity=32)
        self.untracked = RowBuffer((), dtype=bool, capacity=32)
        self.times = RowBuffer((), dtype=np.int64, capacity=32)
        self.n_in = 0
        self.p0 = None
        self.first_tracked = None
        self.last = None  # the last tracked (or held) frame

    def push(self, frames, times, n_out, hand_on):
        """Append the next validated frames, whose stream times are ``times``.

        ``n_out`` is the stage's count of rows handed on; ``hand_on(until)``
        hands on the leading frames before ``until`` as rest and returns its
        output. Returns the list of those outputs (empty once tracking began),
        the index of ``frames[0]`` and the frames' untracked mask.
        """
        first = self.n_in
        self.n_in += len(frames)
        untracked = missing_frames(frames)
        self.untracked.append(untracked)
        self.times.append(times)
        mask = untracked
        out = []
        if self.p0 is None:
            if untracked.all():
                out.append(hand_on(first + len(frames) - self.max_backfill))
                return out, first, mask
            k = int(np.argmax(~untracked))
            until = first + k - self.max_backfill
            out.append(hand_on(until))
            self.p0, self.first_tracked = max(n_out, until), first + k
            self.frames.restart(self.p0)
            # The leading frames kept back become copies of the first tracked one.
            n_copies = self.first_tracked - self.p0
            self.frames.append(np.repeat(frames[k : k + 1], n_copies, axis=0))
            self.last = frames[k]
            frames, untracked = frames[k:], untracked[k:]
        if untracked.any():  # hold: an untracked frame repeats the last tracked one
            frames = frames.copy()
            src = np.maximum.accumulate(
                np.where(~untracked, np.arange(len(frames)), -1)
            )
            frames[src < 0] = self.last
            frames[src >= 0] = frames[src[src >= 0]]
        self.last = frames[-1]
        self.frames.append(frames)
        return out, first, mask


def _concat_rows(parts, row_shape, dtype=np.float64):
    """One :class:`Rows` block from a list of blocks."""
    parts = [p for p in parts if p is not None and len(p)]
    if not parts:
        return Rows.empty(row_shape, dtype)
    if len(parts) == 1:
        return parts[0]
    return Rows(
        np.concatenate([p.data for p in parts]),
        np.concatenate([p.mask for p in parts]),
        np.concatenate([p.time for p in parts]),
        parts[0].info,
    )


class RunningMedian:
    """Column medians of the last ``window`` rows added, kept sorted.

    Each column is a sorted list (``bisect``): adding a row and dropping the
    oldest costs a binary search and a move of at most ``window`` values per
    column, not a partition of the whole window; the median is
    ``numpy.median``'s (the middle value, or the mean of the two middle
    values, ``(a + b) / 2``), bit for bit.

    Parameters
    ----------
    n_columns : int
        Values per row.
    window : int
        Rows kept.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils._buffers import RunningMedian
    >>> x = np.random.RandomState(0).rand(50, 2)
    >>> med = RunningMedian(2, 8)
    >>> for row in x.tolist():
    ...     med.add(row)
    >>> bool(np.array_equal(med.median(), np.median(x[-8:], axis=0)))
    True
    """

    def __init__(self, n_columns, window):
        from collections import deque

        self.n_columns = int(n_columns)
        self.window = int(window)
        self.sorted = [[] for _ in range(self.n_columns)]
        self.rows = deque()
        self.n_added = 0  # rows added since the start

    def __len__(self):
        return len(self.rows)

    def add(self, row):
        """Add a row (a sequence of ``n_columns`` floats); drop the oldest."""
        import bisect

        row = [float(v) for v in row]
        for values, v in zip(self.sorted, row):
            bisect.insort(values, v)
        self.rows.append(row)
        self.n_added += 1
        if len(self.rows) > self.window:
            for values, v in zip(self.sorted, self.rows.popleft()):
                del values[bisect.bisect_left(values, v)]

    def median(self):
        """The median of every column, float64."""
        n = len(self.rows)
        if n % 2:
            return np.array([values[n // 2] for values in self.sorted])
        h = n // 2
        return np.array([(values[h - 1] + values[h]) / 2 for values in self.sorted])
