"""Thread limits of the BLAS libraries during prediction.

numpy's BLAS (OpenBLAS) splits even small matrix products over every core.
The products of prediction are small (a gesture run's rows projected on 24
components, an MLP's rows), so the threads gain nothing and, on a machine
whose cores are busy, wait for each other: a ``predict`` of the recommended
model on PRECOG ran at 69 µs a frame with the BLAS threads as they were and at
55 with one thread, beside two training processes (docs/benchmarks.md,
"BLAS threads in prediction"). Estimators therefore run their numpy inference
with as many BLAS threads as their ``n_threads`` (torch's threads are set by
:func:`skgesture._nn._training.torch_threads`). This module imports no torch,
so that a model file loaded for prediction needs none.
"""

# SPDX-License-Identifier: BSD-3-Clause

import functools
from contextlib import contextmanager

__all__ = ["blas_threads"]


@functools.cache
def _blas_controller():
    """One scan of the loaded BLAS libraries, reused by every prediction."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


@contextmanager
def blas_threads(n_threads):
    """Run the block with at most ``n_threads`` BLAS threads (None: as is).

    The previous limits are restored on exit. Entering costs about 50 µs:
    use it around a whole prediction, not around each frame.

    Parameters
    ----------
    n_threads : int or None
        Threads of every loaded BLAS library inside the block.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils._threads import blas_threads
    >>> with blas_threads(1):
    ...     product = np.ones((3, 4)) @ np.ones((4, 2))
    >>> product.shape
    (3, 2)
    """
    if n_threads is None:
        yield
        return
    with _blas_controller().limit(limits=int(n_threads), user_api="blas"):
        yield
