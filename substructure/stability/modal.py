"""Modal parameters of the tool point: modes, FRF synthesis and a modal fit.

Semi-discretization integrates the equations of motion in time and so needs
a modal model: each mode a single-degree-of-freedom oscillator acting in the
feed (``x``) or normal (``y``) direction, with natural frequency ``f_n``
[Hz], damping ratio ``zeta`` and modal stiffness ``k`` [N/m].  Its receptance
is ``1 / (k (1 - r^2 + 2 i zeta r))``, ``r = f / f_n`` (conventions.md:
``x(t) = X exp(i omega t)``); a direction without modes is rigid.

:class:`ModalFitter` fits such modes to a measured or predicted receptance:
peak picking (half-power bandwidths) for the start values, then a complex
nonlinear least-squares fit (``scipy.optimize.least_squares``) of all modes at
once, with a constant (upper) and a ``-1/omega^2`` (lower) residual term that
take up modes outside the band.  The residual terms are reported, not kept
in the modal model.
"""

from __future__ import annotations

import csv
import io
import os
import warnings
from typing import Any

import attrs
import numpy as np
import pint

from .._files import decode_text, read_bytes
from ..errors import FileFormatError, InvalidValueError, SubstructureWarning
from ..frf import FRF, Frequency
from ..units import Q_, dimensionless, items_of, quantity, show_value
from .structure import XY_LABELS, _one_entry, xy_receptance

__all__ = ["Mode", "ModalModel", "ModalFitter", "fit_modes", "MODES_CSV_HEADER", "MODE_FREQUENCY_RANGE_HZ",
           "MODE_STIFFNESS_RANGE_N_PER_M", "ModalFitWarning", "FIT_DAMPING_RANGE"]

#: Most lines of a modal model's default grid (about 64 MB of 2x2 complex receptances).
MAX_DEFAULT_LINES = 2_000_000

#: The header of a modes CSV file (:meth:`ModalModel.from_csv`): direction ``x`` or ``y``,
#: natural frequency in Hz, damping ratio, modal stiffness in N/m.
MODES_CSV_HEADER = "direction,frequency_hz,damping_ratio,stiffness_n_per_m"


#: The natural frequencies a mode may have, in Hz: a machine tool's modes lie between a few Hz and tens
#: of kHz; outside 0.1 Hz to 1 MHz a number is a wrong unit (and 1e-300 Hz divides by zero in the lobes).
MODE_FREQUENCY_RANGE_HZ = (0.1, 1e6)

#: The modal stiffnesses a mode may have, in N/m: a tool point has 1e5 to 1e9 N/m; outside 1 N/m to
#: 1e12 N/m a number is a wrong unit (and the lobes divide by zero or overflow).
MODE_STIFFNESS_RANGE_N_PER_M = (1.0, 1e12)


#: The damping ratios :class:`ModalFitter` may give a mode: a fitted mode at the lower end is one the fit
#: did not resolve (noise, or a feature of the data that is not a mode), not a mode of that damping.
FIT_DAMPING_RANGE = (1e-5, 0.5)


_COLUMNS = MODES_CSV_HEADER.split(",")
_FIELDS = {"direction": 1, "frequency": 2, "damping_ratio": 3, "stiffness": 4}  # Mode's field -> column
_EXPECTED = {
    "direction": "'x' (feed) or 'y' (normal)",
    "frequency_hz": (f"a natural frequency in Hz, {MODE_FREQUENCY_RANGE_HZ[0]:g} to {MODE_FREQUENCY_RANGE_HZ[1]:g} "
                     "(MODE_FREQUENCY_RANGE_HZ)"),
    "damping_ratio": "a damping ratio 0 < zeta < 1, a plain number (0.011, not 1.1%)",
    "stiffness_n_per_m": (f"a modal stiffness in N/m, {MODE_STIFFNESS_RANGE_N_PER_M[0]:g} to "
                          f"{MODE_STIFFNESS_RANGE_N_PER_M[1]:g} (MODE_STIFFNESS_RANGE_N_PER_M)"),
}


class ModalFitWarning(SubstructureWarning):
    """A modal fit is poor, or leaves out part of the data (cross terms)."""


def _direction(value: Any) -> str:
    if value not in XY_LABELS:
        raise InvalidValueError(f"direction: got {value!r}; expected 'x' (feed) or 'y' (normal)")
    return value


def _in_range(field: str, dimension: str, unit: str, limits: tuple[float, float], name: str):
    def convert(value: Any) -> pint.Quantity:
        q = quantity(value, field, dimension)
        if q.magnitude <= 0:
            raise InvalidValueError(f"{field}: got {show_value(value)}; expected a positive value")
        lo, hi = limits
        v = float(q.m_as(unit))
        if not lo <= v <= hi:
            raise InvalidValueError(f"{field}: got {v:.6g} {unit}; expected {lo:g} to {hi:g} {unit} ({name}): "
                                    "a wrong unit?")
        return q

    return convert


def _zeta(value: Any) -> float:
    z = dimensionless(value, "damping_ratio")
    if not 0.0 < z < 1.0:
        raise InvalidValueError(f"damping_ratio: got {show_value(value)}; expected 0 < zeta < 1 (an underdamped mode)")
    return z


@attrs.frozen
class Mode:
    """One mode of the tool point in one direction.

    Parameters
    ----------
    direction : {"x", "y"}
        The direction the mode acts in (x the feed direction).
    frequency : quantity or str
        Natural frequency, e.g. ``"922 Hz"``, from 0.1 Hz to 1 MHz
        (``MODE_FREQUENCY_RANGE_HZ``).
    damping_ratio : float
        Viscous damping ratio ``zeta``, ``0 < zeta < 1``.
    stiffness : quantity or str
        Modal stiffness, e.g. ``"1.34e6 N/m"``, from 1 N/m to 1e12 N/m
        (``MODE_STIFFNESS_RANGE_N_PER_M``).  The modal mass is
        ``k / (2 pi f_n)^2``.
    """

    direction: str = attrs.field(validator=lambda i, a, v: _direction(v))
    frequency: pint.Quantity = attrs.field(
        converter=_in_range("frequency", "1 / [time]", "Hz", MODE_FREQUENCY_RANGE_HZ, "MODE_FREQUENCY_RANGE_HZ"))
    damping_ratio: float = attrs.field(converter=_zeta)
    stiffness: pint.Quantity = attrs.field(
        converter=_in_range("stiffness", "[mass] / [time] ** 2", "N/m", MODE_STIFFNESS_RANGE_N_PER_M,
                            "MODE_STIFFNESS_RANGE_N_PER_M"))

    @property
    def frequency_hz(self) -> float:
        """Natural frequency in Hz (a float)."""
        return float(self.frequency.m_as("Hz"))

    @property
    def stiffness_n_per_m(self) -> float:
        """Modal stiffness in N/m (a float)."""
        return float(self.stiffness.m_as("N/m"))

    @property
    def mass_kg(self) -> float:
        """Modal mass ``k / omega_n^2``."""
        return self.stiffness_n_per_m / (2.0 * np.pi * self.frequency_hz) ** 2

    def receptance(self, frequency_hz: Any) -> np.ndarray:
        """``1 / (k (1 - r^2 + 2 i zeta r))`` with ``r = f / f_n``.

        Parameters
        ----------
        frequency_hz : array_like
            Frequencies in Hz.

        Returns
        -------
        ndarray
            Complex receptance in m/N, one value per frequency.
        """
        r = np.asarray(frequency_hz, dtype=float) / self.frequency_hz
        return 1.0 / (self.stiffness_n_per_m * (1.0 - r**2 + 2j * self.damping_ratio * r))


def _modes(value: Any) -> tuple[Mode, ...]:
    modes = tuple(value)
    if not modes:
        raise InvalidValueError("modes: got none; a modal model needs at least one mode")
    for m in modes:
        if not isinstance(m, Mode):
            raise InvalidValueError(f"modes: got {m!r}; expected Mode objects")
    return modes


@attrs.frozen
class ModalModel:
    """Modes of the tool point in x and y; a direction without modes is rigid.

    Parameters
    ----------
    modes : sequence of Mode
        At least one mode.

    Examples
    --------
    >>> model = ModalModel([Mode("x", "922 Hz", 0.011, "1.34e6 N/m")])
    >>> complex(model.xy_frf(Frequency.from_hz([922.0])).data[0, 1, 1])   # y is rigid
    0j
    """

    modes: tuple[Mode, ...] = attrs.field(converter=_modes)

    @classmethod
    def from_csv(cls, path: Any) -> ModalModel:
        """Read a file with the header ``direction,frequency_hz,damping_ratio,stiffness_n_per_m``.

        Numbers are in Hz and N/m; errors name the file, the line and the column, the cell as written
        and what was expected.  A row with the direction and natural frequency of an earlier one is
        refused, naming both lines: the modes of a file are summed, and one mode listed twice would
        halve the depth limit.

        Parameters
        ----------
        path : str or os.PathLike
            The CSV file.

        Returns
        -------
        ModalModel
            The modes of the file.
        """
        name = os.fspath(path)
        text = decode_text(read_bytes(path, "modes CSV file"), name)
        try:
            rows = [(k + 1, row) for k, row in enumerate(csv.reader(io.StringIO(text, newline="")))
                    if any(c.strip() for c in row)]
        except csv.Error as exc:
            raise FileFormatError(f"{name}: cannot read the file ({exc})") from None
        if not rows:
            raise FileFormatError(f"{name}: the file is empty; expected the header {MODES_CSV_HEADER!r}")
        line, header = rows[0]
        if ",".join(c.strip() for c in header) != MODES_CSV_HEADER:
            raise FileFormatError(f"{name}, line {line}: header {','.join(header)!r}; expected {MODES_CSV_HEADER!r}")
        modes = []
        seen: dict[tuple[str, float], tuple[int, tuple[float, float]]] = {}
        for line, row in rows[1:]:
            if len(row) != 4:
                raise FileFormatError(f"{name}, line {line}: expected 4 values ({MODES_CSV_HEADER}), got {len(row)}")
            values = []
            for column, (field, cell) in enumerate(zip(_COLUMNS[1:], row[1:]), start=2):
                try:
                    values.append(float(cell))
                except ValueError:
                    raise FileFormatError(f"{name}, line {line}, column {column} ({field}): cannot read {cell!r} as a "
                                          f"number; expected {_EXPECTED[field]}") from None
            f, z, k = values
            try:
                mode = Mode(row[0].strip(), Q_(f, "Hz"), z, Q_(k, "N/m"))
            except InvalidValueError as exc:
                field, _, rest = str(exc).partition(": ")
                column = _FIELDS.get(field)
                if column is None:  # not one field's value: said as it is
                    raise FileFormatError(f"{name}, line {line}: {exc}") from None
                header = _COLUMNS[column - 1]
                unit = ": a wrong unit?" if rest.endswith("a wrong unit?") else ""  # positive, out of range
                raise FileFormatError(f"{name}, line {line}, column {column} ({header}): got {row[column - 1]!r}; "
                                      f"expected {_EXPECTED[header]}{unit}") from None
            key = (mode.direction, f)
            if key in seen:
                first, others = seen[key]
                what = ("repeats line {first}: one mode listed twice would be counted twice (the depth limit "
                        "halved); give it once" if others == (z, k) else
                        "has the direction and natural frequency of line {first}: two modes at exactly one "
                        "frequency in one direction are one mode; give it once, with its damping ratio and "
                        "stiffness")
                raise FileFormatError(f"{name}, line {line} ({mode.direction}, {row[1].strip()} Hz) "
                                      + what.format(first=first)) from None
            seen[key] = (line, (z, k))
            modes.append(mode)
        if not modes:
            raise FileFormatError(f"{name}: no modes after the header")
        return cls(modes)

    def to_csv(self, path: Any, overwrite: bool = False) -> None:
        """Write the modes in the format :meth:`from_csv` reads (full precision).

        Parameters
        ----------
        path : str or os.PathLike
            The CSV file to write.
        overwrite : bool, default False
            Whether an existing file may be replaced (else ``OutputExistsError``, naming it).
        """
        from .._files import write_text

        rows = [f"{m.direction},{m.frequency_hz!r},{m.damping_ratio!r},{m.stiffness_n_per_m!r}\n" for m in self.modes]
        write_text(path, MODES_CSV_HEADER + "\n" + "".join(rows), overwrite=overwrite)

    # -- arrays for the kernels ---------------------------------------------------
    def arrays(self) -> dict[str, np.ndarray]:
        """``frequency_hz``, ``damping_ratio``, ``stiffness``, ``mass`` and ``direction`` (0 x, 1 y) per mode.

        Returns
        -------
        dict
            Arrays over the modes: Hz, dimensionless, N/m, kg, and 0 or 1.
        """
        return {
            "frequency_hz": np.array([m.frequency_hz for m in self.modes]),
            "damping_ratio": np.array([m.damping_ratio for m in self.modes]),
            "stiffness": np.array([m.stiffness_n_per_m for m in self.modes]),
            "mass": np.array([m.mass_kg for m in self.modes]),
            "direction": np.array([XY_LABELS.index(m.direction) for m in self.modes]),
        }

    def default_frequency(self) -> Frequency:
        """Lines from 0.3 f_min to 3 f_max, log-spaced at a relative step of zeta_min / 50.

        Returns
        -------
        Frequency
            The lines, in Hz.
        """
        a = self.arrays()
        lo, hi = 0.3 * a["frequency_hz"].min(), 3.0 * a["frequency_hz"].max()
        step = np.log1p(a["damping_ratio"].min() / 50.0)
        count = np.log(hi / lo) / step + 1
        if count > MAX_DEFAULT_LINES:
            raise InvalidValueError(
                f"modes: the default grid for damping ratio {a['damping_ratio'].min():.3g} needs {count:.3g} lines "
                f"(a relative step of zeta/50 from 0.3 f_min to 3 f_max), more than MAX_DEFAULT_LINES = "
                f"{MAX_DEFAULT_LINES:.3g}; check the damping (a ratio: 0.02 for 2 %; the damping_ratio column of a "
                "modes file), or give the lines yourself (frequency=Frequency(...) in Python)")
        n = int(np.ceil(count))
        return Frequency.from_hz(np.geomspace(lo, hi, n))

    def receptance(self, frequency_hz: Any) -> np.ndarray:
        """``(n, 2, 2)`` receptance matrix, x and y (no cross terms).

        Parameters
        ----------
        frequency_hz : array_like
            Frequencies in Hz.

        Returns
        -------
        ndarray
            Complex, shape ``(n_freq, 2, 2)``, in m/N.
        """
        f = np.asarray(frequency_hz, dtype=float)
        out = np.zeros((f.size, 2, 2), dtype=complex)
        for m in self.modes:
            i = XY_LABELS.index(m.direction)
            out[:, i, i] += m.receptance(f)
        return out

    def xy_frf(self, frequency: Frequency | None = None) -> FRF:
        """Synthesised receptances as an FRF labelled ``x``/``y`` (default grid: :meth:`default_frequency`).

        Parameters
        ----------
        frequency : Frequency, optional
            The lines; default :meth:`default_frequency`.

        Returns
        -------
        FRF
            Shape ``(n_freq, 2, 2)``, in m/N.
        """
        frequency = self.default_frequency() if frequency is None else frequency
        if not isinstance(frequency, Frequency):
            raise InvalidValueError(f"frequency: got {type(frequency).__name__}; expected a Frequency")
        return FRF(frequency, self.receptance(frequency.hz), XY_LABELS, XY_LABELS)

    def describe(self) -> str:
        """One line: every mode with its direction, frequency, damping ratio and stiffness.

        Returns
        -------
        str
            The description, in Hz and N/m.
        """
        return "; ".join(f"{m.direction}: {m.frequency_hz:.6g} Hz, zeta {m.damping_ratio:.4g}, "
                         f"k {m.stiffness_n_per_m:.4g} N/m" for m in self.modes)


# -- fitting ----------------------------------------------------------------------


def _half_power_zeta(f: np.ndarray, mag: np.ndarray, i: int) -> float:
    level = mag[i] / np.sqrt(2.0)
    left = np.flatnonzero(mag[:i] < level)
    right = np.flatnonzero(mag[i:] < level)
    if left.size == 0 or right.size == 0:
        return 0.02
    a, b = left[-1], i + right[0]
    # linear interpolation of the crossings
    fa = np.interp(level, [mag[a], mag[a + 1]], [f[a], f[a + 1]])
    fb = np.interp(level, [mag[b], mag[b - 1]], [f[b], f[b - 1]])
    return float(np.clip((fb - fa) / (2.0 * f[i]), 1e-4, 0.3))


class ModalFitter:
    """Fit modes to one translational receptance (scikit-learn style: ``fit`` returns self).

    Parameters
    ----------
    n_modes : int, optional
        Number of modes; default: every peak of ``|H|`` with the given
        prominence.
    band : (lo, hi) in Hz, optional
        Fit only these lines (e.g. leave out the rigid-body region of a
        free-free model).
    prominence : float, default 0.05
        Peak prominence as a fraction of the largest ``|H|`` in the band.
    residuals : bool, default True
        Fit an upper (constant) and a lower (``-1/omega^2``) residual term.

    Attributes
    ----------
    modes_ : tuple of Mode
        The fitted modes, by frequency.
    model_ : ModalModel
    relative_error_ : float
        ``||H_fit - H|| / ||H||`` over the band (with the residual terms).
    modal_error_ : float
        The same without the residual terms: how well the modes alone (what
        semi-discretization uses) reproduce the data.
    residual_compliance_, residual_inverse_mass_ : float
        Upper residual [m/N] and lower residual [1/kg] (term ``-R / omega^2``).
    frequency_ : Frequency
        The lines fitted.
    """

    def __init__(self, n_modes: int | None = None, band: tuple[float, float] | None = None,
                 prominence: float = 0.05, residuals: bool = True) -> None:
        self.n_modes = n_modes
        self.band = band
        self.prominence = prominence
        self.residuals = residuals

    def fit(self, frf: FRF, direction: str = "x") -> ModalFitter:
        """Fit the modes of ``frf`` (a one-entry receptance), acting in ``direction``.

        Parameters
        ----------
        frf : FRF
            A one-entry receptance in m/N (tool point H).
        direction : {"x", "y"}
            The direction the fitted modes act in.

        Returns
        -------
        ModalFitter
            ``self``, with ``modes_``, ``model_`` and the fit's errors.
        """
        from scipy.optimize import least_squares
        from scipy.signal import find_peaks

        _direction(direction)
        frf = _one_entry(frf, "frf")
        if self.band is not None:
            pair = items_of(self.band, "band", "two frequencies, (lo, hi) in Hz")
            if len(pair) != 2:
                raise InvalidValueError(f"band: got {self.band!r}; expected (lo, hi) in Hz")
            frf = frf.crop(*pair)
        f, h = frf.frequency.hz, frf.data[:, 0, 0]
        if f.size < 8:
            raise InvalidValueError(f"frf: {f.size} lines in the band; a modal fit needs at least 8")
        if f[0] <= 0:
            raise InvalidValueError("frf: the band starts at 0 Hz; give band=(lo, hi) with lo > 0")
        mag = np.abs(h)
        peaks, props = find_peaks(mag, prominence=self.prominence * mag.max())
        if self.n_modes is not None:
            if not isinstance(self.n_modes, int) or self.n_modes < 1:
                raise InvalidValueError(f"n_modes: got {self.n_modes!r}; expected a whole number >= 1")
            if peaks.size < self.n_modes:
                raise InvalidValueError(
                    f"n_modes: asked for {self.n_modes} modes, found {peaks.size} peaks of |H| with prominence "
                    f"{self.prominence:g} in {f[0]:g}..{f[-1]:g} Hz; lower the prominence or the number of modes"
                )
            peaks = np.sort(peaks[np.argsort(props["prominences"])[::-1][: self.n_modes]])
        if peaks.size == 0:
            raise InvalidValueError(
                f"frf: no peak of |H| in {f[0]:g}..{f[-1]:g} Hz; a modal fit needs resonances in the band (choose "
                "it around the tool's modes)"
            )
        fn0 = f[peaks]
        zeta0 = np.array([_half_power_zeta(f, mag, i) for i in peaks])
        im = -h.imag[peaks]
        k0 = 1.0 / (2.0 * zeta0 * np.where(im > 0, im, mag[peaks]))
        scale = mag.max()
        w = 2.0 * np.pi * f
        w_mid = 2.0 * np.pi * np.sqrt(f[0] * f[-1])
        n = peaks.size
        x0 = np.concatenate([np.log(fn0), np.log(zeta0), np.log(k0), [0.0, 0.0] if self.residuals else []])
        zeta_lo, zeta_hi = FIT_DAMPING_RANGE
        lower = np.concatenate([np.full(n, np.log(f[0])), np.full(n, np.log(zeta_lo)), np.log(k0) - 7.0,
                                [-np.inf, -np.inf] if self.residuals else []])
        upper = np.concatenate([np.full(n, np.log(f[-1])), np.full(n, np.log(zeta_hi)), np.log(k0) + 7.0,
                                [np.inf, np.inf] if self.residuals else []])
        x0 = np.clip(x0, lower + 1e-9, upper - 1e-9)

        def model(p: np.ndarray, with_residuals: bool = True) -> np.ndarray:
            fn, zeta, k = np.exp(p[:n]), np.exp(p[n:2 * n]), np.exp(p[2 * n:3 * n])
            r = f[:, None] / fn[None, :]
            out = (1.0 / (k * (1.0 - r**2 + 2j * zeta * r))).sum(axis=1)
            if self.residuals and with_residuals:
                out = out + scale * p[3 * n] - scale * p[3 * n + 1] * (w_mid / w) ** 2
            return out

        def residual(p: np.ndarray) -> np.ndarray:
            d = (model(p) - h) / scale
            return np.concatenate([d.real, d.imag])

        sol = least_squares(residual, x0, bounds=(lower, upper), x_scale="jac", xtol=1e-12, ftol=1e-12,
                            max_nfev=200 * (3 * n + 2))
        p = sol.x
        order = np.argsort(p[:n])
        lo_k, hi_k = MODE_STIFFNESS_RANGE_N_PER_M
        for i in order:
            k = float(np.exp(p[2 * n + i]))
            if not lo_k <= k <= hi_k:  # the fit, not a unit: say so, with what to do
                raise InvalidValueError(
                    f"frf: the modal fit gave the mode near {float(np.exp(p[i])):.5g} Hz a stiffness of {k:.3g} N/m, "
                    f"outside {lo_k:g} to {hi_k:g} N/m (MODE_STIFFNESS_RANGE_N_PER_M): the band holds more than its "
                    f"{n} peaks' modes resolve; choose the band (e.g. around the tool's modes) or the number of modes")
        self.modes_ = tuple(
            Mode(direction, Q_(float(np.exp(p[i])), "Hz"), float(np.exp(p[n + i])),
                 Q_(float(np.exp(p[2 * n + i])), "N/m"))
            for i in order
        )
        self.model_ = ModalModel(self.modes_)
        norm = np.linalg.norm(h)
        self.relative_error_ = float(np.linalg.norm(model(p) - h) / norm)
        self.modal_error_ = float(np.linalg.norm(model(p, with_residuals=False) - h) / norm)
        self.residual_compliance_ = float(scale * p[3 * n]) if self.residuals else 0.0
        self.residual_inverse_mass_ = float(scale * p[3 * n + 1] * w_mid**2) if self.residuals else 0.0
        self.frequency_ = frf.frequency
        return self

    def predict(self, frequency: Frequency | None = None) -> FRF:
        """The fitted receptance (modes and residual terms) as a one-entry FRF.

        Parameters
        ----------
        frequency : Frequency, optional
            The lines; default those fitted.

        Returns
        -------
        FRF
            The receptance, in m/N.
        """
        if not hasattr(self, "model_"):
            raise InvalidValueError("ModalFitter: call fit(frf) first")
        frequency = self.frequency_ if frequency is None else frequency
        f = frequency.hz
        i = XY_LABELS.index(self.modes_[0].direction)
        h = (self.model_.receptance(f)[:, i, i] + self.residual_compliance_
             - self.residual_inverse_mass_ / (2 * np.pi * f) ** 2)
        return FRF.single(frequency, h, output=self.modes_[0].direction, input=self.modes_[0].direction)


def fit_modes(structure: FRF, n_modes: int | None = None, band: tuple[float, float] | None = None,
              prominence: float = 0.05, max_error: float = 0.2) -> ModalModel:
    """Modal model of the tool point in x and y from receptance data.

    Parameters
    ----------
    structure : FRF
        One translational receptance (a symmetric tool: the modes are used in
        x and in y) or an FRF labelled ``x``/``y`` (:func:`xy_frf`), whose
        ``xx`` and ``yy`` entries are fitted separately.
    n_modes, band, prominence
        As in :class:`ModalFitter` (``n_modes`` per direction).
    max_error : float, default 0.2
        Warn (:class:`ModalFitWarning`) when the modes alone miss the data by
        more than this relative error.

    Returns
    -------
    ModalModel
        Modes in x and y (Hz, damping ratio, N/m).

    Notes
    -----
    Cross terms are not fitted; a warning says so when they are not zero.
    """
    def fitted(frf: FRF, direction: str) -> ModalFitter:
        return ModalFitter(n_modes=n_modes, band=band, prominence=prominence).fit(frf, direction)

    if isinstance(structure, FRF) and structure.shape[1:] == (1, 1):
        fits = [fitted(structure, "x")]
        modes = list(fits[0].modes_) + [attrs.evolve(m, direction="y") for m in fits[0].modes_]
    else:
        hz, g = xy_receptance(structure)
        frequency = Frequency(hz)
        if np.any(g[:, 0, 1] != 0) or np.any(g[:, 1, 0] != 0):
            warnings.warn("fit_modes: the cross receptances xy and yx are not fitted (modes act in x or y only)",
                          ModalFitWarning, stacklevel=2)
        fits = [fitted(FRF.single(frequency, g[:, i, i], output=d, input=d), d) for i, d in enumerate(XY_LABELS)]
        modes = [m for fit in fits for m in fit.modes_]
    worst = max(fit.modal_error_ for fit in fits)
    if worst > max_error:
        warnings.warn(f"fit_modes: the fitted modes miss the data by {worst:.0%} (relative); "
                      "choose the band or the number of modes", ModalFitWarning, stacklevel=2)
    return ModalModel(modes)
