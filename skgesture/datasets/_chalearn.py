"""ChaLearn LAP 2014 Track 3 (Montalbano V2) reader and prediction writer.

Also reads the ChaLearn 2013 (Montalbano V1) samples once converted to the same
three CSV files. File formats: docs/method.md §1.2-§1.7; the writer applies the
clamping of docs/method.md §2.2 so that the official scorer never silently drops or
misfiles a prediction.
"""

# SPDX-License-Identifier: BSD-3-Clause

import re
import zipfile
import zlib
from pathlib import Path

import numpy as np

from skgesture.datasets._base import (
    DataFormatError,
    _check_magnitude,
    _check_path,
    _decode,
    _descr,
    _empty_segments,
    _format_error,
    _lines,
    _make_bunch,
    _parse_table,
    _progress,
    _read_text,
    _require_lines,
    _sort_and_label,
    _warn,
)
from skgesture.layouts import N_COORDS, N_KINECT_JOINTS
from skgesture.utils._segments import from_file_lines, labels_to_segments, to_file_lines

__all__ = [
    "CHALEARN_GESTURE_NAMES",
    "load_chalearn",
    "read_chalearn_labels",
    "write_chalearn_predictions",
]

# docs/method.md §1.6: class id k (1-based) is CHALEARN_GESTURE_NAMES[k - 1].
CHALEARN_GESTURE_NAMES = (
    "vattene", "vieniqui", "perfetto", "furbo", "cheduepalle",
    "chevuoi", "daccordo", "seipazzo", "combinato", "freganiente",
    "ok", "cosatifarei", "basta", "prendere", "noncenepiu",
    "fame", "tantotempo", "buonissimo", "messidaccordo", "sonostufo",
)  # fmt: skip
N_CHALEARN_CLASSES = len(CHALEARN_GESTURE_NAMES)  # docs/method.md §1.6
CHALEARN_FPS = 20.0  # docs/method.md §1.3: every Montalbano sequence
VALUES_PER_JOINT = 9  # Wx, Wy, Wz, 4 rotation, Px, Py (docs/method.md §1.4)
N_SKELETON_COLUMNS = N_KINECT_JOINTS * VALUES_PER_JOINT  # 180
N_LABEL_COLUMNS = 3  # class, start, end (docs/method.md §1.5)
N_DATA_COLUMNS = 3  # numFrames, fps, maxDepth (docs/method.md §1.3)
# numFrames may differ from the skeleton's line count by this much (the skeleton
# is then padded with missing frames or truncated, with a warning); beyond it the
# two files disagree too much to trust either and loading stops. Every real
# sample has exactly numFrames lines.
FRAME_MISMATCH_FRAMES = 20  # one second at 20 fps ...
FRAME_MISMATCH_FRACTION = 0.05  # ... or 5 % of the skeleton, whichever is larger
# Without a skeleton (labels only) numFrames cannot be checked against data:
# a day at 20 fps is refused as corrupt, and a numFrames far beyond the last
# labelled frame (over 2 x last end + 30 s; the 230 validation samples stay
# within 1.33 x and 339 frames) is used with a warning.
MAX_LABELS_ONLY_FRAMES = 24 * 3600 * 20
TRAILING_REST_FRAMES = 600

_KINDS = ("skeleton", "labels", "data")
# Columns of the world positions Wx, Wy, Wz of every joint in a skeleton line.
_WORLD_COLUMNS = (
    np.arange(N_KINECT_JOINTS)[:, None] * VALUES_PER_JOINT + np.arange(N_COORDS)
).ravel()
_FILE_RE = re.compile(r"^(Sample\d{4,5})_(skeleton|labels|data)\.csv$")
_ZIP_RE = re.compile(r"^(Sample\d{4,5})\.zip$")
_DIR_RE = re.compile(r"^Sample\d{4,5}$")
_ID_RE = re.compile(r"^(?:Sample)?(\d+)$")

_DESCR_BODY = """
ChaLearn Looking at People 2014, Track 3 (gesture spotting), "Montalbano V2":
Kinect v1 recordings of 20 Italian cultural signs performed continuously, 20 fps.
Training Sample0001-0470, validation 0471-0700, test 0701-0940. Labels are
1-based inclusive (class, start, end) lines in the files; here ``segments`` are
0-based with an exclusive end and ``y`` is 0 outside every gesture. Untracked
frames are all-zero rows and are kept (see ``missing``). Cite S. Escalera et al.,
"ChaLearn Looking at People Challenge 2014: Dataset and Results", ECCV-W 2014.
The data are for research use under the challenge terms.
"""


# ----------------------------------------------------------------------------
# Finding the files of each sample
# ----------------------------------------------------------------------------


def _sample_number(sample_id):
    """Numeric part of a sample id given as int or (``Sample``-prefixed) str."""
    if isinstance(sample_id, (int, np.integer)) and not isinstance(sample_id, bool):
        return int(sample_id)
    match = _ID_RE.match(str(sample_id))
    if match is None:
        raise ValueError(
            f"sample id {sample_id!r} is not of the form 'Sample0123' or 123"
        )
    return int(match.group(1))


def _format_sample_id(sample_id):
    """``SampleXXXX`` name of a sample id given as int or str (writer side)."""
    if isinstance(sample_id, (int, np.integer)) and not isinstance(sample_id, bool):
        if sample_id < 0:
            raise ValueError(f"sample id {sample_id} is negative")
        return f"Sample{int(sample_id):04d}"
    match = _ID_RE.match(str(sample_id))
    if match is None:
        raise ValueError(
            f"sample id {sample_id!r} is not of the form 'Sample0123' or 123"
        )
    return f"Sample{match.group(1)}"


def _open_zip(path):
    try:
        return zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError, EOFError, ValueError) as exc:
        raise DataFormatError(
            f"{path.name} is not a valid zip file ({exc})", file=path.name
        ) from None


def _zip_members(path):
    """``{(sample_id, kind): member}`` of the skeleton/labels/data CSVs in a zip."""
    with _open_zip(path) as zf:
        names = zf.namelist()
    found = {}
    for member in names:
        match = _FILE_RE.match(member.rsplit("/", 1)[-1])
        if match:
            found[(match.group(1), match.group(2))] = member
    return found


def _scan_folder(folder, sources, *, prefer):
    """Add the extracted CSVs of ``folder`` to ``sources`` (if ``prefer`` or new)."""
    for entry in folder.iterdir():
        match = _FILE_RE.match(entry.name)
        if match and entry.is_file():
            key = match.group(2)
            slot = sources.setdefault(match.group(1), {})
            if prefer or key not in slot:
                slot[key] = ("file", entry)


def _discover(path):
    """Map each sample id to the source of its skeleton / labels / data file.

    A source is ``("file", Path)`` or ``("zip", Path, member)``. Extracted CSVs win
    over the same file inside a zip (the starting kit keeps both).
    """
    sources = {}
    if path.is_file():
        zmatch = _ZIP_RE.match(path.name)
        fmatch = _FILE_RE.match(path.name)
        if zmatch or path.suffix.lower() == ".zip":
            for (sid, kind), member in _zip_members(path).items():
                sources.setdefault(sid, {})[kind] = ("zip", path, member)
            if not sources:
                raise DataFormatError(
                    f"{path.name} holds no SampleXXXX_skeleton/labels/data.csv file",
                    file=path.name,
                )
        elif fmatch:
            _scan_folder(path.parent, sources, prefer=True)
            sources = {fmatch.group(1): sources[fmatch.group(1)]}
        else:
            raise ValueError(
                f"{path.name} is neither a SampleXXXX.zip nor a "
                f"SampleXXXX_{{skeleton,labels,data}}.csv file"
            )
        return sources
    if not path.is_dir():
        raise ValueError(f"{str(path)!r} is neither a file nor a folder")
    entries = sorted(path.iterdir())
    for entry in entries:
        if entry.is_file() and _ZIP_RE.match(entry.name):
            for (sid, kind), member in _zip_members(entry).items():
                sources.setdefault(sid, {})[kind] = ("zip", entry, member)
    for entry in entries:
        if entry.is_dir() and _DIR_RE.match(entry.name):
            _scan_folder(entry, sources, prefer=True)
    _scan_folder(path, sources, prefer=True)
    if not sources:
        raise FileNotFoundError(
            f"no ChaLearn sample (SampleXXXX.zip or SampleXXXX_skeleton/labels/"
            f"data.csv) in folder {str(path)!r}"
        )
    return sources


def _source_name(src):
    if src[0] == "zip":
        return f"{src[1].name}/{src[2]}"
    return src[1].name


def _source_lines(src):
    """Lines of a source file (inside a zip or not)."""
    if src[0] == "file":
        return _lines(_read_text(src[1]))
    try:
        with _open_zip(src[1]) as zf:
            data = zf.read(src[2])
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError) as exc:
        if isinstance(exc, DataFormatError):
            raise
        raise _format_error(
            _source_name(src), None, f"corrupt zip member ({exc})"
        ) from None
    return _lines(_decode(data, _source_name(src)))


# ----------------------------------------------------------------------------
# Parsing the three files of a sample
# ----------------------------------------------------------------------------


def _parse_data(lines, name):
    """``(n_frames, fps, max_depth)`` from the last line of a ``_data.csv``."""
    _require_lines(lines, name, "one line 'numFrames,fps,maxDepth'")
    n_frames, fps, max_depth = _parse_table(
        lines[-1:], N_DATA_COLUMNS, name, sep=",", first_line=len(lines)
    )[0]
    if n_frames != int(n_frames) or n_frames < 1:
        raise _format_error(
            name,
            len(lines),
            f"numFrames must be a positive integer, got {n_frames:g}",
        )
    if not fps > 0:
        raise _format_error(name, len(lines), f"fps must be > 0, got {fps:g}")
    return int(n_frames), float(fps), float(max_depth)


def _parse_labels(lines, name, n_frames=None):
    """0-based, end-exclusive segments from the lines of a labels file."""
    if not lines:
        return _empty_segments()
    raw = _parse_table(lines, N_LABEL_COLUMNS, name, sep=",", dtype=np.int64)
    cls, start, end = raw.T
    last = np.iinfo(np.int64).max if n_frames is None else n_frames
    bad = (
        (cls < 1) | (cls > N_CHALEARN_CLASSES) | (start < 1) | (start > end)
        | (end > last)
    )  # fmt: skip
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        c, s, e = raw[i].tolist()
        if not 1 <= c <= N_CHALEARN_CLASSES:
            why = f"class {c} is outside 1..{N_CHALEARN_CLASSES}"
        elif s < 1:
            why = f"start frame {s} is < 1 (frames are 1-based)"
        elif s > e:
            why = f"start frame {s} is after end frame {e}"
        else:
            why = f"end frame {e} is beyond the last frame {n_frames}"
        raise _format_error(name, i + 1, f"{why} (line {lines[i].strip()!r})")
    return from_file_lines(np.stack([cls, start, end], axis=1))


def read_chalearn_labels(file, *, n_frames=None):
    """Read a ChaLearn labels or prediction file into segments.

    The 1-based inclusive ``class,start,end`` lines become rows of the package's
    segment convention (0-based start, exclusive end).

    Parameters
    ----------
    file : str or path-like
        A ``SampleXXXX_labels.csv`` or ``SampleXXXX_prediction.csv`` file: one
        ``class,start,end`` line per gesture, 1-based inclusive frames. An empty
        file means no gesture.
    n_frames : int or None, default=None
        If given, an end frame beyond it raises.

    Returns
    -------
    ndarray of shape (n_gestures, 3)
        Rows ``(class, start, end)``, 0-based, ``end`` exclusive, in file order.

    Raises
    ------
    ValueError
        Naming the file and line of a malformed line, a class outside 1..20 or a
        start after the end.

    See Also
    --------
    write_chalearn_predictions : Write such files.
    load_chalearn : Read whole samples.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import read_chalearn_labels
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "Sample0001_labels.csv"
    >>> _ = path.write_text("3,2,6\\n5,7,10\\n")
    >>> read_chalearn_labels(path).tolist()
    [[3, 1, 6], [5, 6, 10]]
    >>> tmp.cleanup()
    """
    path = _check_path(file, "labels file")
    return _parse_labels(_lines(_read_text(path)), path.name, n_frames)


def _parse_skeleton(lines, name, n_frames, data_where=None):
    """``(T, 180)`` skeleton values, padded/truncated to ``n_frames`` (warns).

    ``data_where`` is ``(file name, line)`` of numFrames, named in the error
    when the skeleton and numFrames disagree beyond the tolerance.
    """
    _require_lines(lines, name, f"one line of {N_SKELETON_COLUMNS} values per frame")
    skel = _parse_table(lines, N_SKELETON_COLUMNS, name, sep=",")
    _check_magnitude(skel, name, columns=_WORLD_COLUMNS, what="world coordinate")
    if n_frames is not None and len(skel) != n_frames:
        tolerance = max(
            FRAME_MISMATCH_FRAMES, int(np.ceil(FRAME_MISMATCH_FRACTION * len(skel)))
        )
        if abs(n_frames - len(skel)) > tolerance:
            data_name, data_line = data_where or ("the data file", None)
            raise _format_error(
                data_name,
                data_line,
                f"numFrames {n_frames} disagrees with the {len(skel)} lines of "
                f"{name} by more than {tolerance} frames (the tolerance: "
                f"{FRAME_MISMATCH_FRAMES} frames or "
                f"{FRAME_MISMATCH_FRACTION:.0%} of the skeleton); one of the two "
                f"files is corrupt",
            )
        if len(skel) > n_frames:
            _warn(
                f"{name} has {len(skel)} frames but the data file says {n_frames}; "
                f"the last {len(skel) - n_frames} frame(s) are dropped"
            )
            skel = skel[:n_frames]
        else:
            _warn(
                f"{name} has {len(skel)} frames but the data file says {n_frames}; "
                f"padded with {n_frames - len(skel)} missing (all-zero) frame(s)"
            )
            pad = np.zeros((n_frames - len(skel), N_SKELETON_COLUMNS))
            skel = np.concatenate([skel, pad])
    return skel


def _load_sample(sid, src, *, labels_only):
    """Read one sample; returns a dict with skel, segments, y, n_frames, fps..."""
    out = {"has_labels": "labels" in src}
    data_where = None
    if "data" in src:
        data_lines = _source_lines(src["data"])
        data_where = (_source_name(src["data"]), len(data_lines))
        n_frames, fps, max_depth = _parse_data(data_lines, data_where[0])
        if labels_only and n_frames > MAX_LABELS_ONLY_FRAMES:
            raise _format_error(
                *data_where,
                f"numFrames {n_frames} is more than a day at 20 fps "
                f"({MAX_LABELS_ONLY_FRAMES}); the file is corrupt",
            )
    elif labels_only:
        raise FileNotFoundError(
            f"{sid}: no {sid}_data.csv, which is needed to know the number of "
            f"frames when only labels are read"
        )
    else:
        n_frames, fps, max_depth = None, CHALEARN_FPS, np.nan
    skel = None
    if not labels_only:
        skel = _parse_skeleton(
            _source_lines(src["skeleton"]),
            _source_name(src["skeleton"]),
            n_frames,
            data_where,
        )
        if n_frames is None:
            n_frames = len(skel)
            _warn(
                f"{sid}: no {sid}_data.csv; numFrames is taken from the skeleton "
                f"({n_frames}) and fps is assumed to be {CHALEARN_FPS:g}"
            )
    if "labels" in src:
        name = _source_name(src["labels"])
        raw = _parse_labels(_source_lines(src["labels"]), name, n_frames)
        last = int(raw[:, 2].max()) if len(raw) else 0
        if labels_only and last and n_frames > 2 * last + TRAILING_REST_FRAMES:
            _warn(
                f"{data_where[0]}: numFrames {n_frames} is far beyond the last "
                f"labelled frame {last} of {name}; it is used as given (check the "
                f"data file)"
            )
        seg, y, overlaps = _sort_and_label(raw, n_frames)
        if overlaps:
            pairs = "; ".join(
                f"line {a + 1} ({raw[a, 0]},{raw[a, 1] + 1},{raw[a, 2]}) and line "
                f"{b + 1} ({raw[b, 0]},{raw[b, 1] + 1},{raw[b, 2]})"
                for a, b in overlaps
            )
            _warn(
                f"{name}: overlapping gestures: {pairs}; both are kept in "
                f"`segments`, and in `y` the later-starting one wins"
            )
    else:
        seg, y = _empty_segments(), np.zeros(n_frames, dtype=np.int64)
    out.update(
        skel=skel, segments=seg, y=y, n_frames=n_frames, fps=fps, max_depth=max_depth
    )
    return out


def _select_samples(sources, samples, path):
    """Sorted sample ids to read, restricted to ``samples`` if given."""
    ids = sorted(sources, key=_sample_number)
    if samples is None:
        return ids
    if isinstance(samples, (str, int, np.integer)):
        samples = [samples]
    by_number = {_sample_number(s): s for s in ids}
    wanted, absent = [], []
    for s in samples:
        number = _sample_number(s)
        (wanted if number in by_number else absent).append(number)
    if absent:
        raise FileNotFoundError(
            f"sample(s) {', '.join(map(str, absent))} not found in {str(path)!r}"
        )
    return [by_number[n] for n in dict.fromkeys(wanted)]


def load_chalearn(
    path, *, return_joint_data=False, labels_only=False, samples=None, verbose=0
):
    """Load ChaLearn LAP 2014 Track 3 (Montalbano) samples.

    Reads ``SampleXXXX.zip`` archives (only their skeleton, labels and data CSV
    members; videos are never extracted) and/or extracted
    ``SampleXXXX_{skeleton,labels,data}.csv`` files (4- or 5-digit ids, so the
    ChaLearn 2013 samples converted to CSV work too).

    Parameters
    ----------
    path : str or path-like
        A folder holding zips, extracted CSVs or ``SampleXXXX/`` subfolders; or
        a single ``SampleXXXX.zip``; or one ``SampleXXXX_*.csv`` file (its sibling
        files of the same sample are read with it).
    return_joint_data : bool, default=False
        Also return every skeleton value (``joint_data``: world position,
        rotation quaternion and pixel position of each joint).
    labels_only : bool, default=False
        Read only labels and data files (``X`` is None). Chosen automatically
        when no sample of the folder has a skeleton file (for example the
        validation ground-truth folders).
    samples : list of (str or int) or None, default=None
        Only these samples, e.g. ``["Sample0101", 470]``.
    verbose : int, default=0
        0 is silent; 1 shows a tqdm progress bar over the samples.

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys

        X : list of ndarray of shape (n_frames_i, 20, 3) or None
            World joint positions in metres, Kinect v1 NUI joint order (float64).
            Untracked frames are all zeros, as in the files.
        y : list of ndarray of shape (n_frames_i,)
            Per-frame labels (int64): 0 = no gesture, 1..20 = gesture class.
        segments : list of ndarray of shape (n_gestures_i, 3)
            The labelled rows ``(class, start, end)``, 0-based, ``end`` exclusive,
            sorted by start (the file order for the released labels).
        sample_ids : list of str
            ``"Sample0101"``, ...
        groups : ndarray of shape (n_sequences,)
            The sample ids (the subject of a Montalbano sample is not released).
        fps : float or ndarray of shape (n_sequences,)
            Frame rate from the data files; a float when all agree (20.0).
        n_frames : ndarray of shape (n_sequences,)
            numFrames of each sample.
        missing : list of ndarray of shape (n_frames_i,) or None
            True where the frame has no skeleton.
        has_labels : ndarray of shape (n_sequences,)
            False for a sample without labels file (its ``y`` is all zeros).
        max_depth : ndarray of shape (n_sequences,)
            maxDepth of the data file (NaN where there is none).
        joint_data : list of ndarray of shape (n_frames_i, 20, 9)
            Only with ``return_joint_data=True``: the 9 values of every joint.
        target_names : list of str
            ``target_names[k - 1]`` is the name of class ``k``.
        layout : str
            ``"kinect_v1"``.
        DESCR : str
            Description of the data.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist, holds no sample, or a requested sample is
        absent.
    DataFormatError
        For a corrupt, truncated or wrongly shaped file, naming the file and the
        1-based line: a value that is not a finite number, a world position
        beyond 10 km, a bad zip, or a numFrames that disagrees with the number
        of skeleton lines by more than 20 frames or 5 % (see Notes).
        It is a :class:`ValueError`.
    ValueError
        For a folder mixing samples with and without skeleton (pass
        ``labels_only=True`` or ``samples``).

    Warns
    -----
    DataFileWarning
        When a skeleton has a few more or fewer lines than numFrames (truncated
        or padded with missing frames, docs/method.md §1.4), when labels overlap
        (kept in ``segments``; in ``y`` the later gesture wins), or, labels
        only, when numFrames lies far beyond the last labelled frame.

    See Also
    --------
    write_chalearn_predictions : Write predictions in the official format.
    read_chalearn_labels : Read one labels or prediction file.

    Notes
    -----
    ``_data.csv`` is read from its last line, as the official scorer does. A
    sample without data file takes numFrames from its skeleton and fps 20, with
    a warning.

    numFrames is bounded by the data present, so that a corrupt data file
    cannot make the loader allocate gigabytes: with a skeleton, it may differ
    from the number of skeleton lines by at most 20 frames or 5 % of them
    (whichever is larger; the skeleton is then padded with missing frames or
    truncated, with a warning), and a larger difference raises
    :class:`DataFormatError` naming the data file. Every real sample has
    exactly numFrames lines. With labels only, numFrames above a day at 20 fps
    (1,728,000) raises, and one above twice the last labelled frame plus 600
    frames is used with a warning.

    References
    ----------
    .. [1] S. Escalera et al., "ChaLearn Looking at People Challenge 2014:
       Dataset and Results", ECCV Workshops, 2014.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from skgesture.datasets import load_chalearn
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> _ = (folder / "Sample0001_data.csv").write_text("8,20,4095\\n")
    >>> _ = (folder / "Sample0001_labels.csv").write_text("3,2,4\\n")
    >>> frame = ",".join(["0.5"] * 180) + "\\n"
    >>> _ = (folder / "Sample0001_skeleton.csv").write_text(frame * 8)
    >>> data = load_chalearn(folder)
    >>> data.X[0].shape, data.y[0].tolist()
    ((8, 20, 3), [0, 3, 3, 3, 0, 0, 0, 0])
    >>> data.segments[0].tolist(), data.target_names[3 - 1], data.fps
    ([[3, 1, 4]], 'perfetto', 20.0)
    >>> tmp.cleanup()
    """
    root = _check_path(path)
    sources = _discover(root)
    ids = _select_samples(sources, samples, root)
    no_skel = [s for s in ids if "skeleton" not in sources[s]]
    if not labels_only and no_skel:
        if len(no_skel) == len(ids):
            labels_only = True
        else:
            raise ValueError(
                f"{len(no_skel)} of {len(ids)} samples in {str(root)!r} have no "
                f"skeleton file ({', '.join(no_skel[:5])}"
                f"{', ...' if len(no_skel) > 5 else ''}); pass labels_only=True, or "
                f"select samples with `samples=`"
            )
    if labels_only:
        unlabelled = [s for s in ids if "labels" not in sources[s]]
        if unlabelled:
            raise FileNotFoundError(
                f"labels_only: no labels file for {', '.join(unlabelled[:5])}"
                f"{', ...' if len(unlabelled) > 5 else ''}"
            )
    loaded = [
        _load_sample(s, sources[s], labels_only=labels_only)
        for s in _progress(ids, verbose=verbose, desc="ChaLearn samples")
    ]
    X = joint_data = None
    if not labels_only:
        blocks = [
            d["skel"].reshape(len(d["skel"]), N_KINECT_JOINTS, VALUES_PER_JOINT)
            for d in loaded
        ]
        X = [np.ascontiguousarray(b[:, :, :N_COORDS]) for b in blocks]
        joint_data = blocks if return_joint_data else None
    fps = np.array([d["fps"] for d in loaded])
    n_frames = np.array([d["n_frames"] for d in loaded], dtype=np.int64)
    extra = {} if joint_data is None else {"joint_data": joint_data}
    segments = [d["segments"] for d in loaded]
    return _make_bunch(
        X=X,
        y=[d["y"] for d in loaded],
        segments=segments,
        sample_ids=ids,
        groups=np.array(ids),
        fps=float(fps[0]) if np.all(fps == fps[0]) else fps,
        n_frames=n_frames,
        target_names=CHALEARN_GESTURE_NAMES,
        descr=_descr(
            "ChaLearn LAP 2014 Track 3 (Montalbano)"
            + (" - labels only" if labels_only else ""),
            _DESCR_BODY,
            len(ids),
            n_frames.sum(),
            sum(len(s) for s in segments),
        ),
        has_labels=np.array([d["has_labels"] for d in loaded]),
        max_depth=np.array([d["max_depth"] for d in loaded], dtype=np.float64),
        **extra,
    )


# ----------------------------------------------------------------------------
# Writing predictions
# ----------------------------------------------------------------------------


def _as_prediction_segments(pred, sid, n_frames):
    """Clamped 1-based inclusive ``(class, start, end)`` rows for one sequence."""
    arr = np.asarray(pred)
    if arr.ndim == 1:
        if arr.size and not np.issubdtype(arr.dtype, np.integer):
            if (
                arr.dtype == bool
                or not np.issubdtype(arr.dtype, np.number)
                or not (np.all(np.isfinite(arr)) and np.all(arr == np.round(arr)))
            ):
                raise ValueError(
                    f"{sid}: per-frame predictions must be integer labels (0 = rest), "
                    f"got dtype {arr.dtype}"
                )
        labels = arr.astype(np.int64)
        bad = np.flatnonzero((labels < 0) | (labels > N_CHALEARN_CLASSES))
        if bad.size:
            f = int(bad[0])
            raise ValueError(
                f"{sid}: predicted label {labels[f]} at frame {f} (0-based) is outside "
                f"0..{N_CHALEARN_CLASSES} (0 = rest); it cannot be written"
            )
        if n_frames is not None and len(labels) > n_frames:
            if labels[n_frames:].any():
                _warn(
                    f"{sid}: predictions beyond numFrames={n_frames} are dropped "
                    f"({len(labels)} frames given)"
                )
            labels = labels[:n_frames]
        seg = labels_to_segments(labels)
    elif arr.ndim == 2 and arr.shape[1] == N_LABEL_COLUMNS:
        if arr.size and not np.issubdtype(arr.dtype, np.integer):
            raise ValueError(f"{sid}: segments must be integers, got {arr.dtype}")
        seg = arr.astype(np.int64).reshape(-1, N_LABEL_COLUMNS)
        for row, (c, s, e) in enumerate(seg.tolist()):
            if not 1 <= c <= N_CHALEARN_CLASSES:
                raise ValueError(
                    f"{sid}: segment row {row} = ({c}, {s}, {e}) has class {c}, "
                    f"outside 1..{N_CHALEARN_CLASSES}; it cannot be written"
                )
            if e <= s:
                raise ValueError(
                    f"{sid}: segment row {row} = ({c}, {s}, {e}) is empty or "
                    f"reversed (start is 0-based, end exclusive: end > start needed)"
                )
    else:
        raise ValueError(
            f"{sid}: expected per-frame labels of shape (n_frames,) or segments of "
            f"shape (n, 3), got shape {arr.shape}"
        )
    start = np.maximum(to_file_lines(seg)[:, 1], 1)  # docs/method.md §2.2 clamping
    end = seg[:, 2] if n_frames is None else np.minimum(seg[:, 2], n_frames)
    outside = start > end
    if outside.any():
        _warn(
            f"{sid}: {int(outside.sum())} segment(s) lie entirely outside frames "
            f"1..{n_frames} and are not written"
        )
    keep = ~outside
    out = np.stack([seg[keep, 0], start[keep], end[keep]], axis=1)
    return out[np.argsort(out[:, 1], kind="stable")]


def write_chalearn_predictions(
    predictions, sample_ids, folder, *, n_frames=None, overwrite=False
):
    """Write one official ``SampleXXXX_prediction.csv`` file per sequence.

    Each file has one ``class,start,end`` line per predicted gesture (1-based,
    inclusive frames, sorted by start); a sequence without any prediction gets
    an empty file, as the official scorer expects (docs/method.md §1.7).

    Parameters
    ----------
    predictions : list of ndarray
        Per sequence, either per-frame labels of shape (n_frames_i,) (0 = rest,
        1..20 = class; every maximal run of one class becomes a line) or
        segments of shape (n_i, 3), rows ``(class, start, end)`` 0-based with an
        exclusive end (written as given, after clamping).
    sample_ids : list of (str or int)
        ``"Sample0701"`` or ``701`` for each sequence.
    folder : str or path-like
        Output folder, created if needed.
    n_frames : int, list of int or None, default=None
        Number of frames (numFrames) of each sequence (e.g. ``data.n_frames``). Frames
        are clamped to ``1 <= start <= end <= numFrames`` (docs/method.md
        §2.2); without it
        only ``start >= 1`` is enforced (and labels past it are dropped).
    overwrite : bool, default=False
        Replace prediction files that already exist in ``folder``. By default
        an existing one raises :class:`FileExistsError` and nothing is written.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    ValueError
        If a class is outside 1..20 (per-frame labels outside 0..20), naming the
        sample and the row or frame: nothing is silently written for it.
    FileExistsError
        If ``overwrite=False`` and a ``SampleXXXX_prediction.csv`` to write
        already exists (it names the file; nothing is written).
    NotADirectoryError
        If ``folder`` (or a folder above it) is an existing file.

    Warns
    -----
    DataFileWarning
        When a segment lies entirely beyond numFrames (it is not written).

    See Also
    --------
    read_chalearn_labels : Read such a file back.
    load_chalearn : Read ground truth.

    Examples
    --------
    >>> import tempfile
    >>> import numpy as np
    >>> from skgesture.datasets import write_chalearn_predictions
    >>> tmp = tempfile.TemporaryDirectory()
    >>> y_pred = [np.array([0, 3, 3, 3, 0, 5, 5]), np.zeros(4, dtype=int)]
    >>> paths = write_chalearn_predictions(y_pred, ["Sample0701", 702], tmp.name)
    >>> [p.name for p in paths]
    ['Sample0701_prediction.csv', 'Sample0702_prediction.csv']
    >>> print(paths[0].read_text(), end="")
    3,2,4
    5,6,7
    >>> paths[1].read_text()
    ''
    >>> tmp.cleanup()
    """
    if isinstance(sample_ids, (str, int)):
        raise TypeError("sample_ids must be a list (one id per sequence)")
    sample_ids = list(sample_ids)
    if len(predictions) != len(sample_ids):
        raise ValueError(
            f"{len(predictions)} predictions but {len(sample_ids)} sample ids"
        )
    if n_frames is None or np.ndim(n_frames) == 0:
        n_frames = [n_frames] * len(sample_ids)
    elif len(n_frames) != len(sample_ids):
        raise ValueError(
            f"n_frames has {len(n_frames)} entries but there are {len(sample_ids)} "
            f"sequences"
        )
    names = [_format_sample_id(s) for s in sample_ids]
    if len(set(names)) != len(names):
        raise ValueError(f"duplicate sample ids in {names}")
    rows = []
    for pred, sid, n in zip(predictions, names, n_frames):
        if n is not None and (int(n) != n or n < 1):
            raise ValueError(f"{sid}: n_frames must be a positive integer, got {n}")
        rows.append(_as_prediction_segments(pred, sid, None if n is None else int(n)))
    out_dir = Path(folder).expanduser()
    for parent in (out_dir, *out_dir.parents):
        if parent.exists() and not parent.is_dir():
            raise NotADirectoryError(
                f"output folder {str(out_dir)!r}: {str(parent)!r} is an existing "
                f"file, not a folder; give a folder for the prediction files"
            )
    paths = [out_dir / f"{sid}_prediction.csv" for sid in names]
    folders = [p for p in paths if p.is_dir()]
    if folders:
        raise IsADirectoryError(f"{str(folders[0])!r} is a folder, expected a file")
    if not overwrite:
        existing = [p for p in paths if p.exists()]
        if existing:
            raise FileExistsError(
                f"{str(existing[0])!r} already exists"
                + (f" (and {len(existing) - 1} more)" if len(existing) > 1 else "")
                + "; pass overwrite=True to replace prediction files, or write to "
                "an empty folder"
            )
    out_dir.mkdir(parents=True, exist_ok=True)
    for path, seg in zip(paths, rows):
        path.write_text("".join(f"{c},{s},{e}\n" for c, s, e in seg.tolist()))
    return paths
