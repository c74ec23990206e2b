"""Hostile inputs to the Python API of components, joints, points and sweeps.

Each case gave a silently wrong value, a raw Python error from deep inside, or
gigabytes of memory before it was checked where it enters.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

from substructure import (Assembly, Flutes, Joint, Material, MeasuredComponent, Segment, Tool, UnitError,
                          default_assembly)
from substructure.errors import InvalidValueError, UnknownPointError
from substructure.frf import FRF
from substructure.materials import get_material
from substructure.points import parse_point
from substructure.sweep import sweep

GRID = [500.0, 1000.0]


@pytest.mark.parametrize("text", ["1,5 mm", "1, 5 mm", "1,000 mm"])
def test_a_comma_in_a_value_is_refused_not_dropped(text):
    """pint drops the comma: '1,5 mm' was a segment of 15 mm and '1, 5 mm' one of 5 mm."""
    with pytest.raises(UnitError, match=r"length: cannot read '1, ?[05]+ mm': a comma is neither a decimal point"):
        Segment(text, "12 mm")


def test_a_comma_in_a_plain_number_is_refused_too():
    with pytest.raises(InvalidValueError, match=r"loss_factor: cannot read '0,002': a comma"):
        Material("x", "210 GPa", 0.3, "7850 kg/m^3", loss_factor="0,002")
    with pytest.raises(InvalidValueError, match=r"flutes.diameter_ratio: cannot read '0,8': a comma"):
        Flutes("0,8")
