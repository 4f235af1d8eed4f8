"""Truth consistency: what an IMU at the truth point senses reproduces what the aircraft did.

60 s of flight in light turbulence (default profile). Integrating the recorded specific force with the truth's
own gravity (geo.gravity_ned: JSBSim's J2 gravitation minus centrifugal, the one gravity of the simulated world),
Coriolis and transport rate (local-level NED mechanization, Titterton & Weston eq. 3.70) must reproduce the
recorded NED velocity: down within 1 mm/s (measured 0.38 mm/s), north / east within 10 mm/s (measured 4.5 mm/s,
the Euler step on turbulent attitude). The down tolerance sees the ~1e-5 m/s^2 difference of normal_gravity
(Somigliana) from the truth's gravity: integrated with normal_gravity the down error is 2.7 mm/s (measured).
Integrating the recorded inertial body rates (corrected for Earth rate and transport rate, eq. 3.57) must
reproduce the recorded attitude within 0.01 deg. Row k's specific force and rate carry the state from row k to
row k+1 (see flight/fdm.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from approachsim import geo
from approachsim.flight.run import Approach
from approachsim.profile import load_profile

PROFILES = Path(__file__).resolve().parents[3] / "profiles"

pytestmark = pytest.mark.slow

DURATION_S = 60.0


@pytest.fixture(scope="module")
def flight():
    profile = load_profile(PROFILES / "default.toml")
    assert profile.environment.turbulence == "light"
    return Approach(profile).fly(seed=3, run=0, max_time_s=DURATION_S)


def _skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def _rot(phi):
    """Rotation matrix exp([phi x]) (Rodrigues)."""
    a = float(np.linalg.norm(phi))
    k = _skew(phi)
    if a < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + math.sin(a) / a * k + (1.0 - math.cos(a)) / a**2 * (k @ k)


def _c_nb(euler):
    phi, th, psi = euler
    cf, sf, ct, st, cp, sp = math.cos(phi), math.sin(phi), math.cos(th), math.sin(th), math.cos(psi), math.sin(psi)
    return np.array([
        [ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
        [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
        [-st, sf * ct, cf * ct],
    ])


def _rates(lat, h, v):
    """Earth rate and transport rate in NED, rad/s."""
    r_n, r_e = geo.radii(lat)
    w_ie = geo.OMEGA_E * np.array([math.cos(lat), 0.0, -math.sin(lat)])
    w_en = np.array([v[1] / (r_e + h), -v[0] / (r_n + h), -v[1] * math.tan(lat) / (r_e + h)])
    return w_ie, w_en


def test_flight_is_turbulent_and_long_enough(flight):
    t = flight.truth
    assert t.t_s[-1] >= DURATION_S - 1e-9
    # turbulence: the vertical specific force varies by well over 0.1 g
    assert np.std(t.f_body[:, 2]) > 0.2


def _integrate_velocity(t, earth_terms: bool = True, gravity=geo.gravity_ned) -> np.ndarray:
    """Max |v_integrated - v_truth| (m/s) per NED axis over the record, mechanization from row 0; gravity(lat, h)
    gives the NED gravity vector."""
    dt = float(t.t_s[1] - t.t_s[0])
    v = t.v_ned[0].copy()
    err = np.zeros(3)
    for k in range(len(t) - 1):
        lat, h = float(t.lat_rad[k]), float(t.h_m[k])
        w_ie, w_en = _rates(lat, h, v)
        g_n = gravity(lat, h)
        # v' = C_nb f + g - (2 w_ie + w_en) x v
        a = _c_nb(t.euler_rad[k]) @ t.f_body[k] + g_n
        if earth_terms:
            a = a - np.cross(2.0 * w_ie + w_en, v)
        v = v + dt * a
        err = np.maximum(err, np.abs(v - t.v_ned[k + 1]))
    return err


def _normal_gravity_ned(lat: float, h: float) -> np.ndarray:
    return np.array([0.0, 0.0, float(geo.normal_gravity(lat, h))])


def test_specific_force_integrates_to_velocity(flight):
    err = _integrate_velocity(flight.truth)
    assert err[2] <= 1e-3, f"down velocity from specific force differs from the truth by {err[2]:.5f} m/s"
    assert np.all(err[:2] <= 0.01), f"north/east velocity from specific force differs by {err[:2]} m/s"
    # the check has teeth: another gravity model (normal gravity, 2.7 mm/s measured) or no Coriolis and
    # transport-rate terms (0.4 m/s measured) fail it
    assert _integrate_velocity(flight.truth, gravity=_normal_gravity_ned)[2] > 2e-3
    assert np.max(_integrate_velocity(flight.truth, earth_terms=False)) > 0.1


def test_body_rates_integrate_to_attitude(flight):
    t = flight.truth
    dt = float(t.t_s[1] - t.t_s[0])
    c = _c_nb(t.euler_rad[0])
    worst = 0.0
    for k in range(len(t) - 1):
        w_ie, w_en = _rates(float(t.lat_rad[k]), float(t.h_m[k]), t.v_ned[k])
        c = _rot(-(w_ie + w_en) * dt) @ c @ _rot(t.w_ib_body[k] * dt)
        d = c.T @ _c_nb(t.euler_rad[k + 1])
        ang = math.degrees(math.acos(min(1.0, max(-1.0, (np.trace(d) - 1.0) / 2.0))))
        worst = max(worst, ang)
    print(f"attitude from body rates: worst {worst:.6f} deg over {t.t_s[-1]:.0f} s")
    assert worst <= 0.01, f"attitude from body rates differs from the truth by {worst:.5f} deg"


def test_quaternion_matches_euler_and_ecef_matches_geodetic(flight):
    t = flight.truth
    q = t.q_nb
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    w, x, y, z = q.T
    c20 = 2.0 * (x * z - w * y)
    np.testing.assert_allclose(-np.arcsin(c20), t.euler_rad[:, 1], atol=1e-9)
    np.testing.assert_allclose(geo.geodetic_to_ecef(t.lat_rad, t.lon_rad, t.h_m), t.r_ecef, atol=1e-6)
    np.testing.assert_allclose(t.runway.from_ecef(t.r_ecef)[:, :2], t.r_rwy[:, :2], atol=1e-6)
