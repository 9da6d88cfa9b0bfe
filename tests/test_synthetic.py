"""Tests of the synthetic Montalbano-like stream generator."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
from sklearn.neighbors import NearestCentroid

from skgesture.datasets import make_gesture_streams
from skgesture.layouts import KINECT_V1
from skgesture.utils import labels_to_segments, missing_frames, runs, segments_to_labels
from skgesture.utils._testing import make_skeleton_stream

# Reference statistics of the LAP 2014 Track 3 validation labels
# (shared/data/chalearn_montalbano/PROVENANCE.md): gesture length 6-96 frames,
# median 39; median gap between gestures 27 frames.
REAL_LENGTH_RANGE = (6, 96)
LENGTH_MEDIAN_BAND = (33, 45)
GAP_MEDIAN_BAND = (20, 34)
BUNCH_KEYS = {
    "X", "y", "segments", "sample_ids", "groups", "fps", "n_frames", "missing",
    "target_names", "layout", "DESCR",
}  # fmt: skip
HANDS = list(KINECT_V1.indices(["HandLeft", "HandRight"]))
HIP = KINECT_V1.index("HipCenter")
# crude per-gesture features: hands and elbows relative to HipCenter
FEATURE_JOINTS = list(
    KINECT_V1.indices(["HandLeft", "HandRight", "ElbowLeft", "ElbowRight"])
)
N_FEATURE_SAMPLES = 6  # instants per gesture
CHANCE_20 = 1 / 20


@pytest.fixture(scope="module")
def streams():
    """200 default sequences: 3,000 gestures of 20 classes, 40 subjects."""
    return make_gesture_streams(n_sequences=200, random_state=0)


@pytest.fixture(scope="module")
def clean():
    """Streams without noise or dropouts, for exact geometric checks."""
    return make_gesture_streams(
        n_sequences=12, n_subjects=4, noise=0.0, dropout_rate=0.0, random_state=1
    )


def _bone_lengths(X):
    """(n_frames, n_bones) bone lengths of one sequence."""
    parent, child = (
        np.array([KINECT_V1.index(b[k]) for b in KINECT_V1.bones]) for k in (0, 1)
    )
    return np.linalg.norm(X[:, child] - X[:, parent], axis=-1)


def _gesture_features(data):
    """Resampled hand/elbow trajectories relative to HipCenter, per gesture."""
    feats, labels, groups = [], [], []
    for X, seg, miss, g in zip(data.X, data.segments, data.missing, data.groups):
        for c, s, e in seg:
            frames = np.arange(s, e)[~miss[s:e]]
            rel = X[frames][:, FEATURE_JOINTS] - X[frames][:, [HIP]]
            pick = np.linspace(0, len(rel) - 1, N_FEATURE_SAMPLES).round().astype(int)
            feats.append(rel[pick].ravel())
            labels.append(c)
            groups.append(g)
    return np.array(feats), np.array(labels), np.array(groups)


def test_same_seed_gives_identical_streams():
    a = make_gesture_streams(n_sequences=4, n_classes=6, random_state=3)
    b = make_gesture_streams(
        n_sequences=4, n_classes=6, random_state=np.random.RandomState(3)
    )
    for key in ("X", "y", "segments", "missing"):
        for u, v in zip(a[key], b[key]):
            assert_array_equal(u, v)
    assert_array_equal(a.groups, b.groups)
    c = make_gesture_streams(n_sequences=4, n_classes=6, random_state=4)
    assert [len(s) for s in a.y] != [len(s) for s in c.y]


def test_bunch_follows_the_data_contract(streams):
    assert set(streams) == BUNCH_KEYS
    n = len(streams.X)
    assert n == 200
    assert len(streams.y) == len(streams.segments) == len(streams.missing) == n
    for X, y, seg, miss, n_frames in zip(
        streams.X, streams.y, streams.segments, streams.missing, streams.n_frames
    ):
        assert X.dtype == np.float64 and X.shape == (n_frames, 20, 3)
        assert y.dtype == np.int64 and y.shape == (n_frames,)
        assert seg.dtype == np.int64 and seg.shape[1] == 3
        assert miss.dtype == bool and miss.shape == (n_frames,)
    assert streams.groups.shape == (n,)
    assert np.issubdtype(streams.groups.dtype, np.integer)
    assert streams.fps == 20.0 and isinstance(streams.fps, float)
    assert streams.layout == "kinect_v1"
    assert streams.target_names[0] == "gesture_01"
    assert len(streams.target_names) == 20
    assert len(set(streams.sample_ids)) == n
    assert "Montalbano" in streams.DESCR


def test_labels_agree_with_segments(streams):
    for y, seg in zip(streams.y, streams.segments):
        assert_array_equal(segments_to_labels(seg, len(y)), y)
        assert_array_equal(labels_to_segments(y), seg)
        assert set(np.unique(y)) <= set(range(21))


def test_timing_follows_the_real_validation_labels(streams):
    seg = streams.segments
    lengths = np.concatenate([s[:, 2] - s[:, 1] for s in seg])
    gaps = np.concatenate([s[1:, 1] - s[:-1, 2] for s in seg])
    assert REAL_LENGTH_RANGE[0] <= lengths.min()
    assert lengths.max() <= REAL_LENGTH_RANGE[1]
    assert LENGTH_MEDIAN_BAND[0] <= np.median(lengths) <= LENGTH_MEDIAN_BAND[1]
    assert GAP_MEDIAN_BAND[0] <= np.median(gaps) <= GAP_MEDIAN_BAND[1]
    assert gaps.min() == 0 and 0.03 < np.mean(gaps == 0) < 0.15  # real: 8.6 %
    n_gestures = np.array([len(s) for s in seg])
    assert n_gestures.min() >= 8 and n_gestures.max() <= 22
    lead = np.array([s[0, 1] for s in seg])
    tail = streams.n_frames - np.array([s[-1, 2] for s in seg])
    assert lead.min() > 0 and tail.min() > 0
    assert 1000 < np.median(streams.n_frames) < 1700  # real: 1283.5


def test_classes_all_present_and_balanced(streams):
    counts = np.bincount(np.concatenate([s[:, 0] for s in streams.segments]))
    assert counts[0] == 0 and len(counts) == 21
    assert counts[1:].max() - counts[1:].min() <= 1
    # distinct within a sequence, unless it has more gestures than classes
    for s in streams.segments:
        assert len(np.unique(s[:, 0])) == min(len(s), 20)
    assert max(len(s) for s in streams.segments) > 20


def test_bone_lengths_are_constant_within_a_sequence(clean, streams):
    for X in clean.X:
        lengths = _bone_lengths(X)
        assert_allclose(lengths, lengths[:1].repeat(len(X), 0), atol=1e-9)
    # with sensor jitter, up to the noise (std of a length ~ noise * sqrt(2))
    X, miss = streams.X[0], streams.missing[0]
    assert _bone_lengths(X[~miss]).std(axis=0).max() < 3 * 0.005 * np.sqrt(2)


def test_groups_are_subjects_with_one_body(clean):
    assert_array_equal(np.bincount(clean.groups), [3, 3, 3, 3])
    body = np.array([_bone_lengths(X)[0] for X in clean.X])
    for g in range(4):
        same = body[clean.groups == g]
        assert_allclose(same, same[:1].repeat(len(same), 0), atol=1e-9)
    assert np.ptp(body[:, 0] / body[:, 0].mean()) > 0.01  # bodies differ
    assert 1 <= len(np.unique(make_gesture_streams(7, 3, random_state=0).groups))


def test_missing_frames_are_all_zero_exactly_where_reported(streams, clean):
    for X, miss in zip(streams.X, streams.missing):
        assert_array_equal(missing_frames(X), miss)
    rate = np.mean(np.concatenate(streams.missing))
    assert 0.002 < rate < 0.02  # about 0.002 per frame x 3 frames + start
    for X, miss in zip(clean.X, clean.missing):
        assert not miss.any() and not missing_frames(X).any()


def test_skeleton_stands_in_front_of_the_sensor(streams):
    hip = np.concatenate([X[~m, HIP] for X, m in zip(streams.X, streams.missing)])
    assert 1.9 < hip[:, 2].min() and hip[:, 2].max() < 3.1
    head = np.concatenate(
        [X[~m, KINECT_V1.index("Head")] for X, m in zip(streams.X, streams.missing)]
    )
    assert (head[:, 1] > hip[:, 1] + 0.4).all()  # y is up


def test_gestures_move_the_hands_and_rests_do_not():
    quiet = make_gesture_streams(20, oov_rate=0.0, dropout_rate=0.0, random_state=2)
    busy = make_gesture_streams(20, oov_rate=1.0, dropout_rate=0.0, random_state=2)
    for data, limit in ((quiet, 0.2), (busy, None)):
        devs, speed_g, speed_r = [], [], []
        for X, y in zip(data.X, data.y):
            rel = X[:, HANDS] - X[:, [HIP]]
            dev = np.linalg.norm(rel - np.median(rel[y == 0], axis=0), axis=-1)
            starts, ends, vals = runs(y)
            devs += [dev[s:e].max() for s, e, v in zip(starts, ends, vals) if v == 0]
            speed = np.linalg.norm(np.diff(rel, axis=0), axis=-1).max(-1)
            speed_g.append(speed[y[1:] > 0].mean())
            speed_r.append(speed[y[1:] == 0].mean())
        assert np.mean(speed_g) > 2 * np.mean(speed_r)
        if limit is not None:  # idle sway only
            assert max(devs) < limit
        else:  # out-of-vocabulary motions during rests, labelled 0
            assert np.mean(np.array(devs) > 0.25) > 0.2


def test_classes_are_learnable_on_held_out_subjects_but_not_trivial(streams):
    # train on 40 subjects, test on 10 new ones drawn with another seed: class k
    # is the same motion whatever the seed
    test = make_gesture_streams(n_sequences=50, random_state=11)
    X_tr, y_tr, _ = _gesture_features(streams)
    X_te, y_te, _ = _gesture_features(test)
    simple = NearestCentroid().fit(X_tr, y_tr).score(X_te, y_te)
    linear = LinearDiscriminantAnalysis().fit(X_tr, y_tr).score(X_te, y_te)
    assert 10 * CHANCE_20 < simple < linear < 0.97  # measured 0.811 and 0.919


def test_nearly_alike_classes_are_closest(streams):
    feats, labels, _ = _gesture_features(streams)
    centroids = np.array([feats[labels == k].mean(0) for k in range(1, 21)])
    dist = np.linalg.norm(centroids[:, None] - centroids[None], axis=-1)
    np.fill_diagonal(dist, np.inf)
    assert np.argmin(dist[15 - 1]) + 1 == 14
    assert np.argmin(dist[6 - 1]) + 1 == 5


def test_options_n_gestures_fps_and_return_segments():
    data = make_gesture_streams(
        5, 4, n_gestures=3, fps=40, return_segments=False, random_state=0
    )
    assert "segments" not in data and data.fps == 40.0
    segs = [labels_to_segments(y) for y in data.y]
    assert [len(s) for s in segs] == [3] * 5
    lengths = np.concatenate([s[:, 2] - s[:, 1] for s in segs])
    assert np.median(lengths) > 1.5 * LENGTH_MEDIAN_BAND[0]  # durations in seconds
    one = make_gesture_streams(2, 1, n_gestures=(1, 2), random_state=0)
    assert set(np.concatenate(one.y).tolist()) == {0, 1}


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_sequences": 0}, "n_sequences"),
        ({"n_sequences": 2.5}, "n_sequences"),
        ({"n_classes": 0}, "n_classes"),
        ({"n_classes": 51}, "n_classes"),
        ({"n_gestures": 0}, "n_gestures"),
        ({"n_gestures": (5, 2)}, "min <= max"),
        ({"n_gestures": (1, 2, 3)}, "n_gestures"),
        ({"n_subjects": 5}, "n_subjects"),
        ({"oov_rate": -0.1}, "oov_rate"),
        ({"noise": -1.0}, "noise"),
        ({"dropout_rate": 0.9}, "dropout_rate"),
        ({"fps": 0}, "fps"),
        ({"random_state": "seed"}, "seed"),
    ],
)
def test_invalid_parameters_raise(kwargs, match):
    params = {"n_sequences": 2, **kwargs}
    with pytest.raises(ValueError, match=match):
        make_gesture_streams(**params)


def test_make_skeleton_stream_is_tiny_clean_and_exact():
    X, y = make_skeleton_stream(n_frames=150, random_state=0)
    assert X.shape == (150, 20, 3) and y.shape == (150,)
    assert_array_equal(np.unique(labels_to_segments(y)[:, 0]), [1, 2, 3])
    assert not missing_frames(X).any()
    X2, y2 = make_skeleton_stream(n_frames=150, random_state=0)
    assert_array_equal(X, X2)
    assert_array_equal(y, y2)
    with pytest.raises(ValueError, match="too short"):
        make_skeleton_stream(n_frames=10)
    with pytest.raises(ValueError, match="n_gestures"):
        make_skeleton_stream(n_gestures=(1, 2))
