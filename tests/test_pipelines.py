"""make_method_a / make_method_b: structure, paper defaults, and the pipelines in
scikit-learn's model-selection tools on a small synthetic stream."""

import joblib
import numpy as np
import pytest
import torch
from numpy.testing import assert_array_equal
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate
from sklearn.pipeline import Pipeline

from skgesture import (
    ActivitySegmenter,
    DynamicPoseWindow,
    MultiScaleClassifier,
    PoseDescriptor,
    TorchMLPClassifier,
    make_method_a,
    make_method_b,
)
from skgesture.datasets import make_gesture_streams
from skgesture.metrics import jaccard_index, jaccard_scorer

# METHOD_SPEC §4.4, §5.5, §6.1-§6.3
STEPS_A, STEPS_B = (4,), (4, 3, 2)
WEIGHTS_B = (0.4895, 0.4576, 0.0529)
THRESHOLDS_A = (0.8717, 0.6255)  # short, long
THRESHOLDS_B = (0.6014, 0.6033)
SEGMENTER_DEFAULTS = {
    "threshold": 0.4,
    "min_length": 12,
    "smooth_span": 15,
    "n_context": 10,
}
STAGES = ["descriptor", "segmenter", "windows", "classifier"]
N_CLASSES = 3
# tiny networks: measured 0.91-0.94 on the training streams and 0.69-0.81 on
# streams drawn with another seed, over six torch seeds
MIN_TRAIN_JACCARD = 0.8
MIN_TEST_JACCARD = 0.5
GRID = {"classifier__threshold_short": [0.5, 0.8], "segmenter__threshold": [0.3, 0.5]}


def _small_net(**params):
    return TorchMLPClassifier(
        hidden_layer_sizes=(8,), activations=("tanh",), max_epochs=30, **params
    )


def _small(pipe):
    # the window network sees ~150 windows: training on all of them (no
    # validation stop) makes the tiny network reliable
    return pipe.set_params(
        segmenter__estimator=_small_net(),
        classifier__estimator=_small_net(validation_fraction=0.0),
    )


@pytest.fixture(scope="module")
def streams():
    return make_gesture_streams(
        n_sequences=4,
        n_classes=N_CLASSES,
        n_gestures=(3, 4),
        n_subjects=2,
        random_state=0,
    )


@pytest.fixture(scope="module")
def other_streams():
    """Streams of the same classes drawn with another seed."""
    return make_gesture_streams(
        n_sequences=4,
        n_classes=N_CLASSES,
        n_gestures=(3, 4),
        n_subjects=2,
        random_state=1,
    )


@pytest.fixture(scope="module")
def fitted_a(streams):
    n_threads = torch.get_num_threads()
    torch.set_num_threads(1)
    pipe = _small(make_method_a(random_state=0)).fit(streams.X, streams.y)
    torch.set_num_threads(n_threads)
    return pipe


# --------------------------------------------------------------------------------
# Structure and defaults
# --------------------------------------------------------------------------------


def test_method_a_has_the_papers_stages_and_numbers():
    pipe = make_method_a()
    assert isinstance(pipe, Pipeline)
    assert [name for name, _ in pipe.steps] == STAGES
    types = [PoseDescriptor, ActivitySegmenter, DynamicPoseWindow, MultiScaleClassifier]
    assert [type(step) for _, step in pipe.steps] == types
    clf = pipe.named_steps["classifier"]
    assert tuple(pipe.named_steps["windows"].steps) == STEPS_A
    assert tuple(clf.steps) == STEPS_A
    assert (clf.threshold_short, clf.threshold_long) == THRESHOLDS_A
    assert clf.weights is None
    # The paper's 549-300 (tanh)-100 (tanh)-K network, explicit so that nested
    # parameters (classifier__estimator__max_epochs) can be set.
    assert isinstance(clf.estimator, TorchMLPClassifier)
    assert tuple(clf.estimator.hidden_layer_sizes) == (300, 100)
    assert tuple(clf.estimator.activations) == ("tanh", "tanh")
    seg = pipe.named_steps["segmenter"].estimator
    assert tuple(seg.hidden_layer_sizes) == (100, 100)
    assert tuple(seg.activations) == ("relu", "tanh")
    seg = pipe.named_steps["segmenter"]
    assert {k: seg.get_params()[k] for k in SEGMENTER_DEFAULTS} == SEGMENTER_DEFAULTS
    assert pipe.named_steps["descriptor"].joints == "paper11"


def test_method_b_has_three_scales_fusion_weights_and_thresholds():
    pipe = make_method_b()
    assert [name for name, _ in pipe.steps] == STAGES
    clf = pipe.named_steps["classifier"]
    assert tuple(pipe.named_steps["windows"].steps) == STEPS_B
    assert tuple(clf.steps) == STEPS_B
    assert tuple(clf.weights) == WEIGHTS_B
    assert sum(WEIGHTS_B) == pytest.approx(1.0)
    assert (clf.threshold_short, clf.threshold_long) == THRESHOLDS_B
    assert (clf.short_length, clf.min_consecutive, clf.stride) == (55, 3, 2)


@pytest.mark.parametrize("make", [make_method_a, make_method_b])
def test_method_factories_pass_their_options_to_every_stage(make, tmp_path):
    memory = joblib.Memory(tmp_path, verbose=0)
    pipe = make(joints="full20", memory=memory, random_state=7, verbose=1)
    assert pipe.named_steps["descriptor"].joints == "full20"
    for name in ("segmenter", "classifier"):
        step = pipe.named_steps[name]
        assert step.memory is memory
        assert step.random_state == 7
        assert step.verbose == 1
    without = make(segment=False)
    assert [name for name, _ in without.steps] == [
        "descriptor",
        "windows",
        "classifier",
    ]


# --------------------------------------------------------------------------------
# End to end on a small synthetic stream
# --------------------------------------------------------------------------------


def test_method_a_end_to_end_fit_predict(fitted_a, streams, other_streams):
    pred = fitted_a.predict(streams.X)
    assert len(pred) == len(streams.X)
    for p, lab in zip(pred, streams.y):
        assert p.shape == lab.shape
        assert set(np.unique(p)) <= set(range(N_CLASSES + 1))
    assert jaccard_index(streams.y, pred) > MIN_TRAIN_JACCARD
    assert fitted_a.score(streams.X, streams.y) == jaccard_index(streams.y, pred)
    assert fitted_a.score(other_streams.X, other_streams.y) > MIN_TEST_JACCARD


def test_method_b_end_to_end_fit_predict(streams, other_streams):
    pipe = _small(make_method_b(random_state=0)).fit(streams.X, streams.y)
    clf = pipe.named_steps["classifier"]
    assert len(clf.estimators_) == 3
    assert_array_equal(clf.classes_, np.arange(1, N_CLASSES + 1))
    pred = pipe.predict(streams.X)
    assert jaccard_index(streams.y, pred) > MIN_TRAIN_JACCARD
    assert pipe.score(other_streams.X, other_streams.y) > MIN_TEST_JACCARD


def test_method_a_predictions_are_rest_outside_the_segmenter_periods(fitted_a, streams):
    periods = fitted_a[:2].transform(streams.X)  # descriptor + segmenter
    for masked, p in zip(periods, fitted_a.predict(streams.X)):
        rest = np.ma.getmaskarray(masked).all(axis=1)
        assert rest.any() and (~rest).any()
        assert (p[rest] == 0).all()


def test_method_a_clone_is_unfitted_with_equal_params(fitted_a):
    copy = clone(fitted_a)
    assert not hasattr(copy.named_steps["classifier"], "estimators_")
    params, original = copy.get_params(deep=False), fitted_a.get_params(deep=False)
    assert params.keys() == original.keys()
    deep = copy.get_params()
    for key, value in fitted_a.get_params().items():
        if not hasattr(value, "get_params") and key != "steps":
            assert deep[key] == value, key


def test_method_a_joblib_round_trip_gives_identical_predictions(
    fitted_a, streams, tmp_path
):
    path = tmp_path / "method_a.joblib"
    joblib.dump(fitted_a, path)
    restored = joblib.load(path)
    for a, b in zip(restored.predict(streams.X), fitted_a.predict(streams.X)):
        assert_array_equal(a, b)


def test_method_a_cross_validate_with_groups(streams):
    pipe = _small(make_method_a(random_state=0))
    result = cross_validate(
        pipe,
        streams.X,
        streams.y,
        groups=streams.groups,
        cv=GroupKFold(n_splits=2),
        scoring=jaccard_scorer,
    )
    assert len(result["test_score"]) == 2
    assert np.isfinite(result["test_score"]).all()
    assert ((result["test_score"] >= 0) & (result["test_score"] <= 1)).all()


def test_method_a_grid_search_trains_each_network_once_per_fold(streams, tmp_path):
    memory = joblib.Memory(tmp_path, verbose=0)
    pipe = _small(make_method_a(memory=memory, random_state=0))
    search = GridSearchCV(pipe, GRID, cv=GroupKFold(n_splits=2), scoring=jaccard_scorer)
    search.fit(streams.X, streams.y, groups=streams.groups)
    assert len(search.cv_results_["params"]) == 4
    assert search.best_params_["classifier__threshold_short"] in (0.5, 0.8)
    assert search.best_params_["segmenter__threshold"] in (0.3, 0.5)
    assert np.isfinite(search.cv_results_["mean_test_score"]).all()
    # (2 folds + refit) x (segmenter network + one window network); the
    # thresholds never reach a network's cache key
    assert len(list(tmp_path.rglob("output.pkl"))) == 3 * 2
    best = search.best_estimator_.named_steps
    assert best["segmenter"].threshold == search.best_params_["segmenter__threshold"]
    assert len(search.predict(streams.X)) == len(streams.X)
