"""Tests of substructure.cli: the `substructure` command (docs/file-formats.md)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from substructure import FRF, Frequency
from substructure.cli import DEMO_STEPS, main
from substructure.io.assembly_toml import default_assembly, load_assembly

EXAMPLE = Path(__file__).parent / "data" / "formats_example.toml"
EXAMPLE_TEXT = EXAMPLE.read_text(encoding="utf-8")


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


def test_frf_json_is_one_object_that_matches_the_python_api(capsys):
    status, out, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--json")
    assert status == 0 and err == ""
    result = json.loads(out)
    assert set(result) == {"frequency_hz", "real", "imag", "peaks_hz"}
    hz = np.array(result["frequency_hz"])
    assert len(hz) == len(result["real"]) == len(result["imag"])
    peaks = np.array(result["peaks_hz"])
    assert peaks.size > 0 and np.all(np.diff(peaks) > 0)
    assert np.all((peaks > hz[0]) & (peaks < hz[-1]))
    expected = load_assembly(EXAMPLE).receptance("tool.tip:y")
    np.testing.assert_array_equal(hz, expected.frequency.hz)
    values = np.array(result["real"]) + 1j * np.array(result["imag"])
    np.testing.assert_allclose(values, expected.data[:, 0, 0], rtol=1e-12, atol=0)
    np.testing.assert_array_equal(peaks, expected.peaks())


def test_frf_to_point_dof_and_grid_with_units(capsys):
    status, out, _ = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--to", "holder.tip:theta",
                         "--grid", "100 Hz:2 kHz:5 Hz", "--json")
    assert status == 0
    result = json.loads(out)
    grid = Frequency.from_range("100 Hz", "2 kHz", "5 Hz")
    expected = load_assembly(EXAMPLE).receptance("tool.tip:y", "holder.tip:theta", grid)
    np.testing.assert_array_equal(result["frequency_hz"], grid.hz)
    np.testing.assert_allclose(result["real"], expected.data[:, 0, 0].real, rtol=1e-12, atol=0)


def test_frf_plain_numbers_in_grid_are_hz(capsys):
    status, out, _ = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--grid", "20:200:10", "--json")
    assert status == 0
    assert json.loads(out)["frequency_hz"] == list(np.arange(20.0, 201.0, 10.0))


def test_frf_summary_names_the_assembly_points_grid_and_peaks(capsys):
    status, out, _ = run(capsys, "frf", EXAMPLE, "--at", "tool.tip")
    assert status == 0
    assert "BT40 holder" in out and "tool.tip:y" in out and "2491 lines" in out
    for peak in load_assembly(EXAMPLE).receptance("tool.tip:y").peaks():
        assert f"{peak:g} Hz" in out


def test_frf_out_csv_uff_and_plot(capsys, tmp_path):
    csv, uff, png = tmp_path / "tip.csv", tmp_path / "tip.uff", tmp_path / "tip.png"
    status, out, _ = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--out", csv, "--plot", png)
    assert status == 0 and str(csv) in out and str(png) in out
    assert run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--out", uff)[0] == 0
    expected = load_assembly(EXAMPLE).receptance("tool.tip:y")
    from_csv = FRF.from_csv(csv)
    np.testing.assert_array_equal(from_csv.data, expected.data)
    from_uff = FRF.from_uff(uff)
    assert from_uff.frequency == expected.frequency
    np.testing.assert_allclose(from_uff.data.real, expected.data.real, rtol=5e-12, atol=0)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_warnings_go_to_stderr_once_and_json_stays_clean(capsys, tmp_path):
    path = tmp_path / "thesis.toml"  # thesis Table 2.2 joint: not positive semi-definite
    text = EXAMPLE_TEXT.replace('ym = "1.0e6 N", tf = "1.0e6 N/rad"', 'ym = "2.06e6 N", tf = "2.06e6 N/rad"')
    path.write_text(text, encoding="utf-8")
    status, out, err = run(capsys, "frf", path, "--at", "tool.tip", "--json")
    assert status == 0
    json.loads(out)
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("substructure: warning: ") and "non-passive" in lines[0]


@pytest.mark.parametrize("argv, status, message", [
    (["frf", EXAMPLE, "--at", "tool.nose"], 1, "nose"),
    (["frf", EXAMPLE, "--at", "tool@80 mm"], 1, "outside 'tool'"),
    (["frf", "no-such-file.toml", "--at", "tool.tip"], 1, "no-such-file.toml"),
    (["frf", EXAMPLE, "--at", "tool.tip", "--grid", "20:5000"], 2, "--grid"),
    (["frf", EXAMPLE, "--at", "tool.tip", "--grid", "20 kg:5000:2"], 2, "frequency"),
    (["frf", EXAMPLE, "--at", "tool.tip", "--out", "tip.txt"], 2, ".csv or .uff"),
    (["frf", EXAMPLE], 2, "--at"),
    (["frobnicate"], 2, "invalid choice"),
    ([], 2, "choose a command"),
])
def test_mistakes_print_one_line_and_a_status(capsys, argv, status, message):
    got, out, err = run(capsys, *argv)
    assert got == status
    assert out == ""
    assert err.startswith("substructure: error: ") and err.count("\n") == 1 and message in err


def test_frf_without_grid_anywhere_is_an_error(capsys, tmp_path):
    path = tmp_path / "nogrid.toml"
    head, grid = EXAMPLE_TEXT.split("[frequency]")
    path.write_text(head + grid.split('step = "2 Hz"\n', 1)[1], encoding="utf-8")
    assert load_assembly(path).frequency is None
    status, _, err = run(capsys, "frf", path, "--at", "tool.tip")
    assert status == 2 and "--grid" in err
    assert run(capsys, "frf", path, "--at", "tool.tip", "--grid", "20:100:2", "--json")[0] == 0


def test_bad_assembly_file_names_file_and_key(capsys, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(EXAMPLE_TEXT.replace('od = "63 mm"', 'od = 63'), encoding="utf-8")
    status, _, err = run(capsys, "frf", path, "--at", "tool.tip")
    assert status == 1 and str(path) in err and "components[1].segments[0].od" in err


def test_demo_writes_its_files(capsys, tmp_path):
    out_dir = tmp_path / "demo"
    status, out, err = run(capsys, "demo", "--out", out_dir)
    assert status == 0 and err == ""
    for name in ("tool_point_frf.png", "tool_point_frf.csv", "default_assembly.toml"):
        assert (out_dir / name).is_file() and str(out_dir / name) in out
    assert load_assembly(out_dir / "default_assembly.toml") == default_assembly()
    frf = FRF.from_csv(out_dir / "tool_point_frf.csv")
    np.testing.assert_array_equal(frf.data, default_assembly().receptance("tool.tip:y").data)
    assert "tool mode" in out and "spindle" in out and "holder-tool" in out
    assert len(DEMO_STEPS) >= 4


def test_demo_json(capsys, tmp_path):
    status, out, _ = run(capsys, "demo", "--out", tmp_path, "--json")
    assert status == 0
    result = json.loads(out)
    assert result["components"] == ["spindle", "holder", "tool"]
    assert abs(result["tool_mode_hz"] - 1438.0) <= 143.8 and result["tool_mode_hz"] in result["peaks_hz"]


def test_python_dash_m_substructure(tmp_path):
    ok = subprocess.run([sys.executable, "-m", "substructure", "frf", str(EXAMPLE), "--at", "tool.tip",
                         "--grid", "100:1000:50", "--json"], capture_output=True, text=True, timeout=300)
    assert ok.returncode == 0, ok.stderr
    assert len(json.loads(ok.stdout)["frequency_hz"]) == 19
    bad = subprocess.run([sys.executable, "-m", "substructure", "frf", str(tmp_path / "absent.toml"),
                          "--at", "tool.tip"], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 1 and bad.stdout == ""
    assert bad.stderr.startswith("substructure: error: ") and "Traceback" not in bad.stderr


def test_frf_plot_unit_and_kind(capsys, tmp_path, monkeypatch):
    import matplotlib.figure

    saved = []
    real_savefig = matplotlib.figure.Figure.savefig

    def spy(fig, path, *args, **kwargs):
        saved.append((fig.axes[0].get_ylabel(), fig.axes[0].get_xlabel(), fig._suptitle.get_text()))
        return real_savefig(fig, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    png = tmp_path / "tip.png"
    assert run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--plot", png)[0] == 0
    assert saved[-1][0] == "receptance |H| (µm/N)" and "tool.tip:y / tool.tip:y" in saved[-1][2].replace("\n", " ")
    assert run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--plot", png, "--overwrite", "--unit", "m/N",
               "--kind", "nyquist")[0] == 0
    assert saved[-1][:2] == ("receptance, imaginary part (m/N)", "receptance, real part (m/N)")
    status, _, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--plot", png, "--unit", "in/N")
    assert status == 2 and "--unit" in err
