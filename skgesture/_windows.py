"""DynamicPoseWindow: descriptors sampled around each frame at several time steps."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval
from sklearn.utils.validation import _check_feature_names_in, check_is_fitted

from skgesture._stream import Rows, StreamableMixin
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._validation import (
    SequenceOf,
    SequenceOutputMixin,
    check_sequences,
    sequence_tags,
    untracked_rows,
)

__all__ = ["DynamicPoseWindow", "DynamicPoses", "dynamic_poses", "check_steps"]

STEPS_CONSTRAINT = SequenceOf.ints(1)

N_POSES = 3  # docs/method.md §5.1: three descriptors per dynamic pose
STEPS_A = (4,)  # docs/method.md §5.1
STEPS_B = (4, 3, 2)  # docs/method.md §6.1


def check_steps(steps, n_poses):
    """Validate ``steps`` and ``n_poses``; return ``steps`` as a tuple of ints.

    Steps must be ints (a float step such as 2.5 is refused, not truncated).
    """
    try:
        values = tuple(np.asarray(steps).tolist())
    except TypeError:
        values = None
    if values is None or not STEPS_CONSTRAINT.is_satisfied_by(values):
        raise ValueError(
            f"steps must be a non-empty tuple of positive ints, got {steps!r}"
        )
    steps = tuple(int(s) for s in values)
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


def _pose_frames(centres, step, n_poses, n_frames):
    """Frames of the poses of the windows at ``centres`` (edges replicated)."""
    half = (n_poses - 1) // 2
    offsets = np.arange(-half, half + 1) * step
    return np.clip(np.asarray(centres)[:, None] + offsets, 0, n_frames - 1)


class DynamicPoses:
    """The dynamic poses of one sequence, gathered on demand (lazy windows).

    What :class:`DynamicPoseWindow` ``(lazy=True)`` returns per sequence: the
    per-frame descriptors (float32) and the window layout, standing for the
    ``(n_frames, n_scales, n_poses * n_features)`` float32 array of
    :func:`dynamic_poses` without storing it (4 bytes per descriptor value
    instead of ``4 * n_scales * n_poses``). :class:`MultiScaleClassifier`
    gathers the windows it scores straight from the descriptors;
    ``numpy.asarray`` and indexing give the dense windows, identical to those
    of ``DynamicPoseWindow(lazy=False)``.

    Parameters
    ----------
    descriptors : ndarray of shape (n_frames, n_features)
        Per-frame descriptors; stored as C-contiguous float32.
    steps : tuple of int
        Time step of each scale.
    n_poses : int, default=3
        Descriptors per dynamic pose.
    rest : ndarray of bool of shape (n_frames,) or None, default=None
        Rows outside every period of activity (the masked rows of the input);
        ``None`` when the input was a plain array.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture._windows import DynamicPoses, dynamic_poses
    >>> D = np.arange(10, dtype=float)[:, None]
    >>> W = DynamicPoses(D, (4, 2))
    >>> W.shape, W.dtype
    ((10, 2, 3), dtype('float32'))
    >>> W[4].tolist()
    [[0.0, 4.0, 8.0], [2.0, 4.0, 6.0]]
    >>> bool((np.asarray(W) == dynamic_poses(D, (4, 2))).all())
    True
    """

    ndim = 3
    dtype = np.dtype(np.float32)

    def __init__(self, descriptors, steps, n_poses=N_POSES, rest=None):
        self.descriptors = np.ascontiguousarray(descriptors, dtype=np.float32)
        self.steps = tuple(int(s) for s in steps)
        self.n_poses = int(n_poses)
        self.rest = None if rest is None else np.asarray(rest, dtype=bool)

    @property
    def shape(self):
        """``(n_frames, n_scales, n_poses * n_features)``, as the dense windows."""
        T, F = self.descriptors.shape
        return (T, len(self.steps), self.n_poses * F)

    @property
    def size(self):
        return int(np.prod(self.shape))

    def __len__(self):
        return len(self.descriptors)

    def __repr__(self):
        return (
            f"DynamicPoses(shape={self.shape}, steps={self.steps}, "
            f"n_poses={self.n_poses}, masked={self.rest is not None})"
        )

    def windows(self, centres=None):
        """Dense float32 windows at ``centres`` (every frame when None)."""
        return dynamic_poses(self.descriptors, self.steps, self.n_poses, centres)

    def rest_rows(self):
        """Rows outside every period: the masked rows of the input, or, for a
        plain input, the rows whose dense window is all zeros (an untracked
        frame of a plain array, as :func:`untracked_rows` of the dense windows).
        """
        if self.rest is not None:
            return self.rest.copy()
        zero = ~self.descriptors.any(axis=1)
        rest = zero.copy()
        for s in self.steps:
            rest &= zero[_pose_frames(np.arange(len(zero)), s, self.n_poses,
                                      len(zero))].all(axis=1)  # fmt: skip
        return rest

    def toarray(self):
        """The dense windows: an ndarray, or a MaskedArray whose masked rows are
        the ``rest`` rows (as ``DynamicPoseWindow(lazy=False)`` returns)."""
        w = self.windows()
        if self.rest is None:
            return w
        return np.ma.MaskedArray(
            w, mask=np.repeat(self.rest, w[0].size).reshape(w.shape)
        )

    def __array__(self, dtype=None, copy=None):
        w = self.windows()
        return w if dtype is None else w.astype(dtype, copy=False)

    def __getitem__(self, key):
        """Dense windows of the selected frames (then the rest of ``key``)."""
        first, rest = (key[0], key[1:]) if isinstance(key, tuple) else (key, ())
        frames = np.arange(len(self))[first]
        if np.ndim(frames) == 0:
            return self.windows(np.atleast_1d(frames))[(0,) + rest]
        return self.windows(frames)[(slice(None),) + rest]


class PeriodWindows:
    """The windows of one period of a :class:`DynamicPoses`, not yet gathered.

    What :func:`~skgesture._multiscale.period_windows` returns for lazy
    windows: ``source`` holds the descriptors the windows read (the sequence's,
    or the resized period's) and ``centres`` the window centres in it.
    :func:`scale_matrix` gathers one scale of many of them into one array.
    """

    def __init__(self, source, centres, steps, n_poses):
        self.source = np.ascontiguousarray(source, dtype=np.float32)
        self.centres = np.asarray(centres, dtype=np.intp)
        self.steps = tuple(steps)
        self.n_poses = n_poses

    def __len__(self):
        return len(self.centres)

    @property
    def shape(self):
        return (len(self), len(self.steps), self.n_poses * self.source.shape[1])

    def __array__(self, dtype=None, copy=None):
        w = dynamic_poses(self.source, self.steps, self.n_poses, self.centres)
        return w if dtype is None else w.astype(dtype, copy=False)

    def take_scale(self, k, out):
        """Write the windows of scale ``k`` into ``out`` (``(n, n_poses * F)``)."""
        idx = _pose_frames(self.centres, self.steps[k], self.n_poses, len(self.source))
        np.take(self.source, idx, axis=0, out=out.reshape(idx.shape + (-1,)))


def scale_matrix(wins, k):
    """Windows of scale ``k`` of a list of period windows, as one C-contiguous
    float32 ``(n_windows, n_poses * n_features)`` array (the input of that
    scale's network): one copy, straight from the descriptors for lazy windows.

    ``wins`` holds dense ``(n, n_scales, width)`` arrays and/or
    :class:`PeriodWindows`.
    """
    width = wins[0].shape[2]
    out = np.empty((sum(len(w) for w in wins), width), dtype=np.float32)
    pos, i = 0, 0
    while i < len(wins):
        w = wins[i]
        if not isinstance(w, PeriodWindows):
            out[pos : pos + len(w)] = w[:, k]
            pos, i = pos + len(w), i + 1
            continue
        # Consecutive periods of one sequence: one gather for all of them.
        j = i + 1
        while (
            j < len(wins)
            and isinstance(wins[j], PeriodWindows)
            and wins[j].source is w.source
        ):
            j += 1
        group = PeriodWindows(
            w.source,
            np.concatenate([v.centres for v in wins[i:j]]),
            w.steps,
            w.n_poses,
        )
        group.take_scale(k, out[pos : pos + len(group)])
        pos, i = pos + len(group), j
    return out


def check_lazy_windows(X, steps, n_poses, estimator, reset):
    """Validate a list of :class:`DynamicPoses` for a classifier of ``steps``.

    Returns True when every sequence is a :class:`DynamicPoses` of these steps
    (the classifier then reads its descriptors), False when none is lazy, and
    raises when they disagree with ``steps`` or with the frame shape of ``fit``.
    A mixed list is refused as well: pass one kind.
    """
    lazy = [isinstance(x, DynamicPoses) for x in X]
    if not any(lazy):
        return False
    if not all(lazy):
        raise TypeError(
            "X mixes lazy DynamicPoses and dense window arrays: give one kind "
            "(DynamicPoseWindow(lazy=True) or lazy=False for every sequence)"
        )
    for i, W in enumerate(X):
        if W.steps != tuple(steps) or W.n_poses != n_poses:
            raise ValueError(
                f"X[{i}] does not hold dynamic poses with steps={tuple(steps)} "
                f"and n_poses={n_poses} (the classifier's): they were built with "
                f"steps={W.steps} and n_poses={W.n_poses}. The window stage and "
                f"the classifier must use the same steps, e.g. "
                f"pipe.set_params(windows__steps=s, classifier__steps=s)"
            )
    shapes = {W.shape[1:] for W in X}
    if len(shapes) > 1:
        raise ValueError(
            f"X has sequences with frames of different shapes {sorted(shapes)}: "
            f"all sequences must agree"
        )
    (shape,) = shapes
    if reset:
        estimator.frame_shape_in_ = shape
        estimator.n_features_in_ = int(np.prod(shape))
    elif shape != estimator.frame_shape_in_:
        raise ValueError(
            f"X has frames of shape {shape}; expected {estimator.frame_shape_in_} "
            f"(as seen in fit)"
        )
    return True


class DynamicPoseWindow(
    NewParamsMixin,
    StreamableMixin,
    SequenceOutputMixin,
    TransformerMixin,
    BaseEstimator,
    auto_wrap_output_keys=None,
):
    """Dynamic poses: the descriptors at ``t - s``, ``t``, ``t + s`` for every frame.

    For each frame ``t`` and each time step ``s`` in ``steps`` this concatenates
    ``n_poses`` descriptors centred on ``t`` (docs/method.md §5.1, §6.2), so with the
    paper's 183-D descriptor and 3 poses each window has 549 values. Frames
    beyond the ends of a sequence repeat its first / last frame. A masked input
    (rest rows masked by :class:`ActivitySegmenter`) gives a masked output with
    the same rows masked.

    The windows of every frame are computed; :class:`MultiScaleClassifier` takes
    them at stride 2 inside each period of activity and resizes periods too
    short for 5 windows, as the paper does. The windows describe their own
    steps (the middle pose of every scale is the frame's own descriptor), and
    :class:`MultiScaleClassifier` checks them against its ``steps`` in ``fit``
    and ``predict``.

    Values must be finite and at most 1e30 in magnitude, so the float32 output
    cannot overflow. ``set_output`` is refused (the output is a list of 3-D
    arrays); :meth:`get_feature_names_out` names the values of a flattened
    frame.

    Parameters
    ----------
    steps : tuple of int, default=(4,)
        Time step of each scale: ``(4,)`` for Method A, ``(4, 3, 2)`` for B.
    n_poses : int, default=3
        Descriptors per dynamic pose (odd).
    lazy : bool, default=False
        Return :class:`~skgesture._windows.DynamicPoses` (the float32
        descriptors and the layout; windows gathered on demand) instead of
        dense window arrays. Same windows and same predictions, without the
        ``n_scales * n_poses`` copies of every descriptor; ``make_method_a``
        and ``make_method_b`` use it (docs/scale.md).

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
    The dense output is float32: ``len(steps) * n_poses * n_features * 4``
    bytes per frame (6.6 KB for Method B on 183-D descriptors); the lazy one
    holds ``n_features * 4`` bytes per frame (0.7 KB).

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
        "steps": [SequenceOf.ints(1)],
        "n_poses": [Interval(Integral, 1, None, closed="left")],
        "lazy": ["boolean"],
    }

    def __init__(self, *, steps=STEPS_A, n_poses=N_POSES, lazy=False):
        self.steps = steps
        self.n_poses = n_poses
        self.lazy = lazy

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
            float32 windows (masked arrays where the input was masked), or
            :class:`~skgesture._windows.DynamicPoses` with ``lazy=True``.
        """
        check_is_fitted(self)
        steps = check_steps(self.steps, self.n_poses)
        data = check_sequences(X, ndim=2, estimator=self, reset=False)
        if getattr(self, "lazy", False):  # getattr: models pickled before it
            return [
                DynamicPoses(
                    d,
                    steps,
                    self.n_poses,
                    untracked_rows(x) if isinstance(x, np.ma.MaskedArray) else None,
                )
                for x, d in zip(X, data)
            ]
        out = []
        for x, d in zip(X, data):
            w = dynamic_poses(d, steps, self.n_poses)
            if isinstance(x, np.ma.MaskedArray):
                rows = untracked_rows(x)  # a row with any masked value is rest
                w = np.ma.MaskedArray(
                    w, mask=np.repeat(rows, w[0].size).reshape(w.shape)
                )
            out.append(w)
        return out

    def get_feature_names_out(self, input_features=None):
        """Names of the values of one output frame, flattened in C order.

        Parameters
        ----------
        input_features : array-like of str or None, default=None
            Names of the input features (e.g. ``PoseDescriptor``'s); ``None``
            gives ``x0, x1, ...``.

        Returns
        -------
        ndarray of str of shape (n_scales * n_poses * n_features_in_,)
            ``"step{s}_t{offset:+d}_{name}"``: the feature ``name`` at
            ``offset = (j - middle) * s`` frames from the centre, for scale
            ``s`` and pose ``j``; reshaped to ``(n_scales, n_poses *
            n_features_in_)`` it matches a frame of :meth:`transform`.

        Examples
        --------
        >>> import numpy as np
        >>> from skgesture import DynamicPoseWindow
        >>> win = DynamicPoseWindow(steps=(4,)).fit([np.zeros((5, 2))])
        >>> win.get_feature_names_out().tolist()
        ['step4_t-4_x0', 'step4_t-4_x1', 'step4_t+0_x0', 'step4_t+0_x1', \
'step4_t+4_x0', 'step4_t+4_x1']
        """
        check_is_fitted(self)
        names = _check_feature_names_in(self, input_features)
        steps = check_steps(self.steps, self.n_poses)
        half = (self.n_poses - 1) // 2
        out = [
            f"step{s}_t{j * s:+d}_{name}"
            for s in steps
            for j in range(-half, half + 1)
            for name in names
        ]
        return np.asarray(out, dtype=object)

    def __sklearn_tags__(self):
        return sequence_tags(super().__sklearn_tags__())

    # -- incremental step (docs/design.md, "Incremental steps") ----------------

    _stream_options = ()

    def _stream_state(self):
        """A fresh state for one live stream (docs/design.md, "Incremental steps").

        Descriptor rows in; the same rows out at once, with their lazy windows
        (a :class:`DynamicPoses`, ``rows.info["windows"]``), the layout of
        :meth:`transform` (``lazy=True``) on the block. The window of frame
        ``u`` needs ``hw`` frames of future, and the classifier needs to know
        that those frames are still in the period before it reads the window;
        so :class:`MultiScaleClassifier` reads the windows of the centres it
        scores from the ``DynamicPoses`` of its period. Dense windows of every
        frame are never made.

        Returns
        -------
        WindowStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        check_is_fitted(self)
        return WindowStream(check_steps(self.steps, self.n_poses), self.n_poses)

    @property
    def stream_lookahead(self):
        """Frames of look-ahead of the stream step: 0.

        The rows are handed on at once; the windows' own look-ahead, ``max(steps)
        * (n_poses - 1) // 2``, counts in the classifier's.
        """
        return 0


class WindowStream:
    """State of :meth:`DynamicPoseWindow.stream_step`: the rows, with their
    lazy windows.

    A window centred at frame ``u`` needs the descriptors up to ``u + hw``,
    and the classifier needs to know whether frame ``u + hw`` is still in the
    period before it scores that window. So this stage hands each block of
    descriptor rows on at once with its :class:`DynamicPoses` (the layout of
    the offline ``transform``, ``rows.info["windows"]``), and
    :class:`~skgesture._multiscale._stream.MultiScaleStream` reads the windows
    of the centres it scores from the ``DynamicPoses`` of its period. Dense
    windows of every frame are never made (the classifier reads one window
    every ``stride`` frames of a period).

    Parameters
    ----------
    steps : tuple of int
        Time step of each scale (checked).
    n_poses : int
        Descriptors per dynamic pose.
    """

    def __init__(self, steps, n_poses):
        self.steps = tuple(steps)
        self.n_poses = int(n_poses)

    def step(self, rows):
        windows = DynamicPoses(rows.data, self.steps, self.n_poses, rest=rows.mask)
        info = {**(rows.info or {}), "windows": windows}
        return Rows(windows.descriptors, rows.mask, rows.time, info)

    def flush(self):
        return None

    def held(self):
        return {}
