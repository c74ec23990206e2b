"""sphinx-gallery support: the examples' own PNG figures in the gallery, and the smoke-test checks.

The teaching scripts in ``examples/`` save every figure they show as a PNG
file in ``$SUBSTRUCTURE_EXAMPLES_OUT`` (that is what ``make examples`` leaves
for the reader).  In the documentation build:

* :func:`prepare_example` (a sphinx-gallery ``reset_modules`` hook) gives each
  example a directory of its own under ``docs/_build/examples-out/`` through
  that variable, and runs it with Python warnings turned into errors, as the
  test run does; a warning that an example does not handle itself fails it;
  every figure the example saves is checked for empty panels as it is saved
  (docs/_ext/figure_checks.py: a panel whose data all lie outside its limits,
  or show only as a sliver, fails the example);
* :func:`png_scraper` (a sphinx-gallery image scraper) puts the PNG files that
  a code block wrote, in the order they were written, under that block on
  the example's page, then closes the block's matplotlib figures (scripts
  leave them open so that a notebook shows them inline);
* :func:`check_gallery` fails the build when an example page shows no output
  or no figure: an example must print what it does and draw something.

An example that raises an exception fails the build (sphinx-gallery's own
check).  These are the checks that ``tests/test_examples.py`` makes when it
runs the scripts itself (``SUBSTRUCTURE_RUN_EXAMPLES=1``).
"""

from __future__ import annotations

import os
import re
import shutil
import warnings
from pathlib import Path

from sphinx.errors import ExtensionError

import figure_checks

OUT_ROOT = Path(__file__).resolve().parent.parent / "_build" / "examples-out"
_state: dict = {"written": set(), "warnings": None}


def _out_dir() -> Path:
    return Path(os.environ["SUBSTRUCTURE_EXAMPLES_OUT"])


def prepare_example(gallery_conf, fname, when):
    """Before an example: its own empty output directory and warnings as errors; after: restore.

    Parameters
    ----------
    gallery_conf : dict
        sphinx-gallery's configuration.
    fname : str or None
        The example's file name (None when sphinx-gallery enters a directory).
    when : str
        ``"before"`` or ``"after"`` the example runs.
    """
    if fname is None:
        return
    if when == "before":
        out = OUT_ROOT / Path(fname).stem
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir(parents=True)
        os.environ["SUBSTRUCTURE_EXAMPLES_OUT"] = str(out)
        _state["written"] = set()
        _state["warnings"] = warnings.catch_warnings()
        _state["warnings"].__enter__()
        warnings.simplefilter("error")
        figure_checks.install()
    elif _state["warnings"] is not None:
        figure_checks.uninstall()
        _state["warnings"].__exit__(None, None, None)
        _state["warnings"] = None
        import matplotlib.pyplot as plt

        plt.close("all")


def png_scraper(block, block_vars, gallery_conf, **kwargs):
    """The PNG files a code block wrote to ``$SUBSTRUCTURE_EXAMPLES_OUT``, as reST images.

    Parameters
    ----------
    block : tuple
        The code block (sphinx-gallery's ``Block``).
    block_vars : dict
        sphinx-gallery's state of the example; gives the image paths to fill.
    gallery_conf : dict
        sphinx-gallery's configuration.
    **kwargs
        Further arguments of newer sphinx-gallery versions (unused).

    Returns
    -------
    str
        The reST of the images, empty when the block wrote none.
    """
    from sphinx_gallery.scrapers import figure_rst

    import matplotlib.pyplot as plt

    plt.close("all")  # the scripts leave figures open for notebooks; the saved PNG is the figure
    out = _out_dir()
    new = [p for p in out.rglob("*.png") if p not in _state["written"]]
    new.sort(key=lambda p: (p.stat().st_mtime_ns, str(p)))
    _state["written"].update(new)
    image_paths = []
    for png, target in zip(new, block_vars["image_path_iterator"]):
        shutil.copyfile(png, target)
        image_paths.append(target)
    return figure_rst(image_paths, gallery_conf["src_dir"])


def check_gallery(app):
    """After sphinx-gallery wrote the example pages: each shows printed output and a figure.

    Parameters
    ----------
    app : sphinx.application.Sphinx
        The application.
    """
    conf = app.config.sphinx_gallery_conf
    if not app.config.sphinx_gallery_conf.get("plot_gallery", True) or str(conf.get("plot_gallery")) == "False":
        return
    problems = []
    for examples_dir, gallery_dir in zip(conf["examples_dirs"], conf["gallery_dirs"]):
        src = Path(app.confdir, examples_dir)
        for script in sorted(src.glob("[0-9]*.py")):
            page = Path(app.srcdir, gallery_dir, script.stem + ".rst")
            if not page.exists():
                problems.append(f"{script.name}: no gallery page was written")
                continue
            text = page.read_text(encoding="utf-8")
            if "sphx-glr-script-out" not in text:
                problems.append(f"{script.name}: the example printed nothing")
            if not re.search(r"image(-sg)?:: /" + re.escape(gallery_dir) + r"/images/", text):
                problems.append(f"{script.name}: the example wrote no PNG figure to $SUBSTRUCTURE_EXAMPLES_OUT")
    if problems:
        raise ExtensionError("gallery checks failed:\n  " + "\n  ".join(problems))


def setup(app):
    app.connect("builder-inited", check_gallery, priority=900)  # after sphinx-gallery (500)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
