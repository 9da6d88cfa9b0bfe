"""MATLAB-style loess smoothing against the reference numbers of docs/method.md §8.1."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from skgesture.utils._smoothing import loess_kernel, loess_smooth

# docs/method.md §8.1, interior kernel table (5 decimals).
KERNELS_GT = {
    5: [0, 0, 1, 0, 0],
    7: [0, -0.07734, 0.30938, 0.53594, 0.30938, -0.07734, 0],
    9: [0, -0.05898, 0.05673, 0.30394, 0.39663, 0.30394, 0.05673, -0.05898, 0],
    11: [0, -0.03753, -0.02065, 0.12891, 0.27064, 0.31725, 0.27064, 0.12891,
         -0.02065, -0.03753, 0],
    15: [0, -0.01525, -0.03575, -0.00400, 0.07435, 0.15681, 0.21040, 0.22690,
         0.21040, 0.15681, 0.07435, -0.00400, -0.03575, -0.01525, 0],
}  # fmt: skip

# docs/method.md §8.1 test vector and its smoothed versions (4 decimals).
Y_GT = np.array(
    [0.10, 0.20, 0.90, 0.30, 0.80, 0.70, 0.95, 0.20, 0.10, 0.05, 0.60, 0.40]
)
SMOOTHED_GT = {
    5: [0.0346, 0.4471, 0.9000, 0.3000, 0.8000, 0.7000, 0.9500, 0.2000, 0.1000,
        0.0500, 0.4244, 0.4465],
    7: [0.0737, 0.3562, 0.5332, 0.6171, 0.5950, 0.8779, 0.7180, 0.3740, 0.0111,
        0.1478, 0.2988, 0.5276],
    9: [0.0984, 0.3349, 0.5152, 0.6488, 0.7026, 0.7789, 0.6808, 0.3584, 0.2153,
        0.2049, 0.3016, 0.5185],
}  # fmt: skip

# docs/method.md §11 item 5: short tracks with span 15.
SHORT_GT = [
    ([1, 3, 2, 5], [1.2410, 2.0897, 2.9103, 4.7590]),
    ([1, 3, 2, 5, 4], [1.2410, 2.0897, 2.0000, 3.9596, 4.2754]),
]

ATOL_4DP = 5e-5  # spec values have 4 decimals
ATOL_5DP = 5e-6  # kernel table has 5 decimals


def _reference_smooth(y, span, degree):
    """Point-by-point weighted polyfit written straight from docs/method.md §8.1."""
    y = np.asarray(y, dtype=float)
    n = y.size
    h = (span - 1) // 2
    out = np.empty(n)
    for i in range(n):  # 0-based
        if h <= i < n - h:
            d = np.arange(-(h - 1), h)
            x, yy = d, y[i + d]
            w = (1 - (np.abs(d) / h) ** 3) ** 3
            at = 0.0
        else:
            j = i + 1 if i < h else n - i  # 1-based distance from its end
            x = np.arange(1, span)
            seg = y[: span - 1] if i < h else y[::-1][: span - 1]
            w = (1 - (np.abs(x - j) / (span - j)) ** 3) ** 3
            yy, at = seg, j
        deg = min(degree, x.size - 1)
        coef = np.polyfit(x, yy, deg, w=np.sqrt(w))
        out[i] = np.polyval(coef, at)
    return out


@pytest.mark.parametrize("span", sorted(KERNELS_GT))
def test_loess_kernel_matches_spec_table(span):
    assert_allclose(loess_kernel(span), KERNELS_GT[span], rtol=0, atol=ATOL_5DP)


def test_loess_kernel_is_symmetric_and_sums_to_one():
    for span in (5, 7, 9, 11, 15, 21, 31):
        for method in ("loess", "lowess"):
            k = loess_kernel(span, method=method)
            assert_allclose(k, k[::-1], rtol=0, atol=1e-14)
            assert_allclose(k.sum(), 1.0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("span", sorted(SMOOTHED_GT))
def test_loess_matches_spec_test_vectors(span):
    assert_allclose(loess_smooth(Y_GT, span), SMOOTHED_GT[span], rtol=0, atol=ATOL_4DP)


def test_loess_default_span_is_five_and_leaves_interior_unchanged():
    out = loess_smooth(Y_GT)
    assert_allclose(out, SMOOTHED_GT[5], rtol=0, atol=ATOL_4DP)
    assert_array_equal(out[2:-2], Y_GT[2:-2])


def test_even_span_behaves_as_next_odd():
    assert_array_equal(loess_smooth(Y_GT, 4), loess_smooth(Y_GT, 5))
    assert_array_equal(loess_smooth(Y_GT, 6), loess_smooth(Y_GT, 7))
    assert_array_equal(loess_kernel(4), loess_kernel(5))


def test_non_integer_span_is_floored():
    assert_array_equal(loess_smooth(Y_GT, 7.9), loess_smooth(Y_GT, 7))


@pytest.mark.parametrize(("y", "expected"), SHORT_GT)
def test_short_tracks_use_end_point_fits(y, expected):
    assert_allclose(loess_smooth(y, 15), expected, rtol=0, atol=ATOL_4DP)


def test_fractional_span_is_a_fraction_of_the_length():
    # 0.5 * 12 = 6 -> forced odd 7; 0.3 * 12 = 3.6 -> ceil 4 -> 5
    assert_array_equal(loess_smooth(Y_GT, 0.5), loess_smooth(Y_GT, 7))
    assert_array_equal(loess_smooth(Y_GT, 0.3), loess_smooth(Y_GT, 5))


@pytest.mark.parametrize("span", [1, 2, 3, 1.0])
def test_tiny_spans_return_data_unchanged(span):
    # span 1 returns y; spans 2 and 3 fit <= 3 points with a quadratic.
    assert_array_equal(loess_smooth(Y_GT, span), Y_GT)


@pytest.mark.parametrize("n", [1, 2, 3])
def test_very_short_tracks_are_unchanged(n):
    y = Y_GT[:n]
    assert_array_equal(loess_smooth(y, 15), y)


@pytest.mark.parametrize("method", ["loess", "lowess"])
@pytest.mark.parametrize("span", [5, 7, 9, 11, 15, 21])
@pytest.mark.parametrize("n", [4, 5, 6, 9, 14, 15, 16, 40])
def test_loess_matches_direct_weighted_fits(method, span, n):
    rng = np.random.default_rng(n * 100 + span)
    y = rng.standard_normal(n)
    eff = min(span, n)
    eff = 2 * (eff // 2) + 1
    degree = 2 if method == "loess" else 1
    expected = _reference_smooth(y, eff, degree)
    assert_allclose(loess_smooth(y, span, method=method), expected, atol=1e-10)


def test_lowess_span_five_changes_the_interior():
    # degree-1 fit over 3 tricube-weighted points: (w, 1, w) / (1 + 2 w)
    w = (1 - 0.5**3) ** 3
    expected = np.array([w, 1.0, w]) / (1 + 2 * w)
    assert_allclose(loess_kernel(5, method="lowess")[1:-1], expected, atol=1e-14)


def test_matrix_is_smoothed_column_by_column():
    rng = np.random.default_rng(0)
    scores = rng.random((50, 21))
    out = loess_smooth(scores, 15)
    expected = np.column_stack([loess_smooth(c, 15) for c in scores.T])
    assert out.shape == scores.shape
    assert_allclose(out, expected, rtol=0, atol=1e-14)
    assert_allclose(loess_smooth(scores.T, 15, axis=1), expected.T, atol=1e-14)
    assert_allclose(loess_smooth(scores, 15, axis=-2), expected, atol=1e-14)


def test_dtypes():
    assert loess_smooth(Y_GT.astype(np.float32), 7).dtype == np.float32
    ints = loess_smooth(np.arange(10), 7)
    assert ints.dtype == np.float64
    assert_allclose(ints, np.arange(10.0), atol=1e-12)  # a line is reproduced


def test_input_is_not_modified():
    y = Y_GT.copy()
    loess_smooth(y, 7)
    assert_array_equal(y, Y_GT)


@pytest.mark.parametrize("span", [0, -1, np.nan, "5"])
def test_invalid_span_raises(span):
    with pytest.raises(ValueError, match="span"):
        loess_smooth(Y_GT, span)


def test_invalid_method_raises():
    with pytest.raises(ValueError, match="method"):
        loess_smooth(Y_GT, 5, method="rloess")
