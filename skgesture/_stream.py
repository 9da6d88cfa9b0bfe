"""Incremental steps: how every stage of a pipeline runs on a live stream.

The protocol (docs/design.md, "Incremental steps"). A fitted stage that can
stream has three methods and one property:

``stage.stream_init(**options) -> state``
    A fresh state for one stream. Options a stage does not know are ignored
    (the recogniser passes the same options to every stage).
``stage.stream_step(state, rows) -> (out, state)``
    ``rows`` are the next frames of the stream (a :class:`Rows` block, one row
    per frame, in order, never empty); ``out`` holds everything that became
    final with them: a :class:`Rows` block of the stage's output rows (a
    transformer) or a list of :class:`StreamSegment` (the last stage, a
    classifier or tagger). The state may be updated in place; callers use
    the returned one.
``stage.stream_flush(state) -> (out, state)``
    The end of the stream: the remaining outputs, with the offline end rules
    (padding, end-point fits). The state is then spent.
``stage.stream_lookahead``
    Frames of input after a frame that the stage may need before its output
    for that frame is final (its delay, worst case). The recogniser adds them
    up to bound the delay of an event.

Every output row and segment carries ``time``: the stream frame whose arrival
made it final (for a flush, the last frame). Rows are never dropped or added:
a stage hands on exactly one row per input frame, in order (contract 1 of the
data), possibly later. Masked rows are rest (untracked frames, or frames the
segmenter finds at rest), as in the offline masked arrays (contract 2).

The building blocks here (:class:`RowBuffer`, :class:`LoessStepper`,
:class:`LabelRuns`, :func:`fast_proba`) are shared by the stages' steps; the
stages' own steps (``DescriptorStream`` ... ``TaggerStream``) reuse the
offline decision rules (``decide_period``, ``period_windows``,
``dynamic_poses``, ``loess_smooth``), so that a stream gives the rows and the
segments of offline ``transform`` and ``predict_segments`` on the whole
recording.
"""

# SPDX-License-Identifier: BSD-3-Clause

from typing import NamedTuple

import numpy as np

__all__ = [
    "DEFAULT_MAX_BACKFILL",
    "DEFAULT_MAX_PERIOD",
    "Rows",
    "StreamSegment",
    "stream_frames",
]

DEFAULT_MAX_BACKFILL = 64  # leading untracked frames that may become copies
DEFAULT_MAX_PERIOD = 1200  # frames (60 s at 20 fps) before a period is closed


class Rows:
    """A block of consecutive rows of a stream.

    Parameters
    ----------
    data : ndarray of shape (n, ...)
        One row per frame.
    mask : ndarray of bool of shape (n,)
        True for a masked row: rest (an untracked frame, or a frame outside
        every period of activity).
    time : ndarray of int64 of shape (n,)
        Stream frame whose arrival made each row final.
    info : dict or None, default=None
        What a stage tells the next one about its rows (e.g. the window layout
        of :class:`WindowStream`).
    """

    __slots__ = ("data", "mask", "time", "info")

    def __init__(self, data, mask, time, info=None):
        self.data = data
        self.mask = mask
        self.time = time
        self.info = info

    def __len__(self):
        return len(self.data)

    @classmethod
    def empty(cls, row_shape, dtype=np.float64):
        """An empty block of rows of shape ``row_shape``."""
        return cls(
            np.empty((0, *row_shape), dtype=dtype),
            np.zeros(0, dtype=bool),
            np.zeros(0, dtype=np.int64),
        )

    def __repr__(self):
        return f"Rows(n={len(self)}, row_shape={self.data.shape[1:]})"


class StreamSegment(NamedTuple):
    """A gesture decided by the last stage of a stream (``end`` exclusive)."""

    label: int
    start: int
    end: int
    confidence: float
    time: int


def stream_frames(frames, first):
    """Raw frames ``first, first + 1, ...`` as the input :class:`Rows` of a stream.

    Parameters
    ----------
    frames : ndarray of shape (n, ...)
        Consecutive frames.
    first : int
        Stream index of the first one.

    Returns
    -------
    Rows
        Unmasked rows, each final at its own frame.
    """
    n = len(frames)
    return Rows(frames, np.zeros(n, dtype=bool), np.arange(first, first + n))


# -- causal loess --------------------------------------------------------------


# -- framewise network scores ----------------------------------------------------


# -- the descriptor, one frame at a time -----------------------------------------


# -- segmenter: framewise score, loess, threshold, minimum length ----------------


# -- windows and the multi-scale classifier: periods, windows, decision rules --------


# -- taggers: per-frame class probabilities, loess, minimum run ---------------------


# -- JointFeatures, one frame at a time --------------------------------------------
