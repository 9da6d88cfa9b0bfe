"""Models pickled by an earlier skgesture: the parameters added since.

scikit-learn's ``get_params`` (and so ``set_params``, ``clone`` and
``GridSearchCV``) reads every parameter of ``__init__`` as an attribute. A
model pickled before a parameter existed has no such attribute, so it would
predict but could not be tuned or cloned. :class:`NewParamsMixin` gives such a
model, as it is loaded, every missing parameter at its default. A parameter is
only ever added with a default that keeps what models did before it (the code
that reads it falls back to the same value), so the loaded model predicts as
it did (tests/test_legacy_models.py).
"""

# SPDX-License-Identifier: BSD-3-Clause

import inspect

__all__ = ["NewParamsMixin"]


class NewParamsMixin:
    """Mixin of an estimator: on unpickling, the ``__init__`` parameters that
    the pickled state lacks are set to their defaults.

    Put it before ``BaseEstimator`` in the bases.

    Examples
    --------
    >>> from sklearn.base import BaseEstimator
    >>> from skgesture.utils._params import NewParamsMixin
    >>> class Model(NewParamsMixin, BaseEstimator):
    ...     def __init__(self, alpha=1.0, beta="new"):
    ...         self.alpha = alpha
    ...         self.beta = beta
    >>> state = Model(alpha=2.0).__getstate__()
    >>> del state["beta"]  # as pickled before beta existed
    >>> loaded = Model.__new__(Model)
    >>> loaded.__setstate__(state)  # what unpickling does
    >>> loaded.get_params()
    {'alpha': 2.0, 'beta': 'new'}
    """

    def __setstate__(self, state):
        super().__setstate__(state)
        for name, param in inspect.signature(type(self).__init__).parameters.items():
            if param.kind not in (param.POSITIONAL_OR_KEYWORD, param.KEYWORD_ONLY):
                continue
            if name != "self" and name not in self.__dict__:
                if param.default is not param.empty:
                    setattr(self, name, param.default)
