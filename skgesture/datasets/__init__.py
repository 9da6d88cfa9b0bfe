"""Real and synthetic skeleton gesture data.

Every loader returns a :class:`sklearn.utils.Bunch` with the same keys: ``X``
(list of ``(n_frames_i, 20, 3)`` float64 world positions in metres, Kinect v1 NUI
joint order, untracked frames all zeros), ``y`` (list of per-frame int64 labels,
0 = rest), ``segments`` (list of ``(n_i, 3)`` int64 rows ``(class, start, end)``,
0-based, end exclusive), ``sample_ids``, ``groups`` (subject where known),
``fps``, ``n_frames``, ``missing``, ``target_names`` (``target_names[k - 1]``
names class ``k``), ``layout`` (``"kinect_v1"``) and ``DESCR``.
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture.datasets._background import SyntheticBackground, make_background
from skgesture.datasets._base import DataFileWarning, DataFormatError
from skgesture.datasets._chalearn import (
    CHALEARN_GESTURE_NAMES,
    load_chalearn,
    read_chalearn_labels,
    write_chalearn_predictions,
)
from skgesture.datasets._intervals import read_intervals, write_intervals
from skgesture.datasets._others import (
    MSR_ACTION3D_ACTION_NAMES,
    MSRC12_GESTURE_NAMES,
    UTKINECT_ACTION_NAMES,
    load_msr_action3d,
    load_msrc12,
    load_utkinect,
)
from skgesture.datasets._precog import PRECOG_ACTION_NAMES, load_precog
from skgesture.datasets._recordings import load_recordings
from skgesture.datasets._skeleton_csv import read_skeleton_csv
from skgesture.datasets._synthetic import make_gesture_streams
from skgesture.layouts import MSR_ACTION3D_TO_KINECT_V1

__all__ = [
    "CHALEARN_GESTURE_NAMES",
    "DataFileWarning",
    "DataFormatError",
    "MSRC12_GESTURE_NAMES",
    "MSR_ACTION3D_ACTION_NAMES",
    "MSR_ACTION3D_TO_KINECT_V1",
    "PRECOG_ACTION_NAMES",
    "SyntheticBackground",
    "UTKINECT_ACTION_NAMES",
    "load_chalearn",
    "load_msr_action3d",
    "load_msrc12",
    "load_precog",
    "load_recordings",
    "load_utkinect",
    "make_background",
    "make_gesture_streams",
    "read_chalearn_labels",
    "read_intervals",
    "read_skeleton_csv",
    "write_chalearn_predictions",
    "write_intervals",
]
