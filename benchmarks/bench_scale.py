"""Scale: peak memory on 1,000 streams, and Dask against one process (issue 10).

``memory`` rows: Method B (paper's 11 joints) on ``make_gesture_streams(n)``
(1,000 streams, about 1.4 million frames), each measurement in a fresh
process, peak resident memory (``ru_maxrss``) read after each step:

* ``fit``: generate the streams, fit on all of them. The networks are small
  (16 tanh units, 5 epochs): memory is the data's, not the networks'.
* ``predict``: fit on the first 50 streams, then predict all streams, first
  in calls of ``CHUNK`` streams, then in one call.

``bound`` is the limit this run checks: ``BASE_MB`` plus ``KB_PER_FRAME`` per
frame of the data set (the raw skeletons take 0.47 KB per frame).

``dask`` rows: a ``GridSearchCV`` over decision parameters (Method A, small
networks, 2 x 2 fits) and ``predict_files`` over a folder of recordings, in
this process and on a ``LocalCluster`` of 2 workers with 1 thread each
(threads, as in ``tests/test_parallel.py``), after a warm-up of both.
``--quick`` uses 200 streams for memory and less data for Dask.
"""

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

N_STREAMS = 1000
N_FIT_FOR_PREDICT = 50  # streams the model of the predict measurement is fitted on
CHUNK = 100  # streams per predict call in the chunked rows
TINY = {"hidden_layer_sizes": (16,), "activations": ("tanh",), "max_epochs": 5}
BASE_MB = 1024  # the interpreter with numpy, torch, numba and skgesture, and slack
KB_PER_FRAME = 5.0  # fit: data, descriptors, the segmenter's training copies

COLUMNS = ["what", "streams", "frames", "seconds", "peak RSS (MB)", "bound (MB)", "ok"]


def _rss_mb():
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KB on Linux


def _model():
    from skgesture import TorchMLPClassifier, make_method_b

    return make_method_b(random_state=0).set_params(
        segmenter__estimator=TorchMLPClassifier(**TINY),
        classifier__estimator=TorchMLPClassifier(**TINY),
    )


def _child(mode, n_streams):
    """Run in a fresh process; prints one JSON line of timings and peaks."""
    import torch
    from threadpoolctl import threadpool_limits

    from skgesture.datasets import make_gesture_streams

    torch.set_num_threads(1)
    threadpool_limits(1)
    out = {"base": _rss_mb()}
    t0 = time.perf_counter()
    data = make_gesture_streams(n_streams, random_state=0)
    out["frames"] = int(sum(len(x) for x in data.X))
    out["data"], out["data_s"] = _rss_mb(), time.perf_counter() - t0
    t0 = time.perf_counter()
    if mode == "fit":
        _model().fit(data.X, data.y)
        out["fit"], out["fit_s"] = _rss_mb(), time.perf_counter() - t0
    else:
        k = N_FIT_FOR_PREDICT
        est = _model().fit(data.X[:k], data.y[:k])
        out["small_fit"], out["small_fit_s"] = _rss_mb(), time.perf_counter() - t0
        t0 = time.perf_counter()
        chunked = []
        for start in range(0, n_streams, CHUNK):
            chunked += est.predict(data.X[start : start + CHUNK])
        out["chunked"], out["chunked_s"] = _rss_mb(), time.perf_counter() - t0
        t0 = time.perf_counter()
        whole = est.predict(data.X)
        out["whole"], out["whole_s"] = _rss_mb(), time.perf_counter() - t0
        out["same"] = all((a == b).all() for a, b in zip(chunked, whole))
    print(json.dumps(out), flush=True)


def _run_child(mode, n):
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", mode, str(n)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"memory child ({mode}) failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def memory_rows(quick=False):
    n = 200 if quick else N_STREAMS
    fit, pred = _run_child("fit", n), _run_child("predict", n)
    frames = fit["frames"]
    bound = BASE_MB + frames * KB_PER_FRAME / 1024
    steps = [
        (fit, "data", f"make_gesture_streams({n})"),
        (fit, "fit", "+ fit Method B on all streams (small networks)"),
        (pred, "chunked", f"predict all streams, {CHUNK} per call (fit on 50)"),
        (pred, "whole", "+ predict all streams in one call"),
    ]
    rows = []
    for res, key, what in steps:
        rows.append(
            {
                "what": what,
                "streams": n,
                "frames": frames,
                "seconds": res[f"{key}_s"],
                "peak RSS (MB)": res[key],
                "bound (MB)": bound,
                "ok": "yes" if res[key] <= bound else "NO",
            }
        )
    if not pred["same"]:
        rows[-1]["ok"] = "NO (chunked != whole)"
    return rows


def _dask_data(quick):
    from skgesture.datasets import make_gesture_streams

    return make_gesture_streams(8 if quick else 16, n_subjects=4, random_state=0)


def dask_rows(quick=False):
    import joblib
    import numpy as np
    from sklearn.model_selection import GridSearchCV, GroupKFold

    from skgesture import TorchMLPClassifier, make_method_a
    from skgesture.metrics import jaccard_scorer
    from skgesture.parallel import local_cluster, predict_files

    data = _dask_data(quick)
    frames = int(sum(len(x) for x in data.X))

    def model():
        return make_method_a(random_state=0).set_params(
            segmenter__estimator=TorchMLPClassifier(**TINY),
            classifier__estimator=TorchMLPClassifier(**TINY),
        )

    def search():
        gs = GridSearchCV(
            model(),
            {"classifier__threshold_long": [0.4, 0.6]},
            scoring=jaccard_scorer,
            cv=GroupKFold(2),
        )
        return gs.fit(data.X, data.y, groups=data.groups)

    fitted = model().fit(data.X, data.y)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for i, x in enumerate(data.X):
            np.save(Path(folder) / f"rec{i:03d}.npy", x)
        timings = {}
        search()  # warm-up (kernel compilation, torch)
        predict_files(fitted, folder)
        t0 = time.perf_counter()
        serial = search()
        timings["search", "one process"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        serial_pred = predict_files(fitted, folder)
        timings["predict_files", "one process"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        with local_cluster(n_workers=2, threads_per_worker=1) as client:
            start = time.perf_counter() - t0
            with joblib.parallel_backend("dask", scatter=[data.X, data.y]):
                search()  # warm-up of the workers
            t0 = time.perf_counter()
            with joblib.parallel_backend("dask", scatter=[data.X, data.y]):
                remote = search()
            timings["search", "LocalCluster 2x1"] = time.perf_counter() - t0
            predict_files(fitted, folder, client=client)
            t0 = time.perf_counter()
            remote_pred = predict_files(fitted, folder, client=client)
            timings["predict_files", "LocalCluster 2x1"] = time.perf_counter() - t0
        same_search = np.allclose(
            serial.cv_results_["mean_test_score"], remote.cv_results_["mean_test_score"]
        )
        same_pred = all(np.array_equal(a, b) for a, b in zip(serial_pred, remote_pred))
    for (what, where), seconds in timings.items():
        rows.append(
            {
                "what": f"{what} ({len(data.X)} streams)",
                "where": where,
                "frames": frames,
                "seconds": seconds,
                "same result": "yes"
                if (same_search if what == "search" else same_pred)
                else "NO",
            }
        )
    rows.append(
        {
            "what": "LocalCluster start",
            "where": "LocalCluster 2x1",
            "frames": "",
            "seconds": start,
            "same result": "",
        }
    )
    return rows


DASK_COLUMNS = ["what", "where", "frames", "seconds", "same result"]


def run(quick=False):
    """Rows of both tables, each tagged with its ``table`` (memory, dask)."""
    rows = [{"table": "memory", **row} for row in memory_rows(quick)]
    return rows + [{"table": "dask", **row} for row in dask_rows(quick)]


def format_tables(rows, title):
    """The memory table and the Dask table (``run.py`` calls this)."""
    from _common import format_table

    memory = [r for r in rows if r["table"] == "memory"]
    dask = [r for r in rows if r["table"] == "dask"]
    return format_table(
        memory, COLUMNS, f"{title}: peak memory of fit and predict on many streams"
    ) + ("\n" + format_table(dask, DASK_COLUMNS, f"{title}: Dask against one process"))


if __name__ == "__main__":
    if len(sys.argv) > 3 and sys.argv[1] == "--child":
        _child(sys.argv[2], int(sys.argv[3]))
        sys.exit(0)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    print(format_tables(run("--quick" in sys.argv), "Scale"))
