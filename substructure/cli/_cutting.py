"""What the commands that cut share (``lobes``, ``report``): the options of the cut, the machine and the lobes.

The options are added by :func:`add_cut_options` and :func:`add_lobes_options`
and read back into library objects by :func:`cut_from_args` and
:func:`limits_from_args`, so that every command that computes lobes takes the
same options with the same defaults and the same errors.  Imported by the
parsers: the library's modules are imported inside the functions.
"""

from __future__ import annotations

import argparse
import re
from typing import Any

from ._common import UsageError, band_arg, range_arg

CUT_OPTIONS = ("radial_depth", "immersion", "kt", "kn", "kr", "workpiece", "feed_per_tooth", "turning", "kf",
               "orientation")
"""The options (argparse destinations) that describe a cut: any one of them given means a cut is asked for."""

MILLING_WORDS = ("down", "climb", "up", "conventional")
"""What ``--milling`` accepts: climb is down milling, conventional is up milling."""

MACHINE_OPTIONS = ("max_speed", "min_speed", "power", "power_curve", "torque", "torque_curve", "max_depth")
"""The options (argparse destinations) that describe the machine's limits."""


DEFAULT_SPEED_STEP = 50.0
"""The step [rpm] of ``--speeds START:STOP`` (and ``--speed-range START-STOP``) without a step: the default
grid's."""

_THOUSANDS = re.compile(r"^\s*(\d+(?:\.\d*)?|\.\d+)\s*k\s*(rpm)?\s*$", re.IGNORECASE)
_DASHED = re.compile(r"^\s*(\d+(?:\.\d*)?|\.\d+)\s*(k?)\s*(?:-|\.\.|to)\s*(\d+(?:\.\d*)?|\.\d+)\s*(k?)\s*(?:rpm)?\s*$",
                     re.IGNORECASE)


def _thousands(text: str) -> str:
    """``20k`` (or ``20k rpm``, ``2.4K``) is 20,000 rpm: the shop's thousands, not pint's Boltzmann constant."""
    match = _THOUSANDS.match(text)
    return f"{float(match.group(1)) * 1000.0!r} rpm" if match else text


def speeds_arg(text: str):
    """Spindle speeds: ``START:STOP:STEP``, ``START:STOP`` or ``START-STOP`` (the step
    :data:`DEFAULT_SPEED_STEP`); plain numbers are rpm, ``20k`` is 20,000 rpm; units allowed, Hz refused."""
    from ..stability import spindle_speeds

    dashed = _DASHED.match(text) if ":" not in text else None
    if dashed:
        lo, klo, hi, khi = dashed.groups()
        parts = [f"{float(lo) * (1000.0 if klo else 1.0)!r}", f"{float(hi) * (1000.0 if khi else 1.0)!r}"]
    else:
        parts = [_thousands(p) for p in text.split(":")]
    if len(parts) == 2:
        parts.append(f"{DEFAULT_SPEED_STEP!r}")
    return range_arg(":".join(parts), "rpm", spindle_speeds,
                     "2000:24000:50 (rpm), 2000:24000 (50 rpm steps), 2k-24k or '2000 rpm:24000 rpm:50 rpm'",
                     shown=text)


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
    """A spindle speed: a plain number is rpm, ``20k`` is 20,000 rpm; a value in other words is refused here,
    in plain language."""
    try:
        return f"{float(text)!r} rpm"
    except ValueError:
        pass
    text = _thousands(text)
    from ..errors import SubstructureError
    from ..stability import as_speed_rpm

    try:
        as_speed_rpm(text)
    except SubstructureError:
        raise argparse.ArgumentTypeError(
            f"got {text!r}; expected a spindle speed in rpm: a number (20000), thousands (20k) or with its unit "
            "('20000 rpm')") from None
    return text


def kr_arg(text: str) -> float:
    """``--kr``: the ratio Kn/Kt, a plain number; a pressure is refused with the hint that it belongs in ``--kn``."""
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"got {text!r}; expected the ratio Kn/Kt, a plain number such as 0.3 (a pressure such as '100 MPa' "
            "is the normal coefficient itself: give it with --kn)") from None


def add_cut_options(parser: argparse.ArgumentParser) -> None:
    """Add the groups "milling cut", "machine and recommendation" and "turning" to a command's parser."""
    cutting = parser.add_argument_group("milling cut")
    cutting.add_argument("--teeth", type=int, metavar="N",
                         help="number of teeth (default: the tool's, with an assembly)")
    cutting.add_argument("--diameter", metavar="D",
                         help="tool diameter with its unit, e.g. '12 mm' (default: the tool's, with an assembly)")
    cutting.add_argument("--radial-depth", metavar="A", help="radial depth of cut with its unit, e.g. '3 mm'")
    cutting.add_argument("--immersion", type=float, metavar="RATIO", help="radial immersion a/D, in (0, 1]")
    cutting.add_argument("--milling", type=str.lower, choices=MILLING_WORDS, metavar="{down,climb,up,conventional}",
                         help="down (= climb) or up (= conventional) milling; default up, said in every output")
    cutting.add_argument("--kt", metavar="PRESSURE", help="tangential cutting coefficient, e.g. '625 MPa'")
    cutting.add_argument("--kn", metavar="PRESSURE", help="normal (radial) cutting coefficient, e.g. '100 MPa'")
    cutting.add_argument("--kr", type=kr_arg, metavar="RATIO", help="or the ratio Kn/Kt, e.g. 0.16")
    cutting.add_argument("--workpiece", metavar="NAME",
                         help="cutting coefficients from the table, e.g. aluminium-7075, steel-1045 (instead of --kt)")
    cutting.add_argument("--workpiece-table", metavar="FILE.toml", help="your own table of workpieces, searched first")
    cutting.add_argument("--feed-per-tooth", metavar="C",
                         help="feed per tooth with its unit, e.g. '0.1 mm' (removal rate, power; Kienzle entries); "
                              "with --workpiece the table's default for the work and tool material")
    cutting.add_argument("--tool-material", type=str.lower, choices=("carbide", "hss"),
                         help="the tool's material, for the cutting-speed and feed check (default: the tool's in "
                              "the assembly, else carbide, said in a note)")
    cutting.add_argument("--cutting-data", metavar="FILE.toml",
                         help="your own table of cutting-speed and feed ranges, searched first")
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
    # '-2000:24000:50' is a (bad) value, not an option: let it reach the option's check
    parser._negative_number_matcher = re.compile(r"^-[\d.]")
    parser.add_argument("--method", choices=("zoa", "sdm"), default="zoa",
                        help="zoa: zero-order (default, from FRF data); sdm: semi-discretization (modes; fitted "
                             "to FRF data when needed)")
    parser.add_argument("--speeds", "--speed-range", type=speeds_arg, default="2000:24000:50",
                        metavar="START:STOP[:STEP]",
                        help="spindle speeds in rpm: 2000:24000:50, 2000:24000 or 2000-24000 (50 rpm steps), "
                             "2k-24k (default 2000:24000:50)")
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
    return next((comp for comp in assembly.components if isinstance(comp, Tool) and comp.name == name), None)


def cut_from_args(args: argparse.Namespace, tool: Any, notes: list[str]):
    """The cut the options describe: a ``MillingCut`` (teeth and diameter from ``tool`` unless given) or a
    ``TurningCut``; what was taken from where is appended to ``notes``.

    Raises :class:`~substructure.cli._common.UsageError` for missing or conflicting options.
    """
    from ..stability import MillingCut, TurningCut, workpiece

    milling_only = {"--teeth": args.teeth, "--diameter": args.diameter, "--radial-depth": args.radial_depth,
                    "--immersion": args.immersion, "--kt": args.kt, "--kn": args.kn, "--kr": args.kr,
                    "--workpiece": args.workpiece, "--feed-per-tooth": args.feed_per_tooth,
                    "--tool-material": getattr(args, "tool_material", None),
                    "--cutting-data": getattr(args, "cutting_data", None)}
    if args.turning:
        given = [name for name, value in milling_only.items() if value is not None]
        if given:
            raise UsageError(f"--turning takes --kf [--orientation U]; {', '.join(given)} describe a milling cut")
        unused = machine_given(args) + [name for name, value, default in (
            ("--margin", getattr(args, "margin", 0.2), 0.2),
            ("--speed-tolerance", getattr(args, "speed_tolerance", 0.03), 0.03)) if value != default]
        if unused:
            verb = "sets" if len(unused) == 1 else "set"
            raise UsageError(f"--turning: {', '.join(unused)} {verb} the machinist's recommendation, which is for "
                             "milling cuts (a turning cut gets the lobes only): leave them out")
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
    for name, value in (("--workpiece-table", args.workpiece_table),
                        ("--cutting-data", getattr(args, "cutting_data", None)),
                        ("--tool-material", getattr(args, "tool_material", None))):
        if value is not None and args.workpiece is None:
            raise UsageError(f"{name} goes with --workpiece NAME" + ("" if name == "--workpiece-table" else
                             " (the cutting-speed and feed check is of a workpiece from the table)"))
    milling = milling_of(args, notes)
    if args.workpiece is not None:
        if args.kt is not None:
            raise UsageError("give --workpiece NAME or --kt, not both (the table gives Kt)")
        entry = workpiece(args.workpiece, args.workpiece_table)
        notes.append(f"workpiece: {entry.describe()}")
        for name, value in (("--kn", args.kn), ("--kr", args.kr)):
            if value is not None:
                notes.append(f"workpiece: {name} {value} overrides the table's normal coefficient: the cut's Kn "
                             "(the cut: line) is from it")
        feed = args.feed_per_tooth
        if feed is None:
            data = cutting_data_of(args, entry, tool, notes)
            if data is not None:
                feed = data.default_feed_per_tooth
                notes.append(f"feed per tooth: {feed:~P}, the default for {entry.name} with a {data.tool_material} "
                             "tool (cutting_data.toml); give --feed-per-tooth for yours")
        return MillingCut.for_workpiece(teeth, diameter, entry, radial_depth=args.radial_depth,
                                        immersion=args.immersion, milling=milling,
                                        feed_per_tooth=feed, kn=args.kn, kr=args.kr)
    extra = {"feed_per_tooth": args.feed_per_tooth} if args.feed_per_tooth is not None else {}
    return MillingCut.from_spec(teeth, diameter, radial_depth=args.radial_depth, immersion=args.immersion,
                                milling=milling, kt=args.kt, kn=args.kn, kr=args.kr, **extra)


def tool_material_of(args: argparse.Namespace, tool: Any, notes: list[str]) -> str:
    """``--tool-material``, else the material of the assembly's tool when it is carbide or HSS, else carbide (with
    a note saying it was assumed)."""
    given = getattr(args, "tool_material", None)
    if given is not None:
        return given
    if tool is not None:
        names = {s.material.name.lower() for s in getattr(tool, "segments", ()) if s.material is not None}
        for name in ("carbide", "hss"):
            if any(name in n for n in names):
                return name
    notes.append("tool material: carbide assumed for the cutting-speed check; give --tool-material hss for a "
                 "high-speed steel tool")
    return "carbide"


def cutting_data_of(args: argparse.Namespace, entry: Any, tool: Any, notes: list[str]):
    """The cutting-data row of the workpiece ``entry`` and the tool material (None when no table has one; noted).
    Looked up once per command: the result is kept on ``args``."""
    if hasattr(args, "_cutting_data"):
        return args._cutting_data
    from ..stability import cutting_data

    material = tool_material_of(args, tool, notes)
    row = cutting_data(entry, material, getattr(args, "cutting_data", None))
    if row is None:
        notes.append(f"cutting data: no range for {entry.name} with a {material} tool; the cutting speed and feed "
                     "are not checked")
    args._cutting_data = row
    return row


def cutting_check(args: argparse.Namespace, cut: Any, tool: Any, best: Any, notes: list[str]) -> dict | None:
    """The shop's numbers of the recommendation checked against the table (the ``cutting_data`` object of
    ``--json``), with a :class:`~substructure.stability.CuttingDataWarning` per value outside its range."""
    import warnings

    from ..stability import CuttingDataWarning, check_cutting, cutting_conditions

    if best is None or getattr(cut, "workpiece", None) is None:
        return None
    data = cutting_data_of(args, cut.workpiece, tool, notes)
    out = cutting_conditions(cut, best.spindle_speed_rpm, data)
    out["warnings"] = check_cutting(cut, best.spindle_speed_rpm, data)
    for text in out["warnings"]:
        warnings.warn(f"{text}: check the recommendation against your tool maker's data", CuttingDataWarning,
                      stacklevel=2)
    return out


MILLING_DEFAULT_NOTE = ("milling: up (conventional) milling, the default (kept for the results of earlier "
                        "versions); most CNC programs climb-mill: give --milling down (or climb) for that")
"""The note every output carries when ``--milling`` was not given."""


def milling_of(args: argparse.Namespace, notes: list[str]) -> str:
    """The milling direction of ``--milling`` as ``"up"`` or ``"down"``; the default up, with
    :data:`MILLING_DEFAULT_NOTE` appended to ``notes``."""
    given = getattr(args, "milling", None)
    if given is None:
        notes.append(MILLING_DEFAULT_NOTE)
        return "up"
    return "down" if given in ("down", "climb") else "up"


DEEP_CUT_DIAMETERS = 4.0
"""A recommended depth more than this many tool diameters, with no largest depth to bound it, is warned of:
end mills' flutes reach about 2 to 4 diameters (a recommendation deeper than the flutes cuts with the shank)."""


def deep_cut_note(best: Any, cut: Any, limits: Any) -> str | None:
    """The warning for a recommended depth beyond :data:`DEEP_CUT_DIAMETERS` tool diameters that no largest depth
    bounds (an FRF or modes do not say the flute length; a tiny radial immersion leaves a huge limit), or None."""
    if best is None or limits is None or limits.max_depth is not None:
        return None
    diameter = float(cut.diameter.m_as("m"))
    if not best.depth_m > DEEP_CUT_DIAMETERS * diameter:
        return None
    return (f"warning: the recommended depth {best.depth_m * 1e3:.4g} mm is {best.depth_m / diameter:.3g} times the "
            f"tool's diameter ({diameter * 1e3:.4g} mm), and no largest depth bounds it: give --max-depth (the flute "
            "length; --assembly takes it from the tool), as a depth beyond the flutes cannot be cut")


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
