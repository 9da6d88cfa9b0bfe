"""TorchMLPClassifier: solvers, outputs, reproducibility, MATLAB-style stopping."""

import pickle

import numpy as np
import pytest
import torch
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import clone
from sklearn.exceptions import NotFittedError

from skgesture import TorchMLPClassifier
from skgesture._networks import seed_from

SOLVERS = ("scg", "adam", "lbfgs")
FAST = {"hidden_layer_sizes": (8,), "activations": ("tanh",), "max_epochs": 30}
SOLVER_PARAMS = {
    "scg": {},
    "adam": {"learning_rate": 0.05, "batch_size": 32},
    "lbfgs": {},
}
MIN_TRAIN_ACCURACY = 0.95
# MATLAB dividerand defaults (METHOD_SPEC §8.6.4)
VALIDATION_FRACTION = TEST_FRACTION = 0.15


def _blobs(centres, n_per_class=40, spread=0.5, seed=0, labels=None):
    rng = np.random.RandomState(seed)
    X = np.concatenate([rng.normal(c, spread, (n_per_class, 2)) for c in centres])
    labels = range(len(centres)) if labels is None else labels
    y = np.concatenate([np.full(n_per_class, lab) for lab in labels])
    return X, y


BINARY = _blobs([(-2.0, 0.0), (2.0, 0.0)])
THREE_CLASS = _blobs([(-3.0, 0.0), (3.0, 0.0), (0.0, 4.0)], labels=[1, 5, 9])


def _clf(**params):
    return TorchMLPClassifier(**{**FAST, **params})


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("problem", ["binary", "three_class"])
def test_mlp_solvers_learn_a_separable_problem(solver, problem):
    X, y = BINARY if problem == "binary" else THREE_CLASS
    clf = _clf(solver=solver, random_state=0, **SOLVER_PARAMS[solver]).fit(X, y)
    assert clf.score(X, y) >= MIN_TRAIN_ACCURACY
    assert len(clf.net_.history) <= FAST["max_epochs"]


def test_mlp_binary_problem_has_one_sigmoid_output():
    X, y = BINARY
    clf = _clf(random_state=0).fit(X, y)
    assert clf.net_.module_.net[-1].out_features == 1
    proba = clf.predict_proba(X)
    logits = clf.net_.module_(torch.as_tensor(X, dtype=torch.float32)).detach().numpy()
    assert_allclose(proba[:, 1], 1 / (1 + np.exp(-logits[:, 0])), rtol=1e-5)


def test_mlp_multiclass_problem_has_a_softmax_output():
    X, y = THREE_CLASS
    clf = _clf(random_state=0).fit(X, y)
    assert clf.net_.module_.net[-1].out_features == 3
    logits = clf.net_.module_(torch.as_tensor(X, dtype=torch.float32)).detach().numpy()
    e = np.exp(logits - logits.max(axis=1, keepdims=True))
    assert_allclose(clf.predict_proba(X), e / e.sum(axis=1, keepdims=True), rtol=1e-5)


def test_mlp_hidden_layers_and_activations_build_the_module():
    X, y = BINARY
    clf = _clf(
        hidden_layer_sizes=(5, 4), activations=("relu", "sigmoid"), max_epochs=2
    ).fit(X, y)
    layers = list(clf.net_.module_.net)
    assert [type(m).__name__ for m in layers] == [
        "Linear",
        "ReLU",
        "Linear",
        "Sigmoid",
        "Linear",
    ]
    assert [(m.in_features, m.out_features) for m in layers[::2]] == [
        (2, 5),
        (5, 4),
        (4, 1),
    ]


@pytest.mark.parametrize("data", [BINARY, THREE_CLASS], ids=["binary", "three_class"])
def test_mlp_predict_proba_rows_sum_to_one_in_classes_order(data):
    X, y = data
    clf = _clf(random_state=0).fit(X, y)
    proba = clf.predict_proba(X)
    assert proba.shape == (len(X), len(np.unique(y)))
    assert ((proba >= 0) & (proba <= 1)).all()
    assert_allclose(proba.sum(axis=1), 1.0, rtol=1e-6)
    assert_array_equal(clf.classes_, np.unique(y))
    assert_array_equal(clf.predict(X), clf.classes_[proba.argmax(axis=1)])


def test_mlp_string_labels_are_returned_as_given():
    X, y = BINARY
    labels = np.where(y == 1, "wave", "point")
    clf = _clf(random_state=0).fit(X, labels)
    assert_array_equal(clf.classes_, ["point", "wave"])
    assert (clf.predict(X) == labels).mean() >= MIN_TRAIN_ACCURACY


@pytest.mark.parametrize("solver", SOLVERS)
def test_mlp_same_random_state_gives_identical_predictions(solver):
    X, y = THREE_CLASS
    torch.manual_seed(1)
    a = _clf(solver=solver, random_state=0, **SOLVER_PARAMS[solver]).fit(X, y)
    torch.manual_seed(2)  # the global torch RNG must not matter
    b = _clf(solver=solver, random_state=0, **SOLVER_PARAMS[solver]).fit(X, y)
    assert_array_equal(a.predict_proba(X), b.predict_proba(X))


def test_mlp_different_random_states_give_different_networks():
    X, y = THREE_CLASS
    a = _clf(random_state=0).fit(X, y)
    b = _clf(random_state=1).fit(X, y)
    assert not np.array_equal(a.predict_proba(X), b.predict_proba(X))


def test_mlp_pickle_round_trip_gives_identical_predictions():
    X, y = THREE_CLASS
    clf = _clf(random_state=0).fit(X, y)
    restored = pickle.loads(pickle.dumps(clf))
    assert_array_equal(restored.predict_proba(X), clf.predict_proba(X))
    assert_array_equal(restored.classes_, clf.classes_)
    assert restored.get_params() == clf.get_params()


def test_mlp_restores_the_best_validation_weights():
    # overlapping classes: the validation loss stops improving early
    X, y = _blobs([(-0.3, 0.0), (0.3, 0.0)], n_per_class=60, spread=1.0)
    clf = _clf(hidden_layer_sizes=(32,), max_epochs=200, max_fail=3, random_state=0)
    clf.fit(X, y)
    history = clf.net_.history
    valid = np.array(history[:, "valid_loss"])
    best = int(np.argmin(valid))
    assert clf.net_.best_epoch_ == history[best, "epoch"]
    # stopped after max_fail epochs worse than the best (METHOD_SPEC §8.6.3)
    assert len(history) < 200
    assert (valid[best + 1 :] > valid[best]).sum() == 3
    # the kept weights have the best validation loss: rebuild the 70/15/15 division
    n = len(X)
    perm = np.random.RandomState(seed_from(0)).permutation(n)
    n_val = round(VALIDATION_FRACTION * n)
    n_train = n - n_val - round(TEST_FRACTION * n)
    val = np.sort(perm[n_train : n_train + n_val])
    p = clf.predict_proba(X[val])[:, 1]
    t = y[val]
    loss = -np.mean(t * np.log(p) + (1 - t) * np.log(1 - p))
    assert_allclose(loss, valid[best], rtol=1e-4)


def test_mlp_without_validation_trains_on_all_samples():
    X, y = BINARY
    clf = _clf(validation_fraction=0.0, max_epochs=5, random_state=0).fit(X, y)
    assert "valid_loss" not in clf.net_.history[-1]
    assert len(clf.net_.history) == 5
    assert clf.net_.history[-1, "train_batch_count"] == 1  # one full batch of 80


def test_mlp_set_params_changes_the_network():
    X, y = BINARY
    clf = _clf(random_state=0).fit(X, y)
    clf.set_params(hidden_layer_sizes=(3,)).fit(X, y)
    assert clf.net_.module_.net[0].out_features == 3


def test_mlp_clone_is_unfitted_with_equal_params():
    X, y = BINARY
    clf = _clf(random_state=0).fit(X, y)
    copy = clone(clf)
    assert copy.get_params() == clf.get_params()
    assert not hasattr(copy, "net_")


@pytest.mark.parametrize(
    "params, message",
    [
        ({"hidden_layer_sizes": (8, 4)}, "hidden_layer_sizes has 2 layers but "
                                         "activations has 1"),
        ({"validation_fraction": 0.5, "test_fraction": 0.5}, "must be < 1"),
    ],
)  # fmt: skip
def test_mlp_rejects_inconsistent_parameters(params, message):
    X, y = BINARY
    with pytest.raises(ValueError, match=message):
        _clf(**params).fit(X, y)


def test_mlp_rejects_a_single_class():
    X, _ = BINARY
    with pytest.raises(ValueError, match="at least 2 classes; y has 1 class"):
        _clf().fit(X, np.zeros(len(X), int))


def test_mlp_predict_checks_the_number_of_features():
    X, y = BINARY
    clf = _clf(random_state=0, max_epochs=2).fit(X, y)
    with pytest.raises(ValueError, match="3 features"):
        clf.predict(np.zeros((4, 3)))


@pytest.mark.parametrize("method", ["predict", "predict_proba", "score"])
def test_mlp_unfitted_raises_not_fitted(method):
    args = BINARY if method == "score" else BINARY[:1]
    with pytest.raises(NotFittedError):
        getattr(_clf(), method)(*args)
