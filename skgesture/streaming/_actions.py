"""From gesture events to robot commands: action map and pick-and-place robot.

The paper commands a collaborative robot with five gestures that drive a
pick-and-place task: move to the tool, close the gripper, carry the tool, open
the gripper, return home. :class:`ActionMap` turns gesture events into
commands (confidence floor, refractory period: one gesture, one command;
optionally an arming gesture before each command);
:class:`PickAndPlaceRobot` is the task's state machine, which refuses commands
out of order, with :class:`SimulatedRobot` as a ready-made implementation and
the place where a real robot plugs in (:meth:`PickAndPlaceRobot._perform`);
:class:`GestureCommander` wires a recogniser, a map, the state machine of a
:class:`~skgesture.streaming.CommandMap` (any vocabulary, ``_commands.py``), a
robot and the command publishers together.
"""

# SPDX-License-Identifier: BSD-3-Clause

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum
from numbers import Integral, Real

from skgesture.streaming._commands import (
    DEFAULT_ARMING_FRAMES,
    CommandEvent,
    CommandMap,
    resolve_classes,
)

__all__ = [
    "RobotCommand",
    "RobotState",
    "CommandResult",
    "PickAndPlaceRobot",
    "SimulatedRobot",
    "ActionDecision",
    "ActionMap",
    "GestureCommander",
]


class RobotCommand(str, Enum):
    """The five actions of the paper's pick-and-place task, in task order.

    Examples
    --------
    >>> from skgesture.streaming import RobotCommand
    >>> [str(c) for c in RobotCommand][:2]
    ['move_to_tool', 'close_gripper']
    >>> RobotCommand("carry_tool") is RobotCommand.CARRY_TOOL
    True
    """

    MOVE_TO_TOOL = "move_to_tool"
    CLOSE_GRIPPER = "close_gripper"
    CARRY_TOOL = "carry_tool"
    OPEN_GRIPPER = "open_gripper"
    RETURN_HOME = "return_home"

    def __str__(self):
        return self.value


class RobotState(str, Enum):
    """States of the pick-and-place cycle.

    Examples
    --------
    >>> from skgesture.streaming import RobotState, SimulatedRobot
    >>> SimulatedRobot().state is RobotState.HOME
    True
    """

    HOME = "home"  # gripper open, empty, at the home pose
    AT_TOOL = "at_tool"  # gripper open around the tool
    HOLDING = "holding"  # gripper closed on the tool, at its pick-up place
    CARRIED = "carried"  # tool held at its target place
    RELEASED = "released"  # tool left at the target, gripper open

    def __str__(self):
        return self.value


# The cycle: state -> (the one command accepted there, the state it leads to).
TRANSITIONS = {
    RobotState.HOME: (RobotCommand.MOVE_TO_TOOL, RobotState.AT_TOOL),
    RobotState.AT_TOOL: (RobotCommand.CLOSE_GRIPPER, RobotState.HOLDING),
    RobotState.HOLDING: (RobotCommand.CARRY_TOOL, RobotState.CARRIED),
    RobotState.CARRIED: (RobotCommand.OPEN_GRIPPER, RobotState.RELEASED),
    RobotState.RELEASED: (RobotCommand.RETURN_HOME, RobotState.HOME),
}
_HOLDS_TOOL = {RobotState.HOLDING, RobotState.CARRIED}

# Why a command is refused, for the cases worth a specific message.
_REASONS = {
    (RobotState.HOME, RobotCommand.RETURN_HOME): "already home",
    (RobotState.AT_TOOL, RobotCommand.MOVE_TO_TOOL): "already at the tool",
    (RobotState.HOLDING, RobotCommand.CLOSE_GRIPPER): "the gripper is already closed",
    (RobotState.CARRIED, RobotCommand.CARRY_TOOL): "the tool is already carried",
    (RobotState.CARRIED, RobotCommand.CLOSE_GRIPPER): "the gripper is already closed",
    (RobotState.RELEASED, RobotCommand.OPEN_GRIPPER): "the gripper is already open",
    (RobotState.HOME, RobotCommand.CLOSE_GRIPPER): "the gripper is not at the tool",
    (RobotState.RELEASED, RobotCommand.CLOSE_GRIPPER): "the gripper is not at the tool",
    (RobotState.HOLDING, RobotCommand.OPEN_GRIPPER):
        "the tool has not been carried to its target yet",
}  # fmt: skip


def _refusal(state, command):
    if (state, command) in _REASONS:
        return _REASONS[(state, command)]
    if command is RobotCommand.OPEN_GRIPPER and state not in _HOLDS_TOOL:
        return "the gripper holds nothing"
    if command is RobotCommand.CARRY_TOOL and state not in _HOLDS_TOOL:
        return "no tool is held"
    if state in _HOLDS_TOOL:
        return f"a tool is held: {TRANSITIONS[state][0]} comes next"
    return f"out of order: {TRANSITIONS[state][0]} comes next in state {state}"


@dataclass(frozen=True)
class CommandResult:
    """What a robot did with one command.

    Parameters
    ----------
    command : RobotCommand or object
        The command.
    accepted : bool
        Whether it was executed.
    state_before, state_after : RobotState, str or None
        Robot state around it (equal when refused); for a result made by a
        :class:`GestureCommander` (no robot, or a command its state machine
        rejected), the commander's state (None without a state machine).
    reason : str
        ``"ok"`` or why it was refused.
    frame : int or None, default=None
        Stream frame at which it was issued.

    Examples
    --------
    >>> from skgesture.streaming import SimulatedRobot
    >>> result = SimulatedRobot().execute("close_gripper", frame=40)
    >>> result.accepted, result.reason, result.frame
    (False, 'the gripper is not at the tool', 40)
    """

    command: RobotCommand
    accepted: bool
    state_before: RobotState
    state_after: RobotState
    reason: str
    frame: int | None = None


class PickAndPlaceRobot(ABC):
    """The paper's pick-and-place task as a state machine; subclass per robot.

    ``home -> at_tool -> holding -> carried -> released -> home`` through
    ``move_to_tool``, ``close_gripper``, ``carry_tool``, ``open_gripper`` and
    ``return_home``. :meth:`execute` accepts only the next command of the cycle:
    any other is refused with a reason (e.g. opening a gripper that holds
    nothing), the state does not change and the refusal is logged.

    To drive a real robot, subclass and implement :meth:`_perform` with the
    vendor's API (move to a taught pose, close/open the gripper); raise an
    exception there to refuse a command the hardware could not carry out. The
    state machine, the refusals and the log stay the same.

    Attributes
    ----------
    state : RobotState
        Current state.
    log : list of CommandResult
        Every command received, accepted or not.

    Examples
    --------
    >>> from skgesture.streaming import PickAndPlaceRobot
    >>> class PrintingRobot(PickAndPlaceRobot):
    ...     def _perform(self, command):
    ...         print("robot:", command)
    >>> robot = PrintingRobot()
    >>> robot.execute("move_to_tool").state_after.value
    robot: move_to_tool
    'at_tool'
    """

    def __init__(self):
        self.state = RobotState.HOME
        self.log = []

    def execute(self, command, frame=None):
        """Carry out ``command`` if it is the next step of the task.

        Parameters
        ----------
        command : RobotCommand or str
            The command (``"open_gripper"`` works too).
        frame : int or None, default=None
            Stream frame, kept in the log.

        Returns
        -------
        CommandResult
            Accepted or refused, with the reason.
        """
        command = RobotCommand(command)
        before = self.state
        expected, after = TRANSITIONS[before]
        if command is not expected:
            result = CommandResult(
                command, False, before, before, _refusal(before, command), frame
            )
        else:
            try:
                self._perform(command)
            except Exception as exc:  # the hardware refused: state unchanged
                result = CommandResult(
                    command, False, before, before, f"robot error: {exc}", frame
                )
            else:
                self.state = after
                result = CommandResult(command, True, before, after, "ok", frame)
        self.log.append(result)
        return result

    @property
    def holding(self):
        """Whether the gripper holds the tool."""
        return self.state in _HOLDS_TOOL

    def status(self):
        """Current state in words.

        Returns
        -------
        dict
            ``state``, ``next_command``, ``gripper`` (``"open"``/``"closed"``),
            ``holding`` (bool), ``n_accepted`` and ``n_refused``.
        """
        n_ok = sum(r.accepted for r in self.log)
        return {
            "state": self.state.value,
            "next_command": TRANSITIONS[self.state][0].value,
            "gripper": "closed" if self.holding else "open",
            "holding": self.holding,
            "n_accepted": n_ok,
            "n_refused": len(self.log) - n_ok,
        }

    def reset(self):
        """Back to ``home`` with an empty log (the simulated robot only)."""
        self.state = RobotState.HOME
        self.log = []

    @abstractmethod
    def _perform(self, command):
        """Make the robot do ``command`` (called only for an in-order command)."""


class SimulatedRobot(PickAndPlaceRobot):
    """A pick-and-place robot that only records what it would do.

    Examples
    --------
    >>> from skgesture.streaming import SimulatedRobot
    >>> robot = SimulatedRobot()
    >>> robot.execute("open_gripper").reason
    'the gripper holds nothing'
    >>> [robot.execute(c).accepted for c in ("move_to_tool", "close_gripper")]
    [True, True]
    >>> robot.status()["state"], robot.status()["gripper"], robot.status()["n_refused"]
    ('holding', 'closed', 1)
    """

    def __init__(self):
        super().__init__()
        self.actions = []

    def _perform(self, command):
        self.actions.append(command)

    def reset(self):
        """Back to ``home`` with empty logs."""
        super().reset()
        self.actions = []


@dataclass(frozen=True)
class ActionDecision:
    """What an :class:`ActionMap` made of one gesture event.

    Parameters
    ----------
    event : GestureEvent
        The event.
    command : object or None
        The command issued, None when the event was ignored.
    reason : str
        ``"issued"`` or why the event was ignored.

    Examples
    --------
    >>> from skgesture.streaming import ActionMap, GestureEvent
    >>> ev = GestureEvent(label=2, start=0, end=30, confidence=0.9, emitted_at=42)
    >>> decision = ActionMap({1: "move_to_tool"}).decide(ev)
    >>> decision.issued, decision.reason
    (False, 'class 2 has no command')
    """

    event: object
    command: object
    reason: str

    @property
    def issued(self):
        """Whether a command was issued."""
        return self.command is not None


class ActionMap:
    """Maps gesture classes to commands, once per gesture.

    An event is turned into its class's command when its confidence is a
    number that reaches ``min_confidence`` (a NaN or infinite confidence never
    does) and no command was issued in the last ``refractory_frames`` frames
    (counted between the frames at which the events were emitted), so that
    one gesture, even if it is recognised as two overlapping events, gives
    one command.

    With an arming gesture (``arming_class``), as human-robot interfaces use
    an attention gesture, a command is accepted only if it is emitted within
    ``arming_frames`` frames after the event of the arming gesture, and if
    its gesture starts after the arming gesture ended (an overlapping event
    is the same motion recognised twice). The arming gesture gives no command
    itself: it is an error to map its class too. It arms when its confidence
    reaches ``min_confidence``; the refractory period does not apply to it,
    and a new arming gesture restarts the window. With ``disarm_on_command``
    (the default) the command issued disarms the map: one arming gesture,
    one command, even when the state machine or the robot then refuses the
    command. Otherwise every command in the window is accepted (each subject
    to the refractory period). The arming protects against commands given by
    chance; the model must still reject motion that is not a gesture.

    The classes are checked against a model by :meth:`bind`, which
    :class:`GestureCommander` calls with its recogniser's classes: a class the
    model does not have, or one given twice, is an error then; so is an
    arming class the model does not have.

    Parameters
    ----------
    mapping : dict or CommandMap
        ``{gesture class: command}``. A class is its label (an int >= 1, as in
        ``y``) or its name (a str): names are turned into labels with
        ``target_names`` when given, else matched against the ``name`` of each
        event (set when the recogniser has ``target_names``). Commands are
        :class:`RobotCommand` values (strings such as ``"close_gripper"`` are
        converted) or any object for other programs. A :class:`CommandMap`
        (e.g. read from a file) gives its commands and its state machine,
        which :class:`GestureCommander` enforces.
    min_confidence : float, default=0.0
        Confidence floor, in [0, 1].
    refractory_frames : int, default=0
        Frames after an issued command during which events are ignored.
    target_names : sequence of str or None, default=None
        ``target_names[k - 1]`` names class ``k`` (as the dataset loaders'
        ``target_names``), to write ``mapping`` with class names.
    arming_class : int, str or None, default=None
        The arming gesture's class, a label or a name as in ``mapping``; None
        (and no ``arming`` in the :class:`CommandMap`): every command is
        accepted without arming, as before.
    arming_frames : int or None, default=None
        Frames after the arming gesture's event in which a command is
        accepted (counted between emission frames); None: 90 (3 s at 30 fps),
        or the command map's.
    disarm_on_command : bool or None, default=None
        Whether an issued command disarms the map; None: True, or the command
        map's. Given with a command map that sets ``arming``, these three are
        an error (set the arming in one place).

    Attributes
    ----------
    mapping : dict
        ``{label: command}`` for the classes given as labels or named through
        ``target_names``, ``{name: command}`` for names matched at decision
        time (until :meth:`bind` resolves them).
    command_map : CommandMap or None
        The map given as ``mapping`` (bound by :meth:`bind`), else None.
    arming_class : int, str or None
        The arming gesture's label (its name, until :meth:`bind` resolves a
        name), or None without arming.
    arming_frames : int
        The arming window, in frames.
    disarm_on_command : bool
        Whether an issued command disarms the map.
    armed_at : int or None
        Emission frame of the arming event that armed the map; None before
        any, or after a command disarmed it (see :meth:`is_armed`).

    Examples
    --------
    >>> from skgesture.streaming import ActionMap, GestureEvent
    >>> amap = ActionMap({1: "move_to_tool", 2: "close_gripper"},
    ...                  min_confidence=0.7, refractory_frames=20)
    >>> ev = GestureEvent(label=1, start=0, end=40, confidence=0.9, emitted_at=52)
    >>> str(amap.decide(ev).command)
    'move_to_tool'
    >>> late = GestureEvent(label=2, start=30, end=50, confidence=0.95, emitted_at=62)
    >>> amap.decide(late).reason
    'refractory: 10 frames after the last command (< 20)'
    >>> names = ["wave", "point"]
    >>> by_name = ActionMap({"point": "carry_tool"}, target_names=names)
    >>> by_name.mapping
    {2: <RobotCommand.CARRY_TOOL: 'carry_tool'>}

    With an arming gesture (class 5), a command counts only in the 90 frames
    after it:

    >>> armed = ActionMap({1: "move_to_tool"}, arming_class=5, arming_frames=90)
    >>> armed.decide(GestureEvent(1, 0, 30, 0.9, emitted_at=40)).reason
    'not armed: the arming gesture (class 5) comes first'
    >>> armed.decide(GestureEvent(5, 50, 80, 0.9, emitted_at=90)).reason
    'armed: a command is accepted for 90 frames'
    >>> str(armed.decide(GestureEvent(1, 100, 130, 0.9, emitted_at=140)).command)
    'move_to_tool'
    >>> armed.decide(GestureEvent(1, 150, 180, 0.9, emitted_at=190)).reason
    'not armed: the arming gesture (class 5) comes first'
    """

    def __init__(self, mapping, *, min_confidence=0.0, refractory_frames=0,
                 target_names=None, arming_class=None, arming_frames=None,
                 disarm_on_command=None):  # fmt: skip
        if (
            isinstance(min_confidence, bool)
            or not isinstance(min_confidence, Real)
            or not 0 <= min_confidence <= 1
        ):
            raise ValueError(
                f"min_confidence must be a number in [0, 1], got {min_confidence!r}"
            )
        if (
            isinstance(refractory_frames, bool)
            or not isinstance(refractory_frames, Integral)
            or refractory_frames < 0
        ):
            raise ValueError(
                "refractory_frames must be a non-negative int, got "
                f"{refractory_frames!r}"
            )
        self.command_map = None
        if isinstance(mapping, CommandMap):
            self.command_map = mapping
            mapping = mapping.mapping if mapping.bound else mapping.commands
        if not isinstance(mapping, Mapping):
            raise TypeError(
                "mapping must be a dict {gesture class: command}, got "
                f"{type(mapping).__name__}"
            )
        if target_names is not None and (
            isinstance(target_names, str)
            or not all(isinstance(n, str) for n in target_names)
        ):
            raise TypeError(
                f"target_names must be a sequence of class names, got {target_names!r}"
            )
        self.target_names = None if target_names is None else list(target_names)
        self.mapping = {}
        for key, command in mapping.items():
            if self.command_map is not None and isinstance(key, str):
                key = int(key) if key.strip().isdecimal() else key.strip()
            cls = self._class_key(key)
            if cls in self.mapping:
                raise ValueError(
                    f"gesture class {key!r} is mapped twice (as {cls!r}); give one "
                    f"command per class"
                )
            self.mapping[cls] = _as_command(command)
        self.min_confidence = min_confidence
        self.refractory_frames = refractory_frames
        self._init_arming(arming_class, arming_frames, disarm_on_command)
        self.reset()

    def _init_arming(self, arming_class, arming_frames, disarm_on_command):
        """Check and set the arming parameters (or the command map's)."""
        if arming_frames is not None and (
            isinstance(arming_frames, bool)
            or not isinstance(arming_frames, Integral)
            or arming_frames < 1
        ):
            raise ValueError(
                f"arming_frames must be a positive int or None, got {arming_frames!r}"
            )
        if disarm_on_command is not None and not isinstance(disarm_on_command, bool):
            raise ValueError(
                f"disarm_on_command must be a bool or None, got {disarm_on_command!r}"
            )
        given = {
            "arming_class": arming_class,
            "arming_frames": arming_frames,
            "disarm_on_command": disarm_on_command,
        }
        given = [k for k, v in given.items() if v is not None]
        cmap = self.command_map
        if cmap is not None and getattr(cmap, "arming", None) is not None:
            if given:
                raise ValueError(
                    f"{', '.join(given)} given, but the command map sets the arming "
                    f"gesture already ({cmap.arming!r}): set it in one place"
                )
            arming = cmap.arming
            arming_class = cmap.arming_label if cmap.bound else arming["class"]
            arming_frames = arming["frames"]
            disarm_on_command = arming["disarm_on_command"]
        elif arming_class is None and given:
            raise ValueError(
                f"{', '.join(given)} given without arming_class: name the arming "
                f"gesture"
            )
        self.arming_frames = (
            DEFAULT_ARMING_FRAMES if arming_frames is None else int(arming_frames)
        )
        self.disarm_on_command = (
            True if disarm_on_command is None else disarm_on_command
        )
        self.arming_class = None
        if arming_class is not None:
            try:
                cls = self._class_key(arming_class)
            except (TypeError, ValueError) as exc:
                raise type(exc)(f"arming_class: {exc}") from None
            self._check_arming_unmapped(cls)
            self.arming_class = cls

    def _check_arming_unmapped(self, cls):
        if cls in self.mapping:
            raise ValueError(
                f"arming_class {cls!r} also gives the command "
                f"{str(self.mapping[cls])!r}: the arming gesture gives no command; "
                f"remove it from the mapping"
            )

    def _class_key(self, key):
        """A key of ``mapping`` as a label (int >= 1) or a name to match."""
        if isinstance(key, str):
            if self.target_names is None:
                return key  # matched against event.name
            if key not in self.target_names:
                raise ValueError(
                    f"unknown gesture class name {key!r}; target_names has "
                    f"{self.target_names}"
                )
            return self.target_names.index(key) + 1
        if isinstance(key, bool) or not isinstance(key, Integral):
            raise TypeError(
                f"a gesture class must be a label (int >= 1) or a class name (str), "
                f"got {key!r} of type {type(key).__name__}"
            )
        if key < 1:
            raise ValueError(
                f"gesture class {key!r} cannot command anything: labels start at 1 "
                f"(0 is rest)"
            )
        if self.target_names is not None and key > len(self.target_names):
            raise ValueError(
                f"gesture class {key} is beyond target_names "
                f"({len(self.target_names)} classes)"
            )
        return int(key)

    def bind(self, classes, target_names=None):
        """Check the mapping against a model's classes; resolve class names.

        Parameters
        ----------
        classes : array-like of int
            The model's gesture classes (``recognizer.classes_``).
        target_names : sequence of str or None, default=None
            The model's class names; defaults to the map's ``target_names``.

        Returns
        -------
        ActionMap
            ``self``, with :attr:`mapping` ``{label: command}``.

        Raises
        ------
        ValueError
            For a class the model does not have (a number not among
            ``classes``, a name not in ``target_names`` or a name without
            them) and for a class given twice (by name and by number).

        Examples
        --------
        >>> from skgesture.streaming import ActionMap
        >>> ActionMap({1: "move_to_tool", 9: "beep"}).bind([1, 2, 3, 4])
        Traceback (most recent call last):
        ...
        ValueError: mapping[9]: class 9 is not a class of the model (its \
classes are 1, 2, 3, 4)
        """
        names = self.target_names if target_names is None else list(target_names)
        if self.command_map is not None:
            self.command_map = self.command_map.bind(classes, names)
            self.mapping = {
                k: _as_command(c) for k, c in self.command_map.mapping.items()
            }
        else:
            entries = [(k, k, c) for k, c in self.mapping.items()]
            self.mapping = resolve_classes(entries, classes, names)
        if self.command_map is not None and self.command_map.arming is not None:
            self.arming_class = self.command_map.arming_label
        elif self.arming_class is not None:
            key = self.arming_class
            (self.arming_class,) = resolve_classes(
                [(key, key, None)], classes, names, where=lambda k: "arming_class"
            )
            self._check_arming_unmapped(self.arming_class)
        return self

    def reset(self):
        """Forget the last issued command and disarm."""
        self._last_issued = None
        self.armed_at = None
        self._armed_end = None

    def is_armed(self, frame):
        """Whether a command emitted at ``frame`` would be in the arming window.

        Parameters
        ----------
        frame : int
            A stream frame (e.g. the current one, to show the operator that
            the robot listens).

        Returns
        -------
        bool
            Always True without an arming gesture.
        """
        if self.arming_class is None:
            return True
        return self.armed_at is not None and (
            0 <= frame - self.armed_at <= self.arming_frames
        )

    def decide(self, event):
        """The command for one event, or why there is none.

        Parameters
        ----------
        event : GestureEvent
            A recognised gesture.

        Returns
        -------
        ActionDecision
            With ``command`` None when the event is ignored.
        """
        for attr in ("label", "confidence", "emitted_at"):
            if not hasattr(event, attr):
                raise TypeError(
                    f"ActionMap.decide takes a GestureEvent (label, confidence, "
                    f"emitted_at), got {type(event).__name__}"
                )
        name = getattr(event, "name", None)
        arming = self.arming_class is not None and self.arming_class in (
            int(event.label), name
        )  # fmt: skip
        command = None
        if not arming:  # the arming gesture gives no command
            command = self.mapping.get(int(event.label))
            if command is None and name is not None:
                command = self.mapping.get(name)
            if command is None:
                what = f"class {event.label}" + (f" ({name})" if name else "")
                return ActionDecision(event, None, f"{what} has no command")
        refused = self._refuse_confidence(event.confidence)
        if refused:
            return ActionDecision(event, None, refused)
        if arming:
            self.armed_at = event.emitted_at
            self._armed_end = getattr(event, "end", None)
            return ActionDecision(
                event, None,
                f"armed: a command is accepted for {self.arming_frames} frames",
            )  # fmt: skip
        if self._last_issued is not None:
            gap = event.emitted_at - self._last_issued
            if gap < self.refractory_frames:
                return ActionDecision(
                    event, None,
                    f"refractory: {gap} frames after the last command "
                    f"(< {self.refractory_frames})",
                )  # fmt: skip
        if self.arming_class is not None:
            refused = self._refuse_unarmed(event)
            if refused:
                return ActionDecision(event, None, refused)
            if self.disarm_on_command:
                self.armed_at = self._armed_end = None
        self._last_issued = event.emitted_at
        return ActionDecision(event, command, "issued")

    __call__ = decide

    def _refuse_confidence(self, confidence):
        """Why ``confidence`` issues nothing, or None."""
        try:
            number = isinstance(confidence, Real) and math.isfinite(confidence)
        except TypeError:
            number = False
        if not number:
            return f"confidence {confidence!r} is not a finite number"
        if not confidence >= self.min_confidence:
            return f"confidence {confidence:.2f} < {self.min_confidence:g}"
        return None

    def _refuse_unarmed(self, event):
        """Why a command event is outside the arming window, or None."""
        if self.armed_at is None:
            return (
                f"not armed: the arming gesture (class {self.arming_class}) comes first"
            )
        gap = event.emitted_at - self.armed_at
        if gap > self.arming_frames:
            return (
                f"not armed: {gap} frames after the arming gesture "
                f"(> {self.arming_frames})"
            )
        start = getattr(event, "start", None)
        if self._armed_end is not None and start is not None:
            if start < self._armed_end:
                return (
                    f"not armed: the gesture starts at frame {start}, before the "
                    f"arming gesture ended (frame {self._armed_end})"
                )
        return None


def _as_command(value):
    try:
        return RobotCommand(value)
    except ValueError:
        return value


class GestureCommander:
    """Recogniser -> action map -> state machine -> robot and publishers.

    Every event of the recogniser goes through the action map (confidence
    floor, refractory period, arming gesture). An issued command is then
    checked against the state machine of the map's :class:`CommandMap`, if it
    has one: a command that is not valid in the current state is rejected
    (neither executed nor published) and counted in :attr:`n_rejected`. It
    is executed by the robot, if there is one (which may refuse it too), and,
    once carried out, the state machine moves on and a :class:`CommandEvent`
    goes to every ``on_command`` callback.

    Parameters
    ----------
    recognizer : StreamingRecognizer
        Gives gesture events.
    action_map : ActionMap or CommandMap
        Turns them into commands; a :class:`CommandMap` is used as
        ``ActionMap(command_map)`` (no floor, no refractory period). When the
        recogniser has ``classes_`` (a :class:`StreamingRecognizer` does), the
        map is bound to them and to its ``target_names``
        (:meth:`ActionMap.bind`): a class the model does not have, or one
        given twice, is a ValueError here rather than a gesture that never
        commands anything.
    robot : PickAndPlaceRobot or None, default=None
        Executes the commands; None when the commands are only published.
    on_command : callable, sequence of callable or None, default=None
        Called with the :class:`CommandEvent` of every command carried out:
        a :class:`JSONLinesPublisher`, a :class:`UDPPublisher` or any
        function.
    fps : float or None, default=None
        Frame rate of the stream, for :attr:`CommandEvent.time`.

    Attributes
    ----------
    log : list of tuple
        ``(decision, result)`` for every event: the :class:`ActionDecision`
        and the :class:`CommandResult` (None when no command was issued). A
        command the state machine rejects has a result made here, with
        ``accepted`` False, the commander's states and the reason; otherwise
        the result is the robot's, or, without a robot, one that accepts.
    state : str or None
        Current state of the map's state machine (None without one).
    n_rejected : int
        Commands rejected by the state machine.
    published : list of CommandEvent
        Every command carried out, as published.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn.linear_model import LogisticRegression
    >>> from skgesture import make_method_a
    >>> from skgesture.datasets import make_gesture_streams
    >>> from skgesture.streaming import (ActionMap, GestureCommander,
    ...                                  SimulatedRobot, StreamingRecognizer)
    >>> data = make_gesture_streams(n_sequences=4, n_classes=3, random_state=0)
    >>> pipe = make_method_a(random_state=0).set_params(
    ...     segmenter__estimator=LogisticRegression(),
    ...     classifier__estimator=LogisticRegression()).fit(data.X[:3], data.y[:3])
    >>> commander = GestureCommander(
    ...     StreamingRecognizer(pipe), ActionMap({1: "move_to_tool"}),
    ...     SimulatedRobot())
    >>> log = commander.run(data.X[3])
    >>> all(result is None or result.command == "move_to_tool"
    ...     for _, result in log)
    True

    Without a robot, with a state machine and a callback:

    >>> from skgesture.streaming import CommandMap, GestureEvent
    >>> cmap = CommandMap({1: "pick", 2: "place"},
    ...                   states={"idle": {"pick": "holding"},
    ...                           "holding": {"place": "idle"}}, initial="idle")
    >>> class Events:  # a stand-in recogniser that gives one event per frame
    ...     def push(self, label):
    ...         return [GestureEvent(label, 0, 10, 0.9, emitted_at=20)]
    ...     def flush(self):
    ...         return []
    >>> commander = GestureCommander(
    ...     Events(), cmap, on_command=lambda ev: print(ev.command, "->", ev.state))
    >>> _ = commander.run([1, 1, 2])
    pick -> holding
    place -> idle
    >>> commander.n_rejected, commander.log[1][1].reason
    (1, "'pick' is not valid in state 'holding' (valid there: place)")
    """

    def __init__(
        self, recognizer, action_map, robot=None, *, on_command=None, fps=None
    ):
        if isinstance(action_map, CommandMap):
            action_map = ActionMap(action_map)
        for arg, value, methods, kind in (
            ("recognizer", recognizer, ("push", "flush"), "a StreamingRecognizer"),
            ("action_map", action_map, ("decide",), "an ActionMap"),
            ("robot", robot, ("execute",), "a PickAndPlaceRobot or None"),
        ):
            if arg == "robot" and value is None:
                continue
            if not all(callable(getattr(value, m, None)) for m in methods):
                raise TypeError(
                    f"GestureCommander: {arg} must be {kind} (with "
                    f"{', '.join(m + '()' for m in methods)}), got "
                    f"{type(value).__name__}"
                )
        if on_command is None:
            callbacks = []
        elif callable(on_command):
            callbacks = [on_command]
        else:
            callbacks = list(on_command) if isinstance(on_command, list | tuple) else []
            if not callbacks or not all(callable(c) for c in callbacks):
                raise TypeError(
                    "GestureCommander: on_command must be a callable (e.g. a "
                    "JSONLinesPublisher), a list of callables or None, got "
                    f"{on_command!r}"
                )
        if fps is not None and (
            isinstance(fps, bool) or not isinstance(fps, Real) or not fps > 0
        ):
            raise ValueError(f"fps must be a positive number or None, got {fps!r}")
        classes = getattr(recognizer, "classes_", None)
        if classes is not None and callable(getattr(action_map, "bind", None)):
            action_map.bind(classes, getattr(recognizer, "target_names", None))
        self.recognizer = recognizer
        self.action_map = action_map
        self.robot = robot
        self.on_command = callbacks
        self.fps = fps
        self.reset()

    @property
    def command_map(self):
        """The action map's :class:`CommandMap`, or None."""
        return getattr(self.action_map, "command_map", None)

    def reset(self):
        """Back to the initial state, with an empty log.

        The recogniser and the robot are left as they are (they have their own
        ``reset``).
        """
        cmap = self.command_map
        self.state = None if cmap is None else cmap.initial
        self.n_rejected = 0
        self.published = []
        self.log = []
        if callable(getattr(self.action_map, "reset", None)):
            self.action_map.reset()

    def push(self, frame):
        """Push one frame; act on the events it completes.

        Parameters
        ----------
        frame : array-like of shape (20, 3)
            Kinect v1 frame.

        Returns
        -------
        list of tuple
            New ``(decision, result)`` pairs.
        """
        return self._act(self.recognizer.push(frame))

    def flush(self):
        """End the stream and act on the last events.

        Returns
        -------
        list of tuple
            New ``(decision, result)`` pairs.
        """
        return self._act(self.recognizer.flush())

    def run(self, source):
        """Act on every frame of a source, then flush.

        Parameters
        ----------
        source : iterable of ndarray of shape (20, 3)
            A :class:`SkeletonSource` or any iterable of Kinect v1 frames.

        Returns
        -------
        list of tuple
            The whole :attr:`log`.
        """
        for frame in source:
            self.push(frame)
        self.flush()
        return self.log

    def _act(self, events):
        out = []
        for event in events:
            decision = self.action_map.decide(event)
            result = None
            if decision.issued:
                result = self._command(event, decision.command)
            out.append((decision, result))
        self.log += out
        return out

    def _command(self, event, command):
        frame = event.emitted_at
        cmap, before = self.command_map, self.state
        after = None
        if cmap is not None and cmap.states is not None:
            after = cmap.next_state(before, command)
            if after is None:
                self.n_rejected += 1
                valid = cmap.allowed(before)
                where = (
                    f"valid there: {', '.join(valid)}" if valid
                    else "no command is valid there"
                )  # fmt: skip
                reason = f"{str(command)!r} is not valid in state {before!r} ({where})"
                return CommandResult(command, False, before, before, reason, frame)
        if self.robot is None:
            result = CommandResult(command, True, before, after, "ok", frame)
        else:
            result = self.robot.execute(command, frame=frame)
            if not result.accepted:
                return result
        if after is not None:
            self.state = after
        published = CommandEvent.from_gesture(
            event, command, fps=self.fps, state=after, previous=before
        )
        self.published.append(published)
        for callback in self.on_command:
            callback(published)
        return result
