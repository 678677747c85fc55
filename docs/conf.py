"""Sphinx configuration of the boxplus documentation (``make docs``).

The API pages are autodoc over the installed package (the extension must be
built: ``make install``); docstrings are NumPy style (napoleon). The built-in
"alabaster" theme keeps the build small. ``make docs`` runs with ``-W``:
every warning is an error.
"""

import sys
from pathlib import Path

import boxplus

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "boxplus"
author = "the boxplus authors"
copyright = "the boxplus authors"
version = release = boxplus.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",  # the guide pages (docs/guide/*.md), readable on GitHub as they are
    "boxplus_docs",  # _ext/boxplus_docs.py: command help and C++ headers from the code
]
exclude_patterns = ["_build"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
# The guide pages link to files of the repository (examples/, bench/, cpp/), which
# are not pages of the site; those links work where the pages are read on GitHub.
suppress_warnings = ["myst.xref_missing"]
html_theme = "alabaster"
# Alabaster's 940 px page cut the examples' code lines (seen in a headless browser);
# a wider page and a smaller code font show 100-column lines whole.
html_theme_options = {"page_width": "1320px", "sidebar_width": "240px", "code_font_size": "0.8em"}
html_static_path: list = []
html_title = f"boxplus {release}"

# Members are listed per directive in api/*.rst (a module's re-exports would
# otherwise be documented twice).
autodoc_default_options = {"show-inheritance": True}
autodoc_member_order = "bysource"
# Signatures as written; the pybind11 classes carry their own in the docstrings.
autodoc_typehints = "signature"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
# "Attributes" sections as fields, not directives: a documented attribute that
# is also a bound property would be described twice.
napoleon_use_ivar = True
# The NumPy-style "x : array_like" would otherwise become cross-references
# that cannot resolve (array_like, callable, optional, ...).
napoleon_preprocess_types = False
nitpicky = False
