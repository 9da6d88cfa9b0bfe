"""Where one fit of the recommended model spends its time (cProfile).

Fits ``make_recommended(joints="full20", random_state=0)`` on the first 36
PRECOG sequences (subjects 1-6, as the README's example) under cProfile, after
one descriptor transform outside the profile (so numba's first compilation is
not counted), and prints the seconds of each part: the descriptor of the
training set, the crops and their augmentation (``_CropData.sample``), the
network's forward pass, its backward pass, the loss and the optimiser's
update, and the training loop as a whole.
cProfile slows the Python-heavy parts more than torch's kernels; compare the
parts, not the total with an unprofiled fit.

Usage: ``python benchmarks/profile_fit.py [--threads N] [--no-profile]``
(``tagger__fit_threads``; default the model's, every core). ``--no-profile``
fits without cProfile and prints the fit's wall seconds alone: the command to
time two versions of the code side by side (``farm-bench --vs``, each on its own
checkout; docs/benchmarks.md).
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import cProfile
import pstats
import time

from skgesture import make_recommended
from skgesture.datasets import load_precog

# (label, file suffix, function name): cumulative seconds of that function
PARTS = (
    ("descriptor of the training set", "sklearn/pipeline.py", "_fit"),
    ("crops and augmentation", "_nn/_sequence_net.py", "sample"),
    ("forward", "skorch/net.py", "infer"),
    ("backward", "torch/autograd/__init__.py", "backward"),
    ("whole optimiser step (forward, backward, update)", "torch/optim/adam.py", "step"),
    ("training loop", "skorch/net.py", "fit_loop"),
)


def cumulative(stats, suffix, name):
    """Cumulative seconds of the functions ``name`` defined in ``*suffix``."""
    return sum(
        row[3]
        for (path, _, func), row in stats.stats.items()
        if func == name and path.endswith(suffix)
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=None, help="fit threads")
    parser.add_argument(
        "--no-profile", action="store_true", help="time the fit alone, no cProfile"
    )
    args = parser.parse_args(argv)
    data = load_precog()
    X, y = data.X[:36], data.y[:36]
    model = make_recommended(joints="full20", random_state=0)
    if args.threads:
        model.set_params(tagger__fit_threads=args.threads)
    model[0].fit_transform(X[:2])  # numba compiles (or loads its cache) here
    if args.no_profile:
        start = time.perf_counter()
        model.fit(X, y, fps=data.fps)
        print(f"fit of {len(X)} sequences: {time.perf_counter() - start:.1f} s")
        return
    profile = cProfile.Profile()
    start = time.perf_counter()
    profile.enable()
    model.fit(X, y, fps=data.fps)
    profile.disable()
    total = time.perf_counter() - start
    stats = pstats.Stats(profile)
    n_frames = sum(len(x) for x in X)
    print(
        f"fit of {len(X)} sequences ({n_frames:,} frames) under cProfile: {total:.1f} s"
    )
    parts = {label: cumulative(stats, *where) for label, *where in PARTS}
    step = parts["whole optimiser step (forward, backward, update)"]
    parts["loss and optimiser update"] = step - parts["forward"] - parts["backward"]
    for label, seconds in parts.items():
        print(f"  {label:<50} {seconds:7.1f} s  {seconds / total:6.1%}")


if __name__ == "__main__":
    main()
