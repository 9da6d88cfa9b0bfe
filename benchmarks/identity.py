"""Bit-identity check of the package restructure: same seeds, same outputs.

The restructure moves modules into subpackages and must change no number. This
script trains Methods A, B, C and the recommended model with fixed seeds on

* ``precog``: the bundled PRECOG streams, subjects 1-3 for training and the 6
  streams of subject 4 for testing (``joints="full20"``, 30 fps);
* ``synthetic``: 14 streams of :func:`skgesture.datasets.make_gesture_streams`
  (5 classes, with tracking dropouts), 10 for training and 4 for testing
  (``joints="paper11"``),

with networks and epochs far below the defaults (the point is identity, not
accuracy), and stores for every test sequence:

* ``predict``: the per-frame labels;
* ``predict_proba``: where the last step has it (Method C, recommended);
* ``predict_segments``: the last step's segments ``(class, start, end,
  confidence)`` on the transformed input;
* ``segmenter_decision``: the smoothed segmenter score (Methods A, B);
* ``stream``: the events of :class:`skgesture.StreamingRecognizer`
  (``recognize`` of the whole stream), rows ``(label, start, end, confidence,
  emitted_at)``;

and a SHA-256 digest of the data (method ``data``). Methods A, B and C are built
with ``descriptor__fill="hold"``, the condition under which the streamed events
equal ``predict_segments`` (docs/streaming.md); the recommended model keeps its
defaults (its streamed events are only close to offline ``predict``).

It uses only public names (``skgesture`` and ``skgesture.datasets``), so it runs
unchanged before and after the restructure::

    # before (commit 59fafcb, checked out in /tmp/old59)
    cd /tmp/old59 && PYTHONPATH=/tmp/old59 OMP_NUM_THREADS=1 \\
        /work/main/.venv/bin/python /work/main/benchmarks/identity.py \\
        --out /tmp/identity_59fafcb.npz
    # after
    OMP_NUM_THREADS=1 python benchmarks/identity.py --out /tmp/identity_new.npz
    python benchmarks/identity.py --compare /tmp/identity_59fafcb.npz \\
        /tmp/identity_new.npz

``--compare`` prints one row per (method, dataset, quantity): identical or
not, and the largest absolute difference; it exits with status 1 if anything
differs or is missing. It also prints how far the streamed events agree with
offline prediction in each file. The whole run takes a few minutes on one core.
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import hashlib
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

import skgesture
from skgesture import (
    StreamingRecognizer,
    make_method_a,
    make_method_b,
    make_method_c,
    make_recommended,
    segments_to_labels,
)
from skgesture.datasets import load_precog, make_gesture_streams

METHODS = ("A", "B", "C", "R")
DATASETS = ("precog", "synthetic")
JOINTS = {"precog": "full20", "synthetic": "paper11"}
SEED = 0
SEP = "__"
META = "meta"


# -- data and models ---------------------------------------------------------------


def load(dataset):
    """``(X_train, y_train, X_test)`` of ``dataset``."""
    if dataset == "precog":
        train = load_precog(subjects=[1, 2, 3])
        test = load_precog(subjects=[4])
        return train.X, train.y, test.X
    data = make_gesture_streams(
        n_sequences=14, n_classes=5, n_gestures=(3, 5), random_state=1
    )
    return data.X[:10], data.y[:10], data.X[10:]


def build(method, joints):
    """The unfitted, reduced model of ``method`` with fixed seeds."""
    if method in ("A", "B"):
        factory = make_method_a if method == "A" else make_method_b
        net = {"hidden_layer_sizes": (64, 32), "max_epochs": 100}
        params = {f"segmenter__estimator__{k}": v for k, v in net.items()}
        params.update({f"classifier__estimator__{k}": v for k, v in net.items()})
        return factory(joints=joints, random_state=SEED).set_params(
            descriptor__fill="hold", **params
        )
    if method == "C":
        return make_method_c(joints=joints, random_state=SEED).set_params(
            descriptor__fill="hold", tagger__hidden_sizes=(32,), tagger__max_epochs=10
        )
    if method == "R":
        return make_recommended(joints=joints, random_state=SEED).set_params(
            tagger__hidden_sizes=(32,),
            tagger__tcn_layers=6,
            tagger__tcn_stages=2,
            tagger__crop_length=128,
            tagger__batch_size=16,
            tagger__steps_per_epoch=20,
            tagger__max_epochs=12,
        )
    raise ValueError(f"unknown method {method!r}")


def _seed_globals():
    """Seed the global generators too, so no model depends on the run order."""
    import torch

    np.random.seed(SEED)  # noqa: NPY002 - the global generator, in case of use
    torch.manual_seed(SEED)
    torch.set_num_threads(1)


def digest(arrays):
    """SHA-256 of a list of arrays (dtype, shape and bytes), as 32 uint8."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return np.frombuffer(h.digest(), dtype=np.uint8)


def outputs(model, X):
    """``{quantity: list of arrays, one per test sequence}`` of a fitted model."""
    out = {"predict": model.predict(X)}
    last = model.steps[-1][1]
    if hasattr(last, "predict_proba"):
        out["predict_proba"] = model.predict_proba(X)
    out["predict_segments"] = last.predict_segments(model[:-1].transform(X))
    if "segmenter" in model.named_steps:
        before = list(model.named_steps).index("segmenter")
        segmenter = model.named_steps["segmenter"]
        out["segmenter_decision"] = segmenter.decision_function(
            model[:before].transform(X)
        )
    rec = StreamingRecognizer(model)
    out["stream"] = []
    for x in X:
        events = rec.recognize(x)
        rows = [(e.label, e.start, e.end, e.confidence, e.emitted_at) for e in events]
        out["stream"].append(np.array(rows, dtype=np.float64).reshape(-1, 5))
    return {q: [np.asarray(a) for a in arrays] for q, arrays in out.items()}


def collect(methods, datasets):
    """Every stored array, keyed ``method__dataset__quantity__i``."""
    arrays = {
        f"{META}{SEP}skgesture_version": np.array(skgesture.__version__),
        f"{META}{SEP}skgesture_file": np.array(skgesture.__file__),
    }
    for dataset in datasets:
        X_train, y_train, X_test = load(dataset)
        arrays[f"data{SEP}{dataset}{SEP}sha256{SEP}0"] = digest(
            list(X_train) + list(y_train) + list(X_test)
        )
        for method in methods:
            _seed_globals()
            t0 = time.perf_counter()
            model = build(method, JOINTS[dataset]).fit(X_train, y_train)
            t1 = time.perf_counter()
            out = outputs(model, X_test)
            t2 = time.perf_counter()
            for q, values in out.items():
                for i, a in enumerate(values):
                    arrays[SEP.join((method, dataset, q, str(i)))] = a
            arrays[f"{META}{SEP}seconds{SEP}{method}{SEP}{dataset}"] = np.array(
                [t1 - t0, t2 - t1]
            )
            print(
                f"{method} {dataset:9s} fit {t1 - t0:6.1f} s, "
                f"predict + stream {t2 - t1:5.1f} s",
                flush=True,
            )
    return arrays


# -- reading and comparing ---------------------------------------------------------


def groups(arrays):
    """``{(method, dataset, quantity): [array per sequence]}``; meta left out."""
    out = {}
    for key in arrays:
        parts = key.split(SEP)
        if parts[0] == META:
            continue
        method, dataset, quantity, i = parts
        out.setdefault((method, dataset, quantity), {})[int(i)] = arrays[key]
    return {k: [v[i] for i in sorted(v)] for k, v in sorted(out.items())}


def _max_abs_diff(a, b):
    if a.shape != b.shape:
        return np.inf
    if a.size == 0:
        return 0.0
    if a.dtype.kind not in "biuf" or b.dtype.kind not in "biuf":
        return 0.0 if np.array_equal(a, b) else np.inf
    d = np.abs(a.astype(np.float64) - b.astype(np.float64))
    both_nan = np.isnan(a.astype(np.float64)) & np.isnan(b.astype(np.float64))
    d[both_nan] = 0.0
    return float(np.nan_to_num(d, nan=np.inf).max())


def _identical(a, b):
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))


def agreement(arrays):
    """Streamed events against offline prediction, per (method, dataset).

    ``events``: share of test sequences whose events have exactly the
    ``(class, start, end)`` rows of ``predict_segments``; ``frames``: share of
    test frames whose streamed label equals ``predict``; ``conf``: the largest
    confidence difference over matching event lists.
    """
    g = groups(arrays)
    rows = []
    for method, dataset, quantity in g:
        if quantity != "stream":
            continue
        stream = g[(method, dataset, "stream")]
        segs = g.get((method, dataset, "predict_segments"), [])
        labels = g.get((method, dataset, "predict"), [])
        same_events, conf, equal, total = 0, 0.0, 0, 0
        for ev, seg, lab in zip(stream, segs, labels, strict=True):
            if ev[:, :3].shape == seg[:, :3].shape and np.array_equal(
                ev[:, :3], seg[:, :3]
            ):
                same_events += 1
                if len(ev):
                    conf = max(conf, float(np.abs(ev[:, 3] - seg[:, 3]).max()))
            live = segments_to_labels(
                ev[:, :3].astype(np.int64), len(lab), on_overlap="later"
            )
            equal += int((live == lab).sum())
            total += len(lab)
        rows.append((method, dataset, same_events / len(stream), equal / total, conf))
    return rows


def print_agreement(arrays, title):
    print(f"\nstream vs offline ({title})")
    print(f"{'method':6s} {'dataset':9s} {'events':>7s} {'frames':>7s} {'conf':>9s}")
    for method, dataset, events, frames, conf in agreement(arrays):
        print(f"{method:6s} {dataset:9s} {events:7.3f} {frames:7.3f} {conf:9.2e}")


def compare(path_a, path_b):
    """Print the comparison table; return the number of differing rows."""
    a = dict(np.load(path_a))
    b = dict(np.load(path_b))
    ga, gb = groups(a), groups(b)
    bad = 0
    print(f"A = {path_a}\nB = {path_b}")
    for name in ("skgesture_version", "skgesture_file"):
        key = f"{META}{SEP}{name}"
        print(f"{name}: A {a.get(key, '?')}, B {b.get(key, '?')}")
    print(
        f"\n{'method':6s} {'dataset':9s} {'quantity':18s} {'seqs':>4s} "
        f"{'identical':>9s} {'max abs diff':>12s}"
    )
    for key in sorted(set(ga) | set(gb)):
        method, dataset, quantity = key
        if key not in ga or key not in gb:
            where = "A" if key not in ga else "B"
            status, diff, n = f"no ({where} lacks)", "", len(ga.get(key, gb.get(key)))
        else:
            xs, ys = ga[key], gb[key]
            n = max(len(xs), len(ys))
            same = len(xs) == len(ys) and all(map(_identical, xs, ys))
            if len(xs) == len(ys):
                d = max((_max_abs_diff(x, y) for x, y in zip(xs, ys)), default=0.0)
            else:
                d = np.inf
            status, diff = ("yes" if same else "no"), f"{d:.3g}"
        bad += status != "yes"
        print(
            f"{method:6s} {dataset:9s} {quantity:18s} {n:4d} {status:>9s} {diff:>12s}"
        )
    print_agreement(a, "A")
    print_agreement(b, "B")
    print(f"\n{'IDENTICAL' if bad == 0 else f'{bad} ROWS DIFFER'}")
    return bad


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Bit-identity check of the restructure (see the docstring)."
    )
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--out", help="run everything and write this .npz")
    mode.add_argument("--compare", nargs=2, metavar=("A", "B"), help="two .npz files")
    parser.add_argument(
        "--methods", default=",".join(METHODS), help="subset of A,B,C,R"
    )
    parser.add_argument(
        "--datasets", default=",".join(DATASETS), help="subset of precog,synthetic"
    )
    args = parser.parse_args(argv)
    if args.compare:
        return 1 if compare(*args.compare) else 0
    methods = [m for m in args.methods.split(",") if m]
    datasets = [d for d in args.datasets.split(",") if d]
    for m in methods:
        if m not in METHODS:
            parser.error(f"unknown method {m!r}")
    for d in datasets:
        if d not in DATASETS:
            parser.error(f"unknown dataset {d!r}")
    print(f"skgesture {skgesture.__version__} from {skgesture.__file__}")
    t0 = time.perf_counter()
    arrays = collect(methods, datasets)
    np.savez_compressed(args.out, **arrays)
    print(
        f"wrote {args.out} ({os.path.getsize(args.out)} B) in "
        f"{time.perf_counter() - t0:.1f} s"
    )
    print_agreement(arrays, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
