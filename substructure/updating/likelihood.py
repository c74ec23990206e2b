"""The likelihood of a model given measured FRFs: whitened complex log ratios.

For measured FRFs ``H_j`` with the per-line noise of
:mod:`substructure.updating.noise` and a model ``M_j(theta)`` of the same
entries, the residual of line ``k`` of FRF ``j`` is
``r_jk = ln(M_jk / H_jk)`` and, the noise being Gaussian in ``ln H`` with
variances ``v_re,jk`` and ``v_im,jk``,

``-2 ln L(theta) = chi^2(theta) + const,
chi^2 = sum_jk [ Re(r_jk)^2 / v_re,jk + Im(r_jk)^2 / v_im,jk ]``.

:class:`Likelihood` evaluates the whitened residual vector (whose sum of
squares is ``chi^2``) for a model given as the assembly plus a list of
changes (:class:`~substructure.updating.parameters.Change` with values),
each measured FRF in its own configuration (sensors on, components off, as
its measurement says).  Every configuration is evaluated once per model on
the SI form of the structure; changes that have an SI form are applied
there, others (registered effects without one) on the assembly.
"""

from __future__ import annotations

import hashlib

from collections import OrderedDict
from typing import Sequence

import attrs
import numpy as np

from ..errors import FrequencyAxisMismatchError, InvalidValueError, UnknownPointError
from .._memo import Same
from ..frf import FRF, REVERSED_SHARE, reversed_share
from ..measurements import model_of_measurement
from ..units import whole_number
from .noise import NoiseModel, estimate_noise
from .parameters import Change
from .quantity import quantity_error, quantity_signature
from .evaluator import Evaluator
from .structure import Structure

__all__ = ["Measured", "Likelihood", "measured_frfs", "calibration_checked", "CALIBRATION_HINT", "LOG_RATIO_PENALTY"]

SIGN_ERROR_FACTOR = 4.0
"""How many times smaller a driving point's phase error must be negated or conjugated to call it so."""
LOG_RATIO_PENALTY = 10.0
"""The log ratio used where a model value is zero or not finite [-]."""

APPLIED_KEPT = 16
"""Structures with changes applied kept per configuration from recent evaluations (by the changes and their
values, in order): the changes already added are applied once per scan, not once per trial."""


@attrs.frozen
class Measured:
    """One measured FRF entry with its noise and its test configuration.

    Parameters
    ----------
    label : str
        ``"response / excitation"``, for messages.
    frf : FRF
        The receptance (one entry), on the band analysed.
    noise : NoiseModel
        Its per-line noise.
    measurement : object
        The measurement (with ``sensors`` and ``removed``) or the FRF itself.
    """

    label: str
    frf: FRF = attrs.field(eq=False)
    noise: NoiseModel = attrs.field(eq=False)
    measurement: object = attrs.field(eq=False)

    @property
    def configuration(self) -> tuple:
        """``(sensors, removed)`` sorted: measurements alike share one evaluation."""
        return (tuple(sorted(getattr(self.measurement, "sensors", ()) or ())),
                tuple(sorted(getattr(self.measurement, "removed", ()) or ())))


def _no_copies(items: list) -> None:
    """Refuse one record given as two measurements (a file copied under another name): the same numbers on every
    line, which two taps never give, would be weighed twice and fitted at two places.  A reciprocal pair of an
    exact simulation (``H_ab`` and ``H_ba``) may be equal and stays."""
    seen: dict[bytes, tuple] = {}
    for m, frf in items:
        digest = hashlib.sha256(np.ascontiguousarray(frf.data).tobytes()).digest()
        if digest in seen and seen[digest][0] is not m:
            first, other = seen[digest]
            if (other.outputs, other.inputs) != (frf.inputs, frf.outputs):
                def name(x, f):
                    return x.describe() if hasattr(x, "describe") else f"{f.outputs[0]} / {f.inputs[0]}"
                raise InvalidValueError(
                    f"measurements: {name(first, other)} and {name(m, frf)} hold the same numbers on every line: one "
                    "record given twice (a file copied under another name?); two taps never give the same record "
                    "to the last digit: keep the right one")
        seen.setdefault(digest, (m, frf))


def measured_frfs(measurements, band=None) -> tuple[list[Measured], tuple[float, float]]:
    """Measured FRFs (one entry each) cropped to a band, with their noise estimated on the whole record.

    Parameters
    ----------
    measurements : MeasurementSet, or sequence of measurements or FRFs
        The data; an FRF with several entries counts as one per entry.
    band : (float, float), optional
        Lines ``lo <= f <= hi`` [Hz]; default all.

    Returns
    -------
    (list of Measured, (lo, hi))
        The data and the band used.

    Raises
    ------
    InvalidValueError
        For no data, a band not within the data (saying which part is
        outside), fewer than 10 lines in the band, or an FRF that is zero on
        every line (named).
    FrequencyAxisMismatchError
        For FRFs on different frequency lines in the band (taps of different
        lengths or sample rates), naming two of them.
    """
    if isinstance(measurements, FRF):  # one FRF is one measurement (iterated, it was read as FRF[0])
        measurements = [measurements]
    items = []
    for m in measurements:
        # an H2 with its coherence is compared as the H1 of the same taps (Measurement.h1_frf)
        frf = m if isinstance(m, FRF) else getattr(m, "h1_frf", getattr(m, "frf", None))
        if not isinstance(frf, FRF):
            raise InvalidValueError(f"measurements: got {m!r}; expected FRFs or measurements")
        frf = frf.to_receptance()
        for i, out in enumerate(frf.outputs):
            for j, inp in enumerate(frf.inputs):
                items.append((m, frf.select([out], [inp]) if frf.shape[1:] != (1, 1) else frf))
    if not items:
        raise InvalidValueError("measurements: got none")
    _no_copies(items)
    f0 = items[0][1].frequency
    full = (float(f0.hz[0]), float(f0.hz[-1]))
    try:
        if isinstance(band, (str, bytes)):  # '100-200' unpacked to its characters, or a raw error
            raise TypeError
        lo, hi = full if band is None else band
        if any(isinstance(x, (str, bytes, bool, np.bool_)) for x in (lo, hi)):
            raise TypeError
        lo, hi = float(lo), float(hi)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(f"band: got {band!r}; expected (lo, hi) in Hz") from None
    if not lo < hi:
        raise InvalidValueError(f"band: got {lo:g}-{hi:g} Hz; expected lo < hi")
    tol = 1e-9 * max(abs(full[1]), 1.0)
    if hi < full[0] or lo > full[1]:
        raise InvalidValueError(f"band: {lo:g}-{hi:g} Hz is outside the measured data ({full[0]:g}-{full[1]:g} Hz)")
    if lo < full[0] - tol or hi > full[1] + tol:
        part = (f"starts at {lo:g} Hz, below the first measured line ({full[0]:g} Hz)" if lo < full[0] - tol
                else f"ends at {hi:g} Hz, above the last measured line ({full[1]:g} Hz)")
        raise InvalidValueError(f"band: {lo:g}-{hi:g} Hz {part}; the data cover {full[0]:g}-{full[1]:g} Hz: "
                                "give a band within them")
    out = []
    for m, frf in items:
        label = f"{frf.outputs[0]} / {frf.inputs[0]}"
        h = frf.data[:, 0, 0]
        where = getattr(m, "describe", lambda: label)()
        if not np.any(np.isfinite(h) & (np.abs(h) > 0)):
            raise InvalidValueError(f"measured FRF {where}: zero (or not finite) on every line: a dead channel? "
                                    "Leave it out of the measurement set")
        noise = estimate_noise(frf, coherence=getattr(m, "coherence", None), averages=getattr(m, "averages", None),
                               force_noise=getattr(m, "force_noise", None),
                               force_window_s=getattr(m, "force_window_s", None),
                               estimator=getattr(m, "estimator", None),
                               truncation=getattr(m, "truncation", None),
                               window_tau=getattr(m, "window_tau", None))
        mask = frf.frequency.band_mask(lo, hi)
        if mask.sum() < 10:
            raise InvalidValueError(f"band: {lo:g}-{hi:g} Hz holds {int(mask.sum())} lines of {label}; "
                                    "at least 10 are needed")
        held = int(np.sum(mask & np.isfinite(h) & (h != 0)))
        if held < 10:
            raise InvalidValueError(f"measured FRF {where}: {held} of its {int(mask.sum())} lines in the band "
                                    f"{lo:g}-{hi:g} Hz hold a value (the others are zero or not finite); at least "
                                    "10 are needed")
        out.append(Measured(label, frf.crop(lo, hi), noise.select(mask), m))
    first = out[0].frf.frequency.hz
    for item in out[1:]:  # one set of lines for all: the fits compare every FRF line by line
        hz = item.frf.frequency.hz
        if hz.size != first.size or not np.allclose(hz, first, rtol=1e-9, atol=0.0):
            where = [getattr(x.measurement, "describe", lambda x=x: x.label)() for x in (out[0], item)]
            raise FrequencyAxisMismatchError(
                f"measured FRFs {where[0]} and {where[1]} are on different frequency lines in the band "
                f"{lo:g}-{hi:g} Hz ({first.size} lines every {_step(first)} Hz against {hz.size} every "
                f"{_step(hz)} Hz): taps of different lengths or sample rates give different lines; compare each "
                "such set on its own, or take the taps with one length and rate")
    return out, (lo, hi)


def _step(hz: np.ndarray) -> str:
    return f"{float(np.median(np.diff(hz))):.4g}" if hz.size > 1 else "-"


def _has_si(change) -> bool:
    return type(change).apply_si is not Change.apply_si


class _Group:
    """The measured FRFs of one configuration (and one exponential window): one evaluation gives all of them.

    FRFs measured through an exponential window ``exp(-t/tau)`` are compared
    with the model at the complex frequency ``omega - i/tau`` (the windowed
    FRF is exactly that, whatever the force's shape): the window's damping is
    in the model as in the data.  Where a component or joint model cannot be
    evaluated there (``not_windowed`` names it), the model is evaluated on
    the real lines and the window's damping is left in the data alone.
    """

    def __init__(self, assembly, items: list[tuple[int, Measured]], lines: np.ndarray):
        first = items[0][1]
        self.indices = [i for i, _ in items]
        self.assembly = model_of_measurement(assembly, first.measurement)
        self.structure = Structure.from_assembly(self.assembly)
        outputs = list(dict.fromkeys(m.frf.outputs[0] for _, m in items))
        inputs = list(dict.fromkeys(m.frf.inputs[0] for _, m in items))
        self.entries = [(outputs.index(m.frf.outputs[0]), inputs.index(m.frf.inputs[0])) for _, m in items]
        tau = getattr(first.measurement, "window_tau", None)
        self.not_windowed = self.structure.not_at_complex_frequency() if tau else []
        self.window_tau = None if self.not_windowed else tau
        self.evaluator = Evaluator(outputs, inputs, first.frf.frequency.hz[lines],
                                   decay=1.0 / self.window_tau if self.window_tau else 0.0)
        self._applied: OrderedDict = OrderedDict()

    def structure_with(self, changes: Sequence[tuple]) -> Structure:
        if all(_has_si(c) for c, _ in changes):
            s = self.structure
            key: tuple | None = ()
            for change, values in changes:
                # the structure after the same changes with the same values is kept from a recent evaluation:
                # the changes already added, held during a scan (its beams keep their receptances' token)
                found = None
                if key is not None:
                    key += ((Same(change), tuple(sorted(values.items()))),)
                    try:
                        found = self._applied.get(key)
                    except TypeError:  # values that are not plain numbers: these changes applied every time
                        key = None
                if found is not None:
                    self._applied.move_to_end(key)
                    s = found
                    continue
                try:
                    s = change.apply_si(s, values)
                except UnknownPointError:  # no place for it in this configuration
                    pass
                if key is not None:
                    self._applied[key] = s
                    while len(self._applied) > APPLIED_KEPT:
                        self._applied.popitem(last=False)
            return s
        a = self.assembly
        for change, values in changes:
            try:
                a = change.apply(a, values)
            except UnknownPointError:
                continue
        return Structure.from_assembly(a, like=self.structure)

    def predict(self, changes) -> list[np.ndarray]:
        y = self.evaluator(self.structure_with(changes))
        return [y[:, i, j] for i, j in self.entries]

    def predict_many(self, lists) -> list[list[np.ndarray]]:
        ys = self.evaluator.many([self.structure_with(changes) for changes in lists])
        return [[y[:, i, j] for i, j in self.entries] for y in ys]


def _line_indices(lines, n: int) -> np.ndarray:
    """``lines`` checked as indices of distinct lines of the data, increasing (a negative index counted from the
    end, a line twice weighed twice, a boolean mask read as the lines 0 and 1: each silently wrong)."""
    idx = np.asarray(lines)
    if idx.ndim != 1 or idx.size == 0 or idx.dtype.kind not in "iu":
        raise InvalidValueError(f"lines: got {_short(lines)}; expected a 1-D array of line indices (whole numbers)")
    if idx.min() < 0 or idx.max() >= n or np.any(np.diff(idx) <= 0):
        raise InvalidValueError(f"lines: got {_short(lines)}; expected increasing, distinct indices from 0 to {n - 1}")
    return idx


def _short(values) -> str:
    text = " ".join(repr(values).split())
    return text if len(text) <= 80 else text[:77] + "..."


CALIBRATION_HINT = (0.01, 0.25)
"""The data's level off by this much (the lower number to the upper, relatively) is worth the calibration
uncertainty: a diagnosis or an identification made without one then suggests giving it
(``DiagnoseSettings.calibration_hint``, :class:`~substructure.identify.JointIdentifier`'s note); beyond the upper
number it is no calibration but a unit error."""


def calibration_checked(calibration) -> float | None:
    """``calibration`` as a float, or None; refused unless a relative uncertainty in (0, 1).

    Parameters
    ----------
    calibration : float or None
        The relative uncertainty of the measured FRFs' common scale (see :class:`Likelihood`).

    Returns
    -------
    float or None
        The uncertainty.
    """
    if calibration is not None and not (isinstance(calibration, (int, float)) and not isinstance(
            calibration, bool) and 0.0 < calibration < 1.0):
        raise InvalidValueError(f"calibration: got {calibration!r}; expected the relative uncertainty of the "
                                "FRFs' scale, a number in (0, 1), e.g. 0.05, or None")
    return None if calibration is None else float(calibration)


class Likelihood:
    """``chi^2`` of models (the assembly with changes) against measured FRFs.

    Parameters
    ----------
    assembly : Assembly
        The model as given (sensors declared; each measurement's
        configuration is set from it).
    measured : sequence of Measured
        The data (:func:`measured_frfs`).
    lines : ndarray of int, optional
        Indices of the lines to use (default all): a subsample for screening.
    calibration : float, optional
        The relative uncertainty of the measured FRFs' common scale (the
        hammer's and the sensors' sensitivities), e.g. 0.05.  With it every
        model's log ratios are compared after the common level that fits them
        best (the mean of ``ln |model / measured|`` weighed by the noise),
        within ``ln(1 + calibration)`` either way: one more fitted number,
        profiled out of every evaluation (:meth:`level`).  None (default): the
        data's scale is taken as exact.

    Attributes
    ----------
    alive : list of ndarray of bool
        Per measured FRF, on ``lines``: the lines it holds a value on (not
        zero, finite) that were measured (``NoiseModel.held``: not
        interpolated between measured lines).  The others are left out of
        every comparison.
    """

    def __init__(self, assembly, measured: Sequence[Measured], lines: np.ndarray | None = None,
                 calibration: float | None = None):
        self.calibration = calibration_checked(calibration)
        self.assembly = assembly
        self.measured = list(measured)
        if not self.measured or not all(isinstance(m, Measured) for m in self.measured):
            raise InvalidValueError(f"measured: got {measured!r}; expected at least one Measured (from "
                                    "measured_frfs)")
        n = self.measured[0].frf.frequency.n
        self.lines = np.arange(n) if lines is None else _line_indices(lines, n)
        groups: dict[tuple, list] = {}
        for i, m in enumerate(self.measured):
            groups.setdefault((m.configuration, getattr(m.measurement, "window_tau", None)), []).append((i, m))
        self.groups = [_Group(assembly, items, self.lines) for items in groups.values()]
        self.data = [m.frf.data[self.lines, 0, 0] for m in self.measured]
        # the lines each FRF holds: a line of zero or not finite (a dropout, a line an analyser left empty) says
        # nothing of the structure, and is left out (no weight, no degree of freedom, no share of an error)
        # lines interpolated between measured ones (NoiseModel.held) are the interpolant's, not data
        self.alive = [np.isfinite(d) & (d != 0) & (True if m.noise.held is None else m.noise.held[self.lines])
                      for d, m in zip(self.data, self.measured)]
        # lines whose noise is correlated (through an exponential window, NoiseModel.correlation) weigh as that
        # many times fewer lines: a fit's uncertainty and a comparison of chi^2 count what the data hold
        self.w_re = [np.where(a, 1.0 / np.sqrt(m.noise.correlation * m.noise.var_re[self.lines]), 0.0)
                     for m, a in zip(self.measured, self.alive)]
        self.w_im = [np.where(a, 1.0 / np.sqrt(m.noise.correlation * m.noise.var_im[self.lines]), 0.0)
                     for m, a in zip(self.measured, self.alive)]
        self.n = 2 * sum(int(a.sum()) for a in self.alive)
        # the same, one row per FRF: every evaluation's ratios and weights in one pass
        self._data = np.array(self.data)
        self._alive = np.array(self.alive)
        self._all_alive = bool(self._alive.all())
        self._w = np.stack([np.array(self.w_re), np.array(self.w_im)], axis=1)  # (FRF, part, line)
        self.evaluations = 0
        if lines is None:  # the data as given (a subsample of them was checked when they were)
            self._check_quantities()
        self._check_signs()
        self.evaluations = 0  # the checks' evaluation is not the caller's

    def _check_quantities(self) -> None:
        """Refuse an FRF that holds another quantity than the one it was read as (:mod:`.quantity`): the model times
        ``(i omega)^n`` over the whole band, an accelerance or a mobility exported without its units."""
        predicted = self.predict()
        for m, y, data, w_re, w_im in zip(self.measured, predicted, self.data, self.w_re, self.w_im):
            fit = quantity_signature(data, y, m.frf.frequency.hz[self.lines], w_re, w_im)
            where = getattr(m.measurement, "describe", lambda m=m: m.label)()
            message = quantity_error(fit, where, getattr(m.measurement, "quantity", "receptance"))
            if message:
                raise InvalidValueError(message)

    def _check_signs(self) -> None:
        """Refuse a driving point whose sign is reversed or conjugated: by passivity, and against the model.

        A passive structure's driving-point receptance has ``Im H <= 0``
        (:func:`~substructure.frf.reversed_share`).  One whose imaginary part
        is mostly positive, and whose phase error against the model (its mean
        square, weighted by the noise) falls :data:`SIGN_ERROR_FACTOR` times or
        more when the data are negated or conjugated, is refused, saying
        which: large phase noise can turn the first test, a wrong model the
        second, not both.
        """
        suspects = [i for i, m in enumerate(self.measured)
                    if m.frf.outputs[0] == m.frf.inputs[0] and reversed_share(self.data[i]) > REVERSED_SHARE]
        if not suspects:
            return
        predicted = self.predict()
        for i in suspects:
            h, w = self.data[i], self.w_im[i] ** 2

            def error(x):
                with np.errstate(divide="ignore", invalid="ignore"):
                    phase = np.angle(predicted[i] / x)
                ok = np.isfinite(phase) & np.isfinite(w)
                return float(np.sum(w[ok] * phase[ok] ** 2) / max(np.sum(w[ok]), 1e-300))

            as_is, negated, conjugated = error(h), error(-h), error(np.conj(h))
            if min(negated, conjugated) * SIGN_ERROR_FACTOR > as_is:
                continue
            m = self.measured[i]
            where = getattr(m.measurement, "describe", lambda: m.label)()
            fix = ("one channel's sign is reversed (the hammer's or the sensor's polarity, or a sensor facing the "
                   "other way; unless it is an accelerance whose units the file left out, with Im > 0 too: then give "
                   "them): negate the FRF (substructure tap --reverse-polarity)" if negated <= conjugated else
                   "the data follow the convention exp(-i omega t), not exp(+i omega t): take their complex "
                   "conjugate")
            raise InvalidValueError(
                f"measured FRF {where}: a driving point, whose receptance has Im(H) <= 0 on a passive structure, "
                f"has a positive imaginary part on lines holding {reversed_share(h):.0%} of |Im H|, and its phase "
                f"error against the model falls from {np.sqrt(as_is):.2f} rad RMS to "
                f"{np.sqrt(min(negated, conjugated)):.2f} when it is "
                f"{'negated' if negated <= conjugated else 'conjugated'}: {fix}")

    def windows(self) -> list[tuple[float | None, list[str]]]:
        """How each measured FRF's model is seen: through its exponential window or on the real lines.

        Returns
        -------
        list of (float or None, list of str)
            Per measured FRF: the window's ``tau`` [s] when the model is
            evaluated at ``omega - i/tau`` as the data were measured (else
            None), and the components and joint models that kept a windowed
            measurement's model on the real lines (empty otherwise).
        """
        out: list = [(None, [])] * len(self.measured)
        for g in self.groups:
            for i in g.indices:
                out[i] = (g.window_tau, list(g.not_windowed))
        return out

    def subsample(self, step: int, keep=None) -> "Likelihood":
        """The same likelihood on every ``step``-th line, and on the lines ``keep`` (for cheap screening).

        Parameters
        ----------
        step : int
            Keep every this-many-th line.
        keep : array of int, optional
            Positions in ``lines`` kept as well (the lines around
            resonances, where a mode that moves by a line changes ``chi^2``
            most).

        Returns
        -------
        Likelihood
            The subsampled likelihood (the same noise per line).
        """
        lines = self.lines[:: whole_number(step, "step", 1)]
        if keep is not None and len(keep):
            keep = np.asarray(keep, dtype=int)
            lines = np.union1d(lines, self.lines[keep[(keep >= 0) & (keep < self.lines.size)]])
        return self.same(lines=lines)

    def same(self, measured: Sequence[Measured] | None = None, lines: np.ndarray | None = None) -> "Likelihood":
        """The same model and calibration on other data or lines.

        Parameters
        ----------
        measured : sequence of Measured, optional
            The data (default: these).
        lines : ndarray of int, optional
            Indices of the lines to use (default: all of the data's).

        Returns
        -------
        Likelihood
            The new likelihood.
        """
        return Likelihood(self.assembly, self.measured if measured is None else measured, lines, self.calibration)

    def predict(self, changes: Sequence[tuple] = ()) -> list[np.ndarray]:
        """Model values per measured FRF on the lines used.

        Parameters
        ----------
        changes : sequence of (Change, dict)
            The changes with their values (SI), applied in order.

        Returns
        -------
        list of ndarray
            Complex receptances, one array per measured FRF.
        """
        self.evaluations += 1
        return self._gather([g.predict(changes) for g in self.groups])

    def _gather(self, per_group: list) -> list:
        """Per measured FRF, its array among the groups' (each group's in the order of its indices)."""
        out: list = [None] * len(self.measured)
        for g, ys in zip(self.groups, per_group):
            for i, y in zip(g.indices, ys):
                out[i] = y
        return out

    def log_ratios(self, changes: Sequence[tuple] = ()) -> list[np.ndarray]:
        """``ln(model / measured)`` per measured FRF (non-finite values replaced by a penalty).

        Parameters
        ----------
        changes : sequence of (Change, dict)
            The changes with their values (SI), applied in order.

        Returns
        -------
        list of ndarray
            Complex log ratios, one array per measured FRF.
        """
        return self._ratios(self.predict(changes))

    def rms(self, ratios: Sequence[np.ndarray]) -> float:
        """The RMS of log ratios over the lines the data hold (``alive``).

        Parameters
        ----------
        ratios : sequence of ndarray
            Log ratios per measured FRF (:meth:`log_ratios`).

        Returns
        -------
        float
            ``sqrt(mean |r|^2)``.
        """
        return float(np.sqrt(np.mean(np.concatenate([np.abs(r[a]) ** 2 for r, a in zip(ratios, self.alive)]))))

    def floors(self) -> tuple[float, list[float]]:
        """The RMS log ratio a perfect model would show on the lines the data hold: in all, and per FRF.

        Returns
        -------
        (float, list of float)
            ``sqrt(mean(v_re + v_im))`` over every measured FRF's ``alive``
            lines, and over each one's.
        """
        variances = [(m.noise.var_re + m.noise.var_im)[self.lines][a] for m, a in zip(self.measured, self.alive)]
        return (float(np.sqrt(np.mean(np.concatenate(variances)))),
                [float(np.sqrt(np.mean(v))) for v in variances])

    def _ratios(self, predicted: list) -> list[np.ndarray]:
        return list(self._log_ratio_array(np.array(predicted)))

    def level(self, changes: Sequence[tuple] = ()) -> float:
        """The measured FRFs' common scale over the model's that fits best: ``exp(-c)``, ``c`` the mean of
        ``ln |model / measured|`` over the lines the data hold, each weighed by its inverse variance.

        With ``calibration`` it is the factor profiled out of every comparison (within ``1 + calibration``
        either way); without, what it would be (1 for data and a model that agree in level).

        Parameters
        ----------
        changes : sequence of (Change, dict)
            The changes with their values (SI), applied in order.

        Returns
        -------
        float
            E.g. 1.03: the data read 3 % above the model throughout.
        """
        raw = self._log_ratio_array(np.array(self.predict(changes)), calibrated=False)
        return float(np.exp(-self._offset(raw, self.calibration)))

    def _offset(self, r: np.ndarray, bound: float | None) -> np.ndarray:
        """The weighted mean of ``Re r`` per model (``r``: ``(..., FRF, line)``), within ``ln(1 + bound)``."""
        w = self._w[:, 0, :] ** 2
        ok = np.isfinite(r.real) & (w > 0)
        c = np.sum(np.where(ok, r.real, 0.0) * w, axis=(-2, -1)) / np.maximum(np.sum(np.where(ok, w, 0.0),
                                                                                   axis=(-2, -1)), 1e-300)
        return c if bound is None else np.clip(c, -np.log1p(bound), np.log1p(bound))

    def _log_ratio_array(self, predicted: np.ndarray, calibrated: bool = True) -> np.ndarray:
        """Log ratios of model values ``(..., FRF, line)`` (several models at once: the same numbers, element by
        element, as each alone); with ``calibration``, less each model's common level (:meth:`level`)."""
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            q = predicted / self._data
            # ln|q| + i arg q: the complex logarithm's value (to rounding), several times faster than np.log
            r = np.empty_like(q)
            r.real = np.log(np.abs(q))
            r.imag = np.arctan2(q.imag, q.real)
        if calibrated and self.calibration is not None:
            r.real -= self._offset(r, self.calibration)[..., None, None]
        bad = ~np.isfinite(r)
        if bad.any():
            r = np.where(bad, LOG_RATIO_PENALTY * (1 + 1j), r)
        if not self._all_alive:  # a line without data: no residual
            r = np.where(self._alive, r, 0.0)
        return r

    def _whitened(self, r: np.ndarray) -> np.ndarray:
        """:meth:`whiten` of log ratios ``(..., FRF, line)``: ``(..., 2 FRF line)``."""
        parts = r.view(np.float64).reshape(r.shape + (2,))  # (..., FRF, line, part): real and imaginary parts
        return (np.swapaxes(parts, -1, -2) * self._w).reshape(r.shape[:-2] + (-1,))

    def whiten(self, ratios: Sequence[np.ndarray]) -> np.ndarray:
        """The whitened residual vector of log ratios (real parts, then imaginary parts, per FRF).

        Parameters
        ----------
        ratios : sequence of ndarray
            Log ratios per measured FRF (:meth:`log_ratios`).

        Returns
        -------
        ndarray
            Each part divided by its standard deviation.
        """
        return self._whitened(np.array(ratios, dtype=complex))

    def residual(self, changes: Sequence[tuple] = ()) -> np.ndarray:
        """The whitened residual vector; its sum of squares is ``chi^2``.

        Parameters
        ----------
        changes : sequence of (Change, dict)
            The changes with their values (SI), applied in order.

        Returns
        -------
        ndarray
            The residuals.
        """
        return self.whiten(self.log_ratios(changes))

    def residuals(self, lists: Sequence[Sequence[tuple]]) -> list[np.ndarray]:
        """The residuals of several models, as :meth:`residual` gives each in turn (the same numbers).

        The models are evaluated together (``Evaluator.many`` of
        :mod:`substructure.updating.structure`: the trials of a scan cost one
        coupling, not one each).  When one of them cannot be
        evaluated, they are evaluated one by one: the error is the one
        :meth:`residual` raises for the first such model, after the models
        before it were counted.

        Parameters
        ----------
        lists : sequence of sequence of (Change, dict)
            Each model's changes with their values (SI), applied in order.

        Returns
        -------
        list of ndarray
            The residuals of each model.
        """
        lists = [list(changes) for changes in lists]
        try:
            per_group = [g.predict_many(lists) for g in self.groups]
        except Exception:  # noqa: BLE001 - one by one, so that the error is the first model's, as with residual
            return [self.residual(changes) for changes in lists]
        self.evaluations += len(lists)
        # every model's log ratios and whitening in one array operation (the same numbers as each alone)
        predicted = np.array([self._gather([ys[k] for ys in per_group]) for k in range(len(lists))], dtype=complex)
        return list(self._whitened(self._log_ratio_array(predicted)))

    def chi2(self, changes: Sequence[tuple] = ()) -> float:
        """``chi^2`` of the model (``-2 ln L`` up to a constant).

        Parameters
        ----------
        changes : sequence of (Change, dict)
            The changes with their values (SI), applied in order.

        Returns
        -------
        float
            The sum of squared whitened residuals.
        """
        r = self.residual(changes)
        return float(r @ r)
