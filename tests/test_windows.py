"""Dynamic poses (docs/method.md §5.1-§5.3, §6.2): offsets, borders, masks and the
windows of one period of activity (§11 item 8)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.utils._param_validation import InvalidParameterError

from skgesture import DynamicPoseWindow
from skgesture._multiscale._rules import period_windows
from skgesture._windows import dynamic_poses
from skgesture.utils._resize import resize_frames

# Descriptor of frame t = (10 t, -t): every window value names its source frame.
N_FRAMES = 12
D_RAMP = np.column_stack([10.0 * np.arange(N_FRAMES), -np.arange(N_FRAMES)])

# (centre, step) -> source frames of the 3 poses, clipped to 0..11 (edge replication).
SOURCES_GT = {
    (0, 4): (0, 0, 4),
    (1, 3): (0, 1, 4),
    (2, 2): (0, 2, 4),
    (5, 3): (2, 5, 8),
    (6, 4): (2, 6, 10),
    (8, 4): (4, 8, 11),
    (10, 2): (8, 10, 11),
    (11, 4): (7, 11, 11),
}
# n_poses = 5, step 2, centre 5 -> frames 1, 3, 5, 7, 9; centre 1 -> 0, 0, 1, 3, 5
SOURCES_5_GT = {5: (1, 3, 5, 7, 9), 1: (0, 0, 1, 3, 5)}

# §5.2 / §11 item 8: a period [a, a + L) with step 4.
PERIOD_START = 3
CENTRES_L17_GT = (7, 9, 11, 13, 15)  # a + 4 .. a + 12, every 2 frames
CENTRES_RESIZED_GT = (4, 6, 8, 10, 12)  # in the period resized to 17 frames
RESIZED_LENGTH = 17


def _window(sources):
    return np.concatenate([D_RAMP[f] for f in sources]).astype(np.float32)


def test_dynamic_poses_concatenates_offset_frames_with_edge_replication():
    steps = (4, 3, 2)
    W = dynamic_poses(D_RAMP, steps)
    assert W.shape == (N_FRAMES, 3, 6)
    assert W.dtype == np.float32
    for (centre, step), sources in SOURCES_GT.items():
        assert_array_equal(W[centre, steps.index(step)], _window(sources))


def test_dynamic_poses_with_five_poses_and_given_centres():
    centres = np.array(sorted(SOURCES_5_GT))
    W = dynamic_poses(D_RAMP, (2,), n_poses=5, centres=centres)
    assert W.shape == (2, 1, 10)
    for row, centre in enumerate(centres):
        assert_array_equal(W[row, 0], _window(SOURCES_5_GT[centre]))


def test_dynamic_pose_window_transform_gives_one_window_array_per_sequence():
    X = [D_RAMP, D_RAMP[:5]]
    W = DynamicPoseWindow(steps=(4, 3, 2)).fit(X).transform(X)
    assert isinstance(W, list)
    assert [w.shape for w in W] == [(12, 3, 6), (5, 3, 6)]
    assert_array_equal(W[0], dynamic_poses(D_RAMP, (4, 3, 2)))
    # the short sequence replicates its own edges
    assert_array_equal(W[1][4, 0], _window((0, 4, 4)))


def test_dynamic_pose_window_default_is_method_a_549_wide():
    D = np.random.RandomState(0).normal(size=(20, 183))
    W = DynamicPoseWindow().fit_transform([D])[0]
    assert W.shape == (20, 1, 549)  # §5.1: [x(t-4), x(t), x(t+4)]
    assert_allclose(W[10, 0], np.concatenate([D[6], D[10], D[14]]), rtol=1e-6)


def test_dynamic_pose_window_masked_input_keeps_row_mask():
    rows = np.zeros(N_FRAMES, bool)
    rows[[0, 1, 2, 9, 10, 11]] = True
    X = np.ma.MaskedArray(D_RAMP, mask=np.repeat(rows[:, None], 2, axis=1))
    W = DynamicPoseWindow(steps=(4, 2)).fit_transform([X])[0]
    assert isinstance(W, np.ma.MaskedArray)
    assert_array_equal(np.ma.getmaskarray(W).all(axis=(1, 2)), rows)
    assert_array_equal(np.ma.getmaskarray(W).any(axis=(1, 2)), rows)
    # values come from the underlying data, masked rows included
    assert_array_equal(W.data, dynamic_poses(D_RAMP, (4, 2)))


def test_dynamic_pose_window_plain_input_gives_plain_output():
    W = DynamicPoseWindow().fit_transform([D_RAMP])[0]
    assert not isinstance(W, np.ma.MaskedArray)


STEPS_ERROR = (
    r"'steps' parameter of DynamicPoseWindow must be a non-empty tuple of ints"
)


@pytest.mark.parametrize(
    "params, error, message",
    [
        ({"steps": ()}, InvalidParameterError, STEPS_ERROR),
        ({"steps": (4, 0)}, InvalidParameterError, STEPS_ERROR),
        ({"steps": (4, "a")}, InvalidParameterError, STEPS_ERROR),
        ({"steps": (2.5,)}, InvalidParameterError, STEPS_ERROR),  # not truncated
        ({"steps": (4, True)}, InvalidParameterError, STEPS_ERROR),
        ({"n_poses": 2}, ValueError, "n_poses must be odd"),
    ],
)
def test_dynamic_pose_window_rejects_bad_steps(params, error, message):
    with pytest.raises(error, match=message):
        DynamicPoseWindow(**params).fit([D_RAMP])


def test_dynamic_pose_window_transform_rechecks_steps_changed_after_fit():
    win = DynamicPoseWindow().fit([D_RAMP]).set_params(steps=(2.5,))
    with pytest.raises(ValueError, match="steps must be a non-empty tuple"):
        win.transform([D_RAMP])


@pytest.mark.parametrize(
    "bad, message",
    [
        (np.inf, r"X\[1\] contains NaN or infinite values \(first at frame 3\)"),
        (np.nan, r"X\[1\] contains NaN or infinite values \(first at frame 3\)"),
        # float32 would turn this into inf: refused before the cast
        (1e39, r"X\[1\] has the value 1e\+39 at frame 3, beyond the accepted"),
    ],
)
def test_dynamic_pose_window_refuses_values_float32_cannot_hold(bad, message):
    win = DynamicPoseWindow().fit([D_RAMP])
    X = D_RAMP.copy()
    X[3, 1] = bad
    for method in (win.transform, DynamicPoseWindow().fit):
        with pytest.raises(ValueError, match=message):
            method([D_RAMP, X])


def test_dynamic_pose_window_masks_rows_with_any_masked_value():
    mask = np.zeros(D_RAMP.shape, dtype=bool)
    mask[2, 0] = True  # one masked value marks the row
    W = DynamicPoseWindow().fit_transform([np.ma.MaskedArray(D_RAMP, mask=mask)])[0]
    rows = np.arange(N_FRAMES) == 2
    assert_array_equal(np.ma.getmaskarray(W).all(axis=(1, 2)), rows)
    assert not np.ma.getmaskarray(W)[~rows].any()


def test_dynamic_pose_window_feature_names_follow_the_output_layout():
    D = np.arange(30, dtype=float).reshape(10, 3)
    win = DynamicPoseWindow(steps=(4, 2)).fit([D])
    names = win.get_feature_names_out(["a", "b", "c"]).reshape(2, 9)
    W = win.transform([D])[0]
    # frame 5, scale of step 2: the pose 2 frames before is descriptor frame 3
    assert names[1, 0] == "step2_t-2_a" and W[5, 1, 0] == D[3, 0]
    assert names[0, 8] == "step4_t+4_c" and W[5, 0, 8] == D[9, 2]
    assert win.get_feature_names_out()[0] == "step4_t-4_x0"
    with pytest.raises(ValueError, match="input_features"):
        win.get_feature_names_out(["a", "b"])


def test_dynamic_pose_window_refuses_a_dataframe_output():
    win = DynamicPoseWindow()
    assert win.set_output(transform="default") is win
    with pytest.raises(ValueError, match="list of per-sequence arrays"):
        win.set_output(transform="pandas")


def test_dynamic_pose_window_transform_checks_width_seen_in_fit():
    win = DynamicPoseWindow().fit([D_RAMP])
    with pytest.raises(ValueError, match=r"X\[0\] has frames of shape \(3,\)"):
        win.transform([np.ones((5, 3))])


# --------------------------------------------------------------------------------
# Windows of one period (§5.2, §5.3, §6.2, §11 item 8)
# --------------------------------------------------------------------------------


def _ramp_windows(steps, n_frames=40, n_features=2):
    D = np.arange(n_frames * n_features, dtype=float).reshape(n_frames, n_features)
    return D, dynamic_poses(D, steps)


def test_period_of_17_frames_gives_5_windows_at_a_plus_4_to_a_plus_12():
    D, W = _ramp_windows((4,))
    windows, centres, resized = period_windows(W, PERIOD_START, PERIOD_START + 17, (4,))
    assert not resized
    assert_array_equal(centres, CENTRES_L17_GT)
    assert_array_equal(windows, W[list(CENTRES_L17_GT)])
    # the first window starts at a, the last ends at a + 16
    assert_array_equal(windows[0, 0, :2], D[PERIOD_START])
    assert_array_equal(windows[-1, 0, -2:], D[PERIOD_START + 16])


@pytest.mark.parametrize("length", range(17, 31))
def test_period_window_count_is_floor_of_l_minus_9_over_2_plus_1(length):
    _, W = _ramp_windows((4,))
    windows, centres, resized = period_windows(W, 0, length, (4,))
    assert not resized
    assert len(windows) == (length - 9) // 2 + 1  # §5.2
    assert centres[-1] + 4 <= length - 1


def test_period_of_16_frames_is_resized_to_17():
    D, W = _ramp_windows((4,))
    windows, centres, resized = period_windows(W, PERIOD_START, PERIOD_START + 16, (4,))
    assert resized
    assert_array_equal(centres, CENTRES_RESIZED_GT)
    R = resize_frames(D[PERIOD_START : PERIOD_START + 16], RESIZED_LENGTH)
    assert R.shape == (RESIZED_LENGTH, 2)
    for row, c in enumerate(CENTRES_RESIZED_GT):
        expected = np.concatenate([R[c - 4], R[c], R[c + 4]])
        assert_allclose(windows[row, 0], expected, rtol=1e-6)


def test_period_of_1_frame_gives_5_copies_of_it():
    D, W = _ramp_windows((4, 3, 2))
    windows, centres, resized = period_windows(W, 7, 8, (4, 3, 2))
    assert resized
    assert windows.shape == (5, 3, 6)
    assert_allclose(windows, np.tile(D[7], (5, 3, 3)).reshape(5, 3, 6))


def test_period_windows_of_three_scales_share_the_step_4_centres():
    D, W = _ramp_windows((4, 3, 2))
    windows, centres, resized = period_windows(W, 10, 30, (4, 3, 2))
    assert not resized
    assert_array_equal(centres, np.arange(14, 26, 2))  # §6.2: a+4 .. b-4
    for row, c in enumerate(centres):
        for k, s in enumerate((4, 3, 2)):
            assert_array_equal(
                windows[row, k], np.concatenate([D[c - s], D[c], D[c + s]])
            )


def test_period_resize_keeps_a_constant_period_constant():
    D = np.tile([0.5, -2.0], (40, 1))
    W = dynamic_poses(D, (4,))
    windows, _, resized = period_windows(W, 5, 15, (4,))
    assert resized
    assert_allclose(windows, np.tile([0.5, -2.0], (5, 1, 3)), rtol=1e-6)
