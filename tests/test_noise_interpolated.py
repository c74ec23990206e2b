"""An FRF interpolated onto a finer grid: the noise of its measured lines, and the comparisons on them.

``MeasurementSet`` asks for measurements on one grid and says to interpolate them first; an
FRF measured every 4th or 8th line of that grid and interpolated onto it holds 4 or 8 times as
many lines as measurements.  Read as measured, a cubic spline's smooth lines hid the noise
from the smoothing residual (a noise floor 3 to 16 times too low) and straight lines over 8
lines made it look correlated: on the independent FE rig, 16 of 16 tests of the kind made
here were unexplained (a cubic spline over 4 lines with an exact model, a softer joint, a
4 g sensor and a 35 g nut; a spline and straight lines over 8 lines with an exact model and
a softer joint; two seeds each).  The lines are now read as interpolated from the data themselves
(an interpolant's differences vanish between its knots), and the noise and the comparisons
are those of the measured lines: checked against the same data on the coarse grid, which
must give the same diagnosis.
"""

from __future__ import annotations

import numpy as np
import pytest

import hidden_data as hd
import real_noise
from substructure import FRF, Frequency
from substructure.diagnose import diagnose
from substructure.io.frf_files import read_csv, write_csv
from substructure.updating import estimate_noise, interpolated_from


def _coarse(frf: FRF, step: int, seed: int, first: int = 0) -> FRF:
    """Every ``step``-th line of an exact FRF from ``first``, with 2 % relative noise and an additive floor."""
    rng = np.random.default_rng(seed)
    h = frf.data[first::step, 0, 0]

    def noise():
        return (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size)) / np.sqrt(2)

    data = h * (1 + 0.02 * noise()) + 1e-3 * np.median(np.abs(h)) * noise()
    return FRF(Frequency.from_hz(frf.frequency.hz[first::step]), data[:, None, None], frf.outputs, frf.inputs)


def _fine(coarse: FRF, step: int, kind: str) -> FRF:
    """The coarse FRF interpolated onto the grid ``step`` times finer that it spans."""
    hz = coarse.frequency.hz
    return coarse.interpolate(Frequency.from_hz(np.linspace(hz[0], hz[-1], (hz.size - 1) * step + 1)), kind=kind)


@pytest.fixture(scope="module")
def exact() -> FRF:
    (frf,) = hd.measure(noise=0.0, phase_deg=0.0, floor=0.0)
    return frf


@pytest.mark.parametrize("step, kind, degree", [(2, "linear", 1), (3, "linear", 1), (8, "linear", 1),
                                                (4, "cubic", 3), (16, "cubic", 3)])
def test_the_measured_lines_are_read_from_an_interpolated_frf(exact, step, kind, degree):
    fine = _fine(_coarse(exact, step, 1), step, kind)
    assert interpolated_from(fine.data[:, 0, 0]) == (step, 0, degree)
    later = fine.crop(lo=fine.frequency.hz[1])  # the first line between knots: the knots from the next-but-one
    assert interpolated_from(later.data[:, 0, 0]) == (step, step - 1, degree)


def test_held_values_and_values_written_with_six_digits_are_read_too(exact):
    coarse = _coarse(exact, 4, 2)
    held = np.repeat(coarse.data[:, 0, 0], 4)
    assert interpolated_from(held) == (4, 0, 0)
    fine = _fine(coarse, 4, "linear").data[:, 0, 0]
    six = np.array([complex(float(f"{x.real:.6g}"), float(f"{x.imag:.6g}")) for x in fine])
    assert interpolated_from(six) == (4, 0, 1)


def test_measured_lines_are_not_taken_for_interpolated(exact):
    """Noisy lines (simulated, the real residuals at three levels, values with 4 digits) and exact ones."""
    frfs = [f for seed in range(10) for f in hd.measure(seed=seed)]
    frfs += [f for offset in (0, 500, 1000) for level in (1.0, 3.0)
             for f in real_noise.with_real_noise([exact], offset, level)]
    values = [f.data[:, 0, 0] for f in frfs] + [exact.data[:, 0, 0]]
    values.append(np.array([complex(float(f"{x.real:.4g}"), float(f"{x.imag:.4g}")) for x in values[0]]))
    assert [interpolated_from(v) for v in values] == [None] * len(values)


def test_the_noise_of_an_interpolated_frf_is_that_of_its_measured_lines(exact, tmp_path):
    coarse = _coarse(exact, 4, 3)
    fine = _fine(coarse, 4, "cubic")
    write_csv(fine, tmp_path / "fine.csv")  # as a file writes it: read back to the same floats
    noise = estimate_noise(read_csv(tmp_path / "fine.csv", output="tool.tip:y", input="tool.tip:y"))
    alone = estimate_noise(coarse)
    assert noise.interpolated == (4, 3)
    np.testing.assert_array_equal(np.flatnonzero(noise.held), np.arange(0, fine.frequency.n, 4))
    np.testing.assert_allclose(noise.var_re[noise.held], alone.var_re, rtol=1e-9)
    assert noise.floor == pytest.approx(alone.floor, rel=0.05)
    assert noise.select(fine.frequency.band_mask(1000.0, 2000.0)).held.sum() == pytest.approx(1000 / 8, abs=1)


@pytest.mark.parametrize("step, kind", [(4, "cubic"), (8, "linear")])
def test_an_exact_model_on_interpolated_data_is_explained_as_on_the_coarse_grid(exact, step, kind):
    coarse = _coarse(exact, step, 4)
    on_lines = diagnose(hd.nominal_model(), [_fine(coarse, step, kind)])
    assert on_lines.explained and not on_lines.effects, on_lines.report
    (note,) = [line for line in on_lines.report if "interpolated from every" in line]
    assert f"every {step}th" in note and f"on the {coarse.frequency.n} measured lines" in note
    alone = diagnose(hd.nominal_model(), [coarse])
    assert on_lines.final_error == pytest.approx(alone.final_error, rel=1e-9)
    assert on_lines.noise_floor == pytest.approx(alone.noise_floor, rel=1e-9)


def test_a_softer_joint_on_interpolated_data_is_found_alone():
    (exact,) = hd.measure(noise=0.0, phase_deg=0.0, floor=0.0, ht_scale=0.7)
    d = diagnose(hd.nominal_model(), [_fine(_coarse(exact, 4, 1), 4, "cubic")])
    assert d.explained, d.report
    (found,) = d.effects
    assert (found.name, found.where) == ("joint-stiffness", "holder-tool")
    assert found.values["k_yf"] == pytest.approx(0.7 * 1.43e7, rel=0.03)


@pytest.mark.parametrize("quantity", ["accelerance", "mobility"])
@pytest.mark.parametrize("tau", [None, 0.1])
def test_an_interpolated_accelerance_or_mobility_is_read_as_such_once_a_receptance(exact, quantity, tau):
    """Analysers export accelerances: interpolated as such, then divided by ``-omega^2`` (or ``i omega``; at
    ``omega - i/tau`` through a window) into the receptance compared, whose lines are no interpolant."""
    from substructure.measurements import Measurement

    coarse = _coarse(exact, 4, 6)
    s = coarse.frequency.omega - (1j / tau if tau else 0.0)
    factor = -(s**2) if quantity == "accelerance" else 1j * s
    given = FRF(coarse.frequency, coarse.data * factor[:, None, None], coarse.outputs, coarse.inputs,
                quantity=quantity)
    m = Measurement.from_frf(_fine(given, 4, "cubic"), "tool.tip", "tool.tip", window_tau=tau)
    assert estimate_noise(m.frf, window_tau=tau).interpolated == (4, 3)


@pytest.mark.parametrize("values", [np.full(200, 1e-6 + 0j), np.linspace(1.0, 2.0, 200) + 0j, np.zeros(200, complex),
                                    np.array([1.0, np.nan, 2.0] * 60, complex), np.ones(2, complex),
                                    np.full(200, 1e300 - 1e300j), np.array([], complex)],
                         ids=["constant", "a straight line", "zeros", "not finite", "two lines", "huge", "empty"])
def test_values_that_say_nothing_of_measured_lines_read_as_none(values):
    """A constant or one straight line is no interpolant between knots (every difference vanishes, across too);
    values that are not finite, too few or beyond any structure say nothing, without error."""
    assert interpolated_from(values) is None
