"""What the subcommands share: the parser that raises, option types, strict JSON, figures and output files.

Imported by the parser of every command: it loads only light modules itself;
the library's numerical and unit modules (and numpy) are imported inside the
functions that need them, so that a command pays for what it uses.
"""

from __future__ import annotations

import argparse
import math
import os
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable

from .._json import json_text, strict  # noqa: F401 (strict: read from here as before)
from .._text import plain_text
from ..errors import SubstructureError

if TYPE_CHECKING:
    from ..frf import FRF, Frequency

PROG = "substructure"

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 1, 2, 70, 130
"""Exit statuses: success, an error in the input, misuse of the command line, an internal error (a bug,
``EX_SOFTWARE`` of sysexits.h), interrupted."""

IMAGE_SUFFIXES = (".png", ".pdf", ".svg", ".svgz", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff", ".webp")
"""Image files ``--plot`` writes (formats matplotlib saves without extra software)."""


MAX_REPEATS = 10_000
"""The most bootstrap refits (``identify --bootstrap``) or samples (``predict --samples``) a command runs: the
limit of :data:`substructure.units.MAX_REPEATS`, here again so that the command line starts without pint (a test
keeps the two equal)."""


def count_arg(option: str, value: int, minimum: int = 0) -> int:
    """A count of repetitions, ``minimum`` to :data:`MAX_REPEATS`, checked before any work."""
    if not minimum <= value <= MAX_REPEATS:
        raise UsageError(f"argument {option}: got {value}; expected {minimum} to {MAX_REPEATS} "
                         "(each one is a full computation)")
    return value


class UsageError(Exception):
    """Misuse of the command line (exit status 2)."""


class Parser(argparse.ArgumentParser):
    """An argument parser that raises instead of printing usage and exiting.

    An argument that starts with a minus and a digit (``--band -5:10``,
    ``--grid "-20 Hz:..."``) is a value, not an option, so that its own
    check can say what is wrong with it (no option of the command starts
    with a digit).
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str):
        raise UsageError(message)


def positive_arg(option: str, value: float | None, zero: bool = False) -> float | None:
    """A number option's value when it is finite and > 0 (>= 0 with ``zero``), None when not given; else an error."""
    if value is not None and not (math.isfinite(value) and (value > 0 or (zero and value == 0))):
        raise UsageError(f"argument {option}: got {value!r}; expected a finite number {'>= 0' if zero else '> 0'}")
    return value


def calibration_arg(value: float | None) -> float | None:
    """``--calibration``: the relative uncertainty of the FRFs' scale, in (0, 1), or None."""
    if value is not None and not (math.isfinite(value) and 0 < value < 1):
        raise UsageError(f"argument --calibration: got {value:g}; expected the relative uncertainty of "
                         "the FRFs' scale, a number between 0 and 1 (0.05 for 5 %)")
    return value


CALIBRATION_HELP = ("relative uncertainty of the FRFs' scale (the hammer's and the sensors' sensitivities), "
                    "e.g. 0.05: compare at the common level that fits best within it (default: exact)")


def one_line(text: str) -> str:
    """The text on one line, runs of white space made one space."""
    return " ".join(str(text).split())


def print_json(value: Any) -> int:
    """Print the one JSON object of ``--json`` (strict, :func:`json_text`) and return exit status 0."""
    print(json_text(value))
    return EXIT_OK


_LEADING_NUMBER = re.compile(r"^\s*[-+]?(\d|\.\d)")


def range_arg(text: str, unit: str, build: Callable, example: str, shown: str | None = None):
    """``START:STOP:STEP`` of quantities: plain numbers are in ``unit``, units may be written; ``shown`` is what
    the user typed, for messages (default ``text``)."""
    shown = text if shown is None else shown
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"got {shown!r}; expected START:STOP:STEP, e.g. {example}")
    values: list[Any] = []
    for name, part in zip(("START", "STOP", "STEP"), parts):
        if not _LEADING_NUMBER.match(part):
            raise argparse.ArgumentTypeError(
                f"got {shown!r}; {name} {part.strip()!r} is not a number; expected START:STOP:STEP, e.g. {example}"
            )
        try:
            values.append(f"{float(part)!r} {unit}")  # a plain number: in the option's unit
        except ValueError:
            values.append(part.strip())
    try:
        return build(*values)
    except SubstructureError as exc:
        raise argparse.ArgumentTypeError(f"{shown!r}: {one_line(str(exc))}") from None


def grid_arg(text: str) -> Frequency:
    """``START:STOP:STEP`` in Hz, or with units (``"20 Hz:5 kHz:2 Hz"``)."""
    from ..frf import Frequency

    return range_arg(text, "Hz", Frequency.from_range, "20:5000:2 (Hz) or '20 Hz:5 kHz:2 Hz'")


def point_arg(text: str) -> str:
    """A point name with its DOF, ``y`` when none is given."""
    import attrs

    from ..points import parse_point

    ref = parse_point(text)
    return str(attrs.evolve(ref, dof=ref.dof or "y"))


def assembly_point_arg(assembly, text: str, option: str) -> str:
    """A point of ``assembly`` given with ``option`` (``"--at"``), its DOF ``y`` when none is given.

    The point is checked to exist before any computation; an error names the
    option and what was given (``argument --at: point tool.tip-500 mm: lies
    outside 'tool', ...``).
    """
    from ..points import parse_point

    try:
        point = point_arg(text)
        assembly.node_key(parse_point(point).point)
    except SubstructureError as exc:
        raise type(exc)(f"argument {option}: {one_line(str(exc))}") from None
    return point


def peak_table(frf: FRF) -> list[tuple[float, float]]:
    """``(frequency in Hz, |FRF|)`` of the peaks of a one-entry FRF, ascending."""
    import numpy as np

    peaks = frf.peaks()
    magnitude = np.abs(frf.data[:, 0, 0])
    index = np.searchsorted(frf.frequency.hz, peaks)
    return [(float(f), float(magnitude[i])) for f, i in zip(peaks, index)]


def grid_text(frequency: Frequency) -> str:
    return f"{frequency.start:g} Hz to {frequency.stop:g} Hz, {frequency.n} lines"


def save_figure(fig, path, overwrite: bool = True) -> None:
    """Save a figure to an image file (atomically, :func:`substructure.io.replacing`) and close it."""
    import matplotlib.pyplot as plt

    from ..io import replacing

    try:
        suffix = Path(path).suffix.lower().lstrip(".") or "png"
        with replacing(path, overwrite) as temporary:
            fig.savefig(temporary, dpi=120, format=suffix)
    finally:
        plt.close(fig)


def figures() -> None:
    """Select matplotlib's file-only backend before any figure is made."""
    import matplotlib

    matplotlib.use("Agg")


def draw_to(path: str | os.PathLike, overwrite: bool, make: Callable[[], Any]) -> None:
    """Make a figure with ``make()`` on the file-only backend (:func:`figures`) and save it to ``path``."""
    figures()
    save_figure(make(), path, overwrite)


def save_plot(frf: FRF, path: str | os.PathLike, title: str, overwrite: bool = True) -> None:
    """Plot an FRF (magnitude and phase) with a title to an image file."""
    figures()
    fig = frf.plot()
    fig.suptitle(plain_text(title))
    save_figure(fig, path, overwrite)


def write_frf(frf: FRF, path: str, overwrite: bool = False) -> None:
    """Write an FRF to a CSV or UFF file, chosen by the suffix (atomically)."""
    from ..io.frf_files import write_csv, write_uff

    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        write_csv(frf, path, overwrite)
    elif suffix in (".uff", ".unv"):
        write_uff(frf, path, overwrite)
    else:  # checked before computing; kept for callers of this helper
        raise UsageError(f"argument --out: {path!r}: expected a .csv or .uff file")


def check_plot(path: str | None, option: str = "--plot") -> None:
    """Refuse, before any work, a figure file whose suffix is not an image format matplotlib writes."""
    if path is None:
        return
    suffix = Path(path).suffix.lower()
    if suffix not in IMAGE_SUFFIXES:
        got = f"the suffix {suffix!r}" if suffix else "no suffix"
        raise UsageError(f"argument {option}: {path!r} has {got}; expected an image file: "
                         + ", ".join(IMAGE_SUFFIXES))


def _resolved(path) -> Path:
    from ..io import file_name

    return Path(os.path.abspath(os.path.expanduser(file_name(path)))).resolve()


def check_outputs(outputs: Iterable[tuple[str, Any]], inputs: Iterable[Any], overwrite: bool) -> None:
    """Check, before any work, the files a command will write.

    Parameters
    ----------
    outputs : iterable of (str, path)
        The option that names each file (``"--out"``) and its path; ``None``
        paths are skipped.
    inputs : iterable of path
        Every file the command reads (``None`` skipped).
    overwrite : bool
        Whether ``--overwrite`` was given.

    Raises
    ------
    UsageError
        When an output is one of the inputs (compared as resolved paths:
        links and ``..`` do not hide it; even with ``--overwrite``), or two
        outputs are the same file.
    FileExistsError
        When an output exists and ``overwrite`` is false.
    substructure.errors.FileFormatError
        When an output is a directory or its directory does not exist.
    """
    from ..io import check_writable

    read = {_resolved(path): os.fspath(path) for path in inputs if path is not None}
    seen: dict[Path, str] = {}
    for option, path in outputs:
        if path is None:
            continue
        where = _resolved(path)
        if where in read:
            raise UsageError(f"argument {option}: {os.fspath(path)} is the input {read[where]}; an output is "
                             "never written onto an input, choose another file")
        if where in seen:
            raise UsageError(f"argument {option}: {os.fspath(path)} is also the file of {seen[where]}")
        seen[where] = option
        check_writable(path, overwrite, option)


def band_arg(text: str, auto: bool = True):
    """``auto`` (unless ``auto`` is False) or ``LO:HI``: plain numbers in Hz, or frequencies with units (rad/s,
    rpm converted)."""
    from ..units import frequency_hz

    if auto and text.strip() == "auto":
        return "auto"
    parts = text.split(":")
    if len(parts) != 2 or not all(_LEADING_NUMBER.match(p) for p in parts):
        raise argparse.ArgumentTypeError(f"got {text!r}; expected {'auto or ' if auto else ''}LO:HI in Hz, "
                                         "e.g. 1200:1700")
    values = []
    for part in parts:
        try:
            values.append(float(part))
        except ValueError:
            try:
                values.append(frequency_hz(part.strip(), "band"))
            except SubstructureError as exc:
                raise argparse.ArgumentTypeError(f"got {text!r}: {one_line(str(exc))}") from None
    lo, hi = values
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise argparse.ArgumentTypeError(f"got {text!r}; expected finite frequencies")
    if lo < 0:
        raise argparse.ArgumentTypeError(f"got {text!r}; LO is {lo:g} Hz, expected frequencies >= 0 Hz")
    if not lo < hi:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected LO < HI")
    return (lo, hi)


def band_range_arg(text: str):
    """``LO:HI`` as :func:`band_arg`, without ``auto``."""
    return band_arg(text, auto=False)


def measurement_inputs(path) -> list:
    """A measurement file and the data files it names (for :func:`check_outputs`), as far as they can be read.

    A file that cannot be read yields itself only: loading it reports the
    problem properly.
    """
    from .._toml import read_toml

    files: list = [path]
    try:
        for table in read_toml(path, "measurement set file").data.get("frf", []):
            if isinstance(table, dict) and isinstance(table.get("file"), str):
                files.append(Path(path).parent / table["file"])
    except (SubstructureError, AttributeError):
        pass
    return files
