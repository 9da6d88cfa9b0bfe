"""Scorers for ``GridSearchCV``, ``cross_validate`` and friends.

A scorer is a callable ``scorer(estimator, X, y) -> float`` (greater is better)
that calls ``estimator.predict(X)``, which returns one per-frame label array per
sequence, and scores it against ``y``. scikit-learn accepts any such callable,
alone or in a dict for multi-metric evaluation.
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture.metrics._jaccard import _check_mode, jaccard_index
from skgesture.metrics._segmental import edit_score, frame_accuracy, segmental_f1

__all__ = [
    "make_sequence_scorer",
    "make_jaccard_scorer",
    "jaccard_scorer",
    "get_scorer",
    "SCORERS",
]


class _SequenceScorer:
    """Calls ``estimator.predict(X)`` and scores it with ``score_func(y, y_pred)``."""

    def __init__(self, score_func, kwargs, factory=None):
        self._score_func = score_func
        self._kwargs = dict(kwargs)
        self._factory = factory

    def __call__(self, estimator, X, y):
        if y is None:
            raise ValueError(
                "this scorer needs the true per-frame labels y; got y=None"
            )
        y_pred = estimator.predict(X)
        return float(self._score_func(y, y_pred, **self._kwargs))

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self._kwargs.items())
        if self._factory is not None:
            return f"{self._factory}({args})"
        sep = ", " if args else ""
        return f"make_sequence_scorer({self._score_func.__name__}{sep}{args})"


def make_sequence_scorer(score_func, **kwargs):
    """Make a scorer from a metric of lists of per-frame labels.

    Parameters
    ----------
    score_func : callable
        ``score_func(y_true, y_pred, **kwargs) -> float``, greater is better,
        e.g. :func:`segmental_f1` or :func:`jaccard_index`.
    **kwargs : dict
        Keyword arguments passed to ``score_func``.

    Returns
    -------
    callable
        ``scorer(estimator, X, y) -> float``, usable as ``scoring=`` (alone or
        as a value of a dict) in ``GridSearchCV`` and ``cross_validate``.

    See Also
    --------
    make_jaccard_scorer : The Jaccard index scorer in one of its modes.
    get_scorer : Ready-made scorers by name.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.metrics import make_sequence_scorer, segmental_f1
    >>> class Tagger:  # predicts the labels stored in the first column of X
    ...     def predict(self, X):
    ...         return [x[:, 0].astype(int) for x in X]
    >>> y = [np.array([0, 1, 1, 1, 0, 0, 2, 2])]
    >>> X = [np.array([[0], [0], [1], [1], [0], [0], [2], [2]])]
    >>> scorer = make_sequence_scorer(segmental_f1, overlap=0.5)
    >>> scorer
    make_sequence_scorer(segmental_f1, overlap=0.5)
    >>> scorer(Tagger(), X, y)
    1.0
    """
    if not callable(score_func):
        raise TypeError(f"score_func must be callable, got {score_func!r}")
    return _SequenceScorer(score_func, kwargs)


def make_jaccard_scorer(mode="official_2014"):
    """Make a scorer computing :func:`jaccard_index` in the given mode.

    Parameters
    ----------
    mode : {"official_2014", "fp_penalised", "inclusive"}, default="official_2014"
        Passed to :func:`jaccard_index`.

    Returns
    -------
    callable
        ``scorer(estimator, X, y) -> float``, the mean Jaccard index of
        ``estimator.predict(X)`` against ``y``.

    See Also
    --------
    jaccard_scorer : The official-mode scorer, ready made.

    Examples
    --------
    >>> from skgesture.metrics import make_jaccard_scorer
    >>> make_jaccard_scorer(mode="fp_penalised")
    make_jaccard_scorer(mode='fp_penalised')
    """
    _check_mode(mode)
    return _SequenceScorer(jaccard_index, {"mode": mode}, factory="make_jaccard_scorer")


jaccard_scorer = make_jaccard_scorer()

SCORERS = {
    "jaccard": jaccard_scorer,
    "jaccard_fp_penalised": make_jaccard_scorer(mode="fp_penalised"),
    "jaccard_inclusive": make_jaccard_scorer(mode="inclusive"),
    "frame_accuracy": make_sequence_scorer(frame_accuracy),
    "f1@10": make_sequence_scorer(segmental_f1, overlap=0.1),
    "f1@25": make_sequence_scorer(segmental_f1, overlap=0.25),
    "f1@50": make_sequence_scorer(segmental_f1, overlap=0.5),
    "edit": make_sequence_scorer(edit_score),
}


def get_scorer(scoring):
    """Return a scorer by name (a key of ``SCORERS``).

    Parameters
    ----------
    scoring : str or callable
        One of ``"jaccard"``, ``"jaccard_fp_penalised"``, ``"jaccard_inclusive"``,
        ``"frame_accuracy"``, ``"f1@10"``, ``"f1@25"``, ``"f1@50"``, ``"edit"``.
        A callable is returned unchanged, as :func:`sklearn.metrics.get_scorer`
        does.

    Returns
    -------
    callable
        ``scorer(estimator, X, y) -> float``.

    See Also
    --------
    make_sequence_scorer : Build a scorer from any sequence metric.

    Examples
    --------
    >>> from skgesture.metrics import get_scorer
    >>> get_scorer("f1@50")
    make_sequence_scorer(segmental_f1, overlap=0.5)
    >>> get_scorer("jaccard")
    make_jaccard_scorer(mode='official_2014')
    """
    if callable(scoring):
        return scoring
    try:
        return SCORERS[scoring]
    except (KeyError, TypeError):
        raise ValueError(
            f"{scoring!r} is not a skgesture scorer name; valid names are "
            f"{sorted(SCORERS)}"
        ) from None
