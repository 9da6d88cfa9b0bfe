"""Your own recordings: skeleton CSV/TSV files and ``(start, end, label)`` intervals.

A recording is one skeleton file (one line per frame) in a named layout
(``kinect_v1``, ``kinect_v2``, ``azure``, ``mediapipe``, ``msr_action3d``) or a
given joint order; other layouts are mapped to the toolkit's Kinect v1 layout by
the adapters of :mod:`skgesture.streaming`. Its annotation, if any, is an
interval file next to it. ``docs/recordings.md`` describes the files with an
example.
"""

# SPDX-License-Identifier: BSD-3-Clause

import csv
import io
import os
import re
from numbers import Integral, Real
from pathlib import Path

import numpy as np
from sklearn.utils._param_validation import Interval, StrOptions, validate_params

from skgesture.datasets._base import (
    MAX_ABS_COORDINATE,
    MAX_EXACT_INTEGER,
    DataFormatError,
    _check_path,
    _descr,
    _format_error,
    _integer_column,
    _lines,
    _make_bunch,
    _parse_table,
    _progress,
    _read_text,
    _sort_and_label,
    _warn,
)
from skgesture.layouts import KINECT_V1, N_COORDS
from skgesture.utils._segments import labels_to_segments

__all__ = ["read_skeleton_csv", "read_intervals", "write_intervals", "load_recordings"]

# Layout names accepted by ``layout=`` -> name of the adapter in
# :func:`skgesture.streaming.get_adapter`.
LAYOUT_ALIASES = {
    "kinect_v1": "kinect_v1",
    "kinect_v2": "kinect_v2",
    "azure": "azure_kinect",
    "azure_kinect": "azure_kinect",
    "mediapipe": "mediapipe_pose",
    "mediapipe_pose": "mediapipe_pose",
    "msr_action3d": "msr_action3d",
}
SKELETON_SUFFIXES = (".csv", ".tsv")  # skeleton and interval files
LABELS_TAG = ".labels"  # ``walk.csv`` is annotated by ``walk.labels.csv``
CLASSES_FILE = "classes.txt"  # class names of a recordings folder
REST_NAME = "rest"  # the label name of class 0 (no gesture)
DEFAULT_FPS = 30.0  # nominal Kinect v1 skeleton rate
# Raw values (before the adapter turns them into metres) beyond this are corrupt
# whatever the unit (millimetres, pixels, normalised image coordinates).
MAX_ABS_RAW_VALUE = 1e7
# Median |coordinate| of tracked frames above this many metres after adaptation:
# the file is probably in millimetres or pixels (a warning).
UNIT_WARNING_METRES = 50.0
DELIMITERS = {",": ",", "\t": "\t", ";": ";", " ": None}  # " " = runs of blanks
# Class numbers above this need class names (no typo makes 10**9 class names).
MAX_NUMBERED_CLASSES = 1000
_INT_RE = re.compile(r"^[+-]?[0-9]+$")
_COORD_RE = re.compile(r"^(.*?)[\s_.:/-]*([xyzXYZ])$")
_INTERVAL_COLUMNS = {
    "start": ("start", "begin", "start_frame", "from"),
    "end": ("end", "stop", "end_frame", "to"),
    "label": ("label", "class", "gesture", "action", "name"),
}
_END_OPTIONS = ("exclusive", "inclusive")

_DESCR_BODY = """
Skeleton recordings read by skgesture.datasets.load_recordings: one skeleton file
per sequence, mapped to the Kinect v1 layout (metres; untracked frames, written
as all zeros or NaN, are all-zero frames), and per-frame labels from the
``(start, end, label)`` interval file next to each one. See docs/recordings.md.
"""


# ----------------------------------------------------------------------------
# Layouts and joint orders
# ----------------------------------------------------------------------------


def _norm(name):
    """Joint name for matching: lower case without blanks, ``_``, ``-``, ``.``."""
    return re.sub(r"[\s_.\-]", "", str(name)).lower()


def _layout_names():
    """``{adapter name: joint names or None}`` of the known layouts."""
    from skgesture.streaming._adapters import (
        AZURE_KINECT_JOINTS,
        KINECT_V2_JOINTS,
        MEDIAPIPE_POSE_LANDMARKS,
    )

    return {
        "kinect_v1": KINECT_V1.joint_names,
        "kinect_v2": KINECT_V2_JOINTS,
        "azure_kinect": AZURE_KINECT_JOINTS,
        "mediapipe_pose": MEDIAPIPE_POSE_LANDMARKS,
        "msr_action3d": None,  # the MSR file order has no joint names
    }


def _required(adapter, names):
    """Normalised names of the joints the adapter actually reads."""
    mapping = getattr(adapter, "mapping", None)
    if mapping is None:  # identity (Kinect v1): every joint
        return {_norm(n) for n in names}
    return {_norm(src) for sources in mapping.values() for src in sources}


class _Layout:
    """How the joints of a file become the Kinect v1 frames of the toolkit.

    ``adapter`` maps frames of the layout ``names`` (or ``n_joints`` unnamed
    joints) to Kinect v1; ``order`` (or None) lists the file's joints by name.
    """

    def __init__(self, layout):
        from skgesture.streaming._adapters import SkeletonAdapter, get_adapter

        known = _layout_names()
        self.order = None
        if isinstance(layout, SkeletonAdapter):
            self.adapter = layout
        elif isinstance(layout, str):
            if layout not in LAYOUT_ALIASES:
                raise ValueError(
                    f"unknown layout {layout!r}; use one of "
                    f"{', '.join(sorted(LAYOUT_ALIASES))}, a SkeletonAdapter, or the "
                    f"list of joint names of the file"
                )
            self.adapter = get_adapter(LAYOUT_ALIASES[layout])
        elif isinstance(layout, (list, tuple)) and all(
            isinstance(n, str) for n in layout
        ):
            self.order = list(layout)
            self.adapter = get_adapter(self._detect(self.order, known))
        else:
            raise TypeError(
                f"layout must be a layout name, a SkeletonAdapter or a list of joint "
                f"names, got {layout!r}"
            )
        self.name = self.adapter.name
        self.names = known.get(self.name)
        self.n_joints = self.adapter.n_joints

    @staticmethod
    def _detect(order, known):
        """Name of the first known layout whose needed joints are all in ``order``."""
        normed = [_norm(n) for n in order]
        dup = {n for n in normed if normed.count(n) > 1}
        if dup:
            raise ValueError(f"layout lists joint(s) {sorted(dup)} more than once")
        from skgesture.streaming._adapters import get_adapter

        best = None
        for name, names in known.items():
            if names is None:
                continue
            need = _required(get_adapter(name), names)
            absent = sorted(need - set(normed))
            if not absent:
                return name
            if best is None or len(absent) < len(best[1]):
                best = (name, absent)
        raise ValueError(
            f"the joint names of `layout` match no known layout; closest "
            f"{best[0]!r}, which also needs {', '.join(best[1][:8])}"
            + (", ..." if len(best[1]) > 8 else "")
        )

    def take(self, file_joints, name):
        """For each joint of the layout, its column in the file (-1: absent)."""
        if file_joints is None:
            return np.arange(self.n_joints)
        normed = [_norm(j) for j in file_joints]
        if self.names is None:
            raise _format_error(
                name,
                1,
                f"joint names in the header, but layout {self.name!r} has no joint "
                f"names to match them to",
            )
        layout = [_norm(j) for j in self.names]
        unknown = [j for j, n in zip(file_joints, normed) if n not in layout]
        if unknown:
            raise _format_error(
                name,
                1,
                f"joint(s) {', '.join(unknown[:5])} are not in layout {self.name!r} "
                f"({', '.join(self.names[:4])}, ...); give the right `layout`",
            )
        absent = sorted(_required(self.adapter, self.names) - set(normed))
        if absent:
            raise _format_error(
                name,
                1,
                f"layout {self.name!r} needs joint(s) {', '.join(absent[:8])}, which "
                f"the file does not have",
            )
        where = {n: k for k, n in enumerate(normed)}
        return np.array([where.get(n, -1) for n in layout])


# ----------------------------------------------------------------------------
# Skeleton files
# ----------------------------------------------------------------------------


def _split(line, sep):
    return [t.strip().strip('"').strip("'") for t in line.split(sep)]


def _is_number(token):
    try:
        float(token)
    except ValueError:
        return False
    return True


def _detect_delimiter(line, delimiter):
    if delimiter is not None:
        return DELIMITERS[delimiter]
    for sep in ("\t", ";", ","):
        if sep in line:
            return sep
    return None


def _header_joints(tokens):
    """``(has_frame_column, values_per_joint, joint names)`` from a header, or None.

    Only a header whose joint columns are named ``<joint>_x, <joint>_y,
    <joint>_z`` (separator ``_``, ``.``, ``:``, ``/``, ``-``, blank or none;
    optionally a 4th column per joint) gives joint names.
    """
    for frame in (0, 1):
        for per_joint in (3, 4):
            body = tokens[frame:]
            if not body or len(body) % per_joint:
                continue
            names = []
            for k in range(0, len(body), per_joint):
                parts = [_COORD_RE.match(t) for t in body[k : k + 3]]
                if not all(parts):
                    break
                stems = {p.group(1) for p in parts}
                axes = "".join(p.group(2).lower() for p in parts)
                if len(stems) != 1 or axes != "xyz" or not parts[0].group(1):
                    break
                names.append(parts[0].group(1))
            else:
                return bool(frame), per_joint, names
    return None


def _names_joints(header_joints, layout):
    """Whether header names are meant as joint names (any is a known joint)."""
    if layout.names is None:
        return False
    known = {_norm(n) for n in layout.names}
    if layout.order is not None:
        known |= {_norm(n) for n in layout.order}
    return any(_norm(j) in known for j in header_joints)


def _read_skeleton(path, layout, *, delimiter, header, frame_column):
    """``(X, frame_numbers or None)`` of one skeleton file (see read_skeleton_csv)."""
    name = path.name
    lines = _lines(_read_text(path))
    if not lines:
        raise DataFormatError(
            f"{name} is empty: expected one line of joint positions per frame",
            file=name,
        )
    sep = _detect_delimiter(lines[0], delimiter)
    tokens = _split(lines[0], sep)
    has_header = (
        not any(_is_number(t) for t in tokens) if header is None else bool(header)
    )
    body = lines[1:] if has_header else lines
    first = 2 if has_header else 1
    if not body:
        raise DataFormatError(f"{name} has a header but no frame line", file=name)
    n_columns = len(_split(body[0], sep))
    file_joints = fixed = None
    if has_header:
        if len(tokens) != n_columns:
            raise _format_error(
                name,
                1,
                f"the header has {len(tokens)} columns but line 2 has {n_columns} "
                f"values",
            )
        found = _header_joints(tokens)
        if found is not None and not _names_joints(found[2], layout):
            found = None  # generic column names (``j0_x``...): not joint names
        if found is not None:
            frame, per_joint, file_joints = found
            if layout.order is not None and [_norm(j) for j in file_joints] != [
                _norm(j) for j in layout.order
            ]:
                raise _format_error(
                    name,
                    1,
                    f"the header names the joints {', '.join(file_joints[:4])}, ... "
                    f"but `layout` lists {', '.join(layout.order[:4])}, ...",
                )
            if frame_column is None or bool(frame_column) == frame:
                fixed = (frame, per_joint)
    if file_joints is None and layout.order is not None:
        file_joints = layout.order
    take = layout.take(file_joints, name)
    n_file = layout.n_joints if file_joints is None else len(file_joints)
    if fixed is None:
        options = [
            (frame, per_joint)
            for frame in ((0, 1) if frame_column is None else (int(frame_column),))
            for per_joint in (3, 4)
            if frame + per_joint * n_file == n_columns
        ]
        if not options:
            frame_part = {None: " (+1 with a frame number first)", True: " + 1"}
            raise _format_error(
                name,
                first,
                f"expected {3 * n_file} or {4 * n_file} values"
                f"{frame_part.get(frame_column, '')} per line for {n_file} joints of "
                f"layout {layout.name!r} (x, y, z and an optional 4th value per "
                f"joint), got {n_columns}",
            )
        fixed = options[0]
    frame, per_joint = fixed
    values = _parse_table(
        body, n_columns, name, sep=sep, first_line=first, allow_nan=True
    )
    frame_numbers = None
    if frame:
        frame_numbers = _integer_column(
            values[:, 0], name, first_line=first, what="frame number"
        )
        back = np.flatnonzero(np.diff(frame_numbers) <= 0)
        if back.size:
            i = int(back[0]) + 1
            raise _format_error(
                name,
                i + first,
                f"frame number {frame_numbers[i]} does not follow "
                f"{frame_numbers[i - 1]} (frame numbers must increase)",
            )
    raw = values[:, frame:]
    big = np.abs(raw) > MAX_ABS_RAW_VALUE
    if big.any():
        i, j = np.argwhere(big)[0]
        raise _format_error(
            name,
            int(i) + first,
            f"value {j + frame + 1} ({raw[i, j]:g}) is beyond +-{MAX_ABS_RAW_VALUE:g} "
            f"in any unit; the file is corrupt",
        )
    coords = raw.reshape(len(raw), n_file, per_joint)[..., :N_COORDS]
    frames = np.zeros((len(raw), layout.n_joints, N_COORDS))
    present = take >= 0
    frames[:, present] = coords[:, take[present]]
    with np.errstate(all="ignore"):
        X = layout.adapter(frames)
    bad = ~np.isfinite(X) | (np.abs(X) > MAX_ABS_COORDINATE)
    if bad.any():
        i = int(np.flatnonzero(bad.reshape(len(X), -1).any(axis=1))[0])
        raise _format_error(
            name,
            i + first,
            f"the frame maps to positions beyond +-{MAX_ABS_COORDINATE:g} m in the "
            f"Kinect v1 layout; the file is corrupt or the layout is wrong",
        )
    tracked = np.any(X != 0, axis=(1, 2))
    if tracked.any():
        typical = float(np.median(np.abs(X[tracked])))
        if typical > UNIT_WARNING_METRES:
            _warn(
                f"{name}: the median |coordinate| is {typical:g} m after mapping "
                f"layout {layout.name!r}; skgesture expects metres (millimetres? "
                f"divide by 1000, or use an adapter with the right units)"
            )
    return np.ascontiguousarray(X), frame_numbers


def _check_reader_options(delimiter, header, frame_column):
    if delimiter is not None and delimiter not in DELIMITERS:
        raise ValueError(
            f"delimiter must be None (detect), ',', '\\t', ';' or ' ' (blanks), got "
            f"{delimiter!r}"
        )
    for what, value in (("header", header), ("frame_column", frame_column)):
        if value is not None and not isinstance(value, (bool, np.bool_)):
            raise ValueError(f"{what} must be None (detect), True or False")


_LAYOUT_DOC = """layout : str, SkeletonAdapter or list of str, default="kinect_v1"
        The skeleton in the file. A name: ``"kinect_v1"`` (20 joints in the
        toolkit's native order, :data:`skgesture.layouts.KINECT_V1`),
        ``"kinect_v2"`` (25), ``"azure"`` (Azure Kinect, 32, millimetres),
        ``"mediapipe"`` (MediaPipe Pose, 33, normalised image coordinates) or
        ``"msr_action3d"``; a :class:`~skgesture.streaming.SkeletonAdapter`
        for other settings (e.g. ``MediaPipePoseAdapter(coordinates="world")``);
        or the joint names of the file in column order, from any of those
        layouts (joints the mapping does not use may be left out or added)."""


@validate_params(
    {
        "file": [str, os.PathLike],
        "layout": "no_validation",
        "delimiter": "no_validation",
        "header": ["boolean", None],
        "frame_column": ["boolean", None],
        "return_frame_numbers": ["boolean"],
    },
    prefer_skip_nested_validation=True,
)
def read_skeleton_csv(
    file,
    *,
    layout="kinect_v1",
    delimiter=None,
    header=None,
    frame_column=None,
    return_frame_numbers=False,
):
    """Read one skeleton recording (CSV/TSV) into Kinect v1 frames.

    One line per frame: an optional frame number, then ``x, y, z`` of every
    joint in the order of ``layout`` (optionally a 4th value per joint, such as
    a confidence, which is ignored). Frames of other layouts are mapped to the
    toolkit's Kinect v1 layout by the adapters of :mod:`skgesture.streaming`.

    Parameters
    ----------
    file : str or path-like
        The skeleton file.
    {layout}
    delimiter : {{",", "\\t", ";", " "}} or None, default=None
        Value separator (``" "``: runs of blanks). None detects it from the
        first line: tab, else semicolon, else comma, else blanks.
    header : bool or None, default=None
        Whether the first line is a header. None: it is one when none of its
        values is a number. A header naming the joint columns ``<joint>_x,
        <joint>_y, <joint>_z`` sets the joint order (checked against
        ``layout``); any other header is skipped.
    frame_column : bool or None, default=None
        Whether the first value of a line is the frame number. None decides
        from the number of values (``3 * n_joints + 1`` or ``4 * n_joints + 1``
        means a frame number). Frame numbers must be increasing integers; they
        are returned, not used to place the rows.
    return_frame_numbers : bool, default=False
        Also return the frame numbers (None without a frame column).

    Returns
    -------
    X : ndarray of shape (n_frames, 20, 3)
        Kinect v1 positions in metres (float64). A frame written as all zeros
        or holding a NaN (not tracked) is all zeros.
    frame_numbers : ndarray of shape (n_frames,) or None
        Only with ``return_frame_numbers=True``.

    Raises
    ------
    DataFormatError
        Naming the file and 1-based line: a wrong number of values, a value
        that is not a number, an infinite value, a frame number that is not an
        increasing integer, a position out of range, a header whose joints do
        not fit ``layout``.

    Warns
    -----
    DataFileWarning
        When the positions do not look like metres (median above 50 m).

    See Also
    --------
    load_recordings : Read a folder of recordings with their annotations.
    skgesture.streaming.get_adapter : The adapters used for other layouts.

    Notes
    -----
    ``docs/recordings.md`` describes the file formats. Rows are frames in file
    order: frame ``k`` (0-based) of ``X`` is the ``k``-th data line, whatever
    its frame number.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from skgesture.datasets import read_skeleton_csv
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "wave.csv"
    >>> frames = np.tile(np.linspace(0.1, 2.0, 60), (4, 1))
    >>> np.savetxt(path, np.column_stack([np.arange(10, 14), frames]),
    ...            delimiter=",", fmt="%.17g")
    >>> X, numbers = read_skeleton_csv(path, return_frame_numbers=True)
    >>> X.shape, numbers.tolist()
    ((4, 20, 3), [10, 11, 12, 13])
    >>> tmp.cleanup()
    """
    _check_reader_options(delimiter, header, frame_column)
    spec = _Layout(layout)
    path = _check_path(file, "skeleton file")
    X, numbers = _read_skeleton(
        path, spec, delimiter=delimiter, header=header, frame_column=frame_column
    )
    return (X, numbers) if return_frame_numbers else X


read_skeleton_csv.__doc__ = read_skeleton_csv.__doc__.format(layout=_LAYOUT_DOC)


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


def _read_interval_rows(path):
    """``[(line, start, end, label token)]`` of an interval file (ints unchecked)."""
    name = path.name
    lines = _lines(_read_text(path))
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


# ----------------------------------------------------------------------------
# A folder of recordings
# ----------------------------------------------------------------------------


def _natural_key(text):
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"([0-9]+)", text)]


def _is_labels_file(path):
    return path.stem.endswith(LABELS_TAG)


def _find_recordings(root):
    """``[(sample_id, skeleton path, labels path or None)]`` and orphan labels."""
    if root.is_file():
        if root.suffix.lower() not in SKELETON_SUFFIXES or _is_labels_file(root):
            raise ValueError(
                f"{root.name} is not a skeleton file (*.csv or *.tsv, not "
                f"*{LABELS_TAG}.csv)"
            )
        files, base = [root], root.parent
    elif root.is_dir():
        base = root
        files = [
            p
            for p in root.rglob("*")
            if p.is_file()
            and p.suffix.lower() in SKELETON_SUFFIXES
            and not any(part.startswith(".") for part in p.relative_to(root).parts)
        ]
    else:
        raise ValueError(f"{str(root)!r} is neither a file nor a folder")
    labels = {}
    skeletons = []
    for p in files:
        if _is_labels_file(p):
            key = p.parent / p.stem[: -len(LABELS_TAG)]
            if key in labels:
                raise ValueError(
                    f"two annotation files for {key.name}: {labels[key].name} and "
                    f"{p.name}"
                )
            labels[key] = p
        else:
            skeletons.append(p)
    if root.is_file():
        for suffix in SKELETON_SUFFIXES:
            cand = root.parent / f"{root.stem}{LABELS_TAG}{suffix}"
            if cand.is_file():
                labels[root.parent / root.stem] = cand
    found = []
    for p in skeletons:
        sid = p.relative_to(base).with_suffix("").as_posix()
        found.append((sid, p, labels.pop(p.parent / p.stem, None)))
    if not found:
        raise FileNotFoundError(
            f"no skeleton file (*.csv or *.tsv) in {str(root)!r} or its subfolders"
        )
    dups = {sid for sid, _, _ in found if [f[0] for f in found].count(sid) > 1}
    if dups:
        raise ValueError(
            f"recording(s) {sorted(dups)} exist both as .csv and .tsv; keep one"
        )
    found.sort(key=lambda f: _natural_key(f[0]))
    return found, sorted(labels.values())


def _groups(sample_ids, pattern):
    """Group of each recording (see load_recordings)."""
    if pattern is None:
        out = [sid.split("/", 1)[0] if "/" in sid else sid for sid in sample_ids]
    else:
        regex = re.compile(pattern)
        out = []
        for sid in sample_ids:
            match = regex.search(sid)
            if match is None:
                raise ValueError(
                    f"groups pattern {pattern!r} does not match recording {sid!r}"
                )
            out.append(match.group(1) if regex.groups else match.group(0))
    if all(g.isdigit() for g in out):
        return np.array([int(g) for g in out], dtype=np.int64)
    return np.array(out)


@validate_params(
    {
        "path": [str, os.PathLike],
        "layout": "no_validation",
        "classes": [list, tuple, str, os.PathLike, None],
        "labels": ["boolean", None],
        "base": [Interval(Integral, 0, 1, closed="both")],
        "end": [StrOptions(set(_END_OPTIONS))],
        "groups": [str, None],
        "fps": [Interval(Real, 0, None, closed="neither")],
        "delimiter": "no_validation",
        "header": ["boolean", None],
        "frame_column": ["boolean", None],
        "verbose": ["verbose"],
    },
    prefer_skip_nested_validation=True,
)
def load_recordings(
    path,
    *,
    layout="kinect_v1",
    classes=None,
    labels=None,
    base=0,
    end="exclusive",
    groups=None,
    fps=DEFAULT_FPS,
    delimiter=None,
    header=None,
    frame_column=None,
    verbose=0,
):
    """Load a folder of your own skeleton recordings and their annotations.

    Every ``*.csv`` / ``*.tsv`` file under ``path`` (subfolders included) is
    one recording, read by :func:`read_skeleton_csv`. A recording
    ``<name>.csv`` is annotated by the interval file ``<name>.labels.csv`` (or
    ``.tsv``) next to it, read by :func:`read_intervals`; ``classes.txt`` in
    ``path`` names the classes. The result has the keys of every loader, like
    :func:`load_precog`.

    Parameters
    ----------
    path : str or path-like
        The folder (or one skeleton file).
    {layout}
    classes : list of str, str or path-like, or None, default=None
        Class names: ``classes[k - 1]`` names class ``k``, or a class-names
        file (one name per line, line ``k`` names class ``k``). None reads
        ``path/classes.txt`` when it exists; otherwise labels given as numbers
        are named ``"1"``, ``"2"``, ... and labels given as names are numbered
        in sorted order of the names found.
    labels : bool or None, default=None
        None: use the annotation files when every recording has one, return
        ``y=None`` when none has (for prediction), and raise when only some
        have. True requires them; False ignores them.
    {frames}
    groups : str or None, default=None
        How recordings are grouped (``groups``, for ``GroupKFold``). None: by
        the first subfolder under ``path`` (``alice/take1.csv`` is in group
        ``"alice"``); a recording directly in ``path`` is its own group. A
        regular expression is searched in each sample id (``"alice/take1"``)
        and its first group (or the whole match) is the group, e.g.
        ``r"subject(\\d+)"``. Groups that are all digits become ints.
    fps : float, default=30.0
        Frame rate of the recordings (stored in ``fps``).
    delimiter : {{",", "\\t", ";", " "}} or None, default=None
        Value separator of the skeleton files, as in :func:`read_skeleton_csv`
        (None detects it).
    header : bool or None, default=None
        Whether the skeleton files start with a header line, as in
        :func:`read_skeleton_csv` (None detects it).
    frame_column : bool or None, default=None
        Whether the first value of a line is the frame number, as in
        :func:`read_skeleton_csv` (None detects it).
    verbose : int, default=0
        0 is silent; 1 shows a tqdm progress bar over the recordings.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys

        X : list of ndarray of shape (n_frames_i, 20, 3)
            Kinect v1 positions in metres (untracked frames are all zeros).
        y : list of ndarray of shape (n_frames_i,) or None
            Per-frame int64 labels, 0 = rest; None without annotations.
        segments : list of ndarray of shape (n_i, 3) or None
            The annotated intervals ``(class, start, end)``, 0-based, end
            exclusive, sorted by start; None without annotations.
        sample_ids : list of str
            Path of each skeleton file relative to ``path``, without suffix.
        groups : ndarray of shape (n_sequences,)
            Group of each recording (see ``groups``).
        target_names : list of str
            ``target_names[k - 1]`` names class ``k``.
        fps, n_frames, missing, layout, DESCR
            As for every loader (``layout`` is ``"kinect_v1"``).
        source_layout : str
            The layout of the files (the adapter's name).
        frame_numbers : list of (ndarray or None)
            Frame numbers of each file that has a frame column.
        files, label_files : list of str
            The skeleton file and the annotation file (or None) of each
            recording.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist or holds no skeleton file.
    DataFormatError
        For a malformed skeleton, interval or class-names file, naming the
        file and the 1-based line.
    ValueError
        If only some recordings have an annotation file (with
        ``labels=None``), or none has one with ``labels=True``.

    Warns
    -----
    DataFileWarning
        For an annotation file without skeleton file, overlapping intervals
        (the later-starting one wins in ``y``), or positions that do not look
        like metres.

    See Also
    --------
    read_skeleton_csv, read_intervals, write_intervals : The file readers and
        the writer.
    load_precog : A dataset with the same keys.

    Notes
    -----
    ``docs/recordings.md`` describes the files. By default interval frames
    are 0-based with an exclusive end, as :func:`write_intervals` writes them
    and as Python slices count; ``base=1, end="inclusive"`` reads
    ChaLearn-style files. Frames count the data lines of the skeleton file,
    not its frame numbers. When training and predicting on different folders,
    give both the same ``classes`` so that class numbers agree.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from skgesture.datasets import load_recordings
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> for subject in ("alice", "bob"):
    ...     (folder / subject).mkdir()
    ...     frames = np.tile(np.linspace(0.1, 2.0, 60), (30, 1))
    ...     np.savetxt(folder / subject / "take1.csv", frames, delimiter=",")
    ...     _ = (folder / subject / "take1.labels.csv").write_text(
    ...         "start,end,label\\n5,12,wave\\n")
    >>> _ = (folder / "classes.txt").write_text("wave\\npoint\\n")
    >>> data = load_recordings(folder)
    >>> data.sample_ids, data.groups.tolist(), data.X[0].shape
    (['alice/take1', 'bob/take1'], ['alice', 'bob'], (30, 20, 3))
    >>> data.segments[0].tolist(), data.target_names
    ([[1, 5, 12]], ['wave', 'point'])
    >>> tmp.cleanup()
    """
    _check_reader_options(delimiter, header, frame_column)
    _check_frame_options(base, end)
    spec = _Layout(layout)
    root = _check_path(path)
    found, orphans = _find_recordings(root)
    for orphan in orphans:
        _warn(f"{orphan.name}: no skeleton file {orphan.stem[: -len(LABELS_TAG)]}.*")
    sample_ids = [f[0] for f in found]
    group_ids = _groups(sample_ids, groups)
    folder = root if root.is_dir() else root.parent
    if classes is None and (folder / CLASSES_FILE).is_file():
        classes = folder / CLASSES_FILE
    names = _class_names(classes)
    annotated = [f for f in found if f[2] is not None]
    use_labels = bool(annotated) if labels is None else labels
    if use_labels and len(annotated) < len(found):
        absent = [sid for sid, _, lab in found if lab is None]
        raise ValueError(
            f"{len(absent)} of {len(found)} recordings have no annotation file "
            f"({', '.join(a + LABELS_TAG + '.csv' for a in absent[:3])}"
            f"{', ...' if len(absent) > 3 else ''}); add one (a file with the header "
            f"only means no gesture), or pass labels=False to ignore annotations"
        )
    X, frame_numbers, rows = [], [], []
    for sid, skel, lab in _progress(found, verbose=verbose, desc="recordings"):
        x, numbers = _read_skeleton(
            skel, spec, delimiter=delimiter, header=header, frame_column=frame_column
        )
        X.append(x)
        frame_numbers.append(numbers)
        if use_labels:
            rows.append(
                _convert_frames(_read_interval_rows(lab), lab.name, base, end, len(x))
            )
    n_frames = np.array([len(x) for x in X], dtype=np.int64)
    y = segments = None
    if use_labels:
        y, segments, names = _label_recordings(rows, found, n_frames, names)
    elif names is None:
        names = []
    n_segments = 0 if segments is None else sum(len(s) for s in segments)
    return _make_bunch(
        X=X,
        y=y,
        segments=segments,
        sample_ids=sample_ids,
        groups=group_ids,
        fps=float(fps),
        n_frames=n_frames,
        target_names=names,
        descr=_descr(
            f"Recordings in {root.name} (layout {spec.name})",
            _DESCR_BODY,
            len(X),
            n_frames.sum(),
            n_segments,
        ),
        source_layout=spec.name,
        frame_numbers=frame_numbers,
        files=[str(f[1]) for f in found],
        label_files=[None if f[2] is None else str(f[2]) for f in found],
    )


load_recordings.__doc__ = load_recordings.__doc__.format(
    layout=_LAYOUT_DOC, frames=_FRAMES_DOC
)


def _label_recordings(rows, found, n_frames, names):
    """``(y, segments, target_names)`` of the annotated recordings."""
    tokens = [label for file_rows in rows for (_, _, _, label) in file_rows]
    numeric = [t for t in tokens if _INT_RE.match(t)]
    if names is None:
        named = sorted(
            {t for t in tokens if not _INT_RE.match(t) and t.lower() != REST_NAME}
        )
        if named and numeric:
            raise ValueError(
                "the annotation files mix class numbers and class names; give the "
                f"class names (`classes`, or a {CLASSES_FILE} file)"
            )
        if named:
            names = named
    ids = None if names is None else {n: k for k, n in enumerate(names, start=1)}
    y, segments = [], []
    for file_rows, (_, _, lab), n in zip(rows, found, n_frames):
        classes = _label_ids(file_rows, lab.name, ids)
        raw = [(c, s, e) for c, (_, s, e, _) in zip(classes, file_rows) if c]
        lines = [i for c, (i, _, _, _) in zip(classes, file_rows) if c]
        seg, lab_y, overlaps = _sort_and_label(raw, int(n))
        if overlaps:
            pairs = "; ".join(
                f"line {lines[a]} and line {lines[b]}" for a, b in overlaps
            )
            _warn(
                f"{lab.name}: overlapping intervals: {pairs}; both are kept in "
                f"`segments`, and in `y` the later-starting one wins"
            )
        y.append(lab_y)
        segments.append(seg)
    if names is None:
        top = max((int(s[:, 0].max()) for s in segments if len(s)), default=0)
        names = [str(k) for k in range(1, top + 1)]
    return y, segments, names
