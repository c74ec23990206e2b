"""Universal files as acquisition systems write them: quantity and units from the type-58 record.

The records here are written the way measurement front ends export FRFs
(accelerance in g/N or m/s^2 per N, mobility, mm-based units, the ordinate
type "general" with a unit label, a units record, single precision, 0 Hz
first line, several records with a coherence among them), by a writer of the
UFF 58 layout in this file (independent of pyuff, which the package reads
with).  The reference is the closed-form receptance of a damped
single-degree-of-freedom oscillator, ``H = 1 / (k - m w^2 + i c w)``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pyuff
import pytest

from substructure import FRF, Frequency
from substructure.errors import FileFormatError, SubstructureWarning
from substructure.io.frf_files import read_uff, write_uff
from substructure.io.measurements import load_measurements

M, K, C = 1.2, 4.0e7, 60.0  # kg, N/m, N s/m: a mode at 918.8 Hz
G = 9.80665  # standard gravity, m/s^2
SINGLE = 1e-5  # single precision (E13.5 keeps 6 digits): 5e-6 relative per part


def receptance(hz):
    w = 2 * np.pi * np.asarray(hz, dtype=float)
    return 1.0 / (K - M * w**2 + 1j * C * w)


def field(text, width):
    return f"{text:<{width}.{width}}"


def record_58(values, x0=0.0, dx=5.0, x=None, *, func=4, num=(12, 1, 0, "g"), den=(13, 0, 1, "N"),
              abscissa=(18, "Hz"), rsp=(1, 3), ref=(1, 3), ids=("Point1:+Z/Point1:+Z", "FRF", "NONE")):
    """One ASCII type-58 record, complex single precision, laid out as UFF 58 says (records 1-12).

    ``num`` and ``den`` are ``(specific data type, length exponent, force exponent, units label)``.
    """
    values = np.asarray(values, dtype=complex)
    even = x is None
    lines = ["    -1", "    58"]
    lines += [field(t, 80) for t in (*ids, "NONE", "NONE")][:5]
    lines.append(f"{func:5d}{1:10d}{1:5d}{0:10d} {field('Point1', 10)}{rsp[0]:10d}{rsp[1]:4d} "
                 f"{field('Point1', 10)}{ref[0]:10d}{ref[1]:4d}")
    lines.append(f"{5:10d}{values.size:10d}{int(even):10d}{x0 if even else 0.0:13.5E}{dx if even else 0.0:13.5E}"
                 f"{0.0:13.5E}")
    lines.append(f"{abscissa[0]:10d}{0:5d}{0:5d}{0:5d} {field('Frequency', 20)} {field(abscissa[1], 20)}")
    lines.append(f"{num[0]:10d}{num[1]:5d}{num[2]:5d}{0:5d} {field('Response', 20)} {field(num[3], 20)}")
    lines.append(f"{den[0]:10d}{den[1]:5d}{den[2]:5d}{0:5d} {field('Reference', 20)} {field(den[3], 20)}")
    lines.append(f"{0:10d}{0:5d}{0:5d}{0:5d} {field('NONE', 20)} {field('NONE', 20)}")
    if even:
        flat = np.column_stack([values.real, values.imag]).ravel()
    else:
        flat = np.column_stack([np.asarray(x, dtype=float), values.real, values.imag]).ravel()
    for i in range(0, flat.size, 6):
        lines.append("".join(f"{v:13.5E}" for v in flat[i:i + 6]))
    lines.append("    -1")
    return "\n".join(lines) + "\n"


def record_164(code, description, length, force):
    """A units record (type 164): factors that divide file units into SI units."""
    text = f"    -1\n   164\n{code:10d}{field(description, 20)}{2:10d}\n"
    text += (f"{length:25.16E}{force:25.16E}{1.0:25.16E}\n{273.15:25.16E}\n").replace("E", "D")
    return text + "    -1\n"


def grid(start=0.0, step=5.0, n=361):
    return start + step * np.arange(n)


def measurement_set(tmp_path, data_file, **extra):
    lines = ['name = "tap test"', "[[frf]]", 'response = "tool.tip"', 'excitation = "tool.tip"',
             f'file = "{data_file}"'] + [f"{k} = {v!r}".replace("'", '"') for k, v in extra.items()]
    path = tmp_path / "measurements.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def read_set(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        measurement = next(iter(load_measurements(path)))
    return measurement, [str(w.message) for w in caught if issubclass(w.category, SubstructureWarning)]


def assert_receptance(frf, rtol=SINGLE):
    hz = frf.frequency.hz
    expected = receptance(hz)
    err = np.abs(frf.data[:, 0, 0] - expected) / np.abs(expected)
    assert err.max() < rtol, err.max()


def test_accelerance_in_g_per_newton_from_0_hz(tmp_path):
    """The usual export: acceleration (12) in g over excitation force (13) in N, first line at 0 Hz."""
    hz = grid()
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz) / G  # in g/N
    (tmp_path / "tip.uff").write_text(record_58(accelerance), encoding="ascii")
    frf = read_uff(tmp_path / "tip.uff")
    assert frf.quantity == "accelerance"
    np.testing.assert_allclose(np.abs(frf.data[1:, 0, 0]), np.abs(accelerance[1:] * G), rtol=SINGLE)
    measurement, notes = read_set(measurement_set(tmp_path, "tip.uff"))
    assert measurement.quantity == "accelerance"
    assert measurement.frf.frequency.hz[0] == 5.0  # the 0 Hz line has no receptance: dropped, with a note
    assert any("dropped the 0 Hz line" in n and "tip.uff" in n for n in notes), notes
    assert_receptance(measurement.frf)


@pytest.mark.parametrize("num, den, scale", [
    ((12, 1, 0, "m/s^2"), (13, 0, 1, "N"), 1.0),              # numerator and denominator labels
    ((12, 1, 0, "m/s2"), (13, 0, 1, "N"), 1.0),               # the exponent written without ^
    ((12, 1, 0, "(m/s^2)/N"), (13, 0, 1, "NONE"), 1.0),       # the whole unit on the ordinate
    ((1, 1, -1, "(1/N)*(m/s^2)"), (13, 0, 1, "NONE"), 1.0),   # data type "general" with a unit label
    ((1, 0, 0, "g/kN"), (0, 0, 0, "NONE"), G / 1e3),          # general, g per kilonewton
    ((12, 1, 0, "mm/s^2"), (13, 0, 1, "N"), 1e-3),            # mm-based
])
def test_accelerance_labels_and_units(tmp_path, num, den, scale):
    hz = grid(start=10.0)
    accelerance_si = -((2 * np.pi * hz) ** 2) * receptance(hz)
    (tmp_path / "a.uff").write_text(record_58(accelerance_si / scale, x0=10.0, num=num, den=den), encoding="ascii")
    frf = read_uff(tmp_path / "a.uff")
    assert frf.quantity == "accelerance"
    assert_receptance(frf.to_receptance())


def test_general_type_with_accelerance_label_is_not_read_as_receptance(tmp_path):
    """The reported case: ordinate type general, label (1/N)*(m/s^2); it was taken as a receptance."""
    hz = grid(start=10.0)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    (tmp_path / "g.uff").write_text(record_58(accelerance, x0=10.0, num=(1, 0, 0, "(1/N)*(m/s^2)"),
                                              den=(0, 0, 0, "NONE")), encoding="ascii")
    measurement, _ = read_set(measurement_set(tmp_path, "g.uff"))
    assert measurement.quantity == "accelerance"
    assert_receptance(measurement.frf)


@pytest.mark.parametrize("num, den, scale, quantity", [
    ((11, 1, 0, "m/s"), (13, 0, 1, "N"), 1.0, "mobility"),
    ((11, 1, 0, "mm/s"), (13, 0, 1, "N"), 1e-3, "mobility"),
    ((8, 1, 0, "mm"), (13, 0, 1, "N"), 1e-3, "receptance"),
    ((8, 1, 0, "mm/N"), (13, 0, 1, "NONE"), 1e-3, "receptance"),
    ((8, 1, 0, "in"), (13, 0, 1, "lbf"), 0.0254 / 4.4482216152605, "receptance"),
])
def test_mobility_and_receptance_units(tmp_path, num, den, scale, quantity):
    hz = grid(start=10.0)
    factor = {"receptance": 1.0, "mobility": 1j * 2 * np.pi * hz}[quantity]
    (tmp_path / "m.uff").write_text(record_58(factor * receptance(hz) / scale, x0=10.0, num=num, den=den),
                                    encoding="ascii")
    frf = read_uff(tmp_path / "m.uff")
    assert frf.quantity == quantity
    assert_receptance(frf.to_receptance())


def test_units_record_without_labels(tmp_path):
    """No unit labels: the data type (acceleration) in the units of the file's type-164 record (mm, N)."""
    hz = grid(start=10.0)
    accelerance_si = -((2 * np.pi * hz) ** 2) * receptance(hz)
    text = record_164(10, "MN: mm (newton)", 1000.0, 1.0)
    text += record_58(accelerance_si * 1000.0, x0=10.0, num=(12, 1, 0, "NONE"), den=(13, 0, 1, "NONE"))
    (tmp_path / "mm.uff").write_text(text, encoding="ascii")
    frf = read_uff(tmp_path / "mm.uff")
    assert frf.quantity == "accelerance"
    assert_receptance(frf.to_receptance())


def test_several_records_with_a_coherence_among_them(tmp_path):
    """A front end's export: the FRF of each channel and its coherence; records are chosen by index."""
    hz = grid(start=10.0)
    h = receptance(hz)
    text = (record_58(h * 1e3, x0=10.0, num=(8, 1, 0, "mm"), rsp=(1, 3), ref=(1, 3))
            + record_58(np.full(hz.size, 0.98 + 0j), x0=10.0, func=6, num=(0, 0, 0, "NONE"), den=(0, 0, 0, "NONE"))
            + record_58(-0.5 * h * (2 * np.pi * hz) ** 2 / G, x0=10.0, rsp=(2, 3), ref=(1, 3)))
    (tmp_path / "run.uff").write_text(text, encoding="ascii")
    assert_receptance(read_uff(tmp_path / "run.uff", record=0))
    cross = read_uff(tmp_path / "run.uff", record=2)
    assert cross.quantity == "accelerance" and cross.outputs == ("node2:dir3",)
    np.testing.assert_allclose(cross.to_receptance().data[:, 0, 0], 0.5 * h, rtol=SINGLE)
    with pytest.raises(FileFormatError, match=r"run.uff, type-58 record 1: a coherence \(function type 6\)"):
        read_uff(tmp_path / "run.uff", record=1)
    with pytest.raises(FileFormatError, match="coherence"):
        read_uff(tmp_path / "run.uff")


def test_uneven_abscissa_and_an_abscissa_in_rad_per_s(tmp_path):
    hz = np.array([10.0, 12.5, 20.0, 50.0, 400.0, 900.0, 918.0, 1000.0])
    text = record_58(receptance(hz), x=2 * np.pi * hz, num=(8, 1, 0, "m"), abscissa=(18, "rad/s"))
    (tmp_path / "w.uff").write_text(text, encoding="ascii")
    frf = read_uff(tmp_path / "w.uff")
    np.testing.assert_allclose(frf.frequency.hz, hz, rtol=SINGLE)
    np.testing.assert_allclose(frf.data[:, 0, 0], receptance(hz), rtol=SINGLE)


@pytest.mark.parametrize("kwargs, message", [
    ({"num": (0, 0, 0, "NONE"), "den": (13, 0, 1, "NONE")}, "does not say whether it holds a receptance"),
    ({"num": (11, 1, 0, "g"), "den": (13, 0, 1, "N")}, "data type says mobility .* unit label 'g' .* an accelerance"),
    ({"num": (12, 1, 0, "kg"), "den": (13, 0, 1, "N")}, "'kg' is not a displacement, velocity or acceleration"),
    ({"num": (12, 1, 0, "furlong/fortnight"), "den": (13, 0, 1, "N")}, "data type says accelerance .* mobility"),
    ({"num": (12, 1, 0, "bananas"), "den": (13, 0, 1, "N")}, "cannot read the unit label 'bananas'"),
    ({"num": (12, 1, 0, "g"), "den": (12, 1, 0, "g")}, "denominator is an acceleration"),
    ({"num": (2, 0, 0, "Pa"), "den": (13, 0, 1, "N")}, "ordinate is a stress"),
    ({"func": 1, "abscissa": (17, "s")}, r"a time response \(function type 1\)"),
    ({"func": 12}, r"a spectrum \(function type 12\)"),
    ({"abscissa": (17, "s")}, "the abscissa is time, not frequency"),
])
def test_records_that_do_not_say_or_are_not_frfs_are_refused(tmp_path, kwargs, message):
    hz = grid(start=10.0, n=20)
    (tmp_path / "x.uff").write_text(record_58(receptance(hz), x0=10.0, **kwargs), encoding="ascii")
    with pytest.raises(FileFormatError, match=message):
        read_uff(tmp_path / "x.uff")


def test_a_record_that_does_not_say_is_read_when_the_quantity_is_given(tmp_path):
    hz = grid(start=10.0)
    (tmp_path / "x.uff").write_text(record_58(receptance(hz), x0=10.0, num=(1, 1, 0, "NONE"),
                                              den=(1, 0, 1, "NONE")), encoding="ascii")
    with pytest.raises(FileFormatError, match=r"measurements.toml.*frf\[0\].file.*quantity"):
        load_measurements(measurement_set(tmp_path, "x.uff"))
    measurement, _ = read_set(measurement_set(tmp_path, "x.uff", quantity="receptance"))
    assert_receptance(measurement.frf)
    # a quantity that contradicts the record is refused, not taken
    (tmp_path / "y.uff").write_text(record_58(receptance(hz), x0=10.0, num=(8, 1, 0, "m"), den=(13, 0, 1, "N")),
                                    encoding="ascii")
    with pytest.raises(FileFormatError, match="quantity given is accelerance, but its unit label 'm'"):
        load_measurements(measurement_set(tmp_path, "y.uff", quantity="accelerance"))


def test_dead_channel_is_refused_naming_the_file_and_the_frf(tmp_path):
    hz = grid(start=10.0, n=30)
    (tmp_path / "dead.uff").write_text(record_58(np.zeros(hz.size), x0=10.0), encoding="ascii")
    with pytest.raises(FileFormatError, match=r"measurements.toml.*frf\[0\]\.file.*dead.uff.*every value is 0, a "
                                              r"dead channel"):
        load_measurements(measurement_set(tmp_path, "dead.uff"))
    (tmp_path / "dead.csv").write_text("frequency_hz,real,imag\n10,0,0\n20,0.0,-0.0\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.file.*dead.csv: every value is 0"):
        load_measurements(measurement_set(tmp_path, "dead.csv"))


def test_truncated_file_says_so(tmp_path):
    hz = grid(start=10.0)
    text = record_58(receptance(hz), x0=10.0, num=(8, 1, 0, "m")) * 2
    lines = text.splitlines()
    for keep in (len(lines) - 1, len(lines) - 40, 30, 8):
        (tmp_path / "cut.uff").write_text("\n".join(lines[:keep]) + "\n", encoding="ascii")
        with pytest.raises(FileFormatError, match="cut.uff: the file is truncated"):
            read_uff(tmp_path / "cut.uff")


def binary_record_58(values, x0, dx, num, den):
    """A binary type-58 record (58b): the ASCII header, then little-endian doubles, then -1."""
    values = np.asarray(values, dtype=complex)
    data = np.column_stack([values.real, values.imag]).ravel().astype("<f8").tobytes()
    ascii_part = record_58(values[:1], x0=x0, dx=dx, num=num, den=den).splitlines()[2:13]
    ascii_part[6] = f"{6:10d}{values.size:10d}{1:10d}{x0:13.5E}{dx:13.5E}{0.0:13.5E}"
    header = f"    -1\n    58b{1:6d}{2:6d}{11:12d}{len(data):12d}{0:6d}{0:6d}{0:12d}{0:12d}\n"
    return (header + "\n".join(ascii_part) + "\n").encode("ascii") + data + b"    -1\n"


def test_files_that_are_not_universal_files(tmp_path):
    (tmp_path / "photo.uff").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(100))
    with pytest.raises(FileFormatError, match="photo.uff: not a universal file"):
        read_uff(tmp_path / "photo.uff")
    (tmp_path / "nodes.uff").write_text("    -1\n    15\n         1         0         0         0  0.0  0.0  0.0\n"
                                        "    -1\n", encoding="ascii")
    with pytest.raises(FileFormatError, match=r"nodes.uff: no type-58 record \(FRF\); the file holds record types 15"):
        read_uff(tmp_path / "nodes.uff")


def test_binary_records_and_a_spectrum_file(tmp_path):
    hz = grid(start=10.0)
    mobility = 1j * 2 * np.pi * hz * receptance(hz)
    (tmp_path / "b.uff").write_bytes(binary_record_58(mobility, 10.0, 5.0, (11, 1, 0, "m/s"), (13, 0, 1, "N")))
    frf = read_uff(tmp_path / "b.uff")
    assert frf.quantity == "mobility"
    assert_receptance(frf.to_receptance(), rtol=1e-12)
    (tmp_path / "s.uff").write_text(record_58(np.abs(mobility) + 0j, x0=10.0, func=2), encoding="ascii")
    with pytest.raises(FileFormatError, match=r"an auto spectrum \(function type 2\)"):
        read_uff(tmp_path / "s.uff")


@pytest.mark.parametrize("dofs, length, den_length", [(("y", "y"), 1, 0), (("theta", "y"), 0, 0),
                                                       (("y", "theta"), 1, 1), (("theta", "theta"), 0, 1)])
@pytest.mark.parametrize("quantity", ["receptance", "mobility", "accelerance"])
def test_records_written_by_the_project_carry_their_unit_exponents(tmp_path, dofs, length, den_length, quantity):
    """Other programs read the quantity and the units from the record itself (UFF 58, records 9 and 10)."""
    f = Frequency.from_range("10 Hz", "100 Hz", "10 Hz")
    labels = (f"a:{dofs[0]}",), (f"b:{dofs[1]}",)
    frf = FRF.single(f, receptance(f.hz) * (1 + 0.1j), output=labels[0][0], input=labels[1][0], quantity=quantity)
    write_uff(frf, tmp_path / "ours.uff")
    raw = pyuff.UFF(str(tmp_path / "ours.uff")).read_sets(0)
    assert raw["ordinate_spec_data_type"] == {"receptance": 8, "mobility": 11, "accelerance": 12}[quantity]
    assert (raw["ordinate_len_unit_exp"], raw["ordinate_force_unit_exp"]) == (length, 0)
    assert raw["orddenom_spec_data_type"] == 13
    assert (raw["orddenom_len_unit_exp"], raw["orddenom_force_unit_exp"]) == (den_length, 1)
    assert raw["ordinate_axis_units_lab"].strip() == frf.unit(*labels[0], *labels[1])
    back = read_uff(tmp_path / "ours.uff")
    assert back.quantity == quantity and back.outputs == labels[0] and back.inputs == labels[1]
    np.testing.assert_allclose(back.data, frf.data, rtol=1e-11)


@pytest.mark.parametrize("label", ["dB", "dB g/N", "dB re 1 g/N"])
@pytest.mark.parametrize("quantity", [None, "accelerance"])
def test_ordinate_in_decibels_is_refused_even_with_the_quantity(tmp_path, label, quantity):
    """A magnitude in dB (its reference not in the file) was a raw pint error, or with the quantity given
    read as linear values in SI units."""
    hz = grid(start=10.0, n=20)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    (tmp_path / "db.uff").write_text(record_58(accelerance, x0=10.0, num=(12, 1, 0, label)), encoding="ascii")
    with pytest.raises(FileFormatError, match=r"db\.uff, type-58 record 0: .*decibels"):
        read_uff(tmp_path / "db.uff", quantity=quantity)


@pytest.mark.parametrize("label", ["%", "deg", "1", "V/V", "dB", "dB g/N"])
def test_abscissa_labelled_with_a_ratio_is_not_taken_for_hz(tmp_path, label):
    """An abscissa whose unit is a ratio, an angle or a percentage was read as Hz."""
    hz = grid(start=10.0, n=20)
    (tmp_path / "x.uff").write_text(record_58(receptance(hz), x0=10.0, num=(8, 1, 0, "m"), abscissa=(18, label)),
                                    encoding="ascii")
    with pytest.raises(FileFormatError, match=r"x\.uff, type-58 record 0: .*abscissa"):
        read_uff(tmp_path / "x.uff")


@pytest.mark.parametrize("rsp, response, kind", [
    ((1, 3), "tool.tip:theta", "translation"),   # a Z sensor taken for a rotation
    ((1, 6), "tool.tip", "rotation"),             # a rotation (+Z) taken for y
    ((1, -4), "tool.tip:y", "rotation"),
])
def test_record_direction_of_another_kind_than_the_tables_dof_is_refused(tmp_path, rsp, response, kind):
    """Records of other programs are taken for the table's points; a rotation read as y (or a translation as
    theta) went through silently."""
    hz = grid(start=10.0, n=20)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    (tmp_path / "d.uff").write_text(record_58(accelerance, x0=10.0, num=(12, 0, 0, "NONE"), den=(13, 0, 1, "NONE"),
                                              rsp=rsp), encoding="ascii")
    path = measurement_set(tmp_path, "d.uff")
    text = path.read_text(encoding="utf-8").replace('response = "tool.tip"', f'response = "{response}"')
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=rf"frf\[0\]\.response: .*d\.uff, type-58 record 0: its response is "
                                              rf"a {kind} \(direction code {abs(rsp[1])}\)"):
        load_measurements(path)


def test_record_direction_of_the_tables_kind_is_read(tmp_path):
    """A translation in any axis (here -Z) is the table's y, the sign of the data turned."""
    hz = grid(start=10.0, n=20)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    (tmp_path / "d.uff").write_text(record_58(accelerance, x0=10.0, num=(12, 1, 0, "m/s^2"), rsp=(1, -3)),
                                    encoding="ascii")
    measurement, _ = read_set(measurement_set(tmp_path, "d.uff"))
    np.testing.assert_allclose(measurement.frf.data[:, 0, 0], -receptance(hz), rtol=SINGLE)


def test_a_file_of_spectra_and_an_frf_read_whole_names_the_frfs_index(tmp_path):
    """An analyser's export, auto spectrum then FRF: read without the record, the error said to export the FRFs
    again, though the file holds one."""
    hz = grid(start=10.0, n=20)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    (tmp_path / "test.uff").write_text(record_58(np.abs(accelerance) ** 2 + 0j, x0=10.0, func=2)
                                       + record_58(accelerance, x0=10.0, num=(12, 1, 0, "m/s^2")), encoding="ascii")
    with pytest.raises(FileFormatError, match=r"record 0: an auto spectrum .*; the file's FRFs are type-58 "
                                              r"record\(s\) 1: give the index of the one meant \(record = 1"):
        read_uff(tmp_path / "test.uff")
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.file: .*record = 1 in the measurement set"):
        load_measurements(measurement_set(tmp_path, "test.uff"))
    frf, _ = read_set(measurement_set(tmp_path, "test.uff", record=1))
    assert_receptance(frf.frf)


def _roving_hammer_file(tmp_path, pairs):
    """One file of several records, response node and reference node each (direction +Z), as a roving-hammer
    test exports them; each record's values scaled so that no two are the same."""
    hz = grid(start=10.0, n=20)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    text = "".join(record_58((1 + 0.1 * i) * accelerance, x0=10.0, num=(12, 1, 0, "m/s^2"), rsp=(out, 3),
                             ref=(ref, 3)) for i, (out, ref) in enumerate(pairs))
    (tmp_path / "rove.uff").write_text(text, encoding="ascii")


def _set_of(tmp_path, rows):
    lines = ['name = "roving hammer"']
    for response, excitation, record in rows:
        lines += ["[[frf]]", f'response = "{response}"', f'excitation = "{excitation}"', 'file = "rove.uff"',
                  f"record = {record}"]
    path = tmp_path / "measurements.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        measurements = load_measurements(path)
    return measurements, [str(w.message) for w in caught if issubclass(w.category, SubstructureWarning)]


ROVING = [("tool.tip", "tool.tip", 0), ("tool.tip", "tool.tip-20 mm", 1), ("tool.tip", "holder.tip", 2)]


def test_records_whose_nodes_agree_with_the_tables_are_read_without_a_word(tmp_path):
    _roving_hammer_file(tmp_path, [(1, 1), (1, 2), (1, 3)])
    measurements, said = _set_of(tmp_path, ROVING)
    assert said == [] and len(measurements) == 3


def test_a_driving_point_read_from_a_cross_record_is_named(tmp_path):
    """Record indices counted from 1: the driving point's record 1 is the cross FRF node 1 / node 2.  The nodes
    said so, but the set read the cross FRF as the tool tip's driving point without a word."""
    _roving_hammer_file(tmp_path, [(1, 1), (1, 2), (1, 3)])
    _, said = _set_of(tmp_path, [("tool.tip", "tool.tip", 1), ("tool.tip", "tool.tip-20 mm", 2)])
    assert any("frf[0]: rove.uff, type-58 record 1 has its response at node 1 (direction 3) and its reference at "
               "node 2 (direction 3), but this table measures the driving point tool.tip:y; check the record index "
               "(0-based)" in s for s in said), said


def test_a_cross_frf_read_from_a_driving_point_record_is_named(tmp_path):
    _roving_hammer_file(tmp_path, [(9, 9), (1, 1), (1, 2), (1, 3)])
    _, said = _set_of(tmp_path, ROVING)
    assert any("frf[1]: rove.uff, type-58 record 1: its excitation is node 1, read as tool.tip-20 mm, but its "
               "response is that node too, read as tool.tip" in s for s in said), said


def test_one_node_read_as_two_points_is_named(tmp_path):
    """Records off by one among cross FRFs: node 2 read as the point 20 mm back in one table and as the holder's
    tip in another."""
    _roving_hammer_file(tmp_path, [(1, 1), (1, 2), (1, 3), (2, 2)])
    _, said = _set_of(tmp_path, [("tool.tip", "tool.tip", 0), ("tool.tip", "holder.tip", 1),
                                 ("tool.tip-20 mm", "tool.tip-20 mm", 3)])
    assert len(said) == 2, said  # node 2 as two points, as the response and as the reference
    for role, text in zip(("response", "excitation"), said):
        assert (f"frf[2]: rove.uff, type-58 record 3: its {role} is node 2, read as tool.tip-20 mm, but frf[1] "
                "reads node 2 of this file as holder.tip; a node is one point") in text


def test_one_point_read_from_two_nodes_is_named(tmp_path):
    _roving_hammer_file(tmp_path, [(1, 1), (1, 2), (1, 3)])
    _, said = _set_of(tmp_path, [("tool.tip", "tool.tip", 0), ("tool.tip", "holder.tip", 1),
                                 ("holder.tip", "tool.tip", 2)])
    assert any("frf[2]: rove.uff, type-58 record 2: its excitation tool.tip is node 3, but in frf[0] tool.tip is "
               "node 1 of this file" in s for s in said), said


def test_nodes_of_another_configuration_are_not_compared(tmp_path):
    """Node 2 is the holder's tip with the tool on and a point of the tool in a test without it: another test,
    numbered anew (here in one file)."""
    _roving_hammer_file(tmp_path, [(1, 1), (1, 2), (2, 2)])
    lines = ['name = "two tests"', "[[frf]]", 'response = "tool.tip"', 'excitation = "tool.tip"',
             'file = "rove.uff"', "record = 0", "[[frf]]", 'response = "tool.tip"', 'excitation = "holder.tip"',
             'file = "rove.uff"', "record = 1", "[[frf]]", 'response = "holder.tip-5 mm"',
             'excitation = "holder.tip-5 mm"', 'file = "rove.uff"', "record = 2", 'removed = ["tool"]']
    path = tmp_path / "measurements.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(load_measurements(path)) == 3


def test_a_driving_point_from_a_record_of_two_directions_is_named(tmp_path):
    """Node 1 in Z over node 1 in X: a cross-axis FRF, not a driving point (-Z over +Z is one, its sign turned)."""
    hz = grid(start=10.0, n=20)
    accelerance = -((2 * np.pi * hz) ** 2) * receptance(hz)
    for ref, words in (((1, 1), ["reference at node 1 (direction 1)"]), ((1, -3), [])):
        (tmp_path / "d.uff").write_text(record_58(accelerance, x0=10.0, num=(12, 1, 0, "m/s^2"), rsp=(1, 3),
                                                  ref=ref), encoding="ascii")
        _, said = read_set(measurement_set(tmp_path, "d.uff"))
        assert [w for w in words if any(w in s for s in said)] == words and len(said) == len(words), said
