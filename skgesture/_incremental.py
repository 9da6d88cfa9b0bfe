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

import math
import re
import warnings
from numbers import Integral, Real
from typing import NamedTuple

import numpy as np

from skgesture._descriptor import DEGENERATE_INCLINATION, MIN_NORM
from skgesture.utils._smoothing import loess_kernel, loess_smooth

__all__ = [
    "Rows",
    "StreamSegment",
    "RowBuffer",
    "LoessStepper",
    "LabelRuns",
    "fast_proba",
    "stream_frames",
]

DEFAULT_MAX_BACKFILL = 64  # leading untracked frames that may become copies
DEFAULT_MAX_PERIOD = 1200  # frames (60 s at 20 fps) before a period is closed
_WARM = []  # whether the compiled descriptor kernel was run in this process


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


# -- causal loess --------------------------------------------------------------


def check_stream_span(span, owner):
    """Odd integer span of a streamed loess; fractions need the whole length."""
    if isinstance(span, Real) and not isinstance(span, Integral) and 0 < span < 1:
        raise ValueError(
            f"{owner}={span!r} is a fraction of the sequence length, which a "
            f"stream does not know in advance; use an integer span"
        )
    return len(loess_kernel(span))


class LoessStepper:
    """MATLAB ``smooth(y, span, 'loess')`` of a series that grows at its end.

    The smoothed value of row ``u`` needs rows up to ``u + h`` (``h = (span -
    1) / 2``): it is the interior kernel of :func:`loess_kernel`, applied in
    the accumulation order of :func:`loess_smooth` (bit-identical values). The
    first ``h`` rows use MATLAB's end-point fits once ``2 h`` rows are known,
    the last ``h`` rows at :meth:`flush`, both through :func:`loess_smooth`
    itself.

    Parameters
    ----------
    span : int
        Loess span in frames (a fraction is refused: see
        :func:`check_stream_span`).
    n_tracks : int
        Columns smoothed independently.
    owner : str, default="smooth_span"
        Parameter name for error messages.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._incremental import LoessStepper
    >>> from skgesture.utils._smoothing import loess_smooth
    >>> y = np.sin(np.arange(40.0))[:, None]
    >>> st = LoessStepper(7, 1)
    >>> parts = [st.step(y[i : i + 1], np.array([i]))[1] for i in range(40)]
    >>> out = np.concatenate(parts + [st.flush(39)[1]])
    >>> bool(np.array_equal(out, loess_smooth(y, 7)))
    True
    """

    def __init__(self, span, n_tracks, owner="smooth_span"):
        self.span = check_stream_span(span, owner)
        self.kernel = loess_kernel(self.span)
        self.taps = self.kernel[1:-1].tolist()
        self.h = (self.span - 1) // 2
        self.n_tracks = n_tracks
        self.buf = RowBuffer((n_tracks,), capacity=4 * self.span + 16)
        self.n_out = 0

    def step(self, values, times):
        """Append raw rows; return ``(first, smoothed, times)`` of the rows that
        became final (``first`` is the index of the first one)."""
        self.buf.append(values, None, times)
        return self._advance()

    def _advance(self):
        h, n, lo0 = self.h, self.buf.stop, self.n_out
        parts, times = [], []
        if h == 0:
            if n > lo0:
                parts.append(self.buf.data(lo0, n).copy())
                times.append(self.buf.time(lo0, n).copy())
                self.n_out = n
        else:
            if self.n_out == 0 and n >= 2 * h:
                # MATLAB's end-point fits on the first 2h rows, as loess_smooth.
                head = loess_smooth(self.buf.data(0, 2 * h), self.span, axis=0)[:h]
                parts.append(head)
                times.append(np.full(h, self.buf.time(2 * h - 1, 2 * h)[0]))
                self.n_out = h
            lo, stop = self.n_out, n - h
            if self.n_out >= h and stop > lo:
                m = stop - lo
                window = self.buf.data(lo - h, stop + h)
                # Same accumulation order as loess_smooth (bitwise equal values).
                if m == 1 and self.n_tracks == 1:  # one new frame: Python floats
                    value = 0.0
                    for k, w in zip(self.taps, window[1:-1, 0].tolist()):
                        value += k * w
                    acc = np.array([[value]])
                else:
                    acc = np.zeros((m, self.n_tracks))
                    for k in range(1, self.span - 1):
                        acc += self.kernel[k] * window[k : k + m]
                parts.append(acc)
                times.append(self.buf.time(lo + h, stop + h).copy())
                self.n_out = stop
        # Keep h rows before the next one to smooth and span rows for the end
        # fits of flush (everything while fewer than span rows are known).
        self.buf.drop(max(0, min(self.n_out - h, n - self.span)))
        if not parts:
            return lo0, np.empty((0, self.n_tracks)), np.zeros(0, dtype=np.int64)
        return lo0, np.concatenate(parts), np.concatenate(times)

    def flush(self, now):
        """The remaining rows, with the end-point fits; their time is ``now``."""
        n, lo = self.buf.stop, self.n_out
        if n <= lo:
            return lo, np.empty((0, self.n_tracks)), np.zeros(0, dtype=np.int64)
        first = self.buf.start
        smoothed = loess_smooth(self.buf.data(first, n), self.span, axis=0)
        self.n_out = n
        return lo, smoothed[lo - first :], np.full(n - lo, now, dtype=np.int64)

    def held(self):
        """Rows currently held."""
        return len(self.buf)


# -- framewise network scores ----------------------------------------------------


def _module_ops(module):
    """The layers of a sequential torch module as plain torch functions.

    ``nn.Linear``, ``nn.Tanh``, ``nn.ReLU`` and ``nn.Sigmoid`` become the
    functions their ``forward`` calls (the same kernels, hence the same
    numbers), without the module-call machinery that costs more than the
    arithmetic of one row; any other layer is called as a module. ``None``
    when the module is not a plain ``Sequential`` network.
    """
    import functools

    import torch
    from torch import nn

    net = getattr(module, "net", None)
    if not isinstance(net, nn.Sequential) or type(module).forward is not getattr(
        _mlp_module_type(), "forward", None
    ):
        return None
    ops = []
    for layer in net:
        if type(layer) is nn.Linear:
            # Detached: no autograd bookkeeping, without an inference-mode block.
            weight = layer.weight.detach()
            bias = None if layer.bias is None else layer.bias.detach()
            ops.append(functools.partial(torch.nn.functional.linear,
                                         weight=weight, bias=bias))  # fmt: skip
        elif type(layer) is nn.Tanh:
            ops.append(torch.tanh)
        elif type(layer) is nn.ReLU:
            ops.append(torch.relu)
        elif type(layer) is nn.Sigmoid:
            ops.append(torch.sigmoid)
        else:
            ops.append(layer)
    return ops


def _mlp_module_type():
    from skgesture._networks import MLPModule

    return MLPModule


def fast_proba(estimator):
    """``predict_proba`` of a fitted 2-D classifier, as a fast callable.

    For a :class:`~skgesture.TorchMLPClassifier` on the CPU the network's layers
    are called directly: the same float32 forward pass and output map as
    ``predict_proba`` (hence the same numbers), without its per-call input
    validation and module-call machinery, which cost more than the forward
    pass of one row. Any other classifier's own ``predict_proba`` is returned.
    """
    import torch

    from skgesture._mlp import TorchMLPClassifier

    if not isinstance(estimator, TorchMLPClassifier):
        return estimator.predict_proba
    module = estimator.net_.module_
    if next(module.parameters()).device.type != "cpu":
        return estimator.predict_proba
    module.eval()
    ops = _module_ops(module)
    binary = len(estimator.classes_) == 2
    if ops is None:
        ops = [module]
        context = torch.inference_mode
    else:
        import contextlib

        context = contextlib.nullcontext  # detached weights: nothing to record

    def proba(X):
        with context():
            x = torch.from_numpy(np.ascontiguousarray(X, dtype=np.float32))
            for op in ops:
                x = op(x)
            if binary:
                p = torch.sigmoid(x).numpy()[:, 0].astype(np.float64)
                out = np.empty((len(p), 2))
                out[:, 1] = p
                np.subtract(1.0, p, out=out[:, 0])
                return out
            return torch.softmax(x, dim=1).numpy().astype(np.float64)

    return proba


# -- the descriptor, one frame at a time -----------------------------------------


def _dot3(u, v):
    """Dot product over axis 1 (coordinates), summed ``(x + z) + y`` as offline."""
    out = u[:, 0] * v[:, 0]
    out += u[:, 2] * v[:, 2]
    out += u[:, 1] * v[:, 1]
    return out


def _unit3(v):
    n = np.sqrt(_dot3(v, v))
    ok = n > MIN_NORM
    np.maximum(n, MIN_NORM, out=n)
    return v / n[:, None], ok


def _pdot(u, v):
    return (u[0] * v[0] + u[2] * v[2]) + u[1] * v[1]


def _pcross(u, v):
    return (
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    )


def _smallest_eigvec(a, b, c, d, e, f):
    """The closed form of ``skgesture._descriptor._smallest_eigvec`` for one
    matrix, in Python floats (same operations, same order)."""
    q = (a + b + c) / 3.0
    p1 = d * d + e * e + f * f
    p2 = (a - q) ** 2 + (b - q) ** 2 + (c - q) ** 2 + 2.0 * p1
    p = math.sqrt(p2 / 6.0)
    ps = p if p > 0 else 1.0
    B00, B11, B22 = (a - q) / ps, (b - q) / ps, (c - q) / ps
    B01, B12, B02 = d / ps, e / ps, f / ps
    detB = (
        B00 * (B11 * B22 - B12 * B12)
        - B01 * (B01 * B22 - B12 * B02)
        + B02 * (B01 * B12 - B11 * B02)
    )
    phi = math.acos(min(max(detB / 2.0, -1.0), 1.0)) / 3.0
    lam = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    r0, r1, r2 = (a - lam, d, f), (d, b - lam, e), (f, e, c - lam)
    cands = (_pcross(r0, r1), _pcross(r0, r2), _pcross(r1, r2))
    norms = [math.sqrt(_pdot(v, v)) for v in cands]
    n0, n1, n2 = norms
    k = 0 if (n0 >= n1 and n0 >= n2) else (1 if n1 >= n2 else 2)
    v, n = cands[k], norms[k]
    ok = n > MIN_NORM * max(p, MIN_NORM) ** 2
    if n <= 0:
        n = 1.0
    return (v[0] / n, v[1] / n, v[2] / n), ok


def _body_axes(cov, up, lr):
    """``(u_x, u_z, ok)`` of one frame (docs/method.md §3.8), in Python floats."""
    u_z, ok_n = _smallest_eigvec(*cov)
    s = _pcross(lr, up)
    ok_s = math.sqrt(_pdot(s, s)) > MIN_NORM
    if _pdot(u_z, s) < 0:
        u_z = (-u_z[0], -u_z[1], -u_z[2])
    dz = _pdot(up, u_z)
    y = (up[0] - dz * u_z[0], up[1] - dz * u_z[1], up[2] - dz * u_z[2])
    ny = math.sqrt(_pdot(y, y))
    ok_y = ny > MIN_NORM
    ny = max(ny, MIN_NORM)
    u_y = (y[0] / ny, y[1] / ny, y[2] / ny)
    return _pcross(u_y, u_z), u_z, ok_n and ok_y and ok_s


def _link_levels(links):
    """Group tree-ordered links ``(a, b)`` into levels whose parents are final."""
    depth = {}
    levels = []
    for k, (a, b) in enumerate(np.asarray(links).tolist()):
        d = depth.get(a, -1) + 1
        depth[b] = d
        while len(levels) <= d:
            levels.append([])
        levels[d].append((a, b, k))
    return [tuple(np.array(col, dtype=np.intp) for col in zip(*lev)) for lev in levels]


class FrameDescriber:
    """The per-frame computation of a fitted :class:`~skgesture.PoseDescriptor`.

    ``positions`` gives the root-centred, link-normalised kept joints of raw
    frames; ``smooth`` the temporal Gaussian of one frame from its neighbours;
    ``rows`` the standardised descriptor of frames from their smoothed
    neighbourhood. Arrays are ``(n, 3, K)`` (frames, coordinates, joints), so
    one call handles one frame or a block. The arithmetic is that of
    ``PoseDescriptor._describe`` in the same order; ``tests/test_streaming.py``
    checks the two agree (to 1e-9, bit for bit in practice).
    """

    def __init__(self, desc):
        from skgesture._descriptor import (
            DERIVATIVE_REACH,
            GAUSSIAN_SIZE,
            gaussian_kernel,
        )
        from skgesture.layouts import KINECT_V1

        spec = desc._spec()
        self.used = spec["used"]
        self.root = KINECT_V1.index(KINECT_V1.root)
        self.normalise = bool(desc.link_normalisation)
        self.direction = desc.link_direction
        self.lengths = np.asarray(desc.link_lengths_, dtype=np.float64)
        self.levels = _link_levels(spec["used_links"])
        links = np.asarray(spec["used_links"]).reshape(-1, 2)
        self.link_a, self.link_b = links[:, 0], links[:, 1]
        self.keep = np.asarray(spec["used_keep"])
        self.K = len(self.keep)
        self.kernel = gaussian_kernel(desc.sigma) if desc.sigma > 0 else None
        self.g = (GAUSSIAN_SIZE - 1) // 2 if self.kernel is not None else 0
        self.reach = self.g + DERIVATIVE_REACH  # the descriptor's look-ahead
        self.border = desc.border
        tri = np.asarray(spec["triples"]).reshape(-1, 3)
        self.ti, self.tj, self.tk = tri[:, 0], tri[:, 1], tri[:, 2]
        self.tri_ik = np.concatenate([self.ti, self.tk])
        self.tri_jj = np.concatenate([self.tj, self.tj])
        nt, K = len(tri), len(spec["keep"])
        self.fallback = np.r_[np.full(nt, DEGENERATE_INCLINATION), np.zeros(nt + K)]
        self.torso = np.asarray(spec["torso"])
        self.left_right = list(spec["left_right"])
        self.spine = list(spec["spine"])
        pairs = np.asarray(spec["joints"].pairs, dtype=np.intp).reshape(-1, 2)
        self.pa, self.pb = pairs[:, 0], pairs[:, 1]
        self.spine_scale = desc.distance_scale == "spine"
        self.mean = np.asarray(desc.mean_, dtype=np.float64)
        self.scale = np.asarray(desc.scale_, dtype=np.float64)
        self.n_features = len(self.mean)

    def positions(self, frames):
        """Centred, link-normalised kept joints ``(n, 3, K)`` of filled frames."""
        q = np.ascontiguousarray(frames[:, self.used].transpose(0, 2, 1))
        q -= frames[:, self.root, :, None]
        if self.normalise:
            if self.direction == "original":
                v = q[:, :, self.link_b] - q[:, :, self.link_a]
                v *= self._scales(v, self.lengths)[:, None, :]
                for a, b, k in self.levels:
                    q[:, :, b] = q[:, :, a] + v[:, :, k]
            else:
                for a, b, k in self.levels:
                    w = q[:, :, b] - q[:, :, a]
                    w *= self._scales(w, self.lengths[k])[:, None, :]
                    q[:, :, b] = q[:, :, a] + w
        return np.ascontiguousarray(q[:, :, self.keep])

    @staticmethod
    def _scales(v, lengths):
        norm = np.sqrt(_dot3(v, v))
        norm[norm <= 0] = np.inf
        return lengths / norm

    def smooth(self, window):
        """Gaussian of the middle frames: ``window`` is ``(n + 2g, 3, K)``."""
        if self.kernel is None:
            return window.copy()
        n = len(window) - 2 * self.g
        out = window[0:n] * self.kernel[0]
        for m in range(1, len(self.kernel)):
            out += window[m : m + n] * self.kernel[m]
        return out

    def rows(self, S, basis):
        """Standardised descriptors of the middle frames of ``S`` ``(n + 4, 3, K)``.

        ``basis`` is ``[u_x, u_z, found]`` of the last frame with a well-defined
        body frame (camera axes and False at the start); it is updated.
        """
        n = len(S) - 4
        S0 = S[2 : 2 + n]
        vel = S[3 : 3 + n] - S[1 : 1 + n]
        acc = S[4 : 4 + n] + S[0:n]
        acc -= 2.0 * S0
        u_x, u_z = self._axes(S0, basis)
        nt, K = len(self.ti), self.K
        t2, t3 = 2 * nt, 3 * nt
        # Bones p_i - p_j and p_k - p_j of every triple, and the joints, made
        # unit in one pass; then the projections of docs/method.md §3.9-3.11.
        V = np.empty((n, 3, t2 + K))
        np.subtract(S0[:, :, self.tri_ik], S0[:, :, self.tri_jj], out=V[:, :, :t2])
        V[:, :, t2:] = S0
        U, ok = _unit3(V)
        a, b2 = U[:, :, :nt], V[:, :, nt:t2]
        # One pass for the dot products (a, c), (b2, a), (a, u_x), (pos, u_z).
        X = np.empty((n, 3, t3 + K))
        Y = np.empty_like(X)
        X[:, :, :nt] = a
        X[:, :, nt:t2] = b2
        X[:, :, t2:t3] = a
        X[:, :, t3:] = U[:, :, t2:]
        Y[:, :, :nt] = U[:, :, nt:t2]
        Y[:, :, nt:t2] = a
        Y[:, :, t2:t3] = u_x[:, :, None]
        Y[:, :, t3:] = u_z[:, :, None]
        dots = _dot3(X, Y)
        # Projections onto the plane normal to the first bone.
        W = np.empty((n, 3, t2))
        np.subtract(b2, dots[:, None, nt:t2] * a, out=W[:, :, :nt])
        np.subtract(u_x[:, :, None], dots[:, None, t2:t3] * a, out=W[:, :, nt:])
        W, ok_w = _unit3(W)
        cos = np.empty((n, t2 + K))
        cos[:, :nt] = dots[:, :nt]
        cos[:, nt:t2] = _dot3(W[:, :, :nt], W[:, :, nt:])
        cos[:, t2:] = dots[:, t3:]
        ok_a = ok[:, :nt]
        good = np.empty((n, t2 + K), dtype=bool)
        np.logical_and(ok_a, ok[:, nt:t2], out=good[:, :nt])
        np.logical_and(ok_a, ok_w[:, :nt], out=good[:, nt:t2])
        good[:, nt:t2] &= ok_w[:, nt:]
        good[:, t2:] = ok[:, t2:]
        np.maximum(cos, -1.0, out=cos)
        np.minimum(cos, 1.0, out=cos)
        angles = np.arccos(cos, out=cos)
        if not good.all():
            np.copyto(angles, self.fallback, where=~good)
        diff = S0[:, :, self.pb] - S0[:, :, self.pa]
        dist = diff[:, 0] * diff[:, 0]
        dist += diff[:, 1] * diff[:, 1]
        dist += diff[:, 2] * diff[:, 2]
        np.sqrt(dist, out=dist)
        if self.spine_scale:
            lo, hi = self.spine
            d = S0[:, :, hi] - S0[:, :, lo]
            sp = np.sqrt((d[:, 0] * d[:, 0] + d[:, 2] * d[:, 2]) + d[:, 1] * d[:, 1])
            sp[~(sp > MIN_NORM)] = 1.0
            dist /= sp[:, None]
        K3 = 3 * self.K
        out = np.empty((n, self.n_features))
        out[:, 0:K3] = S0.transpose(0, 2, 1).reshape(n, K3)
        out[:, K3 : 2 * K3] = vel.transpose(0, 2, 1).reshape(n, K3)
        out[:, 2 * K3 : 3 * K3] = acc.transpose(0, 2, 1).reshape(n, K3)
        lo = 3 * K3 + 2 * nt + K
        out[:, 3 * K3 : lo] = angles
        out[:, lo:] = dist
        out -= self.mean
        out /= self.scale
        return out

    def _axes(self, S0, basis):
        """Body axes of every frame, degenerate frames taking the last good one."""
        n = len(S0)
        # Torso points as (3, n_torso, n), reduced over the torso axis in the
        # order of the offline code.
        pts = S0[:, :, self.torso].transpose(1, 2, 0)
        pts = pts - np.add.reduce(pts, axis=1, keepdims=True) / len(self.torso)
        cov = np.empty((6, n))
        for k, (i, j) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))):
            np.add.reduce(pts[i] * pts[j], axis=0, out=cov[k])
        cov = cov.T
        hi, lo = self.spine[1], self.spine[0]
        up = (S0[:, :, hi] - S0[:, :, lo]).tolist()
        lr = (S0[:, :, self.left_right[0]] - S0[:, :, self.left_right[1]]).tolist()
        u_x = np.empty((n, 3))
        u_z = np.empty((n, 3))
        for r, row in enumerate(cov.tolist()):
            x, z, ok = _body_axes(row, up[r], lr[r])
            if ok:
                basis[0], basis[1], basis[2] = x, z, True
            u_x[r], u_z[r] = basis[0], basis[1]
        return u_x, u_z


def check_stream_frames(desc, frames, first):
    """Validate pushed raw frames exactly as the stage's offline ``transform`` does.

    ``desc`` is the first stage: a :class:`~skgesture.PoseDescriptor` (its own
    ``_validate``) or any other stage reading raw skeletons, such as
    :class:`~skgesture.JointFeatures` (``check_skeletons``, the rule both
    share). Returns the frames as float64 ``(n, 20, 3)``; a bad frame raises a
    ``ValueError`` naming its index in the stream.
    """
    if isinstance(frames, np.ma.MaskedArray):
        frames = np.ma.filled(np.ma.asarray(frames, dtype=float), np.nan)
    try:
        if hasattr(desc, "_validate"):
            return desc._validate([frames], reset=False)[0]
        from skgesture.utils._validation import check_skeletons

        return check_skeletons([frames], estimator=desc, reset=False)[0]
    except ValueError as exc:
        msg = str(exc)
        match = re.search(r"at frame (\d+)|\(frame (\d+)\)", msg)
        k = int(next(g for g in match.groups() if g is not None)) if match else 0
        msg = re.sub(r"^X\[0\] ", "", msg)
        raise ValueError(f"frame {first + k} of the stream is invalid: {msg}") from None


class DescriptorStream:
    """State of :meth:`PoseDescriptor.stream_step` for one stream.

    Untracked frames (all zeros or a NaN) are held (the last tracked frame
    repeats, as ``fill="hold"``) and masked (rest). Untracked frames at the
    start of the stream wait for the first tracked frame and become copies of
    it, as offline filling does; only the last ``max_backfill`` of them wait,
    earlier ones are handed on at once as masked all-zero rows (the descriptor
    of an untracked sequence).
    """

    def __init__(self, desc, max_backfill=DEFAULT_MAX_BACKFILL):
        from skgesture._descriptor import _compiled_kernel

        self.desc = desc
        self.fd = FrameDescriber(desc)
        self.a = self.fd.reach
        # With the compiled kernel the descriptor's own batch code is cheapest
        # on the few frames a row needs (tail mode); without it, the per-frame
        # arithmetic of FrameDescriber is (the batch numpy code costs about as
        # much for 9 frames as for 4,000).
        self.tail = _compiled_kernel() is not None
        self.spec = desc._spec() if self.tail else None
        if self.tail and not _WARM:
            # Load the compiled kernel now, not on the first pushed frame.
            still = np.random.RandomState(0).normal(size=(2 * self.a + 1, 20, 3))
            desc._describe_all([still], self.spec, standardize=True)
            _WARM.append(True)
        self.R = RowBuffer((20, 3), capacity=32)  # filled raw frames (tail mode)
        self.max_backfill = int(max_backfill)
        shape = (3, self.fd.K)
        self.P = RowBuffer(shape, capacity=32)  # positions, from frame p0 on
        self.S = RowBuffer(shape, capacity=32)  # smoothed positions
        self.untracked = RowBuffer((), dtype=bool, capacity=32)
        self.times = RowBuffer((), dtype=np.int64, capacity=32)
        self.n_in = 0
        self.n_out = 0
        self.p0 = None  # first frame with positions (None: no tracked frame yet)
        self.f = None  # first tracked frame
        self.last = None  # positions of the last tracked frame
        self.basis = [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0), False]

    def step(self, rows):
        """Validated raw frames in; the descriptor rows that became final out."""
        frames, times = rows.data, rows.time
        first = self.n_in
        self.n_in += len(frames)
        flat = frames.reshape(len(frames), -1)
        untracked = np.isnan(flat).any(axis=1) | ~np.any(flat != 0, axis=1)
        self.untracked.append(untracked)
        self.times.append(times)
        out = []
        if self.p0 is None:
            if untracked.all():
                out.append(self._hand_on_leading(self.n_in - self.max_backfill))
                self._trim()
                return _concat_rows(out, (self.fd.n_features,))
            k = int(np.argmax(~untracked))
            out.append(self._hand_on_leading(first + k - self.max_backfill))
            self.p0, self.f = self.n_out, first + k
            frames, untracked = frames[k:], untracked[k:]
            # The leading frames kept back become copies of the first tracked one.
            if self.tail:
                self.R.restart(self.p0)
                self.R.append(np.repeat(frames[:1], self.f - self.p0, axis=0))
                self.last = frames[0]
            else:
                P = self.fd.positions(frames[:1])
                self.P.restart(self.p0)
                self.P.append(np.repeat(P, self.f - self.p0, axis=0))
                self.last = P[0]
                self.S.restart(self.p0)
        if self.tail:  # hold the raw frames; described in _advance_tail
            if untracked.any():
                frames = frames.copy()
                tracked = ~untracked
                src = np.maximum.accumulate(
                    np.where(tracked, np.arange(len(frames)), -1)
                )
                frames[src < 0] = self.last
                frames[src >= 0] = frames[src[src >= 0]]
            self.last = frames[-1]
            self.R.append(frames)
            rows = self._advance_tail(final=False)
            self._trim()
            if not out:
                return rows
            return _concat_rows(out + [rows], (self.fd.n_features,))
        if len(frames) == 1:  # push(): one frame
            P = self.last[None] if untracked[0] else self.fd.positions(frames)
        else:
            P = np.empty((len(frames), 3, self.fd.K))
            tracked = ~untracked
            if tracked.any():
                P[tracked] = self.fd.positions(frames[tracked])
            # Hold: an untracked frame repeats the last tracked one.
            src = np.maximum.accumulate(np.where(tracked, np.arange(len(frames)), -1))
            P[src < 0] = self.last
            P[src >= 0] = P[src[src >= 0]]
        self.last = P[-1]
        self.P.append(P)
        rows = self._advance(final=False)
        self._trim()
        return rows if not out else _concat_rows(out + [rows], (self.fd.n_features,))

    def flush(self):
        """The last rows, with the offline end padding."""
        if self.p0 is None:
            return self._hand_on_leading(self.n_in)
        return self._advance_tail(final=True) if self.tail else self._advance(True)

    def _advance_tail(self, final):
        """Tail mode: the rows that became final, by the descriptor's batch code
        on the frames they need (the sequence's start and end padding where the
        slice reaches them); bit for bit the rows of ``transform``.

        A degenerate torso takes the body axes of the last good frame within
        the ``a`` frames before it (offline: any earlier frame).
        """
        R, a, lo = self.R, self.a, self.n_out
        r_stop = R.stop if final else R.stop - a
        if r_stop <= lo:
            return Rows.empty((self.fd.n_features,))
        first = max(self.p0, lo - a)
        seq = R.data(first, R.stop)
        D = self.desc._describe_all([seq], self.spec, standardize=True)[0]
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
            return Rows.empty((self.fd.n_features,))
        self.n_out = until
        n = until - lo
        return Rows(
            np.zeros((n, self.fd.n_features)),
            np.ones(n, dtype=bool),
            np.full(n, self._now(), dtype=np.int64),
        )

    def _p_at(self, t):
        """Positions of frame ``t``, with the offline border padding beyond the
        frames known (at the end: only called by flush)."""
        p0, stop = self.p0, self.P.stop
        if p0 <= t < stop:
            return self.P.data(t, t + 1)[0]
        border = self.fd.border
        if border == "replicate" or (t < p0 and p0 > 0):
            # Copies of the first tracked frame stand before p0 when earlier
            # frames were handed on as rest.
            edge = p0 if t < p0 else stop - 1
            return self.P.data(edge, edge + 1)[0]
        if border == "zero":
            return np.zeros((3, self.fd.K))
        length = stop - p0  # symmetric, as np.pad
        u = (t - p0) % (2 * length)
        u = u if u < length else 2 * length - 1 - u
        return self.P.data(p0 + u, p0 + u + 1)[0]

    def _p_window(self, lo, hi):
        if lo >= self.p0 and hi <= self.P.stop:
            return self.P.data(lo, hi)
        return np.stack([self._p_at(t) for t in range(lo, hi)])

    def _advance(self, final):
        """Smooth what can be smoothed, describe what can be described."""
        g, S = self.fd.g, self.S
        # S_j needs P_(j + g); at the end of the stream, the padding.
        s_stop = self.P.stop if final else self.P.stop - g
        if s_stop > S.stop:
            S.append(self.fd.smooth(self._p_window(S.stop - g, s_stop + g)))
        # Row j needs S_(j - 2) .. S_(j + 2), replicated beyond the ends.
        r_stop = S.stop if final else S.stop - 2
        lo = self.n_out
        if r_stop <= lo:
            return Rows.empty((self.fd.n_features,))
        if lo - 2 >= self.p0 and r_stop + 2 <= S.stop:
            Sw = S.data(lo - 2, r_stop + 2)
        else:
            idx = np.clip(np.arange(lo - 2, r_stop + 2), self.p0, S.stop - 1)
            Sw = S.data(idx[0], idx[-1] + 1)[idx - idx[0]]
        data = self.fd.rows(Sw, self.basis)
        mask = self.untracked.data(lo, r_stop).copy()
        if final:
            time = np.full(r_stop - lo, self._now(), dtype=np.int64)
        elif lo + self.a >= self.f:
            # Row j is final with frame j + a.
            time = self.times.data(lo + self.a, r_stop + self.a).copy()
        else:
            # The first tracked frame completed the rows before it.
            done = np.maximum(np.arange(lo, r_stop) + self.a, self.f)
            time = self.times.data(done[0], done[-1] + 1)[done - done[0]].copy()
        self.n_out = r_stop
        return Rows(data, mask, time)

    def _trim(self):
        if self.p0 is not None and self.tail:
            self.R.drop(self.n_out - self.a)
        elif self.p0 is not None:
            self.P.drop(self.S.stop - self.fd.g)
            self.S.drop(self.n_out - 2)
        self.untracked.drop(self.n_out)
        self.times.drop(min(self.n_out, self.n_in - 1))

    def held(self):
        """Rows held by the buffers."""
        if self.tail:
            return {"frames": len(self.R)}
        return {"positions": len(self.P), "smoothed": len(self.S)}


# -- segmenter: framewise score, loess, threshold, minimum length ----------------


class SegmenterStream:
    """State of :meth:`ActivitySegmenter.stream_step` for one stream.

    Scores every descriptor row, smooths the score track with the causal
    loess (:class:`LoessStepper`), thresholds it and keeps the runs of active
    frames of at least ``min_length`` frames (``remove_short_runs``). An
    active row is handed on once its run reaches ``min_length`` frames, a rest
    row at once; the rows are the descriptors, masked where at rest.
    Untracked (masked) rows are rest.
    """

    def __init__(self, seg):
        self.proba = fast_proba(seg.estimator_)
        self.column = list(seg.estimator_.classes_).index(1)
        self.smoother = LoessStepper(
            seg.smooth_span, 1, owner="ActivitySegmenter.smooth_span"
        )
        self.threshold = seg.threshold
        self.min_length = seg.min_length
        self.rows = None  # descriptor rows not yet handed on
        self.n_out = 0
        self.run_start = None  # first row of the current run of active rows
        self.last_time = 0

    def step(self, rows):
        if self.rows is None:
            self.rows = RowBuffer(rows.data.shape[1:], capacity=64)
        self.rows.append(rows.data, rows.mask, rows.time)
        self.last_time = int(rows.time[-1])
        score = self.proba(rows.data)[:, self.column]
        lo, smoothed, times = self.smoother.step(score[:, None], rows.time)
        return self._decide(lo, smoothed[:, 0], times)

    def flush(self):
        if self.rows is None:
            return None
        lo, smoothed, times = self.smoother.flush(self.last_time)
        out = self._decide(lo, smoothed[:, 0], times)
        # A run still shorter than min_length at the end is rest.
        tail = self._hand_on(self.rows.stop, False, self.last_time)
        return _concat_rows([out, tail], self.rows._data.shape[1:])

    def _decide(self, lo, smoothed, times):
        untracked = self.rows.mask(lo, lo + len(smoothed))
        active = (smoothed > self.threshold) & ~untracked
        out = []
        for i, on in enumerate(active.tolist()):
            u = lo + i
            if on:
                if self.run_start is None:
                    self.run_start = u
                if u + 1 - self.run_start >= self.min_length:
                    out.append(self._hand_on(u + 1, True, times[i]))
            else:
                # A run shorter than min_length is rest, with this row.
                self.run_start = None
                out.append(self._hand_on(u + 1, False, times[i]))
        return _concat_rows(out, self.rows._data.shape[1:])

    def _hand_on(self, stop, active, time):
        lo = self.n_out
        if stop <= lo:
            return Rows.empty(self.rows._data.shape[1:])
        block = self.rows.rows(lo, stop)
        block.mask = np.full(stop - lo, not active)
        block.time = np.full(stop - lo, time, dtype=np.int64)
        self.n_out = stop
        self.rows.drop(stop)
        return block

    def held(self):
        return {"scores": self.smoother.held(), "pending": len(self.rows or ())}


# -- windows and the multi-scale classifier: periods, windows, decision rules --------


class WindowStream:
    """State of :meth:`DynamicPoseWindow.stream_step`: the descriptor rows, as
    lazy windows.

    A window centred at frame ``u`` needs the descriptors up to ``u + hw``,
    and the classifier needs to know whether frame ``u + hw`` is still in the
    period before it scores that window. So in a stream the windows are built
    where they are used: this stage hands the descriptor rows on at once,
    tagged with its ``steps`` and ``n_poses`` (``rows.info["windows"]``), and
    :class:`MultiScaleStream` builds the windows of the centres it scores with
    :func:`~skgesture._windows.dynamic_poses`, the function of the offline
    ``transform``. Dense windows of every frame are never made (the classifier
    reads one window every ``stride`` frames of a period).
    """

    def __init__(self, windows):
        from skgesture._windows import check_steps

        self.layout = (check_steps(windows.steps, windows.n_poses), windows.n_poses)

    def step(self, rows):
        rows.info = {**(rows.info or {}), "windows": self.layout}
        return rows

    def flush(self):
        return None

    def held(self):
        return {}


class MultiScaleStream:
    """State of :meth:`MultiScaleClassifier.stream_step` for one stream.

    Periods of activity are the runs of unmasked rows. While a period is open,
    the window centred at ``c`` (stride ``stride`` from its start + ``hw``) is
    built and scored as soon as row ``c + hw`` is known to be in the period. A
    period is decided when it closes (at the first masked row) with the
    offline rule (:meth:`MultiScaleClassifier._period_segments`: the paper's
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

    def __init__(self, clf, max_period=DEFAULT_MAX_PERIOD, early_decision=False):
        steps = clf._check_steps()
        self.clf = clf
        self.steps = steps
        self.n_poses = clf.n_poses
        self.hw = max(steps) * (clf.n_poses - 1) // 2
        self.stride = clf.stride
        self.min_windows = clf.min_windows
        # A period shorter than this has fewer than min_windows windows and is
        # resized (docs/method.md §5.3, period_windows).
        self.n_resize = 2 * self.hw + 1 + self.stride * (self.min_windows - 1)
        self.fusion = clf._fusion_weights(len(steps))
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
        layout = (rows.info or {}).get("windows")
        if rows.data.ndim != 2 or layout is None:
            raise TypeError(
                "MultiScaleClassifier streams after a DynamicPoseWindow stage, whose "
                "stream step hands on the descriptor rows as lazy windows; got rows "
                f"of shape {rows.data.shape[1:]}"
            )
        if layout != (self.steps, self.n_poses):
            raise ValueError(
                f"DynamicPoseWindow(steps={layout[0]}, n_poses={layout[1]}) does not "
                f"match MultiScaleClassifier(steps={self.steps}, n_poses="
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

    def _fused(self, wins):
        """Fused class scores of windows ``(n, n_scales, width)``, as offline."""
        return sum(
            wk * proba(wins[:, k])
            for k, (wk, proba) in enumerate(zip(self.fusion, self.probas))
        )

    def _score_windows(self, u):
        """Score the windows whose frames are all known to be in the period."""
        from skgesture._windows import dynamic_poses

        hw, stride = self.hw, self.stride
        last = u - hw  # largest centre whose window ends inside the period
        if self.next_centre > last:
            return
        centres = np.arange(self.next_centre, last + 1, stride)
        D = self.rows.data(centres[0] - hw, centres[-1] + hw + 1)
        wins = dynamic_poses(D, self.steps, self.n_poses, centres - centres[0] + hw)
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
        return self.clf._period_segments(
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
        from skgesture._multiscale import period_windows
        from skgesture._windows import dynamic_poses

        length = end - self.start
        resized = False
        if length >= self.n_resize:
            scores, centres = self.scores, self.centres
        else:
            # Too short for min_windows windows: resized (docs/method.md §5.3).
            W = dynamic_poses(self.rows.data(self.start, end), self.steps, self.n_poses)
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


# -- taggers: per-frame class probabilities, loess, minimum run ---------------------


class MeanStepper:
    """``smooth_proba(..., smoothing="mean")`` of a series that grows at its end.

    The centred moving average of ``scipy.ndimage.uniform_filter1d`` (size
    ``int(span)``, edges replicated), computed by scipy's own recurrence (a
    running sum, one value in and one out per row, divided by the size), so
    the values equal the offline ones. The value of row ``u`` needs rows up
    to ``u + h`` (``h = size - size // 2 - 1``); the last rows come at
    :meth:`flush`, with the last row replicated. Same interface as
    :class:`LoessStepper`.

    Parameters
    ----------
    span : int or float
        Window in frames (``int(span)``; 1 or less: no smoothing).
    n_tracks : int
        Columns smoothed independently.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.ndimage import uniform_filter1d
    >>> from skgesture._incremental import MeanStepper
    >>> y = np.sin(np.arange(30.0))[:, None]
    >>> st = MeanStepper(5, 1)
    >>> parts = [st.step(y[i : i + 1], np.array([i]))[1] for i in range(30)]
    >>> out = np.concatenate(parts + [st.flush(29)[1]])
    >>> ref = uniform_filter1d(y, 5, axis=0, mode="nearest")
    >>> bool(np.allclose(out, ref, rtol=0, atol=1e-12))
    True
    """

    def __init__(self, span, n_tracks):
        self.size = max(int(span), 1)
        self.left = self.size // 2
        self.h = self.size - self.left - 1
        self.n_tracks = n_tracks
        self.buf = RowBuffer((n_tracks,), capacity=2 * self.size + 16)
        self.n_out = 0
        self.total = None  # running sum of the current window

    def _ext(self, j, stop):
        """Row ``j - left`` of the series, end rows replicated (``"nearest"``)."""
        k = min(max(j - self.left, 0), stop - 1)
        return self.buf.data(k, k + 1)[0]

    def step(self, values, times):
        """Append raw rows; return ``(first, smoothed, times)`` of the final ones."""
        self.buf.append(values, None, times)
        return self._advance(self.buf.stop - self.h, self.buf.stop, final=False)

    def _advance(self, stop, n, final, now=None):
        lo0 = self.n_out
        if self.size == 1:
            out = self.buf.data(lo0, n).copy()
            times = self.buf.time(lo0, n).copy()
            self.n_out = n
            self.buf.drop(n)
            return lo0, out, times
        rows, times = [], []
        size = self.size
        for u in range(lo0, stop):
            if u == 0:
                total = np.zeros(self.n_tracks)
                for j in range(size):
                    total += self._ext(j, n)
                self.total = total
            else:
                self.total = self.total + (
                    self._ext(u - 1 + size, n) - self._ext(u - 1, n)
                )
            rows.append(self.total / size)
            if final:
                times.append(now)
            else:
                last = min(u + self.h, n - 1)
                times.append(self.buf.time(last, last + 1)[0])
            self.n_out = u + 1
        self.buf.drop(max(self.n_out - 1 - self.left, 0))
        if not rows:
            return lo0, np.empty((0, self.n_tracks)), np.zeros(0, dtype=np.int64)
        return lo0, np.array(rows), np.asarray(times, dtype=np.int64)

    def flush(self, now):
        """The remaining rows (the last row replicated); their time is ``now``."""
        n = self.buf.stop
        return self._advance(n, n, final=True, now=now)

    def held(self):
        """Rows currently held."""
        return len(self.buf)


def make_smoother(smoothing, span, n_tracks, owner="smooth_span"):
    """The stepper of ``smooth_proba(proba, span, smoothing)`` for a stream.

    Parameters
    ----------
    smoothing : {"loess", "mean", "none"}
        As :func:`skgesture._decoding.smooth_proba`.
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

    The offline rules of :func:`skgesture._decoding.decode` (arg-max, rest on
    masked rows, rest gaps of at most ``max_gap`` frames between two runs of
    one class filled, gesture runs shorter than ``min_run`` set to rest) and
    the segments and confidences of
    :func:`skgesture._decoding.segments_with_confidence`, applied by calling
    those functions on stretches of rows that no later row can change: the
    stream is cut where the labels before and after cannot interact, i.e.
    between two different gesture labels, before a gesture whose preceding
    rest gap cannot be filled, and inside a rest run longer than ``max_gap``.
    A run of one gesture is therefore emitted once ``max_gap + 1`` rest rows
    follow it (its first rest row for ``max_gap=0``) or another gesture
    starts; the segments equal the offline ones on the whole stream.

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

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._decoding import decode
    >>> from skgesture._incremental import LabelRuns
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

    def __init__(self, classes, min_run, max_gap=0, max_run=None):
        self.classes = np.asarray(classes)
        self.min_run = int(min_run)
        self.max_gap = int(max_gap)
        self.max_run = None if max_run is None else max(int(max_run), 1)
        n = len(self.classes)
        self.smoothed = RowBuffer((n,), capacity=64)
        self.raw = RowBuffer((n,), capacity=64)
        self.rest = RowBuffer((), dtype=bool, capacity=64)
        self.cs = 0  # first row of the stretch not yet decided
        self.n = 0  # rows fed
        self.gestures = 0  # gesture labels in the stretch
        self.label = 0  # label of the current run
        self.start = 0  # its first row
        self.before = 0  # label of the run before it

    def feed(self, lo, smoothed, raw, rest, times):
        """Rows ``lo ..`` in (smoothed and raw scores, rest flags, times); the
        segments of the stretches they close out."""
        smoothed = np.asarray(smoothed)
        rest = np.asarray(rest, dtype=bool)
        if lo != self.n:
            raise IndexError(f"rows fed out of order: {lo}, expected {self.n}")
        labels = self.classes[np.argmax(smoothed, axis=1)]
        labels[rest] = 0
        self.smoothed.append(smoothed)
        self.raw.append(raw, rest)
        self.rest.append(rest)
        out = []
        gap = self.max_gap
        for i, lab in enumerate(labels.tolist()):
            j = lo + i
            self.n = j + 1
            if lab != self.label:
                if lab != 0 and (
                    self.label != 0  # between two different gestures
                    or self.start <= self.cs  # after a rest run already cut
                    or j - self.start > gap  # after a long rest gap
                    or self.before != lab  # between two different classes
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
        self._cut(stop, int(now), out)
        self.label, self.start, self.before = 0, stop, 0
        return out

    def _cut(self, b, now, out):
        """Decide rows ``cs .. b - 1`` with the offline functions."""
        from skgesture._decoding import decode, segments_with_confidence

        cs = self.cs
        if b <= cs:
            return
        if self.gestures:
            rest = self.rest.data(cs, b)
            labels = decode(
                self.smoothed.data(cs, b),
                self.classes,
                smoothing="none",  # the rows are already smoothed
                min_run=self.min_run,
                max_gap=self.max_gap,
                untracked=rest,
            )
            for cls, s, e, conf in segments_with_confidence(
                labels, self.raw.data(cs, b), self.classes
            ).tolist():
                out.append(StreamSegment(int(cls), cs + int(s), cs + int(e), conf, now))
        self.cs = b
        self.gestures = 0
        for buf in (self.smoothed, self.raw, self.rest):
            buf.drop(b)

    def held(self):
        """Rows of the stretch not yet decided."""
        return self.n - self.cs


class TaggerStream:
    """State of :meth:`BiLSTMTagger.stream_step` for one stream.

    The network runs on every completed chunk of ``window`` frames, exactly
    the chunks of offline ``predict_proba`` (non-overlapping from the start of
    the stream; with ``overlap=True`` the half-overlapping ones, and the final
    irregular chunk at the end). Each class track is smoothed by the causal
    loess, the label is the arg-max, and each run of one gesture label of at
    least ``min_run`` frames is emitted when the label changes
    (:class:`LabelRuns`).
    """

    def __init__(self, tagger):
        from skgesture._bilstm import _chunks

        self.tagger = tagger
        self.chunks = _chunks
        self.window = int(tagger.window)
        self.overlap = bool(tagger.overlap) and self.window > 1
        self.chunk_step = max(self.window // 2, 1) if self.overlap else self.window
        self.classes = np.asarray(tagger.classes_)
        n = len(self.classes)
        self.smoother = LoessStepper(
            tagger.smooth_span, n, owner="BiLSTMTagger.smooth_span"
        )
        self.runs = LabelRuns(
            self.classes, tagger.min_run, max_gap=getattr(tagger, "max_gap", 0)
        )
        self.D = None  # descriptor rows of the chunks to come
        self.raw = RowBuffer((n,), capacity=64)  # released probabilities
        self.sums = np.zeros((self.window + self.chunk_step, n))
        self.counts = np.zeros(self.window + self.chunk_step)
        self.base = 0  # row of sums[0]
        self.next_chunk = 0
        self.last_time = 0

    def _proba(self, lo, hi):
        return self.tagger.predict_proba([self.D.data(lo, hi)])[0]

    def step(self, rows):
        if self.D is None:
            self.D = RowBuffer(rows.data.shape[1:], capacity=64)
        self.D.append(rows.data, rows.mask, rows.time)
        self.last_time = int(rows.time[-1])
        out = []
        W, step = self.window, self.chunk_step
        while self.next_chunk + W <= self.D.stop:
            s = self.next_chunk
            proba = self._proba(s, s + W)
            i = s - self.base
            self.sums[i : i + W] += proba
            self.counts[i : i + W] += 1
            # Frames s .. s + step - 1 are covered by no later regular chunk.
            now = int(self.D.time(s + W - 1, s + W)[0])
            out += self._release(s + step, now)
            self.next_chunk += step
        # The last window rows stay for the final irregular chunk of flush.
        self.D.drop(min(self.next_chunk, self.D.stop - W))
        return out

    def _release(self, stop, now):
        """Hand the averaged probabilities of rows ``base .. stop - 1`` on."""
        n = stop - self.base
        if n <= 0:
            return []
        rows = self.sums[:n] / self.counts[:n, None]
        self.sums = np.roll(self.sums, -n, axis=0)
        self.counts = np.roll(self.counts, -n)
        self.sums[-n:] = 0.0
        self.counts[-n:] = 0
        lo = self.base
        self.base = stop
        self.raw.append(rows, self._rest(lo, stop), np.full(n, now))
        return self._smoothed(*self.smoother.step(rows, np.full(n, now)))

    def _rest(self, lo, hi):
        """Untracked rows, rest by construction (contract 2 of the data)."""
        return self.D.mask(lo, hi).copy()

    def _smoothed(self, lo, smoothed, times):
        if not len(smoothed):
            return []
        hi = lo + len(smoothed)
        raw = self.raw.data(lo, hi)
        rest = self.raw.mask(lo, hi)
        out = self.runs.feed(lo, smoothed, raw, rest, times)
        self.raw.drop(hi)
        return out

    def flush(self):
        if self.D is None:
            return []
        T = self.D.stop
        W, step = self.window, self.chunk_step
        extra = [
            (s, e) for s, e in self.chunks(T, W, self.overlap)
            if e - s < W or s % step
        ]  # fmt: skip
        for s, e in extra:
            proba = self._proba(s, e)
            # Frames already handed on (still unsmoothed) get the extra chunk too.
            done = max(min(self.base, e) - s, 0)
            if done:
                self._add_to_released(s, proba[:done])
            i = max(s - self.base, 0)
            self.sums[i : i + (e - s - done)] += proba[done:]
            self.counts[i : i + (e - s - done)] += 1
        out = self._release(T, self.last_time)
        out += self._smoothed(*self.smoother.flush(self.last_time))
        out += self.runs.end(T, self.last_time)
        return out

    def _add_to_released(self, s, proba):
        """Average an extra chunk into released rows ``s ..`` still held."""
        W, step = self.window, self.chunk_step
        for k, p in enumerate(proba):
            u = s + k
            # Regular chunks that covered u: starts in (u - W, u], multiples of step.
            count = (u // step) - (max(u - W + step, 0) // step) + 1
            for buf in (self.smoother.buf, self.raw):
                if buf.start <= u < buf.stop:
                    row = buf.data(u, u + 1)
                    row[0] = (row[0] * count + p) / (count + 1)

    def held(self):
        return {
            "descriptors": len(self.D or ()),
            "scores": self.smoother.held(),
        }


class WindowScorer:
    """Class probabilities of a frame from a window of rows around it.

    ``proba(rows) -> (len(rows), n_classes)`` is run on the rows
    ``u - lookback .. end - 1`` (clipped to the rows held) and the row of
    frame ``u`` is read off: a tagger that reads whole sequences offline (a
    TCN, any ``predict_proba``) run on a trailing window.

    Parameters
    ----------
    proba : callable
        Probabilities of a block of consecutive feature rows.
    lookback : int
        Rows before a frame that its window holds.
    """

    def __init__(self, proba, lookback):
        self.proba = proba
        self.lookback = int(lookback)

    def __call__(self, X, lo, stop, end):
        """Probabilities of rows ``lo .. stop - 1``, each from the rows up to
        ``end - 1`` (``X``: a :class:`RowBuffer`)."""
        out = []
        for u in range(lo, stop):
            a = max(u - self.lookback, X.start)
            out.append(self.proba(X.data(a, end))[u - a])
        return np.array(out, dtype=np.float64).reshape(stop - lo, -1)

    def reset(self):
        """Nothing is carried from one frame to the next."""


class RecurrentScorer:
    """Class probabilities of a frame from a bidirectional recurrent network,
    its forward states carried along the stream.

    For :class:`~skgesture._modules.RecurrentTaggerModule` (stacked
    bidirectional GRUs or LSTMs and a linear read-out): the forward direction
    of every layer is run once per frame from the state it had at the frame
    before, as over the whole recording offline (no look-back window: the
    first layer's forward outputs are the offline ones); the backward
    direction of every layer is run from the last row known (``end - 1``)
    down to the frame, from a zero state, as if the recording ended there.
    Per frame that is ``n_layers`` forward steps and ``n_layers * (end - u)``
    backward steps, instead of the whole window through both directions.

    The cells run in numpy, float32, with the module's weights and torch's
    equations (GRU gates ``r, z, n``, LSTM gates ``i, f, g, o``): a torch
    call costs about 10 µs per step and 15 µs per call on these sizes, twice
    the numpy arithmetic; the probabilities equal the module's to float32
    rounding (about 1e-6).

    Parameters
    ----------
    module : RecurrentTaggerModule
        The fitted network.
    mean, scale : ndarray
        The tagger's standardisation.
    """

    lookback = 0

    def __init__(self, module, mean, scale):
        import torch

        def numpy(t):
            return t.detach().cpu().numpy().astype(np.float32)

        module.eval()
        self.mean = mean
        self.scale = scale
        self.weights, self.lstm, self.hidden = [], [], []
        for rnn in module.layers:
            pair = []
            for suffix in ("", "_reverse"):
                w = {n: numpy(getattr(rnn, f"{n}_l0{suffix}")) for n in
                     ("weight_ih", "bias_ih", "weight_hh", "bias_hh")}  # fmt: skip
                pair.append((w["weight_ih"].T.copy(), w["bias_ih"],
                             w["weight_hh"].T.copy(), w["bias_hh"]))  # fmt: skip
            self.weights.append(pair)
            self.lstm.append(isinstance(rnn, torch.nn.LSTM))
            self.hidden.append(int(rnn.hidden_size))
        act = module.activation  # between layers (dropout: identity in eval)
        if isinstance(act, torch.nn.Identity):
            self.activation = None
        elif isinstance(act, torch.nn.LeakyReLU):
            slope = np.float32(act.negative_slope)
            self.activation = lambda h: np.where(h > 0, h, h * slope)
        else:
            self.activation = lambda h: act(torch.from_numpy(h)).numpy()
        self.head = (numpy(module.head.weight).T.copy(), numpy(module.head.bias))
        self.reset()

    def reset(self):
        """A fresh stream: zero forward states."""
        self.states = [self._zero(k) for k in range(len(self.hidden))]
        self.n_done = 0  # rows whose forward state of layers 2.. is committed
        self.first = np.empty((0, self.hidden[0]), dtype=np.float32)  # rows n_done..
        self.first_stop = 0  # rows with a first-layer forward output

    def _zero(self, k):
        z = np.zeros(self.hidden[k], dtype=np.float32)
        return (z, z) if self.lstm[k] else z

    def _run(self, k, direction, x, state):
        """Layer ``k``'s direction (0 forward, 1 backward: from the last row)
        over the rows ``x``; its outputs, in row order, and its last state."""
        w_ih, b_ih, w_hh, b_hh = self.weights[k][direction]
        gates = x @ w_ih + b_ih
        H = self.hidden[k]
        out = np.empty((len(x), H), dtype=np.float32)
        rows = range(len(x) - 1, -1, -1) if direction else range(len(x))
        if self.lstm[k]:
            h, c = state
            for t in rows:
                g = gates[t] + (h @ w_hh + b_hh)
                i, f, o = _sigmoid(g[:H]), _sigmoid(g[H : 2 * H]), _sigmoid(g[3 * H :])
                c = f * c + i * np.tanh(g[2 * H : 3 * H])
                h = o * np.tanh(c)
                out[t] = h
            return out, (h, c)
        h = state
        for t in rows:
            gh = h @ w_hh + b_hh
            rz = _sigmoid(gates[t, : 2 * H] + gh[: 2 * H])
            n = np.tanh(gates[t, 2 * H :] + rz[:H] * gh[2 * H :])
            h = n + rz[H:] * (h - n)
            out[t] = h
        return out, h

    def _standardised(self, X, lo, hi):
        return ((X.data(lo, hi) - self.mean) / self.scale).astype(np.float32)

    def __call__(self, X, lo, stop, end):
        """Probabilities of rows ``lo .. stop - 1`` (``lo`` the next row), each
        from the rows up to ``end - 1``; the forward states move to ``stop``."""
        if lo != self.n_done:
            raise IndexError(f"rows scored out of order: {lo}, expected {self.n_done}")
        if end > self.first_stop:  # the first layer's forward direction
            x = self._standardised(X, self.first_stop, end)
            out, self.states[0] = self._run(0, 0, x, self.states[0])
            self.first = np.concatenate([self.first, out])
            self.first_stop = end
        back, _ = self._run(0, 1, self._standardised(X, lo, end), self._zero(0))
        h = np.concatenate([self.first[: end - lo], back], axis=1)
        m = stop - lo
        last = len(self.hidden) - 1
        for k in range(1, last + 1):
            if self.activation is not None:
                h = self.activation(h)
            ahead, self.states[k] = self._run(k, 0, h[:m], self.states[k])
            if k < last and end > stop:  # later rows, from the new state
                more, _ = self._run(k, 0, h[m:], self.states[k])
                ahead = np.concatenate([ahead, more])
            back, _ = self._run(k, 1, h, self._zero(k))
            h = np.concatenate([ahead, back if k < last else back[:m]], axis=1)
        w, b = self.head
        prob = _softmax(h[:m] @ w + b).astype(np.float64)
        self.n_done = stop
        self.first = self.first[m:]
        return prob


def _sigmoid(x):
    from scipy.special import expit  # no overflow warning for large |x|

    return expit(x)


class TemporalConvProba:
    """Class probabilities of an MS-TCN on a block of rows, in numpy.

    The arithmetic of :class:`~skgesture._modules.TemporalConvModule` (eval
    mode: dropout off) with every dilated convolution written as one matrix
    product of the three shifted copies of its input (zero padding at the
    block's ends, as ``padding=dilation``): the same float32 products, summed
    in another order, so the probabilities equal the module's to float32
    rounding. torch's dilated ``conv1d`` costs about 100 µs per call on the
    few rows of a stream's window, the product about 15 µs; a layer whose
    dilation reaches past the block reads only its centre tap.

    Parameters
    ----------
    module : TemporalConvModule
        The fitted network (CPU).
    mean, scale : ndarray
        The tagger's standardisation.
    """

    def __init__(self, module, mean, scale):
        def numpy(t):
            return t.detach().cpu().numpy().astype(np.float32)

        def pointwise(conv):  # a kernel-1 Conv1d as (in, out) weights and bias
            return numpy(conv.weight)[:, :, 0].T.copy(), numpy(conv.bias)

        self.mean = mean
        self.scale = scale
        self.stages = []
        for stage in module.stages:
            layers = []
            for layer in stage.layers:
                W = numpy(layer.conv.weight)  # (out, in, 3): taps t - d, t, t + d
                stacked = np.concatenate([W[:, :, k].T for k in range(3)], axis=0)
                d = int(layer.conv.dilation[0])
                bias = numpy(layer.conv.bias)
                layers.append((d, stacked, bias, *pointwise(layer.mix)))
            self.stages.append((pointwise(stage.inp), layers, pointwise(stage.out)))

    def __call__(self, rows):
        """``(len(rows), n_classes)`` probabilities of consecutive feature rows."""
        x = ((rows - self.mean) / self.scale).astype(np.float32)
        n = len(x)
        for s, ((w_in, b_in), layers, (w_out, b_out)) in enumerate(self.stages):
            if s:
                x = _softmax(x)  # a refinement stage reads probabilities
            h = x @ w_in + b_in
            for d, stacked, bias, w_mix, b_mix in layers:
                c = h.shape[1]
                if d >= n:  # the other taps fall in the padding
                    a = h @ stacked[c : 2 * c] + bias
                else:
                    z = np.zeros((n + 2 * d, c), dtype=np.float32)
                    z[d : d + n] = h
                    shifted = np.concatenate([z[:n], h, z[2 * d :]], axis=1)
                    a = shifted @ stacked + bias
                np.maximum(a, 0.0, out=a)
                h = h + (a @ w_mix + b_mix)
            x = h @ w_out + b_out
        return _softmax(x).astype(np.float64)


def _softmax(x):
    e = np.exp(x - x.max(axis=1, keepdims=True))
    return e / e.sum(axis=1, keepdims=True)


class VotingScorer:
    """Weighted mean of the probabilities of several scorers (a VotingTagger).

    Parameters
    ----------
    scorers : list
        :class:`WindowScorer` or :class:`RecurrentScorer` of every member.
    weights : ndarray
        Weight of every member, summing to 1.
    """

    def __init__(self, scorers, weights):
        self.scorers = list(scorers)
        self.weights = np.asarray(weights, dtype=float)
        self.lookback = max(s.lookback for s in self.scorers)

    def __call__(self, X, lo, stop, end):
        from skgesture.utils._validation import untracked_rows

        # A member's predict_proba makes an all-zero row certain rest.
        zero = untracked_rows(X.data(lo, stop))
        total = None
        for weight, scorer in zip(self.weights, self.scorers):
            p = scorer(X, lo, stop, end)
            if zero.any():
                p = p.copy()
                p[zero] = 0.0
                p[zero, 0] = 1.0
            total = weight * p if total is None else total + weight * p
        return total

    def reset(self):
        """Reset every member."""
        for scorer in self.scorers:
            scorer.reset()


class TrailingWindowStream:
    """Stream state of a tagger that sees a window of frames around each frame.

    For taggers that read whole sequences offline (a bidirectional GRU, a
    TCN): the probabilities of frame ``u`` are computed from the rows up to
    ``u + lookahead`` as soon as row ``u + lookahead`` arrives (the rows
    ``u - lookback ..`` of a window, or a recurrent network's carried state:
    :class:`WindowScorer`, :class:`RecurrentScorer`), smoothed by the stepper
    of the offline smoothing (:func:`make_smoother`) and decoded by
    :class:`LabelRuns`, which calls the offline decoding functions (masked
    rows are rest in the labels, after the smoothing). At :meth:`flush` the
    remaining frames are scored from the rows up to the last one. A stage's
    ``stream_init`` returns one; its ``stream_step`` and ``stream_flush`` call
    :meth:`step` and :meth:`flush`, and its ``stream_lookahead`` is
    :attr:`delay`,
    ``lookahead + h + max_gap + 1`` (``h`` the smoothing's look-ahead,
    ``(span - 1) // 2`` for loess).

    Parameters
    ----------
    proba : callable or scorer
        ``proba(rows) -> (len(rows), n_classes)`` class probabilities of a block
        of consecutive feature rows (the row of frame ``u`` is read off its
        window of ``lookback`` rows before it), or a scorer object such as
        :class:`RecurrentScorer` (its own ``lookback``).
    classes : ndarray
        Class of every probability column, rest (0) first.
    lookback, lookahead : int
        Frames of context before and after a frame.
    span : int
        Span of the probability smoothing.
    min_run : int
        Shortest gesture run kept.
    smoothing : {"loess", "mean", "none"}, default="loess"
        Smoothing method, as :func:`skgesture._decoding.smooth_proba`.
    max_gap : int, default=0
        Longest rest gap filled between two runs of one class.
    max_run : int or None, default=None
        Stretches of undecided rows this long are decided (see
        :class:`LabelRuns`).
    owner : str, default="smooth_span"
        Parameter name for error messages.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._incremental import TrailingWindowStream, stream_frames
    >>> def proba(rows):  # class 1 where the mean of the first feature > 0
    ...     p = (rows[:, :1].mean() > 0) * np.ones((len(rows), 1))
    ...     return np.hstack([1 - p, p])
    >>> st = TrailingWindowStream(proba, np.array([0, 1]), 3, 2, 1, 4)
    >>> x = np.r_[-np.ones(10), np.ones(8), -np.ones(10)][:, None]
    >>> segs = st.step(stream_frames(x, 0)) + st.flush()
    >>> [(s.label, s.start, s.end) for s in segs], st.delay
    ([(1, 11, 18)], 3)
    """

    def __init__(
        self,
        proba,
        classes,
        lookback,
        lookahead,
        span,
        min_run,
        *,
        smoothing="loess",
        max_gap=0,
        max_run=None,
        owner="smooth_span",
    ):
        self.scorer = (
            proba if hasattr(proba, "reset") else WindowScorer(proba, lookback)
        )
        self.scorer.reset()
        self.classes = np.asarray(classes)
        self.lookback = int(self.scorer.lookback)
        self.lookahead = int(lookahead)
        self.smoother = make_smoother(smoothing, span, len(self.classes), owner=owner)
        self.runs = LabelRuns(self.classes, min_run, max_gap=max_gap, max_run=max_run)
        self.delay = self.lookahead + self.smoother.h + int(max_gap) + 1
        self.X = None
        self.raw = RowBuffer((len(self.classes),), capacity=64)
        self.n_out = 0  # frames whose probabilities are computed
        self.last_time = 0

    def step(self, rows):
        """Feature rows in; the segments of the runs that ended out."""
        if self.X is None:
            self.X = RowBuffer(rows.data.shape[1:], capacity=64)
        self.X.append(rows.data, rows.mask, rows.time)
        self.last_time = int(rows.time[-1])
        out = []
        for u in range(self.n_out, self.X.stop - self.lookahead):
            end = u + self.lookahead + 1
            p = self.scorer(self.X, u, u + 1, end)
            out += self._scored(u, p, [int(self.X.time(end - 1, end)[0])])
        self.X.drop(self.n_out - self.lookback)
        return out

    def flush(self):
        """The remaining frames (shorter look-ahead), end-point fits, last run."""
        if self.X is None:
            return []
        out = []
        n = self.X.stop
        if n > self.n_out:
            p = self.scorer(self.X, self.n_out, n, n)
            out += self._scored(self.n_out, p, np.full(n - self.n_out, self.last_time))
        out += self._decide(*self.smoother.flush(self.last_time))
        return out + self.runs.end(n, self.last_time)

    def _scored(self, u, p, times):
        """Probabilities of rows ``u ..`` in: smoothed, then decided (masked
        rows are rest in the labels, after the smoothing, as offline)."""
        hi = u + len(p)
        self.raw.append(p, self.X.mask(u, hi), times)
        self.n_out = hi
        return self._decide(*self.smoother.step(p, np.asarray(times)))

    def _decide(self, lo, smoothed, times):
        if not len(smoothed):
            return []
        hi = lo + len(smoothed)
        out = self.runs.feed(
            lo, smoothed, self.raw.data(lo, hi), self.raw.mask(lo, hi), times
        )
        self.raw.drop(hi)
        return out

    def held(self):
        """Rows held by the buffers."""
        return {
            "rows": len(self.X or ()),
            "scores": self.smoother.held(),
            "undecided": self.runs.held(),
        }


# -- JointFeatures, one frame at a time --------------------------------------------


class JointFeatureStream:
    """State of :meth:`JointFeatures.stream_step` for one stream.

    The offline arithmetic of :func:`skgesture._features.joint_features`
    (``_frame_quantities``, ``_statistics``, ``_normalised``,
    ``_with_derivatives``) on the frames a row needs, with the sequence
    statistics (median trunk length, median hip position, median hip
    direction) taken over the last ``stream_stats_window`` tracked frames
    received when the row is emitted. A row is emitted once the frames its
    derivatives read have arrived (1 frame later with velocities, 2 with
    accelerations) but not before frame ``stream_warmup - 1`` (the first rows
    wait for the statistics of the first ``stream_warmup`` frames); all the
    frames it reads are normalised with the statistics of that moment, so its
    velocity is that of one consistent body frame. Untracked frames are held
    (the last tracked frame repeats, ``fill="hold"``) and masked; untracked
    frames at the start wait for the first tracked frame and become copies of
    it, the last ``max_backfill`` of them, earlier ones are handed on at once
    as masked zero rows.
    """

    def __init__(self, feats, max_backfill=DEFAULT_MAX_BACKFILL):
        from skgesture._features import (
            _frame_quantities,
            _normalised,
            _statistics,
            _with_derivatives,
        )

        self.quantities = _frame_quantities
        self.statistics = _statistics
        self.normalised = _normalised
        self.derivatives = _with_derivatives
        self.index = feats._joint_index
        self.velocities = bool(feats.velocities)
        self.accelerations = bool(feats.accelerations)
        self.align = bool(feats.align)
        self.a = 2 if self.accelerations else int(self.velocities)
        # (getattr: a model saved before these parameters existed streams too)
        self.window = int(getattr(feats, "stream_stats_window", 600))
        self.ready = int(getattr(feats, "stream_warmup", 0)) - 1  # ends the warm-up
        self.width = int(feats.n_features_out_)
        self.max_backfill = int(max_backfill)
        self.R = RowBuffer((20, 3), capacity=32)  # filled raw frames, from p0
        self.untracked = RowBuffer((), dtype=bool, capacity=32)
        self.times = RowBuffer((), dtype=np.int64, capacity=32)
        self.Q = RowBuffer((7,), capacity=64)  # quantities of the tracked frames
        self.Q_frame = RowBuffer((), dtype=np.int64, capacity=64)  # their frames
        self.n_in = 0
        self.n_out = 0
        self.p0 = None  # first frame with a filled raw frame
        self.f = None  # first tracked frame
        self.last = None  # the last tracked frame
        self.medians = RunningMedian(7 if self.align else 4, self.window)
        self.cached = (None, None)  # (tracked frames used, statistics)

    def step(self, rows):
        """Validated raw frames in; the feature rows that became final out."""
        from skgesture.utils._validation import missing_frames

        frames, times = rows.data, rows.time
        first = self.n_in
        self.n_in += len(frames)
        untracked = missing_frames(frames)
        self.untracked.append(untracked)
        self.times.append(times)
        tracked = ~untracked
        if tracked.any():
            self.Q.append(self.quantities(frames[tracked]))
            self.Q_frame.append(first + np.flatnonzero(tracked))
        out = []
        if self.p0 is None:
            if untracked.all():
                out.append(self._zeros(self.n_in - self.max_backfill))
                return _concat_rows(out, (self.width,), np.float32)
            k = int(np.argmax(tracked))
            out.append(self._zeros(first + k - self.max_backfill))
            self.p0, self.f = self.n_out, first + k
            self.R.restart(self.p0)
            # The leading frames kept back become copies of the first tracked one.
            self.R.append(np.repeat(frames[k : k + 1], self.f - self.p0, axis=0))
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
        self.R.append(frames)
        out.append(self._advance())
        return _concat_rows(out, (self.width,), np.float32)

    def flush(self):
        """The remaining rows, the end rows with one-sided differences."""
        if self.p0 is None:
            return self._zeros(self.n_in)
        return self._emit(self.n_out, self.n_in, self.n_in - 1)

    def _advance(self):
        """Rows final with the frames received: row ``t`` at frame
        ``max(t + a, first tracked frame, end of warm-up)``."""
        now = self.n_in - 1
        start = max(self.f, self.ready)
        if now < start:
            return Rows.empty((self.width,), np.float32)
        parts = []
        # Rows whose derivatives were complete before the warm-up ended (or
        # the first tracked frame arrived) share the statistics of that frame.
        shared = min(start - self.a + 1, now - self.a + 1)
        if shared > self.n_out:
            parts.append(self._emit(self.n_out, shared, start))
        for t in range(self.n_out, now - self.a + 1):
            parts.append(self._emit(t, t + 1, t + self.a))
        return _concat_rows(parts, (self.width,), np.float32)

    def _stats(self, tau):
        """Statistics of the last ``window`` tracked frames up to frame ``tau``."""
        frames = self.Q_frame.data(self.Q_frame.start, self.Q_frame.stop)
        k = self.Q_frame.start + int(np.searchsorted(frames, tau, side="right"))
        if self.cached[0] != k:
            # The tracked frames up to tau join the sorted window in order.
            cols = self.medians.n_columns
            for row in self.Q.data(self.medians.n_added, k)[:, :cols].tolist():
                self.medians.add(row)
            median = self.medians.median()
            self.cached = (k, self.statistics(None, self.align, median=median))
        return self.cached[1]

    def _emit(self, lo, hi, tau):
        """Rows ``lo .. hi - 1`` with the statistics at frame ``tau``."""
        if hi <= lo:
            return Rows.empty((self.width,), np.float32)
        a = self.a
        b0 = max(lo - a, self.p0)
        b1 = min(hi + a, tau + 1)
        flat = self.normalised(self.R.data(b0, b1), self.index, self._stats(tau))
        data = self.derivatives(flat, self.velocities, self.accelerations)
        rows = Rows(
            np.ascontiguousarray(data[lo - b0 : hi - b0]),
            self.untracked.data(lo, hi).copy(),
            np.full(hi - lo, self.times.data(tau, tau + 1)[0], dtype=np.int64),
        )
        self.n_out = hi
        self._trim()
        return rows

    def _trim(self):
        keep = self.n_out
        self.R.drop(max(keep - self.a, self.p0 or 0))
        self.untracked.drop(keep)
        self.times.drop(keep)
        if self.cached[0] is not None:  # the sorted window holds them now
            self.Q.drop(self.cached[0])
            self.Q_frame.drop(self.cached[0])

    def _zeros(self, until):
        """Hand on the leading untracked frames before ``until`` as zero rows."""
        lo = self.n_out
        if until <= lo:
            return Rows.empty((self.width,), np.float32)
        self.n_out = until
        n = until - lo
        rows = Rows(
            np.zeros((n, self.width), dtype=np.float32),
            np.ones(n, dtype=bool),
            self.times.data(lo, until).copy(),
        )
        self.untracked.drop(until)
        self.times.drop(until)
        return rows

    def held(self):
        """Rows held by the buffers."""
        return {"frames": len(self.R), "tracked": len(self.medians)}


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
    >>> from skgesture._incremental import RunningMedian
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
