"""Open-loop runs of one flight group share one flown truth: the RMS bounds must hold their coverage on
clustered errors (Kish's design effect from the between-group correlation, evaluate.stats.effective_runs)."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim.evaluate.stats import MIN_GROUPS, effective_runs, rms_bounds
from approachsim.evaluate.verdict import category_verdict

TRIALS = 1000


def _coverage(tau: float, corrected: bool, seed: int) -> float:
    """Upper-bound coverage of theta = sqrt(1 + tau^2) on 10 groups of 20 runs, shared N(0, tau^2) per group."""
    r = np.random.default_rng(seed)
    g = np.repeat(np.arange(10), 20)
    hits = 0
    for _ in range(TRIALS):
        x = r.standard_normal(200) + tau * r.standard_normal(10)[g]
        ne = effective_runs(x, g)[0] if corrected else None
        hits += rms_bounds(x, 0.95, ne)[1] >= np.sqrt(1.0 + tau**2)
    return hits / TRIALS


def test_clustered_errors_break_the_independent_bound_and_the_design_effect_restores_it():
    # intraclass correlation 0.5: the independent-run bound covers ~72 %, the corrected one >= 95 %
    assert _coverage(1.0, corrected=False, seed=3) < 0.85
    assert _coverage(1.0, corrected=True, seed=3) >= 0.94


def test_independent_groups_keep_their_run_count_and_coverage():
    r = np.random.default_rng(4)
    g = np.repeat(np.arange(10), 20)
    n_eff, rho = effective_runs(r.standard_normal(200), g)
    assert rho < 0.1 and n_eff > 150
    assert abs(_coverage(0.0, corrected=True, seed=5) - 0.95) <= 0.025  # binomial sd 0.7 %


def test_the_correlation_estimate_follows_the_truth():
    r = np.random.default_rng(6)
    g = np.repeat(np.arange(200), 10)
    x = r.standard_normal(2000) + r.standard_normal(200)[g]  # rho = 0.5
    n_eff, rho = effective_runs(x, g)
    assert rho == pytest.approx(0.5, abs=0.08)
    assert n_eff == pytest.approx(2000 / (1 + 9 * rho), rel=1e-9)


def test_too_few_groups_are_not_estimated():
    g = np.repeat(np.arange(MIN_GROUPS - 1), 10)
    n_eff, rho = effective_runs(np.arange(g.size, dtype=float), g)
    assert n_eff == g.size and np.isnan(rho)


def test_a_shared_truth_widens_the_verdict_bound():
    r = np.random.default_rng(7)
    g = np.repeat(np.arange(10), 20)
    lat = 5.0 * (r.standard_normal(200) + r.standard_normal(10)[g])
    ver = 0.5 * r.standard_normal(200)
    indep = category_verdict("CAT I", 200.0, lat, ver)
    clustered = category_verdict("CAT I", 200.0, lat, ver, groups=g)
    assert clustered.lateral_axis.rms_upper_ft > indep.lateral_axis.rms_upper_ft * 1.1
    assert clustered.lateral_axis.n_eff < 100
