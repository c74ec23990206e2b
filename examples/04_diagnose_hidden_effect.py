"""
Diagnose a model against a tap test: where it fails, what it misses, the fix
============================================================================

A model of the assembly and a tap test of it disagree. Which physical effect
does the model lack? Here the "measured" data are made with the library's own
model plus an effect the model does not have, and 1.5 % noise (fixed seeds),
so that we know the answer the diagnosis should find.

The first hidden effect is the one of thesis chapter 5: an accelerometer's
mass lowers the tool mode of a tap test (thesis Table 5.1), which the
structural modification of eq. 5.1-5.3 predicts.

Steps: (a) compare the model with the tap test; (b) diagnose: every
candidate (every number of the model, bodies and springs at fitted places,
the catalogue of effects) screened, the promising ones fitted, a change added
only when it is statistically significant; (c) add the effect found to the
model and save it as a TOML file; (d) the refinement: watch the error fall;
(e) two hidden effects at once (flutes the model lacks, and a forgotten 2 g
accelerometer); (f) an effect of your own, registered without touching the
library (a heavy clamping nut on the holder); (g) a tip tested a few
millimetres below its edge, as every real tap test is, but recorded as
``tool.tip``; (h) the usual tap test: the accelerometer the record forgot,
sitting 2 mm below the edge where the test was; (i) the sensor and the hammer
at different heights below the edge, with a cross FRF of the same hit.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import attrs

from substructure import Segment, Sensor, Tool, default_assembly, load_assembly, save_assembly
from substructure.diagnose import Effect, Parameter, compare, diagnose, registered
from substructure.measurements import MeasurementSet
from substructure.synthetic import simulate

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def tap_test(rig, hidden_sensors, seed):
    """A 1.5 % noisy tap test of the tool tip of `rig`, whose record forgets the sensors on it."""
    taps = simulate(rig, ["tool.tip"], frequency=rig.frequency, noise=0.015, seed=seed, sensors=hidden_sensors)
    return MeasurementSet(taps.name, tuple(attrs.evolve(m, sensors=()) for m in taps))


def values(effect):
    """An effect's fitted parameters with their SI units."""
    return ", ".join(f"{k} = {v['value']:.4g} {v['unit'] if v['unit'] != 'dimensionless' else ''}".rstrip()
                     for k, v in effect.parameters_json().items())


def show_candidates(diagnosis, n=5):
    print(f"    {'effect':24s} {'where':15s} {'error':>7s}  fitted parameters")
    for c in diagnosis.candidates[:n]:
        print(f"    {c.name:24s} {c.where:15s} {c.error:7.4f}  {values(c.effect)}")


def save_history(diagnosis, name):
    fig = diagnosis.plot_history()
    fig.axes[0].margins(x=0.3, y=0.15)     # room for the labels of the first and last steps
    save(fig, name)


def show_refinement(diagnosis):
    for s in diagnosis.refinement:
        what = "model as given" if s.added is None else f"+ {s.added.name} at {s.added.where}"
        print(f"    step {s.step}: {what:40s} error {s.error:.4f}")
    print(f"    noise floor {diagnosis.noise_floor:.4f}: the final error is "
          f"{diagnosis.refinement[-1].error / diagnosis.noise_floor:.2f} times the floor")


model = default_assembly()    # the model: built-in spindle, holder, 12 mm end mill (76 mm, 30 mm fluted)
rig = model.attach(Sensor("accelerometer", "tool.tip", "2 g"))   # the structure as it was tested
taps = tap_test(rig, ["accelerometer"], seed=4)
measured = taps.measurements[0].frf
print(f"1. Model: {model.name}; tap test: {measured.outputs[0]} / {measured.inputs[0]}, "
      f"{measured.frequency.n} lines, 1.5 % noise, an accelerometer on the tip that the record forgot")

# %%
# (a) Compare: the error, the noise floor, the modes, where the error is
# ----------------------------------------------------------------------
# The error is the RMS over the band of the complex log ratio,
#
# .. math::
#
#    e = \sqrt{\frac{1}{n} \sum_{j=1}^{n} \left| \ln \frac{H_{model}(\omega_j)}{H_{measured}(\omega_j)} \right|^2}
#
# log magnitude and phase (rad) together, every line weighted alike; 1 % off
# on every line gives 0.01. The noise floor is what a perfect model would still
# show, estimated from the scatter of the data about a smoothed version.
print("2. (a) Model against measurement")
H_model = model.frf(list(measured.outputs), list(measured.inputs), measured.frequency)
c = compare(H_model, measured)
print(f"    error {c.error:.4f}, noise floor {c.noise_floor:.4f}, FRAC {c.frac:.4f}; "
      f"as good as the data allow: {c.as_good_as_data}")
for m in c.modes:
    if m.model_hz is not None:   # measured peaks the model has no peak near (noise ripples) are left out
        print(f"    mode measured {m.measured_hz:6.0f} Hz, model {m.model_hz:6.0f} Hz ({m.shift_hz:+5.0f} Hz), "
              f"peak height model/measured {m.amplitude_ratio:.2f}")
print("    most of the error is in: " + ", ".join(f"{lo:.0f}-{hi:.0f} Hz ({s:.0%})" for lo, hi, s in c.bands))
save(c.plot(), "04a_where_it_fails.png")

# %%
# (b) Diagnose: which effect is missing?
# --------------------------------------
# Every candidate is screened cheaply, the promising ones are fitted (by
# maximum likelihood on the complex log ratio, weighted by the noise of each
# line), and the best enters only when its likelihood ratio beats the BIC
# penalty of its parameters. The data are "explained" when the final
# residual is consistent with the noise. A sensor on the tip and a mass at
# the tip describe the same physics (the structural modification of thesis
# eq. 5.1-5.3): both are reported, with the
# measurement that would tell them apart.
d = diagnose(model, taps)
print(f"3. (b) Diagnosis: {len(d.candidates)} candidates (change and place) that improve the model, the best first")
show_candidates(d)
best = d.candidates[0]
print(f"    missing effect: {d.missing_effect} at {d.missing_where}; explained: {d.explained}")
print(f"    why: {best.effect.explanation}")
print(f"    equally possible: {', '.join(d.ambiguous_with) or 'nothing'}"
      + (f"; to tell them apart: {d.suggestion}" if d.suggestion else ""))

# %%
# (c) Add it to the model and save the model file
# -----------------------------------------------
# with_effect returns a normal assembly: here a sensor at the tool tip, which
# the file writes as a [[sensors]] entry with always_on = true (on in every
# test, although the records do not list it), so that the saved model and the
# same tap test agree. The sensor belongs to the test, not to the machine:
# predict cutting with improved.without_sensors().
print("4. (c) The fix, written back")
improved = model.with_effect(best.effect)
path = out / "04c_improved_assembly.toml"
save_assembly(improved, path, overwrite=True)
text = path.read_text()
print("    " + text[text.index("[[sensors]]"):].strip().replace("\n", "\n    "))
again = compare(load_assembly(path).frf(list(measured.outputs), list(measured.inputs), measured.frequency), measured)
print(f"    the saved model against the tap test: error {again.error:.4f} (was {c.error:.4f})")
print(f"    diagnosed again: {diagnose(load_assembly(path), taps).missing_effect} missing")

# %%
# (d) The refinement: watch the error fall
# ----------------------------------------
# diagnose adds the best effect, refits, and looks again until nothing beats
# the noise floor; its history is the table and the figure.
print("5. (d) Refinement")
show_refinement(d)
save_history(d, "04d_error_fall.png")

# %%
# (e) Two hidden effects at once
# ------------------------------
# Now the model's tool has no flutes (a plain 12 mm carbide rod, 76 mm), while
# the real tool is fluted over its last 30 mm (diameter ratio 0.8), and the
# forgotten 2 g accelerometer is on its tip again. The refinement finds both,
# one per step, and refits the first with the second.
print("6. (e) Two hidden effects: flutes the model lacks and a forgotten 2 g accelerometer")
plain = model.with_component(Tool("tool", [Segment("76 mm", "12 mm", material="carbide")]))
taps2 = tap_test(rig, ["accelerometer"], seed=5)        # rig: the fluted tool with the sensor
d2 = diagnose(plain, taps2)
show_candidates(d2, n=3)
show_refinement(d2)
for e in d2.effects:
    print(f"    found {e.name} at {e.where}: {values(e)}")
save_history(d2, "04e_error_fall_two_effects.png")
save(d2.plot_where(), "04e_where_it_fails_two_effects.png")
# After the refinement the residual is white noise at the floor (the shaded
# "error bands" are then only the largest lumps of noise).
save(d2.final[0].plot(), "04e_after_refinement.png")

# %%
# (f) An effect of your own
# -------------------------
# A heavy clamping nut on the holder face is not in the catalogue. An effect
# is a class: its parameters (name, SI unit, bounds, start), where it may act,
# and how it changes an assembly. ``registered`` makes diagnose consider it
# inside a ``with`` block (``register_effect``, as a class decorator, for
# good: then every later diagnosis in the process considers it too).
print("7. (f) A user-defined effect: a clamping nut on the holder face")
nut_rig = model.attach(Sensor("nut", "holder.tip", "150 g"))
taps3 = tap_test(nut_rig, ["nut"], seed=6)
d3 = diagnose(model, taps3, open_world=False)
print(f"    the catalogue only: explained {d3.explained}")
print(f"    | {d3.report[0] if d3.report else ''}")


class ClampingNut(Effect):
    name = "clamping-nut"
    parameters = (Parameter("mass", "kg", 0.01, 1.0, 0.1),)
    explanation = ("a heavy nut on the holder face lowers the modes in which the holder face moves; "
                   "modes in which only the tool bends hardly move")

    @classmethod
    def places(cls, assembly, measured_points):
        return ["holder.tip"] if "holder" in assembly.component_names else []

    def apply(self, assembly):
        return assembly.attach(Sensor("clamping-nut", self.where, f"{self.values['mass']!r} kg"))


with registered(ClampingNut):
    d4 = diagnose(model, taps3)
show_candidates(d4, n=3)
print(f"    missing effect: {d4.missing_effect} at {d4.missing_where}; why: {d4.candidates[0].effect.explanation}")
show_refinement(d4)
save_history(d4, "04f_error_fall_clamping_nut.png")

# %%
# (g) A tip tested below its edge
# -------------------------------
# A sensor cannot sit on the tool's cutting edge, nor a hammer strike it: the
# test was taken 2 mm below the tip (``tool.tip-2 mm``), the record says
# ``tool.tip``.  That moves no mode; a search of the model's changes finds
# nothing that explains it, so the diagnosis then tries the free tip alone,
# towards its base: where it alone reaches the noise, that is the answer, and
# the fix is to name the point where it was.
print("8. (g) A tip tested 2 mm below its edge, recorded as tool.tip")
below = simulate(model, ["tool.tip-2 mm"], frequency=model.frequency, noise=0.015, seed=8)
relabelled = MeasurementSet(below.name, tuple(
    attrs.evolve(m, response="tool.tip:y", excitation="tool.tip:y",
                 frf=m.frf.with_labels(("tool.tip:y",), ("tool.tip:y",))) for m in below))
d5 = diagnose(model, relabelled)
print(f"    explained: {d5.explained}; missing effect: {d5.missing_effect} at {d5.missing_where}")
print(f"    the search explained nothing, the tip alone did: {d5.search.get('tip_alone')}")

# %%
# (h) The usual tap test: a sensor the record forgot, below the edge
# ------------------------------------------------------------------
# What a real test of a model without its accelerometer looks like: the
# 2 g sensor sat 2 mm below the edge, where the hammer struck too, and the
# record says ``tool.tip`` without the sensor.  The sensor lowers the modes,
# which the tip's position alone cannot do, and the search, without the
# tip, ends elsewhere.  So the tip is fitted together with what a test puts
# at that point (a sensor on it, which then sits at the tip's fitted place):
# the two are the answer, the sensor's mass and where the test was.
print("9. (h) A 2 g sensor 2 mm below the edge, forgotten by the record, which says tool.tip")
rig_below = model.attach(Sensor("accelerometer", "tool.tip-2 mm", "2 g"))
below = simulate(rig_below, ["tool.tip-2 mm"], frequency=model.frequency, noise=0.015, seed=9,
                 sensors=["accelerometer"])
relabelled = MeasurementSet(below.name, tuple(
    attrs.evolve(m, response="tool.tip:y", excitation="tool.tip:y", sensors=(),
                 frf=m.frf.with_labels(("tool.tip:y",), ("tool.tip:y",))) for m in below))
d6 = diagnose(model, relabelled)
print(f"    explained: {d6.explained}; the search explained nothing, the tip with the sensor did: "
      f"{d6.search.get('tip_alone')}")
for e in d6.effects:
    print(f"    {e.name} at {e.where}: {values(e)}")

# %%
# (i) The sensor and the hammer at different heights
# ---------------------------------------------------
# The sensor sits on one side of the tool 3 mm below the edge, the hammer
# strikes the other side 1 mm below it; both are recorded as ``tool.tip``,
# with the response on the holder face to the same hit.  On the driving
# point alone the two places are one (reciprocity); the cross FRF depends on
# where the hammer hit alone, so the tip's place and the hammer's
# (``hit-position``) are fitted apart.
print("10. (i) The sensor 3 mm and the hammer 1 mm below the edge, both recorded as tool.tip, and the holder face")
apart = simulate(model, ["tool.tip-3 mm", "holder.tip"], "tool.tip-1 mm", frequency=model.frequency,
                 noise=0.015, seed=10)
named = {"tool.tip-3 mm:y": "tool.tip:y", "holder.tip:y": "holder.tip:y"}
relabelled = MeasurementSet(apart.name, tuple(
    attrs.evolve(m, response=named[m.response], excitation="tool.tip:y",
                 frf=m.frf.with_labels((named[m.response],), ("tool.tip:y",))) for m in apart))
d7 = diagnose(model, relabelled)
print(f"    explained: {d7.explained}")
for e in d7.effects:
    print(f"    {e.name} at {e.where}: {values(e)}")
