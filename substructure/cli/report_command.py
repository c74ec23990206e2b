"""The ``substructure report`` command: one self-contained HTML report of an assembly, its tap tests and a cut."""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import warnings
from pathlib import Path

from ..errors import SubstructureWarning
from ._common import PROG, UsageError, check_outputs, measurement_inputs, print_json
from ._cutting import (
    add_cut_options,
    add_lobes_options,
    cut_from_args,
    cut_given,
    limits_from_args,
    machine_given,
    structure_band_arg,
    tool_of,
)

REPORT_SUFFIXES = (".html", ".htm")
"""The files ``--out`` writes."""


def _identify(text: str):
    """``--identify``: ``auto``, ``none`` or comma-separated joint names."""
    value = text.strip()
    if value == "auto":
        return "auto"
    if value == "none":
        return None
    names = [name.strip() for name in value.split(",") if name.strip()]
    if not names:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected auto, none or joint names, e.g. holder-tool")
    return names


def _title(text: str) -> str:
    """``--title``: bytes of the command line that are not UTF-8 (a Latin-1 terminal) as U+FFFD, said at once.

    Python hands such bytes over as lone surrogates, which no page can be
    written with; they are replaced here, before anything is computed.
    """
    if not any("\udc80" <= ch <= "\udcff" for ch in text):
        return text
    raw = os.fsencode(text)  # the bytes as typed
    bad = sorted({f"0x{ord(ch) - 0xdc00:02x}" for ch in text if "\udc80" <= ch <= "\udcff"})
    cleaned = raw.decode("utf-8", errors="replace")
    warnings.warn(f"--title: bytes that are not UTF-8 ({', '.join(bad)}) are shown as U+FFFD: {cleaned!r} (give "
                  "the title in UTF-8, the encoding of the page)", SubstructureWarning, stacklevel=2)
    return cleaned


def run(args: argparse.Namespace) -> int:
    from ..io.assembly_toml import load_assembly
    from ..report import report, tool_point
    from ..stability import CuttingDataWarning, MillingCut

    suffix = Path(args.out).suffix.lower()
    if suffix not in REPORT_SUFFIXES:
        got = f"the suffix {suffix!r}" if suffix else "no suffix"
        raise UsageError(f"argument --out: {args.out!r} has {got}; expected an HTML file (.html)")
    inputs = [args.assembly, args.workpiece_table]
    if args.measurements is not None:
        inputs += measurement_inputs(args.measurements)
    check_outputs([("--out", args.out)], inputs, args.overwrite)
    if args.intervals is not None and args.method != "sdm":
        raise UsageError("--intervals sets the semi-discretization: use it with --method sdm")
    if args.identify != "auto" and args.measurements is None:
        raise UsageError("--identify names joints to identify from the measurements: give MEASUREMENTS.toml")
    given = cut_given(args)
    if not given:
        extra = machine_given(args) + [name for name, value in (("--method", args.method != "zoa"),
                                                                   ("--intervals", args.intervals is not None))
                                       if value]
        if extra:
            verb = "goes" if len(extra) == 1 else "go"
            raise UsageError(f"{', '.join(extra)} {verb} with a cut: give the cut too (e.g. --radial-depth '3 mm' "
                             "--workpiece aluminium-7075)")
    assembly = load_assembly(args.assembly)
    at = tool_point(assembly, args.at)
    tool = tool_of(assembly, at)
    notes: list[str] = []
    cut = limits = None
    if given:
        cut = cut_from_args(args, tool, notes)
        if isinstance(cut, MillingCut):
            limits = limits_from_args(args, tool, notes)
        elif machine_given(args):
            raise UsageError(f"{', '.join(machine_given(args))} are limits for a milling cut's recommendation")
    progress = None if args.quiet else (lambda text: print(f"{PROG}: {text}", file=sys.stderr, flush=True))
    argv = getattr(args, "argv", None)
    command = " ".join(shlex.quote(str(a)) for a in [PROG, *argv]) if argv else None
    result = report(args.assembly, args.measurements, cut, limits, at=at, speeds=args.speeds if given else None,
                    band="auto" if args.band is None else args.band, method=args.method, intervals=args.intervals,
                    margin=args.margin, speed_tolerance=args.speed_tolerance, identify=args.identify,
                    title=args.title, notes=notes, command=command, progress=progress or False,
                    tool_material=args.tool_material, cutting_table=args.cutting_data)
    for text in (result.cutting or {}).get("warnings", []):
        warnings.warn(f"{text}: check the recommendation against your tool maker's data", CuttingDataWarning,
                      stacklevel=2)
    path = result.save(args.out, overwrite=args.overwrite)
    size = path.stat().st_size
    if args.json:
        summary = result.to_json()
        summary["file"] = str(path)
        summary["bytes"] = size
        return print_json(summary)
    print(f"wrote {path} ({size / 1024:.0f} kB): {result.title}")
    best = result.recommendation
    if best is not None:
        print(f"recommended: {best.describe()[0]}")
        print(f"  {best.describe()[1]}")
        shop = [line for line in best.describe() if line.startswith("cutting speed")]
        if shop:
            print(f"  {shop[0]}")
        robust = result.band_recommendation
        if robust is not None:
            print(f"  across the joints' uncertainty ({len(result.band.members)} variants): {robust.describe()[0]}")
            lo, hi = result.depth_range_m
            print(f"  until the joints are identified, use that; each variant alone allows {lo * 1e3:.3g} to "
                  f"{hi * 1e3:.3g} mm (against a holder whose range overlaps, the order is not decided by the data)")
        elif result.band_no_recommendation:
            print(f"  across the joints' uncertainty: no recommendation ({result.band_no_recommendation})")
    elif result.no_recommendation:
        print(f"no recommendation: {result.no_recommendation}")
    else:
        print("no cut given: the report shows the model, its tool point FRF"
              + (", the tap test" if result.diagnosis is not None else "") + " and the joints")
    if result.diagnosis is not None:
        from ..report.text import diagnosis_verdict

        print(f"tap test: {diagnosis_verdict(result.diagnosis.to_json())[1]}")
    print(f"open it in a browser: {path.resolve().as_uri()}")
    return 0


def add_parser(commands) -> None:
    """Add the ``report`` subcommand to the subparsers ``commands``."""
    rep = commands.add_parser("report", help="one self-contained HTML report: model, tool point FRF, tap test, "
                                             "lobes and the recommended speed and depth")
    rep.add_argument("assembly", metavar="ASSEMBLY.toml", help="assembly file (docs/file-formats.md)")
    rep.add_argument("measurements", nargs="?", metavar="MEASUREMENTS.toml",
                     help="measurement set of tap tests (optional): adds the diagnosis and the joints identified")
    rep.add_argument("--out", required=True, metavar="FILE.html", help="the report file to write")
    rep.add_argument("--at", metavar="POINT", help="the tool point (default: the tip of the assembly's tool)")
    rep.add_argument("--band", type=structure_band_arg, metavar="auto|all|LO:HI",
                     help="FRF lines stability uses: auto (default: leave out rigid-body and suspension lines), "
                          "all, or LO:HI in Hz")
    add_cut_options(rep)
    add_lobes_options(rep)
    rep.add_argument("--identify", type=_identify, default="auto", metavar="auto|none|NAMES",
                     help="joints to identify from the measurements: auto (every elastic joint, default), none, "
                          "or comma-separated names")
    rep.add_argument("--title", type=_title, metavar="TEXT",
                     help="the report's title (default: 'Tool report: <assembly name>')")
    rep.add_argument("--overwrite", action="store_true", help="let --out replace an existing file (never an input)")
    rep.add_argument("--quiet", action="store_true", help="no progress on standard error")
    rep.add_argument("--json", action="store_true",
                     help="print one JSON object (the report's summary) instead of the lines for people")
    rep.set_defaults(run=run)
