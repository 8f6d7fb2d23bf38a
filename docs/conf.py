"""Sphinx configuration of the stewartid documentation site.

Build: ``pip install -e ".[docs]"`` then ``python -m sphinx -W -b html docs/ docs/_build/html``.
The build needs no network: links to the numpy, scipy, pandas and matplotlib documentation
(intersphinx) are made only when ``STEWARTID_DOCS_INTERSPHINX=1`` asks for them; without it,
references to those projects stay plain text. The gallery (``examples/``) is executed on
every build.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(DOCS))
os.environ.setdefault("MPLBACKEND", "Agg")

from method_pages import write_method_pages  # noqa: E402
from plain_bars import process_docstring  # noqa: E402

import stewartid  # noqa: E402

project = "stewartid"
author = "stewartid developers"
copyright = "stewartid developers"  # noqa: A001
release = version = stewartid.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip", "auto_examples/*.json",
                    "auto_examples/*.md5", "sg_execution_times.rst"]
templates_path = ["_templates"]

# --- the user guide: the Markdown pages of docs/ ----------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
# the pages link to files of the repository (src/..., benchmarks/...), which are not pages
suppress_warnings = ["myst.xref_missing", "myst.header"]

# --- the API reference ------------------------------------------------------------------------
autosummary_generate = True
autosummary_ignore_module_all = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_typehints = "none"
add_module_names = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# --- links to the libraries stewartid builds on (network only on request) ---------------------
intersphinx_mapping: dict[str, tuple[str, None]] = {}
if os.environ.get("STEWARTID_DOCS_INTERSPHINX") == "1":
    intersphinx_mapping = {
        "python": ("https://docs.python.org/3", None),
        "numpy": ("https://numpy.org/doc/stable", None),
        "scipy": ("https://docs.scipy.org/doc/scipy", None),
        "pandas": ("https://pandas.pydata.org/docs", None),
        "matplotlib": ("https://matplotlib.org/stable", None),
    }
intersphinx_timeout = 10

# --- the gallery --------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
    "show_memory": False,
    "write_computation_times": True,
}

# --- the page --------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"stewartid {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 6,
}
html_show_sourcelink = False


def setup(app):  # noqa: ANN001, ANN201 - the Sphinx extension hook
    """Write one page per registered identification method before the sources are read, and
    let the docstrings' bars (``|x|``) stand for themselves."""
    app.connect("builder-inited", lambda app: write_method_pages(DOCS / "api" / "methods"))
    app.connect("autodoc-process-docstring", process_docstring, priority=400)
