"""Tap records in NI's TDMS files (LabVIEW, FlexLogger, DAQExpress): groups of channels with their units in
the channel property unit_string and the time step in wf_increment, as NI's software writes them; written here
with npTDMS's writer and read against the same samples (and the FRF of the plain records)."""

from __future__ import annotations

import numpy as np
import pytest
from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

from substructure.cli import main
from substructure.datasets import impact_records
from substructure.errors import FileFormatError
from substructure.io.frf_files import read_csv
from substructure.io.tap_files import read_tap_tdms
from substructure.tap import TapRecord, process_taps

G = 9.80665


def _channel(group, name, data, unit=None, dt=None, **more):
    properties = dict(more)
    if unit is not None:
        properties["unit_string"] = unit
    if dt is not None:
        properties.update(wf_increment=dt, wf_start_offset=0.0, wf_samples=len(data))
    return ChannelObject(group, name, np.asarray(data, dtype=np.float64), properties=properties)


def _write(path, groups):
    """groups: {group name: [ChannelObject, ...]}, one segment per group (as a logger writes a tap at a time)."""
    with TdmsWriter(str(path)) as writer:
        writer.write_segment([RootObject(properties={"name": "hammer test"})])
        for group, channels in groups.items():
            writer.write_segment([GroupObject(group), *channels])
    return path


@pytest.fixture(scope="module")
def records():
    return impact_records()


def test_a_group_per_tap_reads_to_the_frf_of_the_records(records, tmp_path):
    dt = 1.0 / records[0].sample_rate
    path = _write(tmp_path / "taps.tdms", {
        f"Tap {k + 1}": [_channel(f"Tap {k + 1}", "Hammer", r.force, "N", dt),
                         _channel(f"Tap {k + 1}", "Accelerometer", r.response / G, "g", dt)]
        for k, r in enumerate(records)})
    taps = read_tap_tdms(path)
    assert [t.source for t in taps] == [f"{path} [Tap {k + 1}]" for k in range(5)]
    assert taps[0].quantity == "acceleration" and taps[0].sample_rate == pytest.approx(25600.0)
    np.testing.assert_allclose(taps[2].response, records[2].response, rtol=1e-12)
    np.testing.assert_allclose(taps[2].force, records[2].force, rtol=0, atol=0)
    a, b = process_taps(taps).frf.data, process_taps(records).frf.data
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.abs(b).max())


def test_one_long_record_in_volts_with_a_time_channel(records, tmp_path):
    """One group of a continuous acquisition: channels in mV (with the sensors' sensitivities), a time channel
    instead of wf_increment, and a trigger channel beside them; the taps are found in the long record."""
    force = np.concatenate([r.force for r in records])
    response = np.concatenate([r.response for r in records])
    t = np.arange(force.size) / records[0].sample_rate
    path = _write(tmp_path / "long.tdms", {"Log": [
        _channel("Log", "Time", t, "s"), _channel("Log", "Trigger", np.zeros_like(t), "V"),
        _channel("Log", "Force", force * 2.25, "mV"), _channel("Log", "Response", response / G * 10.2, "mV")]})
    # the force is found by its name; two channels in volts beside it: which one is the response is asked
    with pytest.raises(FileFormatError, match=r"group 'Log': 0 response columns among 2 .*--response-column"):
        read_tap_tdms(path, "10.2 mV/g", "2.25 mV/N")
    (tap,) = read_tap_tdms(path, "10.2 mV/g", "2.25 mV/N", response_column="Response")
    assert tap.source == str(path)  # one group: the file alone
    np.testing.assert_allclose(tap.force, force, rtol=1e-12)
    result = process_taps([tap], tap_length=1.0)
    assert result.averages == 5
    b = process_taps([TapRecord(t, force, response, "acceleration")], tap_length=1.0).frf.data  # the same arrays
    np.testing.assert_allclose(result.frf.data, b, rtol=1e-9, atol=1e-12 * np.abs(b).max())
    with pytest.raises(FileFormatError, match=r"column 'Force \[mV\]'.*hammer sensitivity"):
        read_tap_tdms(path, "10.2 mV/g", response_column=4)


def test_the_sample_rate_comes_from_wf_increment_or_the_option(records, tmp_path):
    r = records[0]
    dt = 1.0 / r.sample_rate
    path = _write(tmp_path / "a.tdms", {"g": [_channel("g", "force", r.force, "N"),
                                             _channel("g", "acc", r.response, "m/s^2")]})
    with pytest.raises(FileFormatError, match=r"no column in units of time .* no sample rate; give the rate with "
                                              r"--sample-rate .* or the channels' wf_increment property"):
        read_tap_tdms(path)
    (tap,) = read_tap_tdms(path, sample_rate="25.6 kHz")
    assert tap.sample_rate == pytest.approx(25600.0)
    path = _write(tmp_path / "b.tdms", {"g": [_channel("g", "force", r.force, "N", dt),
                                             _channel("g", "acc", r.response, "m/s^2", dt)]})
    read_tap_tdms(path, sample_rate=25600)  # the same rate: accepted
    with pytest.raises(FileFormatError, match=r"wf_increment 3.90625e-05 s is 25600 Hz, --sample-rate 51200 Hz"):
        read_tap_tdms(path, sample_rate="51.2 kHz")


def test_a_channel_of_another_rate_beside_the_tap_is_not_read(records, tmp_path):
    """A logger's channel in the tap's group (five readings, a second apart): the force and the response are read at
    their own rate; a force and a response at two rates stay refused."""
    r = records[0]
    dt = 1.0 / r.sample_rate
    path = _write(tmp_path / "log.tdms", {"g": [_channel("g", "force", r.force, "N", dt),
                                               _channel("g", "acc", r.response, "m/s^2", dt),
                                               _channel("g", "supply", np.full(5, 24.0), "V", 1.0)]})
    (tap,) = read_tap_tdms(path)
    assert tap.sample_rate == pytest.approx(r.sample_rate) and tap.response_column == "acc [m/s^2]"
    np.testing.assert_allclose(tap.force, r.force, rtol=0, atol=0)
    path = _write(tmp_path / "two.tdms", {"g": [_channel("g", "force", r.force, "N", dt),
                                               _channel("g", "acc", r.response, "m/s^2", 2 * dt),
                                               _channel("g", "supply", np.full(5, 24.0), "V", 1.0)]})
    with pytest.raises(FileFormatError, match=r"group 'g': the channels' time steps \(wf_increment\) differ: "
                                              r"3.90625e-05, 7.8125e-05 s"):
        read_tap_tdms(path)


@pytest.mark.parametrize("case, message", [
    ("steps", r"group 'g': the channels' time steps \(wf_increment\) differ: 3.90625e-05, 7.8125e-05 s"),
    ("no unit", r"group 'g': channel 'acc' has no unit; expected its property unit_string"),
    ("lengths", r"group 'g': channels of 25600, 25599 samples"),
    ("nan", r"group 'g': channel 'acc \[m/s\^2\]', sample 11 is nan; expected a finite number"),
    ("quantity", r"holds an acceleration, and the quantity option says velocity"),
    ("empty", r"no channel with data"),
    ("text step", r"group 'g': channel 'acc': wf_increment 'fast'; expected a time step in s"),
    ("zero step", r"group 'g': channel 'acc': wf_increment 0.0 s; expected a time step > 0"),
])
def test_errors_name_the_file_the_group_and_the_channel(records, tmp_path, case, message):
    r = records[0]
    dt = 1.0 / r.sample_rate
    force, acc = r.force, r.response.copy()
    channels = [_channel("g", "force", force, "N", dt), _channel("g", "acc", acc, "m/s^2", dt)]
    if case == "steps":
        channels[1] = _channel("g", "acc", acc, "m/s^2", 2 * dt)
    elif case == "no unit":
        channels[1] = _channel("g", "acc", acc, None, dt)
    elif case == "lengths":
        channels[1] = _channel("g", "acc", acc[:-1], "m/s^2", dt)
    elif case == "nan":
        acc[10] = np.nan
        channels[1] = _channel("g", "acc", acc, "m/s^2", dt)
    elif case in ("text step", "zero step"):
        channels[1] = _channel("g", "acc", acc, "m/s^2", wf_increment="fast" if case == "text step" else 0.0)
    elif case == "empty":
        channels = [_channel("g", "force", [], "N")]
    path = _write(tmp_path / "bad.tdms", {"g": channels})
    with pytest.raises(FileFormatError, match=message) as info:
        read_tap_tdms(path, quantity="velocity" if case == "quantity" else None)
    assert str(path) in str(info.value)


def test_a_file_that_is_not_tdms_is_refused(tmp_path):
    path = tmp_path / "fake.tdms"
    path.write_text("time [s],force [N],acceleration [m/s^2]\n0,1,2\n")
    with pytest.raises(FileFormatError, match=r"fake.tdms: cannot read the TDMS file .*; expected a file written "
                                              r"by NI's acquisition software"):
        read_tap_tdms(path)


def test_the_command_reads_a_tdms_file(records, tmp_path, capsys):
    dt = 1.0 / records[0].sample_rate
    path = _write(tmp_path / "taps.tdms", {
        f"Tap {k + 1}": [_channel(f"Tap {k + 1}", "Hammer", r.force, "N", dt),
                         _channel(f"Tap {k + 1}", "Accelerometer", r.response, "m/s^2", dt)]
        for k, r in enumerate(records)})
    code = main(["tap", str(path), "--out", str(tmp_path / "frf.csv")])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "taps: 5 found, 5 averaged (H1), 0 rejected" in out.out
    b = process_taps(records).frf
    written = read_csv(tmp_path / "frf.csv").data
    np.testing.assert_allclose(written, b.data, rtol=1e-9, atol=1e-12 * np.abs(b.data).max())


def test_time_stamps_text_and_integer_channels(records, tmp_path):
    """A logger's clock as time stamps (read as seconds from the first), a channel of text beside the samples
    (not a candidate), the force as int16 counts already scaled to N by the writer; a group of text alone is
    refused by name."""
    r = records[0]
    n = 4096
    clock = (np.arange(n) * 1e9 / r.sample_rate).astype("timedelta64[ns]")
    stamps = np.datetime64("2026-11-26T10:00:00", "ns") + clock
    force = np.round(r.force[:n]).astype(np.int16)
    path = _write(tmp_path / "log.tdms", {"g": [
        ChannelObject("g", "Timestamp", stamps), ChannelObject("g", "Comment", np.array(["hit"] * n)),
        ChannelObject("g", "Hammer", force, properties={"unit_string": "N"}),
        ChannelObject("g", "Acc", r.response[:n].astype(np.float32), properties={"unit_string": "m/s^2"})]})
    (tap,) = read_tap_tdms(path)
    assert tap.sample_rate == pytest.approx(r.sample_rate, rel=1e-6)
    assert tap.time[0] == pytest.approx(0.0, abs=1e-6)  # stamps come to the microsecond: the clock fitted to them
    np.testing.assert_array_equal(tap.force, force.astype(float))
    np.testing.assert_allclose(tap.response, r.response[:n], rtol=1e-6)
    path = _write(tmp_path / "text.tdms", {"notes": [ChannelObject("notes", "Comment", np.array(["a", "b"])),
                                                     ChannelObject("notes", "Force", np.array([1.0, 2.0]),
                                                                   properties={"unit_string": "N"})]})
    with pytest.raises(FileFormatError, match=r"group 'notes': 1 channel of numbers \(Comment, Force\); expected a "
                                              r"force and a response channel"):
        read_tap_tdms(path)


@pytest.mark.parametrize("force_unit, response_unit, scale_f, scale_r, options", [
    ("Newtons", "MetersPerSecondSquared", 1.0, 1.0, {}),
    ("Pounds", "g", 1.0 / 4.4482216152605, 1.0 / G, {}),
    ("Volts", "Volts", 2.25e-3, 10.2e-3 / G, {"hammer_sensitivity": "2.25 mV/N", "sensitivity": "10.2 mV/g"}),
])
def test_units_as_ni_writes_them(records, tmp_path, force_unit, response_unit, scale_f, scale_r, options):
    """DAQmx and LabVIEW name units in words (Newtons, Volts, MetersPerSecondSquared); read as N, V, m/s^2."""
    r = records[1]
    dt = 1.0 / r.sample_rate
    path = _write(tmp_path / "ni.tdms", {"Hammer test": [
        _channel("Hammer test", "Dev1/ai0", r.force * scale_f, force_unit, dt),
        _channel("Hammer test", "Dev1/ai1", r.response * scale_r, response_unit, dt)]})
    (tap,) = read_tap_tdms(path, force_column=1, response_column=2, **options)
    np.testing.assert_allclose(tap.force, r.force, rtol=1e-12)
    np.testing.assert_allclose(tap.response, r.response, rtol=1e-12)
