"""nav/initial.py: the converged start. The conditioning draw gives cov(e) = P_conv and cov(e, x_hat) = 0 (a
converged filter's orthogonality) over many seeded draws; channels out of view keep their prior; the converged
covariance is the filter's own recursion (never above the prior on the observed states); the profile key."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
from approachsim.config import ProfileError, Section
from approachsim.nav import initial
from approachsim.nav.config import parse_nav
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILE = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")


def _linear_case(seed: int = 3):
    """A 7-state prior (3 'nav' + 4 'sensor' states, the sensors uncorrelated) and the posterior of a few
    scalar updates that mix them: a P_conv <= P0 with strong nav / sensor correlations."""
    g = np.random.default_rng(seed)
    P0 = np.diag([25.0, 16.0, 4.0, 9.0, 1.0, 4.0, 0.25])
    P = P0.copy()
    for _ in range(6):
        h = g.standard_normal(7)
        K = P @ h / (h @ P @ h + 0.5)
        P = P - np.outer(K, h @ P)
    return P0, 0.5 * (P + P.T), np.arange(3, 7)


def test_conditioning_gives_cov_e_equal_P_conv_and_e_orthogonal_to_the_estimate():
    P0, P_conv, s = _linear_case()
    m, n = 40000, 7
    g = np.random.default_rng(11)
    x_s = g.standard_normal((m, 4)) * np.sqrt(np.diag(P0)[s])  # the sensors' realization, prior Pi_ss
    e, excess = initial.condition(P_conv, P0[np.ix_(s, s)], s, x_s, g.standard_normal((m, n)))
    assert excess == 0.0
    x = np.zeros((m, n))
    x[:, :3] = e[:, :3]  # INS error = e_nav (its estimate 0)
    x[:, s] = x_s
    x_hat = x - e
    assert np.all(x_hat[:, :3] == 0.0)
    c_e = e.T @ e / m
    c_ex = e.T @ x_hat / m
    sd = np.sqrt(np.diag(P_conv))
    sd_hat = np.sqrt(np.maximum(np.diag(P0) - np.diag(P_conv), 1e-300))
    sd_hat[:3] = 1.0
    # sampling sd of a covariance element <= sigma_i sigma_j sqrt(2 / m): 5 of them (0.035 relative here)
    tol = 5.0 * np.sqrt(2.0 / m)
    assert np.max(np.abs(c_e - P_conv) / np.outer(sd, sd)) < tol
    assert np.max(np.abs(c_ex) / np.outer(sd, sd_hat)) < tol
    # and the estimate's covariance is what is left: cov(x_hat_s) = Pi_ss - P_conv[s, s]
    c_hat = x_hat[:, s].T @ x_hat[:, s] / m
    np.testing.assert_allclose(c_hat, (P0 - P_conv)[np.ix_(s, s)], atol=tol * np.max(np.diag(P0)))


def test_conditioning_holds_in_mixed_units():
    """The same law when the states carry the filter's units: gyro-bias-like variances of ~1e-14 next to a clock-like
    1e4 (scaled by S, P -> S P S). Every state's drawn variance must be its P_conv's (the eigenvalue floor of the
    conditional covariance relative to its largest eigenvalue zeroed the small states' independent part: their
    variance came out at the part explained by x_s alone: 0.75, 0.71 and 0.95 of P_conv on the three small states)."""
    P0, P_conv, s = _linear_case()
    S = np.array([1e2, 1.0, 1e-7, 1.0, 1e-7, 1e2, 1e-7])
    P0, P_conv = P0 * np.outer(S, S), P_conv * np.outer(S, S)
    m, n = 40000, 7
    g = np.random.default_rng(11)
    x_s = g.standard_normal((m, 4)) * np.sqrt(np.diag(P0)[s])
    e, _ = initial.condition(P_conv, P0[np.ix_(s, s)], s, x_s, g.standard_normal((m, n)))
    sd = np.sqrt(np.diag(P_conv))
    c_e = e.T @ e / m
    tol = 5.0 * np.sqrt(2.0 / m)  # as above: 5 sampling sd of a normalized covariance element
    assert np.max(np.abs(c_e - P_conv) / np.outer(sd, sd)) < tol


def test_a_naive_independent_draw_is_not_orthogonal():
    """The check above can fail: e ~ N(0, P_conv) drawn independently of x_s has cov(e, x_hat) = -P_conv."""
    P0, P_conv, s = _linear_case()
    m = 40000
    g = np.random.default_rng(11)
    x_s = g.standard_normal((m, 4)) * np.sqrt(np.diag(P0)[s])
    e = g.standard_normal((m, 7)) @ np.linalg.cholesky(P_conv).T
    x_hat_s = x_s - e[:, s]
    c_ex = e.T @ x_hat_s / m
    assert np.max(np.abs(c_ex + P_conv[:, s])) < 0.1 * np.max(np.abs(P_conv[:, s]))


def test_prior_raised_only_where_P_conv_exceeds_it():
    P0, P_conv, s = _linear_case()
    P = P_conv.copy()
    P[6, 6] = 1.2 * P0[6, 6]  # a random-walk state grown past its stationary prior
    w, V = np.linalg.eigh(P)
    P = (V * np.maximum(w, 0.0)) @ V.T
    e, excess = initial.condition(P, P0[np.ix_(s, s)], s, np.zeros((2, 4)), np.zeros((2, 7)))
    assert excess > 0.1
    with pytest.raises(ValueError):
        initial.condition(P, P0[np.ix_(s, s)], s, np.zeros((1, 3)), np.zeros((1, 7)))  # wrong shapes


FIXED = replace(PROFILE, sensors=replace(
    PROFILE.sensors, gnss=replace(PROFILE.sensors.gnss, epoch="fixed")))
"""The default profile on one sky for every run (the default draws each run's own epoch)."""


def _start_default(runs=(0, 1, 2), prof=FIXED):
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 5.0,
                                        ground_speed_mps=70.0)
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=2, runs=list(runs))
    nav = NavSystem.from_profile(prof)
    obs = nav.observations(recs, float(truth.t_s[0]), 0.025, True)
    el = recs["gnss"].elevation_rad[0] if not recs["gnss"].per_run_sky else recs["gnss"].elevation_rad[0, 0]
    s, fl = nav.start(truth, [stream(2, r, "nav") for r in runs], 0, elevation_rad=el, obs=obs, states=st)
    return nav, truth, recs, st, s, fl, nav.initial_covariance(el)


def test_converged_start_of_the_default_profile():
    nav, truth, recs, st, s, fl, P0 = _start_default()
    lay = nav.layout
    P = fl[0].fs.P
    assert all(np.array_equal(r.fs.P, P) for r in fl)  # one P_conv for the runs on one truth
    assert np.all(np.linalg.eigvalsh(P) > -1e-9 * np.max(np.diag(P)))
    # GPS-aided for 10 minutes: vertical and velocity far below the prior, never above it
    d, d0 = np.diag(P), np.diag(P0)
    assert d[2] < 0.25 * d0[2] and np.all(d[3:6] < d0[3:6])
    # a channel out of view is never updated: it keeps its prior (estimate 0, variance, no correlation)
    out = np.flatnonzero(~recs["gnss"].valid[0, 0])
    assert out.size >= 18
    for k in out:
        j = lay.i("gse", int(k))
        assert d[j] == pytest.approx(d0[j], rel=1e-12)
        assert np.all(np.abs(np.delete(P[j], j)) < 1e-12 * d0[j])
        # m, against a 4 m prior: round-off of the Schur complement next to the 300 m clock prior (measured 2e-6)
        assert all(abs(r.fs.x[j]) < 1e-5 for r in fl)
    # a channel in view is estimated: x_hat = x - e differs from 0, and from the truth
    k = int(np.flatnonzero(recs["gnss"].valid[0, 0])[0])
    j = lay.i("gse", k)
    assert d[j] < d0[j]
    assert all(abs(r.fs.x[j]) > 0.0 for r in fl)


def test_batch_epoch_update_equals_the_sequential_scalar_recursion():
    """converged_covariance updates the epoch's rows at once; the filter's own recursion updates them one
    scalar row at a time (Joseph form each, converged_covariance_reference). Equal to rounding over the whole
    600 s segment."""
    nav, truth, recs, st, s, fl, P0 = _start_default(runs=(0,))
    obs = nav.observations(recs, float(truth.t_s[0]), 0.025, True)
    assert len(initial._segment(nav, truth, obs, 0, P0)[2]) >= 5  # rows to update
    P = initial.converged_covariance_reference(nav, truth, obs, 0, P0, 600.0)
    Pb = initial.converged_covariance(nav, truth, obs, 0, P0, 600.0)
    sd = np.sqrt(np.diag(P))
    assert np.max(np.abs(Pb - P) / np.outer(sd, sd)) < 1e-9
    assert not np.allclose(P, P0)  # the segment did something


def test_per_run_skies_get_their_own_converged_covariance():
    """Each run's own GPS sky (the default): its own P0 and P_conv, each a valid covariance, equal to the run
    started alone."""
    nav, truth, recs, st, s, fl, _ = _start_default(prof=PROFILE)
    assert recs["gnss"].per_run_sky
    assert not np.array_equal(fl[0].fs.P, fl[1].fs.P)
    for r in fl:
        assert np.all(np.linalg.eigvalsh(r.fs.P) > -1e-9 * np.max(np.diag(r.fs.P)))
    _, _, _, _, s1, alone, _ = _start_default(runs=(1,), prof=PROFILE)
    np.testing.assert_array_equal(alone[0].fs.P, fl[1].fs.P)
    np.testing.assert_array_equal(alone[0].fs.x, fl[1].fs.x)
    np.testing.assert_array_equal(s1.h_m, s.h_m[1:2])


def test_converged_start_without_a_baro():
    """A suite with its baro removed ([sensors.baro] enabled = false) starts converged: the filter's baro-bias
    state has no baro error to carry, so it starts and stays at 0 with zero variance (it stopped the start before:
    "no realized sensor value for filter state group 'bb'")."""
    prof = replace(FIXED, sensors=replace(FIXED.sensors, baro=None))
    nav, truth, recs, st, s, fl, P0 = _start_default(prof=prof)
    j = nav.layout.i("bb")
    assert "baro" not in recs and P0[j, j] == 0.0
    assert all(r.fs.P[j, j] == 0.0 and r.fs.x[j] == 0.0 for r in fl)
    assert np.all(np.isfinite(fl[0].fs.P)) and np.all(np.diag(fl[0].fs.P) >= 0.0)


def test_prior_start_keeps_todays_draws():
    truth = synthetic.glidepath_descent(PROFILE.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 5.0,
                                        ground_speed_mps=70.0)
    nav = NavSystem.build(replace(PROFILE.nav, initial_error=replace(PROFILE.nav.initial_error, start="prior")),
                          PROFILE.sensors, PROFILE.runway.frame, PROFILE.terrain)
    s, fl = nav.start(truth, [stream(2, 0, "nav")], 0)
    sd = np.sqrt(np.diag(nav.initial_covariance())[:9])
    e = sd * stream(2, 0, "nav").standard_normal(9)
    assert s.h_m[0] == pytest.approx(truth.h_m[0] - e[2], abs=1e-9)  # geodetic heights < 1000 m: floor 1e-13 m
    assert np.all(fl[0].fs.x == 0.0)
    with pytest.raises(ValueError, match="converged start"):
        NavSystem.from_profile(PROFILE).start(truth, [stream(2, 0, "nav")], 0)


def test_profile_key_start_is_checked():
    nav = parse_nav(Section({"initial_error": {"start": "prior", "converge_s": 120.0}}, "nav"))
    assert nav.initial_error.start == "prior" and nav.initial_error.converge_s == 120.0
    with pytest.raises(ProfileError, match="start"):
        parse_nav(Section({"initial_error": {"start": "warm"}}, "nav"))
    with pytest.raises(ProfileError, match="converge_s"):
        parse_nav(Section({"initial_error": {"converge_s": -1.0}}, "nav"))


def test_zero_segment_is_the_prior_start_in_distribution():
    """converge_s = 0: P_conv = P0, every sensor state keeps its prior (estimate 0, e_s = x_s)."""
    truth = synthetic.glidepath_descent(FIXED.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 5.0,
                                        ground_speed_mps=70.0)
    recs, st = measure_with_states(SensorSuite.from_profile(FIXED), truth, seed=2, runs=[0, 1])
    cfg = replace(FIXED.nav, initial_error=replace(FIXED.nav.initial_error, converge_s=0.0))
    nav = NavSystem.build(cfg, FIXED.sensors, FIXED.runway.frame, FIXED.terrain)
    el = recs["gnss"].elevation_rad[0]
    _, fl = nav.start(truth, [stream(2, r, "nav") for r in (0, 1)], 0, elevation_rad=el,
                      obs=nav.observations(recs, float(truth.t_s[0]), 0.025, True), states=st)
    np.testing.assert_array_equal(fl[0].fs.P, nav.initial_covariance(el))
    assert all(np.max(np.abs(r.fs.x)) < 1e-5 for r in fl)  # round-off next to the 300 m clock prior


@pytest.mark.parametrize("grade", ["nav-0.4", "nav-2.0", "tactical"])
def test_accelerometer_prior_is_per_axis_under_one_g(grade: str) -> None:
    """The ba prior (nav/noise.py initial_covariance): under 1 g, f_b = (0, 0, -g), a level triad's (S + M) f_b puts
    g x misalignment on each horizontal body axis and g x scale factor on the vertical only, beside the turn-on bias
    and bias instability on every axis (issue 39: both on every axis over-claimed the nav-0.4 candidate's tilt by
    13 %). Compared with the formula's own floating-point value: the same operations, so equal to within one
    rounding of the sum (4 eps of the largest term)."""
    from approachsim.sensors.presets import PRESETS

    prof = replace(PROFILE, sensors=replace(PROFILE.sensors, imu=replace(PROFILE.sensors.imu, grade=grade)))
    nav = NavSystem.from_profile(prof)
    g = PRESETS[grade]
    ba = np.diag(nav.initial_covariance())[nav.layout.index["ba"]]
    base = g.accel_bias_mps2**2 + g.accel_bi_mps2**2
    want = base + np.array([9.8 * g.accel_misalign_rad, 9.8 * g.accel_misalign_rad, 9.8 * g.accel_sf]) ** 2
    np.testing.assert_allclose(ba, want, rtol=4 * np.finfo(float).eps)
    if g.accel_sf != g.accel_misalign_rad:  # the axes differ as the scale factor and misalignment do
        assert ba[0] == ba[1] and ba[2] != ba[0]
