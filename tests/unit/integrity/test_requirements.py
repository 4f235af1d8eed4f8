"""Integrity requirements: Annex 10 alert-limit scaling at the reference notes' worked values, multipliers
against the Gaussian tails they stand for, thresholds from the continuity budget."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm

from approachsim import units
from approachsim.integrity.requirements import (
    REQUIREMENTS,
    gaussian_tail_two_sided,
    lateral_alert_limit_m,
    vertical_alert_limit_m,
)

CAT1 = REQUIREMENTS["CAT I"]


def test_cat1_alert_limits_scale_as_annex10_tables_b68_b69():
    """Worked values (FASVAL 10 m, FASLAL 40 m): VAL 10 m at 200 ft, 18.8 at 500 ft, 33.4 at 1000 ft, 43.35
    above 1340 ft; LAL 40 m to 873 m, 45.0 at 2 km, 58.2 at 5 km, 69.15 beyond 7.5 km; continuous at the joints."""
    h = np.array([100.0, 200.0, 500.0, 1000.0, 1340.0, 2000.0]) * units.FT
    np.testing.assert_allclose(vertical_alert_limit_m(CAT1, h), [10.0, 10.0, 18.775, 33.4, 43.345, 43.35], atol=0.011)
    d = np.array([0.0, 873.0, 2000.0, 5000.0, 7500.0, 20000.0])
    np.testing.assert_allclose(lateral_alert_limit_m(CAT1, d), [40.0, 40.0, 44.95, 58.15, 69.15, 69.15], atol=0.02)
    eps = 1e-6
    assert lateral_alert_limit_m(CAT1, 873.0 + eps) == pytest.approx(40.0, abs=0.01)  # table joints within 1 cm
    assert vertical_alert_limit_m(CAT1, 1340.0 * units.FT + eps) == pytest.approx(43.35, abs=0.01)


def test_cat2_cat3_limits_fixed():
    for cat in ("CAT II", "CAT III"):
        r = REQUIREMENTS[cat]
        assert np.all(lateral_alert_limit_m(r, [0.0, 5000.0]) == 17.0)
        assert np.all(vertical_alert_limit_m(r, [0.0, 300.0]) == 10.0)


@pytest.mark.parametrize("cat", ["CAT I", "CAT II", "CAT III"])
def test_multipliers_stand_for_their_allocations(cat):
    r = REQUIREMENTS[cat]
    assert gaussian_tail_two_sided(r.k_ff()) == pytest.approx(r.integrity_risk / 4 / r.n_es, rel=1e-6)
    assert norm.sf(r.k_md()) == pytest.approx(r.integrity_risk / 4 / (r.n_es * r.p_fault_per_sat), rel=1e-6)
    # more demanding categories need larger multipliers than the SBAS K_V = 5.33 (1e-7)
    assert r.k_ff() > 5.33
    assert r.time_to_alert_s == (6.0 if cat == "CAT I" else 2.0)


def test_false_alert_threshold_meets_the_continuity_budget():
    """Six channels at 1 Hz: per-test P_fa = 8e-6 / (15 x 6); over 15 s the union bound is the budget, where
    the old fixed p = 1e-4 per channel and epoch gave 9e-3."""
    p = CAT1.p_fa(1.0, 6)
    assert p * 15 * 6 == pytest.approx(8e-6)
    assert 1.0 - (1.0 - 1e-4) ** (15 * 6) == pytest.approx(9e-3, rel=0.01)
    from scipy.stats import chi2

    assert chi2.sf(CAT1.chi2_threshold(1, 1.0, 6), 1) == pytest.approx(p, rel=1e-6)
    assert 2 * norm.sf(CAT1.k_fa(1.0, 6)) == pytest.approx(p, rel=1e-6)


def test_one_table_for_evaluate_and_integrity():
    """Issue 41 item 5: evaluate's alert limits and covariance factors are the requirements table's, every row says
    what it models and where its numbers come from, and availability names the fault modes it covers."""
    from approachsim.evaluate.limits import K_H_PA, K_V_PA, LIMITS
    from approachsim.integrity.requirements import COVARIANCE_K_H, COVARIANCE_K_V, ROWS

    for cat, lim in LIMITS.items():
        r = REQUIREMENTS[cat]
        assert lim.horizontal_al_m == pytest.approx(r.lal_m, abs=1e-12)
        assert lim.vertical_al_m == pytest.approx(r.val_m, abs=1e-12)
        assert ROWS[cat] is r and r.model and r.source
        assert "GPS satellite" in r.availability_covers and "baro" in r.availability_covers
    assert (K_V_PA, K_H_PA) == (COVARIANCE_K_V, COVARIANCE_K_H) == (5.33, 6.0)
    for cat in ("CAT II", "CAT III"):
        r = REQUIREMENTS[cat]
        assert "LAAS-style" in r.model and "not GAST-D" in r.model
        assert (r.lal_m, r.val_m) == (17.0, 10.0)
        assert r.hmi_window_s() == (15.0, 30.0)
    assert REQUIREMENTS["CAT I"].hmi_window_s() is None  # per approach


@pytest.mark.parametrize("n_modes", [1, 10])
def test_k_md_spreads_the_faulted_allocation_over_the_modes(n_modes):
    """P_md = P_H1,axis / (N_es n_modes P_sat): CAT II / III 2.5e-10 / (7.5 x 1e-5) = 3.3e-6 for one mode (the
    issue's figure), 3.3e-7 for ten; K_md = Q^-1(P_md) = 4.50 / 4.97."""
    r = REQUIREMENTS["CAT II"]
    assert r.p_md(n_modes) == pytest.approx(1e-9 / 4 / (7.5 * n_modes * 1e-5), rel=1e-12)
    assert norm.sf(r.k_md(n_modes)) == pytest.approx(r.p_md(n_modes), rel=1e-9)
    assert r.k_md(n_modes) == pytest.approx({1: 4.504, 10: 4.971}[n_modes], abs=1e-3)
