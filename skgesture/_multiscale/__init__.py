"""MultiScaleClassifier: Methods A and B of the paper (docs/method.md §5-6).

* ``_rules``: the paper's decision rules (windows of a period, its decision);
* ``_classifier``: the :class:`MultiScaleClassifier` estimator;
* ``_stream``: its live step (the state of one stream).
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture._multiscale._classifier import MultiScaleClassifier

__all__ = ["MultiScaleClassifier"]
