"""`substructure diagnose`: the JSON of docs/file-formats.md, human output, figures, the improved model, bad input."""

import json

import pytest

import hidden_data as hd
from substructure import load_assembly, save_assembly
from substructure.cli import main
from substructure.measurements import Measurement, MeasurementSet
from substructure.synthetic import write_measurement_set


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("diagnose")
    frf = hd.measure(sensor_kg=0.002, seed=3)[0]
    write_measurement_set(MeasurementSet("tap test", (Measurement.from_frf(frf, "tool.tip", "tool.tip"),)), d)
    save_assembly(hd.nominal_model(), d / "model.toml")
    return d


def _run(files, *extra):
    return main(["diagnose", str(files / "model.toml"), str(files / "measurements.toml"), "--quiet", *extra])


def test_json_is_exactly_formats_md(files, capsys):
    assert _run(files, "--json", "--effects", "sensor-mass,joint-stiffness") == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("metric", "baseline_error", "noise_floor", "missing_effect", "ambiguous_with", "candidates",
                "refinement"):
        assert key in out
    assert out["metric"] == "rms_log_ratio"
    assert out["missing_effect"] == "sensor-mass"
    best = out["candidates"][0]
    assert best["effect"] == "sensor-mass" and best["where"] == "tool.tip"
    assert best["parameters"]["mass"]["unit"] == "kg"
    assert best["parameters"]["mass"]["value"] == pytest.approx(0.002, rel=0.15)
    assert out["refinement"][1]["added"] == "sensor-mass" and out["refinement"][1]["where"] == "tool.tip"
    assert out["refinement"][-1]["error"] < out["baseline_error"] / 5
    assert out["rivals"] == [] and out["search"]["budget"] == 3000 and not out["search"]["cut"]


def test_human_output_figures_and_the_improved_model(files, capsys, tmp_path):
    model_out = tmp_path / "improved.toml"
    assert _run(files, "--effects", "sensor-mass,joint-stiffness", "--plot", str(tmp_path / "figs"),
                "--save-model", str(model_out)) == 0
    text = capsys.readouterr().out
    assert "missing effect: sensor-mass at tool.tip" in text and "watch the error fall" in text
    for name in ("where_it_fails.png", "error_fall.png", "after_refinement.png"):
        assert (tmp_path / "figs" / name).stat().st_size > 0
    improved = load_assembly(model_out)
    (sensor,) = improved.sensors  # written back in its normal form: a [[sensors]] entry
    assert sensor.at == "tool.tip" and sensor.mass_kg == pytest.approx(0.002, rel=0.15)


def test_bad_input(files, capsys, tmp_path):
    assert _run(files, "--effects", "gremlins") == 1
    assert "unknown effect 'gremlins'" in capsys.readouterr().err
    assert _run(files, "--band", "6000:9000") == 1
    assert "outside the measured data" in capsys.readouterr().err
    for option, value in (("--budget", "0"), ("--budget", "nan"), ("--time-limit", "-1")):
        assert _run(files, option, value) == 2
        assert f"argument {option}" in capsys.readouterr().err
    other = tmp_path / "other.toml"
    other.write_text((files / "measurements.toml").read_text().replace('"tool.tip:y"', '"drill.tip:y"', 1))
    (tmp_path / "00_tool_tip__tool_tip.csv").write_text((files / "00_tool_tip__tool_tip.csv").read_text())
    assert main(["diagnose", str(files / "model.toml"), str(other), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "drill" in err and "Traceback" not in err


def test_demo_runs_the_diagnosis_on_built_in_data(capsys, tmp_path):
    assert main(["demo", "--out", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    diagnosis = out["diagnosis"]
    assert diagnosis["missing_effect"] == "sensor-mass"
    assert diagnosis["refinement"][-1]["error"] <= 1.5 * diagnosis["noise_floor"]
    for name in ("where_it_fails.png", "error_fall.png", "improved_assembly.toml", "tool_point_frf.png"):
        assert (tmp_path / name).stat().st_size > 0


def test_an_empty_effect_list_a_band_half_outside_and_a_dead_channel_say_what_is_wrong(files, capsys, tmp_path):
    assert _run(files, "--effects", "") == 2
    assert "--effects: got an empty list" in capsys.readouterr().err
    assert _run(files, "--band", "1000:9000") == 1
    err = capsys.readouterr().err
    assert "ends at 9000 Hz, above the last measured line" in err and "outside the data" not in err
    dead = tmp_path / "dead"
    dead.mkdir()
    (dead / "measurements.toml").write_text((files / "measurements.toml").read_text())
    rows = (files / "00_tool_tip__tool_tip.csv").read_text().splitlines()
    zeros = [rows[0]] + [f"{row.split(',')[0]},0,0" for row in rows[1:]]
    (dead / "00_tool_tip__tool_tip.csv").write_text("\n".join(zeros) + "\n")
    assert main(["diagnose", str(files / "model.toml"), str(dead / "measurements.toml"), "--quiet", "--json"]) == 1
    captured = capsys.readouterr()
    assert "00_tool_tip__tool_tip.csv" in captured.err and "dead channel" in captured.err
    assert captured.out == "" and "Traceback" not in captured.err


def test_an_unexplained_diagnosis_writes_no_partial_model_unless_asked(files, capsys, tmp_path):
    """Only joint damping to explain a hidden sensor: unexplained, and its guesses stay out of the model file."""
    model_out = tmp_path / "partial.toml"
    args = ("--catalogue-only", "--effects", "joint-damping", "--save-model", str(model_out))
    assert _run(files, *args, "--json") == 0
    out = json.loads(capsys.readouterr().out)
    assert out["explained"] is False
    assert out["saved_model"] is None and "not written" in out["notes"][0] and "--save-partial" in out["notes"][0]
    assert not model_out.exists()
    assert _run(files, *args) == 0
    assert "not written" in capsys.readouterr().err
    assert not model_out.exists()
    assert _run(files, *args, "--save-partial", "--json") == 0
    assert json.loads(capsys.readouterr().out)["saved_model"] == str(model_out)
    assert load_assembly(model_out).name


@pytest.mark.parametrize("name", ["improved.csv", "improved", "improved.toml.bak"])
def test_save_model_is_a_toml_file_checked_before_the_diagnosis(files, capsys, tmp_path, name):
    # an assembly file was written under any name, e.g. over a CSV that is no input with --overwrite
    target = tmp_path / name
    target.write_text("frequency_hz,real,imag\n")
    assert _run(files, "--save-model", str(target), "--overwrite") == 2
    err = capsys.readouterr().err
    assert "argument --save-model" in err and "expected a .toml file" in err, err
    assert target.read_text() == "frequency_hz,real,imag\n"
