"""Loading a model file for prediction imports only what prediction needs.

A Method A or B model predicts with its MLPs in numpy (``MLPProba``): loading
and predicting never import torch, skorch or safetensors' torch part, and the
networks are built (``DeferredNet``) only when something else asks for them.
"""

import copy
import pickle
import subprocess
import sys
import textwrap

import joblib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

torch = pytest.importorskip("torch")
pytest.importorskip("skops")
pytest.importorskip("safetensors")

from skorch import NeuralNet  # noqa: E402

import skgesture  # noqa: E402
from skgesture import (  # noqa: E402
    TorchMLPClassifier,
    load_model,
    make_method_b,
    save_model,
)
from skgesture._nn._deferred import DeferredNet  # noqa: E402
from skgesture._nn._fast import ACTIVATIONS, MLPProba  # noqa: E402
from skgesture._persistence import (  # noqa: E402
    _is_trusted_name,
    _trusted_type_names,
)
from skgesture.datasets import make_gesture_streams  # noqa: E402


def _tiny_mlp(**kw):
    params = {"hidden_layer_sizes": (4,), "activations": ("tanh",), "max_epochs": 5}
    params["validation_fraction"] = 0.0
    return TorchMLPClassifier(**{**params, **kw})


@pytest.fixture(scope="module")
def data():
    return make_gesture_streams(
        n_sequences=3, n_classes=3, n_gestures=(3, 4), n_subjects=2, random_state=0
    )


@pytest.fixture(scope="module")
def method_b(data):
    pipe = make_method_b(random_state=0).set_params(
        segmenter__estimator=_tiny_mlp(), classifier__estimator=_tiny_mlp()
    )
    with torch.random.fork_rng(devices=[]):
        return pipe.fit(data.X, data.y)


@pytest.fixture(scope="module")
def saved(method_b, tmp_path_factory):
    return save_model(method_b, tmp_path_factory.mktemp("lazy") / "b.skg")


def _nets(model):
    clf = model.named_steps["classifier"]
    return [model.named_steps["segmenter"].estimator_.net_] + [
        est.net_ for est in clf.estimators_
    ]


def test_a_method_b_file_loads_and_predicts_without_torch(saved, data, tmp_path):
    X = tmp_path / "X.npy"
    np.save(X, data.X[0])
    script = textwrap.dedent(
        f"""
        import sys
        import numpy as np
        from skgesture import load_model
        model = load_model({str(saved)!r})
        labels = model.predict([np.load({str(X)!r})])[0]
        np.save({str(tmp_path / "labels.npy")!r}, labels)
        heavy = [m for m in ("torch", "skorch", "safetensors.torch")
                 if m in sys.modules]
        print("imported:", heavy)
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    ).stdout
    assert "imported: []" in out
    assert_array_equal(np.load(tmp_path / "labels.npy"), load_model(saved).predict(
        [data.X[0]])[0])  # fmt: skip


def test_loaded_networks_are_deferred_and_predict_as_the_fitted_model(
    saved, method_b, data
):
    loaded = load_model(saved)
    nets = _nets(loaded)
    assert all(isinstance(n, DeferredNet) and not n.built for n in nets)
    for a, b in zip(method_b.predict(data.X), loaded.predict(data.X)):
        assert_array_equal(a, b)
    # prediction read only the arrays
    assert not any(n.built for n in nets)


def test_a_deferred_net_is_built_when_torch_is_needed(saved, method_b, data):
    loaded = load_model(saved)
    net = _nets(loaded)[1]
    before = loaded.predict(data.X)
    assert not net.built
    assert len(net.history_) >= 1 and net.built  # any attribute but the arrays
    assert isinstance(net.module_, torch.nn.Module)
    assert isinstance(net.materialize(), NeuralNet)
    assert net.materialize() is net.materialize()  # built once
    for a, b in zip(before, loaded.predict(data.X)):
        assert_array_equal(a, b)


def test_training_a_built_net_further_changes_what_it_predicts(saved, data):
    loaded = load_model(saved)
    clf = loaded.named_steps["classifier"].estimators_[0]
    rows = np.random.default_rng(0).normal(size=(8, clf.n_features_in_))
    before = clf.predict_proba(rows)
    with torch.no_grad():
        for p in clf.net_.module_.parameters():
            p.add_(0.5)
    assert not np.allclose(clf.predict_proba(rows), before)


def test_copies_pickles_and_saves_of_a_loaded_model_hold_skorch_nets(
    saved, method_b, data, tmp_path
):
    loaded = load_model(saved)
    want = method_b.predict(data.X)
    for other in (
        copy.deepcopy(loaded),
        pickle.loads(pickle.dumps(loaded)),
        joblib.load(joblib.dump(loaded, tmp_path / "b.joblib")[0]),
    ):
        assert all(isinstance(n, NeuralNet) for n in _nets(other))
        for a, b in zip(want, other.predict(data.X)):
            assert_array_equal(a, b)
    again = load_model(save_model(loaded, tmp_path / "again.skg"))
    for a, b in zip(want, again.predict(data.X)):
        assert_array_equal(a, b)


def test_a_bare_skorch_net_is_loaded_built(tmp_path):
    rng = np.random.default_rng(0)
    X = rng.normal(size=(40, 3)).astype(np.float32)
    y = (X[:, 0] > 0).astype(np.int64)
    clf = _tiny_mlp().fit(X, y)
    loaded = load_model(save_model(clf.net_, tmp_path / "net.skg"))
    assert isinstance(loaded, NeuralNet)


@pytest.mark.parametrize("activation", sorted(ACTIVATIONS))
@pytest.mark.parametrize("n_classes", [2, 4])
def test_numpy_forward_equals_the_torch_module(activation, n_classes):
    rng = np.random.default_rng(1)
    X = rng.normal(size=(300, 5)).astype(np.float32)
    y = rng.integers(0, n_classes, size=300)
    clf = _tiny_mlp(
        hidden_layer_sizes=(7, 6), activations=(activation, "tanh"), random_state=0
    ).fit(X, y)
    module = clf.net_.module_.eval()
    with torch.inference_mode():
        logits = module(torch.from_numpy(X))
        if n_classes == 2:
            p = torch.sigmoid(logits)[:, 0].numpy().astype(np.float64)
            want = np.column_stack([1 - p, p])
        else:
            want = torch.softmax(logits, dim=1).numpy().astype(np.float64)
    got = clf.predict_proba(X)
    assert got.shape == (300, n_classes) and got.dtype == np.float64
    assert_allclose(got, want, rtol=0, atol=1e-6)
    # the live step's callable is the same computation
    assert_array_equal(MLPProba(clf)(X), got)


def test_numpy_activations_are_the_modules():
    from skgesture._nn._modules import _ACTIVATIONS

    assert set(ACTIVATIONS) == set(_ACTIVATIONS)


def test_a_network_with_a_missing_layer_is_a_clear_error():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(40, 3)).astype(np.float32)
    clf = _tiny_mlp().fit(X, (X[:, 0] > 0).astype(int))
    arrays = {"net.0.weight": np.zeros((4, 3), np.float32)}
    clf.net_ = DeferredNet(arrays, {"module__activations": ("tanh",)}, build=None)
    with pytest.raises(ValueError, match="no layer 'net.0.bias'"):
        clf.predict_proba(X)


def test_trusting_a_name_imports_only_its_module_and_agrees_with_the_table():
    names = _trusted_type_names()
    assert all(_is_trusted_name(n) for n in names)
    for name in (
        "skgesture._nn._training.FramewiseNetwork",
        "skgesture.streaming.StreamingRecognizer",
        "skgesture.nope.Nothing",
        "sklearn.pipeline.Pipeline",
        "builtins.eval",
    ):
        assert not _is_trusted_name(name)
    assert _is_trusted_name("skgesture.TorchMLPClassifier")
    assert hasattr(skgesture, "TorchMLPClassifier")


def test_the_manifest_records_the_training_rate(data, tmp_path):
    from skgesture._persistence import model_info

    pipe = make_method_b(random_state=0).set_params(
        segmenter__estimator=_tiny_mlp(), classifier__estimator=_tiny_mlp()
    )
    with torch.random.fork_rng(devices=[]):
        pipe.fit(data.X, data.y, fps=20.0)
    path = save_model(pipe, tmp_path / "b20.skg")
    assert model_info(path)["input"]["fps"] == 20.0
    assert load_model(path).fps_ == 20.0


def test_a_short_command_line_evaluation_imports_neither_torch_nor_numba(saved):
    """The command line computes the descriptor of a few frames in numpy: loading
    the compiled kernel would cost more than computing them."""
    script = textwrap.dedent(
        f"""
        import sys
        from skgesture._cli import main
        import skgesture._descriptor._compute as compute
        status = main(["evaluate", {str(saved)!r}, "synthetic", "--n-sequences",
                       "2", "--n-classes", "3", "-q"])
        heavy = [m for m in ("torch", "skorch", "numba") if m in sys.modules]
        print("status", status, "imported:", heavy,
              "restored:", compute.USE_COMPILED == compute.USE_COMPILED_DEFAULT)
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    ).stdout
    assert "status 0 imported: [] restored: True" in out, out
