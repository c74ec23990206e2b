"""Model selection by significance: is the residual noise, does a change earn its parameters.

Three decisions, each a documented test on the ``chi^2`` of
:mod:`substructure.updating.likelihood` (``n`` residuals, ``p`` fitted
parameters, ``nu = n - p``):

**Consistent with noise** (:func:`consistency`).  A model explains the data
when its whitened residual is what the noise model predicts, globally and
in every band:

* globally, ``2 S / (2 E - p) <= 1 + z sqrt(4 V / (2 E - p)^2 + e^2)``,
  ``z = 3.09`` (one-sided 0.1 %), with ``S`` the sum of the line scores each
  capped at :data:`LINE_CAP` (a few lines far off do not decide it alone),
  ``E`` and ``V`` the sums of the capped scores' means and variances
  (exponential where a line's variance is known, ``F(2, nu)`` where it is
  estimated, :attr:`NoiseModel.dof`), and ``e`` the relative standard error
  of the noise variance estimated from the data
  (:attr:`NoiseModel.scale_error`);
* in each block of lines (2 % of the band, at least 20 lines, per FRF), the
  mean of the line scores (half the squared whitened residual,
  :meth:`NoiseModel.line_scores`), each capped at :data:`LINE_CAP`, stays
  below the upper ``0.001 / M`` quantile of its distribution (Bonferroni
  over the ``M`` blocks), widened by ``1 + z e`` as the global test is; a
  line whose variance is estimated with ``nu`` degrees of freedom (the
  coherence of a few taps, :attr:`NoiseModel.dof`) scores ``F(2, nu)``;
* lines whose noise is correlated (an FRF measured through an exponential
  window, ``NoiseModel.correlation`` ``kappa``) keep the mean of their
  scores and their sums vary ``kappa`` times as much: both tests, and the
  plain check beside them (:func:`error_check`), widen by it.

**Significance of a change** (:func:`significance`).  A change with ``k``
parameters that lowers ``chi^2`` from ``chi2_0`` to ``chi2_1`` enters only
when the likelihood ratio, scaled by the misfit of the larger model
``s^2 = max(1, chi2_1 / nu_1)`` (quasi-likelihood: a model that misses
something has a larger effective noise), exceeds both the BIC penalty
``k ln n`` and the chi-square quantile ``chi2_k(1 - 0.01 / M)`` for ``M``
candidates tried (Bonferroni: searching many candidates must not let noise
through).

**Indifference** (:func:`indifferent`).  Two explanations with ``chi2_a``,
``k_a`` and ``chi2_b``, ``k_b`` differ by
``Delta BIC = (chi2_b - chi2_a) / s^2 + (k_b - k_a) ln n``; within
``|Delta BIC| <= 10`` (a Bayes factor below ``e^5``, not "very strong"
evidence in Kass and Raftery's scale, J. Am. Stat. Assoc. 90, 1995) the
data cannot tell them apart: both are reported, with the measurement that
would separate them.
"""

from __future__ import annotations

import functools
import math
from typing import Sequence

import attrs
import numpy as np
from scipy.stats import chi2 as chi2_dist
from scipy.stats import gamma as gamma_dist

from ..errors import InvalidValueError
from ..units import whole_number

__all__ = ["Consistency", "consistency", "ErrorCheck", "error_check", "Significance", "significance", "indifferent",
           "bic", "INDIFFERENCE", "CONSISTENCY_ALPHA", "outlying_runs", "OUTLYING_RUN"]

CONSISTENCY_ALPHA = 0.001
"""Level of the consistency tests (global and, Bonferroni-corrected, per band)."""
SIGNIFICANCE_ALPHA = 0.01
"""Level of the likelihood-ratio test of a change, before the Bonferroni correction."""
INDIFFERENCE = 10.0
"""Largest ``|Delta BIC|`` of two explanations the data cannot tell apart."""
LINE_CAP = 6.907755278982137
"""Cap of one line's score in the band test: the upper 1e-3 tail of noise (``-ln 0.001``).

Real tap-test noise is heavy-tailed: a few lines of a band (a double hit's ripple, the
data's own antiresonance) may lie far out.  Capped, such lines cannot fail a band alone,
while a missing effect, which moves many lines, still does."""
_Z = 3.090232306167813  # one-sided 0.1 %


def _block_bound(size: int, alpha: float, dof: np.ndarray | None = None, correlation: float = 1.0) -> float:
    """Upper ``alpha`` quantile of the mean of ``size`` line scores capped at :data:`LINE_CAP`.

    A line score of noise is exponential with mean 1 where its variance is known; capped at
    ``c`` it has mean ``1 - exp(-c)`` and second moment ``2 - 2 (1 + c) exp(-c)``.  Where the
    variance is estimated with ``dof`` degrees of freedom (from the coherence of a few taps,
    :attr:`~substructure.updating.noise.NoiseModel.dof`), the score follows ``F(2, dof)``,
    heavier-tailed (a mean of 2 for 3 taps).  The sum of the ``size`` capped scores is taken as
    the gamma distribution of the same mean and variance (it is bounded and skewed to the
    right, as the gamma is).  Lines whose noise is correlated (an exponential window,
    ``NoiseModel.correlation``) keep the mean and vary
    ``correlation`` times as much.
    """
    mean, var = _line_moments(dof, size)
    var *= correlation
    shape = mean * mean / var
    scale = var / mean
    return float(gamma_dist.isf(alpha, shape, scale=scale)) / size


_NU_GRID = np.geomspace(1.0, 1e6, 241)


@functools.lru_cache(maxsize=1)
def _capped_f_table(cap: float = LINE_CAP) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean, variance and third central moment of ``min(F, cap)`` for ``F ~ F(2, nu)`` on :data:`_NU_GRID`
    (by quadrature: ``E[X^k] = int_0^cap k x^(k-1) P(F > x) dx``).

    A line's score ``0.5 (chi^2_2)`` over a variance known to ``nu`` degrees of freedom is
    ``F(2, nu)``: ``P(F > x) = (1 + 2 x / nu)^(-nu / 2)``, the exponential as ``nu`` grows.
    """
    x = np.linspace(0.0, cap, 4001)
    tail = (1.0 + 2.0 * x[None, :] / _NU_GRID[:, None]) ** (-_NU_GRID[:, None] / 2.0)
    mean = np.trapezoid(tail, x, axis=1)
    second = np.trapezoid(2.0 * x[None, :] * tail, x, axis=1)
    third = np.trapezoid(3.0 * x[None, :] ** 2 * tail, x, axis=1)
    return mean, second - mean * mean, third - 3.0 * mean * second + 2.0 * mean**3


def _line_moments(dof: np.ndarray | None, size: int) -> tuple[float, float]:
    """Sum of the means and of the variances of ``size`` capped line scores with these degrees of freedom."""
    means, variances, _ = _each_line_moments(dof, size)
    return float(means.sum()), float(variances.sum())


def _each_line_moments(dof: np.ndarray | None, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mean, variance and third central moment of each of ``size`` capped line scores (exponential where
    ``dof`` is None or infinite, ``F(2, dof)`` where finite)."""
    c = LINE_CAP
    tail = math.exp(-c)
    m1, m2, m3 = 1.0 - tail, 2.0 * (1.0 - tail * (1.0 + c)), 6.0 * (1.0 - tail * (1.0 + c + c * c / 2.0))
    means, variances = np.full(size, m1), np.full(size, m2 - m1 * m1)
    thirds = np.full(size, m3 - 3.0 * m1 * m2 + 2.0 * m1**3)
    if dof is None:
        return means, variances, thirds
    nu = np.asarray(dof, dtype=float)
    finite = np.isfinite(nu) & (nu < _NU_GRID[-1])
    where = np.log(np.clip(nu[finite], _NU_GRID[0], _NU_GRID[-1]))
    for out, table in zip((means, variances, thirds), _capped_f_table()):
        out[finite] = np.interp(where, np.log(_NU_GRID), table)
    return means, variances, thirds


@attrs.frozen
class Band:
    """A block of lines where the residual is larger than the noise allows.

    Parameters
    ----------
    item : int
        Index of the measured FRF.
    lo_hz, hi_hz : float
        Its frequency range.
    ratio : float
        Mean squared whitened residual over the block (1 for noise).
    threshold : float
        What the test allows there.
    share : float
        The block's share of the excess ``chi^2`` over the noise: its
        ``chi^2`` above its degrees of freedom over the sum of that of every
        block (between 0 and 1).
    """

    item: int
    lo_hz: float
    hi_hz: float
    ratio: float
    threshold: float
    share: float


@attrs.frozen
class Consistency:
    """Whether a model's residual is consistent with the noise (see the module docstring).

    Parameters
    ----------
    consistent : bool
        Both tests pass.
    chi2_reduced : float
        ``chi^2 / nu``.
    threshold : float
        The global test's bound on ``chi2_reduced``.
    bands : tuple of Band
        Blocks failing the band test, largest excess first.
    """

    consistent: bool
    chi2_reduced: float
    threshold: float
    bands: tuple


def _correlation(noise) -> float:
    """A noise model's correlation of neighbouring lines (1 for one that does not say: independent lines)."""
    return float(getattr(noise, "correlation", 1.0))


def _scores(likelihood, ratios: Sequence[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray | None]]:
    """Per measured FRF, on the lines it holds (``alive``: no score where it holds nothing), its lines' scores
    (:meth:`NoiseModel.line_scores`) and the degrees of freedom of their variances (None: known)."""
    return [(m.noise.line_scores(r, likelihood.lines)[a],
             None if m.noise.dof is None else m.noise.dof[likelihood.lines][a])
            for r, m, a in zip(ratios, likelihood.measured, likelihood.alive)]


def consistency(likelihood, ratios: Sequence[np.ndarray], p: int) -> Consistency:
    """Test a model's residual against the noise, globally and band by band.

    Parameters
    ----------
    likelihood : Likelihood
        The data and noise (its ``measured`` items and lines).
    ratios : sequence of ndarray
        ``ln(model / measured)`` per measured FRF (:meth:`Likelihood.log_ratios`).
    p : int
        Number of fitted parameters.

    Returns
    -------
    Consistency
        The verdict and where the residual is too large.
    """
    whole_number(p, "consistency: p", 0, "the number of fitted parameters, a whole number")
    alive = likelihood.alive
    scored = _scores(likelihood, ratios)
    z2, dofs = [z for z, _ in scored], [d for _, d in scored]
    sizes = np.array([z.size for z in z2], dtype=float)
    errs = np.array([m.noise.scale_error for m in likelihood.measured])
    kappa = [_correlation(m.noise) for m in likelihood.measured]  # 1 for independent lines
    e = float(np.sqrt(np.sum((sizes * errs) ** 2)) / max(sizes.sum(), 1.0))
    # every line enters capped at LINE_CAP, as in the band test, against the capped scores' mean and variance
    # (exponential scores where the variance is known, F(2, nu) where estimated: heavy-tailed, infinite variance
    # for nu <= 4): a few lines far off (a real test's first lines, a double hit's notch) do not make the noise
    # alone fail the test; a misfit over many lines still does, and the bands test where it lies
    total, mean, var = 0.0, 0.0, 0.0
    for z, d, k in zip(z2, dofs, kappa):
        total += float(np.minimum(z, LINE_CAP).sum())
        m_all, v_all = _line_moments(d, z.size)
        mean += m_all
        var += k * v_all
    expected = max(2.0 * mean - p, 1.0)
    reduced = 2.0 * total / expected
    threshold = 1.0 + _Z * math.sqrt(4.0 * var / expected**2 + e * e)
    blocks = []
    for item, (z, m) in enumerate(zip(z2, likelihood.measured)):
        size = max(20, int(round(0.02 * z.size)))
        f = m.frf.frequency.hz[likelihood.lines][alive[item]]
        starts = list(range(0, z.size, size))
        if len(starts) > 1 and z.size - starts[-1] < size // 2:  # a short last block joins the one before
            starts.pop()
        for start, stop in zip(starts, starts[1:] + [z.size]):
            blocks.append((item, slice(start, stop), f))
    m_blocks = max(len(blocks), 1)
    # each block's chi^2 above its degrees of freedom; a share is of the sum of these (so the shares of all
    # blocks add up to 1 even where the blocks below their mean make chi^2 - nu smaller than one block's excess)
    excess = [max(2.0 * float(z2[item][sl].sum()) - 2 * z2[item][sl].size, 0.0) for item, sl, _ in blocks]
    excess_total = max(sum(excess), 1e-300)
    failing = []
    for (item, sl, f), over in zip(blocks, excess):
        z = z2[item][sl]
        # widened, as the global test is, by how well the noise itself is known
        dof = None if dofs[item] is None else dofs[item][sl]
        bound = _block_bound(z.size, CONSISTENCY_ALPHA / m_blocks, dof, kappa[item]) * (1.0 + _Z * float(errs[item]))
        ratio = float(np.minimum(z, LINE_CAP).mean())
        if ratio > bound:
            failing.append(Band(item, float(f[sl][0]), float(f[sl][-1]), ratio, bound, over / excess_total))
    failing.sort(key=lambda b: -b.share)
    return Consistency(bool(reduced <= threshold and not failing), reduced, threshold, tuple(failing))


@attrs.frozen
class ErrorCheck:
    """The plain check beside the tests: the error in noise floors, each line as the noise model scores it.

    Parameters
    ----------
    ratio : float
        ``sqrt(sum v_k min(z_k, c) / sum v_k)``: the RMS error over the
        noise floor with each line's squared error ``v_k z_k`` (``z_k`` its
        score, read linearly where the noise drowns it) capped at
        ``LINE_CAP`` times its variance ``v_k``; the plain ratio, where
        no line is capped or read linearly.
    allowed : float
        What the noise allows: ``factor``, or the upper
        ``CONSISTENCY_ALPHA`` (0.1 %) quantile of ``ratio`` for noise when the
        floor lives on a few lines and that is larger.
    """

    ratio: float
    allowed: float

    @property
    def passed(self) -> bool:
        """The error is within what the noise allows."""
        return bool(self.ratio <= self.allowed)


def error_check(likelihood, ratios: Sequence[np.ndarray], factor: float) -> ErrorCheck:
    """The verdict's plain check: the RMS error within ``factor`` noise floors, as the noise allows.

    The squared RMS error over the squared noise floor is a mean of the
    lines' scores weighted by their variances, ``sum v_k z_k / sum v_k``.
    Where a few lines of large variance hold most of the floor (the lines
    below the first mode of a short record, say: three lines held 80 % of
    it in a 0.1 s tap test), that mean varies as much as a few scores do,
    and one line 3 sigma out put an exact model's error at 1.6 floors; a
    line drowned in noise read as a log ratio (``ln(M / H)`` of a data value
    near zero) put it at 1.8.  So each line enters with its score as the
    noise model gives it (read linearly where drowned) and capped at
    ``LINE_CAP``, as in the band test, and the bound is the larger of
    ``factor`` and the upper ``CONSISTENCY_ALPHA`` (0.1 %) quantile of the
    weighted mean for noise: a shifted gamma distribution of its mean,
    variance and third moment, from each line's capped score's
    (``_each_line_moments``; the gamma of the mean and variance alone has
    too light a tail when a few weights dominate: 0.3 % of noise above its
    0.1 % quantile).

    Parameters
    ----------
    likelihood : Likelihood
        The data and noise (its ``measured`` items and lines).
    ratios : sequence of ndarray
        ``ln(model / measured)`` per measured FRF.
    factor : float
        The plain bound in noise floors (``DiagnoseSettings.explained_error_factor``).

    Returns
    -------
    ErrorCheck
        The ratio and what is allowed.
    """
    weighted = mean = var = third = total = 0.0
    for (z, dof), m, a in zip(_scores(likelihood, ratios), likelihood.measured, likelihood.alive):
        v = (m.noise.var_re + m.noise.var_im)[likelihood.lines][a]
        z = np.minimum(z, LINE_CAP)
        means, variances, thirds = _each_line_moments(dof, v.size)
        k = _correlation(m.noise)  # correlated lines: a sum of k times fewer independent ones, each k lines' worth
        weighted += float(v @ z)
        mean += float(v @ means)
        var += k * float((v * v) @ variances)
        third += k * k * float((v * v * v) @ thirds)
        total += float(v.sum())
    if not total > 0.0:
        return ErrorCheck(0.0, factor)
    mean, var, third = mean / total, var / total**2, third / total**3
    quantile = mean
    if var > 0.0 and third > 0.0:  # a gamma of the same three moments, shifted (Pearson's type III)
        skew = third / var**1.5
        shape, scale = 4.0 / skew**2, math.sqrt(var) * skew / 2.0
        quantile = mean - shape * scale + float(gamma_dist.isf(CONSISTENCY_ALPHA, shape, scale=scale))
    return ErrorCheck(math.sqrt(weighted / total), max(factor, math.sqrt(quantile)))


OUTLYING_RUN = 8
"""Fewest neighbouring lines beyond the noise's 0.1 % tail that make a run worth reporting (times the noise's
correlation ``kappa``).  Independent noise puts three in a row once in about 1e9 starts, but real tap-test
noise is heavy-tailed and uneven: the residual of the shipped impact records laid on an exact model (at one
to ten times its level, 54 placements) put up to six lines in a row beyond the tail, near the real
structure's sharp resonances; eight is beyond what it showed."""


def outlying_runs(likelihood, ratios: Sequence[np.ndarray]) -> list[tuple[int, float, float, int]]:
    """Runs of neighbouring lines far beyond the noise, which the tests count as outliers only.

    The tests cap each line's score at the noise's 0.1 % tail (:data:`LINE_CAP`; for a variance
    estimated with ``nu`` degrees of freedom, the same tail of ``F(2, nu)``), so that the few lines
    of a real tap test far out (a double hit's notch, the first lines of a short record) do not
    decide the verdict.  A misfit confined to a few neighbouring lines is then not judged either:
    these runs say where it would hide.  A run is :data:`OUTLYING_RUN` lines or more (times the
    lines' correlation) each beyond the tail.

    Parameters
    ----------
    likelihood : Likelihood
        The data and noise.
    ratios : sequence of ndarray
        ``ln(model / measured)`` per measured FRF.

    Returns
    -------
    list of (int, float, float, int)
        Per run, the measured FRF's index, its first and last line [Hz] and its number of lines.
    """
    runs = []
    for item, ((z, dof), m, a) in enumerate(zip(_scores(likelihood, ratios), likelihood.measured, likelihood.alive)):
        if dof is None:
            tail = np.full(z.size, LINE_CAP)
        else:  # the 0.1 % tail of F(2, nu): (1 + 2 x / nu)^(-nu / 2) = 0.001
            nu = np.asarray(dof, dtype=float)
            tail = np.where(np.isfinite(nu), 0.5 * nu * (1000.0 ** (2.0 / np.where(np.isfinite(nu), nu, 1.0)) - 1.0),
                            LINE_CAP)
        out = np.concatenate([[False], z > tail, [False]])
        edges = np.flatnonzero(np.diff(out.astype(np.int8)))
        hz = m.frf.frequency.hz[likelihood.lines][a]
        least = max(OUTLYING_RUN, math.ceil(OUTLYING_RUN * _correlation(m.noise)))
        for start, stop in zip(edges[::2], edges[1::2]):
            if stop - start >= least:
                runs.append((item, float(hz[start]), float(hz[stop - 1]), int(stop - start)))
    return runs


@attrs.frozen
class Significance:
    """The test of one change against the model without it.

    Parameters
    ----------
    statistic : float
        The scaled likelihood ratio ``(chi2_0 - chi2_1) / s^2``.
    threshold : float
        ``max(k ln n, chi2_k quantile)``.
    significant : bool
        ``statistic > threshold``.
    """

    statistic: float
    threshold: float
    significant: bool


def significance(chi2_0: float, chi2_1: float, k: int, n: int, p1: int, candidates: int = 1) -> Significance:
    """Does a change with ``k`` parameters earn them (see the module docstring)?

    Parameters
    ----------
    chi2_0, chi2_1 : float
        ``chi^2`` without and with the change (refitted).
    k : int
        Parameters the change adds.
    n : int
        Number of residuals.
    p1 : int
        Parameters of the larger model.
    candidates : int
        How many changes were tried for this one (Bonferroni).

    Returns
    -------
    Significance
        The statistic, the threshold and the verdict.
    """
    _checked("significance", chi2=(chi2_0, chi2_1), counts=(("k", k), ("p1", p1), ("candidates", candidates)), n=n)
    s2 = max(1.0, chi2_1 / max(n - p1, 1))
    stat = (chi2_0 - chi2_1) / s2
    threshold = max(k * math.log(n), float(chi2_dist.isf(SIGNIFICANCE_ALPHA / max(candidates, 1), max(k, 1))))
    return Significance(float(stat), float(threshold), bool(stat > threshold))


def bic(chi2: float, k: int, n: int, s2: float = 1.0) -> float:
    """``chi2 / s2 + k ln n``: the Bayesian information criterion with a misfit scale.

    Parameters
    ----------
    chi2 : float
        The model's ``chi^2``.
    k : int
        Its number of fitted parameters.
    n : int
        Number of residuals.
    s2 : float
        Misfit scale (``max(1, chi^2 / nu)`` of the best model compared).

    Returns
    -------
    float
        The criterion (lower is better).
    """
    return chi2 / s2 + k * math.log(n)


def indifferent(chi2_a: float, k_a: int, chi2_b: float, k_b: int, n: int, s2: float = 1.0) -> bool:
    """True when the data cannot tell two explanations apart: ``|Delta BIC| <= 10``.

    Parameters
    ----------
    chi2_a : float
        ``chi^2`` of the first explanation.
    k_a : int
        Its number of fitted parameters.
    chi2_b : float
        ``chi^2`` of the second explanation.
    k_b : int
        Its number of fitted parameters.
    n : int
        Number of residuals.
    s2 : float
        Misfit scale of the better one.

    Returns
    -------
    bool
        Whether they are inside the indifference region.
    """
    _checked("indifferent", chi2=(chi2_a, chi2_b), counts=(("k_a", k_a), ("k_b", k_b)), n=n)
    if not (isinstance(s2, (int, float, np.integer, np.floating)) and s2 > 0 and math.isfinite(s2)):
        raise InvalidValueError(f"indifferent: s2: got {s2!r}; expected a finite misfit scale > 0")
    return abs(bic(chi2_b, k_b, n, s2) - bic(chi2_a, k_a, n, s2)) <= INDIFFERENCE


def _checked(what: str, chi2: tuple, counts: tuple, n) -> None:
    """The numbers of a test checked where they enter: ``chi^2`` values that are numbers >= 0 (inf, a model that
    cannot be held, allowed), counts that are whole numbers >= 0, ``n`` >= 1 (a NaN gave a verdict of False
    without a word, n = 0 a raw math domain error)."""
    for x in chi2:
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)) or not x >= 0:
            raise InvalidValueError(f"{what}: chi^2 of {x!r}; expected a number >= 0")
    for name, value in counts + (("n", n),):
        whole_number(value, f"{what}: {name}", int(name == "n"))
