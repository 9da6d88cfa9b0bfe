"""
===================================================
ChaLearn prediction files and the official Jaccard
===================================================

The ChaLearn LAP 2014 Track 3 challenge scores one ``SampleXXXX_prediction.csv``
file per sequence against its ``SampleXXXX_labels.csv``: one
``class,start,end`` line per gesture, 1-based and inclusive frames
(docs/method.md §1.5, §1.7). This example

1. trains Method A on synthetic Montalbano-like streams (with small networks,
   so that it runs in seconds);
2. writes the predictions, and the ground truth, in the official format with
   :func:`~skgesture.datasets.write_chalearn_predictions`;
3. reads the files back and scores them line by line with
   :func:`~skgesture.metrics.jaccard_index_segments`, exactly as the official
   script does (docs/method.md §2.1), and checks that this gives the number
   :func:`~skgesture.metrics.jaccard_index` computes on the label arrays.
"""

# %%
# Train a quick Method A model
# ----------------------------
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from skgesture import TorchMLPClassifier, make_method_a
from skgesture.datasets import (
    make_gesture_streams,
    read_chalearn_labels,
    write_chalearn_predictions,
)
from skgesture.metrics import jaccard_index, jaccard_index_segments
from skgesture.plotting import plot_gesture_timeline

data = make_gesture_streams(16, n_classes=5, n_subjects=4, random_state=0)
test = data.groups == data.groups.max()  # one unseen subject
train = ~test
small = {"activations": ("tanh",), "max_epochs": 100}
model = make_method_a(random_state=0).set_params(
    segmenter__estimator=TorchMLPClassifier(hidden_layer_sizes=(32,), **small),
    classifier__estimator=TorchMLPClassifier(hidden_layer_sizes=(64,), **small),
)
model.fit(
    [x for x, t in zip(data.X, train) if t],
    [y for y, t in zip(data.y, train) if t],
    fps=data.fps,  # the model records the rate it was trained at
)
X_test = [x for x, t in zip(data.X, test) if t]
y_test = [y for y, t in zip(data.y, test) if t]
y_pred = model.predict(X_test)
n_frames = [len(y) for y in y_test]
sample_ids = [f"Sample{701 + i:04d}" for i in range(len(y_test))]
print(f"trained on {train.sum()} streams, predicting {len(y_test)} unseen ones")

# %%
# Write the official files
# ------------------------
# The ground truth has the same format as a prediction; it is written with the
# same function and renamed to ``_labels.csv``. Frames are clamped to
# ``1 <= start <= end <= numFrames``, so the official scorer never drops a line.
folder = Path(tempfile.mkdtemp(prefix="skgesture_chalearn_"))
pred_files = write_chalearn_predictions(
    y_pred, sample_ids, folder / "pred", n_frames=n_frames
)
truth_files = []
for path in write_chalearn_predictions(
    y_test, sample_ids, folder / "truth", n_frames=n_frames
):
    truth_files.append(
        path.rename(path.with_name(path.name.replace("_prediction", "_labels")))
    )
print(f"{pred_files[0].name}:")
print(pred_files[0].read_text())

# %%
# Score the files as the official script does
# -------------------------------------------
# :func:`~skgesture.datasets.read_chalearn_labels` returns 0-based segments with
# an exclusive end; ``start + 1`` gives back the file's 1-based lines, which
# :func:`~skgesture.metrics.jaccard_index_segments` reads as the script does
# (the labelled end frame is not counted).
rows = []
for truth, pred, n in zip(truth_files, pred_files, n_frames):
    gt_lines = read_chalearn_labels(truth) + [0, 1, 0]
    pred_lines = read_chalearn_labels(pred) + [0, 1, 0]
    rows.append(
        [
            jaccard_index_segments(gt_lines, pred_lines, n, mode=mode)
            for mode in ("official_2014", "fp_penalised")
        ]
    )
rows = np.array(rows)
from_files = rows[:, 0].mean()
from_arrays = jaccard_index(y_test, y_pred)
print(
    f"Jaccard from the files {from_files:.4f}, from the label arrays {from_arrays:.4f}"
)
assert np.isclose(from_files, from_arrays)

# %%
# Per-sequence scores, and the first sequence
# -------------------------------------------
# The official score ignores predicted classes absent from the ground truth;
# the penalised one (the challenge web page's definition) counts them.
fig, (ax_bar, ax_line) = plt.subplots(
    2, 1, figsize=(9, 5.5), gridspec_kw={"height_ratios": [1.2, 1]}
)
index = np.arange(len(rows))
ax_bar.bar(index - 0.2, rows[:, 0], 0.4, label="official 2014")
ax_bar.bar(index + 0.2, rows[:, 1], 0.4, label="fp-penalised")
ax_bar.set_xticks(index, sample_ids)
ax_bar.set_ylabel("Jaccard index")
ax_bar.set_ylim(0, 1.25)
ax_bar.legend(loc="upper center", ncols=2)
first = slice(0, 30 * int(data.fps))  # the first 30 s of the first stream
plot_gesture_timeline(
    y_test[0][first],
    y_pred[0][first],
    fps=data.fps,
    target_names=data.target_names,
    ax=ax_line,
    title=f"{sample_ids[0]}, first 30 s",
)
fig.tight_layout()
