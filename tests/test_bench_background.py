"""The ``background`` benchmark section runs in quick mode on tiny data.

Each variant of synthetic negatives is fitted (``bench_decoding``'s quick data
and tiny tagger, seed 0) and set beside no background: the rows' keys and
ranges, the changes paired against ``"none"``, the worst change, the negatives
actually reaching the fits, and the figure and JSON beside the cache.
"""

# SPDX-License-Identifier: BSD-3-Clause

import json
import sys
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")
pytest.importorskip("torch")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_background  # noqa: E402

from skgesture import GesturePipeline  # noqa: E402


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("background")
    seen = []  # the training sequences of every fit, and its background
    fit = GesturePipeline.fit

    def recording_fit(self, X, y, **kwargs):
        seen.append((len(X), self.background))
        return fit(self, X, y, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(GesturePipeline, "fit", recording_fit)
        rows = bench_background.run(
            quick=True, variants=["synthetic", "share10-nofragment"], out_dir=out
        )
    return out, rows, seen


def test_rows_pair_every_variant_with_no_background(quick_run):
    _, rows, _ = quick_run
    table = [r for r in rows if r["table"] == "background"]
    assert [r["background"] for r in table] == [
        "none",  # added first: the changes are paired against it
        "synthetic",
        "share10-nofragment",
    ]
    base = table[0]
    for r in table:
        assert set(r["jaccard"]) == {"quick A", "quick B"}
        for d, value in r["jaccard"].items():
            assert 0.0 <= value <= 1.0
            assert r["jaccard_change"][d] == pytest.approx(value - base["jaccard"][d])
        assert r["worst change"] == min(r["jaccard_change"].values())
        assert r["jaccard_change"][r["worst on"]] == r["worst change"]
        assert 0.0 <= r["recall"] <= 1.0
        assert r["false events/min"] >= 0.0
        assert set(r["events_per_min_by"]) == {"synthetic A", "synthetic B"}
        assert r["seeds"] == [0]
    assert base["worst change"] == 0.0
    assert table[1]["what"] == "24 sequences, every kind"
    assert table[2]["what"].startswith("10% of the training sequences")


def test_the_negatives_reach_the_fits(quick_run):
    _, _, seen = quick_run
    backgrounds = [bg for _, bg in seen]
    assert backgrounds.count(None) == 2  # "none": one fit per quick dataset
    made = [bg for bg in backgrounds if bg is not None]
    assert len(made) == 4
    assert {bg.n_sequences for bg in made} == {24, 0.1}


def test_figure_json_and_table(quick_run):
    out, rows, _ = quick_run
    (figure,) = [r for r in rows if r["table"] == "figure"]
    path = Path(figure["path"])
    assert path == out / "backgrounds_quick.png" and path.stat().st_size > 0
    saved = json.loads(path.with_suffix(".json").read_text())
    assert [r["background"] for r in saved["rows"]] == [
        "none",
        "synthetic",
        "share10-nofragment",
    ]
    text = bench_background.format_tables(rows)
    lines = [line for line in text.splitlines() if line.startswith("| ")]
    assert len(lines) == 1 + 3
    assert "jaccard quick A" in lines[0] and "worst change" in lines[0]
    assert str(path) in text


def test_an_unknown_variant_is_named(tmp_path):
    with pytest.raises(ValueError, match="unknown background 'noise'"):
        bench_background.run(quick=True, variants=["noise"], out_dir=tmp_path)
