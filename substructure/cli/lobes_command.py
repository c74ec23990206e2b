"""The ``substructure lobes`` command: stability lobes of a cut from an FRF, an assembly or modes."""

from __future__ import annotations

import argparse
import re
import warnings

from ..errors import SubstructureError
from ._common import (
    UsageError,
    band_arg,
    check_outputs,
    check_plot,
    figures,
    grid_text,
    point_arg,
    print_json,
    range_arg,
    save_figure,
)


def _speeds(text: str):
    """``START:STOP:STEP`` spindle speeds: plain numbers are rpm; units allowed, Hz refused."""
    from ..stability import spindle_speeds

    return range_arg(text, "rpm", spindle_speeds, "2000:24000:50 (rpm) or '2000 rpm:24000 rpm:50 rpm'")


def _band(text: str):
    """``--band``: ``auto`` (default), ``all`` or ``LO:HI`` (Hz, or frequencies with units)."""
    if text.strip() == "all":
        return "all"
    try:
        return band_arg(text)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(str(exc).replace("expected auto or LO:HI", "expected auto, all or LO:HI"))


def _curve(text: str, unit: str):
    """``RPM:VALUE,RPM:VALUE,...`` (values in ``unit``) -> list of (speed, value) pairs."""
    from ..units import Q_

    pairs = []
    for item in text.split(","):
        try:
            n, v = (float(x) for x in item.split(":"))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"got {text!r}; expected RPM:{unit},RPM:{unit},... e.g. 0:0,6000:15,24000:15") from None
        pairs.append((Q_(n, "rpm"), Q_(v, unit)))
    return pairs


def _tool_of(assembly, at: str):
    """The Tool component that holds the point ``at`` (or None)."""
    from ..components import Tool
    from ..points import parse_point

    name = parse_point(at).component
    for comp in assembly.components:
        if isinstance(comp, Tool) and comp.name == name:
            return comp
    return None


def _lobes_cut(args: argparse.Namespace, tool, notes: list[str]):
    from ..stability import MillingCut, TurningCut, workpiece

    milling_only = {"--teeth": args.teeth, "--diameter": args.diameter, "--radial-depth": args.radial_depth,
                    "--immersion": args.immersion, "--kt": args.kt, "--kn": args.kn, "--kr": args.kr,
                    "--workpiece": args.workpiece, "--feed-per-tooth": args.feed_per_tooth}
    if args.turning:
        given = [name for name, value in milling_only.items() if value is not None]
        if given:
            raise UsageError(f"--turning takes --kf [--orientation U]; {', '.join(given)} describe a milling cut")
        if args.kf is None:
            raise UsageError("--turning needs --kf PRESSURE (the cutting pressure, e.g. '2000 MPa')")
        return TurningCut(args.kf, args.orientation if args.orientation is not None else 1.0)
    if args.kf is not None or args.orientation is not None:
        raise UsageError("--kf and --orientation describe a turning cut: add --turning")
    teeth, diameter = args.teeth, args.diameter
    if tool is not None and tool.teeth is not None:
        if teeth is None:
            teeth = tool.teeth
            notes.append(f"teeth: {teeth} from the tool {tool.name!r} of the assembly")
        elif teeth != tool.teeth:
            notes.append(f"teeth: --teeth {teeth} overrides the {tool.teeth} teeth of the tool {tool.name!r}")
    if tool is not None and diameter is None:
        diameter = tool.cutting_diameter
        notes.append(f"diameter: {diameter:~P} from the tool {tool.name!r} of the assembly")
    elif tool is not None:
        from ..units import quantity

        given = quantity(diameter, "--diameter", "[length]")
        if abs(given.m_as("m") - tool.cutting_diameter.m_as("m")) > 1e-9:
            notes.append(f"diameter: --diameter {given:~P} overrides the tool's {tool.cutting_diameter:~P}")
    missing = [name for name, value in (("--teeth", teeth), ("--diameter", diameter)) if value is None]
    if args.kt is None and args.workpiece is None:
        missing.append("--kt or --workpiece")
    if args.radial_depth is None and args.immersion is None:
        missing.append("--radial-depth or --immersion")
    if args.workpiece is None and args.kn is None and args.kr is None:
        missing.append("--kn or --kr")
    if missing:
        raise UsageError(f"the milling cut needs {', '.join(missing)}")
    if args.radial_depth is not None and args.immersion is not None:
        raise UsageError("give --radial-depth or --immersion, not both")
    if args.kn is not None and args.kr is not None:
        raise UsageError("give --kn (a pressure) or --kr (the ratio Kn/Kt), not both")
    if args.workpiece_table is not None and args.workpiece is None:
        raise UsageError("--workpiece-table goes with --workpiece NAME")
    if args.workpiece is not None:
        if args.kt is not None:
            raise UsageError("give --workpiece NAME or --kt, not both (the table gives Kt)")
        entry = workpiece(args.workpiece, args.workpiece_table)
        notes.append(f"workpiece: {entry.describe()}")
        return MillingCut.for_workpiece(teeth, diameter, entry, radial_depth=args.radial_depth,
                                        immersion=args.immersion, milling=args.milling,
                                        feed_per_tooth=args.feed_per_tooth, kn=args.kn, kr=args.kr)
    extra = {"feed_per_tooth": args.feed_per_tooth} if args.feed_per_tooth is not None else {}
    return MillingCut.from_spec(teeth, diameter, radial_depth=args.radial_depth, immersion=args.immersion,
                                milling=args.milling, kt=args.kt, kn=args.kn, kr=args.kr, **extra)


def _lobes_structure(args: argparse.Namespace):
    """The structure, a line describing it, the band chosen and the tool: FRF (labelled x/y) or ModalModel."""
    from ..frf import FRF
    from ..io.assembly_toml import load_assembly
    from ..stability import ModalModel, assembly_structure, xy_frf

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
        return model, f"modes from {args.modes}: {model.describe()}", None, None
    band = "auto" if args.band is None else args.band
    tool = None
    if args.assembly is not None:
        assembly = load_assembly(args.assembly)
        at = point_arg(args.at)
        if at.endswith(":theta"):
            raise SubstructureError(f"--at {args.at}: the cut needs a translational receptance (':y'), not ':theta'")
        if assembly.frequency is None:
            raise UsageError(f"{args.assembly} has no [frequency] table; lobes need the FRF on a grid")
        tool = _tool_of(assembly, at)
        what = f"tool point FRF of {assembly.name} at {at}, y = x (a symmetric tool)"
        if band == "auto":  # the model says what its supports do
            one, band = assembly_structure(assembly, at)
            return xy_frf(one), f"{what}, {grid_text(one.frequency)}", band, tool
        frf = xy_frf(assembly.receptance(at, frequency=assembly.frequency))
    else:
        x = FRF.from_csv(args.frf)
        y = FRF.from_csv(args.frf_y) if args.frf_y else None
        frf = xy_frf(x, y)
        what = f"FRF from {args.frf}" + (f" (x) and {args.frf_y} (y)" if args.frf_y else ", y = x (a symmetric tool)")
    from ..stability import choose_band

    frf, band = choose_band(frf, band)
    return frf, f"{what}, {grid_text(frf.frequency)}", band, tool


def _limits(args: argparse.Namespace, tool, notes: list[str]):
    from ..stability import MachineLimits

    if args.power is not None and args.power_curve is not None:
        raise UsageError("give --power or --power-curve, not both")
    if args.torque is not None and args.torque_curve is not None:
        raise UsageError("give --torque or --torque-curve, not both")
    max_depth = args.max_depth
    if max_depth is None and tool is not None and tool.flute_length is not None:
        max_depth = tool.flute_length
        notes.append(f"largest depth: the flute length {max_depth:~P} of the tool {tool.name!r}")
    return MachineLimits(max_speed=args.max_speed, min_speed=args.min_speed,
                         power=args.power if args.power is not None else args.power_curve,
                         torque=args.torque if args.torque is not None else args.torque_curve, max_depth=max_depth)


def _speed(text: str) -> str:
    """A spindle speed: a plain number is rpm."""
    try:
        return f"{float(text)!r} rpm"
    except ValueError:
        return text


def run(args: argparse.Namespace) -> int:
    import attrs
    import numpy as np

    from ..frf import FRF
    from ..stability import MillingCut, ModalFitter, ModalFitWarning, ModalModel, recommend, sdm, zoa

    check_plot(args.plot)
    check_outputs([("--plot", args.plot)], [args.assembly, args.frf, args.frf_y, args.modes, args.workpiece_table],
                  args.overwrite)
    if args.intervals is not None and args.method != "sdm":
        raise UsageError("--intervals sets the semi-discretization: use it with --method sdm")
    structure, what, band, tool = _lobes_structure(args)
    notes: list[str] = []
    if band is not None:
        notes.append(f"structure band: {band.lo_hz:g} to {band.hi_hz:g} Hz ({band.kind}); {band.reason}")
    cut = _lobes_cut(args, tool, notes)
    limits = _limits(args, tool, notes) if isinstance(cut, MillingCut) else None
    if args.method == "zoa":
        lobes = zoa(structure, cut, args.speeds, band=band if band is not None else "auto")
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
        if band is not None:
            lobes = attrs.evolve(lobes, band=band)
        info = lobes.discretisation
        method = "semi-discretization (updated first order, Insperger & Stepan 2004)"
        lo, hi = info["intervals_in_cut"]
        notes.append(f"discretisation: {lo}" + (f" to {hi}" if hi != lo else "") + " intervals in the cut per "
                     f"delay period; boundary to {info['depth_rtol']:.1%}")
    best = None
    if limits is not None:
        best = recommend(lobes, cut, limits, margin=args.margin, speed_tolerance=args.speed_tolerance)
    else:
        notes.append("no recommendation: the machinist's recommendation is for milling cuts")
    if args.plot:
        figures()
        fig = lobes.plot(lobes=args.method == "zoa", recommendation=best, title=f"Stability lobes: {cut.describe()}")
        save_figure(fig, args.plot, args.overwrite)
    if args.json:
        out = lobes.to_json()
        out["recommended"] = None if best is None else best.to_json()
        if limits is not None:
            out["machine"] = limits.to_json()
        if getattr(cut, "workpiece", None) is not None:
            out["workpiece"] = cut.workpiece.to_json()
        if isinstance(cut, MillingCut):
            out["cut"] = {"teeth": cut.teeth, "diameter_m": float(cut.diameter.m_as("m")),
                          "radial_depth_m": float(cut.radial_depth.m_as("m")), "milling": cut.milling,
                          "kt_pa": cut.kt_pa, "kn_pa": cut.kn_pa,
                          "feed_per_tooth_m": None if cut.feed_per_tooth is None else float(cut.feed_per_tooth.m_as("m"))}
        out["notes"] = notes
        return print_json(out)
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
    peaks = lobes.best_speeds(3)
    if peaks:
        print("best speeds (the tips of the lobes: the limit itself, no margin):")
        for n, a in peaks:
            k = int(np.argmin(np.abs(speeds - n)))
            print(f"  {n:9.6g} rpm   depth limit {a * 1e3:.4g} mm   chatter {lobes.chatter_frequency_hz[k]:.5g} Hz")
    if best is not None:
        lines = best.describe()
        print(f"recommended: {lines[0]}")
        for line in lines[1:]:
            print(f"  {line}")
        if best.mrr_m3_per_s is None:
            print("  (give --feed-per-tooth for the removal rate and the power check)")
        for k, other in enumerate(best.runners_up, 1):
            print(f"runner-up {k}: {other.describe()[0]} (limit {other.limit_depth_m * 1e3:.3g} mm within "
                  f"{other.window_rpm[0]:.0f}..{other.window_rpm[1]:.0f} rpm)")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0


# -- entry point ----------------------------------------------------------------------


# -- predict --------------------------------------------------------------------------


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
    where.add_argument("--band", type=_band, metavar="auto|all|LO:HI",
                       help="FRF lines to use: auto (default: leave out rigid-body and suspension lines, "
                            "reported), all, or LO:HI in Hz")
    cutting = lobes.add_argument_group("milling cut")
    cutting.add_argument("--teeth", type=int, metavar="N", help="number of teeth (default: the tool's, with --assembly)")
    cutting.add_argument("--diameter", metavar="D",
                         help="tool diameter with its unit, e.g. '12 mm' (default: the tool's, with --assembly)")
    cutting.add_argument("--radial-depth", metavar="A", help="radial depth of cut with its unit, e.g. '3 mm'")
    cutting.add_argument("--immersion", type=float, metavar="RATIO", help="radial immersion a/D, in (0, 1]")
    cutting.add_argument("--milling", choices=("up", "down"), default="up", help="up (default) or down milling")
    cutting.add_argument("--kt", metavar="PRESSURE", help="tangential cutting coefficient, e.g. '625 MPa'")
    cutting.add_argument("--kn", metavar="PRESSURE", help="normal (radial) cutting coefficient, e.g. '100 MPa'")
    cutting.add_argument("--kr", type=float, metavar="RATIO", help="or the ratio Kn/Kt, e.g. 0.16")
    cutting.add_argument("--workpiece", metavar="NAME",
                         help="cutting coefficients from the table, e.g. aluminium-7075, steel-1045 (instead of --kt)")
    cutting.add_argument("--workpiece-table", metavar="FILE.toml", help="your own table of workpieces, searched first")
    cutting.add_argument("--feed-per-tooth", metavar="C",
                         help="feed per tooth with its unit, e.g. '0.1 mm' (removal rate, power; Kienzle entries)")
    machine = lobes.add_argument_group("machine and recommendation")
    machine.add_argument("--max-speed", type=_speed, metavar="RPM", help="highest spindle speed (rpm)")
    machine.add_argument("--min-speed", type=_speed, metavar="RPM", help="lowest spindle speed (rpm)")
    machine.add_argument("--power", metavar="P", help="spindle power with its unit, e.g. '15 kW'")
    machine.add_argument("--power-curve", type=lambda t: _curve(t, "kW"), metavar="RPM:KW,...",
                         help="spindle power curve, e.g. 0:0,6000:15,24000:15 (rpm:kW, linear between)")
    machine.add_argument("--torque", metavar="T", help="spindle torque with its unit, e.g. '60 N*m'")
    machine.add_argument("--torque-curve", type=lambda t: _curve(t, "N*m"), metavar="RPM:NM,...",
                         help="spindle torque curve (rpm:N m, linear between)")
    machine.add_argument("--max-depth", metavar="A",
                         help="largest axial depth with its unit (default: the tool's flute length, where known)")
    machine.add_argument("--margin", type=float, default=0.2, metavar="FRACTION",
                         help="fraction of the stability limit kept in reserve (default 0.2)")
    machine.add_argument("--speed-tolerance", type=float, default=0.03, metavar="FRACTION",
                         help="the speed must stay stable within +- this fraction (default 0.03)")
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
    # '-2000:24000:50' is a (bad) value, not an option: let it reach the option's check
    lobes._negative_number_matcher = re.compile(r"^-[\d.]")
