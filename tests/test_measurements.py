"""Tests of measurement sets: substructure.measurements and substructure.io.measurements."""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

from substructure import FRF, Frequency, Sensor, Segment, Tool
from substructure.errors import FileFormatError, FrequencyAxisMismatchError, InvalidValueError
from substructure.io.measurements import load_measurements, loads_measurements
from substructure.measurements import (
    Measurement,
    MeasurementSet,
    MeasurementSetError,
    MissingMeasurementError,
    dof_label,
)

from conftest import make_assembly

GRID = Frequency.from_range("100 Hz", "2000 Hz", "10 Hz")
POINTS = ("tool.tip", "tool.tip-5 mm", "tool.tip-10 mm")


@pytest.fixture(scope="module")
def model() -> FRF:
    """y-y receptances of a free-free tool at three points: the 'truth' behind the files."""
    tool = Tool("tool", [Segment("80 mm", "12 mm", material="carbide")])
    frf = tool.receptance(GRID, list(POINTS))
    labels = [f"{p}:y" for p in POINTS]
    return frf.select(labels, labels)


def write(frf: FRF, response: str, excitation: str, path, factor=None) -> None:
    """One entry of ``frf`` to a CSV file, optionally multiplied by ``factor`` (an array over frequency)."""
    entry = frf[f"{response}:y", f"{excitation}:y"]
    if factor is not None:
        entry = FRF.single(entry.frequency, entry.data[:, 0, 0] * factor)
    entry.to_csv(path)


EXAMPLE = """\
name = "bench test, 12 mm tool, 60 mm overhang"

[[frf]]
response = "tool.tip"            # point[:dof], dof y by default
excitation = "tool.tip"
file = "tool_tip__tool_tip.csv"
quantity = "receptance"
sensors = ["accelerometer"]

[[frf]]
response = "holder.tip"
excitation = "holder.tip"
removed = ["tool"]
file = "holder_tip__holder_tip.csv"
"""


def test_example_of_the_file_formats_page(tmp_path, model):
    write(model, "tool.tip", "tool.tip", tmp_path / "tool_tip__tool_tip.csv")
    write(model, "tool.tip-5 mm", "tool.tip-5 mm", tmp_path / "holder_tip__holder_tip.csv")
    (tmp_path / "set.toml").write_text(EXAMPLE)
    ms = load_measurements(tmp_path / "set.toml")
    assert ms.name == "bench test, 12 mm tool, 60 mm overhang"
    assert len(ms) == 2 and ms.frequency == GRID
    first, second = ms.measurements
    assert (first.response, first.excitation) == ("tool.tip:y", "tool.tip:y")
    assert first.sensors == ("accelerometer",) and first.removed == ()
    assert first.file == "tool_tip__tool_tip.csv" and first.record is None
    assert first.quantity == "receptance"
    assert first.frf.outputs == ("tool.tip:y",) and first.frf.inputs == ("tool.tip:y",)
    np.testing.assert_array_equal(first.values, model.entry("tool.tip:y", "tool.tip:y"))
    assert second.removed == ("tool",) and second.sensors == ()
    assert ms.configurations() == ((("accelerometer",), ()), ((), ("tool",)))
    assert ms.select(sensors=["accelerometer"]) == (first,)
    assert ms.select(removed="tool") == (second,)
    assert ms.select() == ()
    assert MeasurementSet.from_file(tmp_path / "set.toml") == ms


def test_paths_are_relative_to_the_measurement_file(tmp_path, model):
    (tmp_path / "campaign" / "data").mkdir(parents=True)
    write(model, "tool.tip", "tool.tip", tmp_path / "campaign" / "data" / "tip.csv")
    (tmp_path / "campaign" / "set.toml").write_text(
        '[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "data/tip.csv"\n'
    )
    ms = load_measurements(tmp_path / "campaign" / "set.toml")
    assert ms.name == "set"  # the file's stem when the file has no name
    assert ms.measurements[0].file == "data/tip.csv"


def test_a_set_written_on_windows_names_its_files_with_backslashes(tmp_path, model):
    # 'data\\tip.csv' was "no such file" on Linux and macOS
    (tmp_path / "campaign" / "data").mkdir(parents=True)
    write(model, "tool.tip", "tool.tip", tmp_path / "campaign" / "data" / "tip.csv")
    path = tmp_path / "campaign" / "set.toml"
    path.write_text("[[frf]]\nresponse = 'tool.tip'\nexcitation = 'tool.tip'\nfile = 'data\\tip.csv'\n")
    (m,) = load_measurements(path).measurements
    assert m.file == "data\\tip.csv"  # kept as written
    np.testing.assert_array_equal(m.values, model.entry("tool.tip:y", "tool.tip:y"))
    path.write_text("[[frf]]\nresponse = 'tool.tip'\nexcitation = 'tool.tip'\nfile = 'C:\\data\\tip.csv'\n")
    with pytest.raises(FileFormatError, match=r"set.toml, line 4: frf\[0\]\.file: .*C:\\data\\tip.csv: no such file"):
        load_measurements(path)  # another machine's disk is not looked for here


@pytest.mark.parametrize("quantity, factor", [("mobility", lambda w: 1j * w), ("accelerance", lambda w: -(w**2))])
def test_mobility_and_accelerance_are_converted_on_read(tmp_path, model, quantity, factor):
    write(model, "tool.tip", "tool.tip-5 mm", tmp_path / "m.csv", factor=factor(GRID.omega))
    text = f'[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip-5 mm"\nfile = "m.csv"\nquantity = "{quantity}"\n'
    ms = loads_measurements(text, tmp_path, "set.toml")
    m = ms.measurements[0]
    assert m.quantity == quantity and m.frf.quantity == "receptance"
    np.testing.assert_allclose(m.values, model.entry("tool.tip:y", "tool.tip-5 mm:y"), rtol=1e-13)


def test_uff_records(tmp_path, model):
    labels = [f"{p}:y" for p in POINTS[:2]]
    model.select(labels, labels).to_uff(tmp_path / "all.uff")  # records: 00, 01, 10, 11
    accelerance = FRF.single(GRID, model.entry("tool.tip:y", "tool.tip:y") * -(GRID.omega**2),
                             "tool.tip:y", "tool.tip:y", quantity="accelerance")
    accelerance.to_uff(tmp_path / "acc.uff")
    text = """
[[frf]]
response = "tool.tip-5 mm"
excitation = "tool.tip"
file = "all.uff"
record = 2

[[frf]]
response = "tool.tip"
excitation = "tool.tip"
file = "acc.uff"          # one record: no index needed; the record says it is an accelerance
"""
    ms = loads_measurements(text, tmp_path, "set.toml")
    cross, point = ms.measurements
    assert cross.record == 2 and cross.response == "tool.tip-5 mm:y"
    np.testing.assert_allclose(cross.values, model.entry("tool.tip-5 mm:y", "tool.tip:y"), rtol=1e-11)
    assert point.quantity == "accelerance" and point.record is None
    np.testing.assert_allclose(point.values, model.entry("tool.tip:y", "tool.tip:y"), rtol=1e-11)


def test_uff_errors_name_the_record(tmp_path, model):
    labels = [f"{p}:y" for p in POINTS[:2]]
    model.select(labels, labels).to_uff(tmp_path / "all.uff")
    base = '[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "all.uff"\n'
    with pytest.raises(FileFormatError, match=r"set\.toml.*frf\[0\]\.record: missing.*4 type-58 records"):
        loads_measurements(base, tmp_path, "set.toml")
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.record: .*all\.uff.*indices 0\.\.3"):
        loads_measurements(base + "record = 7\n", tmp_path, "set.toml")
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.record: .*record 1 holds response tool\.tip:y / "
                                              r"excitation tool\.tip-5 mm:y.*0-based"):
        loads_measurements(base + "record = 1\n", tmp_path, "set.toml")
    with pytest.raises(FileFormatError, match=r"line 5: frf\[0\]\.record: got -1; expected the 0-based index"):
        loads_measurements(base + "record = -1\n", tmp_path, "set.toml")


def error_of(tmp_path, text: str) -> str:
    (tmp_path / "set.toml").write_text(text)
    with pytest.raises(FileFormatError) as info:
        load_measurements(tmp_path / "set.toml")
    message = str(info.value)
    assert message.startswith(str(tmp_path / "set.toml"))
    return message


GOOD = '[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "tip.csv"\n'


@pytest.fixture
def tip_file(tmp_path, model):
    write(model, "tool.tip", "tool.tip", tmp_path / "tip.csv")
    return tmp_path / "tip.csv"


@pytest.mark.parametrize(
    "text, pattern",
    [
        ('colour = "red"\n' + GOOD, r"line 1: colour: unknown key; allowed keys: name, frf"),
        (GOOD + "colour = 3\n", r"line 5: frf\[0\]\.colour: unknown key; allowed keys: response, excitation, "
                                r"file, record, quantity, sensors, removed"),
        ('[[frf]]\nresponse = "tool.tip"\nfile = "tip.csv"\n', r"line 1: frf\[0\]\.excitation: missing"),
        (GOOD + GOOD.replace('file = "tip.csv"\n', ""), r"line 5: frf\[1\]\.file: missing"),
        ('name = "x"\n', r"frf: missing; a measurement set needs at least one \[\[frf\]\]"),
        (GOOD + 'quantity = "displacement"\n',
         r"line 5: frf\[0\]\.quantity: got 'displacement'; expected one of receptance, mobility, accelerance"),
        (GOOD.replace('"tool.tip"', '"tooltip"', 1), r"line 2: frf\[0\]\.response: .*'tooltip'"),
        (GOOD.replace('"tool.tip"\n', '"tool.tip:z"\n', 1), r"frf\[0\]\.response: .*unknown DOF 'z'"),
        (GOOD + 'sensors = "accelerometer"\n', r"line 5: frf\[0\]\.sensors: .*expected an array"),
        (GOOD + 'removed = ["tool", "tool"]\n', r"frf\[0\]\.removed: 'tool' given more than once"),
        (GOOD + "record = 1\n", r"frf\[0\]\.record: a CSV file \(tip\.csv\) holds one FRF"),
        (GOOD + "window_tau_s = -0.2\n", r"line 5: frf\[0\]\.window_tau_s: got -0\.2; expected the exponential "
                                        r"window's time constant in s"),
        (GOOD + 'window_tau_s = "0.2 s"\n', r"line 5: frf\[0\]\.window_tau_s: got '0\.2 s'"),
        (GOOD + "window_tau_s = nan\n", r"line 5: frf\[0\]\.window_tau_s: got nan"),
        (GOOD + 'estimator = "H3"\n', r"line 5: frf\[0\]\.estimator: got 'H3'; expected one of H1, H2, Hv"),
        (GOOD + "estimator = 2\n", r"line 5: frf\[0\]\.estimator: got 2; expected one of H1, H2, Hv"),
        (GOOD.replace("tip.csv", "tip.txt"), r"frf\[0\]\.file: 'tip\.txt': unknown kind of file"),
        (GOOD + GOOD, r"line 5: frf\[1\]: measures tool\.tip:y / tool\.tip:y in the same configuration as frf\[0\]"),
        ("name = [", r"invalid TOML"),
    ],
)
def test_file_errors_name_file_line_and_key(tmp_path, tip_file, text, pattern):
    assert re.search(pattern, error_of(tmp_path, text))


def test_a_window_s_time_constant_reads_into_the_measurement(tmp_path, tip_file):
    path = tmp_path / "set.toml"
    path.write_text(GOOD + "window_tau_s = 0.25\n")
    (m,) = load_measurements(path).measurements
    assert m.window_tau == 0.25 and m.crop(100, 200).window_tau == 0.25
    path.write_text(GOOD)
    assert load_measurements(path).measurements[0].window_tau is None
    with pytest.raises(InvalidValueError, match="window_tau: got 0; expected the exponential window's time constant"):
        Measurement.from_frf(m.frf, "tool.tip", "tool.tip", window_tau=0)


def test_the_estimator_reads_into_the_measurement(tmp_path, tip_file):
    path = tmp_path / "set.toml"
    path.write_text(GOOD + 'estimator = "H2"\n')
    (m,) = load_measurements(path).measurements
    assert m.estimator == "H2" and m.crop(100, 200).estimator == "H2"
    assert m.h1_frf is m.frf  # no coherence column: nothing to make it the H1 of its taps with
    path.write_text(GOOD)
    assert load_measurements(path).measurements[0].estimator is None


def test_the_hammer_noise_column_and_its_window_read_into_the_measurement(tmp_path, model):
    from substructure.io.frf_files import write_csv

    frf = model.select(["tool.tip:y"], ["tool.tip:y"]).crop(100, 400)
    n = frf.frequency.n
    noise = np.linspace(1e-8, 4e-8, n)
    noise[-1] = np.inf  # a line without force
    write_csv(frf, tmp_path / "tip.csv", coherence=np.full(n, 0.99), force_noise=noise)
    assert (tmp_path / "tip.csv").read_text().splitlines()[0] == "frequency_hz,real,imag,coherence,force_noise"
    path = tmp_path / "set.toml"
    path.write_text(GOOD + "force_window_s = 0.001\n")
    (m,) = load_measurements(path).measurements
    assert np.array_equal(m.force_noise, noise) and m.force_window_s == 0.001
    cropped = m.crop(150, 200)
    assert np.array_equal(cropped.force_noise, noise[5:11]) and cropped.force_window_s == 0.001
    # the column needs its window; a negative variance is refused naming its line
    path.write_text(GOOD)
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.force_window_s: missing; tip.csv has a force_noise column"):
        load_measurements(path)
    lines = (tmp_path / "tip.csv").read_text().splitlines()
    lines[3] = lines[3].rsplit(",", 1)[0] + ",-1e-8"
    (tmp_path / "tip.csv").write_text("\n".join(lines) + "\n")
    path.write_text(GOOD + "force_window_s = 0.001\n")
    with pytest.raises(FileFormatError, match=r"tip.csv, line 4: force_noise is -1e-08; expected a variance >= 0"):
        load_measurements(path)
    path.write_text(GOOD + "force_window_s = 0\n")
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.force_window_s: got 0; expected the force window's length"):
        load_measurements(path)
    with pytest.raises(InvalidValueError, match="force_window_s: needed with force_noise"):
        Measurement.from_frf(frf, "tool.tip", "tool.tip", force_noise=noise)
    with pytest.raises(InvalidValueError, match="force_noise: got 3 values for 31 frequency lines"):
        Measurement.from_frf(frf, "tool.tip", "tool.tip", force_noise=[0.0] * 3, force_window_s=0.001)
    with pytest.raises(InvalidValueError, match="force_noise: line 0 is nan; expected a variance >= 0"):
        Measurement.from_frf(frf, "tool.tip", "tool.tip", force_noise=[np.nan] * n, force_window_s=0.001)

def test_missing_data_file(tmp_path):
    message = error_of(tmp_path, GOOD.replace("tip.csv", "nowhere.csv"))
    assert "frf[0].file" in message and str(tmp_path / "nowhere.csv") in message and "no such file" in message


def test_missing_measurement_file(tmp_path):
    with pytest.raises(FileFormatError, match="no such file"):
        load_measurements(tmp_path / "absent.toml")


def test_nan_in_a_data_file(tmp_path, tip_file):
    lines = tip_file.read_text().splitlines()
    lines[3] = "120.0,nan,1e-9"
    tip_file.write_text("\n".join(lines) + "\n")
    message = error_of(tmp_path, GOOD)
    assert re.search(r"line 4: frf\[0\]\.file: .*tip\.csv, line 4: real is nan; expected a finite number", message)


def test_non_increasing_axis_in_a_data_file(tmp_path, tip_file):
    lines = tip_file.read_text().splitlines()
    lines[3], lines[4] = lines[4], lines[3]
    tip_file.write_text("\n".join(lines) + "\n")
    message = error_of(tmp_path, GOOD)
    assert "frf[0].file" in message and "tip.csv, line 5" in message and "strictly increasing" in message


def test_mismatched_grids_name_both_files(tmp_path, model, tip_file):
    coarse = model.interpolate(Frequency.from_range("100 Hz", "2000 Hz", "20 Hz"))
    write(coarse, "tool.tip-5 mm", "tool.tip", tmp_path / "cross.csv")
    text = GOOD + '[[frf]]\nresponse = "tool.tip-5 mm"\nexcitation = "tool.tip"\nfile = "cross.csv"\n'
    message = error_of(tmp_path, text)
    assert "frf[1].file" in message and "cross.csv" in message and "tip.csv" in message
    assert "different frequency axes" in message and "interpolate" in message


# -- the value objects ------------------------------------------------------------------------


def measurement_set(model, pairs, sensors=(), removed=()) -> MeasurementSet:
    items = [
        Measurement.from_frf(model[f"{r}:y", f"{e}:y"], r, e, sensors=sensors, removed=removed)
        for r, e in pairs
    ]
    return MeasurementSet("synthetic", items)


def test_dof_labels_are_canonical():
    assert dof_label("tool.tip") == "tool.tip:y"
    assert dof_label("tool.tip-5mm") == "tool.tip-5 mm:y"
    assert dof_label("tool@30.0 mm:theta") == "tool@30 mm:theta"


def test_matrix_uses_reciprocity_for_unmeasured_cross_terms(model):
    a, b, c = POINTS
    ms = measurement_set(model, [(a, a), (b, b), (c, c), (a, b), (c, a), (b, c)])
    measured = {(a, a), (b, b), (c, c), (a, b), (c, a), (b, c)}
    frf = ms.matrix(POINTS)
    assert frf.outputs == frf.inputs == tuple(f"{p}:y" for p in POINTS)
    for r in POINTS:
        for e in POINTS:
            source = (r, e) if (r, e) in measured else (e, r)
            expected = model.entry(f"{source[0]}:y", f"{source[1]}:y")
            np.testing.assert_array_equal(frf.entry(f"{r}:y", f"{e}:y"), expected)


def test_matrix_takes_each_measured_entry_as_measured(model):
    a, b = POINTS[:2]
    ms = measurement_set(model, [(a, a), (b, b), (a, b)])
    shifted = Measurement.from_frf(2.0 * model[f"{b}:y", f"{a}:y"], b, a)
    ms = MeasurementSet("x", ms.measurements + (shifted,))
    frf = ms.matrix([a, b])
    np.testing.assert_array_equal(frf.entry(f"{a}:y", f"{b}:y"), model.entry(f"{a}:y", f"{b}:y"))
    np.testing.assert_array_equal(frf.entry(f"{b}:y", f"{a}:y"), 2.0 * model.entry(f"{b}:y", f"{a}:y"))


def test_matrix_lists_exactly_the_missing_frfs(model):
    a, b, c = POINTS
    ms = measurement_set(model, [(a, a), (b, b), (a, b)])
    with pytest.raises(MissingMeasurementError) as info:
        ms.matrix(POINTS)
    assert info.value.missing == ((f"{a}:y", f"{c}:y"), (f"{b}:y", f"{c}:y"), (f"{c}:y", f"{c}:y"))
    assert "needs 3 FRF(s)" in str(info.value) and "(or its reciprocal)" in str(info.value)
    with pytest.raises(MissingMeasurementError) as info:
        ms.matrix([a, b], reciprocity=False)
    assert info.value.missing == ((f"{b}:y", f"{a}:y"),)
    with pytest.raises(MissingMeasurementError, match=r"sensors=\[accelerometer\].*Configurations in the set: "
                                                      r"sensors=\[\], removed=\[\]"):
        ms.matrix([a], sensors=["accelerometer"])


def test_matrix_refuses_rotational_and_repeated_points(model):
    ms = measurement_set(model, [(POINTS[0], POINTS[0])])
    with pytest.raises(InvalidValueError, match=r"points\[0\].*rdof"):
        ms.matrix(["tool.tip:theta"])
    with pytest.raises(InvalidValueError, match=r"points\[1\].*twice"):
        ms.matrix(["tool.tip", "tool.tip:y"])


def test_configurations_do_not_depend_on_order(model):
    a = POINTS[0]
    ms = measurement_set(model, [(a, a)], sensors=["s2", "s1"], removed=["tool"])
    assert ms.configurations() == ((("s1", "s2"), ("tool",)),)
    assert len(ms.select(sensors=["s1", "s2"], removed=["tool"])) == 1
    assert ms.matrix([a], sensors=["s1", "s2"], removed="tool").shape == (GRID.n, 1, 1)


def test_value_objects_check_their_fields(model):
    a, b = POINTS[:2]
    entry = model[f"{a}:y", f"{b}:y"]
    with pytest.raises(InvalidValueError, match="labels .* differ"):
        Measurement(a, a, entry)
    with pytest.raises(InvalidValueError, match="expected one FRF"):
        Measurement.from_frf(model, a, b)
    with pytest.raises(InvalidValueError, match=r"sensors\[0\]"):
        Measurement.from_frf(entry, a, b, sensors=["a.b"])
    one = Measurement.from_frf(entry, a, b)
    with pytest.raises(InvalidValueError, match=r"measurements\[0\] and measurements\[1\] are both"):
        MeasurementSet("x", [one, one])
    with pytest.raises(InvalidValueError, match="at least one"):
        MeasurementSet("x", [])
    other = Measurement.from_frf(entry.interpolate(Frequency.from_range("100 Hz", "1000 Hz", "10 Hz")), b, a)
    with pytest.raises(FrequencyAxisMismatchError, match=r"measurements\[1\].*interpolate"):
        MeasurementSet("x", [one, other])


def test_validate_lists_every_problem(model):
    assembly = make_assembly().attach(Sensor("accelerometer", "tool.tip", "2 g"))
    a = POINTS[0]
    good = measurement_set(model, [(a, a)], sensors=["accelerometer"])
    good.validate(assembly)
    bad = MeasurementSet("bad", [
        Measurement.from_frf(model[f"{a}:y", f"{a}:y"], "tool@200 mm", "drill.tip", sensors=["laser", "accelerometer"]),
        Measurement.from_frf(model[f"{a}:y", f"{a}:y"], "tool.tip", "holder.tip", removed=["tool", "table"],
                             sensors=["accelerometer"]),
    ])
    with pytest.raises(MeasurementSetError) as info:
        bad.validate(assembly)
    problems = info.value.problems
    assert len(problems) == 6, problems
    text = str(info.value)
    assert "6 problem(s)" in text
    assert re.search(r"measurements\[0\]\.response: .*tool@200 mm.*outside", text)
    assert re.search(r"measurements\[0\]\.excitation: .*no component 'drill'", text)
    assert re.search(r"measurements\[0\]\.sensors: no sensor 'laser'", text)
    assert re.search(r"measurements\[1\]\.removed: 'table' is not a component", text)
    assert re.search(r"measurements\[1\]\.response: tool\.tip:y is on component 'tool', which this measurement "
                     r"lists as removed", text)
    assert re.search(r"measurements\[1\]\.sensors: sensor 'accelerometer' sits at tool\.tip", text)


def test_validate_of_a_file_names_frf_tables(tmp_path, tip_file):
    ms = loads_measurements(GOOD + 'sensors = ["laser"]\n', tmp_path, "set.toml")
    with pytest.raises(MeasurementSetError, match=r"(?s)set\.toml.*frf\[0\]\.sensors: no sensor 'laser'"):
        ms.validate(make_assembly())


def test_a_data_file_off_a_uniform_grid_is_refused_naming_set_entry_file_and_line(tmp_path, tip_file):
    lines = tip_file.read_text().splitlines()
    del lines[10]  # the line at 190 Hz: a 20 Hz step among 10 Hz ones
    tip_file.write_text("\n".join(lines) + "\n")
    message = error_of(tmp_path, GOOD)
    assert re.search(r"set\.toml, line 4: frf\[0\]\.file: .*tip\.csv, line 11: at 200 Hz: 20 Hz after the line "
                     r"before, where the grid's step is 10 Hz: identify and diagnose .* need equally spaced lines; "
                     r"write the data on one frequency step", message), message


@pytest.mark.parametrize("quantity, article", [("receptance", "the model has no receptance at 0 Hz"),
                                               ("accelerance", "an accelerance has no receptance at 0 Hz")])
def test_a_0_hz_line_is_dropped_with_a_warning_naming_the_entry(tmp_path, quantity, article):
    grid = Frequency.from_range("0 Hz", "100 Hz", "10 Hz")
    FRF.single(grid, np.linspace(1e-6, 2e-6, grid.n) + 1e-8j).to_csv(tmp_path / "tip.csv")
    text = GOOD + f'quantity = "{quantity}"\n'
    with pytest.warns(UserWarning, match=rf"set\.toml, line 4: frf\[0\]\.file: tip\.csv: dropped the 0 Hz line: "
                                         rf"{article}"):
        ms = loads_measurements(text, tmp_path, "set.toml")
    assert ms.measurements[0].frf.frequency.hz[0] == pytest.approx(10.0)


@pytest.mark.parametrize("decimals, read", [(2, True), (3, True), (1, False)])
def test_frequencies_written_rounded_are_read_as_the_uniform_grid_they_round(tmp_path, decimals, read):
    """A 0.15625 Hz step (a 6.4 s record) written with 2 or 3 decimals lies 3 % or 0.3 % of a step off its grid:
    read as the grid, the values untouched; with 1 decimal (32 % off) it is refused."""
    hz = 20.0 + 0.15625 * np.arange(400)
    h = 1e-6 / (1 - (hz / 60.0) ** 2 + 0.04j * hz / 60.0)
    rows = "".join(f"{f:.{decimals}f},{float(v.real)!r},{float(v.imag)!r}\n" for f, v in zip(hz, h))
    (tmp_path / "tip.csv").write_text("frequency_hz,real,imag\n" + rows)
    if not read:
        assert re.search(r"tip\.csv, line \d+: at .* Hz: .* need equally spaced lines; .* rounded within 0\.25 of "
                         r"a step are read as their grid", error_of(tmp_path, GOOD))
        return
    ms = loads_measurements(GOOD, tmp_path, "set.toml")
    frf = ms.measurements[0].frf
    np.testing.assert_allclose(frf.frequency.hz, hz, rtol=0, atol=0.5 * 10.0**-decimals / 10)  # 10 x the rounding
    np.testing.assert_allclose(np.diff(frf.frequency.hz), np.diff(frf.frequency.hz)[0], rtol=1e-9)
    np.testing.assert_array_equal(frf.data[:, 0, 0], h)


@pytest.mark.parametrize("quantity", ["receptance", "mobility", "accelerance"])
def test_a_csv_file_says_its_quantity(tmp_path, model, quantity):
    """A mobility or an accelerance written to CSV is read by a measurement set as what it is, with or without
    the quantity key; a key that says another quantity than the file is refused naming the key."""
    h = model.entry("tool.tip:y", "tool.tip:y")
    factor = {"receptance": 1, "mobility": 1j * GRID.omega, "accelerance": -GRID.omega**2}[quantity]
    FRF.single(GRID, h * factor, "tool.tip:y", "tool.tip:y", quantity=quantity).to_csv(tmp_path / "tip.csv")
    entry = '[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "tip.csv"\n'
    for key in ("", f'quantity = "{quantity}"\n'):
        m = loads_measurements(entry + key, tmp_path, "set.toml").measurements[0]
        assert m.quantity == quantity and m.frf.quantity == "receptance"
        np.testing.assert_allclose(m.values, h, rtol=1e-12)
    if quantity != "receptance":
        with pytest.raises(FileFormatError, match=r"set\.toml.*frf\[0\]\.quantity: 'receptance' contradicts the "
                                                  rf"data file: .*tip\.csv, line 1: the header's units are those of "
                                                  rf"an? {quantity}, but the quantity given is receptance"):
            loads_measurements(entry + 'quantity = "receptance"\n', tmp_path, "set.toml")


def test_a_file_of_a_0_hz_line_and_one_more_is_refused_naming_it(tmp_path):
    """Two lines, the first at 0 Hz: the set kept one line after dropping it, and diagnose failed later with
    'band: got 10-10 Hz' naming no file."""
    (tmp_path / "two.csv").write_text("frequency_hz,real,imag\n0,1e-6,0\n10,1e-6,-1e-7\n", encoding="utf-8")
    text = '[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "two.csv"\n'
    with pytest.raises(FileFormatError, match=r"line 4: frf\[0\]\.file: .*two\.csv: 2 frequency lines, the first "
                                              r"at 0 Hz"):
        loads_measurements(text, base_dir=tmp_path, source="set.toml")


def test_the_same_file_under_a_hard_link_is_refused_as_read_twice(tmp_path):
    """A hard link (or, on a case-insensitive file system, the name in other case) gave the file a second path
    that the comparison of resolved paths did not see: one measurement read as two."""
    (tmp_path / "a.csv").write_text("frequency_hz,real,imag\n10,1e-6,-1e-7\n20,1e-6,-2e-7\n30,1e-6,-1e-7\n",
                                    encoding="utf-8")
    try:
        os.link(tmp_path / "a.csv", tmp_path / "b.csv")
    except OSError:
        pytest.skip("no hard links here")
    text = ('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "a.csv"\n'
            '[[frf]]\nresponse = "holder.tip"\nexcitation = "tool.tip"\nfile = "b.csv"\n')
    with pytest.raises(FileFormatError, match=r"frf\[1\]\.file: reads the same data as frf\[0\]"):
        loads_measurements(text, base_dir=tmp_path, source="set.toml")
