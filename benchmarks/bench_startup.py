"""Start-up time of the command line (issue 16): what a command costs before its work.

Each command runs as a fresh process, 5 times; the table gives the median
wall time ("cold"). Its work (reading the model file and the recording,
predicting, scoring) is timed apart: the same command run twice in one
process, the second run timed, when every module is already imported. The
difference is the start-up: Python, the imports and what a first call sets
up. Issue 16's target: at most 2 s beyond the work for ``--help`` and for
``evaluate`` of a Method B model on one file. The last column says whether
torch was imported (a Method B model predicts in numpy and never needs it).
"""

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPEAT = 5
TARGET_S = 2.0
COLUMNS = ["command", "cold (s)", "work (s)", "start-up (s)", "target", "torch"]

# Runs one CLI command in-process twice; prints the second run's wall time and
# whether torch is imported. argv: the command's arguments.
_WARM = """
import io, sys, time, contextlib
from skgesture._cli import main
args = sys.argv[1:]
with contextlib.redirect_stdout(io.StringIO()):
    main(args)
    t = time.perf_counter()
    main(args)
    t = time.perf_counter() - t
print(t, "torch" in sys.modules)
"""


def _cli(*args):
    return [sys.executable, "-m", "skgesture", *args]


def _cold(argv, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def _warm(args):
    out = subprocess.run(
        [sys.executable, "-c", _WARM, *args],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()
    return float(out[-2]), out[-1] == "True"


def _setup(folder, quick):
    """A Method B and a recommended model file, and one recording with labels."""
    from skgesture.datasets import load_precog, write_intervals

    models = {}
    for method in ("B", "recommended"):
        path = folder / f"{method}.skg"
        epochs = ["--max-epochs", "2"] if quick or method == "recommended" else []
        subprocess.run(
            _cli(
                "train",
                "precog",
                "--subjects",
                "1-2",
                "--method",
                method,
                "--fast",
                "-q",
                "-o",
                str(path),
                *epochs,
            ),  # fmt: skip
            check=True,
            stdout=subprocess.DEVNULL,
        )
        models[method] = path
    data = load_precog(subjects=[4])
    recording = folder / "take1.csv"
    X = np.asarray(data.X[0], dtype=float).reshape(len(data.X[0]), -1)
    np.savetxt(recording, X, delimiter=",", fmt="%.6f")
    write_intervals(folder / "take1.labels.csv", data.y[0])
    return models, recording


def run(quick=False):
    """Rows: cold wall time, work and start-up of each command (median of 5)."""
    repeat = 2 if quick else REPEAT
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        models, recording = _setup(folder, quick)
        commands = [
            ("skgesture --help", ["--help"], False),
            (
                "evaluate, Method B, one file",
                ["evaluate", str(models["B"]), str(recording), "-q"],
                True,
            ),  # fmt: skip
            (
                "evaluate, recommended, one file",
                ["evaluate", str(models["recommended"]), str(recording), "-q"],
                False,
            ),
        ]
        for label, args, targeted in commands:
            cold = _cold(_cli(*args), repeat)
            if args == ["--help"]:  # argparse's help: nothing but start-up
                work = 0.0
                torch = (
                    "torch"
                    in subprocess.run(
                        [
                            sys.executable,
                            "-X",
                            "importtime",
                            "-m",
                            "skgesture",
                            "--help",
                        ],
                        capture_output=True,
                        text=True,
                    ).stderr
                )
            else:
                work, torch = _warm(args)
            startup = cold - work
            rows.append(
                {
                    "command": label,
                    "cold (s)": f"{cold:.2f}",
                    "work (s)": f"{work:.2f}",
                    "start-up (s)": f"{startup:.2f}",
                    "target": (
                        ("met" if startup <= TARGET_S else "MISSED")
                        + f" (<= {TARGET_S:g} s)"
                        if targeted or args == ["--help"]
                        else "-"
                    ),
                    "torch": "imported" if torch else "not imported",
                }
            )
    return rows
