"""Skeleton layouts: joint names, bones and the joint sets the descriptor uses.

Every model in skgesture works on the Kinect v1 (NUI) 20-joint layout, in metres,
camera space, y up. Other sensors are mapped onto it by the adapters in
:mod:`skgesture.streaming` (Kinect v2 / Azure Kinect, MediaPipe Pose, MSR Action3D).

Joint indices are never written as bare numbers elsewhere in the package: use
``KINECT_V1.index("HandRight")`` or the ``JOINT_*`` constants below.
"""

# SPDX-License-Identifier: BSD-3-Clause

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

__all__ = [
    "SkeletonLayout",
    "DescriptorJoints",
    "KINECT_V1",
    "PAPER_11",
    "FULL_BODY_20",
    "get_descriptor_joints",
    "KINECT_V2_JOINTS",
    "AZURE_KINECT_JOINTS",
    "MEDIAPIPE_POSE_LANDMARKS",
    "MSR_ACTION3D_TO_KINECT_V1",
]


@dataclass(frozen=True)
class SkeletonLayout:
    """A named skeleton: ordered joints and the bones between them.

    Parameters
    ----------
    name : str
        Short name of the layout.
    joint_names : tuple of str
        Joint names in storage order (index ``k`` is column block ``k``).
    bones : tuple of (str, str)
        ``(parent, child)`` pairs, ordered so that every parent appears as a child
        (or is the root) before its own children.
    root : str
        Name of the root joint.

    Examples
    --------
    >>> from skgesture.layouts import KINECT_V1
    >>> KINECT_V1.n_joints, KINECT_V1.index("HandRight")
    (20, 11)
    """

    name: str
    joint_names: tuple
    bones: tuple
    root: str

    @property
    def n_joints(self):
        """Number of joints."""
        return len(self.joint_names)

    def index(self, name):
        """Storage index of the joint called ``name``."""
        try:
            return self.joint_names.index(name)
        except ValueError:
            raise ValueError(
                f"joint {name!r} is not in layout {self.name!r}; "
                f"known joints: {', '.join(self.joint_names)}"
            ) from None

    def indices(self, names):
        """Storage indices of several joints, in the order given."""
        return tuple(self.index(n) for n in names)


# Kinect for Windows SDK v1 order, docs/method.md §1.4.
KINECT_V1 = SkeletonLayout(
    name="kinect_v1",
    joint_names=(
        "HipCenter",
        "Spine",
        "ShoulderCenter",
        "Head",
        "ShoulderLeft",
        "ElbowLeft",
        "WristLeft",
        "HandLeft",
        "ShoulderRight",
        "ElbowRight",
        "WristRight",
        "HandRight",
        "HipLeft",
        "KneeLeft",
        "AnkleLeft",
        "FootLeft",
        "HipRight",
        "KneeRight",
        "AnkleRight",
        "FootRight",
    ),  # fmt: skip
    bones=(
        ("HipCenter", "Spine"),
        ("Spine", "ShoulderCenter"),
        ("ShoulderCenter", "Head"),
        ("ShoulderCenter", "ShoulderLeft"),
        ("ShoulderLeft", "ElbowLeft"),
        ("ElbowLeft", "WristLeft"),
        ("WristLeft", "HandLeft"),
        ("ShoulderCenter", "ShoulderRight"),
        ("ShoulderRight", "ElbowRight"),
        ("ElbowRight", "WristRight"),
        ("WristRight", "HandRight"),
        ("HipCenter", "HipRight"),
        ("HipRight", "KneeRight"),
        ("KneeRight", "AnkleRight"),
        ("AnkleRight", "FootRight"),
        ("HipCenter", "HipLeft"),
        ("HipLeft", "KneeLeft"),
        ("KneeLeft", "AnkleLeft"),
        ("AnkleLeft", "FootLeft"),
    ),  # fmt: skip
    root="HipCenter",
)

N_KINECT_JOINTS = KINECT_V1.n_joints  # docs/method.md §1.4
N_COORDS = 3  # world x, y, z in metres


@dataclass(frozen=True)
class DescriptorJoints:
    """Which joints, links, triples and torso joints the pose descriptor uses.

    Parameters
    ----------
    name : str
        Short name (``"paper11"``, ``"full20"``).
    joints : tuple of str
        Joints kept in the descriptor, in feature order; the first is the root.
    links : tuple of (str, str)
        Link-length normalisation tree ``(parent, child)``, parents first
        (docs/method.md §3.5). May pass through joints that are not kept.
    triples : tuple of (str, str, str)
        Joint triples ``(i, j, k)`` for the inclination and azimuth angles
        (docs/method.md §3.9-3.10).
    torso : tuple of str
        Joints whose best-fit plane gives the body frame (docs/method.md §3.8).
    left_right : tuple of (str, str)
        ``(ShoulderLeft, ShoulderRight)``-style pair giving the body's x axis sign.
    spine : tuple of (str, str)
        ``(lower, upper)`` pair giving the body's y axis.

    Examples
    --------
    >>> from skgesture.layouts import PAPER_11
    >>> PAPER_11.n_features
    183
    """

    name: str
    joints: tuple
    links: tuple
    triples: tuple
    torso: tuple
    left_right: tuple = ("ShoulderLeft", "ShoulderRight")
    spine: tuple = ("HipCenter", "ShoulderCenter")

    @property
    def n_joints(self):
        """Number of joints in the descriptor."""
        return len(self.joints)

    @property
    def pairs(self):
        """Unordered joint pairs for the distances, lexicographic (§3.12)."""
        return tuple(combinations(range(self.n_joints), 2))

    @property
    def n_features(self):
        """Width of the descriptor (183 for the paper's 11 joints)."""
        j = self.n_joints
        t = len(self.triples)
        return 9 * j + 2 * t + j + j * (j - 1) // 2


_UPPER_BODY = frozenset(KINECT_V1.joint_names[:13]) | {"HipRight"}  # no legs

# The paper's 11 upper-body joints, docs/method.md §3.1 (decision D1), the 13-link
# upper-body tree of §3.5 and the 9 triples of §3.9 (decision D6).
PAPER_11 = DescriptorJoints(
    name="paper11",
    joints=(
        "HipCenter",
        "ShoulderCenter",
        "Head",
        "ShoulderLeft",
        "ElbowLeft",
        "HandLeft",
        "ShoulderRight",
        "ElbowRight",
        "HandRight",
        "HipLeft",
        "HipRight",
    ),  # fmt: skip
    # The 13-link upper-body tree: every Kinect bone between upper-body joints.
    links=tuple(
        (a, b) for a, b in KINECT_V1.bones if a in _UPPER_BODY and b in _UPPER_BODY
    ),
    # fmt: skip
    triples=(
        ("HipCenter", "ShoulderCenter", "Head"),
        ("HipCenter", "ShoulderCenter", "ShoulderLeft"),
        ("HipCenter", "ShoulderCenter", "ShoulderRight"),
        ("ShoulderCenter", "ShoulderLeft", "ElbowLeft"),
        ("ShoulderCenter", "ShoulderRight", "ElbowRight"),
        ("ShoulderLeft", "ElbowLeft", "HandLeft"),
        ("ShoulderRight", "ElbowRight", "HandRight"),
        ("ElbowLeft", "HandLeft", "HipCenter"),  # virtual bone Hand-HipCenter
        ("ElbowRight", "HandRight", "HipCenter"),  # virtual bone Hand-HipCenter
    ),
    torso=(
        "HipCenter",
        "HipLeft",
        "HipRight",
        "ShoulderCenter",
        "ShoulderLeft",
        "ShoulderRight",
    ),  # fmt: skip
)


def _chain_triples(layout):
    """Every grandparent-parent-child chain of a layout's bone tree."""
    parent = {child: par for par, child in layout.bones}
    return tuple(
        (parent[par], par, child) for par, child in layout.bones if par in parent
    )


# Whole Kinect v1 body: every joint, every bone, every chain triple plus the two
# virtual hand-root triples of the paper (18 triples, 426 features).
FULL_BODY_20 = DescriptorJoints(
    name="full20",
    joints=KINECT_V1.joint_names,
    links=KINECT_V1.bones,
    triples=_chain_triples(KINECT_V1)
    + (
        ("WristLeft", "HandLeft", "HipCenter"),
        ("WristRight", "HandRight", "HipCenter"),
    ),
    torso=PAPER_11.torso,
)

_DESCRIPTOR_JOINTS = {d.name: d for d in (PAPER_11, FULL_BODY_20)}


def get_descriptor_joints(joints):
    """Resolve a descriptor joint set given by name or as a :class:`DescriptorJoints`.

    Parameters
    ----------
    joints : {"paper11", "full20"} or DescriptorJoints
        The joint set.

    Returns
    -------
    DescriptorJoints
        The resolved joint set.

    Examples
    --------
    >>> from skgesture.layouts import get_descriptor_joints
    >>> get_descriptor_joints("full20").n_features
    426
    """
    if isinstance(joints, DescriptorJoints):
        return joints
    try:
        return _DESCRIPTOR_JOINTS[joints]
    except (KeyError, TypeError):
        raise ValueError(
            f"joints must be one of {sorted(_DESCRIPTOR_JOINTS)} or a "
            f"DescriptorJoints instance, got {joints!r}"
        ) from None


# Kinect for Windows SDK 2.0 ``JointType`` order (25 joints).
KINECT_V2_JOINTS = (
    "SpineBase", "SpineMid", "Neck", "Head",
    "ShoulderLeft", "ElbowLeft", "WristLeft", "HandLeft",
    "ShoulderRight", "ElbowRight", "WristRight", "HandRight",
    "HipLeft", "KneeLeft", "AnkleLeft", "FootLeft",
    "HipRight", "KneeRight", "AnkleRight", "FootRight",
    "SpineShoulder", "HandTipLeft", "ThumbLeft", "HandTipRight", "ThumbRight",
)  # fmt: skip


# Azure Kinect Body Tracking SDK ``k4abt_joint_id_t`` order (32 joints).
AZURE_KINECT_JOINTS = (
    "PELVIS", "SPINE_NAVEL", "SPINE_CHEST", "NECK",
    "CLAVICLE_LEFT", "SHOULDER_LEFT", "ELBOW_LEFT", "WRIST_LEFT",
    "HAND_LEFT", "HANDTIP_LEFT", "THUMB_LEFT",
    "CLAVICLE_RIGHT", "SHOULDER_RIGHT", "ELBOW_RIGHT", "WRIST_RIGHT",
    "HAND_RIGHT", "HANDTIP_RIGHT", "THUMB_RIGHT",
    "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "FOOT_LEFT",
    "HIP_RIGHT", "KNEE_RIGHT", "ANKLE_RIGHT", "FOOT_RIGHT",
    "HEAD", "NOSE", "EYE_LEFT", "EAR_LEFT", "EYE_RIGHT", "EAR_RIGHT",
)  # fmt: skip


# MediaPipe Pose (BlazePose) landmark order (33 landmarks).
MEDIAPIPE_POSE_LANDMARKS = (
    "nose", "left_eye_inner", "left_eye", "left_eye_outer",
    "right_eye_inner", "right_eye", "right_eye_outer", "left_ear", "right_ear",
    "mouth_left", "mouth_right", "left_shoulder", "right_shoulder",
    "left_elbow", "right_elbow", "left_wrist", "right_wrist",
    "left_pinky", "right_pinky", "left_index", "right_index",
    "left_thumb", "right_thumb", "left_hip", "right_hip",
    "left_knee", "right_knee", "left_ankle", "right_ankle",
    "left_heel", "right_heel", "left_foot_index", "right_foot_index",
)  # fmt: skip


# For each Kinect v1 NUI joint (HipCenter, Spine, ShoulderCenter, Head,
# ShoulderLeft, ElbowLeft, WristLeft, HandLeft, ShoulderRight, ElbowRight,
# WristRight, HandRight, HipLeft, KneeLeft, AnkleLeft, FootLeft, HipRight,
# KneeRight, AnkleRight, FootRight) the 0-based index of the same joint in the MSR
# Action3D file order (data PROVENANCE: 1 left shoulder, 2 right shoulder,
# 3 shoulder centre, 4 spine, 5 left hip, 6 right hip, 7 hip centre, 8/9 elbows,
# 10/11 wrists, 12/13 hands, 14/15 knees, 16/17 ankles, 18/19 feet, 20 head).
# Use as ``X_kinect = X_msr[:, MSR_ACTION3D_TO_KINECT_V1]``.
MSR_ACTION3D_TO_KINECT_V1 = (
    6, 3, 2, 19,
    0, 7, 9, 11,
    1, 8, 10, 12,
    4, 13, 15, 17,
    5, 14, 16, 18,
)  # fmt: skip
