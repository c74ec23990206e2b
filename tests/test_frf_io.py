"""Tests of substructure.io.frf_files: CSV and UFF type-58 files of FRFs."""

from __future__ import annotations

import os

import numpy as np
import pyuff
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from substructure.errors import FileFormatError, InvalidValueError
from substructure.frf import FRF, Frequency
from substructure.io.frf_files import read_csv, read_csv_with_coherence, read_uff, write_csv, write_uff

# pyuff's ASCII writer keeps 12 significant digits (E20.11): 5e-12 relative per part.
UFF_RTOL = 5e-12


def random_frf(n_out=1, n_in=1, seed=0, frequency=None, labels=None, quantity="receptance"):
    rng = np.random.default_rng(seed)
    f = frequency or Frequency.from_range("20 Hz", "200 Hz", "0.5 Hz")
    shape = (f.n, n_out, n_in)
    data = (rng.normal(size=shape) + 1j * rng.normal(size=shape)) * 10.0 ** rng.uniform(-9, -5, shape)
    outputs, inputs = labels or ([f"out{i}:y" for i in range(n_out)], [f"in{j}:y" for j in range(n_in)])
    return FRF(f, data, outputs, inputs, quantity)


def assert_close_parts(actual, expected, rtol=UFF_RTOL):
    np.testing.assert_allclose(actual.real, expected.real, rtol=rtol, atol=0)
    np.testing.assert_allclose(actual.imag, expected.imag, rtol=rtol, atol=0)


# -- CSV ----------------------------------------------------------------------------------------


def test_csv_round_trip_is_exact(tmp_path):
    frf = random_frf(frequency=Frequency.from_range("20 Hz", "30 Hz", "0.1 Hz"))
    path = tmp_path / "tip.csv"
    frf.to_csv(path)
    assert path.read_text().splitlines()[0] == "frequency_hz,real,imag"
    back = FRF.from_csv(path, output="out0:y", input="in0:y")
    assert back == frf
    other = read_csv(str(path), output="tool.tip:y", input="tool.tip:theta", quantity="mobility")
    assert other.outputs == ("tool.tip:y",) and other.inputs == ("tool.tip:theta",)
    assert other.quantity == "mobility"
    np.testing.assert_array_equal(other.data, frf.data)


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@settings(max_examples=40, deadline=None)
@given(
    values=st.lists(st.tuples(finite, finite), min_size=2, max_size=20),
    hz=st.lists(st.floats(0, 1e5, allow_nan=False), min_size=2, max_size=20, unique=True),
)
def test_csv_round_trip_of_arbitrary_floats(tmp_path_factory, values, hz):
    n = min(len(values), len(hz))
    assume(any(r or i for r, i in values[:n]))  # all zero: a dead channel, refused (test_dead_channel_...)
    frequency = Frequency.from_hz(np.sort(hz[:n]))
    frf = FRF.single(frequency, [complex(r, i) for r, i in values[:n]])
    path = tmp_path_factory.mktemp("csv") / "frf.csv"
    write_csv(frf, path)
    assert read_csv(path) == frf


def test_write_csv_requires_one_entry(tmp_path):
    frf = random_frf(2, 2)
    with pytest.raises(InvalidValueError, match=r"2x2 entries.*select one entry.*frf\['out0:y', 'in0:y'\]"):
        write_csv(frf, tmp_path / "x.csv")
    assert not (tmp_path / "x.csv").exists()


GOOD = "frequency_hz,real,imag\n10,1e-6,-2e-7\n20,2e-6,-3e-7\n30,1e-6,-1e-7\n"


@pytest.mark.parametrize(
    "content, match",
    [
        ("freq,re,im\n10,1,2\n20,1,2\n", r"line 1: column 'freq' has no unit; name it frequency_hz or give the unit"),
        ("", "empty"),
        (GOOD.replace("20,2e-6", "20,abc"), r"line 3: real is 'abc'; expected a number"),
        (GOOD.replace("-3e-7", ""), r"line 3: imag is ''; expected a number"),
        (GOOD.replace("20,2e-6,-3e-7", "20,2e-6"), r"line 3: '20,2e-6' has 2 value\(s\); expected 3"),
        (GOOD.replace("2e-6", "nan"), r"line 3: real is nan; expected a finite number"),
        (GOOD.replace("-1e-7", "inf"), r"line 4: imag is inf; expected a finite number"),
        (GOOD.replace("30,", "15,"), r"line 4: frequency 15.0 Hz does not exceed 20.0 Hz of line 3"),
        (GOOD.replace("30,", "20,"), r"line 4: frequency 20.0 Hz does not exceed 20.0 Hz .*without repeats"),
        (GOOD.replace("10,", "-10,"), r"line 2: frequency -10.0 Hz is negative"),
        ("frequency_hz,real,imag\n10,1e-6,-2e-7\n", r"1 data row\(s\); an FRF needs at least 2"),
    ],
)
def test_csv_errors_name_the_file_and_line(tmp_path, content, match):
    path = tmp_path / "measured_tip.csv"
    path.write_text(content)
    with pytest.raises(FileFormatError, match=match) as info:
        read_csv(path)
    assert str(info.value).startswith(str(path))


def test_csv_missing_file(tmp_path):
    path = tmp_path / "nowhere.csv"
    with pytest.raises(FileFormatError, match="no such file") as info:
        read_csv(path)
    assert str(path) in str(info.value)


def test_csv_tolerates_blank_lines_and_byte_order_mark(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_text("\ufeff" + GOOD.replace("\n20", "\n\n20") + "\n\n", encoding="utf-8")
    frf = read_csv(path)
    np.testing.assert_array_equal(frf.frequency.hz, [10.0, 20.0, 30.0])
    np.testing.assert_array_equal(frf.data[:, 0, 0], [1e-6 - 2e-7j, 2e-6 - 3e-7j, 1e-6 - 1e-7j])
    # line numbers count the blank lines
    path.write_text(GOOD.replace("\n20,2e-6", "\n\n20,x"))
    with pytest.raises(FileFormatError, match="line 4: real is 'x'"):
        read_csv(path)


# -- UFF -----------------------------------------------------------------------------------------


def test_uff_round_trip_single(tmp_path):
    frf = random_frf(labels=(["tool.tip:y"], ["tool.tip:y"]))
    path = tmp_path / "tip.uff"
    frf.to_uff(path)
    assert path.stat().st_size > 0
    back = FRF.from_uff(path)
    assert back.frequency == frf.frequency  # the exact grid comes back
    assert (back.outputs, back.inputs, back.quantity) == (frf.outputs, frf.inputs, frf.quantity)
    assert_close_parts(back.data, frf.data)
    # the precision is pyuff's 12 digits, not full double precision
    assert not np.array_equal(back.data, frf.data)


def test_uff_round_trip_matrix_with_rotations(tmp_path):
    labels = ["tool.tip:y", "tool.tip:theta", "tool.tip-15 mm:y"]
    frf = random_frf(3, 2, seed=4, labels=(labels, labels[:2]), quantity="accelerance")
    path = tmp_path / "matrix.unv"
    write_uff(frf, path)
    uff = pyuff.UFF(str(path))
    assert list(uff.get_set_types()) == [58] * 6
    first, second = uff.read_sets([0, 1])
    assert (first["rsp_dir"], first["ref_dir"], second["ref_dir"]) == (2, 2, 6)
    assert first["func_type"] == 4 and first["ordinate_spec_data_type"] == 12
    back = read_uff(path)
    assert (back.outputs, back.inputs, back.quantity) == (frf.outputs, frf.inputs, "accelerance")
    assert back.frequency == frf.frequency
    assert_close_parts(back.data, frf.data)


def test_read_uff_record_index(tmp_path):
    labels = (["a:y", "a:theta"], ["a:y", "b:y"])
    frf = random_frf(2, 2, seed=5, labels=labels)
    path = tmp_path / "m.uff"
    write_uff(frf, path)
    third = read_uff(path, record=2)  # records go output by output, input by input
    assert third.outputs == ("a:theta",) and third.inputs == ("a:y",)
    assert_close_parts(third.data[:, 0, 0], frf.data[:, 1, 0])
    assert FRF.from_uff(path, record=3).inputs == ("b:y",)
    with pytest.raises(InvalidValueError, match=r"record: got 4; .*m.uff has 4 type-58 record\(s\), indices 0..3"):
        read_uff(path, record=4)
    with pytest.raises(InvalidValueError, match="record: got '1'"):
        read_uff(path, record="1")


def test_write_uff_replaces_an_existing_file(tmp_path):
    path = tmp_path / "tip.uff"
    write_uff(random_frf(2, 2, seed=1), path)
    small = random_frf(seed=2, frequency=Frequency.from_range("100 Hz", "110 Hz", "2 Hz"))
    write_uff(small, path, overwrite=True)
    assert list(pyuff.UFF(str(path)).get_set_types()) == [58]
    back = read_uff(path)
    assert back.frequency == small.frequency
    assert_close_parts(back.data, small.data)
    assert os.listdir(tmp_path) == ["tip.uff"]  # no temporary file left behind


def test_uff_keeps_a_step_with_more_digits_than_the_header(tmp_path):
    # 5000 Hz / 4096 lines: the E13.5 header alone would give 1.22070 Hz
    grid = Frequency.from_range("0 Hz", "5000 Hz", "1.220703125 Hz")
    frf = random_frf(frequency=grid)
    path = tmp_path / "analyzer.uff"
    write_uff(frf, path)
    assert pyuff.UFF(str(path)).read_sets(0)["abscissa_inc"] == 1.2207
    back = read_uff(path)
    assert back.frequency == grid
    assert_close_parts(back.data, frf.data)


def test_uff_non_uniform_grids(tmp_path):
    path = tmp_path / "nonuniform.uff"
    # frequencies with at most 6 significant digits are kept exactly
    grid = Frequency.from_hz([10.0, 12.5, 20.0, 31.25, 1234.56, 2000.0])
    frf = random_frf(frequency=grid)
    write_uff(frf, path)
    back = read_uff(path)
    assert back.frequency == grid
    assert_close_parts(back.data, frf.data)
    # more digits than UFF keeps: refused with advice
    fine = random_frf(frequency=Frequency.from_hz([10.0, 12.5, 20.0, 31.234567]))
    with pytest.raises(InvalidValueError, match="6 significant digits.*interpolate"):
        write_uff(fine, path)
    assert read_uff(path).frequency == grid  # the old file is untouched


def test_uff_nearly_uniform_grid_comes_back_within_rounding(tmp_path):
    grid = Frequency.from_hz(np.linspace(0.0, 1000.0, 3001))  # step 1/3 Hz
    frf = random_frf(frequency=grid)
    path = tmp_path / "third.uff"
    write_uff(frf, path)
    back = read_uff(path)
    np.testing.assert_allclose(back.frequency.hz, grid.hz, rtol=0, atol=1e-12 * 1000.0)
    assert_close_parts(back.data, frf.data)


def test_read_uff_of_another_program(tmp_path):
    path = tmp_path / "foreign.uff"
    x = 5.0 + 0.25 * np.arange(40)
    data = np.exp(1j * x) * 1e-6
    common = dict(func_type=4, rsp_node=7, ref_node=3, abscissa_spacing=1, x=x,
                  ordinate_spec_data_type=11, orddenom_spec_data_type=13)
    sets = [pyuff.prepare_58(id1="hammer test", rsp_dir=2, ref_dir=2, data=data, **common),
            pyuff.prepare_58(id1="hammer test", rsp_dir=6, ref_dir=2, data=2 * data, **common)]
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    frf = read_uff(path)
    assert frf.outputs == ("node7:y", "node7:theta") and frf.inputs == ("node3:y",)
    assert frf.quantity == "mobility"
    np.testing.assert_array_equal(frf.frequency.hz, x)
    assert_close_parts(frf.data[:, 1, 0], 2 * data)
    assert read_uff(path, record=0, quantity="mobility").quantity == "mobility"
    # a quantity that contradicts the record's data type (11, velocity) is refused, not taken
    with pytest.raises(FileFormatError, match="quantity given is receptance, but its data type says mobility"):
        read_uff(path, record=0, quantity="receptance")


def test_read_uff_refuses_records_on_different_grids(tmp_path):
    path = tmp_path / "mixed.uff"
    one = random_frf(frequency=Frequency.from_range("10 Hz", "20 Hz", "1 Hz"), labels=(["a:y"], ["a:y"]))
    two = random_frf(frequency=Frequency.from_range("10 Hz", "20 Hz", "2 Hz"), labels=(["b:y"], ["a:y"]))
    write_uff(one, path)
    pyuff.UFF(str(path)).write_sets(
        pyuff.prepare_58(func_type=4, id1="response=b:y", id2="excitation=a:y", rsp_node=2, rsp_dir=2,
                         ref_node=1, ref_dir=2, abscissa_spacing=1, ordinate_spec_data_type=8,
                         orddenom_spec_data_type=13, data=two.data[:, 0, 0],
                         x=np.array(two.frequency.hz)),
        mode="add",
    )
    with pytest.raises(FileFormatError, match=r"mixed.uff: type-58 records 0 and 1 have different frequency grids"):
        read_uff(path)
    assert read_uff(path, record=1).frequency == two.frequency


def test_read_uff_errors_name_the_file(tmp_path):
    missing = tmp_path / "missing.uff"
    with pytest.raises(FileFormatError, match="missing.uff: no such file"):
        read_uff(missing)
    empty = tmp_path / "empty.uff"
    empty.write_text("")
    with pytest.raises(FileFormatError, match="empty.uff: the file is empty; no type-58 record"):
        read_uff(empty)
    incomplete = tmp_path / "incomplete.uff"
    write_uff(random_frf(2, 2, seed=3), incomplete)
    sets = pyuff.UFF(str(incomplete)).read_sets([0, 1, 2])
    pyuff.UFF(str(tmp_path / "three.uff")).write_sets(sets, mode="add")
    with pytest.raises(FileFormatError, match=r"three.uff: the records do not form a full matrix"):
        read_uff(tmp_path / "three.uff")
    pyuff.UFF(str(tmp_path / "twice.uff")).write_sets([sets[0], sets[1], sets[0]], mode="add")
    with pytest.raises(FileFormatError, match=r"twice.uff: type-58 records 0 and 2 both hold \('out0:y', 'in0:y'\)"):
        read_uff(tmp_path / "twice.uff")


def test_write_uff_input_errors(tmp_path):
    one_line = FRF.single(Frequency.from_hz([10.0]), [1e-6])
    with pytest.raises(InvalidValueError, match="at least 2 frequency lines"):
        write_uff(one_line, tmp_path / "a.uff")
    long_label = "x" * 80 + ":y"
    with pytest.raises(InvalidValueError, match="at most 80 characters"):
        write_uff(random_frf(labels=([long_label], ["a:y"])), tmp_path / "a.uff")
    with pytest.raises(InvalidValueError, match="expected an FRF"):
        write_uff(np.ones(3), tmp_path / "a.uff")
    assert not (tmp_path / "a.uff").exists()
    with pytest.raises(FileFormatError, match="no_such_dir"):
        write_uff(random_frf(), tmp_path / "no_such_dir" / "a.uff")


def test_an_frf_saved_by_numpy_savetxt_with_its_header_reads_back(tmp_path):
    """``numpy.savetxt(..., header=...)`` writes the header as a comment ('# frequency_hz,real,imag') and, by
    default, separates the columns by blanks: the comment right above the rows is the header when the file reads
    with it, and blank-separated columns are read as the rows show them; a comment that is not a header (the
    window's line) leaves the file without one, refused as before."""
    f = np.linspace(20.0, 5000.0, 50)
    h = 1e-7 / (1 - (f / 1000.0) ** 2 + 0.05j * f / 1000.0)
    table = np.column_stack([f, h.real, h.imag])
    for case, kw in [("commas", dict(header="frequency_hz,real,imag", delimiter=",")),
                     ("units", dict(header="Frequency [Hz];Real [mm/N];Imag [mm/N]", delimiter=";")),
                     ("blanks", dict(header="frequency_hz real imag")),
                     ("blank units", dict(header="Frequency [Hz]  Real [m/N]  Imag [m/N]"))]:
        path = tmp_path / f"{case.replace(' ', '_')}.csv"
        np.savetxt(path, table * ([1.0, 1e3, 1e3] if case == "units" else 1.0), **kw)
        frf = read_csv(path)
        np.testing.assert_allclose(frf.frequency.hz, f, rtol=1e-15)
        np.testing.assert_allclose(frf.data[:, 0, 0], h, rtol=1e-14, err_msg=case)
    path = tmp_path / "window.csv"
    path.write_text("# window_tau_s = 0.04\n20,1e-7,0\n30,1e-7,0\n")
    with pytest.raises(FileFormatError, match=r"window.csv, line 2: column '20'; expected frequency"):
        read_csv(path)


@pytest.mark.parametrize("quantity, header", [
    ("receptance", "frequency_hz,real,imag"),
    ("mobility", "frequency_hz,real [m/(N s)],imag [m/(N s)]"),
    ("accelerance", "frequency_hz,real [m/(N s^2)],imag [m/(N s^2)]"),
])
def test_csv_keeps_the_quantity(tmp_path, quantity, header):
    """A mobility or an accelerance is written with its unit in the header and reads back as what it is."""
    grid = Frequency.from_range("100 Hz", "3000 Hz", "10 Hz")
    h = 1 / (1e7 * (1 - (grid.hz / 1000) ** 2 + 0.05j * grid.hz / 1000))
    factor = {"receptance": 1, "mobility": 1j * grid.omega, "accelerance": -grid.omega**2}[quantity]
    frf = FRF.single(grid, h * factor, output="tool.tip:y", input="tool.tip:y", quantity=quantity)
    path = tmp_path / "tip.csv"
    frf.to_csv(path)
    assert path.read_text().splitlines()[0] == header
    back = FRF.from_csv(path, output="tool.tip:y", input="tool.tip:y")
    assert back == frf and back.quantity == quantity
    assert read_csv(path, output="tool.tip:y", input="tool.tip:y", quantity=quantity) == frf
    np.testing.assert_allclose(back.to_receptance().data[:, 0, 0], h, rtol=1e-12)


def test_csv_quantity_of_a_rotation_and_with_the_coherence(tmp_path):
    grid = Frequency.from_range("100 Hz", "300 Hz", "10 Hz")
    frf = FRF.single(grid, np.linspace(1, 2, grid.n) * (1 - 1j), output="tool.tip:theta", input="tool.tip:theta",
                     quantity="accelerance")
    gamma = np.linspace(0.5, 1, grid.n)
    write_csv(frf, tmp_path / "r.csv", coherence=gamma)
    assert (tmp_path / "r.csv").read_text().splitlines()[0] == \
        "frequency_hz,real [1/(N m s^2)],imag [1/(N m s^2)],coherence"
    back, coherence = read_csv_with_coherence(tmp_path / "r.csv", output="tool.tip:theta", input="tool.tip:theta")
    assert back == frf
    np.testing.assert_array_equal(coherence, gamma)


def test_csv_units_in_the_header_that_contradict_the_quantity_given(tmp_path):
    grid = Frequency.from_range("100 Hz", "300 Hz", "10 Hz")
    frf = FRF.single(grid, np.linspace(1, 2, grid.n) + 1j, quantity="accelerance")
    frf.to_csv(tmp_path / "a.csv")
    with pytest.raises(FileFormatError, match=r"a\.csv, line 1: the header's units are those of an accelerance, "
                                              r"but the quantity given is receptance"):
        read_csv(tmp_path / "a.csv", quantity="receptance")
    text = (tmp_path / "a.csv").read_text().replace("imag [m/(N s^2)]", "imag [m/N]")
    (tmp_path / "b.csv").write_text(text)
    with pytest.raises(FileFormatError, match=r"b\.csv, line 1: the real and imaginary parts have different units"):
        read_csv(tmp_path / "b.csv")
    (tmp_path / "c.csv").write_text(text.replace("[m/(N s^2)]", "[kg]").replace("[m/N]", "[kg]"))
    with pytest.raises(FileFormatError, match=r"c\.csv, line 1: column 'real \[kg\]': the unit 'kg' is not that of"):
        read_csv(tmp_path / "c.csv")
    mm = (tmp_path / "a.csv").read_text().replace("m/(N s^2)", "mm/(N s^2)")  # not SI: converted
    (tmp_path / "d.csv").write_text(mm)
    np.testing.assert_allclose(read_csv(tmp_path / "d.csv").data, frf.data * 1e-3, rtol=1e-15)


@pytest.mark.parametrize("write", [
    lambda frf, path, **kw: frf.to_csv(path, **kw), lambda frf, path, **kw: write_csv(frf, path, **kw),
    lambda frf, path, **kw: frf.to_uff(path, **kw), lambda frf, path, **kw: write_uff(frf, path, **kw),
])
def test_frf_writers_keep_an_existing_file_unless_told(tmp_path, write):
    from substructure.errors import OutputExistsError

    path = tmp_path / "tip.data"
    path.write_text("the user's file\n")
    with pytest.raises(OutputExistsError, match=rf"{path}: the file exists; pass overwrite=True to replace it"):
        write(random_frf(), path)
    assert path.read_text() == "the user's file\n"
    assert isinstance(OutputExistsError("x"), FileExistsError)
    write(random_frf(), path, overwrite=True)
    assert path.read_text() != "the user's file\n"


def test_labels_are_checked_where_an_frf_is_made(tmp_path):
    grid = Frequency.from_range("100 Hz", "200 Hz", "10 Hz")
    for field, label, why in [("output", "tool tip", "not a point name"),
                              ("input", "tool.tip", "a point without its DOF"),
                              ("output", "a.tip:z", "unknown DOF 'z'"), ("input", "tool tip:y", "'tool tip' is not")]:
        kwargs = {"output": "tool.tip:y", "input": "tool.tip:y", field: label}
        with pytest.raises(InvalidValueError, match=rf"^{field}: got the label '{label}' \({why}.*expected 'POINT:y' "
                                                    r"or 'POINT:theta'"):
            FRF.single(grid, np.ones(grid.n), **kwargs)
    with pytest.raises(InvalidValueError, match=r"outputs: got the label 'tool\.tip'"):
        FRF(grid, np.ones((grid.n, 1, 1)), ("tool.tip",), ("tool.tip:y",))
    FRF.single(grid, np.ones(grid.n)).to_csv(tmp_path / "a.csv")
    with pytest.raises(InvalidValueError, match=r"^output: got the label 'tool tip'"):
        FRF.from_csv(tmp_path / "a.csv", output="tool tip")
    for label in ("tool.tip-5 mm:theta", "spindle@310 mm:y", "a:y", "x", "response"):  # points, plain names
        assert FRF.single(grid, np.ones(grid.n), output=label, input=label).outputs == (label,)
