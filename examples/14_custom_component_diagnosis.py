"""
A chuck of your own in the diagnosis
====================================

A new holder or collet type is a class of your own (docs/extending.md):
here a collet chuck whose clamping nut is a rigid body at its tip, the nut's
mass a field of the class.  Such a component takes part in every workflow
through its ``receptance_matrix``; the numbers its class adds are model
parameters like any other, by path (``components.holder.nut_mass``), so the
diagnosis can find that the nut is not what the model says.

Steps: (a) the class (the nut added by structural modification, thesis
eq. 5.3), and its receptances checked against the plain holder with the nut
as a ``Mass`` (the engine's own coupling); (b) its parameters
by path; (c) a tap test of the chuck with a 350 g nut where the model says
150 g, diagnosed; (d) the same with the built-in equivalent (a plain holder
and a ``Mass``): the same answer, with as many model evaluations; (e) the
figure: measured, model as given, model as diagnosed.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# (a) A chuck with its nut
# ------------------------
# The nut is added to the beam's free-free receptances by structural
# modification, as thesis eq. 5.3 adds a mass to an FRF:
# :math:`H - H_{:,t} Z (I + H_{t,t} Z)^{-1} H_{t,:}` with
# :math:`Z = -\omega^2 \mathrm{diag}(m, 0)`, the 2x2 inverse written out so
# that every frequency line is computed at once.
import os
from pathlib import Path

import attrs
import matplotlib.pyplot as plt
import numpy as np
import pint

from substructure import Frequency, Holder, Mass, default_assembly
from substructure.diagnose import diagnose
from substructure.points import parse_point
from substructure.synthetic import simulate
from substructure.units import quantity
from substructure.updating import model_parameters, set_parameters

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


@attrs.frozen
class NutChuck(Holder):
    """A collet chuck whose clamping nut is a rigid body at its tip."""

    nut_mass: pint.Quantity = attrs.field(default="150 g", kw_only=True,
                                          converter=lambda v: quantity(v, "nut_mass", "[mass]"))

    def receptance_matrix(self, refs, frequency_hz):
        f = np.asarray(frequency_hz, dtype=float)
        tip = [i for i, r in enumerate(refs) if self.position(r) >= self.length_m * (1 - 1e-12)]
        points = list(refs) if tip else [*refs, parse_point(f"{self.name}.tip", allow_dof=False)]
        h = super().receptance_matrix(points, f)            # the beam alone, (2q, 2q, n_freq)
        z = -((2 * np.pi * f) ** 2) * self.nut_mass.m_as("kg")
        t = 2 * (tip[0] if tip else len(refs))
        det = (1 + h[t, t] * z)                             # I + H_tt Z, with Z = diag(z, 0)
        p = 2 * len(refs)
        return h[:p, :p] - h[:p, t][:, None] * (z / det) * h[t, :p][None, :]


base = default_assembly()
segments = base.component("holder").segments
chuck = base.with_component(NutChuck("holder", segments, nut_mass="150 g"))
plain = base.attach(Mass("nut", "holder.tip", "150 g"))
grid = Frequency.from_range("20 Hz", "5000 Hz", "4 Hz")
a = chuck.receptance("tool.tip:y", frequency=grid).data
b = plain.receptance("tool.tip:y", frequency=grid).data
print(f"(a) the chuck against a plain holder with a 150 g Mass: largest relative difference "
      f"{np.abs(a - b).max() / np.abs(b).max():.1e}")

# %%
# (b) Its numbers by path
# -----------------------
# Without a ``parameters()`` method of its own, a component that is not a
# plain beam offers the fields its class adds: here the nut's mass, searched
# from a tenth to ten times its value.
nut = next(p for p in model_parameters(chuck) if p.path == "components.holder.nut_mass")
print(f"(b) {nut.path}: {nut.nominal:g} {nut.unit}, bounds {nut.lower:g} to {nut.upper:g} {nut.unit}")
print("    set by path:", set_parameters(chuck, {"components.holder.nut_mass": 0.25}).component("holder").nut_mass)

# %%
# (c) A tap test of a chuck with a heavier nut
# --------------------------------------------
# Simulated with 1.5 % noise at the tool tip and 20 mm behind it.
truth = chuck.with_component(NutChuck("holder", segments, nut_mass="350 g"))
taps = simulate(truth, ["tool.tip", "tool.tip-20 mm"], frequency=grid, noise=0.015, seed=1)
found = diagnose(chuck, taps, progress=False)
print("(c) explained:", found.explained)
for effect in found.effects:
    size = effect.values.get("value")
    print(f"    {effect.where} = {size * 1e3:.1f} g" if size is not None else f"    {effect!r}")

# %%
# (d) The built-in equivalent
# ---------------------------
# The same physics written as a plain holder with a ``Mass`` at its tip.
builtin = diagnose(plain, taps, progress=False)
print("(d) built-in:", [f"{e.where} = {e.values['value'] * 1e3:.1f} g" for e in builtin.effects])
print(f"    model evaluations: chuck {found.search['evaluations']:.0f}, built-in {builtin.search['evaluations']:.0f}")

# %%
# (e) The figure
# --------------
f = grid.hz
measured = next(iter(taps)).frf.data[:, 0, 0]
given = chuck.receptance("tool.tip:y", frequency=grid).data[:, 0, 0]
fixed = found.refined_assembly.receptance("tool.tip:y", frequency=grid).data[:, 0, 0]
fig, ax = plt.subplots(figsize=(7, 4))
ax.semilogy(f, np.abs(measured) * 1e6, ".", ms=3, color="0.3", zorder=3, label="tap test (350 g nut)")
ax.semilogy(f, np.abs(given) * 1e6, label="model as given (150 g)")
ax.semilogy(f, np.abs(fixed) * 1e6, "--", label="model as diagnosed")
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|H| tool tip [um/N]")
ax.set_title("A chuck of one's own: the nut found by the diagnosis")
ax.legend()
fig.tight_layout()
fig.savefig(out / "14_custom_component_diagnosis.png", dpi=110)
print(f"    wrote {out / '14_custom_component_diagnosis.png'}")
