"""The verdict's plain check of the error (`selection.error_check`) against noise drawn here.

The check's bound is the upper 0.1 % quantile of the variance-weighted mean
of capped line scores, taken as a shifted gamma distribution of its first
three moments.  Here the same mean is drawn many times from noise of the
variances the check is given (complex Gaussian residuals, seeded), and its
quantile counted: the two must agree where the floor lives on a few lines,
and the bound must stay the plain factor where it is spread over many.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from substructure.updating.selection import LINE_CAP, error_check


def _likelihood(variances: np.ndarray):
    """The parts of a likelihood the check reads: one FRF, its lines' variances (half in each part)."""
    var_re = var_im = variances / 2.0

    def line_scores(r, lines):
        return 0.5 * (r.real**2 / var_re[lines] + r.imag**2 / var_im[lines])

    noise = SimpleNamespace(var_re=var_re, var_im=var_im, dof=None, line_scores=line_scores)
    lines = np.arange(variances.size)
    return SimpleNamespace(measured=[SimpleNamespace(noise=noise)], lines=lines,
                           alive=[np.ones(variances.size, dtype=bool)])


def _draws(variances: np.ndarray, count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    sd = np.sqrt(variances / 2.0)
    return rng.normal(size=(count, variances.size)) * sd + 1j * rng.normal(size=(count, variances.size)) * sd


def test_a_floor_on_a_few_lines_allows_what_its_noise_does():
    """Three lines of large variance and 500 small ones (a short record's lowest lines): the bound is the noise's
    own 0.1 % quantile, counted here over 40,000 draws, not 1.5 floors."""
    variances = np.concatenate([[0.45, 0.8, 0.55], np.full(500, 0.002)])
    lik = _likelihood(variances)
    draws = _draws(variances, 40_000, seed=1)
    ratios = np.array([error_check(lik, [r], 1.5).ratio for r in draws])
    allowed = error_check(lik, [draws[0]], 1.5).allowed
    assert allowed > 1.6
    counted = float(np.quantile(ratios, 1.0 - 1e-3))
    assert allowed == pytest.approx(counted, rel=0.02)
    assert 0.0005 < float(np.mean(ratios > allowed)) < 0.002  # about one in a thousand
    assert float(np.mean(ratios > 1.5)) > 0.005  # the plain factor calls noise a misfit five times as often


def test_a_floor_spread_over_many_lines_keeps_the_plain_factor():
    variances = np.random.default_rng(2).uniform(0.001, 0.003, 800)
    lik = _likelihood(variances)
    draws = _draws(variances, 2_000, seed=3)
    checks = [error_check(lik, [r], 1.5) for r in draws]
    assert {c.allowed for c in checks} == {1.5}
    assert all(c.passed for c in checks)
    assert np.mean([c.ratio for c in checks]) == pytest.approx(1.0, abs=0.02)


def test_one_line_far_out_counts_as_its_cap():
    variances = np.concatenate([[0.45, 0.8, 0.55], np.full(500, 0.002)])
    lik = _likelihood(variances)
    r = _draws(variances, 1, seed=4)[0]
    far = r.copy()
    far[1] = 40.0 * np.sqrt(variances[1])  # a score of 800: counts as the cap
    capped = np.sqrt((variances @ np.minimum(lik.measured[0].noise.line_scores(far, lik.lines), LINE_CAP))
                     / variances.sum())
    assert error_check(lik, [far], 1.5).ratio == pytest.approx(capped)
    assert error_check(lik, [far], 1.5).ratio < 40.0 * np.sqrt(variances[1] / variances.sum())


def test_a_misfit_of_many_lines_fails():
    variances = np.random.default_rng(2).uniform(0.001, 0.003, 800)
    lik = _likelihood(variances)
    off = _draws(variances, 1, seed=5)[0] + 0.12  # every line off by 12 %, about three of its deviations
    check = error_check(lik, [off], 1.5)
    assert not check.passed and check.ratio > 1.5 * check.allowed


@pytest.mark.parametrize("nu", [3.0, 8.0, 40.0, None])
def test_the_capped_scores_moments_are_those_of_the_distribution(nu):
    """Mean, variance and third central moment of a capped line score, against scipy's F(2, nu) (exponential
    without degrees of freedom) integrated here: the moments the bound of the check is built from."""
    from scipy import integrate, stats

    from substructure.updating.selection import _each_line_moments

    dist = stats.expon() if nu is None else stats.f(2, nu)
    raw = [integrate.quad(lambda x, k=k: x**k * dist.pdf(x), 0.0, LINE_CAP, limit=200)[0]
           + LINE_CAP**k * dist.sf(LINE_CAP) for k in (1, 2, 3)]
    mean, var = raw[0], raw[1] - raw[0] ** 2
    third = raw[2] - 3.0 * raw[0] * raw[1] + 2.0 * raw[0] ** 3
    got = _each_line_moments(None if nu is None else np.array([nu]), 1)
    assert [float(g[0]) for g in got] == pytest.approx([mean, var, third], rel=2e-3)
