"""
Rigid joints: the limit of a stiff elastic joint
================================================

A joint of thesis eq. 2.5 connects two points through a complex stiffness
[K]; a rigid joint makes their displacements and slopes equal.  The rigid
joint is the limit of an elastic one as its stiffness grows: in thesis
eq. 2.2 the joint enters as its compliance :math:`[K]^{-1}`, which goes to
zero.

Steps: (a) a rod cut in two and joined rigidly is the rod in one piece;
(b) thesis eq. 2.2 with :math:`[K]^{-1} = 0`, written out with numpy,
against the library's rigid holder-tool joint; (c) an elastic holder-tool
joint made stiffer decade by decade: the tool point FRF and its first peak
approach the rigid ones, the difference falling as 1/k; (d) the figures.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup: the spindle, holder and tool of lesson 01
# ------------------------------------------------
# The components are those of ``01_forward_coupling.py``; the spindle-holder
# joint here is a plain passive one (diagonal stiffness and damping), so that
# only the holder-tool joint changes below.
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import Assembly, Flutes, Frequency, Holder, Insert, Joint, Segment, Spindle, Tool
from substructure.materials import carbide

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)
grid = Frequency.from_range("20 Hz", "5000 Hz", "2 Hz")
inv = np.linalg.inv  # inverts stacks of 2x2 matrices, shape (n_freq, 2, 2)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def rel_diff(a, b):
    """Largest difference relative to the largest value: max|a - b| / max|b|."""
    return np.abs(a - b).max() / np.abs(b).max()


def first_peak(assembly, coarse):
    """The lowest peak of the tool point |H| in Hz: the coarse one, on a 0.01 Hz grid around it,
    then the vertex of the parabola through log|H| at the finest three lines."""
    f0 = coarse.peaks()[0]
    fine = Frequency.from_range(f"{f0 - 3:g} Hz", f"{f0 + 3:g} Hz", "0.01 Hz")
    y = np.log(np.abs(assembly.receptance("tool.tip:y", frequency=fine).data[:, 0, 0]))
    i = int(np.clip(np.argmax(y), 1, y.size - 2))
    shift = 0.5 * (y[i - 1] - y[i + 1]) / (y[i - 1] - 2 * y[i] + y[i + 1])
    return fine.hz[i] + shift * 0.01


spindle = Spindle("spindle", [Segment("120 mm", "70 mm", "40 mm"),
                              Segment("150 mm", "90 mm", "40 mm"),
                              Segment("60 mm", "110 mm", "40 mm")])
holder = Holder("holder", [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"),
                           Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"))])
tool = Tool("tool", [Segment("30 mm", "12 mm", material="carbide"),
                     Segment("30 mm", "12 mm", material="carbide", flutes=Flutes(0.8))])
sh_joint = Joint("spindle-holder", ("spindle.tip", "holder.base"),
                 k={"yf": "5e8 N/m", "tm": "2e6 N*m/rad"}, c={"yf": "300 N*s/m", "tm": "20 N*m*s/rad"})
rigid = Joint.rigid_between("holder-tool", "holder.tip", "tool.base")
base = Assembly("rigid holder-tool joint", components=(spindle, holder, tool), joints=(sh_joint, rigid))
print("1. The assembly: spindle, holder, 60 mm of a 12 mm carbide tool; the holder-tool joint rigid")

# %%
# (a) A rod cut in two and joined rigidly is the rod in one piece
# ---------------------------------------------------------------
# A rigid joint adds nothing and takes nothing away: two 100 mm halves of a
# 200 mm carbide rod, joined rigidly, have the free-free receptance of the
# whole rod, which the library computes from the exact Timoshenko beam of one
# segment.  The first free-free bending frequency is also close to the
# Euler-Bernoulli value :math:`f_1 = \frac{(4.7300)^2}{2 \pi L^2} \sqrt{EI / \rho A}`;
# the Timoshenko beam is a little lower (shear and rotary inertia).
print("2. (a) A rod in two halves joined rigidly against the rod in one piece")
rod = Tool("rod", [Segment("200 mm", "12 mm", material="carbide")])
halves = Assembly("two halves", components=(Tool("a", [Segment("100 mm", "12 mm", material="carbide")]),
                                            Tool("b", [Segment("100 mm", "12 mm", material="carbide")])),
                  joints=(Joint.rigid_between("a-b", "a.tip", "b.base"),))
whole = rod.receptance(grid, ["tip"])["rod.tip:y", "rod.tip:y"]
joined = halves.receptance("b.tip:y", frequency=grid)
print(f"    max relative difference of the tip receptance: {rel_diff(joined.data, whole.data):.1e}")
E, rho, d, L = carbide.E.m_as("Pa"), carbide.rho.m_as("kg/m^3"), 0.012, 0.2
f_eb = 4.7300**2 / (2 * np.pi * L**2) * np.sqrt(E * np.pi * d**4 / 64 / (rho * np.pi * d**2 / 4))
print(f"    first free-free mode: {whole.peaks()[0]:g} Hz (Timoshenko, 2 Hz grid); "
      f"Euler-Bernoulli {f_eb:.0f} Hz")

# %%
# (b) Thesis eq. 2.2 with a rigid joint
# -------------------------------------
# With the tool (T, point 1 its tip, point 2 its base) on the spindle-holder
# subassembly (:math:`[SH_{11}]` at the holder tip), thesis eq. 2.2 reads
#
# .. math::
#
#    [SHT_{11}] = [T_{11}] - [T_{12}] \left[ [T_{22}] + [K_{ht}]^{-1} + [SH_{11}] \right]^{-1} [T_{21}]
#    \qquad (2.2)
#
# and a rigid joint is :math:`[K_{ht}]^{-1} = 0`.  Written out with numpy and
# compared with the library's rigid joint (a different path: the engine
# makes the two points one instead of inverting a compliance).
print("3. (b) Thesis eq. 2.2 with [K_ht]^-1 = 0 against the rigid joint")
SH11 = base.without("tool").receptance("holder.tip", frequency=grid).data
T = tool.receptance(grid, ["tip", "base"]).data
T11, T12, T21, T22 = T[:, :2, :2], T[:, :2, 2:], T[:, 2:, :2], T[:, 2:, 2:]
SHT11_rigid_eq = T11 - T12 @ inv(T22 + SH11) @ T21
H_rigid = base.receptance("tool.tip:y", frequency=grid)
print(f"    max relative difference of H: {rel_diff(SHT11_rigid_eq[:, :1, :1], H_rigid.data):.1e}")
f_rigid = first_peak(base, H_rigid)
print(f"    tool point peaks {H_rigid.peaks()} Hz; the first, refined: {f_rigid:.3f} Hz")

# %%
# (c) A stiff elastic joint approaches the rigid one
# --------------------------------------------------
# The elastic holder-tool joint has :math:`k_{yf} = s \cdot 2 \times 10^7` N/m and
# :math:`k_{\theta m} = s \cdot 2 \times 10^5` N m/rad, with fixed light damping,
# for s = 1 to 10^5.  Its compliance in eq. 2.2 shrinks as 1/s, so the FRF
# and the first peak approach the rigid joint's at that rate: each decade of
# stiffness divides the difference by about ten, and the difference times
# :math:`k_{yf}` settles at a constant.
print("4. (c) An elastic holder-tool joint made stiffer, against the rigid joint")
scales = 10.0 ** np.arange(0, 6)
rows, elastic_frfs = [], []
print(f"    {'k_yf (N/m)':>11s} {'first peak (Hz)':>16s} {'minus rigid (Hz)':>17s} "
      f"{'(f - f_rigid) k_yf':>19s} {'FRF difference':>15s}")
for s in scales:
    k_yf = 2e7 * s
    joint = Joint("holder-tool", ("holder.tip", "tool.base"),
                  k={"yf": f"{k_yf:g} N/m", "tm": f"{2e5 * s:g} N*m/rad"},
                  c={"yf": "100 N*s/m", "tm": "1 N*m*s/rad"})
    elastic = base.with_joint(joint)
    h = elastic.receptance("tool.tip:y", frequency=grid)
    f1 = first_peak(elastic, h)
    diff = rel_diff(h.data, H_rigid.data)
    rows.append((k_yf, f1, f1 - f_rigid, diff))
    elastic_frfs.append(h)
    print(f"    {k_yf:11.0e} {f1:16.3f} {f1 - f_rigid:17.4f} {(f1 - f_rigid) * k_yf:19.3e} {diff:15.2e}")
rows = np.array(rows)
per_decade = rows[:-1, 3] / rows[1:, 3]
print("    the FRF difference falls by " + ", ".join(f"{r:.1f}" for r in per_decade[-3:])
      + " over the last three decades of k"
      " (10 for a 1/k rate; the softest joints are not yet in that regime)")
print(f"    rigid joint: first peak {f_rigid:.3f} Hz; the stiffest elastic joint is "
      f"{abs(rows[-1, 2]) * 1e3:.2f} mHz from it")

# %%
# (d) The figures
# ---------------
# The tool point receptance for each stiffness over the rigid joint's
# (dashed), and the convergence on logarithmic axes with a 1/k line.
# ``limits`` sets the magnitude axis with its unit, whatever unit the axes
# show (micrometres per newton here).
print("5. (d) Figures")
fig = None
for i, (s, h) in enumerate(zip(scales, elastic_frfs)):
    fig = h.crop("300 Hz", "5000 Hz").plot(ax=fig, label=f"k_yf = {2e7 * s:.0e} N/m",
                                           color=plt.cm.viridis(i / len(scales)))
H_rigid.crop("300 Hz", "5000 Hz").plot(ax=fig, label="rigid joint", color="k", ls="--",
                                       limits=("1e-5 um/N", "3e-5 m/N"))
fig.axes[0].legend(fontsize="x-small", ncols=2, loc="lower center")  # below the curves
fig.suptitle("(c) Tool point FRF as the holder-tool joint stiffens, and the rigid joint")
save(fig, "13a_stiffening_joint.png")

fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
ax.loglog(rows[:, 0], np.abs(rows[:, 2]), "o-", label="|first peak - rigid| (Hz)")
ax.loglog(rows[:, 0], rows[:, 3], "s-", label="FRF difference, max|H - H_rigid| / max|H_rigid|")
ax.loglog(rows[:, 0], rows[-1, 3] * rows[-1, 0] / rows[:, 0], "k:", label="1/k (through the stiffest joint)")
ax.set_xlabel("joint stiffness k_yf (N/m)")
ax.set_ylabel("difference to the rigid joint")
ax.set_title("(c) The elastic joint converges to the rigid one as 1/k")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize="small")
save(fig, "13b_convergence.png")
