"""What a command loads, the unit registry's cache, the SI path for building variants (issue 12).

No timings here: speed is measured by `make bench`.  These tests check the
properties the speed rests on (what is imported, what is cached) and that
the fast paths give the same objects and numbers as the general ones.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import substructure
from substructure import Flutes, Insert, InvalidValueError, Segment, UnitError, units

ASSEMBLY = str(Path(__file__).parent.parent / "substructure" / "data" / "default_assembly.toml")


def _modules_after(code: str) -> set[str]:
    """The modules imported by a fresh interpreter after running ``code``."""
    probe = code + "\nimport sys, json\nprint(json.dumps(sorted(sys.modules)))\n"
    env = dict(os.environ, MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, env=env,
                         cwd=Path(__file__).parent)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_the_parser_of_the_command_imports_no_library_module():
    loaded = _modules_after("from substructure.cli import _parser\n_parser()")
    heavy = {"numpy", "pint", "scipy", "matplotlib", "numba", "sklearn", "substructure.units",
             "substructure.assembly", "substructure.stability", "substructure.diagnose"}
    assert not heavy & loaded


def test_a_one_shot_frf_loads_neither_scipy_signal_nor_plotting_nor_numba():
    loaded = _modules_after(
        "import io, contextlib\nfrom substructure.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    assert main(['frf', {ASSEMBLY!r}, '--at', 'tool.tip', '--json']) == 0"
    )
    assert "substructure._ckernels" in loaded
    for name in ("scipy.signal", "matplotlib", "numba", "sklearn", "substructure.sweep", "substructure.diagnose",
                 "substructure.stability", "substructure.surrogate", "concurrent.futures"):
        assert name not in loaded, name


def test_package_names_are_imported_on_first_use():
    loaded = _modules_after("import substructure")
    assert "substructure.assembly" not in loaded and "pint" not in loaded
    # and every public name resolves, to what the submodules define
    for name in substructure.__all__:
        value = getattr(substructure, name)
        assert value is getattr(sys.modules[f"substructure.{substructure._EXPORTS[name]}"], name)
    with pytest.raises(AttributeError):
        substructure.no_such_name  # noqa: B018


def test_importing_the_sweep_module_keeps_the_sweep_function():
    loaded = subprocess.run(
        [sys.executable, "-c", "import substructure.sweep, substructure; print(callable(substructure.sweep), "
         "substructure.sweep.__module__)"],
        capture_output=True, text=True, check=True, cwd=Path(__file__).parent,
    ).stdout.split()
    assert loaded == ["True", "substructure.sweep"]


# -- the unit registry's cache --------------------------------------------------------------------


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    folder = tmp_path / "units"
    monkeypatch.setenv(units.CACHE_VARIABLE, str(folder))
    return folder


def test_registry_cache_is_written_read_and_rebuilt_when_damaged(cache_dir):
    first = units._registry()
    files = list(cache_dir.iterdir())
    assert files, "the registry's cache was not written"
    second = units._registry()  # from the cache
    for text in ("60 mm", "4.1e7 N/m", "3.5e6 N*m/rad", "7850 kg/m^3", "2 g", "210 GPa"):
        assert second.Quantity(text).to_base_units().magnitude == first.Quantity(text).to_base_units().magnitude
    for f in files:  # damage every file: the registry is built again, and the cache with it
        f.write_bytes(b"not a pickle")
    third = units._registry()
    assert third.Quantity("60 mm").m_as("m") == 0.06
    assert any(f.read_bytes() != b"not a pickle" for f in cache_dir.iterdir())


def test_registry_cache_can_be_switched_off(monkeypatch):
    for off in ("off", "", "none"):
        monkeypatch.setenv(units.CACHE_VARIABLE, off)
        assert units.cache_folder() is None
    monkeypatch.delenv(units.CACHE_VARIABLE)
    assert units.cache_folder().endswith(os.path.join("substructure", "pint"))


# -- parsing and conversions, cached ----------------------------------------------------------------


def test_cached_parsing_gives_new_equal_quantities_and_the_same_errors():
    a = units.quantity("52.3 mm", "length", "[length]")
    b = units.quantity("52.3 mm", "length", "[length]")
    assert a == b and a is not b  # never one object shared by two owners
    a.ito("m")  # pint quantities can be changed in place: the other one must not follow
    assert str(b.units) == "millimeter"
    for bad, error in (("52.3", UnitError), ("52.3 furlong/s", UnitError), ("nonsense mm", UnitError),
                       ("inf mm", InvalidValueError)):
        for _ in range(2):  # the second time from the cache
            with pytest.raises(error):
                units.quantity(bad, "length", "[length]")


@pytest.mark.parametrize("value, given, unit", [(60, "mm", "m"), (2.5, "inch", "m"), (4.19e7, "N/m", "N/m"),
                                                (4.19e4, "N/mm", "N/m"), (210, "GPa", "Pa"),
                                                (7.85, "g/cm^3", "kg/m^3"), (3.0, "g", "kg"),
                                                (1.7, "lbf*s/inch", "N*s/m"), (25.0, "degC", "K")])
def test_magnitude_in_is_pint_conversion(value, given, unit):
    q = units.ureg.Quantity(value, given)
    assert units.magnitude_in(q, unit) == float(q.m_as(unit))  # the same bits (offset units included)


# -- Segment.from_si ---------------------------------------------------------------------------------


def test_segment_from_si_equals_segment_from_strings():
    cases = [
        (Segment("46 mm", "12 mm", material="carbide"), Segment.from_si(0.046, 0.012, material="carbide")),
        (Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8)),
         Segment.from_si(0.03, 0.012, material="carbide", flutes=Flutes(0.8))),
        (Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide")),
         Segment.from_si(0.04, 0.04, 0.012, insert=Insert("12 mm", "carbide"))),
        (Segment("150 mm", "90 mm", "40 mm"), Segment.from_si(0.15, np.float64(0.09), 0.04)),
    ]
    for text, si in cases:
        assert text == si
        assert text.length_m == si.length_m and text.section() == si.section()


def test_segment_from_si_checks_what_the_constructor_checks():
    with pytest.raises(InvalidValueError, match="length"):
        Segment.from_si(0.0, 0.012)
    with pytest.raises(InvalidValueError, match="od"):
        Segment.from_si(0.03, -0.012)
    with pytest.raises(InvalidValueError, match="id"):
        Segment.from_si(0.03, 0.012, 0.012)
    with pytest.raises(InvalidValueError, match="finite"):
        Segment.from_si(float("nan"), 0.012)
    for bad in ("30 mm", True, None, [0.03]):
        with pytest.raises(InvalidValueError, match="number of metres"):
            Segment.from_si(bad, 0.012)
