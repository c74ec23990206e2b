"""
A tool library on Dask: every tool's FRF, band, lobes and spindle speed
=======================================================================

A shop does not ask about one tool but about its library: for every
holder/tool combination on every machine, the tool point FRF, the stability
lobes of its usual cuts and the spindle speed and depth to run at, refreshed
whenever a new tap test changes the joint table.  ``substructure.study``
computes each combination as one task on Dask, saves it as it completes,
resumes an interrupted run, fails a bad combination's rows only, and gives
one table.

The library here is the 13 end mills of the thesis's Table 4.2 (diameters
10 to 20 mm, gauge lengths 65 to 106 mm, the holder-tool stiffness ``k_yf``
identified from tap tests for each) in a BT40 ER32 collet chuck on the
built-in spindle, and three tools the table does not have.

Steps: (a) the library as a study (in Python, and as the study file and CSV
that ``substructure study`` reads); (b) the identified joints of the table
(thesis chapter 3) on a local Dask cluster; (c) the joints predicted by a
Gaussian process (thesis chapter 4), with the band of each prediction
carried to the tool mode and to a recommendation that keeps its margin over
the band; (d) resuming; (e) what the uncertainty costs, tool by tool.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure.datasets import thesis_table
from substructure.study import Combination, Compute, Cut, Machine, Study, SurrogateSpec
from substructure.surrogate import thesis_table_4_2

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)
work = Path(tempfile.mkdtemp(prefix="substructure-study-"))  # the study's own output directory

# %%
# (a) The library as a study
# --------------------------
# A combination names its tool (diameter, overhang out of the holder, flute
# length, teeth), its holder (here a catalogue collet chuck whose bore takes
# the tool's diameter) and, when it is known, its holder-tool joint.  The
# thesis's gauge length is the tool's length out of the holder.  The machine
# is the built-in spindle model (free-free, as the thesis's rig: the
# rigid-body lines below its first antiresonance are left out of stability)
# with a spindle of 24,000 rpm and 11 kW.  Two cuts: finishing aluminium
# (a quarter of the diameter, down milling) and slotting steel.
rows = thesis_table("4.2")


def tool(d, length):
    return {"diameter": f"{d} mm", "overhang": f"{length} mm", "flute_length": f"{min(2.5 * d, length - 25):g} mm",
            "teeth": 4}


identified = [Combination(f"D{r['tool_diameter_mm']}-L{r['gauge_length_mm']}",
                          tool=tool(float(r["tool_diameter_mm"]), float(r["gauge_length_mm"])),
                          holder={"catalog": "BT40 ER32"},
                          joint={"k": {"yf": f"{float(r['k_yf_identified_1e7_N_per_m']) * 1e7!r} N/m"}})
              for r in rows]
machine = Machine("thesis spindle", "default",
                  limits={"max_speed": "24000 rpm", "power": [["0 rpm", "0 kW"], ["6000 rpm", "11 kW"],
                                                              ["24000 rpm", "11 kW"]]})
cuts = [Cut("aluminium finish", workpiece="aluminium-7075", immersion=0.25, milling="down", feed_per_tooth="0.05 mm"),
        Cut("steel slot", workpiece="steel-1045", kr=0.35, immersion=1.0, milling="up", feed_per_tooth="0.08 mm")]
speeds = ("3000 rpm", "24000 rpm", "100 rpm")
from substructure.study import Grid  # noqa: E402

grid = Grid(frequency=("100 Hz", "5000 Hz", "4 Hz"), speeds=speeds)
study = Study("Thesis Table 4.2, identified joints", [machine], identified, cuts,
              Compute(band=False, figures=False), grid)
print(f"1. {len(study.combinations)} combinations x {len(study.machines)} machine x {len(study.cuts)} cuts "
      f"= {len(study.tasks()) * len(study.cuts)} rows")

# The same study as files, for `substructure study STUDY.toml --out DIR`: the
# library as a CSV file whose columns are the keys of a combination.
(work / "library.csv").write_text(
    "name,tool.diameter [mm],tool.overhang [mm],tool.flute_length [mm],tool.teeth,holder.catalog,joint.k.yf [N/m]\n"
    + "".join(f"{c.name},{c.tool['diameter'][:-3]},{c.tool['overhang'][:-3]},{c.tool['flute_length'][:-3]},4,"
              f"BT40 ER32,{c.joint['k']['yf'][:-4]}\n" for c in identified))
(work / "study.toml").write_text("""\
name = "Thesis Table 4.2, identified joints"
combinations_csv = "library.csv"

[grid]
frequency = { start = "100 Hz", stop = "5000 Hz", step = "4 Hz" }
speeds = { start = "3000 rpm", stop = "24000 rpm", step = "100 rpm" }

[compute]
band = false
figures = false

[[machines]]
name = "thesis spindle"
assembly = "default"
limits = { max_speed = "24000 rpm", power = [["0 rpm", "0 kW"], ["6000 rpm", "11 kW"], ["24000 rpm", "11 kW"]] }

[[cuts]]
name = "aluminium finish"
workpiece = "aluminium-7075"
immersion = 0.25
milling = "down"
feed_per_tooth = "0.05 mm"

[[cuts]]
name = "steel slot"
workpiece = "steel-1045"
kr = 0.35
immersion = 1.0
milling = "up"
feed_per_tooth = "0.08 mm"
""")
from_file = Study.from_file(work / "study.toml")
print(f"    read back from the study file: the same combinations: {from_file.combinations == study.combinations}, "
      f"the same tasks: {[t['fingerprint'] for t in from_file.tasks()] == [t['fingerprint'] for t in study.tasks()]}")

# %%
# (b) The identified joints, on a local Dask cluster
# --------------------------------------------------
# ``scheduler="local:2"`` runs two Dask workers as threads of this process
# (a script needs no ``if __name__ == "__main__"`` guard for that);
# ``processes:N`` starts worker processes, an address uses a cluster's
# scheduler, and a notebook passes its own ``dask.distributed.Client``.
# Progress lines (done / total, rate, time left) go to standard error.
table_id = study.run(scheduler="local:2", out=work / "identified")
print("2. Identified joints (thesis Table 4.2): recommended speed and depth per tool")
alu = table_id[table_id["cut"] == "aluminium finish"]
for _, r in alu.iterrows():
    print(f"    {r['combination']:10s} k_yf {r['joint_k_yf_n_per_m']:.3g} N/m  tool mode {r['tool_mode_hz']:6.0f} Hz  "
          f"{r['spindle_speed_rpm']:6.0f} rpm  {r['depth_m'] * 1e3:5.2f} mm  "
          f"{r['mrr_m3_per_s'] * 6e7:6.1f} cm^3/min  ({r['limited_by']})")

# %%
# (c) Predicted joints, with their uncertainty
# --------------------------------------------
# Without an explicit joint, the study's surrogate predicts it from the
# combination's features (thesis eq. 4.9-4.10 in spirit: a model trained on
# identified joints); the features map to the tool's diameter and overhang.
# Three tools the table does not have are added.  For each predicted joint
# the FRFs at the 2.5 %, 50 % and 97.5 % quantiles of the prediction give
# the tool mode's band and three lobe diagrams; the recommended depth keeps
# its 20 % margin on all three.
untested = [Combination(name, tool=tool(d, length), holder={"catalog": "BT40 ER32"})
            for name, d, length in (("new D12-L90", 12, 90), ("new D16-L95", 16, 95), ("new D20-L102", 20, 102))]
library = [Combination(c.name, tool=c.tool, holder=c.holder) for c in identified] + untested
surrogate = SurrogateSpec(thesis_table_4_2(), model="gp",
                          features={"tool_diameter": "tool.diameter", "gauge_length": "tool.overhang"})
predicted = Study("Thesis Table 4.2, joints predicted by a Gaussian process", [machine], library, cuts,
                  Compute(band=True, figures=True), grid, surrogate)
table_pr = predicted.run(scheduler="local:2", out=work / "predicted")
print("3. Predicted joints: tool mode with its 95 % band, and the recommendation over the band")
alu_pr = table_pr[table_pr["cut"] == "aluminium finish"]
for _, r in alu_pr.iterrows():
    print(f"    {r['combination']:12s} k_yf {r['joint_k_yf_n_per_m']:.3g} N/m "
          f"[{r['joint_k_yf_lo_n_per_m']:.3g}, {r['joint_k_yf_hi_n_per_m']:.3g}]  "
          f"tool mode {r['tool_mode_hz']:5.0f} Hz "
          f"[{r['tool_mode_lo_hz']:.0f}, {r['tool_mode_hi_hz']:.0f}]  {r['spindle_speed_rpm']:6.0f} rpm "
          f"{r['depth_m'] * 1e3:5.2f} mm")
# the study's own figures: the ranking, and one combination (FRF band, lobes and recommendation per cut)
shutil.copy(work / "predicted" / "summary.png", out / "08a_summary_ranking.png")
one = alu_pr[alu_pr["combination"] == "new D12-L90"].iloc[0]
shutil.copy(work / "predicted" / "figures" / f"{one['key']}.png", out / "08b_one_combination.png")
print(f"    files: {sorted(p.name for p in (work / 'predicted').iterdir())}")

# %%
# (d) Resuming
# ------------
# Every finished combination is in ``results/`` (one file each, written as it
# completed).  Running again with ``resume=True`` (``--resume``) computes only
# what is missing or whose inputs changed; here nothing is, so it only
# reassembles the table, which is the same.
again = predicted.run(scheduler="serial", out=work / "predicted", resume=True, progress=False)
print(f"4. Resumed: the same table: {again.equals(table_pr)}")

# %%
# (e) What the uncertainty costs
# ------------------------------
# For the 13 tools of the table, the removal rate recommended with the
# identified joint against the one that holds over the band of the
# predicted joint; and the tool mode with its band against the diameter and
# gauge length.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
names = list(alu["combination"])
x = np.arange(len(names))
mrr_pr = alu_pr.set_index("combination").loc[names, "mrr_m3_per_s"] * 6e7
ax1.bar(x - 0.2, alu["mrr_m3_per_s"] * 6e7, 0.4, label="identified joint (Table 4.2)")
ax1.bar(x + 0.2, mrr_pr, 0.4, label="predicted joint, margin over its band")
ax1.set_xticks(x, names, rotation=60, fontsize="x-small")
ax1.set_ylabel("recommended removal rate [cm^3/min]")
ax1.set_title("aluminium finish: what the prediction's uncertainty costs", fontsize="small")
ax1.legend(fontsize="x-small")
for d, colour in zip((10, 12, 16, 20), ("C0", "C1", "C2", "C3")):
    rows_d = alu_pr[np.isclose(alu_pr["tool_diameter_m"], d / 1e3)]
    ax2.errorbar(rows_d["overhang_m"] * 1e3, rows_d["tool_mode_hz"],
                 yerr=[rows_d["tool_mode_hz"] - rows_d["tool_mode_lo_hz"], rows_d["tool_mode_hi_hz"]
                       - rows_d["tool_mode_hz"]], fmt="o", color=colour, capsize=3, label=f"{d} mm, predicted")
    ident = alu[np.isclose(alu["tool_diameter_m"], d / 1e3)]
    ax2.plot(ident["overhang_m"] * 1e3, ident["tool_mode_hz"], "x", color=colour, ms=8)
ax2.set_xlabel("gauge length (tool out of the holder) [mm]")
ax2.set_ylabel("tool mode [Hz]")
ax2.set_title("tool mode: predicted with its 95 % band (o), identified joint (x)", fontsize="small")
ax2.legend(fontsize="x-small")
ax2.grid(True, alpha=0.3)
fig.savefig(out / "08c_uncertainty_cost.png", dpi=110)  # left open: a notebook shows it
ratio = (mrr_pr.to_numpy() / (alu["mrr_m3_per_s"] * 6e7).to_numpy())
print(f"5. Removal rate with the predicted joint over that with the identified one: median {np.median(ratio):.2f}, "
      f"from {ratio.min():.2f} to {ratio.max():.2f}")
shutil.rmtree(work, ignore_errors=True)
print(f"wrote figures to {out}")
