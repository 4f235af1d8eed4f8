"""Synthetic truth / navigation pairs with known errors, for scoring tests.

The true IMU point flies a straight 3-degree descent along the extended centreline at a constant rate
(height above the threshold exactly linear in time); the navigation solution is the truth plus a given
NED error, and a given constant covariance.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from approachsim.geo import RunwayFrame, c_ecef_to_ned, ecef_to_geodetic, geodetic_to_ecef
from approachsim.records import NavSolution, Truth

RWY = RunwayFrame(math.radians(37.6117), math.radians(-122.3581), 4.0, math.radians(298.0))
GP = math.radians(3.0)


def make_truth(
    *, hz: float = 10.0, hat0_m: float = 700.0, sink_mps: float = 3.5, dur_s: float | None = None, loc_dev_m=0.0
) -> Truth:
    """Straight descent: height above threshold hat0 - sink t (exactly linear), on the centreline."""
    if dur_s is None:
        dur_s = (hat0_m - 2.0) / sink_mps
    t = np.arange(0.0, dur_s, 1.0 / hz)
    hat = hat0_m - sink_mps * t
    along = -(hat - 15.0) / math.tan(GP)
    cross = np.zeros_like(t) + loc_dev_m
    r_plane = RWY.to_ecef(np.stack([along, cross, np.zeros_like(t)], axis=-1))
    lat, lon, _ = ecef_to_geodetic(r_plane)
    h = RWY.threshold_h_m + hat
    r = geodetic_to_ecef(lat, lon, h)
    n = t.size
    z1, z3 = np.zeros(n), np.zeros((n, 3))
    q = np.zeros((n, 4))
    q[:, 0] = 1.0
    return Truth(
        t_s=t, lat_rad=lat, lon_rad=lon, h_m=h, r_ecef=r, v_ned=z3, q_nb=q, euler_rad=z3, w_ib_body=z3,
        f_body=z3, p_static_pa=z1 + 101325.0, t_air_k=z1 + 288.15, h_agl_m=hat, r_rwy=RWY.from_ecef(r),
        gs_dev_m=z1, loc_dev_m=cross, controls=np.zeros((n, 4)), airspeed_mps=z1 + 70.0, runway=RWY,
    )


def make_nav(
    truth: Truth, e_ned: Callable[[np.ndarray], np.ndarray] | np.ndarray, sigma_ned_m=(1.0, 1.0, 1.0)
) -> NavSolution:
    """truth + error; e_ned is an (n, 3) array or a function of time giving one, NED metres."""
    e = e_ned(truth.t_s) if callable(e_ned) else np.broadcast_to(np.asarray(e_ned, float), (len(truth), 3))
    c = c_ecef_to_ned(truth.lat_rad, truth.lon_rad)  # ecef -> ned; transpose takes ned -> ecef
    r = truth.r_ecef + np.einsum("nji,nj->ni", c, e)
    n = len(truth)
    p = np.zeros((n, 3, 3))
    p[:, [0, 1, 2], [0, 1, 2]] = np.asarray(sigma_ned_m, float) ** 2
    return NavSolution(
        t_s=truth.t_s.copy(), r_ecef=r, v_ned=np.zeros((n, 3)), euler_rad=np.zeros((n, 3)), P_pos_ned=p,
        clock_bias_m=np.zeros(n), clock_bias_sigma_m=np.ones(n),
    )


def cross_axis_ned() -> np.ndarray:
    """Unit vector of the runway's cross-track (right) axis in NED."""
    return np.array([-math.sin(RWY.heading_rad), math.cos(RWY.heading_rad), 0.0])


def along_axis_ned() -> np.ndarray:
    """Unit vector of the runway's along-track (landing direction) axis in NED."""
    return np.array([math.cos(RWY.heading_rad), math.sin(RWY.heading_rad), 0.0])
