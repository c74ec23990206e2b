"""A universal file whose function records are qualified by a type-1858 record saying an exponential window.

Some analysers write, before each type-58 function, a type-1858 record of its qualifiers,
among them the window (type 4: exponential, 6: impact and exponential).  The time constant is
not among its fields, but the window's damping ``1/(tau omega)`` is in every mode of the FRF,
and raises stability limits: read as it is, the file is warned of.  The record here is
written by hand in the layout of the format's description (six 12-wide integers, then twelve
6-wide, then three lines of five numbers, the directions and an unused line).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import hidden_data as hd
from substructure import FRF
from substructure.errors import WindowedFRFWarning
from substructure.io.measurements import load_measurements


def _qualifiers(window_type: int) -> str:
    return ("    -1\n  1858\n" + "%12d" * 6 % (1, 0, 1, 0, 0, 0) + "\n"
            + "%6d" * 12 % (0, window_type, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0) + "\n"
            + "%15.7E" * 5 % (0, 0, 0, 0, 0) + "\n" + "%15.7E" * 5 % (0, 0, 0, 0, 10.0) + "\n"
            + "%15.7E" * 5 % (0, 0, 0, 0, 0) + "\nNONE  NONE\nNONE\n    -1\n")


@pytest.fixture(scope="module")
def function(tmp_path_factory) -> tuple[FRF, str]:
    """The FRF as read from a universal file without qualifiers, and the file's text."""
    (frf,) = hd.measure()
    path = tmp_path_factory.mktemp("uff") / "plain.uff"
    frf.to_uff(path)
    return FRF.from_uff(path), path.read_text()


def _read(path) -> tuple[FRF, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frf = FRF.from_uff(path)
    return frf, [str(w.message) for w in caught if issubclass(w.category, WindowedFRFWarning)]


@pytest.mark.parametrize("window_type, warned", [(4, True), (6, True), (0, False), (1, False), (3, False)])
def test_an_exponential_window_in_the_qualifiers_is_warned_of(tmp_path, function, window_type, warned):
    frf, text = function
    path = tmp_path / "qualified.uff"
    path.write_text(_qualifiers(window_type) + text)
    read, said = _read(path)
    np.testing.assert_array_equal(read.data, frf.data)  # the function itself is read as without the qualifiers
    assert len(said) == int(warned)
    if warned:
        assert "type-58 record(s) 0 measured through an exponential window" in said[0]
        assert "window_tau_s" in said[0] and "--window-tau" in said[0]


def test_qualifiers_after_the_function_or_none_say_nothing(tmp_path, function):
    _, text = function
    path = tmp_path / "after.uff"
    path.write_text(text + _qualifiers(4))
    assert _read(path)[1] == []
    path.write_text(text)
    assert _read(path)[1] == []


def test_a_measurement_set_that_gives_the_window_is_not_warned_of_it(tmp_path, function):
    _, text = function
    (tmp_path / "tip.uff").write_text(_qualifiers(4) + text)
    base = '[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "tip.uff"\n'
    for extra, warned in (("", 1), ("window_tau_s = 0.1\n", 0)):
        (tmp_path / "set.toml").write_text(base + extra, encoding="utf-8")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            (m,) = load_measurements(tmp_path / "set.toml").measurements
        assert sum(issubclass(w.category, WindowedFRFWarning) for w in caught) == warned
        assert m.window_tau == (0.1 if extra else None)
