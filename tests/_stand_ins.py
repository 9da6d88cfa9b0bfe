"""Stand-ins for the networks of Methods A/B, shared by the streaming tests.

``make_cheap_pipeline()`` is Method B's pipeline with an always-active
segmenter and a numpy window classifier: it fits and predicts in milliseconds,
and every frame lies inside a period, which stresses the period buffers.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.pipeline import Pipeline

from skgesture import (
    ActivitySegmenter,
    DynamicPoseWindow,
    MultiScaleClassifier,
    PoseDescriptor,
)


class ConstantProba(ClassifierMixin, BaseEstimator):
    """Segmenter network stand-in: every frame has gesture probability ``p``."""

    def __init__(self, p=0.9):
        self.p = p

    def fit(self, X, y):
        self.classes_ = np.unique(y)
        return self

    def predict_proba(self, X):
        return np.tile([1.0 - self.p, self.p], (len(X), 1))


class CentroidProba(ClassifierMixin, BaseEstimator):
    """Softmax of minus mean squared distances to class means (microseconds)."""

    def fit(self, X, y):
        self.classes_, inv = np.unique(y, return_inverse=True)
        self.means_ = np.stack([X[inv == k].mean(0) for k in range(len(self.classes_))])
        return self

    def predict_proba(self, X):
        d = -((np.asarray(X)[:, None, :] - self.means_[None]) ** 2).mean(-1)
        e = np.exp(d - d.max(axis=1, keepdims=True))
        return e / e.sum(axis=1, keepdims=True)


def make_cheap_pipeline():
    """The unfitted cheap Method B pipeline (module docstring)."""
    return Pipeline([
        ("descriptor", PoseDescriptor()),
        ("segmenter", ActivitySegmenter(ConstantProba())),
        ("windows", DynamicPoseWindow(steps=(4, 2))),
        ("classifier", MultiScaleClassifier(
            CentroidProba(), steps=(4, 2), threshold_short=0.2, threshold_long=0.2
        )),
    ])  # fmt: skip
