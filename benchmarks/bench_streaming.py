"""Streaming: compute per pushed frame, decision delay, trade-offs (issue 5).

* ``latency``: wall and thread CPU time of every ``StreamingRecognizer.push``
  on one core (torch and BLAS limited to one thread), Methods A, B
  (paper-size networks) and C (the CPU-sized BiLSTM), with the ``"eager"`` and
  ``"balanced"`` schedules, over held-out PRECOG streams.
* ``delay``: frames between the true end of a gesture and the event that names
  it (same class, largest overlap), on PRECOG (train subjects 1-6, test 7-8)
  and synthetic streams (unseen subjects), with the share of true gestures
  found and the Jaccard index of the streamed events.
* ``tradeoff``: the segmenter's loess span and minimum period length (Method
  B) and the tagger's span and minimum run (Method C) against Jaccard and
  delay; decision parameters only, so nothing is retrained.

``python benchmarks/bench_streaming.py [--quick] [--sections latency ...]``
prints the tables; ``run(quick, sections)`` returns the rows. ``--quick``
trains small networks on less data (a smoke run of about a minute); the full
run (about 17 minutes on 2 cores) trains the paper's network sizes (fewer
epochs than the paper: latency does not depend on them).
"""

import argparse
import time

import numpy as np
from _common import format_table, machine_line, one_core

from skgesture import TorchMLPClassifier, make_method_a, make_method_b, make_method_c
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.metrics import jaccard_index
from skgesture.streaming import StreamingRecognizer
from skgesture.utils import segments_to_labels

SPANS = (1, 5, 9, 15, 21)
MIN_LENGTHS = (6, 12, 18)
MIN_RUNS = (5, 10, 15, 20)


def _networks(quick):
    """Segmenter and window networks: paper sizes, or tiny for --quick."""
    if quick:
        seg = TorchMLPClassifier(
            hidden_layer_sizes=(16,), activations=("tanh",), max_epochs=30
        )
        win = TorchMLPClassifier(
            hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=30
        )
    else:  # METHOD_SPEC §4.2, §5.4 sizes; fewer SCG epochs than MATLAB's 1000
        seg = TorchMLPClassifier(
            hidden_layer_sizes=(100, 100), activations=("relu", "tanh"), max_epochs=200
        )
        win = TorchMLPClassifier(
            hidden_layer_sizes=(300, 100), activations=("tanh", "tanh"), max_epochs=200
        )
    return {"segmenter__estimator": seg, "classifier__estimator": win}


def _pipelines(quick):
    out = {
        "A": lambda: make_method_a(random_state=0).set_params(**_networks(quick)),
        "B": lambda: make_method_b(random_state=0).set_params(**_networks(quick)),
    }
    epochs = 5 if quick else 40

    def method_c():
        pipe = make_method_c(random_state=0).set_params(tagger__max_epochs=epochs)
        if quick:
            pipe.set_params(tagger__hidden_sizes=(16,))
        return pipe

    out["C"] = method_c
    return out


def _data(quick):
    """(name, fps, X_train, y_train, X_test, y_test) of PRECOG and synthetic."""
    precog = load_precog()
    train = (1, 2) if quick else (1, 2, 3, 4, 5, 6)
    test = (8,) if quick else (7, 8)
    tr = [i for i, g in enumerate(precog.groups) if g in train]
    te = [i for i, g in enumerate(precog.groups) if g in test]
    sets = [(
        "PRECOG", precog.fps,
        [precog.X[i] for i in tr], [precog.y[i] for i in tr],
        [precog.X[i] for i in te], [precog.y[i] for i in te],
    )]  # fmt: skip
    n_train, n_test = (12, 4) if quick else (60, 20)
    syn = make_gesture_streams(
        n_sequences=n_train + n_test, n_classes=5, n_subjects=(n_train + n_test) // 4,
        random_state=0,
    )  # fmt: skip
    # Unseen subjects in the test part.
    order = np.argsort(syn.groups, kind="stable")
    tr, te = order[:n_train], order[n_train:]
    sets.append((
        "synthetic", syn.fps,
        [syn.X[i] for i in tr], [syn.y[i] for i in tr],
        [syn.X[i] for i in te], [syn.y[i] for i in te],
    ))  # fmt: skip
    return sets


def _events_to_labels(events, n_frames):
    segs = [(ev.label, ev.start, ev.end) for ev in events]
    return segments_to_labels(
        np.array(segs, dtype=np.int64).reshape(-1, 3), n_frames, on_overlap="later"
    )


def _delays(events, y):
    """Delay of the best-overlapping same-class event of every true gesture."""
    from skgesture.utils import labels_to_segments

    delays, missed = [], 0
    for cls, s, e in labels_to_segments(y):
        best, overlap = None, 0
        for ev in events:
            ov = min(e, ev.end) - max(s, ev.start)
            if ev.label == cls and ov > overlap:
                best, overlap = ev, ov
        if best is None:
            missed += 1
        else:
            delays.append(best.emitted_at - (e - 1))
    return delays, missed


def _stream_scores(rec, X_test, y_test, fps):
    delays, missed, pred = [], 0, []
    for X, y in zip(X_test, y_test):
        events = rec.recognize(X)
        d, m = _delays(events, y)
        delays += d
        missed += m
        pred.append(_events_to_labels(events, len(X)))
    n_true = len(delays) + missed
    return {
        "jaccard": float(jaccard_index(y_test, pred)),
        "found": len(delays) / max(n_true, 1),
        "delay_median": float(np.median(delays)) if delays else float("nan"),
        "delay_p90": float(np.percentile(delays, 90)) if delays else float("nan"),
        "delay_median_ms": 1000 * float(np.median(delays)) / fps
        if delays
        else float("nan"),
    }


def _latency(rec, X_test, max_frames):
    """Wall and thread CPU time of every push (and flush), in microseconds.

    The CPU time leaves out the time the thread waited for a core, so it stays
    meaningful on a loaded machine; the wall time is what a caller sees.
    """
    wall, cpu, n = [], [], 0
    rec.recognize(X_test[0][:100])  # warm-up
    for X in X_test:
        for frame in list(X) + [None]:
            t0, c0 = time.perf_counter_ns(), time.thread_time_ns()
            if frame is None:
                rec.flush()
            else:
                rec.push(frame)
                n += 1
            cpu.append(time.thread_time_ns() - c0)
            wall.append(time.perf_counter_ns() - t0)
        if n >= max_frames:
            break
    wall, cpu = np.array(wall) / 1000.0, np.array(cpu) / 1000.0
    return {
        "frames": n,
        "median_us": float(np.median(wall)),
        "p99_us": float(np.percentile(wall, 99)),
        "max_us": float(wall.max()),
        "cpu_median_us": float(np.median(cpu)),
        "cpu_p99_us": float(np.percentile(cpu, 99)),
    }


SECTIONS = ("latency", "delay", "tradeoff")


def run(quick=False, sections=SECTIONS):
    """Run the sections and return their rows.

    Parameters
    ----------
    quick : bool, default=False
        Small networks and data: a smoke run.
    sections : tuple of str, default=("latency", "delay", "tradeoff")
        Which measurements to take (the networks are trained in any case).

    Returns
    -------
    list of dict
        One row per measurement; ``section`` is ``"latency"``, ``"delay"`` or
        ``"tradeoff"``.
    """
    rows = []
    with one_core():
        for name, fps, X_tr, y_tr, X_te, y_te in _data(quick):
            if name != "PRECOG" and set(sections) == {"latency"}:
                continue
            for method, make in _pipelines(quick).items():
                t0 = time.perf_counter()
                pipe = make().fit(X_tr, y_tr)
                fit_s = time.perf_counter() - t0
                rec = StreamingRecognizer(pipe)
                base = {"data": name, "method": method}
                if name == "PRECOG" and "latency" in sections:
                    for schedule in ("eager", "balanced"):
                        lat = _latency(
                            StreamingRecognizer(pipe, schedule=schedule),
                            X_te, 600 if quick else 5000,
                        )  # fmt: skip
                        rows.append({
                            "section": "latency", **base, "schedule": schedule, **lat
                        })  # fmt: skip
                if "delay" in sections:
                    scores = _stream_scores(rec, X_te, y_te, fps)
                    rows.append({
                        "section": "delay", **base, "fps": fps,
                        "lookahead": rec.lookahead, "max_delay": rec.max_delay,
                        **scores, "fit_s": fit_s,
                    })  # fmt: skip
                if "tradeoff" in sections:
                    rows += _tradeoff(pipe, method, base, X_te, y_te, fps, quick)
    return rows


def _tradeoff(pipe, method, base, X_te, y_te, fps, quick):
    rows = []
    if method == "A":
        return rows
    if method == "B":
        grid = [
            {"segmenter__smooth_span": s, "segmenter__min_length": m}
            for s in SPANS
            for m in MIN_LENGTHS
        ]
    else:
        grid = [
            {"tagger__smooth_span": s, "tagger__min_run": m}
            for s in SPANS
            for m in MIN_RUNS
        ]
    if quick:
        grid = grid[::4]
    old = {k: pipe.get_params()[k] for k in grid[0]}
    for params in grid:
        pipe.set_params(**params)
        rec = StreamingRecognizer(pipe)
        rows.append({
            "section": "tradeoff", **base,
            "span": list(params.values())[0], "min_length": list(params.values())[1],
            "lookahead": rec.lookahead, **_stream_scores(rec, X_te, y_te, fps),
        })  # fmt: skip
    pipe.set_params(**old)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small smoke run")
    parser.add_argument(
        "--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS),
        help="measurements to take",
    )  # fmt: skip
    args = parser.parse_args()
    rows = run(quick=args.quick, sections=tuple(args.sections))
    print(machine_line())
    print()
    for section, columns in (
        ("latency", ["data", "method", "schedule", "frames", "median_us", "p99_us",
                     "max_us",
                     "cpu_median_us", "cpu_p99_us"]),
        ("delay", ["data", "method", "fps", "lookahead", "max_delay", "jaccard",
                   "found", "delay_median", "delay_p90", "delay_median_ms", "fit_s"]),
        ("tradeoff", ["data", "method", "span", "min_length", "lookahead", "jaccard",
                      "found", "delay_median", "delay_p90"]),
    ):  # fmt: skip
        print(format_table([r for r in rows if r["section"] == section], columns,
                           title=f"streaming {section}"))  # fmt: skip


if __name__ == "__main__":
    main()
