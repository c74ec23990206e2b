"""`substructure identify` on a synthetic tap test with an accelerometer on the tool tip."""

import json

import pytest

from substructure import Frequency, Sensor, default_assembly, load_assembly, save_assembly
from substructure.cli import main
from substructure.measurements import MeasurementSet
from substructure.synthetic import simulate, write_measurement_set

POINTS = ["tool.tip", "tool.tip-20 mm", "tool.tip-40 mm"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("identify")
    truth = default_assembly().attach(Sensor("accelerometer", "tool.tip", "2 g", "5e-8 kg*m^2"))
    grid = Frequency.from_range("100 Hz", "5000 Hz", "4 Hz")
    measured = [m for i, e in enumerate(POINTS)
                for m in simulate(truth, POINTS, e, frequency=grid, noise=0.02, seed=i, sensors=["accelerometer"])]
    write_measurement_set(MeasurementSet("bench test", tuple(measured)), d)
    start = truth.with_joint(truth.joint("holder-tool").with_parameters(k={"yf": "0.7e7 N/m"}, c={"yf": "30 N*s/m"}))
    save_assembly(start, d / "model.toml")
    return d


def test_identify_json_follows_formats_md(files, capsys):
    status = main(["identify", str(files / "model.toml"), str(files / "measurements.toml"),
                   "--joint", "holder-tool", "--json", "--plot", str(files / "id.png")])
    out = json.loads(capsys.readouterr().out)
    assert status == 0
    assert set(out) >= {"joint", "band_hz", "k", "c", "k_std", "c_std", "warnings"}
    assert out["joint"] == "holder-tool" and out["band_hz"][0] < out["band_hz"][1]
    assert set(out["k"]) == {"yf", "ym", "tf", "tm"} == set(out["c_std"])
    assert out["k"]["yf"] == pytest.approx(1.43e7, rel=0.01)  # the accelerometer was put on the model
    assert out["c"]["yf"] == pytest.approx(12.0, rel=0.1)
    assert abs(out["k"]["yf"] - 1.43e7) < 3 * out["k_std"]["yf"] + 1e-3 * 1.43e7
    assert (files / "id.png").stat().st_size > 0


def test_identify_human_output_and_errors(files, capsys):
    assert main(["identify", str(files / "model.toml"), str(files / "measurements.toml"),
                 "--joint", "holder-tool", "--band", "2200:3200"]) == 0
    text = capsys.readouterr().out
    assert "band 2200-3200 Hz" in text and "k_yf = 1.43e+07" in text
    assert main(["identify", str(files / "model.toml"), str(files / "measurements.toml"), "--joint", "nope"]) == 1
    assert "no joint 'nope'" in capsys.readouterr().err
    assert main(["identify", str(files / "model.toml"), str(files / "measurements.toml"),
                 "--joint", "holder-tool", "--band", "3000:1000"]) == 2
    err = capsys.readouterr().err
    assert "LO < HI" in err and "Traceback" not in err


def test_a_value_on_the_bound_of_its_search_is_printed_without_a_standard_deviation(files, capsys):
    # c_tm starts at 2500 times its true value (4 N*m*s/rad): the fit runs to the lower bound of its search, 10
    model = load_assembly(files / "model.toml")
    far = model.with_joint(model.joint("holder-tool").with_parameters(c={"tm": "1e4 N*m*s/rad"}))
    save_assembly(far, files / "far.toml", overwrite=True)
    args = ["identify", str(files / "far.toml"), str(files / "measurements.toml"), "--joint", "holder-tool",
            "--parameters", "c_tm"]
    assert main(args) == 0
    text = capsys.readouterr().out
    line = next(s for s in text.splitlines() if s.strip().startswith("c_tm ="))
    assert "bound of its search" in line and "not a measurement" in line and "+-" not in line
    assert "note: c_tm = " in text and "widen the band (--band" in text
    assert main(args + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["at_bound"] == ["c_tm"]
    assert out["parameters"]["c_tm"]["at_bound"] == "lower" and out["c"]["tm"] == pytest.approx(10.0)
    assert out["parameters"]["c_tm"]["std"] is None and out["c_std"]["tm"] is None
    assert out["parameters"]["c_tm"]["search"][0] < out["parameters"]["c_tm"]["search"][1]


def test_values_inside_their_search_carry_no_bound(files, capsys):
    assert main(["identify", str(files / "model.toml"), str(files / "measurements.toml"), "--joint", "holder-tool",
                 "--parameters", "k_yf,c_yf", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["at_bound"] == [] and out["parameters"]["k_yf"]["at_bound"] is None
    assert out["parameters"]["k_yf"]["std"] > 0


def test_a_zero_joint_value_and_a_parameter_named_twice_are_refused_in_cli_words(files, capsys):
    model = load_assembly(files / "model.toml")
    zero = model.with_joint(model.joint("holder-tool").with_parameters(k={"yf": "0 N/m"}))
    save_assembly(zero, files / "zero.toml", overwrite=True)
    assert main(["identify", str(files / "zero.toml"), str(files / "measurements.toml"),
                 "--joint", "holder-tool"]) == 1
    err = capsys.readouterr().err
    assert "joint 'holder-tool' has k_yf = 0 N/m in the assembly" in err
    assert "positive k_yf in the assembly file" in err and "Traceback" not in err
    assert main(["identify", str(files / "model.toml"), str(files / "measurements.toml"),
                 "--joint", "holder-tool", "--parameters", "k_yf,k_yf"]) == 2
    assert "argument --parameters: k_yf named twice" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["identify", "diagnose"])
def test_a_data_file_off_a_uniform_grid_is_named_with_its_set_entry_and_line(files, capsys, tmp_path, command):
    grid = Frequency.from_range("100 Hz", "2000 Hz", "10 Hz")
    hz = [float(f) for i, f in enumerate(grid.hz) if i != 50]
    (tmp_path / "tip.csv").write_text("frequency_hz,real,imag\n" + "".join(f"{f!r},1e-6,1e-8\n" for f in hz))
    (tmp_path / "set.toml").write_text('[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\nfile = "tip.csv"\n')
    extra = ["--joint", "holder-tool"] if command == "identify" else []
    assert main([command, str(files / "model.toml"), str(tmp_path / "set.toml"), *extra]) == 1
    err = capsys.readouterr().err
    assert "set.toml, line 4: frf[0].file: " in err and "tip.csv, line 52: at 610 Hz" in err
    assert "need equally spaced lines" in err and "Traceback" not in err and "interpolate" not in err
