"""WGS-84 geodesy and the runway frame, as plain vectorized numpy functions.

Angles in radians, lengths in metres, heights above the WGS-84 ellipsoid. Arrays broadcast over any
leading axes; vectors are on the last axis. Frames: ECEF, local NED at a reference point, and the runway
frame (origin at the threshold, x along the landing direction, y to the right, z up).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

A_WGS84 = 6378137.0
"""WGS-84 semi-major axis, m."""
F_WGS84 = 1.0 / 298.257223563
"""WGS-84 flattening."""
B_WGS84 = A_WGS84 * (1.0 - F_WGS84)
"""WGS-84 semi-minor axis, m."""
E2_WGS84 = F_WGS84 * (2.0 - F_WGS84)
"""WGS-84 first eccentricity squared."""
OMEGA_E = 7.2921151467e-5
"""Earth rotation rate, rad/s (IS-GPS-200 value)."""
GM_WGS84 = 3.986004418e14
"""WGS-84 Earth gravitational constant, m^3/s^2."""

# Somigliana normal-gravity constants (WGS-84)
_GAMMA_E = 9.7803253359
_K_SOMIGLIANA = 0.00193185265241
_M_WGS84 = OMEGA_E**2 * A_WGS84**2 * B_WGS84 / GM_WGS84

Array = NDArray[np.float64]


def radii(lat_rad: ArrayLike) -> tuple[Array, Array]:
    """Meridian radius R_N (north-south) and prime-vertical radius R_E (east-west), m."""
    s2 = np.sin(lat_rad) ** 2
    w = np.sqrt(1.0 - E2_WGS84 * s2)
    r_e = A_WGS84 / w
    r_n = A_WGS84 * (1.0 - E2_WGS84) / w**3
    return r_n, r_e


def geodetic_to_ecef(lat_rad: ArrayLike, lon_rad: ArrayLike, h_m: ArrayLike) -> Array:
    """Geodetic latitude, longitude (rad) and ellipsoid height (m) to ECEF position (..., 3), m."""
    lat = np.asarray(lat_rad, dtype=float)
    lon = np.asarray(lon_rad, dtype=float)
    h = np.asarray(h_m, dtype=float)
    _, r_e = radii(lat)
    cl = np.cos(lat)
    x = (r_e + h) * cl * np.cos(lon)
    y = (r_e + h) * cl * np.sin(lon)
    z = (r_e * (1.0 - E2_WGS84) + h) * np.sin(lat)
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


def ecef_to_geodetic(r_ecef: ArrayLike) -> tuple[Array, Array, Array]:
    """ECEF position (..., 3), m, to geodetic latitude, longitude (rad) and ellipsoid height (m).

    Closed-form start (Bowring) and two Newton-like refinements: better than 1e-9 m near the Earth's surface.
    """
    r = np.asarray(r_ecef, dtype=float)
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    lon = np.arctan2(y, x)
    p = np.hypot(x, y)
    ep2 = E2_WGS84 / (1.0 - E2_WGS84)
    theta = np.arctan2(z * A_WGS84, p * B_WGS84)
    lat = np.arctan2(z + ep2 * B_WGS84 * np.sin(theta) ** 3, p - E2_WGS84 * A_WGS84 * np.cos(theta) ** 3)
    for _ in range(2):
        _, r_e = radii(lat)
        h = np.where(
            np.abs(np.cos(lat)) > 1e-9,
            p / np.maximum(np.abs(np.cos(lat)), 1e-300) - r_e,
            np.abs(z) - B_WGS84,
        )
        lat = np.arctan2(z, p * (1.0 - E2_WGS84 * r_e / (r_e + h)))
    _, r_e = radii(lat)
    h = np.where(
        np.abs(np.cos(lat)) > 1e-9,
        p / np.maximum(np.abs(np.cos(lat)), 1e-300) - r_e,
        np.abs(z) - B_WGS84,
    )
    return lat, lon, h


def c_ecef_to_ned(lat_rad: ArrayLike, lon_rad: ArrayLike) -> Array:
    """Rotation matrix (..., 3, 3) taking ECEF vectors to local NED: v_ned = C @ v_ecef."""
    lat = np.asarray(lat_rad, dtype=float)
    lon = np.asarray(lon_rad, dtype=float)
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    c = np.empty(np.broadcast(lat, lon).shape + (3, 3))
    c[..., 0, 0] = -sl * co
    c[..., 0, 1] = -sl * so
    c[..., 0, 2] = cl
    c[..., 1, 0] = -so
    c[..., 1, 1] = co
    c[..., 1, 2] = 0.0
    c[..., 2, 0] = -cl * co
    c[..., 2, 1] = -cl * so
    c[..., 2, 2] = -sl
    return c


def normal_gravity(lat_rad: ArrayLike, h_m: ArrayLike) -> Array:
    """WGS-84 normal gravity magnitude (m/s^2) at geodetic latitude and ellipsoid height.

    Somigliana's formula on the ellipsoid with the second-order free-air height correction
    (NIMA TR8350.2 eq. 4-1 and 4-3). Gravity plus centrifugal: what a plumb bob feels.
    """
    s2 = np.sin(lat_rad) ** 2
    g0 = _GAMMA_E * (1.0 + _K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2_WGS84 * s2)
    h = np.asarray(h_m, dtype=float)
    return g0 * (
        1.0 - 2.0 / A_WGS84 * (1.0 + F_WGS84 + _M_WGS84 - 2.0 * F_WGS84 * s2) * h + 3.0 / A_WGS84**2 * h**2
    )


# JSBSim's Earth (src/models/FGInertial.cpp, FGInertial::FGInertial, JSBSim 1.3.x), converted from feet
_FT = 0.3048
GM_JSBSIM = 14.0764417572e15 * _FT**3
"""JSBSim's Earth gravitational constant (14.0764417572e15 ft^3/s^2), m^3/s^2."""
J2_JSBSIM = 1.08262982e-3
"""JSBSim's Earth J2 (dimensionless)."""
A_JSBSIM = 20925646.32546 * _FT
"""JSBSim's Earth semi-major axis (20925646.32546 ft), m: the WGS-84 value."""
OMEGA_JSBSIM = 7.292115e-5
"""JSBSim's Earth rotation rate, rad/s (0.00007292115; differs from OMEGA_E by 1.5e-14 rad/s)."""


def gravitation_j2_ecef(r_ecef: ArrayLike) -> Array:
    """J2 gravitation (mass attraction only, no centrifugal term) at ECEF positions (..., 3), m/s^2, ECEF axes.

    JSBSim's WGS-84 gravity model (simulation/gravity-model = 1, FGInertial::GetGravityJ2, Stevens & Lewis
    eq. 1.4-16) with its constants GM_JSBSIM, J2_JSBSIM, A_JSBSIM; sin(lat) there is the *geocentric*
    latitude's, z / r:
        g_xy = -GM/r^2 (1 + 3/2 J2 (a/r)^2 (1 - 5 s^2)) (x, y)/r,
        g_z  = -GM/r^2 (1 + 3/2 J2 (a/r)^2 (3 - 5 s^2)) z/r,   s = z / r.
    JSBSim integrates the inertial velocity with exactly this plus the body forces / mass (FGAccelerations).
    """
    r_vec = np.asarray(r_ecef, dtype=float)
    r2 = np.einsum("...i,...i->...", r_vec, r_vec)
    r = np.sqrt(r2)
    s2 = r_vec[..., 2] ** 2 / r2
    pre = 1.5 * J2_JSBSIM * A_JSBSIM**2 / r2
    k = -GM_JSBSIM / (r2 * r)
    out = np.empty(r_vec.shape)
    kxy = k * (1.0 + pre * (1.0 - 5.0 * s2))
    out[..., 0] = kxy * r_vec[..., 0]
    out[..., 1] = kxy * r_vec[..., 1]
    out[..., 2] = k * (1.0 + pre * (3.0 - 5.0 * s2)) * r_vec[..., 2]
    return out


def gravity_ned(lat_rad: ArrayLike, h_m: ArrayLike) -> Array:
    """Gravity (J2 gravitation + centrifugal) as a full NED vector (..., 3), m/s^2, at geodetic lat and height.

    The plumb-bob gravity of JSBSim's Earth (gravitation_j2_ecef minus W x (W x r), W = OMEGA_JSBSIM: the
    centrifugal term JSBSim's FGAccelerations::CalculateUVWdot subtracts), resolved on the local geodetic NED
    axes. It is not exactly along the ellipsoid normal: the J2-only field's level surfaces are not the WGS-84
    ellipsoid, so it has a north component of a few 1e-5 m/s^2. This is the one gravity model of the
    simulated world (JSBSim) and of the navigation computer (nav/ins.py, synthetic.py). It differs from
    normal_gravity (Somigliana, the full normal field) by ~1e-5 m/s^2 (the neglected J4... terms; tests/unit/
    test_geo.py states the measured difference). Gravity is axisymmetric: longitude does not enter.
    """
    lat = np.asarray(lat_rad, dtype=float)
    h = np.asarray(h_m, dtype=float)
    sl, cl = np.sin(lat), np.cos(lat)
    _, r_e = radii(lat)
    p = (r_e + h) * cl  # distance from the spin axis (meridian plane at longitude 0)
    z = (r_e * (1.0 - E2_WGS84) + h) * sl
    r2 = p * p + z * z
    r = np.sqrt(r2)
    s2 = z * z / r2
    pre = 1.5 * J2_JSBSIM * A_JSBSIM**2 / r2
    k = -GM_JSBSIM / (r2 * r)
    gp = k * (1.0 + pre * (1.0 - 5.0 * s2)) * p + OMEGA_JSBSIM**2 * p
    gz = k * (1.0 + pre * (3.0 - 5.0 * s2)) * z
    out = np.empty(np.broadcast(lat, h).shape + (3,))
    out[..., 0] = -sl * gp + cl * gz
    out[..., 1] = 0.0
    out[..., 2] = -cl * gp - sl * gz
    return out


@dataclass(frozen=True)
class RunwayFrame:
    """Runway frame: origin at the threshold point, x along the landing direction, y right, z up (m).

    threshold_lat_rad, threshold_lon_rad: geodetic threshold position; threshold_h_m: its ellipsoid height;
    heading_rad: true heading of the landing direction.
    """

    threshold_lat_rad: float
    threshold_lon_rad: float
    threshold_h_m: float
    heading_rad: float

    @property
    def origin_ecef(self) -> Array:
        """Threshold position in ECEF, m."""
        return geodetic_to_ecef(self.threshold_lat_rad, self.threshold_lon_rad, self.threshold_h_m)

    @property
    def c_ecef_to_rwy(self) -> Array:
        """Rotation (3, 3) from ECEF to runway axes (x along, y right, z up), at the threshold."""
        c_ned = c_ecef_to_ned(self.threshold_lat_rad, self.threshold_lon_rad)
        ch, sh = np.cos(self.heading_rad), np.sin(self.heading_rad)
        # runway axes in NED: x = (cos h, sin h, 0), y = (-sin h, cos h, 0), z = (0, 0, -1)
        c_ned_to_rwy = np.array([[ch, sh, 0.0], [-sh, ch, 0.0], [0.0, 0.0, -1.0]])
        return c_ned_to_rwy @ c_ned

    def from_ecef(self, r_ecef: ArrayLike) -> Array:
        """ECEF positions (..., 3) to runway-frame (along, cross, up) (..., 3), m.

        The frame is the tangent plane at the threshold: z is height above that plane, which differs from
        height above the threshold's ellipsoid height by d^2 / (2 R) (0.3 m at 2 km, 27 m at 18.5 km).
        Use height_above_threshold() for the height that decision heights are measured in.
        """
        d = np.asarray(r_ecef, dtype=float) - self.origin_ecef
        return d @ self.c_ecef_to_rwy.T

    def to_ecef(self, r_rwy: ArrayLike) -> Array:
        """Runway-frame (along, cross, up) positions (..., 3) to ECEF, m."""
        return np.asarray(r_rwy, dtype=float) @ self.c_ecef_to_rwy + self.origin_ecef

    def height_above_threshold(self, h_m: ArrayLike) -> Array:
        """Ellipsoid height (m) to height above the threshold elevation, m (what decision heights use)."""
        return np.asarray(h_m, dtype=float) - self.threshold_h_m
