"""Bodies on the structure: permanent masses ([[masses]]) and sensors that are on in every test."""

import numpy as np
import pytest

from substructure import FileFormatError, Mass, Sensor, default_assembly, dumps_assembly, loads_assembly, sweep
from substructure.coupling import add_mass
from substructure.measurements import model_of_measurement

F = np.linspace(50.0, 5000.0, 300)


def test_a_mass_acts_like_the_structural_modification_of_thesis_eq_5_2():
    """Coupling a body into the assembly equals adding it to the FRF afterwards (independent formula)."""
    model = default_assembly()
    with_nut = model.attach(Mass("nut", "holder@55 mm", "150 g"))
    points = ["tool.tip:y", "holder@55 mm:y"]
    bare = model.frf(points, points, F)
    expected = add_mass(bare, "holder@55 mm:y", "150 g")
    np.testing.assert_allclose(with_nut.frf(points, points, F).data, expected.data, rtol=1e-9)


def test_masses_and_always_on_sensors_round_trip_through_the_file():
    model = (default_assembly().attach(Mass("nut", "holder@55 mm", "150 g", "4e-5 kg*m^2"))
             .attach(Sensor("acc", "tool.tip", "2 g", always_on=True)))
    text = dumps_assembly(model)
    assert "[[masses]]" in text and "always_on = true" in text
    again = loads_assembly(text)
    assert again == model
    assert again.mass("nut").inertia_si == pytest.approx(4e-5)
    with pytest.raises(FileFormatError, match=r"masses\[0\]\.mass"):
        loads_assembly(text.replace('mass = "150 g"', 'mass = "150 mm"'))
    with pytest.raises(FileFormatError, match="always_on"):
        loads_assembly(text.replace("always_on = true", 'always_on = "yes"'))
    with pytest.raises(FileFormatError, match=r"masses\[0\]\.at"):
        loads_assembly(text.replace('at = "holder@55 mm"', 'at = "holder@95 mm"'))


def test_tests_keep_permanent_masses_and_always_on_sensors():
    model = (default_assembly().attach(Mass("nut", "holder@55 mm", "150 g"))
             .attach(Sensor("acc", "tool.tip", "2 g", always_on=True), Sensor("laser-target", "tool.tip", "1 g")))

    class Test:
        sensors, removed = (), ()

    configured = model_of_measurement(model, Test())
    assert [s.name for s in configured.sensors] == ["acc"] and [m.name for m in configured.masses] == ["nut"]
    assert configured.without_sensors().masses == configured.masses
    assert model.without("holder").masses == () and model.without("tool").sensors == ()
    assert [m.name for m in model.without("tool").masses] == ["nut"]


def test_sweeps_and_prepared_frfs_include_masses():
    model = default_assembly().attach(Mass("nut", "holder@55 mm", "150 g"))
    ref = model.frf("tool.tip:y", "tool.tip:y", F).data
    np.testing.assert_allclose(sweep([model, model], "tool.tip:y", frequency=F)[1].data, ref, rtol=1e-10)
    np.testing.assert_allclose(model.prepare("tool.tip:y", "tool.tip:y", F).evaluate().data, ref, rtol=1e-10)
