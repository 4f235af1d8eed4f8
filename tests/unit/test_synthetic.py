"""Synthetic test truth is kinematically consistent, checked in the ECEF/inertial frame (independent of NED)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim import geo, synthetic
from approachsim.glidepath import GlidePath

RWY = geo.RunwayFrame(math.radians(37.6117), math.radians(-122.3581), 4.0, math.radians(298.0))


def _c_en(lat, lon):
    return np.swapaxes(geo.c_ecef_to_ned(lat, lon), -1, -2)


def _log_so3(c):
    """Rotation vector of rotation matrices (..., 3, 3) (small and moderate angles)."""
    a = np.arccos(np.clip((np.trace(c, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0))
    v = np.stack([c[..., 2, 1] - c[..., 1, 2], c[..., 0, 2] - c[..., 2, 0], c[..., 1, 0] - c[..., 0, 1]], axis=-1)
    return v * (a / np.where(a > 1e-15, 2.0 * np.sin(a), 2.0))[..., None]


def _check_ecef_consistency(truth, tol_acc, tol_rate):
    """r'' = C_en (f + g) - 2 W x r' - W x (W x r) + W x (W x r) ... in ECEF with g = geo.gravity_ned (plumb)."""
    t = truth.t_s
    dt = t[1] - t[0]
    r = truth.r_ecef
    # central differences at interior samples: of 6.4e6 m ECEF positions, so the second difference carries
    # floor(1, |r|, 2|r|, |r|) / dt^2 ~ 4 eps |r| / dt^2 = 5.7e-9 m/s^2 per rounding, ~4 of them: 2.3e-8 m/s^2 at dt =
    # 1 s (tol_acc 1e-7 and 2e-7 are 4x and 9x that); the velocity floor(2, |r|, |r|) / 2 dt = 2.8e-9 m/s (1e-6: 350x)
    v_e = (r[2:] - r[:-2]) / (2 * dt)
    a_e = (r[2:] - 2 * r[1:-1] + r[:-2]) / dt**2
    lat, lon, h = truth.lat_rad[1:-1], truth.lon_rad[1:-1], truth.h_m[1:-1]
    c_en = _c_en(lat, lon)
    c_nb = synthetic.euler_to_c_nb(truth.euler_rad[1:-1])
    f_ned = np.einsum("nij,nj->ni", c_nb, truth.f_body[1:-1])
    g_ned = synthetic.gravity_ned(lat, h)
    w = np.array([0.0, 0.0, geo.OMEGA_E])
    # ECEF Newton with plumb-bob gravity (gravitation + centrifugal): r'' = C_en (f + g) - 2 w x r'
    a_model = np.einsum("nij,nj->ni", c_en, f_ned + g_ned) - 2.0 * np.cross(w, v_e)
    assert np.max(np.abs(a_e - a_model)) < tol_acc
    # velocity in NED from position differences
    v_ned = np.einsum("nji,nj->ni", c_en, v_e)
    assert np.max(np.abs(v_ned - truth.v_ned[1:-1])) < 1e-6
    # body rate relative to inertial space: C_ib(t) = Rz(W t) C_en C_nb, rotation between samples k-1 and k+1
    def c_ib(k):
        wt = geo.OMEGA_E * t[k]
        rz = np.array([[math.cos(wt), -math.sin(wt), 0.0], [math.sin(wt), math.cos(wt), 0.0], [0.0, 0.0, 1.0]])
        cen = _c_en(truth.lat_rad[k], truth.lon_rad[k])
        return rz @ cen @ synthetic.euler_to_c_nb(truth.euler_rad[k])

    # the rotation vector of C'C from differences of entries of size 1, ~20 roundings: floor(20, 1) / 2 dt = 2.2e-15
    # rad/s at dt = 1 s (tol_rate 1e-12 and 1e-11 are >= 450x that, the descent's covering the truncation too)
    for k in (1, len(t) // 2, len(t) - 2):
        dc = c_ib(k - 1).T @ c_ib(k + 1)
        w_fd = _log_so3(dc) / (2 * dt)
        assert np.max(np.abs(w_fd - truth.w_ib_body[k])) < tol_rate


def test_stationary_reads_one_g_up_and_earth_rate():
    tr = synthetic.stationary(RWY.threshold_lat_rad, RWY.threshold_lon_rad, 4.0, 10.0, 10.0,
                              euler_rad=(0.1, -0.05, 1.0))
    g = np.linalg.norm(geo.gravity_ned(RWY.threshold_lat_rad, 4.0))
    # g rotated into the body and normed, ~10 roundings of 9.8 m/s^2: floor(10, 9.8) = 2.2e-14; 1e-12 is 45x that
    assert np.allclose(np.linalg.norm(tr.f_body, axis=1), g, rtol=0, atol=1e-12)
    assert np.allclose(np.linalg.norm(tr.w_ib_body, axis=1), geo.OMEGA_E, rtol=1e-12)  # 4500 eps of a ~10-op chain
    # level attitude: f_body = (0, 0, -g), gyros see Earth rate north and up components
    lv = synthetic.stationary(RWY.threshold_lat_rad, 0.0, 0.0, 1.0, 10.0)
    assert np.allclose(lv.f_body[0], -geo.gravity_ned(RWY.threshold_lat_rad, 0.0), atol=1e-12)  # 45x, as above
    lat = RWY.threshold_lat_rad
    # ~10 roundings of the 7.3e-5 rad/s Earth rate: floor(10, 7.3e-5) = 1.6e-19 rad/s; 1e-18 is 6x that
    assert np.allclose(lv.w_ib_body[0], geo.OMEGA_E * np.array([math.cos(lat), 0, -math.sin(lat)]), atol=1e-18)
    assert np.all(tr.v_ned == 0.0)  # exact by construction: a stationary truth writes zeros


def test_stationary_is_consistent_in_ecef():
    tr = synthetic.stationary(RWY.threshold_lat_rad, RWY.threshold_lon_rad, 400.0, 20.0, 1.0,
                              euler_rad=(0.2, 0.1, -2.0))
    _check_ecef_consistency(tr, tol_acc=1e-7, tol_rate=1e-12)


def test_descent_is_consistent_in_ecef():
    tr = synthetic.glidepath_descent(RWY, rate_hz=1.0, ground_speed_mps=72.0)
    _check_ecef_consistency(tr, tol_acc=2e-7, tol_rate=1e-11)


def test_descent_follows_the_straight_cone_and_reaches_the_threshold():
    """The descent is the straight line of the glide path cone (approachsim.glidepath): its elevation angle seen
    from the GPI, above the GPI's horizontal plane, is the glide path angle at every sample (exact ECEF
    geometry), the recorded gs_dev_m is the cone's second-order approximation error (< 5 mm), and it ends on the
    centreline at the threshold at the cone's height there."""
    gp = math.radians(3.0)
    tr = synthetic.glidepath_descent(RWY, rate_hz=10.0, start_distance_m=18520.0, tch_m=15.24, glidepath_rad=gp)
    cone = GlidePath(gp, 15.24, RWY.heading_rad, RWY.threshold_lat_rad)
    # the exact cone: elevation from the GPI (on the centreline at the threshold's ellipsoid height)
    lat_g, lon_g, _ = geo.ecef_to_geodetic(RWY.to_ecef(np.array([cone.gpi_m, 0.0, 0.0])))
    gpi = geo.geodetic_to_ecef(lat_g, lon_g, RWY.threshold_h_m)
    ned = (tr.r_ecef - gpi) @ geo.c_ecef_to_ned(lat_g, lon_g).T
    elevation = np.arctan2(-ned[:, 2], np.hypot(ned[:, 0], ned[:, 1]))
    # atan2 of differences of 6.4e6 m ECEF positions (floor(2, 6.4e6) = 2.8e-9 m) over >= 290 m: 1e-11 rad; 1e-9 is
    # 100x that
    assert np.max(np.abs(elevation - gp)) < 1e-9
    assert np.max(np.abs(tr.gs_dev_m)) < 5e-3  # the second-order drop's error (glidepath module docstring)
    np.testing.assert_allclose(tr.gs_dev_m, cone.deviation_rwy_m(tr.r_rwy), rtol=0, atol=1e-12)
    assert np.max(np.abs(tr.loc_dev_m)) < 1e-3  # the centreline's vertical plane at the GPI vs the threshold's
    # the end: on the centreline at the threshold, the cone's height (TCH + the 6.6 mm drop under the GPI's plane)
    assert tr.r_rwy[-1, :2] == pytest.approx([0.0, 0.0], abs=1e-3)
    assert tr.r_rwy[-1, 2] == pytest.approx(float(cone.height_m(0.0)), abs=5e-3)
    assert tr.r_rwy[0, 0] == pytest.approx(-18520.0, abs=7.0)  # the duration rounded to the 0.1 s grid (7 m)
    # 27 m above the path parallel to the ellipsoid it flew before, at 10 nmi (x^2 / 2R)
    assert tr.r_rwy[0, 2] - (15.24 - tr.r_rwy[0, 0] * math.tan(gp)) == pytest.approx(27.5, abs=1.0)
    # constant ECEF velocity: the specific force differs from -g only by the Coriolis term 2 W x v (< 0.02 m/s^2)
    g = np.linalg.norm(geo.gravity_ned(tr.lat_rad, tr.h_m), axis=-1)
    assert np.max(np.abs(np.linalg.norm(tr.f_body, axis=1) - g)) < 0.02
    # and it is there (2 * 7.29e-5 * 70 = 0.01 m/s^2)
    f_ned = np.einsum("nij,nj->ni", synthetic.euler_to_c_nb(tr.euler_rad), tr.f_body)
    assert np.max(np.abs(f_ned[:, :2])) > 5e-3
