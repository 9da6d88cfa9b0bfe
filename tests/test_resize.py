"""Time resampling of frame matrices (docs/method.md §8.5, decision D15)."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from skgesture.utils._resize import imresize_weights, resize_frames

# docs/method.md §8.5 test vector: column (0, 1, 0, 2) resized to 9 rows (4 decimals).
COLUMN_GT = np.array([0.0, 1.0, 0.0, 2.0])
RESIZED_9_GT = np.array(
    [-0.1003, 0.1319, 0.7101, 0.9896, 0.4375, -0.0159, 0.6523, 1.7477, 2.2006]
)
ATOL_4DP = 5e-5
N_MIN_FRAMES = 17  # docs/method.md §5.3: short segments are enlarged to 17 frames


def _keys(x):
    x = abs(x)
    if x <= 1:
        return 1.5 * x**3 - 2.5 * x**2 + 1
    if x < 2:
        return -0.5 * x**3 + 2.5 * x**2 - 4 * x + 2
    return 0.0


def _mirror(j, n):
    """1-based symmetric reflection with the edge repeated: 0 -> 1, n+1 -> n."""
    while j < 1 or j > n:
        j = 1 - j if j < 1 else 2 * n + 1 - j
    return j


def _scalar_imresize(col, m):
    """Scalar-loop transcription of docs/method.md §8.5 (with antialiasing)."""
    n = len(col)
    scale = m / n
    shrink = scale < 1
    width = 4 / scale if shrink else 4
    out = []
    for i in range(1, m + 1):
        u = i / scale + 0.5 * (1 - 1 / scale)
        js = range(
            math.floor(u - width / 2), math.floor(u - width / 2) + 7 + int(width)
        )
        ws = [scale * _keys(scale * (u - j)) if shrink else _keys(u - j) for j in js]
        total = sum(ws)
        out.append(sum(w * col[_mirror(j, n) - 1] for w, j in zip(ws, js)) / total)
    return np.array(out)


def test_bicubic_matches_spec_test_vector():
    assert_allclose(resize_frames(COLUMN_GT, 9), RESIZED_9_GT, rtol=0, atol=ATOL_4DP)


@pytest.mark.parametrize(
    ("n_in", "n_out"),
    [(4, 9), (16, 17), (9, 17), (2, 17), (3, 5), (8, 4), (17, 5), (10, 7)],
)
def test_bicubic_matches_scalar_transcription(n_in, n_out):
    col = np.random.default_rng(n_in * 31 + n_out).standard_normal(n_in)
    assert_allclose(resize_frames(col, n_out), _scalar_imresize(col, n_out), atol=1e-12)


def test_bicubic_is_exact_for_a_line_away_from_the_borders():
    n_in, n_out = 10, 25
    out = resize_frames(np.arange(n_in, dtype=float), n_out)
    scale = n_out / n_in
    u = np.arange(1, n_out + 1) / scale + 0.5 * (1 - 1 / scale)
    inside = (np.floor(u) - 1 >= 1) & (np.floor(u) + 2 <= n_in)
    assert inside.sum() > 10
    assert_allclose(out[inside], u[inside] - 1, atol=1e-12)


@pytest.mark.parametrize("method", ["bicubic", "pchip", "spline"])
def test_same_length_is_identity(method):
    x = np.random.default_rng(0).standard_normal((11, 3))
    assert_allclose(resize_frames(x, 11, method=method), x, atol=1e-12)


@pytest.mark.parametrize("method", ["bicubic", "pchip", "spline"])
def test_single_frame_is_repeated(method):
    x = np.array([[1.0, -2.0, 3.0]])
    out = resize_frames(x, N_MIN_FRAMES, method=method)
    assert_array_equal(out, np.repeat(x, N_MIN_FRAMES, axis=0))


@pytest.mark.parametrize("method", ["pchip", "spline"])
def test_two_frames_give_a_straight_line(method):
    out = resize_frames([[0.0], [4.0]], 5, method=method)
    assert_allclose(out[:, 0], [0.0, 1.0, 2.0, 3.0, 4.0], atol=1e-12)


def test_spline_with_three_frames_is_the_parabola():
    t = np.linspace(1, 3, 9)
    out = resize_frames([1.0, 4.0, 9.0], 9, method="spline")  # (t)^2 at t = 1, 2, 3
    assert_allclose(out, t**2, atol=1e-12)


def test_spline_reproduces_cubics():
    t = np.arange(1, 7, dtype=float)
    out = resize_frames(t**3 - 2 * t, 17, method="spline")
    tq = np.linspace(1, 6, 17)
    assert_allclose(out, tq**3 - 2 * tq, atol=1e-10)


def test_pchip_preserves_monotonicity_and_range():
    x = np.array([0.0, 0.1, 0.2, 5.0, 5.1, 5.2])
    out = resize_frames(x, N_MIN_FRAMES, method="pchip")
    assert np.all(np.diff(out) >= 0)
    assert out.min() >= 0 and out.max() <= 5.2
    assert_allclose(out[[0, -1]], [0.0, 5.2], atol=1e-12)  # end points aligned


def test_pchip_known_values():
    # pchip through (1, 0), (2, 1), (3, 0): slope 0 at the peak t = 2; end slope
    # ((2 h0 + h1) d0 - h0 d1) / (h0 + h1) = (3 + 1) / 2 = 2 (kept: |2| <= 3 |d0|),
    # so at t = 1.5 the Hermite form gives h10 * 2 + h01 * 1 = 0.125 * 2 + 0.5.
    out = resize_frames([0.0, 1.0, 0.0], 5, method="pchip")
    assert_allclose(out, [0.0, 0.75, 1.0, 0.75, 0.0], atol=1e-12)


@pytest.mark.parametrize("method", ["bicubic", "pchip", "spline"])
def test_columns_are_resized_independently(method):
    x = np.random.default_rng(1).standard_normal((12, 183))
    out = resize_frames(x, N_MIN_FRAMES, method=method)
    assert out.shape == (N_MIN_FRAMES, 183)
    for k in (0, 57, 182):
        expected = resize_frames(x[:, k], N_MIN_FRAMES, method=method)
        assert_allclose(out[:, k], expected, atol=1e-12)


@pytest.mark.parametrize(
    ("n_in", "n_out"), [(1, 5), (2, 17), (16, 17), (8, 4), (20, 3)]
)
def test_weight_rows_sum_to_one(n_in, n_out):
    w = imresize_weights(n_in, n_out)
    assert w.shape == (n_out, n_in)
    assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)


def test_shrinking_is_antialiased():
    x = np.arange(8, dtype=float)
    assert_allclose(resize_frames(x, 4), _scalar_imresize(x, 4), atol=1e-12)
    # Without antialiasing only the 4 nearest samples count.
    plain = imresize_weights(8, 4, antialiasing=False)
    assert np.count_nonzero(plain[1]) == 4
    assert np.count_nonzero(imresize_weights(8, 4)[1]) > 4


def test_dtype_is_kept_for_floats():
    assert resize_frames(np.ones((3, 2), np.float32), 5).dtype == np.float32
    assert resize_frames(np.ones((3, 2), int), 5).dtype == np.float64


@pytest.mark.parametrize("n_out", [0, -3, 2.5, True])
def test_invalid_n_out_raises(n_out):
    with pytest.raises(ValueError, match="n_out"):
        resize_frames(COLUMN_GT, n_out)


def test_invalid_input_raises():
    with pytest.raises(ValueError, match="method"):
        resize_frames(COLUMN_GT, 9, method="cubic")
    with pytest.raises(ValueError, match="1-D or 2-D"):
        resize_frames(np.zeros((2, 2, 2)), 9)
    with pytest.raises(ValueError, match="at least one frame"):
        resize_frames(np.zeros((0, 3)), 9)
