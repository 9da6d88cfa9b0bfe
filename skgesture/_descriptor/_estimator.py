"""PoseDescriptor: the paper's per-frame pose descriptor (docs/method.md §3)."""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from numbers import Real

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import check_is_fitted

from skgesture._descriptor._compute import (
    _ROOT,
    _angles,
    _batches,
    _body_frame_planes,
    _compiled_kernel,
    _derivatives,
    _distances_planes,
    _feature_groups,
    _fill_missing,
    _link_normalise_planes,
    _mean_std,
    _norm,
    _pair_runs,
    _planes,
    _segment_offsets,
    _sequence_planes,
    _smoothed,
    _standardise,
    gaussian_kernel,
)
from skgesture._descriptor._constants import (
    BATCH_VALUES,
    DERIVATIVE_REACH,
    EDGE,
    GAUSSIAN_SIZE,
    MIN_NORM,
    MIN_SCALE,
)
from skgesture._descriptor._stream import DescriptorStream
from skgesture._stream import DEFAULT_MAX_BACKFILL, StreamableMixin
from skgesture.layouts import (
    KINECT_V1,
    N_COORDS,
    DescriptorJoints,
    get_descriptor_joints,
)
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._validation import (
    SequenceOutputMixin,
    check_skeletons,
    mask_rows,
    missing_frames,
    sequence_tags,
)

__all__ = ["PoseDescriptor"]


class PoseDescriptor(
    NewParamsMixin,
    StreamableMixin,
    SequenceOutputMixin,
    TransformerMixin,
    BaseEstimator,
    auto_wrap_output_keys=None,
):
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
        X = check_skeletons(X, estimator=self, reset=True)
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
        X = check_skeletons(X, estimator=self, reset=False)
        out = self._describe_all(X, spec, standardize=True)
        return [mask_rows(out[i], missing_frames(seq)) for i, seq in enumerate(X)]

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
        return sequence_tags(super().__sklearn_tags__(), raw_skeletons=True)

    # -- incremental step (docs/design.md, "Incremental steps") ----------------
    # StreamableMixin writes stream_init/step/flush; the state is
    # DescriptorStream (skgesture/_descriptor/_stream.py), which computes rows
    # with _describe_all, as transform does.

    _stream_options = ("max_backfill",)

    def _stream_state(self, *, max_backfill=DEFAULT_MAX_BACKFILL):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Raw frames in, the descriptor rows that became final out: every frame
        is checked as :meth:`transform` checks it (a bad one raises a
        ``ValueError`` naming its stream index, the state unchanged);
        untracked frames hold the last tracked frame (``fill="hold"``: the
        future is unknown) and come out masked.

        Parameters
        ----------
        max_backfill : int, default=64
            Untracked frames at the start of a stream that wait for the first
            tracked frame and become copies of it, as offline filling does;
            earlier ones are handed on at once as rest (all-zero masked rows).

        Returns
        -------
        DescriptorStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.

        Examples
        --------
        >>> from skgesture import PoseDescriptor
        >>> from skgesture._stream import stream_frames
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
        check_is_fitted(self)
        spec = self._spec()
        self._check_joints(spec)

        def describe(seq):
            return self._describe_all([seq], spec, standardize=True)[0]

        return DescriptorStream(
            describe,
            spec["joints"].n_features,
            self.stream_lookahead,
            self,
            max_backfill=max_backfill,
        )

    @property
    def stream_lookahead(self):
        """Frames after a frame that its descriptor needs (4; 2 if ``sigma=0``)."""
        return (GAUSSIAN_SIZE - 1) // 2 * int(self.sigma > 0) + DERIVATIVE_REACH
