"""Measurement sets: which measured FRFs exist, where they were taken, on what configuration.

A :class:`Measurement` is one measured FRF (a tap test: the response at one
DOF to a force at another) together with the configuration of the structure
during the test: the sensors that were on it and the components that were
taken off.  A :class:`MeasurementSet` gathers the measurements of one test
campaign on one frequency axis, builds the translational receptance matrices
that identification needs (:meth:`MeasurementSet.matrix`, using reciprocity
only when asked to) and checks itself against an assembly
(:meth:`MeasurementSet.validate`).  Both are frozen value objects; files in
the format of docs/file-formats.md ("Measurement set (TOML)") are read by
:mod:`substructure.io.measurements`.
"""

from __future__ import annotations

import os
from typing import Any, Iterator, Sequence

import attrs
import numpy as np

from .errors import FrequencyAxisMismatchError, InvalidValueError, SubstructureError, UnknownPointError
from .frf import FRF, QUANTITIES, Frequency
from .points import check_name, parse_point

__all__ = ["Measurement", "MeasurementSet", "MeasurementSetError", "MissingMeasurementError", "dof_label",
           "model_of_measurement"]

Configuration = tuple[tuple[str, ...], tuple[str, ...]]


class MeasurementSetError(SubstructureError, ValueError):
    """A measurement set does not fit an assembly, or lacks what a computation needs.

    Parameters
    ----------
    message : str
        The message (it lists every problem).
    problems : sequence of str
        One line per problem found; kept as the attribute ``problems``.
    """

    def __init__(self, message: str, problems: Sequence[str] = ()):
        super().__init__(message)
        self.problems = tuple(problems)


class MissingMeasurementError(MeasurementSetError):
    """FRFs needed for a receptance matrix are not in the measurement set.

    Parameters
    ----------
    message : str
        The message.
    missing : sequence of (str, str)
        The ``(response, excitation)`` DOF labels that are missing; kept as the
        attribute ``missing``.
    """

    def __init__(self, message: str, missing: Sequence[tuple[str, str]] = ()):
        super().__init__(message, [f"{r} / {e}" for r, e in missing])
        self.missing = tuple(missing)


def dof_label(point: Any, field: str = "point") -> str:
    """The canonical DOF label of a point name, ``:y`` by default.

    ``"tool.tip"`` gives ``"tool.tip:y"``, ``"tool@30mm:theta"`` gives
    ``"tool@30 mm:theta"`` (the spelling :class:`~substructure.assembly.Assembly`
    uses in its labels).

    Parameters
    ----------
    point : str
        A point name, with or without a DOF suffix.
    field : str
        Name of the argument, for error messages.

    Returns
    -------
    str
        The DOF label.

    Raises
    ------
    UnknownPointError
        When ``point`` is not a point name; the message starts with ``field``.
    """
    try:
        ref = parse_point(point)
    except UnknownPointError as exc:
        raise UnknownPointError(f"{field}: {exc}") from None
    return f"{ref.point}:{ref.dof or 'y'}"


def _names(field: str):
    def convert(value: Any) -> tuple[str, ...]:
        if value is None:
            return ()
        if isinstance(value, str):
            value = (value,)
        try:
            names = tuple(value)
        except TypeError:
            raise InvalidValueError(f"{field}: got {value!r}; expected a sequence of names") from None
        for i, name in enumerate(names):
            check_name(name, f"{field}[{i}]")
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise InvalidValueError(f"{field}: {', '.join(map(repr, twice))} given more than once")
        return names

    return convert


def _optional_record(value: Any) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise InvalidValueError(f"record: got {value!r}; expected a 0-based record index (an integer >= 0)")
    return int(value)


def _check_quantity(instance: Any, attribute: Any, value: Any) -> None:
    if value not in QUANTITIES:
        raise InvalidValueError(f"quantity: got {value!r}; expected one of {', '.join(QUANTITIES)}")


def _coherence(value: Any) -> np.ndarray | None:
    if value is None:
        return None
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidValueError(
            f"coherence: got {type(value).__name__}; expected an array of floats in [0, 1]"
        ) from None
    if array.ndim != 1:
        raise InvalidValueError(f"coherence: got shape {array.shape}; expected one value per frequency line")
    bad = ~np.isfinite(array) | (array < 0.0) | (array > 1.0 + COHERENCE_ROUNDING)
    if bad.any():
        k = int(np.argmax(bad))
        raise InvalidValueError(f"coherence: line {k} is {float(array[k])!r}; expected a number in [0, 1]")
    array = np.minimum(array, 1.0)
    array.setflags(write=False)
    return array


COHERENCE_ROUNDING = 1e-9
"""How far above 1 a coherence may lie and be read as 1 (rounding of its estimate)."""


def _optional_averages(value: Any) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InvalidValueError(f"averages: got {value!r}; expected the number of averages (an integer >= 1)")
    return int(value)


def _same_array(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is b
    return bool(np.array_equal(a, b))


def _check_coherence(instance: "Measurement", attribute: Any, value: np.ndarray | None) -> None:
    if value is not None and value.shape[0] != instance.frf.frequency.n:
        raise InvalidValueError(
            f"coherence: got {value.shape[0]} values for {instance.frf.frequency.n} frequency lines; expected "
            "one per line of the FRF"
        )


def _check_frf(instance: "Measurement", attribute: Any, frf: Any) -> None:
    hint = "; build it with Measurement.from_frf(frf, response, excitation)"
    if not isinstance(frf, FRF):
        raise InvalidValueError(f"frf: got {type(frf).__name__}; expected an FRF{hint}")
    if frf.shape[1:] != (1, 1):
        raise InvalidValueError(f"frf: got {frf.shape[1]}x{frf.shape[2]} entries; expected one FRF (1x1){hint}")
    if frf.quantity != "receptance":
        raise InvalidValueError(f"frf: got a {frf.quantity}; expected a receptance (FRF.to_receptance){hint}")
    if frf.outputs != (instance.response,) or frf.inputs != (instance.excitation,):
        raise InvalidValueError(
            f"frf: labels {frf.outputs[0]!r} / {frf.inputs[0]!r} differ from response "
            f"{instance.response!r} / excitation {instance.excitation!r}{hint}"
        )


@attrs.frozen(repr=False)
class Measurement:
    """One measured FRF and the configuration of the structure during the test.

    Parameters
    ----------
    response, excitation : str
        Point names with an optional DOF (``"tool.tip"``, ``"tool.tip-5 mm:y"``);
        stored as canonical DOF labels, ``:y`` by default (``"tool.tip:y"``).
    frf : FRF
        One receptance (1x1) whose labels are ``response`` and ``excitation``.
        :meth:`from_frf` relabels and converts any FRF.
    quantity : {"receptance", "mobility", "accelerance"}
        What the data were before conversion to receptance (as measured).
    sensors : sequence of str
        Names of the sensors (declared in the assembly) on the structure
        during this test.
    removed : sequence of str
        Names of the components taken off the assembly for this test.
    file : str, optional
        The data file as written in the measurement file.
    record : int, optional
        The 0-based index of the type-58 record, for universal files.
    coherence : array of float, optional
        The ordinary coherence of the estimate (dimensionless, in [0, 1]),
        one value per line of ``frf`` (a tap test's, see
        :mod:`substructure.tap`); read-only.
    averages : int, optional
        The number of taps averaged into the FRF (>= 1).
    """

    response: str = attrs.field(converter=lambda value: dof_label(value, "response"))
    excitation: str = attrs.field(converter=lambda value: dof_label(value, "excitation"))
    frf: FRF = attrs.field(validator=_check_frf)
    quantity: str = attrs.field(default="receptance", validator=_check_quantity)
    sensors: tuple[str, ...] = attrs.field(default=(), converter=_names("sensors"))
    removed: tuple[str, ...] = attrs.field(default=(), converter=_names("removed"))
    file: str | None = attrs.field(default=None)
    record: int | None = attrs.field(default=None, converter=_optional_record)
    coherence: np.ndarray | None = attrs.field(
        default=None, converter=_coherence, validator=_check_coherence, eq=attrs.cmp_using(eq=_same_array)
    )
    averages: int | None = attrs.field(default=None, converter=_optional_averages)

    @classmethod
    def from_frf(
        cls, frf: FRF, response: str, excitation: str, *, sensors: Sequence[str] = (),
        removed: Sequence[str] = (), file: str | None = None, record: int | None = None,
        coherence: Any = None, averages: int | None = None,
    ) -> "Measurement":
        """A measurement from a one-entry FRF of any quantity.

        The FRF is relabelled with the canonical labels of ``response`` and
        ``excitation`` and converted to receptance; its quantity is kept in
        ``quantity``.

        Parameters
        ----------
        frf : FRF
            One entry: a receptance (m/N), mobility (m/(N s)) or accelerance (m/(N s^2)).
        response : str
            The response point, e.g. ``"tool.tip"`` (``:y`` by default).
        excitation : str
            The excitation point.
        sensors : sequence of str
            Sensors on the structure during the test (names declared in the assembly).
        removed : sequence of str
            Components absent during the test.
        file : str, optional
            The file the FRF came from, for messages.
        record : int, optional
            Its record in a universal file.
        coherence : array of float, optional
            The coherence (dimensionless, in [0, 1]) on the FRF's lines.
        averages : int, optional
            The number of averages (>= 1).

        Returns
        -------
        Measurement
            The measurement, its FRF a receptance in m/N.
        """
        if not isinstance(frf, FRF):
            raise InvalidValueError(f"frf: got {type(frf).__name__}; expected an FRF")
        out, inp = dof_label(response, "response"), dof_label(excitation, "excitation")
        if frf.shape[1:] != (1, 1):
            raise InvalidValueError(
                f"frf: got {frf.shape[1]}x{frf.shape[2]} entries; expected one FRF (select one entry first)"
            )
        receptance = frf.with_labels((out,), (inp,)).to_receptance()
        return cls(out, inp, receptance, frf.quantity, sensors, removed, file, record, coherence, averages)

    def crop(self, lo: Any = None, hi: Any = None) -> "Measurement":
        """The measurement restricted to ``lo <= f <= hi``, its coherence on the same lines.

        Parameters
        ----------
        lo, hi : float, pint.Quantity, str or None
            Band limits; plain numbers are in Hz; ``None`` leaves that side open.

        Returns
        -------
        Measurement
            The lines of the band (an empty band is an error).
        """
        mask = self.frf.frequency.band_mask(lo, hi)
        coherence = None if self.coherence is None else self.coherence[mask]
        return attrs.evolve(self, frf=self.frf.crop(lo, hi), coherence=coherence)

    @property
    def configuration(self) -> Configuration:
        """``(sensors, removed)``, each sorted: what identifies the tested configuration."""
        return tuple(sorted(self.sensors)), tuple(sorted(self.removed))

    @property
    def values(self) -> np.ndarray:
        """The receptance as a 1-D complex array (read-only)."""
        return self.frf.data[:, 0, 0]

    def describe(self) -> str:
        """``response / excitation`` and, when known, the file: for messages.

        Returns
        -------
        str
            The description.
        """
        where = "" if self.file is None else f" ({self.file}{'' if self.record is None else f', record {self.record}'})"
        return f"{self.response} / {self.excitation}{where}"

    def __repr__(self) -> str:
        config = _describe_configuration(self.configuration)
        return f"Measurement({self.describe()}, {self.quantity}, {config}, {self.frf.frequency!r})"


def _describe_configuration(configuration: Configuration) -> str:
    sensors, removed = configuration
    return f"sensors=[{', '.join(sensors)}], removed=[{', '.join(removed)}]"


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
        from .io.measurements import load_measurements

        return load_measurements(path)

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
        points = [points] if isinstance(points, str) else list(points)
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
