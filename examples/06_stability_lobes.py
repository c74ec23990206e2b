"""
Stability lobes from a predicted tool point FRF
===============================================

What an error in the tool point FRF costs at the machine (thesis Figures 4.5
and 5.2): the stability lobes of the thesis's cut on the tool point FRF the
library predicts for its built-in assembly, with and without a 2 g
accelerometer on the tool tip, and how far an uncertain joint moves them.
Then the one-degree-of-freedom benchmark of Insperger & Stepan, where the
zero-order method and semi-discretization are checked against a closed form
and against each other, including the low immersion where the zero order
fails.

Steps: (a) the cut and its units; (b) the tool point FRF; (c) zero-order
lobes with and without the accelerometer; (d) a band from an uncertain
holder-tool joint; (e) semi-discretization on fitted modes; (f) the
Insperger-Stepan benchmark.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import Frequency, Joint, Sensor, default_assembly
from substructure.stability import (MillingCut, ModalFitter, ModalModel, Mode, lobes_band, sdm,
                                    spindle_speeds, tooth_passing_hz, xy_frf, zoa)
from substructure.sweep import sweep
from substructure.units import Q_

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


def describe_best(lobes, count=3):
    for n, a in lobes.best_speeds(count):
        print(f"      {n:8.0f} rpm: depth limit {a * 1e3:5.2f} mm")


# %%
# (a) The cut, with units
# -----------------------
# The thesis's cut: 4 teeth, 12 mm tool, 3 mm radial depth, up milling,
# Kt = 625 MPa and "Kr = 100 MPa".  Kr is given there as a pressure: without
# helix and lead angle the radial force is the normal force, so it is
# kn = "100 MPa" here, a ratio Kn/Kt = 0.16.  A ratio is given as kr=0.16.
cut = MillingCut(4, "12 mm", "3 mm", kt="625 MPa", kn="100 MPa", milling="up")
print("1. The cut")
print(f"    {cut.describe()}")
print(f"    entry and exit angles {np.degrees(cut.angles[0]):.0f} and {np.degrees(cut.angles[1]):.0f} deg")
# Spindle speeds are in rpm; the tooth-passing frequency is an explicit
# helper (pint would convert rpm to Hz as an angular velocity: off by 2*pi).
speeds = spindle_speeds("3000 rpm", "24000 rpm", "10 rpm")
print(f"    {len(speeds)} spindle speeds; at 12000 rpm the teeth pass at "
      f"{tooth_passing_hz(12000, cut.teeth):.0f} Hz")

# %%
# (b) The predicted tool point FRF
# --------------------------------
# The built-in assembly is free-free, as the thesis's test rig was: below
# its first flexible mode the FRF is rigid-body motion, which a spindle held
# by its bearings does not have.  The lobes use the band above it.
assembly = default_assembly()
grid = Frequency.from_range("500 Hz", "5000 Hz", "2 Hz")
bare = assembly.receptance("tool.tip:y", frequency=grid)
with_sensor = assembly.attach(Sensor("accelerometer", "tool.tip", "2 g")).receptance("tool.tip:y", frequency=grid)
print("2. Tool point FRF of the built-in assembly, 500-5000 Hz")
print(f"    peaks without sensor: {bare.peaks()} Hz")
print(f"    peaks with a 2 g accelerometer: {with_sensor.peaks()} Hz")

# %%
# (c) Zero-order lobes with and without the accelerometer
# -------------------------------------------------------
# A rotating symmetric tool: x and y receptances are equal (xy_frf(H)).  The
# zero-order method (Altintas and Budak, 1995; the method behind the thesis's
# lobes, Figures 4.5 and 5.2) takes the eigenvalues Lambda of the oriented
# FRF at each chatter frequency and gives, for N teeth,
#
# .. math::
#
#    a_{lim} = -\frac{2\pi \Lambda_R}{N K_t} \left(1 + \left(\frac{\Lambda_I}{\Lambda_R}\right)^2\right)
#
# the chatter frequency and the lobe number fixing the spindle speed.
lobes_bare = zoa(xy_frf(bare), cut, speeds, label="model, no sensor")
lobes_sensor = zoa(xy_frf(with_sensor), cut, speeds, label="model with a 2 g accelerometer")
print("3. Zero-order lobes (Altintas & Budak)")
for lobes in (lobes_bare, lobes_sensor):
    print(f"    {lobes.label}: absolute limit {lobes.absolute_limit_m * 1e3:.3f} mm "
          f"(chatter at {lobes.absolute_limit_frequency_hz:.0f} Hz); best speeds:")
    describe_best(lobes)
(n0, a0), (n1, a1) = lobes_bare.best_speeds(1)[0], lobes_sensor.best_speeds(1)[0]
print(f"    lobes from a tap test with the accelerometer on put the best speed at {n1:.0f} rpm "
      f"({a1 * 1e3:.2f} mm) instead of {n0:.0f} rpm ({a0 * 1e3:.2f} mm); at {n0:.0f} rpm they give "
      f"{lobes_sensor.limit_at(n0)[()] * 1e3:.2f} mm, where the tool without the sensor takes {a0 * 1e3:.2f} mm")
fig = lobes_bare.plot(lobes=True)
lobes_sensor.plot(ax=fig.axes[0], ls="--")
fig.axes[0].set_title("thesis cut on the predicted tool point FRF (zero order)")
save(fig, "lobes_accelerometer.png")

# %%
# (d) A band from an uncertain joint
# ----------------------------------
# The holder-tool stiffness k_yf known to +-20 % (an identification's
# uncertainty): lobes for the ends and the middle of that range.
joint = assembly.joint("holder-tool")
variants = []
for factor in (0.8, 0.9, 1.0, 1.1, 1.2):
    k = {key: Q_(value) * (factor if key == "yf" else 1.0) for key, value in joint.k.as_dict().items()}
    variants.append(assembly.with_joint(Joint(joint.name, joint.between, k=k, c=joint.c.as_dict())))
frfs = sweep(variants, "tool.tip:y", frequency=grid)
members = [zoa(xy_frf(frfs[i]), cut, speeds) for i in range(len(variants))]
band = lobes_band(members, nominal=lobes_bare, label="k_yf of the holder-tool joint +-20 %")
spread = (band.upper_m - band.lower_m) / lobes_bare.depth_limit_m
print("4. Band from the holder-tool stiffness +-20 %")
print(f"    depth limit spread: median {np.median(spread):.0%}, largest {spread.max():.0%} of the nominal")
fig = band.plot()
fig.axes[0].set_title("zero-order lobes over an uncertain holder-tool stiffness")
save(fig, "lobes_band.png")

# %%
# (e) Semi-discretization on fitted modes
# ---------------------------------------
# Semi-discretization needs modes: fit them to the predicted FRF (peak
# picking, then a complex least-squares fit with residual terms).
fitter = ModalFitter().fit(bare)
model = ModalModel(list(fitter.modes_) + [Mode("y", m.frequency, m.damping_ratio, m.stiffness)
                                           for m in fitter.modes_])
print("5. Semi-discretization on the fitted modes")
for m in fitter.modes_:
    print(f"    mode {m.frequency_hz:7.1f} Hz, zeta {m.damping_ratio:.4f}, k {m.stiffness_n_per_m:.3e} N/m")
print(f"    the modes miss the FRF by {fitter.modal_error_:.1%} (with residual terms {fitter.relative_error_:.1%})")
coarse = spindle_speeds("6000 rpm", "22000 rpm", "200 rpm")
lobes_sdm = sdm(model, cut, coarse, label="semi-discretization, fitted modes")
lobes_zoa = zoa(xy_frf(bare), cut, coarse)
ratio = lobes_zoa.depth_limit_m / lobes_sdm.depth_limit_m
print(f"    discretisation: {lobes_sdm.discretisation['intervals_in_cut']} intervals in the cut")
print(f"    zero order / semi-discretization: median {np.median(ratio):.2f}, from {ratio.min():.2f} to "
      f"{ratio.max():.2f}; lowest limits {lobes_zoa.min_limit_m * 1e3:.2f} and {lobes_sdm.min_limit_m * 1e3:.2f} mm")
fig = lobes_bare.plot()
lobes_sdm.plot(ax=fig.axes[0], marker=".", ls="none")
fig.axes[0].set_title("a/D = 0.25: zero order (FRF data) and semi-discretization (fitted modes)")
save(fig, "lobes_zoa_sdm.png")

# %%
# (f) The Insperger-Stepan benchmark
# ----------------------------------
# One mode in the feed direction: 2 teeth, Kt = 6e8 N/m^2, Kn = 2e8 N/m^2,
# f_n = 922 Hz, zeta = 0.011, m = 0.03993 kg, down milling.
m, fn, zeta = 0.03993, 922.0, 0.011
k = m * (2 * np.pi * fn) ** 2
bench = ModalModel([Mode("x", Q_(fn, "Hz"), zeta, Q_(k, "N/m"))])
bench_speeds = spindle_speeds("5000 rpm", "25000 rpm", "50 rpm")
print("6. Insperger-Stepan benchmark")
fig, axes = plt.subplots(2, 1, figsize=(7.5, 7.5), layout="constrained")
for ax, immersion in zip(axes, (1.0, 0.05)):
    c = MillingCut.from_spec(2, "10 mm", immersion=immersion, milling="down", kt="6e8 Pa", kn="2e8 Pa")
    z = zoa(bench, c, bench_speeds, label="zero order")
    s = sdm(bench, c, bench_speeds, label="semi-discretization")
    # Closed form for one mode: h0 = mean of h(t) = sin(phi) (Kt cos(phi) + Kn sin(phi)) over the
    # teeth; the limit is 2 k zeta (1 + zeta) / h0 (chatter above f_n), or 2 k zeta (1 - zeta) / |h0|
    # when h0 < 0 (low-immersion down milling: chatter below f_n).
    h0 = -c.mean_force_matrix()[0, 0]  # N/m^2
    closed = 2 * k * zeta * (1 + zeta) / h0 if h0 > 0 else 2 * k * zeta * (1 - zeta) / -h0
    print(f"    a/D = {immersion:g}: h0 = {h0:.4g} N/m^2; zero-order absolute limit {z.absolute_limit_m * 1e3:.4f} mm, "
          f"closed form {closed * 1e3:.4f} mm")
    r = z.depth_limit_m / s.depth_limit_m
    worst = int(np.argmax(np.abs(np.log(r))))
    a = s.depth_limit_m  # the floors of the lobes: local minima below twice the lowest limit
    floors = [i for i in range(1, a.size - 1) if a[i] <= a[i - 1] and a[i] < a[i + 1] and a[i] < 2 * a.min()]
    print(f"      lobe floors at {', '.join(f'{bench_speeds.m[i]:.0f}' for i in floors)} rpm: zero order / "
          f"semi-discretization {', '.join(f'{r[i]:.2f}' for i in floors)}")
    print(f"      lowest limits: zero order {z.min_limit_m * 1e3:.3f} mm, semi-discretization "
          f"{s.min_limit_m * 1e3:.3f} mm; intervals in the cut {s.discretisation['intervals_in_cut']}")
    print(f"      within 10 % at {np.mean(np.abs(r - 1) <= 0.1):.0%} of the speeds; largest gap at "
          f"{bench_speeds.m[worst]:.0f} rpm: zero order {z.depth_limit_m[worst] * 1e3:.2f} mm, "
          f"semi-discretization {s.depth_limit_m[worst] * 1e3:.2f} mm ({s.bifurcation[worst]})")
    flips = np.array(s.bifurcation) == "flip"
    print(f"      period-doubling (flip) limits at {flips.mean():.0%} of the speeds: the zero order cannot see them")
    z.plot(ax=ax)
    s.plot(ax=ax)
    ax.set_title(f"Insperger-Stepan benchmark, down milling, a/D = {immersion:g}", fontsize="medium")
save(fig, "insperger_stepan_benchmark.png")
