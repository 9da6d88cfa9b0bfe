"""Evaluation of per-frame gesture labellings.

The ChaLearn LAP 2014 Jaccard index exactly as the official script computes it
(with the penalised and inclusive variants of docs/method.md §2.3), frame accuracy,
the frame confusion matrix, the per-class report (frame precision, recall and F1,
gestures found), the segmental F1@k and edit scores of temporal action
segmentation, the event-level recall and false events per minute of a command
interface (``rejection_curve``), why true gestures were missed
(``event_misses``), and scorers for ``GridSearchCV``.
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture.metrics._events import event_misses, event_recall, rejection_curve
from skgesture.metrics._jaccard import jaccard_index, jaccard_index_segments
from skgesture.metrics._scorers import (
    SCORERS,
    get_scorer,
    jaccard_scorer,
    make_jaccard_scorer,
    make_sequence_scorer,
)
from skgesture.metrics._segmental import (
    edit_score,
    frame_accuracy,
    frame_confusion_matrix,
    per_class_report,
    segmental_f1,
)
from skgesture.utils._segments import labels_to_segments, segments_to_labels

__all__ = [
    "jaccard_index",
    "jaccard_index_segments",
    "frame_accuracy",
    "frame_confusion_matrix",
    "per_class_report",
    "segmental_f1",
    "edit_score",
    "event_recall",
    "event_misses",
    "rejection_curve",
    "jaccard_scorer",
    "make_jaccard_scorer",
    "make_sequence_scorer",
    "get_scorer",
    "SCORERS",
    "labels_to_segments",
    "segments_to_labels",
]
