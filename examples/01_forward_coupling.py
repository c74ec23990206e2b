"""
Forward receptance coupling, step by step
=========================================

The analytical case of the thesis (Özşahin, section 2.3): a spindle, a holder
and a tool, each a free-free stepped Timoshenko beam, coupled through the
joints of thesis Tables 2.1 (spindle-holder) and 2.2 (holder-tool).

Steps: (a) free-free receptances of the components; (b) thesis eq. 2.1 and
(c) eq. 2.2 written out with numpy, against the library's Assembly; (d) a
"measured" spindle-holder coupled to a tool model; (e) a 2 g accelerometer
at the tool tip (thesis eq. 5.1-5.4); (f) a sweep over the tool overhang.

Each step names the thesis equation it implements.  Figures are written to
$SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
# Every dimensional input carries its unit (a string pint reads, or a pint
# quantity); a bare number where a length is expected is an error.
import os
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import (FRF, Assembly, Flutes, Frequency, Holder, Insert, Joint, MeasuredComponent,
                          NonPassiveJointWarning, Segment, Sensor, Spindle, Tool, add_mass, remove_mass)
from substructure.datasets import thesis_joint
from substructure.sweep import sweep

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)
grid = Frequency.from_range("20 Hz", "5000 Hz", "2 Hz")  # free-free parts: no line at 0 Hz
inv = np.linalg.inv  # inverts stacks of matrices, shape (n_freq, 2, 2)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def highest_peak(frf):
    """Frequency in Hz of the largest local maximum of |H| of a one-entry FRF."""
    peaks = frf.peaks()
    return peaks[np.argmax(np.abs(frf.data[np.searchsorted(frf.frequency.hz, peaks), 0, 0]))]


def rel_diff(a, b):
    """Largest difference relative to the largest value: max|a - b| / max|b|."""
    return np.abs(a - b).max() / np.abs(b).max()


# Segments run from each component's base to its tip (length, od, id).
spindle = Spindle("spindle", [Segment("120 mm", "70 mm", "40 mm"),
                              Segment("150 mm", "90 mm", "40 mm"),
                              Segment("60 mm", "110 mm", "40 mm")])
# The holder's bore holds the tool shank: an insert of carbide in the last segment.
holder = Holder("holder", [Segment("16 mm", "63 mm"), Segment("10 mm", "40 mm"),
                           Segment("40 mm", "40 mm", "12 mm", insert=Insert("12 mm", "carbide"))])


def make_tool(overhang_mm):
    """The part of a 12 mm carbide end mill outside the holder; the outer half is fluted."""
    half = f"{overhang_mm / 2:g} mm"
    return Tool("tool", [Segment(half, "12 mm", material="carbide"),
                         Segment(half, "12 mm", material="carbide", flutes=Flutes(0.8))])


tool = make_tool(60)
print("1. Components (free-free stepped Timoshenko beams)")
for part in (spindle, holder, tool):
    print(f"    {part.name:8s} length {part.length:~P}, mass {part.mass():.3f} kg")

# %%
# The joints of thesis Tables 2.1 and 2.2
# ---------------------------------------
# thesis_joint gives the k and c entries (yf, ym, tf, tm) with units.  The
# library warns when a joint matrix is not positive semi-definite: here
# k_ym * k_tf > k_yf * k_tm, and likewise for c.  Along some combination of
# relative displacement and rotation the joint then has a negative stiffness,
# and its damping does negative work: it can feed energy into the structure.
# The thesis made the off-diagonal terms equal (reciprocity) but did not ask
# for passivity.  Each joint is the fully populated complex stiffness matrix of
# thesis eq. 2.5 (y the displacement, theta the slope, f the force, m the moment):
#
# .. math::
#
#    [K] = \begin{bmatrix} k_{yf} + i\omega c_{yf} & k_{ym} + i\omega c_{ym} \\
#          k_{\theta f} + i\omega c_{\theta f} & k_{\theta m} + i\omega c_{\theta m} \end{bmatrix}
#    \qquad (2.5)
#
# The values are accepted; we record the warnings while the
# joints are built, print them, and so keep them out of the rest of the script.
print("2. Joints of thesis Tables 2.1 and 2.2")
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", NonPassiveJointWarning)
    k_sh, c_sh = thesis_joint("2.1")
    k_ht, c_ht = thesis_joint("2.2")
    sh_joint = Joint("spindle-holder", ("spindle.tip", "holder.base"), k=k_sh, c=c_sh)
    ht_joint = Joint("holder-tool", ("holder.tip", "tool.base"), k=k_ht, c=c_ht)
for w in caught:
    print(f"    {w.category.__name__}: {w.message}")

assembly = Assembly("thesis analytical case", components=(spindle, holder, tool),
                    joints=(sh_joint, ht_joint))

# %%
# (a) Free-free receptances
# -------------------------
# A component's receptance between points is an FRF of shape (n_freq, 2p, 2p),
# with labels "point:y" and "point:theta": at one point, [[H, L], [N, P]], the
# receptances of thesis eq. 2.7,
#
# .. math::
#
#    H = \frac{y}{f}, \quad N = \frac{\theta}{f}, \quad L = \frac{y}{m}, \quad P = \frac{\theta}{m}
#    \qquad (2.7)
#
# computed here from the exact Timoshenko beam, not from the modal series of
# eq. 2.8-2.11.  At low frequency a free-free beam moves as a rigid body:
# :math:`|H| \approx 1/(m \omega^2)`.
print("3. (a) Free-free tip receptances H = y/f")
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
for part in (spindle, holder, tool):
    tip = f"{part.name}.tip:y"
    h = part.receptance(grid, ["tip"])[tip, tip]
    h.plot(ax=ax, parts=("magnitude",), label=part.name)
    peaks = h.peaks()
    print(f"    {part.name:8s} resonances below 5 kHz: {f'{peaks} Hz' if peaks.size else 'none'}")
ax.set_title("(a) Free-free point receptances H at the components' tips")
save(fig, "01a_free_free.png")

# %%
# (b) Thesis eq. 2.1: the spindle-holder subassembly
# --------------------------------------------------
# The holder (receptances H, point 1 its tip, point 2 its base) is coupled to
# the spindle (S11 at its tip) through the spindle-holder joint K_sh:
#
# .. math::
#
#    [SH_{11}] = [H_{11}] - [H_{12}] \left[ [H_{22}] + [K_{sh}]^{-1} + [S_{11}] \right]^{-1} [H_{21}]
#    \qquad (2.1)
#
# written out below with numpy, one 2x2 inversion per frequency line, and
# compared with the library's Assembly.
print("4. (b) Thesis eq. 2.1 against Assembly(spindle, holder)")
S = spindle.receptance(grid, ["tip"]).data                  # (n, 2, 2)
H = holder.receptance(grid, ["tip", "base"]).data           # (n, 4, 4): tip first, then base
K_sh = np.moveaxis(sh_joint.dynamic_stiffness(grid.hz), -1, 0)  # (2, 2, n) -> (n, 2, 2)
H11, H12, H21, H22 = H[:, :2, :2], H[:, :2, 2:], H[:, 2:, :2], H[:, 2:, 2:]
SH11_eq = H11 - H12 @ inv(H22 + inv(K_sh) + S) @ H21

# Assembly.without("tool") drops the tool and the joints that touch it.
SH11 = assembly.without("tool").receptance("holder.tip", frequency=grid)
print(f"    max relative difference: {rel_diff(SH11_eq, SH11.data):.1e}")

# %%
# (c) Thesis eq. 2.2: the tool point
# ----------------------------------
# The tool (T, point 1 its tip, point 2 its base) is coupled to the
# spindle-holder subassembly of step (b) through the holder-tool joint K_ht:
#
# .. math::
#
#    [SHT_{11}] = [T_{11}] - [T_{12}] \left[ [T_{22}] + [K_{ht}]^{-1} + [SH_{11}] \right]^{-1} [T_{21}]
#    \qquad (2.2)
print("5. (c) Thesis eq. 2.2 against the full assembly")
T = tool.receptance(grid, ["tip", "base"]).data
K_ht = np.moveaxis(ht_joint.dynamic_stiffness(grid.hz), -1, 0)
T11, T12, T21, T22 = T[:, :2, :2], T[:, :2, 2:], T[:, 2:, :2], T[:, 2:, 2:]
SHT11_eq = T11 - T12 @ inv(T22 + inv(K_ht) + SH11_eq) @ T21

SHT11 = assembly.receptance("tool.tip", frequency=grid)      # [[H, L], [N, P]] at the tool tip
print(f"    max relative difference: {rel_diff(SHT11_eq, SHT11.data):.1e}")
H_tool = SHT11["tool.tip:y", "tool.tip:y"]
tool_mode = highest_peak(H_tool)
print(f"    tool point peaks: {H_tool.peaks()} Hz; tool mode (highest): {tool_mode:g} Hz")
# Under x = X exp(i omega t) a passive structure has Im H <= 0 at a driving
# point.  The non-passive damping matrices of the thesis joints (c_ym * c_tf >
# c_yf * c_tm) break this on some lines; with c_ym = c_tf = 0 they would not.
lines = grid.hz[H_tool.imag[:, 0, 0] > 0]
print(f"    lines with Im H > 0 (energy from the joints): {lines.size}, "
      f"{lines.min():g}-{lines.max():g} Hz")

# %%
# (d) A measured spindle-holder coupled to the tool model
# -------------------------------------------------------
# In practice [SH11] comes from tap tests on the machine (rotational terms by
# finite differences).  A MeasuredComponent holds such data; its labels name
# the points ("holder.tip:y", "holder.tip:theta"), so the joint finds them.
print("6. (d) Measured [SH11] (here: the computed one) coupled to the tool model")
measured = MeasuredComponent("spindle-holder", SH11)
semi = Assembly("semi-analytical", components=(measured, tool), joints=(ht_joint,))
SHT11_semi = semi.receptance("tool.tip", frequency=grid)
print(f"    max relative difference to the full model: {rel_diff(SHT11_semi.data, SHT11.data):.1e}")

# Wrap the numpy results as FRFs (same labels) to plot them over the Assembly's.
SH11_eq = FRF(grid, SH11_eq, SH11.outputs, SH11.inputs)["holder.tip:y", "holder.tip:y"]
SHT11_eq = FRF(grid, SHT11_eq, SHT11.outputs, SHT11.inputs)["tool.tip:y", "tool.tip:y"]
fig = SH11["holder.tip:y", "holder.tip:y"].plot(label="H of [SH11], holder tip: Assembly")
SH11_eq.plot(ax=fig, label="H of [SH11]: eq. 2.1 (numpy)", ls=":", color="k")
H_tool.plot(ax=fig, label="H of [SHT11], tool tip: Assembly")
SHT11_eq.plot(ax=fig, label="H of [SHT11]: eq. 2.2 (numpy)", ls=":", color="k")
# The axes show um/N (plot_frf's default unit): limits are given with their
# unit, and converted to it.  The upper limit leaves head room for the legend.
SHT11_semi["tool.tip:y", "tool.tip:y"].plot(ax=fig, label="H of [SHT11]: measured + tool", ls="--",
                                            limits=(None, "1e-3 m/N"))
fig.axes[0].legend(loc="upper right", fontsize="x-small")
fig.suptitle("(b)-(d) Receptances H = y/f after coupling")
save(fig, "01bcd_coupling.png")

# %%
# (e) A 2 g accelerometer at the tool tip
# ---------------------------------------
# As part of the model (Assembly.attach), or as a structural modification of
# the sensor-free FRF (add_mass): with the modification matrix
# :math:`[D] = -\omega^2 M` (eq. 5.2), thesis eq. 5.1 reads
#
# .. math::
#
#    [SHT_{11}]^{modified} = \left[ [I] + [SHT_{11}]^{unmodified} [D] \right]^{-1} [SHT_{11}]^{unmodified}
#    \qquad (5.1)
#
# and with H alone (eq. 5.3) :math:`H_{mod} = H / (1 - \omega^2 M H)`.
# remove_mass (eq. 5.4) takes the mass off a measurement again.
print("7. (e) 2 g accelerometer at the tool tip")
accelerometer = Sensor("accelerometer", "tool.tip", "2 g")
H_mass = assembly.attach(accelerometer).receptance("tool.tip:y", frequency=grid)
# With only H measured, as in a tap test, add_mass is the scalar eq. 5.3,
# H / (1 - omega^2 m H); a sensor with rotary inertia needs the 2x2 receptance.
H_added = add_mass(H_tool, "tool.tip", "2 g")
H_removed = remove_mass(H_mass, "tool.tip", "2 g")
print(f"    add_mass (eq. 5.3) vs Assembly.attach:  {rel_diff(H_added.data, H_mass.data):.1e}")
print(f"    remove_mass (eq. 5.4) vs sensor-free H: {rel_diff(H_removed.data, H_tool.data):.1e}")
moved = H_mass.peaks()[np.argmin(np.abs(H_mass.peaks() - tool_mode))]
print(f"    tool mode {tool_mode:g} Hz -> {moved:g} Hz with the sensor ({moved - tool_mode:+g} Hz)")
fig = H_tool.crop("1000 Hz", "2000 Hz").plot(label="no sensor")
H_mass.crop("1000 Hz", "2000 Hz").plot(ax=fig, label="2 g accelerometer at the tip", ls="--")
fig.suptitle("(e) Mass loading of the tool point FRF by an accelerometer")
save(fig, "01e_sensor.png")

# %%
# (f) Tool overhang sweep
# -----------------------
# Variants of one assembly (same components and joints by name) are evaluated
# together: the spindle-holder part is coupled once, the tools in one batch.
print("8. (f) Tool overhang sweep")
overhangs = np.arange(40, 95, 10)
result = sweep([assembly.with_component(make_tool(L)) for L in overhangs], "tool.tip:y",
               frequency=grid)
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
for i, L in enumerate(overhangs):
    frf = result[i]          # the FRF of variant i
    frf.plot(ax=ax, parts=("magnitude",), label=f"{L} mm", color=plt.cm.viridis(i / len(overhangs)))
    print(f"    overhang {L} mm: peaks {frf.peaks()} Hz")
ax.set_title("(f) Tool point receptance H for several tool overhangs")
save(fig, "01f_overhang_sweep.png")
print("    the tool mode (the lowest peak here) moves down as the tool gets longer")
