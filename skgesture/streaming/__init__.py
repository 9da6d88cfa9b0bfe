"""Live recognition: streaming recogniser, commands, a robot, skeleton sources.

* :class:`StreamingRecognizer` pushes frames through a fitted Method A, B or C
  pipeline and returns :class:`GestureEvent` objects as soon as they are
  certain (causal, constant work and memory per frame).
* :class:`ActionMap`, :class:`PickAndPlaceRobot` / :class:`SimulatedRobot`
  (with :class:`RobotCommand`, :class:`RobotState`) and
  :class:`GestureCommander` turn events into the paper's pick-and-place
  commands; :class:`CommandMap` maps any gesture vocabulary to any commands,
  with an optional state machine (a JSON or TOML file), and
  :class:`JSONLinesPublisher` / :class:`UDPPublisher` publish each
  :class:`CommandEvent` as JSON.
* Adapters map Kinect v2, Azure Kinect, MediaPipe Pose and MSR Action3D
  skeletons to the Kinect v1 layout of the models; :class:`SkeletonSource`
  is the interface of a source, :class:`ReplaySource` replays a recording,
  and :class:`UDPSource` (JSON datagrams), :class:`StdinSource` (CSV rows)
  and :class:`LSLSource` (Lab Streaming Layer) read a live stream.

See ``docs/streaming.md`` for the timing and the differences from offline
``predict``.
"""

# SPDX-License-Identifier: BSD-3-Clause

from skgesture.layouts import (
    AZURE_KINECT_JOINTS,
    KINECT_V2_JOINTS,
    MEDIAPIPE_POSE_LANDMARKS,
)
from skgesture.streaming._actions import (
    ActionDecision,
    ActionMap,
    CommandResult,
    GestureCommander,
    PickAndPlaceRobot,
    RobotCommand,
    RobotState,
    SimulatedRobot,
)
from skgesture.streaming._adapters import (
    AzureKinectAdapter,
    KinectV1Adapter,
    KinectV2Adapter,
    MediaPipePoseAdapter,
    MSRAction3DAdapter,
    SkeletonAdapter,
    get_adapter,
)
from skgesture.streaming._commands import (
    CommandEvent,
    CommandMap,
    JSONLinesPublisher,
    UDPPublisher,
)
from skgesture.streaming._recognizer import GestureEvent, StreamingRecognizer
from skgesture.streaming._sources import (
    LSLSource,
    ReplaySource,
    SkeletonSource,
    StdinSource,
    UDPSource,
)

__all__ = [
    "AZURE_KINECT_JOINTS",
    "KINECT_V2_JOINTS",
    "MEDIAPIPE_POSE_LANDMARKS",
    "ActionDecision",
    "ActionMap",
    "AzureKinectAdapter",
    "CommandEvent",
    "CommandMap",
    "CommandResult",
    "GestureCommander",
    "GestureEvent",
    "JSONLinesPublisher",
    "KinectV1Adapter",
    "KinectV2Adapter",
    "LSLSource",
    "MSRAction3DAdapter",
    "MediaPipePoseAdapter",
    "PickAndPlaceRobot",
    "ReplaySource",
    "RobotCommand",
    "RobotState",
    "SimulatedRobot",
    "SkeletonAdapter",
    "SkeletonSource",
    "StdinSource",
    "StreamingRecognizer",
    "UDPPublisher",
    "UDPSource",
    "get_adapter",
]
