"""What a type-58 record holds: its DOF labels, its quantity, its units and its abscissa in Hz.

The quantity and the SI factor of a record come from its labels, specific
data types, unit exponents and axis unit labels, and from the units record
(type 164) of the file; whatever disagrees is an error that names the
record, never a guess.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ...errors import FileFormatError
from .._fields import QUANTITIES
from ._common import _DIRECTION_NAME


def _label(dset: dict, id_key: str, prefix: str, node_key: str, dir_key: str) -> str:
    text = str(dset.get(id_key, "")).strip()
    if text.startswith(prefix) and len(text) > len(prefix):
        return text[len(prefix):]
    direction = abs(int(dset.get(dir_key, 0)))  # -Y is read as +Y, the sign goes to the data (_parse_record)
    dof = _DIRECTION_NAME.get(direction, f"dir{direction}")
    return f"node{int(dset.get(node_key, 0))}:{dof}"


# Function types (record 6, field 1) and specific data types (records 8-10, field 1) of UFF 58.
_FUNCTION_TYPES = {
    0: "general or unknown function", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
    4: "frequency response function", 5: "transmissibility", 6: "coherence", 7: "auto correlation",
    8: "cross correlation", 9: "power spectral density", 10: "energy spectral density",
    11: "probability density function", 12: "spectrum", 13: "cumulative frequency distribution",
    14: "peaks valley", 15: "stress/cycles", 16: "strain/cycles", 17: "orbit", 18: "mode indicator function",
    19: "force pattern", 20: "partial power", 21: "partial coherence", 22: "eigenvalue", 23: "eigenvector",
    24: "shock response spectrum", 25: "finite impulse response filter", 26: "multiple coherence",
    27: "order function",
}
_DATA_TYPES = {
    0: "unknown", 1: "general", 2: "stress", 3: "strain", 5: "temperature", 6: "heat flux", 8: "displacement",
    9: "reaction force", 11: "velocity", 12: "acceleration", 13: "excitation force", 15: "pressure", 16: "mass",
    17: "time", 18: "frequency", 19: "rpm", 20: "order",
}
_TIME_EXPONENT = {0: "receptance", -1: "mobility", -2: "accelerance"}  # of an FRF unit m^a N^-1 s^t
_NO_LABEL = ("", "NONE", "N/A", "NA", "-")


def _a(word: str) -> str:
    """``word`` with its indefinite article."""
    return f"{'an' if word[:1].lower() in 'aeiou' else 'a'} {word}"


_UNREADABLE = re.compile(r"[\ufffd\x00-\x1f\x7f-\x9f]")
_DECIBEL = re.compile(r"(?i)\bdb|decibel|neper")


class DecibelLabel(ValueError):
    """A unit label in decibels (``dB``, ``dB g/N``): a logarithm of a ratio whose reference the file does not
    give, never read as linear values."""


def _unit_of_label(label: Any):
    """A pint Quantity of 1 of the unit an axis units label names; None for no label; ValueError if unreadable.

    Labels of acquisition systems are read by
    :func:`substructure.units.instrument_unit` (``g`` is the standard
    acceleration of gravity, ``s2`` and ``s\u00b2`` are ``s^2``; ``\u00b2`` and
    ``\u00b3`` may come as Latin-1 bytes in a label pyuff could not decode:
    ``_latin1_labels``).  A label with a byte that is no character (U+FFFD)
    or a control character is unreadable.
    """
    from ...units import instrument_unit, ureg

    text = str(label if label is not None else "").strip()
    if text.upper() in _NO_LABEL:
        return None
    if _UNREADABLE.search(text):  # a byte that is no character (U+FFFD), a control character
        raise ValueError(text)
    if _DECIBEL.search(text):
        raise DecibelLabel(text)
    try:
        q = ureg.Quantity(1.0, instrument_unit(text))
        q.dimensionality  # noqa: B018 - pint fails here on a logarithmic unit in a product
        linear = q._is_multiplicative  # offset units (degC) are not a scale
    except Exception:  # pint raises its own errors, AttributeError among them
        raise ValueError(text) from None
    if not linear:
        raise ValueError(text)
    return q


def _exponents(q) -> tuple[int, int, int] | None:
    """``(force, length, time)`` exponents of a unit made of mass, length and time; None otherwise."""
    dims = dict(q.dimensionality)
    if set(dims) - {"[mass]", "[length]", "[time]"}:
        return None
    m, n, t = (dims.get(k, 0) for k in ("[mass]", "[length]", "[time]"))
    if any(float(x) != int(x) for x in (m, n, t)):
        return None
    m, n, t = int(m), int(n), int(t)
    return m, n - m, t + 2 * m  # M^m L^n T^t = F^m L^(n-m) T^(t+2m)


def frf_quantity(unit, lengths: tuple[int, ...] = (1, 0, -1)) -> tuple[str, float] | None:
    """``(quantity, factor to SI)`` of an FRF's unit (a pint Quantity of 1, as :func:`_unit_of_label` gives):
    a response per force whose length exponent is one of ``lengths`` (1: ``m/N``; 0: ``1/N``, a rotation per
    force or a displacement per moment; -1: ``1/(N m)``), its time exponent saying the quantity
    (:data:`_TIME_EXPONENT`); None for another unit or None."""
    exps = _exponents(unit) if unit is not None else None
    if exps is None or exps[0] != -1 or exps[1] not in lengths or exps[2] not in _TIME_EXPONENT:
        return None
    return _TIME_EXPONENT[exps[2]], float(unit.m_as(f"meter ** {exps[1]} / newton * second ** {exps[2]}"))


class DecibelRecord(FileFormatError):
    """A record whose ordinate is labelled in decibels: refused even when the quantity is given."""


def _frf_unit(dset: dict, where: str):
    """The FRF unit its labels give (a pint Quantity of 1 per force), None without labels.

    Raises FileFormatError for a label that cannot be read or is not a
    response per force.
    """
    from ...units import ureg

    labels = {}
    for key in ("ordinate_axis_units_lab", "orddenom_axis_units_lab"):
        try:
            labels[key] = _unit_of_label(dset.get(key))
        except DecibelLabel as exc:
            raise DecibelRecord(
                f"{where}: the unit label {str(exc)!r} ({key.split('_')[0]}) is in decibels, a logarithm whose "
                "reference the file does not give; export the FRF as real and imaginary parts (or magnitude and "
                "phase) in linear units such as m/N or g/N"
            ) from None
        except ValueError as exc:
            raise FileFormatError(
                f"{where}: cannot read the unit label {str(exc)!r} ({key.split('_')[0]}); give the quantity "
                "(receptance, mobility or accelerance, in SI units) to read it as such"
            ) from None
    num, den = labels["ordinate_axis_units_lab"], labels["orddenom_axis_units_lab"]
    if num is None:
        return None
    exps = _exponents(num)
    if exps is not None and exps[0] == -1:  # the whole FRF unit, e.g. (1/N)*(m/s^2)
        return num
    if exps is not None and exps[0] == 0:  # the response alone: the force is the denominator's
        force = ureg.Quantity(1.0, "N") if den is None else den
        fexps = _exponents(force)
        if fexps is not None and fexps[0] == 1 and fexps[2] == 0:
            return num / force
        raise FileFormatError(
            f"{where}: the ordinate denominator's unit {dset.get('orddenom_axis_units_lab')!r} is not a force "
            "or a moment; an FRF here is a response per excitation force"
        )
    raise FileFormatError(
        f"{where}: the unit label {dset.get('ordinate_axis_units_lab')!r} is not a displacement, velocity or "
        "acceleration (per force); this record is not a receptance, mobility or accelerance"
    )


def _record_quantity(dset: dict, where: str, given: str | None, system: tuple[float, float] | None):
    """The quantity of a type-58 record and the factor to SI, from its data types, unit labels and exponents.

    Returns ``(quantity, factor)``; raises FileFormatError when the
    record contradicts itself or does not say what it holds.
    """
    rotation = abs(int(dset.get("rsp_dir", 0) or 0)) in (4, 5, 6)
    moment = abs(int(dset.get("ref_dir", 0) or 0)) in (4, 5, 6)
    length_exponent = (0 if rotation else 1) - (1 if moment else 0)  # y/f: m/N, y/m and theta/f: 1/N, ...
    num_type = int(dset.get("ordinate_spec_data_type", 0) or 0)
    den_type = int(dset.get("orddenom_spec_data_type", 0) or 0)
    if den_type not in (0, 1, 9, 13):
        raise FileFormatError(
            f"{where}: the ordinate denominator is {_a(_DATA_TYPES.get(den_type, f'data type {den_type}'))}; a "
            "receptance, mobility or accelerance is a response per excitation force"
        )
    by_type = {8: "receptance", 11: "mobility", 12: "accelerance"}.get(num_type)
    if by_type is None and num_type not in (0, 1):
        raise FileFormatError(
            f"{where}: the ordinate is {_a(_DATA_TYPES.get(num_type, f'data type {num_type}'))}, not a "
            "displacement, velocity or acceleration: not a receptance, mobility or accelerance"
        )
    stored = str(dset.get("id3", "")).strip()
    ours = stored[len("quantity="):] if stored.startswith("quantity=") else None
    ours = ours if ours in QUANTITIES else None
    try:
        unit = _frf_unit(dset, where)
    except FileFormatError as exc:
        if given is None or isinstance(exc, DecibelRecord):  # values in dB are never read as linear ones
            raise
        unit = None  # the user says what it is: the unreadable label is left aside
    by_label, label_factor = None, None
    label = dset.get("ordinate_axis_units_lab")
    if unit is not None:
        exps = _exponents(unit)
        assert exps is not None  # _frf_unit gives units of force, length and time only
        force, length, time = exps
        by_label = _TIME_EXPONENT.get(time)
        if by_label is None or (int(dset.get("rsp_dir", 0) or 0) and length != length_exponent):
            raise FileFormatError(
                f"{where}: the unit label {label!r} is not that of a receptance, mobility or accelerance of "
                f"this record's directions (response {dset.get('rsp_dir')}, reference {dset.get('ref_dir')})"
            )
        label_factor = float(unit.m_as(f"meter ** {length} / newton * second ** {time}"))
    if given is None:
        if by_label is not None and by_type is not None and by_label != by_type:
            raise FileFormatError(
                f"{where}: its data type says {by_type} ({_DATA_TYPES[num_type]}) but its unit label {label!r} "
                f"is that of {_a(by_label)}; give the quantity to say which"
            )
        quantity = by_label or by_type or ours
        if quantity is None:
            raise FileFormatError(
                f"{where}: the record does not say whether it holds a receptance, a mobility or an accelerance "
                f"(ordinate data type {_DATA_TYPES.get(num_type, num_type)}, no unit label); give the quantity "
                "(quantity = \"...\" in the measurement set, or read_uff(..., quantity=...)); values are then "
                "taken in SI units"
            )
        if by_label is not None:
            return quantity, label_factor
    elif by_label == given:
        return given, label_factor
    elif not (by_type == given or (by_label is None and by_type is None)):
        says = f"its unit label {label!r} is that of {_a(by_label)}" if by_label is not None else \
            f"its data type says {by_type} ({_DATA_TYPES[num_type]})"
        raise FileFormatError(f"{where}: the quantity given is {given}, but {says}")
    else:
        quantity = given
    if system is None:
        return quantity, 1.0
    # no labels: the file's unit system (a type-164 record) with the exponents of the data types
    # (UFF 58, Addendum A), or those the record gives for the data type "general"
    length_factor, force_factor = system
    if num_type == 1:
        num_length, num_force = int(dset.get("ordinate_len_unit_exp", 0)), int(dset.get("ordinate_force_unit_exp", 0))
    else:
        num_length, num_force = (0 if rotation else 1), 0
    if den_type == 1:
        den_length, den_force = int(dset.get("orddenom_len_unit_exp", 0)), int(dset.get("orddenom_force_unit_exp", 0))
    else:
        den_length, den_force = (1 if moment else 0), 1
    factor = length_factor ** -(num_length - den_length) * force_factor ** -(num_force - den_force)
    return quantity, factor


def _unit_system(dset: dict, name: str) -> tuple[float, float] | None:
    """``(length, force)`` factors of a type-164 record (file units per SI unit); None for SI."""
    try:
        length, force = float(dset["length"]), float(dset["force"])
    except (KeyError, TypeError, ValueError):
        raise FileFormatError(f"{name}: a units record (type 164) without length and force factors") from None
    if not (np.isfinite(length) and np.isfinite(force) and length > 0 and force > 0):
        raise FileFormatError(f"{name}: the units record (type 164) has factors {length}, {force}; expected > 0")
    return None if length == 1.0 and force == 1.0 else (length, force)


def _frequency_unit(label: str):
    """:func:`_unit_of_label` of a frequency axis's label, also in capitals (``HZ``, ``KHZ``, ``RPM``, ``RAD/S``:
    read in lower case; ``MHZ``, mHz or MHz, is unreadable)."""
    try:
        return _unit_of_label(label)
    except ValueError:
        return _unit_of_label({"hz": "Hz", "khz": "kHz"}.get(label.lower(), label.lower()))


def _abscissa_hz(dset: dict, where: str) -> np.ndarray:
    """The abscissa in Hz: a frequency axis (a label in rad/s is divided by 2 pi); time or orders refused."""
    from ...units import cycles_per_second

    kind = int(dset.get("abscissa_spec_data_type", 0) or 0)
    if kind not in (0, 1, 18):
        raise FileFormatError(
            f"{where}: the abscissa is {_DATA_TYPES.get(kind, f'data type {kind}')}, not frequency; an FRF "
            "is a function of frequency"
        )
    hz = np.asarray(dset["x"], dtype=np.float64)
    label = str(dset.get("abscissa_axis_units_lab") or "").strip()
    try:
        unit = _frequency_unit(label)
    except ValueError:
        raise FileFormatError(
            f"{where}: cannot read the abscissa's unit label {label!r}; expected a frequency unit "
            "(Hz, rad/s, rpm): convert the file, or export it with the frequency axis in Hz"
        ) from None
    if unit is not None and unit.check("1 / [time]"):
        hz = np.asarray(cycles_per_second(hz * unit, "abscissa"), dtype=np.float64)
    elif unit is not None:  # a length, a time; or a ratio, an angle, a percentage: never taken as Hz
        raise FileFormatError(
            f"{where}: the abscissa's unit is {dset.get('abscissa_axis_units_lab')!r}, not a frequency (Hz, kHz, "
            "rad/s, rpm)"
        )
    return hz

