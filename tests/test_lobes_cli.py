"""`substructure lobes`: structure from an assembly, FRF files or modes; JSON; plot; clear errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import attrs
import numpy as np
import pytest

from substructure import FRF, Frequency, default_assembly
from substructure.cli import main
from substructure.stability import MillingCut, ModalModel, Mode, spindle_speeds, xy_frf, zoa
from substructure.units import Q_

ASSEMBLY = Path(__file__).parent.parent / "substructure" / "data" / "default_assembly.toml"
THESIS_CUT = ["--teeth", "4", "--diameter", "12 mm", "--radial-depth", "3 mm", "--milling", "up",
              "--kt", "625 MPa", "--kn", "100 MPa"]
BENCH_CUT = ["--teeth", "2", "--diameter", "10 mm", "--immersion", "1", "--milling", "down",
             "--kt", "6e8 Pa", "--kn", "2e8 Pa"]
KEYS = {"method", "spindle_speed_rpm", "depth_limit_m", "chatter_frequency_hz"}


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return status, out, err


@pytest.fixture
def frf_files(tmp_path):
    grid = Frequency.from_range("500 Hz", "5000 Hz", "2 Hz")
    assembly = default_assembly()
    x = assembly.receptance("tool.tip:y", frequency=grid)
    y = 1.1 * x  # a more flexible y direction: anything different from x
    px, py = tmp_path / "x.csv", tmp_path / "y.csv"
    x.to_csv(px)
    y.to_csv(py)
    return px, py, x, y


@pytest.fixture
def modes_file(tmp_path):
    k = 0.03993 * (2 * np.pi * 922) ** 2
    path = tmp_path / "modes.csv"
    ModalModel([Mode("x", "922 Hz", 0.011, Q_(k, "N/m"))]).to_csv(path)
    return path


def test_frf_files_zoa_json_matches_the_library(capsys, frf_files):
    px, py, x, y = frf_files
    status, out, err = run(capsys, "lobes", "--frf", px, "--frf-y", py, *THESIS_CUT, "--speeds", "4000:20000:100",
                           "--json")
    assert status == 0 and err == ""
    result = json.loads(out)
    assert KEYS | {"absolute_limit_m"} <= set(result)
    assert result["method"] == "zoa"
    expected = zoa(xy_frf(FRF.from_csv(px), FRF.from_csv(py)),
                   MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa"), spindle_speeds("4000 rpm", "20000 rpm",
                                                                                              "100 rpm"))
    np.testing.assert_allclose(result["spindle_speed_rpm"], np.arange(4000, 20001, 100))
    np.testing.assert_allclose(result["depth_limit_m"], expected.depth_limit_m, rtol=1e-12)
    assert result["absolute_limit_m"] == pytest.approx(expected.absolute_limit_m)
    # depth limit = the lowest lobe at each speed
    assert min(result["depth_limit_m"]) >= result["absolute_limit_m"] * (1 - 1e-9)


def test_one_frf_file_is_a_symmetric_tool(capsys, frf_files):
    px, _, x, _ = frf_files
    _, out, _ = run(capsys, "lobes", "--frf", px, *THESIS_CUT, "--speeds", "4000:20000:100", "--json")
    _, out2, _ = run(capsys, "lobes", "--frf", px, "--frf-y", px, *THESIS_CUT, "--speeds", "4000:20000:100", "--json")
    assert json.loads(out)["depth_limit_m"] == json.loads(out2)["depth_limit_m"]


def test_modes_file_with_sdm_reports_its_discretisation(capsys, modes_file):
    status, out, err = run(capsys, "lobes", "--modes", modes_file, *BENCH_CUT, "--method", "sdm",
                           "--speeds", "10000:16000:1000", "--json")
    assert status == 0, err
    result = json.loads(out)
    assert KEYS <= set(result) and result["method"] == "sdm"
    assert result["discretisation"]["intervals_in_cut"][0] >= 20
    assert len(result["depth_limit_m"]) == 7
    assert all(2e-4 < a < 5e-3 for a in result["depth_limit_m"])


def test_semi_discretization_says_its_steps_on_stderr_unless_quiet(capsys, modes_file):
    """A run takes minutes at low speeds: each step of the search, then the recommendation's new runs, is a line on
    standard error; the JSON on standard output is the same with --quiet, which prints none."""
    argv = ["lobes", "--modes", modes_file, *BENCH_CUT, "--method", "sdm", "--speeds", "10000:16000:1000", "--json"]
    status, out, err = run(capsys, *argv)
    assert status == 0, err
    lines = err.splitlines()
    assert lines and all(line.startswith("substructure: ") for line in lines)
    assert any("coarse scan of the depths, step 1: 7 of 7 speeds" in line for line in lines)
    assert any("narrowing the limits to 0.5%" in line for line in lines)
    new_runs = [line for line in lines if "semi-discretization: a new run on " in line]
    recommended = json.loads(out)["recommended"]
    assert recommended is not None and new_runs  # each of the recommendation's new runs is a line
    status, quiet, err = run(capsys, *argv, "--quiet")
    assert status == 0 and err == "" and json.loads(quiet) == json.loads(out)


def test_assembly_and_point_with_band_and_plot(capsys, tmp_path):
    png = tmp_path / "lobes.png"
    status, out, err = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", "--band", "500:5000",
                           *THESIS_CUT, "--speeds", "3000:24000:30", "--plot", png)
    assert status == 0 and err == ""
    assert png.stat().st_size > 10_000
    assert "absolute limit" in out and "best speeds" in out and f"wrote {png}" in out
    assert "y = x" in out


def test_free_free_assembly_leaves_out_the_rigid_body_lines_and_says_so(capsys):
    status, out, err = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", *THESIS_CUT, "--json")
    assert status == 0 and err == ""
    result = json.loads(out)
    band = result["structure_band"]
    assert band["kind"] == "free-free" and 150 < band["lo_hz"] < 250 and band["excluded_hz"][0] == 20
    chatter = [f for f in result["chatter_frequency_hz"] if f is not None]
    assert min(chatter) >= band["lo_hz"]
    assert result["recommended"]["chatter_frequency_hz"] >= band["lo_hz"]
    # the same limit as cropping by hand above the antiresonance
    _, out2, _ = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", *THESIS_CUT, "--json",
                     "--band", f"{band['lo_hz']}:5000")
    assert json.loads(out2)["absolute_limit_m"] == pytest.approx(result["absolute_limit_m"])
    _, human, _ = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", *THESIS_CUT)
    assert "rigid-body mass line" in human and "left out" in human
    # --band all keeps the old behaviour: a limit at the first line, with the warning
    status, out3, err3 = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", *THESIS_CUT, "--json",
                             "--band", "all")
    assert status == 0 and "warning" in err3 and "first line" in err3
    assert json.loads(out3)["absolute_limit_m"] < 0.5 * result["absolute_limit_m"]


def test_sdm_from_frf_data_fits_modes(capsys, frf_files):
    px = frf_files[0]
    status, out, _ = run(capsys, "lobes", "--frf", px, *THESIS_CUT, "--method", "sdm", "--speeds",
                         "12000:14000:1000")
    assert status == 0
    assert "modal fit" in out and "discretisation" in out


def test_turning(capsys, modes_file):
    status, out, _ = run(capsys, "lobes", "--modes", modes_file, "--turning", "--kf", "2000 MPa",
                         "--orientation", "0.7", "--speeds", "2000:4000:10", "--json")
    assert status == 0
    k = 0.03993 * (2 * np.pi * 922) ** 2
    assert json.loads(out)["absolute_limit_m"] == pytest.approx(2 * k * 0.011 * 1.011 / (2e9 * 0.7), rel=1e-6)


@pytest.mark.parametrize("argv, status, message", [
    (["--radial-depth", "13 mm"], 1, "larger than the tool diameter"),
    (["--teeth", "0"], 1, "teeth"),
    (["--kt", "-625 MPa"], 1, "kt"),
    (["--kn", "-1 MPa"], 1, "kn"),
    (["--speeds", "50 Hz:300 Hz:1 Hz"], 2, "rpm"),
    (["--speeds", "1000:2000:50:5"], 2, "START:STOP:STEP"),  # START:STOP alone has a default step
    (["--diameter", "12"], 1, "diameter"),
    (["--kr", "100 MPa"], 2, "--kr: got '100 MPa'; expected the ratio Kn/Kt, a plain number such as 0.3 (a "
                              "pressure such as '100 MPa' is the normal coefficient itself: give it with --kn)"),
])
def test_bad_cut_or_speeds_are_clear_errors(capsys, frf_files, argv, status, message):
    args = dict(zip(THESIS_CUT[::2], THESIS_CUT[1::2]))
    for key, value in zip(argv[::2], argv[1::2]):
        args[key] = value
    cut = [x for pair in args.items() for x in pair]
    code, out, err = run(capsys, "lobes", "--frf", frf_files[0], *cut)
    assert code == status and out == ""
    assert err.startswith("substructure: error:") and message in err


@pytest.mark.parametrize("argv, message", [
    ([], "--assembly"),
    (["--frf", "X", "--modes", "Y"], "one of"),
    (["--assembly", str(ASSEMBLY)], "--at"),
    (["--frf-y", "y.csv", "--modes", "m.csv"], "--frf-y goes with --frf"),
])
def test_structure_must_be_given_once(capsys, argv, message):
    code, out, err = run(capsys, "lobes", *argv, *THESIS_CUT)
    assert code == 2 and out == "" and message in err


def test_missing_cut_options_and_bad_files(capsys, frf_files, tmp_path):
    code, _, err = run(capsys, "lobes", "--frf", frf_files[0], "--teeth", "4")
    assert code == 2 and "--diameter" in err and "--kt" in err
    code, _, err = run(capsys, "lobes", "--frf", tmp_path / "missing.csv", *THESIS_CUT)
    assert code == 1 and "missing.csv" in err
    code, _, err = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip:theta", *THESIS_CUT)
    assert code == 1 and "translational" in err
    code, _, err = run(capsys, "lobes", "--frf", frf_files[0], *THESIS_CUT, "--turning", "--kf", "1 GPa")
    assert code == 2 and "milling cut" in err


def test_the_installed_command_prints_one_json_object(frf_files):
    done = subprocess.run([sys.executable, "-m", "substructure", "lobes", "--frf", str(frf_files[0]), *THESIS_CUT,
                           "--speeds", "5000:6000:500", "--json"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert set(json.loads(done.stdout)) >= KEYS


# -- the machinist's recommendation (issue 11) ------------------------------------------------------

REC_KEYS = {"spindle_speed_rpm", "depth_m", "limit_depth_m", "margin", "mrr_m3_per_s", "chatter_frequency_hz"}
NO_TEETH_CUT = ["--radial-depth", "3 mm", "--milling", "up", "--kt", "625 MPa", "--kn", "100 MPa"]


def test_the_recommendation_in_json_and_in_mm_and_rpm(capsys):
    argv = ["lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", *THESIS_CUT, "--feed-per-tooth", "0.05 mm",
            "--max-speed", "20000", "--power", "5 kW", "--margin", "0.25", "--speed-tolerance", "0.04"]
    status, out, err = run(capsys, *argv, "--json")
    assert status == 0 and err == ""
    result = json.loads(out)
    rec = result["recommended"]
    assert REC_KEYS <= set(rec) and rec["margin"] == 0.25 and rec["speed_tolerance"] == 0.04
    assert rec["spindle_speed_rpm"] <= 20000 and rec["depth_m"] == pytest.approx(0.75 * rec["limit_depth_m"])
    assert rec["mrr_m3_per_s"] == pytest.approx(rec["depth_m"] * 3e-3 * 4 * 0.05e-3 * rec["spindle_speed_rpm"] / 60)
    assert rec["power_w"] == pytest.approx(625e6 * rec["mrr_m3_per_s"], rel=1e-9)  # Kt * MRR, no edge force
    assert result["machine"]["power_w"] == 5000 and len(rec["runners_up"]) == 2
    status, human, _ = run(capsys, *argv)
    line = next(t for t in human.splitlines() if t.startswith("recommended:"))
    assert f"{rec['spindle_speed_rpm']:.0f} rpm" in line and f"{rec['depth_m'] * 1e3:.3g} mm" in line
    assert "margin 25%" in human and "runner-up 1" in human and "cm^3/min" in human


def test_the_tooth_count_and_diameter_flow_from_the_assembly_file(capsys, tmp_path):
    from substructure.io.assembly_toml import load_assembly, save_assembly

    assembly = load_assembly(ASSEMBLY)
    tool = assembly.component("tool")
    three = tmp_path / "three.toml"
    save_assembly(assembly.with_component(attrs.evolve(tool, teeth=3, helix="35 deg")), three)
    assert load_assembly(three).component("tool").teeth == 3
    _, out, _ = run(capsys, "lobes", "--assembly", three, "--at", "tool.tip", *NO_TEETH_CUT, "--json")
    from_file = json.loads(out)
    assert from_file["cut"]["teeth"] == 3 and from_file["cut"]["diameter_m"] == pytest.approx(0.012)
    assert any("3 from the tool" in n for n in from_file["notes"])
    _, out, _ = run(capsys, "lobes", "--assembly", three, "--at", "tool.tip", *NO_TEETH_CUT, "--teeth", "3",
                    "--diameter", "12 mm", "--json")
    assert json.loads(out)["depth_limit_m"] == from_file["depth_limit_m"]
    _, out, _ = run(capsys, "lobes", "--assembly", three, "--at", "tool.tip", *NO_TEETH_CUT, "--teeth", "2", "--json")
    overridden = json.loads(out)
    assert overridden["cut"]["teeth"] == 2 and any("overrides" in n for n in overridden["notes"])
    # the built-in assembly carries the thesis's 4 teeth; without teeth anywhere it is asked for
    _, out, _ = run(capsys, "lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", *NO_TEETH_CUT, "--json")
    assert json.loads(out)["cut"]["teeth"] == 4
    bare = tmp_path / "bare.toml"
    save_assembly(assembly.with_component(attrs.evolve(tool, teeth=None)), bare)
    code, _, err = run(capsys, "lobes", "--assembly", bare, "--at", "tool.tip", *NO_TEETH_CUT)
    assert code == 2 and "--teeth" in err


def test_workpiece_by_name_and_from_a_user_table(capsys, tmp_path):
    base = ["lobes", "--assembly", ASSEMBLY, "--at", "tool.tip", "--radial-depth", "3 mm", "--json"]
    _, out, _ = run(capsys, *base, "--workpiece", "aluminium-7075")
    result = json.loads(out)
    assert result["cut"]["kt_pa"] == pytest.approx(767.01e6) and result["cut"]["kn_pa"] == pytest.approx(168.8e6)
    assert "doi" in result["workpiece"]["source"]
    code, _, err = run(capsys, *base, "--workpiece", "steel-1045", "--feed-per-tooth", "0.1 mm")
    assert code == 1 and "radial" in err and "kr" in err
    code, out, _ = run(capsys, *base, "--workpiece", "steel-1045", "--feed-per-tooth", "0.1 mm", "--kr", "0.3")
    assert code == 0 and json.loads(out)["workpiece"]["model"] == "kienzle"
    table = tmp_path / "mine.toml"
    table.write_text('[[workpiece]]\nname = "shop-7075"\nmodel = "linear"\nkt = "700 MPa"\nkr = "200 MPa"\n'
                     'source = "our calibration cuts, 2025"\n', encoding="utf-8")
    _, out, _ = run(capsys, *base, "--workpiece", "shop-7075", "--workpiece-table", table)
    assert json.loads(out)["cut"]["kt_pa"] == pytest.approx(700e6)
    code, _, err = run(capsys, *base, "--workpiece", "unobtainium")
    assert code == 1 and "known" in err and "aluminium-7075" in err
    code, _, err = run(capsys, *base, "--workpiece", "aluminium-7075", "--kt", "600 MPa")
    assert code == 2 and "not both" in err


@pytest.mark.parametrize("speeds, message", [
    ("-2000:24000:50", "positive"),
    ("2000:-24000:50", "positive"),
    ("2000:24000:1e-4", "MAX_SPEEDS"),
])
def test_bad_speed_grids_get_a_clear_message(capsys, frf_files, speeds, message):
    code, out, err = run(capsys, "lobes", "--frf", frf_files[0], *THESIS_CUT, "--speeds", speeds)
    assert code == 2 and out == "" and message in err and "expected one argument" not in err


def test_too_many_intervals_is_refused_by_name(capsys, modes_file):
    code, _, err = run(capsys, "lobes", "--modes", modes_file, *BENCH_CUT, "--method", "sdm", "--intervals", "100000",
                       "--speeds", "10000:11000:500")
    assert code == 1 and "MAX_INTERVALS" in err


def test_the_summary_says_the_order_of_the_eigenvalue_problems_and_how_they_were_solved(capsys, modes_file):
    argv = ["lobes", "--modes", modes_file, *BENCH_CUT, "--method", "sdm", "--speeds", "12000:12500:500", "--quiet"]
    status, out, err = run(capsys, *argv)
    assert status == 0, err
    line = next(x for x in out.splitlines() if x.startswith("discretisation: "))
    assert "(monodromy matrices of order " in line and "Arnoldi" not in line
    status, out, err = run(capsys, *argv, "--intervals", "450")
    assert status == 0, err
    line = next(x for x in out.splitlines() if x.startswith("discretisation: "))
    assert line.startswith("discretisation: 450 intervals in the cut per delay period (monodromy matrices of order "
                           "452, the largest multipliers by Arnoldi iterations from order 400)")


def test_a_fixed_interval_count_too_coarse_for_the_modes_is_refused_naming_the_least(capsys, modes_file):
    argv = ["lobes", "--modes", modes_file, *BENCH_CUT, "--method", "sdm", "--speeds", "15000:16000:500", "--quiet"]
    phase = 2 * np.pi * 922 * 60.0 / (2 * 15000)  # the slot: the tooth cuts through the whole delay period
    for count in ("1", "2", "25"):
        code, out, err = run(capsys, *argv, "--intervals", count)
        assert code == 1 and out == ""
        assert f"--intervals: got {count}; at 15000 rpm one interval spans a phase step of " \
               f"{phase / int(count):.3g} rad" in err and "at least 26 intervals" in err
    code, out, err = run(capsys, *argv, "--intervals", "26")
    assert code == 0, err
    assert "discretisation: 26 intervals in the cut" in out


def test_a_driving_point_frf_with_the_wrong_sign_of_its_imaginary_part_is_refused(capsys, frf_files, tmp_path):
    x = frf_files[2]
    rng = np.random.default_rng(7)
    h = x.data[:, 0, 0]
    noisy = h + 0.05 * np.abs(h) * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size))
    flipped = np.imag(noisy) > 0
    assert flipped.any()  # measured noise flips a few lines near the antiresonances: accepted
    cases = {"noisy": (noisy, None), "negated": (-h, "100% of the lines"), "conjugated": (np.conj(h), "100%")}
    for name, (data, refused) in cases.items():
        path = tmp_path / f"{name}.csv"
        FRF.single(x.frequency, data, output="tool.tip:y", input="tool.tip:y").to_csv(path)
        code, out, err = run(capsys, "lobes", "--frf", path, *THESIS_CUT, "--speeds", "5000:6000:500")
        if refused is None:
            assert code == 0, err
        else:
            assert code == 1 and out == ""
            assert f"{path}: Im(H) > 0 on {refused}" in err and "sign" in err and "conjugate" in err
    code, _, err = run(capsys, "lobes", "--frf", frf_files[0], "--frf-y", tmp_path / "negated.csv", *THESIS_CUT)
    assert code == 1 and "negated.csv: Im(H) > 0" in err


def test_a_band_that_misses_the_resonance_is_said(capsys, modes_file, tmp_path):
    f = np.arange(10.0, 2000.0, 0.5)
    k = 0.03993 * (2 * np.pi * 922) ** 2
    h = 1.0 / (k * (1 - (f / 922) ** 2 + 2j * 0.011 * f / 922))
    path = tmp_path / "one.csv"
    FRF.single(Frequency(f), h, output="t:y", input="t:y").to_csv(path)
    argv = ["lobes", "--frf", path, *BENCH_CUT, "--speeds", "15000:16000:500"]
    for method in ("zoa", "sdm"):
        code, out, err = run(capsys, *argv, "--band", "10:300", "--method", method, "--quiet")
        assert code == 1 and out == "" and "never negative from 10 to 300 Hz: the band holds no resonance" in err
    code, out, err = run(capsys, *argv, "--band", "1000:1001")
    assert code == 0 and "first line of the band (1000 Hz)" in err
    assert "\nwarning: zoa: the oriented FRF's most negative real part, the absolute limit, is at the first line" in out
    code, out, _ = run(capsys, *argv, "--band", "1000:1001", "--json")
    assert any(n.startswith("warning: zoa:") and "1000 Hz" in n for n in json.loads(out)["notes"])


def test_options_that_would_be_unused_are_refused(capsys, modes_file, tmp_path):
    turning = ["lobes", "--modes", modes_file, "--turning", "--kf", "2000 MPa", "--speeds", "15000:16000:500"]
    for extra in (["--max-speed", "20000"], ["--margin", "0.3"], ["--power", "5 kW"], ["--max-depth", "2 mm"]):
        code, out, err = run(capsys, *turning, *extra)
        assert code == 2 and out == "" and f"--turning: {extra[0]} sets the machinist's recommendation" in err
    milling = ["lobes", "--modes", modes_file, *BENCH_CUT, "--speeds", "15000:16000:500"]
    for extra in (["--cutting-data", tmp_path / "missing.toml"], ["--tool-material", "hss"]):
        code, out, err = run(capsys, *milling, *extra)
        assert code == 2 and out == "" and f"{extra[0]} goes with --workpiece NAME" in err


def test_a_normal_coefficient_given_with_a_workpiece_is_said_to_override_the_table(capsys, modes_file):
    code, out, err = run(capsys, "lobes", "--modes", modes_file, "--teeth", "2", "--diameter", "12 mm",
                         "--immersion", "1", "--workpiece", "aluminium-7075", "--kr", "0.5", "--speeds",
                         "15000:16000:500")
    assert code == 0, err
    assert "workpiece: --kr 0.5 overrides the table's normal coefficient" in out
    assert "Kn = 383.5 MPa (Kn/Kt = 0.5)" in out  # 0.5 x the table's Kt of 767.01 MPa


def test_low_speed_turning_from_modes_is_within_the_cap_and_meets_the_closed_form(capsys, modes_file):
    status, out, err = run(capsys, "lobes", "--modes", modes_file, "--turning", "--kf", "2000MPa", "--speeds",
                           "500:3000:10", "--json")
    assert status == 0, err
    k = 0.03993 * (2 * np.pi * 922) ** 2
    closed = 2 * k * 0.011 * 1.011 / 2e9  # b_lim = -1 / (2 Kf min Re G)
    depth = np.array(json.loads(out)["depth_limit_m"])
    assert depth.size == 251 and depth.min() == pytest.approx(closed, rel=2e-4) and depth.min() >= closed
    status, out, err = run(capsys, "lobes", "--modes", modes_file, "--turning", "--kf", "2000MPa", "--speeds",
                           "20:3000:10")
    assert status == 1 and out == "" and "raise the lowest spindle speed to 37.59 rpm or more (--speeds" in err
    assert "crop the FRF" not in err


def test_semi_discretization_of_a_fine_frf_checks_its_band_without_building_zero_order_lobes(capsys, tmp_path):
    """136,000 lines x 21 lobes x 2 at 3000 rpm exceed MAX_LOBE_POINTS: the zero order's lobes are not needed by
    sdm, only its checks of the band; the limit meets sdm on the modes themselves."""
    k = 0.03993 * (2 * np.pi * 922) ** 2
    f = np.arange(300.0, 2000.0, 0.0125)
    h = 1.0 / (k * (1 - (f / 922) ** 2 + 2j * 0.011 * f / 922))
    path = tmp_path / "fine.csv"
    FRF.single(Frequency(f), h, output="t:y", input="t:y").to_csv(path)
    cut = ["--teeth", "2", "--diameter", "10 mm", "--immersion", "0.5", "--kt", "600 MPa", "--kn", "200 MPa"]
    status, out, err = run(capsys, "lobes", "--frf", path, *cut, "--method", "sdm", "--speeds", "3000:3100:100",
                           "--json")
    assert status == 0, err
    modes = tmp_path / "modes.csv"
    ModalModel([Mode(d, "922 Hz", 0.011, Q_(k, "N/m")) for d in "xy"]).to_csv(modes)
    _, direct, _ = run(capsys, "lobes", "--modes", modes, *cut, "--method", "sdm", "--speeds", "3000:3100:100",
                       "--json")
    np.testing.assert_allclose(json.loads(out)["depth_limit_m"], json.loads(direct)["depth_limit_m"], rtol=0.01)
    status, out, err = run(capsys, "lobes", "--frf", path, *cut, "--method", "sdm", "--speeds", "3000:3100:100",
                           "--band", "300:800")
    assert status == 1 and "never negative from 300 to 800 Hz: the band holds no resonance" in err


def test_a_recommended_depth_of_many_diameters_with_nothing_to_bound_it_is_warned_of(capsys, modes_file):
    """A radial immersion of 1e-6 leaves a limit of hundreds of metres on one mode: the recommendation follows it
    when no largest depth is given (modes do not say the flute length); the warning says so, and --max-depth
    (or a normal cut) has none."""
    cut = ["--diameter", "12 mm", "--teeth", "2", "--milling", "down", "--kt", "600 MPa", "--kn", "200 MPa",
           "--speeds", "15000:16000:100", "--json"]
    status, out, _ = run(capsys, "lobes", "--modes", modes_file, "--immersion", "1e-6", *cut)
    result = json.loads(out)
    depth = result["recommended"]["depth_m"]
    assert status == 0 and depth > 4 * 0.012
    (note,) = [n for n in result["notes"] if "times the tool's diameter" in n]
    assert f"{depth * 1e3:.4g} mm is {depth / 0.012:.3g} times" in note and "--max-depth" in note
    for extra in (["--immersion", "1e-6", "--max-depth", "30 mm"], ["--immersion", "0.5"]):
        status, out, _ = run(capsys, "lobes", "--modes", modes_file, *extra, *cut)
        assert status == 0 and not [n for n in json.loads(out)["notes"] if "times the tool's diameter" in n]


def test_an_frf_ending_below_the_tool_mode_gives_lobes_and_no_recommendation(capsys, tmp_path):
    # a soft tip's band, cropped at 1400 Hz below the tool mode at 1.5 kHz: 69 mm was recommended where the
    # whole FRF's limit is 1.7 mm
    path = tmp_path / "soft_tip.csv"
    grid = Frequency.from_range("20 Hz", "1400 Hz", "2 Hz")
    default_assembly().receptance("tool.tip:y", frequency=grid).to_csv(path)
    status, out, err = run(capsys, "lobes", "--frf", path, *THESIS_CUT, "--json")
    assert status == 0 and "warning: zoa: a mode lies above the band: the FRF (x) rises from" in err, err
    result = json.loads(out)
    assert result["recommended"] is None
    assert result["no_recommendation_reason"].startswith("a mode lies above the FRF's band (the FRF (x) rises from")
    assert any(n.startswith("warning: zoa: a mode lies above the band") for n in result["notes"])
    assert result["structure_band"]["mode_above"].startswith("the FRF (x) rises from 11")
    assert result["absolute_limit_m"] is not None  # the lobes of what was measured stand


def test_an_assembly_whose_grid_stops_below_the_tool_mode_is_refused(capsys, tmp_path):
    # the model's [frequency] stopping at 1200 Hz gave a recommendation of 30 mm, the flutes' length
    path = tmp_path / "low.toml"
    path.write_text(ASSEMBLY.read_text().replace('stop = "5000 Hz"', 'stop = "1200 Hz"'))
    status, out, err = run(capsys, "lobes", "--assembly", path, "--at", "tool.tip", "--immersion", "0.5",
                           "--workpiece", "aluminium-6061")
    assert status == 1 and out == ""
    assert "the grid stops at 1200 Hz, below a mode of the model at about 1" in err, err
    assert "[frequency] stop in the assembly file" in err
