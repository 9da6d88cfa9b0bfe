"""The baseline a practitioner tries first: a forest on framewise joint features.

Per frame: root-centred positions and velocities of the joints of ``joints`` (the
20 Kinect v1 joints or the paper's 11) of the frames at
``t - half_window .. t + half_window`` (every ``step`` frames), a scikit-learn
random forest over all frames (rest included), class probabilities averaged over
``smooth`` frames, arg-max, and runs shorter than ``min_run`` set to rest.
"""

import numpy as np
from scipy.ndimage import uniform_filter1d
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.ensemble import RandomForestClassifier

from skgesture.layouts import KINECT_V1, PAPER_11
from skgesture.utils import remove_short_runs
from skgesture.utils._validation import check_sequence_labels, check_sequences

_JOINTS = {
    "full20": list(range(len(KINECT_V1.joint_names))),
    "paper11": [KINECT_V1.joint_names.index(j) for j in PAPER_11.joints],
}


def _frame_features(seq, half_window, step, joints="full20"):
    q = np.nan_to_num(seq)
    q = q[:, _JOINTS[joints]] - q[:, :1]  # root-centre (HipCenter is joint 0)
    T = len(q)
    flat = q.reshape(T, -1)
    vel = np.gradient(flat, axis=0) if T > 1 else np.zeros_like(flat)
    base = np.hstack([flat, vel])
    offsets = np.arange(-half_window, half_window + 1, step)
    idx = np.clip(np.arange(T)[:, None] + offsets[None, :], 0, T - 1)
    return base[idx].reshape(T, -1)


class SlidingWindowForest(ClassifierMixin, BaseEstimator):
    """Random forest on a short window of framewise joint features, smoothed."""

    def __init__(
        self,
        *,
        joints="full20",
        n_estimators=100,
        half_window=4,
        step=2,
        smooth=9,
        min_run=8,
        n_jobs=2,
        random_state=None,
    ):
        self.joints = joints
        self.n_estimators = n_estimators
        self.half_window = half_window
        self.step = step
        self.smooth = smooth
        self.min_run = min_run
        self.n_jobs = n_jobs
        self.random_state = random_state

    def fit(self, X, y):
        X = check_sequences(X, ndim=3, allow_nan=True)
        y = check_sequence_labels(y, X)
        if self.joints not in _JOINTS:
            raise ValueError(
                f"joints must be one of {sorted(_JOINTS)}, got {self.joints!r}"
            )
        F = np.concatenate(
            [_frame_features(s, self.half_window, self.step, self.joints) for s in X]
        )
        self.forest_ = RandomForestClassifier(
            n_estimators=self.n_estimators,
            n_jobs=self.n_jobs,
            min_samples_leaf=2,
            random_state=self.random_state,
        ).fit(F, np.concatenate(y))
        self.classes_ = self.forest_.classes_
        return self

    def predict(self, X):
        X = check_sequences(X, ndim=3, allow_nan=True)
        out = []
        for s in X:
            p = self.forest_.predict_proba(
                _frame_features(s, self.half_window, self.step, self.joints)
            )
            p = uniform_filter1d(p, self.smooth, axis=0, mode="nearest")
            lab = self.classes_[np.argmax(p, axis=1)]
            out.append(remove_short_runs(lab, self.min_run))
        return out
