"""Sphinx configuration of the substructure documentation.

Build it with ``make docs`` (HTML in docs/_build/html, warnings as errors);
how it is put together is explained in docs/writing-docs.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import offline_inventories  # noqa: E402
import public_api  # noqa: E402

import substructure  # noqa: E402

project = "substructure"
author = "the substructure developers"
copyright = "the substructure developers, BSD-3-Clause"
version = release = substructure.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    # the project's own, in docs/_ext/
    "api_pages",  # the API reference pages, from __all__
    "repo_links",  # links to files of the repository, mapped to site pages
    "gallery_support",  # the examples' PNG figures in the gallery, and its checks
    "offline_site",  # MathJax from _static, not a CDN; a check that no page loads from the network
    "chapter_figures",  # the chapter pages' figures, drawn from the library into docs/figures/
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "_inventories", "_templates", "_static", "figures", "**/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.md5", "auto_examples/*.zip", "auto_examples/*.json"]
templates_path = ["_templates"]

# -- Warnings: every unresolved reference is an error (with -W) ------------------------------------
nitpicky = True
# numpydoc writes the types of its Parameters sections as references (see the aliases
# below); words of a type that are not a known name stay text.
nitpick_ignore_regex = []
suppress_warnings = []

# -- MyST: the Markdown pages -----------------------------------------------------------------------
myst_heading_anchors = 4  # GitHub's anchors (#8-adding-an-effect), as the pages link them
myst_enable_extensions = ["colon_fence", "deflist"]

# -- API reference: autodoc, autosummary, numpydoc --------------------------------------------------
autosummary_generate = True  # the list of API pages is set by docs/_ext/api_pages.py
autosummary_imported_members = True
autodoc_typehints = "none"  # types and units are in the numpydoc text
autodoc_member_order = "groupwise"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = True
numpydoc_xref_ignore = "all"  # only the names below become links
numpydoc_xref_aliases = {
    # the package's own public names, found from __all__ (FRF -> substructure.FRF, ...)
    **{name: f"{entry.name}.{name}" for entry in reversed(public_api.public_modules())
       for name in entry.classes + entry.exceptions},
    "ndarray": "numpy.ndarray",
    "array_like": ":term:`numpy:array_like`",
    "Generator": "numpy.random.Generator",
    "Quantity": "pint.Quantity",
    "pint.Quantity": "pint.Quantity",
    "UnitRegistry": "pint.UnitRegistry",
    "Figure": "matplotlib.figure.Figure",
    "Axes": "matplotlib.axes.Axes",
    "PathLike": "os.PathLike",
    "os.PathLike": "os.PathLike",
    "Path": "pathlib.Path",
}
# The docstring check: the same numpydoc findings as tests/test_docstrings.py.
numpydoc_validation_checks = set(public_api.DOCSTRING_CHECKS)
numpydoc_validation_exclude = {
    r"^substructure\.\w+$",  # module docstrings: a paragraph, not a numpydoc function docstring
}

# -- Intersphinx, offline ---------------------------------------------------------------------------
# The inventories are written from docs/_inventories/*.txt (see docs/_ext/offline_inventories.py):
# the pages link to the projects' online documentation, and the build needs no network.
intersphinx_mapping = {
    key: (url, str(path))
    for key, (url, path) in offline_inventories.write_inventories(HERE / "_build" / "inventories").items()
}

# -- Gallery of the examples ------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": ["../examples"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/\d\d_",  # run every numbered example (output and figures on its page)
    "ignore_pattern": r"(__init__|conftest)\.py",
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("gallery_support.png_scraper",),
    "reset_modules": ("matplotlib", "gallery_support.prepare_example"),
    "reset_modules_order": "both",
    "download_all_examples": True,
    "remove_config_comments": True,
    "first_notebook_cell": "%matplotlib inline",
    "capture_repr": (),
    "show_memory": False,
    "min_reported_time": 1e9,  # no timings on the pages: they vary from machine to machine
    "matplotlib_animations": False,
    "plot_gallery": "True",
    "backreferences_dir": None,
    "doc_module": (),
    "show_signature": False,
    "write_computation_times": False,
}

# -- HTML -------------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"substructure {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc", "sourcelink"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version", "theme-version"],
}
html_static_path = ["_static"]
html_css_files = ["substructure.css"]  # code lines wrap instead of running out of the column
html_show_sourcelink = True
html_last_updated_fmt = None
