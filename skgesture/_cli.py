"""The ``skgesture`` command line: train, evaluate, predict, plot, stream, demo.

Run ``skgesture --help`` (or ``python -m skgesture --help``); ``docs/cli.md``
has a walk-through. Every subcommand is a thin layer over the public API:
data come from :mod:`skgesture.datasets`, models from the ``make_*`` factories,
model files from :func:`skgesture.save_model` / :func:`skgesture.load_model`,
scores from :mod:`skgesture.metrics` and figures from :mod:`skgesture.plotting`.

A user mistake (a missing folder, a file that is not a model, an unknown
method, a model from another version, bad data) ends with one line on stderr
and exit status 1; a wrong option ends with the subcommand's usage and one
line (the closest option suggested) and status 2; ``--traceback`` shows the
full traceback instead. An error that is no user mistake (a bug) shows its
traceback. Progress bars go to stderr (plain lines when stderr is not a
terminal), results to stdout; a reader that goes away early (``| head``)
ends the program quietly with status 141.

This module holds the argument parser, :func:`main` and its error reporting;
the subcommands are in :mod:`skgesture._cli_commands`, and what they share
(reading the data, building and loading models, the scores) in
:mod:`skgesture._cli_support`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import contextlib
import difflib
import linecache
import os
import re
import sys
import warnings
from pathlib import Path

from skgesture._cli_commands import (
    cmd_demo,
    cmd_evaluate,
    cmd_plot,
    cmd_predict,
    cmd_stream,
    cmd_train,
)
from skgesture._cli_support import UsageError, plain_progress
from skgesture._version import __version__

__all__ = ["main"]

METHODS = ("recommended", "A", "B", "C", "C-paper")
DEFAULT_METHOD = "recommended"  # make_recommended, as README and docs/choosing.md
JOINTS = ("auto", "paper11", "full20")
EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a shell shows for `yes | head -1`
PLOTS = ("timeline", "segmentation", "confusion", "skeleton")
FPS_HELP = (
    "frame rate of the data (default: what the data say; your own recordings: "
    "the model's, else 30)"
)
FPS_RATE_HELP = (
    "frame rate of the data (default: what the data say; your own recordings: "
    "the model's); the model resamples data at another rate to its own"
)
DEFAULT_MAX_TIMELINES = 12  # sequences drawn by `plot timeline`


# -- errors and warnings --------------------------------------------------------


def _one_line(exc):
    """The message of an exception as one line, without ``[Errno N]``."""
    if isinstance(exc, OSError) and exc.strerror and exc.filename:
        text = f"{exc.strerror}: {exc.filename}"
    else:
        text = str(exc) or type(exc).__name__
    text = re.sub(r"^\[Errno \d+\]\s*", "", text)
    return " ".join(text.split())


# Packages whose deliberate ``raise TypeError(...)`` is input validation: a
# TypeError raised there by a ``raise`` statement is a user mistake, any other
# TypeError (one Python raises inside an expression) a bug.
_VALIDATING_PACKAGES = ("skgesture", "sklearn")


def _package_dirs():
    dirs = []
    for name in _VALIDATING_PACKAGES:
        module = sys.modules.get(name)
        if getattr(module, "__file__", None):
            dirs.append(Path(module.__file__).resolve().parent)
    return dirs


def _raised_by_validation(exc):
    """Whether ``exc`` comes from a ``raise`` statement of skgesture or sklearn."""
    tb = exc.__traceback__
    if tb is None:
        return False
    while tb.tb_next is not None:
        tb = tb.tb_next
    filename = tb.tb_frame.f_code.co_filename
    try:
        path = Path(filename).resolve()
    except (OSError, ValueError):
        return False
    if not any(d in path.parents for d in _package_dirs()):
        return False
    return linecache.getline(filename, tb.tb_lineno).lstrip().startswith("raise ")


def _library_error_types():
    """The error classes of skgesture that are user mistakes, where loaded.

    Both are ValueErrors today; naming them keeps them one-line errors
    whatever their bases become. Looked up in ``sys.modules``: an error of a
    module that was never imported cannot have been raised.
    """
    found = []
    for module, name in (
        ("skgesture._persistence", "ModelFileError"),
        ("skgesture.datasets._base", "DataFormatError"),
    ):
        cls = getattr(sys.modules.get(module), name, None)
        if isinstance(cls, type) and issubclass(cls, Exception):
            found.append(cls)
    return tuple(found)


def _is_user_error(exc):
    """Whether ``exc`` is a mistake of the user (one line) rather than a bug.

    A :class:`~skgesture._cli_support.UsageError`, an ``OSError`` (a missing
    or unreadable file), a ``ValueError`` (bad data, a damaged or foreign
    model file: ``ModelFileError``, ``DataFormatError``), an ``ImportError``
    (a missing optional dependency), and a ``TypeError`` raised on purpose by
    the input validation of skgesture or scikit-learn (a model file holding
    something that cannot stream, say). Any other exception is a bug.
    """
    if isinstance(exc, (UsageError, OSError, ValueError, ImportError)):
        return True
    if isinstance(exc, _library_error_types()):
        return True
    return isinstance(exc, TypeError) and _raised_by_validation(exc)


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


def _positive(text):
    """An option's value as a positive finite float (argparse ``type``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r} is not a positive number")
    return value


def _size(text):
    """``--size WIDTH,HEIGHT`` in inches as a pair of positive floats."""
    parts = text.replace("x", ",").split(",")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give WIDTH,HEIGHT in inches, e.g. 12,4"
        )
    return tuple(_positive(part.strip()) for part in parts)


def _add_fps(parser, help):
    parser.add_argument("--fps", type=_positive, metavar="FPS", help=help)


def _add_data(parser, *, with_model=False, optional=False):
    if with_model:
        parser.add_argument("model", help="model file written by `skgesture train`")
    parser.add_argument(
        "data",
        nargs="?" if optional else None,
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
        help="skeleton layout of your recordings (or of a live --source): "
        "kinect_v1, kinect_v2, azure, mediapipe, msr_action3d (default "
        "kinect_v1)",
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
        default=DEFAULT_METHOD,
        help="recommended (the toolkit's recommended model, make_recommended; "
        "the default), A, B (the paper's multi-scale methods), C (BiLSTM "
        "tagger, CPU size) or C-paper (the paper's network)",
    )
    parser.add_argument(
        "--joints",
        choices=JOINTS,
        default="auto",
        help="joints the model reads: full20 (all 20 Kinect joints), paper11 "
        "(the paper's 11 upper-body joints) or auto (the default): full20 "
        "when the data track all 20 joints, as every loader gives them, "
        "paper11 when they track only the upper body",
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


def _subcommand(sub, name, help):
    """A subparser; like every parser here it takes no abbreviated options."""
    return sub.add_parser(name, help=help, description=help, allow_abbrev=False)


def build_parser():
    """The argument parser of ``skgesture``.

    Options must be spelt out (``allow_abbrev=False`` on every parser):
    ``--data 3`` is an unknown option, not ``--data-seed 3``. The parser's
    ``commands`` attribute maps each subcommand to its parser.
    """
    parser = argparse.ArgumentParser(
        prog="skgesture",
        allow_abbrev=False,
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

    p = _subcommand(sub, "train", "train a model and write the model file")
    _add_data(p)
    _add_fps(p, FPS_HELP + " (written to the model file)")
    _add_method(p)
    p.add_argument(
        "--background",
        action="append",
        metavar="DIR",
        help="recordings of ordinary work with no command in them (a folder of "
        "your own recordings, read like DATA; labels are not needed), learnt "
        "as rest so that everyday motion fires no gesture; 'synthetic' makes 12 "
        "background sequences from the training recordings that the whole model "
        "learns, as make_recommended(background_for='model') does "
        "(skgesture.datasets.make_background; the recommended model's run namer "
        "learns such sequences by default). May be given more than once",
    )
    p.add_argument(
        "-o", "--output", default="model.skg", help="model file (default model.skg)"
    )
    p.add_argument("--overwrite", action="store_true", help="replace the model file")
    _add_common(p)
    p.set_defaults(func=cmd_train)

    p = _subcommand(
        sub, "evaluate", "score a model: Jaccard indices, accuracy, F1@k, per class"
    )
    _add_data(p, with_model=True)
    _add_model_loading(p)
    _add_fps(p, FPS_RATE_HELP)
    p.add_argument("--json", action="store_true", help="print the scores as JSON")
    _add_common(p)
    p.set_defaults(func=cmd_evaluate)

    p = _subcommand(
        sub, "predict", "write prediction files (ChaLearn CSVs or intervals)"
    )
    _add_data(p, with_model=True)
    _add_model_loading(p)
    _add_fps(p, FPS_RATE_HELP)
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

    p = _subcommand(sub, "plot", "draw a figure to PNG, SVG or PDF")
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
    _add_fps(p, FPS_HELP + "; the time axis is in seconds at this rate")
    p.add_argument("--title", help="the figure's title (default: what it shows)")
    p.add_argument(
        "--size",
        type=_size,
        metavar="WIDTH,HEIGHT",
        help="the figure's size in inches, e.g. 12,4 (default: sized to the figure)",
    )
    p.add_argument("--dpi", type=int, default=110, help="resolution (default 110)")
    p.add_argument("--overwrite", action="store_true", help="replace the figure")
    _add_common(p)
    p.set_defaults(func=cmd_plot)

    p = _subcommand(
        sub,
        "stream",
        "recognise gestures live (--source) or in a recording replayed frame by "
        "frame, and print the events as they come",
    )
    _add_data(p, with_model=True, optional=True)
    _add_model_loading(p)
    p.add_argument(
        "--source",
        metavar="SOURCE",
        help="a live source instead of DATA: udp://HOST:PORT (JSON datagrams; "
        "port 0 picks a free port, printed), lsl://NAME (a Lab Streaming Layer "
        "stream, the lsl extra) or - (CSV rows on stdin; also DATA -). Ends at "
        "--timeout, the end of stdin, or Ctrl-C (status 0)",
    )
    p.add_argument(
        "--timeout",
        type=_positive,
        metavar="SECONDS",
        help="udp:// and lsl://: end the stream after this many seconds without "
        "a frame (default: wait until Ctrl-C)",
    )
    p.add_argument("--sequence", help="replay: sequence index or sample id (default 0)")
    _add_fps(
        p,
        "frame rate: of the replayed data (default the data's), or of the live "
        "sender (default the model's training data, else 30; lsl:// the "
        "stream's nominal rate)",
    )
    p.add_argument("--realtime", action="store_true", help="replay at the frame rate")
    p.add_argument(
        "--robot",
        action="store_true",
        help="drive the simulated pick-and-place robot with the events",
    )
    p.add_argument(
        "--commands",
        help="a command file (.json or .toml: any gestures, by name or number, to "
        "any commands, with an optional state machine; docs/streaming.md, 'Command "
        "files'), or with --robot the 5 distinct gesture classes giving "
        "move_to_tool, close_gripper, carry_tool, open_gripper, return_home "
        "(default the first 5 classes)",
    )
    p.add_argument(
        "--publish",
        action="append",
        metavar="TARGET",
        help="publish each command as JSON: 'stdout' (JSON lines; the event lines "
        "then go to stderr) or udp://HOST:PORT (one datagram each); repeatable",
    )
    p.add_argument(
        "--min-confidence",
        type=float,
        default=0.5,
        help="confidence floor of a command (default 0.5)",
    )
    _add_common(p)
    p.set_defaults(func=cmd_stream)

    p = _subcommand(
        sub, "demo", "train on PRECOG subjects 1-6 and report on subjects 7-8"
    )
    _add_method(p)
    p.add_argument("-o", "--output", help="also write the model file")
    _add_common(p)
    p.set_defaults(func=cmd_demo)
    parser.commands = dict(sub.choices)
    return parser


def _option_strings(parser):
    return [opt for action in parser._actions for opt in action.option_strings]


def _reject_unknown(parser, args, extras):
    """Exit (status 2) for the arguments that no parser took.

    Reported under the usage of the subcommand they were given to, with the
    closest option of that subcommand where one is close.
    """
    owner = parser.commands.get(getattr(args, "command", None), parser)
    unknown = [a for a in extras if a.startswith("-") and a != "-"]
    if not unknown:
        owner.error(f"unrecognized arguments: {' '.join(extras)}")
    given = unknown[0].split("=", 1)[0]
    close = difflib.get_close_matches(given, _option_strings(owner), n=1)
    hint = f"; did you mean {close[0]}?" if close else ""
    owner.error(f"unknown option {given}{hint}")


def main(argv=None):
    """Run the command line.

    Parameters
    ----------
    argv : list of str or None, default=None
        The arguments (without the program name); None reads ``sys.argv``.

    Returns
    -------
    int
        The exit status: 0 on success, 1 for an error, 2 for a usage error,
        130 on Ctrl-C (but ``stream`` takes Ctrl-C as the end of its stream:
        it prints the last events and the summary and returns 0) and 141
        when the reader of the output went away early
        (``skgesture evaluate ... | head -1``), as for a program that
        SIGPIPE ends.

    Examples
    --------
    >>> from skgesture._cli import main
    >>> main(["--version"])  # doctest: +ELLIPSIS
    skgesture ...
    0
    """
    try:
        status = _run(argv)
        sys.stdout.flush()  # a broken pipe shows here, not at interpreter exit
    except BrokenPipeError:
        _discard_output()
        return EXIT_BROKEN_PIPE
    return status


def _discard_output():
    """Point stdout, and stderr where it is broken too, at the null device.

    After a broken pipe the interpreter would report the failed flush of the
    buffered output at exit; flushing into the null device ends quietly.
    """
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if name == "stderr":
            try:
                stream.flush()
                continue  # stderr still reaches its reader
            except BrokenPipeError:
                pass
            except (AttributeError, OSError, ValueError):
                continue
        try:
            fd = stream.fileno()
        except (AttributeError, OSError, ValueError):
            continue  # not a real file (captured output): nothing is flushed at exit
        null = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(null, fd)
        finally:
            os.close(null)


@contextlib.contextmanager
def _descriptor_path():
    """Restore the descriptor's implementation switch, which a command on a
    few frames turns to numpy (``_cli_support.COMPILED_MIN_FRAMES``)."""
    name = "skgesture._descriptor._compute"  # not imported here: --help stays light
    loaded = sys.modules.get(name)
    before = None if loaded is None else loaded.USE_COMPILED
    try:
        yield
    finally:
        compute = sys.modules.get(name)
        if compute is not None:
            compute.USE_COMPILED = (
                compute.USE_COMPILED_DEFAULT if before is None else before
            )


def _run(argv):
    parser = build_parser()
    try:
        args, extras = parser.parse_known_args(argv)
        if extras:
            _reject_unknown(parser, args, extras)
    except SystemExit as exc:  # --help, --version, or a usage error
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    if args.command is None:
        parser.print_usage(sys.stderr)
        print("skgesture: error: give a command, e.g. skgesture demo", file=sys.stderr)
        return EXIT_USAGE
    with _warnings_as_lines(), plain_progress(args), _descriptor_path():
        try:
            return args.func(args) or 0
        except KeyboardInterrupt:
            print("skgesture: interrupted", file=sys.stderr)
            return 130
        except BrokenPipeError:
            raise
        except Exception as exc:
            if args.traceback or not _is_user_error(exc):
                raise
            print(f"skgesture {args.command}: error: {_one_line(exc)}", file=sys.stderr)
            return EXIT_ERROR
