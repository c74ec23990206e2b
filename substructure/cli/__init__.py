"""The ``substructure`` command: the library's workflows without writing code.

Each subcommand is a module of this package (``frf_command``, ``tap_command``, ``identify_command``,
``diagnose_command``, ``lobes_command``, ``predict_command``, ``report_command``,
``study_command``, ``demo_command``) with ``add_parser(commands)`` and ``run(args)``; the modules
import the heavy parts of the library only when their command runs, so that a
one-shot command loads what it needs and nothing more.  Options that several
commands share live in ``_common`` (all of them) and ``_cutting`` (the cut, the
machine and the lobes: ``lobes`` and ``report``).  The options and JSON outputs are documented in
docs/cli.md and docs/file-formats.md.

Every subcommand prints a human summary, or with ``--json`` exactly one strict
JSON object (SI units, Hz; no NaN or Infinity) and nothing else on standard
output.  A user's mistake prints ``substructure: error: ...`` on standard error
and returns 1 (2 for misuse of the options), never a traceback; an unexpected
exception (a bug) prints one ``substructure: error: internal error: ...`` line
with a request to report it and returns 70 (``SUBSTRUCTURE_DEBUG=1`` shows the
traceback instead); warnings print once each as ``substructure: warning: ...``
on standard error.  No command writes over an existing file without
``--overwrite``, nor over one of its inputs.
"""

from __future__ import annotations

import importlib
import os
import sys
import warnings

from ..errors import SubstructureError
from ._common import EXIT_ERROR, EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_USAGE, PROG, Parser, UsageError, one_line

__all__ = ["main", "DEMO_STEPS", "DemoState", "COMMANDS"]

COMMANDS = ("frf", "tap", "identify", "diagnose", "lobes", "predict", "report", "study", "demo")
"""The subcommands, in the order of ``substructure --help``; each is the module ``<name>_command``."""


def __getattr__(name: str):
    if name in ("DEMO_STEPS", "DemoState"):  # the demo's steps, importable as before
        from . import demo_command

        return getattr(demo_command, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _parser() -> Parser:
    parser = Parser(prog=PROG, description="Receptance coupling of spindle-holder-tool assemblies.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f".{name}_command", __name__).add_parser(commands)
    return parser


def _error(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        return f"{exc.filename}: {exc.strerror}"
    return one_line(str(exc))


PLUGIN_GROUP = "substructure.plugins"
"""Entry-point group whose modules are imported before a command runs.

A package that registers its own component types (``register_component``)
declares ``[project.entry-points."substructure.plugins"] name = "module"``
so that assembly files using its types work from the command line too.
"""


def _load_plugins() -> None:
    from importlib.metadata import entry_points

    for ep in entry_points(group=PLUGIN_GROUP):
        try:
            ep.load()
        except Exception as exc:  # a broken plugin must not break the command
            warnings.warn(f"plugin {ep.name!r} ({ep.value}) failed to load: {exc}", stacklevel=2)


def _internal(exc: BaseException) -> str:
    return (f"internal error: {type(exc).__name__}: {one_line(str(exc)) or 'no message'}; this is a bug in "
            f"{PROG}: please report it with the command line and the input files "
            "(SUBSTRUCTURE_DEBUG=1 shows the traceback)")


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status.

    Parameters
    ----------
    argv : list of str, optional
        The arguments without the program name (default ``sys.argv[1:]``).

    Returns
    -------
    int
        0 success, 1 an error in the input (a file, a value), 2 misuse of
        the command line, 70 an internal error (a bug: one line asking to
        report it, never a traceback unless ``SUBSTRUCTURE_DEBUG=1``), 130
        interrupted.
    """
    reported: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        text = one_line(str(message))
        if text not in reported:
            reported.add(text)
            print(f"{PROG}: warning: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = show
        try:
            _load_plugins()
            args = _parser().parse_args(argv)
            args.argv = list(sys.argv[1:] if argv is None else argv)  # the command line, for reports
            if args.command is None:
                raise UsageError(f"choose a command: {', '.join(COMMANDS)} (see substructure --help)")
            return args.run(args)
        except UsageError as exc:
            print(f"{PROG}: error: {one_line(str(exc))}", file=sys.stderr)
            return EXIT_USAGE
        except BrokenPipeError:  # e.g. piped into `head`: stop quietly
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            return EXIT_ERROR
        except (SubstructureError, OSError) as exc:
            print(f"{PROG}: error: {_error(exc)}", file=sys.stderr)
            return EXIT_ERROR
        except MemoryError:
            print(f"{PROG}: error: out of memory; the problem is too large for this computer (fewer frequency "
                  "lines, speeds or variants)", file=sys.stderr)
            return EXIT_ERROR
        except SystemExit as exc:  # --help and --version print and exit
            return exc.code if isinstance(exc.code, int) else 0
        except KeyboardInterrupt:
            print(f"{PROG}: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED
        except Exception as exc:  # a bug: one line, never a traceback, unless asked for
            if os.environ.get("SUBSTRUCTURE_DEBUG"):
                raise
            print(f"{PROG}: error: {_internal(exc)}", file=sys.stderr)
            return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
