"""Scalar WGS-84 geodesy and the simulated world's gravity for compiled kernels (numba, cache=True).

The same equations, in the same order, as approachsim.geo (radii, geodetic_to_ecef, ecef_to_geodetic's latitude and
longitude, c_ecef_to_ned, gravity_ned): the numpy functions there are the oracle (tests/unit/nav/test_nav_kernels.py,
tests/unit/sensors/test_gnss_kernels.py). The constants are read from approachsim.geo when this module is imported,
so there is one source for each of them.
"""

from __future__ import annotations

import math

import numpy as np

from approachsim import geo
from approachsim.core.jit import njit

A = geo.A_WGS84
B = geo.B_WGS84
E2 = geo.E2_WGS84
EP2 = E2 / (1.0 - E2)
OMEGA_E = geo.OMEGA_E
_GM = geo.GM_JSBSIM
_J2A2 = 1.5 * geo.J2_JSBSIM * geo.A_JSBSIM**2
_OMEGA_J2 = geo.OMEGA_JSBSIM**2


@njit(cache=True)
def radii(lat: float) -> tuple[float, float]:
    """Meridian radius R_N and prime-vertical radius R_E (m) at geodetic latitude lat (rad):
    R_E = a / w, R_N = a (1 - e^2) / w^3, w = sqrt(1 - e^2 sin^2 L)."""
    s = math.sin(lat)
    w = math.sqrt(1.0 - E2 * (s * s))
    return A * (1.0 - E2) / w**3, A / w


@njit(cache=True)
def geodetic_to_ecef(lat: float, lon: float, h: float) -> tuple[float, float, float]:
    """ECEF position (m) of geodetic latitude, longitude (rad) and ellipsoid height h (m):
    ((R_E + h) cos L cos l, (R_E + h) cos L sin l, (R_E (1 - e^2) + h) sin L)."""
    _, r_e = radii(lat)
    cl = math.cos(lat)
    return ((r_e + h) * cl * math.cos(lon), (r_e + h) * cl * math.sin(lon), (r_e * (1.0 - E2) + h) * math.sin(lat))


@njit(cache=True)
def gravity_nd(lat: float, h: float) -> tuple[float, float]:
    """North and down components (m/s^2) of geo.gravity_ned: JSBSim's J2 gravitation plus the centrifugal
    term W^2 p, resolved on the geodetic NED axes (the east component is zero)."""
    sl, cl = math.sin(lat), math.cos(lat)
    _, r_e = radii(lat)
    p = (r_e + h) * cl
    z = (r_e * (1.0 - E2) + h) * sl
    r2 = p * p + z * z
    r = math.sqrt(r2)
    s2 = z * z / r2
    pre = _J2A2 / r2
    k = -_GM / (r2 * r)
    gp = k * (1.0 + pre * (1.0 - 5.0 * s2)) * p + _OMEGA_J2 * p
    gz = k * (1.0 + pre * (3.0 - 5.0 * s2)) * z
    return -sl * gp + cl * gz, -cl * gp - sl * gz


@njit(cache=True)
def geodetic_lat_lon(x: float, y: float, z: float) -> tuple[float, float]:
    """Geodetic latitude and longitude (rad) of the ECEF point (x, y, z), m: geo.ecef_to_geodetic's Bowring start
    and two refinements lat = atan2(z, p (1 - e^2 R_E / (R_E + h))), in the same order."""
    lon = math.atan2(y, x)
    p = math.hypot(x, y)
    theta = math.atan2(z * A, p * B)
    lat = math.atan2(z + EP2 * B * math.pow(math.sin(theta), 3.0), p - E2 * A * math.pow(math.cos(theta), 3.0))
    for _ in range(2):
        s = math.sin(lat)
        r_e = A / math.sqrt(1.0 - E2 * (s * s))
        c = abs(math.cos(lat))
        h = p / max(c, 1e-300) - r_e if c > 1e-9 else abs(z) - B
        lat = math.atan2(z, p * (1.0 - E2 * r_e / (r_e + h)))
    return lat, lon


@njit(cache=True)
def ned_axes(lat: float, lon: float) -> tuple[tuple[float, float, float], ...]:
    """The rows of the rotation ECEF -> local NED at (lat, lon), rad (geo.c_ecef_to_ned): the north, east and down
    unit vectors in ECEF, (-sin L cos l, -sin L sin l, cos L), (-sin l, cos l, 0), (-cos L cos l, -cos L sin l,
    -sin L)."""
    sl, cl = math.sin(lat), math.cos(lat)
    so, co = math.sin(lon), math.cos(lon)
    return (-sl * co, -sl * so, cl), (-so, co, 0.0), (-cl * co, -cl * so, -sl)


@njit(cache=True)
def c_ecef_to_ned(lat: float, lon: float, c: np.ndarray) -> None:
    """The rotation ECEF -> local NED at (lat, lon), rad, into c (3, 3) (geo.c_ecef_to_ned; rows: ned_axes)."""
    n, e, d = ned_axes(lat, lon)
    for j in range(3):
        c[0, j], c[1, j], c[2, j] = n[j], e[j], d[j]
