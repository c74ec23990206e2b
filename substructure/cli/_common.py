"""What the subcommands share: the parser that raises, option types, figures and output files."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any, Callable

import attrs
import numpy as np

from ..errors import SubstructureError
from ..frf import FRF, Frequency
from ..points import parse_point
from ..units import Q_

PROG = "substructure"


class UsageError(Exception):
    """Misuse of the command line (exit status 2)."""


class Parser(argparse.ArgumentParser):
    """An argument parser that raises instead of printing usage and exiting."""

    def error(self, message: str):
        raise UsageError(message)


def one_line(text: str) -> str:
    return " ".join(str(text).split())


def range_arg(text: str, unit: str, build: Callable, example: str):
    """``START:STOP:STEP`` of quantities: plain numbers are in ``unit``, units may be written."""
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected START:STOP:STEP, e.g. {example}")
    values: list[Any] = []
    for part in parts:
        try:
            values.append(Q_(float(part), unit))
        except ValueError:
            values.append(part.strip())
    try:
        return build(*values)
    except SubstructureError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {one_line(str(exc))}") from None


def grid_arg(text: str) -> Frequency:
    """``START:STOP:STEP`` in Hz, or with units (``"20 Hz:5 kHz:2 Hz"``)."""
    return range_arg(text, "Hz", Frequency.from_range, "20:5000:2 (Hz) or '20 Hz:5 kHz:2 Hz'")


def point_arg(text: str) -> str:
    """A point name with its DOF, ``y`` when none is given."""
    ref = parse_point(text)
    return str(attrs.evolve(ref, dof=ref.dof or "y"))


def peak_table(frf: FRF) -> list[tuple[float, float]]:
    """``(frequency in Hz, |FRF|)`` of the peaks of a one-entry FRF, ascending."""
    peaks = frf.peaks()
    magnitude = np.abs(frf.data[:, 0, 0])
    index = np.searchsorted(frf.frequency.hz, peaks)
    return [(float(f), float(magnitude[i])) for f, i in zip(peaks, index)]


def grid_text(frequency: Frequency) -> str:
    return f"{frequency.start:g} Hz to {frequency.stop:g} Hz, {frequency.n} lines"


def save_figure(fig, path) -> None:
    """Save a figure to an image file and close it (Agg: files only, no display needed)."""
    import matplotlib.pyplot as plt

    try:
        fig.savefig(path, dpi=120)
    finally:
        plt.close(fig)


def figures() -> None:
    """Select matplotlib's file-only backend before any figure is made."""
    import matplotlib

    matplotlib.use("Agg")


def save_plot(frf: FRF, path: str | os.PathLike, title: str) -> None:
    figures()
    fig = frf.plot()
    fig.suptitle(title)
    save_figure(fig, path)


def write_frf(frf: FRF, path: str) -> None:
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        frf.to_csv(path)
    elif suffix in (".uff", ".unv"):
        frf.to_uff(path)
    else:  # checked before computing; kept for callers of this helper
        raise UsageError(f"argument --out: {path!r}: expected a .csv or .uff file")


# -- frf ------------------------------------------------------------------------------


def band_arg(text: str):
    if text == "auto":
        return "auto"
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected auto or LO:HI in Hz, e.g. 1200:1700") from None
    if not lo < hi:
        raise argparse.ArgumentTypeError(f"got {text!r}; expected LO < HI")
    return (lo, hi)


def band_range_arg(text: str):
    band = band_arg(text)
    if band == "auto":
        raise argparse.ArgumentTypeError("expected LO:HI in Hz, e.g. 200:3000")
    return band
