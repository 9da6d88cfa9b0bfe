"""The ``oov`` benchmark section (issue 14) runs in quick mode on tiny data.

Synthetic streams and a tiny tagger: no shared data, a few seconds. Checks the
rows' keys and ranges, that no configuration is tested on its own background,
that the curves are monotone in the confidence threshold, and that the figure
is written to the folder asked for (not into the repository).
"""

import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_oov  # noqa: E402

KEYS = {
    "table",
    "config",
    "background",
    "test_negatives",
    "threshold",
    "events_per_min",
    "events_per_min_sd",
    "events",
    "minutes",
    "recall",
    "recall_sd",
    "gestures",
    "jaccard",
    "jaccard_sd",
    "jaccard_delta",
    "runs",
    "fit_s",
}


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("oov")
    rows = bench_oov.run(quick=True, out_dir=out)
    return out, rows


def test_rows_keys_and_ranges(quick_run):
    _, rows = quick_run
    oov = [r for r in rows if r["table"] == "oov"]
    assert {r["config"] for r in oov} == set(bench_oov.QUICK_CONFIGS)
    for r in oov:
        assert set(r) == KEYS
        assert r["threshold"] in bench_oov.THRESHOLDS
        assert 0.0 <= r["recall"] <= 1.0
        assert 0.0 <= r["jaccard"] <= 1.0
        assert r["events_per_min"] >= 0.0 and np.isfinite(r["events_per_min"])
        assert r["events"] >= 0.0 and r["minutes"] > 0.0
        assert r["gestures"] > 0 and r["runs"] == 1 and r["fit_s"] > 0.0
        # never tested on the negatives the model was trained with
        assert r["test_negatives"] != r["config"]
        if r["config"] == "none":
            assert r["jaccard_delta"] == 0.0
        else:
            assert -1.0 <= r["jaccard_delta"] <= 1.0
    tested = defaultdict(set)
    for r in oov:
        tested[r["config"]].add(r["test_negatives"])
    a, b = bench_oov.QUICK_A, bench_oov.QUICK_B
    assert tested["none"] == tested["synthetic"] == {a, b, "pooled"}
    assert tested[a] == {b} and tested[b] == {a}


def test_curves_are_monotone_in_the_threshold(quick_run):
    _, rows = quick_run
    curves = defaultdict(list)
    for r in rows:
        if r["table"] == "oov":
            curves[r["config"], r["test_negatives"]].append(r)
    for key, curve in curves.items():
        curve.sort(key=lambda r: r["threshold"])
        assert [r["threshold"] for r in curve] == list(bench_oov.THRESHOLDS), key
        events = [r["events_per_min"] for r in curve]
        recall = [r["recall"] for r in curve]
        assert all(b <= a + 1e-12 for a, b in zip(events, events[1:])), key
        assert all(b <= a + 1e-12 for a, b in zip(recall, recall[1:])), key


def test_figure_and_tables(quick_run):
    out, rows = quick_run
    figures = [r for r in rows if r["table"] == "figure"]
    assert len(figures) == 1
    path = Path(figures[0]["path"])
    assert path.parent == out and path.is_file() and path.stat().st_size > 0
    assert not (out / "oov").exists()  # quick mode caches nothing
    text = bench_oov.format_tables(rows, "oov")
    assert "operating points" in text and str(path) in text
    for t in ("0.00", "0.60", "0.90"):
        assert f"| {t} |" in text
    assert any("protocol (quick)" in note for note in bench_oov.NOTES)
