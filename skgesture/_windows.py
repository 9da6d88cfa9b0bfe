"""DynamicPoseWindow: descriptors sampled around each frame at several time steps."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval
from sklearn.utils.validation import check_is_fitted

from skgesture.utils._validation import check_sequences

__all__ = ["DynamicPoseWindow", "dynamic_poses", "check_steps"]

N_POSES = 3  # METHOD_SPEC §5.1: three descriptors per dynamic pose
STEPS_A = (4,)  # METHOD_SPEC §5.1
STEPS_B = (4, 3, 2)  # METHOD_SPEC §6.1


def check_steps(steps, n_poses):
    """Validate ``steps`` and ``n_poses``; return ``steps`` as a tuple of ints."""
    try:
        steps = tuple(int(s) for s in steps)
    except (TypeError, ValueError):
        raise ValueError(
            f"steps must be a sequence of positive ints, got {steps!r}"
        ) from None
    if not steps or any(s < 1 for s in steps):
        raise ValueError(
            f"steps must be a non-empty sequence of positive ints, got {steps!r}"
        )
    if n_poses % 2 != 1:
        raise ValueError(
            f"n_poses must be odd (poses centred on a frame), got {n_poses}"
        )
    return steps


def dynamic_poses(D, steps, n_poses=N_POSES, centres=None):
    """Dynamic poses of one sequence: descriptors at ``c + j*s`` around centres ``c``.

    Parameters
    ----------
    D : ndarray of shape (n_frames, n_features)
        Per-frame descriptors.
    steps : tuple of int
        Time step of each scale.
    n_poses : int, default=3
        Descriptors per dynamic pose (odd), centred on the frame.
    centres : ndarray of int or None, default=None
        Centre frames; every frame when None. Frames beyond the ends repeat the
        first / last frame.

    Returns
    -------
    ndarray of shape (n_centres, n_scales, n_poses * n_features)
        float32; the poses of one window are concatenated in time order.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._windows import dynamic_poses
    >>> D = np.arange(10, dtype=float)[:, None]
    >>> dynamic_poses(D, (4, 2), centres=np.array([4]))[0].tolist()
    [[0.0, 4.0, 8.0], [2.0, 4.0, 6.0]]
    """
    T, F = D.shape
    c = np.arange(T) if centres is None else np.asarray(centres)
    half = (n_poses - 1) // 2
    offsets = np.arange(-half, half + 1)
    out = np.empty((len(c), len(steps), n_poses * F), dtype=np.float32)
    for k, s in enumerate(steps):
        idx = np.clip(c[:, None] + offsets[None, :] * s, 0, T - 1)
        out[:, k] = D[idx].reshape(len(c), n_poses * F)
    return out


class DynamicPoseWindow(TransformerMixin, BaseEstimator):
    """Dynamic poses: the descriptors at ``t - s``, ``t``, ``t + s`` for every frame.

    For each frame ``t`` and each time step ``s`` in ``steps`` this concatenates
    ``n_poses`` descriptors centred on ``t`` (METHOD_SPEC §5.1, §6.2), so with the
    paper's 183-D descriptor and 3 poses each window has 549 values. Frames
    beyond the ends of a sequence repeat its first / last frame. A masked input
    (rest rows masked by :class:`ActivitySegmenter`) gives a masked output with
    the same rows masked.

    The windows of every frame are computed; :class:`MultiScaleClassifier` takes
    them at stride 2 inside each period of activity and resizes periods too
    short for 5 windows, as the paper does.

    Parameters
    ----------
    steps : tuple of int, default=(4,)
        Time step of each scale: ``(4,)`` for Method A, ``(4, 3, 2)`` for B.
    n_poses : int, default=3
        Descriptors per dynamic pose (odd).

    Attributes
    ----------
    n_features_in_ : int
        Descriptor width.
    frame_shape_in_ : tuple of int
        Shape of one input frame.

    See Also
    --------
    MultiScaleClassifier : Classifies the windows, one network per scale.

    Notes
    -----
    The output is float32 and dense: ``len(steps) * n_poses * n_features * 4``
    bytes per frame (6.6 KB for Method B on 183-D descriptors).

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture import DynamicPoseWindow
    >>> D = [np.arange(20, dtype=float).reshape(10, 2)]
    >>> W = DynamicPoseWindow(steps=(4, 2)).fit_transform(D)
    >>> W[0].shape
    (10, 2, 6)
    >>> W[0][5, 0].tolist()
    [2.0, 3.0, 10.0, 11.0, 18.0, 19.0]
    """

    _parameter_constraints: dict = {
        "steps": [tuple, list],
        "n_poses": [Interval(Integral, 1, None, closed="left")],
    }

    def __init__(self, *, steps=STEPS_A, n_poses=N_POSES):
        self.steps = steps
        self.n_poses = n_poses

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Check the parameters and remember the descriptor width.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame descriptors (plain or masked).
        y : None
            Ignored.

        Returns
        -------
        self : DynamicPoseWindow
            The fitted transformer.
        """
        check_steps(self.steps, self.n_poses)
        check_sequences(X, ndim=2, estimator=self, reset=True)
        return self

    def transform(self, X):
        """Dynamic poses of every frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_features)
            Per-frame descriptors; masked rows stay masked.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_scales, n_poses * n_features)
            float32 windows (masked arrays where the input was masked).
        """
        check_is_fitted(self)
        steps = check_steps(self.steps, self.n_poses)
        data = check_sequences(X, ndim=2, estimator=self, reset=False)
        out = []
        for x, d in zip(X, data):
            w = dynamic_poses(d, steps, self.n_poses)
            if isinstance(x, np.ma.MaskedArray):
                rows = np.ma.getmaskarray(x).all(axis=1)
                w = np.ma.MaskedArray(
                    w, mask=np.broadcast_to(rows[:, None, None], w.shape)
                )
            out.append(w)
        return out

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        return tags
