"""JointFeatures: body-normalised joint positions and velocities per frame.

The input a practitioner gives a sequence network: every joint relative to the
hip, in units of the subject's own trunk length, plus its velocity. Unlike the
paper's :class:`~skgesture.PoseDescriptor` the features stay 3-D vectors
(xyz triples), so that augmentations such as a rotation about the vertical axis
apply to them directly (:class:`~skgesture.SkeletonAugmenter`).
"""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import check_is_fitted

from skgesture._descriptor._compute import _fill_missing
from skgesture._stream import DEFAULT_MAX_BACKFILL, Rows, StreamableMixin
from skgesture.layouts import KINECT_V1, N_COORDS, get_descriptor_joints
from skgesture.utils._buffers import (
    HeldFrames,
    RowBuffer,
    RunningMedian,
    _concat_rows,
)
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._validation import (
    SequenceOutputMixin,
    check_skeletons,
    check_stream_frames,
    mask_rows,
    missing_frames,
    sequence_tags,
)

__all__ = ["JointFeatures"]

ROOT = "HipCenter"
TRUNK_TOP = "ShoulderCenter"
MIN_TRUNK = 1e-6  # a trunk shorter than this (degenerate skeleton) scales by 1


def _joint_names(joints):
    """Joint names of a ``joints`` specification, in Kinect v1 storage order."""
    if isinstance(joints, str):
        names = get_descriptor_joints(joints).joints
    else:
        names = tuple(joints)
    idx = KINECT_V1.indices(names)  # raises naming an unknown joint
    if len(set(idx)) != len(idx):
        raise ValueError(f"joints has duplicates: {list(names)}")
    if ROOT not in names:
        raise ValueError(
            f"joints must contain the root {ROOT!r} (its row carries the hip "
            f"motion), got {list(names)}"
        )
    order = np.argsort(idx)
    return tuple(names[k] for k in order), np.asarray(idx)[order]


def _yaw_rotation(across):
    """Rotation about the vertical (y) axis putting the median hips along +x.

    ``across`` is the median left-to-right hip vector (HipRight - HipLeft).
    """
    norm = np.hypot(across[0], across[2])
    if norm < MIN_TRUNK:
        return np.eye(N_COORDS)
    c, s = across[0] / norm, across[2] / norm
    # Maps (c, ., s) to (1, ., 0).
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def joint_features(
    seq,
    joint_index,
    *,
    velocities=True,
    accelerations=False,
    align=False,
    fill="linear",
):
    """Normalised positions (and derivatives) of one raw sequence.

    Parameters
    ----------
    seq : ndarray of shape (n_frames, 20, 3)
        Raw skeleton sequence (Kinect v1 order); untracked frames are all zero
        or NaN.
    joint_index : ndarray of int
        Kinect v1 indices of the joints kept, the root among them.
    velocities, accelerations : bool
        Append first / second time differences (``numpy.gradient``).
    align : bool
        Rotate every sequence about the vertical axis so that its median
        left-to-right hip direction is the x axis.
    fill : {"linear", "hold"}
        How untracked frames are filled before differentiating.

    Returns
    -------
    ndarray of shape (n_frames, n_features)
        xyz triples: the joints (the root replaced by its offset from the
        sequence's median root position), then their derivatives; float32.
    """
    seq = np.asarray(seq, dtype=np.float64)
    n = len(seq)
    missing = missing_frames(seq)
    width = len(joint_index) * N_COORDS * (1 + velocities + accelerations)
    if missing.all():
        return np.zeros((n, width), dtype=np.float32)
    q = _fill_missing(np.nan_to_num(seq), missing, fill)
    stats = _statistics(_frame_quantities(q[~missing]), align)
    flat = _normalised(q, joint_index, stats)
    return _with_derivatives(flat, velocities, accelerations)


# The steps of joint_features, shared with the stream step of JointFeatures
# (JointFeatureStream, below), which applies them to the
# frames a row needs with the statistics of a trailing window.


def _frame_quantities(q):
    """Per-frame quantities behind the statistics: ``(n, 7)`` rows of the
    trunk length, the hip position and the left-to-right hip vector."""
    root, top = KINECT_V1.index(ROOT), KINECT_V1.index(TRUNK_TOP)
    left, right = KINECT_V1.index("HipLeft"), KINECT_V1.index("HipRight")
    out = np.empty((len(q), 7))
    out[:, 0] = np.linalg.norm(q[:, top] - q[:, root], axis=1)
    out[:, 1:4] = q[:, root]
    out[:, 4:7] = q[:, right] - q[:, left]
    return out


def _statistics(quantities, align, median=None):
    """``(scale, hip, rotation)`` from the quantities of the tracked frames: the
    median trunk length (1 if degenerate), the median hip position and, with
    ``align``, the yaw rotation of the median hip direction (else None).
    ``median``: the column medians, if known (a stream keeps them sorted)."""
    if median is None:
        median = np.median(quantities if align else quantities[:, :4], axis=0)
    scale = median[0] if median[0] > MIN_TRUNK else 1.0
    rotation = _yaw_rotation(median[4:7]) if align else None
    return scale, median[1:4], rotation


def _normalised(q, joint_index, stats):
    """Joints relative to the hip in trunk lengths (the root row: the hip's
    offset from the median hip), flattened to ``(n, 3 * n_joints)``."""
    scale, hip_median, rotation = stats
    root = KINECT_V1.index(ROOT)
    hip = q[:, root].copy()
    rel = q - hip[:, None, :]
    rel[:, root] = hip - hip_median
    if rotation is not None:
        rel = rel @ rotation.T
    return (rel[:, joint_index] / scale).reshape(len(q), -1)


def _with_derivatives(flat, velocities, accelerations):
    """``flat`` with its ``numpy.gradient`` velocities and accelerations, float32."""
    n = len(flat)
    parts = [flat]
    if velocities or accelerations:
        vel = np.gradient(flat, axis=0) if n > 1 else np.zeros_like(flat)
        if velocities:
            parts.append(vel)
        if accelerations:
            parts.append(np.gradient(vel, axis=0) if n > 1 else np.zeros_like(flat))
    return np.hstack(parts).astype(np.float32)


class JointFeatures(
    NewParamsMixin,
    StreamableMixin,
    SequenceOutputMixin,
    TransformerMixin,
    BaseEstimator,
    auto_wrap_output_keys=None,
):
    """Body-normalised joint positions and velocities of every frame.

    Per sequence: untracked frames are filled (as :class:`PoseDescriptor`
    does), every joint is taken relative to HipCenter and divided by the
    sequence's median HipCenter-ShoulderCenter length, the HipCenter row is
    replaced by the hip's offset from its median position (so whole-body
    motion such as a step is kept), and the per-frame velocities
    (``numpy.gradient`` along time) are appended. The result is a block of
    xyz triples: 66 features for the paper's 11 joints, 120 for all 20.

    These are the inputs of the recommended model
    (:func:`~skgesture.make_recommended`). The transformer has no learned
    statistics: standardisation happens in the tagger, after augmentation.

    Parameters
    ----------
    joints : {"paper11", "full20"} or sequence of str, default="paper11"
        Joints kept: the paper's 11 upper-body joints, all 20 Kinect v1
        joints, or a list of Kinect v1 joint names (HipCenter included).
    velocities : bool, default=True
        Append the velocity of every feature.
    accelerations : bool, default=False
        Append the acceleration of every feature.
    align : bool, default=False
        Rotate each sequence about the vertical axis so that the subject's
        median left-to-right hip direction is the x axis (removes the camera
        yaw, at the price of the orientation's estimation noise).
    fill : {"linear", "hold"}, default="linear"
        Filling of untracked frames before differentiation.
    statistics : {"sequence", "running"}, default="sequence"
        ``"sequence"``: offline, the statistics (median trunk length, hip
        position, hip direction) are the whole sequence's; live, those of a
        trailing window (``stream_stats_window``), so live rows differ from
        offline ones. ``"running"``: offline as live, every row is the live
        step's (:meth:`stream_init`) run over the sequence, with the
        statistics of the trailing window when the row is final: offline
        features equal streamed ones, exactly (requires ``fill="hold"``, the
        live rule for untracked frames).
    stream_stats_window : int, default=600
        The statistics of a row are those of the last
        ``stream_stats_window`` tracked frames received when it is emitted
        (600: 30 s at 20 fps), live, and offline with
        ``statistics="running"`` (docs/streaming.md, "The recommended model").
    stream_warmup : int, default=0
        Streaming only: the first rows wait until this many frames have
        arrived, so that their statistics rest on more frames (0: no wait; a
        longer wait changed nothing measurable, docs/streaming.md).

    Attributes
    ----------
    joint_names_ : tuple of str
        Joints kept, in Kinect v1 storage order (the feature order).
    n_features_out_ : int
        Number of features per frame.
    frame_shape_in_ : tuple of int
        Shape of one input frame seen in ``fit``, ``(20, 3)``.
    n_features_in_ : int
        Number of values per input frame (60).

    See Also
    --------
    PoseDescriptor : The paper's 183-D descriptor.
    SequenceTagger : The network these features feed in the recommended model.

    Notes
    -----
    Untracked frames are rest by construction (docs/design.md): a sequence
    with untracked frames is returned as a ``numpy.ma.MaskedArray`` whose
    masked rows are those frames. Input rules (finite values, magnitude at
    most 1e5) are those of :class:`PoseDescriptor`.

    Examples
    --------
    >>> from skgesture import JointFeatures
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> F = JointFeatures().fit_transform([X])
    >>> F[0].shape == (len(X), 66)
    True
    >>> JointFeatures(joints="full20").fit([X]).n_features_out_
    120
    """

    _parameter_constraints: dict = {
        "joints": [StrOptions({"paper11", "full20"}), list, tuple],
        "velocities": ["boolean"],
        "accelerations": ["boolean"],
        "align": ["boolean"],
        "fill": [StrOptions({"linear", "hold"})],
        "statistics": [StrOptions({"sequence", "running"})],
        "stream_stats_window": [Interval(Integral, 1, None, closed="left")],
        "stream_warmup": [Interval(Integral, 0, None, closed="left")],
    }

    def __init__(
        self,
        *,
        joints="paper11",
        velocities=True,
        accelerations=False,
        align=False,
        fill="linear",
        statistics="sequence",
        stream_stats_window=600,
        stream_warmup=0,
    ):
        self.joints = joints
        self.velocities = velocities
        self.accelerations = accelerations
        self.align = align
        self.fill = fill
        self.statistics = statistics
        self.stream_stats_window = stream_stats_window
        self.stream_warmup = stream_warmup

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Check the input and record the joint set.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeleton sequences (Kinect v1 joint order).
        y : None
            Ignored.

        Returns
        -------
        self : JointFeatures
            The fitted transformer.
        """
        check_skeletons(X, estimator=self, reset=True)
        if self.statistics == "running" and self.fill != "hold":
            raise ValueError(
                f"statistics='running' computes every row as the live step does, "
                f"which holds the last tracked frame over untracked ones: set "
                f"fill='hold' (got fill={self.fill!r})"
            )
        self.joint_names_, self._joint_index = _joint_names(self.joints)
        n_parts = 1 + self.velocities + self.accelerations
        self.n_features_out_ = len(self.joint_names_) * N_COORDS * n_parts
        return self

    def transform(self, X):
        """Compute the features of every frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeleton sequences.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_features_out_)
            The float32 features; a sequence with untracked frames comes as a
            ``numpy.ma.MaskedArray`` whose masked rows are those frames.
        """
        check_is_fitted(self)
        names, index = _joint_names(self.joints)
        if names != self.joint_names_:
            raise ValueError(
                f"joints was changed after fit ({list(self.joint_names_)} -> "
                f"{list(names)}); refit the features and every stage after them"
            )
        X = check_skeletons(X, estimator=self, reset=False)
        if getattr(self, "statistics", "sequence") == "running":
            return [self._running(seq, index) for seq in X]
        out = []
        for seq in X:
            feats = joint_features(
                seq,
                index,
                velocities=self.velocities,
                accelerations=self.accelerations,
                align=self.align,
                fill=self.fill,
            )
            out.append(mask_rows(feats, missing_frames(seq)))
        return out

    def _running(self, seq, index):
        """The live step's rows of one whole sequence (``statistics="running"``)."""
        from skgesture._stream import stream_frames

        state = JointFeatureStream(self, index)
        parts = [state.step(stream_frames(seq, 0)), state.flush()]
        data = np.concatenate([p.data for p in parts]).astype(np.float32, copy=False)
        return mask_rows(data, np.concatenate([p.mask for p in parts]))

    def get_feature_names_out(self, input_features=None):
        """Get the names of the features, e.g. ``"pos_HandRight_x"``, ``"vel_Head_y"``.

        Parameters
        ----------
        input_features : None
            Ignored; present for API consistency.

        Returns
        -------
        ndarray of str of shape (n_features_out_,)
            Feature names in output order.
        """
        check_is_fitted(self)
        kinds = ["pos"] + ["vel"] * self.velocities + ["acc"] * self.accelerations
        names = [
            f"{kind}_{joint}_{c}"
            for kind in kinds
            for joint in self.joint_names_
            for c in "xyz"
        ]
        return np.asarray(names, dtype=object)

    def __sklearn_tags__(self):
        return sequence_tags(super().__sklearn_tags__(), raw_skeletons=True)

    # -- incremental step (docs/design.md §4.1, "Incremental steps") -----------
    # StreamableMixin writes stream_init/step/flush; the state and the per-row
    # arithmetic are JointFeatureStream, below, built on the steps of
    # joint_features above.

    _stream_options = ("max_backfill",)

    def _stream_state(self, *, max_backfill=DEFAULT_MAX_BACKFILL):
        """A fresh state for one live stream (docs/design.md §4.1).

        Raw frames in, the feature rows that became final out. Every frame is
        checked as :meth:`transform` checks it (a bad one raises a
        ``ValueError`` naming its stream index, the state unchanged). Row
        ``t`` comes with frame ``t + 1`` (``t + 2`` with accelerations; the
        central differences of ``numpy.gradient``), the first rows not before
        frame ``stream_warmup - 1``, normalised with the statistics of the
        last ``stream_stats_window`` tracked frames received by then.
        Untracked frames hold the last tracked frame (the future is unknown;
        offline ``fill="hold"``) and come out masked.

        Parameters
        ----------
        max_backfill : int, default=64
            Untracked frames at the start of a stream that wait for the first
            tracked frame and become copies of it, as offline filling does;
            earlier ones are handed on at once as rest (masked zero rows).

        Returns
        -------
        JointFeatureStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.

        Examples
        --------
        >>> from skgesture import JointFeatures
        >>> from skgesture._stream import stream_frames
        >>> from skgesture.utils._testing import make_skeleton_stream
        >>> X, _ = make_skeleton_stream(random_state=0)
        >>> feats = JointFeatures(stream_warmup=0).fit([X])
        >>> state = feats.stream_init()
        >>> rows, state = feats.stream_step(state, stream_frames(X[:10], 0))
        >>> len(rows), feats.stream_lookahead  # rows 0..8 are final with frame 9
        (9, 1)
        >>> last, state = feats.stream_flush(state)
        >>> len(last), rows.data.shape[1] == feats.n_features_out_
        (1, True)
        """
        check_is_fitted(self)
        names, index = _joint_names(self.joints)
        if names != self.joint_names_:
            raise ValueError(
                f"joints was changed after fit ({list(self.joint_names_)} -> "
                f"{list(names)}); refit the features and every stage after them"
            )
        return JointFeatureStream(self, index, max_backfill=max_backfill)

    @property
    def stream_lookahead(self):
        """Frames after a frame that its row needs (1; 2 with accelerations).

        The central differences of ``numpy.gradient``; 0 without velocities
        and accelerations.
        """
        return 2 if self.accelerations else int(bool(self.velocities))


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

    def __init__(self, feats, index, max_backfill=DEFAULT_MAX_BACKFILL):
        self.estimator = feats
        self.quantities = _frame_quantities
        self.statistics = _statistics
        self.normalised = _normalised
        self.derivatives = _with_derivatives
        self.index = index
        self.root = KINECT_V1.index(ROOT)
        self.root_column = int(np.flatnonzero(np.asarray(index) == self.root)[0])
        self.velocities = bool(feats.velocities)
        self.accelerations = bool(feats.accelerations)
        self.align = bool(feats.align)
        self.a = 2 if self.accelerations else int(self.velocities)
        # (getattr: a model saved before these parameters existed streams too)
        self.window = int(getattr(feats, "stream_stats_window", 600))
        self.ready = int(getattr(feats, "stream_warmup", 0)) - 1  # ends the warm-up
        self.width = int(feats.n_features_out_)
        self.max_backfill = int(max_backfill)
        self.held_frames = HeldFrames(max_backfill)
        self.R = self.held_frames.frames  # filled raw frames, from p0
        self.untracked = self.held_frames.untracked
        self.times = self.held_frames.times
        self.Q = RowBuffer((7,), capacity=64)  # quantities of the tracked frames
        self.Q_frame = RowBuffer((), dtype=np.int64, capacity=64)  # their frames
        self.n_out = 0
        self.p0 = None  # first frame with a filled raw frame
        self.f = None  # first tracked frame
        self.medians = RunningMedian(7 if self.align else 4, self.window)
        self.cached = (None, None)  # (tracked frames used, statistics)

    def step(self, rows):
        """Raw frames in (checked as offline); the feature rows that became
        final out."""
        frames = check_stream_frames(rows.data, int(rows.time[0]), self.estimator)
        out, first, untracked = self.held_frames.push(
            frames, rows.time, self.n_out, self._zeros
        )
        tracked = ~untracked
        if tracked.any():
            self.Q.append(self.quantities(frames[tracked]))
            self.Q_frame.append(first + np.flatnonzero(tracked))
        if self.held_frames.p0 is None:
            return _concat_rows(out, (self.width,), np.float32)
        self.p0, self.f = self.held_frames.p0, self.held_frames.first_tracked
        out.append(self._advance())
        return _concat_rows(out, (self.width,), np.float32)

    def flush(self):
        """The remaining rows, the end rows with one-sided differences."""
        if self.p0 is None:
            return self._zeros(self.held_frames.n_in)
        return self._emit(self.n_out, self.held_frames.n_in, self.held_frames.n_in - 1)

    def _advance(self):
        """Rows final with the frames received: row ``t`` at frame
        ``max(t + a, first tracked frame, end of warm-up)``."""
        now = self.held_frames.n_in - 1
        start = max(self.f, self.ready)
        if now < start:
            return Rows.empty((self.width,), np.float32)
        parts = []
        # Rows whose derivatives were complete before the warm-up ended (or
        # the first tracked frame arrived) share the statistics of that frame.
        shared = min(start - self.a + 1, now - self.a + 1)
        if shared > self.n_out:
            parts.append(self._emit(self.n_out, shared, start))
        parts.append(self._emit_each(self.n_out, now - self.a + 1))
        return _concat_rows(parts, (self.width,), np.float32)

    def _emit_each(self, lo, hi):
        """Rows ``lo .. hi - 1``, row ``t`` with the statistics at frame ``t + a``.

        Velocities alone (``a`` = 1) without ``align``: the rows whose three
        frames are all filled are computed at once (:meth:`_emit_batch`), with
        the arithmetic of :meth:`_emit`, value for value; the others one by one.
        """
        a = self.a
        batch = a == 1 and self.velocities and not self.align
        first = min(hi, max(lo, self.p0 + a)) if batch else hi
        parts = [self._emit(t, t + 1, t + a) for t in range(lo, first)]
        if first < hi:
            parts.append(self._emit_batch(first, hi))
        return _concat_rows(parts, (self.width,), np.float32)

    def _emit_batch(self, lo, hi):
        """Rows ``lo .. hi - 1`` (``a`` = 1, no ``align``), each with the
        statistics at its next frame: :meth:`_emit` on every row's three
        frames (``_normalised``, then ``numpy.gradient``'s central difference),
        vectorised over the rows."""
        n = hi - lo
        stats = [self._stats(t + 1) for t in range(lo, hi)]
        scale = np.array([s[0] for s in stats], dtype=np.float64)[:, None, None]
        hip_median = np.array([s[1] for s in stats], dtype=np.float64)
        q = self.R.data(lo - 1, hi + 1)  # frames lo - 1 .. hi
        hip = q[:, self.root].copy()
        rel = (q - hip[:, None, :])[:, self.index]

        def normalised(d):  # frames t + d, with the statistics of row t
            p = rel[1 + d : 1 + d + n].copy()
            p[:, self.root_column] = hip[1 + d : 1 + d + n] - hip_median
            return (p / scale).reshape(n, -1)

        before, flat, after = normalised(-1), normalised(0), normalised(1)
        data = np.hstack([flat, (after - before) / 2.0]).astype(np.float32)
        rows = Rows(
            data,
            self.untracked.data(lo, hi).copy(),
            self.times.data(lo + 1, hi + 1).copy(),
        )
        self.n_out = hi
        self._trim()
        return rows

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
