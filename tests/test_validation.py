"""Sequence validation (skgesture.utils._validation) and the segment helpers
the estimators rely on (skgesture.utils._segments)."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from sklearn.base import BaseEstimator

from skgesture.utils import (
    check_sequence_labels,
    check_sequences,
    labels_to_segments,
    missing_frames,
    remove_short_runs,
    runs,
    segments_to_labels,
)
from skgesture.utils._validation import check_positive_int

GOOD = [np.zeros((4, 20, 3)) + 1.0, np.ones((6, 20, 3))]

# labels <-> segments (0-based, exclusive end), by hand
LABELS_GT = [0, 3, 3, 0, 0, 5, 5, 5, 2, 0]
SEGMENTS_GT = [[3, 1, 3], [5, 5, 8], [2, 8, 9]]
RUNS_GT = ([0, 1, 3, 5, 8, 9], [1, 3, 5, 8, 9, 10], [0, 3, 0, 5, 2, 0])
SHORT_RUNS_GT = {  # min_length -> filtered LABELS_GT
    1: LABELS_GT,
    2: [0, 3, 3, 0, 0, 5, 5, 5, 0, 0],
    3: [0, 0, 0, 0, 0, 5, 5, 5, 0, 0],
    4: [0] * 10,
}


class _Dummy(BaseEstimator):
    pass


# --------------------------------------------------------------------------------
# check_sequences
# --------------------------------------------------------------------------------


def test_check_sequences_returns_contiguous_float_arrays():
    X = [np.arange(6, dtype=np.int32).reshape(3, 2), [[1, 2], [3, 4]]]
    out = check_sequences(X)
    assert isinstance(out, list)
    assert [a.dtype for a in out] == [np.float64, np.float64]
    assert all(a.flags.c_contiguous for a in out)
    assert_array_equal(out[1], [[1.0, 2.0], [3.0, 4.0]])
    out32 = check_sequences(X, dtype=np.float32)
    assert out32[0].dtype == np.float32


def test_check_sequences_unwraps_masked_arrays():
    x = np.ma.MaskedArray(np.arange(4.0).reshape(2, 2), mask=[[1, 1], [0, 0]])
    out = check_sequences([x])[0]
    assert not isinstance(out, np.ma.MaskedArray)
    assert_array_equal(out, [[0.0, 1.0], [2.0, 3.0]])


@pytest.mark.parametrize("X", [np.zeros((5, 20, 3)), np.zeros((5, 3))])
def test_check_sequences_refuses_a_single_array(X):
    with pytest.raises(TypeError, match=r"wrap a single sequence as \[X\]"):
        check_sequences(X)


@pytest.mark.parametrize("X", [5, "abc", None])
def test_check_sequences_refuses_non_lists(X):
    with pytest.raises(TypeError, match="must be a list of sequences"):
        check_sequences(X)


def test_check_sequences_accepts_an_object_array_of_sequences():
    X = np.empty(2, dtype=object)
    X[0], X[1] = np.ones((3, 2)), np.ones((5, 2))
    assert [a.shape for a in check_sequences(X)] == [(3, 2), (5, 2)]


@pytest.mark.parametrize(
    "X, kwargs, message",
    [
        ([], {}, "X is empty"),
        ([np.ones((3, 2)), np.ones(3)], {}, r"X\[1\] has shape \(3,\)"),
        ([np.ones((3, 2)), [["a", "b"]]], {}, r"X\[1\] cannot be converted"),
        ([np.ones((3, 20, 3)), np.ones((3, 60))], {"ndim": 3, "frame_shape": (20, 3)},
         r"X\[1\] has shape \(3, 60\); expected \(n_frames, 20, 3\)"),
        ([np.ones((3, 4))], {"ndim": 3}, r"expected \(n_frames, \?, \?\)"),
        ([np.ones((3, 19, 3))], {"frame_shape": (20, 3)},
         r"X\[0\] has frames of shape \(19, 3\); expected \(20, 3\)"),
        ([np.ones((3, 7))], {"frame_shape": (None,)}, None),
        ([np.ones((3, 2)), np.ones((1, 2))], {"min_frames": 2},
         r"X\[1\] has 1 frames; at least 2"),
        ([np.ones((3, 2)), np.array([[0, 1], [np.nan, 0]])], {},
         r"X\[1\] contains NaN or infinite values \(first at frame 1\)"),
        ([np.array([[0, np.inf]])], {"allow_nan": True}, r"X\[0\] contains infinite"),
        ([np.ones((2, 2))], {"name": "D"}, None),
        ([np.ones(2)], {"name": "D"}, r"D\[0\] has shape"),
    ],
)  # fmt: skip
def test_check_sequences_errors_name_the_sequence_and_the_shape(X, kwargs, message):
    if message is None:
        assert len(check_sequences(X, **kwargs)) == len(X)
    else:
        with pytest.raises(ValueError, match=message):
            check_sequences(X, **kwargs)


def test_check_sequences_allows_nan_when_asked():
    x = np.array([[0.0, np.nan], [1.0, 2.0]])
    out = check_sequences([x], allow_nan=True)[0]
    assert np.isnan(out[0, 1])


def test_check_sequences_sets_and_then_enforces_the_frame_shape():
    est = _Dummy()
    check_sequences([np.ones((3, 20, 3)), np.ones((5, 20, 3))], estimator=est)
    assert est.frame_shape_in_ == (20, 3)
    assert est.n_features_in_ == 60
    with pytest.raises(
        ValueError, match=r"\(19, 3\); expected \(20, 3\) \(as seen in fit\)"
    ):
        check_sequences([np.ones((3, 19, 3))], estimator=est, reset=False)
    # reset=False does not change the fitted shape
    check_sequences([np.ones((2, 20, 3))], estimator=est, reset=False)
    assert est.frame_shape_in_ == (20, 3)


def test_check_sequences_in_fit_requires_one_frame_shape():
    with pytest.raises(
        ValueError,
        match=r"X\[1\] has frames of shape \(4,\), but X\[0\] "
        r"has \(3,\)",
    ):
        check_sequences([np.ones((2, 3)), np.ones((2, 4))], estimator=_Dummy())


# --------------------------------------------------------------------------------
# check_sequence_labels
# --------------------------------------------------------------------------------


def test_check_sequence_labels_returns_int64_arrays():
    out = check_sequence_labels([[0, 1, 1], np.array([2.0, 0.0])])
    assert [a.dtype for a in out] == [np.int64, np.int64]
    assert_array_equal(out[1], [2, 0])


@pytest.mark.parametrize(
    "y, X, kwargs, error, message",
    [
        (None, None, {}, ValueError, "y is required"),
        (np.zeros(5, int), None, {}, TypeError, "list of per-frame label arrays"),
        ([], None, {}, ValueError, "y is empty"),
        ([[0, 1]], [np.ones((2, 1)), np.ones((2, 1))], {}, ValueError,
         "X has 2 sequences but y has 1"),
        ([[0, 1], [[0, 1]]], None, {}, ValueError, r"y\[1\] has shape \(1, 2\)"),
        ([[0, 0.5]], None, {}, ValueError, r"y\[0\] must hold integer class labels"),
        ([["a", "b"]], None, {}, ValueError, "integer class labels"),
        ([[0, 1, 1]], [np.ones((2, 1))], {}, ValueError,
         r"y\[0\] has 3 labels but X\[0\] has 2 frames"),
        ([[0, -1]], None, {}, ValueError, r"negative label -1 at frame 1"),
        ([[0, 4, 21]], None, {"n_classes": 20}, ValueError,
         r"label 21 at frame 2, out of range 0..20"),
    ],
)  # fmt: skip
def test_check_sequence_labels_errors(y, X, kwargs, error, message):
    with pytest.raises(error, match=message):
        check_sequence_labels(y, X, **kwargs)


def test_check_sequence_labels_accepts_a_2d_array_of_equal_length_sequences():
    out = check_sequence_labels(np.array([[0, 1], [2, 0]]))
    assert [a.tolist() for a in out] == [[0, 1], [2, 0]]


# --------------------------------------------------------------------------------
# missing_frames, check_positive_int
# --------------------------------------------------------------------------------


def test_missing_frames_flags_all_zero_and_nan_frames():
    seq = np.ones((5, 20, 3))
    seq[1] = 0.0
    seq[3, 7, 2] = np.nan
    seq[4, 0] = 0.0  # HipCenter at the origin, other joints tracked: not missing
    assert_array_equal(missing_frames(seq), [False, True, False, True, False])
    flat = seq.reshape(5, 60)
    assert_array_equal(missing_frames(flat), missing_frames(seq))


def test_check_positive_int_returns_a_python_int():
    out = check_positive_int(np.int64(4), "n")
    assert out == 4 and type(out) is int


@pytest.mark.parametrize("value", [0, -3, 2.0, "3", None])
def test_check_positive_int_rejects_non_positive_ints(value):
    with pytest.raises(ValueError, match="n must be a positive integer"):
        check_positive_int(value, "n")


# --------------------------------------------------------------------------------
# Segment helpers
# --------------------------------------------------------------------------------


def test_runs_of_equal_values():
    starts, ends, vals = runs(LABELS_GT)
    assert_array_equal(starts, RUNS_GT[0])
    assert_array_equal(ends, RUNS_GT[1])
    assert_array_equal(vals, RUNS_GT[2])
    empty = runs([])
    assert [len(a) for a in empty] == [0, 0, 0]


def test_labels_to_segments_and_back():
    seg = labels_to_segments(LABELS_GT)
    assert_array_equal(seg, SEGMENTS_GT)
    assert_array_equal(segments_to_labels(seg, len(LABELS_GT)), LABELS_GT)
    assert labels_to_segments([0, 0, 0]).shape == (0, 3)


def test_segments_to_labels_overlap_policies():
    segs = [[1, 0, 4], [2, 3, 6]]
    with pytest.raises(
        ValueError, match=r"segment 1 = \(2, 3, 6\) overlaps .* frame 3"
    ):
        segments_to_labels(segs, 6)
    with pytest.warns(UserWarning, match="the later segment wins"):
        warned = segments_to_labels(segs, 6, on_overlap="warn")
    assert_array_equal(warned, [1, 1, 1, 2, 2, 2])
    assert_array_equal(segments_to_labels(segs, 6, on_overlap="later"), warned)


@pytest.mark.parametrize(
    "segments, message",
    [([[0, 1, 3]], "class 0"), ([[1, 3, 3]], "outside"), ([[1, 0, 11]], "outside"),
     ([[1, -1, 2]], "outside")],
)  # fmt: skip
def test_segments_to_labels_rejects_bad_rows(segments, message):
    with pytest.raises(ValueError, match=message):
        segments_to_labels(segments, 10)


@pytest.mark.parametrize("min_length", sorted(SHORT_RUNS_GT))
def test_remove_short_runs(min_length):
    labels = np.array(LABELS_GT)
    out = remove_short_runs(labels, min_length)
    assert_array_equal(out, SHORT_RUNS_GT[min_length])
    assert_array_equal(labels, LABELS_GT)  # a copy


# --------------------------------------------------------------------------------
# Values: checked before the cast, bounded (docs/design.md, "Bad input")
# --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "bad, kwargs, message",
    [
        # float32 would silently turn 1e39 into inf
        (1e39, {"dtype": np.float32}, r"X\[1\] has the value 1e\+39 at frame 2"),
        (-2e30, {}, r"X\[1\] has the value -2e\+30 at frame 2, beyond the accepted "
         r"magnitude 1e\+30"),
        (2e5, {"allow_nan": True, "max_abs": 1e5}, r"X\[1\] has the value 2e\+05"),
        (np.inf, {"allow_nan": True}, r"X\[1\] contains infinite values \(first at "
         r"frame 2\).*never inf"),
        (np.nan, {}, r"X\[1\] contains NaN or infinite values \(first at frame 2\)"),
    ],
)  # fmt: skip
def test_check_sequences_refuses_values_beyond_the_bound(bad, kwargs, message):
    x = np.ones((4, 3))
    x[2, 1] = bad
    with pytest.raises(ValueError, match=message):
        check_sequences([np.ones((2, 3)), x], **kwargs)


def test_check_sequences_bound_is_inclusive_and_nan_passes_when_allowed():
    x = np.full((3, 2), 1e30)
    x[1] = np.nan
    out = check_sequences([x], allow_nan=True, dtype=np.float32)[0]
    assert out.dtype == np.float32 and np.isfinite(out[[0, 2]]).all()
    assert np.isnan(check_sequences([np.full((2, 2), np.nan)], allow_nan=True)[0]).all()


@pytest.mark.parametrize(
    "X, message",
    [
        ([np.ones((2, 2), dtype=complex)], r"X\[0\] cannot be converted .* complex"),
        (
            [np.array([[1, 2], [3, 10**40]], dtype=object)],
            r"X\[0\] has the value 1e\+40",
        ),
        ([[["1", "x"]]], r"X\[0\] cannot be converted"),
    ],
)
def test_check_sequences_refuses_non_real_values(X, message):
    with pytest.raises(ValueError, match=message):
        check_sequences(X)


def test_check_sequences_accepts_ints_bools_and_read_only_arrays():
    x = np.arange(6).reshape(3, 2)
    x.setflags(write=False)
    assert check_sequences([x, np.ones((2, 2), dtype=bool)])[0].dtype == np.float64


def test_sequence_of_constraint_checks_every_entry():
    from sklearn.utils._param_validation import (
        InvalidParameterError,
        validate_parameter_constraints,
    )

    from skgesture.utils._validation import SequenceOf

    steps = SequenceOf.ints(1)
    assert steps.is_satisfied_by([4, np.int64(3)])
    for bad in [(), (0,), (2.5,), (True,), "42", 4, None, np.array([4, 3])]:
        assert not steps.is_satisfied_by(bad), bad
    assert SequenceOf.ints(1, allow_empty=True).is_satisfied_by(())
    weights = SequenceOf(lambda w: w >= 0, "weights", whole=sum, arrays=True)
    assert weights.is_satisfied_by(np.array([0.0, 1.0]))
    assert not weights.is_satisfied_by((0.0, 0.0))
    with pytest.raises(InvalidParameterError, match="must be a non-empty tuple of"):
        validate_parameter_constraints({"steps": [steps]}, {"steps": (2.5,)}, "f")


def test_refuse_set_output_keeps_the_default_and_explains_the_rest():
    from skgesture.utils._validation import refuse_set_output

    est = BaseEstimator()
    assert refuse_set_output(est, None) is est
    assert refuse_set_output(est, "default") is est
    for container in ("pandas", "polars"):
        with pytest.raises(ValueError, match=f"set_output.transform='{container}'"):
            refuse_set_output(est, container)
