"""The structure a stability method sees: tool point receptances in x and y.

Stability needs the receptance of the tool relative to the workpiece in the
plane of the cut: ``x`` along the feed, ``y`` normal to it.  Here that is an
:class:`~substructure.frf.FRF` with outputs and inputs labelled ``"x"`` and
``"y"`` (a 2x2 matrix ``[[xx, xy], [yx, yy]]`` per frequency line), built by
:func:`xy_frf` from the FRFs a user has: one FRF for a symmetric tool (``y``
equal to ``x``, no cross terms), two for an asymmetric one, cross terms when
measured.  A :class:`~substructure.stability.modal.ModalModel` gives the same
object from modal parameters.  :func:`xy_receptance` turns anything the
methods accept into frequency-first arrays, and names what is missing.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import FrequencyAxisMismatchError, InvalidValueError
from ..frf import FRF, Frequency

__all__ = ["xy_frf", "xy_receptance", "XY_LABELS"]

XY_LABELS = ("x", "y")
"""Labels of the two directions in the plane of the cut: feed (x) and normal (y)."""


def _one_entry(frf: Any, field: str) -> FRF:
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"{field}: got {type(frf).__name__}; expected an FRF (e.g. FRF.from_csv(path))")
    if frf.shape[1:] != (1, 1):
        raise InvalidValueError(
            f"{field}: got an FRF with outputs {list(frf.outputs)} and inputs {list(frf.inputs)}; expected "
            "one translational receptance, e.g. frf['tool.tip:y', 'tool.tip:y']"
        )
    label = frf.outputs[0]
    if label.endswith(":theta") or frf.inputs[0].endswith(":theta"):
        raise InvalidValueError(
            f"{field}: got the rotational entry {frf.outputs[0]} / {frf.inputs[0]}; the cutting force "
            "and the chip thickness need a translational receptance (':y' DOFs)"
        )
    return frf.to_receptance()


def xy_frf(x: FRF, y: FRF | None = None, xy: FRF | None = None, yx: FRF | None = None) -> FRF:
    """Tool point receptances in the feed (x) and normal (y) directions as one 2x2 FRF.

    Parameters
    ----------
    x : FRF
        One translational receptance of the tool point in the feed direction
        (m/N; mobility and accelerance are converted).
    y : FRF, optional
        The same normal to the feed; default: equal to ``x`` (a symmetric
        tool, which is what a single tap test of a rotating tool gives).
    xy, yx : FRF, optional
        Cross receptances (x response to a y force, and the reverse); zero
        when not given.  Give both or neither.

    Returns
    -------
    FRF
        Outputs and inputs ``("x", "y")``.

    Raises
    ------
    FrequencyAxisMismatchError
        When the FRFs are not on one frequency axis (interpolate first).
    """
    x = _one_entry(x, "x")
    y = x if y is None else _one_entry(y, "y")
    if (xy is None) != (yx is None):
        raise InvalidValueError("xy, yx: give both cross receptances or neither")
    parts = {"xx": x, "yy": y}
    if xy is not None:
        parts["xy"], parts["yx"] = _one_entry(xy, "xy"), _one_entry(yx, "yx")
    data = np.zeros((x.frequency.n, 2, 2), dtype=complex)
    for name, frf in parts.items():
        if frf.frequency != x.frequency:
            raise FrequencyAxisMismatchError(
                f"{name}: on {frf.frequency!r}, while x is on {x.frequency!r}; "
                "interpolate them to one grid first (FRF.interpolate)"
            )
        data[:, XY_LABELS.index(name[0]), XY_LABELS.index(name[1])] = frf.data[:, 0, 0]
    return FRF(x.frequency, data, XY_LABELS, XY_LABELS)


def xy_receptance(structure: Any, frequency: Frequency | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(frequency_hz, G)`` with ``G`` of shape ``(n, 2, 2)`` from what the methods accept.

    Parameters
    ----------
    structure : FRF or ModalModel
        An FRF labelled ``x``/``y`` (:func:`xy_frf`), a one-entry
        translational FRF (taken as a symmetric tool), or modal parameters
        (anything with ``xy_frf(frequency)``).
    frequency : Frequency, optional
        For modal parameters: the lines to evaluate on (default: the model's
        own grid, refined around every mode).
    """
    if hasattr(structure, "xy_frf") and not isinstance(structure, FRF):
        frf = structure.xy_frf(frequency)
    elif isinstance(structure, FRF):
        if frequency is not None:
            raise InvalidValueError(
                "frequency: FRF data are used on their own lines; crop or interpolate the FRF instead"
            )
        if structure.shape[1:] == (1, 1):
            frf = xy_frf(structure)
        elif set(structure.outputs) == set(XY_LABELS) and set(structure.inputs) == set(XY_LABELS):
            frf = structure.select(list(XY_LABELS), list(XY_LABELS)).to_receptance()
        else:
            raise InvalidValueError(
                f"structure: got an FRF with outputs {list(structure.outputs)} and inputs "
                f"{list(structure.inputs)}; stability needs the tool point receptances in x (feed) and y: "
                "build them with xy_frf(x=H) for a symmetric tool (H = frf['tool.tip:y', 'tool.tip:y']) "
                "or xy_frf(x=Hx, y=Hy)"
            )
    else:
        raise InvalidValueError(
            f"structure: got {type(structure).__name__}; expected an FRF (xy_frf(...)) or a ModalModel"
        )
    hz = frf.frequency.hz
    if hz[0] <= 0.0:
        raise InvalidValueError("structure: the FRF has a line at 0 Hz; crop it (frf.crop(lo='1 Hz'))")
    return hz, np.asarray(frf.data)
