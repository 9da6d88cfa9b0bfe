"""Beyond one process: Dask clusters for searches and for batch prediction.

A ``LocalCluster`` of 2 workers with 1 thread each (threads of this process,
which start in a fraction of a second) runs a ``GridSearchCV`` and a
``cross_validate`` under ``joblib.parallel_backend("dask")`` with the results of
the local backend, and shuts down without a warning; ``predict_files`` over a
folder of recordings gives what serial prediction gives, on the cluster and
without Dask.
"""

import logging
import sys
import warnings
from pathlib import Path

import joblib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate

from skgesture import PoseDescriptor, TorchMLPClassifier, make_method_a
from skgesture.datasets import make_gesture_streams
from skgesture.metrics import jaccard_scorer
from skgesture.parallel import predict_files, read_recording

distributed = pytest.importorskip("distributed")
from skgesture.parallel import local_cluster  # noqa: E402

TINY = {"hidden_layer_sizes": (8,), "activations": ("tanh",), "max_epochs": 10}
GRID = {"classifier__threshold_long": [0.3, 0.6]}


@pytest.fixture(scope="module")
def streams():
    return make_gesture_streams(8, n_subjects=4, random_state=0)


def _small_method_a():
    return make_method_a(random_state=0).set_params(
        segmenter__estimator=TorchMLPClassifier(**TINY),
        classifier__estimator=TorchMLPClassifier(**TINY),
    )


@pytest.fixture(scope="module")
def fitted(streams):
    return _small_method_a().fit(streams.X, streams.y)


@pytest.fixture
def no_warnings(caplog):
    """Fail the test on any Python warning or WARNING log record (Dask logs
    its shutdown problems, e.g. "Worker process still alive ... killing")."""
    caplog.set_level(logging.WARNING)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    assert [str(w.message) for w in caught] == []
    assert [
        r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING
    ] == []


def test_grid_search_and_cross_validate_on_dask_equal_the_local_backend(
    streams, no_warnings
):
    def search():
        return GridSearchCV(
            _small_method_a(), GRID, scoring=jaccard_scorer, cv=GroupKFold(2)
        )

    local = search().fit(streams.X, streams.y, groups=streams.groups)
    local_cv = cross_validate(
        _small_method_a(), streams.X, streams.y, groups=streams.groups,
        cv=GroupKFold(2), scoring=jaccard_scorer,
    )  # fmt: skip
    with local_cluster(n_workers=2, threads_per_worker=1) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        with joblib.parallel_backend("dask"):
            remote = search().fit(streams.X, streams.y, groups=streams.groups)
            remote_cv = cross_validate(
                _small_method_a(), streams.X, streams.y, groups=streams.groups,
                cv=GroupKFold(2), scoring=jaccard_scorer,
            )  # fmt: skip
    for key in ("mean_test_score", "split0_test_score", "split1_test_score"):
        assert_allclose(remote.cv_results_[key], local.cv_results_[key], rtol=1e-12)
    assert remote.best_params_ == local.best_params_
    assert_allclose(remote_cv["test_score"], local_cv["test_score"], rtol=1e-12)
    for a, b in zip(remote.predict(streams.X[:2]), local.predict(streams.X[:2])):
        assert_array_equal(a, b)


def _write_recordings(folder, streams):
    paths = []
    for i, x in enumerate(streams.X):
        path = folder / f"take{i:02d}.npy"
        np.save(path, x)
        paths.append(path)
    return paths


def test_predict_files_on_dask_equals_serial_prediction(
    tmp_path, streams, fitted, no_warnings
):
    _write_recordings(tmp_path, streams)
    # One recording per call, as each task does (torch's float32 sums may
    # depend on the batch: the confidences of a joint call differ by ~1e-8).
    expected = [fitted.predict([x])[0] for x in streams.X]
    serial = predict_files(fitted, tmp_path)  # no client: in this process
    with local_cluster(n_workers=2, threads_per_worker=1) as client:
        on_dask = predict_files(fitted, tmp_path, client=client)
        segments = predict_files(
            fitted, str(tmp_path / "*.npy"), method="predict_segments", client=client
        )
    assert len(serial) == len(on_dask) == len(expected)
    for a, b, c in zip(serial, on_dask, expected):
        assert_array_equal(a, c)
        assert_array_equal(b, c)
    want_segments = [
        fitted[-1].predict_segments(fitted[:-1].transform([x]))[0] for x in streams.X
    ]
    for got, want in zip(segments, want_segments):
        # class, start and end exactly; the confidence (a mean of float32
        # probabilities) to float32 rounding: a worker process's torch may
        # sum in another order (a 1.5e-8 difference seen on a busy machine)
        assert_array_equal(got[:, :3], want[:, :3])
        assert_allclose(got[:, 3], want[:, 3], rtol=1e-6, atol=1e-7)


def test_predict_files_writes_one_result_per_recording(tmp_path, streams, fitted):
    (tmp_path / "in").mkdir()
    paths = _write_recordings(tmp_path / "in", streams)
    out = predict_files(fitted, paths[:3], output_dir=tmp_path / "out")
    assert [Path(p).name for p in out] == [
        "take00.predict.npy", "take01.predict.npy", "take02.predict.npy"
    ]  # fmt: skip
    for path, x in zip(out, streams.X):
        assert_array_equal(np.load(path), fitted.predict([x])[0])


def test_predict_files_reads_csv_recordings_and_a_custom_reader(tmp_path, streams):
    x = streams.X[0][:40]
    np.savetxt(tmp_path / "a.csv", x.reshape(len(x), -1), delimiter=",", fmt="%.17g")
    desc = PoseDescriptor().fit(streams.X)
    (got,) = predict_files(desc, tmp_path, method="transform")
    assert_allclose(np.ma.getdata(got), np.ma.getdata(desc.transform([x])[0]))
    assert_array_equal(read_recording(tmp_path / "a.csv"), x)

    def first_ten(path):
        return read_recording(path)[:10]

    (short,) = predict_files(desc, tmp_path, method="transform", reader=first_ten)
    assert short.shape == (10, 183)


def test_predict_files_reports_bad_input_clearly(tmp_path, fitted):
    with pytest.raises(FileNotFoundError, match="holds no recording"):
        predict_files(fitted, tmp_path)
    with pytest.raises(FileNotFoundError, match="no file matches"):
        predict_files(fitted, str(tmp_path / "*.npy"))
    np.save(tmp_path / "flat.npy", np.zeros((5, 60)))
    with pytest.raises(ValueError, match=r"shape \(5, 60\); expected \(n_frames, 20"):
        predict_files(fitted, tmp_path)
    with pytest.raises(ValueError, match="has no method 'decision_function'"):
        predict_files(fitted, tmp_path, method="decision_function")
    with pytest.raises(TypeError, match="scheduler address"):
        predict_files(fitted, tmp_path / "flat.npy", client=8786)


def test_predict_files_without_dask_names_the_extra(tmp_path, fitted, monkeypatch):
    np.save(tmp_path / "a.npy", np.ones((12, 20, 3)))
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if not installed
    with pytest.raises(ImportError, match=r"skgesture\[dask\]"):
        predict_files(fitted, tmp_path, client="tcp://127.0.0.1:8786")
    assert len(predict_files(fitted, tmp_path)) == 1  # serial needs no Dask


@pytest.mark.slow
def test_worker_processes_shut_down_without_being_killed(
    tmp_path, streams, no_warnings
):
    # Worker processes that imported torch used to exceed LocalCluster's 4 s
    # and be killed with a warning; local_cluster gives them time to exit.
    _write_recordings(tmp_path, streams)
    desc = PoseDescriptor().fit(streams.X)
    with local_cluster(n_workers=2, threads_per_worker=1, processes=True) as client:
        out = predict_files(desc, tmp_path, method="transform", client=client)
    for got, x in zip(out, streams.X):
        assert_array_equal(np.ma.getdata(got), np.ma.getdata(desc.transform([x])[0]))
