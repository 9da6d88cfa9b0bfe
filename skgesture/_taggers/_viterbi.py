"""Duration-aware Viterbi path of per-frame class scores, decided at a fixed lag.

The arg-max of every frame's probabilities (the default path of
:func:`skgesture._taggers._decoding.decode`) lets one noisy frame split a
gesture in two or start a brief false one. This path instead reads the best
sequence of labels under a small model of how gestures follow each other:

* a gesture of class ``c`` lasts at least ``durations[c]`` frames (each class
  is a chain of that many states, the last one looping on itself; rest is one
  state), so a run shorter than the class's short gesture costs the whole
  chain;
* entering a gesture costs ``penalty`` (in nats, against the sum of the
  frames' log probabilities); leaving it for rest costs nothing, and a
  gesture may follow another directly (at the same cost).

It is decided **at a fixed lag**: the label of frame ``t`` is the state at
``t`` of the best path ending at frame ``t + lag`` (the last ``lag`` frames
of a sequence are read off the best path ending at its last frame). Offline
and live run the same steps (:class:`ViterbiPath`), so a stream decides every
frame exactly as ``predict`` does, ``lag`` frames after it arrives; a full
Viterbi would wait until every surviving path agrees, a median of 22 frames
after a gesture's end on PRECOG (docs/design.md, "Duration-aware decoding").

With ``decision="run"`` (the recommended model's), only rest is decided at the
lag: once the path reads a gesture's first frame, its frames are held, and
when a later frame is read as rest they are decided together from the best
path of that moment, which has read the whole gesture. The gesture's end is
known as early as before, and its first frames are no longer named after the
gesture they looked like before its end was seen.

The forward step is one function, compiled by numba when it is installed and
run as Python otherwise; both perform the same floating-point operations in
the same order, so both give the same labels.
"""

# SPDX-License-Identifier: BSD-3-Clause

import functools

import numpy as np

__all__ = ["ViterbiPath", "chain_lengths", "log_scores"]

NEG = -1e18  # log score of an unreachable state
FLOOR = 1e-8  # probabilities are clipped here before the log
MASKED = -1e9  # log score of a gesture on an untracked frame
MAX_HELD = 1024  # frames of a gesture held before they are decided (decision="run")
DECISIONS = ("frame", "run")


def _forward(delta, lp, first, last, cls, pen, lag, whole, held, ring, t, out, owner):
    """Advance the path over the rows of ``lp``; write decided labels.

    ``delta`` (n_states,) holds the best log score of a path ending in every
    state at frame ``t - 1`` (unused when ``t == 0``); ``ring`` (cap,
    n_states) the back-pointers of the last ``cap`` frames, row ``frame %
    cap`` (``cap > lag``). Frame ``t + i - lag`` is read off the best path
    once frame ``t + i`` is. Without ``whole`` it is decided then; with
    ``whole`` a gesture frame is held (``held[0]``: the first frame held, -1
    while none is) until a frame is read as rest, and the held frames are
    then decided together from the best path of that moment (or once ``cap``
    frames are held). The decided class indices go to ``out`` in frame order,
    and ``owner`` gets the row of ``lp`` that decided each. Returns the next
    ``t`` and the number of frames decided.
    """
    n_states = delta.shape[0]
    n_classes = first.shape[0]
    cap = ring.shape[0]
    new = np.empty(n_states)
    n = 0
    for i in range(lp.shape[0]):
        tau = t + i
        bp = ring[tau % cap]
        if tau == 0:
            for s in range(n_states):
                delta[s] = NEG
                bp[s] = s
            for k in range(n_classes):
                delta[first[k]] = lp[i, k] - (pen if k > 0 else 0.0)
        else:
            # the two best chain ends: where each class is entered from
            b1 = 0
            for k in range(1, n_classes):
                if delta[last[k]] > delta[last[b1]]:
                    b1 = k
            b2 = 1 if b1 == 0 else 0
            for k in range(n_classes):
                if k != b1 and delta[last[k]] > delta[last[b2]]:
                    b2 = k
            for s in range(n_states):
                new[s] = NEG
            for k in range(n_classes):
                f, e = first[k], last[k]
                src = b2 if k == b1 else b1
                entry = delta[last[src]] - (pen if k > 0 else 0.0)
                for s in range(f + 1, e + 1):  # advance along the chain
                    new[s] = delta[s - 1]
                    bp[s] = s - 1
                if f == e:  # one state: stay, or enter (ties stay)
                    if delta[e] >= entry:
                        new[e] = delta[e]
                        bp[e] = e
                    else:
                        new[e] = entry
                        bp[e] = last[src]
                else:
                    new[f] = entry
                    bp[f] = last[src]
                    if delta[e] > new[e]:  # the last state loops
                        new[e] = delta[e]
                        bp[e] = e
            for s in range(n_states):
                delta[s] = new[s] + lp[i, cls[s]]
        if tau < lag:
            continue
        top = 0  # the best state now (the first of equal ones)
        for q in range(1, n_states):
            if delta[q] > delta[top]:
                top = q
        s = top
        for back in range(lag):
            s = ring[(tau - back) % cap][s]
        v = cls[s]  # frame tau - lag on the best path of now
        if whole:
            h = held[0]
            if v != 0 and (h < 0 or tau - h + 1 < cap):
                if h < 0:
                    held[0] = tau - lag  # a gesture begins: hold its frames
                continue  # (or it goes on)
            if h >= 0:  # decide the held frames from the path of now
                stop = tau - lag + (0 if v == 0 else 1)
                s = top
                for x in range(tau, h, -1):
                    if x < stop:
                        out[n + x - h] = cls[s]
                    s = ring[x % cap][s]
                out[n] = cls[s]
                for x in range(stop - h):
                    owner[n + x] = i
                n += stop - h
                held[0] = -1
                if v != 0:  # MAX_HELD frames held: decided where it stands
                    continue
        out[n] = v
        owner[n] = i
        n += 1
    return t + lp.shape[0], n


def _trace_tail(delta, cls, ring, t, out):
    """Class indices of the last ``len(out)`` frames (``out``, oldest
    first), read off the best path ending at frame ``t - 1``."""
    m = out.shape[0]
    cap = ring.shape[0]
    s = 0
    for q in range(1, delta.shape[0]):
        if delta[q] > delta[s]:
            s = q
    for back in range(m):
        out[m - 1 - back] = cls[s]
        s = ring[(t - 1 - back) % cap][s]


@functools.cache
def _kernels():
    """``(_forward, _trace_tail)``, compiled by numba when it is installed.

    Compiled on first use, so importing the taggers does not import numba.
    """
    try:
        import numba
    except ImportError:  # pragma: no cover - the minimal install
        return _forward, _trace_tail
    jit = numba.njit(cache=True, nogil=True)
    return jit(_forward), jit(_trace_tail)


def chain_lengths(class_lengths, ratio):
    """Frames each class lasts at least: ``ceil(ratio * class_lengths)``, at
    least 1; rest (index 0) 1.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._viterbi import chain_lengths
    >>> chain_lengths(np.array([0.0, 10.0, 3.0]), 0.7).tolist()
    [1, 7, 3]
    """
    d = np.maximum(np.ceil(float(ratio) * np.asarray(class_lengths, float)), 1)
    d = d.astype(np.int64)
    d[0] = 1
    return d


def log_scores(proba, untracked=None):
    """Log probabilities of the path (clipped at ``FLOOR``); a gesture on an
    untracked frame is all but impossible."""
    lp = np.log(np.clip(np.asarray(proba, dtype=np.float64), FLOOR, None))
    if untracked is not None and np.any(untracked):
        lp[np.asarray(untracked, dtype=bool), 1:] = MASKED
    return np.ascontiguousarray(lp)


class ViterbiPath:
    """The duration-aware path, one block of frames at a time.

    Parameters
    ----------
    durations : ndarray of int of shape (n_classes,)
        Shortest run of every class, in frames (:func:`chain_lengths`); rest
        (index 0) first.
    penalty : float
        Log score of entering a gesture.
    lag : int
        Frames between a frame and its decision (its being read off the best
        path).
    decision : {"frame", "run"}, default="frame"
        ``"frame"``: every frame is decided ``lag`` frames after it.
        ``"run"``: a frame read as rest is decided then, but the frames of a
        gesture are held until a frame is read as rest again, and are then
        decided together from the best path of that moment, which has seen
        the whole gesture (at most ``MAX_HELD`` frames are held). A gesture's
        end is decided as soon as with ``"frame"``, and the frames before it
        are read with hindsight: its class does not change midway because the
        first frames looked like another gesture.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._viterbi import ViterbiPath, log_scores
    >>> p = np.tile([0.9, 0.1], (12, 1))
    >>> p[3:9] = [0.1, 0.9]  # frames 3-8: class 1
    >>> p[5] = [0.8, 0.2]  # one doubtful frame inside the gesture
    >>> ViterbiPath(np.array([1, 4]), penalty=2.0, lag=3).run(log_scores(p)).tolist()
    [0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0, 0]
    >>> p.argmax(axis=1).tolist()
    [0, 0, 0, 1, 1, 0, 1, 1, 1, 0, 0, 0]

    A gesture of class 2 whose first frames look a little more like class 1:

    >>> q = np.tile([0.9, 0.05, 0.05], (16, 1))
    >>> q[3:6] = [0.1, 0.5, 0.4]
    >>> q[6:13] = [0.05, 0.05, 0.9]
    >>> d = np.array([1, 3, 3])
    >>> ViterbiPath(d, 2.0, lag=1).run(log_scores(q)).tolist()
    [0, 0, 0, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 0, 0, 0]
    >>> ViterbiPath(d, 2.0, lag=1, decision="run").run(log_scores(q)).tolist()
    [0, 0, 0, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 0, 0, 0]
    """

    def __init__(self, durations, penalty, lag, decision="frame"):
        if decision not in DECISIONS:
            raise ValueError(f"decision must be one of {DECISIONS}, got {decision!r}")
        d = np.asarray(durations, dtype=np.int64)
        self.last = np.cumsum(d) - 1
        self.first = self.last - d + 1
        self.cls = np.repeat(np.arange(len(d), dtype=np.int64), d)
        self.penalty = float(penalty)
        self.lag = int(lag)
        self.whole = decision == "run"
        self.delta = np.full(len(self.cls), NEG)
        cap = max(MAX_HELD, self.lag + 2) if self.whole else self.lag + 1
        self.ring = np.zeros((cap, len(self.cls)), dtype=np.int64)
        self.held = np.full(1, -1, dtype=np.int64)  # first frame held, -1: none
        self.t = 0  # frames read
        self.decided = 0  # frames decided

    def feed(self, lp):
        """Log scores of the next frames in; the class indices of the frames
        decided by them out (in frame order, from the first not yet
        decided)."""
        return self.feed_owned(lp)[0]

    def feed_owned(self, lp):
        """:meth:`feed`, and for every frame decided, the row of ``lp`` whose
        arrival decided it (``lag`` rows later; with ``decision="run"``, a
        gesture's frames all by the row that ends it)."""
        lp = np.ascontiguousarray(lp, dtype=np.float64)
        # at most every frame not yet decided: the held ones and these
        out = np.empty(self.t - self.decided + len(lp), dtype=np.int64)
        owner = np.empty(len(out), dtype=np.int64)
        self.t, n = _kernels()[0](
            self.delta, lp, self.first, self.last, self.cls, self.penalty,
            self.lag, self.whole, self.held, self.ring, self.t, out, owner,
        )  # fmt: skip
        self.decided += n
        return out[:n], owner[:n]

    def finish(self):
        """The class indices of the frames not yet decided (the sequence ends)."""
        out = np.empty(self.t - self.decided, dtype=np.int64)
        if len(out):
            _kernels()[1](self.delta, self.cls, self.ring, self.t, out)
        self.decided = self.t
        self.held[0] = -1
        return out

    def run(self, lp):
        """Class indices of a whole sequence (``feed`` then ``finish``)."""
        return np.concatenate([self.feed(lp), self.finish()])
