"""PRECOG 2016 reader (continuous punches and kicks, per-frame labels), and its bundle.

The 48 sequences of subjects 1-8 ship inside the package
(``skgesture/datasets/data/precog_2016.npz``, MIT licence, see ``PRECOG_README.md``
next to it), so ``load_precog()`` works without any download.

Bundle format (``_BUNDLE_FORMAT``): positions are stored as float32 (the files
hold 7 significant digits, i.e. float32 values written by the Kinect SDK), as
the frame-to-frame difference of their little-endian int32 bit patterns
(wrapping), joint-coordinate major, split into 4 byte planes. The transform is
exact and lets zlib halve the size; ``_unpack_positions`` reverses it.
"""

# SPDX-License-Identifier: BSD-3-Clause

import importlib.resources
import io
import re

import numpy as np

from skgesture.datasets._base import (
    DataFormatError,
    _check_magnitude,
    _check_path,
    _descr,
    _find_dir,
    _flag_all_zero,
    _format_error,
    _lines,
    _make_bunch,
    _parse_table,
    _progress,
    _read_text,
    _require_lines,
)
from skgesture.layouts import KINECT_V1, N_COORDS, N_KINECT_JOINTS
from skgesture.utils._segments import labels_to_segments

__all__ = ["PRECOG_ACTION_NAMES", "load_precog"]

# Label value k (1-based) is PRECOG_ACTION_NAMES[k - 1] (data PROVENANCE.md; the
# mapping was derived from the dataset slides, the repository does not state it).
PRECOG_ACTION_NAMES = (
    "right punch", "left punch", "front right kick", "front left kick",
    "side right kick", "side left kick", "back fist", "elbow strike",
)  # fmt: skip
N_PRECOG_CLASSES = len(PRECOG_ACTION_NAMES)
PRECOG_FPS = 30.0  # not stated by the dataset: the nominal Kinect v1 skeleton rate
N_FIELDS = N_KINECT_JOINTS + 1  # 20 "x y z" joint fields + the label
N_VALUES = N_KINECT_JOINTS * N_COORDS + 1  # 61 numbers per frame line
FIELD_SEP = ";"

BUNDLE_FILE = "precog_2016.npz"
_BUNDLE_FORMAT = "skgesture-precog-bundle-1"
_SOURCE = "DavidJardim/precog_dataset_16@1ff2c9de2559664b2845d992ed60024a173e2eae"
_FILE_RE = re.compile(r"^Seq(\d+)_(\d+)\.csv$")

_DESCR_BODY = """
PRECOG dataset 2016 (David Jardim, davidwfj@gmail.com; MIT licence,
github.com/DavidJardim/precog_dataset_16). Kinect v1 (SDK 1.8) skeleton streams:
each sequence is one subject performing a fixed script of 5 punches/kicks in a
row, with a label on every frame (0 = no action / transition). File SeqA_B.csv is
script A (1-6) by subject B; ``groups`` are the subjects and ``scripts`` the
scripts. Because the action order is fixed per script, split by subject. The frame
rate is not stated; ``fps`` is the nominal Kinect v1 rate of 30 Hz. The class
names were matched to the label values from the dataset slides.
"""


def _parse_precog(text, name):
    """``(X, y)`` of one PRECOG CSV file."""
    lines = _lines(text)
    _require_lines(lines, name, "a header line of 20 joint names")
    header = tuple(h.strip() for h in lines[0].split(FIELD_SEP))
    if header != KINECT_V1.joint_names:
        raise _format_error(
            name,
            1,
            f"expected the header of the 20 Kinect v1 joint names separated by "
            f"'; ' ({'; '.join(KINECT_V1.joint_names[:3])}; ...), got "
            f"{lines[0][:80]!r}",
        )
    body = lines[1:]
    if not body:
        raise DataFormatError(f"{name} has a header but no frame line", file=name)
    n_sep = np.fromiter((ln.count(FIELD_SEP) for ln in body), np.int64, len(body))
    bad = np.flatnonzero(n_sep != N_FIELDS - 1)
    if bad.size:
        i = int(bad[0])
        raise _format_error(
            name,
            i + 2,
            f"expected {N_FIELDS} ';'-separated fields (20 joints 'x y z' and a "
            f"label), got {n_sep[i] + 1}",
        )
    values = _parse_table(
        [ln.replace(FIELD_SEP, " ") for ln in body], N_VALUES, name, first_line=2
    )
    _check_magnitude(values, name, first_line=2, columns=slice(0, -1))
    label = values[:, -1]
    bad = np.flatnonzero(
        (label != np.round(label)) | (label < 0) | (label > N_PRECOG_CLASSES)
    )
    if bad.size:
        i = int(bad[0])
        raise _format_error(
            name,
            i + 2,
            f"label {label[i]:g} is not an integer in 0..{N_PRECOG_CLASSES}",
        )
    X = values[:, :-1].reshape(len(values), N_KINECT_JOINTS, N_COORDS)
    return np.ascontiguousarray(X), label.astype(np.int64)


def _list_files(path):
    """``[(script, subject, Path)]`` of a PRECOG folder (or single file)."""
    p = _check_path(path)
    if p.is_file():
        match = _FILE_RE.match(p.name)
        if match is None:
            raise ValueError(f"{p.name} is not named SeqA_B.csv (script A, subject B)")
        return [(int(match.group(1)), int(match.group(2)), p)]
    folder = _find_dir(p, child="CSV", pattern="Seq*_*.csv")
    files = []
    for entry in folder.iterdir():
        match = _FILE_RE.match(entry.name)
        if match and entry.is_file():
            files.append((int(match.group(1)), int(match.group(2)), entry))
    return files


def _pack_positions(X):
    """Byte planes of the time-differenced float32 bit patterns (module docstring)."""
    flat = np.concatenate([np.asarray(x, dtype="<f4").reshape(len(x), -1) for x in X])
    bits = flat.view("<i4")
    delta = np.diff(bits, axis=0, prepend=np.zeros((1, bits.shape[1]), "<i4"))
    col_major = np.ascontiguousarray(delta.T)
    return np.ascontiguousarray(col_major.view(np.uint8).reshape(-1, 4).T)


def _unpack_positions(planes, n_total):
    """Inverse of :func:`_pack_positions`: float32 array ``(n_total, 60)``."""
    n_cols = N_KINECT_JOINTS * N_COORDS
    delta = np.ascontiguousarray(planes.T).view("<i4").reshape(n_cols, n_total).T
    return np.cumsum(delta, axis=0, dtype="<i4").view("<f4")


def _write_bundle(data, file):
    """Write the Bunch of :func:`load_precog` to a compressed ``.npz`` bundle."""
    np.savez_compressed(
        file,
        format=np.array(_BUNDLE_FORMAT),
        source=np.array(_SOURCE),
        positions=_pack_positions(data.X),
        labels=np.concatenate(data.y).astype(np.uint8),
        n_frames=np.asarray(data.n_frames, dtype=np.int64),
        subjects=np.asarray(data.groups, dtype=np.int64),
        scripts=np.asarray(data.scripts, dtype=np.int64),
    )


def _read_bundle(file):
    """``[(script, subject, X, y)]`` from a bundle file or file object."""
    with np.load(file, allow_pickle=False) as npz:
        if str(npz["format"]) != _BUNDLE_FORMAT:
            raise DataFormatError(
                f"{BUNDLE_FILE}: unknown bundle format {npz['format']}",
                file=BUNDLE_FILE,
            )
        n_frames = npz["n_frames"]
        flat = _unpack_positions(npz["positions"], int(n_frames.sum()))
        labels = npz["labels"].astype(np.int64)
        subjects, scripts = npz["subjects"], npz["scripts"]
    bounds = np.concatenate([[0], np.cumsum(n_frames)])
    return [
        (
            int(scripts[i]),
            int(subjects[i]),
            flat[a:b].astype(np.float64).reshape(b - a, N_KINECT_JOINTS, N_COORDS),
            labels[a:b],
        )
        for i, (a, b) in enumerate(zip(bounds[:-1], bounds[1:]))
    ]


def _bundle_bytes():
    resource = importlib.resources.files(__package__) / "data" / BUNDLE_FILE
    return resource.read_bytes()


def load_precog(path=None, *, subjects=None, verbose=0):
    """Load the PRECOG 2016 continuous action dataset.

    Kinect v1 streams of one subject performing 5 punches and kicks, with a label
    on every frame. Without ``path`` the 48 sequences of subjects 1-8 bundled
    with skgesture are returned.

    Parameters
    ----------
    path : str, path-like or None, default=None
        Folder of the dataset's ``SeqA_B.csv`` files (or the folder holding its
        ``CSV`` subfolder, or one file). ``None`` reads the bundled copy.
    subjects : list of int or None, default=None
        Only the sequences of these subjects.
    verbose : int, default=0
        0 is silent; 1 shows a tqdm progress bar over the files read (only
        with ``path``: the bundle is one file).

    Returns
    -------
    :class:`~sklearn.utils.Bunch`
        Dictionary-like object with keys ``X`` (list of (n_frames_i, 20, 3) float64
        arrays, metres, Kinect v1 NUI order), ``y`` (per-frame int64 labels, 0 = no
        action, 1..8), ``segments`` (runs of non-zero labels, rows ``(class, start,
        end)`` 0-based with exclusive end), ``sample_ids`` (``"Seq1_1"``, ...),
        ``groups`` (subject of each sequence, int), ``scripts`` (script 1-6), ``fps``
        (30.0), ``n_frames``, ``missing``, ``target_names``, ``layout`` and ``DESCR``.
        Sequences are sorted by subject, then script.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist or holds no ``SeqA_B.csv`` file.
    DataFormatError
        For a malformed file, naming the file and 1-based line (wrong header or
        fields, a value that is not a finite number, a position beyond 10 km, a
        label outside 0..8).
    ValueError
        When a requested subject is absent.

    Warns
    -----
    DataFileWarning
        For a file whose skeleton is all zeros (subject 10 of the source has
        two); it is kept with ``missing`` all True.

    See Also
    --------
    load_chalearn : The Montalbano gesture streams.

    Notes
    -----
    The bundled positions are the float32 values of the CSV decimals (the files
    carry 7 significant digits): they differ from a float64 parse of the CSV by
    at most 1.2e-7 m. The frame rate is not stated by the dataset; 30 Hz is the
    nominal Kinect v1 skeleton rate. The action order is fixed per script, so
    split by subject (``GroupKFold(groups=data.groups)``).

    References
    ----------
    .. [1] D. Jardim, PRECOG dataset 2016,
       https://github.com/DavidJardim/precog_dataset_16 (MIT licence).

    Examples
    --------
    >>> from skgesture.datasets import load_precog
    >>> data = load_precog(subjects=[1])
    >>> len(data.X), data.X[0].shape, data.sample_ids[0]
    (6, (232, 20, 3), 'Seq1_1')
    >>> data.segments[0][:, 0].tolist(), data.target_names[0]
    ([1, 2, 5, 6, 3], 'right punch')
    """
    if path is None:
        records = _read_bundle(io.BytesIO(_bundle_bytes()))
        descr_title = "PRECOG 2016 (bundled: subjects 1-8)"
    else:
        records = []
        files = _list_files(path)
        for script, subject, file in _progress(
            files, verbose=verbose, desc="PRECOG files"
        ):
            X, y = _parse_precog(_read_text(file), file.name)
            records.append((script, subject, X, y))
        descr_title = "PRECOG 2016"
    if subjects is not None:
        wanted = {int(s) for s in np.atleast_1d(subjects)}
        present = {r[1] for r in records}
        absent = sorted(wanted - present)
        if absent:
            raise ValueError(
                f"subject(s) {absent} not in the data; available: {sorted(present)}"
            )
        records = [r for r in records if r[1] in wanted]
    records.sort(key=lambda r: (r[1], r[0]))
    sample_ids = [f"Seq{script}_{subject}" for script, subject, _, _ in records]
    X = [r[2] for r in records]
    y = [r[3] for r in records]
    _flag_all_zero(X, sample_ids)
    segments = [labels_to_segments(lab) for lab in y]
    n_frames = np.array([len(lab) for lab in y], dtype=np.int64)
    return _make_bunch(
        X=X,
        y=y,
        segments=segments,
        sample_ids=sample_ids,
        groups=np.array([r[1] for r in records], dtype=np.int64),
        fps=PRECOG_FPS,
        n_frames=n_frames,
        target_names=PRECOG_ACTION_NAMES,
        descr=_descr(
            descr_title,
            _DESCR_BODY,
            len(X),
            n_frames.sum(),
            sum(len(s) for s in segments),
        ),
        scripts=np.array([r[0] for r in records], dtype=np.int64),
    )
