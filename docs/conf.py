"""Sphinx configuration: the Markdown pages (MyST) and an API reference from the docstrings.

Build: ``sphinx-build -W -b html docs docs/_build/html``.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

project = "reflector_opt"
author = "reflector_opt contributors"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "README.md"]
myst_heading_anchors = 3
# Links from the Markdown pages to files outside docs/ (README.md, examples/) are not Sphinx
# documents; tests/test_docs.py checks that every relative link resolves.
suppress_warnings = ["myst.xref_missing"]
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": False}
html_theme = "alabaster"
