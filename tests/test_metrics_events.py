"""Event-level metrics: recall of true gestures and false events per minute."""

import numpy as np
import pytest

from skgesture.metrics import event_misses, event_recall, rejection_curve


def test_recall_needs_same_class_and_enough_overlap():
    true = [np.array([[1, 10, 40], [2, 60, 90], [3, 100, 110]])]
    events = [
        np.array(
            [
                [1, 10, 40, 0.9],  # exact: found
                [1, 60, 90, 0.9],  # right place, wrong class: not found
                [3, 108, 130, 0.9],  # IoU 2/30: not found
            ]
        )
    ]
    assert event_recall(true, events) == pytest.approx(1 / 3)
    # a looser overlap rule finds the third gesture too
    assert event_recall(true, events, min_iou=0.05) == pytest.approx(2 / 3)


def test_event_misses_says_why_each_missed_gesture_was_missed():
    true = [
        np.array([[1, 10, 40], [2, 60, 90], [1, 100, 110], [1, 112, 122]]),
        np.array([[2, 0, 50], [1, 80, 100], [3, 200, 230]]),
    ]
    events = [
        np.array(
            [
                [1, 12, 40, 0.9],  # IoU 28/30: found
                [1, 60, 90, 0.9],  # right place, wrong class
                [1, 100, 122, 0.9],  # one event over two gestures: both merged
            ]
        ),
        np.array(
            [
                [2, 0, 10, 0.9],  # the right class, IoU 0.2, no other gesture
                [2, 40, 50, 0.9],  # a second piece of it, still too little
                [1, 80, 100, 0.3],  # would find it, but under min_confidence
            ]
        ),
    ]
    counts = event_misses(true, events, min_confidence=0.5)
    assert counts == {
        "found": 1,
        "wrong_class": 1,
        "merged": 2,
        "boundaries": 1,
        "no_event": 2,
    }
    # the outcomes partition the gestures, and "found" is event_recall's count
    assert sum(counts.values()) == 7
    assert counts["found"] / 7 == pytest.approx(
        event_recall(true, events, min_confidence=0.5)
    )
    for min_iou in (0.1, 0.5, 0.9):
        found = event_misses(true, events, min_iou=min_iou)["found"]
        assert found / 7 == pytest.approx(event_recall(true, events, min_iou=min_iou))
    # a looser overlap turns the too-short events into found gestures
    assert event_misses(true, events, min_iou=0.1)["found"] == 5
    with pytest.raises(ValueError, match="true_segments has 2 sequences, events 1"):
        event_misses(true, events[:1])
    with pytest.raises(ValueError, match=r"events\[0\], row 0: end 5 is not after"):
        event_misses(true[:1], [np.array([[1, 5, 5, 0.9]])])


def test_the_best_matching_confidence_decides_when_a_gesture_is_found():
    true = [np.array([(1, 0, 10), (2, 20, 30), (1, 40, 50)])]
    pred = [
        np.array(
            [
                [1, 0, 8, 0.7],  # IoU 0.8: match
                [1, 2, 12, 0.9],  # IoU 8/12: match, higher confidence
                [1, 20, 30, 0.99],  # wrong class
                [2, 27, 40, 0.8],  # IoU 3/20: too little
                [1, 45, 60, 0.6],  # IoU 5/20: too little
            ]
        )
    ]
    curve = rejection_curve(true, pred, thresholds=[0.0, 0.9, 0.91])
    np.testing.assert_allclose(curve.recall, [1 / 3, 1 / 3, 0.0])


def test_one_event_finds_each_gesture_it_overlaps_but_confidence_gates_it():
    true = [np.array([[1, 0, 20]]), np.array([[1, 0, 20]])]
    events = [np.array([[1, 0, 18, 0.7]]), np.zeros((0, 4))]
    curve = rejection_curve(true, events, thresholds=[0.0, 0.7, 0.71])
    np.testing.assert_allclose(curve.recall, [0.5, 0.5, 0.0])
    assert curve.n_gestures == 2
    assert "false_per_minute" not in curve


def test_false_events_per_minute_fall_with_the_floor():
    true = [np.array([[1, 0, 30]])]
    events = [np.array([[1, 0, 30, 0.95]])]
    rng = np.random.default_rng(0)
    conf = rng.uniform(0, 1, 50)
    background = [
        np.column_stack([np.ones(25), np.arange(25) * 10, np.arange(25) * 10 + 5, c])
        for c in (conf[:25], conf[25:])
    ]
    thresholds = np.linspace(0, 0.9, 10)
    curve = rejection_curve(true, events, background, 5.0, thresholds=thresholds)
    assert np.all(np.diff(curve.false_per_minute) <= 0)
    np.testing.assert_allclose(
        curve.false_per_minute, [np.sum(conf >= t) / 5.0 for t in thresholds]
    )
    assert curve.n_false[0] == 50 and curve.minutes == 5.0
    np.testing.assert_allclose(curve.recall, 1.0)


def test_no_gestures_gives_nan_recall():
    curve = rejection_curve([np.zeros((0, 3))], [np.zeros((0, 4))], thresholds=[0.5])
    assert np.isnan(curve.recall[0]) and curve.n_gestures == 0


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"true_segments": [np.zeros((1, 2))]}, r"true_segments\[0\]: expected rows"),
        ({"events": [np.array([[1, 5, 5, 0.5]])]}, r"events\[0\], row 0: end 5"),
        ({"events": [[], []]}, "true_segments has 1 sequences, events 2"),
        ({"events": np.zeros((1, 4))}, "must be lists"),
        ({"min_iou": 0}, r"min_iou must be a number in \(0, 1\]"),
        ({"thresholds": []}, "thresholds must be a non-empty"),
        ({"background_minutes": 2.0}, "without background_events"),
        (
            {"background_events": [np.zeros((0, 4))], "background_minutes": 0},
            "background_minutes must be a positive number",
        ),
        (
            {"background_events": [np.array([[1, 0, 3]])], "background_minutes": 1},
            r"background_events\[0\]: expected rows of 4",
        ),
    ],
)
def test_bad_input_is_named(kwargs, match):
    args = {
        "true_segments": [np.array([[1, 0, 10]])],
        "events": [np.array([[1, 0, 10, 0.9]])],
    }
    args.update(kwargs)
    with pytest.raises((ValueError, TypeError), match=match):
        rejection_curve(**args)
