"""A network read from a model file, kept as arrays until torch is needed.

Importing torch and skorch costs seconds; predicting with the paper's MLPs
needs neither (their inference runs in numpy, :class:`~skgesture._nn._fast.MLPProba`).
So :func:`~skgesture.load_model` gives a :class:`~skgesture.TorchMLPClassifier`
a :class:`DeferredNet` in place of its skorch net: its module's weights as
numpy arrays and its module's parameters, which is all that prediction reads.
Anything else asked of it (training further, its history, its torch module)
builds the skorch net, once, and is answered by it; copying or pickling it
gives that skorch net.
"""

# SPDX-License-Identifier: BSD-3-Clause

import threading

__all__ = ["DeferredNet"]


class DeferredNet:
    """A skorch net of a model file, built only when torch is needed.

    Parameters
    ----------
    module_arrays : dict of str to ndarray
        The state of the net's module (``module_.state_dict()``), as arrays.
    module_params : dict
        The net's ``module__*`` parameters (plain values).
    build : callable
        ``build()`` returns the skorch net, with these weights.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._nn._deferred import DeferredNet
    >>> calls = []
    >>> net = DeferredNet({"net.0.weight": np.zeros((2, 3), np.float32)},
    ...                   {"module__activations": ()},
    ...                   build=lambda: calls.append(1) or "the skorch net")
    >>> net.module__activations, calls
    ((), [])
    >>> net.materialize(), net.materialize(), calls
    ('the skorch net', 'the skorch net', [1])
    """

    def __init__(self, module_arrays, module_params, build):
        self._arrays = module_arrays
        self._params = dict(module_params)
        self._build = build
        self._net = None
        self._lock = threading.Lock()

    @property
    def built(self):
        """Whether the skorch net has been built."""
        return self._net is not None

    @property
    def module_arrays(self):
        """The module's state as arrays (the built net's current state once built)."""
        if self._net is None:
            return self._arrays
        from skgesture._nn._fast import module_arrays

        return module_arrays(self._net)

    def materialize(self):
        """The skorch net (imports torch and skorch, and builds it the first time)."""
        with self._lock:
            if self._net is None:
                self._net = self._build()
                self._arrays = None
        return self._net

    def __getattr__(self, name):
        # only reached for names that are not set on the instance
        if name.startswith("__") or name in ("_arrays", "_params", "_build", "_net"):
            raise AttributeError(name)
        if self._net is None and name in self._params:
            return self._params[name]
        return getattr(self.materialize(), name)

    def __setattr__(self, name, value):
        if name in ("_arrays", "_params", "_build", "_net", "_lock"):
            object.__setattr__(self, name, value)
        else:
            setattr(self.materialize(), name, value)

    def __reduce_ex__(self, protocol):
        # a copy or a pickle holds the skorch net itself
        return (_net, (self.materialize(),))

    def __repr__(self):
        state = "built" if self._net is not None else "not built: numpy arrays"
        return f"<DeferredNet of a model file ({state})>"


def _net(net):
    """What a pickled or copied :class:`DeferredNet` becomes: its skorch net."""
    return net
