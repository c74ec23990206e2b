"""The examples as Jupyter notebooks, executed, each checked to show its figures inline.

``make notebooks`` runs this: every numbered script of ``examples/`` becomes
the notebook the documentation site offers for download (sphinx-gallery's
converter, with the gallery settings of docs/conf.py), which is executed
with nbclient on a Python kernel (ipykernel) in a directory of its own under
``out/notebooks/``; the executed notebook is saved there, beside the files
the example wrote.  A notebook fails when a cell raises or when it shows no
figure inline (the examples leave their figures open so that Jupyter's
inline backend displays them at the end of a cell; one that closes its
figures after saving them shows none).

Usage: ``python docs/_ext/notebooks.py [--out DIR] [examples/NN_name.py ...]``.
Needs the ``notebooks`` extra (``pip install -e '.[docs,notebooks]'``).
"""

from __future__ import annotations

import argparse
import ast
import copy
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def gallery_conf() -> dict:
    """The ``sphinx_gallery_conf`` of docs/conf.py (a literal there), over sphinx-gallery's defaults."""
    from sphinx_gallery import gen_gallery

    tree = ast.parse((ROOT / "docs" / "conf.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "sphinx_gallery_conf" for t in node.targets):
            conf = copy.deepcopy(gen_gallery.DEFAULT_GALLERY_CONF)
            conf.update(ast.literal_eval(node.value))
            return conf
    raise RuntimeError("docs/conf.py defines no sphinx_gallery_conf")


def write_notebook(script: Path, target: Path) -> Path:
    """Convert one example to the notebook the site offers; return its path."""
    from sphinx_gallery.notebook import jupyter_notebook, save_notebook
    from sphinx_gallery.py_source_parser import split_code_and_text_blocks

    _, blocks = split_code_and_text_blocks(str(script))
    notebook = jupyter_notebook(blocks, gallery_conf(), target)
    path = target / (script.stem + ".ipynb")
    save_notebook(notebook, path)
    return path


def inline_images(notebook) -> int:
    """The number of images a notebook shows in its outputs."""
    return sum(1 for cell in notebook.cells if cell.cell_type == "code"
               for output in cell.get("outputs", []) if "image/png" in output.get("data", {}))


def run(script: Path, out: Path, timeout: int = 1200) -> str:
    """Write, execute and check one example's notebook; return a line saying how it went.

    Raises
    ------
    RuntimeError
        When a cell fails or the notebook shows no figure.
    """
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    target = out / script.stem
    target.mkdir(parents=True, exist_ok=True)
    path = write_notebook(script, target)
    notebook = nbformat.read(path, as_version=4)
    os.environ["SUBSTRUCTURE_EXAMPLES_OUT"] = str(target / "figures")  # the kernel inherits it
    client = NotebookClient(notebook, timeout=timeout, kernel_name="python3",
                            resources={"metadata": {"path": str(target)}})
    try:
        client.execute()
    except CellExecutionError as exc:
        nbformat.write(notebook, path)
        raise RuntimeError(f"{script.name}: a cell failed (executed notebook: {path}):\n{exc}") from None
    nbformat.write(notebook, path)
    shown = inline_images(notebook)
    written = len(list((target / "figures").rglob("*.png")))
    if shown == 0:
        raise RuntimeError(f"{script.name}: the notebook shows no figure inline ({written} PNG files written; "
                           f"does the example close its figures after saving them?); see {path}")
    return f"{script.name}: {shown} figure(s) inline, {written} PNG file(s) written -> {path}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scripts", nargs="*", type=Path, help="examples to run (default: every numbered one)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "notebooks", help="where the notebooks go")
    args = parser.parse_args(argv)
    scripts = args.scripts or sorted((ROOT / "examples").glob("[0-9]*.py"))
    failed = []
    for script in scripts:
        try:
            print(run(script.resolve(), args.out.resolve()), flush=True)
        except RuntimeError as exc:
            print(f"FAILED {exc}", flush=True)
            failed.append(script.name)
    print(f"notebooks: {len(scripts) - len(failed)} of {len(scripts)} ran and show their figures inline"
          + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
