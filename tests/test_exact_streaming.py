"""A bounded look-ahead model streams exactly what it predicts offline.

``JointFeatures(statistics="running")`` computes offline rows as the live
step does, and ``SequenceTagger(architecture="tcn", lookahead=L)`` is a
network whose frame ``t`` depends on no frame after ``t + L``; with both, the
stream's events are the offline segments, to the frame.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.pipeline import Pipeline

torch = pytest.importorskip("torch")

from skgesture import JointFeatures, SequenceTagger  # noqa: E402
from skgesture._nn import _modules  # noqa: E402
from skgesture._nn._fast import CausalConvScorer  # noqa: E402
from skgesture._nn._modules import (  # noqa: E402
    MaskBank,
    MaskDropout,
    TemporalConvModule,
    frame_probabilities,
)
from skgesture._stream import stream_frames  # noqa: E402
from skgesture.datasets import make_gesture_streams  # noqa: E402
from skgesture.streaming import StreamingRecognizer  # noqa: E402
from skgesture.utils._buffers import RowBuffer  # noqa: E402
from skgesture.utils._testing import make_skeleton_stream  # noqa: E402

L = 5


def _module(lookahead=L, stages=2):
    torch.manual_seed(0)
    return TemporalConvModule(
        4, 3, channels=8, n_layers=4, n_stages=stages, lookahead=lookahead
    ).eval()


@pytest.mark.parametrize("lookahead", [0, 1, L])
def test_no_frame_depends_on_frames_after_its_lookahead(lookahead):
    module = _module(lookahead)
    x = torch.randn(1, 50, 4)
    changed = x.clone()
    changed[0, 30:] = torch.randn(20, 4)
    with torch.no_grad():
        a, b = module(x)[-1][0], module(changed)[-1][0]
    assert a.shape == (50, 3)
    last = 30 - lookahead  # the first frame that sees frame 30
    assert torch.equal(a[:last], b[:last])
    assert not torch.allclose(a[last], b[last])


def test_whole_sequence_tcn_sees_the_future():
    module = _module(None)
    x = torch.randn(1, 50, 4)
    changed = x.clone()
    changed[0, 45:] = torch.randn(5, 4)
    with torch.no_grad():
        assert not torch.allclose(module(x)[-1][0, 35], module(changed)[-1][0, 35])


@pytest.mark.parametrize("stages", [1, 3])
def test_the_numpy_stream_scorer_equals_the_module(stages):
    module = _module(L, stages)
    X = np.random.default_rng(0).normal(size=(70, 4))
    mean, scale = X.mean(axis=0), X.std(axis=0)
    want = frame_probabilities(module, ((X - mean) / scale)[None].astype(np.float32))
    scorer = CausalConvScorer(module, mean, scale)
    rows = RowBuffer((4,), capacity=8)
    got, done = [], 0
    for t in range(len(X)):
        rows.append(X[t : t + 1], np.zeros(1, bool), np.array([t]))
        for u in range(done, rows.stop - L):  # frame u is final with row u + L
            got.append(scorer(rows, u, u + 1, u + L + 1))
            done = u + 1
    got.append(scorer(rows, done, len(X), len(X)))  # the end: zero rows
    assert_allclose(np.concatenate(got), want[0], rtol=0, atol=1e-6)
    with pytest.raises(ValueError, match="after the end"):
        rows.append(X[:1], np.zeros(1, bool), np.array([70]))
        scorer(rows, len(X), len(X) + 1, len(X) + 1)


def test_running_statistics_give_the_live_rows_offline():
    X, _ = make_skeleton_stream(random_state=0)
    X = X.copy()
    X[40:55] = 0.0  # untracked frames
    feats = JointFeatures(statistics="running", fill="hold").fit([X])
    offline = feats.transform([X])[0]
    state = feats.stream_init()
    parts = []
    for t in range(len(X)):
        rows, state = feats.stream_step(state, stream_frames(X[t : t + 1], t))
        parts.append(rows)
    rows, state = feats.stream_flush(state)
    parts.append(rows)
    live = np.concatenate([p.data for p in parts])
    assert_array_equal(np.ma.getdata(offline), live)
    assert_array_equal(np.ma.getmaskarray(offline)[:, 0], np.concatenate(
        [p.mask for p in parts]))  # fmt: skip
    # and differ from the whole-sequence statistics
    whole = JointFeatures(fill="hold").fit([X]).transform([X])[0]
    assert not np.allclose(np.ma.getdata(whole), live)


def test_running_rows_are_those_of_their_own_trailing_statistics():
    # each row: its three frames normalised with the statistics (medians) of
    # the tracked frames up to the next one, then numpy.gradient (the rows
    # are computed many at once offline; this is the definition, row by row)
    from skgesture._features import (
        _frame_quantities,
        _normalised,
        _statistics,
        _with_derivatives,
    )

    X, _ = make_skeleton_stream(random_state=1)
    feats = JointFeatures(statistics="running", fill="hold").fit([X])
    got = np.ma.getdata(feats.transform([X])[0])
    index = feats._joint_index
    for t in (1, 2, 30, len(X) - 2):
        stats = _statistics(_frame_quantities(X[: t + 2]), False)
        want = _with_derivatives(
            _normalised(X[t - 1 : t + 2], index, stats), True, False
        )
        assert_array_equal(got[t], want[1])
    with_window = JointFeatures(
        statistics="running", fill="hold", stream_stats_window=20
    ).fit([X])
    t = 100
    stats = _statistics(_frame_quantities(X[t + 2 - 20 : t + 2]), False)
    want = _with_derivatives(_normalised(X[t - 1 : t + 2], index, stats), True, False)
    assert_array_equal(np.ma.getdata(with_window.transform([X])[0])[t], want[1])


def test_running_statistics_need_the_live_fill():
    X, _ = make_skeleton_stream(random_state=0)
    with pytest.raises(ValueError, match="fill='hold'"):
        JointFeatures(statistics="running").fit([X])


def test_lookahead_is_for_the_tcn_only():
    X = [np.random.default_rng(0).normal(size=(30, 6))]
    y = [np.r_[np.zeros(15, int), np.ones(15, int)]]
    with pytest.raises(ValueError, match="architecture='tcn'"):
        SequenceTagger(architecture="gru", lookahead=4).fit(X, y)


def _exact_pipeline(n_sequences=6, max_epochs=4, **tagger_params):
    """A tiny exactly streaming pipeline fitted on all but 2 synthetic streams;
    the pipeline and the 2 streams."""
    data = make_gesture_streams(
        n_sequences=n_sequences, n_classes=3, n_gestures=(3, 4), random_state=0
    )
    tagger = SequenceTagger(
        architecture="tcn",
        hidden_sizes=(16,),
        tcn_layers=5,
        lookahead=L,
        max_epochs=max_epochs,
        steps_per_epoch=10,
        crop_length=96,
        smooth_span=5,
        min_run=5,
        random_state=0,
        **tagger_params,
    )
    pipe = Pipeline(
        [
            ("features", JointFeatures(statistics="running", fill="hold")),
            ("tagger", tagger),
        ]
    )
    with torch.random.fork_rng(devices=[]):
        pipe.fit(data.X[:-2], data.y[:-2])
    return pipe, data.X[-2:]


@pytest.fixture(scope="module")
def exact_model():
    return _exact_pipeline()


def test_streamed_events_are_the_offline_segments(exact_model):
    pipe, X = exact_model
    found = 0
    for x in X:
        segments = pipe[-1].predict_segments(pipe[:-1].transform([x]))[0]
        events = StreamingRecognizer(pipe).recognize(x)
        got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
        assert_array_equal(got, segments[:, :3].astype(int))
        assert_allclose([e.confidence for e in events], segments[:, 3], atol=1e-5)
        found += len(events)
    assert found > 0


def test_sequences_of_other_lengths_batched_together_keep_their_probabilities(
    exact_model,
):
    # a causal network runs sequences of different lengths as one padded batch;
    # each one's probabilities are those of its own run
    pipe, X = exact_model
    F = pipe[:-1].transform([X[0], X[1][:-37], X[1][:120]])
    assert len({len(f) for f in F}) == 3
    together = pipe[-1].predict_proba(F)
    for f, p in zip(F, together):
        assert p.shape == (len(f), 3 + 1)
        assert_allclose(pipe[-1].predict_proba([f])[0], p, atol=1e-6)


def test_the_delay_is_the_lookahead_and_the_decoding(exact_model):
    pipe, X = exact_model
    tagger = pipe[-1]
    h = (tagger.smooth_span - 1) // 2  # the mean smoothing's half span
    assert tagger.stream_lookahead == L + h + tagger.max_gap + 1
    events = StreamingRecognizer(pipe).recognize(X[0])
    features = pipe[0].stream_lookahead
    assert max(e.emitted_at - (e.end - 1) for e in events) <= (
        features + tagger.stream_lookahead
    )


def test_mask_dropout_is_dropout():
    drop = MaskDropout(0.3)
    x = torch.ones(200_000)
    torch.manual_seed(0)
    y = drop.train()(x)
    assert abs(float((y == 0).float().mean()) - 0.3) < 0.01
    assert torch.allclose(y[y != 0], torch.tensor(1 / 0.7))
    assert torch.equal(drop.eval()(x), x)
    assert torch.equal(MaskDropout(0.0).train()(x), x)
    # the same seed, the same mask; any shape, an odd count of values too
    odd = torch.ones(3, 7, 5)
    torch.manual_seed(1)
    first = drop.train()(odd)
    torch.manual_seed(1)
    assert torch.equal(drop(odd), first)
    assert 0 < int((first == 0).sum()) < odd.numel()
    assert torch.equal(MaskDropout(1.0).train()(odd), torch.zeros_like(odd))


def test_tcn_dropout_masks_are_slices_of_one_bank_drawn_again_never_saved(
    monkeypatch,
):
    import pickle

    monkeypatch.setattr(_modules, "MASK_BANK", 4096)
    monkeypatch.setattr(_modules, "MASK_MASKS", 1)
    monkeypatch.setattr(_modules, "MASK_REUSE", 3)
    module = TemporalConvModule(6, 3, channels=8, n_layers=3, n_stages=2, dropout=0.3)
    drops = [m for m in module.modules() if isinstance(m, MaskDropout)]
    assert len(drops) == 6 and all(d.bank is drops[0].bank for d in drops)
    bank, x = drops[0].bank, torch.ones(4, 100, 8)
    torch.manual_seed(0)
    masks = [drops[0].train()(x) for _ in range(4)]  # 3.1 times the bank's size
    old = bank._values
    assert old.numel() == 4096
    masks += [drops[0](x) for _ in range(5)]  # from a bank drawn again
    assert bank._values is not old and not torch.equal(bank._values, old)
    values = torch.stack(masks)
    assert_allclose(torch.unique(values).numpy(), [0.0, 1 / 0.7], rtol=1e-6)
    assert abs(float((values == 0).float().mean()) - 0.3) < 0.02
    assert not torch.equal(masks[0], masks[1])  # each mask at its own offset
    # the same seed, a fresh network, the same masks
    again = TemporalConvModule(6, 3, channels=8, n_layers=3, n_stages=2, dropout=0.3)
    torch.manual_seed(0)
    first = next(m for m in again.modules() if isinstance(m, MaskDropout))
    assert all(torch.equal(first.train()(x), m) for m in masks)
    # never saved; a loaded network's layers share one bank still
    loaded = pickle.loads(pickle.dumps(module))
    fresh = TemporalConvModule(6, 3, channels=8, n_layers=3, n_stages=2, dropout=0.3)
    assert len(pickle.dumps(module)) == len(pickle.dumps(fresh))  # no values saved
    banks = {id(m.bank) for m in loaded.modules() if isinstance(m, MaskDropout)}
    assert len(banks) == 1
    assert torch.equal(loaded.eval()(x[..., :6])[-1], module.eval()(x[..., :6])[-1])
    with pytest.raises(ValueError, match="MaskBank of p=0.5 for a dropout of p=0.3"):
        MaskDropout(0.3, bank=MaskBank(0.5))


def _conv_reference(module, X):
    """The TCN of ``module`` written with torch's conv1d, channels first (the
    form it was trained in before its time-major matrix products)."""
    F = torch.nn.functional
    x = X.transpose(1, 2)
    L = module.lookahead or 0
    x = F.pad(x, (0, L))
    outputs = []
    for k, stage in enumerate(module.stages):
        h = F.conv1d(F.softmax(outputs[-1], dim=1) if k else x, stage.inp.weight,
                     stage.inp.bias)  # fmt: skip
        for layer in stage.layers:
            d = layer.conv.dilation[0]
            w, b = layer.conv.weight, layer.conv.bias
            if module.lookahead is None:
                a = F.conv1d(h, w, b, padding=d, dilation=d)
            else:
                a = F.conv1d(F.pad(h, (2 * d, 0)), w, b, dilation=d)
            h = h + F.conv1d(F.relu(a), layer.mix.weight, layer.mix.bias)
        outputs.append(F.conv1d(h, stage.out.weight, stage.out.bias))
    return [o[:, :, L:].transpose(1, 2) for o in outputs]


@pytest.mark.parametrize("lookahead", [None, 0, L])
def test_tcn_computes_the_convolutions_of_its_parameters(lookahead):
    """Every stage is the dilated convolutions of its ``Conv1d`` parameters
    (so a model file saved before the matrix-product form predicts as it
    did), gradients included."""
    module = _module(lookahead, stages=3)
    X = torch.randn(2, 40, 4)
    with torch.no_grad():
        for got, want in zip(module(X), _conv_reference(module, X), strict=True):
            assert got.shape == want.shape == (2, 40, 3)
            assert_allclose(got.numpy(), want.numpy(), atol=1e-5)
    module.train()
    for stage in module.stages:
        for layer in stage.layers:
            layer.dropout.p = 0.0
    module(X)[-1].sum().backward()
    mine = [p.grad.clone() for p in module.parameters()]
    module.zero_grad()
    _conv_reference(module, X)[-1].sum().backward()
    for a, p in zip(mine, module.parameters(), strict=True):
        assert_allclose(a.numpy(), p.grad.numpy(), rtol=1e-4, atol=1e-5)


@pytest.mark.parametrize("features", ["descriptor", "joints", "descriptor+joints"])
def test_make_recommended_with_a_lookahead_streams_exactly(features):
    from skgesture import make_recommended

    data = make_gesture_streams(
        n_sequences=5, n_classes=3, n_gestures=(3, 4), random_state=1
    )
    model = make_recommended(
        joints="full20", features=features, lookahead=4, random_state=0
    )
    if features == "joints":
        assert model.named_steps["features"].statistics == "running"
    if features == "descriptor+joints":
        assert model.get_params()["features__joints__statistics"] == "running"
    # trained enough to find the gestures it is compared on
    model.set_params(
        tagger__hidden_sizes=(16,), tagger__tcn_layers=4, tagger__tcn_stages=2,
        tagger__max_epochs=6, tagger__steps_per_epoch=10, tagger__crop_length=64,
        tagger__learning_rate=1e-2, tagger__namer_hidden_sizes=(16,),
    )  # fmt: skip
    # live, an untracked frame is the last tracked one: offline too
    stages = model.named_steps["features"]
    stages = [t for _, t in getattr(stages, "transformers", [(None, stages)])]
    assert [t.fill for t in stages] == ["hold"] * len(stages)
    with torch.random.fork_rng(devices=[]):
        model.fit(data.X[:4], data.y[:4])
    x = data.X[4].copy()
    inside = np.flatnonzero(data.y[4])[10]
    x[inside : inside + 8] = 0.0  # lost tracking inside a gesture (interpolated
    # offline, fill="linear", its event here differs from the live one by a frame)
    segments = model[-1].predict_segments(model[:-1].transform([x]))[0]
    assert len(segments) >= 2
    events = StreamingRecognizer(model).recognize(x)
    got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
    assert_array_equal(got, segments[:, :3].astype(int))


def test_same_seed_same_predictions_when_training_on_two_threads():
    X = [np.random.default_rng(k).normal(size=(60, 6)) for k in range(3)]
    y = [np.r_[np.zeros(20, int), np.ones(20, int), np.zeros(20, int)]] * 3

    def fit():
        tagger = SequenceTagger(
            architecture="tcn", hidden_sizes=(8,), tcn_layers=3, max_epochs=2,
            steps_per_epoch=4, crop_length=32, dropout=0.2, fit_threads=2,
            random_state=0,
        )  # fmt: skip
        with torch.random.fork_rng(devices=[]):
            return tagger.fit(X, y).predict_proba(X)

    for a, b in zip(fit(), fit()):
        assert_array_equal(a, b)


def test_rejected_runs_stream_exactly(exact_model):
    # the confidence floor and the per-class duration judge each run on its
    # own, once it has ended: the live events are still the offline ones
    import copy

    pipe = copy.deepcopy(exact_model[0])
    X = exact_model[1]
    tagger = pipe[-1]
    F = pipe[:-1].transform(X)
    before = np.concatenate(tagger.predict_segments(F))
    # the longest run, too long for its class (max_duration)
    longest = before[np.argmax(before[:, 2] - before[:, 1])]
    k = int(np.searchsorted(tagger.classes_, longest[0]))
    too_long = (longest[2] - longest[1] - 0.5) / tagger.class_long_lengths_[k]
    # a floor between two confidences: at a tie, float32 live against float64
    # offline sums may fall either side of it
    conf = np.unique(before[:, 3])
    floor = float(conf[len(conf) // 2 - 1 : len(conf) // 2 + 1].mean())
    tagger.set_params(
        min_confidence=floor,
        min_duration=0.8,
        max_duration=float(too_long),
    )
    after = tagger.predict_segments(F)
    assert 0 < sum(len(s) for s in after) < len(before)
    assert not any(
        ((s[:, 0] == longest[0]) & (s[:, 2] - s[:, 1] >= longest[2] - longest[1])).any()
        for s in after
    )
    for x, segments in zip(X, after):
        events = StreamingRecognizer(pipe).recognize(x)
        got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
        assert_array_equal(got, segments[:, :3].astype(int))
        assert_allclose([e.confidence for e in events], segments[:, 3], atol=1e-5)


@pytest.mark.parametrize(("lag", "decision"), [(0, "frame"), (6, "frame"), (6, "run")])
def test_the_viterbi_path_streams_exactly(exact_model, lag, decision):
    # the duration-aware path is decided at a fixed lag (or a gesture's frames
    # once it ends) by the same steps offline and live: the events equal
    # predict_segments, lag frames after their end
    import copy

    pipe = copy.deepcopy(exact_model[0])
    X = exact_model[1]
    tagger = pipe[-1]
    F = pipe[:-1].transform(X)
    plain = tagger.predict(F)
    tagger.set_params(
        viterbi_penalty=3.0,
        viterbi_duration=0.7,
        viterbi_lag=lag,
        viterbi_decision=decision,
    )
    after = tagger.predict_segments(F)
    assert any(not np.array_equal(a, b) for a, b in zip(plain, tagger.predict(F)))
    delays = []
    for x, segments in zip(X, after):
        rec = StreamingRecognizer(pipe)
        events = rec.recognize(x)
        got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
        assert_array_equal(got, segments[:, :3].astype(int))
        assert_allclose([e.confidence for e in events], segments[:, 3], atol=1e-5)
        delays += [e.emitted_at - (e.end - 1) for e in events if e.end < len(x)]
    # the lag adds to the promised delay, and the events keep the promise
    without = tagger.set_params(viterbi_penalty=None).stream_lookahead
    assert rec.delays["tagger"] == without + lag
    assert delays and max(delays) <= rec.max_delay


def test_novel_runs_stream_exactly(exact_model):
    # the novelty rule judges each run on its own, once it has ended, from
    # each frame's own features: the live events are the offline ones
    import copy

    pipe = copy.deepcopy(exact_model[0])
    X = exact_model[1]
    tagger = pipe[-1]
    F = pipe[:-1].transform(X)
    before = tagger.predict_segments(F)
    # a limit between two runs' median novelty: some runs go, some stay
    medians = sorted(
        float(np.median(tagger.novelty_.score(f[int(s) : int(e)], k)))
        for f, segs in zip(F, before)
        for c, s, e, _ in segs
        for k in [int(np.searchsorted(tagger.classes_, c))]
    )
    middle = len(medians) // 2
    tagger.set_params(max_novelty=(medians[middle - 1] + medians[middle]) / 2)
    after = tagger.predict_segments(F)
    assert 0 < sum(len(s) for s in after) < sum(len(s) for s in before)
    for x, segments in zip(X, after):
        events = StreamingRecognizer(pipe).recognize(x)
        got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
        assert_array_equal(got, segments[:, :3].astype(int))
        assert_allclose([e.confidence for e in events], segments[:, 3], atol=1e-5)


@pytest.mark.parametrize("stride", [1, 2])
def test_named_runs_stream_exactly(stride):
    # the run namer names each run once it has ended, from its own rows (with
    # a stride, every phase of them): the live events are the offline ones
    # (docs/design.md, "The run namer")
    import copy

    pipe, X = _exact_pipeline(
        n_sequences=7,
        max_epochs=6,
        namer="gru",
        namer_weight=0.9,
        namer_stride=stride,
    )
    assert pipe[-1].namer_stride_ == stride
    F = pipe[:-1].transform(X)
    named = pipe[-1].predict_segments(F)
    plain = copy.deepcopy(pipe[-1]).set_params(namer_weight=0.0).predict_segments(F)
    # the namer changes some names (else this test could not fail)
    assert any(
        len(a) != len(b) or (a[:, 0] != b[:, 0]).any() for a, b in zip(named, plain)
    )
    for x, segments in zip(X, named):
        events = StreamingRecognizer(pipe).recognize(x)
        got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
        assert_array_equal(got, segments[:, :3].astype(int))
        assert_allclose([e.confidence for e in events], segments[:, 3], atol=1e-5)
    # the namer's rest rule too, at a limit that removes some events
    from skgesture._taggers._namer import namer_scores

    tagger = pipe[-1]
    args = (tagger.namer_.module_, tagger.namer_mean_, tagger.namer_scale_)
    rest = [
        np.exp(namer_scores(*args, f[int(s) : int(e)], len(tagger.classes_), stride)[0])
        for f, segments in zip(F, named)
        for _, s, e, _ in segments
    ]
    rest = np.sort(rest)  # a limit halfway between two runs' rest
    middle = len(rest) // 2
    pipe.set_params(tagger__max_namer_rest=float(rest[middle - 1 : middle + 1].mean()))
    judged = pipe[-1].predict_segments(F)
    assert 0 < sum(map(len, judged)) < sum(map(len, named))
    for x, segments in zip(X, judged):
        events = StreamingRecognizer(pipe).recognize(x)
        got = np.array([(e.label, e.start, e.end) for e in events]).reshape(-1, 3)
        assert_array_equal(got, segments[:, :3].astype(int))
