"""Make the legacy model fixtures: tiny models saved by skgesture at commit 59fafcb.

The files next to this script were written by the release at commit 59fafcb,
before the package was restructured (``skgesture/_incremental.py``,
``_tagger.py``, ``_networks.py``, ... moved into subpackages). They let the
tests prove that model files and joblib pickles written by that release still
load and predict exactly as they did then.

This script documents how they were made. It uses only the public API and is
meant to run against commit 59fafcb only (later code would write files of the
new layout, which defeats their purpose)::

    git worktree add /tmp/old59 59fafcb
    cd /tmp/old59 && PYTHONPATH=/tmp/old59 OMP_NUM_THREADS=1 \\
        /work/main/.venv/bin/python \\
        /work/main/tests/data/legacy/make_legacy_fixtures.py

``--check`` only loads the existing files and compares their outputs with the
stored ones (it runs against any version that can load them).

Three tiny models are trained on small synthetic streams (3 classes, 6 training
sequences) with fixed seeds:

* ``method_b``: :func:`skgesture.make_method_b` with 16-8 networks;
* ``recommended``: :func:`skgesture.make_recommended` with a 1-stage,
  3-layer, 8-channel TCN;
* ``method_c``: :func:`skgesture.make_method_c` with an 8-unit BiLSTM.

Each is written as ``<name>.skg`` (:func:`skgesture.save_model`) and
``<name>.joblib`` (``joblib.dump(..., compress=3)``). ``inputs_expected.npz``
holds the three test sequences (``X__<i>``) and, for every model, the outputs
at 59fafcb (keys ``<name>__<quantity>__<i>``): ``predict``, ``predict_proba``
(taggers), ``predict_segments`` of the last step on the transformed input,
the segmenter's ``decision_function`` (Method B), and the events of
:class:`skgesture.streaming.StreamingRecognizer` (``stream``: rows ``label,
start, end, confidence, emitted_at``).
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
import os
import sys
import time
from pathlib import Path

import joblib
import numpy as np

from skgesture import (
    load_model,
    make_method_b,
    make_method_c,
    make_recommended,
    save_model,
)
from skgesture.datasets import make_gesture_streams
from skgesture.streaming import StreamingRecognizer

HERE = Path(__file__).resolve().parent
NAMES = ("method_b", "recommended", "method_c")
N_TRAIN = 6
N_TEST = 3
SEED = 0


def make_data():
    """Small synthetic streams: 6 for training, 3 (about 240-400 frames) to test."""
    data = make_gesture_streams(
        n_sequences=N_TRAIN + N_TEST, n_classes=3, n_gestures=(3, 4), random_state=SEED
    )
    # Sequence 0 (780 frames) is the longest: train on it, test on short ones.
    return data.X[:N_TRAIN], data.y[:N_TRAIN], data.X[N_TRAIN:]


def make_model(name):
    """The unfitted tiny model ``name``."""
    if name == "method_b":
        small = {"hidden_layer_sizes": (16, 8), "max_epochs": 30}
        params = {f"segmenter__estimator__{k}": v for k, v in small.items()}
        params.update({f"classifier__estimator__{k}": v for k, v in small.items()})
        return make_method_b(random_state=SEED).set_params(**params)
    if name == "recommended":
        return make_recommended(random_state=SEED).set_params(
            tagger__hidden_sizes=(8,),
            tagger__tcn_layers=3,
            tagger__tcn_stages=1,
            tagger__crop_length=64,
            tagger__batch_size=8,
            tagger__steps_per_epoch=5,
            tagger__max_epochs=3,
        )
    if name == "method_c":
        return make_method_c(random_state=SEED).set_params(
            tagger__hidden_sizes=(8,), tagger__max_epochs=3
        )
    raise ValueError(name)


def outputs(model, X):
    """Every output to compare: ``{quantity: list of arrays, one per sequence}``."""
    out = {"predict": model.predict(X)}
    last = model.steps[-1][1]
    if hasattr(last, "predict_proba"):
        out["predict_proba"] = model.predict_proba(X)
    Xt = model[:-1].transform(X)
    out["predict_segments"] = last.predict_segments(Xt)
    if "segmenter" in model.named_steps:
        Xd = model[: list(model.named_steps).index("segmenter")].transform(X)
        out["segmenter_decision"] = model.named_steps["segmenter"].decision_function(Xd)
    rec = StreamingRecognizer(model)
    out["stream"] = [
        np.array(
            [(e.label, e.start, e.end, e.confidence, e.emitted_at) for e in events],
            dtype=np.float64,
        ).reshape(-1, 5)
        for events in (rec.recognize(x) for x in X)
    ]
    return {k: [np.asarray(a) for a in v] for k, v in out.items()}


def flatten(name, out):
    return {
        f"{name}__{q}__{i}": a
        for q, arrays in out.items()
        for i, a in enumerate(arrays)
    }


def expected(npz, name):
    """``{quantity: list of arrays}`` of model ``name`` stored in ``npz``."""
    out = {}
    for key in npz.files:
        model, _, rest = key.partition("__")
        if model == name:
            q, _, i = rest.rpartition("__")
            out.setdefault(q, {})[int(i)] = npz[key]
    return {q: [d[i] for i in sorted(d)] for q, d in out.items()}


def inputs(npz):
    return [npz[f"X__{i}"] for i in range(int(npz["n_test"]))]


def compare(name, kind, model, npz):
    """Outputs of a loaded model against the stored ones; True when all equal."""
    X = inputs(npz)
    got = outputs(model, X)
    want = expected(npz, name)
    ok = True
    for q in sorted(want):
        same = q in got and all(
            a.shape == b.shape and np.array_equal(a, b)
            for a, b in zip(got[q], want[q], strict=True)
        )
        ok &= same
        print(f"  {name:12s} {kind:7s} {q:20s} {'identical' if same else 'DIFFERS'}")
    return ok


def check(folder):
    npz = np.load(folder / "inputs_expected.npz")
    ok = True
    for name in NAMES:
        ok &= compare(name, "skg", load_model(folder / f"{name}.skg"), npz)
        ok &= compare(name, "joblib", joblib.load(folder / f"{name}.joblib"), npz)
    return ok


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE, help="folder to write")
    parser.add_argument("--check", action="store_true", help="only check the files")
    args = parser.parse_args(argv)
    folder = args.out
    if not args.check:
        import skgesture

        folder.mkdir(parents=True, exist_ok=True)
        X_train, y_train, X_test = make_data()
        arrays = {f"X__{i}": x for i, x in enumerate(X_test)}
        arrays["n_test"] = np.array(len(X_test))
        arrays["skgesture_version"] = np.array(skgesture.__version__)
        for name in NAMES:
            t0 = time.perf_counter()
            model = make_model(name).fit(X_train, y_train)
            fit_s = time.perf_counter() - t0
            save_model(model, folder / f"{name}.skg", metadata={"fixture": name})
            joblib.dump(model, folder / f"{name}.joblib", compress=3)
            arrays.update(flatten(name, outputs(model, X_test)))
            sizes = [os.path.getsize(folder / f"{name}.{e}") for e in ("skg", "joblib")]
            print(f"{name}: fit {fit_s:.1f} s, .skg {sizes[0]} B, .joblib {sizes[1]} B")
        np.savez_compressed(folder / "inputs_expected.npz", **arrays)
        print(
            f"inputs_expected.npz {os.path.getsize(folder / 'inputs_expected.npz')} B"
        )
    ok = check(folder)
    print("all identical" if ok else "SOME OUTPUTS DIFFER")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
