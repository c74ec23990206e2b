"""Tap-test processing: synthetic taps through a known system, rejections, readers, the shipped real data."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import optimize, signal

from substructure.datasets import free_free_beam_frfs, impact_records
from substructure.errors import FileFormatError, InvalidValueError
from substructure.io.tap_files import read_tap_csv, read_tap_uff
from substructure.tap import ESTIMATORS, SwappedChannelsError, TapRecord, added_damping, process_taps

FS = 10240.0
N = 10240  # 1 s
M, K, ZETA = 0.5, 0.5 * (2 * np.pi * 400.0) ** 2, 0.01
C = 2 * ZETA * np.sqrt(K * M)


def receptance(s):
    """The 1-DOF receptance at Laplace variable s (closed form)."""
    return 1.0 / (M * s**2 + C * s + K)


def held(hz):
    """lsim holds the force linear between samples: the sampled response sees the triangle's sinc^2(f/fs)."""
    return np.sinc(hz / FS) ** 2


def half_sine(peak=50.0, width=0.6e-3, start=0.01, n=N, fs=FS):
    t = np.arange(n) / fs
    f = np.where((t >= start) & (t <= start + width), peak * np.sin(np.pi * (t - start) / width), 0.0)
    return t, np.clip(f, 0.0, None)


def simulate(force, quantity="displacement", fs=FS):
    """The response by scipy.signal.lsim of the state-space model (independent of the FFT path)."""
    a = [[0.0, 1.0], [-K / M, -C / M]]
    b = [[0.0], [1.0 / M]]
    c, d = {"displacement": ([[1.0, 0.0]], [[0.0]]),
            "acceleration": ([[-K / M, -C / M]], [[1.0 / M]])}[quantity]
    t = np.arange(force.size) / fs
    _, y, _ = signal.lsim((a, b, c, d), force, t)
    return y


def tap(peak=50.0, start=0.01, quantity="displacement", source="tap", **kw):
    t, f = half_sine(peak, start=start, **kw)
    return TapRecord(t, f, simulate(f, quantity), quantity, source)


def test_h1_is_the_closed_form_of_the_windowed_system():
    records = [tap(peak) for peak in (40.0, 55.0, 70.0)]
    result = process_taps(records, exponential=True)
    s = 2j * np.pi * result.frf.frequency.hz + 1.0 / result.tau  # exp(-t/tau): every pole shifted by -1/tau
    expected = receptance(s) * held(result.frf.frequency.hz)
    band = (result.frf.frequency.hz > 20) & (result.frf.frequency.hz < 1500)
    error = np.abs(result.frf.data[band, 0, 0] / expected[band] - 1.0)
    assert error.max() < 2e-3
    assert result.averages == 3 and result.estimator == "H1"
    assert np.all(result.coherence[band] > 0.999999)
    # the closed form of the unwindowed system differs at the resonance by the window's added damping
    peak = np.argmax(np.abs(result.frf.data[:, 0, 0]))
    zeta_total = ZETA + added_damping(result.tau, 400.0)
    assert abs(result.frf.data[peak, 0, 0]) == pytest.approx(1 / (2 * zeta_total * K), rel=0.02)


def test_without_exponential_window_h1_is_the_closed_form():
    result = process_taps([tap()], exponential=False)
    hz = result.frf.frequency.hz
    band = (hz > 20) & (hz < 1500)
    expected = receptance(2j * np.pi * hz) * held(hz)
    assert np.abs(result.frf.data[band, 0, 0] / expected[band] - 1.0).max() < 2e-3
    assert result.tau is None


def test_the_window_is_applied_only_when_the_response_has_not_died_out():
    """1 s holds 25 decay times of the 400 Hz mode (1 %): no window; 50 ms holds one: windowed, saying why."""
    whole = process_taps([tap(peak) for peak in (40.0, 55.0)])
    assert whole.tau is None and whole.window.startswith("none: the response died out within every tap")
    hz = whole.frf.frequency.hz
    band = (hz > 20) & (hz < 1500)
    expected = receptance(2j * np.pi * hz) * held(hz)  # no window: the system itself
    assert np.abs(whole.frf.data[band, 0, 0] / expected[band] - 1.0).max() < 2e-3
    short = process_taps([tap(peak, n=512) for peak in (40.0, 55.0)])
    assert short.tau is not None and "had not died out by the end of tap 2 (0.3 of its peak" in short.window
    assert process_taps([tap(peak, n=512) for peak in (40.0, 55.0)], exponential=False).tau is None
    forced = process_taps([tap(peak) for peak in (40.0, 55.0)], exponential=True)
    assert forced.tau is not None and forced.window == "asked for"


def test_exponential_takes_true_false_or_none_and_refuses_other_values():
    """numpy's booleans are booleans; 0, 1, "no" are refused (0 applied the window: it is not ``False``)."""
    assert process_taps([tap()], exponential=np.False_).tau is None
    assert process_taps([tap()], exponential=np.True_).tau is not None
    for value in (0, 1, "no", 0.0):
        with pytest.raises(InvalidValueError, match=rf"exponential: got {value!r} \({type(value).__name__}\); "
                                                    r"expected True, False or None"):
            process_taps([tap()], exponential=value)


def test_acceleration_is_converted_to_receptance():
    """Through the window the taps measure the system at s = i omega + 1/tau: the accelerance s^2 H(s), and the
    receptance it converts to is H(s) (divided by s^2, not by (i omega)^2, which left a phase error of
    2 / (tau omega))."""
    result = process_taps([tap(quantity="acceleration")], exponential=True)
    hz = result.frf.frequency.hz
    s = 2j * np.pi * hz + 1.0 / result.tau
    expected = receptance(s)  # the windowed system's receptance
    band = (hz > 20) & (hz < 1000)
    # the force's direct part of the acceleration is sampled, not held: 0.5 % here (7 % with (i omega)^2)
    assert np.abs(result.frf.data[band, 0, 0] / expected[band] - 1.0).max() < 0.01
    assert result.measured.quantity == "accelerance" and result.frf.quantity == "receptance"
    assert hz[0] > 0.0  # the 0 Hz line dropped


def _noisy(n_taps, out_noise=0.0, in_noise=0.0, seed=1):
    rng = np.random.default_rng(seed)
    records = []
    for i in range(n_taps):
        t, f = half_sine(50.0 + 5 * i)
        x = simulate(f)
        records.append(TapRecord(t, f + in_noise * rng.standard_normal(N), x + out_noise * rng.standard_normal(N),
                                 "displacement", f"tap{i}"))
    return records


def test_output_noise_lowers_coherence_and_h1_stays_unbiased():
    records = _noisy(30, out_noise=2e-7)
    h1 = process_taps(records, exponential=False)
    h2 = process_taps(records, "H2", exponential=False)
    hz = h1.frf.frequency.hz
    true = process_taps(_noisy(1), exponential=False).frf.data[:, 0, 0]  # noise-free: checked above
    band = (hz > 1000) & (hz < 2000)  # above the mode: small response, low coherence
    assert np.median(h1.coherence[band]) < 0.9
    ratio = h1.frf.data[band, 0, 0] / true[band]
    # unbiased: the complex mean over the band's lines is 1 (its magnitude per line is not: |H + noise| > |H|)
    assert abs(np.mean(ratio) - 1.0) < 0.03
    assert np.median(np.abs(h2.frf.data[band, 0, 0] / true[band])) > 1.05  # H2 biased up by output noise
    assert np.median(h1.coherence[(hz > 300) & (hz < 500)]) > 0.99  # at the mode: a strong response


def test_the_hammer_s_noise_before_the_pulse_is_outside_the_force_window():
    """The force window opens one pulse width before the trigger crossing: the hammer channel's samples
    before it (the pre-trigger's noise) do not enter the FRF.  Shuffled among themselves (the same median
    and spread: the same trigger and baseline), they leave H1 the same to the last bit; shuffled within
    the window, they do not."""
    rng = np.random.default_rng(8)
    records = []
    for k, peak in enumerate((40.0, 55.0, 50.0)):
        t, f = half_sine(peak, start=0.05)
        x = simulate(f)
        records.append(TapRecord(t, f + rng.normal(0.0, 1e-3 * peak, N), x + rng.normal(0.0, 1e-9, N),
                                 "displacement", f"tap {k}"))
    base = process_taps(records, exponential=False).frf.data
    hit = int(0.05 * FS)  # the pulse rises from this sample; each tap starts 5 ms (51 samples) before it

    def shuffled(lo, hi):
        out = []
        for r in records:
            force = r.force.copy()
            force[lo:hi] = rng.permutation(force[lo:hi])
            out.append(TapRecord(r.time, force, r.response, r.quantity, r.source))
        return process_taps(out, exponential=False).frf.data

    assert np.array_equal(shuffled(hit - 45, hit - 12), base)  # before the window (a pulse is ~6 samples)
    assert not np.array_equal(shuffled(hit - 5, hit), base)  # inside it


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_the_frf_and_coherence_do_not_depend_on_the_channels_scale(estimator):
    """Force and response multiplied by 1e150 or 1e-150 (together, or one alone but for Hv, a total least squares
    in the channels' units): the FRF scaled by their ratio,
    the same coherence, windows, band and noise in proportion (their squares overflowed or underflowed: a
    coherence of 0 on every line)."""
    records = _noisy(4, out_noise=2e-7, in_noise=0.05)
    base = process_taps(records, estimator)
    assert np.median(base.coherence) < 0.999  # noisy: a coherence that can move
    together = ((1e150, 1e150), (1e-150, 1e-150))  # Hv weighs the channels' errors in their units: only together
    for f_scale, x_scale in together + (() if estimator == "Hv" else ((1e150, 1.0), (1.0, 1e-150), (1e-150, 1e150))):
        scaled = [TapRecord(r.time, r.force * f_scale, r.response * x_scale, r.quantity, r.source)
                  for r in records]
        got = process_taps(scaled, estimator)
        assert np.allclose(got.frf.data, base.frf.data * (x_scale / f_scale), rtol=1e-9, atol=0)
        assert np.allclose(got.coherence, base.coherence, rtol=0, atol=1e-9)
        assert got.tau == base.tau and got.window == base.window and got.hammer_band_hz == base.hammer_band_hz
        assert got.force_noise_rms == pytest.approx(base.force_noise_rms * f_scale, rel=1e-9)
        assert [t.peak_force for t in got.taps] == pytest.approx([t.peak_force * f_scale for t in base.taps],
                                                                 rel=1e-12)
        assert np.allclose(got.force_spectra_db, base.force_spectra_db + 20 * np.log10(f_scale), rtol=0, atol=1e-9)
        for a, b in ((got.force_noise, base.force_noise), (got.truncation, base.truncation)):
            assert (a is None) == (b is None) and (a is None or np.allclose(a, b, rtol=1e-9, atol=0))


def test_peaks_of_lines_above_the_hammer_s_band_are_none():
    """A result kept to lines above the hammer's usable band has no peaks to report (not a crop's error)."""
    result = process_taps([tap(peak) for peak in (40.0, 55.0)])
    above = process_taps([tap(peak) for peak in (40.0, 55.0)], band=(result.hammer_band_hz + 100.0, 5000.0))
    assert result.hammer_band_hz < 4900.0 and above.frf.frequency.hz[0] > result.hammer_band_hz
    assert above.peaks().size == 0


def test_input_noise_biases_h1_down_and_not_h2():
    records = _noisy(30, in_noise=0.3)
    kw = dict(exponential=False, force_window_extra=1e9)  # keep the force's noise over the whole tap
    h1 = process_taps(records, **kw)
    h2 = process_taps(records, "H2", **kw)
    hv = process_taps(records, "Hv", **kw)
    hz = h1.frf.frequency.hz
    true = process_taps(_noisy(1), **kw).frf.data[:, 0, 0]
    band = (hz > 2000) & (hz < 4000)  # where the pulse's force is weak
    r1 = np.median(np.abs(h1.frf.data[band, 0, 0] / true[band]))
    r2 = np.median(np.abs(h2.frf.data[band, 0, 0] / true[band]))
    rv = np.median(np.abs(hv.frf.data[band, 0, 0] / true[band]))
    assert r1 < 0.95
    assert r2 == pytest.approx(1.0, abs=0.03)
    assert r1 * (1 - 1e-9) <= rv <= r2 * (1 + 1e-9)  # in SI units Gff >> Gxx: Hv lies next to H1


def test_hv_is_the_total_least_squares_direction():
    records = _noisy(6, out_noise=1e-7, in_noise=0.05, seed=3)
    h1, h2, hv = (process_taps(records, e, exponential=False) for e in ("H1", "H2", "Hv"))
    # the spectral matrix over Gff from H1 = Gfx/Gff and H2 = Gxx/Gxf: [[1, H1], [conj(H1), H2 conj(H1)]];
    # Hv is the direction [1, H] orthogonal to the eigenvector of its smallest eigenvalue
    a, b = h1.frf.data[:, 0, 0], h2.frf.data[:, 0, 0]
    g = np.empty((a.size, 2, 2), dtype=complex)
    g[:, 0, 0], g[:, 0, 1], g[:, 1, 0], g[:, 1, 1] = 1.0, a, np.conj(a), (b * np.conj(a)).real
    _, v = np.linalg.eigh(g)
    smallest = v[:, :, 0]
    h_tls = -smallest[:, 0] / smallest[:, 1]  # [-H, 1] is orthogonal to the data direction [1, conj(H)]
    hz = hv.frf.frequency.hz
    band = (hz > 20) & (hz < 3000)
    assert np.allclose(hv.frf.data[band, 0, 0], h_tls[band], rtol=1e-6)
    assert np.all(np.abs(a[band]) <= np.abs(hv.frf.data[band, 0, 0]) * (1 + 1e-9))
    assert np.all(np.abs(hv.frf.data[band, 0, 0]) <= np.abs(b[band]) * (1 + 1e-9))


def test_double_hit_is_rejected_with_its_time():
    good = tap(60.0, source="good")
    t, f = half_sine(60.0)
    _, f2 = half_sine(20.0, start=0.2)
    f = f + f2
    bad = TapRecord(t, f, simulate(f), "displacement", "bad.csv")
    result = process_taps([good, bad])
    assert result.averages == 1
    (rejected,) = result.rejected
    assert rejected.source == "bad.csv" and rejected.number == 2
    assert rejected.reason.startswith("double hit at t = 0.2")


def test_clipped_channels_are_rejected():
    t, f = half_sine(60.0, width=1e-3)
    x = simulate(f)
    clipped_force = TapRecord(t, np.minimum(f, 30.0), x, "displacement", "f.csv")
    clipped_response = TapRecord(t, f, np.clip(x, -0.7 * x.max(), 0.7 * x.max()), "displacement", "x.csv")
    result = process_taps([tap(), clipped_force, clipped_response])
    reasons = {t.source: t.reason for t in result.rejected}
    assert reasons["f.csv"].startswith("clipped: column 'force' stays at its maximum")
    assert reasons["x.csv"].startswith("clipped: column 'response'")
    assert result.averages == 1


def test_a_dead_response_channel_is_said_dead_not_clipped():
    """A response that is the same number throughout (a sensor not connected) is no overload."""
    rng = np.random.default_rng(3)
    t, f = half_sine(50.0)
    for level in (0.0, 2.5):
        records = [TapRecord(t, f + rng.normal(0.0, 1e-3, N), np.full(N, level), "displacement", f"tap {k}")
                   for k in range(2)]
        with pytest.raises(InvalidValueError, match="dead channel: column 'response' is"):
            process_taps(records)


def test_a_dead_force_channel_is_said_dead_not_swapped():
    """A hammer channel of zeros beside a ringing response was called swapped channels: it is a dead channel,
    rejected by its tap as a dead response channel is (one tap a record, or in a record cut with tap_length)."""
    t, f = half_sine(50.0)
    dead = TapRecord(t, np.zeros(N), simulate(f), "displacement", "dead.csv")
    result = process_taps([tap(), dead])
    (rejected,) = result.rejected
    assert rejected.source == "dead.csv" and rejected.reason.startswith(
        "dead channel: column 'force' is 0 throughout the tap (a sensor not connected")
    with pytest.raises(InvalidValueError, match=r"no tap kept: tap 1 \(dead.csv\): dead channel: column 'force' is "
                                                r"0 throughout the record"):
        process_taps([dead], tap_length=0.5)


def test_a_record_of_complex_samples_is_refused_by_its_field():
    t, f = half_sine(50.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's warning of a dropped imaginary part is no answer
        for field, args in (("force", (t, f + 1j * f, f)), ("response", (t, f, f.astype(complex)))):
            with pytest.raises(InvalidValueError, match=rf"{field}: got complex samples \(complex128\); expected "
                                                        r"real samples of a time record"):
                TapRecord(*args)


def test_a_hit_at_the_end_of_the_record_is_said_so_not_swapped():
    """A hit in the record's last samples: the response has hardly begun; it is not a swapped record."""
    rng = np.random.default_rng(4)
    t, f = half_sine(50.0, start=(N - 3) / FS)
    record = TapRecord(t, f + rng.normal(0.0, 1e-3, N), simulate(f), "displacement", "late.csv")
    with pytest.raises(InvalidValueError, match=r"late.csv: the hit in column 'force' comes at t = 0.99"):
        process_taps([record])
    with pytest.raises(SwappedChannelsError):  # swapped, with the hit early: still said swapped
        t, f = half_sine(50.0)
        x = simulate(f)
        process_taps([TapRecord(t, x * 1e7, f * 1e-7, "displacement", "early.csv")])


def test_a_tap_hit_near_its_record_s_end_is_rejected_not_every_tap_cut_to_it():
    """Three good taps and one hit 10 ms before its record ends: the late one is rejected as cut short (by file and
    number), the FRF is that of the three good ones (it was every tap cut to 150 samples, windowed with tau 2 ms)."""
    good = [tap(peak, source=f"good{k}.csv") for k, peak in enumerate((40.0, 55.0, 70.0))]
    late = tap(60.0, start=0.99, source="late.csv")
    alone, both = process_taps(good), process_taps([good[0], late, good[1], good[2]])
    assert both.averages == 3 and [t.number for t in both.rejected] == [2]
    (rejected,) = both.rejected
    assert rejected.source == "late.csv" and rejected.peak_force == pytest.approx(60.0, rel=0.02)
    assert rejected.reason.startswith("cut short: the record ends 0.01494 s after this tap's start (t = 0.9851 s), "
                                      "under 0.25 of the taps' median 0.9949 s")
    assert both.tap_samples == alone.tap_samples and both.tau is None and alone.shortest is None
    assert np.array_equal(both.frf.data, alone.frf.data) and np.array_equal(both.coherence, alone.coherence)
    # taps of records of different lengths are all cut to the shortest kept one, which the result names
    mixed = process_taps([tap(40.0, source="long.csv"), tap(55.0, n=N // 2, source="half.csv")])
    assert mixed.averages == 2 and mixed.tap_samples <= N // 2 - 51
    assert mixed.shortest == "tap 2 (half.csv): its record ends 0.4949 s after its start"
    assert mixed.summary()["shortest"] == mixed.shortest and both.summary()["shortest"] is None


def test_a_force_within_its_noise_is_no_hit():
    rng = np.random.default_rng(7)
    t = np.arange(N) / FS
    quiet = TapRecord(t, 0.01 * rng.standard_normal(N), 1e-9 * rng.standard_normal(N), "displacement", "q.csv")
    result = process_taps([tap(), quiet])
    (rejected,) = result.rejected
    assert rejected.reason.startswith("no hit")
    with pytest.raises(InvalidValueError, match=r"no tap kept: tap 1 \(q.csv\): no hit"):
        process_taps([quiet])


def test_swapped_channels_are_an_error_naming_file_and_column():
    t, f = half_sine(60.0)
    x = simulate(f, "acceleration")
    swapped = TapRecord(t, x, f, "acceleration", "swap.csv", "force [N]", "acceleration [m/s^2]")
    with pytest.raises(SwappedChannelsError, match=r"swap.csv: column 'force \[N\]' does not look like"):
        process_taps([swapped])


def test_one_long_record_of_five_taps_is_split_in_five():
    n = 5 * N
    t = np.arange(n) / FS
    f = np.zeros(n)
    for k in range(5):
        f += half_sine(40.0 + 10 * k, start=0.05 + k * 1.0, n=n)[1]
    x = simulate(f)
    record = TapRecord(t, f, x, "displacement", "long.csv")
    result = process_taps(record, tap_length=0.9, pre_trigger=0.01, exponential=True)
    assert [tp.kept for tp in result.taps] == [True] * 5
    assert [round(tp.start_s, 3) for tp in result.taps] == [0.04, 1.04, 2.04, 3.04, 4.04]
    assert [round(tp.peak_force) for tp in result.taps] == [40, 50, 60, 70, 80]
    hz = result.frf.frequency.hz
    s = 2j * np.pi * hz + 1.0 / result.tau
    band = (hz > 50) & (hz < 1500)
    # each tap's tail holds what the structure still did at the cut: a small, bounded difference
    assert np.median(np.abs(result.frf.data[band, 0, 0] / (receptance(s) * held(hz))[band] - 1)) < 0.01


def test_records_of_different_sample_rates_are_refused():
    a = tap(source="a.csv")
    t, f = half_sine(fs=2 * FS, n=2 * N)
    b = TapRecord(t, f, simulate(f, fs=2 * FS), "displacement", "b.csv")
    with pytest.raises(InvalidValueError, match=r"b.csv: sampled at 20480 Hz, a.csv at 10240 Hz"):
        process_taps([a, b])


def test_record_checks_name_the_column():
    t, f = half_sine()
    x = simulate(f)
    with pytest.raises(InvalidValueError, match=r"r.csv: column 'response' has 10239 samples"):
        TapRecord(t, f, x[:-1], source="r.csv")
    y = x.copy()
    y[5] = np.nan
    with pytest.raises(InvalidValueError, match=r"r.csv: column 'response', sample 5"):
        TapRecord(t, f, y, source="r.csv")
    gap = t.copy()
    gap[100:] += 0.5 / FS  # a sample lost: half a step late from there on
    with pytest.raises(InvalidValueError, match=r"r.csv: column 'time', sample 100: step"):
        TapRecord(gap, f, x, source="r.csv")
    same = TapRecord.from_samples(f, x, "10.24 kHz", "displacement")
    assert same.sample_rate == FS and np.array_equal(same.time, t)


def test_a_result_becomes_a_measurement_with_coherence_and_averages():
    from substructure.measurements import Measurement

    result = process_taps(_noisy(3, out_noise=1e-8))
    m = Measurement.from_frf(result.measured, "tool.tip", "tool.tip", coherence=result.coherence,
                             averages=result.averages)
    assert m.averages == 3 and np.array_equal(m.coherence, result.coherence)
    assert np.allclose(m.values, result.frf.data[:, 0, 0]) and m.quantity == "receptance"


# -- files ---------------------------------------------------------------------------------------------------------

def _write(path, header, columns):
    rows = "\n".join(",".join(repr(float(v)) for v in row) for row in np.column_stack(columns))
    path.write_text(header + "\n" + rows + "\n")
    return path


def test_csv_in_g_and_in_millivolts_reads_in_si(tmp_path):
    t, f = half_sine()
    x = simulate(f, "acceleration")
    g = _write(tmp_path / "g.csv", "time [s],force [N],acceleration [g]", [t, f, x / 9.80665])
    record = read_tap_csv(g)
    assert record.quantity == "acceleration" and np.allclose(record.response, x)
    mv = _write(tmp_path / "mv.csv", "time [ms],force [mV],acceleration [mV]", [t * 1e3, f * 2.25, x / 9.80665 * 10.2])
    record = read_tap_csv(mv, sensitivity="10.2 mV/g", hammer_sensitivity="2.25 mV/N")
    assert np.allclose(record.force, f) and np.allclose(record.response, x) and np.allclose(record.time, t)
    with pytest.raises(FileFormatError, match=r"mv.csv: column 'acceleration \[mV\]': the channel is a voltage"):
        read_tap_csv(mv, hammer_sensitivity="2.25 mV/N")
    with pytest.raises(FileFormatError, match=r"g.csv: column 'acceleration \[g\]': the channel is already"):
        read_tap_csv(g, sensitivity="10.2 mV/g")
    with pytest.raises(FileFormatError, match="holds an acceleration, and the quantity option says velocity"):
        read_tap_csv(g, quantity="velocity")
    v = _write(tmp_path / "v.csv", "time [s],force [N],velocity [mm/s]", [t, f, x])
    assert read_tap_csv(v).quantity == "velocity" and np.allclose(read_tap_csv(v).response, x * 1e-3)


def test_a_header_written_as_a_comment_as_numpy_savetxt_writes_it(tmp_path):
    """``numpy.savetxt(..., header=...)`` puts the header after '# ': a comment line right above the rows that
    names every column with its unit is the header (whatever its separator); a comment that does not stays a
    comment, and the file without a header is refused as before."""
    t, f = half_sine()
    x = simulate(f, "acceleration")
    table = np.column_stack([t, f, x])
    for case, kw in [("spaces", dict(header="time(s) force(N) acceleration(m/s^2)")),
                     ("commas", dict(header="time [s], force [N], acceleration [m/s^2]")),
                     ("tabs", dict(header="time [s]\tforce [N]\tacceleration [m/s^2]", delimiter="\t")),
                     ("under notes", dict(header="tap 3, operator K\ntime(s), \t force(N), \t acceleration(m/s^2)"))]:
        path = tmp_path / f"{case.replace(' ', '_')}.txt"
        np.savetxt(path, table, **kw)
        record = read_tap_csv(path)
        assert record.force_column == "force [N]" and record.response_column == "acceleration [m/s^2]", case
        np.testing.assert_allclose(record.force, f, rtol=1e-15, atol=0)
        np.testing.assert_allclose(record.response, x, rtol=1e-15, atol=0)
    path = tmp_path / "notes.txt"
    np.savetxt(path, table, header="three channels: time force acceleration")
    with pytest.raises(FileFormatError, match=r"notes.txt, line 2: numbers with no header above them"):
        read_tap_csv(path)


@pytest.mark.parametrize("text, message", [
    ("", r"e.csv: the file is empty"),
    ("time [s],force,acceleration [m/s^2]\n0,1,2\n", r"e.csv, line 1: column 2 'force' has no unit"),
    ("time [s],force [N],acceleration [m/s^2]\n", r"e.csv: a header and no samples"),
    ("time [s],force [N],acceleration [m/s^2]\n0,1,2\n1,2\n", r"e.csv, line 3: 2 value\(s\); expected 3"),
    ("time [s],force [N],acceleration [m/s^2]\n0,1,2\n1,nan,2\n", r"e.csv, line 3: column 'force \[N\]' is nan"),
    ("time [s],force [N],acceleration [m/s^2]\n0,1,x\n", r"e.csv, line 2: column 'acceleration \[m/s\^2\]' is 'x'"),
    ("time [s],force [N],acceleration [bogus]\n0,1,2\n", r"e.csv, line 1: cannot read the unit 'bogus'"),
    ("time [s],force [N]\n0,1\n", r"e.csv, line 1: 2 columns"),
])
def test_csv_errors_name_file_line_and_column(tmp_path, text, message):
    path = tmp_path / "e.csv"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=message):
        read_tap_csv(path)


def test_uff_time_records_read_by_their_data_types(tmp_path):
    import pyuff

    t, f = half_sine()
    x = simulate(f, "acceleration")
    path = tmp_path / "tap.uff"
    uff = pyuff.UFF(str(path))
    for data, spec, unit, node in ((x / 9.80665, 12, "g", 2), (f, 13, "N", 1)):
        uff.write_sets(pyuff.prepare_58(
            func_type=1, rsp_node=node, rsp_dir=3, ref_node=1, ref_dir=3, data=data, x=t, num_pts=t.size,
            abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=1 / FS, abscissa_spec_data_type=17,
            ordinate_spec_data_type=spec, ordinate_axis_units_lab=unit, id1=f"node {node}",
            orddenom_spec_data_type=0, orddenom_axis_units_lab="", abscissa_axis_units_lab="s",
            z_axis_spec_data_type=0, z_axis_axis_units_lab=""), mode="add")
    record = read_tap_uff(path)
    assert record.quantity == "acceleration"
    assert np.allclose(record.force, f) and np.allclose(record.response, x, rtol=1e-6, atol=1e-9 * np.ptp(x))
    assert record.force_column.startswith("record 1")
    with pytest.raises(FileFormatError, match="says velocity"):
        read_tap_uff(path, quantity="velocity")


# -- the shipped real data ----------------------------------------------------------------------------------------

def test_pyfrf_impact_records_give_the_known_coherence_and_peaks():
    result = process_taps(impact_records())
    assert result.averages == 5 and not result.rejected
    hz = result.frf.frequency.hz
    band = (hz >= 20) & (hz <= 5000)
    assert np.median(result.coherence[band]) > 0.99
    peaks = result.peaks(20, 5000)
    for known in (900.0, 2640.0, 3669.0, 3689.0, 4093.0, 4128.0, 4164.0, 4392.0, 4470.0):
        assert np.min(np.abs(peaks - known)) <= 3.0, known
    assert hz[1] - hz[0] == 1.0  # 25.6 kHz over 1 s, the time column's rounding undone


def test_pyuff_free_free_beam_peaks_follow_euler_bernoulli():
    roots = [optimize.brentq(lambda x: np.cos(x) * np.cosh(x) - 1.0, (n + 0.5) * np.pi - 0.4, (n + 0.5) * np.pi + 0.4)
             for n in range(1, 7)]
    ratios = (np.array(roots) / roots[0]) ** 2
    for frf in free_free_beam_frfs():
        c = frf.crop(20, 1000)
        peaks = c.peaks()
        magnitude = np.abs(c.data[:, 0, 0])
        six = np.sort(peaks[np.argsort(-magnitude[np.searchsorted(c.frequency.hz, peaks)])[:6]])
        assert np.allclose(six, [52, 142, 279, 460, 687, 959], atol=3)
        assert np.allclose(six / six[0], ratios, rtol=0.05)


def test_the_windows_added_damping_is_taken_out_of_the_half_power_damping():
    # a longer tap, so that the 1-DOF peak (8 Hz wide at 400 Hz) spans many lines
    t, f = half_sine(n=4 * N)
    record = TapRecord(t, f, simulate(f), "displacement", "long tap")
    result = process_taps(record, tau=0.1)
    (peak,) = result.damping(result.peaks(100, 1000))
    added = 1 / (0.1 * 2 * np.pi * peak["frequency_hz"])
    assert peak["added_damping_ratio"] == pytest.approx(added)
    assert peak["damping_ratio"] == pytest.approx(ZETA + added, rel=0.01)  # what the windowed FRF shows
    assert peak["damping_ratio_corrected"] == pytest.approx(ZETA, rel=0.01)  # the structure's own
    assert abs(peak["damping_ratio"] - ZETA) > 0.3 * ZETA  # the window's share is not negligible here


def test_the_figure_shows_spectra_band_coherence_and_frf():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from substructure.plot import plot_taps

    result = process_taps(_noisy(2, out_noise=1e-8))
    fig = plot_taps(result, title="two taps")
    ax_f, ax_c, ax_m, ax_p = fig.axes
    assert len(ax_f.lines) == 3  # two taps and the band's line
    assert ax_f.lines[-1].get_xdata()[0] == result.hammer_band_hz
    assert np.array_equal(ax_c.lines[0].get_ydata(), result.coherence)
    assert ax_m.get_yscale() == "log" and "two taps" in fig._suptitle.get_text()
    plt.close(fig)


def test_a_tap_the_record_cuts_short_is_rejected_and_a_quiet_long_record_is_an_error():
    n = 2 * N
    t = np.arange(n) / FS
    f = half_sine(50.0, start=0.05, n=n)[1] + half_sine(60.0, start=1.5, n=n)[1]
    record = TapRecord(t, f, simulate(f), "displacement", "long.csv")
    result = process_taps(record, tap_length=0.9, pre_trigger=0.01)
    assert [tp.kept for tp in result.taps] == [True, False]
    assert result.taps[1].reason.startswith("cut short: the record ends 0.5099 s into this tap of 0.9 s")
    rng = np.random.default_rng(5)
    quiet = TapRecord(t, 0.01 * rng.standard_normal(n), 1e-9 * rng.standard_normal(n), "displacement", "q.csv")
    with pytest.raises(InvalidValueError, match=r"no tap kept: tap 1 \(q.csv\): no hit"):
        process_taps(quiet, tap_length=0.9)


def test_csv_of_another_acquisition_system_semicolons_decimal_commas_and_parentheses(tmp_path):
    """Exports of decimal-comma locales: 'Time (s);Force (N);Acceleration (g)' and 0,5 in the cells."""
    t, f = half_sine()
    x = simulate(f)
    plain = _write(tmp_path / "plain.csv", "time [s],force [N],acceleration [g]", [t, f, x])
    rows = ["Time (s);Force (N);Acceleration (g)"] + [
        ";".join(repr(float(v)).replace(".", ",") for v in row) for row in zip(t, f, x)]
    (tmp_path / "semi.csv").write_text("\n".join(rows) + "\n")
    a, b = read_tap_csv(plain), read_tap_csv(tmp_path / "semi.csv")
    assert b.quantity == a.quantity == "acceleration"
    assert np.array_equal(a.time, b.time) and np.array_equal(a.force, b.force)
    assert np.array_equal(a.response, b.response)
    tabbed = ["time [s]\tforce [N]\tacceleration [g]"] + ["\t".join(repr(float(v)) for v in row)
                                                         for row in zip(t, f, x)]
    (tmp_path / "tab.csv").write_text("\n".join(tabbed) + "\n")
    assert np.array_equal(read_tap_csv(tmp_path / "tab.csv").response, a.response)


def test_the_offset_is_read_before_the_force_window_not_from_what_rings_ahead_of_the_pulse():
    """A response with a constant offset (a sensor's bias) and, in the last 0.3 ms before the pulse, what an
    acquisition's linear-phase filter spreads ahead of it.  The offset is read from the samples before the force
    window opens: through the exponential window an error c of the offset is c / (1/tau + i omega) on every line,
    not on the 0 Hz line alone (read up to the pulse, it took the ringing for offset)."""
    t, f = half_sine(55.0)
    clean = simulate(f)
    ahead = (t >= 0.01 - 0.3e-3) & (t < 0.01)
    ring = np.where(ahead, 0.3 * clean.max(), 0.0)  # one-signed: its mean is no offset
    result = process_taps([TapRecord(t, f, clean + 2e-7 + ring, "displacement", "tap")], exponential=True, tau=0.05)
    hz = result.frf.frequency.hz
    # the closed form, and what the ringing itself adds to H = X / F on the same cut of the record, same window
    first = int(round(result.taps[0].start_s * FS))
    cut = slice(first, first + int(round(FS / hz[1])))
    w = np.exp(-(t[cut] - 0.01) / result.tau)
    ring_h = np.fft.rfft(ring[cut] * w) / np.fft.rfft(f[cut] * w)
    expected = receptance(2j * np.pi * hz + 1.0 / result.tau) * held(hz) + ring_h[np.searchsorted(
        np.fft.rfftfreq(w.size, 1.0 / FS), hz)]
    band = (hz > 20) & (hz < 1500)
    assert np.abs(result.frf.data[band, 0, 0] / expected[band] - 1.0).max() < 5e-3
    # read up to the pulse, the offset would have been the bias plus the ringing's mean: that error, as it shows
    p = int(round((0.01 - result.taps[0].start_s) * FS))
    leak = np.mean(ring[cut][:p]) * np.fft.rfft(w)[np.searchsorted(np.fft.rfftfreq(w.size, 1.0 / FS), hz)] / \
        np.fft.rfft(f[cut] * w)[np.searchsorted(np.fft.rfftfreq(w.size, 1.0 / FS), hz)]
    assert np.abs(leak[band] / expected[band]).max() > 0.02


@pytest.mark.parametrize("scale", [1e3, 1e-3])
def test_a_time_axis_in_other_units_than_read_is_refused_by_the_hammer_s_pulse(scale):
    # times in ms read as s gave an FRF up to 7 Hz with modes below 1 Hz, said "kept", without a word of doubt
    r = tap()
    wrong = TapRecord(r.time * scale, r.force, r.response, r.quantity, "tap.csv")
    with pytest.raises(InvalidValueError, match=r"tap.csv: the hammer's pulse lasts (\S+) ms \(median of the 1 kept "
                                                r"taps\) .* a hammer's lasts about 0\.05 to 10 ms: the time axis is "
                                                r"not in the unit it was read in") as caught:
        process_taps([wrong])
    said = float(str(caught.value).split("lasts ")[1].split(" ms")[0])
    assert said == pytest.approx(0.6 * scale, rel=0.05)  # the half sine's 0.6 ms above the trigger level
    # the same pulse read right, and one of 0.05 ms at 100 kHz or 10 ms at 2 kHz, are taps
    assert process_taps([r]).taps[0].pulse_width_s == pytest.approx(0.6e-3, abs=2 / FS)
    t, f = half_sine(width=5e-5, n=100_000, fs=1e5)
    assert process_taps([TapRecord(t, f, simulate(f, fs=1e5))]).taps[0].kept
    t, f = half_sine(width=1e-2, n=4000, fs=2e3)  # a soft tip on a heavy hammer, on a structure ringing at 40 Hz
    ring = np.where(t > 0.01, np.exp(-(t - 0.01) / 0.2) * np.sin(2 * np.pi * 40.0 * (t - 0.01)), 0.0)
    assert process_taps([TapRecord(t, f, ring)]).taps[0].kept


def test_a_pulse_of_a_sample_or_two_at_a_low_rate_is_not_judged_short():
    t, f = half_sine(width=0.2e-3, n=1000, fs=1e3, start=0.1)  # a steel tip sampled at 1 kHz: one sample
    f[100] = 50.0
    assert process_taps([TapRecord(t, f, simulate(f, fs=1e3))]).taps[0].kept
