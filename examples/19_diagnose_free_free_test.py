"""
A free-free test on bands: where the bands hang, from the rigid-body modes
==========================================================================

A "free-free" tap test hangs the structure on soft bands, and the model of
it is free: no spring holds it. The bands do: below its first flexible
mode the structure moves as one rigid body, and on the bands that motion
has two low modes, a bounce and a pitch, where the model has only a mass
line. The thesis's substructuring then compares a free model with a
structure that is not quite free.

The diagnosis has ``support-springs`` in its catalogue for this, two
springs at fitted places on the heaviest component. Their two modes are
lightly damped, and their minimum is far narrower than any grid of
stiffnesses and places can step through. So the search starts them from
the body itself (docs/diagnose.md, "The search"):

1. the body's mass, rotary inertia about its centre and the centre's place
   come from the model's receptances at the component's two ends, well
   below its first flexible mode, where ``-omega^2 H_ij = 1/m + d_i d_j / J``
   (``d`` a point's distance from the centre);
2. the springs that put the body's two modes at the measured resonances
   the model lacks follow from a two-degree-of-freedom eigenproblem.

Here the bands are the answer we know: the library's model plus two bands,
with 1.5 % noise (fixed seed).

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup: the model, and a tap test of it hung on two bands
# --------------------------------------------------------
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import Support, default_assembly
from substructure.diagnose import diagnose
from substructure.diagnose.modes import rigid_body
from substructure.synthetic import simulate
from substructure.updating import Structure

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)

model = default_assembly()          # the built-in spindle, holder and 12 mm end mill, free
K_BAND, FROM_BASE, FROM_TIP = 4e5, 0.040, 0.070   # N/m per band; m from the spindle's base and from its tip
length = model.component("spindle").length_m
rig = (model.support(Support(f"spindle@{FROM_BASE * 1e3:g} mm", k={"yf": f"{K_BAND:g} N/m"}, name="band-1"))
       .support(Support(f"spindle@{(length - FROM_TIP) * 1e3:g} mm", k={"yf": f"{K_BAND:g} N/m"}, name="band-2")))
taps = simulate(rig, ["tool.tip", "holder.tip"], frequency=model.frequency, noise=0.015, seed=4,
                name="free-free tap test")
print(f"1. Tap test: {len(taps)} FRFs, the hammer at the tool's tip, 1.5 % noise; the model is free")

# %%
# The rigid body, read off the model
# ----------------------------------
# Its mass, rotary inertia and centre, then the two modes it would have on
# the bands (the 2-DOF eigenproblem, written out here): they are the
# resonances the measurement has and the model lacks.
mass, inertia, centre = rigid_body(Structure.from_assembly(model), "spindle", length, 2.0)
print(f"2. The rigid body: {mass:.3f} kg, {inertia * 1e3:.1f} g m^2 about its centre, {centre * 1e3:.1f} mm "
      "from the spindle's base")
d1, d2 = FROM_BASE - centre, length - FROM_TIP - centre
stiffness = K_BAND * np.array([[2.0, d1 + d2], [d1 + d2, d1 ** 2 + d2 ** 2]])
modes_hz = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(np.diag([mass, inertia]), stiffness)).real)) / (2 * np.pi)
print(f"    on the bands its modes would lie at {modes_hz[0]:.1f} and {modes_hz[1]:.1f} Hz")
tip = taps.measurements[0].frf
f, h = tip.frequency.hz, np.abs(tip.data[:, 0, 0])
low = f < 300
tops = np.flatnonzero(low[1:-1] & (h[1:-1] > h[:-2]) & (h[1:-1] > h[2:])) + 1
tops = sorted(f[tops[np.argsort(h[tops])[-2:]]])  # the two highest (the noise ripples elsewhere)
print(f"    the two highest measured peaks below 300 Hz: {tops[0]:.0f} and {tops[1]:.0f} Hz (lines 2 Hz apart)")

# %%
# The diagnosis places the bands
# ------------------------------
d = diagnose(model, taps)
print(f"3. Diagnosis: explained = {d.explained}, error {d.final_error:.3g} (noise floor {d.noise_floor:.3g})")
for found in d.effects:
    values = ", ".join(f"{k} = {p['value']:.4g} +- {p['std']:.2g} {p['unit']}".replace(" dimensionless", "")
                       for k, p in found.parameters_json().items())
    print(f"    {found.name} at {found.where}: {values}")
print(f"    the bands were {K_BAND:.3g} N/m, inset {FROM_BASE / length:.4f} from the base and "
      f"{FROM_TIP / length:.4f} from the tip")

# %%
# The low end of the FRF: the mass line of the model, the bands' modes
# --------------------------------------------------------------------
refined = simulate(d.refined_assembly, ["tool.tip"], frequency=model.frequency).measurements[0].frf
nominal = simulate(model, ["tool.tip"], frequency=model.frequency).measurements[0].frf
fig, ax = plt.subplots(figsize=(7, 4))
ax.semilogy(f[low], h[low], ".", ms=3, color="0.4", label="measured (on bands)")
ax.semilogy(f[low], np.abs(nominal.data[low, 0, 0]), label="model as given (free)")
ax.semilogy(f[low], np.abs(refined.data[low, 0, 0]), "--", label="model with the bands found")
for x in modes_hz:
    ax.axvline(x, color="0.7", lw=0.8)
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|H| tool tip [m/N]")
ax.set_title("A free-free test: the bands' two rigid-body modes (grey lines)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "19_free_free_bands.png", dpi=110)
print(f"    wrote {out / '19_free_free_bands.png'}")
