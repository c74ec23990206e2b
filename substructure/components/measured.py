"""Substructures known by their receptances: :class:`MeasuredComponent`.

A tap test or a subassembly computed elsewhere, coupled like any component
at the points its FRF names; its frequency lines must cover those of the
computation exactly (no silent interpolation).
"""

from __future__ import annotations

from typing import Sequence

import attrs
import numpy as np

from ..errors import FrequencyAxisMismatchError, InvalidValueError, UnknownPointError
from ..frf import FRF
from ..points import DOFS, PointRef, check_name, parse_point
from .protocol import register_component

__all__ = ["MeasuredComponent"]


def _measured_frf(value) -> FRF:
    if not isinstance(value, FRF):
        raise InvalidValueError(f"frf: got {value!r}; expected an FRF")
    if value.outputs != value.inputs:
        raise InvalidValueError(
            "frf: a measured component needs a square receptance matrix with the same "
            f"outputs and inputs; got outputs {value.outputs} and inputs {value.inputs}"
        )
    for label in value.outputs:
        try:
            ref = parse_point(label)
        except UnknownPointError as exc:
            raise InvalidValueError(
                f"frf: the label {label!r} is not a point name with its DOF ({exc}); expected labels such as "
                "'holder.tip:y' and 'holder.tip:theta', which say the points the component is coupled at"
            ) from None
        if ref.dof is None:
            raise InvalidValueError(f"frf: the label {label!r} has no DOF; expected '{label}:y' or '{label}:theta'")
    return value.to_receptance()


@register_component("measured")
@attrs.frozen
class MeasuredComponent:
    """A substructure known by its receptances (measured, or computed elsewhere).

    Parameters
    ----------
    name : str
        Name of the component in messages.
    frf : FRF
        Square receptance matrix whose labels are point names with DOFs,
        e.g. ``"holder.tip:y"``, ``"holder.tip:theta"``.  Both DOFs of a point
        are needed for coupling at that point (estimate rotational FRFs by
        finite differences when only ``y`` was measured).

    Notes
    -----
    The points answer to the component names in the labels, so that a
    measured spindle-holder subassembly keeps the point names of the model
    (``"holder.tip"``) and couples to a tool like the modelled one.
    """

    name: str = attrs.field(converter=check_name)
    frf: FRF = attrs.field(converter=_measured_frf)

    @property
    def component_names(self) -> frozenset[str]:
        """The component names in the FRF's labels: the points this component answers for."""
        return frozenset(parse_point(lbl).component for lbl in self.frf.outputs)

    @property
    def points(self) -> tuple[str, ...]:
        """The point names of the FRF's labels, in order."""
        return tuple(dict.fromkeys(str(parse_point(lbl).point) for lbl in self.frf.outputs))

    def node_key(self, ref: PointRef):
        """A key of the physical point, after checking that both DOFs were measured.

        Parameters
        ----------
        ref : PointRef
            A point named in the FRF's labels.

        Returns
        -------
        tuple
            ``(name, point name)``.

        Raises
        ------
        UnknownPointError
            When the point, or one of its DOFs ``y`` and ``theta``, is not in the FRF.
        """
        point = str(ref.point)
        missing = [f"{point}:{d}" for d in DOFS if f"{point}:{d}" not in self.frf.outputs]
        if len(missing) == 2:
            raise UnknownPointError(
                f"point {point}: not in measured component {self.name!r}, which has {', '.join(self.points)}"
            )
        if missing:
            raise UnknownPointError(
                f"point {point}: measured component {self.name!r} lacks {', '.join(missing)}; "
                "coupling needs both y and theta (estimate rotational FRFs by finite differences)"
            )
        return (self.name, point)

    def receptance_matrix(self, refs: Sequence[PointRef], frequency_hz: np.ndarray) -> np.ndarray:
        """The measured receptances between points, frequency last (the component protocol).

        Parameters
        ----------
        refs : sequence of PointRef
            The p points.
        frequency_hz : ndarray
            Frequencies in Hz: a contiguous run of the FRF's own lines (never interpolated).

        Returns
        -------
        ndarray
            Complex, shape ``(2p, 2p, n_freq)``, DOFs ``(y, theta)`` per point, in m/N, m/(N m),
            rad/N and rad/(N m).

        Raises
        ------
        FrequencyAxisMismatchError
            When the frequencies are not lines of the FRF.
        """
        f = np.asarray(frequency_hz, dtype=float)
        hz = self.frf.frequency.hz
        start = int(np.searchsorted(hz, f[0])) if f.size else 0
        if f.size == 0 or not np.array_equal(hz[start : start + f.size], f):
            raise FrequencyAxisMismatchError(
                f"measured component {self.name!r} is known on {self.frf.frequency!r}; the request "
                "uses another grid: interpolate the FRF or compute on its grid"
            )
        for r in refs:
            self.node_key(r)
        labels = [f"{r.point}:{d}" for r in refs for d in DOFS]
        index = [self.frf.outputs.index(lbl) for lbl in labels]
        data = self.frf.data[start : start + f.size]
        return np.moveaxis(data[:, index][:, :, index], 0, -1)

