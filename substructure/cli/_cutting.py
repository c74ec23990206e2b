"""What the commands that cut share (``lobes``, ``report``): the options of the cut, the machine and the lobes.

The options are added by :func:`add_cut_options` and :func:`add_lobes_options`
and read back into library objects by :func:`cut_from_args` and
:func:`limits_from_args`, so that every command that computes lobes takes the
same options with the same defaults and the same errors.  Imported by the
parsers: the library's modules are imported inside the functions.
"""

from __future__ import annotations

import argparse
from typing import Any

from ._common import UsageError, band_arg, range_arg

CUT_OPTIONS = ("radial_depth", "immersion", "kt", "kn", "kr", "workpiece", "feed_per_tooth", "turning", "kf",
               "orientation")
"""The options (argparse destinations) that describe a cut: any one of them given means a cut is asked for."""

MACHINE_OPTIONS = ("max_speed", "min_speed", "power", "power_curve", "torque", "torque_curve", "max_depth")
"""The options (argparse destinations) that describe the machine's limits."""


def speeds_arg(text: str):
    """``START:STOP:STEP`` spindle speeds: plain numbers are rpm; units allowed, Hz refused."""
    from ..stability import spindle_speeds

    return range_arg(text, "rpm", spindle_speeds, "2000:24000:50 (rpm) or '2000 rpm:24000 rpm:50 rpm'")


def structure_band_arg(text: str):
    """``--band``: ``auto`` (default), ``all`` or ``LO:HI`` (Hz, or frequencies with units)."""
    if text.strip() == "all":
        return "all"
    try:
        return band_arg(text)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(str(exc).replace("expected auto or LO:HI", "expected auto, all or LO:HI"))


def curve_arg(text: str, unit: str):
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


def speed_arg(text: str) -> str:
    """A spindle speed: a plain number is rpm."""
    try:
        return f"{float(text)!r} rpm"
    except ValueError:
        return text


def add_cut_options(parser: argparse.ArgumentParser) -> None:
    """Add the groups "milling cut", "machine and recommendation" and "turning" to a command's parser."""
    cutting = parser.add_argument_group("milling cut")
    cutting.add_argument("--teeth", type=int, metavar="N", help="number of teeth (default: the tool's, with an assembly)")
    cutting.add_argument("--diameter", metavar="D",
                         help="tool diameter with its unit, e.g. '12 mm' (default: the tool's, with an assembly)")
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
    machine = parser.add_argument_group("machine and recommendation")
    machine.add_argument("--max-speed", type=speed_arg, metavar="RPM", help="highest spindle speed (rpm)")
    machine.add_argument("--min-speed", type=speed_arg, metavar="RPM", help="lowest spindle speed (rpm)")
    machine.add_argument("--power", metavar="P", help="spindle power with its unit, e.g. '15 kW'")
    machine.add_argument("--power-curve", type=lambda t: curve_arg(t, "kW"), metavar="RPM:KW,...",
                         help="spindle power curve, e.g. 0:0,6000:15,24000:15 (rpm:kW, linear between)")
    machine.add_argument("--torque", metavar="T", help="spindle torque with its unit, e.g. '60 N*m'")
    machine.add_argument("--torque-curve", type=lambda t: curve_arg(t, "N*m"), metavar="RPM:NM,...",
                         help="spindle torque curve (rpm:N m, linear between)")
    machine.add_argument("--max-depth", metavar="A",
                         help="largest axial depth with its unit (default: the tool's flute length, where known)")
    machine.add_argument("--margin", type=float, default=0.2, metavar="FRACTION",
                         help="fraction of the stability limit kept in reserve (default 0.2)")
    machine.add_argument("--speed-tolerance", type=float, default=0.03, metavar="FRACTION",
                         help="the speed must stay stable within +- this fraction (default 0.03)")
    turning = parser.add_argument_group("turning or boring (Tlusty's oriented single direction)")
    turning.add_argument("--turning", action="store_true", help="a turning cut instead of milling")
    turning.add_argument("--kf", metavar="PRESSURE", help="cutting pressure along the resultant force, e.g. '2000 MPa'")
    turning.add_argument("--orientation", type=float, metavar="U", help="directional factor u in x (default 1)")


def add_lobes_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--method``, ``--speeds`` and ``--intervals`` to a command's parser."""
    parser.add_argument("--method", choices=("zoa", "sdm"), default="zoa",
                        help="zoa: zero-order (default, from FRF data); sdm: semi-discretization (modes; fitted "
                             "to FRF data when needed)")
    parser.add_argument("--speeds", type=speeds_arg, default="2000:24000:50", metavar="START:STOP:STEP",
                        help="spindle speeds in rpm (default 2000:24000:50)")
    parser.add_argument("--intervals", type=int, metavar="M",
                        help="sdm: intervals in the cut per delay period (default: chosen per speed)")


def cut_given(args: argparse.Namespace) -> bool:
    """Whether any option that describes a cut was given (:data:`CUT_OPTIONS`)."""
    return any(getattr(args, name, None) not in (None, False) for name in CUT_OPTIONS)


def machine_given(args: argparse.Namespace) -> list[str]:
    """The machine options given, as ``--option`` names (:data:`MACHINE_OPTIONS`)."""
    return ["--" + name.replace("_", "-") for name in MACHINE_OPTIONS if getattr(args, name, None) is not None]


def tool_of(assembly: Any, at: str):
    """The :class:`~substructure.components.Tool` component that holds the point ``at`` (or None)."""
    from ..components import Tool
    from ..points import parse_point

    name = parse_point(at).component
    for comp in assembly.components:
        if isinstance(comp, Tool) and comp.name == name:
            return comp
    return None


def cut_from_args(args: argparse.Namespace, tool: Any, notes: list[str]):
    """The cut the options describe: a ``MillingCut`` (teeth and diameter from ``tool`` unless given) or a
    ``TurningCut``; what was taken from where is appended to ``notes``.

    Raises :class:`~substructure.cli._common.UsageError` for missing or conflicting options.
    """
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


def limits_from_args(args: argparse.Namespace, tool: Any, notes: list[str]):
    """The machine's limits the options give (``MachineLimits``); the largest depth defaults to the flute
    length of ``tool`` (noted in ``notes``)."""
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
