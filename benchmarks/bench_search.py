"""GridSearchCV over decision parameters with and without the network cache.

Method B on bundled PRECOG: 20 candidates (fusion weights x short/long
thresholds), 2 group folds. With ``memory`` the networks train once per fold;
without, once per candidate and fold. Both searches must pick the same best
parameters.
"""

import tempfile
import time

import numpy as np
from joblib import Memory
from sklearn.model_selection import GridSearchCV, GroupKFold

from skgesture import make_method_b
from skgesture.datasets import load_precog
from skgesture.metrics import jaccard_scorer

GRID = {
    "classifier__weights": [
        (0.4895, 0.4576, 0.0529),
        (1, 1, 1),
        (1, 0, 0),
        (0, 1, 0),
        (0, 0, 1),
    ],
    "classifier__threshold_short": [0.5, 0.6014],
    "classifier__threshold_long": [0.45, 0.6033],
}
QUICK_GRID = {
    "classifier__weights": [(0.4895, 0.4576, 0.0529), (1, 1, 1)],
    "classifier__threshold_short": [0.5, 0.6014],
    "classifier__threshold_long": [0.6033],
}


def _search(memory, grid, X, y, groups):
    model = make_method_b(joints="full20", memory=memory, random_state=0)
    search = GridSearchCV(model, grid, scoring=jaccard_scorer, cv=GroupKFold(2))
    t0 = time.perf_counter()
    search.fit(X, y, groups=groups)
    return time.perf_counter() - t0, search


def run(quick=False):
    data = load_precog()
    groups = np.asarray(data.groups)
    grid = QUICK_GRID if quick else GRID
    n_cand = int(np.prod([len(v) for v in grid.values()]))
    with tempfile.TemporaryDirectory() as folder:
        t_cached, s_cached = _search(
            Memory(folder, verbose=0), grid, data.X, data.y, groups
        )
    t_plain, s_plain = _search(None, grid, data.X, data.y, groups)
    same = s_cached.best_params_ == s_plain.best_params_
    return [
        {
            "search": f"{n_cand} candidates x 2 folds, memory=None",
            "seconds": t_plain,
            "best jaccard": s_plain.best_score_,
            "best params": s_plain.best_params_,
        },
        {
            "search": f"{n_cand} candidates x 2 folds, memory=joblib.Memory",
            "seconds": t_cached,
            "best jaccard": s_cached.best_score_,
            "best params": s_cached.best_params_,
        },
        {
            "search": "speed-up (plain / cached)",
            "seconds": t_plain / t_cached,
            "best jaccard": float("nan"),
            "best params": f"same best: {same}",
        },
    ]


COLUMNS = ["search", "seconds", "best jaccard", "best params"]

if __name__ == "__main__":
    from _common import format_table

    print(format_table(run(), COLUMNS))
