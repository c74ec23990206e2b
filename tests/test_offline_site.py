"""The check that the built documentation loads nothing from the network (docs/_ext/offline_site.py).

``make docs`` runs it on the whole site at the end of the build; here it is
tried on small sites whose answer is known.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "docs" / "_ext"))
import offline_site  # noqa: E402

OFFLINE_PAGE = """<!DOCTYPE html><html><head>
<script src="_static/mathjax/tex-svg.js" defer></script>
<link rel="stylesheet" href="_static/substructure.css">
<link rel="canonical" href="https://example.org/page.html">
<style>h1 { background: url(_static/local.png); }</style>
</head><body>
<a href="https://numpy.org/doc/stable/">numpy</a>
<img src="images/figure.png" srcset="images/figure@2x.png 2x">
</body></html>
"""


def site(tmp_path, pages):
    for name, text in pages.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text, encoding="utf-8")
    return tmp_path


def test_links_and_local_files_are_offline(tmp_path):
    assert offline_site.remote_loads(site(tmp_path, {"index.html": OFFLINE_PAGE,
                                                     "_static/a.css": "p { color: red }"})) == []


def test_every_kind_of_load_from_the_network_is_found_with_its_page_and_line(tmp_path):
    page = OFFLINE_PAGE.replace("</head>", """<script defer src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js"></script>
<link href="//fonts.example.com/css?family=Lato" rel="stylesheet">
<link rel="preload" as="font" href="HTTP://cdn.example.com/f.woff2">
<style>@import url("https://example.com/x.css");</style>
</head>""").replace("</body>", '<img src="images/a.png" srcset="a.png 1x, https://example.com/b.png 2x"></body>')
    found = offline_site.remote_loads(site(tmp_path, {
        "sub/page.html": page,
        "_static/theme.css": "p {}\n@font-face { src: url(https://fonts.example.com/a.woff2) }\n"}))
    assert found == [
        "sub/page.html:6: <script src> https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js",
        "sub/page.html:7: <link href> //fonts.example.com/css?family=Lato",
        "sub/page.html:8: <link href> HTTP://cdn.example.com/f.woff2",
        "sub/page.html:9: style https://example.com/x.css",
        "sub/page.html:13: <img srcset> https://example.com/b.png",
        "_static/theme.css:2: style https://fonts.example.com/a.woff2",
    ]


def test_mathjax_for_the_site_is_a_local_copy():
    pytest.importorskip("mathjax", reason="the docs extra (django-static-mathjax) is not installed")
    source = offline_site.mathjax_source()
    script = source / "tex-svg.js"
    assert offline_site.MATHJAX_PATH == "mathjax/tex-svg.js" and script.is_file()
    assert script.stat().st_size > 1_000_000      # the whole combined component, not a loader stub
    assert '.VERSION="3.' in script.read_text(encoding="utf-8", errors="replace")  # MathJax 3
