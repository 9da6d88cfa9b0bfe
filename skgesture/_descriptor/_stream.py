"""The live step of PoseDescriptor: its state for one stream."""

# SPDX-License-Identifier: BSD-3-Clause

import math

import numpy as np

from skgesture._descriptor._constants import DEGENERATE_INCLINATION, MIN_NORM
from skgesture._stream import DEFAULT_MAX_BACKFILL, Rows
from skgesture.utils._buffers import RowBuffer, _concat_rows

_WARM = []  # whether the compiled descriptor kernel was run in this process


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
        from skgesture._descriptor._compute import gaussian_kernel
        from skgesture._descriptor._constants import DERIVATIVE_REACH, GAUSSIAN_SIZE
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
        from skgesture._descriptor._compute import _compiled_kernel

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
