"""Joint identification: the closed form (thesis eq. 2.3) and the robust band fit."""


import numpy as np
import pytest

from conftest import make_holder
from substructure import (
    FRF,
    Assembly,
    AssemblyError,
    Frequency,
    InvalidValueError,
    Joint,
    Segment,
    Tool,
    default_assembly,
)
from substructure.identify import JointIdentifier, closed_form, joint_sides

GRID = Frequency.from_range("20 Hz", "5000 Hz", "5 Hz")


def _closed_form_on_model(assembly, joint, at):
    side_a, side_b, at_a, at_b = joint_sides(assembly, joint)
    coupled = assembly.receptance(at, frequency=GRID)
    ya = side_a.receptance(at_a, frequency=GRID)
    yb = side_b.frf([at, at_b] if at != at_b else [at], frequency=GRID)
    return closed_form(coupled, ya, yb, at=at, at_a=at_a, at_b=at_b)


def _check_recovers(result, joint, rtol=1e-6):
    for name in ("k_yf", "k_ym", "k_tf", "k_tm", "c_yf", "c_ym", "c_tf", "c_tm"):
        kind, entry = name.split("_")
        expected = (joint.k if kind == "k" else joint.c).get(entry)
        got = result.parameter(name)
        if expected == 0:
            scale = max(abs((joint.k if kind == "k" else joint.c).get(e)) for e in ("yf", "tm"))
            assert np.abs(got).max() <= rtol * scale, name
        else:
            np.testing.assert_allclose(got, expected, rtol=rtol, err_msg=name)


def test_closed_form_recovers_table_2_2_at_every_line(assembly):
    """Noise-free data from the forward model: every parameter of Table 2.2 to 1e-6."""
    result = _closed_form_on_model(assembly, "holder-tool", "tool.tip")
    _check_recovers(result, assembly.joint("holder-tool"))
    assert set(result.condition) == {"T12", "T21", "W", "K_inv"}


def test_closed_form_recovers_the_spindle_holder_joint(assembly):
    """The same for the spindle-holder joint (Table 2.1), measuring at the holder tip."""
    result = _closed_form_on_model(assembly.without("tool"), "spindle-holder", "holder.tip")
    _check_recovers(result, assembly.joint("spindle-holder"))


def test_closed_form_in_another_topology():
    """A branch: two tools on one holder; identify one tool's joint, measuring at its tip."""
    holder = make_holder()
    a = Tool("a", [Segment("50 mm", "12 mm", material="carbide")])
    b = Tool("b", [Segment("40 mm", "10 mm", material="carbide")])
    ja = Joint("ja", ("holder.tip", "a.base"),
               k={"yf": "3e7 N/m", "ym": "1e5 N", "tf": "1e5 N/rad", "tm": "5e4 N*m/rad"},
               c={"yf": "40 N*s/m", "tm": "2 N*m*s/rad"})
    jb = Joint("jb", ("holder@30 mm", "b.base"), k={"yf": "2e7 N/m", "tm": "4e4 N*m/rad"}, c={"yf": "20 N*s/m"})
    asm = Assembly("branch", components=(holder, a, b), joints=(ja, jb))
    _check_recovers(_closed_form_on_model(asm, "ja", "a.tip"), ja)
    # measuring at the joint point itself (T11 = T12 = T22)
    _check_recovers(_closed_form_on_model(asm, "jb", "b.base"), jb, rtol=1e-5)


def test_closed_form_errors(assembly):
    loop = assembly.connect("spindle@100 mm", "tool@30 mm", name="brace", k={"yf": "1e6 N/m"})
    with pytest.raises(AssemblyError, match="does not separate"):
        joint_sides(loop, "holder-tool")
    side_a, side_b, at_a, at_b = joint_sides(assembly, "holder-tool")
    coupled = assembly.receptance("tool.tip:y", frequency=GRID)
    with pytest.raises(InvalidValueError, match="lacks tool.tip:theta"):
        closed_form(coupled, side_a.receptance(at_a, frequency=GRID), side_b.frf(["tool.tip", at_b], frequency=GRID),
                    at="tool.tip", at_a=at_a, at_b=at_b)


def _noisy(frf, level, seed):
    rng = np.random.default_rng(seed)
    noise = (rng.standard_normal(frf.data.shape) + 1j * rng.standard_normal(frf.data.shape)) / np.sqrt(2)
    return FRF(frf.frequency, frf.data * (1 + level * noise), frf.outputs, frf.inputs)


def test_band_fit_recovers_a_passive_joint_from_noisy_tool_point_data():
    asm = default_assembly()
    truth = asm.joint("holder-tool")
    h = asm.receptance("tool.tip:y", frequency=Frequency.from_range("20 Hz", "5000 Hz", "2 Hz"))
    start = asm.with_joint(truth.with_parameters(k={"yf": "0.6e7 N/m", "tm": "2e5 N*m/rad"},
                                                 c={"yf": "30 N*s/m", "tm": "1 N*m*s/rad"}))
    within = 0
    for seed in range(6):
        ident = JointIdentifier("holder-tool").fit(start, [_noisy(h, 0.02, seed)])
        assert ident.values_["k_yf"] == pytest.approx(1.43e7, rel=0.02)
        assert ident.values_["c_yf"] == pytest.approx(12.0, rel=0.1)
        errors = [abs(ident.values_[p] - v) / ident.std_[p] for p, v in
                  (("k_yf", 1.43e7), ("k_tm", 8e4), ("c_yf", 12.0), ("c_tm", 4.0))]
        within += all(e < 3 for e in errors)
        assert 0.015 < ident.residual_rms_ < 0.025  # the 2 % noise, not model error
    assert within >= 5
    assert ident.warnings_ == []


def test_band_fit_errors():
    asm = default_assembly()
    h = asm.receptance("tool.tip:y", frequency=Frequency.from_range("1000 Hz", "1100 Hz", "50 Hz"))
    with pytest.raises(InvalidValueError, match="parameters"):
        JointIdentifier("holder-tool", parameters=("k_xx",)).fit(asm, [h])
    with pytest.raises(InvalidValueError, match="too few"):
        JointIdentifier("holder-tool", band=(1000, 1100)).fit(asm, [h])
    with pytest.raises(InvalidValueError, match="lo < hi"):
        JointIdentifier("holder-tool", band=(2000, 1000)).fit(asm, [h])


def test_a_set_without_what_the_fit_needs_says_what_is_missing():
    from substructure.synthetic import simulate

    asm = default_assembly()
    only_holder = simulate(asm, ["holder.tip"], frequency=Frequency.from_range("100 Hz", "2000 Hz", "10 Hz"),
                           removed=["tool"])
    with pytest.raises(InvalidValueError, match=r"needs at least one FRF measured with the joint in place.*"
                                                r"holder.tip:y with \['tool'\] removed"):
        JointIdentifier("holder-tool").fit(asm, list(only_holder))


def test_closed_form_diagonal_model_eq_2_4():
    """A diagonal joint (eq. 2.4) is recovered by both models; with cross terms only 'full' is exact."""
    asm = default_assembly()
    side_a, side_b, at_a, at_b = joint_sides(asm, "holder-tool")
    args = (asm.receptance("tool.tip", frequency=GRID), side_a.receptance(at_a, frequency=GRID),
            side_b.frf(["tool.tip", at_b], frequency=GRID))
    for model in ("full", "diagonal"):
        _check_recovers(closed_form(*args, at="tool.tip", at_a=at_a, at_b=at_b, model=model), asm.joint("holder-tool"))
    with pytest.raises(InvalidValueError, match="model"):
        closed_form(*args, at="tool.tip", at_a=at_a, at_b=at_b, model="banded")


def test_a_parameter_the_data_do_not_determine_is_reported_on_its_bound_not_as_a_measurement():
    asm = default_assembly()
    grid = Frequency.from_range("1000 Hz", "5000 Hz", "4 Hz")
    truth = asm.with_joint(asm.joint("holder-tool").with_parameters(c={"tm": "1e-6 N*m*s/rad"}))
    h = _noisy(truth.receptance("tool.tip:y", frequency=grid), 0.02, 0)
    ident = JointIdentifier("holder-tool", parameters=("c_tm",)).fit(asm, [h])
    assert ident.at_bound_ == {"c_tm": "lower"}
    assert ident.search_["c_tm"] == pytest.approx((4e-3, 4e3))
    assert ident.values_["c_tm"] == pytest.approx(4e-3)
    assert np.isnan(ident.std_["c_tm"])  # no standard deviation: not a measurement
    note = next(w for w in ident.warnings_ if "bound" in w)
    assert "c_tm = 0.004 N*m*s/rad is on the lower bound of its search" in note
    assert "not a measurement" in note and "widen the band" in note and "initial=" in note


def test_values_inside_their_search_are_not_on_a_bound():
    asm = default_assembly()
    h = _noisy(asm.receptance("tool.tip:y", frequency=Frequency.from_range("1000 Hz", "5000 Hz", "4 Hz")), 0.02, 1)
    ident = JointIdentifier("holder-tool", parameters=("k_yf", "c_yf")).fit(asm, [h])
    assert ident.at_bound_ == {}
    assert ident.search_["k_yf"] == pytest.approx((1.43e4, 1.43e10))
    assert all(np.isfinite(ident.std_[p]) and ident.std_[p] > 0 for p in ("k_yf", "c_yf"))
    assert not any("bound" in w for w in ident.warnings_)


def test_a_joint_value_that_cannot_start_the_search_is_refused_naming_joint_and_parameter():
    asm = default_assembly()
    h = asm.receptance("tool.tip:y", frequency=Frequency.from_range("1000 Hz", "5000 Hz", "4 Hz"))
    zero = asm.with_joint(asm.joint("holder-tool").with_parameters(k={"yf": "0 N/m"}))
    with pytest.raises(InvalidValueError, match=r"joint 'holder-tool' has k_yf = 0 N/m in the assembly; .*"
                                                r"give the joint a positive k_yf in the assembly file"):
        JointIdentifier("holder-tool").fit(zero, [h])
    ident = JointIdentifier("holder-tool", parameters=("k_yf",), initial={"k_yf": 1e7}).fit(zero, [h])
    assert ident.values_["k_yf"] == pytest.approx(1.43e7, rel=1e-3)


def test_a_parameter_named_twice_is_refused():
    asm = default_assembly()
    h = asm.receptance("tool.tip:y", frequency=Frequency.from_range("1000 Hz", "5000 Hz", "4 Hz"))
    with pytest.raises(InvalidValueError, match="parameters: k_yf named twice"):
        JointIdentifier("holder-tool", parameters=("k_yf", "c_yf", "k_yf")).fit(asm, [h])


def test_band_mean_refuses_a_band_without_lines(assembly):
    result = _closed_form_on_model(assembly, "holder-tool", "tool.tip")
    k = result.band_mean("k_yf", (500, 1500))
    np.testing.assert_allclose(k, assembly.joint("holder-tool").k.get("yf"), rtol=1e-6)
    with pytest.raises(InvalidValueError, match=r"band: \(6000, 7000\) holds no line of the result's frequencies "
                                                r"20\.\.5000 Hz"):
        result.band_mean("k_yf", (6000, 7000))
    with pytest.raises(InvalidValueError, match=r"band: got 500; expected \(lo, hi\) in Hz"):
        result.band_mean("k_yf", 500)
