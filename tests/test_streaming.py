"""StreamingRecognizer and the stages' incremental steps: agreement with offline
predict (Methods A, B, C, real data), causality, frame validation, untracked
frames, streams starting mid-gesture, bounded memory, the protocol itself."""

import numpy as np
import pytest
import torch
from _stand_ins import ConstantProba, make_cheap_pipeline
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import Pipeline

from skgesture import (
    ActivitySegmenter,
    PoseDescriptor,
    TorchMLPClassifier,
    make_method_a,
    make_method_b,
    make_method_c,
)
from skgesture._stream import Rows, StreamSegment, stream_frames
from skgesture._taggers._decoding import LabelRuns
from skgesture._taggers._stream import TrailingWindowStream
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.streaming import GestureEvent, StreamingRecognizer
from skgesture.utils._smoothing import LoessStepper, loess_smooth

TRAIN_SUBJECTS = (1, 2)  # PRECOG (real Kinect v1 streams, bundled)
TEST_SUBJECTS = (8,)
HALF_HOUR = 36_000  # frames at 20 fps


def _tiny(pipe):
    return pipe.set_params(
        segmenter__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(16,), activations=("tanh",), max_epochs=30
        ),
        classifier__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=30
        ),
    )


@pytest.fixture(scope="module")
def precog():
    return load_precog()


def _split(data, subjects):
    idx = [i for i, g in enumerate(data.groups) if g in subjects]
    return [data.X[i] for i in idx], [data.y[i] for i in idx]


@pytest.fixture(scope="module", params=["A", "B"])
def fitted(request, precog):
    make = make_method_a if request.param == "A" else make_method_b
    X, y = _split(precog, TRAIN_SUBJECTS)
    old = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        return _tiny(make(random_state=0)).fit(X, y)
    finally:
        torch.set_num_threads(old)


@pytest.fixture(scope="module")
def method_c(precog):
    X, y = _split(precog, TRAIN_SUBJECTS)
    pipe = make_method_c(random_state=0).set_params(
        tagger__hidden_sizes=(16,), tagger__max_epochs=5
    )
    return pipe.fit(X, y)


@pytest.fixture(scope="module")
def cheap_pipeline(precog):
    """Always-active segmenter and a numpy window classifier: fast, and every
    frame is inside a period, which stresses the period buffers."""
    X, y = _split(precog, (1,))
    pipe = make_cheap_pipeline()
    return pipe.fit(X, y)


def _offline(pipe, X, fill="hold"):
    """Offline ``predict_segments`` with the descriptor filling like the stream."""
    old = pipe.named_steps["descriptor"].fill
    pipe.set_params(descriptor__fill=fill)
    try:
        return pipe[-1].predict_segments(pipe[:-1].transform([X]))[0]
    finally:
        pipe.set_params(descriptor__fill=old)


def _sorted(rows):
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    return rows[np.lexsort((rows[:, 2], rows[:, 1]))]


def _push_all(rec, X):
    events = []
    for frame in X:
        events += rec.push(frame)
    return events + rec.flush()


def _assert_same_segments(events, offline):
    _assert_same_segments_rows([ev.to_segment() for ev in events], offline)


def _assert_same_segments_rows(rows, offline):
    got = _sorted(rows)
    want = _sorted(offline)
    assert got.shape == want.shape, (got, want)
    np.testing.assert_array_equal(got[:, :3], want[:, :3])
    np.testing.assert_allclose(got[:, 3], want[:, 3], rtol=0, atol=1e-6)


def _key(events):
    return [(e.label, e.start, e.end, e.emitted_at) for e in events]


# -- agreement with offline predict ---------------------------------------------


@pytest.mark.slow
def test_streaming_events_equal_offline_segments_on_precog(fitted, precog):
    X_test, _ = _split(precog, TEST_SUBJECTS)
    rec = StreamingRecognizer(fitted)
    n_events, delays = 0, []
    for X in X_test:
        events = _push_all(rec, X)
        _assert_same_segments(events, _offline(fitted, X))
        n_events += len(events)
        for ev in events:
            assert ev.emitted_at <= len(X) - 1
            if ev.emitted_at < len(X) - 1:  # decided before the end of the stream
                assert ev.delay >= rec.lookahead
                delays.append(ev.delay)
    assert n_events >= len(X_test)  # the tiny model finds gestures
    # Most events come within the documented bound; the others waited for their
    # period to be known long (short_length frames).
    short_length = fitted.named_steps["classifier"].short_length
    assert np.median(delays) <= rec.max_delay
    assert max(delays) <= rec.max_delay + short_length


@pytest.mark.slow
def test_method_c_events_equal_offline_segments(method_c, precog):
    rec = StreamingRecognizer(method_c)
    assert rec.delays == {"descriptor": 4, "tagger": 7 + 10}
    assert rec.lookahead == 4 and rec.max_delay == 21
    X_test, _ = _split(precog, (8,))
    streams = X_test[:3] + [X_test[0][:7], X_test[0][:23]]
    for overlap in (False, True):
        method_c.set_params(tagger__overlap=overlap)
        try:
            rec = StreamingRecognizer(method_c)
            for X in streams:
                events = _push_all(rec, X)
                _assert_same_segments(events, _offline(method_c, X))
                assert all(ev.delay <= rec.max_delay for ev in events)
        finally:
            method_c.set_params(tagger__overlap=False)


@pytest.mark.slow
def test_streaming_agrees_with_offline_on_synthetic_streams():
    data = make_gesture_streams(n_sequences=14, n_classes=5, random_state=3)
    pipe = _tiny(make_method_b(random_state=0)).fit(data.X[:10], data.y[:10])
    rec = StreamingRecognizer(pipe)
    for X in data.X[10:]:
        _assert_same_segments(rec.recognize(X), _offline(pipe, X))


@pytest.mark.parametrize("compiled", [True, False], ids=["kernel", "numpy"])
def test_descriptor_stream_gives_the_rows_of_transform(precog, monkeypatch, compiled):
    """The descriptor step equals the batch transform bit for bit, for every
    parameter of PoseDescriptor, one frame or a block at a time: with the
    compiled kernel and without it (the numpy batch code): the stream runs the
    descriptor's own batch code on the frames a row needs."""
    import skgesture._descriptor._compute as descriptor_module

    if compiled and descriptor_module._compiled_kernel() is None:
        pytest.skip("numba is not installed")
    monkeypatch.setattr(descriptor_module, "USE_COMPILED", compiled)
    X_fit = precog.X[:4]
    X = precog.X[7].copy()
    X[50:53] = 0.0  # dropouts
    X[80, 3, 1] = np.nan
    X[120] *= 0.0
    params = [
        {}, {"joints": "full20"}, {"sigma": 0}, {"border": "zero"},
        {"border": "symmetric"}, {"link_direction": "simao"},
        {"distance_scale": "spine"}, {"link_normalisation": False},
    ]  # fmt: skip
    for p in params:
        desc = PoseDescriptor(fill="hold", **p).fit(X_fit)
        for seq in (X, X[:3], X[:1]):
            want = desc.transform([seq])[0]
            for block in (1, 7, 1000):
                state = desc.stream_init()
                out = []
                for lo in range(0, len(seq), block):
                    rows, state = desc.stream_step(
                        state, stream_frames(seq[lo : lo + block], lo)
                    )
                    out.append(rows)
                out.append(desc.stream_flush(state)[0])
                data = np.concatenate([r.data for r in out])
                mask = np.concatenate([r.mask for r in out])
                # One implementation: the rows are transform's, bit for bit.
                np.testing.assert_array_equal(data, np.ma.getdata(want), str(p))
                np.testing.assert_array_equal(
                    mask, np.ma.getmaskarray(want).any(axis=1)
                )
                time = np.concatenate([r.time for r in out])
                assert np.all(np.diff(time) >= 0) and time[-1] == len(seq) - 1


@pytest.mark.parametrize("span", [1, 3, 5, 7, 15, 21])
def test_loess_stepper_equals_loess_smooth(span):
    rng = np.random.RandomState(span)
    for n in (1, 2, 5, span - 1, span, span + 1, 60):
        if n < 1:
            continue
        y = rng.normal(size=(n, 2))
        for chunk in (1, 3, 50):
            st_ = LoessStepper(span, 2)
            parts = []
            for lo in range(0, n, chunk):
                block = y[lo : lo + chunk]
                first, vals, _ = st_.step(block, np.arange(lo, lo + len(block)))
                assert first == sum(len(p) for p in parts)
                parts.append(vals)
            parts.append(st_.flush(n - 1)[1])
            np.testing.assert_array_equal(np.concatenate(parts), loess_smooth(y, span))


def test_events_before_a_frame_do_not_depend_on_later_frames(fitted, precog):
    X_test, _ = _split(precog, TEST_SUBJECTS)
    X = X_test[0]
    t = len(X) // 2
    other_future = np.concatenate([X[:t], X[::-1][: len(X) - t]])
    runs = []
    for stream in (X, other_future):
        rec = StreamingRecognizer(fitted)
        runs.append([ev for f in stream[:t] for ev in rec.push(f)])
    assert runs[0] == runs[1]
    assert all(ev.emitted_at < t for ev in runs[0])


def test_push_many_and_recognize_match_push(fitted, precog):
    X_test, _ = _split(precog, TEST_SUBJECTS)
    rec = StreamingRecognizer(fitted)
    X = X_test[0]
    one = _key(_push_all(rec, X))
    many = rec.push_many(X[:100]) + rec.push_many(X[100:]) + rec.flush()
    assert _key(many) == one
    assert _key(rec.recognize(X)) == one


def test_untracked_frames_are_held(fitted, precog):
    """Zeros and NaN frames (dropouts) are held: the events equal offline
    predict with ``fill="hold"`` exactly."""
    X_test, _ = _split(precog, TEST_SUBJECTS)
    rng = np.random.RandomState(0)
    rec = StreamingRecognizer(fitted)
    for X in X_test[:2]:
        X = X.copy()
        for start in rng.choice(len(X) - 5, size=6, replace=False):
            X[start : start + rng.randint(1, 5)] = 0.0
        X[rng.choice(len(X), size=3, replace=False), 4, 1] = np.nan
        _assert_same_segments(_push_all(rec, X), _offline(fitted, X))


def test_linear_fill_differs_only_around_dropouts(fitted, precog):
    """Against offline linear interpolation, every event more than 30 frames
    away from a dropout is the same."""
    X_test, _ = _split(precog, TEST_SUBJECTS)
    X = X_test[1].copy()
    dropouts = np.array([60, 61, 62, 150, 151])
    X[dropouts] = 0.0
    rec = StreamingRecognizer(fitted)
    got = {tuple(int(v) for v in ev.to_segment()[:3]) for ev in rec.recognize(X)}
    want = {
        tuple(int(v) for v in row[:3]) for row in _offline(fitted, X, fill="linear")
    }

    def far(seg):
        return np.abs(dropouts[:, None] - np.arange(seg[1], seg[2])).min() > 30

    assert {s for s in got if far(s)} == {s for s in want if far(s)}


def test_stream_starting_untracked_or_mid_gesture(fitted, precog):
    X_test, y_test = _split(precog, TEST_SUBJECTS)
    X, y = X_test[2], y_test[2]
    rec = StreamingRecognizer(fitted)
    # A few untracked frames first: copies of the first tracked one, as offline.
    late = np.concatenate([np.zeros((6, 20, 3)), X])
    _assert_same_segments(_push_all(rec, late), _offline(fitted, late))
    # Many untracked frames: only the last max_backfill wait for the first
    # tracked frame, earlier ones are handed on as rest at once; they are far
    # from every tracked frame, so the events are still those of offline.
    very_late = np.concatenate([np.full((300, 20, 3), np.nan), X])
    events = _push_all(rec, very_late)
    assert rec.n_frames_seen == 0  # flush reset the recogniser
    _assert_same_segments(events, _offline(fitted, very_late))
    # The stream starts in the middle of the first gesture.
    first = int(np.flatnonzero(y > 0)[0])
    cut = X[first + 10 :]
    _assert_same_segments(_push_all(rec, cut), _offline(fitted, cut))


# -- safety: untracked frames and bad frames -------------------------------------


def test_lost_tracking_never_gives_an_event(fitted, method_c, cheap_pipeline, precog):
    """All-zero and all-NaN streams, and long dropouts, are rest (contract 2) in
    every method, even with an always-active segmenter network."""
    X = _split(precog, TEST_SUBJECTS)[0][0]
    gap = X.copy()
    gap[100:300] = 0.0
    for pipe in (fitted, method_c, cheap_pipeline):
        rec = StreamingRecognizer(pipe)
        assert rec.recognize(np.zeros((200, 20, 3))) == []
        assert rec.recognize(np.full((150, 20, 3), np.nan)) == []
        for ev in rec.recognize(gap):
            assert ev.end <= 100 or ev.start >= 300, ev


def _bad_frames():
    good = np.full((20, 3), 0.5)
    inf = good.copy()
    inf[4, 1] = np.inf
    return [
        ("transposed", good.T, ValueError, r"frame 5 .*shape \(3, 20\).*\(20, 3\)"),
        ("flat", good.ravel(), ValueError, r"frame 5 .*shape \(60,\)"),
        ("inf", inf, ValueError, r"frame 5 of the stream is invalid.*infinite"),
        ("huge", good * 1e200, ValueError, r"frame 5 of the stream .*magnitude"),
        ("-huge", -good * 1e6, ValueError, r"frame 5 of the stream .*magnitude"),
        ("string", "frame", TypeError, r"frame 5 of the stream must be an array"),
        ("none", None, TypeError, r"frame 5 of the stream must be an array"),
        ("text", np.full((20, 3), "a"), ValueError, r"frame 5 .*numeric"),
        ("complex", good + 1j, ValueError, r"frame 5 .*(complex|real)"),
        ("joints", np.zeros((25, 3)), ValueError, r"frame 5 .*\(25, 3\)"),
    ]


@pytest.mark.parametrize("name, frame, error, match", _bad_frames())
def test_push_refuses_a_bad_frame_and_names_it(cheap_pipeline, precog, name, frame,
                                               error, match):  # fmt: skip
    X = _split(precog, (1,))[0][0][:200]
    rec = StreamingRecognizer(cheap_pipeline)
    want = _key(rec.recognize(X))
    events = []
    for f in X[:5]:
        events += rec.push(f)
    with pytest.raises(error, match=match):
        rec.push(frame)
    assert rec.n_frames_seen == 5
    # The bad frame changed nothing: the stream goes on as if it never came.
    for f in X[5:]:
        events += rec.push(f)
    assert _key(events + rec.flush()) == want


def test_push_many_names_the_bad_frame(cheap_pipeline, precog):
    X = _split(precog, (1,))[0][0][:50].copy()
    X[37, 2, 0] = -np.inf
    rec = StreamingRecognizer(cheap_pipeline)
    rec.push_many(X[:10])
    with pytest.raises(ValueError, match="frame 37 of the stream is invalid"):
        rec.push_many(X[10:])
    with pytest.raises(ValueError, match=r"\(n_frames, 20, 3\)"):
        rec.push_many(np.zeros((4, 3, 20)))


def test_masked_joints_are_untracked(cheap_pipeline, precog):
    X = _split(precog, (1,))[0][0][:120]
    masked = np.ma.masked_array(X.copy(), mask=np.zeros(X.shape, bool))
    masked.mask[40:60, 3] = True
    nan = X.copy()
    nan[40:60, 3] = np.nan
    rec = StreamingRecognizer(cheap_pipeline)
    a = []
    for f in masked:
        a += rec.push(f)
    assert _key(a + rec.flush()) == _key(rec.recognize(nan))


# -- the protocol ----------------------------------------------------------------


class MeanTagger(ClassifierMixin, BaseEstimator):
    """A tagger built outside skgesture: a per-frame logistic regression whose
    probabilities are averaged over a centred window of 5 frames, as a
    bidirectional network would read a window of context. It streams through
    the protocol alone, with TrailingWindowStream (look-back and look-ahead 2)."""

    def fit(self, X, y):
        self.net_ = LogisticRegression(max_iter=200).fit(
            np.concatenate(X), np.concatenate(y)
        )
        self.classes_ = self.net_.classes_
        return self

    def _window_proba(self, rows):
        P = self.net_.predict_proba(np.asarray(rows))
        idx = np.clip(np.arange(len(P))[:, None] + np.arange(-2, 3), 0, len(P) - 1)
        return P[idx].mean(axis=1)

    def predict_segments(self, X):
        out = []
        for x in X:
            rest = np.ma.getmaskarray(x).any(axis=1)
            P = self._window_proba(np.ma.getdata(x))
            runs = LabelRuns(self.classes_, 5)
            segs = runs.feed(0, P, P, rest, np.zeros(len(P), int))
            segs += runs.end(len(P), 0)
            out.append(np.array([s[:4] for s in segs], float).reshape(-1, 4))
        return out

    def stream_init(self, **options):
        return TrailingWindowStream(self._window_proba, self.classes_, 2, 2, 1, 5)

    def stream_step(self, state, rows):
        return state.step(rows), state

    def stream_flush(self, state):
        return state.flush(), state

    stream_lookahead = 2 + 0 + 1


def test_any_stage_with_the_protocol_streams(precog):
    X, y = _split(precog, (1,))
    X, y = X[:2], y[:2]
    pipe = Pipeline([("descriptor", PoseDescriptor(fill="hold")),
                     ("tagger", MeanTagger())]).fit(X, y)  # fmt: skip
    rec = StreamingRecognizer(pipe)
    assert rec.delays == {"descriptor": 4, "tagger": 3}
    X_test = _split(precog, (8,))[0][0]
    rows = pipe[-1].predict_segments(pipe[:-1].transform([X_test]))[0]
    events = _push_all(rec, X_test)
    assert len(events) > 0
    _assert_same_segments(events, rows)


def test_a_stage_without_the_protocol_is_refused(precog):
    from sklearn.preprocessing import FunctionTransformer

    X, _ = _split(precog, (1,))
    pipe = Pipeline([
        ("descriptor", PoseDescriptor().fit(X[:1])),
        ("scale", FunctionTransformer(lambda Z: Z)),
        ("tagger", MeanTagger()),
    ])  # fmt: skip
    with pytest.raises(TypeError, match="'scale' .*stream_init"):
        StreamingRecognizer(pipe)


def test_segments_carry_the_frame_that_decided_them():
    s = StreamSegment(3, 10, 20, 0.5, 31)
    assert (s.label, s.end, s.time) == (3, 20, 31)
    rows = Rows.empty((4,))
    assert len(rows) == 0 and rows.data.shape == (0, 4)


# -- properties of the recogniser -------------------------------------------------


@settings(max_examples=15, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])  # fmt: skip
@given(
    start=st.integers(0, 150),
    length=st.integers(1, 260),
    dropout=st.integers(0, 40),
    cut=st.integers(0, 260),
)
def test_events_lie_inside_the_stream_and_reset_forgets(
    cheap_pipeline, precog, start, length, dropout, cut
):
    X = _split(precog, (1,))[0][0][start : start + length].copy()
    X[: min(dropout, len(X))] = 0.0
    rec = StreamingRecognizer(cheap_pipeline, max_period=60)
    events = []
    for t, frame in enumerate(X):
        new = rec.push(frame)
        assert all(ev.emitted_at == t for ev in new)
        events += new
    events += rec.flush()
    for ev in events:
        assert 0 <= ev.start < ev.end <= len(X)
        assert ev.end - 1 <= ev.emitted_at <= len(X) - 1
        assert ev.label in rec.classes_
    # reset mid-stream: nothing of the old stream comes out afterwards.
    for frame in X[: min(cut, len(X))]:
        rec.push(frame)
    rec.reset()
    assert rec.n_frames_seen == 0 and rec.flush() == []
    assert _key(rec.recognize(X)) == _key(events)


# -- bounded memory, max_period, misc --------------------------------------------


@pytest.mark.slow
def test_long_stream_keeps_bounded_buffers(cheap_pipeline, precog):
    """Half an hour at 20 fps (the benchmark's soak streams a full hour)."""
    X = np.concatenate(_split(precog, (1,))[0])
    stream = np.tile(X, (-(-HALF_HOUR // len(X)), 1, 1))[:HALF_HOUR]
    rec = StreamingRecognizer(cheap_pipeline, max_period=600)
    seen, n_events = [], 0
    for lo in range(0, HALF_HOUR, 2400):
        n_events += len(rec.push_many(stream[lo : lo + 2400]))
        seen.append(rec.buffer_lengths())
    assert rec.n_frames_seen == HALF_HOUR
    keys = set(seen[0])
    assert {"segmenter.scores", "classifier.windows"} <= keys
    worst = {k: max(s[k] for s in seen) for k in keys}
    # Fixed bounds, independent of the stream length.
    assert all(worst[k] < 64 for k in keys if k.startswith("descriptor."))
    assert worst["segmenter.scores"] < 64
    assert worst["classifier.windows"] <= 600 // 2 + 1
    assert worst["classifier.descriptors"] <= 600
    # Always active: periods are force-closed every 600 frames and decided.
    n_events += len(rec.flush())
    assert n_events >= HALF_HOUR // 600


def test_max_period_force_closes_periods(cheap_pipeline, precog):
    X = np.concatenate(_split(precog, (1,))[0])[:1000]
    rec = StreamingRecognizer(cheap_pipeline, max_period=200)
    events = rec.recognize(X)
    assert events
    for ev in events:  # no event crosses a forced period boundary
        assert ev.start // 200 == (ev.end - 1) // 200
    # Without the cap the whole stream is one period, as offline.
    rec = StreamingRecognizer(cheap_pipeline, max_period=10_000)
    _assert_same_segments(rec.recognize(X), _offline(cheap_pipeline, X))


def test_early_decision_trades_agreement_for_delay(fitted, precog):
    X_test, _ = _split(precog, TEST_SUBJECTS)
    base, early = [], []
    for X in X_test:
        base += StreamingRecognizer(fitted).recognize(X)
        early += StreamingRecognizer(fitted, early_decision=True).recognize(X)
    assert early and base
    assert np.median([e.delay for e in early]) <= np.median([e.delay for e in base])
    assert max(e.delay for e in early) <= max(e.delay for e in base)


def test_threads_are_set_for_each_call_and_restored(cheap_pipeline, precog):
    X = _split(precog, (1,))[0][0][:40]
    torch.set_num_threads(2)
    rec = StreamingRecognizer(cheap_pipeline)
    rec.recognize(X)
    assert torch.get_num_threads() == 2
    with pytest.raises(ValueError, match="n_threads"):
        StreamingRecognizer(cheap_pipeline, n_threads=0)


def test_gesture_event_fields_and_names(fitted, precog):
    X_test, _ = _split(precog, TEST_SUBJECTS)
    rec = StreamingRecognizer(fitted, target_names=precog.target_names)
    events = rec.recognize(X_test[0])
    assert events
    for ev in events:
        assert isinstance(ev, GestureEvent)
        assert ev.name == precog.target_names[ev.label - 1]
        assert ev.n_frames == ev.end - ev.start > 0
        assert ev.delay == ev.emitted_at - ev.end + 1
        assert ev.label in rec.classes_


def test_invalid_pipelines_and_options(cheap_pipeline, precog):
    with pytest.raises(TypeError, match="Pipeline"):
        StreamingRecognizer(LogisticRegression())
    with pytest.raises(NotFittedError):
        StreamingRecognizer(make_method_a())
    X, y = _split(precog, (1,))
    seg = Pipeline(
        [
            ("descriptor", PoseDescriptor()),
            ("segmenter", ActivitySegmenter(ConstantProba())),
        ]
    ).fit(X, y)
    with pytest.raises(TypeError, match="predict_segments"):
        StreamingRecognizer(seg)
    fitted = cheap_pipeline
    fitted.set_params(segmenter__smooth_span=0.2)
    try:
        with pytest.raises(ValueError, match="integer span"):
            StreamingRecognizer(fitted)
    finally:
        fitted.set_params(segmenter__smooth_span=15)
    fitted.set_params(windows__steps=(4, 3))
    try:
        with pytest.raises(ValueError, match="same steps"):
            StreamingRecognizer(fitted).recognize(X[0][:200])
    finally:
        fitted.set_params(windows__steps=(4, 2))
    with pytest.raises(ValueError, match="max_period"):
        StreamingRecognizer(fitted, max_period=5)
    with pytest.raises(ValueError, match="max_backfill"):
        StreamingRecognizer(fitted, max_backfill=-1)
    with pytest.raises(ValueError, match="target_names"):
        StreamingRecognizer(fitted, target_names=["one"])
    rec = StreamingRecognizer(fitted)
    assert rec.flush() == []  # nothing pushed: nothing to decide
    assert rec.push(np.zeros((20, 3))) == [] and rec.flush() == []


# -- the protocol: options routed to the stages that declare them -----------------


def test_each_stage_refuses_an_option_it_does_not_declare(cheap_pipeline):
    desc = cheap_pipeline.named_steps["descriptor"]
    assert desc._stream_options == ("max_backfill",)
    desc.stream_init(max_backfill=3)  # its own option
    with pytest.raises(TypeError, match="unknown option.*max_period.*max_backfill"):
        desc.stream_init(max_period=100)
    seg = cheap_pipeline.named_steps["segmenter"]
    with pytest.raises(TypeError, match="early_decision; it takes no option"):
        seg.stream_init(early_decision=True)


def test_recogniser_routes_options_and_refuses_one_no_stage_takes(
    cheap_pipeline, method_c
):
    rec = StreamingRecognizer(cheap_pipeline, max_period=300, max_backfill=5)
    routed = dict(zip([name for name, _ in cheap_pipeline.steps], rec._options))
    assert routed["descriptor"] == {"max_backfill": 5}
    assert routed["segmenter"] == {} and routed["windows"] == {}
    assert routed["classifier"] == {"max_period": 300, "early_decision": False}
    # Method C has no stage that decides early: the option is an error, not
    # silently ignored.
    with pytest.raises(ValueError, match="early_decision=True is an option of no"):
        StreamingRecognizer(method_c, early_decision=True)
    assert dict(zip([n for n, _ in method_c.steps], StreamingRecognizer(
        method_c, max_period=50)._options))["tagger"] == {"max_period": 50}  # fmt: skip


def test_method_c_stream_enforces_max_period(method_c, precog):
    """max_period bounds Method C's live runs (it was dropped before)."""
    X = np.concatenate(_split(precog, TEST_SUBJECTS)[0])
    offline = _offline(method_c, X)
    longest = int(max(offline[:, 2] - offline[:, 1]))
    cap = max(longest // 2, 2)
    assert longest > cap  # the cap does cut
    events = StreamingRecognizer(method_c, max_period=cap).recognize(X)
    assert events and max(ev.end - ev.start for ev in events) <= cap


def test_window_step_hands_on_the_offline_lazy_windows(cheap_pipeline, precog):
    """DynamicPoseWindow's step hands on the DynamicPoses of transform, and
    the offline transform is that step over the whole sequence."""
    from skgesture._windows import DynamicPoses

    pipe = cheap_pipeline
    D = pipe[:2].transform([_split(precog, (1,))[0][0][:120]])[0]
    win = pipe.named_steps["windows"]
    state = win.stream_init()
    rows = Rows(np.ma.getdata(D), np.ma.getmaskarray(D).any(axis=1),
                np.arange(len(D)))  # fmt: skip
    out, state = win.stream_step(state, rows)
    lazy = out.info["windows"]
    assert isinstance(lazy, DynamicPoses)
    assert (lazy.steps, lazy.n_poses) == (tuple(win.steps), win.n_poses)
    offline = win.set_params(lazy=True).transform([D])[0]
    win.set_params(lazy=False)
    np.testing.assert_array_equal(np.asarray(lazy), np.asarray(offline))
    np.testing.assert_array_equal(lazy.rest_rows(), offline.rest_rows())
    assert win.stream_flush(state)[0] is None
