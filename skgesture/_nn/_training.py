"""Torch modules and the skorch wiring shared by every network in skgesture.

:func:`build_net` makes the skorch net of any of the paper's MLPs;
:class:`FramewiseNetwork` holds the one training loop of every framewise tagger
network (Method C's BiLSTM and the recommended taggers). Estimators that
own networks fit them through :func:`~skgesture.utils._fitting.fit_cached`,
which caches the fitted network keyed on the training data and the network's
own parameters only (docs/design.md §3). Every network is a :class:`LeanNet`,
which leaves its training-only state out of pickles.
"""

# SPDX-License-Identifier: BSD-3-Clause

import copy
import threading
from collections import defaultdict
from contextlib import contextmanager

import numpy as np
import torch
from sklearn.base import BaseEstimator
from skorch import NeuralNet
from skorch.callbacks import Callback, EarlyStopping
from skorch.dataset import Dataset
from torch import nn
from torch.nn import functional as F

from skgesture._nn._defaults import (
    SCG_MAX_FAIL,
    SCG_MIN_GRAD,
    TEST_FRACTION,
    VALIDATION_FRACTION,
)
from skgesture._nn._modules import MLPModule
from skgesture.utils._params import NewParamsMixin

__all__ = [
    "FramewiseLoss",
    "FramewiseNetwork",
    "LeanNet",
    "SequenceSplit",
    "MLPModule",
    "build_net",
    "held_out_sequences",
    "torch_threads",
]

IGNORE_INDEX = -100  # target of frames a framewise loss leaves out (padding, untracked)
SMOOTHING_CLAMP = 16.0  # MS-TCN's truncation of the squared log-prob change


class LeanNet(NeuralNet):
    """skorch's ``NeuralNet``, pickled without its training-only state.

    Every network of skgesture is one. A fitted net holds, besides its
    weights, state that only training uses: the optimiser's (SCG keeps three
    float64 vectors of the size of the weights, Adam two moments) and its
    callbacks' (the best weights so far, the learning-rate scheduler and its
    optimiser, a progress bar). A pickle (``pickle``, ``joblib``,
    ``copy.deepcopy``) leaves that out: the optimiser comes back with its
    hyper-parameters and no state, each callback as freshly initialised. The
    module, the criterion and the history are kept, so a net and its
    unpickled copy predict identically and the copy can be fitted again;
    ``partial_fit`` (``warm_start``) after unpickling continues from the
    weights with a fresh optimiser state, not where training stopped.
    """

    def __getstate__(self):
        memo = {}
        lean = object.__new__(type(self))
        for name, value in vars(self).items():
            if name == "callbacks" or name.startswith("callbacks_"):
                value = _lean_callbacks(value, memo)
            elif name.endswith("_") and name[:-1] in self._optimizers:
                value = _stateless(value)
            vars(lean)[name] = value
        return NeuralNet.__getstate__(lean)


def _stateless(optimizer):
    """A copy of ``optimizer`` (same parameters and hyper-parameters) without state."""
    if not isinstance(optimizer, torch.optim.Optimizer):
        return optimizer
    new = object.__new__(type(optimizer))
    new.__setstate__(
        {
            "defaults": optimizer.defaults,
            "state": defaultdict(dict),
            "param_groups": optimizer.param_groups,
        }
    )
    return new


def _lean_callbacks(value, memo):
    """``value`` (a callback or a list of them, named or not) with every callback
    replaced by a copy as initialised, without what training set on it."""
    if isinstance(value, (list, tuple)):
        return type(value)(_lean_callbacks(v, memo) for v in value)
    if not isinstance(value, Callback):
        return value
    if id(value) not in memo:
        new = copy.copy(value)
        for key in [k for k in vars(new) if k.endswith("_") and k[:1] != "_"]:
            delattr(new, key)  # skorch's rule: set by initialize and training
        memo[id(value)] = new.initialize()
    return memo[id(value)]


class MatlabCrossEntropy(nn.CrossEntropyLoss):
    """MATLAB's ``crossentropy`` of a softmax output (docs/method.md §8.6.5).

    ``-t log y`` averaged over samples *and* outputs: torch's cross-entropy
    averaged over the samples, divided by the number of outputs ``K``. The
    scale matters to SCG: on a loss ``K`` times larger, its initial ``lambda``
    and its ``min_grad`` stop act as if ``K`` times smaller (docs/method.md
    §8.6.5).
    """

    def forward(self, input, target):
        return super().forward(input, target) / input.shape[-1]


class _MatlabDivision:
    """Random 70/15/15 division of the samples (MATLAB ``dividerand``, §8.6.4).

    skorch's ``train_split``: returns the training and validation subsets; the
    test share is held out of both, as MATLAB does (it is only reported there).
    """

    def __init__(self, validation_fraction, test_fraction, random_state):
        self.validation_fraction = validation_fraction
        self.test_fraction = test_fraction
        self.random_state = random_state

    def __call__(self, dataset, y=None):
        n = len(dataset)
        rng = np.random.RandomState(self.random_state)
        perm = rng.permutation(n)
        n_val = int(round(self.validation_fraction * n))
        n_test = int(round(self.test_fraction * n))
        n_train = n - n_val - n_test
        if n_train < 1 or (self.validation_fraction > 0 and n_val < 1):
            raise ValueError(
                f"{n} training samples are too few for a {self.validation_fraction:.0%}"
                f" validation / {self.test_fraction:.0%} test division"
            )
        train, valid = np.sort(perm[:n_train]), np.sort(perm[n_train : n_train + n_val])
        return _subset(dataset, train), _subset(dataset, valid)


def _subset(dataset, idx):
    """A skorch ``Dataset`` of the rows ``idx`` (arrays sliced once, not per item)."""
    return Dataset(dataset.X[idx], None if dataset.y is None else dataset.y[idx])


class ArrayLoader:
    """Batches of a skorch ``Dataset`` of arrays, sliced directly.

    Replaces torch's ``DataLoader`` (one ``__getitem__`` and a collate per
    sample), which dominates full-batch training time on small networks.

    Parameters
    ----------
    dataset : skorch.dataset.Dataset
        Dataset holding ``X`` and ``y`` arrays.
    batch_size : int, default=128
        Rows per batch.
    shuffle : bool, default=False
        Draw a new permutation (torch's global RNG) at every pass.
    **kwargs : dict
        Other ``DataLoader`` arguments, ignored.
    """

    def __init__(self, dataset, batch_size=128, shuffle=False, **kwargs):
        self.dataset = dataset
        self.batch_size = batch_size
        self.shuffle = shuffle

    def __len__(self):
        n = len(self.dataset)
        return (n + self.batch_size - 1) // self.batch_size

    def __iter__(self):
        ds = self.dataset
        X = torch.as_tensor(np.asarray(ds.X))
        y = None if ds.y is None else torch.as_tensor(np.asarray(ds.y))
        n = len(X)
        order = torch.randperm(n) if self.shuffle else None
        for start in range(0, n, self.batch_size):
            sl = slice(start, start + self.batch_size)
            idx = order[sl] if order is not None else sl
            yield X[idx], (y[idx] if y is not None else torch.zeros(0))


class SequenceSplit:
    """The skorch ``train_split`` of skgesture's networks: whole sequences held out.

    Frames of one sequence (or overlapping windows of it) are too alike for a
    split of samples to validate on unseen data, so validation holds out whole
    sequences: ``held_out_sequences(n, fraction, seed)`` of them.

    Parameters
    ----------
    fraction : float or None, default=None
        Share of the sequences held out for validation; ``None`` trains on
        everything and validates on nothing.
    seed : int or None, default=None
        Seed of the draw.
    sequence_ids : ndarray of shape (n_samples,) or None, default=None
        The sequence of each sample, for a dataset of windows (Method C):
        the split is two ``Subset``s of the dataset. ``None``: the dataset's
        items are whole sequences (``dataset.X``), and it makes its own two
        parts with ``dataset.split(keep, held)`` (crops to train on, whole
        sequences to validate on).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._nn._training import SequenceSplit
    >>> seq = np.repeat(np.arange(5), 2)  # two windows per sequence
    >>> train, valid = SequenceSplit(0.2, seed=0, sequence_ids=seq)(list(range(10)))
    >>> len(train), len(valid), len(set(seq[valid.indices]))
    (8, 2, 1)
    """

    def __init__(self, fraction=None, seed=None, sequence_ids=None):
        self.fraction = fraction
        self.seed = seed
        self.sequence_ids = sequence_ids

    def __call__(self, dataset, y=None, **kwargs):
        if self.fraction is None:
            return dataset, None
        if self.sequence_ids is not None:
            ids = np.unique(self.sequence_ids)
            held = ids[held_out_sequences(len(ids), self.fraction, self.seed)]
            valid = np.isin(self.sequence_ids, held)
            return (
                torch.utils.data.Subset(dataset, np.flatnonzero(~valid)),
                torch.utils.data.Subset(dataset, np.flatnonzero(valid)),
            )
        n = len(dataset.X)
        held = held_out_sequences(n, self.fraction, self.seed)
        return dataset.split(np.setdiff1d(np.arange(n), held), held)

    def __setstate__(self, state):
        # Pickles of 0.1 hold _TrainOnly (no state), _HoldOutSequences
        # (fraction, seed) or _SequenceHoldout (fraction, sequence_ids,
        # random_state): skgesture._legacy maps those names to this class.
        state = dict(state)
        if "random_state" in state:
            state["seed"] = state.pop("random_state")
        for key in ("fraction", "seed", "sequence_ids"):
            state.setdefault(key, None)
        self.__dict__.update(state)


class _MatlabStopping(Callback):
    """Validation stop and best-weights restore as MATLAB's trainers do (§8.6.3-4).

    The best so far starts as the initial weights and their loss (MATLAB's
    ``validation_start``), measured before the first epoch. After each epoch, a
    validation loss below the best so far stores the weights and resets the
    failure count; a higher one counts a failure; an equal one changes nothing.
    Training stops after ``max_fail`` failures, or when the SCG gradient norm
    falls below ``min_grad``; the best weights are restored at the end, the
    initial ones if no epoch beat them. Without validation data the lowest
    training loss decides.
    """

    def __init__(self, max_fail=SCG_MAX_FAIL, min_grad=SCG_MIN_GRAD):
        self.max_fail = max_fail
        self.min_grad = min_grad

    def on_train_begin(self, net, **kwargs):
        self.best_loss_ = None  # set from the initial weights at the first epoch
        self.best_state_ = None
        self.best_epoch_ = 0
        self.fails_ = 0

    def on_epoch_begin(self, net, dataset_train=None, dataset_valid=None, **kwargs):
        if self.best_loss_ is not None:
            return
        dataset = dataset_valid if dataset_valid is not None else dataset_train
        self.best_loss_ = np.inf if dataset is None else _mean_loss(net, dataset)
        self.best_state_ = copy.deepcopy(net.module_.state_dict())

    def on_epoch_end(self, net, **kwargs):
        row = net.history[-1]
        key = "valid_loss" if "valid_loss" in row else "train_loss"
        loss = row[key]
        if loss < self.best_loss_:
            self.best_loss_ = loss
            self.best_state_ = copy.deepcopy(net.module_.state_dict())
            self.best_epoch_ = row["epoch"]
            self.fails_ = 0
        elif loss > self.best_loss_:
            self.fails_ += 1
        stop = (
            key == "valid_loss"
            and self.max_fail is not None
            and self.fails_ >= self.max_fail
        )
        grad_norm = getattr(net.optimizer_, "grad_norm", None)
        if grad_norm is not None and grad_norm <= self.min_grad:
            stop = True
        if stop:
            raise KeyboardInterrupt  # skorch ends training cleanly on this

    def on_train_end(self, net, **kwargs):
        if self.best_state_ is not None:
            net.module_.load_state_dict(self.best_state_)
            net.best_epoch_ = self.best_epoch_


def _mean_loss(net, dataset):
    """Loss of the current weights on ``dataset``, averaged as skorch records it
    (batch losses weighted by batch size), without a gradient."""
    total, count = 0.0, 0
    for batch in net.get_iterator(dataset, training=False):
        step = net.validation_step(batch)
        n = len(batch[0])
        total += float(step["loss"]) * n
        count += n
    return total / count if count else np.inf


class EpochProgress(Callback):
    """A tqdm bar over epochs showing the latest losses (``verbose=1``)."""

    def on_train_begin(self, net, **kwargs):
        from tqdm.auto import tqdm

        self.bar_ = tqdm(
            total=net.max_epochs,
            desc=type(net.module_).__name__,
            unit="epoch",
            leave=False,
        )

    def on_epoch_end(self, net, **kwargs):
        row = net.history[-1]
        losses = {k: f"{row[k]:.4f}" for k in ("train_loss", "valid_loss") if k in row}
        self.bar_.set_postfix(losses, refresh=False)
        self.bar_.update(1)

    def on_train_end(self, net, **kwargs):
        self.bar_.close()


# -- the training loop of every framewise tagger network -------------------------


class FramewiseLoss(nn.Module):
    """Cross-entropy of every frame of ``(batch, time, classes)`` logits.

    The loss of every tagger network. Frames whose target is ``IGNORE_INDEX``
    (padding, untracked frames) are left out. A tuple of logits (the stages
    of an MS-TCN) adds up the loss of every stage.

    Parameters
    ----------
    time_reduction : {"mean", "sum"}, default="mean"
        ``"mean"`` averages over every frame of the batch (weighted by
        ``class_weight``); ``"sum"`` sums over the frames of each sequence and
        averages over the sequences (MATLAB's sequence loss, docs/method.md
        §7.2).
    class_weight : list of float or None, default=None
        Weight of each class in the cross-entropy.
    smoothing_weight : float, default=0.0
        Weight of MS-TCN's smoothing loss, the truncated mean squared change of
        the log-probabilities between consecutive frames (Farha & Gall 2019);
        0 disables it.
    smoothing_margin : int, default=0
        Frames on each side of a true boundary (a change of the target label)
        left out of the smoothing loss, so that it does not hold back the
        changes the labels ask for (in the spirit of ASRF's similarity-weighted
        smoothing, Ishikawa et al. 2021, with the known labels in place of the
        features' similarity); 0: every pair of frames.
    """

    def __init__(
        self,
        time_reduction="mean",
        class_weight=None,
        smoothing_weight=0.0,
        smoothing_margin=0,
    ):
        super().__init__()
        self.time_reduction = time_reduction
        weight = None if class_weight is None else torch.as_tensor(class_weight)
        self.register_buffer("weight", weight)
        self.smoothing_weight = smoothing_weight
        self.smoothing_margin = smoothing_margin

    def forward(self, output, target):
        stages = output if isinstance(output, (tuple, list)) else (output,)
        if self.smoothing_weight:
            # the pairs of frames smoothed: the same for every stage
            valid = (target[:, 1:] != IGNORE_INDEX) & (target[:, :-1] != IGNORE_INDEX)
            if self.smoothing_margin:
                valid = valid & ~near_boundary(target, self.smoothing_margin)
        loss = None
        for logits in stages:
            term = self._cross_entropy(logits, target)
            loss = term if loss is None else loss + term
            if self.smoothing_weight:
                logp = F.log_softmax(logits, dim=-1)
                change = (logp[:, 1:] - logp[:, :-1].detach()) ** 2
                if valid.any():
                    change = torch.clamp(change, max=SMOOTHING_CLAMP)[valid]
                    loss = loss + self.smoothing_weight * change.mean()
        return loss

    def __setstate__(self, state):
        # criteria pickled before the smoothing loss (or its margin) existed
        state.setdefault("smoothing_weight", 0.0)
        state.setdefault("smoothing_margin", 0)
        super().__setstate__(state)

    def _cross_entropy(self, logits, target):
        flat, flat_target = logits.reshape(-1, logits.shape[-1]), target.reshape(-1)
        if self.time_reduction == "sum":
            total = F.cross_entropy(
                flat,
                flat_target,
                weight=self.weight,
                ignore_index=IGNORE_INDEX,
                reduction="sum",
            )
            return total / target.shape[0]
        if not (flat_target != IGNORE_INDEX).any():
            # Every frame ignored (e.g. a held-out sequence that never tracked):
            # no evidence, a zero loss rather than torch's 0/0 = NaN.
            return flat.sum() * 0.0
        return F.cross_entropy(
            flat, flat_target, weight=self.weight, ignore_index=IGNORE_INDEX
        )


def near_boundary(target, margin):
    """Mask ``(batch, time - 1)`` of the consecutive pairs of frames within
    ``margin`` pairs of a change of the target label (padding and untracked
    frames, ``IGNORE_INDEX``, are no change)."""
    a, b = target[:, :-1], target[:, 1:]
    change = (a != b) & (a != IGNORE_INDEX) & (b != IGNORE_INDEX)
    if margin <= 0 or change.shape[1] == 0:  # a crop of one frame has no pair
        return change
    near = F.max_pool1d(
        change[:, None].float(), kernel_size=2 * margin + 1, stride=1, padding=margin
    )
    return near[:, 0] > 0


def held_out_sequences(n_sequences, fraction, seed):
    """Indices of the whole sequences held out for validation.

    ``round(fraction * n_sequences)`` of them, at least 1 and at most
    ``n_sequences - 1``, drawn by ``numpy.random.RandomState(seed)``.

    Examples
    --------
    >>> from skgesture._nn._training import held_out_sequences
    >>> len(held_out_sequences(10, 0.2, seed=0))
    2
    """
    n_valid = min(max(int(round(fraction * n_sequences)), 1), n_sequences - 1)
    return np.random.RandomState(seed).choice(n_sequences, n_valid, replace=False)


def _silent(*args, **kwargs):
    """A skorch ``sink`` that prints nothing."""


class FramewiseNetwork(NewParamsMixin, BaseEstimator):
    """The trainable part of a tagger, with the training loop every tagger shares.

    A subclass is fitted through :func:`~skgesture.utils._fitting.fit_cached`
    (its parameters are the network and training parameters only, so a
    tagger's decoding parameters never change the cache key). Its ``fit``
    prepares what differs between taggers: the sampler of the training data
    (a dataset, its iterators and a ``train_split`` holding out whole
    sequences), the module, the optimiser and the schedule; :meth:`_train`
    does the rest, the same way for every tagger: the loss
    (:class:`FramewiseLoss`), early stopping on the held-out sequences (best
    epoch restored), progress (``verbose``), the device, and seeding under
    ``TORCH_RNG_LOCK``.

    A subclass has the parameters ``max_epochs``, ``batch_size``,
    ``learning_rate``, ``early_stopping``, ``n_iter_no_change``, ``device``
    and ``verbose``.
    """

    # verbose >= this prints one line per epoch (skorch's log); 1 .. this - 1
    # shows a tqdm bar over epochs
    _epoch_lines_from = 2

    def _train(
        self,
        module,
        data,
        target=None,
        *,
        seed,
        n_sequences,
        train_split,
        callbacks=(),
        module_params=None,
        criterion_params=None,
        **net_params,
    ):
        """Build the skorch ``NeuralNet`` and fit it on ``(data, target)``.

        ``train_split`` is used with ``early_stopping`` only; ``callbacks``
        (the schedule) come before the early stopping and the progress bar;
        ``net_params`` are further ``NeuralNet`` arguments (the optimiser, the
        iterators of the sampler). Returns the fitted net.
        """
        if self.early_stopping and n_sequences < 2:
            raise ValueError(
                "early_stopping holds out whole sequences for validation and "
                f"needs at least 2 training sequences, got {n_sequences}"
            )
        lines = self.verbose >= self._epoch_lines_from
        callbacks = list(callbacks)
        if self.early_stopping:
            stopper = EarlyStopping(
                monitor="valid_loss",
                patience=self.n_iter_no_change,
                load_best=True,
                sink=print if lines else _silent,
            )
            callbacks.append(("early_stopping", stopper))
        if self.verbose and not lines:
            callbacks.append(("progress", EpochProgress()))
        net = LeanNet(
            module,
            **{f"module__{k}": v for k, v in (module_params or {}).items()},
            criterion=FramewiseLoss,
            **{f"criterion__{k}": v for k, v in (criterion_params or {}).items()},
            lr=self.learning_rate,
            max_epochs=self.max_epochs,
            batch_size=self.batch_size,
            train_split=train_split if self.early_stopping else None,
            callbacks=callbacks,
            device=self.device,
            verbose=int(lines),
            **net_params,
        )
        # Initialisation, dropout and shuffling draw from torch's global RNG:
        # seeded in a fork, under the lock, so that neither the caller's RNG
        # nor a network fitted in a parallel thread interferes.
        on_gpu = str(self.device).startswith("cuda")
        with TORCH_RNG_LOCK, torch.random.fork_rng(devices=None if on_gpu else []):
            torch.manual_seed(seed)
            net.fit(data, target)
        return net


def _solver_settings(solver, learning_rate, batch_size, n_samples):
    """Optimizer class, its keyword arguments and the batch size for ``solver``."""
    if solver == "scg":
        from skgesture.utils._scg import SCG

        # Full batch, as MATLAB trainscg; with a fixed batch the re-evaluation at
        # the start of each step is redundant (identical weights, a third fewer
        # forward/backward passes).
        return SCG, {"reevaluate": False}, n_samples
    if solver == "lbfgs":
        return torch.optim.LBFGS, {"lr": learning_rate or 1.0}, n_samples
    if solver == "adam":
        return torch.optim.Adam, {"lr": learning_rate or 1e-3}, batch_size
    raise ValueError(f"solver must be 'scg', 'adam' or 'lbfgs', got {solver!r}")


def build_net(
    module_params,
    *,
    loss,
    solver="scg",
    max_epochs=1000,
    learning_rate=None,
    batch_size=256,
    n_samples=None,
    validation_fraction=VALIDATION_FRACTION,
    test_fraction=TEST_FRACTION,
    max_fail=SCG_MAX_FAIL,
    seed=0,
    device="cpu",
    verbose=0,
):
    """An unfitted skorch net (a :class:`LeanNet`) around :class:`MLPModule`.

    ``loss="binary"`` uses a sigmoid output with binary cross-entropy,
    ``"multiclass"`` a softmax output with cross-entropy averaged over samples and
    outputs (:class:`MatlabCrossEntropy`, MATLAB ``crossentropy``, docs/method.md
    §8.6.5). Training stops as MATLAB's trainers do (:class:`_MatlabStopping`) on
    a random 70/15/15 division.
    """
    criterion = nn.BCEWithLogitsLoss if loss == "binary" else MatlabCrossEntropy
    optimizer, opt_kwargs, batch = _solver_settings(
        solver, learning_rate, batch_size, n_samples
    )
    if validation_fraction > 0:
        split = _MatlabDivision(validation_fraction, test_fraction, seed)
    else:
        split = SequenceSplit()  # no validation
    callbacks = [("matlab_stop", _MatlabStopping(max_fail=max_fail))]
    if verbose == 1:
        callbacks.append(("progress", EpochProgress()))
    # verbose >= 2: skorch's own default callbacks (epoch timer, print log) print
    # one line per epoch once the net is verbose.
    return LeanNet(
        MLPModule,
        criterion=criterion,
        optimizer=optimizer,
        max_epochs=max_epochs,
        batch_size=max(int(batch), 1),
        train_split=split,
        iterator_train=ArrayLoader,
        iterator_valid=ArrayLoader,
        iterator_train__shuffle=solver == "adam",
        callbacks=callbacks,
        device=device,
        verbose=int(verbose > 1),
        **{f"module__{k}": v for k, v in module_params.items()},
        **{f"optimizer__{k}": v for k, v in opt_kwargs.items()},
    )


# Held while seeding torch's global RNG and initialising a network from it, so
# that networks fitted in parallel threads (joblib's threading backend, a Dask
# worker with threads) each get the initial weights of their own seed. A tagger
# network (FramewiseNetwork._train) holds it for its whole fit: its dropout and
# window shuffling draw from that RNG at every epoch.
TORCH_RNG_LOCK = threading.RLock()


@contextmanager
def torch_threads(n_threads):
    """Run the block with ``n_threads`` torch intra-op threads (``None``: as is).

    The thread policy of every torch estimator in skgesture: tiny networks run
    fastest, and never oversubscribe a busy machine, on one intra-op thread.
    The previous setting is restored on exit.
    """
    if n_threads is None:
        yield
        return
    before = torch.get_num_threads()
    torch.set_num_threads(n_threads)
    try:
        yield
    finally:
        torch.set_num_threads(before)
