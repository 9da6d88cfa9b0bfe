"""The subcommands of the ``skgesture`` command line: one ``cmd_*`` function each.

Each takes the parsed arguments and returns the exit status; a user mistake
raises :class:`~skgesture._cli_support.UsageError`. The parser that routes to
them and ``main`` are in :mod:`skgesture._cli`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import contextlib
import functools
import json
import math
import signal
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from skgesture._cli_support import (
    UsageError,
    _check_device,
    _class_name,
    _frame_rate,
    _info,
    _input_rates,
    _joints,
    _live_bars,
    _load_data,
    _load_model,
    _loader_verbose,
    _make_model,
    _model_fps,
    _model_target_names,
    _n_frames,
    _parse_subjects,
    _predict,
    _print_scores,
    _progress,
    _rate_options,
    _scores,
    _select_subjects,
    _subset,
    _target_names,
    _training_rate,
    _warn_unknown_rate,
    fast_tradeoff,
)

__all__ = [
    "cmd_train",
    "cmd_evaluate",
    "cmd_predict",
    "cmd_plot",
    "cmd_stream",
    "cmd_demo",
]

DEMO_TRAIN_SUBJECTS = "1-6"  # PRECOG subjects of the demo's training set
DEMO_TEST_SUBJECTS = "7-8"
ROBOT_REFRACTORY_FRAMES = 20  # one gesture, one command (examples/robot_...)


# -- subcommands -------------------------------------------------------------------


def cmd_train(args):
    from skgesture._persistence import save_model

    output = Path(args.output).expanduser()
    if output.exists() and not args.overwrite:
        raise UsageError(f"{output} exists; pass --overwrite to replace it")
    _check_device(args.device)
    data, kind, name = _load_data(args, need_labels=True)
    verbose = 0 if args.quiet else 1
    joints = _joints(args, data)
    pipe = _make_model(args, verbose, joints)
    fps = _training_rate(args, data, kind)
    _warn_unknown_rate(args, data, kind, fps, "the rate the model is trained at")
    X_bg = _background(args, data)
    _info(
        args,
        f"training method {args.method} (joints {joints}) on {name}: "
        f"{len(data.X)} sequences, {_n_frames(data):,} frames at {fps:g} fps"
        + (
            f", and {len(X_bg)} background sequences "
            f"({sum(len(x) for x in X_bg):,} frames)"
            if X_bg
            else ""
        ),
    )
    if args.fast:
        _info(args, fast_tradeoff(args.method))
    start = time.perf_counter()
    X = list(data.X) + X_bg
    y = list(data.y) + [np.zeros(len(x), dtype=int) for x in X_bg]
    pipe.fit(X, y, fps=fps)
    seconds = time.perf_counter() - start
    metadata = {
        "method": args.method,
        "joints": joints,
        "data": args.data,
        "data_kind": kind,
        "subjects": args.subjects,
        "n_sequences": len(data.X),
        "n_frames": _n_frames(data),
        "background": args.background,
        "n_background_frames": int(sum(len(x) for x in X_bg)),
        "target_names": _target_names(data),
        "fps": _frame_rate(args, data, kind),
        "seed": args.seed,
        "fit_seconds": round(seconds, 1),
    }
    save_model(pipe, output, metadata=metadata, overwrite=True)
    print(f"trained method {args.method} in {seconds:.1f} s; model written to {output}")
    return 0


def _background(args, data):
    """The ``--background`` sequences: skeletons, all rest (labels ignored)."""
    from skgesture import datasets
    from skgesture._pipelines import BACKGROUND_SEQUENCES

    out = []
    for spec in args.background or ():
        if spec == "synthetic":  # as many as make_recommended(background=...)
            made = datasets.make_background(
                data.X, data.y, n_sequences=BACKGROUND_SEQUENCES, random_state=args.seed
            )
            out += list(made.X)
            continue
        path = Path(spec).expanduser()
        if not path.exists():
            raise UsageError(f"--background {spec}: no such file or folder")
        fps = {"fps": args.fps} if args.fps else {}
        bg = datasets.load_recordings(
            path, layout=args.layout, labels=False, verbose=_loader_verbose(args), **fps
        )
        if not len(bg.X):
            raise UsageError(f"--background {spec}: no recording found")
        out += list(bg.X)
    return out


def cmd_evaluate(args):
    data, kind, name = _load_data(args, need_labels=True)
    model, info = _load_model(args, data)
    names = _target_names(data, info)
    _warn_unknown_rate(args, data, kind, _model_fps(model, info))
    rates = _input_rates(args, data, kind)
    y_pred = _predict(args, model, data.X, data.get("sample_ids"), rates, info)
    scores = _scores(data, kind, y_pred, names)
    meta = info.get("metadata") or {}
    if args.json:
        out = {
            "model": str(args.model),
            "method": meta.get("method"),
            "data": args.data,
            "subjects": args.subjects,
            **scores,
        }
        print(json.dumps(out, indent=2))
    else:
        method = meta.get("method", "?")
        _print_scores(scores, f"model {args.model} (method {method}) on {name}")
    return 0


def _write_frames(path, labels, overwrite):
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass --overwrite to replace it")
    rows = "".join(f"{t},{int(v)}\n" for t, v in enumerate(labels))
    path.write_text("frame,label\n" + rows)
    return path


def _prediction_names(data, info, y_pred):
    """The class names the interval files are written with, or None (numbers).

    The model's names (recorded when it was trained: the class names of its
    training data, or ``"1"``, ``"2"``, ... where those were numbered) name
    its predictions; a model file without them takes the data's. Numbers are
    written where neither has names, or where a prediction holds a class
    beyond the names (with a warning). ``read_intervals`` reads the files
    back with the ``classes.txt`` written next to them.
    """
    data_names = _target_names(data)
    names = _model_target_names(info) or data_names
    if not names:
        return None
    if data_names and names != data_names:
        warnings.warn(
            f"the data name the classes {', '.join(data_names[:5])}"
            f"{', ...' if len(data_names) > 5 else ''}, the model file "
            f"{', '.join(names[:5])}{', ...' if len(names) > 5 else ''}; the "
            "predictions are named by the model's",
            UserWarning,
            stacklevel=2,
        )
    top = max((int(np.max(p)) for p in y_pred if len(p)), default=0)
    if top > len(names):
        warnings.warn(
            f"the model predicts class {top} but names only {len(names)} "
            "classes; the predictions are written as class numbers",
            UserWarning,
            stacklevel=2,
        )
        return None
    return names


def cmd_predict(args):
    data, kind, name = _load_data(args, need_labels=False)
    model, info = _load_model(args, data)
    out = Path(args.output).expanduser()
    if out.exists() and not out.is_dir():
        raise UsageError(f"--output {out} is a file; give a folder")
    fmt = args.predict_format
    if fmt == "auto":
        fmt = "chalearn" if kind == "chalearn" else "intervals"
    if fmt == "chalearn" and kind != "chalearn":
        raise UsageError("--format chalearn needs ChaLearn input (sample ids)")
    ids = [str(s) for s in data.sample_ids]
    suffix = {
        "chalearn": "_prediction.csv",
        "intervals": ".labels.csv",
        "frames": ".frames.csv",
    }[fmt]
    targets = [Path(f"{out / sid}{suffix}") for sid in ids]
    existing = [p for p in targets if p.exists()]
    if existing and not args.overwrite:
        more = f" (and {len(existing) - 1} more)" if len(existing) > 1 else ""
        raise UsageError(f"{existing[0]} exists{more}; pass --overwrite to replace")
    _warn_unknown_rate(args, data, kind, _model_fps(model, info))
    rates = _input_rates(args, data, kind)
    y_pred = _predict(args, model, data.X, data.get("sample_ids"), rates, info)
    out.mkdir(parents=True, exist_ok=True)
    if fmt == "chalearn":
        from skgesture.datasets import write_chalearn_predictions

        paths = write_chalearn_predictions(
            y_pred, ids, out, n_frames=data.get("n_frames"), overwrite=args.overwrite
        )
    else:
        from skgesture.datasets import write_intervals

        names = _prediction_names(data, info, y_pred)
        if names:
            (out / "classes.txt").write_text("".join(f"{n}\n" for n in names))
        paths = []
        for path, labels in zip(targets, y_pred):
            path.parent.mkdir(parents=True, exist_ok=True)
            if fmt == "intervals":
                paths.append(
                    write_intervals(
                        path, labels, classes=names, overwrite=args.overwrite
                    )
                )
            else:
                paths.append(_write_frames(path, labels, args.overwrite))
    from skgesture.utils._segments import labels_to_segments

    n_gestures = sum(len(labels_to_segments(p)) for p in y_pred)
    print(
        f"wrote {len(paths)} {fmt} prediction file(s) to {out}: {n_gestures} "
        f"gestures found in {len(y_pred)} sequences"
    )
    return 0


def _sequence_index(data, spec):
    ids = [str(s) for s in data.sample_ids]
    if spec in ids:
        return ids.index(spec)
    try:
        i = int(spec)
    except ValueError:
        raise UsageError(
            f"--sequence {spec!r}: neither an index nor a sample id (e.g. {ids[0]!r})"
        ) from None
    if not 0 <= i < len(ids):
        raise UsageError(f"--sequence {i}: the data has sequences 0..{len(ids) - 1}")
    return i


def cmd_plot(args):
    output = Path(args.output).expanduser()
    if output.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise UsageError(f"--output {output}: give a .png, .svg or .pdf file name")
    if output.exists() and not args.overwrite:
        raise UsageError(f"{output} exists; pass --overwrite to replace it")
    try:
        import matplotlib
    except ImportError:
        raise ImportError(
            "plotting needs matplotlib: pip install skgesture[plot]"
        ) from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from skgesture import plotting

    kind = args.kind
    need_model = kind != "skeleton"
    if need_model and not args.model:
        raise UsageError(f"plot {kind} needs --model MODEL")
    data, data_kind, name = _load_data(args, need_labels=kind != "skeleton")
    i = _sequence_index(data, args.sequence)
    sid = str(data.sample_ids[i])
    if kind == "skeleton":
        x = np.asarray(data.X[i])
        frame = args.frame if args.frame is not None else len(x) // 2
        if not 0 <= frame < len(x):
            raise UsageError(f"--frame {frame}: {sid} has frames 0..{len(x) - 1}")
        ax = plotting.plot_skeleton(
            x[frame], view=args.view, title=args.title or f"{sid}, frame {frame}"
        )
    else:
        model, info = _load_model(args, data)
        names = _target_names(data, info)
        if kind == "segmentation":
            ax = plotting.plot_segmentation(
                model,
                data.X[i],
                data.y[i],
                fps=_frame_rate(args, data, data_kind, info, i),
                target_names=names,
                title=args.title or f"{sid}: activity segmentation",
            )
        else:
            n = len(data.X) if kind == "confusion" else args.max_sequences
            X, y = data.X[:n], data.y[:n]
            rates = _input_rates(args, data, data_kind)
            y_pred = _predict(args, model, X, rates=rates and rates[:n], info=info)
            if kind == "confusion":
                ax = plotting.plot_confusion_matrix(
                    y,
                    y_pred,
                    target_names=names,
                    title=args.title or f"frame confusions, {name}",
                )
            else:
                ax = plotting.plot_timelines(
                    y,
                    y_pred,
                    sample_ids=[str(s) for s in data.sample_ids[:n]],
                    target_names=names,
                    fps=_frame_rate(
                        args, _subset(data, list(range(len(X)))), data_kind, info
                    ),
                    title=args.title or f"truth against prediction, {name}",
                )
    fig = ax.figure
    if args.size:
        fig.set_size_inches(*args.size)
    fig.tight_layout()
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=args.dpi)
    plt.close(fig)
    print(f"{kind} figure written to {output}")
    return 0


def _robot_mapping(args, recognizer):
    """``{class: RobotCommand}`` of ``--robot``: ``--commands`` as 5 distinct
    classes of the model, one per command in task order, or the first 5."""
    from skgesture.streaming import RobotCommand

    commands = list(RobotCommand)
    classes = [int(c) for c in recognizer.classes_ if c != 0]
    if args.commands:
        given = [int(c) for c in _parse_subjects(args.commands)]
        if len(given) != len(commands):
            raise UsageError(
                f"--commands needs {len(commands)} gesture classes (one per command: "
                f"{', '.join(map(str, commands))}), got {len(given)}"
            )
        twice = sorted({c for c in given if given.count(c) > 1})
        if twice:
            raise UsageError(
                f"--commands {args.commands}: class {twice[0]} is given twice; each "
                f"command needs its own gesture"
            )
        unknown = [c for c in given if c not in classes]
        if unknown:
            raise UsageError(
                f"--commands {args.commands}: class {unknown[0]} is not a class of "
                f"the model (its classes are {', '.join(map(str, classes))})"
            )
        classes = given
    elif len(classes) < len(commands):
        raise UsageError(
            f"--robot needs {len(commands)} gesture classes (one per command), the "
            f"model has {len(classes)}; give a command file with --commands FILE"
        )
    return dict(zip(classes, commands[: len(classes)]))


def _command_file(spec):
    """The path of ``--commands`` when it names a command file, else None."""
    if spec and (
        Path(spec).suffix.lower() in (".json", ".toml") or Path(spec).is_file()
    ):
        return Path(spec)
    return None


def _publishers(args):
    """The ``on_command`` callbacks of ``--publish`` (stdout, udp://HOST:PORT)."""
    from skgesture.streaming import JSONLinesPublisher, UDPPublisher

    out = []
    for target in args.publish or ():
        if target == "stdout":
            out.append(JSONLinesPublisher(sys.stdout))
        elif target.startswith("udp://"):
            host, _, port = target[len("udp://") :].rpartition(":")
            if not host or not port.isdigit() or not 0 < int(port) < 65536:
                raise UsageError(
                    f"--publish {target}: expected udp://HOST:PORT, e.g. "
                    f"udp://127.0.0.1:9001"
                )
            out.append(UDPPublisher(host, int(port)))
        else:
            raise UsageError(f"--publish {target}: expected stdout or udp://HOST:PORT")
    return out


def _delay_bound(recognizer, fps):
    """``(frames, text)``: the most frames an event comes after its gesture's end.

    ``recognizer.max_delay`` (the sum of the stages' look-aheads) bounds every
    event but one case: with Methods A/B nothing in an activity period is
    emitted before the period is known to be long (``short_length`` frames),
    so a gesture ending in its first ``short_length`` frames waits until the
    classifier has seen frame ``start + short_length - 1``, that is up to
    ``lookahead + short_length - 1`` frames after its end (docs/streaming.md,
    "Delay"; :class:`~skgesture.streaming.StreamingRecognizer`, Notes).
    """
    bound = int(recognizer.max_delay)
    text = (
        f"events come at most {bound} frames ({bound / fps:.2f} s) after a gesture ends"
    )
    last = recognizer.pipeline.steps[-1][1]
    short = getattr(last, "short_length", None)
    if short is None or recognizer.early_decision:
        return bound, text
    short = math.ceil(int(short) * recognizer.ratio)  # in input frames
    wait = int(recognizer.lookahead) + int(short) - 1
    if wait <= bound:
        return bound, text
    text = (
        f"events come at most {wait} frames ({wait / fps:.2f} s) after a gesture "
        f"ends: at most {bound} ({bound / fps:.2f} s), but a gesture that ends in "
        f"the first {short} frames of a longer activity period waits until the "
        f'period is known to be long (docs/streaming.md, "Delay")'
    )
    return wait, text


def _parse_source(spec):
    """``(kind, target)`` of ``--source``: ``("udp", (host, port))``,
    ``("lsl", name)`` or ``("stdin", None)``."""
    if spec in ("-", "stdin"):
        return "stdin", None
    scheme, sep, rest = spec.partition("://")
    scheme = scheme.lower()
    if sep and scheme == "lsl" and rest:
        return "lsl", rest
    if sep and scheme == "udp":
        host, colon, port = rest.rpartition(":")
        if colon and port.isdigit() and int(port) <= 65535:
            return "udp", (host.strip("[]") or "127.0.0.1", int(port))
    raise UsageError(
        f"--source {spec!r}: give udp://HOST:PORT (e.g. udp://0.0.0.0:9000; port "
        "0 picks a free one), lsl://NAME or - (CSV rows on stdin)"
    )


def _live_adapter(layout):
    """The adapter of ``--layout`` (the names of ``--layout`` or get_adapter's)."""
    from skgesture.datasets._skeleton_csv import LAYOUT_ALIASES
    from skgesture.streaming import get_adapter

    return get_adapter(LAYOUT_ALIASES.get(layout, layout))


def _open_source(args, spec, fps):
    """``(source, where)``: the live source of ``--source`` and its name."""
    from skgesture import streaming

    kind, target = _parse_source(spec)
    adapter = _live_adapter(args.layout)
    if kind == "stdin":
        if args.timeout is not None:
            raise UsageError(
                "--timeout is for udp:// and lsl:// sources; stdin ends at the end "
                "of its input"
            )
        return streaming.StdinSource(fps=fps, layout=adapter), "stdin"
    if kind == "udp":
        source = streaming.UDPSource(
            *target, fps=fps, layout=adapter, timeout=args.timeout
        )
        host, port = source.bound_address
        return source, f"udp://{host}:{port}"
    source = streaming.LSLSource(
        target, fps=args.fps, layout=adapter, timeout=args.timeout
    )
    return source, f"lsl://{target}"


class _HeldInterrupt:
    """Ctrl-C ends a stream between two frames, never inside a push.

    While installed, a SIGINT that comes while a frame is pushed through the
    recogniser sets ``pending`` (the push completes, and its events are
    printed); one that comes elsewhere (a source waiting for data) raises
    ``KeyboardInterrupt`` at once. The handler is only installed where
    Python's own is (in the main thread, where Ctrl-C is not ignored).
    """

    def __init__(self):
        self.busy = False
        self.pending = False
        self._previous = None

    def _handle(self, signum, frame):
        if self.busy:
            self.pending = True
        else:
            raise KeyboardInterrupt

    def __enter__(self):
        try:
            if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
                self._previous = signal.signal(signal.SIGINT, self._handle)
        except ValueError:  # not the main thread
            self._previous = None
        return self

    def __exit__(self, *exc_info):
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)

    @contextlib.contextmanager
    def pushing(self):
        self.busy = True
        try:
            yield
        finally:
            self.busy = False


def _push_all(frames, push, report):
    """Push every frame and report its output; ``(n_frames, interrupted)``.

    Ctrl-C (``KeyboardInterrupt``) ends the loop between two frames.
    """
    n = 0
    with _HeldInterrupt() as held:
        try:
            for frame in frames:
                with held.pushing():
                    out = push(frame)
                n += 1
                report(*out)
                if held.pending:
                    return n, True
        except KeyboardInterrupt:
            return n, True
    return n, False


def _paced(frames, fps):
    """The frames of a recording, each at its time (``--realtime``)."""
    start = time.perf_counter()
    for t, frame in enumerate(frames):
        lag = start + t / fps - time.perf_counter()
        if lag > 0:
            time.sleep(lag)
        yield frame


def _commander(args, recognizer, names, fps):
    """``(commander, robot)`` of ``--robot``/``--commands FILE``/``--publish``,
    or ``(None, None)`` when the events drive nothing."""
    path = _command_file(args.commands)
    if not (args.robot or path or args.publish):
        return None, None
    from skgesture.streaming import (
        ActionMap,
        CommandMap,
        GestureCommander,
        SimulatedRobot,
    )

    if path is not None:
        try:
            mapping = CommandMap.from_file(path)
        except FileNotFoundError:
            raise UsageError(f"--commands {path}: no such file") from None
    elif args.robot or args.commands:
        mapping = CommandMap(
            {str(c): str(cmd) for c, cmd in _robot_mapping(args, recognizer).items()}
        )
    else:
        raise UsageError("--publish needs --robot or a command file (--commands FILE)")
    action_map = ActionMap(
        mapping,
        min_confidence=args.min_confidence,
        refractory_frames=ROBOT_REFRACTORY_FRAMES,
    )
    robot = SimulatedRobot() if args.robot else None
    commander = GestureCommander(
        recognizer, action_map, robot, on_command=_publishers(args) or None, fps=fps
    )
    for cls, command in commander.command_map.mapping.items():
        _info(args, f"  gesture {_class_name(cls, names)} -> {command}")
    return commander, robot


def cmd_stream(args):
    """Replay DATA, or read ``--source`` live, and print the events as they come.

    Both end the same way: at the end of the frames (of the recording, of
    stdin, or ``--timeout`` seconds without a frame) or on Ctrl-C, after which
    the recogniser is flushed, its last events printed, then the summary;
    the status is 0 either way.
    """
    from skgesture.streaming import StreamingRecognizer

    spec = args.source
    if spec is None and args.data == "-":
        spec = "-"
    elif spec is not None and args.data is not None:
        raise UsageError(f"give DATA ({args.data}) or --source {spec}, not both")
    if spec is None and args.data is None:
        raise UsageError(
            "give DATA, a recording to replay, or --source udp://HOST:PORT | "
            "lsl://NAME | - for a live stream"
        )
    if spec is not None:
        if args.sequence is not None or args.realtime:
            option = "--sequence" if args.sequence is not None else "--realtime"
            raise UsageError(f"{option} is for a replayed recording, not --source")
        from skgesture.layouts import KINECT_V1, N_COORDS

        # the sources' frames: Kinect v1, whatever the sender's layout
        model, info = _load_model(args, frame_shape=(KINECT_V1.n_joints, N_COORDS))
        fps = args.fps or _model_fps(model, info) or 30.0
        names = _target_names(None, info)
    else:
        data, data_kind, name = _load_data(args, need_labels=False)
        model, info = _load_model(args, data)
        i = _sequence_index(data, "0" if args.sequence is None else args.sequence)
        stream = np.asarray(data.X[i])
        fps = _frame_rate(args, data, data_kind, info, i) or 30.0
        names = _target_names(data, info)
        _warn_unknown_rate(args, _subset(data, [i]), data_kind, _model_fps(model, info))
    source = bar = None
    if spec is not None:
        source, where = _open_source(args, spec, fps)
        fps = source.fps  # an LSL stream's nominal rate
    try:
        # the frames' rate, where the model knows its own (it resamples)
        rate = (_rate_options(model, [fps], info) or [{}])[0]
        recognizer = StreamingRecognizer(model, target_names=names, **rate)
        commander, robot = _commander(args, recognizer, names, fps)
    except BaseException:
        if source is not None:
            source.close()
        raise
    # With --publish stdout, stdout carries only the commands' JSON lines.
    human = sys.stderr if "stdout" in (args.publish or ()) else sys.stdout
    write = functools.partial(print, file=human)
    if spec is not None:
        frames = source
        write = functools.partial(print, file=human, flush=True)  # a pipe sees each
        ends = (
            "the end of its input" if where == "stdin"
            else f"{args.timeout:g} s without a frame" if args.timeout
            else "Ctrl-C"
        )  # fmt: skip
        write(
            f"streaming {where} ({source.adapter.name} layout, {fps:g} fps) until "
            f"{ends}{'' if ends == 'Ctrl-C' else ' or Ctrl-C'}"
        )
    else:
        write(
            f"streaming {data.sample_ids[i]} of {name}: {len(stream)} frames at "
            f"{fps:g} fps"
        )
        bar = _progress(args, range(len(stream)), "frames", unit="frame")
        frames = (stream[t] for t in bar)
        if args.realtime:
            frames = _paced(frames, fps)
        if not args.quiet and _live_bars() and human is sys.stdout:
            from tqdm.auto import tqdm

            write = tqdm.write  # the events above the bar
    write(_delay_bound(recognizer, fps)[1])
    delays = []

    def report(events, pairs):
        for ev in events:
            delays.append(ev.delay)
            label = ev.name or _class_name(ev.label, names)
            write(
                f"{ev.emitted_at / fps:8.2f} s  frame {ev.emitted_at:6d}  "
                f"{label:<20}  frames {ev.start}-{ev.end - 1}  conf "
                f"{ev.confidence:.2f}  delay {ev.delay} frames "
                f"({ev.delay / fps:.2f} s)"
            )
        who = "robot" if robot is not None else "command"
        for decision, result in pairs:
            if result is None:
                write(f"{'':>25}{who}: ignored ({decision.reason})")
            elif result.accepted:
                write(f"{'':>25}{who}: {result.command} -> {result.state_after}")
            else:
                write(f"{'':>25}{who}: {result.command} refused ({result.reason})")

    def push(frame):
        if commander is None:
            return recognizer.push(frame), []
        pairs = commander.push(frame)
        return [d.event for d, _ in pairs], pairs

    try:
        n, interrupted = _push_all(frames, push, report)
    finally:
        if source is not None and hasattr(source, "close"):
            source.close()
        if hasattr(bar, "close"):
            bar.close()
    if interrupted:
        print(f"skgesture stream: stopped (Ctrl-C) after {n} frames", file=sys.stderr)
    if commander is not None:
        pairs = commander.flush()
        report([d.event for d, _ in pairs], pairs)
    else:
        report(recognizer.flush(), [])
    if source is not None:
        write(
            f"{where}: {n} frames, {source.n_filled_} of them untracked for lost "
            f"frames; {source.n_dropped_} bad messages skipped, "
            f"{source.n_out_of_order_} out of order"
        )
    summary = f"{len(delays)} events"
    if delays:
        summary += (
            f"; delay mean {np.mean(delays):.1f}, max {max(delays)} frames "
            f"({max(delays) / fps:.2f} s)"
        )
    write(summary)
    if robot is not None:
        write(f"robot: {robot.status()}")
    return 0


def cmd_demo(args):
    """Summarise PRECOG, train on subjects 1-6, report on subjects 7-8."""
    from skgesture.datasets import load_precog

    _check_device(args.device)
    data = load_precog(verbose=_loader_verbose(args))
    segments = np.concatenate(data.segments)
    lengths = segments[:, 2] - segments[:, 1]
    print("PRECOG 2016 (bundled, subjects 1-8, MIT licence, D. Jardim)")
    print(
        f"  sequences {len(data.X)}, frames {_n_frames(data):,}, subjects "
        f"{len(np.unique(data.groups))}, gestures {len(segments)} (length "
        f"{lengths.min()}-{lengths.max()}, median {np.median(lengths):.0f} frames)"
    )
    train = _select_subjects(data, DEMO_TRAIN_SUBJECTS, "PRECOG")
    test = _select_subjects(data, DEMO_TEST_SUBJECTS, "PRECOG")
    joints = _joints(args, train)
    pipe = _make_model(args, 0 if args.quiet else 1, joints)
    _info(
        args,
        f"training method {args.method} (joints {joints}) on subjects "
        f"{DEMO_TRAIN_SUBJECTS}",
    )
    start = time.perf_counter()
    pipe.fit(train.X, train.y, fps=data.fps)
    seconds = time.perf_counter() - start
    y_pred = _predict(args, pipe, test.X, rates=_input_rates(args, test, "precog"))
    scores = _scores(test, "precog", y_pred, _target_names(data))
    _print_scores(
        scores,
        f"\nmethod {args.method}, trained in {seconds:.1f} s; held-out subjects "
        f"{DEMO_TEST_SUBJECTS}:",
    )
    if args.output:
        from skgesture._persistence import save_model

        path = save_model(
            pipe,
            args.output,
            metadata={"method": args.method, "joints": joints, "data": "precog",
                      "target_names": list(map(str, data.target_names))},
        )  # fmt: skip
        print(f"model written to {path}")
    return 0
