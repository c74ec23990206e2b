"""The response through an exponential window the data do not declare, read from the noise.

An analyser that windows the response with ``exp(-t/tau)`` (the usual setting of an impact
test) measures the structure at the complex frequency ``omega - i/tau``: every mode has the
damping ratio ``1/(tau omega)`` more than the structure, which no change of the model makes.
Its CSV or universal-file export seldom says so.  Before, such data made an exact model
"unexplained" with loss factors stacked on it (the independent FE rig through windows of a
half, a fifth and a tenth of the record, with an exact model, a holder-tool joint 30 % softer
and a forgotten 4 g sensor: 9 of 9 unexplained).  The same window correlates the noise of
neighbouring lines, which the noise model reads (``NoiseModel.seen_tau``); the diagnosis now
tries the data read through that window when they are not explained without it, and says
so first.

The windowed data are made here from the rig at ``omega - i/tau`` (``hidden_data.measure``'s
``decay``), with noise through the same window (numpy alone, ``_noisy``), and, for an
accelerance, converted with the complex frequency by hand.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import hidden_data as hd
from substructure import FRF
from substructure.diagnose import DiagnoseSettings, diagnose
from substructure.diagnose.words import summary
from substructure.errors import InvalidValueError
from substructure.measurements import Measurement
from substructure.report.text import diagnosis_verdict
from test_noise_correlated import _noisy

DF = 2.0  # the rig's line spacing [Hz]: a record of 0.5 s


def _through(x: float, seed: int, **hidden) -> list[FRF]:
    """The rig's tip FRF through ``exp(-t/tau)``, ``tau`` a ``1/x`` of the record, with noise through it too."""
    tau = 1.0 / (x * DF)
    return _noisy(hd.measure(noise=0, phase_deg=0, floor=0, decay=1.0 / tau, **hidden), seed, x)


def _accelerance(frf: FRF, tau: float) -> FRF:
    """What the analyser exports: the windowed acceleration over the force, ``-(omega - i/tau)^2`` H."""
    s = frf.frequency.omega - 1j / tau
    return FRF(frf.frequency, frf.data * -(s**2)[:, None, None], frf.outputs, frf.inputs, quantity="accelerance")


def test_a_measurement_read_through_a_window_is_the_one_made_with_it():
    (frf,) = hd.measure(noise=0, phase_deg=0, floor=0)
    tau = 0.07
    omega = frf.frequency.omega
    for quantity, factor in (("accelerance", -(omega**2)), ("mobility", 1j * omega)):
        given = FRF(frf.frequency, frf.data * factor[:, None, None], frf.outputs, frf.inputs, quantity=quantity)
        plain = Measurement.from_frf(given, "tool.tip", "tool.tip")
        read = plain.through_window(tau)
        s = omega - 1j / tau  # the closed form: the quantity over the window's complex frequency
        expected = given.data[:, 0, 0] / (-(s**2) if quantity == "accelerance" else 1j * s)
        np.testing.assert_allclose(read.values, expected, rtol=1e-12)
        assert read.window_tau == tau and read.quantity == quantity and plain.window_tau is None
        np.testing.assert_allclose(read.values, Measurement.from_frf(given, "tool.tip", "tool.tip",
                                                                     window_tau=tau).values, rtol=1e-12)
    receptance = Measurement.from_frf(frf, "tool.tip", "tool.tip")
    np.testing.assert_array_equal(receptance.through_window(tau).values, receptance.values)


def test_reading_through_a_window_refuses_a_second_window_and_a_bad_time_constant():
    (frf,) = hd.measure(noise=0, phase_deg=0, floor=0)
    windowed = Measurement.from_frf(frf, "tool.tip", "tool.tip", window_tau=0.05)
    with pytest.raises(InvalidValueError, match="window_tau.*already"):
        windowed.through_window(0.05)
    plain = Measurement.from_frf(frf, "tool.tip", "tool.tip")
    for bad in (0.0, -0.1, float("nan"), "long"):
        with pytest.raises(InvalidValueError, match="window_tau"):
            plain.through_window(bad)
    with pytest.raises(InvalidValueError, match="seen_window"):
        DiagnoseSettings(seen_window="yes")


def test_an_exact_model_through_an_undeclared_window_is_explained_through_it_and_says_so():
    d = diagnose(hd.nominal_model(), _through(5.0, 1))
    assert d.explained and not d.effects, d.report
    (which, tau), = d.assumed_windows
    assert which.startswith("tool.tip:y / tool.tip:y") and tau == pytest.approx(0.1, rel=0.2)
    assert d.report[0].startswith("explained through an exponential window the data do not declare")
    assert "window_tau_s" in d.report[0] and "times the noise floor" in d.report[0]
    assert d.search["without_window"]["evaluations"] > 0
    saved = json.loads(json.dumps(d.to_json()))
    assert saved["assumed_windows"] == [{"measurement": which, "window_tau_s": tau}]
    assert saved["settings"]["seen_window"] is True
    lines = summary(d, "rig", 1)  # the command's summary and the report page say it before anything else
    assert lines[0] == d.report[0] and sum(d.report[0] in line for line in lines) == 1
    word, sentence = diagnosis_verdict(saved)
    assert word == "agrees" and f"exponential window (tau = {tau:.3g} s)" in sentence


def test_a_softer_joint_in_windowed_accelerances_is_found_alone():
    """Accelerances as the analyser exports them: read at the real frequency first, again through the window."""
    tau = 1.0 / (10.0 * DF)
    (frf,) = _through(10.0, 2, ht_scale=0.7)
    m = Measurement.from_frf(_accelerance(frf, tau), "tool.tip", "tool.tip", file="tap.csv")
    d = diagnose(hd.nominal_model(), [m])
    assert d.explained, d.report
    (found,) = d.effects
    assert (found.name, found.where) == ("joint-stiffness", "holder-tool")
    assert found.values["k_yf"] == pytest.approx(0.7 * 1.43e7, rel=0.03)
    (which, seen), = d.assumed_windows
    assert which == "tool.tip:y / tool.tip:y (tap.csv)" and seen == pytest.approx(tau, rel=0.2)


def test_what_the_window_does_not_explain_stays_unexplained_and_is_said():
    """A softer joint the candidates given cannot make: not explained through the window either; the first
    diagnosis is returned, with a line that the window was tried."""
    runs = _through(5.0, 3, ht_scale=0.7)
    d = diagnose(hd.nominal_model(), runs, effects=["sensor-mass"], open_world=False)
    assert not d.explained and not d.assumed_windows
    assert d.report[-1].startswith("read through the window its noise shows (tool.tip:y / tool.tip:y as through")
    assert "not explained either" in d.report[-1]
    off = diagnose(hd.nominal_model(), runs, effects=["sensor-mass"], open_world=False,
                   settings=DiagnoseSettings(seen_window=False))
    assert not off.explained and not any("either" in line for line in off.report)
    assert "without_window" not in off.search


LOBES = ["--teeth", "2", "--diameter", "10 mm", "--immersion", "1", "--milling", "down", "--kt", "6e8 Pa",
         "--kn", "2e8 Pa", "--speeds", "3000:30000:100"]


def test_lobes_from_a_file_whose_noise_shows_an_undeclared_window_warn_and_name_the_option(capsys, tmp_path):
    """Read as it is, a windowed FRF carries the window's damping into the lobes, which then promise depths the
    tool cannot take: the command says so and names ``--window-tau``; white noise says nothing."""
    from substructure.cli import main
    from substructure.io.frf_files import write_csv

    (windowed,) = _through(5.0, 1)
    (white,) = hd.measure(seed=4)
    for name, frf in (("windowed.csv", windowed), ("white.csv", white)):
        write_csv(frf, tmp_path / name)
    assert main(["lobes", "--frf", str(tmp_path / "windowed.csv"), *LOBES]) == 0
    out, err = capsys.readouterr()
    (line,) = [x for x in out.splitlines() if "declares no window" in x]
    assert line.startswith("warning: ") and "--window-tau" in line and "declares no window" in err
    assert float(line.split("tau = ")[1].split(" s")[0]) == pytest.approx(0.1, rel=0.2)
    assert main(["lobes", "--frf", str(tmp_path / "white.csv"), *LOBES]) == 0
    out, err = capsys.readouterr()
    assert "declares no window" not in out + err
    assert main(["lobes", "--frf", str(tmp_path / "windowed.csv"), "--window-tau", "0.1", *LOBES]) == 0
    out, err = capsys.readouterr()
    assert "declares no window" not in out + err and "exponential window: tau" in out


@pytest.mark.parametrize("hostile", [5, "abc", [1, None], {"window_tau_s": 0.1}, [{"window_tau_s": "x"}], None])
def test_the_report_page_reads_a_hostile_assumed_windows_key_without_error(hostile):
    """A diagnosis JSON edited by hand: the page's sentence says what it can and never fails."""
    word, sentence = diagnosis_verdict({"explained": True, "noise_floor": 0.02, "final_error": 0.02,
                                        "assumed_windows": hostile})
    assert word == "agrees" and ("tau = ?" in sentence) == (hostile == [{"window_tau_s": "x"}])
