"""save_model / load_model: safe model files (skops + safetensors, never pickle)."""

import copy
import hashlib
import io
import json
import pickle
import sys
import zipfile

import joblib
import numpy as np
import pytest
from numpy.testing import assert_array_equal
from sklearn.base import BaseEstimator, TransformerMixin

torch = pytest.importorskip("torch")
pytest.importorskip("skops")
pytest.importorskip("safetensors")

import skgesture  # noqa: E402
from skgesture import (  # noqa: E402
    TorchMLPClassifier,
    load_model,
    make_method_a,
    make_method_b,
    make_method_c,
    save_model,
)
from skgesture._persistence import (  # noqa: E402
    LayoutMismatchError,
    ModelFileError,
    ModelVersionError,
    UntrustedTypesError,
    _find_torch_objects,
    _trusted_type_names,
    model_info,
)
from skgesture.datasets import make_gesture_streams  # noqa: E402


def _tiny_mlp():
    return TorchMLPClassifier(
        hidden_layer_sizes=(4,),
        activations=("tanh",),
        max_epochs=5,
        validation_fraction=0.0,
    )


@pytest.fixture(scope="module")
def data():
    return make_gesture_streams(
        n_sequences=3, n_classes=3, n_gestures=(3, 4), n_subjects=2, random_state=0
    )


def _fit(method, data):
    if method == "C":
        pipe = make_method_c(random_state=0).set_params(
            tagger__hidden_sizes=(4,), tagger__max_epochs=2
        )
    else:
        make = make_method_a if method == "A" else make_method_b
        pipe = make(random_state=0).set_params(
            segmenter__estimator=_tiny_mlp(), classifier__estimator=_tiny_mlp()
        )
    with torch.random.fork_rng(devices=[]):
        return pipe.fit(data.X, data.y)


@pytest.fixture(scope="module")
def fitted(data):
    return {m: _fit(m, data) for m in ("A", "B", "C")}


@pytest.fixture(scope="module")
def saved_b(fitted, tmp_path_factory):
    return save_model(fitted["B"], tmp_path_factory.mktemp("model") / "b.skg")


def _assert_same_predictions(a, b, X):
    for pa, pb in zip(a.predict(X), b.predict(X)):
        assert_array_equal(pa, pb)


def _rewrite(src, dst, *, fix_checksums=True, drop=(), **members):
    """Copy a model file, replacing or adding members (``name=bytes``)."""
    members = {k.replace("__", "."): v for k, v in members.items()}
    with zipfile.ZipFile(src) as zf:
        data = {n: zf.read(n) for n in zf.namelist() if n not in drop}
    data.update(members)
    if fix_checksums and "manifest.json" in data:
        manifest = json.loads(data["manifest.json"])
        for name in manifest["sha256"]:
            if name in data:
                manifest["sha256"][name] = hashlib.sha256(data[name]).hexdigest()
        data["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(dst, "w") as zf:
        for name, blob in data.items():
            zf.writestr(name, blob)
    return dst


def _edit_manifest(src, dst, **changes):
    with zipfile.ZipFile(src) as zf:
        manifest = json.loads(zf.read("manifest.json"))
    manifest.update(changes)
    return _rewrite(
        src, dst, fix_checksums=False, manifest__json=json.dumps(manifest).encode()
    )


class _Boom:
    """Unpickling this runs ``open(marker, "w")``: evidence that pickle ran."""

    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (open, (str(self.marker), "w"))


# -- round trips -------------------------------------------------------------------


@pytest.mark.parametrize("method", ["A", "B", "C"])
def test_round_trip_gives_identical_predictions(method, fitted, data, tmp_path):
    model = fitted[method]
    path = save_model(model, tmp_path / "model.skg")
    loaded = load_model(path)
    assert loaded is not model
    _assert_same_predictions(model, loaded, data.X)
    last, loaded_last = model.steps[-1][1], loaded.steps[-1][1]
    assert_array_equal(last.classes_, loaded_last.classes_)
    assert loaded.get_params(deep=False).keys() == model.get_params(deep=False).keys()
    if method == "C":
        D = model[:-1].transform(data.X)
        for a, b in zip(last.predict_proba(D), loaded_last.predict_proba(D)):
            assert_array_equal(a, b)
        # the training history travels with the weights
        assert len(loaded_last.net_.history) == len(last.net_.history) == 2


@pytest.mark.parametrize("features", ["descriptor", "descriptor+joints"])
def test_round_trip_recommended(data, tmp_path, features):
    if not hasattr(skgesture, "make_recommended"):
        pytest.skip("skgesture.make_recommended does not exist yet (lead's tagger)")
    pipe = skgesture.make_recommended(features=features, random_state=0)
    tagger = pipe.steps[-1][1]
    tiny = {
        k: v
        for k, v in {"hidden_sizes": (4,), "max_epochs": 2}.items()
        if k in tagger.get_params()
    }
    pipe.set_params(**{f"{pipe.steps[-1][0]}__{k}": v for k, v in tiny.items()})
    with torch.random.fork_rng(devices=[]):
        pipe.fit(data.X, data.y)
    path = save_model(pipe, tmp_path / "rec.skg")
    loaded = load_model(path)
    _assert_same_predictions(pipe, loaded, data.X)
    # The manifest says what the model reads (it said null before).
    assert model_info(path)["input"]["layout"] == "kinect_v1"
    joints = pipe.get_params()["features__descriptor__joints" if "+" in features
                               else "features__joints"]  # fmt: skip
    assert model_info(path)["input"]["joints"] == joints
    with pytest.raises(ValueError, match="unknown layout"):
        load_model(path, layout="kinect2")


def test_round_trip_with_a_synthetic_background(data, tmp_path):
    # the background object travels with the model (a trusted type), and the
    # per-class lengths the default decoding reads come back with the tagger
    pipe = skgesture.make_recommended(background="synthetic", random_state=0)
    pipe.set_params(
        tagger__hidden_sizes=(8,), tagger__tcn_layers=2, tagger__tcn_stages=1,
        tagger__max_epochs=1, tagger__steps_per_epoch=2, tagger__crop_length=32,
        tagger__fit_threads=1,
    )  # fmt: skip
    with torch.random.fork_rng(devices=[]):
        pipe.fit(data.X, data.y)
    loaded = load_model(save_model(pipe, tmp_path / "bg.skg"))
    assert loaded.background.get_params() == pipe.background.get_params()
    assert_array_equal(loaded[-1].class_lengths_, pipe[-1].class_lengths_)
    _assert_same_predictions(pipe, loaded, data.X)


def test_bare_net_with_tensor_and_array_parameters(tmp_path):
    # A skorch net given directly, with a tensor among its criterion arguments
    # and an array among its attributes: both go to safetensors and come back.
    from skorch import NeuralNet

    from skgesture._nn._modules import MLPModule

    rng = np.random.RandomState(0)
    X = rng.normal(size=(40, 3)).astype(np.float32)
    y = (X[:, 0] > 0).astype(np.int64)
    net = NeuralNet(
        MLPModule,
        module__n_inputs=3,
        module__n_outputs=2,
        module__hidden_layer_sizes=(5,),
        module__activations=("relu",),
        criterion=torch.nn.CrossEntropyLoss,
        criterion__weight=torch.tensor([1.0, 3.0]),
        max_epochs=3,
        train_split=None,
        verbose=0,
    )
    with torch.random.fork_rng(devices=[]):
        net.fit(X, y)
    net.feature_mean_ = X.mean(axis=0)
    loaded = load_model(save_model(net, tmp_path / "net.skg"))
    assert isinstance(loaded, NeuralNet) and loaded is not net
    assert_array_equal(loaded.predict(X), net.predict(X))
    assert_array_equal(loaded.criterion_.weight, torch.tensor([1.0, 3.0]))
    assert_array_equal(loaded.feature_mean_, net.feature_mean_)


def test_save_leaves_the_estimator_untouched(fitted, tmp_path):
    model = fitted["C"]
    net = model.named_steps["tagger"].net_
    state = {k: v.clone() for k, v in net.module_.state_dict().items()}
    save_model(model, tmp_path / "c.skg")
    assert model.named_steps["tagger"].net_ is net
    for k, v in net.module_.state_dict().items():
        assert_array_equal(v, state[k])


def test_load_leaves_torch_rng_alone(saved_b):
    before = torch.get_rng_state()
    load_model(saved_b)
    assert torch.equal(torch.get_rng_state(), before)


def test_cuda_saved_model_loads_on_cpu(fitted, data, tmp_path):
    # As a GPU-trained model would be: the estimator and its network say "cuda".
    # The weights are stored on the CPU and the network is rebuilt there, so
    # the file loads and predicts on a machine without CUDA.
    model = copy.deepcopy(fitted["C"])
    tagger = model.named_steps["tagger"]
    tagger.set_params(device="cuda")
    tagger.net_.device = "cuda"
    path = save_model(model, tmp_path / "gpu.skg")
    assert model_info(path)["nets"][0]["device"] == "cuda"
    loaded = load_model(path)
    net = loaded.named_steps["tagger"].net_
    assert net.device == "cpu" and net.saved_device_ == "cuda"
    assert all(p.device.type == "cpu" for p in net.module_.parameters())
    _assert_same_predictions(fitted["C"], loaded, data.X)


def test_joblib_keeps_working_for_trusted_use(fitted, data, tmp_path):
    for method in ("B", "C"):
        path = tmp_path / f"{method}.joblib"
        joblib.dump(fitted[method], path)
        _assert_same_predictions(fitted[method], joblib.load(path), data.X)


def _nets(estimator):
    return [net for net, _ in _find_torch_objects(estimator)[0]]


def _weight_bytes(estimator):
    """Bytes of every network's weights (its module's state dict)."""
    return sum(
        t.nbytes for net in _nets(estimator) for t in net.module_.state_dict().values()
    )


def _holds_training_state(callback):
    """Whether a callback holds tensors (best weights) or an optimizer (a
    learning-rate scheduler's)."""

    def heavy(v):
        if isinstance(v, (torch.Tensor, torch.optim.Optimizer)):
            return True
        if isinstance(v, dict):
            return any(isinstance(t, torch.Tensor) for t in v.values())
        return isinstance(getattr(v, "optimizer", None), torch.optim.Optimizer)

    return any(heavy(v) for v in vars(callback).values())


@pytest.mark.parametrize("method", ["B", "C"])
def test_pickle_leaves_training_state_out(method, data, tmp_path):
    # Networks of 16 units, so that the weights outweigh the rest of the
    # pipeline; SCG (Method B) keeps 6 times their size as optimizer state,
    # and the stopping callbacks a copy of the best weights.
    if method == "B":
        net = {"hidden_layer_sizes": (16,), "activations": ("tanh",), "max_epochs": 10}
        model = make_method_b(random_state=0).set_params(
            segmenter__estimator=TorchMLPClassifier(**net),
            classifier__estimator=TorchMLPClassifier(**net),
        )
    else:
        model = make_method_c(random_state=0).set_params(
            tagger__hidden_sizes=(16,), tagger__max_epochs=2
        )
    with torch.random.fork_rng(devices=[]):
        model.fit(data.X, data.y)
    nets = _nets(model)
    # training state: the optimizer's, and tensors held by the callbacks
    assert nets and all(net.optimizer_.state for net in nets)
    assert all(
        any(_holds_training_state(cb) for _, cb in net.callbacks_) for net in nets
    )
    weights = _weight_bytes(model)
    blob = pickle.dumps(model)
    joblib.dump(model, tmp_path / "model.joblib")
    assert len(blob) <= 2 * weights
    assert (tmp_path / "model.joblib").stat().st_size <= 2 * weights
    assert all(net.optimizer_.state for net in nets)  # the model keeps it
    loaded = pickle.loads(blob)
    _assert_same_predictions(model, loaded, data.X)
    if method == "C":
        for a, b in zip(model.predict_proba(data.X), loaded.predict_proba(data.X)):
            assert_array_equal(a, b)
    for net in _nets(loaded):
        assert not net.optimizer_.state
        # the optimizer drives the module's own parameters, not copies of them
        driven = {id(p) for g in net.optimizer_.param_groups for p in g["params"]}
        assert driven == {id(p) for p in net.module_.parameters()}
        assert not any(_holds_training_state(cb) for _, cb in net.callbacks_)
        assert len(net.history) > 0
    # the copy is fitted again as the original was
    with torch.random.fork_rng(devices=[]):
        loaded.fit(data.X, data.y)
    _assert_same_predictions(model, loaded, data.X)


def test_unpickled_network_can_continue_training():
    # warm start: the weights are kept, the optimizer starts afresh
    rng = np.random.RandomState(0)
    X = rng.normal(size=(60, 3))
    y = (X[:, 0] > 0).astype(int)
    clf = _tiny_mlp().set_params(random_state=0)
    with torch.random.fork_rng(devices=[]):
        clf.fit(X, y)
    copy_ = pickle.loads(pickle.dumps(clf))
    before = [p.detach().clone() for p in copy_.net_.module_.parameters()]
    with torch.random.fork_rng(devices=[]):
        copy_.net_.partial_fit(X.astype(np.float32), y.astype(np.float32)[:, None])
    assert len(copy_.net_.history) > len(clf.net_.history)
    after = list(copy_.net_.module_.parameters())
    assert any(not torch.equal(a, b) for a, b in zip(before, after))


def test_model_info_records_version_layout_and_metadata(fitted, tmp_path):
    path = save_model(
        fitted["B"], tmp_path / "b.skg", metadata={"target_names": ["a", "b", "c"]}
    )
    info = model_info(path)
    assert info["skgesture_version"] == skgesture.__version__
    assert info["input"] == {
        "frame_shape": [20, 3],
        "layout": "kinect_v1",
        "joints": "paper11",
        "fps": 30.0,  # GesturePipeline's default training rate
    }
    assert info["classes"] == [1, 2, 3]
    assert info["metadata"] == {"target_names": ["a", "b", "c"]}
    assert len(info["nets"]) == 4  # segmenter + one network per time scale


def test_an_existing_file_is_refused_unless_overwrite(saved_b, fitted):
    before = saved_b.read_bytes()
    with pytest.raises(FileExistsError, match="exists"):
        save_model(fitted["B"], saved_b)  # the default, as the CLI
    with pytest.raises(FileExistsError, match="exists"):
        save_model(fitted["B"], saved_b, overwrite=False)
    assert saved_b.read_bytes() == before  # nothing lost
    save_model(fitted["B"], saved_b, overwrite=True)
    assert load_model(saved_b) is not None


def test_misspelt_layout_name_is_an_error(saved_b):
    load_model(saved_b, layout="kinect_v1")
    with pytest.raises(
        ValueError, match="unknown layout 'kinect2'; known: .*kinect_v2"
    ):
        load_model(saved_b, layout="kinect2")
    with pytest.raises(LayoutMismatchError, match="kinect_v1"):
        load_model(saved_b, layout="kinect_v2")


# -- never pickle, refuse what is not trusted ------------------------------------


def test_loading_never_unpickles(saved_b, monkeypatch, data, fitted):
    def forbidden(*args, **kwargs):
        raise AssertionError("pickle was called while loading a model file")

    for name in ("load", "loads", "Unpickler"):
        monkeypatch.setattr(pickle, name, forbidden)
    monkeypatch.setattr(torch, "load", forbidden)
    monkeypatch.setattr(joblib, "load", forbidden)
    loaded = load_model(saved_b)
    monkeypatch.undo()
    _assert_same_predictions(fitted["B"], loaded, data.X)


def test_smuggled_pickle_member_is_refused(saved_b, tmp_path):
    marker = tmp_path / "pwned"
    bad = _rewrite(
        saved_b, tmp_path / "bad.skg", payload__pkl=pickle.dumps(_Boom(marker))
    )
    with pytest.raises(ModelFileError, match="unexpected payload.pkl"):
        load_model(bad)
    assert not marker.exists()


def test_pickle_in_place_of_the_estimator_is_refused(saved_b, tmp_path):
    marker = tmp_path / "pwned"
    bad = _rewrite(
        saved_b, tmp_path / "bad.skg", estimator__skops=pickle.dumps(_Boom(marker))
    )
    with pytest.raises(ModelFileError, match="unreadable estimator"):
        load_model(bad)
    assert not marker.exists()


def test_pickle_in_place_of_the_weights_is_refused(saved_b, tmp_path):
    marker = tmp_path / "pwned"
    bad = _rewrite(
        saved_b, tmp_path / "bad.skg", weights__safetensors=pickle.dumps(_Boom(marker))
    )
    with pytest.raises(ModelFileError, match="unreadable weights"):
        load_model(bad)
    assert not marker.exists()


def _edit_schema(src, dst, edit):
    """Copy a model file, passing the skops schema (a dict) through ``edit``."""
    with zipfile.ZipFile(src) as zf:
        inner = zf.read("estimator.skops")
    with zipfile.ZipFile(io.BytesIO(inner)) as zf:
        files = {n: zf.read(n) for n in zf.namelist()}
    schema = json.loads(files["schema.json"])
    edit(schema)
    files["schema.json"] = json.dumps(schema).encode()
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as zf:
        for name, blob in files.items():
            zf.writestr(name, blob)
    return _rewrite(src, dst, estimator__skops=buffer.getvalue())


def _nodes(schema):
    """Every node of a skops schema that names a class."""
    stack = [schema]
    while stack:
        node = stack.pop()
        if isinstance(node, list):
            stack.extend(node)
        elif isinstance(node, dict):
            if isinstance(node.get("__module__"), str):
                yield node
            stack.extend(node.values())


def _renamer(old_class, module, name):
    def edit(schema):
        found = [n for n in _nodes(schema) if n["__class__"] == old_class]
        assert found, f"no {old_class} in the schema"
        for node in found:
            node["__module__"], node["__class__"] = module, name

    return edit


@pytest.mark.parametrize(
    "module, name",
    [
        ("os", "system"),
        # skgesture classes outside the public API table: a private estimator,
        # a public class that is no estimator, a module reached through an
        # old 0.1 path, a private base class reached through one
        ("skgesture._nn._training", "FramewiseNetwork"),
        ("skgesture", "StreamingRecognizer"),
        ("skgesture._networks", "copy"),
        ("skgesture._tagger", "_BaseTagger"),
    ],
)
def test_untrusted_type_in_the_schema_is_refused(saved_b, tmp_path, module, name):
    # An attacker rewrites the skops schema to build another type instead of a
    # PoseDescriptor (and fixes the checksums): refused before anything is built.
    bad = _edit_schema(
        saved_b, tmp_path / "bad.skg", _renamer("PoseDescriptor", module, name)
    )
    with pytest.raises(UntrustedTypesError, match=f"{module}.{name}") as err:
        load_model(bad)
    assert err.value.types == [f"{module}.{name}"]


def test_trusted_types_are_the_public_api_and_what_it_holds():
    from sklearn.base import BaseEstimator

    from skgesture import layouts
    from skgesture._legacy import MOVED
    from skgesture._persistence import _NetSlot, _TensorSlot

    public = {
        getattr(skgesture, n)
        for n in skgesture._LAZY
        if isinstance(getattr(skgesture, n), type)
        and issubclass(getattr(skgesture, n), BaseEstimator)
    }
    assert {TorchMLPClassifier, skgesture.PoseDescriptor} <= public
    support = {layouts.DescriptorJoints, layouts.SkeletonLayout, _NetSlot, _TensorSlot}
    support.add(skgesture.datasets.SyntheticBackground)  # a pipeline's background
    support.add(skgesture.utils.PoseNovelty)  # a SequenceTagger's novelty_
    names = _trusted_type_names()
    resolved = {}
    for name in names:
        module, _, attr = name.rpartition(".")
        __import__(module)
        resolved[name] = getattr(sys.modules[module], attr)
    # every trusted name imports a class of the table or one it holds, and
    # every class of the table is trusted under its public name
    assert set(resolved.values()) == public | support
    for cls in public:
        assert f"skgesture.{cls.__name__}" in names
        assert f"{cls.__module__}.{cls.__name__}" in names
    # the paths of 0.1 stay trusted for old files: the moved modules that held
    # estimators, and the modules that became packages
    assert {n.rpartition(".")[0] for n in names if n.rpartition(".")[0] in MOVED} == {
        "skgesture._tagger",
        "skgesture._bilstm",
        "skgesture._mlp",
    }
    assert {
        "skgesture._descriptor.PoseDescriptor",
        "skgesture._tagger.VotingTagger",
    } < (names)
    # nothing else of skgesture is
    assert "skgesture._nn._training.FramewiseNetwork" not in names
    assert "skgesture.streaming.StreamingRecognizer" not in names


def test_a_file_outlives_the_module_that_defined_its_classes(
    saved_b, fitted, data, tmp_path, monkeypatch
):
    # As after a move: the module that defines PoseDescriptor can no longer be
    # imported. The file names skgesture.PoseDescriptor, and loads.
    _trusted_type_names()  # cached as in any session, before the module goes
    monkeypatch.setitem(sys.modules, "skgesture._descriptor._estimator", None)
    loaded = load_model(saved_b)
    _assert_same_predictions(fitted["B"], loaded, data.X)
    # a file naming the private path (as files did before) breaks on the move
    private = _edit_schema(
        saved_b,
        tmp_path / "private.skg",
        _renamer(
            "PoseDescriptor", "skgesture._descriptor._estimator", "PoseDescriptor"
        ),
    )
    with pytest.raises(ModelFileError):
        load_model(private)


class _Doubler(TransformerMixin, BaseEstimator):
    """A step of the user's own, unknown to skops and skgesture."""

    def fit(self, X, y=None):
        self.n_seen_ = len(X)
        return self

    def transform(self, X):
        return [2 * np.asarray(x) for x in X]


def test_user_types_load_only_when_trusted(tmp_path):
    from sklearn.pipeline import Pipeline

    pipe = Pipeline([("double", _Doubler())]).fit([np.ones(2)])
    path = save_model(pipe, tmp_path / "user.skg")
    name = f"{__name__}._Doubler"
    with pytest.raises(UntrustedTypesError, match="trusted=") as err:
        load_model(path)
    assert err.value.types == [name]
    loaded = load_model(path, trusted=[name])
    assert_array_equal(loaded.transform([np.ones(2)])[0], [2.0, 2.0])


def test_network_class_outside_skgesture_is_refused(saved_b, tmp_path):
    with zipfile.ZipFile(saved_b) as zf:
        manifest = json.loads(zf.read("manifest.json"))
    manifest["nets"][0]["params"]["module"] = {"__class__": "os:system"}
    bad = _rewrite(
        saved_b, tmp_path / "bad.skg", manifest__json=json.dumps(manifest).encode()
    )
    with pytest.raises(ModelFileError, match="only classes from skgesture"):
        load_model(bad)
    manifest["nets"][0]["params"]["module"] = {"__class__": "torch.nn:Linear"}
    bad = _rewrite(
        saved_b, tmp_path / "bad2.skg", manifest__json=json.dumps(manifest).encode()
    )
    with pytest.raises(ModelFileError, match="only classes from skgesture"):
        load_model(bad)


class _UserModule(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.lin = torch.nn.Linear(2, 2)

    def forward(self, X):
        return self.lin(X)


def test_save_refuses_a_network_it_could_not_rebuild(tmp_path):
    from skorch import NeuralNet

    net = NeuralNet(_UserModule, criterion=torch.nn.CrossEntropyLoss).initialize()
    with pytest.raises(ValueError, match="not a class of skgesture"):
        save_model(net, tmp_path / "user.skg")
    assert not (tmp_path / "user.skg").exists()


# -- damaged and foreign files -------------------------------------------------------


def test_truncated_file_gives_a_clear_error(saved_b, tmp_path):
    blob = saved_b.read_bytes()
    bad = tmp_path / "truncated.skg"
    bad.write_bytes(blob[: len(blob) // 2])
    with pytest.raises(ModelFileError, match="damaged"):
        load_model(bad)


def test_corrupt_bytes_give_a_clear_error(saved_b, tmp_path):
    blob = bytearray(saved_b.read_bytes())
    with zipfile.ZipFile(saved_b) as zf:
        info = zf.getinfo("weights.safetensors")
    middle = info.header_offset + 30 + len(info.filename) + info.compress_size // 2
    blob[middle] ^= 0xFF
    bad = tmp_path / "corrupt.skg"
    bad.write_bytes(bytes(blob))
    with pytest.raises(ModelFileError, match="damaged"):
        load_model(bad)


def test_tampered_member_fails_its_checksum(saved_b, tmp_path):
    with zipfile.ZipFile(saved_b) as zf:
        weights = zf.read("weights.safetensors")
    bad = _rewrite(
        saved_b,
        tmp_path / "tampered.skg",
        fix_checksums=False,
        weights__safetensors=weights[:-1] + b"\x00",
    )
    with pytest.raises(ModelFileError, match="weights.safetensors fails its checksum"):
        load_model(bad)


@pytest.mark.parametrize(
    "content, match",
    [
        (b"class,start,end\n1,2,3\n", "not a skgesture model file"),
        (b"", "not a skgesture model file"),
    ],
)
def test_foreign_file_gives_a_clear_error(tmp_path, content, match):
    path = tmp_path / "model.skg"
    path.write_bytes(content)
    with pytest.raises(ModelFileError, match=match):
        load_model(path)


def test_other_zip_is_not_a_model_file(tmp_path):
    path = tmp_path / "other.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("readme.txt", "hello")
    with pytest.raises(ModelFileError, match="missing manifest.json"):
        load_model(path)


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_model(tmp_path / "nope.skg")


# -- version and layout ----------------------------------------------------------------


def test_other_version_is_refused_unless_allowed(saved_b, tmp_path, data, fitted):
    old = _edit_manifest(saved_b, tmp_path / "old.skg", skgesture_version="9.3.1")
    with pytest.raises(ModelVersionError, match=r"skgesture 9\.3\.1.*allow_version"):
        load_model(old)
    with pytest.warns(UserWarning, match="9.3.1"):
        loaded = load_model(old, allow_version_mismatch=True)
    _assert_same_predictions(fitted["B"], loaded, data.X[:1])


def test_newer_format_is_refused(saved_b, tmp_path):
    new = _edit_manifest(saved_b, tmp_path / "new.skg", format_version=99)
    with pytest.raises(ModelVersionError, match="format 99"):
        load_model(new, allow_version_mismatch=True)


def test_layout_mismatch_is_refused(saved_b):
    assert load_model(saved_b, layout="kinect_v1") is not None
    assert load_model(saved_b, layout=(20, 3)) is not None
    with pytest.raises(LayoutMismatchError, match=r"\(20, 3\).*\(33, 3\)"):
        load_model(saved_b, layout=(33, 3))
    with pytest.raises(LayoutMismatchError, match="'kinect_v1'.*'mediapipe_pose'"):
        load_model(saved_b, layout="mediapipe_pose")
