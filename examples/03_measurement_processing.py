"""
From tap tests to identification inputs: rotations, smoothing, sensor mass
==========================================================================

What a tap test gives is not yet what eq. 2.3 needs.  Three processing steps
of the thesis, on synthetic tap tests of the built-in model (a 12 mm carbide
end mill, 76 mm out of a BT40-like holder):

(a) rotational receptances L, N, P from translational FRFs at 2 or 3 points
    by finite differences (thesis eq. 2.12-2.18);
(b) Savitzky-Golay smoothing of a noisy FRF (thesis section 3.4);
(c) the mass of a 2 g accelerometer: how it moves the tool mode (thesis
    Table 5.1) and how eq. 5.4 takes it out again.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import Frequency, Sensor, default_assembly, remove_mass
from substructure.datasets import thesis_table
from substructure.rdof import estimate_rotational, positions_from
from substructure.smoothing import choose_window, smooth
from substructure.synthetic import simulate

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def relative_rms(frf, reference):
    """RMS over the lines of |frf - reference| / |reference| (one-entry FRFs)."""
    return float(np.sqrt(np.mean(np.abs(frf.data / reference.data - 1) ** 2)))


def tool_mode(frf, near, width=0.2):
    """Frequency of the largest |H| within +-width of `near` (Hz): the peak of the tool mode."""
    band = frf.crop(near * (1 - width), near * (1 + width))
    return float(band.frequency.hz[np.argmax(np.abs(band.data[:, 0, 0]))])


assembly = default_assembly()            # its joints are passive: no warnings
grid = assembly.frequency                # 20-5000 Hz, 2 Hz
print(f"1. The built-in model: {assembly.name}, grid {grid.start:g}-{grid.stop:g} Hz, {grid.n} lines")

# %%
# (a) Rotational receptances by finite differences
# ------------------------------------------------
# Translational FRFs between the y DOFs of the tool tip and of points 5 mm and
# 10 mm behind it (the 3x3 matrix a tap test with a roving hammer gives; here
# computed noise-free).  estimate_rotational forms, as thesis eq. 2.17,
#
# .. math::
#
#    [H_{est}] = \begin{bmatrix} H_{yy} & H_{\theta y}^T \\ H_{\theta y} & H_{\theta\theta} \end{bmatrix}
#    = [T] [H_{meas}] [T]^T \qquad (2.17)
#
# the row of T for y picks the tip, the row for theta holds the weights of a
# backward difference at the tip: first order with 2 points at spacing s,
# :math:`[T_{1b}] = \begin{bmatrix} 0 & 1 \\ -1/s & 1/s \end{bmatrix}` (eq. 2.13), second order
# with 3 points (eq. 2.16).  Positions run from the tool's base to its tip.
print("2. (a) Rotational receptances at the tool tip by finite differences")
points = ["tool.tip", "tool.tip-5 mm", "tool.tip-10 mm"]
positions = positions_from(assembly, points)
print("    points: " + ", ".join(f"{p} (x = {x.m_as('mm'):g} mm)" for p, x in zip(points, positions)))
H_meas = assembly.frf([f"{p}:y" for p in points], frequency=grid)
exact = assembly.receptance("tool.tip", frequency=grid)               # [[H, L], [N, P]]
first = estimate_rotational(H_meas, points[:2], positions[:2], "tool.tip")
second = estimate_rotational(H_meas, points, positions, "tool.tip")
print("    relative errors |estimate - exact| / |exact| (H is taken as measured: exact):")
print(f"    {'f [Hz]':>8s} {'N, 2 pts':>10s} {'N, 3 pts':>10s} {'P, 2 pts':>10s} {'P, 3 pts':>10s}")
for f in (200, 1000, 1500, 3000):
    i = np.searchsorted(grid.hz, f)
    err = [abs(e.data[i, 1, j] / exact.data[i, 1, j] - 1) for j in (0, 1) for e in (first, second)]
    print(f"    {f:8d} " + " ".join(f"{x:10.2e}" for x in err))

# Why the errors do not vanish: the beams are Timoshenko beams, whose theta is
# the rotation psi of the cross-section, while finite differences of y give
# the slope dy/dx = psi + shear angle.  At the tip, under a tip force, the
# shear angle adds 1/(kappa G A) to N (0.4-1 % of it here), whatever the spacing.
# Worse, y has a kink at the loaded point (its slope jumps by 1/(kappa G A)),
# which the driving-point terms of H_meas carry into P as a constant bias of
# about 1/(kappa G A s) for 2 points and 2.5/(kappa G A s) for the 3-point
# stencil at an end (see the docstring of estimate_rotational): the smaller
# the spacing s, the larger the bias.  Truncation errors grow with s instead,
# so P wants a large spacing and N a small one (Duarte and Ewins).  At a
# free tip the curvature is nearly zero (no moment), so there the 2-point
# difference is already about second-order accurate, and the 3-point stencil,
# which reaches twice as far, is not better.
kGA = assembly.component("tool").segments[-1].section().kGA.real
print(f"    kappa G A of the fluted tip section: {kGA:.3g} N, so 1/(kappa G A) = {1 / kGA:.3g} m/N")
check = Frequency.from_hz([1000.0])
spacings = [1, 2, 5, 10, 20]
errors = {("N", 2): [], ("N", 3): [], ("P", 2): [], ("P", 3): []}
print(f"    at 1000 Hz: {'s [mm]':>6s} {'N, 2 pts':>9s} {'N, 3 pts':>9s} {'P, 2 pts':>9s} {'P, 3 pts':>9s}"
      f" {'(P3-P)*s*kGA':>13s}")
for s in spacings:
    pts = ["tool.tip", f"tool.tip-{s} mm", f"tool.tip-{2 * s} mm"]
    Y = assembly.frf([f"{p}:y" for p in pts], frequency=check)
    ref = assembly.receptance("tool.tip", frequency=check).data[0]
    for n in (2, 3):
        est = estimate_rotational(Y, pts[:n], positions_from(assembly, pts[:n]), "tool.tip").data[0]
        errors["N", n].append(abs(est[1, 0] / ref[1, 0] - 1))
        errors["P", n].append(abs(est[1, 1] / ref[1, 1] - 1))
    bias = (est[1, 1] - ref[1, 1]).real * s * 1e-3 * kGA    # tends to 2.5 as s shrinks
    print(f"    {'':11s} {s:6d} " + " ".join(f"{errors[key][-1]:9.2e}" for key in errors) + f" {bias:13.2f}")

fig, axes = plt.subplots(1, 3, figsize=(13, 4), layout="constrained")
for ax, j, term, unit in ((axes[0], 0, "N", "rad/N"), (axes[1], 1, "P", "rad/(N m)")):
    for frf, label, style in ((exact, "exact (model)", "-"), (first, "2 points, 1st order", "--"),
                              (second, "3 points, 2nd order", ":")):
        ax.semilogy(grid.hz, np.abs(frf.data[:, 1, j]), style, label=label)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"|{term}| [{unit}]")
    ax.set_title(f"{term} = theta/{'f' if term == 'N' else 'm'} at the tool tip, spacing 5 mm")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
for (term, n), values in errors.items():   # dips: the shear bias and the truncation error cancel
    axes[2].loglog(spacings, values, "o-" if term == "N" else "s--", color="tab:blue" if n == 2 else "tab:orange",
                   label=f"{term}, {n} points")
axes[2].set_xlabel("spacing s [mm]")
axes[2].set_ylabel("relative error at 1000 Hz")
axes[2].set_title("error against spacing")
axes[2].legend(fontsize="small")
axes[2].grid(True, which="both", alpha=0.3)
fig.suptitle("(a) Rotational receptances from translational FRFs (thesis eq. 2.12-2.18)")
save(fig, "03a_finite_differences.png")

# %%
# (b) Smoothing a noisy FRF
# -------------------------
# A synthetic tap test at the tool tip with 2 % complex multiplicative noise.
# choose_window takes the narrowest half-power bandwidth B of the resonances
# (in lines) and returns the widest odd window that lowers such a peak by at
# most 0.5 % (about B/2 lines for a cubic); smooth filters Re and Im.
print("3. (b) Savitzky-Golay smoothing of a 2 % noisy tool point FRF")
H = assembly.receptance("tool.tip:y", frequency=grid)
noisy = simulate(assembly, ["tool.tip"], frequency=grid, noise=0.02, seed=3).measurements[0].frf
window = choose_window(noisy)
smoothed = smooth(noisy, window=window)
print(f"    window chosen from the data: {window} lines ({window * 2} Hz), cubic polynomials")
print(f"    relative RMS error against the noise-free FRF: {relative_rms(noisy, H):.2%} before, "
      f"{relative_rms(smoothed, H):.2%} after")

fig, axes = plt.subplots(1, 2, figsize=(12, 4), layout="constrained")
for ax, (lo, hi) in zip(axes, ((grid.start, grid.stop), (1300, 1700))):
    for frf, label, kw in ((noisy, "2 % noise", dict(color="0.6", lw=0.6)),
                           (smoothed, f"smoothed, window {window}", dict(color="tab:blue", lw=1.2)),
                           (H, "noise-free", dict(color="k", ls=":", lw=1.2))):
        part = frf.crop(lo, hi)
        ax.semilogy(part.frequency.hz, np.abs(part.data[:, 0, 0]), label=label, **kw)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|H| at the tool tip [m/N]")
    ax.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize="small")
axes[1].set_title("the tool mode")
fig.suptitle("(b) Savitzky-Golay smoothing (thesis section 3.4)")
save(fig, "03b_smoothing.png")

# %%
# (c) The mass of a 2 g accelerometer
# -----------------------------------
# The sensor is declared on the assembly; simulate puts it on the structure
# when it is listed in sensors=[...], as a measurement set would record it.
print("4. (c) A 2 g accelerometer at the tool tip")
truth = assembly.attach(Sensor("accelerometer", "tool.tip", "2 g"))
free = simulate(truth, ["tool.tip"], frequency=grid).measurements[0].frf          # laser: no mass
loaded = simulate(truth, ["tool.tip"], frequency=grid, sensors=["accelerometer"]).measurements[0].frf
tapped = simulate(truth, ["tool.tip"], frequency=grid, sensors=["accelerometer"], noise=0.02,
                  seed=7).measurements[0].frf
row = next(r for r in thesis_table("5.1") if (r["tool_diameter_mm"], r["gauge_length_mm"]) == ("12", "76"))
f0, f1 = float(row["tool_mode_without_mass_hz"]), float(row["tool_mode_with_mass_hz"])
print(f"    thesis Table 5.1, 12 mm tool, 76 mm gauge length: {f0:g} Hz -> {f1:g} Hz "
      f"({f1 - f0:+g} Hz)")
print("    our model, all peaks: " + ", ".join(f"{a:g} -> {b:g} Hz" for a, b in zip(free.peaks(), loaded.peaks())))
m0 = tool_mode(free, 1500)
m1 = tool_mode(loaded, m0)
print(f"    our model, tool mode (highest peak): {m0:g} Hz -> {m1:g} Hz ({m1 - m0:+g} Hz)")
# A mode with effective mass m at the tip drops by sqrt(m / (m + 2 g)):
# m = 2 g / ((f0/f1)^2 - 1).  The measured shift means a light tool mode at the
# tip; in the model, spindle and holder move with the tool in that mode.
for who, a, b in (("thesis", f0, f1), ("model", m0, m1)):
    print(f"    effective mass of the tool mode at the tip ({who}): {2.0 / ((a / b) ** 2 - 1):.1f} g")

# Thesis eq. 5.4, the structural modification of eq. 5.1 run backwards with
# the mass m of the sensor, on the measured y DOF only:
#
# .. math::
#
#    H_{free} = \frac{H}{1 + \omega^2 m H} \qquad (5.4)
compensated = remove_mass(loaded, "tool.tip:y", "2 g")
print(f"    noise-free: compensated vs sensor-free, max |ratio - 1| = "
      f"{np.abs(compensated.data / free.data - 1).max():.1e}")
tapped_smooth = smooth(tapped)                       # smooth first, then compensate
compensated_noisy = remove_mass(tapped_smooth, "tool.tip:y", "2 g")
print(f"    {'tool mode peak [Hz]':28s} {'sensor-free':>11s} {'with sensor':>11s} {'compensated':>11s}")
for label, loaded_frf, comp_frf in (("noise-free", loaded, compensated),
                                    ("2 % noise, smoothed", tapped_smooth, compensated_noisy)):
    a, b = tool_mode(loaded_frf, m0), tool_mode(comp_frf, m0)
    print(f"    {label:28s} {m0:11g} {a:11g} {b:11g}   compensated off by {b / m0 - 1:+.2%}")

fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
for frf, label, kw in ((tapped, "tap test with the sensor, 2 % noise", dict(color="0.7", lw=0.6)),
                       (loaded, "with the 2 g sensor (noise-free)", dict(color="tab:red", lw=1.2)),
                       (free, "without the sensor", dict(color="k", lw=1.2)),
                       (compensated_noisy, "noisy, smoothed, mass removed (eq. 5.4)", dict(color="tab:blue", ls="--")),
                       (compensated, "noise-free, mass removed (eq. 5.4)", dict(color="tab:green", ls=":", lw=2))):
    part = frf.crop(1300, 1700)
    ax.semilogy(part.frequency.hz, np.abs(part.data[:, 0, 0]), label=label, **kw)
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|H| at the tool tip [m/N]")
ax.set_title("(c) Sensor mass on the tool mode and its removal (cf. thesis Fig. 5.5)")
ax.legend(fontsize="small")
ax.grid(True, which="both", alpha=0.3)
save(fig, "03c_sensor_mass.png")
