"""Tests of the readers of a user's own recordings (skeleton CSV + intervals)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from skgesture.datasets import (
    PRECOG_ACTION_NAMES,
    DataFileWarning,
    DataFormatError,
    load_precog,
    load_recordings,
    read_intervals,
    read_skeleton_csv,
    write_intervals,
)
from skgesture.layouts import KINECT_V1
from skgesture.streaming import (
    AZURE_KINECT_JOINTS,
    KINECT_V2_JOINTS,
    MEDIAPIPE_POSE_LANDMARKS,
    AzureKinectAdapter,
    KinectV2Adapter,
    MediaPipePoseAdapter,
)


def _frames(n_frames=6, n_joints=20, seed=0, low=-1.0, high=3.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(low, high, size=(n_frames, n_joints, 3))


def _write(path, rows, sep=",", header=None):
    text = "\n".join(sep.join(f"{v:.17g}" for v in row) for row in rows) + "\n"
    path.write_text(("" if header is None else header + "\n") + text)
    return path


def _header(names, frame=True, sep=","):
    cols = [f"{n}_{a}" for n in names for a in "xyz"]
    return sep.join((["frame"] if frame else []) + cols)


# ============================================================================
# Skeleton files
# ============================================================================


@pytest.mark.parametrize("sep", [",", "\t", ";", " "])
def test_skeleton_delimiters_round_trip_exactly(tmp_path, sep):
    X = _frames()
    path = _write(tmp_path / "take.csv", X.reshape(len(X), -1), sep=sep)
    assert_array_equal(read_skeleton_csv(path), X)
    assert_array_equal(read_skeleton_csv(path, delimiter=sep), X)


def test_skeleton_frame_column_and_header_are_detected(tmp_path):
    X = _frames()
    rows = np.column_stack([np.arange(100, 106), X.reshape(6, -1)])
    path = _write(tmp_path / "a.csv", rows, header=_header(KINECT_V1.joint_names))
    got, numbers = read_skeleton_csv(path, return_frame_numbers=True)
    assert_array_equal(got, X)
    assert numbers.dtype == np.int64 and numbers.tolist() == list(range(100, 106))
    # a 4th value per joint (confidence) is ignored; no frame numbers -> None
    conf = np.concatenate([X, np.ones((6, 20, 1))], axis=2)
    path = _write(tmp_path / "b.csv", conf.reshape(6, -1))
    got, numbers = read_skeleton_csv(path, return_frame_numbers=True)
    assert_array_equal(got, X) and numbers is None


def test_skeleton_header_with_joint_names_sets_the_order(tmp_path):
    X = _frames()
    perm = np.random.default_rng(1).permutation(20)
    names = [KINECT_V1.joint_names[k] for k in perm]
    path = _write(
        tmp_path / "a.csv", X[:, perm].reshape(6, -1), header=_header(names, False)
    )
    assert_array_equal(read_skeleton_csv(path), X)
    # the same order given as `layout`, without header
    path = _write(tmp_path / "b.csv", X[:, perm].reshape(6, -1))
    assert_array_equal(read_skeleton_csv(path, layout=names), X)
    # a header contradicting `layout` is an error
    path = _write(
        tmp_path / "c.csv", X[:, perm].reshape(6, -1), header=_header(names, False)
    )
    with pytest.raises(DataFormatError, match="c.csv line 1: the header names"):
        read_skeleton_csv(path, layout=list(KINECT_V1.joint_names))


def test_skeleton_generic_header_is_skipped(tmp_path):
    X = _frames()
    header = ",".join(f"j{k}_{a}" for k in range(20) for a in "xyz")
    path = _write(tmp_path / "a.csv", X.reshape(6, -1), header=header)
    assert_array_equal(read_skeleton_csv(path), X)


def test_skeleton_header_naming_unknown_joints_is_an_error(tmp_path):
    names = list(KINECT_V1.joint_names[:-1]) + ["Tail"]
    path = _write(
        tmp_path / "a.csv", _frames().reshape(6, -1), header=_header(names, False)
    )
    with pytest.raises(DataFormatError, match="joint\\(s\\) Tail are not in layout"):
        read_skeleton_csv(path)


def test_skeleton_untracked_frames_become_zeros(tmp_path):
    X = _frames()
    X[1] = 0.0
    X[3, 5, 2] = np.nan
    path = _write(tmp_path / "a.csv", X.reshape(6, -1))
    got = read_skeleton_csv(path)
    assert_array_equal(got[[1, 3]], 0.0)
    assert np.isfinite(got).all()
    assert_array_equal(got[[0, 2, 4, 5]], X[[0, 2, 4, 5]])


@pytest.mark.parametrize(
    "mutate, line, match",
    [
        (lambda r: r[:2] + [r[2][:-1]] + r[3:], 3, "expected 60 values, got 59"),
        (lambda r: r[:1] + [r[1][:1] + ["inf"] + r[1][2:]] + r[2:], 2, "'inf'"),
        (lambda r: r[:4] + [r[4][:3] + ["abc"] + r[4][4:]] + r[5:], 5, "'abc'"),
        (lambda r: r[:2] + [["2e7"] + r[2][1:]] + r[3:], 3, "beyond \\+-1e\\+07"),
        (lambda r: r[:2] + [["1e5"] + r[2][1:]] + r[3:], 3, "beyond \\+-10000 m"),
        (lambda r: r[:2] + [[]] + r[3:], 3, "got 0"),
    ],
)
def test_skeleton_errors_name_file_and_line(tmp_path, mutate, line, match):
    rows = [[f"{v:.6g}" for v in row] for row in _frames().reshape(6, -1)]
    path = tmp_path / "take.csv"
    path.write_text("\n".join(",".join(r) for r in mutate(rows)) + "\n")
    with pytest.raises(DataFormatError, match=match) as info:
        read_skeleton_csv(path)
    assert (info.value.file, info.value.line) == ("take.csv", line)
    assert str(info.value).startswith(f"take.csv line {line}: ")


def test_skeleton_frame_numbers_must_increase(tmp_path):
    rows = np.column_stack([[0, 1, 2, 2, 4, 5], _frames().reshape(6, -1)])
    path = _write(tmp_path / "a.csv", rows)
    with pytest.raises(DataFormatError, match="a.csv line 4: frame number 2 does not"):
        read_skeleton_csv(path)
    rows[:, 0] = [0, 1, 2.5, 3, 4, 5]
    with pytest.raises(DataFormatError, match="line 3: frame number 2.5 is not an int"):
        read_skeleton_csv(_write(tmp_path / "a.csv", rows))


def test_skeleton_empty_files(tmp_path):
    (tmp_path / "a.csv").write_text("")
    with pytest.raises(DataFormatError, match="a.csv is empty"):
        read_skeleton_csv(tmp_path / "a.csv")
    (tmp_path / "a.csv").write_text(_header(KINECT_V1.joint_names) + "\n")
    with pytest.raises(DataFormatError, match="a.csv has a header but no frame line"):
        read_skeleton_csv(tmp_path / "a.csv")


def test_skeleton_millimetres_warn(tmp_path):
    path = _write(tmp_path / "a.csv", _frames(low=500, high=3000).reshape(6, -1))
    with pytest.warns(DataFileWarning, match="a.csv: the median .*millimetres"):
        read_skeleton_csv(path)


def test_skeleton_reader_option_errors(tmp_path):
    path = _write(tmp_path / "a.csv", _frames().reshape(6, -1))
    with pytest.raises(ValueError, match="unknown layout 'kinect'"):
        read_skeleton_csv(path, layout="kinect")
    with pytest.raises(ValueError, match="delimiter must be"):
        read_skeleton_csv(path, delimiter="|")
    with pytest.raises(ValueError, match="'frame_column' parameter"):
        read_skeleton_csv(path, frame_column="yes")
    with pytest.raises(ValueError, match="match no known layout; closest"):
        read_skeleton_csv(path, layout=[f"j{k}" for k in range(20)])
    with pytest.raises(ValueError, match="more than once"):
        read_skeleton_csv(path, layout=["Head"] * 20)
    with pytest.raises(DataFormatError, match="expected 75 or 100 values"):
        read_skeleton_csv(path, layout="kinect_v2")


def test_skeleton_header_time_and_confidence_columns_are_recognised(tmp_path):
    X = _frames()
    names = [f"{j}_{a}" for j in KINECT_V1.joint_names for a in ("x", "y", "z", "c")]
    values = np.concatenate([X, np.full((6, 20, 1), 0.7)], axis=2).reshape(6, -1)
    times = np.arange(6) * 0.033
    rows = np.column_stack([values, times])  # the timestamp last
    path = _write(tmp_path / "a.csv", rows, header=",".join(names + ["timestamp"]))
    got, numbers = read_skeleton_csv(path, return_frame_numbers=True)
    assert_array_equal(got, X)
    assert numbers is None  # a timestamp is no frame number
    rows[3, -1] = 0.0
    with pytest.raises(DataFormatError, match="a.csv line 5: timestamp 0 is before"):
        read_skeleton_csv(_write(path, rows, header=",".join(names + ["time"])))


# ============================================================================
# Other layouts through the streaming adapters
# ============================================================================


def test_kinect_v2_and_azure_layouts_use_the_adapters(tmp_path):
    v2 = _frames(n_joints=25)
    path = _write(tmp_path / "v2.tsv", v2.reshape(6, -1), sep="\t")
    assert_allclose(read_skeleton_csv(path, layout="kinect_v2"), KinectV2Adapter()(v2))
    az = _frames(n_joints=32, low=-800, high=2500)
    path = _write(tmp_path / "az.csv", az.reshape(6, -1))
    assert_allclose(read_skeleton_csv(path, layout="azure"), AzureKinectAdapter()(az))
    path = _write(tmp_path / "azm.csv", (az / 1000).reshape(6, -1))
    got = read_skeleton_csv(path, layout=AzureKinectAdapter(units="m"))
    assert_allclose(got, AzureKinectAdapter()(az))


def test_mediapipe_layout_with_visibility_column(tmp_path):
    lm = _frames(n_joints=33, low=0.0, high=1.0)
    rows = np.concatenate([lm, np.full((6, 33, 1), 0.9)], axis=2).reshape(6, -1)
    path = _write(tmp_path / "mp.csv", rows)
    assert_allclose(
        read_skeleton_csv(path, layout="mediapipe"), MediaPipePoseAdapter()(lm)
    )
    world = MediaPipePoseAdapter(coordinates="world")
    assert_allclose(read_skeleton_csv(path, layout=world), world(lm))


def test_joint_list_of_another_layout_may_leave_out_unused_joints(tmp_path):
    v2 = _frames(n_joints=25)
    keep = [j for j in KINECT_V2_JOINTS if "Thumb" not in j and "Tip" not in j]
    cols = [KINECT_V2_JOINTS.index(j) for j in keep][::-1]
    path = _write(tmp_path / "v2.csv", v2[:, cols].reshape(6, -1))
    names = [KINECT_V2_JOINTS[c] for c in cols]
    assert_allclose(read_skeleton_csv(path, layout=names), KinectV2Adapter()(v2))
    # a header of Azure joint names (upper case, any order) picks the joints
    az = _frames(n_joints=32, low=-800, high=2500)
    order = np.random.default_rng(3).permutation(32)
    header = _header([AZURE_KINECT_JOINTS[k] for k in order], frame=False)
    path = _write(tmp_path / "az.csv", az[:, order].reshape(6, -1), header=header)
    assert_allclose(read_skeleton_csv(path, layout="azure"), AzureKinectAdapter()(az))
    # MediaPipe names in file order work as a layout
    lm = _frames(n_joints=33, low=0.0, high=1.0)
    path = _write(tmp_path / "mp.csv", lm.reshape(6, -1))
    got = read_skeleton_csv(path, layout=list(MEDIAPIPE_POSE_LANDMARKS))
    assert_allclose(got, MediaPipePoseAdapter()(lm))


# ============================================================================
# Interval files
# ============================================================================


def test_read_intervals_header_in_any_order_and_class_names(tmp_path):
    path = tmp_path / "a.labels.csv"
    path.write_text("label,note,end,start\nwave,fast,10,3\nrest,,12,10\npoint,,20,12\n")
    assert read_intervals(path, classes=["point", "wave"]).tolist() == [
        [2, 3, 10],
        [1, 12, 20],
    ]
    names = tmp_path / "classes.txt"
    names.write_text("point\nwave\n")
    assert read_intervals(path, classes=names).tolist() == [[2, 3, 10], [1, 12, 20]]
    with pytest.raises(DataFormatError, match="line 2: label 'wave' is not a class"):
        read_intervals(path)


def test_read_intervals_frame_conventions(tmp_path):
    path = tmp_path / "a.labels.tsv"
    path.write_text("1\t4\t2\n")
    assert read_intervals(path).tolist() == [[2, 1, 4]]
    assert read_intervals(path, base=1).tolist() == [[2, 0, 3]]
    assert read_intervals(path, end="inclusive").tolist() == [[2, 1, 5]]
    assert read_intervals(path, base=1, end="inclusive").tolist() == [[2, 0, 4]]
    path.write_text("")
    assert read_intervals(path).shape == (0, 3)


@pytest.mark.parametrize(
    "text, kwargs, line, match",
    [
        ("3,3,1\n", {}, 1, "end frame 3 is not after start frame 3"),
        ("4,3,1\n", {"end": "inclusive"}, 1, "end frame 3 is before start frame 4"),
        ("0,3,1\n", {"base": 1}, 1, "start frame 0 is before the first frame 1"),
        ("1,3,1\n5,11,1\n", {"n_frames": 10}, 2, "end frame 11 is beyond the record"),
        ("1,3.5,1\n", {}, 1, "end frame '3.5' is not an integer"),
        ("1,3\n", {}, 1, "expected 3 values"),
        ("1,3,-2\n", {}, 1, "label -2 is negative"),
        ("1,3,1001\n", {}, 1, "label 1001 is above 1000"),
        ("1,3,3\n", {"classes": ["a", "b"]}, 1, "label 3 is beyond the 2 named"),
        ("1,3,1\n2,1" + "0" * 30 + ",1\n", {}, 2, "beyond 2\\*\\*53"),
        ("first,last,what\n", {}, 1, "expected a header naming the columns"),
    ],
)
def test_read_intervals_errors(tmp_path, text, kwargs, line, match):
    path = tmp_path / "a.labels.csv"
    path.write_text(text)
    with pytest.raises(DataFormatError, match=match) as info:
        read_intervals(path, **kwargs)
    assert (info.value.file, info.value.line) == ("a.labels.csv", line)


@pytest.mark.parametrize(
    "text, match",
    [
        ("wave\n\npoint\n", "classes.txt line 2: empty line"),
        ("wave\nwave\n", "classes.txt line 2: class name 'wave' appears twice"),
        ("wave\n3\n", "classes.txt line 2: class name '3' is a number"),
        ("Rest\n", "classes.txt line 1: 'Rest' names class 0"),
    ],
)
def test_class_names_file_errors(tmp_path, text, match):
    (tmp_path / "classes.txt").write_text(text)
    (tmp_path / "a.csv").write_text("1,2,wave\n")
    with pytest.raises(DataFormatError, match=match):
        read_intervals(tmp_path / "a.csv", classes=tmp_path / "classes.txt")


@pytest.mark.parametrize("base", [0, 1])
@pytest.mark.parametrize("end", ["exclusive", "inclusive"])
def test_write_intervals_round_trip(tmp_path, base, end):
    y = np.array([0, 2, 2, 2, 0, 1, 1, 3, 3, 0, 2])
    names = ["point, left", "wave", "stop"]  # a name holding the delimiter
    path = write_intervals(
        tmp_path / "a.labels.csv", y, classes=names, base=base, end=end
    )
    seg = read_intervals(path, classes=names, base=base, end=end, n_frames=len(y))
    assert_array_equal(seg, [[2, 1, 4], [1, 5, 7], [3, 7, 9], [2, 10, 11]])
    first = path.read_text().splitlines()[1]
    assert first == f"{1 + base},{4 + base - (end == 'inclusive')},wave"
    numbers = write_intervals(tmp_path / "b.csv", seg, base=base, end=end)
    assert_array_equal(read_intervals(numbers, base=base, end=end), seg)


def test_write_intervals_refuses_bad_input_and_overwriting(tmp_path):
    path = write_intervals(tmp_path / "a.csv", [0, 0, 0])
    assert path.read_text() == "start,end,label\n"
    assert read_intervals(path).shape == (0, 3)
    with pytest.raises(FileExistsError, match="a.csv' already exists"):
        write_intervals(path, [0, 1])
    write_intervals(path, [0, 1], overwrite=True)
    assert path.read_text() == "start,end,label\n1,2,1\n"
    with pytest.raises(ValueError, match="labels must be integers"):
        write_intervals(tmp_path / "b.csv", [0.0, 1.5])
    with pytest.raises(ValueError, match="class 3 has no name"):
        write_intervals(tmp_path / "b.csv", [0, 3], classes=["a", "b"])
    with pytest.raises(ValueError, match="segment row 0 .* is empty"):
        write_intervals(tmp_path / "b.csv", [[1, 4, 4]])
    with pytest.raises(ValueError, match="class -1 is negative"):
        write_intervals(tmp_path / "b.csv", [0, -1])
    assert not (tmp_path / "b.csv").exists()


# ============================================================================
# Folders of recordings
# ============================================================================


def _recording(folder, name, n_frames=12, labels=None, seed=0):
    folder.mkdir(parents=True, exist_ok=True)
    X = _frames(n_frames, seed=seed)
    _write(folder / f"{name}.csv", X.reshape(n_frames, -1))
    if labels is not None:
        (folder / f"{name}.labels.csv").write_text(labels)
    return X


def test_load_recordings_groups_from_subfolders_and_names(tmp_path):
    xa = _recording(tmp_path / "alice", "take2", labels="2,5,wave\n")
    xb = _recording(tmp_path / "alice", "take10", labels="1,4,point\n6,9,wave\n")
    xc = _recording(tmp_path / "bob", "take1", labels="")
    data = load_recordings(tmp_path)
    assert data.sample_ids == ["alice/take2", "alice/take10", "bob/take1"]
    assert data.groups.tolist() == ["alice", "alice", "bob"]
    assert data.target_names == ["point", "wave"]  # sorted names found
    for got, want in zip(data.X, (xa, xb, xc)):
        assert_array_equal(got, want)
    assert data.y[0].tolist() == [0, 0, 2, 2, 2] + [0] * 7
    assert data.segments[1].tolist() == [[1, 1, 4], [2, 6, 9]]
    assert data.y[2].tolist() == [0] * 12 and data.segments[2].shape == (0, 3)
    assert data.layout == "kinect_v1" and data.source_layout == "kinect_v1"
    assert data.n_frames.tolist() == [12, 12, 12] and data.fps == 30.0
    assert data.label_files[0].endswith("take2.labels.csv")


def test_load_recordings_regex_groups_numbers_and_classes_file(tmp_path):
    _recording(tmp_path, "s01_take1", labels="2,5,1\n")
    _recording(tmp_path, "s02_take1", labels="0,3,3\n")
    data = load_recordings(tmp_path, groups=r"s(\d+)_")
    assert data.groups.tolist() == [1, 2]
    assert data.target_names == ["1", "2", "3"]
    (tmp_path / "classes.txt").write_text("a\nb\nc\nd\n")
    data = load_recordings(tmp_path)
    assert data.groups.tolist() == ["s01_take1", "s02_take1"]  # own group each
    assert data.target_names == ["a", "b", "c", "d"]
    with pytest.raises(ValueError, match="does not match recording 's01_take1'"):
        load_recordings(tmp_path, groups=r"subject(\d+)")


def test_load_recordings_unlabelled_and_mixed_folders(tmp_path):
    _recording(tmp_path, "a")
    _recording(tmp_path, "b")
    data = load_recordings(tmp_path)
    assert data.y is None and data.segments is None and len(data.X) == 2
    with pytest.raises(ValueError, match="2 of 2 recordings have no annotation"):
        load_recordings(tmp_path, labels=True)
    (tmp_path / "a.labels.csv").write_text("1,3,1\n")
    with pytest.raises(ValueError, match="1 of 2 recordings .*\\(b.labels.csv\\)"):
        load_recordings(tmp_path)
    assert load_recordings(tmp_path, labels=False).y is None
    one = load_recordings(tmp_path / "a.csv")  # one file and its annotation
    assert one.sample_ids == ["a"] and one.y[0].tolist()[:4] == [0, 1, 1, 0]


def test_load_recordings_warnings_and_errors(tmp_path):
    _recording(tmp_path, "a", labels="1,5,1\n3,8,2\n")
    (tmp_path / "ghost.labels.csv").write_text("1,2,1\n")
    with pytest.warns(DataFileWarning) as record:
        data = load_recordings(tmp_path)
    messages = " | ".join(str(w.message) for w in record)
    assert "ghost.labels.csv: no skeleton file ghost" in messages
    assert "a.labels.csv: overlapping intervals: line 1 and line 2" in messages
    assert data.y[0].tolist()[:9] == [0, 1, 1, 2, 2, 2, 2, 2, 0]
    (tmp_path / "ghost.labels.csv").unlink()
    (tmp_path / "a.labels.csv").write_text("1,13,1\n")
    with pytest.raises(DataFormatError, match="a.labels.csv line 1: end frame 13 is"):
        load_recordings(tmp_path)
    (tmp_path / "a.labels.csv").write_text("1,3,1\n4,6,wave\n")
    with pytest.raises(ValueError, match="mix class numbers and class names"):
        load_recordings(tmp_path)


def test_load_recordings_empty_folder_and_verbose(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="no skeleton file"):
        load_recordings(tmp_path / "empty")
    _recording(tmp_path / "rec", "a")
    load_recordings(tmp_path / "rec")
    assert capsys.readouterr().err == ""
    load_recordings(tmp_path / "rec", verbose=1)
    assert "recordings" in capsys.readouterr().err


def test_precog_written_as_recordings_reads_back_identical(tmp_path):
    data = load_precog()
    (tmp_path / "classes.txt").write_text("\n".join(data.target_names) + "\n")
    for x, y, sid, subject in zip(data.X, data.y, data.sample_ids, data.groups):
        folder = tmp_path / f"subject{subject}"
        folder.mkdir(exist_ok=True)
        rows = np.column_stack([np.arange(len(x)), x.reshape(len(x), -1)])
        header = _header(KINECT_V1.joint_names)
        _write(folder / f"{sid}.csv", rows, header=header)
        write_intervals(folder / f"{sid}.labels.csv", y, classes=data.target_names)
    back = load_recordings(tmp_path, groups=r"subject(\d+)")
    assert back.target_names == list(PRECOG_ACTION_NAMES) == data.target_names
    index = {sid: k for k, sid in enumerate(back.sample_ids)}
    order = [index[f"subject{g}/{sid}"] for sid, g in zip(data.sample_ids, data.groups)]
    assert len(order) == len(back.sample_ids) == 48
    for k, x, y, seg in zip(order, data.X, data.y, data.segments):
        assert_array_equal(back.X[k], x)
        assert_array_equal(back.y[k], y)
        assert_array_equal(back.segments[k], seg)
        assert back.frame_numbers[k].tolist() == list(range(len(x)))
    assert_array_equal(back.groups[order], data.groups)
    assert_array_equal(back.n_frames[order], data.n_frames)


def test_load_recordings_errors_name_the_file_relative_to_the_folder(tmp_path):
    """alice/take1.csv and bob/take1.csv: the error says which one is broken."""
    _recording(tmp_path / "alice", "take1", labels="1,4,1\n")
    _recording(tmp_path / "bob", "take1", labels="1,4,1\n")
    broken = tmp_path / "bob" / "take1.csv"
    good = broken.read_text()
    broken.write_text(good.replace("\n", "\nnot,a,number\n", 1))
    with pytest.raises(DataFormatError) as info:
        load_recordings(tmp_path)
    assert info.value.file == "bob/take1.csv" and info.value.line == 2
    assert str(info.value).startswith("bob/take1.csv line 2: ")
    broken.write_bytes(b"caf\xe9\n")  # not UTF-8
    with pytest.raises(DataFormatError, match="^bob/take1.csv line 1: not a text"):
        load_recordings(tmp_path)
    broken.write_text(good)
    (tmp_path / "alice" / "take1.labels.csv").write_text("1,40,1\n")
    with pytest.raises(DataFormatError, match="^alice/take1.labels.csv line 1: end"):
        load_recordings(tmp_path)
    (tmp_path / "alice" / "take1.labels.csv").write_text("1,4,wave\n")
    (tmp_path / "classes.txt").write_text("point\n")
    with pytest.raises(DataFormatError, match="^alice/take1.labels.csv line 1: lab"):
        load_recordings(tmp_path)
    (tmp_path / "classes.txt").unlink()
    (tmp_path / "alice" / "take1.labels.csv").write_text("1,5,1\n3,8,1\n")
    (tmp_path / "bob" / "ghost.labels.csv").write_text("1,2,1\n")
    with pytest.warns(DataFileWarning) as record:
        load_recordings(tmp_path)
    messages = [str(w.message) for w in record]
    assert any(m.startswith("alice/take1.labels.csv: overlapping") for m in messages)
    assert any(m.startswith("bob/ghost.labels.csv: no skeleton") for m in messages)
    # one file given directly: its own name
    broken.write_text(good.replace("\n", "\nnot,a,number\n", 1))
    with pytest.raises(DataFormatError, match="^take1.csv line 2: "):
        load_recordings(broken)
