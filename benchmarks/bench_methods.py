"""Methods A, B (and C) against a forest baseline on the same splits (issues 3, 4).

* PRECOG (bundled subjects 1-8), leave-one-subject-out, full 20-joint layout.
* Synthetic Montalbano-like streams: train on 100 sequences, test on 50
  sequences of unseen subjects.
"""

import tempfile
import time

import numpy as np
from _baseline import SlidingWindowForest
from joblib import Memory
from sklearn.model_selection import GridSearchCV, GroupKFold, LeaveOneGroupOut

from skgesture import make_method_a, make_method_b, make_method_c
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.metrics import frame_accuracy, jaccard_index, jaccard_scorer

ALL_METHODS = ("forest", "A", "B", "B (tuned)", "C (cpu)")
DEFAULT_METHODS = ALL_METHODS

# Decision parameters searched for "B (tuned)": segmenter threshold and the
# classifier's thresholds; the networks are trained once per inner fold.
TUNING_GRID = [
    {
        "segmenter__threshold": [0.3, 0.4, 0.5],
        "classifier__threshold_short": [0.6014],
        "classifier__threshold_long": [0.6033],
    },
    {
        "segmenter__threshold": [0.3, 0.4, 0.5],
        "classifier__threshold_short": [0.4],
        "classifier__threshold_long": [0.4],
    },
]


def _tuned_b(joints, random_state, memory_dir):
    """Method B whose decision parameters are chosen by an inner GroupKFold(2)."""
    model = make_method_b(
        joints=joints, memory=Memory(memory_dir, verbose=0), random_state=random_state
    )
    return GridSearchCV(model, TUNING_GRID, scoring=jaccard_scorer, cv=GroupKFold(2))


def method_factories(joints, random_state, include, memory_dir):
    """``{name: make}`` for the methods of ``include``; ``make()`` builds one unfitted.

    Shared with the side-by-side section (``bench_compare.py``).
    """
    out = {
        "forest": lambda: SlidingWindowForest(joints=joints, random_state=random_state),
        "A": lambda: make_method_a(joints=joints, random_state=random_state),
        "B": lambda: make_method_b(joints=joints, random_state=random_state),
        "B (tuned)": lambda: _tuned_b(joints, random_state, memory_dir),
        "C (cpu)": lambda: make_method_c(joints=joints, random_state=random_state),
    }
    return {name: out[name] for name in include}


def evaluate(make, X_tr, y_tr, X_te, y_te, groups_tr, groups_te=None):
    """Fit ``make()`` on the training part, score it on the test part.

    Returns official and fp-penalised Jaccard, frame accuracy, fit seconds and
    prediction µs per frame (and the segmenter's accuracy for A and B). With
    ``groups_te``, also ``per_subject``: ``{subject: official Jaccard}``.
    """
    est = make()
    t0 = time.perf_counter()
    if isinstance(est, GridSearchCV):
        est.fit(X_tr, y_tr, groups=groups_tr)
    else:
        est.fit(X_tr, y_tr)
    fit_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    pred = est.predict(X_te)
    pred_s = time.perf_counter() - t0
    row = {
        "jaccard": jaccard_index(y_te, pred),
        "jaccard_fp": jaccard_index(y_te, pred, mode="fp_penalised"),
        "frame_acc": frame_accuracy(y_te, pred),
        "fit_s": fit_s,
        "pred_us_per_frame": 1e6 * pred_s / sum(len(x) for x in X_te),
    }
    if groups_te is not None:
        per_seq = jaccard_index(y_te, pred, per_sequence=True)
        groups_te = np.asarray(groups_te)
        row["per_subject"] = {
            str(g): float(np.nanmean(per_seq[groups_te == g]))
            for g in np.unique(groups_te)
        }
    if isinstance(est, GridSearchCV):
        est = est.best_estimator_
    if hasattr(est, "named_steps") and "segmenter" in est.named_steps:
        Xd = est[:1].transform(X_te)
        row["segmenter_acc"] = est.named_steps["segmenter"].score(Xd, y_te)
    return row


def _mean_rows(rows):
    keys = rows[0].keys()
    return {k: float(np.mean([r[k] for r in rows])) for k in keys}


def split_data(data, tr, te):
    """``(X_tr, y_tr, X_te, y_te, groups_tr)`` of a dataset Bunch."""
    return (
        [data.X[i] for i in tr],
        [data.y[i] for i in tr],
        [data.X[i] for i in te],
        [data.y[i] for i in te],
        np.asarray(data.groups)[tr],
    )


def precog_folds(data, quick=False):
    """Leave-one-subject-out folds of PRECOG, in subject order (2 when quick)."""
    groups = np.asarray(data.groups)
    folds = list(LeaveOneGroupOut().split(data.X, groups=groups))
    return folds[:2] if quick else folds


def synthetic_split(quick=False, random_state=0):
    """Synthetic streams and a ``(train, test)`` split with unseen test subjects.

    100 training and 50 test sequences (30 / 15 when quick), 5 per subject.
    """
    n_train, n_test = (30, 15) if quick else (100, 50)
    data = make_gesture_streams(
        n_train + n_test, n_subjects=(n_train + n_test) // 5, random_state=random_state
    )
    groups = np.asarray(data.groups)
    # Unseen subjects: the last subjects go to the test set.
    test_subjects = np.unique(groups)[-(n_test // 5) :]
    te = np.flatnonzero(np.isin(groups, test_subjects))
    tr = np.flatnonzero(~np.isin(groups, test_subjects))
    return data, tr, te


def precog_rows(quick=False, include=DEFAULT_METHODS, random_state=0):
    """PRECOG (bundled subjects 1-8), leave-one-subject-out, 20 joints."""
    data = load_precog()
    folds = precog_folds(data, quick)
    rows = []
    with tempfile.TemporaryDirectory() as memory_dir:
        for name, make in method_factories(
            "full20", random_state, include, memory_dir
        ).items():
            per_fold = [evaluate(make, *split_data(data, tr, te)) for tr, te in folds]
            rows.append(
                {
                    "data": f"PRECOG LOSO ({len(folds)} folds)",
                    "method": name,
                    **_mean_rows(per_fold),
                }
            )
    return rows


def synthetic_rows(quick=False, include=DEFAULT_METHODS, random_state=0):
    """Synthetic streams: 100 training sequences, 50 test sequences of new subjects."""
    data, tr, te = synthetic_split(quick, random_state)
    rows = []
    with tempfile.TemporaryDirectory() as memory_dir:
        for name, make in method_factories(
            "paper11", random_state, include, memory_dir
        ).items():
            row = evaluate(make, *split_data(data, tr, te))
            rows.append(
                {"data": f"synthetic {len(tr)}/{len(te)}", "method": name, **row}
            )
    return rows


COLUMNS = [
    "data",
    "method",
    "jaccard",
    "jaccard_fp",
    "frame_acc",
    "segmenter_acc",
    "fit_s",
    "pred_us_per_frame",
]


def run(quick=False, include=DEFAULT_METHODS, datasets=("precog", "synthetic")):
    rows = []
    if "precog" in datasets:
        rows += precog_rows(quick, include)
    if "synthetic" in datasets:
        rows += synthetic_rows(quick, include)
    return rows


if __name__ == "__main__":
    import argparse

    from _common import format_table

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--methods", default=",".join(DEFAULT_METHODS))
    parser.add_argument("--datasets", default="precog,synthetic")
    args = parser.parse_args()
    rows = run(args.quick, args.methods.split(","), args.datasets.split(","))
    print(format_table(rows, COLUMNS, "Jaccard and cost per method"))
