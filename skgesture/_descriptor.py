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
from numbers import Real

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import check_is_fitted

from skgesture.layouts import (
    KINECT_V1,
    N_COORDS,
    DescriptorJoints,
    get_descriptor_joints,
)
from skgesture.utils._validation import (
    MAX_COORDINATE,
    check_sequences,
    missing_frames,
    refuse_set_output,
)

__all__ = ["PoseDescriptor"]

GAUSSIAN_SIZE = 5  # docs/method.md §3.6: fspecial('gaussian', [5 1], 1)
DERIVATIVE_REACH = 2  # docs/method.md §3.7: the acceleration looks 2 frames each way
EDGE = max((GAUSSIAN_SIZE - 1) // 2, DERIVATIVE_REACH)  # padding per sequence end
MIN_NORM = 1e-8  # docs/method.md §3.9-3.11: below this a vector is degenerate
MIN_SCALE = 1e-8  # docs/method.md §3.14: a feature with smaller std keeps scale 1
DEGENERATE_INCLINATION = np.pi / 2  # docs/method.md decision D8
BATCH_VALUES = 750_000  # descriptor values per vectorised pass (4096 frames of
# 183 features): large enough to amortise the Python overhead, small enough
# for the intermediates to stay in cache


_ROOT = KINECT_V1.index(KINECT_V1.root)
# Whether the descriptor may use the compiled kernel (numba) when it is
# installed; False forces the numpy implementation (tests compare the two).
# SKGESTURE_DISABLE_NUMBA=1 in the environment sets it to False.
USE_COMPILED = os.environ.get("SKGESTURE_DISABLE_NUMBA", "0") in ("", "0")


def _compiled_kernel():
    """The compiled descriptor kernel module, or None (numba missing or
    ``USE_COMPILED`` False): the numpy implementation is used then."""
    global USE_COMPILED
    if not USE_COMPILED:
        return None
    try:
        from skgesture import _descriptor_kernel
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
    >>> from skgesture._descriptor import gaussian_kernel
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


class PoseDescriptor(TransformerMixin, BaseEstimator, auto_wrap_output_keys=None):
    """Per-frame handcrafted pose descriptor of Brás, Simão & Neto.

    Turns each skeleton sequence ``(n_frames, 20, 3)`` (Kinect v1 joint order, in
    metres) into ``(n_frames, n_features)`` descriptors: for the paper's 11
    upper-body joints, 183 features = 33 smoothed positions, 33 velocities, 33
    accelerations, 9 inclination, 9 azimuth and 11 bending angles and 55 pairwise
    distances, z-scored with statistics of the training frames.

    Processing per sequence: untracked frames (all zeros or NaN, or with a
    masked value in a ``numpy.ma.MaskedArray`` input) are filled, the skeleton
    is centred on HipCenter, every link is rescaled to its mean training
    length, the kept joints are smoothed along time by a 5-tap Gaussian, and
    derivatives and angles are computed from the smoothed positions.

    Parameters
    ----------
    joints : {"paper11", "full20"} or DescriptorJoints, default="paper11"
        Joint set: the paper's 11 upper-body joints (183 features) or the whole
        20-joint body (426 features), or a custom
        :class:`~skgesture.layouts.DescriptorJoints`.
    sigma : float, default=1.0
        Standard deviation, in frames, of the 5-tap temporal Gaussian. ``0``
        disables smoothing.
    border : {"replicate", "zero", "symmetric"}, default="replicate"
        Padding of the Gaussian at the sequence ends (docs/method.md decision D3).
    link_normalisation : bool, default=True
        Rescale every link to its mean length over the training frames.
    link_direction : {"original", "simao"}, default="original"
        Direction of a normalised link: from the original parent (``"original"``)
        or from the already normalised parent (``"simao"``) (decision D2).
    fill : {"linear", "hold"}, default="linear"
        How untracked frames are filled: linear interpolation between the nearest
        tracked frames, or holding the last tracked frame (decision D11).
    distance_scale : {"none", "spine"}, default="none"
        Divide the pairwise distances by the HipCenter-ShoulderCenter distance of
        each frame (decision D9).
    standardize : bool, default=True
        Z-score every feature with the mean and standard deviation of the
        training frames.

    Attributes
    ----------
    link_lengths_ : ndarray of shape (n_links,)
        Mean training length of every link of the normalisation tree.
    mean_ : ndarray of shape (n_features_out,)
        Per-feature mean over the training frames.
    scale_ : ndarray of shape (n_features_out,)
        Per-feature standard deviation (1 where it is below 1e-8).
    n_features_out_ : int
        Width of the descriptor (183 for ``joints="paper11"``).
    joints_ : DescriptorJoints
        The joint set the statistics were learned for; ``transform`` refuses
        a changed ``joints`` until the descriptor is refitted.
    frame_shape_in_ : tuple of int
        Shape of one input frame seen in ``fit``, ``(20, 3)``.
    n_features_in_ : int
        Number of values per input frame (60).

    See Also
    --------
    ActivitySegmenter : Framewise rest-vs-gesture network on these descriptors.
    DynamicPoseWindow : Concatenates descriptors sampled around each frame.

    Notes
    -----
    The layout of the 183 features follows docs/method.md §3.13; the triples, body
    frame and degenerate-angle values follow decisions D5-D8. A sequence with no
    tracked frame gives an all-zero (standardised) descriptor; ``fit`` ignores
    such sequences with a warning.

    Untracked frames are rest by construction (docs/design.md §1.1):
    ``transform`` returns a sequence with untracked frames as a
    ``numpy.ma.MaskedArray`` whose masked rows are those frames (the data under
    the mask is the descriptor of the filled frames, as before), and every
    classifier and tagger of skgesture predicts rest on masked rows. A sequence
    without untracked frames stays a plain ndarray.

    Coordinates must be finite (NaN marks an untracked joint) and at most 1e5
    in magnitude (metres or millimetres alike); anything else raises a
    ``ValueError`` naming the sequence and the frame. ``set_output`` is refused:
    the output is a list of per-sequence arrays, which has no DataFrame form,
    so a global ``transform_output="pandas"`` setting leaves it unchanged.

    References
    ----------
    .. [1] Brás, Simão & Neto, "Gesture Recognition from Skeleton Data for
       Intuitive Human-Machine Interaction".
    .. [2] Zanfir, Leordeanu & Sminchisescu, "The Moving Pose", ICCV 2013.

    Examples
    --------
    >>> from skgesture import PoseDescriptor
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> desc = PoseDescriptor().fit([X])
    >>> Z = desc.transform([X])
    >>> Z[0].shape == (len(X), 183)
    True
    >>> bool(abs(Z[0].mean()) < 1e-6)
    True
    """

    _parameter_constraints: dict = {
        "joints": [StrOptions({"paper11", "full20"}), DescriptorJoints],
        "sigma": [Interval(Real, 0, None, closed="left")],
        "border": [StrOptions({"replicate", "zero", "symmetric"})],
        "link_normalisation": ["boolean"],
        "link_direction": [StrOptions({"original", "simao"})],
        "fill": [StrOptions({"linear", "hold"})],
        "distance_scale": [StrOptions({"none", "spine"})],
        "standardize": ["boolean"],
    }

    def __init__(
        self,
        *,
        joints="paper11",
        sigma=1.0,
        border="replicate",
        link_normalisation=True,
        link_direction="original",
        fill="linear",
        distance_scale="none",
        standardize=True,
    ):
        self.joints = joints
        self.sigma = sigma
        self.border = border
        self.link_normalisation = link_normalisation
        self.link_direction = link_direction
        self.fill = fill
        self.distance_scale = distance_scale
        self.standardize = standardize

    # -- fitting ---------------------------------------------------------------

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Learn link lengths and feature statistics from training sequences.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeleton sequences; untracked frames are all zeros or NaN.
        y : None
            Ignored.

        Returns
        -------
        self : PoseDescriptor
            The fitted transformer.
        """
        X = self._validate(X, reset=True)
        spec = self._spec()
        self.joints_ = spec["joints"]
        links = spec["links"]
        # Statistics accumulated sequence by sequence (and batch by batch):
        # fit holds one batch of descriptors at a time, not all of them.
        bone_sum, n_tracked, valid_seq = 0.0, 0, []
        for i, seq in enumerate(X):
            q, miss = self._prepare(seq)
            if miss.all():
                warnings.warn(
                    f"X[{i}] has no tracked frame; it is ignored in fit",
                    UserWarning,
                    stacklevel=2,
                )
                continue
            q = q[~miss]
            bones = _planes(q[:, links[:, 1]] - q[:, links[:, 0]])
            bone_sum = bone_sum + _norm(bones).sum(axis=-1)
            n_tracked += len(q)
            valid_seq.append(i)
        if not valid_seq:
            raise ValueError(
                "every sequence of X is untracked (all-zero or NaN frames)"
            )
        self.link_lengths_ = bone_sum / n_tracked
        self.n_features_out_ = spec["joints"].n_features
        self.mean_ = np.zeros(self.n_features_out_)
        self.scale_ = np.ones(self.n_features_out_)
        if self.standardize:
            valid = [X[i] for i in valid_seq]
            size = BATCH_VALUES // self.n_features_out_
            chunks = (
                np.concatenate(
                    self._describe_all([valid[i] for i in batch], spec, False)
                )
                for batch in _batches([len(seq) for seq in valid], size)
            )
            self.mean_, std = _mean_std(chunks)
            self.scale_ = np.where(std < MIN_SCALE, 1.0, std)
        return self

    def transform(self, X):
        """Compute the standardised descriptor of every frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeleton sequences.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_features_out_)
            One descriptor matrix per sequence, same number of frames. A
            sequence with untracked frames comes as a ``numpy.ma.MaskedArray``
            whose masked rows are those frames (rest by construction).
        """
        check_is_fitted(self)
        spec = self._spec()
        self._check_joints(spec)
        X = self._validate(X, reset=False)
        out = self._describe_all(X, spec, standardize=True)
        for i, seq in enumerate(X):
            rows = missing_frames(seq)
            if rows.any():
                mask = np.repeat(rows[:, None], out[i].shape[1], axis=1)
                out[i] = np.ma.MaskedArray(out[i], mask=mask)
        return out

    def set_output(self, *, transform=None):
        """Refuse a DataFrame output: a list of sequences has none.

        Parameters
        ----------
        transform : {"default"} or None, default=None
            Only ``"default"`` and ``None`` (no change) are accepted.

        Returns
        -------
        self : PoseDescriptor
            Unchanged.

        Raises
        ------
        ValueError
            For ``"pandas"``, ``"polars"`` or any other container. Wrap one
            sequence's descriptor yourself, e.g.
            ``pandas.DataFrame(Z[i], columns=desc.get_feature_names_out())``.
        """
        return refuse_set_output(self, transform)

    def get_feature_names_out(self, input_features=None):
        """Names of the descriptor features, in layout order.

        Parameters
        ----------
        input_features : None
            Ignored; present for API consistency.

        Returns
        -------
        ndarray of str of shape (n_features_out,)
            Names such as ``"pos_Head_x"``, ``"incl_ShoulderLeft_ElbowLeft_HandLeft"``
            or ``"dist_Head_HandRight"``.
        """
        check_is_fitted(self)
        spec = self._spec()
        self._check_joints(spec)
        dj = spec["joints"]
        names = []
        for kind in ("pos", "vel", "acc"):
            names += [f"{kind}_{j}_{c}" for j in dj.joints for c in "xyz"]
        for kind in ("incl", "azim"):
            names += [f"{kind}_{'_'.join(t)}" for t in dj.triples]
        names += [f"bend_{j}" for j in dj.joints]
        names += [f"dist_{dj.joints[a]}_{dj.joints[b]}" for a, b in dj.pairs]
        return np.asarray(names, dtype=object)

    # -- internals -------------------------------------------------------------

    def _validate(self, X, reset):
        if isinstance(X, (list, tuple)):
            # A masked value marks an untracked joint: it becomes NaN, so its
            # frame is untracked, whatever lies under the mask.
            X = [
                np.ma.filled(np.ma.asarray(seq, dtype=float), np.nan)
                if isinstance(seq, np.ma.MaskedArray)
                else seq
                for seq in X
            ]
        return check_sequences(
            X,
            frame_shape=(KINECT_V1.n_joints, N_COORDS),
            ndim=3,
            allow_nan=True,
            estimator=self,
            reset=reset,
            max_abs=MAX_COORDINATE,
        )

    def _check_joints(self, spec):
        """Refuse a ``joints`` changed since ``fit`` (set_params on a fitted model)."""
        fitted = getattr(self, "joints_", spec["joints"])
        if spec["joints"] != fitted:
            raise ValueError(
                f"joints was changed after fit: the descriptor was fitted for "
                f"{fitted.name!r} ({fitted.n_features} features) but joints is now "
                f"{spec['joints'].name!r} ({spec['joints'].n_features} features); "
                f"refit the descriptor and every stage after it"
            )

    def _spec(self):
        """Joint, link, triple and pair indices for the chosen joint set.

        ``links`` are Kinect indices; ``used_links`` and ``used_keep`` index the
        ``used`` joints (kept or on a link); triples, torso and pair runs index the
        kept joints; ``groups`` are the row slices of the feature groups.
        """
        dj = get_descriptor_joints(self.joints)
        idx = KINECT_V1.indices
        keep = np.asarray(idx(dj.joints))
        links = np.asarray([idx(link) for link in dj.links], dtype=np.intp)
        links = links.reshape(-1, 2)
        pos_in_keep = {k: n for n, k in enumerate(keep)}
        # Joints the descriptor reads: the kept ones and those of the links.
        used = np.union1d(keep, links)
        pos_in_used = np.searchsorted(used, np.arange(KINECT_V1.n_joints))
        return {
            "joints": dj,
            "keep": keep,
            "links": links,
            "triples": np.asarray(
                [[pos_in_keep[k] for k in idx(t)] for t in dj.triples], dtype=np.intp
            ).reshape(-1, 3),
            "torso": np.asarray([pos_in_keep[k] for k in idx(dj.torso)]),
            "left_right": [pos_in_keep[k] for k in idx(dj.left_right)],
            "spine": [pos_in_keep[k] for k in idx(dj.spine)],
            "pair_runs": _pair_runs(dj.pairs),
            "groups": _feature_groups(dj),
            "used": used,
            "used_links": pos_in_used[links],
            "used_keep": pos_in_used[keep],
        }

    def _prepare(self, seq):
        """Fill untracked frames and centre on the root; returns (q, missing)."""
        miss = missing_frames(seq)
        if miss.all():
            return seq, miss
        q = _fill_missing(seq, miss, self.fill)
        q = q - q[:, KINECT_V1.index(KINECT_V1.root)][:, None, :]
        return q, miss

    def _describe(self, seq, spec):
        """Raw (unstandardised) descriptor of one sequence, ``(T, n_features)``."""
        return self._describe_all([seq], spec, standardize=False)[0]

    def _describe_all(self, X, spec, standardize):
        """Descriptors of sequences ``X``, computed batch by batch."""
        out = []
        kernel = _compiled_kernel()
        n = spec["joints"].n_features
        size = (BATCH_VALUES if kernel is None else kernel.BATCH_VALUES) // n
        lengths = [len(seq) for seq in X]
        if kernel is not None:  # scratch arrays shared by the batches
            work = kernel.workspace(spec, n, max(lengths, default=1))
        for batch in _batches(lengths, size):
            seqs = [X[i] for i in batch]
            if kernel is None:
                out += self._describe_batch(seqs, spec, standardize)
            else:
                out += self._describe_compiled(kernel, seqs, spec, standardize, work)
        return out

    def _describe_compiled(self, kernel, X, spec, standardize, work=None):
        """:meth:`_describe_batch` by the compiled kernel (same descriptors)."""
        n = spec["joints"].n_features
        return kernel.describe_batch(
            X,
            spec,
            {
                "root_u": int(np.searchsorted(spec["used"], _ROOT)),
                "kernel": gaussian_kernel(self.sigma) if self.sigma > 0 else None,
                "border": self.border,
                "link_lengths": self.link_lengths_ if self.link_normalisation else None,
                "link_direction": self.link_direction,
                "fill": self.fill,
                "distance_scale": self.distance_scale,
            },
            self.mean_ if standardize else np.zeros(n),
            self.scale_ if standardize else np.ones(n),
            0.0 if standardize else self.mean_,
            work,
        )

    def _describe_batch(self, X, spec, standardize):
        """Descriptors of sequences ``X`` from one pass over their concatenation.

        Returns one ``(T_i, n_features)`` array per sequence, standardised or raw
        (C-contiguous views of one array).
        """
        lengths = np.array([len(seq) for seq in X])
        Q, untracked = _sequence_planes(X, lengths, self.fill)
        q = Q[:, spec["used"]]
        q -= Q[:, KINECT_V1.index(KINECT_V1.root), None]
        if self.link_normalisation:
            _link_normalise_planes(
                q, spec["used_links"], self.link_lengths_, self.link_direction
            )
        P = q[:, spec["used_keep"]].reshape(-1, q.shape[-1])  # (3 * K, frames)

        offsets, n = _segment_offsets(lengths)
        kernel = gaussian_kernel(self.sigma) if self.sigma > 0 else None
        K = len(spec["keep"])
        S = _smoothed(P, lengths, offsets, n, kernel, self.border)
        S = S.reshape(N_COORDS, K, n)  # smoothed joints over the padded frames

        # D holds the descriptor as feature rows over the padded frames. Each
        # group of rows is standardised as soon as it is complete (in cache).
        D = np.empty((spec["joints"].n_features, n))
        pos, vel, acc, incl, azim, bend, dist = groups = [
            D[rows] for rows in spec["groups"]
        ]
        if standardize:
            stats = [(self.mean_[g], self.scale_[g]) for g in spec["groups"]]
        else:
            stats = [(None, None)] * len(groups)
        pos_vel_acc = [  # joint-major rows, seen as coordinate planes
            rows.reshape(K, N_COORDS, n).transpose(1, 0, 2) for rows in groups[:3]
        ]
        pos_vel_acc[0][...] = S
        _standardise(pos, *stats[0])
        _derivatives(S, *pos_vel_acc[1:])
        _standardise(vel, *stats[1])
        _standardise(acc, *stats[2])
        u_x, u_z = _body_frame_planes(
            S, spec["torso"], spec["left_right"], spec["spine"], offsets
        )
        _angles(S, spec["triples"], u_x, u_z, incl, azim, bend)
        for rows, (mean, scale) in zip((incl, azim, bend), stats[3:6]):
            _standardise(rows, mean, scale)
        _distances_planes(S, spec["pair_runs"], dist)
        if self.distance_scale == "spine":
            lo, hi = spec["spine"]
            spine = _norm(S[:, hi] - S[:, lo])
            spine[~(spine > MIN_NORM)] = 1.0
            dist /= spine
        _standardise(dist, *stats[6])

        Z = np.ascontiguousarray(D.T)  # frames as rows
        out = []
        for o, T, skip in zip(offsets + EDGE, lengths, untracked):
            if skip:  # no tracked frame: the standardised descriptor is all zeros
                Z[o : o + T] = 0.0 if standardize else self.mean_
            out.append(Z[o : o + T])
        return out

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        tags.input_tags.allow_nan = True
        tags.requires_fit = True
        return tags

    # -- incremental step (docs/design.md, "Incremental steps") ----------------
    # The per-frame arithmetic and the state live in skgesture/_incremental.py;
    # tests/test_streaming.py checks that a stream gives the rows of transform.

    def stream_init(self, *, max_backfill=64, **options):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Parameters
        ----------
        max_backfill : int, default=64
            Untracked frames at the start of a stream that wait for the first
            tracked frame and become copies of it, as offline filling does;
            earlier ones are handed on at once as rest (all-zero masked rows).
        **options
            Options of other stages, ignored.

        Returns
        -------
        object
            The state, for :meth:`stream_step` and :meth:`stream_flush`.

        Examples
        --------
        >>> from skgesture import PoseDescriptor
        >>> from skgesture._incremental import stream_frames
        >>> from skgesture.utils._testing import make_skeleton_stream
        >>> X, _ = make_skeleton_stream(random_state=0)
        >>> desc = PoseDescriptor(fill="hold").fit([X])
        >>> state = desc.stream_init()
        >>> rows, state = desc.stream_step(state, stream_frames(X[:10], 0))
        >>> len(rows), desc.stream_lookahead  # frames 0..5 are final with frame 9
        (6, 4)
        >>> last, state = desc.stream_flush(state)
        >>> bool(abs(rows.data - desc.transform([X[:10]])[0][:6]).max() < 1e-12)
        True
        """
        from skgesture._incremental import DescriptorStream

        check_is_fitted(self)
        if hasattr(self, "_check_joints"):
            self._check_joints(self._spec())
        return DescriptorStream(self, max_backfill=max_backfill)

    def stream_step(self, state, rows):
        """Raw frames in; the descriptor rows that became final out.

        Every frame is checked as :meth:`transform` checks it, and a bad one
        raises a ``ValueError`` naming its index in the stream (the state is
        then unchanged). Untracked frames hold the last tracked frame
        (``fill="hold"``: the future is unknown) and come out masked.

        Parameters
        ----------
        state : object
            From :meth:`stream_init`.
        rows : Rows
            The next raw frames ``(n, 20, 3)``, with their stream indices as
            ``time``.

        Returns
        -------
        out : Rows
            Descriptor rows ``(m, n_features_out_)``, masked where untracked.
        state : object
            The updated state.
        """
        from skgesture._incremental import Rows, check_stream_frames

        frames = check_stream_frames(self, rows.data, int(rows.time[0]))
        return state.step(Rows(frames, rows.mask, rows.time)), state

    def stream_flush(self, state):
        """End of the stream: the last rows, with the offline end padding.

        Parameters
        ----------
        state : object
            From :meth:`stream_init`.

        Returns
        -------
        out : Rows
            The remaining rows.
        state : object
            The spent state.
        """
        return state.flush(), state

    @property
    def stream_lookahead(self):
        """Frames after a frame that its descriptor needs (4; 2 if ``sigma=0``)."""
        return (GAUSSIAN_SIZE - 1) // 2 * int(self.sigma > 0) + DERIVATIVE_REACH
