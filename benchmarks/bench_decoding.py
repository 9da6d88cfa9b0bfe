"""Decoding defaults by their worst case: Jaccard change and false events per minute.

Section ``decoding`` of ``make bench``. The decoding of the recommended
model's tagger (``SequenceTagger``, step ``"tagger"`` of
``skgesture.make_recommended()``) turns per-frame probabilities into gestures;
its parameters change no training. This section scores a grid of them on
probabilities computed once per fit, and chooses the defaults as
``make_recommended`` itself was chosen: by the worst case over the datasets.

Protocol
--------
* **Datasets** (``bench_compare.load_folds``): PRECOG (the 8 bundled subjects,
  leave one subject out, ``joints="full20"``), UTKinect (leave one subject out,
  ``"full20"``; its folder under ``$SKGESTURE_SHARED_DATA``, skipped with a note
  when absent) and the synthetic split of ``bench_methods`` (100 training, 50
  test streams of unseen subjects, ``"paper11"``) (``JOINTS``).
* **Fits**: ``make_recommended(joints=..., random_state=seed)`` per dataset,
  seed (``SEEDS`` = 0, 1, 2) and fold, fitted with ``fps=`` the dataset's rate
  (``data.fps``: PRECOG 30, synthetic 20). UTKinect has one rate per stream
  (its rows are irregular, 5-10 a second); as in ``bench_compare`` the model
  sees its rows as frames: fitted without ``fps`` (``fps_`` = 30) and
  predicted without resampling.
* **Probabilities**, at the model's rate: every input at another rate than
  ``model.fps_`` is resampled to it (``skgesture._rate.resample``), then
  ``model[:-1].transform`` and the tagger's ``_proba`` give the raw
  probabilities and the untracked rows, as ``predict`` computes them. For the
  test sequences of every fit and, for the PRECOG models only, for the
  out-of-vocabulary negatives of ``bench_oov.load_negatives`` (MSR Action3D
  without punches and kicks, MSRC-12 without its kick, UTKinect; each stream at
  its own rate).
* **Decoding** (no refit): for every setting of ``GRID`` (smooth_span x min_run
  x min_confidence x min_duration x max_duration x viterbi_penalty x
  max_novelty, 576 settings; max_duration and max_novelty None are no limit,
  viterbi_penalty None the arg-max path; ``viterbi_duration`` stays the
  tagger's default, 0.7, and ``viterbi_lag`` too, 6, ``namer_weight``,
  0.75, and ``max_namer_rest``, all in ``VARY``; the
  current default is added when the grid lacks it; ``--vary NAME`` instead
  varies ``NAME`` alone over ``VARY``, the others at the default's values:
  ``--vary viterbi_lag`` gives the Jaccard of every lag, the decoding's share
  of the live delay) the parameters
  are set on the tagger (``tagger.set_params``) and ``tagger._decode(p,
  untracked, novelty)`` gives the labels (``novelty``: the cell's novelty of
  every frame, read through ``CachedNovelty``; the run namer's scores of every
  run that the settings' paths give, computed in the fit (``namer_table``)
  and read through ``CachedNamer``), ``segments_with_confidence``
  the events; labels go back to the input's frames with ``frames_back``,
  events with ``segments_back`` (as ``GesturePipeline.predict`` /
  ``predict_segments`` do). ``max_gap`` and the
  smoothing method stay the model's.
* **Scores** per setting: the official ChaLearn 2014 Jaccard index
  (``jaccard_index``) per dataset, the mean over folds, then the mean and sd
  (ddof=1) over seeds; its **change** from the current default (the tagger's
  parameters as ``make_recommended()`` sets them), per dataset the mean over
  seeds of the paired differences, and the **worst change**, the smallest over
  the datasets; the **recall** of true PRECOG gestures (those of at least
  ``MIN_TRUE_LENGTH`` = 5 frames found by an event of the same class at IoU >=
  ``MIN_IOU`` = 0.5, ``event_recall``; pooled over the folds of a seed, then
  mean and sd over seeds), and why the others were missed (``event_misses``:
  the share of the gestures of every seed found, named wrongly, merged with
  another, with boundaries too far off, or with no event; the default's shares
  in the notes); and the **false events per minute** on the pooled
  negatives of the PRECOG models (every event is false; minutes are each
  stream's rows over its rate, as in ``bench_oov``; mean over folds, then over
  seeds).
* **Chosen** setting: of the settings whose worst change is at least
  ``-TOLERANCE`` (-0.005), the one with the fewest false events per minute
  (ties: the larger worst change). The default qualifies, so there always is
  one; it is printed under the table.
* **Figure** (``decoding.png``, ``decoding_quick.png`` in quick mode): false
  events per minute against the worst change, one point per setting; the rows
  and notes beside it as ``decoding.json`` (``decoding_quick.json``).

Every fit's probabilities are cached as a compressed ``.npz`` (float32: the
network's softmax is float32, so nothing is lost) under
``bench_results/decoding/``, keyed by the dataset's content, fold, seed and
joints, and by a code key: ``bench_oov._code_key`` (the skgesture sources,
``bench_oov.py``, the library versions and the data sizes) with the code of
the functions here that build, fit and run the model (``CACHED_BY``). The
grid and the scoring are not in the key: changing them refits nothing. The
output folder is ``run(out_dir=...)``, else ``$SKG_BENCH_DECODING_DIR``, else
``bench_results/``. A full run is 57 fits (19 folds x 3 seeds), about 80 s
each on a 2-core machine, then about 0.07 s per setting and fit to decode;
cached fits are reused.

Quick mode (``run(quick=True)``, ``--quick``): synthetic data only, no shared
data, a few seconds: two tiny datasets (``QUICK_DATASETS``) of 12
``make_gesture_streams`` streams of 4 classes, subject 3 held out; the first
(``bench_oov.quick_data``'s) plays PRECOG's part, with ``bench_oov``'s synthetic
negatives (``synthetic B`` resampled to 15 fps, so that the rate path runs);
``bench_oov.make_model``'s tiny tagger, seed 0, ``QUICK_GRID``. Its cache goes
under the output folder too.

``--background NAME`` fits the variant ``NAME`` of ``BACKGROUNDS`` instead
of the model's own background: ``synthetic`` is
``make_recommended(background="synthetic")`` (24 synthetic negatives made
from every training fold), ``none`` no negatives, the others vary their count
(``share10``: 10 % of the training sequences) and kinds (``nofragment``;
``motion``: random joint motion alone);
each in cache cells and a figure of its own (``bench_background.py`` sets
them side by side). ``--jobs N`` fits the missing cells in N worker
processes, each tagger on ``cpu_count // N`` threads, in cells of their own
(``-t<threads>``). ``--default-only`` decodes the current default alone.
``--set PARAM=VALUE ...`` sets parameters of every model before its fit
(``set_params``, e.g. ``tagger__lookahead=4``), in cells and a figure of
their own (``-set<hash>``), to measure a training parameter on every dataset.

Usage: ``python benchmarks/bench_decoding.py [--quick] [--seeds 0,1,2]
[--datasets precog,utkinect,synthetic] [--out-dir DIR] [--background NAME]
[--jobs N] [--default-only]``, or ``python benchmarks/run.py --only
decoding``.
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import functools
import hashlib
import inspect
import itertools
import json
import os
import platform
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (  # noqa: E402
    _code_only,
    comma_list,
    figure_lines,
    format_table,
    parse_params,
    print_report,
    save_figure,
)
from bench_compare import Folds, data_key, load_folds  # noqa: E402
from bench_oov import (  # noqa: E402
    MIN_IOU,
    MIN_TRUE_LENGTH,
    QUICK_B,
    Negatives,
    _code_key,
    _mean_sd,
    _pm,
    load_negatives,
    make_model,
    quick_data,
)
from joblib import Parallel, delayed  # noqa: E402

import skgesture  # noqa: E402
from skgesture._rate import (  # noqa: E402
    frames_back,
    resample,
    same_rate,
    segments_back,
)
from skgesture._taggers._decoding import segments_with_confidence  # noqa: E402
from skgesture._taggers._namer import namer_scores  # noqa: E402
from skgesture.datasets import (  # noqa: E402
    SyntheticBackground,
    make_background,
    make_gesture_streams,
)
from skgesture.metrics import event_misses, jaccard_index  # noqa: E402
from skgesture.utils import runs  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench_results"
OUT_ENV = "SKG_BENCH_DECODING_DIR"

SEEDS = (0, 1, 2)
QUICK_SEEDS = (0,)
# The datasets and their joints (bench_compare.DATASETS; PRECOG with all 20:
# its vocabulary has kicks). The models of REFERENCE meet the negatives.
JOINTS = {"precog": "full20", "utkinect": "full20", "synthetic": "paper11"}
REFERENCE = "precog"
QUICK_DATASETS = ("quick A", "quick B")
QUICK_REFERENCE = "quick A"
QUICK_NEGATIVE_FPS = 15.0  # synthetic B is tested at this rate (quick mode)

PARAMS = (
    "smooth_span",
    "min_run",
    "min_confidence",
    "min_duration",
    "max_duration",
    "viterbi_penalty",
    "max_novelty",
    "viterbi_lag",
    "viterbi_decision",
    "viterbi_duration",
    "namer_weight",
    "max_namer_rest",
)
GRID = {
    "smooth_span": (1, 5),
    "min_run": (1,),
    "min_confidence": (0.0, 0.5, 0.7, 0.9),
    "min_duration": (0.0, 0.3, 0.5),
    "max_duration": (None, 1.5, 2.5),  # None: no limit
    "viterbi_penalty": (None, 2.0, 5.0, 10.0),  # None: the arg-max path
    "max_novelty": (None, 1.5),  # None: no limit; VARY sweeps it
}
# --vary; viterbi_lag (frames between a frame and its decision, the live
# delay's share of the decoding) stays the default in GRID
VARY = {
    **GRID,
    "max_novelty": (None, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0),
    "viterbi_lag": (0, 1, 2, 3, 4, 6, 8, 12),
    "viterbi_decision": ("frame", "run"),
    "viterbi_duration": (0.5, 0.7, 0.85, 1.0),
    "namer_weight": (0.0, 0.1, 0.25, 0.4, 0.5, 0.75, 1.0),  # 0: no renaming
    # None: the namer's rest is not read
    "max_namer_rest": (None, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.8),
}
QUICK_GRID = {
    "smooth_span": (1, 5),
    "min_run": (1,),
    "min_confidence": (0.0, 0.5, 0.9),
    "min_duration": (0.0, 0.5),
    "max_duration": (None, 2.5),
    "viterbi_penalty": (None, 5.0),
    "max_novelty": (None, 1.5),
}
# --set names that are make_recommended's arguments, not set_params ones
FACTORY_PARAMS = ("features", "lookahead", "background_for")
TOLERANCE = 0.005  # the chosen setting loses at most this Jaccard anywhere
PROBA_DTYPE = np.float32  # of the cache: the network's softmax is float32

COLUMNS = ["mark", *PARAMS]  # then "jaccard <dataset>" per dataset, and TAIL_COLUMNS
TAIL_COLUMNS = ["worst change", "worst on", "recall", "false events/min"]
# Filled by run(): the notes printed under the table (skipped data, protocol).
NOTES = []


# ---------------------------------------------------------------- data


def quick_datasets():
    """``({name: Folds}, {name: Negatives})`` of the quick mode (synthetic).

    ``quick A`` is ``bench_oov.quick_data``'s positives and ``quick B`` 12
    other streams (4 classes, 4 subjects); each holds out subject 3. The
    negatives are ``bench_oov``'s, ``synthetic B`` resampled to
    ``QUICK_NEGATIVE_FPS``.
    """
    pos, negatives = quick_data()
    other = make_gesture_streams(
        n_sequences=12, n_classes=4, n_subjects=4, n_gestures=(3, 5), random_state=4
    )
    out = {}
    for name, data in zip(QUICK_DATASETS, (pos, other)):
        groups = np.asarray(data.groups)
        folds = [("subject3", np.flatnonzero(groups != 3), np.flatnonzero(groups == 3))]
        slug = name.replace(" ", "_")
        out[name] = Folds(slug, f"{name} 9/3", data, folds, data_key(data.X, data.y))
    neg = negatives[QUICK_B]
    negatives[QUICK_B] = Negatives(
        QUICK_B,
        [resample(x, f, QUICK_NEGATIVE_FPS) for x, f in zip(neg.X, neg.fps)],
        np.full(len(neg.X), QUICK_NEGATIVE_FPS),
        f"{neg.how}, resampled to {QUICK_NEGATIVE_FPS:g} fps",
    )
    return out, negatives


def fit_rate(data):
    """The rate a dataset's models are fitted with: ``data.fps`` when it is one
    number, None (rows as frames) when every sequence has its own."""
    fps = getattr(data, "fps", None)
    if fps is None or np.ndim(fps) != 0:
        return None
    return float(fps)


def joints_of(name, quick):
    """The joints of a dataset's models (quick: ``make_model``'s 20)."""
    return "full20" if quick else JOINTS[name]


def true_gestures(segments):
    """The rows ``(class, start, end)`` of at least ``MIN_TRUE_LENGTH`` frames."""
    rows = np.asarray(segments).reshape(-1, 3)
    return rows[rows[:, 2] - rows[:, 1] >= MIN_TRUE_LENGTH]


# ---------------------------------------------------------------- fitting


# The background variants ``--background`` fits instead of the model's own
# (each a ``make(X, y)`` object seeded by the fit's seed, or "none"):
# "synthetic" is make_recommended(background="synthetic") itself; the others
# vary its count (an int, or a share of the training sequences) and its kinds;
# "for": "namer" gives them to the run namer alone (background_for="namer").
NO_FRAGMENT = ("motion", "reversed", "concatenation")
BACKGROUNDS = {
    "none": None,
    "synthetic": {},
    "namer": {"for": "namer"},
    "nofragment": {"kinds": NO_FRAGMENT},
    "share10": {"n_sequences": 0.1},
    "share10-nofragment": {"n_sequences": 0.1, "kinds": NO_FRAGMENT},
    "motion": {"kinds": ("motion",)},
}


class PossibleKinds(SyntheticBackground):
    """``SyntheticBackground`` whose ``kinds`` are the most it asks for: of
    them, those the recordings of the fit can give (``make_background``
    refuses a kind it cannot make; ``kinds=None`` makes every possible one)."""

    def make(self, X, y):
        kinds = self.kinds
        if kinds is not None:
            kinds = [k for k in kinds if _can_make(X, y, k)] or None
        return SyntheticBackground(**{**self.get_params(), "kinds": kinds}).make(X, y)


def _can_make(X, y, kind):
    try:
        make_background(X, y, n_sequences=1, n_frames=2, kinds=(kind,))
    except ValueError as exc:
        if "cannot give" in str(exc):
            return False
        raise
    return True


def background_of(name, seed):
    """The background object of the variant ``name`` (``BACKGROUNDS``)."""
    if name not in BACKGROUNDS:
        raise ValueError(f"unknown background {name!r}; use one of {list(BACKGROUNDS)}")
    if BACKGROUNDS[name] is None:
        return None
    made = skgesture.make_recommended(background="synthetic", random_state=seed)
    params = made.background.get_params()
    own = {k: v for k, v in BACKGROUNDS[name].items() if k != "for"}
    return PossibleKinds(**{**params, **own})


def build_model(joints, seed, quick, background=None, fit_threads=None, params=None):
    """``make_recommended(joints=joints, random_state=seed)`` (quick:
    ``bench_oov.make_model``'s tiny tagger, 20 joints) with the background
    variant ``background`` (``background_of``; None: the model's own);
    ``fit_threads`` (None: the model's) sets the tagger's; ``params`` (a
    dict or None) are set last (``set_params``), but for those of
    ``FACTORY_PARAMS``, which are ``make_recommended``'s arguments."""
    params = dict(params or {})
    # make_recommended's own arguments (--set features=descriptor+joints)
    factory = {k: params.pop(k) for k in FACTORY_PARAMS if k in params}
    if quick:
        if factory:
            raise ValueError(f"quick mode builds no make_recommended: {factory}")
        model = make_model(seed, quick=True)
    else:
        model = skgesture.make_recommended(joints=joints, random_state=seed, **factory)
    if background is not None:
        model.set_params(
            background=background_of(background, seed),
            background_for=(BACKGROUNDS[background] or {}).get("for", "model"),
        )
    if fit_threads is not None:
        model.set_params(tagger__fit_threads=fit_threads)
    if params:
        model.set_params(**params)
    return model


def model_rate_proba(model, X, rates):
    """The tagger's raw probabilities, untracked rows and novelty at the
    model's rate.

    A sequence whose rate (None: rows as frames) differs from ``model.fps_``
    is resampled to it first; then ``model[:-1].transform``, the tagger's
    ``_proba``, as ``predict`` does, and the novelty of every frame for every
    class (``tagger.novelty_.score``, what ``max_novelty`` reads). Returns a
    list of ``(proba, untracked, novelty)``, proba and novelty as
    ``PROBA_DTYPE``.
    """
    fps = model.fps_
    Xm = [x if r is None else resample(x, r, fps) for x, r in zip(X, rates)]
    F = model[:-1].transform(Xm)
    tagger = model[-1]
    proba, untracked = tagger._proba(F)
    return [
        (
            np.asarray(p, dtype=PROBA_DTYPE),
            np.asarray(u, dtype=bool),
            np.asarray(tagger.novelty_.score(f), dtype=PROBA_DTYPE),
            *namer_table(tagger, p, u, f),
        )
        for p, u, f in zip(proba, untracked, F)
    ]


def path_settings():
    """The settings of ``GRID`` and ``VARY`` that move the runs the run
    rules judge (smoothing, path, ``min_run``), the others at the default."""
    default = current_default()
    moving = (
        "smooth_span",
        "min_run",
        "viterbi_penalty",
        "viterbi_lag",
        "viterbi_decision",
        "viterbi_duration",
    )
    grid = [dict(zip(moving, v)) for v in itertools.product(
        *[GRID.get(p, (default[p],)) for p in moving])]  # fmt: skip
    vary = [{p: v} for p in moving for v in VARY.get(p, ())]
    out = []
    for setting in grid + vary:
        full = {p: setting.get(p, default[p]) for p in moving}
        if full not in out:
            out.append(full)
    return out


def namer_table(tagger, proba, untracked, features):
    """The run namer's scores of every run that a setting of
    :func:`path_settings` gives (``tagger._path``, the runs the rules judge): ``(spans,
    scores)``, ``(n_runs, 2)`` start and end rows and ``(n_runs, n_classes)``
    scores (:func:`skgesture._taggers._namer.namer_scores`), empty without a
    namer; :class:`CachedNamer` reads them back."""
    n_classes = len(tagger.classes_)
    if getattr(tagger, "namer_", None) is None:
        return np.zeros((0, 2), np.int32), np.zeros((0, n_classes), PROBA_DTYPE)
    saved = tagger.get_params()
    rows = np.asarray(features, dtype=np.float64)
    p = np.asarray(proba, dtype=np.float64)
    spans = set()
    try:
        for setting in path_settings():
            tagger.set_params(**setting)
            starts, ends, values = runs(tagger._path(p, untracked))
            spans |= {(s, e) for s, e, v in zip(starts, ends, values) if v != 0}
    finally:
        tagger.set_params(**saved)
    spans = np.array(sorted(spans), dtype=np.int32).reshape(-1, 2)
    module = tagger.namer_.module_
    scores = [
        namer_scores(
            module, tagger.namer_mean_, tagger.namer_scale_, rows[s:e], n_classes
        )
        for s, e in spans.tolist()
    ]
    return spans, np.asarray(scores, dtype=PROBA_DTYPE).reshape(-1, n_classes)


def fit_cell(make, X_tr, y_tr, X_te, rate, negatives):
    """Fit ``make()`` and return its probabilities (a cache cell).

    ``{"meta": {"classes", "class_lengths", "fps", "input_fps", "fit_s",
    "proba_s", "negatives"}, "test": [(proba, untracked, novelty), ...],
    "negatives": {name: [(proba, untracked, novelty), ...]}}``; ``rate`` is
    the rate of the training and test sequences (None: rows as frames).
    """
    model = make()
    t0 = time.perf_counter()
    model.fit(X_tr, y_tr, fps=rate)
    fit_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    test = model_rate_proba(model, X_te, [rate] * len(X_te))
    neg = {n: model_rate_proba(model, d.X, d.fps) for n, d in negatives.items()}
    tagger = model.named_steps["tagger"]
    meta = {
        "classes": np.asarray(tagger.classes_).tolist(),
        "class_lengths": np.asarray(tagger.class_lengths_, dtype=float).tolist(),
        "class_long_lengths": np.asarray(
            tagger.class_long_lengths_, dtype=float
        ).tolist(),
        "fps": float(model.fps_),
        "input_fps": rate,
        "fit_s": fit_s,
        "proba_s": time.perf_counter() - t0,
        "negatives": list(neg),
        "namer_rest": getattr(tagger, "namer_rest_", None),
    }
    return {"meta": meta, "test": test, "negatives": neg}


CACHED_BY = (build_model, model_rate_proba, fit_cell)


# ---------------------------------------------------------------- cache


def cache_key(sizes):
    """``bench_oov._code_key(sizes)`` with the code of ``CACHED_BY``."""
    h = hashlib.sha1(_code_key(sizes).encode())
    for func in CACHED_BY:
        h.update(_code_only(inspect.getsource(func)))
    return h.hexdigest()[:12]


def params_key(params):
    """A short, stable name of the ``--set`` parameters (``""`` without)."""
    if not params:
        return ""
    text = json.dumps(params, sort_keys=True, default=repr)
    return "-set" + hashlib.sha1(text.encode()).hexdigest()[:8]


def _cell_path(
    cache_dir,
    folds,
    joints,
    seed,
    fold_id,
    key,
    background=None,
    fit_threads=None,
    params=None,
):
    bg = "" if background is None else f"-bg{background}"
    bg += "" if fit_threads is None else f"-t{fit_threads}"
    bg += params_key(params)
    return (
        cache_dir
        / f"{folds.name}-{folds.key}"
        / f"{joints}{bg}-seed{seed}-{fold_id}-{key}.npz"
    )


def save_cell(path, cell):
    """Write a cell as one compressed ``.npz`` (``meta`` a JSON string)."""
    arrays = {"meta": np.array(json.dumps(cell["meta"]))}
    parts = [("test", cell["test"])]
    parts += [
        (f"neg{k}", cell["negatives"][n]) for k, n in enumerate(cell["negatives"])
    ]
    for prefix, rows in parts:
        for i, (p, u, n, ms, mv) in enumerate(rows):
            arrays[f"{prefix}_p{i}"], arrays[f"{prefix}_u{i}"] = p, u
            arrays[f"{prefix}_n{i}"] = n
            arrays[f"{prefix}_ms{i}"], arrays[f"{prefix}_mv{i}"] = ms, mv
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    tmp.replace(path)


def load_cell(path):
    """The cell of :func:`save_cell`."""
    with np.load(path, allow_pickle=False) as f:
        meta = json.loads(str(f["meta"]))

        def rows(prefix):
            n = sum(1 for k in f.files if k.startswith(f"{prefix}_p"))
            return [
                tuple(f[f"{prefix}_{a}{i}"] for a in ("p", "u", "n", "ms", "mv"))
                for i in range(n)
            ]

        neg = {n: rows(f"neg{k}") for k, n in enumerate(meta["negatives"])}
        return {"meta": meta, "test": rows("test"), "negatives": neg}


# ---------------------------------------------------------------- decoding


def fmt_value(value):
    """A parameter's value in the table: ``"off"`` for None."""
    if value is None:
        return "off"
    return value if isinstance(value, str) else f"{value:g}"


def settings_of(grid):
    """Every setting of ``grid`` (dicts over ``PARAMS``), the current default
    added when missing; and the index of the default."""
    default = current_default()
    levels = [grid.get(p, (default[p],)) for p in PARAMS]  # absent: the default's
    settings = [dict(zip(PARAMS, v)) for v in itertools.product(*levels)]
    if default not in settings:
        settings.append(default)
    return settings, settings.index(default)


def current_default():
    """The decoding parameters of ``make_recommended()``'s tagger."""
    params = skgesture.make_recommended().named_steps["tagger"].get_params()
    return {p: params[p] for p in PARAMS}


def decoder(make, meta):
    """The tagger of ``make()`` with the fitted state its decoding reads.

    ``_decode`` needs ``classes_``, ``class_lengths_``,
    ``class_long_lengths_`` and (with the namer's rest rule) ``namer_rest_``
    of the fitted tagger (skgesture/_taggers/_base.py), all in the cell, so a
    cached fit decodes without its network.
    """
    tagger = make().named_steps["tagger"]
    tagger.classes_ = np.asarray(meta["classes"])
    tagger.class_lengths_ = np.asarray(meta["class_lengths"], dtype=float)
    tagger.class_long_lengths_ = np.asarray(meta["class_long_lengths"], dtype=float)
    tagger.novelty_ = CachedNovelty()
    if meta.get("namer_rest") is not None:
        tagger.namer_rest_ = int(meta["namer_rest"])
    return tagger


class CachedNamer:
    """Stands in for a fitted tagger's run namer in :func:`decode_back`: the
    scores of :func:`namer_table` looked up by the run's rows, which
    :func:`decode_back` gives as the cell's novelty with each row's index in
    a last column."""

    def __init__(self, spans, scores):
        self.table = {
            (int(s), int(e)): np.asarray(v, dtype=np.float64)
            for (s, e), v in zip(spans, scores)
        }

    def score(self, rows):
        span = (int(rows[0, -1]), int(rows[-1, -1]) + 1)
        if span not in self.table:
            raise KeyError(
                f"no cached namer scores for the run of rows {span}: a decoding "
                "setting outside path_settings(); refit the cell"
            )
        return self.table[span]


class CachedNovelty:
    """Stands in for a fitted tagger's ``novelty_`` in :func:`decode_back`:
    the "features" it is given are the cell's novelty of every frame for
    every class (``model_rate_proba``), so ``score(rows, k)`` is column
    ``k``, the scores ``PoseNovelty.score`` gave."""

    def score(self, rows, k=None):
        rows = np.asarray(rows, dtype=np.float64)
        return rows if k is None else rows[:, k]


def decode_back(tagger, cached, rate, fps, n_frames):
    """Labels and events ``(class, start, end, confidence)`` in input frames
    of one cached sequence ``(proba, untracked, novelty, spans, scores)``."""
    proba, untracked, novelty, spans, scores = cached
    p = np.asarray(proba, dtype=np.float64)  # as predict decodes them
    rows = np.column_stack([novelty, np.arange(len(p))])  # + each row's index
    namer = CachedNamer(spans, scores)
    used = len(spans) and tagger._reads_namer()
    tagger._namer_rule = lambda: namer.score if used else None
    labels = tagger._decode(p, untracked, rows)
    segs = segments_with_confidence(labels, p, tagger.classes_)
    if rate is None or same_rate(rate, fps):
        return labels, segs
    return (
        frames_back(labels, rate, fps, n_frames),
        segments_back(segs, rate, fps, n_frames, n_out=len(p)),
    )


def score_cell(cell, tagger, settings, y_te, truth, negatives):
    """Jaccard, gestures found and false events of every setting on one fit.

    ``truth`` (true gestures per test sequence) is None but for the reference
    dataset. Returns one ``{"jaccard", "found", "gestures", "events": {name:
    count}}`` per setting.
    """
    meta = cell["meta"]
    fps, rate = meta["fps"], meta["input_fps"]
    out = []
    for setting in settings:
        tagger.set_params(**setting)
        decoded = [
            decode_back(tagger, c, rate, fps, len(y))
            for c, y in zip(cell["test"], y_te)
        ]
        score = {"jaccard": float(jaccard_index(y_te, [d[0] for d in decoded]))}
        if truth is not None:
            n = sum(len(t) for t in truth)
            # "found" is event_recall's count (the same rule, one pass)
            misses = event_misses(truth, [d[1] for d in decoded], min_iou=MIN_IOU)
            score.update(found=float(misses["found"]), gestures=n, misses=misses)
        score["events"] = {
            name: sum(
                len(decode_back(tagger, c, f, fps, len(x))[1])
                for c, x, f in zip(
                    cell["negatives"][name], negatives[name].X, negatives[name].fps
                )
            )
            for name in cell["negatives"]
        }
        out.append(score)
    return out


# ---------------------------------------------------------------- summary


def summarise(scores, settings, default, reference, negatives):
    """One row per setting from ``scores[dataset][(seed, fold_id)][k]``."""
    datasets = list(scores)
    seeds = {d: sorted({s for s, _ in scores[d]}) for d in datasets}

    def per_seed(d, k, value):
        return [
            np.mean([value(r[k]) for (s, _), r in scores[d].items() if s == seed])
            for seed in seeds[d]
        ]

    jac = {
        d: [per_seed(d, k, lambda c: c["jaccard"]) for k in range(len(settings))]
        for d in datasets
    }
    minutes = sum(n.minutes for n in negatives.values())
    rows = []
    for k, setting in enumerate(settings):
        row = {
            "table": "decoding",
            "setting": dict(setting),
            "label": ", ".join(f"{p}={fmt_value(setting[p])}" for p in PARAMS),
            "default": k == default,
            "chosen": False,
            "jaccard": {},
            "jaccard_sd": {},
            "jaccard_change": {},
        }
        for d in datasets:
            row["jaccard"][d], row["jaccard_sd"][d] = _mean_sd(jac[d][k])
            change = np.subtract(jac[d][k], jac[d][default])
            row["jaccard_change"][d] = float(np.mean(change))
        worst = min(datasets, key=lambda d: row["jaccard_change"][d])
        row["worst_change"] = row["jaccard_change"][worst]
        row["worst_dataset"] = worst
        row.update(_reference_scores(scores.get(reference), k, negatives, minutes))
        row["runs"] = {
            d: f"{len(seeds[d])}x{len(scores[d]) // len(seeds[d])}" for d in datasets
        }
        rows.append(row)
    choose(rows)
    rows.sort(key=lambda r: (-r["worst_change"], _events_key(r)))
    return rows


def _reference_scores(cells, k, negatives, minutes):
    """Recall and false events per minute of setting ``k`` (NaN without)."""
    nan = float("nan")
    out = {
        "recall": nan,
        "recall_sd": nan,
        "gestures": 0,
        "events_per_min": nan,
        "events_per_min_sd": nan,
        "events_per_min_by": {},
        "events": nan,
        "minutes": minutes,
        "misses": {},
    }
    if not cells:
        return out
    by_seed = {}
    for (seed, _), r in cells.items():
        by_seed.setdefault(seed, []).append(r[k])
    runs = list(by_seed.values())
    gestures = [sum(c["gestures"] for c in run) for run in runs]
    out["recall"], out["recall_sd"] = _mean_sd(
        [
            sum(c["found"] for c in run) / g if g else nan
            for run, g in zip(runs, gestures)
        ]
    )
    out["gestures"] = int(gestures[0])
    pooled = [c["misses"] for run in runs for c in run]  # every seed's gestures
    total = sum(sum(m.values()) for m in pooled)
    out["misses"] = {
        outcome: sum(m[outcome] for m in pooled) / total if total else nan
        for outcome in pooled[0]
    }
    if negatives:
        events = [[sum(c["events"].values()) for c in run] for run in runs]
        out["events"] = float(np.mean([np.mean(e) for e in events]))
        out["events_per_min"], out["events_per_min_sd"] = _mean_sd(
            [np.mean(e) / minutes for e in events]
        )
        out["events_per_min_by"] = {
            n: float(
                np.mean([np.mean([c["events"][n] for c in run]) for run in runs])
                / d.minutes
            )
            for n, d in negatives.items()
        }
    return out


def _events_key(row):
    ev = row["events_per_min"]
    return ev if ev == ev else float("inf")


def choose(rows):
    """Mark and return the chosen row: of those whose worst change is at least
    ``-TOLERANCE``, the fewest false events per minute (ties: the larger worst
    change, then the earlier setting)."""
    eligible = [r for r in rows if r["worst_change"] >= -TOLERANCE]
    best = min(eligible, key=lambda r: (_events_key(r), -r["worst_change"]))
    best["chosen"] = True
    return best


# ---------------------------------------------------------------- running


def _datasets(quick, names):
    """``({name: Folds}, negatives)``; notes the datasets not on this machine."""
    known = QUICK_DATASETS if quick else tuple(JOINTS)
    names = tuple(names or known)
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError(f"unknown datasets {unknown}; use {', '.join(known)}")
    if quick:
        folds, negatives = quick_datasets()
        return {n: folds[n] for n in names}, negatives
    folds = {}
    for name in names:
        found = load_folds(name, quick=False)
        if found is None:
            NOTES.append(f"{name}: recordings not found, skipped")
            print(f"  [decoding] {name}: recordings not found, skipped", flush=True)
        else:
            folds[name] = found
    negatives = load_negatives(NOTES) if REFERENCE in folds else {}
    return folds, negatives


def run(
    quick=False,
    seeds=None,
    datasets=None,
    grid=None,
    out_dir=None,
    background=None,
    n_jobs=1,
    params=None,
):
    """Fit what is missing, decode every setting, return the rows (notes in
    ``NOTES``).

    Parameters
    ----------
    quick : bool, default=False
        Two tiny synthetic datasets and a tiny tagger (seconds; no shared data).
    seeds : sequence of int or None, default=None
        Seeds; None: ``SEEDS`` (quick: ``QUICK_SEEDS``).
    datasets : sequence of str or None, default=None
        Names of ``JOINTS`` (quick: of ``QUICK_DATASETS``); None: all.
    grid : dict or None, default=None
        Values of every parameter of ``PARAMS`` (a parameter left out keeps
        the default's value, so ``{}`` decodes the default alone); None:
        ``GRID`` (quick: ``QUICK_GRID``). The cache does not depend on it.
    out_dir : path-like or None, default=None
        Folder of the figure and of the cache (``<out_dir>/decoding``); None:
        ``$SKG_BENCH_DECODING_DIR`` or ``bench_results/``.
    background : None or str, default=None
        A name of ``BACKGROUNDS``: the background of every fit instead of
        ``make_recommended``'s own (None): ``"synthetic"`` is
        ``make_recommended(background="synthetic")``, ``"none"`` no
        background, the others variants of the synthetic negatives (their
        own cache cells, their own figure).
    n_jobs : int, default=1
        Fits run at once, in worker processes (joblib). With more than one,
        each tagger trains on ``cpu_count // n_jobs`` threads
        (``tagger__fit_threads``; on 2 cores two one-thread fits at once
        finish 1.6 times sooner than one after the other on two threads),
        in cache cells of their own (``-t<threads>``).
    params : dict or None, default=None
        ``set_params`` of every model before its fit (``--set``), e.g.
        ``{"tagger__lookahead": 4}``: cache cells and a figure of their own
        (``-set<hash>``, ``params_key``); the decoding grid applies as
        without them.

    Returns
    -------
    list of dict
        ``table="decoding"`` rows, one per setting, sorted by worst change
        (largest first), with ``setting`` (``{param: value}``), ``label``,
        ``default`` and ``chosen`` (bool), ``jaccard``, ``jaccard_sd`` and
        ``jaccard_change`` (``{dataset: value}``), ``worst_change``,
        ``worst_dataset``, ``recall`` (``recall_sd``, ``gestures`` per seed),
        ``misses`` (``{outcome: share}`` of ``event_misses``),
        ``events_per_min`` (``events_per_min_sd``, ``events_per_min_by``
        negative dataset), ``events`` (per run), ``minutes`` and ``runs``
        (``{dataset: "seedsxfolds"}``); then one ``table="figure"`` row
        (``path``).
    """
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, int) or n_jobs < 1:
        raise ValueError(f"n_jobs must be an int >= 1 (fits at once), got {n_jobs!r}")
    NOTES.clear()
    out_dir = Path(out_dir or os.environ.get(OUT_ENV) or RESULTS)
    seeds = tuple(seeds) if seeds is not None else (QUICK_SEEDS if quick else SEEDS)
    reference = QUICK_REFERENCE if quick else REFERENCE
    folds_of, negatives = _datasets(quick, datasets)
    if not folds_of:
        raise ValueError("no dataset to run on (none found)")
    settings, default = settings_of(
        grid if grid is not None else (QUICK_GRID if quick else GRID)
    )
    cache_dir = out_dir / "decoding"
    fit_threads = None if n_jobs == 1 else max(1, (os.cpu_count() or 1) // n_jobs)
    variant = (background, fit_threads, params)  # what a cell's name adds to its key
    plan, missing = [], []  # every cell, and the ones to fit
    for name, folds in folds_of.items():
        joints = joints_of(name, quick)
        negs = negatives if name == reference else {}
        rate = fit_rate(folds.data)
        sizes = {
            "data": folds.key,
            "quick": quick,
            "rate": rate,
            "dtype": np.dtype(PROBA_DTYPE).name,
            "negatives": {n: [len(x) for x in d.X] for n, d in negs.items()},
        }
        key = cache_key(sizes)
        for seed in seeds:
            make = functools.partial(
                build_model, joints, seed, quick, background, fit_threads, params
            )
            info = {"dataset": folds.name, "joints": joints, "seed": seed, "key": key}
            for fold in folds.folds:
                path = _cell_path(
                    cache_dir, folds, joints, seed, fold[0], key, *variant
                )
                plan.append((name, seed, fold, make, path))
                if not path.exists():
                    missing.append((name, folds, fold, make, rate, negs, path, info))
    if missing:
        verbose = not quick
        Parallel(n_jobs=n_jobs)(
            delayed(_fit_and_save)(*task, verbose=verbose) for task in missing
        )
    scores = {name: {} for name in folds_of}
    for name, seed, (fold_id, _, te), make, path in plan:
        data = folds_of[name].data
        cell = load_cell(path)
        truth = None
        if name == reference:
            truth = [true_gestures(data.segments[i]) for i in te]
        negs = negatives if name == reference else {}
        scores[name][(seed, fold_id)] = score_cell(
            cell,
            decoder(make, cell["meta"]),
            settings,
            [data.y[i] for i in te],
            truth,
            negs,
        )
    rows = summarise(scores, settings, default, reference, negatives)
    _notes(rows, folds_of, negatives, reference, seeds, quick)
    if background is not None:
        NOTES.append(f"every fit: make_recommended(background={background!r})")
    if params:
        NOTES.append(f"every fit: set_params({params!r}) ({params_key(params)[1:]})")
    stem = "decoding" + ("" if background is None else f"_bg{background}")
    stem += params_key(params).replace("-set", "_set")
    stem += "_quick" if quick else ""
    figure = plot_settings(rows, out_dir / f"{stem}.png")
    with open(out_dir / f"{stem}.json", "w") as fh:  # the rows, to re-plot or quote
        json.dump({"rows": rows, "notes": NOTES}, fh, indent=1)
    rows.append({"table": "figure", "path": str(figure)})
    return rows


def _fit_and_save(name, folds, fold, make, rate, negatives, path, info, verbose):
    """Fit one cache cell (``fit_cell``) and write it to ``path``."""
    fold_id, tr, te = fold
    data = folds.data
    X_tr, y_tr = [data.X[i] for i in tr], [data.y[i] for i in tr]
    X_te = [data.X[i] for i in te]
    cell = fit_cell(make, X_tr, y_tr, X_te, rate, negatives)
    cell["meta"].update(
        fold=fold_id,
        machine=f"{platform.node()} {platform.machine()}",
        when=time.strftime("%Y-%m-%d %H:%M:%S"),
        **info,
    )
    save_cell(path, cell)
    if verbose:
        print(
            f"  [decoding] {name} seed {info['seed']} {fold_id}: fit "
            f"{cell['meta']['fit_s']:.0f} s",
            flush=True,
        )


def _notes(rows, folds_of, negatives, reference, seeds, quick):
    mode = "quick" if quick else "full"
    NOTES.append(
        f"protocol ({mode}): seeds {list(seeds)}; Jaccard = mean over folds, then "
        "mean ± sd over seeds; change = paired difference from the current default "
        "(mean over seeds); worst = the smallest change over the datasets"
    )
    for name, folds in folds_of.items():
        rate = fit_rate(folds.data)
        how = f"{rate:g} fps" if rate else "rows as frames (one rate per stream)"
        joints = joints_of(name, quick)
        NOTES.append(f"{name}: {folds.label}, joints={joints}, {how}")
    if reference in folds_of:
        NOTES.append(
            f"recall: true {reference} gestures >= {MIN_TRUE_LENGTH} frames found "
            f"by an event of the same class at IoU >= {MIN_IOU}; false events: every "
            f"event of the {reference} models on the pooled negatives"
        )
    for name, data in negatives.items():
        NOTES.append(f"{name}: {data.how}, {data.minutes:.1f} minutes")
    default = next(r for r in rows if r["default"])
    if default["misses"]:
        shares = ", ".join(
            f"{outcome.replace('_', ' ')} {share:.3f}"
            for outcome, share in default["misses"].items()
        )
        NOTES.append(
            f"true {reference} gestures under the current default, pooled over "
            f"seeds (event_misses: why each missed one was missed): {shares}"
        )
    chosen = next(r for r in rows if r["chosen"])
    NOTES.append(
        f"chosen (worst change >= -{TOLERANCE}, then fewest false events/min): "
        f"{chosen['label']}: worst change {chosen['worst_change']:+.4f} "
        f"({chosen['worst_dataset']}), {chosen['events_per_min']:.2f} false "
        f"events/min, recall {chosen['recall']:.3f}; current default "
        f"{default['label']}: {default['events_per_min']:.2f} false events/min, "
        f"recall {default['recall']:.3f}"
    )


# ---------------------------------------------------------------- output


def plot_settings(rows, path):
    """False events per minute against the worst change, a point per setting."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if r.get("table") == "decoding"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    x = [r["worst_change"] for r in rows]
    y = [
        r["events_per_min"] if r["events_per_min"] == r["events_per_min"] else 0.0
        for r in rows
    ]
    ax.scatter(x, y, s=18, color="C0", label="a setting")
    for r, xi, yi in zip(rows, x, y):
        short = ", ".join(f"{p} {fmt_value(r['setting'][p])}" for p in PARAMS)
        short = textwrap.fill(short, 60, subsequent_indent="  ")
        if r["default"]:
            label = f"current default: {short}"
            ax.plot(xi, yi, "s", ms=10, mfc="none", color="C3", label=label)
        if r["chosen"]:
            label = f"chosen: {short}"
            ax.plot(xi, yi, "o", ms=13, mfc="none", color="C2", label=label)
    ax.axvline(-TOLERANCE, color="grey", ls=":", lw=1)
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_ylim(0, 1.5 * max(y + [1.0]))
    ax.set_xlabel("worst-case Jaccard change from the current default")
    ax.set_ylabel("false gesture events per minute")
    ax.set_title("decoding settings (dotted: the tolerance)")
    ax.legend(fontsize=7, loc="lower center")
    fig.tight_layout()
    return save_figure(fig, path)


def format_tables(rows, title="Decoding defaults by their worst case"):
    """The settings, sorted by worst change, and the figure's path."""
    table = [r for r in rows if r.get("table") == "decoding"]
    datasets = list(table[0]["jaccard"]) if table else []
    lines = []
    for r in table:
        mark = [m for m in ("default", "chosen") if r[m]]
        line = {"mark": ", ".join(mark)}
        line.update({p: fmt_value(r["setting"][p]) for p in PARAMS})
        for d in datasets:
            line[f"jaccard {d}"] = _pm(r["jaccard"][d], r["jaccard_sd"][d], 3)
        line["worst change"] = f"{r['worst_change']:+.4f}"
        line["worst on"] = "" if r["default"] else r["worst_dataset"]
        line["recall"] = _pm(r["recall"], r["recall_sd"], 3)
        line["false events/min"] = _pm(r["events_per_min"], r["events_per_min_sd"], 2)
        lines.append(line)
    columns = COLUMNS + [f"jaccard {d}" for d in datasets] + TAIL_COLUMNS
    return format_table(lines, columns, title) + figure_lines(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="synthetic smoke run")
    parser.add_argument(
        "--seeds", default=None, help="comma-separated seeds (default 0,1,2)"
    )
    parser.add_argument(
        "--datasets", default=None, help="comma-separated: precog,utkinect,synthetic"
    )
    parser.add_argument(
        "--out-dir", default=None, help="figure and cache folder (bench_results/)"
    )
    parser.add_argument(
        "--background",
        choices=list(BACKGROUNDS),
        default=None,
        help="fit this background variant instead of the model's own (BACKGROUNDS)",
    )
    parser.add_argument(
        "--default-only",
        action="store_true",
        help="decode with the current default alone (to compare fits, not decodings)",
    )
    parser.add_argument(
        "--vary",
        default=None,
        help="comma-separated parameters of PARAMS: the default with these "
        "alone varied over VARY (a smaller grid)",
    )
    parser.add_argument(
        "--set",
        nargs="+",
        default=[],
        metavar="PARAM=VALUE",
        help="set_params of every model before its fit (cells of their own); "
        "features, lookahead and background_for go to make_recommended",
    )
    parser.add_argument(
        "--jobs", type=int, default=1, help="fits at once (worker processes)"
    )
    args = parser.parse_args(argv)
    grid = None
    if args.default_only:
        grid = {}
    elif args.vary:
        unknown = [p for p in comma_list(args.vary) if p not in VARY]
        if unknown:
            parser.error(f"--vary: unknown parameters {unknown}; use {list(PARAMS)}")
        values = {**VARY, **QUICK_GRID} if args.quick else VARY
        grid = {p: values[p] for p in comma_list(args.vary)}
    rows = run(
        quick=args.quick,
        seeds=[int(s) for s in comma_list(args.seeds)] if args.seeds else None,
        datasets=comma_list(args.datasets),
        grid=grid,
        out_dir=args.out_dir,
        background=args.background,
        n_jobs=args.jobs,
        params=parse_params(args.set) or None,
    )
    print_report(rows, format_tables, NOTES)


if __name__ == "__main__":
    main()
