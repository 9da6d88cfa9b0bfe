"""Run the benchmarks and print their tables (``make bench``).

Usage: ``python benchmarks/run.py [--quick] [--only SECTION,...]``.
Every number is a median (or a mean over folds) measured in this run, on this
machine; compare rows of one run, not across runs.
"""

import argparse
import importlib
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import format_table, machine_line  # noqa: E402

SECTIONS = {
    "descriptor": ("bench_descriptor", "Descriptor and generator speed (one core)"),
    "methods": ("bench_methods", "Jaccard and cost per method"),
    "search": (
        "bench_search",
        "GridSearchCV over decision parameters: cache on vs off",
    ),
    "streaming": ("bench_streaming", "Streaming recognition: latency and delay"),
    "predict": ("bench_predict", "Prediction cost per frame, Methods A and B"),
    "scale": ("bench_scale", "Scale"),
    "rate": ("bench_rate", "Frame rates: trained at 30 fps, tested at 15, 10, 20, 60"),
    "startup": ("bench_startup", "Command-line start-up: cold process vs its work"),
    "oov": ("bench_oov", "Out-of-vocabulary rejection: false events/min vs recall"),
    "decoding": (
        "bench_decoding",
        "Decoding defaults by their worst case: Jaccard change, false events/min",
    ),
    "background": (
        "bench_background",
        "Synthetic negatives by their cost: Jaccard change, false events/min",
    ),
    "speed": (
        "bench_speed",
        "Recommended model: fit, predict and --fast times against their targets",
    ),
    "compare": (
        "bench_compare",
        "skgesture beside the peers (seed means; cached in bench_results/compare)",
    ),
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--quick", action="store_true", help="smaller data, fewer folds"
    )
    parser.add_argument(
        "--only",
        default=",".join(SECTIONS),
        help="comma-separated sections: " + ", ".join(SECTIONS),
    )
    parser.add_argument(
        "--out", default=None, help="also write the tables to this file"
    )
    args = parser.parse_args(argv)
    chunks = [
        f"# skgesture benchmarks{' (quick)' if args.quick else ''}\n",
        machine_line() + "\n",
    ]
    print("\n".join(chunks), flush=True)
    for name in args.only.split(","):
        module_name, title = SECTIONS[name.strip()]
        module = importlib.import_module(module_name)
        rows = module.run(quick=args.quick)
        if hasattr(module, "format_tables"):  # sections with their own columns
            table = module.format_tables(rows, title)
        else:
            table = format_table(rows, getattr(module, "COLUMNS", None), title)
        notes = getattr(module, "NOTES", ())
        if notes:
            table += "\n" + "".join(f"* {note}\n" for note in notes)
        quick = " --quick" if args.quick else ""
        table += f"\ncommand: python benchmarks/run.py --only {name.strip()}{quick}\n"
        print(table, flush=True)
        chunks.append(table)
    if args.out:
        Path(args.out).write_text("\n".join(chunks))


if __name__ == "__main__":
    main()
