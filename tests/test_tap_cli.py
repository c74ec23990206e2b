"""The ``substructure tap`` command and the measurement set it writes; coherence and averages of measurements."""

from __future__ import annotations

import json

import numpy as np
import pytest

from substructure.cli import main
from substructure.datasets import impact_records
from substructure.errors import FileFormatError, InvalidValueError
from substructure.frf import FRF, Frequency
from substructure.io.frf_files import read_csv, read_csv_with_coherence, write_csv
from substructure.io.measurements import load_measurements
from substructure.measurements import Measurement, MeasurementSet


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """The five pyFRF impact records as CSV files, the third one's channels in volts."""
    folder = tmp_path_factory.mktemp("taps")
    paths = []
    for i, r in enumerate(impact_records()):
        path = folder / f"tap{i + 1}.csv"
        np.savetxt(path, np.column_stack([r.time, r.force, r.response]), delimiter=",",
                   header="time [s],force [N],acceleration [m/s^2]", comments="")
        paths.append(str(path))
    return folder, paths


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_tap_writes_frf_with_coherence_and_a_set_that_reads_back(records, tmp_path, capsys):
    _, paths = records
    out, toml, png = tmp_path / "frf.csv", tmp_path / "set.toml", tmp_path / "tap.png"
    code, text, err = run(capsys, "tap", *paths, "--out", out, "--measurements", toml, "--response", "tool.tip",
                          "--excitation", "tool.tip", "--plot", png)
    assert code == 0, err
    assert "taps: 5 found, 5 averaged (H1), 0 rejected" in text
    # the real taps nearly die out within their records: no window, the output says why, and what still rang is
    # counted (docs/tap.md, section 3)
    assert "exponential window: none: the response nearly died out within every tap" in text
    assert "truncation: the response still rang at the taps' end" in text
    assert png.stat().st_size > 10_000
    frf, coherence = read_csv_with_coherence(out)
    assert coherence is not None and coherence.shape == (frf.frequency.n,)
    assert read_csv(out).frequency == frf.frequency  # the three-column reader reads it too
    measurements = load_measurements(toml)
    (m,) = measurements.measurements
    assert m.averages == 5 and m.response == "tool.tip:y" and m.estimator == "H1"
    assert np.array_equal(m.coherence, coherence)
    hz = m.frf.frequency.hz
    assert np.median(m.coherence[(hz >= 20) & (hz <= 5000)]) > 0.99
    cropped = measurements.crop(100, 200)
    assert np.array_equal(cropped.measurements[0].coherence, coherence[(hz >= 100) & (hz <= 200)])
    # nothing the user wrote is replaced without --overwrite
    before = toml.read_text()
    code, _, err = run(capsys, "tap", *paths, "--out", out, "--measurements", toml, "--response", "tool.tip",
                       "--excitation", "tool.tip")
    assert code == 1 and "--overwrite" in err and toml.read_text() == before
    code, _, err = run(capsys, "tap", *paths, "--out", out, "--measurements", toml, "--response", "holder.tip",
                       "--excitation", "tool.tip", "--overwrite")
    assert code == 0, err
    assert load_measurements(toml).measurements[0].response == "holder.tip:y"
    assert "exponential window" not in toml.read_text()  # none was applied
    assert load_measurements(toml).measurements[0].window_tau is None
    # windowed on request: the set says so in a comment, and reads back as before
    code, _, err = run(capsys, "tap", *paths, "--out", out, "--measurements", toml, "--response", "tool.tip",
                       "--excitation", "tool.tip", "--overwrite", "--exponential-window")
    assert code == 0, err
    assert toml.read_text().startswith("# measured through an exponential window, tau = 0.217 s")
    assert load_measurements(toml).measurements[0].averages == 5
    # and in a key the diagnosis reads (its report says what the window adds)
    assert abs(load_measurements(toml).measurements[0].window_tau - 0.2171) < 1e-3
    # an H2 set says so, with its coherence and the hammer's noise of the H1 it is compared as
    code, _, err = run(capsys, "tap", *paths, "--out", out, "--measurements", toml, "--response", "tool.tip",
                       "--excitation", "tool.tip", "--overwrite", "--estimator", "H2")
    assert code == 0, err
    (m,) = load_measurements(toml).measurements
    assert m.estimator == "H2" and m.force_noise is not None and m.force_window_s > 0
    np.testing.assert_allclose(m.h1_frf.data, m.frf.data * m.coherence[:, None, None])


def test_tap_json(records, capsys):
    _, paths = records
    code, text, err = run(capsys, "tap", *paths[:3], "--json", "--estimator", "H2", "--band", "10:6000",
                          "--exponential-window")
    assert code == 0, err
    data = json.loads(text)
    assert data["taps"] == 3 and data["rejected"] == [] and data["estimator"] == "H2"
    assert len(data["frequency_hz"]) == len(data["real"]) == len(data["imag"]) == len(data["coherence"]) == 5991
    assert data["frequency_hz"][0] == 10.0 and data["tau_s"] > 0 and data["window"] == "asked for"
    peak = min(data["peaks"], key=lambda p: abs(p["frequency_hz"] - 900))
    assert peak["added_damping_ratio"] == pytest.approx(1 / (data["tau_s"] * 2 * np.pi * peak["frequency_hz"]))
    assert "damping_ratio" not in peak
    code, text, err = run(capsys, "tap", *paths[:3], "--json", "--correct-window-damping")
    assert code == 0, err
    for p in json.loads(text)["peaks"]:
        if p["damping_ratio"] is not None:
            assert p["damping_ratio_corrected"] == pytest.approx(p["damping_ratio"] - p["added_damping_ratio"])
    assert any(p["damping_ratio"] is not None for p in json.loads(text)["peaks"])


def test_tap_reports_a_rejected_tap_with_its_reason(records, tmp_path, capsys):
    _, paths = records
    r = impact_records()[0]
    force = r.force.copy()
    force[5000:5008] += r.force[20:28]  # the same pulse again at 0.195 s
    bad = tmp_path / "double.csv"
    np.savetxt(bad, np.column_stack([r.time, force, r.response]), delimiter=",",
               header="time [s],force [N],acceleration [m/s^2]", comments="")
    code, text, err = run(capsys, "tap", paths[1], bad, "--json")
    assert code == 0, err
    data = json.loads(text)
    assert data["taps"] == 1
    (rejected,) = data["rejected"]
    assert rejected["tap"] == 2 and rejected["file"] == str(bad)
    assert rejected["reason"].startswith("double hit at t = 0.195")


def test_tap_errors_name_the_file(records, tmp_path, capsys):
    _, paths = records
    swapped = tmp_path / "swapped.csv"
    r = impact_records()[0]
    np.savetxt(swapped, np.column_stack([r.time, r.response, r.force]), delimiter=",",
               header="time [s],force [N],acceleration [m/s^2]", comments="")
    code, _, err = run(capsys, "tap", swapped)
    assert code == 1 and f"{swapped}: column 'force [N]' does not look like a hammer's force" in err
    code, _, err = run(capsys, "tap", paths[0], "--measurements", tmp_path / "s.toml")
    assert code == 2 and "--measurements needs --out" in err
    code, _, err = run(capsys, "tap", paths[0], "--sensitivity", "10 mV/g")
    assert code == 1 and "already in" in err and "tap1.csv" in err
    code, _, err = run(capsys, "tap", tmp_path / "x.xlsx")
    assert code == 2 and "expected a tap record in a .csv, .uff or .unv file" in err


# -- the measurement's new fields ---------------------------------------------------------------------------

def _frf(n=5):
    return FRF.single(Frequency.from_hz(np.arange(1.0, n + 1)), np.full(n, 1e-7 + 0j), "tool.tip:y", "tool.tip:y")


@pytest.mark.parametrize("argv, message", [
    (["--tau", "inf"], "argument --tau: got inf; expected a finite number > 0"),
    (["--tau", "0"], "argument --tau: got 0.0; expected a finite number > 0"),
    (["--tap-length", "nan"], "argument --tap-length: got nan; expected a finite number > 0"),
    (["--pre-trigger", "-1"], "argument --pre-trigger: got -1.0; expected a finite number >= 0"),
    (["--hammer-band-db", "-5"], "argument --hammer-band-db: got -5.0; expected a finite number > 0"),
    (["--tap-length", "0.004"], "argument --tap-length: got 0.004 s, not longer than --pre-trigger 0.005 s (its "
                                "default); expected a tap longer than the time kept before its hit"),
    (["--tap-length", "0.1", "--pre-trigger", "0.1"], "argument --tap-length: got 0.1 s, not longer than "
                                                      "--pre-trigger 0.1 s; expected a tap longer"),
    (["--no-exponential-window", "--tau", "0.1"], "--tau sets the exponential window's time constant; it cannot "
                                                  "go with --no-exponential-window"),
])
def test_tap_options_out_of_range_are_refused_by_name(records, tmp_path, capsys, argv, message):
    _, paths = records
    code, _, err = run(capsys, "tap", paths[0], "--out", tmp_path / "frf.csv", *argv)
    assert code != 0 and message in err and not (tmp_path / "frf.csv").exists()


def test_a_record_file_given_twice_is_refused_naming_it(records, tmp_path, capsys):
    """The same file twice (also by another path to it) would be its taps averaged twice: coherence 1."""
    folder, paths = records
    link = tmp_path / "link.csv"
    link.symlink_to(paths[0])
    for again in (paths[0], str(folder / "." / "tap1.csv"), str(link)):
        code, _, err = run(capsys, "tap", paths[0], paths[1], again, "--out", tmp_path / "frf.csv")
        assert code != 0 and not (tmp_path / "frf.csv").exists()
        assert f"{again}: the record file is given more than once (also as {paths[0]}); expected each record once" \
            in err


def test_the_same_tap_twice_in_python_is_refused():
    from substructure.tap import process_taps

    taps = impact_records()[:3]
    with pytest.raises(InvalidValueError, match=r"records\[2\] \(.*\): the same force and response samples as "
                                                r"records\[0\] \(.*\); expected each tap once"):
        process_taps([taps[0], taps[1], taps[0]])
    assert process_taps(taps).averages == 3


def test_a_band_above_the_hammer_s_or_the_records_band_is_refused_at_the_option(records, tmp_path, capsys):
    """The shipped taps: 25600 Hz, the hammer's usable band to about 7 kHz: a band above it (below the Nyquist
    frequency) is refused naming --band and both limits (it was an internal message of a crop); above Nyquist
    likewise; a band reaching into the usable band is kept; --band takes LO:HI only, and says so."""
    from substructure.tap import process_taps

    _, paths = records
    usable = process_taps(impact_records()).hammer_band_hz
    assert 5000 < usable < 11000
    code, _, err = run(capsys, "tap", *paths, "--band", "11000:12000", "--out", tmp_path / "frf.csv")
    assert code != 0 and not (tmp_path / "frf.csv").exists()
    assert (f"argument --band: got 11000:12000 Hz, above the hammer's usable band (up to {usable:.0f} Hz, where its "
            "force spectrum has fallen 20 dB; the Nyquist frequency is 12800 Hz)") in err
    code, _, err = run(capsys, "tap", *paths, "--band", "13000:14000")
    assert code != 0 and ("argument --band: got 13000:14000 Hz; the records' lines end at the Nyquist frequency, "
                          "12800 Hz") in err
    code, out, err = run(capsys, "tap", *paths, "--band", f"{usable - 500:.0f}:12000")
    assert code == 0, err
    for text in ("100", "auto"):
        code, _, err = run(capsys, "tap", paths[0], "--band", text)
        assert code != 0 and f"argument --band: got {text!r}; expected LO:HI in Hz, e.g. 1200:1700" in err


def test_process_taps_refuses_settings_out_of_range():
    records = impact_records()[:2]
    from substructure.tap import process_taps

    for kw, message in ((dict(tap_length=float("nan")), "tap_length: got nan s; expected a finite number > 0"),
                        (dict(tap_length=0.004), "tap_length: got 0.004 s, not longer than pre_trigger 0.005 s"),
                        (dict(pre_trigger=-0.1), "pre_trigger: got -0.1 s; expected a finite number >= 0"),
                        (dict(tau=float("inf")), "tau: got inf s; expected a finite number > 0"),
                        (dict(hammer_band_db=0.0), "hammer_band_db: got 0.0 dB; expected a finite number > 0"),
                        (dict(tau=0.1, exponential=False), "a time constant asks for the window")):
        with pytest.raises(InvalidValueError, match=message):
            process_taps(records, **kw)


def test_measurement_coherence_and_averages_are_checked():
    m = Measurement("tool.tip", "tool.tip", _frf(), coherence=[0.5, 0.9, 1.0, 0.0, 1.0 + 1e-12], averages=10)
    assert m.coherence[-1] == 1.0 and m.averages == 10 and not m.coherence.flags.writeable
    assert m == Measurement("tool.tip", "tool.tip", _frf(), coherence=m.coherence, averages=10)
    assert m != Measurement("tool.tip", "tool.tip", _frf(), averages=10)
    with pytest.raises(InvalidValueError, match="coherence: got 4 values for 5 frequency lines"):
        Measurement("tool.tip", "tool.tip", _frf(), coherence=[1, 1, 1, 1])
    with pytest.raises(InvalidValueError, match=r"coherence: line 1 is 1.5; expected a number in \[0, 1\]"):
        Measurement("tool.tip", "tool.tip", _frf(), coherence=[1, 1.5, 1, 1, 1])
    with pytest.raises(InvalidValueError, match="averages: got 0"):
        Measurement("tool.tip", "tool.tip", _frf(), averages=0)
    cropped = MeasurementSet("s", [m]).crop(2, 4).measurements[0]
    assert np.array_equal(cropped.coherence, [0.9, 1.0, 0.0]) and cropped.frf.frequency.n == 3


def test_measurement_file_averages_and_coherence_column(tmp_path):
    frf = _frf()
    write_csv(frf, tmp_path / "a.csv", coherence=[0.1, 0.2, 0.3, 0.4, 0.5])
    (tmp_path / "set.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
                                       'file = "a.csv"\naverages = 7\n')
    m = load_measurements(tmp_path / "set.toml").measurements[0]
    assert m.averages == 7 and np.array_equal(m.coherence, [0.1, 0.2, 0.3, 0.4, 0.5])
    (tmp_path / "bad.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
                                       'file = "a.csv"\naverages = 0\n')
    with pytest.raises(FileFormatError, match=r"bad.toml, line 5: frf\[0\].averages: got 0"):
        load_measurements(tmp_path / "bad.toml")
    text = (tmp_path / "a.csv").read_text().replace("0.3\n", "1.3\n")
    (tmp_path / "a.csv").write_text(text)
    with pytest.raises(FileFormatError, match=r"a.csv, line 4: coherence is 1.3"):
        load_measurements(tmp_path / "set.toml")
    write_csv(frf, tmp_path / "a.csv", overwrite=True)  # an old three-column file: no coherence
    assert load_measurements(tmp_path / "set.toml").measurements[0].coherence is None


def test_tap_reads_a_universal_file_and_a_long_record(tmp_path, capsys):
    import pyuff

    r = impact_records()[0]
    path = tmp_path / "tap.uff"
    uff = pyuff.UFF(str(path))
    for data, spec, unit, node in ((r.force, 13, "N", 1), (r.response, 12, "m/s^2", 2)):
        uff.write_sets(pyuff.prepare_58(
            func_type=1, rsp_node=node, rsp_dir=3, ref_node=1, ref_dir=3, data=data, x=r.time, num_pts=len(r),
            abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=1 / 25600, abscissa_spec_data_type=17,
            ordinate_spec_data_type=spec, ordinate_axis_units_lab=unit, id1=f"node {node}",
            orddenom_spec_data_type=0, orddenom_axis_units_lab="", abscissa_axis_units_lab="s",
            z_axis_spec_data_type=0, z_axis_axis_units_lab=""), mode="add")
    code, text, err = run(capsys, "tap", path, "--json")
    assert code == 0, err
    data = json.loads(text)
    assert data["taps"] == 1 and data["per_tap"][0]["peak_force_n"] == pytest.approx(68.6, abs=0.1)
    # the five records one after the other in one file, cut again into five taps of 0.9 s
    records = impact_records()
    long = tmp_path / "long.csv"
    t = np.arange(5 * len(r)) / 25600
    np.savetxt(long, np.column_stack([t, np.concatenate([x.force for x in records]),
                                      np.concatenate([x.response for x in records])]), delimiter=",",
               header="time [s],force [N],acceleration [g]", comments="")
    code, text, err = run(capsys, "tap", long, "--tap-length", "0.9", "--json")
    assert code == 0, err
    data = json.loads(text)
    assert data["taps"] == 5 and [round(p["start_s"]) for p in data["per_tap"]] == [0, 1, 2, 3, 4]


def test_a_reversed_polarity_is_said_and_undone(tmp_path, capsys):
    """Taps simulated on the tool tip of the default assembly, the hammer's channel negated: the driving
    point's imaginary part is then positive, which no passive structure gives; the command says so, and
    --reverse-polarity gives the FRF of the records as they were (the diagnosis refuses such a driving
    point by name, tests/test_passivity.py)."""
    from substructure import default_assembly
    from test_tap_to_diagnosis import _taps

    paths, flipped = [], []
    for i, r in enumerate(_taps(default_assembly(), seed=1)):
        for sign, names in ((1, paths), (-1, flipped)):
            names.append(tmp_path / f"tap{i + 1}{'-' if sign < 0 else ''}.csv")
            np.savetxt(names[-1], np.column_stack([r.time, sign * r.force, r.response]), delimiter=",",
                       header="time [s],force [N],acceleration [m/s^2]", comments="")
    point = ("--response", "tool.tip", "--excitation", "tool.tip")
    code, _, err = run(capsys, "tap", *paths, "--out", tmp_path / "a.csv", "--measurements", tmp_path / "a.toml",
                       *point)
    assert code == 0 and "warning" not in err, err
    code, _, err = run(capsys, "tap", *flipped, "--out", tmp_path / "b.csv", "--measurements", tmp_path / "b.toml",
                       *point)
    assert code == 0 and "warning: the FRF of the driving point tool.tip:y has a positive imaginary part" in err
    assert "--reverse-polarity negates it" in err
    code, _, err = run(capsys, "tap", *flipped, "--out", tmp_path / "c.csv", "--measurements", tmp_path / "c.toml",
                       *point, "--reverse-polarity")
    assert code == 0 and "warning" not in err, err
    a, c = read_csv(tmp_path / "a.csv"), read_csv(tmp_path / "c.csv")
    np.testing.assert_allclose(c.data, a.data, rtol=1e-12, atol=0)
    # no warning where the points differ: a cross point has no sign of its own
    code, _, err = run(capsys, "tap", *flipped, "--out", tmp_path / "d.csv", "--measurements", tmp_path / "d.toml",
                       "--response", "holder.tip", "--excitation", "tool.tip")
    assert code == 0 and "warning" not in err, err
