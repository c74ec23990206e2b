"""Measured FRFs in MATLAB files of signal structures (Simcenter Testlab exports): read into a measurement set with
their quantity from the unit, their coherence beside them, checked against the closed form of a one-mode
receptance."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.io import savemat

from substructure.errors import FileFormatError
from substructure.frf.files.mat_reader import read_mat, read_mat_coherence
from substructure.io.measurements import load_measurements

G = 9.80665
HZ = 100.0 + 2.0 * np.arange(200)
W = 2 * np.pi * HZ
H = 1.0 / (1e7 - 0.5 * W**2 + 1j * 300.0 * W)  # a receptance (m/N), closed form
GAMMA = np.clip(0.6 + 0.4 * np.cos(HZ / 60.0) ** 2, 0.0, 1.0)


def struct(values, label, name, factor=1.0, x_label="Hz", start=HZ[0], step=2.0, kind="FRF"):
    """A signal structure as Testlab exports it: the values times ``factor`` are in ``label``."""
    return {"x_values": {"start_value": start, "increment": step, "number_of_values": np.shape(values)[0],
                         "quantity": {"label": x_label}},
            "y_values": {"values": values, "quantity": {"label": label,
                                                        "unit_transformation": {"factor": factor, "offset": 0.0}}},
            "function_record": {"name": name, "type": kind}}


def measurement_set(tmp_path, extra, file="test.mat"):
    text = (f'[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "{file}"\naverages = 5\n' + extra)
    (tmp_path / "set.toml").write_text(text, encoding="utf-8")
    return tmp_path / "set.toml"


@pytest.mark.parametrize("values, label, factor", [
    (-W**2 * H, "g/N", 1 / G),  # as Testlab stores it: SI values, the factor to the unit shown
    (-W**2 * H / G, "g/N", 1.0),  # values in the label's unit
    (1j * W * H * 1e3, "mm/s/N", 1.0),  # a mobility in mm/s per N
    (H, "m/N", 1.0),
])
def test_an_frf_reads_in_si_with_the_quantity_of_its_unit(tmp_path, values, label, factor):
    path = tmp_path / "test.mat"
    savemat(path, {"FRF": struct(values, label, "Tip:+Y/Tip:+Y", factor=factor),
                   "Coh": struct(GAMMA, "", "Coherence Tip:+Y", kind="Coherence")})
    frf = read_mat(path, record=0)
    assert frf.quantity == {"g/N": "accelerance", "mm/s/N": "mobility", "m/N": "receptance"}[label]
    np.testing.assert_allclose(frf.frequency.hz, HZ, rtol=1e-12)
    np.testing.assert_allclose(frf.to_receptance().data[:, 0, 0], H, rtol=1e-12)
    (m,) = load_measurements(measurement_set(tmp_path, "coherence_record = 1\n")).measurements
    np.testing.assert_allclose(m.frf.to_receptance().data[:, 0, 0], H, rtol=1e-12)
    np.testing.assert_allclose(m.coherence, GAMMA, rtol=1e-12)
    assert m.frf.outputs == m.frf.inputs == ("tool.tip:y",) and m.averages == 5


def test_a_group_of_frfs_needs_its_record_and_what_is_not_an_frf_is_said(tmp_path):
    path = tmp_path / "test.mat"
    group = struct(np.column_stack([H, 2 * H]), "m/N", np.array(["H11", "H21"], dtype=object))
    savemat(path, {"Group": group, "Coh": struct(GAMMA, "", "Coherence", kind="Coherence")})
    with pytest.raises(FileFormatError, match=r"test.mat: 2 complex channels on a frequency axis \(0: H11 \(complex, "
                                              r"m/N\); 1: H21 \(complex, m/N\); 2: Coherence \(real, no unit\)\); "
                                              r"give the 0-based index"):
        read_mat(path)
    np.testing.assert_allclose(read_mat(path, record=1).data[:, 0, 0], 2 * H, rtol=1e-12)
    with pytest.raises(FileFormatError, match=r"channel 2 \(Coherence\): real values; an FRF needs complex values"):
        read_mat(path, record=2)
    with pytest.raises(FileFormatError, match=r"channel 0 \(H11\): complex values; expected a coherence"):
        read_mat_coherence(path, 0)
    with pytest.raises(FileFormatError, match=r"test.mat: coherence record 7; the file has 3 channel\(s\)"):
        read_mat_coherence(path, 7)
    # in the measurement set: the key and the file named
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.file: .*2 complex channels"):
        load_measurements(measurement_set(tmp_path, ""))
    assert load_measurements(measurement_set(tmp_path, "record = 1\n")).measurements[0].frf.frequency.n == HZ.size
    with pytest.raises(FileFormatError, match=r"frf\[0\]\.record: .*test.mat: got 5; .*test.mat has 3 channel\(s\) "
                                              r"on a frequency axis, indices 0..2"):
        load_measurements(measurement_set(tmp_path, "record = 5\n"))


@pytest.mark.parametrize("content, message", [
    ({"FRF": struct(H, "dB", "H")}, r"the unit 'dB' is in decibels"),
    ({"FRF": struct(H, "N/m", "H")}, r"the unit 'N/m' is not a displacement, velocity or acceleration per force"),
    ({"FRF": struct(H, "", "H")}, r"no unit \(y_values.quantity.label is empty\); give the quantity"),
    ({"FRF": struct(0 * H, "m/N", "H")}, r"every value is 0, a dead channel"),
    ({"FRF": struct(H * 1e9, "m/N", "H")}, r"more than 1 m/N"),
    ({"FRF": struct(H, "m/N", "H", step=-2.0)}, r"FRF.x_values.increment is -2.0 Hz; expected a positive step"),
    ({"Signal": struct(H.real, "N", "Force", x_label="s", step=1e-4)}, r"no signal structure on a frequency axis "
                                                                       r"\(an FRF\); the file holds time records "
                                                                       r"\(Force\): make the FRF from them"),
    ({"x": np.arange(3.0)}, r"the file holds no signal structure"),
])
def test_files_that_hold_no_usable_frf_are_refused_by_name(tmp_path, content, message):
    path = tmp_path / "test.mat"
    savemat(path, content)
    with pytest.raises(FileFormatError, match=message):
        load_measurements(measurement_set(tmp_path, ""))


def test_a_quantity_given_agrees_with_the_unit_or_stands_for_a_missing_one(tmp_path):
    path = tmp_path / "test.mat"
    savemat(path, {"FRF": struct(-W**2 * H, "(m/s^2)/N", "H")})
    assert read_mat(path, quantity="accelerance").quantity == "accelerance"
    with pytest.raises(FileFormatError, match=r"the quantity given is receptance, but its unit '\(m/s\^2\)/N' is that "
                                              r"of an accelerance"):
        read_mat(path, quantity="receptance")
    savemat(path, {"FRF": struct(-W**2 * H, "", "H")})
    frf = read_mat(path, quantity="accelerance")
    np.testing.assert_allclose(frf.to_receptance().data[:, 0, 0], H, rtol=1e-12)


def test_lobes_read_an_accelerance_in_every_file_that_says_so_as_its_receptance(tmp_path, capsys):
    """A tool point accelerance whose file states its units (a CSV header in m/(N s^2), a universal file of data
    type 12, a Testlab export in g/N to MATLAB, a spreadsheet export in g/N with decimal commas) gives the lobes of
    its receptance; it was refused as a reversed sign."""
    import json

    import pyuff

    from substructure import FRF, Frequency
    from substructure.cli import main

    hz = np.arange(1.0, 4001.0)
    w = 2 * np.pi * hz
    h = 1.0 / (2e7 - 0.4 * w**2 + 1j * 300 * w) + 1.0 / (5e7 - 0.1 * w**2 + 1j * 200 * w)
    a = -(w**2) * h
    FRF.single(Frequency.from_hz(hz), h).to_csv(tmp_path / "receptance.csv")
    lines = "".join(f"{float(f)!r},{float(v.real)!r},{float(v.imag)!r}\n" for f, v in zip(hz, a))
    (tmp_path / "accelerance.csv").write_text("frequency [Hz],real [m/(N s^2)],imag [m/(N s^2)]\n" + lines)
    pyuff.UFF(str(tmp_path / "accelerance.uff")).write_sets([pyuff.prepare_58(
        func_type=4, rsp_node=1, rsp_dir=2, ref_node=1, ref_dir=2, data=a, x=hz, abscissa_spacing=1,
        abscissa_min=1.0, abscissa_inc=1.0, abscissa_spec_data_type=18, ordinate_spec_data_type=12,
        orddenom_spec_data_type=13, ordinate_axis_units_lab="m/s^2", orddenom_axis_units_lab="N", id1="tip")])
    savemat(tmp_path / "accelerance.mat", {"FRF": struct(a, "g/N", "H1", factor=1 / G, start=1.0, step=1.0)})
    export = "".join(f"{f:.1f};{v.real:.12e};{v.imag:.12e}\n".replace(".", ",") for f, v in zip(hz, a / G))
    (tmp_path / "export.csv").write_text("Frequency (Hz);Real (g/N);Imaginary (g/N)\n" + export)
    cut = ["--teeth", "2", "--diameter", "12 mm", "--radial-depth", "6 mm", "--kt", "625 MPa", "--kn", "100 MPa",
           "--speeds", "2000:20000", "--json"]
    results = {}
    for name in ("receptance.csv", "accelerance.csv", "accelerance.uff", "accelerance.mat", "export.csv"):
        code = main(["lobes", "--frf", str(tmp_path / name), *cut])
        out = capsys.readouterr()
        assert code == 0, out.err
        results[name] = json.loads(out.out)
    expected = results.pop("receptance.csv")
    for name, got in results.items():
        assert got["spindle_speed_rpm"] == expected["spindle_speed_rpm"], name
        np.testing.assert_allclose(got["depth_limit_m"], expected["depth_limit_m"], rtol=1e-6, err_msg=name)
        assert got["absolute_limit_m"] == pytest.approx(expected["absolute_limit_m"], rel=1e-6)
    # files of two FRFs: --frf takes one, and says so
    savemat(tmp_path / "two.mat", {"A": struct(a, "g/N", "H11", factor=1 / G, start=1.0, step=1.0),
                                   "B": struct(2 * a, "g/N", "H21", factor=1 / G, start=1.0, step=1.0)})
    pyuff.UFF(str(tmp_path / "accelerance.uff")).write_sets([pyuff.prepare_58(
        func_type=4, rsp_node=2, rsp_dir=2, ref_node=1, ref_dir=2, data=2 * a, x=hz, abscissa_spacing=1,
        abscissa_min=1.0, abscissa_inc=1.0, abscissa_spec_data_type=18, ordinate_spec_data_type=12,
        orddenom_spec_data_type=13, ordinate_axis_units_lab="m/s^2", orddenom_axis_units_lab="N", id1="other")],
        mode="add")
    for name, message in (("two.mat", "2 FRF channels (H11, H21); --frf takes a file of one tool point FRF"),
                          ("accelerance.uff", "2 FRF records (node1:y, node2:y / node1:y); --frf takes a file of one")):
        assert main(["lobes", "--frf", str(tmp_path / name), *cut]) == 1
        assert message in capsys.readouterr().err


@pytest.mark.parametrize("values, unit, shown", [(np.where(HZ > 300, 1.2, GAMMA), "", "1.2"),
                                                 (np.where(HZ > 300, np.nan, GAMMA), "", "nan"),
                                                 (GAMMA * 100 + 5, "%", r"1\.0\d+;")])
def test_a_coherence_outside_0_to_1_is_refused_at_its_first_bad_line(tmp_path, values, unit, shown):
    """In a fraction or in %: the channel, the line and the value named (a rounding just above 1 is clipped)."""
    path = tmp_path / "test.mat"
    savemat(path, {"FRF": struct(H, "m/N", "H11"), "Coh": struct(values, unit, "Coherence", kind="Coherence")})
    scaled = values * (0.01 if unit else 1.0)
    k = int(np.argmax(~(np.isfinite(scaled) & (scaled <= 1.0 + 1e-6))))
    with pytest.raises(FileFormatError, match=rf"channel 1 \(Coherence\): value {k + 1} is {shown}"):
        read_mat_coherence(path, 1)
    savemat(path, {"FRF": struct(H, "m/N", "H11"), "Coh": struct(np.where(HZ > 300, 1 + 5e-7, GAMMA), "",
                                                                 "Coherence", kind="Coherence")})
    assert read_mat_coherence(path, 1)[1].max() == 1.0


def test_a_value_not_finite_or_an_empty_number_is_refused_by_name_without_a_warning(tmp_path):
    path = tmp_path / "test.mat"
    values = H.copy()
    values[5] = np.inf
    savemat(path, {"FRF": struct(values, "g/N", "H11", factor=1 / G)})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # inf times the factor: refused as a value, not warned about
        with pytest.raises(FileFormatError, match=r"channel 0 \(H11\): value 6 is \(inf\+nanj\); expected finite"):
            read_mat(path)
    frf = struct(H, "m/N", "H11")
    frf["x_values"]["start_value"] = np.array([])
    savemat(path, {"FRF": frf})
    with pytest.raises(FileFormatError, match=r"FRF\.x_values\.start_value is empty; expected a number"):
        read_mat(path)
