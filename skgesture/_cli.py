"""The ``skgesture`` command line: train, evaluate, predict, plot, stream, demo.

Run ``skgesture --help`` (or ``python -m skgesture --help``); ``docs/cli.md``
has a walk-through. Every subcommand is a thin layer over the public API:
data come from :mod:`skgesture.datasets`, models from the ``make_*`` factories,
model files from :func:`skgesture.save_model` / :func:`skgesture.load_model`,
scores from :mod:`skgesture.metrics` and figures from :mod:`skgesture.plotting`.

A user mistake (a missing folder, a file that is not a model, an unknown
method, a model from another version, bad data) ends with one line on stderr
and exit status 1; ``--traceback`` shows the full traceback instead. Progress
bars go to stderr, results to stdout.
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import contextlib
import json
import re
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from skgesture._version import __version__

__all__ = ["main"]

METHODS = ("recommended", "A", "B", "C", "C-paper")
BUILTIN_DATA = ("precog", "synthetic")
PLOTS = ("timeline", "segmentation", "confusion", "skeleton")
F1_OVERLAPS = (0.1, 0.25, 0.5)
FAST_MLP_HIDDEN = 32  # units of the one-layer networks of --fast (Methods A/B)
FAST_TAGGER_HIDDEN = (16,)  # --fast tagger (Methods C and recommended)
FAST_MAX_EPOCHS = 60
DEFAULT_MAX_TIMELINES = 12  # sequences drawn by `plot timeline`
DEMO_TRAIN_SUBJECTS = "1-6"  # PRECOG subjects of the demo's training set
DEMO_TEST_SUBJECTS = "7-8"
ROBOT_REFRACTORY_FRAMES = 20  # one gesture, one command (examples/robot_...)
_CHALEARN_NAME = re.compile(
    r"^Sample\d{4,5}(\.zip|_(skeleton|labels|data|prediction)\.csv)?$", re.I
)


class UsageError(Exception):
    """A mistake on the command line; reported as one line, no traceback."""


# -- output ----------------------------------------------------------------------


def _info(args, message):
    """A progress or status line (stderr, silenced by --quiet)."""
    if not args.quiet:
        print(message, file=sys.stderr, flush=True)


def _progress(args, iterable, desc, total=None, unit="seq"):
    """A tqdm bar over ``iterable`` (stderr), or the bare iterable with --quiet."""
    if args.quiet:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, unit=unit, leave=False)


def _one_line(exc):
    """The message of an exception as one line, without ``[Errno N]``."""
    if isinstance(exc, OSError) and exc.strerror and exc.filename:
        text = f"{exc.strerror}: {exc.filename}"
    else:
        text = str(exc) or type(exc).__name__
    text = re.sub(r"^\[Errno \d+\]\s*", "", text)
    return " ".join(text.split())


@contextlib.contextmanager
def _warnings_as_lines():
    """Print warnings as ``skgesture: warning: ...`` lines, each message once."""
    seen = set()

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        if text not in seen:
            seen.add(text)
            print(f"skgesture: warning: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = show
        yield


# -- data ------------------------------------------------------------------------


def _parse_subjects(spec):
    """``"1-6"``, ``"7,8"`` or ``"alice,bob"`` as a list of tokens and ints."""
    out = []
    for token in str(spec).split(","):
        token = token.strip()
        if not token:
            continue
        match = re.fullmatch(r"(\d+)-(\d+)", token)
        if match:
            lo, hi = int(match.group(1)), int(match.group(2))
            if hi < lo:
                raise UsageError(f"--subjects: empty range {token!r}")
            out += list(range(lo, hi + 1))
        else:
            out.append(int(token) if token.isdigit() else token)
    if not out:
        raise UsageError(f"--subjects: nothing selected by {spec!r}")
    return out


def _subset(data, idx):
    """The sequences ``idx`` of a loader's Bunch (every per-sequence key)."""
    from sklearn.utils import Bunch

    n = len(data.X if data.get("X") is not None else data.y)
    out = Bunch(**data)
    for key, value in data.items():
        if isinstance(value, (list, tuple)) and len(value) == n:
            out[key] = [value[i] for i in idx]
        elif isinstance(value, np.ndarray) and value.ndim >= 1 and len(value) == n:
            out[key] = value[idx]
    return out


def _select_subjects(data, spec, name):
    wanted = _parse_subjects(spec)
    groups = np.asarray(data.groups)
    keys = [g.item() if hasattr(g, "item") else g for g in groups]
    as_text = [str(k) for k in keys]
    idx = [
        i
        for i, (k, t) in enumerate(zip(keys, as_text))
        if k in wanted or t in map(str, wanted)
    ]
    missing = [w for w in wanted if w not in keys and str(w) not in as_text]
    if missing:
        available = ", ".join(sorted(set(as_text), key=lambda s: (len(s), s)))
        raise UsageError(
            f"--subjects: {', '.join(map(str, missing))} not in {name} "
            f"(subjects: {available})"
        )
    return _subset(data, idx)


def _detect_format(path):
    """``"chalearn"`` for ChaLearn samples, else ``"recordings"``."""
    if path.is_file():
        return "chalearn" if _CHALEARN_NAME.match(path.name) else "recordings"
    for entry in path.iterdir():
        if _CHALEARN_NAME.match(entry.name):
            return "chalearn"
    return "recordings"


def _loader_verbose(args):
    return 0 if args.quiet else 1


def _load_data(args, *, need_labels, need_skeletons=True):
    """The data named on the command line: ``(bunch, kind, name)``."""
    from skgesture import datasets

    spec = args.data
    verbose = _loader_verbose(args)
    if spec == "precog":
        data, kind, name = datasets.load_precog(verbose=verbose), "precog", "PRECOG"
    elif spec == "synthetic":
        data = datasets.make_gesture_streams(
            n_sequences=args.n_sequences,
            n_classes=args.n_classes,
            random_state=args.data_seed,
        )
        kind, name = "synthetic", "synthetic streams"
    else:
        path = Path(spec).expanduser()
        if not path.exists():
            raise UsageError(
                f"data {spec!r}: no such file or folder (the built-in sets are "
                f"{' and '.join(BUILTIN_DATA)})"
            )
        kind = args.format if args.format != "auto" else _detect_format(path)
        name = str(path)
        if kind == "chalearn":
            data = datasets.load_chalearn(path, verbose=verbose)
        else:
            load_recordings = getattr(datasets, "load_recordings", None)
            if load_recordings is None:
                raise UsageError(
                    "reading your own recordings needs "
                    "skgesture.datasets.load_recordings, which this installation "
                    "lacks"
                )
            data = load_recordings(path, layout=args.layout, verbose=verbose)
    if args.subjects:
        data = _select_subjects(data, args.subjects, name)
    if need_skeletons and data.get("X") is None:
        raise UsageError(f"{name} holds labels but no skeleton data")
    if len(data.X if data.get("X") is not None else data.y) == 0:
        raise UsageError(f"{name} holds no sequence")
    if need_labels and data.get("y") is None:
        raise UsageError(f"{name} has no annotations (labels) to train or score on")
    return data, kind, name


def _n_frames(data):
    return int(sum(len(x) for x in data.X))


def _fps(data):
    fps = data.get("fps")
    if fps is None or np.ndim(fps):
        return None
    return float(fps)


# -- models ----------------------------------------------------------------------


def _set_if_present(est, **params):
    """``est.set_params`` for the parameters it has."""
    known = est.get_params(deep=False)
    present = {k: v for k, v in params.items() if k in known and v is not None}
    if present:
        est.set_params(**present)
    return est


def _make_model(args, verbose):
    """The unfitted pipeline of ``--method`` with the size options applied."""
    import skgesture
    from skgesture._multiscale._classifier import default_window_network
    from skgesture._segmenter import default_frame_network

    method = args.method
    common = {"joints": args.joints, "random_state": args.seed, "verbose": verbose}
    if method == "recommended":
        make = getattr(skgesture, "make_recommended", None)
        if make is None:
            raise UsageError(
                "--method recommended is not available in this version of "
                "skgesture; use A, B, C or C-paper"
            )
        pipe = make(**common)
    elif method in ("A", "B"):
        make = skgesture.make_method_a if method == "A" else skgesture.make_method_b
        pipe = make(**common)
    else:
        pipe = skgesture.make_method_c(
            **common, paper=method == "C-paper", device=args.device
        )
    last = pipe.steps[-1][1]
    _set_if_present(last, device=args.device)
    if method in ("A", "B"):
        for step, default in (
            ("segmenter", default_frame_network),
            ("classifier", default_window_network),
        ):
            net = default()
            if args.fast:
                net.set_params(
                    hidden_layer_sizes=(FAST_MLP_HIDDEN,), activations=("tanh",)
                )
            _set_if_present(
                net,
                max_epochs=args.max_epochs or (FAST_MAX_EPOCHS if args.fast else None),
                device=args.device,
            )
            pipe.set_params(**{f"{step}__estimator": net})
    else:
        epochs = args.max_epochs or (FAST_MAX_EPOCHS if args.fast else None)
        _set_if_present(last, max_epochs=epochs)
        if args.fast:
            _set_if_present(last, hidden_sizes=FAST_TAGGER_HIDDEN)
    return pipe


def _load_model(args, data=None):
    """``(estimator, manifest)`` of the MODEL argument, checked against the data."""
    from skgesture._persistence import load_model, model_info

    path = Path(args.model).expanduser()
    info = model_info(path)
    layout = None if data is None else tuple(np.shape(data.X[0])[1:])
    model = load_model(
        path,
        trusted=args.trust,
        layout=layout,
        allow_version_mismatch=args.allow_version_mismatch,
    )
    if not hasattr(model, "predict"):
        raise UsageError(f"{path} holds a {type(model).__name__}, not a model")
    return model, info


def _target_names(data, info=None):
    names = data.get("target_names") if data is not None else None
    if names is None and info is not None:
        names = (info.get("metadata") or {}).get("target_names")
    return None if names is None else [str(n) for n in names]


def _predict(args, model, X):
    """Per-frame labels of every sequence, with a progress bar."""
    return [
        np.asarray(model.predict([x])[0])
        for x in _progress(args, X, "predicting", total=len(X))
    ]


# -- scores ----------------------------------------------------------------------


def _official_jaccard(data, kind, y_pred, mode):
    """Mean Jaccard index; from the label files' lines for ChaLearn data.

    Per-frame labels merge adjacent instances of one class, which changes the
    official score; ChaLearn data keep their labelled lines in ``segments``,
    which are scored as the official script scores the label files.
    """
    from skgesture.metrics import jaccard_index, jaccard_index_segments
    from skgesture.utils._segments import labels_to_segments

    if kind != "chalearn" or data.get("segments") is None:
        return float(jaccard_index(data.y, y_pred, mode=mode))
    has_labels = data.get("has_labels")
    scores = []
    for i, (seg, pred) in enumerate(zip(data.segments, y_pred)):
        if has_labels is not None and not has_labels[i]:
            continue
        seg = np.asarray(seg).reshape(-1, 3)
        if len(seg) == 0:
            continue
        gt = np.column_stack([seg[:, 0], seg[:, 1] + 1, seg[:, 2]])
        runs = np.asarray(labels_to_segments(pred)).reshape(-1, 3)
        lines = np.column_stack([runs[:, 0], runs[:, 1] + 1, runs[:, 2]])
        n_frames = int(data.n_frames[i]) if "n_frames" in data else len(pred)
        scores.append(
            jaccard_index_segments(
                gt, lines, n_frames, mode=mode, n_classes=max(20, int(seg[:, 0].max()))
            )
        )
    return float(np.nanmean(scores)) if scores else float("nan")


def _scores(data, kind, y_pred, target_names):
    """Every number ``evaluate`` reports, as a JSON-ready dict."""
    from skgesture.metrics import frame_accuracy, frame_confusion_matrix, segmental_f1
    from skgesture.utils._segments import labels_to_segments

    y_true = [np.asarray(y) for y in data.y]
    labels = np.unique(np.concatenate(y_true + [np.asarray(p) for p in y_pred]))
    n_named = len(target_names) if target_names else 0
    labels = np.union1d(labels, np.arange(n_named + 1)).astype(int)
    cm = frame_confusion_matrix(y_true, y_pred, labels=labels)
    true_counts = {int(c): 0 for c in labels}
    pred_counts = {int(c): 0 for c in labels}
    for y, p in zip(y_true, y_pred):
        for c, _, _ in labels_to_segments(y):
            true_counts[int(c)] += 1
        for c, _, _ in labels_to_segments(p):
            pred_counts[int(c)] += 1
    per_class = []
    for k, c in enumerate(labels):
        tp, support, predicted = cm[k, k], cm[k].sum(), cm[:, k].sum()
        precision = tp / predicted if predicted else 0.0
        recall = tp / support if support else 0.0
        f1 = 2 * precision * recall / (precision + recall) if tp else 0.0
        name = "rest" if c == 0 else _class_name(c, target_names)
        per_class.append(
            {
                "class": int(c),
                "name": name,
                "frames": int(support),
                "precision": float(precision),
                "recall": float(recall),
                "f1": float(f1),
                "gestures_true": true_counts[int(c)] if c else None,
                "gestures_predicted": pred_counts[int(c)] if c else None,
            }
        )
    return {
        "n_sequences": len(y_true),
        "n_frames": int(sum(len(y) for y in y_true)),
        "jaccard": {
            "official_2014": _official_jaccard(data, kind, y_pred, "official_2014"),
            "fp_penalised": _official_jaccard(data, kind, y_pred, "fp_penalised"),
        },
        "frame_accuracy": float(frame_accuracy(y_true, y_pred)),
        "f1": {
            f"{int(k * 100)}": float(segmental_f1(y_true, y_pred, overlap=k))
            for k in F1_OVERLAPS
        },
        "per_class": per_class,
    }


def _class_name(c, target_names):
    c = int(c)
    if target_names and 1 <= c <= len(target_names):
        return target_names[c - 1]
    return str(c)


def _print_scores(scores, header):
    print(header)
    print(f"  sequences {scores['n_sequences']}, frames {scores['n_frames']:,}")
    jac = scores["jaccard"]
    print(f"  Jaccard index (official 2014)  {jac['official_2014']:.4f}")
    print(f"  Jaccard index (fp-penalised)   {jac['fp_penalised']:.4f}")
    print(f"  frame accuracy                 {scores['frame_accuracy']:.4f}")
    f1 = "  ".join(f"F1@{k} {v:.4f}" for k, v in scores["f1"].items())
    print(f"  segmental {f1}")
    rows = scores["per_class"]
    width = max([len(r["name"]) for r in rows] + [5])
    print(
        f"\n  {'class':>5}  {'name':<{width}}  {'frames':>7}  {'precision':>9}  "
        f"{'recall':>6}  {'F1':>6}  {'gestures':>8}  {'found':>5}"
    )
    for r in rows:
        g = "" if r["gestures_true"] is None else r["gestures_true"]
        p = "" if r["gestures_predicted"] is None else r["gestures_predicted"]
        print(
            f"  {r['class']:>5}  {r['name']:<{width}}  {r['frames']:>7}  "
            f"{r['precision']:>9.3f}  {r['recall']:>6.3f}  {r['f1']:>6.3f}  "
            f"{g!s:>8}  {p!s:>5}"
        )


# -- subcommands -------------------------------------------------------------------


def cmd_train(args):
    from skgesture._persistence import save_model

    output = Path(args.output).expanduser()
    if output.exists() and not args.overwrite:
        raise UsageError(f"{output} exists; pass --overwrite to replace it")
    data, kind, name = _load_data(args, need_labels=True)
    verbose = 0 if args.quiet else 1
    pipe = _make_model(args, verbose)
    _info(
        args,
        f"training method {args.method} on {name}: {len(data.X)} sequences, "
        f"{_n_frames(data):,} frames",
    )
    start = time.perf_counter()
    pipe.fit(data.X, data.y)
    seconds = time.perf_counter() - start
    metadata = {
        "method": args.method,
        "data": args.data,
        "data_kind": kind,
        "subjects": args.subjects,
        "n_sequences": len(data.X),
        "n_frames": _n_frames(data),
        "target_names": _target_names(data),
        "fps": _fps(data),
        "seed": args.seed,
        "fit_seconds": round(seconds, 1),
    }
    save_model(pipe, output, metadata=metadata, overwrite=True)
    print(f"trained method {args.method} in {seconds:.1f} s; model written to {output}")
    return 0


def cmd_evaluate(args):
    data, kind, name = _load_data(args, need_labels=True)
    model, info = _load_model(args, data)
    names = _target_names(data, info)
    y_pred = _predict(args, model, data.X)
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
    y_pred = _predict(args, model, data.X)
    out.mkdir(parents=True, exist_ok=True)
    if fmt == "chalearn":
        from skgesture.datasets import write_chalearn_predictions

        paths = write_chalearn_predictions(
            y_pred, ids, out, n_frames=data.get("n_frames"), overwrite=args.overwrite
        )
    else:
        from skgesture.datasets import write_intervals

        names = _target_names(data, info)
        if names:
            (out / "classes.txt").write_text("".join(f"{n}\n" for n in names))
        paths = []
        for path, labels in zip(targets, y_pred):
            path.parent.mkdir(parents=True, exist_ok=True)
            if fmt == "intervals":
                paths.append(write_intervals(path, labels, overwrite=args.overwrite))
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
    fps = _fps(data)
    i = _sequence_index(data, args.sequence)
    sid = str(data.sample_ids[i])
    if kind == "skeleton":
        x = np.asarray(data.X[i])
        frame = args.frame if args.frame is not None else len(x) // 2
        if not 0 <= frame < len(x):
            raise UsageError(f"--frame {frame}: {sid} has frames 0..{len(x) - 1}")
        ax = plotting.plot_skeleton(
            x[frame], view=args.view, title=f"{sid}, frame {frame}"
        )
    else:
        model, info = _load_model(args, data)
        names = _target_names(data, info)
        if kind == "segmentation":
            ax = plotting.plot_segmentation(
                model,
                data.X[i],
                data.y[i],
                fps=fps,
                target_names=names,
                title=f"{sid}: activity segmentation",
            )
        else:
            n = len(data.X) if kind == "confusion" else args.max_sequences
            X, y = data.X[:n], data.y[:n]
            y_pred = _predict(args, model, X)
            if kind == "confusion":
                ax = plotting.plot_confusion_matrix(
                    y, y_pred, target_names=names, title=f"frame confusions, {name}"
                )
            else:
                ax = plotting.plot_timelines(
                    y,
                    y_pred,
                    sample_ids=[str(s) for s in data.sample_ids[:n]],
                    target_names=names,
                    fps=fps,
                    title=f"truth against prediction, {name}",
                )
    fig = ax.figure
    fig.tight_layout()
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=args.dpi)
    plt.close(fig)
    print(f"{kind} figure written to {output}")
    return 0


def _robot_mapping(args, recognizer):
    from skgesture.streaming import RobotCommand

    commands = list(RobotCommand)
    if args.commands:
        classes = [int(c) for c in _parse_subjects(args.commands)]
    else:
        classes = [int(c) for c in recognizer.classes_ if c != 0][: len(commands)]
    if len(classes) != len(commands):
        raise UsageError(
            f"--commands needs {len(commands)} gesture classes (one per command: "
            f"{', '.join(map(str, commands))}), got {len(classes)}"
        )
    return dict(zip(classes, commands))


def cmd_stream(args):
    from skgesture.streaming import StreamingRecognizer

    data, _, name = _load_data(args, need_labels=False)
    model, info = _load_model(args, data)
    i = _sequence_index(data, args.sequence)
    stream = np.asarray(data.X[i])
    fps = args.fps or _fps(data) or 30.0
    names = _target_names(data, info)
    recognizer = StreamingRecognizer(model, target_names=names)
    commander = robot = None
    if args.robot:
        from skgesture.streaming import ActionMap, GestureCommander, SimulatedRobot

        mapping = _robot_mapping(args, recognizer)
        action_map = ActionMap(
            mapping,
            min_confidence=args.min_confidence,
            refractory_frames=ROBOT_REFRACTORY_FRAMES,
        )
        robot = SimulatedRobot()
        commander = GestureCommander(recognizer, action_map, robot)
        for cls, command in mapping.items():
            _info(args, f"  gesture {_class_name(cls, names)} -> {command}")
    print(
        f"streaming {data.sample_ids[i]} of {name}: {len(stream)} frames at "
        f"{fps:g} fps (events come at most {recognizer.max_delay} frames after "
        f"a gesture ends)"
    )
    bar = _progress(args, range(len(stream)), "frames", unit="frame")
    write = print
    if not args.quiet:
        from tqdm.auto import tqdm

        write = tqdm.write
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
        for decision, result in pairs:
            if result is None:
                write(f"{'':>25}robot: ignored ({decision.reason})")
            elif result.accepted:
                write(f"{'':>25}robot: {result.command} -> {result.state_after}")
            else:
                write(f"{'':>25}robot: {result.command} refused ({result.reason})")

    start = time.perf_counter()
    for t in bar:
        if args.realtime:
            lag = start + t / fps - time.perf_counter()
            if lag > 0:
                time.sleep(lag)
        if commander is not None:
            pairs = commander.push(stream[t])
            report([d.event for d, _ in pairs], pairs)
        else:
            report(recognizer.push(stream[t]), [])
    if commander is not None:
        pairs = commander.flush()
        report([d.event for d, _ in pairs], pairs)
    else:
        report(recognizer.flush(), [])
    if hasattr(bar, "close"):
        bar.close()
    summary = f"{len(delays)} events"
    if delays:
        summary += (
            f"; delay mean {np.mean(delays):.1f}, max {max(delays)} frames "
            f"({max(delays) / fps:.2f} s)"
        )
    print(summary)
    if robot is not None:
        print(f"robot: {robot.status()}")
    return 0


def cmd_demo(args):
    """Summarise PRECOG, train on subjects 1-6, report on subjects 7-8."""
    from skgesture.datasets import load_precog

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
    pipe = _make_model(args, 0 if args.quiet else 1)
    _info(args, f"training method {args.method} on subjects {DEMO_TRAIN_SUBJECTS}")
    start = time.perf_counter()
    pipe.fit(train.X, train.y)
    seconds = time.perf_counter() - start
    y_pred = _predict(args, pipe, test.X)
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
            metadata={"method": args.method, "data": "precog", "target_names": list(
                map(str, data.target_names)
            )},
        )  # fmt: skip
        print(f"model written to {path}")
    return 0


# -- parser --------------------------------------------------------------------------


def _add_common(parser):
    # SUPPRESS: a subcommand's default does not overwrite the global option
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        default=argparse.SUPPRESS,
        help="no progress bars or status lines",
    )
    parser.add_argument(
        "--traceback",
        action="store_true",
        default=argparse.SUPPRESS,
        help="show the full traceback of an error (for bug reports)",
    )


def _add_data(parser, *, with_model=False):
    if with_model:
        parser.add_argument("model", help="model file written by `skgesture train`")
    parser.add_argument(
        "data",
        help="'precog' (bundled), 'synthetic', a ChaLearn folder or zip, or a "
        "folder of your own recordings",
    )
    parser.add_argument(
        "--format",
        choices=("auto", "chalearn", "recordings"),
        default="auto",
        help="how to read a path (default: ChaLearn if it holds SampleXXXX "
        "files, else recordings)",
    )
    parser.add_argument(
        "--layout",
        default="kinect_v1",
        help="skeleton layout of your recordings: kinect_v1, kinect_v2, azure, "
        "mediapipe, msr_action3d (default kinect_v1)",
    )
    parser.add_argument(
        "--subjects",
        help="only these subjects (groups), e.g. '1-6' or '7,8' for PRECOG",
    )
    parser.add_argument(
        "--n-sequences",
        type=int,
        default=40,
        help="synthetic data: number of sequences (default 40)",
    )
    parser.add_argument(
        "--n-classes",
        type=int,
        default=8,
        help="synthetic data: number of gesture classes (default 8)",
    )
    parser.add_argument(
        "--data-seed",
        type=int,
        default=0,
        help="synthetic data: seed (use another one for held-out data)",
    )


def _add_model_loading(parser):
    parser.add_argument(
        "--trust",
        action="append",
        metavar="TYPE",
        help="trust this type in the model file (repeatable; only for files "
        "whose origin you trust)",
    )
    parser.add_argument(
        "--allow-version-mismatch",
        action="store_true",
        help="load a model written by another skgesture version",
    )


def _add_method(parser):
    parser.add_argument(
        "--method",
        choices=METHODS,
        default="B",
        help="recommended (the toolkit's recommended tagger), A, B (the paper's "
        "multi-scale methods), C (BiLSTM tagger, CPU size) or C-paper (the "
        "paper's network); default B",
    )
    parser.add_argument(
        "--joints",
        choices=("paper11", "full20"),
        default="paper11",
        help="descriptor joints (default paper11, the paper's upper body)",
    )
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument(
        "--max-epochs", type=int, help="cap the training epochs of every network"
    )
    parser.add_argument(
        "--fast",
        action="store_true",
        help="small networks and few epochs: a quick trial, not a good model",
    )
    parser.add_argument(
        "--device", default="cpu", help="torch device of the training (default cpu)"
    )


def build_parser():
    """The argument parser of ``skgesture``."""
    parser = argparse.ArgumentParser(
        prog="skgesture",
        description="Find and name dynamic gestures in skeleton streams: train a "
        "model, score it, write predictions, draw figures, replay a stream.",
        epilog="Example: skgesture train precog --subjects 1-6 -o model.skg && "
        "skgesture evaluate model.skg precog --subjects 7,8",
    )
    parser.add_argument(
        "--version", action="version", version=f"skgesture {__version__}"
    )
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="no progress bars or status lines"
    )
    parser.add_argument(
        "--traceback", action="store_true", help="show the full traceback of an error"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("train", help="train a model and write the model file")
    _add_data(p)
    _add_method(p)
    p.add_argument(
        "-o", "--output", default="model.skg", help="model file (default model.skg)"
    )
    p.add_argument("--overwrite", action="store_true", help="replace the model file")
    _add_common(p)
    p.set_defaults(func=cmd_train)

    p = sub.add_parser(
        "evaluate", help="score a model: Jaccard indices, accuracy, F1@k, per class"
    )
    _add_data(p, with_model=True)
    _add_model_loading(p)
    p.add_argument("--json", action="store_true", help="print the scores as JSON")
    _add_common(p)
    p.set_defaults(func=cmd_evaluate)

    p = sub.add_parser(
        "predict", help="write prediction files (ChaLearn CSVs or intervals)"
    )
    _add_data(p, with_model=True)
    _add_model_loading(p)
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.add_argument(
        "--predict-format",
        "--as",
        dest="predict_format",
        choices=("auto", "chalearn", "intervals", "frames"),
        default="auto",
        help="chalearn: SampleXXXX_prediction.csv; intervals: <id>.labels.csv "
        "(start,end,label); frames: <id>.frames.csv (frame,label); auto: "
        "chalearn for ChaLearn data, else intervals",
    )
    p.add_argument("--overwrite", action="store_true", help="replace existing files")
    _add_common(p)
    p.set_defaults(func=cmd_predict)

    p = sub.add_parser("plot", help="draw a figure to PNG, SVG or PDF")
    p.add_argument(
        "kind",
        choices=PLOTS,
        help="timeline: truth against prediction per sequence; segmentation: "
        "the segmenter's score and periods (Methods A/B); confusion: frame "
        "confusion matrix; skeleton: one pose",
    )
    _add_data(p)
    p.add_argument("--model", help="model file (all figures but skeleton)")
    _add_model_loading(p)
    p.add_argument("-o", "--output", required=True, help="figure file")
    p.add_argument(
        "--sequence", default="0", help="sequence index or sample id (default 0)"
    )
    p.add_argument("--frame", type=int, help="skeleton: frame (default the middle)")
    p.add_argument(
        "--view",
        choices=("front", "side", "top", "3d"),
        default="front",
        help="skeleton: projection",
    )
    p.add_argument(
        "--max-sequences",
        type=int,
        default=DEFAULT_MAX_TIMELINES,
        help=f"timeline: sequences drawn (default {DEFAULT_MAX_TIMELINES})",
    )
    p.add_argument("--dpi", type=int, default=110, help="resolution (default 110)")
    p.add_argument("--overwrite", action="store_true", help="replace the figure")
    _add_common(p)
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser(
        "stream", help="replay a recording frame by frame and print the events"
    )
    _add_data(p, with_model=True)
    _add_model_loading(p)
    p.add_argument(
        "--sequence", default="0", help="sequence index or sample id (default 0)"
    )
    p.add_argument("--fps", type=float, help="frame rate (default: the data's)")
    p.add_argument("--realtime", action="store_true", help="replay at the frame rate")
    p.add_argument(
        "--robot",
        action="store_true",
        help="drive the simulated pick-and-place robot with the events",
    )
    p.add_argument(
        "--commands",
        help="--robot: the 5 gesture classes giving move_to_tool, close_gripper, "
        "carry_tool, open_gripper, return_home (default the first 5 classes)",
    )
    p.add_argument(
        "--min-confidence",
        type=float,
        default=0.5,
        help="--robot: confidence floor of a command (default 0.5)",
    )
    _add_common(p)
    p.set_defaults(func=cmd_stream)

    p = sub.add_parser(
        "demo", help="train on PRECOG subjects 1-6 and report on subjects 7-8"
    )
    _add_method(p)
    p.add_argument("-o", "--output", help="also write the model file")
    _add_common(p)
    p.set_defaults(func=cmd_demo)
    return parser


def main(argv=None):
    """Run the command line.

    Parameters
    ----------
    argv : list of str or None, default=None
        The arguments (without the program name); None reads ``sys.argv``.

    Returns
    -------
    int
        The exit status: 0 on success, 1 for an error, 2 for a usage error.

    Examples
    --------
    >>> from skgesture._cli import main
    >>> main(["--version"])  # doctest: +ELLIPSIS
    skgesture ...
    0
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error
        return exc.code if isinstance(exc.code, int) else 2
    if args.command is None:
        parser.print_usage(sys.stderr)
        print("skgesture: error: give a command, e.g. skgesture demo", file=sys.stderr)
        return 2
    with _warnings_as_lines():
        try:
            return args.func(args) or 0
        except KeyboardInterrupt:
            print("skgesture: interrupted", file=sys.stderr)
            return 130
        except (UsageError, OSError, ValueError, ImportError) as exc:
            if args.traceback:
                raise
            print(f"skgesture {args.command}: error: {_one_line(exc)}", file=sys.stderr)
            return 1
