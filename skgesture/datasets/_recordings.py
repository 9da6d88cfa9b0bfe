"""Your own recordings: skeleton CSV/TSV files and ``(start, end, label)`` intervals.

A recording is one skeleton file (one line per frame) in a named layout
(``kinect_v1``, ``kinect_v2``, ``azure``, ``mediapipe``, ``msr_action3d``) or a
given joint order; other layouts are mapped to the toolkit's Kinect v1 layout by
the adapters of :mod:`skgesture.streaming`. Its annotation, if any, is an
interval file next to it. ``docs/recordings.md`` describes the files with an
example.

This module finds the recordings of a folder and loads them with their
annotations; the file readers are :mod:`skgesture.datasets._skeleton_csv`
(skeleton files) and :mod:`skgesture.datasets._intervals` (interval and
class-names files).
"""

# SPDX-License-Identifier: BSD-3-Clause

import os
import re
from numbers import Integral, Real

import numpy as np
from sklearn.utils._param_validation import Interval, StrOptions, validate_params

from skgesture.datasets._base import (
    _check_path,
    _descr,
    _make_bunch,
    _progress,
    _sort_and_label,
    _warn,
)
from skgesture.datasets._intervals import (
    _END_OPTIONS,
    _FRAMES_DOC,
    _INT_RE,
    CLASSES_FILE,
    REST_NAME,
    _check_frame_options,
    _class_names,
    _convert_frames,
    _label_ids,
    _read_interval_rows,
)
from skgesture.datasets._skeleton_csv import (
    _LAYOUT_DOC,
    _check_reader_options,
    _Layout,
    _read_skeleton,
)

__all__ = ["load_recordings"]

SKELETON_SUFFIXES = (".csv", ".tsv")  # skeleton and interval files
LABELS_TAG = ".labels"  # ``walk.csv`` is annotated by ``walk.labels.csv``
DEFAULT_FPS = 30.0  # nominal Kinect v1 skeleton rate

_DESCR_BODY = """
Skeleton recordings read by skgesture.datasets.load_recordings: one skeleton file
per sequence, mapped to the Kinect v1 layout (metres; untracked frames, written
as all zeros or NaN, are all-zero frames), and per-frame labels from the
``(start, end, label)`` interval file next to each one. See docs/recordings.md.
"""


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
                    f"two annotation files for {_shown(key, base)}: "
                    f"{_shown(labels[key], base)} and {_shown(p, base)}"
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


def _shown(path, base):
    """``path`` as messages name it: relative to the folder given (``alice/a.csv``)."""
    return path.relative_to(base).as_posix()


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
        :func:`read_skeleton_csv` (None detects it); a header naming the
        joint columns decides the columns by name.
    frame_column : bool or None, default=None
        Whether the skeleton files have a frame-number column, as in
        :func:`read_skeleton_csv` (None decides, and raises when the layout
        of the values is ambiguous).
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
        file by its path relative to ``path`` (``alice/take1.csv``; also in
        its ``file`` attribute) and the 1-based line.
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
    folder = root if root.is_dir() else root.parent  # files are named from here
    for orphan in orphans:
        _warn(
            f"{_shown(orphan, folder)}: no skeleton file "
            f"{orphan.stem[: -len(LABELS_TAG)]}.*"
        )
    sample_ids = [f[0] for f in found]
    group_ids = _groups(sample_ids, groups)
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
            skel,
            spec,
            delimiter=delimiter,
            header=header,
            frame_column=frame_column,
            name=_shown(skel, folder),
        )
        X.append(x)
        frame_numbers.append(numbers)
        if use_labels:
            shown = _shown(lab, folder)
            rows.append(
                _convert_frames(
                    _read_interval_rows(lab, shown), shown, base, end, len(x)
                )
            )
    n_frames = np.array([len(x) for x in X], dtype=np.int64)
    y = segments = None
    if use_labels:
        shown = [_shown(lab, folder) for _, _, lab in found]
        y, segments, names = _label_recordings(rows, shown, n_frames, names)
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


def _label_recordings(rows, label_names, n_frames, names):
    """``(y, segments, target_names)`` of the annotated recordings.

    ``label_names`` names each recording's annotation file in messages.
    """
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
    for file_rows, lab, n in zip(rows, label_names, n_frames):
        classes = _label_ids(file_rows, lab, ids)
        raw = [(c, s, e) for c, (_, s, e, _) in zip(classes, file_rows) if c]
        lines = [i for c, (i, _, _, _) in zip(classes, file_rows) if c]
        seg, lab_y, overlaps = _sort_and_label(raw, int(n))
        if overlaps:
            pairs = "; ".join(
                f"line {lines[a]} and line {lines[b]}" for a, b in overlaps
            )
            _warn(
                f"{lab}: overlapping intervals: {pairs}; both are kept in "
                f"`segments`, and in `y` the later-starting one wins"
            )
        y.append(lab_y)
        segments.append(seg)
    if names is None:
        top = max((int(s[:, 0].max()) for s in segments if len(s)), default=0)
        names = [str(k) for k in range(1, top + 1)]
    return y, segments, names
