"""
From tap test to spindle speed
==============================

The machinist's question: "at what spindle speed and depth do I run this
tool?"  This script answers it the way ``substructure lobes`` does, step by
step: the tool point FRF (predicted by the model, or tapped), the part of it
that stability may use (no rigid-body or suspension lines), the work
material by name, the machine's limits, and a recommended speed and depth
with a stated margin, its runners-up and a plot.

Steps: (a) the structure and its rigid-body band; (b) the same from tap-test
data; (c) the cut from the workpiece table; (d) the machine; (e) the
recommendation and its margin, checked on a finer grid; (f) robust to an
uncertain joint; (g) the plot; (h) all of it in one HTML report; (i) the
cutting speed and feed in the shop's units, against the usual range; (j) a
catalogue holder whose joints were never identified: its priors and the
stability band.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
import tempfile
from pathlib import Path

import numpy as np

from substructure import FRF, Frequency, Holder, Sensor, default_assembly
from substructure.joint_priors import joint_provenances, with_joint_priors
from substructure.report import report
from substructure.stability import (MachineLimits, MillingCut, assembly_structure, check_cutting, cutting_data,
                                    flexible_band, lobes_band, recommend, spindle_speeds, workpiece, xy_frf, zoa)
from substructure.stability.plotting import plot_recommendation, wrap_title
from substructure.sweep import sweep
from substructure.units import Q_

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)

# %%
# (a) The structure: the tool point FRF, without rigid-body lines
# ---------------------------------------------------------------
# The built-in assembly is free-free, like the thesis's test rig.  Below its
# first antiresonance its tool point receptance is the mass line
# -1/(m omega^2) of the whole body (thesis eq. 2.2 couples free-free
# components; nothing holds them).  A spindle in its bearings has no such
# motion: lobes from those lines would put chatter at 20-120 Hz and give a
# fraction of the real limit.  ``assembly_structure`` finds the band and says
# why; the tool carries its tooth count and diameter.
assembly = default_assembly()
tool = assembly.component("tool")
frf, band = assembly_structure(assembly, "tool.tip:y")
print("1. Structure")
print(f"    {band.reason}")
print(f"    lines used: {band.lo_hz:g} to {band.hi_hz:g} Hz; tool: {tool.teeth} teeth, D = {tool.cutting_diameter:~P}, "
      f"flutes {tool.flute_length:~P}")
# On bearings (supports as modelled) nothing is left out: the low modes are
# the spindle's on its bearings, real at the machine.
on_bearings = (assembly.support("spindle@30 mm", k={"yf": "1e8 N/m"}, c={"yf": "200 N*s/m"})
               .support("spindle@250 mm", k={"yf": "1e8 N/m"}, c={"yf": "200 N*s/m"}))
print(f"    on bearings: {assembly_structure(on_bearings, 'tool.tip:y')[1].reason}")

# %%
# (b) The same from tap-test data
# -------------------------------
# A tap test with a 2 g accelerometer on the tool tip, saved as CSV
# (frequency_hz,real,imag) and read back: the data rule finds the mass line
# at the lowest lines (phase within 30 degrees of -180) and the antiresonance
# above it, without the model.
tapped = assembly.attach(Sensor("accelerometer", "tool.tip", "2 g")).receptance("tool.tip:y",
                                                                                frequency=assembly.frequency)
with tempfile.TemporaryDirectory() as folder:
    path = Path(folder) / "tap_test.csv"
    tapped.to_csv(path)
    measured = FRF.from_csv(path)
found = flexible_band(measured)
print("2. Tap-test data")
print(f"    {found.reason}")

# %%
# (c) The cut, with the work material by name
# -------------------------------------------
# Aluminium 7075-T6 from the project's table (linear edge-force model with
# its published source), 3 mm radial depth, 0.05 mm feed per tooth.
material = workpiece("Aluminum 7075-T6")  # the shop's spelling finds the table's aluminium-7075
cut = MillingCut.for_workpiece(tool.teeth, tool.cutting_diameter, material, radial_depth="3 mm",
                               feed_per_tooth="0.05 mm", milling="down")
print("3. Cut")
print(f"    {material.describe()}")
print(f"    {cut.describe()}")

# %%
# (d) The machine
# ---------------
# A 20,000 rpm spindle with constant torque up to its base speed and
# constant power above (a curve of speed and power); the tool's flute
# length caps the depth.
limits = MachineLimits(max_speed="20000 rpm", power=[("0 rpm", "0 kW"), ("6000 rpm", "11 kW"), ("20000 rpm", "11 kW")],
                       max_depth=tool.flute_length)
print("4. Machine: 20,000 rpm, 11 kW above 6,000 rpm (constant torque below), depth at most the flute length")

# %%
# (e) The recommendation and its margin
# -------------------------------------
# Every speed is judged with its window n (1 +- 3 %): the lobes move when
# the natural frequency moves (the 2 g sensor alone moves the tool mode),
# so the limit used is the lowest over the window; the depth is 80 % of it
# (a 20 % margin).  Among the speeds, the largest removal rate wins.
speeds = spindle_speeds("3000 rpm", "24000 rpm", "20 rpm")
lobes = zoa(xy_frf(frf), cut, speeds, band=band, label="predicted tool point FRF")
best = recommend(lobes, cut, limits, margin=0.2, speed_tolerance=0.03)
print("5. Recommendation")
for line in best.describe():
    print(f"    {line}")
for k, other in enumerate(best.runners_up, 1):
    print(f"    runner-up {k}: {other.describe()[0]}")
tip_n, tip_a = lobes.best_speeds(1)[0]
print(f"    (the tip of the highest lobe, {tip_a * 1e3:.2f} mm at {tip_n:.0f} rpm, has no margin: 3 % slower "
      f"the limit is {lobes.limit_on([tip_n * 0.97])[0][0] * 1e3:.2f} mm)")
# Checked on a finer grid, computed anew: the depth is below 80 % of the
# limit at every speed of the window.
lo, hi = best.window_rpm
fine = zoa(xy_frf(frf), cut, Q_(np.linspace(lo, hi, 2001), "rpm"), band=band)
print(f"    check on 2001 speeds in {lo:.0f}..{hi:.0f} rpm: depth / limit at most "
      f"{np.max(best.depth_m / fine.depth_limit_m):.3f}")

# %%
# (f) Robust to an uncertain joint
# --------------------------------
# The holder-tool stiffness known to +-15 %: lobes for three values, and a
# recommendation that keeps its margin for every one of them.
joint = assembly.joint("holder-tool")
k_nominal = joint.k.as_dict()["yf"]
variants = [assembly.with_joint(joint.with_parameters(k={"yf": Q_(k_nominal) * f})) for f in (0.85, 1.0, 1.15)]
result = sweep(variants, "tool.tip:y", frequency=Frequency(frf.frequency.hz))
members = [zoa(xy_frf(result[i]), cut, speeds, band=band) for i in range(3)]
spread = lobes_band(members, nominal=members[1], label="holder-tool k_yf +-15 %")
robust = recommend(members[1], cut, limits, band=spread)
print("6. With the joint's uncertainty")
print(f"    {robust.describe()[0]} (limit {robust.limit_depth_m * 1e3:.2f} mm over "
      f"{robust.band_members} FRFs)")

# %%
# (g) The plot
# ------------
# The depth axis always shows the recommendation, its safe window and the
# limit it keeps its margin from; labels are plain ("zero-order", with the
# technical name in the note below the axes).
fig = lobes.plot(lobes=True, recommendation=best,
                 title=f"From tap test to spindle speed: {cut.describe()}")
fig.savefig(out / "machinist_recommendation.png", dpi=110)
fig = spread.plot()
plot_recommendation(robust, ax=fig.axes[0])
wrap_title(fig.axes[0], "Recommendation kept for every FRF of the joint's uncertainty band")
fig.savefig(out / "machinist_recommendation_band.png", dpi=110)
print(f"    wrote {out / 'machinist_recommendation.png'} and {out / 'machinist_recommendation_band.png'}")

# %%
# (h) One report to hand over
# ---------------------------
# ``substructure.report`` runs the same workflows (the structure band, the
# lobes, ``recommend``) and writes one HTML page that opens in any browser
# offline: the recommendation with its margin at the top, the lobes, the
# tool point FRF and its modes, the joints, the model and the assumptions.
# With a measurement set it adds the diagnosis of the tap test and the
# joints identified from it (``report(assembly, measurements, cut, limits)``);
# ``substructure report`` does the same from the command line.
page = report(assembly, cut=cut, limits=limits, speeds=speeds)
assert page.recommendation == best  # the same answer as step (e)
path = page.save(out / "machinist_report.html", overwrite=True)
print("7. Report")
print(f"    wrote {path} ({path.stat().st_size / 1024:.0f} kB): {len(page.modes)} modes, "
      f"{len(page.assumptions())} assumptions stated")

# %%
# (i) Cutting speed and feed, in the shop's units
# -----------------------------------------------
# The recommendation in rpm, as a cutting speed (pi D n, in m/min and SFM)
# and a feed rate, checked against the usual range of the work material
# with a carbide tool (an assumed range of published orders of magnitude:
# a warning outside it, never a clip).
data = cutting_data(material, "carbide")
print("8. Cutting data")
print(f"    {best.cutting_speed_m_per_min:.0f} m/min ({best.cutting_speed_m_per_min / 0.3048:.0f} SFM), "
      f"{best.feed_per_tooth_m * 1e3:.3g} mm/tooth, {best.feed_rate_m_per_min * 1e3:.0f} mm/min")
print(f"    usual for {data.workpiece} with carbide: {data.speed_range_m_per_min[0]:.0f} to "
      f"{data.speed_range_m_per_min[1]:.0f} m/min; outside: "
      f"{check_cutting(cut, best.spindle_speed_rpm, data) or 'none'}")

# %%
# (j) A catalogue holder: priors instead of another holder's joints
# ------------------------------------------------------------------
# An HSK-A63 shrink-fit chuck from the catalogue has no joint values of its
# own; the built-in assembly's are a collet chuck's.  The report says so.
# Its documented priors (a wide uncertainty, factor 4) replace them, and
# the report recommends the depth that is stable for every variant of the
# joints within that uncertainty, next to the nominal one.
shrink = assembly.with_component(Holder.from_catalog("HSK-A63 shrink-fit", bore="12 mm", gauge_length="80 mm"))
print("9. HSK-A63 shrink-fit from the catalogue")
for row in joint_provenances(shrink):
    print(f"    {row['name']}: {row['kind']}" + (" (flagged: may be another holder's)" if row["warning"] else ""))
priored = report(with_joint_priors(shrink), cut=cut, limits=limits, speeds=speeds)
for row in joint_provenances(priored.assembly):
    print(f"    {row['name']}: {row['kind']}, within a factor {row['uncertainty']:g}")
nominal, banded = priored.recommendation, priored.band_recommendation
print(f"    nominal joints: {nominal.describe()[0]}")
print(f"    across {len(priored.band.members)} variants of the joints: {banded.describe()[0]}")
