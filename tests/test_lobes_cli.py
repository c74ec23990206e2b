"""`substructure lobes`: structure from an assembly, FRF files or modes; JSON; plot; clear errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

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
    (["--speeds", "1000:2000"], 2, "START:STOP:STEP"),
    (["--diameter", "12"], 1, "diameter"),
    (["--kr", "100 MPa"], 2, "--kr"),
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
