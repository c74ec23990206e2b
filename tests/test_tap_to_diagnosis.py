"""From the hammer's and the sensor's time records to the verdict, end to end.

Taps on the tool tip of an assembly are simulated here in the time domain: a
half-sine hammer pulse, the accelerometer's response by convolution with the
assembly's impulse response (the FRF on a grid eight times finer than the
record's, transformed back: no wrap-around), noise on both channels at the
level of a good acquisition system (1e-4 of each channel's peak per sample).
The records go through the tap-test processing with its defaults and the
result through the diagnosis.  The rule: an exact model is consistent with
what the taps measured (nothing added), and a body the model lacks is found
as itself, with nothing stacked on top.
"""

from __future__ import annotations

import attrs
import numpy as np
import pytest

from substructure import Frequency, Mass, default_assembly
from substructure.diagnose import DiagnoseSettings, diagnose
from substructure.errors import InvalidValueError
from substructure.identify import identify_joint
from substructure.measurements import Measurement
from substructure.tap import TapRecord, process_taps
from substructure.updating import Likelihood, consistency, measured_frfs

FS = 20480.0  # Hz
T = 0.5  # s per record
PAD = 8  # the impulse response computed over PAD records: it has died out long before


def _taps(truth, seed: int, peaks=(60.0, 75.0, 90.0, 70.0, 80.0), length: float = T, force_noise: float = 1e-4,
          response_noise: float = 1e-4, smooth: bool = False):
    """Tap records of ``truth``; ``smooth``: a Gaussian hammer pulse (68 us standard deviation, -40 dB at the
    Nyquist frequency) instead of the half-sine of 0.25 ms, whose spectrum the sampling cuts at the Nyquist
    frequency: the cut rings ahead of the pulse in the response (what an acquisition's anti-aliasing filter
    prevents), which an exponential window, unlike a plain transform, does not forgive."""
    n, m = int(FS * T), int(FS * length)  # simulated over T, kept: length
    f = np.fft.rfftfreq(PAD * n, 1.0 / FS)
    accelerance = np.empty(f.size, complex)
    h = truth.frf("tool.tip", "tool.tip", Frequency.from_hz(f[1:])).data[:, 0, 0]
    accelerance[1:] = -(2 * np.pi * f[1:]) ** 2 * h
    accelerance[0] = accelerance[1]  # a free body: the acceleration's static part is 1 / mass
    t = np.arange(PAD * n) / FS
    rng = np.random.default_rng(seed)
    records = []
    for k, peak in enumerate(peaks):
        start, width = 0.005, 0.25e-3
        if smooth:
            force = peak * np.exp(-0.5 * ((t - start - 2 * width) / 68e-6) ** 2)
        else:
            force = np.where((t >= start) & (t <= start + width), peak * np.sin(np.pi * (t - start) / width), 0.0)
        response = np.fft.irfft(np.fft.rfft(force) * accelerance, PAD * n)[:m]
        force = force[:m] + rng.normal(0.0, force_noise * peak, m)
        response = response + rng.normal(0.0, response_noise * np.abs(response).max(), m)
        records.append(TapRecord(t[:m], force, response, "acceleration", f"tap {k + 1}"))
    return records


def _measured(records, estimator: str = "H1") -> tuple[Measurement, object]:
    result = process_taps(records, estimator)
    window = result.force_window_s if result.force_noise is not None else None
    m = Measurement.from_frf(result.frf, "tool.tip", "tool.tip", coherence=result.coherence,
                             averages=result.averages, force_noise=result.force_noise,
                             force_window_s=window, estimator=estimator,
                             truncation=result.truncation)  # as substructure tap writes the set
    return m.crop(150.0, 5000.0), result


@pytest.fixture(scope="module")
def model():
    return default_assembly()


def test_an_exact_model_is_consistent_with_its_tap_test(model):
    measured, result = _measured(_taps(model, seed=3))
    # the responses die out within the taps: no exponential window, so no damping the model lacks
    assert result.tau is None and result.window.startswith("none: the response died out")
    assert result.averages == 5 and np.median(measured.coherence) > 0.999
    d = diagnose(model, [measured], progress=False)
    assert d.explained and d.effects == [], d.report


def test_a_body_the_model_lacks_is_found_through_the_tap_test(model):
    truth = model.attach(Mass("sensor", "tool.tip", "4 g"))
    measured, _ = _measured(_taps(truth, seed=4))
    d = diagnose(model, [measured], progress=False)
    assert d.explained, d.report
    (effect,) = d.effects
    assert effect.where == "tool.tip" and effect.name == "sensor-mass"
    mass, std = effect.values["mass"], effect.std["mass"]
    assert abs(mass - 0.004) < max(3 * std, 2e-4), (mass, std)
    # the refined model on what it was not fitted to: the holder's tip and the tool's rotation, above the band
    grid = Frequency.from_hz(np.linspace(5000.0, 8000.0, 301))
    for out, inp in (("holder.tip", "holder.tip"), ("tool.tip:theta", "tool.tip")):
        true = truth.frf(out, inp, grid).data[:, 0, 0]
        before = np.abs(np.log(model.frf(out, inp, grid).data[:, 0, 0] / true)).max()
        after = np.abs(np.log(d.refined_assembly.frf(out, inp, grid).data[:, 0, 0] / true)).max()
        assert after < 0.2 * before, (out, before, after)


def test_an_exact_model_is_consistent_with_three_taps(model):
    """Three taps: the variance each line takes from the coherence is itself an estimate from three
    records (4 degrees of freedom), so a line's whitened residual follows F(2, 4), not the exponential
    (a mean of 2).  The band test takes that into account; before, 4 of these 10 tap tests of the exact
    model were called unexplained (near 150-250 Hz, where the coherence is about 0.5)."""
    peaks = (60.0, 75.0, 90.0)
    for seed in range(10):
        measured, result = _measured(_taps(model, seed=seed, peaks=peaks))
        assert result.averages == 3
        d = diagnose(model, [measured], progress=False)
        assert d.explained and d.effects == [], (seed, d.report)


def test_an_exact_model_is_consistent_with_two_taps(model):
    """Two taps: a line whose variance is mostly the coherence's has 2 degrees of freedom, its score F(2, 2)
    has no finite mean, and the global test's uncapped chi^2 failed 1 of these 10 tests of the exact model
    (2 before the band test took the degrees of freedom); such lines enter it capped, against the capped
    scores' mean and variance."""
    for seed in range(10):
        measured, result = _measured(_taps(model, seed=seed, peaks=(60.0, 75.0)))
        assert result.averages == 2
        d = diagnose(model, [measured], progress=False)
        assert d.explained and d.effects == [], (seed, d.report)


def test_an_exact_model_is_consistent_with_six_taps(model):
    """Six taps: the hammer channel's noise in the pre-trigger, left in the force window, was a smooth
    random error of H1 over hundreds of hertz, largest relative to the response's noise at the tool mode
    (3.8 kHz), where 5 of 20 such tap tests failed a band; the window now opens a pulse width before
    the trigger."""
    peaks = (60.0, 75.0, 90.0, 70.0, 80.0, 65.0)
    for seed in range(10):
        measured, _ = _measured(_taps(model, seed=seed, peaks=peaks))
        d = diagnose(model, [measured], progress=False)
        assert d.explained and d.effects == [], (seed, d.report)


def test_lines_drowned_in_the_response_noise_are_read_linearly(model):
    """Ten times more noise on the accelerometer: below 250 Hz the coherence is near 0 and the log of H1
    is biased; those lines are read in the linear domain (as lines drowned in a noise floor are), so the
    exact model is consistent (before: 0 of 10 such tests), and a 4 g body is still found at its mass."""
    for seed in range(4):
        measured, _ = _measured(_taps(model, seed=seed, peaks=(60.0, 75.0, 90.0), response_noise=1e-3))
        assert np.median(measured.coherence[measured.frf.frequency.hz < 250.0]) < 0.5
        d = diagnose(model, [measured], progress=False)
        assert d.explained and d.effects == [], (seed, d.report)
    truth = model.attach(Mass("sensor", "tool.tip", "4 g"))
    measured, _ = _measured(_taps(truth, seed=4, peaks=(60.0, 75.0, 90.0), response_noise=1e-3))
    d = diagnose(model, [measured], progress=False)
    assert d.explained and len(d.effects) == 1, d.report
    assert abs(d.effects[0].values["mass"] - 0.004) < 3e-4


def _windowed(records, tau):
    result = process_taps(records, "H1", exponential=True, tau=tau)
    return Measurement.from_frf(result.frf, "tool.tip", "tool.tip", coherence=result.coherence,
                                averages=result.averages, force_noise=result.force_noise,
                                force_window_s=result.force_window_s, estimator="H1", window_tau=result.tau,
                                truncation=result.truncation).crop(150.0, 5000.0)


def test_a_windowed_measurement_is_said_so_in_the_report(model):
    """A measurement taken through an exponential window (the measurement set's window_tau_s) carries the
    window's damping: the report says so, with the damping ratio it adds, that the model was compared through
    the same window, and how many times fewer lines its correlated noise counts as, whatever the verdict."""
    records = _taps(model, seed=3, smooth=True)
    measured, _ = _measured(records)
    d = diagnose(model, [_windowed(records, 0.2)], progress=False)
    (line,) = [r for r in d.report if "exponential window" in r]
    lo, hi = measured.frf.frequency.hz[[0, -1]]  # quoted at the band's ends: largest at the lowest line
    assert line.startswith("tool.tip:y / tool.tip:y was measured through an exponential window (tau = 0.2 s)")
    assert f"({1 / (0.2 * 2 * np.pi * lo):.2g} at {lo:.4g} Hz to {1 / (0.2 * 2 * np.pi * hi):.2g} at {hi:.4g} Hz)" \
        in line
    x = 0.2 * np.diff(measured.frf.frequency.hz[:2])[0]  # tau / T: T / tau = 0.5 / 0.2 = 2.5
    assert "compared through the same window" in line
    assert f"counted as {1 / (x * np.tanh(1 / x)):.3g} times fewer lines" in line
    assert not [r for r in diagnose(model, [measured], progress=False).report if "window" in r]


@pytest.mark.parametrize("length, tau, seed", [(0.05, 0.02, 0), (0.1, 0.05, 1), (0.1, 0.05, 2), (0.2, 0.1, 3),
                                               (0.5, 0.03, 4)])
def test_windowed_taps_of_the_exact_model_are_explained_through_the_window(model, length, tau, seed):
    """Taps processed through an exponential window measure the structure at the complex frequency
    omega - i/tau (exactly: the window multiplies the impulse response by exp(-t/tau)); the model is evaluated
    there, and the window's correlation of neighbouring lines is counted: the exact model is explained with
    nothing added (before: not explained, a joint's damping and the tool's loss factor as the partial
    explanation)."""
    d = diagnose(model, [_windowed(_taps(model, seed=seed, length=length, smooth=True), tau)], progress=False)
    assert d.explained and d.effects == [], d.report


def test_windowed_taps_compared_on_the_real_lines_are_not_consistent(model):
    """The windowed FRFs the test above explains, without their window_tau (the model on the real lines, the
    window's damping in the data alone): the exact model is not consistent with them; with it, it is."""
    for seed, length, tau in [(1, 0.1, 0.05), (3, 0.2, 0.1)]:
        windowed = _windowed(_taps(model, seed=seed, length=length, smooth=True), tau)
        for m, consistent in ((windowed, True), (attrs.evolve(windowed, window_tau=None), False)):
            (item,), _ = measured_frfs([m])
            lik = Likelihood(model, [item])
            assert consistency(lik, lik.log_ratios([]), 0).consistent is consistent


def test_bodies_are_found_through_the_window(model):
    """A 4 g body on the tool's tip and a 20 g nut on the holder's, under 0.1 s taps through a 50 ms window:
    each found as itself, at its mass and place, nothing stacked on it."""
    for seed, (point, grams) in enumerate([("tool.tip", 4.0), ("holder.tip", 20.0)]):
        truth = model.attach(Mass("body", point, f"{grams} g"))
        d = diagnose(model, [_windowed(_taps(truth, seed=seed, length=0.1, smooth=True), 0.05)], progress=False)
        assert d.explained and len(d.effects) == 1, d.report
        assert d.effects[0].values["mass"] == pytest.approx(grams * 1e-3, rel=0.02)


@pytest.mark.parametrize("exponential", [False, True])
def test_the_hammer_noise_in_h1_is_what_the_tap_processing_says(model, exponential):
    """The variance of H1's relative error from the hammer channel's noise (TapResult.force_noise) against
    the error itself: the same taps with and without noise on the force, over 30 seeds (Monte Carlo)."""
    errors, predicted = [], []
    for seed in range(30):
        noisy = process_taps(_taps(model, seed, force_noise=1e-3, response_noise=0.0), exponential=exponential)
        clean = process_taps(_taps(model, seed, force_noise=0.0, response_noise=0.0), exponential=exponential)
        errors.append(np.abs(noisy.frf.data[:, 0, 0] / clean.frf.data[:, 0, 0] - 1.0) ** 2)
        predicted.append(noisy.force_noise)
    f = noisy.frf.frequency.hz
    band = (f > 100.0) & (f < noisy.hammer_band_hz)
    ratio = np.mean(errors, axis=0)[band] / np.mean(predicted, axis=0)[band]
    assert 0.8 < np.median(ratio) < 1.2 and np.percentile(ratio, 90) < 1.5
    # the noise measured outside the pulse, and the force window's length (a pulse of 0.25 ms, opened one
    # pulse width before it and closed one after)
    assert noisy.force_noise_rms == pytest.approx(1e-3 * 75.0, rel=0.1)  # the taps' peaks: 60 to 90 N
    assert 0.5e-3 < noisy.force_window_s < 1.2e-3
    assert noisy.force_scatter() == pytest.approx(np.sqrt(np.max(noisy.force_noise[f <= noisy.hammer_band_hz])))
    # an H2 is compared as the H1 of the same taps (gamma^2 H2), whose hammer noise this is; an Hv is not
    h1, h2 = (process_taps(_taps(model, 1), estimator=e) for e in ("H1", "H2"))
    assert np.array_equal(h2.force_noise, h1.force_noise)
    assert process_taps(_taps(model, 1), estimator="Hv").force_noise is None


def test_the_hammer_noise_enters_the_noise_model_over_its_width(model):
    from substructure.updating.noise import VARIANCE_CAP, estimate_noise

    result = process_taps(_taps(model, 1, force_noise=1e-3))
    plain = estimate_noise(result.frf, coherence=result.coherence, averages=result.averages)
    with_force = estimate_noise(result.frf, coherence=result.coherence, averages=result.averages,
                                force_noise=result.force_noise, force_window_s=result.force_window_s)
    lines = 1.0 / (result.force_window_s * (result.frf.frequency.hz[1] - result.frf.frequency.hz[0]))
    expected = np.minimum(plain.var_re + 0.5 * result.force_noise * lines, VARIANCE_CAP)
    np.testing.assert_allclose(with_force.var_re, expected, rtol=1e-12)
    assert lines > 100  # a window of under 1 ms on 2 Hz lines: the error spans hundreds of lines
    with pytest.raises(Exception, match="the force window's length is needed"):
        estimate_noise(result.frf, force_noise=result.force_noise)


@pytest.mark.parametrize("seed", [5, 6, 8, 9])
def test_an_exact_model_is_consistent_with_a_noisy_hammer(model, seed):
    # ten times the hammer's noise (1e-3 of the peak, as on the shipped real records' pre-trigger) and a clean
    # accelerometer: the force window's smooth error dominated the resonances' lines; these seeds were called
    # unexplained, or had corrections invented, before the noise model counted it
    measured, _ = _measured(_taps(model, seed, force_noise=1e-3))
    d = diagnose(model, [measured], progress=False)
    assert d.explained and d.effects == [], d.report


def test_a_light_body_is_still_found_with_a_noisy_hammer(model):
    truth = model.attach(Mass("sensor", "tool.tip", "1 g"))
    measured, _ = _measured(_taps(truth, 2, force_noise=1e-3))
    d = diagnose(model, [measured], progress=False)
    assert d.explained and [e.name for e in d.effects] == ["sensor-mass"], d.report
    assert d.effects[0].values["mass"] == pytest.approx(1e-3, rel=0.1)


def test_the_three_estimators_of_one_set_of_taps_are_ordered_by_their_coherence(model):
    """H1 = Gfx / Gff and H2 = Gxx / Gxf of the same spectra: H1 = gamma^2 H2 exactly (so an H2 with its
    coherence gives the H1 of its taps, Measurement.h1_frf), and the total least squares Hv lies between
    them in magnitude with their phase: the bound the noise model takes for an Hv's bias."""
    records = _taps(model, 2, response_noise=1e-3, force_noise=1e-3)
    h1, h2, hv = (process_taps(records, e) for e in ("H1", "H2", "Hv"))
    a1, a2, av = (r.frf.data[:, 0, 0] for r in (h1, h2, hv))
    gamma = h2.coherence
    np.testing.assert_allclose(gamma * a2, a1, rtol=1e-9)
    m = Measurement.from_frf(h2.frf, "tool.tip", "tool.tip", coherence=gamma, averages=5, estimator="H2")
    np.testing.assert_allclose(m.h1_frf.data[:, 0, 0], a1, rtol=1e-9)
    assert m.crop(200.0, 400.0).estimator == "H2"
    assert np.all(np.abs(a1) <= np.abs(av) * (1 + 1e-9)) and np.all(np.abs(av) <= np.abs(a2) * (1 + 1e-9))
    np.testing.assert_allclose(np.angle(av / a1), 0.0, atol=1e-9)
    assert np.median(gamma[h1.frf.frequency.hz < 250.0]) < 0.9  # low coherence: the three differ there
    # an FRF that is not an H2 with its coherence is compared as it is
    for other in (attrs.evolve(m, estimator="Hv"), attrs.evolve(m, estimator=None), attrs.evolve(m, coherence=None)):
        assert other.h1_frf is other.frf
    with pytest.raises(InvalidValueError, match="estimator: got 'H3'; expected one of H1, H2, Hv, or None"):
        attrs.evolve(m, estimator="H3")


@pytest.mark.parametrize("seed", range(4))
def test_an_exact_model_is_consistent_with_an_h2_estimate(model, seed):
    """H2 exceeds the FRF by 1/gamma^2 where the response's noise is large: compared as it is, each of these
    tap tests of the exact model was called unexplained (at 150-250 Hz, where gamma^2 is about 0.5); its
    coherence makes it the H1 of the same taps, and the report says so."""
    measured, _ = _measured(_taps(model, seed), "H2")
    d = diagnose(model, [measured], progress=False)
    assert d.explained and d.effects == [], d.report
    assert "tool.tip:y / tool.tip:y is an H2 estimate: compared as the H1 of the same taps, gamma^2 H2" \
        in " ".join(d.report)
    bare = diagnose(model, [attrs.evolve(measured, coherence=None)], progress=False)
    assert any("an H2 estimate without its coherence" in r for r in bare.report)


def test_the_bias_an_hv_estimate_may_carry_enters_the_noise_model(model):
    """Closed form of the term: ``(ln gamma^2)^2`` added to the log magnitude's variance (capped), nothing to
    the phase's, ``(1/gamma^2 - 1)^2`` to the linear domain's; none for H1, H2 or one average."""
    from substructure.updating.noise import VARIANCE_CAP, estimate_noise

    result = process_taps(_taps(model, 1, response_noise=1e-3), "Hv")
    frf, gamma = result.frf.crop(150.0, 5000.0), result.coherence[(result.frf.frequency.hz >= 150.0)
                                                                   & (result.frf.frequency.hz <= 5000.0)]
    plain = estimate_noise(frf, coherence=gamma, averages=5)
    hv = estimate_noise(frf, coherence=gamma, averages=5, estimator="Hv")
    b = -np.log(np.clip(gamma, 1e-3, 1.0))
    np.testing.assert_allclose(hv.var_re, np.minimum(plain.var_re + b**2, VARIANCE_CAP), rtol=1e-12)
    np.testing.assert_array_equal(hv.var_im, plain.var_im)
    lin = np.isfinite(plain.linear[1])
    assert lin.any()
    np.testing.assert_allclose(hv.linear[1][lin], plain.linear[1][lin] + (1 / np.clip(gamma, 1e-3, 1) - 1)[lin] ** 2,
                               rtol=1e-12)
    for estimator, averages in (("H1", 5), ("H2", 5), ("Hv", 1)):
        other = estimate_noise(frf, coherence=gamma, averages=averages, estimator=estimator)
        same = estimate_noise(frf, coherence=gamma, averages=averages)
        np.testing.assert_array_equal(other.var_re, same.var_re)


@pytest.mark.parametrize("seed", range(4))
def test_an_exact_model_is_consistent_with_an_hv_estimate_of_noisy_taps(model, seed):
    """Ten times the accelerometer's noise: Hv sits near H2 where the response channel's power is the larger
    (here at the holder and tool modes, 2.6 kHz) and each of these was called unexplained; the noise model
    now counts the bias Hv may carry, up to -ln gamma^2."""
    measured, _ = _measured(_taps(model, seed, response_noise=1e-3), "Hv")
    d = diagnose(model, [measured], progress=False)
    assert d.explained and d.effects == [], d.report


@pytest.mark.parametrize("estimator, grams, response_noise", [("H2", 2, 1e-4), ("H2", 4, 1e-3), ("Hv", 4, 1e-3)])
def test_a_body_is_found_through_h2_and_hv_estimates(model, estimator, grams, response_noise):
    truth = model.attach(Mass("sensor", "tool.tip", f"{grams} g"))
    measured, _ = _measured(_taps(truth, seed=10, response_noise=response_noise), estimator)
    d = diagnose(model, [measured], progress=False)
    assert d.explained, d.report
    (effect,) = d.effects
    assert effect.where == "tool.tip" and effect.name == "sensor-mass"
    assert abs(effect.values["mass"] - grams * 1e-3) < max(3 * effect.std["mass"], 1e-4)


@pytest.mark.parametrize("lines", [slice(100, 103), slice(700, 1450), slice(0, None, 7)],
                         ids=["three lines", "a block of 30 %", "every 7th line"])
def test_lines_without_a_value_are_left_out(model, lines):
    """Lines an FRF holds no value on (zero: an FRF holds no NaN; a dropout, lines an analyser left empty) say
    nothing of the structure.  Compared as values, three zero lines had the exact model called unexplained
    (its error 3.1 times the noise floor); they are left out of every comparison, and the report says so."""
    measured, _ = _measured(_taps(model, seed=2))
    data = measured.frf.data.copy()
    data[lines] = 0.0
    holed = attrs.evolve(measured, frf=attrs.evolve(measured.frf, data=data))
    d = diagnose(model, [holed], progress=False)
    assert d.explained and d.effects == [], d.report
    count = int(np.sum(data[:, 0, 0] == 0))
    (line,) = [r for r in d.report if "holds no value" in r]
    assert line.startswith(f"tool.tip:y / tool.tip:y holds no value on {count} lines of the band")
    assert d.measures.final_error <= 1.5 * d.measures.noise_floor
    if lines.start == 700:  # a body is still found at its mass through the hole
        truth = model.attach(Mass("sensor", "tool.tip", "4 g"))
        found, _ = _measured(_taps(truth, seed=2))
        data = found.frf.data.copy()
        data[lines] = 0.0
        d = diagnose(model, [attrs.evolve(found, frf=attrs.evolve(found.frf, data=data))], progress=False)
        assert d.explained and [e.name for e in d.effects] == ["sensor-mass"], d.report
        assert abs(d.effects[0].values["mass"] - 0.004) < max(3 * d.effects[0].std["mass"], 1e-4)


def test_a_band_with_too_few_values_is_refused(model):
    measured, _ = _measured(_taps(model, seed=2))
    data = measured.frf.data.copy()
    hz = measured.frf.frequency.hz
    data[(hz > 1000.0) & (hz < 1100.0)] = 0.0
    holed = attrs.evolve(measured, frf=attrs.evolve(measured.frf, data=data))
    with pytest.raises(InvalidValueError, match=r"measured FRF tool.tip:y / tool.tip:y: 0 of its \d+ lines in the band "
                                                r"1010-1090 Hz hold a value"):
        diagnose(model, [holed], band=(1010.0, 1090.0), progress=False)


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_an_exact_model_is_consistent_with_taps_cut_while_the_response_rings(model, seed):
    """30 ms taps (33 Hz lines): the response is cut at 0.1 % of its peak, still ringing.  Its truncation was an
    error the coherence does not see (the taps repeat it): 2 of these 4 tests called the exact model
    unexplained (a block at 170-820 Hz).  The taps' end now estimates it, and the noise model counts it."""
    measured, result = _measured(_taps(model, seed=seed, length=0.03))
    assert result.tau is None and result.truncation is not None and "truncation" in result.window
    d = diagnose(model, [measured], progress=False)
    assert d.explained and not d.effects, d.report


@pytest.mark.parametrize("grams, length", [(4.0, 0.02), (10.0, 0.03)])
def test_a_body_is_found_at_its_mass_through_taps_cut_while_the_response_rings(model, grams, length):
    # 10 g at 30 ms rings at 0.3 % of the peak at the end: it was windowed (tau 5 ms), and the window's damping
    # had the diagnosis call it unexplained with a damping change invented on top; now counted, not windowed
    truth = model.attach(Mass("sensor", "tool.tip", f"{grams} g"))
    measured, result = _measured(_taps(truth, seed=3, length=length))
    assert result.tau is None and result.truncation is not None
    d = diagnose(model, [measured], progress=False)
    assert d.explained, d.report
    (effect,) = d.effects
    assert effect.where == "tool.tip" and effect.name == "sensor-mass"
    mass, std = effect.values["mass"], effect.std["mass"]
    assert abs(mass - grams / 1000) < max(3 * std, 0.05 * grams / 1000), (mass, std)


@pytest.mark.parametrize("grams, length, seed", [(20.0, 0.03, 2), (35.0, 0.03, 4), (60.0, 0.1, 5)])
def test_a_nut_on_the_holder_is_found_where_and_as_heavy_as_it_is(model, grams, length, seed):
    """A body on the holder's tip, not the tool's: the scan tried its size on a coarse grid and searched only the
    best place between the grid's values; 20 g at the tip lies between 10 g and 94 g, both far off there, while
    10 g near the base fitted fairly: the body was fitted at the base (13 g) and a section of the holder changed
    instead (20 g and 35 g, 30 ms).  Searching the size at every place must not favour a section change (60 g,
    0.1 s: a first version of the search had one with a 0.92 kg spindle body stacked on it)."""
    truth = model.attach(Mass("nut", "holder.tip", f"{grams} g"))
    measured, _ = _measured(_taps(truth, seed=seed, length=length))
    d = diagnose(model, [measured], progress=False)
    assert d.explained, d.report
    (effect,) = d.effects
    assert effect.name == "added-mass" and effect.where.startswith("holder@"), (effect.name, effect.where)
    assert effect.values["position"] == pytest.approx(0.066, abs=0.002)
    assert effect.values["mass"] == pytest.approx(grams / 1000, rel=0.02)


@pytest.mark.parametrize("length, seed, grams", [(0.1, 5, 0.0), (0.1, 6, 0.0), (0.2, 5, 0.0), (0.1, 5, 6.0)])
def test_a_noise_floor_that_lives_on_a_few_lines_does_not_fail_a_model(model, length, seed, grams):
    """Below the first mode of a short record a few lines hold most of the noise floor (three held 80 % at 0.1 s);
    the plain check of the RMS log ratio against 1.5 floors called the exact model unexplained (1.65, 1.62 and
    1.85 floors; a 6 g sensor found at 6.0 g likewise) on one line three deviations out, or drowned in noise and
    read as the log of a value near zero."""
    truth = model if not grams else model.attach(Mass("sensor", "tool.tip", f"{grams} g"))
    measured, _ = _measured(_taps(truth, seed=seed, length=length))
    d = diagnose(model, [measured], progress=False)
    assert d.final_error > 1.5 * d.noise_floor  # the RMS of the log ratios alone
    assert d.explained, d.report
    assert d.error_check.ratio < 1.5 < d.error_check.allowed
    assert [e.name for e in d.effects] == ([] if not grams else ["sensor-mass"])
    if grams:
        assert d.effects[0].values["mass"] == pytest.approx(grams / 1000, rel=0.02)


@pytest.mark.parametrize("seed", [15, 16])
def test_two_bodies_are_found_through_short_taps(model, seed):
    """4 g on the tool's tip and 30 g on the holder's, 30 ms taps (142 lines): the budget, counted in evaluations of
    all lines, was spent in the first step and the data were left unexplained with the tool's body alone; counted
    as a share of 2,500 lines (``budget_lines``), both are found."""
    truth = model.attach(Mass("sensor", "tool.tip", "4 g")).attach(Mass("nut", "holder.tip", "30 g"))
    measured, _ = _measured(_taps(truth, seed=seed, length=0.03))
    d = diagnose(model, [measured], progress=False)
    assert d.explained, d.report
    found = {e.where.split("@")[0]: e for e in d.effects}
    assert sorted(found) == ["holder", "tool.tip"], [(e.name, e.where) for e in d.effects]
    assert found["tool.tip"].values["mass"] == pytest.approx(0.004, rel=0.02)
    assert found["holder"].values["mass"] == pytest.approx(0.030, rel=0.02)
    assert found["holder"].values["position"] == pytest.approx(0.066, abs=0.002)
    assert not d.search["cut"]
    cut = diagnose(model, [measured], progress=False, settings=DiagnoseSettings(budget_lines=1))
    assert cut.search["cut"] and not cut.explained  # counted in evaluations of its own 142 lines


def test_an_antiresonance_line_the_grid_does_not_resolve_is_scored_by_its_own_coherence(model):
    """45 ms taps (22 Hz lines): the receptance's zero near 180 Hz falls on one line, ten times below its
    neighbours, with a coherence of 0.04 to 0.5.  Read in the linear domain with the variance of its neighbours'
    smoothing residual, the exact model scored 30 to 220 there in 11 of 12 seeds (3 called unexplained); the
    line's own coherence now enters its linear-domain variance, as it enters the log-domain one."""
    from substructure.updating.noise import estimate_noise
    from substructure.updating.selection import LINE_CAP

    scores = []
    for seed in range(1, 13):
        measured, _ = _measured(_taps(model, seed=seed, length=0.045))
        hz = measured.frf.frequency.hz
        k = int(np.argmin(np.abs(hz - 180.0)))
        exact = model.frf("tool.tip", "tool.tip", measured.frf.frequency).data[:, 0, 0]
        assert np.abs(exact[k]) < 0.2 * np.abs(exact[[k - 1, k + 1]]).min()  # one line, far below its neighbours
        noise = estimate_noise(measured.frf, coherence=measured.coherence, averages=measured.averages,
                               force_noise=measured.force_noise, force_window_s=measured.force_window_s,
                               truncation=measured.truncation)
        assert np.isfinite(noise.linear[1][k])  # read in the linear domain
        scores.append(noise.line_scores(np.log(exact / measured.values))[k])
    assert np.median(scores) < 1.5 and max(scores) < LINE_CAP, scores


def test_the_report_says_when_the_taps_ended_while_the_response_rang(model):
    measured, result = _measured(_taps(model, seed=1, length=0.03))
    d = diagnose(model, [measured], progress=False)
    (line,) = [r for r in d.report if "the taps ended while the response still rang" in r]
    hz = measured.frf.frequency.hz
    k = int(np.argmax(measured.truncation))
    assert line.startswith("tool.tip:y / tool.tip:y: the taps ended") and f"near {hz[k]:.4g} Hz" in line
    assert f"up to {np.sqrt(measured.truncation[k]):.2g} relative" in line
    long, _ = _measured(_taps(model, seed=1))
    assert not [r for r in diagnose(model, [long], progress=False).report if "still rang" in r]


def test_an_explained_summary_shows_the_facts_of_the_data_as_notes(model):
    """The facts a report holds whatever the verdict (a window, an H2, lines without a value, the taps' end) were
    printed by the command only for an unexplained diagnosis."""
    from substructure.diagnose import words

    measured, _ = _measured(_taps(model, seed=1, length=0.03))
    d = diagnose(model, [attrs.evolve(measured, window_tau=0.2)], progress=False)
    assert d.explained
    lines = words.summary(d, "built-in", 1)
    notes = [line for line in lines if line.startswith("note: ")]
    assert len(notes) == 2 and any("exponential window" in n for n in notes) and any("still rang" in n for n in notes)
    assert lines[-1].startswith("verdict: explained")


def test_a_joint_identified_from_windowed_taps_has_the_joints_damping_not_the_windows(model):
    """A holder-tool joint of 30 N s/m (the model says 12) identified from 0.1 s taps through a 50 ms window: with
    the model seen through the window, 30 within two standard deviations (two seeds); the same FRFs compared
    on the real lines gave 32.6 +- 0.05 and called it consistent (the window's damping taken for the joint's)."""
    truth = model.with_joint(model.joint("holder-tool").with_parameters(c={"yf": "30 N*s/m"}))
    for seed in (5, 6):
        windowed = _windowed(_taps(truth, seed=seed, length=0.1, smooth=True), 0.05)
        report = identify_joint(model, [windowed], "holder-tool", parameters=("k_yf", "c_yf"))
        assert abs(report.c["yf"] - 30.0) < 2.0 * report.c_std["yf"], (report.c["yf"], report.c_std["yf"])
        assert any("measured through an exponential window (tau = 0.05 s)" in w for w in report.warnings)
        plain = identify_joint(model, [attrs.evolve(windowed, window_tau=None)], "holder-tool",
                               parameters=("k_yf", "c_yf"))
        assert plain.c["yf"] - 30.0 > 20.0 * plain.c_std["yf"]
