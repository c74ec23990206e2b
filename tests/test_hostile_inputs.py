"""Issue 10's reproducers, one test each: nothing silently wrong, nothing lost, clear errors.

Each test is the input a user or a hostile tester gave, with what must
happen now: a correct result (checked against a number computed here), a
clear error naming what is wrong, or a file left as it was.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from substructure import Assembly, Frequency, Holder, Segment
from substructure.cli import main
from substructure.errors import FileFormatError, InvalidValueError, UnitError
from substructure.io.assembly_toml import load_assembly, loads_assembly
from substructure.io.frf_files import write_csv
from substructure.surrogate import GPSurrogate, JointTable, cross_validate, thesis_table_4_2

from conftest import make_spindle, make_tool

DATA = Path(__file__).parent / "data"
EXAMPLE = DATA / "formats_example.toml"
EXAMPLE_TEXT = EXAMPLE.read_text(encoding="utf-8")
TWO_PI = 2 * math.pi


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return status, out, err


@pytest.fixture
def tap(tmp_path):
    """A measurement set of the example assembly (tool tip) and the model file, in tmp_path."""
    from substructure.measurements import Measurement, MeasurementSet
    from substructure.synthetic import write_measurement_set

    model = load_assembly(EXAMPLE)
    frf = model.receptance("tool.tip:y", frequency=Frequency.from_range("200 Hz", "3000 Hz", "10 Hz"))
    write_measurement_set(MeasurementSet("tap", (Measurement.from_frf(frf, "tool.tip", "tool.tip"),)), tmp_path)
    (tmp_path / "model.toml").write_text(EXAMPLE_TEXT, encoding="utf-8")
    return tmp_path


def snapshot(directory: Path) -> dict:
    return {p.relative_to(directory): p.read_bytes() for p in directory.rglob("*") if p.is_file()}


# -- frequencies in angular units ---------------------------------------------------------------


def test_angular_units_are_converted_the_same_way_everywhere(capsys):
    rad = Frequency.from_range(f"{TWO_PI * 100!r} rad/s", f"{TWO_PI * 1000!r} rad/s", f"{TWO_PI * 10!r} rad/s")
    rpm = Frequency.from_range("6000 rpm", "60000 rpm", "600 rpm")
    hz = Frequency.from_range("100 Hz", "1000 Hz", "10 Hz")
    np.testing.assert_allclose(rad.hz, hz.hz, rtol=1e-12)
    np.testing.assert_allclose(rpm.hz, hz.hz, rtol=1e-12)
    assert Frequency.from_range("360 deg/s", "3600 deg/s", "360 deg/s").start == pytest.approx(1.0)
    np.testing.assert_array_equal(hz.band_mask(f"{TWO_PI * 500!r} rad/s", "30000 rpm"), hz.band_mask(500, 500))
    # an assembly file's [frequency]
    text = EXAMPLE_TEXT.replace('start = "20 Hz"', 'start = "1200 rpm"').replace('step = "2 Hz"', 'step = "120 rpm"')
    assert loads_assembly(text).frequency == load_assembly(EXAMPLE).frequency
    # --grid
    status, out, _ = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--json",
                         "--grid", f"{TWO_PI * 1490!r} rad/s:{TWO_PI * 1510!r} rad/s:{TWO_PI * 10!r} rad/s")
    assert status == 0
    np.testing.assert_allclose(json.loads(out)["frequency_hz"], [1490, 1500, 1510], rtol=1e-12)
    with pytest.raises(UnitError, match="angle to the power 2"):
        Frequency.from_range("1 rad**2/s", "2 rad**2/s", "1 rad**2/s")


# -- the joint that loses its damping -----------------------------------------------------------


def test_connect_with_damping_and_no_stiffness_is_refused():
    assembly = Assembly("a", components=(make_spindle(), make_tool()))
    with pytest.raises(InvalidValueError, match="damping c without stiffness k"):
        assembly.connect("spindle.tip", "tool.base", c={"yf": "100 N*s/m"})
    with pytest.raises(InvalidValueError, match="rigid joint takes no k or c"):
        assembly.connect("spindle.tip", "tool.base", k={"yf": "1e7 N/m"}, rigid=True)
    assert assembly.connect("spindle.tip", "tool.base").joints[0].rigid  # neither: rigid, as documented


# -- joint tables --------------------------------------------------------------------------------


TABLE_HEADER = "tool_diameter [mm],gauge_length [mm],k_yf [N/m],k_yf_std [N/m]\n"
ROWS = "12,76,1.4e7,1e5\n16,80,2.0e7,\n20,90,2.6e7,2e5\n"


@pytest.mark.parametrize("text, message", [
    (TABLE_HEADER.replace("k_yf [N/m],", "k_yf [N],") + ROWS, r"column k_yf: the unit 'N' .* not one of a stiffness"),
    (TABLE_HEADER.replace("k_yf [N/m],", "k_yf [furlongs],") + ROWS, "'furlongs'.*not one of a stiffness"),
    (TABLE_HEADER.replace("k_yf_std [N/m]", "k_yf_std [N*s/m]") + ROWS, "k_yf_std: the unit 'N\\*s/m'"),
    (TABLE_HEADER + ROWS.replace("2.0e7", "-2.0e7"), r"line 3: k_yf is -2e\+07 N/m; expected a positive stiffness"),
    (TABLE_HEADER + ROWS.replace("1e5", "-1e5"), r"line 2: k_yf_std is -100000; expected a standard deviation"),
    (TABLE_HEADER + ROWS.replace("2.0e7", "nan"), r"line 3: k_yf = 'nan'; expected a finite number"),
    (TABLE_HEADER + ROWS.replace("1e5", "nan"), r"line 2: k_yf_std = 'nan'.*leave the cell empty"),
    (TABLE_HEADER + ROWS.replace("76", "inf"), r"line 2: gauge_length = 'inf'"),
    ("tool_diameter [mm],tool_diameter [mm],k_yf [N/m]\n12,12,1e7\n", "tool_diameter is given more than once"),
    (TABLE_HEADER.replace("tool_diameter [mm]", "tool_diameter [kg/furlong^2]") + ROWS, None),  # a feature: any unit
])
def test_joint_table_dimensions_signs_finiteness_and_duplicates(tmp_path, text, message):
    path = tmp_path / "joints.csv"
    path.write_text(text, encoding="utf-8")
    if message is None:
        assert len(JointTable.from_csv(path)) == 3
        return
    with pytest.raises(FileFormatError, match=message):
        JointTable.from_csv(path)


def test_joint_table_checks_apply_to_rows_appended_and_toml_files(tmp_path):
    table = thesis_table_4_2()
    with pytest.raises(InvalidValueError, match="k_yf is -1e\\+07 N/m; expected a positive stiffness"):
        table.append({"tool_diameter": "14 mm", "gauge_length": "80 mm", "k_yf": "-1e7 N/m"})
    with pytest.raises(InvalidValueError, match="k_yf_std is -1e\\+06"):
        table.append({"tool_diameter": "14 mm", "gauge_length": "80 mm", "k_yf": "1e7 N/m", "k_yf_std": "-1e6 N/m"})
    with pytest.raises(UnitError, match="units that do not match"):
        table.append({"tool_diameter": "14 mm", "gauge_length": "80 mm", "k_yf": "1e7 N"})
    table.to_toml(tmp_path / "t.toml")
    bad = (tmp_path / "t.toml").read_text().replace('k_yf = "N/m"', 'k_yf = "N"', 1)
    (tmp_path / "bad.toml").write_text(bad)
    with pytest.raises(FileFormatError, match="bad.toml: k_yf: the unit 'N'"):
        JointTable.from_toml(tmp_path / "bad.toml")


def test_a_constant_feature_is_not_a_narrow_guess():
    rows = [{"tool_diameter": f"{d} mm", "gauge_length": "76 mm", "k_yf": f"{k} N/m"}
            for d, k in ((8, 0.9e7), (10, 1.2e7), (12, 1.4e7), (16, 2.0e7), (20, 2.6e7))]
    model = GPSurrogate().fit(JointTable.from_rows(rows))
    assert model.predict({"tool_diameter": "14 mm", "gauge_length": "76 mm"}).value("k_yf")[0] > 0
    with pytest.raises(InvalidValueError, match="every row of the joint table has gauge_length = 76 mm"):
        model.predict({"tool_diameter": "14 mm", "gauge_length": "100 mm"})


def test_a_one_row_table_is_not_called_empty(tmp_path, capsys):
    path = tmp_path / "one.csv"
    path.write_text(TABLE_HEADER + ROWS.splitlines()[0] + "\n", encoding="utf-8")
    table = JointTable.from_csv(path)
    assert len(table) == 1
    with pytest.raises(InvalidValueError, match="has 1 row; leave-one-out needs|holding out one row leaves 0"):
        cross_validate(GPSurrogate(), table, "k_yf")
    for extra in (["--cross-validate", "loo"], ["--features", "tool_diameter=14 mm,gauge_length=80 mm"]):
        status, _, err = run(capsys, "predict", path, *extra)
        assert status == 1 and "1 row" in err and "empty" not in err, err


def test_joint_table_with_a_byte_order_mark_reads(tmp_path):
    path = tmp_path / "bom.csv"
    path.write_bytes(b"\xef\xbb\xbf" + (TABLE_HEADER + ROWS).encode())
    assert list(JointTable.from_csv(path).features) == ["tool_diameter", "gauge_length"]


# -- dead channels -------------------------------------------------------------------------------


def test_a_dead_channel_is_refused_with_its_file(tap, capsys):
    csv = next(tap.glob("*.csv"))
    lines = csv.read_text().splitlines()
    csv.write_text("\n".join([lines[0]] + [f"{ln.split(',')[0]},0.0,0.0" for ln in lines[1:]]) + "\n")
    for command in (["identify", "--joint", "holder-tool"], ["diagnose", "--quiet"]):
        status, out, err = run(capsys, command[0], tap / "model.toml", tap / "measurements.toml", *command[1:],
                               "--json")
        assert status == 1 and out == ""
        assert f"frf[0].file: {csv}: every value is 0, a dead channel" in err, err


# -- one-line grids ------------------------------------------------------------------------------


def test_one_line_grids_are_refused(tmp_path, capsys):
    with pytest.raises(InvalidValueError, match="single line; a grid needs at least two"):
        Frequency.from_range("20 Hz", "20 Hz", "1 Hz")
    with pytest.raises(InvalidValueError, match="single line"):
        Frequency.from_range("20 Hz", "25 Hz", "10 Hz")
    from substructure import FRF

    with pytest.raises(InvalidValueError, match="at least 2 frequency lines"):
        write_csv(FRF.single(Frequency.from_hz([20.0]), [1e-6]), tmp_path / "one.csv")
    assert not (tmp_path / "one.csv").exists()
    status, _, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--grid", "20:20:1", "--out", tmp_path / "x.csv")
    assert status == 2 and "single line" in err and not (tmp_path / "x.csv").exists()
    text = EXAMPLE_TEXT.replace('stop = "5000 Hz"', 'stop = "20 Hz"')
    with pytest.raises(FileFormatError, match=r"one.toml, line 5: frequency.stop: .* single line"):
        loads_assembly(text, "one.toml")


def test_grid_size_is_checked_before_memory_is_allocated(capsys):
    with pytest.raises(InvalidValueError, match=r"makes 4.98e\+09 lines; the limit is 1e\+06 lines"):
        Frequency.from_range("20 Hz", "5000 Hz", "1e-6 Hz")
    status, _, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--grid", "20:5000:1e-6")
    assert status == 2 and "MAX_GRID_LINES" in err


# -- nothing lost --------------------------------------------------------------------------------


def test_demo_does_not_replace_a_users_files(tmp_path, capsys):
    mine = {"default_assembly.toml": "my machine\n", "improved_assembly.toml": "my improved\n"}
    for name, text in mine.items():
        (tmp_path / name).write_text(text)
    status, _, err = run(capsys, "demo", "--out", tmp_path)
    assert status == 1 and "default_assembly.toml, improved_assembly.toml" in err and "--overwrite" in err
    assert {n: (tmp_path / n).read_text() for n in mine} == mine
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(mine)  # nothing else written either
    (tmp_path / "notes.txt").write_text("mine")
    status, _, err = run(capsys, "demo", "--out", tmp_path / "notes.txt")
    assert status == 1 and "is a file" in err


def test_diagnose_figures_and_model_are_never_written_over_inputs_or_existing_files(tap, capsys):
    before = snapshot(tap)
    (tap / "figs").mkdir()
    (tap / "figs" / "error_fall.png").write_bytes(b"my figure")
    base = ["diagnose", tap / "model.toml", tap / "measurements.toml", "--quiet"]
    status, _, err = run(capsys, *base, "--plot", tap / "figs")
    assert status == 1 and "error_fall.png: the file exists; add --overwrite" in err
    assert (tap / "figs" / "error_fall.png").read_bytes() == b"my figure"
    for target in (tap / "model.toml", tap / "sub" / ".." / "measurements.toml", next(tap.glob("*.csv"))):
        status, _, err = run(capsys, *base, "--save-model", target, "--overwrite")
        assert status == 2 and "is the input" in err, err
    os.symlink(tap / "model.toml", tap / "link.toml")
    status, _, err = run(capsys, *base, "--save-model", tap / "link.toml", "--overwrite")
    assert status == 2 and "is the input" in err
    assert {k: v for k, v in snapshot(tap).items() if k.parts[0] not in ("figs", "link.toml")} == before


def test_frf_out_and_plot_are_not_overwritten_without_asking(tmp_path, capsys):
    out = tmp_path / "tip.csv"
    out.write_text("mine\n")
    status, _, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--out", out)
    assert status == 1 and "--overwrite" in err and out.read_text() == "mine\n"
    assert run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--out", out, "--overwrite")[0] == 0
    assert out.read_text().startswith("frequency_hz,real,imag")


# -- clear errors, never a traceback ---------------------------------------------------------------


def test_an_unsupported_plot_file_is_refused_before_the_work(tmp_path, capsys):
    for argv in (["frf", EXAMPLE, "--at", "tool.tip", "--out", tmp_path / "x.csv", "--plot", tmp_path / "x.xyz"],
                 ["predict", tmp_path / "none.csv", "--cross-validate", "loo", "--plot", tmp_path / "cv.docx"],
                 ["frf", EXAMPLE, "--at", "tool.tip", "--plot", tmp_path / "noextension"]):
        status, _, err = run(capsys, *argv)
        assert status == 2 and "expected an image file" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv, message", [
    (["frf", EXAMPLE, "--at", "tool.tip", "--grid", "-20:5000:2"], "start: got '-20.0 Hz'; expected a frequency >= 0"),
    (["frf", EXAMPLE, "--at", "tool.tip", "--grid", "-20 Hz:5000 Hz:2 Hz"], "expected a frequency >= 0"),
    (["frf", EXAMPLE, "--at", "tool.tip", "--grid", "a:b:c"], "START 'a' is not a number"),
    (["frf", EXAMPLE, "--at", "tool.tip", "--grid", "20 mm:5000:2"], "start: got '20 mm'"),
    (["identify", EXAMPLE, EXAMPLE, "--joint", "x", "--band", "-5:10"], "LO is -5 Hz, expected frequencies >= 0"),
    (["identify", EXAMPLE, EXAMPLE, "--joint", "x", "--band=-5:10"], "LO is -5 Hz"),
    (["diagnose", EXAMPLE, EXAMPLE, "--band", "-100:-10"], "LO is -100 Hz"),
    (["lobes", "--frf", "x.csv", "--band", "-5:10"], "LO is -5 Hz"),
    (["lobes", "--frf", "x.csv", "--teeth", "2", "--speeds", "-2000:24000:50"], "-2000"),
])
def test_negative_and_malformed_numbers_say_what_is_wrong(capsys, argv, message):
    status, _, err = run(capsys, *argv)
    assert status == 2 and "expected one argument" not in err
    assert message in err, err


def test_repetitions_are_bounded_before_any_work(capsys):
    for argv in (["identify", EXAMPLE, EXAMPLE, "--joint", "holder-tool", "--bootstrap", "100000000"],
                 ["identify", EXAMPLE, EXAMPLE, "--joint", "holder-tool", "--bootstrap", "-1"],
                 ["predict", EXAMPLE, "--features", "d=1 mm", "--samples", "0"],
                 ["predict", EXAMPLE, "--features", "d=1 mm", "--samples", "1000000000"]):
        status, _, err = run(capsys, *argv)
        assert status == 2 and "to 10000" in err, err


def test_byte_order_marks_are_accepted(tap, capsys):
    for name in ("model.toml", "measurements.toml", next(tap.glob("*.csv")).name):
        (tap / name).write_bytes(b"\xef\xbb\xbf" + (tap / name).read_bytes())
    status, out, _ = run(capsys, "identify", tap / "model.toml", tap / "measurements.toml", "--joint", "holder-tool",
                         "--parameters", "k_yf", "--json")
    assert status == 0 and json.loads(out)["joint"] == "holder-tool"


def test_a_directory_given_as_a_file(tmp_path, capsys):
    for argv in (["frf", tmp_path, "--at", "tool.tip"], ["identify", EXAMPLE, tmp_path, "--joint", "holder-tool"],
                 ["lobes", "--frf", tmp_path, "--teeth", "2", "--diameter", "12 mm", "--immersion", "0.5",
                  "--kt", "600 MPa", "--kr", "0.3"],
                 ["predict", tmp_path, "--cross-validate", "loo"]):
        status, _, err = run(capsys, *argv)
        assert status == 1 and f"{tmp_path}: is a directory" in err, err


def test_strings_without_a_number_are_not_one_unit():
    with pytest.raises(UnitError, match="does not start with a number"):
        Segment("mm", "12 mm")
    with pytest.raises(UnitError, match="does not start with a number"):
        Frequency.from_range("a", "5 kHz", "1 Hz")  # pint reads 'a' as one year


def test_an_unexpected_exception_is_one_line_with_its_own_status(monkeypatch, capsys):
    from substructure.cli import frf_command

    def broken(args):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(frf_command, "run", broken)
    status, out, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip")
    assert status == 70 and out == ""
    assert err.count("\n") == 1 and err.startswith("substructure: error: internal error: ZeroDivisionError")
    assert "please report it" in err
    monkeypatch.setenv("SUBSTRUCTURE_DEBUG", "1")
    with pytest.raises(ZeroDivisionError):
        main(["frf", str(EXAMPLE), "--at", "tool.tip"])


def test_json_output_is_strict():
    from substructure.cli._common import json_text

    text = json_text({"a": math.nan, "b": [np.inf, -np.inf, np.float32(1.5)], "c": np.arange(2), "d": (True, None)})

    def refuse(constant):
        raise AssertionError(f"{constant} in JSON")

    assert json.loads(text, parse_constant=refuse) == {"a": None, "b": [None, None, 1.5], "c": [0, 1],
                                                       "d": [True, None]}


def test_holder_subclass_table_without_hooks_reads_fields(tmp_path):
    """The generic table of a registered Beam subclass carries its extra fields (test_extension_component)."""
    holder = Holder("holder", [Segment("16 mm", "63 mm")])
    assert loads_assembly('name = "x"\n[[components]]\nname = "holder"\ntype = "holder"\n'
                          'segments = [{ length = "16 mm", od = "63 mm" }]\n').component("holder") == holder


def test_inputs_of_the_python_api_that_raised_raw_errors_are_named():
    """Each of these gave a raw TypeError or ValueError from deep inside (or, for an FRF times a length, a pint
    quantity wrapping the FRF): now an error naming the field, the value and what was expected."""
    from substructure import Assembly, Frequency, Segment, add_mass, default_assembly
    from substructure.errors import InvalidValueError, UnknownPointError
    from substructure.units import Q_

    d = default_assembly()
    g = Frequency.from_range("100 Hz", "1000 Hz", "100 Hz")
    h = d.receptance("tool.tip:y", frequency=g)
    with pytest.raises(InvalidValueError, match=r"length: got \(1\+1j\) millimeter; expected a real value"):
        Segment(Q_(1 + 1j, "mm"), "12 mm")
    with pytest.raises(InvalidValueError, match=r"frequency: got \['100 Hz', '200 Hz'\]; expected a Frequency"):
        d.receptance("tool.tip:y", frequency=["100 Hz", "200 Hz"])
    with pytest.raises(InvalidValueError, match=r"components: got a Holder; expected a sequence of them"):
        Assembly("a", components=d.component("holder"))
    with pytest.raises(InvalidValueError, match=r"sensors\[0\]: got 'tip'; expected a Sensor"):
        Assembly("a", components=(d.component("tool"),), sensors=["tip"])
    with pytest.raises(InvalidValueError, match=r"cannot multiply an FRF by a quantity in millimeter"):
        h * Q_(2, "mm")
    np.testing.assert_array_equal((h * Q_(2, "")).data, 2 * h.data)  # a dimensionless quantity is a number
    with pytest.raises(UnknownPointError, match=r"point tool\.tip: a modification there needs the point's DOFs "
                                                r"among both the FRF's outputs and its inputs .* inputs are "
                                                r"holder\.tip:y"):
        add_mass(d.receptance("tool.tip:y", "holder.tip:y", frequency=g), "tool.tip", "2 g")
