"""A measurement set: :class:`MeasurementSet` (one test campaign on one frequency axis), :func:`model_of_measurement`.

Files in the format of docs/file-formats.md ("Measurement set (TOML)") are read by ``files``
(:meth:`MeasurementSet.from_file`, :func:`substructure.io.measurements.load_measurements`).
"""

from __future__ import annotations

import os
from typing import Any, Iterator, Sequence

import attrs
import numpy as np

from ..errors import FrequencyAxisMismatchError, InvalidValueError, SubstructureError
from ..units import items_of
from ..frf import FRF, Frequency
from ..points import parse_point
from .measurement import (
    Configuration,
    Measurement,
    MeasurementSetError,
    MissingMeasurementError,
    _describe_configuration,
    _names,
    dof_label,
)

__all__ = ["MeasurementSet", "model_of_measurement"]


def _measurements(value: Any) -> tuple[Measurement, ...]:
    if isinstance(value, Measurement):
        value = (value,)
    try:
        items = tuple(value)
    except TypeError:
        raise InvalidValueError(f"measurements: got {value!r}; expected a sequence of Measurement") from None
    if not items:
        raise InvalidValueError("measurements: got none; expected at least one Measurement")
    for i, item in enumerate(items):
        if not isinstance(item, Measurement):
            raise InvalidValueError(f"measurements[{i}]: got {type(item).__name__}; expected a Measurement")
    return items


def measurements_given(value: Any) -> Any:
    """What a workflow (``identify_joint``, ``diagnose``) was given as its measurements, to go through: a
    MeasurementSet or a sequence as it is; refused by name when it is no sequence (a number, None)."""
    try:
        iter(value)
    except TypeError:
        raise InvalidValueError(f"measurements: got {type(value).__name__}; expected a MeasurementSet or a list of "
                                "measurements") from None
    return value


def _configuration_of(sensors: Any, removed: Any) -> Configuration:
    return tuple(sorted(_names("sensors")(sensors))), tuple(sorted(_names("removed")(removed)))


@attrs.frozen(repr=False)
class MeasurementSet:
    """The measured FRFs of one test campaign, on one frequency axis.

    Parameters
    ----------
    name : str
        What was measured, for summaries.
    measurements : sequence of Measurement
        At least one; all on the same frequency axis (interpolate them to a
        common grid first: axes are never reconciled silently), and no two
        with the same response, excitation and configuration.
    source : str, optional
        The file the set was read from, for messages (not compared).

    Raises
    ------
    FrequencyAxisMismatchError
        When two measurements have different frequency axes; names both.
    InvalidValueError
        For a duplicate measurement or an empty set.
    """

    name: str = attrs.field()
    measurements: tuple[Measurement, ...] = attrs.field(converter=_measurements)
    source: str | None = attrs.field(default=None, eq=False)

    def __attrs_post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InvalidValueError(f"name: got {self.name!r}; expected a non-empty string")
        first = self.measurements[0]
        seen: dict[tuple, int] = {}
        for i, m in enumerate(self.measurements):
            if m.frf.frequency != first.frf.frequency:
                raise FrequencyAxisMismatchError(
                    f"measurements[0] ({first.describe()}) and measurements[{i}] ({m.describe()}) have "
                    f"different frequency axes ({first.frf.frequency!r} and {m.frf.frequency!r}); all "
                    "FRFs of a measurement set must share one grid: interpolate them to a common grid "
                    "(FRF.interpolate) first"
                )
            key = (m.response, m.excitation, m.configuration)
            if key in seen:
                raise InvalidValueError(
                    f"measurements[{seen[key]}] and measurements[{i}] are both {m.response} / "
                    f"{m.excitation} in the configuration {_describe_configuration(m.configuration)}; "
                    "keep one (or average them into one file)"
                )
            seen[key] = i

    @classmethod
    def from_file(cls, path: str | os.PathLike) -> "MeasurementSet":
        """Read a measurement file (:func:`substructure.io.measurements.load_measurements`).

        Parameters
        ----------
        path : str or os.PathLike
            The measurement set file (TOML).

        Returns
        -------
        MeasurementSet
            The measurements.
        """
        from .files import read_measurements

        return read_measurements(cls, path)

    @property
    def frequency(self) -> Frequency:
        """The frequency axis all measurements share."""
        return self.measurements[0].frf.frequency

    def __len__(self) -> int:
        return len(self.measurements)

    def __iter__(self) -> Iterator[Measurement]:
        return iter(self.measurements)

    def _where(self) -> str:
        return f"measurement set {self.name!r}" + ("" if self.source is None else f" ({self.source})")

    def crop(self, lo: Any = None, hi: Any = None) -> "MeasurementSet":
        """The set restricted to ``lo <= f <= hi``; coherences stay aligned with the lines.

        Parameters
        ----------
        lo, hi : float, pint.Quantity, str or None
            Band limits; plain numbers are in Hz; ``None`` leaves that side open.

        Returns
        -------
        MeasurementSet
            Every measurement cropped (:meth:`Measurement.crop`).
        """
        return attrs.evolve(self, measurements=[m.crop(lo, hi) for m in self.measurements])

    def configurations(self) -> tuple[Configuration, ...]:
        """The distinct ``(sensors, removed)`` combinations, in order of first appearance.

        Each is a pair of sorted tuples of names, e.g.
        ``(("accelerometer",), ())`` or ``((), ("tool",))``.

        Returns
        -------
        tuple of tuple
            The configurations.
        """
        return tuple(dict.fromkeys(m.configuration for m in self.measurements))

    def select(self, sensors: Sequence[str] | str = (), removed: Sequence[str] | str = ()) -> tuple[Measurement, ...]:
        """The measurements taken in one configuration (order does not matter); may be empty.

        Parameters
        ----------
        sensors : str or sequence of str
            Sensors on the structure in that configuration.
        removed : str or sequence of str
            Components removed in that configuration.

        Returns
        -------
        tuple of Measurement
            The measurements of the configuration.
        """
        wanted = _configuration_of(sensors, removed)
        return tuple(m for m in self.measurements if m.configuration == wanted)

    def matrix(
        self, points: Sequence[str] | str, sensors: Sequence[str] | str = (),
        removed: Sequence[str] | str = (), reciprocity: bool = True,
    ) -> FRF:
        """The square receptance matrix between the ``y`` DOFs of points, in one configuration.

        Parameters
        ----------
        points : sequence of str
            Point names (``"tool.tip"``; a ``:y`` suffix is accepted, ``:theta``
            is not: rotational terms come from :mod:`substructure.rdof`).
        sensors, removed : sequence of str
            The configuration (see :meth:`configurations`).
        reciprocity : bool, default True
            Entry ``(i, j)`` is the measurement with response ``i`` and
            excitation ``j``.  When it was not measured and this is True, the
            measurement with response ``j`` and excitation ``i`` fills it
            (``H_ij = H_ji``, which the thesis assumes for linear passive
            structures); when both were measured each is used as measured.
            With False every entry must be measured.

        Returns
        -------
        FRF
            Receptances, outputs and inputs ``"POINT:y"`` in the order of ``points``.

        Raises
        ------
        MissingMeasurementError
            Listing every entry that is not measured (with its reciprocal, when
            ``reciprocity`` is True), and the configurations the set holds.
        """
        points = [points] if isinstance(points, str) else items_of(points, "points", "point names")
        if not points:
            raise InvalidValueError("points: got none; expected at least one point name")
        labels = [dof_label(p, f"points[{i}]") for i, p in enumerate(points)]
        for i, (p, label) in enumerate(zip(points, labels)):
            if not label.endswith(":y"):
                raise InvalidValueError(f"points[{i}]: got {p!r}; matrix() is built from translational (y) "
                                        "FRFs, estimate rotational terms with substructure.rdof")
            if label in labels[:i]:
                raise InvalidValueError(f"points[{i}]: {p!r} is given twice")
        configuration = _configuration_of(sensors, removed)
        measured = {(m.response, m.excitation): m for m in self.measurements if m.configuration == configuration}
        n = len(labels)
        data = np.empty((self.frequency.n, n, n), dtype=np.complex128)
        missing: list[tuple[str, str]] = []
        for i, out in enumerate(labels):
            for j, inp in enumerate(labels):
                found = measured.get((out, inp))
                if found is None and reciprocity:
                    found = measured.get((inp, out))
                if found is None:
                    if not (reciprocity and (inp, out) in missing):
                        missing.append((out, inp))
                    continue
                data[:, i, j] = found.values
        if missing:
            either = " (or its reciprocal)" if reciprocity else ""
            lines = [f"response {r} / excitation {e}{either}" for r, e in missing]
            have = "; ".join(_describe_configuration(c) for c in self.configurations())
            raise MissingMeasurementError(
                f"{self._where()}: the receptance matrix of {', '.join(labels)} in the configuration "
                f"{_describe_configuration(configuration)} needs {len(missing)} FRF(s) that are not "
                f"measured: {'; '.join(lines)}. Configurations in the set: {have}",
                missing,
            )
        return FRF(self.frequency, data, labels, labels)

    def validate(self, assembly: Any) -> None:
        """Check the set against an assembly; one error lists every problem.

        Every response and excitation point must exist in the assembly and
        must not lie on a component the measurement lists as removed; every
        sensor must be declared in the assembly (and not sit on a removed
        component); every removed name must be a component of the assembly
        (top level, as :meth:`Assembly.without` needs).

        Parameters
        ----------
        assembly : Assembly
            The model the measurements are of.

        Raises
        ------
        MeasurementSetError
            Listing all problems, each with the index of the measurement and
            the field (``measurements[2].sensors``, or ``frf[2].sensors`` for
            a set read from a file).
        """
        if not hasattr(assembly, "components"):
            raise InvalidValueError(f"assembly: got {type(assembly).__name__}; expected an Assembly")
        problems: list[str] = []
        top_level = {c.name: c for c in assembly.components}
        table = "measurements" if self.source is None else "frf"  # the file's [[frf]] tables
        for k, m in enumerate(self.measurements):
            where = f"{table}[{k}]"
            gone: set[str] = set()
            for name in m.removed:
                if name in top_level:
                    gone |= set(top_level[name].component_names)
                elif name in assembly.component_names:
                    problems.append(f"{where}.removed: {name!r} is inside a subassembly of {assembly.name!r}; "
                                    f"only top-level components can be removed ({', '.join(top_level)})")
                else:
                    problems.append(f"{where}.removed: {name!r} is not a component of {assembly.name!r} "
                                    f"(components: {', '.join(sorted(assembly.component_names)) or 'none'})")
            for field in ("response", "excitation"):
                label = getattr(m, field)
                ref = parse_point(label)
                try:
                    assembly.node_key(ref.point)
                except SubstructureError as exc:
                    problems.append(f"{where}.{field}: {exc}")
                    continue
                if ref.component in gone:
                    problems.append(f"{where}.{field}: {label} is on component {ref.component!r}, which this "
                                    "measurement lists as removed")
            for name in m.sensors:
                try:
                    sensor = assembly.sensor(name)
                except SubstructureError as exc:
                    problems.append(f"{where}.sensors: {exc}")
                    continue
                if parse_point(sensor.at).component in gone:
                    problems.append(f"{where}.sensors: sensor {name!r} sits at {sensor.at}, on a component "
                                    "this measurement lists as removed")
        if problems:
            raise MeasurementSetError(
                f"{self._where()} does not fit assembly {assembly.name!r}: {len(problems)} problem(s):\n  - "
                + "\n  - ".join(problems),
                problems,
            )

    def __repr__(self) -> str:
        return (
            f"MeasurementSet({self.name!r}, {len(self.measurements)} FRFs, "
            f"{len(self.configurations())} configuration(s), {self.frequency!r})"
        )


def model_of_measurement(assembly: Any, measurement: Any) -> Any:
    """The model of the structure as it was measured: removed components off, sensors on.

    The sensors the measurement lists are put on, and those declared
    ``always_on`` (bodies the records do not mention); the assembly's other
    sensors are taken off.  Permanent bodies (``Assembly.masses``) stay.

    Parameters
    ----------
    assembly : Assembly
        The model with every sensor the tests used declared.
    measurement : Measurement or object with ``sensors`` and ``removed``
        The test (an FRF without them stands for the assembly as given, with
        its ``always_on`` sensors only).

    Returns
    -------
    Assembly
        The configured model.
    """
    removed = tuple(getattr(measurement, "removed", ()) or ())
    listed = tuple(getattr(measurement, "sensors", ()) or ())
    model = assembly.without(*removed) if removed else assembly
    kept = {s.name for s in model.sensors}
    on = [assembly.sensor(name) for name in listed]
    on += [s for s in assembly.sensors if getattr(s, "always_on", False) and s.name not in listed and s.name in kept]
    return model.without_sensors().attach(*on)
