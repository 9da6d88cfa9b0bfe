"""Background sequences (all rest) made from gesture recordings.

:func:`make_background` turns the recordings a model is trained on into
negatives for ``fit``: random joint motion around a rest pose, time-reversed
gestures, fragments of gestures and concatenations of gesture parts, each
labelled 0. A made motion that resembles a gesture of the vocabulary is left
out, so the negatives never teach the model to reject its own gestures
(docs/streaming.md, "Background recordings").
"""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
from scipy.ndimage import gaussian_filter1d
from sklearn.base import BaseEstimator
from sklearn.utils import Bunch, check_random_state

from skgesture.datasets._synthetic import _check_int, _check_real
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._segments import labels_to_segments
from skgesture.utils._validation import (
    check_sequence_labels,
    check_sequences,
    missing_frames,
    untracked_rows,
)

__all__ = ["SyntheticBackground", "make_background"]


BACKGROUND_KINDS = ("motion", "reversed", "fragment", "concatenation")
MIN_BACKGROUND_GESTURES = 4  # n_frames=None: at least this many median gestures long
CONTEXT_RANGE = (0.25, 1.0)  # rest frames kept around a piece, x median gesture
MOTION_LEN_RANGE = (1.0, 3.0)  # a random motion lasts this many median gestures
MOTION_SIGMA = 1 / 8  # its time scale (Gaussian filter sigma), x median gesture
MOTION_RAMP = 0.25  # share of the motion spent fading in and out
FRAGMENT_RANGE = (0.25, 0.5)  # a fragment's length, x the shortest gesture
HEAD_TAIL_RANGE = (0.3, 0.7)  # share of each gesture a concatenation takes
N_TEMPLATE_FRAMES = 24  # gestures are compared resampled to this many frames
MAX_TEMPLATES_PER_CLASS = 50  # instances per class used for the class spread
N_CONCAT_TRIES = 10  # draws of a concatenation before falling back to a fragment


def _resample(x, n):
    """``x`` (n_frames, n_features) linearly resampled to ``n`` frames."""
    src = np.linspace(0.0, len(x) - 1, n)
    grid = np.arange(len(x))
    return np.stack([np.interp(src, grid, col) for col in x.T], axis=1)


def _template(x):
    """A gesture as compared by the vocabulary check: resampled, time-mean free."""
    t = _resample(x, N_TEMPLATE_FRAMES)
    return (t - t.mean(axis=0)).ravel()


class _Vocabulary:
    """The training gestures, to tell whether a made motion looks like one.

    A candidate is refused when it is as close to a gesture instance of class
    ``c`` as the instances of ``c`` are to one another (the median distance
    between them, the class's spread): a reversed wave is a wave, a reversed
    "swipe left" may be a "swipe right".
    """

    def __init__(self, pieces, rng):
        classes = np.array([c for c, _ in pieces])
        self.templates = np.stack([_template(x) for _, x in pieces])
        self.classes = classes
        spread = {}
        for c in np.unique(classes):
            idx = np.flatnonzero(classes == c)
            if len(idx) > MAX_TEMPLATES_PER_CLASS:
                idx = rng.choice(idx, MAX_TEMPLATES_PER_CLASS, replace=False)
            if len(idx) >= 2:
                t = self.templates[idx]
                d = np.linalg.norm(t[:, None] - t[None], axis=-1)
                spread[c] = float(np.median(d[np.triu_indices(len(idx), 1)]))
        if spread:
            fallback = float(np.median(list(spread.values())))
        elif len(classes) >= 2:  # one instance per class: half their distance
            t = self.templates
            d = np.linalg.norm(t[:, None] - t[None], axis=-1)
            fallback = 0.5 * float(np.median(d[np.triu_indices(len(t), 1)]))
        else:
            fallback = 0.0
        self.spread = np.array([spread.get(c, fallback) for c in classes])

    def resembles(self, x):
        d = np.linalg.norm(self.templates - _template(x), axis=1)
        return bool(np.any(d <= self.spread))


def _n_background(n_sequences, n_recordings):
    """The number of sequences ``n_sequences`` asks for: an int as it is, a
    float in (0, 1) as that share of ``n_recordings`` (at least one)."""
    if isinstance(n_sequences, Real) and not isinstance(n_sequences, (bool, Integral)):
        share = float(n_sequences)
        if not 0.0 < share < 1.0:
            raise ValueError(
                f"n_sequences must be an int >= 1 or a share of the recordings "
                f"in (0, 1), got {n_sequences!r}"
            )
        return max(1, int(round(share * n_recordings)))
    return _check_int(n_sequences, "n_sequences", 1)


def _check_kinds(kinds):
    if kinds is None:
        return None
    if isinstance(kinds, str):
        kinds = (kinds,)
    try:
        kinds = tuple(kinds)
    except TypeError:
        raise ValueError(
            f"kinds must be a sequence of {BACKGROUND_KINDS} or None, got {kinds!r}"
        ) from None
    if not kinds:
        raise ValueError(f"kinds is empty: give some of {BACKGROUND_KINDS} or None")
    for kind in kinds:
        if kind not in BACKGROUND_KINDS:
            raise ValueError(
                f"unknown background kind {kind!r}; the kinds are {BACKGROUND_KINDS}"
            )
    return tuple(dict.fromkeys(kinds))


class _Recording:
    """One recording, flattened, with what the background pieces need."""

    def __init__(self, x, y, tracked):
        self.x, self.y, self.tracked = x, y, tracked
        rest = tracked & (y == 0)
        self.poses = np.flatnonzero(rest) if rest.any() else np.flatnonzero(tracked)
        self.rest = rest
        # gestures fully tracked and at least 2 frames long
        self.gestures = [
            (int(c), int(s), int(e))
            for c, s, e in labels_to_segments(y)
            if e - s >= 2 and tracked[s:e].all()
        ]
        self.reversible = []  # set by make_background (needs the vocabulary)

    def context(self, i, m, direction):
        """Up to ``m`` tracked rest frames next to frame ``i`` (before it with
        ``direction=-1``, after it with ``+1``), contiguous, as a slice."""
        if direction < 0:
            lo = i
            while lo > 0 and i - lo < m and self.rest[lo - 1]:
                lo -= 1
            return slice(lo, i)
        hi = i
        while hi < len(self.y) and hi - i < m and self.rest[hi]:
            hi += 1
        return slice(i, hi)


def _ease(a, b, n):
    """``n`` frames going smoothly from ``a`` to ``b``, both ends excluded."""
    w = 0.5 - 0.5 * np.cos(np.pi * np.arange(1, n + 1) / (n + 1))
    return a + w[:, None] * (b - a)


def _overlap(k, n_before, part):
    """Frames a join cross-fades: ``k``, fewer if a side is shorter (a part
    always adds at least one frame)."""
    return max(0, min(k, n_before, len(part) - 1))


def _join(parts, k):
    """Concatenate pieces, cross-fading ``k`` frames at every join."""
    out = parts[0]
    for part in parts[1:]:
        n = _overlap(k, len(out), part)
        if n == 0:
            out = np.concatenate([out, part])
            continue
        w = ((np.arange(n) + 1) / (n + 1))[:, None]
        fade = (1 - w) * out[len(out) - n :] + w * part[:n]
        out = np.concatenate([out[: len(out) - n], fade, part[n:]])
    return out


def make_background(
    X,
    y,
    *,
    n_sequences=10,
    n_frames=None,
    kinds=None,
    motion_scale=0.5,
    random_state=None,
):
    """Make background sequences (all rest) from gesture recordings.

    Synthetic negatives for ``fit``: motions that are not a gesture of the
    vocabulary, labelled 0 (rest), so that a model learns not to fire on them.
    Each sequence is made from one recording drawn at random (its body,
    placement and sensor), as a chain of pieces of the kinds that recording
    can give, joined by its own rest frames:

    * ``"motion"``: random joint motion around a rest pose: every coordinate
      moves along its own smooth random track (time scale: a median gesture's
      length / 8; one to three gestures long, fading in and out), by
      ``motion_scale`` times as much as it moves during the gestures;
    * ``"reversed"``: a gesture played backwards, with its rest before and
      after, unless it looks like a gesture of the vocabulary (see Notes);
    * ``"fragment"``: the start of a gesture that goes back to rest, or the
      end of one entered from rest, the whole motion shorter than the
      shortest gesture of ``y``;
    * ``"concatenation"``: the first part of a gesture joined to the last part
      of a gesture of another class of the recording, unless the result looks
      like a gesture of the vocabulary.

    Parameters
    ----------
    X : list of array-like of shape (n_frames_i, ...)
        The recordings, e.g. the training skeletons ``(n_frames_i, 20, 3)``.
        Untracked frames (all zeros, NaN, or masked rows of a
        ``numpy.ma.MaskedArray``) are never used.
    y : list of array-like of shape (n_frames_i,)
        Their per-frame labels, 0 = rest; at least one gesture.
    n_sequences : int or float, default=10
        Number of sequences made. A float in (0, 1) is a share of the
        recordings: ``round(n_sequences * len(X))`` sequences, at least one,
        so that the negatives are the same share of the training sequences
        (and of the crops a tagger draws from them) whatever the data size.
    n_frames : int or None, default=None
        Length of every sequence; None: the median length of the recordings,
        at least four median gestures.
    kinds : sequence of str or None, default=None
        The kinds of piece drawn (uniformly), among ``"motion"``,
        ``"reversed"``, ``"fragment"`` and ``"concatenation"``. None: every
        kind the recordings can give.
    motion_scale : float, default=0.5
        Amplitude of the random joint motion, relative to how much every
        coordinate moves during the gestures of ``y`` (its standard deviation
        there); in (0, 10]. Motion as large as the gestures (1.0) starts to
        pass through their poses, which teaches the model to doubt them.
    random_state : int, RandomState instance or None, default=None
        Controls every draw. Pass an int for reproducible output.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with the keys of the loaders that apply:

        X : list of ndarray of shape (n_frames, ...)
            The sequences, float64, frames shaped as those of ``X``.
        y : list of ndarray of shape (n_frames,)
            All zeros (rest), int64.
        segments : list of ndarray of shape (0, 3)
            No gesture, int64.
        missing : list of ndarray of shape (n_frames,)
            All False: only tracked frames are used.
        n_frames : ndarray of shape (n_sequences,)
            Length of every sequence.
        sources : ndarray of shape (n_sequences,)
            Index in ``X`` of the recording each sequence is made from.
        pieces : list of list of tuple
            ``(kind, start, end)`` of every piece of every sequence, rest
            context included (joins overlap by a few frames).
        DESCR : str
            Description of the data.

    Raises
    ------
    ValueError
        If a parameter is out of range, ``y`` has no gesture, or a kind asked
        for cannot be made from the recordings (e.g. ``"concatenation"`` when
        no recording has gestures of two classes).

    See Also
    --------
    make_gesture_streams : Synthetic gesture streams.
    skgesture.SequenceTagger : Learns background sequences as rest.

    Notes
    -----
    Add the sequences to the training data with their all-zero labels
    (``model.fit(X + bg.X, y + bg.y)``): the taggers and the
    :class:`~skgesture.ActivitySegmenter` learn them as rest
    (docs/streaming.md, "Background recordings"). They complement real
    background recordings of ordinary work, and do not replace them.

    A made motion that resembles a gesture would teach the model to reject
    that gesture. A reversed gesture or a concatenation is therefore compared
    with every gesture instance of ``y`` (all resampled to 24 frames, their
    mean over time removed): it is refused when it is as close to an instance
    of class ``c`` as the instances of ``c`` are to each other (their median
    distance). A wave, its own reversal, never becomes a negative. Fragments
    are shorter than any gesture, so they are not compared.

    In a cross-validation, make the background of each training fold from
    that fold's recordings only (``sources`` says which recording each
    sequence comes from): a sequence made from a test subject's gestures
    would leak them into training.

    Examples
    --------
    >>> from skgesture.datasets import make_background, make_gesture_streams
    >>> data = make_gesture_streams(n_sequences=4, n_classes=5, random_state=0)
    >>> bg = make_background(data.X, data.y, n_sequences=3, random_state=0)
    >>> len(bg.X), bg.X[0].shape[1:], all((lab == 0).all() for lab in bg.y)
    (3, (20, 3), True)
    >>> sorted({kind for p in bg.pieces for kind, _, _ in p})
    ['concatenation', 'fragment', 'motion', 'reversed']
    >>> X_train, y_train = data.X + bg.X, data.y + bg.y
    """
    masked = (
        [isinstance(x, np.ma.MaskedArray) and untracked_rows(x) for x in X]
        if isinstance(X, (list, tuple))
        else []
    )  # the masks, which check_sequences drops
    X = check_sequences(X, allow_nan=True)
    y = check_sequence_labels(y, X)
    frame_shape = X[0].shape[1:]
    for i, x in enumerate(X):
        if x.shape[1:] != frame_shape:
            raise ValueError(
                f"X[{i}] has frames of shape {x.shape[1:]}, but X[0] has "
                f"{frame_shape}: all recordings must agree"
            )
    n_sequences = _n_background(n_sequences, len(X))
    if n_frames is not None:
        n_frames = _check_int(n_frames, "n_frames", 2)
    kinds = _check_kinds(kinds)
    motion_scale = _check_real(motion_scale, "motion_scale", 0.0, 10.0, low_open=True)
    rng = check_random_state(random_state)

    recs = [
        _Recording(x.reshape(len(x), -1), lab, ~(missing_frames(x) | rows))
        for x, lab, rows in zip(X, y, masked or [False] * len(X))
    ]
    all_gestures = [labels_to_segments(lab) for lab in y]
    lengths = np.concatenate([s[:, 2] - s[:, 1] for s in all_gestures])
    if lengths.size == 0:
        raise ValueError(
            "y has no gesture (every label is 0): the background is made from "
            "the gestures of the recordings and their rest"
        )
    median_len = float(np.median(lengths))
    shortest = int(lengths.min())

    # how much every coordinate moves in the gestures, and the sensor jitter
    dev, jit = [], []
    for r in recs:
        if not r.tracked.any():
            continue
        centre = r.x[r.tracked].mean(axis=0)
        g = r.tracked & (r.y > 0)
        dev.append(r.x[g] - centre)
        d2 = r.x[2:] - 2 * r.x[1:-1] + r.x[:-2]
        ok = r.rest[2:] & r.rest[1:-1] & r.rest[:-2]
        jit.append(d2[ok])
    dev = np.concatenate(dev) if dev else np.zeros((0, recs[0].x.shape[1]))
    if not len(dev):
        raise ValueError(
            "y has no tracked gesture frame: the background is made from the "
            "gestures of the recordings"
        )
    amplitude = motion_scale * np.sqrt((dev**2).mean(axis=0))
    jit = np.concatenate(jit)
    jitter = np.sqrt((jit**2).mean(axis=0) / 6) if len(jit) else 0 * amplitude

    instances = [(c, r.x[s:e]) for r in recs for c, s, e in r.gestures]
    vocab = _Vocabulary(instances, rng) if instances else None
    for r in recs:
        r.reversible = [
            (c, s, e) for c, s, e in r.gestures if not vocab.resembles(r.x[s:e][::-1])
        ]

    def can(r, kind):
        if kind == "motion":
            return len(r.poses) > 0
        if kind == "reversed":
            return bool(r.reversible)
        if kind == "fragment":
            return bool(r.gestures)
        return len({c for c, _, _ in r.gestures}) >= 2

    reasons = {
        "motion": "no recording has a tracked frame",
        "reversed": "every reversed gesture resembles a gesture of the vocabulary "
        "(or no gesture is fully tracked)",
        "fragment": "no gesture is fully tracked",
        "concatenation": "no recording has fully tracked gestures of two classes",
    }
    asked = kinds
    if kinds is None:
        kinds = tuple(k for k in BACKGROUND_KINDS if any(can(r, k) for r in recs))
    for kind in kinds:
        if not any(can(r, kind) for r in recs):
            raise ValueError(
                f"kinds includes {kind!r}, which these recordings cannot give: "
                f"{reasons[kind]}"
            )
    # every recording that gives a kind is a source; each gives the kinds it can
    usable = [i for i, r in enumerate(recs) if any(can(r, k) for k in kinds)]
    if n_frames is None:
        n_frames = max(
            int(np.median([len(r.y) for r in recs])),
            int(round(MIN_BACKGROUND_GESTURES * median_len)),
            2,
        )
    join = max(1, int(round(median_len / 10)))
    ctx_lo, ctx_hi = (max(0, int(round(f * median_len))) for f in CONTEXT_RANGE)
    frag_lo, frag_hi = (max(1, int(f * shortest)) for f in FRAGMENT_RANGE)

    def context(r, i, direction):
        return r.context(i, rng.randint(ctx_lo, ctx_hi + 1), direction)

    def motion(r):
        p = int(r.poses[rng.randint(len(r.poses))])
        n = max(2, int(round(rng.uniform(*MOTION_LEN_RANGE) * median_len)))
        sigma = max(1.0, MOTION_SIGMA * median_len)
        pad = int(4 * sigma) + 1
        noise = gaussian_filter1d(
            rng.standard_normal((n + 2 * pad, len(amplitude))), sigma, axis=0
        )[pad : pad + n]
        noise /= (2 * np.sqrt(np.pi) * sigma) ** -0.5  # unit variance
        ramp = max(1, int(MOTION_RAMP * n))
        rise = 0.5 - 0.5 * np.cos(np.pi * np.arange(ramp) / ramp)  # from 0
        env = np.ones(n)
        env[:ramp], env[n - ramp :] = rise, rise[::-1]
        core = r.x[p] + env[:, None] * amplitude * noise
        core = core + rng.standard_normal(core.shape) * jitter
        before, after = context(r, p, -1), context(r, p + 1, +1)
        return np.concatenate([r.x[before], core, r.x[after]])

    def reversed_(r):
        _, s, e = r.reversible[rng.randint(len(r.reversible))]
        lo, hi = context(r, s, -1).start, context(r, e, +1).stop
        return r.x[lo:hi][::-1]

    def fragment(r):
        _, s, e = r.gestures[rng.randint(len(r.gestures))]
        f = min(rng.randint(frag_lo, frag_hi + 1), e - s)
        if rng.rand() < 0.5:  # a start that goes back to rest
            part = r.x[context(r, s, -1).start : s + f]
            return np.concatenate([part, part[::-1]])
        part = r.x[e - f : context(r, e, +1).stop]  # an end entered from rest
        return np.concatenate([part[::-1], part])

    def concatenation(r):
        for _ in range(N_CONCAT_TRIES):
            i, j = rng.choice(len(r.gestures), 2, replace=False)
            (c1, s1, e1), (c2, s2, e2) = r.gestures[i], r.gestures[j]
            if c1 == c2:
                continue
            a = max(1, int(round(rng.uniform(*HEAD_TAIL_RANGE) * (e1 - s1))))
            b = max(1, int(round(rng.uniform(*HEAD_TAIL_RANGE) * (e2 - s2))))
            head, tail = r.x[s1 : s1 + a], r.x[e2 - b : e2]
            seam = _ease(head[-1], tail[0], max(2, int(round(median_len / 6))))
            core = np.concatenate([head, seam, tail])
            if vocab.resembles(core):
                continue
            before, after = context(r, s1, -1), context(r, e2, +1)
            return np.concatenate([r.x[before], core, r.x[after]])
        return None

    makers = {
        "motion": motion,
        "reversed": reversed_,
        "fragment": fragment,
        "concatenation": concatenation,
    }
    out_X, pieces, sources = [], [], []
    for _ in range(n_sequences):
        src = usable[rng.randint(len(usable))]
        r = recs[src]
        own = [k for k in kinds if can(r, k)]
        parts, spans, length = [], [], 0
        while length < n_frames:
            kind = own[rng.randint(len(own))]
            part = makers[kind](r)
            if part is None:  # no concatenation unlike a gesture: a fragment
                kind, part = "fragment", fragment(r)
            start = length - _overlap(join, length, part)
            parts.append(part)
            length = start + len(part)
            spans.append((kind, int(start), int(min(length, n_frames))))
        seq = _join(parts, join)[:n_frames]
        out_X.append(seq.reshape((n_frames,) + frame_shape))
        pieces.append([s for s in spans if s[1] < n_frames])
        sources.append(src)
    descr = _BACKGROUND_DESCR.format(
        n_sequences=n_sequences,
        n_frames=n_frames,
        n_recordings=len(X),
        motion_scale=motion_scale,
        kinds=", ".join(kinds),
        asked="" if asked is not None else " (every kind the recordings give)",
    )
    return Bunch(
        X=out_X,
        y=[np.zeros(n_frames, dtype=np.int64) for _ in out_X],
        segments=[np.zeros((0, 3), dtype=np.int64) for _ in out_X],
        missing=[np.zeros(n_frames, dtype=bool) for _ in out_X],
        n_frames=np.full(n_sequences, n_frames, dtype=np.int64),
        sources=np.array(sources, dtype=np.int64),
        pieces=pieces,
        DESCR=descr,
    )


_BACKGROUND_DESCR = """\
Synthetic background sequences
==============================

{n_sequences} sequences of {n_frames} frames, all rest (label 0), made from
{n_recordings} recordings: chains of {kinds}{asked}, each
sequence from one recording and joined by its rest frames. Random joint motion
moves every coordinate {motion_scale:g} times as much as in the gestures;
reversed gestures and concatenations that resemble a gesture of the
recordings are left out.
"""


# sequences a SyntheticBackground makes by default: make_recommended's
# (docs/benchmarks.md, "Synthetic negatives by their cost")
BACKGROUND_SEQUENCES = 24


class SyntheticBackground(NewParamsMixin, BaseEstimator):
    """Background sequences made in ``fit``, from the training recordings.

    The parameters of :func:`make_background`, as an object a
    :class:`~skgesture.GesturePipeline` takes (``background=``): each ``fit``
    makes the sequences from the recordings it is given and adds them, all
    rest, to its training data. In a cross-validation or a grid search the
    negatives of every training fold are thus made from that fold only (no
    test gesture leaks into them), and their parameters can be searched
    (``background__motion_scale``), or the background switched off
    (``background=None``).

    Parameters
    ----------
    n_sequences : int or float, default=24
        Sequences made at every ``fit``; a float in (0, 1) is that share of
        the recordings ``fit`` is given (see :func:`make_background`).
    n_frames : int or None, default=None
        Length of every sequence (see :func:`make_background`).
    kinds : sequence of str or None, default=None
        The kinds of piece (see :func:`make_background`); None: all.
    motion_scale : float, default=0.5
        Amplitude of the random joint motion (see :func:`make_background`).
    random_state : int, RandomState instance or None, default=None
        Controls every draw. Pass an int for the same sequences at every fit
        on the same data.

    See Also
    --------
    make_background : The function it calls.

    Examples
    --------
    >>> from skgesture.datasets import SyntheticBackground, make_gesture_streams
    >>> data = make_gesture_streams(n_sequences=4, n_classes=5, random_state=0)
    >>> bg = SyntheticBackground(n_sequences=3, random_state=0).make(data.X, data.y)
    >>> len(bg.X), all((lab == 0).all() for lab in bg.y)
    (3, True)
    """

    def __init__(
        self,
        n_sequences=BACKGROUND_SEQUENCES,
        *,
        n_frames=None,
        kinds=None,
        motion_scale=0.5,
        random_state=None,
    ):
        self.n_sequences = n_sequences
        self.n_frames = n_frames
        self.kinds = kinds
        self.motion_scale = motion_scale
        self.random_state = random_state

    def make(self, X, y):
        """The background sequences of the recordings ``X``, ``y``.

        Parameters
        ----------
        X : list of array-like of shape (n_frames_i, ...)
            The training recordings.
        y : list of array-like of shape (n_frames_i,)
            Their per-frame labels, 0 = rest; at least one gesture.

        Returns
        -------
        :class:`~sklearn.utils.Bunch`
            As :func:`make_background` returns it (``X``, ``y`` all zeros, ...).
        """
        return make_background(
            X,
            y,
            n_sequences=self.n_sequences,
            n_frames=self.n_frames,
            kinds=self.kinds,
            motion_scale=self.motion_scale,
            random_state=self.random_state,
        )
