"""The ``substructure frf`` command: a receptance of an assembly file, its peaks, saved or plotted."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import (
    UsageError,
    assembly_point_arg,
    check_outputs,
    check_plot,
    draw_to,
    grid_arg,
    grid_text,
    peak_table,
    print_json,
    write_frf,
)


def run(args: argparse.Namespace) -> int:
    from ..io.assembly_toml import load_assembly

    if args.grid is not None and args.grid.hz[0] <= 0:  # the rule of [frequency], checked before any work
        raise UsageError(f"argument --grid: START is {args.grid.hz[0]:g} Hz; expected a frequency > 0 Hz, as in "
                         "[frequency] (the components of an assembly are free-free: no static receptance)")
    if args.out and Path(args.out).suffix.lower() not in (".csv", ".uff", ".unv"):
        raise UsageError(f"argument --out: {args.out!r}: expected a .csv or .uff file")
    check_plot(args.plot)
    check_outputs([("--out", args.out), ("--plot", args.plot)], [args.assembly], args.overwrite)
    assembly = load_assembly(args.assembly)
    at = assembly_point_arg(assembly, args.at, "--at")
    to = assembly_point_arg(assembly, args.to, "--to") if args.to else at
    frequency = args.grid or assembly.frequency
    if frequency is None:
        raise UsageError(f"{args.assembly} has no [frequency] table; give the grid with --grid START:STOP:STEP")
    frf = assembly.receptance(at, to, frequency)
    peaks = peak_table(frf)
    written = []
    if args.out:
        write_frf(frf, args.out, args.overwrite)
        written.append(args.out)
    if args.plot:
        draw_to(args.plot, args.overwrite, lambda: frf.plot(kind=args.kind, unit=args.unit,
                                                            title=f"{assembly.name}: {at} / {to}"))
        written.append(args.plot)
    if args.json:
        values = frf.data[:, 0, 0]
        return print_json({
            "frequency_hz": frf.frequency.hz.tolist(),
            "real": values.real.tolist(),
            "imag": values.imag.tolist(),
            "peaks_hz": [f for f, _ in peaks],
        })
    unit = frf.unit(frf.outputs[0], frf.inputs[0])
    print(f"assembly: {assembly.name}")
    print(f"receptance: response {at}, excitation {to} [{unit}]")
    print(f"grid: {grid_text(frf.frequency)}")
    print("peaks:" if peaks else "peaks: none inside the grid")
    for f, m in peaks:
        print(f"  {f:10.6g} Hz   |FRF| = {m:.4g} {unit}")
    for path in written:
        print(f"wrote {path}")
    return 0


def add_parser(commands) -> None:
    """Add the ``frf`` subcommand to the subparsers ``commands``."""
    frf = commands.add_parser("frf", help="receptance of an assembly file between two points")
    frf.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (docs/file-formats.md)")
    frf.add_argument("--at", required=True, metavar="POINT[:dof]",
                     help="response point, e.g. tool.tip (DOF y by default)")
    frf.add_argument("--to", metavar="POINT[:dof]", help="excitation point (default: --at)")
    frf.add_argument("--grid", type=grid_arg, metavar="START:STOP:STEP",
                     help="frequency grid in Hz or with units; rad/s and rpm are converted (default: the "
                          "file's [frequency])")
    frf.add_argument("--out", metavar="FILE.csv|FILE.uff", help="write the FRF to a CSV or UFF file")
    frf.add_argument("--plot", metavar="FILE.png", help="plot the FRF to an image file (.png, .pdf, .svg, ...)")
    frf.add_argument("--unit", choices=("um/N", "m/N", "mm/N", "nm/N"), default="um/N",
                     help="unit of translational FRFs in the plot (default: um/N)")
    frf.add_argument("--kind", choices=("bode", "nyquist", "real-imag"), default="bode",
                     help="plot view: magnitude and phase (default), Nyquist plane, or real and imaginary parts")
    frf.add_argument("--overwrite", action="store_true", help="let --out and --plot replace existing files")
    frf.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    frf.set_defaults(run=run)
