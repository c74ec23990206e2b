"""Tapered (conical) segments against closed forms and the independent FE model.

The library models a taper by the fourth-order commutator-free Magnus scheme
(uniform half-steps fed to the exact Timoshenko kernels); the references
share no code with it: the unit-load closed form of a tapered cantilever's
static compliance, integrated by scipy (``test_fe_reference.taper_compliance``),
and the FE model of ``fe_reference`` whose elements integrate the varying
section at Gauss points.
"""

import math
import re

import attrs
import numpy as np
import pytest
from scipy.optimize import brentq

import fe_reference as fe
from substructure import Assembly, Frequency, Holder, Insert, Flutes, Joint, Material, Segment, Spindle, Tool
from substructure.beams import segment_transfer_matrix, stepped_beam_receptance, stepped_beam_receptance_batch
from substructure.tapers import TAPER_ERROR_BOUND
from substructure.errors import InvalidValueError
from test_fe_reference import taper_compliance
from substructure.updating.evaluator import Evaluator

STEEL0 = Material("steel0", E="210 GPa", nu=0.29, rho="7850 kg/m^3")
CARBIDE0 = Material("carbide0", E="580 GPa", nu=0.22, rho="14500 kg/m^3")
FE_STEEL = fe.Material(210e9, 0.29, 7850.0)
F_HZ = np.linspace(20.0, 5000.0, 300)
FE_CARBIDE = fe.Material(580e9, 0.22, 14500.0)
# damped materials (quality factor ~ 1/eta = 100) for receptance comparisons: near an
# undamped pole a tiny frequency error is an unbounded receptance error
STEEL_D = Material("steel_d", E="210 GPa", nu=0.29, rho="7850 kg/m^3", loss_factor=0.01)
CARBIDE_D = Material("carbide_d", E="580 GPa", nu=0.22, rho="14500 kg/m^3", loss_factor=0.01)
FE_STEEL_D = fe.Material(210e9, 0.29, 7850.0, 0.01)
FE_CARBIDE_D = fe.Material(580e9, 0.22, 14500.0, 0.01)
# Receptances near a resonance of quality factor Q carry about 2 Q times the relative
# frequency error (docs/beams.md): 2 * 100 * TAPER_ERROR_BOUND of the peak value.
RECEPTANCE_TOL = 200 * TAPER_ERROR_BOUND

# (library segment, FE taper) pairs: steep taper, hollow cone with a bore that is not
# proportional, a shrink-fit-like nose around a carbide shank, a tapered fluted tool,
# a long slender cone and a cone widening towards the tip
CASES = {
    "steep-taper": (Segment("65.4 mm", "25.375 mm", material=STEEL0, od_tip="44.45 mm"),
                    fe.Taper(0.025375, 0.04445, 0.0, 0.0, FE_STEEL)),
    "hollow": (Segment("70 mm", "60 mm", "30 mm", STEEL0, od_tip="20 mm", id_tip="12 mm"),
               fe.Taper(0.06, 0.02, 0.03, 0.012, FE_STEEL)),
    "insert": (Segment("50 mm", "50 mm", "16 mm", STEEL0, insert=Insert("16 mm", CARBIDE0), od_tip="30 mm"),
               fe.Taper(0.05, 0.03, 0.016, 0.016, FE_STEEL, insert=FE_CARBIDE, insert_od=0.016)),
    "fluted": (Segment("40 mm", "12 mm", material=CARBIDE0, flutes=Flutes(0.8), od_tip="8 mm"),
               fe.Taper(0.012, 0.008, 0.0, 0.0, FE_CARBIDE, ratio=0.8)),
    "slender": (Segment("300 mm", "40 mm", material=STEEL0, od_tip="10 mm"),
                fe.Taper(0.04, 0.01, 0.0, 0.0, FE_STEEL)),
    "widening": (Segment("120 mm", "25 mm", "5 mm", STEEL0, od_tip="45 mm", id_tip="20 mm"),
                 fe.Taper(0.025, 0.045, 0.005, 0.02, FE_STEEL)),
}


def cantilever_compliance(seg: Segment, steps=None) -> np.ndarray:
    """Clamped base, loads at the tip: the 2x2 static compliance from the model's transfer matrices."""
    sections = seg.piece_sections(steps)
    h = seg.length_m / len(sections)
    t = np.eye(4, dtype=complex)
    for sec in sections:
        t = segment_transfer_matrix(sec, h, np.array([0.0]))[..., 0] @ t
    # state [w, psi, V, M]: base displacements 0, base loads F0; tip loads T_FF F0, tip displacements T_uF F0
    return (t[:2, 2:] @ np.linalg.inv(t[2:, 2:])).real * np.array([[-1, 1], [1, -1]])


@pytest.mark.parametrize("name", list(CASES))
def test_static_compliance_matches_closed_form_within_the_bound(name):
    seg, tp = CASES[name]
    exact = taper_compliance(seg.length_m, tp)
    got = cantilever_compliance(seg)
    err = np.abs(np.abs(got) / np.abs(exact) - 1).max()
    assert err < TAPER_ERROR_BOUND, (name, seg.taper_step_count(), err)


@pytest.mark.parametrize("name", ["steep-taper", "hollow", "widening"])
def test_static_compliance_converges_at_fourth_order(name):
    seg, tp = CASES[name]
    exact = taper_compliance(seg.length_m, tp)[0, 0]
    errors = [abs(abs(cantilever_compliance(seg, n)[0, 0]) / exact - 1) for n in (4, 8, 16, 32)]
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 10) and np.all(ratios[1:] > 14) and np.all(ratios < 18), ratios  # 16: fourth order
    assert errors[-1] < 1e-6


def free_free_poles(segments, f_max, n_modes, lines=6000):
    length = sum(s.length_m for s in segments)

    def h(f):
        return stepped_beam_receptance(segments, [length], np.atleast_1d(f))[0, 0].real

    f = np.linspace(f_max / lines, f_max, lines)
    values = h(f)
    found = []
    for i in np.nonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]:
        if values[i] > 0 > values[i + 1]:
            found.append(brentq(lambda x: 1.0 / h(x)[0], f[i], f[i + 1], xtol=1e-10, rtol=1e-14))
    return np.array(found[:n_modes])


@pytest.mark.parametrize("name", ["steep-taper", "hollow", "insert", "slender", "widening"])
def test_free_free_natural_frequencies_match_fe(name):
    """First modes within the bound: the steps follow the geometry and the highest line."""
    seg, tp = CASES[name]
    model = fe.Model(order=4)
    model.add_beam([(seg.length_m, tp)], n_elem=60)
    expected = model.natural_frequencies(6)
    expected = expected[expected < 40000.0]
    found = free_free_poles([seg], 1.02 * expected[-1], len(expected))
    np.testing.assert_allclose(found, expected, rtol=TAPER_ERROR_BOUND)


@pytest.mark.parametrize("decay", [0.0, 50.0])
def test_tapered_holder_in_an_assembly_matches_fe_receptances(decay):
    """A spindle, a holder with a tapered nose around the tool shank and a tapered tool, with joints; with
    ``decay``, at the complex frequency omega - i decay (as seen through an exponential window of 20 ms), the
    tapered components through their receptance_matrix (not plain SI beams)."""
    spindle = Spindle("spindle", [Segment("200 mm", "80 mm", "40 mm", STEEL_D),
                                  Segment("60 mm", "100 mm", "40 mm", STEEL_D, od_tip="70 mm")])
    holder = Holder("holder", [Segment("20 mm", "63 mm", material=STEEL_D),
                               Segment("50 mm", "44 mm", "12 mm", STEEL_D, insert=Insert("12 mm", CARBIDE_D),
                                       od_tip="24 mm")])
    tool = Tool("tool", [Segment("40 mm", "12 mm", material=CARBIDE_D),
                         Segment("30 mm", "12 mm", material=CARBIDE_D, flutes=Flutes(0.8), od_tip="10 mm")])
    asm = Assembly("tapers", [spindle, holder, tool], [
        Joint("sh", ["spindle.tip", "holder.base"], k={"yf": "4e7 N/m", "tm": "3e6 N*m/rad"},
              c={"yf": "400 N*s/m", "tm": "7 N*m*s/rad"}),
        Joint("ht", ["holder.tip", "tool.base"], k={"yf": "1.4e7 N/m", "tm": "8e4 N*m/rad"},
              c={"yf": "12 N*s/m", "tm": "4 N*m*s/rad"}),
    ])
    m = fe.Model()
    s = m.add_beam([(0.2, fe.ring(0.08, 0.04, FE_STEEL_D)), (0.06, fe.Taper(0.1, 0.07, 0.04, 0.04, FE_STEEL_D))],
                   n_elem=12)
    h = m.add_beam([(0.02, fe.ring(0.063, 0.0, FE_STEEL_D)),
                    (0.05, fe.Taper(0.044, 0.024, 0.012, 0.012, FE_STEEL_D, insert=FE_CARBIDE_D, insert_od=0.012))],
                   n_elem=12)
    t = m.add_beam([(0.04, fe.ring(0.012, 0.0, FE_CARBIDE_D)),
                    (0.03, fe.Taper(0.012, 0.01, 0.0, 0.0, FE_CARBIDE_D, ratio=0.8))],
                   n_elem=12)
    m.add_joint((s, 0.26), (h, 0.0), k=[[4e7, 0], [0, 3e6]], c=[[400, 0], [0, 7]])
    m.add_joint((h, 0.07), (t, 0.0), k=[[1.4e7, 0], [0, 8e4]], c=[[12, 0], [0, 4]])
    grid = Frequency.from_range("50 Hz", "6000 Hz", "50 Hz")
    if decay:
        from substructure.updating.evaluator import Evaluator
        from substructure.updating.structure import Structure

        structure = Structure.from_assembly(asm)
        # the tapers held in the SI arrays (the fits' fast path), evaluated at the complex frequency
        assert set(structure.beams) == {"spindle", "holder", "tool"} and not structure.opaque
        assert all(structure.beam(n).tapered.any() for n in structure.beams)
        assert structure.not_at_complex_frequency() == []
        labels = ["tool.tip:y", "tool.tip:theta", "holder.tip:y", "holder.tip:theta"]
        ours = Evaluator(labels, labels, grid.hz, decay=decay)(structure)
    else:
        ours = asm.frf(["tool.tip", "holder.tip"], frequency=grid).data
    theirs = m.receptance(grid.hz, [(t, 0.07, "y"), (t, 0.07, "theta"), (h, 0.07, "y"), (h, 0.07, "theta")],
                          decay=decay)
    err = np.abs(ours - theirs).max(axis=0) / np.abs(theirs).max(axis=0)
    assert err.max() < RECEPTANCE_TOL  # measured 7e-5 (the FE mesh error included)
    assert asm.frf(["tool.tip"], frequency=grid).reciprocity_error() < 1e-10
    if not decay:  # the fits' SI arrays against the FE model too, not only against the objects
        from substructure.updating.evaluator import Evaluator
        from substructure.updating.structure import Structure

        labels = ["tool.tip:y", "tool.tip:theta", "holder.tip:y", "holder.tip:theta"]
        si = Evaluator(labels, labels, grid.hz)(Structure.from_assembly(asm))
        assert (np.abs(si - theirs).max(axis=0) / np.abs(theirs).max(axis=0)).max() < RECEPTANCE_TOL


def test_mass_is_the_frustum_and_the_model_carries_it():
    seg = Segment("80 mm", "30 mm", "10 mm", STEEL0, od_tip="50 mm", id_tip="20 mm")
    r0, r1, q0, q1 = 0.015, 0.025, 0.005, 0.010
    def cone(a, b):
        return math.pi * 0.08 / 3 * (a * a + a * b + b * b)

    assert seg.mass() == pytest.approx(7850 * (cone(r0, r1) - cone(q0, q1)), rel=1e-13)
    # the stepped model (two-point Gauss per step) integrates rho*A exactly
    sections = seg.piece_sections()
    assert sum(s.rhoA for s in sections) * seg.length_m / len(sections) == pytest.approx(seg.mass(), rel=1e-13)
    # and the rigid-body limit of the free-free receptance sees that mass
    w2 = (2 * np.pi * 1e-3) ** 2
    y = Holder("h", [seg]).receptance([1e-3], ["tip", "base"])
    # a force at the centre of mass would give -1/(m w^2); here: sum over both ends' H and the lever arms
    h_tip = y.entry("h.tip:y", "h.tip:y")[0].real
    assert -1 / (seg.mass() * w2) > h_tip  # an end is more compliant than the centre of mass
    total = Holder("h", [seg, Segment("20 mm", "50 mm", material=STEEL0)])
    assert total.mass() == pytest.approx(seg.mass() + Segment("20 mm", "50 mm", material=STEEL0).mass())


def test_equal_ends_are_a_uniform_segment():
    uniform = Segment("40 mm", "30 mm", "10 mm", STEEL0)
    same = Segment("40 mm", "30 mm", "10 mm", STEEL0, od_tip="30 mm", id_tip="1 cm")
    assert not same.is_tapered and same.section() == uniform.section()
    f = np.array([100.0, 3000.0])
    np.testing.assert_array_equal(stepped_beam_receptance([same], [0.0, 0.04], f),
                                  stepped_beam_receptance([uniform], [0.0, 0.04], f))


def test_points_inside_a_taper_and_invariance():
    """A point inside a taper cuts it (each part stepped on its own): the end receptances
    change only within the error bound, and the result stays reciprocal."""
    seg = attrs.evolve(CASES["slender"][0], material=STEEL_D)
    f = np.linspace(50.0, 5000.0, 400)
    ends = stepped_beam_receptance([seg], [0.0, 0.3], f)
    more = stepped_beam_receptance([seg], [0.0, 0.3, 0.1, 0.17], f)
    np.testing.assert_allclose(more, np.swapaxes(more, 0, 1), rtol=1e-10, atol=1e-12 * np.abs(more).max())
    err = np.abs(more[:4, :4] - ends) / np.abs(ends).max(axis=-1, keepdims=True)
    assert err.max() < RECEPTANCE_TOL  # measured 2.5e-4 over four resonances
    # and both against a much finer stepping (the converged model)
    fine = stepped_beam_receptance([attrs.evolve(seg, taper_steps=200)], [0.0, 0.3], f)
    assert (np.abs(ends - fine) / np.abs(fine).max(axis=-1, keepdims=True)).max() < RECEPTANCE_TOL  # 8e-5


def test_split_gives_the_same_beam():
    seg = Segment("60 mm", "40 mm", "10 mm", STEEL0, od_tip="20 mm", id_tip="8 mm")
    a, b = seg.split("25 mm")
    assert a.od == seg.od and b.od_tip == seg.od_tip and a.od_tip == b.od
    assert a.od_tip.m_as("mm") == pytest.approx(40 - 20 * 25 / 60)
    assert a.mass() + b.mass() == pytest.approx(seg.mass(), rel=1e-13)
    f = np.linspace(100.0, 8000.0, 30)
    one = stepped_beam_receptance([seg], [0.0, 0.06], f)
    two = stepped_beam_receptance([a, b], [0.0, 0.06], f)
    # no resonance below 8 kHz
    assert (np.abs(one - two) / np.abs(one).max(axis=-1, keepdims=True)).max() < TAPER_ERROR_BOUND
    with pytest.raises(InvalidValueError, match="at:"):
        seg.split("60 mm")


@pytest.mark.parametrize("steps", [None, 9])
def test_points_inside_a_taper_are_cuts_as_split_makes_them(steps):
    """Points inside a taper step each part between them as Segment.split cuts it (the parts are not built
    there): the same receptances as the split segments given as separate segments, to rounding, with
    automatic steps and with ``taper_steps`` shared out between the parts."""
    seg = Segment("60 mm", "40 mm", "10 mm", STEEL_D, od_tip="20 mm", id_tip="8 mm", taper_steps=steps)
    f = np.linspace(100.0, 12000.0, 60)
    cuts = [0.013, 0.031, 0.047]
    parts, rest, start = [], seg, 0.0
    for x in cuts:
        first, rest = rest.split(f"{(x - start) * 1e3!r} mm")
        parts.append(first)
        start = x
    parts.append(rest)
    points = [0.0, *cuts, 0.06]
    inside = stepped_beam_receptance([seg], points, f)
    split = stepped_beam_receptance(parts, points, f)
    assert (np.abs(inside - split) / np.abs(split).max(axis=-1, keepdims=True)).max() < 1e-9


def test_batch_with_tapers_equals_single_configurations():
    configs = [
        [Segment("30 mm", "63 mm", material=STEEL0), Segment(f"{L} mm", "40 mm", "12 mm", STEEL0,
                                                             insert=Insert("12 mm", CARBIDE0), od_tip="25 mm")]
        for L in (40, 55, 70)
    ]
    configs.append([Segment("30 mm", "63 mm", material=STEEL0), Segment("50 mm", "40 mm", "12 mm", STEEL0)])
    f = np.linspace(100.0, 4000.0, 20)
    batch = stepped_beam_receptance_batch(configs, ["tip", "base"], f)
    for c, segs in enumerate(configs):
        single = stepped_beam_receptance(segs, [sum(s.length_m for s in segs), 0.0], f)
        part = batch[..., c * f.size:(c + 1) * f.size]
        # the batch steps each configuration as finely as the finest of the column
        assert (np.abs(part - single) / np.abs(single).max(axis=-1, keepdims=True)).max() < TAPER_ERROR_BOUND
    # with the same explicit steps the two paths are the same computation
    fixed = [[attrs.evolve(s, taper_steps=6) if s.is_tapered else s for s in segs] for segs in configs[:3]]
    batch = stepped_beam_receptance_batch(fixed, ["tip"], f)
    for c, segs in enumerate(fixed):
        single = stepped_beam_receptance(segs, [sum(s.length_m for s in segs)], f)
        np.testing.assert_allclose(batch[..., c * f.size:(c + 1) * f.size], single, rtol=1e-9)


def test_step_count_follows_geometry_and_frequency():
    cone = Segment("65.4 mm", "25.375 mm", od_tip="44.45 mm")
    steep = Segment("65.4 mm", "20 mm", od_tip="44.45 mm")
    assert steep.taper_step_count() > cone.taper_step_count() >= 2
    slender = Segment("500 mm", "20 mm", od_tip="19 mm")
    assert slender.taper_step_count() == 1
    assert slender.taper_step_count("15 kHz") > 10 > slender.taper_step_count("50 Hz")
    assert Segment("65.4 mm", "25.375 mm", od_tip="44.45 mm", taper_steps=3).taper_step_count("50 kHz") == 3
    assert Segment("10 mm", "12 mm").taper_step_count() == 1


def test_taper_input_errors():
    with pytest.raises(InvalidValueError, match="id_tip"):
        Segment("40 mm", "30 mm", "10 mm", od_tip="20 mm", id_tip="20 mm")
    with pytest.raises(InvalidValueError, match="od_tip"):
        Segment("40 mm", "30 mm", od_tip="-2 mm")
    with pytest.raises(InvalidValueError, match="insert: the bore is tapered"):
        Segment("40 mm", "30 mm", "12 mm", insert=Insert("12 mm", "carbide"), id_tip="14 mm")
    with pytest.raises(InvalidValueError, match="flutes.diameter_ratio"):
        Segment("40 mm", "30 mm", "10 mm", flutes=Flutes(0.5), od_tip="20 mm")
    for bad in (0, -1, 2.5, True, "3"):
        with pytest.raises(InvalidValueError, match="taper_steps"):
            Segment("40 mm", "30 mm", od_tip="20 mm", taper_steps=bad)
    seg = Segment("40 mm", "30 mm", od_tip="20 mm")
    with pytest.raises(InvalidValueError, match="tapered"):
        seg.section()
    with pytest.raises(InvalidValueError, match="x:"):
        seg.section_at("41 mm")
    assert seg.section_at("0 mm").EI.real == pytest.approx(Segment("1 mm", "30 mm").section().EI.real)
    assert seg.section_at("4 cm").EI.real == pytest.approx(Segment("1 mm", "20 mm").section().EI.real)
    # a tapered od around a uniform bore holds an insert (a shrink-fit nose)
    nose = Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"), od_tip="24 mm", id_tip="12 mm")
    assert nose.is_tapered and nose.insert is not None


def test_assembly_file_round_trip_and_errors():
    from substructure.errors import FileFormatError
    from substructure.io.assembly_toml import dumps_assembly, loads_assembly

    holder = Holder("holder", [
        Segment("65.4 mm", "25.375 mm", material=STEEL0, od_tip="44.45 mm"),
        Segment("20 mm", "63 mm", material=STEEL0),
        Segment("50 mm", "40 mm", "12 mm", STEEL0, insert=Insert("12 mm", CARBIDE0), od_tip="1 in", taper_steps=5),
    ], description="a tapered holder")
    tool = Tool("tool", [Segment("30 mm", "12 mm", material=CARBIDE0, flutes=Flutes(0.8), od_tip="10 mm",
                                 id_tip="2 mm")])
    asm = Assembly("tapers", [holder, tool], [Joint("ht", ["holder.tip", "tool.base"], rigid=True)],
                   frequency=Frequency.from_range("100 Hz", "3000 Hz", "100 Hz"), materials=[STEEL0, CARBIDE0])
    text = dumps_assembly(asm)
    assert 'od_tip = "44.45 mm"' in text and "taper_steps = 5" in text and 'id_tip = "2 mm"' in text
    again = loads_assembly(text)
    assert again == asm
    np.testing.assert_array_equal(again.receptance("tool.tip:y").data, asm.receptance("tool.tip:y").data)
    assert "holder (holder, 3 segments" in asm.describe() and "a tapered holder" in asm.describe()
    bad = text.replace('od_tip = "44.45 mm"', 'od_tip = "44.45 mm", id_tip = "50 mm"')
    with pytest.raises(FileFormatError, match=r"components\[0\]\.segments\[0\]\.id_tip: got 50 mm"):
        loads_assembly(bad, "m.toml")
    with pytest.raises(FileFormatError, match=r"segments\[2\]\.taper_steps: got 0"):
        loads_assembly(text.replace("taper_steps = 5", "taper_steps = 0"), "m.toml")


@pytest.mark.parametrize("decay", [0.0, 30.0])
def test_the_fits_arrays_hold_tapers_as_the_segments_do(decay):
    """The SI arrays of a beam with tapers (flutes, an insert in a uniform bore, a tapered bore, a given step
    count, a point inside a taper) give the segments' receptances, mass and segments back."""
    from substructure.updating.structure import BeamArrays

    segs = [Segment("20 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"), od_tip="34 mm"),
            Segment("25 mm", "30 mm", "8 mm", od_tip="26 mm", id_tip="5 mm"),
            Segment("10 mm", "25 mm"),
            Segment("30 mm", "20 mm", material="carbide", flutes=Flutes(0.8), od_tip="16 mm", taper_steps=3),
            Segment("5 mm", "16 mm", material="carbide", id_tip="2 mm")]
    beam = Holder("h", segs)
    arrays = BeamArrays.from_beam(beam)
    assert arrays.tapered.tolist() == [True, True, False, True, True] and arrays.has_taper
    f = np.linspace(50.0, 8000.0, 120)
    for xs in ([0.0, 0.09], [0.0, 0.01, 0.03, 0.07, 0.09], [0.08, 0.0, 0.062]):  # inside tapers, in any order
        ref = stepped_beam_receptance(segs, xs, f, decay)
        np.testing.assert_allclose(arrays.receptance(xs, f, decay), ref, rtol=1e-11, atol=1e-13 * np.abs(ref).max())
    assert arrays.mass() == pytest.approx(beam.mass(), rel=1e-13)
    back = BeamArrays.from_beam(arrays.as_component(beam))  # tips and step counts kept
    for name in ("length", "od", "id", "od_tip", "id_tip", "steps", "tapered"):
        np.testing.assert_allclose(getattr(back, name), getattr(arrays, name), rtol=1e-15, err_msg=name)
    assert [s.taper_steps for s in arrays.as_component(beam).segments] == [None, None, None, 3, None]
    uniform = BeamArrays.from_beam(Holder("u", [Segment("20 mm", "40 mm"), Segment("20 mm", "30 mm", od_tip="30 mm")]))
    assert uniform.tapered.tolist() == [False, False] and not uniform.has_taper and not uniform.no_tips


def test_the_fits_arrays_refuse_a_taper_the_segment_refuses():
    """A tip diameter set in the SI form that a Segment refuses (a bore as wide as the tip, an insert in a
    tapered bore) is refused with the path, as set_parameters refuses it."""
    from substructure import default_assembly
    from substructure.updating.parameters import apply_path_si, set_parameters
    from substructure.updating.structure import Structure

    model = default_assembly()
    tool = model.component("tool")
    model = model.with_component(attrs.evolve(tool, segments=[*tool.segments[:-1], attrs.evolve(
        tool.segments[-1], id="4 mm")]))
    structure = Structure.from_assembly(model)
    last = len(tool.segments) - 1
    holder_insert = next(i for i, s in enumerate(model.component("holder").segments) if s.insert is not None)
    for path, value in ((f"components.tool.segments.{last}.od_tip", 0.004),
                        (f"components.tool.segments.{last}.id_tip", 0.0125),
                        (f"components.holder.segments.{holder_insert}.id_tip", 0.0135)):
        with pytest.raises(InvalidValueError, match=re.escape(repr(path))):
            apply_path_si(structure, path, value)
        with pytest.raises(InvalidValueError):
            set_parameters(model, {path: value})
    # a material changed by name leaves the tapered parts as the objects do (each part's own material path
    # changes it)
    tapered = set_parameters(model, {f"components.tool.segments.{last}.od_tip": 0.01})
    for path, value in (("materials.carbide.E", 5.5e11), ("components.tool.E", 0.9)):
        ref = set_parameters(tapered, {path: value}).frf(["tool.tip:y"], ["tool.tip:y"], frequency=F_HZ).data
        got = Evaluator(["tool.tip:y"], ["tool.tip:y"], F_HZ)(apply_path_si(Structure.from_assembly(tapered), path,
                                                                              value))
        np.testing.assert_allclose(got, ref, rtol=1e-10)
