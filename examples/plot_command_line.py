"""
=====================================
The command line: train, score, write
=====================================

``skgesture`` (or ``python -m skgesture``) trains a model and writes it to a
safe model file, scores it, writes prediction files and draws figures, without
writing Python. This example runs it on synthetic streams, small and fast
(``--fast`` trains small networks); replace ``synthetic`` by ``precog`` (the
bundled recordings), a ChaLearn folder or a folder of your own recordings.
Every command has ``--help``.
"""

# %%
# The commands
# ------------
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.image as mpimg
import matplotlib.pyplot as plt


def skgesture(*args):
    """Run ``python -m skgesture ARGS`` and print what it prints."""
    command = [sys.executable, "-m", "skgesture", *args]
    print("$ skgesture", " ".join(args))
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    print(done.stdout + done.stderr)
    done.check_returncode()
    return done.stdout


skgesture("--help")

# %%
# Train, evaluate, predict
# ------------------------
# Training data and held-out data are two synthetic sets with different seeds.
work = Path(tempfile.mkdtemp(prefix="skgesture_cli_"))
model = work / "model.skg"
data = ["synthetic", "--n-sequences", "12", "--n-classes", "4"]
skgesture("train", *data, "--data-seed", "0", "--method", "A", "--fast", "-q",
          "-o", str(model))  # fmt: skip
skgesture("evaluate", str(model), *data, "--data-seed", "1", "-q")
skgesture("predict", str(model), *data, "--data-seed", "1", "-q",
          "-o", str(work / "predictions"))  # fmt: skip
files = sorted((work / "predictions").iterdir())
print(f"{len(files)} prediction files, e.g. {files[0].name}:")
print(files[0].read_text()[:200])

# %%
# A figure
# --------
# ``skgesture plot`` draws the timeline, segmentation, confusion matrix or
# skeleton figures of :mod:`skgesture.plotting` to a file.
png = work / "timeline.png"
skgesture("plot", "timeline", *data, "--data-seed", "1", "--model", str(model),
          "-q", "-o", str(png))  # fmt: skip
fig, ax = plt.subplots(figsize=(10, 5))
ax.imshow(mpimg.imread(png))
ax.set_axis_off()
fig.tight_layout()
