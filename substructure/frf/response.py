"""The FRF value object: complex responses between labelled DOFs on one axis.

:class:`FRF` holds data ``(n_freq, n_out, n_in)`` in SI units with its DOF
labels and quantity; selection of entries and bands, interpolation,
arithmetic, peaks, reciprocity and the conversion to receptance return new
objects.  Plots and files are the edges: :mod:`substructure.plot` and
:mod:`substructure.io.frf_files`, imported inside the methods that need them.
"""

from __future__ import annotations

import numbers
import warnings
from collections.abc import Sequence
from typing import Any

import attrs
import numpy as np

from ..errors import FrequencyAxisMismatchError, InvalidValueError, NonReciprocalWarning, UnknownPointError
from ..units import finite_real
from ._fields import check_label, _check_frequency, _check_quantity, _complex_array, _labels, _scalar
from .axis import _GRID_RTOL, Frequency
from .files._common import register_frf_class
from .peaks import local_maxima

__all__ = ["FRF"]


@attrs.frozen(repr=False)
class FRF:
    """Frequency response functions between labelled DOFs on one frequency axis.

    Parameters
    ----------
    frequency : Frequency
        The axis, in Hz.
    data : array_like
        Complex values of shape ``(n_freq, n_out, n_in)``, finite, in SI units
        (receptance in m/N, 1/N or 1/(N m) depending on the DOFs).  Stored as
        a read-only complex128 copy.  A 1-D array is not reshaped: use
        :meth:`FRF.single` for one FRF.
    outputs, inputs : sequence of str
        Unique labels of the response and excitation DOFs, ``"POINT:y"`` or
        ``"POINT:theta"`` (conventions.md).
    quantity : {"receptance", "mobility", "accelerance"}
        What the data are; :meth:`to_receptance` converts.

    Examples
    --------
    >>> f = Frequency.from_range("100 Hz", "110 Hz", "5 Hz")
    >>> frf = FRF.single(f, [1e-7, 2e-7, 1e-7], output="tool.tip:y", input="tool.tip:y")
    >>> frf.entry("tool.tip:y", "tool.tip:y").real
    array([1.e-07, 2.e-07, 1.e-07])
    """

    __array_ufunc__ = None  # numpy scalars defer to FRF.__rmul__ instead of broadcasting

    frequency: Frequency = attrs.field(validator=_check_frequency)
    data: np.ndarray = attrs.field(converter=_complex_array, eq=attrs.cmp_using(eq=np.array_equal))
    outputs: tuple[str, ...] = attrs.field(converter=_labels("outputs"))  # type: ignore[misc]  # attrs plugin: converter factory
    inputs: tuple[str, ...] = attrs.field(converter=_labels("inputs"))  # type: ignore[misc]  # attrs plugin: converter factory
    quantity: str = attrs.field(default="receptance", validator=_check_quantity)

    def __attrs_post_init__(self) -> None:
        expected = (self.frequency.n, len(self.outputs), len(self.inputs))
        if self.data.shape != expected:
            hint = " (for one FRF use FRF.single)" if self.data.ndim == 1 else ""
            raise InvalidValueError(
                f"data: got shape {self.data.shape}; expected (n_freq, n_out, n_in) = {expected} "
                f"for {expected[0]} frequency lines, {expected[1]} output label(s) and "
                f"{expected[2]} input label(s){hint}"
            )
        bad = ~np.isfinite(self.data)
        if bad.any():
            k, i, j = np.argwhere(bad)[0]
            raise InvalidValueError(
                f"data: got {self.data[k, i, j]} at {self.frequency.hz[k]:g} Hz, entry "
                f"({self.outputs[i]!r}, {self.inputs[j]!r}); expected finite values"
            )

    @classmethod
    def single(
        cls, frequency: Frequency, values: Any, output: str = "response", input: str = "excitation",
        quantity: str = "receptance",
    ) -> FRF:
        """One FRF, shape ``(n_freq, 1, 1)``, from a 1-D array of ``n_freq`` complex values.

        Parameters
        ----------
        frequency : Frequency
            The axis, in Hz.
        values : array_like
            ``n_freq`` complex values, in the SI unit of the quantity (receptance
            m/N, mobility m/(N s), accelerance m/(N s^2) for a y/f entry).
        output : str
            Output label, e.g. ``"tool.tip:y"``.
        input : str
            Input label.
        quantity : {"receptance", "mobility", "accelerance"}
            What the values are.

        Returns
        -------
        FRF
            The one-entry FRF.
        """
        for field, label in (("output", output), ("input", input)):
            if not isinstance(label, str) or not label.strip() or label != label.strip():
                raise InvalidValueError(f"{field}: got {label!r}; expected a DOF label such as 'tool.tip:y'")
            check_label(field, label)
        values = np.asarray(values)
        if values.ndim != 1:
            raise InvalidValueError(f"values: got shape {values.shape}; expected a 1-D array of n_freq values")
        return cls(frequency, values[:, None, None], (output,), (input,), quantity)

    # -- labels ---------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, int, int]:
        """``(n_freq, n_out, n_in)``."""
        return self.data.shape

    def _index(self, labels: Any, which: str) -> list[int]:
        have = self.outputs if which == "output" else self.inputs
        if isinstance(labels, slice) and labels == slice(None):
            return list(range(len(have)))
        wanted = list(labels) if isinstance(labels, (list, tuple, np.ndarray)) else [labels]
        for label in wanted:
            if not isinstance(label, str) or label not in have:
                available = ", ".join(repr(x) for x in have)
                raise UnknownPointError(f"{which} {label!r} is not in this FRF; {which}s available: {available}")
        return [have.index(x) for x in wanted]

    def entry(self, output: str, input: str) -> np.ndarray:
        """The 1-D complex FRF from ``input`` to ``output`` (read-only view).

        Parameters
        ----------
        output : str
            One output label.
        input : str
            One input label.

        Returns
        -------
        ndarray
            Complex, shape ``(n_freq,)``, in the entry's unit (:meth:`unit`).
        """
        if not isinstance(output, str) or not isinstance(input, str):
            raise InvalidValueError(
                f"output, input: got {output!r}, {input!r}; expected one label each (use select for more)"
            )
        (i,), (j,) = self._index(output, "output"), self._index(input, "input")
        return self.data[:, i, j]

    def select(self, outputs: Any = None, inputs: Any = None) -> FRF:
        """Sub-FRF with these outputs and inputs (a label or a list; ``None`` keeps all).

        Parameters
        ----------
        outputs : str or list of str, optional
            Output labels to keep, in this order.
        inputs : str or list of str, optional
            Input labels to keep, in this order.

        Returns
        -------
        FRF
            Shape ``(n_freq, n_outputs, n_inputs)``, same units.
        """
        rows = self._index(slice(None) if outputs is None else outputs, "output")
        cols = self._index(slice(None) if inputs is None else inputs, "input")
        outputs, inputs = [self.outputs[i] for i in rows], [self.inputs[j] for j in cols]
        return attrs.evolve(self, data=self.data[:, rows][:, :, cols], outputs=outputs, inputs=inputs)

    def __getitem__(self, key: Any) -> FRF:
        """``frf[outputs, inputs]``: labels, lists of labels or ``:``; always an FRF."""
        if not isinstance(key, tuple) or len(key) != 2:
            raise InvalidValueError(
                f"index: got {key!r}; expected a pair frf[outputs, inputs] of labels, "
                "lists of labels or ':'"
            )
        return self.select(*key)

    def with_labels(self, outputs: Sequence[str], inputs: Sequence[str]) -> FRF:
        """Same data under new output and input labels.

        Parameters
        ----------
        outputs : sequence of str
            New output labels, one per output.
        inputs : sequence of str
            New input labels, one per input.

        Returns
        -------
        FRF
            The relabelled FRF.
        """
        return attrs.evolve(self, outputs=outputs, inputs=inputs)

    def unit(self, output: str, input: str) -> str:
        """SI unit of one entry, from the DOF kinds and the quantity (e.g. ``"m/N"``).

        Parameters
        ----------
        output : str
            An output label (``":theta"`` for a rotation, else a displacement).
        input : str
            An input label (``":theta"`` for a moment, else a force).

        Returns
        -------
        str
            The unit: ``"m/N"``, ``"1/N"`` (m/(N m) or rad/N), ``"1/(N m)"``, with
            ``s`` or ``s^2`` more for a mobility or an accelerance.
        """
        self._index(output, "output"), self._index(input, "input")
        rotation, moment = output.endswith(":theta"), input.endswith(":theta")  # else y (default)
        # y/f in m/N; y/m = m/(N m) and theta/f = rad/N in 1/N; theta/m in 1/(N m)
        numerator = "1" if rotation or moment else "m"
        factors = ["N"] + (["m"] if rotation and moment else [])
        factors += {"receptance": [], "mobility": ["s"], "accelerance": ["s^2"]}[self.quantity]
        denominator = " ".join(factors)
        return f"{numerator}/({denominator})" if len(factors) > 1 else f"{numerator}/{denominator}"

    # -- views of the data ----------------------------------------------------
    @property
    def omega(self) -> np.ndarray:
        """Angular frequencies in rad/s."""
        return self.frequency.omega

    @property
    def magnitude(self) -> np.ndarray:
        """``|data|``, same shape as the data."""
        return np.abs(self.data)

    def phase(self, deg: bool = False) -> np.ndarray:
        """Phase angle of the data in rad (or degrees), in (-pi, pi].

        Parameters
        ----------
        deg : bool
            Degrees instead of radians.

        Returns
        -------
        ndarray
            Same shape as the data, in rad (or deg).
        """
        return np.angle(self.data, deg=deg)

    @property
    def real(self) -> np.ndarray:
        """Real part of the data."""
        return self.data.real

    @property
    def imag(self) -> np.ndarray:
        """Imaginary part of the data."""
        return self.data.imag

    # -- frequency axis -------------------------------------------------------
    def crop(self, lo: Any = None, hi: Any = None) -> FRF:
        """FRF restricted to ``lo <= f <= hi`` (floats in Hz, quantities or strings).

        Parameters
        ----------
        lo, hi : float, pint.Quantity, str or None
            Band limits; plain numbers are in Hz; ``None`` leaves that side open.

        Returns
        -------
        FRF
            The lines of the band; an empty band is an error.
        """
        mask = self.frequency.band_mask(lo, hi)
        return attrs.evolve(self, frequency=self.frequency.crop(lo, hi), data=self.data[mask])

    def interpolate(self, frequency: Frequency, kind: str = "linear") -> FRF:
        """FRF on another grid, real and imaginary parts interpolated separately.

        Parameters
        ----------
        frequency : Frequency
            The new grid; it must lie within this FRF's range (no extrapolation,
            up to a rounding tolerance of 1e-12 of the largest frequency).
        kind : {"linear", "cubic"}
            Piecewise linear, or a not-a-knot cubic spline (needs 4 lines).

        Returns
        -------
        FRF
            The FRF on the new grid, same units.
        """
        if not isinstance(frequency, Frequency):
            raise InvalidValueError(
                f"frequency: got {type(frequency).__name__}; expected a Frequency "
                "(e.g. Frequency.from_range('20 Hz', '5000 Hz', '2 Hz'))"
            )
        if kind not in ("linear", "cubic"):
            raise InvalidValueError(f"kind: got {kind!r}; expected 'linear' or 'cubic'")
        old, new = self.frequency.hz, frequency.hz
        if np.array_equal(old, new):
            return self
        tol = _GRID_RTOL * max(abs(old[-1]), 1.0)
        if new[0] < old[0] - tol or new[-1] > old[-1] + tol:
            raise InvalidValueError(
                f"frequency: the new grid {new[0]:g}..{new[-1]:g} Hz leaves this FRF's range "
                f"{old[0]:g}..{old[-1]:g} Hz; extrapolation is not done, crop the new grid"
            )
        minimum = 2 if kind == "linear" else 4
        if old.size < minimum:
            raise InvalidValueError(
                f"kind: {kind} interpolation needs at least {minimum} lines; this FRF has {old.size}"
            )
        x = np.clip(new, old[0], old[-1])
        if kind == "linear":
            k = np.clip(np.searchsorted(old, x, side="right") - 1, 0, old.size - 2)
            t = ((x - old[k]) / (old[k + 1] - old[k]))[:, None, None]
            data = self.data[k] * (1.0 - t) + self.data[k + 1] * t
        else:
            from scipy.interpolate import CubicSpline

            real, imag = (CubicSpline(old, part, axis=0)(x) for part in (self.data.real, self.data.imag))
            data = real + 1j * imag
        return attrs.evolve(self, frequency=frequency, data=data)

    # -- arithmetic -----------------------------------------------------------
    def _check_compatible(self, other: FRF, operation: str) -> None:
        if self.frequency != other.frequency:
            raise FrequencyAxisMismatchError(
                f"cannot {operation} FRFs on different frequency axes ({self.frequency!r} and "
                f"{other.frequency!r}); call .interpolate(frequency) or .crop(lo, hi) first"
            )
        if (self.outputs, self.inputs) != (other.outputs, other.inputs):
            raise InvalidValueError(
                f"cannot {operation} FRFs with different labels: outputs {self.outputs} / "
                f"{other.outputs}, inputs {self.inputs} / {other.inputs}; use .select or .with_labels"
            )
        if self.quantity != other.quantity:
            raise InvalidValueError(
                f"cannot {operation} a {self.quantity} and a {other.quantity}; "
                "convert with .to_receptance() first"
            )

    def __add__(self, other: Any) -> FRF:
        if not isinstance(other, FRF):
            return NotImplemented
        self._check_compatible(other, "combine")
        return attrs.evolve(self, data=self.data + other.data)

    def __sub__(self, other: Any) -> FRF:
        return self + (-other) if isinstance(other, FRF) else NotImplemented

    def __neg__(self) -> FRF:
        return attrs.evolve(self, data=-self.data)

    def __mul__(self, other: Any) -> FRF:
        if hasattr(other, "units") and hasattr(other, "magnitude"):  # a quantity: pint would wrap the FRF in it
            if getattr(other, "dimensionless", False):
                other = other.m_as("dimensionless")
            else:
                raise InvalidValueError(
                    f"cannot multiply an FRF by a quantity in {other.units}: an FRF's values are in the units of its "
                    "quantity (m/N for a receptance); scale it by a plain number")
        factor = _scalar(other)
        if factor is None:
            return NotImplemented
        return attrs.evolve(self, data=self.data * factor)

    __rmul__ = __mul__

    # -- analysis -------------------------------------------------------------
    def peaks(
        self, output: str | None = None, input: str | None = None, prominence: float | None = None
    ) -> np.ndarray:
        """Frequencies in Hz (ascending) of the local maxima of ``|FRF|`` of one entry.

        Parameters
        ----------
        output, input : str, optional
            The entry; may be left out along a side with a single label.
        prominence : float, optional
            Keep only peaks whose prominence is at least this fraction of the
            largest ``|FRF|`` of the entry (the prominences of
            ``scipy.signal.peak_prominences``).

        Returns
        -------
        ndarray
            Frequencies of the peaks in Hz, ascending (empty when there is none).

        Notes
        -----
        A line is a peak when it is higher than both neighbours; a run of
        equal values counts as one peak at its middle line (the left one of
        the two middle lines), where it rises before and falls after.  A
        maximum at the first or last line is not a peak (it may be outside
        the band).  The resolution is the grid's: no sub-line refinement.
        These are the rules of ``scipy.signal.find_peaks``; the search is
        done here with numpy alone, so that a plain peak search does not
        load ``scipy.signal``.
        """
        chosen = []
        for label, have, which in ((output, self.outputs, "output"), (input, self.inputs, "input")):
            if label is None and len(have) != 1:
                raise InvalidValueError(
                    f"{which}: this FRF has {len(have)} {which}s ({', '.join(have)}); name one"
                )
            chosen.append(have[0] if label is None else label)
        magnitude = np.abs(self.entry(*chosen))
        if prominence is not None and (not isinstance(prominence, numbers.Real) or not 0.0 <= prominence <= 1.0):
            raise InvalidValueError(
                f"prominence: got {prominence!r}; expected a fraction of the largest |FRF| in [0, 1]"
            )
        index = local_maxima(magnitude)
        if prominence is not None and index.size:
            from scipy.signal import peak_prominences

            index = index[peak_prominences(magnitude, index)[0] >= prominence * magnitude.max()]
        return self.frequency.hz[index].copy()

    def reciprocity_error(self) -> float:
        """Largest relative asymmetry ``|Y_pq - Y_qp| / max(|Y_pq|, |Y_qp|)``.

        Taken over the frequency lines and every pair of labels ``p, q`` that
        are both outputs and inputs (``H_ij = H_ji``, ``L_ij = N_ji``); 0.0 when
        there is no such pair.

        Returns
        -------
        float
            The relative asymmetry (dimensionless).
        """
        common = [x for x in self.outputs if x in self.inputs]
        if len(common) < 2:
            return 0.0
        rows = [self.outputs.index(x) for x in common]
        cols = [self.inputs.index(x) for x in common]
        block = self.data[:, rows][:, :, cols]
        transposed = np.swapaxes(block, 1, 2)
        scale = np.maximum(np.maximum(np.abs(block), np.abs(transposed)), np.finfo(float).tiny)
        return float((np.abs(block - transposed) / scale).max())

    def check_reciprocity(self, rtol: float = 1e-6) -> float:
        """:meth:`reciprocity_error`, warning with NonReciprocalWarning above ``rtol``.

        Parameters
        ----------
        rtol : float
            Largest relative asymmetry accepted without a warning (dimensionless).

        Returns
        -------
        float
            The relative asymmetry.
        """
        if not (finite_real(rtol) and rtol >= 0):
            raise InvalidValueError(f"rtol: got {rtol!r}; expected a relative tolerance >= 0")
        error = self.reciprocity_error()
        if error > rtol:
            message = f"FRF is not reciprocal: relative asymmetry {error:.3g} exceeds rtol={rtol:g}"
            warnings.warn(message, NonReciprocalWarning, stacklevel=2)
        return error

    def to_receptance(self, decay: float = 0.0) -> FRF:
        """Receptance from mobility (``/ (i omega)``) or accelerance (``/ -omega**2``).

        Parameters
        ----------
        decay : float, optional
            ``1/tau`` [1/s] of the exponential window ``exp(-t/tau)`` the FRF
            was measured through (default 0: none).  Such an FRF is the
            structure's at the complex frequency ``omega - i/tau``, and so is
            the quotient: ``/ (i (omega - i/tau))`` and ``/ -(omega - i/tau)**2``
            (with the real ``omega``, a windowed accelerance's receptance would
            carry a phase error of ``2/(tau omega)``).

        Returns
        -------
        FRF
            The receptance (m/N for y/f); this FRF itself when it is one.
        """
        if self.quantity == "receptance":
            return self
        if not (np.isfinite(decay) and decay >= 0):
            raise InvalidValueError(f"decay: got {decay!r}; expected a finite rate >= 0 in 1/s (1/tau of the window)")
        omega = self.frequency.omega - 1j * decay if decay else self.frequency.omega
        if omega[0] == 0.0:
            article = "an" if self.quantity[0] in "aeiou" else "a"
            raise InvalidValueError(
                f"frequency: the grid starts at 0 Hz, where {article} {self.quantity} has no "
                "receptance; crop it first, e.g. frf.crop(lo='1 Hz')"
            )
        factor = 1j * omega if self.quantity == "mobility" else -(omega**2)
        return attrs.evolve(self, data=self.data / factor[:, None, None], quantity="receptance")

    # -- edges: plots and files -----------------------------------------------
    def plot(self, ax: Any = None, **kw: Any):
        """Plot with :func:`substructure.plot.plot_frf`; returns the Figure.

        Parameters
        ----------
        ax : Axes, sequence of Axes, Figure or None
            Where to draw (an earlier figure overlays); None makes a new figure.
        **kw
            Options of :func:`~substructure.plot.plot_frf`: ``kind`` (``"bode"``,
            ``"real-imag"``, ``"nyquist"``), ``unit`` (``"um/N"`` by default,
            ``"m/N"``, ``"mm/N"``, ``"nm/N"``), ``title``, ``entries``,
            ``label``, ``parts``, ``note`` and line options.

        Returns
        -------
        matplotlib.figure.Figure
            The figure (never shown by the library).
        """
        from .plotting import draw_frf

        return draw_frf(self, ax=ax, **kw)

    def to_csv(self, path: Any, overwrite: bool = False) -> None:
        """Write a 1x1 FRF to a CSV file (:func:`substructure.io.frf_files.write_csv`).

        A mobility or an accelerance is written with its unit in the header,
        so that :meth:`from_csv` reads it back as what it is.

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        overwrite : bool, default False
            Whether an existing file may be replaced.

        Raises
        ------
        OutputExistsError
            (a ``FileExistsError``) When ``path`` exists and ``overwrite`` is
            false, naming the path.
        """
        from .files.csv_files import write_csv

        write_csv(self, path, overwrite=overwrite)

    @classmethod
    def from_csv(cls, path: Any, output: str = "response", input: str = "excitation",
                 quantity: str | None = None) -> FRF:
        """Read a CSV file (:func:`substructure.io.frf_files.read_csv`).

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        output : str
            Output label of the FRF read.
        input : str
            Input label.
        quantity : {"receptance", "mobility", "accelerance"}, optional
            What the file holds; default: what the header's units say (an export
            with ``[g/N]`` is an accelerance, converted), else a receptance.

        Returns
        -------
        FRF
            The FRF (a receptance in m/N), shape ``(n_freq, 1, 1)``.
        """
        from .files.csv_files import read_csv

        return read_csv(path, output=output, input=input, quantity=quantity)

    def to_uff(self, path: Any, overwrite: bool = False) -> None:
        """Write type-58 records, one per entry (:func:`substructure.io.frf_files.write_uff`).

        Parameters
        ----------
        path, overwrite
            As for :meth:`to_csv` (an existing file is kept unless ``overwrite``).
        """
        from .files.uff_writer import write_uff

        write_uff(self, path, overwrite=overwrite)

    @classmethod
    def from_uff(cls, path: Any, record: int | None = None, quantity: str | None = None) -> FRF:
        """Read type-58 records (:func:`substructure.io.frf_files.read_uff`).

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        record : int, optional
            Read only this record (0-based); default all.
        quantity : {"receptance", "mobility", "accelerance"}, optional
            What the records hold when the file does not say.

        Returns
        -------
        FRF
            The FRF.
        """
        from .files.uff_reader import read_uff

        return read_uff(path, record=record, quantity=quantity)

    def __hash__(self) -> int:
        return hash((self.frequency, self.data.tobytes(), self.outputs, self.inputs, self.quantity))

    def __repr__(self) -> str:
        def short(labels: tuple[str, ...]) -> str:
            return ", ".join(labels) if len(labels) <= 4 else f"{', '.join(labels[:3])}, ... ({len(labels)})"

        return (
            f"FRF({self.quantity}, {self.frequency!r}, {len(self.outputs)}x{len(self.inputs)}, "
            f"outputs=[{short(self.outputs)}], inputs=[{short(self.inputs)}])"
        )


# the class the files of frf.files are read into (they cannot import this module, which imports them)
register_frf_class(FRF)


def frf_checked(value: Any, field: str = "frf") -> FRF:
    """``value`` when it is an :class:`FRF`, else an error naming ``field`` (the one check of an FRF argument).

    Parameters
    ----------
    value : object
        What was given.
    field : str, default "frf"
        Its name in the message.

    Returns
    -------
    FRF
        ``value``.
    """
    if not isinstance(value, FRF):
        raise InvalidValueError(f"{field}: got {type(value).__name__}; expected an FRF")
    return value
