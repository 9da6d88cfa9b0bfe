"""Frame rates (issue 17): a model trained at one rate works at another.

``skgesture._rate`` resamples a recording to the model's rate and maps the
labels back; :class:`~skgesture.GesturePipeline` records the training rate
(``fps_``) and resamples in ``predict``; the streaming recogniser puts the same
rule's incremental step in front of the stages. Cheap stand-ins
(``tests/_stand_ins.py``) keep the models fast; one slow test streams a tiny
real Method B.
"""

# SPDX-License-Identifier: BSD-3-Clause

import copy
import math
import pickle
from fractions import Fraction

import joblib
import numpy as np
import pytest
import sklearn
from _stand_ins import make_cheap_pipeline
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate
from sklearn.pipeline import Pipeline

from skgesture import (
    GesturePipeline,
    TorchMLPClassifier,
    make_method_a,
    make_method_b,
    make_method_c,
    make_recommended,
)
from skgesture._rate import (
    FrameClock,
    FrameResampler,
    RateMap,
    check_fps,
    estimate_fps,
    frames_back,
    frames_from_timestamps,
    resample,
    segments_back,
)
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.streaming import StdinSource, StreamingRecognizer
from skgesture.utils import missing_frames, segments_to_labels

MODEL_FPS = 30.0
RATES = (15, 20, 60, 10, 29.97, 7.3, 45, 120)
NO_CAP = 10**6  # max_period that no test stream reaches (streams equal offline)


# -- fixtures ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def streams():
    """Synthetic streams at the model's 30 fps: 5 to train on, 3 held out."""
    return make_gesture_streams(n_sequences=8, n_classes=4, fps=30, random_state=1)


@pytest.fixture(scope="module")
def cheap(streams):
    """The cheap Method B (always-active segmenter, numpy window classifier),
    filling untracked frames as the stream does, trained at 30 fps."""
    pipe = GesturePipeline(make_cheap_pipeline().steps)
    pipe.set_params(descriptor__fill="hold")
    return pipe.fit(streams.X[:5], streams.y[:5], fps=streams.fps)


@pytest.fixture(scope="module")
def tagger(streams):
    """A tiny Method C (BiLSTM tagger): predict_proba and decision_function."""
    pipe = make_method_c(random_state=0).set_params(
        tagger__hidden_sizes=(4,), tagger__max_epochs=2
    )
    return pipe.fit(streams.X[:3], streams.y[:3], fps=streams.fps)


def _with_dropouts(x, seed=0):
    """``x`` with untracked frames: runs of zeros, NaN joints, a NaN frame."""
    x = np.array(x, dtype=float)
    rng = np.random.RandomState(seed)
    for start in rng.choice(len(x) - 5, size=4, replace=False):
        x[start : start + rng.randint(1, 4)] = 0.0
    x[rng.randint(len(x)), 3] = np.nan
    x[rng.randint(len(x))] = np.nan
    return x


def _reference_resample(x, from_fps, to_fps):
    """The rule of the module docstring, frame by frame, in exact fractions:
    interpolation of the two input frames around each model-rate frame, which
    is untracked (zeros) when one of them is, or when an input frame nearest to
    it in time (ties: the earlier model-rate frame) is."""
    f, g = Fraction(str(from_fps)), Fraction(str(to_fps))
    untracked = missing_frames(x)
    out, lost = [], []
    j = 0
    while (p := j * f / g) <= len(x) - 1:
        lo, w = math.floor(p), p - math.floor(p)
        if w == 0:
            out.append(x[lo].copy())
            lost.append(untracked[lo])
        else:
            out.append((1 - float(w)) * x[lo] + float(w) * x[lo + 1])
            lost.append(untracked[lo] or untracked[lo + 1])
        j += 1
    for i in np.flatnonzero(untracked):
        q = i * g / f  # the input frame's time in model-rate frames
        nearest = math.ceil(q - Fraction(1, 2))  # a tie goes to the earlier one
        lost[min(nearest, len(out) - 1)] = True
    out = np.array(out).reshape(-1, *x.shape[1:])
    out[np.array(lost, dtype=bool)] = 0.0
    return out


def _rows(segments):
    rows = np.asarray(segments, dtype=float).reshape(-1, 4)
    return rows[np.lexsort((rows[:, 2], rows[:, 1]))]


def _event_rows(events):
    return _rows([ev.to_segment() for ev in events])


# -- the resampling rule -----------------------------------------------------------


def test_resampling_is_the_identity_at_the_same_rate(streams):
    """At the model's own rate nothing is computed: the input object itself."""
    x = _with_dropouts(streams.X[5])
    assert resample(x, 30, 30) is x
    assert resample(x, 30, 30.0 * (1 + 1e-12)) is x  # float rounding of one rate
    masked = np.ma.masked_array(x, mask=np.zeros_like(x, bool))
    assert resample(masked, 20, 20) is masked
    labels = np.arange(len(x))
    assert frames_back(labels, 30, 30, len(x)) is labels
    segs = np.array([[1, 2, 5]])
    assert segments_back(segs, 30, 30, 9) is segs


def test_model_predicts_bit_for_bit_without_a_rate_or_at_its_own(cheap, streams):
    """No fps, or the model's own, is the plain Pipeline's computation."""
    X = [_with_dropouts(x, seed=k) for k, x in enumerate(streams.X[5:])]
    plain = Pipeline(cheap.steps)
    want = plain.predict(X)
    want_segments = plain[-1].predict_segments(plain[:-1].transform(X))
    for fps in (None, 30, 30.0, [30, 30.0, 30], np.full(3, 30.0)):
        got = cheap.predict(X, fps=fps)
        assert all(np.array_equal(a, b) for a, b in zip(got, want))
        got = cheap.predict_segments(X, fps=fps)
        assert all(np.array_equal(a, b) for a, b in zip(got, want_segments))
    assert cheap.score(X, streams.y[5:]) == cheap.score(X, streams.y[5:], fps=30)


def test_tagger_outputs_bit_for_bit_at_its_rate_and_one_row_per_frame(tagger, streams):
    X = streams.X[5:7]
    plain = Pipeline(tagger.steps)
    for method in ("predict", "predict_proba", "decision_function"):
        want = getattr(plain, method)(X)
        got = getattr(tagger, method)(X, fps=30)
        assert all(np.array_equal(a, b) for a, b in zip(got, want)), method
        for fps in (15, 60, 29.97):
            out = getattr(tagger, method)(X, fps=fps)
            assert [len(o) for o in out] == [len(x) for x in X], (method, fps)
    proba = tagger.predict_proba(X, fps=15)
    assert all(np.allclose(p.sum(axis=1), 1) for p in proba)


def test_taking_every_2nd_or_3rd_frame_copies_them(streams):
    x = np.array(streams.X[5])
    x = x[~missing_frames(x)]  # tracked throughout
    for k in (2, 3, 4):
        assert np.array_equal(resample(x, 30, 30 / k), x[::k])
    # a lost frame is not dropped: the model-rate frame nearest to it is lost
    x[7] = 0.0
    got = resample(x, 30, 15)
    assert missing_frames(got).tolist()[2:5] == [False, True, False]  # 7 -> 3
    assert np.array_equal(np.delete(got, 3, 0), np.delete(x[::2], 3, 0))


@pytest.mark.parametrize("from_fps, to_fps", [(30, 60), (30, 45), (29.97, 30),
                                              (15, 30), (60, 30), (30, 7.3),
                                              (20, 30), (10, 30)])  # fmt: skip
def test_resampling_follows_the_rule_and_never_interpolates_across_a_gap(
    streams, from_fps, to_fps
):
    x = _with_dropouts(streams.X[6][:400], seed=3)
    got = resample(x, from_fps, to_fps)
    want = _reference_resample(x, from_fps, to_fps)
    assert got.shape == want.shape
    assert len(got) == math.floor((len(x) - 1) * to_fps / from_fps + 1e-9) + 1
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    assert not np.isnan(got).any()  # untracked frames are zeros
    assert missing_frames(got).sum() >= 1
    # every untracked input frame takes its label from an untracked frame
    back = frames_back(missing_frames(got), from_fps, to_fps, len(x))
    assert back[missing_frames(x)].all()


@pytest.mark.parametrize("from_fps, to_fps", [(15, 30), (10, 30), (60, 30),
                                              (29.97, 30), (20, 30), (7.3, 30),
                                              (30, 45)])  # fmt: skip
def test_incremental_step_equals_the_offline_resample(streams, from_fps, to_fps):
    """Offline and live are one implementation: blocks of any size give the
    frames of :func:`resample` bit for bit, each as soon as it is complete."""
    x = _with_dropouts(streams.X[7][:500], seed=5)
    want = resample(x, from_fps, to_fps)
    rng = np.random.RandomState(0)
    for sizes in ([1] * len(x), None):
        step = FrameResampler(from_fps, to_fps)
        parts, times, pushed = [], [], 0
        while pushed < len(x):
            k = 1 if sizes else int(rng.randint(1, 40))
            out = step.push(x[pushed : pushed + k])
            pushed += len(x[pushed : pushed + k])
            assert np.all(out.time <= pushed - 1)  # complete with the frames seen
            if len(out):
                assert np.array_equal(out.mask, missing_frames(out.data))
            parts.append(out.data)
            times.append(out.time)
        last = step.flush()
        assert last.time.tolist() == [len(x) - 1]  # the last one, at the end
        got = np.concatenate([*parts, last.data])
        assert np.array_equal(got, want)
        times = np.concatenate(times)
        rates = RateMap(from_fps, to_fps)
        assert np.array_equal(times, rates.ready_at(np.arange(len(want) - 1)))
        assert step.n_in == len(x) and step.n_out == len(want)
        assert step.flush() is None


def test_the_map_back_gives_every_input_frame_its_nearest_model_frame():
    for from_fps, to_fps in [(15, 30), (60, 30), (29.97, 30), (7.3, 30), (45, 30)]:
        n = 97
        rates = RateMap(from_fps, to_fps)
        n_out = rates.n_out(n)
        t_in, t_out = np.arange(n) / from_fps, np.arange(n_out) / to_fps
        dist = np.abs(t_in[:, None] - t_out[None, :])
        nearest = rates.nearest(np.arange(n), n_out)
        best = dist.min(axis=1)
        assert np.allclose(dist[np.arange(n), nearest], best, atol=1e-9)
        # segments: the input frames that take their label from them
        labels = np.repeat(np.arange(1, 6), math.ceil(n_out / 5))[:n_out]
        segs = np.array([[c, np.argmax(labels == c), n_out - np.argmax(
            labels[::-1] == c)] for c in range(1, 6)])  # fmt: skip
        back = segments_back(segs, from_fps, to_fps, n)
        assert np.array_equal(
            segments_to_labels(back, n), frames_back(labels, from_fps, to_fps, n)
        )


# -- predict at another rate -------------------------------------------------------


@pytest.mark.parametrize("fps", RATES)
def test_one_label_per_input_frame_at_every_rate(cheap, streams, fps):
    X = [_with_dropouts(x, seed=k)[:700] for k, x in enumerate(streams.X[5:])]
    labels = cheap.predict(X, fps=fps)
    segments = cheap.predict_segments(X, fps=fps)
    for x, lab, seg in zip(X, labels, segments):
        assert lab.shape == (len(x),)
        assert np.all((seg[:, 1] >= 0) & (seg[:, 1] < seg[:, 2]))
        assert np.all(seg[:, 2] <= len(x))
        # the segments are the labelled frames
        assert np.array_equal(segments_to_labels(seg[:, :3].astype(int), len(x)), lab)
        assert not lab[missing_frames(x)].any()  # untracked frames are rest
    y = [y[: len(x)] for x, y in zip(X, streams.y[5:])]
    assert 0 <= cheap.score(X, y, fps=fps) <= 1  # against the labels as they are


def test_per_sequence_rates_resample_only_the_others(cheap, streams):
    X = streams.X[5:8]
    want = cheap.predict(X)
    got = cheap.predict([X[0], X[1][::2], X[2]], fps=[30, 15, 30])
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[2], want[2])
    assert len(got[1]) == len(X[1][::2])


def test_a_recording_duplicated_at_60_fps_gets_the_same_segments_in_seconds(
    cheap, tagger, streams
):
    for model in (cheap, tagger):
        for x30 in streams.X[5:8]:
            x60 = np.repeat(x30, 2, axis=0)  # every frame twice
            seg30 = model.predict_segments([x30])[0]
            seg60 = model.predict_segments([x60], fps=60)[0]
            assert len(seg30) or model is tagger  # the tiny tagger may find none
            assert np.array_equal(seg60[:, 0], seg30[:, 0])
            assert np.array_equal(seg60[:, 1:3] / 60, seg30[:, 1:3] / 30)
            assert np.array_equal(seg60[:, 3], seg30[:, 3])
            labels = model.predict([x60], fps=60)[0]
            assert np.array_equal(labels, np.repeat(model.predict([x30])[0], 2))


def test_masked_joints_and_bad_frames_at_another_rate(cheap, streams):
    x = np.array(streams.X[5][:300])
    masked = np.ma.masked_array(x, mask=np.zeros_like(x, bool))
    masked[40:50, 3] = np.ma.masked
    labels = cheap.predict([masked], fps=15)[0]
    assert not labels[40:50].any()  # untracked: rest
    bad = x.copy()
    bad[17, 2, 1] = np.inf
    with pytest.raises(ValueError, match=r"X\[1\] contains infinite.*frame 17"):
        cheap.predict([x, bad], fps=15)
    with pytest.raises(ValueError, match=r"X\[0\] has frames of shape \(19, 3\)"):
        cheap.predict([x[:, :19]], fps=15)


# -- timestamps --------------------------------------------------------------------


def test_timestamps_with_gaps_become_untracked_frames():
    x = np.arange(1.0, 6.0)[:, None, None] * np.ones((5, 20, 3))
    t = np.array([0, 1, 2, 5, 6]) / 30
    out, source = frames_from_timestamps(x, t, fps=30)
    assert source.tolist() == [0, 1, 2, -1, -1, 3, 4]
    assert missing_frames(out).tolist() == [False] * 3 + [True] * 2 + [False] * 2
    assert np.array_equal(out[source >= 0], x)
    # jitter rounds to the nominal period; only differences matter
    out, source = frames_from_timestamps(x, 1000 + t + [0, 0.004, -0.003, 0, 0.01], 30)
    assert source.tolist() == [0, 1, 2, -1, -1, 3, 4]
    with pytest.warns(UserWarning, match="dropped 1 frame"):
        _, source = frames_from_timestamps(x, [0, 0.1, 0.1, 0.2, 0.3], fps=10)
    assert source.tolist() == [0, 1, 3, 4]
    with pytest.warns(UserWarning, match="left out"):
        out, _ = frames_from_timestamps(x[:2], [0.0, 100.0], fps=10, max_gap=1.0)
    assert len(out) == 12
    with pytest.raises(ValueError, match="timestamp 1 is nan"):
        frames_from_timestamps(x[:2], [0.0, np.nan], fps=10)
    with pytest.raises(ValueError, match="one time per frame"):
        frames_from_timestamps(x, [0.0], fps=10)
    assert estimate_fps(t) == pytest.approx(30)
    assert estimate_fps([1.0]) is None


def test_live_sources_and_recordings_share_the_clock():
    import io

    from skgesture.streaming import _sources

    assert _sources._FrameClock is FrameClock
    x = np.linspace(0.1, 1.0, 60).reshape(1, 20, 3) * np.arange(1, 6)[:, None, None]
    t = [0.0, 0.05, 0.1, 0.3, 0.35]
    lines = "".join(
        f"{ti},{','.join(map(repr, f.ravel().tolist()))}\n" for ti, f in zip(t, x)
    )
    live = np.array(list(StdinSource(io.StringIO(lines), fps=20, timestamps=True)))
    offline, _ = frames_from_timestamps(x, t, fps=20)
    assert np.array_equal(live, offline)


# -- streaming ---------------------------------------------------------------------


@pytest.mark.parametrize("fps", [15, 10, 60, 29.97])
def test_streaming_at_another_rate_equals_offline_at_that_rate(cheap, streams, fps):
    """The target of issue 17: streamed events = offline predict_segments(fps=)."""
    short = cheap.named_steps["classifier"].short_length
    rec = StreamingRecognizer(cheap, fps=fps, max_period=NO_CAP)
    assert rec.ratio == pytest.approx(fps / MODEL_FPS)
    assert rec.delays["resample"] == math.ceil(rec.ratio / 2) + 2
    for k, x30 in enumerate(streams.X[5:8]):
        x = _with_dropouts(x30[:: 2 if fps == 15 else 3 if fps == 10 else 1], k)
        events = rec.recognize(x)
        offline = cheap.predict_segments([x], fps=fps)[0]
        assert len(offline) >= 5
        got, want = _event_rows(events), _rows(offline)
        assert got.shape == want.shape
        assert np.array_equal(got[:, :3], want[:, :3])
        np.testing.assert_allclose(got[:, 3], want[:, 3], rtol=0, atol=1e-6)
        decided = [ev for ev in events if ev.emitted_at < len(x) - 1]
        assert all(ev.emitted_at <= len(x) - 1 for ev in events)
        assert all(
            0 <= ev.delay <= rec.max_delay + math.ceil(short * rec.ratio)
            for ev in decided
        )
    # one frame at a time: the same events, emitted at the same frames
    x = x[:400]
    one_by_one = []
    for frame in x:
        one_by_one += rec.push(frame)
    one_by_one += rec.flush()
    at_once = rec.recognize(x)
    key = [(e.label, e.start, e.end, e.emitted_at) for e in one_by_one]
    assert key == [(e.label, e.start, e.end, e.emitted_at) for e in at_once]


def test_the_recogniser_resamples_only_when_the_rates_differ(cheap, streams):
    x = streams.X[5][:500]
    plain = StreamingRecognizer(cheap)
    for same in (
        StreamingRecognizer(cheap, fps=30),
        StreamingRecognizer(cheap, fps=30.0),
    ):
        assert same.ratio == 1.0 and same.delays == plain.delays
        assert same.recognize(x) == plain.recognize(x)
    rec = StreamingRecognizer(cheap, fps=15)
    assert set(rec.delays) == {"resample", *plain.delays}
    first = rec.push_many(x[:50])
    held = rec.buffer_lengths()
    assert held["resample.last_frame"] == held["resample.model_frame"] == 1
    # a bad frame is refused, named by its index in the stream, and changes nothing
    bad = x[50].copy()
    bad[0, 0] = np.inf
    with pytest.raises(ValueError, match="frame 50 of the stream is invalid"):
        rec.push(bad)
    assert rec.n_frames_seen == 50
    events = first + rec.push_many(x[50:]) + rec.flush()
    fresh = StreamingRecognizer(cheap, fps=15)
    assert events == fresh.push_many(x[:50]) + fresh.push_many(x[50:]) + fresh.flush()
    assert events == fresh.recognize(x)


def test_the_recogniser_needs_the_model_rate(cheap):
    plain = Pipeline(cheap.steps)  # fitted stages, no fps_
    assert StreamingRecognizer(plain).ratio == 1.0
    with pytest.raises(ValueError, match="does not know the rate it was trained at"):
        StreamingRecognizer(plain, fps=15)
    for bad in (0, -5, np.nan, np.inf, True, "15"):
        with pytest.raises(ValueError, match="fps must be a positive finite number"):
            StreamingRecognizer(cheap, fps=bad)


@pytest.mark.slow
def test_method_b_streamed_at_15_fps_equals_offline_at_15_fps():
    """A tiny real Method B trained on PRECOG (30 fps), fed every 2nd frame."""
    data = load_precog(subjects=[1, 2, 8])
    train = [i for i, g in enumerate(data.groups) if g in (1, 2)]
    test = [i for i, g in enumerate(data.groups) if g == 8][:3]
    pipe = make_method_b(random_state=0).set_params(
        descriptor__fill="hold",
        segmenter__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(16,), activations=("tanh",), max_epochs=30
        ),
        classifier__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=30
        ),
    )
    pipe.fit([data.X[i] for i in train], [data.y[i] for i in train], fps=data.fps)
    assert pipe.fps_ == 30.0
    rec = StreamingRecognizer(pipe, fps=15)
    n_events = 0
    for i in test:
        x = data.X[i][::2]
        events = rec.recognize(x)
        offline = pipe.predict_segments([x], fps=15)[0]
        got, want = _event_rows(events), _rows(offline)
        assert got.shape == want.shape
        assert np.array_equal(got[:, :3], want[:, :3])
        np.testing.assert_allclose(got[:, 3], want[:, 3], rtol=0, atol=1e-6)
        n_events += len(events)
    assert n_events >= len(test)


# -- rates as parameters: errors, metadata, model files ----------------------------


def test_bad_rates_are_clear_errors(cheap, streams):
    X, y = streams.X[:2], streams.y[:2]
    fresh = GesturePipeline(make_cheap_pipeline().steps)
    for bad in (0, -1, np.nan, np.inf, True, "30"):
        with pytest.raises(ValueError, match="fps"):
            fresh.fit(X, y, fps=bad)
        with pytest.raises(ValueError, match="fps"):
            cheap.predict(X, fps=bad)
    with pytest.raises(ValueError, match=r"fps\[1\] must be a positive"):
        cheap.predict(X, fps=[30, 0])
    with pytest.raises(ValueError, match="3 rates for 2 sequences"):
        cheap.predict(X, fps=[30, 15, 15])
    with pytest.raises(ValueError, match="differs between the training sequences"):
        fresh.fit(X, y, fps=[30, 20])
    with pytest.raises(ValueError, match="from_fps must be a positive finite"):
        resample(X[0], 0, 30)
    with pytest.raises(ValueError, match="to_fps must be a positive finite"):
        FrameResampler(30, -2)
    with pytest.raises(ValueError, match="model-rate rows for"):
        frames_back(np.zeros(3), 15, 30, 10)
    assert check_fps(np.float32(29.97)) == pytest.approx(29.97)
    unfitted = GesturePipeline(make_cheap_pipeline().steps)
    with pytest.raises(sklearn.exceptions.NotFittedError):
        unfitted.predict(X, fps=15)
    no_rate = GesturePipeline(cheap.steps)  # fitted stages, fit never called
    assert no_rate.predict(X[:1])[0].shape == (len(X[0]),)
    with pytest.raises(ValueError, match="no fps_"):
        no_rate.predict(X[:1], fps=15)


def test_fit_records_the_rate_as_a_plain_float(streams):
    X, y = streams.X[:2], streams.y[:2]
    pipe = GesturePipeline(make_cheap_pipeline().steps)
    assert pipe.fit(X, y).fps_ == 30.0  # the default
    assert type(pipe.fit(X, y, fps=np.float32(20)).fps_) is float
    assert pipe.fit(X, y, fps=np.array([25, 25.0])).fps_ == 25.0
    assert "fps" not in pipe.get_params() and "fps_" not in pipe.get_params()


def test_fps_survives_pickle_and_clone_gives_an_unfitted_copy(cheap, streams):
    for copied in (
        pickle.loads(pickle.dumps(cheap)),
        copy.deepcopy(cheap),
    ):
        assert type(copied) is GesturePipeline and copied.fps_ == cheap.fps_
        x = streams.X[5][:300]
        want = cheap.predict([x], fps=15)[0]
        assert np.array_equal(copied.predict([x], fps=15)[0], want)
    clone_ = clone(cheap)
    assert type(clone_) is GesturePipeline and not hasattr(clone_, "fps_")
    assert clone_.get_params(deep=False).keys() == cheap.get_params(deep=False).keys()
    assert clone_.fit(streams.X[:2], streams.y[:2], fps=12.5).fps_ == 12.5
    assert type(cheap[:2]) is GesturePipeline  # slicing keeps the class


def test_joblib_and_model_files_keep_the_rate(tmp_path, streams):
    pytest.importorskip("skops")
    from skgesture import load_model, save_model

    pipe = make_method_b(random_state=0).set_params(
        segmenter__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(4,), activations=("tanh",), max_epochs=2
        ),
        classifier__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(4,), activations=("tanh",), max_epochs=2
        ),
    )
    pipe.fit(streams.X[:2], streams.y[:2], fps=25)
    joblib.dump(pipe, tmp_path / "m.joblib")
    assert joblib.load(tmp_path / "m.joblib").fps_ == 25.0
    path = save_model(pipe, tmp_path / "m.skg")
    loaded = load_model(path)
    assert type(loaded) is GesturePipeline and loaded.fps_ == 25.0
    x = streams.X[6][:200]
    assert np.array_equal(loaded.predict([x], fps=15)[0], pipe.predict([x], fps=15)[0])


def test_fit_takes_the_rate_as_metadata(streams):
    """GridSearchCV and cross_validate hand fps on to fit, routing on or off."""
    X, y = streams.X, streams.y
    groups = np.arange(len(X)) % 2
    grid = {"classifier__threshold_short": [0.2, 0.3]}

    def search():
        return GridSearchCV(
            GesturePipeline(make_cheap_pipeline().steps), grid, cv=GroupKFold(2)
        )

    found = search().fit(X, y, groups=groups, fps=24.0)
    assert found.best_estimator_.fps_ == 24.0
    found = search().fit(X, y, groups=groups, fps=np.full(len(X), 24.0))  # split
    assert found.best_estimator_.fps_ == 24.0
    with sklearn.config_context(enable_metadata_routing=True):
        found = search().fit(X, y, groups=groups, fps=25.0)
        assert found.best_estimator_.fps_ == 25.0
        out = cross_validate(
            GesturePipeline(make_cheap_pipeline().steps),
            X,
            y,
            cv=GroupKFold(2),
            params={"groups": groups, "fps": [26.0] * len(X)},
            return_estimator=True,
        )
        assert [est.fps_ for est in out["estimator"]] == [26.0, 26.0]


def test_every_factory_returns_a_gesture_pipeline():
    for make in (make_method_a, make_method_b, make_method_c, make_recommended):
        pipe = make()
        assert type(pipe) is GesturePipeline
        assert isinstance(pipe, Pipeline)
        assert type(clone(pipe)) is GesturePipeline
