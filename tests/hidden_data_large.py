"""A second test rig, larger than hidden_data.py's, from the independent FE model (test helper).

A machine spindle of 420 mm on four bearings, a holder 100 mm long with a 50 mm bore, and a 20 mm carbide end
mill of 160 mm (110 mm out of the holder) whose last 40 mm are fluted at 0.8: other sizes, joints and modes
(about 430, 870, 1140, 1500 and 1950 Hz below 4 kHz) than the rig the diagnosis was built on, so that its
tests see a neighbour nobody tuned it to.  :func:`model` is what the library's user believes;
:func:`measure` gives the FE rig's exact FRFs with a hidden effect (no noise: the tests put on the noise they
need).  tests/fe_reference.py imports nothing from substructure.
"""

from __future__ import annotations

import numpy as np

import fe_reference as fe
from substructure import FRF, Assembly, Flutes, Frequency, Holder, Insert, Joint, Segment, Spindle, Support, Tool

GRID = Frequency.from_range("10 Hz", "4000 Hz", "2 Hz")
STEEL = fe.Material(210e9, 0.29, 7850.0, 0.002)
CARBIDE = fe.Material(580e9, 0.22, 14500.0, 0.002)
SPINDLE = ((0.15, 0.08, 0.03), (0.20, 0.10, 0.03), (0.07, 0.13, 0.03))  # (length, od, id) [m], base to tip
BEARINGS = (0.04, 0.10, 0.32, 0.39)  # [m] along the spindle: rear pair, front pair
BEARING_K, BEARING_C = 3.0e8, 1000.0  # N/m, N s/m each
HOLDER = ((0.020, 0.063, 0.0), (0.030, 0.045, 0.0), (0.050, 0.040, 0.020))  # the last holds the tool's shank
TOOL_OD, TOOL_LENGTH, FLUTES = 0.020, 0.160, (0.040, 0.8)  # flutes: (length m, diameter ratio)
K_SH, C_SH = (6e7, 5e6), (500.0, 10.0)  # spindle-holder: (yf N/m, tm N m/rad), (yf N s/m, tm N m s/rad)
K_HT, C_HT = (3e7, 2e5), (30.0, 8.0)  # holder-tool


def _mm(x: float) -> str:
    return f"{x * 1e3!r} mm"


def _joint(name: str, between: tuple[str, str], k, c) -> Joint:
    return Joint(name, between, k={"yf": f"{k[0]} N/m", "tm": f"{k[1]} N*m/rad"},
                 c={"yf": f"{c[0]} N*s/m", "tm": f"{c[1]} N*m*s/rad"})


def model() -> Assembly:
    """The library's model of the rig, as drawn: joints and bearings nominal, flutes 40 mm at 0.8."""
    spindle = Spindle("spindle", [Segment(_mm(length), _mm(od), _mm(bore)) for length, od, bore in SPINDLE])
    *plain, (length, od, bore) = HOLDER
    holder = Holder("holder", [Segment(_mm(a), _mm(b), _mm(c)) for a, b, c in plain]
                    + [Segment(_mm(length), _mm(od), _mm(bore), insert=Insert(_mm(bore), "carbide"))])
    fluted, ratio = FLUTES
    tool = Tool("tool", [Segment(_mm(TOOL_LENGTH - fluted), _mm(TOOL_OD), material="carbide"),
                         Segment(_mm(fluted), _mm(TOOL_OD), material="carbide", flutes=Flutes(ratio))])
    supports = tuple(Support(f"spindle@{_mm(x)}", k={"yf": f"{BEARING_K} N/m"}, c={"yf": f"{BEARING_C} N*s/m"},
                             name=f"bearing-{i + 1}") for i, x in enumerate(BEARINGS))
    return Assembly("large-rig", components=(spindle, holder, tool), supports=supports, joints=(
        _joint("spindle-holder", ("spindle.tip", "holder.base"), K_SH, C_SH),
        _joint("holder-tool", ("holder.tip", "tool.base"), K_HT, C_HT)))


def measure(points=("tool.tip",), sensor_kg: float = 0.0, flutes: tuple[float, float] = FLUTES,
            nut: tuple[float, float, float] | None = None, ht_scale: float = 1.0,
            tool_E: float = 580e9, tool_rho: float = 14500.0, tool_nu: float = 0.22,
            bearings: tuple[float, float] = (1.0, 1.0), shank_taper: float | None = None,
            below: float = 0.0, hammer_below: float | None = None) -> list[FRF]:
    """Exact FRFs of the rig with hidden effects (response at each point, the hammer at the tool's tip).

    points: ``tool.tip``, ``tool.tip-X mm`` or ``holder.tip``; flutes: the tool's real fluted tip (length m,
    diameter ratio); nut: (mass kg, rotary inertia kg m^2, x m) on the holder; ht_scale: the holder-tool
    joint's k_yf times this; tool_E, tool_rho, tool_nu: the tool's material; bearings: (rear, front) factors on
    the stiffness of the bearing pairs; shank_taper: the tool's plain length tapering linearly (16 uniform
    pieces) as if from 20 mm at its base to this diameter [m] at its tip, its fluted tip left at 20 mm (not the
    library's tapered tool, which tapers the flutes too); below: the test taken this far below the tip [m] (the
    hammer, the sensor of ``sensor_kg`` and the point labelled ``tool.tip``: a sensor cannot sit on the edge);
    hammer_below: the hammer this far below the tip instead [m] (the sensor and the hammer at different heights).
    """
    hammer_x = TOOL_LENGTH - (below if hammer_below is None else hammer_below)
    m = fe.Model()
    lengths = {"holder": sum(h[0] for h in HOLDER), "tool": TOOL_LENGTH}

    def place(point: str) -> tuple[str, float]:
        comp, _, rest = point.partition(".")
        back = float(rest[4:].replace("mm", "")) / 1e3 if rest.startswith("tip-") else 0.0
        back = below if point == "tool.tip" else back
        return comp, lengths[comp] - back

    wanted: dict[str, list[float]] = {"holder": [], "tool": []}
    for p in list(points):
        comp, x = place(p)
        if x not in wanted[comp]:
            wanted[comp].append(x)
    if hammer_x not in wanted["tool"]:  # the hammer's place too
        wanted["tool"].append(hammer_x)
    s = m.add_beam([(length, fe.section(od, bore, STEEL)) for length, od, bore in SPINDLE], points=list(BEARINGS))
    *plain, (length, od, bore) = HOLDER
    h = m.add_beam([(a, fe.section(b, c, STEEL)) for a, b, c in plain]
                   + [(length, fe.section(od, bore, STEEL, insert=CARBIDE))],
                   points=wanted["holder"] + ([nut[2]] if nut else []))
    material = fe.Material(tool_E, tool_nu, tool_rho, 0.002)
    fluted, ratio = flutes
    plain_length = TOOL_LENGTH - fluted
    if shank_taper is None:
        shank = [(plain_length, fe.section(TOOL_OD, 0.0, material))]
    else:
        shank = [(plain_length / 16, fe.section(TOOL_OD + (shank_taper - TOOL_OD) * (k + 0.5) / 16 * plain_length
                                                / TOOL_LENGTH, 0.0, material)) for k in range(16)]
    t = m.add_beam(shank + [(fluted, fe.fluted(TOOL_OD, ratio, material))], points=wanted["tool"])
    m.add_joint((s, sum(x[0] for x in SPINDLE)), (h, 0.0), np.diag(K_SH), np.diag(C_SH))
    m.add_joint((h, lengths["holder"]), (t, 0.0), np.diag([K_HT[0] * ht_scale, K_HT[1]]), np.diag(C_HT))
    for i, x in enumerate(BEARINGS):
        factor = bearings[0] if i < 2 else bearings[1]
        m.add_support((s, x), [[BEARING_K * factor, 0], [0, 0]], [[BEARING_C, 0], [0, 0]])
    if sensor_kg:
        m.add_mass((t, TOOL_LENGTH - below), sensor_kg, 0.0)
    if nut:
        m.add_mass((h, nut[2]), nut[0], nut[1])
    beams = {"holder": h, "tool": t}
    outputs = [(beams[place(p)[0]], place(p)[1], "y") for p in points]
    receptance = m.receptance(GRID.hz, outputs, [(t, hammer_x, "y")])
    return [FRF(GRID, receptance[:, i:i + 1, :], (f"{p}:y",), ("tool.tip:y",)) for i, p in enumerate(points)]
