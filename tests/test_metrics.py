"""Tests of skgesture.metrics against hand-computed values.

docs/method.md §2 and §11.3.
"""

import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import BaseEstimator
from sklearn.exceptions import UndefinedMetricWarning
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate
from sklearn.utils import _safe_indexing

from skgesture.metrics import (
    SCORERS,
    edit_score,
    frame_accuracy,
    frame_confusion_matrix,
    get_scorer,
    jaccard_index,
    jaccard_index_segments,
    jaccard_scorer,
    labels_to_segments,
    make_jaccard_scorer,
    make_sequence_scorer,
    per_class_report,
    segmental_f1,
    segments_to_labels,
)

MODES = ("official_2014", "fp_penalised", "inclusive")

# docs/method.md §2.4: n = 10, GT lines 3,2,6 and 5,7,10; prediction 3,3,6 and 8,7,9.
N_WORKED = 10
GT_WORKED = [[3, 2, 6], [5, 7, 10]]
PRED_WORKED = [[3, 3, 6], [8, 7, 9]]
EXPECTED_WORKED = {"official_2014": 0.375, "fp_penalised": 0.25, "inclusive": 0.4}
# The same sequence as per-frame labels (frame 1 is rest).
Y_TRUE_WORKED = np.array([0, 3, 3, 3, 3, 3, 5, 5, 5, 5])
Y_PRED_WORKED = np.array([0, 0, 3, 3, 3, 3, 8, 8, 8, 0])


def _official_gesture_overlap(gt_rows, pred_rows, n_frames):
    """Transcription of the official script's ``gesture_overlap_csv`` (§2.1)."""
    max_gestures = 20
    binvec_gt = np.zeros((max_gestures, n_frames))
    gt_gestures = []
    for c, s, e in gt_rows:
        binvec_gt[c - 1, s - 1 : e - 1] = 1
        gt_gestures.append(c)
    binvec_pred = np.zeros((max_gestures, n_frames))
    pred_gestures = []
    for c, s, e in pred_rows:
        binvec_pred[c - 1, s - 1 : e - 1] = 1
        pred_gestures.append(c)
    gt_gestures = np.unique(gt_gestures)
    pred_gestures = np.unique(np.asarray(pred_gestures, dtype=int))
    false_pos = np.setdiff1d(gt_gestures, np.union1d(gt_gestures, pred_gestures))
    overlaps = []
    for idx in gt_gestures:
        intersec = sum(binvec_gt[idx - 1] * binvec_pred[idx - 1])
        aux = binvec_gt[idx - 1] + binvec_pred[idx - 1]
        union = sum(aux > 0)
        overlaps.append(intersec / union)
    return sum(overlaps) / (len(overlaps) + len(false_pos))


# --------------------------------------------------------------------------- Jaccard


@pytest.mark.parametrize("mode", MODES)
def test_jaccard_segments_worked_example(mode):
    score = jaccard_index_segments(GT_WORKED, PRED_WORKED, N_WORKED, mode=mode)
    assert_allclose(score, EXPECTED_WORKED[mode], rtol=0, atol=1e-15)


@pytest.mark.parametrize("mode", MODES)
def test_jaccard_framewise_worked_example_matches_segment_variant(mode):
    score = jaccard_index([Y_TRUE_WORKED], [Y_PRED_WORKED], mode=mode)
    assert_allclose(score, EXPECTED_WORKED[mode], rtol=0, atol=1e-15)


@pytest.mark.parametrize("mode", MODES)
def test_jaccard_perfect_copy_scores_one(mode):
    y = [Y_TRUE_WORKED, np.array([0, 1, 1, 2, 2, 2, 0, 4, 4, 0, 1, 1])]
    assert jaccard_index(y, y, mode=mode) == 1.0
    assert jaccard_index_segments(GT_WORKED, GT_WORKED, N_WORKED, mode=mode) == 1.0


@pytest.mark.parametrize("mode", MODES)
def test_jaccard_empty_prediction_scores_zero(mode):
    empty = np.zeros_like(Y_TRUE_WORKED)
    assert jaccard_index([Y_TRUE_WORKED], [empty], mode=mode) == 0.0
    assert jaccard_index_segments(GT_WORKED, [], N_WORKED, mode=mode) == 0.0
    assert jaccard_index_segments(GT_WORKED, None, N_WORKED, mode=mode) == 0.0


def test_official_jaccard_ignores_false_positive_classes():
    # GT: class 1 on frames 2..4 (scored 2, 3). Extra class 2 on frames 6..7.
    y_true = [np.array([0, 1, 1, 1, 0, 0, 0, 0])]
    y_pred = [np.array([0, 1, 1, 1, 0, 2, 2, 0])]
    assert jaccard_index(y_true, y_pred) == 1.0
    assert jaccard_index(y_true, y_pred, mode="inclusive") == 1.0


def test_fp_penalised_jaccard_counts_each_false_positive_class_once():
    # Class 2 appears twice and class 7 once: 2 extra classes -> 1 / (1 + 2).
    y_true = [np.array([0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0])]
    y_pred = [np.array([0, 1, 1, 1, 0, 2, 2, 0, 2, 2, 7, 7])]
    assert_allclose(jaccard_index(y_true, y_pred, mode="fp_penalised"), 1 / 3)


def test_official_jaccard_wrong_class_frames_only_miss_the_intersection():
    # GT class 1 on frames 1..6 -> scored frames 1..5.
    y_true = [np.array([1, 1, 1, 1, 1, 1, 0, 0])]
    wrong_class = [np.array([1, 1, 1, 2, 2, 2, 0, 0])]  # class 1 run 1..3 -> {1, 2}
    rest = [np.array([1, 1, 1, 0, 0, 0, 0, 0])]
    assert_allclose(jaccard_index(y_true, wrong_class), 2 / 5)
    assert jaccard_index(y_true, wrong_class) == jaccard_index(y_true, rest)


def test_official_jaccard_predictions_outside_gt_extent_enlarge_union():
    # Predicted class 1 on frames 1..8 -> scored 1..7; GT scored 1..5 -> 5 / 7.
    y_true = [np.array([1, 1, 1, 1, 1, 1, 0, 0])]
    y_pred = [np.array([1, 1, 1, 1, 1, 1, 1, 1])]
    assert_allclose(jaccard_index(y_true, y_pred), 5 / 7)


def test_official_jaccard_merges_instances_of_one_class():
    # Class 1 runs 1..3 and 9..11 -> G_1 = {1, 2, 9, 10}; class 2 run 5..7 -> {5, 6}.
    # Prediction finds only the first class-1 instance: J_1 = 2/4, J_2 = 1 -> 0.75
    # (a per-instance mean would give (1 + 0 + 1) / 3).
    y_true = [np.array([1, 1, 1, 0, 2, 2, 2, 0, 1, 1, 1, 0])]
    y_pred = [np.array([1, 1, 1, 0, 2, 2, 2, 0, 0, 0, 0, 0])]
    assert_allclose(jaccard_index(y_true, y_pred), 0.75)


def test_jaccard_segments_overlapping_gt_rows_are_or_ed():
    # Same class: {2..5} | {4..8} = {2..8}; the prediction 1,2,9 covers {2..8}.
    assert jaccard_index_segments([[1, 2, 6], [1, 4, 9]], [[1, 2, 9]], 10) == 1.0
    # Different classes overlapping (as Sample0797): J_3 = 1, J_4 = 0.
    assert jaccard_index_segments([[3, 2, 6], [4, 5, 9]], [[3, 2, 6]], 10) == 0.5


def test_official_jaccard_one_frame_prediction_contributes_nothing():
    # GT class 1 on frames 2..5 -> scored {2, 3, 4}; prediction is frame 2 only.
    y_true = [np.array([0, 1, 1, 1, 1, 0])]
    y_pred = [np.array([0, 1, 0, 0, 0, 0])]
    assert jaccard_index(y_true, y_pred) == 0.0
    assert jaccard_index_segments([[1, 2, 5]], [[1, 3, 3]], 6) == 0.0
    # Inclusive mode counts it: |{2}| / |{2..5}|.
    assert jaccard_index(y_true, y_pred, mode="inclusive") == 0.25


def test_official_jaccard_one_frame_gt_class_not_predicted_scores_zero_with_warning():
    # Class 1 is a 1-frame run (empty after exclusion, 0/0): J_1 = 0, J_2 = 1.
    y_true = [np.array([0, 1, 0, 2, 2, 2, 0])]
    y_pred = [np.array([0, 0, 0, 2, 2, 2, 0])]
    with pytest.warns(UndefinedMetricWarning, match=r"class\(es\) \[1\]"):
        assert jaccard_index(y_true, y_pred) == 0.5
    with pytest.warns(UndefinedMetricWarning, match="0/0"):
        assert jaccard_index_segments([[1, 2, 2], [2, 4, 6]], [[2, 4, 6]], 7) == 0.5


def test_jaccard_skips_sequence_without_gt_gesture_with_warning():
    y_true = [np.array([0, 0, 0, 0]), np.array([0, 1, 1, 1, 0])]
    y_pred = [np.array([2, 2, 0, 0]), np.array([0, 1, 1, 1, 0])]
    with pytest.warns(UndefinedMetricWarning, match=r"indices \[0\]"):
        assert jaccard_index(y_true, y_pred) == 1.0
    with pytest.warns(UndefinedMetricWarning):
        scores = jaccard_index(y_true, y_pred, per_sequence=True)
    assert_array_equal(scores, [np.nan, 1.0])


def test_jaccard_without_any_gt_gesture_returns_nan_with_warning():
    y = [np.zeros(5, dtype=int), np.zeros(3, dtype=int)]
    with pytest.warns(UndefinedMetricWarning, match="undefined"):
        assert np.isnan(jaccard_index(y, y))
    with pytest.warns(UndefinedMetricWarning, match="divides by zero"):
        assert np.isnan(jaccard_index_segments([], [[1, 1, 3]], 5))


def test_jaccard_mean_weighs_every_sequence_equally():
    # Sequence scores 1.0 (long) and 0.375 (short) -> 0.6875 whatever the lengths.
    long_seq = np.repeat([0, 1, 0, 2, 0], 20)
    y_true = [long_seq, Y_TRUE_WORKED]
    y_pred = [long_seq, Y_PRED_WORKED]
    assert jaccard_index(y_true, y_pred) == 0.6875
    assert_array_equal(jaccard_index(y_true, y_pred, per_sequence=True), [1, 0.375])


def test_jaccard_segments_clips_out_of_range_frames():
    # GT 1,8,15 on 10 frames -> frames 8..10; prediction 1,8,10 -> 8, 9.
    assert_allclose(jaccard_index_segments([[1, 8, 15]], [[1, 8, 10]], 10), 2 / 3)
    assert jaccard_index_segments([[1, 8, 15]], [[1, 8, 30]], 10) == 1.0
    # A line starting after the sequence marks nothing.
    assert jaccard_index_segments([[1, 8, 15]], [[1, 12, 30]], 10) == 0.0


def test_jaccard_segments_start_zero_loses_the_gesture():
    # Slice [-1, 4) is empty: the prediction is lost.
    with pytest.warns(UserWarning, match="start frame"):
        assert jaccard_index_segments([[2, 1, 5]], [[2, 0, 5]], 10) == 0.0
    # Unless e - 1 >= n: slice [-1, 10) keeps the last frame only -> 1 / 10.
    with pytest.warns(UserWarning, match="start frame"):
        assert jaccard_index_segments([[2, 1, 11]], [[2, 0, 11]], 10) == 0.1


def test_jaccard_segments_class_zero_shares_the_row_of_class_20():
    with pytest.warns(UserWarning, match="class 0"):
        assert jaccard_index_segments([[20, 1, 5]], [[0, 1, 5]], 10) == 1.0
    with pytest.warns(UserWarning, match="class 0"):
        score = jaccard_index_segments(
            [[20, 1, 5]], [[0, 1, 5]], 10, mode="fp_penalised"
        )
    assert score == 0.5


def test_jaccard_segments_rejects_class_above_20():
    with pytest.raises(ValueError, match="class 21 > n_classes=20"):
        jaccard_index_segments([[21, 1, 5]], [], 10)
    with pytest.raises(ValueError, match="class 21 > n_classes=20"):
        jaccard_index_segments([[1, 1, 5]], [[21, 1, 5]], 10)
    assert jaccard_index_segments([[21, 1, 5]], [[21, 1, 5]], 10, n_classes=21) == 1.0


def test_jaccard_segments_rejects_malformed_lines():
    with pytest.raises(ValueError, match=r"shape \(n_lines, 3\)"):
        jaccard_index_segments([[1, 2]], [], 10)
    with pytest.raises(ValueError, match="integers"):
        jaccard_index_segments([[1, 2, 5.5]], [], 10)
    with pytest.raises(ValueError, match="negative class"):
        jaccard_index_segments([[-1, 2, 5]], [], 10)
    with pytest.raises(ValueError, match="n_frames"):
        jaccard_index_segments([[1, 2, 5]], [], -1)


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_jaccard_segments_equals_official_script_bit_for_bit():
    rng = np.random.default_rng(0)
    compared = 0
    for _ in range(300):
        n = int(rng.integers(5, 40))

        def lines(k):
            c = rng.integers(0, 21, size=k)
            s = rng.integers(0, n + 4, size=k)
            e = s + rng.integers(-1, 25, size=k)
            return np.stack([c, s, e], axis=1).tolist()

        gt, pred = lines(int(rng.integers(1, 6))), lines(int(rng.integers(0, 6)))
        reference = _official_gesture_overlap(gt, pred, n)
        if not np.isfinite(reference):  # 0/0 in the script; ours scores 0
            continue
        assert jaccard_index_segments(gt, pred, n) == reference
        compared += 1
    assert compared > 150


def test_jaccard_rejects_different_number_of_sequences():
    with pytest.raises(ValueError, match="y_true has 2 sequences but y_pred has 1"):
        jaccard_index([Y_TRUE_WORKED, Y_TRUE_WORKED], [Y_PRED_WORKED])


def test_jaccard_rejects_sequence_length_mismatch_naming_index_and_lengths():
    y_true = [Y_TRUE_WORKED, np.array([0, 1, 1, 0])]
    y_pred = [Y_PRED_WORKED, np.array([0, 1, 1])]
    with pytest.raises(
        ValueError,
        match=r"sequence 1: y_true\[1\] has 4 frames but "
        r"y_pred\[1\] has 3",
    ):
        jaccard_index(y_true, y_pred)


def test_jaccard_rejects_negative_and_non_integer_labels():
    with pytest.raises(ValueError, match="negative label"):
        jaccard_index([np.array([0, 1, 1])], [np.array([0, -1, 1])])
    with pytest.raises(ValueError, match="integer class labels"):
        jaccard_index([np.array([0, 1.5, 1])], [np.array([0, 1, 1])])


def test_jaccard_n_classes_bounds_labels():
    y = [np.array([0, 25, 25, 25, 0])]
    assert jaccard_index(y, y) == 1.0
    with pytest.raises(ValueError, match="out of range 0..20"):
        jaccard_index(y, y, n_classes=20)


def test_jaccard_invalid_mode_lists_the_modes():
    msg = "'official_2014', 'fp_penalised', 'inclusive'; got 'paper'"
    with pytest.raises(ValueError, match=msg):
        jaccard_index([Y_TRUE_WORKED], [Y_PRED_WORKED], mode="paper")
    with pytest.raises(ValueError, match=msg):
        jaccard_index_segments(GT_WORKED, PRED_WORKED, 10, mode="paper")
    with pytest.raises(ValueError, match=msg):
        make_jaccard_scorer(mode="paper")


def test_metrics_reexports_segment_conversions():
    seg = labels_to_segments(Y_TRUE_WORKED)
    assert_array_equal(seg, [[3, 1, 6], [5, 6, 10]])
    assert_array_equal(segments_to_labels(seg, 10), Y_TRUE_WORKED)


# ------------------------------------------------------------------ frame metrics


def test_frame_accuracy_pools_frames_over_sequences():
    # 3/4 and 2/2 correct -> 5/6 pooled (the mean of ratios would be 0.875).
    y_true = [np.array([0, 1, 1, 0]), np.array([2, 2])]
    y_pred = [np.array([0, 1, 0, 0]), np.array([2, 2])]
    assert_allclose(frame_accuracy(y_true, y_pred), 5 / 6)


def test_frame_confusion_matrix_counts_pooled_frames_in_label_order():
    y_true = [np.array([0, 1, 1, 0]), np.array([2, 2])]
    y_pred = [np.array([0, 1, 0, 0]), np.array([2, 1])]
    assert_array_equal(
        frame_confusion_matrix(y_true, y_pred), [[2, 0, 0], [1, 1, 0], [0, 1, 1]]
    )
    assert_array_equal(
        frame_confusion_matrix(y_true, y_pred, labels=[2, 1]), [[1, 1], [0, 1]]
    )
    assert_allclose(
        frame_confusion_matrix(y_true, y_pred, normalize="true")[1], [0.5, 0.5, 0]
    )


# ------------------------------------------------------------- per-class report


def test_per_class_report_hand_computed():
    # Pooled frames: rest 2/3 precision, 2/2 recall; class 1 is predicted on
    # frames 1 and 5 (1 right) and is 2 frames; class 2 is predicted once, right.
    y_true = [np.array([0, 1, 1, 0]), np.array([2, 2])]
    y_pred = [np.array([0, 1, 0, 0]), np.array([2, 1])]
    report = per_class_report(y_true, y_pred)
    assert_array_equal(report.labels, [0, 1, 2])
    assert_array_equal(report.support, [2, 2, 2])
    assert_allclose(report.precision, [2 / 3, 1 / 2, 1])
    assert_allclose(report.recall, [1, 1 / 2, 1 / 2])
    assert_allclose(report.f1, [0.8, 0.5, 2 / 3])
    assert_array_equal(report.true_gestures, [0, 1, 1])
    assert_array_equal(report.predicted_gestures, [0, 2, 1])
    for key in ("labels", "support", "true_gestures", "predicted_gestures"):
        assert report[key].dtype == np.int64


def test_per_class_report_equals_scikit_learn_on_pooled_frames():
    from sklearn.metrics import precision_recall_fscore_support

    rng = np.random.default_rng(0)
    y_true = [rng.integers(0, 4, n) for n in (30, 1, 17)]
    y_pred = [rng.integers(0, 5, len(y)) for y in y_true]
    # Every label, more than every label, and a subset in another order.
    for labels in (None, [0, 1, 2, 3, 4, 7], [3, 0, 7]):
        report = per_class_report(y_true, y_pred, labels=labels)
        expected = (
            np.unique(np.concatenate(y_true + y_pred)) if labels is None else labels
        )
        p, r, f, support = precision_recall_fscore_support(
            np.concatenate(y_true),
            np.concatenate(y_pred),
            labels=expected,
            zero_division=0,
        )
        assert_array_equal(report.labels, expected)
        assert_allclose(report.precision, p)
        assert_allclose(report.recall, r)
        assert_allclose(report.f1, f)
        assert_array_equal(report.support, support)


def test_per_class_report_undefined_scores_are_zero_without_warning():
    # Class 3 is never predicted (precision 0/0), class 4 never true (recall
    # 0/0), class 5 is in neither (everything 0/0).
    y_true = [np.array([0, 3, 3, 0])]
    y_pred = [np.array([0, 0, 4, 0])]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        report = per_class_report(y_true, y_pred, labels=[3, 4, 5])
    assert_array_equal(report.precision, [0, 0, 0])
    assert_array_equal(report.recall, [0, 0, 0])
    assert_array_equal(report.f1, [0, 0, 0])
    assert_array_equal(report.support, [2, 0, 0])
    assert_array_equal(report.true_gestures, [1, 0, 0])
    assert_array_equal(report.predicted_gestures, [0, 1, 0])


def test_per_class_report_counts_gestures_as_runs_of_the_listed_labels():
    # Two touching runs of different classes are two gestures; a run of an
    # unlisted class is not counted anywhere.
    y_true = [np.array([1, 1, 2, 2, 0, 1]), np.array([3, 3])]
    y_pred = [np.array([1, 0, 1, 2, 2, 2]), np.array([0, 0])]
    report = per_class_report(y_true, y_pred, labels=[2, 1])
    assert_array_equal(report.true_gestures, [1, 2])
    assert_array_equal(report.predicted_gestures, [1, 2])


@pytest.mark.parametrize(
    "labels, match",
    [
        ([[0, 1]], "1-D"),
        ([], "non-empty"),
        (["a", "b"], "integers"),
        ([0.5, 1], "integers"),
        ([1, 2, 1], r"\[1\] more than once"),
    ],
)
def test_per_class_report_rejects_bad_labels(labels, match):
    with pytest.raises(ValueError, match=match):
        per_class_report([[0, 1, 2]], [[0, 1, 1]], labels=labels)


def test_per_class_report_validates_the_label_pairs():
    with pytest.raises(ValueError, match="sequences"):
        per_class_report([[0, 1]], [[0, 1], [1]])
    with pytest.raises(ValueError, match="at least one frame"):
        per_class_report([[]], [[]])
    with pytest.raises(ValueError, match="at least one sequence"):
        per_class_report([], [], labels=[0, 1])


# ---------------------------------------------------------------- segmental F1


def test_segmental_f1_iou_thresholds():
    # Segments: GT (1, [1, 5)), (2, [6, 8)); prediction (1, [2, 4)), (2, [5, 10)).
    # IoUs 2/4 = 0.5 and 2/5 = 0.4.
    y_true = [np.array([0, 1, 1, 1, 1, 0, 2, 2, 0, 0])]
    y_pred = [np.array([0, 0, 1, 1, 0, 2, 2, 2, 2, 2])]
    assert segmental_f1(y_true, y_pred, overlap=0.1) == 1.0
    assert segmental_f1(y_true, y_pred, overlap=0.25) == 1.0
    # TP 1, FP 1, FN 1 -> 2 / (2 + 1 + 1).
    assert segmental_f1(y_true, y_pred, overlap=0.5) == 0.5


def test_segmental_f1_counts_over_segmentation_as_false_positive():
    # One GT segment of 10 frames, predicted as [0, 5) and [6, 10): TP 1, FP 1.
    y_true = [np.ones(10, dtype=int)]
    y_pred = [np.array([1, 1, 1, 1, 1, 0, 1, 1, 1, 1])]
    assert_allclose(segmental_f1(y_true, y_pred, overlap=0.1), 2 / 3)
    assert_allclose(segmental_f1(y_true, y_pred, overlap=0.5), 2 / 3)


def test_segmental_f1_wrong_class_is_a_false_positive_and_a_miss():
    y_true = [np.array([0, 1, 1, 1, 0])]
    y_pred = [np.array([0, 2, 2, 2, 0])]
    assert segmental_f1(y_true, y_pred) == 0.0


def test_segmental_f1_pools_counts_over_sequences():
    # Sequence 0: TP 2. Sequence 1: FN 1. Pooled 4 / (4 + 1) (per-sequence mean 0.5).
    y_true = [np.array([0, 1, 1, 0, 2, 2]), np.array([0, 3, 3, 3, 0])]
    y_pred = [np.array([0, 1, 1, 0, 2, 2]), np.zeros(5, dtype=int)]
    assert_allclose(segmental_f1(y_true, y_pred, overlap=0.5), 0.8)


def test_segmental_f1_compares_each_prediction_with_its_best_gt_segment_only():
    # GT class 1 on [0, 10) and [12, 30); prediction on [0, 5) and [6, 16).
    # The first prediction takes [0, 10) (IoU 0.5). The second is closest to
    # [0, 10) too (IoU 4/16 = 0.25 > 4/24 against [12, 30)), already matched:
    # a false positive, as in MS-TCN. TP 1, FP 1, FN 1 -> 0.5.
    y_true = np.zeros(30, dtype=int)
    y_true[0:10] = 1
    y_true[12:30] = 1
    y_pred = np.zeros(30, dtype=int)
    y_pred[0:5] = 1
    y_pred[6:16] = 1
    assert segmental_f1([y_true], [y_pred], overlap=0.1) == 0.5


def test_segmental_f1_prediction_without_gt_segments_is_false_positive():
    y_true = [np.zeros(5, dtype=int), np.array([0, 1, 1, 0, 0])]
    y_pred = [np.array([0, 2, 2, 0, 0]), np.array([0, 1, 1, 0, 0])]
    assert_allclose(segmental_f1(y_true, y_pred), 2 / 3)  # TP 1, FP 1


def test_segmental_f1_without_any_segment_returns_zero_with_warning():
    y = [np.zeros(4, dtype=int)]
    with pytest.warns(UndefinedMetricWarning):
        assert segmental_f1(y, y) == 0.0


@pytest.mark.parametrize("overlap", [0, -0.1, 1.5, "0.5", True])
def test_segmental_f1_rejects_invalid_overlap(overlap):
    with pytest.raises(ValueError, match="overlap"):
        segmental_f1([np.array([0, 1])], [np.array([0, 1])], overlap=overlap)


# ------------------------------------------------------------------- edit score


def test_edit_score_penalises_over_segmentation():
    # [1, 2] vs [1, 1, 2]: one insertion over 3 segments.
    assert_allclose(
        edit_score(
            [np.array([0, 1, 1, 0, 2, 2, 0])], [np.array([0, 1, 0, 1, 2, 2, 2])]
        ),
        100 * (1 - 1 / 3),
    )


def test_edit_score_ignores_timing_and_rest():
    y_true = [np.array([0, 1, 1, 1, 0, 2, 2])]
    y_pred = [np.array([1, 0, 0, 0, 0, 0, 2])]
    assert edit_score(y_true, y_pred) == 100.0


def test_edit_score_swapped_order_scores_zero():
    assert edit_score([np.array([1, 1, 2, 2])], [np.array([2, 2, 1, 1])]) == 0.0


def test_edit_score_is_mean_over_sequences():
    # 100 (perfect), 0 (nothing predicted), 50 ([3, 4] vs [3, 5]): mean 50.
    y_true = [np.array([1, 1, 0]), np.array([0, 2, 2]), np.array([3, 0, 4])]
    y_pred = [np.array([1, 1, 0]), np.array([0, 0, 0]), np.array([3, 0, 5])]
    assert edit_score(y_true, y_pred) == 50.0


def test_edit_score_of_two_empty_labellings_is_100():
    assert edit_score([np.zeros(3, dtype=int)], [np.zeros(3, dtype=int)]) == 100.0


# ----------------------------------------------------------------------- scorers


class _ThresholdTagger(BaseEstimator):
    """Labels frame t with class X[t, 1] where the activity X[t, 0] > threshold."""

    def __init__(self, threshold=0.5):
        self.threshold = threshold

    def fit(self, X, y=None):
        if not isinstance(X, list) or not isinstance(y, list):
            raise TypeError(f"expected lists, got {type(X)} and {type(y)}")
        self.n_sequences_fit_ = len(X)
        return self

    def predict(self, X):
        if not isinstance(X, list) or any(x.ndim != 2 for x in X):
            raise TypeError("X must be a list of 2-D arrays")
        return [np.where(x[:, 0] > self.threshold, x[:, 1], 0).astype(int) for x in X]


def _threshold_data(n_sequences=8, seed=0):
    """Sequences whose gesture frames have activity in [0.5, 0.7], rest in [0.2, 0.4].

    Column 1 holds the class of the nearest gesture on every frame, so a low
    threshold stretches the predicted gestures over the rests.
    """
    rng = np.random.default_rng(seed)
    X, y = [], []
    for i in range(n_sequences):
        c1, c2 = 1 + i % 5, 6 + i % 3
        labels = np.repeat([0, c1, 0, c2, 0], [4 + i % 3, 12, 6, 9 + i % 4, 5])
        cls = np.where(np.arange(len(labels)) < 4 + i % 3 + 12 + 3, c1, c2)
        act = np.where(
            labels > 0,
            rng.uniform(0.5, 0.7, len(labels)),
            rng.uniform(0.2, 0.4, len(labels)),
        )
        X.append(np.column_stack([act, cls]))
        y.append(labels)
    groups = np.repeat(np.arange(n_sequences // 2), 2)
    return X, y, groups


def test_safe_indexing_of_a_list_of_sequences_returns_a_list():
    X, _, _ = _threshold_data()
    subset = _safe_indexing(X, np.array([3, 0]))
    assert isinstance(subset, list)
    assert subset[0] is X[3] and subset[1] is X[0]


def test_jaccard_scorer_calls_predict_and_scores_official_jaccard():
    X, y, _ = _threshold_data()
    assert jaccard_scorer(_ThresholdTagger(threshold=0.45), X, y) == 1.0
    assert jaccard_scorer(_ThresholdTagger(threshold=0.9), X, y) == 0.0
    low = _ThresholdTagger(threshold=0.1)
    assert jaccard_scorer(low, X, y) == jaccard_index(y, low.predict(X))


def test_scorer_in_grid_search_picks_the_right_threshold():
    X, y, groups = _threshold_data()
    search = GridSearchCV(
        _ThresholdTagger(),
        {"threshold": [0.1, 0.45, 0.9]},
        scoring={"jaccard": jaccard_scorer, "f1@50": get_scorer("f1@50")},
        refit="jaccard",
        cv=GroupKFold(n_splits=2),
        error_score="raise",
    )
    search.fit(X, y, groups=groups)
    assert search.best_params_ == {"threshold": 0.45}
    assert search.best_score_ == 1.0
    assert_array_equal(search.cv_results_["rank_test_jaccard"], [2, 1, 3])
    assert_allclose(search.cv_results_["mean_test_jaccard"][[1, 2]], [1.0, 0.0])
    assert_allclose(search.cv_results_["mean_test_f1@50"][1], 1.0)
    assert search.best_estimator_.n_sequences_fit_ == 8


def test_all_named_scorers_work_in_cross_validate():
    X, y, groups = _threshold_data()
    result = cross_validate(
        _ThresholdTagger(threshold=0.45),
        X,
        y,
        groups=groups,
        cv=GroupKFold(n_splits=2),
        scoring=SCORERS,
        error_score="raise",
    )
    for name in SCORERS:
        expected = 100.0 if name == "edit" else 1.0
        assert_allclose(result[f"test_{name}"], expected, err_msg=name)


def test_named_scorers_match_their_metrics():
    X, y, _ = _threshold_data()
    est = _ThresholdTagger(threshold=0.1)
    y_pred = est.predict(X)
    expected = {
        "jaccard": jaccard_index(y, y_pred),
        "jaccard_fp_penalised": jaccard_index(y, y_pred, mode="fp_penalised"),
        "jaccard_inclusive": jaccard_index(y, y_pred, mode="inclusive"),
        "frame_accuracy": frame_accuracy(y, y_pred),
        "f1@10": segmental_f1(y, y_pred, overlap=0.1),
        "f1@25": segmental_f1(y, y_pred, overlap=0.25),
        "f1@50": segmental_f1(y, y_pred, overlap=0.5),
        "edit": edit_score(y, y_pred),
    }
    assert sorted(SCORERS) == sorted(expected)
    for name, value in expected.items():
        assert get_scorer(name)(est, X, y) == value, name
    # The low threshold stretches every gesture over its rests: not perfect.
    assert expected["jaccard"] < 1.0


def test_get_scorer_rejects_unknown_name_listing_valid_ones():
    with pytest.raises(ValueError, match="'f1@10'"):
        get_scorer("f1")
    assert get_scorer(jaccard_scorer) is jaccard_scorer


def test_make_sequence_scorer_passes_keyword_arguments():
    X, y, _ = _threshold_data()
    scorer = make_sequence_scorer(jaccard_index, mode="inclusive")
    est = _ThresholdTagger(threshold=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert scorer(est, X, y) == jaccard_index(y, est.predict(X), mode="inclusive")
    assert repr(scorer) == "make_sequence_scorer(jaccard_index, mode='inclusive')"
    with pytest.raises(TypeError, match="callable"):
        make_sequence_scorer("jaccard")


# --------------------------------------------------------------------------------
# Official (segment-file) score vs per-frame score; absurd labels (issue 11)
# --------------------------------------------------------------------------------

# Issue 11: GT lines 3,11,40 and 3,41,70 (touching instances of one class),
# prediction 3,11,70; 1-based inclusive file lines, 80 frames.
TOUCHING_GT_LINES = [[3, 11, 40], [3, 41, 70]]
TOUCHING_PRED_LINES = [[3, 11, 70]]
TOUCHING_OFFICIAL = 58 / 59  # 0.98305: one end frame dropped per GT instance


def test_per_frame_jaccard_differs_from_the_official_one_on_touching_instances():
    y = np.zeros(80, int)
    y[10:70] = 3  # what the ground truth looks like as per-frame labels
    official = jaccard_index_segments(TOUCHING_GT_LINES, TOUCHING_PRED_LINES, 80)
    assert official == pytest.approx(TOUCHING_OFFICIAL)
    assert round(official, 5) == 0.98305
    assert jaccard_index([y], [y]) == 1.0  # the documented difference
    # the official path from loader-style segments (0-based, end exclusive)
    segments = [[[3, 10, 40], [3, 40, 70]]]
    assert jaccard_index([y], [y], true_segments=segments) == official
    for mode in MODES:
        assert jaccard_index(
            [y], [y], true_segments=segments, mode=mode
        ) == jaccard_index_segments(
            TOUCHING_GT_LINES, TOUCHING_PRED_LINES, 80, mode=mode
        )


def test_jaccard_true_segments_equal_the_runs_when_instances_do_not_touch():
    y_true, y_pred = [Y_TRUE_WORKED], [Y_PRED_WORKED]
    segments = [labels_to_segments(Y_TRUE_WORKED)]
    for mode in MODES:
        assert jaccard_index(y_true, y_pred, mode=mode, true_segments=segments) == (
            jaccard_index(y_true, y_pred, mode=mode)
        )


@pytest.mark.parametrize(
    "segments, error, match",
    [
        ([], ValueError, "true_segments has 0 sequences but y_true has 1"),
        ("3,10,40", TypeError, "true_segments must be a list"),
        ([[[3, 10]]], ValueError, r"true_segments\[0\] must have shape \(n_segm"),
        ([[[3, 10, 90]]], ValueError, r"true_segments\[0\] row 0 .* outside"),
        ([[[3, 10.5, 40]]], ValueError, r"true_segments\[0\] row 0 .* whole number"),
    ],
)  # fmt: skip
def test_jaccard_true_segments_are_validated(segments, error, match):
    y = np.zeros(80, int)
    y[10:70] = 3
    with pytest.raises(error, match=match):
        jaccard_index([y], [y], true_segments=segments)


def test_jaccard_of_a_huge_label_allocates_one_frame_row_at_a_time():
    import tracemalloc

    y_true = [np.r_[np.zeros(50, int), np.full(100, 10**9), np.zeros(50, int)]]
    y_pred = [np.r_[np.zeros(60, int), np.full(90, 10**9), np.zeros(50, int)]]
    tracemalloc.start()
    try:
        score = jaccard_index(y_true, y_pred)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert score == pytest.approx(89 / 99)
    assert peak < 1_000_000  # 10**9 x 200 frames would be 186 GB


@pytest.mark.parametrize(
    "y, match",
    [
        ([0, 1.7, 1.7, 0], r"frame 1 has .*1\.7"),
        ([0, np.nan, 0], r"frame 1 has .*nan"),
        ([0, np.inf, 0], r"frame 1 has .*inf"),
        ([[0, 1], [1, 0]], r"must be 1-D .* shape \(2, 2\)"),
        (["a", "b"], "must hold integers"),
    ],
)
def test_labels_to_segments_rejects_non_integer_labels(y, match):
    with pytest.raises(ValueError, match=match):
        labels_to_segments(y)


def test_labels_to_segments_accepts_whole_floats():
    assert labels_to_segments([0.0, 2.0, 2.0, 0.0]).tolist() == [[2, 1, 3]]


@pytest.mark.parametrize(
    "segments, n_frames, match",
    [
        ([[1, 1.5, 3]], 5, r"row 0 = \(1\.0, 1\.5, 3\.0\) holds a value that is not"),
        ([[1, 1, 3.2]], 5, "not a whole number"),
        ([[1, 1, np.nan]], 5, "not a whole number"),
        ([[1.5, 1, 3]], 5, "not a whole number"),
        ([[1, 1]], 5, r"shape \(n_segments, 3\) .* got shape \(1, 2\)"),
        ([[1, 1], [2, 2], [3, 3]], 5, r"got shape \(3, 2\)"),  # not read as 2 rows
        ([1, 1, 3], 5, r"got shape \(3,\)"),
        ([[1, 1, 3]], -5, "n_frames must be a non-negative integer, got -5"),
        ([[1, 1, 3]], 5.5, "n_frames must be a non-negative integer"),
        ([[1, 0, 1e30]], 5, "outside|overflows"),
        ([["a", 1, 3]], 5, "must hold integers"),
    ],
)
def test_segments_to_labels_rejects_malformed_segments(segments, n_frames, match):
    with pytest.raises(ValueError, match=match):
        segments_to_labels(segments, n_frames)


def test_segments_to_labels_accepts_whole_float_bounds_and_no_segment():
    assert segments_to_labels([[2.0, 1.0, 3.0]], 4).tolist() == [0, 2, 2, 0]
    assert segments_to_labels(np.zeros((0, 3)), 3).tolist() == [0, 0, 0]
    assert segments_to_labels([], 0).tolist() == []
