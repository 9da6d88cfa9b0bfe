"""Fast CPU inference: numpy copies of the torch networks, bit for bit where stated."""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

# The activations of MLPModule (skgesture._nn._modules._ACTIVATIONS; a test
# holds the names equal), in float32 numpy.
ACTIVATIONS = {
    "relu": lambda h: np.maximum(h, np.float32(0.0)),
    "tanh": np.tanh,
    "sigmoid": lambda h: _sigmoid(h),
    "leaky_relu": lambda h: np.where(h > 0, h, h * np.float32(0.01)),  # torch's slope
}


def module_arrays(net):
    """``{name: float32 ndarray}``: the state of a skorch net's module.

    A :class:`~skgesture._nn._deferred.DeferredNet` (a network of a model file
    that torch has not been needed for) gives its arrays without torch.
    """
    arrays = getattr(net, "module_arrays", None)
    if arrays is not None:
        return arrays
    return {
        name: t.detach().cpu().numpy() for name, t in net.module_.state_dict().items()
    }


class MLPProba:
    """Class probabilities of a fitted :class:`~skgesture.TorchMLPClassifier`, in numpy.

    The forward pass of its :class:`~skgesture._nn._modules.MLPModule` (linear
    layers and their activations, float32, as torch computes it) and the
    output map (a sigmoid for two classes, else a softmax), returned as
    float64 ``(n_samples, n_classes)`` in ``classes_`` order. The same float32
    products as torch, summed by numpy's BLAS: the probabilities equal the
    module's to float32 rounding (about 1e-7). It is the classifier's one
    inference path, offline and live, so a model predicts the same with or
    without torch imported, and loading a model file for prediction never
    imports torch.

    Parameters
    ----------
    estimator : TorchMLPClassifier
        The fitted classifier.
    """

    def __init__(self, estimator):
        from skgesture._nn._defaults import PREDICT_BATCH

        net = estimator.net_
        activations = tuple(net.module__activations)
        arrays = module_arrays(net)
        self.layers = []
        for i in range(len(activations) + 1):
            try:
                weight = arrays[f"net.{2 * i}.weight"]
                bias = arrays[f"net.{2 * i}.bias"]
            except KeyError as exc:
                raise ValueError(
                    f"the network of {type(estimator).__name__} has no layer {exc} "
                    f"(layers: {sorted(arrays)})"
                ) from None
            if self.layers and weight.shape[1] != self.layers[-1][0].shape[1]:
                raise ValueError(
                    f"layer net.{2 * i} takes {weight.shape[1]} inputs, the layer "
                    f"before gives {self.layers[-1][0].shape[1]}"
                )
            act = ACTIVATIONS[activations[i]] if i < len(activations) else None
            # (in, out) weights: x @ W.T without a copy per call
            self.layers.append((weight.T.astype(np.float32, copy=False),
                                bias.astype(np.float32, copy=False), act))  # fmt: skip
        n_out = self.layers[-1][0].shape[1]
        self.binary = len(estimator.classes_) == 2
        if n_out != (1 if self.binary else len(estimator.classes_)):
            raise ValueError(
                f"the network has {n_out} outputs for {len(estimator.classes_)} classes"
            )
        self.n_inputs = self.layers[0][0].shape[0]
        self.batch = PREDICT_BATCH

    def _block(self, x):
        for weight, bias, act in self.layers:
            x = x @ weight + bias
            if act is not None:
                x = act(x)
        if self.binary:
            p = _sigmoid(x[:, 0]).astype(np.float64)
            return np.column_stack([1.0 - p, p])
        return _softmax(x).astype(np.float64)

    def __call__(self, X):
        """``(len(X), n_classes)`` probabilities of the rows ``X``."""
        x = np.asarray(X, dtype=np.float32)
        if x.ndim != 2 or x.shape[1] != self.n_inputs:
            raise ValueError(
                f"expected rows of {self.n_inputs} features, got shape {x.shape}"
            )
        if len(x) <= self.batch:
            return self._block(x)
        return np.concatenate(
            [self._block(x[i : i + self.batch]) for i in range(0, len(x), self.batch)]
        )


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

        module.eval()
        self.mean = mean
        self.scale = scale
        self.weights, self.lstm, self.hidden = [], [], []
        for rnn in module.layers:
            pair = []
            for suffix in ("", "_reverse"):
                w = {n: _to_numpy(getattr(rnn, f"{n}_l0{suffix}")) for n in
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
        self.head = (
            _to_numpy(module.head.weight).T.copy(),
            _to_numpy(module.head.bias),
        )
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
        self.mean = mean
        self.scale = scale
        self.stages = _tcn_stages(module)  # taps t - d, t, t + d

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


class CausalConvScorer:
    """Class probabilities of a bounded look-ahead MS-TCN, row by row, in numpy.

    For a :class:`~skgesture._nn._modules.TemporalConvModule` with
    ``lookahead=L`` (causal convolutions, outputs read ``L`` frames later):
    every feature row that arrives goes through every layer once, each
    layer keeping the last ``2d`` rows of its input (zeros before the first
    frame, as the module's left padding), so the probabilities of frame
    ``u`` are known once row ``u + L`` has arrived, and they are the
    module's offline ones (the same float32 arithmetic in numpy: equal to
    float32 rounding). At the end of the stream ``L`` zero rows are pushed,
    as the module extends a sequence. A scorer of
    :class:`~skgesture._taggers._stream.TrailingWindowStream` (``lookback``
    0: the state is carried).

    Parameters
    ----------
    module : TemporalConvModule
        The fitted network, with an int ``lookahead``.
    mean, scale : ndarray
        The tagger's standardisation.
    """

    lookback = 0

    def __init__(self, module, mean, scale):
        self.mean = mean
        self.scale = scale
        self.lookahead = int(module.lookahead)
        self.stages = _tcn_stages(module)  # causal taps t - 2d, t - d, t
        self.reset()

    def reset(self):
        """A fresh stream: zero history in every layer."""
        self.history = [
            [
                np.zeros((2 * d, stacked.shape[1]), np.float32)
                for d, stacked, *_ in layers
            ]
            for _, layers, _ in self.stages
        ]
        self.n_in = 0  # input rows pushed (the zero rows of the end included)
        self.ended = False
        self.proba = np.empty((0, self.stages[-1][2][0].shape[1]))  # frames to hand on
        self.first = 0  # frame of proba[0]

    def _push(self, x):
        """Standardised rows ``x`` through the network; their outputs kept."""
        for s, ((w_in, b_in), layers, (w_out, b_out)) in enumerate(self.stages):
            if s:
                x = _softmax(x)  # a refinement stage reads probabilities
            h = x @ w_in + b_in
            for k, (d, stacked, bias, w_mix, b_mix) in enumerate(layers):
                full = np.concatenate([self.history[s][k], h])
                m = len(h)
                taps = np.concatenate(
                    [full[:m], full[d : d + m], full[2 * d :]], axis=1
                )
                a = taps @ stacked + bias
                np.maximum(a, 0.0, out=a)
                self.history[s][k] = full[m:]
                h = h + (a @ w_mix + b_mix)
            x = h @ w_out + b_out
        # output row j is frame j - lookahead
        skip = max(self.lookahead - self.n_in, 0)
        self.n_in += len(x)
        self.proba = np.concatenate([self.proba, _softmax(x[skip:]).astype(np.float64)])

    def __call__(self, X, lo, stop, end):
        """Probabilities of frames ``lo .. stop - 1`` (``lo`` the next one);
        rows up to ``end - 1`` are read, and when the last frame asked for
        needs rows past ``end - 1`` the stream has ended there."""
        real = self.n_in - (self.lookahead if self.ended else 0)
        if end > real:
            if self.ended:
                raise ValueError("rows pushed after the end of the stream")
            rows = X.data(real, end)
            self._push(((rows - self.mean) / self.scale).astype(np.float32))
        need = stop + self.lookahead - self.n_in
        if need > 0:  # the end of the stream: the module's zero rows
            self.ended = True
            width = self.stages[0][0][0].shape[0]
            self._push(np.zeros((self.lookahead, width), np.float32))
        if lo != self.first:
            raise IndexError(f"frames scored out of order: {lo}, expected {self.first}")
        out = self.proba[: stop - lo]
        self.proba = self.proba[stop - lo :]
        self.first = stop
        return out


def _to_numpy(t):
    return t.detach().cpu().numpy().astype(np.float32)


def _pointwise(conv):
    """A kernel-1 ``Conv1d`` as ``(in, out)`` weights and its bias."""
    return _to_numpy(conv.weight)[:, :, 0].T.copy(), _to_numpy(conv.bias)


def _tcn_stages(module):
    """The weights of a TemporalConvModule's stages, for numpy: per stage its
    input map, its layers ``(dilation, stacked taps (3 * in, out), bias, mix
    weights, mix bias)`` and its output map."""
    stages = []
    for stage in module.stages:
        layers = []
        for layer in stage.layers:
            W = _to_numpy(layer.conv.weight)  # (out, in, 3): the three taps
            stacked = np.concatenate([W[:, :, k].T for k in range(3)], axis=0)
            d = int(layer.conv.dilation[0])
            bias = _to_numpy(layer.conv.bias)
            layers.append((d, stacked, bias, *_pointwise(layer.mix)))
        stages.append((_pointwise(stage.inp), layers, _pointwise(stage.out)))
    return stages


def _softmax(x):
    e = np.exp(x - x.max(axis=1, keepdims=True))
    return e / e.sum(axis=1, keepdims=True)
