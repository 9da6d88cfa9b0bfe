"""Input validation for lists of sequences, shared by every estimator.

One sample is one sequence: ``X`` is a list of ``(n_frames_i, ...)`` arrays and
``y`` a list of per-frame integer label arrays. Errors name the sequence index,
the frame and the expected shape, so a user can find the bad recording.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numbers

import numpy as np
from sklearn.utils._param_validation import Options

__all__ = [
    "check_sequences",
    "check_sequence_labels",
    "missing_frames",
    "untracked_rows",
    "SequenceOf",
    "MAX_ABS_VALUE",
    "MAX_COORDINATE",
]

# The bounds of docs/design.md §1.2 (bad input). Features, windows and network inputs
# stay far inside float32 (3.4e38), so no stage can overflow when it casts them;
# raw skeleton coordinates are metres (or millimetres), so 1e5 is absurd in any
# unit while the descriptor's squared norms stay exact in float64.
MAX_ABS_VALUE = 1e30
MAX_COORDINATE = 1e5


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
    max_abs=MAX_ABS_VALUE,
    first_frame=None,
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
    max_abs : float, default=1e30
        Largest magnitude accepted (``MAX_ABS_VALUE``; ``PoseDescriptor`` passes
        ``MAX_COORDINATE`` = 1e5 for raw coordinates). Values are checked
        before the cast to ``dtype``, so nothing overflows to ``inf`` silently
        (docs/design.md §1.2).
    first_frame : int or None, default=None
        Set for the frames pushed to a live stream (one sequence, the next
        block): the stream index of its first frame. Messages then name the
        offending frame by its stream index (``frame 37 of the stream is
        invalid: ...``) instead of ``X[0] ... at frame 2``.

    Returns
    -------
    list of ndarray
        Validated, C-contiguous copies (or views) of the sequences. The data
        of a ``numpy.ma.MaskedArray`` is validated and returned (its mask is
        not); read :func:`untracked_rows` first to keep it.

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
        where = f"{name}[{i}]"
        if first_frame is not None:
            where = f"frame {first_frame} of the stream is invalid: the block"
        arr = _as_real_array(seq, where)
        if arr.ndim < 2:
            raise ValueError(
                f"{where} has shape {arr.shape}; expected (n_frames, ...) with "
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
            raise ValueError(f"{where} has shape {arr.shape}; expected {expect}")
        if frame_shape is not None:
            fs = tuple(frame_shape)
            ok = len(fs) == arr.ndim - 1 and all(
                e is None or e == a for e, a in zip(fs, arr.shape[1:])
            )
            if not ok:
                raise ValueError(
                    f"{where} has frames of shape {arr.shape[1:]}; expected "
                    f"{fs} (as seen in fit)"
                    if estimator is not None and not reset
                    else f"{where} has frames of shape {arr.shape[1:]}; expected {fs}"
                )
        if arr.shape[0] < min_frames:
            raise ValueError(
                f"{where} has {arr.shape[0]} frames; at least {min_frames} are required"
            )
        _check_values(arr, where, allow_nan, max_abs, first_frame)
        out.append(np.ascontiguousarray(arr, dtype=dtype))
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


def _as_real_array(seq, where):
    """``seq`` as a floating ndarray (bool and int become float64), not yet cast."""
    try:
        arr = np.asarray(seq)
        if arr.dtype.kind == "c":
            raise TypeError(f"complex values (dtype {arr.dtype}) are not real")
        if arr.dtype.kind != "f":
            arr = np.asarray(seq, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"{where} cannot be converted to a numeric array: {exc}"
        ) from None
    return arr


def _check_values(arr, where, allow_nan, max_abs, first_frame=None):
    """Raise a ValueError naming the frame of the first non-finite or absurd value.

    The common case costs two reductions and no temporary array: the minimum and
    the maximum are NaN if a NaN is present (``fmin``/``fmax`` skip NaN when NaN
    is allowed), infinite if an inf is, and beyond ``max_abs`` if any value is.
    The offending frame is only looked for on error. With ``first_frame`` (a
    live stream) the message names the frame by its stream index.
    """
    if arr.size == 0:
        return
    lo_fn, hi_fn = (np.fmin, np.fmax) if allow_nan else (np.minimum, np.maximum)
    lo, hi = float(lo_fn.reduce(arr, axis=None)), float(hi_fn.reduce(arr, axis=None))
    if allow_nan and np.isnan(hi):
        return  # every value is NaN: an untracked sequence
    if -max_abs <= lo and hi <= max_abs:
        return
    flat = arr.reshape(arr.shape[0], -1)
    with np.errstate(invalid="ignore"):
        ok = np.abs(flat) <= max_abs
    if allow_nan:
        ok |= np.isnan(flat)
    frame, col = (int(v[0]) for v in np.nonzero(~ok))
    value = float(flat[frame, col])
    if not np.isfinite(value):
        if allow_nan:
            what, hint = "infinite", "untracked frames are NaN or all zeros, never inf"
        else:
            what, hint = (
                "NaN or infinite",
                (
                    "inputs must be finite: untracked frames are NaN only in raw "
                    "skeletons, which PoseDescriptor fills (and masks)"
                ),
            )
        if first_frame is None:
            where, at = f"{where} contains", f" (first at frame {frame})"
        else:
            where = f"frame {first_frame + frame} of the stream is invalid: it contains"
            at = ""
        raise ValueError(f"{where} {what} values{at}, e.g. {value}; {hint}")
    if first_frame is None:
        where = f"{where} has the value {value:.4g} at frame {frame}"
    else:
        where = (
            f"frame {first_frame + frame} of the stream is invalid: it has the "
            f"value {value:.4g}"
        )
    raise ValueError(
        f"{where}, beyond the accepted magnitude {max_abs:.0e} "
        f"(docs/design.md §1.2): check the units and the recording"
    )


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


def mask_rows(data, rows):
    """``data`` (2-D, one row per frame) with the rows ``rows`` masked.

    The offline form of rest rows (data contract 2): a ``numpy.ma.MaskedArray``
    whose mask covers every value of each masked row, or ``data`` itself when
    no row is masked.
    """
    rows = np.asarray(rows, dtype=bool)
    if not rows.any():
        return data
    return np.ma.MaskedArray(data, mask=np.repeat(rows[:, None], data.shape[1], axis=1))


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


def _is_int(value, low):
    return (
        isinstance(value, numbers.Integral)
        and not isinstance(value, bool)
        and value >= low
    )


class SequenceOf(Options):
    """Parameter constraint: a tuple or list whose every item passes ``item``.

    For ``_parameter_constraints``, so a bad entry of a tuple parameter (a step
    of 2.5, a layer of width 0, an unknown activation) raises sklearn's
    ``InvalidParameterError`` naming the parameter, like any other constraint.
    It subclasses :class:`~sklearn.utils._param_validation.Options` only to be
    accepted by sklearn's ``make_constraint``.

    Parameters
    ----------
    item : callable
        ``item(value) -> bool`` for one entry.
    description : str
        What a valid value is, completing "must be ...".
    allow_empty : bool, default=False
        Whether an empty sequence is valid.
    whole : callable or None, default=None
        ``whole(values) -> bool``, a condition on the entries together.
    arrays : bool, default=False
        Whether a 1-D ndarray is accepted as well as a tuple or list.

    Examples
    --------
    >>> from skgesture.utils._validation import SequenceOf
    >>> steps = SequenceOf.ints(low=1)
    >>> steps.is_satisfied_by((4, 3, 2)), steps.is_satisfied_by((2.5,))
    (True, False)
    >>> str(steps)
    'a non-empty tuple of ints >= 1'
    """

    def __init__(self, item, description, *, allow_empty=False, whole=None,
                 arrays=False):  # fmt: skip
        super().__init__(type=object, options=set())
        self.item = item
        self.description = description
        self.allow_empty = allow_empty
        self.whole = whole
        self.arrays = arrays

    @classmethod
    def ints(cls, low=1, *, allow_empty=False):
        """Tuples of ints ``>= low``."""
        size = "a tuple" if allow_empty else "a non-empty tuple"
        return cls(
            lambda v: _is_int(v, low),
            f"{size} of ints >= {low}",
            allow_empty=allow_empty,
        )

    def is_satisfied_by(self, val):
        if self.arrays and isinstance(val, np.ndarray) and val.ndim == 1:
            val = val.tolist()
        if not isinstance(val, (tuple, list)):
            return False
        if not val and not self.allow_empty:
            return False
        if not all(self.item(v) for v in val):
            return False
        return self.whole is None or bool(self.whole(val))

    def __str__(self):
        return self.description


class SequenceOutputMixin:
    """``set_output`` of a sequence stage, which returns lists of sequences.

    Put before ``TransformerMixin`` in the bases: the one ``set_output`` of
    every stage (:func:`refuse_set_output`).
    """

    def set_output(self, *, transform=None):
        """Refuse a DataFrame output: a list of sequences has none.

        Parameters
        ----------
        transform : {"default"} or None, default=None
            Only ``"default"`` and ``None`` (no change) are accepted.

        Returns
        -------
        self : object
            This estimator, unchanged.

        Raises
        ------
        ValueError
            For ``"pandas"``, ``"polars"`` or any other container. Wrap one
            sequence's features yourself, e.g.
            ``pandas.DataFrame(Xt[i], columns=stage.get_feature_names_out())``.
        """
        return refuse_set_output(self, transform)


def refuse_set_output(estimator, transform):
    """``set_output`` of a sequence stage: only the default container exists.

    The stages of skgesture return lists of per-sequence arrays (masked where
    frames are rest), which no DataFrame holds; sklearn's automatic output
    wrapping is off for them, so a global ``transform_output`` setting leaves
    them unchanged, and an explicit request is refused here.
    """
    if transform is None or transform == "default":
        return estimator
    name = type(estimator).__name__
    raise ValueError(
        f"{name}.set_output(transform={transform!r}) is not supported: {name} "
        f"returns a list of per-sequence arrays (one per recording), which has no "
        f"{transform!r} form. Keep transform='default' and wrap one sequence "
        f"yourself, e.g. pandas.DataFrame(Xt[i], "
        f"columns=stage.get_feature_names_out())"
    )


def check_skeletons(X, *, estimator=None, reset=True, name="X", first_frame=None):
    """Validate raw Kinect v1 skeleton sequences ``(n_frames_i, 20, 3)``.

    The input rule of every stage that reads raw skeletons: a masked value of a
    ``numpy.ma.MaskedArray`` marks an untracked joint and becomes NaN (so its
    frame is untracked whatever lies under the mask); NaN is allowed; every
    other value must be finite and at most ``MAX_COORDINATE`` in magnitude.

    Parameters
    ----------
    X : list of array-like of shape (n_frames_i, 20, 3)
        Skeleton sequences.
    estimator : estimator or None, default=None
        Passed to :func:`check_sequences` (``frame_shape_in_`` and
        ``n_features_in_`` are set or checked).
    reset : bool, default=True
        Whether this call is a ``fit``.
    name : str, default="X"
        Name used in error messages.
    first_frame : int or None, default=None
        Stream index of the first frame, for frames pushed to a live stream
        (see :func:`check_sequences`).

    Returns
    -------
    list of ndarray of shape (n_frames_i, 20, 3)
        float64 copies, NaN where a joint is untracked.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.utils._validation import check_skeletons
    >>> seq = np.ma.masked_array(np.ones((2, 20, 3)))
    >>> seq[1, 4] = np.ma.masked
    >>> out = check_skeletons([seq])
    >>> bool(np.isnan(out[0][1, 4]).all()), bool(np.isnan(out[0][0]).any())
    (True, False)
    """
    from skgesture.layouts import KINECT_V1, N_COORDS

    if isinstance(X, (list, tuple)):
        X = [
            np.ma.filled(np.ma.asarray(seq, dtype=float), np.nan)
            if isinstance(seq, np.ma.MaskedArray)
            else seq
            for seq in X
        ]
    return check_sequences(
        X,
        frame_shape=(KINECT_V1.n_joints, N_COORDS),
        ndim=3,
        allow_nan=True,
        estimator=estimator,
        reset=reset,
        max_abs=MAX_COORDINATE,
        name=name,
        first_frame=first_frame,
    )


def check_stream_frames(frames, first, estimator):
    """Validate raw frames pushed to a stream as offline input is validated.

    The rule of :func:`check_skeletons` (every stage reading raw skeletons
    shares it), on one block of frames whose first has stream index
    ``first``: a bad frame raises a ``ValueError`` naming its stream index.

    Parameters
    ----------
    frames : array-like of shape (n, 20, 3)
        The next raw frames; masked values mark untracked joints.
    first : int
        Stream index of ``frames[0]``.
    estimator : estimator
        The fitted first stage (its ``frame_shape_in_`` is enforced).

    Returns
    -------
    ndarray of shape (n, 20, 3)
        float64, NaN where a joint is untracked.
    """
    return check_skeletons(
        [frames], estimator=estimator, reset=False, first_frame=int(first)
    )[0]


def sequence_tags(tags, *, raw_skeletons=False):
    """scikit-learn tags of a stage whose input is a list of sequences.

    Not 2-D arrays but 3-D-like sequences; a stage reading raw skeletons also
    allows NaN (untracked joints) and needs fitting.

    Parameters
    ----------
    tags : sklearn.utils.Tags
        The tags of the base classes (``super().__sklearn_tags__()``).
    raw_skeletons : bool, default=False
        Whether the stage reads raw skeletons ``(n_frames, 20, 3)``.

    Returns
    -------
    sklearn.utils.Tags
        ``tags``, updated.
    """
    tags.input_tags.two_d_array = False
    tags.input_tags.three_d_array = True
    if raw_skeletons:
        tags.input_tags.allow_nan = True
        tags.requires_fit = True
    return tags
