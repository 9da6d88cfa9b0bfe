"""VotingTagger: soft voting over fitted taggers."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral

import numpy as np
from sklearn.base import _fit_context, clone
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval

from skgesture._taggers._base import (
    _DECODING_CONSTRAINTS,
    _STREAM_CONSTRAINTS,
    _BaseTagger,
)
from skgesture.utils._fitting import seed_from

__all__ = ["VotingTagger"]


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
    min_confidence : float, default=0.0
        Gesture runs whose mean raw probability of their class (the
        confidence of ``predict_segments``) is lower become rest; in [0, 1].
    min_duration : float, default=0.0
        Gesture runs shorter than this fraction of their class's short
        gesture (``class_lengths_``: the 10th percentile of its run lengths
        in ``fit``) become rest. Everyday motion that the network takes for a
        gesture is mostly briefer than the gesture.
    max_duration : float or None, default=None
        Gesture runs longer than this multiple of their class's long gesture
        (``class_long_lengths_``: the 90th percentile of its run lengths in
        ``fit``) become rest: a "gesture" that goes on for several times its
        usual length is walking, carrying or another activity. None: no
        limit.
    viterbi_penalty : float or None, default=None
        None: the labels are the arg-max of every frame. A float: they are
        the duration-aware Viterbi path (a gesture lasts at least
        ``viterbi_duration`` of its class's short gesture, entering one costs
        this many nats of log probability), decided ``viterbi_lag`` frames
        after each frame, offline as live; one doubtful frame then neither
        splits a gesture nor starts a brief false one (docs/design.md,
        "Duration-aware decoding").
    viterbi_duration : float, default=0.7
        Shortest run of the path, as a fraction of ``class_lengths_``.
    viterbi_lag : int, default=6
        Frames between a frame and the path's decision on it (added to the
        stream's delay).
    viterbi_decision : {"frame", "run"}, default="frame"
        When the path decides a frame, as in
        :class:`~skgesture.SequenceTagger`: ``viterbi_lag`` frames after it, or
        (``"run"``) a gesture's frames together once it has ended.
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
    class_lengths_ : ndarray of shape (n_classes,)
        The 10th percentile of every class's run lengths in ``fit``, in
        frames (0 for rest), the unit of ``min_duration``.
    class_long_lengths_ : ndarray of shape (n_classes,)
        The 90th percentile of every class's run lengths in ``fit``, in
        frames (0 for rest), the unit of ``max_duration``.
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
        min_confidence=0.0,
        min_duration=0.0,
        max_duration=None,
        viterbi_penalty=None,
        viterbi_duration=0.7,
        viterbi_lag=6,
        viterbi_decision="frame",
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
        self.min_confidence = min_confidence
        self.min_duration = min_duration
        self.max_duration = max_duration
        self.viterbi_penalty = viterbi_penalty
        self.viterbi_duration = viterbi_duration
        self.viterbi_lag = viterbi_lag
        self.viterbi_decision = viterbi_decision
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
            Per-frame labels, 0 = rest; a sequence whose labels are all 0 is
            a background recording, which every tagger learns as rest.

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
        from skgesture._taggers._stream import VotingScorer, WindowScorer

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
