"""Synthetic negatives by their cost: Jaccard change and false events per minute.

Section ``background`` of ``make bench``. ``make_recommended()`` makes
negatives from its training recordings at every fit (``background="synthetic"``,
``SyntheticBackground``: random joint motion, reversed gestures, fragments,
concatenations) and gives them to its run namer alone
(``background_for="namer"``). This section fits the recommended model with
each variant of ``bench_decoding.BACKGROUNDS`` (none, the negatives for the
namer as shipped, the same given to the whole model, and variants of their
count and kinds, given to the whole model) on the datasets
of ``bench_decoding`` and sets them side by side: the Jaccard on every dataset,
its change from no background (paired by seed), the worst change over the
datasets, the recall of true PRECOG gestures and the false gesture events per
minute on recordings of other motion (``bench_oov.load_negatives``: MSR
Action3D without punches and kicks, MSRC-12 without its kick, UTKinect).

Protocol
--------
* Every fit and every score is ``bench_decoding``'s (``bench_decoding.run``
  with ``background=`` the variant and ``grid={}``: the current default
  decoding alone), one run per variant and seed, so its cache cells are
  shared with ``python benchmarks/bench_decoding.py --background NAME``.
* **Change**: per dataset, the mean over seeds of the paired difference from
  ``"none"`` on the same seed (the fits differ only by the negatives);
  **worst change**: the smallest over the datasets.
* **Figure** (``backgrounds.png``, ``backgrounds_quick.png`` in quick mode):
  false events per minute against the worst change, a point per variant,
  with the rows and notes beside it as JSON.

Quick mode (``run(quick=True)``): ``bench_decoding``'s quick data, seed 0,
the variants ``QUICK_VARIANTS``, a few seconds.

Usage: ``python benchmarks/bench_background.py [--quick] [--seeds 0,1]
[--variants none,synthetic,...] [--datasets precog,utkinect,synthetic]
[--jobs 2] [--out-dir DIR]``, or ``python benchmarks/run.py --only
background``.
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_decoding  # noqa: E402
from _common import (  # noqa: E402
    comma_list,
    figure_lines,
    format_table,
    print_report,
    save_figure,
)

VARIANTS = ("none", "namer", "synthetic", "nofragment", "share10", "share10-nofragment")
QUICK_VARIANTS = ("none", "synthetic", "share10-nofragment")
SEEDS = (0, 1, 2)
BASE = "none"  # the changes are paired differences from this variant
COLUMNS = [
    "background",
    "what",
    "worst change",
    "worst on",
    "recall",
    "false events/min",
]
NOTES = []


def describe(name):
    """A variant in words: its count and kinds."""
    made = bench_decoding.background_of(name, 0)
    if made is None:
        return "gesture recordings only"
    n = made.n_sequences
    count = f"{n:.0%} of the training sequences" if n < 1 else f"{n} sequences"
    kinds = "every kind" if made.kinds is None else "+".join(made.kinds)
    return f"{count}, {kinds}"


def _default_row(rows):
    (row,) = [r for r in rows if r.get("table") == "decoding" and r["default"]]
    return row


def run(quick=False, seeds=None, variants=None, datasets=None, out_dir=None, n_jobs=1):
    """Fit (or read from the cache) every variant and seed; return the rows.

    Parameters
    ----------
    quick : bool, default=False
        ``bench_decoding``'s quick data (seconds; no shared data).
    seeds : sequence of int or None, default=None
        None: ``SEEDS`` (quick: 0).
    variants : sequence of str or None, default=None
        Names of ``bench_decoding.BACKGROUNDS``; ``BASE`` is added first when
        missing. None: ``VARIANTS`` (quick: ``QUICK_VARIANTS``).
    datasets : sequence of str or None, default=None
        As ``bench_decoding.run``.
    out_dir : path-like or None, default=None
        As ``bench_decoding.run`` (the figure goes beside its cache).
    n_jobs : int, default=1
        Fits at once (``bench_decoding.run``). With more than one, the fits
        train on fewer threads each, in cache cells of their own: a cache
        filled with ``--jobs 2`` is read again with ``--jobs 2``.

    Returns
    -------
    list of dict
        ``table="background"`` rows, one per variant: ``background``,
        ``what``, ``jaccard`` / ``jaccard_sd`` / ``jaccard_change``
        (``{dataset: value}``), ``worst change``, ``worst on``, ``recall``,
        ``false events/min`` (mean over seeds), ``events_per_min_sd``,
        ``events_per_min_by`` (negative dataset) and ``seeds``; then one
        ``table="figure"`` row.
    """
    NOTES.clear()
    seeds = tuple(seeds) if seeds is not None else ((0,) if quick else SEEDS)
    variants = list(variants or (QUICK_VARIANTS if quick else VARIANTS))
    for name in variants:  # an unknown name fails before any fit
        bench_decoding.background_of(name, 0)
    if BASE not in variants:
        variants.insert(0, BASE)
    out_dir = Path(
        out_dir or os.environ.get(bench_decoding.OUT_ENV) or bench_decoding.RESULTS
    )
    per = {}  # (variant, seed) -> the default row of that run
    for name in variants:
        for seed in seeds:
            rows = bench_decoding.run(
                quick=quick,
                seeds=[seed],
                datasets=datasets,
                grid={},
                out_dir=out_dir,
                background=name,
                n_jobs=n_jobs,
            )
            per[name, seed] = _default_row(rows)
    names = list(per[BASE, seeds[0]]["jaccard"])
    out = []
    for name in variants:
        rows = [per[name, s] for s in seeds]
        jac = {d: [r["jaccard"][d] for r in rows] for d in names}
        change = {
            d: float(
                np.mean(
                    [
                        per[name, s]["jaccard"][d] - per[BASE, s]["jaccard"][d]
                        for s in seeds
                    ]
                )
            )  # fmt: skip
            for d in names
        }
        worst_on = min(change, key=change.get)
        events = [r["events_per_min"] for r in rows]
        by = {
            n: float(np.mean([r["events_per_min_by"][n] for r in rows]))
            for n in rows[0]["events_per_min_by"]
        }
        out.append(
            {
                "table": "background",
                "background": name,
                "what": describe(name),
                "jaccard": {d: float(np.mean(v)) for d, v in jac.items()},
                "jaccard_sd": {d: _sd(v) for d, v in jac.items()},
                "jaccard_change": change,
                "worst change": change[worst_on],
                "worst on": worst_on,
                "recall": float(np.mean([r["recall"] for r in rows])),
                "false events/min": float(np.mean(events)),
                "events_per_min_sd": _sd(events),
                "events_per_min_by": by,
                "seeds": list(seeds),
            }
        )
    NOTES.append(
        f"seeds {list(seeds)}; Jaccard: mean over folds, then over seeds (± sd); "
        f"change: paired by seed, from {BASE!r}; worst: the smallest change over "
        "the datasets; decoding: make_recommended's default"
    )
    NOTES.append(
        "false events/min by negative dataset: "
        + "; ".join(
            f"{r['background']} "
            + ", ".join(f"{n} {v:.2f}" for n, v in r["events_per_min_by"].items())
            for r in out
        )
    )
    stem = "backgrounds" + ("_quick" if quick else "")
    figure = plot_backgrounds(out, out_dir / f"{stem}.png")
    with open(out_dir / f"{stem}.json", "w") as fh:
        json.dump({"rows": out, "notes": NOTES}, fh, indent=1)
    return out + [{"table": "figure", "path": str(figure)}]


def _sd(values):
    return float(np.std(values, ddof=1)) if len(values) > 1 else 0.0


def plot_backgrounds(rows, path):
    """False events per minute against the worst change, a point per variant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for k, r in enumerate(rows):
        ax.errorbar(
            r["worst change"],
            r["false events/min"],
            yerr=r["events_per_min_sd"] or None,
            fmt="o",
            color=f"C{k}",
            label=f"{r['background']}: {r['what']}",
        )
    ax.set_xlabel(f"worst-case Jaccard change from {BASE!r} (paired by seed)")
    ax.set_ylabel("false gesture events per minute")
    ax.set_ylim(bottom=0)
    ax.set_title("synthetic negatives in fit: what they cost, what they remove")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return save_figure(fig, path)


def format_tables(rows, title="Synthetic negatives by their cost"):
    """One row per variant: Jaccard (change) per dataset, worst change, recall,
    false events per minute; and the figure's path."""
    table = [r for r in rows if r.get("table") == "background"]
    datasets = list(table[0]["jaccard"]) if table else []
    lines = []
    for r in table:
        line = {c: r[c] for c in COLUMNS}
        for d in datasets:
            line[f"jaccard {d}"] = (
                f"{r['jaccard'][d]:.3f} ({r['jaccard_change'][d]:+.3f})"
            )
        line["worst change"] = f"{r['worst change']:+.3f}"
        line["recall"] = f"{r['recall']:.3f}"
        sd = r["events_per_min_sd"]
        fe = r["false events/min"]
        line["false events/min"] = f"{fe:.2f}" + (f" ± {sd:.2f}" if sd else "")
        lines.append(line)
    columns = COLUMNS[:2] + [f"jaccard {d}" for d in datasets] + COLUMNS[2:]
    return format_table(lines, columns, title) + figure_lines(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="synthetic smoke run")
    parser.add_argument("--seeds", default=None, help="comma-separated (0,1,2)")
    parser.add_argument(
        "--variants",
        default=None,
        help="comma-separated names of bench_decoding.BACKGROUNDS "
        f"(default {','.join(VARIANTS)})",
    )
    parser.add_argument(
        "--datasets", default=None, help="comma-separated: precog,utkinect,synthetic"
    )
    parser.add_argument("--jobs", type=int, default=1, help="fits at once")
    parser.add_argument("--out-dir", default=None, help="figure and cache folder")
    args = parser.parse_args(argv)
    rows = run(
        quick=args.quick,
        seeds=[int(s) for s in comma_list(args.seeds)] if args.seeds else None,
        variants=comma_list(args.variants),
        datasets=comma_list(args.datasets),
        out_dir=args.out_dir,
        n_jobs=args.jobs,
    )
    print_report(rows, format_tables, NOTES)


if __name__ == "__main__":
    main()
