"""The per-frame pose descriptor of Brás, Simão & Neto (183-D for 11 joints).

The computation works on *coordinate planes*: points over time are held as a
``(3, n_points, n_frames)`` array, so that every arithmetic step runs on
contiguous ``(n_points, n_frames)`` blocks of one coordinate instead of on tiny
trailing axes of size 3. ``transform`` concatenates whole sequences into
batches (about ``BATCH_VALUES`` descriptor values each); every sequence gets
``EDGE`` padding frames at both ends, so that the temporal filter and the
derivatives never cross a sequence boundary, and one vectorised pass describes
the whole batch, writing each feature group into its rows of one output array.
"""

# SPDX-License-Identifier: BSD-3-Clause

import os
import warnings

import numpy as np

from skgesture._descriptor._constants import (
    DEGENERATE_INCLINATION,
    EDGE,
    GAUSSIAN_SIZE,
    MIN_NORM,
)
from skgesture.layouts import (
    KINECT_V1,
    N_COORDS,
)

_ROOT = KINECT_V1.index(KINECT_V1.root)
# Whether the descriptor may use the compiled kernel (numba) when it is
# installed; False forces the numpy implementation (tests compare the two).
# SKGESTURE_DISABLE_NUMBA=1 in the environment sets it to False.
USE_COMPILED = os.environ.get("SKGESTURE_DISABLE_NUMBA", "0") in ("", "0")
USE_COMPILED_DEFAULT = USE_COMPILED  # (the command line restores it after a command)


def _compiled_kernel():
    """The compiled descriptor kernel module, or None (numba missing or
    ``USE_COMPILED`` False): the numpy implementation is used then."""
    global USE_COMPILED
    if not USE_COMPILED:
        return None
    try:
        from skgesture._descriptor import _kernel as _descriptor_kernel
    except ImportError:  # numba is an optional dependency
        return None
    except Exception as exc:  # e.g. numba finds no writable cache folder
        USE_COMPILED = False
        warnings.warn(
            f"the compiled descriptor kernel is unavailable ({exc}); using the "
            f"numpy implementation (same descriptor, slower). Setting "
            f"NUMBA_CACHE_DIR to a writable folder may help.",
            RuntimeWarning,
            stacklevel=3,
        )
        return None
    return _descriptor_kernel


def gaussian_kernel(sigma, size=GAUSSIAN_SIZE):
    """Unit-sum sampled Gaussian, as MATLAB ``fspecial('gaussian', [size 1], sigma)``.

    Parameters
    ----------
    sigma : float
        Standard deviation in frames.
    size : int, default=5
        Number of taps (odd).

    Returns
    -------
    ndarray of shape (size,)
        The kernel.

    Examples
    --------
    >>> from skgesture._descriptor._compute import gaussian_kernel
    >>> gaussian_kernel(1.0).round(6).tolist()
    [0.054489, 0.244201, 0.40262, 0.244201, 0.054489]
    """
    m = np.arange(size) - (size - 1) / 2
    w = np.exp(-(m**2) / (2.0 * sigma**2))
    return w / w.sum()


# -- time axis -----------------------------------------------------------------


def _pad_time(P, h, border):
    """Pad ``P`` with ``h`` frames on both ends along axis 0."""
    if h == 0:
        return P
    mode = {"replicate": "edge", "zero": "constant", "symmetric": "symmetric"}[border]
    return np.pad(P, [(h, h)] + [(0, 0)] * (P.ndim - 1), mode=mode)


def _correlate(Pp, kernel, out):
    """``out[..., t] = sum_m kernel[m] * Pp[..., t + m]`` along the last axis."""
    n = out.shape[-1]
    tmp = np.empty_like(out)
    np.multiply(Pp[..., 0:n], kernel[0], out=out)
    for m in range(1, len(kernel)):
        out += np.multiply(Pp[..., m : m + n], kernel[m], out=tmp)
    return out


def _smooth_time(P, kernel, border):
    """Centred correlation of every column of ``P`` with ``kernel`` (§3.6)."""
    h = (len(kernel) - 1) // 2
    Pp = np.moveaxis(_pad_time(P, h, border), 0, -1)
    out = _correlate(Pp, kernel, np.empty(Pp.shape[:-1] + (len(P),)))
    return np.moveaxis(out, -1, 0)


def _derivatives(pos, vel, acc):
    """Velocities and accelerations (§3.7) of frames along the last axis.

    Central differences over 1 and 2 frames; the outermost frames, which lack
    a neighbour, get 0.
    """
    vel[..., :1] = vel[..., -1:] = acc[..., :2] = acc[..., -2:] = 0.0
    np.subtract(pos[..., 2:], pos[..., :-2], out=vel[..., 1:-1])
    inner = np.add(pos[..., 4:], pos[..., :-4], out=acc[..., 2:-2])
    inner -= 2.0 * pos[..., 2:-2]


# -- batches of sequences ------------------------------------------------------


def _batches(lengths, size):
    """Split sequence indices into consecutive runs of about ``size`` frames."""
    batches, batch, n = [], [], 0
    for i, T in enumerate(lengths):
        batch.append(i)
        n += T
        if n >= size:
            batches.append(batch)
            batch, n = [], 0
    return batches + [batch] if batch else batches


def _fill_plan(missing, method):
    """How to fill untracked frames: ``(cols, prev, nxt, w)``.

    docs/method.md §3.3, decision D11.

    Untracked frame ``cols[i]`` becomes ``q[prev[i]] + w[i] * (q[nxt[i]] -
    q[prev[i]])``: ``"linear"`` interpolates between the nearest tracked frames
    on both sides, leading and trailing runs copy the nearest tracked frame.
    ``"hold"`` repeats the last tracked frame (``nxt`` and ``w`` are None).
    """
    cols = np.flatnonzero(missing)
    tracked = np.flatnonzero(~missing)
    k = np.searchsorted(tracked, cols)  # next tracked frame
    prev = tracked[np.maximum(k - 1, 0)]
    if method == "hold":
        return cols, prev, None, None
    nxt = tracked[np.minimum(k, len(tracked) - 1)]
    span = (nxt - prev).astype(float)
    w = np.where(span > 0, (cols - prev) / np.where(span > 0, span, 1.0), 0.0)
    return cols, prev, nxt, w


def _fill_missing(q, missing, method):
    """Fill the untracked frames of a ``(T, ...)`` sequence (docs/method.md §3.3)."""
    if not missing.any():
        return q
    q = q.copy()
    _fill_frames(np.moveaxis(q, 0, -1), missing, method)
    return q


def _fill_frames(planes, missing, method):
    """Fill, in place, the untracked frames along the last axis of ``planes``."""
    cols, prev, nxt, w = _fill_plan(missing, method)
    filled = planes[..., prev]
    if nxt is not None:
        filled += w * (planes[..., nxt] - filled)
    planes[..., cols] = filled


def _sequence_planes(X, lengths, fill):
    """Concatenate ``(T_i, J, 3)`` sequences as planes ``(3, J, sum T_i)``.

    Untracked frames (all zeros or any NaN) are filled by the ``fill`` rule; a
    sequence without any tracked frame is set to zeros and flagged in the
    returned mask.
    """
    starts = np.cumsum(lengths) - lengths
    Q = np.empty(X[0].shape[:0:-1] + (lengths.sum(),))
    for seq, a, T in zip(X, starts, lengths):
        Q[..., a : a + T] = seq.T
    flat = Q.reshape(-1, Q.shape[-1])
    # All zeros, or a NaN (max and min propagate it).
    missing = ~((flat.max(axis=0) > 0) | (flat.min(axis=0) < 0))
    untracked = np.zeros(len(X), dtype=bool)
    if missing.any():
        for i, (a, T) in enumerate(zip(starts, lengths)):
            miss = missing[a : a + T]
            untracked[i] = miss.all()
            if untracked[i]:
                flat[:, a : a + T] = 0.0  # described as a still skeleton, then reset
            elif miss.any():
                _fill_frames(flat[:, a : a + T], miss, fill)
    return Q, untracked


def _segment_offsets(lengths):
    """Start of every segment ``[EDGE pads | T_i frames | EDGE pads]`` of a batch
    laid out back to back, and the total number of padded frames."""
    ends = np.cumsum(lengths + 2 * EDGE)
    return ends - (lengths + 2 * EDGE), int(ends[-1])


def _pad_segments(A, lengths, offsets, border):
    """Set, in place, the padding frames (columns) of every segment of ``A``.

    ``"replicate"`` copies the edge frame, ``"symmetric"`` mirrors the frames
    next to the edge (edge included, as ``np.pad``), ``"zero"`` writes zeros.
    """
    T = lengths[:, None]
    rel = np.arange(-EDGE, EDGE)  # padding frames relative to each sequence
    rel = np.where(rel < 0, rel, rel + T)
    if border == "symmetric":
        u = rel % (2 * T)
        frame = np.where(u < T, u, 2 * T - 1 - u)
    else:
        frame = np.clip(rel, 0, T - 1)
    first = offsets[:, None] + EDGE
    if border == "zero":
        A[:, (first + rel).ravel()] = 0.0
    else:
        A[:, (first + rel).ravel()] = A[:, (first + frame).ravel()]


def _padded(P, lengths, offsets, n, border):
    """Frames (columns) of concatenated sequences in the padded layout."""
    out = np.empty(P.shape[:-1] + (n,))
    for o, a, T in zip(offsets + EDGE, np.cumsum(lengths) - lengths, lengths):
        out[:, o : o + T] = P[:, a : a + T]
    _pad_segments(out, lengths, offsets, border)
    return out


def _smoothed(P, lengths, offsets, n, kernel, border):
    """Rows ``P`` of concatenated frames smoothed by ``kernel`` (§3.6; None: not
    smoothed), in the padded layout with replicated padding frames (§3.7)."""
    if kernel is None:
        return _padded(P, lengths, offsets, n, "replicate")
    h = (len(kernel) - 1) // 2
    Pp = _padded(P, lengths, offsets, n, border)
    S = np.empty_like(Pp)
    _correlate(Pp, kernel, S[:, h : n - h])
    _pad_segments(S, lengths, offsets, "replicate")
    return S


# -- coordinate planes ---------------------------------------------------------


def _planes(P):
    """``(T, ..., 3)`` points as ``(3, ..., T)`` coordinate planes (a copy)."""
    return np.array(P.T, order="C")


def _points(A):
    """``(3, ..., T)`` coordinate planes back as ``(T, ..., 3)`` points."""
    return np.ascontiguousarray(A.T)


def _dot(u, v, out=None):
    """Dot product of the vectors of coordinate planes ``(3, ...)``.

    Sums ``(x + z) + y``, the order of ``np.einsum`` over a length-3 axis, so the
    results match an einsum-based computation bit for bit.
    """
    out = np.multiply(u[0], v[0], out=out)
    tmp = np.multiply(u[2], v[2])
    out += tmp
    out += np.multiply(u[1], v[1], out=tmp)
    return out


def _norm(v):
    """Euclidean norm of the vectors of coordinate planes ``(3, ...)``."""
    n = _dot(v, v)
    return np.sqrt(n, out=n)


def _cross(u, v):
    """Cross product of the vectors of coordinate planes ``(3, ...)``."""
    out = np.empty(np.broadcast_shapes(u.shape, v.shape))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        np.multiply(u[j], v[k], out=out[i])
        out[i] -= u[k] * v[j]
    return out


def _unit(v, out=None):
    """Unit vectors of coordinate planes ``(3, ...)`` and the mask of usable
    (non-zero) ones."""
    n = _norm(v)
    ok = n > MIN_NORM
    np.maximum(n, MIN_NORM, out=n)  # any divisor will do where not ok
    return np.divide(v, n, out=out), ok


def _arccos(cos, ok, fallback, out):
    """``arccos`` of cosines into ``out``, ``fallback`` where not ``ok``."""
    np.arccos(np.clip(cos, -1.0, 1.0, out=cos), out=out)
    if not ok.all():
        np.copyto(out, fallback, where=~ok)
    return out


# -- descriptor steps on coordinate planes -------------------------------------


def _link_scales(v, lengths):
    """Factors rescaling the vectors ``v`` to ``lengths``; 0 for zero vectors."""
    norm = _norm(v)
    norm[norm <= 0] = np.inf
    return np.divide(lengths, norm, out=norm)


def _link_normalise_planes(q, links, lengths, direction):
    """Rescale, in place, every link of the tree to its reference length (§3.5).

    ``q`` holds root-centred joints as planes ``(3, J, n)``; ``links`` holds index
    pairs in tree order, parents first, so every parent is final before its
    children and every child is read before it is overwritten.
    """
    if direction == "original":  # directions of the original links
        v = q[:, links[:, 1]] - q[:, links[:, 0]]
        v *= _link_scales(v, lengths[:, None])
    for k, (a, b) in enumerate(links):
        if direction == "original":
            w = v[:, k]
        else:  # from the normalised parent to the original child
            w = q[:, b] - q[:, a]
            w *= _link_scales(w, lengths[k])
        np.add(q[:, a], w, out=q[:, b])
    return q


def _link_normalise(q, links, lengths, direction):
    """Link-normalised copy of a ``(T, J, 3)`` sequence."""
    return _points(_link_normalise_planes(_planes(q), links, lengths, direction))


def _smallest_eigvec(cov):
    """Eigenvector of the smallest eigenvalue of symmetric 3x3 matrices.

    ``cov`` holds the entries ``(a, b, c, d, e, f)`` = (xx, yy, zz, xy, yz, xz) as
    rows of frames. Closed form (trigonometric eigenvalues, then the longest
    cross product of two rows of ``C - lambda I``): much faster than a batched
    ``eigh`` on many tiny matrices. Returns planes ``(3, n)`` and the mask of
    well-defined ones.
    """
    a, b, c, d, e, f = cov
    q = (a + b + c) / 3.0
    p1 = d * d + e * e + f * f
    p2 = (a - q) ** 2 + (b - q) ** 2 + (c - q) ** 2 + 2.0 * p1
    p = np.sqrt(p2 / 6.0)
    ps = np.where(p > 0, p, 1.0)
    B00, B11, B22 = (a - q) / ps, (b - q) / ps, (c - q) / ps
    B01, B12, B02 = d / ps, e / ps, f / ps
    detB = (
        B00 * (B11 * B22 - B12 * B12)
        - B01 * (B01 * B22 - B12 * B02)
        + B02 * (B01 * B12 - B11 * B02)
    )
    phi = np.arccos(np.clip(detB / 2.0, -1.0, 1.0)) / 3.0
    lam = q + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)  # smallest eigenvalue
    # Rows r0, r1, r2 of the symmetric C - lambda I, as planes (3, 3, n).
    rows = np.array([[a - lam, d, f], [d, b - lam, e], [f, e, c - lam]])
    cands = _cross(rows[:, [0, 0, 1]], rows[:, [1, 2, 2]])  # r0xr1, r0xr2, r1xr2
    n0, n1, n2 = norms = _norm(cands)
    # The longest candidate, the first one on ties (as argmax).
    take0 = (n0 >= n1) & (n0 >= n2)
    take1 = ~take0 & (n1 >= n2)
    v, n = cands[:, 2], norms[2]
    for k, take in ((1, take1), (0, take0)):
        np.copyto(v, cands[:, k], where=take)
        np.copyto(n, norms[k], where=take)
    ok = n > MIN_NORM * np.maximum(p, MIN_NORM) ** 2
    n[n <= 0] = 1.0
    v /= n
    return v, ok


def _body_frame_planes(S, torso, left_right, spine, offsets=None):
    """Per-frame body axes ``u_x, u_z`` (planes ``(3, n)``), docs/method.md §3.8.

    ``S`` holds the joints as planes ``(3, K, n)``. ``offsets`` are the first
    frames of the sequences laid out back to back in ``S`` (``None``: a single
    sequence): a degenerate frame reuses the basis of the previous good frame of
    its own sequence, or the camera axes.
    """
    pts = S[:, torso]
    pts -= pts.mean(axis=1, keepdims=True)
    cov = np.empty((6,) + pts.shape[2:])
    for k, (i, j) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))):
        np.add.reduce(pts[i] * pts[j], axis=0, out=cov[k])
    n, ok_n = _smallest_eigvec(cov)
    up = S[:, spine[1]] - S[:, spine[0]]
    s = _cross(S[:, left_right[0]] - S[:, left_right[1]], up)
    ok_s = _norm(s) > MIN_NORM  # collinear shoulders and spine: no orientation
    u_z = np.negative(n, out=n, where=_dot(n, s) < 0)
    u_y, ok_y = _unit(up - _dot(up, u_z) * u_z)
    u_x = _cross(u_y, u_z)
    ok = ok_n & ok_y & ok_s
    if not ok.all():
        # Degenerate frames reuse the previous good frame's basis; camera axes
        # before the first good frame of a sequence (docs/method.md §3.8).
        t = np.arange(len(ok))
        idx = np.maximum.accumulate(np.where(ok, t, -1))
        first = 0
        if offsets is not None:
            first = np.repeat(offsets, np.diff(offsets, append=len(ok)))
        found = idx >= first
        eye = np.eye(3)[:, :, None]
        u_x = np.where(found, u_x[:, np.maximum(idx, 0)], eye[0])
        u_z = np.where(found, u_z[:, np.maximum(idx, 0)], eye[2])
    return u_x, u_z


def _body_frame(P, torso, left_right, spine):
    """:func:`_body_frame_planes` for ``(T, K, 3)`` joints; ``(T, 3)`` axes."""
    u_x, u_z = _body_frame_planes(_planes(P), torso, left_right, spine)
    return _points(u_x), _points(u_z)


def _angles(S, triples, u_x, u_z, incl, azim, bend):
    """Inclination, azimuth and bending angles (docs/method.md §3.9-3.11).

    ``S`` holds the joints as planes ``(3, K, n)``, ``u_x, u_z`` the body axes
    ``(3, n)``; the angles are written into the rows of ``incl``, ``azim`` and
    ``bend``.
    """
    i, j, k = triples.T
    pj = S[:, j]
    a = S[:, i]
    a, ok_a = _unit(np.subtract(a, pj, out=a), out=a)  # first bone p_i - p_j
    b2 = np.subtract(S[:, k], pj, out=pj)  # second bone p_k - p_j
    c, ok_c = _unit(b2)
    _arccos(_dot(a, c), ok_a & ok_c, DEGENERATE_INCLINATION, incl)

    # Projections onto the plane normal to the first bone b1 = -a (the signs of
    # b1 cancel in (x . b1) b1).
    b2 -= np.multiply(_dot(b2, a), a, out=c)
    b2p, ok_b2 = _unit(b2, out=b2)
    up = np.multiply(_dot(a, u_x[:, None]), a, out=c)
    np.subtract(u_x[:, None], up, out=up)
    up, ok_u = _unit(up, out=up)
    _arccos(_dot(b2p, up), ok_a & ok_b2 & ok_u, 0.0, azim)

    pos, ok_p = _unit(S)
    _arccos(_dot(pos, u_z[:, None]), ok_p, 0.0, bend)


def _mean_std(chunks):
    """Per-column mean and (population) standard deviation of the rows of
    ``chunks``, combined chunk by chunk (Chan, Golub & LeVeque's update, as
    numerically sound as one pass over all rows)."""
    n, mean, m2 = 0, 0.0, 0.0
    for rows in chunks:
        k = len(rows)
        if k == 0:
            continue
        mean_k = rows.mean(axis=0)
        m2_k = ((rows - mean_k) ** 2).sum(axis=0)
        delta = mean_k - mean
        total = n + k
        mean = mean + delta * (k / total)
        m2 = m2 + m2_k + delta**2 * (n * k / total)
        n = total
    return mean, np.sqrt(m2 / n)


def _standardise(rows, mean, scale):
    """``(rows - mean) / scale`` in place, per row; nothing when ``mean`` is None."""
    if mean is not None:
        rows -= mean[:, None]
        rows /= scale[:, None]


def _pair_runs(pairs):
    """Group joint pairs into runs ``(row, a, b_start, b_stop)`` of one first
    joint ``a`` and consecutive second joints."""
    runs = []
    for row, (a, b) in enumerate(np.asarray(pairs).reshape(-1, 2).tolist()):
        if runs and runs[-1][1] == a and runs[-1][3] == b:
            runs[-1][3] += 1
        else:
            runs.append([row, a, b, b + 1])
    return runs


def _distances_planes(S, runs, out):
    """Joint distances of the pair ``runs`` (docs/method.md §3.12) into ``out`` rows.

    ``S`` holds the joints as planes ``(3, K, n)``.
    """
    tmp = np.empty((max((hi - lo for _, _, lo, hi in runs), default=0),) + S.shape[2:])
    for row, a, lo, hi in runs:
        d, t = out[row : row + hi - lo], tmp[: hi - lo]
        for c in range(N_COORDS):
            np.subtract(S[c, lo:hi], S[c, a], out=t)
            if c == 0:
                np.multiply(t, t, out=d)
            else:
                d += np.multiply(t, t, out=t)
        np.sqrt(d, out=d)
    return out


def _distances(P, pairs):
    """Pairwise joint distances of ``(T, K, 3)`` joints in ``pairs`` order."""
    pairs = np.asarray(pairs).reshape(-1, 2)
    out = np.empty((len(pairs), len(P)))
    return _distances_planes(_planes(P), _pair_runs(pairs), out).T.copy()


def _feature_groups(dj):
    """Row slices of the feature groups of the layout (docs/method.md §3.13):
    positions, velocities, accelerations, inclinations, azimuths, bendings and
    distances."""
    K, n_tri = dj.n_joints, len(dj.triples)
    sizes = [3 * K, 3 * K, 3 * K, n_tri, n_tri, K, K * (K - 1) // 2]
    ends = np.cumsum(sizes).tolist()
    return [slice(end - size, end) for size, end in zip(sizes, ends)]
