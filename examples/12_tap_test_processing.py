"""
From hammer taps to an FRF with coherence and a measurement set
===============================================================

A tap test starts as time records: the force of an instrumented hammer and
the response of an accelerometer, one record per tap.  The thesis computes
its FRFs "using the frequency spectrums of the force and the response"
before any identification; this is that step.  This example takes
five real impact records (the pyFRF project's, MIT, shipped with the
package: 25.6 kHz, 1 s each) through ``substructure.tap``:

(a) the records and what each tap looks like (peak force, pulse width, the
    hammer's usable band);
(b) the FRF (H1) with its coherence, converted to receptance, whether an
    exponential window is needed, its peaks and the damping a window adds;
(c) a synthetic double hit added to the taps: rejected with its reason,
    never averaged in;
(d) the result written as a CSV file with a coherence column and a
    measurement set that ``substructure identify`` and ``diagnose`` read;
(e) the same taps as an acquisition system exports them, all in one
    universal file, read back tap by tap;
(f) the three estimators of the same taps, and why a diagnosis compares
    an H2 as the H1 of its taps;
(g) the same taps cut short while their modes still ring: the error the
    end of a tap leaves, which the coherence does not see, estimated from
    the taps and counted;
(h) the same taps as Simcenter Testlab exports them to MATLAB: a signal
    structure per channel, SI values with the factor to the unit shown;
    and the FRF as Testlab exports it, read into a measurement set.

Figures are written to $SUBSTRUCTURE_EXAMPLES_OUT (default: out/examples).
"""

# %%
# Setup
# -----
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pyuff
from scipy.io import savemat

from substructure.datasets import impact_records
from substructure.io.frf_files import write_csv
from substructure.io.measurements import load_measurements
from substructure.io.tap_files import read_tap_mat, read_taps_uff
from substructure.measurements import Measurement
from substructure.plot import plot_taps
from substructure.tap import TapRecord, process_taps

out = Path(os.environ.get("SUBSTRUCTURE_EXAMPLES_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)


def save(fig, name):
    """Write a figure to the output directory; it stays open, so that a notebook shows it."""
    fig.savefig(out / name, dpi=110)
    print(f"    wrote {out / name}")


# %%
# (a) The records
# ---------------
# Each record holds time, force and acceleration.  The hit comes 0.86 ms
# after the first sample; the pulse lasts about 0.3 ms (a hard tip).
records = impact_records()
for r in records:
    print(f"{r.source}: {len(r)} samples at {r.sample_rate:g} Hz, peak force {r.force.max():.1f} N")

fig, (ax_f, ax_x) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
r = records[0]
ax_f.plot(r.time * 1e3, r.force, lw=0.8)
ax_f.set_ylabel("force [N]")
ax_x.plot(r.time * 1e3, r.response, lw=0.5)
ax_x.set_ylabel("acceleration [m/s²]")
ax_x.set_xlabel("time [ms]")
ax_x.set_xlim(0, 60)
fig.suptitle("the first tap: a short pulse, a long ringing response")
save(fig, "12_tap_record.png")

# %%
# (b) H1 and the coherence
# ------------------------
# The force is kept in a rectangular window around the pulse.  An
# exponential window exp(-t/tau) on both channels stops a response that has
# not died out by the end of the tap from leaking, but it adds a damping
# ratio 1/(tau omega) to every mode, which a model compared with the FRF
# lacks.  So by default it is applied only when the response has not died
# out (the result says which, and why); these taps ring down within their
# second.  Asked for, with tau chosen so that 1 % is left at the end of the
# tap, its added damping is reported with each peak and left in the FRF.
result = process_taps(records)
for tap in result.taps:
    print(f"tap {tap.number}: peak {tap.peak_force:.1f} N, pulse {tap.pulse_width_s * 1e3:.2f} ms, "
          f"usable band {tap.band_hz:.0f} Hz")
hz = result.frf.frequency.hz
band = (hz >= 20) & (hz <= 5000)
print(f"{result.averages} taps averaged; hammer's band up to {result.hammer_band_hz:.0f} Hz")
print(f"exponential window: {result.window}")
print(f"median coherence 20 Hz - 5 kHz: {np.median(result.coherence[band]):.4f}")
windowed = process_taps(records, exponential=True)
print(f"with the window asked for: tau = {windowed.tau:.3f} s")
for f in windowed.peaks(20, 5000):
    print(f"  peak {f:6.0f} Hz, added damping ratio {windowed.added_damping(f):.1e}")
save(plot_taps(result, title="pyFRF impact records"), "12_tap_frf.png")

# %%
# (c) A double hit is rejected
# ----------------------------
# The hammer bounces: a second pulse 0.195 s after the first.  The tap is
# listed with its reason and the FRF is that of the five good taps.
bounced = records[0].force.copy()
bounced[5000:5008] += records[0].force[20:28]
double = TapRecord(records[0].time, bounced, records[0].response, "acceleration", "bounce.csv")
with_bounce = process_taps([*records, double])
for tap in with_bounce.rejected:
    print(f"tap {tap.number} ({tap.source}) rejected: {tap.reason}")
same = np.allclose(with_bounce.frf.data, result.frf.data)
print(f"{with_bounce.averages} taps averaged; the FRF equals the one without the bounced tap: {same}")

# %%
# (d) The measurement set
# -----------------------
# The receptance with its coherence column, and a set naming it with the
# number of averages; reading the set gives both back.
# (overwrite=True: this example's own output, written anew on each run)
write_csv(result.frf, out / "12_tool_tip.csv", overwrite=True, coherence=result.coherence)
(out / "12_tests.toml").write_text(
    'name = "pyFRF impact records"\n\n[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
    f'file = "12_tool_tip.csv"\nquantity = "receptance"\naverages = {result.averages}\n'
)
measurement = load_measurements(out / "12_tests.toml").measurements[0]
print(f"read back: {measurement.describe()}, {measurement.averages} averages, "
      f"coherence on {measurement.coherence.size} lines")

# %%
# (e) A file of several taps
# --------------------------
# Acquisition systems often export a test's hits into one universal file: a
# force record (specific data type 13, in N) and a response record (type 12,
# here in g) per tap.  ``read_taps_uff`` pairs the k-th force with the k-th
# response (``substructure tap FILE.uff`` does the same) and the FRF is that
# of the taps read one by one.
uff_path = out / "12_taps.uff"
uff_path.unlink(missing_ok=True)
uff = pyuff.UFF(str(uff_path))
for k, r in enumerate(records):
    for node, data, spec, unit in ((1, r.force, 13, "N"), (2, r.response / 9.80665, 12, "g")):
        uff.write_sets(pyuff.prepare_58(
            binary=0, func_type=1, rsp_node=node, rsp_dir=3, ref_node=1, ref_dir=3, data=data, x=r.time - r.time[0],
            num_pts=data.size, abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=1.0 / r.sample_rate,
            abscissa_spec_data_type=17, abscissa_axis_units_lab="s", ordinate_spec_data_type=spec,
            ordinate_axis_units_lab=unit, orddenom_spec_data_type=0, orddenom_axis_units_lab="",
            z_axis_spec_data_type=0, z_axis_axis_units_lab="",
            id1=f"tap {k + 1} {'force' if node == 1 else 'response'}"), mode="add")
taps = read_taps_uff(uff_path)
print(f"{uff_path.name}: {len(taps)} taps, {taps[0].sample_rate:g} Hz, response in {taps[0].quantity}")
from_file = process_taps(taps)
close = np.allclose(from_file.frf.data, result.frf.data, rtol=1e-5, atol=1e-6 * np.abs(result.frf.data).max())
print(f"{from_file.averages} taps averaged; the FRF equals the one from the arrays (to the file's 6 digits): {close}")

# %%
# (f) H1, H2 and Hv
# -----------------
# H1 = Gfx/Gff is unbiased by the response's noise, H2 = Gxx/Gxf by the
# force's, and Hv (total least squares) lies between them.  Of one set of
# spectra, H1 = gamma^2 H2 exactly: where the coherence is low, H2 lies
# above the FRF by 1/gamma^2, a bias more taps do not remove.  A
# measurement set written by ``substructure tap`` says which estimator it
# holds (``estimator``), and the diagnosis and the fits compare an H2 that
# carries its coherence as ``gamma^2 H2`` (``Measurement.h1_frf``): the
# H1 of the same taps.
h1, h2, hv = (process_taps(records, e) for e in ("H1", "H2", "Hv"))
low = band & (result.coherence < 0.99)
print(f"{low.sum()} lines of 20 Hz - 5 kHz with a coherence below 0.99; there |H2/H1| reaches "
      f"{np.abs(h2.frf.data[low, 0, 0] / h1.frf.data[low, 0, 0]).max():.3g}")
between = np.all(np.abs(h1.frf.data) <= np.abs(hv.frf.data) * (1 + 1e-9)) and \
    np.all(np.abs(hv.frf.data) <= np.abs(h2.frf.data) * (1 + 1e-9))
print(f"|H1| <= |Hv| <= |H2| on every line: {between}")
as_h2 = Measurement.from_frf(h2.frf, "tool.tip", "tool.tip", coherence=h2.coherence, averages=h2.averages,
                             estimator="H2")
same = np.allclose(as_h2.h1_frf.data, h1.frf.data, rtol=1e-9, atol=0.0)
print(f"the H2 measurement compared as gamma^2 H2 equals H1: {same}")
fig, (ax, ax_c) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
for name, r in (("H2", h2), ("Hv", hv), ("H1", h1)):
    ax.semilogy(hz[band], np.abs(r.frf.data[band, 0, 0]), lw=0.8, label=name)
ax_c.plot(hz[band], result.coherence[band], lw=0.8, color="k")
ax.set_xlim(2500, 3800)  # a band of low coherence between two modes
ax.set_ylabel("|receptance| [m/N]")
ax_c.set_ylabel("coherence")
ax_c.set_xlabel("frequency [Hz]")
ax.legend()
ax.set_title("three estimators of the same taps: apart where the coherence is low")
save(fig, "12_estimators.png")


# %%
# (g) A tap cut short
# -------------------
# This structure's lightest modes still ring after a second.  Cut to
# 0.25 s, the taps leave out the rest of the response: every tap repeats
# that error, so the coherence does not see it.  The processing estimates
# it from the taps' last samples (``TapResult.truncation``; the exponential
# window is kept for responses ringing above 10 % of their peak, since its
# damping is an error no model shares) and the diagnosis's noise model
# counts it.  Against the FRF of the whole second, the difference is that
# error.  The estimate is conservative (for lightly damped modes several
# times the error between them): it says where a short record cannot be
# trusted, not what the rest of the response was.
n = int(0.25 * records[0].sample_rate)
short = process_taps([TapRecord(r.time[:n], r.force[:n], r.response[:n], r.quantity, r.source) for r in records])
print(f"0.25 s taps: {short.window}")
lines = np.searchsorted(hz, short.frf.frequency.hz)
difference = np.abs(short.frf.data[:, 0, 0] / result.frf.data[lines, 0, 0] - 1.0)
gamma = np.clip(short.coherence, 1e-3, 1.0)
scatter = np.sqrt((1.0 - gamma) / (2 * short.averages * gamma))  # H1's noise, from the coherence
estimate = np.sqrt(short.truncation)
cut_band = (short.frf.frequency.hz > 20) & (short.frf.frequency.hz < 5000)
print(f"difference from the 1 s FRF: median {np.median(difference[cut_band]):.1%}; within the coherence's noise on "
      f"{np.mean(difference[cut_band] <= scatter[cut_band]):.0%} of the lines, within the truncation's estimate "
      f"(and the noise) on {np.mean(difference[cut_band] <= np.hypot(estimate, scatter)[cut_band]):.0%}")
error_at, where = short.truncation_error()
print(f"largest estimated error {error_at:.2g} (relative) near {where:.0f} Hz")
fig, ax = plt.subplots(figsize=(7, 3.5))
f_short = short.frf.frequency.hz
ax.semilogy(f_short[cut_band], difference[cut_band], lw=0.8, color="k", label="difference from the 1 s FRF")
ax.semilogy(f_short[cut_band], estimate[cut_band], lw=0.8, label="truncation's estimate")
ax.semilogy(f_short[cut_band], scatter[cut_band], lw=0.8, label="noise from the coherence")
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("relative error")
ax.legend(fontsize=8)
ax.set_title("taps cut at 0.25 s: an error the coherence does not see")
fig.tight_layout()
save(fig, "12_truncation.png")


# %%
# (h) A Simcenter Testlab export to MATLAB
# ----------------------------------------
# Testlab writes each channel as a struct: ``x_values`` (the time step in
# ``increment``), ``y_values`` (the samples, stored in SI, and
# ``quantity.label`` with the ``unit_transformation`` factor to the unit
# shown: 1/9.80665 for g) and ``function_record.name``.  ``read_tap_mat``
# (and ``substructure tap FILE.mat``) takes the unit and the clock from
# them; nothing else needs saying.
def testlab_signal(values, label, factor, channel, fs):
    return {"x_values": {"start_value": 0.0, "increment": 1.0 / fs, "number_of_values": values.size,
                         "quantity": {"label": "s"}},
            "y_values": {"values": values, "quantity": {"label": label,
                                                        "unit_transformation": {"factor": factor, "offset": 0.0}}},
            "function_record": {"name": channel, "type": "Signal"}}


first = records[0]
mat_path = out / "12_testlab_tap1.mat"
savemat(mat_path, {"Signal_0": testlab_signal(first.force, "N", 1.0, "Hammer", first.sample_rate),
                   "Signal_1": testlab_signal(first.response, "g", 1 / 9.80665, "Tip:+Y", first.sample_rate)})
read_back = read_tap_mat(mat_path)
print(f"{mat_path.name}: force {read_back.force_column}, response {read_back.response_column}, "
      f"{read_back.sample_rate:g} Hz; the samples are the record's: "
      f"{np.allclose(read_back.response, first.response, rtol=1e-12, atol=0)}")

# %%
# Testlab exports its FRFs the same way: complex values on an axis in Hz,
# here an accelerance stored in SI with the factor to g/N, and a coherence
# beside it.  A measurement set names the file; the unit says the quantity,
# and ``record`` / ``coherence_record`` count its channels on a frequency
# axis from 0.
hz = result.frf.frequency.hz
keep = hz > 0
accelerance = -(2 * np.pi * hz[keep]) ** 2 * result.frf.data[keep, 0, 0]
frf_struct = testlab_signal(accelerance, "g/N", 1 / 9.80665, "H1 Tip:+Y/Hammer", first.sample_rate)
frf_struct["x_values"].update(start_value=hz[keep][0], increment=hz[1] - hz[0], quantity={"label": "Hz"})
coherence_struct = testlab_signal(result.coherence[keep], "", 1.0, "Coherence Tip:+Y", first.sample_rate)
coherence_struct["x_values"] = frf_struct["x_values"]
savemat(out / "12_testlab_frf.mat", {"FRF": frf_struct, "Coherence": coherence_struct})
(out / "12_tests_testlab.toml").write_text(
    'name = "pyFRF impact records, Testlab export"\n\n[[frf]]\nresponse = "tool.tip"\nexcitation = "tool.tip"\n'
    f'file = "12_testlab_frf.mat"\nrecord = 0\ncoherence_record = 1\naverages = {result.averages}\n'
)
from_testlab = load_measurements(out / "12_tests_testlab.toml").measurements[0]
receptance = from_testlab.frf.to_receptance().data[:, 0, 0]
print(f"read back: {from_testlab.describe()}, read from g/N and held as a {from_testlab.frf.quantity}; it equals "
      f"the CSV's: {np.allclose(receptance, result.frf.data[keep, 0, 0], rtol=1e-9)}")
