"""The command line, through ``main(argv)`` and once through the console script."""

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

torch = pytest.importorskip("torch")
pytest.importorskip("skops")

import skgesture  # noqa: E402
from skgesture import load_model  # noqa: E402
from skgesture._cli import main  # noqa: E402
from skgesture.datasets import (  # noqa: E402
    make_gesture_streams,
    read_chalearn_labels,
)
from skgesture.metrics import (  # noqa: E402
    frame_accuracy,
    jaccard_index,
    jaccard_index_segments,
    per_class_report,
)
from skgesture.utils._segments import labels_to_segments  # noqa: E402

# Tiny synthetic data: 3 training streams, 3 classes; held-out streams from
# another seed. --fast with 5 epochs trains in about a second.
SYNTH = ["synthetic", "--n-sequences", "3", "--n-classes", "3"]
HELD_OUT = SYNTH[:2] + ["2", "--n-classes", "3", "--data-seed", "1"]
TINY = ["--fast", "--max-epochs", "5", "-q"]


def run(argv, capsys):
    """``(status, stdout, stderr)`` of ``skgesture argv``."""
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def _assert_one_line_error(status, err, match):
    assert status == 1
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("skgesture ") and "error:" in lines[0]
    assert match in lines[0], lines[0]


@pytest.fixture(scope="module")
def model_b(tmp_path_factory):
    path = tmp_path_factory.mktemp("cli") / "b.skg"
    with torch.random.fork_rng(devices=[]):
        assert main(["train", *SYNTH, "--method", "B", *TINY, "-o", str(path)]) == 0
    return path


@pytest.fixture(scope="module")
def held_out():
    return make_gesture_streams(n_sequences=2, n_classes=3, random_state=1)


# -- the program -----------------------------------------------------------------


def test_version_and_help(capsys):
    status, out, _ = run(["--version"], capsys)
    assert status == 0 and out.strip() == f"skgesture {skgesture.__version__}"
    status, out, _ = run(["--help"], capsys)
    assert status == 0
    for command in ("train", "evaluate", "predict", "plot", "stream", "demo"):
        assert command in out
    status, _, err = run([], capsys)
    assert status == 2 and "give a command" in err


def test_console_script_and_module():
    script = Path(sys.executable).parent / "skgesture"
    if not script.exists():
        script = shutil.which("skgesture")
    if script is None:
        pytest.skip("the skgesture console script is not installed")
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    out = subprocess.run(
        [str(script), "--version"], capture_output=True, text=True, env=env
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"skgesture {skgesture.__version__}"
    out = subprocess.run(
        [sys.executable, "-m", "skgesture", "--help"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert out.returncode == 0, out.stderr
    assert "evaluate" in out.stdout


# -- train, evaluate, predict ----------------------------------------------------------


def test_train_writes_a_safe_model_file(model_b):
    from skgesture._persistence import model_info

    info = model_info(model_b)
    assert info["metadata"]["method"] == "B"
    assert info["metadata"]["target_names"] == [
        "gesture_01",
        "gesture_02",
        "gesture_03",
    ]
    assert info["input"]["frame_shape"] == [20, 3]
    with zipfile.ZipFile(model_b) as zf:
        assert sorted(zf.namelist()) == [
            "estimator.skops",
            "manifest.json",
            "weights.safetensors",
        ]


def test_evaluate_json_matches_the_api(model_b, held_out, capsys):
    status, out, err = run(["evaluate", model_b, *HELD_OUT, "--json", "-q"], capsys)
    assert status == 0, err
    scores = json.loads(out)
    pred = load_model(model_b).predict(held_out.X)
    assert scores["jaccard"]["official_2014"] == pytest.approx(
        jaccard_index(held_out.y, pred)
    )
    assert scores["jaccard"]["fp_penalised"] == pytest.approx(
        jaccard_index(held_out.y, pred, mode="fp_penalised")
    )
    assert scores["frame_accuracy"] == pytest.approx(frame_accuracy(held_out.y, pred))
    assert set(scores["f1"]) == {"10", "25", "50"}
    assert [row["class"] for row in scores["per_class"]] == [0, 1, 2, 3]
    rest = scores["per_class"][0]
    assert rest["name"] == "rest"
    assert rest["frames"] == sum(int((y == 0).sum()) for y in held_out.y)


def test_evaluate_per_class_table_is_the_metrics_report(model_b, held_out, capsys):
    """The per-class rows (JSON and text) are skgesture.metrics.per_class_report."""
    status, out, err = run(["evaluate", model_b, *HELD_OUT, "--json", "-q"], capsys)
    assert status == 0, err
    rows = json.loads(out)["per_class"]
    pred = load_model(model_b).predict(held_out.X)
    report = per_class_report(held_out.y, pred, labels=[0, 1, 2, 3])
    assert [row["class"] for row in rows] == report.labels.tolist()
    assert [row["frames"] for row in rows] == report.support.tolist()
    for key in ("precision", "recall", "f1"):
        assert [row[key] for row in rows] == report[key].tolist(), key
    assert [row["gestures_true"] for row in rows] == [
        None,
        *report.true_gestures[1:].tolist(),
    ]
    assert [row["gestures_predicted"] for row in rows] == [
        None,
        *report.predicted_gestures[1:].tolist(),
    ]
    status, out, err = run(["evaluate", model_b, *HELD_OUT, "-q"], capsys)
    assert status == 0, err
    table = out.splitlines()[out.splitlines().index("") + 2 :]
    assert len(table) == len(rows)
    for line, k in zip(table, range(len(report.labels))):
        values = line.split()
        assert int(values[0]) == report.labels[k]
        assert int(values[2]) == report.support[k]
        assert [float(v) for v in values[3:6]] == pytest.approx(
            [report.precision[k], report.recall[k], report.f1[k]], abs=5e-4
        )


def test_evaluate_prints_a_table(model_b, capsys):
    status, out, err = run(["evaluate", model_b, *HELD_OUT], capsys)
    assert status == 0
    assert "Jaccard index (official 2014)" in out and "gesture_02" in out
    assert "predicting" in err  # the progress bar, on stderr


def test_predict_intervals_read_back(model_b, held_out, tmp_path, capsys):
    out_dir = tmp_path / "pred"
    status, out, err = run(["predict", model_b, *HELD_OUT, "-o", out_dir, "-q"], capsys)
    assert status == 0, err
    from skgesture.datasets import read_intervals

    pred = load_model(model_b).predict(held_out.X)
    for sid, p in zip(held_out.sample_ids, pred):
        rows = read_intervals(out_dir / f"{sid}.labels.csv")
        assert_array_equal(np.asarray(rows).reshape(-1, 3), labels_to_segments(p))
    assert (out_dir / "classes.txt").read_text().split() == [
        "gesture_01",
        "gesture_02",
        "gesture_03",
    ]
    # a second run does not overwrite silently
    status, _, err = run(["predict", model_b, *HELD_OUT, "-o", out_dir, "-q"], capsys)
    _assert_one_line_error(status, err, "--overwrite")
    status, _, _ = run(
        ["predict", model_b, *HELD_OUT, "-o", out_dir, "-q", "--overwrite"], capsys
    )
    assert status == 0


def test_predict_frames(model_b, held_out, tmp_path, capsys):
    status, _, err = run(
        ["predict", model_b, *HELD_OUT, "-o", tmp_path, "--as", "frames", "-q"],
        capsys,
    )
    assert status == 0, err
    pred = load_model(model_b).predict(held_out.X)
    table = np.loadtxt(
        tmp_path / f"{held_out.sample_ids[0]}.frames.csv",
        delimiter=",",
        skiprows=1,
        dtype=int,
    )
    assert_array_equal(table[:, 0], np.arange(len(pred[0])))
    assert_array_equal(table[:, 1], pred[0])


def test_round_trip_on_own_recordings(tmp_path, capsys):
    # A folder of the user's own recordings: one CSV per take, its intervals
    # next to it, class names in classes.txt.
    from skgesture.datasets import write_intervals

    data = make_gesture_streams(n_sequences=4, n_classes=3, random_state=3)
    folder = tmp_path / "takes"
    folder.mkdir()
    for k, (x, y) in enumerate(zip(data.X, data.y)):
        np.savetxt(folder / f"take{k}.csv", x.reshape(len(x), -1), delimiter=",")
        write_intervals(folder / f"take{k}.labels.csv", y)
    (folder / "classes.txt").write_text("wave\npoint\nstop\n")
    model = tmp_path / "own.skg"
    with torch.random.fork_rng(devices=[]):
        status, out, err = run(["train", folder, *TINY, "-o", model], capsys)
    assert status == 0, err
    status, out, err = run(["evaluate", model, folder, "--json", "-q"], capsys)
    assert status == 0, err
    names = [row["name"] for row in json.loads(out)["per_class"]]
    assert names == ["rest", "wave", "point", "stop"]
    status, out, err = run(
        ["predict", model, folder, "-o", tmp_path / "p", "-q"], capsys
    )
    assert status == 0, err
    assert sorted(p.name for p in (tmp_path / "p").glob("*.labels.csv")) == [
        f"take{k}.labels.csv" for k in range(4)
    ]


@pytest.mark.slow
def test_round_trip_on_precog(tmp_path, capsys):
    model = tmp_path / "precog.skg"
    with torch.random.fork_rng(devices=[]):
        status, _, err = run(
            ["train", "precog", "--subjects", "1-2", "--method", "C", *TINY]
            + ["-o", model],
            capsys,
        )
    assert status == 0, err
    status, out, err = run(
        ["evaluate", model, "precog", "--subjects", "8", "--json", "-q"], capsys
    )
    assert status == 0, err
    scores = json.loads(out)
    assert scores["n_sequences"] == 6
    assert 0 <= scores["jaccard"]["official_2014"] <= 1
    status, out, err = run(
        ["predict", model, "precog", "--subjects", "8", "-o", tmp_path / "p", "-q"],
        capsys,
    )
    assert status == 0, err
    assert len(list((tmp_path / "p").glob("*.labels.csv"))) == 6


@pytest.mark.slow
def test_round_trip_on_chalearn_samples(shared_data, tmp_path, capsys):
    folder = shared_data / "chalearn_montalbano" / "v2_2014_samples"
    if not folder.is_dir():
        pytest.skip(f"{folder} not present")
    model = tmp_path / "chalearn.skg"
    with torch.random.fork_rng(devices=[]):
        status, _, err = run(
            ["train", folder, "--method", "C", *TINY, "-o", model], capsys
        )
    assert status == 0, err
    status, out, err = run(["evaluate", model, folder, "--json", "-q"], capsys)
    assert status == 0, err
    reported = json.loads(out)["jaccard"]["official_2014"]
    status, _, err = run(["predict", model, folder, "-o", tmp_path / "p", "-q"], capsys)
    assert status == 0, err

    # The official score of the written prediction files against the label
    # files is the score `evaluate` reported.
    def lines(path):  # the file's 1-based inclusive lines
        seg = read_chalearn_labels(path).reshape(-1, 3)
        return np.column_stack([seg[:, 0], seg[:, 1] + 1, seg[:, 2]])

    scores = []
    for sid in ("Sample0101", "Sample0470"):
        truth = lines(folder / f"{sid}_labels.csv")
        pred = lines(tmp_path / "p" / f"{sid}_prediction.csv")
        n_frames = int((folder / f"{sid}_data.csv").read_text().split(",")[0])
        scores.append(jaccard_index_segments(truth, pred, n_frames))
    assert reported == pytest.approx(np.mean(scores))


# -- user mistakes: one line, non-zero status, no traceback --------------------------


def _copy_with_manifest(src, dst, **changes):
    with zipfile.ZipFile(src) as zf:
        members = {n: zf.read(n) for n in zf.namelist()}
    manifest = json.loads(members["manifest.json"])
    for key, value in changes.items():
        manifest[key] = value
    members["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(dst, "w") as zf:
        for name, blob in members.items():
            zf.writestr(name, blob)
    return dst


def test_missing_data_folder(tmp_path, capsys):
    status, _, err = run(["train", tmp_path / "nope", "-o", tmp_path / "m.skg"], capsys)
    _assert_one_line_error(status, err, "no such file or folder")


def test_empty_recordings_folder(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    status, _, err = run(
        ["train", tmp_path / "empty", "-q", "-o", tmp_path / "m.skg"], capsys
    )
    _assert_one_line_error(status, err, "empty")


def test_missing_model_file(tmp_path, capsys):
    status, _, err = run(["evaluate", tmp_path / "nope.skg", *SYNTH], capsys)
    _assert_one_line_error(status, err, "does not exist")


@pytest.mark.parametrize(
    "content, match",
    [
        (b"class,start,end\n1,2,40\n", "not a skgesture model file"),
        ("truncated", "damaged"),
    ],
)
def test_wrong_or_corrupt_model_file(model_b, tmp_path, capsys, content, match):
    path = tmp_path / "bad.skg"
    if content == "truncated":
        content = model_b.read_bytes()[:1000]
    path.write_bytes(content)
    status, _, err = run(["evaluate", path, *SYNTH, "-q"], capsys)
    _assert_one_line_error(status, err, match)


def test_unknown_method(tmp_path, capsys):
    status, _, err = run(["train", *SYNTH, "--method", "D"], capsys)
    assert status == 2 and "invalid choice: 'D'" in err and "Traceback" not in err


def test_recommended_method_when_missing(tmp_path, capsys):
    if hasattr(skgesture, "make_recommended"):
        pytest.skip("make_recommended exists")
    status, _, err = run(
        ["train", *SYNTH, "--method", "recommended", "-o", tmp_path / "m.skg"], capsys
    )
    _assert_one_line_error(status, err, "not available")


def test_model_from_another_version(model_b, tmp_path, capsys):
    old = _copy_with_manifest(model_b, tmp_path / "old.skg", skgesture_version="9.9.0")
    status, _, err = run(["evaluate", old, *HELD_OUT, "-q"], capsys)
    _assert_one_line_error(status, err, "written by skgesture 9.9.0")
    status, out, err = run(
        ["evaluate", old, *HELD_OUT, "-q", "--allow-version-mismatch"], capsys
    )
    assert status == 0 and "Jaccard" in out
    assert "skgesture: warning:" in err and "9.9.0" in err


def test_model_for_another_layout(model_b, tmp_path, capsys):
    info = {"frame_shape": [33, 3], "layout": "mediapipe", "joints": None}
    other = _copy_with_manifest(model_b, tmp_path / "other.skg", input=info)
    status, _, err = run(["evaluate", other, *HELD_OUT, "-q"], capsys)
    _assert_one_line_error(status, err, "expects frames of shape (33, 3)")


def test_unknown_subject(capsys):
    status, _, err = run(["evaluate", "m.skg", "precog", "--subjects", "99"], capsys)
    _assert_one_line_error(status, err, "99 not in PRECOG")


def test_train_refuses_to_overwrite(model_b, capsys):
    status, _, err = run(["train", *SYNTH, "-o", model_b], capsys)
    _assert_one_line_error(status, err, "--overwrite")


def test_traceback_flag_shows_the_error(tmp_path):
    with pytest.raises(FileNotFoundError):
        main(["--traceback", "evaluate", str(tmp_path / "nope.skg"), *SYNTH])


# -- plot, stream, demo ---------------------------------------------------------------


@pytest.mark.parametrize(
    "kind, suffix, magic",
    [
        ("timeline", ".png", b"\x89PNG"),
        ("segmentation", ".png", b"\x89PNG"),
        ("confusion", ".svg", b"<?xml"),
        ("skeleton", ".png", b"\x89PNG"),
    ],
)
def test_plot(model_b, tmp_path, capsys, kind, suffix, magic):
    pytest.importorskip("matplotlib")
    path = tmp_path / f"{kind}{suffix}"
    argv = ["plot", kind, *HELD_OUT, "-o", path, "-q"]
    if kind != "skeleton":
        argv += ["--model", model_b]
    status, out, err = run(argv, capsys)
    assert status == 0, err
    assert path.read_bytes().startswith(magic)
    assert str(path) in out


def test_plot_needs_a_model(tmp_path, capsys):
    status, _, err = run(["plot", "timeline", *SYNTH, "-o", tmp_path / "t.png"], capsys)
    _assert_one_line_error(status, err, "needs --model")


def test_stream_prints_events_with_delays(model_b, held_out, capsys):
    from skgesture.streaming import StreamingRecognizer

    status, out, err = run(["stream", model_b, *HELD_OUT, "-q"], capsys)
    assert status == 0, err
    expected = StreamingRecognizer(load_model(model_b)).recognize(held_out.X[0])
    lines = [line for line in out.splitlines() if "delay" in line and "frame " in line]
    assert len(lines) == len(expected)
    for line, ev in zip(lines, expected):
        assert f"frame {ev.emitted_at:6d}" in line
        assert f"delay {ev.delay} frames" in line
    assert f"{len(expected)} events" in out.splitlines()[-1]


def test_stream_drives_the_robot(model_b, capsys):
    status, out, err = run(
        ["stream", model_b, *HELD_OUT, "--robot", "--commands", "1,2,3,1,2", "-q"],
        capsys,
    )
    assert status == 0, err
    assert "robot:" in out and out.splitlines()[-1].startswith("robot: ")
    status, _, err = run(
        ["stream", model_b, *HELD_OUT, "--robot", "--commands", "1,2", "-q"], capsys
    )
    _assert_one_line_error(status, err, "needs 5 gesture classes")


@pytest.mark.slow
def test_demo(capsys):
    with torch.random.fork_rng(devices=[]):
        status, out, err = run(["demo", "--method", "C", *TINY], capsys)
    assert status == 0, err
    assert "PRECOG" in out and "held-out subjects 7-8" in out
    assert "Jaccard index (official 2014)" in out
