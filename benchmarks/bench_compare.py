"""skgesture's methods beside the practitioners' peers of issue 8 (section ``compare``).

In one run and on the same folds: the forest baseline, Methods A, B, C (CPU
default), the recommended model (``skgesture.make_recommended``, when it exists)
and the four peers of ``_peers.py`` (GRU, HGB, seglearn, MiniRocket), on

* PRECOG, leave one subject out over the 8 bundled subjects, with the 20 joints
  and with the paper's 11 (``joints="full20"`` / ``"paper11"``);
* UTKinect (the 20 streams of ``../shared/data/utkinect_action3d``: 10 daily
  actions, continuous, 10 subjects), leave one subject out, 20 joints. Its rows
  are irregular (5-10 a second); every model sees rows as frames, as the peers do;
* the synthetic streams of ``bench_methods.py`` (100 training, 50 test streams of
  10 unseen subjects, the paper's 11 joints).

``format_tables`` prints the table and, under it, the **margins**: for each
dataset, each skgesture model's Jaccard minus the best peer's (the peers being
the rows of family ``peer`` measured on that dataset), and the worst case over
the datasets, the number by which the recommended model is chosen
(docs/choosing.md).

Every (dataset, joints, method, seed, fold) result is a JSON file under
``bench_results/compare/``, keyed by the method's parameters, the code it runs
(hash of the skgesture sources, or of ``_peers.py``) and the library versions, so a
rerun computes only what is missing. Runs are serial (fit timings are not shared
with a second worker). The table is the mean over seeds of the mean over folds;
``seed_sd`` is the standard deviation (ddof=1) of the seeds' mean Jaccards,
``subject_range`` the min-max over subjects of their seed-mean Jaccard.

Usage::

    python benchmarks/bench_compare.py [--quick] [--methods M,...]
        [--datasets precog,utkinect,synthetic] [--joints full20,paper11] [--seeds 0,1,2]
        [--no-compute] [--cache-dir DIR] [--list]
"""

import argparse
import functools
import hashlib
import json
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (  # noqa: E402
    format_table,
    load_utkinect_quiet,
    shared_data_dir,
    source_key,
)
from _peers import PEERS, have_seglearn  # noqa: E402
from bench_methods import (  # noqa: E402
    evaluate,
    method_factories,
    precog_folds,
    split_data,
    synthetic_split,
)

import skgesture  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
CACHE_DIR = ROOT / "bench_results" / "compare"
SEEDS = (0, 1, 2)
DATASETS = {
    "precog": ("full20", "paper11"),
    "utkinect": ("full20",),
    "synthetic": ("paper11",),
}
COLUMNS = [
    "data",
    "joints",
    "method",
    "jaccard",
    "seed_sd",
    "jaccard_fp",
    "frame_acc",
    "subject_range",
    "fit_s",
    "pred_us_per_frame",
    "runs",
]
# Filled by run(): the notes printed under the table (skipped rows, backends).
NOTES = []


# ---------------------------------------------------------------- registry


@dataclass
class Method:
    """One row of the comparison.

    ``make(joints, seed, memory_dir)`` returns an unfitted estimator with the
    ``fit(X, y)`` / ``predict(X)`` contract over lists of raw sequences;
    ``unavailable()`` returns why it cannot run here (the row is skipped with
    that note), or None; ``sources`` are the files whose content keys its cache.
    """

    make: Callable
    family: str = "skgesture"
    unavailable: Callable = field(default=lambda: None)
    sources: tuple = ()


def _skg_sources():
    pkg = Path(skgesture.__file__).resolve().parent
    return tuple(sorted(pkg.rglob("*.py"))) + (
        ROOT / "benchmarks" / "_baseline.py",
        ROOT / "benchmarks" / "bench_methods.py",
    )


def _skgesture_method(name):
    def make(joints, seed, memory_dir):
        return method_factories(joints, seed, [name], memory_dir)[name]()

    return Method(make=make, family="skgesture", sources=_skg_sources())


def _variant(set=None, **params):
    """A ``make`` of ``make_recommended(**params)``, then ``set_params(**set)``:
    the candidates of the default."""

    def make(joints, seed, memory_dir):
        model = skgesture.make_recommended(joints=joints, random_state=seed, **params)
        return model.set_params(**(set or {}))

    return make


# make_recommended's default and the other candidates for it (docs/choosing.md):
# the whole-sequence models (best offline, approximate live) and the exact model
# on joint features.
VARIANTS = {
    "recommended": {},
    "recommended (joints whole)": {"features": "joints", "lookahead": None},
    "recommended (descriptor whole)": {
        "features": "descriptor",
        "lookahead": None,
    },
    "recommended (joints exact 8)": {"features": "joints", "lookahead": 8},
    "recommended (descriptor+joints)": {"features": "descriptor+joints"},
    # "set": parameters of the model set after make_recommended
    "recommended (namer 2 layers)": {"set": {"tagger__namer_hidden_sizes": (128, 128)}},
    "recommended (12 negatives)": {"set": {"background__n_sequences": 12}},
}


def _recommended_unavailable():
    if hasattr(skgesture, "make_recommended"):
        return None
    return "skgesture.make_recommended does not exist yet: row 'recommended' skipped"


def _peer_method(cls, unavailable):
    def make(joints, seed, memory_dir):
        return cls(joints=joints, random_state=seed)

    return Method(
        make=make,
        family="peer",
        unavailable=unavailable,
        sources=(ROOT / "benchmarks" / "_peers.py",),
    )


REGISTRY = {name: _skgesture_method(name) for name in ("forest", "A", "B", "C (cpu)")}
for _name, _params in VARIANTS.items():
    REGISTRY[_name] = Method(
        make=_variant(**_params),
        unavailable=_recommended_unavailable,
        sources=_skg_sources(),
    )
REGISTRY["B (tuned)"] = _skgesture_method("B (tuned)")
for _name, (_cls, _why) in PEERS.items():
    REGISTRY[_name] = _peer_method(_cls, _why)

DEFAULT_METHODS = (
    "forest",
    "A",
    "B",
    "C (cpu)",
    "recommended",
    "recommended (joints whole)",
    "recommended (descriptor whole)",
    "GRU peer",
    "HGB peer",
    "seglearn peer",
    "MiniRocket peer",
)


def register(name, make, *, family="skgesture", unavailable=None, sources=None):
    """Add (or replace) a row: ``make(joints, seed, memory_dir)`` -> estimator.

    ``name`` has no comma (``--methods`` is a comma-separated list)."""
    if "," in name:
        raise ValueError(
            f"a method name has no comma (--methods splits on it): {name!r}"
        )
    REGISTRY[name] = Method(
        make=make,
        family=family,
        unavailable=unavailable or (lambda: None),
        sources=_skg_sources() if sources is None else tuple(sources),
    )


# ------------------------------------------------------------- cache keys


def _sha(text):
    return hashlib.sha1(text.encode()).hexdigest()


def _plain(value):
    """A stable text for a parameter value (no memory addresses, no temp paths)."""
    if hasattr(value, "get_params"):
        return type(value).__qualname__
    if type(value).__name__ == "Memory":
        return "Memory"
    if callable(value):
        return (
            f"{getattr(value, '__module__', '')}.{getattr(value, '__qualname__', '')}"
        )
    if isinstance(value, np.ndarray):
        return f"array{value.shape}:{_sha(value.tobytes().hex())}"
    text = repr(value)
    return type(value).__qualname__ if " at 0x" in text else text


def param_key(estimator):
    """Hash of an unfitted estimator's class and deep parameters."""
    params = estimator.get_params(deep=True)
    text = type(estimator).__qualname__ + "".join(
        f"|{k}={_plain(v)}" for k, v in sorted(params.items())
    )
    return _sha(text)[:12]


@functools.cache
def _library_versions():
    import sklearn
    import torch

    out = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "sklearn": sklearn.__version__,
        "torch": torch.__version__,
        "skgesture": skgesture.__version__,
    }
    for extra in ("seglearn", "aeon"):
        try:
            out[extra] = __import__(extra).__version__
        except Exception:
            out[extra] = None
    return out


@functools.cache
def _source_bytes(path):
    # Cached: each file is read once, when this process first needs it (primed at
    # import for the registered methods), so that an edit made while a long run
    # goes on cannot label results of the code already loaded.
    return source_key(path)


def code_key(method):
    """Hash of the method's source code (docstrings and comments aside) and of
    the library versions."""
    h = hashlib.sha1(json.dumps(_library_versions(), sort_keys=True).encode())
    for path in method.sources:
        h.update(str(Path(path).name).encode())
        h.update(_source_bytes(path))
    return h.hexdigest()[:12]


for _method in REGISTRY.values():
    for _path in _method.sources:
        _source_bytes(_path)


def git_commit():
    """``HEAD`` of the repository, ``+dirty`` when the tree has changes."""
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+dirty" if dirty else "")


def data_key(X, y):
    """Hash of the sequences and labels of a dataset."""
    h = hashlib.sha1()
    for x, t in zip(X, y):
        h.update(np.ascontiguousarray(x, dtype=np.float64).tobytes())
        h.update(np.ascontiguousarray(t, dtype=np.int64).tobytes())
    return h.hexdigest()[:10]


def _slug(text):
    return "".join(c if c.isalnum() else "_" for c in text).strip("_")


# ---------------------------------------------------------------- datasets


@dataclass
class Folds:
    """A dataset and its folds: ``[(fold_id, train_idx, test_idx), ...]``."""

    name: str
    label: str
    data: object
    folds: list
    key: str


def load_folds(dataset, quick):
    """The folds of ``dataset`` ("precog", "utkinect" or "synthetic"), or None
    when its recordings are not on this machine."""
    if dataset in ("precog", "utkinect"):
        if dataset == "precog":
            from skgesture.datasets import load_precog

            data, name = load_precog(), "PRECOG"
        else:
            path = shared_data_dir() / "utkinect_action3d"
            if not path.is_dir():
                return None
            data, name = load_utkinect_quiet(path), "UTKinect"
        groups = np.asarray(data.groups)
        folds = [  # leave one subject out, in subject order (2 folds when quick)
            (f"subject{groups[te][0]}", tr, te) for tr, te in precog_folds(data, quick)
        ]
        label = f"{name} LOSO ({len(folds)} folds)"
    elif dataset == "synthetic":
        data, tr, te = synthetic_split(quick)
        folds = [("unseen", tr, te)]
        label = f"synthetic {len(tr)}/{len(te)}"
        dataset = f"synthetic{len(tr)}_{len(te)}"
    else:
        raise ValueError(
            f"unknown dataset {dataset!r}; use precog, utkinect or synthetic"
        )
    return Folds(dataset, label, data, folds, data_key(data.X, data.y))


# ---------------------------------------------------------------- running


def _row_path(folds, joints, method_name, seed, fold_id, pkey, ckey):
    return (
        CACHE_DIR
        / f"{folds.name}-{folds.key}"
        / joints
        / _slug(method_name)
        / f"seed{seed}-{fold_id}-p{pkey}-c{ckey}.json"
    )


def run_cell(folds, joints, name, method, seed, fold, memory_dir, ckey, compute):
    """The cached result row of one fit, computed when missing (or None).

    ``ckey`` is ``code_key(method)``, computed once per run.
    """
    fold_id, tr, te = fold
    est_key = param_key(method.make(joints, seed, memory_dir))
    path = _row_path(folds, joints, name, seed, fold_id, est_key, ckey)
    if path.exists():
        return json.loads(path.read_text())
    if not compute:
        return None
    groups_te = np.asarray(folds.data.groups)[te]
    row = evaluate(
        lambda: method.make(joints, seed, memory_dir),
        *split_data(folds.data, tr, te),
        groups_te=groups_te,
    )
    row["meta"] = {
        "dataset": folds.name,
        "joints": joints,
        "method": name,
        "seed": seed,
        "fold": fold_id,
        "param_key": est_key,
        "code_key": ckey,
        "commit": git_commit(),
        "versions": _library_versions(),
        "machine": f"{platform.node()} {platform.machine()}",
        "when": time.strftime("%Y-%m-%d %H:%M:%S"),
    }
    if name == "seglearn peer":
        row["meta"]["featurerep"] = "seglearn" if have_seglearn() else "numpy copy"
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(row, indent=1))
    tmp.replace(path)
    print(
        f"  [compare] {folds.name} {joints} {name} seed {seed} {fold_id}: "
        f"jaccard {row['jaccard']:.3f}, fit {row['fit_s']:.1f} s, "
        f"{row['pred_us_per_frame']:.0f} us/frame",
        flush=True,
    )
    return row


def summarise(label, joints, name, cells, seeds, fold_ids):
    """One table row from the cells ``{(seed, fold_id): row}`` (None if none)."""
    complete = [
        s for s in seeds if all((s, f) in cells for f in fold_ids)
    ]  # a seed counts only with all its folds
    if not complete:
        return None
    rows = [cells[(s, f)] for s in complete for f in fold_ids]

    def seed_means(key):
        return [np.mean([cells[(s, f)][key] for f in fold_ids]) for s in complete]

    jac = seed_means("jaccard")
    subjects = {}
    for s in complete:
        for f in fold_ids:
            for subj, score in cells[(s, f)].get("per_subject", {}).items():
                subjects.setdefault(subj, []).append(score)
    subj_means = [np.mean(v) for v in subjects.values()]
    return {
        "data": label,
        "joints": joints,
        "method": name,
        "jaccard": float(np.mean(jac)),
        "seed_sd": float(np.std(jac, ddof=1)) if len(jac) > 1 else "",
        "jaccard_fp": float(np.mean(seed_means("jaccard_fp"))),
        "frame_acc": float(np.mean(seed_means("frame_acc"))),
        "subject_range": (
            f"{min(subj_means):.2f}-{max(subj_means):.2f}" if subj_means else ""
        ),
        "fit_s": float(np.mean([r["fit_s"] for r in rows])),
        "pred_us_per_frame": float(np.mean([r["pred_us_per_frame"] for r in rows])),
        "runs": f"{len(complete)}x{len(fold_ids)}",
    }


def run(
    quick=False,
    methods=DEFAULT_METHODS,
    datasets=("precog", "utkinect", "synthetic"),
    joints=("full20", "paper11"),
    seeds=None,
    compute=True,
):
    """Compute what is missing, then return the table rows (notes in ``NOTES``)."""
    seeds = tuple(seeds) if seeds is not None else ((0,) if quick else SEEDS)
    NOTES.clear()
    unknown = [m for m in methods if m not in REGISTRY]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; known: {list(REGISTRY)}")
    active = {}
    for name in methods:
        why = REGISTRY[name].unavailable()
        if why:
            NOTES.append(why)
            print(f"  [compare] {why}", flush=True)
        else:
            active[name] = REGISTRY[name]
    if "seglearn peer" in active and not have_seglearn():
        NOTES.append(
            "seglearn is not installed: the seglearn peer uses the numpy copy of "
            "FeatureRep()'s default features (identical values)"
        )
    table = []
    with tempfile.TemporaryDirectory() as memory_dir:
        for dataset in datasets:
            folds = load_folds(dataset, quick)
            if folds is None:
                NOTES.append(
                    f"{dataset}: recordings not found under {shared_data_dir()}"
                )
                continue
            fold_ids = [f[0] for f in folds.folds]
            for js in DATASETS[dataset]:
                if js not in joints:
                    continue
                for name, method in active.items():
                    ckey = code_key(method)
                    cells = {}
                    for seed in seeds:
                        for fold in folds.folds:
                            row = run_cell(
                                folds,
                                js,
                                name,
                                method,
                                seed,
                                fold,
                                memory_dir,
                                ckey,
                                compute,
                            )
                            if row is not None:
                                cells[(seed, fold[0])] = row
                    summary = summarise(folds.label, js, name, cells, seeds, fold_ids)
                    if summary is not None:
                        summary["family"] = method.family
                        table.append(summary)
                    elif not compute:
                        NOTES.append(f"{folds.label} {js} {name}: nothing cached")
    return table


def margins(rows):
    """The margin table: each skgesture model's Jaccard minus the best peer's, per
    dataset, and the worst case over the datasets where both were measured.

    Returns ``(columns, rows)``; a dataset without a peer row has no margin.
    """
    datasets = []
    for r in rows:
        key = f"{r['data']}, {r['joints']}"
        if key not in datasets:
            datasets.append(key)
    best = {}
    for r in rows:
        if r.get("family") == "peer":
            key = f"{r['data']}, {r['joints']}"
            if r["jaccard"] > best.get(key, ("", -1.0))[1]:
                best[key] = (r["method"], r["jaccard"])
    out = []
    for name in dict.fromkeys(r["method"] for r in rows if r.get("family") != "peer"):
        row = {"method": name}
        for r in rows:
            key = f"{r['data']}, {r['joints']}"
            if r["method"] == name and key in best:
                row[key] = r["jaccard"] - best[key][1]
        have = [v for k, v in row.items() if k != "method"]
        row["worst case"] = min(have) if have else ""
        row["datasets"] = f"{len(have)}/{len(best)}"
        out.append(row)
    out.sort(key=lambda r: -r["worst case"] if r["worst case"] != "" else 1.0)
    peers = [{"method": "best peer"}]
    for key, (name, jac) in best.items():
        peers[0][key] = f"{name} {jac:.3f}"
    columns = (
        ["method"] + [k for k in datasets if k in best] + ["worst case", "datasets"]
    )
    return columns, peers + out


def format_tables(rows, title):
    """The table, then the margins over the best peer with their worst case."""
    text = format_table(rows, COLUMNS, title)
    columns, margin_rows = margins(rows)
    if len(columns) > 3 and len(margin_rows) > 1:  # a peer and a model measured
        text += "\n" + format_table(
            margin_rows,
            columns,
            "Margin over the best peer (Jaccard difference); worst case over datasets",
        )
    return text


def main(argv=None):
    from _common import machine_line

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 folds, 1 seed")
    parser.add_argument("--methods", default=",".join(DEFAULT_METHODS))
    parser.add_argument("--datasets", default="precog,utkinect,synthetic")
    parser.add_argument("--joints", default="full20,paper11")
    parser.add_argument(
        "--seeds", default=None, help="comma-separated seeds (default 0,1,2)"
    )
    parser.add_argument(
        "--no-compute", action="store_true", help="print only what is cached"
    )
    parser.add_argument(
        "--cache-dir",
        default=None,
        help="where results are kept (default bench_results/compare); a new folder "
        "recomputes everything, e.g. to time fits side by side on a quiet machine",
    )
    parser.add_argument("--list", action="store_true", help="list the methods")
    args = parser.parse_args(argv)
    if args.cache_dir is not None:
        global CACHE_DIR
        CACHE_DIR = Path(args.cache_dir)
    if args.list:
        for name, m in REGISTRY.items():
            print(f"{name} ({m.family}){'  *' if name in DEFAULT_METHODS else ''}")
        return
    rows = run(
        quick=args.quick,
        methods=[m.strip() for m in args.methods.split(",") if m.strip()],
        datasets=[d.strip() for d in args.datasets.split(",") if d.strip()],
        joints=[j.strip() for j in args.joints.split(",") if j.strip()],
        seeds=(
            [int(s) for s in args.seeds.split(",")] if args.seeds is not None else None
        ),
        compute=not args.no_compute,
    )
    print(machine_line() + "\n")
    print(format_tables(rows, "skgesture beside the peers"))
    for note in NOTES:
        print(f"* {note}")


if __name__ == "__main__":
    main()
