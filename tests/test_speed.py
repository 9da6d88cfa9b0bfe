"""The fast paths give the results of the reference implementations.

* The compiled descriptor kernel (numba, optional) and the numpy implementation
  both reproduce a frozen reference: ``tests/data/descriptor_reference.npz``
  holds inputs and the descriptors computed by the numpy implementation of
  commit eddd87c, before any speed work.
* Lazy windows give the predictions of dense windows.
* ``TorchMLPClassifier(n_threads=...)`` restores torch's thread count.
"""

import warnings
from pathlib import Path

import numpy as np
import pytest
import torch
from numpy.testing import assert_allclose, assert_array_equal

import skgesture
import skgesture._descriptor._compute as descriptor_module
from skgesture import PoseDescriptor
from skgesture.datasets import make_gesture_streams
from skgesture.utils._validation import missing_frames

REFERENCE = Path(__file__).parent / "data" / "descriptor_reference.npz"
CONFIGS = {
    "paper11": {},
    "full20_variant": {
        "joints": "full20",
        "sigma": 1.5,
        "border": "symmetric",
        "link_direction": "simao",
        "fill": "hold",
        "distance_scale": "spine",
    },
}
RTOL = ATOL = 1e-6  # standardised features have unit scale


@pytest.fixture(params=["compiled", "numpy"])
def implementation(request, monkeypatch):
    """Run the test with the compiled kernel, then with numpy."""
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", request.param == "compiled")
    if request.param == "compiled":
        pytest.importorskip("numba")
        assert descriptor_module._compiled_kernel() is not None
    return request.param


def _reference():
    with np.load(REFERENCE) as ref:
        return dict(ref)


@pytest.mark.parametrize("config", sorted(CONFIGS))
def test_descriptor_reproduces_the_frozen_reference(implementation, config):
    ref = _reference()
    X = [ref[f"X{i}"] for i in range(5)]
    desc = PoseDescriptor(**CONFIGS[config])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # X[3] has no tracked frame
        desc.fit(X)
    assert_allclose(desc.link_lengths_, ref[f"{config}__link_lengths"], rtol=RTOL)
    assert_allclose(desc.mean_, ref[f"{config}__mean"], rtol=RTOL, atol=ATOL)
    assert_allclose(desc.scale_, ref[f"{config}__scale"], rtol=RTOL, atol=ATOL)
    Z = desc.transform(X)
    for i, (x, z) in enumerate(zip(X, Z)):
        expected = ref[f"{config}__Z{i}"]
        assert z.shape == expected.shape
        assert_allclose(np.ma.getdata(z), expected, rtol=RTOL, atol=ATOL)
        # Untracked frames stay masked, whichever implementation.
        assert_array_equal(np.ma.getmaskarray(z).all(axis=1), missing_frames(x))


@pytest.mark.parametrize(
    "params",
    [
        {},
        {"sigma": 0.0, "link_normalisation": False},
        {"border": "zero", "link_direction": "simao"},
        {"joints": "full20", "fill": "hold", "distance_scale": "spine"},
        {"standardize": False},
    ],
)
@pytest.mark.filterwarnings(r"ignore:X\[5\] has no tracked frame")
def test_compiled_kernel_equals_numpy_on_streams_with_dropouts(params, monkeypatch):
    pytest.importorskip("numba")
    data = make_gesture_streams(4, dropout_rate=0.02, random_state=0)
    X = data.X + [data.X[0][:3], data.X[1][:1]]  # and sequences shorter than 5
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", False)
    desc = PoseDescriptor(**params).fit(X)
    expected = desc.transform(X)
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", True)
    assert descriptor_module._compiled_kernel() is not None
    refit = PoseDescriptor(**params).fit(X)  # fit through the kernel
    assert_allclose(refit.mean_, desc.mean_, rtol=RTOL, atol=ATOL)
    assert_allclose(refit.scale_, desc.scale_, rtol=RTOL, atol=ATOL)
    for got, want in zip(desc.transform(X), expected):
        assert_allclose(np.ma.getdata(got), np.ma.getdata(want), rtol=RTOL, atol=ATOL)
        assert_array_equal(np.ma.getmaskarray(got), np.ma.getmaskarray(want))


def test_compiled_kernel_is_used_when_numba_is_installed(monkeypatch):
    pytest.importorskip("numba")
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", True)  # not disabled
    from skgesture._descriptor import _kernel as _descriptor_kernel

    calls = []
    real = _descriptor_kernel.describe_batch

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(_descriptor_kernel, "describe_batch", spy)
    data = make_gesture_streams(2, random_state=0)
    PoseDescriptor().fit(data.X).transform(data.X)
    assert calls


def test_numpy_fallback_without_numba(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "numba", None)  # as if not installed
    monkeypatch.delitem(sys.modules, "skgesture._descriptor._kernel", raising=False)
    monkeypatch.delattr(skgesture._descriptor, "_kernel", raising=False)
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", True)
    assert descriptor_module._compiled_kernel() is None
    data = make_gesture_streams(2, random_state=0)
    Z = PoseDescriptor().fit(data.X).transform(data.X)
    assert [z.shape for z in Z] == [(len(x), 183) for x in data.X]


def test_numpy_fallback_when_the_kernel_is_disabled(monkeypatch):
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", False)
    assert descriptor_module._compiled_kernel() is None
    data = make_gesture_streams(2, random_state=0)
    Z = PoseDescriptor().fit(data.X).transform(data.X)
    assert [z.shape for z in Z] == [(len(x), 183) for x in data.X]


def test_mlp_n_threads_restores_torch_thread_count_and_keeps_predictions():
    from skgesture import TorchMLPClassifier

    rng = np.random.RandomState(0)
    X = np.r_[rng.normal(-1, 1, (60, 4)), rng.normal(1, 1, (60, 4))]
    y = np.r_[np.zeros(60, int), np.ones(60, int)]
    params = {"hidden_layer_sizes": (6,), "activations": ("tanh",),
              "max_epochs": 15, "random_state": 0}  # fmt: skip
    torch.set_num_threads(2)
    try:
        seen = []
        one = TorchMLPClassifier(**params)
        assert one.n_threads == 1  # the default
        original = torch.set_num_threads

        def record(n):
            seen.append(n)
            original(n)

        torch.set_num_threads = record
        try:
            one.fit(X, y)
            p_one = one.predict_proba(X)
        finally:
            torch.set_num_threads = original
        assert 1 in seen  # fit and predict ran on one thread
        assert torch.get_num_threads() == 2  # and the setting came back
        as_is = TorchMLPClassifier(**params, n_threads=None).fit(X, y)
        assert torch.get_num_threads() == 2
        assert_allclose(as_is.predict_proba(X), p_one, rtol=1e-5, atol=1e-6)
    finally:
        torch.set_num_threads(1)


def _small_method_b(**params):
    from skgesture import TorchMLPClassifier, make_method_b

    tiny = {"hidden_layer_sizes": (12,), "activations": ("tanh",), "max_epochs": 20}
    return make_method_b(random_state=0, **params).set_params(
        segmenter__estimator=TorchMLPClassifier(**tiny),
        classifier__estimator=TorchMLPClassifier(**tiny),
        classifier__threshold_short=0.4,
        classifier__threshold_long=0.4,
    )


def test_method_b_predictions_equal_the_reference_path(monkeypatch):
    # Reference: numpy descriptor and dense windows (before issue 10), fitted
    # and predicted that way; default: compiled kernel (if any), lazy windows.
    data = make_gesture_streams(10, dropout_rate=0.01, random_state=3)
    X_tr, y_tr, X_te = data.X[:7], data.y[:7], data.X[7:]
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", False)
    ref = _small_method_b().set_params(windows__lazy=False).fit(X_tr, y_tr)
    ref_labels = ref.predict(X_te)
    ref_segments = ref[-1].predict_segments(ref[:-1].transform(X_te))
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", True)
    est = _small_method_b().fit(X_tr, y_tr)
    assert est.named_steps["windows"].lazy  # the factory's default
    labels = est.predict(X_te)
    assert sum(int((lab > 0).sum()) for lab in labels) > 0  # gestures were found
    for got, want in zip(labels, ref_labels):
        assert_array_equal(got, want)
    segments = est[-1].predict_segments(est[:-1].transform(X_te))
    for got, want in zip(segments, ref_segments):
        assert_array_equal(got[:, :3], want[:, :3])
        assert_allclose(got[:, 3], want[:, 3], rtol=1e-6)


def test_lazy_windows_equal_dense_windows_and_keep_the_rest_rows():
    from skgesture import DynamicPoseWindow
    from skgesture._windows import DynamicPoses, dynamic_poses

    rng = np.random.RandomState(0)
    D = rng.normal(size=(30, 5))
    D[[0, 1, 2, 3, 4, 5, 6, 7, 8]] = 0.0  # leading all-zero (untracked) rows
    rows = np.zeros(30, bool)
    rows[20:24] = True
    masked = np.ma.MaskedArray(D, mask=np.repeat(rows[:, None], 5, axis=1))
    dense = DynamicPoseWindow(steps=(4, 3, 2)).fit([D]).transform([D, masked])
    lazy = DynamicPoseWindow(steps=(4, 3, 2), lazy=True).fit([D])
    lazy = lazy.transform([D, masked])
    assert all(isinstance(w, DynamicPoses) for w in lazy)
    assert lazy[0].shape == dense[0].shape and lazy[0].dtype == np.float32
    assert_array_equal(np.asarray(lazy[0]), dense[0])
    assert_array_equal(lazy[0][[3, 17]], dense[0][[3, 17]])
    assert_array_equal(lazy[0][5, 1, 2:7], dense[0][5, 1, 2:7])
    assert_array_equal(lazy[0][10:12], dense[0][10:12])
    assert_array_equal(
        lazy[0].windows(np.array([29])), dynamic_poses(D, (4, 3, 2), 3, [29])
    )
    # Rest rows: the masked rows, or (plain input) the all-zero dense rows.
    assert_array_equal(lazy[1].rest_rows(), rows)
    assert_array_equal(lazy[0].rest_rows(), ~np.asarray(dense[0]).any(axis=(1, 2)))
    assert lazy[0].rest_rows()[:5].all() and not lazy[0].rest_rows()[5:].any()
    assert_array_equal(
        np.ma.getmaskarray(lazy[1].toarray()), np.ma.getmaskarray(dense[1])
    )


def test_lazy_windows_with_other_steps_are_refused_by_the_classifier():
    from skgesture import DynamicPoseWindow, MultiScaleClassifier

    D = [np.random.RandomState(0).normal(size=(40, 4)) for _ in range(2)]
    W = DynamicPoseWindow(steps=(4, 2), lazy=True).fit(D).transform(D)
    y = [
        np.r_[np.zeros(10, int), np.full(30, 1)],
        np.r_[np.zeros(10, int), np.full(30, 2)],
    ]
    clf = MultiScaleClassifier(steps=(4, 3))
    with pytest.raises(ValueError, match=r"X\[0\] does not hold dynamic poses with"):
        clf.fit(W, y)
