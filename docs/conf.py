"""Sphinx configuration: ``make docs`` (``sphinx-build -W docs docs/_build/html``).

Needs the ``docs`` extra. Every generated file stays in ignored folders
(``docs/_build``, ``docs/generated``, ``docs/auto_examples``,
``docs/sg_execution_times.rst``); the examples write their own files into a
temporary folder (see ``docs/gallery_args.py``).
"""

import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import skgesture  # noqa: E402

project = "skgesture"
author = "skgesture developers"
copyright = "skgesture developers"
release = skgesture.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "sg_execution_times.rst", "**.ipynb_checkpoints"]
templates_path = ["_templates"]

autosummary_generate = True
autodoc_default_options = {"inherited-members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# Markdown links to headings (``[...](method.md#slug)``) resolve, to depth 4.
myst_heading_anchors = 4
myst_enable_extensions = ["dollarmath"]

sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    # Every example runs (plot_* and the others); gallery_args.py gives the
    # slower ones their quick command-line options.
    "filename_pattern": r".*\.py$",
    "ignore_pattern": r"__init__\.py",
    "reset_argv": "gallery_args.reset_argv",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
}

html_theme = "alabaster"
html_static_path = []
html_theme_options = {"description": "Gesture recognition from skeletons"}

# Examples that draw figures use the Agg backend; tqdm bars go to stderr.
warnings.filterwarnings("ignore", message="Matplotlib is currently using agg")
os.environ.setdefault("MPLBACKEND", "Agg")
