"""Torch modules of the sequence taggers: every one maps ``(batch, time, features)``
to per-frame logits ``(batch, time, classes)``.

* :class:`RecurrentTaggerModule`: stacked bidirectional GRUs or LSTMs with a
  linear read-out per frame (the recommended tagger; Method C's BiLSTM is the
  LSTM case with the paper's activation, dropout and initialisation).
* :class:`TemporalConvModule`: MS-TCN (Farha & Gall, CVPR 2019): a stage of
  dilated residual 1-D convolutions, then refinement stages that read the
  previous stage's probabilities. Returns the logits of every stage (a tuple),
  so the loss can supervise each; the last one is the prediction.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
import torch
from torch import nn
from torch.nn import functional as F
from torch.nn.utils.rnn import PackedSequence, pack_padded_sequence, pad_packed_sequence

__all__ = [
    "RecurrentTaggerModule",
    "TemporalConvModule",
    "final_logits",
    "frame_probabilities",
]

PAPER_MODULE = {"cell": "lstm", "activation": "leaky_relu", "init": "matlab"}
CPU_HIDDEN_SIZES = (64, 64)
CPU_DROPOUT = 0.3
LEAKY_SLOPE = 0.01  # docs/method.md §7.2: LeakyReLU between the paper's BiLSTMs
KERNEL = 3  # MS-TCN's dilated convolution width
# A TCN's dropout masks are slices of one bank of at least MASK_BANK values
# (and MASK_MASKS masks' worth), drawn again once MASK_REUSE times its size
# has been read from it (MaskBank).
MASK_BANK = 2**22
MASK_MASKS = 32
MASK_REUSE = 16


def final_logits(output):
    """The prediction of a module output: the last stage of a tuple, or itself."""
    return output[-1] if isinstance(output, (tuple, list)) else output


def frame_probabilities(module, batch):
    """Per-frame softmax probabilities of ``module`` on a batch of sequences.

    Parameters
    ----------
    module : torch.nn.Module
        A tagger module in eval mode, mapping ``(batch, time, features)`` to
        logits (or a tuple of stages, the last one read).
    batch : ndarray of float32 of shape (n_sequences, n_frames, n_features)
        Sequences of equal length.

    Returns
    -------
    ndarray of float64 of shape (n_sequences, n_frames, n_classes)
        Probabilities.
    """
    device = next(module.parameters()).device
    with torch.inference_mode():
        logits = final_logits(module(torch.as_tensor(batch, device=device)))
        return torch.softmax(logits, dim=-1).cpu().numpy().astype(np.float64)


class RecurrentTaggerModule(nn.Module):
    """Stacked bidirectional recurrent layers and a linear read-out per frame.

    Parameters
    ----------
    n_inputs : int
        Features per frame.
    n_outputs : int
        Classes.
    hidden_sizes : tuple of int, default=(64, 64)
        Units per direction of each layer, input side first.
    cell : {"gru", "lstm"}, default="gru"
        Recurrent cell.
    dropout : float, default=0.0
        Drop probability between layers.
    activation : {"none", "leaky_relu"}, default="none"
        Non-linearity between layers (the paper's BiLSTM uses LeakyReLU).
    init : {"torch", "matlab"}, default="torch"
        Weight initialisation: torch's defaults, or MATLAB's (Glorot-uniform
        input and read-out weights, orthogonal recurrent weights, LSTM
        forget-gate bias 1; docs/method.md §7.2).
    """

    def __init__(
        self,
        n_inputs,
        n_outputs,
        hidden_sizes=(64, 64),
        cell="gru",
        dropout=0.0,
        activation="none",
        init="torch",
    ):
        super().__init__()
        layer = {"gru": nn.GRU, "lstm": nn.LSTM}[cell]
        self.cell = cell
        self.layers = nn.ModuleList()
        width = n_inputs
        for size in hidden_sizes:
            self.layers.append(layer(width, size, batch_first=True, bidirectional=True))
            width = 2 * size
        self.activation = (
            nn.LeakyReLU(LEAKY_SLOPE) if activation == "leaky_relu" else nn.Identity()
        )
        self.dropout = nn.Dropout(dropout)
        self.head = nn.Linear(width, n_outputs)
        if init == "matlab":
            self._matlab_init()

    def _matlab_init(self):
        for rnn in self.layers:
            size = rnn.hidden_size
            for name, param in rnn.named_parameters():
                if name.startswith("weight_ih"):
                    nn.init.xavier_uniform_(param)
                elif name.startswith("weight_hh"):
                    nn.init.orthogonal_(param)
                elif name.startswith("bias_ih") and self.cell == "lstm":
                    nn.init.zeros_(param)
                    with torch.no_grad():
                        param[size : 2 * size] = 1.0  # torch gate order i, f, g, o
                else:  # the other biases (they add up)
                    nn.init.zeros_(param)
        nn.init.xavier_uniform_(self.head.weight)
        nn.init.zeros_(self.head.bias)

    def forward(self, X, lengths=None):
        """Logits of every frame of ``X`` (batch, time, features); with
        ``lengths`` (frames of each sequence), the padding after them is
        packed away, so that the backward direction starts at each
        sequence's last frame (as it does on a sequence alone), and its
        logits are the read-out of zeros."""
        if lengths is None:
            return self.head(self.recurrent(X))
        packed = pack_padded_sequence(
            X, lengths.cpu(), batch_first=True, enforce_sorted=False
        )
        out, _ = pad_packed_sequence(
            self.recurrent(packed), batch_first=True, total_length=X.shape[1]
        )
        return self.head(out)

    def recurrent(self, out):
        """The recurrent layers on a batch ``(batch, time, features)`` or a
        ``PackedSequence`` (of the same type out), with the activation and
        the dropout between them: the network before its read-out."""
        for k, rnn in enumerate(self.layers):
            out, _ = rnn(out)
            if k < len(self.layers) - 1:
                if isinstance(out, PackedSequence):
                    out = out._replace(data=self.dropout(self.activation(out.data)))
                else:
                    out = self.dropout(self.activation(out))
        return out


class MaskDropout(nn.Module):
    """``nn.Dropout`` drawn as random integers and a comparison.

    Each value is zeroed with probability ``p`` and the others are scaled by
    ``1 / (1 - p)``, as ``nn.Dropout`` does. On the CPU torch's dropout
    draws a Bernoulli value at a time, and ``torch.rand_like`` a float at a
    time; here one 64-bit draw gives the 16-bit integers of four values,
    compared with ``p`` scaled to 2**16 (so ``p`` is exact to 2**-16: 0.3
    drops 0.300003 of the values): 2.4x cheaper than ``rand_like`` on the
    recommended model's layers (0.21 against 0.50 ms a mask, and 0.35 ms
    with two 32-bit values a draw). With a ``bank`` (a :class:`MaskBank`
    of the same ``p``, which the layers of one network share) the scaled
    mask is a slice of the bank instead: one product a layer. The identity
    in eval mode.
    """

    bank = None  # (modules pickled before the mask bank existed)

    def __init__(self, p=0.5, bank=None):
        super().__init__()
        self.p = float(p)
        if bank is not None and bank.p != self.p:
            raise ValueError(f"a MaskBank of p={bank.p} for a dropout of p={self.p}")
        self.bank = bank

    def forward(self, x):
        if not self.training or self.p == 0.0:
            return x
        if self.p >= 1.0:
            return torch.zeros_like(x)
        if self.bank is not None:
            return x * self.bank.take(x)
        # one product in the graph: the kept values times 1 / (1 - p) exactly
        scaled = keep_mask(x, self.p).to(x.dtype).mul_(1.0 / (1.0 - self.p))
        return x * scaled


class MaskBank:
    """Scaled dropout masks read from one bank at random offsets.

    The bank holds at least ``MASK_BANK`` values (and ``MASK_MASKS`` masks'
    worth), each ``1 / (1 - p)`` or, with probability ``p``, 0 (drawn by
    :func:`keep_mask` from torch's global generator at the first training
    step, so the fit's seed gives the same bank); a mask is the slice of
    the size of its input at an offset drawn from the same generator. The
    bank is drawn again once ``MASK_REUSE`` times its size has been read from
    it, and is never saved (a loaded network draws its own when it trains).
    The layers of the recommended network share one bank: a mask then costs
    one offset and a product instead of a draw, a comparison, a conversion
    and a product (docs/benchmarks.md, "Cheaper random numbers"). Within a
    mask the values are independent draws; two masks share values only where
    their slices overlap, and then at other positions unless their offsets
    differ by a multiple of the input's size along its last axes.

    Parameters
    ----------
    p : float
        Drop probability, in [0, 1).

    Examples
    --------
    >>> import torch
    >>> from skgesture._nn._modules import MaskBank, MaskDropout
    >>> bank = MaskBank(0.3)
    >>> drop = MaskDropout(0.3, bank=bank).train()
    >>> _ = torch.manual_seed(0)
    >>> out = drop(torch.ones(64, 256, 32))
    >>> round(float((out == 0).float().mean()), 2), round(float(out.max()), 4)
    (0.3, 1.4286)
    """

    def __init__(self, p):
        self.p = float(p)
        self._values, self._unread = None, 0

    def __getstate__(self):
        return {"p": self.p}  # the values are drawn again, never saved

    def __setstate__(self, state):
        self.__init__(state["p"])

    def take(self, x):
        """The scaled mask of ``x``: a tensor of its shape, dtype and device."""
        n, values = x.numel(), self._values
        if (
            values is None
            or self._unread <= 0
            or values.numel() < n
            or values.dtype != x.dtype
            or values.device != x.device
        ):
            size = max(MASK_BANK, MASK_MASKS * n)
            values = torch.empty(size, dtype=x.dtype, device=x.device)
            values = keep_mask(values, self.p).to(x.dtype).mul_(1.0 / (1.0 - self.p))
            self._values, self._unread = values, MASK_REUSE * size
        self._unread -= n
        start = int(torch.randint(values.numel() - n + 1, ()))
        return values[start : start + n].view(x.shape)


def keep_mask(x, p):
    """A boolean tensor shaped as ``x``: each value False with probability
    ``p`` (to 2**-16), from torch's global generator of ``x``'s device."""
    n = x.numel()
    draws = torch.empty((n + 3) // 4, dtype=torch.int64, device=x.device)
    values = draws.random_(-(2**63), None).view(torch.int16)[:n].view(x.shape)
    return values >= int(round(p * 2**16)) - 2**15


class _DilatedResidual(nn.Module):
    """A dilated residual layer: taps ``t - d, t, t + d``, or with ``causal``
    ``t - 2d, t - d, t`` (zeros before the first frame)."""

    causal = False  # (modules pickled before causal layers existed)

    def __init__(self, dilation, channels, dropout, causal=False, bank=None):
        super().__init__()
        self.causal = causal
        self.conv = nn.Conv1d(
            channels,
            channels,
            KERNEL,
            padding=0 if causal else dilation,
            dilation=dilation,
        )
        self.mix = nn.Conv1d(channels, channels, 1)
        self.dropout = MaskDropout(dropout, bank=bank)

    def forward(self, h):
        """``(batch, time, channels)`` in and out."""
        d, n = self.conv.dilation[0], h.shape[1]
        if self.causal:  # taps t - 2d, t - d, t; zeros before the first frame
            z = F.pad(h, (0, 0, (KERNEL - 1) * d, 0))
            taps = torch.cat([z[:, :n], z[:, d : d + n], z[:, 2 * d :]], dim=2)
        else:  # taps t - d, t, t + d; zeros beyond both ends
            z = F.pad(h, (0, 0, d, d))
            taps = torch.cat([z[:, :n], h, z[:, 2 * d :]], dim=2)
        a = F.linear(taps, stacked_taps(self.conv.weight), self.conv.bias)
        return h + self.dropout(pointwise(self.mix, F.relu(a)))


def stacked_taps(weight):
    """A ``Conv1d`` weight ``(out, in, k)`` as ``(out, k * in)``: the linear
    map of its ``k`` shifted inputs concatenated along the channels."""
    return weight.permute(0, 2, 1).reshape(weight.shape[0], -1)


def pointwise(conv, h):
    """A kernel-1 ``Conv1d`` on ``(batch, time, channels)`` rows."""
    return F.linear(h, conv.weight[:, :, 0], conv.bias)


class _Stage(nn.Module):
    def __init__(
        self, n_inputs, n_outputs, channels, n_layers, dropout, causal=False, bank=None
    ):
        super().__init__()
        self.inp = nn.Conv1d(n_inputs, channels, 1)
        self.layers = nn.ModuleList(
            _DilatedResidual(2**k, channels, dropout, causal, bank)
            for k in range(n_layers)
        )
        self.out = nn.Conv1d(channels, n_outputs, 1)

    def forward(self, x):
        """``(batch, time, features)`` in, ``(batch, time, outputs)`` out."""
        h = pointwise(self.inp, x)
        for layer in self.layers:
            h = layer(h)
        return pointwise(self.out, h)


class TemporalConvModule(nn.Module):
    """Multi-stage temporal convolutional network (MS-TCN).

    Parameters
    ----------
    n_inputs : int
        Features per frame.
    n_outputs : int
        Classes.
    channels : int, default=64
        Feature maps of every layer.
    n_layers : int, default=8
        Dilated residual layers per stage (dilations 1, 2, 4, ...); the
        receptive field of a stage is ``2 ** (n_layers + 1) - 1`` frames.
    n_stages : int, default=2
        The first stage plus refinement stages.
    dropout : float, default=0.3
        Drop probability inside the residual layers; their masks are slices
        of one :class:`MaskBank` of the network.
    lookahead : int or None, default=None
        None: every convolution reads ``t - d, t, t + d`` (the output of a
        frame depends on frames far on both sides: whole sequences). An int
        ``L``: every convolution is causal (``t - 2d, t - d, t``) and the
        output of frame ``t`` is read ``L`` frames later, so that it depends
        on the frames up to ``t + L`` and on no later one; the input is
        extended by ``L`` zero rows at its end (the stream's end does the
        same). Such a network streams exactly, ``L`` frames behind
        (:class:`~skgesture._nn._fast.CausalConvScorer`).
    """

    lookahead = None  # (modules pickled before the look-ahead existed)

    def __init__(
        self,
        n_inputs,
        n_outputs,
        channels=64,
        n_layers=8,
        n_stages=2,
        dropout=0.3,
        lookahead=None,
    ):
        super().__init__()
        self.lookahead = lookahead
        causal = lookahead is not None
        bank = MaskBank(dropout) if 0.0 < dropout < 1.0 else None  # all layers'
        self.stages = nn.ModuleList(
            _Stage(
                n_inputs if k == 0 else n_outputs,
                n_outputs,
                channels,
                n_layers,
                dropout,
                causal,
                bank,
            )
            for k in range(n_stages)
        )

    def forward(self, X):
        # Time-major rows throughout: every convolution is one matrix product
        # of its shifted inputs (stacked_taps): a training step's forward and
        # backward 1.2x faster on the CPU than with torch's dilated conv1d
        # (docs/benchmarks.md, "Where a fit's time goes"), the Conv1d parameters kept
        # (so model files of before load) and the arithmetic of the numpy
        # scorers of skgesture/_nn/_fast.py.
        x = X
        if self.lookahead:
            x = F.pad(x, (0, 0, 0, self.lookahead))
        out = self.stages[0](x)
        outputs = [out]
        for stage in self.stages[1:]:
            out = stage(F.softmax(out, dim=-1))
            outputs.append(out)
        L = self.lookahead or 0
        return tuple(o[:, L:] for o in outputs)


_ACTIVATIONS = {
    "relu": nn.ReLU,
    "tanh": nn.Tanh,
    "sigmoid": nn.Sigmoid,
    "leaky_relu": nn.LeakyReLU,
}


class MLPModule(nn.Module):
    """Fully connected network returning logits (the loss applies the output map).

    Parameters
    ----------
    n_inputs : int
        Input width.
    n_outputs : int
        Output width (1 for a sigmoid output, K for a softmax output).
    hidden_layer_sizes : tuple of int
        Width of each hidden layer.
    activations : tuple of str
        Activation after each hidden layer (``"relu"``, ``"tanh"``, ...).
    """

    def __init__(
        self, n_inputs, n_outputs, hidden_layer_sizes=(100,), activations=("tanh",)
    ):
        super().__init__()
        if len(activations) != len(hidden_layer_sizes):
            raise ValueError(
                f"{len(hidden_layer_sizes)} hidden layers but {len(activations)} "
                f"activations"
            )
        layers, width = [], n_inputs
        for size, act in zip(hidden_layer_sizes, activations):
            layers += [nn.Linear(width, size), _ACTIVATIONS[act]()]
            width = size
        layers.append(nn.Linear(width, n_outputs))
        self.net = nn.Sequential(*layers)

    def forward(self, X):
        return self.net(X)


class _BiLSTMModule(RecurrentTaggerModule):
    """Method C's network as saved before it became a
    :class:`~skgesture._nn._modules.RecurrentTaggerModule`; kept so that those
    files load (their ``lstms`` are the ``layers``). New taggers use
    ``RecurrentTaggerModule(**PAPER_MODULE)`` directly."""

    def __init__(
        self, n_inputs, n_outputs, hidden_sizes=CPU_HIDDEN_SIZES, dropout=CPU_DROPOUT
    ):
        super().__init__(
            n_inputs, n_outputs, hidden_sizes, dropout=dropout, **PAPER_MODULE
        )

    def __setstate__(self, state):  # a pickled (joblib) tagger
        modules = state.get("_modules", {})
        if "lstms" in modules:
            state["_modules"] = type(modules)(
                ("layers" if k == "lstms" else k, v) for k, v in modules.items()
            )
            state.setdefault("cell", "lstm")
        super().__setstate__(state)

    def load_state_dict(self, state_dict, *args, **kwargs):  # a model file
        state_dict = {
            ("layers." + k[len("lstms.") :] if k.startswith("lstms.") else k): v
            for k, v in state_dict.items()
        }
        return super().load_state_dict(state_dict, *args, **kwargs)
