"""Framewise sequence taggers: the shared base, SequenceTagger and VotingTagger.

:class:`_BaseTagger` holds what every tagger shares: label encoding and input
checks in ``fit``, the network cached by ``memory`` (decision parameters never
retrain it), untracked frames forced to rest, and one decoding path
(:func:`skgesture._taggers._decoding.decode`). :class:`~skgesture.BiLSTMTagger`
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
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import check_is_fitted

from skgesture._nn._training import IGNORE_INDEX, torch_threads
from skgesture._stream import DEFAULT_MAX_PERIOD, StreamableMixin
from skgesture._taggers._decoding import (
    LONG_QUANTILE,
    SMOOTHINGS,
    ViterbiRule,
    class_lengths,
    novelty_of,
    path_runs,
    reject_runs,
    segments_with_confidence,
)
from skgesture._taggers._namer import namer_batch, namer_of, namer_scores
from skgesture._taggers._stream import TrailingWindowStream
from skgesture._taggers._viterbi import DECISIONS, chain_lengths
from skgesture.utils._fitting import fit_cached, seed_from
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._segments import runs
from skgesture.utils._threads import blas_threads
from skgesture.utils._validation import (
    check_sequence_labels,
    check_sequences,
    sequence_tags,
    untracked_rows,
)

DEFAULT_STREAM_PAST = 32  # streaming: frames of window before a frame
DEFAULT_STREAM_FUTURE = 8  # and after it (docs/streaming.md)


# -- training data: random crops of whole sequences ----------------------------


# -- the shared base -----------------------------------------------------------


_DECODING_CONSTRAINTS = {
    "smooth_span": [Interval(Real, 0, None, closed="neither")],
    "smoothing": [StrOptions(SMOOTHINGS)],
    "min_run": [Interval(Integral, 1, None, closed="left")],
    "max_gap": [Interval(Integral, 0, None, closed="left")],
    "min_confidence": [Interval(Real, 0, 1, closed="both")],
    "min_duration": [Interval(Real, 0, None, closed="left")],
    "max_duration": [None, Interval(Real, 0, None, closed="neither")],
    "viterbi_penalty": [None, Interval(Real, 0, None, closed="left")],
    "viterbi_duration": [Interval(Real, 0, None, closed="left")],
    "viterbi_lag": [Interval(Integral, 0, None, closed="left")],
    "viterbi_decision": [StrOptions(set(DECISIONS))],
}

_STREAM_CONSTRAINTS = {
    "stream_past": [Interval(Integral, 0, None, closed="left")],
    "stream_future": [Interval(Integral, 0, None, closed="left")],
}


class _BaseTagger(NewParamsMixin, StreamableMixin, ClassifierMixin, BaseEstimator):
    """Per-frame classifier of whole sequences, with one decoding path.

    Subclasses implement ``_network(n_classes)`` (an unfitted estimator whose
    ``fit(X, y_idx)`` trains the network; cached by ``memory``),
    ``_adopt(fitted)`` (copies its fitted state) and ``_raw_proba(X)``, and
    have the parameters ``smooth_span``, ``smoothing``, ``min_run``,
    ``max_gap``, ``min_confidence``, ``min_duration``, ``max_duration``,
    ``memory`` and ``n_threads`` (or class attributes of these names, for
    rules a tagger fixes).

    ``fit`` stores ``class_lengths_`` and ``class_long_lengths_``, the 10th
    and 90th percentiles of every class's training run lengths (its short and
    its long gesture), so that ``min_duration`` and ``max_duration`` (fractions
    of them) change without retraining.

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
        self.class_lengths_ = class_lengths(y, classes)
        self.class_long_lengths_ = class_lengths(y, classes, quantile=LONG_QUANTILE)
        y_idx = np.split(y_idx.astype(np.int64), np.cumsum([len(v) for v in y])[:-1])
        if ignore_untracked:
            for lab, rows in zip(y_idx, _untracked(X, data)):
                lab[rows] = IGNORE_INDEX
        return data, y_idx, classes

    def _fit_network(self, X, y_idx, classes):
        network = self._network(len(classes))
        with torch_threads(self._fit_threads()):
            fitted = fit_cached(self.memory, network, X, y_idx)
        self.classes_ = classes
        self._adopt(fitted)
        return self

    def _fit_threads(self):
        """Torch threads of a fit: ``fit_threads``, every core for "all", or
        ``n_threads``."""
        threads = getattr(self, "fit_threads", None)
        if threads is None:
            return self.n_threads
        if threads == "all":
            import os

            return os.cpu_count() or 1
        return threads

    def _namer_rule(self, batch=False):
        """``score(rows)``, the run namer's scores of a run's feature rows
        (:func:`~skgesture._taggers._namer.namer_scores`; with ``batch``,
        ``score(list of rows)``, :func:`~skgesture._taggers._namer.namer_batch`),
        or None: no namer fitted, or ``namer_weight`` 0 and no
        ``max_namer_rest`` (the runs keep the path's labels)."""
        fitted = getattr(self, "namer_", None)
        if fitted is None or not self._reads_namer():
            return None
        module, n_classes = fitted.module_, len(self.classes_)
        mean, scale = self.namer_mean_, self.namer_scale_
        threads = getattr(self, "n_threads", None)
        scores = namer_batch if batch else namer_scores
        stride = getattr(self, "namer_stride_", 1)  # 1: fitted before the stride

        def score(rows):
            with torch_threads(threads):
                return scores(module, mean, scale, rows, n_classes, stride)

        return score

    def _reads_namer(self):
        """Whether a decoding rule reads the run namer's scores: a
        ``namer_weight`` above 0, or a ``max_namer_rest``."""
        return (
            float(getattr(self, "namer_weight", 0.0)) > 0
            or getattr(self, "max_namer_rest", None) is not None
        )

    def _decode_all(self, proba, untracked, features):
        """:meth:`_decode` of every sequence; the run namer names the runs of
        all of them in one batch (:func:`~skgesture._taggers._namer.namer_batch`)."""
        # numpy's products here are small (a run's rows projected for its
        # novelty): BLAS threads beyond n_threads only wait (utils/_threads.py)
        with blas_threads(getattr(self, "n_threads", None)):
            labels = [self._path(p, u) for p, u in zip(proba, untracked)]
            namers = [None] * len(labels)
            batch = self._namer_rule(batch=True)
            if batch is not None:
                spans = [
                    (i, s, e)
                    for i, lab in enumerate(labels)
                    for s, e, v in zip(*runs(lab))
                    if v != 0
                ]
                rows = [features[i][s:e] for i, s, e in spans]
                table = dict(zip(spans, batch(rows)))
                namers = [
                    lambda s, e, i=i: table[(i, s, e)] for i in range(len(labels))
                ]
            return [self._judge(*args) for args in zip(labels, proba, features, namers)]

    def _proba(self, X):
        """The network's probabilities and the untracked rows of every sequence."""
        proba, untracked, _ = self._scores(X)
        return proba, untracked

    def _scores(self, X):
        """:meth:`_proba`'s probabilities and untracked rows, and the features
        that the ``max_novelty`` rule reads (the checked sequences; None for
        each sequence when the rule is off)."""
        check_is_fitted(self)
        data = check_sequences(X, ndim=2, estimator=self, reset=False)
        with torch_threads(self.n_threads):
            proba = self._raw_proba(data)
        features = data
        if getattr(self, "max_novelty", None) is None and self._namer_rule() is None:
            features = [None] * len(data)
        return proba, _untracked(X, data), features

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
        proba, untracked, features = self._scores(X)
        return self._decode_all(proba, untracked, features)

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
        proba, untracked, features = self._scores(X)
        return [
            segments_with_confidence(labels, p, self.classes_)
            for labels, p in zip(self._decode_all(proba, untracked, features), proba)
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

    def _run_rules(self):
        """The decoding rules after the smoothing, for :func:`decode` and the
        stream's :class:`~skgesture._taggers._decoding.LabelRuns` alike."""
        ratio = float(getattr(self, "min_duration", 0.0))
        penalty = getattr(self, "viterbi_penalty", None)
        lengths = viterbi = None
        if ratio > 0 or penalty is not None:
            fitted = self._fitted_lengths(
                "class_lengths_",
                f"min_duration={ratio}" if ratio > 0 else "viterbi_penalty",
                "min_duration=0 and viterbi_penalty=None",
            )
            if ratio > 0:
                lengths = ratio * fitted
            if penalty is not None:
                viterbi = ViterbiRule(
                    chain_lengths(fitted, getattr(self, "viterbi_duration", 0.0)),
                    penalty,
                    getattr(self, "viterbi_lag", 0),
                    getattr(self, "viterbi_decision", "frame"),
                )
        longest = getattr(self, "max_duration", None)
        max_lengths = None
        if longest is not None:  # no limit for a class without a run
            fitted = self._fitted_lengths(
                "class_long_lengths_", f"max_duration={longest}", "max_duration=None"
            )
            max_lengths = np.where(fitted > 0, longest * fitted, np.inf)
        max_novelty = getattr(self, "max_novelty", None)
        if max_novelty is not None:
            self._fitted("novelty_", f"max_novelty={max_novelty}", "max_novelty=None")
        max_namer_rest = getattr(self, "max_namer_rest", None)
        if max_namer_rest is not None:
            self._fitted(
                "namer_rest_",
                f"max_namer_rest={max_namer_rest}",
                "max_namer_rest=None (or refit with namer='gru')",
            )
            max_namer_rest = float(max_namer_rest)
        return {
            "min_run": self.min_run,
            "max_gap": self.max_gap,
            "min_confidence": float(getattr(self, "min_confidence", 0.0)),
            "min_lengths": lengths,
            "max_lengths": max_lengths,
            "max_novelty": None if max_novelty is None else float(max_novelty),
            "viterbi": viterbi,
            "namer_weight": float(getattr(self, "namer_weight", 0.0)),
            "max_namer_rest": max_namer_rest,
        }

    def _fitted_lengths(self, attribute, rule, off):
        """The fitted per-class lengths ``attribute`` that ``rule`` reads
        (:meth:`_fitted`)."""
        return np.asarray(self._fitted(attribute, rule, off), dtype=float)

    def _fitted(self, attribute, rule, off):
        """The fitted ``attribute`` that ``rule`` reads; a clear error for a
        model fitted before the attribute existed (``off``: how to do
        without it)."""
        fitted = getattr(self, attribute, None)
        if fitted is None:
            raise ValueError(
                f"{rule} needs {attribute}, which this {type(self).__name__} "
                f"was fitted without: refit it, or set {off}"
            )
        return fitted

    def _decode(self, proba, untracked=None, features=None):
        """Labels of one sequence; ``features`` (its rows as ``fit`` saw them)
        are read by the ``max_novelty`` rule and the run namer alone, on the
        rows of the runs they judge."""
        return self._judge(self._path(proba, untracked), proba, features)

    def _path(self, proba, untracked=None):
        """The runs the run rules judge (:func:`decode`'s path and first rules)."""
        rules = self._run_rules()
        return path_runs(
            proba,
            self.classes_,
            smooth_span=self.smooth_span,
            smoothing=self.smoothing,
            min_run=rules["min_run"],
            max_gap=rules["max_gap"],
            untracked=untracked,
            viterbi=rules["viterbi"],
        )

    def _judge(self, labels, proba, features=None, namer=None):
        """The run rules on the runs of :meth:`_path` (``namer``: the namer's
        scores of a run given, ``namer(start, end)``, as :meth:`_decode_all`
        does; None: computed from ``features``)."""
        rules = self._run_rules()
        novelty = None
        if rules["max_novelty"] is not None:
            if features is None:
                raise ValueError("max_novelty needs the sequence's features")
            novelty = novelty_of(features, self.novelty_.score)
        score = self._namer_rule()
        if score is None:
            namer = None
        elif namer is None:
            if features is None:
                raise ValueError("the run namer needs the sequence's features")
            namer = namer_of(features, score)
        return reject_runs(
            labels,
            proba,
            self.classes_,
            min_confidence=rules["min_confidence"],
            min_lengths=rules["min_lengths"],
            max_lengths=rules["max_lengths"],
            novelty=novelty,
            max_novelty=rules["max_novelty"],
            namer=namer,
            namer_weight=rules["namer_weight"],
            max_namer_rest=rules["max_namer_rest"],
        )

    def __sklearn_tags__(self):
        tags = sequence_tags(super().__sklearn_tags__())
        tags.non_deterministic = getattr(self, "device", "cpu") != "cpu"
        return tags

    # -- incremental step (docs/design.md §4.1, "Incremental steps") -----------
    # A tagger that reads whole sequences streams over a trailing window with
    # a fixed look-ahead (skgesture/_taggers/_stream.py, TrailingWindowStream):
    # probabilities of frame u once frame u + stream_future is known, then the
    # offline decoding (the smoothing's stepper and decode on stretches that
    # no later frame can change). Subclasses with their own step (the chunked
    # BiLSTMTagger) override these methods.

    _stream_options = ("max_period",)

    def _stream_state(self, *, max_period=DEFAULT_MAX_PERIOD):
        """A fresh state for one live stream (docs/design.md §4.1).

        Feature rows in, the gestures decided out. The probabilities of frame
        ``u`` are computed when frame ``u + stream_future`` arrives, from the
        frames up to it (a window of ``stream_past`` frames before, or a
        recurrent network's carried state), then smoothed and decoded with the
        offline rules (:func:`skgesture._taggers._decoding.decode`); untracked
        (masked) rows are rest.

        Parameters
        ----------
        max_period : int, default=1200
            A stretch of frames this long that the decoding cannot cut yet
            (one gesture, or runs of one class joined by short gaps) is
            decided as if the stream ended there, which bounds memory;
            offline has no such cap.

        Returns
        -------
        TrailingWindowStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        check_is_fitted(self)
        past = getattr(self, "stream_past", DEFAULT_STREAM_PAST)
        with torch_threads(getattr(self, "n_threads", None)):
            scorer = self._stream_scorer(past)
        rules = self._run_rules()
        return TrailingWindowStream(
            scorer,
            self.classes_,
            past,
            self._stream_future(),
            self.smooth_span,
            smoothing=self.smoothing,
            max_run=max_period,
            owner=f"{type(self).__name__}.smooth_span",
            novelty=None if rules["max_novelty"] is None else self.novelty_.score,
            namer=self._namer_rule(),
            **rules,
        )

    @property
    def stream_lookahead(self):
        """Frames between a gesture's last frame and its event, at most.

        ``stream_future`` + the smoothing's look-ahead + the Viterbi path's
        ``viterbi_lag`` (when ``viterbi_penalty`` is set) + ``max_gap`` + 1.
        """
        from skgesture._taggers._decoding import make_smoother

        future = self._stream_future()
        name = f"{type(self).__name__}.smooth_span"
        h = make_smoother(self.smoothing, self.smooth_span, 1, owner=name).h
        lag = 0
        if getattr(self, "viterbi_penalty", None) is not None:
            lag = int(getattr(self, "viterbi_lag", 0))
        return int(future) + h + lag + int(self.max_gap) + 1

    def _stream_future(self):
        """Frames after a frame that its probabilities wait for, live."""
        return int(getattr(self, "stream_future", DEFAULT_STREAM_FUTURE))

    def _training_params(self):
        """The parameters of the training loop every tagger's network takes
        (``FramewiseNetwork``), from the tagger's own; the network's seed is
        drawn from ``random_state``."""
        seed = None if self.random_state is None else seed_from(self.random_state)
        return {
            "max_epochs": self.max_epochs,
            "batch_size": self.batch_size,
            "learning_rate": self.learning_rate,
            "weight_decay": self.weight_decay,
            "early_stopping": self.early_stopping,
            "validation_fraction": self.validation_fraction,
            "n_iter_no_change": self.n_iter_no_change,
            "device": self.device,
            "random_state": seed,
            "verbose": self.verbose,
        }

    def _stream_scorer(self, past):
        """Probabilities of a frame in a stream: ``_raw_proba`` on a window."""
        from skgesture._taggers._stream import WindowScorer

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
