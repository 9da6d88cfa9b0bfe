"""What the subcommands of the ``skgesture`` command line share.

The error for a user mistake (:class:`UsageError`), status lines and progress
bars, reading the data named on the command line, building the model of
``--method`` and loading a model file, and the scores that ``evaluate`` and
``demo`` print (computed by :mod:`skgesture.metrics`). The subcommands are in
:mod:`skgesture._cli_commands`, the parser and ``main`` in :mod:`skgesture._cli`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import re
import sys
from pathlib import Path

import numpy as np

__all__ = ["UsageError"]

BUILTIN_DATA = ("precog", "synthetic")
F1_OVERLAPS = (0.1, 0.25, 0.5)
FAST_MLP_HIDDEN = 32  # units of the one-layer networks of --fast (Methods A/B)
FAST_TAGGER_HIDDEN = (16,)  # --fast tagger (Methods C and recommended)
FAST_MAX_EPOCHS = 60
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
    which are scored as the official script scores the label files. Samples
    without a labelled gesture are left out (the official script cannot score
    them).
    """
    from skgesture.metrics import jaccard_index

    if kind != "chalearn" or data.get("segments") is None:
        return float(jaccard_index(data.y, y_pred, mode=mode))
    has_labels = data.get("has_labels")
    scored = [
        i
        for i, seg in enumerate(data.segments)
        if (has_labels is None or has_labels[i]) and len(seg)
    ]
    if not scored:
        return float("nan")
    scores = jaccard_index(
        [data.y[i] for i in scored],
        [y_pred[i] for i in scored],
        mode=mode,
        per_sequence=True,
        true_segments=[data.segments[i] for i in scored],
    )
    return float(np.nanmean(scores))


def _scores(data, kind, y_pred, target_names):
    """Every number ``evaluate`` reports, as a JSON-ready dict."""
    from skgesture.metrics import frame_accuracy, per_class_report, segmental_f1

    y_true = [np.asarray(y) for y in data.y]
    labels = np.unique(np.concatenate(y_true + [np.asarray(p) for p in y_pred]))
    n_named = len(target_names) if target_names else 0
    labels = np.union1d(labels, np.arange(n_named + 1)).astype(int)
    report = per_class_report(y_true, y_pred, labels=labels)
    per_class = [
        {
            "class": int(c),
            "name": "rest" if c == 0 else _class_name(c, target_names),
            "frames": int(report.support[k]),
            "precision": float(report.precision[k]),
            "recall": float(report.recall[k]),
            "f1": float(report.f1[k]),
            "gestures_true": int(report.true_gestures[k]) if c else None,
            "gestures_predicted": int(report.predicted_gestures[k]) if c else None,
        }
        for k, c in enumerate(report.labels)
    ]
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
