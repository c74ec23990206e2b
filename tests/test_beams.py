"""Exact Timoshenko beams against closed forms and invariants."""

import math
import typing

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from substructure import Flutes, Insert, InvalidValueError, Material, Segment, Tool, shear_coefficient
from substructure.beams import (
    Section,
    segment_dynamic_stiffness,
    segment_transfer_matrix,
    stepped_beam_receptance,
    stepped_beam_receptance_batch,
)

STEEL_NO_LOSS = Material("steel0", E="210 GPa", nu=0.29, rho="7850 kg/m^3")


def natural_frequencies(segments, n_modes, f_max, lines=20000):
    """Free-free natural frequencies: the poles of the (undamped) tip point receptance.

    At a pole the real receptance jumps from +inf to -inf; 1/H is continuous
    there and crosses zero, which brentq pins down to ~1e-12.
    """
    length = sum(s.length_m for s in segments)

    def inv_h(f):
        with np.errstate(all="ignore"):
            h = stepped_beam_receptance(segments, [length], np.array([f]))[0, 0, 0].real
        return 0.0 if not np.isfinite(h) else 1.0 / h  # exactly on the pole

    f = np.linspace(f_max / lines, f_max, lines)
    h = stepped_beam_receptance(segments, [length], f)[0, 0].real
    found = []
    for i in np.nonzero(np.sign(h[:-1]) != np.sign(h[1:]))[0]:
        if h[i] > 0 > h[i + 1]:  # through a pole (an antiresonance goes - to +)
            found.append(brentq(inv_h, f[i], f[i + 1], xtol=1e-12, rtol=1e-14))
    return np.array(found[:n_modes])


def test_cowper_shear_coefficient():
    assert shear_coefficient(0.29, 0.0) == pytest.approx(6 * 1.29 / (7 + 6 * 0.29))
    assert shear_coefficient(0.29) == pytest.approx(0.886, abs=5e-4)  # conventions.md
    # A thin ring tends to Cowper's thin-walled value 2(1+nu)/(4+3nu).
    assert shear_coefficient(0.3, 0.9999) == pytest.approx(2 * 1.3 / (4 + 0.9), rel=1e-6)


def test_free_free_slender_beam_matches_euler_bernoulli():
    """beta*L = 4.7300, 7.8532, 10.9956 for a free-free uniform beam (< 0.1 %)."""
    d, length = 0.005, 1.0  # L/d = 200: shear and rotary inertia negligible
    seg = [Segment(f"{length} m", f"{d} m", material=STEEL_NO_LOSS)]
    sec = seg[0].section()
    beta_l = np.array([4.730040745, 7.853204624, 10.99560784])
    expected = beta_l**2 / (2 * np.pi * length**2) * math.sqrt(sec.EI.real / sec.rhoA)
    found = natural_frequencies(seg, 3, 1.2 * expected[-1])
    np.testing.assert_allclose(found, expected, rtol=1e-3)
    # and Timoshenko lowers them, by less than 0.1 % here
    assert np.all(found < expected)


def test_cantilever_static_tip_compliance():
    """Clamped base, load at the tip: L^3/(3EI) + L/(kappa G A), from the exact stiffness at omega = 0."""
    for od, idd, length in [(0.012, 0.0, 0.06), (0.04, 0.02, 0.03), (0.1, 0.0, 0.05)]:
        seg = Segment(f"{length} m", f"{od} m", f"{idd} m", material=STEEL_NO_LOSS)
        sec = seg.section()
        _, _, _, d22 = segment_dynamic_stiffness(sec, length, np.array([0.0]))
        compliance = np.linalg.inv(d22[..., 0])
        expected = length**3 / (3 * sec.EI.real) + length / sec.kGA.real
        assert compliance[0, 0].real == pytest.approx(expected, rel=1e-12)
        assert compliance[1, 1].real == pytest.approx(length / sec.EI.real, rel=1e-12)


def test_rigid_body_limit_of_free_free_receptance():
    """At low frequency a free-free uniform beam is a rigid body (thesis eq. 2.8-2.11)."""
    length = 0.08
    seg = [Segment(f"{length} m", "0.012 m", material=STEEL_NO_LOSS)]
    sec = seg[0].section()
    mass = sec.rhoA * length
    f = np.array([1e-3])
    w2 = (2 * np.pi * f[0]) ** 2
    y = stepped_beam_receptance(seg, [length], f)[..., 0]
    rot = 1 + 12 * sec.rhoI / (sec.rhoA * length**2)  # rotary inertia adds to the body's inertia
    # End receptances of a rigid bar with mass m and inertia J = m L^2/12 + rhoI L about its centre
    j_c = mass * length**2 / 12 * rot
    h = -(1 / mass + (length / 2) ** 2 / j_c) / w2
    n = -(length / 2) / j_c / w2
    p = -1 / j_c / w2
    np.testing.assert_allclose(y.real, [[h, n], [n, p]], rtol=1e-6)


def test_transfer_matrix_is_exact_against_matrix_exponential():
    """T = exp(A L) from the closed form equals scipy's expm of the first-order system."""
    from scipy.linalg import expm

    mat = Material("m", E="200 GPa", nu=0.3, rho="7800 kg/m^3", loss_factor=0.01)
    sec = Segment("50 mm", "30 mm", "10 mm", material=mat).section()
    for f in [0.0, 1e-3, 50.0, 3000.0, 40000.0]:
        w2 = (2 * np.pi * f) ** 2
        a = np.array(
            [
                [0, 1, 1 / sec.kGA, 0],
                [0, 0, 0, 1 / sec.EI],
                [-w2 * sec.rhoA, 0, 0, 0],
                [0, -w2 * sec.rhoI, -1, 0],
            ],
            dtype=complex,
        )
        for length in [0.001, 0.05, 0.3]:
            t = segment_transfer_matrix(sec, length, np.array([2 * np.pi * f]))[..., 0]
            ref = expm(a * length)
            np.testing.assert_allclose(t, ref, rtol=1e-10, atol=1e-13 * np.abs(ref).max())


def test_segment_dynamic_stiffness_is_symmetric():
    sec = Segment("40 mm", "20 mm", material="carbide").section()
    d11, d12, d21, d22 = segment_dynamic_stiffness(sec, 0.04, 2 * np.pi * np.linspace(10, 8000, 50))
    scale = np.abs(d11).max()
    assert np.abs(d12 - d21.transpose(1, 0, 2)).max() < 1e-13 * scale
    assert np.abs(d11 - d11.transpose(1, 0, 2)).max() < 1e-13 * scale


segment_strategy = st.builds(
    lambda length, od, ratio, mat: Segment(f"{length} mm", f"{od} mm", f"{od * ratio} mm", material=mat),
    st.floats(5, 150),
    st.floats(6, 120),
    st.sampled_from([0.0, 0.3, 0.6]),
    st.sampled_from(["steel", "carbide", "aluminium"]),
)


@settings(max_examples=25, deadline=None)
@given(st.lists(segment_strategy, min_size=1, max_size=4), st.floats(0.05, 0.95))
def test_reciprocity_and_splitting_invariants(segments, frac):
    """Y is symmetric to machine precision; an extra point does not change the others.

    Slender pieces too (k L up to ~40 at 6 kHz): long chains are evaluated in
    rigidly joined pieces of k L <= 8, see docs/beams.md.
    """
    length = sum(s.length_m for s in segments)
    f = np.linspace(10, 6000, 97)
    y3 = stepped_beam_receptance(segments, [length, 0.0, frac * length], f)
    assert np.abs(y3 - y3.transpose(1, 0, 2)).max() <= 1e-10 * np.abs(y3).max()
    y2 = stepped_beam_receptance(segments, [length, 0.0], f)
    # (two different cuts of the same chain; near resonances the cut costs a few digits)
    assert np.abs(y3[:4, :4] - y2).max() <= 1e-9 * np.abs(y2).max()


def test_batch_equals_single_configurations():
    f = np.linspace(20, 5000, 300)
    configs = [
        [Segment("20 mm", "12 mm", material="carbide"),
         Segment(f"{L} mm", "12 mm", material="carbide", flutes=Flutes(0.8))]
        for L in (10, 33, 70)
    ] + [  # a segment that is the same in every configuration is computed once
        [Segment(f"{L} mm", "12 mm", material="carbide"),
         Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8))]
        for L in (10, 33, 300)
    ]
    batch = np.concatenate([stepped_beam_receptance_batch(configs[:3], ["tip", "base"], f),
                            stepped_beam_receptance_batch(configs[3:], ["tip", "base"], f)], axis=-1)
    for i, c in enumerate(configs):
        single = stepped_beam_receptance(c, [sum(s.length_m for s in c), 0.0], f)
        got = batch[..., i * 300 : (i + 1) * 300]
        # per entry, relative to its largest value over the band (the 300 mm tool is
        # evaluated in pieces, cut at other places in the batch than alone)
        scale = np.abs(single).max(axis=-1, keepdims=True)
        assert np.all(np.abs(got - single) <= 1e-11 * scale)


def test_si_beams_of_one_layout_together_are_each_the_beam_alone():
    """stepped_beam_receptances_si: several beams of the same segment lengths at the same nodes in one kernel
    call (the intervals alike in all computed once) give each beam's numbers alone, to the bit; a beam whose
    chain must be cut is left to the single call (None)."""
    from substructure import default_assembly
    from substructure.beams import stepped_beam_receptances_si
    from substructure.updating.structure import Structure

    structure = Structure.from_assembly(default_assembly())
    rng = np.random.default_rng(3)
    for name, lines, decay in (("tool", 250, 0.0), ("holder", 1000, 0.0), ("spindle", 333, 40.0), ("tool", 3, 7.0)):
        beam = structure.beams[name]
        f = np.linspace(20.0, 5000.0, lines)
        length = beam.total_length
        xs = [length, 0.0, 0.37 * length, 0.5 * length]
        n = beam.od.size
        variants = [beam.evolve(od=beam.od * np.where(np.arange(n) == k % n, 1.0 + 0.05 * rng.random(), 1.0),
                                material=beam.material * np.where(np.arange(n)[:, None] == (k + 1) % n,
                                                                  [1.0 + 0.1 * rng.random(), 1, 1, 1], 1.0))
                    for k in range(7)] + [beam]
        together = stepped_beam_receptances_si([v.sections() for v in variants], beam.length, xs, f, decay)
        assert together is not None and len(together) == len(variants)
        for v, y in zip(variants, together):
            assert np.array_equal(y, v.receptance(xs, f, decay))
    long_bar = beam.evolve(length=beam.length * 40.0)
    f = np.linspace(20.0, 20000.0, 50)
    assert stepped_beam_receptances_si([long_bar.sections()] * 2, long_bar.length, [0.0], f) is None
    # a section that is not a number raises alone: left to the single call, not coupled as NaN
    not_a_number = beam.evolve(od=beam.od * np.where(np.arange(beam.od.size) == 0, np.nan, 1.0))
    assert stepped_beam_receptances_si([beam.sections(), not_a_number.sections()], beam.length, [0.0], f) is None


def _si_tool():
    from substructure import default_assembly
    from substructure.updating.structure import Structure

    beam = Structure.from_assembly(default_assembly()).beams["tool"]
    return beam.sections(), beam.length


@pytest.mark.parametrize("case, message", [
    ("fewer lengths", "ei: got 2 values for 1 segments"),
    ("negative length", "lengths: got [-0.046, -0.03]"),
    ("position past the tip", "positions: got [0.0, 0.5]; expected at least one position in m from the base, "
                              "each within the beam (0 to 0.076 m)"),
    ("position before the base", "positions: got [-0.001, 0.076]"),
    ("no position", "positions: got []"),
    ("a line at 0 Hz", "frequency_hz: expected lines above 0 Hz"),
    ("a line not a number", "frequency_hz: expected lines above 0 Hz"),
    ("negative EI", "segment 1: got EI = (-"),
    ("massless segment", "segment 0: got EI = (590"),
    ("EI not a number", "segment 0: got EI = (nan+nanj)"),
])
def test_si_beam_receptances_refuse_what_a_beam_cannot_be(case, message):
    """The SI fast paths took these and gave numbers: positions off the beam (extrapolated), infinite values at
    0 Hz or for a massless segment, receptances of a negative stiffness or length; arrays of another number of
    segments than lengths were cut silently to the lengths. Each is now refused naming the argument, in the single
    call and in the batch (where a section that is not a number is still left to the single call, None)."""
    from substructure.beams import stepped_beam_receptance_si, stepped_beam_receptances_si

    (ei, kga, rhoa, rhoi), length = _si_tool()
    f, xs = np.linspace(20.0, 5000.0, 20), [0.0, 0.076]
    if case == "fewer lengths":
        length = length[:1]
    elif case == "negative length":
        length = -length
    elif case == "position past the tip":
        xs = [0.0, 0.5]
    elif case == "position before the base":
        xs = [-0.001, 0.076]
    elif case == "no position":
        xs = []
    elif case == "a line at 0 Hz":
        f = np.array([0.0, 100.0])
    elif case == "a line not a number":
        f = np.array([np.nan, 100.0])
    elif case == "negative EI":
        ei = ei * np.array([1.0, -1.0])
    elif case == "massless segment":
        rhoa = rhoa * np.array([0.0, 1.0])
    elif case == "EI not a number":
        ei = ei * np.array([np.nan, 1.0])
    with pytest.raises(InvalidValueError) as single:
        stepped_beam_receptance_si(ei, kga, rhoa, rhoi, length, xs, f)
    assert message in str(single.value)
    good = tuple(np.array(v) for v in _si_tool()[0])
    if case == "EI not a number":
        assert stepped_beam_receptances_si([good, (ei, kga, rhoa, rhoi)], length, xs, f) is None
        return
    with pytest.raises(InvalidValueError) as batch:
        stepped_beam_receptances_si([good, (ei, kga, rhoa, rhoi)] if case != "fewer lengths" else [good], length,
                                    xs, f)
    assert message in str(batch.value)


def test_si_beams_together_refuse_no_beams_and_beams_of_other_segment_counts():
    from substructure.beams import stepped_beam_receptances_si

    (ei, kga, rhoa, rhoi), length = _si_tool()
    f = np.linspace(20.0, 5000.0, 20)
    with pytest.raises(InvalidValueError, match="sections: got none"):
        stepped_beam_receptances_si([], length, [0.0], f)
    with pytest.raises(InvalidValueError, match="expected \\(ei, kga, rhoa, rhoi\\) of 2 values each"):
        stepped_beam_receptances_si([(ei, kga, rhoa, rhoi), (ei[:1], kga[:1], rhoa[:1], rhoi[:1])], length, [0.0], f)


def test_composite_and_fluted_sections():
    steel, carbide = Material.from_catalog("steel"), Material.from_catalog("carbide")
    seg = Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"))
    sec = seg.section()
    ring = Section.ring(0.04, 0.012, steel)
    core = Section.ring(0.012, 0.0, carbide)
    assert sec.EI == pytest.approx(ring.EI + core.EI)
    assert sec.kGA == pytest.approx(ring.kGA + core.kGA)
    assert sec.rhoA == pytest.approx(math.pi / 4 * ((0.04**2 - 0.012**2) * 7850 + 0.012**2 * 14500))
    fl = Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8)).section()
    assert fl.EI == pytest.approx(Section.ring(0.0096, 0.0, carbide).EI)
    assert fl.rhoA == pytest.approx(Section.ring(0.0096, 0.0, carbide).rhoA)


def test_segment_validation_errors():
    with pytest.raises(InvalidValueError, match="insert: the segment is solid"):
        Segment("10 mm", "40 mm", insert=Insert("12 mm", "carbide"))
    with pytest.raises(InvalidValueError, match="insert.od: got 14 mm, larger than the bore id 12 mm"):
        Segment("10 mm", "40 mm", "12 mm", insert=Insert("14 mm", "carbide"))
    with pytest.raises(InvalidValueError, match=r"flutes.diameter_ratio: got 1.2; expected a ratio in \(0, 1\]"):
        Flutes(1.2)
    with pytest.raises(InvalidValueError, match="material"):
        Segment("10 mm", "12 mm", material=3)
    with pytest.raises(InvalidValueError, match="segments"):
        Tool("tool", [])


def test_end_mill_constructor():
    tool = Tool.end_mill("12 mm", "60 mm", "30 mm")
    assert [s.length.m_as("mm") for s in tool.segments] == [30, 30]
    assert tool.segments[1].flutes == Flutes(0.8)
    assert tool.length.m_as("mm") == pytest.approx(60)
    with pytest.raises(InvalidValueError, match="flute_length"):
        Tool.end_mill("12 mm", "60 mm", "70 mm")


@pytest.mark.parametrize("field, kw", [("od", dict(od="1e300 mm")), ("od", dict(od="1e-300 mm")),
                                       ("od", dict(length="5 m", od="1e-12 m")), ("length", dict(length="2 km")),
                                       ("id", dict(id="1e-9 mm")), ("id", dict(od="40 mm", id="1e-7 m")),
                                       ("od_tip", dict(od_tip="1e9 mm"))])
def test_segment_dimensions_outside_the_beam_models_range_are_refused_by_name(field, kw):
    # these once overflowed, gave NaN or hung in the chain kernel; the file reader refused them
    # already, the Python API now does the same at the constructor
    args = {"length": "10 mm", "od": "10 mm", **kw}
    with pytest.raises(InvalidValueError, match=rf"^{field}: .*1 um to 1 km"):
        Segment(**args)


def test_segments_at_the_ends_of_the_range_give_finite_reciprocal_receptances():
    for length, od in (("1 um", "1 um"), ("1 km", "1 m"), ("5 m", "1 mm")):
        seg = Segment(length, od)
        h = stepped_beam_receptance([seg], [0.0, seg.length_m], np.array([10.0, 1e3, 2e4]))
        assert np.all(np.isfinite(h))
        assert np.allclose(h, np.swapaxes(h, 0, 1), rtol=1e-6, atol=0)   # Maxwell reciprocity
    with pytest.raises(InvalidValueError, match="taper_steps: .*at most 10,000"):
        Segment("10 mm", "10 mm", od_tip="5 mm", taper_steps=10**9)


def test_segment_annotations_resolve():
    # every annotation names something importable (typing.get_type_hints once raised NameError: Material)
    hints = typing.get_type_hints(Segment)
    assert hints["material"] is Material and hints["insert"] == Insert | None
