"""Skeleton adapters: other layouts -> Kinect v1.

Every model of skgesture works on the 20-joint Kinect v1 (NUI) layout, in
metres, camera space (x towards the sensor's left, y up, z away from the
sensor; the user's left shoulder has the smaller x when facing the sensor).
An adapter maps the frames of another sensor onto it:

* Kinect v2 (25 joints) and Azure Kinect body tracking (32 joints),
* MediaPipe Pose (33 landmarks, normalised image coordinates or world metres),
* the joint order of the MSR Action3D files.

Adapters work on one frame ``(J, C)`` or a sequence ``(T, J, C)``; untracked
frames (all zeros or holding a NaN) map to all-zero frames, which every
skgesture stage treats as untracked. The sources that yield adapted frames
(:class:`SkeletonSource`, :class:`ReplaySource` and the live ones) are in
``skgesture/streaming/_sources.py``.
"""

# SPDX-License-Identifier: BSD-3-Clause

from abc import ABC, abstractmethod

import numpy as np

from skgesture.layouts import (
    AZURE_KINECT_JOINTS,
    KINECT_V1,
    KINECT_V2_JOINTS,
    MEDIAPIPE_POSE_LANDMARKS,
    N_COORDS,
)
from skgesture.utils._validation import missing_frames

__all__ = [
    "KINECT_V2_JOINTS",
    "AZURE_KINECT_JOINTS",
    "MEDIAPIPE_POSE_LANDMARKS",
    "SkeletonAdapter",
    "KinectV1Adapter",
    "KinectV2Adapter",
    "AzureKinectAdapter",
    "MediaPipePoseAdapter",
    "MSRAction3DAdapter",
    "get_adapter",
]


_LIMB_PARTS = ("Shoulder", "Elbow", "Wrist", "Hand", "Hip", "Knee", "Ankle", "Foot")

# Each Kinect v1 joint is the mean of these source joints (in KINECT_V1 order).
_KINECT_V2_SOURCES = {
    "HipCenter": ("SpineBase",),
    "Spine": ("SpineMid",),
    "ShoulderCenter": ("SpineShoulder",),
    "Head": ("Head",),
    **{
        f"{part}{side}": (f"{part}{side}",)
        for side in ("Left", "Right")
        for part in _LIMB_PARTS
    },
}
_AZURE_KINECT_SOURCES = {
    "HipCenter": ("PELVIS",),
    "Spine": ("SPINE_NAVEL",),
    "ShoulderCenter": ("NECK",),
    "Head": ("HEAD",),
    **{
        f"{part}{side.title()}": (f"{part.upper()}_{side}",)
        for side in ("LEFT", "RIGHT")
        for part in _LIMB_PARTS
    },
}
_MEDIAPIPE_SOURCES = {
    "HipCenter": ("left_hip", "right_hip"),
    "Spine": (),  # interpolated between HipCenter and ShoulderCenter
    "ShoulderCenter": ("left_shoulder", "right_shoulder"),
    "Head": ("left_ear", "right_ear"),
    **{
        f"{part.title()}{side.title()}": (f"{side}_{part}",)
        for side in ("left", "right")
        for part in ("shoulder", "elbow", "wrist", "hip", "knee", "ankle")
    },
    "HandLeft": ("left_pinky", "left_index"),
    "HandRight": ("right_pinky", "right_index"),
    "FootLeft": ("left_heel", "left_foot_index"),
    "FootRight": ("right_heel", "right_foot_index"),
}

AZURE_MM_PER_M = 1000.0  # Azure Kinect positions are in millimetres
# Kinect v1 Spine lies this far from HipCenter towards ShoulderCenter: median
# projection measured on the real UTKinect-Action3D (0.167) and PRECOG (0.163)
# skeletons of shared/data.
SPINE_FRACTION = 0.165
# Shoulder height 0.818 H minus hip (greater trochanter) height 0.530 H
# (Drillis & Contini, 1966): the torso is 0.288 of the body height H.
TORSO_HEIGHT_RATIO = 0.288
DEFAULT_BODY_HEIGHT = 1.70  # metres


def _as_positions(X, what, n_joints=None):
    """``X`` as a float64 array, or a clear error for anything that is not one."""
    expect = (
        f"an array of joint positions of shape ({n_joints}, 3) or (n_frames, "
        f"{n_joints}, 3)"
        if n_joints is not None
        else "an array of joint positions of shape (n_frames, n_joints, 3)"
    )
    if isinstance(X, (str, bytes, dict)) or X is None:
        raise TypeError(f"{what} must be {expect}, got {type(X).__name__}")
    try:
        arr = np.asarray(X)
        if arr.dtype.kind == "c":
            raise ValueError("got complex values")
        if arr.dtype.kind not in "biuf":
            arr = np.asarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} must be {expect} of real numbers: {exc}") from None
    return arr.astype(np.float64, copy=False)


def _sources_matrix(sources, names):
    """``(20, J)`` averaging matrix: Kinect v1 joint = mean of its sources."""
    M = np.zeros((KINECT_V1.n_joints, len(names)))
    for k, joint in enumerate(KINECT_V1.joint_names):
        for src in sources[joint]:
            M[k, names.index(src)] = 1.0 / len(sources[joint])
    return M


class SkeletonAdapter(ABC):
    """Maps frames of one skeleton layout onto the Kinect v1 layout.

    Subclasses define :meth:`_convert` on tracked frames; calling the adapter
    checks the shape, zeroes untracked frames and accepts one frame or a
    sequence.

    Attributes
    ----------
    n_joints : int
        Joints per input frame.
    name : str
        Short name of the source layout.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import SkeletonAdapter
    >>> class Mirror(SkeletonAdapter):  # a Kinect v1 sensor seen in a mirror
    ...     name = "kinect_v1_mirrored"
    ...     def _convert(self, X):
    ...         return X * np.array([-1.0, 1.0, 1.0])
    >>> frame = np.full((20, 3), 0.5)
    >>> Mirror()(frame)[0].tolist()
    [-0.5, 0.5, 0.5]
    """

    n_joints = KINECT_V1.n_joints
    name = "kinect_v1"

    def __call__(self, X):
        """Map one frame ``(J, C)`` or a sequence ``(T, J, C)`` to Kinect v1.

        Parameters
        ----------
        X : array-like of shape (n_joints, n_values) or (n_frames, n_joints, n_values)
            Positions in the source layout; the first 3 values of a joint are
            its coordinates, further ones (confidence, visibility) are ignored.

        Returns
        -------
        ndarray of shape (20, 3) or (n_frames, 20, 3)
            Kinect v1 positions in metres, float64; untracked frames are zeros.
        """
        X = _as_positions(X, f"{type(self).__name__} input", self.n_joints)
        single = X.ndim == 2
        if single:
            X = X[None]
        if X.ndim != 3 or X.shape[1] != self.n_joints or X.shape[2] < N_COORDS:
            raise ValueError(
                f"{type(self).__name__} expects frames of shape ({self.n_joints}, 3) "
                f"or sequences (n_frames, {self.n_joints}, 3), got "
                f"{X.shape[1:] if single else X.shape}"
            )
        X = X[..., :N_COORDS]
        out = np.zeros((len(X), KINECT_V1.n_joints, N_COORDS))
        tracked = ~missing_frames(X)
        if tracked.any():
            out[tracked] = self._convert(X[tracked])
        return out[0] if single else out

    @abstractmethod
    def _convert(self, X):
        """Kinect v1 positions ``(T, 20, 3)`` of tracked frames ``(T, J, 3)``."""


class KinectV1Adapter(SkeletonAdapter):
    """The identity on Kinect v1 frames (only checks and zeroes untracked frames).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import KinectV1Adapter
    >>> frame = np.ones((20, 3)); frame[0, 0] = np.nan
    >>> float(KinectV1Adapter()(frame).sum())
    0.0
    """

    def _convert(self, X):
        return X


class KinectV2Adapter(SkeletonAdapter):
    """Kinect v2 (25 joints, SDK 2.0 ``JointType`` order) to Kinect v1.

    Kinect v2 camera space has the same axes and units as Kinect v1 (metres,
    x towards the sensor's left, y up, z away from it), so joints are only
    renamed: ``SpineBase`` -> HipCenter, ``SpineMid`` -> Spine,
    ``SpineShoulder`` -> ShoulderCenter (not ``Neck``, which sits higher),
    every limb joint to the joint of the same name. ``Neck``, the hand tips and
    the thumbs are dropped.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import KINECT_V2_JOINTS, KinectV2Adapter
    >>> frame = np.zeros((25, 3))
    >>> frame[KINECT_V2_JOINTS.index("SpineShoulder")] = [0.0, 0.4, 2.0]
    >>> frame[KINECT_V2_JOINTS.index("SpineBase")] = [0.0, 0.0, 2.0]
    >>> KinectV2Adapter()(frame)[2].tolist()  # ShoulderCenter
    [0.0, 0.4, 2.0]
    """

    n_joints = len(KINECT_V2_JOINTS)
    name = "kinect_v2"
    mapping = _KINECT_V2_SOURCES

    def _convert(self, X):
        M = _sources_matrix(self.mapping, KINECT_V2_JOINTS)
        return np.einsum("kj,tjc->tkc", M, X)


class AzureKinectAdapter(SkeletonAdapter):
    """Azure Kinect Body Tracking (32 joints, ``k4abt_joint_id_t`` order) to Kinect v1.

    Azure Kinect positions are millimetres in the depth camera frame (x right,
    y down, z forward); they are divided by 1000 and turned by 180 degrees
    about z (x and y negated), which gives Kinect v1 axes and keeps the
    coordinate system right-handed. Joints: ``PELVIS`` -> HipCenter,
    ``SPINE_NAVEL`` -> Spine, ``NECK`` -> ShoulderCenter, ``HEAD`` -> Head,
    ``HAND_*`` -> Hand*, and every limb joint to the joint of the same name.
    Clavicles, ``SPINE_CHEST``, hand tips, thumbs and the face joints are
    dropped.

    Parameters
    ----------
    units : {"mm", "m"}, default="mm"
        Units of the input (the SDK gives millimetres).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import AZURE_KINECT_JOINTS, AzureKinectAdapter
    >>> frame = np.zeros((32, 3))
    >>> frame[AZURE_KINECT_JOINTS.index("HEAD")] = [100.0, -600.0, 2000.0]
    >>> frame[AZURE_KINECT_JOINTS.index("PELVIS")] = [100.0, 0.0, 2000.0]
    >>> AzureKinectAdapter()(frame)[3].tolist()  # Head: up is +y in Kinect v1
    [-0.1, 0.6, 2.0]
    """

    n_joints = len(AZURE_KINECT_JOINTS)
    name = "azure_kinect"
    mapping = _AZURE_KINECT_SOURCES

    def __init__(self, units="mm"):
        if units not in ("mm", "m"):
            raise ValueError(f"units must be 'mm' or 'm', got {units!r}")
        self.units = units

    def _convert(self, X):
        M = _sources_matrix(self.mapping, AZURE_KINECT_JOINTS)
        out = np.einsum("kj,tjc->tkc", M, X)
        if self.units == "mm":
            out = out / AZURE_MM_PER_M
        return out * np.array([-1.0, -1.0, 1.0])


class MediaPipePoseAdapter(SkeletonAdapter):
    """MediaPipe Pose (33 BlazePose landmarks) to Kinect v1.

    Joints: HipCenter = mean of the hips, ShoulderCenter = mean of the
    shoulders, Spine = HipCenter + 0.165 (ShoulderCenter - HipCenter) (the
    median position of Kinect v1's Spine on real recordings), Head = mean of
    the ears, Hand = mean of the pinky and index knuckles, Foot = mean of the
    heel and the foot index, and shoulders, elbows, wrists, hips, knees and
    ankles map one to one (MediaPipe's left/right are the person's own sides,
    as in Kinect).

    Coordinates, ``coordinates="normalized"`` (``pose_landmarks``): x and y
    are in [0, 1] of the image width and height (x right, y down), z is the
    depth relative to the hips' midpoint in about the units of x (smaller is
    closer to the camera). They become isotropic units of image width
    (``y / aspect_ratio``), then metres by ``metres_per_unit`` or, when it is
    None, by making the median torso (shoulder midpoint to hip midpoint) of
    the frames of the call ``0.288 * body_height`` long. Finally x and y are
    negated (180 degrees about z: x towards the camera's left, y up, z away
    from the camera, right-handed, as Kinect v1). With
    ``coordinates="world"`` (``pose_world_landmarks``, metres, hip-centred,
    same axes) only the axes are turned.

    Depth and position are relative (the hips' midpoint at z = 0); skgesture's
    descriptor centres every frame on HipCenter and rescales every link to its
    training length, so only the directions of the links matter to the models.

    Parameters
    ----------
    coordinates : {"normalized", "world"}, default="normalized"
        Which MediaPipe output the frames hold.
    aspect_ratio : float, default=4/3
        Image width / height, for normalised coordinates.
    body_height : float, default=1.70
        Height of the person in metres, used when ``metres_per_unit`` is None.
    metres_per_unit : float or None, default=None
        Metres per unit of image width; fixes the scale of every frame.
    image_mirrored : bool, default=False
        Set for a selfie (horizontally flipped) image, whose x axis is reversed.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import MEDIAPIPE_POSE_LANDMARKS, MediaPipePoseAdapter
    >>> lm = {name: k for k, name in enumerate(MEDIAPIPE_POSE_LANDMARKS)}
    >>> frame = np.full((33, 3), 0.5)
    >>> frame[[lm["left_hip"], lm["right_hip"]], 1] = 0.7
    >>> frame[[lm["left_shoulder"], lm["right_shoulder"]], 1] = 0.4
    >>> out = MediaPipePoseAdapter(aspect_ratio=1.0, metres_per_unit=2.0)(frame)
    >>> (out[2] - out[0]).round(3).tolist()  # ShoulderCenter - HipCenter, metres
    [0.0, 0.6, 0.0]
    """

    n_joints = len(MEDIAPIPE_POSE_LANDMARKS)
    name = "mediapipe_pose"
    mapping = _MEDIAPIPE_SOURCES

    def __init__(
        self,
        *,
        coordinates="normalized",
        aspect_ratio=4 / 3,
        body_height=DEFAULT_BODY_HEIGHT,
        metres_per_unit=None,
        image_mirrored=False,
    ):
        if coordinates not in ("normalized", "world"):
            raise ValueError(
                f"coordinates must be 'normalized' or 'world', got {coordinates!r}"
            )
        for name, value in (
            ("aspect_ratio", aspect_ratio),
            ("body_height", body_height),
        ):
            if not value > 0:
                raise ValueError(f"{name} must be positive, got {value!r}")
        if metres_per_unit is not None and not metres_per_unit > 0:
            raise ValueError(
                f"metres_per_unit must be positive, got {metres_per_unit!r}"
            )
        self.coordinates = coordinates
        self.aspect_ratio = aspect_ratio
        self.body_height = body_height
        self.metres_per_unit = metres_per_unit
        self.image_mirrored = image_mirrored

    def _convert(self, X):
        M = _sources_matrix(self.mapping, MEDIAPIPE_POSE_LANDMARKS)
        out = np.einsum("kj,tjc->tkc", M, X)
        hip, spine, centre = (
            KINECT_V1.index(j) for j in ("HipCenter", "Spine", "ShoulderCenter")
        )
        out[:, spine] = out[:, hip] + SPINE_FRACTION * (out[:, centre] - out[:, hip])
        if self.coordinates == "normalized":
            out[..., 1] /= self.aspect_ratio
            scale = self.metres_per_unit
            if scale is None:
                torso = np.median(np.linalg.norm(out[:, centre] - out[:, hip], axis=-1))
                scale = (
                    TORSO_HEIGHT_RATIO * self.body_height / torso if torso > 0 else 1.0
                )
            out = out * scale
        flip = np.array([1.0 if self.image_mirrored else -1.0, -1.0, 1.0])
        return out * flip


class MSRAction3DAdapter(SkeletonAdapter):
    """MSR Action3D file joint order to Kinect v1 (a reordering).

    The MSR Action3D ``*_skeleton3D.txt`` files hold 20 joints per frame in
    their own order, already in metres with Kinect axes; this applies
    :data:`skgesture.datasets.MSR_ACTION3D_TO_KINECT_V1` (which
    :func:`~skgesture.datasets.load_msr_action3d` also uses).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.streaming import MSRAction3DAdapter
    >>> frame = np.arange(60, dtype=float).reshape(20, 3) + 1
    >>> MSRAction3DAdapter()(frame)[3].tolist()  # Head is the 20th MSR joint
    [58.0, 59.0, 60.0]
    """

    name = "msr_action3d"

    def _convert(self, X):
        from skgesture.layouts import MSR_ACTION3D_TO_KINECT_V1

        return X[:, list(MSR_ACTION3D_TO_KINECT_V1)]


_ADAPTERS = {
    cls.name: cls
    for cls in (KinectV1Adapter, KinectV2Adapter, AzureKinectAdapter,
                MediaPipePoseAdapter, MSRAction3DAdapter)
}  # fmt: skip


def get_adapter(name, **params):
    """The adapter of a layout given by name.

    Parameters
    ----------
    name : {"kinect_v1", "kinect_v2", "azure_kinect", "mediapipe_pose", "msr_action3d"}
        Source layout.
    **params
        Parameters of the adapter class (e.g. ``aspect_ratio`` for MediaPipe).

    Returns
    -------
    SkeletonAdapter
        The adapter.

    Examples
    --------
    >>> from skgesture.streaming import get_adapter
    >>> get_adapter("azure_kinect").n_joints
    32
    """
    cls = _ADAPTERS.get(name) if isinstance(name, str) else None
    if cls is None:
        raise ValueError(
            f"unknown layout {name!r}; known: {', '.join(sorted(_ADAPTERS))}"
        )
    return cls(**params)
