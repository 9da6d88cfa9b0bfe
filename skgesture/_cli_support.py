"""What the subcommands of the ``skgesture`` command line share.

The error for a user mistake (:class:`UsageError`), status lines and progress
bars (as plain lines where stderr is no terminal: :class:`ProgressLines`),
reading the data named on the command line, the joints of ``--joints auto``,
building the model of ``--method`` and loading a model file, and the scores
that ``evaluate`` and ``demo`` print (computed by :mod:`skgesture.metrics`).
The subcommands are in :mod:`skgesture._cli_commands`, the parser and
``main`` in :mod:`skgesture._cli`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import contextlib
import re
import sys
import time
import warnings
from pathlib import Path

import numpy as np

__all__ = ["UsageError", "ProgressLines", "plain_progress"]

BUILTIN_DATA = ("precog", "synthetic")
F1_OVERLAPS = (0.1, 0.25, 0.5)
FAST_MLP_HIDDEN = 32  # units of the one-layer networks of --fast (Methods A/B)
FAST_TAGGER_HIDDEN = (16,)  # --fast tagger (Methods C and recommended)
FAST_MAX_EPOCHS = 60
# --fast recommended model: a one-stage TCN on fewer, smaller batches (a small
# fraction of the work per epoch of the default's 2 stages of 8 layers).
FAST_TCN = {"tcn_stages": 1, "tcn_layers": 6, "steps_per_epoch": 5, "batch_size": 8}
# What --fast gives up, said before such a training (docs/cli.md has the measured cost).
FAST_TRADEOFF = {
    "recommended": "a one-stage, 6-layer temporal network instead of 2 stages of 8, "
    "trained on 300 batches of 8 crops instead of 600 of 16",
    "A": "networks of one 32-unit layer instead of the paper's sizes, 60 epochs",
    "B": "networks of one 32-unit layer instead of the paper's sizes, 60 epochs",
    "C": "a one-layer, 16-unit recurrent network, 60 epochs",
}
PROGRESS_LINE_SECONDS = 10.0  # a bar's state at most this often, stderr no terminal
# What tqdm writes to redraw its bars: a carriage return before each state, and
# newlines and "cursor up" around the states of nested bars.
_CURSOR_UP = "\x1b[A"
_BAR_CONTROL = re.compile("(\r|\n|\x1b\\[A)")
_CHALEARN_NAME = re.compile(
    r"^Sample\d{4,5}(\.zip|_(skeleton|labels|data|prediction)\.csv)?$", re.I
)


class UsageError(Exception):
    """A mistake on the command line; reported as one line, no traceback."""


# -- output ----------------------------------------------------------------------


def fast_tradeoff(method):
    """The line ``train --fast`` prints: what the quick model gives up."""
    what = FAST_TRADEOFF.get(method, FAST_TRADEOFF["C"])
    return (
        f"--fast: {what}; a quick trial of the pipeline, not a model to deploy "
        "(expect a lower Jaccard; docs/cli.md)"
    )


def _info(args, message):
    """A progress or status line (stderr, silenced by --quiet)."""
    if not args.quiet:
        print(message, file=sys.stderr, flush=True)


def _progress(args, iterable, desc, total=None, unit="seq"):
    """A tqdm bar over ``iterable`` (stderr), or the bare iterable with --quiet.

    Where stderr is no terminal the bar's states become plain lines
    (:func:`plain_progress`).
    """
    if args.quiet:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, unit=unit, leave=False)


def _live_bars():
    """Whether progress bars are redrawn in place (stderr is a terminal)."""
    return not isinstance(sys.stderr, ProgressLines)


class ProgressLines:
    """A text stream that writes progress bars as plain lines to another one.

    tqdm redraws a bar in place: a carriage return (``\\r``) before each
    state, and newlines and "cursor up" escapes around the states of nested
    bars. In a log file or a pipe that makes one long line full of control
    characters. This stream passes ordinary text through and writes each bar
    as whole lines: its first state at once, then its latest state at most
    every ``interval`` seconds, and its last state when the bar is cleared or
    closed, before the next ordinary line and at :meth:`finish`. Nothing it
    writes holds a carriage return or an escape.

    Parameters
    ----------
    target : file-like
        The stream written to (``sys.stderr``).
    interval : float, default=PROGRESS_LINE_SECONDS
        Seconds between two lines of one bar, at least.
    clock : callable, default=time.monotonic
        The time in seconds.

    Examples
    --------
    >>> import io
    >>> from tqdm import tqdm
    >>> out = io.StringIO()
    >>> lines = ProgressLines(out, interval=60)
    >>> for _ in tqdm(range(3), desc="work", file=lines, leave=False,
    ...               mininterval=0, bar_format="{desc}: {n}/{total}"):
    ...     pass
    >>> lines.finish()
    >>> print(out.getvalue(), end="")
    work: 0/3
    work: 3/3
    """

    def __init__(self, target, interval=PROGRESS_LINE_SECONDS, clock=time.monotonic):
        self.target = target
        self.interval = interval
        self.clock = clock
        self._line = ""  # ordinary text of the current line, not yet ended
        self._row = 0  # the line below the first bar that tqdm's cursor is on
        self._bars = {}  # row -> _BarLines
        self._after_bar = False  # the last thing written was a bar's

    def write(self, text):
        """Write ``text``; a bar's state follows a carriage return.

        tqdm draws one state with one call (``"\\r" + state``), so the text
        after a carriage return, up to the end of the call or the next control
        character, is one state of the bar on the current row.
        """
        text = str(text)
        state = None  # the state being drawn by this call
        for token in _BAR_CONTROL.split(text):
            if token == "\r":
                if state is not None:
                    self._bar_state(state)
                state = ""
            elif token in ("\n", _CURSOR_UP):
                if state is not None:
                    self._bar_state(state)
                    state = None
                if token == _CURSOR_UP:
                    self._row = max(self._row - 1, 0)
                elif self._line or not self._after_bar:
                    self._end_line()
                else:  # a bare newline between bars moves to the next bar
                    self._row += 1
            elif state is not None:
                state += token
            elif token:
                self._line += token
                self._after_bar = False
        if state is not None:
            self._bar_state(state)
        return len(text)

    def _emit(self, line):
        self.target.write(line + "\n")

    def _bar_state(self, state):
        state = state.strip()
        self._after_bar = True
        bar = self._bars.setdefault(self._row, _BarLines())
        if not state:  # the bar was cleared: its last state, and a new bar may come
            bar.write_pending(self._emit)
            del self._bars[self._row]
            return
        now = self.clock()
        bar.pending = state
        if bar.time is None or now - bar.time >= self.interval:
            bar.write_pending(self._emit)
            bar.time = now

    def _write_pending(self):
        for row in sorted(self._bars):
            self._bars[row].write_pending(self._emit)
        self._bars.clear()

    def _end_line(self):
        self._write_pending()
        self._emit(self._line)
        self._line = ""
        self._row = 0
        self._after_bar = False

    def flush(self):
        """Flush the target (a bar's state waiting for its interval stays)."""
        self.target.flush()

    def finish(self):
        """Write the bars' last states and any unfinished line; flush."""
        self._write_pending()
        if self._line:
            self._emit(self._line)
            self._line = ""
        self.flush()

    def isatty(self):
        """False: bars are written as lines."""
        return False

    def __getattr__(self, name):  # fileno, encoding, ...: the target's
        return getattr(self.target, name)


class _BarLines:
    """What :class:`ProgressLines` knows of one bar."""

    def __init__(self):
        self.pending = None  # the latest state, not yet written
        self.time = None  # when a state was last written
        self.written = None  # the progress part of the last state written

    def write_pending(self, emit):
        """Write the pending state, unless it shows no progress since the last.

        The progress part is the state up to its times (``" ["``): a bar's
        final redraw on close repeats its last state with another rate.
        """
        if self.pending is None:
            return
        progress = self.pending.split(" [", 1)[0]
        if progress != self.written:
            emit(self.pending)
            self.written = progress
        self.pending = None


def _isatty(stream):
    try:
        return bool(stream.isatty())
    except (AttributeError, OSError, ValueError):
        return False


@contextlib.contextmanager
def plain_progress(args):
    """Progress bars as plain lines (:class:`ProgressLines`) where stderr is
    no terminal, for the duration of the block.

    tqdm writes to ``sys.stderr`` as it is when a bar starts, so the bars of
    the library (training epochs, files read) are plain lines too.
    """
    target = sys.stderr
    if getattr(args, "quiet", False) or _isatty(target):
        yield None
        return
    lines = ProgressLines(target)
    sys.stderr = lines
    try:
        yield lines
    finally:
        if sys.stderr is lines:
            sys.stderr = target
        lines.finish()


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
            fps = {"fps": args.fps} if getattr(args, "fps", None) else {}
            data = load_recordings(path, layout=args.layout, verbose=verbose, **fps)
    if getattr(args, "fps", None):  # --fps replaces the rate the data say
        from sklearn.utils import Bunch

        data = Bunch(**data)  # a copy: a loader may cache its Bunch
        data["fps"] = float(args.fps)
    if args.subjects:
        data = _select_subjects(data, args.subjects, name)
    if need_skeletons and data.get("X") is None:
        raise UsageError(f"{name} holds labels but no skeleton data")
    if len(data.X if data.get("X") is not None else data.y) == 0:
        raise UsageError(f"{name} holds no sequence")
    if need_labels and data.get("y") is None:
        raise UsageError(f"{name} has no annotations (labels) to train or score on")
    if need_skeletons and _n_frames(data) < COMPILED_MIN_FRAMES:
        import skgesture._descriptor._compute as compute

        compute.USE_COMPILED = False  # restored when the command ends (_cli._run)
    return data, kind, name


# Loading the compiled descriptor kernel (numba) costs about 0.7 s in a fresh
# process, in which the numpy implementation computes 170,000 frames (250,000
# a second): a command on fewer frames than this computes the descriptor in
# numpy (the same descriptor, to 1e-12), for the whole command.
COMPILED_MIN_FRAMES = 100_000


def _n_frames(data):
    return int(sum(len(x) for x in data.X))


def _fps(data, i=None):
    """The data's frame rate: one number, or per sequence (ChaLearn).

    Per-sequence rates give sequence ``i``'s, or their common value, or
    None when they differ.
    """
    fps = None if data is None else data.get("fps")
    if fps is None:
        return None
    if np.ndim(fps):
        fps = np.asarray(fps, dtype=float)
        if i is not None:
            return float(fps[i])
        return float(fps[0]) if len(fps) and np.all(fps == fps[0]) else None
    return float(fps)


def _frame_rate(args, data, kind, info=None, i=None):
    """The frame rate of the data, for the seconds of an axis or an event.

    ``--fps`` when given; else the rate the data know (ChaLearn's data
    files, PRECOG's and the synthetic streams' nominal rates), except for
    your own recordings, whose loader only assumes 30 fps: for them the rate
    recorded in the model file (the training data's) comes first. None when
    nothing knows.
    """
    if getattr(args, "fps", None):
        return float(args.fps)
    model_fps = (((info or {}).get("metadata")) or {}).get("fps")
    if model_fps is not None and not model_fps > 0:
        model_fps = None
    if kind == "recordings" and model_fps:
        return float(model_fps)
    fps = _fps(data, i)
    return fps if fps else (float(model_fps) if model_fps else None)


def _input_rates(args, data, kind):
    """The frame rate of every sequence, for the model; None where unknown.

    ``--fps`` when given (it also replaces the data's, :func:`_load_data`); else
    the rate the data know (PRECOG's, the synthetic streams', ChaLearn's data
    files, one per sequence), except for your own recordings, whose loader only
    assumes 30 fps: for them nothing is known (None), and the model takes the
    frames as they come.
    """
    n = len(data.X)
    if getattr(args, "fps", None):
        return [float(args.fps)] * n
    fps = data.get("fps")
    if kind == "recordings" or fps is None:
        return None
    rates = np.broadcast_to(np.asarray(fps, dtype=float), (n,))
    return [float(r) if np.isfinite(r) and r > 0 else None for r in rates]


def _training_rate(args, data, kind):
    """The rate ``train`` fits at: the data's one rate (or ``--fps``), else 30."""
    from skgesture._rate import DEFAULT_FPS, same_rate

    rates = _input_rates(args, data, kind)
    if rates is None:
        return float(data.get("fps") or DEFAULT_FPS)
    known = [r for r in rates if r is not None]
    if not known:
        return DEFAULT_FPS
    if any(not same_rate(r, known[0]) for r in known):
        raise UsageError(
            f"the training sequences have different frame rates ({min(known):g} to "
            f"{max(known):g} fps) and a model has one; train on sequences of one "
            f"rate, or give --fps"
        )
    return known[0]


def _model_fps(model, info=None):
    """The rate a model was trained at: its ``fps_``, else the model file's."""
    fps = getattr(model, "fps_", None)
    if fps is None:
        fps = ((info or {}).get("metadata") or {}).get("fps")
    return float(fps) if fps and fps > 0 else None


def _warn_unknown_rate(args, data, kind, model_fps, what="the model's rate"):
    """One warning line when no rate is known for recordings whose frame
    numbers suggest another rate than ``model_fps``.

    Frame numbers that advance by ``k`` per line, with a counter at
    ``model_fps``, are a recording at ``model_fps / k``.
    """
    from skgesture._rate import estimate_fps

    if getattr(args, "fps", None) or kind != "recordings" or not model_fps:
        return
    numbers = data.get("frame_numbers") or []
    for sid, nums in zip(data.get("sample_ids") or [], numbers):
        if nums is None or len(nums) < 3:
            continue
        suggested = estimate_fps(np.asarray(nums, dtype=float) / model_fps)
        if suggested is None or abs(suggested - model_fps) <= 0.05 * model_fps:
            continue
        step = model_fps / suggested
        warnings.warn(
            f"{sid}: no frame rate is known (pass --fps), and its frame numbers "
            f"advance by {step:g} per frame: a recording at {suggested:g} fps if "
            f"they count frames at {model_fps:g} fps ({what}); its frames are "
            f"taken as {model_fps:g} fps",
            UserWarning,
            stacklevel=2,
        )
        return


# -- models ----------------------------------------------------------------------


def _data_joints(data):
    """The joints of ``--joints auto``: those the data track.

    ``"full20"`` when each of the 20 Kinect v1 joints has a position (finite,
    not all zero) in some frame, as every loader gives them; ``"paper11"``
    when only the paper's 11 upper-body joints do (Kinect's seated mode,
    say). Frames of another shape get ``"full20"``, for the model to reject.
    """
    from skgesture.layouts import KINECT_V1, N_COORDS, PAPER_11

    shape = (KINECT_V1.n_joints, N_COORDS)
    tracked = np.zeros(KINECT_V1.n_joints, dtype=bool)
    for x in data.X:
        x = np.ma.filled(np.ma.asarray(x, dtype=float), np.nan)
        if x.shape[1:] != shape:
            return "full20"
        seen = np.isfinite(x).all(axis=-1) & (x != 0).any(axis=-1)
        tracked |= seen.any(axis=0)
        if tracked.all():
            return "full20"
    missing = [n for n, t in zip(KINECT_V1.joint_names, tracked) if not t]
    if not set(PAPER_11.joints) & set(missing):
        return "paper11"
    raise UsageError(
        f"--joints auto: the data never track {', '.join(missing)}, not even "
        f"the 11 upper-body joints of paper11 are all there; give --joints "
        f"paper11 or full20 to train anyway"
    )


def _joints(args, data):
    """``--joints``, ``auto`` resolved on ``data``."""
    return _data_joints(data) if args.joints == "auto" else args.joints


def _check_device(device):
    """``--device`` as torch reads it, or a :class:`UsageError` saying why not.

    Checked before any work: torch would only fail in the first epoch, with an
    ``AssertionError`` or ``RuntimeError`` that reads like a bug.
    """
    import torch

    try:
        dev = torch.device(device)
    except (RuntimeError, ValueError, TypeError):
        raise UsageError(
            f"--device {device}: not a torch device (e.g. cpu, cuda, cuda:1, mps)"
        ) from None
    if dev.type == "cuda":
        if not torch.cuda.is_available():
            raise UsageError(
                f"--device {device}: CUDA is not available to this torch "
                f"({torch.__version__}); use --device cpu"
            )
        if dev.index is not None and dev.index >= torch.cuda.device_count():
            raise UsageError(
                f"--device {device}: there are {torch.cuda.device_count()} CUDA "
                f"device(s), cuda:0 to cuda:{torch.cuda.device_count() - 1}"
            )
    elif dev.type == "mps" and not torch.backends.mps.is_available():
        raise UsageError(f"--device {device}: MPS is not available; use --device cpu")
    return dev


def _set_if_present(est, **params):
    """``est.set_params`` for the parameters it has."""
    known = est.get_params(deep=False)
    present = {k: v for k, v in params.items() if k in known and v is not None}
    if present:
        est.set_params(**present)
    return est


def _make_model(args, verbose, joints):
    """The unfitted pipeline of ``--method`` on ``joints``, size options applied."""
    import skgesture
    from skgesture._multiscale._classifier import default_window_network
    from skgesture._segmenter import default_frame_network

    method = args.method
    common = {"joints": joints, "random_state": args.seed, "verbose": verbose}
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
            if method == "recommended":
                _set_if_present(last, **FAST_TCN)
    return pipe


def _load_model(args, data=None, *, frame_shape=None):
    """``(estimator, manifest)`` of the MODEL argument, checked against the
    frames of the data (or ``frame_shape``, the shape of one frame)."""
    from skgesture._persistence import load_model, model_info

    path = Path(args.model).expanduser()
    info = model_info(path)
    layout = frame_shape
    if data is not None:
        layout = tuple(np.shape(data.X[0])[1:])
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
    """The class names of the data, else those of the model file, else None.

    Recordings read without annotations have no names (an empty list): the
    model's, written when it was trained, name its classes then.
    """
    names = data.get("target_names") if data is not None else None
    if not names and info is not None:
        names = (info.get("metadata") or {}).get("target_names")
    return [str(n) for n in names] if names else None


def _model_target_names(info):
    """The class names recorded in the model file, or None."""
    names = (info.get("metadata") or {}).get("target_names") if info else None
    return [str(n) for n in names] if names else None


def _min_gesture_frames(model):
    """``(frames, why)``: the shortest recording in which ``model`` can find a
    gesture (the segmenter's ``min_length``, a tagger's ``min_run``), or None."""
    from skgesture import ActivitySegmenter

    steps = [est for _, est in getattr(model, "steps", [("model", model)])]
    for est in steps:
        if isinstance(est, ActivitySegmenter):
            n = int(est.min_length)
            return n, f"its segmenter drops activity shorter than min_length={n}"
    min_run = getattr(steps[-1], "min_run", None)
    if isinstance(min_run, (int, np.integer)) and min_run > 1:
        n = int(min_run)
        return n, f"its tagger drops runs shorter than min_run={n}"
    return None


def _rate_options(model, rates, info=None):
    """``predict``'s keyword arguments for each sequence: ``{"fps": rate}``
    where the rate is known and the model knows its own. A model file written
    before models knew their rate takes the frames as they are, with a warning
    where its file records another training rate than the data's."""
    from skgesture._rate import same_rate

    if rates is None:
        return None
    if getattr(model, "fps_", None) is None:
        trained = _model_fps(model, info)
        other = [
            r for r in rates if trained and r is not None and not same_rate(r, trained)
        ]
        if other:
            warnings.warn(
                f"the model was trained at {trained:g} fps and the data are at "
                f"{other[0]:g} fps, but the model file predates resampling: the "
                f"data are predicted at their own frames",
                UserWarning,
                stacklevel=3,
            )
        return None
    return [{} if r is None else {"fps": r} for r in rates]


def _predict(args, model, X, ids=None, rates=None, info=None):
    """Per-frame labels of every sequence, with a progress bar; a recording too
    short for the model to find any gesture in gets a warning that says so.

    ``rates``: the frame rate of each sequence (None where unknown), passed to
    the model, which resamples to its own rate (docs/streaming.md, "Frame
    rates").
    """
    from skgesture._rate import RateMap, same_rate

    options = _rate_options(model, rates, info)
    floor = _min_gesture_frames(model)
    if floor is not None:
        n_min, why = floor
        for i, x in enumerate(X):
            n = len(x)
            rate = options[i].get("fps") if options else None
            if rate is not None and not same_rate(rate, model.fps_):
                n = RateMap(rate, model.fps_).n_out(n)  # at the model's rate
            if n < n_min:
                sid = f"recording {i}" if ids is None else str(ids[i])
                warnings.warn(
                    f"{sid}: {len(x)} frames, shorter than the {n_min} frames in "
                    f"which this model can find a gesture ({why}); it is predicted "
                    f"as rest throughout",
                    UserWarning,
                    stacklevel=2,
                )
    options = options or [{}] * len(X)
    return [
        np.asarray(model.predict([x], **kw)[0])
        for x, kw in zip(_progress(args, X, "predicting", total=len(X)), options)
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
