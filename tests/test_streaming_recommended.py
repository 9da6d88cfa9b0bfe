"""The recommended model (JointFeatures -> SequenceTagger / VotingTagger) on a live
stream: the features' step against transform, the taggers' trailing-window step
against offline predict_segments (every architecture, VotingTagger, every decoding
rule), the shared decoding pieces against decode, safety and reset."""

import numpy as np
import pytest
from sklearn.utils._param_validation import InvalidParameterError

from skgesture import JointFeatures, SequenceTagger, VotingTagger, make_recommended
from skgesture._features import (
    _frame_quantities,
    _normalised,
    _statistics,
    _with_derivatives,
)
from skgesture._stream import stream_frames
from skgesture._taggers._decoding import LabelRuns, decode, make_smoother, smooth_proba
from skgesture.datasets import load_precog
from skgesture.streaming import StreamingRecognizer
from skgesture.utils._smoothing import MeanStepper

TINY = {"max_epochs": 1, "steps_per_epoch": 3, "crop_length": 32, "batch_size": 8}
# Streamed exactly as offline: the whole stream in the statistics window, no
# warm-up cut, the tagger's look-ahead and window beyond the stream's end.
WHOLE = {
    "features__fill": "hold",
    "features__stream_warmup": 10**6,
    "features__stream_stats_window": 10**6,
}
WHOLE_TAGGER = {"stream_future": 10**6, "stream_past": 10**6}


@pytest.fixture(scope="module")
def precog():
    return load_precog()


def _split(data, subjects):
    idx = [i for i, g in enumerate(data.groups) if g in subjects]
    return [data.X[i] for i in idx], [data.y[i] for i in idx]


def _tagger(architecture="gru", **params):
    return SequenceTagger(
        architecture=architecture,
        hidden_sizes=(8, 8),
        tcn_layers=3,
        random_state=0,
        **TINY,
        **params,
    )


def _fit(tagger, precog):
    X, y = _split(precog, (1,))
    # the whole-sequence model on joint features, streamed over a trailing window
    model = make_recommended(
        features="joints", lookahead=None, background=None, random_state=0
    )  # (these taggers have no run namer to give negatives to)
    model.steps[-1] = ("tagger", tagger)
    return model.fit(X[:4], y[:4])


@pytest.fixture(scope="module")
def models(precog):
    """Tiny fitted recommended models, one per kind of tagger."""
    vote = VotingTagger([("gru", _tagger("gru")), ("tcn", _tagger("tcn"))],
                        weights=[2, 1], random_state=0)  # fmt: skip
    taggers = {
        "gru": _tagger("gru"),
        "lstm": _tagger("lstm"),
        "tcn": _tagger("tcn"),
        "voting": vote,
    }
    return {name: _fit(t, precog) for name, t in taggers.items()}


@pytest.fixture(scope="module")
def stream(precog):
    """A held-out PRECOG stream of 160 frames with a NaN start and a dropout."""
    X = _split(precog, (8,))[0][0][:160].copy()
    X[:3] = np.nan
    X[70:76] = 0.0
    return X


def _offline(model, X):
    return model[-1].predict_segments(model[:-1].transform([X]))[0]


def _push_all(rec, X):
    events = []
    for frame in X:
        events += rec.push(frame)
    return events + rec.flush()


def _rows(events):
    return np.array([ev.to_segment() for ev in events], dtype=float).reshape(-1, 4)


def _key(events):
    return [(e.label, e.start, e.end, e.emitted_at) for e in events]


def _set_whole(model):
    model.set_params(**WHOLE)
    model[-1].set_params(**WHOLE_TAGGER)
    return model


def _defaults(model):
    """The default stream and decoding settings (tests share the models)."""
    fresh = JointFeatures().get_params()
    keys = ("fill", "stream_warmup", "stream_stats_window")
    model.set_params(**{f"features__{k}": fresh[k] for k in keys})
    tagger = model[-1]
    voting = isinstance(tagger, VotingTagger)
    fresh = type(tagger)(*([tagger.estimators] if voting else [])).get_params()
    keys = ("stream_future", "stream_past", "smoothing", "smooth_span", "min_run",
            "max_gap")  # fmt: skip
    tagger.set_params(**{k: fresh[k] for k in keys})
    return model


# -- JointFeatures: the step against transform ------------------------------------


def _stream_rows(feats, X, block=1):
    state = feats.stream_init()
    parts = []
    for lo in range(0, len(X), block):
        out, state = feats.stream_step(state, stream_frames(X[lo : lo + block], lo))
        parts.append(out)
    out, state = feats.stream_flush(state)
    parts.append(out)
    return (np.concatenate([p.data for p in parts]),
            np.concatenate([p.mask for p in parts]),
            np.concatenate([p.time for p in parts]))  # fmt: skip


@pytest.mark.parametrize(
    "params",
    [{}, {"align": True}, {"accelerations": True}, {"velocities": False},
     {"joints": "full20", "align": True, "accelerations": True}],
)  # fmt: skip
def test_feature_stream_gives_the_rows_of_transform(stream, params):
    """Whole stream in the statistics window, warm-up to the end, hold filling:
    bit for bit the rows and masks of transform, in any block size."""
    whole = {"stream_warmup": 10**6, "stream_stats_window": 10**6}
    feats = JointFeatures(fill="hold", **whole, **params).fit([stream])
    want = feats.transform([stream])[0]
    for block in (1, 7, len(stream)):
        data, mask, time = _stream_rows(feats, stream, block)
        assert data.dtype == np.float32 and data.shape == want.shape
        np.testing.assert_array_equal(data, np.ma.getdata(want))
        np.testing.assert_array_equal(mask, np.ma.getmaskarray(want).any(axis=1))
        assert (time == len(stream) - 1).all()  # all wait for the statistics


def test_feature_rows_use_the_statistics_of_a_trailing_window(stream):
    """Row t: emitted with frame t + 1, every frame it reads normalised with the
    statistics of the last W tracked frames up to frame t + 1 (hold filling)."""
    W = 25
    feats = JointFeatures(stream_warmup=0, stream_stats_window=W).fit([stream])
    data, mask, time = _stream_rows(feats, stream)
    filled = stream.copy()
    missing = np.isnan(filled).any(axis=(1, 2)) | ~filled.any(axis=(1, 2))
    first = int(np.argmax(~missing))
    for t in range(len(filled)):  # hold, the leading frames copy the first
        if missing[t]:
            filled[t] = filled[max(t - 1, first)] if t > first else filled[first]
    T = len(filled)
    for t in (first + 2, 40, 72, 120, T - 1):
        tau = min(max(t + 1, first), T - 1)
        tracked = np.flatnonzero(~missing[: tau + 1])[-W:]
        stats = _statistics(_frame_quantities(filled[tracked]), False)
        lo, hi = max(t - 1, 0), min(t + 2, tau + 1)
        rows = _with_derivatives(_normalised(filled[lo:hi], feats._joint_index,
                                             stats), True, False)  # fmt: skip
        np.testing.assert_array_equal(data[t], rows[t - lo])
        assert time[t] == tau and mask[t] == missing[t]


def test_feature_stream_starting_untracked_and_all_untracked(stream):
    feats = JointFeatures(fill="hold", stream_warmup=10**6,
                          stream_stats_window=10**6).fit([stream])  # fmt: skip
    late = np.concatenate([np.zeros((100, 20, 3)), stream])
    data, mask, _ = _stream_rows(feats, late)
    want = feats.transform([late])[0]
    # The first tracked frame is 103; the frames before 103 - 64 (max_backfill)
    # are handed on as zero rows at once, the rest are the rows of transform.
    np.testing.assert_array_equal(data[:39], 0.0)
    np.testing.assert_array_equal(data[39:], np.ma.getdata(want)[39:])
    np.testing.assert_array_equal(mask, np.ma.getmaskarray(want).any(axis=1))
    for X in (np.zeros((90, 20, 3)), np.full((5, 20, 3), np.nan)):
        data, mask, _ = _stream_rows(feats, X)
        assert mask.all() and not data.any() and len(data) == len(X)


def test_feature_stream_refuses_joints_changed_after_fit(stream):
    feats = JointFeatures().fit([stream])
    feats.set_params(joints="full20")
    with pytest.raises(ValueError, match="joints was changed after fit"):
        feats.stream_init()


# -- the shared decoding pieces ----------------------------------------------------


@pytest.mark.parametrize("seed", range(6))
def test_label_runs_decide_as_decode(seed):
    """LabelRuns, fed row by row, gives the segments of decode on the whole
    sequence, for gaps, minimum runs and untracked rows."""
    rng = np.random.RandomState(seed)
    n, classes = 300, np.array([0, 1, 2, 5])
    labels = rng.choice(4, size=n, p=[0.5, 0.2, 0.2, 0.1])
    labels = np.repeat(labels, rng.randint(1, 6, size=n))[:n]  # runs
    p = np.full((n, 4), 0.1)
    p[np.arange(n), labels] = 0.7
    p += rng.uniform(0, 0.01, p.shape)
    rest = rng.rand(n) < 0.05
    for min_run, max_gap in [(1, 0), (3, 0), (4, 2), (2, 5)]:
        want = decode(p, classes, smoothing="none", min_run=min_run,
                      max_gap=max_gap, untracked=rest)  # fmt: skip
        runs = LabelRuns(classes, min_run, max_gap=max_gap)
        got = []
        for t in range(n):
            segs = runs.feed(t, p[t : t + 1], p[t : t + 1], rest[t : t + 1], [t])
            assert all(s.end - 1 <= s.time == t for s in segs)  # causal
            got += segs
        got += runs.end(n, n - 1)
        lab = np.zeros(n, dtype=int)
        for s in got:
            lab[s.start : s.end] = s.label
        np.testing.assert_array_equal(lab, want)


@pytest.mark.parametrize("smoothing, span", [("mean", 1), ("mean", 4), ("mean", 9),
                                             ("loess", 7), ("none", 5)])  # fmt: skip
def test_smoothing_steppers_equal_smooth_proba(smoothing, span):
    rng = np.random.RandomState(0)
    for n in (1, 3, 8, 60):
        p = rng.rand(n, 3)
        st = make_smoother(smoothing, span, 3)
        parts = [st.step(p[t : t + 1], np.array([t]))[1] for t in range(n)]
        got = np.concatenate(parts + [st.flush(n - 1)[1]])
        np.testing.assert_allclose(got, smooth_proba(p, span, smoothing),
                                   rtol=0, atol=1e-12)  # fmt: skip
    assert MeanStepper(4, 1).h == 1 and MeanStepper(5, 1).h == 2


def test_numpy_tcn_equals_the_module():
    """The MS-TCN of a stream's window, in numpy, gives the module's
    probabilities (every block length, dilations beyond the block included)."""
    import torch

    from skgesture._nn._fast import TemporalConvProba
    from skgesture._nn._modules import TemporalConvModule, frame_probabilities

    torch.manual_seed(0)
    rng = np.random.RandomState(0)
    module = TemporalConvModule(6, 4, channels=8, n_layers=4, n_stages=2).eval()
    mean = rng.randn(6).astype(np.float32)
    scale = (0.5 + rng.rand(6)).astype(np.float32)
    proba = TemporalConvProba(module, mean, scale)
    for n in (1, 3, 9, 40):
        x = rng.randn(n, 6)
        want = frame_probabilities(
            module, ((x - mean) / scale).astype(np.float32)[None]
        )
        np.testing.assert_allclose(proba(x), want[0], rtol=0, atol=1e-6)


@pytest.mark.parametrize("cell, activation", [("gru", "none"), ("lstm", "leaky_relu")])
def test_recurrent_scorer_equals_the_module(cell, activation):
    """With the whole sequence as future, the carried forward states and the
    backward passes give the module's probabilities, row by row or at once."""
    import torch

    from skgesture._nn._fast import RecurrentScorer
    from skgesture._nn._modules import RecurrentTaggerModule, frame_probabilities
    from skgesture.utils._buffers import RowBuffer

    torch.manual_seed(0)
    rng = np.random.RandomState(0)
    module = RecurrentTaggerModule(
        5, 3, hidden_sizes=(6, 4, 5), cell=cell, activation=activation
    ).eval()
    mean = rng.randn(5).astype(np.float32)
    scale = (0.5 + rng.rand(5)).astype(np.float32)
    x = 3 * rng.randn(30, 5)
    X = RowBuffer((5,))
    X.append(x)
    want = frame_probabilities(module, ((x - mean) / scale).astype(np.float32)[None])
    scorer = RecurrentScorer(module, mean, scale)
    rows = [scorer(X, u, u + 1, 30) for u in range(12)] + [scorer(X, 12, 30, 30)]
    np.testing.assert_allclose(np.concatenate(rows), want[0], rtol=0, atol=1e-5)
    # Truncated future: the backward direction starts at the window's end.
    scorer.reset()
    head = ((x[:7] - mean) / scale).astype(np.float32)[None]
    want = frame_probabilities(module, head)[0][:1]
    np.testing.assert_allclose(scorer(X, 0, 1, 7), want, rtol=0, atol=1e-5)


# -- the recommended model through StreamingRecognizer ------------------------------


@pytest.mark.parametrize("kind", ["gru", "lstm", "tcn", "voting"])
@pytest.mark.parametrize(
    "decoding",
    [{}, {"smoothing": "mean", "smooth_span": 5, "min_run": 3, "max_gap": 4},
     {"smoothing": "loess", "smooth_span": 7, "min_run": 2}],
    ids=["default", "mean-gap", "loess"],
)  # fmt: skip
def test_streamed_events_equal_offline_segments(models, stream, kind, decoding):
    """With the whole stream in every window (look-ahead beyond its end), the
    events are the rows of offline predict_segments, every architecture."""
    model = _set_whole(_defaults(models[kind]))
    model[-1].set_params(**decoding)
    offline = _offline(model, stream)
    events = StreamingRecognizer(model).recognize(stream)
    assert len(offline) > 0  # an untrained net still finds short runs
    got = _rows(events)
    np.testing.assert_array_equal(got[:, :3], offline[:, :3])
    np.testing.assert_allclose(got[:, 3], offline[:, 3], rtol=0, atol=1e-6)
    assert all(ev.label in model[-1].classes_ for ev in events)


def test_default_settings_stream_with_a_bounded_delay(models, stream):
    model = _defaults(models["gru"])
    rec = StreamingRecognizer(model)
    assert rec.delays["features"] == 1  # the central difference
    assert rec.max_delay == 1 + rec.delays["tagger"]
    warmup = model[0].stream_warmup
    events = _push_all(rec, stream)
    assert events, "the tiny model finds short runs"
    for ev in events:
        assert 0 <= ev.start < ev.end <= len(stream)
        assert 0.0 <= ev.confidence <= 1.0
        if ev.emitted_at < len(stream) - 1:  # not decided by flush
            # (or it waited for the end of the features' warm-up)
            assert ev.delay <= rec.max_delay or ev.emitted_at == warmup - 1
    model[-1].set_params(stream_future=8, max_gap=3, smoothing="mean", smooth_span=5)
    assert StreamingRecognizer(model).delays == {"features": 1, "tagger": 8 + 2 + 3 + 1}
    model[-1].set_params(smoothing="loess", smooth_span=7, max_gap=0)
    assert StreamingRecognizer(model).delays["tagger"] == 8 + 3 + 0 + 1


def test_push_many_and_reset(models, stream):
    model = _defaults(models["voting"])
    rec = StreamingRecognizer(model)
    want = _key(_push_all(rec, stream))
    assert want
    assert _key(rec.push_many(stream) + rec.flush()) == want
    # A half-pushed stream is forgotten by reset(), and the next one is as new.
    rec.push_many(stream[:90])
    rec.reset()
    assert rec.n_frames_seen == 0
    assert _key(rec.recognize(stream)) == want


def test_lost_tracking_never_gives_an_event(models, stream):
    rec = StreamingRecognizer(_defaults(models["gru"]))
    assert rec.recognize(np.zeros((120, 20, 3))) == []
    assert rec.recognize(np.full((90, 20, 3), np.nan)) == []
    gap = stream.copy()
    gap[40:110] = 0.0
    for ev in rec.recognize(gap):
        assert ev.end <= 40 or ev.start >= 110, ev


@pytest.mark.parametrize("frame, error, match", [
    (np.full((3, 20), 0.5), ValueError, r"frame 5 .*shape \(3, 20\).*\(20, 3\)"),
    (np.where(np.eye(20, 3) > 0, np.inf, 0.5), ValueError,
     r"frame 5 of the stream is invalid.*infinite"),
    (np.full((20, 3), 1e200), ValueError, r"frame 5 of the stream .*magnitude"),
    ("frame", TypeError, r"frame 5 of the stream must be an array"),
    (np.full((20, 3), 0.5 + 1j), ValueError, r"frame 5 .*(complex|real)"),
])  # fmt: skip
def test_bad_frames_are_refused_and_change_nothing(models, stream, frame, error,
                                                   match):  # fmt: skip
    rec = StreamingRecognizer(_defaults(models["gru"]))
    want = _key(rec.recognize(stream))
    events = []
    for f in stream[:5]:
        events += rec.push(f)
    with pytest.raises(error, match=match):
        rec.push(frame)
    assert rec.n_frames_seen == 5
    for f in stream[5:]:
        events += rec.push(f)
    assert _key(events + rec.flush()) == want


def test_buffers_stay_bounded_on_a_long_stream(models, precog):
    X = np.concatenate(_split(precog, (8,))[0])[:1500]
    rec = StreamingRecognizer(_defaults(models["tcn"]))
    peak = {}
    for lo in range(0, len(X), 100):
        rec.push_many(X[lo : lo + 100])
        for key, n in rec.buffer_lengths().items():
            peak[key] = max(peak.get(key, 0), n)
    tagger = models["tcn"][-1]
    assert peak["features.frames"] <= 110 and peak["features.tracked"] <= 700
    assert peak["tagger.rows"] <= tagger.stream_past + tagger.stream_future + 101
    assert peak["tagger.undecided"] < 1200


@pytest.mark.parametrize("params", [{"stream_past": -1}, {"stream_future": 1.5}])
def test_stream_parameters_are_validated(params, stream):
    X = [np.ones((30, 6))]
    y = [np.r_[np.zeros(15, int), np.ones(15, int)]]
    with pytest.raises(InvalidParameterError, match=list(params)[0]):
        _tagger(**params).fit(X, y)
    with pytest.raises(InvalidParameterError, match="stream_stats_window"):
        JointFeatures(stream_stats_window=0).fit([stream])
