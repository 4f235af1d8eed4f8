"""WGS-84 geodesy and the runway frame: round trips, outside values, invariants."""

from __future__ import annotations

import math

import numpy as np
import pytest
from floors import assert_within, floor
from hypothesis import given, settings
from hypothesis import strategies as st

from approachsim import geo
from approachsim.core import geodesy as gk

lat_s = st.floats(-89.9, 89.9).map(math.radians)
lon_s = st.floats(-180.0, 180.0).map(math.radians)
h_s = st.floats(-500.0, 20000.0)


@settings(derandomize=True, max_examples=200, deadline=None)
@given(lat_s, lon_s, h_s)
def test_geodetic_ecef_round_trip(lat, lon, h):
    lat2, lon2, h2 = geo.ecef_to_geodetic(geo.geodetic_to_ecef(lat, lon, h))
    # the floor of a round trip through ECEF is a few eps * R_EARTH_M = 1.4e-9 m per rounding (measured <= 3.2e-9 m
    # in h, <= 1 ulp in lat over -500..20000 m, 0..89.9 deg); the bounds are the method's stated accuracy instead:
    assert abs(lat2 - lat) < 1e-11  # rad: 0.06 mm, 4.5e4x the angle floor eps * R_EARTH_M / R_EARTH_M ~ eps
    assert abs(math.remainder(lon2 - lon, 2 * math.pi)) < 1e-11  # as lat
    assert abs(h2 - h) < 1e-6  # m: 350x floor(2, R_EARTH_M) = 2.8e-9 m (two roundings of a 6.4e6 m operand)


def test_ecef_outside_values():
    # equator / prime meridian: (a, 0, 0); pole: (0, 0, b)
    # x = (R_E + h) cos(lat) cos(lon): ~4 roundings of a 6.4e6 m operand, floor(4, a) = 5.7e-9 m (1e-9 was 1 ulp)
    assert_within(geo.geodetic_to_ecef(0.0, 0.0, 0.0), [geo.A_WGS84, 0, 0], floor(4, geo.A_WGS84), "equator")
    # the pole: z = R_E (1 - e^2) against b (a different formula of b, ~6 roundings: 8e-9 m); 1e-6 m is 120x that
    np.testing.assert_allclose(geo.geodetic_to_ecef(math.pi / 2, 0.0, 0.0), [0, 0, geo.B_WGS84], atol=1e-6)
    # NIMA TR8350.2 table 3.1 gives b to 1e-6 m: the table's last digit, not a rounding floor (eps * b = 1.4e-9 m)
    assert geo.B_WGS84 == pytest.approx(6356752.314245, abs=1e-6)


def test_radii_outside_values():
    r_n, r_e = geo.radii(0.0)
    # reference values to their printed 1e-3 m; approx's default rel 1e-6 is 4.5e9 eps: both far above the
    # radii's ~5-rounding floor 5 eps R = 7e-9 m
    assert r_e == pytest.approx(geo.A_WGS84)
    assert r_n == pytest.approx(6335439.327, abs=1e-3)  # a (1 - e^2)
    r_n, r_e = geo.radii(math.pi / 2)
    assert r_n == pytest.approx(r_e) and r_e == pytest.approx(6399593.626, abs=1e-3)  # a^2 / b


def test_normal_gravity_outside_values():
    # NIMA TR8350.2: equator 9.7803253359, pole 9.8321849378 m/s^2; free-air gradient about -3.086e-6 /s^2 per m
    # (the tables' last digits, 1e-10 / 1e-9 m/s^2, set the bounds: the formula's floor ~10 eps g = 2e-14 m/s^2; the
    # gradient is a difference of two 9.8 m/s^2 values over 1000 m, floor 4 eps 9.8 / 1000 = 9e-18, rel 0.01 is physics)
    assert geo.normal_gravity(0.0, 0.0) == pytest.approx(9.7803253359, abs=1e-9)
    assert geo.normal_gravity(math.pi / 2, 0.0) == pytest.approx(9.8321849378, abs=1e-8)
    grad = (geo.normal_gravity(0.7, 1000.0) - geo.normal_gravity(0.7, 0.0)) / 1000.0
    assert grad == pytest.approx(-3.086e-6, rel=0.01)


@settings(derandomize=True, max_examples=100, deadline=None)
@given(lat_s, lon_s)
def test_ecef_to_ned_is_a_rotation_with_down_along_the_normal(lat, lon):
    c = geo.c_ecef_to_ned(lat, lon)
    # entries of size 1, each 1-2 roundings (sin, cos, a product), c c' sums 3 products: floor(10, 1) = 2.2e-15;
    # 1e-12 is 450x that
    np.testing.assert_allclose(c @ c.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(c) == pytest.approx(1.0)  # rel 1e-6: far above the floor 20 eps of a 3x3 determinant
    # down is minus the ellipsoid normal: moving 1 m "up" in height moves -1 m in NED down
    r1, r0 = geo.geodetic_to_ecef(lat, lon, 101.0), geo.geodetic_to_ecef(lat, lon, 100.0)
    # a difference of two ECEF positions: each component 3 roundings ((R_E + h) cos lat cos lon) of |r| ~ 6.4e6 m
    # (R_E's own error is common to both and cancels): floor(3, |r1|, |r0|) = 8.5e-9 m (the 1e-8 it had was ~1x)
    assert_within(c @ (r1 - r0), [0.0, 0.0, -1.0], floor(3, np.linalg.norm(r1), np.linalg.norm(r0)), "up")


def test_runway_frame_axes_and_round_trip():
    rf = geo.RunwayFrame(math.radians(37.6), math.radians(-122.4), 4.0, math.radians(90.0))
    # runway pointing east: 1 km along x is 1 km east of the threshold
    # to_ecef adds a local offset to the 6.4e6 m origin (one rounding of an ECEF component, 0.5 ulp = 4.7e-10 m),
    # from_ecef / the check subtract it again (exact: Sterbenz) and rotate: floor(2, |p|, |origin|) = 5.7e-9 m for
    # each (the 1e-9 m it had was one ulp of 6.4e6 m)
    o = rf.origin_ecef
    p = rf.to_ecef([1000.0, 0.0, 0.0])
    ned = geo.c_ecef_to_ned(rf.threshold_lat_rad, rf.threshold_lon_rad) @ (p - o)
    assert_within(ned, [0.0, 1000.0, 0.0], floor(2, np.linalg.norm(p), np.linalg.norm(o)), "1 km along")
    # y is to the right of the landing direction (south for an east-pointing runway), z up
    p_y = rf.to_ecef([0, 1.0, 0])
    ned_y = geo.c_ecef_to_ned(rf.threshold_lat_rad, rf.threshold_lon_rad) @ (p_y - o)
    assert_within(ned_y, [-1.0, 0.0, 0.0], floor(2, np.linalg.norm(p_y), np.linalg.norm(o)), "1 m right")
    pts = np.array([[-18520.0, 30.0, 1000.0], [5.0, -3.0, 0.5]])
    r = rf.to_ecef(pts)
    assert_within(rf.from_ecef(r), pts, floor(2, np.linalg.norm(r, axis=-1), np.linalg.norm(o))[:, None], "round trip")


def test_tangent_plane_height_drop():
    """The tangent-plane z of a point at ellipsoid height equal to the threshold's falls as d^2 / (2 R)."""
    rf = geo.RunwayFrame(math.radians(45.0), 0.0, 0.0, 0.0)
    lat, lon, _ = geo.ecef_to_geodetic(rf.to_ecef([-18520.0, 0.0, 0.0]))
    z = rf.from_ecef(geo.geodetic_to_ecef(lat, lon, 0.0))[2]
    r_n, _ = geo.radii(math.radians(45.0))
    assert z == pytest.approx(-(18520.0**2) / (2 * r_n), rel=0.01)  # the d^4 / R^3 terms; the floor 2e-9 m is 1e-8 of z


def test_jsbsim_gravity_closed_forms_at_equator_and_pole():
    """J2 gravitation + centrifugal (JSBSim's FGInertial) from its closed forms on the axes."""
    gm, j2, a, w = geo.GM_JSBSIM, geo.J2_JSBSIM, geo.A_JSBSIM, geo.OMEGA_JSBSIM
    # gravity_ned takes ~20 roundings from (lat, h) to g (radii, p, z, r^2, r, the J2 factor, the rotation), each
    # relative to |g| ~ 9.8 m/s^2, against a closed form in ~8: floor(30, 9.8) = 6.5e-14 m/s^2 (1e-12 is 15x that)
    g_eq = geo.gravity_ned(0.0, 0.0)
    np.testing.assert_allclose(g_eq, [0.0, 0.0, gm / a**2 * (1.0 + 1.5 * j2) - w**2 * a], atol=1e-12)
    b = geo.B_WGS84
    g_pole = geo.gravity_ned(math.pi / 2, 0.0)
    assert g_pole[2] == pytest.approx(gm / b**2 * (1.0 - 3.0 * j2 * (a / b) ** 2), abs=1e-12)  # as at the equator
    assert abs(g_pole[0]) < 1e-12  # cos(pi / 2) = 6e-17 rounds g's 9.8 m/s^2 into north: 6e-16 m/s^2
    # JSBSim's constants are WGS-84's, converted from feet: data tolerances (JSBSim prints GM to 12 digits, measured
    # 3.6e-13 apart; a to 1e-5 ft, measured 2.1e-7 m apart), not rounding floors (the conversions' floor: 3 eps)
    assert geo.GM_JSBSIM == pytest.approx(geo.GM_WGS84, rel=1e-12)
    assert geo.A_JSBSIM == pytest.approx(geo.A_WGS84, abs=1e-6)


def test_j2_gravitation_is_the_gradient_of_the_j2_potential():
    """g = -grad U, U = -GM/r (1 - J2 (a/r)^2 P2(z/r)) (central differences, 1 m steps)."""
    gm, j2, a = geo.GM_JSBSIM, geo.J2_JSBSIM, geo.A_JSBSIM

    def u(r):
        rr = np.linalg.norm(r)
        s = r[2] / rr
        return -gm / rr * (1.0 - j2 * (a / rr) ** 2 * 0.5 * (3.0 * s * s - 1.0))

    for lat, lon, h in ((0.3, 1.0, 100.0), (0.66, -2.1, 1000.0), (-1.2, 0.2, 9000.0)):
        r = geo.geodetic_to_ecef(lat, lon, h)
        up = np.array([u(r + e) for e in np.eye(3)])
        dn = np.array([u(r - e) for e in np.eye(3)])
        grad = (up - dn) / 2.0
        g = geo.gravitation_j2_ecef(r)
        # a difference of two potentials of 6.2e7 m^2/s^2 each ~4 roundings (the norm, the division, the J2
        # factor), over 2 m: floor(4, u+, u-) / 2 = 5.5e-8 m/s^2, plus r +- 1 m rounded to 0.5 ulp of 6.4e6 m
        # (4.7e-10 m of the 2 m step: |g| eps |r| / 2); the truncation error h^2 u''' / 6 ~ 1e-12 m/s^2 is below both
        assert_within(g, -grad, floor(4, up, dn) / 2.0 + np.linalg.norm(g) * floor(1, r) / 2.0, f"grad at {lat}")


@settings(derandomize=True, max_examples=100, deadline=None)
@given(lat_s, lon_s, h_s)
def test_gravity_ned_is_ecef_gravitation_plus_centrifugal_on_ned_axes(lat, lon, h):
    r = geo.geodetic_to_ecef(lat, lon, h)
    w = geo.OMEGA_JSBSIM
    g_ecef = geo.gravitation_j2_ecef(r) + w**2 * np.array([r[0], r[1], 0.0])
    g = geo.gravity_ned(lat, h)
    # two formulas of g, each ~20 roundings relative to |g| (on ECEF axes: the ECEF position's 1 ulp moves g by
    # 2 eps |g|), the rotation summing three terms of |g|: floor(30, |g|) = 6.5e-14 m/s^2; 1e-12 is 15x that
    np.testing.assert_allclose(g, geo.c_ecef_to_ned(lat, lon) @ g_ecef, atol=1e-12)
    assert g[1] == 0.0  # exact: gravity_ned writes the east component as the constant 0.0
    # the kernels' twin: the same formula compiled (FMA or not, libm sin/cos/sqrt vs numpy's): ~20 roundings each,
    # north = -sin(lat) g_p + cos(lat) g_z sums two terms of |g|: floor(20, |g|, |g|) = 8.7e-14 m/s^2
    gn = float(np.linalg.norm(g))
    assert_within(gk.gravity_nd(lat, h), g[[0, 2]], floor(20, gn, gn), "kernel twin")


def test_jsbsim_gravity_against_somigliana_normal_gravity():
    """The J2-only field against the full normal field (Somigliana), latitudes 0..90 deg, 0 and 3000 m.

    Measured: down components differ by -1.18e-4 (pole) .. +5.0e-5 m/s^2 (mid-latitudes; +4.9e-5 at the
    default runway's 37.6 deg), and the J2 field leans off the ellipsoid normal by up to 6.2e-5 m/s^2 north
    at sea level (Somigliana's is along the normal there): the neglected J4.. terms, GM/a^2 |J4| ~ 2.3e-5
    times factors up to 5. A mismatch of this size is what drifted the INS 0.7 m on JSBSim truth.
    """
    lat = np.radians(np.linspace(0.0, 90.0, 91))
    for h in (0.0, 3000.0):
        g = geo.gravity_ned(lat, h)
        d = g[:, 2] - geo.normal_gravity(lat, h)  # a model difference of 1e-4; its floor 4 eps 9.8 = 9e-15 m/s^2
        assert -1.3e-4 < d.min() < -1.0e-4 and 4.0e-5 < d.max() < 6.0e-5
        assert 5e-5 < np.abs(g[:, 0]).max() < 1e-4
    g0 = geo.gravity_ned(lat, 0.0)
    assert np.abs(g0[:, 0]).max() == pytest.approx(6.2e-5, abs=0.2e-5)
    # the free-air gradient is the same physics in both: -3.086e-6 /s^2 (0.1 % apart; the rounding floor of either
    # gradient, 4 eps 9.8 / 1000 m = 9e-18 /s^2, is 3e-12 of it)
    grad = (geo.gravity_ned(0.7, 1000.0)[2] - geo.gravity_ned(0.7, 0.0)[2]) / 1000.0
    assert grad == pytest.approx((geo.normal_gravity(0.7, 1000.0) - geo.normal_gravity(0.7, 0.0)) / 1000.0, rel=1e-3)
