"""ConcatFeatures: several per-frame feature transformers side by side.

scikit-learn's ``FeatureUnion`` for lists of sequences: every transformer reads
the same raw skeletons, and the features of a frame are theirs, concatenated
in the order given. Live, each transformer runs its own incremental step and a
row is handed on once every transformer has given it, so the stream equals the
offline features exactly when each of them does (docs/design.md, "Incremental
steps").
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np
from sklearn.base import TransformerMixin, _fit_context, clone
from sklearn.utils.metaestimators import _BaseComposition
from sklearn.utils.validation import check_is_fitted

from skgesture._stream import Rows, StreamableMixin, missing_stream_methods
from skgesture.utils._buffers import _concat_rows
from skgesture.utils._validation import (
    SequenceOutputMixin,
    check_skeletons,
    check_stream_frames,
    mask_rows,
    sequence_tags,
)

__all__ = ["ConcatFeatures"]


class ConcatFeatures(
    StreamableMixin,
    SequenceOutputMixin,
    TransformerMixin,
    _BaseComposition,
    auto_wrap_output_keys=None,
):
    """The features of several transformers, side by side, for every frame.

    The sequence version of scikit-learn's ``FeatureUnion``: each transformer
    is fitted on the same raw skeleton sequences, and the features of a
    frame are the concatenation of theirs, in the order of ``transformers``.
    A frame is rest (a masked row) when any transformer masks it. Nested
    parameters are reached as in a ``Pipeline``
    (``set_params(descriptor__fill="hold")``).

    ``make_recommended(features="descriptor+joints")`` uses it to give the
    tagger the paper's descriptor and the normalised joints together.

    Parameters
    ----------
    transformers : list of (str, transformer)
        Named per-frame transformers, each taking a list of raw sequences and
        returning one ``(n_frames_i, n_features)`` array per sequence (e.g.
        :class:`PoseDescriptor` and :class:`JointFeatures`). The names are
        unique and contain no ``"__"``.

    Attributes
    ----------
    transformers_ : list of (str, transformer)
        The fitted clones of ``transformers``.
    n_features_out_ : int
        Number of features per frame, the sum of the transformers'.
    frame_shape_in_ : tuple of int
        Shape of one input frame seen in ``fit``, ``(20, 3)``.
    n_features_in_ : int
        Number of values per input frame (60).

    See Also
    --------
    PoseDescriptor : The paper's descriptor of every frame.
    JointFeatures : Normalised joint positions and velocities.

    Notes
    -----
    Live (:meth:`stream_init`), every transformer runs its own step on the
    frames; a row is final once all of them have given it, so the stage's
    look-ahead is the largest of theirs, and the streamed rows equal
    :meth:`transform`'s wherever each transformer streams exactly
    (``JointFeatures(statistics="running", fill="hold")``,
    ``PoseDescriptor(fill="hold")``).

    Examples
    --------
    >>> from skgesture import JointFeatures, PoseDescriptor
    >>> from skgesture._concat import ConcatFeatures
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> both = ConcatFeatures([
    ...     ("descriptor", PoseDescriptor(fill="hold")),
    ...     ("joints", JointFeatures(fill="hold", statistics="running")),
    ... ])
    >>> F = both.fit_transform([X])
    >>> F[0].shape == (len(X), 183 + 66), both.stream_lookahead
    (True, 4)
    """

    _parameter_constraints: dict = {"transformers": [list, tuple]}
    _stream_options = ("max_backfill",)

    def __init__(self, transformers):
        self.transformers = transformers

    def get_params(self, deep=True):
        """Get the parameters of this estimator and, with ``deep``, its transformers'.

        Parameters
        ----------
        deep : bool, default=True
            Also return the parameters of the transformers, as
            ``<name>__<parameter>``.

        Returns
        -------
        params : dict
            Parameter names mapped to their values.
        """
        return self._get_params("transformers", deep=deep)

    def set_params(self, **params):
        """Set parameters, those of a transformer as ``<name>__<parameter>``.

        Parameters
        ----------
        **params : dict
            Parameters to set; a transformer may be replaced by its name.

        Returns
        -------
        self : ConcatFeatures
            This estimator.
        """
        self._set_params("transformers", **params)
        return self

    def _check_transformers(self):
        items = self.transformers
        if not isinstance(items, (list, tuple)) or not items:
            raise ValueError(
                f"transformers must be a non-empty list of (name, transformer) "
                f"pairs, got {items!r}"
            )
        for i, item in enumerate(items):
            if not isinstance(item, (list, tuple)) or len(item) != 2:
                raise ValueError(
                    f"transformers[{i}] must be a (name, transformer) pair, got "
                    f"{item!r}"
                )
            if not (hasattr(item[1], "fit") and hasattr(item[1], "transform")):
                raise TypeError(
                    f"transformers[{i}] ({item[0]!r}) has no fit/transform: {item[1]!r}"
                )
        names = [name for name, _ in items]
        self._validate_names(names)  # unique, no "__", no clash with a parameter

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y=None):
        """Fit every transformer on the same sequences.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeleton sequences (Kinect v1 joint order).
        y : None
            Ignored.

        Returns
        -------
        self : ConcatFeatures
            The fitted transformer.
        """
        self._check_transformers()
        check_skeletons(X, estimator=self, reset=True)
        self.transformers_ = [(name, clone(t).fit(X)) for name, t in self.transformers]
        self.n_features_out_ = int(
            sum(int(t.n_features_out_) for _, t in self.transformers_)
        )
        return self

    def transform(self, X):
        """The concatenated features of every frame.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, 20, 3)
            Skeleton sequences.

        Returns
        -------
        list of ndarray of shape (n_frames_i, n_features_out_)
            The float32 features; a sequence with a frame that any transformer
            masks comes as a ``numpy.ma.MaskedArray`` whose masked rows are
            those frames.
        """
        check_is_fitted(self)
        X = check_skeletons(X, estimator=self, reset=False)
        parts = [t.transform(X) for _, t in self.transformers_]
        out = []
        for i in range(len(X)):
            blocks = [p[i] for p in parts]
            n = len(X[i])
            for (name, _), b in zip(self.transformers_, blocks):
                if len(b) != n:
                    raise ValueError(
                        f"transformer {name!r} gave {len(b)} rows for sequence "
                        f"{i} of {n} frames; ConcatFeatures needs one row per frame"
                    )
            data = np.concatenate(
                [np.ma.getdata(b) for b in blocks], axis=1, dtype=np.float32
            )
            masked = np.zeros(n, dtype=bool)
            for b in blocks:
                masked |= np.ma.getmaskarray(b).reshape(n, -1).any(axis=1)
            out.append(mask_rows(data, masked))
        return out

    def get_feature_names_out(self, input_features=None):
        """Get the names of the features, ``"<transformer>__<feature>"``.

        Parameters
        ----------
        input_features : None
            Ignored; present for API consistency.

        Returns
        -------
        ndarray of str of shape (n_features_out_,)
            Feature names in output order.
        """
        check_is_fitted(self)
        names = []
        for name, t in self.transformers_:
            names.extend(f"{name}__{f}" for f in t.get_feature_names_out())
        return np.asarray(names, dtype=object)

    def __sklearn_tags__(self):
        return sequence_tags(super().__sklearn_tags__(), raw_skeletons=True)

    # -- incremental step (docs/design.md §4.1, "Incremental steps") -----------

    def _stream_state(self, **options):
        """A fresh state for one live stream: every transformer's own state.

        Parameters
        ----------
        **options
            ``max_backfill``, handed to the transformers that declare it.

        Returns
        -------
        ConcatStream
            The state, for :meth:`stream_step` and :meth:`stream_flush`.
        """
        check_is_fitted(self)
        states = []
        for name, t in self.transformers_:
            missing = missing_stream_methods(t)
            if missing:
                raise TypeError(
                    f"transformer {name!r} ({type(t).__name__}) cannot stream: it "
                    f"has no {', '.join(missing)}"
                )
            declared = getattr(t, "_stream_options", ())
            states.append(
                t.stream_init(**{k: v for k, v in options.items() if k in declared})
            )
        return ConcatStream(self, states)

    @property
    def stream_lookahead(self):
        """Frames after a frame that its row needs (the transformers' largest).

        Each transformer's own ``stream_lookahead``; a row is final once the
        slowest of them has given it.
        """
        check_is_fitted(self)
        return max(int(t.stream_lookahead) for _, t in self.transformers_)


class ConcatStream:
    """State of :meth:`ConcatFeatures.stream_step` for one stream.

    Each transformer's state runs on every block of frames; the rows each
    gives wait in a queue until every transformer has given them, and leave
    concatenated, masked where any of them is masked, with the latest of
    their completion times.
    """

    def __init__(self, feats, states):
        self.estimator = feats
        self.names = [name for name, _ in feats.transformers_]
        self.stages = [t for _, t in feats.transformers_]
        self.states = states
        self.width = int(feats.n_features_out_)
        self.queues = [[] for _ in states]  # Rows blocks not yet handed on

    def step(self, rows):
        """Raw frames in; the rows every transformer has given out."""
        # Checked once before any transformer reads them: a bad frame raises
        # (naming its stream index) with every state unchanged.
        check_stream_frames(rows.data, int(rows.time[0]), self.estimator)
        for k, (stage, state) in enumerate(zip(self.stages, self.states)):
            out, self.states[k] = stage.stream_step(state, rows)
            self._queue(k, out)
        return self._emit()

    def flush(self):
        """The remaining rows, with each transformer's end rules."""
        for k, (stage, state) in enumerate(zip(self.stages, self.states)):
            out, self.states[k] = stage.stream_flush(state)
            self._queue(k, out)
        return self._emit()

    def _queue(self, k, out):
        if out is not None and len(out):
            self.queues[k].append(out)

    def _emit(self):
        blocks = [_concat_rows(q, (0,), np.float32) for q in self.queues]
        n = min(len(b) for b in blocks)
        if n == 0:
            return Rows.empty((self.width,), np.float32)
        data = np.concatenate([b.data[:n] for b in blocks], axis=1, dtype=np.float32)
        mask = np.logical_or.reduce([b.mask[:n] for b in blocks])
        time = np.maximum.reduce([b.time[:n] for b in blocks])
        for k, b in enumerate(blocks):
            rest = Rows(b.data[n:], b.mask[n:], b.time[n:])
            self.queues[k] = [rest] if len(rest) else []
        return Rows(data, mask, time)

    def held(self):
        """Rows held by the transformers' buffers and by the queues."""
        out = {"queued": sum(len(b) for q in self.queues for b in q)}
        for name, state in zip(self.names, self.states):
            for key, value in state.held().items():
                out[f"{name}:{key}"] = value
        return out
