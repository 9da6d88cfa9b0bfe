"""Skeleton recordings in CSV/TSV files, read into the toolkit's Kinect v1 frames.

One line per frame: an optional frame number, then ``x, y, z`` (and an optional
4th value) of every joint, in a named layout (``kinect_v1``, ``kinect_v2``,
``azure``, ``mediapipe``, ``msr_action3d``) or a given joint order, optionally
under a header naming the joints. Other layouts are mapped to Kinect v1 by the
adapters of :mod:`skgesture.streaming`. ``docs/recordings.md`` describes the
files; :func:`~skgesture.datasets.load_recordings` reads a folder of them.
"""

# SPDX-License-Identifier: BSD-3-Clause

import os
import re

import numpy as np
from sklearn.utils._param_validation import validate_params

from skgesture.datasets._base import (
    MAX_ABS_COORDINATE,
    DataFormatError,
    _check_path,
    _format_error,
    _integer_column,
    _lines,
    _parse_table,
    _read_text,
    _warn,
)
from skgesture.layouts import KINECT_V1, N_COORDS

__all__ = ["read_skeleton_csv"]

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
# Raw values (before the adapter turns them into metres) beyond this are corrupt
# whatever the unit (millimetres, pixels, normalised image coordinates).
MAX_ABS_RAW_VALUE = 1e7
# Median |coordinate| of tracked frames above this many metres after adaptation:
# the file is probably in millimetres or pixels (a warning).
UNIT_WARNING_METRES = 50.0
DELIMITERS = {",": ",", "\t": "\t", ";": ";", " ": None}  # " " = runs of blanks
_COORD_RE = re.compile(r"^(.*?)[\s_.:/-]*([xyzXYZ])$")
# Header names (after _norm) of a frame-number column and of a timestamp column.
FRAME_NAMES = frozenset(
    {
        "frame",
        "frames",
        "frameno",
        "framenr",
        "framenum",
        "framenumber",
        "frameid",
        "frameidx",
        "frameindex",
    }
)
TIME_NAMES = frozenset(
    {
        "t",
        "time",
        "times",
        "timems",
        "timeus",
        "timens",
        "timestamp",
        "timestamps",
        "timestampms",
        "timestampus",
        "timestampns",
    }
)
# Without a header, a first column of integers that increase, by 1 on at least
# this share of at least this many lines, looks like frame numbers.
FRAME_LIKE_SHARE = 0.5
MIN_FRAME_LIKE_LINES = 3


# ----------------------------------------------------------------------------
# Layouts and joint orders
# ----------------------------------------------------------------------------


def _norm(name):
    """Joint name for matching: lower case without blanks, ``_``, ``-``, ``.``."""
    return re.sub(r"[\s_.\-]", "", str(name)).lower()


def _layout_names():
    """``{adapter name: joint names or None}`` of the known layouts."""
    from skgesture.layouts import (
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


def _joint_names(layout):
    """``{normalised name: name}`` of the joints a header may name, or {}."""
    known = {_norm(n): n for n in layout.names or ()}
    for n in layout.order or ():
        known.setdefault(_norm(n), n)
    return known


def _classify(token, known):
    """``(kind, joint, detail)`` of one header name.

    ``kind`` is ``"frame"``, ``"time"``, ``"coord"`` (``joint`` and axis 0-2 in
    ``detail``), ``"extra"`` (a value of ``joint`` that is not a coordinate,
    such as ``Head_confidence``: the suffix in ``detail``), ``"empty"`` or
    ``"unknown"``. ``joint`` is a normalised name of ``known``.
    """
    n = _norm(token)
    if not n:
        return "empty", None, None
    if n in FRAME_NAMES:
        return "frame", None, None
    if n in TIME_NAMES:
        return "time", None, None
    match = _COORD_RE.match(token)
    if match and match.group(1) and _norm(match.group(1)) in known:
        return "coord", _norm(match.group(1)), "xyz".index(match.group(2).lower())
    stems = [k for k in known if n.startswith(k) and len(n) > len(k)]
    if stems:
        joint = max(stems, key=len)
        return "extra", joint, n[len(joint) :]
    return "unknown", None, None


def _axis_name(tokens, cols, axis):
    """Name of the missing ``axis`` column, spelt like its joint's other columns."""
    token = tokens[next(c for c in cols if c >= 0)]
    match = _COORD_RE.match(token)
    letters = "XYZ" if match.group(2).isupper() else "xyz"
    return token[:-1] + letters[axis]


def _listed(items, limit=8):
    items = list(items)
    return ", ".join(items[:limit]) + (", ..." if len(items) > limit else "")


def _header_columns(tokens, layout, frame_column):
    """``(coords, frame, time, problems)`` from a header naming joint columns.

    None when no header name is a coordinate of a joint of ``layout`` (a
    generic header such as ``j0_x, j0_y, ...``, read by position). ``coords``
    is an ``(n_joints, 3)`` array of the column of each coordinate of each
    joint of the layout (-1: the file lacks the joint); ``frame`` and ``time``
    are columns or None; ``problems`` lists what is wrong with the header
    (missing, duplicated, unknown columns), empty when it can be read.
    """
    known = _joint_names(layout)
    kinds = [_classify(t, known) for t in tokens]
    if not any(kind == "coord" for kind, _, _ in kinds):
        return None
    frames = [i for i, (kind, _, _) in enumerate(kinds) if kind == "frame"]
    problems = []
    if frame_column is True and not frames:
        if kinds[0][0] == "coord":
            problems.append(
                f"frame_column=True, but the header names no frame column and its "
                f"first column {tokens[0]!r} is a joint coordinate"
            )
        else:
            kinds[0] = ("frame", None, None)
            frames = [0]
    elif frame_column is False and frames:
        problems.append(
            f"the header names a frame column {tokens[frames[0]]!r} (column "
            f"{frames[0] + 1}), but frame_column=False"
        )
    where = {}  # (kind, joint, detail) -> columns
    for i, key in enumerate(kinds):
        where.setdefault(key, []).append(i)
    for (kind, _, _), cols in where.items():
        if len(cols) > 1 and kind not in ("unknown", "empty"):
            problems.append(
                f"column {tokens[cols[0]]!r} appears {len(cols)} times (columns "
                f"{', '.join(str(c + 1) for c in cols)})"
            )
    coords_of = {}  # joint -> [column of x, y, z] (-1: missing)
    for i, (kind, joint, axis) in enumerate(kinds):
        if kind == "coord":
            cols = coords_of.setdefault(joint, [-1, -1, -1])
            if cols[axis] < 0:
                cols[axis] = i
    unknown = [i for i, (kind, _, _) in enumerate(kinds) if kind == "unknown"]
    # A non-coordinate value of a joint (a confidence) is read, and ignored,
    # when most joints of the file have one of that name; otherwise it is an
    # unknown column (a misspelt coordinate such as ``Head_q``).
    holders = {}
    for kind, joint, suffix in kinds:
        if kind == "extra" and joint in coords_of:
            holders.setdefault(suffix, set()).add(joint)
    for i, (kind, joint, suffix) in enumerate(kinds):
        if kind == "extra" and (
            joint not in coords_of or 2 * len(holders[suffix]) <= len(coords_of)
        ):
            unknown.append(i)
    empty = [i for i, (kind, _, _) in enumerate(kinds) if kind == "empty"]
    if empty:
        problems.append(
            f"column(s) {', '.join(str(i + 1) for i in empty)} of the header have "
            f"no name"
        )
    layout_joints = {_norm(n): k for k, n in enumerate(layout.names)}
    # names of `layout` (a list) that are not joints of the layout it matched
    strange = [known[j] for j in coords_of if j not in layout_joints]
    columns = []
    for i in sorted(unknown):
        match = _COORD_RE.match(tokens[i])
        if kinds[i][0] == "unknown" and match and match.group(1):
            strange.append(match.group(1))
        else:
            columns.append(repr(tokens[i]))
    if strange:
        problems.append(
            f"joint(s) {_listed(dict.fromkeys(strange), 5)} are not in layout "
            f"{layout.name!r} ({_listed(layout.names, 4)}); give the right `layout`"
        )
    if columns:
        problems.append(
            f"column(s) {_listed(columns)} name no coordinate of a joint of layout "
            f"{layout.name!r} (<joint>_x, <joint>_y, <joint>_z), nor a frame or "
            f"time column"
        )
    missing = [
        _axis_name(tokens, cols, a)
        for cols in coords_of.values()
        for a in range(3)
        if cols[a] < 0
    ]
    if missing:
        problems.append(
            f"the header has no column {_listed(missing)} (each joint it names "
            f"needs its x, y and z columns)"
        )
    absent = _required(layout.adapter, layout.names) - set(coords_of)
    if absent:
        names = [n for n in layout.names if _norm(n) in absent]
        problems.append(
            f"layout {layout.name!r} needs joint(s) {_listed(names)}, which the file "
            f"does not have"
        )
    if not problems and layout.order is not None:
        order = [_norm(j) for j in layout.order]
        if list(coords_of) != order:
            named = [known[j] for j in coords_of]
            problems.append(
                f"the header names the joints {_listed(named, 4)} but `layout` "
                f"lists {_listed(layout.order, 4)}"
            )
    coords = np.full((layout.n_joints, 3), -1, dtype=np.intp)
    for joint, cols in coords_of.items():
        if joint in layout_joints:
            coords[layout_joints[joint]] = cols
    times = [i for i, (kind, _, _) in enumerate(kinds) if kind == "time"]
    frame = frames[0] if frames and frame_column is not False else None
    return coords, frame, times[0] if times else None, problems


def _positional_columns(n_columns, layout, name, line, frame_column, lead):
    """``(coords, frame, time, per_joint)`` of a file read by position.

    The joints are in the order of ``layout`` after an optional first column
    (the frame number, or a timestamp when ``lead`` is ``"time"``); a header,
    if any, names no joint of the layout (``lead``: what its first name says
    the first column is, or None). Raises when the number of values fits no
    reading, or more than one.
    """
    take = layout.take(layout.order, name)
    n_file = layout.n_joints if layout.order is None else len(layout.order)
    if frame_column is None:
        firsts = (0, 1) if lead is None else (1,)
    else:
        firsts = (int(frame_column),)
    options = [
        (first, per_joint)
        for first in firsts
        for per_joint in (3, 4)
        if first + per_joint * n_file == n_columns
    ]
    if not options:
        if frame_column is None and lead is not None:
            frame_part = f" + 1 (the header names a {lead} column first)"
        else:
            frame_part = {
                None: " (+1 with a frame number first)",
                True: " + 1",
                False: "",
            }[frame_column]
        raise _format_error(
            name,
            line,
            f"expected {3 * n_file} or {4 * n_file} values{frame_part} per line for "
            f"{n_file} joints of layout {layout.name!r} (x, y, z and an optional 4th "
            f"value per joint), got {n_columns}",
        )
    if len(options) > 1:
        readings = " or ".join(
            f"{'a frame number and ' if first else ''}{per_joint} values per joint"
            for first, per_joint in options
        )
        raise _format_error(
            name,
            line,
            f"{n_columns} values per line fit {readings} for the {n_file} joint(s) of "
            f"layout {layout.name!r}; say which with frame_column=True or False, or "
            f"add a header naming the columns",
        )
    first, per_joint = options[0]
    coords = np.full((layout.n_joints, 3), -1, dtype=np.intp)
    present = take >= 0
    coords[present] = first + per_joint * take[present, None] + np.arange(N_COORDS)
    is_time = first and lead == "time" and frame_column is None
    frame = 0 if first and not is_time else None
    return coords, frame, 0 if is_time else None, per_joint


def _looks_like_frame_numbers(column):
    """Whether a column holds increasing integers, mostly one apart."""
    if len(column) < MIN_FRAME_LIKE_LINES or not np.isfinite(column).all():
        return False
    steps = np.diff(column)
    return bool(
        np.all(column == np.round(column))
        and np.all(steps > 0)
        and np.mean(steps == 1) >= FRAME_LIKE_SHARE
    )


def _drop_trailing_empty(line, sep):
    """``line`` without the separator that ends it (an empty last value)."""
    text = line.rstrip(" \r")
    return text[: -len(sep)] if text.endswith(sep) else line


def _read_skeleton(path, layout, *, delimiter, header, frame_column, name=None):
    """``(X, frame_numbers or None)`` of one skeleton file (see read_skeleton_csv).

    ``name`` names the file in messages (default: its base name).
    """
    name = path.name if name is None else name
    frame_column = None if frame_column is None else bool(frame_column)
    lines = _lines(_read_text(path, name=name))
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
    if has_header and sep is not None and len(tokens) > 1 and not tokens[-1]:
        # A trailing separator on every line (spreadsheet exports): no column.
        tokens = tokens[:-1]
        body = [_drop_trailing_empty(ln, sep) for ln in body]
    # A header names the columns: every line must have a value for each.
    n_columns = len(tokens) if has_header else len(_split(body[0], sep))
    found = lead = None
    if has_header:
        found = _header_columns(tokens, layout, frame_column)
        if found is not None and found[3]:
            raise _format_error(name, 1, "; ".join(found[3]))
        first_name = _norm(tokens[0])
        lead = (
            "frame"
            if first_name in FRAME_NAMES
            else "time"
            if first_name in TIME_NAMES
            else None
        )
    check_first = False
    if found is None:
        coords, frame, time, per_joint = _positional_columns(
            n_columns, layout, name, first, frame_column, lead
        )
        check_first = frame_column is None and lead is None and frame is None
    else:
        coords, frame, time, _ = found
    values = _parse_table(
        body, n_columns, name, sep=sep, first_line=first, allow_nan=True
    )
    frame_numbers = None
    if frame is not None:
        frame_numbers = _integer_column(
            values[:, frame], name, first_line=first, what="frame number"
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
    if time is not None:
        _check_times(values[:, time], name, first)
    if check_first and _looks_like_frame_numbers(values[:, 0]):
        n_file = layout.n_joints if layout.order is None else len(layout.order)
        shown = ", ".join(f"{v:g}" for v in values[:3, 0])
        raise _format_error(
            name,
            None,
            f"the first value of every line looks like a frame number ({shown}, "
            f"...), but {n_columns} values per line fit layout {layout.name!r} only "
            f"without a frame number ({n_file} joints x {per_joint} values): with "
            f"one, a value is missing from every line. Pass frame_column=False if "
            f"the first value is a coordinate; otherwise add the missing column, or "
            f"a header naming the columns",
        )
    special = [c for c in (frame, time) if c is not None]
    data = np.setdiff1d(np.arange(n_columns), special)
    raw = values[:, data]
    big = np.abs(raw) > MAX_ABS_RAW_VALUE
    if big.any():
        i, j = np.argwhere(big)[0]
        raise _format_error(
            name,
            int(i) + first,
            f"value {data[j] + 1} ({raw[i, j]:g}) is beyond +-{MAX_ABS_RAW_VALUE:g} "
            f"in any unit; the file is corrupt",
        )
    frames = np.zeros((len(values), layout.n_joints, N_COORDS))
    present = coords[:, 0] >= 0
    frames[:, present] = values[:, coords[present]]
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


def _check_times(column, name, first):
    """Raise unless a timestamp column is finite and never decreases."""
    bad = np.flatnonzero(~np.isfinite(column))
    if bad.size:
        i = int(bad[0])
        raise _format_error(
            name, i + first, f"timestamp {column[i]:g} is not a finite number"
        )
    back = np.flatnonzero(np.diff(column) < 0)
    if back.size:
        i = int(back[0]) + 1
        raise _format_error(
            name,
            i + first,
            f"timestamp {column[i]:g} is before {column[i - 1]:g} (timestamps must "
            f"not decrease)",
        )


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
        values is a number. A header that names joint columns
        ``<joint>_x, <joint>_y, <joint>_z`` (``.``, ``:``, ``-``, a blank or
        nothing may replace ``_``; any case) with joint names of ``layout``
        decides the columns by name, in any order: a column ``frame`` (or
        ``frame_number``, ``frame_id``, ...) holds the frame numbers, a column
        ``time`` or ``timestamp`` is checked (finite, never decreasing) and
        ignored, a column ``<joint>_<name>`` that most joints have (such as
        ``Head_confidence``) is ignored, and a missing, duplicated, unnamed or
        unknown column is an error naming it. A header that names no joint
        of ``layout`` (``j0_x, j0_y, ...``) is skipped and the values are read
        by position. A header that ends with an empty name (a trailing
        separator) has no column there.
    frame_column : bool or None, default=None
        Whether the file has a frame-number column. None decides: from a
        header naming the columns, by the name ``frame``; otherwise from the
        number of values (``3 * n_joints + 1`` or ``4 * n_joints + 1`` means a
        frame number first). It is an error when the number of values fits
        both readings, or when the first value of every line looks like a
        frame number (integers increasing mostly by 1) but the number of
        values fits only the reading without one (a column is missing, or
        the first value is a coordinate): say which with True or False. True:
        the column named ``frame``, else the first column, holds the frame
        numbers; False: no column does. Frame numbers must be increasing
        integers; they are returned, not used to place the rows.
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
        increasing integer, a position out of range; a header with a missing,
        duplicated or unknown column (naming it) or whose joints do not fit
        ``layout``; values whose layout is ambiguous (see ``frame_column``).

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
