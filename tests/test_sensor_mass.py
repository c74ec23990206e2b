"""Sensor mass compensation (thesis ch. 5): data with a 2 g accelerometer made sensor-free."""

import numpy as np
import pytest

from substructure import FRF, Frequency, Sensor, default_assembly, remove_mass
from substructure.smoothing import smooth

GRID = Frequency.from_range("100 Hz", "5000 Hz", "2 Hz")


def _tool_mode(frf: FRF) -> float:
    """The tool mode's peak: a parabola through log|H| on 17 lines around the highest line."""
    f, h = frf.frequency.hz, np.abs(frf.data[:, 0, 0])
    band = (f > 1100) & (f < 1700)  # the tool mode of the built-in assembly, with or without the sensor
    i = int(np.argmax(np.where(band, h, 0.0)))
    near = slice(i - 8, i + 9)
    c = np.polyfit(f[near] - f[i], np.log(h[near]), 2)
    return float(f[i] - c[1] / (2 * c[0]))


def test_removing_the_sensor_recovers_the_sensor_free_frf():
    """Noise-free: eq. 5.4 on the tool-point H measured with a 2 g sensor gives the laser FRF (1e-8)."""
    free = default_assembly()
    with_sensor = free.attach(Sensor("accelerometer", "tool.tip", "2 g"))
    h_free = free.receptance("tool.tip:y", frequency=GRID)
    h_acc = with_sensor.receptance("tool.tip:y", frequency=GRID)
    assert _tool_mode(h_acc) < 0.99 * _tool_mode(h_free)  # the sensor lowers the tool mode (Table 5.1)
    back = remove_mass(h_acc, "tool.tip:y", "2 g")
    assert np.abs(back.data - h_free.data).max() <= 1e-8 * np.abs(h_free.data).max()
    np.testing.assert_allclose(back.data, h_free.data, rtol=1e-8)


@pytest.mark.parametrize("seed", range(5))
def test_on_noisy_data_the_tool_mode_returns_within_half_a_percent(seed):
    free = default_assembly()
    h_free = free.receptance("tool.tip:y", frequency=GRID)
    h_acc = free.attach(Sensor("accelerometer", "tool.tip", "2 g")).receptance("tool.tip:y", frequency=GRID)
    rng = np.random.default_rng(seed)
    z = (rng.standard_normal(h_acc.data.shape) + 1j * rng.standard_normal(h_acc.data.shape)) / np.sqrt(2)
    noisy = FRF(GRID, h_acc.data * (1 + 0.02 * z), h_acc.outputs, h_acc.inputs)
    back = remove_mass(smooth(noisy), "tool.tip:y", "2 g")
    assert _tool_mode(back) == pytest.approx(_tool_mode(h_free), rel=0.005)
    assert abs(_tool_mode(noisy) - _tool_mode(h_free)) > 0.015 * _tool_mode(h_free)  # it had moved
