"""GesturePipeline: a scikit-learn Pipeline that knows the frame rate it was trained at.

Apart from the pipeline builders of ``_pipelines`` (which import every stage,
torch's taggers among them), so that a model file naming it loads without
torch.
"""

# SPDX-License-Identifier: BSD-3-Clause

import warnings
from numbers import Real

import numpy as np
from sklearn.pipeline import Pipeline
from sklearn.utils._metadata_requests import _routing_enabled
from sklearn.utils._param_validation import HasMethods, StrOptions
from sklearn.utils.metadata_routing import UNUSED
from sklearn.utils.metaestimators import available_if
from sklearn.utils.validation import check_is_fitted

from skgesture._rate import (
    DEFAULT_FPS,
    check_fps,
    frames_back,
    resample,
    same_rate,
    segments_back,
)
from skgesture.utils._params import NewParamsMixin

__all__ = ["GesturePipeline"]


def _last_step_has(attr):
    """``available_if`` check: the last step has ``attr`` (as sklearn's Pipeline)."""

    def check(self):
        getattr(self._final_estimator, attr)
        return True

    return check


def _sequence_rates(fps, n, what):
    """``fps`` as one float per sequence, from a number or one rate per sequence."""
    if isinstance(fps, Real) and not isinstance(fps, (bool, np.bool_)):
        return [check_fps(fps, what)] * n
    if isinstance(fps, (str, bytes)) or not hasattr(fps, "__len__"):
        raise ValueError(
            f"{what} must be a positive finite number of frames per second, or one "
            f"per sequence, got {fps!r}"
        )
    rates = list(np.ravel(np.asarray(fps, dtype=object)))
    if len(rates) != n:
        raise ValueError(
            f"{what} holds {len(rates)} rates for {n} sequences: give one number, "
            f"or one rate per sequence"
        )
    return [check_fps(r, f"{what}[{i}]") for i, r in enumerate(rates)]


class GesturePipeline(NewParamsMixin, Pipeline):
    """A scikit-learn ``Pipeline`` that knows the frame rate it was trained at.

    Every model of the toolkit counts time in frames (the paper's Gaussian of 5
    frames, windows of 9, periods of at least 12, steps of 2 to 4), so the same
    gesture at another rate looks like another gesture. ``fit`` records the
    rate of the training data (``fps_``); ``predict`` and its siblings take
    the rate of their input (``fps=``) and, where it differs, resample each
    sequence to ``fps_`` (linear interpolation, never across an untracked
    frame), run the pipeline, and bring the output back to the input's frames:
    exactly one label (probability row, segment frame) per input frame. With
    no ``fps``, or the model's own, the computation is the plain
    ``Pipeline``'s, bit for bit. The factories (:func:`make_method_a`,
    :func:`make_method_b`, :func:`make_method_c`, :func:`make_recommended`)
    return one; docs/streaming.md ("Frame rates") describes the rule.

    Parameters
    ----------
    steps : list of (str, estimator) tuples
        The stages, as for :class:`sklearn.pipeline.Pipeline`.
    transform_input : list of str or None, default=None
        As for :class:`sklearn.pipeline.Pipeline`.
    memory : str, joblib.Memory or None, default=None
        As for :class:`sklearn.pipeline.Pipeline`.
    verbose : bool, default=False
        As for :class:`sklearn.pipeline.Pipeline`.
    background : object with ``make(X, y)`` or None, default=None
        Negatives made in ``fit`` from the training recordings, e.g.
        :class:`~skgesture.datasets.SyntheticBackground`: its ``make(X, y)``
        returns sequences (``.X``, all-rest ``.y``) added to the training
        data, at the training rate. None adds nothing. Made from the data
        each ``fit`` sees, so a cross-validation fold's negatives come from
        its own training recordings.
    background_for : {"model", "namer"}, default="model"
        Who learns the negatives of ``background``: ``"model"``, every step
        (the tagger's network learns them as rest); ``"namer"``, the run
        namer of the last step alone (a :class:`~skgesture.SequenceTagger`
        with ``namer``, fitted with ``namer_only``): its ``max_namer_rest``
        rule then sets to rest the runs that look like them, and the
        network is the one fitted without them (docs/safety.md, "Synthetic
        negatives for the namer"). A last step without a run namer gets no
        negatives, with a warning.

    Attributes
    ----------
    fps_ : float
        The frame rate of the training data (``fit(..., fps=...)``; 30.0 when
        none was given).
    named_steps : Bunch
        The steps by name.
    classes_ : ndarray
        The classes of the last step.

    See Also
    --------
    skgesture.streaming.StreamingRecognizer : Takes the input's rate too
        (``fps=``).

    Notes
    -----
    ``fps`` is metadata: ``GridSearchCV(...).fit(X, y, fps=data.fps)`` and
    ``cross_validate(..., params={"fps": data.fps})`` hand it on to ``fit``
    (one rate per sequence is split with the sequences), with or without
    ``sklearn.set_config(enable_metadata_routing=True)``. A model file keeps
    ``fps_`` (a plain float attribute). A plain ``Pipeline`` saved by an
    older version loads and predicts as before, without rates.

    Examples
    --------
    >>> from sklearn.linear_model import LogisticRegression
    >>> from skgesture import make_method_b
    >>> from skgesture.datasets import make_gesture_streams
    >>> data = make_gesture_streams(n_sequences=4, n_classes=3, random_state=0)
    >>> model = make_method_b(random_state=0).set_params(
    ...     segmenter__estimator=LogisticRegression(),
    ...     classifier__estimator=LogisticRegression())
    >>> model = model.fit(data.X[:3], data.y[:3], fps=data.fps)
    >>> model.fps_
    20.0
    >>> x = data.X[3][::2]  # the same stream at 10 fps
    >>> labels = model.predict([x], fps=10)[0]
    >>> labels.shape == (len(x),)
    True
    """

    # fps is the pipeline's own metadata, requested by default (as a group
    # splitter requests ``groups``), so routers hand it on.
    __metadata_request__fit = {"fps": True}
    __metadata_request__predict = {"fps": True}
    __metadata_request__predict_proba = {"fps": True}
    __metadata_request__decision_function = {"fps": True}
    __metadata_request__score = {"fps": True, "sample_weight": UNUSED}

    _parameter_constraints: dict = {
        **Pipeline._parameter_constraints,
        "background": [HasMethods(["make"]), None],
        "background_for": [StrOptions({"model", "namer"})],
    }

    def __init__(
        self,
        steps,
        *,
        transform_input=None,
        memory=None,
        verbose=False,
        background=None,
        background_for="model",
    ):
        super().__init__(
            steps, transform_input=transform_input, memory=memory, verbose=verbose
        )
        self.background = background
        self.background_for = background_for

    def fit(self, X, y=None, fps=None, **params):
        """Fit every step, and record the frame rate of the training data.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Training skeletons.
        y : list of ndarray of shape (n_frames_i,) or None, default=None
            Per-frame labels.
        fps : float, array-like of shape (n_sequences,) or None, default=None
            The frame rate of the training data (a loader's ``data.fps``);
            one rate per sequence must be one rate. None means 30 fps.
        **params : dict
            Fit parameters of the steps, as for
            :meth:`sklearn.pipeline.Pipeline.fit`.

        Returns
        -------
        self : object
            The fitted pipeline.

        Raises
        ------
        ValueError
            When ``fps`` is not a positive finite number, or the sequences'
            rates differ.
        """
        rate = DEFAULT_FPS
        if fps is not None:
            rates = _sequence_rates(fps, len(X), "fps")
            rate = rates[0] if rates else DEFAULT_FPS
            other = [i for i, r in enumerate(rates) if not same_rate(r, rate)]
            if other:
                raise ValueError(
                    f"fps differs between the training sequences (X[0] at "
                    f"{rate:g} fps, X[{other[0]}] at {rates[other[0]]:g}): a model "
                    f"has one rate; resample the sequences to one rate first "
                    f"(skgesture._rate.resample)"
                )
        if self.background is not None:
            self._validate_params()  # a clear error before make(X, y) is called
            if self.background_for == "model":
                X, y = self._with_background(X, y)
            elif (name := self._namer_step()) is not None:
                n = len(X)
                X, y = self._with_background(X, y)
                params = self._namer_only_params(params, name, n, len(X))
        super().fit(X, y, **params)
        self.fps_ = float(rate)
        return self

    def _with_background(self, X, y):
        """The training data with the negatives of ``background`` appended."""
        if y is None:
            raise ValueError(
                "background needs the labels y: negatives are made from the gestures"
            )
        made = self.background.make(X, y)
        return list(X) + list(made.X), list(y) + list(made.y)

    def _namer_step(self):
        """The name of the last step when it has a run namer to learn the
        negatives (``background_for="namer"``), else None with a warning: the
        negatives are then not made (``make_recommended().set_params(
        tagger__namer=None)`` trains as with ``background=None``)."""
        name, last = self.steps[-1]
        if getattr(last, "namer", None) is not None:
            return name
        warnings.warn(
            f"background_for='namer' gives the negatives of background to the run "
            f"namer of the last step, but {name!r} ({type(last).__name__}) has "
            f"none: no negatives are made. Set background=None to train without "
            f"them (and silence this), or background_for='model' to give them to "
            f"the whole model",
            UserWarning,
            stacklevel=3,
        )
        return None

    def _namer_only_params(self, params, name, n_recordings, n_sequences):
        """``params`` with the ``namer_only`` flags of the last step, ``name``:
        the sequences after the first ``n_recordings`` are the negatives."""
        flags = np.arange(n_sequences) >= n_recordings
        if _routing_enabled():
            return {**params, "namer_only": flags}
        return {**params, f"{name}__namer_only": flags}

    def get_metadata_routing(self):
        """Get the metadata routing of this object: the steps' and ``fps``.

        Returns
        -------
        MetadataRouter
            The routing of :class:`sklearn.pipeline.Pipeline`, with the
            pipeline's own request for ``fps``.
        """
        return super().get_metadata_routing().add_self_request(self)

    # -- the input's rate ----------------------------------------------------------

    def _plan(self, X, fps):
        """``None`` (predict as is) or ``(X at fps_, input rates, resampled)``."""
        check_is_fitted(self)
        if fps is None:
            return None
        rates = _sequence_rates(fps, len(X), "fps")
        model = getattr(self, "fps_", None)
        if model is None:
            raise ValueError(
                "this pipeline does not know the rate it was trained at (no fps_): "
                "fit it with fit(X, y, fps=...), or set fps_"
            )
        todo = [i for i, r in enumerate(rates) if not same_rate(r, model)]
        if not todo:
            return None
        checked = self._checked_input(X)
        Xm = list(X)
        for i in todo:
            Xm[i] = resample(checked[i], rates[i], model)
        return Xm, rates, todo

    def _checked_input(self, X):
        """The raw sequences validated as the first step validates them."""
        from skgesture.utils._validation import MAX_COORDINATE, check_sequences

        if isinstance(X, (list, tuple)):
            X = [
                np.ma.filled(np.ma.asarray(x, dtype=float), np.nan)
                if isinstance(x, np.ma.MaskedArray)
                else x
                for x in X
            ]
        first = self.steps[0][1]
        return check_sequences(
            X,
            allow_nan=True,
            max_abs=MAX_COORDINATE,
            estimator=first if hasattr(first, "frame_shape_in_") else None,
            reset=False,
        )

    def _rows_back(self, out, X, plan):
        """Per-frame outputs of the resampled sequences back at their frames."""
        _, rates, todo = plan
        out = list(out)
        for i in todo:
            out[i] = frames_back(out[i], rates[i], self.fps_, len(X[i]))
        return out

    def _transform_all(self, Xm):
        Xt = Xm
        for _, _, transform in self._iter(with_final=False):
            Xt = transform.transform(Xt)
        return Xt

    @available_if(_last_step_has("predict"))
    def predict(self, X, fps=None, **params):
        """Per-frame labels, one per input frame, at any input rate.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeletons.
        fps : float, array-like of shape (n_sequences,) or None, default=None
            Their frame rate (or one per sequence). None, or ``fps_``: no
            resampling, the plain pipeline's output.
        **params : dict
            Passed on as by :meth:`sklearn.pipeline.Pipeline.predict`.

        Returns
        -------
        list of ndarray of shape (n_frames_i,)
            Gesture class of every input frame, 0 = rest.
        """
        plan = self._plan(X, fps)
        if plan is None:
            return super().predict(X, **params)
        return self._rows_back(super().predict(plan[0], **params), X, plan)

    @available_if(_last_step_has("predict_proba"))
    def predict_proba(self, X, fps=None, **params):
        """Per-frame class probabilities, one row per input frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeletons.
        fps : float, array-like of shape (n_sequences,) or None, default=None
            Their frame rate, as for :meth:`predict`.
        **params : dict
            Passed on as by :meth:`sklearn.pipeline.Pipeline.predict_proba`.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_classes)
            The last step's probabilities; an input frame takes the row of
            the model-rate frame nearest in time.
        """
        plan = self._plan(X, fps)
        if plan is None:
            return super().predict_proba(X, **params)
        return self._rows_back(super().predict_proba(plan[0], **params), X, plan)

    @available_if(_last_step_has("decision_function"))
    def decision_function(self, X, fps=None, **params):
        """The last step's per-frame scores, one row per input frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeletons.
        fps : float, array-like of shape (n_sequences,) or None, default=None
            Their frame rate, as for :meth:`predict`.
        **params : dict
            Passed on as by :meth:`sklearn.pipeline.Pipeline.decision_function`.

        Returns
        -------
        list of ndarray of shape (n_frames_i, ...)
            The last step's scores at the input's frames.
        """
        plan = self._plan(X, fps)
        if plan is None:
            return super().decision_function(X, **params)
        scores = super().decision_function(plan[0], **params)
        return self._rows_back(scores, X, plan)

    @available_if(_last_step_has("predict_segments"))
    def predict_segments(self, X, fps=None):
        """Gesture instances with their confidence, in the input's frames.

        The last step's ``predict_segments`` on the output of the others.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeletons.
        fps : float, array-like of shape (n_sequences,) or None, default=None
            Their frame rate, as for :meth:`predict`.

        Returns
        -------
        list of ndarray of shape (n_segments_i, 4)
            Rows ``(class, start, end, confidence)``, 0-based, ``end``
            exclusive, in input frames: the frames that :meth:`predict`
            labels with the segment.
        """
        plan = self._plan(X, fps)
        last = self.steps[-1][1]
        if plan is None:
            return last.predict_segments(self._transform_all(X))
        Xm, rates, todo = plan
        out = list(last.predict_segments(self._transform_all(Xm)))
        for i in todo:
            out[i] = segments_back(
                out[i], rates[i], self.fps_, len(X[i]), n_out=len(Xm[i])
            )
        return out

    @available_if(_last_step_has("score"))
    def score(self, X, y=None, sample_weight=None, fps=None, **params):
        """The last step's score; at another rate, the mean official Jaccard index.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeletons.
        y : list of ndarray of shape (n_frames_i,) or None, default=None
            True per-frame labels.
        sample_weight : None, default=None
            Passed on to the last step (none of the toolkit's takes one).
        fps : float, array-like of shape (n_sequences,) or None, default=None
            Their frame rate, as for :meth:`predict`.
        **params : dict
            Passed on as by :meth:`sklearn.pipeline.Pipeline.score`.

        Returns
        -------
        float
            Without resampling, the last step's score (the mean official
            ChaLearn 2014 Jaccard index for every classifier and tagger of the
            toolkit); with it, that index of :meth:`predict` on the input's
            frames.
        """
        plan = self._plan(X, fps)
        if plan is None:
            return super().score(X, y, sample_weight=sample_weight, **params)
        if not hasattr(self._final_estimator, "predict_segments"):
            raise ValueError(
                f"score at another frame rate needs a last step that finds gestures "
                f"(predict_segments); {type(self._final_estimator).__name__} does not"
            )
        from skgesture.metrics import jaccard_index

        return jaccard_index(y, self._rows_back(super().predict(plan[0]), X, plan))
