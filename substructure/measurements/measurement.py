"""One measurement: :class:`Measurement` (a measured FRF and the configuration it was taken in), :func:`dof_label`.

The errors of measurement sets (:class:`MeasurementSetError`, :class:`MissingMeasurementError`) are
here too; :class:`~substructure.measurements.MeasurementSet` is in ``measurement_set``.
"""

from __future__ import annotations

from typing import Any, Sequence

import attrs
import numpy as np

from ..errors import InvalidValueError, SubstructureError, UnknownPointError
from ..frf import FRF
from ..frf._fields import _check_quantity, window_tau
from ..points import check_name, parse_point
from ..tap import ESTIMATORS
from ..units import finite_real

__all__ = ["Measurement", "MeasurementSetError", "MissingMeasurementError", "dof_label", "Configuration"]

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


def _optional_int(field: str, minimum: int, expected: str):
    def convert(value: Any) -> int | None:
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
            raise InvalidValueError(f"{field}: got {value!r}; expected {expected}")
        return int(value)

    return convert


_optional_record = _optional_int("record", 0, "a 0-based record index (an integer >= 0)")
_optional_averages = _optional_int("averages", 1, "the number of averages (an integer >= 1)")


COHERENCE_ROUNDING = 1e-9
"""How far above 1 a coherence may lie and be read as 1 (rounding of its estimate)."""


def _optional_seconds(field: str, expected: str):
    def convert(value: Any) -> float | None:
        if value is None:
            return None
        if not finite_real(value) or value <= 0:
            raise InvalidValueError(f"{field}: got {value!r}; expected {expected}")
        return float(value)

    return convert


def _optional_tau(value: Any) -> float | None:
    return None if value is None else window_tau(value)


_optional_force_window = _optional_seconds("force_window_s", "the force window's length in s (a finite number > 0), "
                                                             "or None")


def _per_line(name: str, values: str, each: str, bad, top: float | None = None):
    """A converter of an optional array of one value per frequency line, read-only.

    ``bad`` marks the values refused (``values`` and ``each`` say what is wanted of the array and of a value);
    ``top`` clips the rest from above.
    """

    def convert(value: Any) -> np.ndarray | None:
        if value is None:
            return None
        try:
            array = np.array(value, dtype=np.float64)
        except (TypeError, ValueError, OverflowError):
            raise InvalidValueError(f"{name}: got {type(value).__name__}; expected an array of {values}") from None
        if array.ndim != 1:
            raise InvalidValueError(f"{name}: got shape {array.shape}; expected one value per frequency line")
        refused = bad(array)
        if refused.any():
            k = int(np.argmax(refused))
            raise InvalidValueError(f"{name}: line {k} is {float(array[k])!r}; expected {each}")
        if top is not None:
            array = np.minimum(array, top)
        array.setflags(write=False)
        return array

    return convert


_coherence = _per_line("coherence", "floats in [0, 1]", "a number in [0, 1]",
                       lambda a: ~np.isfinite(a) | (a < 0.0) | (a > 1.0 + COHERENCE_ROUNDING), top=1.0)
_force_noise = _per_line("force_noise", "variances >= 0", "a variance >= 0 (inf where there was no force)",
                         lambda a: ~(a >= 0.0))
_truncation = _per_line("truncation", "variances >= 0", "a variance >= 0 (inf where the FRF is zero)",
                        lambda a: ~(a >= 0.0))


def _estimator(value: Any) -> str | None:
    if value is not None and (not isinstance(value, str) or value not in ESTIMATORS):
        raise InvalidValueError(f"estimator: got {value!r}; expected one of {', '.join(ESTIMATORS)}, or None when "
                                "not known")
    return value


def _same_array(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is b
    return bool(np.array_equal(a, b))


def _check_lines(instance: "Measurement", attribute: Any, value: np.ndarray | None) -> None:
    if value is not None and value.shape[0] != instance.frf.frequency.n:
        raise InvalidValueError(
            f"{attribute.name}: got {value.shape[0]} values for {instance.frf.frequency.n} frequency lines; expected "
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


def _describe_configuration(configuration: Configuration) -> str:
    sensors, removed = configuration
    return f"sensors=[{', '.join(sensors)}], removed=[{', '.join(removed)}]"


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
    window_tau : float, optional
        The time constant [s] of the exponential window the taps were
        measured through (None: no window).  The window adds the damping
        ratio ``1 / (tau omega)`` to every measured mode, which no model
        has: the diagnosis says so in its report.
    force_noise : array of float, optional
        Per line, the variance of H1's relative error from the hammer's
        noise (``substructure.tap.TapResult.force_noise``; >= 0, ``inf``
        where there was no force); read-only.  With ``force_window_s`` the
        noise model counts it as the smooth error it is.
    force_window_s : float, optional
        The force window's effective length [s]: the hammer's noise in H1 is
        correlated over about ``1 / force_window_s`` hertz.
    estimator : {"H1", "H2", "Hv"}, optional
        How the FRF was estimated from the taps (None: not known).  An H2
        estimate exceeds the FRF by the factor ``1 / gamma^2`` where the
        response's noise is large; with its coherence it is compared as H1
        (:attr:`h1_frf`).
    truncation : array of float, optional
        Per line, the variance of the FRF's relative error that the end of
        the taps leaves where the response still rang there, counted over
        the lines it spans (``substructure.tap.TapResult.truncation``; >= 0,
        ``inf`` allowed); read-only.  The noise model adds it.
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
        default=None, converter=_coherence, validator=_check_lines, eq=attrs.cmp_using(eq=_same_array)
    )
    averages: int | None = attrs.field(default=None, converter=_optional_averages)
    window_tau: float | None = attrs.field(default=None, converter=_optional_tau)
    force_noise: np.ndarray | None = attrs.field(
        default=None, converter=_force_noise, validator=_check_lines, eq=attrs.cmp_using(eq=_same_array)
    )
    force_window_s: float | None = attrs.field(default=None, converter=_optional_force_window)
    estimator: str | None = attrs.field(default=None, converter=_estimator)
    truncation: np.ndarray | None = attrs.field(
        default=None, converter=_truncation, validator=_check_lines, eq=attrs.cmp_using(eq=_same_array)
    )

    @force_window_s.validator
    def _check_force_window(self, attribute: Any, value: float | None) -> None:
        if self.force_noise is not None and value is None:
            raise InvalidValueError("force_window_s: needed with force_noise (the force window's length in s, over "
                                    "whose inverse the hammer's noise is correlated)")

    @classmethod
    def from_frf(
        cls, frf: FRF, response: str, excitation: str, *, sensors: Sequence[str] = (),
        removed: Sequence[str] = (), file: str | None = None, record: int | None = None,
        coherence: Any = None, averages: int | None = None, window_tau: float | None = None,
        force_noise: Any = None, force_window_s: float | None = None, estimator: str | None = None,
        truncation: Any = None,
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
        window_tau : float, optional
            The exponential window's time constant [s], when there was one.
        force_noise : array of float, optional
            The hammer's noise in H1 per line (a variance, >= 0).
        force_window_s : float, optional
            The force window's effective length [s].
        estimator : {"H1", "H2", "Hv"}, optional
            How the FRF was estimated from the taps.
        truncation : array of float, optional
            The error the taps' end leaves, per line (a variance, >= 0).

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
        tau = _optional_tau(window_tau)  # a windowed FRF's receptance: at omega - i/tau, as the window saw it
        receptance = frf.with_labels((out,), (inp,)).to_receptance(1.0 / tau if tau else 0.0)
        return cls(out, inp, receptance, frf.quantity, sensors, removed, file, record, coherence, averages,
                   window_tau, force_noise, force_window_s, estimator, truncation)

    def crop(self, lo: Any = None, hi: Any = None) -> "Measurement":
        """The measurement restricted to ``lo <= f <= hi``, its per-line arrays (coherence, noise) on the same lines.

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
        lines = {name: None if getattr(self, name) is None else getattr(self, name)[mask]
                 for name in ("coherence", "force_noise", "truncation")}
        return attrs.evolve(self, frf=self.frf.crop(lo, hi), **lines)

    def through_window(self, tau: Any) -> "Measurement":
        """The same measurement read as through the exponential window ``exp(-t/tau)``, which it did not declare.

        What :meth:`from_frf` would have made with ``window_tau=tau``: a
        mobility or accelerance is divided again by the complex frequency
        ``omega - i/tau`` the window saw (a receptance is the same lines).

        Parameters
        ----------
        tau : float
            The window's time constant [s].

        Returns
        -------
        Measurement
            The measurement with ``window_tau`` set.

        Raises
        ------
        InvalidValueError
            For a measurement that declares a window already (its own is kept) or a bad ``tau``.
        """
        if self.window_tau is not None:
            raise InvalidValueError(f"window_tau: {self.describe()} was measured through a window of "
                                    f"{self.window_tau!r} s already; expected a measurement that declares none")
        tau = window_tau(tau)
        unit = attrs.evolve(self.frf, data=np.ones_like(self.frf.data), quantity=self.quantity)
        ratio = unit.to_receptance(1.0 / tau).data / unit.to_receptance().data  # 1 for a receptance
        return attrs.evolve(self, frf=attrs.evolve(self.frf, data=self.frf.data * ratio), window_tau=tau)

    @property
    def configuration(self) -> Configuration:
        """``(sensors, removed)``, each sorted: what identifies the tested configuration."""
        return tuple(sorted(self.sensors)), tuple(sorted(self.removed))

    @property
    def h1_frf(self) -> FRF:
        """The FRF as H1 where it can be had: for an H2 estimate with its coherence, ``gamma^2 H2``.

        H1 = Gfx / Gff and H2 = Gxx / Gxf of one set of spectra differ by their
        coherence, ``H1 = gamma^2 H2`` exactly, so this is the H1 of the same
        taps: free of H2's bias ``1 / gamma^2`` from the response's noise
        (large where the coherence is low), with H1's own error from the
        hammer's noise (``force_noise``).  Any other FRF (H1, Hv, an estimator
        not stated, an H2 without its coherence) is returned as it is.  The
        fits and the diagnosis compare this FRF with the model.
        """
        if self.estimator != "H2" or self.coherence is None:
            return self.frf
        return attrs.evolve(self.frf, data=self.frf.data * self.coherence[:, None, None])

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
