"""The margin table of the ``compare`` section: the rule that chooses the
recommended model (its worst-case margin over the best peer, docs/choosing.md)."""

import sys
from pathlib import Path

import pytest

pytest.importorskip("torch")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_compare  # noqa: E402


def _row(data, method, jaccard, family="skgesture", joints="full20"):
    return {
        "data": data,
        "joints": joints,
        "method": method,
        "jaccard": jaccard,
        "family": family,
    }


ROWS = [
    _row("PRECOG", "tcn", 0.72),
    _row("PRECOG", "descriptor", 0.69),
    _row("PRECOG", "GRU peer", 0.62, "peer"),
    _row("PRECOG", "HGB peer", 0.60, "peer"),
    _row("UTK", "tcn", 0.50),
    _row("UTK", "descriptor", 0.52),
    _row("UTK", "HGB peer", 0.47, "peer"),
    _row("UTK", "GRU peer", 0.46, "peer"),
    _row("synthetic", "tcn", 0.64, joints="paper11"),
    _row("synthetic", "descriptor", 0.83, joints="paper11"),
    _row("synthetic", "GRU peer", 0.86, "peer", joints="paper11"),
    _row("nopeer", "tcn", 0.99),  # no peer measured here: no margin
]


def test_margins_are_over_the_best_peer_of_each_dataset():
    columns, rows = bench_compare.margins(ROWS)
    assert columns == [
        "method",
        "PRECOG, full20",
        "UTK, full20",
        "synthetic, paper11",
        "worst case",
        "datasets",
    ]
    best, *models = rows
    assert best["UTK, full20"] == "HGB peer 0.470"  # the best peer differs by data
    assert best["PRECOG, full20"] == "GRU peer 0.620"
    by_name = {r["method"]: r for r in models}
    tcn, desc = by_name["tcn"], by_name["descriptor"]
    assert tcn["PRECOG, full20"] == pytest.approx(0.10)
    assert tcn["worst case"] == pytest.approx(0.64 - 0.86)
    assert desc["worst case"] == pytest.approx(0.83 - 0.86)
    assert tcn["datasets"] == "3/3"  # the dataset without a peer does not count
    # the model with the better worst case comes first, whatever its best case
    assert [r["method"] for r in models] == ["descriptor", "tcn"]


def test_format_tables_prints_the_margins_under_the_table():
    text = bench_compare.format_tables(ROWS, "compare")
    assert text.index("## compare") < text.index("## Margin over the best peer")
    assert "| descriptor | 0.070 | 0.050 | -0.030 | -0.030 | 3/3 |" in text


def test_a_run_without_peers_prints_no_margin_table():
    text = bench_compare.format_tables([_row("PRECOG", "tcn", 0.7)], "compare")
    assert "Margin" not in text


def test_a_variant_sets_the_parameters_of_the_recommended_model():
    # a candidate of the default measured beside it: make_recommended, then its
    # "set" parameters, unfitted, with the joints and seed of the run
    model = bench_compare.REGISTRY["recommended (namer 2 layers)"].make(
        "paper11", 3, None
    )
    tagger = model.named_steps["tagger"]
    assert tagger.namer_hidden_sizes == (128, 128)
    assert tagger.random_state == 3
    default = bench_compare.REGISTRY["recommended"].make("paper11", 3, None)
    assert default.named_steps["tagger"].namer_hidden_sizes == (128,)
