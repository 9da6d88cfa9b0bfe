"""The command layer: any vocabulary in a file, its state machine, publishers."""

# SPDX-License-Identifier: BSD-3-Clause

import io
import json
import re
import socket
from pathlib import Path

import numpy as np
import pytest
from _stand_ins import make_cheap_pipeline

from skgesture.datasets import load_precog
from skgesture.streaming import (
    ActionMap,
    CommandEvent,
    CommandMap,
    GestureCommander,
    GestureEvent,
    JSONLinesPublisher,
    RobotCommand,
    RobotState,
    SimulatedRobot,
    StreamingRecognizer,
    UDPPublisher,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PICK_AND_PLACE = EXAMPLES / "pick_and_place_commands.json"
NAMES = ["wave", "point_left", "grab", "release"]
CLASSES = [1, 2, 3, 4]
STATES = {
    "idle": {"pick": "holding", "stop": "idle"},
    "holding": {"place": "idle", "stop": "holding"},
}


def _event(label, emitted_at, confidence=0.9, name=None):
    return GestureEvent(label, emitted_at - 40, emitted_at - 12, confidence,
                        emitted_at, name)  # fmt: skip


class _Scripted:
    """A stand-in recogniser with ``classes_``: prepared events at given frames."""

    def __init__(self, events, classes=CLASSES, target_names=NAMES):
        self.events, self.t = events, -1
        self.classes_ = np.asarray(classes)
        self.target_names = target_names

    def push(self, frame):
        self.t += 1
        return [ev for ev in self.events if ev.emitted_at == self.t]

    def flush(self):
        return [ev for ev in self.events if ev.emitted_at > self.t]


def _write(tmp_path, data, name="commands.json"):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return path


# -- the mapping --------------------------------------------------------------


def test_classes_by_name_and_by_number_any_vocabulary(tmp_path):
    commands = {"wave": "stop", "3": "pick", "point_left": "move_left", "4": "stop"}
    path = _write(tmp_path, {"commands": commands})
    cmap = CommandMap.from_file(path)
    assert not cmap.bound and cmap.vocabulary == ["stop", "pick", "move_left"]
    bound = cmap.bind(CLASSES, NAMES)
    assert bound.mapping == {1: "stop", 3: "pick", 2: "move_left", 4: "stop"}
    assert bound.classes == (1, 2, 3, 4) and not cmap.bound  # a bound copy
    # Through the commander: bound to the recogniser's classes and names.
    events = [_event(k, 20 * k) for k in (1, 2, 3, 4)]
    commander = GestureCommander(_Scripted(events), cmap)
    commander.run(range(100))
    assert [e.command for e in commander.published] == [
        "stop", "move_left", "pick", "stop"
    ]  # fmt: skip
    assert commander.action_map.mapping[3] == "pick"


def test_a_toml_file_is_the_same_map(tmp_path):
    path = _write(tmp_path, 'initial = "idle"\n[commands]\nwave = "stop"\n3 = "pick"\n'
                  '2 = "place"\n[states.idle]\npick = "holding"\nstop = "idle"\n'
                  '[states.holding]\nplace = "idle"\nstop = "holding"\n',
                  "commands.toml")  # fmt: skip
    cmap = CommandMap.from_file(path)
    assert cmap.initial == "idle" and cmap.next_state("idle", "pick") == "holding"
    assert cmap.bind(CLASSES, NAMES).mapping == {1: "stop", 3: "pick", 2: "place"}
    assert CommandMap.from_dict(cmap.to_dict()).to_dict() == cmap.to_dict()


@pytest.mark.parametrize(
    "commands, message",
    [
        ({}, r"commands: is empty"),
        ({"1": ""}, r"commands\['1'\]: a command must be a non-empty string, got ''"),
        ({"1": "  "}, r"commands\['1'\]: a command must be a non-empty string"),
        ({"1": 7}, r"commands\['1'\]: a command must be a non-empty string, got 7"),
        ({"1": None}, r"commands\['1'\]: a command must be a non-empty string"),
        ({"1": ["a"]}, r"commands\['1'\]: a command must be a non-empty string"),
        ({"0": "go"}, r"commands\['0'\]: class 0 cannot give a command: .*0 is rest"),
        ({"": "go"}, r"commands\[''\]: a gesture class cannot be an empty string"),
        ([["1", "go"]], r"commands: must be a table"),
    ],
)
def test_bad_entries_are_refused_when_the_file_is_read(tmp_path, commands, message):
    path = _write(tmp_path, {"commands": commands})
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: {message}"):
        CommandMap.from_file(path)


@pytest.mark.parametrize(
    "commands, message",
    [
        ({"jump": "go"}, r"commands\['jump'\]: unknown class name 'jump'; the model's "
         r"classes are 1 'wave', 2 'point_left', 3 'grab', 4 'release'"),
        ({"9": "go"}, r"commands\['9'\]: class 9 is not a class of the model"),
        ({"wave": "go", "1": "stop"}, r"commands\['1'\]: class 1 is given twice, as "
         r"'wave' and as '1'"),
    ],
)  # fmt: skip
def test_bad_classes_are_refused_when_bound_to_the_model(tmp_path, commands, message):
    path = _write(tmp_path, {"commands": commands})
    cmap = CommandMap.from_file(path)
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: {message}"):
        cmap.bind(CLASSES, NAMES)
    with pytest.raises(ValueError, match=message):  # at construction too
        GestureCommander(_Scripted([]), cmap)


def test_more_class_errors(tmp_path):
    with pytest.raises(ValueError, match=r"commands\[3\]: class 3 is given twice"):
        CommandMap({"3": "a", 3: "b"})
    with pytest.raises(ValueError, match="is a class name, but the model has no"):
        CommandMap({"wave": "go"}).bind(CLASSES)  # no target_names
    with pytest.raises(ValueError, match="class 2 is not a class of the model"):
        CommandMap({"point_left": "go"}).bind([1, 3], NAMES)  # named, not trained
    with pytest.raises(ValueError, match="gesture class is a class number"):
        CommandMap({1.5: "go"})
    # A duplicate key in a JSON file (json.loads would keep the last one).
    with pytest.raises(ValueError, match="key '1' appears twice"):
        CommandMap.from_file(_write(tmp_path, '{"commands": {"1": "a", "1": "b"}}'))


def test_broken_files_name_the_file(tmp_path):
    for text, suffix, message in [
        ('{"commands": {"1": "a",}}', ".json", "not valid JSON"),
        ("[commands\n1 = ", ".toml", "not valid TOML"),
        ('{"comands": {"1": "a"}}', ".json", "unknown key.*'comands'"),
        ('{"states": {}}', ".json", "no 'commands' table"),
        ("[1, 2]", ".json", "a command file holds a table"),
        ("x", ".yaml", "a command file is .json or .toml"),
    ]:
        path = _write(tmp_path, text, "bad" + suffix)
        with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: {message}"):
            CommandMap.from_file(path)


def test_action_map_is_bound_to_the_model_by_the_commander():
    """A plain dict map (as the CLI builds from --commands) is checked too."""
    with pytest.raises(ValueError, match=r"mapping\[9\]: class 9 is not a class"):
        GestureCommander(_Scripted([]), ActionMap({1: "move_to_tool", 9: "beep"}))
    with pytest.raises(ValueError, match="given twice"):
        GestureCommander(_Scripted([]), ActionMap({"wave": "a", 1: "b"}))
    amap = ActionMap({"grab": "close_gripper", 1: "move_to_tool"})
    GestureCommander(_Scripted([]), amap)
    assert amap.mapping == {
        3: RobotCommand.CLOSE_GRIPPER, 1: RobotCommand.MOVE_TO_TOOL
    }  # fmt: skip


# -- the arming gesture in the file ---------------------------------------------


def test_the_file_names_the_arming_gesture(tmp_path):
    data = {"commands": {"grab": "pick", "release": "place"},
            "arming": {"class": "wave", "frames": 60}}  # fmt: skip
    cmap = CommandMap.from_file(_write(tmp_path, data))
    assert cmap.arming == {"class": "wave", "frames": 60, "disarm_on_command": True}
    assert CommandMap.from_dict(cmap.to_dict()).to_dict() == cmap.to_dict()
    text = '[commands]\ngrab = "pick"\nrelease = "place"\n[arming]\nclass = "wave"\n'
    toml = _write(tmp_path, text + "frames = 60\n", "commands.toml")
    assert CommandMap.from_file(toml).to_dict() == cmap.to_dict()
    assert cmap.bind(CLASSES, NAMES).arming_label == 1 and cmap.arming_label is None
    # ActionMap and the commander take the arming from the map
    events = [
        _event(3, 50),  # grab, not armed
        _event(1, 100),  # wave: armed for 60 frames
        _event(3, 150),  # pick
        _event(4, 155),  # disarmed by the last command
        _event(1, 200),
        _event(4, 261),  # 61 frames later: too late
    ]
    commander = GestureCommander(_Scripted(events), cmap)
    log = commander.run(range(300))
    assert [e.command for e in commander.published] == ["pick"]
    assert log[5][0].reason == "not armed: 61 frames after the arming gesture (> 60)"
    amap = commander.action_map
    assert (amap.arming_class, amap.arming_frames, amap.disarm_on_command) == (
        1, 60, True
    )  # fmt: skip
    with pytest.raises(ValueError, match="arming_class given, but the command map"):
        ActionMap(cmap, arming_class=2)
    with pytest.raises(ValueError, match="arming_frames given, but the command map"):
        ActionMap(cmap, arming_frames=30)
    # a map without arming takes ActionMap's
    plain = ActionMap(CommandMap({"3": "pick"}), arming_class="wave", arming_frames=30)
    plain.bind(CLASSES, NAMES)
    assert plain.arming_class == 1 and plain.arming_frames == 30


@pytest.mark.parametrize(
    "arming, message",
    [
        ("wave", r"arming: must be a table"),
        ({"frames": 30}, r"arming: no 'class': name the arming gesture"),
        ({"class": "wave", "window": 30}, r"arming: unknown key\(s\) 'window'"),
        ({"class": "0"}, r"arming\['class'\]: class 0 cannot give a command"),
        ({"class": "wave", "frames": 0}, r"arming\['frames'\]: must be a positive int"),
        ({"class": "wave", "frames": 2.5}, r"arming\['frames'\]: must be a positive"),
        ({"class": "wave", "disarm_on_command": "no"},
         r"arming\['disarm_on_command'\]: must be true or false"),
        ({"class": "grab"}, r"arming\['class'\]: class 'grab' is the arming gesture "
         r"and also gives a command \(commands\['grab'\]\)"),
    ],
)  # fmt: skip
def test_bad_arming_tables_are_refused_when_the_file_is_read(tmp_path, arming, message):
    path = _write(tmp_path, {"commands": {"grab": "pick"}, "arming": arming})
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: {message}"):
        CommandMap.from_file(path)


def test_the_arming_class_is_checked_when_bound_to_the_model(tmp_path):
    path = _write(tmp_path, {"commands": {"grab": "pick"}, "arming": {"class": "9"}})
    with pytest.raises(
        ValueError,
        match=rf"^{re.escape(str(path))}: arming\['class'\]: class 9 is not a class "
        r"of the model",
    ):
        GestureCommander(_Scripted([]), CommandMap.from_file(path))
    # by number in the file, by name in the commands: the same class
    clash = CommandMap({"grab": "pick"}, arming={"class": 3})
    with pytest.raises(ValueError, match=r"class 3 is the arming gesture and also "
                       r"gives the command 'pick'"):  # fmt: skip
        clash.bind(CLASSES, NAMES)


# -- the state machine --------------------------------------------------------


def test_state_machine_accepts_and_rejects():
    cmap = CommandMap({"wave": "stop", "grab": "pick", "release": "place"},
                      states=STATES, initial="idle")  # fmt: skip
    events = [
        _event(4, 10),  # place in idle: rejected
        _event(3, 20),  # pick -> holding
        _event(3, 30),  # pick again: rejected
        _event(1, 40),  # stop in holding: stays
        _event(4, 50),  # place -> idle
    ]
    seen = []
    commander = GestureCommander(_Scripted(events), cmap, on_command=seen.append)
    log = commander.run(range(60))
    assert [(r.command, r.accepted, r.state_before, r.state_after) for _, r in log] == [
        ("place", False, "idle", "idle"),
        ("pick", True, "idle", "holding"),
        ("pick", False, "holding", "holding"),
        ("stop", True, "holding", "holding"),
        ("place", True, "holding", "idle"),
    ]
    assert log[0][1].reason == (
        "'place' is not valid in state 'idle' (valid there: stop, pick)"
    )
    assert commander.n_rejected == 2 and commander.state == "idle"
    assert seen == commander.published  # rejected commands are not published
    assert [(e.command, e.previous_state, e.state) for e in seen] == [
        ("pick", "idle", "holding"), ("stop", "holding", "holding"),
        ("place", "holding", "idle"),
    ]  # fmt: skip
    commander.reset()
    assert commander.state == "idle" and commander.n_rejected == 0
    assert commander.log == commander.published == []


@pytest.mark.parametrize(
    "states, initial, message",
    [
        (STATES, None, r"initial: missing: name the state"),
        (STATES, "busy", r"initial: 'busy' is not a state \(states: idle, holding\)"),
        ({"idle": {"pick": "holdin"}, "holding": {"place": "idle", "stop": "idle"}},
         "idle", r"states\['idle'\]\['pick'\]: leads to 'holdin', which is not a "
         r"state"),
        ({**STATES, "idle": {**STATES["idle"], "dance": "idle"}}, "idle",
         r"states\['idle'\]\['dance'\]: 'dance' is not a command of the mapping"),
        ({"idle": {"pick": "holding"}, "holding": {"place": "idle"}}, "idle",
         r"commands\['wave'\]: command 'stop' is valid in no state"),
        ({"idle": ["pick"]}, "idle", r"states\['idle'\]: must be a table"),
        ({}, "idle", r"states: must be a non-empty table"),
        (None, "idle", r"initial: 'idle' is given without states"),
    ],
)  # fmt: skip
def test_bad_state_machines_are_refused_at_load_time(
    tmp_path, states, initial, message
):
    data = {"commands": {"wave": "stop", "grab": "pick", "release": "place"}}
    if states is not None:
        data["states"] = states
    if initial is not None:
        data["initial"] = initial
    path = _write(tmp_path, data)
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}: {message}"):
        CommandMap.from_file(path)


def test_the_paper_pick_and_place_file_drives_the_robot():
    cmap = CommandMap.from_file(PICK_AND_PLACE)
    assert cmap.initial == "home" and cmap.vocabulary == [str(c) for c in RobotCommand]
    # A valid cycle, an invalid command in the middle, and a second cycle.
    script = [1, 2, 4, 3, 4, 5, 1, 2, 3, 4, 5]
    events = [_event(label, 20 * (i + 1)) for i, label in enumerate(script)]
    robot, seen = SimulatedRobot(), []
    commander = GestureCommander(
        _Scripted(events, classes=range(1, 9), target_names=None),
        ActionMap(cmap, min_confidence=0.5, refractory_frames=10),
        robot,
        on_command=seen.append,
        fps=20,
    )
    log = commander.run(range(300))
    refused = [(d.event.emitted_at, r.reason) for d, r in log if not r.accepted]
    assert refused == [
        (60, "'open_gripper' is not valid in state 'holding' (valid there: "
         "carry_tool)"),
    ]  # fmt: skip
    assert commander.n_rejected == 1 and len(robot.log) == 10  # never reached it
    assert robot.actions == list(RobotCommand) * 2
    assert robot.state is RobotState.HOME and commander.state == "home"
    assert [e.command for e in seen] == [str(c) for c in RobotCommand] * 2
    assert seen[0].time == 1.0 and seen[0].state == "at_tool"
    # The paper's five classes: a model without class 5 cannot use the file.
    with pytest.raises(ValueError, match=r"commands\['5'\]: class 5 is not a class"):
        cmap.bind([1, 2, 3, 4])


# -- publishing -------------------------------------------------------------


def _events():
    return [
        CommandEvent.from_gesture(_event(3, 62, 0.92, "grab"), "pick", fps=20,
                                  state="holding", previous="idle"),
        CommandEvent.from_gesture(_event(4, 90, 0.8), "place"),
    ]  # fmt: skip


def test_json_lines_publisher_output_parses_back():
    out = io.StringIO()
    publish = JSONLinesPublisher(out)
    for ev in _events():
        publish(ev)
    lines = out.getvalue().splitlines()
    assert publish.n_published == len(lines) == 2
    first, second = map(json.loads, lines)
    assert first == {
        "type": "command", "command": "pick", "label": 3, "name": "grab",
        "confidence": 0.92, "start": 22, "end": 50, "frame": 62, "time": 3.1,
        "timestamp": first["timestamp"], "state": "holding", "previous_state": "idle",
    }  # fmt: skip
    assert isinstance(first["timestamp"], float) and first["timestamp"] > 1.6e9
    assert second["name"] is second["time"] is second["state"] is None
    assert CommandEvent(**{k: v for k, v in first.items() if k != "type"}).to_dict(
    ) == first  # fmt: skip
    with pytest.raises(TypeError, match="text stream"):
        JSONLinesPublisher("stdout")


def test_json_lines_publisher_defaults_to_stdout(capsys):
    JSONLinesPublisher()(_events()[1])
    assert json.loads(capsys.readouterr().out)["command"] == "place"


def test_udp_publisher_over_a_real_socket():
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        receiver.bind(("127.0.0.1", 0))
        receiver.settimeout(5.0)
        port = receiver.getsockname()[1]
        with UDPPublisher("127.0.0.1", port) as publish:
            assert publish.address == ("127.0.0.1", port)
            for ev in _events():
                publish(ev)
            assert publish.n_published == 2
        got = [json.loads(receiver.recv(65536).decode("utf-8")) for _ in range(2)]
    finally:
        receiver.close()
    assert [m["command"] for m in got] == ["pick", "place"]
    assert got[0] == _events()[0].to_dict() | {"timestamp": got[0]["timestamp"]}
    with pytest.raises(ValueError, match="closed"):
        publish(_events()[0])
    for port in (0, 70000, "9001", True):
        with pytest.raises(ValueError, match="port must be"):
            UDPPublisher("127.0.0.1", port)


# -- a real stream ------------------------------------------------------------


def test_the_callback_receives_the_commands_of_a_stream():
    precog = load_precog()
    train = [i for i, g in enumerate(precog.groups) if g == 1]
    test = next(i for i, g in enumerate(precog.groups) if g == 8)
    pipe = make_cheap_pipeline().fit(
        [precog.X[i] for i in train], [precog.y[i] for i in train]
    )
    names = list(precog.target_names)
    recognizer = StreamingRecognizer(pipe, target_names=names)
    cmap = CommandMap({name: f"do_{k}" for k, name in enumerate(names, 1)})
    seen, out = [], io.StringIO()
    commander = GestureCommander(
        recognizer, cmap, on_command=[seen.append, JSONLinesPublisher(out)], fps=20
    )
    log = commander.run(precog.X[test])
    events = [d.event for d, _ in log]
    assert events, "the stream gave no event"
    assert [(e.label, e.name, e.frame, e.start, e.end) for e in seen] == [
        (ev.label, ev.name, ev.emitted_at, ev.start, ev.end) for ev in events
    ]
    assert all(e.command == f"do_{e.label}" and e.name == names[e.label - 1]
               and e.time == e.frame / 20 for e in seen)  # fmt: skip
    assert [json.loads(line) for line in out.getvalue().splitlines()] == [
        e.to_dict() for e in seen
    ]
    with pytest.raises(TypeError, match="on_command must be a callable"):
        GestureCommander(recognizer, cmap, on_command=["not callable"])
