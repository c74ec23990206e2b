"""
Diagnose what a user thinks of as one thing: another material, a tapered tool's tip, within a budget
=====================================================================================================

A model can be wrong in ways a user names in one phrase: "the tool is HSS,
not carbide", "the cone ends at 9 mm, not 10". The diagnosis has candidates
that move several numbers as that one thing, so that the statistics compare
one explanation against others that need several changes:

(a) an end mill modelled as carbide is high-speed steel: the candidate
    ``components.tool.material`` fits ``E``, ``rho`` and ``nu`` of the
    tool's own material together, starting from every material the library
    knows, within the range of engineering materials; it is found in one
    step where single numbers would need several;
(b) a conical tool whose tip diameter is off: a tapered segment's ``od_tip``
    is a candidate like a length (fits set it on the assembly);
(c) the search has a budget of work (``budget``, model evaluations of all
    lines, counted so that the answer is the same on every machine): what
    it did and whether the budget cut it are in ``result.search`` and the
    JSON.

The decisions are statistical (docs/diagnose.md, "How the decisions are
made"): a change enters when its likelihood ratio beats the BIC penalty
(``chi^2 / s^2 + p ln n``), an explanation of several changes is compared
with the best single and pair explanations fitted from their own starts, and
the data are "explained" only when the residual is consistent with the
noise and no explanation that changes other parts is as good. The
"measured" data are made with the library's model plus the hidden change
and 1.5 % noise (fixed seeds), so that we know the answer. The beams are
the exact Timoshenko segments of the thesis (eq. 2.1-2.9), coupled by
receptance coupling (eq. 3.1-3.6).

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import attrs

from substructure import Material, Segment, Tool, default_assembly
from substructure.diagnose import diagnose
from substructure.synthetic import simulate

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def show(found):
    """A found change with its fitted values, standard deviations and the model's values."""
    parts = []
    for name, p in found.parameters_json().items():
        text = f"{name} = {p['value']:.4g} +- {p['std']:.2g} {p['unit']}".replace(" dimensionless", "")
        if "nominal" in p:
            text += f" (model {p['nominal']:.4g})"
        parts.append(text)
    return f"{found.name} at {found.where}: " + ", ".join(parts)


model = default_assembly()        # the built-in spindle, holder and 12 mm carbide end mill

# %%
# (a) The tool is HSS, the model says carbide
# -------------------------------------------
# The rig's tool has the same geometry but is made of high-speed steel
# (E = 210 GPa, rho = 8100 kg/m^3, nu = 0.29). A stiffer-only or a
# lighter-only explanation leaves a misfit; the material as one candidate
# fits all three constants together.
hss = Material("HSS", E="210 GPa", nu=0.29, rho="8100 kg/m^3", loss_factor=0.002)
tool = model.component("tool")
rig = model.with_component(attrs.evolve(tool, segments=[attrs.evolve(s, material=hss) for s in tool.segments]))
taps = simulate(rig, ["tool.tip"], frequency=model.frequency, noise=0.015, seed=11, name="tap test, HSS tool")
print("1. (a) An HSS tool modelled as carbide")
found = diagnose(model, taps, progress=False)
print(f"    explained: {found.explained}; error {found.baseline_error:.4f} -> {found.final_error:.4f} "
      f"(noise floor {found.noise_floor:.4f})")
for change in found.effects:
    print(f"    {show(change)}")
save(found.plot_history(), "11a_error_fall.png")

# %%
# (b) A conical tool whose tip is thinner than the drawing
# --------------------------------------------------------
# The model's tool is one conical segment from 12 mm to 10 mm; the rig's
# ends at 9 mm. The tapered segment's diameters are candidates like lengths
# (``components.tool.segments.0.od_tip``).
cone = model.with_component(Tool("tool", [Segment("76 mm", "12 mm", material="carbide", od_tip="10 mm")]))
cone_rig = model.with_component(Tool("tool", [Segment("76 mm", "12 mm", material="carbide", od_tip="9 mm")]))
cone_taps = simulate(cone_rig, ["tool.tip"], frequency=model.frequency, noise=0.015, seed=12,
                     name="tap test, conical tool")
print("2. (b) A conical tool, tip 9 mm, the model says 10 mm")
tip = diagnose(cone, cone_taps)
print(f"    explained: {tip.explained}")
for change in tip.effects:
    print(f"    {show(change)}")

# %%
# (c) The budget
# --------------
# Every diagnosis runs within a budget of work (3000 model evaluations of
# all lines by default). Screening every candidate is cheap; only the best
# few get full fits. What the search did is reported; here it finished well
# within its budget.
print("3. (c) What the searches did")
for label, result in (("HSS tool", found), ("conical tool", tip)):
    s = result.search
    print(f"    {label}: {s['candidates']} candidates, {s['steps_screened']} step(s) screened, "
          f"{s['full_fits']} full fits, {s['evaluations']:.0f} evaluations of a budget of {s['budget']:g}, "
          f"cut: {s['cut']}")
