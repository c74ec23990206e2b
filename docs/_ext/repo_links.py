"""Sphinx extension: links from the Markdown pages to files of the repository, mapped to the site.

The pages in ``docs/`` and the README are read on the repository's web view
too, so they link to files by their path in the repository:
``../examples/01_forward_coupling.py``, ``../README.md``,
``../substructure/data/default_assembly.toml``.  In the built site:

* a numbered example script links to its gallery page (with its output and
  figures, and the script and notebook to download);
* the README links to :doc:`getting-started`, the page that includes it;
* a link in the README to a page in ``docs/`` links to that page;
* any other file of the repository (a data file, the licence) becomes a
  download of that file (MyST does this for a path to an existing file).

The pages keep their repository paths; only the text Sphinx reads is
changed.  A link to a file that does not exist is left alone, and MyST's
warning about it fails the build.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

# [text](target) or [text](target#anchor); targets without spaces or a scheme
LINK = re.compile(r"(\]\()([^)\s#]+)(#[^)\s]*)?(\))")
GALLERY = "auto_examples"
README_PAGE = "getting-started"


def _map(target: str, written_in: Path, resolved_from: Path, docs_dir: Path) -> str | None:
    """The new target of a link written in a file of ``written_in`` and read on a page of
    ``resolved_from``, or None to keep it."""
    if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("/"):
        return None  # a URL, or a MyST scheme (project:, inv:, path:)
    root = docs_dir.parent
    path = (written_in / target).resolve()
    try:
        repo_path = path.relative_to(root)
    except ValueError:
        return None
    if not path.exists():
        return None
    parts = repo_path.parts
    if len(parts) == 2 and parts[0] == "examples" and re.match(r"\d", parts[1]) and path.suffix == ".py":
        new = docs_dir / GALLERY / (path.stem + ".rst")
    elif repo_path.as_posix() == "README.md":
        new = docs_dir / f"{README_PAGE}.md"
    elif written_in != resolved_from:
        new = path  # a page of docs/ or any other file (a download), from the including page
    else:
        return None
    return os.path.relpath(new, resolved_from).replace(os.sep, "/")


def rewrite(text: str, written_in: Path, resolved_from: Path, docs_dir: Path) -> str:
    """``text`` with the links that point into the repository mapped to the site."""
    def repl(match: re.Match) -> str:
        new = _map(match.group(2), written_in, resolved_from, docs_dir)
        if new is None:
            return match.group(0)
        return f"{match.group(1)}{new}{match.group(3) or ''}{match.group(4)}"

    return LINK.sub(repl, text)


def _on_source_read(app, docname, source):
    if not app.env.doc2path(docname).suffix == ".md":
        return
    page_dir = Path(app.env.doc2path(docname)).parent
    source[0] = rewrite(source[0], page_dir, page_dir, Path(app.srcdir))


def _on_include_read(app, relative_path, parent_docname, content):
    docs_dir = Path(app.srcdir)
    included = (docs_dir / relative_path).resolve()
    if included.suffix != ".md":
        return
    # links in the included file are written relative to the file; the page that
    # includes it resolves them relative to itself (docs/)
    including = Path(app.env.doc2path(app.env.docname)).parent if app.env.docname else docs_dir
    content[0] = rewrite(content[0], included.parent, including, docs_dir)


def setup(app):
    app.connect("source-read", _on_source_read)
    app.connect("include-read", _on_include_read)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
