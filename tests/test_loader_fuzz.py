"""Fuzz test of every loader on mutated copies of the real data files.

Each case copies real files of ``shared/data`` (shortened to a few hundred
frames so that the whole test runs in seconds), applies one seeded mutation to
one file (truncation, garbage bytes, huge numbers, NaN, infinity, wrong column
counts, empty file, swapped delimiters, ...) and loads it. The only acceptable
outcomes are:

* a :class:`~skgesture.datasets.DataFormatError` that names a file, or
* a result that keeps every promise of the loaders (finite positions within
  range, lengths of ``X``, ``y`` and ``n_frames`` that agree, labels and
  segments within the classes and the sequence, no wrapped integers, no
  allocation beyond the data present), with no warning other than
  :class:`~skgesture.datasets.DataFileWarning`.

Anything else (a bare numpy/Overflow/Index/UnicodeDecode error, a silent
garbage array, a RuntimeWarning) fails the test and is listed.
"""

import re
import shutil
import warnings
import zipfile
from collections import Counter

import numpy as np
import pytest

from skgesture.datasets import (
    CHALEARN_GESTURE_NAMES,
    PRECOG_ACTION_NAMES,
    DataFileWarning,
    DataFormatError,
    load_chalearn,
    load_msr_action3d,
    load_msrc12,
    load_precog,
    load_recordings,
    load_utkinect,
    read_chalearn_labels,
    write_intervals,
)

SEED = 20240611
N_FRAMES = 120  # frames kept of each long real file
STACKED_PER_FILE = 3  # extra cases per file: three random mutations at once
MAX_COORD = 1e4  # metres; the loaders' documented bound
MAX_EXACT = 2**53
MAX_LABELS_ONLY_FRAMES = 24 * 3600 * 20  # documented bound of load_chalearn
_NUMBER = re.compile(rb"[-+]?[0-9]+(?:\.[0-9]+)?(?:[eE][-+]?[0-9]+)?")

# ----------------------------------------------------------------------------
# Mutations: bytes -> bytes, each drawing its positions from ``rng``
# ----------------------------------------------------------------------------


def _lines(data):
    return data.split(b"\n")


def _pick_line(data, rng):
    lines = _lines(data)
    return lines, int(rng.integers(len(lines)))


def _replace_token(new):
    def mutate(data, rng):
        tokens = list(_NUMBER.finditer(data))
        if not tokens:
            return data + new
        m = tokens[int(rng.integers(len(tokens)))]
        return data[: m.start()] + new + data[m.end() :]

    return mutate


def _truncate(data, rng):
    return data[: int(rng.integers(len(data))) if data else 0]


def _garbage(data, rng):
    at = int(rng.integers(len(data) + 1))
    junk = rng.integers(0, 256, size=int(rng.integers(4, 32)), dtype=np.uint8)
    return data[:at] + junk.tobytes() + data[at:]


def _insert(new):
    def mutate(data, rng):
        at = int(rng.integers(len(data) + 1))
        return data[:at] + new + data[at:]

    return mutate


def _drop_value(data, rng):
    tokens = list(_NUMBER.finditer(data))
    if not tokens:
        return data
    m = tokens[int(rng.integers(len(tokens)))]
    end = m.end() + (1 if data[m.end() : m.end() + 1] in (b",", b" ", b";") else 0)
    return data[: m.start()] + data[end:]


def _extra_value(data, rng):
    lines, i = _pick_line(data, rng)
    sep = b";" if b";" in lines[i] else b"," if b"," in lines[i] else b" "
    lines[i] = lines[i] + sep + b"0.5"
    return b"\n".join(lines)


def _swap_delimiter_line(data, rng):
    lines, i = _pick_line(data, rng)
    lines[i] = lines[i].replace(b",", b"\t").replace(b";", b",")
    return b"\n".join(lines)


def _swap_delimiter_file(data, rng):
    if b"," in data:
        return data.replace(b",", b";")
    return data.replace(b" ", b",")


def _blank_line(data, rng):
    lines, i = _pick_line(data, rng)
    lines.insert(i, b"")
    return b"\n".join(lines)


def _drop_line(data, rng):
    lines, i = _pick_line(data, rng)
    del lines[i]
    return b"\n".join(lines)


def _dup_line(data, rng):
    lines, i = _pick_line(data, rng)
    lines.insert(i, lines[i])
    return b"\n".join(lines)


def _digit_flip(data, rng):
    digits = [i for i, b in enumerate(data) if 48 <= b <= 57]
    if not digits:
        return data
    i = digits[int(rng.integers(len(digits)))]
    return data[:i] + bytes([48 + int(rng.integers(10))]) + data[i + 1 :]


MUTATIONS = {
    "truncate": _truncate,
    "empty": lambda data, rng: b"",
    "garbage_bytes": _garbage,
    "invalid_utf8": _insert("caf\xe9".encode("latin-1")),
    "nul_bytes": _insert(b"\x00\x00"),
    "huge_float": _replace_token(b"1e308"),
    "float_overflow": _replace_token(b"1e999"),
    "huge_int": _replace_token(b"9" * 25),
    "huge_negative_int": _replace_token(b"-" + b"9" * 25),
    "int64_edge": _replace_token(b"9223372036854775808"),
    "nan": _replace_token(b"nan"),
    "inf": _replace_token(b"inf"),
    "minus_inf": _replace_token(b"-inf"),
    "text": _replace_token(b"abc"),
    "negative": _replace_token(b"-1"),
    "zero": _replace_token(b"0"),
    "fraction": _replace_token(b"2.5"),
    "big_finite": _replace_token(b"123456789"),
    "drop_value": _drop_value,
    "extra_value": _extra_value,
    "swap_delimiter_line": _swap_delimiter_line,
    "swap_delimiter_file": _swap_delimiter_file,
    "blank_line": _blank_line,
    "drop_line": _drop_line,
    "duplicate_line": _dup_line,
    "digit_flip": _digit_flip,
    "crlf": lambda data, rng: data.replace(b"\n", b"\r\n"),
    "bom": lambda data, rng: b"\xef\xbb\xbf" + data,
}


def _stacked(data, rng):
    for name in rng.choice(sorted(MUTATIONS), size=3, replace=False):
        data = MUTATIONS[name](data, rng)
    return data


# ----------------------------------------------------------------------------
# Targets: real files copied (and shortened) into a folder, and how to load them
# ----------------------------------------------------------------------------


def _head(src, dst, n_lines):
    lines = src.read_bytes().split(b"\n")
    dst.write_bytes(b"\n".join(lines[:n_lines]) + b"\n")


def _chalearn_folder(shared, folder):
    src = shared / "chalearn_montalbano" / "v2_2014_samples"
    _head(src / "Sample0101_skeleton.csv", folder / "Sample0101_skeleton.csv", N_FRAMES)
    labels = [
        ln
        for ln in (src / "Sample0101_labels.csv").read_text().splitlines()
        if int(ln.split(",")[2]) <= N_FRAMES
    ]
    assert labels, "the shortened sample should keep some gestures"
    (folder / "Sample0101_labels.csv").write_text("\n".join(labels) + "\n")
    (folder / "Sample0101_data.csv").write_text(f"{N_FRAMES},20,4095\n")
    return ["Sample0101_skeleton.csv", "Sample0101_labels.csv", "Sample0101_data.csv"]


def _setup_chalearn(shared, folder):
    return _chalearn_folder(shared, folder), lambda: load_chalearn(folder)


def _setup_chalearn_zip(shared, folder):
    work = folder / "src"
    work.mkdir()
    names = _chalearn_folder(shared, work)
    # Stored (not deflated), so that the text mutations reach the CSV inside.
    with zipfile.ZipFile(folder / "Sample0101.zip", "w", zipfile.ZIP_STORED) as zf:
        for name in names:
            zf.write(work / name, name)
    shutil.rmtree(work)
    return ["Sample0101.zip"], lambda: load_chalearn(folder)


def _setup_chalearn_labels_only(shared, folder):
    src = shared / "chalearn_montalbano" / "v2_2014_validation_labels"
    names = ["Sample0471_labels.csv", "Sample0471_data.csv"]
    for name in names:
        shutil.copy(src / name, folder / name)
    return names, lambda: load_chalearn(folder)


def _setup_read_labels(shared, folder):
    src = shared / "chalearn_montalbano" / "v2_2014_validation_labels"
    shutil.copy(src / "Sample0471_labels.csv", folder / "Sample0471_labels.csv")
    return ["Sample0471_labels.csv"], lambda: read_chalearn_labels(
        folder / "Sample0471_labels.csv", n_frames=1400
    )


def _setup_precog(shared, folder):
    shutil.copy(shared / "precog_2016" / "CSV" / "Seq1_1.csv", folder / "Seq1_1.csv")
    return ["Seq1_1.csv"], lambda: load_precog(folder)


def _setup_utkinect(shared, folder):
    src = shared / "utkinect_action3d" / "joints"
    _head(src / "joints_s01_e01.txt", folder / "joints_s01_e01.txt", N_FRAMES)
    shutil.copy(src / "actionLabel.txt", folder / "actionLabel.txt")
    return ["joints_s01_e01.txt", "actionLabel.txt"], lambda: load_utkinect(folder)


def _setup_msrc12(shared, folder):
    src = shared / "msrc12_subset" / "data"
    _head(src / "P3_1_1_p01.csv", folder / "P3_1_1_p01.csv", N_FRAMES)
    shutil.copy(src / "P3_1_1_p01.tagstream", folder / "P3_1_1_p01.tagstream")
    return ["P3_1_1_p01.csv", "P3_1_1_p01.tagstream"], lambda: load_msrc12(folder)


def _setup_msr_action3d(shared, folder):
    src = shared / "msr_action3d" / "real_world_coordinates"
    clip = "a01_s01_e01_skeleton3D.txt"
    shutil.copy(src / clip, folder / clip)
    (folder / "files_used_in_cvpr12_paper.txt").write_text("a01_s01_e01\n")
    return [clip, "files_used_in_cvpr12_paper.txt"], lambda: load_msr_action3d(folder)


def _setup_recordings(shared, folder):
    """A PRECOG sequence written as a recording with header and frame numbers."""
    data = load_precog(shared / "precog_2016" / "CSV" / "Seq1_1.csv")
    x = data.X[0].reshape(len(data.X[0]), -1)
    from skgesture.layouts import KINECT_V1

    header = "frame," + ",".join(
        f"{j}_{a}" for j in KINECT_V1.joint_names for a in "xyz"
    )
    np.savetxt(
        folder / "take1.csv",
        np.column_stack([np.arange(len(x)), x]),
        delimiter=",",
        header=header,
        comments="",
        fmt="%.9g",
    )
    write_intervals(folder / "take1.labels.csv", data.y[0], classes=data.target_names)
    (folder / "classes.txt").write_text("\n".join(PRECOG_ACTION_NAMES) + "\n")
    files = ["take1.csv", "take1.labels.csv", "classes.txt"]
    return files, lambda: load_recordings(folder)


TARGETS = {
    "chalearn": (_setup_chalearn, len(CHALEARN_GESTURE_NAMES)),
    "chalearn_zip": (_setup_chalearn_zip, len(CHALEARN_GESTURE_NAMES)),
    "chalearn_labels_only": (_setup_chalearn_labels_only, len(CHALEARN_GESTURE_NAMES)),
    "read_chalearn_labels": (_setup_read_labels, len(CHALEARN_GESTURE_NAMES)),
    "precog": (_setup_precog, len(PRECOG_ACTION_NAMES)),
    "utkinect": (_setup_utkinect, 10),
    "msrc12": (_setup_msrc12, 12),
    "msr_action3d": (_setup_msr_action3d, 20),
    "recordings": (_setup_recordings, len(PRECOG_ACTION_NAMES)),
}

# ----------------------------------------------------------------------------
# What a loaded result must satisfy
# ----------------------------------------------------------------------------


def _check_segments(seg, n_frames, n_classes):
    assert seg.dtype == np.int64 and seg.ndim == 2 and seg.shape[1] == 3
    assert np.all((seg[:, 0] >= 1) & (seg[:, 0] <= n_classes)), "class out of range"
    assert np.all(seg[:, 1] >= 0) and np.all(seg[:, 1] < seg[:, 2]), "bad interval"
    if n_frames is not None:
        assert np.all(seg[:, 2] <= n_frames), "segment beyond the sequence"


def _check_result(out, n_classes, max_frames):
    """Raise AssertionError when ``out`` breaks a promise of the loaders."""
    if isinstance(out, np.ndarray):  # read_chalearn_labels
        _check_segments(out, None, n_classes)
        return
    n = len(out.sample_ids)
    n_frames = np.asarray(out.n_frames)
    assert n_frames.shape == (n,) and len(out.groups) == n
    assert n_frames.sum() <= max_frames, f"{n_frames.sum()} frames allocated"
    n_classes = min(n_classes, len(out.target_names))
    if out.X is not None:
        assert len(out.X) == n
        for x, t, miss in zip(out.X, n_frames, out.missing):
            assert x.dtype == np.float64 and x.shape == (t, 20, 3), x.shape
            assert np.all(np.isfinite(x)), "non-finite position"
            assert np.all(np.abs(x) <= MAX_COORD), "position out of range"
            assert miss.shape == (t,)
    if out.y is not None:
        assert len(out.y) == len(out.segments) == n
        for lab, seg, t in zip(out.y, out.segments, n_frames):
            assert lab.dtype == np.int64 and lab.shape == (t,), "y length"
            assert lab.min(initial=0) >= 0 and lab.max(initial=0) <= n_classes
            _check_segments(seg, t, n_classes)
    for key in ("timestamps", "frame_numbers"):
        for arr in out.get(key) or []:
            if arr is not None:
                assert arr.dtype == np.int64
                assert np.all(np.abs(arr) <= MAX_EXACT), f"{key} wrapped"
    for points, t in zip(out.get("action_points") or [], n_frames):
        assert np.all((points >= 0) & (points < max(t, 1)))


def _run_case(load, n_classes, max_frames):
    """``(outcome, detail)``: "ok", "error" or "FAIL"."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            out = load()
        except DataFormatError as exc:
            if not exc.file or exc.file not in str(exc):
                return "FAIL", f"DataFormatError without file name: {exc}"
            outcome, detail = "error", str(exc)
        except Exception as exc:  # noqa: BLE001 - what the fuzz test hunts
            return "FAIL", f"{type(exc).__name__}: {str(exc)[:200]}"
        else:
            try:
                _check_result(out, n_classes, max_frames)
            except AssertionError as exc:
                return "FAIL", f"garbage result: {exc}"
            outcome, detail = "ok", ""
    others = [w for w in caught if not issubclass(w.category, DataFileWarning)]
    if others:
        w = others[0]
        return "FAIL", f"{w.category.__name__}: {str(w.message)[:200]}"
    return outcome, detail


def _cases(files, rng):
    for file in files:
        for name, mutate in MUTATIONS.items():
            yield file, name, mutate
        for k in range(STACKED_PER_FILE):
            yield file, f"stacked{k}", _stacked


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_loader_fuzz_raises_only_documented_errors(shared_data, tmp_path, target):
    setup, n_classes = TARGETS[target]
    files, load = setup(shared_data, tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataFileWarning)
        clean = load()  # the unmutated copy loads
    _check_result(clean, n_classes, np.inf)
    max_frames = (
        MAX_LABELS_ONLY_FRAMES
        if target == "chalearn_labels_only"
        else 2 * int(np.sum(getattr(clean, "n_frames", 0))) + 1000
    )
    rng = np.random.default_rng([SEED, sorted(TARGETS).index(target)])
    originals = {f: (tmp_path / f).read_bytes() for f in files}
    outcomes, failures = Counter(), []
    for file, name, mutate in _cases(files, rng):
        path = tmp_path / file
        path.write_bytes(mutate(originals[file], rng))
        try:
            outcome, detail = _run_case(load, n_classes, max_frames)
        finally:
            path.write_bytes(originals[file])
        outcomes[outcome] += 1
        if outcome == "FAIL":
            failures.append(f"{file} / {name}: {detail}")
    assert not failures, "\n".join(failures)
    assert outcomes["error"] > 0  # the mutations do reach the checks
    # Record the counts for the summary (`pytest -rA` or the test log).
    print(f"{target}: {sum(outcomes.values())} cases, {dict(outcomes)}")
