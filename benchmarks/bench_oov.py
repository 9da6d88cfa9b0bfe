"""Out-of-vocabulary rejection: false events per minute against recall (issue 14).

Section ``oov`` of ``make bench``. A robot commanded by gestures must not move
when the person does something else; this section measures how often the
recommended model fires on motion outside its vocabulary, and how many true
gestures it still finds, with and without background recordings in ``fit``.

Protocol
--------
* **Model**: ``make_recommended(joints="full20", random_state=seed)`` (all 20
  joints: the vocabulary has kicks), fitted with ``fps`` of PRECOG (30).
* **Positives**: PRECOG (``load_precog()``, the bundled subjects 1-8; the
  shared data folder holds the same 48 files, subjects 9-12 are kept aside).
  Each fold trains on the other subjects and tests on the held-out ones.
  Default (reduced) protocol: ``REDUCED_FOLDS`` = held-out subject pairs
  (7, 8) and (3, 4), ``REDUCED_SEEDS`` = (0,); with ``SKG_BENCH_OOV_FULL=1``:
  leave one subject out over the 8 subjects (``FULL_FOLDS``) x seeds 0, 1, 2
  (``FULL_SEEDS``), the issue's protocol. A fit took 2 to 9 minutes on a
  shared 2-core machine, so the reduced protocol (10 fits) takes 20-90
  minutes and the full one (120 fits) 4-18 hours; cached fits are reused.
* **Negatives** (out of vocabulary), read from ``$SKGESTURE_SHARED_DATA`` or
  ``<repo>/../shared/data`` (a missing folder skips its dataset with a note):

  - ``MSR Action3D`` (15 fps): the ``cvpr12`` clips without forward punch, side
    boxing, forward kick and side kick, joined per subject (10 streams);
  - ``MSRC-12`` (30 fps): the subset's streams without its ``kick`` class;
  - ``UTKinect`` (20 streams): skeleton rows are irregular, 5-10 a second; each
    stream has its own ``fps`` (the loader's mean rows per second).

  Every stream is predicted with its own ``fps`` (the pipeline resamples it to
  the model's 30 fps and maps the segments back); minutes are its rows divided
  by its ``fps`` (UTKinect: 15,860 rows are 37 minutes, not the 8.8 of reading
  them as 30 fps frames).
* **Background in fit** (``CONFIGS``): ``none``; ``synthetic``
  (``make_background`` of the fold's training recordings); or one real
  negative dataset. A real one is resampled to 30 fps, joined end to end and
  cut into ``BACKGROUND_PIECES`` (12) equal pieces, as many as the synthetic
  background of this row has sequences, so every configuration gives
  background the same share of the tagger's training crops (they are drawn
  from uniformly chosen sequences). **A dataset used as background is never
  a test set of that row**: background MSR Action3D is tested on MSRC-12 and
  UTKinect, UTKinect on MSR Action3D and MSRC-12, MSRC-12 on MSR Action3D and
  UTKinect; ``none`` and ``synthetic`` on all three. ``pooled`` = all test
  sets of the row together.
* **Events**: ``model.predict_segments(X, fps=fps)``, rows ``(class, start,
  end, confidence)``: the runs of ``predict``, the confidence the mean
  probability of the class over the run. At a confidence threshold ``t`` the
  segments with confidence >= ``t`` are kept (``t = 0``: every segment, the
  defaults; ``t = 0.6``: ``ActionMap``'s default floor). On the negatives every
  kept segment is a false event: ``events_per_min`` = kept segments / minutes.
* **Recall** (matching rule): a true PRECOG gesture (a ``segments`` row of the
  held-out subjects, at least ``MIN_TRUE_LENGTH`` = 5 frames: shorter ones are
  label glitches) is found when a kept predicted segment of the **same class**
  overlaps it with **IoU >= 0.5** (``MIN_IOU``; intersection over union of
  their frame intervals). ``recall`` = found / true gestures.
* **Jaccard**: official ChaLearn 2014 Jaccard index (``jaccard_index``) of the
  held-out PRECOG sequences, labels rebuilt from the kept segments (at ``t = 0``
  the labels of ``predict``); ``jaccard_delta`` = the row minus the ``none``
  row of the same fold, seed and threshold (mean of the paired differences).
* **Curve**: thresholds 0, 0.05, ..., 0.95 (``THRESHOLDS``); the figure
  (``oov.png``, ``oov_quick.png`` in quick mode) plots false events per minute
  against recall, one curve per configuration and one panel per test set.
* **Spread**: each figure is the mean over the fold x seed runs, ``*_sd`` their
  standard deviation (ddof=1; empty for one run).
* **Targets** (issue 14): <= 0.5 false events/min with background in fit,
  recall >= 0.90, Jaccard no more than 0.01 below the ``none`` model.

Each fit's raw segments are cached as JSON under ``bench_results/oov/`` (keyed
by configuration, fold, seed, the skgesture and benchmark sources, the library
versions and the data sizes), so a rerun computes only what is missing; the
output folder is ``run(out_dir=...)``, else ``$SKG_BENCH_OOV_DIR``, else
``bench_results/``.

Quick mode (``run(quick=True)``, ``--quick``): synthetic data only, no shared
data needed, no cache: 12 ``make_gesture_streams`` streams of 4 classes
(subjects 0-3, one fold holding out subject 3); the negatives are streams of
other synthetic classes with the gestures of the vocabulary cut out, relabelled
0 (``synthetic A``: classes 5-8, ``synthetic B``: classes 9-12); a tiny tagger.

Usage: ``python benchmarks/bench_oov.py [--quick]`` (``SKG_BENCH_OOV_FULL=1`` for
LOSO x 3 seeds), or ``python benchmarks/run.py --only oov``.
"""

import argparse
import hashlib
import json
import os
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (  # noqa: E402
    format_table,
    load_utkinect_quiet,
    machine_line,
    shared_data_dir,
    source_key,
)

import skgesture  # noqa: E402
from skgesture._rate import resample  # noqa: E402
from skgesture.datasets import (  # noqa: E402
    load_msr_action3d,
    load_msrc12,
    load_precog,
    make_background,
    make_gesture_streams,
)
from skgesture.metrics import (  # noqa: E402
    jaccard_index,
    rejection_curve,
    segments_to_labels,
)

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench_results"

REDUCED_FOLDS = ((7, 8), (3, 4))  # held-out PRECOG subjects of each fold
REDUCED_SEEDS = (0,)
FULL_FOLDS = tuple((s,) for s in range(1, 9))  # leave one subject out
FULL_SEEDS = (0, 1, 2)
FULL_ENV = "SKG_BENCH_OOV_FULL"
OUT_ENV = "SKG_BENCH_OOV_DIR"

THRESHOLDS = tuple(round(0.05 * i, 2) for i in range(20))  # 0 .. 0.95
OPERATING_POINTS = (0.0, 0.6, 0.9)
MIN_IOU = 0.5
MIN_TRUE_LENGTH = 5
# All-rest sequences given to fit (the user's "background recordings"), not
# the model's own synthetic negatives for its run namer (24 by default,
# skgesture.datasets.SyntheticBackground), which every row has.
BACKGROUND_PIECES = 12
TARGET_EVENTS_PER_MIN = 0.5
TARGET_RECALL = 0.9
TARGET_JACCARD_DROP = 0.01

# The real negative datasets: folder under the shared data, and the classes of
# the PRECOG vocabulary (punches, kicks) that are removed from them.
MSR, MSRC, UTK = "MSR Action3D", "MSRC-12", "UTKinect"
MSR_IN_VOCABULARY = ("forward punch", "side boxing", "forward kick", "side kick")
MSRC_IN_VOCABULARY = ("kick",)
FOLDERS = {MSR: "msr_action3d", MSRC: "msrc12_subset", UTK: "utkinect_action3d"}
# Background configurations of fit: "none", "synthetic" or a negative dataset.
CONFIGS = ("none", "synthetic", MSR, UTK, MSRC)
QUICK_A, QUICK_B = "synthetic A", "synthetic B"
QUICK_CONFIGS = ("none", "synthetic", QUICK_A, QUICK_B)

COLUMNS = [
    "config",
    "background in fit",
    "tested on",
    "threshold",
    "false events/min",
    "recall",
    "jaccard",
    "jaccard delta",
    "meets targets",
    "runs",
]
DETAIL_COLUMNS = ["config", "tested on", "minutes", "t = 0", "t = 0.6", "t = 0.9"]
# Filled by run(): the notes printed under the table (skipped data, protocol).
NOTES = []


# ---------------------------------------------------------------- data


@dataclass
class Negatives:
    """Streams of motion outside the vocabulary: ``X`` and the ``fps`` of each."""

    name: str
    X: list
    fps: np.ndarray
    how: str

    @property
    def minutes(self):
        """Duration in minutes: the rows of every stream over its frame rate."""
        return float(sum(len(x) / f for x, f in zip(self.X, self.fps)) / 60.0)


def _class_ids(target_names, names):
    missing = [n for n in names if n not in target_names]
    if missing:
        raise ValueError(f"classes {missing} not in {target_names}")
    return {list(target_names).index(n) + 1 for n in names}


def _load_msr(path):
    data = load_msr_action3d(path)
    drop = _class_ids(data.target_names, MSR_IN_VOCABULARY)
    groups = np.asarray(data.groups)
    keep = [i for i, lab in enumerate(data.y) if int(lab[0]) not in drop]
    X = [
        np.concatenate([data.X[i] for i in keep if groups[i] == g])
        for g in np.unique(groups[keep])
    ]
    how = (
        f"{len(keep)} clips without {', '.join(MSR_IN_VOCABULARY)}, joined per "
        f"subject: {len(X)} streams"
    )
    return Negatives(MSR, X, np.full(len(X), float(data.fps)), how)


def _load_msrc(path):
    data = load_msrc12(path)
    drop = _class_ids(data.target_names, MSRC_IN_VOCABULARY)
    keep = [i for i, c in enumerate(data.action_classes) if not set(c) & drop]
    X = [data.X[i] for i in keep]
    how = f"{len(X)} of {len(data.X)} streams (no {', '.join(MSRC_IN_VOCABULARY)})"
    return Negatives(MSRC, X, np.full(len(X), float(data.fps)), how)


def _load_utk(path):
    data = load_utkinect_quiet(path)
    fps = np.asarray(data.fps, dtype=float)
    how = f"{len(data.X)} streams at {fps.min():.1f}-{fps.max():.1f} rows/s"
    return Negatives(UTK, list(data.X), fps, how)


LOADERS = {MSR: _load_msr, MSRC: _load_msrc, UTK: _load_utk}


def load_negatives(notes):
    """The real negative datasets found (``{name: Negatives}``); notes the absent."""
    base = shared_data_dir()
    out = {}
    for name, folder in FOLDERS.items():
        path = base / folder
        if not path.is_dir():
            notes.append(f"{name}: {path} not found, skipped")
            print(f"  [oov] {name}: {path} not found, skipped", flush=True)
            continue
        out[name] = LOADERS[name](path)
    return out


def _without_classes(x, y, keep_from):
    """The frames of a stream whose label is rest or at least ``keep_from``."""
    rows = (y == 0) | (y >= keep_from)
    return x[rows]


def quick_data():
    """``(positives, {name: Negatives})`` of synthetic streams (quick mode)."""
    pos = make_gesture_streams(
        n_sequences=12, n_classes=4, n_subjects=4, n_gestures=(3, 5), random_state=0
    )
    negs = {}
    for name, n_classes, keep_from, seed in ((QUICK_A, 8, 5, 1), (QUICK_B, 12, 9, 2)):
        other = make_gesture_streams(
            n_sequences=3,
            n_classes=n_classes,
            n_subjects=3,
            n_gestures=(4, 6),
            oov_rate=0.0,
            random_state=seed,
        )
        X = [_without_classes(x, y, keep_from) for x, y in zip(other.X, other.y)]
        how = f"classes {keep_from}-{n_classes} of make_gesture_streams, labelled 0"
        negs[name] = Negatives(name, X, np.full(len(X), float(other.fps)), how)
    return pos, negs


def background_pieces(neg, fps, n_pieces):
    """A negative dataset as ``n_pieces`` training sequences at ``fps``.

    Every stream is resampled to the model's rate, all are joined end to end
    and cut into equal pieces.
    """
    frames = np.concatenate([resample(x, f, fps) for x, f in zip(neg.X, neg.fps)])
    return list(np.array_split(frames, n_pieces))


# ---------------------------------------------------------------- fitting


def make_model(seed, quick):
    """The recommended model (20 joints); a tiny tagger in quick mode."""
    model = skgesture.make_recommended(joints="full20", random_state=seed)
    if quick:
        model.set_params(
            tagger__hidden_sizes=(16,),
            tagger__tcn_layers=3,
            tagger__tcn_stages=1,
            tagger__crop_length=64,
            tagger__batch_size=8,
            tagger__max_epochs=6,
            tagger__steps_per_epoch=8,
            tagger__fit_threads=1,  # a tiny network: one thread is fastest
        )
    return model


def _background(config, X_tr, y_tr, negatives, fps, seed):
    """The background sequences of ``config`` for one fold (list of arrays)."""
    if config == "none":
        return []
    if config == "synthetic":
        bg = make_background(
            X_tr, y_tr, n_sequences=BACKGROUND_PIECES, random_state=seed
        )
        return list(bg.X)
    return background_pieces(negatives[config], fps, BACKGROUND_PIECES)


def fit_cell(config, seed, quick, X_tr, y_tr, X_te, negatives, fps):
    """Fit one model and return its raw segments (a JSON-able dict).

    ``{"positives": [[[class, start, end, confidence], ...], ...] (one list per
    held-out sequence), "negatives": {name: [confidence, ...]}, "fit_s": ...}``;
    the negatives are those not used as background.
    """
    bg = _background(config, X_tr, y_tr, negatives, fps, seed)
    X_fit = list(X_tr) + bg
    y_fit = list(y_tr) + [np.zeros(len(x), dtype=np.int64) for x in bg]
    model = make_model(seed, quick)
    t0 = time.perf_counter()
    model.fit(X_fit, y_fit, fps=fps)
    fit_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    pos = model.predict_segments(X_te, fps=fps)
    neg = {}
    for name, data in negatives.items():
        if name == config:
            continue  # never test on the negatives used in training
        segs = model.predict_segments(data.X, fps=data.fps)
        conf = np.concatenate([np.asarray(s, dtype=float)[:, 3] for s in segs])
        neg[name] = np.nan_to_num(conf, nan=0.0).tolist()
    return {
        "positives": [np.asarray(s, dtype=float).tolist() for s in pos],
        "negatives": neg,
        "fit_s": fit_s,
        "predict_s": time.perf_counter() - t0,
        "background_frames": int(sum(len(x) for x in bg)),
    }


# ---------------------------------------------------------------- cache


def _code_key(data_sizes):
    """Hash of the skgesture and benchmark code, versions and data sizes."""
    import sklearn
    import torch

    h = hashlib.sha1()
    pkg = Path(skgesture.__file__).resolve().parent
    for path in sorted(pkg.rglob("*.py")) + [Path(__file__).resolve()]:
        h.update(str(path.relative_to(ROOT)).encode())
        h.update(source_key(path))
    versions = [platform.python_version(), np.__version__, sklearn.__version__]
    h.update(json.dumps(versions + [torch.__version__, data_sizes]).encode())
    return h.hexdigest()[:12]


def _cell_path(cache_dir, config, fold, seed, key):
    slug = "".join(c if c.isalnum() else "_" for c in config)
    test = "-".join(str(s) for s in fold)
    return cache_dir / f"{slug}-test{test}-seed{seed}-{key}.json"


# ---------------------------------------------------------------- scoring


def score_cell(cell, y_te, true_segments, thresholds):
    """Recall, Jaccard and events per minute of one fit at every threshold.

    Recall is ``skgesture.metrics.rejection_curve``'s (same class, IoU >=
    ``MIN_IOU``) over the true gestures of at least ``MIN_TRUE_LENGTH`` frames.
    Returns ``{threshold: {"recall", "jaccard", "gestures", "events": {name:
    count}}}``.
    """
    pred = [np.asarray(p, dtype=float).reshape(-1, 4) for p in cell["positives"]]
    true = [
        [r for r in np.asarray(t).reshape(-1, 3) if r[2] - r[1] >= MIN_TRUE_LENGTH]
        for t in true_segments
    ]
    curve = rejection_curve(true, pred, thresholds=thresholds, min_iou=MIN_IOU)
    out = {}
    for t, recall in zip(thresholds, curve.recall):
        labels = [
            segments_to_labels(p[p[:, 3] >= t, :3].astype(np.int64), len(y))
            for p, y in zip(pred, y_te)
        ]
        out[t] = {
            "recall": float(recall),
            "gestures": curve.n_gestures,
            "jaccard": float(jaccard_index(y_te, labels)),
            "events": {
                name: int(np.sum(np.asarray(conf) >= t))
                for name, conf in cell["negatives"].items()
            },
        }
    return out


def _mean_sd(values):
    values = [v for v in values if v == v]
    if not values:
        return float("nan"), float("nan")
    sd = float(np.std(values, ddof=1)) if len(values) > 1 else float("nan")
    return float(np.mean(values)), sd


def summarise(scores, fit_s, negatives, thresholds):
    """Table rows from ``scores[config][(fold, seed)][threshold]``."""
    rows = []
    for config, runs in scores.items():
        tested = [n for n in negatives if n != config]
        sets = [(n, [n]) for n in tested]
        if len(tested) > 1:
            sets.append(("pooled", tested))
        for label, names in sets:
            minutes = sum(negatives[n].minutes for n in names)
            for t in thresholds:
                per_run = [r[t] for r in runs.values()]
                rate = [sum(r["events"][n] for n in names) / minutes for r in per_run]
                delta = [
                    r[t]["jaccard"] - scores["none"][k][t]["jaccard"]
                    for k, r in runs.items()
                    if "none" in scores and k in scores["none"]
                ]
                ev, ev_sd = _mean_sd(rate)
                rec, rec_sd = _mean_sd([r["recall"] for r in per_run])
                jac, jac_sd = _mean_sd([r["jaccard"] for r in per_run])
                rows.append(
                    {
                        "table": "oov",
                        "config": config,
                        "background": _background_label(config, negatives),
                        "test_negatives": label,
                        "threshold": float(t),
                        "events_per_min": ev,
                        "events_per_min_sd": ev_sd,
                        "events": float(
                            np.mean(
                                [sum(r["events"][n] for n in names) for r in per_run]
                            )
                        ),
                        "minutes": minutes,
                        "recall": rec,
                        "recall_sd": rec_sd,
                        "gestures": int(np.mean([r["gestures"] for r in per_run])),
                        "jaccard": jac,
                        "jaccard_sd": jac_sd,
                        "jaccard_delta": _mean_sd(delta)[0],
                        "runs": len(per_run),
                        "fit_s": float(np.mean(fit_s[config])),
                    }
                )
    return rows


def _background_label(config, negatives):
    if config == "none":
        return "none"
    if config == "synthetic":
        return f"synthetic ({BACKGROUND_PIECES} make_background sequences)"
    return f"{config} ({BACKGROUND_PIECES} pieces)"


# ---------------------------------------------------------------- running


def _protocol(quick, folds, seeds):
    if quick:
        return (3,), (0,), "quick"
    full = os.environ.get(FULL_ENV, "") not in ("", "0")
    folds = folds or (FULL_FOLDS if full else REDUCED_FOLDS)
    seeds = seeds or (FULL_SEEDS if full else REDUCED_SEEDS)
    return tuple(tuple(f) for f in folds), tuple(seeds), "full" if full else "reduced"


def run(quick=False, folds=None, seeds=None, configs=None, out_dir=None):
    """Fit what is missing and return the rows (notes in ``NOTES``).

    Parameters
    ----------
    quick : bool, default=False
        Synthetic data and a tiny tagger (seconds; no shared data, no cache).
    folds : sequence of tuple of int or None, default=None
        Held-out subjects of each fold; None: ``REDUCED_FOLDS``, or
        ``FULL_FOLDS`` with ``SKG_BENCH_OOV_FULL=1`` (quick: subject 3).
    seeds : sequence of int or None, default=None
        Seeds; None: ``REDUCED_SEEDS``, or ``FULL_SEEDS`` when full.
    configs : sequence of str or None, default=None
        Background configurations (``CONFIGS``; quick: ``QUICK_CONFIGS``).
    out_dir : path-like or None, default=None
        Folder of the figure and the cache; None: ``$SKG_BENCH_OOV_DIR`` or
        ``bench_results/``.

    Returns
    -------
    list of dict
        ``table="oov"`` rows, one per configuration, test set (and ``pooled``)
        and threshold of ``THRESHOLDS``, with ``config``, ``background`` (what
        ``fit`` got), ``test_negatives``, ``threshold``, ``events_per_min``
        and ``events`` (mean over runs; ``events_per_min_sd``), ``minutes``,
        ``recall`` (``recall_sd``), ``gestures`` (true gestures per run),
        ``jaccard`` (``jaccard_sd``), ``jaccard_delta`` (against ``none``),
        ``runs`` and ``fit_s``; then one ``table="figure"`` row (``path``).
    """
    NOTES.clear()
    out_dir = Path(out_dir or os.environ.get(OUT_ENV) or RESULTS)
    folds, seeds, mode = _protocol(quick, folds, seeds)
    if quick:
        pos, negatives = quick_data()
    else:
        pos, negatives = load_precog(), load_negatives(NOTES)
    fps = float(pos.fps)
    configs = [
        c
        for c in (configs or (QUICK_CONFIGS if quick else CONFIGS))
        if c in ("none", "synthetic") or c in negatives
    ]
    if not quick:
        for c in CONFIGS:
            if c not in configs and c not in ("none", "synthetic"):
                NOTES.append(f"background {c}: dataset absent, row skipped")
    groups = np.asarray(pos.groups)
    sizes = {"positives": int(np.sum(pos.n_frames))}
    sizes.update({n: int(sum(len(x) for x in d.X)) for n, d in negatives.items()})
    cache = None if quick else out_dir / "oov"
    key = None if quick else _code_key(sizes)
    scores, fit_s = {c: {} for c in configs}, {c: [] for c in configs}
    for fold in folds:
        te = np.flatnonzero(np.isin(groups, fold))
        tr = np.flatnonzero(~np.isin(groups, fold))
        X_tr, y_tr = [pos.X[i] for i in tr], [pos.y[i] for i in tr]
        X_te, y_te = [pos.X[i] for i in te], [pos.y[i] for i in te]
        true = [pos.segments[i] for i in te]
        for seed in seeds:
            for config in configs:
                path = cache and _cell_path(cache, config, fold, seed, key)
                if path and path.exists():
                    cell = json.loads(path.read_text())
                else:
                    cell = fit_cell(
                        config, seed, quick, X_tr, y_tr, X_te, negatives, fps
                    )
                    if path:
                        path.parent.mkdir(parents=True, exist_ok=True)
                        cell["meta"] = {
                            "config": config,
                            "fold": list(fold),
                            "seed": seed,
                            "key": key,
                            "machine": f"{platform.node()} {platform.machine()}",
                            "when": time.strftime("%Y-%m-%d %H:%M:%S"),
                        }
                        tmp = path.with_suffix(".tmp")
                        tmp.write_text(json.dumps(cell))
                        tmp.replace(path)
                    if not quick:
                        print(
                            f"  [oov] {config} test {fold} seed {seed}: fit "
                            f"{cell['fit_s']:.0f} s",
                            flush=True,
                        )
                scores[config][(fold, seed)] = score_cell(cell, y_te, true, THRESHOLDS)
                fit_s[config].append(cell["fit_s"])
    rows = summarise(scores, fit_s, negatives, THRESHOLDS)
    NOTES.append(
        f"protocol ({mode}): {'synthetic' if quick else 'PRECOG'} held-out "
        f"subjects {list(folds)} x seeds "
        f"{list(seeds)}; positives found at IoU >= {MIN_IOU} with a segment of the "
        f"same class (true gestures >= {MIN_TRUE_LENGTH} frames); mean ± sd over runs"
    )
    for name, data in negatives.items():
        NOTES.append(f"{name}: {data.how}, {data.minutes:.1f} minutes")
    NOTES.append(
        f"targets: <= {TARGET_EVENTS_PER_MIN} false events/min with background in "
        f"fit, recall >= {TARGET_RECALL:.2f}, jaccard delta >= -{TARGET_JACCARD_DROP}"
    )
    figure = plot_curves(rows, out_dir / ("oov_quick.png" if quick else "oov.png"))
    rows.append({"table": "figure", "path": str(figure)})
    return rows


# ---------------------------------------------------------------- output


def plot_curves(rows, path):
    """False events per minute against recall, a panel per test set."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if r.get("table") == "oov"]
    sets = list(dict.fromkeys(r["test_negatives"] for r in rows))
    sets = [s for s in sets if s != "pooled"] + (["pooled"] if "pooled" in sets else [])
    configs = list(dict.fromkeys(r["config"] for r in rows))
    fig, axes = plt.subplots(
        1, max(len(sets), 1), figsize=(5 * max(len(sets), 1), 4.2), squeeze=False
    )
    markers = {0.0: "o", 0.6: "s", 0.9: "^"}
    for ax, name in zip(axes[0], sets):
        for i, config in enumerate(configs):
            curve = sorted(
                (
                    r
                    for r in rows
                    if r["config"] == config and r["test_negatives"] == name
                ),
                key=lambda r: r["threshold"],
            )
            if not curve:
                continue
            colour = f"C{i}"
            ax.plot(
                [r["events_per_min"] for r in curve],
                [r["recall"] for r in curve],
                "-",
                color=colour,
                label=config,
            )
            for r in curve:
                if r["threshold"] in markers:
                    ax.plot(
                        r["events_per_min"],
                        r["recall"],
                        markers[r["threshold"]],
                        color=colour,
                    )
        ax.axvline(TARGET_EVENTS_PER_MIN, color="grey", ls=":", lw=1)
        ax.axhline(TARGET_RECALL, color="grey", ls=":", lw=1)
        ax.set_xscale("symlog", linthresh=1.0)
        ax.set_xlim(left=0)
        ax.set_ylim(-0.02, 1.02)
        where = "every test set of the row" if name == "pooled" else name
        ax.set_title(f"tested on {where}")
        ax.set_xlabel("false gesture events per minute")
        ax.set_ylabel(f"recall of true gestures (IoU >= {MIN_IOU})")
        ax.legend(fontsize=8, title="background in fit", title_fontsize=8)
    fig.text(
        0.5,
        0.005,
        "curve: confidence threshold 0 to 0.95; o: 0 (defaults), s: 0.6, ^: 0.9; "
        "dotted: targets",
        ha="center",
        fontsize=8,
    )
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _pm(mean, sd, digits):
    if mean != mean:
        return "nan"
    text = f"{mean:.{digits}f}"
    return text + (f" ± {sd:.{digits}f}" if sd == sd else "")


def _meets(row):
    marks = []
    if row["config"] != "none":
        ok = row["events_per_min"] <= TARGET_EVENTS_PER_MIN
        marks.append(f"events {'yes' if ok else 'no'}")
    marks.append(f"recall {'yes' if row['recall'] >= TARGET_RECALL else 'no'}")
    if row["config"] != "none" and row["jaccard_delta"] == row["jaccard_delta"]:
        ok = row["jaccard_delta"] >= -TARGET_JACCARD_DROP
        marks.append(f"jaccard {'yes' if ok else 'no'}")
    return ", ".join(marks)


def format_tables(rows, title="Out-of-vocabulary rejection"):
    """The operating points (pooled test sets) and the events per test set."""
    oov = [r for r in rows if r.get("table") == "oov"]
    points = [r for r in oov if r["threshold"] in OPERATING_POINTS]
    configs = list(dict.fromkeys(r["config"] for r in oov))
    main = []
    for config in configs:
        mine = [r for r in points if r["config"] == config]
        pooled = [r for r in mine if r["test_negatives"] == "pooled"] or mine
        for r in pooled:
            main.append(
                {
                    "config": config,
                    "background in fit": r["background"],
                    "tested on": (
                        " + ".join(
                            sorted(
                                {
                                    x["test_negatives"]
                                    for x in mine
                                    if x["test_negatives"] != "pooled"
                                }
                            )
                        )
                    ),
                    "threshold": f"{r['threshold']:.2f}",
                    "false events/min": _pm(
                        r["events_per_min"], r["events_per_min_sd"], 2
                    ),
                    "recall": _pm(r["recall"], r["recall_sd"], 3),
                    "jaccard": _pm(r["jaccard"], r["jaccard_sd"], 3),
                    "jaccard delta": (
                        f"{r['jaccard_delta']:+.3f}"
                        if r["config"] != "none"
                        and r["jaccard_delta"] == r["jaccard_delta"]
                        else ""
                    ),
                    "meets targets": _meets(r),
                    "runs": r["runs"],
                }
            )
    detail = []
    for config in configs:
        for name in dict.fromkeys(
            r["test_negatives"] for r in oov if r["config"] == config
        ):
            mine = {
                r["threshold"]: r
                for r in points
                if r["config"] == config and r["test_negatives"] == name
            }
            detail.append(
                {
                    "config": config,
                    "tested on": name,
                    "minutes": f"{next(iter(mine.values()))['minutes']:.1f}",
                    **{
                        f"t = {t:g}": _pm(
                            mine[t]["events_per_min"], mine[t]["events_per_min_sd"], 2
                        )
                        for t in OPERATING_POINTS
                        if t in mine
                    },
                }
            )
    out = format_table(main, COLUMNS, f"{title}: operating points")
    out += "\n" + format_table(
        detail, DETAIL_COLUMNS, f"{title}: false events per minute per test set"
    )
    for r in rows:
        if r.get("table") == "figure":
            out += f"\ncurve figure: {r['path']}\n"
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="synthetic smoke run")
    parser.add_argument(
        "--out-dir", default=None, help="figure and cache folder (bench_results/)"
    )
    args = parser.parse_args(argv)
    rows = run(quick=args.quick, out_dir=args.out_dir)
    print(machine_line() + "\n")
    print(format_tables(rows))
    for note in NOTES:
        print(f"* {note}")


if __name__ == "__main__":
    main()
