"""The ``speed`` benchmark section runs in quick mode on tiny data.

Synthetic streams, a tiny tagger and ``train --fast --max-epochs 1`` in a
subprocess: no shared data, some seconds. Checks the rows' keys, that every
time is positive and finite, that the JSON file is written to the folder asked
for (not into the repository), and that no quick row claims a target as met.
"""

# SPDX-License-Identifier: BSD-3-Clause

import json
import math
import sys
from pathlib import Path

import pytest

pytest.importorskip("torch")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_speed  # noqa: E402

MEASUREMENTS = ["fit", "predict", "train --fast", "train --fast (fit, as printed)"]


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("speed")
    rows = bench_speed.run(quick=True, out_dir=out)
    return out, rows


def test_rows_keys_and_times(quick_run):
    _, rows = quick_run
    assert [r["measurement"] for r in rows] == MEASUREMENTS
    for r in rows:
        assert set(r) == set(bench_speed.KEYS)
        assert r["quick"] is True
        assert r["n"] == len(r["values"]) >= 1
        # the printed training time has one decimal: 0.0 s is possible
        low = 0.0 if r["measurement"].endswith("as printed)") else 1e-12
        for v in (r["median"], r["min"], r["max"], *r["values"]):
            assert v >= low and math.isfinite(v)
        assert r["min"] <= r["median"] <= r["max"]
    by = {r["measurement"]: r for r in rows}
    assert by["fit"]["n"] == 1 and by["fit"]["unit"] == "s"
    assert by["predict"]["n"] == bench_speed.PREDICT_CALLS
    assert by["predict"]["unit"] == "µs/frame"
    assert by["train --fast"]["n"] == 1
    # the command as a whole takes longer than the training it reports
    printed = by["train --fast (fit, as printed)"]
    assert printed["median"] <= by["train --fast"]["median"]
    assert printed["target"] is None


def test_quick_rows_claim_no_target(quick_run):
    _, rows = quick_run
    for r in rows:
        assert r["met"] is None
    text = bench_speed.format_tables(rows, "speed")
    assert "n/a (quick)" in text and "| yes |" not in text and "| NO |" not in text
    for r in rows:
        assert r["measurement"] in text


def test_json_written(quick_run):
    out, rows = quick_run
    path = out / "speed_quick.json"
    assert path.is_file() and not (out / "speed.json").exists()
    saved = json.loads(path.read_text())
    assert saved["quick"] is True and saved["rows"] == rows
    assert any("protocol (quick" in note for note in saved["notes"])
