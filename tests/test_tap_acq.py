"""Tap records as acquisition systems write them: preambles, unit rows, no time column, extra channels, LabVIEW
.lvm files, binary UFF 58b; each layout written here after the system's documented form and read against the
same samples (and the plain CSV's FRF)."""

from __future__ import annotations

import gc
import json
import warnings

import numpy as np
import pytest
from scipy.io import savemat

from substructure.cli import main
from substructure.datasets import impact_records
from substructure.errors import FileFormatError, InvalidValueError, SubstructureWarning
from substructure.io import _tap_table
from substructure.io.tap_files import read_tap_csv, read_tap_lvm, read_tap_mat, read_tap_uff, read_taps_uff
from substructure.tap.records import TapRecord

FS = 10240.0
G = 9.80665


def samples(n=2048, seed=1):
    """Force (N), acceleration (m/s^2) of a fixed random record and the time axis, rounded as files write them."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    f = np.round(rng.normal(0.0, 20.0, n), 6)
    a = np.round(rng.normal(0.0, 3.0, n), 6)
    return t, f, a


def rows(columns, sep=",", fmt="{!r}", decimal_comma=False):
    lines = []
    for row in np.column_stack(columns):
        cells = [fmt.format(float(v)) for v in row]
        if decimal_comma:
            cells = [c.replace(".", ",") for c in cells]
        lines.append(sep.join(cells))
    return "\n".join(lines) + "\n"


# -- 1. a preamble, units in a row or in the names ---------------------------------------------------------------

def test_a_preamble_and_a_row_of_units_under_the_names(tmp_path):
    t, f, a = samples()
    path = tmp_path / "export.csv"
    path.write_text("Sample rate: 10240 Hz\nDate: 2026-03-01 10:00:00\nChannel 1: Force, hammer 086C03\n"
                    "Channel 2: Accel, 352C23\n\nTime,Force,Accel\ns,N,g\n" + rows([t, f, a / G]))
    record = read_tap_csv(path)
    assert np.allclose(record.time, t, rtol=0, atol=1e-12) and np.array_equal(record.force, f)
    assert np.allclose(record.response, a, rtol=1e-9, atol=1e-12) and record.quantity == "acceleration"
    assert record.force_column == "Force [N]" and record.response_column == "Accel [g]"


@pytest.mark.parametrize("names, units, scale", [
    ('"Time";"Hammer";"Acc"', '"s";"N";"m/s2"', 1.0),  # quoted names and units, as exports with ';' write them
    ("Time;Force;Accel", "s;N;m s-2", 1.0),
    ("Time;Force;Accel", "s;N;m.s-2", 1.0),
    ("Time;Force;Accel", "s;N;m\u00b7s\u207b\u00b2", 1.0),
    ("Time;Force;Accel", "s;lbf;G", 1.0 / G),  # G: gravity (not the gauss), the force in pounds
    ("Time;Force;Accel", "s;lb;mm/s2", 1000.0),
])
def test_units_as_acquisition_programs_write_them_in_a_row_of_their_own(tmp_path, names, units, scale):
    t, f, a = samples()
    lbf = 4.4482216152605  # N, the pound-force by definition (0.45359237 kg times 9.80665 m/s^2)
    force_scale = 1.0 / lbf if "lb" in units else 1.0
    path = tmp_path / "export.csv"
    path.write_text(names + "\n" + units + "\n" + rows([t, f * force_scale, a * scale], sep=";", decimal_comma=True),
                    encoding="utf-8")
    record = read_tap_csv(path)
    assert np.allclose(record.force, f, rtol=1e-12, atol=1e-12)
    assert np.allclose(record.response, a, rtol=1e-12, atol=1e-12) and record.quantity == "acceleration"


@pytest.mark.parametrize("header", [
    "Time (s)\tForce (N)\tAcceleration (m/s^2)",
    "Time [s]\tForce [N]\tAcceleration [m/s²]",
    "Time/s\tForce/N\tAcceleration/(m/s^2)",
    "Time in s\tForce in N\tAcceleration in m/s^2",
])
def test_units_in_the_names_in_every_form(tmp_path, header):
    t, f, a = samples()
    path = tmp_path / "named.txt"
    path.write_text("Title\tImpact 3\nOperator\tJS\n" + header + "\n" + rows([t, f, a], sep="\t", decimal_comma=True))
    record = read_tap_csv(path)
    assert np.allclose(record.time, t, atol=1e-12) and np.array_equal(record.force, f)
    assert np.allclose(record.response, a, rtol=1e-12, atol=0)


def test_whitespace_columns_with_comment_lines(tmp_path):
    t, f, a = samples()
    path = tmp_path / "pulse.asc"
    path.write_text("# exported 2026-03-01\nTime [s]   Force [N]   Acceleration [m/s^2]\n" + rows([t, f, a], sep="   "))
    record = read_tap_csv(path)
    assert np.array_equal(record.force, f) and np.array_equal(record.response, a)


# -- 2. no time column ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("line", [
    "Sample rate: 10.24 kHz", "Sampling frequency = 10240 Hz", "Fs;10240", "Fs [Hz];10240", "dt: 9.765625e-05 s",
    "Delta_X\t9.765625E-5\t9.765625E-5", "Increment;9,765625e-5", "Sample interval: 97.65625 us",
    "Sample rate: 10240 S/s", "# Sampling rate: 10240",
])
def test_the_sample_rate_from_the_preamble(tmp_path, line):
    _, f, a = samples()
    path = tmp_path / "nt.csv"
    path.write_text(line + "\nForce [N];Acceleration [g]\n" + rows([f, a / G], sep=";", decimal_comma=True))
    record = read_tap_csv(path)
    assert record.sample_rate == FS and np.allclose(record.time, np.arange(f.size) / FS, rtol=1e-12, atol=0)
    assert np.array_equal(record.force, f)


def test_the_sample_rate_option_agrees_or_is_refused(tmp_path):
    t, f, a = samples()
    bare = tmp_path / "bare.csv"
    bare.write_text("force [N],acceleration [m/s^2]\n" + rows([f, a]))
    with pytest.raises(FileFormatError, match=r"bare.csv, line 1: no column in units of time .* --sample-rate"):
        read_tap_csv(bare)
    assert read_tap_csv(bare, sample_rate="10.24 kHz").sample_rate == FS
    assert read_tap_csv(bare, sample_rate=FS).sample_rate == FS
    stated = tmp_path / "stated.csv"
    stated.write_text("Sample rate: 10240 Hz\n" + bare.read_text())
    assert read_tap_csv(stated, sample_rate="10240 Hz").sample_rate == FS
    with pytest.raises(FileFormatError, match=r"stated.csv, line 1: the file says 10240 Hz, --sample-rate 20480 Hz"):
        read_tap_csv(stated, sample_rate="20.48 kHz")
    timed = tmp_path / "timed.csv"
    timed.write_text("time [s],force [N],acceleration [m/s^2]\n" + rows([t, f, a]))
    with pytest.raises(FileFormatError, match=r"sampled at 10240 Hz, --sample-rate says 12800 Hz"):
        read_tap_csv(timed, sample_rate="12.8 kHz")
    both = tmp_path / "both.csv"
    both.write_text("Sample rate: 10240 Hz\ndt: 1e-4 s\n" + bare.read_text())
    with pytest.raises(FileFormatError, match=r"both.csv, lines 1 and 2: .* the preamble contradicts itself"):
        read_tap_csv(both)
    odd = tmp_path / "odd.csv"
    odd.write_text("Sample rate: 10240 zorks\n" + bare.read_text())
    with pytest.raises(FileFormatError, match=r"odd.csv, line 1: cannot read the unit 'zorks'"):
        read_tap_csv(odd)


# -- 3. more than three columns ------------------------------------------------------------------------------------

def test_more_channels_chosen_by_name_or_index_or_by_their_units(tmp_path):
    t, f, a = samples()
    b = -2.0 * a
    path = tmp_path / "four.csv"
    path.write_text("time [s],hammer [N],Accel 1 [g],Accel 2 [g],Trigger [V]\n"
                    + rows([t, f, a / G, b / G, np.zeros_like(t)]))
    with pytest.raises(FileFormatError, match=r"four.csv, line 1: 2 response columns .*1: time \[s\]; "
                                              r"2: hammer \[N\]; 3: Accel 1 \[g\]; 4: Accel 2 \[g\]; "
                                              r"5: Trigger \[V\].*--response-column"):
        read_tap_csv(path)
    assert np.allclose(read_tap_csv(path, response_column="accel 2").response, b)
    assert np.allclose(read_tap_csv(path, response_column=3).response, a)
    assert np.allclose(read_tap_csv(path, response_column="Accel 1 [g]").response, a)
    with pytest.raises(FileFormatError, match=r"--response-column 'Accel 3' names no columns"):
        read_tap_csv(path, response_column="Accel 3")
    with pytest.raises(FileFormatError, match=r"--force-column 9: the file has 5 columns"):
        read_tap_csv(path, force_column=9, response_column=3)
    with pytest.raises(FileFormatError, match=r"--force-column names the time column"):
        read_tap_csv(path, force_column=1, response_column=3)
    trigger = tmp_path / "trigger.csv"  # one force, one response by their units; the trigger and a status column left
    trigger.write_text("time [s],Trigger [V],force [N],status,acceleration [m/s^2]\n"
                       + rows([t, np.zeros_like(t), f, np.ones_like(t), a]))
    record = read_tap_csv(trigger)
    assert np.array_equal(record.force, f) and np.array_equal(record.response, a)
    two = tmp_path / "two.csv"
    two.write_text("time [s],force 1 [N],force 2 [N],acceleration [g]\n" + rows([t, f, f, a]))
    with pytest.raises(FileFormatError, match=r"two.csv, line 1: 2 force columns .*--force-column"):
        read_tap_csv(two)
    assert np.array_equal(read_tap_csv(two, force_column="force 2").force, f)


# -- the numeric rows: whole-array parse, exact errors -------------------------------------------------------------

def test_the_fast_parse_reads_every_row_and_never_falls_back_on_a_good_file(tmp_path, monkeypatch):
    rng = np.random.default_rng(7)
    table = rng.normal(size=(20000, 4)) * 10.0 ** rng.integers(-8, 8, size=(20000, 4))
    path = tmp_path / "big.csv"
    np.savetxt(path, table, delimiter=",", header="time [s],force [N],acceleration [g],x [V]", comments="")
    monkeypatch.setattr(_tap_table, "CHUNK_BYTES", 4096)  # many pieces, each cut at a line

    def no_fallback(*args, **kwargs):
        raise AssertionError("fell back to the line-by-line reading")

    monkeypatch.setattr(_tap_table, "_slow", no_fallback)
    data = path.read_bytes()
    parsed = _tap_table.parse_rows(data, 2, 4, ",", False, list("tfax"), "big.csv", data.index(b"\n") + 1)
    assert np.array_equal(parsed, np.loadtxt(path, delimiter=",", skiprows=1))  # numpy's own text reader
    crlf = path.read_bytes().replace(b"\n", b";\r\n").split(b"\r\n", 1)[1]  # CRLF, a separator at each row's end
    parsed = _tap_table.parse_rows(crlf.replace(b",", b";"), 2, 4, ";", False, list("tfax"), "big.csv")
    assert np.array_equal(parsed, table)


@pytest.mark.parametrize("bad, message", [
    ("1 2,3,4", r"line 1502: column 'time \[s\]' is '1 2'"),
    ("1,,2", r"line 1502: column 'force \[N\]' is ''"),
    ("1,2,3,4", r"line 1502: 4 value\(s\); expected 3"),
    ("1,2,0x3", r"line 1502: column 'acceleration \[m/s\^2\]' is '0x3'"),
    ("1,2,3µ", r"line 1502: column 'acceleration \[m/s\^2\]' is '3µ'"),
    ("1,nan,3", r"line 1502: column 'force \[N\]' is nan; expected a finite number"),
])
def test_a_bad_cell_deep_in_a_large_file_is_named_by_its_line(tmp_path, monkeypatch, bad, message):
    monkeypatch.setattr(_tap_table, "CHUNK_BYTES", 2048)
    t, f, a = samples(3000)
    lines = rows([t, f, a]).splitlines()
    lines[1500] = bad  # line 1502 of the file: the header is line 1
    path = tmp_path / "deep.csv"
    path.write_text("time [s],force [N],acceleration [m/s^2]\n" + "\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match="deep.csv, " + message):
        read_tap_csv(path)


def test_layout_errors_name_the_line(tmp_path):
    cases = {
        "0,1,2\n1,2,3\n": r"line 1: numbers with no header above them",
        "Time,Force,Accel\n0,1,2\n": r"line 1: column 1 'Time' has no unit",
        "time [s],force [N],acceleration [g]\n0,1,2,3\n": r"line 1: the header names 3 columns .* \(line 2\) has 4",
        "Title: x\n" * 2001: r"no row of numbers in the first 2000 lines",
        "Sample rate: fast\nforce [N],acceleration [g]\n0,1\n": r"line 1: 'Sample rate' without a number",
    }
    for text, message in cases.items():
        path = tmp_path / "l.csv"
        path.write_text(text)
        with pytest.raises(FileFormatError, match="l.csv.*" + message):
            read_tap_csv(path)


# -- 4. LabVIEW measurement files ----------------------------------------------------------------------------------

def lvm(segments, x_columns="One", sep="\t", decimal=".", units=("N", "g")):
    """A .lvm file as LabVIEW's Write Measurement File writes it (header, segment headers, rows)."""
    s = sep
    out = [f"LabVIEW Measurement{s}", f"Writer_Version{s}2", f"Reader_Version{s}2",
           f"Separator{s}{'Tab' if sep == chr(9) else 'Comma'}", f"Decimal_Separator{s}{decimal}",
           f"Multi_Headings{s}No", f"X_Columns{s}{x_columns}", f"Time_Pref{s}Relative", f"Operator{s}bench",
           f"Date{s}2026/03/01", f"Time{s}10:00:00.000", f"***End_of_Header***{s}", ""]
    for x0, dt, force, accel in segments:
        def num(v):
            return f"{v:.16E}".replace(".", decimal)

        out += [f"Channels{s}2{s}", f"Samples{s}{force.size}{s}{force.size}{s}",
                f"Date{s}2026/03/01{s}2026/03/01{s}", f"Time{s}10:00:00.000{s}10:00:00.000{s}",
                f"X_Dimension{s}Time{s}Time{s}", f"X0{s}{num(x0)}{s}{num(x0)}{s}",
                f"Delta_X{s}{num(dt)}{s}{num(dt)}{s}"]
        if units:
            out.append(f"Y_Unit_Label{s}{units[0]}{s}{units[1]}{s}")
        out.append(f"***End_of_Header***{s}")
        x = x0 + np.arange(force.size) * dt
        names = {"One": ["X_Value", "Hammer", "Accel"], "No": ["Hammer", "Accel"],
                 "Multi": ["X_Value", "Hammer", "X_Value", "Accel"]}[x_columns] + ["Comment"]
        out.append(s.join(names))
        cols = {"One": [x, force, accel], "No": [force, accel], "Multi": [x, force, x, accel]}[x_columns]
        body = rows(cols, sep=s, fmt="{:.6f}", decimal_comma=decimal == ",")
        out += body.splitlines()
        out.append("")
    return "\r\n".join(out) + "\r\n"


def labview_no_x(force, accel, said=None, comment="", empty=False, x_cell=""):
    """A .lvm file as LabVIEW itself writes one without x columns: the heading X_Value over an empty first cell of
    every row, the units in Y_Unit_Label only, decimal commas; a channel without samples as empty cells."""
    n = force.size if said is None else said
    extra = ["0"] if empty else []
    out = ["LabVIEW Measurement\t", "Writer_Version\t2", "Reader_Version\t2", "Separator\tTab",
           "Decimal_Separator\t,", "Multi_Headings\tYes", "X_Columns\tNo", "Time_Pref\tAbsolute",
           "***End_of_Header***\t", "\t", "\t".join(["Channels", str(2 + len(extra))] + [""] * 2),
           "\t".join(["Samples", str(n), str(n)] + extra + [""]),
           "\t".join(["Y_Unit_Label", "Newtons", "m/s^2"] + ["Volts"] * len(extra) + [""]),
           "\t".join(["X_Dimension"] + ["Time"] * (2 + len(extra)) + [""]),
           "\t".join(["X0"] + ["0,0000000000000000E+0"] * (2 + len(extra)) + [""]),
           "\t".join(["Delta_X"] + [f"{1 / FS:.6E}".replace(".", ",")] * (2 + len(extra)) + [""]),
           "***End_of_Header***\t\t\t\t",
           "\t".join(["X_Value", "Excitation (Trigger)", "Response (Trigger)"] + ["Untitled"] * len(extra)
                     + ["Comment"])]
    for fv, av in zip(force, accel):
        cells = [x_cell, f"{fv:.6f}".replace(".", ","), f"{av:.6f}".replace(".", ",")]
        out.append("\t".join(cells + [""] * len(extra) + ([comment] if comment else [])))
    return "\r\n".join(out) + "\r\n"


def test_lvm_as_labview_writes_it_without_an_x_column(tmp_path):
    """LabVIEW's own files with X_Columns No: an empty cell under the heading X_Value on every row, words in
    brackets in the channels' names ('Excitation (Trigger)') and the units in Y_Unit_Label (Newtons), the Comment
    column's text after the numbers, a channel without samples written as empty cells, the rows of several writes
    under one segment header; a segment holding fewer rows than its header announces is refused as truncated, and
    values under X_Value where the file says it has no x column are checked as an x column (here refused)."""
    t, f, a = samples()
    f, a = np.round(f, 6), np.round(a, 6)
    for case, text in [("plain", labview_no_x(f, a)), ("comment", labview_no_x(f, a, comment="OK")),
                       ("empty", labview_no_x(f, a, empty=True, comment="LOST COMMUNICATION")),
                       ("two writes", labview_no_x(f, a, said=f.size // 2))]:
        path = tmp_path / f"{case}.lvm"
        path.write_text(text, newline="")
        (record,) = read_tap_lvm(path)
        assert record.sample_rate == pytest.approx(FS, rel=1e-6), case
        assert np.array_equal(record.force, f) and np.allclose(record.response, a, rtol=1e-12, atol=0), case
        assert record.force_column == "Excitation (Trigger) [N]" and record.response_column.endswith("[m/s^2]")
    path = tmp_path / "cut.lvm"
    path.write_text(labview_no_x(f[:100], a[:100], said=f.size), newline="")
    with pytest.raises(FileFormatError, match=r"cut.lvm, segment 1 \(header ending on line 17\): the segment header "
                                              r"announces 2048 samples but its rows hold 100: the file is truncated"):
        read_tap_lvm(path)
    path = tmp_path / "x.lvm"
    path.write_text(labview_no_x(f, a, x_cell="0,1"), newline="")
    with pytest.raises(FileFormatError, match=r"x.lvm, segment 1 .*: X_Value 0.1 on row 1 where X0 \+ n Delta_X is "
                                              r"0.0; expected the x column of a uniform time axis"):
        read_tap_lvm(path)


def test_of_two_channels_a_response_and_one_in_volts_the_volts_are_the_hammer(tmp_path):
    """As LabVIEW logs a hammer through a plain voltage input: 'Voltage' in Volts beside 'Acceleration' in g (x
    columns of their own): the voltage channel is the force, read through the hammer's sensitivity; without the
    sensitivity the message asks for it; with a third channel the rule does not guess."""
    t, f, a = samples()
    volts, g = np.round(f * 2.25e-3, 9), np.round(a / G, 6)
    path = tmp_path / "v.lvm"
    path.write_text(lvm([(0.0, 1 / FS, volts, g)], "Multi", units=("Volts", "g")).replace("Hammer", "Voltage")
                    .replace("Accel", "Acceleration"), newline="")
    (record,) = read_tap_lvm(path, hammer_sensitivity="2.25 mV/N")
    assert record.force_column == "Voltage [V]" and np.allclose(record.force, f, rtol=0, atol=2.3e-4)  # 1e-6 V rounding
    assert record.quantity == "acceleration" and np.allclose(record.response, a, rtol=1e-6, atol=1e-5)
    with pytest.raises(FileFormatError, match=r"v.lvm: column 'Voltage \[V\]': the channel is a voltage \(V\); give "
                                              r"the sensor's sensitivity with hammer sensitivity"):
        read_tap_lvm(path)
    three = tmp_path / "three.csv"
    three.write_text("time [s],voltage [V],acceleration [g],acceleration 2 [g]\n"
                     + rows([t, volts, g, g]), newline="")
    with pytest.raises(FileFormatError, match=r"three.csv, line 1: 0 force columns"):
        read_tap_csv(three, hammer_sensitivity="2.25 mV/N")


def labview_one(force, accel, logger, logger_dt):
    """A .lvm file of LabVIEW with one x column, commas, the tags written under their channels' columns: a force
    in N, a channel without a unit, an acceleration in g and a logger channel of ``logger`` samples, each
    ``logger_dt`` apart (empty cells after them)."""
    n, dt = force.size, f"{1 / FS:.6E}"
    out = ["LabVIEW Measurement,", "Writer_Version,2", "Reader_Version,2", "Separator,Comma", "Decimal_Separator,.",
           "Multi_Headings,No", "X_Columns,One", "Time_Pref,Relative", "***End_of_Header***,", ",",
           "Channels,4,,,,", f"Samples,{n},{n},{n},{logger},", "Y_Unit_Label,N,,g,,",
           "X_Dimension,Time,Time,Time,Time,", "X0,0.0000000000000000E+0" + ",0.0000000000000000E+0" * 3 + ",",
           f"Delta_X,{dt},{dt},{dt},{logger_dt},", "***End_of_Header***,,,,,", "X_Value,Force,Aux,Accel,Logger,Comment"]
    for k in range(n):
        out.append(",".join([f"{k / FS:.6f}", f"{force[k]:.6f}", "0.000000", f"{accel[k]:.6f}",
                             f"{100.0 * k:.6f}" if k < logger else ""]))
    return "\r\n".join(out) + "\r\n"


def test_lvm_tags_are_read_under_their_channels_and_a_channel_of_another_rate_is_left_out(tmp_path):
    """A tag cell left empty under a channel (no unit for 'Aux') does not hand the next channel's unit to it: the
    acceleration keeps its g (read before as 'Aux' in g: the wrong channel, silently); a channel whose samples end
    early (a logger's five readings a second beside the tap's channels) is left out with a warning, not refused as
    empty cells."""
    t, f, a = samples()
    f, a = np.round(f, 6), np.round(a, 6)
    path = tmp_path / "logger.lvm"
    path.write_text(labview_one(f, a, 5, "1.000000"), newline="")
    with pytest.warns(SubstructureWarning, match=r"logger.lvm, segment 1 .*: 'Logger' hold fewer samples than the "
                                                 r"other channels .*: left out"):
        (record,) = read_tap_lvm(path)
    assert record.force_column == "Force [N]" and record.response_column == "Accel [g]"
    assert np.array_equal(record.force, f) and np.allclose(record.response, a * G, rtol=1e-12, atol=0)
    path = tmp_path / "all.lvm"  # every channel at the tap's rate: 'Aux' and 'Logger' without units, not read
    path.write_text(labview_one(f, a, f.size, f"{1 / FS:.6E}"), newline="")
    (record,) = read_tap_lvm(path)
    assert record.force_column == "Force [N]" and record.response_column == "Accel [g]"  # not 'Aux [g]'
    assert np.allclose(record.response, a * G, rtol=1e-12, atol=0)


def test_lvm_tags_under_x_columns_of_their_own_are_read_by_place(tmp_path):
    """X_Columns Multi as LabVIEW writes it: each tag's value under its channel, empty under the x columns, and
    the unit of the middle channel left empty: the acceleration keeps its g."""
    t, f, a = samples()
    f, a = np.round(f, 6), np.round(a, 6)
    n, dt = f.size, f"{1 / FS:.6E}"
    out = ["LabVIEW Measurement\t", "Writer_Version\t2", "Reader_Version\t2", "Separator\tTab",
           "Decimal_Separator\t.", "Multi_Headings\tYes", "X_Columns\tMulti", "Time_Pref\tRelative",
           "***End_of_Header***\t", "\t", "Channels\t3\t\t\t\t\t", f"Samples\t{n}\t\t{n}\t\t{n}\t",
           "Y_Unit_Label\tN\t\t\t\tg\t", "X_Dimension\tTime\t\tTime\t\tTime\t", "X0\t0.0\t\t0.0\t\t0.0\t",
           f"Delta_X\t{dt}\t\t{dt}\t\t{dt}\t", "***End_of_Header***\t\t\t\t\t\t",
           "X_Value\tForce\tX_Value\tAux\tX_Value\tAccel\tComment"]
    out += ["\t".join([f"{k / FS:.6f}", f"{f[k]:.6f}", f"{k / FS:.6f}", "0.000000", f"{k / FS:.6f}", f"{a[k]:.6f}"])
            for k in range(n)]
    path = tmp_path / "multi.lvm"
    path.write_text("\r\n".join(out) + "\r\n", newline="")
    (record,) = read_tap_lvm(path)
    assert record.force_column == "Force [N]" and record.response_column == "Accel [g]"
    assert record.sample_rate == pytest.approx(FS) and np.allclose(record.response, a * G, rtol=1e-12, atol=0)


@pytest.mark.parametrize("x_columns, sep, decimal", [("One", "\t", "."), ("No", "\t", ","), ("One", ",", "."),
                                                    ("Multi", "\t", ".")])
def test_lvm_one_segment(tmp_path, x_columns, sep, decimal):
    t, f, a = samples()
    f, a = np.round(f, 6), np.round(a / G, 6)
    path = tmp_path / "tap.lvm"
    path.write_text(lvm([(0.0, 1 / FS, f, a)], x_columns, sep, decimal), newline="")
    (record,) = read_tap_lvm(path)
    assert record.sample_rate == FS and np.allclose(record.time, t, rtol=1e-12, atol=1e-15)
    assert np.array_equal(record.force, f) and np.allclose(record.response, a * G, rtol=1e-12, atol=0)
    assert record.force_column == "Hammer [N]" and record.response_column == "Accel [g]"


def test_lvm_without_a_line_of_names(tmp_path):
    t, f, a = samples()
    f, a = np.round(f, 6), np.round(a, 6)
    text = lvm([(0.0, 1 / FS, f, a)], units=("N", "m/s^2"))
    text = text.replace("X_Value\tHammer\tAccel\tComment\r\n", "")
    path = tmp_path / "bare.lvm"
    path.write_text(text, newline="")
    (record,) = read_tap_lvm(path)
    assert np.array_equal(record.force, f) and np.array_equal(record.response, a)
    assert record.force_column == "channel 1 [N]"


def test_lvm_segments_join_when_contiguous_and_split_when_not(tmp_path):
    _, f, a = samples(3000)
    dt = 1 / FS
    path = tmp_path / "loop.lvm"  # a loop that wrote 1000 samples per call: one record
    path.write_text(lvm([(k * 1000 * dt, dt, f[k * 1000:(k + 1) * 1000], a[k * 1000:(k + 1) * 1000])
                         for k in range(3)]), newline="")
    (record,) = read_tap_lvm(path)
    assert np.array_equal(record.force, f) and len(record) == 3000
    path = tmp_path / "taps.lvm"  # one acquisition per tap, each starting at 0: three records
    path.write_text(lvm([(0.0, dt, f[k * 1000:(k + 1) * 1000], a[k * 1000:(k + 1) * 1000]) for k in range(3)]),
                    newline="")
    records = read_tap_lvm(path)
    assert len(records) == 3 and np.array_equal(records[2].force, f[2000:])


def test_lvm_errors(tmp_path):
    _, f, a = samples()
    path = tmp_path / "e.lvm"
    path.write_text(lvm([(0.0, 1 / FS, f, a)], units=None), newline="")
    with pytest.raises(FileFormatError, match=r"e.lvm, line 22: channel 'Hammer' has no unit; expected a Y_Unit_Label"):
        read_tap_lvm(path)
    text = lvm([(0.0, 1 / FS, f, a)])
    path.write_text(text.replace("Delta_X", "Delta_Y"), newline="")
    with pytest.raises(FileFormatError, match=r"e.lvm, segment 1 \(header ending on line 22\): no Delta_X"):
        read_tap_lvm(path)
    path.write_text(text.replace("\r\n0.010742\t", "\r\n0.020000\t"), newline="")
    with pytest.raises(FileFormatError, match=r"X_Value 0.02 on row 111 where X0 \+ n Delta_X is 0.0107"):
        read_tap_lvm(path)
    path.write_text("Time,Force\n", newline="")
    with pytest.raises(FileFormatError, match=r"e.lvm, line 1: expected 'LabVIEW Measurement'"):
        read_tap_lvm(path)
    path.write_text(text, newline="")
    with pytest.raises(FileFormatError, match=r"Delta_X .* is 10240 Hz, --sample-rate 10000 Hz"):
        read_tap_lvm(path, sample_rate="10 kHz")


@pytest.mark.parametrize("line, message", [
    ("dt = -0.0001", r"line 1: 'dt' is -0.0001 s; expected a positive time step"),
    ("Sample interval: 0 ms", r"line 1: 'Sample interval' is 0 ms; expected a positive time step"),
    ("Sample rate: -10240 Hz", r"line 1: a sample rate of -10240 Hz; expected a positive rate"),
])
def test_a_preamble_s_time_step_that_is_not_positive_is_named_as_written(tmp_path, line, message):
    """A negative or zero step is named by the step the file states, not by the rate it would give."""
    _, f, a = samples()
    path = tmp_path / "step.csv"
    path.write_text(line + "\nforce [N],acceleration [m/s^2]\n" + rows([f, a]))
    with pytest.raises(FileFormatError, match=r"step.csv, " + message):
        read_tap_csv(path)


# -- 5. UFF ----------------------------------------------------------------------------------------------------------

def write_uff(path, channels, binary=0, abscissa_spec=17, abscissa_label="s", x=None):
    import pyuff

    with warnings.catch_warnings():  # pyuff's binary writer leaves its file to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        _write_uff(pyuff, path, channels, binary, abscissa_spec, abscissa_label, x)
        gc.collect()
    return path


def _write_uff(pyuff, path, channels, binary, abscissa_spec, abscissa_label, x):
    uff = pyuff.UFF(str(path))
    n = channels[0][0].size
    uniform = x is None
    x = np.arange(n) / FS if x is None else x
    for k, (data, spec, unit) in enumerate(channels):
        uff.write_sets(pyuff.prepare_58(
            binary=binary, func_type=1, rsp_node=k + 1, rsp_dir=3, ref_node=1, ref_dir=3, data=data, x=x,
            num_pts=n, abscissa_spacing=1 if uniform else 0, abscissa_min=0.0, abscissa_inc=1 / FS,
            abscissa_spec_data_type=abscissa_spec, ordinate_spec_data_type=spec, ordinate_axis_units_lab=unit,
            id1=f"channel {k + 1}", orddenom_spec_data_type=0, orddenom_axis_units_lab="",
            abscissa_axis_units_lab=abscissa_label, z_axis_spec_data_type=0, z_axis_axis_units_lab=""), mode="add")


def test_binary_uff_58b_and_units_in_the_labels_alone(tmp_path):
    _, f, a = samples()
    path = write_uff(tmp_path / "b.uff", [(a / G, 0, "g"), (f, 0, "N")], binary=1)
    assert b"58b" in path.read_bytes()[:200]
    record = read_tap_uff(path)
    assert np.allclose(record.force, f, rtol=1e-6) and np.allclose(record.response, a, rtol=1e-6, atol=1e-6)
    volts = write_uff(tmp_path / "mv.uff", [(f * 2.25, 0, "mV"), (a / G, 0, "g")], binary=1)
    record = read_tap_uff(volts, hammer_sensitivity="2.25 mV/N")
    assert np.allclose(record.force, f, rtol=1e-6) and record.quantity == "acceleration"
    volts = write_uff(tmp_path / "mv2.uff", [(f, 0, "N"), (a / G * 10.2, 0, "mV")])
    record = read_tap_uff(volts, sensitivity="10.2 mV/g")
    assert np.allclose(record.response, a, rtol=1e-5, atol=1e-6)


def test_a_tap_file_cut_short_or_of_one_record_is_said_so_not_misread(tmp_path):
    """A universal file copied only in part: a record that lost samples is named with what its header announced;
    a file that ends inside a record is truncated (not read as the records before the cut); one record is not a
    tap; records of no force say what each holds."""
    _, f, a = samples()
    lines = write_uff(tmp_path / "whole.uff", [(f, 13, "N"), (a, 12, "m/s^2")]).read_text().splitlines()
    assert read_tap_uff(tmp_path / "whole.uff").force.size == f.size
    closing = [k for k, line in enumerate(lines) if line.strip() == "-1"]
    for name, kept, message in [
        ("first.uff", lines[:closing[1] - 40] + lines[closing[1]:],
         r"first.uff, record 0: its header announces 2048 samples but it holds 1888: the file is truncated"),
        ("second.uff", lines[:-41] + lines[-1:], r"second.uff, record 1: its header announces 2048 samples but it "
                                                 r"holds 1888"),
        ("ends.uff", lines[:len(lines) * 3 // 4], r"ends.uff: the file is truncated: it does not end with the '-1' "
                                                   r"line that closes a record \(the last type-58 record starts at "),
    ]:
        (tmp_path / name).write_text("\n".join(kept) + "\n")
        for read in (read_tap_uff, read_taps_uff):
            with pytest.raises(FileFormatError, match=message):
                read(tmp_path / name)
    one = write_uff(tmp_path / "one.uff", [(a, 12, "m/s^2")])
    with pytest.raises(FileFormatError, match=r"one.uff: one type-58 record; a tap needs two time records"):
        read_tap_uff(one)
    accelerations = write_uff(tmp_path / "acc.uff", [(a, 12, "m/s^2"), (a, 0, "g")])
    with pytest.raises(FileFormatError, match=r"acc.uff: 0 force records among 2 type-58 records; give the force "
                                              r"record's index \(--force-record, 0-based\); they hold 0 acceleration, "
                                              r"1 acceleration$"):
        read_tap_uff(accelerations)


def test_uff_abscissa_not_time_or_uneven_is_refused(tmp_path):
    _, f, a = samples()
    path = write_uff(tmp_path / "hz.uff", [(a, 12, "m/s^2"), (f, 13, "N")], abscissa_spec=18, abscissa_label="Hz")
    with pytest.raises(FileFormatError, match=r"hz.uff, record 0: abscissa of specific data type 18"):
        read_tap_uff(path)
    path = write_uff(tmp_path / "lab.uff", [(a, 12, "m/s^2"), (f, 13, "N")], abscissa_spec=0, abscissa_label="Hz")
    with pytest.raises(FileFormatError, match=r"lab.uff, record 0: abscissa in 'Hz'; expected a time"):
        read_tap_uff(path)
    x = np.arange(f.size) / FS
    x[100:] += 0.5 / FS
    path = write_uff(tmp_path / "uneven.uff", [(a, 12, "m/s^2"), (f, 13, "N")], x=x)
    import pyuff

    if np.allclose(np.diff(pyuff.UFF(str(path)).read_sets(0)["x"]), 1 / FS):
        pytest.skip("pyuff rewrites x from the spacing")  # pragma: no cover
    with pytest.raises(FileFormatError, match=r"uneven.uff, record 0: uneven abscissa"):
        read_tap_uff(path)



def test_uff_abscissa_in_milliseconds_is_converted_to_seconds(tmp_path):
    """A time axis labelled 'ms' (or 'us') is read in its unit: the same samples with the abscissa in s and in ms
    give the same record and the same FRF (it was read as seconds: a sample rate 1000 times too low); a unit that
    cannot be read, a decreasing or a standing abscissa are refused as such."""
    from substructure.tap import process_taps

    tap = impact_records()[0]
    t = tap.time - tap.time[0]
    channels = [(tap.force, 13, "N"), (tap.response / G, 0, "g")]
    seconds = read_tap_uff(write_uff(tmp_path / "s.uff", channels, x=t))
    for label, scale in (("ms", 1e3), ("us", 1e6)):
        other = read_tap_uff(write_uff(tmp_path / f"{label}.uff", channels, abscissa_label=label, x=t * scale))
        assert other.sample_rate == pytest.approx(seconds.sample_rate, rel=1e-9)
        assert np.allclose(other.time, seconds.time, rtol=0, atol=1e-9 / seconds.sample_rate)
        a, b = process_taps(seconds), process_taps(other)
        assert np.allclose(b.frf.frequency.hz, a.frf.frequency.hz, rtol=1e-9)
        assert np.allclose(b.frf.data, a.frf.data, rtol=1e-6, atol=1e-9 * np.abs(a.frf.data).max())
        assert np.allclose(b.coherence, a.coherence, atol=1e-9)
    path = write_uff(tmp_path / "furlong.uff", channels, abscissa_label="blips", x=t)
    with pytest.raises(FileFormatError, match=r"furlong.uff, record 0: abscissa unit label 'blips' "
                                              r"is not a unit read here; expected a time unit"):
        read_tap_uff(path)
    path = write_uff(tmp_path / "down.uff", channels, x=1.0 - t)
    with pytest.raises(FileFormatError, match=r"down.uff, record 0: the abscissa decreases \(from 1.0 s to "
                                              r"3.90625e-05 s over 25600 samples, a step of -3.90625e-05 s\)"):
        read_tap_uff(path)
    path = write_uff(tmp_path / "still.uff", channels, x=0 * t)
    with pytest.raises(FileFormatError, match=r"still.uff, record 0: the abscissa does not advance"):
        read_tap_uff(path)


def test_a_universal_file_of_several_taps_reads_as_one_tap_each(tmp_path, capsys):
    taps = impact_records()[:3]  # the shipped real taps, as an acquisition system exports a test's hits
    # (times written as x values with five digits, as pyuff writes them: the uniform clock read back)
    t = taps[0].time
    interleaved = [ch for r in taps for ch in ((r.force, 13, "N"), (r.response / G, 0, "g"))]
    blocked = [(r.force, 13, "N") for r in taps] + [(r.response / G, 0, "g") for r in taps]
    for name, channels in (("interleaved.uff", interleaved), ("blocked.uff", blocked)):
        got = read_taps_uff(write_uff(tmp_path / name, channels, x=t))
        assert len(got) == 3 and [g.source[-7:] for g in got] == ["(tap 1)", "(tap 2)", "(tap 3)"]
        for g, r in zip(got, taps):
            scale = np.abs(r.response).max()
            assert np.allclose(g.force, r.force, rtol=1e-6, atol=1e-9 * np.abs(r.force).max())
            assert np.allclose(g.response, r.response, rtol=1e-6, atol=1e-9 * scale)
    # the command averages a file's taps as it does the same taps in files of their own
    one_each = [write_uff(tmp_path / f"tap{k}.uff", [(r.force, 13, "N"), (r.response / G, 0, "g")], x=t)
                for k, r in enumerate(taps)]
    code, out, err = run(capsys, "tap", *one_each, "--json")
    assert code == 0, err
    expected = json.loads(out)
    code, out, err = run(capsys, "tap", tmp_path / "interleaved.uff", "--json")
    assert code == 0, err
    got = json.loads(out)
    assert got["averages"] == expected["averages"] == 3 and got["real"] == expected["real"]
    # one tap of them chosen by its records; counts that do not pair are refused with what to give
    chosen = read_tap_uff(tmp_path / "interleaved.uff", force_record=2, response_record=3)
    assert np.allclose(chosen.force, taps[1].force, rtol=1e-6, atol=1e-9 * np.abs(taps[1].force).max())
    odd = write_uff(tmp_path / "odd.uff", interleaved + [(taps[0].response / G, 0, "g")], x=t)
    with pytest.raises(FileFormatError, match=r"odd.uff: 3 force records among 7 type-58 records; give the force "):
        read_taps_uff(odd)

# -- the command, on the shipped real records written as acquisition systems write them -------------------------

def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_the_command_reads_every_layout_to_the_same_frf(tmp_path, capsys):
    r = impact_records()[0]
    plain = tmp_path / "plain.csv"
    plain.write_text("time [s],force [N],acceleration [m/s^2]\n" + rows([r.time, r.force, r.response], fmt="{!r}"))
    code, out, err = run(capsys, "tap", plain, "--json")
    assert code == 0, err
    expected = json.loads(out)
    fs = r.sample_rate
    export = tmp_path / "export.txt"
    export.write_text(f"Sampling frequency: {fs:g} Hz\nTrigger\tstatus\tForce\tAccel\n-\t-\tN\tm/s^2\n"
                      + rows([np.zeros_like(r.force), np.ones_like(r.force), r.force, r.response], sep="\t",
                             fmt="{!r}", decimal_comma=True))
    labview = tmp_path / "tap.lvm"
    text = lvm([(0.0, 1 / fs, r.force, r.response / G)])
    labview.write_text(text, newline="")
    for path, extra in ((export, ["--force-column", "Force", "--response-column", "4"]),
                        (export, ["--sample-rate", f"{fs / 1000:g} kHz"])):
        code, out, err = run(capsys, "tap", path, "--json", *extra)
        assert code == 0, err
        got = json.loads(out)
        assert got["frequency_hz"] == expected["frequency_hz"]
        assert np.allclose(got["real"], expected["real"], rtol=1e-9, atol=1e-12 * np.max(np.abs(expected["real"])))
    code, out, err = run(capsys, "tap", labview, "--json")
    assert code == 0, err
    got = json.loads(out)  # the .lvm rows keep six decimals (LabVIEW's default): the FRF to that rounding
    band = (np.array(got["frequency_hz"]) > 20) & (np.array(got["frequency_hz"]) < 5000)
    scale = np.max(np.abs(expected["real"]))
    assert np.allclose(np.array(got["real"])[band], np.array(expected["real"])[band], atol=1e-3 * scale)
    code, _, err = run(capsys, "tap", export, "--sample-rate", "1 kHz")
    assert code == 1 and "export.txt, line 1: the file says 25600 Hz, --sample-rate 1000 Hz" in err
    uff = write_uff(tmp_path / "t.uff", [(r.force, 13, "N"), (r.response, 12, "m/s^2")])
    code, _, err = run(capsys, "tap", uff, "--force-column", "1")
    assert code == 2 and "--force-column applies to columns of a text record" in err
    code, _, err = run(capsys, "tap", export, "--force-record", "1")
    assert code == 2 and "use --force-column and --response-column" in err


def test_times_written_with_few_digits_are_the_uniform_clock_and_a_lost_sample_is_refused(tmp_path):
    n, fs = 4096, 51200.0
    t, f, a = np.arange(n) / fs, np.ones(n), np.zeros(n)
    path = tmp_path / "six.csv"  # six decimals, as LabVIEW and many exports write: steps of 1.9e-5 and 2.0e-5 s
    path.write_text("time [s],force [N],acceleration [g]\n" + rows([t, f, a], fmt="{:.6f}"))
    record = read_tap_csv(path)
    assert record.sample_rate == pytest.approx(fs, rel=1e-6) and np.allclose(record.time, t, rtol=0, atol=1e-8)
    lost = np.delete(t, 2000)  # one sample lost: the clock jumps a whole step
    path.write_text("time [s],force [N],acceleration [g]\n" + rows([lost, f[1:], a[1:]], fmt="{:.6f}"))
    with pytest.raises(FileFormatError, match=r"six.csv: column 'time', sample 2000: step"):
        read_tap_csv(path)


@pytest.mark.parametrize("origin", [1.7e9, 86400.0 * 365])
def test_time_stamps_far_from_their_origin_are_the_uniform_clock_from_the_first_sample(tmp_path, origin):
    # a logger's Unix time (1.7e9 s) written with every digit: float64 holds such times to 2.4e-7 s, so that
    # the steps of 1.95e-5 s came out uneven by 1 % and the file was refused as not uniformly sampled
    t, f, a = samples()
    whole, frac = divmod(np.arange(t.size) * 390625, 4 * 10 ** 9)  # k / 10240 s = k * 390625 / 4e9 s, exactly
    stamps = [f"{int(origin) + int(w)}.{int(r) * 25:011d}" for w, r in zip(whole, frac)]
    path = tmp_path / "logger.csv"
    path.write_text("time [s],force [N],acceleration [g]\n"
                    + "".join(f"{s},{float(x)!r},{float(y)!r}\n" for s, x, y in zip(stamps, f, a)))
    record = read_tap_csv(path)
    assert record.sample_rate == pytest.approx(FS, rel=1e-9)
    np.testing.assert_allclose(record.time, t, rtol=0, atol=1e-9)  # counted from the first sample
    assert np.array_equal(record.force, f)


def test_a_record_of_time_stamps_given_in_python_says_why_its_steps_are_uneven():
    t, f, a = samples()
    with pytest.raises(InvalidValueError, match=r"expected increasing, uniformly sampled times \(one record per "
                                                r"sample rate\) \(times near 1\.7e\+09 s, which float64 holds only "
                                                r"to 2\.4e-07 s: give them from the record's first sample\)"):
        TapRecord(t + 1.7e9, f, a)


def test_lines_ended_by_a_carriage_return_alone_are_read(tmp_path):
    # Excel for Mac's "CSV (Macintosh)": the file read as one header line and no samples
    t, f, a = samples()
    path = tmp_path / "mac.csv"
    path.write_bytes(("Sample rate: 10240 Hz\rtime [s];force [N];acceleration [g]\r"
                      + rows([t, f, a], sep=";", decimal_comma=True).replace("\n", "\r")).encode())
    record = read_tap_csv(path)
    assert np.allclose(record.time, t, rtol=0, atol=1e-15) and np.array_equal(record.force, f)
    assert np.allclose(record.response, a * G, rtol=1e-12, atol=0)


def test_blanks_after_separators_quoted_names_and_a_separator_ending_every_line(tmp_path):
    t, f, a = samples()
    path = tmp_path / "spaced.csv"
    path.write_text('"Time [s]", "Force [N]", "Acceleration [g]",\n' + rows([t, f, a], sep=", ").replace("\n", ",\n"))
    record = read_tap_csv(path)
    assert np.allclose(record.time, t, rtol=0, atol=1e-15) and np.array_equal(record.force, f)
    assert np.allclose(record.response, a * G, rtol=1e-12, atol=0)


def test_a_sample_rate_without_its_unit_is_refused_on_the_command_line(tmp_path, capsys):
    _, f, a = samples()
    path = tmp_path / "bare.csv"
    path.write_text("force [N],acceleration [m/s^2]\n" + rows([f, a]))
    code, _, err = run(capsys, "tap", path, "--sample-rate", "10240")
    assert code == 1 and "--sample-rate" in err and "10240" in err


def test_rows_that_start_with_a_clock_time_are_refused_as_such(tmp_path):
    path = tmp_path / "clock.csv"
    path.write_text("Time;Force [N];Acceleration [g]\n" + "".join(f"10:00:00.{k:03d};1,5;0,25\n" for k in range(50)))
    with pytest.raises(FileFormatError, match=r"clock.csv, line 2: the first cell '10:00:00.000' is not a number "
                                              r"\(a clock time or a date\?\)"):
        read_tap_csv(path)


# -- 6. MATLAB files -------------------------------------------------------------------------------------------------

def test_matlab_vectors_with_their_units(tmp_path):

    t, f, a = samples()
    path = tmp_path / "tap.mat"
    savemat(path, {"time": t, "force": f, "force_unit": "N", "acc": a / G, "acc_unit": "g", "trigger": 0 * t})
    record = read_tap_mat(path)
    assert np.array_equal(record.force, f) and np.allclose(record.response, a, rtol=1e-12, atol=0)
    assert record.sample_rate == FS and record.response_column == "acc [g]"
    savemat(path, {"fs": FS, "hammer": f * 2.25, "hammer_unit": "mV", "acc1": a, "acc2": -a, "acc1_unit": "m/s^2",
                   "acc2_unit": "m/s^2"})
    with pytest.raises(FileFormatError, match=r"tap.mat: 2 response columns .*--response-column"):
        read_tap_mat(path, hammer_sensitivity="2.25 mV/N")
    record = read_tap_mat(path, hammer_sensitivity="2.25 mV/N", response_column="acc2")
    assert np.allclose(record.force, f) and np.array_equal(record.response, -a) and record.sample_rate == FS
    with pytest.raises(FileFormatError, match=r"variable 'fs' says 10240 Hz, --sample-rate 20000 Hz"):
        read_tap_mat(path, hammer_sensitivity="2.25 mV/N", response_column="acc2", sample_rate="20 kHz")
    savemat(path, {"t": t, "force": f, "acc": a})
    with pytest.raises(FileFormatError, match=r"tap.mat: variable 'force' has no unit; add a text variable force_unit"):
        read_tap_mat(path)
    savemat(path, {"force": f, "force_unit": "N", "acc": a, "acc_unit": "g"})
    with pytest.raises(FileFormatError, match=r"tap.mat: no column in units of time .* a scalar variable fs"):
        read_tap_mat(path)
    path.write_bytes(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Mar  2 10:00:00 2026 HDF5 schema 1.00 ."
                     + b" " * 400 + b"\x89HDF\r\n\x1a\n" + b"\0" * 64)
    with pytest.raises(FileFormatError, match=r"tap.mat: a MATLAB 7.3 file \(HDF5\), which is not read; save it again "
                                              r"as version 7"):
        read_tap_mat(path)
    path.write_bytes(b"not a MATLAB file at all" * 10)
    with pytest.raises(FileFormatError, match=r"tap.mat: cannot read the MATLAB file"):
        read_tap_mat(path)



def test_matlab_matrices_of_a_tap_a_column(tmp_path, capsys):
    from substructure.io.tap_files import read_taps_mat

    taps = impact_records()[:3]  # the shipped real taps, as a MATLAB acquisition returns them: a tap a column
    fs, n = taps[0].sample_rate, taps[0].time.size
    forces, accs = np.column_stack([r.force for r in taps]), np.column_stack([r.response for r in taps])
    path = tmp_path / "taps.mat"
    for layout in (lambda m: m, lambda m: m.T):  # samples down the columns, or along the rows
        savemat(path, {"fs": fs, "force": layout(forces), "force_unit": "N", "acc": layout(accs / G), "acc_unit": "g"})
        got = read_taps_mat(path)
        assert [r.source[-7:] for r in got] == ["(tap 1)", "(tap 2)", "(tap 3)"]
        for g, r in zip(got, taps):
            assert np.array_equal(g.force, r.force) and np.allclose(g.response, r.response, rtol=1e-12, atol=0)
            assert g.sample_rate == fs and np.allclose(g.time, r.time - r.time[0], rtol=0, atol=1e-12)
    with pytest.raises(FileFormatError, match=r"taps.mat: the force and the response are matrices of 3 taps; read "
                                              r"them with read_taps_mat"):
        read_tap_mat(path)
    # a time per tap, as some exports write it: the same clock for every tap, or refused
    timed = tmp_path / "timed.mat"
    clock = np.column_stack([taps[0].time - taps[0].time[0]] * 3)
    savemat(timed, {"t": clock, "force": forces, "force_unit": "N", "acc": accs, "acc_unit": "m/s^2"})
    assert [r.sample_rate for r in read_taps_mat(timed)] == [fs] * 3
    clock[:, 2] += 1.0
    savemat(timed, {"t": clock, "force": forces, "force_unit": "N", "acc": accs, "acc_unit": "m/s^2"})
    with pytest.raises(FileFormatError, match=r"timed.mat: the time 't' is a matrix whose columns differ"):
        read_taps_mat(timed)
    # the command averages them as the same taps in files of their own
    one_each = []
    for k, r in enumerate(taps):
        one_each.append(tmp_path / f"tap{k}.mat")
        savemat(one_each[-1], {"fs": fs, "force": r.force, "force_unit": "N", "acc": r.response / G, "acc_unit": "g"})
    code, out, err = run(capsys, "tap", *one_each, "--json")
    assert code == 0, err
    expected = json.loads(out)
    code, out, err = run(capsys, "tap", path, "--json")
    assert code == 0, err
    assert json.loads(out)["real"] == expected["real"] and expected["averages"] == 3
    # a response missing for a tap, a gap in one tap: refused naming them
    savemat(path, {"fs": fs, "force": forces, "force_unit": "N", "acc": accs[:, :2], "acc_unit": "m/s^2"})
    with pytest.raises(FileFormatError, match=rf"the force 'force' holds 3 tap\(s\) of {n} samples, the response "
                                              rf"'acc' 2 of {n}"):
        read_taps_mat(path)
    forces[700, 1] = np.nan
    savemat(path, {"fs": fs, "force": forces, "force_unit": "N", "acc": accs, "acc_unit": "m/s^2"})
    with pytest.raises(FileFormatError, match=r"variable 'force', tap 2, sample 701: nan"):
        read_taps_mat(path)

# -- text of Windows programs ------------------------------------------------------------------------------------

def test_a_header_in_windows_1252_is_read_with_a_warning_as_the_utf8_one(tmp_path):
    """m/s² written by a Windows program (byte 0xB2): the same record as the UTF-8 file, and a warning naming the
    line; bytes that are not Windows-1252 either are refused as before."""
    t, f, a = samples()
    text = "Sample rate: 10240 Hz\nTime [s];Force [N];Acceleration [m/s²]\n" + rows([t, f, a], sep=";",
                                                                                    decimal_comma=True)
    utf8, windows, neither = tmp_path / "u.csv", tmp_path / "w.csv", tmp_path / "x.csv"
    utf8.write_text(text, encoding="utf-8")
    windows.write_bytes(text.encode("cp1252"))
    neither.write_bytes(text.encode("cp1252").replace(b"\xb2", b"\x81"))
    expected = read_tap_csv(utf8)
    with pytest.warns(UserWarning, match=r"w.csv, line 2: not UTF-8; read as Windows-1252"):
        got = read_tap_csv(windows)
    assert np.array_equal(got.response, expected.response) and got.response_column == expected.response_column
    with pytest.raises(FileFormatError, match=r"x.csv, line 2: not UTF-8 text .*save the file as UTF-8"):
        read_tap_csv(neither)
    t, f, a = samples()
    f, a = np.round(f, 6), np.round(a, 6)
    path = tmp_path / "tap.lvm"
    path.write_bytes(lvm([(0.0, 1 / FS, f, a)], units=("N", "m/s²")).encode("cp1252"))
    with pytest.warns(UserWarning, match="not UTF-8; read as Windows-1252"):
        (record,) = read_tap_lvm(path)
    assert np.allclose(record.response, a, rtol=1e-12, atol=0) and record.response_column == "Accel [m/s²]"


@pytest.mark.parametrize("sep, decimal_comma", [(",", False), (";", True), ("\t", False)])
def test_numbers_in_quotes_as_some_exports_write_every_cell(tmp_path, monkeypatch, sep, decimal_comma):
    # every cell quoted: "no row of numbers in the first 2000 lines" before
    monkeypatch.setattr(_tap_table, "CHUNK_BYTES", 2048)  # pieces by the fast parse, one of them by the slow
    t, f, a = samples(3000)
    body = rows([t, f, a], sep=sep, decimal_comma=decimal_comma).splitlines()
    quoted = [sep.join(f'"{c}"' for c in line.split(sep)) for line in body]
    quoted[1700] = quoted[1700].replace('"', "", 2)  # one row half quoted
    quoted.insert(1200, "# range changed")  # a comment: that piece is read line by line
    names = sep.join(['"time [s]"', '"force [N]"', '"acceleration [m/s^2]"'])
    path = tmp_path / "quoted.csv"
    path.write_text(names + "\n" + "\n".join(quoted) + "\n")
    record = read_tap_csv(path)
    assert np.array_equal(record.force, f) and np.array_equal(record.response, a)
    assert np.allclose(record.time, t, rtol=0, atol=1e-12)
    quoted[2500] = sep.join(['"1"', '"x"', '"3"'])  # line 2502 of the file
    path.write_text(names + "\n" + "\n".join(quoted) + "\n")
    with pytest.raises(FileFormatError, match=r"quoted.csv, line 2502: column 'force \[N\]' is '\"x\"'; expected a "
                                              r"number"):
        read_tap_csv(path)


def test_matlab_vectors_of_complex_values_are_named_as_passed_over(tmp_path):
    # they were dropped without a word: "1 columns (time [s]); expected three" left the user guessing

    t, f, a = samples()
    path = tmp_path / "tap.mat"
    savemat(path, {"time": t, "force": f + 0j, "force_unit": "N", "acc": a + 1j, "acc_unit": "m/s^2"})
    with pytest.raises(FileFormatError, match=r"tap.mat: 1 columns \(time \[s\]\); expected three: .*; passed over: "
                                              r"force \(complex values: a spectrum or an FRF, not a time record\); "
                                              r"acc \(complex values"):
        read_tap_mat(path)
    savemat(path, {"time": t, "force": f, "force_unit": "N", "acc": a, "acc_unit": "m/s^2", "spectrum": a + 1j})
    record = read_tap_mat(path)  # a spectrum beside the record: read as before
    assert np.array_equal(record.force, f) and np.array_equal(record.response, a)


@pytest.mark.parametrize("header, said", [
    ("time [s],force [N],acceleration [m/s]", "its name says acceleration and its unit velocity"),
    ("time [s],force [N],Acc_Z [um]", "its name says acceleration and its unit displacement"),
    ("time [s],force [N],LDV velocity [m/s^2]", "its name says velocity and its unit acceleration"),
    ("Zeit [s],Kraft [N],Beschleunigung [m/s]", "its name says acceleration and its unit velocity"),
])
def test_a_response_whose_name_and_unit_say_two_quantities_is_refused(tmp_path, header, said):
    # 'acceleration [m/s]' was read as a velocity: a receptance off by i omega, modes in place, slopes wrong
    t, f, a = samples()
    path = tmp_path / "tap.csv"
    path.write_text(header + "\n" + rows([t, f, a]))
    with pytest.raises(FileFormatError, match=rf"tap.csv, line 1: column '.*': {said}; correct the one that is wrong"):
        read_tap_csv(path)


@pytest.mark.parametrize("header", ["time [s],force [N],acc1 [g]", "time [s],hammer [N],vel [mm/s]",
                                    "time [s],force [N],displacement probe [um]", "time [s],force [N],response [g]",
                                    "time [s],force [N],Accelerometer 352C23 [m/s^2]"])
def test_names_that_agree_with_their_units_or_say_nothing_read_as_before(tmp_path, header):
    t, f, a = samples()
    path = tmp_path / "tap.csv"
    path.write_text(header + "\n" + rows([t, f, a]))
    assert np.array_equal(read_tap_csv(path).force, f)
