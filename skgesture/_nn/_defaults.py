"""Numbers shared by the training loop and the estimators' signatures.

They live apart from ``_training`` (which needs torch and skorch) so that an
estimator's module, and a model file that names it, import without torch.
"""

# SPDX-License-Identifier: BSD-3-Clause

__all__ = [
    "PREDICT_BATCH",
    "SCG_MAX_FAIL",
    "SCG_MIN_GRAD",
    "TEST_FRACTION",
    "VALIDATION_FRACTION",
]

# MATLAB trainscg defaults, docs/method.md §8.6.1
SCG_MAX_FAIL = 6
SCG_MIN_GRAD = 1e-6
# MATLAB dividerand defaults, docs/method.md §8.6.4
VALIDATION_FRACTION = 0.15
TEST_FRACTION = 0.15
# Rows per forward pass when predicting (bounds the memory of one pass).
PREDICT_BATCH = 65536
