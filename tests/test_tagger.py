"""SequenceTagger, VotingTagger, JointFeatures, SkeletonAugmenter and the decoding
path, and make_recommended (issue 8's test list)."""

import copy

import joblib
import numpy as np
import pytest
from joblib import Memory
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, LeaveOneGroupOut
from sklearn.utils._param_validation import InvalidParameterError

from skgesture import (
    JointFeatures,
    SequenceTagger,
    SkeletonAugmenter,
    VotingTagger,
    make_recommended,
)
from skgesture._augment import time_warp
from skgesture._taggers._decoding import decode, fill_short_gaps
from skgesture.metrics import jaccard_index
from skgesture.utils._testing import make_skeleton_stream

ARCHITECTURES = ["gru", "lstm", "tcn"]


def _toy(n_sequences=6, n_frames=120, seed=0):
    """Two-class toy streams: rest is noise, the gesture a bump on 2 features."""
    rng = np.random.RandomState(seed)
    X, y = [], []
    for _ in range(n_sequences):
        x = rng.normal(0, 0.1, (n_frames, 6)).astype(np.float32)
        lab = np.zeros(n_frames, dtype=np.int64)
        start = 0
        while True:
            start += rng.randint(15, 30)
            length = rng.randint(15, 25)
            if start + length >= n_frames:
                break
            bump = np.sin(np.linspace(0, np.pi, length))
            x[start : start + length, 0] += 2 * bump
            x[start : start + length, 1] -= 2 * bump
            lab[start : start + length] = 1
            start += length
        X.append(x)
        y.append(lab)
    return X, y


def _tagger(architecture="gru", **params):
    defaults = {
        "architecture": architecture,
        "hidden_sizes": (16,),
        "tcn_layers": 4,
        "crop_length": 64,
        "batch_size": 16,
        "max_epochs": 8,
        "steps_per_epoch": 10,
        "learning_rate": 1e-2,
        "random_state": 0,
    }
    return SequenceTagger(**{**defaults, **params})


@pytest.fixture(scope="module")
def toy():
    return _toy()


@pytest.fixture(scope="module")
def fitted_gru(toy):
    X, y = toy
    return _tagger().fit(X[:5], y[:5])


# -- learning ----------------------------------------------------------------------


@pytest.mark.parametrize("architecture", ARCHITECTURES)
def test_every_architecture_learns_a_two_class_toy_stream(toy, architecture):
    X, y = toy
    tagger = _tagger(architecture).fit(X[:5], y[:5])
    assert tagger.classes_.tolist() == [0, 1]
    assert jaccard_index(y[5:], tagger.predict(X[5:])) > 0.9


def test_voting_tagger_learns_and_averages(toy):
    X, y = toy
    vote = VotingTagger(
        [("gru", _tagger("gru")), ("tcn", _tagger("tcn"))], random_state=0
    ).fit(X[:5], y[:5])
    assert jaccard_index(y[5:], vote.predict(X[5:])) > 0.9
    members = [est.predict_proba(X[5:])[0] for est in vote.estimators_]
    np.testing.assert_allclose(vote.predict_proba(X[5:])[0], np.mean(members, axis=0))


def test_voting_weights_select_a_member(toy):
    X, y = toy
    vote = VotingTagger(
        [("a", _tagger(max_epochs=1)), ("b", _tagger("tcn"))],
        weights=[0, 1],
        random_state=0,
    ).fit(X[:5], y[:5])
    np.testing.assert_allclose(
        vote.predict_proba(X[5:])[0], vote.estimators_[1].predict_proba(X[5:])[0]
    )


# -- determinism and persistence -----------------------------------------------------


@pytest.mark.parametrize("architecture", ["gru", "tcn"])
def test_same_random_state_same_predictions(toy, architecture):
    X, y = toy
    a = _tagger(architecture, max_epochs=2, augment=SkeletonAugmenter(rotation=0))
    p1 = a.fit(X[:5], y[:5]).predict_proba(X[5:])
    p2 = clone(a).fit(X[:5], y[:5]).predict_proba(X[5:])
    np.testing.assert_array_equal(p1[0], p2[0])
    p3 = clone(a).set_params(random_state=1).fit(X[:5], y[:5]).predict_proba(X[5:])
    assert not np.array_equal(p1[0], p3[0])


def test_joblib_round_trip_gives_identical_predictions(fitted_gru, toy, tmp_path):
    X, _ = toy
    joblib.dump(fitted_gru, tmp_path / "tagger.joblib")
    loaded = joblib.load(tmp_path / "tagger.joblib")
    np.testing.assert_array_equal(
        loaded.predict_proba(X[5:])[0], fitted_gru.predict_proba(X[5:])[0]
    )


def test_thread_setting_is_restored(toy):
    import torch

    X, y = toy
    before = torch.get_num_threads()
    _tagger(max_epochs=1, n_threads=1).fit(X[:2], y[:2]).predict(X[:1])
    assert torch.get_num_threads() == before


def test_decoding_runs_on_n_threads_blas_threads_and_restores_them(
    fitted_gru, toy, monkeypatch
):
    # The novelty rule's products are small: BLAS threads beyond n_threads
    # only wait on a busy machine (skgesture/utils/_threads.py).
    from threadpoolctl import threadpool_info

    from skgesture.utils import _novelty

    X, _ = toy
    blas = [i for i in threadpool_info() if i["user_api"] == "blas"]
    if not blas:
        pytest.skip("no BLAS library loaded")
    before = [i["num_threads"] for i in blas]
    seen = []
    nearest = _novelty._nearest

    def record(*args):
        seen.append({i["num_threads"] for i in threadpool_info()
                     if i["user_api"] == "blas"})  # fmt: skip
        return nearest(*args)

    monkeypatch.setattr(_novelty, "_nearest", record)
    tagger = copy.deepcopy(fitted_gru).set_params(max_novelty=100.0, n_threads=1)
    as_is = copy.deepcopy(fitted_gru).set_params(max_novelty=100.0, n_threads=None)
    expected = as_is.predict(X)
    seen.clear()
    got = tagger.predict(X)
    assert seen and all(threads == {1} for threads in seen)
    assert [i["num_threads"] for i in threadpool_info()
            if i["user_api"] == "blas"] == before  # fmt: skip
    for a, b in zip(got, expected):
        np.testing.assert_array_equal(a, b)


# -- decoding without retraining ---------------------------------------------------


def test_decoding_parameters_change_predictions_without_retraining(toy, tmp_path):
    X, y = toy
    memory = Memory(tmp_path, verbose=0)
    tagger = _tagger(max_epochs=2, memory=memory).fit(X[:5], y[:5])
    first = tagger.predict(X[5:])[0]
    cached = clone(tagger).set_params(min_run=60, smooth_span=9)
    calls = []
    import skgesture._nn._sequence_net as module

    original = module._CropNet.fit

    def spy(self, *args, **kwargs):
        calls.append(1)
        return original(self, *args, **kwargs)

    module._CropNet.fit = spy
    try:
        cached.fit(X[:5], y[:5])
    finally:
        module._CropNet.fit = original
    assert calls == []  # the network came from the cache
    np.testing.assert_array_equal(
        cached.predict_proba(X[5:])[0], tagger.predict_proba(X[5:])[0]
    )
    second = cached.predict(X[5:])[0]
    assert not np.array_equal(first, second)
    assert set(np.unique(second)) <= {0, 1}
    # the per-class length rule too: class_lengths_ comes back with the network
    assert_lengths = cached.set_params(min_run=1, smooth_span=1, min_duration=0.8)
    np.testing.assert_array_equal(cached.class_lengths_, tagger.class_lengths_)
    for c, s, e, _ in assert_lengths.predict_segments(X[5:])[0]:
        k = int(np.searchsorted(cached.classes_, c))
        assert e - s >= 0.8 * cached.class_lengths_[k]


def test_decode_rules():
    p = np.zeros((12, 2))
    p[:, 0] = 1
    p[3:6] = [0, 1]
    p[7:10] = [0, 1]
    classes = np.array([0, 4])
    assert decode(p, classes).tolist() == [0, 0, 0, 4, 4, 4, 0, 4, 4, 4, 0, 0]
    merged = decode(p, classes, max_gap=1)
    assert merged.tolist() == [0, 0, 0] + [4] * 7 + [0, 0]
    assert decode(p, classes, max_gap=1, min_run=8).tolist() == [0] * 12
    assert decode(p, classes, min_run=4).tolist() == [0] * 12
    untracked = np.zeros(12, bool)
    untracked[4] = True
    assert decode(p, classes, untracked=untracked)[4] == 0


def test_fill_short_gaps_leaves_different_classes_apart():
    assert fill_short_gaps(np.array([1, 0, 2]), 5).tolist() == [1, 0, 2]
    assert fill_short_gaps(np.array([0, 0, 1]), 5).tolist() == [0, 0, 1]


# -- augmentation --------------------------------------------------------------------


def test_time_warp_keeps_labels_aligned_with_frames():
    n = 90
    x = np.zeros((n, 3), dtype=np.float32)
    y = np.zeros(n, dtype=np.int64)
    x[30:60, 0] = 1.0  # the gesture's frames carry a marker
    y[30:60] = 2
    for rate in (0.6, 0.85, 1.0, 1.3, 1.9):
        xw, yw = time_warp(x, y, rate)
        assert len(xw) == len(yw) == max(int(round(n * rate)), 2)
        # Every frame labelled 2 carries (some of) the marker, and every frame
        # whose marker is fully on is labelled 2.
        assert np.all(xw[yw == 2, 0] > 0.4)
        assert np.all(yw[xw[:, 0] > 0.99] == 2)


def test_augmenter_rotates_about_the_vertical_axis_and_keeps_lengths():
    rng = np.random.RandomState(0)
    x = rng.normal(size=(40, 12)).astype(np.float32)
    y = np.repeat([0, 1], 20)
    aug = SkeletonAugmenter(rotation=90, scale=0, time_warp=0, noise=0)
    xa, ya = aug.augment(x, y, np.random.RandomState(1))
    np.testing.assert_array_equal(ya, y)
    v, va = x.reshape(40, 4, 3), xa.reshape(40, 4, 3)
    np.testing.assert_allclose(va[..., 1], v[..., 1], atol=1e-6)  # y untouched
    np.testing.assert_allclose(
        np.hypot(va[..., 0], va[..., 2]), np.hypot(v[..., 0], v[..., 2]), atol=1e-5
    )
    with pytest.raises(ValueError, match="multiple of 3"):
        aug.augment(x[:, :5], y, np.random.RandomState(0))


def test_augmenter_crop_is_the_crop_of_the_whole_perturbation():
    """``augment(length=n)`` computes only the frames it returns, and they are
    those of the whole perturbation cropped at the next draw of ``rng``."""
    x = np.random.RandomState(0).normal(size=(300, 9)).astype(np.float32)
    y = np.arange(300) // 30
    for params in ({}, {"rotation": 0, "scale": 0}, {"time_warp": 0}):
        aug = SkeletonAugmenter(**params)
        for seed in range(20):
            for n, length in ((300, 64), (300, 400), (1, 8), (2, 1)):
                rng = np.random.RandomState(seed)
                xa, ya = aug.augment(x[:n], y[:n], rng, noise=False)
                if len(xa) > length:
                    s = rng.randint(len(xa) - length + 1)
                    xa, ya = xa[s : s + length], ya[s : s + length]
                rng = np.random.RandomState(seed)
                xc, yc = aug.augment(x[:n], y[:n], rng, noise=False, length=length)
                np.testing.assert_array_equal(xc, xa)
                np.testing.assert_array_equal(yc, ya)
    for bad in (0, -3, 2.5, True):
        with pytest.raises(ValueError, match="length must be a positive int"):
            aug.augment(x, y, np.random.RandomState(0), length=bad)


@pytest.mark.parametrize(
    "params",
    [{"rotation": 200}, {"scale": 1.0}, {"time_warp": -0.1}, {"noise": -1.0}],
)
def test_augmenter_parameters_are_validated(params):
    x, y = np.zeros((10, 3), np.float32), np.zeros(10, int)
    with pytest.raises(InvalidParameterError):
        SkeletonAugmenter(**params).augment(x, y, np.random.RandomState(0))


def test_training_crops_keep_labels_aligned(toy):
    from skgesture._nn._sequence_net import _CropData

    X, y = toy
    data = _CropData(
        X,
        y,
        crop_length=40,
        augmenter=SkeletonAugmenter(rotation=0, scale=0, time_warp=0.3, noise=0),
        mean=np.zeros(6),
        scale=np.ones(6),
        seed=0,
    )
    xb, yb = data.sample(64)
    xb, yb = xb.numpy(), yb.numpy()
    bump = xb[..., 0] - xb[..., 1]  # +4 at a bump's top, about 0 at rest
    assert np.all(yb[bump > 2.5] == 1)
    assert np.all(np.abs(bump[yb == 0]) < 1.5)


def test_training_crops_get_the_noise_of_the_raw_features_on_kept_frames_only():
    """The noise is drawn per batch, after standardisation: it must be the
    augmenter's ``noise`` in raw units on every real frame, none on padding,
    and the same batches for the same seed."""
    from skgesture._nn._sequence_net import _CropData

    X = [np.zeros((n, 4), np.float32) for n in (30, 500, 500)]
    y = [np.zeros(len(x), np.int64) for x in X]
    scale = np.array([1.0, 2.0, 0.5, 4.0])

    def batch(noise, seed=0):
        data = _CropData(
            X, y, crop_length=64, mean=np.zeros(4), scale=scale, seed=seed,
            augmenter=SkeletonAugmenter(rotation=0, scale=0, time_warp=0, noise=noise),
        )  # fmt: skip
        xb, yb = data.sample(256)
        return xb.numpy(), yb.numpy()

    xb, yb = batch(0.3)
    real = yb != -100
    assert (~real).any() and real.any()  # the 30-frame sequence is padded
    assert np.all(xb[~real] == 0)
    raw = xb[real] * scale  # back to the raw features' units
    np.testing.assert_allclose(raw.std(axis=0), 0.3, rtol=0.03)
    np.testing.assert_allclose(raw.mean(axis=0), 0.0, atol=0.01)
    np.testing.assert_array_equal(batch(0.3)[0], xb)
    assert not np.array_equal(batch(0.3, seed=1)[0], xb)
    assert np.all(batch(0.0)[0] == 0)
    # the augmenter alone, asked for no noise, adds none
    x = np.ones((20, 3), np.float32)
    aug = SkeletonAugmenter(rotation=0, scale=0, time_warp=0, noise=0.5)
    np.testing.assert_array_equal(
        aug.augment(x, y[0][:20], np.random.RandomState(0), noise=False)[0], x
    )
    assert not np.array_equal(aug.augment(x, y[0][:20], np.random.RandomState(0))[0], x)


def test_training_crops_read_independent_noise_from_a_bank_drawn_again(monkeypatch):
    """The crops' noise is read from a bank of normal values: within a crop
    no value repeats, the crops of a batch are uncorrelated, and the bank is
    drawn again once NOISE_REUSE times its size has been read."""
    from skgesture._nn import _sequence_net
    from skgesture._nn._sequence_net import _CropData

    monkeypatch.setattr(_sequence_net, "NOISE_BANK", 1)  # the crops' minimum
    monkeypatch.setattr(_sequence_net, "NOISE_CROPS", 8)
    monkeypatch.setattr(_sequence_net, "NOISE_REUSE", 4)
    X = [np.zeros((500, 5), np.float32) for _ in range(3)]
    y = [np.zeros(500, np.int64) for _ in X]
    data = _CropData(
        X, y, crop_length=40, mean=np.zeros(5), scale=np.ones(5), seed=0,
        augmenter=SkeletonAugmenter(rotation=0, scale=0, time_warp=0, noise=1.0),
    )  # fmt: skip
    xb = data.sample(2)[0].numpy()
    bank = data._bank
    assert bank.numel() == 8 * 40 * 5  # NOISE_CROPS crops of 40 frames of 5 features
    for crop in xb:  # every value of a crop is a distinct draw
        assert len(np.unique(crop)) == crop.size
    batch = data.sample(64)[0].numpy().reshape(64, -1)
    corr = np.corrcoef(batch)[np.triu_indices(64, 1)]
    assert np.abs(corr).mean() < 0.1 and np.abs(corr).max() < 0.5
    # 66 crops read 66 * 200 values > 4 * 1600: the bank was drawn again
    assert data._bank is not bank
    assert not np.isin(data._bank.numpy(), bank.numpy()).any()
    everything = np.concatenate([data.sample(16)[0].numpy().ravel() for _ in range(40)])
    assert abs(everything.std() - 1.0) < 0.03 and abs(everything.mean()) < 0.03


# -- JointFeatures -----------------------------------------------------------------


def test_joint_features_are_translation_and_scale_normalised():
    X, _ = make_skeleton_stream(random_state=0)
    feats = JointFeatures(joints="full20").fit([X])
    base = feats.transform([X])[0]
    moved = feats.transform([2.0 * X + np.array([0.5, -0.2, 1.0])])[0]
    np.testing.assert_allclose(moved, base, atol=1e-4)
    assert base.shape == (len(X), 120)
    names = feats.get_feature_names_out()
    assert names[0] == "pos_HipCenter_x" and names[-1] == "vel_FootRight_z"


def test_joint_features_mask_untracked_frames_and_tagger_predicts_rest(toy):
    X, y = make_skeleton_stream(random_state=0)
    X = X.copy()
    X[50:60] = 0.0
    feats = JointFeatures().fit([X])
    F = feats.transform([X])[0]
    assert isinstance(F, np.ma.MaskedArray)
    assert np.ma.getmaskarray(F)[50:60].all() and not np.ma.getmaskarray(F)[:50].any()
    tagger = _tagger(max_epochs=1).fit([F], [y])
    assert (tagger.predict([F])[0][50:60] == 0).all()
    proba = tagger.predict_proba([F])[0]
    np.testing.assert_array_equal(proba[50:60, 0], 1.0)


def test_all_untracked_sequence_is_rest_for_the_recommended_model():
    X, y = make_skeleton_stream(random_state=0)
    model = _tiny_recommended().fit([X], [y])
    assert (model.predict([np.zeros((80, 20, 3))])[0] == 0).all()
    assert (model.predict([np.full((30, 20, 3), np.nan)])[0] == 0).all()


def test_joint_features_refuse_unknown_joints():
    X, _ = make_skeleton_stream(random_state=0)
    with pytest.raises(ValueError, match="'Tail'"):
        JointFeatures(joints=["HipCenter", "Tail"]).fit([X])
    with pytest.raises(ValueError, match="root"):
        JointFeatures(joints=["Head", "HandLeft"]).fit([X])


# -- bad input -----------------------------------------------------------------------


def test_only_rest_labels_are_refused(toy):
    X, y = toy
    with pytest.raises(ValueError, match="no gesture frame"):
        _tagger().fit(X[:2], [np.zeros_like(v) for v in y[:2]])


def test_labels_without_rest_are_refused(toy):
    X, y = toy
    with pytest.raises(ValueError, match="no rest frame"):
        _tagger().fit(X[:2], [v + 1 for v in y[:2]])


def test_short_and_empty_sequences(fitted_gru):
    # Whole-sequence taggers have no minimum length: 1 and 3 frames predict.
    short = [np.zeros((1, 6), np.float32), np.ones((3, 6), np.float32)]
    assert [len(p) for p in fitted_gru.predict(short)] == [1, 3]
    with pytest.raises(ValueError, match=r"X\[1\] has 0 frames"):
        fitted_gru.predict([np.zeros((5, 6)), np.zeros((0, 6))])


def test_wrong_feature_count_and_non_finite_input_are_named(fitted_gru):
    with pytest.raises(ValueError, match=r"X\[0\].*\(7,\)"):
        fitted_gru.predict([np.zeros((10, 7))])
    bad = np.zeros((10, 6))
    bad[4, 2] = np.inf
    with pytest.raises(ValueError, match=r"X\[0\].*frame 4"):
        fitted_gru.predict([bad])


def test_unseen_class_in_score_warns(fitted_gru, toy):
    X, y = toy
    y_new = [v.copy() for v in y[5:]]
    y_new[0][y_new[0] == 1] = 7
    with pytest.warns(UserWarning, match="7"):
        fitted_gru.score(X[5:], y_new)


def test_voting_tagger_refuses_members_with_different_classes(toy):
    from skgesture import BiLSTMTagger

    X, y = toy

    class _Shifted(BiLSTMTagger):
        def fit(self, X, y):
            super().fit(X, y)
            self.classes_ = self.classes_ + 1
            return self

    vote = VotingTagger(
        [
            ("a", _tagger(max_epochs=1)),
            ("b", _Shifted(hidden_sizes=(4,), max_epochs=1, random_state=0)),
        ]
    )
    with pytest.raises(ValueError, match="tagger 'b' learned classes"):
        vote.fit(X[:2], y[:2])


@pytest.mark.parametrize(
    "params",
    [
        {"architecture": "transformer"},
        {"crop_length": 1},
        {"class_weight": "inverse"},
        {"smoothing": "gaussian"},
        {"augment": "rotate"},
        {"clip_norm": 0},
    ],
)
def test_invalid_parameters_raise_invalid_parameter_error(toy, params):
    X, y = toy
    with pytest.raises(InvalidParameterError):
        _tagger(**params).fit(X[:2], y[:2])


def test_hidden_sizes_are_checked(toy):
    X, y = toy
    with pytest.raises(ValueError, match="hidden_sizes"):
        _tagger(hidden_sizes=(0,)).fit(X[:2], y[:2])


def test_voting_tagger_checks_weights(toy):
    X, y = toy
    with pytest.raises(ValueError, match="weights"):
        VotingTagger([("a", _tagger())], weights=[np.nan]).fit(X[:2], y[:2])
    with pytest.raises(ValueError, match="empty"):
        VotingTagger([]).fit(X[:2], y[:2])


# -- background recordings ---------------------------------------------------------


def test_after_training_with_background_random_joint_motion_gives_no_event():
    """The toy stream of issue 14: a tiny tagger of the recommended kind (joint
    features, MS-TCN, augmentation), trained with and without background
    sequences of random joint motion, then run on random joint motion around
    the rest poses of other subjects."""
    from sklearn.pipeline import make_pipeline

    from skgesture.datasets import make_background, make_gesture_streams
    from skgesture.utils import labels_to_segments

    kw = {"n_classes": 3, "n_gestures": (3, 4), "oov_rate": 0.0, "dropout_rate": 0.0}
    train = make_gesture_streams(6, random_state=0, **kw)
    test = make_gesture_streams(3, random_state=1, **kw)
    background = make_background(train.X, train.y, n_sequences=6, n_frames=3000,
                                 kinds="motion", random_state=0)  # fmt: skip
    motion = make_background(test.X, test.y, n_sequences=10, kinds="motion",
                             random_state=1)  # fmt: skip

    def fit(X, y):
        tagger = SequenceTagger(
            architecture="tcn", hidden_sizes=(16,), tcn_layers=5, tcn_stages=2,
            dropout=0.3, smoothing_weight=0.15, crop_length=96, batch_size=8,
            steps_per_epoch=10, max_epochs=20, min_run=5, random_state=0,
            augment=SkeletonAugmenter(rotation=20.0, scale=0.15, noise=0.02),
        )  # fmt: skip
        return make_pipeline(JointFeatures(), tagger).fit(X, y)

    def n_events(model, X):
        return sum(len(labels_to_segments(p)) for p in model.predict(X))

    alone = fit(train.X, train.y)
    assert n_events(alone, motion.X) >= 1  # 1 to 8 events over seeds 0-4
    model = fit(train.X + background.X, train.y + background.y)
    assert n_events(model, motion.X) == 0  # 0 for each of seeds 0-4
    # ... and it still finds the gestures of the held-out streams
    assert n_events(model, test.X) >= sum(len(s) for s in test.segments) // 2
    assert jaccard_index(test.y, model.predict(test.X)) > 0.35


# -- make_recommended --------------------------------------------------------------


def _tiny_recommended(**params):
    return make_recommended(random_state=0, **params).set_params(
        **_tiny_tagger_params()
    )


def _tiny_tagger_params():
    model = make_recommended()
    tagger = model.steps[-1][1]
    prefix = model.steps[-1][0]
    members = (
        [f"{prefix}__{name}" for name, _ in tagger.estimators]
        if isinstance(tagger, VotingTagger)
        else [prefix]
    )
    tiny = {"hidden_sizes": (8,), "max_epochs": 1, "steps_per_epoch": 3}
    return {f"{m}__{k}": v for m in members for k, v in tiny.items()}


@pytest.mark.parametrize("joints, width", [("paper11", 66), ("full20", 120)])
def test_make_recommended_builds_the_documented_pipeline(joints, width):
    model = make_recommended(joints=joints, features="joints", random_state=0)
    X, y = make_skeleton_stream(random_state=0)
    features = model.steps[0][1].fit([X])
    assert features.n_features_out_ == width
    assert model.steps[0][1].joints == joints


def test_make_recommended_default_streams_exactly_on_the_descriptor():
    # the default is chosen by its worst case among exactly streaming models
    model = make_recommended(joints="paper11", random_state=0)
    assert type(model.steps[0][1]).__name__ == "PoseDescriptor"
    assert model.steps[0][1].fill == "hold"  # untracked frames as live
    assert model.steps[-1][1].lookahead == 8
    assert model.steps[-1][1].viterbi_decision == "run"
    assert model.steps[-1][1].viterbi_lag == 4
    assert model.steps[-1][1].smoothing_margin == 4  # onsets not smoothed away
    assert model.steps[-1][1].max_novelty == 1.5
    assert make_recommended(lookahead=None).steps[0][1].fill == "linear"
    offline = make_recommended(features="joints", lookahead=None)
    assert offline.steps[-1][1].lookahead is None
    assert offline.steps[0][1].statistics == "sequence"
    assert make_recommended(features="joints").steps[0][1].statistics == "running"
    # synthetic negatives that the run namer alone learns, and its rule on
    assert model.background.n_sequences == 24 and model.background_for == "namer"
    assert model.steps[-1][1].max_namer_rest == 0.5
    # fewer, wider layers (docs/benchmarks.md, "Fewer, wider layers")
    tagger = model.steps[-1][1]
    assert (tagger.hidden_sizes, tagger.tcn_layers, tagger.tcn_stages) == ((48,), 8, 2)


def test_make_recommended_gives_its_negatives_to_the_namer_alone():
    from sklearn.base import clone

    streams = [make_skeleton_stream(random_state=s) for s in range(3)]
    X, y = [x for x, _ in streams], [v for _, v in streams]
    default = _tiny_recommended().fit(X, y)
    plain = _tiny_recommended(background=None).fit(X, y)
    F = default[:-1].transform(X)  # (the descriptor's statistics saw them)
    # the tagger's network is the one fitted on the recordings alone ...
    alone = clone(default[-1]).fit(F, y)
    for a, b in zip(default[-1].predict_proba(F), alone.predict_proba(F)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(default[-1].class_lengths_, alone.class_lengths_)
    # ... and its namer learnt rest from the negatives too
    assert default[-1].namer_rest_ > alone.namer_rest_ == plain[-1].namer_rest_
    # given to the model, the network learns them
    model = _tiny_recommended(background_for="model").fit(X, y)
    G = model[:-1].transform(X)
    together = clone(model[-1]).fit(G, y).predict_proba(G)
    assert not all(
        np.array_equal(a, b) for a, b in zip(model[-1].predict_proba(G), together)
    )


def test_make_recommended_descriptor_variant_reads_the_paper_descriptor():
    model = make_recommended(joints="paper11", features="descriptor", random_state=0)
    X, _ = make_skeleton_stream(random_state=0)
    assert model.steps[0][1].fit([X]).transform([X])[0].shape == (len(X), 183)
    # coordinates are not rotated or scaled once they are angles and distances
    augment = model.steps[-1][1].augment
    assert (augment.rotation, augment.scale) == (0.0, 0.0)
    with pytest.raises(ValueError, match="features must be"):
        make_recommended(features="pixels")
    # both side by side: the descriptor then the running joint features
    both = make_recommended(joints="paper11", features="descriptor+joints")
    F = both.steps[0][1].fit([X]).transform([X])[0]
    assert F.shape == (len(X), 183 + 66)
    assert both.get_params()["features__joints__statistics"] == "running"
    augment = both.steps[-1][1].augment
    assert (augment.rotation, augment.scale) == (0.0, 0.0)


def test_make_recommended_in_grid_search_with_groups(tmp_path):
    streams = [make_skeleton_stream(random_state=s) for s in range(4)]
    X = [x for x, _ in streams]
    y = [v for _, v in streams]
    groups = [0, 0, 1, 1]
    model = _tiny_recommended(memory=Memory(tmp_path, verbose=0))
    decoding = model.steps[-1][0] + "__min_run"
    search = GridSearchCV(
        model, {decoding: [1, 5]}, cv=LeaveOneGroupOut(), error_score="raise"
    ).fit(X, y, groups=groups)
    assert search.best_params_[decoding] in (1, 5)
    assert len(search.predict(X[:1])[0]) == len(X[0])


def test_loss_of_a_batch_whose_frames_are_all_ignored_is_zero_not_nan():
    import torch

    from skgesture._nn._training import IGNORE_INDEX, FramewiseLoss

    logits = torch.randn(2, 5, 3, requires_grad=True)
    target = torch.full((2, 5), IGNORE_INDEX)
    loss = FramewiseLoss()(logits, target)
    assert float(loss) == 0.0
    loss.backward()  # still differentiable
