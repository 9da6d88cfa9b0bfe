"""TorchMLPClassifier: the paper's frame and window networks as a 2-D classifier."""

# SPDX-License-Identifier: BSD-3-Clause

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, _fit_context
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

from skgesture._nn._defaults import SCG_MAX_FAIL, TEST_FRACTION, VALIDATION_FRACTION
from skgesture._nn._fast import ACTIVATIONS, MLPProba
from skgesture.utils._fitting import seed_from
from skgesture.utils._params import NewParamsMixin
from skgesture.utils._threads import blas_threads
from skgesture.utils._validation import SequenceOf

__all__ = ["TorchMLPClassifier", "fast_proba"]


class TorchMLPClassifier(NewParamsMixin, ClassifierMixin, BaseEstimator):
    """Multi-layer perceptron trained through skorch, MATLAB-style by default.

    An ordinary 2-D scikit-learn classifier (one row per sample). With two
    classes it has one sigmoid output (binary cross-entropy), with more a softmax
    output (cross-entropy). The default solver is MATLAB's full-batch scaled
    conjugate gradient with a random 70/15/15 division, validation stop after 6
    failures and the best validation weights kept (docs/method.md §8.6).

    Parameters
    ----------
    hidden_layer_sizes : tuple of int, default=(300, 100)
        Width of each hidden layer (the paper's window network: 300, 100).
    activations : tuple of {"relu", "tanh", "sigmoid", "leaky_relu"}, \
            default=("tanh", "tanh")
        Activation after each hidden layer.
    solver : {"scg", "adam", "lbfgs"}, default="scg"
        Optimiser: scaled conjugate gradient (full batch), Adam (mini-batches of
        ``batch_size``) or L-BFGS (full batch).
    max_epochs : int, default=1000
        Maximum number of epochs (MATLAB ``trainscg`` default).
    learning_rate : float or None, default=None
        Learning rate of Adam (default 1e-3) or L-BFGS (default 1); unused by SCG.
    batch_size : int, default=256
        Mini-batch size for Adam.
    validation_fraction : float, default=0.15
        Share of the samples used for validation stop; 0 trains on all samples
        and keeps the weights of the lowest training loss.
    test_fraction : float, default=0.15
        Share held out of training and validation, as MATLAB's ``dividerand``.
    max_fail : int, default=6
        Validation failures before training stops.
    device : str, default="cpu"
        Torch device, passed to skorch.
    n_threads : int or None, default=1
        CPU threads while fitting (torch's intra-op threads) and predicting
        (the BLAS threads of numpy); the previous setting is restored
        afterwards, and ``None`` keeps it. One thread is fastest for the
        paper's small networks and never oversubscribes a busy machine or
        parallel jobs (docs/design.md §6).
    random_state : int, RandomState instance or None, default=None
        Seeds the initialisation, the data division and the shuffling.
    verbose : int, default=0
        0 is silent, 1 shows a tqdm bar over epochs, 2 prints skorch's epoch table.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Class labels.
    net_ : skorch.NeuralNet
        The trained network.
    n_features_in_ : int
        Number of input features.

    See Also
    --------
    ActivitySegmenter : Uses a (100 ReLU, 100 tanh) instance on single frames.
    MultiScaleClassifier : Uses one (300, 100) tanh instance per time scale.

    Examples
    --------
    >>> import numpy as np
    >>> from skgesture import TorchMLPClassifier
    >>> rng = np.random.RandomState(0)
    >>> X = np.r_[rng.normal(-2, 1, (40, 2)), rng.normal(2, 1, (40, 2))]
    >>> y = np.r_[np.zeros(40, int), np.ones(40, int)]
    >>> clf = TorchMLPClassifier(hidden_layer_sizes=(8,), activations=("tanh",),
    ...                          max_epochs=50, random_state=0).fit(X, y)
    >>> float(clf.score(X, y)) > 0.9
    True
    """

    _parameter_constraints: dict = {
        "hidden_layer_sizes": [SequenceOf.ints(1, allow_empty=True)],
        "activations": [
            SequenceOf(
                lambda a: isinstance(a, str) and a in ACTIVATIONS,
                f"a tuple of names among {sorted(ACTIVATIONS)}",
                allow_empty=True,
            )
        ],
        "solver": [StrOptions({"scg", "adam", "lbfgs"})],
        "max_epochs": [Interval(Integral, 1, None, closed="left")],
        "learning_rate": [Interval(Real, 0, None, closed="neither"), None],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "validation_fraction": [Interval(Real, 0, 1, closed="left")],
        "test_fraction": [Interval(Real, 0, 1, closed="left")],
        "max_fail": [Interval(Integral, 1, None, closed="left")],
        "device": [str],
        "n_threads": [Interval(Integral, 1, None, closed="left"), None],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        *,
        hidden_layer_sizes=(300, 100),
        activations=("tanh", "tanh"),
        solver="scg",
        max_epochs=1000,
        learning_rate=None,
        batch_size=256,
        validation_fraction=VALIDATION_FRACTION,
        test_fraction=TEST_FRACTION,
        max_fail=SCG_MAX_FAIL,
        device="cpu",
        n_threads=1,
        random_state=None,
        verbose=0,
    ):
        self.hidden_layer_sizes = hidden_layer_sizes
        self.activations = activations
        self.solver = solver
        self.max_epochs = max_epochs
        self.learning_rate = learning_rate
        self.batch_size = batch_size
        self.validation_fraction = validation_fraction
        self.test_fraction = test_fraction
        self.max_fail = max_fail
        self.device = device
        self.n_threads = n_threads
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y):
        """Train the network.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
            Training samples.
        y : array-like of shape (n_samples,)
            Class labels.

        Returns
        -------
        self : TorchMLPClassifier
            The fitted classifier.
        """
        import torch

        from skgesture._nn._training import TORCH_RNG_LOCK, build_net, torch_threads

        X, y = validate_data(self, X, y, dtype=np.float32)
        check_classification_targets(y)
        if len(self.activations) != len(self.hidden_layer_sizes):
            raise ValueError(
                f"hidden_layer_sizes has {len(self.hidden_layer_sizes)} layers but "
                f"activations has {len(self.activations)} entries"
            )
        if self.validation_fraction + self.test_fraction >= 1:
            raise ValueError(
                f"validation_fraction + test_fraction must be < 1, got "
                f"{self.validation_fraction} + {self.test_fraction}"
            )
        self.classes_, y_idx = np.unique(y, return_inverse=True)
        n_classes = len(self.classes_)
        if n_classes < 2:
            raise ValueError(
                f"TorchMLPClassifier needs samples of at least 2 classes; y has "
                f"{n_classes} class"
            )
        binary = n_classes == 2
        seed = seed_from(self.random_state)
        module_params = {
            "n_inputs": X.shape[1],
            "n_outputs": 1 if binary else n_classes,
            "hidden_layer_sizes": tuple(self.hidden_layer_sizes),
            "activations": tuple(self.activations),
        }
        validation = self.validation_fraction
        if validation > 0 and round(validation * len(X)) < 1:
            validation = 0.0  # too few samples for a validation set
        self.net_ = build_net(
            module_params,
            loss="binary" if binary else "multiclass",
            solver=self.solver,
            max_epochs=self.max_epochs,
            learning_rate=self.learning_rate,
            batch_size=self.batch_size,
            n_samples=len(X),
            validation_fraction=validation,
            test_fraction=self.test_fraction if validation > 0 else 0.0,
            max_fail=self.max_fail,
            seed=seed,
            device=self.device,
            verbose=self.verbose,
        )
        target = y_idx.astype(np.float32).reshape(-1, 1) if binary else y_idx
        # skorch does not seed (its FAQ): the initialisation and the shuffling use
        # torch's global RNG, so seed it from random_state (docs/design.md §9). Seeding
        # and initialisation hold a lock: networks fitted in parallel threads
        # (a Dask worker's, joblib's threading backend) keep their own seeds.
        # (NeuralNet.fit is initialize + partial_fit.)
        with torch_threads(self.n_threads):
            with TORCH_RNG_LOCK:
                torch.manual_seed(seed)
                self.net_.initialize()
            self.net_.partial_fit(X, target)
        return self

    def predict_proba(self, X):
        """Class probabilities.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
            Samples.

        Returns
        -------
        ndarray of shape (n_samples, n_classes)
            Probabilities, rows sum to 1, columns in ``classes_`` order.

        Notes
        -----
        The forward pass runs in numpy (float32, the module's weights; equal
        to torch's to float32 rounding), so that a model file loaded for
        prediction never imports torch, and the live step computes exactly
        what this method does.
        """
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float32, reset=False)
        # getattr: a model pickled before n_threads existed keeps the BLAS setting.
        with blas_threads(getattr(self, "n_threads", None)):
            return MLPProba(self)(X)

    def predict(self, X):
        """Most probable class.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
            Samples.

        Returns
        -------
        ndarray of shape (n_samples,)
            Predicted labels.
        """
        check_is_fitted(self)
        return self.classes_[np.argmax(self.predict_proba(X), axis=1)]

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.non_deterministic = False
        return tags


def fast_proba(estimator):
    """``predict_proba`` of a fitted 2-D classifier, as a fast callable.

    For a :class:`TorchMLPClassifier` its one inference path
    (:class:`~skgesture._nn._fast.MLPProba`) without the per-call input
    validation of ``predict_proba``, which costs more than the forward pass of
    one row: the same numbers. Any other classifier's own ``predict_proba``
    is returned.
    """
    if not isinstance(estimator, TorchMLPClassifier):
        return estimator.predict_proba
    return MLPProba(estimator)
