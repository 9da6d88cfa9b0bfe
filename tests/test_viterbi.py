"""The duration-aware Viterbi path of the decoding (``viterbi_penalty``).

What a user relies on: one doubtful frame neither splits a gesture nor starts a
brief false one; the path is decided at a fixed lag (or, with
``decision="run"``, a gesture's frames together once it ends), so a stream fed
one frame at a time gives the labels of the whole sequence; the compiled and
the Python steps agree; and a tagger with the path learns a toy stream near
perfectly, changing its decisions without retraining.
"""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from skgesture._taggers import _viterbi
from skgesture._taggers._decoding import ViterbiRule, decode
from skgesture._taggers._viterbi import (
    DECISIONS,
    ViterbiPath,
    chain_lengths,
    log_scores,
)


def _proba(labels, n_classes, sure=0.9, seed=None):
    """Probabilities that favour ``labels`` (optionally noisy)."""
    labels = np.asarray(labels)
    p = np.full((len(labels), n_classes), (1 - sure) / (n_classes - 1))
    p[np.arange(len(labels)), labels] = sure
    if seed is not None:
        p = p + np.random.default_rng(seed).uniform(0, 0.6, p.shape)
        p /= p.sum(axis=1, keepdims=True)
    return p


def test_one_doubtful_frame_neither_splits_a_gesture_nor_starts_one():
    truth = np.array([0] * 10 + [2] * 12 + [0] * 10 + [1] * 10 + [0] * 8)
    p = _proba(truth, 3)
    p[15] = [0.7, 0.1, 0.2]  # a doubtful frame inside the gesture of class 2
    p[5] = [0.3, 0.6, 0.1]  # a one-frame "gesture" of class 1 in the rest
    classes = np.array([0, 1, 2])
    plain = decode(p, classes, smoothing="none")
    assert plain[15] == 0 and plain[5] == 1  # the arg-max splits and starts
    rule = ViterbiRule(np.array([1, 5, 5]), penalty=2.0, lag=4)
    got = decode(p, classes, smoothing="none", viterbi=rule)
    assert_array_equal(got, truth)


def test_a_run_shorter_than_its_class_becomes_rest():
    truth = np.array([0] * 8 + [1] * 3 + [0] * 8 + [1] * 9 + [0] * 6)
    p = _proba(truth, 2, sure=0.8)
    durations = chain_lengths(np.array([0.0, 10.0]), 0.6)  # 6 frames
    rule = ViterbiRule(durations, 0.0, lag=8)
    got = decode(p, np.array([0, 1]), smoothing="none", viterbi=rule)
    assert not got[:19].any()  # 3 frames < 6: rest
    assert (got[19:28] == 1).all()
    # decided sooner than the duration, a frame follows the best path of the
    # moment, which may still be inside a chain: the length rule then rejects
    # what the path would have (min_lengths, the tagger's min_duration)
    soon = ViterbiRule(durations, 0.0, lag=1)
    got = decode(p, np.array([0, 1]), smoothing="none", viterbi=soon,
                 min_lengths=np.array([0.0, 5.0]))  # fmt: skip
    assert not got[:19].any() and (got[19:28] == 1).all()


def test_untracked_frames_stay_rest_on_the_path():
    truth = np.array([0] * 5 + [1] * 12 + [0] * 5)
    p = _proba(truth, 2)
    untracked = np.zeros(len(truth), bool)
    untracked[9] = True
    rule = ViterbiRule(np.array([1, 3]), 1.0, lag=2)
    got = decode(p, np.array([0, 1]), smoothing="none", untracked=untracked,
                 viterbi=rule)  # fmt: skip
    assert got[9] == 0 and (got[5:9] == 1).all() and (got[10:17] == 1).all()


@pytest.mark.parametrize("decision", ["frame", "run"])
@pytest.mark.parametrize("lag", [0, 1, 6, 25])
@pytest.mark.parametrize("seed", [0, 1])
def test_frames_fed_in_blocks_give_the_labels_of_the_whole_sequence(
    lag, seed, decision
):
    rng = np.random.default_rng(seed)
    truth = np.repeat(rng.integers(0, 4, 30), rng.integers(1, 12, 30))
    lp = log_scores(_proba(truth, 4, sure=0.5, seed=seed))
    durations = np.array([1, 3, 1, 7])
    whole = ViterbiPath(durations, 1.5, lag, decision).run(lp)
    path, parts, i = ViterbiPath(durations, 1.5, lag, decision), [], 0
    while i < len(lp):
        k = int(rng.integers(1, 5))
        parts.append(path.feed(lp[i : i + k]))
        i += k
        decided = sum(map(len, parts))
        if decision == "frame":  # a frame is decided exactly lag frames after it
            assert decided == max(i - lag, 0)
        else:  # or later, while it is held in a gesture
            assert decided == max(i - lag, 0) - (i - lag - path.held[0]) * (
                path.held[0] >= 0
            )
    parts.append(path.finish())
    assert_array_equal(np.concatenate(parts), whole)


@pytest.mark.parametrize("decision", ["frame", "run"])
@pytest.mark.parametrize("n", [0, 1, 3, 6])
def test_sequences_shorter_than_the_lag(n, decision):
    lp = log_scores(_proba(np.ones(n, int), 2))
    got = ViterbiPath(np.array([1, 1]), 0.5, lag=6, decision=decision).run(lp)
    assert got.tolist() == [1] * n


def _late_naming():
    """A gesture of class 2 whose first frames look a little more like 1."""
    p = np.tile([0.9, 0.05, 0.05], (40, 1))
    p[10:16] = [0.1, 0.5, 0.4]
    p[16:30] = [0.05, 0.05, 0.9]
    return log_scores(p)


def test_decided_by_run_a_gesture_is_read_whole():
    lp = _late_naming()
    durations = np.array([1, 4, 4])
    truth = [0] * 10 + [2] * 20 + [0] * 10
    # decided 2 frames after each frame, its first frames are still class 1
    by_frame = ViterbiPath(durations, 2.0, 2).run(lp)
    assert by_frame[10:14].tolist() == [1] * 4 and by_frame[14:30].tolist() == [2] * 16
    by_run = ViterbiPath(durations, 2.0, 2, decision="run").run(lp)
    assert by_run.tolist() == truth


def test_decided_by_run_rest_waits_the_lag_and_a_gesture_its_end():
    lp = _late_naming()
    lag = 2
    paths = {d: ViterbiPath(np.array([1, 4, 4]), 2.0, lag, d) for d in DECISIONS}
    when = {d: np.full(len(lp), -1) for d in DECISIONS}
    for t in range(len(lp)):
        for d, path in paths.items():
            first = path.decided
            path.feed(lp[t : t + 1])
            when[d][first : path.decided] = t
    assert (when["frame"] == np.arange(len(lp)) + lag)[: len(lp) - lag].all()
    run = when["run"]
    rest = np.r_[0:10, 30 : len(lp) - lag]
    assert_array_equal(run[rest], rest + lag)  # rest: at the lag
    # the gesture's frames: together, when its first rest frame is decided,
    # as soon as the gesture's end is known frame by frame
    assert (run[10:30] == 30 + lag).all() and when["frame"][30] == 30 + lag


def test_decided_by_run_at_most_max_held_frames_wait(monkeypatch):
    monkeypatch.setattr(_viterbi, "MAX_HELD", 16)
    lp = log_scores(_proba(np.r_[np.zeros(5, int), np.ones(100, int)], 2))
    path = ViterbiPath(np.array([1, 3]), 1.0, 4, decision="run")
    assert len(path.ring) == 16  # the memory of a path: MAX_HELD frames
    parts = []
    for t in range(len(lp)):
        parts.append(path.feed(lp[t : t + 1]))
        assert t + 1 - path.decided <= 16  # a never-ending gesture is decided
    parts.append(path.finish())
    whole = ViterbiPath(np.array([1, 3]), 1.0, 4, decision="run").run(lp)
    assert_array_equal(np.concatenate(parts), whole)
    assert whole.tolist() == [0] * 5 + [1] * 100


def test_an_unknown_decision_is_a_clear_error():
    with pytest.raises(ValueError, match="decision must be one of"):
        ViterbiPath(np.array([1, 2]), 1.0, 2, decision="late")


@pytest.mark.parametrize("decision", ["frame", "run"])
def test_the_compiled_and_the_python_steps_agree(decision):
    compiled = _viterbi._kernels()[0]
    if compiled is _viterbi._forward:
        pytest.skip("numba is not installed: the Python step is the only one")
    rng = np.random.default_rng(3)
    truth = np.repeat(rng.integers(0, 5, 40), rng.integers(1, 15, 40))
    lp = log_scores(_proba(truth, 5, sure=0.4, seed=3))
    durations = np.array([1, 4, 2, 9, 1])
    outs = []
    for step in (compiled, _viterbi._forward):
        path = ViterbiPath(durations, 3.0, 5, decision)
        out = np.empty(len(lp) + len(path.ring), dtype=np.int64)
        owner = np.empty_like(out)
        _, n = step(
            path.delta, lp, path.first, path.last, path.cls, path.penalty,
            path.lag, path.whole, path.held, path.ring, 0, out, owner,
        )  # fmt: skip
        outs.append((out[:n], owner[:n], path.delta.copy()))
    for a, b in zip(*outs):
        assert_array_equal(a, b)
    assert len(outs[0][0]) > 0


def test_chain_lengths_are_at_least_one_frame_and_rest_is_one():
    got = chain_lengths(np.array([40.0, 0.0, 2.0, 14.0]), 0.7)
    assert got.tolist() == [1, 1, 2, 10]


# -- in a tagger -----------------------------------------------------------------


def test_a_tagger_with_the_path_learns_a_toy_stream_and_ignores_bursts():
    pytest.importorskip("torch")
    from test_tagger_base import TRAINED, _bursts, _streams

    from skgesture.metrics import jaccard_index

    tagger = TRAINED["sequence"]().fit(*_streams(3))
    X_test, y_test = _bursts(2, seed=5)
    proba = tagger.predict_proba(X_test)
    plain = tagger.predict(X_test)
    tagger.set_params(viterbi_penalty=2.0, viterbi_duration=0.7, viterbi_lag=4)
    got = tagger.predict(X_test)
    # decisions change without retraining: the probabilities are the same
    for a, b in zip(proba, tagger.predict_proba(X_test)):
        assert_array_equal(a, b)
    assert jaccard_index(y_test, got) >= 0.9 > jaccard_index(y_test, plain)
    with_lag = tagger.stream_lookahead
    assert with_lag == tagger.set_params(viterbi_lag=0).stream_lookahead + 4
