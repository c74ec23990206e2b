"""Second hostile round (issue 10 follow-up): files as acquisition systems and careless hands write them.

Each test is an input that gave a wrong number, a hang, an internal error
or an unhelpful refusal, with what must happen now.  References are the
closed-form single-degree-of-freedom receptance of tests/test_uff_units.py
and values written here by hand.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from substructure.cli import main
from substructure.errors import FileFormatError
from substructure.io.assembly_toml import load_assembly, loads_assembly
from substructure.io.frf_files import read_uff
from substructure.io.measurements import load_measurements

from test_uff_units import G, assert_receptance, grid, measurement_set, read_set, receptance, record_58

from pathlib import Path

EXAMPLE = Path(__file__).parent / "data" / "formats_example.toml"
EXAMPLE_TEXT = EXAMPLE.read_text(encoding="utf-8")
TOOL_SEGMENT = '{ length = "30 mm", od = "12 mm" },'


# -- universal files ------------------------------------------------------------------------------


@pytest.mark.parametrize("rsp, ref, sign", [(-3, 3, -1), (3, -3, -1), (-3, -3, 1), (-2, 2, -1)])
def test_negative_direction_codes_flip_the_sign(tmp_path, rsp, ref, sign):
    """A sensor mounted along -Z (LMS writes '-Z') measures -H in +Z: the reader gives +H, never -H."""
    hz = grid(5.0)
    (tmp_path / "tip.uff").write_text(
        record_58(sign * receptance(hz), x0=5.0, num=(8, 1, 0, "m"), rsp=(1, rsp), ref=(1, ref)), encoding="ascii")
    frf = read_uff(tmp_path / "tip.uff")
    assert_receptance(frf)
    assert frf.outputs[0].endswith(f"dir{abs(rsp)}") or frf.outputs[0].endswith(":y")
    measurement, _ = read_set(measurement_set(tmp_path, "tip.uff"))
    assert_receptance(measurement.frf)


@pytest.mark.parametrize("label, scale", [("RPM", 60.0), ("HZ", 1.0), ("RAD/S", 2 * np.pi)])
def test_abscissa_labels_in_capitals_are_read(tmp_path, label, scale):
    hz = grid(5.0)
    (tmp_path / "tip.uff").write_text(
        record_58(receptance(hz), x0=5.0 * scale, dx=5.0 * scale, num=(8, 1, 0, "m"), abscissa=(18, label)),
        encoding="ascii")
    frf = read_uff(tmp_path / "tip.uff")
    np.testing.assert_allclose(frf.frequency.hz, hz, rtol=1e-5)  # 6 digits of an E13.5 abscissa
    assert_receptance(frf, rtol=1e-3)  # (the 6-digit abscissa moves a line by up to 5e-6 near the mode)


def test_an_unreadable_abscissa_label_is_refused_not_taken_as_hz(tmp_path):
    hz = grid(5.0)
    (tmp_path / "tip.uff").write_text(
        record_58(receptance(hz), x0=5.0, num=(8, 1, 0, "m"), abscissa=(18, "Umdrehungen")), encoding="ascii")
    with pytest.raises(FileFormatError, match="abscissa's unit label 'Umdrehungen'.*Hz"):
        read_uff(tmp_path / "tip.uff")


def test_a_record_of_one_line_is_refused(tmp_path):
    (tmp_path / "one.uff").write_text(record_58(receptance([100.0]), x0=100.0, num=(8, 1, 0, "m")),
                                      encoding="ascii")
    with pytest.raises(FileFormatError, match="1 frequency line"):
        read_uff(tmp_path / "one.uff")


def test_one_record_used_for_two_measurements_is_refused(tmp_path):
    hz = grid(5.0)
    (tmp_path / "two.uff").write_text(
        record_58(receptance(hz), x0=5.0, num=(8, 1, 0, "m"))
        + record_58(2 * receptance(hz), x0=5.0, num=(8, 1, 0, "m"), rsp=(2, 3)), encoding="ascii")
    text = ('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "two.uff"\nrecord = 1\n'
            '[[frf]]\nresponse = "holder.tip"\nexcitation = "tool.tip"\nfile = "./two.uff"\nrecord = 1\n')
    (tmp_path / "m.toml").write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"frf\[1\]\.record: reads the same data as frf\[0\]"):
        load_measurements(tmp_path / "m.toml")
    (tmp_path / "m.toml").write_text(text.replace("record = 1\n", "record = 0\n", 1), encoding="utf-8")
    assert len(load_measurements(tmp_path / "m.toml")) == 2  # two records of one file are fine


# -- text encodings ---------------------------------------------------------------------------------


def test_utf16_text_with_its_byte_order_mark_is_read(tmp_path):
    """Windows tools ("Unicode text") write UTF-16 with a byte-order mark: unambiguous, so read."""
    (tmp_path / "a.toml").write_text(EXAMPLE_TEXT, encoding="utf-16")
    assert load_assembly(tmp_path / "a.toml") == load_assembly(EXAMPLE)
    (tmp_path / "b.toml").write_bytes(b"\xff\xfe" + b"\x00\xd8")  # a lone surrogate: not UTF-16
    with pytest.raises(FileFormatError, match="not UTF-16 text"):
        load_assembly(tmp_path / "b.toml")


# -- assembly files: sizes the beam model cannot take -------------------------------------------------


@pytest.mark.parametrize("segment", [
    '{ length = "30 mm", od = "1e300 mm" },',        # was an OverflowError (internal error)
    '{ length = "30 mm", od = "1e-300 mm" },',       # was a NaN in the beam chain (internal error)
    '{ length = "5 m", od = "1e-12 m" },',           # hung
    '{ length = "1e-30 mm", od = "12 mm" },',
    '{ length = "30 mm", od = "12 mm", id = "1e-9 mm" },',
    '{ length = "30 mm", od = "12 mm", od_tip = "2 km" },',
])
def test_sizes_outside_the_beam_models_range_are_refused_on_reading(segment):
    text = EXAMPLE_TEXT.replace(TOOL_SEGMENT, segment, 1)
    with pytest.raises(FileFormatError, match=r"components\[2\]\.segments\[0\]\.\w+: got .*1 um to 1 km"):
        loads_assembly(text)


def test_sizes_at_the_ends_of_the_range_are_accepted():
    for segment in ('{ length = "1 um", od = "12 mm" },', '{ length = "30 mm", od = "12 mm", id = "0.001 mm" },'):
        loads_assembly(EXAMPLE_TEXT.replace(TOOL_SEGMENT, segment, 1))


def test_taper_steps_beyond_the_limit_are_refused_before_allocating():
    text = EXAMPLE_TEXT.replace(TOOL_SEGMENT, '{ length = "30 mm", od = "12 mm", od_tip = "10 mm", '
                                              'taper_steps = 1000000000 },', 1)
    with pytest.raises(FileFormatError, match=r"taper_steps: got 1000000000; expected at most 10,000"):
        loads_assembly(text)


def test_the_command_refuses_a_huge_diameter_in_one_line(tmp_path, capsys):
    (tmp_path / "a.toml").write_text(EXAMPLE_TEXT.replace(TOOL_SEGMENT, '{ length = "30 mm", od = "1e300 mm" },', 1),
                                     encoding="utf-8")
    status = main(["frf", str(tmp_path / "a.toml"), "--at", "tool.tip", "--grid", "100:200:50", "--json"])
    out, err = capsys.readouterr()
    assert status == 1 and out == ""
    assert err.count("\n") == 1 and "internal error" not in err and "od: got '1e300 mm'" in err


# -- CSV exports of other programs --------------------------------------------------------------------

HZ = np.arange(100.0, 1500.0, 10.0)
H = receptance(HZ)
W = 2 * np.pi * HZ


def _export(tmp_path, header, columns, sep=",", decimal=".", prefix="", encoding="utf-8", newline="\n"):
    rows = [sep.join(f"{v!r}".replace(".", decimal) for v in map(float, row)) for row in zip(*columns)]
    path = tmp_path / "export.csv"
    path.write_bytes((prefix + newline.join([header, *rows]) + newline).encode(encoding))
    return path


@pytest.mark.parametrize("header, columns, kw, quantity", [
    ("Frequency [Hz];Real [m/N];Imag [m/N];", (HZ, H.real, H.imag, [""] * HZ.size), {"sep": ";", "decimal": ","},
     "receptance"),
    ('"Frequency (Hz)"\t"Re (mm/N)"\t"Im (mm/N)"', (HZ, 1e3 * H.real, 1e3 * H.imag), {"sep": "\t"}, "receptance"),
    ("frequency [kHz],real [µm/N],imag [µm/N]", (HZ / 1e3, 1e6 * H.real, 1e6 * H.imag),
     {"prefix": "# exported 2026-11-23\n# channel 3\n", "newline": "\r\n"}, "receptance"),
    ("Frequency [Hz];Magnitude [g/N];Phase [deg]", (HZ, np.abs(W**2 * H) / G, np.degrees(np.angle(-(W**2) * H))),
     {"sep": ";", "decimal": ",", "encoding": "utf-16"}, "accelerance"),
    ("freq [rad/s],magnitude [(m/s^2)/N],phase [rad]", (W, np.abs(W**2 * H), np.angle(-(W**2) * H)), {},
     "accelerance"),
    ("frequency_hz,real [m/s/N],imag [m/s/N]", (HZ, (1j * W * H).real, (1j * W * H).imag), {}, "mobility"),
    # units in a row of their own under the names, names of several words (as analysers export an FRF)
    ('"Frequency","FRF Real","FRF Imag"\n"Hz","(m/s2)/N","(m/s2)/N"', (HZ, (-(W**2) * H).real, (-(W**2) * H).imag),
     {}, "accelerance"),
    ("Frequency\tH1 Real\tH1 Imag\nHz\tmm/N\tmm/N", (HZ, 1e3 * H.real, 1e3 * H.imag), {"sep": "\t"}, "receptance"),
    ("Freq;Re;Im\n[Hz];[g/N];[g/N]", (HZ, (-(W**2) * H).real / G, (-(W**2) * H).imag / G),
     {"sep": ";", "decimal": ","}, "accelerance"),
])
def test_exports_with_units_in_the_header_are_read_and_converted(tmp_path, header, columns, kw, quantity):
    from substructure.io.frf_files import read_csv

    path = _export(tmp_path, header, [c for c in columns if not isinstance(c, list)], **kw)
    if len(columns) == 4:  # the trailing empty column of a spreadsheet
        path.write_bytes(path.read_bytes().replace(b"\n", b";\n").replace(b"];;\n", b"];\n"))
    frf = read_csv(path)
    assert frf.quantity == quantity
    np.testing.assert_allclose(frf.frequency.hz, HZ, rtol=1e-12)
    np.testing.assert_allclose(frf.to_receptance().data[:, 0, 0], H, rtol=1e-9, atol=1e-9 * np.abs(H).max())
    # a measurement set takes the quantity from the header and converts to a receptance
    (tmp_path / "m.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
                                     'file = "export.csv"\n', encoding="utf-8")
    measurement = next(iter(load_measurements(tmp_path / "m.toml")))
    assert measurement.quantity == quantity
    np.testing.assert_allclose(measurement.frf.data[:, 0, 0], H, rtol=1e-9, atol=1e-9 * np.abs(H).max())


@pytest.mark.parametrize("header, pattern", [
    ("frequency_hz,magnitude_db,phase_deg", "dB of what"),
    ("Frequency [Hz],Magnitude [dB],Phase [deg]", "dB of what"),
    ("Frequency [Hz],Magnitude [m/N],Phase", "give the phase's unit"),
    ("Frequency,Real [m/N],Imag [m/N]", "has no unit"),
    ("Frequency [mm],Real [m/N],Imag [m/N]", "not a frequency unit"),
    ("Frequency [Hz],Real [m/N],Imag [mm/N]", "different units"),
    ("Frequency [Hz],Real [N/m],Imag [N/m]", "not that of a receptance"),
    ("Frequency [Hz],Coherence,Imag", "in this order"),  # a coherence goes after the FRF's columns
    ("Frequency [Hz],Imag [m/N],Real [m/N]", "in this order"),
    ("Frequency [Hz],Real Imag [m/N],Imag [m/N]", "column 'Real Imag \\[m/N\\]'; expected frequency"),  # two kinds
    ("Frequency,Real,Imag\nHz,,m/N", "has no unit|different units"),  # a unit row with a unit missing
])
def test_ambiguous_exports_are_refused_with_what_to_give(tmp_path, header, pattern):
    from substructure.io.frf_files import read_csv

    path = _export(tmp_path, header, (HZ, H.real, H.imag))
    with pytest.raises(FileFormatError, match=pattern):
        read_csv(path)


@pytest.mark.parametrize("header, scale, kw", [
    ("Frequency [Hz];Real [m/N];Imag [m/N];Coherence", 1.0, {"sep": ";", "decimal": ","}),
    ("Frequency (Hz)\tMagnitude (m/N)\tPhase (deg)\tCoh (%)", 100.0, {"sep": "\t"}),
    ("frequency_hz,real [m/N],imag [m/N],gamma^2 [-]", 1.0, {}),
])
def test_exports_with_a_coherence_column_carry_it_into_the_measurement(tmp_path, header, scale, kw):
    """Analysers export the coherence beside the FRF; it is read (in [0, 1], or in % with its unit) and the
    measurement set gives it to the measurement, as for the package's own files."""
    from substructure.io.frf_files import read_csv_with_coherence

    gamma = np.linspace(0.5, 1.0, HZ.size)
    values = (np.abs(H), np.degrees(np.angle(H))) if "Magnitude" in header else (H.real, H.imag)
    path = _export(tmp_path, header, (HZ, *values, gamma * scale), **kw)
    frf, coherence = read_csv_with_coherence(path)
    np.testing.assert_allclose(coherence, gamma, rtol=1e-12)
    np.testing.assert_allclose(frf.data[:, 0, 0], H, rtol=1e-9, atol=1e-9 * np.abs(H).max())
    (tmp_path / "m.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
                                     'file = "export.csv"\naverages = 5\n', encoding="utf-8")
    measurement = next(iter(load_measurements(tmp_path / "m.toml")))
    np.testing.assert_allclose(measurement.coherence, gamma, rtol=1e-12)


@pytest.mark.parametrize("header, gamma, pattern", [
    ("Frequency [Hz],Real [m/N],Imag [m/N],Coherence", 1.5, r"line 2: Coherence is '1.5'; expected a coherence "
                                                             r"in \[0, 1\]$"),
    ("Frequency [Hz],Real [m/N],Imag [m/N],Coherence [%]", 150.0, r"expected a coherence in \[0, 1\] \(0 to 100 %\)"),
    ("Frequency [Hz],Real [m/N],Imag [m/N],Coherence [dB]", 0.5, r"a coherence has no unit \(or %\); got 'dB'"),
    ("Frequency [Hz],Real [m/N],Imag [m/N],Coherence,Coherence", 0.5, "in this order"),
])
def test_a_coherence_column_out_of_range_is_refused_naming_the_line(tmp_path, header, gamma, pattern):
    from substructure.io.frf_files import read_csv

    columns = (HZ, H.real, H.imag, np.full(HZ.size, gamma)) + ((np.full(HZ.size, gamma),) if header.count("Coh") > 1
                                                             else ())
    path = _export(tmp_path, header, columns)
    with pytest.raises(FileFormatError, match=pattern):
        read_csv(path)


def test_an_export_whose_units_contradict_the_quantity_given_is_refused(tmp_path):
    from substructure.io.frf_files import read_csv

    path = _export(tmp_path, "Frequency [Hz],Real [g/N],Imag [g/N]", (HZ, H.real, H.imag))
    with pytest.raises(FileFormatError, match="those of an accelerance, but the quantity given is receptance"):
        read_csv(path, quantity="receptance")


def test_no_stability_limit_tells_a_command_line_user_the_option(tmp_path, capsys):
    """A cutting coefficient of 1e-300 Pa leaves no finite limit: the lobes are given, the recommendation is
    absent, and its reason names --max-depth."""
    from substructure import Frequency
    from substructure.io.frf_files import write_csv

    frf = load_assembly(EXAMPLE).receptance("tool.tip:y", frequency=Frequency.from_range("200 Hz", "3000 Hz", "20 Hz"))
    write_csv(frf, tmp_path / "tip.csv")
    status = main(["lobes", "--frf", str(tmp_path / "tip.csv"), "--teeth", "4", "--diameter", "12 mm",
                   "--immersion", "0.5", "--kt", "1e-300 MPa", "--kr", "0.3", "--speeds", "5000:8000:100", "--json"])
    out, err = capsys.readouterr()
    result = json.loads(out)
    assert status == 0 and result["recommended"] is None and "--max-depth" in result["no_recommendation_reason"]
    assert not np.isfinite(np.array(result["depth_limit_m"], dtype=float)).any()


def test_frf_from_csv_reads_the_quantity_from_the_header_as_read_csv_does(tmp_path):
    # `lobes --frf` reads through FRF.from_csv: an export in g/N is an accelerance, converted, not
    # taken as a receptance in m/N
    from substructure import FRF

    path = _export(tmp_path, "Frequency [Hz],Real [g/N],Imag [g/N]",
                   (HZ, (-(W**2) * H).real / G, (-(W**2) * H).imag / G))
    frf = FRF.from_csv(path)
    assert frf.quantity == "accelerance"
    np.testing.assert_allclose(frf.to_receptance().data[:, 0, 0], H, rtol=1e-9, atol=1e-9 * np.abs(H).max())
    with pytest.raises(FileFormatError, match="quantity given is receptance"):
        FRF.from_csv(path, quantity="receptance")


def test_a_record_without_its_closing_line_is_refused_not_merged(tmp_path):
    # pyuff takes the next record's opening -1 as the closing one and the second record is lost
    hz = grid(5.0)
    first = record_58(receptance(hz), x0=hz[0], num=(8, 1, 0, "m"))
    second = record_58(2 * receptance(hz), x0=hz[0], num=(8, 1, 0, "m"), rsp=(2, 3))
    path = tmp_path / "two.uff"
    path.write_text(first.rsplit("    -1\n", 1)[0] + second, encoding="ascii")
    with pytest.raises(FileFormatError, match=r"line \d+: text outside any record .*closes the record before it"):
        read_uff(path)
    path.write_text(first + second, encoding="ascii")     # intact, both records are read
    assert read_uff(path).shape[1:] == (2, 1)
