"""The ``substructure diagnose`` command: model against measurement, what is missing, an honest verdict."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from ._common import (
    CALIBRATION_HELP,
    PROG,
    UsageError,
    band_range_arg,
    calibration_arg,
    check_outputs,
    count_arg,
    figures,
    measurement_inputs,
    print_json,
    save_figure,
)

FIGURES = ("where_it_fails.png", "error_fall.png", "after_refinement.png")
"""The figures ``--plot DIR`` writes."""


def run(args: argparse.Namespace) -> int:
    from ..diagnose import DiagnoseSettings, diagnose
    from ..io.assembly_toml import load_assembly, save_assembly
    from ..io.measurements import load_measurements

    if not args.effects.strip():
        raise UsageError("argument --effects: got an empty list; give 'all' or effect names separated by commas")
    count_arg("--max-steps", args.max_steps, minimum=1)
    for option, value, what in (("--budget", args.budget, "model evaluations"), ("--time-limit", args.time_limit,
                                                                               "seconds")):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise UsageError(f"argument {option}: got {value:g}; expected a positive number of {what}")
    calibration_arg(args.calibration)
    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise UsageError(f"argument --plot: {args.plot} is a file; expected a directory for the figures")
    # figures go into DIR (created if missing): the ones there already are checked like any output
    into_dir = args.plot is not None and Path(args.plot).is_dir()
    figures_out = [("--plot", Path(args.plot) / name) for name in FIGURES] if into_dir else []
    check_outputs([("--save-model", args.save_model), *figures_out],
                  [args.assembly, *measurement_inputs(args.measurements)], args.overwrite)
    if args.save_model and Path(args.save_model).suffix.lower() != ".toml":  # an assembly file, whatever the name
        raise UsageError(f"argument --save-model: {args.save_model!r}: expected a .toml file (the model is written "
                         "as an assembly file)")
    assembly = load_assembly(args.assembly)
    measurements = load_measurements(args.measurements)
    progress = None if args.quiet else (lambda text: print(f"{PROG}: {text}", file=sys.stderr, flush=True))
    settings = None if args.calibration is None else DiagnoseSettings(calibration=args.calibration)
    result = diagnose(assembly, measurements, effects=args.effects, band=args.band, progress=progress or False,
                      max_steps=args.max_steps, open_world=not args.catalogue_only, settings=settings,
                      time_limit=args.time_limit, **({} if args.budget is None else {"budget": args.budget}))
    written = []
    if args.plot:
        figures()
        out = Path(args.plot)
        out.mkdir(parents=True, exist_ok=True)
        makers = [result.plot_where, result.plot_history]
        if len(result.refinement) > 1:
            makers.append(lambda: result.final[0].plot())
        for name, make in zip(FIGURES, makers):
            save_figure(make(), out / name, args.overwrite)
            written.append(str(out / name))
    notes = []
    saved = None
    if args.save_model and (result.explained or args.save_partial):
        save_assembly(result.refined_assembly, args.save_model, overwrite=args.overwrite)
        written.append(args.save_model)
        saved = args.save_model
    elif args.save_model:
        notes.append(f"{args.save_model} not written: the diagnosis is unexplained, and its partial changes are "
                     "guesses (a model with them may predict what was not measured worse than the one given); "
                     "--save-partial writes them anyway")
    if args.json:
        data = result.to_json()
        data["saved_model"] = saved
        data["notes"] = notes
        return print_json(data)
    for note in notes:
        print(f"{PROG}: {note}", file=sys.stderr)
    from ..diagnose.words import summary

    print("\n".join(summary(result, assembly.name, len(measurements))))
    for path in written:
        print(f"wrote {path}")
    return 0


def add_parser(commands) -> None:
    """Add the ``diagnose`` subcommand to the subparsers ``commands``."""
    diag = commands.add_parser("diagnose", help="what the model misses against measurements, with an honest verdict")
    diag.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (docs/file-formats.md)")
    diag.add_argument("measurements", metavar="MEASUREMENTS.toml", help="measurement set (docs/file-formats.md)")
    diag.add_argument("--effects", default="all", metavar="all|NAME,...",
                      help="effects of the catalogue to consider (default all registered effects)")
    diag.add_argument("--catalogue-only", action="store_true",
                      help="consider only the catalogue's effects, not every model parameter and added element")
    diag.add_argument("--max-steps", type=int, default=4, metavar="N",
                      help="most changes the refinement adds (default 4)")
    diag.add_argument("--budget", type=float, default=None, metavar="N",
                      help="budget of the search in model evaluations of all lines, of at least 2,500 lines "
                           "(default 3000); once spent the "
                           "search stops adding changes and says so")
    diag.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                      help="a limit in wall-clock seconds as well (default none)")
    diag.add_argument("--calibration", type=float, default=None, metavar="FRACTION", help=CALIBRATION_HELP)
    diag.add_argument("--band", type=band_range_arg, metavar="LO:HI", help="frequency band in Hz (default: all data)")
    diag.add_argument("--plot", metavar="DIR", help="write the figures (where it fails, error fall) to DIR")
    diag.add_argument("--save-model", metavar="FILE.toml", help="write the model with the changes found")
    diag.add_argument("--save-partial", action="store_true",
                      help="with --save-model: write the partial changes of an unexplained diagnosis too "
                           "(by default only an explained diagnosis is written)")
    diag.add_argument("--overwrite", action="store_true",
                      help="let --save-model and --plot replace existing files (never an input)")
    diag.add_argument("--quiet", action="store_true", help="no progress on standard error")
    diag.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    diag.set_defaults(run=run)
