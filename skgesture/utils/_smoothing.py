"""MATLAB-compatible ``smooth(y, span, 'loess')`` for uniformly spaced frames."""

# SPDX-License-Identifier: BSD-3-Clause

from functools import lru_cache
from math import ceil, floor, isfinite
from numbers import Real

import numpy as np

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
