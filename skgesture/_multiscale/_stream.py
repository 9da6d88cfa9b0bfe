"""The live step of MultiScaleClassifier: its state for one stream."""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from numbers import Integral

import numpy as np

from skgesture._nn._mlp import fast_proba
from skgesture._stream import DEFAULT_MAX_PERIOD, StreamSegment
from skgesture._windows import (
    DynamicPoses,
)
from skgesture.utils._buffers import RowBuffer


class MultiScaleStream:
    """State of :meth:`MultiScaleClassifier.stream_step` for one stream.

    Periods of activity are the runs of unmasked rows. While a period is open,
    the window centred at ``c`` (stride ``stride`` from its start + ``hw``) is
    built and scored as soon as row ``c + hw`` is known to be in the period. A
    period is decided when it closes (at the first masked row) with the
    offline rule (``decide``, the classifier's ``_period_segments``: the paper's
    short and long rules, and the cubic resizing of a short period). In a
    period known to be long (``short_length`` frames), a run of windows is
    emitted as soon as no later window can change its frames (see
    docs/streaming.md, "Delay"). A period reaching ``max_period`` frames is
    closed and decided.

    With ``early_decision=True`` a period is treated as long from its start:
    runs are emitted without waiting ``short_length`` frames, and a period that
    ends short gets the majority vote only if nothing was emitted in it. The
    events may then differ from offline ``predict``: agreement is traded for
    delay (docs/streaming.md, "Delay").
    """

    def __init__(
        self,
        clf,
        steps,
        fusion,
        decide,
        max_period=DEFAULT_MAX_PERIOD,
        early_decision=False,
    ):
        self.clf = clf
        self.steps = tuple(steps)
        self.n_poses = clf.n_poses
        self.hw = max(steps) * (clf.n_poses - 1) // 2
        self.stride = clf.stride
        self.min_windows = clf.min_windows
        # A period shorter than this has fewer than min_windows windows and is
        # resized (docs/method.md §5.3, period_windows).
        self.n_resize = 2 * self.hw + 1 + self.stride * (self.min_windows - 1)
        self.fusion = fusion
        self.decide = decide  # the offline decision of one period
        self.probas = [fast_proba(est) for est in clf.estimators_]
        self.classes = np.asarray(clf.classes_)
        self.short_length = clf.short_length
        self.threshold_long = clf.threshold_long
        self.min_consecutive = clf.min_consecutive
        if (
            isinstance(max_period, bool)
            or not isinstance(max_period, Integral)
            or max_period < self.n_resize
        ):
            raise ValueError(
                f"max_period must be an int of at least {self.n_resize} frames (a "
                f"period of min_windows={self.min_windows} windows), got "
                f"{max_period!r}"
            )
        self.max_period = int(max_period)
        self.early = bool(early_decision)
        self.rows = None
        self.n_in = 0
        self.last_time = 0
        self.events = []
        self._reset_period()

    def _reset_period(self):
        self.start = None  # first row of the open period
        self.length = 0
        self.long = self.early
        self.next_centre = 0
        self.scores = []
        self.centres = []
        self.rec = []  # best class of each window above threshold_long, else -1
        self.scan_pos = 0
        self.run_first = 0
        self.pending = []  # finished runs of windows, not yet final
        self.emitted = set()

    def step(self, rows):
        windows = (rows.info or {}).get("windows")
        if rows.data.ndim != 2 or not isinstance(windows, DynamicPoses):
            raise TypeError(
                "MultiScaleClassifier streams after a DynamicPoseWindow stage, whose "
                "stream step hands on the descriptor rows with their lazy windows; "
                f"got rows of shape {rows.data.shape[1:]}"
            )
        if (windows.steps, windows.n_poses) != (self.steps, self.n_poses):
            raise ValueError(
                f"DynamicPoseWindow(steps={windows.steps}, n_poses={windows.n_poses}) "
                f"does not match MultiScaleClassifier(steps={self.steps}, n_poses="
                f"{self.n_poses}): use the same steps in both stages"
            )
        if self.rows is None:
            self.rows = RowBuffer(rows.data.shape[1:], capacity=64)
        self.events = []
        first = self.n_in
        self.n_in += len(rows)
        self.last_time = int(rows.time[-1])
        for i, masked in enumerate(rows.mask.tolist()):
            u, now = first + i, int(rows.time[i])
            if masked:
                if self.start is not None:
                    self._close(u, now)
                    self._reset_period()
                continue
            if self.start is None:
                self.start = u
                self.next_centre = u + self.hw
                self.rows.restart(u)
            self.rows.append(rows.data[i : i + 1])
            self._on_row(u, now)
        return self.events

    def flush(self):
        self.events = []
        if self.start is not None:
            self._close(self.n_in, self.last_time)
            self._reset_period()
        return self.events

    def _on_row(self, u, now):
        self.length = u - self.start + 1
        self._score_windows(u)
        if not self.long and self.length >= self.short_length:
            self.long = True
        if self.long:
            self._scan_runs(now)
        if self.length >= self.max_period:
            self._close(u + 1, now)
            self._reset_period()

    def _windows(self, D):
        """The lazy windows of descriptor rows ``D`` of the period."""
        return DynamicPoses(D, self.steps, self.n_poses)

    def _fused(self, wins):
        """Fused class scores of windows ``(n, n_scales, width)``, as offline."""
        return sum(
            wk * proba(wins[:, k])
            for k, (wk, proba) in enumerate(zip(self.fusion, self.probas))
        )

    def _score_windows(self, u):
        """Score the windows whose frames are all known to be in the period."""

        hw, stride = self.hw, self.stride
        last = u - hw  # largest centre whose window ends inside the period
        if self.next_centre > last:
            return
        centres = np.arange(self.next_centre, last + 1, stride)
        D = self.rows.data(centres[0] - hw, centres[-1] + hw + 1)
        wins = self._windows(D).windows(centres - centres[0] + hw)
        scores = self._fused(wins)
        self.next_centre = int(centres[-1]) + stride
        best = np.argmax(scores, axis=1)
        top = scores[np.arange(len(scores)), best]
        self.scores.extend(scores)
        self.centres.extend(int(c) - self.start for c in centres)
        self.rec.extend(np.where(top > self.threshold_long, best, -1).tolist())
        # Keep the rows of a period that may still be resized, else those of
        # the windows to come.
        if self.length >= self.n_resize:
            self.rows.drop(self.next_centre - hw)

    def _scan_runs(self, now):
        """Long period: emit the runs of windows that no later window can change.

        A frame belongs to a run only inside the run's extent (its centres
        +- ``hw``) and goes to the nearest centre, the earlier run on ties
        (docs/method.md §5.5, decision D17). A finished run whose last centre
        is ``c`` is therefore final once every window that could still join a
        qualifying run is centred at ``c + 2 hw`` or later: the next window to
        come, or the first window of a trailing run of one class still shorter
        than ``min_consecutive``.
        """
        rec, n = self.rec, len(self.rec)
        min_run = self.min_consecutive
        for i in range(self.scan_pos, n):
            if i > 0 and rec[i] != rec[i - 1]:
                a = self.run_first
                if rec[a] >= 0 and i - a >= min_run:
                    self.pending.append((a, i))
                self.run_first = i
        self.scan_pos = n
        if not self.pending:
            return
        first = self.run_first
        if rec[first] >= 0 and n - first < min_run:
            frontier = self.centres[first]
        else:
            frontier = self.centres[-1] + self.stride
        while self.pending:
            a, b = self.pending[0]
            if self.centres[b - 1] + 2 * self.hw > frontier:
                break
            self.pending.pop(0)
            self._emit_run(a, now)

    def _segments(self, scores, centres, length, resized=False, early=False):
        short = 0 if early else None  # early decision: the long-period rule
        return self.decide(
            np.asarray(scores), np.asarray(centres), length, resized,
            short_length=short,
        )  # fmt: skip

    def _emit_run(self, a, now):
        """Emit the segment of the run starting at window ``a``, decided with
        the offline rule on every window of the period so far."""
        c0 = self.centres[a]
        segs = self._segments(self.scores, self.centres, self.length, early=self.early)
        for seg in segs:
            if seg[1] <= c0 < seg[2]:
                self._emit_segment(seg, now)

    def _emit_segment(self, seg, now):
        cls, lo, hi, conf = seg
        key = (int(cls), int(lo), int(hi))
        if key in self.emitted:
            return
        self.emitted.add(key)
        self.events.append(
            StreamSegment(
                int(self.classes[cls - 1]),
                self.start + int(lo),
                self.start + int(hi),
                float(conf),
                int(now),
            )  # fmt: skip
        )

    def _close(self, end, now):
        """Decide the period ``[start, end)`` with the offline rule."""
        from skgesture._multiscale._rules import period_windows

        length = end - self.start
        resized = False
        if length >= self.n_resize:
            scores, centres = self.scores, self.centres
        else:
            # Too short for min_windows windows: resized (docs/method.md §5.3).
            W = self._windows(self.rows.data(self.start, end)).windows()
            wins, centres, resized = period_windows(
                W, 0, length, self.steps, n_poses=self.n_poses,
                stride=self.stride, min_windows=self.min_windows,
                resize=self.clf.resize,
            )  # fmt: skip
            scores = self._fused(np.asarray(wins))
        if self.early and self.emitted and length < self.short_length:
            return  # early decision: the runs already emitted stand
        segs = self._segments(scores, centres, length, resized)  # the offline rule
        final = {(int(c), int(lo), int(hi)) for c, lo, hi, _ in segs}
        if not self.early and not self.emitted <= final:
            warnings.warn(
                "StreamingRecognizer emitted a gesture that the offline decision "
                "rule no longer gives at the end of its period; the rule of "
                "decide_period changed in a way the early emission does not know",
                RuntimeWarning,
                stacklevel=2,
            )
        for seg in segs:
            self._emit_segment(seg, now)

    def held(self):
        return {"descriptors": len(self.rows or ()), "windows": len(self.scores)}
