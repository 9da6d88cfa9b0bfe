"""Input validation for lists of sequences, shared by every estimator.

One sample is one sequence: ``X`` is a list of ``(n_frames_i, ...)`` arrays and
``y`` a list of per-frame integer label arrays. Errors name the sequence index,
the frame and the expected shape, so a user can find the bad recording.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numbers

import numpy as np

__all__ = [
    "check_sequences",
    "check_sequence_labels",
    "missing_frames",
    "untracked_rows",
]


def _describe(obj):
    if isinstance(obj, np.ndarray):
        return f"array of shape {obj.shape}"
    return type(obj).__name__


def check_sequences(
    X,
    *,
    frame_shape=None,
    ndim=None,
    allow_nan=False,
    min_frames=1,
    estimator=None,
    reset=True,
    dtype=np.float64,
    name="X",
):
    """Validate a list of sequences and return it as a list of float arrays.

    Parameters
    ----------
    X : list of array-like of shape (n_frames_i, ...)
        The sequences. A single 2-D/3-D ndarray is refused: wrap it in a list.
    frame_shape : tuple or None, default=None
        Expected shape of one frame, e.g. ``(20, 3)`` or ``(183,)``; ``None``
        entries are free. With ``estimator`` and ``reset=False`` the shape seen
        in ``fit`` (``estimator.frame_shape_in_``) is enforced instead.
    ndim : int or None, default=None
        Expected number of dimensions of each sequence (frames included).
    allow_nan : bool, default=False
        Whether NaN values are allowed (untracked skeleton frames).
    min_frames : int, default=1
        Minimum number of frames per sequence.
    estimator : estimator or None, default=None
        With ``reset=True`` its ``frame_shape_in_`` and ``n_features_in_`` are set;
        with ``reset=False`` they are checked.
    reset : bool, default=True
        Whether this call is a ``fit``.
    dtype : dtype, default=np.float64
        Output dtype.
    name : str, default="X"
        Name used in error messages.

    Returns
    -------
    list of ndarray
        Validated, C-contiguous copies (or views) of the sequences.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils import check_sequences
    >>> [s.shape for s in check_sequences([np.zeros((4, 2)), np.ones((3, 2))])]
    [(4, 2), (3, 2)]
    """
    if isinstance(X, np.ndarray) and X.dtype != object:
        raise TypeError(
            f"{name} must be a list of sequences (one array per recording), got a "
            f"single {_describe(X)}; wrap a single sequence as [{name}]"
        )
    if isinstance(X, (str, bytes)) or not hasattr(X, "__len__"):
        raise TypeError(f"{name} must be a list of sequences, got {_describe(X)}")
    if len(X) == 0:
        raise ValueError(f"{name} is empty: at least one sequence is required")
    if estimator is not None and not reset:
        frame_shape = getattr(estimator, "frame_shape_in_", frame_shape)
    out = []
    for i, seq in enumerate(X):
        if isinstance(seq, np.ma.MaskedArray):
            seq = seq.data
        try:
            arr = np.asarray(seq, dtype=dtype)
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"{name}[{i}] cannot be converted to a numeric array: {exc}"
            ) from None
        if arr.ndim < 2:
            raise ValueError(
                f"{name}[{i}] has shape {arr.shape}; expected (n_frames, ...) with "
                f"at least 2 dimensions"
            )
        if ndim is not None and arr.ndim != ndim:
            expect = (
                "(n_frames, "
                + ", ".join(
                    str(s) if s is not None else "?"
                    for s in (frame_shape or (None,) * (ndim - 1))
                )
                + ")"
            )
            raise ValueError(f"{name}[{i}] has shape {arr.shape}; expected {expect}")
        if frame_shape is not None:
            fs = tuple(frame_shape)
            ok = len(fs) == arr.ndim - 1 and all(
                e is None or e == a for e, a in zip(fs, arr.shape[1:])
            )
            if not ok:
                raise ValueError(
                    f"{name}[{i}] has frames of shape {arr.shape[1:]}; expected "
                    f"{fs} (as seen in fit)"
                    if estimator is not None and not reset
                    else f"{name}[{i}] has frames of shape {arr.shape[1:]}; "
                    f"expected {fs}"
                )
        if arr.shape[0] < min_frames:
            raise ValueError(
                f"{name}[{i}] has {arr.shape[0]} frames; at least {min_frames} "
                f"are required"
            )
        if not allow_nan:
            bad = ~np.isfinite(arr.reshape(arr.shape[0], -1))
            if bad.any():
                frame = int(np.flatnonzero(bad.any(axis=1))[0])
                raise ValueError(
                    f"{name}[{i}] contains NaN or infinite values (first at frame "
                    f"{frame}); fill untracked frames first (PoseDescriptor does)"
                )
        elif np.isinf(arr).any():
            frame = int(
                np.flatnonzero(np.isinf(arr.reshape(arr.shape[0], -1)).any(1))[0]
            )
            raise ValueError(f"{name}[{i}] contains infinite values (frame {frame})")
        out.append(np.ascontiguousarray(arr))
    if estimator is not None and reset:
        estimator.frame_shape_in_ = tuple(out[0].shape[1:])
        estimator.n_features_in_ = int(np.prod(out[0].shape[1:]))
        for i, arr in enumerate(out):
            if arr.shape[1:] != estimator.frame_shape_in_:
                raise ValueError(
                    f"{name}[{i}] has frames of shape {arr.shape[1:]}, but {name}[0] "
                    f"has {estimator.frame_shape_in_}: all sequences must agree"
                )
    return out


def check_sequence_labels(y, X=None, *, n_classes=None, name="y"):
    """Validate per-frame labels and return them as a list of int64 arrays.

    Parameters
    ----------
    y : list of array-like of shape (n_frames_i,)
        Per-frame labels: 0 is rest, 1..K gesture classes.
    X : list of ndarray or None, default=None
        If given, every ``y[i]`` must have ``len(X[i])`` frames.
    n_classes : int or None, default=None
        If given, labels must lie in ``0..n_classes``.
    name : str, default="y"
        Name used in error messages.

    Returns
    -------
    list of ndarray of shape (n_frames_i,)
        The labels as int64.

    Examples
    --------
    >>> from skgesture.utils import check_sequence_labels
    >>> check_sequence_labels([[0, 1, 1]])[0].tolist()
    [0, 1, 1]
    """
    if y is None:
        raise ValueError(f"{name} is required: a list of per-frame label arrays")
    if isinstance(y, np.ndarray) and y.dtype != object and y.ndim != 2:
        raise TypeError(
            f"{name} must be a list of per-frame label arrays (one per sequence), "
            f"got a single {_describe(y)}"
        )
    if len(y) == 0:
        raise ValueError(f"{name} is empty: at least one sequence is required")
    if X is not None and len(X) != len(y):
        raise ValueError(
            f"X has {len(X)} sequences but {name} has {len(y)}: give one label "
            f"array per sequence"
        )
    out = []
    for i, lab in enumerate(y):
        arr = np.asarray(lab)
        if arr.ndim != 1:
            raise ValueError(f"{name}[{i}] has shape {arr.shape}; expected (n_frames,)")
        if arr.size and not np.issubdtype(arr.dtype, np.integer):
            if (
                not np.issubdtype(arr.dtype, np.number)
                or not np.all(np.isfinite(arr))
                or np.any(arr != np.round(arr))
            ):
                raise ValueError(
                    f"{name}[{i}] must hold integer class labels (0 = rest), got "
                    f"dtype {arr.dtype}"
                )
        arr = arr.astype(np.int64)
        if X is not None and len(arr) != len(X[i]):
            raise ValueError(
                f"{name}[{i}] has {len(arr)} labels but X[{i}] has {len(X[i])} frames"
            )
        if arr.size and arr.min() < 0:
            frame = int(np.argmax(arr < 0))
            raise ValueError(
                f"{name}[{i}] has a negative label {arr[frame]} at frame {frame}; "
                f"labels are 0 (rest) or 1..K"
            )
        if n_classes is not None and arr.size and arr.max() > n_classes:
            frame = int(np.argmax(arr > n_classes))
            raise ValueError(
                f"{name}[{i}] has label {arr[frame]} at frame {frame}, out of range "
                f"0..{n_classes}"
            )
        out.append(arr)
    return out


def missing_frames(seq):
    """Boolean mask of untracked frames (all zeros, or any NaN) of one sequence.

    Parameters
    ----------
    seq : ndarray of shape (n_frames, n_joints, 3) or (n_frames, n_features)
        One sequence.

    Returns
    -------
    ndarray of shape (n_frames,)
        True where the frame is missing.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils import missing_frames
    >>> seq = np.ones((3, 20, 3)); seq[1] = 0; seq[2, 4, 0] = np.nan
    >>> missing_frames(seq).tolist()
    [False, True, True]
    """
    flat = np.asarray(seq, dtype=float).reshape(len(seq), -1)
    return np.isnan(flat).any(axis=1) | ~np.any(flat != 0, axis=1)


def untracked_rows(x):
    """Boolean mask of the untracked frames of one sequence, raw or described.

    The toolkit-wide rule is that an untracked frame is rest, in every model and
    in streaming. A described sequence carries its untracked frames as the
    masked rows of a ``numpy.ma.MaskedArray``; a raw one as all-zero or NaN
    frames.

    Parameters
    ----------
    x : ndarray or MaskedArray of shape (n_frames, ...)
        One sequence.

    Returns
    -------
    ndarray of bool of shape (n_frames,)
        True where the frame is untracked.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils._validation import untracked_rows
    >>> feats = np.ma.masked_array(np.ones((3, 2)), mask=[[0, 0], [1, 1], [0, 0]])
    >>> untracked_rows(feats).tolist()
    [False, True, False]
    >>> untracked_rows(np.zeros((2, 20, 3))).tolist()
    [True, True]
    """
    if isinstance(x, np.ma.MaskedArray):
        mask = np.ma.getmaskarray(x)
        return mask.reshape(len(mask), -1).any(axis=1)
    return missing_frames(x)


def check_positive_int(value, name):
    """Return ``value`` as int, raising a ValueError naming ``name`` otherwise."""
    if not isinstance(value, numbers.Integral) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)
