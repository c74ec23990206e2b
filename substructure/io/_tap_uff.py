"""Tap records in universal files (type-58 time records): ``read_tap_uff`` and ``read_taps_uff``
(re-exported by :mod:`substructure.io.tap_files`).

The force is the record whose ordinate is an excitation force (specific data
type 13, or 9) or whose unit label is a force, the response the record of
displacement, velocity or acceleration (types 8, 11, 12) or whose unit label
says so; ``force_record`` and ``response_record`` choose them by index when a
file holds more.  A file cut short (no closing ``-1`` line, a record holding
fewer samples than its header announces) is refused as such.
"""

from __future__ import annotations

import contextlib
import io
import os
from typing import Any

import numpy as np

from ..errors import FileFormatError, SubstructureError
from ..tap.records import RESPONSE_QUANTITIES, TIME_STEP_TOLERANCE, TapRecord, channel_to_si, unit_of
from ..units import magnitude_in
from . import check_readable_file
from ._tap_build import MAX_RECORD_BYTES, RESPONSES, check_quantity_option, quantity_of, regular

__all__ = ["read_tap_uff", "read_taps_uff"]

_FORCE_TYPES = (9, 13)
_RESPONSE_TYPES = {8: "displacement", 11: "velocity", 12: "acceleration"}


def read_tap_uff(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                 quantity: str | None = None, force_record: int | None = None,
                 response_record: int | None = None) -> TapRecord:
    """Read a tap record from a universal file: two type-58 time records, the force and the response.

    Parameters
    ----------
    path : str or path-like
        The file.
    sensitivity, hammer_sensitivity : str or pint.Quantity, optional
        As for :func:`~substructure.io.tap_files.read_tap_csv`, for records whose unit label is a voltage.
    quantity : {"acceleration", "velocity", "displacement"}, optional
        What the response is; it must agree with the record (its specific
        data type and unit label).
    force_record, response_record : int, optional
        0-based indices of the two records among the file's type-58 records;
        default: found by their specific data types or unit labels.

    Returns
    -------
    TapRecord
        In SI units; ``force_column`` and ``response_column`` name the records.

    Raises
    ------
    FileFormatError
        Naming the file and the record: no or several candidates for a
        channel, a record that is not a time response, a unit that
        contradicts the specific data type or the options, different time
        axes.
    """
    name, records, kinds = _uff_records(path)
    pair = _uff_pair(name, records, kinds, force_record, response_record)
    return _uff_tap(name, records, kinds, pair, sensitivity, hammer_sensitivity, quantity)


def read_taps_uff(path: str | os.PathLike, sensitivity: Any = None, hammer_sensitivity: Any = None,
                  quantity: str | None = None) -> list[TapRecord]:
    """Read every tap of a universal file: its force records paired in order with its response records.

    A file of one tap reads as :func:`~substructure.io.tap_files.read_tap_uff` does.  A file of several
    taps holds as many force records as response records (a force and its
    response after each other, or all forces first): the k-th force record
    and the k-th response record are the k-th tap, and must share their
    time axis.

    Parameters
    ----------
    path, sensitivity, hammer_sensitivity, quantity
        As for :func:`~substructure.io.tap_files.read_tap_uff` (``quantity``: what the responses are).

    Returns
    -------
    list of TapRecord
        One a tap, in the file's order.

    Raises
    ------
    FileFormatError
        As :func:`~substructure.io.tap_files.read_tap_uff`; also for counts of force and response
        records that do not pair (then choose one tap with
        :func:`~substructure.io.tap_files.read_tap_uff`'s ``force_record`` and ``response_record``).
    """
    name, records, kinds = _uff_records(path)
    forces = [k for k, q in enumerate(kinds) if q == "force"]
    responses = [k for k, q in enumerate(kinds) if q in RESPONSES or q == "response"]
    if len(forces) < 2 or len(forces) != len(responses):
        return [_uff_tap(name, records, kinds, _uff_pair(name, records, kinds, None, None), sensitivity,
                         hammer_sensitivity, quantity)]
    return [_uff_tap(name, records, kinds, pair, sensitivity, hammer_sensitivity, quantity, tap=k + 1)
            for k, pair in enumerate(zip(forces, responses))]


def _uff_records(path) -> tuple[str, list[dict], list[str | None]]:
    """The file's name, its type-58 records (each checked a time record) and what each holds by its data type
    or unit label (``force``, a response quantity, ``response`` or None: not known)."""
    import pyuff

    from ..frf.files.uff_reader import check_complete

    name = check_readable_file(path, "tap record", MAX_RECORD_BYTES)
    check_complete(name)  # a file cut off in a record: said so, not read as the records before the cut
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # pyuff prints some records it reads (not ours to show)
            sets = pyuff.UFF(name).read_sets()
    except Exception as exc:  # pyuff raises many kinds for broken files
        raise FileFormatError(f"{name}: cannot read the universal file ({exc})") from None
    sets = sets if isinstance(sets, list) else [sets]
    records = [s for s in sets if int(s.get("type", 0)) == 58]
    if not records:
        raise FileFormatError(f"{name}: no type-58 record; expected two time records (force and response)")
    for k, r in enumerate(records):
        if int(r.get("func_type", 0)) != 1:
            raise FileFormatError(f"{name}, record {k}: function type {r.get('func_type')}; expected 1 (time "
                                  "response): a tap record holds the time signals, not an FRF")
        announced, held = r.get("num_pts"), np.asarray(r.get("data", [])).size
        if announced is not None and int(announced) != held:
            raise FileFormatError(f"{name}, record {k}: its header announces {int(announced)} samples but it holds "
                                  f"{held}: the file is truncated or damaged; copy or export it again")
    if len(records) < 2:
        raise FileFormatError(f"{name}: one type-58 record; a tap needs two time records, the force and the "
                              "response, sampled together")
    for k, r in enumerate(records):
        _check_abscissa(name, k, r)
    kinds = [_uff_kind(name, records, k) for k in range(len(records))]
    if len(records) == 2 and kinds.count(None) == 1 and _uff_unit(name, records, kinds.index(None)) is not None:
        # two records, one of them known by its type or unit, the other in volts or unlabelled: the other channel
        unknown = kinds.index(None)
        kinds[unknown] = "force" if kinds[1 - unknown] in RESPONSES else "response"
    return name, records, kinds


def _uff_unit(name: str, records: list[dict], k: int):
    label = str(records[k].get("ordinate_axis_units_lab", "") or "").strip()
    if not label or label.upper() in ("NONE", "N/A", "NA", "-"):
        return None
    try:
        return unit_of(label, f"{name}, record {k}")
    except SubstructureError as exc:
        raise FileFormatError(str(exc)) from None


def _uff_kind(name: str, records: list[dict], k: int) -> str | None:
    spec = int(records[k].get("ordinate_spec_data_type", 0))
    u = _uff_unit(name, records, k)
    by_type = "force" if spec in _FORCE_TYPES else _RESPONSE_TYPES.get(spec)
    found = None if u is None else quantity_of(u)  # one quantity at most: the dimensions differ
    by_unit = found if found in ("force", *RESPONSES) else None
    if by_type and by_unit and by_type != by_unit:
        raise FileFormatError(f"{name}, record {k}: the specific data type says {by_type}, the unit label "
                              f"{records[k].get('ordinate_axis_units_lab')!r} says {by_unit}; fix one")
    return by_type or by_unit


def _uff_pair(name: str, records: list[dict], kinds: list, force_record, response_record) -> tuple[int, int]:
    """The indices of the force and the response record: given, or the one candidate of each."""
    # what each record holds by its data type or unit label, for the messages
    held = ", ".join(f"{k} {q or 'not said'}" for k, q in enumerate(kinds))
    if force_record is None:
        found = [k for k, q in enumerate(kinds) if q == "force"]
        if len(found) != 1:
            raise FileFormatError(f"{name}: {len(found)} force records among {len(records)} type-58 records; "
                                  f"give the force record's index (--force-record, 0-based); they hold {held}")
        force_record = found[0]
    if response_record is None:
        found = [k for k, q in enumerate(kinds) if (q in RESPONSES or q == "response") and k != force_record]
        if len(found) != 1:
            raise FileFormatError(f"{name}: {len(found)} response records among {len(records)} type-58 records; "
                                  f"give the response record's index (--response-record, 0-based); they hold {held}")
        response_record = found[0]
    for option, k in (("force_record", force_record), ("response_record", response_record)):
        if not 0 <= k < len(records):
            raise FileFormatError(f"{name}: {option} {k}: the file holds {len(records)} type-58 records "
                                  f"(0 to {len(records) - 1})")
    return force_record, response_record


def _uff_tap(name: str, records: list[dict], kinds: list, pair: tuple[int, int], sensitivity: Any,
             hammer_sensitivity: Any, quantity: str | None, tap: int | None = None) -> TapRecord:
    """The record of the force and the response records ``pair`` (``tap``: its number among the file's taps)."""
    force_record, response_record = pair
    f_set, r_set = records[force_record], records[response_record]
    where = "" if tap is None else f" (tap {tap})"
    t = np.asarray(f_set["x"], dtype=np.float64)
    if np.asarray(r_set["x"]).shape != t.shape or not np.allclose(r_set["x"], t, rtol=1e-9, atol=1e-12):
        raise FileFormatError(f"{name}: records {force_record} and {response_record}{where} have different time "
                              "axes; expected both channels sampled together")
    labels = [f"record {force_record} ({str(f_set.get('id1', '')).strip() or 'force'})",
              f"record {response_record} ({str(r_set.get('id1', '')).strip() or 'response'})"]
    try:
        f_unit = _uff_unit(name, records, force_record) or unit_of("N", name)
        force, _ = channel_to_si(np.real(np.asarray(f_set["data"])), f_unit, f"{name}: {labels[0]}", ("force",),
                                 hammer_sensitivity, "hammer sensitivity (--hammer-sensitivity)")
        r_unit = _uff_unit(name, records, response_record)
        if r_unit is None:
            said = kinds[response_record] if kinds[response_record] in RESPONSES else quantity
            if said is None:
                raise FileFormatError(f"{name}: {labels[1]} has neither a unit label nor a specific data type; "
                                      "give the quantity (--quantity)")
            r_unit = unit_of(RESPONSE_QUANTITIES[said][0], name)
        response, found_q = channel_to_si(np.real(np.asarray(r_set["data"])), r_unit, f"{name}: {labels[1]}",
                                          RESPONSES, sensitivity, "sensitivity (--sensitivity)")
        if kinds[response_record] in RESPONSES and kinds[response_record] != found_q:
            raise FileFormatError(f"{name}: {labels[1]}: the specific data type says {kinds[response_record]}, the "
                                  f"sensitivity makes it {found_q}")
        check_quantity_option(quantity, found_q, f"{name}: {labels[1]}")
        return TapRecord(t, force, response, found_q, name + where, labels[0], labels[1])
    except FileFormatError:
        raise
    except SubstructureError as exc:
        message = str(exc)
        raise FileFormatError(message if message.startswith(name) else f"{name}: {message}") from None


def _check_abscissa(name: str, k: int, record: dict) -> None:
    """Refuse a record whose abscissa is not time (by its data type or unit label), not increasing or not
    uniformly spaced; convert it to seconds by its unit label (``ms``, ``us``, ``min``; none: seconds)."""
    spec = int(record.get("abscissa_spec_data_type", 0) or 0)
    label = str(record.get("abscissa_axis_units_lab", "") or "").strip()
    if spec not in (0, 17):
        raise FileFormatError(f"{name}, record {k}: abscissa of specific data type {spec}; expected 17 (time) "
                              "or 0: a tap record is sampled in time")
    to_seconds = 1.0
    if label and label.upper() not in ("NONE", "N/A", "NA", "-"):
        try:
            unit = unit_of(label, f"{name}, record {k}")
        except SubstructureError:
            raise FileFormatError(f"{name}, record {k}: abscissa unit label {label!r} is not a unit read here; "
                                  "expected a time unit (s, ms, us)") from None
        if not (1.0 * unit).check("[time]"):
            raise FileFormatError(f"{name}, record {k}: abscissa in {label!r}; expected a time in s")
        to_seconds = magnitude_in(1.0 * unit, "s")
    x = regular(np.asarray(record.get("x", []), dtype=np.float64))  # times written rounded: the clock
    x = record["x"] = x * to_seconds if to_seconds != 1.0 else x
    if x.size > 2:
        step = np.diff(x)
        mean = (x[-1] - x[0]) / (x.size - 1)
        if not mean > 0:
            how = "decreases" if mean < 0 else "does not advance"
            raise FileFormatError(f"{name}, record {k}: the abscissa {how} (from {float(x[0])!r} s to "
                                  f"{float(x[-1])!r} s over {x.size} samples, a step of {float(mean)!r} s); "
                                  "expected time increasing at a uniform step")
        if np.any(np.abs(step - mean) > TIME_STEP_TOLERANCE * mean):
            worst = int(np.argmax(np.abs(step - mean))) + 1
            raise FileFormatError(f"{name}, record {k}: uneven abscissa (sample {worst}: step "
                                  f"{float(step[worst - 1])!r} s, mean {float(mean)!r} s); expected uniform sampling "
                                  "in time")
