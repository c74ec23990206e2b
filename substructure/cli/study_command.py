"""The ``substructure study`` command: a whole tool library on Dask, resumable, with progress."""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
from pathlib import Path

from ._common import EXIT_INTERRUPTED, PROG, UsageError, check_outputs, print_json


def _interrupt(signum, frame):  # SIGTERM stops the study as Ctrl-C does: saved results stay, clusters close
    raise KeyboardInterrupt


def run(args: argparse.Namespace) -> int:
    from ..errors import InvalidValueError
    from ..study import Study
    from ..study.runner import parse_scheduler

    if args.resume and args.overwrite:
        raise UsageError("--resume and --overwrite: choose one (--resume keeps finished combinations, --overwrite "
                         "computes everything anew)")
    if args.scheduler is not None:
        try:
            parse_scheduler(args.scheduler)
        except InvalidValueError as exc:
            raise UsageError(f"argument --scheduler: {exc}") from None
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"argument --out: {out} is a file; expected a directory (created if missing)")
    study = Study.from_file(args.study)
    names = ("table.parquet", "table.csv", "summary.png")
    check_outputs([("--out", out / n) for n in names if out.is_dir()], study.inputs, True)
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        table = study.run(out=out, scheduler=args.scheduler or "processes", resume=args.resume,
                          overwrite=args.overwrite, progress=not args.quiet)
    except KeyboardInterrupt as exc:  # one line: what is saved and how to go on (the progress said it unless quiet)
        if args.quiet and exc.args:
            print(f"{PROG}: {exc.args[0]}", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        signal.signal(signal.SIGTERM, previous)
    return _report(args, study, table, out)


def _report(args, study, table, out: Path) -> int:
    from ..study.table import rank_value

    counts = {s: int((table["status"] == s).sum()) for s in ("ok", "failed", "crashed", "pending")}
    value, label = rank_value(table)
    best = []
    none_ok = []  # cuts whose every row failed (or is not computed): nothing to call best
    for cut in dict.fromkeys(table["cut"].tolist()):
        rows = table[(table["cut"] == cut) & (table["status"] == "ok") & value.notna()]
        if not (table.loc[table["cut"] == cut, "status"] == "ok").any():
            none_ok.append(cut)
        if len(rows):
            i = value[rows.index].idxmax()
            row = table.loc[i]
            best.append({"cut": cut, "combination": row["combination"], "machine": row["machine"],
                         "spindle_speed_rpm": row["spindle_speed_rpm"], "depth_m": row["depth_m"],
                         "mrr_m3_per_s": row["mrr_m3_per_s"], "tool_mode_hz": row["tool_mode_hz"],
                         "extrapolated": _extrapolated(row["notes"])})
    failures = [{k: table.loc[i, k] for k in ("combination", "machine", "cut", "status", "error")}
                for i in table.index[table["status"] != "ok"]]
    files = {"table_parquet": os.fspath(out / "table.parquet"), "table_csv": os.fspath(out / "table.csv"),
             "results": os.fspath(out / "results"), "figures": os.fspath(out / "figures") if study.compute.figures
             else None, "summary": os.fspath(out / "summary.png") if study.compute.figures else None,
             "frf": os.fspath(out / "frf") if study.compute.frf_files else None}
    if args.json:
        return print_json({"study": study.name, "out": os.fspath(out), "rows": len(table), **counts,
                           "ranked_by": label, "best": best, "no_ok_row": none_ok, "failures": failures,
                           "files": files})
    print(f"study {study.name!r}: {len(table)} rows (combinations on their machines, for each cut): "
          + ", ".join(f"{n} {s}" for s, n in counts.items() if n or s == "ok"))
    print(f"table: {files['table_parquet']}, {files['table_csv']}"
          + (f"; figures: {files['figures']}; summary: {files['summary']}" if files["figures"] else ""))
    if best:
        print(f"best by {label}:")
        for b in best:
            cut = f"cut {b['cut']!r}: " if b["cut"] else ""
            what = (f"{b['spindle_speed_rpm']:.0f} rpm, axial depth {b['depth_m'] * 1e3:.3g} mm"
                    if b["spindle_speed_rpm"] == b["spindle_speed_rpm"] else f"tool mode {b['tool_mode_hz']:.0f} Hz")
            caveat = (f" (extrapolated: {'; '.join(b['extrapolated'])}; the joint's prediction is not to be trusted)"
                      if b["extrapolated"] else "")
            print(f"  {cut}{b['combination']} on {b['machine']}: {what}{caveat}")
    for cut in none_ok:
        print(f"no best {f'for cut {cut!r}' if cut else 'combination'}: no row succeeded (see below)")
    for f in failures[:20]:
        cut = f" / {f['cut']}" if f["cut"] else ""
        print(f"{f['status']}: {f['combination']} on {f['machine']}{cut}: {f['error']}")
    if len(failures) > 20:
        print(f"... and {len(failures) - 20} more rows that did not succeed (see the table's status and error)")
    return 0


_EXTRAPOLATION = re.compile(r"^(?P<value>\S+ = \S+(?: \S+)?) is .*?the table's range (?P<range>\S+(?: \S+)?)\) "
                            r"(?:below the smallest|above the largest) in the table: an extrapolation")


def _extrapolated(notes: str) -> list[str]:
    """The features of a row's joint prediction outside the joint table's range, from its notes (the
    surrogate's extrapolation warnings), as ``"gauge_length = 300 mm (table 65-106 mm)"``."""
    out = []
    for note in str(notes).split("; "):
        if "an extrapolation" not in note:
            continue
        m = _EXTRAPOLATION.match(note)
        out.append(f"{m['value']} outside the joint table's {m['range']}" if m else note)
    return out


def add_parser(commands) -> None:
    """Add the ``study`` subcommand to the subparsers ``commands``."""
    study = commands.add_parser("study", help="a whole tool library on Dask: FRFs, bands, lobes and recommendations "
                                              "of every holder/tool combination, resumable")
    study.add_argument("study", metavar="STUDY.toml", help="the study file (docs/file-formats.md)")
    study.add_argument("--out", required=True, metavar="DIR",
                       help="output directory: results/ per combination as it completes, figures/, frf/, "
                            "table.parquet, table.csv, summary.png")
    study.add_argument("--scheduler", metavar="ADDRESS|local:N|processes:N|serial",
                       help="processes:N (default, N = the CPUs): a local Dask cluster of N worker processes; "
                            "local:N: N worker threads in this process; an address (tcp://host:8786): an existing "
                            "scheduler; serial: this process without Dask")
    study.add_argument("--resume", action="store_true",
                       help="keep the combinations finished in DIR (same inputs) and compute the rest")
    study.add_argument("--overwrite", action="store_true", help="compute everything anew, replacing a study in DIR")
    study.add_argument("--quiet", action="store_true", help="no progress lines on standard error")
    study.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    study.set_defaults(run=run)
