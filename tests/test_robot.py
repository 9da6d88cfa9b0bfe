"""Action map, pick-and-place robot and the commander wiring them to events."""

import pytest

from skgesture.streaming import (
    ActionMap,
    GestureCommander,
    GestureEvent,
    PickAndPlaceRobot,
    RobotCommand,
    RobotState,
    SimulatedRobot,
)

CYCLE = [
    ("move_to_tool", "at_tool"),
    ("close_gripper", "holding"),
    ("carry_tool", "carried"),
    ("open_gripper", "released"),
    ("return_home", "home"),
]


def _event(label, emitted_at, confidence=0.9):
    return GestureEvent(
        label=label,
        start=emitted_at - 40,
        end=emitted_at - 12,
        confidence=confidence,
        emitted_at=emitted_at,
    )


def test_full_cycle_is_accepted_in_order():
    robot = SimulatedRobot()
    for command, state in CYCLE * 2:
        result = robot.execute(command, frame=7)
        assert result.accepted and result.reason == "ok" and result.frame == 7
        assert robot.state == RobotState(state) == result.state_after
    assert robot.actions == [RobotCommand(c) for c, _ in CYCLE] * 2
    assert robot.status() == {
        "state": "home", "next_command": "move_to_tool", "gripper": "open",
        "holding": False, "n_accepted": 10, "n_refused": 0,
    }  # fmt: skip


@pytest.mark.parametrize(
    "prefix, command, reason",
    [
        (0, "open_gripper", "the gripper holds nothing"),
        (0, "carry_tool", "no tool is held"),
        (0, "return_home", "already home"),
        (0, "close_gripper", "the gripper is not at the tool"),
        (1, "move_to_tool", "already at the tool"),
        (1, "open_gripper", "the gripper holds nothing"),
        (2, "open_gripper", "the tool has not been carried to its target yet"),
        (2, "close_gripper", "the gripper is already closed"),
        (2, "return_home", "a tool is held: carry_tool comes next"),
        (3, "move_to_tool", "a tool is held: open_gripper comes next"),
        (4, "open_gripper", "the gripper is already open"),
        (4, "move_to_tool", "out of order: return_home comes next in state released"),
    ],
)
def test_out_of_order_commands_are_refused_and_logged(prefix, command, reason):
    robot = SimulatedRobot()
    for c, _ in CYCLE[:prefix]:
        robot.execute(c)
    before = robot.state
    result = robot.execute(command)
    assert not result.accepted
    assert result.reason == reason
    assert robot.state is before is result.state_before is result.state_after
    assert robot.log[-1] is result
    assert robot.status()["n_refused"] == 1
    assert len(robot.actions) == prefix  # nothing was done


def test_unknown_command_raises():
    with pytest.raises(ValueError):
        SimulatedRobot().execute("dance")


def test_a_real_robot_plugs_in_through_perform():
    class FlakyGripper(PickAndPlaceRobot):
        def __init__(self):
            super().__init__()
            self.calls = []

        def _perform(self, command):
            self.calls.append(command)
            if command is RobotCommand.CLOSE_GRIPPER:
                raise RuntimeError("gripper jammed")

    robot = FlakyGripper()
    assert robot.execute("move_to_tool").accepted
    result = robot.execute("close_gripper")
    assert not result.accepted and result.reason == "robot error: gripper jammed"
    assert robot.state is RobotState.AT_TOOL and not robot.holding
    assert robot.calls == [RobotCommand.MOVE_TO_TOOL, RobotCommand.CLOSE_GRIPPER]


def test_action_map_confidence_floor_refractory_and_unmapped():
    amap = ActionMap(
        {1: "move_to_tool", 2: RobotCommand.CLOSE_GRIPPER, 3: "beep"},
        min_confidence=0.6,
        refractory_frames=30,
    )
    assert amap.mapping[1] is RobotCommand.MOVE_TO_TOOL
    assert amap.mapping[3] == "beep"  # any command for other programs
    low = amap.decide(_event(1, 100, confidence=0.5))
    assert not low.issued and low.reason == "confidence 0.50 < 0.6"
    first = amap.decide(_event(1, 110))
    assert first.issued and first.command is RobotCommand.MOVE_TO_TOOL
    # A second event from the same gesture (or too soon after it) is ignored.
    echo = amap.decide(_event(2, 139))
    assert not echo.issued
    assert echo.reason == "refractory: 29 frames after the last command (< 30)"
    assert amap(_event(2, 140)).command is RobotCommand.CLOSE_GRIPPER
    unmapped = amap.decide(_event(9, 400))
    assert not unmapped.issued and unmapped.reason == "class 9 has no command"
    amap.reset()
    assert amap.decide(_event(1, 141)).issued
    with pytest.raises(ValueError, match="min_confidence"):
        ActionMap({}, min_confidence=2)
    with pytest.raises(ValueError, match="refractory_frames"):
        ActionMap({}, refractory_frames=-1)


class _ScriptedRecognizer:
    """Returns prepared events at given frames (a stand-in for the recogniser)."""

    def __init__(self, events):
        self.events = events
        self.t = -1

    def push(self, frame):
        self.t += 1
        return [ev for ev in self.events if ev.emitted_at == self.t]

    def flush(self):
        return [ev for ev in self.events if ev.emitted_at > self.t]


def test_commander_drives_the_robot_from_events():
    events = [
        _event(1, 50),  # move_to_tool
        _event(3, 60),  # open_gripper: refused, holds nothing (refractory 0)
        _event(2, 100),  # close_gripper
        _event(2, 105, confidence=0.3),  # below the floor
        _event(4, 150),  # carry_tool
        _event(3, 200),  # open_gripper
        _event(5, 260),  # return_home, decided at flush
    ]
    amap = ActionMap(
        {
            1: "move_to_tool",
            2: "close_gripper",
            4: "carry_tool",
            3: "open_gripper",
            5: "return_home",
        },
        min_confidence=0.5,
    )
    robot = SimulatedRobot()
    commander = GestureCommander(_ScriptedRecognizer(events), amap, robot)
    log = commander.run([None] * 240)
    assert len(log) == len(events)
    issued = [
        (d.event.emitted_at, str(d.command), r.accepted, r.reason)
        for d, r in log
        if d.issued
    ]
    assert issued == [
        (50, "move_to_tool", True, "ok"),
        (60, "open_gripper", False, "the gripper holds nothing"),
        (100, "close_gripper", True, "ok"),
        (150, "carry_tool", True, "ok"),
        (200, "open_gripper", True, "ok"),
        (260, "return_home", True, "ok"),
    ]
    ignored = [d.reason for d, r in log if not d.issued]
    assert ignored == ["confidence 0.30 < 0.5"] and robot.state is RobotState.HOME
    assert [r.frame for r in robot.log] == [50, 60, 100, 150, 200, 260]


@pytest.mark.parametrize("confidence", [float("nan"), float("inf"), -float("inf")])
@pytest.mark.parametrize("floor", [0.0, 0.5, 1.0])
def test_a_non_finite_confidence_never_issues_a_command(confidence, floor):
    amap = ActionMap({1: "move_to_tool"}, min_confidence=floor)
    decision = amap.decide(_event(1, 80, confidence=confidence))
    assert not decision.issued
    assert decision.reason == f"confidence {confidence!r} is not a finite number"
    assert amap.decide(_event(1, 81, confidence=1.0)).issued  # nothing else changed


def test_action_map_takes_class_names():
    names = ["wave", "point", "grab"]
    amap = ActionMap({"point": "close_gripper", 3: "carry_tool"}, target_names=names)
    assert amap.mapping == {
        2: RobotCommand.CLOSE_GRIPPER, 3: RobotCommand.CARRY_TOOL
    }  # fmt: skip
    assert amap.decide(_event(2, 50)).command is RobotCommand.CLOSE_GRIPPER
    # Without target_names a name is matched against the event's name.
    by_event = ActionMap({"wave": "move_to_tool"})
    named = GestureEvent(label=1, start=0, end=9, confidence=0.9, emitted_at=20,
                         name="wave")  # fmt: skip
    assert by_event.decide(named).command is RobotCommand.MOVE_TO_TOOL
    unnamed = by_event.decide(_event(1, 30))
    assert not unnamed.issued and unnamed.reason == "class 1 has no command"
    with pytest.raises(ValueError, match="unknown gesture class name 'jump'"):
        ActionMap({"jump": "move_to_tool"}, target_names=names)
    with pytest.raises(ValueError, match="beyond target_names"):
        ActionMap({4: "move_to_tool"}, target_names=names)
    with pytest.raises(ValueError, match="mapped twice"):
        ActionMap({"wave": "move_to_tool", 1: "beep"}, target_names=names)
    with pytest.raises(ValueError, match="0 is rest"):
        ActionMap({0: "move_to_tool"})
    with pytest.raises(TypeError, match="label .*or a class name"):
        ActionMap({1.5: "move_to_tool"})
    with pytest.raises(TypeError, match="mapping must be a dict"):
        ActionMap([(1, "move_to_tool")])
    with pytest.raises(TypeError, match="GestureEvent"):
        ActionMap({1: "beep"}).decide("wave")


def test_commander_refuses_the_wrong_objects():
    amap, robot = ActionMap({1: "move_to_tool"}), SimulatedRobot()
    rec = _ScriptedRecognizer([])
    with pytest.raises(TypeError, match="recognizer must be a StreamingRecognizer"):
        GestureCommander("recognizer", amap, robot)
    with pytest.raises(TypeError, match="action_map must be an ActionMap"):
        GestureCommander(rec, {1: "move_to_tool"}, robot)
    with pytest.raises(TypeError, match="robot must be a PickAndPlaceRobot"):
        GestureCommander(rec, amap, "robot")
    with pytest.raises(TypeError, match="robot must be a PickAndPlaceRobot or None"):
        GestureCommander(rec, amap, robot=object())
    assert GestureCommander(rec, amap, robot=None).robot is None  # publish only


# -- the arming gesture -------------------------------------------------------

ARMING = 9  # the attention gesture of these tests
NOT_ARMED = "not armed: the arming gesture (class 9) comes first"


def _armed_map(**params):
    return ActionMap(
        {1: "move_to_tool", 2: "close_gripper"}, arming_class=ARMING, **params
    )


def test_a_command_counts_only_in_the_window_after_the_arming_gesture():
    amap = _armed_map(arming_frames=60)
    assert amap.arming_frames == 60 and amap.disarm_on_command
    early = amap.decide(_event(1, 50))
    assert not early.issued and early.reason == NOT_ARMED
    assert not amap.is_armed(50)
    arming = amap.decide(_event(ARMING, 100))
    assert arming.command is None  # the arming gesture gives no command itself
    assert arming.reason == "armed: a command is accepted for 60 frames"
    assert amap.armed_at == 100 and amap.is_armed(160) and not amap.is_armed(161)
    issued = amap.decide(_event(1, 160))  # the last frame of the window
    assert issued.command is RobotCommand.MOVE_TO_TOOL
    # the command disarmed the map: one arming gesture, one command
    again = amap.decide(_event(2, 165))
    assert not again.issued and again.reason == NOT_ARMED
    assert amap.armed_at is None
    # the window expires
    amap.decide(_event(ARMING, 300))
    late = amap.decide(_event(2, 361))
    assert not late.issued
    assert late.reason == "not armed: 61 frames after the arming gesture (> 60)"
    # re-arming opens a new window; so does re-arming before a command
    amap.decide(_event(ARMING, 400))
    amap.decide(_event(ARMING, 450))  # restarts the window at 450
    assert amap.decide(_event(2, 505)).command is RobotCommand.CLOSE_GRIPPER
    # reset disarms
    amap.decide(_event(ARMING, 600))
    amap.reset()
    assert amap.armed_at is None and amap.decide(_event(1, 650)).reason == NOT_ARMED


def test_arming_rules_confidence_refractory_overlap_and_several_commands():
    amap = _armed_map(min_confidence=0.6, refractory_frames=40, arming_frames=90)
    weak = amap.decide(_event(ARMING, 10, confidence=0.5))
    assert weak.reason == "confidence 0.50 < 0.6" and amap.armed_at is None
    # A command whose gesture starts before the arming gesture ended is the same
    # motion recognised twice (_event: start = emitted - 40, end = emitted - 12).
    amap.decide(_event(ARMING, 100))
    overlap = amap.decide(_event(1, 120))
    assert not overlap.issued and overlap.reason == (
        "not armed: the gesture starts at frame 80, before the arming gesture "
        "ended (frame 88)"
    )
    assert amap.decide(_event(1, 128)).issued  # starts at 88: after the end
    # the refractory period does not hold back the arming gesture
    amap.decide(_event(ARMING, 130))
    assert amap.armed_at == 130
    # without disarm_on_command, every command in the window counts (each after
    # the refractory period)
    many = _armed_map(disarm_on_command=False, refractory_frames=20)
    many.decide(_event(ARMING, 100))
    decisions = [many.decide(_event(c, t)) for c, t in [(1, 130), (2, 140), (2, 160)]]
    assert [d.issued for d in decisions] == [True, False, True]
    assert decisions[1].reason.startswith("refractory")
    assert many.decide(_event(1, 191)).reason.startswith("not armed: 91 frames")


def test_without_an_arming_gesture_every_command_counts():
    amap = ActionMap({1: "move_to_tool"})
    assert amap.arming_class is None and amap.is_armed(0)
    assert amap.decide(_event(1, 10)).issued


def test_bad_arming_parameters_are_refused():
    with pytest.raises(ValueError, match="arming_frames must be a positive int"):
        _armed_map(arming_frames=0)
    with pytest.raises(ValueError, match="arming_frames must be a positive int"):
        _armed_map(arming_frames=2.5)
    with pytest.raises(ValueError, match="arming_frames must be a positive int"):
        _armed_map(arming_frames=True)
    with pytest.raises(ValueError, match="disarm_on_command must be a bool"):
        _armed_map(disarm_on_command="yes")
    with pytest.raises(ValueError, match="arming_frames given without arming_class"):
        ActionMap({1: "move_to_tool"}, arming_frames=30)
    with pytest.raises(ValueError, match="arming_class: gesture class 0 cannot"):
        ActionMap({1: "move_to_tool"}, arming_class=0)
    with pytest.raises(TypeError, match="arming_class: a gesture class must be"):
        ActionMap({1: "move_to_tool"}, arming_class=1.5)
    with pytest.raises(ValueError, match="arming_class 1 also gives the command"):
        ActionMap({1: "move_to_tool"}, arming_class=1)
    names = ["wave", "point"]
    with pytest.raises(ValueError, match="arming_class: unknown gesture class name"):
        ActionMap({1: "move_to_tool"}, arming_class="jump", target_names=names)
    with pytest.raises(ValueError, match="arming_class 2 also gives the command"):
        ActionMap({"point": "beep"}, arming_class=2, target_names=names)


def test_the_arming_class_is_checked_against_the_model_in_bind():
    with pytest.raises(
        ValueError,
        match=r"^arming_class: class 9 is not a class of the model \(its classes "
        r"are 1, 2, 3\)",
    ):
        _armed_map().bind([1, 2, 3])
    # a name is resolved by bind, and may not be a mapped class there
    named = ActionMap({1: "move_to_tool"}, arming_class="wave").bind(
        [1, 2, 3], target_names=["point", "wave", "grab"]
    )
    assert named.arming_class == 2
    with pytest.raises(ValueError, match="arming_class 1 also gives the command"):
        ActionMap({1: "move_to_tool"}, arming_class="point").bind(
            [1, 2], target_names=["point", "wave"]
        )
    with pytest.raises(ValueError, match="arming_class: 'wave' is a class name"):
        ActionMap({1: "move_to_tool"}, arming_class="wave").bind([1, 2])
    # unbound, a name is matched against the event's name
    by_name = ActionMap({1: "move_to_tool"}, arming_class="wave")
    wave = GestureEvent(label=7, start=0, end=9, confidence=0.9, emitted_at=20,
                        name="wave")  # fmt: skip
    assert by_name.decide(wave).reason.startswith("armed")
    assert by_name.decide(_event(1, 60)).issued


def test_the_commander_sends_only_armed_commands_to_the_robot():
    events = [
        _event(1, 50),  # not armed
        _event(ARMING, 100),
        _event(1, 150),  # move_to_tool
        _event(2, 200),  # disarmed by the last command
        _event(ARMING, 300),
        _event(2, 500),  # too late
        _event(ARMING, 600),
        _event(2, 650),  # close_gripper
    ]
    robot = SimulatedRobot()
    amap = _armed_map(arming_frames=90)
    log = GestureCommander(_ScriptedRecognizer(events), amap, robot).run([None] * 700)
    assert [(d.event.emitted_at, d.issued) for d, _ in log] == [
        (50, False), (100, False), (150, True), (200, False), (300, False),
        (500, False), (600, False), (650, True),
    ]  # fmt: skip
    assert robot.actions == [RobotCommand.MOVE_TO_TOOL, RobotCommand.CLOSE_GRIPPER]
