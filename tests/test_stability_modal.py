"""Modal parameters (substructure.stability.modal): modes, synthesis, CSV files, the modal fit."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from substructure import FRF, FileFormatError, Frequency, InvalidValueError, UnitError
from substructure.stability import MODES_CSV_HEADER, ModalFitter, ModalFitWarning, ModalModel, Mode, fit_modes, xy_frf
from substructure.units import Q_

TRUE_MODES = [("x", 820.0, 0.025, 1.2e7), ("x", 1480.0, 0.018, 5.0e6), ("x", 2650.0, 0.03, 2.2e7)]


def true_model(direction="x") -> ModalModel:
    return ModalModel([Mode(direction, Q_(f, "Hz"), z, Q_(k, "N/m")) for _, f, z, k in TRUE_MODES])


def test_mode_receptance_closed_forms():
    mode = Mode("x", "1000 Hz", 0.02, "1e7 N/m")
    assert mode.receptance([1000.0])[0] == pytest.approx(1 / (2j * 0.02 * 1e7))
    assert mode.receptance([1e-6])[0] == pytest.approx(1e-7, rel=1e-9)  # static: 1/k
    assert mode.mass_kg == pytest.approx(1e7 / (2 * np.pi * 1000) ** 2)


def test_mode_checks():
    with pytest.raises(InvalidValueError, match="damping_ratio"):
        Mode("x", "1000 Hz", 1.5, "1e7 N/m")
    with pytest.raises(InvalidValueError, match="direction"):
        Mode("z", "1000 Hz", 0.02, "1e7 N/m")
    with pytest.raises(InvalidValueError, match="stiffness.*positive"):
        Mode("x", "1000 Hz", 0.02, "-1e7 N/m")
    with pytest.raises(UnitError, match="frequency"):
        Mode("x", 1000.0, 0.02, "1e7 N/m")
    with pytest.raises(InvalidValueError, match="at least one mode"):
        ModalModel([])


def test_a_direction_without_modes_is_rigid():
    frf = true_model().xy_frf(Frequency.from_range("500 Hz", "3000 Hz", "10 Hz"))
    assert frf.outputs == ("x", "y")
    assert np.all(frf.data[:, 1, 1] == 0) and np.all(frf.data[:, 0, 1] == 0)
    np.testing.assert_allclose(frf.data[:, 0, 0], sum(m.receptance(frf.frequency.hz) for m in true_model().modes))


def test_csv_round_trip_and_errors(tmp_path):
    model = ModalModel(list(true_model().modes) + [Mode("y", "900 Hz", 0.02, "1.5e7 N/m")])
    path = tmp_path / "modes.csv"
    model.to_csv(path)
    assert path.read_text().splitlines()[0] == MODES_CSV_HEADER
    assert ModalModel.from_csv(path) == model
    bad = tmp_path / "bad.csv"
    bad.write_text(MODES_CSV_HEADER + "\nx,900,0.02,1e7\nz,900,0.02,1e7\n")
    with pytest.raises(FileFormatError, match="bad.csv, line 3.*direction"):
        ModalModel.from_csv(bad)
    bad.write_text(MODES_CSV_HEADER + "\nx,900,abc,1e7\n")
    with pytest.raises(FileFormatError, match=r"line 2, column 3 \(damping_ratio\): cannot read 'abc' as a number"):
        ModalModel.from_csv(bad)
    bad.write_text("direction,frequency,zeta,k\nx,900,0.02,1e7\n")
    with pytest.raises(FileFormatError, match="header"):
        ModalModel.from_csv(bad)
    with pytest.raises(FileFormatError, match="no such file"):
        ModalModel.from_csv(tmp_path / "missing.csv")


@pytest.mark.parametrize("row, column, message", [
    ("x,922,0.011,-1.34e6", "column 4 (stiffness_n_per_m): got '-1.34e6'", "a modal stiffness in N/m, 1 to 1e+12"),
    ("x,922,0.011,0", "column 4 (stiffness_n_per_m): got '0'", "a modal stiffness in N/m"),
    ("x,922,0.011,inf", "column 4 (stiffness_n_per_m): got 'inf'", "a modal stiffness in N/m"),
    ("x,0,0.011,1.34e6", "column 2 (frequency_hz): got '0'", "a natural frequency in Hz, 0.1 to 1e+06"),
    ("x,922,nan,1.34e6", "column 3 (damping_ratio): got 'nan'", "a damping ratio 0 < zeta < 1"),
    ("x,922,1.1%,1.34e6", "column 3 (damping_ratio): cannot read '1.1%' as a number", "not 1.1%"),
    ("X,922,0.011,1.34e6", "column 1 (direction): got 'X'", "'x' (feed) or 'y' (normal)"),
])
def test_a_bad_cell_is_named_by_line_and_column_as_written(tmp_path, row, column, message):
    bad = tmp_path / "bad.csv"
    bad.write_text(f"{MODES_CSV_HEADER}\ny,900,0.02,1e7\n{row}\n")
    with pytest.raises(FileFormatError) as info:
        ModalModel.from_csv(bad)
    text = str(info.value)
    assert text.startswith(f"{bad}, line 3, {column}; expected ") and message in text
    assert "Quantity" not in text and "<Q" not in text


def test_a_mode_listed_twice_is_refused_naming_both_lines(tmp_path):
    bad = tmp_path / "dup.csv"
    bad.write_text(f"{MODES_CSV_HEADER}\nx,922,0.011,1.34e6\ny,922,0.011,1.34e6\n\nx,922,0.011,1.34e6\n")
    with pytest.raises(FileFormatError, match=r"dup.csv, line 5 \(x, 922 Hz\) repeats line 2: one mode listed "
                                              r"twice would be counted twice \(the depth limit halved\)"):
        ModalModel.from_csv(bad)
    bad.write_text(f"{MODES_CSV_HEADER}\nx,922,0.011,1.34e6\nx,922.0,0.02,3e6\n")
    with pytest.raises(FileFormatError, match=r"line 3 \(x, 922.0 Hz\) has the direction and natural frequency of "
                                              r"line 2: two modes at exactly one frequency in one direction are one"):
        ModalModel.from_csv(bad)
    bad.write_text(f"{MODES_CSV_HEADER}\nx,922,0.011,1.34e6\ny,922,0.011,1.34e6\nx,922.5,0.011,1.34e6\n")
    assert len(ModalModel.from_csv(bad).modes) == 3  # the same mode in x and y, and a close one: three modes


def test_a_mode_given_as_quantities_is_refused_in_plain_words():
    with pytest.raises(InvalidValueError) as info:
        Mode("x", "922 Hz", 0.011, Q_(-1.34e6, "N/m"))
    assert "<Quantity" not in str(info.value) and "-1.34e+06" in str(info.value)


def noisy_frf(noise=0.01, seed=1) -> FRF:
    grid = Frequency.from_range("400 Hz", "4000 Hz", "2 Hz")
    h = true_model().receptance(grid.hz)[:, 0, 0]
    rng = np.random.default_rng(seed)
    h = h + noise * np.abs(h).max() * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size)) / np.sqrt(2)
    return FRF.single(grid, h, "tool.tip:y", "tool.tip:y")


def test_modal_fit_recovers_the_modes_from_noisy_data():
    fit = ModalFitter().fit(noisy_frf())
    assert len(fit.modes_) == 3
    for mode, (_, f, z, k) in zip(fit.modes_, TRUE_MODES):
        assert mode.frequency_hz == pytest.approx(f, rel=2e-3)
        assert mode.damping_ratio == pytest.approx(z, rel=0.05)
        assert mode.stiffness_n_per_m == pytest.approx(k, rel=0.05)
    predicted = fit.predict()
    assert predicted.frequency == fit.frequency_
    truth = noisy_frf(noise=0.0).data[:, 0, 0]
    assert np.linalg.norm(predicted.data[:, 0, 0] - truth) / np.linalg.norm(truth) < 0.02


def test_modal_fit_with_residual_terms_for_modes_outside_the_band():
    fit = ModalFitter(band=(1100.0, 4000.0)).fit(noisy_frf(noise=0.0))  # the 820 Hz mode is below the band
    assert [round(m.frequency_hz) for m in fit.modes_] == [1480, 2650]
    assert fit.residual_inverse_mass_ > 0  # a mode below the band acts as a mass
    assert fit.relative_error_ < 0.01


def test_fit_modes_symmetric_and_errors():
    model = fit_modes(noisy_frf())
    assert sorted({m.direction for m in model.modes}) == ["x", "y"] and len(model.modes) == 6
    with pytest.raises(InvalidValueError, match="found 3 peaks"):
        ModalFitter(n_modes=5).fit(noisy_frf())
    with pytest.raises(InvalidValueError, match="translational"):
        ModalFitter().fit(xy_frf(noisy_frf()))
    flat = FRF.single(Frequency.from_range("400 Hz", "600 Hz", "2 Hz"), np.full(101, 1e-7 + 0j))
    with pytest.raises(InvalidValueError, match="no peak"):
        ModalFitter().fit(flat)


def test_fit_modes_warns_on_cross_terms_and_poor_fits():
    h = noisy_frf(noise=0.0)
    with pytest.warns(ModalFitWarning, match="cross"):
        fit_modes(xy_frf(h, h, xy=0.1 * h, yx=0.1 * h))
    with pytest.warns(ModalFitWarning, match="miss the data"):
        fit_modes(noisy_frf(noise=0.3), n_modes=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit_modes(h)
