"""Fast CPU inference: numpy copies of the torch networks, bit for bit where stated."""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np


def _module_ops(module):
    """The layers of a sequential torch module as plain torch functions.

    ``nn.Linear``, ``nn.Tanh``, ``nn.ReLU`` and ``nn.Sigmoid`` become the
    functions their ``forward`` calls (the same kernels, hence the same
    numbers), without the module-call machinery that costs more than the
    arithmetic of one row; any other layer is called as a module. ``None``
    when the module is not a plain ``Sequential`` network.
    """
    import functools

    import torch
    from torch import nn

    net = getattr(module, "net", None)
    if not isinstance(net, nn.Sequential) or type(module).forward is not getattr(
        _mlp_module_type(), "forward", None
    ):
        return None
    ops = []
    for layer in net:
        if type(layer) is nn.Linear:
            # Detached: no autograd bookkeeping, without an inference-mode block.
            weight = layer.weight.detach()
            bias = None if layer.bias is None else layer.bias.detach()
            ops.append(functools.partial(torch.nn.functional.linear,
                                         weight=weight, bias=bias))  # fmt: skip
        elif type(layer) is nn.Tanh:
            ops.append(torch.tanh)
        elif type(layer) is nn.ReLU:
            ops.append(torch.relu)
        elif type(layer) is nn.Sigmoid:
            ops.append(torch.sigmoid)
        else:
            ops.append(layer)
    return ops


def _mlp_module_type():
    from skgesture._nn._modules import MLPModule

    return MLPModule


def fast_proba(estimator):
    """``predict_proba`` of a fitted 2-D classifier, as a fast callable.

    For a :class:`~skgesture.TorchMLPClassifier` on the CPU the network's layers
    are called directly: the same float32 forward pass and output map as
    ``predict_proba`` (hence the same numbers), without its per-call input
    validation and module-call machinery, which cost more than the forward
    pass of one row. Any other classifier's own ``predict_proba`` is returned.
    """
    import torch

    from skgesture._nn._mlp import TorchMLPClassifier

    if not isinstance(estimator, TorchMLPClassifier):
        return estimator.predict_proba
    module = estimator.net_.module_
    if next(module.parameters()).device.type != "cpu":
        return estimator.predict_proba
    module.eval()
    ops = _module_ops(module)
    binary = len(estimator.classes_) == 2
    if ops is None:
        ops = [module]
        context = torch.inference_mode
    else:
        import contextlib

        context = contextlib.nullcontext  # detached weights: nothing to record

    def proba(X):
        with context():
            x = torch.from_numpy(np.ascontiguousarray(X, dtype=np.float32))
            for op in ops:
                x = op(x)
            if binary:
                p = torch.sigmoid(x).numpy()[:, 0].astype(np.float64)
                out = np.empty((len(p), 2))
                out[:, 1] = p
                np.subtract(1.0, p, out=out[:, 0])
                return out
            return torch.softmax(x, dim=1).numpy().astype(np.float64)

    return proba


class RecurrentScorer:
    """Class probabilities of a frame from a bidirectional recurrent network,
    its forward states carried along the stream.

    For :class:`~skgesture._nn._modules.RecurrentTaggerModule` (stacked
    bidirectional GRUs or LSTMs and a linear read-out): the forward direction
    of every layer is run once per frame from the state it had at the frame
    before, as over the whole recording offline (no look-back window: the
    first layer's forward outputs are the offline ones); the backward
    direction of every layer is run from the last row known (``end - 1``)
    down to the frame, from a zero state, as if the recording ended there.
    Per frame that is ``n_layers`` forward steps and ``n_layers * (end - u)``
    backward steps, instead of the whole window through both directions.

    The cells run in numpy, float32, with the module's weights and torch's
    equations (GRU gates ``r, z, n``, LSTM gates ``i, f, g, o``): a torch
    call costs about 10 µs per step and 15 µs per call on these sizes, twice
    the numpy arithmetic; the probabilities equal the module's to float32
    rounding (about 1e-6).

    Parameters
    ----------
    module : RecurrentTaggerModule
        The fitted network.
    mean, scale : ndarray
        The tagger's standardisation.
    """

    lookback = 0

    def __init__(self, module, mean, scale):
        import torch

        def numpy(t):
            return t.detach().cpu().numpy().astype(np.float32)

        module.eval()
        self.mean = mean
        self.scale = scale
        self.weights, self.lstm, self.hidden = [], [], []
        for rnn in module.layers:
            pair = []
            for suffix in ("", "_reverse"):
                w = {n: numpy(getattr(rnn, f"{n}_l0{suffix}")) for n in
                     ("weight_ih", "bias_ih", "weight_hh", "bias_hh")}  # fmt: skip
                pair.append((w["weight_ih"].T.copy(), w["bias_ih"],
                             w["weight_hh"].T.copy(), w["bias_hh"]))  # fmt: skip
            self.weights.append(pair)
            self.lstm.append(isinstance(rnn, torch.nn.LSTM))
            self.hidden.append(int(rnn.hidden_size))
        act = module.activation  # between layers (dropout: identity in eval)
        if isinstance(act, torch.nn.Identity):
            self.activation = None
        elif isinstance(act, torch.nn.LeakyReLU):
            slope = np.float32(act.negative_slope)
            self.activation = lambda h: np.where(h > 0, h, h * slope)
        else:
            self.activation = lambda h: act(torch.from_numpy(h)).numpy()
        self.head = (numpy(module.head.weight).T.copy(), numpy(module.head.bias))
        self.reset()

    def reset(self):
        """A fresh stream: zero forward states."""
        self.states = [self._zero(k) for k in range(len(self.hidden))]
        self.n_done = 0  # rows whose forward state of layers 2.. is committed
        self.first = np.empty((0, self.hidden[0]), dtype=np.float32)  # rows n_done..
        self.first_stop = 0  # rows with a first-layer forward output

    def _zero(self, k):
        z = np.zeros(self.hidden[k], dtype=np.float32)
        return (z, z) if self.lstm[k] else z

    def _run(self, k, direction, x, state):
        """Layer ``k``'s direction (0 forward, 1 backward: from the last row)
        over the rows ``x``; its outputs, in row order, and its last state."""
        w_ih, b_ih, w_hh, b_hh = self.weights[k][direction]
        gates = x @ w_ih + b_ih
        H = self.hidden[k]
        out = np.empty((len(x), H), dtype=np.float32)
        rows = range(len(x) - 1, -1, -1) if direction else range(len(x))
        if self.lstm[k]:
            h, c = state
            for t in rows:
                g = gates[t] + (h @ w_hh + b_hh)
                i, f, o = _sigmoid(g[:H]), _sigmoid(g[H : 2 * H]), _sigmoid(g[3 * H :])
                c = f * c + i * np.tanh(g[2 * H : 3 * H])
                h = o * np.tanh(c)
                out[t] = h
            return out, (h, c)
        h = state
        for t in rows:
            gh = h @ w_hh + b_hh
            rz = _sigmoid(gates[t, : 2 * H] + gh[: 2 * H])
            n = np.tanh(gates[t, 2 * H :] + rz[:H] * gh[2 * H :])
            h = n + rz[H:] * (h - n)
            out[t] = h
        return out, h

    def _standardised(self, X, lo, hi):
        return ((X.data(lo, hi) - self.mean) / self.scale).astype(np.float32)

    def __call__(self, X, lo, stop, end):
        """Probabilities of rows ``lo .. stop - 1`` (``lo`` the next row), each
        from the rows up to ``end - 1``; the forward states move to ``stop``."""
        if lo != self.n_done:
            raise IndexError(f"rows scored out of order: {lo}, expected {self.n_done}")
        if end > self.first_stop:  # the first layer's forward direction
            x = self._standardised(X, self.first_stop, end)
            out, self.states[0] = self._run(0, 0, x, self.states[0])
            self.first = np.concatenate([self.first, out])
            self.first_stop = end
        back, _ = self._run(0, 1, self._standardised(X, lo, end), self._zero(0))
        h = np.concatenate([self.first[: end - lo], back], axis=1)
        m = stop - lo
        last = len(self.hidden) - 1
        for k in range(1, last + 1):
            if self.activation is not None:
                h = self.activation(h)
            ahead, self.states[k] = self._run(k, 0, h[:m], self.states[k])
            if k < last and end > stop:  # later rows, from the new state
                more, _ = self._run(k, 0, h[m:], self.states[k])
                ahead = np.concatenate([ahead, more])
            back, _ = self._run(k, 1, h, self._zero(k))
            h = np.concatenate([ahead, back if k < last else back[:m]], axis=1)
        w, b = self.head
        prob = _softmax(h[:m] @ w + b).astype(np.float64)
        self.n_done = stop
        self.first = self.first[m:]
        return prob


def _sigmoid(x):
    from scipy.special import expit  # no overflow warning for large |x|

    return expit(x)


class TemporalConvProba:
    """Class probabilities of an MS-TCN on a block of rows, in numpy.

    The arithmetic of :class:`~skgesture._nn._modules.TemporalConvModule` (eval
    mode: dropout off) with every dilated convolution written as one matrix
    product of the three shifted copies of its input (zero padding at the
    block's ends, as ``padding=dilation``): the same float32 products, summed
    in another order, so the probabilities equal the module's to float32
    rounding. torch's dilated ``conv1d`` costs about 100 µs per call on the
    few rows of a stream's window, the product about 15 µs; a layer whose
    dilation reaches past the block reads only its centre tap.

    Parameters
    ----------
    module : TemporalConvModule
        The fitted network (CPU).
    mean, scale : ndarray
        The tagger's standardisation.
    """

    def __init__(self, module, mean, scale):
        def numpy(t):
            return t.detach().cpu().numpy().astype(np.float32)

        def pointwise(conv):  # a kernel-1 Conv1d as (in, out) weights and bias
            return numpy(conv.weight)[:, :, 0].T.copy(), numpy(conv.bias)

        self.mean = mean
        self.scale = scale
        self.stages = []
        for stage in module.stages:
            layers = []
            for layer in stage.layers:
                W = numpy(layer.conv.weight)  # (out, in, 3): taps t - d, t, t + d
                stacked = np.concatenate([W[:, :, k].T for k in range(3)], axis=0)
                d = int(layer.conv.dilation[0])
                bias = numpy(layer.conv.bias)
                layers.append((d, stacked, bias, *pointwise(layer.mix)))
            self.stages.append((pointwise(stage.inp), layers, pointwise(stage.out)))

    def __call__(self, rows):
        """``(len(rows), n_classes)`` probabilities of consecutive feature rows."""
        x = ((rows - self.mean) / self.scale).astype(np.float32)
        n = len(x)
        for s, ((w_in, b_in), layers, (w_out, b_out)) in enumerate(self.stages):
            if s:
                x = _softmax(x)  # a refinement stage reads probabilities
            h = x @ w_in + b_in
            for d, stacked, bias, w_mix, b_mix in layers:
                c = h.shape[1]
                if d >= n:  # the other taps fall in the padding
                    a = h @ stacked[c : 2 * c] + bias
                else:
                    z = np.zeros((n + 2 * d, c), dtype=np.float32)
                    z[d : d + n] = h
                    shifted = np.concatenate([z[:n], h, z[2 * d :]], axis=1)
                    a = shifted @ stacked + bias
                np.maximum(a, 0.0, out=a)
                h = h + (a @ w_mix + b_mix)
            x = h @ w_out + b_out
        return _softmax(x).astype(np.float64)


def _softmax(x):
    e = np.exp(x - x.max(axis=1, keepdims=True))
    return e / e.sum(axis=1, keepdims=True)
