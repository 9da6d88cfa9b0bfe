"""Methods A, B (and C) against a forest baseline on the same splits (issues 3, 4).

* PRECOG (bundled subjects 1-8), leave-one-subject-out, full 20-joint layout.
* Synthetic Montalbano-like streams: train on 100 sequences, test on 50
  sequences of unseen subjects.
"""

import time

import numpy as np
from _baseline import SlidingWindowForest
from sklearn.model_selection import LeaveOneGroupOut

from skgesture import make_method_a, make_method_b
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.metrics import frame_accuracy, jaccard_index


def _methods(joints, random_state, include_c):
    out = {
        "forest": lambda: SlidingWindowForest(random_state=random_state),
        "A": lambda: make_method_a(joints=joints, random_state=random_state),
        "B": lambda: make_method_b(joints=joints, random_state=random_state),
    }
    if include_c:
        from skgesture import make_method_c

        out["C (cpu)"] = lambda: make_method_c(joints=joints, random_state=random_state)
    return out


def _evaluate(make, X_tr, y_tr, X_te, y_te):
    est = make()
    t0 = time.perf_counter()
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
    if hasattr(est, "named_steps") and "segmenter" in est.named_steps:
        Xd = est[:1].transform(X_te)
        row["segmenter_acc"] = est.named_steps["segmenter"].score(Xd, y_te)
    return row


def _mean_rows(rows):
    keys = rows[0].keys()
    return {k: float(np.mean([r[k] for r in rows])) for k in keys}


def precog_rows(quick=False, include_c=False, random_state=0):
    data = load_precog()
    groups = np.asarray(data.groups)
    folds = list(LeaveOneGroupOut().split(data.X, groups=groups))
    if quick:
        folds = folds[:2]
    rows = []
    for name, make in _methods("full20", random_state, include_c).items():
        per_fold = []
        for tr, te in folds:
            per_fold.append(
                _evaluate(
                    make,
                    [data.X[i] for i in tr],
                    [data.y[i] for i in tr],
                    [data.X[i] for i in te],
                    [data.y[i] for i in te],
                )
            )
        rows.append(
            {
                "data": f"PRECOG LOSO ({len(folds)} folds)",
                "method": name,
                **_mean_rows(per_fold),
            }
        )
    return rows


def synthetic_rows(quick=False, include_c=False, random_state=0):
    n_train, n_test = (30, 15) if quick else (100, 50)
    data = make_gesture_streams(
        n_train + n_test, n_subjects=(n_train + n_test) // 5, random_state=random_state
    )
    groups = np.asarray(data.groups)
    # Unseen subjects: the last subjects go to the test set.
    test_subjects = np.unique(groups)[-(n_test // 5) :]
    te = np.flatnonzero(np.isin(groups, test_subjects))
    tr = np.flatnonzero(~np.isin(groups, test_subjects))
    rows = []
    for name, make in _methods("paper11", random_state, include_c).items():
        row = _evaluate(
            make,
            [data.X[i] for i in tr],
            [data.y[i] for i in tr],
            [data.X[i] for i in te],
            [data.y[i] for i in te],
        )
        rows.append({"data": f"synthetic {len(tr)}/{len(te)}", "method": name, **row})
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


def run(quick=False, include_c=False):
    return precog_rows(quick, include_c) + synthetic_rows(quick, include_c)


if __name__ == "__main__":
    import sys

    from _common import format_table

    print(
        format_table(
            run(quick="--quick" in sys.argv, include_c="--c" in sys.argv),
            COLUMNS,
            "Jaccard and cost per method",
        )
    )
