"""What every tagger shares: one training loop, one untracked-rows rule, one decoding.

BiLSTMTagger (Method C) and SequenceTagger differ only in their sampler (the
paper's windows, random crops), their optimiser and schedule, and their module;
these tests hold both to the shared behaviour.
"""

import threading

import numpy as np
import pytest
from numpy.testing import assert_array_equal

pytest.importorskip("skorch")
torch = pytest.importorskip("torch")

from sklearn.base import clone  # noqa: E402

from skgesture import BiLSTMTagger, SequenceTagger, VotingTagger  # noqa: E402
from skgesture._nn._training import (  # noqa: E402
    FramewiseLoss,
    SequenceSplit,
    held_out_sequences,
    near_boundary,
)
from skgesture.metrics import jaccard_index  # noqa: E402

TAGGERS = {
    "bilstm": lambda **p: BiLSTMTagger(hidden_sizes=(4,), max_epochs=2, **p),
    "sequence": lambda **p: SequenceTagger(
        hidden_sizes=(4,), max_epochs=2, steps_per_epoch=2, crop_length=32, **p
    ),
}


@pytest.fixture(autouse=True)
def _one_torch_thread():
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


def _streams(n=4, seed=0):
    """4-D streams: rest is noise, gesture 1 a bump on the first feature."""
    rng = np.random.RandomState(seed)
    X, y = [], []
    for _ in range(n):
        x = rng.normal(0, 0.2, (60, 4)).astype(np.float32)
        lab = np.zeros(60, dtype=np.int64)
        x[20:40, 0] += 1.5
        lab[20:40] = 1
        X.append(x)
        y.append(lab)
    return X, y


class _SaysGesture(torch.nn.Module):
    """Stand-in network whose logits favour class index 1 everywhere."""

    def __init__(self, n_classes):
        super().__init__()
        self.bias = torch.nn.Parameter(torch.zeros(n_classes))
        with torch.no_grad():
            self.bias[1] = 5.0

    def forward(self, X):
        return self.bias.expand(*X.shape[:2], -1)


@pytest.fixture(params=sorted(TAGGERS))
def gesture_everywhere(request):
    """A fitted tagger of each kind whose network says "gesture" on every frame."""
    X, y = _streams()
    tagger = TAGGERS[request.param](random_state=0).fit(X, y)
    tagger.net_.module_ = _SaysGesture(len(tagger.classes_))
    return tagger


@pytest.mark.parametrize("span", [1, 9])
def test_untracked_rows_are_rest_after_the_smoothing(gesture_everywhere, span):
    tagger = gesture_everywhere.set_params(smooth_span=span, min_run=1)
    x = np.ones((50, 4), dtype=np.float32)
    mask = np.zeros(x.shape, dtype=bool)
    mask[20:30] = True
    masked = np.ma.MaskedArray(x, mask=mask)
    zeroed = x.copy()
    zeroed[20:30] = 0.0  # all-zero rows of a plain array are untracked too
    for data in (masked, zeroed):
        proba = tagger.predict_proba([data])[0]
        assert_array_equal(proba[20:30], [[1.0, 0.0]] * 10)
        # Rest is set after the smoothing: the neighbours stay gestures.
        assert_array_equal(
            tagger.predict([data])[0], np.r_[[1] * 20, [0] * 10, [1] * 20]
        )
        segs = tagger.predict_segments([data])[0]
        assert_array_equal(segs[:, :3], [[1, 0, 20], [1, 30, 50]])
        if isinstance(tagger, BiLSTMTagger):  # its smoothed scores, public
            scores = tagger.decision_function([data])[0]
            assert_array_equal(scores[20:30], [[1.0, 0.0]] * 10)
            tracked = tagger.decision_function([x])[0]
            assert_array_equal(scores[:20], tracked[:20])
            assert_array_equal(scores[30:], tracked[30:])
    assert (tagger.predict([np.zeros_like(x)])[0] == 0).all()


def test_untracked_rows_count_before_min_run(gesture_everywhere):
    tagger = gesture_everywhere.set_params(smooth_span=1, min_run=15)
    x = np.ones((50, 4), dtype=np.float32)
    x[10:20] = 0.0  # leaves a 10-frame remnant, shorter than min_run
    assert_array_equal(tagger.predict([x])[0], np.r_[[0] * 20, [1] * 30])


# -- background recordings ---------------------------------------------------------

# Taggers trained long enough to learn the distractor of _distractors.
TRAINED = {
    "bilstm": lambda: BiLSTMTagger(hidden_sizes=(8,), max_epochs=30, random_state=0),
    "sequence": lambda: SequenceTagger(
        hidden_sizes=(8,), max_epochs=10, steps_per_epoch=5, crop_length=32,
        learning_rate=1e-2, random_state=0,
    ),
    "voting": lambda: VotingTagger([("a", TRAINED["sequence"]())], random_state=0),
}  # fmt: skip


def _distractors(n=4, seed=1):
    """Background streams (all rest): the gesture's bump on feature 0, but with
    feature 1 raised too, a motion that is not the gesture."""
    X, _ = _streams(n, seed)
    for x in X:
        x[20:40, 1] += 1.5
    return X, [np.zeros(len(x), dtype=np.int64) for x in X]


@pytest.mark.parametrize("kind", sorted(TRAINED))
def test_background_sequences_are_learnt_as_rest(kind):
    X, y = _streams(4)
    B, yb = _distractors()
    test, _ = _distractors(seed=2)
    gestures, _ = _streams(4, seed=3)
    alone = TRAINED[kind]().fit(X, y)
    # Without background the distractor is taken for the gesture ...
    assert np.mean([(p[20:40] > 0).mean() for p in alone.predict(test)]) > 0.5
    tagger = TRAINED[kind]().fit(X + B, y + yb)
    assert_array_equal(tagger.classes_, [0, 1])
    # ... with it, it is rest, and the gesture is still found.
    assert all((p == 0).all() for p in tagger.predict(test))
    assert np.mean([(p[20:40] > 0).mean() for p in tagger.predict(gestures)]) > 0.8


@pytest.mark.parametrize("kind", sorted(TRAINED))
def test_a_fit_with_only_background_is_refused(kind):
    B, yb = _distractors(2)
    with pytest.raises(
        ValueError, match=r"y has no gesture frame \(every label is 0\)"
    ):
        TRAINED[kind]().fit(B, yb)


@pytest.mark.parametrize("kind", sorted(TAGGERS))
def test_fit_leaves_the_global_torch_rng_alone(kind):
    X, y = _streams(2)
    torch.manual_seed(123)
    expected = torch.rand(3)
    torch.manual_seed(123)
    TAGGERS[kind](random_state=0).fit(X, y)
    assert_array_equal(torch.rand(3), expected)


@pytest.mark.parametrize("kind", sorted(TAGGERS))
def test_fits_in_parallel_threads_keep_their_seeds(kind):
    X, y = _streams(3)
    make = TAGGERS[kind]
    expected = [make(random_state=s).fit(X, y).predict_proba(X[:1])[0] for s in (0, 1)]
    found = [None, None]

    def fit(k):
        found[k] = make(random_state=k).fit(X, y).predict_proba(X[:1])[0]

    threads = [threading.Thread(target=fit, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(expected, found):
        assert_array_equal(a, b)


@pytest.mark.parametrize("kind", sorted(TAGGERS))
def test_early_stopping_holds_out_whole_sequences(kind):
    X, y = _streams(4)
    tagger = TAGGERS[kind](random_state=0, early_stopping=True, n_iter_no_change=1)
    history = tagger.fit(X, y).net_.history
    assert "valid_loss" in history[-1]
    assert dict(tagger.net_.callbacks_)["early_stopping"].load_best
    with pytest.raises(ValueError, match="at least 2 training sequences"):
        clone(tagger).fit(X[:1], y[:1])


def test_one_split_holds_out_the_same_sequences_of_windows_and_crops():
    from skgesture._nn._sequence_net import _CropData

    # Windows of 6 sequences (several per sequence) and the 6 sequences whole.
    seq = np.repeat(np.arange(6), [3, 1, 4, 2, 2, 5])
    _, valid = SequenceSplit(0.34, 7, seq)(list(range(len(seq))))
    held = np.unique(seq[valid.indices])
    X = [np.full((5, 2), i, np.float32) for i in range(6)]
    y = [np.zeros(5, np.int64)] * 6
    data = _CropData(X, y, crop_length=4, augmenter=None, mean=np.zeros(2),
                     scale=np.ones(2), seed=7)  # fmt: skip
    train, whole = SequenceSplit(0.34, 7)(data)
    assert len(whole) == len(held) == 2 and len(train) == 4
    assert sorted(held) == sorted(held_out_sequences(6, 0.34, 7))
    assert sorted(int(x[0, 0]) for x in whole.X) == sorted(held)
    # No validation: everything trains.
    assert SequenceSplit()(data) == (data, None)


@pytest.mark.parametrize("kind, bar_at_1", [("bilstm", False), ("sequence", True)])
def test_verbosity(kind, bar_at_1, capsys):
    X, y = _streams(2)
    TAGGERS[kind](random_state=0).fit(X, y)
    assert capsys.readouterr() == ("", "")
    TAGGERS[kind](random_state=0, verbose=1).fit(X, y)
    out, err = capsys.readouterr()
    # Method C prints its epochs from 1; the other taggers show a bar at 1.
    assert ("train_loss" in out) != bar_at_1 and ("epoch" in err) == bar_at_1
    TAGGERS[kind](random_state=0, verbose=2).fit(X, y)
    assert "train_loss" in capsys.readouterr().out


def test_framewise_loss_leaves_out_ignored_frames_and_adds_up_stages():
    torch.manual_seed(0)
    logits = torch.randn(2, 6, 3)
    target = torch.tensor([[0, 1, 2, 0, 1, 2], [2, 0, 1, -100, -100, -100]])
    keep = target.reshape(-1) != -100
    ref = torch.nn.functional.cross_entropy(
        logits.reshape(-1, 3)[keep], target.reshape(-1)[keep]
    )
    assert torch.allclose(FramewiseLoss()(logits, target), ref)
    assert torch.allclose(FramewiseLoss()((logits, logits), target), 2 * ref)
    weighted = FramewiseLoss(class_weight=[1.0, 0.0, 0.0])(logits, target)
    rest = target.reshape(-1)[keep] == 0
    ref0 = torch.nn.functional.cross_entropy(
        logits.reshape(-1, 3)[keep][rest], target.reshape(-1)[keep][rest]
    )
    assert torch.allclose(weighted, ref0)


def test_smoothing_margin_spares_the_true_boundaries_alone():
    # The smoothing loss holds every frame's log-probabilities to its
    # predecessor's; with a margin, pairs within it of a change of the target
    # feel no pull, the other pairs the same as without it.
    torch.manual_seed(0)
    target = torch.tensor([[0, 0, 0, 0, 1, 1, 1, 1, 1, 0, 0, -100]])
    near = near_boundary(target, 1)
    # pairs (t, t + 1): the changes are pairs 3 and 8; padding is no change
    assert near[0].tolist() == [
        False,
        False,
        True,
        True,
        True,
        False,
        False,
        True,
        True,
        True,
        False,
    ]
    assert near_boundary(target, 0)[0].nonzero().ravel().tolist() == [3, 8]

    def smoothing_grad(margin):
        logits = torch.randn(1, 12, 2, generator=torch.Generator().manual_seed(1))
        logits.requires_grad_(True)
        loss = FramewiseLoss(smoothing_weight=1.0, smoothing_margin=margin)
        no_smoothing = FramewiseLoss()
        (loss(logits, target) - no_smoothing(logits, target)).backward()
        return logits.grad[0].abs().sum(axis=1)

    spared, every = smoothing_grad(1), smoothing_grad(0)
    # frames 4 and 9 only meet pairs next to a change: no smoothing pull
    assert spared[4] == 0 and spared[9] == 0
    assert every[4] > 0 and every[9] > 0
    # without a boundary in the crop, the margin changes nothing
    flat = torch.zeros(1, 12, dtype=torch.long)
    logits = torch.randn(1, 12, 2)
    assert torch.equal(
        FramewiseLoss(smoothing_weight=0.15, smoothing_margin=2)(logits, flat),
        FramewiseLoss(smoothing_weight=0.15)(logits, flat),
    )
    # a crop of one frame has no pair to smooth: the loss is the cross-entropy
    one = torch.tensor([[1]])
    logits = torch.randn(1, 1, 2)
    assert near_boundary(one, 4).shape == (1, 0)
    assert torch.equal(
        FramewiseLoss(smoothing_weight=0.15, smoothing_margin=4)(logits, one),
        FramewiseLoss()(logits, one),
    )


def test_a_tcn_trained_with_a_smoothing_margin_learns_a_toy_stream():
    # the margin changes the training alone: a causal TCN trained with it still
    # finds the gesture of every unseen stream, and its seed fixes its output
    X, y = _streams(8, seed=0)
    X_test, y_test = _streams(4, seed=1)
    params = {
        "architecture": "tcn", "hidden_sizes": (8,), "tcn_layers": 3,
        "tcn_stages": 2, "lookahead": 2, "smoothing_weight": 0.15,
        "smoothing_margin": 2, "crop_length": 40, "batch_size": 8,
        "steps_per_epoch": 10, "max_epochs": 8, "random_state": 0,
    }  # fmt: skip
    tagger = SequenceTagger(**params).fit(X, y)
    pred = tagger.predict(X_test)
    assert jaccard_index(y_test, pred) >= 0.9
    again = SequenceTagger(**params).fit(X, y).predict_proba(X_test)
    for a, b in zip(tagger.predict_proba(X_test), again):
        np.testing.assert_array_equal(a, b)


# -- run rules: confidence floor and per-class duration ------------------------------


def _bursts(n=4, seed=0):
    """Streams of :func:`_streams` (a 20-frame gesture) with two 4-frame bursts
    of the same bump in the rest: brief motion that looks like the gesture,
    labelled rest."""
    X, y = _streams(n, seed)
    for x in X:
        x[4:8, 0] += 1.5
        x[48:52, 0] += 1.5
    return X, y


def test_fit_stores_the_short_gesture_of_every_class():
    X, y = _streams()
    y[0][20:26] = 2  # one 6-frame run of class 2; class 1 keeps 14-20 frames
    tagger = TAGGERS["sequence"](random_state=0).fit(X, y)
    assert_array_equal(tagger.classes_, [0, 1, 2])
    lengths = tagger.class_lengths_
    assert lengths[0] == 0 and lengths[2] == 6
    assert 14 <= lengths[1] <= 20


def test_min_duration_removes_brief_runs_and_keeps_the_gestures():
    tagger = TRAINED["sequence"]().fit(*_streams(3))
    x_test = _bursts(2, seed=5)[0]
    plain = tagger.predict(x_test)
    # the bump is what the network learnt: the bursts are gestures to it
    assert any(p[4:8].any() for p in plain)
    tagger.set_params(min_duration=0.5)  # half a short gesture: 7-10 frames
    kept = tagger.predict(x_test)
    for p in kept:
        assert not p[:15].any() and not p[45:].any()
        assert (p[22:38] == 1).all()
    # the toy stream is then recognised near perfectly, the bursts as rest
    y_test = _bursts(2, seed=5)[1]
    assert jaccard_index(y_test, kept) >= 0.9 > jaccard_index(y_test, plain)


def test_the_length_rule_scales_with_the_frame_rate():
    # the short gesture is measured in frames of the training data: the same
    # recordings at twice the rate give twice the lengths, and a model trained
    # at either rate keeps the same gestures of a stream at its own rate
    from skgesture import GesturePipeline
    from skgesture._rate import resample

    X, y = _streams(3)
    fast = [resample(x, 30, 60) for x in X]
    y_fast = [np.repeat(lab, 2)[: len(x)] for lab, x in zip(y, fast)]
    slow_tagger = TRAINED["sequence"]().fit(X, y)
    fast_tagger = TRAINED["sequence"]().fit(fast, y_fast)
    assert_array_equal(fast_tagger.class_lengths_, 2 * slow_tagger.class_lengths_)
    pipe = GesturePipeline([("tagger", slow_tagger)])
    pipe.fps_ = 30.0
    pipe[-1].set_params(min_duration=0.5)
    x_test = _bursts(1, seed=5)[0][0]
    at_60 = pipe.predict([resample(x_test, 30, 60)], fps=60)[0]
    assert at_60[44:56].sum() > 0 and not at_60[:30].any()  # gesture kept, bursts not


def test_max_duration_removes_runs_far_longer_than_the_gesture():
    # a 20-frame gesture is learnt; the same motion held for 80 frames (an
    # activity, not a command) is a gesture to the network, and rest once a
    # run may last at most twice the class's long gesture
    tagger = TRAINED["sequence"]().fit(*_streams(3))
    assert_array_equal(tagger.class_long_lengths_, [0, 20])
    rng = np.random.RandomState(5)
    held = rng.normal(0, 0.2, (140, 4)).astype(np.float32)
    held[30:110, 0] += 1.5
    gesture = _streams(1, seed=6)[0][0]
    plain = tagger.predict([held, gesture])
    assert plain[0][40:100].mean() > 0.9  # one long run of class 1
    tagger.set_params(max_duration=2.0)
    held_out, kept = tagger.predict([held, gesture])
    assert not held_out.any()
    assert_array_equal(kept, plain[1])
    assert (kept[22:38] == 1).all()


def test_min_confidence_drops_the_unsure_runs_only():
    tagger = TRAINED["sequence"]().fit(*_streams(3))
    x_test = _streams(2, seed=5)[0]
    segs = tagger.predict_segments(x_test)
    conf = np.concatenate([s[:, 3] for s in segs])
    assert len(conf) >= 2
    floor = float(np.median(conf))
    tagger.set_params(min_confidence=floor)
    kept = np.concatenate(tagger.predict_segments(x_test))
    assert_array_equal(np.sort(kept[:, 3]), np.sort(conf[conf >= floor]))
    tagger.set_params(min_confidence=1.0)
    assert not any(p.any() for p in tagger.predict(x_test))


def test_max_novelty_rejects_motion_unlike_the_training_gestures():
    # the bump is learnt with the other features at rest; the same bump while
    # the rest of the body is in a pose never seen (someone carrying, bending)
    # is a gesture to the network, and rest once novelty is limited
    tagger = TRAINED["sequence"]().fit(*_streams(3))
    assert tagger.novelty_.units_[0] == np.inf and np.isfinite(
        tagger.novelty_.units_[1]
    )
    x_test, y_test = _streams(2, seed=5)
    odd = x_test[1].copy()
    odd[:, 1:3] += 1.0
    plain = tagger.predict([x_test[0], odd])
    assert plain[1][22:38].mean() > 0.8  # the network says gesture
    tagger.set_params(max_novelty=2.0)  # no refit: a decoding rule
    kept, rejected = tagger.predict([x_test[0], odd])
    assert_array_equal(kept, plain[0])
    assert (kept[22:38] == 1).all() and not rejected.any()
    # the true gesture is near 1 unit from the training frames of its class
    score = tagger.novelty_.score(x_test[0][22:38], 1)
    assert np.median(score) < 2.0 < np.median(tagger.novelty_.score(odd[22:38], 1))
    assert_array_equal(tagger.novelty_.score(odd)[:, 1], tagger.novelty_.score(odd, 1))
    assert not tagger.novelty_.score(odd)[:, 0].any()  # rest is never novel


def test_novelty_learns_from_tracked_frames_and_needs_two_sequences_a_class():
    from skgesture.utils import PoseNovelty

    X, y = _streams(3)
    y[0][45:50] = 2  # class 2 in one sequence only: no held-out view of it
    X[1][20:30] = 0.0  # untracked frames, labelled 1, must not enter the bank
    tracked = [np.any(x != 0, axis=1) for x in X]
    nov = PoseNovelty(n_components=3, bank_size=16).fit(
        X, y, np.array([0, 1, 2]), tracked=tracked
    )
    assert nov.components_.shape == (3, 4)
    assert len(nov.banks_[1]) == 16 and not np.isfinite(nov.units_[2])
    assert not (
        np.abs(nov.banks_[1] - nov._project(np.zeros((1, 4)))).sum(1) < 1e-9
    ).any()
    assert not nov.score(X[0])[:, 2].any()  # never novel without a unit
    # bad input is named, not crashed on
    with pytest.raises(ValueError, match="empty"):
        PoseNovelty().fit([], [], np.array([0, 1]))
    with pytest.raises(ValueError, match="2 labels but X\\[0\\] has 60 frames"):
        PoseNovelty().fit(X[:1], [y[0][:2]], np.array([0, 1]))
    with pytest.raises(ValueError, match=r"shape \(n_frames, 4\).*\(5, 3\)"):
        nov.score(np.ones((5, 3)))
    bad = X[0].copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match="first at frame 7"):
        nov.score(bad)


def test_the_novelty_rule_judges_each_run_by_its_median_and_needs_the_rows():
    from skgesture._taggers._decoding import LabelRuns, reject_runs

    lab = np.array([0, 1, 1, 1, 0, 1, 1, 0])
    raw = np.eye(2)[lab]
    far = {1: 0.5, 2: 3.0, 3: 0.5, 5: 3.0, 6: 3.0}  # median 0.5, then 3.0

    def novelty(s, e, k):
        return np.array([far[i] for i in range(s, e)])

    kept = reject_runs(lab, raw, np.arange(2), novelty=novelty, max_novelty=1.0)
    assert kept.tolist() == [0, 1, 1, 1, 0, 0, 0, 0]
    with pytest.raises(ValueError, match="novelty"):
        reject_runs(lab, raw, np.arange(2), max_novelty=1.0)
    runs = LabelRuns(np.arange(2), 1, max_novelty=1.0)
    with pytest.raises(ValueError, match="novelty"):
        runs.feed(0, raw, raw, np.zeros(len(lab), bool), np.arange(len(lab)))


def test_max_novelty_on_a_model_fitted_without_novelty_says_so():
    tagger = TAGGERS["sequence"](random_state=0).fit(*_streams())
    del tagger.novelty_  # a model saved before the rule existed
    tagger.predict(_streams(1)[0])  # the rule off: no novelty needed
    tagger.set_params(max_novelty=2.0)
    with pytest.raises(ValueError, match="novelty_.*refit it"):
        tagger.predict(_streams(1)[0])


@pytest.mark.parametrize(
    "attribute, rule, off",
    [
        ("class_lengths_", {"min_duration": 0.3}, {"min_duration": 0.0}),
        ("class_long_lengths_", {"max_duration": 2.0}, {"max_duration": None}),
    ],
)
def test_a_length_rule_on_a_model_fitted_without_its_lengths_says_so(
    attribute, rule, off
):
    tagger = TAGGERS["sequence"](random_state=0).fit(*_streams())
    delattr(tagger, attribute)  # a model saved before the attribute existed
    tagger.set_params(**rule)
    with pytest.raises(ValueError, match=f"{attribute}.*refit it"):
        tagger.predict(_streams(1)[0])
    tagger.set_params(**off)
    tagger.predict(_streams(1)[0])
