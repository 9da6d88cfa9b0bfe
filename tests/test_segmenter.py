"""ActivitySegmenter (docs/method.md §4): training frames, periods, masks, caching."""

import copy

import joblib
import numpy as np
import pytest
import torch
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.linear_model import LogisticRegression

from skgesture import ActivitySegmenter, TorchMLPClassifier
from skgesture._segmenter import context_mask
from skgesture.utils import runs
from skgesture.utils._smoothing import loess_smooth

# --------------------------------------------------------------------------------
# context_mask (§4.1)
# --------------------------------------------------------------------------------

CONTEXT_CASES = {
    # (labels, n_context) -> training frames
    "docstring": (([0, 0, 0, 5, 5, 0, 0, 0], 2), [0, 1, 1, 1, 1, 1, 1, 0]),
    "no_context": (([0, 0, 0, 5, 5, 0, 0, 0], 0), [0, 0, 0, 1, 1, 0, 0, 0]),
    "every_rest_frame": (([0, 0, 0, 5, 5, 0, 0, 0], None), [1, 1, 1, 1, 1, 1, 1, 1]),
    "gesture_at_the_start": (([3, 3, 0, 0, 0, 0], 2), [1, 1, 1, 1, 0, 0]),
    "gesture_at_the_end": (([0, 0, 0, 0, 3, 3], 3), [0, 1, 1, 1, 1, 1]),
    "adjacent_classes_are_one_gesture": (([0, 0, 0, 1, 2, 0, 0, 0], 1),
                                         [0, 0, 1, 1, 1, 1, 0, 0]),
    "two_gestures": (([0, 0, 0, 0, 4, 0, 0, 0, 0, 0, 0, 2, 0, 0], 2),
                     [0, 0, 1, 1, 1, 1, 1, 0, 0, 1, 1, 1, 1, 1]),
    "background_gives_every_frame": (([0, 0, 0, 0, 0], 1), [1, 1, 1, 1, 1]),
    "background_with_no_context": (([0, 0, 0], 0), [1, 1, 1]),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(CONTEXT_CASES))
def test_context_mask(case):
    (labels, n_context), expected = CONTEXT_CASES[case]
    mask = context_mask(np.array(labels), n_context)
    assert mask.dtype == bool
    assert_array_equal(mask, np.array(expected, dtype=bool))


# --------------------------------------------------------------------------------
# Toy feature streams: gesture frames around 2.0, rest frames around 0.0
# --------------------------------------------------------------------------------

TRAIN_LAYOUT = [(0, 30), (1, 25), (0, 30), (2, 40), (0, 25)]
N_TRAIN_FRAMES_GT = 25 + 40 + 4 * 10  # gestures + 10 rest frames on each side
N_TRAIN_POSITIVES_GT = 25 + 40
# a 6-frame burst of gesture-like frames at 70..75 (not a labelled gesture)
TEST_LAYOUT = [(0, 20), (3, 30), (0, 20), (1, 6), (0, 20), (2, 20), (0, 10)]
PERIODS_GT = [(20, 50), (96, 116)]
BURST = (70, 76)
THRESHOLDS = (0.05, 0.2, 0.4, 0.6, 0.8, 0.95)


def _stream(layout, seed):
    rng = np.random.RandomState(seed)
    X = np.concatenate([rng.normal(2.0 if c else 0.0, 0.3, (n, 3)) for c, n in layout])
    y = np.concatenate([np.full(n, c) for c, n in layout])
    return X, y


def _net(**params):
    return TorchMLPClassifier(
        **{
            "hidden_layer_sizes": (8,),
            "activations": ("tanh",),
            "max_epochs": 30,
            **params,
        }
    )


def _periods(active):
    starts, ends, vals = runs(active)
    return [(int(s), int(e)) for s, e, v in zip(starts, ends, vals) if v]


class _RecordingClassifier(LogisticRegression):
    """LogisticRegression that keeps the samples it was fitted on."""

    def fit(self, X, y, sample_weight=None):
        self.fit_X_, self.fit_y_ = np.array(X), np.array(y)
        return super().fit(X, y, sample_weight=sample_weight)


@pytest.fixture(scope="module")
def train():
    return _stream(TRAIN_LAYOUT, seed=0)


@pytest.fixture(scope="module")
def test_stream():
    return _stream(TEST_LAYOUT, seed=1)


@pytest.fixture(scope="module")
def segmenter(train):
    n_threads = torch.get_num_threads()
    torch.set_num_threads(1)
    X, y = train
    seg = ActivitySegmenter(_net(), smooth_span=5, random_state=0).fit([X], [y])
    torch.set_num_threads(n_threads)
    return seg


def test_segmenter_trains_on_gestures_and_nearby_rest_frames(train):
    X, y = train
    seg = ActivitySegmenter(_RecordingClassifier(), random_state=0).fit([X, X], [y, y])
    keep = context_mask(y, 10)
    assert keep.sum() == N_TRAIN_FRAMES_GT
    assert_array_equal(seg.estimator_.fit_X_, np.concatenate([X[keep], X[keep]]))
    assert_array_equal(seg.estimator_.fit_y_, np.tile((y[keep] > 0).astype(int), 2))
    assert seg.estimator_.fit_y_.sum() == 2 * N_TRAIN_POSITIVES_GT
    assert_array_equal(seg.classes_, [0, 1])


def test_segmenter_recovers_the_periods_of_activity(segmenter, test_stream):
    X, _ = test_stream
    pred = segmenter.predict([X])[0]
    assert pred.shape == (len(X),)
    assert _periods(pred) == PERIODS_GT  # the 6-frame burst is shorter than 12


def test_segmenter_min_length_drops_short_runs(segmenter, test_stream):
    X, _ = test_stream
    seg = copy.deepcopy(segmenter).set_params(min_length=3)
    assert _periods(seg.predict([X])[0]) == sorted(PERIODS_GT + [BURST])
    seg.set_params(min_length=21)  # 30- and 20-frame periods: only the first stays
    assert _periods(seg.predict([X])[0]) == PERIODS_GT[:1]


def test_segmenter_threshold_applies_to_the_smoothed_score(segmenter, test_stream):
    X, _ = test_stream
    seg = copy.deepcopy(segmenter).set_params(min_length=1, smooth_span=15)
    score = seg.decision_function([X])[0]
    raw = seg.predict_proba([X])[0][:, 1]
    assert_allclose(score, loess_smooth(raw, 15), atol=1e-12)
    previous = None
    counts = []
    for threshold in THRESHOLDS:
        active = seg.set_params(threshold=threshold).predict([X])[0].astype(bool)
        assert_array_equal(active, score > threshold)
        if previous is not None:
            assert not (active & ~previous).any()  # a higher threshold only removes
        previous = active
        counts.append(active.sum())
    assert counts[0] > counts[-1]  # the smoothing ramps make the threshold matter


def test_segmenter_predict_proba_columns_are_rest_and_gesture(segmenter, test_stream):
    X, y = test_stream
    proba = segmenter.predict_proba([X, X[:10]])
    assert [p.shape for p in proba] == [(len(X), 2), (10, 2)]
    assert_allclose(proba[0].sum(axis=1), 1.0)
    gesture = y > 0
    assert proba[0][gesture, 1].mean() > 0.9
    assert proba[0][~gesture, 1][:20].mean() < 0.1


def test_segmenter_transform_masks_rest_rows(segmenter, test_stream):
    X, _ = test_stream
    out = segmenter.transform([X])[0]
    assert isinstance(out, np.ma.MaskedArray)
    active = segmenter.predict([X])[0].astype(bool)
    assert_array_equal(np.ma.getmaskarray(out), np.repeat(~active[:, None], 3, axis=1))
    assert_array_equal(out.data, X)


def test_segmenter_score_is_the_frame_accuracy(segmenter, test_stream):
    X, y = test_stream
    pred = segmenter.predict([X])[0]
    expected = np.mean(pred == (y > 0))
    assert segmenter.score([X], [y]) == pytest.approx(expected)
    assert expected == pytest.approx(1 - 6 / len(y), abs=0.03)  # the burst is missed


def test_segmenter_rejects_all_rest_labels(train):
    X, y = train
    with pytest.raises(
        ValueError, match=r"y has no gesture frame \(every label is 0\)"
    ):
        ActivitySegmenter(_net()).fit([X, X[:9]], [np.zeros_like(y), np.zeros(9)])


def test_segmenter_takes_every_frame_of_a_background_sequence(train):
    X, y = train
    rng = np.random.RandomState(3)
    background = rng.normal(1.0, 0.5, (37, 3))  # ordinary motion, no gesture
    keep = context_mask(y, 10)
    seg = ActivitySegmenter(_RecordingClassifier(), random_state=0)
    seg.fit([X, background], [y, np.zeros(37, int)])
    assert_array_equal(seg.estimator_.fit_X_, np.concatenate([X[keep], background]))
    assert_array_equal(
        seg.estimator_.fit_y_, np.r_[(y[keep] > 0).astype(int), np.zeros(37, int)]
    )
    # Without background, the paper's training frames exactly.
    alone = ActivitySegmenter(_RecordingClassifier(), random_state=0).fit([X], [y])
    assert_array_equal(alone.estimator_.fit_X_, X[keep])
    # Pre-cut clips (no rest at all) train once background gives the rest.
    gesture = y > 0
    clips = ActivitySegmenter(_net(), n_context=0, random_state=0)
    clips.fit([X[gesture], background], [y[gesture], np.zeros(37, int)])
    assert_array_equal(clips.classes_, [0, 1])


def test_segmenter_learns_that_background_motion_is_rest(train):
    X, y = train
    rng = np.random.RandomState(4)
    # motion like the gestures (2.0) on two features, like rest (0.0) on the third
    motion = rng.normal((2.0, 2.0, 0.0), 0.3, (60, 3))
    probe = rng.normal((2.0, 2.0, 0.0), 0.3, (40, 3))
    alone = ActivitySegmenter(_net(), smooth_span=5, random_state=0).fit([X], [y])
    seg = ActivitySegmenter(_net(), smooth_span=5, random_state=0)
    seg.fit([X, motion], [y, np.zeros(60, int)])
    assert alone.predict_proba([probe])[0][:, 1].mean() > 0.5
    assert seg.predict_proba([probe])[0][:, 1].mean() < 0.1
    assert _periods(seg.predict([X])[0]) == _periods(y > 0)


def test_segmenter_rejects_labels_without_nearby_rest(train):
    X, y = train
    with pytest.raises(ValueError, match="no rest frame"):
        ActivitySegmenter(_net(), n_context=0).fit([X], [y])


def test_segmenter_rejects_wrong_feature_width(segmenter):
    with pytest.raises(ValueError, match=r"X\[0\] has frames of shape \(4,\)"):
        segmenter.predict([np.zeros((20, 4))])


def test_segmenter_random_state_overrides_the_estimator_seed(train):
    X, y = train
    rec = _RecordingClassifier(random_state=None)
    a = ActivitySegmenter(rec, random_state=0).fit([X], [y])
    b = ActivitySegmenter(rec, random_state=0).fit([X], [y])
    c = ActivitySegmenter(rec, random_state=1).fit([X], [y])
    assert isinstance(a.estimator_.random_state, int)
    assert a.estimator_.random_state == b.estimator_.random_state
    assert a.estimator_.random_state != c.estimator_.random_state
    assert rec.random_state is None


def _state(seg):
    return seg.estimator_.net_.module_.state_dict()


def _n_cached(path):
    return len(list(path.rglob("output.pkl")))


def test_segmenter_memory_reuses_the_network_across_decision_params(train, tmp_path):
    X, y = train
    # random_state=None: a retrained network would get a new seed, so identical
    # weights mean the cached network was reused
    unseeded = [ActivitySegmenter(_net()).fit([X], [y]) for _ in range(2)]
    weights = [_state(seg)["net.0.weight"] for seg in unseeded]
    assert not torch.equal(*weights)
    memory = joblib.Memory(tmp_path, verbose=0)
    first = ActivitySegmenter(_net(), memory=memory).fit([X], [y])
    assert _n_cached(tmp_path) == 1
    second = ActivitySegmenter(
        _net(), memory=memory, threshold=0.7, min_length=5, smooth_span=9
    ).fit([X], [y])
    assert _n_cached(tmp_path) == 1
    for key, value in _state(first).items():
        assert torch.equal(value, _state(second)[key])
    # a change to the network retrains it
    third = ActivitySegmenter(_net(hidden_layer_sizes=(6,)), memory=memory)
    third.fit([X], [y])
    assert _n_cached(tmp_path) == 2
    assert _state(third)["net.0.weight"].shape == (6, 3)
    # so does a change of the training frames
    ActivitySegmenter(_net(), memory=memory, n_context=5).fit([X], [y])
    assert _n_cached(tmp_path) == 3


# --------------------------------------------------------------------------------
# Untracked frames are rest by construction (issue 11)
# --------------------------------------------------------------------------------


class _AlwaysGesture(LogisticRegression):
    """A frame classifier that calls every frame a gesture, whatever it sees."""

    def predict_proba(self, X):
        return np.tile([0.0, 1.0], (len(X), 1))


@pytest.fixture(scope="module")
def always_active(train):
    X, y = train
    return ActivitySegmenter(_AlwaysGesture()).fit([X], [y])


def test_segmenter_reports_no_activity_on_masked_rows(always_active, test_stream):
    X, _ = test_stream
    mask = np.zeros(X.shape, dtype=bool)
    mask[40:60] = True  # untracked frames inside the first gesture
    x = np.ma.MaskedArray(X, mask=mask)
    assert always_active.predict([X])[0].all()  # the network sees activity...
    active = always_active.predict([x])[0]
    assert_array_equal(active, np.r_[np.ones(40), np.zeros(20), np.ones(len(X) - 60)])
    assert_array_equal(always_active.decision_function([x])[0][40:60], 0.0)
    assert_array_equal(always_active.predict_proba([x])[0][40:60], [[1.0, 0.0]] * 20)
    # the smoothing of tracked frames is unchanged: their scores stay 1
    assert_allclose(always_active.decision_function([x])[0][:40], 1.0)
    out = always_active.transform([x])[0]
    assert np.ma.getmaskarray(out)[40:60].all()


def test_segmenter_all_zero_features_are_untracked(always_active):
    # an all-zero descriptor (a sequence without a tracked frame) is no activity
    zeros = np.zeros((200, 3))
    assert not always_active.predict([zeros])[0].any()
    assert not always_active.decision_function([zeros])[0].any()


def test_segmenter_threshold_is_strict(segmenter):
    # docs/method.md §4.4: active when the smoothed score EXCEEDS the threshold
    seg = copy.deepcopy(segmenter).set_params(threshold=0.4, min_length=1)
    assert not seg._periods(np.full(20, 0.4)).any()
    assert seg._periods(np.full(20, np.nextafter(0.4, 1.0))).all()


# --------------------------------------------------------------------------------
# verbose, feature names, output containers (issue 9)
# --------------------------------------------------------------------------------


def test_segmenter_verbose_shows_the_network_progress(train, capsys):
    X, y = train
    ActivitySegmenter(_net(max_epochs=3), random_state=0).fit([X], [y])
    assert capsys.readouterr() == ("", "")
    ActivitySegmenter(_net(max_epochs=3), random_state=0, verbose=1).fit([X], [y])
    assert "epoch" in capsys.readouterr().err  # a tqdm bar over epochs
    ActivitySegmenter(_net(max_epochs=3), random_state=0, verbose=2).fit([X], [y])
    lines = capsys.readouterr().out.splitlines()
    assert "valid_loss" in lines[0]
    assert [ln.split()[0] for ln in lines[2:5]] == ["1", "2", "3"]


def test_segmenter_verbose_does_not_change_the_network(train, tmp_path):
    X, y = train
    quiet = ActivitySegmenter(_net(max_epochs=5), random_state=0).fit([X], [y])
    loud = ActivitySegmenter(_net(max_epochs=5), random_state=0, verbose=2)
    memory = joblib.Memory(tmp_path, verbose=0)
    cached = ActivitySegmenter(_net(max_epochs=5), random_state=0, memory=memory)
    cached.fit([X], [y])
    loud.set_params(memory=memory).fit([X], [y])  # the cache ignores verbose
    assert _n_cached(tmp_path) == 1
    for key, value in _state(quiet).items():
        assert torch.equal(value, _state(loud)[key])


def test_segmenter_feature_names_pass_through(segmenter):
    assert segmenter.get_feature_names_out().tolist() == ["x0", "x1", "x2"]
    names = ["a", "b", "c"]
    assert segmenter.get_feature_names_out(names).tolist() == names


def test_segmenter_refuses_a_dataframe_output(segmenter, test_stream):
    import sklearn

    X, _ = test_stream
    with pytest.raises(ValueError, match="list of per-sequence arrays"):
        copy.deepcopy(segmenter).set_output(transform="pandas")
    with sklearn.config_context(transform_output="pandas"):
        out = segmenter.transform([X])  # the global setting leaves it alone
    assert isinstance(out[0], np.ma.MaskedArray)
