"""PoseDescriptor and its helpers against docs/method.md §3 (layout, worked examples,
test vectors) and brute-force re-computations written straight from the spec."""

from itertools import combinations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from skgesture import PoseDescriptor
from skgesture._descriptor._compute import (
    _body_frame,
    _distances,
    _fill_missing,
    _link_normalise,
    _smooth_time,
    gaussian_kernel,
)
from skgesture.layouts import KINECT_V1, PAPER_11

# --------------------------------------------------------------------------------
# Reference values (docs/method.md §3)
# --------------------------------------------------------------------------------

# §3.1: the 11 joints, in feature order.
JOINTS_GT = (
    "HipCenter", "ShoulderCenter", "Head", "ShoulderLeft", "ElbowLeft", "HandLeft",
    "ShoulderRight", "ElbowRight", "HandRight", "HipLeft", "HipRight",
)  # fmt: skip
# §3.9: the 9 triples T1..T9.
TRIPLES_GT = (
    ("HipCenter", "ShoulderCenter", "Head"),
    ("HipCenter", "ShoulderCenter", "ShoulderLeft"),
    ("HipCenter", "ShoulderCenter", "ShoulderRight"),
    ("ShoulderCenter", "ShoulderLeft", "ElbowLeft"),
    ("ShoulderCenter", "ShoulderRight", "ElbowRight"),
    ("ShoulderLeft", "ElbowLeft", "HandLeft"),
    ("ShoulderRight", "ElbowRight", "HandRight"),
    ("ElbowLeft", "HandLeft", "HipCenter"),
    ("ElbowRight", "HandRight", "HipCenter"),
)
# §3.5: the 13 links, parent -> child, in processing order.
LINKS_GT = (
    ("HipCenter", "Spine"), ("Spine", "ShoulderCenter"), ("ShoulderCenter", "Head"),
    ("ShoulderCenter", "ShoulderLeft"), ("ShoulderLeft", "ElbowLeft"),
    ("ElbowLeft", "WristLeft"), ("WristLeft", "HandLeft"),
    ("ShoulderCenter", "ShoulderRight"), ("ShoulderRight", "ElbowRight"),
    ("ElbowRight", "WristRight"), ("WristRight", "HandRight"),
    ("HipCenter", "HipRight"), ("HipCenter", "HipLeft"),
)  # fmt: skip
# §3.13: feature groups, (first index, stop index, name prefix).
LAYOUT_GT = (
    (0, 33, "pos_"), (33, 66, "vel_"), (66, 99, "acc_"), (99, 108, "incl_"),
    (108, 117, "azim_"), (117, 128, "bend_"), (128, 183, "dist_"),
)  # fmt: skip
N_FEATURES_PAPER11 = 183  # §3.13
N_FEATURES_FULL20 = 426  # 9*20 + 2*18 + 20 + 190
# §3.4 / §3.11 / §11 item 6: HipCenter position, velocity, acceleration, bending.
CONSTANT_ZERO_COLUMNS = (0, 1, 2, 33, 34, 35, 66, 67, 68, 117)
INCL, AZIM, BEND, DIST = 99, 108, 117, 128  # first column of each angle group

# §3.6: 5-tap Gaussian, sigma = 1, and its test vectors (4 decimals).
GAUSS_GT = (0.054489, 0.244201, 0.402620, 0.244201, 0.054489)
SMOOTH_IN = (1.0, 2.0, 4.0, 8.0, 16.0, 32.0)
SMOOTH_GT = {
    "replicate": (1.4077, 2.5166, 4.9788, 9.9576, 18.1716, 26.7851),
    "zero": (1.1090, 2.4622, 4.9788, 9.9576, 16.4279, 17.2270),
    # by hand: w . (2, 1, 1, 2, 4) and w . (8, 16, 32, 32, 16) at the ends
    "symmetric": (1.4622, 2.5166, 4.9788, 9.9576, 18.1716, 25.9132),
}
ATOL_4DP = 5e-5
ATOL_6DP = 5e-7

# §3.9-§3.11 worked examples.
INCLINATION_EXAMPLE = {
    "HipCenter": (0, 0, 0),
    "ShoulderCenter": (0, 1, 0),
    "Head": (0.5, 1.5, 0),
}
INCLINATION_GT = 3 * np.pi / 4  # 2.356194
AZIMUTH_EXAMPLE = {
    "HipCenter": (0, 0, 0),
    "ShoulderCenter": (0, 1, 0),
    "Head": (0.5, 1.5, 0.5),
}
AZIMUTH_GT = np.pi / 4  # 0.785398, with u_x = (1, 0, 0)
BENDING_POINT = (0.0, 0.3, 0.3)
BENDING_GT = np.pi / 4  # 0.785398, with u_z = (0, 0, 1)

# §3.3 missing frames: one coordinate, NaN = untracked, filled by hand.
FILL_IN = (np.nan, 2.0, np.nan, np.nan, 8.0, np.nan, np.nan)
FILL_GT = {"linear": (2, 2, 4, 6, 8, 8, 8), "hold": (2, 2, 2, 2, 8, 8, 8)}

# §3.14: mean root-relative Head / ShoulderCenter height over the training set.
HEAD_Y_GT, SHOULDER_CENTER_Y_GT, ATOL_POSE_MEAN = 0.61, 0.42, 0.05

# A standing skeleton whose body frame is the camera frame: x towards the
# skeleton's left, y up, the torso in the z = 0 plane (so u_x = (1, 0, 0),
# u_z = (0, 0, 1) by the sign rules of §3.8).
POSE = {
    "HipCenter": (0.0, 0.0, 0.0), "Spine": (0.0, 0.5, 0.0),
    "ShoulderCenter": (0.0, 1.0, 0.0), "Head": (0.0, 1.3, 0.05),
    "ShoulderLeft": (0.2, 0.9, 0.0), "ElbowLeft": (0.4, 0.6, 0.05),
    "WristLeft": (0.45, 0.4, 0.1), "HandLeft": (0.5, 0.3, 0.1),
    "ShoulderRight": (-0.2, 0.9, 0.0), "ElbowRight": (-0.4, 0.6, 0.05),
    "WristRight": (-0.45, 0.4, 0.1), "HandRight": (-0.5, 0.3, 0.1),
    "HipLeft": (0.1, -0.1, 0.0), "KneeLeft": (0.1, -0.5, 0.02),
    "AnkleLeft": (0.1, -0.9, 0.0), "FootLeft": (0.1, -0.95, 0.1),
    "HipRight": (-0.1, -0.1, 0.0), "KneeRight": (-0.1, -0.5, 0.02),
    "AnkleRight": (-0.1, -0.9, 0.0), "FootRight": (-0.1, -0.95, 0.1),
}  # fmt: skip


def _pose(**moved):
    """One (20, 3) frame of POSE with some joints moved."""
    frame = np.zeros((KINECT_V1.n_joints, 3))
    for name, xyz in {**POSE, **moved}.items():
        frame[KINECT_V1.index(name)] = xyz
    return frame


def _static(frame, n_frames=8, offset=(0.0, 0.0, 0.0)):
    return np.repeat(frame[None] + np.asarray(offset), n_frames, axis=0)


def _moving_stream(n_frames=40, seed=0):
    """POSE with waving arms, drifting body and sensor noise, camera offset."""
    rng = np.random.RandomState(seed)
    t = np.arange(n_frames)[:, None]
    seq = np.repeat(_pose()[None], n_frames, axis=0)
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        for joint, amp in (("Elbow", 0.15), ("Wrist", 0.3), ("Hand", 0.35)):
            k = KINECT_V1.index(joint + side)
            seq[:, k, 1] += amp * np.sin(0.3 * t[:, 0] + (sign > 0))
            seq[:, k, 2] += amp * np.cos(0.2 * t[:, 0])
            seq[:, k, 0] += sign * 0.5 * amp * np.sin(0.1 * t[:, 0])
    seq += 0.01 * rng.standard_normal(seq.shape)
    drift = np.column_stack([0.01 * t[:, 0], 0.002 * t[:, 0], 2.5 - 0.005 * t[:, 0]])
    return seq + drift[:, None, :]


def _j(name):
    """Position of a joint in the 11-joint feature order."""
    return JOINTS_GT.index(name)


def _reference_body_frame(P):
    """u_x, u_z per frame by SVD and the sign rules of §3.8 (no degenerate frames)."""
    ux, uz = [], []
    torso = [_j(n) for n in PAPER_11.torso]
    for frame in P:
        pts = frame[torso] - frame[torso].mean(axis=0)
        n = np.linalg.svd(pts)[2][-1]
        s = np.cross(
            frame[_j("ShoulderLeft")] - frame[_j("ShoulderRight")],
            frame[_j("ShoulderCenter")] - frame[_j("HipCenter")],
        )
        z = n * np.sign(n @ s)
        up = frame[_j("ShoulderCenter")] - frame[_j("HipCenter")]
        y = up - (up @ z) * z
        y /= np.linalg.norm(y)
        ux.append(np.cross(y, z))
        uz.append(z)
    return np.array(ux), np.array(uz)


def _angle(u, v):
    cos = u @ v / (np.linalg.norm(u) * np.linalg.norm(v))
    return np.arccos(np.clip(cos, -1.0, 1.0))


def _reference_angles(P):
    """Inclination, azimuth and bending angles straight from §3.9-§3.11."""
    ux, uz = _reference_body_frame(P)
    incl, azim, bend = [], [], []
    for frame, x_axis, z_axis in zip(P, ux, uz):
        row_i, row_a = [], []
        for i, j, k in TRIPLES_GT:
            pi, pj, pk = frame[_j(i)], frame[_j(j)], frame[_j(k)]
            row_i.append(_angle(pi - pj, pk - pj))
            b1 = (pj - pi) / np.linalg.norm(pj - pi)
            b2 = pk - pj
            row_a.append(_angle(b2 - (b2 @ b1) * b1, x_axis - (x_axis @ b1) * b1))
        incl.append(row_i)
        azim.append(row_a)
        bend.append(
            [0.0 if np.linalg.norm(p) < 1e-8 else _angle(p, z_axis) for p in frame]
        )
    return np.array(incl), np.array(azim), np.array(bend)


@pytest.fixture(scope="module")
def stream():
    return _moving_stream()


@pytest.fixture(scope="module")
def raw_descriptor(stream):
    """Unstandardised descriptor of the moving stream (fitted on it)."""
    desc = PoseDescriptor(standardize=False).fit([stream])
    return desc, desc.transform([stream])[0]


# --------------------------------------------------------------------------------
# Layout
# --------------------------------------------------------------------------------


def test_descriptor_has_183_features_in_the_layout_of_spec_3_13(raw_descriptor):
    desc, Z = raw_descriptor
    names = desc.get_feature_names_out()
    assert desc.n_features_out_ == N_FEATURES_PAPER11
    assert Z.shape == (40, N_FEATURES_PAPER11)
    assert len(names) == N_FEATURES_PAPER11
    for start, stop, prefix in LAYOUT_GT:
        assert all(n.startswith(prefix) for n in names[start:stop]), prefix
    expected = [
        f"{kind}_{j}_{c}"
        for kind in ("pos", "vel", "acc")
        for j in JOINTS_GT
        for c in "xyz"
    ]
    expected += [f"incl_{'_'.join(t)}" for t in TRIPLES_GT]
    expected += [f"azim_{'_'.join(t)}" for t in TRIPLES_GT]
    expected += [f"bend_{j}" for j in JOINTS_GT]
    expected += [f"dist_{a}_{b}" for a, b in combinations(JOINTS_GT, 2)]
    assert_array_equal(names, expected)


def test_descriptor_root_features_are_constant_zero(raw_descriptor):
    _, Z = raw_descriptor
    assert_allclose(Z[:, CONSTANT_ZERO_COLUMNS], 0.0, atol=1e-12)
    # everything else moves in this stream
    others = np.setdiff1d(np.arange(N_FEATURES_PAPER11), CONSTANT_ZERO_COLUMNS)
    assert (Z[:, others].std(axis=0) > 0).all()


def test_descriptor_standardised_training_frames_have_zero_mean_unit_std(stream):
    desc = PoseDescriptor().fit([stream])
    Z = desc.transform([stream])[0]
    moving = np.setdiff1d(np.arange(N_FEATURES_PAPER11), CONSTANT_ZERO_COLUMNS)
    assert_allclose(Z.mean(axis=0), 0.0, atol=1e-9)
    assert_allclose(Z[:, moving].std(axis=0), 1.0, rtol=1e-9)
    # decision D10: a constant feature keeps scale 1 and stays 0
    assert_allclose(desc.scale_[list(CONSTANT_ZERO_COLUMNS)], 1.0)
    assert_allclose(Z[:, CONSTANT_ZERO_COLUMNS], 0.0, atol=1e-12)


def test_descriptor_full20_has_426_features(stream):
    desc = PoseDescriptor(joints="full20", standardize=False).fit([stream])
    Z = desc.transform([stream])[0]
    assert desc.n_features_out_ == N_FEATURES_FULL20
    assert Z.shape == (40, N_FEATURES_FULL20)
    assert len(desc.get_feature_names_out()) == N_FEATURES_FULL20
    assert np.isfinite(Z).all()
    # 20 joints in Kinect order: the first position block is HipCenter, then Spine
    assert_array_equal(
        desc.get_feature_names_out()[:6],
        [
            "pos_HipCenter_x",
            "pos_HipCenter_y",
            "pos_HipCenter_z",
            "pos_Spine_x",
            "pos_Spine_y",
            "pos_Spine_z",
        ],
    )


def test_descriptor_accepts_a_custom_joint_set(stream):
    desc = PoseDescriptor(joints=PAPER_11, standardize=False).fit([stream])
    ref = PoseDescriptor(standardize=False).fit([stream])
    assert_allclose(desc.transform([stream])[0], ref.transform([stream])[0])


# --------------------------------------------------------------------------------
# Invariances and static poses
# --------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["constant", "per_frame"])
def test_descriptor_is_invariant_to_translating_the_whole_skeleton(stream, kind):
    if kind == "constant":
        shift = np.array([1.5, -0.3, 2.0])
    else:
        t = np.arange(len(stream))[:, None]
        shift = np.hstack([np.sin(t), 0.1 * t, -0.05 * t])[:, None, :]
    shifted = stream + shift
    desc = PoseDescriptor().fit([stream])
    assert_allclose(
        desc.transform([shifted])[0], desc.transform([stream])[0], atol=1e-9
    )
    refit = PoseDescriptor().fit([shifted])
    assert_allclose(refit.link_lengths_, desc.link_lengths_, rtol=1e-12)
    assert_allclose(refit.mean_, desc.mean_, atol=1e-9)


def test_descriptor_static_pose_has_zero_velocity_and_acceleration():
    seq = _static(_pose(), n_frames=8, offset=(0.3, 0.1, 2.5))
    Z = PoseDescriptor(standardize=False).fit_transform([seq])[0]
    assert_allclose(Z[:, 33:99], 0.0, atol=1e-12)
    # positions: the root-centred pose itself in every frame (replicate borders)
    expected = _pose()[[KINECT_V1.index(j) for j in JOINTS_GT]].ravel()
    assert_allclose(Z[:, :33], np.tile(expected, (8, 1)), atol=1e-12)


def test_descriptor_positions_are_the_gaussian_smoothed_root_centred_joints(stream):
    keep = [KINECT_V1.index(j) for j in JOINTS_GT]
    desc = PoseDescriptor(link_normalisation=False, standardize=False)
    Z = desc.fit_transform([stream])[0]
    P = stream[:, keep] - stream[:, [0]]
    padded = np.concatenate([P[:1], P[:1], P, P[-1:], P[-1:]])
    w = np.asarray(GAUSS_GT)
    ref = sum(w[m] * padded[m : m + len(P)] for m in range(5))
    assert_allclose(Z[:, :33], ref.reshape(len(P), 33), atol=1e-6)
    # §3.7 derivatives of the smoothed positions, replicate borders
    Pp = np.concatenate([ref[:1], ref[:1], ref, ref[-1:], ref[-1:]])
    T = len(P)
    vel = Pp[3 : T + 3] - Pp[1 : T + 1]
    acc = Pp[4 : T + 4] + Pp[:T] - 2 * ref
    assert_allclose(Z[:, 33:66], vel.reshape(T, 33), atol=1e-5)
    assert_allclose(Z[:, 66:99], acc.reshape(T, 33), atol=1e-5)


def test_descriptor_sigma_zero_disables_smoothing(stream):
    keep = [KINECT_V1.index(j) for j in JOINTS_GT]
    desc = PoseDescriptor(sigma=0.0, link_normalisation=False, standardize=False)
    Z = desc.fit_transform([stream])[0]
    P = stream[:, keep] - stream[:, [0]]
    assert_allclose(Z[:, :33], P.reshape(len(P), 33), atol=1e-12)


# --------------------------------------------------------------------------------
# Gaussian smoothing (§3.6, §11 item 4)
# --------------------------------------------------------------------------------


def test_gaussian_kernel_matches_fspecial_sigma_1():
    w = gaussian_kernel(1.0)
    assert_allclose(w, GAUSS_GT, atol=ATOL_6DP)
    assert_allclose(w.sum(), 1.0, rtol=1e-12)


def test_gaussian_kernel_of_other_sigma_is_the_normalised_sampled_gaussian():
    m = np.arange(-2, 3)
    ref = np.exp(-(m**2) / (2 * 2.0**2))
    assert_allclose(gaussian_kernel(2.0), ref / ref.sum(), rtol=1e-12)
    assert gaussian_kernel(1.0, size=7).shape == (7,)


@pytest.mark.parametrize("border", sorted(SMOOTH_GT))
def test_smooth_time_reproduces_the_test_vectors(border):
    x = np.asarray(SMOOTH_IN)[:, None]
    out = _smooth_time(x, gaussian_kernel(1.0), border)
    assert out.shape == (6, 1)
    assert_allclose(out[:, 0], SMOOTH_GT[border], atol=ATOL_4DP)


def test_smooth_time_smooths_every_column_of_a_3d_array_alike():
    x = np.asarray(SMOOTH_IN)
    P = np.stack([x, 2 * x, -x], axis=1)[:, None, :]  # (T, 1, 3)
    out = _smooth_time(P, gaussian_kernel(1.0), "replicate")[:, 0]
    ref = np.asarray(SMOOTH_GT["replicate"])
    assert_allclose(out, np.column_stack([ref, 2 * ref, -ref]), atol=2 * ATOL_4DP)


def test_descriptor_border_parameter_is_used(stream):
    keep = [KINECT_V1.index(j) for j in JOINTS_GT]
    Z = PoseDescriptor(
        border="zero", link_normalisation=False, standardize=False
    ).fit_transform([stream])[0]
    # zero padding pulls the first frame towards the root by the two missing taps
    P0 = (stream[0, keep] - stream[0, 0]).ravel()
    P1 = (stream[1, keep] - stream[1, 0]).ravel()
    P2 = (stream[2, keep] - stream[2, 0]).ravel()
    w = np.asarray(GAUSS_GT)
    assert_allclose(Z[0, :33], w[2] * P0 + w[3] * P1 + w[4] * P2, atol=1e-6)


# --------------------------------------------------------------------------------
# Link normalisation (§3.5, §11 item 7)
# --------------------------------------------------------------------------------


def _link_indices():
    return np.array([[KINECT_V1.index(a), KINECT_V1.index(b)] for a, b in LINKS_GT])


@pytest.mark.parametrize("direction", ["original", "simao"])
def test_link_normalise_sets_every_link_to_its_reference_length(direction):
    rng = np.random.RandomState(0)
    q = rng.normal(0, 0.4, (6, 20, 3))
    q -= q[:, [0]]  # root-centred
    links = _link_indices()
    lengths = np.linspace(0.05, 0.6, len(links))
    before = q.copy()
    p = _link_normalise(q, links, lengths, direction)
    got = np.linalg.norm(p[:, links[:, 1]] - p[:, links[:, 0]], axis=2)
    assert_allclose(got, np.tile(lengths, (6, 1)), atol=1e-9)
    assert_allclose(p[:, 0], 0.0)
    assert_array_equal(q, before)  # the input is not modified


def test_link_normalise_original_direction_keeps_every_link_direction():
    rng = np.random.RandomState(1)
    q = rng.normal(0, 0.4, (5, 20, 3))
    q -= q[:, [0]]
    links = _link_indices()
    p = _link_normalise(q, links, np.full(len(links), 0.3), "original")
    for a, b in links:
        u_new = p[:, b] - p[:, a]
        u_old = q[:, b] - q[:, a]
        u_old /= np.linalg.norm(u_old, axis=1, keepdims=True)
        assert_allclose(u_new, 0.3 * u_old, atol=1e-12)


def test_link_normalise_simao_direction_points_from_normalised_parent():
    rng = np.random.RandomState(2)
    q = rng.normal(0, 0.4, (3, 20, 3))
    q -= q[:, [0]]
    links = _link_indices()
    p = _link_normalise(q, links, np.full(len(links), 0.3), "simao")
    for a, b in links:
        d = q[:, b] - p[:, a]
        assert_allclose(
            p[:, b] - p[:, a],
            0.3 * d / np.linalg.norm(d, axis=1, keepdims=True),
            atol=1e-12,
        )


def test_link_normalise_zero_length_link_puts_child_on_parent():
    q = _pose()[None].copy()
    q[0, KINECT_V1.index("WristLeft")] = q[0, KINECT_V1.index("ElbowLeft")]
    p = _link_normalise(q, _link_indices(), np.full(13, 0.25), "original")
    assert_allclose(
        p[0, KINECT_V1.index("WristLeft")], p[0, KINECT_V1.index("ElbowLeft")]
    )
    assert np.isfinite(p).all()


def test_descriptor_link_lengths_are_mean_lengths_over_tracked_training_frames():
    a = _moving_stream(30, seed=0)
    b = _moving_stream(20, seed=1) * 1.1  # a taller subject
    b[[3, 7]] = 0.0  # untracked frames do not count
    desc = PoseDescriptor().fit([a, b])
    links = _link_indices()
    frames = np.concatenate([a, np.delete(b, [3, 7], axis=0)])
    frames = frames - frames[:, [0]]
    ref = np.linalg.norm(frames[:, links[:, 1]] - frames[:, links[:, 0]], axis=2)
    assert_allclose(desc.link_lengths_, ref.mean(axis=0), rtol=1e-12)


def test_descriptor_normalised_links_equal_the_training_lengths(stream):
    desc = PoseDescriptor(sigma=0.0, standardize=False).fit([stream])
    other = _moving_stream(25, seed=3) * 0.8  # smaller subject, other motion
    Z = desc.transform([other])[0]
    names = list(desc.get_feature_names_out())
    for k, (a, b) in enumerate(LINKS_GT):
        if a in JOINTS_GT and b in JOINTS_GT:
            col = names.index(f"dist_{a}_{b}" if _j(a) < _j(b) else f"dist_{b}_{a}")
            assert_allclose(Z[:, col], desc.link_lengths_[k], atol=1e-9)


# --------------------------------------------------------------------------------
# Body frame and angles (§3.8-§3.11)
# --------------------------------------------------------------------------------


def _fit_raw(frame, n_frames=6):
    """Raw descriptor of a static pose, fitted on itself (links keep their length)."""
    seq = _static(frame, n_frames)
    return PoseDescriptor(standardize=False).fit_transform([seq])[0]


def test_descriptor_inclination_worked_example():
    Z = _fit_raw(_pose(**INCLINATION_EXAMPLE))
    assert_allclose(Z[:, INCL + 0], INCLINATION_GT, atol=1e-9)  # T1 = (HC, SC, Head)


def test_descriptor_azimuth_worked_example():
    Z = _fit_raw(_pose(**AZIMUTH_EXAMPLE))
    assert_allclose(Z[:, AZIM + 0], AZIMUTH_GT, atol=1e-9)  # T1, u_x = (1, 0, 0)


def test_descriptor_bending_worked_example():
    Z = _fit_raw(_pose(ElbowLeft=BENDING_POINT))
    assert_allclose(Z[:, BEND + _j("ElbowLeft")], BENDING_GT, atol=1e-9)
    assert_allclose(Z[:, BEND + _j("HipCenter")], 0.0)  # p = 0 -> 0
    # joints in the torso plane are perpendicular to the torso normal
    for name in ("ShoulderCenter", "ShoulderLeft", "HipRight"):
        assert_allclose(Z[:, BEND + _j(name)], np.pi / 2, atol=1e-9)


def test_descriptor_zero_length_bone_gives_degenerate_angles():
    Z = _fit_raw(_pose(Head=POSE["ShoulderCenter"]))
    assert_allclose(Z[:, INCL + 0], np.pi / 2)  # decision D8: alpha = pi/2
    assert_allclose(Z[:, AZIM + 0], 0.0)  # beta = 0
    assert np.isfinite(Z).all()


BODY_FRAME_ARGS = (
    [JOINTS_GT.index(n) for n in PAPER_11.torso],
    [JOINTS_GT.index("ShoulderLeft"), JOINTS_GT.index("ShoulderRight")],
    [JOINTS_GT.index("HipCenter"), JOINTS_GT.index("ShoulderCenter")],
)
YAW = 0.4  # radians


def _turned_pose():
    """The 11 joints of POSE turned by YAW about the vertical axis."""
    c, s = np.cos(YAW), np.sin(YAW)
    good = _pose()[[KINECT_V1.index(j) for j in JOINTS_GT]]
    return good @ np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])


def test_body_frame_follows_the_sign_rules():
    P = _pose()[[KINECT_V1.index(j) for j in JOINTS_GT]][None]
    u_x, u_z = _body_frame(P, *BODY_FRAME_ARGS)
    assert_allclose(u_x, [[1, 0, 0]], atol=1e-12)
    assert_allclose(u_z, [[0, 0, 1]], atol=1e-12)
    mirrored = P.copy()
    mirrored[..., 0] *= -1  # the left shoulder now on -x: both axes flip
    u_x, u_z = _body_frame(mirrored, *BODY_FRAME_ARGS)
    assert_allclose(u_x, [[-1, 0, 0]], atol=1e-12)
    assert_allclose(u_z, [[0, 0, -1]], atol=1e-12)


def test_body_frame_degenerate_frame_reuses_previous_basis_or_camera_axes():
    c, s = np.cos(YAW), np.sin(YAW)
    collapsed = np.zeros((11, 3))  # every joint at the root: no torso plane
    P = np.stack([collapsed, _turned_pose(), collapsed])
    u_x, u_z = _body_frame(P, *BODY_FRAME_ARGS)
    assert_allclose(u_x[0], [1, 0, 0])  # first-frame fallback: camera axes
    assert_allclose(u_z[0], [0, 0, 1])
    assert_allclose(u_x[1], [c, 0, -s], atol=1e-12)
    assert_allclose(u_z[1], [s, 0, c], atol=1e-12)
    assert_allclose(u_x[2], u_x[1])  # degenerate: previous frame's basis
    assert_allclose(u_z[2], u_z[1])


def test_body_frame_collinear_torso_is_degenerate():
    collinear = np.zeros((11, 3))
    collinear[:, 1] = np.linspace(0.0, 1.0, 11)  # every joint on the y axis: s = 0
    u_x, u_z = _body_frame(np.stack([_turned_pose(), collinear]), *BODY_FRAME_ARGS)
    assert_allclose(u_x[1], u_x[0])
    assert_allclose(u_z[1], u_z[0])


def test_descriptor_angles_match_a_direct_implementation_of_the_spec(raw_descriptor):
    _, Z = raw_descriptor
    P = Z[:, :33].reshape(-1, 11, 3)  # the smoothed positions the angles use
    incl, azim, bend = _reference_angles(P)
    assert_allclose(Z[:, INCL : INCL + 9], incl, atol=1e-7)
    assert_allclose(Z[:, AZIM : AZIM + 9], azim, atol=1e-6)
    assert_allclose(Z[:, BEND : BEND + 11], bend, atol=1e-6)


# --------------------------------------------------------------------------------
# Distances (§3.12)
# --------------------------------------------------------------------------------


def test_distances_match_brute_force():
    rng = np.random.RandomState(0)
    P = rng.normal(0, 0.5, (7, 11, 3))
    pairs = np.array(list(combinations(range(11), 2)))
    ref = np.array([[np.linalg.norm(f[a] - f[b]) for a, b in pairs] for f in P])
    assert_allclose(_distances(P, pairs), ref, atol=1e-12)


def test_descriptor_distances_are_those_of_the_smoothed_positions(raw_descriptor):
    _, Z = raw_descriptor
    P = Z[:, :33].reshape(-1, 11, 3)
    ref = np.array(
        [
            [np.linalg.norm(f[a] - f[b]) for a, b in combinations(range(11), 2)]
            for f in P
        ]
    )
    assert_allclose(Z[:, DIST:], ref, atol=1e-9)


def test_descriptor_spine_distance_scale_makes_hc_sc_distance_one(stream):
    raw = PoseDescriptor(standardize=False).fit_transform([stream])[0]
    Z = PoseDescriptor(distance_scale="spine", standardize=False).fit_transform(
        [stream]
    )[0]
    assert_allclose(Z[:, DIST], 1.0, rtol=1e-12)  # dist_HipCenter_ShoulderCenter
    assert_allclose(Z[:, DIST:], raw[:, DIST:] / raw[:, [DIST]], rtol=1e-12)
    assert_allclose(Z[:, :DIST], raw[:, :DIST])


# --------------------------------------------------------------------------------
# Missing frames (§3.3)
# --------------------------------------------------------------------------------


@pytest.mark.parametrize("method", sorted(FILL_GT))
def test_fill_missing_reproduces_hand_values(method):
    q = np.asarray(FILL_IN)[:, None, None] * np.ones((1, 2, 3))
    miss = np.isnan(q[:, 0, 0])
    out = _fill_missing(q, miss, method)
    assert_allclose(out[:, 1, 2], FILL_GT[method])
    assert not np.isnan(out).any()


def test_fill_missing_without_missing_frames_returns_input():
    q = np.ones((4, 2, 3))
    assert_array_equal(_fill_missing(q, np.zeros(4, bool), "linear"), q)


@pytest.mark.parametrize("fill", ["linear", "hold"])
def test_descriptor_fills_zero_and_nan_frames(stream, fill):
    seq = stream[:12].copy()
    seq[5] = 0.0  # untracked: all zeros
    seq[6, 4, 1] = np.nan  # untracked: any NaN
    seq[:2] = 0.0  # leading untracked run
    filled = stream[:12].copy()
    if fill == "linear":
        filled[5] = stream[4] + (stream[7] - stream[4]) / 3
        filled[6] = stream[4] + 2 * (stream[7] - stream[4]) / 3
    else:
        filled[5] = filled[6] = stream[4]
    filled[:2] = stream[2]
    desc = PoseDescriptor(fill=fill).fit([stream])
    Z = desc.transform([seq])[0]
    assert np.isfinite(Z).all()
    assert_allclose(Z, desc.transform([filled])[0], atol=1e-9)


def test_descriptor_all_missing_sequence_gives_zeros_and_is_ignored_in_fit(stream):
    empty = np.zeros((9, 20, 3))
    nan = np.full((4, 20, 3), np.nan)
    with pytest.warns(UserWarning, match=r"X\[1\] has no tracked frame"):
        desc = PoseDescriptor().fit([stream, empty])
    ref = PoseDescriptor().fit([stream])
    assert_allclose(desc.link_lengths_, ref.link_lengths_)
    assert_allclose(desc.mean_, ref.mean_)
    assert_allclose(desc.scale_, ref.scale_)
    Z = desc.transform([empty, nan])
    assert [z.shape for z in Z] == [(9, 183), (4, 183)]
    assert_array_equal(Z[0], 0.0)
    assert_array_equal(Z[1], 0.0)
    raw = PoseDescriptor(standardize=False).fit([stream]).transform([empty])[0]
    assert_array_equal(raw, 0.0)


def test_descriptor_fit_on_untracked_sequences_only_raises():
    with pytest.warns(UserWarning), pytest.raises(ValueError, match="untracked"):
        PoseDescriptor().fit([np.zeros((5, 20, 3))])


# --------------------------------------------------------------------------------
# Real data
# --------------------------------------------------------------------------------


def test_descriptor_on_real_montalbano_sample(shared_data):
    from skgesture.datasets import load_chalearn

    folder = shared_data / "chalearn_montalbano" / "v2_2014_samples"
    data = load_chalearn(folder, samples=["Sample0101"])
    X = data.X[0]
    assert X.shape[1:] == (20, 3)
    Z = PoseDescriptor().fit_transform([X])[0]
    assert Z.shape == (len(X), 183)
    assert np.isfinite(Z).all()
    raw = PoseDescriptor(standardize=False).fit_transform([X])[0]
    assert_allclose(raw[:, CONSTANT_ZERO_COLUMNS], 0.0, atol=1e-12)
    # §3.14: mean root-relative heights of Head and ShoulderCenter
    assert abs(raw[:, 3 * _j("Head") + 1].mean() - HEAD_Y_GT) < ATOL_POSE_MEAN
    sc_y = raw[:, 3 * _j("ShoulderCenter") + 1].mean()
    assert abs(sc_y - SHOULDER_CENTER_Y_GT) < ATOL_POSE_MEAN


# --------------------------------------------------------------------------------
# Input validation
# --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "bad, message",
    [
        (np.ones((5, 60)), r"X\[1\] has shape \(5, 60\); expected \(n_frames, 20, 3\)"),
        (
            np.ones((5, 19, 3)),
            r"X\[1\] has frames of shape \(19, 3\); expected \(20, 3\)",
        ),
        (np.ones((0, 20, 3)), r"X\[1\] has 0 frames"),
        (np.full((5, 20, 3), np.inf), r"X\[1\] contains infinite values"),
    ],
)
def test_descriptor_rejects_bad_sequences_naming_index_and_shape(stream, bad, message):
    with pytest.raises(ValueError, match=message):
        PoseDescriptor().fit([stream, bad])
    desc = PoseDescriptor().fit([stream])
    with pytest.raises(ValueError, match=message):
        desc.transform([stream, bad])


def test_descriptor_rejects_an_empty_list():
    with pytest.raises(ValueError, match="X is empty"):
        PoseDescriptor().fit([])


def test_descriptor_rejects_a_single_array_instead_of_a_list(stream):
    with pytest.raises(TypeError, match=r"wrap a single sequence as \[X\]"):
        PoseDescriptor().fit(stream)
    desc = PoseDescriptor().fit([stream])
    with pytest.raises(TypeError, match="list of sequences"):
        desc.transform(stream)


def test_descriptor_returns_one_array_per_sequence_with_same_frames(stream):
    X = [stream, stream[:7], _static(_pose(), 3)]
    Z = PoseDescriptor().fit(X).transform(X)
    assert isinstance(Z, list)
    assert [z.shape for z in Z] == [(40, 183), (7, 183), (3, 183)]


# --------------------------------------------------------------------------------
# Untracked frames: masked output, masked input (issue 11)
# --------------------------------------------------------------------------------


def test_descriptor_masks_the_rows_of_untracked_frames(stream):
    seq = stream.copy()
    seq[5] = 0.0  # all zeros
    seq[9, 4, 1] = np.nan  # one NaN joint
    desc = PoseDescriptor().fit([stream])
    Z = desc.transform([seq, stream])
    assert isinstance(Z[0], np.ma.MaskedArray)
    rows = np.isin(np.arange(len(seq)), [5, 9])
    assert_array_equal(np.ma.getmaskarray(Z[0]), np.repeat(rows[:, None], 183, 1))
    assert np.isfinite(Z[0].data).all()  # the filled frames are described as before
    assert not isinstance(Z[1], np.ma.MaskedArray)  # nothing untracked: plain
    untracked = desc.transform([np.zeros((6, 20, 3))])[0]
    assert np.ma.getmaskarray(untracked).all()


def test_descriptor_default_fill_is_linear(stream):
    # docs/method.md §3.3, decision D11: interpolate between the tracked neighbours
    assert PoseDescriptor().fill == "linear"
    seq = stream.copy()
    seq[10:13] = 0.0
    by_hand = stream.copy()
    for k, t in enumerate(range(10, 13), start=1):
        by_hand[t] = stream[9] + k * (stream[13] - stream[9]) / 4
    desc = PoseDescriptor().fit([stream])
    assert_allclose(desc.transform([seq])[0].data, desc.transform([by_hand])[0])
    hold = PoseDescriptor(fill="hold").fit([stream]).transform([seq])[0].data
    assert not np.allclose(hold, desc.transform([seq])[0].data)


def test_descriptor_ignores_what_lies_under_the_mask_of_a_masked_input(stream):
    garbage = stream.copy()
    garbage[10:14] = 1e3  # what a broken sensor might leave under the mask
    garbage[20, 3] = np.inf
    mask = np.zeros(stream.shape, dtype=bool)
    mask[10:14] = True
    mask[20, 3] = True  # one masked joint marks the frame untracked
    masked = np.ma.MaskedArray(garbage, mask=mask)
    nan = stream.copy()
    nan[10:14] = np.nan
    nan[20, 3] = np.nan
    desc = PoseDescriptor().fit([stream])
    Z, ref = desc.transform([masked])[0], desc.transform([nan])[0]
    assert_array_equal(Z.data, ref.data)
    assert_array_equal(
        np.ma.getmaskarray(Z)[:, 0], np.isin(range(40), [10, 11, 12, 13, 20])
    )
    # fit honours the mask too
    fitted = PoseDescriptor().fit([masked])
    assert_allclose(fitted.mean_, PoseDescriptor().fit([nan]).mean_)


@pytest.mark.parametrize(
    "scale, value, message",
    [
        (1e200, np.nan, r"X\[1\] has the value .* at frame 0, beyond the accepted "
         r"magnitude 1e\+05"),  # squared norms would overflow to NaN
        (1.0, 2e5, r"X\[1\] has the value 2e\+05 at frame 7"),
        (1.0, -np.inf, r"X\[1\] contains infinite values \(first at frame 7\)"),
    ],
)  # fmt: skip
def test_descriptor_refuses_absurd_coordinates(stream, scale, value, message):
    bad = stream * scale
    if not np.isnan(value):
        bad[7, 2, 1] = value
    desc = PoseDescriptor().fit([stream])
    with pytest.raises(ValueError, match=message):
        desc.transform([stream, bad])
    with pytest.raises(ValueError, match=message):
        PoseDescriptor().fit([stream, bad])


def test_descriptor_accepts_coordinates_in_millimetres(stream):
    Z = PoseDescriptor().fit_transform([stream * 1000.0])[0]
    assert np.isfinite(Z).all()


def test_descriptor_refuses_joints_changed_after_fit(stream):
    desc = PoseDescriptor().fit([stream]).set_params(joints="full20")
    for method in (desc.transform, lambda X: desc.get_feature_names_out()):
        with pytest.raises(ValueError, match=r"fitted for 'paper11' \(183 features\) "
                           r"but joints is now 'full20' \(426 features\)"):  # fmt: skip
            method([stream])
    desc.set_params(joints="paper11")
    assert desc.transform([stream])[0].shape == (40, 183)


def test_descriptor_output_container_stays_a_list_of_arrays(stream):
    import sklearn

    desc = PoseDescriptor()
    assert desc.set_output(transform="default") is desc
    assert desc.set_output() is desc
    with pytest.raises(ValueError, match="list of per-sequence arrays"):
        desc.set_output(transform="pandas")
    with sklearn.config_context(transform_output="pandas"):
        Z = PoseDescriptor().fit_transform([stream])
    assert isinstance(Z, list) and isinstance(Z[0], np.ndarray)
