"""Sphinx configuration for curvefair's documentation (``make docs``).

Built with warnings as errors (``sphinx-build -W --keep-going``): the API reference is read
from the numpydoc docstrings, the Markdown pages (formats, benchmarks) through MyST, and the
gallery scripts in ``examples/`` are run at build time by sphinx-gallery, which embeds their
figures.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "docs"))  # _gallery.py
os.environ.setdefault("CURVEFAIR_QUIET", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import curvefair  # noqa: E402

project = "curvefair"
author = "curvefair developers"
copyright = "curvefair developers, BSD-3-Clause"  # noqa: A001
release = version = curvefair.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "img/bench", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "auto_examples/*.md5"]

# autodoc / numpydoc: members follow each module's ``__all__``; no class member tables
# (numpydoc would otherwise list every attribute twice, once from autodoc)
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

html_theme = "alabaster"
html_static_path: list[str] = []
html_title = f"curvefair {release}"

# the gallery: every examples/plot_*.py is run at build time; its figures are embedded
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"(demo\.py|__init__\.py)$",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "plot_gallery": "True",
    "matplotlib_animations": False,
    "image_scrapers": ("_gallery.curvefair_scraper",),
    "write_computation_times": False,
    "show_memory": False,
    "show_signature": False,
}

suppress_warnings: list[str] = []
