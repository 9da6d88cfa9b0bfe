"""The live step of PoseDescriptor: its state for one stream.

A row is computed by the descriptor's own batch code (the compiled kernel, or
the numpy implementation without numba) on the few frames it needs, with the
sequence's start and end padding where the slice reaches them: the rows of a
stream are those of offline ``transform``, from one implementation.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture._stream import DEFAULT_MAX_BACKFILL, Rows
from skgesture.utils._buffers import HeldFrames, _concat_rows
from skgesture.utils._validation import check_stream_frames

_WARM = []  # whether the descriptor's code was run once in this process


class DescriptorStream:
    """State of :meth:`PoseDescriptor.stream_step` for one stream.

    Untracked frames (all zeros or a NaN) are held (the last tracked frame
    repeats, as ``fill="hold"``) and masked (rest). Untracked frames at the
    start of the stream wait for the first tracked frame and become copies of
    it, as offline filling does; only the last ``max_backfill`` of them wait,
    earlier ones are handed on at once as masked all-zero rows (the descriptor
    of an untracked sequence).

    Parameters
    ----------
    describe : callable
        ``describe(seq)``: the standardised descriptor rows of one filled
        sequence ``(n, 20, 3)``, the offline batch code.
    n_features : int
        Width of a row.
    reach : int
        Frames after a frame that its row needs (``stream_lookahead``).
    estimator : PoseDescriptor
        The fitted stage, whose input rule validates pushed frames.
    max_backfill : int, default=64
        Leading untracked frames that may wait for the first tracked one.
    """

    def __init__(self, describe, n_features, reach, estimator, max_backfill=None):
        self.describe = describe
        self.n_features = int(n_features)
        self.a = int(reach)
        self.estimator = estimator
        if max_backfill is None:
            max_backfill = DEFAULT_MAX_BACKFILL
        self.max_backfill = int(max_backfill)
        self.held_frames = HeldFrames(max_backfill)
        self.R = self.held_frames.frames  # filled raw frames
        self.untracked = self.held_frames.untracked
        self.times = self.held_frames.times
        if not _WARM:  # load the compiled kernel now, not on the first frame
            still = np.random.RandomState(0).normal(size=(2 * self.a + 1, 20, 3))
            describe(still)
            _WARM.append(True)
        self.n_out = 0
        self.p0 = None  # first frame held (None: no tracked frame yet)
        self.f = None  # first tracked frame

    def step(self, rows):
        """Raw frames in (checked as offline); the descriptor rows that became
        final out."""
        frames = check_stream_frames(rows.data, int(rows.time[0]), self.estimator)
        out, _, _ = self.held_frames.push(
            frames, rows.time, self.n_out, self._hand_on_leading
        )
        if self.held_frames.p0 is None:
            self._trim()
            return _concat_rows(out, (self.n_features,))
        self.p0, self.f = self.held_frames.p0, self.held_frames.first_tracked
        rows = self._advance(final=False)
        self._trim()
        if not out:
            return rows
        return _concat_rows(out + [rows], (self.n_features,))

    def flush(self):
        """The last rows, with the offline end padding."""
        if self.p0 is None:
            return self._hand_on_leading(self.held_frames.n_in)
        return self._advance(final=True)

    def _advance(self, final):
        """The rows that became final, by the descriptor's batch code on the
        frames they need (the sequence's start and end padding where the
        slice reaches them); bit for bit the rows of ``transform``.

        A degenerate torso takes the body axes of the last good frame within
        the ``a`` frames before it (offline: any earlier frame).
        """
        R, a, lo = self.R, self.a, self.n_out
        r_stop = R.stop if final else R.stop - a
        if r_stop <= lo:
            return Rows.empty((self.n_features,))
        first = max(self.p0, lo - a)
        D = self.describe(R.data(first, R.stop))
        data = D[lo - first : r_stop - first]
        mask = self.untracked.data(lo, r_stop).copy()
        if final:
            time = np.full(r_stop - lo, self._now(), dtype=np.int64)
        else:
            done = np.maximum(np.arange(lo, r_stop) + a, self.f)
            time = self.times.data(done[0], done[-1] + 1)[done - done[0]].copy()
        self.n_out = r_stop
        return Rows(np.array(data), mask, time)

    def _now(self):
        return int(self.times.data(self.times.stop - 1, self.times.stop)[0])

    def _hand_on_leading(self, until):
        """Hand on the leading untracked frames before ``until`` as zero rows."""
        lo = self.n_out
        if until <= lo:
            return Rows.empty((self.n_features,))
        self.n_out = until
        n = until - lo
        return Rows(
            np.zeros((n, self.n_features)),
            np.ones(n, dtype=bool),
            np.full(n, self._now(), dtype=np.int64),
        )

    def _trim(self):
        if self.p0 is not None:
            self.R.drop(self.n_out - self.a)
        self.untracked.drop(self.n_out)
        self.times.drop(min(self.n_out, self.held_frames.n_in - 1))

    def held(self):
        """Rows held by the buffers."""
        return {"frames": len(self.R)}
