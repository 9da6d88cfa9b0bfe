"""The skorch net of the sequence taggers.

Crop datasets, whole-sequence batches, hold-out splits and the learning-rate
schedule of :class:`~skgesture.SequenceTagger`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
import torch
from skorch.callbacks import GradientNormClipping, LRScheduler

from skgesture._nn._modules import (
    RecurrentTaggerModule,
    TemporalConvModule,
    frame_probabilities,
)
from skgesture._nn._training import (
    IGNORE_INDEX,
    FramewiseNetwork,
    SequenceSplit,
)
from skgesture.utils._fitting import seed_from

MIN_SCALE = 1e-6  # a feature with a smaller training std keeps scale 1
# The crops' Gaussian noise is read from a bank of standard normal values at
# random offsets: at least NOISE_BANK values (and NOISE_CROPS crops' worth),
# drawn again once the crops have read NOISE_REUSE times its size from it.
NOISE_BANK = 2**22
NOISE_CROPS = 32
NOISE_REUSE = 16
FUSED_DEVICES = ("cpu", "cuda")  # where torch has a fused AdamW


class _CropData(torch.utils.data.Dataset):
    """Training sequences from which :class:`_CropBatches` draws random crops.

    Each crop is a random ``crop_length``-frame slice of a random sequence,
    perturbed by ``augmenter`` (before standardisation, so rotations act on
    raw xyz triples) and standardised; a shorter sequence is padded, its
    padding left out of the loss (with ``packed``, a batch is ``({"X": x,
    "lengths": frames of each crop}, y)``, for a recurrent module that packs
    the padding away). The augmenter's Gaussian noise is added after the
    crop, in torch, on the kept frames only: ``noise`` in the raw features'
    units is ``noise / scale`` once standardised, so the crops are
    distributed as if each had been noised before its standardisation, at a
    third of the draws. Each crop reads its noise from a bank of standard
    normal values (:meth:`_noise`) at a random offset: torch draws normal
    values at about 4 ns each on the CPU (6 ms for a batch of the
    recommended model, 16 crops of 256 frames of 426 features), a slice of
    the bank costs a copy. Within a crop the values are independent; two
    crops share values only where their slices overlap, and then at other
    frames and features unless the offsets differ by a multiple of the
    feature count; the bank is drawn again after ``NOISE_REUSE`` times its
    size has been read from it.
    """

    def __init__(
        self, X, y, *, crop_length, augmenter, mean, scale, seed, packed=False
    ):
        self.X, self.y = X, y
        self.packed = packed
        self.crop_length = crop_length
        self.augmenter = augmenter
        if augmenter is not None:
            augmenter._validate_params()  # once; every crop uses _perturb
        self.mean = mean.astype(np.float32)
        self.scale = scale.astype(np.float32)
        self.seed = seed
        self.rng = np.random.RandomState(seed)
        self.noise_generator = torch.Generator().manual_seed(int(seed))
        self._bank, self._unread = None, 0

    def __len__(self):
        return len(self.X)

    def split(self, keep, held):
        """Crops of the sequences ``keep`` to train on (a fresh draw from the
        same seed) and the sequences ``held`` whole, to validate on
        (``SequenceSplit``)."""
        train = _CropData(
            [self.X[i] for i in keep],
            [self.y[i] for i in keep],
            crop_length=self.crop_length,
            augmenter=self.augmenter,
            mean=self.mean,
            scale=self.scale,
            seed=self.seed,
            packed=self.packed,
        )
        valid = _WholeSequences(
            [self.X[i] for i in held], [self.y[i] for i in held], self.mean, self.scale
        )
        return train, valid

    def __getitem__(self, i):
        raise TypeError("crops are drawn in batches by _CropBatches")

    def sample(self, batch_size):
        rng, length = self.rng, self.crop_length
        xb = np.zeros((batch_size, length, self.mean.size), dtype=np.float32)
        yb = np.full((batch_size, length), IGNORE_INDEX, dtype=np.int64)
        lengths = np.zeros(batch_size, dtype=np.int64)  # frames of each crop
        for b in range(batch_size):
            i = rng.randint(len(self.X))
            x, y = self.X[i], self.y[i]
            if self.augmenter is not None:
                # Crop with a margin first, so the time warp has frames to use.
                margin = int(np.ceil(length * 1.5))
                if len(x) > margin:
                    s = rng.randint(len(x) - margin + 1)
                    x, y = x[s : s + margin], y[s : s + margin]
                x, y = self.augmenter._perturb(x, y, rng, noise=False, length=length)
            elif len(x) > length:
                s = rng.randint(len(x) - length + 1)
                x, y = x[s : s + length], y[s : s + length]
            rows = xb[b, : len(x)]
            np.subtract(x, self.mean, out=rows)
            rows /= self.scale
            yb[b, : len(y)] = y
            lengths[b] = len(x)
        xb, yb = torch.from_numpy(xb), torch.from_numpy(yb)
        if self.augmenter is not None and self.augmenter.noise:
            std = torch.from_numpy(np.float32(self.augmenter.noise) / self.scale)
            width = std.numel()
            for b, n in enumerate(lengths.tolist()):  # the padding stays 0
                xb[b, :n].addcmul_(self._noise(n * width).view(n, width), std)
        if self.packed:  # the module packs the padding away
            return {"X": xb, "lengths": torch.from_numpy(lengths)}, yb
        return xb, yb

    def _noise(self, n_values):
        """``n_values`` standard normal values: a slice of the noise bank at
        a random offset (the bank drawn, or drawn again, as needed)."""
        if self._bank is None or self._unread <= 0:
            size = max(NOISE_BANK, NOISE_CROPS * self.crop_length * self.mean.size)
            self._bank = torch.randn(size, generator=self.noise_generator)
            self._unread = NOISE_REUSE * size
        self._unread -= n_values
        high = self._bank.numel() - n_values + 1
        start = int(torch.randint(high, (), generator=self.noise_generator))
        return self._bank[start : start + n_values]


class _CropBatches:
    """skorch iterator: ``steps`` batches of random crops per epoch."""

    def __init__(self, dataset, batch_size=32, steps=10, **kwargs):
        self.dataset = dataset
        self.batch_size = batch_size
        self.steps = steps

    def __len__(self):
        return self.steps

    def __iter__(self):
        for _ in range(self.steps):
            yield self.dataset.sample(self.batch_size)


class _WholeSequences(torch.utils.data.Dataset):
    """Held-out sequences, standardised, for the validation loss."""

    def __init__(self, X, y, mean, scale):
        self.X = [((x - mean) / scale).astype(np.float32) for x in X]
        self.y = y

    def __len__(self):
        return len(self.X)

    def __getitem__(self, i):
        return torch.from_numpy(self.X[i]), torch.from_numpy(self.y[i])


class _OneSequenceBatches:
    """skorch iterator over a :class:`_WholeSequences`, one sequence a batch."""

    def __init__(self, dataset, **kwargs):
        self.dataset = dataset

    def __len__(self):
        return len(self.dataset)

    def __iter__(self):
        for i in range(len(self.dataset)):
            x, y = self.dataset[i]
            yield x[None], y[None]


class WarmupCosine:
    """Learning-rate factor of step ``k``: linear warm-up, then cosine decay.

    The one-cycle shape (warm-up over ``warmup`` of the ``total`` steps, then
    a half cosine down to ``final`` of the peak), as a picklable callable for
    ``torch.optim.lr_scheduler.LambdaLR``; well defined for any ``total >= 1``.

    Examples
    --------
    >>> from skgesture._nn._sequence_net import WarmupCosine
    >>> f = WarmupCosine(10)
    >>> [round(float(f(k)), 2) for k in (0, 1, 5, 9)]
    [0.5, 1.0, 0.51, 0.01]
    """

    def __init__(self, total, warmup=0.1, final=0.01):
        self.total = max(int(total), 1)
        self.warmup = max(int(round(warmup * self.total)), 1)
        self.final = final

    def __call__(self, step):
        if step < self.warmup:
            return (step + 1) / (self.warmup + 1)
        progress = (step - self.warmup) / max(self.total - self.warmup - 1, 1)
        progress = min(progress, 1.0)
        return float(
            self.final + (1 - self.final) * 0.5 * (1 + np.cos(np.pi * progress))
        )


def _module_spec(
    architecture, hidden_sizes, dropout, tcn_layers, tcn_stages, lookahead=None
):
    """Module class and keyword arguments of an ``architecture``."""
    if architecture == "tcn":
        kwargs = {
            "channels": int(hidden_sizes[0]),
            "n_layers": int(tcn_layers),
            "n_stages": int(tcn_stages),
            "dropout": float(dropout),
        }
        if lookahead is not None:  # (absent: the files of whole-sequence TCNs)
            kwargs["lookahead"] = int(lookahead)
        return TemporalConvModule, kwargs
    return RecurrentTaggerModule, {
        "hidden_sizes": tuple(int(h) for h in hidden_sizes),
        "cell": architecture,
        "dropout": float(dropout),
    }


class _CropNet(FramewiseNetwork):
    """The trainable part of :class:`SequenceTagger`, cached by ``fit_cached``.

    Its parameters are the network and training parameters only, so the
    tagger's decoding parameters never change the cache key. ``fit`` takes
    float32 sequences and labels encoded as class indices (``IGNORE_INDEX``
    for frames left out of the loss) and sets ``net_``, ``mean_`` and
    ``scale_``. The training loop is :class:`FramewiseNetwork`'s; the sampler
    draws random crops of whole sequences, the optimiser is AdamW with a
    one-cycle schedule and gradient clipping. With ``packed`` (a recurrent
    architecture only), the padding of a crop shorter than ``crop_length``
    is packed away, so the network trains on each crop as it reads a
    sequence alone (the run namer's windows).
    """

    def __init__(
        self,
        *,
        n_classes=2,
        architecture="gru",
        hidden_sizes=(64, 64),
        dropout=0.0,
        tcn_layers=8,
        tcn_stages=2,
        lookahead=None,
        smoothing_weight=0.0,
        smoothing_margin=0,
        crop_length=128,
        batch_size=32,
        steps_per_epoch=20,
        max_epochs=15,
        learning_rate=3e-3,
        weight_decay=1e-4,
        clip_norm=1.0,
        class_weight=None,
        augmenter=None,
        standardize=True,
        packed=False,
        early_stopping=False,
        validation_fraction=0.15,
        n_iter_no_change=5,
        device="cpu",
        random_state=None,
        verbose=0,
    ):
        self.n_classes = n_classes
        self.architecture = architecture
        self.hidden_sizes = hidden_sizes
        self.dropout = dropout
        self.tcn_layers = tcn_layers
        self.tcn_stages = tcn_stages
        self.lookahead = lookahead
        self.smoothing_weight = smoothing_weight
        self.smoothing_margin = smoothing_margin
        self.crop_length = crop_length
        self.batch_size = batch_size
        self.steps_per_epoch = steps_per_epoch
        self.max_epochs = max_epochs
        self.learning_rate = learning_rate
        self.weight_decay = weight_decay
        self.clip_norm = clip_norm
        self.class_weight = class_weight
        self.augmenter = augmenter
        self.standardize = standardize
        self.packed = packed
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.device = device
        self.random_state = random_state
        self.verbose = verbose

    def fit(self, X, y):
        if self.packed and self.architecture == "tcn":
            raise ValueError("packed crops need a recurrent architecture, not 'tcn'")
        seed = seed_from(self.random_state)
        frames = np.concatenate(X)
        if self.standardize:
            self.mean_ = frames.mean(axis=0).astype(np.float32)
            std = frames.std(axis=0)
            self.scale_ = np.where(std < MIN_SCALE, 1.0, std).astype(np.float32)
        else:
            self.mean_ = np.zeros(frames.shape[1], dtype=np.float32)
            self.scale_ = np.ones(frames.shape[1], dtype=np.float32)
        data = _CropData(
            X,
            y,
            crop_length=self.crop_length,
            augmenter=self.augmenter,
            mean=self.mean_,
            scale=self.scale_,
            seed=seed,
            packed=self.packed,
        )
        module, module_kwargs = _module_spec(
            self.architecture,
            self.hidden_sizes,
            self.dropout,
            self.tcn_layers,
            self.tcn_stages,
            self.lookahead,
        )
        schedule = [
            (
                "lr_scheduler",
                LRScheduler(
                    policy=torch.optim.lr_scheduler.LambdaLR,
                    lr_lambda=WarmupCosine(self.max_epochs * self.steps_per_epoch),
                    step_every="batch",
                ),
            ),
        ]
        if self.clip_norm is not None:
            schedule.append(
                ("clip", GradientNormClipping(gradient_clip_value=self.clip_norm))
            )
        self.net_ = self._train(
            module,
            data,
            seed=seed,
            n_sequences=len(X),
            train_split=SequenceSplit(self.validation_fraction, seed),
            callbacks=schedule,
            module_params={
                "n_inputs": int(frames.shape[1]),
                "n_outputs": int(self.n_classes),
                **module_kwargs,
            },
            criterion_params={
                "class_weight": self.class_weight,
                "smoothing_weight": float(self.smoothing_weight),
                "smoothing_margin": int(self.smoothing_margin),
            },
            optimizer=torch.optim.AdamW,
            optimizer__weight_decay=self.weight_decay,
            # one kernel for every parameter's update: 5x faster than the
            # loop over parameters torch uses by default on the CPU
            optimizer__fused=torch.device(self.device).type in FUSED_DEVICES,
            iterator_train=_CropBatches,
            iterator_train__steps=self.steps_per_epoch,
            iterator_valid=_OneSequenceBatches,
        )
        return self


PAD_BATCH = 32  # sequences per padded batch of a causal network
PAD_WASTE = 1.5  # a padded batch's longest sequence is at most this times its shortest


def _batches(lengths, causal):
    """Index groups run as one batch: sequences of equal length, or for a causal
    network (whose outputs do not depend on later frames, so zero rows after a
    sequence change nothing of it) runs of similar lengths, padded."""
    if not causal:
        groups = {}
        for i, n in enumerate(lengths):
            groups.setdefault(n, []).append(i)
        return list(groups.values())
    order = sorted(range(len(lengths)), key=lambda i: lengths[i])
    out, current = [], []
    for i in order:
        if current and (
            len(current) == PAD_BATCH
            or lengths[i] > PAD_WASTE * max(lengths[current[0]], 1)
        ):
            out.append(current)
            current = []
        current.append(i)
    return out + [current] if current else out


def predict_whole(module, X, mean, scale, n_classes):
    """Per-frame softmax probabilities of ``module`` run over whole sequences.

    Sequences of equal length are batched together; for a TCN with a bounded
    look-ahead (causal), sequences of similar lengths too, zero-padded at the
    end: a causal network's output for a frame depends on no later frame, and
    the padding is the zeros the network appends itself, so each sequence's
    probabilities are those of its own run (to float32 rounding). The output
    is float64.
    """
    module.eval()
    out = [None] * len(X)
    causal = getattr(module, "lookahead", None) is not None
    lengths = [len(x) for x in X]
    mean32, scale32 = np.asarray(mean, np.float32), np.asarray(scale, np.float32)
    for idx in _batches(lengths, causal):
        T = max(lengths[i] for i in idx)
        xb = np.zeros((len(idx), T, np.shape(X[idx[0]])[1]), dtype=np.float32)
        for row, i in enumerate(idx):
            # standardised in float32, in place (no float64 copies): equal to
            # the float64 route of the numpy scorers to float32 rounding
            rows = xb[row, : lengths[i]]
            rows[...] = X[i]
            rows -= mean32
            rows /= scale32
        for i, p in zip(idx, frame_probabilities(module, xb)):
            out[i] = p[: lengths[i]].reshape(lengths[i], n_classes)
    return out
