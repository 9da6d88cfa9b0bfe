"""Property-based tests (hypothesis): invariants that must hold for any input.

The descriptor is invariant to translating the skeleton, keeps the number of
frames and gives finite values for any finite skeleton in a sane range
(degenerate poses included); the Jaccard index lies in [0, 1] and is 1 for a
perfect prediction; segments and per-frame labels convert into each other
without loss.
"""

from functools import cache

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from numpy.testing import assert_allclose, assert_array_equal

from skgesture import PoseDescriptor
from skgesture.metrics import (
    jaccard_index,
    jaccard_index_segments,
    labels_to_segments,
    segments_to_labels,
)
from skgesture.utils._testing import make_skeleton_stream

FAST = settings(max_examples=50, deadline=None)
COORD = 3.0  # metres: any joint within 3 m of the camera origin on each axis


@cache
def _descriptor(standardize):
    X, _ = make_skeleton_stream(n_frames=120, random_state=0)
    return PoseDescriptor(standardize=standardize).fit([X])


def _finite(z):
    return np.isfinite(np.ma.getdata(z)).all()


skeletons = st.integers(1, 25).flatmap(
    lambda n: arrays(
        np.float64,
        (n, 20, 3),
        elements=st.floats(-COORD, COORD, allow_nan=False, width=32),
    )
)


# --------------------------------------------------------------------------------
# PoseDescriptor
# --------------------------------------------------------------------------------


@FAST
@given(
    seed=st.integers(0, 2**16),
    offset=arrays(np.float64, (3,), elements=st.floats(-5.0, 5.0, width=32)),
    n_frames=st.integers(1, 60),
)
def test_descriptor_is_invariant_to_translating_the_skeleton(seed, offset, n_frames):
    X, _ = make_skeleton_stream(random_state=seed)
    X = X[:n_frames]
    desc = _descriptor(False)
    moved = desc.transform([X + offset])[0]
    assert_allclose(moved, desc.transform([X])[0], atol=1e-6)


@FAST
@given(X=skeletons)
def test_descriptor_of_any_finite_skeleton_is_finite_and_keeps_its_length(X):
    for standardize in (False, True):
        Z = _descriptor(standardize).transform([X])[0]
        assert Z.shape == (len(X), 183)
        assert _finite(Z)


@FAST
@given(X=skeletons, data=st.data())
def test_descriptor_untracked_frames_are_exactly_the_masked_rows(X, data):
    lost = data.draw(arrays(bool, (len(X),)))
    X = X.copy()
    X[lost] = 0.0
    Z = _descriptor(True).transform([X])[0]
    untracked = ~X.reshape(len(X), -1).any(axis=1)  # lost, or drawn all-zero
    assert_array_equal(np.ma.getmaskarray(Z).any(axis=1), untracked)
    assert _finite(Z)


# --------------------------------------------------------------------------------
# Metrics
# --------------------------------------------------------------------------------


def _labels(max_len=60, max_class=4):
    return st.integers(1, max_len).flatmap(
        lambda n: arrays(np.int64, (n,), elements=st.integers(0, max_class))
    )


@st.composite
def label_pairs(draw):
    y_true = draw(_labels())
    y_pred = draw(arrays(np.int64, y_true.shape, elements=st.integers(0, 6)))
    return y_true, y_pred


@FAST
@given(pairs=st.lists(label_pairs(), min_size=1, max_size=4))
def test_jaccard_lies_in_0_1_and_is_1_for_a_perfect_prediction(pairs):
    y_true = [t for t, _ in pairs]
    y_pred = [p for _, p in pairs]
    has_gt = [bool(t.any()) for t in y_true]
    with _quiet():
        for mode in ("official_2014", "fp_penalised", "inclusive"):
            scores = jaccard_index(y_true, y_pred, mode=mode, per_sequence=True)
            assert_array_equal(np.isnan(scores), ~np.array(has_gt))
            kept = scores[~np.isnan(scores)]
            assert ((0.0 <= kept) & (kept <= 1.0)).all()
            perfect = jaccard_index(y_true, y_true, mode=mode, per_sequence=True)
            # a one-frame gesture has no frame left once its end frame is
            # dropped: 0/0, scored 0 (docs/method.md §2.2); otherwise 1
            for t, score in zip(y_true, perfect):
                if not t.any():
                    assert np.isnan(score)
                elif mode == "inclusive" or _every_class_has_two_frames(t):
                    assert score == 1.0


def _every_class_has_two_frames(y):
    seg = labels_to_segments(y)
    lengths = {}
    for c, s, e in seg:
        lengths[c] = lengths.get(c, 0) + (e - s - 1)
    return all(n > 0 for n in lengths.values())


class _quiet:
    """Silence the documented UndefinedMetricWarnings of degenerate draws."""

    def __enter__(self):
        import warnings

        self._ctx = warnings.catch_warnings()
        self._ctx.__enter__()
        warnings.simplefilter("ignore")

    def __exit__(self, *exc):
        return self._ctx.__exit__(*exc)


@FAST
@given(pairs=st.lists(label_pairs(), min_size=1, max_size=3))
def test_jaccard_with_true_segments_of_the_runs_equals_the_per_frame_score(pairs):
    y_true = [t for t, _ in pairs]
    y_pred = [p for _, p in pairs]
    with _quiet():
        a = jaccard_index(y_true, y_pred, per_sequence=True)
        b = jaccard_index(
            y_true,
            y_pred,
            per_sequence=True,
            true_segments=[labels_to_segments(t) for t in y_true],
        )
        for t, p, score in zip(y_true, y_pred, a):
            lines = labels_to_segments(t)
            lines[:, 1] += 1
            pred = labels_to_segments(p)
            pred[:, 1] += 1
            if t.any():
                assert score == jaccard_index_segments(
                    lines, pred, len(t), n_classes=20
                )
    assert_array_equal(a, b)


# --------------------------------------------------------------------------------
# Segments <-> labels
# --------------------------------------------------------------------------------


@FAST
@given(y=_labels(max_len=80, max_class=6))
def test_labels_to_segments_to_labels_is_the_identity(y):
    seg = labels_to_segments(y)
    assert_array_equal(segments_to_labels(seg, len(y)), y)
    assert (seg[:, 0] >= 1).all() and (seg[:, 1] < seg[:, 2]).all()
    assert (seg[1:, 1] >= seg[:-1, 2]).all()  # sorted, non-overlapping


@st.composite
def separated_segments(draw):
    """Sorted, non-overlapping segments, touching ones of different classes."""
    n_frames = draw(st.integers(1, 80))
    cuts = sorted(set(draw(st.lists(st.integers(0, n_frames), max_size=12))))
    cuts = [0] + [c for c in cuts if 0 < c < n_frames] + [n_frames]
    rows, previous = [], None
    for s, e in zip(cuts[:-1], cuts[1:]):
        cls = draw(st.integers(0, 5))  # 0: a rest gap
        if cls and cls != previous:
            rows.append((cls, s, e))
        previous = cls if cls else None
    return np.array(rows, dtype=np.int64).reshape(-1, 3), n_frames


@FAST
@given(case=separated_segments())
def test_segments_to_labels_to_segments_is_the_identity(case):
    seg, n_frames = case
    y = segments_to_labels(seg, n_frames)
    assert len(y) == n_frames
    assert_array_equal(labels_to_segments(y), seg)
