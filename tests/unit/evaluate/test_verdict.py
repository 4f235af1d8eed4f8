"""The verdict on confidence bounds: coverage of the RMS bounds, indeterminate samples, failed runs, ICAO ranks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.evaluate.stats import (
    MIN_RUNS,
    bias_ratio,
    quantile_lower_rank,
    quantile_upper_rank,
    rms_bounds,
    rms_lower_factor,
    rms_upper_factor,
)
from approachsim.evaluate.verdict import best_category, category_verdict, clopper_pearson


def _coverage(n: int, mu: float, trials: int = 4000, seed: int = 0) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    theta = np.hypot(mu, 1.0)
    x = rng.normal(mu, 1.0, (trials, n))
    b = np.array([rms_bounds(row) for row in x])
    return float(np.mean(b[:, 1] >= theta)), float(np.mean(b[:, 0] <= theta))


@pytest.mark.parametrize(("n", "mu"), [(20, 0.0), (20, 1.0), (20, 3.0), (200, 0.0), (200, 3.0)])
def test_upper_bound_coverage_is_95_percent_with_and_without_bias(n, mu):
    up, lo = _coverage(n, mu, seed=n + int(10 * mu))
    # 4000 trials: binomial sd of a 95 % coverage estimate 0.0034; the acceptance band is +-1 %
    assert 0.94 <= up <= 0.96, up
    # the lower bound is the zero-mean chi-square one: 95 % at mu = 0, conservative with a bias
    assert lo >= 0.94, lo
    if mu >= 1.0:
        assert lo > 0.96, lo


def test_zero_mean_chi_square_bound_is_wrong_for_a_bias():
    """Why the upper bound models the bias: the zero-mean chi-square bound over-covers a biased sample."""
    rng = np.random.default_rng(4)
    n, mu = 20, 3.0
    x = rng.normal(mu, 1.0, (4000, n))
    rms = np.sqrt(np.mean(x**2, axis=1))
    central = np.mean(rms * np.sqrt(n / sps.chi2.ppf(0.05, n)) >= np.hypot(mu, 1.0))
    assert central > 0.99  # over-covers: the bound is looser than the stated level
    assert rms_upper_factor(n, bias_ratio(x[0])) < np.sqrt(n / sps.chi2.ppf(0.05, n))


def test_bound_factors():
    assert rms_upper_factor(20, 0.0) == pytest.approx(np.sqrt(20 / sps.chi2.ppf(0.05, 20)))
    assert rms_lower_factor(20) == pytest.approx(np.sqrt(20 / sps.chi2.ppf(0.95, 20)))
    assert rms_upper_factor(20, 1e12) == pytest.approx(1.0, abs=1e-4)  # all bias: nothing random to bound
    # exact by construction: a constant's variance is an exact 0 (15 / 5 = 3), a non-positive estimate returns 0.0
    assert bias_ratio(np.full(5, 3.0)) > 1e9 and bias_ratio(np.array([1.0, -1.0])) == 0.0


def test_point_inside_limit_but_bound_outside_is_indeterminate():
    rng = np.random.default_rng(1)
    z = rng.normal(size=20)
    z /= np.sqrt(np.mean(z**2))
    lat = 6.0 * z  # RMS 6.0 ft, well inside CAT I's 28.1 ft (bound ~8 ft)
    ver = 6.0 * rng.permutation(z)  # RMS 6.0 ft: inside 6.8 ft, but its upper bound (~8 ft) is not
    r = category_verdict("CAT I", 200.0, lat, ver)
    assert r.vertical.rms == pytest.approx(6.0) and r.vertical_axis.rms_upper_ft > 6.8
    assert r.lateral_axis.verdict == "meets" and r.vertical_axis.verdict == "indeterminate"
    assert r.verdict == "indeterminate" and not r.meets
    # runs_needed: the smallest n whose upper bound at this RMS reaches 6.8 ft
    n = r.runs_needed
    assert 6.0 * rms_upper_factor(n, bias_ratio(ver)) <= 6.8 < 6.0 * rms_upper_factor(n - 1, bias_ratio(ver))
    # with that many runs of the same spread the verdict is meets
    more = np.resize(ver, n)
    more *= 6.0 / np.sqrt(np.mean(more**2))
    assert category_verdict("CAT I", 200.0, np.resize(lat, n), more).verdict == "meets"


def test_fails_on_the_lower_bound_and_best_category():
    rng = np.random.default_rng(2)
    z = rng.normal(size=30)
    z /= np.sqrt(np.mean(z**2))
    res = [category_verdict(c, h, 4.0 * z, 1.5 * z) for c, h in (("CAT I", 200.0), ("CAT II", 100.0),
                                                                 ("CAT III", 50.0))]
    # 1.5 ft vertical against CAT III's 1.0 ft: lower bound 1.5 sqrt(30 / chi2_0.95(30)) = 1.23 ft > 1.0
    assert res[2].vertical_axis.rms_lower_ft == pytest.approx(1.5 * np.sqrt(30 / sps.chi2.ppf(0.95, 30)))
    assert [r.verdict for r in res] == ["meets", "meets", "fails"]
    assert best_category(res) == "CAT II"


def test_few_runs_never_meet():
    x = np.full(MIN_RUNS - 1, 0.01)  # tiny errors, but fewer than MIN_RUNS runs
    r = category_verdict("CAT III", 50.0, x, x)
    assert r.verdict == "indeterminate" and r.runs_needed == MIN_RUNS
    assert category_verdict("CAT III", 50.0, np.full(MIN_RUNS, 0.01), np.full(MIN_RUNS, 0.01)).meets


def test_one_failed_run_blocks_meets_unless_allowed():
    x = np.random.default_rng(3).normal(0.0, 1.0, 100)
    assert category_verdict("CAT I", 200.0, x, 0.5 * x).verdict == "meets"
    one = category_verdict("CAT I", 200.0, x, 0.5 * x, runs=101, failed_runs=1)
    assert one.verdict == "fails" and one.failure_verdict == "fails" and not one.meets
    # an allowed failure fraction is judged on the Clopper-Pearson upper bound of the failure probability
    hi = clopper_pearson(1, 101)[1]
    assert hi == pytest.approx(sps.beta.ppf(0.95, 2, 100))
    loose = category_verdict("CAT I", 200.0, x, 0.5 * x, runs=101, failed_runs=1, max_failure_fraction=0.05)
    assert hi < 0.05 and loose.verdict == "meets" and loose.failure_fraction_upper == pytest.approx(hi)
    tight = category_verdict("CAT I", 200.0, x, 0.5 * x, runs=101, failed_runs=1, max_failure_fraction=0.02)
    assert tight.verdict == "indeterminate" and tight.runs_needed is not None and tight.runs_needed > 101
    # every run failed: nothing to score, and the failures decide
    none = category_verdict("CAT I", 200.0, np.empty(0), np.empty(0), runs=4, failed_runs=4)
    assert none.verdict == "fails"


def test_icao_order_statistic_bounds():
    # one-sided 95 % upper bound of the 95th percentile: the largest of n exists from n = 59 (0.95^59 < 0.05)
    assert quantile_upper_rank(58) is None and quantile_upper_rank(59) == 59
    for n in (59, 100, 400):
        u, l = quantile_upper_rank(n), quantile_lower_rank(n)
        assert sps.binom.cdf(u - 1, n, 0.95) >= 0.95 and sps.binom.cdf(u - 2, n, 0.95) < 0.95
        assert sps.binom.cdf(l - 1, n, 0.95) <= 0.05 and sps.binom.cdf(l, n, 0.95) > 0.05
    x = np.random.default_rng(5).normal(0.0, 1.0, 40)
    # FAA-only meets; with the ICAO check, 40 runs cannot bound the 95th percentile: indeterminate
    assert category_verdict("CAT I", 200.0, x, 0.3 * x).verdict == "meets"
    r = category_verdict("CAT I", 200.0, x, 0.3 * x, verdict="faa+icao")
    assert r.verdict == "indeterminate" and r.runs_needed >= 59
    big = np.random.default_rng(6).normal(0.0, 1.0, 200)
    assert category_verdict("CAT I", 200.0, big, 0.3 * big, verdict="faa+icao").verdict == "meets"
    # coverage of the upper order statistic bound on samples
    rng = np.random.default_rng(7)
    q = sps.norm.ppf(0.975)
    a = np.sort(np.abs(rng.normal(size=(4000, 100))), axis=1)
    assert 0.95 <= np.mean(a[:, quantile_upper_rank(100) - 1] >= q) <= 0.98
