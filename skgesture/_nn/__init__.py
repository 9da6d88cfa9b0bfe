"""Every torch network of skgesture, its skorch wiring and its fast inference.

* ``_modules``: the ``nn.Module`` classes (MLP, recurrent and temporal
  convolution taggers);
* ``_fast``: numpy/torch-function copies of those modules for fast CPU
  inference, bit for bit where stated;
* ``_training``: losses, data loaders, callbacks, the framewise training loop
  (:class:`FramewiseNetwork`), network caching and seeding;
* ``_sequence_net``: the skorch net of the sequence taggers (crops, hold-out);
* ``_mlp``: :class:`~skgesture.TorchMLPClassifier`.

Nothing is imported here, so that importing one submodule does not import torch
through the others.
"""

# SPDX-License-Identifier: BSD-3-Clause
