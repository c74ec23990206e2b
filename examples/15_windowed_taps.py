"""
Short taps through an exponential window, compared as they were measured
=========================================================================

The thesis identifies contact damping from measured tool point FRFs (its
eq. 2.3 and the fits after it): the damping of the joints is read from the
height of the FRF's peaks.  A tap whose response still rings at the end of
the record is often processed through an exponential window
``exp(-t/tau)`` on both channels.
The window adds the damping ratio ``1/(tau omega)`` to every mode: the FRF
it gives is the structure's at the complex frequency ``omega - i/tau``,
exactly, whatever the force's shape.  A model compared with it on the real
frequency lines lacks that damping, and a diagnosis or a joint
identification then takes the window's damping for the joints'.  This
example:

(a) simulates 60 ms taps of the default assembly carrying a 20 g clamping
    nut the model does not have (a Gaussian hammer pulse, noise on both
    channels) and processes them through a 15 ms window;
(b) draws the measured FRF against the model on the real lines and at the
    complex frequency: the window's damping is in the second, as in the data;
(c) diagnoses the taps with the model seen through the window (the nut,
    found at its mass and place) and on the real lines (the window's damping
    read as the structure's);
(d) shows how neighbouring lines of a windowed FRF share their noise: the
    fits and tests count the data as that many times fewer lines.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import attrs
import matplotlib.pyplot as plt
import numpy as np

from substructure import Frequency, Mass, default_assembly
from substructure.diagnose import DiagnoseSettings, diagnose
from substructure.measurements import Measurement
from substructure.tap import TapRecord, process_taps
from substructure.updating import Evaluator, Structure, window_correlation

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


# %%
# (a) Short taps, processed through a window
# ------------------------------------------
# The response is the accelerance times the force's spectrum, transformed
# back over 2 s (the impulse response has died out long before), of which
# 60 ms are kept: the modes still ring at the end.
model = default_assembly()
truth = model.attach(Mass("nut", "holder.tip", "20 g"))
rate, kept = 20480.0, 0.06
n = int(2.0 * rate)
f = np.fft.rfftfreq(n, 1.0 / rate)
accelerance = np.empty(f.size, complex)
accelerance[1:] = -((2 * np.pi * f[1:]) ** 2) * truth.frf("tool.tip:y", "tool.tip:y", Frequency.from_hz(f[1:])).data[
    :, 0, 0]
accelerance[0] = accelerance[1]
t = np.arange(n) / rate
rng = np.random.default_rng(7)
records = []
for k, peak in enumerate((60.0, 75.0, 90.0, 70.0, 80.0)):
    force = peak * np.exp(-0.5 * ((t - 0.0055) / 68e-6) ** 2)  # a smooth pulse: nothing beyond the Nyquist line
    response = np.fft.irfft(np.fft.rfft(force) * accelerance, n)[: int(kept * rate)]
    force = force[: response.size] + rng.normal(0.0, 1e-4 * peak, response.size)
    response = response + rng.normal(0.0, 1e-4 * np.abs(response).max(), response.size)
    records.append(TapRecord(t[: response.size], force, response, "acceleration", f"tap {k + 1}"))

result = process_taps(records, exponential=True, tau=0.015)
print(f"window: tau = {result.tau} s ({result.window}); lines every {result.frf.frequency.hz[1]:.1f} Hz")
measured = Measurement.from_frf(result.frf, "tool.tip", "tool.tip", coherence=result.coherence,
                                averages=result.averages, force_noise=result.force_noise,
                                force_window_s=result.force_window_s, estimator="H1", window_tau=result.tau,
                                truncation=result.truncation).crop(150.0, 5000.0)

# %%
# (b) The model on the real lines, and as the window sees it
# ----------------------------------------------------------
# ``Evaluator(..., decay=1/tau)`` evaluates the model at ``omega - i/tau``:
# the compiled beam kernels, the joints and the bodies all take the complex
# frequency.  The model without the nut is drawn: the window's damping is in
# the data and in the second curve, not in the first.
hz = measured.frf.frequency.hz
structure = Structure.from_assembly(model)
on_real_lines = Evaluator(["tool.tip:y"], ["tool.tip:y"], hz)(structure)[:, 0, 0]
through_window = Evaluator(["tool.tip:y"], ["tool.tip:y"], hz, decay=1.0 / result.tau)(structure)[:, 0, 0]
fig, ax = plt.subplots(figsize=(7, 4))
ax.semilogy(hz, np.abs(measured.frf.data[:, 0, 0]) * 1e6, "k", lw=1.5, label="measured through the window")
ax.semilogy(hz, np.abs(on_real_lines) * 1e6, "--", color="tab:gray", label="model on the real lines")
ax.semilogy(hz, np.abs(through_window) * 1e6, color="tab:blue", label="model at omega - i/tau")
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|H| [um/N]")
ax.legend()
ax.set_title("a 15 ms window on 60 ms taps: its damping is in the data")
save(fig, "15_windowed_frf.png")

# %%
# (c) The diagnosis, through the window and on the real lines
# -----------------------------------------------------------
# The measurement's ``window_tau`` tells the diagnosis how it was taken.
# Without it (the same FRF compared on the real lines), the window's damping
# is read as the structure's.
d = diagnose(model, [measured], progress=False)
print("through the window:", "explained" if d.explained else "not explained")
for e in d.effects:
    print(f"    {e.name} at {e.where}: " + ", ".join(f"{k} = {v:.4g}" for k, v in e.values.items()))
print("    " + next(line for line in d.report if "exponential window" in line))
quick = DiagnoseSettings(place_search=0)
plain = diagnose(model, [attrs.evolve(measured, window_tau=None)], progress=False, settings=quick)
print("on the real lines:", "explained" if plain.explained else "not explained",
      [f"{e.name} at {e.where}" for e in plain.effects])

# %%
# (d) Neighbouring lines share their noise
# ----------------------------------------
# Through the window the noise of lines ``k`` apart is correlated by
# ``1 / (1 + (pi k tau / T)^2)``; a sum of line scores varies
# ``(T/tau) coth(T/tau)`` times as much as one of independent lines.
taus = np.geomspace(0.1, 10.0, 50) * kept
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.loglog(kept / taus, [window_correlation(tau, 1.0 / kept) for tau in taus])
ax.axvline(kept / result.tau, color="tab:red", lw=0.8, label=f"this test: T/tau = {kept / result.tau:.1f}")
ax.set_xlabel("T / tau")
ax.set_ylabel("lines counted as one")
ax.legend()
save(fig, "15_window_correlation.png")
