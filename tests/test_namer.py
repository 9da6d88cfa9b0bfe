"""The run namer: a bidirectional network names each run once it has ended.

A tagger that reads a bounded look-ahead names the first frames of a gesture
before its end is seen; ``SequenceTagger(namer="gru")`` renames every run from
all of its frames, offline as live.
"""

import copy
import io
import warnings

import joblib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import clone

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
    namer_batch,
    namer_of,
    namer_scores,
    rest_windows,
    strided,
)
from skgesture.metrics import jaccard_index  # noqa: E402
from skgesture.utils._segments import runs  # noqa: E402

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


def test_rest_windows_lie_in_rest_runs_with_gesture_lengths():
    y = np.array([0] * 10 + [1] * 5 + [0] * 2 + [IGNORE_INDEX] * 3 + [0] * 20)
    X = [np.arange(len(y), dtype=np.float32)[:, None], np.zeros((6, 1))]
    W, Y = rest_windows(X, [y, np.zeros(6, dtype=int)], [4, 8, 30], 200, seed=0)
    assert len(W) == len(Y) == 200
    rest = set(range(10)) | set(range(20, 40))
    for w, v in zip(W, Y):
        assert len(w) == len(v) and v.tolist() == [0] * len(v)
        if len(w) and w[0, 0] > 0:  # a window of the first sequence
            rows = w[:, 0].astype(int)
            # in one rest run: never the gesture, the untracked rows, nor the
            # 2-row run (shorter than MIN_REST)
            assert set(rows.tolist()) <= rest
            assert (rows < 10).all() or (rows >= 20).all()
            assert np.all(np.diff(rows) == 1)
    # lengths are the given ones, capped at the run's
    assert {len(w) for w in W} <= {4, 6, 8, 10, 20}
    assert {4, 8, 20} <= {len(w) for w in W}
    # seeded; no rest, no length or no count: no window
    again = rest_windows(X, [y, np.zeros(6, dtype=int)], [4, 8, 30], 200, seed=0)
    assert all(np.array_equal(a, b) for a, b in zip(W, again[0]))
    assert rest_windows(X[:1], [np.ones(len(y), dtype=int)], [4], 5, 0) == ([], [])
    assert rest_windows(X, [y, y[:6]], [], 5, 0) == ([], [])
    assert rest_windows(X, [y, y[:6]], [4], 0, 0) == ([], [])


def test_strided_windows_keep_every_stride_th_row_from_a_random_phase():
    W = [np.arange(n, dtype=np.float32)[:, None] for n in (9, 8, 1, 5) * 5]
    Y = [np.arange(len(w)) + 100 for w in W]
    assert strided(W, Y, 1, 0) == (W, Y)  # stride 1: the windows themselves
    got, labels = strided(W, Y, 3, 0)
    phases = set()
    for w, v, g, lab in zip(W, Y, got, labels):
        p = int(g[0, 0])
        phases.add(p)
        # rows p, p + 3, ... of the window, and their own labels
        assert_array_equal(g[:, 0], w[p::3, 0])
        assert_array_equal(lab, v[p::3])
        assert len(g) >= 1  # a window shorter than its phase keeps its first row
    assert phases == {0, 1, 2}
    again = strided(W, Y, 3, 0)[0]
    assert all(np.array_equal(a, b) for a, b in zip(got, again))  # seeded


def test_a_strided_namer_reads_every_stride_th_row_from_the_first():
    from skgesture._nn._modules import RecurrentTaggerModule

    torch.manual_seed(0)
    module = RecurrentTaggerModule(3, 4, hidden_sizes=(5,))
    mean, scale = np.zeros(3, np.float32), np.ones(3, np.float32)
    rng = np.random.default_rng(0)
    windows = [rng.normal(size=(n, 3)).astype(np.float32) for n in (7, 1, 10, 2)]
    got = namer_batch(module, mean, scale, windows, 4, stride=2)
    # rows 0, 2, 4, ... of every run, read as the run
    want = namer_batch(module, mean, scale, [w[::2] for w in windows], 4)
    assert_allclose(got, want, atol=1e-6)
    for w, score in zip(windows, got):
        # one run alone (a stream's call) is the batch's, to float rounding
        assert_allclose(namer_scores(module, mean, scale, w, 4, 2), score, atol=1e-5)
    # stride 1 reads every row, as before
    plain = namer_batch(module, mean, scale, windows, 4)
    assert_allclose(namer_batch(module, mean, scale, windows, 4, stride=1), plain)
    assert not np.allclose(got[0], plain[0])  # the stride reads another sequence
    assert_allclose(got[1], plain[1])  # a one-row run is its first row either way


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


def test_a_run_the_namer_calls_rest_becomes_rest():
    labels = np.array([0, 1, 1, 1, 0, 2, 2, 2, 0])
    raw = np.full((len(labels), 4), 0.25)
    rows = np.zeros((len(labels), 4))
    rows[1:4, 0] = 1.0  # the namer's rest for the first run
    rows[5:8, 2] = 1.0
    rest = np.exp(_scores(rows[1:4])[0])  # its mean probability of rest
    assert 0.5 < rest < 0.99
    kwargs = {"namer": namer_of(rows, _scores), "namer_weight": 0.0}
    for limit, want in [
        (None, labels),  # not read
        (rest + 0.01, labels),  # below the limit: kept, as labelled (weight 0)
        (rest - 0.01, [0, 0, 0, 0, 0, 2, 2, 2, 0]),
        (0.001, [0] * 9),
    ]:
        got = reject_runs(labels, raw, np.arange(4), max_namer_rest=limit, **kwargs)
        assert got.tolist() == list(want)


@pytest.mark.parametrize(
    "viterbi, max_rest",
    [(None, None), (ViterbiRule([1, 3, 3, 3], 2.0, 3), None), (None, 0.3)],
)
def test_the_stream_names_runs_as_offline(viterbi, max_rest):
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
        proba,
        classes,
        smoothing="none",
        namer=namer_of(rows, _scores),
        max_namer_rest=max_rest,
        **rules,
    )
    plain = decode(proba, classes, smoothing="none", **rules)
    assert (offline != plain).any()  # the namer renames some runs
    if max_rest is not None:  # and its rest rule removes some
        named = decode(
            proba, classes, smoothing="none", namer=namer_of(rows, _scores), **rules
        )
        assert ((offline == 0) & (named != 0)).any()
    stream = LabelRuns(
        classes,
        2,
        max_gap=1,
        viterbi=viterbi,
        namer=_scores,
        namer_weight=0.6,
        max_namer_rest=max_rest,
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


def test_the_namer_learns_rest_and_its_rule_keeps_the_gestures(late_pair):
    tagger, X, y = late_pair
    assert tagger.namer_rest_ > 0  # trained on windows of the rest too
    args = (tagger.namer_.module_, tagger.namer_mean_, tagger.namer_scale_)
    rest, gesture = [], []
    for x, labels in zip(X, y):
        for s, e, v in zip(*runs(labels)):
            p = np.exp(namer_scores(*args, x[s:e], len(tagger.classes_))[0])
            (gesture if v else rest).append(p)
    # held-out runs: the namer tells rest from gestures by their frames
    assert max(gesture) < 0.2 < 0.8 < min(rest)
    want = jaccard_index(y, tagger.predict(X))
    kept = clone_with(tagger, max_namer_rest=0.5).predict(X)
    assert jaccard_index(y, kept) == pytest.approx(want)  # no gesture lost
    none = clone_with(tagger, max_namer_rest=1e-6).predict(X)
    assert all((labels == 0).all() for labels in none)  # every run is rest


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
    with pytest.raises(ValueError, match="max_namer_rest"):
        SequenceTagger(max_namer_rest=1.5, namer="gru").fit(X, y)
    with pytest.raises(ValueError, match="max_namer_rest=0.5 reads the run namer"):
        SequenceTagger(max_namer_rest=0.5).fit(X, y)
    with pytest.raises(ValueError, match="namer_stride"):
        SequenceTagger(namer="gru", namer_stride=0).fit(X, y)
    for bad in [(), (8, 0), (True,)]:
        with pytest.raises(ValueError, match=r"namer_hidden_sizes must be a non-empty"):
            SequenceTagger(namer="gru", namer_hidden_sizes=bad).fit(X, y)


def test_a_strided_namer_names_gestures_that_differ_at_their_end(late_pair):
    # reading every second frame of a run, from both phases, the namer still
    # tells the pair apart by their ends; its stride is fitted with it
    tagger, X, y = late_pair
    X_tr, y_tr = (part[:10] for part in _late_pair(14, 0))
    wide = clone_with(tagger, namer_stride=2, namer_hidden_sizes=(16,))
    with torch.random.fork_rng(devices=[]):
        wide.fit(X_tr, y_tr)
    assert wide.namer_stride_ == 2
    assert [rnn.hidden_size for rnn in wide.namer_.module_.layers] == [16]
    causal = jaccard_index(y, clone_with(wide, namer_weight=0.0).predict(X))
    named = jaccard_index(y, wide.predict(X))
    assert named > 0.9 and named > causal + 0.1
    # the decoding reads the fitted stride, not the parameter
    assert_array_equal(
        np.concatenate(wide.predict(X)),
        np.concatenate(clone_with(wide, namer_stride=1).predict(X)),
    )


def test_the_rest_rule_needs_a_namer_trained_on_rest(late_pair):
    # a model fitted before the namer learnt rest says so, and how to go on
    tagger, X, _ = late_pair
    old = clone_with(tagger, max_namer_rest=0.5)
    del old.namer_rest_
    with pytest.raises(ValueError, match="namer_rest_.*max_namer_rest=None"):
        old.predict(X)
    old.set_params(max_namer_rest=None).predict(X)  # as before


def test_a_rest_rule_without_rest_to_learn_warns():
    # gestures separated by rest too brief to draw a rest window from: the
    # namer learns no rest, so its rule would silently remove nothing
    X, y = [], []
    for x, labels in zip(*_late_pair(4, 1)):
        keep = np.ones(len(labels), bool)
        for s, e, v in zip(*runs(labels)):
            if v == 0:
                keep[s + 2 : e] = False  # rest runs cut to 2 frames
        X.append(x[keep])
        y.append(labels[keep])
    tagger = SequenceTagger(
        hidden_sizes=(4,),
        steps_per_epoch=2,
        max_epochs=2,
        namer="gru",
        max_namer_rest=0.5,
        random_state=0,
    )
    with pytest.warns(UserWarning, match="namer learns no rest.*max_namer_rest=None"):
        tagger.fit(X, y)
    assert tagger.namer_rest_ == 0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        clone(tagger).fit(*_late_pair(4, 1))  # with rest to learn, no warning
    assert not [w for w in caught if "learns no rest" in str(w.message)]


def _tiny_namer_tagger(**params):
    return SequenceTagger(
        **{
            "hidden_sizes": (4,),
            "steps_per_epoch": 3,
            "max_epochs": 4,
            "namer": "gru",
            "random_state": 0,
            **params,
        }
    )


def _rest_like(X, seed):
    """All-rest sequences of the frames of ``X``, shuffled in time."""
    rng = np.random.default_rng(seed)
    out = [x[rng.permutation(len(x))] for x in X]
    return out, [np.zeros(len(x), dtype=np.int64) for x in out]


def test_namer_only_sequences_train_the_namer_alone():
    X, y = _late_pair(4, 2)
    negatives, rest = _rest_like(X[:2], 0)
    flags = np.array([False] * 4 + [True] * 2)
    plain = _tiny_namer_tagger().fit(X, y)
    routed = _tiny_namer_tagger().fit(X + negatives, y + rest, namer_only=flags)
    # the network, its statistics and the rules' data are those of the fit
    # without the negatives ...
    for a, b in zip(plain.predict_proba(X), routed.predict_proba(X)):
        assert_array_equal(a, b)
    assert_array_equal(plain.class_lengths_, routed.class_lengths_)
    assert_array_equal(plain.novelty_.mean_, routed.novelty_.mean_)
    # ... and the namer learnt rest windows of the negatives too
    assert routed.namer_rest_ > plain.namer_rest_ > 0
    assert not np.allclose(plain.namer_mean_, routed.namer_mean_)


@pytest.mark.parametrize(
    "flags, match",
    [
        ([True, False], r"boolean array of shape \(3,\)"),
        ([0, 0, 1], r"boolean array of shape \(3,\)"),
        ([False, True, False], r"X\[1\] has gesture label \d at frame \d+"),
        ([True, True, True], r"flags all 3 sequences.*not namer_only"),
    ],
)
def test_namer_only_is_checked(flags, match):
    X, y = _late_pair(3, 3)
    if all(flags):
        y = [np.zeros_like(v) for v in y]  # all rest, as flagged sequences are
    with pytest.raises(ValueError, match=match):
        _tiny_namer_tagger().fit(X, y, namer_only=np.array(flags))


def test_namer_only_needs_a_namer():
    X, y = _late_pair(3, 3)
    with pytest.raises(ValueError, match="namer_only.*set namer='gru'"):
        _tiny_namer_tagger(namer=None).fit(X, y, namer_only=np.zeros(3, bool))


@pytest.mark.parametrize("routing", [False, True])
def test_a_pipeline_gives_its_background_to_the_namer(routing):
    import sklearn
    from sklearn.preprocessing import FunctionTransformer

    from skgesture import GesturePipeline
    from skgesture.datasets import SyntheticBackground

    X, y = _late_pair(4, 2)

    def pipe(background_for):
        return GesturePipeline(
            [("same", FunctionTransformer()), ("tagger", _tiny_namer_tagger())],
            background=SyntheticBackground(3, kinds=("motion",), random_state=0),
            background_for=background_for,
        )

    with sklearn.config_context(enable_metadata_routing=routing):
        namer = pipe("namer").fit(X, y)
        model = pipe("model").fit(X, y)
    plain = _tiny_namer_tagger().fit(X, y)
    tagger = namer.named_steps["tagger"]
    for a, b in zip(plain.predict_proba(X), tagger.predict_proba(X)):
        assert_array_equal(a, b)  # the network never saw the negatives
    assert tagger.namer_rest_ > plain.namer_rest_
    # background_for="model": the network and the rules learn them too
    assert not np.allclose(
        model.named_steps["tagger"].novelty_.mean_, plain.novelty_.mean_
    )
    # a last step without a namer: no negatives are made, and a warning says so
    seen = {}
    fit = SequenceTagger.fit

    def spy(self, X, y, **params):
        seen["n"], seen["params"] = len(X), params
        return fit(self, X, y, **params)

    bare = GesturePipeline(
        [("same", FunctionTransformer()), ("tagger", _tiny_namer_tagger(namer=None))],
        background=SyntheticBackground(3, random_state=0),
        background_for="namer",
    )
    with pytest.warns(UserWarning, match="background_for='namer'.*has none.*"):
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(SequenceTagger, "fit", spy)
            bare.fit(X, y)
    assert seen == {"n": len(X), "params": {}}


def test_the_decoding_imports_no_torch():
    # the numpy decoding (offline and live) reads the namer's module without torch
    import subprocess
    import sys

    code = "import sys, skgesture._taggers._decoding; print('torch' in sys.modules)"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "False"


def test_the_namer_trains_on_each_window_as_it_reads_a_run():
    # packed crops: the backward direction starts at each window's last frame,
    # as when the namer reads a run alone; padded, it would start in the zeros
    from skgesture._nn._modules import RecurrentTaggerModule
    from skgesture._nn._sequence_net import _CropNet

    torch.manual_seed(0)
    module = RecurrentTaggerModule(3, 4, hidden_sizes=(5,)).eval()
    X = torch.randn(2, 7, 3)
    X[1, 4:] = 0.0  # the second window has 4 frames
    with torch.no_grad():
        packed = module(X, lengths=torch.tensor([7, 4]))
        alone = module(X[1:, :4])
        padded = module(X)
    torch.testing.assert_close(packed[1, :4], alone[0])
    torch.testing.assert_close(packed[0], padded[0])
    assert not torch.allclose(padded[1, :4], alone[0], atol=1e-4)
    windows = [np.zeros((5, 3), np.float32)] * 2
    labels = [np.ones(5, dtype=np.int64)] * 2
    with pytest.raises(ValueError, match="recurrent architecture"):
        _CropNet(architecture="tcn", packed=True).fit(windows, labels)
