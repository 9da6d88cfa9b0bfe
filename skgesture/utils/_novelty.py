"""How far a run's poses are from the training poses of its class.

A network trained on gesture recordings alone has never seen a person walk,
sit down or pick something up, and names such motion with a confident
gesture label (docs/safety.md). Its softmax cannot say "none of these", but
the features can: :class:`PoseNovelty` keeps, for every gesture class, a bank
of that class's training frames (standardised, projected on their principal
components) and scores each frame by its distance to the nearest frame of
each bank, in units of the distance at which the training runs of that class
lie from the other training sequences' frames. A run of class ``c`` whose
median score is above ``max_novelty`` is rest
(:func:`skgesture._taggers._decoding.reject_runs`). Every score is a frame's
own (no context), so a stream computes them frame by frame, exactly as
offline.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture.utils._segments import labels_to_segments
from skgesture.utils._validation import check_sequence_labels, check_sequences

N_COMPONENTS = 24  # principal components of the standardised features
BANK_SIZE = 256  # training frames kept per class (evenly spaced)
QUANTILE = 0.95  # of the held-out run scores: the unit of the score
PCA_ROWS = 5000  # training rows the components are computed from, at most
MIN_SCALE = 1e-6  # a feature with a smaller spread keeps scale 1


def _nearest(Z, bank, bank_sq):
    """Euclidean distance of every row of ``Z`` to its nearest row of ``bank``."""
    d2 = (Z * Z).sum(axis=1)[:, None] - 2.0 * Z @ bank.T + bank_sq[None, :]
    return np.sqrt(np.maximum(d2.min(axis=1), 0.0))


def _evenly(n, k):
    """At most ``k`` indices spread evenly over ``range(n)``."""
    if n <= k:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, k).round().astype(np.intp))


class PoseNovelty:
    """Per-frame distance of features to the training frames of every class.

    Fitted inside :class:`~skgesture.SequenceTagger`'s ``fit`` on its
    training features (it retrains nothing, and costs about two seconds on
    PRECOG's 36 training sequences), held as its ``novelty_`` and read by its
    ``max_novelty`` rule; usable on its own to tell how far new frames are
    from a labelled recording's poses.

    Parameters
    ----------
    n_components : int, default=24
        Principal components of the standardised features the distances are
        measured in.
    bank_size : int, default=256
        Training frames kept per class, evenly spaced over its frames.
    quantile : float, default=0.95
        The unit of a class's score: this quantile, over the training runs of
        the class, of a run's median distance to the class's frames of the
        other training sequences (a held-out sequence's view). A true run of
        an unseen sequence therefore scores about 1 or less; 1.5 is half as
        far again.

    Attributes
    ----------
    mean_, scale_ : ndarray of shape (n_features,)
        Standardisation of the features.
    components_ : ndarray of shape (n_components, n_features)
        Principal axes.
    banks_ : list of ndarray of shape (n_bank_k, n_components)
        Kept frames of every class (rest first: empty).
    units_ : ndarray of shape (n_classes,)
        The unit of every class's score (``inf`` for rest and for a class seen
        in fewer than two training sequences: never novel).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils import PoseNovelty
    >>> rng = np.random.RandomState(0)
    >>> X = [rng.normal(size=(60, 5)) for _ in range(4)]
    >>> y = [np.r_[np.zeros(30, int), np.ones(30, int)] for _ in range(4)]
    >>> for x in X:
    ...     x[30:] += 4.0  # class 1 lives around +4
    >>> nov = PoseNovelty(n_components=3).fit(X, y, np.array([0, 1]))
    >>> near = nov.score(rng.normal(size=(5, 5)) + 4.0)[:, 1]
    >>> far = nov.score(rng.normal(size=(5, 5)) - 6.0)[:, 1]
    >>> bool(np.median(near) < 1.5 < np.median(far))
    True
    """

    def __init__(
        self, n_components=N_COMPONENTS, bank_size=BANK_SIZE, quantile=QUANTILE
    ):
        self.n_components = n_components
        self.bank_size = bank_size
        self.quantile = quantile

    def fit(self, X, y, classes, tracked=None):
        """Fit on training features and labels.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Training features.
        y : list of ndarray of shape (n_frames_i,)
            Their labels (values of ``classes``).
        classes : ndarray of shape (n_classes,)
            The tagger's classes, rest (0) first.
        tracked : list of ndarray of bool or None, default=None
            Rows to learn from (untracked rows are left out); None: all.

        Returns
        -------
        self : PoseNovelty
            The fitted object.
        """
        X = check_sequences(X, ndim=2)
        y = check_sequence_labels(y, X)
        classes = np.asarray(classes)
        if tracked is None:
            tracked = [np.ones(len(x), dtype=bool) for x in X]
        rows = np.concatenate(
            [np.asarray(x, dtype=np.float64)[t] for x, t in zip(X, tracked)]
        )
        self.mean_ = rows.mean(axis=0)
        std = rows.std(axis=0)
        self.scale_ = np.where(std < MIN_SCALE, 1.0, std)
        sample = (rows[_evenly(len(rows), PCA_ROWS)] - self.mean_) / self.scale_
        sample -= sample.mean(axis=0)
        k = int(min(self.n_components, *sample.shape))
        # The leading eigenvectors of the scatter matrix: the SVD's principal
        # axes (up to sign, which no distance sees), 10x cheaper, and spared
        # the multi-threaded SVD's stalls on a busy machine (11 s against
        # 0.2 s on one thread, for 5000 x 426 rows).
        values, vectors = np.linalg.eigh(sample.T @ sample)
        self.components_ = vectors[:, np.argsort(values)[::-1][:k]].T.copy()
        self._projection = None  # made by _project from the fitted values
        Z = [self._project(x) for x in X]
        # frames of every class, with the sequence they come from
        labels = [np.where(t, np.asarray(v), -1) for v, t in zip(y, tracked)]
        self.banks_ = [np.zeros((0, k))]
        self.units_ = np.full(len(classes), np.inf)
        for j, c in enumerate(classes[1:], start=1):
            frames = [(z[lab == c], i) for i, (z, lab) in enumerate(zip(Z, labels))]
            frames = [(f, i) for f, i in frames if len(f)]
            if not frames:
                self.banks_.append(np.zeros((0, k)))
                continue
            allz = np.concatenate([f for f, _ in frames])
            owner = np.concatenate([np.full(len(f), i) for f, i in frames])
            keep = _evenly(len(allz), int(self.bank_size))
            bank, owner = allz[keep], owner[keep]
            self.banks_.append(bank)
            scores = []
            for i, (z, lab) in enumerate(zip(Z, labels)):
                other = bank[owner != i]
                if not len(other):
                    continue
                sq = (other * other).sum(axis=1)
                for cls, s, e in labels_to_segments(lab.clip(0)):
                    if cls == c:
                        scores.append(np.median(_nearest(z[s:e], other, sq)))
            if scores:
                self.units_[j] = max(
                    float(np.quantile(scores, self.quantile)), MIN_SCALE
                )
        self._bank_sq = [(b * b).sum(axis=1) for b in self.banks_]
        return self

    def _project(self, x):
        # ((x - mean) / scale) @ components.T as one product and one offset:
        # no standardised copy of the (wide) features is made.
        projection = getattr(self, "_projection", None)
        if projection is None:  # (fitted objects pickled before it existed)
            weights = self.components_.T / self.scale_[:, None]
            projection = self._projection = (weights, self.mean_ @ weights)
        weights, offset = projection
        return np.asarray(x, dtype=np.float64) @ weights - offset

    def score(self, x, k=None):
        """Novelty of every frame, for every class or for column ``k``.

        Parameters
        ----------
        x : ndarray of shape (n_frames, n_features)
            Features of frames (each is scored on its own).
        k : int or None, default=None
            A class column: its novelty alone (what a run of that class is
            judged by). None: every class.

        Returns
        -------
        ndarray of shape (n_frames, n_classes), or (n_frames,) for ``k``
            Distance of each frame to the nearest kept training frame of the
            class, in units of the class's ``units_`` (rest, and a class
            without a unit: 0).
        """
        x = np.asarray(x, dtype=np.float64)
        if x.ndim != 2 or x.shape[1] != self.mean_.size:
            raise ValueError(
                f"x must be frames of shape (n_frames, {self.mean_.size}), as in "
                f"fit; got an array of shape {x.shape}"
            )
        bad = ~np.isfinite(x).all(axis=1)
        if bad.any():
            raise ValueError(
                f"x has NaN or infinite values (first at frame "
                f"{int(np.argmax(bad))}): novelty needs finite features"
            )
        Z = self._project(x)
        if k is not None:
            return self._column(Z, int(k))
        out = np.zeros((len(Z), len(self.banks_)))
        for j in range(len(self.banks_)):
            out[:, j] = self._column(Z, j)
        return out

    def _column(self, Z, j):
        bank, unit = self.banks_[j], self.units_[j]
        if not len(bank) or not np.isfinite(unit):
            return np.zeros(len(Z))
        return _nearest(Z, bank, self._bank_sq[j]) / unit
