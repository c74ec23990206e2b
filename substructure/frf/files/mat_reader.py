"""Measured FRFs in MATLAB files: the signal structures of Simcenter Testlab exports (``substructure._matlab``).

An FRF is a signal structure of complex values on a frequency axis
(``x_values`` in Hz, or another unit of frequency its label names), its
unit in ``y_values.quantity.label`` (``g/N``, ``m/N``, ``(m/s)/N``) after
the unit transformation (``factor``, ``offset``) is applied, which says
whether it is a receptance, a mobility or an accelerance.  A coherence is
a real signal on the same kind of axis with values in [0, 1] (no unit, or
``%``).  The file's frequency channels (a struct per channel, or a group of
them) are numbered from 0 in the file's order: ``record`` chooses one, as
for the type-58 records of a universal file.
"""

from __future__ import annotations

import os

import numpy as np

from ..._matlab import Signal, flatten, load
from ...errors import FileFormatError, InvalidValueError
from .._fields import QUANTITIES
from ..axis import Frequency
from ._common import coherence_checked, frf_class
from .uff_units import DecibelLabel, _a, _unit_of_label, frf_quantity

__all__ = ["read_mat", "read_mat_coherence", "frf_channels"]


def _channels(path: str | os.PathLike) -> tuple[str, list[tuple[str, Signal]]]:
    """The file's name and its channels on a frequency axis, in the file's order."""
    from ..._files import MAX_DATA_BYTES, file_name, read_bytes

    name = file_name(path, "MATLAB file")
    data = read_bytes(path, "MATLAB file", MAX_DATA_BYTES)
    _, signals, skipped = flatten(load(data, name), name)
    found = [(key, s) for key, s in signals.items() if s.axis == "frequency"]
    if not found:
        times = [key for key, s in signals.items() if s.axis == "time"]
        held = (f"time records ({', '.join(times)}): make the FRF from them with `substructure tap`" if times else
                f"no signal structure{'; passed over: ' + '; '.join(skipped) if skipped else ''}")
        raise FileFormatError(f"{name}: no signal structure on a frequency axis (an FRF); the file holds {held}")
    return name, found


def _listing(found: list[tuple[str, Signal]]) -> str:
    return "; ".join(f"{k}: {key} ({'complex' if np.iscomplexobj(s.values) else 'real'}, {s.unit or 'no unit'})"
                     for k, (key, s) in enumerate(found))


def _chosen(name: str, found: list[tuple[str, Signal]], record, what: str) -> tuple[str, Signal, str]:
    if isinstance(record, bool) or not isinstance(record, (int, np.integer)) or not 0 <= record < len(found):
        has = f"{len(found)} channel(s) on a frequency axis, indices 0..{len(found) - 1} ({_listing(found)})"
        if what == "record":  # as read_uff says of a record index: the caller's argument, not the file, is wrong
            raise InvalidValueError(f"record: got {record!r}; {name} has {has}")
        raise FileFormatError(f"{name}: {what} {record!r}; the file has {has}")
    key, signal = found[int(record)]
    return key, signal, f"{name}, channel {int(record)} ({key})"


def _grid(signal: Signal, where: str) -> Frequency:
    hz = signal.start + signal.step * np.arange(signal.values.size)
    try:
        return Frequency.from_hz(hz)
    except InvalidValueError as exc:
        raise FileFormatError(f"{where}: invalid frequencies ({exc})") from None


def _quantity(signal: Signal, where: str, given: str | None) -> tuple[str, float]:
    """The quantity the channel's unit label says and the factor to SI; the given one without a label."""
    try:
        unit = _unit_of_label(signal.unit)
    except DecibelLabel:
        raise FileFormatError(f"{where}: the unit {signal.unit!r} is in decibels, a logarithm whose reference the "
                              "file does not give; export the FRF as complex values in linear units") from None
    except ValueError:
        raise FileFormatError(f"{where}: cannot read the unit {signal.unit!r}; expected a response per force such "
                              "as 'g/N', 'm/N' or '(m/s)/N'") from None
    if unit is None:
        if given is None:
            raise FileFormatError(f"{where}: no unit (y_values.quantity.label is empty); give the quantity "
                                  "(quantity = \"...\" in the measurement set); values are then taken in SI units")
        return given, 1.0
    found = frf_quantity(unit, lengths=(1, 0))
    if found is None:
        raise FileFormatError(f"{where}: the unit {signal.unit!r} is not a displacement, velocity or acceleration "
                              "per force: not a receptance, mobility or accelerance")
    if given is not None and given != found[0]:
        raise FileFormatError(f"{where}: the quantity given is {given}, but its unit {signal.unit!r} is that of "
                              f"{_a(found[0])}")
    return found


def frf_channels(path: str | os.PathLike) -> list[tuple[int, str]]:
    """``(record, name)`` of each FRF (a complex channel on a frequency axis) of a MATLAB file of signal
    structures; a FileFormatError for a file with no channel on a frequency axis."""
    _, found = _channels(path)
    return [(k, key) for k, (key, s) in enumerate(found) if np.iscomplexobj(s.values)]


def read_mat(path: str | os.PathLike, record: int | None = None, quantity: str | None = None,
             output: str = "response", input: str = "excitation"):
    """Read a measured FRF from a MATLAB file of signal structures (a Simcenter Testlab export), in SI units.

    Parameters
    ----------
    path : str or path-like
        The file (``.mat``, versions 4 to 7).
    record : int, optional
        0-based index of the FRF among the file's channels on a frequency
        axis; needed when it holds more than one complex channel.
    quantity : {"receptance", "mobility", "accelerance"}, optional
        For a channel without a unit label (its values then in SI); with
        a label, it must agree.
    output, input : str
        The FRF's labels.

    Returns
    -------
    FRF
        One entry, with the quantity its unit says.

    Raises
    ------
    FileFormatError
        Naming the file and the channel: no channel on a frequency axis,
        several FRFs and no ``record``, a channel of real values, a unit in
        dB or one that is no response per force, a quantity that contradicts
        the unit, frequencies that do not increase, values that are not
        finite or all 0.
    InvalidValueError
        For a quantity that is none of the three, or a ``record`` beyond
        the file's channels on a frequency axis (the message starts
        ``record:``).
    """
    if quantity is not None and quantity not in QUANTITIES:
        raise InvalidValueError(f"quantity: got {quantity!r}; expected one of {', '.join(QUANTITIES)}")
    name, found = _channels(path)
    if record is None:
        frfs = [k for k, (_, s) in enumerate(found) if np.iscomplexobj(s.values)]
        if len(frfs) != 1:
            raise FileFormatError(f"{name}: {len(frfs)} complex channels on a frequency axis ({_listing(found)}); "
                                  "give the 0-based index of the FRF (record = N in the measurement set)")
        record = frfs[0]
    _, signal, where = _chosen(name, found, record, "record")
    if not np.iscomplexobj(signal.values):
        raise FileFormatError(f"{where}: real values; an FRF needs complex values (real and imaginary parts)")
    values = signal.values
    if not np.isfinite(values).all():
        k = int(np.argmax(~np.isfinite(values)))
        raise FileFormatError(f"{where}: value {k + 1} is {values[k]}; expected finite values")
    if not np.any(values):
        raise FileFormatError(f"{where}: every value is 0, a dead channel; leave this FRF out or measure it again")
    frequency = _grid(signal, where)
    kind, factor = _quantity(signal, where, quantity)
    return frf_class().single(frequency, values * factor, output=output, input=input, quantity=kind)


def read_mat_coherence(path: str | os.PathLike, record: int) -> tuple[np.ndarray, np.ndarray]:
    """Read a coherence channel of a MATLAB file of signal structures, as analysers export it beside the FRF.

    Parameters
    ----------
    path : str or path-like
        The file.
    record : int
        0-based index of the coherence among the file's channels on a
        frequency axis (as for :func:`read_mat`).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Its frequencies [Hz] and its values in [0, 1].

    Raises
    ------
    FileFormatError
        Naming the channel: no such channel, complex values, a unit, or
        values outside [0, 1].
    """
    name, found = _channels(path)
    _, signal, where = _chosen(name, found, record, "coherence record")
    unit = (signal.unit or "").strip()
    if np.iscomplexobj(signal.values) or unit not in ("", "-", "1", "%"):
        raise FileFormatError(f"{where}: {'complex values' if np.iscomplexobj(signal.values) else repr(unit)}; "
                              "expected a coherence (real values in [0, 1], no unit)")
    values = coherence_checked(signal.values * (0.01 if unit == "%" else 1.0), where)
    return _grid(signal, where).hz, values
