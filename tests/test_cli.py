"""The command line, through ``main(argv)`` and once through the console script."""

import io
import json
import os
import queue
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import threading
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


def _python_env():
    """The environment of a ``python -m skgesture`` child: this checkout, quiet."""
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    root = str(Path(skgesture.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [root, env.get("PYTHONPATH")]))
    return env


@pytest.mark.parametrize(
    "argv, prog, given, closest",
    [
        (["train", *SYNTH, "--data", "3"], "skgesture train", "--data", "--data-seed"),
        (["train", "synthetic", "--n-seq", "3"], "skgesture train", "--n-seq", None),
        (["train", "synthetic", "--n-seq=3"], "skgesture train", "--n-seq", None),
        (
            ["evaluate", "m.skg", "synthetic", "--jsn"],
            "skgesture evaluate",
            "--jsn",
            None,
        ),
        (
            ["stream", "m.skg", "synthetic", "--real"],
            "skgesture stream",
            "--real",
            None,
        ),
        (["--tracebak", "-q"], "skgesture", "--tracebak", "--traceback"),
    ],
)
def test_options_are_not_abbreviated(tmp_path, capsys, argv, prog, given, closest):
    """A prefix of an option is an unknown option, with the closest suggested
    under the subcommand's own usage (status 2, no traceback)."""
    closest = (
        closest
        or {
            "--n-seq": "--n-sequences",
            "--jsn": "--json",
            "--real": "--realtime",
        }[given]
    )
    if argv[0] != "--tracebak":
        argv = [*argv, "-o", tmp_path / "m.skg", *TINY]
    status, out, err = run(argv, capsys)
    assert status == 2, (out, err)
    assert "Traceback" not in err
    assert err.startswith(f"usage: {prog} [-h]"), err
    last = err.rstrip().splitlines()[-1]
    assert last == f"{prog}: error: unknown option {given}; did you mean {closest}?"
    assert not (tmp_path / "m.skg").exists()


def test_no_parser_takes_abbreviations():
    from skgesture._cli import build_parser

    parser = build_parser()
    assert parser.allow_abbrev is False
    assert set(parser.commands) == {
        "train",
        "evaluate",
        "predict",
        "plot",
        "stream",
        "demo",
    }
    assert all(p.allow_abbrev is False for p in parser.commands.values())


def test_unknown_argument_without_a_close_option(capsys):
    status, _, err = run(["train", "synthetic", "-x"], capsys)
    assert status == 2
    assert err.rstrip().splitlines()[-1] == "skgesture train: error: unknown option -x"
    status, _, err = run(["train", "synthetic", "more"], capsys)
    assert status == 2
    assert err.rstrip().splitlines()[-1].endswith("unrecognized arguments: more")


def test_broken_pipe_exits_quietly(model_b):
    """`skgesture ... | head -1`: the reader goes away; no traceback, status 141.

    Buffered output meets the closed pipe when it is flushed (at the end),
    unbuffered output (PYTHONUNBUFFERED) at its first line.
    """
    evaluate = ["evaluate", str(model_b), *HELD_OUT]
    for argv, buffered in [(evaluate, True), (evaluate, False), (["--help"], True)]:
        env = _python_env()
        env.pop("PYTHONUNBUFFERED", None)
        if not buffered:
            env["PYTHONUNBUFFERED"] = "1"
        proc = subprocess.Popen(
            [sys.executable, "-m", "skgesture", *argv],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
        )
        proc.stdout.close()  # the reader closes before the first line comes
        err = proc.stderr.read().decode()
        proc.stderr.close()
        assert proc.wait() == 141, (argv, buffered, err)
        assert "Traceback" not in err and "Exception ignored" not in err, err
        assert "error" not in err.lower() and "pipe" not in err.lower(), err


def test_progress_bars_are_plain_lines_in_a_log(tmp_path):
    """stderr no terminal: every bar (the loader's, the networks' epochs) is
    written as whole lines, never redrawn with a carriage return."""
    proc = subprocess.run(
        [sys.executable, "-m", "skgesture", "train", *SYNTH, "--method", "B"]
        + ["--fast", "--max-epochs", "5", "-o", str(tmp_path / "m.skg")],
        capture_output=True,
        text=False,
        env=_python_env(),
    )
    err = proc.stderr.decode()
    assert proc.returncode == 0, err
    assert "\r" not in err and "\x1b" not in err, repr(err)
    assert re.search(r"epoch", err), err  # the networks' bars, as lines
    assert "training method B" in err
    # --fast says what the quick model gives up, before it trains
    assert "--fast: networks of one 32-unit layer" in err, err
    assert err.index("--fast:") < err.index("epoch"), err


def test_progress_lines_of_nested_bars():
    from tqdm import tqdm

    from skgesture._cli_support import ProgressLines

    clock = [0.0]
    out = io.StringIO()
    lines = ProgressLines(out, interval=10, clock=lambda: clock[0])
    options = {
        "file": lines,
        "mininterval": 0,
        "bar_format": "{desc}: {n}/{total} [{rate_fmt}]",
    }
    for _ in tqdm(range(2), desc="scales", **options):
        for _ in tqdm(range(6), desc="epochs", leave=False, **options):
            clock[0] += 3  # a line at most every 10 s
    print("done", file=lines)
    lines.finish()
    text = out.getvalue()
    assert "\r" not in text and "\x1b" not in text
    got = [line.split(" [")[0] for line in text.splitlines()]
    assert got == [
        "scales: 0/2",
        "epochs: 0/6",
        "epochs: 4/6",  # 12 s later
        "epochs: 6/6",  # cleared: the last state
        "scales: 1/2",
        "epochs: 0/6",
        "epochs: 4/6",
        "epochs: 6/6",
        "scales: 2/2",  # once, though closing redraws it
        "done",
    ]


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


def test_train_defaults_to_the_recommended_model_on_the_data_joints(tmp_path, capsys):
    """No --method, no --joints: make_recommended on the 20 joints every loader
    gives (README, docs/choosing.md)."""
    path = tmp_path / "default.skg"
    with torch.random.fork_rng(devices=[]):
        status, out, err = run(["train", *SYNTH, *TINY, "-o", path], capsys)
    assert status == 0, err
    assert "trained method recommended" in out
    from skgesture._persistence import model_info

    meta = model_info(path)["metadata"]
    assert (meta["method"], meta["joints"]) == ("recommended", "full20")
    model = load_model(path)
    assert [name for name, _ in model.steps] == ["features", "tagger"]
    assert model.named_steps["features"].joints == "full20"
    assert model.named_steps["tagger"].architecture == "tcn"
    status, out, _ = run(["train", "--help"], capsys)
    assert status == 0
    assert re.search(r"make_recommended;\s+the default", out), out


def test_default_joints_are_those_the_data_track():
    from sklearn.utils import Bunch

    from skgesture._cli_support import UsageError, _data_joints
    from skgesture.layouts import KINECT_V1, PAPER_11

    X = make_gesture_streams(n_sequences=2, n_classes=3, random_state=0).X
    assert _data_joints(Bunch(X=X)) == "full20"
    legs = [
        KINECT_V1.index(n) for n in KINECT_V1.joint_names if n not in PAPER_11.joints
    ]
    seated = [x.copy() for x in X]
    for x in seated:
        x[:, legs] = 0.0  # Kinect's seated mode: no legs
    seated[1][:, legs] = np.nan
    assert _data_joints(Bunch(X=seated)) == "paper11"
    seated[0][:, KINECT_V1.index("Head")] = 0.0
    seated[1][:, KINECT_V1.index("Head")] = 0.0
    with pytest.raises(UsageError, match="never track .*Head"):
        _data_joints(Bunch(X=seated))


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
        path = out_dir / f"{sid}.labels.csv"
        rows = read_intervals(path, classes=out_dir / "classes.txt")
        assert_array_equal(np.asarray(rows).reshape(-1, 3), labels_to_segments(p))
        if len(p.nonzero()[0]):  # the model's class names, as the data name them
            assert "gesture_0" in path.read_text()
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


def test_round_trip_on_own_recordings(tmp_path, capsys, monkeypatch):
    """A folder of the user's own recordings (20 fps): one CSV per take, its
    intervals next to it labelled by class names, the names in classes.txt.
    --fps reaches the model file and, from it, the figures; predictions on
    new takes (no annotations) are written with the names and read back."""
    from skgesture._persistence import model_info
    from skgesture.datasets import read_intervals, write_intervals

    data = make_gesture_streams(n_sequences=4, n_classes=3, random_state=3)
    names = ["wave", "point", "stop"]
    folder, new_takes = tmp_path / "takes", tmp_path / "new"
    folder.mkdir()
    new_takes.mkdir()
    for k, (x, y) in enumerate(zip(data.X, data.y)):
        np.savetxt(folder / f"take{k}.csv", x.reshape(len(x), -1), delimiter=",")
        write_intervals(folder / f"take{k}.labels.csv", y, classes=names)
        shutil.copy(folder / f"take{k}.csv", new_takes / f"take{k}.csv")
    (folder / "classes.txt").write_text("wave\npoint\nstop\n")
    model = tmp_path / "own.skg"
    with torch.random.fork_rng(devices=[]):
        status, out, err = run(
            ["train", folder, "--fps", "20", *TINY, "-o", model], capsys
        )
    assert status == 0, err
    assert model_info(model)["metadata"]["fps"] == 20.0  # not the loader's 30
    status, out, err = run(["evaluate", model, folder, "--json", "-q"], capsys)
    assert status == 0, err
    names_out = [row["name"] for row in json.loads(out)["per_class"]]
    assert names_out == ["rest", "wave", "point", "stop"]
    saved = _savefig_spy(monkeypatch)
    status, _, err = run(
        ["plot", "timeline", folder, "--model", model, "-o", tmp_path / "t.png"],
        capsys,
    )
    assert status == 0, err
    n_frames = max(len(x) for x in data.X)
    assert saved[-1].axes[0].get_xlim()[1] == pytest.approx(n_frames / 20)
    status, out, err = run(
        ["predict", model, new_takes, "-o", tmp_path / "p", "-q"], capsys
    )
    assert status == 0, err
    pred_dir = tmp_path / "p"
    assert sorted(p.name for p in pred_dir.glob("*.labels.csv")) == [
        f"take{k}.labels.csv" for k in range(4)
    ]
    assert (pred_dir / "classes.txt").read_text().split() == names
    pred = load_model(model).predict(data.X)
    assert any(len(labels_to_segments(p)) for p in pred)
    for k, p in enumerate(pred):
        path = pred_dir / f"take{k}.labels.csv"
        labels = [line.rsplit(",", 1)[1] for line in path.read_text().split()[1:]]
        assert set(labels) <= set(names)  # names, as the input had
        rows = read_intervals(path, classes=pred_dir / "classes.txt")
        assert_array_equal(rows, labels_to_segments(p))


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


def test_a_model_that_cannot_stream_is_one_line(model_b, tmp_path, capsys):
    """A TypeError of the library's validation is a user mistake."""
    from sklearn.pipeline import Pipeline

    from skgesture import save_model

    segmenter_only = Pipeline(load_model(model_b).steps[:2])  # no classifier
    path = save_model(segmenter_only, tmp_path / "segmenter.skg")
    status, _, err = run(["stream", path, *HELD_OUT, "-q"], capsys)
    _assert_one_line_error(status, err, "gives no gesture segments")


@pytest.mark.parametrize("device", ["bogus", "cuda"])
def test_unusable_device(tmp_path, capsys, device):
    """Checked before training: torch's own errors (RuntimeError, AssertionError)
    would come in the first epoch and read like a bug."""
    if device == "cuda" and torch.cuda.is_available():
        pytest.skip("CUDA is available here")
    status, _, err = run(
        ["train", *SYNTH, *TINY, "--device", device, "-o", tmp_path / "m.skg"], capsys
    )
    _assert_one_line_error(status, err, f"--device {device}")
    assert not (tmp_path / "m.skg").exists()


def test_a_bug_shows_its_traceback(monkeypatch, capsys):
    """A TypeError that no validation raised (here: a helper returning None)
    is a bug: it propagates, as every error that is no user mistake."""
    import skgesture._cli_commands as commands

    monkeypatch.setattr(commands, "_n_frames", lambda data: None)
    with pytest.raises(TypeError, match="NoneType"):
        main(["train", *SYNTH, *TINY, "-o", "never-written.skg"])
    assert not Path("never-written.skg").exists()


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


def test_stream_delays_are_within_the_printed_bound(model_b, capsys):
    """Method B: the gestures that end early in a long activity period wait for
    it to be known long, beyond max_delay (21; 49 frames in this sequence); the
    printed bound says so."""
    status, out, err = run(
        ["stream", model_b, *HELD_OUT, "--sequence", "1", "-q"], capsys
    )
    assert status == 0, err
    bound = int(re.search(r"events come at most (\d+) frames", out).group(1))
    delays = [int(d) for d in re.findall(r"delay (\d+) frames \(", out)]
    assert delays, out
    assert max(delays) <= bound, out
    assert bound == 11 + 55 - 1  # lookahead + short_length - 1 (docs/streaming.md)
    assert "first 55 frames of a longer activity period" in out


def test_stream_drives_the_robot(model_b, tmp_path, capsys):
    # The model has 3 classes: a command file gives them 3 of the robot's commands.
    commands = tmp_path / "robot.json"
    commands.write_text(json.dumps({"commands": {
        "1": "move_to_tool", "2": "close_gripper", "3": "carry_tool"}}))  # fmt: skip
    base = ["stream", model_b, *HELD_OUT, "--robot", "-q"]
    status, out, err = run([*base, "--commands", commands], capsys)
    assert status == 0, err
    assert "robot:" in out and out.splitlines()[-1].startswith("robot: ")
    # Duplicate, unknown and missing classes are errors, not silently accepted.
    for bad, match in [
        ("1,2", "needs 5 gesture classes"),
        ("1,1,1,1,1", "class 1 is given twice"),
        ("1,2,3,4,9", "class 4 is not a class of the model"),
    ]:
        status, _, err = run([*base, "--commands", bad], capsys)
        _assert_one_line_error(status, err, match)
    status, _, err = run(base, capsys)  # 3 classes, 5 commands
    _assert_one_line_error(status, err, "give a command file")


def test_stream_publishes_commands_as_json_lines(model_b, tmp_path, capsys):
    commands = tmp_path / "vocabulary.toml"
    commands.write_text('[commands]\n1 = "stop"\n2 = "go"\n3 = "wave"\n')
    base = ["stream", model_b, *HELD_OUT, "-q", "--commands"]
    argv = [*base, commands, "--publish", "stdout", "--min-confidence", "0"]
    status, out, err = run(argv, capsys)
    assert status == 0, err
    messages = [json.loads(line) for line in out.splitlines()]
    assert messages, err
    assert all(m["type"] == "command" for m in messages)
    assert {m["command"] for m in messages} <= {"stop", "go", "wave"}
    assert re.search(r"^\d+ events", err, re.M)  # the human lines went to stderr
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"commands": {"7": "stop"}}))
    status, _, err = run([*base, bad], capsys)
    _assert_one_line_error(status, err, "class 7 is not a class of the model")
    status, _, err = run([*base, commands, "--publish", "udp://nowhere"], capsys)
    _assert_one_line_error(status, err, "expected udp://HOST:PORT")


def _event_lines(out):
    """The event lines and the closing summary of ``skgesture stream``."""
    lines = out.splitlines()
    events = [line for line in lines if "delay" in line and "frame " in line]
    summary = [line for line in lines if re.match(r"\d+ events", line)]
    return events, summary


def _csv_rows(frames):
    """One CSV row per frame, exact (``repr`` of each float; NaN as ``nan``)."""
    return [",".join(map(repr, f.ravel().tolist())) + "\n" for f in frames]


SOCKET_TIMEOUT = 5.0  # seconds, every socket and thread of the live tests


def test_stream_live_udp_gives_the_events_of_replay(
    model_b, held_out, capsys, monkeypatch
):
    """``stream --source udp://127.0.0.1:0`` with a sender thread on 127.0.0.1
    sending sequence 0 as JSON datagrams prints the events of the replay of the
    same frames. Port 0: the source binds a free port (the CLI prints it); the
    test learns it from the UDPSource the CLI makes. At most 32 datagrams in
    flight, so that loopback drops none."""
    from skgesture import streaming

    status, out, err = run(["stream", model_b, *HELD_OUT, "-q"], capsys)
    assert status == 0, err
    replay_events, replay_summary = _event_lines(out)
    assert replay_events

    made, window, sources = queue.Queue(), threading.Semaphore(32), []

    class Recorded(streaming.UDPSource):
        def __init__(self, *a, **k):
            super().__init__(*a, **k)
            sources.append(self)
            made.put(self)

        def frames(self):
            for frame in super().frames():
                yield frame
                window.release()

    monkeypatch.setattr(streaming, "UDPSource", Recorded)
    frames = held_out.X[0]
    failures = []

    def send():
        try:
            address = made.get(timeout=SOCKET_TIMEOUT).bound_address
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
                sock.settimeout(SOCKET_TIMEOUT)
                for k, frame in enumerate(frames):
                    if not window.acquire(timeout=SOCKET_TIMEOUT):
                        raise TimeoutError("the receiver stopped reading")
                    message = {"t": k / held_out.fps}
                    if np.isfinite(frame).all() and frame.any():
                        message["joints"] = frame.tolist()
                    else:
                        message["tracked"] = False
                    sock.sendto(json.dumps(message).encode(), address)
        except Exception as exc:  # reported by the test, not lost in the thread
            failures.append(exc)

    thread = threading.Thread(target=send, daemon=True)
    thread.start()
    argv = ["stream", model_b, "--source", "udp://127.0.0.1:0", "--timeout", "0.5"]
    status, out, err = run(argv + ["-q"], capsys)
    thread.join(SOCKET_TIMEOUT)
    assert not thread.is_alive() and not failures, failures
    assert status == 0, err
    port = sources[0].bound_address[1]
    assert out.startswith(f"streaming udp://127.0.0.1:{port} (kinect_v1 layout, 20")
    assert _event_lines(out) == (replay_events, replay_summary)
    assert f"{len(frames)} frames, 0 of them untracked" in out


def test_stream_live_stdin_gives_the_events_of_replay(
    model_b, held_out, capsys, monkeypatch
):
    """CSV rows on stdin (``--source -``, or DATA ``-``) until its end."""
    status, out, err = run(["stream", model_b, *HELD_OUT, "--sequence", "1"], capsys)
    assert status == 0, err
    replay = _event_lines(out)
    assert replay[0]
    rows = ["# x, y, z of the 20 Kinect v1 joints\n", *_csv_rows(held_out.X[1])]
    for argv in (["--source", "-"], ["-"]):
        monkeypatch.setattr(sys, "stdin", io.StringIO("".join(rows)))
        status, out, err = run(["stream", model_b, *argv, "-q"], capsys)
        assert status == 0, err
        assert out.startswith("streaming stdin (kinect_v1 layout, 20 fps) until the")
        assert _event_lines(out) == replay
        assert out.splitlines()[-1] == replay[1][0]  # the summary comes last


class _Interrupted:
    """Lines of a text stream, then Ctrl-C (``KeyboardInterrupt``)."""

    def __init__(self, lines):
        self.lines = lines

    def __iter__(self):
        yield from self.lines
        raise KeyboardInterrupt


@pytest.mark.parametrize("where", ["waiting for a frame", "inside a push"])
def test_stream_ctrl_c_flushes_and_prints_the_summary(
    model_b, held_out, capsys, monkeypatch, where
):
    """Ctrl-C ends a live stream cleanly, status 0: the frames pushed so far
    are flushed (a Ctrl-C inside a push waits for the push to finish), their
    events printed, then the summary."""
    # Python's own Ctrl-C handler, as in a terminal: a suite started in the
    # background (`cmd &`, nohup) inherits SIGINT ignored, which the CLI honours
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _ctrl_c_case(model_b, held_out, capsys, monkeypatch, where)
    finally:
        signal.signal(signal.SIGINT, before)


def _ctrl_c_case(model_b, held_out, capsys, monkeypatch, where):
    from skgesture.streaming import StreamingRecognizer

    frames, k = held_out.X[0], 900
    if where == "waiting for a frame":
        stdin, n = _Interrupted(_csv_rows(frames[:k])), k
    else:
        stdin, n, pushed = io.StringIO("".join(_csv_rows(frames))), k + 1, [0]
        real_push = StreamingRecognizer.push

        def push(self, frame):
            if pushed[0] == k:
                signal.raise_signal(signal.SIGINT)  # Ctrl-C, during push k
            pushed[0] += 1
            return real_push(self, frame)

        monkeypatch.setattr(StreamingRecognizer, "push", push)
    monkeypatch.setattr(sys, "stdin", stdin)
    status, out, err = run(["stream", model_b, "-", "-q"], capsys)
    assert status == 0, err
    assert f"stopped (Ctrl-C) after {n} frames" in err
    monkeypatch.undo()
    expected = StreamingRecognizer(load_model(model_b)).recognize(frames[:n])
    events, summary = _event_lines(out)
    assert expected and len(events) == len(expected)
    for line, ev in zip(events, expected):
        assert f"frame {ev.emitted_at:6d}" in line and f"delay {ev.delay} " in line
    assert summary and summary[0].startswith(f"{len(expected)} events")
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


@pytest.mark.parametrize(
    "argv, match",
    [
        (["--source", "tcp://127.0.0.1:9000"], "give udp://HOST:PORT"),
        (["--source", "udp://127.0.0.1"], "give udp://HOST:PORT"),
        (["--source", "udp://127.0.0.1:99999"], "give udp://HOST:PORT"),
        (["synthetic", "--source", "-"], "not both"),
        ([], "give DATA"),
        (["--source", "-", "--timeout", "1"], "stdin ends at the end of its input"),
        (["--source", "-", "--sequence", "2"], "--sequence is for a replayed"),
        (["--source", "udp://127.0.0.1:0", "--layout", "kinect3"], "unknown layout"),
    ],
)
def test_stream_source_mistakes_are_one_line(model_b, capsys, argv, match):
    status, _, err = run(["stream", model_b, *argv, "-q"], capsys)
    _assert_one_line_error(status, err, match)


def _savefig_spy(monkeypatch):
    """The figures that ``savefig`` writes, kept for the test to look at."""
    from matplotlib.figure import Figure

    saved, real = [], Figure.savefig

    def savefig(self, *args, **kwargs):
        saved.append(self)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return saved


def test_plot_title_size_and_fps_reach_the_figure(
    model_b, tmp_path, capsys, monkeypatch
):
    pytest.importorskip("matplotlib")
    saved = _savefig_spy(monkeypatch)
    n_frames = max(len(x) for x in make_gesture_streams(2, 3, random_state=1).X)
    base = ["plot", "timeline", *HELD_OUT, "--model", model_b, "-q", "--overwrite"]
    path = tmp_path / "t.png"
    status, _, err = run(base + ["-o", path], capsys)
    assert status == 0, err
    ax = saved[-1].axes[0]
    assert ax.get_xlabel() == "time (s)"
    assert ax.get_xlim()[1] == pytest.approx(n_frames / 20)  # the data's 20 fps
    assert ax.get_title().startswith("truth against prediction")
    argv = base + ["-o", path, "--fps", "10", "--title", "Take 3", "--size", "8,3"]
    status, _, err = run(argv + ["--dpi", "50"], capsys)
    assert status == 0, err
    fig = saved[-1]
    ax = fig.axes[0]
    assert ax.get_xlim()[1] == pytest.approx(n_frames / 10)
    assert ax.get_title() == "Take 3"
    assert tuple(fig.get_size_inches()) == (8, 3)
    png = path.read_bytes()
    assert struct.unpack(">II", png[16:24]) == (400, 150)  # 8 x 3 inches at 50 dpi
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend[0] == "rest" and "gesture_01" in legend
    for bad in (["--size", "8"], ["--size", "8,-1"], ["--fps", "0"]):
        status, _, err = run(base + ["-o", path, *bad], capsys)
        assert status == 2 and bad[0] in err


@pytest.mark.slow
def test_demo(capsys):
    with torch.random.fork_rng(devices=[]):
        status, out, err = run(["demo", "--method", "C", *TINY], capsys)
    assert status == 0, err
    assert "PRECOG" in out and "held-out subjects 7-8" in out
    assert "Jaccard index (official 2014)" in out


# -- documents ---------------------------------------------------------------------


def test_readme_lists_every_document():
    root = Path(__file__).resolve().parents[1]
    readme = (root / "README.md").read_text()
    section = readme.split("## Documentation", 1)[1].split("\n## ", 1)[0]
    for doc in sorted((root / "docs").glob("*.md")):
        assert f"`docs/{doc.name}`" in section, doc.name


def test_a_recording_too_short_for_the_model_gets_a_warning(model_b, held_out):
    """Not 'Jaccard nan' after generic warnings: the warning names the recording
    and the model's floor (Method B: the segmenter's min_length)."""
    import argparse

    from skgesture._cli_support import _predict

    model = load_model(model_b)
    floor = model.named_steps["segmenter"].min_length
    X = [held_out.X[0][: floor - 1], held_out.X[1]]
    args = argparse.Namespace(quiet=True)
    match = rf"short_take: {floor - 1} frames, shorter than the {floor} frames"
    with pytest.warns(UserWarning, match=match + rf".*min_length={floor}") as record:
        y_pred = _predict(args, model, X, ["short_take", "long_take"])
    assert [len(p) for p in y_pred] == [len(x) for x in X]
    assert not any("long_take" in str(w.message) for w in record)
    assert not y_pred[0].any()  # rest throughout, as the warning says


# -- frame rates (issue 17) ------------------------------------------------------


def test_models_record_their_rate_and_resample_data_at_another(
    model_b, held_out, capsys
):
    """train fits at the data's rate (synthetic streams: 20 fps); evaluate and
    predict hand --fps (or the data's rate) to the model, which resamples."""
    model = load_model(model_b)
    assert model.fps_ == 20.0
    status, out, err = run(
        ["evaluate", model_b, *HELD_OUT, "--fps", "40", "--json", "-q"], capsys
    )
    assert status == 0, err
    y_pred = model.predict(held_out.X, fps=40)
    want = jaccard_index(held_out.y, y_pred)
    assert json.loads(out)["jaccard"]["official_2014"] == pytest.approx(want)
    assert [len(p) for p in y_pred] == [len(x) for x in held_out.X]
    status, out, _ = run(["evaluate", model_b, *HELD_OUT, "--json", "-q"], capsys)
    want = jaccard_index(held_out.y, model.predict(held_out.X))  # at 20: as is
    assert json.loads(out)["jaccard"]["official_2014"] == pytest.approx(want)


def test_recordings_whose_frame_numbers_suggest_another_rate_get_a_warning(
    model_b, held_out, tmp_path, capsys
):
    """Own recordings have no known rate: the model takes their frames as they
    are, and says so when their frame numbers advance by 2 (half its rate)."""
    folder = tmp_path / "takes"
    folder.mkdir()
    x = held_out.X[0][:200]
    numbers = 2 * np.arange(len(x))[:, None]
    np.savetxt(folder / "take.csv", np.hstack([numbers, x.reshape(len(x), -1)]),
               delimiter=",", fmt="%.6g")  # fmt: skip
    status, _, err = run(["predict", model_b, folder, "-o", tmp_path / "p"], capsys)
    assert status == 0, err
    warned = [line for line in err.splitlines() if "warning" in line]
    assert len(warned) == 1, err
    assert "take: no frame rate is known (pass --fps)" in warned[0]
    assert "advance by 2 per frame: a recording at 10 fps" in warned[0]
    status, _, err = run(
        ["predict", model_b, folder, "-o", tmp_path / "q", "--fps", "10"], capsys
    )
    assert status == 0 and "warning" not in err, err


def test_train_learns_background_recordings_as_rest(tmp_path, capsys, monkeypatch):
    """--background DIR: the folder's recordings (no annotations needed) are
    training sequences whose every frame is rest; 'synthetic' makes them."""
    from skgesture._persistence import model_info
    from skgesture._pipelines import BACKGROUND_SEQUENCES

    rng = np.random.default_rng(0)
    folder = tmp_path / "work"
    folder.mkdir()
    base = make_gesture_streams(n_sequences=1, n_classes=3, random_state=5).X[0]
    for k in range(2):  # ordinary motion: a recording's rest pose, jittered
        x = base[:80] + rng.normal(0, 0.01, size=base[:80].shape)
        np.savetxt(folder / f"walk{k}.csv", x.reshape(len(x), -1), delimiter=",")
    seen = {}
    fit = skgesture.GesturePipeline.fit

    def spy(self, X, y, **kw):
        seen["X"], seen["y"] = X, y
        return fit(self, X, y, **kw)

    monkeypatch.setattr(skgesture.GesturePipeline, "fit", spy)
    path = tmp_path / "bg.skg"
    with torch.random.fork_rng(devices=[]):
        status, out, err = run(
            ["train", *SYNTH, *TINY, "--background", folder,
             "--background", "synthetic", "-o", path], capsys,
        )  # fmt: skip
    assert status == 0, err
    # 3 gesture streams, then the 2 recordings, then the synthetic ones: as
    # many as make_recommended(background="synthetic") makes at every fit
    made = skgesture.make_recommended(background="synthetic").background
    assert len(seen["X"]) == 5 + made.n_sequences == 5 + BACKGROUND_SEQUENCES
    assert [len(x) for x in seen["X"][3:5]] == [80, 80]
    assert all(not y.any() for y in seen["y"][3:])
    assert any(y.any() for y in seen["y"][:3])
    meta = model_info(path)["metadata"]
    assert meta["background"] == [str(folder), "synthetic"]
    assert meta["n_background_frames"] == sum(len(x) for x in seen["X"][3:])


def test_train_background_folder_must_exist(tmp_path, capsys):
    status, _, err = run(
        ["train", *SYNTH, *TINY, "--background", tmp_path / "nope",
         "-o", tmp_path / "m.skg"], capsys,
    )  # fmt: skip
    _assert_one_line_error(status, err, "--background")
