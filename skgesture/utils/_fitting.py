"""Fitting the estimators inside an estimator: seeds and the network cache.

Estimators that own networks (the segmenter's frame network, the window
networks of every scale, the taggers') fit them through :func:`fit_cached`,
which caches the fitted network with ``joblib.Memory`` keyed on the training
data and the network's own parameters only, so decision parameters
(thresholds, weights, smoothing, minimum lengths) can be searched by
``GridSearchCV`` without retraining (docs/design.md §3). One ``random_state``
on the outer estimator seeds every network through :func:`seed_from`
(docs/design.md §9). Nothing here needs torch.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
from sklearn.base import clone
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_memory

__all__ = ["fit_cached", "fit_inner_estimator", "seed_from"]


def _fit_clone(estimator, X, y, verbose=None):
    est = clone(estimator)
    if verbose is not None:
        est.set_params(verbose=verbose)
    return est.fit(X, y)


def fit_cached(memory, estimator, X, y):
    """Fit a clone of ``estimator`` on ``(X, y)``, cached by ``memory``.

    The cache key is the estimator's parameters and the data, nothing else: an
    estimator holding this network sees the same cached network whatever its own
    decision parameters are (docs/design.md §3). Its ``verbose`` is left out of the
    key too: showing progress never retrains a cached network.

    Parameters
    ----------
    memory : None, str or joblib.Memory
        Where to cache; ``None`` disables caching.
    estimator : estimator
        The unfitted estimator (its ``random_state`` must be an int or None to
        give a stable key).
    X, y : array-like
        Training data.

    Returns
    -------
    estimator
        The fitted clone.
    """
    memory = check_memory(memory)
    verbose = None
    if "verbose" in estimator.get_params(deep=False):
        verbose = estimator.get_params(deep=False)["verbose"]
        estimator = clone(estimator).set_params(verbose=0)
    fitted = memory.cache(_fit_clone, ignore=["verbose"])(estimator, X, y, verbose)
    if verbose is not None:
        fitted.set_params(verbose=verbose)  # as asked, even from the cache
    return fitted


def seed_from(random_state):
    """An int seed for torch drawn from a numpy ``random_state`` (docs/design.md §9)."""
    return int(check_random_state(random_state).randint(np.iinfo(np.int32).max))


def fit_inner_estimator(estimator, default, X, y, *, rng, memory, verbose=0):
    """Fit a clone of ``estimator`` (or of ``default``) for a sequence estimator.

    When ``rng`` is given, an int seed drawn from it replaces the clone's
    ``random_state`` (if it has one), so one ``random_state`` on the outer
    estimator controls every network it trains. A ``verbose`` above 0 is handed
    on to the clone (if it has that parameter), so the outer estimator's
    verbosity shows the network's progress: a bar at 1, one line per epoch at 2.
    """
    est = clone(default if estimator is None else estimator)
    params = est.get_params()
    if rng is not None and "random_state" in params:
        est.set_params(random_state=seed_from(rng))
    if verbose and "verbose" in params:
        est.set_params(verbose=verbose)
    return fit_cached(memory, est, X, y)
