"""PoseDescriptor: the paper's per-frame pose descriptor (docs/method.md §3).

* ``_constants``: the constants shared by every implementation;
* ``_compute``: the numpy implementation, and the switch to the compiled kernel;
* ``_kernel``: the compiled kernel (numba, optional);
* ``_estimator``: the :class:`PoseDescriptor` estimator;
* ``_stream``: its live step (the state of one stream).
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture._descriptor._estimator import PoseDescriptor

__all__ = ["PoseDescriptor"]
