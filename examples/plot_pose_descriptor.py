"""
=========================================
The pose descriptor of a synthetic stream
=========================================

The 183 features of the paper's descriptor over one synthetic stream, with the
gesture timeline above them. Rows are grouped as in the paper: positions,
velocities, accelerations, angles and pairwise distances.
"""

# %%
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from skgesture import PoseDescriptor
from skgesture.datasets import make_gesture_streams
from skgesture.plotting import plot_gesture_timeline

data = make_gesture_streams(20, n_classes=6, random_state=0)
desc = PoseDescriptor().fit(data.X)
D = desc.transform(data.X[:1])[0]
names = desc.get_feature_names_out()

# %%
# Standardised features (clipped at +-3) under the labels.
fig, (ax_top, ax) = plt.subplots(
    2, 1, figsize=(12, 7), sharex=True, gridspec_kw={"height_ratios": [1, 5]}
)
plot_gesture_timeline(data.y[0], ax=ax_top, target_names=data.target_names)
ax.imshow(np.clip(D.T, -3, 3), aspect="auto", cmap="RdBu_r", interpolation="nearest")
groups = ["pos_", "vel_", "acc_", "incl_", "azim_", "bend_", "dist_"]
starts = [int(np.argmax([n.startswith(g) for n in names])) for g in groups]
ax.set_yticks(starts, [g.rstrip("_") for g in groups])
ax.set_xlabel("frame")
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "pose_descriptor.png"
fig.savefig(out, dpi=100)
print(f"saved {out}: {D.shape[0]} frames x {D.shape[1]} features")
