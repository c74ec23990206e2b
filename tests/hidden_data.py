"""Measured FRFs with hidden effects, from the independent FE model (test helper).

The "test rig" is a finite-element model (tests/fe_reference.py, which
imports nothing from substructure) of the built-in spindle, holder and 76 mm
tool with its two joints; a hidden effect is added to it, never to the
library's model, and realistic noise is added: 1.5 % on the magnitude,
0.5 degree on the phase, and an additive floor of 1e-3 times the median
magnitude (levels adjustable).

Hidden effects (keyword arguments of :func:`measure`):

* inside the catalogue: a sensor on the tool tip, flutes, suspension
  springs, a softer holder-tool joint, holder-tool cross-coupling, more
  joint damping, a softer spindle-holder rotation stiffness;
* outside it: a longer tool overhang, a clamping nut (mass and rotary
  inertia) on the holder, a necked tool, a machine spindle on bearings with
  the front pair softer, a different tool material, a tool shank clamped
  less deep in the holder.

:func:`nominal_model` is what the library's user believes: the same
geometry and joint values, without the hidden effect.
"""

from __future__ import annotations

import numpy as np

import fe_reference as fe
from substructure import (FRF, Assembly, Flutes, Frequency, Holder, Insert, Joint, Segment, Spindle, Support,
                          Tool)

GRID = Frequency.from_range("10 Hz", "5000 Hz", "2 Hz")
TOOL_LENGTH = 0.076
NOMINAL = {"sh": ([[4.1e7, 0], [0, 3.5e6]], [[400, 0], [0, 7]]),
           "ht": ([[1.43e7, 0], [0, 8e4]], [[12, 0], [0, 4]])}
BEARINGS = (0.03, 0.09, 0.26, 0.315)  # positions along the spindle [m]: rear pair, front pair
BEARING_K = 2.0e8  # N/m each
BEARING_C = 800.0  # N s/m each

STEEL = fe.Material(210e9, 0.29, 7850.0, 0.002)
CARBIDE = fe.Material(580e9, 0.22, 14500.0, 0.002)


def nominal_model(flutes: tuple[float, float] | None = None, bearings: bool = False,
                  tool_length: float = TOOL_LENGTH, taper: float | None = None) -> Assembly:
    """The library's model: the built-in geometry, joints nominal.

    flutes: (length m, diameter ratio) of a fluted tool tip; bearings: the
    spindle held by four bearings (a machine) instead of free-free; taper:
    the tool one conical segment from 12 mm at its base to this diameter [m]
    at its tip (without flutes).
    """
    spindle = Spindle("spindle", [Segment("120 mm", "70 mm", "40 mm"), Segment("150 mm", "90 mm", "40 mm"),
                                  Segment("60 mm", "110 mm", "40 mm")])
    holder = Holder("holder", [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"),
                               Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"))])
    if flutes:
        length, ratio = flutes
        tool = Tool("tool", [Segment(f"{(tool_length - length) * 1e3!r} mm", "12 mm", material="carbide"),
                             Segment(f"{length * 1e3!r} mm", "12 mm", material="carbide", flutes=Flutes(ratio))])
    elif taper:
        tool = Tool("tool", [Segment(f"{tool_length * 1e3!r} mm", "12 mm", material="carbide",
                                     od_tip=f"{taper * 1e3!r} mm")])
    else:
        tool = Tool("tool", [Segment(f"{(tool_length - 0.030) * 1e3!r} mm", "12 mm", material="carbide"),
                             Segment("30 mm", "12 mm", material="carbide")])
    supports = ()
    if bearings:
        supports = tuple(Support(f"spindle@{x * 1e3!r} mm", k={"yf": f"{BEARING_K} N/m"},
                                 c={"yf": f"{BEARING_C} N*s/m"}, name=f"bearing-{i + 1}")
                         for i, x in enumerate(BEARINGS))
    return Assembly("rig", components=(spindle, holder, tool), joints=(
        Joint("spindle-holder", ("spindle.tip", "holder.base"), k={"yf": "4.1e7 N/m", "tm": "3.5e6 N*m/rad"},
              c={"yf": "400 N*s/m", "tm": "7 N*m*s/rad"}),
        Joint("holder-tool", ("holder.tip", "tool.base"), k={"yf": "1.43e7 N/m", "tm": "8e4 N*m/rad"},
              c={"yf": "12 N*s/m", "tm": "4 N*m*s/rad"}),
    ), supports=supports)


def _offset(point: str, length: float) -> tuple[str, float]:
    """``(component, x)`` of a point name of the rig."""
    comp, _, rest = point.partition(".")
    if "@" in point:
        comp, dist = point.split("@")
        return comp, float(dist.replace("mm", "")) / 1e3
    if rest == "tip":
        return comp, length
    if rest.startswith("tip-"):
        return comp, length - float(rest[4:].replace("mm", "")) / 1e3
    if rest == "base":
        return comp, 0.0
    raise ValueError(point)


def measure(sensor_kg: float = 0.0, flutes: tuple[float, float] | None = None,
            springs: tuple[float, float, float] | None = None, ht_scale: float = 1.0, ht_cross: float = 0.0,
            ht_damping: float = 1.0, sh_ktm_scale: float = 1.0, sh_cross: float = 0.0, tool_length: float = TOOL_LENGTH,
            nut: tuple[float, float, float] | None = None, neck: tuple[float, float, float] | None = None,
            bearings: tuple[float, float] | None = None, tool_E: float = 580e9, tool_rho: float = 14500.0,
            tool_nu: float = 0.22, ht_loss: float = 0.0,
            drawbar: bool = False, taper: float | None = None, taper_pieces: int = 8, insert_length: float = 0.040,
            tool_bore: float = 0.0, bearing_moved: tuple[int, float] | None = None,
            spindle_body: tuple[float, float, float] | None = None, sensor_below: float = 0.0, seed: int = 0,
            points=("tool.tip",), excitation: str = "tool.tip", noise: float = 0.015, phase_deg: float = 0.5,
            floor: float = 1e-3, decay: float = 0.0) -> list[FRF]:
    """FRFs of the rig with the hidden effects, noisy (response at each point, hammer at ``excitation``).

    flutes: (length m, diameter ratio) at the tip; springs: (k N/m, x1 m, x2 m) on the spindle;
    nut: (mass kg, rotary inertia kg m^2, x m) on the holder; neck: (start m from the tool's base,
    length m, diameter m); bearings: (rear factor, front factor) on the stiffness of the bearing pairs
    (None: free-free spindle); sh_cross: the spindle-holder cross term k_ym = k_tf [N]; tool_E, tool_rho,
    tool_nu: the tool's material (carbide: 580e9 Pa, 14500 kg/m^3, 0.22; an HSS tool: about 210e9, 8100,
    0.29).  Beyond every candidate of the diagnosis: ht_loss, a hysteretic loss
    factor of the holder-tool joint (``k (1 + i eta)``: damping that does not grow with frequency);
    drawbar, a 20 mm steel rod in the spindle's bore held at two points; taper, the tool's tip
    diameter [m] of a tool tapering linearly from 12 mm over its length (``taper_pieces`` uniform pieces);
    insert_length, how deep the tool's shank sits in the holder [m] (the model: 40 mm; the holder's length
    stays 66 mm, its 40 mm collar longer by as much as the insert is shorter); tool_bore, a coolant bore
    through the whole tool [m] (the shank in the holder too); bearing_moved, (index, position m) of one
    bearing placed elsewhere than the model says (with ``bearings``); spindle_body, (mass kg, rotary inertia
    kg m^2, x m) of a body on the spindle (a pulley, a rotary union at its rear end); sensor_below, how far below the
    tool's tip the sensor of ``sensor_kg`` sits [m] (a sensor cannot sit on the cutting edge); decay, ``1 / tau`` [1/s]
    of an exponential window the rig is measured through (the FRF at the angular frequency ``omega - i / tau``).
    """
    cb = fe.Material(tool_E, tool_nu, tool_rho, 0.002)
    m = fe.Model()
    lengths = {"spindle": 0.33, "holder": 0.066, "tool": tool_length}
    wanted = {"spindle": [], "holder": [], "tool": []}
    for p in list(points) + [excitation]:
        comp, x = _offset(p, lengths[p.split(".")[0].split("@")[0]])
        if x not in wanted[comp]:  # a point measured and hit: one node (two would make an element of no length)
            wanted[comp].append(x)
    places = list(BEARINGS)
    if bearing_moved:
        places[bearing_moved[0]] = bearing_moved[1]
    spindle_points = (wanted["spindle"] + ([spindle_body[2]] if spindle_body else [])
                      + ([springs[1], springs[2]] if springs else []) + (places if bearings else [])
                      + ([0.30] if drawbar else []))
    s = m.add_beam([(0.12, fe.section(0.07, 0.04, STEEL)), (0.15, fe.section(0.09, 0.04, STEEL)),
                    (0.06, fe.section(0.11, 0.04, STEEL))], points=spindle_points)
    h = m.add_beam([(0.016, fe.section(0.063, 0, STEEL)), (0.050 - insert_length, fe.section(0.04, 0, STEEL)),
                    (insert_length, fe.section(0.04, 0.012, STEEL, insert=CARBIDE, insert_id=tool_bore))],
                   points=wanted["holder"] + ([nut[2]] if nut else []))
    fl_len, fl_ratio = flutes if flutes else (0.0, 1.0)
    cuts = [0.0, tool_length - fl_len, tool_length]
    pieces = []
    if neck:
        start, length, diameter = neck
        pieces = [(start, fe.section(0.012, 0, cb)), (length, fe.section(diameter, 0, cb)),
                  (tool_length - fl_len - start - length, fe.section(0.012, 0, cb))]
    elif taper:
        n_t = taper_pieces
        pieces = [(cuts[1] / n_t, fe.section(0.012 + (taper - 0.012) * (i + 0.5) * cuts[1] / n_t / tool_length, 0, cb))
                  for i in range(n_t)]
    else:
        pieces = [(cuts[1], fe.section(0.012, tool_bore, cb))]
    if flutes:
        pieces.append((fl_len, fe.fluted(0.012, fl_ratio, cb)))
    sensor_x = tool_length - sensor_below
    t = m.add_beam([pc for pc in pieces if pc[0] > 0],
                   points=wanted["tool"] + ([sensor_x] if sensor_below and sensor_x not in wanted["tool"] else []))
    k_sh, c_sh = (np.array(x, dtype=float) for x in NOMINAL["sh"])
    k_sh[1, 1] *= sh_ktm_scale
    k_sh[0, 1] = k_sh[1, 0] = sh_cross
    m.add_joint((s, 0.33), (h, 0.0), k_sh, c_sh)
    k_ht, c_ht = (np.array(x, dtype=float) for x in NOMINAL["ht"])
    k_ht[0, 0] *= ht_scale
    k_ht[0, 1] = k_ht[1, 0] = ht_cross
    c_ht *= ht_damping
    m.add_joint((h, 0.066), (t, 0.0), k_ht * (1 + 1j * ht_loss), c_ht)
    if sensor_kg:
        m.add_mass((t, sensor_x), sensor_kg, 0.0)
    if nut:
        m.add_mass((h, nut[2]), nut[0], nut[1])
    if spindle_body:
        m.add_mass((s, spindle_body[2]), spindle_body[0], spindle_body[1])
    if springs:
        m.add_support((s, springs[1]), [[springs[0], 0], [0, 0]])
        m.add_support((s, springs[2]), [[springs[0], 0], [0, 0]])
    if drawbar:
        rod = m.add_beam([(0.30, fe.section(0.020, 0, STEEL))], points=[0.0, 0.30])
        m.add_joint((s, 0.0), (rod, 0.0), [[1e8, 0], [0, 1e4]])
        m.add_joint((s, 0.30), (rod, 0.30), [[1e8, 0], [0, 1e4]])
    if bearings:
        for i, x in enumerate(places):
            factor = bearings[0] if i < 2 else bearings[1]
            m.add_support((s, x), [[BEARING_K * factor, 0], [0, 0]], [[BEARING_C, 0], [0, 0]])
    beams = {"spindle": s, "holder": h, "tool": t}
    rng = np.random.default_rng(seed)
    ex_comp, ex_x = _offset(excitation, lengths[excitation.split(".")[0].split("@")[0]])
    hammer = (beams[ex_comp], ex_x, "y")
    outputs = []
    for p in points:
        comp, x = _offset(p, lengths[p.split(".")[0].split("@")[0]])
        outputs.append((beams[comp], x, "y"))
    h_all = m.receptance(GRID.hz, outputs, [hammer], decay=decay)
    out = []
    for i, p in enumerate(points):
        h_true = h_all[:, i : i + 1, :]
        n = h_true.shape
        level = floor * np.median(np.abs(h_true))
        noisy = (h_true * (1 + noise * rng.standard_normal(n))
                 * np.exp(1j * np.radians(phase_deg) * rng.standard_normal(n))
                 + level * (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2))
        out.append(FRF(GRID, noisy, (f"{p}:y",), (f"{excitation}:y",)))
    return out
