"""Touchdown scoring (evaluate/touchdown.py): the rigid-body gear state against an independent rotation oracle and a
finite difference, the normal-tail bounds' coverage on constructed normal samples, the extrapolated probability,
what the extrapolation cannot see (a heavier tail that passes the normality test), the outcome / verdict rules and
the details block's keys against docs/contract.md."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from floors import assert_within, floor
from scipy import stats as sps
from scipy.spatial.transform import Rotation

from approachsim import units
from approachsim.evaluate.stats import MIN_RUNS
from approachsim.evaluate.touchdown import (
    CRITERIA,
    SCALARS,
    Criterion,
    c_nb_from_euler,
    clean_runs_needed,
    contact_bank_rad,
    contact_offsets_m,
    criterion_result,
    gear_state,
    nct_sf,
    overall_verdict,
    runs_to_decide,
    tail_bounds,
    touchdown_details,
    touchdown_summary,
    upper_tail_bounds,
    upper_tail_bounds_wald,
    z_required,
)

ROOT = Path(__file__).resolve().parents[3]
LEVER = np.array([[-10.11, -2.54, 0.356], [-10.11, 2.54, 0.356]])
"""The JSBSim 737's main gears relative to the IMU of aircraft/737.toml, body axes, m (x fwd, y right, z down)."""


# --- geometry ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("euler_deg", [(0.0, 0.0, 0.0), (3.0, 4.5, 297.0), (-12.0, -2.0, 10.0), (25.0, 8.0, 181.0)])
def test_c_nb_is_the_zyx_rotation(euler_deg):
    e = np.radians(euler_deg)
    oracle = Rotation.from_euler("ZYX", [e[2], e[1], e[0]]).as_matrix()
    # two formulas of a rotation: direction cosines in ~5 roundings of sin/cos products (entries <= 1), scipy's Euler
    # -> quaternion -> matrix in ~10: floor(16, 1) = 3.6e-15 (the 1e-15 it had was 4.5 eps)
    assert_within(c_nb_from_euler(e), oracle, floor(16, 1.0), "C_nb")


def test_level_gear_positions_are_the_lever_arms_in_runway_axes():
    """Wings level, nose on the runway heading: a gear 10.11 m aft and 2.54 m right of the IMU, 0.356 m below it,
    is 10.11 m behind it along the runway, 2.54 m right and 0.356 m lower."""
    heading = math.radians(298.0)
    r = np.array([500.0, 1.0, 5.0])
    pos, vel = gear_state(r, np.zeros(3), np.array([0.0, 0.0, heading]), np.zeros(3), heading, LEVER)
    # r + C l: a 3-term rotation of the 10.4 m lever arm added to a 500 m position: floor(4, |r|, |l|) = 4.5e-13 m
    fl = floor(4, np.linalg.norm(r), np.linalg.norm(LEVER[0]))
    assert_within(pos[1], r + np.array([-10.11, 2.54, -0.356]), fl, "right gear")
    assert_within(pos[0], r + np.array([-10.11, -2.54, -0.356]), fl, "left gear")
    np.testing.assert_allclose(vel, 0.0, atol=1e-15)  # exact by construction: zero velocity and rate give exact zeros


def test_pitched_up_gear_sits_lower_by_the_lever_arm_times_sin_pitch():
    heading = 0.3
    theta = math.radians(4.0)
    pos, _ = gear_state(np.zeros(3), np.zeros(3), np.array([0.0, theta, heading]), np.zeros(3), heading, LEVER)
    # nose up: the aft gear goes down by 10.11 sin(theta), and its 0.356 m below the IMU shrinks to cos(theta)
    # (~5 roundings of the 10.11 m and 0.356 m terms: floor(5, 10.11, 0.356) = 1.2e-14 m; 1e-12 is 85x that)
    assert pos[0, 2] == pytest.approx(-10.11 * math.sin(theta) - 0.356 * math.cos(theta), abs=1e-12)
    assert pos[0, 0] == pytest.approx(-10.11 * math.cos(theta) + 0.356 * math.sin(theta), abs=1e-12)


@pytest.mark.parametrize("w_body", [(0.0, 0.03, 0.0), (0.05, -0.02, 0.01), (-0.1, 0.04, -0.03)])
def test_gear_velocity_is_the_derivative_of_its_position(w_body):
    """v_gear = v_imu + C_nb (w x l) against a central difference of gear_state's positions with the attitude
    propagated by the body rate (scipy Rotation) and the IMU moved at v_imu."""
    heading = math.radians(298.0)
    e0 = np.radians([2.0, 4.0, 300.0])
    w = np.array(w_body)
    v_ned = np.array([30.0, -58.0, 1.2])
    r0 = np.array([450.0, 0.5, 1.0])
    rot0 = Rotation.from_euler("ZYX", [e0[2], e0[1], e0[0]])
    c_rn = np.array([[math.cos(heading), math.sin(heading), 0.0], [-math.sin(heading), math.cos(heading), 0.0],
                     [0.0, 0.0, -1.0]])

    def at(dt: float) -> np.ndarray:
        rot = rot0 * Rotation.from_rotvec(w * dt)
        z, y, x = rot.as_euler("ZYX")
        return gear_state(r0 + c_rn @ v_ned * dt, v_ned, np.array([x, y, z]), w, heading, LEVER)[0]

    h = 1e-4
    fd = (at(h) - at(-h)) / (2 * h)
    _, vel = gear_state(r0, v_ned, e0, w, heading, LEVER)
    # central difference of ~450 m positions over 2e-4 s: floor(4, 450, 450) / 2e-4 = 4e-9 m/s, truncation h^2
    # |d3x/dt3| / 6 ~ 1e-11 m/s: 1e-7 m/s is 25x the floor
    np.testing.assert_allclose(vel, fd, atol=1e-7)


def test_the_scalars_list_is_what_touchdown_scalars_returns():
    from approachsim.evaluate import touchdown as td

    assert set(td.QUANTITIES) <= set(SCALARS)
    assert {c.quantity for c in CRITERIA} <= set(SCALARS)


# --- the noncentral t and the normal-tail bounds -----------------------------------------------------------------


@pytest.mark.parametrize(("t", "df", "delta"), [(33.6, 49, 30.0), (5.0, 4, 3.0), (-21.0, 49, -20.0), (2.0, 2, 0.5),
                                                (150.0, 999, 140.0)])
def test_nct_sf_agrees_with_scipy_where_scipy_converges(t, df, delta):
    # two algorithms (our series against scipy's Boost): their truncation, not rounding (floor(50, p) ~ 1e-14 p), sets
    # the agreement; rel 1e-9 / abs 1e-13 are what both converge to
    assert nct_sf(t, df, delta) == pytest.approx(float(sps.nct.sf(t, df, delta)), rel=1e-9, abs=1e-13)


def _coverage(n: int, p_true: float, trials: int, seed: int, level: float = 0.95) -> tuple[float, float]:
    """Fractions of normal samples of n whose upper / lower bound of P(X > L) covers the true p (L at p_true)."""
    rng = np.random.default_rng(seed)
    limit = float(sps.norm.isf(p_true))
    up = lo = 0
    for _ in range(trials):
        x = rng.normal(0.0, 1.0, n)
        m, s = float(np.mean(x)), float(np.std(x, ddof=1))
        _, p_lo, p_hi = upper_tail_bounds((limit - m) / s, n, level)
        up += p_hi >= p_true
        lo += p_lo <= p_true
    return up / trials, lo / trials


@pytest.mark.parametrize(("n", "p_true", "seed"), [(20, 1e-3, 1), (50, 1e-6, 2), (10, 1e-2, 3)])
def test_normal_tail_bounds_cover_95_percent(n, p_true, seed):
    """The bounds are exact for normal data (the noncentral t of the tolerance limit): 1000 samples, binomial sd of
    a 95 % coverage 0.0069, acceptance +-0.025 (3.6 sd)."""
    up, lo = _coverage(n, p_true, 1000, seed)
    assert abs(up - 0.95) <= 0.025, up
    assert abs(lo - 0.95) <= 0.025, lo


def test_the_extrapolated_probability_of_a_large_normal_sample():
    """On 100,000 normal values, Phi(-z) at the 1e-6 limit is 1e-6 within its sampling error (z's sd
    sqrt(1/n + z^2 / 2n) = 0.011, dlog p / dz ~ 5: 6 % relative; acceptance 25 %), inside the 95 % bounds."""
    rng = np.random.default_rng(11)
    x = rng.normal(1000.0, 60.0, 100_000)
    crit = Criterion("long", "q", "above", 1000.0 + 60.0 * z_required(1e-6), "ft", 1e-6, "V", "test", "test")
    p, p_lo, p_hi = tail_bounds(crit, float(np.mean(x)), float(np.std(x, ddof=1)), x.size, 0.95)
    assert p == pytest.approx(1e-6, rel=0.25)
    assert p_lo <= 1e-6 <= p_hi


def test_wald_form_is_close_to_the_exact_bounds():
    for z, n in ((4.75, 50), (4.9, 10**6), (1.0, 5), (6.0, 20)):
        ex, wa = upper_tail_bounds(z, n, 0.95), upper_tail_bounds_wald(z, n, 0.95)
        assert ex[0] == wa[0]
        # in log probability the two bound forms agree to a few per cent of the distance to the point
        for i in (1, 2):
            assert abs(math.log(ex[i] / wa[i])) <= 0.2 * abs(math.log(ex[i] / ex[0])) + 1e-9, (z, n, ex, wa)


def test_a_heavier_tail_that_passes_the_normality_test_is_invisible_to_the_extrapolation():
    """Student t(8) scaled to unit variance: at N = 50 Shapiro-Wilk rejects normality in only about a fifth of the
    samples, yet the normal fit puts the distribution's true 1e-6 quantile (10.5 sd) at 1e-14 or less, and even
    the 95 % upper bound is orders of magnitude below 1e-6: the bound covers only under the normal model."""
    rng = np.random.default_rng(7)
    q = float(sps.t.isf(1e-6, 8) / math.sqrt(8 / 6))
    crit = Criterion("t8", "q", "above", q, "ft", 1e-6, "V", "test", "test")
    rejected, p_hat, p_up = [], [], []
    for _ in range(200):
        x = rng.standard_t(8, 50) / math.sqrt(8 / 6)
        rejected.append(sps.shapiro(x).pvalue < 0.05)
        p, _, hi = tail_bounds(crit, float(np.mean(x)), float(np.std(x, ddof=1)), 50, 0.95)
        p_hat.append(p)
        p_up.append(hi)
    assert np.mean(rejected) < 0.35
    assert max(p_hat) < 1e-9
    assert np.median(p_up) < 1e-9


def test_clean_runs_needed_is_the_zero_failure_binomial_bound():
    n = clean_runs_needed(1e-6, 0.95)
    assert 1.0 - (1.0 - 1e-6) ** n >= 0.95 > 1.0 - (1.0 - 1e-6) ** (n - 1)
    assert n == 2995731


def test_runs_to_decide_is_where_the_planning_bound_crosses():
    crit = next(c for c in CRITERIA if c.key == "long")
    for mean, sd in ((480.0, 60.0), (480.0, 85.0), (600.0, 70.0)):
        n = runs_to_decide(crit, mean, sd, 0.95)
        p = tail_bounds(crit, mean, sd, 3, 0.95, exact=False)[0]
        assert n is not None
        if p < crit.probability:  # towards within: the upper bound reaches the requirement at n, not before
            assert tail_bounds(crit, mean, sd, n, 0.95, exact=False)[2] <= crit.probability
            if n > MIN_RUNS:
                assert tail_bounds(crit, mean, sd, n - 1, 0.95, exact=False)[2] > crit.probability
        else:
            assert tail_bounds(crit, mean, sd, n, 0.95, exact=False)[1] > crit.probability


# --- outcome and verdict -----------------------------------------------------------------------------------------


def _sample(n: int, mean: float, sd: float, seed: int = 5) -> np.ndarray:
    """n values with exactly this mean and sd (ddof 1): a standardized normal draw, rescaled."""
    x = np.random.default_rng(seed).normal(size=n)
    return mean + sd * (x - x.mean()) / x.std(ddof=1)


VERIFIED_LONG = Criterion("long", "td_x_m", "above", 915.0, "ft", 1e-6, "V", "test", "test")


def test_within_on_a_verified_limit_meets_and_on_an_unverified_one_says_so():
    x = _sample(200, 450.0, 40.0)  # the limit 11.6 sd away
    r = criterion_result(VERIFIED_LONG, x, 0, 0.95)
    assert (r["outcome"], r["verdict"]) == ("within", "meets")
    s = criterion_result(next(c for c in CRITERIA if c.key == "long"), x, 0, 0.95)
    assert s["mark"] == "S" and (s["outcome"], s["verdict"]) == ("within", "unverified_limit")
    assert s["normal"]["probability_upper"] <= 1e-6 and s["normal"]["z_limit"] == pytest.approx(465.0 / 40.0)


def test_a_failed_landing_counts_as_an_exceedance_and_fails_the_criterion():
    x = _sample(49, 450.0, 40.0)
    r = criterion_result(VERIFIED_LONG, x, 1, 0.95)
    assert (r["exceedances"], r["runs"], r["failed_runs"]) == (1, 50, 1)
    assert (r["outcome"], r["verdict"]) == ("exceeds", "fails")
    assert r["empirical"]["lower"] == pytest.approx(1.0 - 0.95 ** (1 / 50), rel=1e-9)


def test_too_close_a_limit_is_indeterminate_with_the_runs_to_decide():
    x = _sample(50, 450.0, 90.0)  # z = 5.2 > 4.75: the point estimate is within, the bound from 50 runs is not
    r = criterion_result(VERIFIED_LONG, x, 0, 0.95)
    assert r["outcome"] == "indeterminate" and r["normal"]["probability"] < 1e-6 < r["normal"]["probability_upper"]
    assert r["normal"]["runs_needed"] > 50
    far = criterion_result(VERIFIED_LONG, _sample(50, 450.0, 110.0), 0, 0.95)  # z = 4.2: the point is beyond
    assert far["normal"]["probability"] > 1e-6 and far["outcome"] in ("indeterminate", "exceeds")


def test_rejected_normality_and_too_few_runs_are_indeterminate():
    skewed = 450.0 + 40.0 * np.random.default_rng(2).exponential(size=300)  # far from the limit, but not normal
    r = criterion_result(VERIFIED_LONG, skewed, 0, 0.95)
    assert r["normal"]["normality"]["rejected"] and r["outcome"] == "indeterminate"
    few = criterion_result(VERIFIED_LONG, _sample(MIN_RUNS - 1, 450.0, 10.0), 0, 0.95)
    assert few["normal"]["probability_upper"] <= 1e-6 and few["outcome"] == "indeterminate"


def test_below_and_two_sided_criteria_use_their_own_tails():
    short = Criterion("short", "td_x_m", "below", 60.0, "ft", 1e-6, "V", "t", "t")
    x = _sample(100, 100.0, 10.0)  # the short limit 4 sd below the mean: beyond the 4.75 required
    r = criterion_result(short, x, 0, 0.95)
    assert r["normal"]["z_limit"] == pytest.approx(4.0) and r["normal"]["probability"] == pytest.approx(sps.norm.sf(4))
    lat = Criterion("lat", "td_y_m", "abs_above", 15.0, "ft", 1e-6, "V", "t", "t")
    y = _sample(100, 2.0, 2.0)
    p = criterion_result(lat, y, 0, 0.95)["normal"]["probability"]
    assert p == pytest.approx(sps.norm.sf(6.5) + sps.norm.sf(8.5), rel=1e-12)  # the same two calls summed: 4500 eps


def test_the_outboard_gear_is_two_normal_tails_not_one_bimodal_fit():
    """The outboard gear: the right gear's upper tail plus the left gear's lower tail, each fitted on its own; the
    signed outboard position (whichever gear is farther out) is bimodal and fails the normality test."""
    crit = next(c for c in CRITERIA if c.key == "outboard_gear")
    centre = _sample(200, -1.0, 2.7)
    left, right = centre - 2.54, centre + 2.54
    r = criterion_result(crit, right, 0, 0.95, x_low_si=left)
    lim = 70.0 * units.FT
    assert r["lower_quantity"] == "td_left_gear_y_m"
    assert r["normal"]["probability"] == pytest.approx(sps.norm.sf((lim - right.mean()) / right.std(ddof=1))
                                                       + sps.norm.sf((lim + left.mean()) / left.std(ddof=1)))
    assert r["normal"]["z_limit"] == pytest.approx((lim + left.mean()) / 2.7)  # the left gear is the nearer
    outboard = np.where(np.abs(right) > np.abs(left), right, left)
    assert sps.shapiro(outboard).pvalue < 1e-3


def test_overall_verdict():
    def res(*v):
        return {str(i): {"verdict": x} for i, x in enumerate(v)}

    assert overall_verdict(res("meets", "meets")) == "meets"
    assert overall_verdict(res("meets", "indeterminate")) == "indeterminate"
    assert overall_verdict(res("meets", "unverified_limit")) == "unverified_limits"
    assert overall_verdict(res("fails", "unverified_limit")) == "fails"


def test_no_shipped_limit_is_verified_so_no_verdict_is_claimed():
    """docs/touchdown.md: AC 120-28D's and CS-AWO's own numbers were not found; a limit marked V would need them."""
    assert all(c.mark in ("S", "U") for c in CRITERIA)
    assert {c.key for c in CRITERIA if c.mark == "U"} == {"outboard_gear", "ground_contact"}


@pytest.mark.parametrize("theta_deg", [-2.0, 0.0, 3.0, 4.4, 8.0])
def test_the_contact_bank_puts_the_point_on_the_ground(theta_deg):
    """contact_bank_rad against an independent rotation (scipy, ZYX roll-pitch with the heading 0): at the bank
    it returns, the point's down coordinate equals the gear contact's (the ground plane), to 1e-12 m; at a bank
    0.1 deg short of it the point is above the ground."""
    d = np.array([[2.74, 2.36, -0.46], [-3.45, 11.89, -3.93], [0.0, 5.0, -1.0]])
    theta = math.radians(theta_deg)
    phi = contact_bank_rad(theta, d)
    for p, ph in zip(d, phi, strict=True):
        down = Rotation.from_euler("ZYX", [0.0, theta, ph]).apply(p)[2]
        assert down == pytest.approx(0.0, abs=1e-12)
        short = Rotation.from_euler("ZYX", [0.0, theta, ph - math.radians(0.1)]).apply(p)[2]
        assert short < 0.0  # z down: negative is above the ground
    # level pitch: atan(height / outboard distance)
    assert contact_bank_rad(0.0, d[2:])[0] == pytest.approx(math.atan(1.0 / 5.0), rel=1e-14)


def test_contact_offsets_take_the_struct_frame_and_the_strut_compression():
    """Structural (x aft, y right, z up) to body (x forward, y right, z down) offsets from the gear; a compressed
    strut brings every point closer to the ground by the compression."""
    gear = np.array([16.46, 2.54, -2.13])
    pt = np.array([[13.72, 4.90, -1.54]])
    d0 = contact_offsets_m(pt, gear, 0.0)[0]
    np.testing.assert_allclose(d0, [2.74, 2.36, -0.59], atol=1e-12)
    d1 = contact_offsets_m(pt, gear, 0.136)[0]
    assert d1[2] - d0[2] == pytest.approx(0.136, abs=1e-15)
    assert contact_bank_rad(0.0, d1[None, :])[0] < contact_bank_rad(0.0, d0[None, :])[0]


# --- the details block and the contract --------------------------------------------------------------------------


def _columns(n: int = 30) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(4)
    cols = {k: rng.normal(0.0, 0.01, n) for k in SCALARS}
    cols["td_x_m"] = rng.normal(460.0, 50.0, n)
    cols["td_y_m"] = rng.normal(-2.0, 1.0, n)
    cols["td_outboard_gear_y_m"] = cols["td_y_m"] - 2.54
    cols["td_sink_mps"] = rng.normal(1.0, 0.4, n)
    cols["td_cas_mps"] = rng.normal(67.0, 1.0, n)
    return cols


def test_details_are_strict_json_in_display_units():
    det = touchdown_details(_columns(), runs=31, failed_runs=1, level=0.95)
    json.dumps(det, allow_nan=False)
    assert (det["runs"], det["landings"], det["failed_runs"]) == (31, 30, 1)
    assert det["quantities"]["x_ft"]["mean"] == pytest.approx(np.mean(_columns()["td_x_m"]) / units.FT)
    assert det["criteria"]["sink"]["limit"] == pytest.approx(10.0)
    assert det["criteria"]["bank"]["limit"] == pytest.approx(12.0)
    assert all(c["exceedances"] >= 1 for c in det["criteria"].values())  # the failed run, every criterion
    s = touchdown_summary(det)
    json.dumps(s, allow_nan=False)
    assert s["verdict"] == det["verdict"] == "unverified_limits"


def _keys(d, prefix: str = "") -> set[str]:
    out = set()
    for k, v in d.items():
        out.add(k)
        if isinstance(v, dict) and k not in ("criteria", "quantities"):
            out |= _keys(v)
        elif k in ("criteria", "quantities"):
            out |= {kk for e in v.values() for kk in _keys(e)}
            out |= set(v)
    return out


def test_every_touchdown_key_is_in_the_contract():
    det = touchdown_details(_columns(), runs=30, failed_runs=0, level=0.95)
    text = (ROOT / "docs" / "contract.md").read_text(encoding="utf-8")
    start = text.index("## Touchdown")
    end = text.find("\n## ", start + 1)
    section = text[start:end if end > 0 else None]
    documented = set(re.findall(r"`([A-Za-z0-9_]+)`", section)) | set(re.findall(r'"([A-Za-z0-9_]+)"', section))
    keys = _keys(det) | set(touchdown_summary(det))
    missing = {k for k in keys if not re.fullmatch(r"p\d+", k)} - documented
    assert not missing, missing
