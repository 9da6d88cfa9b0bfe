"""The streaming protocol: how every stage of a pipeline runs on a live stream.

This module is the base of every stage's live step; it imports numpy and
nothing of skgesture (tests/test_structure.py holds it so). The protocol
(docs/design.md, "Incremental steps"): a fitted stage that can stream has
three methods and one property, written once by :class:`StreamableMixin`:

``stage.stream_init(**options) -> state``
    A fresh state for one stream. A stage takes the options it declares
    (``_stream_options``) and refuses any other; the recogniser routes each
    option to the stages that declare it.
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

A stage's state lives beside the stage (``_descriptor/_stream.py``,
``_segmenter.py``, ``_windows.py``, ``_multiscale/_stream.py``,
``_features.py``, ``_taggers/_stream.py``); the building blocks they share are
in :mod:`skgesture.utils` (``RowBuffer``, ``LoessStepper``) and
:mod:`skgesture._taggers._decoding` (``LabelRuns``).
"""

# SPDX-License-Identifier: BSD-3-Clause

from typing import NamedTuple

import numpy as np

__all__ = [
    "StreamableMixin",
    "DEFAULT_MAX_BACKFILL",
    "DEFAULT_MAX_PERIOD",
    "Rows",
    "StreamSegment",
    "stream_frames",
    "missing_stream_methods",
]

DEFAULT_MAX_BACKFILL = 64  # leading untracked frames that may become copies
DEFAULT_MAX_PERIOD = 1200  # frames (60 s at 20 fps) before a period is closed
PROTOCOL = ("stream_init", "stream_step", "stream_flush", "stream_lookahead")


def missing_stream_methods(stage):
    """The names of :data:`PROTOCOL` that ``stage``'s class lacks (empty: it
    can run on a stream). Read on the class, so that no property runs."""
    return [name for name in PROTOCOL if not hasattr(type(stage), name)]


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


class StreamableMixin:
    """Mixin of a stage that runs on a live stream, one block of rows at a time.

    Writes the protocol of the module docstring once, as imbalanced-learn's
    ``SamplerMixin`` writes ``fit_resample``. A stage provides:

    * ``_stream_options``: the names of the options its ``stream_init``
      takes (a tuple; empty by default);
    * ``_stream_state(**options)``: a fresh state for one stream, an object
      with ``step(rows)`` (the outputs that became final with ``rows``),
      ``flush()`` (the remaining outputs) and ``held()`` (rows held, by
      buffer); the stage checks that it is fitted there;
    * ``stream_lookahead``: an int property (see the module docstring).

    Offline ``transform``/``predict_segments`` and the live step share their
    rules; tests/test_streaming.py checks that a stream gives the offline
    output of the whole recording.
    """

    _stream_options = ()

    def stream_init(self, **options):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Parameters
        ----------
        **options
            The options this stage declares (``_stream_options``), e.g.
            ``max_backfill`` for the first stage or ``max_period`` for the
            last; see the stage's ``_stream_state``.

        Returns
        -------
        object
            The state, for :meth:`stream_step` and :meth:`stream_flush`.

        Raises
        ------
        TypeError
            On an option the stage does not declare.
        """
        unknown = sorted(set(options) - set(self._stream_options))
        if unknown:
            takes = ", ".join(self._stream_options) or "no option"
            raise TypeError(
                f"{type(self).__name__}.stream_init got the unknown option(s) "
                f"{', '.join(unknown)}; it takes {takes}"
            )
        return self._stream_state(**options)

    def stream_step(self, state, rows):
        """The next rows of the stream in; what became final with them out.

        Parameters
        ----------
        state : object
            From :meth:`stream_init`.
        rows : Rows
            The next rows (raw frames for the first stage), never empty, with
            their stream indices or completion times as ``time``.

        Returns
        -------
        out : Rows or list of StreamSegment
            The output rows that became final (a transformer), or the gestures
            decided (the last stage).
        state : object
            The updated state.
        """
        return state.step(rows), state

    def stream_flush(self, state):
        """End of the stream: the remaining outputs, with the offline end rules.

        Parameters
        ----------
        state : object
            From :meth:`stream_init`.

        Returns
        -------
        out : Rows, list of StreamSegment or None
            The remaining outputs (``None`` when nothing was held back).
        state : object
            The spent state.
        """
        return state.flush(), state
