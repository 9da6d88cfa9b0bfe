"""Shared helpers of the dataset loaders: file reading, table parsing, Bunch building.

Every loader returns the same :class:`sklearn.utils.Bunch` (docs/design.md §1 and §7):
``X`` (list of ``(T_i, 20, 3)`` float64 world positions in metres, Kinect v1 NUI
joint order), ``y`` (list of ``(T_i,)`` int64 per-frame labels, 0 = rest),
``segments`` (list of ``(n_i, 3)`` int64 rows ``(class, start, end)``, 0-based,
``end`` exclusive), ``sample_ids``, ``groups``, ``fps``, ``n_frames``, ``missing``,
``target_names``, ``layout`` and ``DESCR``, plus a few loader-specific keys.

Errors about a file always name the file and, where it makes sense, the 1-based
line, so that a broken download can be found and fixed.
"""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from pathlib import Path

import numpy as np
from sklearn.utils import Bunch

from skgesture.layouts import KINECT_V1, N_COORDS, N_KINECT_JOINTS
from skgesture.utils._segments import segments_to_labels
from skgesture.utils._validation import missing_frames

__all__ = ["DataFileWarning", "DataFormatError"]

LAYOUT_NAME = KINECT_V1.name  # the ``layout`` value of every Bunch
FRAME_SHAPE = (N_KINECT_JOINTS, N_COORDS)  # one frame of ``X``
SEGMENT_COLUMNS = 3  # (class, start, end)
# Positions beyond 10 km cannot come from a skeleton tracker: the file is corrupt.
# (The real data of every loader stays within 5 m of the sensor.)
MAX_ABS_COORDINATE = 1e4
MAX_EXACT_INTEGER = 2**53  # float64 holds every integer up to this exactly


class DataFormatError(ValueError):
    """A data file is malformed: wrong columns, not numbers, out-of-range values.

    Every loader of :mod:`skgesture.datasets` raises it for a file it cannot
    read safely, with a message that names the file and, where it makes sense,
    the 1-based line. It is a :class:`ValueError`, so ``except ValueError`` keeps
    working.

    Parameters
    ----------
    message : str
        The full message (it already names the file and the line).
    file : str or None, default=None
        Name of the offending file (e.g. ``"Sample0001_skeleton.csv"``).
    line : int or None, default=None
        1-based line of the problem in ``file``, None when it is not about one
        line.

    Attributes
    ----------
    file : str or None
        Name of the offending file.
    line : int or None
        1-based line, or None.

    See Also
    --------
    DataFileWarning : For readable but unusual files.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import DataFormatError, read_chalearn_labels
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "Sample0001_labels.csv"
    >>> _ = path.write_text("3,2,6\\n5,7\\n")
    >>> try:
    ...     read_chalearn_labels(path)
    ... except DataFormatError as exc:
    ...     print(exc.file, exc.line, "|", exc)
    Sample0001_labels.csv 2 | Sample0001_labels.csv line 2: expected 3 values, got 2
    >>> tmp.cleanup()
    """

    def __init__(self, message, *, file=None, line=None):
        super().__init__(message)
        self.file = file
        self.line = line

    def __reduce__(self):
        return (_rebuild_error, (type(self), self.args, self.file, self.line))


def _rebuild_error(cls, args, file, line):
    """Unpickle a :class:`DataFormatError` (keyword-only attributes)."""
    return cls(*args, file=file, line=line)


def _format_error(name, line, message):
    """A :class:`DataFormatError` worded ``"{name} line {line}: {message}"``.

    ``line=None`` gives ``"{name}: {message}"``.
    """
    where = name if line is None else f"{name} line {line}"
    return DataFormatError(f"{where}: {message}", file=name, line=line)


class DataFileWarning(UserWarning):
    """A data file was read, but something in it is unusual.

    Raised for padded or truncated skeletons, overlapping labels, all-zero
    skeleton files and similar facts a user should know about.

    See Also
    --------
    skgesture.datasets.load_chalearn : A loader that emits it.

    Examples
    --------
    >>> import warnings
    >>> from skgesture.datasets import DataFileWarning
    >>> issubclass(DataFileWarning, UserWarning)
    True
    """


def _warn(message):
    """Emit a :class:`DataFileWarning` pointing at the user's call site."""
    warnings.warn(message, DataFileWarning, stacklevel=3)


def _check_path(path, what="path"):
    """Return ``path`` as a :class:`~pathlib.Path`, raising if it does not exist."""
    if path is None or isinstance(path, bytes):
        raise TypeError(f"{what} must be a str or os.PathLike, got {path!r}")
    p = Path(path).expanduser()
    if not p.exists():
        raise FileNotFoundError(f"{what} {str(p)!r} does not exist")
    return p


def _decode(data, name):
    """Decode the bytes of a text file, naming the file and line on failure."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise _format_error(
            name,
            line,
            f"not a text file (byte {data[exc.start]:#04x} at offset {exc.start} is "
            f"not valid UTF-8)",
        ) from None


def _read_text(path, name=None):
    """Read a text file, raising ValueError naming it when it is not text.

    ``name`` names the file in the error (default: its base name).
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except IsADirectoryError:
        raise ValueError(f"{str(path)!r} is a folder, expected a file") from None
    return _decode(data, path.name if name is None else name)


def _lines(text):
    """Split text into lines, dropping trailing blank lines (and a BOM)."""
    lines = text.lstrip("\ufeff").splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    return lines


def _parse_table(
    lines,
    n_values,
    name,
    *,
    sep=None,
    dtype=np.float64,
    first_line=1,
    allow_nan=False,
):
    """Parse lines of ``n_values`` separated numbers into a 2-D array.

    Parameters
    ----------
    lines : list of str
        The lines, without newlines.
    n_values : int
        Expected number of values on every line.
    name : str
        File name used in error messages.
    sep : str or None, default=None
        Separator (``None`` = runs of whitespace).
    dtype : dtype, default=np.float64
        ``np.float64`` or ``np.int64``.
    first_line : int, default=1
        1-based file line number of ``lines[0]`` (for error messages).
    allow_nan : bool, default=False
        Accept ``nan`` tokens (float tables only). Infinite values (``inf``, or
        a number beyond the float64 range such as ``1e999``) are always refused.

    Returns
    -------
    ndarray of shape (len(lines), n_values)
        The values.

    Raises
    ------
    DataFormatError
        Naming the file and the 1-based line of the first bad line: a wrong
        number of values, a value that is not a number (an integer for
        ``np.int64``), beyond the int64 range, or not finite.
    """
    rows = [ln.split(sep) for ln in lines]
    lengths = np.fromiter(map(len, rows), dtype=np.int64, count=len(rows))
    bad = np.flatnonzero(lengths != n_values)
    if bad.size:
        i = int(bad[0])
        got = int(lengths[i])
        if sep is not None and not lines[i].strip():
            got = 0
        raise _format_error(
            name,
            i + first_line,
            f"expected {n_values} values, got {got}"
            + (" (empty line)" if got == 0 else ""),
        )
    if not rows:
        return np.zeros((0, n_values), dtype=dtype)
    try:
        values = np.array(rows, dtype=dtype)
    except (ValueError, OverflowError):
        values = None
    if values is not None and values.dtype.kind == "f":
        bad = ~np.isfinite(values)
        if allow_nan:
            bad &= ~np.isnan(values)
        if not bad.any():
            return values
    elif values is not None:
        return values
    _raise_first_bad_value(rows, name, first_line, dtype, allow_nan)
    raise DataFormatError(f"{name}: could not be parsed", file=name)  # pragma: no cover


def _raise_first_bad_value(rows, name, first_line, dtype, allow_nan):
    """Raise the :class:`DataFormatError` of the first unparsable or bad value."""
    integer = np.dtype(dtype).kind == "i"
    int64 = np.iinfo(np.int64)
    for i, row in enumerate(rows):
        for j, value in enumerate(row):
            where = f"value {j + 1} ({value.strip()[:40]!r})"
            try:
                number = int(value) if integer else float(value)
            except ValueError:
                kind = "an integer" if integer else "a number"
                raise _format_error(
                    name, i + first_line, f"{where} is not {kind}"
                ) from None
            if integer and not int64.min <= number <= int64.max:
                raise _format_error(
                    name, i + first_line, f"{where} is beyond the 64-bit integer range"
                )
            if not integer and not (
                np.isfinite(number) or (allow_nan and np.isnan(number))
            ):
                raise _format_error(
                    name,
                    i + first_line,
                    f"{where} is not a finite number (infinite, NaN, or beyond the "
                    f"float64 range)",
                )


def _check_magnitude(values, name, *, first_line=1, columns=None, what="coordinate"):
    """Raise when a position is beyond :data:`MAX_ABS_COORDINATE` (a corrupt file).

    Parameters
    ----------
    values : ndarray of shape (n_lines, n_values)
        Parsed table; row ``i`` is file line ``i + first_line``.
    name : str
        File name used in the message.
    first_line : int, default=1
        1-based file line of ``values[0]``.
    columns : slice, index array or None, default=None
        The columns holding positions (None: all).
    what : str, default="coordinate"
        What the value is, for the message.
    """
    block = values if columns is None else values[:, columns]
    big = np.abs(block) > MAX_ABS_COORDINATE
    if big.any():
        i, j = np.argwhere(big)[0]
        raise _format_error(
            name,
            int(i) + first_line,
            f"{what} {block[i, j]:g} is beyond +-{MAX_ABS_COORDINATE:g} m; skeleton "
            f"positions are metres from the sensor, so the file is corrupt",
        )


def _integer_column(column, name, *, first_line=1, what="value"):
    """Exact int64 copy of a float column of integers (raises naming the line).

    Refuses non-integers and magnitudes beyond 2**53, the largest integers that
    float64 (the parsed values) holds exactly, instead of wrapping.
    """
    bad = (column != np.round(column)) | (np.abs(column) > MAX_EXACT_INTEGER)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise _format_error(
            name,
            i + first_line,
            f"{what} {column[i]:g} is not an integer of at most 2**53 in magnitude",
        )
    return column.astype(np.int64)


def _progress(iterable, *, verbose, desc, total=None):
    """``iterable`` wrapped in a tqdm bar when ``verbose >= 1`` (else unchanged)."""
    if not verbose:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, unit="file", leave=False)


def _require_lines(lines, name, what="data"):
    """Raise a clear ValueError when a file holds no non-blank line."""
    if not lines:
        raise DataFormatError(f"{name} is empty: expected {what}", file=name)


def _sort_and_label(segments, n_frames):
    """Sort segments by start and build per-frame labels (the later one wins).

    Parameters
    ----------
    segments : array-like of shape (n, 3)
        Rows ``(class, start, end)``, 0-based, ``end`` exclusive, valid ranges.
    n_frames : int
        Sequence length.

    Returns
    -------
    segments : ndarray of shape (n, 3)
        The same rows, stably sorted by start.
    y : ndarray of shape (n_frames,)
        Per-frame labels; where segments overlap, the one that starts later
        (or, on equal starts, comes later in the input) wins.
    overlaps : list of (int, int)
        ``(earlier, later)`` pairs of overlapping rows, as indices into the
        *input* rows, for the caller's warning.
    """
    seg = np.asarray(segments, dtype=np.int64).reshape(-1, SEGMENT_COLUMNS)
    order = np.argsort(seg[:, 1], kind="stable")
    seg = seg[order]
    overlaps = []
    for i in range(1, len(seg)):
        earlier = np.flatnonzero(seg[:i, 2] > seg[i, 1])
        if earlier.size:
            overlaps.append((int(order[earlier[0]]), int(order[i])))
    return seg, segments_to_labels(seg, n_frames, on_overlap="later"), overlaps


def _empty_segments():
    return np.zeros((0, SEGMENT_COLUMNS), dtype=np.int64)


def _make_bunch(
    *,
    X,
    y,
    segments,
    sample_ids,
    groups,
    fps,
    target_names,
    descr,
    n_frames=None,
    **extra,
):
    """Build the Bunch every loader returns (see the module docstring)."""
    if n_frames is None:
        n_frames = np.array([len(lab) for lab in y], dtype=np.int64)
    missing = None if X is None else [missing_frames(seq) for seq in X]
    return Bunch(
        X=X,
        y=y,
        segments=segments,
        sample_ids=list(sample_ids),
        groups=np.asarray(groups),
        fps=fps,
        n_frames=np.asarray(n_frames, dtype=np.int64),
        missing=missing,
        target_names=list(target_names),
        layout=LAYOUT_NAME,
        DESCR=descr,
        **extra,
    )


def _descr(title, body, n_sequences, n_frames, n_segments):
    """DESCR text: a title, what was loaded, then the dataset notes."""
    rule = "=" * len(title)
    return (
        f"{title}\n{rule}\n\nLoaded: {n_sequences} sequences, {int(n_frames)} frames, "
        f"{int(n_segments)} labelled segments.\n\n{body.strip()}\n"
    )


def _flag_all_zero(X, sample_ids, what="skeleton"):
    """Warn about sequences whose every frame is missing (all zeros / NaN)."""
    for seq, sid in zip(X, sample_ids):
        if len(seq) and missing_frames(seq).all():
            _warn(
                f"{sid}: every frame of this {what} is all zeros (no tracked "
                f"skeleton); it is kept and its `missing` mask is all True"
            )


def _find_dir(path, *, child, pattern):
    """Resolve a dataset folder that may be given as its parent.

    Returns ``path`` if it holds files matching ``pattern``, else ``path/child``
    if that folder exists and does; raises a clear error otherwise.
    """
    p = _check_path(path)
    if not p.is_dir():
        raise NotADirectoryError(f"{str(p)!r} is not a folder")
    for cand in (p, p / child):
        if cand.is_dir() and any(cand.glob(pattern)):
            return cand
    raise FileNotFoundError(
        f"no {pattern!r} files in {str(p)!r}"
        + (f" nor in its {child!r} subfolder" if child else "")
    )
