"""Which part of a tool point FRF the stability methods may use: no rigid-body or suspension lines.

A free-free model (the thesis's test rig, the built-in assembly) has no
static stiffness: below its first antiresonance its tool point receptance is
the mass line ``-1/(m omega^2)`` of the whole body moving rigidly.  A model or
a test piece hung on soft supports has suspension modes down there instead.
Neither exists on the machine, where the spindle sits in its bearings, and
both would give spurious lobes: chatter "at" 20-120 Hz with a limit a
fraction of the real one.  :func:`flexible_band` finds that region in FRF
data, :func:`assembly_structure` in a model (where it can ask the model what
its supports do), and :class:`FlexibleBand` records the choice, so that it
is reported with the lobes and a recommendation can never sit on such a
line.

The rules, each tied to the physics of a driving-point receptance
(poles and zeros alternate along the frequency axis, ``Im H <= 0``):

* **Mass line.**  A line is mass-like when ``Re H < 0`` and
  ``|Im H| <= tan(30 deg) |Re H|`` (phase within 30 degrees of -180).  When
  the FRF starts mass-like, the whole body moves rigidly there; the band
  starts at the first antiresonance (the first minimum of ``|H|``) above,
  which separates the mass line from the first flexible mode.
* **Suspension.**  In data, the lowest peaks count as suspension modes when
  they lie at most a tenth of the frequency of the next peak (modal testing
  practice keeps suspension modes below 10-20 % of the first flexible mode;
  Ewins, *Modal Testing*, section 3.3) and the FRF is mass-like above them;
  the band starts at the antiresonance after the last of them.
* **Model.**  An assembly without supports is free-free: the mass-line rule.
  An assembly with supports is compared with itself without them: a mode of
  the supported model below the free-free model's first antiresonance is the
  body moving rigidly on its supports (a suspension mode), and so is the
  region below it when the supports change the FRF above it by less than
  10 % of its largest value (damped suspension modes leave no clear peak); modes above it
  deform the structure (a spindle on its bearings) and are kept.

The rules can be wrong for measured data (a machine's column mode far below
the tool mode looks like a suspension); the choice is always reported, and
``band="all"`` (``--band all``) or an explicit band overrides it.
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from ..errors import InvalidValueError
from ..frf import FRF, frf_checked

__all__ = ["FlexibleBand", "flexible_band", "choose_band", "assembly_structure", "mode_above", "MASS_LINE_PHASE_DEG",
           "SUSPENSION_RATIO"]

MASS_LINE_PHASE_DEG = 30.0
"""A line is mass-like when its phase is within this many degrees of -180."""

SUSPENSION_RATIO = 0.1
"""In data, peaks at most this fraction of the next peak's frequency may be suspension modes."""

ABOVE_RISE, ABOVE_STRETCH, ABOVE_SCATTER = 2.0, 0.05, 0.1
"""FRF data end on the flank of a resonance above the band (a driving-point FRF's resonances and antiresonances
alternate) when |H| of a direction rises from its last minimum to the band's last line, without a peak between, by
``ABOVE_RISE`` times or more, over at least ``ABOVE_STRETCH`` of the band's last frequency (a rise over the last few
lines is noise, or the edge of an anti-aliasing filter), scattering about its median filter by at most
``ABOVE_SCATTER`` in log, RMS (a smooth flank: an FRF gone to noise above the hammer's band also rises to its end,
with a scatter near 0.5)."""

ABOVE_PROBE, ABOVE_LINES, ABOVE_SHARE = 4.0, 4000, 0.5
"""A model's grid is probed from its stop to ``ABOVE_PROBE`` times it on ``ABOVE_LINES`` log-spaced lines; a peak
there above ``ABOVE_SHARE`` of the band's largest is a mode the lobes would miss (its absolute limit within about
twice the band's), and the grid is refused."""

_PEAK_PROMINENCE = np.log(1.25)  # a peak or valley of |H| stands out by 25 % (in log |H|)


@attrs.frozen
class FlexibleBand:
    """The lines of a tool point FRF that stability may use, and why.

    Parameters
    ----------
    lo_hz, hi_hz : float
        First and last frequency [Hz] used.
    kind : str
        ``"free-free"`` (a mass line left out), ``"suspended"`` (suspension
        modes left out), ``"supported"`` (a model on its supports: nothing
        left out), ``"flexible"`` (data with no mass line: nothing left
        out), ``"user"`` (a band given by the user) or ``"all"`` (detection
        switched off).
    excluded_hz : (float, float) or None
        The region left out [Hz], from the first line to the start of the
        band; ``None`` when nothing was left out.
    suspension_hz : tuple of float
        Frequencies [Hz] of the peaks taken as suspension modes.
    apparent_mass_kg : float or None
        ``-1 / (omega^2 Re H)`` on the mass line at its first line: the mass
        the tool point "sees" moving rigidly (``None`` without a mass line).
    reason : str
        One sentence for the human output.
    above : str or None
        FRF data that end on the flank of a resonance above the band
        (``mode_above``): what rises where; the lobes do not see that
        mode, :func:`~substructure.stability.zoa` warns and
        :func:`~substructure.stability.recommend` recommends nothing.
    model : bool
        Chosen on a model's receptance (:func:`assembly_structure`) whose
        grid was checked for modes above it (not a model with a measured
        component, known on its lines only).
    """

    lo_hz: float
    hi_hz: float
    kind: str
    excluded_hz: tuple | None = None
    suspension_hz: tuple = attrs.field(default=(), converter=tuple)
    apparent_mass_kg: float | None = None
    reason: str = ""
    above: str | None = None
    model: bool = False

    def crop(self, frf: FRF) -> FRF:
        """``frf`` restricted to ``lo_hz .. hi_hz``.

        Parameters
        ----------
        frf : FRF
            The FRF this band was found on (or one on the same grid).

        Returns
        -------
        FRF
            The lines from ``lo_hz`` to ``hi_hz``.
        """
        return frf.crop(self.lo_hz, self.hi_hz)

    def contains(self, frequency_hz: Any) -> np.ndarray:
        """Whether frequencies lie in the band.

        Parameters
        ----------
        frequency_hz : array_like
            Frequencies in Hz (``nan`` is not in the band).

        Returns
        -------
        ndarray of bool
            True where a frequency lies in ``lo_hz .. hi_hz``.
        """
        f = np.asarray(frequency_hz, dtype=float)
        return (f >= self.lo_hz * (1 - 1e-12)) & (f <= self.hi_hz * (1 + 1e-12))

    def to_json(self) -> dict:
        """The ``structure_band`` object of ``substructure lobes --json``.

        Returns
        -------
        dict
            ``lo_hz``, ``hi_hz``, ``kind``, ``excluded_hz``, ``suspension_hz``,
            ``apparent_mass_kg``, ``reason``, ``mode_above`` (``above``, or None).
        """
        return {
            "lo_hz": self.lo_hz,
            "hi_hz": self.hi_hz,
            "kind": self.kind,
            "excluded_hz": None if self.excluded_hz is None else list(self.excluded_hz),
            "suspension_hz": list(self.suspension_hz),
            "apparent_mass_kg": self.apparent_mass_kg,
            "mode_above": self.above,
            "reason": self.reason,
        }


# -- data ------------------------------------------------------------------------------


def _diagonals(frf: FRF) -> list[np.ndarray]:
    frf_checked(frf)
    data = frf.to_receptance().data
    n = min(data.shape[1], data.shape[2])
    return [data[:, i, i] for i in range(n)]


def _mass_like(h: np.ndarray) -> np.ndarray:
    return (h.real < 0) & (np.abs(h.imag) <= np.tan(np.radians(MASS_LINE_PHASE_DEG)) * np.abs(h.real))


def _extrema(mag: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    from scipy.signal import find_peaks

    log = np.log(np.maximum(mag, 1e-300))
    peaks, _ = find_peaks(log, prominence=_PEAK_PROMINENCE)
    valleys, _ = find_peaks(-log, prominence=_PEAK_PROMINENCE)
    return peaks, valleys


def _valley_between(mag: np.ndarray, valleys: np.ndarray, lo: int, hi: int) -> int:
    """The deepest valley strictly between lines ``lo`` and ``hi`` (or the minimum of |H| there)."""
    inside = valleys[(valleys > lo) & (valleys < hi)]
    if inside.size:
        return int(inside[np.argmin(mag[inside])])
    return int(lo + 1 + np.argmin(mag[lo + 1:hi])) if hi > lo + 1 else hi


def _one_entry(f: np.ndarray, h: np.ndarray) -> dict:
    """Where the flexible band of one driving-point receptance starts (line index) and why."""
    mag = np.abs(h)
    mass = _mass_like(h)
    peaks, valleys = _extrema(mag)
    head = min(3, f.size)
    result = {"start": 0, "kind": "flexible", "mass": None, "suspension": ()}
    if mass[:head].all():  # a rigid-body mass line from the first line
        flexible = peaks[peaks > 0]
        if flexible.size == 0:
            return {"start": None, "kind": "mass-line-only"}
        start = _valley_between(mag, valleys, 0, int(flexible[0]))
        m = float(-1.0 / ((2 * np.pi * f[0]) ** 2 * h[0].real))
        result = {"start": start, "kind": "free-free", "mass": m, "suspension": ()}
    for j in range(peaks.size - 2, -1, -1):  # the last peak that may be a suspension mode
        p, q = int(peaks[j]), int(peaks[j + 1])
        if f[p] > SUSPENSION_RATIO * f[q]:
            continue
        start = _valley_between(mag, valleys, p, q)
        above = mass[p + 1:start]
        if start > result["start"] and above.size and above.mean() >= 0.8:
            k = p + 1 + int(np.argmax(above))
            m = float(-1.0 / ((2 * np.pi * f[k]) ** 2 * h[k].real))
            return {"start": start, "kind": "suspended", "mass": m,
                    "suspension": tuple(float(f[i]) for i in peaks[:j + 1])}
        break
    return result


def flexible_band(frf: FRF) -> FlexibleBand:
    """The band above the rigid-body and suspension lines of tool point FRF data.

    Parameters
    ----------
    frf : FRF
        A one-entry translational FRF or one labelled ``x``/``y``
        (:func:`~substructure.stability.xy_frf`); mobility and accelerance
        are converted.  Each diagonal entry is examined and the band starts
        above the highest region found.

    Returns
    -------
    FlexibleBand
        Kind ``"free-free"``, ``"suspended"`` or ``"flexible"`` (nothing to
        leave out).

    Raises
    ------
    InvalidValueError
        When the FRF is a mass line over its whole band: no flexible mode to
        compute lobes from.

    Notes
    -----
    See the module documentation for the rules and their sources.
    """
    diagonals = _diagonals(frf)  # (an FRF, checked there)
    f = frf.frequency.hz
    results = [_one_entry(f, h) for h in diagonals]
    if any(r["kind"] == "mass-line-only" for r in results):
        raise InvalidValueError(
            f"frf: the FRF is a mass line (rigid-body motion, phase near -180 degrees, no resonance) over its "
            f"whole band {f[0]:g}..{f[-1]:g} Hz: there is no flexible mode to compute lobes from; extend the "
            "band upwards, or give band='all' to use it as it is")
    worst = max(results, key=lambda r: r["start"])
    start = worst["start"]
    if start == 0:
        return FlexibleBand(float(f[0]), float(f[-1]), "flexible",
                            reason="no rigid-body mass line or suspension mode found; the whole FRF is used")
    if start >= f.size - 2:
        raise InvalidValueError(
            f"frf: the rigid-body/suspension region reaches {f[start]:g} Hz, the end of the data; "
            "there is no flexible mode to compute lobes from")
    excluded = (float(f[0]), float(f[start]))
    if worst["kind"] == "free-free":
        reason = (f"rigid-body mass line (apparent mass {worst['mass']:.3g} kg) below the first antiresonance "
                  f"at {f[start]:.5g} Hz left out")
    else:
        peaks = ", ".join(f"{p:.4g}" for p in worst["suspension"])
        reason = (f"suspension modes at {peaks} Hz and the mass line above them left out, up to the "
                  f"antiresonance at {f[start]:.5g} Hz")
    return FlexibleBand(float(f[start]), float(f[-1]), worst["kind"], excluded, worst["suspension"],
                        worst["mass"], reason)


def choose_band(structure: Any, band: Any = "auto") -> tuple[Any, FlexibleBand | None]:
    """Apply a band choice to a structure: the lines stability will use, and the record of the choice.

    Parameters
    ----------
    structure : FRF or ModalModel
        Tool point receptances, or modes (used as they are).
    band : "auto", "all", (lo_hz, hi_hz) or FlexibleBand, default "auto"
        ``"auto"``: :func:`flexible_band`; ``"all"`` (or None): every line;
        a pair: that band in Hz; a :class:`FlexibleBand`: applied as it is.

    Returns
    -------
    (structure, FlexibleBand or None)
        The cropped FRF and the band (``None`` for modes).
    """
    if not isinstance(structure, FRF):
        if band not in ("auto", "all", None):
            raise InvalidValueError("band: modal parameters are used as they are; band applies to FRF data")
        return structure, None
    if isinstance(band, FlexibleBand):
        return band.crop(structure), band
    if band == "auto":
        found = flexible_band(structure)
        return found.crop(structure), _judged(found, found.crop(structure))
    hz = structure.frequency.hz
    if band in ("all", None):
        return structure, _judged(FlexibleBand(float(hz[0]), float(hz[-1]), "all", reason="the whole FRF is used "
                                               "(rigid-body detection switched off)"), structure)
    try:
        lo, hi = (float(v) for v in band)
    except (TypeError, ValueError, OverflowError):
        raise InvalidValueError(
            f"band: got {band!r}; expected 'auto', 'all', (lo_hz, hi_hz) or a FlexibleBand") from None
    cropped = structure.crop(lo, hi)
    f = cropped.frequency.hz
    excluded = (float(hz[0]), float(f[0])) if f[0] > hz[0] else None
    return cropped, _judged(FlexibleBand(float(f[0]), float(f[-1]), "user", excluded,
                                         reason=f"band {lo:g}..{hi:g} Hz given by the user"), cropped)


def _judged(band: FlexibleBand, frf: FRF) -> FlexibleBand:
    """The band with what :func:`mode_above` finds in the FRF data it holds."""
    return attrs.evolve(band, above=mode_above(frf))


def mode_above(frf: FRF) -> str | None:
    """Whether FRF data end on the flank of a resonance above their band (the rules of ``ABOVE_RISE``).

    |H| of each diagonal entry is median-filtered over a hundredth of the
    lines; after its last peak it must rise from its minimum to the last
    line, its largest value there, by ``ABOVE_RISE`` or more, over at least
    ``ABOVE_STRETCH`` of the last frequency, smoothly (``ABOVE_SCATTER``).

    Parameters
    ----------
    frf : FRF
        Tool point receptances (the diagonal entries are judged).

    Returns
    -------
    str or None
        What rises where (``"the FRF (x) rises from 1178 Hz to the band's last line (1400 Hz), 4.98 times,
        without a peak"``), or None.
    """
    from scipy.ndimage import median_filter
    from scipy.signal import find_peaks

    f = frf.frequency.hz
    seen: list[np.ndarray] = []
    for d in range(min(frf.shape[1], frf.shape[2])):
        mag = np.abs(frf.data[:, d, d])
        if any(np.array_equal(mag, m) for m in seen):
            continue  # y = x: said once
        seen.append(mag)
        raw = np.log(np.maximum(mag, 1e-300))
        log = median_filter(raw, size=max(3, mag.size // 100) | 1, mode="nearest")
        peaks, _ = find_peaks(log, prominence=_PEAK_PROMINENCE)
        start = int(peaks[-1]) + 1 if peaks.size else 0
        j = start + int(np.argmin(log[start:]))
        ratio = float(np.exp(log[-1] - log[j]))
        smooth = float(np.sqrt(np.mean((raw[j:] - log[j:]) ** 2))) <= ABOVE_SCATTER  # a flank, not noise
        if ratio >= ABOVE_RISE and f[-1] - f[j] >= ABOVE_STRETCH * f[-1] and log[-1] >= log[j:].max() and smooth:
            return (f"the FRF ({frf.outputs[d]}) rises from {f[j]:g} Hz to the band's last line ({f[-1]:g} Hz), "
                    f"{ratio:.3g} times, without a peak")
    return None


# -- models ----------------------------------------------------------------------------


def assembly_structure(assembly: Any, at: str, frequency: Any = None) -> tuple[FRF, FlexibleBand]:
    """The tool point receptance of a model, as stability should use it, and the band chosen.

    Parameters
    ----------
    assembly : Assembly
        The model, with its supports as modelled (none: free-free).
    at : str
        The tool point with a translational DOF, e.g. ``"tool.tip:y"``.
    frequency : Frequency, optional
        Lines to compute on (default: the assembly's own grid).

    Returns
    -------
    (FRF, FlexibleBand)
        The one-entry receptance cropped to the band, and the band.

    Notes
    -----
    Without supports the model is free-free and the mass-line rule of
    :func:`flexible_band` applies.  With supports, the model without them
    gives the free-free first antiresonance ``f_a``; peaks of the supported
    model below ``f_a`` are the body moving rigidly on soft supports
    (suspension modes) and are left out up to the antiresonance above the
    last of them.  Supports stiff enough to move every mode above ``f_a``
    (bearings, a machine) leave the FRF whole: those modes are the machine's.
    A rigid-body mass line left by supports that do not hold every rigid
    motion is found by the data rule as well.
    """
    if frequency is None:
        frequency = getattr(assembly, "frequency", None)
        if frequency is None:
            raise InvalidValueError("frequency: the assembly has no frequency grid; give frequency=...")
    if str(at).endswith(":theta"):
        raise InvalidValueError(f"at: got {at!r}; the cut needs a translational receptance (':y'), not ':theta'")
    frf = assembly.receptance(at, frequency=frequency)
    f = frf.frequency.hz
    data_band = flexible_band(frf)
    if not assembly.supports:
        band = data_band if data_band.kind != "flexible" else attrs.evolve(
            data_band, kind="free-free", reason="free-free model; its grid starts above the rigid-body mass line")
        return band.crop(frf), _probed(assembly, at, band, band.crop(frf))
    free = attrs.evolve(assembly, supports=())
    hf = free.receptance(at, frequency=frequency).data[:, 0, 0]
    ff = _one_entry(f, hf)
    h = frf.data[:, 0, 0]
    mag = np.abs(h)
    peaks, valleys = _extrema(mag)
    band = data_band
    if ff["kind"] == "free-free" and ff["start"] > 0:
        fa = f[ff["start"]]
        low = peaks[f[peaks] < fa]
        higher = peaks[f[peaks] >= fa]
        above = f >= fa
        change = float(np.max(np.abs(h[above] - hf[above])) / np.max(np.abs(hf[above])))
        start = None
        if low.size and higher.size:
            start = _valley_between(mag, valleys, int(low[-1]), int(higher[0]))
        elif change < 0.1 and higher.size:  # damped suspension modes without a clear peak
            start = _valley_between(mag, valleys, int(np.searchsorted(f, fa / 2)), int(higher[0]))
        if start is not None and f[start] > band.lo_hz:
            if low.size:
                what = "suspension modes at " + ", ".join(f"{f[p]:.4g}" for p in low) + " Hz"
            else:
                what = (f"damped suspension modes (no clear peak; the supports change the FRF above {fa:.5g} Hz "
                        f"by at most {change:.1%} of its peak)")
            band = FlexibleBand(
                float(f[start]), float(f[-1]), "suspended", (float(f[0]), float(f[start])),
                tuple(float(f[p]) for p in low), ff["mass"],
                f"{what}, below the free-free model's first antiresonance at {fa:.5g} Hz (the body moving "
                f"rigidly on its supports), left out up to the antiresonance at {f[start]:.5g} Hz")
    if band.kind == "flexible":
        band = attrs.evolve(band, kind="supported",
                            reason="model on its supports: no rigid-body or suspension mode; the whole FRF is used")
    return band.crop(frf), _probed(assembly, at, band, band.crop(frf))


def _probed(assembly: Any, at: str, band: FlexibleBand, frf: FRF) -> FlexibleBand:
    """The model's band, its grid checked for modes above it (:func:`_no_mode_above`), or judged as data are when
    the model cannot be evaluated there."""
    return attrs.evolve(band, model=True) if _no_mode_above(assembly, at, frf) else _judged(band, frf)


def _no_mode_above(assembly: Any, at: str, frf: FRF) -> bool:
    """Refuse a grid that stops below a mode of the model as flexible at the tool point as those in the band;
    False when the model cannot be evaluated above its grid (a measured component: known on its lines only), whose
    FRF is then judged as data are."""
    from ..errors import FrequencyAxisMismatchError
    from ..frf import Frequency

    top = float(frf.frequency.hz[-1])
    probe = Frequency.from_hz(np.geomspace(top, ABOVE_PROBE * top, ABOVE_LINES)[1:])
    try:
        above = np.abs(assembly.receptance(at, frequency=probe).data[:, 0, 0])
    except FrequencyAxisMismatchError:
        return False
    inside = float(np.abs(frf.data[:, 0, 0]).max())
    k = int(np.argmax(above))
    if above[k] > ABOVE_SHARE * inside:
        hz = float(probe.hz[k])
        raise InvalidValueError(
            f"frequency: the grid stops at {top:g} Hz, below a mode of the model at about {hz:.4g} Hz whose peak at "
            f"{at} is {above[k] / inside:.3g} times the largest in the band: the lobes and the tool mode would miss "
            f"it, and a limit found could be far too deep; raise the grid's stop above {2 * hz:.3g} Hz ([frequency] "
            "stop in the assembly file, or frequency=)")
    return True
