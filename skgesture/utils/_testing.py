"""Tiny synthetic skeleton streams for doctests and unit tests.

Built on the generator of :func:`skgesture.datasets.make_gesture_streams`, so a
doctest sees the same kind of data as a user: a 20-joint Kinect v1 skeleton in
metres, camera space, a few gestures separated by rests.
"""

# SPDX-License-Identifier: BSD-3-Clause

from sklearn.utils import check_random_state

from skgesture.datasets._synthetic import (
    MAX_CLASSES,
    REFERENCE_FPS,
    _check_int,
    _generate,
)

__all__ = ["make_skeleton_stream"]

TESTING_NOISE = 0.005  # metres, the generator's default sensor jitter


def make_skeleton_stream(n_frames=None, n_gestures=3, n_classes=3, random_state=0):
    """One short, clean gesture stream for doctests.

    The stream has ``n_gestures`` gestures drawn from classes ``1..n_classes``
    (all distinct when ``n_gestures <= n_classes``), rests between them, the
    default sensor jitter, and neither tracking dropouts nor out-of-vocabulary
    motions, so every frame is tracked and every label is predictable.

    Parameters
    ----------
    n_frames : int or None, default=None
        Length of the stream. ``None`` keeps the natural length (a few
        hundred frames for three gestures); an int stretches or squeezes the rests and,
        if needed, the gestures (each keeps at least 6 frames).
    n_gestures : int, default=3
        Number of gestures.
    n_classes : int, default=3
        Number of gesture classes to draw from, 1 to 50.
    random_state : int, RandomState instance or None, default=0
        Seed of the stream.

    Returns
    -------
    X : ndarray of shape (n_frames, 20, 3)
        Joint positions in metres, float64.
    y : ndarray of shape (n_frames,)
        Per-frame labels, int64: 0 rest, ``1..n_classes`` gestures.

    Raises
    ------
    ValueError
        If a parameter is out of range or ``n_frames`` cannot hold the
        gestures.

    See Also
    --------
    skgesture.datasets.make_gesture_streams : Full synthetic data sets.

    Examples
    --------
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> X.shape[1:], X.dtype, y.dtype
    ((20, 3), dtype('float64'), dtype('int64'))
    >>> sorted(set(y.tolist()))
    [0, 1, 2, 3]
    >>> X, y = make_skeleton_stream(n_frames=120, random_state=0)
    >>> X.shape, y.shape
    ((120, 20, 3), (120,))
    """
    n_gestures = _check_int(n_gestures, "n_gestures", 1)
    n_classes = _check_int(n_classes, "n_classes", 1, MAX_CLASSES)
    if n_frames is not None:
        n_frames = _check_int(n_frames, "n_frames", 1)
    data = _generate(
        check_random_state(random_state), n_sequences=1, n_classes=n_classes,
        n_gestures=(n_gestures, n_gestures), n_subjects=1, oov_rate=0.0,
        noise=TESTING_NOISE, dropout_rate=0.0, fps=REFERENCE_FPS, n_frames=n_frames,
    )  # fmt: skip
    return data.X[0], data.y[0]
