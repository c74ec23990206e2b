"""The ``substructure predict`` command: prediction, cross-validation, errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from substructure.cli import main
from substructure.surrogate import thesis_table_4_2


@pytest.fixture
def table_csv(tmp_path):
    path = tmp_path / "joints.csv"
    thesis_table_4_2().to_csv(path)
    return str(path)


def test_predict_json(table_csv, capsys):
    assert main(["predict", table_csv, "--features", "tool_diameter=14 mm,gauge_length=90 mm", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    k = out["parameters"]["k_yf"]
    assert k["unit"] == "N/m" and k["value"] > 0 and k["std"] > 0


def test_predict_cross_validate_json(table_csv, capsys):
    assert main(["predict", table_csv, "--target", "k_yf", "--cross-validate", "loo", "--model", "gp", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == "gp" and len(out["folds"]) == 13
    assert set(out["folds"][0]) == {"held_out", "true", "predicted", "std"}
    assert 0 <= out["coverage_95"] <= 1 and out["mean_abs_percent_error"] > 0


def test_predict_summary_and_errors(table_csv, capsys):
    assert main(["predict", table_csv, "--features", "tool_diameter=14 mm,gauge_length=90 mm"]) == 0
    assert "k_yf" in capsys.readouterr().out
    assert main(["predict", table_csv, "--features", "tool_diameter=14 mm"]) == 1
    err = capsys.readouterr().err
    assert "gauge_length" in err and "Traceback" not in err
    assert main(["predict", table_csv, "--features", "tool_diameter=14 kg,gauge_length=90 mm"]) == 1
    assert "do not match" in capsys.readouterr().err
    assert main(["predict", table_csv, "--features", "tool_diameter=40 mm,gauge_length=90 mm"]) == 0
    assert "warning" in capsys.readouterr().err


def test_predict_with_an_assembly_gives_the_frf_band(tmp_path, capsys):
    from substructure.surrogate import thesis_table_4_2

    table = tmp_path / "table.csv"
    thesis_table_4_2().to_csv(table)
    assembly = Path(__file__).resolve().parents[1] / "substructure" / "data" / "default_assembly.toml"
    status = main(["predict", str(table), "--features", "tool_diameter=12 mm,gauge_length=80 mm", "--json",
                   "--assembly", str(assembly), "--joint", "holder-tool", "--samples", "16",
                   "--plot", str(tmp_path / "band.png")])
    out = json.loads(capsys.readouterr().out)
    assert status == 0
    frf = out["frf"]
    assert frf["joint"] == "holder-tool" and frf["n_samples"] == 16
    assert len(frf["frequency_hz"]) == len(frf["magnitude_lower"]) == len(frf["magnitude_upper"])
    assert all(lo <= md <= hi for lo, md, hi in zip(frf["magnitude_lower"], frf["magnitude_median"],
                                                    frf["magnitude_upper"]))
    assert (tmp_path / "band.png").stat().st_size > 0
    assert main(["predict", str(table), "--features", "tool_diameter=12 mm,gauge_length=80 mm",
                 "--assembly", str(assembly)]) == 2
    assert "go together" in capsys.readouterr().err


def test_predict_refuses_non_positive_sizes(table_csv, capsys):
    for value in ("-14 mm", "0 mm"):
        assert main(["predict", table_csv, "--features", f"tool_diameter={value},gauge_length=90 mm"]) == 1
        captured = capsys.readouterr()
        assert f"--features: tool_diameter is {value}; expected a size > 0" in captured.err
        assert captured.out == "" and "Traceback" not in captured.err


def test_predict_plot_needs_something_to_draw(table_csv, tmp_path, capsys):
    plot = tmp_path / "x.png"
    assert main(["predict", table_csv, "--features", "tool_diameter=14 mm,gauge_length=90 mm",
                 "--plot", str(plot)]) == 2
    captured = capsys.readouterr()
    assert "--plot draws the FRF band of --assembly" in captured.err and "--cross-validate" in captured.err
    assert captured.out == "" and not plot.exists()


def test_predict_refuses_a_test_listed_twice(tmp_path, capsys):
    path = tmp_path / "dup.csv"
    path.write_text("tool_diameter [mm],gauge_length [mm],k_yf [N/m]\n" + "12,76,1.43e7\n" * 3)
    assert main(["predict", str(path), "--features", "tool_diameter=12 mm,gauge_length=76 mm"]) == 1
    err = capsys.readouterr().err
    assert "dup.csv, line 3: the same joint as line 2" in err and "the same test listed twice" in err


def test_predict_json_flags_extrapolation(table_csv, capsys):
    assert main(["predict", table_csv, "--features", "tool_diameter=40 mm,gauge_length=90 mm", "--json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    flag = {"feature": "tool_diameter", "value": 40.0, "unit": "mm", "table_min": 10.0, "table_max": 20.0,
            "side": "above", "distance": 20.0, "times_range": 2.0}
    assert out["extrapolation"] == [flag] and out["parameters"]["k_yf"]["extrapolation"] == [flag]
    assert "warning" in captured.err
    assert main(["predict", table_csv, "--features", "tool_diameter=14 mm,gauge_length=90 mm", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["extrapolation"] == [] and out["parameters"]["k_yf"]["extrapolation"] == []


def test_json_numbers_are_si_whatever_unit_the_table_gives(tmp_path, capsys):
    """A table in N/mm gave its prediction's and its cross-validation's numbers in N/mm in the JSON, whose numbers
    are SI by the command's contract; they are in N/m now, the table's unit named beside."""
    import json

    from substructure.cli import main
    from substructure.surrogate import thesis_table_4_2

    si = tmp_path / "si.csv"
    thesis_table_4_2().to_csv(si)
    lines = si.read_text().splitlines()
    assert lines[0].startswith("tool_diameter [mm],gauge_length [mm],k_yf [N/m]")
    in_mm = tmp_path / "mm.csv"
    rows = [lines[0].replace("[N/m]", "[N/mm]")]
    for line in lines[1:]:
        cells = line.split(",")
        cells[2] = repr(float(cells[2]) / 1000.0)
        rows.append(",".join(cells))
    in_mm.write_text("\n".join(rows) + "\n")
    got = {}
    for name, path in (("si", si), ("mm", in_mm)):
        assert main(["predict", str(path), "--features", "tool_diameter=14 mm,gauge_length=80 mm", "--json"]) == 0
        got[name] = json.loads(capsys.readouterr().out)["parameters"]["k_yf"]
        assert main(["predict", str(path), "--cross-validate", "loo", "--json"]) == 0
        got[name + "_cv"] = json.loads(capsys.readouterr().out)
    assert got["mm"]["unit"] == "N/m" and got["mm"]["table_unit"] == "N/mm" and got["si"]["table_unit"] == "N/m"
    assert got["mm"]["value"] == pytest.approx(got["si"]["value"], rel=1e-6)
    assert got["mm"]["interval_95"] == pytest.approx(got["si"]["interval_95"], rel=1e-6)
    assert got["mm_cv"]["unit"] == "N/m" and got["mm_cv"]["table_unit"] == "N/mm"
    assert got["mm_cv"]["folds"][0]["true"] == pytest.approx(got["si_cv"]["folds"][0]["true"], rel=1e-9)
