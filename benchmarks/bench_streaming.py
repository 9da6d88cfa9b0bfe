"""Streaming: compute per pushed frame, decision delay, trade-offs, a one-hour soak.

* ``latency``: wall time (and thread CPU time) of every
  ``StreamingRecognizer.push`` with the default settings (no thread or
  schedule flags), Methods A and B with the paper's network sizes, Method
  C with the CPU-sized BiLSTM and the recommended model (R) with its
  defaults, over held-out PRECOG streams. Two ways of
  feeding: ``paced`` (a frame every 1/30 s, as a sensor delivers them: the
  recogniser waits for the next frame like a live program) and
  ``back-to-back`` (frames pushed in a tight loop, a replay).
* ``delay``: frames between the true end of a gesture and the event that
  names it (same class, largest overlap), the share of true gestures found,
  the Jaccard index of the streamed events next to the offline ``predict`` of
  the same model on the same streams, and ``agreement``: the Jaccard index of
  the streamed events against offline ``predict_segments`` (the first stage
  filling untracked frames as the stream, ``fill="hold"``), 1.000 when they
  are the same, and ``frames_equal``, the share of frames labelled alike
  (PRECOG: train subjects 1-6, test 7-8; synthetic: unseen subjects).
* ``tradeoff``: the smoothing span (Methods B and C), the early decision rule
  (B, ``early_decision=True``) and overlapping chunks (C,
  ``tagger__overlap=True``) against Jaccard and delay; decision parameters
  only, so nothing is retrained. The curve is saved as
  ``bench_results/streaming_tradeoff.png``. ``target`` rows give the setting
  of least delay whose Jaccard stays within 0.01 of the offline Jaccard of the
  paper's setting.
* ``soak``: one hour of stream at 30 fps (108,000 frames; PRECOG recordings
  end to end with tracking lost for 2 s between them) through Method B and the
  recommended model, frame by frame: resident memory at the start and the
  end, and the events against offline ``predict_segments`` of the whole hour
  (``lost``/``extra``: segments without an exact match; ``frames_equal``:
  frames labelled alike, the measure for the recommended model, whose bounded
  look-ahead moves boundaries).
* ``window``: the whole-sequence variant of the recommended model
  (``make_recommended(lookahead=None)``, method ``W``: a TCN that reads
  whole sequences offline, streamed over a trailing window) with the
  tagger's look-ahead ``tagger__stream_future``, the features' warm-up
  (where its features have one) and, for a tagger without a recurrent state
  (TCN), its window of past frames ``tagger__stream_past``, against
  agreement with offline, Jaccard, delay and the CPU time of a push (back to
  back, p50/p99); nothing is retrained.

Method ``R`` is ``make_recommended()`` as it is, the model built to stream
exactly (a causal TCN read 8 frames late, then the decoding's own lag): its
``agreement`` and ``frames_equal`` must be 1. Method ``W`` is its
whole-sequence variant, in ``latency``, ``delay`` and ``window``.

``python benchmarks/bench_streaming.py [--quick] [--sections latency ...]
[--methods ABCRW] [--set tagger__architecture=tcn ...]`` prints the tables
(``--set``: ``set_params`` of the recommended model before training);
``run(quick, sections, recommended_params, methods)`` returns the rows. ``--quick``
trains on less data for fewer epochs, streams fewer frames and soaks 12,000
frames (a smoke run of a few minutes); the full run takes about half an hour
on 2 cores.
"""

import argparse
import os
import time
from pathlib import Path

import numpy as np
from _common import format_table, machine_line, parse_params, save_figure

from skgesture import (
    TorchMLPClassifier,
    make_method_a,
    make_method_b,
    make_method_c,
    make_recommended,
)
from skgesture.datasets import load_precog, make_gesture_streams
from skgesture.metrics import jaccard_index
from skgesture.streaming import StreamingRecognizer
from skgesture.utils import labels_to_segments, segments_to_labels

SPANS = (1, 3, 5, 9, 15)
PAPER_SPAN = 15
STREAM_FPS = 30.0  # the Kinect rate the latency and the soak are paced at
ONE_HOUR = int(3600 * STREAM_FPS)
SOAK_GAP = int(2 * STREAM_FPS)  # untracked frames between recordings
RESULTS = Path(__file__).resolve().parents[1] / "bench_results"

SECTIONS = ("latency", "delay", "tradeoff", "window", "soak")
FUTURES = (2, 4, 8, 16, 32)  # look-aheads of the recommended model's window
WARMUPS = (0, 20, 60)  # warm-ups of its features' statistics
PASTS = (16, 32, 64, 128)  # windows of past frames (a tagger without state)
TABLE_COLUMNS = {
    "latency": ["method", "feed", "frames", "p50_us", "p99_us", "max_us",
                "cpu_p50_us", "cpu_p99_us", "load_avg"],
    "delay": ["data", "method", "max_delay", "agreement", "frames_equal",
              "jaccard_offline",
              "jaccard", "found", "delay_median", "delay_p90", "delay_median_ms",
              "fit_s"],
    "tradeoff": ["data", "method", "span", "variant", "max_delay", "jaccard",
                 "jaccard_offline", "found", "delay_median", "delay_p90"],
    "target": ["data", "method", "span", "variant", "jaccard", "jaccard_offline",
               "delay_median", "meets"],
    "window": ["data", "method", "future", "past", "warmup", "max_delay", "agreement",
               "frames_equal",
               "jaccard", "jaccard_offline", "found", "delay_median", "delay_p90",
               "cpu_p50_us", "cpu_p99_us"],
    "soak": ["method", "frames", "hours_at_30fps", "rss_start_mb", "rss_10pc_mb",
             "rss_end_mb", "events", "offline_segments", "lost", "extra",
             "frames_equal", "us_per_frame"],
}  # fmt: skip


def _networks(quick):
    """The paper's segmenter and window network sizes (docs/method.md §4.2, §5.4);
    fewer SCG epochs than MATLAB's 1000 (latency does not depend on them)."""
    epochs = 15 if quick else 200
    seg = TorchMLPClassifier(
        hidden_layer_sizes=(100, 100), activations=("relu", "tanh"), max_epochs=epochs
    )
    win = TorchMLPClassifier(
        hidden_layer_sizes=(300, 100), activations=("tanh", "tanh"), max_epochs=epochs
    )
    return {"segmenter__estimator": seg, "classifier__estimator": win}


def _pipelines(quick, recommended_params=None):
    def method_c():
        pipe = make_method_c(random_state=0)
        return pipe.set_params(tagger__max_epochs=8) if quick else pipe

    def recommended(**kwargs):
        # Its defaults (streaming ones included); --quick trains fewer epochs.
        pipe = make_recommended(random_state=0, **kwargs)
        pipe.set_params(**(recommended_params or {}))
        if quick:
            epochs = [k for k in pipe.get_params() if k.endswith("max_epochs")]
            pipe.set_params(**dict.fromkeys(epochs, 4))
        return pipe

    return {
        "A": lambda: make_method_a(random_state=0).set_params(**_networks(quick)),
        "B": lambda: make_method_b(random_state=0).set_params(**_networks(quick)),
        "C": method_c,
        "R": recommended,
        # the whole-sequence variant, streamed over a trailing window
        "W": lambda: recommended(lookahead=None),
    }


def _data(quick):
    """(name, fps, X_train, y_train, X_test, y_test) of PRECOG and synthetic."""
    precog = load_precog()
    train = (1, 2, 3) if quick else (1, 2, 3, 4, 5, 6)
    test = (8,) if quick else (7, 8)
    tr = [i for i, g in enumerate(precog.groups) if g in train]
    te = [i for i, g in enumerate(precog.groups) if g in test]
    sets = [(
        "PRECOG", precog.fps,
        [precog.X[i] for i in tr], [precog.y[i] for i in tr],
        [precog.X[i] for i in te], [precog.y[i] for i in te],
    )]  # fmt: skip
    n_train, n_test = (16, 4) if quick else (60, 20)
    syn = make_gesture_streams(
        n_sequences=n_train + n_test, n_classes=5, n_subjects=(n_train + n_test) // 4,
        random_state=0,
    )  # fmt: skip
    order = np.argsort(syn.groups, kind="stable")  # unseen subjects in the test part
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


def _offline_hold(pipe, X):
    """Offline labels with the first stage (descriptor or features) filling
    untracked frames as a stream does."""
    key = f"{pipe.steps[0][0]}__fill"
    old = pipe.get_params()[key]
    pipe.set_params(**{key: "hold"})
    try:
        segs = pipe[-1].predict_segments(pipe[:-1].transform([X]))[0]
    finally:
        pipe.set_params(**{key: old})
    rows = np.asarray(segs[:, :3], dtype=np.int64).reshape(-1, 3)
    return segments_to_labels(rows, len(X), on_overlap="later")


def _stream_scores(rec, X_test, y_test, fps, pipe=None):
    delays, missed, pred, offline = [], 0, [], []
    for X, y in zip(X_test, y_test):
        events = rec.recognize(X)
        d, m = _delays(events, y)
        delays += d
        missed += m
        pred.append(_events_to_labels(events, len(X)))
        if pipe is not None:
            offline.append(_offline_hold(pipe, X))
    nan = float("nan")
    extra = {}
    if pipe is not None:  # the streamed events against offline predict_segments
        extra["agreement"] = float(jaccard_index(offline, pred))
        # The same frames labelled alike (the Jaccard index scores a class whose
        # only frames are excluded ends as 0, so identical labels can give < 1).
        same = np.concatenate([a == b for a, b in zip(offline, pred)])
        extra["frames_equal"] = float(same.mean())
    return {
        **extra,
        "jaccard": float(jaccard_index(y_test, pred)),
        "found": len(delays) / max(len(delays) + missed, 1),
        "delay_median": float(np.median(delays)) if delays else nan,
        "delay_p90": float(np.percentile(delays, 90)) if delays else nan,
        "delay_median_ms": 1000 * float(np.median(delays)) / fps if delays else nan,
    }


def _latency(pipe, streams, max_frames, paced):
    """Wall and thread CPU time of every push, in microseconds.

    ``paced``: frames come every 1/30 s and the loop sleeps in between, as a
    live program waiting for its sensor; otherwise back to back. The CPU time
    leaves out the time the thread waited for a core.
    """
    rec = StreamingRecognizer(pipe)
    rec.recognize(streams[0][:60])  # warm-up
    wall, cpu, n = [], [], 0
    period = 1.0 / STREAM_FPS
    next_t = time.perf_counter()
    load = os.getloadavg()[0]
    for X in streams:
        for frame in X:
            if paced:
                next_t += period
                pause = next_t - time.perf_counter()
                if pause > 0:
                    time.sleep(pause)
            t0, c0 = time.perf_counter_ns(), time.thread_time_ns()
            rec.push(frame)
            cpu.append(time.thread_time_ns() - c0)
            wall.append(time.perf_counter_ns() - t0)
            n += 1
            if n >= max_frames:
                break
        rec.flush()
        if n >= max_frames:
            break
    wall, cpu = np.array(wall) / 1000.0, np.array(cpu) / 1000.0
    return {
        "frames": n,
        "p50_us": float(np.median(wall)),
        "p99_us": float(np.percentile(wall, 99)),
        "max_us": float(wall.max()),
        "cpu_p50_us": float(np.median(cpu)),
        "cpu_p99_us": float(np.percentile(cpu, 99)),
        "load_avg": f"{load:.1f}-{os.getloadavg()[0]:.1f}",
    }


def _offline_jaccard(pipe, X_test, y_test):
    return float(jaccard_index(y_test, pipe.predict(X_test)))


def _tradeoff(pipe, method, name, X_te, y_te, fps, quick):
    """Span (and the early decision rule for A/B) against Jaccard and delay."""
    key = "tagger__smooth_span" if method == "C" else "segmenter__smooth_span"
    reference = _offline_jaccard(pipe, X_te, y_te)  # the paper's span, offline
    rows = []
    old = pipe.get_params()[key]
    spans = SPANS[1::2] + (PAPER_SPAN,) if quick else SPANS
    # Variants: B with the early decision rule, C with overlapping chunks.
    variant = "overlapping chunks" if method == "C" else "early decision"
    try:
        for span in spans:
            pipe.set_params(**{key: span})
            for other in (False, True):
                if method == "C":
                    pipe.set_params(tagger__overlap=other)
                rec = StreamingRecognizer(pipe, early_decision=other and method != "C")
                rows.append({
                    "section": "tradeoff", "data": name, "method": method,
                    "span": span, "variant": variant if other else "",
                    "max_delay": rec.max_delay,
                    "jaccard_offline": reference,
                    **_stream_scores(rec, X_te, y_te, fps),
                })  # fmt: skip
    finally:
        pipe.set_params(**{key: old})
        if method == "C":
            pipe.set_params(tagger__overlap=False)
    ok = [
        r
        for r in rows
        if r["jaccard"] >= r["jaccard_offline"] - 0.01
        and np.isfinite(r["delay_median"])
    ]
    best = min(ok, key=lambda r: (r["delay_median"], -r["jaccard"]), default=None)
    if best is not None:
        rows.append({
            **{k: best[k] for k in TABLE_COLUMNS["target"] if k in best},
            "section": "target", "meets": best["delay_median"] <= 10,
        })  # fmt: skip
    return rows


def _window(pipe, name, X_te, y_te, fps, quick):
    """The whole-sequence model's look-ahead and warm-up (stream-only
    parameters, nothing retrained) against agreement with offline, Jaccard,
    delay and CPU. Features without a warm-up (the descriptor: each row is
    its frame's own) are run at their one setting, ``warmup`` None."""
    future_key = f"{pipe.steps[-1][0]}__stream_future"
    warmup_key = f"{pipe.steps[0][0]}__stream_warmup"
    past_key = f"{pipe.steps[-1][0]}__stream_past"
    params = pipe.get_params()
    default = {k: params[k] for k in (future_key, warmup_key, past_key) if k in params}
    reference = _offline_jaccard(pipe, X_te, y_te)
    futures = (2, 8, 32) if quick else FUTURES
    settings = [{**default, future_key: f} for f in futures]
    if warmup_key in default:
        warmups = [w for w in WARMUPS if w != default[warmup_key]]
        settings += [{**default, warmup_key: w} for w in warmups]
    if not _carries_state(pipe[-1]):  # a window of past frames: its length too
        pasts = [p for p in PASTS if p != default[past_key]]
        settings += [{**default, past_key: p} for p in pasts]
    rows = []
    try:
        for setting in settings:
            pipe.set_params(**setting)
            rec = StreamingRecognizer(pipe)
            cpu = _latency(pipe, X_te, 600 if quick else 2000, paced=False)
            rows.append({
                "section": "window", "data": name, "method": "W",
                "future": setting[future_key], "past": setting[past_key],
                "warmup": setting.get(warmup_key),
                "max_delay": rec.max_delay, "jaccard_offline": reference,
                **_stream_scores(rec, X_te, y_te, fps, pipe),
                "cpu_p50_us": cpu["cpu_p50_us"], "cpu_p99_us": cpu["cpu_p99_us"],
            })  # fmt: skip
    finally:
        pipe.set_params(**default)
    return rows


def _carries_state(tagger):
    """Whether the tagger's stream carries a recurrent state (no past window)."""
    from skgesture._nn._fast import RecurrentScorer
    from skgesture._taggers._stream import VotingScorer

    scorer = tagger._stream_scorer(0)
    scorers = scorer.scorers if isinstance(scorer, VotingScorer) else [scorer]
    return all(isinstance(s, RecurrentScorer) for s in scorers)


def _rss_mb():
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except OSError:  # not Linux
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _soak(pipe, method, streams, n_frames):
    """``n_frames`` of recordings end to end, tracking lost between them."""
    gap = np.zeros((SOAK_GAP, 20, 3))
    parts, total = [], 0
    while total < n_frames:
        for X in streams:
            parts += [X, gap]
            total += len(X) + SOAK_GAP
    stream = np.concatenate(parts)[:n_frames]
    rec = StreamingRecognizer(pipe)
    events, rss = [], {}
    t0 = time.perf_counter()
    for t, frame in enumerate(stream):
        if t == 1000:
            rss["start"] = _rss_mb()
        if t == n_frames // 10:
            rss["10pc"] = _rss_mb()
        events += rec.push(frame)
    events += rec.flush()
    elapsed = time.perf_counter() - t0
    rss["end"] = _rss_mb()
    key = f"{pipe.steps[0][0]}__fill"
    old = pipe.get_params()[key]
    pipe.set_params(**{key: "hold"})  # the stream holds, offline too
    try:
        offline = pipe[-1].predict_segments(pipe[:-1].transform([stream]))[0]
    finally:
        pipe.set_params(**{key: old})
    want = {tuple(int(v) for v in row[:3]) for row in offline}
    got = {(ev.label, ev.start, ev.end) for ev in events}
    same = _events_to_labels(events, n_frames) == segments_to_labels(
        np.asarray(offline[:, :3], dtype=np.int64).reshape(-1, 3), n_frames,
        on_overlap="later",
    )  # fmt: skip
    return {
        "section": "soak", "method": method, "frames": n_frames,
        "hours_at_30fps": n_frames / STREAM_FPS / 3600,
        "rss_start_mb": rss["start"], "rss_10pc_mb": rss["10pc"],
        "rss_end_mb": rss["end"], "events": len(events),
        "offline_segments": len(want), "lost": len(want - got),
        "extra": len(got - want), "frames_equal": float(same.mean()),
        "us_per_frame": 1e6 * elapsed / n_frames,
    }  # fmt: skip


def run(quick=False, sections=SECTIONS, recommended_params=None, methods="ABCRW"):
    """Run the sections and return their rows.

    Parameters
    ----------
    quick : bool, default=False
        Less data, fewer epochs and frames: a smoke run.
    sections : tuple of str, default=SECTIONS
        Which measurements to take (the networks are trained in any case).
    recommended_params : dict or None, default=None
        ``set_params`` of the recommended model before it is trained (e.g.
        ``{"tagger__architecture": "tcn"}``), to measure another set-up.
    methods : str, default="ABCRW"
        The methods measured (``R``: the recommended model, ``W``: its
        whole-sequence variant).

    Returns
    -------
    list of dict
        One row per measurement; ``section`` is ``"latency"``, ``"delay"``,
        ``"tradeoff"``, ``"target"`` or ``"soak"``.
    """
    rows, fitted = [], {}
    needed = set()
    for section, used in (
        ("latency", "ABCRW"), ("delay", "ABCRW"), ("tradeoff", "BC"), ("window", "W"),
        ("soak", "BR"),
    ):  # fmt: skip
        if section in sections:
            needed |= set(used) & set(methods)
    for name, fps, X_tr, y_tr, X_te, y_te in _data(quick):
        if name != "PRECOG" and not {"delay", "tradeoff", "window"} & set(sections):
            continue
        for method, make in _pipelines(quick, recommended_params).items():
            if method not in needed:
                continue
            t0 = time.perf_counter()
            pipe = make().fit(X_tr, y_tr)
            fit_s = time.perf_counter() - t0
            fitted[name, method] = (pipe, X_te)
            if name == "PRECOG" and "latency" in sections:
                frames = 900 if quick else 4000
                for paced in (True, False):
                    rows.append({
                        "section": "latency", "method": method,
                        "feed": "paced 30 fps" if paced else "back-to-back",
                        **_latency(pipe, X_te, frames, paced),
                    })  # fmt: skip
            if "delay" in sections:
                rec = StreamingRecognizer(pipe)
                rows.append({
                    "section": "delay", "data": name, "method": method,
                    "max_delay": rec.max_delay,
                    "jaccard_offline": _offline_jaccard(pipe, X_te, y_te),
                    **_stream_scores(rec, X_te, y_te, fps, pipe), "fit_s": fit_s,
                })  # fmt: skip
            if "tradeoff" in sections and method in ("B", "C"):
                rows += _tradeoff(pipe, method, name, X_te, y_te, fps, quick)
            if "window" in sections and method == "W":
                rows += _window(pipe, name, X_te, y_te, fps, quick)
    if "soak" in sections:
        for method in ("B", "R"):
            if ("PRECOG", method) not in fitted:
                continue
            pipe, X_te = fitted["PRECOG", method]
            rows.append(_soak(pipe, method, X_te, 12_000 if quick else ONE_HOUR))
    if "tradeoff" in sections or "window" in sections:
        path = plot_tradeoff(rows, RESULTS / "streaming_tradeoff.png")
        rows.append({"section": "figure", "path": str(path)})
    return rows


def plot_tradeoff(rows, path):
    """Delay against Jaccard for every data set, method and early rule."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    window = [r for r in rows if r["section"] == "window"]
    rows = [r for r in rows if r["section"] == "tradeoff"]
    names = sorted({r["data"] for r in rows + window})
    fig, axes = plt.subplots(
        1, len(names), figsize=(6 * len(names), 4.5), squeeze=False
    )
    for ax, name in zip(axes[0], names):
        mine = [r for r in rows if r["data"] == name]
        refs = {}
        for (method, variant), marker in (
            (("B", ""), "o-"), (("B", "early decision"), "s--"),
            (("C", ""), "^-"), (("C", "overlapping chunks"), "v--"),
        ):  # fmt: skip
            curve = sorted(
                (r for r in mine if r["method"] == method and r["variant"] == variant),
                key=lambda r: r["span"],
            )
            if not curve:
                continue
            refs[method] = curve[0]["jaccard_offline"]
            label = f"Method {method}" + (f", {variant}" if variant else "")
            delay = [r["delay_median"] for r in curve]
            jac = [r["jaccard"] for r in curve]
            line = ax.plot(delay, jac, marker, label=label)[0]
            for r in curve:
                ax.annotate(str(r["span"]), (r["delay_median"], r["jaccard"]),
                            textcoords="offset points", xytext=(3, 3), fontsize=7,
                            color=line.get_color())  # fmt: skip
        # The recommended model: its look-ahead (labels) at its default warm-up.
        mine = [r for r in window if r["data"] == name]
        usual = {  # the default warm-up and past: the most frequent values
            k: max({r[k] for r in mine}, key=[r[k] for r in mine].count)
            for k in ("warmup", "past")
            if mine
        }
        curve = sorted(
            (r for r in mine if all(r[k] == v for k, v in usual.items())),
            key=lambda r: r["future"],
        )
        if curve:
            refs["W"] = curve[0]["jaccard_offline"]
            line = ax.plot([r["delay_median"] for r in curve],
                           [r["jaccard"] for r in curve], "D-",
                           label="whole-sequence (labels: look-ahead)")[0]  # fmt: skip
            for r in curve:
                ax.annotate(f"L{r['future']}", (r["delay_median"], r["jaccard"]),
                            textcoords="offset points", xytext=(3, -9), fontsize=7,
                            color=line.get_color())  # fmt: skip
        colours = {"B": "tab:blue", "C": "tab:green", "W": "tab:red"}
        for method, ref in refs.items():
            ax.axhspan(ref - 0.01, ref + 0.01, alpha=0.12,
                       color=colours[method])  # fmt: skip
        ax.axvline(10, color="grey", ls=":", lw=1)
        ax.set_title(f"{name}: delay against Jaccard (labels: span, L: look-ahead)")
        ax.set_xlabel("median decision delay (frames after the gesture ends)")
        ax.set_ylabel("Jaccard index of the streamed events")
        ax.legend(fontsize=8, loc="best", framealpha=0.6)
    fig.text(0.5, 0.005, "bands: offline Jaccard (B, C: the paper's span 15; W: "
             "its defaults) +- 0.01; dotted: the 10-frame aim", ha="center",
             fontsize=8)  # fmt: skip
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    return save_figure(fig, path)


def format_tables(rows, title=None):
    """One Markdown table per section (each has its own columns)."""
    out = [f"## {title}\n"] if title else []
    for section, columns in TABLE_COLUMNS.items():
        mine = [r for r in rows if r.get("section") == section]
        if mine:
            out.append(format_table(mine, columns, title=f"streaming {section}"))
    for r in rows:
        if r.get("section") == "figure":
            out.append(f"trade-off figure: {r['path']}\n")
    return "\n".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small smoke run")
    parser.add_argument(
        "--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS),
        help="measurements to take",
    )  # fmt: skip
    parser.add_argument(
        "--methods", default="ABCRW",
        help="methods to measure: any of A, B, C, R (the recommended model) and W "
        "(its whole-sequence variant)",
    )  # fmt: skip
    parser.add_argument(
        "--set", nargs="+", default=[], metavar="PARAM=VALUE",
        help="set_params of the recommended model, e.g. tagger__architecture=tcn "
        "(values are Python literals; anything else is a string)",
    )  # fmt: skip
    args = parser.parse_args()
    rows = run(quick=args.quick, sections=tuple(args.sections),
               recommended_params=parse_params(args.set),
               methods=args.methods)  # fmt: skip
    print(machine_line())
    print()
    print(format_tables(rows))


if __name__ == "__main__":
    main()
