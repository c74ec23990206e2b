"""
A window the file does not declare, read from the noise
=======================================================

The thesis measures the tool point FRF by impact testing (its section 3.3)
and, in chapter 5, shows that a sensor's few grams move its peaks: the
diagnosis finds such a sensor from the FRF alone.  Between the taps and the
FRF file there is the analyser, and most analysers process impact tests
with an exponential window ``exp(-t/tau)`` on the response, and most of
their exports (a CSV, a universal file) do not say so.  The window adds the damping ratio
``1/(tau omega)`` to every mode: the exported FRF is the structure's at
``omega - i/tau``.  Compared at the real frequency, no change of the model
makes that damping, and an exact model is called unexplained.

The same window correlates the noise of neighbouring lines.  The noise
model reads that correlation from the data's own scatter
(``NoiseModel.seen_tau``), and the diagnosis, when the data are not
explained as the file says, tries them again read through the window the
noise shows, and says so first.  This example:

(a) makes a tap test's FRF of the default assembly with a 4 g sensor the
    model lacks, through a window of a fifth of the record, with noise
    through the same window, and writes it to a CSV file with no window line
    (what another analyser exports);
(b) reads the file back: the noise model finds the correlation and the time
    constant;
(c) diagnoses it: explained through the window, the sensor found at its
    mass, and the report's first line saying what was assumed;
(d) draws the data against the model as the file says and through the
    window read.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from substructure import FRF, Frequency, Mass, default_assembly
from substructure.diagnose import diagnose
from substructure.measurements import Measurement
from substructure.updating import Evaluator, Structure, estimate_noise

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


# %%
# (a) A windowed tap test, exported without its window
# ----------------------------------------------------
# Lines every 2 Hz: a record of T = 0.5 s, through a window of tau = 0.1 s.
# The structure (the model with a 4 g sensor on the tip) is evaluated at
# ``omega - i/tau``; the noise, 2 % of the response and a small floor, is
# white noise over the record through the window, transformed, as an
# analyser makes it.
model = default_assembly()
truth = model.attach(Mass("accelerometer", "tool.tip", "4 g"))
hz = np.arange(150.0, 5000.0, 2.0)
record, tau = 0.5, 0.1
through = Evaluator(["tool.tip:y"], ["tool.tip:y"], hz, decay=1.0 / tau)(Structure.from_assembly(truth))[:, 0, 0]
rng = np.random.default_rng(3)


def windowed_noise(n):
    """``n`` lines of unit-RMS complex noise: white over the record, through exp(-t/tau)."""
    samples = 2 * (n + 80)
    t = np.arange(samples) * record / samples
    lines = np.fft.rfft(rng.standard_normal(samples) * np.exp(-t / tau))[75:75 + n]
    return lines / np.sqrt(np.mean(np.abs(lines) ** 2))


data = through * (1 + 0.02 * windowed_noise(hz.size)) + 1e-3 * np.median(np.abs(through)) * windowed_noise(hz.size)
path = out / "20_exported_without_window.csv"
FRF.single(Frequency.from_hz(hz), data, output="tool.tip:y", input="tool.tip:y").to_csv(path, overwrite=True)
print(f"wrote {path} (no '# window_tau_s' line)")

# %%
# (b) The noise tells the window
# ------------------------------
# About a smoother of the data, neighbouring lines' residuals are correlated
# far beyond what independent lines give; the exponential window that
# correlates them as much has the time constant below.
measured = Measurement.from_frf(FRF.from_csv(path), "tool.tip", "tool.tip",
                                file=path.name)
noise = estimate_noise(measured.frf)
print(f"noise floor {noise.floor:.4f}; neighbouring lines counted {noise.correlation:.2f} times fewer; "
      f"window read: tau = {noise.seen_tau:.3g} s (the analyser's: {tau} s)")

# %%
# (c) The diagnosis
# -----------------
# As the file says, the model with or without any change misses the
# window's damping; read through the window the noise shows, the sensor
# explains the data.  The report's first line says what was assumed and
# asks for the analyser's value (``window_tau_s`` in a measurement set).
d = diagnose(model, [measured])
print("explained" if d.explained else "not explained", [f"{e.name} at {e.where}" for e in d.effects])
for e in d.effects:
    print("    " + ", ".join(f"{k} = {v:.4g}" for k, v in e.values.items()))
print("    " + d.report[0])
print("assumed windows:", d.assumed_windows)

# %%
# (d) The data against the model, as the file says and through the window
# ------------------------------------------------------------------------
structure = Structure.from_assembly(d.refined_assembly)
(seen,) = [t for _, t in d.assumed_windows]
as_said = Evaluator(["tool.tip:y"], ["tool.tip:y"], hz)(structure)[:, 0, 0]
as_read = Evaluator(["tool.tip:y"], ["tool.tip:y"], hz, decay=1.0 / seen)(structure)[:, 0, 0]
# The window's damping ratio is ``1/(tau omega)``: about 0.0015 at the first
# mode, a twentieth of its own; its peak (drawn below) is where it shows.
near = (hz > 960.0) & (hz < 1130.0)
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(hz[near], np.abs(data[near]) * 1e6, "k.", ms=3, label="exported FRF")
ax.plot(hz[near], np.abs(as_said[near]) * 1e6, "--", color="tab:gray", label="model found, at the real frequency")
ax.plot(hz[near], np.abs(as_read[near]) * 1e6, color="tab:blue", label=f"model found, through tau = {seen:.3g} s")
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|H| [um/N]")
ax.legend()
ax.set_title("the first mode: the window's damping is in the export, not in any model")
save(fig, "20_undeclared_window.png")
