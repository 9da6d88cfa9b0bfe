"""Synthetic Montalbano-like gesture streams of a 20-joint Kinect v1 skeleton.

The generator builds, for every sequence, smooth joint-angle tracks for the
whole stream (rests with idle sway, gesture instances, out-of-vocabulary
motions) and turns them into joint positions with one forward-kinematics pass
vectorised over the frames. Timing statistics follow the LAP 2014 Track 3
validation labels (``shared/data/chalearn_montalbano/PROVENANCE.md``).

Two design choices are worth knowing. Gesture classes are fixed: the class
prototypes come from a private generator with a constant seed, so
``gesture_05`` is the same motion whatever ``random_state`` is, and streams
drawn with two seeds can serve as a training and a test set. And only the
structure of a stream (subjects, timeline, keyframes) is drawn from the
``RandomState`` given by the user; the bulk sensor noise and the per-frame
dropout draws come from a :class:`numpy.random.Generator` seeded from it, which
is faster for ~10^8 normal variates and keeps one ``random_state`` in control
of everything.
"""

# SPDX-License-Identifier: BSD-3-Clause

from functools import lru_cache
from numbers import Integral, Real

import numpy as np
from scipy.interpolate import PchipInterpolator
from sklearn.utils import Bunch, check_random_state

from skgesture.layouts import KINECT_V1, N_COORDS, N_KINECT_JOINTS
from skgesture.utils._segments import segments_to_labels

__all__ = ["make_gesture_streams"]

# --- timing statistics of the LAP 2014 Track 3 validation labels (PROVENANCE.md:
# 230 sequences, 3454 gestures), all in frames at the reference frame rate.
REFERENCE_FPS = 20.0  # every Montalbano sample is recorded at 20 fps
GESTURE_LEN_MEDIAN = 39.0  # median gesture length
GESTURE_LEN_LOG_SD = 0.245  # std of log(length), measured 0.245
GESTURE_LEN_RANGE = (6, 96)  # shortest and longest labelled gesture
CLASS_LEN_LOG_SD = 0.10  # per-class median lengths span 30-47 frames
SUBJECT_SPEED_LOG_SD = 0.10  # a subject's overall speed factor
INSTANCE_LEN_LOG_SD = float(
    np.sqrt(GESTURE_LEN_LOG_SD**2 - CLASS_LEN_LOG_SD**2 - SUBJECT_SPEED_LOG_SD**2)
)
GAP_ZERO_PROB = 0.086  # fraction of consecutive gestures with no rest between
GAP_POSITIVE_MEDIAN = 30.0  # median of the non-zero gaps (overall median 27)
GAP_LOG_SD = 1.05  # from the inter-quartile and 90 % range of the non-zero gaps
GAP_MAX = 660  # longest gap
LEAD_MEDIAN, LEAD_LOG_SD, LEAD_MAX = 44.0, 1.0, 417  # rest before the 1st gesture
TAIL_MEDIAN, TAIL_LOG_SD, TAIL_MAX = 32.0, 1.0, 339  # rest after the last gesture
EDGE_REST_MIN = 2  # shortest lead-in / tail rest (5th percentile of both)
DEFAULT_N_GESTURES = (8, 22)  # gestures per sequence, min and max

# --- classes
MAX_CLASSES = 50  # the prototype table holds this many classes
PROTOTYPE_SEED = 20140906  # fixed: classes do not depend on random_state
# (a, b): class b is class a with a small change of its last pose, as classes
# 14 and 15 of Montalbano, which the paper reports as the most confused pair.
SIMILAR_PAIRS = ((14, 15), (5, 6))
SIMILAR_DELTA_DEG = (-12.0, 0.0, 0.0, 28.0, 20.0)  # change of the last pose
MIN_PROTOTYPE_DISTANCE = 0.30  # metres, between hand-trajectory descriptors
# (kind, weight): one-handed (right arm; the left arm of left-handed subjects),
# both arms mirror-symmetric, both arms independent, the arms taking turns.
PROTOTYPE_KINDS = (("right", 3), ("mirror", 1), ("both", 1), ("alternate", 1))
N_POSES_RANGE = (2, 5)  # distinct poses of a class, high end exclusive
REPEAT_RATE = 0.3  # fraction of classes that go to and fro between two poses
REPEAT_POSES = 2
MIRROR_JITTER_DEG = 4.0  # how far the two arms of a "mirror" class differ
PROTOTYPE_TIME_JITTER = 0.03  # of the evenly spaced pose times
LEFT_HANDED_RATE = 0.1  # fraction of subjects who gesture with the left hand

# --- skeleton, body frame: x = subject's left, y = up, z = away from the sensor,
# origin at HipCenter. Lengths (metres) and directions are the medians of the
# five real Montalbano skeletons in shared/data.
ARM_LENGTHS = (0.275, 0.25, 0.10)  # shoulder-elbow, elbow-wrist, wrist-hand
# joint: (parent, length, direction) for the rigid part of the left side and
# the spine; right-side joints mirror x.
RIGID_BONES = (
    ("Spine", "HipCenter", 0.08, (0.0, 0.75, 0.66)),
    ("ShoulderCenter", "Spine", 0.36, (0.0, 1.0, -0.08)),
    ("Head", "ShoulderCenter", 0.20, (0.0, 0.95, -0.30)),
    ("ShoulderLeft", "ShoulderCenter", 0.20, (0.82, -0.57, 0.0)),
    ("HipLeft", "HipCenter", 0.107, (0.68, -0.72, -0.12)),
    ("KneeLeft", "HipLeft", 0.42, (0.15, -0.98, 0.10)),
    ("AnkleLeft", "KneeLeft", 0.33, (0.07, -0.96, 0.25)),
    ("FootLeft", "AnkleLeft", 0.10, (0.0, -0.55, -0.83)),
)
BODY_SCALE_LOG_SD = 0.06  # overall body size
BONE_SCALE_LOG_SD = 0.04  # each bone on top of it

# --- arm angles, degrees: [flexion, abduction, twist, elbow, wrist] per arm;
# columns 0-4 are the left arm, 5-9 the right arm.
N_ARM_ANGLES = 5
N_ANGLES = 2 * N_ARM_ANGLES
_LEFT, _RIGHT = slice(0, N_ARM_ANGLES), slice(N_ARM_ANGLES, N_ANGLES)
REST_DOWN_DEG = (8.0, 14.0, 10.0, 18.0, 5.0)  # arms hanging
REST_CLASPED_DEG = (15.0, 5.0, 40.0, 80.0, 10.0)  # hands held before the belly
CLASPED_REST_RATE = 0.25  # fraction of subjects resting with clasped hands
GESTURE_LOW_DEG = (20.0, -10.0, -30.0, 20.0, -30.0)  # prototype pose range
GESTURE_HIGH_DEG = (120.0, 60.0, 70.0, 130.0, 40.0)
JOINT_LIMITS_DEG = (
    (-20.0, -20.0, -80.0, 0.0, -60.0),
    (175.0, 120.0, 90.0, 150.0, 60.0),
)  # low and high joint limits, applied after the per-instance jitter
MIN_PEAK_FLEXION_DEG = 45.0  # every gesture raises the arm at least this much

# --- per-instance variation
KEY_JITTER_DEG = 15.0  # std of each pose angle of a gesture instance
KEY_TIME_JITTER = 0.015  # std of keyframe times, as a fraction of the gesture
TIME_WARP = 0.4  # largest |a| of the monotone time warp u + a u (1 - u)
KEY_TIME_LIMITS = (0.03, 0.97)  # poses stay strictly inside the gesture
AMPLITUDE_LOG_SD = 0.15  # per instance, scales the pose's distance from rest
SUBJECT_AMPLITUDE_LOG_SD = 0.08
KEY_TIME_RANGE = (0.18, 0.82)  # first/last pose times within a gesture
MIN_KEY_SEPARATION = 0.02  # between pose times, as a fraction of the gesture
FIT_GESTURE_SHARE = 0.7  # with a fixed n_frames, gestures fill at most this share

# --- rests and idle motion
REST_JITTER_DEG = 3.0  # a subject's rest pose differs each time a little
REST_KEY_SPACING = 40  # frames between idle-sway keyframes during a rest
SWAY_ARM_DEG = 1.5  # amplitude of the slow arm sway
SWAY_FREQ_HZ = (0.1, 0.5)
BREATH_DEG = 0.6  # torso pitch of breathing
BREATH_FREQ_HZ = (0.2, 0.3)
TORSO_SWAY_DEG = (1.0, 0.8, 1.5)  # pitch, roll, yaw of the upper body
ROOT_SWAY_M = (0.015, 0.004, 0.015)  # slow drift of the whole body

_SWAY_AMPLITUDE = np.concatenate([
    np.full(N_ANGLES, np.radians(SWAY_ARM_DEG)), np.radians(TORSO_SWAY_DEG),
    [np.radians(BREATH_DEG)], ROOT_SWAY_M,
])  # fmt: skip
_SWAY_FREQ_LOW, _SWAY_FREQ_HIGH = (
    np.concatenate([np.full(N_ANGLES + 3, SWAY_FREQ_HZ[i]), [BREATH_FREQ_HZ[i]],
                    np.full(3, SWAY_FREQ_HZ[i])])
    for i in (0, 1)
)  # fmt: skip
_SWAY_SPLITS = (N_ANGLES, N_ANGLES + 3, N_ANGLES + 4)  # arm | torso | breath | root

# --- out-of-vocabulary motions (labelled 0)
OOV_MIN_REST = 30  # a rest must be this long to hold one
OOV_MARGIN = 4  # frames of rest kept on each side of it
OOV_LEN_MEDIAN, OOV_LEN_LOG_SD, OOV_LEN_MIN = 28.0, 0.3, 8
OOV_AMPLITUDE = (0.4, 1.0)  # fraction of a random pose's distance from rest
OOV_ARM_PROBS = (0.3, 0.5, 0.2)  # left arm, right arm, both
OOV_N_KEYS_RANGE = (1, 4)  # poses of one motion, high end exclusive
OOV_KEY_RANGE = (0.2, 0.8)  # pose times within the motion

# --- placement in front of the sensor (camera space, metres / degrees)
ROOT_LOW = (-0.3, -0.15, 2.0)  # HipCenter x, y, z: uniform between these
ROOT_HIGH = (0.3, 0.35, 3.0)  # (z = 2-3 m, as in the Montalbano recordings)
YAW_SD_DEG, YAW_MAX_DEG = 10.0, 25.0
CAMERA_PITCH_MAX_DEG = 4.0

# --- tracking dropouts
DROPOUT_LEN_RANGE = (1, 5)  # frames, inclusive
ACQUISITION_MAX = 4  # untracked frames at the start, as in every real sample

_J = {name: i for i, name in enumerate(KINECT_V1.joint_names)}
# The upper body (Spine .. HandRight) and each arm's elbow, wrist and hand are
# contiguous in the NUI order, so slices replace fancy indexing.
_UPPER = slice(_J["Spine"], _J["HandRight"] + 1)
_ARMS = {s: slice(_J[f"Elbow{s}"], _J[f"Hand{s}"] + 1) for s in ("Left", "Right")}
_STILL = np.array(
    [j for j in range(N_KINECT_JOINTS) if not _UPPER.start <= j < _UPPER.stop]
)  # HipCenter and the legs
_CANONICAL_REST = np.tile(np.radians(REST_DOWN_DEG), 2)
_LIMIT_LOW, _LIMIT_HIGH = (np.tile(np.radians(lim), 2) for lim in JOINT_LIMITS_DEG)
_BONE_TYPES = tuple(b[0].replace("Left", "") for b in RIGID_BONES) + (
    "UpperArm", "Forearm", "Hand",
)  # fmt: skip


# ---------------------------------------------------------------------------
# kinematics
# ---------------------------------------------------------------------------


def _arm_offsets(angles, lengths):
    """Elbow, wrist and hand offsets from the shoulder of a canonical left arm.

    Parameters
    ----------
    angles : ndarray of shape (n_frames, 5)
        Flexion (forward raise), abduction (sideways raise), twist (rotation
        about the upper arm), elbow flexion and wrist flexion, in radians.
    lengths : sequence of 3 float
        Upper arm, forearm and hand lengths.

    Returns
    -------
    ndarray of shape (n_frames, 3, 3)
        Offsets of elbow, wrist and hand from the shoulder, body frame. A right
        arm is the same with x negated.
    """
    flex, abd, twist, elbow, wrist = angles.T
    cf, sf = np.cos(flex), np.sin(flex)
    ca, sa = np.cos(abd), np.sin(abd)
    ct, st = np.cos(twist), np.sin(twist)
    se, ce = np.sin(elbow), np.cos(elbow)
    sw, cw = np.sin(elbow + wrist), np.cos(elbow + wrist)

    def shoulder(vx, vy, vz):
        # Rx(flex) @ Rz(abd) @ v: abduct in the frontal plane, then raise forward.
        x = vx * ca - vy * sa
        y = vx * sa + vy * ca
        return np.stack([x, y * cf - vz * sf, y * sf + vz * cf], axis=-1)

    upper = shoulder(0.0, -1.0, 0.0)
    # The elbow bends forward; twisting the upper arm turns the bending plane.
    fore = shoulder(-se * st, -ce, -se * ct)
    hand = shoulder(-sw * st, -cw, -sw * ct)
    out = np.empty((len(flex), 3, 3))
    out[:, 0] = lengths[0] * upper
    out[:, 1] = out[:, 0] + lengths[1] * fore
    out[:, 2] = out[:, 1] + lengths[2] * hand
    return out


def _rotation(pitch, roll, yaw):
    """Rotation matrices ``Ry(yaw) @ Rx(pitch) @ Rz(roll)``, broadcast over frames.

    Parameters
    ----------
    pitch, roll, yaw : float or ndarray of shape (n_frames,)
        Angles in radians about the x, z and y axes.

    Returns
    -------
    ndarray of shape (..., 3, 3)
        The rotation matrices.
    """
    pitch, roll, yaw = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (pitch, roll, yaw))
    )
    cp, sp = np.cos(pitch), np.sin(pitch)
    cr, sr = np.cos(roll), np.sin(roll)
    cy, sy = np.cos(yaw), np.sin(yaw)
    rows = (
        (cy * cr + sy * sp * sr, sy * sp * cr - cy * sr, sy * cp),
        (cp * sr, cp * cr, -sp),
        (cy * sp * sr - sy * cr, sy * sr + cy * sp * cr, cy * cp),
    )
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def _rest_skeleton(bone_scale):
    """Joint positions of the rigid body parts (arms excluded), body frame.

    Parameters
    ----------
    bone_scale : dict
        Length factor of each bone type (``"Spine"``, ``"UpperArm"``, ...).

    Returns
    -------
    ndarray of shape (20, 3)
        Positions; arm joints other than the shoulders are left at zero.
    """
    pos = np.zeros((N_KINECT_JOINTS, N_COORDS))
    mirror = np.array([-1.0, 1.0, 1.0])
    for name, parent, length, direction in RIGID_BONES:
        d = np.asarray(direction) / np.linalg.norm(direction)
        off = length * bone_scale[name.replace("Left", "")] * d
        pos[_J[name]] = pos[_J[parent]] + off
        if name.endswith("Left"):
            pos[_J[name.replace("Left", "Right")]] = (
                pos[_J[parent.replace("Left", "Right")]] + off * mirror
            )
    return pos


def _forward_kinematics(arm_angles, torso_angles, body, root_rot, root_pos, out=None):
    """Joint positions in camera space of one stream, vectorised over frames.

    Parameters
    ----------
    arm_angles : ndarray of shape (n_frames, 10)
        Left then right arm angles in radians (see :func:`_arm_offsets`).
    torso_angles : ndarray of shape (n_frames, 3)
        Pitch, roll and yaw of the upper body about HipCenter, radians.
    body : dict
        ``"rest"`` (20, 3) rigid skeleton and ``"arm_lengths"`` (3,).
    root_rot : ndarray of shape (3, 3)
        Body-to-camera rotation (subject yaw and sensor tilt).
    root_pos : ndarray of shape (n_frames, 3)
        HipCenter position in camera space.
    out : ndarray of shape (n_frames, 20, 3) or None, default=None
        If given, the positions are added to it in place (the sensor noise).

    Returns
    -------
    ndarray of shape (n_frames, 20, 3)
        Joint positions (``out`` when given).
    """
    n = len(arm_angles)
    rest = body["rest"]
    upper = np.empty((n, _UPPER.stop - _UPPER.start, N_COORDS))
    upper[:] = rest[_UPPER]
    for side, cols, sign in (("Left", _LEFT, 1.0), ("Right", _RIGHT, -1.0)):
        arm = slice(_ARMS[side].start - _UPPER.start, _ARMS[side].stop - _UPPER.start)
        off = _arm_offsets(arm_angles[:, cols], body["arm_lengths"])
        off[..., 0] *= sign  # a right arm mirrors the canonical left arm
        upper[:, arm] = rest[_J[f"Shoulder{side}"]] + off
    # the torso sways about HipCenter (the origin), then the body is placed
    rot = root_rot @ _rotation(*torso_angles.T)
    if out is None:
        out = np.zeros((n, N_KINECT_JOINTS, N_COORDS))
    for i in range(N_COORDS):
        out[:, _UPPER, i] += (
            rot[:, i, 0, None] * upper[..., 0]
            + rot[:, i, 1, None] * upper[..., 1]
            + rot[:, i, 2, None] * upper[..., 2]
            + root_pos[:, i, None]
        )
    out[:, _STILL] += rest[_STILL] @ root_rot.T + root_pos[:, None, :]
    return out


# ---------------------------------------------------------------------------
# class prototypes
# ---------------------------------------------------------------------------


def _random_pose(rng, size=()):
    """Uniform arm pose(s) in the gesture range, radians."""
    low, high = np.radians(GESTURE_LOW_DEG), np.radians(GESTURE_HIGH_DEG)
    return rng.uniform(low, high, size=tuple(np.atleast_1d(size)) + (N_ARM_ANGLES,))


def _draw_prototype(rng):
    """One class: keyframe poses (NaN on an idle arm), times, length factor."""
    kinds, weights = zip(*PROTOTYPE_KINDS)
    kind = kinds[rng.choice(len(kinds), p=np.array(weights) / sum(weights))]
    repeat = rng.rand() < REPEAT_RATE
    n_poses = REPEAT_POSES if repeat else rng.randint(*N_POSES_RANGE)
    right = _random_pose(rng, n_poses)
    while np.degrees(right[:, 0].max()) < MIN_PEAK_FLEXION_DEG:
        right = _random_pose(rng, n_poses)
    if kind == "right":
        left = np.full_like(right, np.nan)
    elif kind == "mirror":
        left = right + np.radians(rng.normal(0.0, MIRROR_JITTER_DEG, right.shape))
    elif kind == "both":
        left = _random_pose(rng, n_poses)
    else:  # "alternate": the arms take turns
        left = np.roll(right, 1, axis=0)
    keys = np.concatenate([left, right], axis=1)
    if repeat:  # a to-and-fro motion: A B A B
        keys = np.concatenate([keys, keys], axis=0)
    n_keys = len(keys)
    times = np.linspace(*KEY_TIME_RANGE, n_keys)
    times += rng.uniform(-PROTOTYPE_TIME_JITTER, PROTOTYPE_TIME_JITTER, n_keys)
    log_len = rng.normal(0.0, CLASS_LEN_LOG_SD)
    return {"keys": keys, "times": np.sort(times), "log_len": log_len}


def _prototype_descriptor(proto):
    """Hand trajectories of a prototype at eight instants, for distinctness."""
    rest = np.tile(np.radians(REST_DOWN_DEG), 2)
    keys = np.where(np.isnan(proto["keys"]), rest, proto["keys"])
    grid = np.linspace(0.0, 1.0, 8)
    t = np.concatenate([[0.0], proto["times"], [1.0]])
    k = np.vstack([rest, keys, rest])
    ang = np.stack([np.interp(grid, t, k[:, j]) for j in range(N_ANGLES)], axis=1)
    hands = []
    for cols in (_LEFT, _RIGHT):
        hands.append(_arm_offsets(ang[:, cols], ARM_LENGTHS)[:, 2])
    return np.concatenate(hands, axis=1).ravel()


@lru_cache(maxsize=1)
def _prototypes():
    """The fixed table of ``MAX_CLASSES`` class prototypes (same for every seed)."""
    rng = np.random.RandomState(PROTOTYPE_SEED)
    protos, descs = [], []
    similar = {b: a for a, b in SIMILAR_PAIRS}
    while len(protos) < MAX_CLASSES:
        cls = len(protos) + 1
        if cls in similar:
            src = protos[similar[cls] - 1]
            proto = {k: np.array(v, copy=True) for k, v in src.items()}
            delta = np.radians(SIMILAR_DELTA_DEG)
            active = ~np.isnan(proto["keys"][-1])
            proto["keys"][-1] += np.tile(delta, 2) * active
        else:
            proto = _draw_prototype(rng)
            desc = _prototype_descriptor(proto)
            if descs and min(np.linalg.norm(desc - d) for d in descs) < (
                MIN_PROTOTYPE_DISTANCE
            ):
                continue
        protos.append(proto)
        descs.append(_prototype_descriptor(proto))
    for proto in protos:
        for v in proto.values():
            if isinstance(v, np.ndarray):
                v.flags.writeable = False
    return tuple(protos)


# ---------------------------------------------------------------------------
# subjects and timelines
# ---------------------------------------------------------------------------


def _draw_subject(rng):
    """Body, rest pose, handedness, speed and amplitude of one subject."""
    size = np.exp(rng.normal(0.0, BODY_SCALE_LOG_SD))
    scale = {b: size * np.exp(rng.normal(0.0, BONE_SCALE_LOG_SD)) for b in _BONE_TYPES}
    clasped = rng.rand() < CLASPED_REST_RATE
    rest_arm = np.radians(REST_CLASPED_DEG if clasped else REST_DOWN_DEG)
    return {
        "body": {
            "rest": _rest_skeleton(scale),
            "arm_lengths": np.array(ARM_LENGTHS)
            * [scale["UpperArm"], scale["Forearm"], scale["Hand"]],
        },
        "rest": np.tile(rest_arm, 2),
        "left_handed": rng.rand() < LEFT_HANDED_RATE,
        "log_speed": rng.normal(0.0, SUBJECT_SPEED_LOG_SD),
        "log_amplitude": rng.normal(0.0, SUBJECT_AMPLITUDE_LOG_SD),
    }


def _lognormal_frames(rng, median, log_sd, size, scale):
    """Log-normal durations in frames, rounded, at ``scale`` times 20 fps."""
    return np.rint(np.exp(rng.normal(np.log(median), log_sd, size)) * scale)


def _draw_timeline(rng, classes, subject, scale, oov_rate, n_frames=None):
    """Gesture lengths, rests and out-of-vocabulary motions of one stream.

    Returns
    -------
    lengths : ndarray of shape (n_gestures,)
        Gesture lengths in frames.
    rests : ndarray of shape (n_gestures + 1,)
        Lead-in, gaps and tail, in frames.
    oov : dict
        Rest index -> (offset, length) of the out-of-vocabulary motion in it.
    """
    protos = _prototypes()
    n_g = len(classes)
    lo, hi = (max(1, round(v * scale)) for v in GESTURE_LEN_RANGE)
    log_len = np.array([protos[c - 1]["log_len"] for c in classes])
    log_len = log_len + subject["log_speed"]
    log_len = log_len + rng.normal(0.0, INSTANCE_LEN_LOG_SD, n_g)
    lengths = np.clip(np.rint(GESTURE_LEN_MEDIAN * scale * np.exp(log_len)), lo, hi)
    gaps = _lognormal_frames(rng, GAP_POSITIVE_MEDIAN, GAP_LOG_SD, n_g - 1, scale)
    gaps = np.clip(gaps, 1, max(1, round(GAP_MAX * scale)))
    # back-to-back gestures, but never two of one class: labels would merge them
    gaps[(rng.rand(n_g - 1) < GAP_ZERO_PROB) & (classes[1:] != classes[:-1])] = 0
    edge_min = max(1, round(EDGE_REST_MIN * scale))
    lead = np.clip(
        _lognormal_frames(rng, LEAD_MEDIAN, LEAD_LOG_SD, 1, scale),
        edge_min, max(edge_min, round(LEAD_MAX * scale)),
    )  # fmt: skip
    tail = np.clip(
        _lognormal_frames(rng, TAIL_MEDIAN, TAIL_LOG_SD, 1, scale),
        edge_min, max(edge_min, round(TAIL_MAX * scale)),
    )  # fmt: skip
    rests = np.concatenate([lead, gaps, tail])
    if n_frames is not None:
        lengths, rests = _fit_to_length(lengths, rests, n_frames, lo)
    lengths, rests = lengths.astype(np.int64), rests.astype(np.int64)

    oov = {}
    margin = max(1, round(OOV_MARGIN * scale))
    min_len = max(2, round(OOV_LEN_MIN * scale))
    eligible = np.flatnonzero(rests >= max(OOV_MIN_REST * scale, 2 * margin + min_len))
    n_oov = min(rng.binomial(n_g, oov_rate), len(eligible))
    for r in np.sort(rng.choice(eligible, n_oov, replace=False)):
        room = rests[r] - 2 * margin
        length = _lognormal_frames(rng, OOV_LEN_MEDIAN, OOV_LEN_LOG_SD, None, scale)
        length = int(np.clip(length, min_len, room))
        offset = margin + rng.randint(0, room - length + 1)
        oov[int(r)] = (offset, length)
    return lengths, rests, oov


def _fit_to_length(lengths, rests, n_frames, min_len):
    """Shrink gestures and rescale rests so the stream has ``n_frames`` frames.

    Gestures keep at least ``min_len`` frames and take at most about 70 % of
    the stream; every rest keeps at least one frame.
    """
    n_g, n_r = len(lengths), len(rests)
    floor = n_g * min_len
    if n_frames < floor + n_r:
        raise ValueError(
            f"n_frames={n_frames} is too short for {n_g} gestures: at least "
            f"{floor + n_r} frames are needed"
        )
    budget = min(max(int(FIT_GESTURE_SHARE * n_frames), floor), n_frames - n_r)
    if lengths.sum() > budget:
        spare = (lengths - min_len) * (budget - floor) / max(lengths.sum() - floor, 1)
        lengths = min_len + np.floor(spare)
    room = n_frames - lengths.sum() - n_r
    share = rests / rests.sum() * room
    extra = np.floor(share)
    extra[np.argsort(extra - share)[: int(room - extra.sum())]] += 1
    return lengths, extra + 1


def _gesture_keys(classes, starts, lengths, subject, rng):
    """Keyframe times and poses of every gesture instance of one stream.

    The prototype poses are scaled away from rest (amplitude), jittered and
    clipped to the joint limits; an idle arm follows the subject's rest pose.
    Key times pass through a random monotone warp ``u + a u (1 - u)`` per
    instance, plus a small jitter, and keep their order.

    Returns
    -------
    times : ndarray of shape (n_keys,)
        Frame times, strictly inside each gesture.
    poses : ndarray of shape (n_keys, 10)
        Arm angles in radians.
    """
    protos = _prototypes()
    n_g = len(classes)
    poses = np.concatenate([protos[c - 1]["keys"] for c in classes])
    u = np.concatenate([protos[c - 1]["times"] for c in classes])
    n_keys = np.array([len(protos[c - 1]["times"]) for c in classes])
    gid = np.repeat(np.arange(n_g), n_keys)
    index = np.arange(len(u)) - (np.cumsum(n_keys) - n_keys)[gid]  # within gesture
    idle = np.isnan(poses)
    amp = np.exp(subject["log_amplitude"] + rng.normal(0.0, AMPLITUDE_LOG_SD, n_g))
    poses = _CANONICAL_REST + amp[gid, None] * (poses - _CANONICAL_REST)
    poses += np.radians(rng.normal(0.0, KEY_JITTER_DEG, poses.shape))
    np.clip(poses, _LIMIT_LOW, _LIMIT_HIGH, out=poses)
    rest = subject["rest"] + np.radians(rng.normal(0.0, REST_JITTER_DEG, poses.shape))
    poses[idle] = rest[idle]
    if subject["left_handed"]:
        poses = np.roll(poses, N_ARM_ANGLES, axis=1)
    warp = rng.uniform(-TIME_WARP, TIME_WARP, n_g)[gid]
    u = u + warp * u * (1.0 - u) + rng.normal(0.0, KEY_TIME_JITTER, len(u))
    offset = 2.0 * gid  # keeps each gesture's keys apart while sorting
    u = np.sort(np.clip(u, 0.0, 1.0) + offset) - offset
    step = index * MIN_KEY_SEPARATION
    u = np.maximum.accumulate(u + offset - step) - offset + step
    # per-key bounds keep the separation after clipping
    n_after = (n_keys[gid] - 1 - index) * MIN_KEY_SEPARATION
    u = np.clip(u, KEY_TIME_LIMITS[0] + step, KEY_TIME_LIMITS[1] - n_after)
    return starts[gid] + u * lengths[gid], poses


def _rest_keys(starts, stops, subject, rng, spacing):
    """Idle keyframes covering each rest ``[starts[i], stops[i]]``.

    A rest gets a key at both ends and about one every ``spacing`` frames; a
    rest of zero frames (two gestures back to back) gets one key.
    """
    span = stops - starts
    n = np.where(span > 0, np.maximum(2, np.rint(span / spacing).astype(int) + 1), 1)
    pid = np.repeat(np.arange(len(n)), n)
    k = np.arange(n.sum()) - (np.cumsum(n) - n)[pid]
    times = starts[pid] + span[pid] * (k / np.maximum(n - 1, 1)[pid])
    jitter = np.radians(rng.normal(0.0, REST_JITTER_DEG, (len(times), N_ANGLES)))
    return times, subject["rest"] + jitter


def _oov_keys(start, length, subject, rng):
    """Keyframes of a random arm motion that belongs to no class."""
    n_keys = rng.randint(*OOV_N_KEYS_RANGE)
    rest = np.broadcast_to(subject["rest"], (n_keys, N_ANGLES))
    amp = rng.uniform(*OOV_AMPLITUDE, size=(n_keys, 1))
    target = np.concatenate([_random_pose(rng, n_keys), _random_pose(rng, n_keys)], 1)
    poses = rest + amp * (target - rest)
    arms = rng.choice(["left", "right", "both"], p=OOV_ARM_PROBS)
    if arms != "both":
        idle = _RIGHT if arms == "left" else _LEFT
        poses[:, idle] = rest[:, idle] + np.radians(
            rng.normal(0.0, REST_JITTER_DEG, (n_keys, N_ARM_ANGLES))
        )
    u = np.sort(rng.uniform(*OOV_KEY_RANGE, n_keys))
    u += np.arange(n_keys) * MIN_KEY_SEPARATION / 10  # strictly increasing
    return start + u * length, poses


def _sway(rng, seconds):
    """Slow idle motion: one sinusoid of random frequency and phase per track.

    Returns
    -------
    arm : ndarray of shape (n_frames, 10)
        Arm angle sway, radians.
    torso : ndarray of shape (n_frames, 3)
        Torso pitch (with breathing), roll and yaw, radians.
    root : ndarray of shape (n_frames, 3)
        Whole-body drift, metres.
    """
    freq = rng.uniform(_SWAY_FREQ_LOW, _SWAY_FREQ_HIGH)
    phase = rng.uniform(0.0, 2 * np.pi, len(freq))
    tracks = _SWAY_AMPLITUDE * np.sin(2 * np.pi * np.outer(seconds, freq) + phase)
    arm, torso, breath, root = np.split(tracks, _SWAY_SPLITS, axis=1)
    torso[:, 0] += breath[:, 0]
    return arm, torso, root


def _make_stream(
    classes,
    subject,
    rng,
    noise_rng,
    *,
    fps,
    oov_rate,
    noise,
    dropout_rate,
    n_frames=None,
):
    """One sequence: positions, labels, segments and missing mask."""
    scale = fps / REFERENCE_FPS
    lengths, rests, oov = _draw_timeline(
        rng, classes, subject, scale, oov_rate, n_frames
    )
    n_total = int(lengths.sum() + rests.sum())
    rest_start = np.cumsum(rests) - rests + np.concatenate([[0], np.cumsum(lengths)])
    rest_stop = rest_start + rests
    g_start = rest_stop[:-1]
    segments = np.stack([classes, g_start, g_start + lengths], axis=1).astype(np.int64)

    piece_start, piece_stop = list(rest_start), list(rest_stop)
    times, poses = [], []
    for r, (offset, length) in oov.items():  # an OOV motion splits its rest
        a = rest_start[r] + offset
        piece_stop[r] = a
        piece_start.append(a + length)
        piece_stop.append(rest_stop[r])
        kt, kp = _oov_keys(a, length, subject, rng)
        times.append(kt)
        poses.append(kp)
    kt, kp = _rest_keys(
        np.array(piece_start, float), np.array(piece_stop, float), subject, rng,
        REST_KEY_SPACING * scale,
    )  # fmt: skip
    times.append(kt)
    poses.append(kp)
    kt, kp = _gesture_keys(classes, g_start, lengths, subject, rng)
    times.append(kt)
    poses.append(kp)
    times, poses = np.concatenate(times), np.concatenate(poses)
    order = np.argsort(times, kind="stable")
    frames = np.arange(n_total)
    arm = PchipInterpolator(times[order], poses[order], axis=0)(frames)
    arm_sway, torso, root_sway = _sway(rng, frames / fps)
    arm += arm_sway

    root = rng.uniform(ROOT_LOW, ROOT_HIGH)
    yaw = np.radians(np.clip(rng.normal(0.0, YAW_SD_DEG), -YAW_MAX_DEG, YAW_MAX_DEG))
    pitch = np.radians(rng.uniform(-CAMERA_PITCH_MAX_DEG, CAMERA_PITCH_MAX_DEG))
    root_rot = _rotation(pitch, 0.0, 0.0) @ _rotation(0.0, 0.0, yaw)
    # the noise is drawn first and the kinematics adds into it (one pass less)
    X = np.zeros((n_total, N_KINECT_JOINTS, N_COORDS))
    if noise > 0:
        noise_rng.standard_normal(out=X)
        X *= noise
    _forward_kinematics(arm, torso, subject["body"], root_rot, root + root_sway, X)
    # Body x is the subject's left; a subject facing a Kinect v1 has the left side
    # at camera -x (as in every real recording in shared/data), so mirror x.
    X[..., 0] *= -1.0

    missing = np.zeros(n_total, dtype=bool)
    if dropout_rate > 0:
        missing[: rng.randint(0, ACQUISITION_MAX + 1)] = True
        starts = np.flatnonzero(noise_rng.random(n_total) < dropout_rate)
        lo, hi = (max(1, round(v * scale)) for v in DROPOUT_LEN_RANGE)
        for s, n in zip(starts, rng.randint(lo, hi + 1, size=len(starts))):
            missing[s : s + n] = True
        X[missing] = 0.0
    y = segments_to_labels(segments, n_total)
    return X, y, segments, missing


# ---------------------------------------------------------------------------
# validation and public function
# ---------------------------------------------------------------------------


def _check_int(value, name, low, high=None):
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    if value < low or (high is not None and value > high):
        rng = f"between {low} and {high}" if high is not None else f">= {low}"
        raise ValueError(f"{name} must be {rng}, got {value}")
    return int(value)


def _check_real(value, name, low, high, *, low_open=False):
    if isinstance(value, bool) or not isinstance(value, Real) or not np.isfinite(value):
        raise ValueError(f"{name} must be a finite real number, got {value!r}")
    if value < low or (low_open and value == low) or value > high:
        op = "<" if low_open else "<="
        raise ValueError(
            f"{name} must satisfy {low} {op} {name} <= {high}, got {value}"
        )
    return float(value)


def _check_n_gestures(n_gestures):
    if isinstance(n_gestures, Integral) and not isinstance(n_gestures, bool):
        n = _check_int(n_gestures, "n_gestures", 1)
        return n, n
    try:
        lo, hi = n_gestures
    except (TypeError, ValueError):
        raise ValueError(
            f"n_gestures must be an int or a (min, max) pair of ints, got "
            f"{n_gestures!r}"
        ) from None
    lo = _check_int(lo, "n_gestures[0]", 1)
    hi = _check_int(hi, "n_gestures[1]", 1)
    if lo > hi:
        raise ValueError(f"n_gestures=({lo}, {hi}) must satisfy min <= max")
    return lo, hi


def _check_params(
    n_sequences, n_classes, n_gestures, n_subjects, oov_rate, noise, dropout_rate, fps
):
    n_sequences = _check_int(n_sequences, "n_sequences", 1)
    n_classes = _check_int(n_classes, "n_classes", 1, MAX_CLASSES)
    n_gestures = _check_n_gestures(n_gestures)
    if n_subjects is None:
        n_subjects = max(1, n_sequences // 5)
    n_subjects = _check_int(n_subjects, "n_subjects", 1, n_sequences)
    oov_rate = _check_real(oov_rate, "oov_rate", 0.0, 1.0)
    noise = _check_real(noise, "noise", 0.0, 1.0)
    dropout_rate = _check_real(dropout_rate, "dropout_rate", 0.0, 0.5)
    fps = _check_real(fps, "fps", 0.0, 1000.0, low_open=True)
    return (
        n_sequences,
        n_classes,
        n_gestures,
        n_subjects,
        oov_rate,
        noise,
        dropout_rate,
        fps,
    )


_DESCR = """\
Synthetic Montalbano-like gesture streams
=========================================

{n_sequences} continuous streams of a 20-joint Kinect v1 skeleton (metres,
camera space, y up) from {n_subjects} simulated subjects, {n_gestures} gesture
instances of {n_classes} classes (labels 1..{n_classes}; 0 = rest), {n_frames}
frames at {fps:g} fps.

Gestures are arm motions built by forward kinematics from a few keyframes of
shoulder, elbow and wrist angles per class (one- and two-handed; classes 14/15
and 5/6 differ only slightly), warped per instance in speed, amplitude and
pose. Between gestures the subject rests with idle sway and sometimes makes an
out-of-vocabulary motion (labelled 0). Subjects differ in body size, rest
posture, handedness, speed, amplitude, position and orientation. Gaussian
sensor jitter (std {noise:g} m) and all-zero tracking dropouts ({dropout_rate:g}
per frame, listed in ``missing``) are added.

Timing follows the ChaLearn LAP 2014 Track 3 validation labels: gesture length
6-96 frames (median 39), gaps between gestures median 27 frames (8.6 % zero),
lead-in median 44 and tail median 32 frames at 20 fps.
"""


def make_gesture_streams(
    n_sequences=100,
    n_classes=20,
    *,
    n_gestures=DEFAULT_N_GESTURES,
    n_subjects=None,
    oov_rate=0.1,
    noise=0.005,
    dropout_rate=0.002,
    fps=20,
    return_segments=True,
    random_state=None,
):
    """Generate continuous gesture streams of a Kinect v1 skeleton.

    Montalbano-like data for tests, examples and benchmarks: each sequence is
    one subject performing a series of arm gestures separated by rests, as in
    the ChaLearn LAP 2014 Track 3 recordings, with the same data contract as
    the real loaders (``skgesture.datasets.load_chalearn``).

    Parameters
    ----------
    n_sequences : int, default=100
        Number of sequences (recordings).
    n_classes : int, default=20
        Number of gesture classes, 1 to 50. Class ``k`` is the same motion for
        every ``random_state`` and every ``n_classes >= k``.
    n_gestures : int or tuple of (int, int), default=(8, 22)
        Gestures per sequence: a fixed number, or an inclusive ``(min, max)``
        range drawn uniformly.
    n_subjects : int or None, default=None
        Number of simulated subjects, at most ``n_sequences``; sequences are
        shared out evenly among them. ``None`` means ``max(1, n_sequences // 5)``.
    oov_rate : float, default=0.1
        Expected number of out-of-vocabulary motions (random arm movements
        labelled 0) per gesture, in ``[0, 1]``. They are placed in rests long
        enough to hold them, so the realised rate can be lower.
    noise : float, default=0.005
        Standard deviation, in metres, of the Gaussian jitter added to every
        joint coordinate of every frame.
    dropout_rate : float, default=0.002
        Probability per frame that a tracking dropout starts: a run of 1-5
        all-zero frames. With a positive rate each sequence also starts with
        0-4 untracked frames, as the real recordings do. ``0`` gives streams
        without missing frames.
    fps : float, default=20
        Frame rate. Durations are defined in seconds at the 20 fps of
        Montalbano, so frame counts scale with ``fps / 20``.
    return_segments : bool, default=True
        Whether the result holds ``segments``.
    random_state : int, RandomState instance or None, default=None
        Controls every random draw (subjects, timelines, poses, noise,
        dropouts). Pass an int for reproducible output.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with the keys of the real loaders:

        X : list of ndarray of shape (n_frames_i, 20, 3)
            Joint positions, float64, metres; missing frames are all zeros.
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels, int64: 0 rest, ``1..n_classes`` gestures.
        segments : list of ndarray of shape (n_gestures_i, 3)
            Rows ``(class, start, end)``, 0-based, ``end`` exclusive, int64.
            Only when ``return_segments=True``.
        sample_ids : list of str
            ``"Synth0000"``, ``"Synth0001"``, ...
        groups : ndarray of shape (n_sequences,)
            Subject of each sequence, ``0..n_subjects - 1``.
        fps : float
            The frame rate.
        n_frames : ndarray of shape (n_sequences,)
            Length of each sequence.
        missing : list of ndarray of shape (n_frames_i,)
            True where the frame is a tracking dropout (all zeros).
        target_names : list of str
            ``target_names[k - 1]`` names class ``k`` (``"gesture_01"``, ...).
        layout : str
            ``"kinect_v1"``.
        DESCR : str
            Description of the data.

    Raises
    ------
    ValueError
        If a parameter is out of range.

    See Also
    --------
    skgesture.utils.labels_to_segments : Per-frame labels to segments.

    Notes
    -----
    Timing follows the LAP 2014 Track 3 validation labels (230 sequences, 3454
    gestures): gesture length is a log-normal with median 39 frames (per-class,
    per-subject and per-instance factors) clipped to 6-96; 8.6 % of the gaps
    are 0 and the others log-normal with median 30, so the median gap is about
    27; lead-in and tail rests have medians 44 and 32. Classes are balanced
    over the whole data set (counts differ by at most one) and distinct within
    a sequence, unless it has more gestures than there are classes; two
    instances of one class are always separated by a rest.

    Each class is a few keyframe poses of flexion, abduction and twist of the
    shoulders, elbow and wrist flexion, interpolated with monotone cubic
    splines (PCHIP) and mapped to positions by forward kinematics on the
    Kinect v1 bone tree, so bone lengths are constant within a sequence up to
    ``noise``. One-handed classes use the right arm, or the left arm for the
    10 % of subjects who are left-handed. The legs stay still apart from a slow
    whole-body sway.

    References
    ----------
    .. [1] S. Escalera et al., "ChaLearn Looking at People Challenge 2014:
       Dataset and Results", ECCV Workshops, 2014.
    .. [2] G. Brás, A. Simão and P. Neto, "Gesture Recognition from Skeleton
       Data for Intuitive Human-Machine Interaction".

    Examples
    --------
    >>> from skgesture.datasets import make_gesture_streams
    >>> data = make_gesture_streams(n_sequences=4, n_classes=5, random_state=0)
    >>> len(data.X), data.X[0].shape[1:], data.X[0].dtype
    (4, (20, 3), dtype('float64'))
    >>> data.groups.tolist(), data.target_names[:2]
    ([0, 0, 0, 0], ['gesture_01', 'gesture_02'])
    >>> bool((data.segments[0][:, 2] - data.segments[0][:, 1] >= 6).all())
    True
    """
    (n_sequences, n_classes, (g_lo, g_hi), n_subjects, oov_rate, noise,
     dropout_rate, fps) = _check_params(
        n_sequences, n_classes, n_gestures, n_subjects, oov_rate, noise,
        dropout_rate, fps,
    )  # fmt: skip
    rng = check_random_state(random_state)
    return _generate(
        rng, n_sequences=n_sequences, n_classes=n_classes, n_gestures=(g_lo, g_hi),
        n_subjects=n_subjects, oov_rate=oov_rate, noise=noise,
        dropout_rate=dropout_rate, fps=fps, return_segments=return_segments,
    )  # fmt: skip


def _draw_classes(n_gestures, drawn, rng):
    """Classes of one sequence, balanced over the data set.

    Each sequence takes the classes drawn least so far (ties broken at random),
    all distinct unless it holds more gestures than there are classes, and
    performs them in random order. ``drawn`` is updated in place.
    """
    n_classes = len(drawn)
    chosen = []
    while n_gestures > 0:
        k = min(n_gestures, n_classes)
        order = rng.permutation(n_classes)
        pick = order[np.argsort(drawn[order], kind="stable")[:k]]
        drawn[pick] += 1
        chosen.append(pick + 1)
        n_gestures -= k
    return rng.permutation(np.concatenate(chosen))


def _generate(
    rng,
    *,
    n_sequences,
    n_classes,
    n_gestures,
    n_subjects,
    oov_rate,
    noise,
    dropout_rate,
    fps,
    return_segments=True,
    n_frames=None,
):
    """The generator behind :func:`make_gesture_streams`, on validated input."""
    noise_rng = np.random.default_rng(rng.randint(np.iinfo(np.int32).max))
    subjects = [_draw_subject(rng) for _ in range(n_subjects)]
    groups = rng.permutation(np.arange(n_sequences) % n_subjects)
    counts = rng.randint(n_gestures[0], n_gestures[1] + 1, size=n_sequences)
    drawn = np.zeros(n_classes, dtype=np.int64)  # instances of each class so far

    X, y, segments, missing = [], [], [], []
    for i in range(n_sequences):
        xi, yi, si, mi = _make_stream(
            _draw_classes(counts[i], drawn, rng), subjects[groups[i]], rng, noise_rng,
            fps=fps, oov_rate=oov_rate, noise=noise, dropout_rate=dropout_rate,
            n_frames=n_frames,
        )  # fmt: skip
        X.append(xi)
        y.append(yi)
        segments.append(si)
        missing.append(mi)
    lengths = np.array([len(lab) for lab in y], dtype=np.int64)
    descr = _DESCR.format(
        n_sequences=n_sequences, n_subjects=n_subjects, n_gestures=int(counts.sum()),
        n_classes=n_classes, n_frames=int(lengths.sum()), fps=fps, noise=noise,
        dropout_rate=dropout_rate,
    )  # fmt: skip
    data = Bunch(
        X=X,
        y=y,
        segments=segments,
        sample_ids=[f"Synth{i:04d}" for i in range(n_sequences)],
        groups=groups.astype(np.int64),
        fps=float(fps),
        n_frames=lengths,
        missing=missing,
        target_names=[f"gesture_{k:02d}" for k in range(1, n_classes + 1)],
        layout=KINECT_V1.name,
        DESCR=descr,
    )
    if not return_segments:
        del data["segments"]
    return data
