"""Sphinx configuration of the skmotion documentation site.

Build: ``pip install -e ".[docs]"`` then ``sphinx-build -W -b html docs docs/_build/html``.
The user guide is the Markdown pages of this folder (MyST), the API reference comes from
the numpydoc docstrings (``api.rst``), and ``../examples`` becomes a gallery whose scripts
run at build time (sphinx-gallery).
"""

import os
import re
import sys

sys.path.insert(0, os.path.abspath(".."))
os.environ.setdefault("MPLBACKEND", "Agg")

import skmotion  # noqa: E402

project = "skmotion"
author = "the skmotion developers"
release = version = skmotion.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx_gallery.gen_gallery",
]
root_doc = "contents"
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "generated/*.examples", "auto_examples/*.ipynb"]

# The Markdown pages link to files beside the docs (tests, benchmarks): plain links there.
myst_heading_anchors = 3
suppress_warnings = ["myst.xref_missing"]

autosummary_generate = True
autodoc_default_options = {"members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": "/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "plot_gallery": "True",
}

html_theme = "alabaster"
html_title = f"skmotion {release}"

# Docstrings name fitted attributes in prose (``n_features_in_``, ``n_components_``):
# reStructuredText reads a word ending in "_" as a link. Outside code, quote such words.
_REF = re.compile(r":ref:`([^<`]+?) *<[^>`]+>`")
_FITTED = re.compile(r"(?<![`\w*:])\b([A-Za-z][A-Za-z0-9_]*[A-Za-z0-9]_)(?![`\w(])")


def _quote_fitted_names(app, what, name, obj, options, lines):
    in_code = False
    for k, line in enumerate(lines):
        stripped = line.strip()
        if stripped.startswith((">>>", "...")) or stripped.endswith("::"):
            in_code = stripped.endswith("::")
            continue
        if in_code and (not stripped or line.startswith((" ", "\t"))):
            continue
        in_code = False
        parts = line.split("``")
        parts[::2] = [_FITTED.sub(r"``\1``", part) for part in parts[::2]]
        # scikit-learn's inherited docstrings (score) cite labels of its own site
        lines[k] = _REF.sub(r"\1", "``".join(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _quote_fitted_names)
