"""The assembly graph: :class:`Assembly`, components connected by joints, with bodies and supports.

Nodes are components, edges are joints; sensors, masses and supports hang on
points.  The assembly owns its bookkeeping (which DOF is where), checks its
names and points on construction, and is immutable: ``add``, ``connect``,
``attach``, ``support`` and the ``with_*``/``without*`` methods return new
assemblies.  Its receptances come from the plan and the coupling of
``substructure.assembly.plan``; an assembly is itself a component.
"""

from __future__ import annotations

from typing import Sequence

import attrs
import numpy as np

from .._blocks import CHUNK_LINES, by_chunks
from ..components import as_frequency
from ..errors import AssemblyError, InvalidValueError, UnknownPointError
from ..frf import FRF, Frequency
from ..joints import Joint, Mass, Sensor, Support
from ..materials import Material
from ..points import PointRef, parse_point
from ._fields import _component_check, _joint_check, _tuple
from .plan import couple, expand_points, plan, point_names
from .prepared import PreparedFRF

__all__ = ["Assembly"]


@attrs.frozen
class Assembly:
    """Components connected by joints, with sensors and supports on points.

    Parameters
    ----------
    name : str
        Name of the assembly, in summaries and saved files.
    components : sequence
        Beams, measured components or subassemblies.
    joints : sequence of Joint
        Connections between points of the components (stiffness in N/m, N and
        N m/rad, damping in N s/m, N s and N m s/rad; or rigid).
    supports : sequence of Support
        Springs and dampers from points to the ground.
    sensors : sequence of Sensor
        Bodies on the structure (they are part of the model: their mass acts).
    frequency : Frequency, optional
        Default frequency grid of the computations and commands.
    materials : sequence of Material
        Custom materials this assembly was defined with (kept for saving).
    masses : sequence of Mass
        Bodies permanently on the structure (clamping nuts, balancing rings):
        unlike sensors, they act in every test and in every prediction.
    """

    name: str = attrs.field(default="assembly")
    components: tuple = attrs.field(default=(), converter=_component_check)
    joints: tuple = attrs.field(default=(), converter=_joint_check)
    supports: tuple[Support, ...] = attrs.field(default=(), converter=_tuple(Support, "supports"))  # type: ignore[misc]  # attrs plugin: converter factory
    sensors: tuple[Sensor, ...] = attrs.field(default=(), converter=_tuple(Sensor, "sensors"))  # type: ignore[misc]  # attrs plugin: converter factory
    frequency: Frequency | None = attrs.field(default=None)
    materials: tuple[Material, ...] = attrs.field(default=(), converter=_tuple(Material, "materials"))  # type: ignore[misc]  # attrs plugin: converter factory
    masses: tuple[Mass, ...] = attrs.field(default=(), converter=_tuple(Mass, "masses"))  # type: ignore[misc]  # attrs plugin: converter factory

    def __attrs_post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InvalidValueError(f"name: got {self.name!r}; expected a non-empty string")
        if self.frequency is not None and not isinstance(self.frequency, Frequency):
            raise InvalidValueError(f"frequency: got {self.frequency!r}; expected a Frequency")
        seen: dict[str, str] = {}
        for comp in self.components:
            for n in comp.component_names:
                if n in seen:
                    raise AssemblyError(
                        f"component name {n!r} is used twice (in {seen[n]!r} and {comp.name!r}); "
                        "names must be unique in an assembly"
                    )
                seen[n] = comp.name
        named_supports = tuple(s for s in self.supports if s.name is not None)
        for kind, items in (("joint", self.joints), ("sensor", self.sensors), ("support", named_supports),
                            ("mass", self.masses)):
            names = [i.name for i in items]
            dup = {n for n in names if n is not None and names.count(n) > 1}  # supports: the named ones
            if dup:
                raise AssemblyError(f"{kind} names used twice: {', '.join(sorted(dup))}")
        for j in self.joints:
            ka, kb = (self._resolve(p, f"joint {j.name!r}")[2] for p in j.between)
            if ka == kb:  # "tool.tip" and "tool@30 mm" on a 30 mm tool: refused here, not at the first receptance
                raise AssemblyError(f"joint {j.name!r}: {j.between[0]} and {j.between[1]} are the same point; a "
                                    "joint connects two different points")
        for sensor in self.sensors:
            self._resolve(sensor.at, f"sensor {sensor.name!r}")
        for support in self.supports:
            self._resolve(support.at, "support")
        for m in self.masses:
            self._resolve(m.at, f"mass {m.name!r}")

    # -- lookup -----------------------------------------------------------

    @property
    def component_names(self) -> frozenset[str]:
        """Every component name whose points this assembly answers for."""
        return frozenset(n for c in self.components for n in c.component_names)

    def _owner(self, ref: PointRef, context: str = "", index: dict | None = None):
        if index is not None and ref.component in index:
            return index[ref.component]
        for comp in self.components:
            if ref.component in comp.component_names:
                return comp
        where = f"{context}: " if context else ""
        known = ", ".join(sorted(self.component_names)) or "none"
        raise UnknownPointError(
            f"{where}point {ref}: there is no component {ref.component!r} in assembly "
            f"{self.name!r} (components: {known})"
        )

    def _resolve(self, point: str | PointRef, context: str = "", index: dict | None = None):
        ref = parse_point(point)
        owner = self._owner(ref, context, index)
        try:
            key = owner.node_key(ref.point)
        except UnknownPointError as exc:
            raise UnknownPointError(f"{context}: {exc}" if context else str(exc)) from None
        return ref, owner, key

    def component(self, name: str):
        """The component (or the subassembly holding it) called ``name``.

        Parameters
        ----------
        name : str
            A component name.

        Returns
        -------
        object
            The component.

        Raises
        ------
        UnknownPointError
            When there is no such component.
        """
        if not isinstance(name, str):
            raise UnknownPointError(f"component: got {name!r}; expected a component's name, e.g. 'tool'")
        for comp in self.components:
            if comp.name == name:
                return comp
        for comp in self.components:
            if name in comp.component_names and isinstance(comp, Assembly):
                return comp.component(name)
        raise UnknownPointError(f"no component {name!r} in assembly {self.name!r}")

    def _named(self, items: tuple, kind: str, plural: str, name: str):
        if not isinstance(name, str):
            raise UnknownPointError(f"{kind}: got {name!r}; expected a {kind}'s name")
        for item in items:
            if item.name == name:
                return item
        known = ", ".join(i.name for i in items) or "none"
        raise UnknownPointError(f"no {kind} {name!r} in assembly {self.name!r} ({plural}: {known})")

    def joint(self, name: str) -> Joint:
        """The joint called ``name``.

        Parameters
        ----------
        name : str
            A joint name.

        Returns
        -------
        Joint
            The joint.

        Raises
        ------
        UnknownPointError
            When there is no such joint (the message lists the joints).
        """
        return self._named(self.joints, "joint", "joints", name)

    def mass(self, name: str) -> Mass:
        """The permanent body (:class:`Mass`) called ``name``.

        Parameters
        ----------
        name : str
            Its name.

        Returns
        -------
        Mass
            The body.

        Raises
        ------
        UnknownPointError
            When there is none of that name.
        """
        return self._named(self.masses, "mass", "masses", name)

    def sensor(self, name: str) -> Sensor:
        """The sensor called ``name``.

        Parameters
        ----------
        name : str
            A sensor name.

        Returns
        -------
        Sensor
            The sensor.

        Raises
        ------
        UnknownPointError
            When there is no such sensor (the message lists the sensors).
        """
        return self._named(self.sensors, "sensor", "sensors", name)

    # -- building (each returns a new assembly) ---------------------------

    def add(self, *components) -> "Assembly":
        """Add components (beams, measured components, subassemblies).

        Parameters
        ----------
        *components : object
            The components to add.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        return attrs.evolve(self, components=self.components + components)

    def connect(self, a, b: str | None = None, *, name: str | None = None,
                k=None, c=None, rigid: bool = False) -> "Assembly":
        """Connect two points by a joint: ``connect(joint)`` or ``connect(a, b, k=..., c=...)``.

        Without ``k`` and ``c`` the connection is rigid; damping ``c`` without
        a stiffness ``k`` is refused (as :class:`Joint` refuses it), rather
        than made rigid with ``c`` lost.

        Parameters
        ----------
        a : str or Joint
            The first point (``"holder.tip"``), or a whole :class:`Joint`.
        b : str, optional
            The second point; needed when ``a`` is a point.
        name : str, optional
            The joint's name; default ``"joint-N"``.
        k : mapping, optional
            Stiffness entries ``{"yf": "4.1e7 N/m", "ym": "... N", "tf": "... N", "tm": "... N*m/rad"}``
            (thesis eq. 2.5); None for a rigid connection.
        c : mapping, optional
            Damping entries ``{"yf": "... N*s/m", "ym": "... N*s", "tf": "... N*s", "tm": "... N*m*s/rad"}``.
        rigid : bool
            A rigid connection (same displacement and slope at both points).

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        if not isinstance(a, str):
            joint = a  # a Joint, or any object of the joint protocol
        else:
            if b is None:
                raise InvalidValueError("connect: expected two points, or a Joint")
            label = name or f"joint-{len(self.joints) + 1}"
            if k is None and c is not None:
                raise InvalidValueError(
                    f"joint {label!r}: got damping c without stiffness k; an elastic joint needs k "
                    "(e.g. k={'yf': '1e7 N/m'}), a rigid one takes neither"
                )
            joint = Joint(label, (a, b), k=k, c=c, rigid=rigid or (k is None and c is None))
        return attrs.evolve(self, joints=self.joints + (joint,))

    def attach(self, *sensors: Sensor | Mass) -> "Assembly":
        """Put sensors (or permanent bodies, :class:`Mass`) on the structure.

        Parameters
        ----------
        *sensors : Sensor or Mass
            The bodies; masses go to ``masses``, sensors to ``sensors``.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        masses = tuple(s for s in sensors if isinstance(s, Mass))
        others = tuple(s for s in sensors if not isinstance(s, Mass))
        return attrs.evolve(self, sensors=self.sensors + others, masses=self.masses + masses)

    def support(self, at: str | Support, k=None, c=None) -> "Assembly":
        """Add springs/dampers to the ground at a point: ``support(Support(...))`` or ``support(at, k, c)``.

        Parameters
        ----------
        at : str or Support
            The point (``"spindle.base"``), or a whole :class:`Support`.
        k : mapping, optional
            Stiffness entries ``{"yf": "... N/m", "tm": "... N*m/rad", ...}``.
        c : mapping, optional
            Damping entries ``{"yf": "... N*s/m", "tm": "... N*m*s/rad", ...}``.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        sup = at if isinstance(at, Support) else Support(at, k=k, c=c)
        return attrs.evolve(self, supports=self.supports + (sup,))

    def with_effect(self, effect) -> "Assembly":
        """The assembly with a physical effect added (e.g. a fitted one from a diagnosis).

        ``effect`` is any object with ``apply(assembly) -> Assembly``, such as the
        effects of :mod:`substructure.diagnose.effects`; the result is a normal
        assembly (a sensor, a joint value, a flutes entry, a support), which
        :func:`substructure.save_assembly` writes in its usual form.

        Parameters
        ----------
        effect : object
            An object with ``apply(assembly) -> Assembly``.

        Returns
        -------
        Assembly
            The assembly the effect returns; this one is unchanged.
        """
        if not hasattr(effect, "apply"):
            raise InvalidValueError(f"effect: got {effect!r}; expected an object with apply(assembly)")
        result = effect.apply(self)
        if not isinstance(result, Assembly):
            raise InvalidValueError(f"effect {effect!r}: apply returned {type(result).__name__}, not an Assembly")
        return result

    def with_joint(self, joint: Joint) -> "Assembly":
        """Replace the joint of the same name.

        Parameters
        ----------
        joint : Joint
            The new joint; an assembly's joint of that name must exist.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        _check_member(joint, "joint", ("name", "between", "rigid", "dynamic_stiffness"), "with_joint")
        self.joint(joint.name)
        return attrs.evolve(self, joints=tuple(joint if j.name == joint.name else j for j in self.joints))

    def with_component(self, component) -> "Assembly":
        """Replace the component of the same name.

        Parameters
        ----------
        component : object
            The new component; an assembly's component of that name must exist.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        _check_member(component, "component", ("name", "component_names", "node_key", "receptance_matrix"),
                      "with_component")
        if not any(c.name == component.name for c in self.components):
            raise UnknownPointError(f"no component {component.name!r} in assembly {self.name!r}")
        return attrs.evolve(
            self, components=tuple(component if c.name == component.name else c for c in self.components)
        )

    def without_sensors(self, *names: str) -> "Assembly":
        """The assembly without the named sensors (all when none is named).

        Parameters
        ----------
        *names : str
            Sensor names; none for all sensors.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        for n in names:
            self.sensor(n)
        keep = tuple(s for s in self.sensors if names and s.name not in names)
        return attrs.evolve(self, sensors=keep)

    def without(self, *names: str) -> "Assembly":
        """The assembly without the named components and what hangs on them.

        Joints, sensors and supports on a removed component are removed too.

        Parameters
        ----------
        *names : str
            Component names.

        Returns
        -------
        Assembly
            A new assembly; this one is unchanged.
        """
        for n in names:
            if not isinstance(n, str) or not any(c.name == n for c in self.components):
                raise UnknownPointError(f"no component {n!r} in assembly {self.name!r}")
        removed = {m for c in self.components if c.name in names for m in c.component_names}

        def on_removed(point: str) -> bool:
            return parse_point(point).component in removed

        return attrs.evolve(
            self,
            components=tuple(c for c in self.components if c.name not in names),
            joints=tuple(j for j in self.joints if not any(on_removed(p) for p in j.between)),
            sensors=tuple(s for s in self.sensors if not on_removed(s.at)),
            supports=tuple(s for s in self.supports if not on_removed(s.at)),
            masses=tuple(m for m in self.masses if not on_removed(m.at)),
        )

    # -- computing ---------------------------------------------------------

    def _frequency(self, frequency) -> Frequency:
        if frequency is None:
            if self.frequency is None:
                raise InvalidValueError(
                    f"frequency: assembly {self.name!r} has no default grid; pass frequency="
                )
            return self.frequency
        return as_frequency(frequency)

    def _plan(self, refs: Sequence[PointRef]):
        # what a computation needs (substructure.assembly.plan.plan); sweeps compare the plans
        return plan(self, refs)

    def receptance_matrix(self, refs: Sequence[PointRef], frequency_hz: np.ndarray) -> np.ndarray:
        """Coupled receptances between points, frequency last (the component protocol).

        Parameters
        ----------
        refs : sequence of PointRef
            The p points.
        frequency_hz : ndarray
            Frequencies in Hz.

        Returns
        -------
        ndarray
            Complex, shape ``(2p, 2p, n_freq)``, DOFs ``(y, theta)`` per point: m/N, m/(N m),
            rad/N and rad/(N m).
        """
        groups, out_keys, links = self._plan(refs)
        return by_chunks(lambda f: self._compute(groups, out_keys, links, f), frequency_hz)

    _compute = staticmethod(couple)  # one chunk of lines (substructure.assembly.plan.couple)

    def prepare(self, outputs, inputs=None, frequency=None) -> "PreparedFRF":
        """The FRF from ``inputs`` to ``outputs``, ready to be re-evaluated fast.

        The components' receptances are computed once; :meth:`PreparedFRF.evaluate`
        then only re-couples, with some joints, sensors or supports replaced.
        Identification and diagnosis fits evaluate the model this way.

        Parameters
        ----------
        outputs : str or sequence of str
            Response points (``"tool.tip:y"``; without a DOF suffix, both DOFs).
        inputs : str or sequence of str, optional
            Excitation points; default ``outputs``.
        frequency : Frequency or array_like, optional
            Frequency lines (plain numbers in Hz); default the assembly's grid.

        Returns
        -------
        PreparedFRF
            The FRF, to be evaluated with :meth:`PreparedFRF.evaluate`.
        """
        return PreparedFRF(self, outputs, inputs, frequency)

    def node_key(self, ref: PointRef):
        """A key of the physical point (the component protocol, for subassemblies).

        Parameters
        ----------
        ref : PointRef
            A point of one of the components.

        Returns
        -------
        object
            The key the owning component gives the point.
        """
        return self._resolve(ref)[2]

    def frf(self, outputs: Sequence[str] | str, inputs: Sequence[str] | str | None = None,
            frequency=None) -> FRF:
        """Coupled receptances from ``inputs`` to ``outputs``.

        Parameters
        ----------
        outputs : str or sequence of str
            Response points; a point without a DOF suffix stands for both its
            DOFs ``(y, theta)``.
        inputs : str or sequence of str, optional
            Excitation points, likewise; default ``outputs``.
        frequency : Frequency or array_like, optional
            Frequency lines (plain numbers in Hz); default the assembly's grid.

        Returns
        -------
        FRF
            Shape ``(n_freq, n_out, n_in)``: displacement y in m or slope theta in rad per
            force in N or moment in N m (H in m/N, L in m/(N m), N in rad/N, P in rad/(N m)).
        """
        freq = self._frequency(frequency)
        outputs = point_names(outputs)
        inputs = outputs if inputs is None else point_names(inputs)
        if not outputs or not inputs:
            raise InvalidValueError("frf: expected at least one output and one input point")

        out_labels, out_idx, out_refs = expand_points(outputs)
        in_labels, in_idx, in_refs = expand_points(inputs)
        groups, keys, links = self._plan(out_refs + in_refs)
        # each physical point once (a point receptance names its point twice), and only the
        # requested entries kept from each chunk of lines: the memory is the result's
        unique = list(dict.fromkeys(keys))
        slot = [unique.index(k) for k in keys]
        rows = [2 * slot[i] + d for i, d in out_idx]
        cols = [2 * slot[len(out_refs) + i] + d for i, d in in_idx]
        f = freq.hz
        data = np.empty((f.size, len(rows), len(cols)), dtype=complex)
        for start in range(0, f.size, CHUNK_LINES):
            stop = min(f.size, start + CHUNK_LINES)
            y = self._compute(groups, unique, links, f[start:stop])
            data[start:stop] = np.moveaxis(y[np.ix_(rows, cols)], -1, 0)
        data.flags.writeable = False  # handed to the FRF without a copy
        return FRF(freq, data, tuple(out_labels), tuple(in_labels))

    def receptance(self, at: str, to: str | None = None, frequency=None) -> FRF:
        """Receptance at ``at`` due to a load at ``to`` (default: the point receptance).

        Without DOF suffixes this is the 2x2 matrix ``[[H, L], [N, P]]``
        (thesis eq. 2.7); ``"tool.tip:y"`` picks one DOF.

        Parameters
        ----------
        at : str
            Response point, with or without a DOF suffix.
        to : str, optional
            Excitation point; default ``at`` (a point receptance).
        frequency : Frequency or array_like, optional
            Frequency lines (plain numbers in Hz); default the assembly's grid.

        Returns
        -------
        FRF
            H in m/N, L in m/(N m), N in rad/N, P in rad/(N m).
        """
        return self.frf([at], [to if to is not None else at], frequency)

    def describe(self) -> str:
        """A few lines describing the assembly, for summaries and teaching.

        Returns
        -------
        str
            One line per component, joint, support and sensor, with units.
        """
        from ..components import component_info

        lines = [f"{self.name}:"]
        lines += [f"  component {component_info(c)}" for c in self.components]
        for j in self.joints:
            what = "rigid" if j.rigid else ", ".join(f"k_{k}={v}" for k, v in j.k.as_dict().items())
            lines.append(f"  joint {j.name}: {j.between[0]} -- {j.between[1]} ({what})")
        for support in self.supports:
            lines.append(f"  support at {support.at}: "
                         + ", ".join(f"k_{k}={v}" for k, v in support.k.as_dict().items()))
        for sensor in self.sensors:
            lines.append(f"  sensor {sensor.name} at {sensor.at}: {sensor.mass:~P}")
        for m in self.masses:
            lines.append(f"  mass {m.name} at {m.at}: {m.mass:~P}")
        return "\n".join(lines)


def _check_member(item, kind: str, attributes: tuple, method: str) -> None:
    """Refuse, naming the method, what is not a joint or a component (a name given for the object, None)."""
    missing = [a for a in attributes if not hasattr(item, a)]
    if missing:
        hint = (f" (a name: give the {kind} itself, e.g. assembly.{kind}({item!r}) changed)"
                if isinstance(item, str) else "")
        raise InvalidValueError(f"{method}: got {item!r}, which is not a {kind} (it has no {missing[0]!r}){hint}")
