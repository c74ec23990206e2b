"""The ``substructure demo`` command: the workflow on the built-in assembly, as a list of steps."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import attrs

from ._common import figures, grid_text, peak_table, print_json, save_figure, save_plot

if TYPE_CHECKING:
    from ..frf import FRF

TOOL_POINT = "tool.tip:y"
"""The tool point of the built-in assembly."""


DEMO_FILES = ("tool_point_frf.csv", "tool_point_frf.png", "default_assembly.toml", "tap_test",
              "where_it_fails.png", "error_fall.png", "improved_assembly.toml")
"""What the built-in steps write into ``--out`` (checked before the first step)."""


@attrs.define
class DemoState:
    """What the demo steps share: the output directory, results so far, files written.

    ``overwrite`` says whether a step may replace an existing file (the
    command's ``--overwrite``); steps write every file through
    :mod:`substructure.io`'s atomic writers with it.
    """

    out: Path
    overwrite: bool = False
    assembly: Any = None
    frf: FRF | None = None
    results: dict = attrs.field(factory=dict)
    files: list = attrs.field(factory=list)
    lines: list = attrs.field(factory=list)
    taps: Any = None


def _demo_load(state: DemoState) -> None:
    from ..io.assembly_toml import default_assembly

    state.assembly = default_assembly()
    state.lines.append(state.assembly.describe())
    state.results["components"] = [c.name for c in state.assembly.components]
    state.results["joints"] = [j.name for j in state.assembly.joints]


def _demo_frf(state: DemoState) -> None:
    state.frf = state.assembly.receptance(TOOL_POINT)
    peaks = peak_table(state.frf)
    tool_mode = max(peaks, key=lambda p: p[1])[0] if peaks else None
    state.results["peaks_hz"] = [f for f, _ in peaks]
    state.results["tool_mode_hz"] = tool_mode
    state.lines.append(f"tool point FRF ({TOOL_POINT}) on {grid_text(state.frf.frequency)}")
    state.lines.append("peaks: " + ", ".join(f"{f:g} Hz" for f, _ in peaks))
    if tool_mode is not None:
        state.lines.append(f"tool mode (highest peak): {tool_mode:g} Hz")
    from ..io.frf_files import write_csv

    path = state.out / "tool_point_frf.csv"
    write_csv(state.frf, path, state.overwrite)
    state.files.append(str(path))


def _demo_plot(state: DemoState) -> None:
    path = state.out / "tool_point_frf.png"
    save_plot(state.frf, path, f"{state.assembly.name}: tool point FRF", state.overwrite)
    state.files.append(str(path))


def _demo_assembly_file(state: DemoState) -> None:
    """The built-in assembly file, to start from; a copy the user has edited is never replaced.

    ``default_assembly.toml`` is written when it is absent, or present and
    equal to the built-in file.  A copy that differs (the user's machine,
    edited as the README invites) is kept even with ``--overwrite``: the
    built-in file goes beside it as ``default_assembly.new.toml``, and the
    summary says so.
    """
    import importlib.resources

    from ..errors import SubstructureError
    from ..io import read_text, write_text

    path = state.out / "default_assembly.toml"
    text = (importlib.resources.files("substructure") / "data" / "default_assembly.toml").read_text("utf-8")
    if path.exists():
        try:
            edited = read_text(path, "assembly file").replace("\r\n", "\n") != text.replace("\r\n", "\n")
        except SubstructureError:  # not a readable text file: not the demo's, in any case
            edited = True
        if edited:
            path = state.out / "default_assembly.new.toml"
            state.lines.append(f"{state.out / 'default_assembly.toml'} differs from the built-in assembly file (your "
                               f"edits?): kept; the built-in file is written to {path}")
            state.results["kept"] = [str(state.out / "default_assembly.toml")]
    write_text(path, text, state.overwrite)  # the packaged file, with its comments
    state.files.append(str(path))


def _demo_tap_test(state: DemoState) -> None:
    """A tap test of the built-in assembly with something the model does not know about."""
    from ..joints import Sensor
    from ..measurements import MeasurementSet
    from ..synthetic import simulate, write_measurement_set

    rig = state.assembly.attach(Sensor("forgotten-accelerometer", "tool.tip", "2 g"))
    taps = simulate(rig, ["tool.tip"], frequency=state.assembly.frequency, noise=0.015, seed=2026,
                    sensors=["forgotten-accelerometer"], name="demo tap test (1.5 % noise)")
    # the measurement file does not mention the sensor: the test report forgot it
    taps = MeasurementSet(taps.name, tuple(attrs.evolve(m, sensors=()) for m in taps))
    state.results["measurements"] = str(write_measurement_set(taps, state.out / "tap_test",
                                                              overwrite=state.overwrite))
    state.lines.append("a simulated tap test of the tool point, 1.5 % noise, with a 2 g accelerometer "
                       "that the test report forgot to mention")
    state.files.append(state.results["measurements"])
    state.taps = taps


def _demo_diagnose(state: DemoState) -> None:
    """Model against tap test: where it fails, what is missing, the error falling."""
    figures()
    from ..diagnose import diagnose
    from ..io.assembly_toml import save_assembly

    result = diagnose(state.assembly, state.taps)
    state.results["diagnosis"] = result.to_json()
    verdict = ("explained: the final error is at the noise floor" if result.explained else
               "not explained: " + (result.report[0] if result.report else "the residual is not noise"))
    state.lines.append(f"diagnosis: error {result.baseline_error:.3f} against a noise floor of "
                       f"{result.noise_floor:.3f}; missing effect: {result.missing_effect} at "
                       f"{result.missing_where} ({verdict})")
    for step in result.refinement:
        what = "model as given" if step.added is None else f"+ {step.added.name} at {step.added.where}"
        state.lines.append(f"  step {step.step}: {what:45s} error {step.error:.4f}")
    for name, make in (("where_it_fails.png", result.plot_where), ("error_fall.png", result.plot_history)):
        save_figure(make(), state.out / name, state.overwrite)
        state.files.append(str(state.out / name))
    path = state.out / "improved_assembly.toml"
    save_assembly(result.refined_assembly, path, overwrite=state.overwrite)
    state.files.append(str(path))


DEMO_STEPS: list[tuple[str, Callable[[DemoState], None]]] = [
    ("load the built-in assembly", _demo_load),
    ("compute the tool point FRF", _demo_frf),
    ("plot the tool point FRF", _demo_plot),
    ("write the assembly file to start from", _demo_assembly_file),
    ("simulate a tap test with a hidden effect", _demo_tap_test),
    ("diagnose the model against the tap test", _demo_diagnose),
]
"""The demo's steps, in order: ``(title, function(state))``; append to add steps."""


def _check_out(out: Path, overwrite: bool) -> None:
    """Refuse, before any work, an ``--out`` that is a file or holds what the demo would replace."""
    from ..errors import FileFormatError, OutputExistsError

    if out.exists() and not out.is_dir():
        raise FileFormatError(f"--out {out}: is a file; expected a directory (created if missing)")
    if overwrite:
        return
    there = [name for name in DEMO_FILES
             if (out / name).exists() and not ((out / name).is_dir() and not any((out / name).iterdir()))]
    if there:
        raise OutputExistsError(
            f"--out {out}: holds {', '.join(there)}, which the demo would replace; add --overwrite to replace "
            "them, or choose another directory"
        )


def run(args: argparse.Namespace) -> int:
    state = DemoState(out=Path(args.out), overwrite=args.overwrite)
    _check_out(state.out, args.overwrite)
    state.out.mkdir(parents=True, exist_ok=True)
    for _title, step in DEMO_STEPS:
        step(state)
    if args.json:
        return print_json({**state.results, "files": state.files})
    print("\n".join(state.lines))
    for path in state.files:
        print(f"wrote {path}")
    return 0


def add_parser(commands) -> None:
    """Add the ``demo`` subcommand to the subparsers ``commands``."""
    demo = commands.add_parser("demo", help="the workflow on the built-in assembly, with plots")
    demo.add_argument("--out", default="out/demo", metavar="DIR", help="output directory (default out/demo)")
    demo.add_argument("--overwrite", action="store_true",
                      help="replace the demo's files in --out (from an earlier run); other files are never touched")
    demo.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    demo.set_defaults(run=run)
