"""The duration-aware Viterbi path of the decoding (``viterbi_penalty``).

What a user relies on: one doubtful frame neither splits a gesture nor starts a
brief false one; the path is decided at a fixed lag, so a stream fed one frame
at a time gives the labels of the whole sequence; the compiled and the Python
steps agree; and a tagger with the path learns a toy stream near perfectly,
changing its decisions without retraining.
"""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from skgesture._taggers import _viterbi
from skgesture._taggers._decoding import ViterbiRule, decode
from skgesture._taggers._viterbi import ViterbiPath, chain_lengths, log_scores


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


@pytest.mark.parametrize("lag", [0, 1, 6, 25])
@pytest.mark.parametrize("seed", [0, 1])
def test_frames_fed_in_blocks_give_the_labels_of_the_whole_sequence(lag, seed):
    rng = np.random.default_rng(seed)
    truth = np.repeat(rng.integers(0, 4, 30), rng.integers(1, 12, 30))
    lp = log_scores(_proba(truth, 4, sure=0.5, seed=seed))
    durations = np.array([1, 3, 1, 7])
    whole = ViterbiPath(durations, 1.5, lag).run(lp)
    path, parts, i = ViterbiPath(durations, 1.5, lag), [], 0
    while i < len(lp):
        k = int(rng.integers(1, 5))
        parts.append(path.feed(lp[i : i + k]))
        i += k
        # a frame is decided exactly lag frames after it arrives
        assert sum(map(len, parts)) == max(i - lag, 0)
    parts.append(path.finish())
    assert_array_equal(np.concatenate(parts), whole)


@pytest.mark.parametrize("n", [0, 1, 3, 6])
def test_sequences_shorter_than_the_lag(n):
    lp = log_scores(_proba(np.ones(n, int), 2))
    got = ViterbiPath(np.array([1, 1]), 0.5, lag=6).run(lp)
    assert got.tolist() == [1] * n


def test_the_compiled_and_the_python_steps_agree():
    compiled = _viterbi._kernels()[0]
    if compiled is _viterbi._forward:
        pytest.skip("numba is not installed: the Python step is the only one")
    rng = np.random.default_rng(3)
    truth = np.repeat(rng.integers(0, 5, 40), rng.integers(1, 15, 40))
    lp = log_scores(_proba(truth, 5, sure=0.4, seed=3))
    durations = np.array([1, 4, 2, 9, 1])
    outs = []
    for step in (compiled, _viterbi._forward):
        path = ViterbiPath(durations, 3.0, 5)
        out = np.empty(len(lp), dtype=np.int64)
        step(path.delta, lp, path.first, path.last, path.cls, path.penalty,
             path.lag, path.ring, 0, out)  # fmt: skip
        outs.append((out, path.delta.copy()))
    assert_array_equal(outs[0][0], outs[1][0])
    assert_array_equal(outs[0][1], outs[1][1])


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
