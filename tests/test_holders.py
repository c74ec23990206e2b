"""The holder catalogue: every entry builds, couples finitely and reciprocally, says it is
approximate; its geometry follows the data (masses by hand); overrides and errors."""

import math

import numpy as np
import pytest

from substructure import Assembly, Frequency, Holder, Joint, Segment, Spindle, Tool
from substructure.errors import FileFormatError, InvalidValueError, SubstructureError
from substructure.holders import catalog_names, catalog_parameters, design
from substructure.io.assembly_toml import dumps_assembly, loads_assembly

GRID = Frequency.from_range("50 Hz", "6000 Hz", "25 Hz")
RHO_STEEL, RHO_CARBIDE = 7850.0, 14500.0


def largest_bore(name):
    if " ER" in name:
        return {"ER16": "10 mm", "ER20": "13 mm", "ER25": "16 mm", "ER32": "20 mm", "ER40": "26 mm"}[name.split()[1]]
    return "32 mm"


def machine(holder, tool_diameter, gauge_line):
    """Spindle, holder, tool; the spindle face meets the holder at its gauge line."""
    spindle = Spindle("spindle", [Segment("150 mm", "70 mm", "35 mm"), Segment("150 mm", "90 mm", "35 mm")])
    tool = Tool.end_mill(tool_diameter, "60 mm", "25 mm")
    at = "holder.base" if gauge_line.magnitude == 0 else f"holder@{gauge_line.m_as('mm')} mm"
    return Assembly("m", [spindle, holder, tool], [
        Joint("sh", ["spindle.tip", at], k={"yf": "5e7 N/m", "tm": "4e6 N*m/rad"},
              c={"yf": "400 N*s/m", "tm": "7 N*m*s/rad"}),
        Joint("ht", ["holder.tip", "tool.base"], k={"yf": "2e7 N/m", "tm": "1e5 N*m/rad"},
              c={"yf": "20 N*s/m", "tm": "3 N*m*s/rad"}),
    ])


@pytest.mark.parametrize("name", catalog_names())
def test_every_entry_builds_and_its_frf_is_finite_and_reciprocal(name):
    for bore, taper in (("10 mm", False), (largest_bore(name), True)):
        d = design(name, bore=bore, shank_taper=taper)
        holder = d.holder()
        assert "APPROXIMATE" in holder.description and "Sources:" in holder.description
        expected = d.parameters["gauge_length"] + (d.parameters["taper_length"] if taper else 0 * d.gauge_line)
        assert holder.length_m == pytest.approx(expected.m_as("m"), rel=1e-12)
        assert 0.3 < holder.mass() < 6.0
        frf = machine(holder, bore, d.gauge_line).frf(["tool.tip", "holder.tip"], frequency=GRID)
        assert np.all(np.isfinite(frf.data))
        assert frf.reciprocity_error() < 1e-9
        h = np.abs(frf.entry("tool.tip:y", "tool.tip:y"))
        assert 1e-9 < h.max() < 1e-4   # a tool point compliance, m/N


def ring_mass(length, od, idd=0.0, rho=RHO_STEEL):
    return rho * math.pi / 4 * (od**2 - idd**2) * length


def frustum_mass(length, d0, d1, idd=0.0, rho=RHO_STEEL):
    return rho * (math.pi * length / 12 * (d0 * d0 + d0 * d1 + d1 * d1) - math.pi / 4 * idd**2 * length)


def test_geometry_follows_the_data_er_chuck():
    """BT40 ER32, 12 mm carbide shank, gauge length 70 mm, by hand from the data file's numbers:
    2 mm gap at 44.45 mm, 25 mm flange at 63 mm, body 50 mm, nut 50 mm over 22.5 mm, shank 40 mm deep."""
    holder = Holder.from_catalog("BT40 ER32", bore="12 mm", gauge_length="70 mm")
    expected = (ring_mass(0.002, 0.04445) + ring_mass(0.025, 0.063) + ring_mass(0.043, 0.05)
                - ring_mass(0.040, 0.012) + ring_mass(0.040, 0.012, rho=RHO_CARBIDE))
    assert holder.mass() == pytest.approx(expected, rel=1e-12)
    assert holder.segments[-1].od.m_as("mm") == 50 and holder.segments[-1].insert.od.m_as("mm") == 12


def test_geometry_follows_the_data_shrink_fit_with_taper():
    """HSK-A63 shrink-fit, 16 mm: a 1:10 hollow taper 32 mm long from 48 mm, a 26 mm flange
    at 63 mm, then a 4.5 degree cone ending at 27 mm at the nose, the shank 48 mm deep."""
    holder = Holder.from_catalog("HSK-A63 shrink-fit", bore="16 mm", gauge_length="80 mm", shank_taper=True)
    slope = 2 * math.tan(math.radians(4.5))
    cone = 0.054
    d_back = 0.027 + slope * cone
    expected = (frustum_mass(0.032, 0.048 - 0.0032, 0.048, 0.036) + ring_mass(0.026, 0.063)
                + frustum_mass(cone, d_back, 0.027) - ring_mass(0.048, 0.016)
                + ring_mass(0.048, 0.016, rho=RHO_CARBIDE))
    assert holder.mass() == pytest.approx(expected, rel=1e-5)   # diameters rounded to 0.1 um in the model
    assert holder.segments[0].is_tapered and holder.segments[-1].is_tapered
    assert holder.segments[-1].od_tip.m_as("mm") == pytest.approx(27.0)
    assert "holder@32 mm" in holder.description


def test_overrides_and_names():
    base = Holder.from_catalog("hsk-a63  SHRINK-FIT", bore="16 mm")
    wider = Holder.from_catalog("HSK-A63 shrink-fit", bore="16 mm", nose_diameter="30 mm", material="aluminium")
    assert wider.segments[-1].od_tip.m_as("mm") == 30 and base.segments[-1].od_tip.m_as("mm") == 27
    assert wider.segments[0].material.name == "aluminium" and wider.mass() < base.mass()
    assert "Given: bore, nose_diameter, material" in wider.description
    empty = Holder.from_catalog("CAT40 hydraulic", bore="20 mm", tool_material=None, clamp_length="30 mm")
    assert empty.segments[-1].insert is None and empty.segments[-1].id.m_as("mm") == 20
    assert "nose_angle" in catalog_parameters("BT40 shrink-fit") and "nut_length" in catalog_parameters("BT40 ER25")
    assert Holder.from_catalog("BT40 ER32", name="chuck", bore="1/2 in").name == "chuck"


@pytest.mark.parametrize("kw, match", [
    ({}, "bore: missing"),
    ({"bore": "21 mm"}, "bore: got 21 mm; an ER32 collet clamps at most 20 mm"),
    ({"bore": "12 mm", "nut_lenght": "20 mm"}, "nut_lenght: not a parameter"),
    ({"bore": "12 mm", "gauge_length": "40 mm"}, "gauge_length: got 40 mm; too short"),
    ({"bore": "12 mm", "gauge_length": "20 mm"}, "gauge_length: got 20 mm; expected more than the gap and flange"),
    ({"bore": "12 mm", "clamp_length": "90 mm"}, "clamp_length"),
    ({"bore": "12"}, "bore"),
    ({"bore": "12 mm", "shank_taper": "yes"}, "shank_taper"),
])
def test_input_errors_er(kw, match):
    with pytest.raises(SubstructureError, match=match):
        Holder.from_catalog("BT40 ER32", **kw)


def test_input_errors_other_families():
    with pytest.raises(InvalidValueError, match="catalog: unknown holder 'BT50 ER32'"):
        Holder.from_catalog("BT50 ER32", bore="12 mm")
    with pytest.raises(InvalidValueError, match="bore: got 13 mm; the catalogue has nose_diameter values"):
        Holder.from_catalog("BT40 shrink-fit", bore="13 mm")
    with pytest.raises(InvalidValueError, match="nose_angle"):
        Holder.from_catalog("BT40 shrink-fit", bore="12 mm", nose_angle=4.5)
    with pytest.raises(InvalidValueError, match="bore: got 12 mm; the holder is only"):
        Holder.from_catalog("BT40 shrink-fit", bore="12 mm", nose_diameter="12 mm")
    assert Holder.from_catalog("BT40 shrink-fit", bore="13 mm", nose_diameter="25 mm", clamp_length="45 mm")


TEXT = """name = "catalogue holder"

[frequency]
start = "50 Hz"
stop = "4000 Hz"
step = "50 Hz"

[materials.hss]
E = "220 GPa"
nu = 0.3
rho = "8100 kg/m^3"

[[components]]
name = "spindle"
type = "spindle"
material = "steel"
segments = [{ length = "300 mm", od = "90 mm", id = "40 mm" }]

[[components]]
name = "holder"
type = "holder"
catalog = "HSK-A63 shrink-fit"
bore = "16 mm"
gauge_length = "90 mm"
nose_diameter = "27.5 mm"
tool_material = "hss"

[[components]]
name = "tool"
type = "tool"
material = "hss"
segments = [{ length = "50 mm", od = "16 mm" }]

[[joints]]
name = "sh"
between = ["spindle.tip", "holder.base"]
k = { yf = "5e7 N/m", tm = "4e6 N*m/rad" }

[[joints]]
name = "ht"
between = ["holder.tip", "tool.base"]
k = { yf = "2e7 N/m", tm = "1e5 N*m/rad" }
"""


def test_assembly_file_catalog_key_and_round_trip():
    asm = loads_assembly(TEXT)
    holder = asm.component("holder")
    assert holder == Holder.from_catalog("HSK-A63 shrink-fit", bore="16 mm", gauge_length="90 mm",
                                         nose_diameter="27.5 mm", tool_material=asm.materials[0])
    text = dumps_assembly(asm)
    assert "catalog =" not in text and "APPROXIMATE" in text     # written out as explicit segments
    again = loads_assembly(text)
    assert again == asm
    np.testing.assert_array_equal(again.receptance("tool.tip:y").data, asm.receptance("tool.tip:y").data)


@pytest.mark.parametrize("change, match", [
    (('catalog = "HSK-A63 shrink-fit"', 'catalog = "HSK-A63 shrinkfit"'), r"components\[1\]\.catalog: unknown holder"),
    (('nose_diameter = "27.5 mm"', 'nose_diameterr = "27.5 mm"'), r"components\[1\]\.nose_diameterr: unknown key"),
    (('nose_diameter = "27.5 mm"', 'nose_diameter = "27.5"'),
     r"components\[1\]\.nose_diameter: got '27.5' without a unit"),
    (('gauge_length = "90 mm"', 'gauge_length = "10 mm"'), r"components\[1\]\.gauge_length: got 10 mm"),
    (('tool_material = "hss"', 'tool_material = "hsss"'), r"components\[1\]\.tool_material: unknown material"),
    (('type = "holder"\ncatalog', 'type = "tool"\ncatalog'), r"components\[1\]\.catalog: only holders"),
    (('bore = "16 mm"\n', ''), r"components\[1\]\.bore: missing"),
])
def test_assembly_file_catalog_errors(change, match):
    with pytest.raises(FileFormatError, match=match):
        loads_assembly(TEXT.replace(*change), source="m.toml")


def test_description_key_for_any_beam():
    text = TEXT.replace('name = "tool"\ntype = "tool"',
                        'name = "tool"\ntype = "tool"\ndescription = "HSS end mill, 4 flutes"')
    asm = loads_assembly(text)
    assert asm.component("tool").description == "HSS end mill, 4 flutes"
    assert loads_assembly(dumps_assembly(asm)) == asm
    with pytest.raises(FileFormatError, match=r"components\[2\]\.description: got 3"):
        loads_assembly(text.replace('description = "HSS end mill, 4 flutes"', "description = 3"))
