"""Statistics over runs: RMS with bias, 95th percentile, and the coverage of their intervals."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.evaluate.stats import error_stats, quantile_ranks, rms_interval


def test_constant_bias():
    s = error_stats(np.full(12, -5.0))
    assert s.rms == pytest.approx(5.0)
    assert s.mean == pytest.approx(-5.0)
    assert s.std == pytest.approx(0.0, abs=1e-12)  # 12 deviations from the mean of 5s: floor(12, 5) = 1.3e-14; 75x
    assert s.p95 == pytest.approx(5.0)
    assert s.rms_lo < 5.0 < s.rms_hi


def test_known_gaussian_with_bias():
    rng = np.random.default_rng(7)
    mu, sigma, n = 1.5, 2.0, 20000
    s = error_stats(rng.normal(mu, sigma, n))
    assert s.rms == pytest.approx(np.hypot(mu, sigma), rel=0.02)
    assert s.mean == pytest.approx(mu, abs=0.05)
    assert s.std == pytest.approx(sigma, rel=0.02)
    # 95th percentile of |N(mu, sigma)|: solve P(|X| <= q) = 0.95
    from scipy.optimize import brentq

    q = brentq(lambda q: sps.norm.cdf(q, mu, sigma) - sps.norm.cdf(-q, mu, sigma) - 0.95, 0.0, 20.0)
    assert s.p95 == pytest.approx(q, rel=0.02)
    assert s.p95_lo <= q <= s.p95_hi


def test_rms_interval_coverage_is_95_percent():
    rng = np.random.default_rng(11)
    n, trials = 20, 4000
    x = rng.normal(0.0, 1.0, (trials, n))
    rms = np.sqrt(np.mean(x**2, axis=1))
    lo1, hi1 = rms_interval(1.0, n)  # the interval scales with the RMS
    cover = np.mean((lo1 * rms <= 1.0) & (1.0 <= hi1 * rms))
    # binomial sd of the estimated coverage with 4000 trials: 0.0034
    assert 0.94 <= cover <= 0.96


def test_quantile_ranks_have_their_coverage():
    for n in (100, 500, 2000):
        l, u = quantile_ranks(n, 0.95, 0.95)
        assert l is not None and u is not None
        # P(X_(l) <= q <= X_(u)) = P(l <= B < u) for B ~ binomial(n, 0.95)
        cov = sps.binom.cdf(u - 1, n, 0.95) - sps.binom.cdf(l - 1, n, 0.95)
        assert cov >= 0.95
        assert l <= round(0.95 * n) <= u
    # with n <= 71 runs, P(all n below the 95th percentile) = 0.95^n > 0.025: no upper bound exists
    assert quantile_ranks(71)[1] is None
    assert quantile_ranks(72)[1] == 72


def test_percentile_interval_coverage():
    rng = np.random.default_rng(3)
    q_true = sps.norm.ppf(0.975)  # 95th percentile of |N(0, 1)|
    hits = 0
    trials = 600
    for _ in range(trials):
        s = error_stats(rng.normal(size=300))
        hits += s.p95_lo <= q_true <= s.p95_hi
    assert hits / trials >= 0.93


def test_nonfinite_runs_are_left_out():
    s = error_stats(np.array([3.0, np.nan, -3.0, np.inf]))
    assert s.n == 2 and s.rms == pytest.approx(3.0)
    assert np.isnan(error_stats(np.array([np.nan])).rms)
