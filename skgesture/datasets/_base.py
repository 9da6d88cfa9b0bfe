"""Shared helpers of the dataset loaders: file reading, table parsing, Bunch building.

Every loader returns the same :class:`sklearn.utils.Bunch` (DESIGN §1 and §7):
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

__all__ = ["DataFileWarning"]

LAYOUT_NAME = KINECT_V1.name  # the ``layout`` value of every Bunch
FRAME_SHAPE = (N_KINECT_JOINTS, N_COORDS)  # one frame of ``X``
SEGMENT_COLUMNS = 3  # (class, start, end)


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
        raise ValueError(
            f"{name} line {line}: not a text file (byte {data[exc.start]:#04x} at "
            f"offset {exc.start} is not valid UTF-8)"
        ) from None


def _read_text(path):
    """Read a text file, raising ValueError naming it when it is not text."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except IsADirectoryError:
        raise ValueError(f"{str(path)!r} is a folder, expected a file") from None
    return _decode(data, path.name)


def _lines(text):
    """Split text into lines, dropping trailing blank lines (and a BOM)."""
    lines = text.lstrip("\ufeff").splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    return lines


def _parse_table(lines, n_values, name, *, sep=None, dtype=np.float64, first_line=1):
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

    Returns
    -------
    ndarray of shape (len(lines), n_values)
        The values.

    Raises
    ------
    ValueError
        Naming the file and the 1-based line of the first bad line.
    """
    rows = [ln.split(sep) for ln in lines]
    lengths = np.fromiter(map(len, rows), dtype=np.int64, count=len(rows))
    bad = np.flatnonzero(lengths != n_values)
    if bad.size:
        i = int(bad[0])
        got = int(lengths[i])
        if sep is not None and not lines[i].strip():
            got = 0
        raise ValueError(
            f"{name} line {i + first_line}: expected {n_values} values, got {got}"
            + (" (empty line)" if got == 0 else "")
        )
    if not rows:
        return np.zeros((0, n_values), dtype=dtype)
    try:
        return np.array(rows, dtype=dtype)
    except ValueError:
        pass
    convert = int if np.dtype(dtype).kind == "i" else float
    kind = "an integer" if convert is int else "a number"
    for i, row in enumerate(rows):
        for j, value in enumerate(row):
            try:
                convert(value)
            except ValueError:
                raise ValueError(
                    f"{name} line {i + first_line}: value {j + 1} ({value.strip()!r}) "
                    f"is not {kind}"
                ) from None
    raise ValueError(f"{name}: could not be parsed")  # pragma: no cover


def _require_lines(lines, name, what="data"):
    """Raise a clear ValueError when a file holds no non-blank line."""
    if not lines:
        raise ValueError(f"{name} is empty: expected {what}")


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
