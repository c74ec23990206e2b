"""The docstring check of the public API, and the check itself on a small package made here.

Every public function, class, method and property (found from ``__all__`` by
``docs/_ext/public_api.py``, which also writes the API reference) has a
numpydoc docstring with every parameter and returned value documented; a
public constant has a ``#:`` comment.  The documentation build runs the same
numpydoc checks on what it renders (``numpydoc_validation_checks``).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("numpydoc", reason="the docstring check needs numpydoc (pip install -e '.[test]')")

_PATH = Path(__file__).resolve().parent.parent / "docs" / "_ext" / "public_api.py"
_spec = importlib.util.spec_from_file_location("public_api", _PATH)
public_api = sys.modules.setdefault("public_api", importlib.util.module_from_spec(_spec))
if not hasattr(public_api, "check_docstrings"):
    _spec.loader.exec_module(public_api)

WORKFLOWS = ["substructure.identify", "substructure.diagnose", "substructure.stability", "substructure.surrogate",
             "substructure.study", "substructure.tap"]


def test_every_public_name_is_documented_with_its_parameters():
    problems = public_api.check_docstrings()
    assert not problems, (f"{len(problems)} docstring problem(s) in the public API "
                          "(name: numpydoc code and message):\n" + "\n".join(problems))


@pytest.mark.parametrize("modname", ["substructure"] + WORKFLOWS)
def test_the_reference_covers_every_name_of_all(modname):
    module = importlib.import_module(modname)
    documented = {id(obj) for _, obj, kind in public_api.documented_objects() if kind != "data"}
    data = {name for name, _, kind in public_api.documented_objects() if kind == "data"}
    for name in module.__all__:
        obj = getattr(module, name)
        kind = public_api._kind(obj)
        if kind == "data":
            assert any(d.endswith(f".{name}") for d in data), f"{modname}.{name} is not in the API reference"
        else:
            assert id(obj) in documented, f"{modname}.{name} is not in the API reference"


def test_names_are_documented_once_where_users_import_them():
    entries = {entry.name: entry for entry in public_api.public_modules()}
    assert "FRF" in entries["substructure"].classes
    assert "substructure.frf" not in entries or "FRF" not in entries["substructure.frf"].classes
    assert "closed_form" in entries["substructure.identify"].functions
    assert "substructure.cli" not in entries and not any(name.split(".")[-1].startswith("_") for name in entries)
    for workflow in WORKFLOWS:
        assert workflow in entries


# -- the check on a package written here --------------------------------------------------------------

TINY = {
    "__init__.py": '''
        """A tiny package to try the docstring check on."""

        from .core import Thing, area, no_docstring, perimeter, undocumented_param
        from .core import SIDES

        __all__ = ["Thing", "area", "perimeter", "undocumented_param", "no_docstring", "SIDES"]
    ''',
    "core.py": '''
        """The core of the tiny package."""

        #: Number of sides of a square.
        SIDES = 4


        def area(side):
            """Area of a square.

            Parameters
            ----------
            side : float
                Side, in m.

            Returns
            -------
            float
                Area, in m^2.
            """
            return side * side


        def perimeter(side):
            """Perimeter of a square.

            Parameters
            ----------
            side : float
                Side, in m.
            """
            return 4 * side


        def undocumented_param(side, height):
            """Volume of a box on a square.

            Parameters
            ----------
            side : float
                Side, in m.

            Returns
            -------
            float
                Volume, in m^3.
            """
            return side * side * height


        def no_docstring(side):
            return side


        class Thing:
            """A thing.

            Parameters
            ----------
            mass : float
                Mass, in kg.
            """

            def __init__(self, mass):
                self.mass = mass

            def weight(self, g):
                """Weight of the thing.

                Returns
                -------
                float
                    Weight, in N.
                """
                return self.mass * g
    ''',
    "extra/__init__.py": '''
        """A subpackage with a public name, found without being listed anywhere."""

        LIMIT = 3.0

        def double(x):
            """Twice x.

            Parameters
            ----------
            x : float
                A value.

            Returns
            -------
            float
                2 x.
            """
            return 2 * x

        __all__ = ["double", "LIMIT"]
    ''',
}


@pytest.fixture
def tiny_package(tmp_path, monkeypatch):
    for name, text in TINY.items():
        path = tmp_path / "tinypkg" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text).lstrip())
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "tinypkg"
    for name in [m for m in sys.modules if m == "tinypkg" or m.startswith("tinypkg.")]:
        del sys.modules[name]


def test_the_check_names_module_object_and_parameter(tiny_package):
    problems = public_api.check_docstrings(tiny_package)
    text = "\n".join(problems)
    assert any(p.startswith("tinypkg.undocumented_param: PR01") and "'height'" in p for p in problems), text
    assert any(p.startswith("tinypkg.no_docstring: GL08") for p in problems), text
    assert any(p.startswith("tinypkg.perimeter: RT01") for p in problems), text
    assert any(p.startswith("tinypkg.Thing.weight: PR01") and "'g'" in p for p in problems), text
    assert any(p.startswith("tinypkg.extra.LIMIT: GL08") for p in problems), text  # a constant with no comment
    # what is documented is not flagged
    assert not any(p.startswith(("tinypkg.area:", "tinypkg.Thing:", "tinypkg.SIDES:", "tinypkg.extra.double:"))
                   for p in problems), text
    assert len(problems) == 5, text


def test_a_new_subpackage_is_found_from_its_all(tiny_package):
    entries = {entry.name: entry for entry in public_api.public_modules(tiny_package)}
    assert list(entries) == ["tinypkg", "tinypkg.extra"]
    assert entries["tinypkg.extra"].functions == ["double"] and entries["tinypkg.extra"].data == ["LIMIT"]
    assert entries["tinypkg"].classes == ["Thing"] and entries["tinypkg"].data == ["SIDES"]
