"""
Diagnose beyond the catalogue: an effect nobody listed, an honest verdict, your own effect
==========================================================================================

The catalogue of effects (a sensor, a joint's stiffness or damping, flutes,
suspension springs, ...) does not know every way a model can be wrong. Here
the tap-test rig carries a heavy clamping nut on the holder that the model
lacks. We diagnose it three ways:

(a) with the catalogue only: nothing in it explains the data, and the
    diagnosis says so first, with where the error lives and what kind of
    change has that signature;
(b) in the open world: every number of the model and bodies, springs and
    section changes at fitted positions are candidates; an ``added-mass`` on
    the holder (a rigid body coupled to the structure, the structural
    modification of thesis eq. 5.1-5.3, at a fitted place) explains the data,
    with its mass, rotary inertia and position and their standard deviations;
(c) with an effect of our own, a clamping nut whose inertia follows from
    its mass and size (one parameter instead of three), passed to
    ``diagnose`` without registering it: the error falls to the noise floor
    and the nut is written into the model file.

The decisions are statistical (docs/diagnose.md, "How the decisions are
made"): a change enters when its likelihood ratio beats the BIC penalty, and
the data are "explained" only when the residual is consistent with the noise
the data themselves show. The "measured" data are made with the library's
model plus the nut and 1.5 % noise (fixed seed), so that we know the answer.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup: the model, and a tap test of the rig with a nut the model lacks
# ----------------------------------------------------------------------
import os
from pathlib import Path

from substructure import Mass, default_assembly, save_assembly
from substructure.diagnose import Effect, Parameter, diagnose
from substructure.synthetic import simulate

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def show(found):
    """A found change with its fitted values and standard deviations."""
    values = ", ".join(f"{k} = {p['value']:.4g} +- {p['std']:.2g} {p['unit']}".replace(" dimensionless", "")
                       for k, p in found.parameters_json().items())
    return f"{found.name} at {found.where}: {values}"


model = default_assembly()        # the built-in spindle, holder and 12 mm end mill
# the rig: a 150 g nut (outer diameter 50 mm, 14 mm long) near the holder face
nut_inertia = 0.150 * (3 * (0.025**2 + 0.020**2) + 0.014**2) / 12   # a thick ring about a diameter, kg m^2
rig = model.attach(Mass("nut", "holder@55 mm", "150 g", f"{nut_inertia!r} kg*m^2"))
taps = simulate(rig, ["tool.tip", "tool.tip-20 mm"], frequency=model.frequency, noise=0.015, seed=9,
                name="tap test of the tool")
print(f"1. Tap test: {len(taps)} FRFs at the tool, 1.5 % noise; the rig has a nut the model does not")

# %%
# (a) The catalogue only: an honest "unexplained"
# -----------------------------------------------
# Only the effects of the catalogue are tried (``open_world=False``). None
# of them is a body on the holder, so the best combination still leaves a
# residual larger than the noise: the verdict says so first, then where the
# remaining error lives (frequency bands and FRFs), the best partial
# explanation (labelled partial), and the signature of the mode shifts.
print("2. (a) The catalogue only")
closed = diagnose(model, taps, open_world=False)
print(f"    explained: {closed.explained}")
for line in closed.report:
    print(f"    | {line}")

# %%
# (b) The open world: every parameter, and elements at fitted positions
# ---------------------------------------------------------------------
# Now every number of the model (by its path in the assembly file), bodies,
# springs to the ground and section changes at fitted positions are
# candidates. Each step screens them all cheaply, fits the promising ones
# with what was added before, and adds the best when its likelihood ratio is
# significant; the search stops when nothing is.
print("3. (b) The open world")
opened = diagnose(model, taps)
print(f"    explained: {opened.explained}; error {opened.baseline_error:.4f} -> {opened.final_error:.4f} "
      f"(noise floor {opened.noise_floor:.4f})")
for found in opened.effects:
    print(f"    {show(found)}")
print(f"    (the rig: 150 g, {nut_inertia:.3g} kg m^2 at 55 mm)")
save(opened.plot_where(), "09b_where_it_fails.png")

# %%
# (c) An effect of your own: a clamping nut of known size
# -------------------------------------------------------
# We know the nut is a ring of 50 mm outer and 40 mm inner diameter, 14 mm
# long, sitting somewhere on the holder: its rotary inertia follows from its
# mass. An effect with that knowledge has two parameters (mass, position)
# instead of the added mass's three, so the statistics prefer it when it
# explains the data as well. It is passed to ``diagnose`` directly, without
# registering it (registrations would be global; ``registered(...)`` limits
# them to a ``with`` block).


class ClampingNut(Effect):
    name = "clamping-nut"
    parameters = (Parameter("mass", "kg", 0.01, 1.0, 0.1),
                  Parameter("position", "m", 0.0, 0.066, 0.05, log=False))
    explanation = ("a clamping nut (a ring 50/40 mm, 14 mm long) on the holder lowers the modes in which the "
                   "holder moves, in proportion to the square of their motion where it sits")

    @classmethod
    def places(cls, assembly, measured_points):
        return ["holder"] if "holder" in assembly.component_names else []

    def apply(self, assembly):
        m = self.values["mass"]
        inertia = m * (3 * (0.025**2 + 0.020**2) + 0.014**2) / 12
        return assembly.attach(Mass("clamping-nut", f"holder@{self.values['position']!r} m", f"{m!r} kg",
                                    f"{inertia!r} kg*m^2"))


print("4. (c) With an effect of our own")
mine = diagnose(model, taps, effects=["sensor-mass", "joint-stiffness", ClampingNut])
print(f"    explained: {mine.explained}")
for step in mine.refinement:
    what = "model as given" if step.added is None else show(step.added)
    print(f"    step {step.step}: error {step.error:.4f}  {what}")
if mine.ambiguous:
    print("    equally possible: " + "; ".join(f"{a.name} at {a.where}" for a, _ in mine.ambiguous))
save(mine.plot_history(), "09c_error_fall.png")
path = out / "09c_model_with_the_nut.toml"
save_assembly(mine.refined_assembly, path, overwrite=True)
text = path.read_text()
print("    " + text[text.index("[[masses]]"):].strip().replace("\n", "\n    "))
