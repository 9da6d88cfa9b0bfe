"""
=========================================================
Commanding a pick-and-place robot with streamed gestures
=========================================================

The paper's use case: five gestures command a collaborative robot through a
pick-and-place task (move to the tool, close the gripper, carry the tool, open
the gripper, return home). The paper drove its robot with a short Method C (a
bidirectional LSTM tagger) trained on the five command gestures only; that is
the default here. This script

1. trains a 5-gesture model: by default Method C (``make_method_c``, the
   CPU-sized network) on the five command classes of synthetic
   Montalbano-like streams (the paper kept 5 of the 20 ChaLearn gestures; the
   other gestures become out-of-vocabulary motions labelled rest);
   ``--method B`` trains Method B instead (descriptor, segmenter, three-scale
   windows), and ``--method recommended`` the recommended model
   (``make_recommended``: body-normalised joints and a whole-sequence tagger,
   streamed over a trailing window with an 8-frame look-ahead);
2. replays a held-out stream of an unseen subject, in which the operator gives
   the five commands in task order, twice, with an unmapped gesture and a
   repeated one in between, through :class:`~skgesture.streaming.StreamingRecognizer`;
3. turns the events into commands with an :class:`~skgesture.streaming.ActionMap`
   (confidence floor, refractory period) and drives a
   :class:`~skgesture.streaming.SimulatedRobot`, which refuses commands out of
   order;
4. prints the timeline of gestures, commands and robot states and saves it as
   a PNG.

``python examples/robot_pick_and_place.py --fast`` trains small networks on 30
streams (well under a minute on 2 CPU cores); without ``--fast`` the default
network sizes are trained on 120 streams (a few minutes).

What to look for in the output: every command comes at most ``max_delay``
frames after its gesture ends (12 to 21 frames, 0.6-1 s, for Method C; about
10 for the recommended model); the unmapped gesture, which the model
never saw as a gesture, should be ignored (its frames were rest in training),
and the repeated "close gripper" is refused by the robot as out of order.
``--out`` chooses the folder of the plot. It trains, so it has no ``plot_``
prefix (the gallery does not run it).

To drive a real robot, subclass :class:`~skgesture.streaming.PickAndPlaceRobot`
and implement ``_perform`` with the robot's API; to read a live sensor,
implement :class:`~skgesture.streaming.SkeletonSource` with an adapter (see
``docs/streaming.md``).
"""

# %%
# Imports and settings
# --------------------

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from skgesture import (
    TorchMLPClassifier,
    make_method_b,
    make_method_c,
    make_recommended,
)
from skgesture.datasets import make_gesture_streams
from skgesture.streaming import (
    ActionMap,
    GestureCommander,
    ReplaySource,
    RobotCommand,
    SimulatedRobot,
    StreamingRecognizer,
)
from skgesture.utils import labels_to_segments, segments_to_labels

N_CLASSES = 8  # classes of the synthetic streams
COMMANDS = {  # the 5 gesture classes kept, and the command of each
    1: RobotCommand.MOVE_TO_TOOL,
    3: RobotCommand.CLOSE_GRIPPER,
    4: RobotCommand.CARRY_TOOL,
    6: RobotCommand.OPEN_GRIPPER,
    8: RobotCommand.RETURN_HOME,
}
# What the operator does in the held-out stream: the cycle, an unmapped
# gesture (class 2, out of vocabulary), the cycle again with close_gripper
# given twice (the robot refuses the second one).
SCRIPT = [1, 3, 4, 6, 8, 2, 1, 3, 3, 4, 6, 8]
CONTEXT = 25  # rest frames kept around each scripted gesture
FPS = 20


def parse_args():
    parser = argparse.ArgumentParser(description="Gesture-commanded robot demo")
    parser.add_argument("--fast", action="store_true", help="small networks")
    parser.add_argument(
        "--method", choices=["C", "B", "recommended"], default="C",
        help="C: the paper's robot model, a Method C tagger on the 5 commands "
        "(default); B: Method B; recommended: make_recommended",
    )  # fmt: skip
    parser.add_argument("--out", type=Path, default=None, help="folder of the PNG")
    parser.add_argument("--seed", type=int, default=0)
    return parser.parse_args()


# %%
# Training data: 5 of the 8 classes are commands, the rest is rest
# ----------------------------------------------------------------


def make_data(fast, seed):
    n_sequences = 40 if fast else 160  # 30 / 120 training streams
    data = make_gesture_streams(
        n_sequences=n_sequences, n_classes=N_CLASSES, n_subjects=n_sequences // 4,
        random_state=seed,
    )  # fmt: skip
    y = [np.where(np.isin(lab, list(COMMANDS)), lab, 0) for lab in data.y]
    held_out = data.groups == data.groups.max()  # one unseen subject
    train = [i for i in range(n_sequences) if not held_out[i]]
    test = [i for i in range(n_sequences) if held_out[i]]
    return data, y, train, test


def make_model(method, fast, seed):
    """The 5-command model: Method C (the paper's robot), B or the recommended."""
    if method == "C":
        # A short Method C: the CPU-sized BiLSTM tagger (docs/method.md §7),
        # smaller and trained for fewer epochs with --fast. Its classes are the
        # five commands and rest, as the labels it is trained on.
        pipe = make_method_c(random_state=seed)
        if fast:
            pipe.set_params(tagger__hidden_sizes=(32,), tagger__max_epochs=15)
        return pipe
    if method == "recommended":
        # Joint features and a whole-sequence tagger; streamed, the tagger reads
        # a trailing window with a fixed look-ahead (docs/streaming.md, "The
        # recommended model"). --fast trains it for fewer epochs.
        pipe = make_recommended(random_state=seed)
        if fast:
            epochs = [k for k in pipe.get_params() if k.endswith("max_epochs")]
            pipe.set_params(**dict.fromkeys(epochs, 8))
        return pipe
    pipe = make_method_b(random_state=seed)
    if fast:
        pipe.set_params(
            segmenter__estimator=TorchMLPClassifier(
                hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=100
            ),
            classifier__estimator=TorchMLPClassifier(
                hidden_layer_sizes=(64,), activations=("tanh",), max_epochs=100
            ),
        )
    return pipe


# %%
# A held-out stream following the script
# --------------------------------------
# Gesture instances of the held-out subject, each with some rest around it,
# are put one after the other in the order of ``SCRIPT``.


def compose_stream(data, test, script, rng):
    instances = {}
    for i in test:
        for cls, s, e in labels_to_segments(data.y[i]):
            lo, hi = s - CONTEXT, e + CONTEXT
            if lo >= 0 and hi <= len(data.y[i]) and not data.y[i][lo:s].any():
                if not data.y[i][e:hi].any():
                    instances.setdefault(int(cls), []).append((i, lo, s, e, hi))
    X, y = [], []
    for cls in script:
        i, lo, s, e, hi = instances[cls][rng.randint(len(instances[cls]))]
        X.append(data.X[i][lo:hi])
        lab = np.zeros(hi - lo, dtype=np.int64)
        lab[s - lo : e - lo] = cls
        y.append(lab)
    return np.concatenate(X), np.concatenate(y)


# %%
# Replay, recognise, command
# --------------------------


def replay(pipe, stream, target_names):
    recognizer = StreamingRecognizer(pipe, target_names=target_names)
    action_map = ActionMap(COMMANDS, min_confidence=0.6, refractory_frames=20)
    robot = SimulatedRobot()
    commander = GestureCommander(recognizer, action_map, robot)
    states = []  # robot state after every frame
    for frame in ReplaySource(stream, fps=FPS):
        commander.push(frame)
        states.append(robot.state.value)
    commander.flush()
    states[-1] = robot.state.value
    return recognizer, commander, robot, states


def print_timeline(commander, truth, recognizer):
    print(
        f"\nlook-ahead per stage {recognizer.delays}; events come at most "
        f"{recognizer.max_delay} frames after a gesture ends (see docs)\n"
    )
    print(f"{'frame':>6} {'time':>6}  {'what':<38} {'result':<44} robot")
    rows = []
    for cls, s, e in labels_to_segments(truth):
        name = COMMANDS.get(int(cls), "(unmapped)")
        rows.append((e - 1, f"true gesture {cls} [{s}, {e}) -> {name}", "", ""))
    for decision, result in commander.log:
        ev = decision.event
        what = f"event {ev.label} [{ev.start}, {ev.end}) conf {ev.confidence:.2f}"
        if result is None:
            outcome = f"ignored: {decision.reason}"
            state = ""
        else:
            verdict = "done" if result.accepted else f"refused: {result.reason}"
            outcome = f"{result.command}: {verdict}"
            state = result.state_after.value
        rows.append((ev.emitted_at, what, outcome, state))
    for frame, what, outcome, state in sorted(rows, key=lambda r: r[0]):
        print(f"{frame:6d} {frame / FPS:5.1f}s  {what:<38} {outcome:<44} {state}")


# %%
# The timeline as a figure
# ------------------------


def plot_timeline(path, commander, truth, states, target_names):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from skgesture.plotting import plot_gesture_timeline

    order = ["home", "at_tool", "holding", "carried", "released"]
    fig, axes = plt.subplots(3, 1, figsize=(12, 6.5), sharex=True,
                             gridspec_kw={"height_ratios": [1.3, 1, 1.4]})  # fmt: skip
    # Performed gestures against the recognised ones (the events), with the
    # frame at which each event was emitted.
    events = [decision.event for decision, _ in commander.log]
    recognised = segments_to_labels(
        [(ev.label, ev.start, ev.end) for ev in events], len(truth), on_overlap="later"
    )
    ax = plot_gesture_timeline(
        truth,
        recognised,
        target_names=target_names,
        ax=axes[0],
        title="Gestures, commands and robot state",
    )
    ax.plot([ev.emitted_at for ev in events], [1.5] * len(events), "kv", ms=5,
            label="event emitted")  # fmt: skip
    ax.set_yticks([1, 2], ["recognised\n(v: emitted)", "performed"])
    ax.set_xlabel("")
    ax = axes[1]
    for decision, result in commander.log:
        if result is None:
            continue
        t = decision.event.emitted_at
        ok = result.accepted
        ax.plot([t], [0.5], "o" if ok else "x", color="tab:green" if ok else "tab:red",
                ms=8)  # fmt: skip
        ax.text(t, 0.75 if ok else 0.2, str(result.command).replace("_", " "),
                rotation=20, fontsize=7, ha="left")  # fmt: skip
    ax.set_yticks([])
    ax.set_ylim(0, 1.3)
    ax.set_ylabel("commands\n(o done, x refused)")
    ax = axes[2]
    ax.step(np.arange(len(states)), [order.index(s) for s in states], where="post")
    ax.set_yticks(range(len(order)), order)
    ax.set_xlabel(f"frame ({FPS} fps)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    # left open: the documentation's gallery shows the figures still open


def main():
    args = parse_args()
    t0 = time.perf_counter()
    data, y5, train, test = make_data(args.fast, args.seed)
    pipe = make_model(args.method, args.fast, args.seed)
    pipe.fit([data.X[i] for i in train], [y5[i] for i in train], fps=data.fps)
    label = {"C": "Method C (the paper's robot model)", "B": "Method B"}.get(
        args.method, "the recommended model"
    )
    print(f"trained {label} on {len(train)} streams (classes {sorted(COMMANDS)}) "
          f"in {time.perf_counter() - t0:.0f} s")  # fmt: skip
    rng = np.random.RandomState(args.seed)
    stream, truth = compose_stream(data, test, SCRIPT, rng)
    names = [str(COMMANDS.get(k, f"gesture {k}")) for k in range(1, N_CLASSES + 1)]
    recognizer, commander, robot, states = replay(pipe, stream, names)
    print_timeline(commander, truth, recognizer)
    print(f"\nrobot: {robot.status()}")
    out = args.out or Path(tempfile.mkdtemp(prefix="skgesture_robot_"))
    out.mkdir(parents=True, exist_ok=True)
    path = out / "robot_pick_and_place.png"
    plot_timeline(path, commander, truth, states, names)
    print(f"timeline plot: {path}  (total {time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
