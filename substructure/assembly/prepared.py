"""An assembly's FRF prepared for fast re-evaluation: :class:`PreparedFRF`.

The components' free-free receptances at the points that take part are
computed once; :meth:`PreparedFRF.evaluate` re-couples them with some
joints, sensors, supports or components replaced.  Identification and
diagnosis fits evaluate models this way.
"""

from __future__ import annotations

import numpy as np

from .._blocks import CHUNK_LINES, by_chunks
from ..components.protocol import receptances
from ..coupling import Link, couple_substructures
from ..errors import InvalidValueError, UnknownPointError
from ..frf import FRF
from ..joints import Mass, Sensor, Support, dynamic_stiffness
from .plan import expand_points, point_names

__all__ = ["PreparedFRF"]


class PreparedFRF:
    """An assembly's FRF at fixed points and frequency lines, for fast re-evaluation.

    Built by :meth:`Assembly.prepare`.  :meth:`evaluate` accepts replacements
    for joints (by name), sensors (by name) and supports (by name or label),
    which must act on the same points as the ones they replace; everything
    else (the components' free-free receptances) is reused.

    Parameters
    ----------
    assembly : Assembly
        The model.
    outputs : str or sequence of str
        Response points (``"tool.tip:y"``; without a DOF suffix, both DOFs).
    inputs : str or sequence of str, optional
        Excitation points; default ``outputs``.
    frequency : Frequency or array_like, optional
        Frequency lines (plain numbers in Hz); default the assembly's grid.
    """

    def __init__(self, assembly, outputs, inputs=None, frequency=None):
        self.assembly = assembly
        self.frequency = assembly._frequency(frequency)
        outputs = point_names(outputs)
        inputs = outputs if inputs is None else point_names(inputs)
        self.outputs, out_idx, out_refs = expand_points(outputs)
        self.inputs, in_idx, in_refs = expand_points(inputs)
        self._groups, self._out_keys, self._links = assembly._plan(out_refs + in_refs)
        self._blocks = [
            ([k for k, _ in items],
             by_chunks(lambda ff, o=owner, r=[ref for _, ref in items]: receptances(o, r, ff), self.frequency.hz))
            for owner, items in self._groups
        ]
        self._rows = [2 * i + d for i, d in out_idx]
        self._cols = [2 * (len(out_refs) + i) + d for i, d in in_idx]

    def _replacement(self, obj, joints, sensors, supports):
        if isinstance(obj, Mass):
            return obj
        if isinstance(obj, Sensor):
            new = sensors.get(obj.name, obj)
            where = (obj.at, new.at)
        elif isinstance(obj, Support):
            new = supports.get(obj.name or f"support at {obj.at}", obj)
            where = (obj.at, new.at)
        else:
            new = joints.get(obj.name, obj)
            where = (tuple(obj.between), tuple(new.between))
        if where[0] != where[1]:
            raise InvalidValueError(
                f"prepared FRF: a replacement must act on the same points ({where[0]}), got {where[1]}"
            )
        return new

    def evaluate(self, joints=None, sensors=None, supports=None, components=None) -> FRF:
        """The FRF with some joints, sensors, supports or components replaced (mappings by name).

        A replaced component is recomputed at the same points (it must have
        them); the others' receptances are reused.

        Parameters
        ----------
        joints : mapping, optional
            ``{joint name: Joint}``: joints acting between the same points.
        sensors : mapping, optional
            ``{sensor name: Sensor}``: sensors at the same points.
        supports : mapping, optional
            ``{support name or "support at POINT": Support}``.
        components : mapping, optional
            ``{component name: component}``, recomputed at the same points.

        Returns
        -------
        FRF
            The FRF at the prepared points and lines (m/N, m/(N m), rad/N, rad/(N m)).
        """
        joints, sensors, supports = dict(joints or {}), dict(sensors or {}), dict(supports or {})
        f = self.frequency.hz
        blocks_all = list(self._blocks)
        names = {owner.name: i for i, (owner, _) in enumerate(self._groups)}
        for name, comp in dict(components or {}).items():
            if name not in names:
                raise UnknownPointError(
                    f"prepared FRF: no component {name!r} takes part (components: {sorted(names)})"
                )
            i = names[name]
            refs = [ref for _, ref in self._groups[i][1]]
            blocks_all[i] = (blocks_all[i][0], by_chunks(lambda ff: receptances(comp, refs, ff), f))
        known = {o.name for _, _, o, _ in self._links if not isinstance(o, (Sensor, Support, Mass))}
        unknown = set(joints) - known
        if unknown:
            raise UnknownPointError(f"prepared FRF: no joint {sorted(unknown)} (joints: {sorted(known)})")
        objs = [self._replacement(obj, joints, sensors, supports) for _, _, obj, _ in self._links]
        n = f.size
        parts = []
        for start in range(0, n, CHUNK_LINES):
            sl = slice(start, min(n, start + CHUNK_LINES))
            blocks = [(keys, y[..., sl]) for keys, y in blocks_all]
            links = [
                Link(ka, kb, None if getattr(o, "rigid", False) else dynamic_stiffness(o, f[sl]), label)
                for (ka, kb, _, label), o in zip(self._links, objs)
            ]
            parts.append(couple_substructures(blocks, links, self._out_keys))
        y = np.concatenate(parts, axis=-1) if len(parts) > 1 else parts[0]
        data = np.moveaxis(y[np.ix_(self._rows, self._cols)], -1, 0)
        return FRF(self.frequency, data, tuple(self.outputs), tuple(self.inputs))
