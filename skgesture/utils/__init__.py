"""Shared helpers: sequence validation, segments, smoothing, resizing, SCG,
the distance of frames to a recording's poses (PoseNovelty).

``SCG`` is imported lazily: ``import skgesture.utils`` does not import torch.
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture.utils._novelty import PoseNovelty
from skgesture.utils._resize import imresize_weights, resize_frames
from skgesture.utils._segments import (
    labels_to_segments,
    remove_short_runs,
    runs,
    segments_to_labels,
)
from skgesture.utils._smoothing import loess_kernel, loess_smooth
from skgesture.utils._validation import (
    check_sequence_labels,
    check_sequences,
    missing_frames,
)

__all__ = [
    "check_sequences",
    "check_sequence_labels",
    "missing_frames",
    "labels_to_segments",
    "segments_to_labels",
    "runs",
    "remove_short_runs",
    "loess_smooth",
    "loess_kernel",
    "resize_frames",
    "imresize_weights",
    "PoseNovelty",
    "SCG",
]


def __getattr__(name):
    if name == "SCG":
        from skgesture.utils._scg import SCG

        return SCG
    raise AttributeError(f"module 'skgesture.utils' has no attribute {name!r}")
