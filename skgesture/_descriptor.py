"""The per-frame pose descriptor of Brás, Simão & Neto (183-D for 11 joints).

Every helper below works on one sequence and is vectorised over its frames; the
only Python loops run over the 13 links of the skeleton tree.
"""

# SPDX-License-Identifier: BSD-3-Clause

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
from skgesture.utils._validation import check_sequences, missing_frames

__all__ = ["PoseDescriptor"]

GAUSSIAN_SIZE = 5  # METHOD_SPEC §3.6: fspecial('gaussian', [5 1], 1)
MIN_NORM = 1e-8  # METHOD_SPEC §3.9-3.11: below this a vector is degenerate
MIN_SCALE = 1e-8  # METHOD_SPEC §3.14: a feature with smaller std keeps scale 1
DEGENERATE_INCLINATION = np.pi / 2  # METHOD_SPEC decision D8


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


def _pad_time(P, h, border):
    """Pad ``P`` with ``h`` frames on both ends along axis 0."""
    if h == 0:
        return P
    mode = {"replicate": "edge", "zero": "constant", "symmetric": "symmetric"}[border]
    return np.pad(P, [(h, h)] + [(0, 0)] * (P.ndim - 1), mode=mode)


def _smooth_time(P, kernel, border):
    """Centred correlation of every column of ``P`` with ``kernel`` (§3.6)."""
    h = (len(kernel) - 1) // 2
    Pp = _pad_time(P, h, border)
    T = len(P)
    out = kernel[0] * Pp[0:T]
    for m in range(1, len(kernel)):
        out = out + kernel[m] * Pp[m : m + T]
    return out


def _fill_missing(q, missing, method):
    """Fill untracked frames of a ``(T, J, 3)`` sequence (METHOD_SPEC §3.3, D11).

    ``"linear"`` interpolates between the nearest tracked frames on both sides;
    leading and trailing runs copy the nearest tracked frame. ``"hold"`` repeats
    the last tracked frame.
    """
    if not missing.any():
        return q
    T = len(q)
    t = np.arange(T)
    valid = ~missing
    first = int(np.argmax(valid))
    last = T - 1 - int(np.argmax(valid[::-1]))
    prev = np.maximum.accumulate(np.where(valid, t, -1))
    prev[:first] = first
    if method == "hold":
        return q[prev]
    nxt = np.minimum.accumulate(np.where(valid, t, T)[::-1])[::-1]
    nxt[last + 1 :] = last
    span = (nxt - prev).astype(float)
    w = np.where(span > 0, (t - prev) / np.where(span > 0, span, 1.0), 0.0)
    return q[prev] + w[:, None, None] * (q[nxt] - q[prev])


def _link_normalise(q, links, lengths, direction):
    """Rescale every link of the tree to its reference length (METHOD_SPEC §3.5).

    ``q`` is root-centred ``(T, J, 3)``; ``links`` holds index pairs in tree order.
    """
    p = q.copy()
    for (a, b), length in zip(links, lengths):
        origin = q[:, a] if direction == "original" else p[:, a]
        v = q[:, b] - origin
        norm = _norm(v)[:, None]
        p[:, b] = p[:, a] + v * (length / np.where(norm > 0, norm, np.inf))
    return p


def _norm(v):
    """Euclidean norm along the last axis (einsum: faster than ``linalg.norm``)."""
    return np.sqrt(np.einsum("...i,...i->...", v, v))


def _unit(v):
    """Unit vectors along the last axis and the mask of usable (non-zero) ones."""
    n = _norm(v)
    ok = n > MIN_NORM
    return v / np.where(ok, n, 1.0)[..., None], ok


def _smallest_eigvec(C):
    """Eigenvector of the smallest eigenvalue of symmetric ``(T, 3, 3)`` matrices.

    Closed form (trigonometric eigenvalues, then the longest cross product of two
    rows of ``C - lambda I``): an order of magnitude faster than a batched
    ``eigh`` on many tiny matrices.
    """
    a, b, c = C[:, 0, 0], C[:, 1, 1], C[:, 2, 2]
    d, e, f = C[:, 0, 1], C[:, 1, 2], C[:, 0, 2]
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
    M = C - lam[:, None, None] * np.eye(3)
    r0, r1, r2 = M[:, 0], M[:, 1], M[:, 2]
    cands = np.stack([np.cross(r0, r1), np.cross(r0, r2), np.cross(r1, r2)], axis=1)
    norms = _norm(cands)
    best = np.argmax(norms, axis=1)
    rows = np.arange(len(C))
    v = cands[rows, best]
    n = norms[rows, best]
    ok = n > MIN_NORM * np.maximum(p, MIN_NORM) ** 2
    return v / np.where(n > 0, n, 1.0)[:, None], ok


def _body_frame(P, torso, left_right, spine):
    """Per-frame body axes ``u_x, u_z`` from the torso plane (METHOD_SPEC §3.8)."""
    T = len(P)
    torso_pts = P[:, torso]
    centred = torso_pts - torso_pts.mean(axis=1, keepdims=True)
    cov = np.einsum("tki,tkj->tij", centred, centred)
    n, ok_n = _smallest_eigvec(cov)
    left, right = P[:, left_right[0]], P[:, left_right[1]]
    up = P[:, spine[1]] - P[:, spine[0]]
    s = np.cross(left - right, up)
    ok_s = _norm(s) > MIN_NORM  # collinear shoulders and spine: no orientation
    sign = np.where(np.einsum("ti,ti->t", n, s) < 0, -1.0, 1.0)
    u_z = n * sign[:, None]
    u_y, ok_y = _unit(up - np.einsum("ti,ti->t", up, u_z)[:, None] * u_z)
    u_x = np.cross(u_y, u_z)
    ok = ok_n & ok_y & ok_s
    if not ok.all():
        # Degenerate frames reuse the previous frame's basis; camera axes before
        # the first good frame (METHOD_SPEC §3.8).
        idx = np.maximum.accumulate(np.where(ok, np.arange(T), -1))
        eye = np.eye(3)
        u_x = np.where((idx >= 0)[:, None], u_x[np.maximum(idx, 0)], eye[0])
        u_z = np.where((idx >= 0)[:, None], u_z[np.maximum(idx, 0)], eye[2])
    return u_x, u_z


def _angle(u, v, ok, fallback):
    """Angle between unit vectors ``u`` and ``v``; ``fallback`` where not ``ok``."""
    cos = np.clip(np.einsum("...i,...i->...", u, v), -1.0, 1.0)
    return np.where(ok, np.arccos(cos), fallback)


def _angles(P, triples, u_x, u_z):
    """Inclination, azimuth and bending angles (METHOD_SPEC §3.9-3.11)."""
    i, j, k = triples[:, 0], triples[:, 1], triples[:, 2]
    pi, pj, pk = P[:, i], P[:, j], P[:, k]
    a, ok_a = _unit(pi - pj)
    c, ok_c = _unit(pk - pj)
    inclination = _angle(a, c, ok_a & ok_c, DEGENERATE_INCLINATION)

    b1 = -a  # (p_j - p_i) / |p_j - p_i|
    b2 = pk - pj
    b2p, ok_b2 = _unit(b2 - np.einsum("tki,tki->tk", b2, b1)[..., None] * b1)
    ux = u_x[:, None, :]
    up, ok_u = _unit(
        ux - np.einsum("tki,tki->tk", np.broadcast_to(ux, b1.shape), b1)[..., None] * b1
    )
    azimuth = _angle(b2p, up, ok_a & ok_b2 & ok_u, 0.0)

    pos, ok_p = _unit(P)
    bending = _angle(pos, u_z[:, None, :], ok_p, 0.0)
    return inclination, azimuth, bending


def _distances(P, pairs):
    """Pairwise joint distances in lexicographic pair order (METHOD_SPEC §3.12).

    Uses the Gram matrix (|a|^2 + |b|^2 - 2 a.b), about twice as fast as
    gathering the 55 difference vectors.
    """
    T, J = P.shape[:2]
    G = np.einsum("tic,tjc->tij", P, P).reshape(T, J * J)
    sq = G[:, :: J + 1]
    d2 = (
        sq[:, pairs[:, 0]]
        + sq[:, pairs[:, 1]]
        - 2.0 * G[:, pairs[:, 0] * J + pairs[:, 1]]
    )
    return np.sqrt(np.maximum(d2, 0.0))


class PoseDescriptor(TransformerMixin, BaseEstimator):
    """Per-frame handcrafted pose descriptor of Brás, Simão & Neto.

    Turns each skeleton sequence ``(n_frames, 20, 3)`` (Kinect v1 joint order, in
    metres) into ``(n_frames, n_features)`` descriptors: for the paper's 11
    upper-body joints, 183 features = 33 smoothed positions, 33 velocities, 33
    accelerations, 9 inclination, 9 azimuth and 11 bending angles and 55 pairwise
    distances, z-scored with statistics of the training frames.

    Processing per sequence: untracked frames (all zeros or NaN) are filled, the
    skeleton is centred on HipCenter, every link is rescaled to its mean training
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
        Padding of the Gaussian at the sequence ends (METHOD_SPEC decision D3).
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
    mean_ : ndarray of shape (n_features_out_,)
        Per-feature mean over the training frames.
    scale_ : ndarray of shape (n_features_out_,)
        Per-feature standard deviation (1 where it is below 1e-8).
    n_features_out_ : int
        Width of the descriptor (183 for ``joints="paper11"``).
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
    The layout of the 183 features follows METHOD_SPEC §3.13; the triples, body
    frame and degenerate-angle values follow decisions D5-D8. A sequence with no
    tracked frame gives an all-zero (standardised) descriptor, so every model
    predicts rest on it; ``fit`` ignores such sequences with a warning.

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
        filled, valid_seq = [], []
        for i, seq in enumerate(X):
            q, miss = self._prepare(seq)
            if miss.all():
                warnings.warn(
                    f"X[{i}] has no tracked frame; it is ignored in fit",
                    UserWarning,
                    stacklevel=2,
                )
                continue
            filled.append(q[~miss])
            valid_seq.append(i)
        if not filled:
            raise ValueError(
                "every sequence of X is untracked (all-zero or NaN frames)"
            )
        allq = np.concatenate(filled)
        links = spec["links"]
        self.link_lengths_ = _norm(allq[:, links[:, 1]] - allq[:, links[:, 0]]).mean(
            axis=0
        )
        self.n_features_out_ = spec["joints"].n_features
        self.mean_ = np.zeros(self.n_features_out_)
        self.scale_ = np.ones(self.n_features_out_)
        if self.standardize:
            feats = np.concatenate([self._describe(X[i], spec) for i in valid_seq])
            self.mean_ = feats.mean(axis=0)
            std = feats.std(axis=0)
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
            One descriptor matrix per sequence, same number of frames.
        """
        check_is_fitted(self)
        X = self._validate(X, reset=False)
        spec = self._spec()
        return [(self._describe(seq, spec) - self.mean_) / self.scale_ for seq in X]

    def get_feature_names_out(self, input_features=None):
        """Names of the descriptor features, in layout order.

        Parameters
        ----------
        input_features : None
            Ignored; present for API consistency.

        Returns
        -------
        ndarray of str of shape (n_features_out_,)
            Names such as ``"pos_Head_x"``, ``"incl_ShoulderLeft_ElbowLeft_HandLeft"``
            or ``"dist_Head_HandRight"``.
        """
        check_is_fitted(self)
        dj = self._spec()["joints"]
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
        return check_sequences(
            X,
            frame_shape=(KINECT_V1.n_joints, N_COORDS),
            ndim=3,
            allow_nan=True,
            estimator=self,
            reset=reset,
        )

    def _spec(self):
        """Joint, link, triple and pair indices for the chosen joint set."""
        dj = get_descriptor_joints(self.joints)
        idx = KINECT_V1.indices
        keep = np.asarray(idx(dj.joints))
        pos_in_keep = {k: n for n, k in enumerate(keep)}
        return {
            "joints": dj,
            "keep": keep,
            "links": np.asarray([idx(link) for link in dj.links], dtype=np.intp),
            "triples": np.asarray(
                [[pos_in_keep[k] for k in idx(t)] for t in dj.triples], dtype=np.intp
            ),
            "torso": np.asarray([pos_in_keep[k] for k in idx(dj.torso)]),
            "left_right": [pos_in_keep[k] for k in idx(dj.left_right)],
            "spine": [pos_in_keep[k] for k in idx(dj.spine)],
            "pairs": np.asarray(dj.pairs, dtype=np.intp).reshape(-1, 2),
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
        T = len(seq)
        q, miss = self._prepare(seq)
        if miss.all():
            # No tracked frame: the standardised descriptor is all zeros.
            return np.broadcast_to(self.mean_, (T, self.n_features_out_)).copy()
        if self.link_normalisation:
            q = _link_normalise(
                q, spec["links"], self.link_lengths_, self.link_direction
            )
        P = q[:, spec["keep"]]
        if self.sigma > 0:
            P = _smooth_time(P, gaussian_kernel(self.sigma), self.border)
        Pp = _pad_time(P, 2, "replicate")
        vel = Pp[3 : T + 3] - Pp[1 : T + 1]
        acc = Pp[4 : T + 4] + Pp[0:T] - 2.0 * P
        u_x, u_z = _body_frame(P, spec["torso"], spec["left_right"], spec["spine"])
        incl, azim, bend = _angles(P, spec["triples"], u_x, u_z)
        dist = _distances(P, spec["pairs"])
        if self.distance_scale == "spine":
            lo, hi = spec["spine"]
            spine = _norm(P[:, hi] - P[:, lo])[:, None]
            dist = dist / np.where(spine > MIN_NORM, spine, 1.0)
        return np.concatenate(
            [
                P.reshape(T, -1),
                vel.reshape(T, -1),
                acc.reshape(T, -1),
                incl,
                azim,
                bend,
                dist,
            ],
            axis=1,
        )

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        tags.input_tags.allow_nan = True
        tags.requires_fit = True
        return tags
