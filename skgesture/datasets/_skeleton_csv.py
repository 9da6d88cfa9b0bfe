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
