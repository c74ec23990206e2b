"""Third hostile round (issues 24 and 21): inputs that recursed, divided by zero, blocked, read without end,
were taken in the wrong unit or overwrote a user's file.

Each test is the input of the report with what must happen now: a clear error naming the file (and the
line, key or column) and what is allowed, or the right result checked against a value computed here.
"""

from __future__ import annotations

import os
import threading
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from substructure import Frequency
from substructure.cli import main
from substructure.errors import FileFormatError, InvalidValueError, SubstructureError
from substructure.io import MAX_DATA_BYTES, MAX_TEXT_BYTES, read_text
from substructure.io.assembly_toml import load_assembly, loads_assembly
from substructure.io.frf_files import read_csv, read_uff
from substructure.io.measurements import load_measurements, loads_measurements

from test_uff_units import measurement_set

DATA = Path(__file__).parent / "data"
EXAMPLE = DATA / "formats_example.toml"
EXAMPLE_TEXT = EXAMPLE.read_text(encoding="utf-8")
MODES_HEADER = "direction,frequency_hz,damping_ratio,stiffness_n_per_m"
CUT = ["--teeth", "2", "--diameter", "10 mm", "--immersion", "1", "--milling", "down", "--kt", "6e8 Pa",
       "--kn", "2e8 Pa", "--speeds", "10000:16000:1000"]


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err and "internal error" not in err, err
    return status, out, err


def tap_test(folder: Path, response: str = "tool.tip:y") -> Path:
    """A noiseless tap test of the example assembly at the tool tip, with the model file, in ``folder``."""
    from substructure.measurements import Measurement, MeasurementSet
    from substructure.synthetic import write_measurement_set

    model = load_assembly(EXAMPLE)
    frf = model.frf([response], ["tool.tip:y"], frequency=Frequency.from_range("200 Hz", "3000 Hz", "10 Hz"))
    write_measurement_set(MeasurementSet("tap", (Measurement.from_frf(frf, response, "tool.tip:y"),)), folder)
    (folder / "model.toml").write_text(EXAMPLE_TEXT, encoding="utf-8")
    return folder


# -- TOML nested thousands deep ------------------------------------------------------------------------


def test_toml_nested_5000_deep_is_refused_with_the_file(tmp_path, capsys):
    deep = tmp_path / "a.toml"
    deep.write_text("name = " + "[" * 5000 + "]" * 5000 + "\n", encoding="utf-8")
    status, out, err = run(capsys, "frf", deep, "--at", "tool.tip")
    assert status == 1 and out == ""
    assert f"{deep}: invalid TOML: arrays or inline tables nested hundreds of levels deep" in err
    nested = "x = " + "{ a = " * 3000 + "1" + " }" * 3000 + "\n"
    for loads in (loads_assembly, loads_measurements):
        with pytest.raises(FileFormatError, match="<deep>: invalid TOML: .*nested"):
            loads(nested, source="<deep>")
    (tmp_path / "m.toml").write_text(nested, encoding="utf-8")
    status, _, err = run(capsys, "diagnose", EXAMPLE, tmp_path / "m.toml")
    assert status == 1 and "m.toml: invalid TOML" in err and "nested" in err


# -- one checked read: regular files, one cap per kind ------------------------------------------------


def test_dev_zero_is_refused_before_reading_wherever_a_file_is_read(capsys):
    from substructure.stability import ModalModel, load_workpieces
    from substructure.study import Cut
    from substructure.study.reader import load_study
    from substructure.surrogate import JointTable

    for argv in (["frf", "/dev/zero", "--at", "tool.tip"], ["diagnose", EXAMPLE, "/dev/zero"],
                 ["lobes", "--modes", "/dev/zero", *CUT], ["lobes", "--frf", "/dev/zero", *CUT],
                 ["predict", "/dev/zero", "--features", "tool_diameter=14 mm"],
                 ["study", "/dev/zero", "--out", "never-written"]):
        status, _, err = run(capsys, *argv)
        assert status == 1 and "/dev/zero: is a character device; expected" in err and "(a regular file)" in err, \
            (argv, err)
    for read in (load_assembly, load_measurements, load_study, load_workpieces, ModalModel.from_csv,
                 JointTable.from_csv, JointTable.from_toml, read_csv, read_uff, read_text):
        with pytest.raises(FileFormatError, match="/dev/zero: is a character device"):
            read("/dev/zero")
    with pytest.raises(FileFormatError, match="/dev/zero: is a character device; expected a workpiece table"):
        Cut("alu", workpiece="aluminium-7075", workpiece_table="/dev/zero", radial_depth="3 mm")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_a_fifo_without_a_writer_is_refused_not_waited_on(tmp_path, capsys):
    fifo = tmp_path / "a.toml"
    os.mkfifo(fifo)
    result = {}
    worker = threading.Thread(target=lambda: result.update(out=run(capsys, "frf", fifo, "--at", "tool.tip")),
                              daemon=True)
    worker.start()
    worker.join(60)
    assert not worker.is_alive(), "the reader blocked on a FIFO"
    status, _, err = result["out"]
    assert status == 1 and f"{fifo}: is a named pipe (FIFO); expected an assembly file (a regular file)" in err
    fifo_set = tmp_path / "m.toml"
    os.mkfifo(fifo_set)
    with pytest.raises(FileFormatError, match="named pipe"):
        load_measurements(fifo_set)
    # a data file named by a measurement set is checked the same way
    os.mkfifo(tmp_path / "tip.csv")
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.file: .*tip.csv: is a named pipe"):
        load_measurements(measurement_set(tmp_path, "tip.csv"))


def test_the_caps_hold_for_tables_and_data_files(tmp_path):
    """Files over their kind's cap are refused by their size, before they are read."""
    assert MAX_TEXT_BYTES == 16 * 2**20 and MAX_DATA_BYTES == 128 * 2**20  # stated in docs/file-formats.md
    big = tmp_path / "big.toml"
    with open(big, "wb") as fh:  # a sparse file: no disk space, a size over the cap
        fh.truncate(MAX_TEXT_BYTES + 1)
    with pytest.raises(FileFormatError, match=f"big.toml: {MAX_TEXT_BYTES + 1:,} bytes, more than the "
                                              f"{MAX_TEXT_BYTES:,} bytes an assembly file may have"):
        load_assembly(big)
    csv = tmp_path / "big.csv"
    with open(csv, "wb") as fh:
        fh.write(b"frequency_hz,real,imag\n1,1e-6,0\n2,1e-6,0\n")
        fh.truncate(MAX_TEXT_BYTES + 1)  # over the cap of a table, within that of an FRF file
    with pytest.raises(FileFormatError, match="modes CSV file may have"):
        from substructure.stability import ModalModel

        ModalModel.from_csv(csv)
    with pytest.raises(FileFormatError) as caught:
        read_csv(csv)  # read (the data file cap is larger), then refused for its content
    assert "may have" not in str(caught.value) and "line 4:" in str(caught.value)
    assert len(str(caught.value)) < 600  # a line of 16 MiB is not copied into the message


# -- measured FRFs beyond any structure ----------------------------------------------------------------


def test_a_measured_frf_of_1e300_is_refused_at_the_reader_with_file_and_line(tmp_path, capsys):
    folder = tap_test(tmp_path)
    csv = next(folder.glob("*.csv"))
    lines = csv.read_text().splitlines()
    csv.write_text("\n".join([lines[0]] + [f"{ln.split(',')[0]},1e300,-1e300" for ln in lines[1:]]) + "\n")
    status, out, err = run(capsys, "diagnose", folder / "model.toml", folder / "measurements.toml", "--quiet")
    assert status == 1 and out == ""
    assert f"frf[0].file: {csv}, line 2: at 200 Hz: |H| is 1.41e+300 in SI units (m/N), more than 1 m/N" in err
    # a single line beyond 1 m/N is refused too, with its own line; 0.9 m/N is let through
    csv.write_text("\n".join(lines[:5] + [f"{lines[5].split(',')[0]},0,2.5"] + lines[6:]) + "\n")
    with pytest.raises(FileFormatError, match=r"line 6: at 240 Hz: \|H\| is 2.5 in SI"):
        load_measurements(folder / "measurements.toml")
    csv.write_text("\n".join(lines[:5] + [f"{lines[5].split(',')[0]},0,0.9"] + lines[6:]) + "\n")
    assert load_measurements(folder / "measurements.toml").measurements[0].frf.data[4, 0, 0] == 0.9j


def test_an_accelerance_is_judged_as_the_receptance_it_is(tmp_path):
    """(m/s^2)/N of 1e3 at 10 Hz is a receptance of 0.25 m/N: accepted; 1e3 at 1 Hz (25 m/N) is not."""
    hz = np.array([1.0, 10.0, 20.0])
    for first, ok in ((10.0, True), (1.0, False)):
        rows = "".join(f"{f!r},1000.0,0.0\n" for f in [first, 20.0, 30.0])
        (tmp_path / "a.csv").write_text("frequency_hz,real,imag\n" + rows)
        path = measurement_set(tmp_path, "a.csv", quantity="accelerance")
        if ok:
            got = load_measurements(path).measurements[0].frf
            np.testing.assert_allclose(np.abs(got.data[:, 0, 0]), 1000.0 / (2 * np.pi * np.array([10, 20, 30.0])) ** 2)
        else:
            with pytest.raises(FileFormatError, match=r"a.csv, line 2: at 1 Hz: \|H\| is 25.3 as a receptance"):
                load_measurements(path)
    del hz


def test_the_noise_estimate_refuses_an_overflowing_frf_from_python():
    from substructure.diagnose import diagnose
    from substructure.frf import FRF
    from substructure.measurements import Measurement, MeasurementSet

    model = load_assembly(EXAMPLE)
    frf = model.receptance("tool.tip:y", frequency=Frequency.from_range("200 Hz", "3000 Hz", "10 Hz"))
    huge = FRF(frf.frequency, np.full(frf.data.shape, 1e300 - 1e300j), frf.outputs, frf.inputs)
    with pytest.raises(InvalidValueError, match=r"measured FRF tool.tip:y / tool.tip:y: \|H\| of 1.41e\+300"):
        diagnose(model, MeasurementSet("t", (Measurement.from_frf(huge, "tool.tip", "tool.tip"),)))


# -- modes outside a physical range --------------------------------------------------------------------


@pytest.mark.parametrize("row, message", [
    ("y,1e-300,0.02,1e7", "line 2, column 2 (frequency_hz): got '1e-300'; expected a natural frequency in Hz, 0.1 to "
                          "1e+06 (MODE_FREQUENCY_RANGE_HZ): a wrong unit?"),
    ("y,2e6,0.02,1e7", "line 2, column 2 (frequency_hz): got '2e6'; expected a natural frequency in Hz, 0.1 to 1e+06"),
    ("y,900,0.02,1e-300", "line 2, column 4 (stiffness_n_per_m): got '1e-300'; expected a modal stiffness in N/m, 1 to "
                          "1e+12 (MODE_STIFFNESS_RANGE_N_PER_M): a wrong unit?"),
    ("y,900,0.02,1e300", "line 2, column 4 (stiffness_n_per_m): got '1e300'; expected a modal stiffness in N/m, "
                         "1 to 1e+12"),
])
@pytest.mark.parametrize("method", ["zoa", "sdm"])
def test_a_mode_outside_the_physical_range_is_refused_with_file_and_line(tmp_path, capsys, row, message, method):
    modes = tmp_path / "m.csv"
    modes.write_text(f"{MODES_HEADER}\n{row}\n")
    status, _, err = run(capsys, "lobes", "--modes", modes, "--method", method, *CUT)
    assert status == 1 and f"{modes}, {message}" in err, err


def test_the_mode_range_ends_are_accepted():
    from substructure.stability import Mode

    for f, k in (("0.1 Hz", "1 N/m"), ("1 MHz", "1e12 N/m")):
        mode = Mode("y", f, 0.02, k)
        assert mode.mass_kg == pytest.approx(mode.stiffness_n_per_m / (2 * np.pi * mode.frequency_hz) ** 2)
    with pytest.raises(InvalidValueError, match="frequency: got 0.0999 Hz"):
        Mode("y", "0.0999 Hz", 0.02, "1e7 N/m")


# -- a rotation as a measured response -----------------------------------------------------------------


def test_diagnose_refuses_a_measured_rotation_with_the_reason(tmp_path, capsys):
    folder = tap_test(tmp_path, "tool.tip:theta")
    status, out, err = run(capsys, "diagnose", folder / "model.toml", folder / "measurements.toml", "--quiet")
    assert status == 1 and out == ""
    assert "measured FRF tool.tip:theta / tool.tip:y" in err and "tool.tip:theta is a rotation" in err
    assert "measurements.toml" in err and "tap tests measure" in err


# -- features given twice ------------------------------------------------------------------------------


def test_a_feature_given_twice_is_refused(tmp_path, capsys):
    from substructure.surrogate import GPSurrogate, thesis_table_4_2

    table = tmp_path / "joints.csv"
    thesis_table_4_2().to_csv(table)
    status, out, err = run(capsys, "predict", table, "--features",
                           "tool_diameter=14 mm,gauge_length=90 mm,tool_diameter=16 mm")
    assert status == 2 and out == ""
    assert "--features: tool_diameter given twice ('14 mm' and '16 mm'); give each feature once" in err
    model = GPSurrogate().fit(thesis_table_4_2(), ["k_yf"])
    with pytest.raises(InvalidValueError, match="features: got the string 'tool_diameter=14 mm'; expected a mapping"):
        model.predict("tool_diameter=14 mm")


# -- UFF unit labels with a Latin-1 superscript ---------------------------------------------------------


def _pyuff_accelerance(path: Path, label: str, ordinate_type: int) -> np.ndarray:
    """A type-58 accelerance written by pyuff with the unit label ``label`` (``^2`` patched to byte 0xB2)."""
    import pyuff

    hz = 5.0 + 5.0 * np.arange(200)
    w, wn = 2 * np.pi * hz, 2 * np.pi * 400.0
    accelerance = -w**2 / (1e6 * (1 - (w / wn) ** 2 + 0.04j * w / wn))
    dset = pyuff.prepare_58(
        func_type=4, rsp_node=1, rsp_dir=3, ref_node=1, ref_dir=3, data=accelerance, x=hz, id1="FRF",
        rsp_ent_name="pt", ref_ent_name="pt", abscissa_spacing=1, abscissa_spec_data_type=18,
        ordinate_spec_data_type=ordinate_type, orddenom_spec_data_type=13, ordinate_axis_units_lab=label,
        abscissa_axis_units_lab="Hz", orddenom_axis_units_lab="NONE", abscissa_min=5.0, abscissa_inc=5.0)
    pyuff.UFF(str(path)).write_sets(dset, "add")
    raw = path.read_bytes()
    assert raw.count(b"^2)") == 1
    path.write_bytes(raw.replace(b"^2)", b"\xb2)"))
    return accelerance


@pytest.mark.parametrize("ordinate_type", [12, 1])  # acceleration, and "general": the label alone decides
def test_a_latin1_superscript_two_is_an_exponent(tmp_path, ordinate_type):
    expected = _pyuff_accelerance(tmp_path / "a.uff", "(1/N)*(m/s^2)", ordinate_type)
    assert b"(m/s\xb2)" in (tmp_path / "a.uff").read_bytes()
    frf = read_uff(tmp_path / "a.uff")
    assert frf.quantity == "accelerance"
    np.testing.assert_allclose(frf.data[:, 0, 0], expected, rtol=1e-10)


def test_utf8_superscripts_and_an_undecidable_label(tmp_path):
    from substructure.io.frf_files.uff_units import _exponents, _unit_of_label

    assert _exponents(_unit_of_label("(1/N)*(m/s²)")) == (-1, 1, -2)
    assert _exponents(_unit_of_label("m³/N")) == (-1, 3, 0)
    with pytest.raises(ValueError):
        _unit_of_label("(1/N)*(m/s\ufffd)")  # a byte pyuff could not decode: unreadable, never dropped
    expected = _pyuff_accelerance(tmp_path / "b.uff", "(1/N)*(m/s^2)", 1)
    raw = (tmp_path / "b.uff").read_bytes()
    (tmp_path / "b.uff").write_bytes(raw.replace(b"\xb2)", b"\x81)"))  # a control character in Latin-1
    with pytest.raises(FileFormatError, match=r"b.uff, type-58 record 0: cannot read the unit label"):
        read_uff(tmp_path / "b.uff")
    frf = read_uff(tmp_path / "b.uff", quantity="accelerance")  # said by the user: the label is set aside
    np.testing.assert_allclose(frf.data[:, 0, 0], expected, rtol=1e-10)


# -- CSV exports: a name and a unit that disagree, a negative magnitude -----------------------------------


def test_a_frequency_named_in_hz_with_a_khz_unit_is_refused(tmp_path):
    path = tmp_path / "x.csv"
    path.write_text("frequency_hz [kHz],real,imag\n1,1e-6,1e-7\n2,1e-6,1e-7\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"x.csv, line 1: column 'frequency_hz \[kHz\]': its name says Hz "
                                              r"but its unit says 'kHz'"):
        read_csv(path)
    path.write_text("frequency_hz [Hz],real,imag\n1,1e-6,1e-7\n2,1e-6,1e-7\n", encoding="utf-8")
    np.testing.assert_array_equal(read_csv(path).frequency.hz, [1.0, 2.0])  # the two agree: read
    path.write_text("Frequency [kHz],real,imag\n1,1e-6,1e-7\n2,1e-6,1e-7\n", encoding="utf-8")
    np.testing.assert_array_equal(read_csv(path).frequency.hz, [1000.0, 2000.0])


def test_a_negative_magnitude_is_refused_with_line_and_column(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("Frequency [Hz];Magnitude [m/N];Phase [deg]\n10;1e-6;30\n20;-1e-6;30\n30;1e-6;30\n",
                    encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"m.csv, line 3: Magnitude \[m/N\] is '-1e-6'; a magnitude is >= 0"):
        read_csv(path)
    path.write_text("Frequency [Hz];Magnitude [m/N];Phase [deg]\n10;1e-6;30\n20;1e-6;-150\n", encoding="utf-8")
    np.testing.assert_allclose(read_csv(path).data[1, 0, 0], 1e-6 * np.exp(-1j * np.radians(150)))


# -- make demo and the user's assembly file ------------------------------------------------------------


def test_demo_keeps_an_edited_assembly_file_even_with_overwrite(tmp_path, capsys, monkeypatch):
    from substructure.cli import demo_command

    steps = dict(demo_command.DEMO_STEPS)
    monkeypatch.setattr(demo_command, "DEMO_STEPS", [(t, f) for t, f in demo_command.DEMO_STEPS
                                                     if f in (steps["load the built-in assembly"],
                                                              steps["write the assembly file to start from"])])
    built_in = (Path(demo_command.__file__).parent.parent / "data" / "default_assembly.toml").read_text("utf-8")
    status, out, _ = run(capsys, "demo", "--out", tmp_path, "--overwrite")
    assert status == 0 and (tmp_path / "default_assembly.toml").read_text("utf-8") == built_in
    status, out, _ = run(capsys, "demo", "--out", tmp_path, "--overwrite")  # unchanged: written again
    assert status == 0 and not (tmp_path / "default_assembly.new.toml").exists()
    mine = built_in.replace('od = "12 mm"', 'od = "16 mm"', 1) + "# my machine\n"
    (tmp_path / "default_assembly.toml").write_text(mine, encoding="utf-8")
    status, out, _ = run(capsys, "demo", "--out", tmp_path, "--overwrite")
    assert status == 0
    assert (tmp_path / "default_assembly.toml").read_text("utf-8") == mine
    assert (tmp_path / "default_assembly.new.toml").read_text("utf-8") == built_in
    assert "default_assembly.toml differs from the built-in assembly file (your edits?): kept" in out
    assert f"wrote {tmp_path / 'default_assembly.new.toml'}" in out
    status, out, _ = run(capsys, "demo", "--out", tmp_path, "--overwrite", "--json")
    import json

    assert json.loads(out)["kept"] == [str(tmp_path / "default_assembly.toml")]


# -- random headers and bytes at the readers -----------------------------------------------------------

_HEADER_WORDS = st.sampled_from(["frequency", "frequency_hz", "freq", "f", "real", "re", "imag", "im",
                                 "magnitude", "mag", "phase", "coherence", "dB", "Hz", "", " "])
_UNITS = st.sampled_from(["", " [Hz]", " [kHz]", " [m/N]", " (mm/N)", " [deg]", " [rad]", " [g/N]", " [dB]",
                          " [s²]", " [\ufffd]", " [", " ]", " (m/s^2)/N", " [1/0]", " [kg]", " [rpm]"])
_CELLS = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                   st.sampled_from(["", "x", "1,5", "-0", "1e999", "nan", "\"1\"", "1;2"]),
                   st.text(max_size=6))
_ROW = st.lists(_CELLS, min_size=0, max_size=4)
_SEP = st.sampled_from([",", ";", "\t"])


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(header=st.lists(st.tuples(_HEADER_WORDS, _UNITS), min_size=0, max_size=4), sep=_SEP,
       rows=st.lists(_ROW, max_size=6), junk=st.binary(max_size=64))
def test_random_csv_headers_and_bytes_give_only_the_projects_errors(tmp_path, header, sep, rows, junk):
    from substructure.stability import ModalModel
    from substructure.study.reader import read_combinations_csv
    from substructure.surrogate import JointTable

    path = tmp_path / "r.csv"
    text = sep.join(n + u for n, u in header) + "\n" + "".join(sep.join(r) + "\n" for r in rows)
    readers = (lambda p: read_csv(p), lambda p: read_csv(p, quantity="mobility"), ModalModel.from_csv,
               JointTable.from_csv, read_combinations_csv)
    for content in (text.encode("utf-8"), junk, text.encode("utf-8") + junk):
        path.write_bytes(content)
        for read in readers:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    read(path)
                except SubstructureError:
                    pass


_TOML_PIECES = st.sampled_from(["[", "]", "{", "}", "=", "\"", "'", "a", "name", "[[frf]]", "[[components]]",
                                "\n", " ", "1", "\"1 mm\"", ",", "#", "\\", "1e999", "nan", "true", "x.y",
                                "response", "file", "segments", "type", "\"beam\"", "[grid]"])


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(pieces=st.lists(_TOML_PIECES, max_size=40), junk=st.binary(max_size=48), depth=st.integers(0, 3000))
def test_random_toml_and_bytes_give_only_the_projects_errors(tmp_path, pieces, junk, depth):
    from substructure.stability import load_workpieces
    from substructure.study.reader import loads_study
    from substructure.surrogate import JointTable

    path = tmp_path / "r.toml"
    text = "".join(pieces) + ("\nz = " + "[" * depth + "]" * depth if depth > 500 else "")
    for content in (text.encode("utf-8"), junk):
        path.write_bytes(content)
        for read in (load_assembly, load_measurements, load_workpieces, JointTable.from_toml,
                     lambda p: loads_study(read_text(p), source=str(p), base=tmp_path)):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    read(path)
                except SubstructureError:
                    pass
