"""SkeletonAugmenter: random rotation, scaling, time warping and noise in ``fit``.

Applied by :class:`~skgesture.SequenceTagger` to each training crop, never at
prediction. The features must be xyz triples with y vertical, as
:class:`~skgesture.JointFeatures` gives (positions and their derivatives all
rotate and scale the same way); the labels are resampled with the frames, so
they stay aligned.
"""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils._param_validation import Interval, validate_params

from skgesture.utils._params import NewParamsMixin

__all__ = ["SkeletonAugmenter", "time_warp"]

N_COORDS = 3


@validate_params(
    {
        "x": ["array-like"],
        "y": ["array-like", None],
        "rate": [Interval(Real, 0, None, closed="neither")],
    },
    prefer_skip_nested_validation=True,
)
def time_warp(x, y, rate):
    """Resample a sequence in time, with its labels.

    Parameters
    ----------
    x : ndarray of shape (n_frames, n_features)
        Features of one sequence.
    y : ndarray of shape (n_frames,) or None
        Per-frame labels (nearest frame), or None.
    rate : float
        Speed factor: ``2.0`` plays the gesture twice as slowly (twice the
        frames), ``0.5`` twice as fast.

    Returns
    -------
    x_warped : ndarray of shape (round(n_frames * rate), n_features)
        Linearly interpolated features (at least 2 frames when
        ``n_frames >= 2``).
    y_warped : ndarray of shape (round(n_frames * rate),) or None
        Labels of the nearest original frame.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._augment import time_warp
    >>> x = np.arange(4.0)[:, None]
    >>> xw, yw = time_warp(x, np.array([0, 1, 1, 0]), 1.5)
    >>> xw.ravel().round(2).tolist(), yw.tolist()
    ([0.0, 0.6, 1.2, 1.8, 2.4, 3.0], [0, 1, 1, 1, 1, 0])
    """
    x = np.asarray(x)
    n = len(x)
    if n < 2:
        return x, (None if y is None else np.asarray(y))
    src = _warp_grid(n, rate)
    lo, w = _grid_weights(src, n, x.dtype)
    warped = _interpolate(x, lo, w)
    labels = None if y is None else np.asarray(y)[np.rint(src).astype(np.intp)]
    return warped, labels


def _warp_grid(n, rate):
    """Source positions of the frames of an ``n``-frame sequence warped by
    ``rate`` (at least 2 frames)."""
    return np.linspace(0.0, n - 1, max(int(round(n * rate)), 2))


def _grid_weights(src, n, dtype):
    """The frame before every source position and the weight of the next."""
    lo = np.minimum(np.floor(src).astype(np.intp), n - 2)
    return lo, (src - lo)[:, None].astype(dtype)


def _interpolate(x, lo, w):
    """Rows ``lo`` and ``lo + 1`` of ``x`` mixed by ``w``."""
    return x[lo] * (1 - w) + x[lo + 1] * w


class SkeletonAugmenter(NewParamsMixin, BaseEstimator):
    """Random perturbations of a training sequence of xyz-triple features.

    Each call draws a rotation about the vertical axis, a global scale, a
    speed change and Gaussian noise, and applies them to one sequence (and
    its labels, for the speed change). Used by
    :class:`~skgesture.SequenceTagger` on each training crop; it is a
    parameter object, so ``tagger__augment__rotation`` can be searched.

    Parameters
    ----------
    rotation : float, default=20.0
        Largest rotation about the vertical (y) axis, in degrees; the angle is
        uniform in ``[-rotation, rotation]``.
    scale : float, default=0.1
        Largest relative change of the body size; the factor is uniform in
        ``[1 - scale, 1 + scale]``.
    time_warp : float, default=0.2
        Largest relative change of the speed; the rate is uniform in
        ``[1 - time_warp, 1 + time_warp]``.
    noise : float, default=0.01
        Standard deviation of the Gaussian noise added to every feature (in
        trunk lengths for :class:`JointFeatures`).

    See Also
    --------
    SequenceTagger : Applies it in ``fit``.
    JointFeatures : Features made of xyz triples.

    Notes
    -----
    The rotation and the scale assume that every consecutive triple of
    features is a 3-D vector with y vertical; the paper's
    :class:`PoseDescriptor` is not such a layout (its angles and distances do
    not rotate), so use ``rotation=0`` and ``scale=0`` with it.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture import SkeletonAugmenter
    >>> x = np.ones((50, 6), dtype=np.float32)
    >>> y = np.r_[np.zeros(25, int), np.ones(25, int)]
    >>> xa, ya = SkeletonAugmenter().augment(x, y, np.random.RandomState(0))
    >>> len(xa) == len(ya), xa.dtype
    (True, dtype('float32'))
    """

    _parameter_constraints: dict = {
        "rotation": [Interval(Real, 0, 180, closed="both")],
        "scale": [Interval(Real, 0, 1, closed="left")],
        "time_warp": [Interval(Real, 0, 1, closed="left")],
        "noise": [Interval(Real, 0, None, closed="left")],
    }

    def __init__(self, *, rotation=20.0, scale=0.1, time_warp=0.2, noise=0.01):
        self.rotation = rotation
        self.scale = scale
        self.time_warp = time_warp
        self.noise = noise

    def augment(self, x, y, rng, *, noise=True, length=None):
        """One random perturbation of a sequence and its labels.

        Parameters
        ----------
        x : ndarray of shape (n_frames, n_features)
            Features; with ``rotation > 0`` ``n_features`` must be a multiple
            of 3.
        y : ndarray of shape (n_frames,)
            Per-frame labels.
        rng : numpy.random.RandomState
            Source of the random draws.
        noise : bool, default=True
            Whether to add the Gaussian noise. ``SequenceTagger`` passes
            False and adds it to a whole batch of crops at once, in torch,
            for the frames it keeps (a third of its fit's time went to
            drawing it here, crop by crop, for frames that the crop then
            dropped).
        length : int or None, default=None
            An int: return a random crop of this many frames of the
            perturbed sequence (all of it when it is shorter), the crop's
            start drawn from ``rng`` after the perturbation's own draws, and
            compute that crop's frames alone. ``SequenceTagger``'s crops
            are a third shorter than the stretch it perturbs.

        Returns
        -------
        x_aug : ndarray of shape (n_frames_aug, n_features)
            Perturbed features, same dtype.
        y_aug : ndarray of shape (n_frames_aug,)
            Labels aligned with ``x_aug``.
        """
        self._validate_params()
        if length is not None and (
            isinstance(length, bool) or not isinstance(length, Integral) or length < 1
        ):
            raise ValueError(f"length must be a positive int or None, got {length!r}")
        return self._perturb(x, y, rng, noise=noise, length=length)

    def _perturb(self, x, y, rng, *, noise=True, length=None):
        """:meth:`augment` without the parameters' validation (a fit checks
        them once, then perturbs thousands of crops)."""
        dtype = x.dtype
        angle = factor = rate = None
        if self.rotation:
            if x.shape[1] % N_COORDS:
                raise ValueError(
                    f"rotation needs xyz-triple features (a multiple of 3), got "
                    f"{x.shape[1]} features; set rotation=0 for other features"
                )
            angle = np.deg2rad(rng.uniform(-self.rotation, self.rotation))
        if self.scale:
            factor = rng.uniform(1 - self.scale, 1 + self.scale)
        if self.time_warp:
            rate = rng.uniform(1 - self.time_warp, 1 + self.time_warp)
        # The frames of the warped sequence (time_warp's arithmetic), then
        # the crop; only the source frames the crop reads are perturbed.
        n = len(x)
        src = None if rate is None or n < 2 else _warp_grid(n, rate)
        m = n if src is None else len(src)
        start, stop = 0, m
        if length is not None and m > length:
            start = rng.randint(m - length + 1)
            stop = start + length
        if src is None:
            x, y = x[start:stop], np.asarray(y)[start:stop]
            x = self._rotate_scale(x, angle, factor)
        else:
            src = src[start:stop]
            lo, w = _grid_weights(src, n, dtype)
            part = self._rotate_scale(x[lo[0] : lo[-1] + 2], angle, factor)
            x = _interpolate(part, lo - lo[0], w)
            y = np.asarray(y)[np.rint(src).astype(np.intp)]
        if noise and self.noise:
            # float32 Gaussians of a Generator seeded from rng: 5x faster than
            # RandomState.normal, and as reproducible
            gen = np.random.default_rng(rng.randint(np.iinfo(np.int32).max))
            noise = gen.standard_normal(x.shape, dtype=np.float32)
            x = x + (noise * np.float32(self.noise)).astype(dtype, copy=False)
        return np.ascontiguousarray(x, dtype=dtype), y

    @staticmethod
    def _rotate_scale(x, angle, factor):
        """Frames rotated by ``angle`` about the vertical axis, then scaled
        by ``factor`` (None: not at all)."""
        dtype = x.dtype
        if angle is not None:
            c, s = np.cos(angle), np.sin(angle)
            rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]], dtype=dtype)
            x = (x.reshape(-1, N_COORDS) @ rot.T).reshape(x.shape)
        if factor is not None:
            x = x * dtype.type(factor)
        return x
