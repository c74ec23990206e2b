"""Stability from an FRF measured through an exponential window: the window's damping taken out.

A window ``exp(-t/tau)`` on both channels gives ``H(i omega + 1/tau)``: every
mode with its decay rate ``1/tau`` larger.  The checks: the closed form of
modes evaluated at ``s + 1/tau`` (written here, not by the library) comes
back as the structure's modes and FRF; lobes from the corrected data equal
the lobes of the structure itself, while the windowed data promise more;
with noise on the data, the correction still lands on the structure's
damping; taps simulated in the time domain (``scipy.signal.lsim``) through
``substructure tap`` and ``substructure lobes``; the file's window line, its
hostile variants and a measurement set that leaves the key out.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from scipy import signal

from substructure import FRF, Frequency
from substructure.cli import main
from substructure.errors import FileFormatError, InvalidValueError, WindowedFRFWarning
from substructure.io.frf_files import read_csv, read_csv_window, read_csv_with_coherence, write_csv
from substructure.measurements import MeasurementSet
from substructure.stability import (MillingCut, ModalFitWarning, ModalModel, Mode, mode_without_window, spindle_speeds,
                                    window_removed, xy_frf, zoa)
from substructure.units import Q_

MODES = [("900 Hz", 0.02, 2.0e7), ("1500 Hz", 0.03, 5.0e7)]
CUT = MillingCut(2, "10 mm", "10 mm", kt="6e8 Pa", kn="2e8 Pa", milling="down")
SPEEDS = spindle_speeds("3000 rpm", "30000 rpm", "50 rpm")


def closed_form(s, modes=MODES):
    """Sum of ``(1/m) / (s^2 + 2 zeta omega_n s + omega_n^2)`` at the Laplace variable ``s``."""
    out = np.zeros_like(s)
    for fn, zeta, k in modes:
        wn = 2 * np.pi * float(Q_(fn).m_as("Hz"))
        out = out + (wn**2 / k) / (s**2 + 2 * zeta * wn * s + wn**2)
    return out


def _frf(hz, values):
    return FRF.single(Frequency.from_hz(hz), values)


@pytest.mark.parametrize("tau", [0.01, 0.03, 0.2])
def test_the_closed_form_through_the_window_comes_back_as_the_structure(tau):
    hz = np.linspace(200.0, 3000.0, 1401)
    s = 2j * np.pi * hz
    fixed = window_removed(_frf(hz, closed_form(s + 1.0 / tau)), tau)
    exact = closed_form(s)
    assert np.max(np.abs(fixed.frf.data[:, 0, 0] - exact)) < 1e-9 * np.max(np.abs(exact))
    assert np.array_equal(fixed.frf.data[:, 1, 1], fixed.frf.data[:, 0, 0])  # a symmetric tool
    got = sorted((m.frequency_hz, m.damping_ratio, m.stiffness_n_per_m)
                 for m in fixed.modes.modes if m.direction == "x")
    for (f, zeta, k), (fn, z, kk) in zip(got, MODES):
        assert f == pytest.approx(float(Q_(fn).m_as("Hz")), rel=1e-9)
        assert zeta == pytest.approx(z, rel=1e-7)
        assert k == pytest.approx(kk, rel=1e-7)
    # the modes as fitted carry 1/(tau omega): at 900 Hz, the window's added damping ratio (to first order)
    measured = min(fixed.measured.modes, key=lambda m: m.frequency_hz)
    assert measured.damping_ratio - 0.02 == pytest.approx(1 / (tau * 2 * np.pi * 900.0), rel=0.02)


def test_lobes_of_the_corrected_data_are_the_structures_and_the_windowed_ones_promise_more():
    hz = np.linspace(200.0, 3000.0, 1401)
    s = 2j * np.pi * hz
    tau = 0.03
    windowed = _frf(hz, closed_form(s + 1.0 / tau))
    truth = zoa(xy_frf(_frf(hz, closed_form(s))), CUT, SPEEDS)
    fixed = zoa(window_removed(windowed, tau).frf, CUT, SPEEDS)
    raw = zoa(xy_frf(windowed), CUT, SPEEDS)
    np.testing.assert_allclose(fixed.depth_limit_m, truth.depth_limit_m, rtol=1e-7)
    assert fixed.absolute_limit_m == pytest.approx(truth.absolute_limit_m, rel=1e-7)
    # the window's 0.59 % on a 2 % mode: the lobes as measured promise about a third more depth
    assert raw.absolute_limit_m > 1.25 * truth.absolute_limit_m
    assert np.all(raw.depth_limit_m >= truth.depth_limit_m * (1 - 1e-9))


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_with_noise_the_correction_lands_on_the_structures_damping(seed):
    """Noise of 1 % of each line's value (a tap test's, near its peaks): the fitted damping scatters, the
    correction removes the same 1/tau from it; the structure's damping within 3 %, the data's 20 to 40 % above."""
    hz = np.linspace(200.0, 3000.0, 1401)
    s = 2j * np.pi * hz
    tau = 0.03
    rng = np.random.default_rng(seed)
    h = closed_form(s + 1.0 / tau)
    noisy = h * (1 + 0.01 * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size)) / np.sqrt(2))
    fixed = window_removed(_frf(hz, noisy), tau)
    x = sorted((m for m in fixed.modes.modes if m.direction == "x"), key=lambda m: m.frequency_hz)
    measured = sorted((m for m in fixed.measured.modes if m.direction == "x"), key=lambda m: m.frequency_hz)
    for m, w, (_, zeta, k) in zip(x, measured, MODES):
        assert m.damping_ratio == pytest.approx(zeta, rel=0.03)
        assert m.stiffness_n_per_m == pytest.approx(k, rel=0.03)
        assert w.damping_ratio > 1.1 * zeta
    truth = zoa(xy_frf(_frf(hz, closed_form(s))), CUT, SPEEDS)
    assert zoa(fixed.frf, CUT, SPEEDS).absolute_limit_m == pytest.approx(truth.absolute_limit_m, rel=0.03)


def test_a_window_per_direction_leaves_the_other_as_measured():
    hz = np.linspace(200.0, 3000.0, 1401)
    s = 2j * np.pi * hz
    tau = 0.02
    plain = closed_form(s, [("1100 Hz", 0.025, 3e7)])
    fixed = window_removed(xy_frf(_frf(hz, closed_form(s + 1.0 / tau)), _frf(hz, plain)), {"x": tau, "y": None})
    assert np.array_equal(fixed.frf.data[:, 1, 1], plain)
    assert np.max(np.abs(fixed.frf.data[:, 0, 0] - closed_form(s))) < 1e-9 * np.max(np.abs(closed_form(s)))
    assert {m.direction for m in fixed.modes.modes} == {"x"} and fixed.tau == {"x": tau, "y": None}


def test_a_mode_the_window_damps_more_than_itself_is_refused_and_bad_taus_too():
    mode = Mode("x", "900 Hz", 0.004, "2e7 N/m")
    # 1/(tau omega) at 900 Hz is 0.00589 for tau = 0.03 s: the fitted 0.4 % is less than the window alone gives
    with pytest.raises(InvalidValueError, match="not above the window's 1/\\(tau omega\\) = 0.00589"):
        mode_without_window(mode, 0.03)
    assert mode_without_window(mode, 0.1).damping_ratio == pytest.approx(0.004 - 1 / (0.1 * 2 * np.pi * 900), rel=1e-3)
    for tau in (0, -1.0, float("nan"), float("inf"), "abc", None):
        with pytest.raises(InvalidValueError, match="expected the exponential window's time constant"):
            mode_without_window(mode, tau)
    hz = np.linspace(200.0, 3000.0, 101)
    with pytest.raises(InvalidValueError, match="directions"):
        window_removed(_frf(hz, closed_form(2j * np.pi * hz)), {"z": 0.1})
    with pytest.raises(InvalidValueError, match="nothing to take out"):
        window_removed(_frf(hz, closed_form(2j * np.pi * hz)), {"x": None})
    with pytest.raises(InvalidValueError, match="expected the measured FRF"):
        window_removed(ModalModel([mode]), 0.1)


# -- the file's window line ----------------------------------------------------------------------------------------

def _written(tmp_path, name="frf.csv", **kw):
    hz = np.linspace(200.0, 3000.0, 101)
    frf = _frf(hz, closed_form(2j * np.pi * hz + 1 / 0.03))
    path = tmp_path / name
    write_csv(frf, path, coherence=np.full(hz.size, 0.99), force_noise=np.full(hz.size, 1e-6),
              truncation=np.full(hz.size, 1e-7), **kw)
    return path, frf


def test_the_window_travels_with_the_file_and_reading_it_as_it_is_warns(tmp_path):
    path, frf = _written(tmp_path, window_tau=0.03)
    assert path.read_text().startswith("# window_tau_s = 0.03\n")
    assert read_csv_window(path) == 0.03
    with pytest.warns(WindowedFRFWarning, match="tau = 0.03 s"):
        back = read_csv(path)
    assert np.array_equal(back.data, frf.data)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got, coherence = read_csv_with_coherence(path)  # the measurement set's path: it handles the window
    assert np.array_equal(got.data, frf.data) and np.all(coherence == 0.99)
    plain, _ = _written(tmp_path, "plain.csv")
    assert read_csv_window(plain) is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_csv(plain)
    with pytest.raises(InvalidValueError, match="window_tau"):
        _written(tmp_path, "bad.csv", window_tau=-0.1)


@pytest.mark.parametrize("line, message", [
    ("# window_tau_s = -1", "line 1: .*expected '# window_tau_s = SECONDS'"),
    ("# window_tau_s = nan", "line 1: .*a number > 0"),
    ("# window_tau_s = 0.01 s", "line 1: .*a number > 0"),
    ("# window_tau_s", "line 1"),
    ("# window_tau_s = 0.01\n# window_tau_s = 0.02", "line 2: window_tau_s is given again \\(first on line 1\\)"),
])
def test_a_window_line_that_is_not_one_is_refused_naming_the_line(tmp_path, line, message):
    path, _ = _written(tmp_path)
    path.write_text(line + "\n" + path.read_text())
    with pytest.raises(FileFormatError, match=message):
        read_csv_window(path)
    with pytest.raises(FileFormatError, match=message):
        read_csv(path)


def test_other_comment_lines_and_an_export_with_the_window_line(tmp_path):
    path, frf = _written(tmp_path)
    path.write_text("# from the shop floor\n# window_tau_s = 0.05\n#\n" + path.read_text())
    assert read_csv_window(path) == 0.05
    with pytest.warns(WindowedFRFWarning):
        assert np.array_equal(read_csv(path).data, frf.data)
    export = tmp_path / "export.csv"
    export.write_text("# window_tau_s = 0.04\nFrequency [Hz];Real [m/N];Imag [m/N]\n100;1,0e-7;-2,0e-8\n"
                      "110;1,1e-7;-2,5e-8\n")
    assert read_csv_window(export) == 0.04


def test_a_measurement_set_takes_the_files_window_and_refuses_another(tmp_path):
    _written(tmp_path, window_tau=0.03)
    body = ('name = "w"\n[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "frf.csv"\n'
            'force_window_s = 0.002\n')
    (tmp_path / "set.toml").write_text(body)
    assert MeasurementSet.from_file(tmp_path / "set.toml").measurements[0].window_tau == 0.03
    (tmp_path / "same.toml").write_text(body + "window_tau_s = 0.03\n")
    assert MeasurementSet.from_file(tmp_path / "same.toml").measurements[0].window_tau == 0.03
    (tmp_path / "other.toml").write_text(body + "window_tau_s = 0.05\n")
    with pytest.raises(FileFormatError, match="window_tau_s.*frf.csv says it was measured through a window of 0.03 s"):
        MeasurementSet.from_file(tmp_path / "other.toml")


# -- through the commands --------------------------------------------------------------------------------------------

FS = 10240.0
FN, ZETA, K = 400.0, 0.01, 2.0e6


def _tap_files(tmp_path, seconds=0.2):
    """Taps of a 1-DOF tool point simulated by lsim (a half-sine hammer pulse), written as tap records."""
    wn = 2 * np.pi * FN
    m = K / wn**2
    t = np.arange(int(seconds * FS)) / FS
    paths = []
    for n, peak in enumerate((40.0, 55.0, 70.0)):
        f = np.where((t >= 0.01) & (t <= 0.0106), peak * np.sin(np.pi * (t - 0.01) / 0.0006), 0.0).clip(0.0)
        _, x, _ = signal.lsim(([[0.0, 1.0], [-wn**2, -2 * ZETA * wn]], [[0.0], [1.0 / m]], [[1.0, 0.0]], [[0.0]]),
                              f, t)
        path = tmp_path / f"tap{n}.csv"
        rows = "\n".join(",".join(repr(float(v)) for v in row) for row in np.column_stack([t, f, x]))
        path.write_text("time [s],force [N],displacement [m]\n" + rows + "\n")
        paths.append(path)
    return paths


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


LOBES = ["--teeth", "2", "--diameter", "10 mm", "--immersion", "1", "--milling", "down", "--kt", "6e8 Pa",
         "--kn", "2e8 Pa", "--speeds", "3000:30000:50"]


def test_taps_through_the_window_give_the_structures_lobes_through_the_commands(capsys, tmp_path):
    taps = _tap_files(tmp_path)
    code, out, err = run(capsys, "tap", *taps, "--exponential-window", "--out", tmp_path / "frf.csv")
    assert code == 0, err
    tau = read_csv_window(tmp_path / "frf.csv")
    assert tau == pytest.approx(0.19 / np.log(100), rel=0.05)
    # the structure's lobes on the file's lines (zero-order lobes from 5 Hz lines differ from those of the modes
    # on a fine grid by 14 %: the lines, not the window)
    lines = read_csv_with_coherence(tmp_path / "frf.csv")[0].frequency
    structure = ModalModel([Mode("x", f"{FN} Hz", ZETA, f"{K} N/m"), Mode("y", f"{FN} Hz", ZETA, f"{K} N/m")])
    truth = zoa(structure.xy_frf(lines), CUT, SPEEDS).to_json()
    code, out, err = run(capsys, "lobes", "--frf", tmp_path / "frf.csv", *LOBES, "--json")
    assert code == 0, err
    got = json.loads(out)
    window = got["window"]
    assert window["tau_s"] == {"x": tau, "y": tau}
    x = [m for m in window["modes"] if m["direction"] == "x"]
    assert len(x) == 1 and x[0]["frequency_hz"] == pytest.approx(FN, rel=2e-3)
    assert x[0]["damping_ratio"] == pytest.approx(ZETA, rel=0.03)
    assert x[0]["damping_ratio_measured"] == pytest.approx(ZETA + 1 / (tau * 2 * np.pi * FN), rel=0.03)
    assert got["absolute_limit_m"] == pytest.approx(truth["absolute_limit_m"], rel=0.02)
    np.testing.assert_allclose(got["depth_limit_m"], truth["depth_limit_m"], rtol=0.02)
    # read as it is, the same file promises 2.3 times the depth (0.99 % of the window on a 1 % mode)
    with pytest.warns(WindowedFRFWarning):
        raw = zoa(xy_frf(FRF.from_csv(tmp_path / "frf.csv")), CUT, SPEEDS)
    assert raw.absolute_limit_m > 2 * truth["absolute_limit_m"]
    code, out, err = run(capsys, "lobes", "--frf", tmp_path / "frf.csv", *LOBES)
    assert code == 0 and "exponential window: tau x" in out and "without the window's" in out
    code, out, err = run(capsys, "lobes", "--frf", tmp_path / "frf.csv", *LOBES, "--method", "sdm", "--speeds",
                         "3000:30000:3000")
    assert code == 0 and "exponential window" in out, err


def test_the_window_option_for_files_that_do_not_say_and_its_errors(capsys, tmp_path):
    taps = _tap_files(tmp_path)
    run(capsys, "tap", *taps, "--exponential-window", "--out", tmp_path / "frf.csv")
    tau = read_csv_window(tmp_path / "frf.csv")
    lines = (tmp_path / "frf.csv").read_text().splitlines()
    (tmp_path / "bare.csv").write_text("\n".join(line for line in lines if not line.startswith("#")) + "\n")
    code, out, _ = run(capsys, "lobes", "--frf", tmp_path / "frf.csv", *LOBES, "--json")
    said = json.loads(out)
    code, out, _ = run(capsys, "lobes", "--frf", tmp_path / "bare.csv", *LOBES, "--json", "--window-tau", repr(tau))
    assert code == 0 and json.loads(out)["depth_limit_m"] == said["depth_limit_m"]
    code, out, _ = run(capsys, "lobes", "--frf", tmp_path / "bare.csv", *LOBES, "--json")
    assert json.loads(out)["window"] is None
    for argv, message in [
        (["--frf", tmp_path / "frf.csv", "--window-tau", "0.5"], "says it was measured through a window of"),
        (["--frf", tmp_path / "bare.csv", "--window-tau", "0"],
         "argument --window-tau: got 0.0; expected a finite number > 0"),
        (["--frf", tmp_path / "bare.csv", "--window-tau", "nan"], "got nan; expected a finite number > 0"),
        (["--modes", tmp_path / "none.csv", "--window-tau", "0.1"], "--window-tau is for measured FRFs"),
    ]:
        code, out, err = run(capsys, "lobes", *argv, *LOBES)
        assert code == 2 and message in err, err


def test_a_window_that_explains_all_of_a_modes_damping_is_refused_by_the_command(capsys, tmp_path):
    """A 0.3 % mode at 650 Hz in a file that says tau = 0.02 s (the window alone adds 1.2 %): no lobes."""
    hz = np.linspace(100.0, 2000.0, 381)
    path = tmp_path / "frf.csv"
    write_csv(_frf(hz, closed_form(2j * np.pi * hz, [("650 Hz", 0.003, 3e6)])), path, window_tau=0.02)
    code, out, err = run(capsys, "lobes", "--frf", path, *LOBES)
    assert code != 0 and out == ""
    assert "the mode at 650" in err and "the record shows the window's damping, not the structure's" in err


def test_a_minor_mode_the_window_cannot_be_taken_out_of_is_left_as_measured_and_named():
    """The tool mode through the window, and a small mode of 0.1 % damping that was not (as a feature of the data
    the window's tau does not describe): its peak is 8.3 % of the largest; the tool mode is corrected as before."""
    hz = np.linspace(200.0, 3000.0, 1401)
    s = 2j * np.pi * hz
    tau = 0.03
    small = [("1300 Hz", 0.001, 8e9)]
    data = closed_form(s + 1.0 / tau, MODES[:1]) + closed_form(s, small)
    with pytest.warns(ModalFitWarning, match="1300 Hz \\(x\\) is left as measured, its peak 8.*% of the largest"):
        fixed = window_removed(_frf(hz, data), tau)
    assert [(round(m.frequency_hz), m.direction) for m, _ in fixed.uncorrected] == [(1300, "x"), (1300, "y")]
    assert "not above the window's" in fixed.uncorrected[0][1]
    (mode,) = [m for m in fixed.modes.modes if m.direction == "x"]
    assert mode.damping_ratio == pytest.approx(0.02, rel=1e-3) and mode.frequency_hz == pytest.approx(900, rel=1e-4)
    assert any("1300 Hz: left as measured" in line for line in fixed.describe())
    # the same small mode as large as the tool mode's peak: refused
    with pytest.raises(InvalidValueError, match="1300 Hz.*its peak is .*% of the largest"):
        window_removed(_frf(hz, closed_form(s + 1.0 / tau, MODES[:1]) + closed_form(s, [("1300 Hz", 0.001, 5e8)])),
                       tau)


# -- real taps -------------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def real():
    """The shipped real impact records (1 s each): the modes fitted to their whole records (no window: the response
    has died out), and the records cut short and processed through the window."""
    import attrs

    from substructure.datasets import impact_records
    from substructure.stability import ModalFitter
    from substructure.tap import process_taps

    records = impact_records()
    whole = ModalFitter().fit(process_taps(records, exponential=False).frf.crop(700.0, 1000.0))
    cut = {}
    for seconds in (0.5, 0.25):
        n = int(seconds / (records[0].time[1] - records[0].time[0]))
        cut[seconds] = process_taps([attrs.evolve(r, time=r.time[:n], force=r.force[:n], response=r.response[:n])
                                     for r in records], exponential=True)
    return whole, cut


@pytest.mark.parametrize("seconds", [0.5, 0.25])
def test_real_taps_cut_short_give_the_whole_records_damping_once_the_window_is_out(real, seconds):
    """Three modes at 810, 851 and 900 Hz of about 0.12 % damping: through the window of the records cut to 0.5
    and 0.25 s (tau 0.11 and 0.054 s, adding 0.18 to 0.36 %), the fitted damping is 2 to 4 times the whole
    record's; without the window's, within 35 %."""
    whole, cut = real
    fixed = window_removed(cut[seconds].frf.crop(700.0, 1000.0), cut[seconds].tau)
    got = sorted((m for m in fixed.modes.modes if m.direction == "x"), key=lambda m: m.frequency_hz)
    seen = sorted((m for m in fixed.measured.modes if m.direction == "x"), key=lambda m: m.frequency_hz)
    assert len(got) == len(whole.modes_) == 3 and not fixed.uncorrected
    for m, w, ref in zip(got, seen, whole.modes_):
        assert m.frequency_hz == pytest.approx(ref.frequency_hz, rel=1e-3)
        assert m.damping_ratio == pytest.approx(ref.damping_ratio, rel=0.35)
        assert w.damping_ratio > 2 * ref.damping_ratio


def test_semi_discretization_with_one_direction_windowed_keeps_the_other_directions_modes(capsys, tmp_path):
    """x tapped through the window, y without: both directions' modes reach the semi-discretization."""
    hz = np.linspace(100.0, 3000.0, 581)
    s = 2j * np.pi * hz
    write_csv(_frf(hz, closed_form(s + 1 / 0.03, MODES[:1])), tmp_path / "x.csv", window_tau=0.03)
    write_csv(_frf(hz, closed_form(s, [("1200 Hz", 0.03, 3e7)])), tmp_path / "y.csv")
    code, out, err = run(capsys, "lobes", "--frf", tmp_path / "x.csv", "--frf-y", tmp_path / "y.csv", *LOBES[:-2],
                         "--speeds", "20000:30000:2000", "--method", "sdm", "--json")
    assert code == 0, err
    got = json.loads(out)
    assert got["window"]["tau_s"] == {"x": 0.03, "y": None}
    fit = next(n for n in got["notes"] if n.startswith("modal fit"))
    assert "x: 900" in fit and "y: 1200" in fit and "zeta 0.02," in fit, fit
