"""Readers for the other real skeleton sets: MSRC-12, UTKinect-Action3D, MSR Action3D.

All three return the Bunch of :mod:`skgesture.datasets._base` in the Kinect v1 NUI
joint order. MSR Action3D stores its joints in another order and is reordered
with :data:`MSR_ACTION3D_TO_KINECT_V1`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import re

import numpy as np

from skgesture.datasets._base import (
    MAX_EXACT_INTEGER,
    DataFormatError,
    _check_magnitude,
    _descr,
    _empty_segments,
    _find_dir,
    _flag_all_zero,
    _format_error,
    _integer_column,
    _lines,
    _make_bunch,
    _parse_table,
    _progress,
    _read_text,
    _require_lines,
    _sort_and_label,
    _warn,
)
from skgesture.layouts import MSR_ACTION3D_TO_KINECT_V1, N_COORDS, N_KINECT_JOINTS

__all__ = [
    "MSR_ACTION3D_TO_KINECT_V1",
    "MSRC12_GESTURE_NAMES",
    "UTKINECT_ACTION_NAMES",
    "MSR_ACTION3D_ACTION_NAMES",
    "load_msrc12",
    "load_utkinect",
    "load_msr_action3d",
]

# ----------------------------------------------------------------------------
# MSRC-12
# ----------------------------------------------------------------------------

# Tag names of the .tagstream files (lower-cased); class k is index k - 1.
MSRC12_GESTURE_NAMES = (
    "lift outstretched arms", "duck", "push right", "goggles", "wind it up",
    "shoot", "bow", "throw", "had enough", "change weapon", "beat both", "kick",
)  # fmt: skip
MSRC12_FPS = 30.0  # Kinect v1 skeleton rate; rows are ~33,000 µs apart
MSRC12_VALUES_PER_JOINT = 4  # x, y, z, w (w = 1 tracked, 0 in all-zero rows)
MSRC12_N_VALUES = 1 + N_KINECT_JOINTS * MSRC12_VALUES_PER_JOINT  # timestamp + 80
# Official loader: t_us = (tick * 1000 + TICKS_PER_MS / 2) / TICKS_PER_MS.
MSRC12_TICKS_PER_MS = 49875
_MSRC12_FILE_RE = re.compile(r"^P(\d+)_(\d+)_(\d+)_p(\d+)\.csv$")
_MSRC12_TAG_RE = re.compile(r"^G([0-9]+)\s+\S")
_MSRC12_TICK_RE = re.compile(r"^[0-9]+$")
# Columns of x, y, z of every joint in a MSRC-12 line (after the timestamp).
_MSRC12_XYZ = (
    1
    + np.arange(N_KINECT_JOINTS)[:, None] * MSRC12_VALUES_PER_JOINT
    + np.arange(N_COORDS)
).ravel()
_MSRC12_HEADER = "XQPCTick;Tag"

_MSRC12_DESCR = """
MSRC-12 Kinect gesture dataset (S. Fothergill, H. Mentis, P. Kohli, S. Nowozin,
"Instructing People for Training Gestural Interactive Systems", CHI 2012).
Kinect v1 streams at 30 Hz, each holding about 10 repetitions of ONE gesture
separated by rest. The annotation is one action point per repetition (the moment
it should be recognised), not an interval: ``y`` is all zeros and ``segments``
empty; ``action_points`` holds the 0-based frame of each action point (the row
whose timestamp is closest) and ``action_classes`` its class. Leading all-zero
rows (no skeleton yet) are kept and flagged in ``missing``. ``timestamps`` are the
row times in microseconds. Research use only.
"""


def _parse_tagstream(text, name):
    """``(ticks, classes)`` of a ``.tagstream`` file."""
    lines = _lines(text)
    _require_lines(lines, name, f"a header line {_MSRC12_HEADER!r}")
    if lines[0].strip() != _MSRC12_HEADER:
        raise _format_error(
            name,
            1,
            f"expected the header {_MSRC12_HEADER!r}, got {lines[0].strip()[:40]!r}",
        )
    ticks, classes = [], []
    for i, line in enumerate(lines[1:], start=2):
        tick, sep, tag = line.partition(";")
        match = _MSRC12_TAG_RE.match(tag.strip())
        if not sep or not _MSRC12_TICK_RE.match(tick.strip()) or match is None:
            raise _format_error(
                name, i, f"expected 'tick;Gk gesture name', got {line.strip()[:60]!r}"
            )
        if int(tick) > MAX_EXACT_INTEGER:
            raise _format_error(
                name, i, f"tick {tick.strip()[:40]} is beyond 2**53; corrupt file"
            )
        cls = int(match.group(1))
        if not 1 <= cls <= len(MSRC12_GESTURE_NAMES):
            raise _format_error(
                name,
                i,
                f"gesture G{match.group(1)[:20]} is outside "
                f"G1..G{len(MSRC12_GESTURE_NAMES)}",
            )
        ticks.append(int(tick))
        classes.append(cls)
    return np.array(ticks, dtype=np.int64), np.array(classes, dtype=np.int64)


def _action_point_frames(ticks, timestamps):
    """Row index whose timestamp (µs) is closest to each tick (official rule)."""
    t_us = (ticks * 1000.0 + MSRC12_TICKS_PER_MS / 2) / MSRC12_TICKS_PER_MS
    if not len(t_us):
        return np.zeros(0, dtype=np.int64)
    return np.abs(timestamps[None, :] - t_us[:, None]).argmin(axis=1).astype(np.int64)


def load_msrc12(path, *, verbose=0):
    """Load (a subset of) the MSRC-12 Kinect gesture dataset.

    Continuous 30 Hz streams, each with about 10 repetitions of one of 12
    gestures, annotated with action points (not intervals).

    Parameters
    ----------
    path : str or path-like
        Folder with the ``P*_*_*_pNN.csv`` skeleton files and their
        ``.tagstream`` files (or the folder holding its ``data`` subfolder).
    verbose : int, default=0
        0 is silent; 1 shows a tqdm progress bar over the files.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys ``X`` (list of (n_frames_i, 20, 3) float64
        arrays, metres, Kinect v1 NUI order; the ``w`` column is dropped), ``y`` (all
        zeros: no intervals are annotated), ``segments`` (empty (0, 3) arrays),
        ``action_points`` (list of int64 arrays: 0-based frame of each action point),
        ``action_classes`` (list of int64 arrays: its class 1..12), ``timestamps`` (list
        of int64 arrays, microseconds), ``sample_ids`` (file stems such as
        ``"P3_1_1_p01"``), ``groups`` (subject number, int), ``fps`` (30.0),
        ``n_frames``, ``missing``, ``target_names``, ``layout`` and ``DESCR``. Sequences
        are sorted by subject, then gesture.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist or holds no skeleton file.
    DataFormatError
        For a malformed file, naming the file and the 1-based line: wrong
        number of values, a value that is not a finite number, a timestamp
        that is not an integer of at most 2**53, a position beyond 10 km.

    Warns
    -----
    DataFileWarning
        If a ``.tagstream`` file is missing (no action points for that file) or
        names another gesture than the file name.

    See Also
    --------
    load_precog : Continuous streams with per-frame labels.

    Notes
    -----
    An action point tick is converted to the csv time axis as the official
    loader does, ``t_us = (tick * 1000 + 49875 / 2) / 49875``, and mapped to the
    row with the closest timestamp. Leading all-zero rows, which the official
    loader drops, are kept here (and marked in ``missing``) so that row indices
    match the files.

    References
    ----------
    .. [1] S. Fothergill, H. M. Mentis, P. Kohli and S. Nowozin, "Instructing
       People for Training Gestural Interactive Systems", CHI 2012.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import load_msrc12
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> rows = [f"{t} " + " ".join(["0.5 0.5 2.5 1"] * 20) for t in (0, 33333, 66666)]
    >>> _ = (folder / "P3_1_4_p07.csv").write_text("\\n".join(rows) + "\\n")
    >>> _ = (folder / "P3_1_4_p07.tagstream").write_text(
    ...     "XQPCTick;Tag\\n1662458;G4  Goggles\\n")
    >>> data = load_msrc12(folder)
    >>> data.X[0].shape, data.groups.tolist(), data.action_points[0].tolist()
    ((3, 20, 3), [7], [1])
    >>> data.target_names[data.action_classes[0][0] - 1]
    'goggles'
    >>> tmp.cleanup()
    """
    folder = _find_dir(path, child="data", pattern="P*_*_*_p*.csv")
    files = []
    for entry in folder.iterdir():
        match = _MSRC12_FILE_RE.match(entry.name)
        if match and entry.is_file():
            gesture, subject = int(match.group(3)), int(match.group(4))
            files.append((subject, gesture, entry.stem, entry))
    files.sort(key=lambda f: f[:3])
    X, timestamps, points, classes = [], [], [], []
    for subject, gesture, stem, file in _progress(
        files, verbose=verbose, desc="MSRC-12 files"
    ):
        lines = _lines(_read_text(file))
        _require_lines(lines, file.name, f"{MSRC12_N_VALUES} values per line")
        values = _parse_table(lines, MSRC12_N_VALUES, file.name)
        ts = values[:, 0]
        _check_magnitude(values, file.name, columns=_MSRC12_XYZ)
        joints = values[:, 1:].reshape(len(values), N_KINECT_JOINTS, -1)
        X.append(np.ascontiguousarray(joints[:, :, :N_COORDS]))
        timestamps.append(_integer_column(ts, file.name, what="timestamp"))
        tag_file = file.with_suffix(".tagstream")
        if tag_file.is_file():
            ticks, cls = _parse_tagstream(_read_text(tag_file), tag_file.name)
        else:
            _warn(f"{file.name}: no {tag_file.name}; no action points for it")
            ticks, cls = np.zeros(0, np.int64), np.zeros(0, np.int64)
        if np.any(cls != gesture):
            _warn(
                f"{tag_file.name}: tags name gesture(s) {sorted(set(cls.tolist()))} "
                f"but the file name says G{gesture}"
            )
        points.append(_action_point_frames(ticks, ts))
        classes.append(cls)
    sample_ids = [f[2] for f in files]
    n_frames = np.array([len(x) for x in X], dtype=np.int64)
    _flag_all_zero(X, sample_ids)
    return _make_bunch(
        X=X,
        y=[np.zeros(n, dtype=np.int64) for n in n_frames],
        segments=[_empty_segments() for _ in X],
        sample_ids=sample_ids,
        groups=np.array([f[0] for f in files], dtype=np.int64),
        fps=MSRC12_FPS,
        n_frames=n_frames,
        target_names=MSRC12_GESTURE_NAMES,
        descr=_descr(
            "MSRC-12 Kinect gestures", _MSRC12_DESCR, len(X), n_frames.sum(), 0
        ),
        action_points=points,
        action_classes=classes,
        timestamps=timestamps,
    )


# ----------------------------------------------------------------------------
# UTKinect-Action3D
# ----------------------------------------------------------------------------

# The fixed action order of every sequence; class k is index k - 1.
UTKINECT_ACTION_NAMES = (
    "walk", "sitDown", "standUp", "pickUp", "carry",
    "throw", "push", "pull", "waveHands", "clapHands",
)  # fmt: skip
UTKINECT_VIDEO_FPS = 30.0  # the authors' video rate; skeleton rows are irregular
UTKINECT_N_VALUES = 1 + N_KINECT_JOINTS * N_COORDS  # frame number + 60
UTKINECT_LABEL_FILES = {
    "original": "actionLabel.txt",
    "alt": "actionLabel_alt_kvega005.txt",
}
_UTK_FILE_RE = re.compile(r"^joints_s(\d+)_e(\d+)\.txt$")
_UTK_BLOCK_RE = re.compile(r"^s\d+_e\d+$")
_UTK_LINE_RE = re.compile(r"^(\w+):\s*(\S+)\s+(\S+)$")

_UTK_DESCR = """
UTKinect-Action3D (L. Xia, C.-C. Chen, J. K. Aggarwal, "View invariant human
action recognition using histograms of 3D joints", CVPR-W 2012). Kinect v1
skeletons of 10 subjects x 2 recordings, each performing 10 whole-body actions in
a fixed order. Rows exist only where a skeleton was tracked: ``frame_numbers``
gives the video frame of each row (30 fps video) and ``fps`` the mean row rate of
each sequence. Labels (video frame numbers, inclusive) are mapped to the rows
whose frame number lies in [start, end]; overlapping push/pull labels are kept in
``segments`` and the later-starting one wins in ``y``. Research use only.
"""


def _parse_utk_labels(text, name):
    """``{"s01_e01": [(class, start, end) or None, ...]}`` of a label file."""
    lines = _lines(text)
    _require_lines(lines, name, "blocks of a 'sXX_eYY' line and 10 action lines")
    blocks, current = {}, None
    for i, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line:
            continue
        if _UTK_BLOCK_RE.match(line):
            if line in blocks:
                raise _format_error(name, i, f"sequence {line} appears twice")
            current = blocks[line] = {}
            continue
        match = _UTK_LINE_RE.match(line)
        if current is None or match is None:
            raise _format_error(
                name, i, f"expected 'sXX_eYY' or 'action: start end', got {line[:60]!r}"
            )
        action, start, end = match.groups()
        if action not in UTKINECT_ACTION_NAMES:
            raise _format_error(
                name,
                i,
                f"unknown action {action[:40]!r}; expected one of "
                f"{', '.join(UTKINECT_ACTION_NAMES)}",
            )
        if start == "NaN" and end == "NaN":
            current[action] = None
            continue
        try:
            s, e = float(start), float(end)
        except ValueError:
            raise _format_error(
                name,
                i,
                f"start/end must be numbers or 'NaN NaN', got {start[:40]!r} "
                f"{end[:40]!r}",
            ) from None
        if not (np.isfinite(s) and np.isfinite(e)) or s > e:
            raise _format_error(
                name, i, f"start {start[:40]} is after end {end[:40]} or not finite"
            )
        current[action] = (UTKINECT_ACTION_NAMES.index(action) + 1, s, e)
    return blocks


def load_utkinect(path, *, labels="original", verbose=0):
    """Load the UTKinect-Action3D skeletons with their action intervals.

    Continuous streams of 10 whole-body actions in a fixed order; the start/end
    labels, given in video frame numbers, are mapped to skeleton rows.

    Parameters
    ----------
    path : str or path-like
        Folder with ``joints_sXX_eYY.txt`` and ``actionLabel.txt`` (or the
        folder holding its ``joints`` subfolder).
    labels : {"original", "alt"}, default="original"
        Which label file: ``actionLabel.txt`` or the second public copy
        ``actionLabel_alt_kvega005.txt`` (7 differences, see the data notes).
    verbose : int, default=0
        0 is silent; 1 shows a tqdm progress bar over the files.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys ``X`` (list of (n_rows_i, 20, 3) float64
        arrays, metres, Kinect v1 NUI order), ``y`` (per-row int64 labels, 0 =
        unlabelled, 1..10), ``segments`` (rows ``(class, start, end)`` over row indices,
        0-based, end exclusive, sorted by start), ``frame_numbers`` (list of int64
        arrays: video frame of each row), ``sample_ids`` (``"s01_e01"``, ...),
        ``groups`` (subject, int), ``fps`` (ndarray: mean skeleton rows per second of
        each sequence, from the 30 fps frame numbers), ``n_frames``, ``missing``,
        ``target_names``, ``layout`` and ``DESCR``.

    Raises
    ------
    FileNotFoundError
        If ``path``, the joints files or the label file do not exist.
    DataFormatError
        For a malformed file (naming the file and the 1-based line: wrong
        number of values, a value that is not a finite number, a frame number
        that is not an integer of at most 2**53 or goes backwards, a position
        beyond 10 km) or a sequence without labels.
    ValueError
        For an unknown ``labels`` value.

    Warns
    -----
    DataFileWarning
        When labels overlap (push/pull in three sequences of the original file)
        or an interval holds no skeleton row.

    See Also
    --------
    load_msr_action3d : Isolated action clips.

    Notes
    -----
    The original label file keeps an obvious typo (s03_e01 push starting at
    2556 instead of 3556, overlapping earlier actions); ``labels="alt"`` fixes
    it. ``NaN NaN`` marks an absent action (s10_e02 carry).

    References
    ----------
    .. [1] L. Xia, C.-C. Chen and J. K. Aggarwal, "View invariant human action
       recognition using histograms of 3D joints", CVPR Workshops, 2012.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import load_utkinect
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> rows = [f"{f} " + " ".join(["0.5"] * 60) for f in (10, 14, 18, 22, 26)]
    >>> _ = (folder / "joints_s01_e01.txt").write_text("\\n".join(rows))
    >>> actions = ["walk: 14 18"] + [f"{a}: NaN NaN" for a in (
    ...     "sitDown", "standUp", "pickUp", "carry", "throw", "push", "pull",
    ...     "waveHands", "clapHands")]
    >>> _ = (folder / "actionLabel.txt").write_text("\\n".join(["s01_e01"] + actions))
    >>> data = load_utkinect(folder)
    >>> data.y[0].tolist(), data.segments[0].tolist(), data.frame_numbers[0][:2]
    ([0, 1, 1, 0, 0], [[1, 1, 3]], array([10, 14]))
    >>> tmp.cleanup()
    """
    if labels not in UTKINECT_LABEL_FILES:
        raise ValueError(
            f"labels must be one of {sorted(UTKINECT_LABEL_FILES)}, got {labels!r}"
        )
    folder = _find_dir(path, child="joints", pattern="joints_s*_e*.txt")
    label_file = folder / UTKINECT_LABEL_FILES[labels]
    if not label_file.is_file():
        raise FileNotFoundError(f"label file {str(label_file)!r} does not exist")
    blocks = _parse_utk_labels(_read_text(label_file), label_file.name)
    files = []
    for entry in folder.iterdir():
        match = _UTK_FILE_RE.match(entry.name)
        if match and entry.is_file():
            files.append((int(match.group(1)), int(match.group(2)), entry))
    files.sort(key=lambda f: f[:2])
    X, y, segments, frames, fps, sample_ids = [], [], [], [], [], []
    overlaps = []
    for subject, take, file in _progress(files, verbose=verbose, desc="UTKinect files"):
        sid = f"s{subject:02d}_e{take:02d}"
        lines = _lines(_read_text(file))
        _require_lines(lines, file.name, f"{UTKINECT_N_VALUES} values per line")
        values = _parse_table(lines, UTKINECT_N_VALUES, file.name)
        number = values[:, 0]
        step = np.diff(number)
        bad = (
            (number != np.round(number))
            | (np.abs(number) > MAX_EXACT_INTEGER)
            | np.r_[False, step < 0]
        )
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise _format_error(
                file.name,
                i + 1,
                f"frame number {number[i]:g} is not an integer of at most 2**53 or "
                f"goes backwards",
            )
        _check_magnitude(values, file.name, columns=slice(1, None))
        if sid not in blocks:
            raise DataFormatError(
                f"{label_file.name} has no labels for {sid}", file=label_file.name
            )
        rows, spans = [], []
        for action in UTKINECT_ACTION_NAMES:
            entry = blocks[sid].get(action)
            if entry is None:
                continue
            cls, start, end = entry
            inside = np.flatnonzero((number >= start) & (number <= end))
            if inside.size == 0:
                _warn(
                    f"{sid}: {action} {start:g}-{end:g} covers no skeleton row; "
                    f"it is left out"
                )
                continue
            rows.append((cls, inside[0], inside[-1] + 1))
            spans.append(f"{action} {start:g}-{end:g}")
        seg, lab, pairs = _sort_and_label(rows, len(values))
        overlaps += [f"{sid} {spans[a]} / {spans[b]}" for a, b in pairs]
        X.append(values[:, 1:].reshape(len(values), N_KINECT_JOINTS, N_COORDS))
        y.append(lab)
        segments.append(seg)
        frames.append(_integer_column(number, file.name, what="frame number"))
        span = number[-1] - number[0]
        fps.append(UTKINECT_VIDEO_FPS * (len(number) - 1) / span if span else np.nan)
        sample_ids.append(sid)
    if overlaps:
        _warn(
            f"{label_file.name}: {len(overlaps)} labelled interval(s) overlap an "
            f"earlier one (frame numbers, inclusive): {'; '.join(overlaps)}. Both are "
            f"kept in `segments`; in `y` the later-starting one wins"
        )
    n_frames = np.array([len(x) for x in X], dtype=np.int64)
    return _make_bunch(
        X=X,
        y=y,
        segments=segments,
        sample_ids=sample_ids,
        groups=np.array([f[0] for f in files], dtype=np.int64),
        fps=np.array(fps),
        n_frames=n_frames,
        target_names=UTKINECT_ACTION_NAMES,
        descr=_descr(
            f"UTKinect-Action3D ({label_file.name})",
            _UTK_DESCR,
            len(X),
            n_frames.sum(),
            sum(len(s) for s in segments),
        ),
        frame_numbers=frames,
    )


# ----------------------------------------------------------------------------
# MSR Action3D
# ----------------------------------------------------------------------------

MSR_ACTION3D_ACTION_NAMES = (
    "high arm wave", "horizontal arm wave", "hammer", "hand catch",
    "forward punch", "high throw", "draw x", "draw tick", "draw circle",
    "hand clap", "two hand wave", "side boxing", "bend", "forward kick",
    "side kick", "jogging", "tennis swing", "tennis serve", "golf swing",
    "pickup and throw",
)  # fmt: skip
MSR_ACTION3D_FPS = 15.0  # "about 15 fps" (depth camera of the recordings)
MSR_ACTION3D_VALUES = 4  # x, y, z, confidence
MSR_ACTION3D_CVPR12_LIST = "files_used_in_cvpr12_paper.txt"
_MSR_FILE_RE = re.compile(r"^a(\d+)_s(\d+)_e(\d+)_skeleton3D\.txt$")

_MSR_DESCR = """
MSR Action3D (W. Li, Z. Zhang, Z. Liu, "Action recognition based on a bag of 3D
points", CVPR-W 2010), skeletons in real-world coordinates. Isolated clips of 20
actions by 10 subjects, about 15 fps, 20 joints estimated from depth. Joints are
reordered from the MSR file order to the Kinect v1 NUI order
(``MSR_ACTION3D_TO_KINECT_V1``); ``joint_confidence`` holds the 4th value of each
joint. Every frame of a clip carries the clip's label. subset="cvpr12" keeps the
557 clips of the common CVPR 2012 protocol. Research use only.
"""


def _parse_msr_clip(text, name):
    """``(X, confidence)`` of one clip, in Kinect v1 joint order."""
    lines = _lines(text)
    _require_lines(lines, name, f"{N_KINECT_JOINTS} lines of 4 values per frame")
    values = _parse_table(lines, MSR_ACTION3D_VALUES, name)
    _check_magnitude(values, name, columns=slice(0, N_COORDS))
    if len(values) % N_KINECT_JOINTS:
        complete = len(values) // N_KINECT_JOINTS
        raise _format_error(
            name,
            complete * N_KINECT_JOINTS + 1,
            f"incomplete last frame ({len(values)} lines is not a multiple of "
            f"{N_KINECT_JOINTS}, one line per joint)",
        )
    frames = values.reshape(-1, N_KINECT_JOINTS, MSR_ACTION3D_VALUES)
    frames = frames[:, MSR_ACTION3D_TO_KINECT_V1]
    return np.ascontiguousarray(frames[:, :, :N_COORDS]), frames[:, :, N_COORDS]


def load_msr_action3d(path, *, subset="cvpr12", verbose=0):
    """Load the MSR Action3D skeleton clips (isolated actions).

    Each clip is one pre-segmented action; its joints are reordered from the MSR
    order to the Kinect v1 NUI order.

    Parameters
    ----------
    path : str or path-like
        Folder with the ``aXX_sYY_eZZ_skeleton3D.txt`` files (or the folder
        holding its ``real_world_coordinates`` subfolder).
    subset : {"cvpr12", "all"}, default="cvpr12"
        ``"cvpr12"``: the clips listed in ``files_used_in_cvpr12_paper.txt`` (557,
        the usual protocol, which leaves out the corrupt ones); ``"all"``: every
        clip (567).
    verbose : int, default=0
        0 is silent; 1 shows a tqdm progress bar over the clips.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys ``X`` (list of (n_frames_i, 20, 3) float64
        arrays, metres, reordered to Kinect v1 NUI order), ``y`` (the clip's action
        1..20 on every frame), ``segments`` (one row ``(action, 0, n_frames_i)`` per
        clip), ``joint_confidence`` (list of (n_frames_i, 20) arrays: the 4th value),
        ``sample_ids`` (``"a01_s01_e01"``, ...), ``groups`` (subject, int),
        ``repetitions`` (ZZ, int), ``fps`` (15.0), ``n_frames``, ``missing``,
        ``target_names``, ``layout`` and ``DESCR``. Clips are sorted by action, subject,
        repetition.

    Raises
    ------
    FileNotFoundError
        If ``path`` or its clips do not exist, or ``subset="cvpr12"`` and the
        list file is absent.
    DataFormatError
        For a malformed clip, naming the file and the 1-based line (wrong
        number of values, a value that is not a finite number, a position
        beyond 10 km, an incomplete last frame).
    ValueError
        For an unknown ``subset``.

    Warns
    -----
    DataFileWarning
        For an all-zero clip (``a13_s09_e02``, read with ``subset="all"``; it is
        kept with ``missing`` all True) and for clips of the list that are absent.

    See Also
    --------
    load_utkinect : Continuous whole-body action streams.

    References
    ----------
    .. [1] W. Li, Z. Zhang and Z. Liu, "Action recognition based on a bag of 3D
       points", CVPR Workshops, 2010.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture.datasets import MSR_ACTION3D_TO_KINECT_V1
    >>> from skgesture.layouts import KINECT_V1
    >>> head = KINECT_V1.index("Head")
    >>> MSR_ACTION3D_TO_KINECT_V1[head] + 1  # the head is joint 20 in MSR files
    20
    >>> x_msr = np.arange(20 * 3, dtype=float).reshape(1, 20, 3)
    >>> x_msr[:, MSR_ACTION3D_TO_KINECT_V1][0, head].tolist()
    [57.0, 58.0, 59.0]
    """
    if subset not in ("cvpr12", "all"):
        raise ValueError(f"subset must be 'cvpr12' or 'all', got {subset!r}")
    folder = _find_dir(
        path, child="real_world_coordinates", pattern="a*_s*_e*_skeleton3D.txt"
    )
    clips = {}
    for entry in folder.iterdir():
        match = _MSR_FILE_RE.match(entry.name)
        if match and entry.is_file():
            key = tuple(int(g) for g in match.groups())
            clips[f"a{key[0]:02d}_s{key[1]:02d}_e{key[2]:02d}"] = (key, entry)
    if subset == "cvpr12":
        list_file = folder / MSR_ACTION3D_CVPR12_LIST
        if not list_file.is_file():
            raise FileNotFoundError(
                f"{str(list_file)!r} does not exist; use subset='all' to read every "
                f"clip"
            )
        listed = [ln.strip() for ln in _lines(_read_text(list_file)) if ln.strip()]
        absent = [c for c in listed if c not in clips]
        if absent:
            _warn(
                f"{len(absent)} clip(s) of {MSR_ACTION3D_CVPR12_LIST} are absent: "
                f"{', '.join(absent[:5])}{', ...' if len(absent) > 5 else ''}"
            )
        clips = {c: clips[c] for c in listed if c in clips}
    order = sorted(clips, key=lambda c: clips[c][0])
    X, confidence, y, segments = [], [], [], []
    for clip in _progress(order, verbose=verbose, desc="MSR Action3D clips"):
        (action, _, _), file = clips[clip]
        if not 1 <= action <= len(MSR_ACTION3D_ACTION_NAMES):
            raise DataFormatError(
                f"{file.name}: action a{action:02d} is outside a01..a20",
                file=file.name,
            )
        x, conf = _parse_msr_clip(_read_text(file), file.name)
        X.append(x)
        confidence.append(conf)
        y.append(np.full(len(x), action, dtype=np.int64))
        segments.append(np.array([[action, 0, len(x)]], dtype=np.int64))
    _flag_all_zero(X, order, what="clip")
    n_frames = np.array([len(x) for x in X], dtype=np.int64)
    return _make_bunch(
        X=X,
        y=y,
        segments=segments,
        sample_ids=order,
        groups=np.array([clips[c][0][1] for c in order], dtype=np.int64),
        fps=MSR_ACTION3D_FPS,
        n_frames=n_frames,
        target_names=MSR_ACTION3D_ACTION_NAMES,
        descr=_descr(
            f"MSR Action3D (subset={subset})",
            _MSR_DESCR,
            len(X),
            n_frames.sum(),
            len(X),
        ),
        joint_confidence=confidence,
        repetitions=np.array([clips[c][0][2] for c in order], dtype=np.int64),
    )
