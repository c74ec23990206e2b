"""The end of a tap: the error a response still ringing there leaves in the FRF, estimated from the taps and counted.

Checked against what the error really is: the closed-form FRF of a 1-DOF system simulated by ``lsim`` (independent
of the FFT path), and the shipped real impact records cut short, against the FRF of their whole second.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from substructure.cli import main
from substructure.datasets import impact_records
from substructure.errors import FileFormatError, InvalidValueError
from substructure.io.frf_files import read_csv_with_coherence, write_csv
from substructure.io.measurements import load_measurements
from substructure.measurements import Measurement
from substructure.tap import TRUNCATION_SEGMENT, TapRecord, process_taps
from substructure.updating.noise import estimate_noise
from test_tap import half_sine, held, receptance, simulate


def _short_taps(n: int, noise: float = 0.0, seed: int = 0, peaks=(40.0, 55.0, 47.0)):
    """1-DOF taps (400 Hz, 1 % damping) of ``n`` samples, white noise of ``noise`` times the response's peak."""
    rng = np.random.default_rng(seed)
    records = []
    for k, peak in enumerate(peaks):
        t, f = half_sine(peak, n=4 * N_LONG)
        x = simulate(f)
        x = x + rng.normal(0.0, noise * np.abs(x).max(), x.size)
        records.append(TapRecord(t[:n], f[:n], x[:n], "displacement", f"tap {k + 1}"))
    return records


N_LONG = 10240  # 1 s: the 400 Hz mode (decay time 40 ms) has died out


def _relative_error(result):
    hz = result.frf.frequency.hz
    exact = receptance(2j * np.pi * hz) * held(hz)
    return hz, np.abs(result.frf.data[:, 0, 0] / exact - 1.0)


def test_a_tap_cut_while_its_mode_rings_has_an_error_the_estimate_covers():
    # 120 ms: the 400 Hz mode has decayed to 5 % of its start; the window is not applied (under WINDOW_SHARE)
    result = process_taps(_short_taps(1229, noise=1e-5))
    assert result.tau is None and "still rang" in result.window and "truncation" in result.window
    hz, error = _relative_error(result)
    band = (hz > 50) & (hz < 2000)
    estimate = np.sqrt(result.truncation[band])
    assert np.median(error[band]) > 0.01  # a real error, far above the noise ...
    assert np.median(1.0 - result.coherence[band]) < 1e-6  # ... that the coherence does not see
    ratio = error[band] / estimate
    assert np.quantile(ratio, 0.95) < 1.0  # covered on 95 % of the lines
    assert np.median(ratio) > 0.05  # and not by an estimate of no use (a median within 20 times)
    error_at, where = result.truncation_error()
    assert error_at == pytest.approx(np.sqrt(np.max(result.truncation[hz <= result.hammer_band_hz])
                                             * TRUNCATION_SEGMENT))
    assert 300 < where < 500 or error_at > 0.1  # the largest near the mode, or large anyway


def test_a_response_that_died_out_leaves_no_truncation_term():
    result = process_taps(_short_taps(N_LONG, noise=1e-4))
    assert result.truncation is None and result.truncation_error() is None
    assert result.window.startswith("none: the response died out") and "truncation" not in result.window


def test_a_response_ringing_strongly_is_still_windowed_and_its_truncation_estimated_on_the_windowed_record():
    result = process_taps(_short_taps(200))  # 20 ms: half a decay time
    assert result.tau is not None and "had not died out" in result.window
    assert result.truncation is None or np.all(result.truncation >= 0)


@pytest.mark.parametrize("seconds, share", [(0.5, 0.8), (0.25, 0.9), (0.1, 0.9)])
def test_real_records_cut_short_differ_from_the_whole_by_about_the_estimate(seconds, share):
    """The shipped real records (1 s, lightly damped modes still ringing) cut short: the difference from the FRF of
    the whole second is the truncation's error (with the noise of both); measured: the coherence's noise alone
    covers at most 6 % of the lines, with the estimate 86 to 97 %, the difference a median 0.07 to 0.2 of it."""
    records = impact_records()
    whole = process_taps(records, exponential=False)
    n = int(round(seconds * records[0].sample_rate))
    cut = process_taps([TapRecord(r.time[:n], r.force[:n], r.response[:n], r.quantity, r.source) for r in records],
                       exponential=False)
    hz = cut.frf.frequency.hz
    index = np.searchsorted(whole.frf.frequency.hz, hz)  # the cut FRF's lines are lines of the whole one's grid
    assert np.allclose(whole.frf.frequency.hz[index], hz)
    difference = np.abs(cut.frf.data[:, 0, 0] / whole.frf.data[index, 0, 0] - 1.0)
    gamma = np.clip(cut.coherence, 1e-3, 1.0)
    noise = np.sqrt((1.0 - gamma) / (2.0 * cut.averages * gamma))  # H1's scatter from its coherence
    band = (hz > 20) & (hz < 5000)
    assert np.mean(difference[band] <= noise[band]) < 0.1  # the coherence does not see the truncation ...
    covered = difference[band] / np.hypot(np.sqrt(cut.truncation[band]), noise[band])
    assert np.mean(covered <= 1.0) > share  # ... which the estimate covers
    assert 0.03 < np.median(covered) < 0.5  # conservative, and not by an estimate of no use


def test_the_noise_model_adds_half_of_the_truncation_to_each_part():
    result = process_taps(_short_taps(1229, noise=1e-5))
    without = estimate_noise(result.frf, coherence=result.coherence, averages=result.averages)
    cut = np.full(result.frf.frequency.n, 1e-4)
    with_it = estimate_noise(result.frf, coherence=result.coherence, averages=result.averages, truncation=cut)
    assert np.allclose(with_it.var_re - without.var_re, 0.5e-4, rtol=1e-9)
    assert np.allclose(with_it.var_im - without.var_im, 0.5e-4, rtol=1e-9)
    with pytest.raises(InvalidValueError, match="truncation of .*expected 20 variances"):
        step = result.frf.frequency.hz[1] - result.frf.frequency.hz[0]
        estimate_noise(result.frf.crop(100, 100 + 20.5 * step), truncation=cut)


def test_the_csv_column_round_trips_and_reaches_the_measurement(tmp_path):
    result = process_taps(_short_taps(1229, noise=1e-5))
    path = tmp_path / "frf.csv"
    write_csv(result.frf, path, coherence=result.coherence, truncation=result.truncation)
    assert path.read_text().splitlines()[0] == "frequency_hz,real,imag,coherence,truncation"
    frf, gamma = read_csv_with_coherence(path)
    assert np.array_equal(frf.data, result.frf.data) and np.array_equal(gamma, result.coherence)
    (tmp_path / "set.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "frf.csv"\n'
                                       'averages = 3\n')
    (measured,) = load_measurements(tmp_path / "set.toml").measurements
    assert np.array_equal(measured.truncation, result.truncation)
    cropped = measured.crop(100, 600)
    assert np.array_equal(cropped.truncation, result.truncation[measured.frf.frequency.band_mask(100, 600)])
    with pytest.raises(InvalidValueError, match="truncation: .*and a coherence"):
        write_csv(result.frf, tmp_path / "no.csv", truncation=result.truncation)


def test_a_bad_truncation_cell_is_refused_with_its_line(tmp_path):
    path = tmp_path / "frf.csv"
    path.write_text("frequency_hz,real,imag,coherence,force_noise,truncation\n"
                    "10,1e-6,-1e-7,0.99,1e-6,1e-4\n20,1e-6,-2e-7,0.99,1e-6,-1\n")
    with pytest.raises(FileFormatError, match=r"line 3: truncation is -1.0; expected a variance >= 0"):
        read_csv_with_coherence(path)
    frf = process_taps(_short_taps(1229)).frf
    with pytest.raises(InvalidValueError, match="truncation: line 1 is nan"):
        Measurement.from_frf(frf, "tool.tip", "tool.tip",
                             truncation=[0.0, float("nan")] + [0.0] * (frf.frequency.n - 2))


def test_the_command_says_what_the_end_of_the_taps_leaves_and_writes_it(tmp_path, capsys):
    files = []
    for k, record in enumerate(_short_taps(1229, noise=1e-5)):
        files.append(str(tmp_path / f"tap{k}.csv"))
        np.savetxt(files[-1], np.column_stack([record.time, record.force, record.response]), delimiter=",",
                   header="time [s],force [N],displacement [m]", comments="")
    out = tmp_path / "frf.csv"
    assert main(["tap", *files, "--out", str(out), "--measurements", str(tmp_path / "set.toml"),
                 "--response", "tool.tip", "--excitation", "tool.tip"]) == 0
    text = capsys.readouterr().out
    assert "truncation: the response still rang at the taps' end" in text
    assert out.read_text().splitlines()[0].endswith(",truncation")
    (measured,) = load_measurements(tmp_path / "set.toml").measurements
    assert measured.truncation is not None and measured.truncation.size == measured.frf.frequency.n
    assert main(["tap", *files, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["truncation_error"]["error"] > 0 and "still rang" in summary["window"]


@pytest.mark.parametrize("header", ["frequency_hz,real,imag,truncation",
                                    "frequency_hz,real,imag,coherence,truncation,force_noise",
                                    "frequency_hz,real,imag,force_noise,coherence"])
def test_the_package_columns_in_another_order_or_without_the_coherence_are_refused_so(tmp_path, header):
    path = tmp_path / "frf.csv"
    cells = ",".join(["0.5"] * (header.count(",") - 2))
    path.write_text(f"{header}\n10,1e-6,-1e-7,{cells}\n20,1e-6,-2e-7,{cells}\n")
    with pytest.raises(FileFormatError, match=r"line 1: the columns .* are the package's in another order or without "
                                              "the coherence; expected 'frequency_hz,real,imag', then 'coherence'"):
        read_csv_with_coherence(path)


def test_the_figure_shows_the_error_the_end_of_the_taps_may_leave():
    import matplotlib.pyplot as plt  # the backend is the Makefile's (Agg)

    from substructure.plot import plot_taps

    result = process_taps(_short_taps(1229, noise=1e-5))
    fig = plot_taps(result)
    magnitude = fig.axes[2]
    (line,) = [ln for ln in magnitude.get_lines() if ln.get_label() == "error the taps' end may leave"]
    drawn = np.asarray(line.get_ydata(), dtype=float)
    expected = np.abs(result.frf.data[:, 0, 0]) * np.sqrt(result.truncation) * 1e6  # um/N, the default unit
    assert np.allclose(drawn, expected, rtol=1e-12, equal_nan=True)
    plt.close(fig)
    died = plot_taps(process_taps(_short_taps(N_LONG, noise=1e-4)))
    assert not [ln for ln in died.axes[2].get_lines() if ln.get_label() == "error the taps' end may leave"]
    plt.close(died)


def test_one_tap_without_samples_before_the_hit_cannot_tell_its_end_from_its_noise():
    # its noise is measured nowhere: whatever its last samples hold would be taken for a tail (it was: an error
    # of 7.5 times the FRF claimed at 32 Hz on a tap that died out)
    (record,) = _short_taps(N_LONG, noise=1e-4, peaks=(50.0,))
    start = int(np.argmax(record.force > 0)) - 1  # the record starts at the hit
    cut = TapRecord(record.time[start:] - record.time[start], record.force[start:], record.response[start:],
                    record.quantity, "at the hit")
    result = process_taps([cut], pre_trigger=0.0)
    assert result.truncation is None
    assert "with one tap and no samples before the hit, an error of its end cannot be told from its noise" \
        in result.window
    # with its noise measured before the hit, one tap cut while it rings has its end's error estimated
    one = process_taps(_short_taps(1229, noise=1e-5, peaks=(50.0,)))
    assert one.truncation is not None and "its truncation is counted" in one.window
    hz, error = _relative_error(one)
    band = (hz > 50) & (hz < 2000)
    assert np.quantile(error[band] / np.sqrt(one.truncation[band]), 0.95) < 1.0
