"""
======================================
skgesture demo: data, training, tuning
======================================

What ``make demo`` runs. It

1. summarises the bundled PRECOG recordings and a batch of synthetic
   Montalbano-like streams (sequences, frames, gestures per class, lengths);
2. computes the paper's pose descriptors;
3. trains the recommended model (``make_recommended``; or the paper's Method
   A / B / C with ``--method``) on PRECOG subjects 1-5 and reports the
   ChaLearn Jaccard index on the held-out subjects 7-8;
4. tunes the decision parameters on subject 6 with ``GridSearchCV`` over the
   cached networks (no network is retrained): the decoding of the recommended
   model, the fusion weights and thresholds of Method B, and scores the tuned
   model on subjects 7-8 again.

Run ``python examples/demo.py --help`` for the options.
"""

# %%
import argparse
import tempfile
import time

import numpy as np
from joblib import Memory
from sklearn.model_selection import GridSearchCV

from skgesture import (
    PoseDescriptor,
    TorchMLPClassifier,
    make_method_a,
    make_method_b,
    make_recommended,
)
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.metrics import frame_accuracy, jaccard_index, jaccard_scorer


def summarise(name, data):
    """Print sequences, frames, gestures per class and gesture lengths."""
    n_frames = sum(len(x) for x in data.X)
    seg = np.concatenate(data.segments)
    lengths = seg[:, 2] - seg[:, 1]
    counts = np.bincount(seg[:, 0], minlength=len(data.target_names) + 1)[1:]
    missing = int(sum(m.sum() for m in data.missing))
    print(f"\n{name}")
    print(
        f"  sequences {len(data.X)}, frames {n_frames:,}, untracked frames {missing}, "
        f"subjects {len(np.unique(data.groups))}"
    )
    print(
        f"  gestures {len(seg)}; length min {lengths.min()}, median "
        f"{np.median(lengths):.0f}, max {lengths.max()} frames"
    )
    per_class = ", ".join(f"{n}: {c}" for n, c in zip(data.target_names, counts))
    print(f"  per class: {per_class}")


def make_pipeline(method, random_state, memory, fast=False):
    if method == "recommended":
        model = make_recommended(
            joints="full20", memory=memory, random_state=random_state
        )
        return model.set_params(tagger__max_epochs=4) if fast else model
    if method == "C":
        from skgesture import make_method_c

        model = make_method_c(joints="full20", memory=memory, random_state=random_state)
        return model.set_params(tagger__max_epochs=5) if fast else model
    make = make_method_a if method == "A" else make_method_b
    model = make(joints="full20", memory=memory, random_state=random_state)
    if fast:  # small networks, fewer epochs: the same steps in seconds
        model.set_params(
            segmenter__estimator=TorchMLPClassifier(
                hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=100
            ),
            classifier__estimator=TorchMLPClassifier(
                hidden_layer_sizes=(64,), activations=("tanh",), max_epochs=100
            ),
        )
    return model


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="skgesture demo: data, training, tuning"
    )
    parser.add_argument(
        "--method",
        choices=["recommended", "A", "B", "C"],
        default="recommended",
        help="the recommended model (default) or one of the paper's methods",
    )
    parser.add_argument(
        "--no-search", action="store_true", help="skip the GridSearchCV example"
    )
    parser.add_argument("--random-state", type=int, default=0)
    parser.add_argument(
        "--fast",
        action="store_true",
        help="small networks (what the docs build runs; lower scores)",
    )
    args = parser.parse_args(argv)

    # %%
    # Data
    precog = load_precog()
    summarise("PRECOG 2016 (bundled, subjects 1-8, MIT licence, D. Jardim)", precog)
    synth = make_gesture_streams(50, random_state=args.random_state)
    summarise("Synthetic Montalbano-like streams (make_gesture_streams)", synth)

    # %%
    # Descriptors
    # The first call of a new installation compiles the descriptor kernel (numba,
    # about 10 s once, then cached on disk); time it apart from the real work.
    t0 = time.perf_counter()
    PoseDescriptor().fit_transform(synth.X[:1])
    warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    D = PoseDescriptor().fit_transform(synth.X)
    dt = time.perf_counter() - t0
    n = sum(len(d) for d in D)
    print(
        f"\nPoseDescriptor: {n:,} frames -> {D[0].shape[1]}-D in {dt:.2f} s "
        f"({n / dt:,.0f} frames/s, fit + transform; first call {warm:.1f} s)"
    )

    # %%
    # Train on subjects 1-5; subject 6 is kept to tune the decision parameters,
    # subjects 7-8 (never seen) to score.
    groups = np.asarray(precog.groups)
    train = np.flatnonzero(groups <= 5)
    tune = np.flatnonzero(groups == 6)
    test = np.flatnonzero(groups > 6)
    X_fit = [precog.X[i] for i in np.r_[train, tune]]
    y_fit = [precog.y[i] for i in np.r_[train, tune]]
    X_te, y_te = [precog.X[i] for i in test], [precog.y[i] for i in test]
    with tempfile.TemporaryDirectory() as cache:
        memory = Memory(cache, verbose=0)
        model = make_pipeline(args.method, args.random_state, memory, args.fast)
        t0 = time.perf_counter()
        model.fit(X_fit[: len(train)], y_fit[: len(train)])
        fit_s = time.perf_counter() - t0
        pred = model.predict(X_te)
        name = f"Method {args.method}"
        if args.method == "recommended":
            name = "The recommended model"
        print(
            f"\n{name} on PRECOG, trained on subjects 1-5 "
            f"({len(train)} sequences) in {fit_s:.1f} s; held-out subjects 7-8:"
        )
        print(
            f"  Jaccard (official 2014) {jaccard_index(y_te, pred):.3f}, "
            f"fp-penalised {jaccard_index(y_te, pred, mode='fp_penalised'):.3f}, "
            f"frame accuracy {frame_accuracy(y_te, pred):.3f}"
        )

        # %%
        # Decision parameters are tuned without retraining: the search fits the
        # same pipeline on the same subjects 1-5, so `memory` hands back the
        # trained networks and each candidate costs only its decoding, scored on
        # subject 6.
        grid = None
        if args.method == "recommended":
            grid = {
                "tagger__smooth_span": [1, 5, 9],
                "tagger__min_run": [1, 8],
                "tagger__min_duration": [0.0, 0.3, 0.5],
            }
        elif args.method == "B":
            grid = {
                "classifier__weights": [(0.4895, 0.4576, 0.0529), (1, 1, 1), (1, 0, 0)],
                "classifier__threshold_short": [0.5, 0.6014],
                "classifier__threshold_long": [0.45, 0.6033],
            }
        if grid is not None and not args.no_search:
            split = [(np.arange(len(train)), np.arange(len(train), len(X_fit)))]
            search = GridSearchCV(
                model, grid, scoring=jaccard_scorer, cv=split, refit=False
            )
            t0 = time.perf_counter()
            search.fit(X_fit, y_fit)
            n_cand = len(search.cv_results_["params"])
            print(
                f"\nGridSearchCV over the decision parameters: {n_cand} candidates "
                f"scored on subject 6 in {time.perf_counter() - t0:.1f} s "
                "(no network retrained)"
            )
            print(f"  best {search.best_params_}, Jaccard {search.best_score_:.3f}")
            model.set_params(**search.best_params_)  # decoding only: no refit
            print(
                "  subjects 7-8 with the tuned decoding: Jaccard "
                f"{jaccard_index(y_te, model.predict(X_te)):.3f}"
            )


if __name__ == "__main__":
    main()
