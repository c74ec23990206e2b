"""The ``substructure identify`` command: a joint's stiffness and damping from a measurement set."""

from __future__ import annotations

import argparse

from ._common import (
    CALIBRATION_HELP,
    UsageError,
    band_arg,
    calibration_arg,
    check_outputs,
    check_plot,
    count_arg,
    draw_to,
    measurement_inputs,
    print_json,
)


def run(args: argparse.Namespace) -> int:
    from ..io.assembly_toml import load_assembly
    from ..identify import identify_joint
    from ..io.measurements import load_measurements

    check_plot(args.plot)
    count_arg("--bootstrap", args.bootstrap)
    calibration_arg(args.calibration)
    check_outputs([("--plot", args.plot)], [args.assembly, *measurement_inputs(args.measurements)], args.overwrite)
    assembly = load_assembly(args.assembly)
    measurements = load_measurements(args.measurements)
    parameters = "auto" if args.parameters.strip() == "auto" else tuple(
        p.strip() for p in args.parameters.split(",") if p.strip())
    if not parameters:
        raise UsageError("argument --parameters: got an empty list; give 'auto' or names such as k_yf,k_tm")
    twice = sorted({p for p in parameters if parameters.count(p) > 1}) if parameters != "auto" else []
    if twice:
        raise UsageError(f"argument --parameters: {', '.join(twice)} named twice in {args.parameters!r}; "
                         "name each parameter once")
    report = identify_joint(assembly, measurements, args.joint, band=args.band, parameters=parameters,
                            bootstrap=args.bootstrap, calibration=args.calibration)
    if args.plot:
        draw_to(args.plot, args.overwrite, report.plot)
    if args.json:
        return print_json(report.to_json())
    lo, hi = report.band
    print(f"joint {report.joint!r} of {assembly.name}")
    if not report.consistent:
        print("warning: the model does not fit the data within their noise: it misses something; the values "
              "below are uncertain (run `substructure diagnose` to find what is missing)")
    print(f"band {lo:.0f}-{hi:.0f} Hz, {len(measurements)} measured FRFs, relative residual {report.residual_rms:.3f}, "
          f"chi^2/nu {report.chi2_reduced:.3g}; joint model: {report.model}")
    if report.level is not None:
        print(f"level: the measured FRFs read {report.level:.4g} times the fitted model's throughout (calibration "
              f"uncertainty {report.calibration:.3g}); the joint was fitted at that level")
    units = {"k": ("N/m", "N", "N/rad", "N*m/rad"), "c": ("N*s/m", "N*s", "N*s/rad", "N*m*s/rad")}
    for kind, values, stds in (("k", report.k, report.k_std), ("c", report.c, report.c_std)):
        for (entry, value), unit in zip(values.items(), units[kind]):
            name = f"{kind}_ym" if entry == "tf" else f"{kind}_{entry}"
            fitted = name in report.fitted
            if name in report.at_bound:
                lower, upper = report.search[name]
                tail = (f" {unit}: on the {report.at_bound[name]} bound of its search ({lower:.4g} to {upper:.4g} "
                        f"{unit}), not a measurement")
            else:
                tail = f" +- {stds[entry]:.3g} {unit}" if fitted else f" {unit} (kept from the model)"
            print(f"  {kind}_{entry} = {value:.4g}{tail}")
    for note in report.warnings:
        print(f"note: {note}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0


def add_parser(commands) -> None:
    """Add the ``identify`` subcommand to the subparsers ``commands``."""
    ident = commands.add_parser("identify", help="identify a joint's stiffness and damping from measurements")
    ident.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (docs/file-formats.md)")
    ident.add_argument("measurements", metavar="MEASUREMENTS.toml", help="measurement set (docs/file-formats.md)")
    ident.add_argument("--joint", required=True, metavar="NAME", help="name of the joint to identify")
    ident.add_argument("--band", type=band_arg, default="auto", metavar="auto|LO:HI",
                       help="frequency band in Hz (default auto: the mode the joint dominates)")
    ident.add_argument("--parameters", default="auto", metavar="auto|NAMES",
                       help="parameters to fit, of k_yf,k_ym,k_tm,c_yf,c_ym,c_tm (k_ym stands for k_ym = k_tf); "
                            "default auto: the diagonal joint, with the cross terms when they are significant")
    ident.add_argument("--bootstrap", type=int, default=0, metavar="N",
                       help="bootstrap refits for the standard deviations (default 0: from the Jacobian)")
    ident.add_argument("--calibration", type=float, default=None, metavar="FRACTION", help=CALIBRATION_HELP)
    ident.add_argument("--plot", metavar="FILE.png", help="plot the closed form, the band, the fit and the FRFs")
    ident.add_argument("--overwrite", action="store_true", help="let --plot replace an existing file")
    ident.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    ident.set_defaults(run=run)
