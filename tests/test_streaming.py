"""StreamingRecognizer: agreement with offline predict on real data, causality,
untracked frames, streams starting mid-gesture, bounded memory, Method C."""

import numpy as np
import pytest
import torch
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import Pipeline

from skgesture import (
    ActivitySegmenter,
    DynamicPoseWindow,
    MultiScaleClassifier,
    PoseDescriptor,
    TorchMLPClassifier,
    make_method_a,
    make_method_b,
    make_method_c,
)
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.streaming import GestureEvent, StreamingRecognizer

TRAIN_SUBJECTS = (1, 2)  # PRECOG (real Kinect v1 streams, bundled)
TEST_SUBJECTS = (8,)
ONE_HOUR = 72_000  # frames at 20 fps


def _tiny(pipe):
    return pipe.set_params(
        segmenter__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(16,), activations=("tanh",), max_epochs=30
        ),
        classifier__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=30
        ),
    )


class ConstantProba(ClassifierMixin, BaseEstimator):
    """Segmenter network stand-in: every frame has gesture probability ``p``."""

    def __init__(self, p=0.9):
        self.p = p

    def fit(self, X, y):
        self.classes_ = np.unique(y)
        return self

    def predict_proba(self, X):
        return np.tile([1.0 - self.p, self.p], (len(X), 1))


class CentroidProba(ClassifierMixin, BaseEstimator):
    """Softmax of minus mean squared distances to class means (microseconds)."""

    def fit(self, X, y):
        self.classes_, inv = np.unique(y, return_inverse=True)
        self.means_ = np.stack([X[inv == k].mean(0) for k in range(len(self.classes_))])
        return self

    def predict_proba(self, X):
        d = -((np.asarray(X)[:, None, :] - self.means_[None]) ** 2).mean(-1)
        e = np.exp(d - d.max(axis=1, keepdims=True))
        return e / e.sum(axis=1, keepdims=True)


@pytest.fixture(scope="module")
def one_thread():
    old = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(old)


@pytest.fixture(scope="module")
def precog():
    return load_precog()


def _split(data, subjects):
    idx = [i for i, g in enumerate(data.groups) if g in subjects]
    return [data.X[i] for i in idx], [data.y[i] for i in idx]


@pytest.fixture(scope="module", params=["A", "B"])
def fitted(request, precog, one_thread):
    make = make_method_a if request.param == "A" else make_method_b
    X, y = _split(precog, TRAIN_SUBJECTS)
    return _tiny(make(random_state=0)).fit(X, y)


@pytest.fixture(scope="module")
def cheap_pipeline(precog):
    """Always-active segmenter and a numpy window classifier: fast, and every
    frame is inside a period, which stresses the period buffers."""
    X, y = _split(precog, (1,))
    pipe = Pipeline([
        ("descriptor", PoseDescriptor()),
        ("segmenter", ActivitySegmenter(ConstantProba())),
        ("windows", DynamicPoseWindow(steps=(4, 2))),
        ("classifier", MultiScaleClassifier(
            CentroidProba(), steps=(4, 2), threshold_short=0.2, threshold_long=0.2
        )),
    ])  # fmt: skip
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


def test_streaming_agrees_with_offline_on_synthetic_streams(one_thread):
    data = make_gesture_streams(n_sequences=14, n_classes=5, random_state=3)
    pipe = _tiny(make_method_b(random_state=0)).fit(data.X[:10], data.y[:10])
    rec = StreamingRecognizer(pipe)
    for X in data.X[10:]:
        _assert_same_segments(rec.recognize(X), _offline(pipe, X))


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
    for X in X_test[:1]:
        one = [(e.label, e.start, e.end, e.emitted_at) for e in _push_all(rec, X)]
        many = rec.push_many(X[:100]) + rec.push_many(X[100:]) + rec.flush()
        assert [(e.label, e.start, e.end, e.emitted_at) for e in many] == one
        again = rec.recognize(X)
        assert [(e.label, e.start, e.end, e.emitted_at) for e in again] == one


def test_balanced_schedule_gives_the_same_events_a_little_later(fitted, precog):
    X_test, _ = _split(precog, TEST_SUBJECTS)
    X = X_test[1]
    eager = _push_all(StreamingRecognizer(fitted), X)
    balanced = _push_all(StreamingRecognizer(fitted, schedule="balanced"), X)
    assert len(eager) == len(balanced) > 0
    for a, b in zip(eager, balanced):
        assert (a.label, a.start, a.end) == (b.label, b.start, b.end)
        assert a.emitted_at <= b.emitted_at <= a.emitted_at + 2
    with pytest.raises(ValueError, match="schedule"):
        StreamingRecognizer(fitted, schedule="lazy")


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
    # A few untracked frames first: copied from the first tracked one, as offline.
    late = np.concatenate([np.zeros((6, 20, 3)), X])
    _assert_same_segments(_push_all(rec, late), _offline(fitted, late))
    # Many untracked frames: only the last max_backfill are copies of the first
    # tracked frame, earlier ones are rest; the events are shifted, not lost.
    very_late = np.concatenate([np.full((300, 20, 3), np.nan), X])
    events = _push_all(rec, very_late)
    assert rec.n_frames_seen == 0  # flush reset the recogniser
    assert rec.max_backfill == 2 * 15 + 2 * 4 + 1
    skipped = 300 - rec.max_backfill
    shifted = [
        (e.label, e.start - skipped, e.end - skipped, e.confidence) for e in events
    ]
    _assert_same_segments_rows(shifted, _offline(fitted, very_late[skipped:]))
    # The stream starts in the middle of the first gesture.
    first = int(np.flatnonzero(y > 0)[0])
    cut = X[first + 10 :]
    events = _push_all(rec, cut)
    _assert_same_segments(events, _offline(fitted, cut))


def test_one_hour_stream_keeps_bounded_buffers(cheap_pipeline, precog):
    X = np.concatenate(_split(precog, (1,))[0])
    stream = np.tile(X, (-(-ONE_HOUR // len(X)), 1, 1))[:ONE_HOUR]
    rec = StreamingRecognizer(cheap_pipeline, max_period=600)
    capacities = rec.buffer_capacities()
    seen, n_events = [], 0
    for lo in range(0, ONE_HOUR, 2400):
        n_events += len(rec.push_many(stream[lo : lo + 2400]))
        seen.append(rec.buffer_lengths())
    assert rec.n_frames_seen == ONE_HOUR
    assert rec.buffer_capacities() == capacities
    for lengths in seen:
        assert set(lengths) == set(capacities)
        assert all(lengths[k] <= capacities[k] for k in lengths)
    # Fixed bounds, independent of the stream length.
    assert capacities["raw"] == 10 and capacities["descriptors"] < 64
    assert capacities["windows"] == 600 // 2 + 1
    # Always active: periods are force-closed every 600 frames and decided.
    n_events += len(rec.flush())
    assert n_events >= ONE_HOUR // 600


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


def test_method_c_runs_on_completed_chunks(precog, one_thread):
    X_train, y_train = _split(precog, TRAIN_SUBJECTS)
    pipe = make_method_c(random_state=0).set_params(
        tagger__hidden_sizes=(16,), tagger__max_epochs=5
    )
    pipe.fit(X_train, y_train)
    rec = StreamingRecognizer(pipe)
    assert rec.method == "tagger"
    assert rec.lookahead == 4 + 7
    assert rec.max_delay == rec.lookahead + 10
    X_test, _ = _split(precog, (8,))
    for X in X_test + [X_test[0][:7], X_test[0][:23]]:
        events = _push_all(rec, X)
        _assert_same_segments(events, _offline(pipe, X))
        assert all(ev.delay <= rec.max_delay for ev in events)


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


def test_invalid_pipelines_and_frames(cheap_pipeline, precog):
    with pytest.raises(TypeError, match="Pipeline"):
        StreamingRecognizer(LogisticRegression())
    with pytest.raises(NotFittedError):
        StreamingRecognizer(make_method_a())
    X, y = _split(precog, (1,))
    no_segmenter = make_method_a(segment=False).set_params(
        classifier__estimator=CentroidProba()
    )
    no_segmenter.fit(X[:2], y[:2])
    with pytest.raises(ValueError, match="segment=True"):
        StreamingRecognizer(no_segmenter)
    fitted = cheap_pipeline
    fitted.set_params(segmenter__smooth_span=0.2)
    try:
        with pytest.raises(ValueError, match="integer span"):
            StreamingRecognizer(fitted)
    finally:
        fitted.set_params(segmenter__smooth_span=15)
    with pytest.raises(ValueError, match="max_period"):
        StreamingRecognizer(fitted, max_period=5)
    with pytest.raises(ValueError, match="target_names"):
        StreamingRecognizer(fitted, target_names=["one"])
    rec = StreamingRecognizer(fitted)
    with pytest.raises(ValueError, match=r"\(20, 3\)"):
        rec.push(np.zeros((25, 3)))
    assert rec.push(np.zeros(60)) == []  # a flat frame is reshaped
    with pytest.raises(ValueError, match="n_frames"):
        rec.push_many(np.zeros((4, 25, 3)))
    assert rec.flush() == []  # nothing tracked: nothing to decide
