"""The ``decoding`` benchmark section runs in quick mode on tiny data.

Synthetic streams and a tiny tagger: no shared data, a few seconds. Checks the
rows' keys and ranges, the current default row (present once, zero change),
that the worst case is the smallest change over the datasets, the chosen
rule, that false events never rise with ``min_confidence``, that the default
row is what the fitted pipeline itself predicts, that the figure is written to
the folder asked for, and that a second run (with another grid) decodes the
cached probabilities without fitting again.
"""

# SPDX-License-Identifier: BSD-3-Clause

import itertools
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")
pytest.importorskip("torch")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_decoding  # noqa: E402
from test_background import _ramps  # noqa: E402

from skgesture import GesturePipeline  # noqa: E402
from skgesture.metrics import event_misses, event_recall, jaccard_index  # noqa: E402
from skgesture.utils._segments import labels_to_segments  # noqa: E402

KEYS = {
    "table",
    "setting",
    "label",
    "default",
    "chosen",
    "jaccard",
    "jaccard_sd",
    "jaccard_change",
    "worst_change",
    "worst_dataset",
    "recall",
    "recall_sd",
    "gestures",
    "events_per_min",
    "events_per_min_sd",
    "events_per_min_by",
    "events",
    "minutes",
    "runs",
    "misses",
}
PARAMS = bench_decoding.PARAMS


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """The quick run, and the pipelines it fitted (in the order of the fits)."""
    out = tmp_path_factory.mktemp("decoding")
    fitted = []
    fit = GesturePipeline.fit

    def recording_fit(self, *args, **kwargs):
        fitted.append(self)
        return fit(self, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(GesturePipeline, "fit", recording_fit)
        rows = bench_decoding.run(quick=True, out_dir=out)
    return out, rows, fitted


def bench_decoding_misses():
    """The outcomes of a missed gesture, in ``event_misses``' order."""
    return ["wrong_class", "merged", "boundaries", "no_event"]


def _settings(rows):
    return [r for r in rows if r["table"] == "decoding"]


def test_rows_keys_and_ranges(quick_run):
    _, rows, fitted = quick_run
    table = _settings(rows)
    grid = bench_decoding.QUICK_GRID
    default = bench_decoding.current_default()  # of the parameters the grid leaves
    levels = [grid.get(p, (default[p],)) for p in PARAMS]
    expected = [dict(zip(PARAMS, v)) for v in itertools.product(*levels)]
    assert sorted(map(str, (r["setting"] for r in table))) == sorted(map(str, expected))
    assert len(fitted) == len(bench_decoding.QUICK_DATASETS)  # one fold, one seed
    datasets = set(bench_decoding.QUICK_DATASETS)
    negatives = {"synthetic A", "synthetic B"}
    for r in table:
        assert set(r) == KEYS
        assert set(r["jaccard"]) == set(r["jaccard_change"]) == datasets
        assert r["runs"] == dict.fromkeys(datasets, "1x1")
        for d in datasets:
            assert 0.0 <= r["jaccard"][d] <= 1.0
            assert -1.0 <= r["jaccard_change"][d] <= 1.0
            assert np.isnan(r["jaccard_sd"][d])  # one seed: no spread
        assert 0.0 <= r["recall"] <= 1.0 and r["gestures"] > 0
        assert list(r["misses"]) == ["found", *bench_decoding_misses()]
        assert sum(r["misses"].values()) == pytest.approx(1.0)
        assert r["misses"]["found"] == pytest.approx(r["recall"])  # one seed
        assert np.isfinite(r["events_per_min"]) and r["events_per_min"] >= 0.0
        assert set(r["events_per_min_by"]) == negatives
        assert r["minutes"] > 0.0
        assert r["events"] == pytest.approx(r["events_per_min"] * r["minutes"])
        assert r["label"] == ", ".join(
            f"{p}={bench_decoding.fmt_value(r['setting'][p])}" for p in PARAMS
        )
    assert sum(r["chosen"] for r in table) == 1


def test_default_row_has_zero_change(quick_run):
    _, rows, _ = quick_run
    table = _settings(rows)
    defaults = [r for r in table if r["default"]]
    assert len(defaults) == 1
    (default,) = defaults
    tagger = bench_decoding.skgesture.make_recommended().named_steps["tagger"]
    assert default["setting"] == {p: tagger.get_params()[p] for p in PARAMS}
    assert default["setting"] == bench_decoding.current_default()
    assert all(v == 0.0 for v in default["jaccard_change"].values())
    assert default["worst_change"] == 0.0
    for r in table:  # one seed: the change is the difference of the Jaccards
        for d, change in r["jaccard_change"].items():
            assert change == pytest.approx(r["jaccard"][d] - default["jaccard"][d])


def test_worst_case_is_the_smallest_change(quick_run):
    _, rows, _ = quick_run
    table = _settings(rows)
    for r in table:
        changes = r["jaccard_change"]
        assert r["worst_change"] == min(changes.values())
        assert changes[r["worst_dataset"]] == r["worst_change"]
    # the datasets disagree somewhere, so the minimum is a choice
    assert any(
        min(r["jaccard_change"].values()) < max(r["jaccard_change"].values())
        for r in table
    )
    worst = [r["worst_change"] for r in table]
    assert worst == sorted(worst, reverse=True)  # the table's order


def test_chosen_rule(quick_run):
    _, rows, _ = quick_run
    table = _settings(rows)
    (chosen,) = [r for r in table if r["chosen"]]
    tol = bench_decoding.TOLERANCE
    assert chosen["worst_change"] >= -tol
    eligible = [r for r in table if r["worst_change"] >= -tol]
    assert chosen["events_per_min"] == min(r["events_per_min"] for r in eligible)
    # some setting fires less but loses more than the tolerance somewhere
    assert any(
        r["events_per_min"] < chosen["events_per_min"] and r["worst_change"] < -tol
        for r in table
    )
    notes = [n for n in bench_decoding.NOTES if n.startswith("chosen")]
    assert len(notes) == 1 and chosen["label"] in notes[0]


def test_false_events_do_not_rise_with_min_confidence(quick_run):
    _, rows, _ = quick_run
    groups = defaultdict(list)
    for r in _settings(rows):
        others = tuple(r["setting"][p] for p in PARAMS if p != "min_confidence")
        groups[others].append(r)
    drops = 0
    for key, group in groups.items():
        group.sort(key=lambda r: r["setting"]["min_confidence"])
        levels = [r["setting"]["min_confidence"] for r in group]
        assert levels == list(bench_decoding.QUICK_GRID["min_confidence"]), key
        events = [r["events_per_min"] for r in group]
        assert all(b <= a for a, b in zip(events, events[1:])), key
        drops += events[-1] < events[0]
    assert drops > 0  # the floor removes events, so the check bites


def test_false_events_do_not_rise_as_max_novelty_falls(quick_run):
    _, rows, _ = quick_run
    groups = defaultdict(dict)
    for r in _settings(rows):
        others = tuple(r["setting"][p] for p in PARAMS if p != "max_novelty")
        groups[others][r["setting"]["max_novelty"]] = r
    limits = bench_decoding.QUICK_GRID["max_novelty"]
    assert limits[0] is None
    for key, group in groups.items():
        if len(group) < len(limits):  # the default, added alone
            continue
        events = [group[limit]["events_per_min"] for limit in limits]
        assert events[1] <= events[0], key


def test_vary_decodes_the_default_with_one_parameter_varied(
    quick_run, monkeypatch, capsys, tmp_path
):
    import shutil

    out, _, _ = quick_run
    shutil.copytree(out / "decoding", tmp_path / "decoding")  # its own figure
    out = tmp_path
    monkeypatch.setattr(GesturePipeline, "fit", None)  # the cache answers
    bench_decoding.main(["--quick", "--vary", "max_novelty", "--out-dir", str(out)])
    text = capsys.readouterr().out
    rows = [line for line in text.splitlines() if line.startswith("| ")][1:]
    limits = bench_decoding.QUICK_GRID["max_novelty"]
    default = bench_decoding.current_default()["max_novelty"]
    assert len(rows) == len(set(limits) | {default})
    with pytest.raises(SystemExit):
        bench_decoding.main(["--quick", "--vary", "nonsense", "--out-dir", str(out)])


def test_default_row_is_what_the_pipeline_predicts(quick_run):
    """The cached probabilities, decoded with the defaults, give the fitted
    pipeline's own ``predict`` / ``predict_segments`` (synthetic B at 15 fps:
    resampled to the model's 20 and mapped back)."""
    _, rows, fitted = quick_run
    (default,) = [r for r in _settings(rows) if r["default"]]
    folds_of, negatives = bench_decoding.quick_datasets()
    name = bench_decoding.QUICK_REFERENCE
    model = fitted[list(folds_of).index(name)]
    data = folds_of[name].data
    (_, _, te) = folds_of[name].folds[0]
    X_te, y_te = [data.X[i] for i in te], [data.y[i] for i in te]
    pred = model.predict(X_te, fps=data.fps)
    assert default["jaccard"][name] == pytest.approx(jaccard_index(y_te, pred))
    truth = [bench_decoding.true_gestures(data.segments[i]) for i in te]
    found = event_recall(truth, model.predict_segments(X_te, fps=data.fps))
    assert default["recall"] == pytest.approx(found)
    misses = event_misses(truth, model.predict_segments(X_te, fps=data.fps))
    n = sum(misses.values())
    assert default["misses"] == pytest.approx({k: v / n for k, v in misses.items()})
    assert model.fps_ != negatives["synthetic B"].fps[0]
    for neg_name, neg in negatives.items():
        segments = model.predict_segments(neg.X, fps=neg.fps)
        count = sum(len(s) for s in segments)
        assert default["events_per_min_by"][neg_name] == pytest.approx(
            count / neg.minutes
        )


def test_figure_and_tables(quick_run):
    out, rows, _ = quick_run
    figures = [r for r in rows if r["table"] == "figure"]
    assert len(figures) == 1
    path = Path(figures[0]["path"])
    assert path.parent == out and path.name == "decoding_quick.png"
    assert path.is_file() and path.stat().st_size > 0
    saved = json.loads(path.with_suffix(".json").read_text())  # the rows beside it
    assert [r["setting"] for r in saved["rows"]] == [
        r["setting"] for r in _settings(rows)
    ]
    assert any(n.startswith("chosen") for n in saved["notes"])
    (why,) = [n for n in saved["notes"] if "event_misses" in n]
    assert "wrong class" in why and "no event" in why  # the default's misses
    text = bench_decoding.format_tables(rows, "decoding")
    lines = [line for line in text.splitlines() if line.startswith("| ")]
    assert len(lines) == 1 + len(_settings(rows))  # the header and a row each
    assert "jaccard quick A" in lines[0] and "false events/min" in lines[0]
    marks = [line.split("|")[1].strip() for line in lines[1:]]
    assert sorted(m for m in marks if m) in (["chosen", "default"], ["default, chosen"])
    assert str(path) in text


def test_second_run_reads_the_cache(quick_run, monkeypatch, tmp_path):
    out, rows, _ = quick_run
    cells = sorted(out.rglob("*.npz"))
    assert len(cells) == len(bench_decoding.QUICK_DATASETS)

    def no_fit(self, *args, **kwargs):
        raise RuntimeError("fit called")

    monkeypatch.setattr(GesturePipeline, "fit", no_fit)
    with pytest.raises(RuntimeError, match="fit called"):  # the patch bites
        bench_decoding.run(quick=True, out_dir=tmp_path)
    grid = {"smooth_span": (1,), "min_run": (1,), "min_confidence": (0.0, 0.9)}
    grid["min_duration"] = (bench_decoding.current_default()["min_duration"],)
    again = bench_decoding.run(quick=True, grid=grid, out_dir=out)  # another grid
    assert sorted(out.rglob("*.npz")) == cells
    first = {r["label"]: r for r in _settings(rows)}
    second = _settings(again)
    assert len(second) == 2
    for r in second:
        old = first[r["label"]]
        for key in ("jaccard", "jaccard_change", "recall", "events_per_min", "events"):
            assert r[key] == old[key], key


def test_background_synthetic_fits_with_negatives_in_cells_of_its_own(tmp_path):
    fitted = []
    fit = GesturePipeline.fit

    def recording_fit(self, *args, **kwargs):
        fitted.append(self.background)
        return fit(self, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(GesturePipeline, "fit", recording_fit)
        rows = bench_decoding.run(
            quick=True, datasets=["quick A"], out_dir=tmp_path, background="synthetic"
        )
    assert fitted and all(bg is not None for bg in fitted)
    cells = sorted(tmp_path.rglob("*.npz"))
    assert cells and all("-bgsynthetic-" in c.name for c in cells)
    figure = next(r for r in rows if r["table"] == "figure")["path"]
    assert Path(figure).name == "decoding_bgsynthetic_quick.png"
    assert Path(figure).exists()
    assert any("background='synthetic'" in n for n in bench_decoding.NOTES)


def test_background_variants_and_parallel_fits(tmp_path):
    """``background="none"`` fits no negatives even where the model has its
    own; a variant fits its own ``SyntheticBackground``; ``n_jobs=2`` fits
    the cells in worker processes, one torch thread each, in cells of their
    own, and scores them as the serial run scores its own."""
    made = bench_decoding.build_model("full20", 0, True, "none")
    assert made.background is None
    made = bench_decoding.build_model("full20", 0, True, "share10-nofragment", 1)
    assert made.background.n_sequences == 0.1
    assert made.background.kinds == bench_decoding.NO_FRAGMENT
    assert made.named_steps["tagger"].fit_threads == 1
    with pytest.raises(ValueError, match="unknown background 'noise'"):
        bench_decoding.background_of("noise", 0)
    for bad in (0, -1, 1.5):  # before any fit
        with pytest.raises(ValueError, match=f"n_jobs must be an int >= 1.*{bad}"):
            bench_decoding.run(quick=True, out_dir=tmp_path, n_jobs=bad)
    serial = bench_decoding.run(
        quick=True, datasets=["quick B"], out_dir=tmp_path / "serial", n_jobs=1
    )
    parallel = bench_decoding.run(
        quick=True, datasets=["quick B"], out_dir=tmp_path / "jobs", n_jobs=2
    )
    cells = sorted((tmp_path / "jobs").rglob("*.npz"))
    assert len(cells) == 1 and "-t1-" in cells[0].name
    assert not any("-t" in c.name for c in (tmp_path / "serial").rglob("*.npz"))
    # one thread or two: the same seed, the same tiny network, nearly the same
    # probabilities, so the default decodes to close scores
    (a,) = [r for r in _settings(serial) if r["default"]]
    (b,) = [r for r in _settings(parallel) if r["default"]]
    assert b["jaccard"]["quick B"] == pytest.approx(a["jaccard"]["quick B"], abs=0.05)


def test_a_variant_makes_the_kinds_it_asks_for_that_the_data_can_give():
    """A variant without fragments fits on data whose every gesture is its own
    reversal (as UTKinect's sit down / stand up may be): it drops
    ``"reversed"`` there instead of failing the fit, and keeps it elsewhere."""
    X, y = _ramps()
    for x, lab in zip(X, y):
        for c, s, e in labels_to_segments(lab):
            x[s:e, c - 1] = np.sin(np.linspace(0, np.pi, e - s))  # out and back
    variant = bench_decoding.background_of("nofragment", 0)
    made = variant.make(X, y)
    kinds = {k for pieces in made.pieces for k, _, _ in pieces}
    assert "reversed" not in kinds and "motion" in kinds
    with pytest.raises(ValueError, match="'reversed'"):  # the strict object
        bench_decoding.SyntheticBackground(kinds=variant.kinds).make(X, y)
    X, y = _ramps()  # ramps (slow, then fast): reversible
    kinds = {k for p in variant.make(X, y).pieces for k, _, _ in p}
    assert "reversed" in kinds


def test_set_fits_every_model_with_its_params_in_cells_of_their_own(tmp_path):
    """``--set``: every fit gets the parameters, its cells and figure a name of
    their own (so the default's cells are never read for them), a note says
    so; ``parse_params`` reads literals and strings and refuses a bare word."""
    fitted = []
    fit = GesturePipeline.fit

    def recording_fit(self, *args, **kwargs):
        fitted.append(self.named_steps["tagger"].dropout)
        return fit(self, *args, **kwargs)

    params = {"tagger__dropout": 0.05}
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(GesturePipeline, "fit", recording_fit)
        rows = bench_decoding.run(
            quick=True, datasets=["quick A"], out_dir=tmp_path, params=params
        )
    assert fitted and all(d == 0.05 for d in fitted)
    key = bench_decoding.params_key(params)
    assert key.startswith("-set") and key == bench_decoding.params_key(dict(params))
    assert key != bench_decoding.params_key({"tagger__dropout": 0.1})
    assert bench_decoding.params_key(None) == ""
    cells = sorted(tmp_path.rglob("*.npz"))
    assert cells and all(key + "-" in c.name for c in cells)
    figure = next(r for r in rows if r["table"] == "figure")["path"]
    assert Path(figure).name == f"decoding_{key[1:]}_quick.png"
    assert any("tagger__dropout" in n for n in bench_decoding.NOTES)
    assert bench_decoding.parse_params(["a=4", "b=gru", "c=(1, 2)"]) == {
        "a": 4,
        "b": "gru",
        "c": (1, 2),
    }
    with pytest.raises(SystemExit, match="PARAM=VALUE"):
        bench_decoding.parse_params(["lookahead"])


def test_set_passes_make_recommended_arguments_to_the_factory():
    """``--set features=descriptor+joints``: the features are make_recommended's
    argument (no set_params has them); the other names are set_params ones."""
    params = {"features": "descriptor+joints", "tagger__dropout": 0.05}
    model = bench_decoding.build_model("paper11", 0, False, params=params)
    assert type(model.named_steps["features"]).__name__ == "ConcatFeatures"
    assert model.named_steps["tagger"].dropout == 0.05
    assert params == {"features": "descriptor+joints", "tagger__dropout": 0.05}
    with pytest.raises(ValueError, match="quick mode"):
        bench_decoding.build_model("full20", 0, True, params={"features": "joints"})
