"""The model seen through a tap test's exponential window, and the window's correlation of neighbouring lines.

A window ``exp(-t/tau)`` on both channels multiplies the impulse response by
``exp(-t/tau)``: the windowed FRF is the structure's at the complex frequency
``omega - i/tau``.  Checked here against the finite-element model of the
tests at complex frequency (a second method: ``K + i w C - w^2 M`` solved with
complex ``w``), and the noise's correlation between lines against windowed
white noise drawn here (Monte Carlo).  End to end (time records to verdict):
``tests/test_tap_to_diagnosis.py``.
"""

from __future__ import annotations

import attrs
import numpy as np
import pytest
from scipy.signal import savgol_filter

from custom_components import NutChuck
from substructure import Frequency, Holder, Mass, default_assembly
from substructure.diagnose import words
from substructure.errors import InvalidValueError
from substructure.frf import FRF
from substructure.measurements import Measurement
from substructure.points import parse_point
from substructure.updating import Likelihood, measured_frfs, window_correlation
from substructure.updating.noise import _kept_share


def _windowed_noise(n: int, tau_over_t: float, draws: int, seed: int) -> np.ndarray:
    """Transforms of white noise records of ``n`` samples through ``exp(-t/tau)``, normalised: ``(draws, lines)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / n  # in records: T = 1
    x = rng.normal(size=(draws, n)) * np.exp(-t / tau_over_t)
    spectrum = np.fft.rfft(x, axis=1)[:, n // 8: 3 * n // 8]  # away from 0 Hz and the Nyquist frequency
    return spectrum / np.sqrt(np.mean(np.abs(spectrum) ** 2))


@pytest.mark.parametrize("tau_over_t", [0.05, 0.2, 0.5])
def test_the_window_correlates_neighbouring_lines_as_said(tau_over_t):
    """|rho_k|^2 = 1 / (1 + (pi k tau / T)^2) between the scores of lines k apart (Monte Carlo, 4000 records),
    and the sum over all lags, 1 + 2 sum |rho_k|^2, is (T/tau) coth(T/tau)."""
    z = np.abs(_windowed_noise(1024, tau_over_t, 4000, seed=1)) ** 2
    z = (z - z.mean()) / z.std()
    for k in (1, 2, 4):
        measured = float(np.mean(z[:, k:] * z[:, :-k]))
        assert measured == pytest.approx(1.0 / (1.0 + (np.pi * k * tau_over_t) ** 2), abs=0.02)
    lags = np.arange(1, 2_000_000)
    series = 1.0 + 2.0 * np.sum(1.0 / (1.0 + (np.pi * lags * tau_over_t) ** 2))
    assert window_correlation(tau_over_t, 1.0) == pytest.approx(series, rel=1e-5)
    assert window_correlation(None, 1.0) == 1.0


@pytest.mark.parametrize("tau_over_t", [None, 0.05, 0.1, 0.2])
def test_the_smoother_keeps_the_share_of_windowed_noise_said(tau_over_t):
    """The noise model's smoother follows correlated noise more than white noise: the residual's variance
    over the noise's, 1 - h0, as drawn (Monte Carlo), for a window of 5 and 9 lines."""
    spectrum = _windowed_noise(2048, tau_over_t if tau_over_t else 1e6, 400, seed=2)
    for w in (5, 9):
        residual = spectrum.real - savgol_filter(spectrum.real, w, 3, axis=1)
        share = float(np.mean(residual[:, w:-w] ** 2) / np.mean(spectrum.real[:, w:-w] ** 2))
        assert share == pytest.approx(1.0 - _kept_share(w, 3, tau_over_t, 1.0), rel=0.05)


def test_fits_and_tests_count_a_windowed_frf_as_fewer_lines():
    """The likelihood weighs each line of a windowed FRF 1/correlation as much (a fit's uncertainty and a
    comparison of chi^2 count what the data hold); the same FRF without a window is untouched."""
    model = default_assembly()
    grid = Frequency.from_hz(np.arange(150.0, 5000.0, 10.0))
    frf = model.frf("tool.tip:y", "tool.tip:y", grid)
    rng = np.random.default_rng(3)
    noisy = attrs.evolve(frf, data=frf.data * (1 + 0.01 * (rng.normal(size=frf.data.shape)
                                                          + 1j * rng.normal(size=frf.data.shape))))
    plain = Measurement.from_frf(noisy, "tool.tip", "tool.tip")
    windowed = attrs.evolve(plain, window_tau=0.2)
    (a,), _ = measured_frfs([plain])
    (b,), _ = measured_frfs([windowed])
    assert a.noise.correlation == 1.0
    assert b.noise.correlation == pytest.approx(window_correlation(0.2, 10.0))
    lik_a, lik_b = Likelihood(model, [a]), Likelihood(model, [b])
    ratio = lik_b.w_re[0] / lik_a.w_re[0]
    assert np.allclose(ratio * np.sqrt(b.noise.correlation * b.noise.var_re / a.noise.var_re), 1.0)


def test_a_component_without_decay_leaves_the_model_on_the_real_lines_and_is_named():
    """A component of one's own whose receptance_matrix takes no decay cannot be evaluated at a complex
    frequency: a windowed measurement's model is then evaluated on the real lines, and the report's window line
    names it (the window's damping then lacking from the model), instead of a wrong number or an error."""
    holder = default_assembly().component("holder")
    model = default_assembly().with_component(NutChuck("holder", holder.segments, nut_mass="150 g"))
    frf = model.frf("tool.tip:y", "tool.tip:y", Frequency.from_hz(np.arange(150.0, 5000.0, 10.0)))
    m = Measurement.from_frf(frf, "tool.tip", "tool.tip", window_tau=0.2)
    (item,), _ = measured_frfs([m])
    ((tau, lacking),) = Likelihood(model, [item]).windows()
    assert tau is None and lacking == ["component 'holder' (NutChuck)"]
    line = words.windowed("tool.tip:y / tool.tip:y", 0.2, 150.0, 5000.0, 2.0, lacking)
    assert "which the model lacks: component 'holder' (NutChuck) cannot be evaluated through it" in line


@attrs.frozen
class _DecayNutChuck(NutChuck):
    """NutChuck able to be seen through a window: its receptance_matrix takes decay (docs/extending.md)."""

    def receptance_matrix(self, refs, frequency_hz, decay=0.0):
        f = np.asarray(frequency_hz, dtype=float)
        tip = [i for i, r in enumerate(refs) if self.position(r) >= self.length_m * (1 - 1e-12)]
        points = list(refs) if tip else [*refs, parse_point(f"{self.name}.tip", allow_dof=False)]
        h = np.moveaxis(Holder.receptance_matrix(self, points, f, decay), -1, 0)  # the beam at omega - i decay
        w2 = (2 * np.pi * f - 1j * decay) ** 2
        z = np.zeros((f.size, 2, 2), dtype=complex)
        z[:, 0, 0], z[:, 1, 1] = -w2 * self.nut_mass.m_as("kg"), -w2 * self.nut_inertia.m_as("kg*m^2")
        t, p = 2 * (tip[0] if tip else len(refs)), 2 * len(refs)
        # the body by structural modification: H - H[:, t] (I + Z H[t, t])^-1 Z H[t, :]
        g = np.linalg.solve(np.eye(2) + z @ h[:, t:t + 2, t:t + 2], z)
        return np.moveaxis(h[:, :p, :p] - h[:, :p, t:t + 2] @ g @ h[:, t:t + 2, :p], 0, -1)


def test_a_component_that_takes_decay_is_seen_through_the_window():
    """The same chuck whose receptance_matrix takes decay is evaluated at the complex frequency: its windowed
    predictions equal those of the built-in equivalent (a plain holder with a 150 g body at its tip)."""
    holder = default_assembly().component("holder")
    custom = default_assembly().with_component(_DecayNutChuck("holder", holder.segments, nut_mass="150 g"))
    builtin = default_assembly().attach(Mass("nut", "holder.tip", "150 g"))
    frf = builtin.frf("tool.tip:y", "tool.tip:y", Frequency.from_hz(np.arange(150.0, 5000.0, 10.0)))
    (item,), _ = measured_frfs([Measurement.from_frf(frf, "tool.tip", "tool.tip", window_tau=0.05)])
    a, b = Likelihood(custom, [item]), Likelihood(builtin, [item])
    assert a.windows() == b.windows() == [(0.05, [])]
    (ya,), (yb,) = a.predict(), b.predict()
    assert np.max(np.abs(ya / yb - 1.0)) < 1e-9
    (y0,) = Likelihood(builtin, [attrs.evolve(item, measurement=attrs.evolve(item.measurement, window_tau=None))]
                       ).predict()
    assert np.max(np.abs(yb / y0 - 1.0)) > 1e-2  # the window's damping is there


def test_accelerance_through_a_window_converts_to_the_receptance_at_the_complex_frequency():
    """A single mode: A(s) = s^2 H(s) measured through the window (s = i omega + 1/tau) converts to H(s)."""
    hz = np.linspace(10.0, 400.0, 100)
    s = 2j * np.pi * hz + 5.0

    def receptance(s):
        return 1.0 / (1e6 + 20.0 * s + 1.0 * s * s)

    accelerance = FRF.single(Frequency.from_hz(hz), s * s * receptance(s), quantity="accelerance")
    assert np.allclose(accelerance.to_receptance(5.0).data[:, 0, 0], receptance(s), rtol=1e-12)
    mobility = FRF.single(Frequency.from_hz(hz), s * receptance(s), quantity="mobility")
    assert np.allclose(mobility.to_receptance(5.0).data[:, 0, 0], receptance(s), rtol=1e-12)
    with pytest.raises(InvalidValueError, match="decay: got -1.0"):
        accelerance.to_receptance(-1.0)


def test_frfs_on_different_lines_are_refused_where_they_enter():
    """Taps of different lengths give different lines; the fits compare every FRF line by line: refused naming
    both grids (before: a broadcasting error deep in the diagnosis)."""
    from substructure.errors import FrequencyAxisMismatchError

    model = default_assembly()
    a, b = (Measurement.from_frf(model.frf("tool.tip:y", "tool.tip:y", Frequency.from_hz(np.arange(150.0, 5000.0, s))),
                                 "tool.tip", "tool.tip") for s in (10.0, 5.0))
    with pytest.raises(FrequencyAxisMismatchError, match=r"485 lines every 10 Hz against 969 every 5 Hz"):
        measured_frfs([a, b])


def test_a_window_time_constant_that_is_not_one_is_refused_by_the_noise_model():
    from substructure.updating import estimate_noise

    frf = default_assembly().frf("tool.tip:y", "tool.tip:y", Frequency.from_hz(np.arange(150.0, 5000.0, 10.0)))
    for bad in (0.0, -0.1, float("nan")):
        with pytest.raises(InvalidValueError, match="window_tau: got"):
            estimate_noise(frf, window_tau=bad)
