"""Tests of the real-data loaders and the ChaLearn prediction writer.

Reference numbers come from the PROVENANCE.md file of each folder of the shared
data (counted there independently of this code), or are recomputed here from the
raw text with plain Python.
"""

import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from skgesture.datasets import (
    CHALEARN_GESTURE_NAMES,
    MSR_ACTION3D_TO_KINECT_V1,
    DataFileWarning,
    DataFormatError,
    load_chalearn,
    load_msr_action3d,
    load_msrc12,
    load_precog,
    load_utkinect,
    read_chalearn_labels,
    write_chalearn_predictions,
)
from skgesture.layouts import KINECT_V1
from skgesture.utils import labels_to_segments, segments_to_labels

# --- ChaLearn Montalbano, chalearn_montalbano/PROVENANCE.md "Sequence summary" ---
# sample: (frames, gestures, distinct classes, median gesture length, empty frames)
CHALEARN_V2 = {
    "Sample0101": (1208, 20, 19, 42.5, 3),
    "Sample0470": (1337, 10, 10, 39.5, 1),
}
CHALEARN_V1 = {
    "Sample00050": (1608, 20, 20, 38.0, 3),
    "Sample00279": (1146, 19, 19, 60.0, 3),
    "Sample00710": (1835, 20, 20, 53.5, 4),
}
VALIDATION = {
    "n_sequences": 230,
    "n_gestures": 3454,
    "n_frames": 312_345,
    "median_frames": 1283.5,
    "length_range": (6, 96),
    "median_length": 39,
    "per_class_range": (164, 186),
}
# --- PRECOG, precog_2016/PROVENANCE.md ---
PRECOG_SCRIPTS = {
    1: [1, 2, 5, 6, 3],
    2: [1, 6, 2, 5, 3],
    3: [1, 4, 6, 7, 3],
    4: [7, 2, 5, 6, 4],
    5: [7, 5, 1, 4, 6],
    6: [7, 5, 3, 8, 6],
}
PRECOG_GLITCH = "Seq6_3"  # its label 6 run is split by one 0 frame (4-frame run)
# --- MSRC-12, msrc12_subset/PROVENANCE.md and the .tagstream files ---
MSRC12_LEADING_ZERO_ROWS = 20  # 120 in P3_2_1_p11
MSRC12_ACTION_POINTS = 246  # 124 for p01, 122 for p11 (counted in the tagstreams)
MSRC12_FRAME_RANGE = (606, 1207)
MSRC12_DROPOUT_FILE, MSRC12_DROPOUT_MISSING = "P3_2_8_p11", 20 + 168
# --- UTKinect, utkinect_action3d/PROVENANCE.md ---
UTK_ROWS, UTK_ROW_RANGE, UTK_INSTANCES = 15_860, (534, 1389), 199
# --- MSR Action3D, msr_action3d/PROVENANCE.md ---
MSR_ALL, MSR_CVPR12, MSR_ZERO_CLIP = 567, 557, "a13_s09_e02"
MSR_LENGTH_RANGE, MSR_MEDIAN_LENGTH = (13, 936), 39
# Counted with this loader (not in PROVENANCE): clips with all-zero (untracked)
# frames, mostly a13 "bend" and a20 "pickup and throw"; 13 of them are in cvpr12.
MSR_CLIPS_WITH_GAPS, MSR_CVPR12_CLIPS_WITH_GAPS = 20, 13


def _chalearn_dir(shared_data, sub):
    return shared_data / "chalearn_montalbano" / sub


def _check_contract(data, *, n_joints=20):
    """The keys and types every loader promises."""
    for key in (
        "X",
        "y",
        "segments",
        "sample_ids",
        "groups",
        "fps",
        "n_frames",
        "missing",
        "target_names",
        "layout",
        "DESCR",
    ):
        assert key in data, key
    assert data.layout == "kinect_v1"
    assert len(data.groups) == len(data.sample_ids) == len(data.y)
    assert all(isinstance(s, str) for s in data.sample_ids)
    for i, (lab, seg) in enumerate(zip(data.y, data.segments)):
        assert lab.dtype == np.int64 and lab.ndim == 1
        assert lab.shape == (data.n_frames[i],)
        assert seg.dtype == np.int64 and seg.ndim == 2 and seg.shape[1] == 3
        assert np.all(seg[:, 0] >= 1) and np.all(seg[:, 0] <= len(data.target_names))
        assert np.all(np.diff(seg[:, 1]) >= 0)
        if data.X is not None:
            x = data.X[i]
            assert x.dtype == np.float64 and x.shape == (len(lab), n_joints, 3)
            assert data.missing[i].dtype == bool and data.missing[i].shape == lab.shape
    assert isinstance(data.DESCR, str) and data.DESCR.strip()


def _first_values(line, n, sep=","):
    return [float(v) for v in line.split(sep)[:n]]


# ============================================================================
# ChaLearn: real files
# ============================================================================


def test_chalearn_v2_samples_match_provenance(shared_data):
    folder = _chalearn_dir(shared_data, "v2_2014_samples")
    data = load_chalearn(folder)
    _check_contract(data)
    assert data.sample_ids == list(CHALEARN_V2)
    assert data.fps == 20.0 and data.target_names == list(CHALEARN_GESTURE_NAMES)
    assert data.target_names[0] == "vattene" and data.target_names[19] == "sonostufo"
    assert_array_equal(data.groups, list(CHALEARN_V2))
    for i, (frames, n_gest, n_cls, median, empty) in enumerate(CHALEARN_V2.values()):
        seg = data.segments[i]
        assert data.n_frames[i] == frames and len(data.X[i]) == frames
        assert len(seg) == n_gest and len(set(seg[:, 0])) == n_cls
        # 1-based inclusive (s, e) in the file -> 0-based exclusive: same length
        assert np.median(seg[:, 2] - seg[:, 1]) == median
        assert data.missing[i].sum() == empty
        assert_array_equal(data.y[i], segments_to_labels(seg, frames))
    assert data.has_labels.all()
    assert_array_equal(data.max_depth, [2930, 4095])


def test_chalearn_values_and_labels_match_raw_text(shared_data):
    folder = _chalearn_dir(shared_data, "v2_2014_samples")
    data = load_chalearn(folder, samples=["Sample0101"], return_joint_data=True)
    lines = (folder / "Sample0101_skeleton.csv").read_text().splitlines()
    # frame 5 (0-based 4), joint HandRight (k = 11): world columns 99..101
    row = [float(v) for v in lines[4].split(",")]
    hand = KINECT_V1.index("HandRight")
    assert data.X[0][4, hand].tolist() == row[9 * hand : 9 * hand + 3]
    assert data.X[0][4, 0].tolist() == [0.052037, 0.031141, 2.1771]
    assert data.joint_data[0].shape == (1208, 20, 9)
    assert data.joint_data[0][4].ravel().tolist() == row
    assert_array_equal(data.joint_data[0][..., :3], data.X[0])
    first = (folder / "Sample0101_labels.csv").read_text().splitlines()[0]
    c, s, e = map(int, first.split(","))
    assert data.segments[0][0].tolist() == [c, s - 1, e]
    assert data.y[0][s - 2] == 0 and data.y[0][s - 1] == c and data.y[0][e - 1] == c
    assert data.y[0][e] != c or e in data.segments[0][1:, 1]


def test_chalearn_v1_2013_five_digit_ids(shared_data):
    data = load_chalearn(_chalearn_dir(shared_data, "v1_2013_samples"))
    _check_contract(data)
    assert data.sample_ids == list(CHALEARN_V1)
    for i, (frames, n_gest, n_cls, median, empty) in enumerate(CHALEARN_V1.values()):
        assert data.n_frames[i] == frames
        assert len(data.segments[i]) == n_gest
        assert len(set(data.segments[i][:, 0])) == n_cls
        assert np.median(np.diff(data.segments[i][:, 1:], axis=1)) == median
        assert data.missing[i].sum() == empty
    # Sample00279: the 19 segments tile the whole sequence (no rest frame)
    assert np.all(data.y[1] > 0)


def test_chalearn_validation_labels_only(shared_data):
    data = load_chalearn(_chalearn_dir(shared_data, "v2_2014_validation_labels"))
    _check_contract(data)
    assert data.X is None and data.missing is None
    assert len(data.y) == VALIDATION["n_sequences"]
    assert data.sample_ids[0] == "Sample0471" and data.sample_ids[-1] == "Sample0700"
    seg = np.concatenate(data.segments)
    assert len(seg) == VALIDATION["n_gestures"]
    assert data.n_frames.sum() == VALIDATION["n_frames"]
    assert sum(len(lab) for lab in data.y) == VALIDATION["n_frames"]
    assert np.median(data.n_frames) == VALIDATION["median_frames"]
    lengths = seg[:, 2] - seg[:, 1]
    assert (lengths.min(), lengths.max()) == VALIDATION["length_range"]
    assert np.median(lengths) == VALIDATION["median_length"]
    counts = np.bincount(seg[:, 0], minlength=21)[1:]
    assert (counts.min(), counts.max()) == VALIDATION["per_class_range"]
    assert data.fps == 20.0
    # the explicit flag gives the same result
    again = load_chalearn(
        _chalearn_dir(shared_data, "v2_2014_validation_labels"),
        labels_only=True,
        samples=["Sample0471", 700],
    )
    assert again.sample_ids == ["Sample0471", "Sample0700"]
    assert_array_equal(again.segments[1], data.segments[-1])


def _make_zips(src, dst, ids, *, extra_member=True):
    dst.mkdir()
    for sid in ids:
        with zipfile.ZipFile(dst / f"{sid}.zip", "w", zipfile.ZIP_DEFLATED) as zf:
            if extra_member:  # the real archives hold videos: never read
                zf.writestr(f"{sid}_color.mp4", b"\x00\x01not a video")
            for kind in ("skeleton", "labels", "data"):
                zf.write(src / f"{sid}_{kind}.csv", f"{sid}_{kind}.csv")
    return dst


def test_chalearn_zip_loads_like_extracted_files(shared_data, tmp_path):
    src = _chalearn_dir(shared_data, "v2_2014_samples")
    zips = _make_zips(src, tmp_path / "zips", CHALEARN_V2)
    ref = load_chalearn(src)
    for path in (zips, zips / "Sample0470.zip"):
        got = load_chalearn(path)
        ids = got.sample_ids
        assert ids == ([*CHALEARN_V2] if path == zips else ["Sample0470"])
        for i, sid in enumerate(ids):
            j = ref.sample_ids.index(sid)
            assert_array_equal(got.X[i], ref.X[j])
            assert_array_equal(got.y[i], ref.y[j])
            assert_array_equal(got.segments[i], ref.segments[j])
            assert got.n_frames[i] == ref.n_frames[j]


def test_chalearn_single_csv_path_and_sample_selection(shared_data):
    folder = _chalearn_dir(shared_data, "v2_2014_samples")
    one = load_chalearn(folder / "Sample0470_skeleton.csv")
    assert one.sample_ids == ["Sample0470"] and one.n_frames.tolist() == [1337]
    sel = load_chalearn(folder, samples=470)
    assert_array_equal(sel.X[0], one.X[0])
    with pytest.raises(FileNotFoundError, match="101000"):
        load_chalearn(folder, samples=[101000])


def test_chalearn_mixed_folder_needs_labels_only(shared_data, tmp_path):
    src = _chalearn_dir(shared_data, "v2_2014_samples")
    for name in (
        "Sample0101_skeleton.csv",
        "Sample0101_labels.csv",
        "Sample0101_data.csv",
        "Sample0470_labels.csv",
        "Sample0470_data.csv",
    ):
        (tmp_path / name).write_bytes((src / name).read_bytes())
    with pytest.raises(ValueError, match="1 of 2 samples .* no skeleton.*labels_only"):
        load_chalearn(tmp_path)
    data = load_chalearn(tmp_path, labels_only=True)
    assert data.X is None and data.n_frames.tolist() == [1208, 1337]


# ============================================================================
# ChaLearn: prediction writer
# ============================================================================


def test_writer_round_trips_validation_labels_byte_for_byte(shared_data, tmp_path):
    folder = _chalearn_dir(shared_data, "v2_2014_validation_labels")
    data = load_chalearn(folder)
    from_y = write_chalearn_predictions(data.y, data.sample_ids, tmp_path / "y")
    from_seg = write_chalearn_predictions(
        data.segments, data.sample_ids, tmp_path / "seg", n_frames=data.n_frames
    )
    for sid, p_y, p_seg in zip(data.sample_ids, from_y, from_seg):
        original = (folder / f"{sid}_labels.csv").read_bytes()
        assert p_y.name == f"{sid}_prediction.csv"
        assert p_y.read_bytes() == original
        assert p_seg.read_bytes() == original
    back = read_chalearn_labels(from_y[0], n_frames=data.n_frames[0])
    assert_array_equal(back, data.segments[0])


def test_writer_maximal_runs_and_empty_file(tmp_path):
    y = [np.array([0, 4, 4, 7, 7, 7, 0, 0, 4]), np.zeros(5, dtype=np.int64)]
    paths = write_chalearn_predictions(y, [12, "Sample0013"], tmp_path)
    assert [p.name for p in paths] == [
        "Sample0012_prediction.csv",
        "Sample0013_prediction.csv",
    ]
    assert paths[0].read_text() == "4,2,3\n7,4,6\n4,9,9\n"
    assert paths[1].read_text() == ""
    assert_array_equal(read_chalearn_labels(paths[0]), labels_to_segments(y[0]))
    assert read_chalearn_labels(paths[1]).shape == (0, 3)


def test_writer_clamps_to_the_sequence(tmp_path):
    seg = np.array([[3, -4, 5], [9, 90, 130], [5, 200, 210]])
    with pytest.warns(DataFileWarning, match="1 segment.* entirely outside"):
        (path,) = write_chalearn_predictions(
            [seg], ["Sample0701"], tmp_path, n_frames=100
        )
    assert path.read_text() == "3,1,5\n9,91,100\n"
    # per-frame labels longer than numFrames are cut at numFrames
    with pytest.warns(DataFileWarning, match="beyond numFrames=4"):
        (path,) = write_chalearn_predictions(
            [np.array([0, 2, 2, 2, 2, 2])], [701], tmp_path, n_frames=4, overwrite=True
        )
    assert path.read_text() == "2,2,4\n"


@pytest.mark.parametrize(
    "pred, match",
    [
        (
            np.array([[0, 1, 5]]),
            "Sample0701: segment row 0 = \\(0, 1, 5\\) has class 0",
        ),
        (np.array([[2, 1, 5], [21, 6, 9]]), "segment row 1 .* class 21"),
        (np.array([0, 3, 21, 0]), "Sample0701: predicted label 21 at frame 2"),
        (np.array([0, -1]), "predicted label -1 at frame 1"),
        (np.array([[2, 5, 5]]), "row 0 = \\(2, 5, 5\\) is empty"),
        (np.array([0.0, 1.5]), "integer labels"),
        (np.zeros((2, 4), dtype=int), "shape \\(2, 4\\)"),
    ],
)
def test_writer_refuses_unwritable_predictions(tmp_path, pred, match):
    with pytest.raises(ValueError, match=match):
        write_chalearn_predictions([pred], ["Sample0701"], tmp_path / "out")
    assert not (tmp_path / "out").exists()  # nothing written


def test_writer_argument_errors(tmp_path):
    with pytest.raises(ValueError, match="2 predictions but 1 sample ids"):
        write_chalearn_predictions([[0], [0]], ["Sample0001"], tmp_path)
    with pytest.raises(ValueError, match="duplicate"):
        write_chalearn_predictions([[0], [0]], [1, "Sample0001"], tmp_path)
    with pytest.raises(ValueError, match="not of the form"):
        write_chalearn_predictions([[0]], ["../evil"], tmp_path)
    with pytest.raises(ValueError, match="n_frames has 1 entries"):
        write_chalearn_predictions([[0], [0]], [1, 2], tmp_path, n_frames=[3])


# ============================================================================
# ChaLearn: broken files
# ============================================================================

FRAME = ",".join(["0.5"] * 180)


def _sample(folder, *, skeleton=None, labels="3,2,4\n", data="6,20,4095\n"):
    folder.mkdir(exist_ok=True)
    if skeleton is None:
        skeleton = (FRAME + "\n") * 6
    for kind, text in (("skeleton", skeleton), ("labels", labels), ("data", data)):
        if text is not None:
            (folder / f"Sample0001_{kind}.csv").write_text(text)
    return folder


def test_chalearn_small_sample_reads(tmp_path):
    data = load_chalearn(_sample(tmp_path))
    assert data.y[0].tolist() == [0, 3, 3, 3, 0, 0]
    assert data.segments[0].tolist() == [[3, 1, 4]]
    assert not data.missing[0].any()


@pytest.mark.parametrize(
    "skeleton, match",
    [
        (
            FRAME + "\n" + FRAME[:-4] + "\n",
            "Sample0001_skeleton.csv line 2: expected 180 values, got 179",
        ),
        (
            FRAME + ",0.1\n",
            "Sample0001_skeleton.csv line 1: expected 180 values, got 181",
        ),
        (
            FRAME + "\n" + FRAME.replace("0.5", "abc", 1) + "\n",
            "Sample0001_skeleton.csv line 2: value 1 \\('abc'\\) is not a number",
        ),
        (FRAME + "\n\n" + FRAME + "\n", "line 2: expected 180 values, got 0"),
        ("", "Sample0001_skeleton.csv is empty"),
        ("\n \n", "Sample0001_skeleton.csv is empty"),
    ],
)
def test_chalearn_broken_skeleton_names_file_and_line(tmp_path, skeleton, match):
    with pytest.raises(ValueError, match=match):
        load_chalearn(_sample(tmp_path, skeleton=skeleton))


@pytest.mark.parametrize(
    "labels, match",
    [
        ("3,9,4\n", "Sample0001_labels.csv line 1: start frame 9 is after end frame 4"),
        ("3,2,4\n0,5,6\n", "line 2: class 0 is outside 1..20"),
        ("21,2,4\n", "line 1: class 21 is outside 1..20"),
        ("3,0,4\n", "line 1: start frame 0 is < 1"),
        ("3,2,7\n", "line 1: end frame 7 is beyond the last frame 6"),
        ("3,2\n", "line 1: expected 3 values, got 2"),
        ("3,2.5,4\n", "line 1: value 2 \\('2.5'\\) is not an integer"),
    ],
)
def test_chalearn_broken_labels(tmp_path, labels, match):
    with pytest.raises(ValueError, match=match):
        load_chalearn(_sample(tmp_path, labels=labels))
    with pytest.raises(ValueError, match=match.split(": ", 1)[-1]):
        read_chalearn_labels(tmp_path / "Sample0001_labels.csv", n_frames=6)


@pytest.mark.parametrize(
    "data, match",
    [
        ("", "Sample0001_data.csv is empty"),
        ("6,20\n", "Sample0001_data.csv line 1: expected 3 values, got 2"),
        ("0,20,4095\n", "numFrames must be a positive integer"),
        ("6,0,4095\n", "fps must be > 0"),
    ],
)
def test_chalearn_broken_data_file(tmp_path, data, match):
    with pytest.raises(ValueError, match=match):
        load_chalearn(_sample(tmp_path, data=data))


def test_chalearn_data_file_last_line_wins(tmp_path):
    data = load_chalearn(_sample(tmp_path, data="99,20,1\n6,20,4095\n"))
    assert data.n_frames.tolist() == [6]


def test_chalearn_frame_count_mismatch_pads_or_truncates(tmp_path):
    with pytest.warns(
        DataFileWarning, match="4 frames but the data file says 6.*padded"
    ):
        short = load_chalearn(_sample(tmp_path / "a", skeleton=(FRAME + "\n") * 4))
    assert short.X[0].shape == (6, 20, 3)
    assert short.missing[0].tolist() == [False] * 4 + [True] * 2
    assert_array_equal(short.X[0][4:], 0.0)
    with pytest.warns(DataFileWarning, match="8 frames .* last 2 frame"):
        long = load_chalearn(_sample(tmp_path / "b", skeleton=(FRAME + "\n") * 8))
    assert long.X[0].shape == (6, 20, 3) and len(long.y[0]) == 6


def test_chalearn_overlapping_labels_keep_rows_later_wins(tmp_path):
    labels = "3,1,4\n5,3,6\n"  # frames 3-4 claimed twice
    with pytest.warns(
        DataFileWarning, match="line 1 \\(3,1,4\\) and line 2 \\(5,3,6\\)"
    ):
        data = load_chalearn(_sample(tmp_path, labels=labels))
    assert data.segments[0].tolist() == [[3, 0, 4], [5, 2, 6]]
    assert data.y[0].tolist() == [3, 3, 5, 5, 5, 5]


def test_chalearn_missing_data_file_warns_and_uses_skeleton(tmp_path):
    with pytest.warns(DataFileWarning, match="no Sample0001_data.csv"):
        data = load_chalearn(_sample(tmp_path, data=None))
    assert data.n_frames.tolist() == [6] and data.fps == 20.0
    assert np.isnan(data.max_depth[0])


def test_chalearn_path_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere"):
        load_chalearn(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="no ChaLearn sample"):
        load_chalearn(tmp_path / "empty")
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "Sample0001.zip").write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(ValueError, match="Sample0001.zip is not a valid zip file"):
        load_chalearn(tmp_path / "bad")
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(ValueError, match="notes.txt is neither"):
        load_chalearn(tmp_path / "notes.txt")


def test_chalearn_corrupt_zip_member_and_binary_file(tmp_path):
    folder = _sample(tmp_path / "src")
    zpath = tmp_path / "z" / "Sample0001.zip"
    zpath.parent.mkdir()
    with zipfile.ZipFile(zpath, "w", zipfile.ZIP_DEFLATED) as zf:
        for kind in ("skeleton", "labels", "data"):
            zf.write(folder / f"Sample0001_{kind}.csv", f"Sample0001_{kind}.csv")
    raw = bytearray(zpath.read_bytes())
    offset = raw.index(b"Sample0001_skeleton.csv") + len("Sample0001_skeleton.csv")
    raw[offset + 5 : offset + 25] = b"\xff" * 20  # garble the compressed stream
    zpath.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match="Sample0001.zip/Sample0001_skeleton.csv"):
        load_chalearn(zpath)
    (folder / "Sample0001_skeleton.csv").write_bytes(
        (FRAME + "\n").encode() * 2 + b"\xff\xfe\n"
    )
    with pytest.raises(ValueError, match="Sample0001_skeleton.csv line 3: not a text"):
        load_chalearn(folder)


# ============================================================================
# PRECOG
# ============================================================================


@pytest.fixture(scope="module")
def precog_csv(shared_data):
    return load_precog(shared_data / "precog_2016" / "CSV")


def test_precog_csv_matches_provenance(precog_csv):
    data = precog_csv
    _check_contract(data)
    assert len(data.X) == 48 and data.fps == 30.0
    assert sorted(np.unique(data.groups, return_counts=True)[1]) == [6] * 8
    assert_array_equal(np.unique(data.groups), np.arange(1, 9))
    assert set(np.concatenate(data.y).tolist()) == set(range(9))
    assert data.target_names[0] == "right punch" and len(data.target_names) == 8
    for sid, script, seg in zip(data.sample_ids, data.scripts, data.segments):
        assert sid.startswith(f"Seq{script}_")
        order = [c for i, c in enumerate(seg[:, 0]) if i == 0 or c != seg[i - 1, 0]]
        assert order == PRECOG_SCRIPTS[script], sid  # 5 actions, script order
        if sid == PRECOG_GLITCH:
            assert len(seg) == 6 and sorted(np.diff(seg[:, 1:]).ravel())[0] == 4
        else:
            assert len(seg) == 5, sid
    assert not np.concatenate(data.missing).any()


def test_precog_values_match_raw_text(shared_data, precog_csv):
    lines = (shared_data / "precog_2016" / "CSV" / "Seq1_1.csv").read_text()
    first = lines.splitlines()[1].split(";")
    i = precog_csv.sample_ids.index("Seq1_1")
    assert precog_csv.X[i][0, 0].tolist() == [float(v) for v in first[0].split()]
    assert precog_csv.X[i][0, 19].tolist() == [float(v) for v in first[19].split()]
    assert precog_csv.y[i][0] == int(first[20])


def test_precog_bundle_equals_csv(precog_csv):
    bundled = load_precog()
    assert bundled.sample_ids == precog_csv.sample_ids
    assert_array_equal(bundled.groups, precog_csv.groups)
    assert_array_equal(bundled.scripts, precog_csv.scripts)
    for xb, xc, yb, yc in zip(bundled.X, precog_csv.X, bundled.y, precog_csv.y):
        assert xb.dtype == np.float64
        assert_array_equal(xb, xc.astype(np.float32))  # float32 storage, exact
        assert_allclose(xb, xc, rtol=0, atol=1.2e-7)
        assert_array_equal(yb, yc)


def test_precog_bundle_without_shared_data():
    data = load_precog(subjects=[2, 5])
    _check_contract(data)
    assert data.sample_ids[:2] == ["Seq1_2", "Seq2_2"] and len(data.X) == 12
    assert set(data.groups.tolist()) == {2, 5}
    assert "David Jardim" in data.DESCR
    folder = Path(__file__).resolve().parents[1] / "skgesture" / "datasets" / "data"
    assert (folder / "precog_2016.npz").stat().st_size < 2_100_000
    assert "MIT License" in (folder / "PRECOG_LICENCE.txt").read_text()
    assert "1ff2c9de" in (folder / "PRECOG_README.md").read_text()
    with pytest.raises(ValueError, match="subject\\(s\\) \\[9\\] not in the data"):
        load_precog(subjects=[9])


PRECOG_HEADER = "; ".join(KINECT_V1.joint_names)
PRECOG_ROW = ";".join(["0.1 0.2 2.5"] * 20)


@pytest.mark.parametrize(
    "text, match",
    [
        ("", "Seq1_1.csv is empty"),
        ("HipCenter; Spine\n" + PRECOG_ROW + ";0\n", "Seq1_1.csv line 1: expected"),
        (PRECOG_HEADER + "\n", "has a header but no frame"),
        (
            PRECOG_HEADER + f"\n{PRECOG_ROW};0\n{PRECOG_ROW}\n",
            "Seq1_1.csv line 3: expected 21 ';'-separated fields",
        ),
        (PRECOG_HEADER + f"\n{PRECOG_ROW};9\n", "line 2: label 9 is not an integer"),
        (
            PRECOG_HEADER + f"\n{PRECOG_ROW.replace('0.2', 'x', 1)};1\n",
            "Seq1_1.csv line 2: value 2 \\('x'\\) is not a number",
        ),
        (
            PRECOG_HEADER + f"\n{PRECOG_ROW.replace(' 0.2', '', 1)};1\n",
            "line 2: expected 61 values, got 60",
        ),
    ],
)
def test_precog_broken_files(tmp_path, text, match):
    (tmp_path / "Seq1_1.csv").write_text(text)
    with pytest.raises(ValueError, match=match):
        load_precog(tmp_path)


def test_precog_all_zero_file_is_flagged(tmp_path):
    zero = ";".join(["0 0 0"] * 20)
    (tmp_path / "Seq2_10.csv").write_text(
        PRECOG_HEADER + f"\n{zero};0\n" * 1 + f"{zero};0\n{zero};0"
    )
    (tmp_path / "Seq1_10.csv").write_text(PRECOG_HEADER + f"\n{PRECOG_ROW};1\n")
    with pytest.warns(DataFileWarning, match="Seq2_10: every frame .* all zeros"):
        data = load_precog(tmp_path)
    assert data.sample_ids == ["Seq1_10", "Seq2_10"]
    assert data.missing[1].tolist() == [True] * 3 and not data.missing[0].any()
    assert data.groups.tolist() == [10, 10] and data.scripts.tolist() == [1, 2]


def test_precog_path_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothere"):
        load_precog(tmp_path / "nothere")
    with pytest.raises(FileNotFoundError, match="no 'Seq\\*_\\*.csv' files"):
        load_precog(tmp_path)


# ============================================================================
# MSRC-12
# ============================================================================


def test_msrc12_matches_provenance(shared_data):
    data = load_msrc12(shared_data / "msrc12_subset")
    _check_contract(data)
    assert len(data.X) == 24 and data.fps == 30.0
    assert sorted(set(data.groups.tolist())) == [1, 11]
    assert np.bincount(data.groups).tolist()[1::10] == [12, 12]
    assert (data.n_frames.min(), data.n_frames.max()) == MSRC12_FRAME_RANGE
    assert sum(len(p) for p in data.action_points) == MSRC12_ACTION_POINTS
    for sid, miss, pts, cls, lab, seg in zip(
        data.sample_ids,
        data.missing,
        data.action_points,
        data.action_classes,
        data.y,
        data.segments,
    ):
        gesture = int(sid.split("_")[2])
        assert set(cls.tolist()) == {gesture} and 9 <= len(pts) <= 15
        lead = 120 if sid == "P3_2_1_p11" else MSRC12_LEADING_ZERO_ROWS
        assert miss[:lead].all() and not miss[lead]
        assert not miss[pts].any() and np.all(np.diff(pts) > 0)
        assert not lab.any() and seg.shape == (0, 3)
    i = data.sample_ids.index(MSRC12_DROPOUT_FILE)
    assert data.missing[i].sum() == MSRC12_DROPOUT_MISSING


def test_msrc12_values_timestamps_and_action_point_rule(shared_data):
    folder = shared_data / "msrc12_subset" / "data"
    data = load_msrc12(folder)
    i = data.sample_ids.index("P3_1_1_p01")
    row = (folder / "P3_1_1_p01.csv").read_text().splitlines()[20].split()
    assert data.timestamps[i][20] == int(row[0])
    assert data.X[i][20, 0].tolist() == [float(v) for v in row[1:4]]
    assert data.X[i][20, 1].tolist() == [float(v) for v in row[5:8]]  # w skipped
    tick = int(
        (folder / "P3_1_1_p01.tagstream").read_text().splitlines()[1].split(";")[0]
    )
    t_us = (tick * 1000 + 49875 / 2) / 49875
    expected = int(np.argmin(np.abs(data.timestamps[i] - t_us)))
    assert data.action_points[i][0] == expected == 113


def test_msrc12_broken_files(tmp_path):
    row = "0 " + " ".join(["0.5 0.5 2.5 1"] * 20)
    (tmp_path / "P3_1_2_p03.csv").write_text(row + "\n" + row[:-2] + "\n")
    with pytest.raises(ValueError, match="P3_1_2_p03.csv line 2: expected 81 values"):
        load_msrc12(tmp_path)
    (tmp_path / "P3_1_2_p03.csv").write_text(row + "\n")
    (tmp_path / "P3_1_2_p03.tagstream").write_text("XQPCTick;Tag\n12;Duck\n")
    with pytest.raises(ValueError, match="P3_1_2_p03.tagstream line 2: expected"):
        load_msrc12(tmp_path)
    (tmp_path / "P3_1_2_p03.tagstream").unlink()
    with pytest.warns(DataFileWarning, match="no P3_1_2_p03.tagstream"):
        data = load_msrc12(tmp_path)
    assert data.action_points[0].size == 0


# ============================================================================
# UTKinect-Action3D
# ============================================================================


def test_utkinect_matches_provenance(shared_data):
    with pytest.warns(DataFileWarning, match="s09_e01 push 3266-3390 / pull 3316-3390"):
        data = load_utkinect(shared_data / "utkinect_action3d")
    _check_contract(data)
    assert len(data.X) == 20 and data.n_frames.sum() == UTK_ROWS
    assert (data.n_frames.min(), data.n_frames.max()) == UTK_ROW_RANGE
    assert sum(len(s) for s in data.segments) == UTK_INSTANCES
    assert np.bincount(data.groups).tolist() == [0] + [2] * 10
    i = data.sample_ids.index("s10_e02")
    assert len(data.segments[i]) == 9 and 5 not in data.segments[i][:, 0]
    assert data.target_names[4] == "carry"
    assert np.all((data.fps > 3) & (data.fps < 16))


def test_utkinect_label_rows_follow_frame_numbers(shared_data):
    folder = shared_data / "utkinect_action3d" / "joints"
    with pytest.warns(DataFileWarning):
        data = load_utkinect(folder)
    frames = [
        float(ln.split()[0])
        for ln in (folder / "joints_s01_e01.txt").read_text().splitlines()
    ]
    inside = [k for k, f in enumerate(frames) if 252 <= f <= 390]  # walk: 252 390
    walk = data.segments[0][data.segments[0][:, 0] == 1]
    assert walk.tolist() == [[1, inside[0], inside[-1] + 1]]
    assert data.frame_numbers[0].tolist() == frames
    # s01_e01: pull 1640-1686 then push 1686-1748 share frame 1686; push wins
    shared = np.flatnonzero(data.frame_numbers[0] == 1686)
    assert shared.size and np.all(data.y[0][shared] == 7)


def test_utkinect_alt_labels(shared_data):
    with pytest.warns(DataFileWarning):
        orig = load_utkinect(shared_data / "utkinect_action3d")
    with pytest.warns(DataFileWarning):
        alt = load_utkinect(shared_data / "utkinect_action3d", labels="alt")
    assert sum(len(s) for s in alt.segments) == UTK_INSTANCES
    i = orig.sample_ids.index("s03_e01")
    push_o = orig.segments[i][orig.segments[i][:, 0] == 7][0]
    push_a = alt.segments[i][alt.segments[i][:, 0] == 7][0]
    assert orig.frame_numbers[i][push_o[1]] >= 2556
    assert orig.frame_numbers[i][push_a[1]] >= 3556 > orig.frame_numbers[i][push_o[1]]
    with pytest.raises(ValueError, match="labels must be one of"):
        load_utkinect(shared_data / "utkinect_action3d", labels="fixed")


def test_utkinect_broken_files(tmp_path):
    row = " ".join(["0.5"] * 60)
    (tmp_path / "joints_s01_e01.txt").write_text(f"10 {row}\n14 {row}\n")
    names = [
        "sitDown",
        "standUp",
        "pickUp",
        "carry",
        "throw",
        "push",
        "pull",
        "waveHands",
        "clapHands",
    ]
    rest = "\n".join(f"{n}: NaN NaN" for n in names)
    for first, match in [
        ("walk: 20 10", "actionLabel.txt line 2: start 20 is after end 10"),
        ("run: 10 14", "actionLabel.txt line 2: unknown action 'run'"),
        ("walk 10 14", "actionLabel.txt line 2: expected 'sXX_eYY'"),
    ]:
        (tmp_path / "actionLabel.txt").write_text(f"s01_e01\n{first}\n{rest}\n")
        with pytest.raises(ValueError, match=match):
            load_utkinect(tmp_path)
    (tmp_path / "actionLabel.txt").write_text(f"s02_e01\nwalk: 10 14\n{rest}\n")
    with pytest.raises(ValueError, match="no labels for s01_e01"):
        load_utkinect(tmp_path)
    (tmp_path / "actionLabel.txt").write_text(f"s01_e01\nwalk: 10 14\n{rest}\n")
    (tmp_path / "joints_s01_e01.txt").write_text(f"14 {row}\n10 {row}\n")
    with pytest.raises(ValueError, match="joints_s01_e01.txt line 2: frame number"):
        load_utkinect(tmp_path)
    (tmp_path / "joints_s01_e01.txt").write_text(f"10 {row}\n14 {row} 1\n")
    with pytest.raises(ValueError, match="line 2: expected 61 values, got 62"):
        load_utkinect(tmp_path)


# ============================================================================
# MSR Action3D
# ============================================================================


@pytest.fixture(scope="module")
def msr_all(shared_data):
    with pytest.warns(DataFileWarning, match=f"{MSR_ZERO_CLIP}: every frame"):
        return load_msr_action3d(shared_data / "msr_action3d", subset="all")


def test_msr_action3d_matches_provenance(shared_data, msr_all):
    _check_contract(msr_all)
    assert len(msr_all.X) == MSR_ALL and msr_all.fps == 15.0
    lengths = msr_all.n_frames
    assert (lengths.min(), lengths.max()) == MSR_LENGTH_RANGE
    assert np.median(lengths) == MSR_MEDIAN_LENGTH
    assert_array_equal(np.unique(msr_all.groups), np.arange(1, 11))
    zero = msr_all.sample_ids.index(MSR_ZERO_CLIP)
    assert msr_all.missing[zero].all()
    assert sum(m.all() for m in msr_all.missing) == 1
    assert sum(m.any() for m in msr_all.missing) == MSR_CLIPS_WITH_GAPS
    for sid, lab, seg in zip(msr_all.sample_ids, msr_all.y, msr_all.segments):
        action = int(sid[1:3])
        assert np.all(lab == action) and seg.tolist() == [[action, 0, len(lab)]]
    cvpr = load_msr_action3d(shared_data / "msr_action3d" / "real_world_coordinates")
    assert len(cvpr.X) == MSR_CVPR12 and MSR_ZERO_CLIP not in cvpr.sample_ids
    assert sum(m.any() for m in cvpr.missing) == MSR_CVPR12_CLIPS_WITH_GAPS
    k = msr_all.sample_ids.index(cvpr.sample_ids[100])
    assert_array_equal(cvpr.X[100], msr_all.X[k])


def test_msr_action3d_reordered_to_kinect(shared_data, msr_all):
    folder = shared_data / "msr_action3d" / "real_world_coordinates"
    lines = (folder / "a01_s01_e01_skeleton3D.txt").read_text().splitlines()
    msr = np.array([[float(v) for v in ln.split()] for ln in lines[:20]])
    x = msr_all.X[0]
    assert msr_all.sample_ids[0] == "a01_s01_e01"
    named = {
        "Head": 20,
        "HipCenter": 7,
        "ShoulderLeft": 1,
        "HandRight": 13,
        "FootLeft": 18,
        "Spine": 4,
    }  # MSR 1-based numbers, PROVENANCE
    for name, msr_number in named.items():
        k = KINECT_V1.index(name)
        assert MSR_ACTION3D_TO_KINECT_V1[k] == msr_number - 1
        assert x[0, k].tolist() == msr[msr_number - 1, :3].tolist()
    assert sorted(MSR_ACTION3D_TO_KINECT_V1) == list(range(20))
    assert_array_equal(
        msr_all.joint_confidence[0][0], msr[list(MSR_ACTION3D_TO_KINECT_V1), 3]
    )
    # anatomy on every non-empty clip: head above the hips, feet lowest
    y_all = np.concatenate([c[~m] for c, m in zip(msr_all.X, msr_all.missing)])
    head, hip = KINECT_V1.index("Head"), KINECT_V1.index("HipCenter")
    feet = [KINECT_V1.index("FootLeft"), KINECT_V1.index("FootRight")]
    assert np.mean(y_all[:, head, 1] > y_all[:, hip, 1]) > 0.95
    assert np.mean(y_all[:, feet, 1].max(1) < y_all[:, hip, 1]) > 0.95


def test_msr_action3d_broken_files(tmp_path):
    line = "0.1 0.2 2.5 1\n"
    (tmp_path / "a01_s01_e01_skeleton3D.txt").write_text(line * 25)
    with pytest.raises(
        ValueError, match="a01_s01_e01_skeleton3D.txt line 21: incomplete last frame"
    ):
        load_msr_action3d(tmp_path, subset="all")
    (tmp_path / "a01_s01_e01_skeleton3D.txt").write_text(line * 19 + "0.1 0.2\n")
    with pytest.raises(ValueError, match="line 20: expected 4 values, got 2"):
        load_msr_action3d(tmp_path, subset="all")
    with pytest.raises(FileNotFoundError, match="files_used_in_cvpr12_paper.txt"):
        load_msr_action3d(tmp_path)
    with pytest.raises(ValueError, match="subset must be"):
        load_msr_action3d(tmp_path, subset="some")
    (tmp_path / "a01_s01_e01_skeleton3D.txt").write_text(line * 20)
    (tmp_path / "files_used_in_cvpr12_paper.txt").write_text("a01_s01_e01\na02_s01_e01")
    with pytest.warns(DataFileWarning, match="1 clip\\(s\\) .* absent: a02_s01_e01"):
        data = load_msr_action3d(tmp_path)
    assert data.sample_ids == ["a01_s01_e01"] and data.X[0].shape == (1, 20, 3)


# ============================================================================
# Hardening: bounded by the data present, clear errors (issue 11)
# ============================================================================


def _raises_format_error(call, file, line, match):
    """``call()`` raises DataFormatError naming ``file`` and ``line``."""
    with pytest.raises(DataFormatError, match=match) as info:
        call()
    assert info.value.file == file and info.value.line == line
    assert file in str(info.value)
    return info.value


@pytest.mark.parametrize("n_frames", ["1000000000", "1208000", "27"])
def test_chalearn_num_frames_far_from_skeleton_raises(tmp_path, n_frames):
    # 1e9 used to ask for 1.3 TiB and 1,208,000 to pad 6 frames to 2.4 GB.
    _raises_format_error(
        lambda: load_chalearn(_sample(tmp_path, data=f"{n_frames},20,4095\n")),
        "Sample0001_data.csv",
        1,
        f"numFrames {n_frames} disagrees with the 6 lines of Sample0001_skeleton.csv "
        f"by more than 20 frames",
    )


def test_chalearn_num_frames_tolerance_is_20_frames_or_5_percent(tmp_path):
    skeleton = (FRAME + "\n") * 500  # 5 % of 500 = 25 frames
    with pytest.warns(DataFileWarning, match="padded with 25 missing"):
        data = load_chalearn(
            _sample(tmp_path / "a", skeleton=skeleton, data="525,20,4095\n")
        )
    assert data.X[0].shape == (525, 20, 3)
    with pytest.raises(DataFormatError, match="by more than 25 frames"):
        load_chalearn(_sample(tmp_path / "b", skeleton=skeleton, data="526,20,4095\n"))
    with pytest.warns(DataFileWarning, match="padded with 20 missing"):
        load_chalearn(_sample(tmp_path / "c", data="26,20,4095\n"))


def test_chalearn_labels_only_num_frames_is_bounded(tmp_path):
    for name, text in (("labels", "3,2,4\n"), ("data", "1000000000,20,4095\n")):
        (tmp_path / f"Sample0001_{name}.csv").write_text(text)
    _raises_format_error(
        lambda: load_chalearn(tmp_path),
        "Sample0001_data.csv",
        1,
        "numFrames 1000000000 is more than a day at 20 fps",
    )
    (tmp_path / "Sample0001_data.csv").write_text("1208,20,4095\n")
    with pytest.warns(DataFileWarning, match="numFrames 1208 is far beyond the last"):
        data = load_chalearn(tmp_path)
    assert data.n_frames.tolist() == [1208] and len(data.y[0]) == 1208
    (tmp_path / "Sample0001_data.csv").write_text("608,20,4095\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_chalearn(tmp_path)  # within 2 x 4 + 600: no warning


@pytest.mark.parametrize(
    "token, match",
    [
        ("inf", "value 2 \\('inf'\\) is not a finite number"),
        ("-inf", "value 2 \\('-inf'\\) is not a finite number"),
        ("nan", "value 2 \\('nan'\\) is not a finite number"),
        ("1e999", "value 2 \\('1e999'\\) is not a finite number"),
        ("2e4", "world coordinate 20000 is beyond \\+-10000 m"),
    ],
)
def test_chalearn_skeleton_non_finite_or_absurd_values(tmp_path, token, match):
    bad = FRAME.replace("0.5", token, 2).replace(token, "0.5", 1)
    skeleton = (FRAME + "\n") * 2 + bad + "\n" + (FRAME + "\n") * 3
    _raises_format_error(
        lambda: load_chalearn(_sample(tmp_path, skeleton=skeleton)),
        "Sample0001_skeleton.csv",
        3,
        match,
    )


@pytest.mark.parametrize("value", ["99999999999999999999", "-9223372036854775809"])
def test_labels_beyond_int64_raise_format_error(tmp_path, value):
    # used to raise a bare OverflowError
    _raises_format_error(
        lambda: load_chalearn(_sample(tmp_path, labels=f"3,2,4\n3,{value},5\n")),
        "Sample0001_labels.csv",
        2,
        "value 2 .* is beyond the 64-bit integer range",
    )


def test_utkinect_huge_frame_number_raises(tmp_path):
    row = " ".join(["0.5"] * 60)
    (tmp_path / "joints_s01_e01.txt").write_text(f"10 {row}\n1e19 {row}\n")
    (tmp_path / "actionLabel.txt").write_text("s01_e01\nwalk: 10 14\n")
    # used to wrap to -9.2e18 silently
    _raises_format_error(
        lambda: load_utkinect(tmp_path),
        "joints_s01_e01.txt",
        2,
        "frame number 1e\\+19 is not an integer of at most 2\\*\\*53",
    )


def test_msrc12_huge_timestamp_and_tick_raise(tmp_path):
    row = " ".join(["0.5 0.5 2.5 1"] * 20)
    (tmp_path / "P3_1_2_p03.csv").write_text(f"0 {row}\n1e19 {row}\n")
    (tmp_path / "P3_1_2_p03.tagstream").write_text("XQPCTick;Tag\n12;G2 Duck\n")
    _raises_format_error(
        lambda: load_msrc12(tmp_path),
        "P3_1_2_p03.csv",
        2,
        "timestamp 1e\\+19 is not an integer",
    )
    (tmp_path / "P3_1_2_p03.csv").write_text(f"0 {row}\n33333 {row}\n")
    (tmp_path / "P3_1_2_p03.tagstream").write_text(
        "XQPCTick;Tag\n99999999999999999999;G2 Duck\n"
    )
    _raises_format_error(
        lambda: load_msrc12(tmp_path), "P3_1_2_p03.tagstream", 2, "beyond 2\\*\\*53"
    )


def test_precog_and_msr_refuse_infinite_positions(tmp_path):
    header = "; ".join(KINECT_V1.joint_names)
    frame = "; ".join(["0.1 0.2 2.5"] * 20) + "; 0"
    (tmp_path / "Seq1_1.csv").write_text(
        f"{header}\n{frame}\n{frame.replace('2.5', 'inf', 1)}\n"
    )
    _raises_format_error(
        lambda: load_precog(tmp_path), "Seq1_1.csv", 3, "value 3 \\('inf'\\)"
    )
    line = "0.1 0.2 2.5 1\n"
    (tmp_path / "a01_s01_e01_skeleton3D.txt").write_text(line * 5 + "1e300 0 0 1\n")
    _raises_format_error(
        lambda: load_msr_action3d(tmp_path, subset="all"),
        "a01_s01_e01_skeleton3D.txt",
        6,
        "coordinate 1e\\+300 is beyond",
    )


def test_data_format_error_is_a_value_error_and_pickles():
    import pickle

    exc = DataFormatError("a.csv line 3: bad", file="a.csv", line=3)
    assert isinstance(exc, ValueError)
    back = pickle.loads(pickle.dumps(exc))
    assert (type(back), str(back), back.file, back.line) == (
        DataFormatError,
        "a.csv line 3: bad",
        "a.csv",
        3,
    )


def test_writer_refuses_to_overwrite_unless_asked(tmp_path):
    (first,) = write_chalearn_predictions([np.array([0, 3, 3])], [701], tmp_path)
    with pytest.raises(FileExistsError, match="Sample0701_prediction.csv"):
        write_chalearn_predictions([np.array([0, 5, 5])], [701], tmp_path)
    assert first.read_text() == "3,2,3\n"  # untouched
    write_chalearn_predictions([np.array([0, 5, 5])], [701], tmp_path, overwrite=True)
    assert first.read_text() == "5,2,3\n"
    # nothing is written when any of the files exists
    with pytest.raises(FileExistsError, match="Sample0701_prediction.csv"):
        write_chalearn_predictions([[0], [0]], [702, 701], tmp_path)
    assert not (tmp_path / "Sample0702_prediction.csv").exists()


def test_writer_output_path_is_a_file(tmp_path):
    (tmp_path / "results").write_text("not a folder")
    with pytest.raises(NotADirectoryError, match="'.*results' is an existing file"):
        write_chalearn_predictions([[0]], [701], tmp_path / "results")
    with pytest.raises(NotADirectoryError, match="is an existing file"):
        write_chalearn_predictions([[0]], [701], tmp_path / "results" / "sub")


def test_loaders_show_progress_only_when_verbose(shared_data, capsys):
    folder = _chalearn_dir(shared_data, "v2_2014_validation_labels")
    load_chalearn(folder, samples=[471, 472])
    assert capsys.readouterr().err == ""
    load_chalearn(folder, samples=[471, 472], verbose=1)
    assert "ChaLearn samples" in capsys.readouterr().err
    load_msr_action3d(shared_data / "msr_action3d", verbose=1)
    assert "MSR Action3D clips" in capsys.readouterr().err
