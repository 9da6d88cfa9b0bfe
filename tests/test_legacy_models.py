"""Models written by skgesture 0.1 load and predict as they did; new files name
classes by their public names.

``tests/data/legacy/`` holds tiny models written at commit 59fafcb, before the
package was restructured, as ``save_model`` files and joblib pickles, with their
test input and every output they gave then (``inputs_expected.npz``; its
README.md describes the keys and ``make_legacy_fixtures.py`` how they were made).
The files name the modules of 0.1 (``skgesture._tagger``, ``skgesture._networks``,
...), which ``skgesture._legacy`` keeps importable.
"""

# SPDX-License-Identifier: BSD-3-Clause

import io
import json
import warnings
import zipfile
from pathlib import Path

import joblib
import numpy as np
import pytest
import skops.io as sio

import skgesture
from skgesture import (
    TorchMLPClassifier,
    load_model,
    make_method_b,
    make_method_c,
    save_model,
)
from skgesture._persistence import _major_minor, model_info
from skgesture.datasets import make_gesture_streams
from skgesture.streaming import StreamingRecognizer

FIXTURES = Path(__file__).resolve().parent / "data" / "legacy"
# The fixtures were written with scikit-learn 1.9.1 and numpy 2.4.6
# (tests/data/legacy/README.md): older versions of those libraries cannot read
# their estimators (numpy < 2 has no numpy._core; scikit-learn refuses an
# estimator pickled by a later version), whatever skgesture does. `make
# test-min` runs on the declared floors, so there these tests skip.
WRITTEN_WITH = {"sklearn": (1, 9), "numpy": (2, 0)}


def _older_libraries():
    import sklearn

    have = {"sklearn": sklearn.__version__, "numpy": np.__version__}
    old = [
        f"{name} {version}"
        for name, version in have.items()
        if tuple(int(v) for v in version.split(".")[:2]) < WRITTEN_WITH[name]
    ]
    return ", ".join(old)


needs_fixture_libraries = pytest.mark.skipif(
    bool(_older_libraries()),
    reason=f"the 0.1 fixtures were written with scikit-learn 1.9 and numpy 2; "
    f"this environment has {_older_libraries()}, which cannot read them",
)
NAMES = ("method_b", "recommended", "method_c")
# What inputs_expected.npz stores for each model (README.md); checked, so that a
# quantity can neither go missing from the file nor be skipped here.
QUANTITIES = {
    "method_b": {"predict", "predict_segments", "segmenter_decision", "stream"},
    "recommended": {"predict", "predict_proba", "predict_segments", "stream"},
    "method_c": {"predict", "predict_proba", "predict_segments", "stream"},
}


@pytest.fixture(scope="module")
def stored():
    """``(inputs, {model: {quantity: list of arrays}})`` of inputs_expected.npz."""
    with np.load(FIXTURES / "inputs_expected.npz", allow_pickle=False) as npz:
        arrays = {key: npz[key] for key in npz.files}
    X = [arrays[f"X__{i}"] for i in range(int(arrays["n_test"]))]
    expected = {}
    for key, value in arrays.items():
        name, _, rest = key.partition("__")
        if name in NAMES:
            quantity, _, i = rest.rpartition("__")
            expected.setdefault(name, {}).setdefault(quantity, {})[int(i)] = value
    expected = {
        name: {q: [d[i] for i in sorted(d)] for q, d in by_q.items()}
        for name, by_q in expected.items()
    }
    return X, expected


def _load_skg(path):
    """``load_model`` of a fixture, allowing the version mismatch if there is one."""
    saved = model_info(path)["skgesture_version"]
    if _major_minor(saved) == _major_minor(skgesture.__version__):
        with warnings.catch_warnings():
            warnings.simplefilter("error", UserWarning)  # no version warning
            return load_model(path, layout=(20, 3))
    with pytest.warns(UserWarning, match=f"written by skgesture {saved}"):
        return load_model(path, layout=(20, 3), allow_version_mismatch=True)


def _outputs(model, X, quantities):
    """Each of ``quantities`` of ``model`` on ``X``, as README.md defines them."""
    out = {}
    last = model.steps[-1][1]
    if "predict" in quantities:
        out["predict"] = model.predict(X)
    if "predict_proba" in quantities:
        out["predict_proba"] = model.predict_proba(X)
    if "predict_segments" in quantities:
        out["predict_segments"] = last.predict_segments(model[:-1].transform(X))
    if "segmenter_decision" in quantities:
        segmenter = model.named_steps["segmenter"]
        out["segmenter_decision"] = segmenter.decision_function(model[:1].transform(X))
    if "stream" in quantities:
        recognizer = StreamingRecognizer(model)
        out["stream"] = [
            np.array(
                [(e.label, e.start, e.end, e.confidence, e.emitted_at) for e in events],
                dtype=np.float64,
            ).reshape(-1, 5)
            for events in (recognizer.recognize(x) for x in X)
        ]
    return {q: [np.asarray(a) for a in arrays] for q, arrays in out.items()}


def test_the_fixtures_are_complete_and_from_0_1(stored):
    X, expected = stored
    assert len(X) == 3 and all(x.shape[1:] == (20, 3) for x in X)
    assert {name: set(q) for name, q in expected.items()} == QUANTITIES
    for name in NAMES:
        assert model_info(FIXTURES / f"{name}.skg")["skgesture_version"] == "0.1.0.dev0"
        for arrays in expected[name].values():
            assert len(arrays) == len(X)
    # they name the module paths of 0.1, which no longer exist as modules
    with zipfile.ZipFile(FIXTURES / "method_b.skg") as zf:
        types = sio.get_untrusted_types(data=zf.read("estimator.skops"))
        manifest = json.loads(zf.read("manifest.json"))
    assert "skgesture._mlp.TorchMLPClassifier" in types
    assert manifest["nets"][0]["params"]["module"] == {
        "__class__": "skgesture._networks:MLPModule"
    }
    with zipfile.ZipFile(FIXTURES / "method_c.skg") as zf:
        types = sio.get_untrusted_types(data=zf.read("estimator.skops"))
    assert "skgesture._bilstm.BiLSTMTagger" in types
    assert not (Path(skgesture.__file__).parent / "_tagger.py").exists()


# Models whose networks are TorchMLPClassifiers: since 0.2 their forward pass
# runs in numpy (skgesture._nn._fast.MLPProba), equal to 0.1's torch pass to
# float32 rounding; everything decided from it (labels, segments) is identical.
FLOAT32_ROUNDING = {"method_b"}
# The recommended model's stream runs its convolutions on trailing windows, whose
# float32 sums the CPU's kernels may order otherwise than the whole-sequence pass
# of 0.1: its events are identical, their confidences equal to float32 rounding
# (exact on the machine that wrote the fixtures, 6e-8 apart on an AMD EPYC).
STREAM_ROUNDING = {"recommended"}
# The recommended model's network is an MS-TCN: since 2026-12-06 its layers compute
# each dilated convolution as one matrix product of the shifted inputs (the
# same Conv1d parameters) rather than torch's conv1d, so its probabilities
# equal 0.1's to float32 rounding, and its labels and segments are identical.
TCN_ROUNDING = {"recommended"}
# Method C's BiLSTM runs torch's CPU LSTM kernels, whose float32 sums follow the
# CPU's instruction set: on an AVX-512 Xeon (2026-12-07) its probabilities were
# 1.8e-7 from 0.1's and its events' confidences 2.3e-8, its labels identical.
CPU_ROUNDING = {"method_c"}
# the columns of those outputs that are probabilities (segments and events:
# class, start, end, confidence[, emitted_at]; the segmenter's decision and
# predict_proba: all, None)
ROUNDED_COLUMNS = {
    "predict_segments": [3],
    "stream": [3],
    "segmenter_decision": [0],
    "predict_proba": None,
}


def _load_fixture(name, kind):
    path = FIXTURES / f"{name}.{kind}"
    return _load_skg(path) if kind == "skg" else joblib.load(path)


every_fixture = pytest.mark.parametrize(
    ("name", "kind"), [(n, k) for n in NAMES for k in ("skg", "joblib")]
)


@needs_fixture_libraries
@every_fixture
def test_legacy_model_gives_identical_outputs(name, kind, stored):
    X, expected = stored
    model = _load_fixture(name, kind)
    got = _outputs(model, X, QUANTITIES[name])
    assert set(got) == QUANTITIES[name]
    for quantity, want in expected[name].items():
        assert len(got[quantity]) == len(want)
        for i, (a, b) in enumerate(zip(got[quantity], want)):
            where = f"{name}.{kind}: {quantity} of sequence {i} differs from 0.1's"
            assert a.shape == b.shape, where
            rounded_here = (
                name in FLOAT32_ROUNDING
                or (name in STREAM_ROUNDING and quantity == "stream")
                or name in TCN_ROUNDING
                or name in CPU_ROUNDING
            )
            if rounded_here and quantity in ROUNDED_COLUMNS:
                # labels and frames exactly; probabilities and confidences to
                # float32 rounding
                rounded = ROUNDED_COLUMNS[quantity]
                exact = np.ones(a.shape[-1:] if a.ndim > 1 else (1,), bool)
                exact[slice(None) if rounded is None else rounded] = False
                if a.ndim > 1:
                    assert np.array_equal(a[:, exact], b[:, exact]), where
                np.testing.assert_allclose(a, b, rtol=0, atol=1e-6, err_msg=where)
            else:
                assert np.array_equal(a, b), where


@needs_fixture_libraries
@every_fixture
def test_legacy_model_can_be_tuned_and_cloned(name, kind, stored):
    # the parameters added since 0.1 come back at their defaults, which keep
    # 0.1's behaviour: get_params, set_params and clone work (GridSearchCV over
    # a loaded model's decision parameters), and the labels are 0.1's
    from sklearn.base import clone

    model = _load_fixture(name, kind)
    params = model.get_params(deep=False)
    assert clone(model).get_params(deep=False).keys() == params.keys()
    model.set_params(**params)
    X, expected = stored
    got = _outputs(model, X, {"predict"})["predict"]
    for i, (a, b) in enumerate(zip(got, expected[name]["predict"])):
        assert np.array_equal(a, b), f"{name}.{kind}: sequence {i}"


def _schema(path):
    with zipfile.ZipFile(path) as zf:
        inner = zf.read("estimator.skops")
    with zipfile.ZipFile(io.BytesIO(inner)) as zf:
        return json.loads(zf.read("schema.json"))


def _class_nodes(schema):
    stack = [schema]
    while stack:
        node = stack.pop()
        if isinstance(node, list):
            stack.extend(node)
        elif isinstance(node, dict):
            if isinstance(node.get("__module__"), str):
                yield node["__module__"], node["__class__"]
            stack.extend(node.values())


@pytest.mark.parametrize("fitted", [False, True])
def test_new_files_record_public_names(fitted, tmp_path):
    data = make_gesture_streams(
        n_sequences=3, n_classes=3, n_gestures=(3, 4), n_subjects=2, random_state=0
    )
    X = data.X
    public = {n for n in skgesture._LAZY if isinstance(getattr(skgesture, n), type)}
    models = {
        "b": make_method_b(random_state=0),
        "c": make_method_c(random_state=0).set_params(
            tagger__hidden_sizes=(4,), tagger__max_epochs=1
        ),
        "rec": skgesture.make_recommended(random_state=0).set_params(
            tagger__hidden_sizes=(4,), tagger__max_epochs=1, tagger__steps_per_epoch=2
        ),
        "rec_joints": skgesture.make_recommended(
            features="joints", random_state=0
        ).set_params(
            tagger__hidden_sizes=(4,), tagger__max_epochs=1, tagger__steps_per_epoch=2
        ),
    }
    if fitted:  # the taggers only: Method B's unfitted file has its classes
        del models["b"]
    seen = set()
    for key, model in models.items():
        if fitted:
            model.fit(X, data.y)
        path = save_model(model, tmp_path / f"{key}.skg")
        nodes = set(_class_nodes(_schema(path)))
        ours = {(m, c) for m, c in nodes if m.split(".")[0] == "skgesture"}
        for module, cls in ours:
            if cls in public:
                assert module == "skgesture", f"{module}.{cls} in {key}.skg"
            else:  # private helpers keep their path; public subpackages theirs
                assert module in (
                    "skgesture._persistence",
                    "skgesture.datasets",  # SyntheticBackground, the negatives
                    "skgesture.layouts",
                    "skgesture.utils",
                )
        seen |= {c for m, c in ours if m == "skgesture"}
        text = json.dumps(_schema(path))
        assert "skgesture._descriptor" not in text and "skgesture._taggers" not in text
        loaded = load_model(path)
        assert type(loaded.steps[-1][1]) is type(model.steps[-1][1])
        if fitted:
            for a, b in zip(model.predict(X), loaded.predict(X)):
                np.testing.assert_array_equal(a, b)
    expected = {"PoseDescriptor", "BiLSTMTagger", "SequenceTagger", "JointFeatures"}
    if not fitted:
        expected |= {
            "ActivitySegmenter",
            "DynamicPoseWindow",
            "MultiScaleClassifier",
            "TorchMLPClassifier",
        }
    assert expected <= seen
    # the manifest names the estimator's class the same way
    assert model_info(path)["estimator"] == "skgesture:GesturePipeline"
    path = save_model(TorchMLPClassifier(), tmp_path / "mlp.skg")
    assert model_info(path)["estimator"] == "skgesture:TorchMLPClassifier"
    assert set(_class_nodes(_schema(path))) >= {("skgesture", "TorchMLPClassifier")}
