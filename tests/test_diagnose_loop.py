"""The loop closes: a model saved by the diagnosis, diagnosed again against the same tests, is explained.

The data come from the independent FE rig (hidden_data.py): a 120 g nut on
the holder and a 2 g accelerometer on the tool tip that the measurement
record does not mention.  The diagnosis finds both; the improved model keeps
the nut as a permanent body (``[[masses]]``) and the accelerometer as a
sensor that is on in every test (``always_on``), so that the second
diagnosis finds nothing missing and identification uses them.
"""

import json

import pytest

import hidden_data as hd
from substructure import load_assembly, save_assembly
from substructure.cli import main
from substructure.diagnose import diagnose
from substructure.identify import identify_joint
from substructure.measurements import Measurement, MeasurementSet
from substructure.synthetic import write_measurement_set

POINTS = ("tool.tip", "tool.tip-20 mm")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("loop")
    frfs = hd.measure(nut=(0.12, 3e-5, 0.030), sensor_kg=0.002, points=POINTS, seed=51)
    measured = tuple(Measurement.from_frf(frf, p, "tool.tip") for frf, p in zip(frfs, POINTS))
    write_measurement_set(MeasurementSet("tap test, nut and accelerometer", measured), d)
    save_assembly(hd.nominal_model(), d / "model.toml")
    return d


def test_the_saved_model_is_explained_by_the_same_tests_in_python(files):
    measurements = MeasurementSet.from_file(files / "measurements.toml")
    first = diagnose(load_assembly(files / "model.toml"), measurements)
    assert first.explained
    assert {e.name for e in first.effects} == {"added-mass", "sensor-mass"}
    save_assembly(first.refined_assembly, files / "improved.toml")
    improved = load_assembly(files / "improved.toml")
    (nut,) = improved.masses
    assert nut.mass_kg == pytest.approx(0.12, rel=0.05)
    (sensor,) = improved.sensors
    assert sensor.always_on and sensor.at == "tool.tip" and sensor.mass_kg == pytest.approx(0.002, rel=0.1)
    again = diagnose(improved, measurements)
    assert again.explained and again.missing_effect is None and len(again.refinement) == 1
    assert again.baseline_error <= 1.5 * again.noise_floor
    assert again.baseline_error == pytest.approx(first.final_error, rel=1e-3)
    # identification uses the bodies the diagnosis added: its model fits the data within the noise
    report = identify_joint(improved, measurements, "holder-tool")
    assert report.consistent and report.k["yf"] == pytest.approx(1.43e7, rel=0.03)
    bare = identify_joint(load_assembly(files / "model.toml"), measurements, "holder-tool")
    assert not bare.consistent and any("misses something" in w for w in bare.warnings)


def test_the_loop_through_the_command(files, tmp_path, capsys):
    model, data = str(files / "model.toml"), str(files / "measurements.toml")
    improved = str(tmp_path / "improved.toml")
    assert main(["diagnose", model, data, "--quiet", "--json", "--save-model", improved]) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["explained"] is True and first["final_error"] <= 1.5 * first["noise_floor"]
    assert main(["diagnose", improved, data, "--quiet", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["explained"] is True and again["missing_effect"] is None
    assert again["baseline_error"] <= 1.5 * again["noise_floor"]
    assert main(["identify", improved, data, "--joint", "holder-tool", "--json"]) == 0
    ident = json.loads(capsys.readouterr().out)
    assert ident["consistent"] is True and not any("misses something" in w for w in ident["warnings"])
