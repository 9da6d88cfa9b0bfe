"""The contract every sequence estimator and every pipeline of skgesture keeps.

scikit-learn's ``parametrize_with_checks`` generates 2-D data, which the sequence
estimators refuse by design (docs/design.md §1.3), so the
same promises are checked here on lists of sequences, for the estimators and for
the pipelines the factories build: clone, get/set_params, no work in
``__init__``, ``fit`` returns self, NotFittedError before fit, a clear error for
an empty list and for non-finite or absurd input, read-only input arrays,
pickling, and determinism under a fixed ``random_state``.

To add an estimator, append a :class:`Case` to ``CASES``: a factory of the
unfitted estimator with tiny settings, a factory of its training data, and the
method whose output is compared. For example, for a new tagger::

    CASES["Tagger"] = Case(lambda: MyTagger(random_state=0, max_epochs=2),
                           _descriptors, "predict")
"""

import pickle
import re
from dataclasses import dataclass
from functools import cache

import numpy as np
import pytest
from sklearn.base import BaseEstimator, clone
from sklearn.exceptions import NotFittedError

from skgesture import (
    ActivitySegmenter,
    BiLSTMTagger,
    DynamicPoseWindow,
    JointFeatures,
    MultiScaleClassifier,
    PoseDescriptor,
    SequenceTagger,
    TorchMLPClassifier,
    VotingTagger,
    make_method_a,
    make_method_b,
    make_method_c,
    make_recommended,
)
from skgesture.utils._testing import make_skeleton_stream


@dataclass(frozen=True)
class Case:
    """One estimator under contract.

    Attributes
    ----------
    make : callable
        ``make()`` returns a fresh unfitted estimator with tiny settings.
    data : callable
        ``data()`` returns ``(X, y)`` (``y`` may be None), a list of sequences
        (or a 2-D array when ``sequences`` is False).
    output : str
        Method whose output must be reproducible (``predict``, ``transform``, ...).
    sequences : bool
        Whether ``X`` is a list of sequences (False: an ordinary 2-D estimator).
    raw : bool
        Whether ``X`` holds raw skeletons, where NaN is an untracked joint
        (allowed) and only inf is non-finite input.
    """

    make: object
    data: object
    output: str
    sequences: bool = True
    raw: bool = False


def _net(**params):
    return TorchMLPClassifier(
        hidden_layer_sizes=(8,), activations=("tanh",), max_epochs=15, **params
    )


@cache
def _stream(seed):
    return make_skeleton_stream(n_frames=160, n_gestures=3, random_state=seed)


def _skeletons():
    (x0, y0), (x1, y1) = _stream(0), _stream(1)
    return [x0, x1], [y0, y1]


def _descriptors():
    X, y = _skeletons()
    return PoseDescriptor().fit_transform(X), y


def _windows():
    X, y = _descriptors()
    return DynamicPoseWindow(steps=(4, 2)).fit_transform(X), y


def _frames():
    rng = np.random.RandomState(0)
    X = np.r_[rng.normal(-1, 1, (40, 3)), rng.normal(1, 1, (40, 3))]
    return X, np.repeat([0, 1], 40)


def _tiny_tagger(**params):
    return SequenceTagger(
        hidden_sizes=(4,), max_epochs=2, steps_per_epoch=3, crop_length=32, **params
    )


def _tiny_multiscale(pipe):
    return pipe.set_params(segmenter__estimator=_net(), classifier__estimator=_net())


CASES = {
    "PoseDescriptor": Case(PoseDescriptor, _skeletons, "transform", raw=True),
    "ActivitySegmenter": Case(
        lambda: ActivitySegmenter(_net(), random_state=0),
        _descriptors,
        "decision_function",
    ),
    "DynamicPoseWindow": Case(
        lambda: DynamicPoseWindow(steps=(4, 2)), _descriptors, "transform"
    ),
    "MultiScaleClassifier": Case(
        lambda: MultiScaleClassifier(
            _net(), steps=(4, 2), threshold_short=0.5, random_state=0
        ),
        _windows,
        "predict_segments",
    ),
    "BiLSTMTagger": Case(
        lambda: BiLSTMTagger(hidden_sizes=(4,), max_epochs=2, random_state=0),
        _descriptors,
        "predict_proba",
    ),
    "TorchMLPClassifier": Case(
        lambda: _net(random_state=0), _frames, "predict_proba", sequences=False
    ),
    "JointFeatures": Case(JointFeatures, _skeletons, "transform", raw=True),
    "SequenceTagger": Case(
        lambda: _tiny_tagger(random_state=0), _descriptors, "predict_proba"
    ),
    "VotingTagger": Case(
        lambda: VotingTagger(
            [("gru", _tiny_tagger()), ("tcn", _tiny_tagger(architecture="tcn"))],
            random_state=0,
        ),
        _descriptors,
        "predict_proba",
    ),
    "make_recommended": Case(
        lambda: make_recommended(random_state=0).set_params(
            tagger__hidden_sizes=(4,),
            tagger__max_epochs=2,
            tagger__steps_per_epoch=3,
        ),
        _skeletons,
        "predict",
        raw=True,
    ),
    "make_method_a": Case(
        lambda: _tiny_multiscale(make_method_a(random_state=0)),
        _skeletons,
        "predict",
        raw=True,
    ),
    "make_method_b": Case(
        lambda: _tiny_multiscale(make_method_b(random_state=0)),
        _skeletons,
        "predict",
        raw=True,
    ),
    "make_method_c": Case(
        lambda: make_method_c(random_state=0).set_params(
            tagger__hidden_sizes=(4,), tagger__max_epochs=2
        ),
        _skeletons,
        "predict",
        raw=True,
    ),
}
NAMES = sorted(CASES)
SEQUENCE_NAMES = [name for name in NAMES if CASES[name].sequences]


@cache
def _fitted_once(name):
    """One fitted instance per case, shared by the tests that only read it."""
    X, y = CASES[name].data()
    return CASES[name].make().fit(X, y)


def _outputs(est, method, X):
    out = getattr(est, method)(X)
    return list(out) if isinstance(out, list) else [out]


def _assert_identical(a, b):
    assert len(a) == len(b)
    for u, v in zip(a, b):
        np.testing.assert_array_equal(np.ma.getdata(u), np.ma.getdata(v))
        np.testing.assert_array_equal(np.ma.getmaskarray(u), np.ma.getmaskarray(v))


def _leaves(est):
    """The estimator and every estimator inside it (pipeline steps, inner nets)."""
    found = [est]
    for value in est.get_params(deep=True).values():
        if isinstance(value, BaseEstimator):
            found.append(value)
    return found


# --------------------------------------------------------------------------------
# Construction and parameters
# --------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_init_does_no_work(name):
    est = CASES[name].make()
    for part in _leaves(est):
        params = part.get_params(deep=False)
        stored = {k for k in vars(part) if not k.startswith("_")}
        assert stored == set(params), type(part).__name__
        assert not [k for k in stored if k.endswith("_")]


def _assert_same_params(a, b):
    """Equal parameters, recursing into estimators and pipeline steps."""
    if isinstance(a, BaseEstimator):
        assert type(a) is type(b)
        pa, pb = a.get_params(deep=False), b.get_params(deep=False)
        assert pa.keys() == pb.keys()
        for key in pa:
            _assert_same_params(pa[key], pb[key])
    elif isinstance(a, (list, tuple)) and a and isinstance(a[0], tuple):  # steps
        assert [n for n, _ in a] == [n for n, _ in b]
        for (_, u), (_, v) in zip(a, b):
            _assert_same_params(u, v)
    else:
        assert a == b or a is b, (a, b)


@pytest.mark.parametrize("name", NAMES)
def test_clone_and_get_set_params_round_trip(name):
    est = CASES[name].make()
    copy = clone(est)
    assert copy is not est
    _assert_same_params(copy, est)
    # every deep parameter can be set back, and reads back unchanged
    rebuilt = CASES[name].make().set_params(**est.get_params(deep=True))
    _assert_same_params(rebuilt, est)
    inner = [k for k, v in est.get_params(deep=True).items() if "__" in k]
    if inner:  # a nested parameter reaches the inner estimator
        key = next(k for k in inner if k.endswith("random_state"))
        assert copy.set_params(**{key: 7}).get_params(deep=True)[key] == 7


@pytest.mark.parametrize("name", NAMES)
def test_fit_returns_self(name):
    X, y = CASES[name].data()
    est = CASES[name].make()
    assert est.fit(X, y) is est


@pytest.mark.parametrize("name", NAMES)
def test_not_fitted_error_before_fit(name):
    X, _ = CASES[name].data()
    with pytest.raises(NotFittedError):
        getattr(CASES[name].make(), CASES[name].output)(X)


@pytest.mark.parametrize("name", SEQUENCE_NAMES)
def test_an_empty_list_is_a_clear_error(name):
    _, y = CASES[name].data()
    with pytest.raises(ValueError, match="is empty: at least one sequence"):
        CASES[name].make().fit([], None if y is None else [])
    with pytest.raises(ValueError, match="is empty: at least one sequence"):
        getattr(_fitted_once(name), CASES[name].output)([])


# --------------------------------------------------------------------------------
# Bad values (docs/design.md §1.2)
# --------------------------------------------------------------------------------


def _spoil(X, value, frame=3):
    """A copy of ``X`` whose second sequence (or row block) holds ``value``."""
    if not isinstance(X, list):
        X = np.array(X, dtype=float)
        X[frame, 1] = value
        return X
    x = np.array(np.ma.getdata(X[1]), dtype=float)
    x.reshape(len(x), -1)[frame, 1] = value
    spoilt = list(X)
    spoilt[1] = x
    return spoilt


def _bad_values(name):
    case = CASES[name]
    if not case.sequences:  # sklearn's own validation of a 2-D classifier
        return [(np.inf, "infinity"), (np.nan, "NaN")]
    values = [
        (np.inf, r"X\[1\] contains (NaN or )?infinite values \(first at frame 3\)")
    ]
    if not case.raw:  # NaN marks an untracked joint in raw skeletons only
        values.append(
            (np.nan, r"X\[1\] contains NaN or infinite values \(first at frame 3\)")
        )
    big = 1e6 if case.raw else 1e39  # beyond 1e5 m, or beyond float32
    values.append((big, re.escape(f"X[1] has the value {big:.0e} at frame 3, beyond")))
    return values


BAD_VALUE_CASES = [
    (name, value, match) for name in NAMES for value, match in _bad_values(name)
]


@pytest.mark.parametrize("name, value, match", BAD_VALUE_CASES)
def test_non_finite_and_absurd_values_are_clear_errors(name, value, match):
    X, y = CASES[name].data()
    bad = _spoil(X, value)
    with pytest.raises(ValueError, match=match):
        CASES[name].make().fit(bad, y)
    with pytest.raises(ValueError, match=match):
        getattr(_fitted_once(name), CASES[name].output)(bad)


# --------------------------------------------------------------------------------
# Inputs are only read; results persist and repeat
# --------------------------------------------------------------------------------


def _read_only(X):
    if isinstance(X, list):
        return [_read_only(x) for x in X]
    if X is None:
        return None
    X = X.copy()
    X.setflags(write=False)
    return X


@pytest.mark.parametrize("name", NAMES)
def test_read_only_inputs_are_accepted_and_left_alone(name):
    X, y = CASES[name].data()
    Xr, yr = _read_only(X), _read_only(y)
    before = [np.array(x, copy=True) for x in (Xr if isinstance(Xr, list) else [Xr])]
    est = CASES[name].make().fit(Xr, yr)
    method = CASES[name].output
    _assert_identical(
        _outputs(est, method, Xr), _outputs(_fitted_once(name), method, X)
    )
    after = Xr if isinstance(Xr, list) else [Xr]
    for b, a in zip(before, after):
        np.testing.assert_array_equal(np.ma.getdata(a), b)


@pytest.mark.parametrize("name", NAMES)
def test_pickle_round_trip_gives_identical_outputs(name):
    X, _ = CASES[name].data()
    est = _fitted_once(name)
    restored = pickle.loads(pickle.dumps(est))
    method = CASES[name].output
    _assert_identical(_outputs(restored, method, X), _outputs(est, method, X))


@pytest.mark.parametrize("name", NAMES)
def test_same_random_state_gives_identical_outputs(name):
    import torch

    X, y = CASES[name].data()
    torch.manual_seed(123)  # the global torch RNG must not matter
    est = CASES[name].make().fit(X, y)
    method = CASES[name].output
    _assert_identical(_outputs(est, method, X), _outputs(_fitted_once(name), method, X))
