"""``substructure frf`` given wrong points, grids and outputs: one line naming the option, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from substructure.cli import main

EXAMPLE = Path(__file__).parent / "data" / "formats_example.toml"


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return status, out, err


@pytest.mark.parametrize("option, point, said", [
    ("--at", "tool.tip-500 mm", "lies outside 'tool'"),
    ("--at", "tool.tip:z", "unknown DOF 'z'"),
    ("--to", "drill.tip", "no component 'drill'"),
    ("--to", "tool", "expected NAME.base"),
])
def test_a_wrong_point_names_its_option_and_writes_nothing(capsys, tmp_path, option, point, said):
    out = tmp_path / "h.csv"
    points = ["--at", point] if option == "--at" else ["--at", "tool.tip", "--to", point]
    status, stdout, err = run(capsys, "frf", EXAMPLE, *points, "--out", out)
    assert status == 1 and stdout == ""
    assert err.startswith(f"substructure: error: argument {option}: point ") and said in err, err
    assert not out.exists()


@pytest.mark.parametrize("grid", ["0:100:5", "0 rpm:100 Hz:5 Hz"])
def test_a_grid_from_0_hz_is_refused_as_the_files_frequency_table_is(capsys, tmp_path, grid):
    # it was read, the file loaded, and the receptance failed with "frequency: component 'tool' is free-free"
    out = tmp_path / "h.csv"
    status, stdout, err = run(capsys, "frf", EXAMPLE, "--at", "tool.tip", "--grid", grid, "--out", out)
    assert status == 2 and stdout == "" and not out.exists()
    assert err.startswith("substructure: error: argument --grid: START is 0 Hz; expected a frequency > 0 Hz"), err
