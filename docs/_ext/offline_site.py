"""The built site loads nothing from the network: MathJax from _static, and a check of every page.

Sphinx's math extension loads MathJax from a CDN by default; offline (a
classroom, a train, a machine shop) the equations then show as raw LaTeX.
This extension

* points ``mathjax_path`` at a copy of MathJax 3 in the site's ``_static``
  (``_static/mathjax/tex-svg.js``), copied at the end of the build from the
  Python package ``django-static-mathjax`` (of the docs extra; it holds
  MathJax's own distribution and needs no Django).  The SVG output draws
  the glyphs as paths: no web fonts to fetch;
* checks, at the end of every HTML build, that no page and no style sheet
  loads a script, a style sheet, a font, an image or a frame from an
  ``http(s)://`` or ``//`` address (links to other sites are fine: they are
  followed only when a reader clicks them).  A load from the network fails
  the build with the page and the address.

``python docs/_ext/offline_site.py docs/_build/html`` runs the check alone.
"""

from __future__ import annotations

import importlib.util
import re
import shutil
import sys
from html.parser import HTMLParser
from pathlib import Path

#: Where the pages load MathJax from, relative to the site's ``_static``.
MATHJAX_PATH = "mathjax/tex-svg.js"
# What of MathJax's es5 distribution the SVG component may load on demand (extensions, menu, speech).
_MATHJAX_PARTS = ("tex-svg.js", "a11y", "adaptors", "input", "output", "sre", "ui")
_REMOTE = re.compile(r"^\s*(https?:)?//", re.I)
# Attributes through which a page makes the browser fetch something as it is displayed.
_LOADS = {
    "script": ("src",), "img": ("src", "srcset"), "source": ("src", "srcset"), "iframe": ("src",),
    "embed": ("src",), "object": ("data",), "video": ("src", "poster"), "audio": ("src",),
    "track": ("src",), "input": ("src",),
}
_LINK_LOADS = {"stylesheet", "preload", "modulepreload", "icon", "shortcut", "apple-touch-icon",
               "manifest", "prefetch", "preconnect", "dns-prefetch"}
_CSS_URL = re.compile(r"""(?:@import\s+(?:url\()?|url\()\s*['"]?([^'")\s;]+)""", re.I)


def mathjax_source() -> Path:
    """MathJax's es5 distribution as installed with the ``django-static-mathjax`` package.

    Returns
    -------
    pathlib.Path
        The ``es5`` directory.

    Raises
    ------
    RuntimeError
        When the package is not installed (the docs extra installs it).
    """
    spec = importlib.util.find_spec("mathjax")
    root = Path(next(iter(spec.submodule_search_locations))) if spec and spec.submodule_search_locations else None
    es5 = root / "static" / "mathjax" / "es5" if root else None
    if es5 is None or not (es5 / MATHJAX_PATH.split("/", 1)[1]).is_file():
        raise RuntimeError(
            "MathJax for the offline site is not installed: pip install django-static-mathjax "
            "(part of the docs extra: pip install -e '.[docs]', as make docs does)"
        )
    return es5


class _Loads(HTMLParser):
    """Collects the addresses a page fetches as it is displayed, with their line."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.found: list[tuple[int, str, str]] = []
        self._in_style = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        names = _LOADS.get(tag, ())
        if tag == "link":
            rel = set((attrs.get("rel") or "").lower().split())
            names = ("href",) if rel & _LINK_LOADS else ()
        for name in names:
            for value in (attrs.get(name) or "").split(","):
                address = value.strip().split(" ")[0]
                if _REMOTE.match(address):
                    self.found.append((self.getpos()[0], f"<{tag} {name}>", address))
        if "style" in attrs:
            self._css(attrs["style"] or "")
        self._in_style = tag == "style"

    def handle_endtag(self, tag):
        if tag == "style":
            self._in_style = False

    def handle_data(self, data):
        if self._in_style:
            self._css(data)

    def _css(self, text):
        for address in _CSS_URL.findall(text):
            if _REMOTE.match(address):
                self.found.append((self.getpos()[0], "style", address))


def remote_loads(site: Path) -> list[str]:
    """Every load from the network in the HTML pages and CSS files of a built site.

    Parameters
    ----------
    site : pathlib.Path
        The HTML output directory (``docs/_build/html``).

    Returns
    -------
    list of str
        ``"page:line: <script src> https://..."`` for each, empty for an offline site.
    """
    problems = []
    for page in sorted(site.rglob("*.html")):
        parser = _Loads()
        parser.feed(page.read_text(encoding="utf-8", errors="replace"))
        problems += [f"{page.relative_to(site)}:{line}: {what} {address}" for line, what, address in parser.found]
    for sheet in sorted(site.rglob("*.css")):
        for number, line in enumerate(sheet.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            problems += [f"{sheet.relative_to(site)}:{number}: style {address}"
                         for address in _CSS_URL.findall(line) if _REMOTE.match(address)]
    return problems


def _use_local_mathjax(app, config):
    mathjax_source()  # fails early, before the examples run, when MathJax is missing
    config.mathjax_path = MATHJAX_PATH


def _finish(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    from sphinx.errors import ExtensionError

    source, target = mathjax_source(), Path(app.outdir, "_static", "mathjax")
    for part in _MATHJAX_PARTS:
        src, dst = source / part, target / part
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            target.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dst)
    shutil.copyfile(source.parent / "LICENSE", target / "LICENSE")
    problems = remote_loads(Path(app.outdir))
    if problems:
        raise ExtensionError("the site loads from the network (it must work offline):\n  " + "\n  ".join(problems))


def setup(app):
    app.connect("config-inited", _use_local_mathjax)
    app.connect("build-finished", _finish)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":
    found = remote_loads(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/_build/html"))
    print("\n".join(found) or "no load from the network")
    sys.exit(1 if found else 0)
