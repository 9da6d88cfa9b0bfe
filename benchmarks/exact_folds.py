"""Offline cost of exact streaming: the recommended model with and without a look-ahead.

PRECOG subjects 1-8, 20 joints, folds of held-out subject pairs (1-2, 3-4, 5-6,
7-8; train on the other six), official ChaLearn 2014 Jaccard of
``make_recommended(joints="full20", lookahead=L)`` against the whole-sequence
default, fold by fold (paired: the same fold and seed for every model).

Usage: ``python benchmarks/exact_folds.py [--models whole,exact8,exact16]
[--folds 1-2,3-4] [--seed 0]``. One fit takes 2 minutes on an idle 2-core
machine, so all four folds of three models take about 25 minutes.
"""

import argparse
import time

import numpy as np

from skgesture import make_recommended
from skgesture.datasets import load_precog
from skgesture.metrics import jaccard_index

MODELS = {"whole": None, "exact8": 8, "exact16": 16}
FOLDS = ((1, 2), (3, 4), (5, 6), (7, 8))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", default=",".join(MODELS))
    parser.add_argument(
        "--folds", default=",".join(f"{a}-{b}" for a, b in FOLDS),
        help="held-out subject pairs, e.g. 1-2,3-4",
    )  # fmt: skip
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    folds = [tuple(int(s) for s in f.split("-")) for f in args.folds.split(",")]
    names = args.models.split(",")
    data = load_precog(subjects=list(range(1, 9)))
    groups = np.asarray(data.groups)
    scores = {name: [] for name in names}
    print("| held out | " + " | ".join(names) + " |")
    print("|---" * (len(names) + 1) + "|")
    for test in folds:
        held = np.isin(groups, test)
        X_tr = [x for x, h in zip(data.X, held) if not h]
        y_tr = [y for y, h in zip(data.y, held) if not h]
        X_te = [x for x, h in zip(data.X, held) if h]
        y_te = [y for y, h in zip(data.y, held) if h]
        cells = []
        for name in names:
            model = make_recommended(
                joints="full20", lookahead=MODELS[name], random_state=args.seed
            )
            t = time.perf_counter()
            model.fit(X_tr, y_tr, fps=data.fps)
            fit_s = time.perf_counter() - t
            scores[name].append(jaccard_index(y_te, model.predict(X_te)))
            cells.append(f"{scores[name][-1]:.3f} (fit {fit_s:.0f} s)")
        print(f"| {test[0]}-{test[1]} | " + " | ".join(cells) + " |", flush=True)
    print("| mean | " + " | ".join(f"{np.mean(scores[n]):.3f}" for n in names) + " |")


if __name__ == "__main__":
    main()
