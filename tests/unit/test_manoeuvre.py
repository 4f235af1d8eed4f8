"""The vertical-manoeuvre truth (approachsim/manoeuvre.py) is kinematically exact: its own increments, through
the strapdown INS (approachsim/nav/ins.py), reproduce it; and its height profile is the one documented."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim import geo, manoeuvre, synthetic
from approachsim.nav import ins
from approachsim.sensors.imu import true_increments

RWY = geo.RunwayFrame(math.radians(37.6117), math.radians(-122.3581), 4.0, math.radians(298.0))


@pytest.fixture(scope="module")
def truth():
    return manoeuvre.vertical_manoeuvre(RWY, rate_hz=10.0)


def test_height_profile_climbs_descends_and_levels_off(truth):
    legs = manoeuvre.SEED003_LEGS
    h, v_up, a_up = manoeuvre.vertical_profile(truth.t_s, 600.0, legs)
    # the truth's height and climb rate are vertical_profile's (same code path: bit-identical in fact); the bounds are
    # 900x floor(5, 1000 m) = 1.1e-12 m and 200x floor(5, 4 m/s) = 4.4e-15 m/s
    np.testing.assert_allclose(truth.h_m, h, atol=1e-9)
    np.testing.assert_allclose(-truth.v_ned[:, 2], v_up, atol=1e-12)
    # level at the start, after every leg the height has changed by exactly that leg's dh, and level again
    for k, leg in enumerate(legs):
        i0, i1 = np.searchsorted(truth.t_s, [leg.start_s, leg.end_s])
        before = 600.0 + sum(lg.dh_m for lg in legs[:k])
        assert truth.h_m[i0] == pytest.approx(before, abs=1e-9)
        assert truth.h_m[i1] == pytest.approx(before + leg.dh_m, abs=1e-9)
        # 1 - cos(2 pi s) at s = 0 and 1 is an exact 0 (cos(0) = cos(fl(2 pi)) = 1.0): the bounds only allow for s a
        # few ulp off an end, (2 pi k eps)^2 / 2 ~ 1e-30
        assert v_up[i0] == pytest.approx(0.0, abs=1e-12) and v_up[i1] == pytest.approx(0.0, abs=1e-9)
        mid = (i0 + i1) // 2
        assert v_up[mid] == pytest.approx(leg.peak_climb_mps, rel=1e-3)
        assert np.abs(a_up[i0:i1 + 1]).max() == pytest.approx(leg.peak_accel_mps2, rel=1e-3)
    # the manoeuvre shows in the specific force: f_ned = v' + (2 w_ie + w_en) x v - g_ned (seed 003 eq. 2; the
    # Coriolis and transport terms are ~0.65 mg at 70 m/s east-west), interval means
    c_nb = ins.cbn_from_quaternion(truth.q_nb)
    f_ned = np.einsum("nij,nj->ni", c_nb, truth.f_body)
    w = 2.0 * synthetic.earth_rate_ned(truth.lat_rad) + synthetic.transport_rate_ned(truth.lat_rad, truth.h_m,
                                                                                      truth.v_ned)
    cor = np.cross(w, truth.v_ned)
    g = synthetic.gravity_ned(truth.lat_rad, truth.h_m)
    mean = lambda a: 0.5 * (a[:-1] + a[1:])  # noqa: E731 - the interval mean (trapezoid)
    expected = np.diff(truth.v_ned, axis=0) * 10.0 + mean(cor) - mean(g)
    # velocity differences of ~70 m/s over 0.1 s (floor(2, 70, 70) / 0.1 = 3e-13 m/s^2) and ~10 roundings of g and
    # the rotation (floor(10, 9.8) = 2e-14): 1e-7 m/s^2 is far above them (the truth integrates these interval means)
    np.testing.assert_allclose(f_ned[:-1], expected, atol=1e-7)
    assert np.abs(cor[:, 2]).max() > 1e-3  # the check above would see a missing Coriolis term
    assert np.abs(np.diff(truth.v_ned[:, 2])).max() * 10.0 > 0.5  # and the manoeuvre's own acceleration


def test_exact_increments_through_the_ins_reproduce_the_truth(truth):
    """Unaided INS (no damping loop) from the true initial state with the truth's own increments: over the
    520 s profile with four 0.16-0.63 m/s^2 vertical manoeuvres it stays < 1 cm and < 1 mm/s of the truth."""
    m = truth.t_s.shape[0] - 1
    dth, dv, dt = true_increments(truth, np.arange(1, m + 1))
    s = ins.init_state(np.array([truth.lat_rad[0]]), truth.lon_rad[0], truth.h_m[0], truth.v_ned[0],
                       ins.cbn_from_quaternion(truth.q_nb[0]))
    dp = np.empty((m, 3))
    dvel = np.empty((m, 3))
    psi = np.empty((m, 3))
    for j in range(m):
        s = ins.step(s, dth[j][None], dv[j][None], dt)
        dp[j] = ins.position_error_ned(s.lat_rad, s.lon_rad, s.h_m, truth.lat_rad[j + 1], truth.lon_rad[j + 1],
                                       truth.h_m[j + 1])[0]
        dvel[j] = s.v_ned[0] - truth.v_ned[j + 1]
        psi[j] = ins.attitude_error(s.c_bn, ins.cbn_from_quaternion(truth.q_nb[j + 1][None]))[0]
    assert np.abs(dp).max() < 0.01
    assert np.abs(dvel).max() < 1e-3
    assert np.abs(psi).max() < 1e-8


def test_bad_leg_is_refused():
    with pytest.raises(ValueError, match="start_s < end_s"):
        manoeuvre.VerticalLeg(10.0, 10.0, 100.0)
    with pytest.raises(ValueError, match="dh_m"):
        manoeuvre.VerticalLeg(0.0, 10.0, float("nan"))


def test_glidepath_deviation_is_against_the_straight_cone(truth):
    """gs_dev_m is the height above the straight glide path cone (approachsim.glidepath, 3 deg, 15.24 m TCH), the
    one glide path reference, not above the path parallel to the ellipsoid (which lies x^2 / 2R lower: the two
    differ by metres over the manoeuvre's 36 km)."""
    from approachsim.glidepath import GlidePath

    cone = GlidePath(math.radians(3.0), 15.24, RWY.heading_rad, RWY.threshold_lat_rad)
    # the same expression on the same operands: equal to rounding (floor(4, 1000 m) = 8.9e-13 m; 1e-9 is 1100x)
    np.testing.assert_allclose(truth.gs_dev_m, cone.deviation_rwy_m(truth.r_rwy), rtol=0, atol=1e-9)
    flat = truth.r_rwy[:, 2] - (15.24 - truth.r_rwy[:, 0] * math.tan(math.radians(3.0)))
    assert np.max(flat - truth.gs_dev_m) > 5.0
