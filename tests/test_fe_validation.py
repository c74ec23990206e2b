"""The library's exact receptances against the independent FE model of fe_reference.

The FE model (Friedman-Kosmatka Timoshenko elements, its own section
properties, its own assembly of joints, masses and springs) shares no code
with the library.  Natural frequencies must agree within 0.2 % (first five);
receptances within the FE model's discretisation error.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

import fe_reference as fe
from substructure import (
    Assembly,
    Flutes,
    Frequency,
    Holder,
    Insert,
    Joint,
    Material,
    Segment,
    Sensor,
    Spindle,
    Support,
    Tool,
)

STEEL0 = Material("steel0", E="210 GPa", nu=0.29, rho="7850 kg/m^3")
CARBIDE0 = Material("carbide0", E="580 GPa", nu=0.22, rho="14500 kg/m^3")
FE_STEEL = fe.Material(210e9, 0.29, 7850.0)
FE_CARBIDE = fe.Material(580e9, 0.22, 14500.0)


def poles(h, f_max, n_modes, lines=6000):
    """Natural frequencies as the poles of a real (undamped) point receptance h(f)."""
    f = np.linspace(f_max / lines, f_max, lines)
    values = h(f)
    found = []

    def inv(x):
        with np.errstate(all="ignore"):
            v = h(np.array([x]))[0]
        return 0.0 if not np.isfinite(v) else 1.0 / v

    for i in np.nonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]:
        if values[i] > 0 > values[i + 1]:
            found.append(brentq(inv, f[i], f[i + 1], xtol=1e-10, rtol=1e-13))
    return np.array(found[:n_modes])


@pytest.mark.parametrize(
    "segments, fe_segments",
    [
        # stubby solid beam, L/d = 2.5: shear and rotary inertia matter
        ([Segment("100 mm", "40 mm", material=STEEL0)], [(0.1, fe.section(0.04, 0, FE_STEEL))]),
        # the spindle: hollow steps
        (
            [Segment("120 mm", "70 mm", "40 mm", STEEL0), Segment("150 mm", "90 mm", "40 mm", STEEL0),
             Segment("60 mm", "110 mm", "40 mm", STEEL0)],
            [(0.12, fe.section(0.07, 0.04, FE_STEEL)), (0.15, fe.section(0.09, 0.04, FE_STEEL)),
             (0.06, fe.section(0.11, 0.04, FE_STEEL))],
        ),
        # a holder with a carbide insert in its bore, and a fluted tool segment
        (
            [Segment("16 mm", "63 mm", material=STEEL0), Segment("10 mm", "40 mm", material=STEEL0),
             Segment("40 mm", "40 mm", "12 mm", STEEL0, insert=Insert("12 mm", CARBIDE0)),
             Segment("30 mm", "12 mm", material=CARBIDE0, flutes=Flutes(0.8))],
            [(0.016, fe.section(0.063, 0, FE_STEEL)), (0.010, fe.section(0.04, 0, FE_STEEL)),
             (0.040, fe.section(0.04, 0.012, FE_STEEL, insert=FE_CARBIDE)),
             (0.030, fe.fluted(0.012, 0.8, FE_CARBIDE))],
        ),
    ],
    ids=["stubby", "stepped-spindle", "holder-insert-flutes"],
)
def test_free_free_natural_frequencies_match_fe(segments, fe_segments):
    beam = Tool("b", segments)
    model = fe.Model()
    model.add_beam(fe_segments)  # default mesh: first five within 2.5e-6 of converged
    expected = model.natural_frequencies(5)

    def h(f):
        return beam.receptance(f, ["tip"]).data[:, 0, 0].real

    found = poles(h, 1.1 * expected[-1], 5)
    np.testing.assert_allclose(found, expected, rtol=2e-4)  # issue asks 0.2 %; we see < 1e-5


def _library_assembly(loss: bool):
    steel = Material.from_catalog("steel") if loss else STEEL0
    carbide = Material.from_catalog("carbide") if loss else CARBIDE0
    spindle = Spindle("spindle", [Segment("120 mm", "70 mm", "40 mm", steel),
                                  Segment("150 mm", "90 mm", "40 mm", steel)])
    holder = Holder("holder", [Segment("16 mm", "63 mm", material=steel),
                               Segment("40 mm", "40 mm", "12 mm", steel, insert=Insert("12 mm", carbide))])
    tool = Tool("tool", [Segment("40 mm", "12 mm", material=carbide),
                         Segment("30 mm", "12 mm", material=carbide, flutes=Flutes(0.8))])
    damping = {"yf": "400 N*s/m", "tm": "7 N*m*s/rad"} if loss else {}
    damping_ht = {"yf": "54 N*s/m", "ym": "2 N*s", "tf": "2 N*s", "tm": "1 N*m*s/rad"} if loss else {}
    return Assembly(
        "fe-check",
        components=(spindle, holder, tool),
        joints=(
            Joint("sh", ("spindle.tip", "holder.base"), k={"yf": "4.1e7 N/m", "tm": "3.5e6 N*m/rad"}, c=damping),
            Joint("ht", ("holder.tip", "tool.base"),
                  k={"yf": "1.4e7 N/m", "ym": "2e4 N", "tf": "2e4 N/rad", "tm": "8e4 N*m/rad"}, c=damping_ht),
        ),
        supports=(Support("spindle@100 mm", k={"yf": "2e5 N/m"}, c={"yf": "50 N*s/m"} if loss else None),),
        sensors=(Sensor("acc", "tool.tip-10 mm", "2 g", "5e-8 kg*m^2"),),
    )


def _fe_assembly(loss: bool):
    st = fe.Material(210e9, 0.29, 7850.0, 0.002 if loss else 0.0)
    cb = fe.Material(580e9, 0.22, 14500.0, 0.002 if loss else 0.0)
    m = fe.Model()
    s = m.add_beam([(0.12, fe.section(0.07, 0.04, st)), (0.15, fe.section(0.09, 0.04, st))], points=[0.1])
    h = m.add_beam([(0.016, fe.section(0.063, 0, st)), (0.04, fe.section(0.04, 0.012, st, insert=cb))])
    t = m.add_beam([(0.04, fe.section(0.012, 0, cb)), (0.03, fe.fluted(0.012, 0.8, cb))], points=[0.06])
    w = 1.0 if loss else 0.0
    m.add_joint((s, 0.27), (h, 0.0), k=[[4.1e7, 0], [0, 3.5e6]], c=[[400 * w, 0], [0, 7 * w]])
    m.add_joint((h, 0.056), (t, 0.0), k=[[1.4e7, 2e4], [2e4, 8e4]], c=[[54 * w, 2 * w], [2 * w, 1 * w]])
    m.add_support((s, 0.1), k=[[2e5, 0], [0, 0]], c=[[50 * w, 0], [0, 0]])
    m.add_mass((t, 0.06), 0.002, 5e-8)
    return m, t


def test_assembly_natural_frequencies_match_fe():
    """Joints with cross terms, a support to ground and a sensor: the coupled modes."""
    asm = _library_assembly(loss=False)
    model, _ = _fe_assembly(loss=False)
    expected = model.natural_frequencies(skip_rigid=1)  # one rigid mode left: rotation about the support
    expected = expected[expected > 5.0][:5]

    def h(f):
        return asm.receptance("tool.tip:y", frequency=f).data[:, 0, 0].real

    found = poles(h, 1.1 * expected[-1], 5, lines=20000)
    np.testing.assert_allclose(found, expected, rtol=2e-4)  # issue asks 0.2 %; we see < 1e-5


def test_assembly_receptances_match_fe_with_damping():
    asm = _library_assembly(loss=True)
    model, t = _fe_assembly(loss=True)
    grid = Frequency.from_range("50 Hz", "4000 Hz", "25 Hz")
    ours = asm.frf(["tool.tip", "spindle@100 mm"], frequency=grid).data
    points = [(t, 0.07, "y"), (t, 0.07, "theta"), (0, 0.1, "y"), (0, 0.1, "theta")]
    theirs = model.receptance(grid.hz, points)
    # Relative to each entry's largest value over the band (the FE mesh error)
    err = np.abs(ours - theirs).max(axis=0) / np.abs(theirs).max(axis=0)
    assert err.max() < 1e-6  # measured 1e-9 with the converged FE mesh


@pytest.mark.parametrize("decay", [5.0, 50.0, 500.0])
def test_assembly_receptances_at_complex_frequency_match_fe(decay):
    """The model as a tap test sees it through an exponential window exp(-t/tau): at omega - i/tau.  The compiled
    beam kernels, joints, support and sensor at complex frequency against the FE model solved with complex w
    (decay = 1/tau: windows of 0.2 s, 20 ms and 2 ms)."""
    from substructure.updating.evaluator import Evaluator
    from substructure.updating.structure import Structure

    asm = _library_assembly(loss=True)
    model, t = _fe_assembly(loss=True)
    grid = Frequency.from_range("50 Hz", "4000 Hz", "25 Hz")
    ours = Evaluator(["tool.tip:y", "tool.tip:theta", "spindle@100 mm:y"], ["tool.tip:y", "spindle@100 mm:y"],
                     grid.hz, decay=decay)(Structure.from_assembly(asm))
    theirs = model.receptance(grid.hz, [(t, 0.07, "y"), (t, 0.07, "theta"), (0, 0.1, "y")],
                              [(t, 0.07, "y"), (0, 0.1, "y")], decay=decay)
    err = np.abs(ours - theirs).max(axis=0) / np.abs(theirs).max(axis=0)
    assert err.max() < 1e-6  # measured 1e-9, as on the real lines
    real = model.receptance(grid.hz, [(t, 0.07, "y")], [(t, 0.07, "y")])
    assert np.abs(theirs[:, 0, 0] - real[:, 0, 0]).max() > 1e-3 * np.abs(real).max()  # the window changes it


def test_slender_beam_at_high_frequency_matches_fe():
    """k L up to ~40: the beam is evaluated in rigidly joined pieces of k L <= 8."""
    rod = Tool("rod", [Segment("0.5 m", "6 mm", material=STEEL0)])
    model = fe.Model()
    model.add_beam([(0.5, fe.section(0.006, 0, FE_STEEL))], n_elem=200, points=[0.2])
    f = np.linspace(100.0, 9000.0, 60)
    ours = rod.receptance(f, ["tip", "@200 mm"]).data
    theirs = model.receptance(f, [(0, 0.5, "y"), (0, 0.5, "theta"), (0, 0.2, "y"), (0, 0.2, "theta")])
    # relative to each entry's largest value (poles excluded by the grid)
    err = np.abs(ours - theirs).max(axis=0) / np.abs(theirs).max(axis=0)
    assert err.max() < 1e-3
    expected = model.natural_frequencies(40)
    expected = expected[expected < 9000.0]

    def h(freq):
        return rod.receptance(freq, ["tip"]).data[:, 0, 0].real

    np.testing.assert_allclose(poles(h, 9000.0, len(expected), lines=40000), expected, rtol=1e-4)
