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

The header mutations of a skeleton file (a deleted, duplicated, unknown,
misspelt, swapped or empty column, a trailing separator, a short row) must read
the right values by name or raise a DataFormatError naming the column and line.
"""

import re
import shutil
import warnings
import zipfile
from collections import Counter

import numpy as np
import pytest
from numpy.testing import assert_allclose

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
    read_skeleton_csv,
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


# ----------------------------------------------------------------------------
# Header mutations: the header's names decide the columns of a skeleton file
# ----------------------------------------------------------------------------


def _skeleton_text(names, rows, sep=","):
    lines = [sep.join(names)] if names is not None else []
    return "\n".join(lines + [sep.join(r) for r in rows]) + "\n"


def _kinect_v2_table(n_frames=8, seed=0):
    """Header names, rows of text and the Kinect v1 frames they should read as."""
    from skgesture.streaming import KINECT_V2_JOINTS, KinectV2Adapter

    v2 = np.round(np.random.default_rng(seed).uniform(-1, 3, (n_frames, 25, 3)), 4)
    names = ["frame"] + [f"{j}_{a}" for j in KINECT_V2_JOINTS for a in "xyz"]
    rows = [
        [str(100 + i)] + [f"{v:.4f}" for v in v2[i].ravel()] for i in range(n_frames)
    ]
    return names, rows, KinectV2Adapter()(v2)


def _precog_table(shared):
    """A real PRECOG sequence (Kinect v1) as header names and rows of text."""
    from skgesture.layouts import KINECT_V1

    x = load_precog(shared / "precog_2016" / "CSV" / "Seq1_1.csv").X[0][:N_FRAMES]
    names = ["frame"] + [f"{j}_{a}" for j in KINECT_V1.joint_names for a in "xyz"]
    rows = [[str(i)] + [f"{v:.9g}" for v in x[i].ravel()] for i in range(len(x))]
    return names, rows


def _columns(order):
    """Mutation keeping the columns ``order(list of indices)`` of header and rows."""

    def mutate(names, rows):
        idx = order(list(range(len(names))))
        return [names[i] for i in idx], [[r[i] for i in idx] for r in rows]

    return mutate


def _swap(a, b):
    def order(c):
        c[a], c[b] = c[b], c[a]
        return c

    return _columns(order)


def _rename(i, new):
    def mutate(names, rows):
        names = list(names)
        names[i] = new(names) if callable(new) else new
        return names, rows

    return mutate


def _row(k, change):
    def mutate(names, rows):
        rows = [list(r) for r in rows]
        rows[k] = change(rows[k])
        return names, rows

    return mutate


def _shuffle(names, rows):
    perm = np.random.default_rng(SEED).permutation(len(names)).tolist()
    return _columns(lambda c: [c[i] for i in perm])(names, rows)


# id: (mutation of (names, rows), None = reads the right values, or
#      (regex of the message, 1-based line of the error))
HEADER_MUTATIONS = {
    "delete_last_z": (_columns(lambda c: c[:-1]), (r"no column \w+_z\b", 1)),
    "delete_a_y": (_columns(lambda c: c[:5] + c[6:]), (r"no column \w+_y\b", 1)),
    "delete_frame": (_columns(lambda c: c[1:]), None),
    "delete_a_name_only": (lambda n, r: (n[:5] + n[6:], r), (r"no column \w+_y", 1)),
    "duplicate_column": (_columns(lambda c: c + [4]), (r"'\w+_x' appears 2 times", 1)),
    "duplicate_name": (
        _rename(4, lambda n: n[1]),
        (r"'\w+_x' appears 2 times .*; the header has no column \w+_x", 1),
    ),
    "unknown_name": (_rename(4, "Foo"), (r"column\(s\) 'Foo' name no coordinate", 1)),
    "unknown_column_added": (
        lambda n, r: (n + ["comment"], [x + ["1"] for x in r]),
        (r"'comment' name no coordinate", 1),
    ),
    "empty_name": (_rename(4, ""), (r"column\(s\) 5 of the header have no name", 1)),
    "swap_axes": (_swap(1, 2), None),
    "swap_joints": (_swap(1, -1), None),
    "frame_last": (_columns(lambda c: c[1:] + [0]), None),
    "shuffle": (_shuffle, None),
    "misspelt_suffix_xx": (
        _rename(4, lambda n: n[4] + "x"),
        (r"'\w+_xx' name no coordinate.*no column \w+_x\b", 1),
    ),
    "misspelt_suffix_q": (
        _rename(-1, lambda n: n[-1][:-1] + "q"),
        (r"'\w+_q' name no coordinate.*no column \w+_z\b", 1),
    ),
    "case_and_separator": (
        lambda n, r: (
            [re.sub(r"_([xyz])$", lambda m: "." + m[1].upper(), t) for t in n],
            r,
        ),
        None,
    ),
    "trailing_empty_column": (
        lambda n, r: (n + [""], [x + [""] for x in r]),
        None,
    ),
    "trailing_separator_on_header_only": (lambda n, r: (n + [""], r), None),
    "fewer_values_in_a_row": (_row(2, lambda x: x[:-1]), (r"expected \d+ values", 4)),
    "fewer_values_in_first_row": (_row(0, lambda x: x[:-1]), (r"expected \d+ val", 2)),
    "more_values_in_a_row": (_row(3, lambda x: x + ["0.5"]), (r"expected \d+ val", 5)),
}


def _check_header_case(path, read, names, rows, want, mutation, expect):
    names, rows = mutation(names, rows)
    path.write_text(_skeleton_text(names, rows))
    if expect is None:
        X, numbers = read(path)
        assert_allclose(X, want, rtol=0, atol=1e-12)
        if "frame" in names:
            assert numbers.tolist() == [int(r[names.index("frame")]) for r in rows]
        else:
            assert numbers is None
        return
    match, line = expect
    with pytest.raises(DataFormatError, match=match) as info:
        read(path)
    assert (info.value.file, info.value.line) == (path.name, line)
    assert str(info.value).startswith(f"{path.name} line {line}: ")


@pytest.mark.parametrize("case", sorted(HEADER_MUTATIONS))
def test_kinect_v2_header_mutations(tmp_path, case):
    names, rows, want = _kinect_v2_table()

    def read(path):
        return read_skeleton_csv(path, layout="kinect_v2", return_frame_numbers=True)

    _check_header_case(
        tmp_path / "v2.csv", read, names, rows, want, *HEADER_MUTATIONS[case]
    )


def test_real_recording_header_mutations(shared_data, tmp_path):
    names, rows = _precog_table(shared_data)
    path = tmp_path / "take1.csv"
    path.write_text(_skeleton_text(names, rows))
    want = read_skeleton_csv(path)
    assert_allclose(
        want,
        load_precog(shared_data / "precog_2016" / "CSV" / "Seq1_1.csv").X[0][:N_FRAMES],
    )

    def read(path):
        return read_skeleton_csv(path, return_frame_numbers=True)

    failures = []
    for case, (mutation, expect) in sorted(HEADER_MUTATIONS.items()):
        try:
            _check_header_case(path, read, names, rows, want, mutation, expect)
        except Exception as exc:  # noqa: BLE001 - list every case that fails
            failures.append(f"{case}: {type(exc).__name__}: {str(exc)[:300]}")
    assert not failures, "\n".join(failures)


def test_kinect_v2_missing_column_is_not_read_as_shifted_data(tmp_path):
    """The case of the issue: ``frame`` and 74 of the 75 joint columns."""
    names, rows, want = _kinect_v2_table()
    gone = names.index("ThumbRight_z")
    keep = [i for i in range(len(names)) if i != gone]
    path = tmp_path / "v2.csv"
    path.write_text(_skeleton_text(names, rows))
    assert_allclose(read_skeleton_csv(path, layout="kinect_v2"), want, atol=1e-12)
    path.write_text(
        _skeleton_text([names[i] for i in keep], [[r[i] for i in keep] for r in rows])
    )
    with pytest.raises(DataFormatError, match="no column ThumbRight_z") as info:
        read_skeleton_csv(path, layout="kinect_v2")
    assert info.value.file == "v2.csv" and str(info.value).startswith("v2.csv line 1")
    # The same file without its header: 75 values fit 25 joints without a frame
    # number, but the first value of every line counts frames.
    path.write_text(_skeleton_text(None, [[r[i] for i in keep] for r in rows]))
    with pytest.raises(DataFormatError, match="looks like a frame number") as info:
        read_skeleton_csv(path, layout="kinect_v2")
    assert "frame_column=False" in str(info.value) and info.value.file == "v2.csv"
    # frame_column=False says the first value is a coordinate: read by position
    got = read_skeleton_csv(path, layout="kinect_v2", frame_column=False)
    assert got.shape == want.shape and not np.allclose(got, want)
    with pytest.raises(DataFormatError, match="expected 75 or 100 values \\+ 1"):
        read_skeleton_csv(path, layout="kinect_v2", frame_column=True)
    # the intact file without header reads as before, with or without frames
    path.write_text(_skeleton_text(None, rows))
    X, numbers = read_skeleton_csv(path, layout="kinect_v2", return_frame_numbers=True)
    assert_allclose(X, want, atol=1e-12) and numbers[0] == 100
    path.write_text(_skeleton_text(None, [r[1:] for r in rows]))
    assert_allclose(read_skeleton_csv(path, layout="kinect_v2"), want, atol=1e-12)


def test_value_count_fitting_two_readings_asks_for_frame_column(tmp_path):
    """4 values of a 1-joint layout: a frame number and x, y, z, or x, y, z, c."""
    from skgesture.streaming import SkeletonAdapter

    class OneJoint(SkeletonAdapter):
        n_joints = 1
        name = "one_joint"

        def _convert(self, X):
            return np.repeat(X, 20, axis=1)

    rows = [[str(i), "0.1", "0.2", "0.3"] for i in range(5)]
    path = tmp_path / "one.csv"
    path.write_text(_skeleton_text(None, rows))
    with pytest.raises(
        DataFormatError, match="fit 4 values per joint or a frame number and 3 values"
    ) as info:
        read_skeleton_csv(path, layout=OneJoint())
    assert "frame_column=True or False" in str(info.value)
    X, numbers = read_skeleton_csv(
        path, layout=OneJoint(), frame_column=True, return_frame_numbers=True
    )
    assert_allclose(X[:, 0], [[0.1, 0.2, 0.3]] * 5) and numbers.tolist() == [
        0,
        1,
        2,
        3,
        4,
    ]
    X = read_skeleton_csv(path, layout=OneJoint(), frame_column=False)
    assert_allclose(X[:, 0], [[i, 0.1, 0.2] for i in range(5)])
