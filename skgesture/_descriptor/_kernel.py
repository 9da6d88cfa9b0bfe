"""Compiled kernel of the pose descriptor (optional, needs numba).

The numpy implementation in :mod:`skgesture._descriptor` makes one pass over
memory per arithmetic step. This kernel fuses the steps: per sequence it fills,
centres, link-normalises and smooths the joints into coordinate planes, then
computes the features of blocks of frames with loops whose inner axis
is time, which the compiler vectorises, and writes the standardised rows of the
output; only the arc cosines of the angles are left to numpy (vectorised).
Every step repeats the floating-point operations of the numpy implementation in
the same order, so both give the same descriptor (within about 1e-12; the tests
require 1e-6 relative). See ``docs/design.md`` for the layout of the features.

This module imports numba; :mod:`skgesture._descriptor` imports it lazily and
uses numpy when numba is not installed.
"""

# SPDX-License-Identifier: BSD-3-Clause

import math

import numba
import numpy as np

from skgesture._descriptor._constants import MIN_NORM

TWO_PI_3 = 2.0 * np.pi / 3.0
BORDER_CODES = {"replicate": 0, "zero": 1, "symmetric": 2}
BLOCK_VALUES = 16384  # floats of a block of features (128 KiB, in the L2 cache)
# Descriptor values per call of the kernel (64 MiB of output): few, large
# allocations, which numpy backs with huge pages.
BATCH_VALUES = 2**23

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")


# Arc cosine as fdlibm's e_acos.c (a rational approximation of asin), without
# its bit-level correction for x > 0.5: within 1 ulp of numpy's arccos, and
# free of libm calls, so the loops computing angles vectorise.
_PIO2_HI = 1.57079632679489655800e00
_PIO2_LO = 6.12323399573676603587e-17
_PI = 3.14159265358979311600e00
_PS = (
    1.66666666666666657415e-01,
    -3.25565818622400915405e-01,
    2.01212532134862925881e-01,
    -4.00555345006794114027e-02,
    7.91534994289814532176e-04,
    3.47933107596021167570e-05,
)
_QS = (
    -2.40339491173441421878e00,
    2.02094576023350569471e00,
    -6.88283971605453293030e-01,
    7.70381505559019352791e-02,
)
PS0, PS1, PS2, PS3, PS4, PS5 = _PS
QS1, QS2, QS3, QS4 = _QS


@numba.njit(inline="always", error_model="numpy")
def _acos(x):
    """``arccos(x)`` for ``-1 <= x <= 1`` (exact at 0 and 1: pi/2 and 0)."""
    ax = abs(x)
    big = ax > 0.5
    z = (1.0 - ax) * 0.5 if big else x * x
    p = z * (PS0 + z * (PS1 + z * (PS2 + z * (PS3 + z * (PS4 + z * PS5)))))
    q = 1.0 + z * (QS1 + z * (QS2 + z * (QS3 + z * QS4)))
    r = p / q
    s = math.sqrt(z)
    small = _PIO2_HI - (x - (_PIO2_LO - x * r))
    pos = 2.0 * (s + s * r)
    neg = _PI - 2.0 * (s + (r * s - _PIO2_LO))
    big_v = pos if x > 0 else neg
    return big_v if big else small


@_jit
def _border_frame(u, T, border):
    """Frame read at padded position ``u`` (``-2 <= u < T + 2``); -1 for a zero."""
    if 0 <= u < T:
        return u
    if border == 0:
        return min(max(u, 0), T - 1)
    if border == 1:
        return -1
    m = 2 * T
    v = ((u % m) + m) % m
    return v if v < T else m - 1 - v


@_jit
def _gather_sequence(X, a, T, used, hold, missing, nxt, G):
    """Joints ``used`` of frames ``a .. a + T`` of ``X`` as planes ``G[c, u, t]``,
    untracked frames filled (docs/method.md §3.3). False if none is tracked."""
    J = X.shape[1]
    n_tracked = 0
    for t in range(T):
        nan = False
        nonzero = False
        for j in range(J):
            for c in range(3):
                v = X[a + t, j, c]
                if v != v:
                    nan = True
                elif v != 0.0:
                    nonzero = True
        missing[t] = nan or not nonzero
        if not missing[t]:
            n_tracked += 1
    if n_tracked == 0:
        return False
    U = used.shape[0]
    # nxt[t]: the first tracked frame at or after t, -1 if none.
    following = -1
    for t in range(T - 1, -1, -1):
        if not missing[t]:
            following = t
        nxt[t] = following
    first = nxt[0]
    prev = -1
    for t in range(T):
        if not missing[t]:
            prev = t
            for u in range(U):
                for c in range(3):
                    G[c, u, t] = X[a + t, used[u], c]
            continue
        # Untracked: between the nearest tracked frames before (p) and after
        # (n); leading and trailing runs copy the nearest tracked frame.
        p = prev if prev >= 0 else first
        if hold:
            for u in range(U):
                for c in range(3):
                    G[c, u, t] = X[a + p, used[u], c]
            continue
        n = nxt[t] if nxt[t] >= 0 else prev
        if prev < 0:
            n = first
        span = n - p
        w = (t - p) / span if span > 0 else 0.0
        for u in range(U):
            for c in range(3):
                pv = X[a + p, used[u], c]
                G[c, u, t] = pv + w * (X[a + n, used[u], c] - pv)
    return True


@_jit
def _centre_and_normalise(G, T, root_u, links, link_lengths, simao, link_norm, R, V):
    """Root-centre the planes ``G`` and rescale every link (docs/method.md §3.5)."""
    U = G.shape[1]
    for c in range(3):
        r = R[c]
        g = G[c, root_u]
        for t in range(T):
            r[t] = g[t]
        for u in range(U):
            g = G[c, u]
            for t in range(T):
                g[t] -= r[t]
    if not link_norm:
        return
    L = links.shape[0]
    for k in range(L):
        pa = links[k, 0]
        pb = links[k, 1]
        length = link_lengths[k]
        ax = G[0, pa]
        ay = G[1, pa]
        az = G[2, pa]
        bx = G[0, pb]
        by = G[1, pb]
        bz = G[2, pb]
        vx = V[0, k]
        vy = V[1, k]
        vz = V[2, k]
        for t in range(T):
            x = bx[t] - ax[t]
            y = by[t] - ay[t]
            z = bz[t] - az[t]
            n = math.sqrt((x * x + z * z) + y * y)
            n = n if n > 0.0 else np.inf
            s = length / n
            vx[t] = x * s
            vy[t] = y * s
            vz[t] = z * s
        if simao:  # from the normalised parent to the original child, in order
            for t in range(T):
                bx[t] = ax[t] + vx[t]
                by[t] = ay[t] + vy[t]
                bz[t] = az[t] + vz[t]
    if not simao:  # directions of the original links, applied parents first
        for k in range(L):
            pa = links[k, 0]
            pb = links[k, 1]
            for c in range(3):
                ga = G[c, pa]
                gb = G[c, pb]
                v = V[c, k]
                for t in range(T):
                    gb[t] = ga[t] + v[t]


@_jit
def _smooth_sequence(G, T, keep_u, kernel, smooth, border, S):
    """Kept joints smoothed along time (docs/method.md §3.6) into ``S[c, k, 2 : T +
    2]``, the edge frames replicated twice on both sides.

    (Inner loops index their arrays by the bare loop counter, on views, so the
    compiler can vectorise them.)
    """
    K = keep_u.shape[0]
    k0, k1, k2, k3, k4 = kernel[0], kernel[1], kernel[2], kernel[3], kernel[4]
    n = max(T - 4, 0)  # frames with all 5 taps inside the sequence
    for k in range(K):
        for c in range(3):
            src = G[c, keep_u[k]]
            dst = S[c, k]
            if not smooth:
                out = dst[2 : T + 2]
                for t in range(T):
                    out[t] = src[t]
            else:
                s0 = src[0:n]
                s1 = src[1 : n + 1]
                s2 = src[2 : n + 2]
                s3 = src[3 : n + 3]
                s4 = src[4 : n + 4]
                out = dst[4 : n + 4]
                for t in range(n):
                    out[t] = (
                        (((s0[t] * k0) + s1[t] * k1) + s2[t] * k2) + s3[t] * k3
                    ) + s4[t] * k4
                for t in range(T):
                    if 2 <= t < T - 2:
                        continue
                    acc = 0.0
                    for m in range(5):
                        f = _border_frame(t - 2 + m, T, border)
                        term = (src[f] if f >= 0 else 0.0) * kernel[m]
                        acc = term if m == 0 else acc + term
                    dst[t + 2] = acc
            dst[0] = dst[1] = dst[2]
            dst[T + 2] = dst[T + 3] = dst[T + 1]


@_jit
def _body_axes(S, r0, nb, torso, lr, spine, E, A):
    """Body axes of frames ``r0 .. r0 + nb`` of ``S`` (docs/method.md §3.8), as
    ``_body_frame_planes``: ``A[0:3]`` = u_x, ``A[3:6]`` = u_z, ``A[6]`` = 1 for
    a well-defined frame, 0 for a degenerate one. ``E`` is scratch."""
    m = torso.shape[0]
    mx = E[0, :nb]
    my = E[1, :nb]
    mz = E[2, :nb]
    for c in range(3):
        e = E[c, :nb]
        s0 = S[c, torso[0], r0 : r0 + nb]
        for t in range(nb):
            e[t] = s0[t]
        for i in range(1, m):
            si = S[c, torso[i], r0 : r0 + nb]
            for t in range(nb):
                e[t] += si[t]
        for t in range(nb):
            e[t] /= m
    ca = E[3, :nb]
    cb = E[4, :nb]
    cc = E[5, :nb]
    cd = E[6, :nb]
    ce = E[7, :nb]
    cf = E[8, :nb]
    for i in range(m):
        sx = S[0, torso[i], r0 : r0 + nb]
        sy = S[1, torso[i], r0 : r0 + nb]
        sz = S[2, torso[i], r0 : r0 + nb]
        if i == 0:
            for t in range(nb):
                px = sx[t] - mx[t]
                py = sy[t] - my[t]
                pz = sz[t] - mz[t]
                ca[t] = px * px
                cb[t] = py * py
                cc[t] = pz * pz
                cd[t] = px * py
                ce[t] = py * pz
                cf[t] = px * pz
        else:
            for t in range(nb):
                px = sx[t] - mx[t]
                py = sy[t] - my[t]
                pz = sz[t] - mz[t]
                ca[t] += px * px
                cb[t] += py * py
                cc[t] += pz * pz
                cd[t] += px * py
                ce[t] += py * pz
                cf[t] += px * pz
    # Smallest eigenvector of [[a, d, f], [d, b, e], [f, e, c]] (_smallest_eigvec).
    qq = E[9, :nb]
    pp = E[10, :nb]
    hh = E[11, :nb]
    for t in range(nb):
        a = ca[t]
        b = cb[t]
        c = cc[t]
        d = cd[t]
        e = ce[t]
        f = cf[t]
        q = (a + b + c) / 3.0
        p1 = d * d + e * e + f * f
        p2 = (a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2.0 * p1
        p = math.sqrt(p2 / 6.0)
        ps = p if p > 0 else 1.0
        B00 = (a - q) / ps
        B11 = (b - q) / ps
        B22 = (c - q) / ps
        B01 = d / ps
        B12 = e / ps
        B02 = f / ps
        detB = (
            B00 * (B11 * B22 - B12 * B12)
            - B01 * (B01 * B22 - B12 * B02)
            + B02 * (B01 * B12 - B11 * B02)
        )
        qq[t] = q
        pp[t] = p
        hh[t] = min(max(detB / 2.0, -1.0), 1.0)
    for t in range(nb):  # libm calls: kept out of the vectorised loops
        phi = np.arccos(hh[t]) / 3.0
        hh[t] = qq[t] + 2.0 * pp[t] * np.cos(phi + TWO_PI_3)
    l0x = S[0, lr[0], r0 : r0 + nb]
    l0y = S[1, lr[0], r0 : r0 + nb]
    l0z = S[2, lr[0], r0 : r0 + nb]
    l1x = S[0, lr[1], r0 : r0 + nb]
    l1y = S[1, lr[1], r0 : r0 + nb]
    l1z = S[2, lr[1], r0 : r0 + nb]
    s0x = S[0, spine[0], r0 : r0 + nb]
    s0y = S[1, spine[0], r0 : r0 + nb]
    s0z = S[2, spine[0], r0 : r0 + nb]
    s1x = S[0, spine[1], r0 : r0 + nb]
    s1y = S[1, spine[1], r0 : r0 + nb]
    s1z = S[2, spine[1], r0 : r0 + nb]
    a0 = A[0, :nb]
    a1 = A[1, :nb]
    a2 = A[2, :nb]
    a3 = A[3, :nb]
    a4 = A[4, :nb]
    a5 = A[5, :nb]
    a6 = A[6, :nb]
    for t in range(nb):
        a = ca[t]
        b = cb[t]
        c = cc[t]
        d = cd[t]
        e = ce[t]
        f = cf[t]
        lam = hh[t]
        p = pp[t]
        r0x = a - lam
        r1y = b - lam
        r2z = c - lam
        # Candidates r0 x r1, r0 x r2, r1 x r2 with r0 = (r0x, d, f),
        # r1 = (d, r1y, e), r2 = (f, e, r2z).
        c0x = d * e - f * r1y
        c0y = f * d - r0x * e
        c0z = r0x * r1y - d * d
        c1x = d * r2z - f * e
        c1y = f * f - r0x * r2z
        c1z = r0x * e - d * f
        c2x = r1y * r2z - e * e
        c2y = e * f - d * r2z
        c2z = d * e - r1y * f
        n0 = math.sqrt((c0x * c0x + c0z * c0z) + c0y * c0y)
        n1 = math.sqrt((c1x * c1x + c1z * c1z) + c1y * c1y)
        n2 = math.sqrt((c2x * c2x + c2z * c2z) + c2y * c2y)
        take0 = (n0 >= n1) and (n0 >= n2)
        take1 = (not take0) and (n1 >= n2)
        nx = c0x if take0 else (c1x if take1 else c2x)
        ny = c0y if take0 else (c1y if take1 else c2y)
        nz = c0z if take0 else (c1z if take1 else c2z)
        nn = n0 if take0 else (n1 if take1 else n2)
        pm = max(p, MIN_NORM)
        ok = nn > MIN_NORM * (pm * pm)
        nn = nn if nn > 0.0 else 1.0
        nx /= nn
        ny /= nn
        nz /= nn
        ux = s1x[t] - s0x[t]
        uy = s1y[t] - s0y[t]
        uz = s1z[t] - s0z[t]
        wx = l0x[t] - l1x[t]
        wy = l0y[t] - l1y[t]
        wz = l0z[t] - l1z[t]
        sx = wy * uz - wz * uy
        sy = wz * ux - wx * uz
        sz = wx * uy - wy * ux
        ok = ok and math.sqrt((sx * sx + sz * sz) + sy * sy) > MIN_NORM
        flip = (nx * sx + nz * sz) + ny * sy < 0
        nx = -nx if flip else nx
        ny = -ny if flip else ny
        nz = -nz if flip else nz
        dd = (ux * nx + uz * nz) + uy * ny
        yx = ux - dd * nx
        yy = uy - dd * ny
        yz = uz - dd * nz
        ny_ = math.sqrt((yx * yx + yz * yz) + yy * yy)
        ok = ok and ny_ > MIN_NORM
        ny_ = max(ny_, MIN_NORM)
        yx /= ny_
        yy /= ny_
        yz /= ny_
        a0[t] = yy * nz - yz * ny
        a1[t] = yz * nx - yx * nz
        a2[t] = yx * ny - yy * nx
        a3[t] = nx
        a4[t] = ny
        a5[t] = nz
        a6[t] = 1.0 if ok else 0.0


@_jit
def _angles(S, r0, nb, triples, A, mean, scale, F, row0):
    """Standardised inclination, azimuth and bending angles (docs/method.md
    §3.9-3.11) of frames ``r0 .. r0 + nb`` into rows ``row0 ..`` of ``F``; a
    degenerate angle gets its fallback (pi/2, 0, 0: the arc cosine of 0, 1, 1)."""
    n_tri = triples.shape[0]
    axx = A[0, :nb]
    axy = A[1, :nb]
    axz = A[2, :nb]
    azx = A[3, :nb]
    azy = A[4, :nb]
    azz = A[5, :nb]
    for m in range(n_tri):
        i, j, k = triples[m, 0], triples[m, 1], triples[m, 2]
        ix = S[0, i, r0 : r0 + nb]
        iy = S[1, i, r0 : r0 + nb]
        iz = S[2, i, r0 : r0 + nb]
        jx = S[0, j, r0 : r0 + nb]
        jy = S[1, j, r0 : r0 + nb]
        jz = S[2, j, r0 : r0 + nb]
        kx = S[0, k, r0 : r0 + nb]
        ky = S[1, k, r0 : r0 + nb]
        kz = S[2, k, r0 : r0 + nb]
        incl = F[row0 + m, :nb]
        azim = F[row0 + n_tri + m, :nb]
        mi, si = mean[row0 + m], scale[row0 + m]
        ma, sa = mean[row0 + n_tri + m], scale[row0 + n_tri + m]
        for t in range(nb):
            x = ix[t] - jx[t]
            y = iy[t] - jy[t]
            z = iz[t] - jz[t]
            na = math.sqrt((x * x + z * z) + y * y)
            ok_a = na > MIN_NORM
            na = max(na, MIN_NORM)
            x /= na
            y /= na
            z /= na
            bx = kx[t] - jx[t]
            by = ky[t] - jy[t]
            bz = kz[t] - jz[t]
            nc = math.sqrt((bx * bx + bz * bz) + by * by)
            ok_c = nc > MIN_NORM
            nc = max(nc, MIN_NORM)
            cos = (x * (bx / nc) + z * (bz / nc)) + y * (by / nc)
            cos = min(max(cos, -1.0), 1.0)
            incl[t] = (_acos(cos if (ok_a and ok_c) else 0.0) - mi) / si
            d = (bx * x + bz * z) + by * y
            bx = bx - d * x
            by = by - d * y
            bz = bz - d * z
            nb2 = math.sqrt((bx * bx + bz * bz) + by * by)
            ok_b = nb2 > MIN_NORM
            nb2 = max(nb2, MIN_NORM)
            bx /= nb2
            by /= nb2
            bz /= nb2
            d = (x * axx[t] + z * axz[t]) + y * axy[t]
            ux = axx[t] - d * x
            uy = axy[t] - d * y
            uz = axz[t] - d * z
            nu = math.sqrt((ux * ux + uz * uz) + uy * uy)
            ok_u = nu > MIN_NORM
            nu = max(nu, MIN_NORM)
            cos = (bx * (ux / nu) + bz * (uz / nu)) + by * (uy / nu)
            cos = min(max(cos, -1.0), 1.0)
            azim[t] = (_acos(cos if (ok_a and ok_b and ok_u) else 1.0) - ma) / sa
    K = S.shape[1]
    for k in range(K):
        sx = S[0, k, r0 : r0 + nb]
        sy = S[1, k, r0 : r0 + nb]
        sz = S[2, k, r0 : r0 + nb]
        bend = F[row0 + 2 * n_tri + k, :nb]
        mb, sb = mean[row0 + 2 * n_tri + k], scale[row0 + 2 * n_tri + k]
        for t in range(nb):
            x = sx[t]
            y = sy[t]
            z = sz[t]
            n = math.sqrt((x * x + z * z) + y * y)
            ok = n > MIN_NORM
            n = max(n, MIN_NORM)
            cos = ((x / n) * azx[t] + (z / n) * azz[t]) + (y / n) * azy[t]
            cos = min(max(cos, -1.0), 1.0)
            bend[t] = (_acos(cos if ok else 1.0) - mb) / sb


@_jit
def _positions_and_distances(S, r0, nb, pairs, dist_spine, spine, mean, scale, F,
                             dist0):  # fmt: skip
    """Standardised positions, velocities, accelerations (docs/method.md §3.7) and
    distances (§3.12) of frames ``r0 .. r0 + nb`` into the rows of ``F``."""
    K = S.shape[1]
    nK = 3 * K
    for k in range(K):
        for c in range(3):
            sm2 = S[c, k, r0 - 2 : r0 - 2 + nb]
            sm1 = S[c, k, r0 - 1 : r0 - 1 + nb]
            s = S[c, k, r0 : r0 + nb]
            sp1 = S[c, k, r0 + 1 : r0 + 1 + nb]
            sp2 = S[c, k, r0 + 2 : r0 + 2 + nb]
            i = 3 * k + c
            pos = F[i, :nb]
            vel = F[nK + i, :nb]
            acc = F[2 * nK + i, :nb]
            m0, s0 = mean[i], scale[i]
            m1, s1 = mean[nK + i], scale[nK + i]
            m2, s2 = mean[2 * nK + i], scale[2 * nK + i]
            for t in range(nb):
                pos[t] = (s[t] - m0) / s0
                vel[t] = ((sp1[t] - sm1[t]) - m1) / s1
                acc[t] = (((sp2[t] + sm2[t]) - 2.0 * s[t]) - m2) / s2
    spine_len = F[dist0 - 1, :nb]  # scratch row (an angle row, written later)
    if dist_spine:
        lo = spine[0]
        hi = spine[1]
        lx = S[0, lo, r0 : r0 + nb]
        ly = S[1, lo, r0 : r0 + nb]
        lz = S[2, lo, r0 : r0 + nb]
        hx = S[0, hi, r0 : r0 + nb]
        hy = S[1, hi, r0 : r0 + nb]
        hz = S[2, hi, r0 : r0 + nb]
        for t in range(nb):
            x = hx[t] - lx[t]
            y = hy[t] - ly[t]
            z = hz[t] - lz[t]
            n = math.sqrt((x * x + z * z) + y * y)
            spine_len[t] = n if n > MIN_NORM else 1.0
    for m in range(pairs.shape[0]):
        a = pairs[m, 0]
        b = pairs[m, 1]
        ax = S[0, a, r0 : r0 + nb]
        ay = S[1, a, r0 : r0 + nb]
        az = S[2, a, r0 : r0 + nb]
        bx = S[0, b, r0 : r0 + nb]
        by = S[1, b, r0 : r0 + nb]
        bz = S[2, b, r0 : r0 + nb]
        out = F[dist0 + m, :nb]
        mu, sd = mean[dist0 + m], scale[dist0 + m]
        if dist_spine:
            for t in range(nb):
                x = bx[t] - ax[t]
                y = by[t] - ay[t]
                z = bz[t] - az[t]
                out[t] = (math.sqrt((x * x + y * y) + z * z) / spine_len[t] - mu) / sd
        else:
            for t in range(nb):
                x = bx[t] - ax[t]
                y = by[t] - ay[t]
                z = bz[t] - az[t]
                out[t] = (math.sqrt((x * x + y * y) + z * z) - mu) / sd


@_jit
def describe(X, starts, lengths, used, root_u, links, link_lengths, simao,
             link_norm, keep_u, hold, kernel, smooth, border, triples, torso, lr,
             spine, pairs, dist_spine, mean, scale, Z, untracked, missing, nxt,
             G, R, V, S, F, E, A):  # fmt: skip
    """Descriptors of the sequences ``X[starts[i] : starts[i] + lengths[i]]``.

    Writes the standardised descriptor of every frame into the rows of ``Z``
    and flags the sequences without any tracked frame in ``untracked`` (their
    rows are not written). ``missing`` to ``A`` are scratch arrays
    (:func:`workspace`), reused from call to call.
    """
    K = keep_u.shape[0]
    n_tri = triples.shape[0]
    n_features = Z.shape[1]
    ang0 = 9 * K  # first angle row of a feature block
    n_ang = 2 * n_tri + K
    dist0 = ang0 + n_ang
    block = F.shape[1]
    for s in range(lengths.shape[0]):
        a = starts[s]
        T = lengths[s]
        ok = _gather_sequence(X, a, T, used, hold, missing, nxt, G)
        untracked[s] = not ok
        if not ok:
            continue
        _centre_and_normalise(G, T, root_u, links, link_lengths, simao, link_norm,
                              R, V)  # fmt: skip
        _smooth_sequence(G, T, keep_u, kernel, smooth, border, S)
        # A degenerate frame reuses the body axes of the last good frame of its
        # own sequence; camera axes before the first good frame (§3.8).
        g0, g1, g2, g3, g4, g5 = 1.0, 0.0, 0.0, 0.0, 0.0, 1.0
        for t0 in range(0, T, block):
            nb = min(block, T - t0)
            r0 = t0 + 2
            _body_axes(S, r0, nb, torso, lr, spine, E, A)
            for t in range(nb):
                if A[6, t] != 0.0:
                    g0, g1, g2 = A[0, t], A[1, t], A[2, t]
                    g3, g4, g5 = A[3, t], A[4, t], A[5, t]
                else:
                    A[0, t], A[1, t], A[2, t] = g0, g1, g2
                    A[3, t], A[4, t], A[5, t] = g3, g4, g5
            _positions_and_distances(S, r0, nb, pairs, dist_spine, spine, mean,
                                     scale, F, dist0)  # fmt: skip
            _angles(S, r0, nb, triples, A, mean, scale, F, ang0)
            for t in range(nb):
                z = Z[a + t0 + t]
                for i in range(n_features):
                    z[i] = F[i, t]


def workspace(spec, n_features, max_frames):
    """Scratch arrays of :func:`describe` for sequences of up to ``max_frames``."""
    U, L, K = len(spec["used"]), len(spec["used_links"]), len(spec["keep"])
    # Frames per block: the features of a block stay in the L2 cache until they
    # are copied into the frame rows of Z; a multiple of 8 (an AVX-512 vector).
    block = max(8, (BLOCK_VALUES // n_features) // 8 * 8)
    return (
        np.empty(max_frames, dtype=np.bool_),
        np.empty(max_frames, dtype=np.intp),
        np.empty((3, U, max_frames)),
        np.empty((3, max_frames)),
        np.empty((3, L, max_frames)),
        np.empty((3, K, max_frames + 4)),
        np.empty((n_features, block)),
        np.empty((12, block)),
        np.empty((7, block)),
    )


def describe_batch(X, spec, params, mean, scale, untracked_value, work=None):
    """Descriptors of the sequences ``X`` with the compiled kernel.

    Parameters
    ----------
    X : list of ndarray of shape (n_frames_i, n_joints, 3)
        Raw skeleton sequences (untracked frames all zeros or NaN).
    spec : dict
        The joint indices of ``PoseDescriptor._spec``.
    params : dict
        ``root_u`` (position of the root among the used joints), ``kernel``
        (the 5 Gaussian taps, or None), ``border``, ``link_lengths`` (or None:
        no link normalisation), ``link_direction``, ``fill``,
        ``distance_scale``.
    mean, scale : ndarray of shape (n_features,)
        Standardisation (zeros and ones for the raw descriptor).
    untracked_value : float or ndarray of shape (n_features,)
        Row written for every frame of a sequence without a tracked frame.
    work : tuple of ndarray or None, default=None
        Scratch arrays from :func:`workspace` for sequences at least as long
        as those of ``X`` (made here when None).

    Returns
    -------
    list of ndarray of shape (n_frames_i, n_features)
        C-contiguous views of one array.
    """
    lengths = np.array([len(x) for x in X], dtype=np.intp)
    starts = np.cumsum(lengths) - lengths
    Xc = np.concatenate(X, axis=0, dtype=np.float64)
    n_features = len(mean)
    if work is None or len(work[0]) < lengths.max():
        work = workspace(spec, n_features, int(lengths.max()))
    Z = np.empty((len(Xc), n_features))
    untracked = np.zeros(len(X), dtype=np.bool_)
    kernel = params["kernel"]
    if kernel is not None and len(kernel) != 5:
        raise ValueError(f"the compiled kernel smooths with 5 taps, got {len(kernel)}")
    link_lengths = params["link_lengths"]
    describe(
        Xc,
        starts,
        lengths,
        np.asarray(spec["used"], dtype=np.intp),
        int(params["root_u"]),
        np.ascontiguousarray(spec["used_links"], dtype=np.intp).reshape(-1, 2),
        np.zeros(0) if link_lengths is None else np.asarray(link_lengths, float),
        params["link_direction"] == "simao",
        link_lengths is not None,
        np.asarray(spec["used_keep"], dtype=np.intp),
        params["fill"] == "hold",
        np.ones(5) if kernel is None else np.asarray(kernel, dtype=float),
        kernel is not None,
        BORDER_CODES[params["border"]],
        np.ascontiguousarray(spec["triples"], dtype=np.intp).reshape(-1, 3),
        np.asarray(spec["torso"], dtype=np.intp),
        np.asarray(spec["left_right"], dtype=np.intp),
        np.asarray(spec["spine"], dtype=np.intp),
        np.ascontiguousarray(spec["joints"].pairs, dtype=np.intp).reshape(-1, 2),
        params["distance_scale"] == "spine",
        np.ascontiguousarray(mean, dtype=float),
        np.ascontiguousarray(scale, dtype=float),
        Z,
        untracked,
        *work,
    )
    out = []
    for a, T, skip in zip(starts, lengths, untracked):
        if skip:
            Z[a : a + T] = untracked_value
        out.append(Z[a : a + T])
    return out
