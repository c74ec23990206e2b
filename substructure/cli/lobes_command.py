"""The ``substructure lobes`` command: stability lobes of a cut from an FRF, an assembly or modes."""

from __future__ import annotations

import argparse
import warnings

from ..errors import SubstructureError
from ._common import (
    UsageError,
    band_range_arg,
    check_outputs,
    check_plot,
    figures,
    grid_text,
    one_line,
    point_arg,
    print_json,
    range_arg,
    save_figure,
)


def _speeds(text: str):
    """``START:STOP:STEP`` spindle speeds: plain numbers are rpm; units allowed, Hz refused."""
    from ..stability import spindle_speeds

    return range_arg(text, "rpm", spindle_speeds, "2000:24000:50 (rpm) or '2000 rpm:24000 rpm:50 rpm'")


def _lobes_cut(args: argparse.Namespace):
    from ..stability import MillingCut, TurningCut

    milling_only = {"--teeth": args.teeth, "--diameter": args.diameter, "--radial-depth": args.radial_depth,
                    "--immersion": args.immersion, "--kt": args.kt, "--kn": args.kn, "--kr": args.kr}
    if args.turning:
        given = [name for name, value in milling_only.items() if value is not None]
        if given:
            raise UsageError(f"--turning takes --kf [--orientation U]; {', '.join(given)} describe a milling cut")
        if args.kf is None:
            raise UsageError("--turning needs --kf PRESSURE (the cutting pressure, e.g. '2000 MPa')")
        return TurningCut(args.kf, args.orientation if args.orientation is not None else 1.0)
    if args.kf is not None or args.orientation is not None:
        raise UsageError("--kf and --orientation describe a turning cut: add --turning")
    missing = [name for name, value in (("--teeth", args.teeth), ("--diameter", args.diameter), ("--kt", args.kt))
               if value is None]
    if args.radial_depth is None and args.immersion is None:
        missing.append("--radial-depth or --immersion")
    if args.kn is None and args.kr is None:
        missing.append("--kn or --kr")
    if missing:
        raise UsageError(f"the milling cut needs {', '.join(missing)}")
    if args.radial_depth is not None and args.immersion is not None:
        raise UsageError("give --radial-depth or --immersion, not both")
    if args.kn is not None and args.kr is not None:
        raise UsageError("give --kn (a pressure) or --kr (the ratio Kn/Kt), not both")
    return MillingCut.from_spec(args.teeth, args.diameter, radial_depth=args.radial_depth,
                                immersion=args.immersion, milling=args.milling, kt=args.kt, kn=args.kn, kr=args.kr)


def _lobes_structure(args: argparse.Namespace):
    """The structure and a line describing it: an FRF (labelled x/y) or a ModalModel."""
    from ..frf import FRF
    from ..io.assembly_toml import load_assembly
    from ..stability import ModalModel, xy_frf

    sources = [name for name, value in (("--assembly", args.assembly), ("--frf", args.frf), ("--modes", args.modes))
               if value is not None]
    if len(sources) != 1:
        raise UsageError("give the structure as one of --assembly A.toml --at POINT, --frf X.csv [--frf-y Y.csv] "
                          "or --modes MODES.csv" + (f" (got {', '.join(sources)})" if sources else ""))
    if (args.at is not None) != (args.assembly is not None):
        raise UsageError("--at POINT goes with --assembly A.toml (and --assembly needs --at)")
    if args.frf_y is not None and args.frf is None:
        raise UsageError("--frf-y goes with --frf")
    if args.modes is not None:
        if args.band is not None:
            raise UsageError("--band crops FRF data; --modes are used as they are")
        model = ModalModel.from_csv(args.modes)
        return model, f"modes from {args.modes}: {model.describe()}"
    if args.assembly is not None:
        assembly = load_assembly(args.assembly)
        at = point_arg(args.at)
        if at.endswith(":theta"):
            raise SubstructureError(f"--at {args.at}: the cut needs a translational receptance (':y'), not ':theta'")
        if assembly.frequency is None:
            raise UsageError(f"{args.assembly} has no [frequency] table; lobes need the FRF on a grid")
        frf = xy_frf(assembly.receptance(at, frequency=assembly.frequency))
        what = f"tool point FRF of {assembly.name} at {at}, y = x (a symmetric tool)"
    else:
        x = FRF.from_csv(args.frf)
        y = FRF.from_csv(args.frf_y) if args.frf_y else None
        frf = xy_frf(x, y)
        what = f"FRF from {args.frf}" + (f" (x) and {args.frf_y} (y)" if args.frf_y else ", y = x (a symmetric tool)")
    if args.band is not None:
        frf = frf.crop(*args.band)
    return frf, f"{what}, {grid_text(frf.frequency)}"


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..frf import FRF
    from ..stability import ModalFitter, ModalFitWarning, ModalModel, sdm, zoa

    check_plot(args.plot)
    check_outputs([("--plot", args.plot)], [args.assembly, args.frf, args.frf_y, args.modes], args.overwrite)
    if args.intervals is not None and args.method != "sdm":
        raise UsageError("--intervals sets the semi-discretization: use it with --method sdm")
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
        figures()
        fig = lobes.plot(lobes=args.method == "zoa")
        fig.axes[0].set_title(one_line(cut.describe()), fontsize="small")
        save_figure(fig, args.plot, args.overwrite)
    if args.json:
        return print_json(lobes.to_json())
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



def add_parser(commands) -> None:
    """Add the ``lobes`` subcommand to the subparsers ``commands``."""
    lobes = commands.add_parser("lobes", help="stability lobe diagram of a cut, from an FRF, an assembly or modes")
    where = lobes.add_argument_group("structure (one of)")
    where.add_argument("--assembly", metavar="A.toml", help="assembly file; the tool point FRF at --at")
    where.add_argument("--at", metavar="POINT", help="the tool point of --assembly, e.g. tool.tip")
    where.add_argument("--frf", metavar="X.csv", help="tool point receptance in the feed direction x (CSV)")
    where.add_argument("--frf-y", metavar="Y.csv", help="receptance in y (default: equal to x, a symmetric tool)")
    where.add_argument("--modes", metavar="MODES.csv",
                       help="modal parameters, header direction,frequency_hz,damping_ratio,stiffness_n_per_m")
    where.add_argument("--band", type=band_range_arg, metavar="LO:HI",
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
    lobes.add_argument("--overwrite", action="store_true", help="let --plot replace an existing file")
    lobes.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    lobes.set_defaults(run=run)
