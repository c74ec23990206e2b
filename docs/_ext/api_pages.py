"""Sphinx extension: the API reference pages, written from the package's ``__all__``.

At the start of every build, ``docs/api/`` is written anew from
:func:`public_api.public_modules`: ``api/index.rst`` (the list of public
modules) and one page per public module with the module docstring and
autosummary tables of its names, grouped by the module that defines them;
autosummary then writes a page per class and function from its docstring
(``api/generated/``).  Constants are documented from their ``#:`` comment.
Nothing under ``docs/api/`` is edited by hand or committed.

References to an object by the path of the module that defines it
(``substructure.frf.FRF``, as type hints and some docstrings write them) are
resolved to the page where it is documented (``substructure.FRF``).
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

from sphinx.util import logging

import public_api

logger = logging.getLogger(__name__)

HEADINGS = {"class": "Classes", "function": "Functions", "exception": "Exceptions and warnings",
            "data": "Constants"}


def _title(text: str, char: str) -> str:
    return f"{text}\n{char * len(text)}\n"


def _defining_module(entry: public_api.PublicModule, name: str) -> str:
    obj = getattr(entry.module, name)
    if name not in entry.data:
        return obj.__module__
    mod = entry.module
    package = mod.__name__ if hasattr(mod, "__path__") else mod.__name__.rpartition(".")[0]
    for modname in sorted(m for m in list(importlib.sys.modules) if m == package or m.startswith(package + ".")):
        other = importlib.sys.modules[modname]
        if getattr(other, name, None) is obj and public_api._attribute_doc(other, name):
            return modname
    return mod.__name__


def _summary(modname: str) -> str:
    doc = inspect.getdoc(importlib.import_module(modname)) or modname
    return doc.strip().splitlines()[0].rstrip(".")


def _value(obj) -> str | None:
    text = repr(obj)
    return text if len(text) <= 70 and "\n" not in text and not text.startswith("<") else None


def module_page(entry: public_api.PublicModule) -> str:
    """The reStructuredText of the API page of one public module."""
    lines = [_title(f"``{entry.name}``", "="), f".. automodule:: {entry.name}", "   :no-members:", "",
             f".. currentmodule:: {entry.name}", ""]
    groups: dict[str, list[str]] = {}
    for name in entry.names:
        groups.setdefault(_defining_module(entry, name), []).append(name)
    several = len(groups) > 1
    for defining, names in groups.items():
        if several:
            lines += [_title(_summary(defining), "-")]
            if defining != entry.name:
                lines += [f"Defined in ``{defining}``.", ""]
        for kind in ("class", "function", "exception", "data"):
            of_kind = [n for n in names if n in getattr(entry, {"class": "classes", "function": "functions",
                                                                 "exception": "exceptions", "data": "data"}[kind])]
            if not of_kind:
                continue
            if not several or len({k for k in ("class", "function", "exception", "data")
                                   if set(names) & set(getattr(entry, {"class": "classes", "function": "functions",
                                                                        "exception": "exceptions",
                                                                        "data": "data"}[k]))}) > 1:
                lines += [f".. rubric:: {HEADINGS[kind]}", ""]
            if kind == "data":
                for name in of_kind:
                    obj = getattr(entry.module, name)
                    doc = public_api.data_docstring(entry.module, name) or ""
                    lines += [f".. data:: {name}"]
                    value = _value(obj)
                    if value is not None:
                        lines += [f"   :value: {value}"]
                    lines += [""] + [f"   {line}" if line else "" for line in doc.splitlines()] + [""]
            else:
                lines += [".. autosummary::", "   :toctree: generated", "   :nosignatures:", ""]
                lines += [f"   {name}" for name in of_kind] + [""]
    return "\n".join(lines)


def index_page(entries: list[public_api.PublicModule]) -> str:
    """The reStructuredText of the API reference's index."""
    lines = [_title("API reference", "="),
             "Every public name of the package, generated from the docstrings.  The names",
             "most users need are importable from ``substructure``; the workflows are",
             "subpackages.  Units: every dimensional input accepts a string that pint reads",
             "(``\"12 mm\"``) or a pint quantity; ``*_m``, ``*_hz`` and similar attributes are",
             "SI floats (see :doc:`../conventions`).", "",
             ".. list-table::", "   :widths: 30 70", ""]
    for entry in entries:
        lines += [f"   * - :mod:`{entry.name}`", f"     - {entry.summary or ''}"]
    lines += ["", ".. toctree::", "   :hidden:", ""] + [f"   {entry.name}" for entry in entries] + [""]
    return "\n".join(lines)


def _write(path: Path, text: str) -> None:
    if not path.exists() or path.read_text(encoding="utf-8") != text:  # keep unchanged pages for incremental builds
        path.write_text(text, encoding="utf-8")


def write_pages(app, config=None) -> None:
    """Write ``api/index.rst`` and a page per public module (``config-inited``: before Sphinx
    looks for the source files)."""
    api = Path(app.srcdir) / "api"
    api.mkdir(exist_ok=True)
    entries = public_api.public_modules()
    # autosummary writes the stubs of exactly these pages (not of the files Sphinx knew at the
    # last build, which would miss a module page written for the first time now)
    (config or app.config).autosummary_generate = ["api/index.rst"] + [f"api/{e.name}.rst" for e in entries]
    wanted = {"index.rst"} | {f"{entry.name}.rst" for entry in entries}
    for stale in api.glob("*.rst"):
        if stale.name not in wanted:
            stale.unlink()
    _write(api / "index.rst", index_page(entries))
    for entry in entries:
        _write(api / f"{entry.name}.rst", module_page(entry))


def _import(target: str):
    """The object named by a dotted path, or None."""
    parts = target.split(".")
    for split in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:split]))
        except ImportError:
            continue
        try:
            for part in parts[split:]:
                obj = getattr(obj, part)
        except AttributeError:
            return None
        return obj
    return None


def _canonical(target: str) -> str | None:
    """The documented name of ``target`` (a path through a defining module), or None."""
    if not target.startswith(public_api.PACKAGE + "."):
        return None
    obj = _import(target)
    if obj is None:
        return None
    if inspect.ismodule(obj):  # a submodule: the page of the documented module that holds it
        documented = {entry.name for entry in public_api.public_modules()}
        name = obj.__name__
        while name and name not in documented:
            name = name.rpartition(".")[0]
        return name or None
    canonical = _CANONICAL.get(id(obj))
    if canonical is None and target.count(".") > 1:  # a method or property: the class's documented name
        owner, _, member = target.rpartition(".")
        owner = _canonical(owner)
        return f"{owner}.{member}" if owner else None
    return canonical


_CANONICAL: dict[int, str] = {}
_SHORT: dict[str, str] = {}  # short name of a public class or function -> its documented name


def _candidates(node) -> list[str]:
    """Full names a reference may mean: as written, in the current module and class, by short name."""
    target = node["reftarget"].lstrip("~.")
    names = [target]
    for prefix in (node.get("py:class"), node.get("py:module")):
        if prefix:
            module = node.get("py:module")
            names.append(f"{module}.{prefix}.{target}" if prefix != module and module else f"{prefix}.{target}")
    head, _, rest = target.partition(".")
    if head in _SHORT:
        names.append(_SHORT[head] + (f".{rest}" if rest else ""))
    return names


def resolve_alias(app, env, node, contnode):
    """``missing-reference``: a reference to a project object by another path, to where it is documented."""
    if node.get("refdomain") != "py":
        return None
    domain = env.get_domain("py")
    for candidate in _candidates(node):
        canonical = _canonical(candidate)
        if canonical is None:
            continue
        for role in (node["reftype"], "obj", "mod"):
            found = domain.resolve_xref(env, node["refdoc"], app.builder, role, canonical, node, contnode)
            if found is not None:
                return found
    return None


def skip_foreign_member(app, what, name, obj, skip, options):
    """``autodoc-skip-member``: a class page shows the members the project defines, inherited
    ones included, not those of ``object``, builtin exceptions or other libraries' base classes."""
    if what not in ("class", "exception"):
        return None
    target = obj
    if isinstance(target, (staticmethod, classmethod)):
        target = target.__func__
    if isinstance(target, property):
        target = target.fget
    module = getattr(target, "__module__", None)
    if module is None or not str(module).split(".")[0] == public_api.PACKAGE:
        return True
    return None


def setup(app):
    _CANONICAL.update(public_api.canonical_names())
    for name in _CANONICAL.values():
        _SHORT.setdefault(name.rpartition(".")[2], name)
    app.connect("config-inited", write_pages)
    app.connect("autodoc-skip-member", skip_foreign_member)
    app.connect("missing-reference", resolve_alias)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
