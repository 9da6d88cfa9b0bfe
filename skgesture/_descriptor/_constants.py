"""The descriptor's constants (docs/method.md §3).

Shared by the numpy code, the compiled kernel and the live step.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

GAUSSIAN_SIZE = 5  # docs/method.md §3.6: fspecial('gaussian', [5 1], 1)
DERIVATIVE_REACH = 2  # docs/method.md §3.7: the acceleration looks 2 frames each way
EDGE = max((GAUSSIAN_SIZE - 1) // 2, DERIVATIVE_REACH)  # padding per sequence end
MIN_NORM = 1e-8  # docs/method.md §3.9-3.11: below this a vector is degenerate
MIN_SCALE = 1e-8  # docs/method.md §3.14: a feature with smaller std keeps scale 1
DEGENERATE_INCLINATION = np.pi / 2  # docs/method.md decision D8
BATCH_VALUES = 750_000  # descriptor values per vectorised pass (4096 frames of
# 183 features): large enough to amortise the Python overhead, small enough
# for the intermediates to stay in cache
