"""Recommended model: fit, predict and ``train --fast`` times against targets.

Section ``speed`` of ``make bench``. Issue 15 sets three speed targets for the
recommended model (``skgesture.make_recommended``); this section measures each,
beside its target, on every core of the machine it runs on.

Protocol
--------
* **Data**: PRECOG as bundled (``skgesture.datasets.load_precog()``): the 48
  sequences of subjects 1-8, 20 joints, 30 fps, about 250 frames each (12,269
  frames in all). It ships with the package; were it missing, the section would
  skip with a note.
* **fit** (target ``TARGET_FIT_S`` = 60 s): wall seconds of
  ``make_recommended(joints="full20", random_state=seed).fit(X, y,
  fps=data.fps)`` on all 48 sequences, with the model's default
  ``tagger__fit_threads="all"`` (every core). Before each timed fit,
  ``model[:-1].fit_transform(X[:2])`` runs once untimed, so numba's first
  compilation of the descriptor (or the loading of its cache) is not counted.
  ``--repeats`` fits (default ``REPEATS`` = 3, seeds 0, 1, 2, one after the
  other in this process); the row gives their median, min and max.
* **predict** (target ``TARGET_PREDICT_US`` = 20 µs/frame): wall microseconds
  per frame of ``model.predict(X)`` on the 48 sequences in one call (features
  included), with the fitted model of the first repeat (seed 0), every core;
  one warm-up call, then ``PREDICT_CALLS`` = 5 timed calls (median, min, max).
* **train --fast** (target ``TARGET_TRAIN_FAST_S`` = 30 s): wall seconds of the
  command ``python -m skgesture train precog --method recommended --fast -o
  <tmp>/model.skops`` in a fresh subprocess (``precog`` is the CLI's name of
  the same bundled 48 sequences; ``--joints auto`` gives ``full20``), timed
  from process start to exit, as a user sees it: Python start-up, imports,
  loading the data, training and writing the model file. One run (n = 1). A
  second row, ``train --fast (fit, as printed)``, gives the training seconds
  the command prints itself (``trained method recommended in X s``); it has
  no target of its own.
* **met**: ``True`` when the median is at or below the target, ``False`` when
  above; ``None`` where no target applies (the printed fit time, and every row
  in quick mode).

Timings are wall time, so they count whatever else the machine is doing: take
them on a quiet machine (the load average at the start is in the notes).

Quick mode (``run(quick=True)``, ``--quick``; a smoke run of the code, some
seconds): 8 ``make_gesture_streams`` streams of 3 classes instead of PRECOG, a
tiny tagger (``bench_oov.make_model``'s, trained for ``QUICK_TRAINING``: one
epoch of 2 steps), one repeat,
and ``train synthetic --n-sequences 8 --n-classes 3 --method recommended
--fast --max-epochs 1``, BLAS on one thread in both (``QUICK_BLAS_ENV``: a
smoke run in the test suite should not compete for the cores of the tests
beside it); the targets are shown but do not apply (``met`` is None, printed ``n/a
(quick)``).

The rows and notes are written as JSON to ``<out_dir>/speed.json``
(``speed_quick.json`` in quick mode); the output folder is
``run(out_dir=...)``, else ``$SKG_BENCH_SPEED_DIR``, else ``bench_results/``.

Usage: ``python benchmarks/bench_speed.py [--quick] [--repeats N] [--out-dir
DIR] [--no-cli]``, or ``python benchmarks/run.py --only speed``.
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import format_table, machine_line, median_time, print_report  # noqa: E402
from bench_oov import make_model as oov_model  # noqa: E402

from skgesture.datasets import load_precog, make_gesture_streams  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench_results"
OUT_ENV = "SKG_BENCH_SPEED_DIR"

REPEATS = 3
PREDICT_CALLS = 5
TARGET_FIT_S = 60.0  # issue 15: a fit on the 48 PRECOG sequences
TARGET_PREDICT_US = 20.0  # issue 15: µs per frame, features included
TARGET_TRAIN_FAST_S = 30.0  # issue 15: `skgesture train precog --fast`, whole command

# Quick mode: a tiny tagger on tiny synthetic data (the targets do not apply).
QUICK_DATA = {"n_sequences": 8, "n_classes": 3, "n_gestures": (3, 5)}
# Quick mode: bench_oov's tiny tagger, trained for two steps.
QUICK_TRAINING = {"tagger__max_epochs": 1, "tagger__steps_per_epoch": 2}
# Quick mode's BLAS on one thread, in this process (threadpoolctl) and in the
# train --fast subprocess (environment).
QUICK_BLAS_ENV = {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}

KEYS = (
    "measurement",
    "data",
    "unit",
    "median",
    "min",
    "max",
    "n",
    "target",
    "met",
    "quick",
    "values",
)
COLUMNS = ["measurement", "data", "median", "min", "max", "n", "target", "met"]
# Filled by run(): the notes printed under the table (protocol, skipped rows).
NOTES = []

_TRAINED = re.compile(r"trained method \S+ in ([0-9.]+) s")


def _row(measurement, data, unit, values, target, quick):
    """One measurement: median, min and max of ``values`` beside its target."""
    median = float(statistics.median(values))
    return {
        "measurement": measurement,
        "data": data,
        "unit": unit,
        "median": median,
        "min": float(min(values)),
        "max": float(max(values)),
        "n": len(values),
        "target": target,
        "met": None if quick or target is None else bool(median <= target),
        "quick": quick,
        "values": [float(v) for v in values],
    }


def _data(quick):
    """``(bunch, label)``: PRECOG, or tiny synthetic streams in quick mode."""
    if quick:
        data = make_gesture_streams(**QUICK_DATA, random_state=0)
        label = f"synthetic, {len(data.X)} streams"
    else:
        data = load_precog()
        label = f"PRECOG, {len(data.X)} sequences"
    frames = sum(len(x) for x in data.X)
    return data, f"{label} ({frames:,} frames)"


def make_model(seed, quick):
    """The recommended model on 20 joints (``bench_oov.make_model``); in quick
    mode its tiny tagger, trained for ``QUICK_TRAINING``."""
    model = oov_model(seed, quick)
    if quick:
        model.set_params(**QUICK_TRAINING)
    return model


def time_fit(data, seed, quick):
    """``(fitted model, wall seconds of fit)``, numba's compilation left out."""
    model = make_model(seed, quick)
    model[:-1].fit_transform(data.X[:2])  # numba compiles (or loads its cache)
    start = time.perf_counter()
    model.fit(data.X, data.y, fps=data.fps)
    return model, time.perf_counter() - start


def time_predict(model, X):
    """Wall µs per frame of ``model.predict(X)``: 5 calls after one warm-up."""
    frames = sum(len(x) for x in X)
    _, times = median_time(lambda: model.predict(X), repeat=PREDICT_CALLS, warmup=1)
    return [1e6 * t / frames for t in times]


def train_command(output, quick):
    """The ``skgesture train --fast`` command line of the section."""
    if quick:
        data = ["synthetic", "--n-sequences", str(QUICK_DATA["n_sequences"])]
        data += ["--n-classes", str(QUICK_DATA["n_classes"])]
    else:
        data = ["precog"]
    cmd = [sys.executable, "-m", "skgesture", "train", *data]
    cmd += ["--method", "recommended", "--fast", "-o", str(output)]
    return cmd + (["--max-epochs", "1"] if quick else [])


def time_train_fast(quick):
    """``(wall seconds of the whole command, seconds it prints or None)``."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = train_command(Path(tmp) / "model.skops", quick)
        start = time.perf_counter()
        env = {**os.environ, **QUICK_BLAS_ENV} if quick else None
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
        wall = time.perf_counter() - start
        if proc.returncode != 0:
            raise RuntimeError(
                f"{' '.join(cmd[1:])} failed ({proc.returncode}):\n{proc.stderr}"
            )
    found = _TRAINED.search(proc.stdout)
    return wall, float(found.group(1)) if found else None


def run(quick=False, repeats=None, out_dir=None, cli=True):
    """Measure fit, predict and ``train --fast``; return the rows (notes in
    ``NOTES``) and write them as JSON.

    Parameters
    ----------
    quick : bool, default=False
        Tiny synthetic data and a tiny tagger, one repeat, BLAS on one thread
        (seconds); the targets do not apply.
    repeats : int or None, default=None
        Timed fits (seeds 0, 1, ...); None: ``REPEATS`` (quick: 1).
    out_dir : path-like or None, default=None
        Folder of ``speed.json`` (``speed_quick.json``); None:
        ``$SKG_BENCH_SPEED_DIR`` or ``bench_results/``.
    cli : bool, default=True
        Time the ``train --fast`` command too.

    Returns
    -------
    list of dict
        One row per measurement, with the keys ``KEYS``: ``fit`` (s),
        ``predict`` (µs/frame), ``train --fast`` (s) and ``train --fast (fit,
        as printed)`` (s), each with its ``data``, ``unit``, ``median``,
        ``min``, ``max``, ``n``, ``target`` (None: none), ``met`` (True, False,
        or None where no target applies: always in quick mode), ``quick`` and
        ``values`` (every timing). Empty when the data are missing.
    """
    if not quick:
        return _run(quick, repeats, out_dir, cli)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1, user_api="blas"):
        return _run(quick, repeats, out_dir, cli)


def _run(quick, repeats, out_dir, cli):
    NOTES.clear()
    if repeats is None:
        repeats = 1 if quick else REPEATS
    if repeats < 1:
        raise ValueError(f"repeats must be at least 1, got {repeats}")
    out_dir = Path(out_dir or os.environ.get(OUT_ENV) or RESULTS)
    if hasattr(os, "getloadavg"):
        load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
        NOTES.append(f"load average at the start: {load} ({os.cpu_count()} cores)")
    try:
        data, label = _data(quick)
    except (OSError, ValueError) as exc:  # bundled: should never happen
        NOTES.append(f"PRECOG not found ({exc}); section skipped")
        return []
    rows, fits, first = [], [], None
    for seed in range(repeats):
        model, seconds = time_fit(data, seed, quick)
        fits.append(seconds)
        if first is None:
            first = model
        if not quick:
            print(f"  [speed] fit seed {seed}: {seconds:.1f} s", flush=True)
    rows.append(_row("fit", label, "s", fits, TARGET_FIT_S, quick))
    per_frame = time_predict(first, list(data.X))
    rows.append(_row("predict", label, "µs/frame", per_frame, TARGET_PREDICT_US, quick))
    if cli:
        wall, printed = time_train_fast(quick)
        what = "CLI's synthetic, 8 streams" if quick else "precog (the CLI's PRECOG)"
        rows.append(_row("train --fast", what, "s", [wall], TARGET_TRAIN_FAST_S, quick))
        if printed is not None:
            rows.append(
                _row(
                    "train --fast (fit, as printed)", what, "s", [printed], None, quick
                )
            )
        else:
            NOTES.append("train --fast printed no training time")
        NOTES.append(
            "train --fast: " + " ".join(train_command("<tmp>/model.skops", quick)[1:])
        )
    else:
        NOTES.append("train --fast: not run (--no-cli)")
    mode = (
        "quick: tiny data and tagger, BLAS on 1 thread, targets n/a"
        if quick
        else "full"
    )
    NOTES.append(
        f"protocol ({mode}): fit x {repeats} (seeds {list(range(repeats))}), "
        f"every core; predict: {PREDICT_CALLS} calls after one warm-up, model of "
        "seed 0; wall times"
    )
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / ("speed_quick.json" if quick else "speed.json")
    with open(path, "w") as fh:
        json.dump(
            {"machine": machine_line(), "quick": quick, "rows": rows, "notes": NOTES},
            fh,
            indent=1,
        )
    NOTES.append(f"rows written to {path}")
    return rows


def _number(value, unit):
    return f"{value:.{1 if value >= 10 else 2}f} {unit}"


def _met(row):
    if row["target"] is None:
        return "-"
    if row["met"] is None:
        return "n/a (quick)" if row["quick"] else "-"
    return "yes" if row["met"] else "NO"


def format_tables(rows, title="Recommended model: speed against the targets"):
    """The measurements as a table, each beside its target."""
    lines = []
    for r in rows:
        unit = r["unit"]
        lines.append(
            {
                "measurement": r["measurement"],
                "data": r["data"],
                "median": _number(r["median"], unit),
                "min": _number(r["min"], unit),
                "max": _number(r["max"], unit),
                "n": r["n"],
                "target": "-" if r["target"] is None else f"<= {r['target']:g} {unit}",
                "met": _met(r),
            }
        )
    return format_table(lines, COLUMNS, title)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="synthetic smoke run")
    parser.add_argument(
        "--repeats", type=int, default=None, help=f"timed fits (default {REPEATS})"
    )
    parser.add_argument(
        "--out-dir", default=None, help="folder of speed.json (bench_results/)"
    )
    parser.add_argument(
        "--no-cli", action="store_true", help="do not time the train --fast command"
    )
    args = parser.parse_args(argv)
    rows = run(
        quick=args.quick,
        repeats=args.repeats,
        out_dir=args.out_dir,
        cli=not args.no_cli,
    )
    print_report(rows, format_tables, NOTES)


if __name__ == "__main__":
    main()
