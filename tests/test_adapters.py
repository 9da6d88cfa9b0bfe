"""Skeleton adapters and sources, checked on the real MSR Action3D and UTKinect
skeletons of shared/data."""

import warnings

import numpy as np
import pytest

from skgesture import PoseDescriptor
from skgesture.datasets import load_msr_action3d, load_utkinect
from skgesture.layouts import KINECT_V1
from skgesture.streaming import (
    AZURE_KINECT_JOINTS,
    KINECT_V2_JOINTS,
    MEDIAPIPE_POSE_LANDMARKS,
    AzureKinectAdapter,
    KinectV1Adapter,
    KinectV2Adapter,
    MediaPipePoseAdapter,
    MSRAction3DAdapter,
    ReplaySource,
    SkeletonSource,
    get_adapter,
)

J = KINECT_V1.index
V2 = {name: k for k, name in enumerate(KINECT_V2_JOINTS)}
AZ = {name: k for k, name in enumerate(AZURE_KINECT_JOINTS)}
MP = {name: k for k, name in enumerate(MEDIAPIPE_POSE_LANDMARKS)}
LIMBS = [
    ("ShoulderLeft", "ElbowLeft"), ("ElbowLeft", "WristLeft"),
    ("ShoulderRight", "ElbowRight"), ("ElbowRight", "WristRight"),
    ("HipLeft", "KneeLeft"), ("KneeLeft", "AnkleLeft"),
    ("HipRight", "KneeRight"), ("KneeRight", "AnkleRight"),
]  # fmt: skip
HAND_MAX_CV = 0.5
# A pinhole camera like Kinect v1's colour camera (640 x 480, focal 525 px).
WIDTH, HEIGHT, FOCAL = 640, 480, 525.0


@pytest.fixture(scope="module")
def msr(shared_data):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_msr_action3d(shared_data / "msr_action3d")


@pytest.fixture(scope="module")
def utk(shared_data):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_utkinect(shared_data / "utkinect_action3d")


def _tracked(X):
    X = np.asarray(X)
    return X[~(np.isnan(X).any(axis=(1, 2)) | (X == 0).all(axis=(1, 2)))]


def assert_anatomy(sequences, *, facing=0.9, max_cv=0.35):
    """Head above the torso, feet lowest, left shoulder on the person's left when
    facing the camera, plausible and nearly constant bone lengths."""
    X = np.concatenate([_tracked(x) for x in sequences])
    y = X[..., 1]
    torso = [
        J(n) for n in ("ShoulderCenter", "ShoulderLeft", "ShoulderRight", "HipCenter")
    ]
    assert np.mean(y[:, J("Head")] > y[:, torso].max(axis=1)) > 0.95
    feet = [J(n) for n in ("FootLeft", "FootRight", "AnkleLeft", "AnkleRight")]
    assert np.mean(np.isin(np.argmin(y, axis=1), feet)) > 0.95
    # Kinect v1: x towards the sensor's left, y up, z away from it; a person
    # facing the sensor has (ShoulderLeft - ShoulderRight) x up pointing at it.
    normal = np.cross(
        X[:, J("ShoulderLeft")] - X[:, J("ShoulderRight")],
        X[:, J("ShoulderCenter")] - X[:, J("HipCenter")],
    )
    assert np.mean(normal[:, 2] < 0) > facing
    for parent, child in KINECT_V1.bones:
        cvs, medians = [], []
        for x in sequences:
            x = _tracked(x)
            length = np.linalg.norm(x[:, J(child)] - x[:, J(parent)], axis=1)
            medians.append(np.median(length))
            cvs.append(length.std() / np.median(length))
        assert 0.04 < np.median(medians) < 0.65, (parent, child, np.median(medians))
        # Wrist-hand is Kinect v1's noisiest link (median CV 0.32 on raw UTKinect).
        limit = HAND_MAX_CV if child.startswith("Hand") else max_cv
        assert np.median(cvs) < limit, (parent, child, np.median(cvs))
    for (a, b), (c, d) in zip(LIMBS[0::4] + LIMBS[1::4], LIMBS[2::4] + LIMBS[3::4]):
        left = np.median(np.linalg.norm(X[:, J(b)] - X[:, J(a)], axis=1))
        right = np.median(np.linalg.norm(X[:, J(d)] - X[:, J(c)], axis=1))
        assert abs(left - right) < 0.1 * (left + right) / 2


def assert_descriptor_finite(sequences):
    desc = PoseDescriptor().fit(sequences)
    for Z in desc.transform(sequences):
        assert np.isfinite(Z).all()


# -- real data: MSR Action3D file order, Kinect v1 UTKinect ----------------------


def _read_msr_file(path):
    values = np.loadtxt(path)
    return values.reshape(-1, 20, 4)  # MSR joint order, x y z confidence


def test_msr_adapter_reorders_real_files_like_the_loader(msr, shared_data):
    folder = shared_data / "msr_action3d" / "real_world_coordinates"
    adapter = MSRAction3DAdapter()
    for clip in (msr.sample_ids[0], msr.sample_ids[280], msr.sample_ids[-1]):
        raw = _read_msr_file(folder / f"{clip}_skeleton3D.txt")
        X = adapter(raw)  # the confidence column is ignored
        np.testing.assert_array_equal(X, msr.X[msr.sample_ids.index(clip)])
        # The 20th MSR joint is the head.
        np.testing.assert_array_equal(X[:, J("Head")], raw[:, 19, :3])


def test_msr_adapted_skeletons_are_anatomical(msr, shared_data):
    folder = shared_data / "msr_action3d" / "real_world_coordinates"
    clips = msr.sample_ids[::5]
    adapted = [
        MSRAction3DAdapter()(_read_msr_file(folder / f"{c}_skeleton3D.txt"))
        for c in clips
    ]
    assert_anatomy(adapted, max_cv=0.2)
    assert_descriptor_finite(adapted[:20])


def test_utkinect_skeletons_are_anatomical(utk):
    adapted = [KinectV1Adapter()(x) for x in utk.X]
    assert_anatomy(adapted)
    assert_descriptor_finite(adapted[:4])


# -- other layouts built from the real UTKinect skeletons -------------------------


def _body_axes(X):
    """Unit left (towards ShoulderLeft) and forward (towards the camera) axes."""
    left = X[:, J("ShoulderLeft")] - X[:, J("ShoulderRight")]
    left /= np.linalg.norm(left, axis=-1, keepdims=True)
    up = X[:, J("ShoulderCenter")] - X[:, J("HipCenter")]
    forward = np.cross(left, up)
    forward /= np.linalg.norm(forward, axis=-1, keepdims=True)
    return left, forward


def _as_kinect_v2(X):
    out = np.zeros((len(X), 25, 3))
    for name in KINECT_V1.joint_names:
        if name in V2:
            out[:, V2[name]] = X[:, J(name)]
    out[:, V2["SpineBase"]] = X[:, J("HipCenter")]
    out[:, V2["SpineMid"]] = X[:, J("Spine")]
    out[:, V2["SpineShoulder"]] = X[:, J("ShoulderCenter")]
    out[:, V2["Neck"]] = X[:, J("ShoulderCenter")] + 0.4 * (
        X[:, J("Head")] - X[:, J("ShoulderCenter")]
    )
    for side in ("Left", "Right"):
        hand, wrist = X[:, J(f"Hand{side}")], X[:, J(f"Wrist{side}")]
        out[:, V2[f"HandTip{side}"]] = hand + 0.8 * (hand - wrist)
        out[:, V2[f"Thumb{side}"]] = hand + [0.0, 0.03, 0.0]
    return out


def _as_azure_kinect(X):
    """Millimetres, x right, y down (180 degrees about z from Kinect v1)."""
    v1 = {name: X[:, J(name)] for name in KINECT_V1.joint_names}
    joints = {
        "PELVIS": v1["HipCenter"], "SPINE_NAVEL": v1["Spine"],
        "SPINE_CHEST": (v1["Spine"] + v1["ShoulderCenter"]) / 2,
        "NECK": v1["ShoulderCenter"], "HEAD": v1["Head"],
        "NOSE": v1["Head"] + [0.0, -0.02, -0.09],
    }  # fmt: skip
    for side in ("LEFT", "RIGHT"):
        s = side.title()
        for part in (
            "Shoulder",
            "Elbow",
            "Wrist",
            "Hand",
            "Hip",
            "Knee",
            "Ankle",
            "Foot",
        ):
            joints[f"{part.upper()}_{side}"] = v1[f"{part}{s}"]
        joints[f"CLAVICLE_{side}"] = (v1["ShoulderCenter"] + v1[f"Shoulder{s}"]) / 2
        joints[f"HANDTIP_{side}"] = v1[f"Hand{s}"] + 0.8 * (
            v1[f"Hand{s}"] - v1[f"Wrist{s}"]
        )
        joints[f"THUMB_{side}"] = v1[f"Hand{s}"] + [0.0, 0.03, 0.0]
        joints[f"EYE_{side}"] = v1["Head"] + [0.0, 0.03, -0.08]
        joints[f"EAR_{side}"] = v1["Head"]
    out = np.zeros((len(X), 32, 3))
    for name, pos in joints.items():
        out[:, AZ[name]] = pos
    return out * 1000.0 * np.array([-1.0, -1.0, 1.0])


def _as_mediapipe(X, world=False):
    """BlazePose landmarks of a Kinect v1 skeleton seen by a pinhole camera."""
    v1 = {name: X[:, J(name)] for name in KINECT_V1.joint_names}
    left, forward = _body_axes(X)
    marks = {"nose": v1["Head"] + 0.09 * forward}
    for side, sign in (("left", 1.0), ("right", -1.0)):
        s = side.title()
        for part in ("shoulder", "elbow", "wrist", "hip", "knee", "ankle"):
            marks[f"{side}_{part}"] = v1[f"{part.title()}{s}"]
        marks[f"{side}_ear"] = v1["Head"] + sign * 0.07 * left
        for k, name in enumerate(("eye_inner", "eye", "eye_outer")):
            marks[f"{side}_{name}"] = v1["Head"] + sign * 0.02 * (k + 1) * left
        marks[f"mouth_{side}"] = v1["Head"] + sign * 0.025 * left - [0.0, 0.06, 0.0]
        hand = v1[f"Hand{s}"]
        marks[f"{side}_pinky"] = hand + 0.02 * left
        marks[f"{side}_index"] = hand - 0.02 * left
        marks[f"{side}_thumb"] = hand + [0.0, 0.03, 0.0]
        marks[f"{side}_heel"] = v1[f"Foot{s}"] - 0.06 * forward
        marks[f"{side}_foot_index"] = v1[f"Foot{s}"] + 0.06 * forward
    P = np.zeros((len(X), 33, 3))
    for name, pos in marks.items():
        P[:, MP[name]] = pos
    hips = (P[:, MP["left_hip"]] + P[:, MP["right_hip"]]) / 2
    if world:  # metres, hip-centred, x right, y down
        return (P - hips[:, None]) * np.array([-1.0, -1.0, 1.0])
    u = WIDTH / 2 - FOCAL * P[..., 0] / P[..., 2]
    v = HEIGHT / 2 - FOCAL * P[..., 1] / P[..., 2]
    z = (P[..., 2] - hips[:, None, 2]) * FOCAL / hips[:, None, 2] / WIDTH
    return np.stack([u / WIDTH, v / HEIGHT, z], axis=-1)


def test_kinect_v2_adapter_on_real_skeletons(utk):
    for x in utk.X[:6]:
        np.testing.assert_array_equal(KinectV2Adapter()(_as_kinect_v2(x)), x)
    assert_anatomy([KinectV2Adapter()(_as_kinect_v2(x)) for x in utk.X])


def test_azure_kinect_adapter_on_real_skeletons(utk):
    for x in utk.X[:6]:
        np.testing.assert_allclose(
            AzureKinectAdapter()(_as_azure_kinect(x)), x, rtol=0, atol=1e-12
        )
    adapted = [AzureKinectAdapter()(_as_azure_kinect(x)) for x in utk.X]
    assert_anatomy(adapted)
    assert_descriptor_finite(adapted[:4])


def test_mediapipe_adapter_on_real_skeletons(utk):
    adapter = MediaPipePoseAdapter(aspect_ratio=WIDTH / HEIGHT, body_height=1.75)
    adapted = [adapter(_as_mediapipe(x)) for x in utk.X]
    assert_anatomy(adapted)
    assert_descriptor_finite(adapted[:4])
    for x, a in zip(utk.X, adapted):
        # Link directions survive the projection (weak perspective).
        for parent, child in LIMBS[:4]:
            u = x[:, J(child)] - x[:, J(parent)]
            w = a[:, J(child)] - a[:, J(parent)]
            cos = np.einsum("ti,ti->t", u, w) / (
                np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1)
            )
            assert np.median(cos) > 0.97
        # The torso gets the length the body height implies.
        torso = np.linalg.norm(a[:, J("ShoulderCenter")] - a[:, J("HipCenter")], axis=1)
        np.testing.assert_allclose(np.median(torso), 0.288 * 1.75, rtol=1e-6)
        # Spine is interpolated at the measured Kinect v1 position.
        np.testing.assert_allclose(
            a[:, J("Spine")],
            a[:, J("HipCenter")]
            + 0.165 * (a[:, J("ShoulderCenter")] - a[:, J("HipCenter")]),
        )


def test_mediapipe_world_landmarks_keep_metres(utk):
    x = utk.X[0]
    a = MediaPipePoseAdapter(coordinates="world")(_as_mediapipe(x, world=True))
    root = (x[:, J("HipLeft")] + x[:, J("HipRight")]) / 2  # MediaPipe's origin
    for name in ("ShoulderLeft", "ElbowRight", "KneeLeft", "HipRight"):
        np.testing.assert_allclose(a[:, J(name)], x[:, J(name)] - root, atol=1e-12)


def test_mirrored_image_swaps_the_x_axis(utk):
    x = _as_mediapipe(utk.X[0][:5])
    mirrored = x.copy()
    mirrored[..., 0] = 1.0 - mirrored[..., 0]
    plain = MediaPipePoseAdapter(metres_per_unit=2.0)(x)
    flipped = MediaPipePoseAdapter(metres_per_unit=2.0, image_mirrored=True)(mirrored)
    np.testing.assert_allclose(flipped[..., 1:], plain[..., 1:])
    # Same skeleton, shifted by the image width (1 unit = 2 m) along x.
    np.testing.assert_allclose(flipped[..., 0] - plain[..., 0], 2.0)


# -- behaviour ------------------------------------------------------------------


@pytest.mark.parametrize(
    "adapter", [KinectV1Adapter(), KinectV2Adapter(), AzureKinectAdapter(),
                MediaPipePoseAdapter(), MSRAction3DAdapter()],
    ids=lambda a: a.name,
)  # fmt: skip
def test_untracked_frames_map_to_zeros(adapter):
    rng = np.random.RandomState(0)
    X = rng.uniform(0.2, 0.8, size=(5, adapter.n_joints, 3))
    X[1] = 0.0
    X[3, 2, 0] = np.nan
    out = adapter(X)
    assert out.shape == (5, 20, 3)
    assert np.all(out[[1, 3]] == 0) and np.isfinite(out).all()
    assert np.all(np.any(out[[0, 2, 4]] != 0, axis=(1, 2)))
    np.testing.assert_allclose(adapter(X[0]), out[0])  # one frame
    extra = np.concatenate([X, np.ones((5, adapter.n_joints, 1))], axis=2)
    np.testing.assert_allclose(adapter(extra), out)  # confidence column ignored


def test_adapter_errors_and_lookup():
    with pytest.raises(ValueError, match=r"\(25, 3\)"):
        KinectV2Adapter()(np.zeros((20, 3)))
    with pytest.raises(ValueError, match="units"):
        AzureKinectAdapter(units="cm")
    with pytest.raises(ValueError, match="coordinates"):
        MediaPipePoseAdapter(coordinates="pixels")
    with pytest.raises(ValueError, match="aspect_ratio"):
        MediaPipePoseAdapter(aspect_ratio=0)
    with pytest.raises(ValueError, match="unknown layout"):
        get_adapter("openpose")
    assert isinstance(
        get_adapter("mediapipe_pose", aspect_ratio=16 / 9), MediaPipePoseAdapter
    )
    assert get_adapter("mediapipe_pose", aspect_ratio=16 / 9).aspect_ratio == 16 / 9
    assert {get_adapter(n).n_joints for n in ("kinect_v2", "azure_kinect")} == {25, 32}


@pytest.mark.parametrize(
    "adapter", [KinectV1Adapter(), KinectV2Adapter(), AzureKinectAdapter(),
                MediaPipePoseAdapter(), MSRAction3DAdapter()],
    ids=lambda a: a.name,
)  # fmt: skip
def test_adapters_refuse_what_is_not_an_array_of_numbers(adapter):
    name = type(adapter).__name__
    for bad in ("frame.csv", b"bytes", None, {"head": 1}):
        with pytest.raises(TypeError, match=rf"{name} input must be an array .*got"):
            adapter(bad)
    with pytest.raises(ValueError, match=rf"{name} input .* of real numbers"):
        adapter(np.full((adapter.n_joints, 3), "x"))
    with pytest.raises(ValueError, match="real numbers"):
        adapter(np.zeros((adapter.n_joints, 3)) + 1j)


def test_replay_source_refuses_bad_arguments():
    X = np.zeros((4, 20, 3))
    with pytest.raises(TypeError, match="ReplaySource X must be an array"):
        ReplaySource("recording.txt")
    with pytest.raises(TypeError, match="adapter must be a SkeletonAdapter"):
        ReplaySource(X, adapter=3)
    with pytest.raises(ValueError, match="unknown layout"):
        ReplaySource(X, adapter="openpose")
    with pytest.raises(ValueError, match="fps"):
        ReplaySource(X, fps="fast")
    with pytest.raises(ValueError, match="unknown layout"):
        get_adapter(["kinect_v2"])


def test_replay_source_adapts_and_paces_frames(utk):
    x = utk.X[0][:6]
    now = [0.0]
    waits = []

    def sleep(seconds):
        waits.append(seconds)
        now[0] += seconds

    source = ReplaySource(
        _as_azure_kinect(x),
        adapter="azure_kinect",
        fps=20,
        realtime=True,
        clock=lambda: now[0],
        sleep=sleep,
    )
    assert isinstance(source, SkeletonSource)
    frames = list(source)
    np.testing.assert_allclose(np.stack(frames), x, atol=1e-12)
    np.testing.assert_allclose(waits, [0.05] * 5)  # nothing else takes time here
    assert len(list(ReplaySource(x))) == 6
    with pytest.raises(ValueError, match="fps"):
        ReplaySource(x, fps=0)
