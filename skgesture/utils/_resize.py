"""Resample frame matrices along time: MATLAB ``imresize`` bicubic, pchip, spline."""

# SPDX-License-Identifier: BSD-3-Clause

from functools import lru_cache
from math import ceil
from numbers import Integral

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

__all__ = ["resize_frames", "imresize_weights"]

KEYS_A = -0.5  # docs/method.md §8.5: Keys cubic convolution parameter of imresize
KEYS_WIDTH = 4.0  # docs/method.md §8.5: the bicubic kernel covers 4 input samples
_METHODS = ("bicubic", "pchip", "spline")  # docs/method.md §8.5, decision D15


def _keys_cubic(x):
    """Keys cubic convolution kernel with ``a = -0.5`` (MATLAB ``cubic``)."""
    a = KEYS_A
    ax = np.abs(x)
    ax2 = ax * ax
    ax3 = ax2 * ax
    near = (a + 2.0) * ax3 - (a + 3.0) * ax2 + 1.0
    far = a * ax3 - 5.0 * a * ax2 + 8.0 * a * ax - 4.0 * a
    return np.where(ax <= 1.0, near, np.where(ax < 2.0, far, 0.0))


@lru_cache(maxsize=128)
def _imresize_weights_cached(n_in, n_out, antialiasing):
    scale = n_out / n_in
    if scale < 1.0 and antialiasing:
        # Widened, flattened kernel: interpolation and low-pass at once.
        def kernel(x):
            return scale * _keys_cubic(scale * x)

        width = KEYS_WIDTH / scale
    else:
        kernel = _keys_cubic
        width = KEYS_WIDTH
    out_pos = np.arange(1, n_out + 1, dtype=np.float64)
    u = out_pos / scale + 0.5 * (1.0 - 1.0 / scale)  # 1-based input coordinate
    left = np.floor(u - width / 2.0)
    n_taps = int(ceil(width)) + 2
    idx = left[:, None] + np.arange(n_taps)[None, :]  # 1-based, may be outside
    weights = kernel(u[:, None] - idx)
    weights /= weights.sum(axis=1, keepdims=True)
    # Symmetric mirroring with the edge sample repeated: ..., 2, 1 | 1..L | L, L-1, ...
    aux = np.concatenate([np.arange(n_in), np.arange(n_in - 1, -1, -1)])
    cols = aux[np.mod(idx.astype(np.int64) - 1, aux.size)]
    matrix = np.zeros((n_out, n_in))
    rows = np.broadcast_to(np.arange(n_out)[:, None], cols.shape)
    np.add.at(matrix, (rows, cols), weights)
    matrix.flags.writeable = False
    return matrix


def imresize_weights(n_in, n_out, *, antialiasing=True):
    """Weight matrix of MATLAB ``imresize`` bicubic along one dimension.

    Parameters
    ----------
    n_in : int
        Input length ``L`` (>= 1).
    n_out : int
        Output length ``m`` (>= 1).
    antialiasing : bool, default=True
        Widen the kernel when shrinking (``m < L``), as ``imresize`` does by
        default. Ignored when enlarging.

    Returns
    -------
    weights : ndarray of shape (n_out, n_in)
        ``weights @ x`` resizes a column ``x`` of length ``n_in``. Every row
        sums to 1.

    See Also
    --------
    resize_frames : Resize a frame matrix with these weights.

    Notes
    -----
    docs/method.md §8.5: output sample ``i`` (1-based) sits at input coordinate
    ``u = i / s + 0.5 (1 - 1 / s)`` with ``s = m / L``; it takes Keys-cubic
    weights ``k(u - j)`` (``a = -0.5``) of the 4 nearest input samples,
    normalised to sum 1, with out-of-range samples mirrored symmetrically
    (edge sample repeated). When shrinking with antialiasing the kernel
    becomes ``s k(s x)`` with width ``4 / s`` (MATLAB ``contributions``).

    Examples
    --------
    >>> from skgesture.utils._resize import imresize_weights
    >>> imresize_weights(2, 3).round(4).tolist()
    [[1.0694, -0.0694], [0.5, 0.5], [-0.0694, 1.0694]]
    """
    for name, value in (("n_in", n_in), ("n_out", n_out)):
        if not isinstance(value, Integral) or isinstance(value, bool) or value < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {value!r}.")
    return _imresize_weights_cached(int(n_in), int(n_out), bool(antialiasing))


@lru_cache(maxsize=128)
def _spline_weights_cached(n_in, n_out):
    # The not-a-knot spline is linear in the data: interpolate the identity.
    t = np.arange(1, n_in + 1, dtype=np.float64)
    tq = np.linspace(1.0, n_in, n_out)
    matrix = CubicSpline(t, np.eye(n_in), axis=0, bc_type="not-a-knot")(tq)
    matrix.flags.writeable = False
    return matrix


def resize_frames(x, n_out, *, method="bicubic"):
    """Resample a frame matrix along time to exactly ``n_out`` rows.

    Parameters
    ----------
    x : array-like of shape (n_frames,) or (n_frames, n_features)
        The frames (rows) to resample; every column is resampled alike.
    n_out : int
        Number of output rows (>= 1).
    method : {"bicubic", "pchip", "spline"}, default="bicubic"
        ``"bicubic"``: MATLAB ``imresize(x, [n_out, n_features])`` (Keys
        cubic convolution, ``a = -0.5``, pixel-centre coordinate map,
        symmetric edges; antialiased when shrinking). ``"pchip"``: MATLAB
        ``interp1(1:L, x, linspace(1, L, n_out), 'pchip')`` (= ``'cubic'``).
        ``"spline"``: the same with a not-a-knot cubic spline.

    Returns
    -------
    resized : ndarray of shape (n_out,) or (n_out, n_features)
        Same dtype as ``x`` when floating, float64 otherwise.

    See Also
    --------
    imresize_weights : The bicubic weight matrix.

    Notes
    -----
    docs/method.md §8.5 and decision D15 (default bicubic). ``"bicubic"`` and
    ``"spline"`` are linear maps, applied as one ``(n_out, L)`` matrix
    product; ``"pchip"`` is not linear and calls
    :class:`scipy.interpolate.PchipInterpolator` on all columns at once.
    A single frame (``L = 1``) is repeated by every method. With ``L = 2``
    pchip and spline are the straight line between the two frames (as in
    MATLAB) and with ``L = 3`` the spline is the parabola through them.
    Shrinking (``n_out < L``) is rarely needed here; bicubic then follows
    ``imresize``'s default antialiasing (kernel ``s k(s x)``, width ``4 / s``,
    ``s = n_out / L``), while pchip and spline simply sample the interpolant.

    Examples
    --------
    >>> from skgesture.utils._resize import resize_frames
    >>> resize_frames([0.0, 1.0, 0.0, 2.0], 9).round(4).tolist()
    [-0.1003, 0.1319, 0.7101, 0.9896, 0.4375, -0.0159, 0.6523, 1.7477, 2.2006]
    >>> resize_frames([[0.0, 1.0], [2.0, 3.0]], 3, method="pchip").tolist()
    [[0.0, 1.0], [1.0, 2.0], [2.0, 3.0]]
    """
    if method not in _METHODS:
        raise ValueError(f"method must be one of {_METHODS}, got {method!r}.")
    if not isinstance(n_out, Integral) or isinstance(n_out, bool) or n_out < 1:
        raise ValueError(f"n_out must be an integer >= 1, got {n_out!r}.")
    x = np.asarray(x)
    if x.ndim not in (1, 2):
        raise ValueError(
            f"x must be 1-D or 2-D (n_frames, n_features), got shape {x.shape}."
        )
    n_in = x.shape[0]
    if n_in == 0:
        raise ValueError("x must contain at least one frame.")
    dtype = x.dtype if np.issubdtype(x.dtype, np.floating) else np.float64
    data = x.astype(np.float64, copy=False)
    n_out = int(n_out)

    if n_in == 1:
        out = np.repeat(data, n_out, axis=0)
    elif method == "bicubic":
        out = imresize_weights(n_in, n_out) @ data
    elif method == "spline":
        out = _spline_weights_cached(n_in, n_out) @ data
    else:
        t = np.arange(1, n_in + 1, dtype=np.float64)
        tq = np.linspace(1.0, n_in, n_out)
        out = PchipInterpolator(t, data, axis=0)(tq)
    return out.astype(dtype, copy=False)
