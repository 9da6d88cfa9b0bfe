"""ConcatFeatures: several per-frame transformers side by side, offline and live."""

import pickle

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from sklearn.base import clone

from skgesture import ConcatFeatures, JointFeatures, PoseDescriptor
from skgesture._stream import stream_frames
from skgesture.utils._testing import make_skeleton_stream


def _both(**params):
    return ConcatFeatures(
        [
            ("descriptor", PoseDescriptor(fill="hold", **params)),
            ("joints", JointFeatures(fill="hold", statistics="running")),
        ]
    )


@pytest.fixture(scope="module")
def stream():
    X, _ = make_skeleton_stream(random_state=0)
    X = X.copy()
    X[:3] = 0.0  # untracked at the start ...
    X[40:55] = 0.0  # ... and inside
    return X


def test_rows_are_the_transformers_rows_side_by_side(stream):
    both = _both().fit([stream])
    got = both.transform([stream])[0]
    desc = PoseDescriptor(fill="hold").fit([stream]).transform([stream])[0]
    joints = JointFeatures(fill="hold", statistics="running").fit([stream])
    joints = joints.transform([stream])[0]
    assert got.shape == (len(stream), 183 + 66) == (len(stream), both.n_features_out_)
    assert got.dtype == np.float32
    desc = np.ma.getdata(desc).astype(np.float32)  # the union's rows are float32
    assert_array_equal(np.ma.getdata(got)[:, :183], desc)
    assert_array_equal(np.ma.getdata(got)[:, 183:], np.ma.getdata(joints))
    # an untracked frame is a masked row of the whole width
    mask = np.ma.getmaskarray(got)
    assert mask[:3].all() and mask[40:55].all() and not mask[3:40].any()
    names = both.get_feature_names_out()
    assert len(names) == both.n_features_out_
    assert names[0].startswith("descriptor__") and names[-1].startswith("joints__vel")


@pytest.mark.parametrize("block", [1, 7, 1000])
def test_stream_gives_the_rows_of_transform(stream, block):
    both = _both().fit([stream])
    offline = both.transform([stream])[0]
    state = both.stream_init(max_backfill=64)
    parts = []
    for t in range(0, len(stream), block):
        rows, state = both.stream_step(state, stream_frames(stream[t : t + block], t))
        assert np.all(rows.time < t + block)  # no row before its frames came
        parts.append(rows)
    rows, state = both.stream_flush(state)
    parts.append(rows)
    live = np.concatenate([p.data for p in parts])
    assert_array_equal(live, np.ma.getdata(offline))
    assert_array_equal(np.concatenate([p.mask for p in parts]),
                       np.ma.getmaskarray(offline)[:, 0])  # fmt: skip
    # a row is final once the slower transformer (the descriptor) has given it
    assert both.stream_lookahead == 4
    times = np.concatenate([p.time for p in parts[:-1]])
    if block == 1 and len(times):
        assert times[-1] == len(times) - 1 + 4


def test_nested_parameters_clone_and_pickle(stream):
    both = _both()
    params = both.get_params()
    assert params["descriptor__fill"] == "hold" and "joints__statistics" in params
    both.set_params(joints__velocities=False)
    assert both.transformers[1][1].velocities is False
    copy = clone(both)
    assert copy.transformers[1][1].velocities is False
    assert copy.transformers[1][1] is not both.transformers[1][1]
    fitted = both.fit([stream])
    assert fitted.n_features_out_ == 183 + 33
    again = pickle.loads(pickle.dumps(fitted))
    assert_array_equal(
        np.ma.getdata(again.transform([stream])[0]),
        np.ma.getdata(fitted.transform([stream])[0]),
    )
    # fit works on clones: the given transformers stay unfitted
    assert not hasattr(both.transformers[0][1], "n_features_out_")


@pytest.mark.parametrize(
    "transformers, error, match",
    [
        ([], ValueError, "non-empty list"),
        ([("a", PoseDescriptor(), 3)], ValueError, r"transformers\[0\]"),
        ([("a", PoseDescriptor()), ("a", JointFeatures())], ValueError, "unique"),
        ([("a__b", PoseDescriptor())], ValueError, "__"),
        ([("a", "not a transformer")], TypeError, "no fit/transform"),
    ],
)
def test_bad_transformers_are_refused_clearly(stream, transformers, error, match):
    with pytest.raises(error, match=match):
        ConcatFeatures(transformers).fit([stream])


def test_bad_input_names_its_sequence(stream):
    both = _both().fit([stream])
    with pytest.raises(ValueError, match=r"X\[1\] has frames of shape \(5, 3\)"):
        both.transform([stream, stream[:, :5]])
    bad = stream[:4].copy()
    bad[3, 3] = np.inf
    state = both.stream_init()
    with pytest.raises(ValueError, match="frame 3 of the stream is invalid"):
        state.step(stream_frames(bad, 0))
    # nothing was consumed: the good frames give the offline rows after all
    state.step(stream_frames(stream[:4], 0))
    rows = state.step(stream_frames(stream[4:], 4))
    rows = [rows, state.flush()]
    assert_array_equal(np.concatenate([r.data for r in rows])[-100:],
                       np.ma.getdata(both.transform([stream])[0])[-100:])  # fmt: skip


def test_a_transformer_that_cannot_stream_is_named(stream):
    class Plain:  # fit/transform, no live step
        n_features_out_ = 1

        def fit(self, X, y=None):
            return self

        def transform(self, X):
            return [np.zeros((len(x), 1), np.float32) for x in X]

        def get_params(self, deep=True):
            return {}

    both = ConcatFeatures([("d", PoseDescriptor()), ("plain", Plain())]).fit([stream])
    assert both.transform([stream])[0].shape == (len(stream), 184)
    with pytest.raises(TypeError, match="'plain'.*cannot stream"):
        both.stream_init()
