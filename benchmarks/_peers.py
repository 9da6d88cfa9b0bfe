"""What a practitioner builds without skgesture: the four peers of issue 8.

Each peer is a small scikit-learn style estimator over lists of raw skeleton
sequences: ``fit(X, y)`` with ``X`` a list of ``(T_i, 20, 3)`` Kinect v1 arrays and
``y`` a list of ``(T_i,)`` label arrays (0 = rest), ``predict(X)`` a list of label
arrays. They all read the same per-frame features (:func:`peer_features`) of the
20 joints (``joints="full20"``) or of the paper's 11 (``joints="paper11"``):

* :class:`GRUPeer`: a PyTorch 2-layer bidirectional GRU tagger over whole
  sequences;
* :class:`HGBPeer`: scikit-learn's ``HistGradientBoostingClassifier`` on each
  frame's features stacked at 7 time offsets;
* :class:`SeglearnPeer`: seglearn's ``FeatureRep()`` statistics of a 16-frame
  centred window and a 200-tree random forest (a faithful numpy copy of the
  feature set when seglearn is not installed);
* :class:`MiniRocketPeer`: aeon's MiniRocket on 24-frame centred windows and a
  ridge classifier (needs aeon).

They predict rest on untracked frames (all-zero or NaN joints), the toolkit-wide
rule (``docs/design.md``).
"""

import importlib.util

import numpy as np
from scipy import stats
from sklearn.base import BaseEstimator, ClassifierMixin
from threadpoolctl import threadpool_limits

from skgesture.layouts import KINECT_V1, PAPER_11
from skgesture.utils._validation import (
    check_sequence_labels,
    check_sequences,
    untracked_rows,
)

JOINT_SETS = {
    "full20": tuple(KINECT_V1.joint_names),
    "paper11": tuple(PAPER_11.joints),
}
_HIP = KINECT_V1.joint_names.index("HipCenter")
_SHOULDER = KINECT_V1.joint_names.index("ShoulderCenter")


def joint_indices(joints):
    """Kinect v1 indices of the joints of ``joints`` ("full20" or "paper11")."""
    if joints not in JOINT_SETS:
        raise ValueError(f"joints must be one of {sorted(JOINT_SETS)}, got {joints!r}")
    return [KINECT_V1.joint_names.index(name) for name in JOINT_SETS[joints]]


def peer_features(seq, joints="full20"):
    """Normalised joint positions and velocities of one raw sequence.

    Joint positions relative to HipCenter, divided by the sequence's median
    HipCenter-ShoulderCenter length; the HipCenter row replaced by the hip's
    offset from its median position (same scale); per-frame velocities
    (``np.gradient`` along time) appended. 120 features for 20 joints, 66 for 11.

    Parameters
    ----------
    seq : ndarray of shape (n_frames, 20, 3)
        One raw Kinect v1 sequence; untracked frames (NaN or all zero) are
        ignored in the medians and read as zeros.
    joints : {"full20", "paper11"}, default="full20"
        The joints kept, in the order of ``JOINT_SETS[joints]``.

    Returns
    -------
    ndarray of shape (n_frames, 6 * n_joints)
        Positions (3 per joint) then velocities (3 per joint), float32.
    """
    idx = joint_indices(joints)
    untracked = untracked_rows(seq)
    q = np.nan_to_num(np.asarray(seq, dtype=np.float64))
    hip = q[:, _HIP]
    tracked = ~untracked if (~untracked).any() else np.ones(len(q), bool)
    bone = np.linalg.norm(q[tracked, _SHOULDER] - hip[tracked], axis=1)
    scale = float(np.median(bone))
    if not np.isfinite(scale) or scale <= 1e-9:
        scale = 1.0
    rel = (q[:, idx] - hip[:, None]) / scale
    rel[:, idx.index(_HIP)] = (hip - np.median(hip[tracked], axis=0)) / scale
    rel[untracked] = 0.0
    flat = rel.reshape(len(q), -1)
    vel = np.gradient(flat, axis=0) if len(q) > 1 else np.zeros_like(flat)
    return np.hstack([flat, vel]).astype(np.float32)


def centred_windows(feats, width):
    """``(T, width, F)`` windows of frames ``t - width//2 .. t + width - width//2 - 1``.

    Frames outside the sequence are replaced by its first or last frame.
    """
    T = len(feats)
    offsets = np.arange(width) - width // 2
    idx = np.clip(np.arange(T)[:, None] + offsets[None, :], 0, T - 1)
    return feats[idx]


def _stride_subsample(n, max_n):
    """Indices of an evenly spaced subset of ``range(n)`` of size ``<= max_n``."""
    if max_n is None or n <= max_n:
        return np.arange(n)
    return np.arange(0, n, int(np.ceil(n / max_n)))


class _PeerBase(ClassifierMixin, BaseEstimator):
    """Validation, features and rest-on-untracked shared by the peers."""

    def _check_X(self, X):
        X = check_sequences(X, ndim=3, allow_nan=True)
        for i, s in enumerate(X):
            if s.shape[1:] != (20, 3):
                raise ValueError(
                    f"X[{i}] has frames of shape {s.shape[1:]}; the peers read raw "
                    "Kinect v1 skeletons of shape (20, 3)"
                )
        return X

    def _features(self, X):
        return [peer_features(s, self.joints) for s in X]

    def fit(self, X, y):
        X = self._check_X(X)
        y = check_sequence_labels(y, X)
        self.classes_ = np.unique(np.concatenate(y))
        self._fit(self._features(X), y)
        return self

    def predict(self, X):
        X = self._check_X(X)
        out = []
        for s, f in zip(X, self._features(X)):
            lab = self.classes_[self._predict_index(f)]
            lab[untracked_rows(s)] = 0
            out.append(lab)
        return out


# --------------------------------------------------------------------------- GRU


class GRUPeer(_PeerBase):
    """PyTorch 2-layer bidirectional GRU tagger, framewise cross-entropy.

    Inputs z-scored with the training frames' statistics; Adam (``lr``,
    ``weight_decay``) for ``n_steps`` steps of ``batch_size`` random
    ``crop``-frame crops (a random sequence, a random start; shorter sequences
    are padded and the padding is ignored in the loss); whole-sequence
    prediction, arg-max per frame. Torch runs on one thread while it fits and
    predicts.
    """

    def __init__(
        self,
        *,
        joints="full20",
        hidden=64,
        n_layers=2,
        lr=3e-3,
        weight_decay=1e-4,
        n_steps=300,
        batch_size=32,
        crop=128,
        random_state=None,
    ):
        self.joints = joints
        self.hidden = hidden
        self.n_layers = n_layers
        self.lr = lr
        self.weight_decay = weight_decay
        self.n_steps = n_steps
        self.batch_size = batch_size
        self.crop = crop
        self.random_state = random_state

    def _fit(self, F, y):
        import torch

        from skgesture._nn._training import torch_threads

        rng = np.random.default_rng(self.random_state)
        allf = np.concatenate(F)
        self.mean_ = allf.mean(axis=0)
        self.scale_ = allf.std(axis=0) + 1e-6
        Z = [(f - self.mean_) / self.scale_ for f in F]
        codes = [np.searchsorted(self.classes_, t) for t in y]
        with torch_threads(1):
            torch.manual_seed(int(rng.integers(2**31)))
            self.net_ = _BiGRU(
                Z[0].shape[1], len(self.classes_), self.hidden, self.n_layers
            )
            opt = torch.optim.Adam(
                self.net_.parameters(), lr=self.lr, weight_decay=self.weight_decay
            )
            loss_fn = torch.nn.CrossEntropyLoss(ignore_index=-100)
            self.net_.train()
            for _ in range(self.n_steps):
                xb = np.zeros((self.batch_size, self.crop, Z[0].shape[1]), np.float32)
                yb = np.full((self.batch_size, self.crop), -100, np.int64)
                for b in range(self.batch_size):
                    i = rng.integers(len(Z))
                    T = len(Z[i])
                    s = rng.integers(T - self.crop + 1) if T > self.crop else 0
                    n = min(self.crop, T)
                    xb[b, :n] = Z[i][s : s + n]
                    yb[b, :n] = codes[i][s : s + n]
                logits = self.net_(torch.from_numpy(xb))
                loss = loss_fn(
                    logits.reshape(-1, logits.shape[-1]),
                    torch.from_numpy(yb).reshape(-1),
                )
                opt.zero_grad()
                loss.backward()
                opt.step()
            self.net_.eval()

    def _predict_index(self, f):
        import torch

        from skgesture._nn._training import torch_threads

        z = ((f - self.mean_) / self.scale_).astype(np.float32)
        with torch_threads(1), torch.no_grad():
            logits = self.net_(torch.from_numpy(z)[None])[0]
        return logits.argmax(dim=1).numpy()


def _BiGRU(n_in, n_classes, hidden, n_layers):
    import torch

    class BiGRU(torch.nn.Module):
        def __init__(self):
            super().__init__()
            self.gru = torch.nn.GRU(
                n_in, hidden, num_layers=n_layers, batch_first=True, bidirectional=True
            )
            self.out = torch.nn.Linear(2 * hidden, n_classes)

        def forward(self, x):
            return self.out(self.gru(x)[0])

    return BiGRU()


# --------------------------------------------------------------------------- HGB


def stacked_offsets(feats, offsets):
    """Each frame's features at the given time offsets, clipped at the ends."""
    T = len(feats)
    idx = np.clip(np.arange(T)[:, None] + np.asarray(offsets)[None, :], 0, T - 1)
    return feats[idx].reshape(T, -1)


class HGBPeer(_PeerBase):
    """Histogram gradient boosting on each frame's features at 7 time offsets.

    ``HistGradientBoostingClassifier(max_iter=150, learning_rate=0.15)`` with
    scikit-learn's other defaults (early stopping on a random 10 % when there
    are more than 10,000 frames, seeded by ``random_state``), on the frame's
    features at offsets -12, -6, -3, 0, +3, +6, +12 (clipped at the sequence
    ends); arg-max per frame. ``n_threads`` OpenMP threads (None: as is): one by
    default, like the torch peer, since its many short parallel regions stall
    when the machine is busy.
    """

    def __init__(
        self,
        *,
        joints="full20",
        offsets=(-12, -6, -3, 0, 3, 6, 12),
        max_iter=150,
        learning_rate=0.15,
        n_threads=1,
        random_state=None,
    ):
        self.joints = joints
        self.offsets = offsets
        self.max_iter = max_iter
        self.learning_rate = learning_rate
        self.n_threads = n_threads
        self.random_state = random_state

    def _fit(self, F, y):
        from sklearn.ensemble import HistGradientBoostingClassifier

        S = np.concatenate([stacked_offsets(f, self.offsets) for f in F])
        codes = np.searchsorted(self.classes_, np.concatenate(y))
        with threadpool_limits(self.n_threads, user_api="openmp"):
            self.model_ = HistGradientBoostingClassifier(
                max_iter=self.max_iter,
                learning_rate=self.learning_rate,
                random_state=self.random_state,
            ).fit(S, codes)

    def _predict_index(self, f):
        with threadpool_limits(self.n_threads, user_api="openmp"):
            return self.model_.predict(stacked_offsets(f, self.offsets))


# ---------------------------------------------------------------------- seglearn


def _mean_crossings(W):
    pos = W > 0
    npos = ~pos
    c = (pos[:, :-1] & npos[:, 1:]) | (npos[:, :-1] & pos[:, 1:])
    return np.count_nonzero(c, axis=1).astype(np.float64)


def feature_rep_numpy(W):
    """seglearn ``FeatureRep()``'s default features of windows ``(N, width, F)``.

    The 11 statistics of ``seglearn.feature_functions.base_features()``, in its
    order, each over time for every channel: mean, median, abs_energy (sum of
    squares), std, var, min, max, skew, kurt (Fisher, biased, as scipy's
    defaults), mse (mean spectral energy: mean ``|fft|**2``) and mnx (the number
    of sign changes). Returns ``(N, 11 * F)``, identical to ``FeatureRep()``.
    """
    W = np.asarray(W, dtype=np.float64)
    return np.column_stack(
        [
            np.mean(W, axis=1),
            np.median(W, axis=1),
            np.sum(W * W, axis=1),
            np.std(W, axis=1),
            np.var(W, axis=1),
            np.min(W, axis=1),
            np.max(W, axis=1),
            stats.skew(W, axis=1),
            stats.kurtosis(W, axis=1),
            np.mean(np.square(np.abs(np.fft.fft(W, axis=1))), axis=1),
            _mean_crossings(W),
        ]
    )


def have_seglearn():
    """Whether seglearn can be imported."""
    if importlib.util.find_spec("seglearn") is None:
        return False
    try:
        import seglearn.transform  # noqa: F401
    except Exception:  # seglearn imports pandas without declaring it
        return False
    return True


class SeglearnPeer(_PeerBase):
    """seglearn: 16-frame centred windows, ``FeatureRep()``, a 200-tree forest.

    The label of a frame is the forest's prediction for the window centred on
    it (frames ``t - 8 .. t + 7``). ``backend="auto"`` uses seglearn's
    ``FeatureRep()`` when seglearn imports, otherwise :func:`feature_rep_numpy`
    (the same numbers). Non-finite statistics (skew and kurtosis of a constant
    window) are read as 0. With more than ``max_train_windows`` training
    frames, an evenly spaced subset of them is used (not on PRECOG, whose
    folds have about 10,700).
    """

    def __init__(
        self,
        *,
        joints="full20",
        width=16,
        n_estimators=200,
        backend="auto",
        max_train_windows=30000,
        n_jobs=2,
        random_state=None,
    ):
        self.joints = joints
        self.width = width
        self.n_estimators = n_estimators
        self.backend = backend
        self.max_train_windows = max_train_windows
        self.n_jobs = n_jobs
        self.random_state = random_state

    def _rep(self, f):
        W = centred_windows(f, self.width).astype(np.float64)
        if self.backend_ == "seglearn":
            from seglearn.transform import FeatureRep

            out = FeatureRep().fit(W).transform(W)
        else:
            out = feature_rep_numpy(W)
        return np.nan_to_num(out, nan=0.0, posinf=0.0, neginf=0.0)

    def _fit(self, F, y):
        from sklearn.ensemble import RandomForestClassifier

        if self.backend not in ("auto", "seglearn", "numpy"):
            raise ValueError(
                f"backend must be 'auto', 'seglearn' or 'numpy', got {self.backend!r}"
            )
        if self.backend == "auto":
            self.backend_ = "seglearn" if have_seglearn() else "numpy"
        else:
            self.backend_ = self.backend
        R = np.concatenate([self._rep(f) for f in F])
        codes = np.searchsorted(self.classes_, np.concatenate(y))
        keep = _stride_subsample(len(R), self.max_train_windows)
        self.model_ = RandomForestClassifier(
            n_estimators=self.n_estimators,
            n_jobs=self.n_jobs,
            random_state=self.random_state,
        ).fit(R[keep], codes[keep])

    def _predict_index(self, f):
        return self.model_.predict(self._rep(f))


# -------------------------------------------------------------------- MiniRocket


def have_aeon():
    """Whether aeon's MiniRocket can be imported."""
    if importlib.util.find_spec("aeon") is None:
        return False
    try:
        from aeon.transformations.collection.convolution_based import (  # noqa: F401
            MiniRocket,
        )
    except Exception:
        return False
    return True


class MiniRocketPeer(_PeerBase):
    """aeon MiniRocket and a ridge classifier on 24-frame centred windows.

    Each frame's window (frames ``t - 12 .. t + 11``, channels = the features)
    goes through aeon's multivariate ``MiniRocket`` (10,000 kernels), then
    ``StandardScaler(with_mean=False)`` and
    ``RidgeClassifierCV(alphas=np.logspace(-3, 3, 10))``, as aeon's own
    ``MiniRocketClassifier`` does. With more than ``max_train_windows`` training
    frames, an evenly spaced subset is used (not on PRECOG).
    """

    def __init__(
        self,
        *,
        joints="full20",
        width=24,
        n_kernels=10000,
        max_train_windows=20000,
        chunk=4000,
        random_state=None,
    ):
        self.joints = joints
        self.width = width
        self.n_kernels = n_kernels
        self.max_train_windows = max_train_windows
        self.chunk = chunk
        self.random_state = random_state

    def _windows(self, f):
        # aeon reads (n_cases, n_channels, n_timepoints)
        return np.ascontiguousarray(centred_windows(f, self.width).transpose(0, 2, 1))

    def _transform(self, W):
        parts = [
            self.rocket_.transform(W[i : i + self.chunk])
            for i in range(0, len(W), self.chunk)
        ]
        return np.concatenate(parts).astype(np.float32, copy=False)

    def _fit(self, F, y):
        from aeon.transformations.collection.convolution_based import MiniRocket
        from sklearn.linear_model import RidgeClassifierCV
        from sklearn.preprocessing import StandardScaler

        W = np.concatenate([self._windows(f) for f in F]).astype(np.float64)
        codes = np.searchsorted(self.classes_, np.concatenate(y))
        keep = _stride_subsample(len(W), self.max_train_windows)
        W, codes = W[keep], codes[keep]
        self.rocket_ = MiniRocket(
            n_kernels=self.n_kernels, random_state=self.random_state
        ).fit(W)
        R = self._transform(W)
        self.scaler_ = StandardScaler(with_mean=False).fit(R)
        self.ridge_ = RidgeClassifierCV(alphas=np.logspace(-3, 3, 10)).fit(
            self.scaler_.transform(R), codes
        )

    def _predict_index(self, f):
        R = self._transform(self._windows(f).astype(np.float64))
        return self.ridge_.predict(self.scaler_.transform(R))


# ---------------------------------------------------------------------- registry


def _unavailable_seglearn():
    return None  # the numpy copy of FeatureRep always works


def _unavailable_aeon():
    if have_aeon():
        return None
    return "aeon is not installed (pip install 'aeon>=1.0'): MiniRocket peer skipped"


PEERS = {
    "GRU peer": (GRUPeer, lambda: None),
    "HGB peer": (HGBPeer, lambda: None),
    "seglearn peer": (SeglearnPeer, _unavailable_seglearn),
    "MiniRocket peer": (MiniRocketPeer, _unavailable_aeon),
}
"""name -> (estimator class, function returning why it cannot run, or None)."""
