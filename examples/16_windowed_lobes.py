"""
Stability lobes from a windowed tap test: the window's damping taken out
========================================================================

The thesis's end use of a tool point FRF is the stability lobe diagram:
the depth of cut that chatters first at each spindle speed grows with the
damping of the tool point's modes.  A tap whose response still rings at the
end of the record is processed through an exponential window
``exp(-t/tau)``, which adds the damping ratio ``1/(tau omega)`` to every
mode.  Lobes read from that FRF as it is promise depths the tool cannot
take.  This example:

(a) simulates 0.2 s taps of a tool point with two modes (1 % and 2 %
    damping), processes them through the window that leaves 1 % at the end,
    and writes the FRF file as ``substructure tap`` does (its
    ``# window_tau_s`` line);
(b) fits the modes of the windowed FRF and removes the window from each
    (``window_removed``): the same modal mass and damped frequency, the
    decay rate less ``1/tau``;
(c) draws the zero-order lobes of the structure, of the FRF as measured and
    of the corrected FRF: the measured one's limits are 1.6 times the
    structure's, the corrected one's are the structure's.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import FRF
from substructure.errors import WindowedFRFWarning
from substructure.io.frf_files import read_csv_window, write_csv
from substructure.stability import MillingCut, ModalModel, Mode, spindle_speeds, window_removed, xy_frf, zoa
from substructure.tap import TapRecord, process_taps

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


# %%
# (a) Taps that still ring, processed through the window
# ------------------------------------------------------
# The tool point: two modes in x (and the same in y, a symmetric tool).  The
# response is the receptance times the force's spectrum, transformed back
# over 4 s (the modes have died out by then), of which 0.2 s are kept: the
# 1 % mode still rings at 4 % of its peak at the end.
structure = ModalModel([Mode(d, f, z, k) for d in "xy"
                        for f, z, k in (("650 Hz", 0.01, "3e6 N/m"), ("1400 Hz", 0.02, "8e6 N/m"))])
rate, kept = 10240.0, 0.2
n = int(4.0 * rate)
hz = np.fft.rfftfreq(n, 1.0 / rate)
receptance = np.zeros(hz.size, complex)
receptance[1:] = structure.receptance(hz[1:])[:, 0, 0]
t = np.arange(n) / rate
rng = np.random.default_rng(3)
records = []
for k, peak in enumerate((50.0, 65.0, 80.0)):
    force = peak * np.exp(-0.5 * ((t - 0.005) / 1e-4) ** 2)
    response = np.fft.irfft(np.fft.rfft(force) * receptance, n)[: int(kept * rate)]
    force = force[: response.size] + rng.normal(0.0, 1e-4 * peak, response.size)
    response = response + rng.normal(0.0, 1e-4 * np.abs(response).max(), response.size)
    records.append(TapRecord(t[: response.size], force, response, "displacement", f"tap {k + 1}"))
result = process_taps(records, exponential=True)
print(f"window: tau = {result.tau:.4g} s ({result.window})")
frf = result.frf.crop(100.0, 3000.0)
path = out / "16_windowed_tap.csv"
write_csv(frf, path, overwrite=True, window_tau=result.tau)  # this example's own output, written anew each run
print(f"    wrote {path}; its window line says tau = {read_csv_window(path):.4g} s")

# %%
# (b) The modes fitted, the window taken out of each
# --------------------------------------------------
# ``FRF.from_csv`` reads the data as they are, and warns that the window is
# in them; ``window_removed`` fits the modes (per direction) and gives the
# data with each mode's window damping removed.
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", WindowedFRFWarning)
    measured = FRF.from_csv(path)
print("warned:", caught[0].message if caught else "nothing")
fixed = window_removed(xy_frf(measured), read_csv_window(path))
for line in fixed.describe():
    if line.startswith("x"):
        print("    " + line)
print("    the structure's: 1.000 % and 2.000 %")

fig, ax = plt.subplots(figsize=(7, 4))
lines = measured.frequency.hz
ax.semilogy(lines, np.abs(structure.receptance(lines)[:, 0, 0]) * 1e6, color="tab:gray", lw=3, alpha=0.5,
            label="the structure")
ax.semilogy(lines, np.abs(measured.data[:, 0, 0]) * 1e6, "k--", lw=1, label="measured through the window")
ax.semilogy(lines, np.abs(fixed.frf.data[:, 0, 0]) * 1e6, color="tab:blue", lw=1, label="window taken out")
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|H| [um/N]")
ax.set_title(f"0.2 s taps through a window of tau = {result.tau * 1e3:.0f} ms")
ax.legend()
save(fig, "16_windowed_frf.png")

# %%
# (c) The lobes: as measured, and with the window taken out
# ---------------------------------------------------------
# A slot in aluminium with a two-flute 10 mm cutter.  The window's damping
# raises every lobe; taken out, the lobes are the structure's on the
# measured lines.
cut = MillingCut(2, "10 mm", "10 mm", kt="7e8 Pa", kn="2.1e8 Pa", milling="down")
speeds = spindle_speeds("4000 rpm", "30000 rpm", "20 rpm")
truth = zoa(structure.xy_frf(measured.frequency), cut, speeds)
as_measured = zoa(xy_frf(measured), cut, speeds)
corrected = zoa(fixed.frf, cut, speeds)
for name, lobes in (("structure", truth), ("as measured", as_measured), ("window taken out", corrected)):
    print(f"{name:>17}: absolute limit {lobes.absolute_limit_m * 1e3:.3f} mm, lowest depth limit "
          f"{lobes.depth_limit_m.min() * 1e3:.3f} mm")
fig, ax = plt.subplots(figsize=(7, 4))
rpm = truth.spindle_speed_rpm
ax.plot(rpm, truth.depth_limit_m * 1e3, color="tab:gray", lw=3, alpha=0.5, label="the structure")
ax.plot(rpm, as_measured.depth_limit_m * 1e3, "k--", lw=1, label="FRF as measured")
ax.plot(rpm, corrected.depth_limit_m * 1e3, color="tab:blue", lw=1, label="window taken out")
ax.set_xlabel("spindle speed [rpm]")
ax.set_ylabel("depth limit [mm]")
ax.set_ylim(0, 1.2 * as_measured.depth_limit_m.max() * 1e3)
ax.legend()
save(fig, "16_windowed_lobes.png")
