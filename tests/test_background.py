"""make_background: all-rest negatives made from gesture recordings."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from skgesture.datasets import make_background, make_gesture_streams
from skgesture.utils import labels_to_segments, missing_frames

KINDS = ["concatenation", "fragment", "motion", "reversed"]
N_FEATURES = 3


@pytest.fixture(scope="module")
def data():
    """Synthetic streams with dropouts (all-zero frames), 5 classes."""
    return make_gesture_streams(
        n_sequences=4, n_classes=5, dropout_rate=0.01, random_state=0
    )


def _source_index(seq, source):
    """For every frame of ``seq``, the index of the same frame in ``source``
    (-1 when it is not a frame of it: a join, a seam or a random motion)."""
    flat = source.reshape(len(source), -1)
    lookup = {row.tobytes(): i for i, row in enumerate(flat)}
    return np.array(
        [lookup.get(row.tobytes(), -1) for row in seq.reshape(len(seq), -1)]
    )


def _ramps(n_sequences=3, seed=0):
    """Feature streams whose gestures are ramps (not their own reversal) of
    class 1 (feature 0) and 2 (feature 1); feature 2 never moves in a gesture."""
    rng = np.random.RandomState(seed)
    X, y = [], []
    for _ in range(n_sequences):
        parts, labels = [], []
        for c in (1, 2, 1, 2):
            rest = rng.normal(0.0, 0.01, (30, N_FEATURES))
            n = rng.randint(20, 30)
            g = rng.normal(0.0, 0.01, (n, N_FEATURES))
            g[:, c - 1] += np.linspace(0.0, 1.0, n) ** 2  # slow, then fast
            parts += [rest, g]
            labels += [np.zeros(30, int), np.full(n, c)]
        parts.append(rng.normal(0.0, 0.01, (30, N_FEATURES)))
        labels.append(np.zeros(30, int))
        X.append(np.concatenate(parts))
        y.append(np.concatenate(labels))
    return X, y


def test_background_is_all_rest_and_follows_the_data_contract(data):
    bg = make_background(data.X, data.y, n_sequences=5, random_state=0)
    assert {"X", "y", "segments", "missing", "n_frames", "sources", "pieces",
            "DESCR"} <= set(bg)  # fmt: skip
    assert len(bg.X) == len(bg.y) == len(bg.pieces) == 5
    n = int(bg.n_frames[0])
    median_gesture = np.median(
        np.concatenate([s[:, 2] - s[:, 1] for s in data.segments])
    )
    assert n == max(int(np.median(data.n_frames)), round(4 * median_gesture))
    for x, lab, seg, miss in zip(bg.X, bg.y, bg.segments, bg.missing):
        assert x.shape == (n, 20, 3) and x.dtype == np.float64
        assert lab.dtype == np.int64 and not lab.any()
        assert seg.shape == (0, 3) and not miss.any()
        # untracked (all-zero) frames of the recordings are never used
        assert not missing_frames(x).any() and np.isfinite(x).all()
    assert set(bg.sources) <= set(range(len(data.X)))
    assert sorted({k for p in bg.pieces for k, _, _ in p}) == KINDS
    for p in bg.pieces:
        assert p[0][1] == 0 and p[-1][2] == n  # the pieces cover the sequence
    again = make_background(data.X, data.y, n_sequences=5, random_state=0)
    for a, b in zip(bg.X, again.X):
        assert_array_equal(a, b)
    other = make_background(data.X, data.y, n_sequences=5, random_state=1)
    assert not np.array_equal(bg.X[0], other.X[0])


def test_reversed_gestures_are_the_recordings_frames_played_backwards():
    X, y = _ramps()
    bg = make_background(X, y, n_sequences=3, n_frames=300, kinds="reversed",
                         random_state=0)  # fmt: skip
    for seq, src in zip(bg.X, bg.sources):
        idx = _source_index(seq, X[src])
        assert (idx >= 0).mean() > 0.9  # all but the cross-faded joins
        steps = np.diff(idx)[(idx[1:] >= 0) & (idx[:-1] >= 0)]
        assert (steps == -1).mean() > 0.9  # backwards through the recording
        assert (y[src][idx[idx >= 0]] > 0).any()  # through its gestures


def test_fragments_are_shorter_than_the_shortest_gesture():
    X, y = _ramps()
    shortest = min((s[:, 2] - s[:, 1]).min() for s in map(labels_to_segments, y))
    bg = make_background(X, y, n_sequences=4, n_frames=400, kinds=["fragment"],
                         random_state=0)  # fmt: skip
    n_motions = 0
    for seq, src in zip(bg.X, bg.sources):
        idx = _source_index(seq, X[src])
        in_gesture = np.zeros(len(seq), bool)
        in_gesture[idx >= 0] = y[src][idx[idx >= 0]] > 0
        runs = labels_to_segments(in_gesture.astype(int))
        assert len(runs) and (runs[:, 2] - runs[:, 1] <= shortest).all()
        n_motions += len(runs)
    assert n_motions >= 8


def test_random_motion_moves_as_the_gestures_do_times_motion_scale():
    X, y = _ramps()
    small = make_background(X, y, n_sequences=4, n_frames=500, kinds="motion",
                            motion_scale=0.2, random_state=0)  # fmt: skip
    large = make_background(X, y, n_sequences=4, n_frames=500, kinds="motion",
                            motion_scale=1.0, random_state=0)  # fmt: skip
    gestures = np.concatenate([x[lab > 0] for x, lab in zip(X, y)])
    spread_small = np.concatenate(small.X).std(axis=0)
    spread_large = np.concatenate(large.X).std(axis=0)
    # features 0 and 1 move in the gestures: so does the motion, in proportion
    assert (spread_large[:2] > 0.3 * gestures.std(axis=0)[:2]).all()
    assert_array_equal(spread_large[:2] > 2.5 * spread_small[:2], [True, True])
    # feature 2 never moves in a gesture: the motion leaves it alone
    assert spread_large[2] < 0.05


def test_a_reversed_gesture_that_looks_like_a_gesture_is_left_out():
    X, y = _ramps()
    # Class 2 becomes its own reversal (up and down): a reversed class-2 gesture
    # is a class-2 gesture, never a negative. Class 1 ramps stay reversible.
    for x, lab in zip(X, y):
        for c, s, e in labels_to_segments(lab):
            if c == 2:
                x[s:e, 1] = np.sin(np.linspace(0, np.pi, e - s))
    bg = make_background(X, y, n_sequences=4, n_frames=300, kinds="reversed",
                         random_state=0)  # fmt: skip
    for seq, src in zip(bg.X, bg.sources):
        idx = _source_index(seq, X[src])
        used = set(y[src][idx[idx >= 0]].tolist())
        assert 1 in used and 2 not in used
    for x, lab in zip(X, y):  # now every gesture is its own reversal
        for c, s, e in labels_to_segments(lab):
            x[s:e, c - 1] = np.sin(np.linspace(0, np.pi, e - s))
    with pytest.raises(ValueError, match="'reversed'.*every reversed gesture"):
        make_background(X, y, kinds="reversed", random_state=0)
    bg = make_background(X, y, n_sequences=2, random_state=0)  # the other kinds
    assert "reversed" not in {k for p in bg.pieces for k, _, _ in p}


def test_concatenations_join_gestures_of_two_classes():
    X, y = _ramps()
    bg = make_background(X, y, n_sequences=3, n_frames=300,
                         kinds="concatenation", random_state=0)  # fmt: skip
    kinds = {k for p in bg.pieces for k, _, _ in p}
    assert "concatenation" in kinds and kinds <= {"concatenation", "fragment"}
    one_class = [lab.clip(0, 1) for lab in y]
    with pytest.raises(ValueError, match="no recording has fully tracked gestures "
                       "of two classes"):  # fmt: skip
        make_background(X, one_class, kinds="concatenation")


def test_masked_rows_are_untracked_frames_and_never_used():
    X, y = _ramps(2)
    masked = []
    for x in X:
        x = x.copy()
        x[::7] = 100.0  # garbage under the mask, as lost tracking may leave
        mask = np.zeros(x.shape, bool)
        mask[::7] = True
        masked.append(np.ma.MaskedArray(x, mask=mask))
    bg = make_background(masked, y, n_sequences=3, n_frames=300, random_state=0)
    assert np.abs(np.concatenate(bg.X)).max() < 10


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_sequences": 0}, "n_sequences must be >= 1"),
        ({"n_sequences": 1.5}, r"a share of the recordings in \(0, 1\), got 1.5"),
        ({"n_sequences": 0.0}, r"a share of the recordings in \(0, 1\), got 0.0"),
        ({"n_sequences": float("nan")}, "a share of the recordings"),
        ({"n_frames": 1}, "n_frames must be >= 2"),
        ({"kinds": ["noise"]}, "unknown background kind 'noise'"),
        ({"kinds": []}, "kinds is empty"),
        ({"kinds": 3}, "kinds must be a sequence"),
        ({"motion_scale": 0.0}, "motion_scale must satisfy 0.0 <"),
        ({"motion_scale": float("nan")}, "motion_scale must be a finite"),
    ],
)
def test_invalid_parameters_raise(kwargs, match):
    X, y = _ramps(1)
    with pytest.raises(ValueError, match=match):
        make_background(X, y, **kwargs)


def test_bad_recordings_are_named():
    X, y = _ramps(2)
    with pytest.raises(ValueError, match=r"y has no gesture \(every label is 0\)"):
        make_background(X, [np.zeros_like(lab) for lab in y])
    with pytest.raises(ValueError, match=r"y\[1\] has 5 labels but X\[1\] has"):
        make_background(X, [y[0], y[1][:5]])
    with pytest.raises(ValueError, match=r"X\[1\] has frames of shape \(2,\), but"):
        make_background([X[0], X[1][:, :2]], y)
    with pytest.raises(TypeError, match="X must be a list of sequences"):
        make_background(X[0], y[0])


# -- SyntheticBackground in a GesturePipeline ----------------------------------------


class _Recorder:
    """A last step that keeps what it was fitted on (a stand-in tagger)."""

    def __init__(self):
        self.seen = None

    def get_params(self, deep=True):
        return {}

    def set_params(self, **params):
        return self

    def fit(self, X, y):
        self.seen = (list(X), list(y))
        return self

    def predict(self, X):
        return [np.zeros(len(x), dtype=np.int64) for x in X]


def _pipeline(background):
    from skgesture import GesturePipeline

    return GesturePipeline([("tagger", _Recorder())], background=background)


def test_the_pipeline_adds_the_negatives_of_its_training_data(data):
    from skgesture.datasets import SyntheticBackground

    bg = SyntheticBackground(n_sequences=3, random_state=0)
    pipe = _pipeline(bg).fit(data.X, data.y, fps=data.fps)
    X_seen, y_seen = pipe[-1].seen
    want = make_background(data.X, data.y, n_sequences=3, random_state=0)
    assert len(X_seen) == len(data.X) + 3
    for made, seen in zip(want.X, X_seen[len(data.X) :]):
        assert_array_equal(made, seen)
    assert all((lab == 0).all() for lab in y_seen[len(data.X) :])
    # made from the recordings of this fit only: other data, other negatives
    pipe.fit(data.X[:2], data.y[:2])
    want = make_background(data.X[:2], data.y[:2], n_sequences=3, random_state=0)
    assert_array_equal(pipe[-1].seen[0][2], want.X[0])


def test_background_none_adds_nothing_and_its_parameters_are_searchable(data):
    from sklearn.base import clone

    from skgesture.datasets import SyntheticBackground

    pipe = _pipeline(None).fit(data.X, data.y)
    assert len(pipe[-1].seen[0]) == len(data.X)
    pipe = _pipeline(SyntheticBackground()).set_params(background__n_sequences=2)
    assert clone(pipe).background.n_sequences == 2
    assert len(pipe.fit(data.X, data.y)[-1].seen[0]) == len(data.X) + 2


def test_a_share_of_the_recordings_makes_that_share_of_sequences(data):
    """A float ``n_sequences`` keeps the negatives the same share of the
    training sequences whatever the data size, never fewer than one."""
    from skgesture.datasets import SyntheticBackground

    X, y = _ramps(20)
    assert len(make_background(X, y, n_sequences=0.1, random_state=0).X) == 2
    assert len(make_background(X, y, n_sequences=0.25, random_state=0).X) == 5
    assert len(make_background(X[:3], y[:3], n_sequences=0.1, random_state=0).X) == 1
    bg = SyntheticBackground(n_sequences=0.5, random_state=0)
    pipe = _pipeline(bg).fit(data.X, data.y)
    n = len(data.X)
    assert len(pipe[-1].seen[0]) == n + max(1, round(0.5 * n))


def test_a_background_without_make_or_labels_is_refused(data):
    from sklearn.utils._param_validation import InvalidParameterError

    from skgesture.datasets import SyntheticBackground

    with pytest.raises(InvalidParameterError, match="'background' parameter"):
        _pipeline("synthetic").fit(data.X, data.y)
    with pytest.raises(ValueError, match="needs the labels y"):
        _pipeline(SyntheticBackground()).fit(data.X)


def test_background_for_is_validated(data):
    from sklearn.utils._param_validation import InvalidParameterError

    from skgesture.datasets import SyntheticBackground

    pipe = _pipeline(SyntheticBackground(n_sequences=2)).set_params(
        background_for="tagger"
    )
    with pytest.raises(InvalidParameterError, match="'background_for' parameter"):
        pipe.fit(data.X, data.y)
