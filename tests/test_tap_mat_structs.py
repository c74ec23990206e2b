"""MATLAB structures of tap records: the signal structures of Simcenter Testlab exports, nested structs and
struct arrays of taps, read to the same records as the project's real taps written as plain vectors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.io import savemat

from substructure.cli import main
from substructure.datasets import impact_records
from substructure.errors import FileFormatError
from substructure.io.tap_files import read_tap_mat, read_taps_mat

G = 9.80665


def signal(values, label, name, fs, factor=1.0, offset=0.0, x_label="s", increment=None, count=None):
    """A signal structure as Testlab exports it: the values times ``factor`` plus ``offset`` are in ``label``."""
    values = np.asarray(values)
    return {"x_values": {"start_value": 0.0, "increment": 1 / fs if increment is None else increment,
                         "number_of_values": values.shape[0] if count is None else count,
                         "quantity": {"label": x_label, "unit_transformation": {"factor": 1.0, "offset": 0.0}}},
            "y_values": {"values": values,
                         "quantity": {"label": label, "unit_transformation": {"factor": factor, "offset": offset,
                                                                              "log_reference": 1e-6}}},
            "function_record": {"name": name, "type": "Signal", "creation_time": "2026/11/28 12:00:00"}}


@pytest.fixture
def tap():
    return impact_records()[0]


def same(got, r):
    assert got.sample_rate == r.sample_rate and got.time.size == r.time.size
    assert np.allclose(got.force, r.force, rtol=1e-12, atol=0)
    assert np.allclose(got.response, r.response, rtol=1e-12, atol=0)


def test_testlab_signals_in_si_with_the_factor_to_their_label_read_as_the_real_tap(tmp_path, tap):
    """Testlab stores SI values and the factor to the label's unit (1/9.80665 for g): read as the tap itself.
    Values stored in the label's unit (factor 1) are read in that unit: the same tap from values in g."""
    fs = tap.sample_rate
    path = tmp_path / "testlab.mat"
    savemat(path, {"Signal_0": signal(tap.force, "N", "Force", fs),
                   "Signal_1": signal(tap.response, "g", "Point1:+Z", fs, factor=1 / G)})
    got = read_tap_mat(path)
    same(got, tap)
    assert (got.force_column, got.response_column) == ("Force [N]", "Point1:+Z [g]")
    savemat(path, {"Signal_0": signal(tap.force, "N", "Force", fs),
                   "Signal_1": signal(tap.response / G, "g", "Point1:+Z", fs)})
    same(read_tap_mat(path), tap)
    # the channel names of the record, or the variables' names when the record names none
    savemat(path, {"hammer": signal(tap.force * 1e-3, "kN", "", fs), "acc": signal(tap.response, "m/s^2", "", fs)})
    got = read_tap_mat(path)
    same(got, tap)
    assert got.force_column.startswith("hammer")


def test_a_group_of_channels_in_one_structure_and_spectra_passed_over(tmp_path, tap):
    """Channels exported as a group: one matrix a channel a column, a cell of names, a quantity a channel; an
    FRF and an autopower spectrum in the same file (complex values, an axis in Hz) are no channels."""
    fs = tap.sample_rate
    group = signal(np.column_stack([tap.force, tap.response]), "N", np.array(["Force", "Tip Z"], dtype=object), fs)
    group["y_values"]["quantity"] = np.array([{"label": "N"}, {"label": "m/s^2"}], dtype=object)
    frf = signal(np.fft.rfft(tap.response)[:100] / np.fft.rfft(tap.force)[:100], "g/N", "H1 Tip Z/Force", fs,
                 x_label="Hz", increment=1.0)
    power = signal(np.abs(np.fft.rfft(tap.force)[:100]) ** 2, "N^2", "Force APS", fs, x_label="Hz", increment=1.0)
    path = tmp_path / "group.mat"
    savemat(path, {"Group": group, "FRF": frf, "APS": power})
    got = read_tap_mat(path)
    same(got, tap)
    assert (got.force_column, got.response_column) == ("Force [N]", "Tip Z [m/s^2]")
    savemat(path, {"FRF": frf, "APS": power})
    with pytest.raises(FileFormatError, match=r"group.mat: no vector .* passed over: FRF \(complex values: a "
                                              r"spectrum or an FRF, not a time record\); APS \(an axis in "
                                              r"frequency: .*time record \(the FRF 'FRF' is read by a measurement "
                                              r"set: file = \"group.mat\"\)"):
        read_tap_mat(path)
    # a channel a row: read by its number of values
    group["y_values"]["values"] = np.vstack([tap.force, tap.response])
    savemat(path, {"Group": group})
    same(read_tap_mat(path), tap)


def test_testlab_signals_that_contradict_themselves_or_lack_a_unit_are_refused(tmp_path, tap):
    fs = tap.sample_rate
    path = tmp_path / "bad.mat"
    force = signal(tap.force, "N", "Force", fs)
    savemat(path, {"F": force, "A": signal(tap.response, "m/s^2", "Acc", fs / 2)})
    with pytest.raises(FileFormatError, match=r"bad.mat: A.x_values.increment says 12800 Hz, F.x_values.increment "
                                              r"25600 Hz; the force and the response must be sampled at one rate"):
        read_tap_mat(path)
    savemat(path, {"F": force, "A": signal(tap.response, "", "Acc", fs)})
    with pytest.raises(FileFormatError, match=r"bad.mat: the signal 'Acc' has no unit \(its y_values.quantity.label "
                                              r"is empty\)"):
        read_tap_mat(path, response_column="Acc")
    savemat(path, {"F": force, "A": signal(tap.response, "m/s^2", "Acc", fs, count=tap.time.size + 1)})
    with pytest.raises(FileFormatError, match=r"A.y_values.values holds 25600 values a channel, "
                                              r"A.x_values.number_of_values says 25601"):
        read_tap_mat(path)
    savemat(path, {"F": force, "A": signal(tap.response, "m/s^2", "Acc", fs, increment=-1 / fs)})
    with pytest.raises(FileFormatError, match=r"A.x_values.increment is -3.9\S+ s; expected a positive step"):
        read_tap_mat(path)
    savemat(path, {"F": force, "A": signal(tap.response, "m/s^2", "Acc", fs)})
    with pytest.raises(FileFormatError, match=r"F.x_values.increment says 25600 Hz, --sample-rate 1000 Hz; leave the "
                                              r"option out or fix the file"):
        read_tap_mat(path, sample_rate="1 kHz")
    savemat(path, {"F": force, "A": signal(tap.response, "m/s^2", "Acc", fs), "fs": fs / 2})
    with pytest.raises(FileFormatError, match=r"F.x_values.increment says 25600 Hz, fs 12800 Hz; the file "
                                              r"contradicts itself"):
        read_tap_mat(path)
    savemat(path, {"F": force, "A": signal(tap.response, "m/s^2", "Acc", fs), "fs": fs})
    same(read_tap_mat(path, sample_rate=fs), tap)
    # a time axis in milliseconds is a time axis
    savemat(path, {"F": signal(tap.force, "N", "Force", fs, x_label="ms", increment=1e3 / fs),
                   "A": signal(tap.response, "m/s^2", "Acc", fs, x_label="ms", increment=1e3 / fs)})
    same(read_tap_mat(path), tap)


def test_nested_structs_and_struct_arrays_of_taps(tmp_path):
    """A struct's fields are variables of dotted names; a struct array of taps is a matrix of a tap a column:
    the same records as the plain vectors."""
    taps = impact_records()[:3]
    fs = taps[0].sample_rate
    path = tmp_path / "s.mat"
    savemat(path, {"test": {"tap": {"force": taps[0].force, "force_unit": "N", "acc": taps[0].response / G,
                                    "acc_unit": "g"}, "fs": fs, "operator": "A. Smith"}})
    got = read_tap_mat(path)
    same(got, taps[0])
    assert got.force_column == "test.tap.force [N]"
    elements = np.empty(3, dtype=object)
    for k, r in enumerate(taps):
        elements[k] = {"force": r.force, "force_unit": "N", "acc": r.response, "acc_unit": "m/s^2", "fs": fs}
    savemat(path, {"taps": elements})
    got = read_taps_mat(path)
    assert len(got) == 3
    for g, r in zip(got, taps):
        same(g, r)
    elements[1] = dict(elements[1], acc_unit="g")
    savemat(path, {"taps": elements})
    with pytest.raises(FileFormatError, match=r"taps\(k\).acc_unit differs between the taps \('m/s\^2', 'g', "):
        read_taps_mat(path)
    elements[1] = dict(elements[1], acc_unit="m/s^2", acc=taps[1].response[:-10])
    savemat(path, {"taps": elements})
    with pytest.raises(FileFormatError, match=r"taps\(k\).acc holds vectors of 25590 to 25600 samples"):
        read_taps_mat(path)


def test_the_command_gives_the_testlab_export_the_frf_of_the_same_taps_as_vectors(tmp_path, capsys):
    taps = impact_records()[:2]
    fs = taps[0].sample_rate
    plain, testlab = [], []
    for k, r in enumerate(taps):
        plain.append(tmp_path / f"v{k}.mat")
        savemat(plain[-1], {"fs": fs, "force": r.force, "force_unit": "N", "acc": r.response, "acc_unit": "m/s^2"})
        testlab.append(tmp_path / f"Run {k + 1}.mat")
        savemat(testlab[-1], {"Signal_0": signal(r.force, "N", "Force", fs),
                              "Signal_1": signal(r.response, "g", "Point1:+Z", fs, factor=1 / G)})
    results = []
    for files in (plain, testlab):
        code = main(["tap", *map(str, files), "--json"])
        out = capsys.readouterr()
        assert code == 0, out.err
        results.append(json.loads(out.out))
    assert results[1]["frequency_hz"] == results[0]["frequency_hz"] and results[1]["averages"] == 2
    scale = np.max(np.abs(results[0]["real"]))
    assert np.allclose(results[1]["real"], results[0]["real"], rtol=0, atol=1e-12 * scale)
    assert np.allclose(results[1]["imag"], results[0]["imag"], rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("rate", ["25600", "25600,000000", "2.56E+04 Hz", "25.6 kHz"])
def test_a_bk_pulse_export_reads_with_its_channel_headers(tmp_path, tap, rate):
    """B&K PULSE's MATLAB export: a File_Header of texts (the sample frequency as the program writes it, decimal
    comma and unit included) and a Channel_k_Header with each Channel_k_Data's unit."""
    path = tmp_path / "pulse.mat"
    header = {"NumberOfChannels": "2", "SampleFrequency": rate, "NumberOfSamplesPerChannel": str(tap.time.size),
              "Date": "28-Nov-2026 12:00:00", "Comment": "tap 1"}
    savemat(path, {"File_Header": header,
                   "Channel_1_Header": {"SignalName": "Hammer", "Unit": "N", "MaxLevel": "500 N"},
                   "Channel_1_Data": tap.force,
                   "Channel_2_Header": {"SignalName": "Tip", "Unit": "m/s²", "MaxLevel": "5000 m/s²"},
                   "Channel_2_Data": tap.response})
    got = read_tap_mat(path)
    same(got, tap)
    assert (got.force_column, got.response_column) == ("Channel_1_Data [N]", "Channel_2_Data [m/s²]")
    header["SampleFrequency"] = "fast"
    savemat(path, {"File_Header": header, "Channel_1_Header": {"Unit": "N"}, "Channel_1_Data": tap.force,
                   "Channel_2_Header": {"Unit": "g"}, "Channel_2_Data": tap.response})
    with pytest.raises(FileFormatError, match=r"pulse.mat: variable 'File_Header.SampleFrequency' is 'fast'; "
                                              r"expected a number"):
        read_tap_mat(path)
    header["SampleFrequency"] = "25,600"  # 25.6 Hz, or 25600 Hz with a thousands separator: not guessed
    savemat(path, {"File_Header": header, "Channel_1_Header": {"Unit": "N"}, "Channel_1_Data": tap.force,
                   "Channel_2_Header": {"Unit": "g"}, "Channel_2_Data": tap.response})
    with pytest.raises(FileFormatError, match=r"a decimal comma or a thousands separator\? Give the rate with "
                                              r"--sample-rate"):
        read_tap_mat(path)
    assert read_tap_mat(path, sample_rate="25.6 kHz").sample_rate == tap.sample_rate


@pytest.mark.robustness
def test_random_structures_give_a_record_or_a_file_format_error(tmp_path):
    """Structures of every shape, signal structures with wrong fields among them: the readers of tap records and
    of FRFs give a result or an error of the package naming the file, never another exception (none of these
    is a whole tap or FRF: the errors are the point)."""
    import io

    from substructure.errors import SubstructureError
    from substructure.frf.files.mat_reader import read_mat, read_mat_coherence

    rng = np.random.default_rng(3)

    def pick(options):
        return options[int(rng.integers(len(options)))]

    def leaf():
        n = int(rng.integers(2, 40))
        return pick([rng.normal(size=n), rng.normal(size=(2, n)), float(rng.normal()), rng.normal(size=n) + 1j,
                     pick(["N", "g", "m/s^2", "Hz", "", "dB", "mV", "25,600", "1e3 Hz", "g/N"]),
                     np.array([np.nan, 1.0, np.inf]), np.arange(n, dtype=np.int16), 0.0])

    def signal():
        n = int(rng.integers(2, 40))
        x = {"increment": pick([1e-4, -1.0, 0.0, "x", np.nan, 1.0]), "number_of_values": pick([n, n + 1, -3]),
             "start_value": pick([0.0, np.nan]), "quantity": {"label": pick(["s", "Hz", "ms", "rpm", "", "m"])}}
        values = pick([rng.normal(size=n), rng.normal(size=(n, 2)), rng.normal(size=(2, n)), rng.normal(size=n) + 1j,
                       "text", rng.normal(size=(n, 3, 2))])
        quantity = pick([{"label": pick(["N", "g", "m/s^2", "g/N", "", "dB"]),
                          "unit_transformation": {"factor": pick([1.0, 0.0, np.nan, 0.1]), "offset": 0.0}}, "bad"])
        return {"x_values": x, "y_values": {"values": values, "quantity": quantity},
                "function_record": {"name": pick(["F", "", np.array(["a", "b"], dtype=object)])}}

    path = tmp_path / "random.mat"
    for _ in range(200):
        content = {}
        for k in range(int(rng.integers(1, 5))):
            key = pick(["force", "acc", "fs", "Signal_0", "tap", "t", "force_unit", "acc_unit", "FRF",
                        "File_Header", "Channel_1_Data", "Channel_1_Header"]) + pick(["", str(k)])
            content[key] = signal() if rng.random() < 0.4 else \
                {"force": leaf(), "force_unit": leaf(), "fs": leaf()} if rng.random() < 0.2 else leaf()
        buffer = io.BytesIO()
        savemat(buffer, content)
        path.write_bytes(buffer.getvalue())
        for reader in (read_taps_mat, read_mat, lambda p: read_mat(p, record=0), lambda p: read_mat_coherence(p, 0)):
            try:
                reader(path)
            except SubstructureError as exc:
                assert "random.mat" in str(exc), exc
