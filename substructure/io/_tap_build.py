"""What the tap record readers share: the quantity of a unit, the sample rate option, rounded times, the record.

Private to :mod:`substructure.io.tap_files` and its helper modules.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import FileFormatError, SubstructureError
from ..frf.axis import ROUNDED_STEP_SHARE, rounded_uniform
from ..tap.records import RESPONSE_QUANTITIES, TIME_STEP_TOLERANCE, TapRecord, channel_to_si, quantity_of, unit_of
from ._tap_columns import Columns

RESPONSES = ("acceleration", "velocity", "displacement")

MAX_RECORD_BYTES = 2**29
"""The largest tap record file read (512 MiB: minutes of three channels at 51.2 kHz written as text; the
reading needs about four times the file's size in memory, so a larger file is refused rather than let run
the machine out of memory)."""


def check_quantity_option(quantity: str | None, found: str, where: str) -> None:
    if quantity is None:
        return
    if quantity not in RESPONSE_QUANTITIES:
        raise FileFormatError(f"quantity: got {quantity!r}; expected one of {', '.join(RESPONSE_QUANTITIES)}")
    if quantity != found:
        raise FileFormatError(f"{where} holds {'an' if found[0] in 'aeiou' else 'a'} {found}, and the quantity "
                              f"option says {quantity}; leave the option out or fix the file")


ROUNDED_TIME_TOLERANCE = ROUNDED_STEP_SHARE
"""Largest distance, in time steps, of a written time from the uniform grid fitted to them all
(times written with few digits, e.g. six decimals at 51.2 kHz); farther (a lost or repeated sample) is refused."""


_EVEN = 1e-6
"""The most a fitted time grid's steps may differ, as a share of its step, before it is taken from the first sample."""


def regular(time_s: np.ndarray) -> np.ndarray:
    """The uniform grid fitted to the times when every time lies within a quarter step of it
    (``substructure.frf.axis.rounded_uniform``); counted from the first sample when float64 cannot hold the
    grid's steps evenly so far from its origin (time stamps).

    Times rounded to the digits a file writes (0.000020 for 1.953125e-05 s)
    make uneven steps of a uniform clock; the grid is what was sampled.  A
    time farther from the grid is left as written, for the record's own
    check to refuse.
    """
    grid = rounded_uniform(time_s)
    if grid is not None and float(np.ptp(np.diff(grid))) > _EVEN * (grid[-1] - grid[0]) / time_s.size:
        # a clock far from its origin (time stamps such as 1.7e9 s): float64 holds its times to steps of 1e-7 s
        # or more, so that even the fitted grid steps unevenly; the grid from the record's first sample does not
        relative = rounded_uniform(time_s - time_s[0])
        return time_s if relative is None else relative
    return time_s if grid is None else grid


def time_axis(time: tuple | None, stated: tuple | None, n: int, name: str) -> np.ndarray:
    """Sample times [s] from ``time = (values, unit, what)``, a time column or vector (rounded times made
    :func:`regular`), checked against a stated ``(rate [Hz], what states it)``; without one, ``n`` samples at the
    stated rate."""
    if time is None:
        assert stated is not None
        return np.arange(n) / stated[0]
    values, unit, what = time
    time_s = regular(values * (1.0 * unit).m_as("s"))
    if stated is not None and time_s.size > 1 and time_s[-1] > time_s[0]:
        from_time = (time_s.size - 1) / (time_s[-1] - time_s[0])
        if abs(from_time - stated[0]) > TIME_STEP_TOLERANCE * stated[0]:
            raise FileFormatError(f"{name}: {what} is sampled at {from_time:.10g} Hz, {stated[1]} says "
                                  f"{stated[0]:.10g} Hz; leave the option out or fix the file")
    return time_s


def units_of_columns(columns: Columns, name: str) -> tuple[list[Any], list[str | None], list[str | None]]:
    """Each column's pint unit, its quantity and the message of a unit pint cannot read (None when read)."""
    parsed: list[Any] = []
    dims: list[str | None] = []
    errors: list[str | None] = []
    for label, unit in zip(columns.labels, columns.units):
        u, error = None, None
        if unit is not None:
            try:
                u = unit_of(unit, label)
            except SubstructureError as exc:
                message = str(exc)
                error = message[message.find("cannot read"):]
        parsed.append(u)
        dims.append(None if u is None else quantity_of(u))
        errors.append(error)
    return parsed, dims, errors


def option_rate(sample_rate: Any) -> float:
    """The ``sample_rate`` option in Hz: a quantity or text with its unit (``"51.2 kHz"``), or a number in Hz."""
    from ..errors import InvalidValueError
    from ..units import frequency_hz

    if isinstance(sample_rate, (int, float, np.integer, np.floating)) and not isinstance(sample_rate, bool):
        hz = float(sample_rate)
    else:
        hz = frequency_hz(sample_rate, "sample rate (--sample-rate)")
    if not np.isfinite(hz) or hz <= 0:
        raise InvalidValueError(f"sample rate (--sample-rate): got {sample_rate!r}; expected a positive rate, "
                                "e.g. '51.2 kHz'")
    return hz


def build_record(name: str, time_s: np.ndarray, force_values: np.ndarray, force_unit: Any, force_label: str,
            response_values: np.ndarray, response_unit: Any, response_label: str, sensitivity: Any,
            hammer_sensitivity: Any, quantity: str | None) -> TapRecord:
    """The record in SI units from two channels in their units; unit errors name the file and the column."""
    try:
        force, _ = channel_to_si(force_values, force_unit, f"{name}: column {force_label!r}", ("force",),
                                 hammer_sensitivity, "hammer sensitivity (--hammer-sensitivity)")
        response, found = channel_to_si(response_values, response_unit, f"{name}: column {response_label!r}",
                                        RESPONSES, sensitivity, "sensitivity (--sensitivity)")
        check_quantity_option(quantity, found, f"{name}: column {response_label!r}")
        return TapRecord(time_s, force, response, found, name, force_label, response_label)
    except FileFormatError:
        raise
    except SubstructureError as exc:
        message = str(exc)
        raise FileFormatError(message if message.startswith(name) else f"{name}: {message}") from None
