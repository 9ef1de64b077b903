"""Sphinx configuration of the assocopt documentation site.

Build it with ``python -m sphinx -W --keep-going -b html docs docs/_build/html``
(``pip install -e ".[docs]"`` first) and open ``docs/_build/html/index.html``.
The Markdown pages are read by MyST, the notebooks are executed by MyST-NB, the
gallery (``docs/gallery``) by sphinx-gallery, and the API reference is generated
from the package by ``docs/_ext/assocopt_api.py``.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))          # the checkout's assocopt wins

import assocopt  # noqa: E402

project = "assocopt"
author = "the assocopt developers"
copyright = "the assocopt developers"
release = version = assocopt.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_nb",
    "sphinx_gallery.gen_gallery",
    "assocopt_api",
]

root_doc = "index"
templates_path = ["_templates"]
# README.md is the index of the Markdown pages as GitHub shows them (index.md includes
# it); sphinx-gallery writes a notebook beside each example page, not a page itself
exclude_patterns = ["_build", "**.ipynb_checkpoints", "README.md", "jupyter_execute",
                    "auto_examples/*.ipynb", "auto_examples/**/*.ipynb"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}

# -- API reference ---------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"                 # the numpydoc Parameters say the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# -- Markdown and notebooks ------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 4
# the papers' tables.md files are sections (### ...) cut out of the pages, and two
# paper pages go from # to ###; both are kept as they are
suppress_warnings = ["myst.header"]
nb_execution_mode = "cache"                # executed once, kept in _build/.jupyter_cache
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_execution_in_temp = True                # a notebook must not write into docs/

# -- Gallery ---------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "abort_on_example_error": True,
    "write_computation_times": False,
}

# -- HTML ------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"assocopt {version}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_sidebars = {"index": []}
html_show_sourcelink = False


# -- Paper tables ----------------------------------------------------------------
# Each paper's NAME/tables.md (the run's full tables, written by the reproduction) is
# built and linked from its paper page, but listed in no toctree, so the section
# navigation shows the papers, not their tables: the page is marked orphan here,
# leaving the generated file exactly as the reproduction writes it.
_PAPER_TABLES = re.compile(r"papers/[\w-]+/tables")


def _orphan_paper_tables(app, docname: str, source: list[str]) -> None:
    if _PAPER_TABLES.fullmatch(docname):
        source[0] = "---\norphan: true\n---\n" + source[0]


def setup(app):
    app.connect("source-read", _orphan_paper_tables)
