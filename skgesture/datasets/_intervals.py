"""Interval annotation files and class-names files of your own recordings.

An interval file has one ``start,end,label`` line per gesture (optionally under
a header naming the columns); labels are class numbers or the names of a
class-names file (line ``k`` names class ``k``). Frames are 0-based with an
exclusive end by default, or 1-based and inclusive (ChaLearn style).
``docs/recordings.md`` describes the files;
:func:`~skgesture.datasets.load_recordings` reads them next to each skeleton file.
"""

# SPDX-License-Identifier: BSD-3-Clause

import csv
import io
import os
import re
from numbers import Integral
from pathlib import Path

import numpy as np
from sklearn.utils._param_validation import Interval, StrOptions, validate_params

from skgesture.datasets._base import (
    MAX_EXACT_INTEGER,
    DataFormatError,
    _check_path,
    _format_error,
    _lines,
    _read_text,
)
from skgesture.datasets._skeleton_csv import _detect_delimiter, _is_number
from skgesture.utils._segments import labels_to_segments

__all__ = ["read_intervals", "write_intervals"]

CLASSES_FILE = "classes.txt"  # class names of a recordings folder
REST_NAME = "rest"  # the label name of class 0 (no gesture)
# Class numbers above this need class names (no typo makes 10**9 class names).
MAX_NUMBERED_CLASSES = 1000
_INT_RE = re.compile(r"^[+-]?[0-9]+$")
_INTERVAL_COLUMNS = {
    "start": ("start", "begin", "start_frame", "from"),
    "end": ("end", "stop", "end_frame", "to"),
    "label": ("label", "class", "gesture", "action", "name"),
}
_END_OPTIONS = ("exclusive", "inclusive")


# ----------------------------------------------------------------------------
# Class names and interval files
# ----------------------------------------------------------------------------


def _read_class_names(path):
    """Class names of a class-names file: line ``k`` names class ``k``."""
    name = path.name
    lines = _lines(_read_text(path))
    if not lines:
        raise DataFormatError(
            f"{name} is empty: expected one class name per line", file=name
        )
    names = []
    for i, line in enumerate(lines, start=1):
        label = line.strip()
        if not label:
            raise _format_error(
                name, i, "empty line (line k names class k; no gaps allowed)"
            )
        names.append(label)
    return _check_class_names(names, name)


def _check_class_names(names, where):
    seen = set()
    for k, label in enumerate(names, start=1):
        line = k if where != "classes" else None
        if _INT_RE.match(label):
            raise _format_error(
                where, line, f"class name {label!r} is a number; names must not be"
            )
        if label.lower() == REST_NAME:
            raise _format_error(
                where,
                line,
                f"{label!r} names class 0 (no gesture) and cannot name class {k}",
            )
        if label in seen:
            raise _format_error(where, line, f"class name {label!r} appears twice")
        seen.add(label)
    return list(names)


def _class_names(classes):
    """``list of names`` (``names[k - 1]`` is class ``k``) or None."""
    if classes is None:
        return None
    if isinstance(classes, (str, os.PathLike)):
        return _read_class_names(_check_path(classes, "class-names file"))
    if not all(isinstance(c, str) for c in classes):
        raise TypeError("classes must be a file or a list of class names (str)")
    return _check_class_names([c.strip() for c in classes], "classes")


def _csv_rows(lines, sep):
    """Values of each line (quoted values may hold the separator)."""
    if sep is None:
        return [ln.split() for ln in lines]
    return [[t.strip() for t in row] for row in csv.reader(lines, delimiter=sep)]


def _read_interval_rows(path, name=None):
    """``[(line, start, end, label token)]`` of an interval file (ints unchecked).

    ``name`` names the file in messages (default: its base name).
    """
    name = path.name if name is None else name
    lines = _lines(_read_text(path, name=name))
    numbered = [(i, ln) for i, ln in enumerate(lines, start=1) if ln.strip()]
    if not numbered:
        return []
    sep = _detect_delimiter(numbered[0][1], None)
    try:
        rows = _csv_rows([ln for _, ln in numbered], sep)
    except csv.Error as exc:
        raise DataFormatError(f"{name}: not a readable CSV file ({exc})", file=name)
    columns, width = (0, 1, 2), 3
    first = rows[0]
    if len(first) >= 2 and not (_is_number(first[0]) or _is_number(first[1])):
        heads = [h.lower().replace(" ", "_") for h in first]
        columns = tuple(
            min((k for k, h in enumerate(heads) if h in synonyms), default=-1)
            for synonyms in _INTERVAL_COLUMNS.values()
        )
        if -1 in columns:
            raise _format_error(
                name,
                numbered[0][0],
                f"expected a header naming the columns start, end and label, or a "
                f"first line 'start,end,label' of numbers, got {numbered[0][1][:60]!r}",
            )
        width = len(first)
        numbered, rows = numbered[1:], rows[1:]
    out = []
    for (i, _), row in zip(numbered, rows):
        if len(row) != width:
            raise _format_error(
                name,
                i,
                f"expected {width} values (start, end, label), got {len(row)}",
            )
        start, end, label = (row[c] for c in columns)
        for what, token in (("start", start), ("end", end)):
            if not _INT_RE.match(token):
                raise _format_error(
                    name, i, f"{what} frame {token[:40]!r} is not an integer"
                )
            if abs(int(token)) > MAX_EXACT_INTEGER:
                raise _format_error(
                    name, i, f"{what} frame {token[:40]} is beyond 2**53"
                )
        if not label:
            raise _format_error(name, i, "empty label")
        out.append((i, int(start), int(end), label))
    return out


def _convert_frames(rows, name, base, end, n_frames):
    """0-based, end-exclusive ``(line, start, end, label)`` rows, checked."""
    out = []
    for i, s, e, label in rows:
        start = s - base
        stop = e - base + (1 if end == "inclusive" else 0)
        if start < 0:
            why = f"start frame {s} is before the first frame {base}"
        elif stop <= start:
            why = (
                f"end frame {e} is before start frame {s}"
                if end == "inclusive"
                else f"end frame {e} is not after start frame {s} (the end is "
                f"exclusive)"
            )
        elif n_frames is not None and stop > n_frames:
            last = n_frames - 1 + base + (0 if end == "inclusive" else 1)
            why = (
                f"end frame {e} is beyond the recording ({n_frames} frames: the "
                f"largest {end} end is {last})"
            )
        else:
            out.append((i, start, stop, label))
            continue
        raise _format_error(name, i, why)
    return out


def _label_ids(rows, name, ids):
    """Class id of each row's label (ints, or names through ``ids``)."""
    out = []
    for i, _, _, label in rows:
        if _INT_RE.match(label):
            value = int(label)
            if value < 0:
                raise _format_error(name, i, f"label {value} is negative (0 = rest)")
            if ids is None and value > MAX_NUMBERED_CLASSES:
                raise _format_error(
                    name,
                    i,
                    f"label {label[:40]} is above {MAX_NUMBERED_CLASSES}; number "
                    f"classes 1..K, or give class names (`classes`)",
                )
            if ids is not None and value > len(ids):
                raise _format_error(
                    name,
                    i,
                    f"label {value} is beyond the {len(ids)} named classes",
                )
            out.append(value)
        elif label.lower() == REST_NAME and (ids is None or label not in ids):
            out.append(0)
        elif ids is not None and label in ids:
            out.append(ids[label])
        else:
            known = "" if ids is None else f" (known: {', '.join(list(ids)[:8])}...)"
            raise _format_error(
                name,
                i,
                f"label {label[:40]!r} is not a class name{known}; give the class "
                f"names (`classes`, or a {CLASSES_FILE} file)",
            )
    return out


def _check_frame_options(base, end):
    if base not in (0, 1) or isinstance(base, bool):
        raise ValueError(f"base must be 0 or 1, got {base!r}")
    if end not in _END_OPTIONS:
        raise ValueError(f"end must be 'exclusive' or 'inclusive', got {end!r}")


_FRAMES_DOC = """base : {0, 1}, default=0
        Number of the first frame in the file: 0 (frame ``k`` is the ``k``-th
        line of the skeleton file counted from 0) or 1 (ChaLearn style).
    end : {"exclusive", "inclusive"}, default="exclusive"
        Whether the end frame of an interval is the first frame after the
        gesture (``"exclusive"``, a Python slice) or its last frame
        (``"inclusive"``, ChaLearn style)."""


@validate_params(
    {
        "file": [str, os.PathLike],
        "classes": [list, tuple, str, os.PathLike, None],
        "base": [Interval(Integral, 0, 1, closed="both")],
        "end": [StrOptions(set(_END_OPTIONS))],
        "n_frames": [Interval(Integral, 1, None, closed="left"), None],
    },
    prefer_skip_nested_validation=True,
)
def read_intervals(file, *, classes=None, base=0, end="exclusive", n_frames=None):
    """Read an interval annotation file into segments.

    An interval file has one ``start,end,label`` line per gesture and an
    optional header naming the columns (``start``, ``end``, ``label``, in any
    order; extra columns are ignored). Labels are class numbers (``1..K``;
    ``0`` is rest) or class names.

    Parameters
    ----------
    file : str or path-like
        The interval file (comma, tab, semicolon or blank separated).
    classes : list of str, str or path-like, or None, default=None
        Class names: ``classes[k - 1]`` names class ``k``, or a class-names
        file with one name per line (line ``k`` names class ``k``). Needed
        when the file labels gestures by name. The name ``rest`` means 0.
    {frames}
    n_frames : int or None, default=None
        Length of the recording; an interval beyond it raises.

    Returns
    -------
    ndarray of shape (n_gestures, 3)
        Rows ``(class, start, end)``, 0-based, ``end`` exclusive, int64, in
        file order (intervals labelled rest are left out).

    Raises
    ------
    DataFormatError
        Naming the file and 1-based line: a malformed line, a frame that is
        not an integer, an empty or reversed interval, one beyond ``n_frames``
        or before the first frame, an unknown class name.

    See Also
    --------
    write_intervals : The writer.
    load_recordings : Read a folder of recordings with their annotations.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import read_intervals
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take1.labels.csv"
    >>> _ = path.write_text("start,end,label\\n3,10,wave\\n12,20,point\\n")
    >>> read_intervals(path, classes=["point", "wave"]).tolist()
    [[2, 3, 10], [1, 12, 20]]
    >>> _ = path.write_text("4,10,2\\n")  # ChaLearn style: 1-based, inclusive
    >>> read_intervals(path, base=1, end="inclusive").tolist()
    [[2, 3, 10]]
    >>> tmp.cleanup()
    """
    _check_frame_options(base, end)
    names = _class_names(classes)
    ids = None if names is None else {n: k for k, n in enumerate(names, start=1)}
    path = _check_path(file, "interval file")
    rows = _convert_frames(_read_interval_rows(path), path.name, base, end, n_frames)
    labels = _label_ids(rows, path.name, ids)
    seg = [(c, s, e) for c, (_, s, e, _) in zip(labels, rows) if c != 0]
    return np.array(seg, dtype=np.int64).reshape(-1, 3)


read_intervals.__doc__ = read_intervals.__doc__.format(frames=_FRAMES_DOC)


@validate_params(
    {
        "file": [str, os.PathLike],
        "labels": ["array-like"],
        "classes": [list, tuple, str, os.PathLike, None],
        "base": [Interval(Integral, 0, 1, closed="both")],
        "end": [StrOptions(set(_END_OPTIONS))],
        "overwrite": ["boolean"],
    },
    prefer_skip_nested_validation=True,
)
def write_intervals(
    file, labels, *, classes=None, base=0, end="exclusive", overwrite=False
):
    """Write per-frame labels (or segments) as an interval annotation file.

    Each maximal run of one non-rest label becomes a ``start,end,label`` line
    under a ``start,end,label`` header; a sequence without gesture gives a file
    with the header only. :func:`read_intervals` reads it back.

    Parameters
    ----------
    file : str or path-like
        The file to write (e.g. ``take1.labels.csv`` next to ``take1.csv``).
    labels : array-like of shape (n_frames,) or (n_gestures, 3)
        Per-frame integer labels (0 = rest), or segments ``(class, start,
        end)``, 0-based with an exclusive end.
    classes : list of str, str or path-like, or None, default=None
        Class names (``classes[k - 1]`` names class ``k``, or a class-names
        file): labels are written as names. None writes class numbers.
    {frames}
    overwrite : bool, default=False
        Replace an existing file. By default an existing file raises
        :class:`FileExistsError`.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        For labels that are not integers, negative, beyond the class names,
        or segments that are empty or reversed.
    FileExistsError
        If ``file`` exists and ``overwrite=False``.

    See Also
    --------
    read_intervals : The reader.
    skgesture.datasets.write_chalearn_predictions : The ChaLearn format.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import write_intervals
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = write_intervals(Path(tmp.name) / "take1.labels.csv",
    ...                        [0, 2, 2, 2, 0, 1, 1], classes=["point", "wave"])
    >>> print(path.read_text(), end="")
    start,end,label
    1,4,wave
    5,7,point
    >>> tmp.cleanup()
    """
    _check_frame_options(base, end)
    names = _class_names(classes)
    arr = np.asarray(labels)
    if arr.size and (
        arr.dtype == bool
        or not np.issubdtype(arr.dtype, np.number)
        or not np.all(np.isfinite(arr))
        or not np.all(arr == np.round(arr))
    ):
        raise ValueError(f"labels must be integers, got dtype {arr.dtype}")
    if arr.ndim == 1:
        seg = labels_to_segments(arr.astype(np.int64))
    elif arr.ndim == 2 and arr.shape[1] == 3:
        seg = arr.astype(np.int64).reshape(-1, 3)
        bad = np.flatnonzero((seg[:, 2] <= seg[:, 1]) | (seg[:, 1] < 0))
        if bad.size:
            raise ValueError(
                f"segment row {int(bad[0])} = {tuple(seg[bad[0]].tolist())} is empty, "
                f"reversed or starts before 0 (start is 0-based, end exclusive)"
            )
    else:
        raise ValueError(
            f"labels must have shape (n_frames,) or (n_gestures, 3), got {arr.shape}"
        )
    bad = np.flatnonzero(seg[:, 0] < (0 if arr.ndim == 1 else 1))
    if bad.size:
        raise ValueError(f"class {seg[bad[0], 0]} is negative (0 = rest)")
    if names is not None and len(seg) and seg[:, 0].max() > len(names):
        raise ValueError(
            f"class {seg[:, 0].max()} has no name ({len(names)} class names)"
        )
    path = Path(file).expanduser()
    if path.is_dir():
        raise IsADirectoryError(f"{str(path)!r} is a folder, expected a file name")
    if path.exists() and not overwrite:
        raise FileExistsError(
            f"{str(path)!r} already exists; pass overwrite=True to replace it"
        )
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["start", "end", "label"])
    for c, s, e in seg.tolist():
        label = str(c) if names is None else names[c - 1]
        writer.writerow([s + base, e + base - (1 if end == "inclusive" else 0), label])
    path.write_text(buffer.getvalue())
    return path


write_intervals.__doc__ = write_intervals.__doc__.format(frames=_FRAMES_DOC)
