"""The ``substructure diagnose`` command: model against measurement, the missing effect, the error falling."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ._common import (
    PROG,
    UsageError,
    band_range_arg,
    check_outputs,
    figures,
    measurement_inputs,
    print_json,
    save_figure,
)

FIGURES = ("where_it_fails.png", "error_fall.png", "after_refinement.png")
"""The figures ``--plot DIR`` writes."""


def run(args: argparse.Namespace) -> int:
    from ..io.assembly_toml import load_assembly

    from ..diagnose import diagnose
    from ..io.assembly_toml import save_assembly
    from ..io.measurements import load_measurements

    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise UsageError(f"argument --plot: {args.plot} is a file; expected a directory for the figures")
    # figures go into DIR (created if missing): the ones there already are checked like any output
    into_dir = args.plot is not None and Path(args.plot).is_dir()
    figures_out = [("--plot", Path(args.plot) / name) for name in FIGURES] if into_dir else []
    check_outputs([("--save-model", args.save_model), *figures_out],
                  [args.assembly, *measurement_inputs(args.measurements)], args.overwrite)
    assembly = load_assembly(args.assembly)
    measurements = load_measurements(args.measurements)
    effects = "all" if args.effects == "all" else [e.strip() for e in args.effects.split(",") if e.strip()]
    band = None if args.band is None else args.band
    progress = None if args.quiet else (lambda text: print(f"{PROG}: {text}", file=sys.stderr, flush=True))
    result = diagnose(assembly, measurements, effects=effects, band=band, progress=progress or False)
    written = []
    if args.plot:
        figures()
        out = Path(args.plot)
        out.mkdir(parents=True, exist_ok=True)
        for name, make in ((FIGURES[0], result.plot_where), (FIGURES[1], result.plot_history)):
            fig = make()
            save_figure(fig, out / name, args.overwrite)
            written.append(str(out / name))
        if len(result.refinement) > 1:
            fig = result.final[0].plot()
            save_figure(fig, out / FIGURES[2], args.overwrite)
            written.append(str(out / FIGURES[2]))
    if args.save_model:
        save_assembly(result.refined_assembly, args.save_model, overwrite=args.overwrite)
        written.append(args.save_model)
    if args.json:
        return print_json(result.to_json())
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


def add_parser(commands) -> None:
    """Add the ``diagnose`` subcommand to the subparsers ``commands``."""
    diag = commands.add_parser("diagnose", help="which physical effect the model misses against measurements")
    diag.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (docs/file-formats.md)")
    diag.add_argument("measurements", metavar="MEASUREMENTS.toml", help="measurement set (docs/file-formats.md)")
    diag.add_argument("--effects", default="all", metavar="all|NAME,...",
                      help="effects to consider (default all registered effects)")
    diag.add_argument("--band", type=band_range_arg, metavar="LO:HI", help="frequency band in Hz (default: all data)")
    diag.add_argument("--plot", metavar="DIR", help="write the figures (where it fails, error fall) to DIR")
    diag.add_argument("--save-model", metavar="FILE.toml", help="write the model with the effects found")
    diag.add_argument("--overwrite", action="store_true",
                      help="let --save-model and --plot replace existing files (never an input)")
    diag.add_argument("--quiet", action="store_true", help="no progress on standard error")
    diag.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    diag.set_defaults(run=run)
