"""BiLSTMTagger (Method C): windows, schedule, decision rules, caching, sklearn API."""

import os
import pickle
import subprocess
import sys
import time

import joblib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

pytest.importorskip("skorch")
torch = pytest.importorskip("torch")

from sklearn.base import clone  # noqa: E402
from sklearn.model_selection import GridSearchCV, GroupKFold  # noqa: E402
from sklearn.pipeline import Pipeline  # noqa: E402

from skgesture import BiLSTMTagger, PoseDescriptor, make_method_c  # noqa: E402
from skgesture._nn._modules import RecurrentTaggerModule, _BiLSTMModule  # noqa: E402
from skgesture._nn._training import FramewiseLoss, SequenceSplit  # noqa: E402
from skgesture._taggers._bilstm import (  # noqa: E402
    IGNORE_INDEX,
    PAPER_MODULE,
    _BiLSTMNet,
    _chunks,
    _training_windows,
    sample_windows,
)
from skgesture.metrics import jaccard_index  # noqa: E402
from skgesture.utils._testing import make_skeleton_stream  # noqa: E402

# docs/method.md §7.3: learning rate of 1-based epochs 1..10, 11..20, 21 and 150.
LR_GT = {1: 0.01, 10: 0.01, 11: 0.0085, 20: 0.0085, 21: 0.007225, 150: 0.001028}
LR_RTOL = 5e-4  # the spec gives 4 significant digits

TINY = {"hidden_sizes": (8,), "dropout": 0.0, "max_epochs": 8, "random_state": 0}


@pytest.fixture(autouse=True)
def _one_torch_thread():
    """Tiny recurrent nets run fastest on one thread (and do not fight other jobs)."""
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


def _toy_streams(n_sequences, random_state):
    """4-D feature streams: rest = noise, class 1 = a bump, class 2 = a ramp.

    Each sequence is rest, gesture, rest, gesture, rest; gestures last 30-40
    frames, rests 15-25.
    """
    rng = np.random.RandomState(random_state)
    X, y = [], []
    for _ in range(n_sequences):
        parts_x, parts_y = [], []
        for k in range(5):
            if k % 2 == 0:
                n = rng.randint(15, 26)
                parts_x.append(rng.normal(0, 0.2, (n, 4)))
                parts_y.append(np.zeros(n, dtype=int))
            else:
                n = rng.randint(30, 41)
                c = rng.randint(1, 3)
                t = np.linspace(0, 1, n)
                x = rng.normal(0, 0.2, (n, 4))
                if c == 1:
                    x[:, 0] += 1.0 + np.sin(np.pi * t)  # bump
                else:
                    x[:, 1] += 1.0 + 2.0 * t  # ramp
                parts_x.append(x)
                parts_y.append(np.full(n, c))
        X.append(np.concatenate(parts_x))
        y.append(np.concatenate(parts_y))
    return X, y


@pytest.fixture(scope="module")
def toy():
    return _toy_streams(20, random_state=0)


@pytest.fixture(scope="module")
def toy_test():
    return _toy_streams(10, random_state=1)


@pytest.fixture(scope="module")
def fitted(toy):
    torch.set_num_threads(1)
    X, y = toy
    return BiLSTMTagger(
        hidden_sizes=(16,), dropout=0.0, max_epochs=25, random_state=0
    ).fit(X, y)


# -- training windows ------------------------------------------------------------


def test_sample_windows_rest_steps_by_five():
    assert_array_equal(sample_windows(np.zeros(30, int)), [0, 5, 10, 15, 20])


def test_sample_windows_gesture_steps_by_two():
    assert_array_equal(sample_windows(np.full(20, 3)), [0, 2, 4, 6, 8, 10])


def test_sample_windows_switches_step_with_window_content():
    y = np.r_[np.zeros(20, int), np.ones(10, int), np.zeros(20, int)]
    # 10 (frames 10-19) is all rest -> 15; 15..29 touch the gesture -> +2;
    # 31 (frames 31-40) is rest again -> 36; 41 would run past frame 49.
    assert_array_equal(
        sample_windows(y), [0, 5, 10, 15, 17, 19, 21, 23, 25, 27, 29, 31, 36]
    )
    # window 20: 0 (frames 0-19) is all rest -> 7; 7..28 touch the gesture -> +3
    assert_array_equal(
        sample_windows(y, window=20, rest_step=7, gesture_step=3),
        [0, 7, 10, 13, 16, 19, 22, 25, 28],
    )


def test_sample_windows_counts_the_last_frame_of_a_window():
    # docs/method.md §7.1: a window whose only gesture frame is its last one is not
    # all rest, so the next window starts gesture_step (2) frames later
    y = np.zeros(30, int)
    y[9] = 1
    assert_array_equal(sample_windows(y)[:3], [0, 2, 4])
    y = np.zeros(30, int)
    y[10] = 1  # just outside the first window: it is all rest
    assert_array_equal(sample_windows(y)[:3], [0, 5, 7])


def test_sample_windows_short_and_empty_sequences():
    assert_array_equal(sample_windows(np.ones(7, int)), [0])
    assert_array_equal(sample_windows(np.zeros(10, int)), [0])
    assert sample_windows(np.zeros(0, int)).shape == (0,)


def test_training_windows_pad_short_sequence_and_ignore_padding():
    X = [np.arange(24.0).reshape(12, 2), np.ones((4, 2))]
    y = [np.r_[np.zeros(6, int), np.ones(6, int)], np.array([0, 2, 2, 0])]
    Xw, yw, seq = _training_windows(X, y, 10, 5, 2)
    # sequence 0: starts 0 and 2 (both windows hold gesture frames); sequence 1: padded
    assert Xw.shape == (3, 10, 2) and Xw.dtype == np.float32
    assert_array_equal(seq, [0, 0, 1])
    assert_array_equal(Xw[1], X[0][2:12])
    assert_array_equal(yw[2], [0, 2, 2, 0] + [IGNORE_INDEX] * 6)
    assert_array_equal(Xw[2, 4:], 0.0)


def test_inference_chunks():
    assert _chunks(23, 10, False) == [(0, 10), (10, 20), (20, 23)]
    assert _chunks(23, 10, True) == [(0, 10), (5, 15), (10, 20), (13, 23)]
    assert _chunks(20, 10, True) == [(0, 10), (5, 15), (10, 20)]
    assert _chunks(4, 10, True) == [(0, 4)]
    assert _chunks(1, 10, False) == [(0, 1)]


def test_sequence_holdout_keeps_sequences_whole():
    seq = np.repeat(np.arange(10), 3)
    train, valid = SequenceSplit(0.2, 0, seq)(list(range(30)))
    held = np.unique(seq[valid.indices])
    assert len(held) == 2
    assert not np.isin(seq[train.indices], held).any()
    assert len(train) + len(valid) == 30


# -- network, loss, optimiser ----------------------------------------------------


def _paper_module(n_inputs, n_outputs, hidden_sizes, dropout):
    return RecurrentTaggerModule(
        n_inputs, n_outputs, hidden_sizes, dropout=dropout, **PAPER_MODULE
    )


def test_module_initialisation_follows_matlab_defaults():
    torch.manual_seed(0)
    m = _paper_module(5, 3, hidden_sizes=(4, 3), dropout=0.5)
    lstm = m.layers[0]
    H = 4
    assert_allclose(lstm.bias_ih_l0[H : 2 * H].detach(), 1.0)  # forget gate
    assert_allclose(lstm.bias_ih_l0[:H].detach(), 0.0)
    assert_allclose(lstm.bias_ih_l0[2 * H :].detach(), 0.0)
    assert_allclose(lstm.bias_hh_l0_reverse.detach(), 0.0)
    W = lstm.weight_hh_l0.detach().numpy()
    assert_allclose(W.T @ W, np.eye(H), atol=1e-5)  # orthogonal
    bound = np.sqrt(6.0 / (5 + 4 * H))  # Glorot uniform on (4H, n_inputs)
    assert np.abs(lstm.weight_ih_l0.detach().numpy()).max() <= bound
    assert m.layers[1].input_size == 2 * H
    assert m.head.in_features == 6 and m.head.out_features == 3
    assert m(torch.zeros(2, 7, 5)).shape == (2, 7, 3)


def test_module_leaky_relu_and_dropout_only_between_lstms():
    m = _paper_module(3, 2, hidden_sizes=(4, 4, 2), dropout=0.6)
    assert m.activation.negative_slope == 0.01
    assert m.dropout.p == 0.6
    calls = []
    m.activation.register_forward_hook(lambda *a: calls.append("act"))
    m.dropout.register_forward_hook(lambda *a: calls.append("drop"))
    m.eval()
    m(torch.zeros(1, 5, 3))
    assert calls == ["act", "drop", "act", "drop"]


def test_bilstm_module_of_saved_taggers_still_loads():
    # Taggers saved before Method C's network became RecurrentTaggerModule hold
    # a _BiLSTMModule whose layers are called `lstms`: pickles and model files
    # (state dicts) of them load, with the same initial draws and outputs.
    torch.manual_seed(0)
    new = _paper_module(5, 3, (4, 3), 0.0).eval()
    torch.manual_seed(0)
    old = _BiLSTMModule(5, 3, hidden_sizes=(4, 3), dropout=0.0).eval()
    x = torch.randn(2, 7, 5)
    assert torch.equal(old(x), new(x))
    state = {k.replace("layers.", "lstms.", 1): v for k, v in new.state_dict().items()}
    fresh = _BiLSTMModule(5, 3, hidden_sizes=(4, 3), dropout=0.0).eval()
    fresh.load_state_dict(state)
    assert torch.equal(fresh(x), new(x))
    legacy = pickle.loads(pickle.dumps(old))
    legacy.__dict__["_modules"] = {
        ("lstms" if k == "layers" else k): v for k, v in legacy._modules.items()
    }
    del legacy.__dict__["cell"]
    loaded = pickle.loads(pickle.dumps(legacy))
    assert torch.equal(loaded(x), new(x))


def test_network_is_the_shared_recurrent_module(fitted):
    module = fitted.net_.module_
    assert type(module) is RecurrentTaggerModule and module.cell == "lstm"
    assert isinstance(module.layers[0], torch.nn.LSTM)
    assert fitted.net_.criterion_.time_reduction == "sum"
    assert fitted.get_params().keys().isdisjoint({"smoothing", "max_gap"})


def test_step_cross_entropy_sum_is_steps_times_mean():
    torch.manual_seed(0)
    logits = torch.randn(3, 10, 4)
    target = torch.randint(0, 4, (3, 10))
    total = FramewiseLoss("sum")(logits, target).item()
    mean = FramewiseLoss("mean")(logits, target).item()
    ref = torch.nn.functional.cross_entropy(logits.reshape(-1, 4), target.reshape(-1))
    assert_allclose(mean, ref.item(), rtol=1e-6)
    assert_allclose(total, 10 * mean, rtol=1e-6)
    target[0, 5:] = IGNORE_INDEX
    ref = torch.nn.functional.cross_entropy(
        logits[0, :5], target[0, :5], reduction="sum"
    )
    assert_allclose(
        FramewiseLoss("sum")(logits[:1], target[:1]).item(), ref.item(), rtol=1e-6
    )


def test_learning_rate_schedule_values():
    X = [np.random.RandomState(0).normal(size=(30, 2))]
    y = [np.r_[np.zeros(15, int), np.ones(15, int)]]
    tagger = BiLSTMTagger(hidden_sizes=(2,), max_epochs=150, random_state=0).fit(X, y)
    lrs = tagger.net_.history[:, "event_lr"]
    assert len(lrs) == 150
    for epoch, lr in LR_GT.items():
        assert_allclose(lrs[epoch - 1], lr, rtol=LR_RTOL)
    assert_allclose(lrs[:10], 0.01)
    assert_allclose(lrs[10:20], 0.0085)


def test_weight_decay_on_weights_only(fitted):
    groups = fitted.net_.optimizer_.param_groups
    names = dict(fitted.net_.module_.named_parameters())
    by_id = {id(p): n for n, p in names.items()}
    decay = {by_id[id(p)]: g["weight_decay"] for g in groups for p in g["params"]}
    assert set(decay) == set(names)
    for name, wd in decay.items():
        assert wd == (0.0 if "bias" in name else 1e-4), name
    assert groups[0]["momentum"] == 0.9


# -- predictions and decision rules ----------------------------------------------


def test_learns_two_class_toy_stream(fitted, toy_test):
    X, y = toy_test
    assert fitted.score(X, y) >= 0.9
    assert jaccard_index(y, fitted.predict(X), mode="official_2014") >= 0.9
    assert_array_equal(fitted.classes_, [0, 1, 2])


def test_predict_proba_shape_and_rows_sum_to_one(fitted, toy_test):
    X = toy_test[0][:3] + [np.zeros((1, 4)), np.zeros((13, 4))]
    proba = fitted.predict_proba(X)
    assert [p.shape for p in proba] == [(len(x), 3) for x in X]
    for p in proba:
        assert_allclose(p.sum(axis=1), 1.0, rtol=1e-6)
        assert (p >= 0).all()
    assert [p.shape for p in fitted.predict(X)] == [(len(x),) for x in X]


def test_chunks_are_run_with_fresh_state(fitted, toy_test):
    x = toy_test[0][0]
    whole = fitted.predict_proba([x])[0]
    parts = fitted.predict_proba([x[s:e] for s, e in _chunks(len(x), 10, False)])
    assert_allclose(whole, np.concatenate(parts), atol=1e-6)


def test_overlap_averages_windows(fitted, toy_test):
    x = toy_test[0][0][:23]
    tagger = pickle.loads(pickle.dumps(fitted)).set_params(overlap=True)
    parts = fitted.predict_proba([x[0:10], x[5:15], x[10:20], x[13:23]])
    proba = tagger.predict_proba([x])[0]
    assert_allclose(proba[7], (parts[0][7] + parts[1][2]) / 2, atol=1e-6)
    assert_allclose(proba[12], (parts[1][7] + parts[2][2]) / 2, atol=1e-6)
    assert_allclose(proba[14], (parts[1][9] + parts[2][4] + parts[3][1]) / 3, atol=1e-6)
    assert_allclose(proba[22], parts[3][9], atol=1e-6)


def test_min_run_turns_short_runs_to_rest(fitted):
    # A smoothed track whose arg-max is 1 for 6 frames, then 2 for 20 frames.
    track = np.zeros((30, 3))
    track[:, 0] = 0.5
    track[2:8, 1] = 0.9
    track[8:28, 2] = 0.9
    tagger = clone(fitted).set_params(min_run=7, smooth_span=1)  # span 1: as is
    tagger.classes_ = fitted.classes_
    assert_array_equal(tagger._decode(track), [0] * 8 + [2] * 20 + [0] * 2)
    tagger.set_params(min_run=6)
    assert_array_equal(tagger._decode(track), [0] * 2 + [1] * 6 + [2] * 20 + [0] * 2)


def test_min_run_and_smooth_span_change_predictions_without_refit(fitted, toy_test):
    X = toy_test[0]
    tagger = pickle.loads(pickle.dumps(fitted))
    tagger.set_params(min_run=1, smooth_span=1)
    raw = [fitted.classes_[p.argmax(axis=1)] for p in fitted.predict_proba(X)]
    assert all(np.array_equal(a, b) for a, b in zip(tagger.predict(X), raw))
    tagger.set_params(min_run=200)
    assert all((p == 0).all() for p in tagger.predict(X))


def test_predict_segments_format_and_confidence(fitted, toy_test):
    X, y = toy_test
    segs = fitted.predict_segments(X[:2])
    labels = fitted.predict(X[:2])
    proba = fitted.predict_proba(X[:2])
    for s, lab, p in zip(segs, labels, proba):
        assert s.shape[1] == 4
        for c, a, b, conf in s:
            c, a, b = int(c), int(a), int(b)
            assert (lab[a:b] == c).all()
            assert_allclose(conf, p[a:b, c].mean())
        assert len(s) == 2  # two gestures per toy sequence


def test_decision_function_is_loess_of_proba(fitted, toy_test):
    from skgesture.utils._smoothing import loess_smooth

    x = toy_test[0][0]
    smooth = fitted.decision_function([x])[0]
    assert_allclose(smooth, loess_smooth(fitted.predict_proba([x])[0], 15, axis=0))


# -- persistence, randomness, caching ----------------------------------------------


def test_joblib_round_trip_gives_identical_predictions(fitted, toy_test, tmp_path):
    X = toy_test[0][:3]
    joblib.dump(fitted, tmp_path / "tagger.joblib")
    loaded = joblib.load(tmp_path / "tagger.joblib")
    for a, b in zip(fitted.predict_proba(X), loaded.predict_proba(X)):
        assert_array_equal(a, b)
    for a, b in zip(fitted.predict(X), loaded.predict(X)):
        assert_array_equal(a, b)


def test_same_seed_same_predictions(toy, toy_test):
    X, y = toy[0][:6], toy[1][:6]
    a = BiLSTMTagger(**TINY).fit(X, y).predict_proba(toy_test[0][:2])
    b = BiLSTMTagger(**TINY).fit(X, y).predict_proba(toy_test[0][:2])
    c = (
        BiLSTMTagger(**{**TINY, "random_state": 1})
        .fit(X, y)
        .predict_proba(toy_test[0][:2])
    )
    for pa, pb, pc in zip(a, b, c):
        assert_array_equal(pa, pb)
        assert not np.allclose(pa, pc)


def test_fit_does_not_touch_global_torch_rng(toy):
    torch.manual_seed(123)
    expected = torch.rand(3)
    torch.manual_seed(123)
    BiLSTMTagger(**{**TINY, "max_epochs": 1}).fit(toy[0][:2], toy[1][:2])
    assert_array_equal(torch.rand(3), expected)


def test_memory_caches_network_across_decision_params(toy, tmp_path, monkeypatch):
    X, y = toy[0][:8], toy[1][:8]
    calls = []
    original = _BiLSTMNet.fit

    def counting_fit(self, X, y):
        calls.append(1)
        return original(self, X, y)

    monkeypatch.setattr(_BiLSTMNet, "fit", counting_fit)
    memory = joblib.Memory(tmp_path, verbose=0)
    params = {**TINY, "max_epochs": 30, "memory": memory}
    t0 = time.perf_counter()
    first = BiLSTMTagger(**params).fit(X, y)
    t_first = time.perf_counter() - t0
    t0 = time.perf_counter()
    second = BiLSTMTagger(**params, smooth_span=7, min_run=3, overlap=True).fit(X, y)
    t_second = time.perf_counter() - t0
    assert len(calls) == 1
    assert t_second < t_first / 3
    s1, s2 = first.net_.module_.state_dict(), second.net_.module_.state_dict()
    assert s1.keys() == s2.keys()
    for key in s1:
        assert torch.equal(s1[key], s2[key])
    # a network parameter changes the key
    BiLSTMTagger(**{**params, "hidden_sizes": (4,)}).fit(X, y)
    assert len(calls) == 2


def test_n_threads_applies_during_fit_and_is_restored(toy, monkeypatch):
    seen = []
    original = _BiLSTMNet.fit

    def spying_fit(self, X, y):
        seen.append(torch.get_num_threads())
        return original(self, X, y)

    monkeypatch.setattr(_BiLSTMNet, "fit", spying_fit)
    X, y = toy[0][:2], toy[1][:2]
    torch.set_num_threads(2)
    BiLSTMTagger(**{**TINY, "max_epochs": 1}).fit(X, y)
    assert seen == [1] and torch.get_num_threads() == 2
    torch.set_num_threads(1)
    BiLSTMTagger(**{**TINY, "max_epochs": 1}, n_threads=None).fit(X, y)
    assert seen == [1, 1]


def test_verbose_prints_epochs_only_when_asked(toy, capsys):
    X, y = toy[0][:2], toy[1][:2]
    BiLSTMTagger(**{**TINY, "max_epochs": 2}).fit(X, y)
    assert capsys.readouterr().out == ""
    BiLSTMTagger(**{**TINY, "max_epochs": 2, "verbose": 1}).fit(X, y)
    out = capsys.readouterr().out
    assert "epoch" in out and "train_loss" in out


def test_early_stopping_validates_on_held_out_sequences(toy):
    X, y = toy[0][:6], toy[1][:6]
    tagger = BiLSTMTagger(
        **{**TINY, "max_epochs": 40},
        early_stopping=True,
        n_iter_no_change=3,
        validation_fraction=0.2,
    ).fit(X, y)
    history = tagger.net_.history
    assert "valid_loss" in history[-1] and len(history) <= 40
    stopper = dict(tagger.net_.callbacks_)["early_stopping"]
    assert stopper.load_best and stopper.patience == 3
    with pytest.raises(ValueError, match="at least 2 training sequences"):
        BiLSTMTagger(**TINY, early_stopping=True).fit(X[:1], y[:1])


@pytest.mark.skipif(torch.cuda.is_available(), reason="needs a machine without CUDA")
def test_cuda_tagged_model_loads_on_cpu(fitted, toy_test):
    # A net saved from a GPU records device="cuda"; skorch maps it to the CPU with a
    # DeviceWarning when CUDA is unavailable (the real GPU round trip is below).
    tagger = pickle.loads(pickle.dumps(fitted))
    tagger.net_.device = "cuda"
    blob = pickle.dumps(tagger)
    with pytest.warns(UserWarning) as record:
        loaded = pickle.loads(blob)
    assert any("no CUDA devices are available" in str(w.message) for w in record)
    assert str(loaded.net_.device) == "cpu"
    X = toy_test[0][:2]
    for a, b in zip(fitted.predict_proba(X), loaded.predict_proba(X)):
        assert_array_equal(a, b)


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs CUDA")
def test_gpu_model_predicts_on_cpu(toy, tmp_path):
    X, y = toy
    tagger = BiLSTMTagger(**TINY, device="cuda").fit(X[:4], y[:4])
    expected = tagger.predict(X[4:6])
    path = tmp_path / "gpu.joblib"
    joblib.dump(tagger, path)
    np.save(tmp_path / "x0.npy", X[4])
    code = (
        "import joblib, numpy as np, warnings; warnings.simplefilter('ignore'); "
        f"t = joblib.load({str(path)!r}); "
        f"print(t.predict([np.load({str(tmp_path / 'x0.npy')!r})])[0].tolist())"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "CUDA_VISIBLE_DEVICES": ""},
    ).stdout
    assert out.strip() == str(expected[0].tolist())


# -- input checks ----------------------------------------------------------------


@pytest.mark.parametrize(
    "X, y, match",
    [
        ([], [], "empty"),
        ([np.zeros((20, 4, 3))], [np.zeros(20, int)], "expected"),
        ([np.full((20, 2), np.nan)], [np.r_[np.zeros(10), np.ones(10)]], "NaN"),
        ([np.zeros((20, 2))], [np.r_[np.zeros(10), -np.ones(10)]], "negative"),
        ([np.zeros((20, 2))], [np.ones(20, int)], "no rest frame"),
        ([np.zeros((20, 2))], [np.zeros(20, int)], "no gesture frame"),
        ([np.zeros((20, 2))], [np.zeros(19, int)], "19 labels"),
        ([np.zeros((20, 2))], [np.r_[np.zeros(10), np.full(10, 1.5)]], "integer"),
    ],
)
def test_fit_rejects_bad_input(X, y, match):
    with pytest.raises(ValueError, match=match):
        BiLSTMTagger(**TINY).fit(X, y)


def test_fit_rejects_bad_hidden_sizes():
    X, y = [np.zeros((20, 2))], [np.r_[np.zeros(10, int), np.ones(10, int)]]
    for bad in [(), (0,), (4, 2.5)]:
        with pytest.raises(ValueError, match="hidden_sizes"):
            BiLSTMTagger(**{**TINY, "hidden_sizes": bad}).fit(X, y)
    with pytest.raises(ValueError, match="dropout"):
        BiLSTMTagger(**{**TINY, "dropout": 1.0}).fit(X, y)


def test_predict_checks_features_and_fit(fitted):
    with pytest.raises(ValueError, match="as seen in fit"):
        fitted.predict([np.zeros((20, 3))])
    with pytest.raises(ValueError, match="empty"):
        fitted.predict_proba([])
    from sklearn.exceptions import NotFittedError

    with pytest.raises(NotFittedError):
        BiLSTMTagger().predict([np.zeros((20, 4))])


def test_short_training_sequence_is_one_padded_window():
    rng = np.random.RandomState(0)
    X = [rng.normal(size=(30, 2)), rng.normal(size=(6, 2))]
    y = [np.r_[np.zeros(15, int), np.ones(15, int)], np.array([0, 0, 2, 2, 2, 0])]
    tagger = BiLSTMTagger(**TINY).fit(X, y)
    assert_array_equal(tagger.classes_, [0, 1, 2])
    assert tagger.n_windows_ == len(sample_windows(y[0])) + 1
    assert tagger.predict([rng.normal(size=(1, 2))])[0].shape == (1,)


# -- sklearn integration -----------------------------------------------------------


def test_clone_get_set_params():
    tagger = BiLSTMTagger(hidden_sizes=(4, 4), min_run=9, random_state=3)
    params = clone(tagger).get_params()
    assert params["hidden_sizes"] == (4, 4) and params["min_run"] == 9
    assert params["random_state"] == 3 and params["window"] == 10
    tagger.set_params(smooth_span=21, hidden_sizes=(8,))
    assert tagger.smooth_span == 21 and tagger.hidden_sizes == (8,)


def test_paper_configuration():
    paper = BiLSTMTagger.paper(device="cuda", min_run=10)
    assert paper.hidden_sizes == (1024, 1024, 512)
    assert paper.dropout == 0.6 and paper.max_epochs == 150
    assert paper.device == "cuda" and paper.min_run == 10
    assert paper.learning_rate == 0.01 and paper.batch_size == 128
    assert paper.lr_drop_factor == 0.85 and paper.lr_drop_period == 10
    assert paper.momentum == 0.9 and paper.weight_decay == 1e-4
    assert paper.window == 10 and paper.rest_step == 5 and paper.gesture_step == 2
    default = BiLSTMTagger()
    assert default.hidden_sizes == (64, 64) and default.max_epochs == 40
    assert default.smooth_span == 15 and default.min_run == 15


def test_make_method_c():
    pipe = make_method_c(joints="full20", memory="cache", random_state=2, verbose=1)
    assert [name for name, _ in pipe.steps] == ["descriptor", "tagger"]
    assert pipe.named_steps["descriptor"].joints == "full20"
    tagger = pipe.named_steps["tagger"]
    assert tagger.hidden_sizes == (64, 64) and tagger.memory == "cache"
    assert tagger.random_state == 2 and tagger.verbose == 1
    paper = make_method_c(paper=True, device="cuda").named_steps["tagger"]
    assert paper.hidden_sizes == (1024, 1024, 512) and paper.device == "cuda"


def _skeleton_streams(n):
    pairs = [make_skeleton_stream(random_state=s) for s in range(n)]
    return [p[0] for p in pairs], [p[1] for p in pairs]


def test_pipeline_and_grid_search_over_min_run(tmp_path, monkeypatch):
    X, y = _skeleton_streams(4)
    groups = np.array([0, 0, 1, 1])
    calls = []
    original = _BiLSTMNet.fit

    def counting_fit(self, X, y):
        calls.append(1)
        return original(self, X, y)

    monkeypatch.setattr(_BiLSTMNet, "fit", counting_fit)
    pipe = Pipeline(
        [
            ("descriptor", PoseDescriptor()),
            (
                "tagger",
                BiLSTMTagger(
                    **{**TINY, "max_epochs": 3},
                    memory=joblib.Memory(tmp_path, verbose=0),
                ),
            ),
        ]
    )
    pred = pipe.fit(X, y).predict(X[:1])
    assert pred[0].shape == y[0].shape
    assert set(np.unique(pred[0])) <= {0, 1, 2, 3}
    calls.clear()
    pipe.set_params(tagger__memory=joblib.Memory(tmp_path / "grid", verbose=0))
    search = GridSearchCV(pipe, {"tagger__min_run": [1, 15]}, cv=GroupKFold(2))
    search.fit(X, y, groups=groups)
    assert len(calls) == 3  # one per fold and the refit, not one per candidate
    scores = search.cv_results_["mean_test_score"]
    assert scores.shape == (2,) and np.all((scores >= 0) & (scores <= 1))
    assert search.best_params_["tagger__min_run"] in (1, 15)


# -- values float32 cannot hold ------------------------------------------------------
# (untracked frames are rest by construction, in every tagger:
# tests/test_tagger_base.py)


@pytest.mark.parametrize(
    "value, match",
    [(1e39, r"X\[0\] has the value 1e\+39 at frame 4"),
     (np.inf, r"X\[0\] contains NaN or infinite values \(first at frame 4\)")],
)  # fmt: skip
def test_values_float32_cannot_hold_are_refused(fitted, toy, value, match):
    X, y = toy
    x = X[0].copy()
    x[4, 1] = value
    with pytest.raises(ValueError, match=match):
        fitted.predict([x])
    with pytest.raises(ValueError, match=match):
        BiLSTMTagger(**TINY).fit([x] + X[1:], y)


def test_hidden_sizes_are_validated_as_a_parameter():
    from sklearn.utils._param_validation import InvalidParameterError

    X, y = [np.zeros((20, 2))], [np.r_[np.zeros(10, int), np.ones(10, int)]]
    for bad in [(), (0,), (4, 2.5), (True,), 8]:
        with pytest.raises(InvalidParameterError, match="'hidden_sizes' parameter"):
            BiLSTMTagger(**{**TINY, "hidden_sizes": bad}).fit(X, y)
