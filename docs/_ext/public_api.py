"""The public API of `substructure`, found from ``__all__``, and the check of its docstrings.

One place says what is public, for the API reference of the documentation
(``docs/conf.py`` writes a page per public module from it) and for the
docstring check of the test suite (``tests/test_docstrings.py``):

* the top-level package ``substructure`` and its ``__all__``;
* every public subpackage (a workflow: ``identify``, ``diagnose``, ...) that
  defines ``__all__``; a subpackage without ``__all__`` (``io``) stands for
  its public submodules that define one;
* every public module of the core (``datasets``, ``smoothing``, ...) for the
  names of its ``__all__`` that the top-level package does not re-export.

A name is documented once, at the first of these modules that exports it
(``substructure.FRF``, not ``substructure.frf.FRF``).  Names and modules
that start with ``_``, and the command line (``substructure.cli``, documented
by its own page), are not public.  A new subpackage or a new name in an
``__all__`` is picked up without editing this file.

The check runs ``numpydoc.validate`` on every public function, class, method
and property (methods and properties of the project's own classes, inherited
ones included) and keeps the findings of :data:`DOCSTRING_CHECKS`; a public
constant needs a ``#:`` comment or a docstring after its assignment.  Run it
by hand with ``python docs/_ext/public_api.py``.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import sys
from dataclasses import dataclass, field

PACKAGE = "substructure"

#: Modules that are not part of the Python API (documented elsewhere, or entry points).
NOT_API = {"substructure.cli", "substructure.__main__"}

#: The numpydoc findings that fail the check (and the docs build): a public name with no
#: docstring or no summary, a parameter not documented, documented but not in the
#: signature, in another order or without a description, a returned value not documented.
DOCSTRING_CHECKS = {
    "GL08",  # the object has no docstring
    "SS01",  # no summary line
    "PR01",  # parameters of the signature not documented
    "PR02",  # documented parameters that are not in the signature
    "PR03",  # parameters documented in another order than the signature's
    "PR07",  # a parameter with no description
    "RT01",  # a function that returns something has no Returns section
    "RT03",  # a returned value with no description
}


@dataclass
class PublicModule:
    """A module of the API reference and the public names documented on its page."""

    name: str
    module: object
    classes: list[str] = field(default_factory=list)
    functions: list[str] = field(default_factory=list)
    exceptions: list[str] = field(default_factory=list)
    data: list[str] = field(default_factory=list)

    @property
    def names(self) -> list[str]:
        return self.classes + self.functions + self.exceptions + self.data

    @property
    def summary(self) -> str:
        """The first line of the module docstring."""
        doc = inspect.getdoc(self.module) or ""
        return doc.strip().splitlines()[0].strip() if doc.strip() else ""


def _public(name: str) -> bool:
    return not name.split(".")[-1].startswith("_")


def _candidate_modules(package: str = PACKAGE) -> list[str]:
    """The top-level package, its public subpackages (with __all__), then its public modules."""
    pkg = importlib.import_module(package)
    packages, modules = [], []
    for info in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda i: i.name):
        full = f"{package}.{info.name}"
        if not _public(full) or full in NOT_API:
            continue
        mod = importlib.import_module(full)
        if info.ispkg and not hasattr(mod, "__all__"):
            for sub in sorted(pkgutil.iter_modules(mod.__path__), key=lambda i: i.name):
                subname = f"{full}.{sub.name}"
                if _public(subname) and subname not in NOT_API:
                    if hasattr(importlib.import_module(subname), "__all__"):
                        packages.append(subname)
        elif hasattr(mod, "__all__"):
            (packages if info.ispkg else modules).append(full)
            # a package may name submodules that are public API of their own
            for sub in getattr(mod, "__public_submodules__", ()):
                packages.append(f"{full}.{sub}")
    return [package] + packages + modules


def _kind(obj, package: str = PACKAGE) -> str:
    """How a name is documented: 'class', 'exception', 'function' or 'data'."""
    own = str(getattr(obj, "__module__", "") or "").split(".")[0] == package
    if inspect.isclass(obj) and own:
        return "exception" if issubclass(obj, BaseException) else "class"
    if callable(obj) and own and hasattr(obj, "__name__") and not inspect.isclass(obj):
        return "function"
    return "data"  # constants, registries, and objects of other libraries (e.g. a pint registry)


def public_modules(package: str = PACKAGE) -> list[PublicModule]:
    """Every module of the API reference, with the names it documents, in reference order.

    Parameters
    ----------
    package : str
        The top-level package.

    Returns
    -------
    list of PublicModule
        The modules; one without a name of its own (all re-exported by the top-level
        package) is left out.
    """
    seen: set[int] = set()
    result = []
    for modname in _candidate_modules(package):
        module = importlib.import_module(modname)
        entry = PublicModule(modname, module)
        for name in module.__all__:
            if not hasattr(module, name):
                raise AttributeError(f"{modname}.__all__ lists {name!r}, which the module does not define")
            obj = getattr(module, name)
            kind = _kind(obj, package)
            if kind != "data":  # functions and classes: documented once, where first exported
                if id(obj) in seen:
                    continue
                seen.add(id(obj))
            elif modname != package and name in getattr(importlib.import_module(package), "__all__", ()):
                continue
            {"class": entry.classes, "exception": entry.exceptions, "function": entry.functions,
             "data": entry.data}[kind].append(name)
        if entry.names:
            result.append(entry)
    return result


def canonical_names(package: str = PACKAGE) -> dict[int, str]:
    """id(object) -> the name it is documented under, for classes and functions.

    Parameters
    ----------
    package : str
        The top-level package.

    Returns
    -------
    dict
        ``{id(obj): "substructure.identify.closed_form", ...}``.
    """
    names = {}
    for entry in public_modules(package):
        for name in entry.classes + entry.functions + entry.exceptions:
            names[id(getattr(entry.module, name))] = f"{entry.name}.{name}"
    return names


def data_docstring(module, name: str) -> str | None:
    """The documentation of a public constant: a ``#:`` comment above it or a string after it.

    It is looked for in the module that exports the name, then in the modules of
    the same package that assign it (a re-export: ``from .closed_form import PARAMETERS``).

    Parameters
    ----------
    module : module
        The module whose ``__all__`` lists the name.
    name : str
        The name of the constant.

    Returns
    -------
    str or None
        The text, or None when there is none.
    """
    candidates = [module]
    package = module.__name__ if hasattr(module, "__path__") else module.__name__.rpartition(".")[0]
    obj = getattr(module, name)
    for other in list(sys.modules.values()):
        other_name = getattr(other, "__name__", "")
        if (other_name.startswith(package + ".") or other_name == package) and other is not module:
            if getattr(other, name, None) is obj:
                candidates.append(other)
    for mod in candidates:
        text = _attribute_doc(mod, name)
        if text:
            return text
    return None


def _attribute_doc(module, name: str) -> str | None:
    try:
        source = inspect.getsource(module)
    except (OSError, TypeError):
        return None
    lines = source.splitlines()
    tree = ast.parse(source)
    body = tree.body
    for i, node in enumerate(body):
        targets = []
        if isinstance(node, ast.Assign):
            targets = [t.id for t in node.targets if isinstance(t, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            targets = [node.target.id]
        if name not in targets:
            continue
        # a docstring right after the assignment
        if i + 1 < len(body) and isinstance(body[i + 1], ast.Expr) and isinstance(
                getattr(body[i + 1], "value", None), ast.Constant) and isinstance(body[i + 1].value.value, str):
            return inspect.cleandoc(body[i + 1].value.value)
        # '#:' comments on the lines right above it
        comment = []
        j = node.lineno - 2
        while j >= 0 and lines[j].lstrip().startswith("#:"):
            comment.insert(0, lines[j].lstrip()[2:].strip())
            j -= 1
        if comment:
            return "\n".join(comment)
    return None


def members(cls, package: str = PACKAGE) -> list[str]:
    """The public methods and properties of a class that its page documents.

    Members defined by the project's own classes, inherited ones included;
    members of ``object``, of builtin exceptions, of attrs or of other libraries
    are left out.

    Parameters
    ----------
    cls : type
        A class of the project.
    package : str
        The top-level package: members defined in it are documented.

    Returns
    -------
    list of str
        The names of the members, sorted.
    """
    names = []
    for name in dir(cls):
        if name.startswith("_"):
            continue
        for klass in inspect.getmro(cls):
            if name in vars(klass):
                raw = vars(klass)[name]
                break
        else:
            continue
        if str(getattr(klass, "__module__", "")).split(".")[0] != package:
            continue
        if isinstance(raw, (staticmethod, classmethod)):
            raw = raw.__func__
        if isinstance(raw, property) or inspect.isfunction(raw):
            names.append(name)
    return sorted(names)


def documented_objects(package: str = PACKAGE) -> list[tuple[str, object, str]]:
    """(documented name, object, kind) of every public object the docstring check covers.

    Parameters
    ----------
    package : str
        The top-level package.

    Returns
    -------
    list of tuple
        Kinds are 'class', 'exception', 'function', 'method', 'property' and 'data'.
    """
    out = []
    for entry in public_modules(package):
        for name in entry.functions:
            out.append((f"{entry.name}.{name}", getattr(entry.module, name), "function"))
        for name in entry.classes + entry.exceptions:
            cls = getattr(entry.module, name)
            kind = "exception" if name in entry.exceptions else "class"
            out.append((f"{entry.name}.{name}", cls, kind))
            for member in members(cls, package):
                raw = inspect.getattr_static(cls, member)
                out.append((f"{entry.name}.{name}.{member}", getattr(cls, member),
                            "property" if isinstance(raw, property) else "method"))
        for name in entry.data:
            out.append((f"{entry.name}.{name}", entry.module, "data"))
    return out


def check_docstrings(package: str = PACKAGE, checks: set[str] = DOCSTRING_CHECKS) -> list[str]:
    """The docstring problems of the public API, one line each: ``name: CODE message``.

    Parameters
    ----------
    package : str
        The top-level package (a test passes a small package of its own).
    checks : set of str
        The numpydoc codes that count.

    Returns
    -------
    list of str
        Empty when every public name is documented.
    """
    from numpydoc.docscrape import get_doc_object
    from numpydoc.validate import validate

    problems = []
    for name, obj, kind in documented_objects(package):
        if kind == "data":
            if not data_docstring(obj, name.rpartition(".")[2]):
                problems.append(f"{name}: GL08 the constant has no '#:' comment or docstring")
            continue
        if kind == "exception" and "__init__" not in vars(obj):
            # an exception with the builtin's *args: only its docstring is checked
            errors = [e for e in validate(get_doc_object(obj))["errors"]
                      if e[0] in {"GL08", "SS01"}]
        else:
            errors = validate(get_doc_object(obj))["errors"]
        problems += [f"{name}: {code} {message}" for code, message in errors if code in checks]
    return problems


def main() -> int:
    """Print the docstring problems of the public API; exit status 1 if there are any."""
    problems = check_docstrings()
    for line in problems:
        print(line)
    print(f"{len(problems)} docstring problem(s) in the public API of {PACKAGE}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
