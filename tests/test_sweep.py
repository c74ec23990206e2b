"""Sweeps give the same receptances as the assemblies one by one."""

import numpy as np
import pytest

from conftest import make_assembly, make_tool, rel_err
from substructure import Frequency, InvalidValueError, Sensor
from substructure.sweep import sweep


def test_overhang_sweep_equals_single_assemblies():
    grid = Frequency.from_range("20 Hz", "5000 Hz", "10 Hz")
    base = make_assembly()
    variants = [base.with_component(make_tool(L)) for L in (40.0, 55.0, 70.0, 85.0)]
    result = sweep(variants, "tool.tip", frequency=grid, chunk_lines=2 * len(grid))  # 2 chunks
    assert result.data.shape == (4, len(grid), 2, 2)
    for i, asm in enumerate(variants):
        single = asm.receptance("tool.tip", frequency=grid)
        assert rel_err(result[i].data, single.data) < 1e-12
        assert result[i].outputs == single.outputs


def test_sweep_over_joint_and_sensor_values():
    grid = Frequency.from_range("100 Hz", "5000 Hz", "20 Hz")
    base = make_assembly().attach(Sensor("acc", "tool.tip", "1 g"))
    variants = [
        base.with_component(make_tool(60.0)).without_sensors().attach(Sensor("acc", "tool@50 mm", f"{m} g"))
        for m in (0.0, 1.0, 3.0)
    ]
    result = sweep(variants, ["tool.tip:y"], ["tool@50 mm:y"], frequency=grid)
    for i, asm in enumerate(variants):
        single = asm.frf(["tool.tip:y"], ["tool@50 mm:y"], frequency=grid)
        assert rel_err(result[i].data, single.data) < 1e-12


def test_sweep_needs_one_structure():
    a = make_assembly()
    with pytest.raises(InvalidValueError, match="another structure"):
        sweep([a, a.attach(Sensor("acc", "tool.tip", "1 g"))], "tool.tip:y", frequency=[100.0, 200.0])
    with pytest.raises(InvalidValueError, match="no assemblies"):
        sweep([], "tool.tip")


# -- the component protocol: a Beam subclass with its own receptances ---------------------------

import attrs  # noqa: E402

from substructure import Holder  # noqa: E402
from substructure.components import is_plain_beam  # noqa: E402
from substructure.coupling import Link, couple_substructures  # noqa: E402


@attrs.frozen
class NutHolder(Holder):
    """A holder with a clamping nut: a lumped mass at its tip, added in receptance_matrix."""

    nut_kg: float = attrs.field(default=0.4, kw_only=True)

    def receptance_matrix(self, refs, frequency_hz):
        f = np.asarray(frequency_hz, dtype=float)
        length = self.length_m
        at_tip = [i for i, r in enumerate(refs) if abs(self.position(r) - length) <= 1e-12 * length]
        refs_all = list(refs) if at_tip else list(refs) + [self._ref("tip")]
        tip = at_tip[0] if at_tip else len(refs)
        y = super().receptance_matrix(refs_all, f)
        mass = np.zeros((2, 2, f.size), dtype=complex)
        mass[0, 0] = -((2.0 * np.pi * f) ** 2) * self.nut_kg  # -omega^2 m on y: a point mass
        keys = list(range(len(refs_all)))
        return couple_substructures([(keys, y)], [Link(tip, None, mass, "nut")], keys[: len(refs)])


def _nut_assembly(nut_kg=0.4, holder_mm=40.0):
    base = make_assembly()
    plain = base.component("holder")
    segments = plain.segments[:-1] + (attrs.evolve(plain.segments[-1], length=f"{holder_mm} mm"),)
    return base.with_component(NutHolder("holder", segments, nut_kg=nut_kg)), base.with_component(
        Holder("holder", segments))


def test_a_holder_with_its_own_receptances_is_not_batched_as_a_plain_beam():
    holder = _nut_assembly()[0].component("holder")
    assert not is_plain_beam(holder) and is_plain_beam(make_assembly().component("holder"))

    @attrs.frozen
    class Renamed(NutHolder):
        plain_beam = True  # a subclass may say it is plain again (here it would be wrong)

    assert is_plain_beam(Renamed("holder", holder.segments))


def test_lumped_nut_same_frf_through_receptance_and_sweep():
    grid = Frequency.from_range("50 Hz", "5000 Hz", "10 Hz")
    # several holders (different lengths and nuts) in one sweep: the batched path of beams
    variants, references = [], []
    for nut, length in ((0.1, 40.0), (0.4, 40.0), (0.4, 55.0), (0.0, 55.0)):
        with_nut, plain = _nut_assembly(nut, length)
        variants.append(with_nut)
        # independent: the plain holder with the nut as a point mass (a massive sensor) at its tip
        references.append(plain.attach(Sensor("nut", "holder.tip", f"{nut * 1000} g")))
    result = sweep(variants, "tool.tip:y", frequency=grid, chunk_lines=3 * len(grid))
    for i, (asm, ref) in enumerate(zip(variants, references)):
        single = asm.receptance("tool.tip:y", frequency=grid)
        assert rel_err(single.data, ref.receptance("tool.tip:y", frequency=grid).data) < 1e-9
        assert rel_err(result[i].data, single.data) < 1e-12
    # and the nut matters: 400 g moves the tool point FRF far beyond the tolerance above
    plain = _nut_assembly(0.4, 40.0)[1].receptance("tool.tip:y", frequency=grid)
    assert rel_err(plain.data, result[1].data) > 0.05


def test_lumped_nut_same_frf_through_the_frf_band():
    from substructure.surrogate import predict_frf_band
    from substructure.surrogate.models import Prediction

    from substructure import default_assembly

    grid = Frequency.from_range("200 Hz", "4000 Hz", "10 Hz")
    base = default_assembly()
    asm = base.with_component(NutHolder("holder", base.component("holder").segments, nut_kg=0.4))
    joint = asm.joint("holder-tool")
    k_yf = joint.k.get("yf")
    prediction = Prediction({"k_yf": np.array([np.log(k_yf)])}, {"k_yf": np.array([0.3])}, {"k_yf": "N/m"})
    band = predict_frf_band(asm, "holder-tool", prediction, at="tool.tip:y", frequency=grid, n_samples=6)
    members = []
    for value in band.samples["k_yf"]:
        variant = asm.with_joint(joint.with_parameters(k={"yf": f"{float(value)!r} N/m"}))
        members.append(np.abs(variant.receptance("tool.tip:y", frequency=grid).data[:, 0, 0]))
    members = np.array(members)
    np.testing.assert_allclose(band.lower, members.min(axis=0), rtol=1e-12)
    np.testing.assert_allclose(band.upper, members.max(axis=0), rtol=1e-12)
    nominal = asm.with_joint(joint.with_parameters(k={"yf": f"{k_yf!r} N/m"})).receptance("tool.tip:y", frequency=grid)
    assert rel_err(band.nominal.data, nominal.data) < 1e-12
