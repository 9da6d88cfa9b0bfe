"""Shared helpers of the benchmarks: timing, tables, one-core execution."""

import ast
import os
import statistics
import time
from contextlib import contextmanager
from pathlib import Path


def shared_data_dir():
    """The real data folder: ``$SKGESTURE_SHARED_DATA`` or ``<repo>/../shared/data``."""
    env = os.environ.get("SKGESTURE_SHARED_DATA")
    root = Path(__file__).resolve().parents[1]
    return Path(env) if env else root.parent / "shared" / "data"


def load_utkinect_quiet(path):
    """``skgesture.datasets.load_utkinect(path)`` without its warnings about the
    overlapping labels of the original annotation file (the benchmarks know)."""
    import warnings

    from skgesture.datasets import DataFileWarning, load_utkinect

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataFileWarning)
        return load_utkinect(path)


def median_time(func, repeat=5, warmup=1):
    """Median wall time of ``func()`` over ``repeat`` runs, after ``warmup`` runs."""
    for _ in range(warmup):
        func()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times


@contextmanager
def one_core():
    """Limit numpy/BLAS and torch to one thread inside the block."""
    import torch
    from threadpoolctl import threadpool_limits

    old = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        with threadpool_limits(1):
            yield
    finally:
        torch.set_num_threads(old)


def format_table(rows, columns=None, title=None):
    """Markdown table of a list of dicts (floats rounded sensibly)."""
    if not rows:
        return f"## {title}\n\n(no rows)\n" if title else "(no rows)\n"
    columns = columns or list(rows[0])

    def fmt(v):
        if isinstance(v, float):
            if v != v:
                return "nan"
            if abs(v) >= 1000:
                return f"{v:,.0f}"
            if abs(v) >= 10:
                return f"{v:.1f}"
            return f"{v:.3f}"
        return str(v)

    lines = []
    if title:
        lines += [f"## {title}", ""]
    lines.append("| " + " | ".join(columns) + " |")
    lines.append("|" + "|".join("---" for _ in columns) + "|")
    for r in rows:
        lines.append("| " + " | ".join(fmt(r.get(c, "")) for c in columns) + " |")
    return "\n".join(lines) + "\n"


def machine_line():
    """One line describing where the numbers were taken."""
    import platform

    import numpy
    import sklearn
    import torch

    return (
        f"{platform.node()} · {os.cpu_count()} cores"
        f" · Python {platform.python_version()}"
        f" · numpy {numpy.__version__} · scikit-learn {sklearn.__version__}"
        f" · torch {torch.__version__}"
    )


def comma_list(text):
    """``"a, b,c"`` as ``["a", "b", "c"]`` (a command-line list); None or ""
    as None."""
    return [t.strip() for t in text.split(",") if t.strip()] if text else None


def parse_params(pairs):
    """``["a=1", "b=gru"]`` (``--set PARAM=VALUE ...``) as ``{"a": 1, "b":
    "gru"}``: a value is a Python literal, else a string."""
    out = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise SystemExit(f"--set takes PARAM=VALUE, got {pair!r}")
        try:
            out[key] = ast.literal_eval(value)
        except (ValueError, SyntaxError):
            out[key] = value
    return out


def save_figure(fig, path, dpi=110):
    """Write a benchmark's matplotlib figure to ``path`` (its folder made when
    missing), close it, and return ``path``."""
    import matplotlib.pyplot as plt

    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def figure_lines(rows):
    """The ``"figure: <path>"`` lines of a section's ``table="figure"`` rows,
    to print under its tables."""
    return "".join(
        f"\nfigure: {r['path']}\n" for r in rows if r.get("table") == "figure"
    )


def print_report(rows, format_tables, notes):
    """Print a section's run on its own: the machine, its tables, its notes."""
    print(machine_line() + "\n")
    print(format_tables(rows))
    for note in notes:
        print(f"* {note}")


def _code_only(source):
    """The source's syntax tree without docstrings: what runs, not its prose.

    Editing a docstring or a comment (citations, wording) leaves the key as it
    was, so it does not discard hours of cached fits; any change to the code does.
    """
    tree = ast.parse(source)
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (
            isinstance(body, list)
            and body
            and isinstance(body[0], ast.Expr)
            and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)
        ):
            node.body = body[1:] or [ast.Pass()]
    return ast.dump(tree, include_attributes=False).encode()


def source_key(path):
    """The bytes a cache key takes from a file: a Python file's code without its
    docstrings (:func:`_code_only`), any other file (or unparsable source) as is."""
    data = Path(path).read_bytes()
    if str(path).endswith(".py"):
        try:
            return _code_only(data.decode("utf-8"))
        except (SyntaxError, UnicodeDecodeError):
            pass
    return data
