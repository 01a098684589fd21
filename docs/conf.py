"""Sphinx configuration of the multiscale user guide (make docs)."""
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import multiscale  # noqa: E402

project = "multiscale"
author = "the multiscale developers"
release = version = multiscale.__version__
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "myst_parser", "multiscale_docs"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "accuracy"]
nitpicky = True                      # a broken cross-reference is an error (make docs runs -W)
autodoc_typehints = "none"           # signatures without annotations: no links to numpy/dolfinx types
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False}
napoleon_google_docstring = False
napoleon_numpy_docstring = False
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]
html_theme = "alabaster"
html_theme_options = {"description": "multi-scale thermo-mechanics of frictional sliding contacts",
                      "page_width": "1150px", "sidebar_width": "230px"}
html_title = f"multiscale {release}"
