"""Frame rates (issue 17): a model trained at one rate, tested at others.

The recommended model (``make_recommended(joints="full20")``) and Method B
(``make_method_b(joints="full20")``, the paper's networks) are trained on
PRECOG subjects 1-6 at its 30 fps and tested on the held-out subjects 7 and 8
(the bundle holds subjects 1-8), the test streams resampled to

* 30 fps: as recorded (the rate of training);
* 15 fps: every 2nd frame; 10 fps: every 3rd frame;
* 20 and 60 fps: linear interpolation (``skgesture._rate.resample``);

with the labels taken at the same frames (at 20 and 60 fps: the label of the
recorded frame nearest in time). ``jaccard_before`` predicts as a model
without rates did (``predict(X)``: a frame is a frame); ``jaccard_after``
tells the model the input's rate (``predict(X, fps=...)``), so it resamples to
its own 30 fps and maps the labels back to the input's frames. The Jaccard
index is the official ChaLearn 2014 one, on the input's frames.

``python benchmarks/bench_rate.py [--quick]`` prints the table; ``run(quick)``
returns the rows. ``--quick`` trains on subject 1 for few epochs and tests on
two streams of subject 8 (a smoke run of about a minute); the full run fits
each model once (a few minutes each on 2 cores).
"""

import argparse
import time

import numpy as np
from _common import format_table, machine_line

from skgesture import make_method_b, make_recommended
from skgesture._rate import RateMap, resample
from skgesture.datasets import load_precog
from skgesture.metrics import jaccard_index

TRAIN_SUBJECTS = (1, 2, 3, 4, 5, 6)
TEST_SUBJECTS = (7, 8)
RATES = (  # (fps, how the test streams are made at that rate)
    (30.0, "as recorded"),
    (15.0, "every 2nd frame"),
    (10.0, "every 3rd frame"),
    (20.0, "linear interpolation"),
    (60.0, "linear interpolation"),
)
COLUMNS = [
    "model",
    "test_fps",
    "test_streams",
    "jaccard_before",
    "jaccard_after",
    "after_minus_30fps",
    "fit_s",
]
NOTES = [
    "trained on PRECOG subjects 1-6 at 30 fps, tested on subjects 7-8 at each "
    "rate; before: predict(X), a frame taken as a frame; after: "
    "predict(X, fps=rate), resampled to the model's 30 fps and mapped back "
    "(--quick: trained on subject 1 for few epochs, two streams of subject 8)",
    "after_minus_30fps: jaccard_after minus the 30 fps score (issue 17's "
    "targets: within 0.02 at 15, 20 and 60 fps, within 0.05 at 10 fps)",
]


def _at_rate(x, y, fps, model_fps=30.0):
    """A recorded stream (and its labels) at ``fps`` (module docstring)."""
    if fps == model_fps:
        return x, y
    k = model_fps / fps
    if float(k).is_integer():  # every k-th frame
        return x[:: int(k)], y[:: int(k)]
    xr = resample(x, model_fps, fps)
    # each frame at fps takes the label of the recorded frame nearest in time
    nearest = RateMap(fps, model_fps).nearest(np.arange(len(xr)), len(y))
    return xr, y[nearest]


def _models(quick):
    recommended = make_recommended(joints="full20", random_state=0)
    method_b = make_method_b(joints="full20", random_state=0)
    if quick:
        recommended.set_params(tagger__max_epochs=3, tagger__steps_per_epoch=5)
        for step in ("segmenter", "classifier"):
            method_b.set_params(**{f"{step}__estimator__max_epochs": 20})
    return {"recommended": recommended, "B": method_b}


def run(quick=False):
    data = load_precog()
    train = TRAIN_SUBJECTS[:1] if quick else TRAIN_SUBJECTS
    test = TEST_SUBJECTS[-1:] if quick else TEST_SUBJECTS
    tr = [i for i, g in enumerate(data.groups) if g in train]
    te = [i for i, g in enumerate(data.groups) if g in test]
    if quick:
        te = te[:2]
    rows = []
    for name, model in _models(quick).items():
        start = time.perf_counter()
        model.fit([data.X[i] for i in tr], [data.y[i] for i in tr], fps=data.fps)
        fit_s = time.perf_counter() - start
        base = None
        for fps, how in RATES:
            pairs = [_at_rate(data.X[i], data.y[i], fps) for i in te]
            X, y = [p[0] for p in pairs], [p[1] for p in pairs]
            before = float(jaccard_index(y, model.predict(X)))
            after = float(jaccard_index(y, model.predict(X, fps=fps)))
            base = after if base is None else base
            rows.append(
                {
                    "model": name,
                    "test_fps": f"{fps:g} ({how})",
                    "test_streams": len(X),
                    "jaccard_before": before,
                    "jaccard_after": after,
                    "after_minus_30fps": after - base,
                    "fit_s": round(fit_s, 1),
                }
            )
            print(
                f"  {name:<12} {fps:>4g} fps  before {before:.3f}  after {after:.3f}",
                flush=True,
            )
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny data, few epochs")
    args = parser.parse_args(argv)
    print(machine_line(), flush=True)
    rows = run(quick=args.quick)
    title = "Frame rates: trained at 30 fps, tested at others"
    print(format_table(rows, COLUMNS, title))
    print("".join(f"* {note}\n" for note in NOTES))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
