"""A fitted value on the bound of its search is not a measurement (diagnose.diagnosis.bound_hits)."""

from types import SimpleNamespace

from substructure.diagnose.diagnosis import bound_hits, bound_text
from substructure.updating.changes import ParamSpec


def _change(*specs):
    return SimpleNamespace(effect="added-mass", where="holder", specs=specs)


def _fit(names, at_bound):
    return SimpleNamespace(names=tuple(names), at_bound=tuple(at_bound))


MASS = ParamSpec("mass", "kg", 1e-4, 1.0, 0.01)
INERTIA = ParamSpec("inertia", "kg*m^2", 1e-10, 1e-3, 1e-8)
POSITION = ParamSpec("position", "m", 0.0, 0.066, 0.03, log=False)
NU = ParamSpec("nu", "dimensionless", 0.1, 0.49, 0.22, log=False)


def test_a_main_size_on_its_floor_is_a_hit_and_is_said_with_its_bound():
    current = [(_change(MASS, INERTIA, POSITION), {"mass": 1e-4, "inertia": 1e-8, "position": 0.03})]
    hits = bound_hits(current, _fit([(0, "mass"), (0, "inertia"), (0, "position")], [True, False, False]))
    assert hits == [(0, "mass", 1e-4, 1e-4, "lower")]
    assert bound_text(current, hits[0]) == ("added-mass at holder: mass = 0.0001 kg, the lower bound of its "
                                            "search (0.0001 kg)")


def test_places_and_negligible_secondary_sizes_are_findings_not_hits():
    """A body at the tip of its component, a sensor without detectable rotary inertia."""
    current = [(_change(MASS, INERTIA, POSITION), {"mass": 0.002, "inertia": 1e-10, "position": 0.066})]
    assert bound_hits(current, _fit([(0, "mass"), (0, "inertia"), (0, "position")], [False, True, True])) == []


def test_a_secondary_linear_parameter_on_its_bound_is_a_hit():
    """Poisson's ratio at 0.49, the bound of the material search."""
    current = [(_change(ParamSpec("E", "Pa", 1e11, 7e11, 5.8e11), NU), {"E": 5.5e11, "nu": 0.49})]
    hits = bound_hits(current, _fit([(0, "E"), (0, "nu")], [False, True]))
    assert [(h[1], h[4]) for h in hits] == [("nu", "upper")]
    assert bound_hits(current, None) == []
