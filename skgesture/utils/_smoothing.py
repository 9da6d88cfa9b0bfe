"""MATLAB-compatible ``smooth(y, span, 'loess')`` for uniformly spaced frames."""

# SPDX-License-Identifier: BSD-3-Clause

from functools import lru_cache
from math import ceil, floor, isfinite
from numbers import Integral, Real

import numpy as np

from skgesture.utils._buffers import RowBuffer

__all__ = ["loess_smooth", "loess_kernel"]

DEFAULT_SPAN = 5  # docs/method.md §8.1 (MATLAB smooth default)
_DEGREES = {"loess": 2, "lowess": 1}  # docs/method.md §8.1 step 2


def _check_method(method):
    if method not in _DEGREES:
        raise ValueError(f"method must be 'loess' or 'lowess', got {method!r}.")
    return _DEGREES[method]


def _effective_span(span, n):
    """Span actually used by MATLAB ``smooth`` for ``n`` uniform points.

    Follows docs/method.md §8.1 step 1 and §8.4: a fraction ``0 < span < 1``
    becomes ``ceil(span * n)``; the span is floored, capped at ``n`` and, when
    it is not 1, forced odd (so it may become ``n + 1`` for even ``n``).
    """
    if isinstance(span, bool) or not isinstance(span, Real) or not isfinite(span):
        raise ValueError(f"span must be a positive finite number, got {span!r}.")
    if span <= 0:
        raise ValueError(f"span must be positive, got {span!r}.")
    if span < 1:
        if n is None:
            raise ValueError(
                f"a fractional span ({span!r}) needs the number of points; "
                "use an integer span >= 1."
            )
        span = ceil(span * n)
    span = floor(span)
    if n is not None:
        span = min(span, n)
    if span <= 1:
        return 1
    return 2 * (span // 2) + 1


def _weighted_projection_row(x, row, weights, degree):
    """Coefficients ``a`` such that ``a @ y`` is the weighted fit at ``x[row]``.

    Mirrors MATLAB ``unifloess``: the Vandermonde matrix is weighted by the
    square root of the tricube weights, projected with an economy QR (which
    also handles the rank-deficient tiny spans), and the projection row is
    multiplied by the same square-root weights.
    """
    if x.size <= degree + 1:
        # The polynomial interpolates every point: the projection is the
        # identity (MATLAB gets the same up to rounding).
        row_vec = np.zeros(x.size)
        row_vec[row] = 1.0
        return row_vec
    sqrt_w = weights**1.5  # (1 - d^3)^1.5 = sqrt of the tricube weight
    vander = np.vander(x.astype(np.float64), degree + 1, increasing=True)
    q, _ = np.linalg.qr(vander * sqrt_w[:, None], mode="reduced")
    return (q[row] @ q.T) * sqrt_w


@lru_cache(maxsize=64)
def _loess_weights(span, degree):
    """Interior kernel (length ``span``) and end-point rows ``(h, span - 1)``.

    ``span`` must be odd and >= 3. Cached; the returned arrays are read-only.
    """
    h = (span - 1) // 2
    # Interior (docs/method.md §8.1 step 2): offsets -(h-1)..(h-1), the two
    # extreme points of the span have zero tricube weight.
    offsets = np.arange(-(h - 1), h, dtype=np.float64)
    base = 1.0 - (np.abs(offsets) / h) ** 3
    inner = _weighted_projection_row(offsets, h - 1, base, degree)
    kernel = np.zeros(span)
    kernel[1:-1] = inner
    # End points (docs/method.md §8.1 step 3): the first span - 1 points.
    x = np.arange(1, span, dtype=np.float64)
    ends = np.empty((h, span - 1))
    for j in range(1, h + 1):
        base = 1.0 - (np.abs(x - j) / (span - j)) ** 3
        ends[j - 1] = _weighted_projection_row(x, j - 1, base, degree)
    kernel.flags.writeable = False
    ends.flags.writeable = False
    return kernel, ends


def loess_kernel(span=DEFAULT_SPAN, *, method="loess"):
    """Interior FIR kernel of MATLAB ``smooth(y, span, 'loess')``.

    For uniformly spaced data every point with a complete span around it is
    a fixed weighted sum of its neighbours; this returns those weights.

    Parameters
    ----------
    span : int, default=5
        Number of points of the smoothing window (``>= 1``). It is floored
        and forced odd as MATLAB does (4 -> 5, 6 -> 7). Fractions are not
        accepted here because they depend on the sequence length.
    method : {"loess", "lowess"}, default="loess"
        Local quadratic ("loess") or linear ("lowess") weighted fit.

    Returns
    -------
    kernel : ndarray of shape (span_odd,)
        Coefficients for offsets ``-h .. h`` with ``h = (span_odd - 1) / 2``;
        the two outer coefficients are 0. ``[1.0]`` for span 1.

    See Also
    --------
    loess_smooth : Apply the smoother, including the end-point fits.

    Notes
    -----
    docs/method.md §8.1 step 2 and its kernel table. With the MATLAB default
    span 5 the loess kernel is ``(0, 0, 1, 0, 0)``: interior values are
    returned unchanged.

    Examples
    --------
    >>> from skgesture.utils._smoothing import loess_kernel
    >>> loess_kernel(5).round(5).tolist()
    [0.0, 0.0, 1.0, 0.0, 0.0]
    >>> loess_kernel(7).round(5).tolist()
    [0.0, -0.07734, 0.30938, 0.53594, 0.30938, -0.07734, 0.0]
    """
    degree = _check_method(method)
    span = _effective_span(span, None)
    if span == 1:
        return np.ones(1)
    return _loess_weights(span, degree)[0].copy()


def loess_smooth(y, span=DEFAULT_SPAN, *, axis=0, method="loess"):
    """Smooth along one axis exactly like MATLAB ``smooth(y, span, 'loess')``.

    Every 1-D slice along ``axis`` is smoothed separately, as MATLAB's
    ``smooth`` does for one vector, with the points at ``x = 1..n``. The
    interior is one kernel correlation applied to all slices at once; the
    ``h`` first and last points use precomputed weighted polynomial fits.

    Parameters
    ----------
    y : array-like of shape (n, ...) along ``axis``
        Data to smooth, e.g. a ``(n_frames, n_classes)`` score matrix.
    span : int or float, default=5
        Window size in points. A value ``0 < span < 1`` is a fraction of the
        length: ``ceil(span * n)``. The span is floored, capped at ``n`` and
        forced odd; span 1 returns the data unchanged.
    axis : int, default=0
        Axis along which to smooth (time).
    method : {"loess", "lowess"}, default="loess"
        Local quadratic ("loess") or linear ("lowess") weighted fit.

    Returns
    -------
    smoothed : ndarray
        Same shape as ``y``. Same dtype for floating input, float64 otherwise.

    See Also
    --------
    loess_kernel : The interior kernel.

    Notes
    -----
    Implements docs/method.md §8.1 (uniform ``x``): tricube-weighted least
    squares, interior points through a fixed FIR kernel, end points
    ``j = 1..h`` through fits on the first (mirrored for the last) ``span - 1``
    points. When ``span`` exceeds an even ``n`` it becomes ``n + 1`` and every
    point is an end point. The robust variant ``'rloess'`` and MATLAB's NaN
    handling (removal and non-uniform refit) are not implemented: NaN values
    propagate to every output that uses them. This is not Savitzky-Golay
    (docs/method.md §8.2).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils._smoothing import loess_smooth
    >>> y = np.array([1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 5.0])
    >>> loess_smooth(y, span=5).round(4).tolist()
    [1.241, 2.0897, 2.0, 5.0, 4.0, 5.2197, 5.2066]
    >>> Y = np.column_stack([y, 10 * y])
    >>> loess_smooth(Y, span=7)[:, 1].round(3).tolist()
    [12.177, 22.255, 31.396, 38.398, 48.453, 52.612, 52.406]
    """
    degree = _check_method(method)
    y = np.asarray(y)
    dtype = y.dtype if np.issubdtype(y.dtype, np.floating) else np.float64
    if y.ndim == 0:
        raise ValueError("y must have at least one dimension.")
    moved = np.moveaxis(y, axis, 0)
    n = moved.shape[0]
    if n == 0:
        return np.array(y, dtype=dtype)
    span = _effective_span(span, n)
    if span == 1:
        return np.array(y, dtype=dtype)

    kernel, ends = _loess_weights(span, degree)
    h = (span - 1) // 2
    flat = moved.reshape(n, -1).astype(np.float64, copy=False)
    out = np.empty_like(flat)

    # Interior i = h .. n-h-1 (0-based): correlation with the symmetric kernel,
    # one vectorised multiply-add per non-zero tap.
    n_inner = n - 2 * h
    if n_inner > 0:
        acc = np.zeros((n_inner, flat.shape[1]))
        for k in range(1, span - 1):
            acc += kernel[k] * flat[k : k + n_inner]
        out[h : n - h] = acc

    # End points: the first span - 1 points forwards and the last ones
    # backwards (at most n points, exactly n when span = n + 1).
    head = flat[: span - 1]
    tail = flat[::-1][: span - 1]
    out[:h] = ends @ head
    out[::-1][:h] = ends @ tail

    out = out.reshape(moved.shape).astype(dtype, copy=False)
    return np.moveaxis(out, 0, axis)


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
    >>> from skgesture.utils._smoothing import LoessStepper
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
    >>> from skgesture.utils._smoothing import MeanStepper
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
