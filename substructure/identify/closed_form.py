"""Closed-form joint identification: thesis eq. 2.3, for any joint that splits an assembly in two.

With the receptances of the two sides of a joint (measured, modelled or
mixed) and the coupled receptance measured at a point of one side, the
joint's complex stiffness matrix at every frequency line,
``K = [ [T12^-1 (T11 - Y_c) T21^-1]^-1 - T22 - Y_A ]^-1``.  Exact on exact
data; very sensitive to noise, because of its four 2x2 inversions, whose
condition numbers it reports.
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np

from .. import _blocks as bk
from ..assembly import Assembly
from ..errors import AssemblyError, IllConditionedWarning, InvalidValueError
from ..frf import FRF, Frequency
from ..points import DOFS, parse_point

__all__ = ["ClosedFormResult", "closed_form", "joint_sides", "PARAMETERS", "COND_WARN"]

PARAMETERS = ("k_yf", "k_ym", "k_tm", "c_yf", "c_ym", "c_tm")
"""Names of the joint parameters (``k_ym`` stands for ``k_ym = k_tf``)."""

_ENTRY = {"yf": (0, 0), "ym": (0, 1), "tf": (1, 0), "tm": (1, 1)}
COND_WARN = 1e6
"""Equilibrated condition numbers above this make the closed-form result meaningless at that line."""


def _cond2(a: np.ndarray) -> np.ndarray:
    """Condition numbers of 2x2 stacks ``(2, 2, n)``, equilibrated by their diagonal.

    The entries mix units (m/N, 1/N, 1/(N m)); scaling rows and columns by
    ``|a_ii|^-1/2`` makes the number independent of the units chosen for
    rotations and moments, so that it measures how close the matrix is to
    singular, not the ratio of metres to radians.
    """
    d = np.sqrt(np.abs(np.stack([a[0, 0], a[1, 1]])))
    with np.errstate(divide="ignore", invalid="ignore"):
        scaled = a / (d[:, None, :] * d[None, :, :])
        fro2 = (np.abs(scaled) ** 2).sum(axis=(0, 1))
        det = np.abs(scaled[0, 0] * scaled[1, 1] - scaled[0, 1] * scaled[1, 0])
        root = np.sqrt(np.maximum(fro2**2 - 4 * det**2, 0.0))
        return np.where(det > 0, (fro2 + root) / (2 * det), np.inf)


@attrs.frozen
class ClosedFormResult:
    """The joint's complex stiffness at every frequency line (thesis eq. 2.3).

    Parameters
    ----------
    frequency : Frequency
        The frequency lines, in Hz.
    stiffness : ndarray, shape (n_freq, 2, 2)
        ``K = k + i omega c`` (thesis eq. 2.5), entries ``[[yf, ym], [tf, tm]]`` in N/m, N, N/rad
        and N m/rad.
    condition : dict of str to ndarray
        Condition numbers (2-norm, each matrix equilibrated by its diagonal)
        of the inverted matrices per line: ``"T12"``,
        ``"T21"``, ``"W"`` (``T12^-1 (T11 - Y_c) T21^-1``) and ``"K_inv"``.
    amplification : ndarray
        First-order factor by which a relative error of the coupled
        receptances grows into ``K`` at each line (see :meth:`reliable`).
    """

    frequency: Frequency
    stiffness: np.ndarray = attrs.field(eq=attrs.cmp_using(eq=np.array_equal))
    condition: dict = attrs.field(eq=False)
    amplification: np.ndarray | None = attrs.field(default=None, eq=False)

    def reliable(self, noise: float, tolerance: float = 0.1) -> np.ndarray:
        """Lines where a relative error ``noise`` of the measured coupled
        receptances gives at most ``tolerance`` relative error in ``K``.

        Uses ``amplification``, a first-order estimate of how the relative
        error of ``Y_c`` grows through eq. 2.3: the cancellation in
        ``T11 - Y_c`` (``||T11|| / ||T11 - Y_c||``) times the condition numbers
        of the two inversions that follow.  The thesis's observation that the
        closed form is usable only near the joint's mode shows here as the
        lines where the amplification is small.

        Parameters
        ----------
        noise : float
            Relative error of the measured coupled receptances (0.05 for 5 %).
        tolerance : float
            Largest relative error of ``K`` accepted.

        Returns
        -------
        ndarray
            Boolean, one value per frequency line.
        """
        if self.amplification is None:
            raise InvalidValueError("reliable: this result has no error amplification estimate")
        return self.amplification * noise <= tolerance

    def parameter(self, name: str) -> np.ndarray:
        """``k_yf``, ``k_ym``, ``k_tf``, ``k_tm``, ``c_...`` at every line (SI).

        Parameters
        ----------
        name : str
            ``k_`` or ``c_`` followed by ``yf``, ``ym``, ``tf`` or ``tm``.

        Returns
        -------
        ndarray
            One value per line: k in N/m, N, N/rad or N m/rad; c in the same times s.
        """
        kind, entry = name.split("_", 1)
        if kind not in ("k", "c") or entry not in _ENTRY:
            raise InvalidValueError(f"parameter: got {name!r}; expected k_/c_ with yf, ym, tf or tm")
        i, j = _ENTRY[entry]
        k = self.stiffness[:, i, j]
        return k.real if kind == "k" else k.imag / self.frequency.omega

    def ill_conditioned(self, limit: float = COND_WARN) -> np.ndarray:
        """Lines where an inversion's condition number exceeds ``limit``.

        Parameters
        ----------
        limit : float
            The largest condition number accepted (dimensionless).

        Returns
        -------
        ndarray
            Boolean, one value per frequency line.
        """
        worst = np.max(np.vstack(list(self.condition.values())), axis=0)
        return ~(worst <= limit)

    def band_mean(self, name: str, band) -> float:
        """Mean of a parameter over a band ``(lo, hi)`` in Hz (the thesis's reading of its plots).

        Parameters
        ----------
        name : str
            The parameter, as for :meth:`parameter`.
        band : tuple of float
            ``(lo, hi)`` in Hz.

        Returns
        -------
        float
            The mean, in the parameter's SI unit.

        Raises
        ------
        InvalidValueError
            For a band that is not two limits, or that holds no line of the
            result's frequencies (naming the band and the result's range).
        """
        try:
            lo, hi = band
        except (TypeError, ValueError):
            raise InvalidValueError(f"band: got {band!r}; expected (lo, hi) in Hz, e.g. (500, 1500)") from None
        mask = self.frequency.band_mask(lo, hi)
        if not mask.any():
            raise InvalidValueError(f"band: ({lo!r}, {hi!r}) holds no line of the result's frequencies "
                                    f"{self.frequency.start:g}..{self.frequency.stop:g} Hz; choose a band within them")
        return float(np.mean(self.parameter(name)[mask]))

    def plot(self, names=("k_yf", "c_yf"), band=None, fitted=None, ax=None, measured=None):
        """The frequency-dependent parameters, the chosen band and fitted constants.

        Parameters
        ----------
        names : sequence of str
            Parameters to draw, one panel each.
        band : tuple of float, optional
            Shaded band ``(lo, hi)`` in Hz.
        fitted : mapping, optional
            Fitted constants (SI), with ``NAME_std`` standard deviations.
        ax : sequence of Axes, optional
            Where to draw; a new figure when None.
        measured : FRF, optional
            A measured point FRF drawn on a second axis.

        Returns
        -------
        Figure
            The figure (see :func:`substructure.plot.plot_identification`).
        """
        from .plotting import plot_identification

        return plot_identification(self, names=names, band=band, fitted=fitted, ax=ax, measured=measured)


def closed_form(coupled: FRF, side_a: FRF, side_b: FRF, *, at: str, at_a: str, at_b: str,
                model: str = "full", warn: bool = True) -> ClosedFormResult:
    """Joint stiffness from the coupled and the two sides' receptances (thesis eq. 2.3).

    Parameters
    ----------
    coupled : FRF
        Receptances of the coupled assembly containing the 2x2 point matrix at
        ``at`` (a point of side B), e.g. ``[[H, L], [N, P]]`` at the tool tip.
    side_a : FRF
        Receptances of side A alone containing the 2x2 point matrix at its
        joint point ``at_a`` (e.g. the spindle-holder at the holder tip).
    side_b : FRF
        Receptances of side B alone containing the points ``at`` and ``at_b``
        (e.g. the free-free tool at its tip and base); ``at`` may equal ``at_b``.
    at, at_a, at_b : str
        Point names (without DOF suffix).
    model : {"full", "diagonal"}
        ``"full"``: the fully populated joint of thesis eq. 2.5; ``"diagonal"``:
        the joint of eq. 2.4 (no cross terms), whose inverse ``K^-1`` is then
        diagonal too: its diagonal is inverted entry by entry.  Both are exact
        for data made with a diagonal joint.
    warn : bool
        Warn where an inversion is so ill-conditioned that the result is
        meaningless (condition number above :data:`COND_WARN`).

    Returns
    -------
    ClosedFormResult
        ``K = k + i omega c`` at every line (N/m, N, N/rad, N m/rad; c times s), with the
        condition numbers of the inversions.
    """
    freq = coupled.frequency
    for name, frf in (("side_a", side_a), ("side_b", side_b)):
        if frf.frequency != freq:
            raise InvalidValueError(
                f"{name}: on another frequency axis than the coupled receptances; interpolate first"
            )

    def block(frf: FRF, row: str, col: str, what: str) -> np.ndarray:
        outs = [f"{row}:{d}" for d in DOFS]
        ins = [f"{col}:{d}" for d in DOFS]
        missing = [lbl for lbl in outs if lbl not in frf.outputs] + [lbl for lbl in ins if lbl not in frf.inputs]
        if missing:
            raise InvalidValueError(
                f"closed_form: {what} lacks {', '.join(dict.fromkeys(missing))}; the closed form needs "
                "y and theta at the points (estimate rotations by finite differences: substructure.rdof)"
            )
        return np.moveaxis(frf.select(outs, ins).data, 0, -1)

    t11 = block(side_b, at, at, "side_b")
    t12 = block(side_b, at, at_b, "side_b")
    t21 = block(side_b, at_b, at, "side_b")
    t22 = block(side_b, at_b, at_b, "side_b")
    ya = block(side_a, at_a, at_a, "side_a")
    yc = block(coupled, at, at, "coupled")
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        w = bk.mul2(bk.inv2(t12), bk.mul2(t11 - yc, bk.inv2(t21)))
        k_inv = bk.inv2(w) - t22 - ya
        if model == "full":
            k = bk.inv2(k_inv)
        elif model == "diagonal":
            k = np.zeros_like(k_inv)
            k[0, 0] = 1.0 / k_inv[0, 0]
            k[1, 1] = 1.0 / k_inv[1, 1]
        else:
            raise InvalidValueError(f"model: got {model!r}; expected 'full' (eq. 2.5) or 'diagonal' (eq. 2.4)")
        diff = t11 - yc
        cancellation = np.sqrt((np.abs(t11) ** 2).sum(axis=(0, 1)) / (np.abs(diff) ** 2).sum(axis=(0, 1)))
        condition = {"T12": _cond2(t12), "T21": _cond2(t21), "W": _cond2(w), "K_inv": _cond2(k_inv)}
    result = ClosedFormResult(freq, np.moveaxis(k, -1, 0), condition,
                              cancellation * condition["W"] * condition["K_inv"])
    bad = result.ill_conditioned()
    if warn and np.any(bad):
        f = freq.hz[bad]
        warnings.warn(
            f"closed form: {bad.sum()} of {bad.size} lines ({f.min():.0f}-{f.max():.0f} Hz) have an "
            f"inversion with condition number above {COND_WARN:.0e}; the joint values there are meaningless",
            IllConditionedWarning,
            stacklevel=2,
        )
    return result


def joint_sides(assembly: Assembly, joint: str) -> tuple[Assembly, Assembly, str, str]:
    """The two sides of an assembly cut at a joint: ``(side_a, side_b, at_a, at_b)``.

    ``side_a`` holds the joint's first point (``between[0]``), ``side_b`` the
    second.  The joint must separate the assembly in two (a bridge of the
    graph); the joints, sensors and supports of each side stay with it.

    Parameters
    ----------
    assembly : Assembly
        The model.
    joint : str
        The joint's name.

    Returns
    -------
    side_a, side_b : Assembly
        The two sides.
    at_a, at_b : str
        The joint's point on each side.
    """
    j = assembly.joint(joint)
    rest = [x for x in assembly.joints if x.name != joint]
    owner = {name: comp.name for comp in assembly.components for name in comp.component_names}
    adjacency: dict[str, set] = {c.name: set() for c in assembly.components}
    for x in rest:
        a, b = (owner[parse_point(p).component] for p in x.between)
        adjacency[a].add(b)
        adjacency[b].add(a)
    start = owner[parse_point(j.between[0]).component]
    seen, stack = {start}, [start]
    while stack:
        for nxt in adjacency[stack.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    other = owner[parse_point(j.between[1]).component]
    if other in seen:
        raise AssemblyError(
            f"joint {joint!r} does not separate the assembly in two (the components stay connected "
            "through other joints), so the closed form of thesis eq. 2.3 does not apply; use the band fit"
        )
    base = attrs.evolve(assembly, joints=tuple(rest))
    a_side = base.without(*[c.name for c in assembly.components if c.name not in seen])
    b_side = base.without(*[c.name for c in assembly.components if c.name in seen])
    return a_side, b_side, j.between[0], j.between[1]


