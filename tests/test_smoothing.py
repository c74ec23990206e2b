"""Tests of substructure.smoothing: Savitzky-Golay smoothing of complex FRFs."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.signal import savgol_filter

from substructure import FRF, Frequency
from substructure.errors import InvalidValueError, SubstructureWarning
from substructure.smoothing import PEAK_BIAS, CoarseDataWarning, choose_window, smooth

GRID = Frequency.from_range("100 Hz", "4000 Hz", "1 Hz")
MODES = ((800.0, 2.0e7), (2300.0, 5.0e7))  # natural frequency (Hz), modal stiffness (N/m)


def two_modes(hz: np.ndarray, zeta: float) -> np.ndarray:
    """Receptance of two well separated modes, each ``1/k`` at 0 Hz."""
    omega = 2 * np.pi * hz
    total = np.zeros(hz.size, dtype=complex)
    for fn, k in MODES:
        wn = 2 * np.pi * fn
        total += (wn**2 / k) / (wn**2 - omega**2 + 2j * zeta * wn * omega)
    return total


def noisy(zeta: float, seed: int = 7, level: float = 0.02, grid: Frequency = GRID) -> tuple[FRF, np.ndarray]:
    rng = np.random.default_rng(seed)
    truth = two_modes(grid.hz, zeta)
    noise = (rng.standard_normal(grid.n) + 1j * rng.standard_normal(grid.n)) / np.sqrt(2)
    return FRF.single(grid, truth * (1 + level * noise), "tool.tip:y", "tool.tip:y"), truth


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.abs(x) ** 2)))


@pytest.mark.parametrize("zeta", [0.05, 0.02, 0.01])
def test_smoothing_brings_noisy_data_closer_to_the_truth(zeta):
    frf, truth = noisy(zeta)
    smoothed = smooth(frf)
    before, after = rms(frf.data[:, 0, 0] - truth), rms(smoothed.data[:, 0, 0] - truth)
    assert after < 0.6 * before
    assert smoothed.outputs == frf.outputs and smoothed.quantity == frf.quantity
    assert smoothed.frequency == frf.frequency
    # near a peak 2 % noise hides shifts of a few lines; the peaks stay within 10 % of their bandwidth
    found = smoothed.peaks(prominence=0.05)
    for fn, _ in MODES:
        true_peak = GRID.hz[np.argmax(np.abs(truth) * (np.abs(GRID.hz - fn) < 300))]
        assert np.min(np.abs(found - true_peak)) <= 0.1 * 2 * zeta * fn


@pytest.mark.parametrize("zeta", [0.05, 0.02, 0.01])
def test_smoothing_preserves_peak_frequencies(zeta):
    frf, _ = noisy(zeta, level=0.0)
    step = GRID.hz[1] - GRID.hz[0]
    before, after = frf.peaks(), smooth(frf).peaks()
    assert before.size == after.size == 2
    assert np.abs(after - before).max() <= step


def test_chosen_window_keeps_the_peak_height():
    frf, truth = noisy(0.02, level=0.0)
    smoothed = smooth(frf)
    loss = 1 - np.abs(smoothed.data[:, 0, 0]).max() / np.abs(truth).max()
    assert 0 <= loss <= 1.2 * PEAK_BIAS


def test_window_shrinks_with_damping():
    windows = [choose_window(noisy(zeta)[0]) for zeta in (0.05, 0.02, 0.01)]
    assert windows[0] > windows[1] > windows[2]
    assert all(w % 2 == 1 and w >= 5 for w in windows)
    # about half the half-power bandwidth 2 zeta fn (in lines) of the sharper (first) mode
    assert windows[0] == pytest.approx(0.5 * 2 * 0.05 * 800, rel=0.2)


def test_window_is_chosen_over_all_entries():
    frf, _ = noisy(0.05)
    sharp, _ = noisy(0.01)
    both = FRF(GRID, np.concatenate([frf.data, sharp.data], axis=2), ["a:y"], ["a:y", "b:y"])
    assert choose_window(both) == choose_window(sharp)
    smoothed = smooth(both, window=choose_window(sharp))
    np.testing.assert_array_equal(smoothed.data[:, :, 1:], smooth(sharp).data)


def test_explicit_window_is_used_as_given():
    frf, _ = noisy(0.02)
    smoothed = smooth(frf, window=21, polyorder=2)
    expected = savgol_filter(frf.data.real, 21, 2, axis=0) + 1j * savgol_filter(frf.data.imag, 21, 2, axis=0)
    np.testing.assert_array_equal(smoothed.data, expected)


def test_coarse_data_warn():
    grid = Frequency.from_range("100 Hz", "4000 Hz", "5 Hz")
    frf, _ = noisy(0.005, grid=grid)  # half-power bandwidth 8 Hz: under 2 lines
    with pytest.warns(CoarseDataWarning, match="too coarse"):
        window = choose_window(frf)
    assert window == 5
    assert issubclass(CoarseDataWarning, SubstructureWarning)
    with pytest.warns(CoarseDataWarning):
        smooth(frf)


def test_fine_data_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        choose_window(noisy(0.02)[0])


@pytest.mark.parametrize(
    "window, polyorder, match",
    [
        (10, 3, "odd"),
        (3, 3, "larger than polyorder"),
        (1, 1, "larger than polyorder"),
        (GRID.n + 2, 3, "only"),
        (11.0, 3, "integer"),
        (11, -1, "polyorder"),
    ],
)
def test_window_errors(window, polyorder, match):
    frf, _ = noisy(0.02)
    with pytest.raises(InvalidValueError, match=match):
        smooth(frf, window=window, polyorder=polyorder)


def test_non_uniform_grid_is_refused():
    hz = np.concatenate([np.arange(100.0, 200.0, 1.0), np.arange(200.0, 300.0, 2.0)])
    frf = FRF.single(Frequency.from_hz(hz), two_modes(hz, 0.02))
    with pytest.raises(InvalidValueError, match="not uniform.*interpolate"):
        smooth(frf, window=5)
    with pytest.raises(InvalidValueError, match="not uniform"):
        choose_window(frf)


def test_no_peak_needs_an_explicit_window():
    grid = Frequency.from_range("10 Hz", "100 Hz", "1 Hz")
    frf = FRF.single(grid, two_modes(grid.hz, 0.02))  # below the first mode: no peak
    with pytest.raises(InvalidValueError, match="give the window explicitly"):
        smooth(frf)
    assert smooth(frf, window=9).shape == frf.shape
