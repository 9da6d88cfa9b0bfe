"""skgesture: find and name dynamic gestures in continuous skeleton streams.

A scikit-learn compatible implementation of Brás, Simão & Neto, "Gesture
Recognition from Skeleton Data for Intuitive Human-Machine Interaction": a 183-D
pose descriptor, an activity segmenter, multi-scale dynamic-pose classifiers
(Methods A and B) and a bidirectional LSTM tagger (Method C).

Public names are imported lazily, so ``import skgesture`` does not import torch.
"""

# SPDX-License-Identifier: BSD-3-Clause

import importlib

from skgesture import _legacy
from skgesture._version import __version__

_legacy.install()  # the module paths of 0.1, for old model files

_LAZY = {
    "PoseDescriptor": "skgesture._descriptor",
    "ActivitySegmenter": "skgesture._segmenter",
    "DynamicPoseWindow": "skgesture._windows",
    "MultiScaleClassifier": "skgesture._multiscale",
    "BiLSTMTagger": "skgesture._taggers._bilstm",
    "TorchMLPClassifier": "skgesture._nn._mlp",
    "JointFeatures": "skgesture._features",
    "ConcatFeatures": "skgesture._concat",
    "SkeletonAugmenter": "skgesture._augment",
    "SequenceTagger": "skgesture._taggers._sequence",
    "VotingTagger": "skgesture._taggers._voting",
    "GesturePipeline": "skgesture._gesture_pipeline",
    "make_recommended": "skgesture._pipelines",
    "make_method_a": "skgesture._pipelines",
    "make_method_b": "skgesture._pipelines",
    "make_method_c": "skgesture._pipelines",
    "StreamingRecognizer": "skgesture.streaming",
    "labels_to_segments": "skgesture.utils._segments",
    "segments_to_labels": "skgesture.utils._segments",
    "save_model": "skgesture._persistence",
    "load_model": "skgesture._persistence",
}

_SUBMODULES = {"datasets", "metrics", "utils", "layouts", "streaming", "plotting"}

__all__ = sorted(_LAZY) + sorted(_SUBMODULES) + ["__version__"]


def __getattr__(name):
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    if name in _SUBMODULES:
        return importlib.import_module(f"skgesture.{name}")
    raise AttributeError(f"module 'skgesture' has no attribute {name!r}")


def __dir__():
    return __all__
