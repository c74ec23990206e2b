"""
Standard holders and tapered segments
=====================================

A machinist rarely has the drawing of a tool holder, but knows its family:
"HSK-A63 shrink-fit, 12 mm, 80 mm gauge length" or "BT40 ER32 collet
chuck".  The library's holder catalogue turns such a name into an
approximate stepped-and-tapered beam, which can be corrected where the real
holder differs.  Conical parts (the steep taper of the shank, the 4.5 degree
nose of a shrink-fit chuck) are tapered segments, computed by a fourth-order
stepping whose error is bounded.

Steps: (a) a catalogue holder with an override; (b) how the taper's
stepping converges, against the closed-form compliance of a tapered
cantilever; (c) two holder families on the same spindle and tool: their
tool point FRFs compared; (d) the other views of an FRF (Nyquist, real and
imaginary parts); (e) a catalogue holder in an assembly file.

The tool point FRF is that of thesis section 2.1 (eq. 2.1-2.2): the holder
(with the tool shank inside its bore, coupled rigidly) is joined to the
spindle at the spindle face, and the tool's overhang to the holder's nose,
each by a complex joint stiffness (eq. 2.5).

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import quad

from substructure import Assembly, Frequency, Holder, Segment, Tool, default_assembly
from substructure.beams import segment_transfer_matrix
from substructure.holders import catalog_names, design
from substructure.io.assembly_toml import dumps_assembly, loads_assembly
from substructure.tapers import TAPER_ERROR_BOUND

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


# %%
# (a) A catalogue holder, with one value overridden
# -------------------------------------------------
# The catalogue combines an interface (BT40, CAT40, HSK-A63) with a
# clamping system (ER16...ER40 collet chucks with their nut, shrink-fit,
# hydraulic).  The holder runs from the gauge line (for HSK: the flange
# contact face), where it meets the spindle face, to its nose; the tool
# shank fills the bore over the clamped length.  Say our shrink-fit chuck
# has a 25 mm nose instead of the catalogue's 24 mm: override it by name.
print(f"(a) {len(catalog_names())} catalogue holders, e.g. {', '.join(catalog_names()[:4])}, ...")
shrink = design("HSK-A63 shrink-fit", bore="12 mm", gauge_length="80 mm", nose_diameter="25 mm")
holder_sf = shrink.holder()
print(f"    {shrink.entry}: {len(holder_sf.segments)} segments, {holder_sf.length:~P}, "
      f"{holder_sf.mass():.3f} kg (with the 12 mm carbide shank {shrink.parameters['clamp_length']:~P} deep)")
for seg in holder_sf.segments:
    tip = f" -> {seg.od_tip:~P}" if seg.is_tapered else ""
    bore = f", bore {seg.id:~P} with {seg.insert.material.name} shank" if seg.insert is not None else ""
    print(f"      {seg.length.m_as('mm'):6.2f} mm long, od {seg.od:~P}{tip}{bore}")
print("    its description says what it is and that it is approximate:")
print("      " + holder_sf.description[:160] + " ...")

# %%
# (b) The taper's stepping converges at fourth order
# --------------------------------------------------
# A tapered segment is cut into n steps; each step is two uniform half-steps
# of the commutator-free Magnus scheme (docs/beams.md), so the exact
# uniform-segment kernels serve it.  The reference is independent: the static
# tip compliance of a cantilever clamped at the taper's small end, by the
# unit-load method, int (L-x)^2/EI dx + int 1/kGA dx, integrated by scipy.
cone = Segment("65.4 mm", "25.375 mm", od_tip="44.45 mm")   # BT40 shank: 7:24 taper
length = cone.length_m


def cantilever_compliance(seg, steps):
    """Tip compliance (m/N) of the stepped model, clamped at the base, from its transfer matrices."""
    pieces = seg.piece_sections(steps)
    t = np.eye(4, dtype=complex)
    for sec in pieces:
        t = segment_transfer_matrix(sec, seg.length_m / len(pieces), np.array([0.0]))[..., 0] @ t
    return abs((t[:2, 2:] @ np.linalg.inv(t[2:, 2:]))[0, 0].real)


def closed_form(seg):
    sec = seg.section_at
    # the material's loss factor makes EI complex: the real part of the compliance is compared
    bending = quad(lambda x: (length - x) ** 2 * (1 / sec(f"{x} m").EI).real, 0, length, epsrel=1e-13)[0]
    shear = quad(lambda x: (1 / sec(f"{x} m").kGA).real, 0, length, epsrel=1e-13)[0]
    return bending + shear


exact = closed_form(cone)
steps = np.array([1, 2, 4, 8, 16, 32])
errors = np.array([abs(cantilever_compliance(cone, n) / exact - 1) for n in steps])
default = cone.taper_step_count()
print(f"(b) BT40 taper, tip compliance {exact * 1e9:.4f} nm/N (closed form); relative error of the steps:")
for n, e in zip(steps, errors):
    print(f"      n = {n:2d}: {e:.1e}" + ("   (ratio to the previous: "
          f"{errors[list(steps).index(n) - 1] / e:.1f})" if n > 1 else ""))
print(f"    default steps {default}: error {abs(cantilever_compliance(cone, default) / exact - 1):.1e} "
      f"(bound {TAPER_ERROR_BOUND:.0e})")
fig, ax = plt.subplots(figsize=(6.0, 4.2), layout="constrained")
ax.loglog(steps, errors, "o-", label="stepped model against the closed form")
ax.loglog(steps, errors[2] * (steps / steps[2]) ** -4.0, "k:", label="slope -4 (fourth order)")
ax.axhline(TAPER_ERROR_BOUND, color="tab:red", lw=0.8, label="documented bound")
ax.axvline(default, color="0.5", lw=0.8, ls="--", label=f"default steps ({default})")
ax.set_xlabel("steps n")
ax.set_ylabel("relative error of the tip compliance")
ax.set_title("A 7:24 steep taper stepped by the fourth-order Magnus scheme")
ax.legend(fontsize="small")
ax.grid(True, which="both", alpha=0.3)
save(fig, "10a_taper_convergence.png")

# %%
# (c) Two holder families on the same spindle and tool
# ----------------------------------------------------
# The spindle and joints of the built-in assembly (thesis Table 4.1/4.2
# values, identified for a collet holder: assumed here for both), a 12 mm
# carbide end mill sticking out 50 mm.  Only the holder changes: an
# HSK-A63 shrink-fit chuck and a BT40 ER32 collet chuck, both 80 mm.
base = default_assembly()
grid = Frequency.from_range("10 Hz", "5000 Hz", "2 Hz")
tool = Tool.end_mill("12 mm", "50 mm", "25 mm")
holders = {
    "HSK-A63 shrink-fit": holder_sf,
    "BT40 ER32": Holder.from_catalog("BT40 ER32", bore="12 mm", gauge_length="80 mm"),
}
frfs = {}
for name, holder in holders.items():
    asm = Assembly(name, [base.component("spindle"), holder, tool], base.joints)
    frfs[name] = asm.receptance("tool.tip:y", frequency=grid)
    h = frfs[name].data[:, 0, 0]
    band = grid.hz > 300   # above the free-free spindle's rigid-body line
    print(f"(c) {name}: holder {holder.mass():.2f} kg; tool point peaks "
          f"{', '.join(f'{f:.0f}' for f in frfs[name].peaks() if f > 300)} Hz; "
          f"largest |H| {np.abs(h[band]).max() * 1e6:.3f} um/N; most negative real part "
          f"{h[band].real.min() * 1e6:.3f} um/N")
names = list(frfs)
fig = frfs[names[0]].plot(label=names[0], title="Tool point FRF of a 12 mm end mill, 50 mm out, "
                          "in two catalogue holders on the same free-free spindle")
frfs[names[1]].plot(ax=fig, label=names[1], ls="--")
save(fig, "10b_two_holder_families.png")

# %%
# (d) The same FRF in other views
# -------------------------------
# The Nyquist plane shows each mode as a circle (the most negative real part
# sets the chatter limit in the zero-order stability theory); the real and
# imaginary parts show where each mode is.  The free-free spindle's
# rigid-body line is drawn but left out of the autoscaling, so the modes fill
# the axes; the unit can be m/N instead of um/N.
save(frfs[names[0]].plot(kind="nyquist", title=f"{names[0]}: Nyquist plane"), "10c_nyquist.png")
save(frfs[names[0]].plot(kind="real-imag", unit="m/N", title=f"{names[0]}: real and imaginary parts"),
     "10d_real_imag.png")

# %%
# (e) In an assembly file
# -----------------------
# A component with `catalog = "..."` and the parameters as keys is built from
# the catalogue; saving writes its explicit segments and its description, so
# the file does not depend on later revisions of the catalogue.
text = dumps_assembly(Assembly("catalogue example", [base.component("spindle"), holder_sf, tool], base.joints,
                               frequency=grid))
toml = """name = "shrink-fit"
[[components]]
name = "holder"
type = "holder"
catalog = "HSK-A63 shrink-fit"
bore = "12 mm"
gauge_length = "80 mm"
nose_diameter = "25 mm"
"""
from_file = loads_assembly(toml).component("holder")
print(f"(e) the catalogue key gives the same holder: {from_file == holder_sf}; saved, it is "
      f"{sum(line.startswith('  {') for line in text.splitlines())} segment lines with od_tip keys "
      f"and a description, and reads back equal: {loads_assembly(text).component('holder') == holder_sf}")
