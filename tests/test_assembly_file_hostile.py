"""Assembly files written the way people get them wrong: each is an error naming file, line and key, or reads right.

The cases come from trying the reader, the writer and ``substructure frf``
as a new user would; each failed silently or with an unclear error before.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from substructure.errors import FileFormatError, InvalidValueError, SubstructureWarning
from substructure.io.assembly_toml import dumps_assembly, load_assembly, loads_assembly, save_assembly

DATA = Path(__file__).parent / "data"
EXAMPLE_TEXT = (DATA / "formats_example.toml").read_text(encoding="utf-8")


def edit(old: str, new: str) -> str:
    assert old in EXAMPLE_TEXT, old
    return EXAMPLE_TEXT.replace(old, new, 1)


SEG_10 = '{ length = "10 mm", od = "40 mm" }'


@pytest.mark.parametrize("old, new, key, said", [
    # pint read these as 205 mm, 2 mm, 1.5 mm, 0.5 in and a loss factor of 2
    (SEG_10, '{ length = "10 mm", od = "20,5 mm" }', "components[1].segments[1].od", "a comma"),
    (SEG_10, '{ length = "1 2 mm", od = "40 mm" }', "components[1].segments[1].length", "a number written after '1'"),
    ('at = "tool.tip"', 'at = "tool@1,5 mm"', "sensors[0].at", "a comma"),
    (SEG_10, '{ length = "1 1/2 in", od = "40 mm" }', "components[1].segments[1].length", "after '1'"),
    ("loss_factor = 0.002", 'loss_factor = "0,002"', "materials.steel.loss_factor", "a comma"),
    # helix reaches pint without the unit checks of the other keys: 35 deg and 30 deg before
    ('type = "tool"', 'type = "tool"\nhelix = "3,5 deg"', "components[2].helix", "a comma"),
    ('type = "tool"', 'type = "tool"\nhelix = "1 30 deg"', "components[2].helix", "after '1'"),
])
def test_a_number_pint_would_misread_is_an_error_at_its_key(old, new, key, said):
    with pytest.raises(FileFormatError) as info:
        loads_assembly(edit(old, new), source="bench.toml")
    message = str(info.value)
    assert message.startswith("bench.toml, line "), message
    assert f": {key}: " in message and said in message, message


def test_a_mil_for_a_length_is_named_as_the_angle_pint_reads():
    with pytest.raises(FileFormatError, match=r"segments\[1\]\.od: got '1575 mil', whose unit mil has no "
                                              r"dimension .*'thou'"):
        loads_assembly(edit(SEG_10, '{ length = "10 mm", od = "1575 mil" }'), source="bench.toml")


@pytest.mark.parametrize("between", ['["holder.tip", "holder@66 mm"]', '["tool.tip-60 mm", "tool.base"]'])
def test_a_joint_between_two_names_of_one_point_is_an_error_on_reading(between):
    # it loaded, and every receptance then failed with "joint 'holder-tool' connects a point to itself"
    text = edit('between = ["holder.tip", "tool.base"]', f"between = {between}")
    with pytest.raises(FileFormatError, match=r"^bench\.toml, line 51: joints\[1\]\.between: '.*' and '.*' are the "
                                              r"same point"):
        loads_assembly(text, source="bench.toml")


@pytest.mark.parametrize("old, new, key", [
    ('yf = "4.19e7 N/m"', 'yf = "1e300 N/m"', "joints[1].k.yf"),
    ('k = { yf = "2e8 N/m" }', 'k = { yf = "-1e200 N/m" }', "supports[0].k.yf"),
])
def test_a_joint_entry_too_large_to_compute_with_is_refused(old, new, key):
    # 1e300 N/m gave a numpy overflow warning, then "coupling through joint 'holder-tool' is singular: a rigid joint
    # that closes a loop of rigid joints", which it is not
    with pytest.raises(FileFormatError, match=rf"^bench\.toml, line \d+: {re.escape(key)}: got '.*'; expected at most "
                                              r"1e\+100 N/m in magnitude .*rigid = true"):
        loads_assembly(edit(old, new), source="bench.toml")


@pytest.mark.parametrize("old, new, key, said", [
    # each failed later: a raw ValueError or OverflowError from the beam model, or receptances of rounding noise
    ('E = "210 GPa"', 'E = "1e300 GPa"', "materials.steel.E", "which is inf in Pa"),
    ('E = "210 GPa"', 'E = "1e-100 Pa"', "materials.steel.E", "from 1 kPa to 10 TPa"),
    ('rho = "7850 kg/m^3"', 'rho = "1e300 kg/m^3"', "materials.steel.rho", "from 0.1 to 1e5 kg/m^3"),
    ("loss_factor = 0.002", "loss_factor = 1e100", "materials.steel.loss_factor", "at most 10"),
    ('mass = "2 g"', 'mass = "1e60 kg"', "sensors[0].mass", "at most 1e6 kg"),
    ('inertia = "5e-8 kg*m^2"', 'inertia = "1e300 kg*m^2"', "sensors[0].inertia", "at most 1e6 kg*m^2"),
])
def test_a_material_or_body_value_the_models_cannot_compute_with_is_refused(old, new, key, said):
    with pytest.raises(FileFormatError, match=rf"^bench\.toml, line \d+: {re.escape(key)}: got .*{re.escape(said)}"):
        loads_assembly(edit(old, new), source="bench.toml")


def test_the_ends_of_the_plausible_ranges_read():
    for old, new in (('E = "210 GPa"', 'E = "10 TPa"'), ('rho = "7850 kg/m^3"', 'rho = "0.1 kg/m^3"'),
                     ("loss_factor = 0.002", "loss_factor = 10"), ('mass = "2 g"', 'mass = "1000 t"')):
        loads_assembly(edit(old, new), source="bench.toml")


@pytest.mark.parametrize("path", [None, 3])
def test_load_and_save_name_what_is_not_a_file_name(path):
    # raw TypeErrors from os.fspath before
    with pytest.raises(FileFormatError, match=rf"got {path!r} of type .*; expected the name of an assembly file"):
        load_assembly(path)
    with pytest.raises(InvalidValueError, match=rf"path: got {path!r} of type .*; expected the name of the assembly"):
        save_assembly(loads_assembly('name = "x"'), path)


def test_a_bytes_file_name_reads_and_writes(tmp_path):
    # load_assembly(b"...") failed with "startswith first arg must be str" when the file had an error
    path = tmp_path / "bench.toml"
    path.write_text(edit(SEG_10, '{ length = "10 mm", od = "40" }'), encoding="utf-8")
    where = rf"^{re.escape(str(path))}, line \d+: components\[1\]\.segments\[1\]\.od"
    with pytest.raises(FileFormatError, match=where):
        load_assembly(os.fsencode(path))
    save_assembly(loads_assembly('name = "x"'), os.fsencode(tmp_path / "x.toml"))
    assert load_assembly(tmp_path / "x.toml").name == "x"


@pytest.mark.parametrize("encoding, said", [
    ("utf-16-le", "a NUL character"),  # UTF-16 without its byte-order mark: "Expected '=' after a key" before
    ("utf-32", "a NUL character"),     # "Invalid statement (at line 1, column 1)" before
])
def test_text_in_another_encoding_says_so(tmp_path, encoding, said):
    path = tmp_path / "bench.toml"
    path.write_bytes(EXAMPLE_TEXT.encode(encoding))
    with pytest.raises(FileFormatError, match=rf"bench\.toml, line 1: {said} .*save the file as UTF-8"):
        load_assembly(path)


def test_lines_ended_by_a_carriage_return_alone_say_so(tmp_path):
    # "invalid TOML: Expected newline or end of document after a statement (at line 1, column ...)" before
    path = tmp_path / "bench.toml"
    path.write_bytes(EXAMPLE_TEXT.replace("\n", "\r").encode("utf-8"))
    with pytest.raises(FileFormatError, match=r"bench\.toml: the lines end in a carriage return alone .* LF"):
        load_assembly(path)
    path.write_bytes(EXAMPLE_TEXT.replace("\n", "\r\n").encode("utf-8"))  # CRLF reads
    assert load_assembly(path) == loads_assembly(EXAMPLE_TEXT)


CATALOG_FILE = '''name = "catalogue holder, the file's own steel and carbide"
[materials.steel]
E = "100 GPa"
nu = 0.3
rho = "7000 kg/m^3"
[materials.carbide]
E = "300 GPa"
nu = 0.22
rho = "14000 kg/m^3"
[[components]]
name = "holder"
type = "holder"
catalog = "HSK-A63 shrink-fit"
bore = "12 mm"
[[components]]
name = "tool"
type = "tool"
segments = [{ length = "40 mm", od = "12 mm" }]
[[joints]]
name = "holder-tool"
between = ["holder.tip", "tool.base"]
rigid = true
'''


def test_a_catalogue_holder_takes_the_files_steel_and_carbide_as_every_segment_does():
    # the holder was built of the catalogue's steel (210 GPa) and its shank of the catalogue's carbide while the
    # tool beside it was of the file's steel; the assembly could then not be saved ("two different materials are
    # called 'steel'")
    assembly = loads_assembly(CATALOG_FILE)
    steel, carbide = assembly.materials
    holder = assembly.component("holder")
    assert {s.material for s in holder.segments} == {steel}
    assert {s.insert.material for s in holder.segments if s.insert is not None} == {carbide}
    assert assembly.component("tool").segments[0].material == steel
    assert loads_assembly(dumps_assembly(assembly)) == assembly


def test_an_assembly_built_in_python_refuses_a_joint_between_two_names_of_one_point():
    from substructure import Assembly, Holder, Segment, Tool
    from substructure.errors import AssemblyError

    parts = [Holder("holder", [Segment("30 mm", "40 mm")]), Tool("tool", [Segment("30 mm", "12 mm")])]
    with pytest.raises(AssemblyError, match=r"joint 'joint-1': tool\.tip and tool@30 mm are the same point"):
        Assembly("a", parts).connect("tool.tip", "tool@30 mm", rigid=True)


def test_a_warning_about_a_value_of_the_file_names_the_file_and_the_line():
    # "joint 'holder-tool': the joint matrix is not symmetric ..." did not say which file
    from substructure.errors import NonReciprocalWarning

    text = edit('tf = "1.0e6 N/rad"', 'tf = "2.0e6 N/rad"')
    with pytest.warns(NonReciprocalWarning, match=r"^bench\.toml, line \d+: joints\[1\]: joint 'holder-tool': the "
                                                  r"joint matrix is not symmetric"):
        loads_assembly(text, source="bench.toml")


HUGE = "9" * 400  # TOML's integers have no limit; this one is beyond every float


@pytest.mark.parametrize("old, new, key", [
    (SEG_10, f'{{ length = "10 mm", od = "{HUGE} mm" }}', "components[1].segments[1].od"),
    ("diameter_ratio = 0.8", f"diameter_ratio = {HUGE}", "components[2].segments[1].flutes.diameter_ratio"),
    ("nu = 0.29", f"nu = {HUGE}", "materials.steel.nu"),
    ('type = "tool"', f'type = "tool"\nteeth = {HUGE}', "components[2].teeth"),
])
def test_an_integer_beyond_every_float_is_an_error_at_its_key(old, new, key):
    # float() of it raised OverflowError, which the command called an internal error
    with pytest.raises(FileFormatError) as info:
        loads_assembly(edit(old, new), source="bench.toml")
    message = str(info.value)
    assert message.startswith("bench.toml, line ") and f": {key}: got " in message, message
    assert "expected" in message, message


@pytest.mark.parametrize("teeth", [1001, 10**6, 4.5, 0])
def test_teeth_beyond_any_cutter_are_refused_in_the_file_the_cut_and_the_tooth_passing(teeth):
    # a million teeth put the tooth passing frequency in the megahertz: the lobes said "no limit found" and the
    # recommendation took the largest depth allowed, at a power of two million kilowatts
    from substructure.stability import MillingCut, tooth_passing_hz

    with pytest.raises(FileFormatError, match=r"components\[2\]\.teeth: got .*; expected a whole number of teeth "
                                              r">= 1 and <= 1000"):
        loads_assembly(edit('type = "tool"', f'type = "tool"\nteeth = {teeth}'), source="bench.toml")
    with pytest.raises(InvalidValueError, match=r"teeth: got .*; expected a whole number of teeth >= 1 and <= 1000"):
        MillingCut(teeth, "10 mm", "5 mm", kt="6e8 Pa", kn="2e8 Pa")
    with pytest.raises(InvalidValueError, match=r"teeth: got .*; expected a whole number of teeth >= 1 and <= 1000"):
        tooth_passing_hz(12000, teeth)
    assert tooth_passing_hz(60, 1000) == pytest.approx(1000.0)
    assert loads_assembly(edit('type = "tool"', 'type = "tool"\nteeth = 1000')).component("tool").teeth == 1000


@pytest.mark.parametrize("old, new, key, said", [
    # the diameters (od, id, the insert's): 12 four times, 40 four times, 63, 70, 90, 110 mm and 40 m: median 40 mm
    (SEG_10, '{ length = "10 mm", od = "40 m" }', "components[1].segments[1].od", "got '40 m', 1e+03 times the "
     "median diameter of the file's segments (40 mm) and over 1 m: a unit typo? (m for mm)"),
    ('{ length = "150 mm", od = "90 mm", id = "40 mm" }', '{ length = "150 m", od = "90 mm", id = "40 mm" }',
     "components[0].segments[1].length", "got '150 m', 4.29e+03 times the median length"),
])
def test_a_segment_in_metres_among_millimetres_is_refused_as_a_unit_typo(old, new, key, said):
    # both were read: a holder 40 m across, a spindle 150 m long, and their FRFs plotted without a word
    with pytest.raises(FileFormatError) as info:
        loads_assembly(edit(old, new), source="bench.toml")
    assert f": {key}: {said}" in str(info.value), str(info.value)


def test_large_parts_that_agree_with_the_rest_are_read():
    # a boring mill's spindle 1.2 m long among others of its size, and a 10 mm tool among 100 mm parts
    text = edit('{ length = "120 mm", od = "70 mm", id = "40 mm" }',
                '{ length = "1200 mm", od = "70 mm", id = "40 mm" }')
    assert loads_assembly(text).component("spindle").length_m == pytest.approx(1.41)
    text = edit('{ length = "30 mm", od = "12 mm" },', '{ length = "30 mm", od = "1 mm" },')
    assert loads_assembly(text).component("tool").segments[0].od.m_as("mm") == pytest.approx(1.0)


def test_a_file_in_metres_throughout_is_warned_of_at_its_largest_part():
    # every size in m for mm agrees with the others, so none stands out: a spindle 330 m long was read and its
    # modes at 26 Hz plotted without a word
    text = re.sub(r'"(\d+(?:\.\d+)?) mm"', r'"\1 m"', EXAMPLE_TEXT)
    with pytest.warns(SubstructureWarning, match=r"bench\.toml, line \d+: components\[0\]: 330 m long; no spindle, "
                                                 r"holder or tool is over 10 m long or 2 m across: sizes in m "
                                                 r"written for mm\? \(read as written\)"):
        assembly = loads_assembly(text, source="bench.toml")
    assert assembly.component("spindle").length_m == pytest.approx(330.0)  # read as written: a warning, not a guess


@pytest.mark.parametrize("segment, said", [
    ('{ length = "76 m", od = "12 m" }', "components[0]: 76 m long"),
    ('{ length = "76 mm", od = "12 m" }', "components[0].segments[0].od: 12 m across"),
])
def test_a_lone_part_beyond_any_machine_tool_is_warned_of_where_no_other_part_shows_the_typo(segment, said):
    text = f'name = "a tool alone"\n[[components]]\nname = "tool"\ntype = "tool"\nsegments = [{segment}]\n'
    with pytest.warns(SubstructureWarning, match=re.escape(said)):
        loads_assembly(text, source="tool.toml")
    loads_assembly(text.replace(" m\"", " mm\""), source="tool.toml")  # in mm: no warning (warnings are errors)
