"""Measured FRFs with hidden effects, from the independent FE model (test helper).

The "test rig" is a finite-element model (tests/fe_reference.py) of the
built-in spindle, holder and 76 mm tool with its two joints; a hidden effect
(a sensor, flutes, suspension springs, a softer joint, cross-coupling) is
added to it, never to the library's model, and realistic noise is added:
1.5 % on the magnitude, 0.5 degree on the phase, and a noise floor.
"""

from __future__ import annotations

import numpy as np

import fe_reference as fe
from substructure import FRF, Assembly, Frequency, Holder, Insert, Joint, Segment, Spindle, Tool

GRID = Frequency.from_range("10 Hz", "5000 Hz", "2 Hz")
TOOL_LENGTH = 0.076
NOMINAL = {"sh": ([[4.1e7, 0], [0, 3.5e6]], [[400, 0], [0, 7]]),
           "ht": ([[1.43e7, 0], [0, 8e4]], [[12, 0], [0, 4]])}


def nominal_model() -> Assembly:
    """The library's model: the built-in geometry, tool without flutes, joints nominal."""
    spindle = Spindle("spindle", [Segment("120 mm", "70 mm", "40 mm"), Segment("150 mm", "90 mm", "40 mm"),
                                  Segment("60 mm", "110 mm", "40 mm")])
    holder = Holder("holder", [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"),
                               Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"))])
    tool = Tool("tool", [Segment("46 mm", "12 mm", material="carbide"), Segment("30 mm", "12 mm", material="carbide")])
    return Assembly("rig", components=(spindle, holder, tool), joints=(
        Joint("spindle-holder", ("spindle.tip", "holder.base"), k={"yf": "4.1e7 N/m", "tm": "3.5e6 N*m/rad"},
              c={"yf": "400 N*s/m", "tm": "7 N*m*s/rad"}),
        Joint("holder-tool", ("holder.tip", "tool.base"), k={"yf": "1.43e7 N/m", "tm": "8e4 N*m/rad"},
              c={"yf": "12 N*s/m", "tm": "4 N*m*s/rad"}),
    ))


def measure(sensor_kg: float = 0.0, flutes: tuple[float, float] | None = None,
            springs: tuple[float, float, float] | None = None, ht_scale: float = 1.0, ht_cross: float = 0.0,
            seed: int = 0, points=("tool.tip",)) -> list[FRF]:
    """Tool-point (and other) FRFs of the rig with the hidden effects, noisy.

    flutes: (length m, diameter ratio); springs: (k N/m, x1 m, x2 m) on the spindle.
    """
    st = fe.Material(210e9, 0.29, 7850.0, 0.002)
    cb = fe.Material(580e9, 0.22, 14500.0, 0.002)
    m = fe.Model()
    spindle_points = [springs[1], springs[2]] if springs else []
    s = m.add_beam([(0.12, fe.section(0.07, 0.04, st)), (0.15, fe.section(0.09, 0.04, st)),
                    (0.06, fe.section(0.11, 0.04, st))], points=spindle_points)
    h = m.add_beam([(0.016, fe.section(0.063, 0, st)), (0.010, fe.section(0.04, 0, st)),
                    (0.040, fe.section(0.04, 0.012, st, insert=cb))])
    if flutes:
        length, ratio = flutes
        tool_segments = [(TOOL_LENGTH - length, fe.section(0.012, 0, cb)), (length, fe.fluted(0.012, ratio, cb))]
    else:
        tool_segments = [(0.046, fe.section(0.012, 0, cb)), (0.030, fe.section(0.012, 0, cb))]
    offsets = {"tool.tip": 0.0, "tool.tip-20 mm": 0.020}
    t = m.add_beam(tool_segments, points=[TOOL_LENGTH - offsets[p] for p in points])
    m.add_joint((s, 0.33), (h, 0.0), *NOMINAL["sh"])
    k_ht, c_ht = (np.array(x, dtype=float) for x in NOMINAL["ht"])
    k_ht[0, 0] *= ht_scale
    k_ht[0, 1] = k_ht[1, 0] = ht_cross
    m.add_joint((h, 0.066), (t, 0.0), k_ht, c_ht)
    if sensor_kg:
        m.add_mass((t, TOOL_LENGTH), sensor_kg, 0.0)
    if springs:
        m.add_support((s, springs[1]), [[springs[0], 0], [0, 0]])
        m.add_support((s, springs[2]), [[springs[0], 0], [0, 0]])
    rng = np.random.default_rng(seed)
    tip = (t, TOOL_LENGTH, "y")
    out = []
    for p in points:
        h_true = m.receptance(GRID.hz, [(t, TOOL_LENGTH - offsets[p], "y")], [tip])
        n = h_true.shape
        floor = 1e-3 * np.median(np.abs(h_true))
        noisy = (h_true * (1 + 0.015 * rng.standard_normal(n)) * np.exp(1j * np.radians(0.5) * rng.standard_normal(n))
                 + floor * (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2))
        out.append(FRF(GRID, noisy, (f"{p}:y",), ("tool.tip:y",)))
    return out
