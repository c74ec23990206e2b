"""The ``substructure`` command: the library's workflows without writing code.

Subcommands (formats.md, "The `substructure` command"):

``substructure frf ASSEMBLY.toml --at POINT[:dof] [--to POINT[:dof]] [--grid START:STOP:STEP]
[--out FILE.csv|.uff] [--plot FILE.png] [--json]``
    A receptance of an assembly file, with its peaks; written to a CSV or UFF
    file and plotted on request.
``substructure lobes (--assembly A.toml --at POINT | --frf X.csv [--frf-y Y.csv] | --modes MODES.csv)
--teeth N --diameter D (--radial-depth A | --immersion RATIO) --kt P (--kn P | --kr RATIO) [--method zoa|sdm]
[--speeds START:STOP:STEP] [--plot FILE.png] [--json]``
    Stability lobes of a milling (or ``--turning``) cut (docs/stability.md).
``substructure demo [--out DIR]``
    The workflow on the built-in assembly, as a list of steps (:data:`DEMO_STEPS`).

Every subcommand prints a human summary, or with ``--json`` exactly one JSON
object (SI units, Hz) and nothing else on standard output.  A user's mistake
prints ``substructure: error: ...`` on standard error and returns 1 (2 for
misuse of the options), never a traceback; warnings print once each as
``substructure: warning: ...`` on standard error.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings
from pathlib import Path
from typing import Any, Callable

import attrs
import numpy as np

from .errors import SubstructureError
from .frf import FRF, Frequency
from .io.assembly_toml import default_assembly, load_assembly
from .points import parse_point
from .units import Q_

__all__ = ["main", "DEMO_STEPS", "DemoState"]

PROG = "substructure"
TOOL_POINT = "tool.tip:y"
"""The tool point of the built-in assembly."""


class _UsageError(Exception):
    """Misuse of the command line (exit status 2)."""


class _Parser(argparse.ArgumentParser):
    """An argument parser that raises instead of printing usage and exiting."""

    def error(self, message: str):
        raise _UsageError(message)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _range_of(text: str, unit: str, build: Callable, example: str):
    """``START:STOP:STEP`` of quantities: plain numbers are in ``unit``, units may be written."""
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected START:STOP:STEP, e.g. {example}")
    values: list[Any] = []
    for part in parts:
        try:
            values.append(Q_(float(part), unit))
        except ValueError:
            values.append(part.strip())
    try:
        return build(*values)
    except SubstructureError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {_one_line(str(exc))}") from None


def _grid(text: str) -> Frequency:
    """``START:STOP:STEP`` in Hz, or with units (``"20 Hz:5 kHz:2 Hz"``)."""
    return _range_of(text, "Hz", Frequency.from_range, "20:5000:2 (Hz) or '20 Hz:5 kHz:2 Hz'")


def _point(text: str) -> str:
    """A point name with its DOF, ``y`` when none is given."""
    ref = parse_point(text)
    return str(attrs.evolve(ref, dof=ref.dof or "y"))


def _peak_table(frf: FRF) -> list[tuple[float, float]]:
    """``(frequency in Hz, |FRF|)`` of the peaks of a one-entry FRF, ascending."""
    peaks = frf.peaks()
    magnitude = np.abs(frf.data[:, 0, 0])
    index = np.searchsorted(frf.frequency.hz, peaks)
    return [(float(f), float(magnitude[i])) for f, i in zip(peaks, index)]


def _grid_text(frequency: Frequency) -> str:
    return f"{frequency.start:g} Hz to {frequency.stop:g} Hz, {frequency.n} lines"


def _save_figure(fig, path) -> None:
    """Save a figure to an image file and close it (Agg: files only, no display needed)."""
    import matplotlib.pyplot as plt

    try:
        fig.savefig(path, dpi=120)
    finally:
        plt.close(fig)


def _figures() -> None:
    """Select matplotlib's file-only backend before any figure is made."""
    import matplotlib

    matplotlib.use("Agg")


def _save_plot(frf: FRF, path: str | os.PathLike, title: str) -> None:
    _figures()
    fig = frf.plot()
    fig.suptitle(title)
    _save_figure(fig, path)


def _write_frf(frf: FRF, path: str) -> None:
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        frf.to_csv(path)
    elif suffix in (".uff", ".unv"):
        frf.to_uff(path)
    else:  # checked before computing; kept for callers of this helper
        raise _UsageError(f"argument --out: {path!r}: expected a .csv or .uff file")


# -- frf ------------------------------------------------------------------------------


def _run_frf(args: argparse.Namespace) -> int:
    if args.out and Path(args.out).suffix.lower() not in (".csv", ".uff", ".unv"):
        raise _UsageError(f"argument --out: {args.out!r}: expected a .csv or .uff file")
    assembly = load_assembly(args.assembly)
    at = _point(args.at)
    to = _point(args.to) if args.to else at
    frequency = args.grid or assembly.frequency
    if frequency is None:
        raise _UsageError(
            f"{args.assembly} has no [frequency] table; give the grid with --grid START:STOP:STEP"
        )
    frf = assembly.receptance(at, to, frequency)
    peaks = _peak_table(frf)
    written = []
    if args.out:
        _write_frf(frf, args.out)
        written.append(args.out)
    if args.plot:
        _save_plot(frf, args.plot, f"{assembly.name}: {at} / {to}")
        written.append(args.plot)
    if args.json:
        values = frf.data[:, 0, 0]
        print(json.dumps({
            "frequency_hz": frf.frequency.hz.tolist(),
            "real": values.real.tolist(),
            "imag": values.imag.tolist(),
            "peaks_hz": [f for f, _ in peaks],
        }))
        return 0
    unit = frf.unit(frf.outputs[0], frf.inputs[0])
    print(f"assembly: {assembly.name}")
    print(f"receptance: response {at}, excitation {to} [{unit}]")
    print(f"grid: {_grid_text(frf.frequency)}")
    print("peaks:" if peaks else "peaks: none inside the grid")
    for f, m in peaks:
        print(f"  {f:10.6g} Hz   |FRF| = {m:.4g} {unit}")
    for path in written:
        print(f"wrote {path}")
    return 0


# -- demo -----------------------------------------------------------------------------


@attrs.define
class DemoState:
    """What the demo steps share: the output directory, results so far, files written."""

    out: Path
    assembly: Any = None
    frf: FRF | None = None
    results: dict = attrs.field(factory=dict)
    files: list = attrs.field(factory=list)
    lines: list = attrs.field(factory=list)
    taps: Any = None


def _demo_load(state: DemoState) -> None:
    state.assembly = default_assembly()
    state.lines.append(state.assembly.describe())
    state.results["components"] = [c.name for c in state.assembly.components]
    state.results["joints"] = [j.name for j in state.assembly.joints]


def _demo_frf(state: DemoState) -> None:
    state.frf = state.assembly.receptance(TOOL_POINT)
    peaks = _peak_table(state.frf)
    tool_mode = max(peaks, key=lambda p: p[1])[0] if peaks else None
    state.results["peaks_hz"] = [f for f, _ in peaks]
    state.results["tool_mode_hz"] = tool_mode
    state.lines.append(f"tool point FRF ({TOOL_POINT}) on {_grid_text(state.frf.frequency)}")
    state.lines.append("peaks: " + ", ".join(f"{f:g} Hz" for f, _ in peaks))
    if tool_mode is not None:
        state.lines.append(f"tool mode (highest peak): {tool_mode:g} Hz")
    path = state.out / "tool_point_frf.csv"
    state.frf.to_csv(path)
    state.files.append(str(path))


def _demo_plot(state: DemoState) -> None:
    path = state.out / "tool_point_frf.png"
    _save_plot(state.frf, path, f"{state.assembly.name}: tool point FRF")
    state.files.append(str(path))


def _demo_assembly_file(state: DemoState) -> None:
    import importlib.resources

    path = state.out / "default_assembly.toml"
    text = (importlib.resources.files("substructure") / "data" / "default_assembly.toml").read_text("utf-8")
    path.write_text(text, encoding="utf-8")  # the packaged file, with its comments
    state.files.append(str(path))


def _demo_tap_test(state: DemoState) -> None:
    """A tap test of the built-in assembly with something the model does not know about."""
    from .joints import Sensor
    from .measurements import MeasurementSet
    from .synthetic import simulate, write_measurement_set

    rig = state.assembly.attach(Sensor("forgotten-accelerometer", "tool.tip", "2 g"))
    taps = simulate(rig, ["tool.tip"], frequency=state.assembly.frequency, noise=0.015, seed=2026,
                    sensors=["forgotten-accelerometer"], name="demo tap test (1.5 % noise)")
    # the measurement file does not mention the sensor: the test report forgot it
    taps = MeasurementSet(taps.name, tuple(attrs.evolve(m, sensors=()) for m in taps))
    state.results["measurements"] = str(write_measurement_set(taps, state.out / "tap_test", overwrite=True))
    state.lines.append("a simulated tap test of the tool point, 1.5 % noise, with a 2 g accelerometer "
                       "that the test report forgot to mention")
    state.files.append(state.results["measurements"])
    state.taps = taps


def _demo_diagnose(state: DemoState) -> None:
    """Model against tap test: where it fails, what is missing, the error falling."""
    _figures()
    from .diagnose import diagnose
    from .io.assembly_toml import save_assembly

    result = diagnose(state.assembly, state.taps)
    state.results["diagnosis"] = result.to_json()
    state.lines.append(f"diagnosis: error {result.baseline_error:.3f} against a noise floor of "
                       f"{result.noise_floor:.3f}; missing effect: {result.missing_effect} at "
                       f"{result.missing_where}")
    for step in result.refinement:
        what = "model as given" if step.added is None else f"+ {step.added.name} at {step.added.where}"
        state.lines.append(f"  step {step.step}: {what:45s} error {step.error:.4f}")
    for name, make in (("where_it_fails.png", result.plot_where), ("error_fall.png", result.plot_history)):
        fig = make()
        _save_figure(fig, state.out / name)
        state.files.append(str(state.out / name))
    path = state.out / "improved_assembly.toml"
    save_assembly(result.refined_assembly, path, overwrite=True)
    state.files.append(str(path))


DEMO_STEPS: list[tuple[str, Callable[[DemoState], None]]] = [
    ("load the built-in assembly", _demo_load),
    ("compute the tool point FRF", _demo_frf),
    ("plot the tool point FRF", _demo_plot),
    ("write the assembly file to start from", _demo_assembly_file),
    ("simulate a tap test with a hidden effect", _demo_tap_test),
    ("diagnose the model against the tap test", _demo_diagnose),
]
"""The demo's steps, in order: ``(title, function(state))``; append to add steps."""


def _run_demo(args: argparse.Namespace) -> int:
    state = DemoState(out=Path(args.out))
    state.out.mkdir(parents=True, exist_ok=True)
    for _title, step in DEMO_STEPS:
        step(state)
    if args.json:
        print(json.dumps({**state.results, "files": state.files}))
        return 0
    print("\n".join(state.lines))
    for path in state.files:
        print(f"wrote {path}")
    return 0


# -- identify -------------------------------------------------------------------------


def _band(text: str):
    if text == "auto":
        return "auto"
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected auto or LO:HI in Hz, e.g. 1200:1700") from None
    if not lo < hi:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected LO < HI")
    return (lo, hi)


def _band_range(text: str):
    band = _band(text)
    if band == "auto":
        raise argparse.ArgumentTypeError("expected LO:HI in Hz, e.g. 200:3000")
    return band


def _run_identify(args: argparse.Namespace) -> int:
    from .identify import identify_joint
    from .io.measurements import load_measurements

    assembly = load_assembly(args.assembly)
    measurements = load_measurements(args.measurements)
    parameters = tuple(p.strip() for p in args.parameters.split(",") if p.strip())
    report = identify_joint(assembly, measurements, args.joint, band=args.band, parameters=parameters,
                            bootstrap=args.bootstrap)
    if args.plot:
        _figures()
        fig = report.plot()
        _save_figure(fig, args.plot)
    if args.json:
        print(json.dumps(report.to_json()))
        return 0
    lo, hi = report.band
    print(f"joint {report.joint!r} of {assembly.name}")
    print(f"band {lo:.0f}-{hi:.0f} Hz, {len(measurements)} measured FRFs, relative residual {report.residual_rms:.3f}")
    units = {"k": ("N/m", "N", "N/rad", "N*m/rad"), "c": ("N*s/m", "N*s", "N*s/rad", "N*m*s/rad")}
    for kind, values, stds in (("k", report.k, report.k_std), ("c", report.c, report.c_std)):
        for (entry, value), unit in zip(values.items(), units[kind]):
            fitted = f"{kind}_{entry}" in report.fitted or (entry == "tf" and f"{kind}_ym" in report.fitted)
            tail = f" +- {stds[entry]:.3g} {unit}" if fitted else f" {unit} (kept from the model)"
            print(f"  {kind}_{entry} = {value:.4g}{tail}")
    for note in report.warnings:
        print(f"note: {note}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0


# -- diagnose -------------------------------------------------------------------------


def _run_diagnose(args: argparse.Namespace) -> int:
    from .diagnose import diagnose
    from .io.assembly_toml import save_assembly
    from .io.measurements import load_measurements

    if args.save_model and Path(args.save_model).exists() and not args.overwrite:
        raise _UsageError(f"argument --save-model: {args.save_model} exists; add --overwrite to replace it")
    assembly = load_assembly(args.assembly)
    measurements = load_measurements(args.measurements)
    effects = "all" if args.effects == "all" else [e.strip() for e in args.effects.split(",") if e.strip()]
    band = None if args.band is None else args.band
    progress = None if args.quiet else (lambda text: print(f"{PROG}: {text}", file=sys.stderr, flush=True))
    result = diagnose(assembly, measurements, effects=effects, band=band, progress=progress or False)
    written = []
    if args.plot:
        _figures()
        out = Path(args.plot)
        out.mkdir(parents=True, exist_ok=True)
        for name, make in (("where_it_fails.png", result.plot_where), ("error_fall.png", result.plot_history)):
            fig = make()
            _save_figure(fig, out / name)
            written.append(str(out / name))
        if len(result.refinement) > 1:
            fig = result.final[0].plot()
            _save_figure(fig, out / "after_refinement.png")
            written.append(str(out / "after_refinement.png"))
    if args.save_model:
        save_assembly(result.refined_assembly, args.save_model, overwrite=args.overwrite)
        written.append(args.save_model)
    if args.json:
        print(json.dumps(result.to_json()))
        return 0
    floor = result.noise_floor
    print(f"model {assembly.name!r} against {len(measurements)} measured FRF(s), "
          f"{result.band[0]:.0f}-{result.band[1]:.0f} Hz")
    print(f"error ({result.metric}): {result.baseline_error:.4f}; noise floor of the data: {floor:.4f}")
    base = result.baseline[0]
    for m in base.modes[:12]:
        if m.model_hz is not None:
            print(f"  mode at {m.measured_hz:7.0f} Hz measured, {m.model_hz:7.0f} Hz in the model "
                  f"({m.shift_hz:+.0f} Hz), peak x{m.amplitude_ratio:.2f}")
        else:
            print(f"  mode at {m.measured_hz:7.0f} Hz measured, none in the model")
    if base.bands:
        print("  most of the error is in " + ", ".join(f"{lo:.0f}-{hi:.0f} Hz ({share:.0%})"
                                                        for lo, hi, share in base.bands))
    if result.missing_effect is None:
        if result.baseline_error <= 1.5 * floor:
            print("the model is as good as the data allow: nothing is missing")
        else:
            print("no effect of the catalogue explains the difference convincingly")
    else:
        best = result.candidates[0]
        print(f"missing effect: {best.name} at {best.where}")
        for name, spec in best.effect.parameters_json().items():
            print(f"  {name} = {spec['value']:.4g} {spec['unit']}")
        print(f"  why: {best.effect.explanation}")
        if result.ambiguous_with:
            print(f"  equally possible: {', '.join(result.ambiguous_with)}; to tell them apart: {result.suggestion}")
    if len(result.refinement) > 1:
        print("refinement (watch the error fall):")
        for step in result.refinement:
            what = "model as given" if step.added is None else f"+ {step.added.name} at {step.added.where}"
            print(f"  step {step.step}: {what:45s} error {step.error:.4f}")
    for path in written:
        print(f"wrote {path}")
    return 0


# -- lobes ----------------------------------------------------------------------------


def _speeds(text: str):
    """``START:STOP:STEP`` spindle speeds: plain numbers are rpm; units allowed, Hz refused."""
    from .stability import spindle_speeds

    return _range_of(text, "rpm", spindle_speeds, "2000:24000:50 (rpm) or '2000 rpm:24000 rpm:50 rpm'")


def _lobes_cut(args: argparse.Namespace):
    from .stability import MillingCut, TurningCut

    milling_only = {"--teeth": args.teeth, "--diameter": args.diameter, "--radial-depth": args.radial_depth,
                    "--immersion": args.immersion, "--kt": args.kt, "--kn": args.kn, "--kr": args.kr}
    if args.turning:
        given = [name for name, value in milling_only.items() if value is not None]
        if given:
            raise _UsageError(f"--turning takes --kf [--orientation U]; {', '.join(given)} describe a milling cut")
        if args.kf is None:
            raise _UsageError("--turning needs --kf PRESSURE (the cutting pressure, e.g. '2000 MPa')")
        return TurningCut(args.kf, args.orientation if args.orientation is not None else 1.0)
    if args.kf is not None or args.orientation is not None:
        raise _UsageError("--kf and --orientation describe a turning cut: add --turning")
    missing = [name for name, value in (("--teeth", args.teeth), ("--diameter", args.diameter), ("--kt", args.kt))
               if value is None]
    if args.radial_depth is None and args.immersion is None:
        missing.append("--radial-depth or --immersion")
    if args.kn is None and args.kr is None:
        missing.append("--kn or --kr")
    if missing:
        raise _UsageError(f"the milling cut needs {', '.join(missing)}")
    if args.radial_depth is not None and args.immersion is not None:
        raise _UsageError("give --radial-depth or --immersion, not both")
    if args.kn is not None and args.kr is not None:
        raise _UsageError("give --kn (a pressure) or --kr (the ratio Kn/Kt), not both")
    return MillingCut.from_spec(args.teeth, args.diameter, radial_depth=args.radial_depth,
                                immersion=args.immersion, milling=args.milling, kt=args.kt, kn=args.kn, kr=args.kr)


def _lobes_structure(args: argparse.Namespace):
    """The structure and a line describing it: an FRF (labelled x/y) or a ModalModel."""
    from .stability import ModalModel, xy_frf

    sources = [name for name, value in (("--assembly", args.assembly), ("--frf", args.frf), ("--modes", args.modes))
               if value is not None]
    if len(sources) != 1:
        raise _UsageError("give the structure as one of --assembly A.toml --at POINT, --frf X.csv [--frf-y Y.csv] "
                          "or --modes MODES.csv" + (f" (got {', '.join(sources)})" if sources else ""))
    if (args.at is not None) != (args.assembly is not None):
        raise _UsageError("--at POINT goes with --assembly A.toml (and --assembly needs --at)")
    if args.frf_y is not None and args.frf is None:
        raise _UsageError("--frf-y goes with --frf")
    if args.modes is not None:
        if args.band is not None:
            raise _UsageError("--band crops FRF data; --modes are used as they are")
        model = ModalModel.from_csv(args.modes)
        return model, f"modes from {args.modes}: {model.describe()}"
    if args.assembly is not None:
        assembly = load_assembly(args.assembly)
        at = _point(args.at)
        if at.endswith(":theta"):
            raise SubstructureError(f"--at {args.at}: the cut needs a translational receptance (':y'), not ':theta'")
        if assembly.frequency is None:
            raise _UsageError(f"{args.assembly} has no [frequency] table; lobes need the FRF on a grid")
        frf = xy_frf(assembly.receptance(at, frequency=assembly.frequency))
        what = f"tool point FRF of {assembly.name} at {at}, y = x (a symmetric tool)"
    else:
        x = FRF.from_csv(args.frf)
        y = FRF.from_csv(args.frf_y) if args.frf_y else None
        frf = xy_frf(x, y)
        what = f"FRF from {args.frf}" + (f" (x) and {args.frf_y} (y)" if args.frf_y else ", y = x (a symmetric tool)")
    if args.band is not None:
        frf = frf.crop(*args.band)
    return frf, f"{what}, {_grid_text(frf.frequency)}"


def _run_lobes(args: argparse.Namespace) -> int:
    from .stability import ModalFitter, ModalFitWarning, ModalModel, sdm, zoa

    if args.plot and Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
        raise _UsageError(f"argument --plot: {args.plot!r}: expected a .png, .pdf or .svg file")
    if args.intervals is not None and args.method != "sdm":
        raise _UsageError("--intervals sets the semi-discretization: use it with --method sdm")
    cut = _lobes_cut(args)
    structure, what = _lobes_structure(args)
    notes = []
    if args.method == "zoa":
        lobes = zoa(structure, cut, args.speeds)
        method = "zero-order approximation (Altintas & Budak 1995)"
    else:
        if isinstance(structure, FRF):  # semi-discretization needs modes: fit them to x and y
            fits = [ModalFitter().fit(FRF.single(structure.frequency, structure.data[:, i, i], output=d, input=d), d)
                    for i, d in enumerate("xy")]
            structure = ModalModel([m for fit in fits for m in fit.modes_])
            errors = ", ".join(f"{d} {fit.modal_error_:.1%}" for d, fit in zip("xy", fits))
            notes.append(f"modal fit: {len(structure.modes)} modes ({structure.describe()}); relative error {errors}")
            if max(fit.modal_error_ for fit in fits) > 0.2:
                warnings.warn(f"the fitted modes miss the FRF by {errors}; choose the band with --band LO:HI",
                              ModalFitWarning, stacklevel=2)
        lobes = sdm(structure, cut, args.speeds, intervals=args.intervals)
        info = lobes.discretisation
        method = "semi-discretization (updated first order, Insperger & Stepan 2004)"
        lo, hi = info["intervals_in_cut"]
        notes.append(f"discretisation: {lo}" + (f" to {hi}" if hi != lo else "") + " intervals in the cut per "
                     f"delay period; boundary to {info['depth_rtol']:.1%}")
    if args.plot:
        _figures()
        fig = lobes.plot(lobes=args.method == "zoa")
        fig.axes[0].set_title(_one_line(cut.describe()), fontsize="small")
        _save_figure(fig, args.plot)
    if args.json:
        print(json.dumps(lobes.to_json()))
        return 0
    speeds = lobes.spindle_speed_rpm
    print(f"structure: {what}")
    print(f"cut: {cut.describe()}")
    print(f"method: {method}")
    for note in notes:
        print(note)
    print(f"speeds: {speeds[0]:g} to {speeds[-1]:g} rpm, {speeds.size} speeds")
    if lobes.absolute_limit_m is not None:
        if np.isfinite(lobes.absolute_limit_m):
            print(f"absolute limit: {lobes.absolute_limit_m * 1e3:.4g} mm at every speed "
                  f"(chatter at {lobes.absolute_limit_frequency_hz:.5g} Hz)")
        else:
            print("absolute limit: none (no chatter possible with this FRF and cut)")
    depth = lobes.depth_limit_m
    finite = np.isfinite(depth)
    if finite.any():
        i, j = np.argmin(depth), np.argmax(np.where(finite, depth, -np.inf))
        print(f"depth limit: {depth[i] * 1e3:.4g} mm (lowest, at {speeds[i]:g} rpm) to "
              f"{depth[j] * 1e3:.4g} mm (highest, at {speeds[j]:g} rpm)")
    if not finite.all():
        print(f"no limit found at {int((~finite).sum())} speeds")
    best = lobes.best_speeds(3)
    if best:
        print("best speeds:")
        for n, a in best:
            k = int(np.argmin(np.abs(speeds - n)))
            print(f"  {n:9.6g} rpm   depth limit {a * 1e3:.4g} mm   chatter {lobes.chatter_frequency_hz[k]:.5g} Hz")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0


# -- entry point ----------------------------------------------------------------------


# -- predict --------------------------------------------------------------------------


def _features(text: str) -> dict[str, str]:
    out = {}
    for part in text.split(","):
        if not part.strip():
            continue
        name, sep, value = part.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise _UsageError(f"--features: cannot read {part.strip()!r}; expected NAME=VALUE, e.g. tool_diameter=14 mm")
        out[name.strip()] = value.strip()
    return out


def _run_predict(args: argparse.Namespace) -> int:
    from .surrogate import JointTable, cross_validate, make_surrogate

    table = JointTable.from_csv(args.table)
    table.check_not_empty()
    surrogate = make_surrogate(args.model)
    if args.cross_validate:
        target = args.target or next(iter(table.parameters))
        cv = cross_validate(surrogate, table, target, args.cross_validate)
        if args.plot:
            _figures()
            fig = cv.plot()
            _save_figure(fig, args.plot)
        if args.json:
            print(json.dumps(cv.to_json()))
            return 0
        print(f"{args.model}, {args.cross_validate} on {args.table}: {len(cv.folds)} folds, {target} [{cv.unit}]")
        print(f"  mean |error| {cv.mean_abs_percent_error:.1f} %, max {cv.max_abs_percent_error:.1f} %")
        print(f"  inside the 68 % interval {cv.coverage(0.68):.0%}, the 95 % interval {cv.coverage(0.95):.0%}")
        return 0
    if args.features is None:
        raise _UsageError("give --features NAME=VALUE,... (or --cross-validate)")
    if bool(args.assembly) != bool(args.joint):
        raise _UsageError("--assembly and --joint go together: the assembly file and the joint to replace")
    targets = [args.target] if args.target else None
    model = surrogate.fit(table, targets)
    prediction = model.predict(_features(args.features))
    result = prediction.to_json()
    band = None
    if args.assembly:
        from .surrogate import predict_frf_band

        band = predict_frf_band(load_assembly(args.assembly), args.joint, prediction, at=_point(args.at),
                                n_samples=args.samples)
        if args.plot:
            _figures()
            fig = band.plot(label=f"{args.model} prediction")
            _save_figure(fig, args.plot)
    if args.json:
        out = {"model": args.model, "features": _features(args.features), "parameters": result}
        if band is not None:
            out["frf"] = {"at": _point(args.at), "joint": args.joint, **band.to_json()}
        print(json.dumps(out))
        return 0
    print(f"{args.model} surrogate on {table.describe()}")
    for name, p in result.items():
        lo, hi = p["interval_95"]
        print(f"  {name} = {p['value']:.4g} +- {p['std']:.3g} {p['unit']} (95 %: {lo:.4g} to {hi:.4g})")
    if band is not None:
        nominal = band.nominal
        peaks = nominal.peaks()
        print(f"tool point FRF ({_point(args.at)}) with the predicted {args.joint!r} joint, "
              f"{len(next(iter(band.samples.values())))} samples: peaks of the median joint at "
              + ", ".join(f"{f:.0f} Hz" for f in peaks))
        if args.plot:
            print(f"wrote {args.plot}")
    return 0


def _parser() -> _Parser:
    parser = _Parser(prog=PROG, description="Receptance coupling of spindle-holder-tool assemblies.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    frf = commands.add_parser("frf", help="receptance of an assembly file between two points")
    frf.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (formats.md)")
    frf.add_argument("--at", required=True, metavar="POINT[:dof]",
                     help="response point, e.g. tool.tip (DOF y by default)")
    frf.add_argument("--to", metavar="POINT[:dof]", help="excitation point (default: --at)")
    frf.add_argument("--grid", type=_grid, metavar="START:STOP:STEP",
                     help="frequency grid in Hz or with units (default: the file's [frequency])")
    frf.add_argument("--out", metavar="FILE.csv|FILE.uff", help="write the FRF to a CSV or UFF file")
    frf.add_argument("--plot", metavar="FILE.png", help="plot the FRF to an image file")
    frf.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    frf.set_defaults(run=_run_frf)
    ident = commands.add_parser("identify", help="identify a joint's stiffness and damping from measurements")
    ident.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (formats.md)")
    ident.add_argument("measurements", metavar="MEASUREMENTS.toml", help="measurement set (formats.md)")
    ident.add_argument("--joint", required=True, metavar="NAME", help="name of the joint to identify")
    ident.add_argument("--band", type=_band, default="auto", metavar="auto|LO:HI",
                       help="frequency band in Hz (default auto: the mode the joint dominates)")
    ident.add_argument("--parameters", default="k_yf,k_tm,c_yf,c_tm", metavar="NAMES",
                       help="parameters to fit, of k_yf,k_ym,k_tm,c_yf,c_ym,c_tm (k_ym stands for k_ym = k_tf)")
    ident.add_argument("--bootstrap", type=int, default=0, metavar="N",
                       help="bootstrap refits for the standard deviations (default 0: from the Jacobian)")
    ident.add_argument("--plot", metavar="FILE.png", help="plot the closed form, the band, the fit and the FRFs")
    ident.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    ident.set_defaults(run=_run_identify)
    diag = commands.add_parser("diagnose", help="which physical effect the model misses against measurements")
    diag.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (formats.md)")
    diag.add_argument("measurements", metavar="MEASUREMENTS.toml", help="measurement set (formats.md)")
    diag.add_argument("--effects", default="all", metavar="all|NAME,...",
                      help="effects to consider (default all registered effects)")
    diag.add_argument("--band", type=_band_range, metavar="LO:HI", help="frequency band in Hz (default: all data)")
    diag.add_argument("--plot", metavar="DIR", help="write the figures (where it fails, error fall) to DIR")
    diag.add_argument("--save-model", metavar="FILE.toml", help="write the model with the effects found")
    diag.add_argument("--overwrite", action="store_true", help="let --save-model replace an existing file")
    diag.add_argument("--quiet", action="store_true", help="no progress on standard error")
    diag.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    diag.set_defaults(run=_run_diagnose)
    lobes = commands.add_parser("lobes", help="stability lobe diagram of a cut, from an FRF, an assembly or modes")
    where = lobes.add_argument_group("structure (one of)")
    where.add_argument("--assembly", metavar="A.toml", help="assembly file; the tool point FRF at --at")
    where.add_argument("--at", metavar="POINT", help="the tool point of --assembly, e.g. tool.tip")
    where.add_argument("--frf", metavar="X.csv", help="tool point receptance in the feed direction x (CSV)")
    where.add_argument("--frf-y", metavar="Y.csv", help="receptance in y (default: equal to x, a symmetric tool)")
    where.add_argument("--modes", metavar="MODES.csv",
                       help="modal parameters, header direction,frequency_hz,damping_ratio,stiffness_n_per_m")
    where.add_argument("--band", type=_band_range, metavar="LO:HI",
                       help="use the FRF between these frequencies in Hz only (e.g. leave out rigid-body motion)")
    cutting = lobes.add_argument_group("milling cut")
    cutting.add_argument("--teeth", type=int, metavar="N", help="number of teeth")
    cutting.add_argument("--diameter", metavar="D", help="tool diameter with its unit, e.g. '12 mm'")
    cutting.add_argument("--radial-depth", metavar="A", help="radial depth of cut with its unit, e.g. '3 mm'")
    cutting.add_argument("--immersion", type=float, metavar="RATIO", help="radial immersion a/D, in (0, 1]")
    cutting.add_argument("--milling", choices=("up", "down"), default="up", help="up (default) or down milling")
    cutting.add_argument("--kt", metavar="PRESSURE", help="tangential cutting coefficient, e.g. '625 MPa'")
    cutting.add_argument("--kn", metavar="PRESSURE", help="normal (radial) cutting coefficient, e.g. '100 MPa'")
    cutting.add_argument("--kr", type=float, metavar="RATIO", help="or the ratio Kn/Kt, e.g. 0.16")
    turning = lobes.add_argument_group("turning or boring (Tlusty's oriented single direction)")
    turning.add_argument("--turning", action="store_true", help="a turning cut instead of milling")
    turning.add_argument("--kf", metavar="PRESSURE", help="cutting pressure along the resultant force, e.g. '2000 MPa'")
    turning.add_argument("--orientation", type=float, metavar="U", help="directional factor u in x (default 1)")
    lobes.add_argument("--method", choices=("zoa", "sdm"), default="zoa",
                       help="zoa: zero-order (default, from FRF data); sdm: semi-discretization (modes; fitted "
                            "to FRF data when needed)")
    lobes.add_argument("--speeds", type=_speeds, default="2000:24000:50", metavar="START:STOP:STEP",
                       help="spindle speeds in rpm (default 2000:24000:50)")
    lobes.add_argument("--intervals", type=int, metavar="M",
                       help="sdm: intervals in the cut per delay period (default: chosen per speed)")
    lobes.add_argument("--plot", metavar="FILE.png", help="plot the lobes to an image file")
    lobes.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    lobes.set_defaults(run=_run_lobes)
    pred = commands.add_parser("predict", help="joint parameters for an untested tool from a joint table")
    pred.add_argument("table", metavar="TABLE", help="joint-parameter table (CSV, units in the header)")
    pred.add_argument("--features", metavar="NAME=VALUE,...", help="features of the tool, e.g. 'tool_diameter=14 mm'")
    pred.add_argument("--model", choices=("mlp", "gp"), default="gp", help="surrogate (default gp)")
    pred.add_argument("--target", metavar="PARAMETER", help="parameter to predict (default: all of the table)")
    pred.add_argument("--cross-validate", metavar="loo|group:FEATURE", help="evaluate the surrogate instead")
    pred.add_argument("--assembly", metavar="A.toml", help="assembly file: the tool point FRF and its band")
    pred.add_argument("--joint", metavar="NAME", help="the joint of --assembly the prediction replaces")
    pred.add_argument("--at", default="tool.tip", metavar="POINT[:dof]", help="FRF point (default tool.tip:y)")
    pred.add_argument("--samples", type=int, default=64, metavar="N",
                      help="samples of the predictive distribution for the FRF band (default 64)")
    pred.add_argument("--plot", metavar="FILE.png", help="parity plot of the cross-validation, or the FRF band")
    pred.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    pred.set_defaults(run=_run_predict)
    demo = commands.add_parser("demo", help="the workflow on the built-in assembly, with plots")
    demo.add_argument("--out", default="out/demo", metavar="DIR", help="output directory (default out/demo)")
    demo.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    demo.set_defaults(run=_run_demo)
    return parser


def _error(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        return f"{exc.filename}: {exc.strerror}"
    return _one_line(str(exc))


PLUGIN_GROUP = "substructure.plugins"
"""Entry-point group whose modules are imported before a command runs.

A package that registers its own component types (``register_component``)
declares ``[project.entry-points."substructure.plugins"] name = "module"``
so that assembly files using its types work from the command line too.
"""


def _load_plugins() -> None:
    from importlib.metadata import entry_points

    for ep in entry_points(group=PLUGIN_GROUP):
        try:
            ep.load()
        except Exception as exc:  # a broken plugin must not break the command
            warnings.warn(f"plugin {ep.name!r} ({ep.value}) failed to load: {exc}", stacklevel=2)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 error, 2 usage).

    Parameters
    ----------
    argv : list of str, optional
        The arguments without the program name (default ``sys.argv[1:]``).
    """
    reported: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        text = _one_line(str(message))
        if text not in reported:
            reported.add(text)
            print(f"{PROG}: warning: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = show
        try:
            _load_plugins()
            args = _parser().parse_args(argv)
            if args.command is None:
                raise _UsageError("choose a command: frf, identify, diagnose, lobes, predict, demo (see substructure --help)")
            return args.run(args)
        except _UsageError as exc:
            print(f"{PROG}: error: {_one_line(str(exc))}", file=sys.stderr)
            return 2
        except BrokenPipeError:  # e.g. piped into `head`: stop quietly
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            return 1
        except (SubstructureError, OSError) as exc:
            print(f"{PROG}: error: {_error(exc)}", file=sys.stderr)
            return 1
        except SystemExit as exc:  # --help and --version print and exit
            return exc.code if isinstance(exc.code, int) else 0
        except KeyboardInterrupt:
            print(f"{PROG}: interrupted", file=sys.stderr)
            return 130


if __name__ == "__main__":
    sys.exit(main())
