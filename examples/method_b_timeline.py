"""
==========================================
Method B on a held-out PRECOG stream, seen
==========================================

Trains Method B on PRECOG subjects 1-6 (bundled data) and draws, for one
stream of an unseen subject, the true actions, the predicted ones and the
segmenter's smoothed gesture score with its 0.4 threshold.
Takes about a minute on two CPU cores; ``--fast`` trains small networks in a
few seconds (what the docs build runs, with lower scores).
"""

# %%
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from skgesture import TorchMLPClassifier, make_method_b
from skgesture.datasets import load_precog
from skgesture.metrics import jaccard_index
from skgesture.plotting import plot_gesture_timeline

args = [a for a in sys.argv[1:] if a != "--fast"]
data = load_precog()
groups = np.asarray(data.groups)
train = np.flatnonzero(groups <= 6)
test = np.flatnonzero(groups > 6)
model = make_method_b(joints="full20", random_state=0)
if "--fast" in sys.argv[1:]:
    model.set_params(
        segmenter__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(32,), activations=("tanh",), max_epochs=100
        ),
        classifier__estimator=TorchMLPClassifier(
            hidden_layer_sizes=(64,), activations=("tanh",), max_epochs=100
        ),
    )
model.fit([data.X[i] for i in train], [data.y[i] for i in train], fps=data.fps)

# %%
X_te = [data.X[i] for i in test]
y_te = [data.y[i] for i in test]
pred = model.predict(X_te)
print(f"Jaccard on subjects 7-8: {jaccard_index(y_te, pred):.3f}")

# %%
# The first held-out stream, with the segmenter's score.
D = model[:1].transform(X_te[:1])
score = model.named_steps["segmenter"].decision_function(D)[0]
ax = plot_gesture_timeline(
    y_te[0],
    pred[0],
    scores=score,
    threshold=model.named_steps["segmenter"].threshold,
    fps=data.fps,
    target_names=data.target_names,
    title=f"{data.sample_ids[test[0]]} (unseen subject)",
)
plt.tight_layout()
out = args[0] if args else "method_b_timeline.png"
plt.savefig(out, dpi=100)
print(f"saved {out}")
