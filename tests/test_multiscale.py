"""MultiScaleClassifier and the paper's decision rules (docs/method.md §5.5, §6)."""

import copy

import joblib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.linear_model import LogisticRegression
from sklearn.utils._param_validation import InvalidParameterError

from skgesture import DynamicPoseWindow, MultiScaleClassifier, TorchMLPClassifier
from skgesture._multiscale._rules import decide_period
from skgesture.metrics import labels_to_segments

# --------------------------------------------------------------------------------
# decide_period on hand-made score sequences
# --------------------------------------------------------------------------------

THRESHOLD_SHORT = 0.8717  # §5.5
THRESHOLD_LONG = 0.6255
SHORT_L, LONG_L = 20, 60
LONG_CENTRES = 4 + 2 * np.arange((LONG_L - 9) // 2 + 1)  # 26 windows, 4 .. 54
SHORT_CENTRES = 4 + 2 * np.arange(5)


def _scores(tops, n_classes=3):
    """One score row per (class index, top score); the rest shared evenly."""
    rows = []
    for cls, top in tops:
        row = np.full(n_classes, (1.0 - top) / (n_classes - 1))
        row[cls] = top
        rows.append(row)
    return np.array(rows)


def _long_scores(runs, background=0.34):
    """26 windows at `background`, with {window index: (class, top)} overrides."""
    tops = [(0, background)] * len(LONG_CENTRES)
    for idx, value in runs.items():
        tops[idx] = value
    return _scores(tops)


# (votes as (class, top)) -> expected class index + 1 for the whole period, or 0
SHORT_CASES = {
    "absolute_majority": ([(0, 0.95), (0, 0.90), (1, 0.88), (0, 0.50), (0, 0.92)], 1),
    "tie_is_rest": ([(0, 0.95), (0, 0.90), (1, 0.88), (1, 0.93)], 0),
    "half_is_not_a_majority": ([(0, 0.95), (0, 0.90), (1, 0.88), (2, 0.93)], 0),
    "plurality_is_not_a_majority": (
        [(0, 0.95), (0, 0.9), (0, 0.9), (1, 0.9), (1, 0.9), (2, 0.9), (2, 0.9)],
        0,
    ),
    "votes_below_threshold_ignored": (
        [(2, 0.95), (1, 0.80), (1, 0.80), (1, 0.80), (1, 0.87)],
        3,
    ),
    "no_votes_is_rest": ([(0, 0.80), (1, 0.70), (2, 0.60)], 0),
}
SHORT_CONF_GT = (0.95 + 0.90 + 0.92) / 3  # "absolute_majority": mean top of its votes

# Long period: run A = windows 5-7 (centres 14, 16, 18, class 0, top 0.9),
# run B = windows 8-10 (centres 20, 22, 24, class 1, top 0.8). Extents [10, 22]
# and [16, 28]; frames 16-19 are nearer (or, 19, equally near) to A's centres.
RUN_A = {5: (0, 0.9), 6: (0, 0.9), 7: (0, 0.9)}
RUN_B = {8: (1, 0.8), 9: (1, 0.8), 10: (1, 0.8)}
OVERLAP_LABELS_GT = np.zeros(LONG_L, int)
OVERLAP_LABELS_GT[10:20] = 1
OVERLAP_LABELS_GT[20:29] = 2


@pytest.mark.parametrize("case", sorted(SHORT_CASES))
def test_decide_short_period(case):
    tops, expected = SHORT_CASES[case]
    scores = _scores(tops)
    labels, segments = decide_period(
        scores, SHORT_CENTRES[: len(scores)], SHORT_L, threshold_short=THRESHOLD_SHORT
    )
    assert_array_equal(labels, np.full(SHORT_L, expected))
    assert len(segments) == (expected > 0)


def test_decide_short_period_segment_and_confidence():
    tops, _ = SHORT_CASES["absolute_majority"]
    _, segments = decide_period(
        _scores(tops), SHORT_CENTRES, SHORT_L, threshold_short=THRESHOLD_SHORT
    )
    assert len(segments) == 1
    cls, start, end, conf = segments[0]
    assert (cls, start, end) == (1, 0, SHORT_L)
    assert_allclose(conf, SHORT_CONF_GT, rtol=1e-12)


def test_decide_short_period_lower_threshold_admits_more_votes():
    tops, _ = SHORT_CASES["votes_below_threshold_ignored"]
    labels, _ = decide_period(
        _scores(tops), SHORT_CENTRES, SHORT_L, threshold_short=0.7
    )
    assert_array_equal(labels, 2)  # now class index 1 has 4 of 5 votes


def test_decide_score_equal_to_threshold_does_not_vote():
    scores = _scores([(0, 0.75)] * 5)
    labels, segments = decide_period(
        scores, SHORT_CENTRES, SHORT_L, threshold_short=0.75
    )
    assert_array_equal(labels, 0)
    assert segments == []


def test_decide_without_windows_is_rest():
    labels, segments = decide_period(np.zeros((0, 3)), np.zeros(0, int), 30)
    assert_array_equal(labels, np.zeros(30, int))
    assert segments == []


def test_decide_long_period_run_of_3_labels_first_start_to_last_end():
    labels, segments = decide_period(
        _long_scores(RUN_A), LONG_CENTRES, LONG_L, threshold_long=THRESHOLD_LONG
    )
    expected = np.zeros(LONG_L, int)
    expected[10:23] = 1  # centres 14..18 -> frames 14-4 .. 18+4
    assert_array_equal(labels, expected)
    assert len(segments) == 1
    assert segments[0][:3] == (1, 10, 23)
    assert_allclose(segments[0][3], 0.9)


def test_decide_long_period_two_consecutive_windows_are_not_enough():
    labels, segments = decide_period(
        _long_scores({5: (0, 0.9), 6: (0, 0.9)}), LONG_CENTRES, LONG_L
    )
    assert_array_equal(labels, 0)
    assert segments == []


def test_decide_long_period_run_broken_by_a_weak_window_is_not_counted():
    runs = {5: (0, 0.9), 6: (0, 0.9), 7: (0, 0.6), 8: (0, 0.9), 9: (0, 0.9)}
    labels, _ = decide_period(
        _long_scores(runs), LONG_CENTRES, LONG_L, threshold_long=THRESHOLD_LONG
    )
    assert_array_equal(labels, 0)


def test_decide_long_period_uses_the_long_threshold():
    runs = dict.fromkeys(range(5, 9), (2, 0.7))
    labels, _ = decide_period(
        _long_scores(runs),
        LONG_CENTRES,
        LONG_L,
        threshold_short=THRESHOLD_SHORT,
        threshold_long=THRESHOLD_LONG,
    )
    assert_array_equal(np.flatnonzero(labels), np.arange(10, 25))
    assert_array_equal(labels[10:25], 3)
    # the same windows in a short period do not reach the short threshold
    labels, _ = decide_period(
        _long_scores(runs)[:20],
        LONG_CENTRES[:20],
        54,
        threshold_short=THRESHOLD_SHORT,
        threshold_long=THRESHOLD_LONG,
    )
    assert_array_equal(labels, 0)


@pytest.mark.parametrize("length, is_short", [(54, True), (55, False)])
def test_decide_short_length_boundary(length, is_short):
    # a single confident window: labels a short period, too short a run if long
    scores = _long_scores({3: (1, 0.99)})
    labels, _ = decide_period(scores, LONG_CENTRES, length, short_length=55)
    assert_array_equal(labels, 2 if is_short else 0)


def test_decide_long_period_overlapping_runs_split_by_nearest_centre():
    labels, segments = decide_period(
        _long_scores({**RUN_A, **RUN_B}),
        LONG_CENTRES,
        LONG_L,
        threshold_long=THRESHOLD_LONG,
    )
    # frame 19 is 1 frame from centre 18 (A) and from centre 20 (B): earlier run A
    assert_array_equal(labels, OVERLAP_LABELS_GT)
    assert [s[0] for s in segments] == [1, 2]
    assert_allclose([s[3] for s in segments], [0.9, 0.8])


def test_decide_long_period_exact_tie_goes_to_the_earlier_run():
    # A at centres 14-18, B at centres 22-26 (window 9 weak): frame 20 is 2 from both
    runs = {**RUN_A, 9: (1, 0.8), 10: (1, 0.8), 11: (1, 0.8)}
    labels, _ = decide_period(
        _long_scores(runs), LONG_CENTRES, LONG_L, threshold_long=THRESHOLD_LONG
    )
    expected = np.zeros(LONG_L, int)
    expected[10:21] = 1  # A: 10 .. 20 (frame 20 tied, frame 21 nearer to B)
    expected[21:31] = 2  # B: 21 .. 26 + 4
    assert_array_equal(labels, expected)


def test_decide_long_period_segments_agree_with_labels():
    labels, segments = decide_period(
        _long_scores({**RUN_A, **RUN_B}),
        LONG_CENTRES,
        LONG_L,
        threshold_long=THRESHOLD_LONG,
    )
    assert_array_equal([s[:3] for s in segments], labels_to_segments(labels))


def test_decide_long_period_adjacent_runs_of_one_class_stay_two_segments():
    # A at centres 4-8 (extent 0-12), B at centres 12-16 (extent 8-20): frame 10
    # is tied (earlier run A), frames 11-12 are nearer to B
    runs = {
        0: (0, 0.9),
        1: (0, 0.9),
        2: (0, 0.9),
        4: (0, 0.8),
        5: (0, 0.8),
        6: (0, 0.8),
    }
    labels, segments = decide_period(
        _long_scores(runs), LONG_CENTRES, LONG_L, threshold_long=THRESHOLD_LONG
    )
    expected = np.zeros(LONG_L, int)
    expected[0:21] = 1
    assert_array_equal(labels, expected)
    assert [s[:3] for s in segments] == [(1, 0, 11), (1, 11, 21)]
    assert_allclose([s[3] for s in segments], [0.9, 0.8])


# --------------------------------------------------------------------------------
# MultiScaleClassifier with a fast linear estimator
# --------------------------------------------------------------------------------

STEPS = (4, 2)
N_FEATURES = 4
# Class means in feature space; frames are mean + N(0, 0.3).
CLASS_MEANS = {
    1: (3.0, 0.0, 0.0, 0.0),
    2: (0.0, 3.0, 0.0, 0.0),
    3: (0.0, 0.0, 3.0, 0.0),
}
REST_MEAN = (0.0, 0.0, 0.0, 3.0)
CLIP_LENGTH = 30


def _frames(mean, n, rng):
    return rng.normal(mean, 0.3, (n, N_FEATURES))


def _clips(classes, seed=0, length=CLIP_LENGTH):
    rng = np.random.RandomState(seed)
    X = [_frames(CLASS_MEANS[c], length, rng) for c in classes]
    y = [np.full(length, c) for c in classes]
    return X, y


def _windows(X, steps=STEPS):
    return DynamicPoseWindow(steps=steps).fit_transform(X)


def _clf(**params):
    params = {"steps": STEPS, "threshold_short": 0.5, **params}
    return MultiScaleClassifier(LogisticRegression(), **params)


def _stream(layout, seed=1):
    """One sequence from [(label, n_frames), ...]; rest (0) rows are masked."""
    rng = np.random.RandomState(seed)
    parts = [_frames(CLASS_MEANS.get(c, REST_MEAN), n, rng) for c, n in layout]
    y = np.concatenate([np.full(n, c) for c, n in layout])
    mask = np.repeat((y == 0)[:, None], N_FEATURES, axis=1)
    return np.ma.MaskedArray(np.concatenate(parts), mask=mask), y


@pytest.fixture(scope="module")
def fitted():
    X, y = _clips([1, 2, 3, 1, 2, 3])
    return _clf().fit(_windows(X), y)


def test_multiscale_plain_arrays_are_one_period(fitted):
    X, _ = _clips([3, 1, 2], seed=5)
    pred = fitted.predict(_windows(X))
    assert [p.tolist() for p in pred] == [[c] * CLIP_LENGTH for c in (3, 1, 2)]
    assert all(p.dtype.kind == "i" for p in pred)


def test_multiscale_masked_input_gives_periods_from_the_mask(fitted):
    layout = [(0, 15), (2, 30), (0, 10), (1, 12), (0, 8), (3, 60), (0, 5)]
    x, y = _stream(layout)
    W = DynamicPoseWindow(steps=STEPS).fit_transform([x])
    pred = fitted.predict(W)[0]
    expected = y.copy()
    # the 60-frame period is long: labelled from the first window's start to the
    # last window's end; L - 9 = 51 is odd, so its last frame stays rest (§5.2)
    expected[15 + 30 + 10 + 12 + 8 + 59] = 0
    assert_array_equal(pred, expected)


def test_multiscale_predict_segments_rows_are_class_start_end_confidence(fitted):
    layout = [(0, 15), (2, 30), (0, 10), (1, 12), (0, 8)]
    x, _ = _stream(layout)
    segs = fitted.predict_segments(DynamicPoseWindow(steps=STEPS).fit_transform([x]))
    assert len(segs) == 1
    assert segs[0].shape == (2, 4)
    assert_array_equal(segs[0][:, :3], [[2, 15, 45], [1, 55, 67]])
    assert ((segs[0][:, 3] > 0.5) & (segs[0][:, 3] <= 1.0)).all()


def test_multiscale_without_prediction_gives_empty_segment_array(fitted):
    X, _ = _clips([1])
    strict = copy.deepcopy(fitted).set_params(threshold_short=1.0)
    segs = strict.predict_segments(_windows(X))
    assert segs[0].shape == (0, 4)


def test_multiscale_confidence_is_the_mean_normalised_fused_score():
    X, y = _clips([1, 2, 3, 1, 2, 3])
    W = _windows(X)
    a = _clf(weights=(3.0, 1.0)).fit(W, y)
    b = _clf(weights=(0.75, 0.25)).fit(W, y)
    test = _windows(_clips([2], seed=7)[0])
    sa, sb = a.predict_segments(test)[0], b.predict_segments(test)[0]
    assert_allclose(sa, sb, rtol=1e-12)
    # by hand: windows at centres 4, 6, .., 24 of the 30-frame clip (§6.2)
    centres = np.arange(4, 26, 2)
    fused = sum(
        # the classifier works on float32 windows (DynamicPoseWindow's dtype)
        w * est.predict_proba(test[0][centres, k].astype(np.float32)).astype(float)
        for k, (w, est) in enumerate(zip((0.75, 0.25), a.estimators_))
    )
    top = fused.max(axis=1)
    assert_array_equal(fused.argmax(axis=1), 1)  # class 2 = classes_[1]
    assert_allclose(sa[0, 3], top[top > 0.5].mean(), rtol=1e-9)


def test_multiscale_fits_one_estimator_per_scale_on_gesture_windows(fitted):
    assert len(fitted.estimators_) == len(STEPS)
    assert_array_equal(fitted.classes_, [1, 2, 3])
    # 6 clips x 11 windows (centres 4..24) per scale, one feature block per scale
    for est in fitted.estimators_:
        assert est.n_features_in_ == 3 * N_FEATURES
        assert_array_equal(est.classes_, [1, 2, 3])


def test_multiscale_class_absent_from_training_is_never_predicted():
    X, y = _clips([1, 3, 1, 3])
    clf = _clf().fit(_windows(X), y)
    assert_array_equal(clf.classes_, [1, 3])
    test, _ = _clips([1, 2, 3, 2], seed=3)
    pred = np.concatenate(clf.predict(_windows(test)))
    assert set(np.unique(pred)) <= {0, 1, 3}
    assert_array_equal(clf.predict(_windows(test))[2], 3)  # mapped back via classes_


def test_multiscale_resizes_a_short_period_and_labels_it_whole(fitted):
    layout = [(0, 10), (3, 9), (0, 10)]
    x, y = _stream(layout)
    pred = fitted.predict(DynamicPoseWindow(steps=STEPS).fit_transform([x]))[0]
    assert_array_equal(pred, y)


def test_multiscale_score_is_the_jaccard_index(fitted):
    X, y = _clips([2, 3], seed=11)
    assert fitted.score(_windows(X), y) == 1.0


WEIGHTS_ERROR = "must be a non-empty tuple of finite weights >= 0, not all 0"
STEPS_ERROR = "'steps' parameter of MultiScaleClassifier must be a non-empty tuple"


@pytest.mark.parametrize(
    "params, message",
    [
        ({"weights": (0.5, 0.3, 0.2)}, "weights has 3 values but steps has 2"),
        ({"steps": (4,)}, r"X has 2 scales per frame but steps=\(4,\)"),
        ({"steps": (4, 3)}, r"X\[0\] does not hold dynamic poses with steps=\(4, 3\)"),
        ({"min_windows": 900, "stride": 20}, "would resize every short period to"),
    ],
)
def test_multiscale_rejects_inconsistent_parameters(params, message):
    X, y = _clips([1, 2])
    with pytest.raises(ValueError, match=message):
        _clf(**params).fit(_windows(X), y)


@pytest.mark.parametrize(
    "params, message",
    [
        ({"weights": (1.0, -1.0)}, WEIGHTS_ERROR),
        ({"weights": (0.0, 0.0)}, WEIGHTS_ERROR),
        ({"weights": (np.nan, 1.0)}, WEIGHTS_ERROR),
        ({"weights": (np.inf, 1.0)}, WEIGHTS_ERROR),
        ({"weights": np.array([1.0, np.nan])}, WEIGHTS_ERROR),
        ({"weights": ("a", 1.0)}, WEIGHTS_ERROR),
        ({"steps": ()}, STEPS_ERROR),
        ({"steps": (4, 2.5)}, STEPS_ERROR),
        ({"min_windows": 10**7}, "'min_windows' parameter of MultiScaleClassifier"),
    ],
)
def test_multiscale_rejects_bad_parameter_values(params, message):
    X, y = _clips([1, 2])
    with pytest.raises(InvalidParameterError, match=message):
        _clf(**params).fit(_windows(X), y)


def test_multiscale_rejects_all_rest_labels():
    X, y = _clips([1, 2])
    with pytest.raises(ValueError, match="no gesture instance"):
        _clf().fit(_windows(X), [np.zeros_like(lab) for lab in y])


def test_multiscale_background_sequences_add_no_window():
    """A background sequence (all rest) is accepted and changes nothing: the
    window classifier learns gestures only; the segmenter learns the rest."""
    X, y = _clips([1, 2, 3, 1, 2, 3])
    rng = np.random.RandomState(7)
    background = [_frames(REST_MEAN, 50, rng), _frames(CLASS_MEANS[1], 3, rng)]
    masked, _ = _stream([(0, 40)])  # as the segmenter hands it on: all masked
    Xb = _windows(X + background) + _windows([masked])
    yb = y + [np.zeros(50, int), np.zeros(3, int), np.zeros(40, int)]
    with_bg = _clf().fit(Xb, yb)
    alone = _clf().fit(_windows(X), y)
    assert_array_equal(with_bg.classes_, [1, 2, 3])
    for a, b in zip(with_bg.estimators_, alone.estimators_):
        assert_array_equal(a.coef_, b.coef_)
    with pytest.raises(ValueError, match="no gesture instance"):
        _clf().fit(Xb[6:], yb[6:])


def test_multiscale_rejects_a_single_class():
    X, y = _clips([2, 2])
    with pytest.raises(ValueError, match="single gesture class"):
        _clf().fit(_windows(X), y)


def test_multiscale_rejects_labels_of_wrong_length():
    X, y = _clips([1, 2])
    with pytest.raises(ValueError, match=r"y\[1\] has 29 labels but X\[1\] has 30"):
        _clf().fit(_windows(X), [y[0], y[1][:-1]])


def test_multiscale_predict_checks_window_width(fitted):
    with pytest.raises(ValueError, match=r"X\[0\] has frames of shape"):
        fitted.predict([np.zeros((20, 2, 9))])


def test_multiscale_random_state_seeds_every_scale():
    X, y = _clips([1, 2, 3])
    W = _windows(X)
    net = TorchMLPClassifier(
        hidden_layer_sizes=(4,), activations=("tanh",), max_epochs=3, random_state=None
    )
    a = MultiScaleClassifier(net, steps=STEPS, random_state=0).fit(W, y)
    b = MultiScaleClassifier(net, steps=STEPS, random_state=0).fit(W, y)
    c = MultiScaleClassifier(net, steps=STEPS, random_state=1).fit(W, y)
    seeds = [e.random_state for e in a.estimators_]
    assert all(isinstance(s, int) for s in seeds)
    assert seeds[0] != seeds[1]  # one draw per scale
    assert seeds == [e.random_state for e in b.estimators_]
    assert seeds != [e.random_state for e in c.estimators_]
    assert net.random_state is None  # the given estimator is not modified


def test_multiscale_memory_reuses_scale_estimators_across_decision_params(tmp_path):
    X, y = _clips([1, 2, 3])
    W = _windows(X)
    memory = joblib.Memory(tmp_path, verbose=0)
    _clf(memory=memory).fit(W, y)
    n_cached = len(list(tmp_path.rglob("output.pkl")))
    assert n_cached == len(STEPS)
    _clf(
        memory=memory,
        threshold_short=0.9,
        threshold_long=0.9,
        weights=(1, 3),
        min_consecutive=4,
        short_length=40,
    ).fit(W, y)
    assert len(list(tmp_path.rglob("output.pkl"))) == n_cached
    MultiScaleClassifier(LogisticRegression(C=0.1), steps=STEPS, memory=memory).fit(
        W, y
    )
    assert len(list(tmp_path.rglob("output.pkl"))) == 2 * n_cached


# --------------------------------------------------------------------------------
# One source of truth for the steps (issue 11): the windows are checked
# --------------------------------------------------------------------------------


@pytest.mark.parametrize("built_with", [(5, 2), (4, 3), (2, 4), (4, 1)])
def test_multiscale_fit_refuses_windows_built_with_other_steps(built_with):
    X, y = _clips([1, 2, 3, 1])
    with pytest.raises(ValueError, match=r"X\[0\] does not hold dynamic poses"):
        _clf().fit(_windows(X, steps=built_with), y)


def test_multiscale_step_error_names_the_step_the_windows_were_built_with():
    X, y = _clips([1, 2])
    with pytest.raises(ValueError, match="scale 0 .* look built with step 5 there"):
        _clf().fit(_windows(X, steps=(5, 2)), y)


def test_multiscale_predict_refuses_windows_built_with_other_steps(fitted):
    # steps 4 and 5 clip to the same frame near the start: checked everywhere
    X, _ = _clips([3, 1, 2], seed=5)
    with pytest.raises(ValueError, match=r"does not hold dynamic poses.*\(4, 2\)"):
        fitted.predict(_windows(X, steps=(5, 2)))
    with pytest.raises(ValueError, match=r"X\[1\] does not hold dynamic poses"):
        fitted.predict_segments(_windows(X[:1]) + _windows(X[1:], steps=(4, 3)))


# --------------------------------------------------------------------------------
# Short periods resized for the long rule (issue 11 bug): decided on the
# resized frames, then mapped back
# --------------------------------------------------------------------------------


def _two_class_clip(first, second, seed=3):
    rng = np.random.RandomState(seed)
    x = np.concatenate(
        [_frames(CLASS_MEANS[first], 6, rng), _frames(CLASS_MEANS[second], 6, rng)]
    )
    return x, np.r_[np.full(6, first), np.full(6, second)]


def test_multiscale_long_rule_on_a_resized_period_maps_frames_back():
    # 12 frames, one step of 4, short_length 10: the period is "long" but too
    # short for 5 windows, so it is resized to 17 frames. The first half is
    # class 1, the second class 2: both halves must be labelled.
    X, y = _clips([1, 2, 3, 1, 2, 3])
    clf = MultiScaleClassifier(
        LogisticRegression(), steps=(4,), short_length=10, min_consecutive=2,
        threshold_long=0.5,
    ).fit(_windows(X, steps=(4,)), y)  # fmt: skip
    x, truth = _two_class_clip(1, 2)
    pred = clf.predict(_windows([x], steps=(4,)))[0]
    # (before the fix the resized centres 4..12 were read as original frames:
    # frames 6 and 7 went to class 1)
    assert_array_equal(pred, truth)
    segments = clf.predict_segments(_windows([x], steps=(4,)))[0]
    assert_array_equal(segments[:, :3].astype(int), labels_to_segments(pred))


@pytest.mark.parametrize("resize", ["bicubic", "pchip", "spline"])
def test_multiscale_resized_period_short_rule_labels_every_original_frame(resize):
    # 12 frames < short_length: one label for all 12 frames, whatever the resampler
    X, y = _clips([1, 2, 3, 1, 2, 3])
    clf = _clf(resize=resize).fit(_windows(X), y)
    x, _ = _clips([2], seed=7, length=12)
    assert_array_equal(clf.predict(_windows(x))[0], np.full(12, 2))


def test_resized_frames_inverts_the_resampling_map():
    from skgesture._multiscale._rules import _resized_frames

    # imresize: output u <- input (u + 0.5) L / n - 0.5, so input t -> nearest u
    assert _resized_frames(12, 17, "bicubic").tolist() == [
        0, 2, 3, 4, 6, 7, 9, 10, 12, 13, 14, 16,
    ]  # fmt: skip
    assert _resized_frames(3, 17, "pchip").tolist() == [0, 8, 16]
    assert _resized_frames(1, 17, "spline").tolist() == [8]


# --------------------------------------------------------------------------------
# Untracked frames are rest by construction (issue 11)
# --------------------------------------------------------------------------------


def test_multiscale_all_zero_rows_are_rest_and_split_the_period(fitted):
    X, _ = _clips([3], seed=5, length=60)
    x = X[0].copy()
    x[25:35] = 0.0  # untracked descriptor frames in the middle of the gesture
    W = _windows([x])
    zero = ~W[0].reshape(60, -1).any(axis=1)  # windows made of untracked frames only
    assert_array_equal(np.flatnonzero(zero), [29, 30])
    pred = fitted.predict(W)[0]
    assert_array_equal(pred[29:31], 0)
    assert set(pred[:25]) == {3} and set(pred[35:]) == {3}


def test_multiscale_masked_rows_from_the_descriptor_are_rest(fitted):
    X, _ = _clips([2], seed=6, length=60)
    mask = np.zeros(X[0].shape, dtype=bool)
    mask[20:30, 1] = True  # the descriptor masks every value of an untracked row
    W = _windows([np.ma.MaskedArray(X[0], mask=mask)])
    pred = fitted.predict(W)[0]
    assert_array_equal(pred[20:30], 0)
    assert set(pred[:20]) == {2} and set(pred[30:]) == {2}


# --------------------------------------------------------------------------------
# verbose, absurd values, paper defaults
# --------------------------------------------------------------------------------


def test_multiscale_verbose_shows_progress_and_is_silent_at_0(capsys):
    X, y = _clips([1, 2, 1, 2])
    net = TorchMLPClassifier(hidden_layer_sizes=(4,), activations=("tanh",),
                             max_epochs=3)  # fmt: skip
    MultiScaleClassifier(net, steps=STEPS, random_state=0).fit(_windows(X), y)
    assert capsys.readouterr() == ("", "")
    MultiScaleClassifier(net, steps=STEPS, random_state=0, verbose=1).fit(
        _windows(X), y
    )
    assert "networks of steps (4, 2)" in capsys.readouterr().err
    MultiScaleClassifier(net, steps=STEPS, random_state=0, verbose=2).fit(
        _windows(X), y
    )
    out = capsys.readouterr().out
    assert out.count("valid_loss") == 2  # one epoch table per scale
    assert len([ln for ln in out.splitlines() if ln.strip()[:1].isdigit()]) >= 2


def test_multiscale_refuses_values_beyond_float32(fitted):
    X, _ = _clips([1, 2], seed=5)
    W = [w.astype(np.float64) for w in _windows(X)]
    W[1][7, 0, 2] = 1e39  # float32 would make it inf
    with pytest.raises(ValueError, match=r"X\[1\] has the value 1e\+39 at frame 7"):
        fitted.predict(W)
    W[1][7, 0, 2] = np.inf
    with pytest.raises(ValueError, match=r"X\[1\] contains NaN or infinite values"):
        fitted.predict(W)


def test_multiscale_default_resize_is_the_papers_bicubic():
    # docs/method.md §5.3 / D15, used by make_method_a and make_method_b
    from skgesture import make_method_a, make_method_b

    assert MultiScaleClassifier().resize == "bicubic"
    for make in (make_method_a, make_method_b):
        assert make().named_steps["classifier"].resize == "bicubic"
    # and it is what the classifier does: a short clip gives bicubic windows
    X, y = _clips([1, 2, 3, 1, 2, 3])
    W = _windows(X)
    default = _clf().fit(W, y)
    x, _ = _clips([2], seed=7, length=12)
    Wx = _windows(x)
    for resize, same in (("bicubic", True), ("pchip", False)):
        other = _clf(resize=resize).fit(W, y)
        probs = [
            clf.estimators_[0].predict_proba(clf._windows(Wx[0], 0, 12, STEPS)[0][:, 0])
            for clf in (default, other)
        ]
        assert np.array_equal(*probs) is same
