"""Sphinx configuration: ``sphinx-build docs docs/_build`` (needs the docs extra)."""

project = "skgesture"
author = "skgesture developers"
extensions = [
    "numpydoc",
    "sphinx.ext.autosummary",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
]
autosummary_generate = True
numpydoc_show_class_members = False
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
}
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
html_theme = "alabaster"
