"""The live steps of the taggers: their states for one stream."""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture._taggers._decoding import LabelRuns, make_smoother
from skgesture.utils._buffers import RowBuffer
from skgesture.utils._segments import _chunks
from skgesture.utils._smoothing import LoessStepper


class TaggerStream:
    """State of :meth:`BiLSTMTagger.stream_step` for one stream.

    The network runs on every completed chunk of ``window`` frames, exactly
    the chunks of offline ``predict_proba`` (non-overlapping from the start of
    the stream; with ``overlap=True`` the half-overlapping ones, and the final
    irregular chunk at the end). Each class track is smoothed by the causal
    loess, the label is the arg-max, and each run of one gesture label of at
    least ``min_run`` frames is emitted when the label changes
    (:class:`LabelRuns`).
    """

    def __init__(self, tagger, max_run=None):
        self.tagger = tagger
        self.chunks = _chunks
        self.window = int(tagger.window)
        self.overlap = bool(tagger.overlap) and self.window > 1
        self.chunk_step = max(self.window // 2, 1) if self.overlap else self.window
        self.classes = np.asarray(tagger.classes_)
        n = len(self.classes)
        self.smoother = LoessStepper(
            tagger.smooth_span, n, owner="BiLSTMTagger.smooth_span"
        )
        self.runs = LabelRuns(self.classes, max_run=max_run, **tagger._run_rules())
        self.D = None  # descriptor rows of the chunks to come
        self.raw = RowBuffer((n,), capacity=64)  # released probabilities
        self.sums = np.zeros((self.window + self.chunk_step, n))
        self.counts = np.zeros(self.window + self.chunk_step)
        self.base = 0  # row of sums[0]
        self.next_chunk = 0
        self.last_time = 0

    def _proba(self, lo, hi):
        return self.tagger.predict_proba([self.D.data(lo, hi)])[0]

    def step(self, rows):
        if self.D is None:
            self.D = RowBuffer(rows.data.shape[1:], capacity=64)
        self.D.append(rows.data, rows.mask, rows.time)
        self.last_time = int(rows.time[-1])
        out = []
        W, step = self.window, self.chunk_step
        while self.next_chunk + W <= self.D.stop:
            s = self.next_chunk
            proba = self._proba(s, s + W)
            i = s - self.base
            self.sums[i : i + W] += proba
            self.counts[i : i + W] += 1
            # Frames s .. s + step - 1 are covered by no later regular chunk.
            now = int(self.D.time(s + W - 1, s + W)[0])
            out += self._release(s + step, now)
            self.next_chunk += step
        # The last window rows stay for the final irregular chunk of flush.
        self.D.drop(min(self.next_chunk, self.D.stop - W))
        return out

    def _release(self, stop, now):
        """Hand the averaged probabilities of rows ``base .. stop - 1`` on."""
        n = stop - self.base
        if n <= 0:
            return []
        rows = self.sums[:n] / self.counts[:n, None]
        self.sums = np.roll(self.sums, -n, axis=0)
        self.counts = np.roll(self.counts, -n)
        self.sums[-n:] = 0.0
        self.counts[-n:] = 0
        lo = self.base
        self.base = stop
        self.raw.append(rows, self._rest(lo, stop), np.full(n, now))
        return self._smoothed(*self.smoother.step(rows, np.full(n, now)))

    def _rest(self, lo, hi):
        """Untracked rows, rest by construction (contract 2 of the data)."""
        return self.D.mask(lo, hi).copy()

    def _smoothed(self, lo, smoothed, times):
        if not len(smoothed):
            return []
        hi = lo + len(smoothed)
        raw = self.raw.data(lo, hi)
        rest = self.raw.mask(lo, hi)
        out = self.runs.feed(lo, smoothed, raw, rest, times)
        self.raw.drop(hi)
        return out

    def flush(self):
        if self.D is None:
            return []
        T = self.D.stop
        W, step = self.window, self.chunk_step
        extra = [
            (s, e) for s, e in self.chunks(T, W, self.overlap)
            if e - s < W or s % step
        ]  # fmt: skip
        for s, e in extra:
            proba = self._proba(s, e)
            # Frames already handed on (still unsmoothed) get the extra chunk too.
            done = max(min(self.base, e) - s, 0)
            if done:
                self._add_to_released(s, proba[:done])
            i = max(s - self.base, 0)
            self.sums[i : i + (e - s - done)] += proba[done:]
            self.counts[i : i + (e - s - done)] += 1
        out = self._release(T, self.last_time)
        out += self._smoothed(*self.smoother.flush(self.last_time))
        out += self.runs.end(T, self.last_time)
        return out

    def _add_to_released(self, s, proba):
        """Average an extra chunk into released rows ``s ..`` still held."""
        W, step = self.window, self.chunk_step
        for k, p in enumerate(proba):
            u = s + k
            # Regular chunks that covered u: starts in (u - W, u], multiples of step.
            count = (u // step) - (max(u - W + step, 0) // step) + 1
            for buf in (self.smoother.buf, self.raw):
                if buf.start <= u < buf.stop:
                    row = buf.data(u, u + 1)
                    row[0] = (row[0] * count + p) / (count + 1)

    def held(self):
        return {
            "descriptors": len(self.D or ()),
            "scores": self.smoother.held(),
        }


class WindowScorer:
    """Class probabilities of a frame from a window of rows around it.

    ``proba(rows) -> (len(rows), n_classes)`` is run on the rows
    ``u - lookback .. end - 1`` (clipped to the rows held) and the row of
    frame ``u`` is read off: a tagger that reads whole sequences offline (a
    TCN, any ``predict_proba``) run on a trailing window.

    Parameters
    ----------
    proba : callable
        Probabilities of a block of consecutive feature rows.
    lookback : int
        Rows before a frame that its window holds.
    """

    def __init__(self, proba, lookback):
        self.proba = proba
        self.lookback = int(lookback)

    def __call__(self, X, lo, stop, end):
        """Probabilities of rows ``lo .. stop - 1``, each from the rows up to
        ``end - 1`` (``X``: a :class:`RowBuffer`)."""
        out = []
        for u in range(lo, stop):
            a = max(u - self.lookback, X.start)
            out.append(self.proba(X.data(a, end))[u - a])
        return np.array(out, dtype=np.float64).reshape(stop - lo, -1)

    def reset(self):
        """Nothing is carried from one frame to the next."""


class VotingScorer:
    """Weighted mean of the probabilities of several scorers (a VotingTagger).

    Parameters
    ----------
    scorers : list
        :class:`WindowScorer` or :class:`RecurrentScorer` of every member.
    weights : ndarray
        Weight of every member, summing to 1.
    """

    def __init__(self, scorers, weights):
        self.scorers = list(scorers)
        self.weights = np.asarray(weights, dtype=float)
        self.lookback = max(s.lookback for s in self.scorers)

    def __call__(self, X, lo, stop, end):
        from skgesture.utils._validation import untracked_rows

        # A member's predict_proba makes an all-zero row certain rest.
        zero = untracked_rows(X.data(lo, stop))
        total = None
        for weight, scorer in zip(self.weights, self.scorers):
            p = scorer(X, lo, stop, end)
            if zero.any():
                p = p.copy()
                p[zero] = 0.0
                p[zero, 0] = 1.0
            total = weight * p if total is None else total + weight * p
        return total

    def reset(self):
        """Reset every member."""
        for scorer in self.scorers:
            scorer.reset()


class TrailingWindowStream:
    """Stream state of a tagger that sees a window of frames around each frame.

    For taggers that read whole sequences offline (a bidirectional GRU, a
    TCN): the probabilities of frame ``u`` are computed from the rows up to
    ``u + lookahead`` as soon as row ``u + lookahead`` arrives (the rows
    ``u - lookback ..`` of a window, or a recurrent network's carried state:
    :class:`WindowScorer`, :class:`RecurrentScorer`), smoothed by the stepper
    of the offline smoothing (:func:`make_smoother`) and decoded by
    :class:`LabelRuns`, which calls the offline decoding functions (masked
    rows are rest in the labels, after the smoothing). At :meth:`flush` the
    remaining frames are scored from the rows up to the last one. A stage's
    ``stream_init`` returns one; its ``stream_step`` and ``stream_flush`` call
    :meth:`step` and :meth:`flush`, and its ``stream_lookahead`` is
    :attr:`delay`,
    ``lookahead + h + lag + max_gap + 1`` (``h`` the smoothing's look-ahead,
    ``(span - 1) // 2`` for loess; ``lag`` the Viterbi path's, 0 without).

    Parameters
    ----------
    proba : callable or scorer
        ``proba(rows) -> (len(rows), n_classes)`` class probabilities of a block
        of consecutive feature rows (the row of frame ``u`` is read off its
        window of ``lookback`` rows before it), or a scorer object such as
        :class:`RecurrentScorer` (its own ``lookback``).
    classes : ndarray
        Class of every probability column, rest (0) first.
    lookback, lookahead : int
        Frames of context before and after a frame.
    span : int
        Span of the probability smoothing.
    min_run : int
        Shortest gesture run kept.
    smoothing : {"loess", "mean", "none"}, default="loess"
        Smoothing method, as :func:`skgesture._taggers._decoding.smooth_proba`.
    max_gap : int, default=0
        Longest rest gap filled between two runs of one class.
    max_run : int or None, default=None
        Stretches of undecided rows this long are decided (see
        :class:`LabelRuns`).
    owner : str, default="smooth_span"
        Parameter name for error messages.
    novelty : callable or None, default=None
        ``novelty(rows) -> (len(rows), n_classes)``, the novelty of feature
        rows (:meth:`skgesture.utils.PoseNovelty.score`), computed
        for each row as it is scored; needed with ``max_novelty``.
    **run_rules : dict
        ``min_confidence``, ``min_lengths``, ``max_lengths``, ``max_novelty``,
        ``viterbi``, ``namer`` and ``namer_weight`` of :class:`LabelRuns`
        (with ``namer``, the feature rows go along with their scores until
        their run is decided).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._stream import TrailingWindowStream
    >>> from skgesture._stream import stream_frames
    >>> def proba(rows):  # class 1 where the mean of the first feature > 0
    ...     p = (rows[:, :1].mean() > 0) * np.ones((len(rows), 1))
    ...     return np.hstack([1 - p, p])
    >>> st = TrailingWindowStream(proba, np.array([0, 1]), 3, 2, 1, 4)
    >>> x = np.r_[-np.ones(10), np.ones(8), -np.ones(10)][:, None]
    >>> segs = st.step(stream_frames(x, 0)) + st.flush()
    >>> [(s.label, s.start, s.end) for s in segs], st.delay
    ([(1, 11, 18)], 3)
    """

    def __init__(
        self,
        proba,
        classes,
        lookback,
        lookahead,
        span,
        min_run,
        *,
        smoothing="loess",
        max_gap=0,
        max_run=None,
        owner="smooth_span",
        novelty=None,
        **run_rules,
    ):
        if run_rules.get("max_novelty") is not None and novelty is None:
            raise ValueError("max_novelty needs novelty=, the rows' novelty")
        self.novelty = novelty if run_rules.get("max_novelty") is not None else None
        self.scorer = (
            proba if hasattr(proba, "reset") else WindowScorer(proba, lookback)
        )
        self.scorer.reset()
        self.classes = np.asarray(classes)
        self.lookback = int(self.scorer.lookback)
        self.lookahead = int(lookahead)
        self.smoother = make_smoother(smoothing, span, len(self.classes), owner=owner)
        self.runs = LabelRuns(
            self.classes, min_run, max_gap=max_gap, max_run=max_run, **run_rules
        )
        self.delay = self.lookahead + self.smoother.h + self.runs.lag + int(max_gap) + 1
        self.X = None
        self.raw = RowBuffer((len(self.classes),), capacity=64)
        self.nov = RowBuffer((len(self.classes),), capacity=64)
        self.rows = None  # feature rows kept for the namer, scored, undecided
        self.n_out = 0  # frames whose probabilities are computed
        self.last_time = 0

    def step(self, rows):
        """Feature rows in; the segments of the runs that ended out."""
        if self.X is None:
            self.X = RowBuffer(rows.data.shape[1:], capacity=64)
        self.X.append(rows.data, rows.mask, rows.time)
        self.last_time = int(rows.time[-1])
        out = []
        for u in range(self.n_out, self.X.stop - self.lookahead):
            end = u + self.lookahead + 1
            p = self.scorer(self.X, u, u + 1, end)
            out += self._scored(u, p, [int(self.X.time(end - 1, end)[0])])
        self.X.drop(self.n_out - self.lookback)
        return out

    def flush(self):
        """The remaining frames (shorter look-ahead), end-point fits, last run."""
        if self.X is None:
            return []
        out = []
        n = self.X.stop
        if n > self.n_out:
            p = self.scorer(self.X, self.n_out, n, n)
            out += self._scored(self.n_out, p, np.full(n - self.n_out, self.last_time))
        out += self._decide(*self.smoother.flush(self.last_time))
        return out + self.runs.end(n, self.last_time)

    def _scored(self, u, p, times):
        """Probabilities of rows ``u ..`` in: smoothed, then decided (masked
        rows are rest in the labels, after the smoothing, as offline)."""
        hi = u + len(p)
        self.raw.append(p, self.X.mask(u, hi), times)
        if self.novelty is not None:
            self.nov.append(self.novelty(self.X.data(u, hi)))
        if self.runs.namer is not None:
            if self.rows is None:
                self.rows = RowBuffer(self.X.data(u, hi).shape[1:], capacity=64)
            self.rows.append(self.X.data(u, hi))
        self.n_out = hi
        return self._decide(*self.smoother.step(p, np.asarray(times)))

    def _decide(self, lo, smoothed, times):
        if not len(smoothed):
            return []
        hi = lo + len(smoothed)
        novelty = None if self.novelty is None else self.nov.data(lo, hi)
        rows = None if self.rows is None else self.rows.data(lo, hi)
        out = self.runs.feed(
            lo,
            smoothed,
            self.raw.data(lo, hi),
            self.raw.mask(lo, hi),
            times,
            novelty,
            rows,
        )
        self.raw.drop(hi)
        self.nov.drop(hi)
        if self.rows is not None:
            self.rows.drop(hi)
        return out

    def held(self):
        """Rows held by the buffers."""
        return {
            "rows": len(self.X or ()),
            "scores": self.smoother.held(),
            "undecided": self.runs.held(),
        }
