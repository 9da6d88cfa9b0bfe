"""TorchMLPClassifier: solvers, outputs, reproducibility, MATLAB-style stopping."""

import pickle

import numpy as np
import pytest
import torch
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import clone
from sklearn.exceptions import NotFittedError

from skgesture import TorchMLPClassifier
from skgesture.utils._fitting import seed_from

SOLVERS = ("scg", "adam", "lbfgs")
FAST = {"hidden_layer_sizes": (8,), "activations": ("tanh",), "max_epochs": 30}
SOLVER_PARAMS = {
    "scg": {},
    "adam": {"learning_rate": 0.05, "batch_size": 32},
    "lbfgs": {},
}
MIN_TRAIN_ACCURACY = 0.95
# MATLAB dividerand defaults (docs/method.md §8.6.4)
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
    # stopped after max_fail epochs worse than the best (docs/method.md §8.6.3)
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


# --------------------------------------------------------------------------------
# MATLAB trainscg's stopping rules with their default numbers (docs/method.md §8.6)
# --------------------------------------------------------------------------------


class _FakeNet:
    """Just what _MatlabStopping reads: the history, the module, the optimiser,
    and a validation pass whose loss is ``initial_loss``."""

    def __init__(self, initial_loss, grad_norm=1.0):
        from types import SimpleNamespace

        self.history = []
        self.module_ = torch.nn.Linear(1, 1, bias=False)
        self.optimizer_ = SimpleNamespace(grad_norm=grad_norm)
        self.initial_loss = initial_loss

    def get_iterator(self, dataset, training=False):
        return [(torch.zeros(4, 1), torch.zeros(4))]

    def validation_step(self, batch):
        return {"loss": torch.tensor(self.initial_loss)}


def _run_stopping(initial_loss, losses, grad_norms=None, **params):
    """Epochs 1, 2, ... with these validation losses; the weight of the module
    is the epoch number. Returns (epochs run, weight restored at the end)."""
    from skgesture._nn._training import _MatlabStopping

    stop = _MatlabStopping(**params)
    net = _FakeNet(initial_loss)
    with torch.no_grad():
        net.module_.weight.fill_(0.0)  # the initial weights
    stop.on_train_begin(net)
    epochs = 0
    try:
        for epoch, loss in enumerate(losses, start=1):
            stop.on_epoch_begin(net, dataset_train=object(), dataset_valid=object())
            with torch.no_grad():
                net.module_.weight.fill_(float(epoch))
            if grad_norms is not None:
                net.optimizer_.grad_norm = grad_norms[epoch - 1]
            net.history.append({"epoch": epoch, "valid_loss": loss})
            epochs = epoch
            stop.on_epoch_end(net)
    except KeyboardInterrupt:  # skorch's clean stop
        pass
    stop.on_train_end(net)
    return epochs, net.module_.weight.detach().item()


def test_validation_stop_after_six_failures_by_default():
    # best at epoch 1, then worse: stops at the 6th failure (MATLAB max_fail 6)
    epochs, kept = _run_stopping(1.0, [0.5] + [0.6] * 20)
    assert (epochs, kept) == (7, 1.0)
    # an equal loss is not a failure
    epochs, _ = _run_stopping(1.0, [0.5] + [0.5] * 3 + [0.6] * 20)
    assert epochs == 10
    assert TorchMLPClassifier().max_fail == 6


def test_validation_stop_starts_from_the_initial_weights():
    # MATLAB's best starts as the initial network and its validation loss: if
    # no epoch beats it, training stops after 6 failures and restores it
    epochs, kept = _run_stopping(0.5, [0.6, 0.7] + [0.8] * 20)
    assert (epochs, kept) == (6, 0.0)
    # a first epoch that improves on the initial loss is kept as before
    epochs, kept = _run_stopping(0.7, [0.6] + [0.8] * 20)
    assert (epochs, kept) == (7, 1.0)


def test_min_grad_stop_at_1e_6_by_default():
    losses = [1.0 / k for k in range(1, 30)]  # always improving
    norms = [1.0] * 4 + [1e-6] + [1.0] * 30
    assert _run_stopping(2.0, losses, norms)[0] == 5  # ||g|| <= 1e-6 stops
    norms = [1.0] * 4 + [1.01e-6] + [1.0] * 30
    assert _run_stopping(2.0, losses, norms)[0] == len(losses)


def test_max_epochs_defaults_to_trainscg_1000():
    from skgesture._multiscale._classifier import default_window_network
    from skgesture._segmenter import default_frame_network

    assert TorchMLPClassifier().max_epochs == 1000
    assert default_window_network().max_epochs == 1000
    assert default_frame_network().max_epochs == 1000
    X, y = BINARY
    net = _clf(max_epochs=1000, random_state=0).fit(X, y).net_
    assert net.max_epochs == 1000


def test_initial_validation_loss_is_the_recorded_validation_loss():
    # the best-so-far before epoch 1 is measured as skorch records valid_loss:
    # on the validation split, averaged over its samples
    from skorch.dataset import Dataset

    from skgesture._nn._training import _mean_loss

    X, y = BINARY
    clf = _clf(max_epochs=3, random_state=0).fit(X, y)
    net = clf.net_
    target = y.astype(np.float32).reshape(-1, 1)
    _, valid = net.train_split(Dataset(X.astype(np.float32), target))
    p = clf.predict_proba(np.asarray(valid.X))[:, 1]
    t = np.asarray(valid.y)[:, 0]
    expected = -np.mean(t * np.log(p) + (1 - t) * np.log(1 - p))
    assert_allclose(_mean_loss(net, valid), expected, rtol=1e-5)
    best = int(np.argmin(net.history[:, "valid_loss"]))
    assert_allclose(_mean_loss(net, valid), net.history[best, "valid_loss"], rtol=1e-5)


# --------------------------------------------------------------------------------
# Parameter values that used to fail deep inside torch (issue 11), verbose=2
# --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "params, name",
    [
        ({"hidden_layer_sizes": (0,)}, "hidden_layer_sizes"),  # a constant model
        ({"hidden_layer_sizes": (8.7,)}, "hidden_layer_sizes"),  # a torch TypeError
        ({"hidden_layer_sizes": (8, -1), "activations": ("tanh", "tanh")},
         "hidden_layer_sizes"),
        ({"hidden_layer_sizes": (True,)}, "hidden_layer_sizes"),
        ({"activations": ("swish",)}, "activations"),  # a KeyError before
        ({"activations": (None,)}, "activations"),
    ],
)  # fmt: skip
def test_mlp_rejects_bad_layers_as_invalid_parameters(params, name):
    from sklearn.utils._param_validation import InvalidParameterError

    X, y = BINARY
    with pytest.raises(InvalidParameterError, match=f"'{name}' parameter"):
        _clf(**params).fit(X, y)


def test_mlp_verbose_2_prints_one_line_per_epoch(capsys):
    X, y = BINARY
    _clf(max_epochs=3, random_state=0, verbose=2).fit(X, y)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["epoch", "train_loss", "valid_loss", "dur"]
    assert [ln.split()[0] for ln in lines[2:]] == ["1", "2", "3"]


def test_mlp_verbose_1_shows_a_bar_and_0_nothing(capsys):
    X, y = BINARY
    _clf(max_epochs=3, random_state=0).fit(X, y)
    assert capsys.readouterr() == ("", "")
    _clf(max_epochs=3, random_state=0, verbose=1).fit(X, y)
    captured = capsys.readouterr()
    assert captured.out == "" and "epoch" in captured.err


def test_multiclass_loss_is_matlab_crossentropy_over_samples_and_outputs():
    # docs/method.md §8.6.5: perf = sum(-t log y) / numel, samples x outputs
    from skgesture._nn._training import MatlabCrossEntropy, build_net

    rng = np.random.RandomState(0)
    logits = torch.as_tensor(rng.normal(size=(7, 4)))
    target = torch.as_tensor(rng.randint(0, 4, 7))
    y = torch.softmax(logits, dim=1).numpy()
    t = np.eye(4)[target.numpy()]
    matlab = -(t * np.log(y)).sum() / t.size
    assert_allclose(float(MatlabCrossEntropy()(logits, target)), matlab, rtol=1e-12)
    module = {"n_inputs": 2, "n_outputs": 4, "hidden_layer_sizes": (3,),
              "activations": ("tanh",)}  # fmt: skip
    assert build_net(module, loss="multiclass", n_samples=10).criterion is (
        MatlabCrossEntropy
    )
    binary = build_net({**module, "n_outputs": 1}, loss="binary", n_samples=10)
    assert binary.criterion is torch.nn.BCEWithLogitsLoss  # MATLAB's binary form
