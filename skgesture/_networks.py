"""Torch modules and the skorch wiring shared by every network in skgesture.

:func:`build_net` makes the skorch net of any of the paper's MLPs. Estimators that
own networks fit them through :func:`fit_cached`, which caches the fitted network
with ``joblib.Memory`` keyed on the training data and the network's own
parameters only, so decision parameters (thresholds, weights, smoothing,
minimum lengths) can be searched by ``GridSearchCV`` without retraining (DESIGN.md §3).
"""

# SPDX-License-Identifier: BSD-3-Clause

import copy
from contextlib import contextmanager

import numpy as np
import torch
from sklearn.base import clone
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_memory
from skorch import NeuralNet
from skorch.callbacks import Callback, EpochTimer, PrintLog
from skorch.dataset import Dataset
from torch import nn

__all__ = [
    "MLPModule",
    "build_net",
    "fit_cached",
    "predict_module",
    "seed_from",
    "torch_threads",
]

# MATLAB trainscg defaults, METHOD_SPEC §8.6.1
SCG_MAX_FAIL = 6
SCG_MIN_GRAD = 1e-6
# MATLAB dividerand defaults, METHOD_SPEC §8.6.4
VALIDATION_FRACTION = 0.15
TEST_FRACTION = 0.15
PREDICT_BATCH = 65536

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


class _TrainOnly:
    """skorch ``train_split`` that keeps every sample for training."""

    def __call__(self, dataset, y=None):
        return dataset, None


class _MatlabStopping(Callback):
    """Validation stop and best-weights restore as MATLAB's trainers do (§8.6.3-4).

    After each epoch, a validation loss below the best so far stores the weights
    and resets the failure count; a higher one counts a failure; an equal one
    changes nothing. Training stops after ``max_fail`` failures, or when the SCG
    gradient norm falls below ``min_grad``; the best weights are restored at the
    end. Without validation data the lowest training loss decides.
    """

    def __init__(self, max_fail=SCG_MAX_FAIL, min_grad=SCG_MIN_GRAD):
        self.max_fail = max_fail
        self.min_grad = min_grad

    def on_train_begin(self, net, **kwargs):
        self.best_loss_ = np.inf
        self.best_state_ = None
        self.best_epoch_ = 0
        self.fails_ = 0

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


def _to_float32(X):
    return np.ascontiguousarray(X, dtype=np.float32)


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
    """An unfitted skorch ``NeuralNet`` around :class:`MLPModule`.

    ``loss="binary"`` uses a sigmoid output with binary cross-entropy,
    ``"multiclass"`` a softmax output with cross-entropy (MATLAB ``crossentropy``,
    METHOD_SPEC §8.6.5). Training stops as MATLAB's trainers do
    (:class:`_MatlabStopping`) on a random 70/15/15 division.
    """
    criterion = nn.BCEWithLogitsLoss if loss == "binary" else nn.CrossEntropyLoss
    optimizer, opt_kwargs, batch = _solver_settings(
        solver, learning_rate, batch_size, n_samples
    )
    if validation_fraction > 0:
        split = _MatlabDivision(validation_fraction, test_fraction, seed)
    else:
        split = _TrainOnly()
    callbacks = [("matlab_stop", _MatlabStopping(max_fail=max_fail))]
    if verbose == 1:
        callbacks.append(("progress", EpochProgress()))
    elif verbose > 1:
        callbacks += [("epoch_timer", EpochTimer()), ("print_log", PrintLog())]
    return NeuralNet(
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
        verbose=0,
        **{f"module__{k}": v for k, v in module_params.items()},
        **{f"optimizer__{k}": v for k, v in opt_kwargs.items()},
    )


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


def _fit_clone(estimator, X, y):
    return clone(estimator).fit(X, y)


def fit_cached(memory, estimator, X, y):
    """Fit a clone of ``estimator`` on ``(X, y)``, cached by ``memory``.

    The cache key is the estimator's parameters and the data, nothing else: an
    estimator holding this network sees the same cached network whatever its own
    decision parameters are (DESIGN.md §3).

    Parameters
    ----------
    memory : None, str or joblib.Memory
        Where to cache; ``None`` disables caching.
    estimator : estimator
        The unfitted estimator (its ``random_state`` must be an int or None to
        give a stable key).
    X, y : array-like
        Training data.

    Returns
    -------
    estimator
        The fitted clone.
    """
    memory = check_memory(memory)
    return memory.cache(_fit_clone)(estimator, X, y)


def predict_module(module, X, output):
    """Probabilities of a torch module on ``X``, in batches, as float64.

    Parameters
    ----------
    module : torch.nn.Module
        Trained module returning logits.
    X : ndarray of shape (n_samples, n_inputs)
        Inputs.
    output : {"sigmoid", "softmax"}
        Output map applied to the logits.

    Returns
    -------
    ndarray of shape (n_samples,) or (n_samples, n_classes)
        Probabilities.
    """
    module.eval()
    device = next(module.parameters()).device
    outs = []
    with torch.inference_mode():
        for start in range(0, len(X), PREDICT_BATCH):
            xb = torch.as_tensor(
                _to_float32(X[start : start + PREDICT_BATCH]), device=device
            )
            logits = module(xb)
            if output == "sigmoid":
                prob = torch.sigmoid(logits)[:, 0]
            else:
                prob = torch.softmax(logits, dim=1)
            outs.append(prob.cpu().numpy().astype(np.float64))
    if not outs:
        width = module.net[-1].out_features
        return np.zeros((0,) if output == "sigmoid" else (0, width))
    return np.concatenate(outs)


def seed_from(random_state):
    """An int seed for torch drawn from a numpy ``random_state`` (STYLE.md §5)."""
    return int(check_random_state(random_state).randint(np.iinfo(np.int32).max))


def fit_inner_estimator(estimator, default, X, y, *, rng, memory):
    """Fit a clone of ``estimator`` (or of ``default``) for a sequence estimator.

    When ``rng`` is given, an int seed drawn from it replaces the clone's
    ``random_state`` (if it has one), so one ``random_state`` on the outer
    estimator controls every network it trains.
    """
    est = clone(default if estimator is None else estimator)
    if rng is not None and "random_state" in est.get_params():
        est.set_params(random_state=seed_from(rng))
    return fit_cached(memory, est, X, y)
