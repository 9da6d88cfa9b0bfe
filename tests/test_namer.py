"""The run namer: a bidirectional network names each run once it has ended.

A tagger that reads a bounded look-ahead names the first frames of a gesture
before its end is seen; ``SequenceTagger(namer="gru")`` renames every run from
all of its frames, offline as live.
"""

import copy
import io

import joblib
import numpy as np
import pytest
from numpy.testing import assert_array_equal

torch = pytest.importorskip("torch")

from skgesture import SequenceTagger, load_model, save_model  # noqa: E402
from skgesture._nn._training import IGNORE_INDEX  # noqa: E402
from skgesture._taggers._decoding import (  # noqa: E402
    LabelRuns,
    ViterbiRule,
    decode,
    reject_runs,
    segments_with_confidence,
)
from skgesture._taggers._namer import (  # noqa: E402
    gesture_windows,
    name_run,
    namer_of,
)
from skgesture.metrics import jaccard_index  # noqa: E402

# -- the pieces ----------------------------------------------------------------


def test_gesture_windows_are_the_gestures_with_jittered_ends():
    y = np.array([0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 0, IGNORE_INDEX, 2, 2, 2, 0])
    X = [np.arange(len(y), dtype=np.float32)[:, None]]
    W, Y = gesture_windows(X, [y], seed=0, copies=1)
    # one window a gesture, rest and untracked rows left out
    assert [w[:, 0].tolist() for w in W] == [list(range(2, 10)), [12, 13, 14]]
    assert [v.tolist() for v in Y] == [[1] * 8, [2] * 3]
    W, Y = gesture_windows(X, [y], seed=0, copies=30, jitter=0.2)
    firsts = {int(w[0, 0]) for w, v in zip(W, Y) if v[0] == 1}
    assert len(firsts) > 1  # the ends move
    for w, v in zip(W, Y):
        assert len(w) == len(v) >= 2
        # a window over the untracked row keeps it out of the loss
        rows = w[:, 0].astype(int)
        assert_array_equal(v == IGNORE_INDEX, rows == 11)
        assert set(v[rows != 11].tolist()) <= {1, 2}
    again = gesture_windows(X, [y], seed=0, copies=30, jitter=0.2)
    assert all(np.array_equal(a, b) for a, b in zip(W, again[0]))


def test_a_run_is_named_by_the_weighted_scores_never_rest():
    raw = np.array([[0.5, 0.3, 0.2, 0.0]] * 4)  # rest is the tagger's best
    namer = np.log([0.01, 0.1, 0.3, 0.59])
    assert name_run(raw, namer, 0.0) == 1  # the tagger's best gesture
    assert name_run(raw, namer, 1.0) == 3  # the namer's
    assert name_run(raw, namer, 0.5) == 2  # a bit of both


def _scores(rows):
    """A namer of rows: the class whose column of the rows' mean is highest."""
    z = rows.mean(axis=0)[:4] * 5.0
    return z - np.log(np.exp(z).sum())


def test_reject_runs_names_every_run_and_touching_runs_named_alike_join():
    labels = np.array([0, 1, 1, 1, 2, 2, 2, 0, 0, 3, 3, 0])
    raw = np.full((len(labels), 4), 0.25)
    rows = np.zeros((len(labels), 4))
    rows[1:7, 2] = 1.0  # the namer says 2 for both touching runs
    rows[9:11, 1] = 1.0
    named = reject_runs(
        labels, raw, np.arange(4), namer=namer_of(rows, _scores), namer_weight=1.0
    )
    assert named.tolist() == [0, 2, 2, 2, 2, 2, 2, 0, 0, 1, 1, 0]
    assert_array_equal(  # one gesture
        segments_with_confidence(named, raw, np.arange(4))[:, :3],
        [[2, 1, 7], [1, 9, 11]],
    )
    # the length rules judge each run by its new name
    short = reject_runs(
        labels,
        raw,
        np.arange(4),
        namer=namer_of(rows, _scores),
        namer_weight=1.0,
        min_lengths=np.array([0, 0, 4, 0]),
    )
    assert short.tolist() == [0] * 9 + [1, 1, 0]


@pytest.mark.parametrize("viterbi", [None, ViterbiRule([1, 3, 3, 3], 2.0, 3)])
def test_the_stream_names_runs_as_offline(viterbi):
    rng = np.random.default_rng(0)
    T = 400
    truth = np.zeros(T, dtype=int)
    t = 5
    while t < T - 30:  # gestures of random classes, some back to back
        n = int(rng.integers(8, 25))
        truth[t : t + n] = rng.integers(1, 4)
        t += n + int(rng.integers(0, 2) * rng.integers(1, 12))
    proba = np.eye(4)[truth] * 2.0 + rng.random((T, 4)) * 1.5
    proba /= proba.sum(axis=1, keepdims=True)
    # the namer reads another class than the tagger's in most runs
    other = np.array([0, 2, 3, 1])[truth]
    rows = rng.normal(size=(T, 4)) + np.eye(4)[other] * rng.random((T, 1)) * 3
    classes = np.arange(4)
    rules = {"min_run": 2, "max_gap": 1, "viterbi": viterbi, "namer_weight": 0.6}
    offline = decode(
        proba, classes, smoothing="none", namer=namer_of(rows, _scores), **rules
    )
    plain = decode(proba, classes, smoothing="none", **rules)
    assert (offline != plain).any()  # the namer renames some runs
    stream = LabelRuns(
        classes,
        2,
        max_gap=1,
        viterbi=viterbi,
        namer=_scores,
        namer_weight=0.6,
    )
    got = []
    for u in range(T):
        p = proba[u : u + 1]
        got += stream.feed(u, p, p, [False], [u], rows=rows[u : u + 1])
    got += stream.end(T, T - 1)
    live = np.zeros(T, dtype=int)
    for seg in got:
        live[seg.start : seg.end] = seg.label
    assert_array_equal(live, offline)
    with pytest.raises(ValueError, match="feature rows"):
        LabelRuns(classes, 1, namer=_scores).feed(0, p, p, [False], [0])


# -- the tagger ----------------------------------------------------------------


def _late_pair(n_sequences, seed):
    """Two gestures that differ only in their last third, with rest between.

    Feature 0 rises during both; feature 1 rises in the last third of class 2
    only.
    """
    rng = np.random.default_rng(seed)
    X, y = [], []
    for _ in range(n_sequences):
        rows, labels = [np.zeros((int(rng.integers(10, 20)), 2))], [np.zeros(0)]
        labels = [np.zeros(len(rows[0]), dtype=int)]
        for _ in range(6):
            c, n = int(rng.integers(1, 3)), int(rng.integers(24, 33))
            g = np.zeros((n, 2))
            g[:, 0] = 1.0
            if c == 2:
                g[2 * n // 3 :, 1] = 1.0
            rest = int(rng.integers(10, 20))
            rows += [g, np.zeros((rest, 2))]
            labels += [np.full(n, c), np.zeros(rest, dtype=int)]
        x = np.concatenate(rows)
        X.append(x + rng.normal(0.0, 0.1, x.shape))
        y.append(np.concatenate(labels))
    return X, y


@pytest.fixture(scope="module")
def late_pair():
    X, y = _late_pair(14, 0)
    tagger = SequenceTagger(
        architecture="tcn",
        hidden_sizes=(8,),
        tcn_layers=4,
        tcn_stages=1,
        lookahead=0,
        crop_length=96,
        batch_size=8,
        steps_per_epoch=10,
        max_epochs=16,
        viterbi_penalty=5.0,  # one run a gesture, named from its first frames
        namer="gru",
        namer_weight=1.0,
        random_state=0,
    )
    with torch.random.fork_rng(devices=[]):
        tagger.fit(X[:10], y[:10])
    return tagger, X[10:], y[10:]


def clone_with(fitted, **params):
    """A fitted estimator's copy with other decision parameters."""
    return copy.deepcopy(fitted).set_params(**params)


def test_the_namer_names_gestures_that_differ_at_their_end(late_pair):
    tagger, X, y = late_pair
    named = jaccard_index(y, tagger.predict(X))
    causal = jaccard_index(y, clone_with(tagger, namer_weight=0.0).predict(X))
    assert named > 0.9
    assert named > causal + 0.1  # a causal tagger names the start of a run


def test_without_a_namer_the_tagger_is_the_same_network(late_pair):
    tagger, X, _ = late_pair
    X_tr, y_tr = (part[:10] for part in _late_pair(14, 0))
    plain = SequenceTagger(**{**tagger.get_params(), "namer": None})
    refit = clone_with(tagger, namer=None)
    with torch.random.fork_rng(devices=[]):
        plain.fit(X_tr, y_tr)
        refit.fit(X_tr, y_tr)
    # namer_weight=0 is the tagger without a namer, whose network is the same
    for a, b in zip(plain.predict(X), clone_with(tagger, namer_weight=0.0).predict(X)):
        assert_array_equal(a, b)
    # a refit without the namer drops it
    for model in (plain, refit):
        assert not hasattr(model, "namer_") and not hasattr(model, "namer_mean_")


def test_a_named_model_round_trips(late_pair, tmp_path):
    tagger, X, _ = late_pair
    want = tagger.predict(X)
    buf = io.BytesIO()
    joblib.dump(tagger, buf)
    buf.seek(0)
    for got in joblib.load(buf).predict(X), _saved(tagger, tmp_path).predict(X):
        for a, b in zip(got, want):
            assert_array_equal(a, b)


def _saved(model, tmp_path):
    path = tmp_path / "named.skg"
    save_model(model, path)
    return load_model(path)


def test_namer_weight_is_validated():
    X, y = _late_pair(2, 1)
    with pytest.raises(ValueError, match="namer_weight"):
        SequenceTagger(namer="gru", namer_weight=1.5).fit(X, y)
    with pytest.raises(ValueError, match="namer"):
        SequenceTagger(namer="tcn").fit(X, y)


def test_the_decoding_imports_no_torch():
    # the numpy decoding (offline and live) reads the namer's module without torch
    import subprocess
    import sys

    code = "import sys, skgesture._taggers._decoding; print('torch' in sys.modules)"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "False"
