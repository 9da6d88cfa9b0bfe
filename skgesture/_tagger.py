"""Framewise sequence taggers: the shared base, SequenceTagger and VotingTagger.

:class:`_BaseTagger` holds what every tagger shares: label encoding and input
checks in ``fit``, the network cached by ``memory`` (decision parameters never
retrain it), untracked frames forced to rest, and one decoding path
(:func:`skgesture._decoding.decode`). :class:`~skgesture.BiLSTMTagger`
(Method C) and :class:`SequenceTagger` (the recommended model) differ only in
the network they train and how they run it.

:class:`SequenceTagger` trains on random crops of whole sequences with AdamW,
a one-cycle schedule, gradient clipping, class weights, augmentation and,
optionally, early stopping on held-out whole sequences, all through one skorch
``NeuralNet``; it predicts over whole sequences.
"""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from numbers import Integral, Real

import numpy as np
import torch
from sklearn.base import BaseEstimator, ClassifierMixin, _fit_context, clone
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions
from sklearn.utils.validation import check_is_fitted
from skorch.callbacks import GradientNormClipping, LRScheduler

from skgesture._augment import SkeletonAugmenter
from skgesture._decoding import SMOOTHINGS, decode, segments_with_confidence
from skgesture._modules import (
    RecurrentTaggerModule,
    TemporalConvModule,
    frame_probabilities,
)
from skgesture._networks import (
    IGNORE_INDEX,
    FramewiseNetwork,
    fit_cached,
    held_out_sequences,
    seed_from,
    torch_threads,
)
from skgesture.utils._validation import (
    check_sequence_labels,
    check_sequences,
    untracked_rows,
)

__all__ = ["SequenceTagger", "VotingTagger"]

MIN_SCALE = 1e-6  # a feature with a smaller training std keeps scale 1
DEFAULT_STREAM_PAST = 32  # streaming: frames of window before a frame
DEFAULT_STREAM_FUTURE = 8  # and after it (docs/streaming.md)


# -- training data: random crops of whole sequences ----------------------------


class _CropData(torch.utils.data.Dataset):
    """Training sequences from which :class:`_CropBatches` draws random crops.

    Each crop is a random ``crop_length``-frame slice of a random sequence,
    perturbed by ``augmenter`` (before standardisation, so rotations act on
    raw xyz triples) and standardised; a shorter sequence is padded, its
    padding left out of the loss.
    """

    def __init__(self, X, y, *, crop_length, augmenter, mean, scale, seed):
        self.X, self.y = X, y
        self.crop_length = crop_length
        self.augmenter = augmenter
        self.mean = mean.astype(np.float32)
        self.scale = scale.astype(np.float32)
        self.rng = np.random.RandomState(seed)

    def __len__(self):
        return len(self.X)

    def __getitem__(self, i):
        raise TypeError("crops are drawn in batches by _CropBatches")

    def sample(self, batch_size):
        rng, length = self.rng, self.crop_length
        xb = np.zeros((batch_size, length, self.mean.size), dtype=np.float32)
        yb = np.full((batch_size, length), IGNORE_INDEX, dtype=np.int64)
        for b in range(batch_size):
            i = rng.randint(len(self.X))
            x, y = self.X[i], self.y[i]
            if self.augmenter is not None:
                # Crop with a margin first, so the time warp has frames to use.
                margin = int(np.ceil(length * 1.5))
                if len(x) > margin:
                    s = rng.randint(len(x) - margin + 1)
                    x, y = x[s : s + margin], y[s : s + margin]
                x, y = self.augmenter.augment(x, y, rng)
            if len(x) > length:
                s = rng.randint(len(x) - length + 1)
                x, y = x[s : s + length], y[s : s + length]
            xb[b, : len(x)] = (x - self.mean) / self.scale
            yb[b, : len(y)] = y
        return torch.from_numpy(xb), torch.from_numpy(yb)


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


class _HoldOutSequences:
    """skorch ``train_split``: whole sequences held out for validation."""

    def __init__(self, fraction, seed):
        self.fraction = fraction
        self.seed = seed

    def __call__(self, dataset, y=None, **kwargs):
        n = len(dataset.X)
        held = held_out_sequences(n, self.fraction, self.seed)
        keep = np.setdiff1d(np.arange(n), held)
        train = _CropData(
            [dataset.X[i] for i in keep],
            [dataset.y[i] for i in keep],
            crop_length=dataset.crop_length,
            augmenter=dataset.augmenter,
            mean=dataset.mean,
            scale=dataset.scale,
            seed=self.seed,
        )
        valid = _WholeSequences(
            [dataset.X[i] for i in held],
            [dataset.y[i] for i in held],
            dataset.mean,
            dataset.scale,
        )
        return train, valid


class WarmupCosine:
    """Learning-rate factor of step ``k``: linear warm-up, then cosine decay.

    The one-cycle shape (warm-up over ``warmup`` of the ``total`` steps, then
    a half cosine down to ``final`` of the peak), as a picklable callable for
    ``torch.optim.lr_scheduler.LambdaLR``; well defined for any ``total >= 1``.

    Examples
    --------
    >>> from skgesture._tagger import WarmupCosine
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


def _module_spec(architecture, hidden_sizes, dropout, tcn_layers, tcn_stages):
    """Module class and keyword arguments of an ``architecture``."""
    if architecture == "tcn":
        return TemporalConvModule, {
            "channels": int(hidden_sizes[0]),
            "n_layers": int(tcn_layers),
            "n_stages": int(tcn_stages),
            "dropout": float(dropout),
        }
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
    one-cycle schedule and gradient clipping.
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
        smoothing_weight=0.0,
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
        self.smoothing_weight = smoothing_weight
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
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.device = device
        self.random_state = random_state
        self.verbose = verbose

    def fit(self, X, y):
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
        )
        module, module_kwargs = _module_spec(
            self.architecture,
            self.hidden_sizes,
            self.dropout,
            self.tcn_layers,
            self.tcn_stages,
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
            train_split=_HoldOutSequences(self.validation_fraction, seed),
            callbacks=schedule,
            module_params={
                "n_inputs": int(frames.shape[1]),
                "n_outputs": int(self.n_classes),
                **module_kwargs,
            },
            criterion_params={
                "class_weight": self.class_weight,
                "smoothing_weight": float(self.smoothing_weight),
            },
            optimizer=torch.optim.AdamW,
            optimizer__weight_decay=self.weight_decay,
            iterator_train=_CropBatches,
            iterator_train__steps=self.steps_per_epoch,
            iterator_valid=_OneSequenceBatches,
        )
        return self


def predict_whole(module, X, mean, scale, n_classes):
    """Per-frame softmax probabilities of ``module`` run over whole sequences.

    Sequences of equal length are batched together; the output is float64.
    """
    module.eval()
    out = [None] * len(X)
    by_length = {}
    for i, x in enumerate(X):
        by_length.setdefault(len(x), []).append(i)
    for idx in by_length.values():
        xb = np.stack([(X[i] - mean) / scale for i in idx]).astype(np.float32)
        for i, p in zip(idx, frame_probabilities(module, xb)):
            out[i] = p.reshape(len(X[i]), n_classes)
    return out


# -- the shared base -----------------------------------------------------------


_DECODING_CONSTRAINTS = {
    "smooth_span": [Interval(Real, 0, None, closed="neither")],
    "smoothing": [StrOptions(SMOOTHINGS)],
    "min_run": [Interval(Integral, 1, None, closed="left")],
    "max_gap": [Interval(Integral, 0, None, closed="left")],
}

_STREAM_CONSTRAINTS = {
    "stream_past": [Interval(Integral, 0, None, closed="left")],
    "stream_future": [Interval(Integral, 0, None, closed="left")],
}


class _BaseTagger(ClassifierMixin, BaseEstimator):
    """Per-frame classifier of whole sequences, with one decoding path.

    Subclasses implement ``_network(n_classes)`` (an unfitted estimator whose
    ``fit(X, y_idx)`` trains the network; cached by ``memory``),
    ``_adopt(fitted)`` (copies its fitted state) and ``_raw_proba(X)``, and
    have the parameters ``smooth_span``, ``smoothing``, ``min_run``,
    ``max_gap``, ``memory`` and ``n_threads`` (or class attributes of these
    names, for rules a tagger fixes).

    Untracked rows (those of :func:`untracked_rows`: the masked rows of a
    ``numpy.ma.MaskedArray``, the all-zero rows of a plain array) are rest by
    construction: certain rest in ``predict_proba``, and rest in the labels,
    set after the smoothing (so they do not change the smoothed scores of
    their tracked neighbours) and before the ``min_run`` filter.
    """

    def _validate_fit(self, X, y, *, ignore_untracked=True):
        """Checked sequences, labels encoded as class indices, and classes.

        With ``ignore_untracked`` the labels of untracked rows are
        ``IGNORE_INDEX``: lost tracking teaches nothing.
        """
        data = check_sequences(X, ndim=2, estimator=self, reset=True)
        y = check_sequence_labels(y, data)
        classes, y_idx = np.unique(np.concatenate(y), return_inverse=True)
        if classes[0] != 0:
            raise ValueError(
                "y has no rest frame (label 0): the tagger learns gestures against "
                f"rest, got labels {classes.tolist()}"
            )
        if len(classes) < 2:
            raise ValueError(
                "y has no gesture frame (every label is 0): the tagger needs "
                "labels 1..K as well as rest"
            )
        y_idx = np.split(y_idx.astype(np.int64), np.cumsum([len(v) for v in y])[:-1])
        if ignore_untracked:
            for lab, rows in zip(y_idx, _untracked(X, data)):
                lab[rows] = IGNORE_INDEX
        return data, y_idx, classes

    def _fit_network(self, X, y_idx, classes):
        network = self._network(len(classes))
        with torch_threads(self.n_threads):
            fitted = fit_cached(self.memory, network, X, y_idx)
        self.classes_ = classes
        self._adopt(fitted)
        return self

    def _proba(self, X):
        """The network's probabilities and the untracked rows of every sequence."""
        check_is_fitted(self)
        data = check_sequences(X, ndim=2, estimator=self, reset=False)
        with torch_threads(self.n_threads):
            proba = self._raw_proba(data)
        return proba, _untracked(X, data)

    def predict_proba(self, X):
        """Raw per-frame class probabilities (before smoothing).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features; any length >= 1.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_classes)
            Rows sum to 1; columns in ``classes_`` order. An untracked row
            (masked, or all zero) is rest with probability 1.
        """
        proba, untracked = self._proba(X)
        return [_rest_where(p, rows) for p, rows in zip(proba, untracked)]

    def predict(self, X):
        """Per-frame labels.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of ndarray of shape (n_frames_i,)
            Labels from ``classes_`` after the decoding rules; untracked
            frames are rest (0).
        """
        proba, untracked = self._proba(X)
        return [self._decode(p, rows) for p, rows in zip(proba, untracked)]

    def predict_segments(self, X):
        """Gesture instances with their confidence.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.

        Returns
        -------
        list of ndarray of shape (n_segments_i, 4)
            Rows ``(class, start, end, confidence)``, 0-based, ``end``
            exclusive; the confidence is the mean raw probability of the class
            over the run.
        """
        proba, untracked = self._proba(X)
        return [
            segments_with_confidence(self._decode(p, rows), p, self.classes_)
            for p, rows in zip(proba, untracked)
        ]

    def score(self, X, y, sample_weight=None):
        """Mean official ChaLearn 2014 Jaccard index.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.
        y : list of ndarray of shape (n_frames_i,)
            True per-frame labels.
        sample_weight : None
            Not supported.

        Returns
        -------
        float
            Mean Jaccard index over the sequences.

        Warns
        -----
        UserWarning
            If ``y`` holds a class never seen in ``fit``: the tagger cannot
            predict it, so its Jaccard index is 0.
        """
        from skgesture.metrics import jaccard_index

        check_is_fitted(self)
        unseen = np.setdiff1d(
            np.unique(np.concatenate([np.ravel(v) for v in y])), self.classes_
        )
        if unseen.size:
            warnings.warn(
                f"y holds classes {unseen.tolist()} never seen in fit (classes_ "
                f"= {self.classes_.tolist()}): their Jaccard index is 0",
                UserWarning,
                stacklevel=2,
            )
        return jaccard_index(y, self.predict(X))

    def _decode(self, proba, untracked=None):
        return decode(
            proba,
            self.classes_,
            smooth_span=self.smooth_span,
            smoothing=self.smoothing,
            min_run=self.min_run,
            max_gap=self.max_gap,
            untracked=untracked,
        )

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        tags.non_deterministic = getattr(self, "device", "cpu") != "cpu"
        return tags

    # -- incremental step (docs/design.md §4.1, "Incremental steps") -----------
    # A tagger that reads whole sequences streams over a trailing window with
    # a fixed look-ahead (skgesture/_incremental.py, TrailingWindowStream):
    # probabilities of frame u once frame u + stream_future is known, then the
    # offline decoding (the smoothing's stepper and decode on stretches that
    # no later frame can change). Subclasses with their own step (the chunked
    # BiLSTMTagger) override these methods.

    def stream_init(self, *, max_period=1200, **options):
        """A fresh state for one live stream (docs/design.md §4.1).

        Parameters
        ----------
        max_period : int, default=1200
            A stretch of frames this long that the decoding cannot cut yet
            (one gesture, or runs of one class joined by short gaps) is
            decided as if the stream ended there, which bounds memory;
            offline has no such cap.
        **options
            Options of other stages, ignored.

        Returns
        -------
        object
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        from skgesture._incremental import TrailingWindowStream

        check_is_fitted(self)
        past = getattr(self, "stream_past", DEFAULT_STREAM_PAST)
        with torch_threads(getattr(self, "n_threads", None)):
            scorer = self._stream_scorer(past)
        return TrailingWindowStream(
            scorer,
            self.classes_,
            past,
            getattr(self, "stream_future", DEFAULT_STREAM_FUTURE),
            self.smooth_span,
            self.min_run,
            smoothing=self.smoothing,
            max_gap=self.max_gap,
            max_run=max_period,
            owner=f"{type(self).__name__}.smooth_span",
        )

    def stream_step(self, state, rows):
        """Feature rows in; the gestures decided with them out.

        The probabilities of frame ``u`` are computed when frame
        ``u + stream_future`` arrives, from the frames up to it (a window of
        ``stream_past`` frames before, or a recurrent network's carried
        state), then smoothed and decoded with the offline rules
        (:func:`skgesture._decoding.decode`); untracked (masked) rows are
        rest.

        Parameters
        ----------
        state : object
            From :meth:`stream_init`.
        rows : Rows
            The next feature rows.

        Returns
        -------
        out : list of StreamSegment
            ``(label, start, end, confidence, time)`` of each gesture decided.
        state : object
            The updated state.
        """
        return state.step(rows), state

    def stream_flush(self, state):
        """End of the stream: the last frames, end-point smoothing, last run.

        Parameters
        ----------
        state : object
            From :meth:`stream_init`.

        Returns
        -------
        out : list of StreamSegment
            The remaining gestures.
        state : object
            The spent state.
        """
        return state.flush(), state

    @property
    def stream_lookahead(self):
        """Frames between a gesture's last frame and its event, at most.

        ``stream_future`` + the smoothing's look-ahead + ``max_gap`` + 1
        (9 with the defaults).
        """
        from skgesture._incremental import make_smoother

        future = getattr(self, "stream_future", DEFAULT_STREAM_FUTURE)
        name = f"{type(self).__name__}.smooth_span"
        h = make_smoother(self.smoothing, self.smooth_span, 1, owner=name).h
        return int(future) + h + int(self.max_gap) + 1

    def _stream_scorer(self, past):
        """Probabilities of a frame in a stream: ``_raw_proba`` on a window."""
        from skgesture._incremental import WindowScorer

        return WindowScorer(lambda rows: self._raw_proba([rows])[0], past)


def _untracked(X, data):
    """Untracked rows of every sequence: the masked rows of a masked array
    (``data``, the validated sequences, has no mask), else the all-zero rows."""
    return [
        untracked_rows(x if isinstance(x, np.ma.MaskedArray) else d)
        for x, d in zip(X, data)
    ]


def _rest_where(proba, rows):
    """``proba`` with the rows ``rows`` set to certain rest (column 0)."""
    if not rows.any():
        return proba
    proba = proba.copy()
    proba[rows] = 0.0
    proba[rows, 0] = 1.0
    return proba


class SequenceTagger(_BaseTagger):
    """Network labelling every frame of whole sequences (the recommended tagger).

    A bidirectional GRU (or LSTM, or an MS-TCN temporal convolutional network)
    reads each whole sequence and gives every frame one of K + 1 classes (rest
    included). Unlike Method C, which reads 10-frame chunks with a fresh state,
    it sees the whole context of every frame.

    Training draws random ``crop_length``-frame crops of the training
    sequences, perturbs them with ``augment`` (rotation about the vertical
    axis, scaling, time warping, noise), standardises the features with the
    training statistics, and minimises the framewise cross-entropy (plus the
    MS-TCN smoothing loss if ``smoothing_weight > 0``) with AdamW, a
    one-cycle learning-rate schedule and gradient-norm clipping, for
    ``max_epochs`` epochs of ``steps_per_epoch`` batches; with
    ``early_stopping`` whole sequences are held out and the best epoch kept.

    Prediction runs the network over each whole sequence, then decodes the
    probabilities: smoothing of every class track, arg-max, rest gaps of at
    most ``max_gap`` frames between runs of one class filled, gesture runs
    shorter than ``min_run`` set to rest. Decoding never retrains: with
    ``memory`` a search over it trains once per fold.

    Parameters
    ----------
    architecture : {"gru", "lstm", "tcn"}, default="gru"
        Bidirectional GRU, bidirectional LSTM, or MS-TCN.
    hidden_sizes : tuple of int, default=(64, 64)
        Units per direction of each recurrent layer; for ``"tcn"`` the first
        entry is the channel count of every layer.
    dropout : float, default=0.0
        Drop probability between recurrent layers / inside the TCN layers.
    tcn_layers : int, default=8
        Dilated residual layers per MS-TCN stage (dilations 1, 2, 4, ...; a
        stage sees ``2 ** (tcn_layers + 1) - 1`` frames).
    tcn_stages : int, default=2
        Stages of the MS-TCN (ignored by the recurrent architectures).
    smoothing_weight : float, default=0.0
        Weight of the MS-TCN smoothing loss (0.15 in Farha & Gall 2019).
    crop_length : int, default=128
        Frames per training crop.
    batch_size : int, default=32
        Crops per batch.
    steps_per_epoch : int, default=20
        Batches per epoch.
    max_epochs : int, default=15
        Epochs; the one-cycle schedule spans ``max_epochs * steps_per_epoch``
        steps.
    learning_rate : float, default=3e-3
        Peak learning rate of the one-cycle schedule.
    weight_decay : float, default=1e-4
        AdamW weight decay.
    clip_norm : float or None, default=1.0
        Largest gradient norm; None disables clipping.
    class_weight : None, "balanced" or float, default=None
        Cross-entropy weight per class: none, inverse class frequency
        (``"balanced"``), or inverse frequency raised to this power (0.5 is a
        milder balance).
    augment : SkeletonAugmenter or None, default=None
        Augmentation of the training crops (needs xyz-triple features such as
        :class:`JointFeatures`'s when it rotates or scales).
    standardize : bool, default=True
        Z-score every feature with the training mean and standard deviation.
    early_stopping : bool, default=False
        Hold out ``validation_fraction`` of the training sequences, stop after
        ``n_iter_no_change`` epochs without a lower validation loss, and keep
        the best epoch's weights.
    validation_fraction : float, default=0.15
        Share of the sequences held out with ``early_stopping``.
    n_iter_no_change : int, default=5
        Patience of the early stopping, in epochs.
    smooth_span : int or float, default=1
        Window of the probability smoothing, in frames (1: none).
    smoothing : {"loess", "mean", "none"}, default="mean"
        Smoothing method.
    min_run : int, default=1
        Shortest gesture run kept, in frames.
    max_gap : int, default=0
        Longest rest gap filled between two runs of one class.
    stream_past : int, default=32
        Streaming only (:class:`~skgesture.streaming.StreamingRecognizer`):
        frames before a frame that a network reading a window (the TCN, or
        any other) sees; a recurrent network carries its forward state from
        the start of the stream instead (docs/streaming.md, "The recommended
        model").
    stream_future : int, default=8
        Streaming only: frames after a frame that the network sees before
        its probabilities are computed; the stage's delay is ``stream_future``
        plus the smoothing's half span plus ``max_gap`` plus 1.
    memory : None, str or joblib.Memory, default=None
        Caches the trained network keyed on the training data and the network
        and training parameters only.
    device : str, default="cpu"
        Torch device of the training; a fitted tagger predicts on the CPU of a
        machine without CUDA.
    n_threads : int or None, default=1
        Torch intra-op threads while fitting and predicting (restored
        afterwards); None keeps torch's setting.
    random_state : int, RandomState instance or None, default=None
        Seeds the initialisation, the crops, the augmentation, the dropout and
        the validation split; an int gives identical results on the CPU.
    verbose : int, default=0
        0 silent, 1 a progress bar over epochs, 2 one line per epoch.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Labels seen in ``fit``, rest (0) first.
    net_ : skorch.NeuralNet
        The trained network (``net_.history`` holds the losses).
    mean_ : ndarray of shape (n_features,)
        Training mean of every feature.
    scale_ : ndarray of shape (n_features,)
        Training standard deviation of every feature.
    n_features_in_ : int
        Number of features per frame.
    frame_shape_in_ : tuple of int
        Shape of one input frame, ``(n_features_in_,)``.

    See Also
    --------
    make_recommended : The pipeline built around this tagger.
    BiLSTMTagger : Method C, the paper's chunked BiLSTM.
    VotingTagger : Soft voting over several taggers.

    Notes
    -----
    Frames of an input ``numpy.ma.MaskedArray`` that are masked (untracked
    skeletons) are left out of the loss in ``fit`` and are rest at
    prediction. A sequence of any length >= 1 can be predicted.

    References
    ----------
    .. [1] Farha & Gall, "MS-TCN: Multi-Stage Temporal Convolutional Network
       for Action Segmentation", CVPR 2019.

    Examples
    --------
    >>> from skgesture import JointFeatures, SequenceTagger
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> F = JointFeatures().fit_transform([X])
    >>> tagger = SequenceTagger(hidden_sizes=(16,), max_epochs=2, random_state=0)
    >>> tagger = tagger.fit(F, [y])
    >>> tagger.classes_.tolist()
    [0, 1, 2, 3]
    >>> tagger.predict(F)[0].shape == y.shape
    True
    """

    _parameter_constraints: dict = {
        "architecture": [StrOptions({"gru", "lstm", "tcn"})],
        "hidden_sizes": [tuple, list],
        "dropout": [Interval(Real, 0, 1, closed="left")],
        "tcn_layers": [Interval(Integral, 1, None, closed="left")],
        "tcn_stages": [Interval(Integral, 1, None, closed="left")],
        "smoothing_weight": [Interval(Real, 0, None, closed="left")],
        "crop_length": [Interval(Integral, 2, None, closed="left")],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "steps_per_epoch": [Interval(Integral, 1, None, closed="left")],
        "max_epochs": [Interval(Integral, 1, None, closed="left")],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
        "weight_decay": [Interval(Real, 0, None, closed="left")],
        "clip_norm": [Interval(Real, 0, None, closed="neither"), None],
        "class_weight": [
            StrOptions({"balanced"}),
            Interval(Real, 0, None, closed="left"),
            None,
        ],
        "augment": [SkeletonAugmenter, None],
        "standardize": ["boolean"],
        "early_stopping": ["boolean"],
        "validation_fraction": [Interval(Real, 0, 1, closed="neither")],
        "n_iter_no_change": [Interval(Integral, 1, None, closed="left")],
        **_DECODING_CONSTRAINTS,
        **_STREAM_CONSTRAINTS,
        "memory": [None, str, HasMethods(["cache"])],
        "device": [str],
        "n_threads": [Interval(Integral, 1, None, closed="left"), None],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        *,
        architecture="gru",
        hidden_sizes=(64, 64),
        dropout=0.0,
        tcn_layers=8,
        tcn_stages=2,
        smoothing_weight=0.0,
        crop_length=128,
        batch_size=32,
        steps_per_epoch=20,
        max_epochs=15,
        learning_rate=3e-3,
        weight_decay=1e-4,
        clip_norm=1.0,
        class_weight=None,
        augment=None,
        standardize=True,
        early_stopping=False,
        validation_fraction=0.15,
        n_iter_no_change=5,
        smooth_span=1,
        smoothing="mean",
        min_run=1,
        max_gap=0,
        stream_past=32,
        stream_future=8,
        memory=None,
        device="cpu",
        n_threads=1,
        random_state=None,
        verbose=0,
    ):
        self.architecture = architecture
        self.hidden_sizes = hidden_sizes
        self.dropout = dropout
        self.tcn_layers = tcn_layers
        self.tcn_stages = tcn_stages
        self.smoothing_weight = smoothing_weight
        self.crop_length = crop_length
        self.batch_size = batch_size
        self.steps_per_epoch = steps_per_epoch
        self.max_epochs = max_epochs
        self.learning_rate = learning_rate
        self.weight_decay = weight_decay
        self.clip_norm = clip_norm
        self.class_weight = class_weight
        self.augment = augment
        self.standardize = standardize
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.smooth_span = smooth_span
        self.smoothing = smoothing
        self.min_run = min_run
        self.max_gap = max_gap
        self.stream_past = stream_past
        self.stream_future = stream_future
        self.memory = memory
        self.device = device
        self.n_threads = n_threads
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y):
        """Train the network on random crops of the sequences.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features (e.g. from :class:`JointFeatures`).
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels, 0 = rest, 1..K gesture classes; both rest and
            gesture frames must occur.

        Returns
        -------
        self : SequenceTagger
            The fitted tagger.
        """
        hidden = self.hidden_sizes
        if len(hidden) == 0 or not all(
            isinstance(h, Integral) and not isinstance(h, bool) and h >= 1
            for h in hidden
        ):
            raise ValueError(
                "hidden_sizes must be a non-empty tuple of positive ints, got "
                f"{hidden!r}"
            )
        X, y_idx, classes = self._validate_fit(X, y)
        self._class_weight = _class_weights(self.class_weight, y_idx, len(classes))
        return self._fit_network([x.astype(np.float32) for x in X], y_idx, classes)

    def _network(self, n_classes):
        return _CropNet(
            n_classes=n_classes,
            architecture=self.architecture,
            hidden_sizes=tuple(int(h) for h in self.hidden_sizes),
            dropout=float(self.dropout),
            tcn_layers=self.tcn_layers,
            tcn_stages=self.tcn_stages,
            smoothing_weight=self.smoothing_weight,
            crop_length=self.crop_length,
            batch_size=self.batch_size,
            steps_per_epoch=self.steps_per_epoch,
            max_epochs=self.max_epochs,
            learning_rate=self.learning_rate,
            weight_decay=self.weight_decay,
            clip_norm=self.clip_norm,
            class_weight=self._class_weight,
            augmenter=None if self.augment is None else clone(self.augment),
            standardize=self.standardize,
            early_stopping=self.early_stopping,
            validation_fraction=self.validation_fraction,
            n_iter_no_change=self.n_iter_no_change,
            device=self.device,
            random_state=(
                None if self.random_state is None else seed_from(self.random_state)
            ),
            verbose=self.verbose,
        )

    def _adopt(self, fitted):
        self.net_ = fitted.net_
        self.mean_ = fitted.mean_
        self.scale_ = fitted.scale_

    def _raw_proba(self, X):
        return predict_whole(
            self.net_.module_, X, self.mean_, self.scale_, len(self.classes_)
        )

    def _stream_scorer(self, past):
        """The recurrent network with its forward states carried along the
        stream, else the network on a window of ``past`` frames (the MS-TCN
        in numpy: :class:`~skgesture._incremental.TemporalConvProba`)."""
        from skgesture._incremental import (
            RecurrentScorer,
            TemporalConvProba,
            WindowScorer,
        )

        module = self.net_.module_
        on_cpu = next(module.parameters()).device.type == "cpu"
        if type(module) is RecurrentTaggerModule and on_cpu:
            return RecurrentScorer(module, self.mean_, self.scale_)
        if type(module) is TemporalConvModule and on_cpu:
            proba = TemporalConvProba(module, self.mean_, self.scale_)
            return WindowScorer(proba, past)
        n_classes = len(self.classes_)

        def proba(rows):
            return predict_whole(module, [rows], self.mean_, self.scale_, n_classes)[0]

        return WindowScorer(proba, past)


def _class_weights(class_weight, y_idx, n_classes):
    """Per-class cross-entropy weights (a list, for a stable cache key)."""
    if class_weight is None:
        return None
    labels = np.concatenate(y_idx)
    counts = np.bincount(labels[labels >= 0], minlength=n_classes).astype(float)
    balanced = counts.sum() / (n_classes * np.maximum(counts, 1.0))
    power = 1.0 if class_weight == "balanced" else float(class_weight)
    return [float(w) for w in balanced**power]


class VotingTagger(_BaseTagger):
    """Soft voting over several fitted taggers, decoded once.

    Fits a clone of every tagger on the same data (each with its own seed
    drawn from ``random_state``), averages their per-frame probabilities with
    ``weights``, and decodes the average with the shared rules. A list of one
    tagger repeated with different seeds is a seed ensemble.

    Parameters
    ----------
    estimators : list of (str, estimator)
        Taggers with ``predict_proba`` over lists of sequences (e.g.
        :class:`SequenceTagger`, :class:`BiLSTMTagger`).
    weights : array-like of shape (n_estimators,) or None, default=None
        Weight of every tagger's probabilities; None weighs them equally.
    smooth_span : int or float, default=1
        Window of the probability smoothing, in frames (1: none).
    smoothing : {"loess", "mean", "none"}, default="mean"
        Smoothing method.
    min_run : int, default=1
        Shortest gesture run kept, in frames.
    max_gap : int, default=0
        Longest rest gap filled between two runs of one class.
    stream_past : int, default=32
        Streaming only (:class:`~skgesture.streaming.StreamingRecognizer`):
        frames before a frame that a member reading a window (a TCN, or any
        other) sees, for every member; a recurrent member carries its forward
        state from the start of the stream instead (docs/streaming.md, "The recommended
        model").
    stream_future : int, default=8
        Streaming only: frames after a frame that the network sees before
        its probabilities are computed; the stage's delay is ``stream_future``
        plus the smoothing's half span plus ``max_gap`` plus 1.
    n_threads : int or None, default=1
        Torch threads while fitting and predicting.
    random_state : int, RandomState instance or None, default=None
        Draws one seed per tagger (replacing its ``random_state``); None
        keeps every tagger's own.

    Attributes
    ----------
    estimators_ : list of estimator
        The fitted taggers.
    classes_ : ndarray of shape (n_classes,)
        Labels seen in ``fit``, rest (0) first.
    n_features_in_ : int
        Number of features per frame.
    frame_shape_in_ : tuple of int
        Shape of one input frame.

    See Also
    --------
    SequenceTagger : The usual member.

    Examples
    --------
    >>> from skgesture import JointFeatures, SequenceTagger, VotingTagger
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> F = JointFeatures().fit_transform([X])
    >>> small = SequenceTagger(hidden_sizes=(8,), max_epochs=1)
    >>> vote = VotingTagger([("a", small), ("b", small)], random_state=0)
    >>> len(vote.fit(F, [y]).estimators_)
    2
    >>> vote.predict(F)[0].shape == y.shape
    True
    """

    _parameter_constraints: dict = {
        "estimators": [list],
        "weights": ["array-like", None],
        **_DECODING_CONSTRAINTS,
        **_STREAM_CONSTRAINTS,
        "n_threads": [Interval(Integral, 1, None, closed="left"), None],
        "random_state": ["random_state"],
    }

    def __init__(
        self,
        estimators,
        *,
        weights=None,
        smooth_span=1,
        smoothing="mean",
        min_run=1,
        max_gap=0,
        stream_past=32,
        stream_future=8,
        n_threads=1,
        random_state=None,
    ):
        self.estimators = estimators
        self.weights = weights
        self.smooth_span = smooth_span
        self.smoothing = smoothing
        self.min_run = min_run
        self.max_gap = max_gap
        self.stream_past = stream_past
        self.stream_future = stream_future
        self.n_threads = n_threads
        self.random_state = random_state

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y):
        """Fit every tagger.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame features.
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels.

        Returns
        -------
        self : VotingTagger
            The fitted ensemble.
        """
        if len(self.estimators) == 0:
            raise ValueError("estimators is empty: give at least one tagger")
        names = [name for name, _ in self.estimators]
        if len(set(names)) != len(names):
            raise ValueError(f"estimator names must be unique, got {names}")
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=float)
            if w.shape != (len(self.estimators),) or not np.all(np.isfinite(w)):
                raise ValueError(
                    f"weights must be {len(self.estimators)} finite numbers, got "
                    f"{self.weights!r}"
                )
            if (w < 0).any() or w.sum() <= 0:
                raise ValueError(
                    f"weights must be non-negative with a positive sum, got "
                    f"{self.weights!r}"
                )
        self._validate_fit(X, y)  # sets n_features_in_; clear errors first
        rng = (
            None if self.random_state is None else check_random_state(self.random_state)
        )
        fitted = []
        for _, est in self.estimators:
            est = clone(est)
            if rng is not None and "random_state" in est.get_params():
                est.set_params(random_state=seed_from(rng))
            fitted.append(est.fit(X, y))
        classes = fitted[0].classes_
        for (name, _), est in zip(self.estimators, fitted):
            if not np.array_equal(est.classes_, classes):
                raise ValueError(
                    f"tagger {name!r} learned classes {est.classes_.tolist()}, "
                    f"the first learned {classes.tolist()}"
                )
        self.estimators_ = fitted
        self.classes_ = classes
        return self

    def _raw_proba(self, X):
        w = (
            np.ones(len(self.estimators_))
            if self.weights is None
            else np.asarray(self.weights, dtype=float)
        )
        w = w / w.sum()
        total = None
        for weight, est in zip(w, self.estimators_):
            proba = est.predict_proba(X)
            if total is None:
                total = [weight * p for p in proba]
            else:
                total = [t + weight * p for t, p in zip(total, proba)]
        return total

    def _stream_scorer(self, past):
        """The weighted mean of the members' stream scorers."""
        from skgesture._incremental import VotingScorer, WindowScorer

        w = (
            np.ones(len(self.estimators_))
            if self.weights is None
            else np.asarray(self.weights, dtype=float)
        )
        scorers = []
        for est in self.estimators_:
            if hasattr(est, "_stream_scorer"):
                scorers.append(est._stream_scorer(past))
            else:
                scorers.append(
                    WindowScorer(lambda rows, e=est: e.predict_proba([rows])[0], past)
                )
        return VotingScorer(scorers, w / w.sum())
