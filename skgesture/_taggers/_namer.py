"""The run namer: a bidirectional network that names each gesture run once it
has ended.

A tagger whose look-ahead is bounded (the recommended model's causal TCN,
``lookahead=8``) labels a frame from the frames up to a few after it. Two
gestures that differ only in how they end (Montalbano's classes 14 and 15,
the paper's most confused pair) are then told apart only at their end, and
the first frames of the run carry the wrong name. Once a run has ended,
though, all of its frames are known: :class:`SequenceTagger` with
``namer="gru"`` trains a small bidirectional GRU on the training gestures
alone (each gesture, and copies of it with jittered ends, all its frames
labelled with its class), and the decoding names every run by the weighted
sum of the log mean probabilities of the tagger and of this namer read over
the run's own rows (``namer_weight``, :func:`name_run`). The rule judges a run
once it has ended, like the other run rules, so the model still streams
exactly (docs/design.md, "The run namer").
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture.utils._segments import runs

NAMER_COPIES = 4  # training windows per gesture: itself and 3 with jittered ends
NAMER_JITTER = 0.1  # sd of a jittered end, as a fraction of the gesture's length
NAMER_REST = 0.25  # rest windows per gesture window (the rest class of the namer)
NAMER_NEGATIVES = 0.25  # more rest windows per gesture window, from namer_only data
MIN_REST = 4  # shortest rest run that rest windows are drawn from, in frames
NAMER_HIDDEN = (64,)  # SequenceTagger's default namer_hidden_sizes
# The namer's own training: short windows, larger batches, half the tagger's
# epochs (its steps per epoch; 300 steps for the recommended model's 600).
NAMER_TRAINING = {
    "crop_length": 64,
    "batch_size": 32,
    "learning_rate": 3e-3,
    "dropout": 0.2,
    "packed": True,  # trained on each window as it reads a run: no padding
}
TINY = 1e-9  # floor of a mean probability before its log


def gesture_windows(X, y_idx, seed, copies=NAMER_COPIES, jitter=NAMER_JITTER):
    """The namer's training data: the rows of every gesture of ``X``.

    Every run of a gesture class in ``y_idx`` (class indices; 0 rest,
    ``IGNORE_INDEX`` untracked) gives ``copies`` windows: the run itself and
    ``copies - 1`` with both ends moved by a Gaussian of ``jitter`` times its
    length (a decoded run's ends are never exactly the true ones), each
    labelled with the run's class on every tracked row.

    Parameters
    ----------
    X : list of ndarray of shape (n_frames_i, n_features)
        Feature rows.
    y_idx : list of ndarray of shape (n_frames_i,)
        Class index of every row.
    seed : int
        Seed of the jitter.
    copies : int, default=4
    jitter : float, default=0.1

    Returns
    -------
    windows : list of ndarray
    labels : list of ndarray of int64

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._namer import gesture_windows
    >>> X = [np.zeros((10, 2), np.float32)]
    >>> y = [np.array([0, 0, 2, 2, 2, 2, 0, 0, 0, 0])]
    >>> W, Y = gesture_windows(X, y, 0, copies=1)
    >>> [w.shape for w in W], Y[0].tolist()
    ([(4, 2)], [2, 2, 2, 2])
    """
    # (imported here: the decoding, which imports this module, needs no torch)
    from skgesture._nn._training import IGNORE_INDEX

    rng = np.random.default_rng(seed)
    windows, labels = [], []
    for x, y in zip(X, y_idx):
        y = np.asarray(y)
        starts, ends, values = runs(y)
        for s, e, v in zip(starts.tolist(), ends.tolist(), values.tolist()):
            if v <= 0:  # rest, or untracked rows
                continue
            n = e - s
            for copy in range(copies):
                a, b = s, e
                if copy:
                    da, db = np.rint(rng.normal(0.0, jitter * n, 2)).astype(int)
                    a, b = max(0, s + int(da)), min(len(y), e + int(db))
                if b - a < 2:
                    continue
                windows.append(x[a:b])
                labels.append(np.where(y[a:b] == IGNORE_INDEX, IGNORE_INDEX, v))
    return windows, labels


def rest_windows(X, y_idx, lengths, n_windows, seed):
    """The namer's rest windows: ``n_windows`` windows of rest rows of ``X``.

    The namer that only ever saw gestures names every run as some gesture;
    trained also on rest (the training sequences' rest, and all of any
    background recording given to ``fit``), it gives a run of motion that is
    no gesture a high probability of rest, which ``max_namer_rest`` reads.
    Each window lies in one run of rest (of at least ``MIN_REST`` rows),
    drawn with a probability proportional to its length; its length is one
    of ``lengths`` (the training gestures'), drawn at random, capped at the
    run's; every row is labelled rest (0).

    Parameters
    ----------
    X : list of ndarray of shape (n_frames_i, n_features)
    y_idx : list of ndarray of shape (n_frames_i,)
        Class index of every row (0 rest).
    lengths : array-like of int
        Lengths to draw from (none: no window).
    n_windows : int
    seed : int

    Returns
    -------
    windows : list of ndarray
    labels : list of ndarray of int64

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._namer import rest_windows
    >>> X = [np.arange(12.0)[:, None]]
    >>> y = [np.array([0] * 8 + [1] * 4)]
    >>> W, Y = rest_windows(X, y, [3], 2, 0)
    >>> [len(w) for w in W], int(max(w.max() for w in W)) < 8, Y[0].tolist()
    ([3, 3], True, [0, 0, 0])
    """
    lengths = np.asarray(lengths, dtype=np.int64)
    spans = [
        (i, s, e)
        for i, y in enumerate(y_idx)
        for s, e, v in zip(*(a.tolist() for a in runs(np.asarray(y))))
        if v == 0 and e - s >= MIN_REST
    ]
    if not spans or not len(lengths) or n_windows <= 0:
        return [], []
    rng = np.random.default_rng(seed)
    sizes = np.array([e - s for _, s, e in spans], dtype=float)
    picks = rng.choice(len(spans), size=int(n_windows), p=sizes / sizes.sum())
    windows, labels = [], []
    for pick in picks.tolist():
        i, s, e = spans[pick]
        n = int(min(rng.choice(lengths), e - s))
        a = s + int(rng.integers(0, e - s - n + 1))
        windows.append(X[i][a : a + n])
        labels.append(np.zeros(n, dtype=np.int64))
    return windows, labels


def strided(windows, labels, stride, seed):
    """Every ``stride``-th row of each training window, from a random first
    row (its phase), as the namer reads a run with ``namer_stride``
    (:func:`namer_batch` reads a run from its first row; the random phases
    of training are an augmentation).

    Parameters
    ----------
    windows : list of ndarray
    labels : list of ndarray
    stride : int
        1 returns the windows unchanged.
    seed : int
        Seed of the phases.

    Returns
    -------
    windows : list of ndarray
    labels : list of ndarray

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._namer import strided
    >>> W, Y = strided([np.arange(7.0)[:, None]], [np.ones(7, int)], 2, 0)
    >>> W[0].ravel().tolist(), Y[0].tolist()  # the phase drawn: 1
    ([1.0, 3.0, 5.0], [1, 1, 1])
    """
    if stride == 1:
        return windows, labels
    rng = np.random.default_rng(seed)
    phases = rng.integers(0, stride, size=len(windows))
    pairs = [
        (w[p::stride], y[p::stride]) if len(w) > p else (w[:1], y[:1])
        for w, y, p in zip(windows, labels, phases.tolist())
    ]
    return [w for w, _ in pairs], [y for _, y in pairs]


def name_run(raw, namer_scores, weight):
    """Column of the name of one run: the gesture column with the highest
    ``(1 - weight) * log(mean raw probability) + weight * namer_scores``
    (rest, column 0, is never a name: the ``max_namer_rest`` rule of
    :func:`~skgesture._taggers._decoding.reject_runs` reads the namer's rest).

    Parameters
    ----------
    raw : ndarray of shape (n_rows, n_classes)
        The tagger's raw probabilities of the run's rows (rest first).
    namer_scores : ndarray of shape (n_classes,)
        The namer's log mean probabilities of the run (:func:`namer_scores`).
    weight : float
        Weight of the namer, in [0, 1] (0: the tagger's mean alone).

    Returns
    -------
    int
        A column of ``raw``, never 0 (rest).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._taggers._namer import name_run
    >>> raw = np.array([[0.1, 0.6, 0.3], [0.1, 0.5, 0.4]])
    >>> namer = np.log([0.01, 0.2, 0.79])
    >>> name_run(raw, namer, 0.0), name_run(raw, namer, 0.5)
    (1, 2)
    """
    score = (1.0 - weight) * np.log(raw.mean(axis=0) + TINY) + weight * namer_scores
    score = np.array(score, dtype=np.float64)
    score[0] = -np.inf
    return int(np.argmax(score))


def namer_scores(module, mean, scale, rows, n_classes, stride=1):
    """The namer's log mean probabilities over ``rows`` (one run): the
    :func:`namer_batch` of one run, as a stream computes it when the run ends.

    Parameters
    ----------
    module : RecurrentTaggerModule
        The namer's network (``SequenceTagger.namer_.module_``).
    mean, scale : ndarray of shape (n_features,)
        Its standardisation.
    rows : ndarray of shape (n_rows, n_features)
        The run's feature rows.
    n_classes : int
    stride : int, default=1
        The namer reads every ``stride``-th row from the run's first
        (``namer_stride_``; rows ``0, stride, 2 * stride, ...``), and the
        mean is over the rows it read.

    Returns
    -------
    ndarray of shape (n_classes,)
    """
    return namer_batch(module, mean, scale, [rows], n_classes, stride)[0]


def namer_batch(module, mean, scale, windows, n_classes, stride=1):
    """:func:`namer_scores` of several runs in one packed forward pass.

    Offline, every run of a ``predict`` call is named in one pass (3 times
    faster than one call a run); the scores equal those of one run at a time
    to float32 rounding (about 1e-6 in log probability).

    Returns
    -------
    ndarray of shape (n_windows, n_classes)
    """
    import torch
    from torch.nn.utils.rnn import PackedSequence

    if not windows:
        return np.zeros((0, n_classes))
    windows = [w[::stride] for w in windows]  # (stride 1: the rows themselves)
    lengths = np.array([len(w) for w in windows])
    # Packed layout built directly (no padded copy): windows sorted longest
    # first; row t of the window ranked r sits at ``first[t] + r``.
    order = np.argsort(-lengths, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    batch_sizes = len(lengths) - np.cumsum(np.bincount(lengths))[:-1]  # longer than t
    first = np.concatenate([[0], np.cumsum(batch_sizes)[:-1]])
    where = np.concatenate([first[:n] + r for n, r in zip(lengths, rank)])
    packed = np.empty((len(where), len(mean)), dtype=np.float32)
    packed[where] = np.concatenate(windows)
    packed -= np.asarray(mean, dtype=np.float32)  # standardised in place
    packed /= np.asarray(scale, dtype=np.float32)
    module.eval()
    with torch.inference_mode():
        out = module.recurrent(
            PackedSequence(torch.from_numpy(packed), torch.from_numpy(batch_sizes))
        )
        proba = torch.softmax(module.head(out.data), dim=-1).numpy()
    sums = np.add.reduceat(
        proba[where].astype(np.float64), np.cumsum(lengths) - lengths
    )
    return np.log(sums / lengths[:, None] + TINY)


def namer_of(rows, score):
    """The ``namer(start, end)`` of :func:`~skgesture._taggers._decoding.reject_runs`:
    ``score(rows[start:end])``, the same call offline (the sequence's rows)
    and live (a stream's rows of the stretch being decided)."""
    return lambda s, e: score(rows[s:e])
