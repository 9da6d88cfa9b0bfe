"""Prediction cost per frame of Methods A and B, descriptor included (issue 10).

* PRECOG: the paper's networks trained on subjects 1-7 (full 20-joint layout,
  426-D descriptor); ``predict`` on the 48 bundled streams (~250 frames each).
* synthetic: 60 training streams, ``predict`` on 20 streams of other
  subjects (paper's 11 joints, 183-D).

Every figure is the median of 5 calls of ``predict`` after one warm-up, on one
core (torch and BLAS limited to one thread), as wall time and as the process
CPU time (the better figure on a shared machine: wall time there includes the
time other jobs hold the core). Two paths per method:

* ``default``: the compiled descriptor kernel (when numba is installed) and
  lazy windows (``DynamicPoseWindow(lazy=True)``, what ``make_method_b``
  builds);
* ``reference``: the numpy descriptor and dense windows (the implementation
  before issue 10); ``identical`` says whether both give the same labels.

The ``stage`` rows split the default path of Method B (CPU time). ``--quick``
trains with 30 epochs instead of 1000 (same network sizes, so nearly the same
prediction cost), on PRECOG subjects 1-3 (predicting subject 8's 6 streams)
and on fewer synthetic streams.
"""

import statistics
import time

import numpy as np
from _common import one_core

import skgesture._descriptor._compute as descriptor_module
from skgesture import make_method_a, make_method_b
from skgesture.datasets import load_precog, make_gesture_streams

COLUMNS = [
    "data",
    "method",
    "path",
    "sequences",
    "frames",
    "µs/frame (wall)",
    "µs/frame (CPU)",
    "identical",
]
TARGET_US = 20.0  # issue 10: Method B <= 20 µs/frame on PRECOG


def cpu_median(func, repeat=5, warmup=1):
    """Median wall and process CPU seconds of ``func()`` after ``warmup`` calls."""
    for _ in range(warmup):
        func()
    wall, cpu = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        func()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)


def _fit(make, X, y, quick):
    est = make()
    if quick:
        est.set_params(
            segmenter__estimator__max_epochs=30, classifier__estimator__max_epochs=30
        )
    return est.fit(X, y)


def _paths(est, X, label, method, n_frames):
    """Rows for the default and the reference path of a fitted pipeline."""
    rows, preds = [], {}
    for path, compiled, lazy in (("default", True, True), ("reference", False, False)):
        descriptor_module.USE_COMPILED = compiled
        est.set_params(windows__lazy=lazy)
        try:
            wall, cpu = cpu_median(lambda: est.predict(X))
            preds[path] = est.predict(X)
        finally:
            descriptor_module.USE_COMPILED = True
            est.set_params(windows__lazy=True)
        rows.append(
            {
                "data": label,
                "method": method,
                "path": path,
                "sequences": len(X),
                "frames": n_frames,
                "µs/frame (wall)": 1e6 * wall / n_frames,
                "µs/frame (CPU)": 1e6 * cpu / n_frames,
            }
        )
    same = all(
        np.array_equal(a, b) for a, b in zip(preds["default"], preds["reference"])
    )
    for row in rows:
        row["identical"] = "yes" if same else "NO"
    return rows


def _stages(est, X, label, n_frames):
    """CPU µs/frame of each stage of the default path (inputs precomputed)."""
    rows, Xt = [], X
    for name, step in est.steps:
        inp = Xt
        if name == est.steps[-1][0]:
            wall, cpu = cpu_median(lambda: step.predict(inp))
        else:
            wall, cpu = cpu_median(lambda: step.transform(inp))
            Xt = step.transform(inp)
        rows.append(
            {
                "data": label,
                "method": "B",
                "path": f"stage: {name}",
                "sequences": len(X),
                "frames": n_frames,
                "µs/frame (wall)": 1e6 * wall / n_frames,
                "µs/frame (CPU)": 1e6 * cpu / n_frames,
                "identical": "",
            }
        )
    return rows


def _datasets(quick):
    precog = load_precog()
    groups = np.asarray(precog.groups)
    train = np.flatnonzero(groups <= 3 if quick else groups != 8)
    test = np.flatnonzero(groups == 8) if quick else np.arange(len(groups))
    yield (
        f"PRECOG ({len(test)} streams)",
        "full20",
        [precog.X[i] for i in train],
        [precog.y[i] for i in train],
        [precog.X[i] for i in test],
    )
    n_train, n_test = (20, 10) if quick else (60, 20)
    syn = make_gesture_streams(n_train + n_test, n_subjects=16, random_state=0)
    yield (
        f"synthetic ({n_test} streams)",
        "paper11",
        syn.X[:n_train],
        syn.y[:n_train],
        syn.X[n_train:],
    )


def run(quick=False):
    """Rows: µs per frame of Methods A and B, default and reference paths."""
    rows = []
    with one_core():
        for label, joints, X_tr, y_tr, X_te in _datasets(quick):
            n_frames = sum(len(x) for x in X_te)
            for method, make in (("A", make_method_a), ("B", make_method_b)):
                est = _fit(
                    lambda make=make: make(joints=joints, random_state=0),
                    X_tr,
                    y_tr,
                    quick,
                )
                rows += _paths(est, X_te, label, method, n_frames)
                if method == "B":
                    rows += _stages(est, X_te, label, n_frames)
    return rows


if __name__ == "__main__":
    from _common import format_table, machine_line

    print(machine_line())
    print(format_table(run(), COLUMNS, "Prediction cost per frame (one core)"))
