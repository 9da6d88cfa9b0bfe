"""Command-line arguments of the gallery examples during ``make docs``.

sphinx-gallery runs each example as ``__main__`` in ``examples/``; this gives
the scripts that parse options their quick settings and sends every file they
write to a temporary folder, so a docs build leaves the tree clean.
"""

import os
import tempfile

_OUT = tempfile.mkdtemp(prefix="skgesture_docs_")


def reset_argv(gallery_conf, script_vars):
    """Return ``sys.argv[1:]`` for one example (sphinx-gallery's ``reset_argv``)."""
    name = os.path.basename(script_vars["src_file"])
    stem = os.path.splitext(name)[0]
    png = os.path.join(_OUT, stem + ".png")
    return {
        "demo.py": ["--fast"],
        "robot_pick_and_place.py": ["--fast", "--out", _OUT],
        "method_b_timeline.py": ["--fast", png],
        "plot_pose_descriptor.py": [png],
    }.get(name, [])
