"""Zero-order approximation of milling stability (Altintas & Budak 1995).

The cutting force matrix ``K(t)`` (:mod:`~substructure.stability.cutting`) is
replaced by its average ``K0`` over a tooth period.  Chatter at frequency
``omega`` with depth ``a`` and delay ``T`` then needs

``det[I - a (1 - exp(-i omega T)) K0 G(i omega)] = 0``,

with ``G`` the 2x2 tool point receptance in x and y.  For each eigenvalue
``lambda`` of ``K0 G`` with ``Re lambda > 0``:

* depth limit ``a = 1 / (2 Re lambda)`` (Altintas's
  ``-2 pi Lambda_R (1 + kappa^2) / (N Kt)`` written with ``lambda = -N Kt / (4 pi Lambda)``),
* phase ``omega T = pi + 2 arg(lambda) + 2 pi k`` for lobe ``k = 0, 1, ...``,
* spindle speed ``n = 60 / (N T)`` rpm.

Every frequency line of the FRF gives one point of every lobe: no modal fit
is needed, any number of modes and cross terms are taken as they are.  The
lobes are mapped onto the requested speeds by linear interpolation between
neighbouring lines, and the depth limit at a speed is the lowest lobe there.
The absolute (speed-independent) limit is the smallest ``a`` over all lines,
refined between lines.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..errors import InvalidValueError
from ..frf import FRF, Frequency
from .band import choose_band
from .modal import ModalModel
from .speeds import as_speed_rpm
from .result import Lobes, StabilityWarning
from .structure import xy_receptance

__all__ = ["zoa", "zoa_eigenvalues", "MAX_LOBE_POINTS", "graded_frequency", "GRADED_STEPS", "check_band"]

MAX_LOBE_POINTS = 5_000_000
"""Most points (FRF lines x lobes x 2 branches) the zero order builds, about 40 MB per array."""


GRADED_STEPS = 50
"""Lines per damping ratio of the graded grid of a modal model (``graded_frequency``): the relative step is
``zeta / GRADED_STEPS`` at a mode, as on the model's default grid, and ``|ln(f / f_n)| / GRADED_STEPS`` away from it,
where the receptance changes by about ``1 / GRADED_STEPS`` of itself from line to line."""


def graded_frequency(model: ModalModel) -> Frequency:
    """Lines from 0.3 f_min to 3 f_max, as fine as the default grid at the modes and coarser away from them.

    At ``f`` the relative step is ``min_i max(zeta_i, |ln(f / f_i)|) / GRADED_STEPS`` over the modes ``i``: a
    mode's half-power band holds ``2 GRADED_STEPS`` lines, and between the modes the step grows with the distance
    from the nearest one, where the receptance varies on that scale.  For one mode about
    ``GRADED_STEPS (2 + ln(1.2 / zeta) + ln(1.1 / zeta))`` lines (566 for zeta = 0.011) instead of the default
    grid's ``ln(10) GRADED_STEPS / zeta`` (10,469).

    Parameters
    ----------
    model : ModalModel
        The modes.

    Returns
    -------
    Frequency
        The lines, in Hz.
    """
    a = model.arrays()
    ln_fn, zeta = np.log(a["frequency_hz"]), a["damping_ratio"]
    ln_f, ln_hi = np.log(0.3 * a["frequency_hz"].min()), np.log(3.0 * a["frequency_hz"].max())
    lines = [ln_f]
    while ln_f < ln_hi:
        ln_f += float(np.min(np.maximum(zeta, np.abs(ln_f - ln_fn)))) / GRADED_STEPS
        lines.append(min(ln_f, ln_hi))
    return Frequency.from_hz(np.exp(lines))


EDGE_WARNING = ("zoa: the oriented FRF's most negative real part, the absolute limit, is at the {edge} line of the "
                "band ({hz:g} Hz): the minimum may lie outside it (a mode outside the band), and the limit be too "
                "deep; extend the band")
"""The warning when the absolute limit of FRF data sits on an edge of the band (not the lower edge the automatic
band chose above a mass line)."""


ABOVE_WARNING = ("zoa: a mode lies above the band: {above}; the lobes do not see it, and the limit may be far "
                 "shallower than found; measure the FRF beyond that mode (a harder hammer tip) and extend the band")
"""The warning when FRF data end on the rising flank of a resonance above the band (``FlexibleBand.above``)."""


def _warn_above(used: Any) -> None:
    if used is not None and used.above:
        warnings.warn(ABOVE_WARNING.format(above=used.above), StabilityWarning, stacklevel=3)


def zoa_eigenvalues(k0: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Eigenvalues of ``K0 @ G`` per line, shape ``(n, 2)``, ordered to follow each branch.

    Parameters
    ----------
    k0 : ndarray, shape (2, 2)
        Mean cutting force matrix in N/m^2.
    g : ndarray, shape (n, 2, 2)
        Receptances in m/N.
    """
    m = np.einsum("ij,njk->nik", k0, g)
    half_tr = 0.5 * (m[:, 0, 0] + m[:, 1, 1])
    det = m[:, 0, 0] * m[:, 1, 1] - m[:, 0, 1] * m[:, 1, 0]
    root = np.sqrt(half_tr**2 - det)
    lam = np.stack([half_tr + root, half_tr - root], axis=1)
    if lam.shape[0] > 1:
        # keep branches continuous across the branch cut of the square root
        same = np.abs(lam[1:] - lam[:-1]).sum(axis=1)
        cross = np.abs(lam[1:] - lam[:-1, ::-1]).sum(axis=1)
        parity = np.concatenate([[0], np.cumsum(cross < same) % 2])
        flip = parity == 1
        lam[flip] = lam[flip, ::-1]
    return lam


def _refine_data(f: np.ndarray, a: np.ndarray, i: int) -> tuple[float, float]:
    """Vertex of the parabola through three lines around the smallest ``a`` (when it is lower)."""
    if 0 < i < a.size - 1 and np.all(np.isfinite(a[i - 1:i + 2])):
        x, y = f[i - 1:i + 2], a[i - 1:i + 2]
        c2, c1, c0 = np.polyfit(x - x[1], y, 2)
        dx = -c1 / (2 * c2) if c2 > 0 else np.nan
        if x[0] - x[1] <= dx <= x[2] - x[1]:
            return float(min(a[i], c0 - c1**2 / (4 * c2))), float(x[1] + dx)
    return float(a[i]), float(f[i])


def _refine_model(structure: Any, k0: np.ndarray, f: np.ndarray, i: int, branch: int) -> tuple[float, float]:
    """Minimise ``a(f)`` of a modal model between the neighbours of line ``i``."""
    from scipy.optimize import minimize_scalar

    lo, hi = f[max(i - 1, 0)], f[min(i + 1, f.size - 1)]

    def depth(x: float) -> float:
        lam = zoa_eigenvalues(k0, structure.receptance(np.array([x])))[0]
        re = lam.real.max()
        return 1.0 / (2.0 * re) if re > 0 else np.inf

    sol = minimize_scalar(depth, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10 * hi})
    return float(sol.fun), float(sol.x)


def _lobes_on_speeds(speeds: np.ndarray, n: np.ndarray, a: np.ndarray, f: np.ndarray, ok: np.ndarray):
    """Lowest lobe at each speed; ``n`` (L, m) speeds of L lobes, ``a``/``f`` (L, m), ``ok`` (L, m-1) segments."""
    lobe, i = np.nonzero(ok)
    n0, n1 = n[lobe, i], n[lobe, i + 1]
    lo = np.searchsorted(speeds, np.minimum(n0, n1), side="left")
    hi = np.searchsorted(speeds, np.maximum(n0, n1), side="right")
    count = hi - lo
    keep = count > 0
    lobe, i, n0, n1, lo, count = lobe[keep], i[keep], n0[keep], n1[keep], lo[keep], count[keep]
    depth = np.full(speeds.size, np.inf)
    freq = np.full(speeds.size, np.nan)
    if count.size == 0:
        return depth, freq
    seg = np.repeat(np.arange(count.size), count)
    start = np.cumsum(count) - count
    j = lo[seg] + np.arange(seg.size) - start[seg]
    span = n1[seg] - n0[seg]
    t = np.where(span != 0, (speeds[j] - n0[seg]) / np.where(span != 0, span, 1.0), 0.0)
    li, ii = lobe[seg], i[seg]
    aj = a[li, ii] + t * (a[li, ii + 1] - a[li, ii])
    fj = f[li, ii] + t * (f[li, ii + 1] - f[li, ii])
    order = np.lexsort((aj, j))
    j, aj, fj = j[order], aj[order], fj[order]
    first = np.flatnonzero(np.diff(j, prepend=-1))
    depth[j[first]] = aj[first]
    freq[j[first]] = fj[first]
    return depth, freq


class _ZoaEnvelope:
    """Every lobe of a zero-order result, to evaluate its envelope at any speed exactly.

    ``n``, ``a``, ``f``: (L, m) speed [rpm], depth [m] and chatter frequency
    [Hz] of L lobes at the m FRF lines; ``ok``: (L, m-1) the segments that
    belong to a lobe.
    """

    def __init__(self, n: np.ndarray, a: np.ndarray, f: np.ndarray, ok: np.ndarray) -> None:
        self.n, self.a, self.f, self.ok = n, a, f, ok
        # vertices where the minimum of a window can lie: local minima of a lobe and lobe ends
        seg_l = np.concatenate([np.zeros((ok.shape[0], 1), bool), ok], axis=1)  # segment to the left exists
        seg_r = np.concatenate([ok, np.zeros((ok.shape[0], 1), bool)], axis=1)
        a_l = np.concatenate([np.full((a.shape[0], 1), np.inf), a[:, :-1]], axis=1)
        a_r = np.concatenate([a[:, 1:], np.full((a.shape[0], 1), np.inf)], axis=1)
        low = (~seg_l | (a <= a_l)) & (~seg_r | (a <= a_r)) & (seg_l | seg_r) & np.isfinite(a)
        self.critical = np.unique(n[low])

    def limit(self, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        order = np.argsort(speeds)
        depth, chatter = _lobes_on_speeds(speeds[order], self.n, self.a, self.f, self.ok)
        out_d, out_f = np.empty_like(depth), np.empty_like(chatter)
        out_d[order], out_f[order] = depth, chatter
        return out_d, out_f

    def window_minimum(self, lo: np.ndarray, hi: np.ndarray):
        crit = self.critical[(self.critical >= lo.min()) & (self.critical <= hi.max())]
        speeds = np.concatenate([lo, hi, crit])
        depth, chatter = self.limit(speeds)
        w = lo.size
        best = np.where(depth[:w] <= depth[w:2 * w], 0, 1)
        rows = np.arange(w)
        d = np.where(best == 0, depth[:w], depth[w:2 * w])
        at = np.where(best == 0, lo, hi)
        fc = np.where(best == 0, chatter[:w], chatter[w:2 * w])
        if crit.size:
            cd, cf = depth[2 * w:], chatter[2 * w:]
            start = np.searchsorted(crit, lo, side="left")
            stop = np.searchsorted(crit, hi, side="right")
            for i in rows[stop > start]:  # windows holding a lobe bottom (a few per window)
                k = start[i] + int(np.argmin(cd[start[i]:stop[i]]))
                if cd[k] < d[i]:
                    d[i], at[i], fc[i] = cd[k], crit[k], cf[k]
        return d, at, fc


def _lines(structure: Any, frequency: Frequency | None, k0: np.ndarray, teeth: int, lowest_rpm: float):
    """Lines, eigenvalues, where they give a lobe, depths, phases and the last lobe needed down to ``lowest_rpm``."""
    f, g = xy_receptance(structure, frequency)
    lam = zoa_eigenvalues(k0, g)  # (m, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        valid = lam.real > 1e-300
        a = np.where(valid, 1.0 / (2.0 * lam.real), np.inf)  # (m, 2)
        theta = np.pi + 2.0 * np.angle(lam)  # in (0, 2 pi) where valid
    # lobes: n = 60 f / (N (theta / 2 pi + k)), k = 0 .. k_max over both branches
    k_max = int(np.ceil(60.0 * f[valid.any(axis=1)].max() / (teeth * lowest_rpm))) if valid.any() else 0
    return f, lam, valid, a, theta, k_max


def _absolute(structure: Any, used: Any, k0: np.ndarray, f: np.ndarray, a: np.ndarray,
              valid: np.ndarray, lam: np.ndarray) -> tuple[float, float] | None:
    """The absolute limit and its frequency (None: no line gives a lobe); for FRF data the band's checks."""
    # the sign decides whether the band holds a resonance, whatever the scale (a cutting pressure of 1e-300 Pa
    # leaves every line below ``valid``'s floor: no finite limit, which is not a band without a resonance)
    if not (lam.real > 0).any() and isinstance(structure, FRF):
        raise InvalidValueError(
            f"zoa: the oriented FRF's real part is never negative from {f[0]:g} to {f[-1]:g} Hz: the band holds no "
            "resonance of the tool point (no limit can be found there, which is not a cut free of chatter); give "
            "the FRF around the tool's modes (band=(lo, hi); --band LO:HI on the command line)")
    if not valid.any():
        return None
    i, branch = np.unravel_index(np.argmin(a, axis=None), a.shape)
    if not isinstance(structure, FRF):
        return _refine_model(structure, k0, f, i, branch)
    if i in (0, f.size - 1) and not (i == 0 and used is not None and used.excluded_hz is not None
                                     and used.kind != "user"):
        warnings.warn(EDGE_WARNING.format(edge="first" if i == 0 else "last", hz=f[i]), StabilityWarning,
                      stacklevel=3)
    return _refine_data(f, a[:, branch], i)


def check_band(structure: Any, cut: Any, band: Any = "auto") -> None:
    """The checks :func:`zoa` makes of FRF data in the band, without its lobes (which grow as the speeds fall).

    Parameters
    ----------
    structure : FRF or ModalModel
        As for :func:`zoa`.
    cut : MillingCut or TurningCut
        The cut (its mean force matrix orients the FRF).
    band : "auto", "all", (lo_hz, hi_hz) or FlexibleBand, default "auto"
        As for :func:`zoa`.

    Raises
    ------
    InvalidValueError
        For FRF data whose oriented real part is never negative in the band (no resonance in it).

    Warns
    -----
    StabilityWarning
        When the absolute limit lies at the first or last line of FRF data (``EDGE_WARNING``), or the data end on
        the flank of a resonance above the band (``ABOVE_WARNING``).
    """
    structure, used = choose_band(structure, band)
    _warn_above(used)
    k0 = cut.mean_force_matrix()
    f, lam, valid, a, _, _ = _lines(structure, None, k0, cut.regenerations_per_revolution, np.inf)
    _absolute(structure, used, k0, f, a, valid, lam)


def zoa(structure: Any, cut: Any, speeds: Any, *, frequency: Frequency | None = None,
        label: str | None = None, band: Any = "auto") -> Lobes:
    """Stability lobes by the zero-order approximation.

    Parameters
    ----------
    structure : FRF or ModalModel
        The tool point receptances: an FRF labelled ``x``/``y``
        (:func:`~substructure.stability.xy_frf`, cross terms included when
        given), a one-entry translational FRF (a symmetric tool: ``y = x``),
        or a :class:`~substructure.stability.ModalModel`.
    cut : MillingCut or TurningCut
        The cut (cutting pressures in Pa, tool and radial depth in m).
    speeds : pint.Quantity
        Spindle speeds in rpm, strictly increasing
        (:func:`~substructure.stability.spindle_speeds`).
    frequency : Frequency, optional
        For a modal model: the lines to evaluate on (default: the model's
        default grid, or ``graded_frequency`` when that grid times the
        lobes down to the lowest speed exceeds ``MAX_LOBE_POINTS``).
    label : str, optional
        Legend label of the result.
    band : "auto", "all", (lo_hz, hi_hz) or FlexibleBand, default "auto"
        FRF data only: which lines to use.  ``"auto"`` leaves out a
        rigid-body mass line and suspension modes
        (:func:`~substructure.stability.flexible_band`); ``"all"`` uses every
        line; a pair crops to that band; a :class:`FlexibleBand` (e.g. from
        :func:`~substructure.stability.assembly_structure`) is applied as it
        is.  The choice is kept in ``Lobes.band``.

    Returns
    -------
    Lobes
        With the absolute limit, the individual lobes and the band used.

    Raises
    ------
    InvalidValueError
        For FRF data whose oriented real part is never negative in the band
        (no resonance in it), and when the lobes would need more than ``MAX_LOBE_POINTS`` (5,000,000) points
        (FRF lines x lobes x 2): crop or thin the FRF, or raise the lowest
        speed.  A modal model whose default grid is too fine for the lobes
        down to the lowest speed is evaluated on ``graded_frequency``
        instead (as fine at the modes, coarser away from them); beyond that
        the message names the lowest speed that fits.

    Warns
    -----
    StabilityWarning
        When the absolute limit lies at the first or last line of FRF data
        (``EDGE_WARNING``): the minimum may lie outside the band; extend
        it.  Not at the first line of a band chosen automatically above a
        rigid-body mass line.  When FRF data end on the flank of a resonance
        above the band (``ABOVE_WARNING``, ``FlexibleBand.above``): the lobes
        do not see that mode, and :func:`recommend` recommends nothing.
    """
    speeds_rpm = as_speed_rpm(speeds)
    structure, used = choose_band(structure, band)
    _warn_above(used)
    k0 = cut.mean_force_matrix()
    teeth = cut.regenerations_per_revolution
    f, lam, valid, a, theta, k_max = _lines(structure, frequency, k0, teeth, speeds_rpm[0])
    points = 2 * (k_max + 1) * f.size
    graded = points > MAX_LOBE_POINTS and frequency is None and isinstance(structure, ModalModel)
    if graded:  # the default grid is fine everywhere: at low speeds too many lines for so many lobes
        f, lam, valid, a, theta, k_max = _lines(structure, graded_frequency(structure), k0, teeth, speeds_rpm[0])
        points = 2 * (k_max + 1) * f.size
    if points > MAX_LOBE_POINTS:
        most = MAX_LOBE_POINTS // (2 * f.size) - 1  # lobes that fit
        lowest = 60.0 * f[valid.any(axis=1)].max() / (teeth * most) if most > 0 else np.inf
        what = (f"{f.size} lines graded around the modes" if graded else
                f"{f.size} {'FRF' if isinstance(structure, FRF) else 'frequency'} lines")
        change = (f"raise the lowest spindle speed to {lowest:.4g} rpm or more (--speeds on the command line)" if graded
                  else "crop the FRF to the band that matters, use fewer lines, or raise the lowest spindle speed "
                  "(fewer lobes)")
        raise InvalidValueError(
            f"zoa: {what} x {k_max + 1} lobes x 2 = {points:.3g} lobe points down to {speeds_rpm[0]:g} rpm, more "
            f"than the limit MAX_LOBE_POINTS = {MAX_LOBE_POINTS:.3g} (about 40 MB per array); {change}")
    absolute = _absolute(structure, used, k0, f, a, valid, lam)
    if absolute is None:
        return Lobes("zoa", speeds_rpm, np.full(speeds_rpm.size, np.inf), np.full(speeds_rpm.size, np.nan),
                     cut=cut, absolute_limit_m=float("inf"), label=label, band=used)
    a_abs, f_abs = absolute
    k = np.arange(k_max + 1)
    phase = theta.T[:, None, :] / (2.0 * np.pi) + k[None, :, None]  # (2, K, m)
    with np.errstate(divide="ignore"):
        n = 60.0 * f[None, None, :] / (teeth * phase)  # inf only on lines that are not valid
    ok_line = np.broadcast_to(valid.T[:, None, :], n.shape)
    ok = ok_line[..., 1:] & ok_line[..., :-1] & (np.abs(np.diff(np.broadcast_to(theta.T[:, None, :], n.shape),
                                                                  axis=-1)) < np.pi)
    shape = (n.shape[0] * n.shape[1], n.shape[2])
    aa = np.broadcast_to(a.T[:, None, :], n.shape).reshape(shape)
    ff = np.broadcast_to(f[None, None, :], n.shape).reshape(shape)
    envelope = _ZoaEnvelope(n.reshape(shape), aa, ff, ok.reshape(shape[0], -1))
    depth, chatter = envelope.limit(speeds_rpm)
    # the individual lobes, for plots: within the speed range and below a few times the deepest limit
    finite = depth[np.isfinite(depth)]
    cap = 5.0 * (finite.max() if finite.size else a_abs)
    curves = []
    for row_n, row_a, row_ok in zip(n.reshape(shape), aa, ok_line.reshape(shape)):
        show = row_ok & (row_a <= cap) & (row_n >= speeds_rpm[0] * 0.98) & (row_n <= speeds_rpm[-1] * 1.02)
        if show.sum() > 1:
            curves.append((np.where(show, row_n, np.nan), np.where(show, row_a, np.nan)))
    return Lobes("zoa", speeds_rpm, depth, chatter, cut=cut, absolute_limit_m=a_abs,
                 absolute_limit_frequency_hz=f_abs, lobes=tuple(curves), label=label, band=used, source=envelope)
