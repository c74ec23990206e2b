"""Validation of the independent FE reference model (tests/fe_reference.py)
against closed forms, so that it can be trusted as a second method."""

import math

import numpy as np
import pytest

import fe_reference as fe

S, C = fe.STEEL, fe.CARBIDE
TWO_PI = 2 * math.pi


def stepped_spindle():
    return [(0.10, fe.ring(0.08, 0.04, S)), (0.25, fe.ring(0.10, 0.04, S)),
            (0.05, fe.ring(0.06, 0.03, S)), (0.08, fe.section(0.05, 0.02, S, C)),
            (0.06, fe.fluted(0.02, 0.8, C))]


def one_beam(segments, clamp=False, **kw):
    m = fe.Model(kw.pop("order", fe.ORDER))
    b = m.add_beam(segments, **kw)
    if clamp:
        m.clamp((b, 0.0))
    return m


# ---------------------------------------------------------------- sections
def test_cowper_kappa():
    assert fe.cowper_kappa(0.3) == pytest.approx(0.8864, abs=1e-4)
    assert fe.cowper_kappa(0.3, 1.0) == pytest.approx(2 * 1.3 / (4 + 3 * 0.3))  # thin tube
    assert fe.cowper_kappa(0.3, 0.5) == pytest.approx(12.1875 / 19.65)  # by hand


def test_sections():
    od, id = 0.05, 0.02
    s = fe.ring(od, id, S)
    assert s.A == pytest.approx(math.pi / 4 * (od**2 - id**2))
    assert s.I == pytest.approx(math.pi / 64 * (od**4 - id**4))
    G = S.E / (2 * (1 + S.nu))
    assert s.kGA == pytest.approx(fe.cowper_kappa(S.nu, id / od) * G * s.A)
    # an insert of the same material restores the solid EI, rho*A, rho*I, but
    # kappa*G*A is the sum of the layers, each with its own kappa
    c, solid = fe.section(od, id, S, insert=S), fe.ring(od, 0.0, S)
    for k in ("EI", "rhoA", "rhoI", "A", "I"):
        assert getattr(c, k) == pytest.approx(getattr(solid, k))
    assert c.kGA == pytest.approx(s.kGA + fe.cowper_kappa(S.nu) * G * math.pi / 4 * id**2)
    assert fe.fluted(0.02, 0.8, C) == fe.ring(0.016, 0.0, C)
    lossy = fe.ring(od, id, S._replace(eta=0.01))
    assert lossy.EI == pytest.approx(s.EI * (1 + 0.01j))
    assert lossy.kGA == pytest.approx(s.kGA * (1 + 0.01j))


# ---------------------------------------------------------------- element
@pytest.mark.parametrize("order", [2, 3, 4])
def test_condensed_element_is_exact_static_iie(order):
    """Condensed stiffness = Friedman & Kosmatka IIE closed form (exact statics)."""
    L, s = 0.03, fe.ring(0.04, 0.01, S)
    phi = 12 * s.EI.real / (s.kGA.real * L * L)
    k = np.array([[12, 6 * L, -12, 6 * L], [6 * L, (4 + phi) * L * L, -6 * L, (2 - phi) * L * L],
                  [-12, -6 * L, 12, -6 * L], [6 * L, (2 - phi) * L * L, -6 * L, (4 + phi) * L * L]])
    k *= s.EI.real / ((1 + phi) * L**3)
    K, M = fe.element(L, s, order)
    np.testing.assert_allclose(fe.condensed_stiffness(K).real, k, rtol=1e-10, atol=1e-10 * k.max())
    # rigid-body motions: no strain energy, exact kinetic energy
    n = K.shape[0]
    trans, rot = np.zeros(n), np.zeros(n)
    trans[[0, 2]] = 1.0
    rot[[1, 2, 3]] = 1.0, L, 1.0                      # y = x, theta = 1
    assert np.abs(K @ trans).max() < 1e-9 * np.abs(K).max()
    assert np.abs(K @ rot).max() < 1e-9 * np.abs(K).max()
    assert trans @ M @ trans == pytest.approx(s.rhoA * L)
    assert rot @ M @ rot == pytest.approx(s.rhoA * L**3 / 3 + s.rhoI * L)


# ---------------------------------------------------------------- closed forms
def test_free_free_euler_bernoulli_limit():
    L, d = 1.0, 0.001                                 # L/d = 1000
    s = fe.ring(d, 0.0, S)
    f = one_beam([(L, s)]).natural_frequencies(3)
    bl = np.array([4.73004074, 7.85320462, 10.99560784])
    f_eb = bl**2 * math.sqrt(s.EI.real / (s.rhoA * L**4)) / TWO_PI
    np.testing.assert_allclose(f, f_eb, rtol=1e-4)


@pytest.mark.parametrize("n_elem", [1, None])
def test_cantilever_static_compliance(n_elem):
    L, mat = 0.08, S._replace(eta=0.02)               # stubby (L/d = 2): shear matters
    s = fe.ring(0.04, 0.0, mat)
    m = one_beam([(L, s)], clamp=True, n_elem=n_elem)
    H = m.point_receptance(0.0, (0, L))[0]
    EI, kGA = s.EI, s.kGA
    exact = np.array([[L**3 / (3 * EI) + L / kGA, L**2 / (2 * EI)], [L**2 / (2 * EI), L / EI]])
    np.testing.assert_allclose(H, exact, rtol=1e-10)
    assert (L / kGA) / exact[0, 0] > 0.1              # shear part is significant here
    np.testing.assert_allclose(m.point_receptance(0.0, (0, 0.0), (0, L))[0], 0.0)  # clamped


def test_simply_supported_timoshenko_stubby():
    """Exact SS Timoshenko spectrum: y = sin(kx), theta = cos(kx), k = n pi / L; the
    quadratic (kGA k^2 - rhoA w2)(EI k^2 + kGA - rhoI w2) = (kGA k)^2 for each n,
    plus the pure shear mode (n = 0) w2 = kGA / rhoI."""
    L, s = 0.12, fe.ring(0.05, 0.01, S)               # L/d = 2.4
    EI, kGA, rA, rI = s.EI.real, s.kGA.real, s.rhoA, s.rhoI
    w2 = [kGA / rI]
    for n in range(1, 20):
        k = n * math.pi / L
        w2 += list(np.roots([rA * rI, -(rA * (EI * k * k + kGA) + rI * kGA * k * k), kGA * EI * k**4]))
    exact = np.sort(np.sqrt(np.real(w2))) / TWO_PI
    m = fe.Model()
    m.add_beam([(L, s)])
    for x in (0.0, L):
        m.clamp((0, x), dofs=("y",))
    np.testing.assert_allclose(m.natural_frequencies(6), exact[:6], rtol=1e-6)


def test_rigid_body_receptance_with_sensor_mass():
    """Far below the first mode a free-free beam with a sensor (m_s, J_s) moves as a
    rigid body: H_tip = -(1/m + (L - x_g)^2 / J_g) / w^2 (sign: mass = -1/(m w^2))."""
    L, s, ms, Js = 0.3, fe.ring(0.03, 0.0, S), 0.05, 2e-6
    m = one_beam([(L, s)])
    m.add_mass((0, L), ms, Js)
    mt = s.rhoA * L + ms
    xg = (s.rhoA * L * L / 2 + ms * L) / mt
    Jg = s.rhoA * (L**3 / 3 - L * L * xg + L * xg * xg) + s.rhoI * L + ms * (L - xg) ** 2 + Js
    f = m.natural_frequencies(1)[0] / 1000
    H = m.point_receptance(f, (0, L))[0]
    w2 = (TWO_PI * f) ** 2
    rigid = -np.array([[1 / mt + (L - xg) ** 2 / Jg, (L - xg) / Jg], [(L - xg) / Jg, 1 / Jg]]) / w2
    np.testing.assert_allclose(H, rigid, rtol=1e-4)


# ---------------------------------------------------------------- mesh
@pytest.mark.parametrize("segments,clamp", [
    ([(0.5, fe.ring(0.02, 0.0, S))], False),          # L/d = 25
    ([(0.25, fe.ring(0.05, 0.0, S))], True),          # L/d = 5
    ([(0.1, fe.ring(0.05, 0.0, S))], False),          # L/d = 2
    (stepped_spindle(), False),
    (stepped_spindle(), True),
])
def test_default_mesh_converged(segments, clamp, monkeypatch):
    f = one_beam(segments, clamp).natural_frequencies(5)
    monkeypatch.setattr(fe, "ELEMENTS_PER_BEAM", 2 * fe.ELEMENTS_PER_BEAM)
    monkeypatch.setattr(fe, "MIN_PER_SEGMENT", 2 * fe.MIN_PER_SEGMENT)
    f2 = one_beam(segments, clamp).natural_frequencies(5)
    assert np.all(f2 <= f * (1 + 1e-9))               # Rayleigh-Ritz: from above
    assert np.abs(f2 / f - 1).max() < 1e-5             # brief: < 5e-4
    monkeypatch.setattr(fe, "ELEMENTS_PER_BEAM", 60)
    fine = one_beam(segments, clamp, order=5).natural_frequencies(5)   # converged to ~1e-9
    assert np.abs(f / fine - 1).max() < 1e-5           # brief: < 2e-3 (measured <= 2.5e-6)


def test_points_become_nodes():
    m = fe.Model()
    b = m.add_beam(stepped_spindle(), points=[0.123, 0.31])
    assert m.x[b][m.node(b, 0.123)] == pytest.approx(0.123)
    assert m.node(b, 0.10) > 0                         # segment ends are nodes
    assert m.length(b) == pytest.approx(0.54)
    with pytest.raises(ValueError):
        m.node(b, 0.1234)
    i, x = m.nearest_node(b, 0.1234)
    assert x == pytest.approx(0.123)


# ---------------------------------------------------------------- assembly
def two_beams(k=None, c=0.0, eta=0.0):
    """Spindle-like beam on two bearing supports, a tool-like beam joined at its tip."""
    m = fe.Model()
    a = m.add_beam([(L, s) for L, s in stepped_spindle()[:3]], points=[0.05, 0.3])
    t = m.add_beam([(0.05, fe.section(0.04, 0.016, S._replace(eta=eta), C)),
                    (0.04, fe.fluted(0.016, 0.8, C._replace(eta=eta)))], points=[0.02])
    m.add_support((a, 0.05), [2e8, 1e5], [200.0, 0.0])
    m.add_support((a, 0.3), np.array([[3e8, 1e6], [1e6, 2e5]]), [[300.0, 1.0], [1.0, 0.5]])
    m.add_mass((t, 0.09), 0.02, 1e-6)
    if k is None:
        m.add_rigid((a, m.length(a)), (t, 0.0))
    else:
        m.add_joint((a, m.length(a)), (t, 0.0), k, c)
    return m, a, t


def test_reciprocity():
    k = np.array([[5e7, 2e6], [2e6, 4e5]])
    c = np.array([[30.0, 0.5], [0.5, 0.02]])
    m, a, t = two_beams(k, c, eta=0.01)
    pts = [(a, 0.05, "y"), (a, 0.3, "theta"), (a, 0.4), (t, 0.0, "theta"), (t, 0.02),
           (t, 0.09), (t, 0.09, "theta")]
    H = m.receptance(np.linspace(10.0, 5000.0, 40), pts)
    err = np.abs(H - H.transpose(0, 2, 1)).max(axis=(1, 2)) / np.abs(H).max(axis=(1, 2))
    assert err.max() < 1e-12


def test_joint_matches_coupling_formula():
    """Joint assembly (incl. a non-symmetric k) equals the receptance-coupling
    (Woodbury) result built from the uncoupled model's receptances."""
    k = np.array([[5e7, 2e6], [1e6, 4e5]])            # k_ym != k_tf on purpose
    c = np.array([[30.0, 0.5], [0.2, 0.02]])
    joined, a, t = two_beams(k, c)
    free = two_beams(np.zeros((2, 2)))[0]              # same model, joint of zero stiffness
    f = np.array([50.0, 700.0, 2300.0])
    pa, pb = (a, joined.length(a)), (t, 0.0)
    dofs = [(*p, d) for p in (pa, pb) for d in ("y", "theta")] + [(t, 0.09), (t, 0.09, "theta")]
    H0 = free.receptance(f, dofs)
    U = np.vstack([np.eye(2), -np.eye(2), np.zeros((2, 2))])
    for i, fi in enumerate(f):
        Kj = k + 1j * TWO_PI * fi * c
        H = H0[i]
        Hc = H - H @ U @ Kj @ np.linalg.solve(np.eye(2) + U.T @ H @ U @ Kj, U.T @ H)
        np.testing.assert_allclose(joined.receptance(fi, dofs)[0], Hc, rtol=1e-8,
                                   atol=1e-10 * np.abs(Hc).max())


def test_mass_and_support_match_structural_modification():
    L, s = 0.3, fe.ring(0.03, 0.01, S)
    base = one_beam([(L, s)], points=[0.1])
    mod = one_beam([(L, s)], points=[0.1])
    D_m, kk, cc = np.diag([0.05, 2e-6]), np.array([[1e7, 1e4], [1e4, 3e3]]), np.diag([20.0, 0.1])
    mod.add_mass((0, L), *np.diag(D_m))
    mod.add_support((0, 0.1), kk, cc)
    f = np.array([30.0, 900.0, 4000.0])
    pts = [(0, L), (0, L, "theta"), (0, 0.1), (0, 0.1, "theta"), (0, 0.2)]
    H0, H1 = base.receptance(f, pts), mod.receptance(f, pts)
    for i, fi in enumerate(f):
        w = TWO_PI * fi
        D = np.zeros((5, 5), complex)
        D[:2, :2] = -w * w * D_m
        D[2:4, 2:4] = kk + 1j * w * cc
        Hc = H0[i] - H0[i] @ D @ np.linalg.solve(np.eye(5) + H0[i] @ D, H0[i])
        np.testing.assert_allclose(H1[i], Hc, rtol=1e-8, atol=1e-10 * np.abs(Hc).max())


def test_stiff_joint_tends_to_rigid():
    f = np.array([100.0, 1500.0, 4000.0])
    rigid, a, t = two_beams()
    tip = (t, 0.09)
    Hr = rigid.point_receptance(f, tip)
    errs = []
    for scale in (1e3, 1e5):                           # k_yf = 1e12, 1e14 N/m
        k = scale * np.array([[1e9, 0.0], [0.0, 1e7]])
        Hj = two_beams(k)[0].point_receptance(f, tip)
        errs.append(np.abs(Hj - Hr).max(axis=(1, 2)) / np.abs(Hr).max(axis=(1, 2)))
    assert errs[1].max() < 2e-5                        # 4000 Hz is near a mode: largest
    np.testing.assert_allclose(errs[0] / errs[1], 100.0, rtol=0.05)   # error ~ 1/k


def test_rigid_merge_of_two_halves_equals_one_beam():
    s1, s2 = fe.ring(0.04, 0.0, S), fe.section(0.04, 0.02, S, C)
    one = fe.Model()
    one.add_beam([(0.1, s1), (0.08, s2)], n_elem=6)
    two = fe.Model()
    two.add_beam([(0.1, s1)], n_elem=6)
    two.add_beam([(0.08, s2)], n_elem=6)
    two.add_rigid((0, 0.1), (1, 0.0))
    np.testing.assert_allclose(two.natural_frequencies(5), one.natural_frequencies(5), rtol=1e-10)
    f = [200.0, 3000.0]
    np.testing.assert_allclose(two.point_receptance(f, (1, 0.08), (0, 0.0)),
                               one.point_receptance(f, (0, 0.18), (0, 0.0)), rtol=1e-8)


def test_sparse_and_dense_eigen_paths_agree():
    m = one_beam(stepped_spindle(), n_elem=25)        # > 400 DOFs: shift-invert eigsh
    assert m.ndof > 400
    np.testing.assert_allclose(m.natural_frequencies(5), m.natural_frequencies()[:5], rtol=1e-8)


# --------------------------------------------------------------------------- tapered elements
def taper_compliance(L, tp):
    """Tip compliance of a cantilever (clamped at x = 0) with a varying section, by the
    unit-load method, exact for a statically determinate Timoshenko beam:
    ``int (L-x)^2/EI dx + int 1/kGA dx`` (and the other entries of the 2x2)."""
    from scipy.integrate import quad

    opts = dict(epsabs=0.0, epsrel=1e-13, limit=200)
    def u(x):
        return 1.0 / tp.at(x / L).EI.real

    def s(x):
        return 1.0 / tp.at(x / L).kGA.real

    h = quad(lambda x: (L - x) ** 2 * u(x), 0, L, **opts)[0] + quad(s, 0, L, **opts)[0]
    ln = quad(lambda x: (L - x) * u(x), 0, L, **opts)[0]
    p = quad(u, 0, L, **opts)[0]
    return np.array([[h, ln], [ln, p]])


TAPERS = [
    fe.Taper(0.025375, 0.04445, 0.0, 0.0, S),                 # a 7:24 steep taper, clamped at its small end
    fe.Taper(0.06, 0.02, 0.03, 0.012, S),                     # hollow cone, bore not proportional
    fe.Taper(0.05, 0.03, 0.016, 0.016, S, insert=C, insert_od=0.016),  # shrink-fit nose with a carbide shank
    fe.Taper(0.012, 0.010, 0.0, 0.0, C, ratio=0.8),           # tapered fluted tool
]


@pytest.mark.parametrize("tp", TAPERS, ids=["steep-taper", "hollow", "insert", "fluted"])
def test_tapered_cantilever_static_compliance_converges(tp):
    """The FE model integrates the varying section: its static compliance converges to the
    closed form as the mesh is refined, as h^6 for order-3 elements (measured: x64 per halving)."""
    L = 0.07
    exact = taper_compliance(L, tp)
    errors = []
    for n in (2, 4, 8, 32):
        m = one_beam([(L, tp)], clamp=True, n_elem=n)
        H = m.point_receptance(0.0, (0, L))[0].real
        errors.append(np.abs(H - exact).max() / np.abs(exact).max())
    assert errors[-1] < 1e-8
    assert errors[0] / errors[1] > 20 and errors[1] / errors[2] > 20     # sixth order: 64


def test_taper_with_equal_ends_is_the_uniform_section():
    s = fe.ring(0.04, 0.01, S)
    tp = fe.Taper(0.04, 0.04, 0.01, 0.01, S)
    K1, M1 = fe.element(0.03, s)
    K2, M2 = fe.element(0.03, tp)
    np.testing.assert_allclose(K2, K1, rtol=1e-12, atol=1e-12 * np.abs(K1).max())
    np.testing.assert_allclose(M2, M1, rtol=1e-12, atol=1e-12 * np.abs(M1).max())
    assert tp.mass(0.5) == pytest.approx(s.rhoA * 0.5, rel=1e-14)


def test_taper_mass_is_the_frustum():
    tp = fe.Taper(0.03, 0.05, 0.0, 0.0, S)
    L = 0.1
    r0, r1 = 0.015, 0.025
    assert tp.mass(L) == pytest.approx(S.rho * math.pi * L / 3 * (r0**2 + r0 * r1 + r1**2), rel=1e-13)
