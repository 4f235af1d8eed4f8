"""Synthetic vertical-manoeuvre truth: climbs, descents and level-offs, exactly kinematically consistent.

For the adaptive-damping test of seed 003 (Sokolovic, Dikic & Stancic, "Simulation" section, Fig. 3: "the
trajectory was chosen to show the results for the cases of high and low vertical maneuvers"). JSBSim flies
only approaches, so this is an analytic truth, NOT a flight model: no aircraft, no autopilot, no wind.

Trajectory (seed 003 prints no numbers for Fig. 3; everything below is our choice, documented):

* constant horizontal ground velocity (ground_speed_mps along track_rad), a rhumb line from (lat0, lon0);
* height h(t) = h0 + sum over vertical legs of dh (s - sin(2 pi s) / (2 pi)), s = (t - t0) / (t1 - t0)
  clipped to [0, 1]: each leg is a climb (dh > 0) or descent (dh < 0) with a smooth 1 - cos vertical
  acceleration a_up = 2 pi dh / T^2 sin(2 pi s) (zero at both ends, so every leg starts and ends level; the
  peak vertical speed is 2 dh / T); the same leg shape as approachsim/papers/sokolovic.py;
* attitude constant relative to the local NED frame (wings level, pitch_rad, heading = track): the vertical
  channel sees the manoeuvre through the specific force alone, as in seed 003 eq. 2-3 (no body-rate
  coupling; a pitching airframe would add micro-rad attitude terms that do not enter the vertical channel).

Consistency contract (as approachsim/synthetic.py, Groves 2nd ed. eq. 5.44-5.56, NED, normal gravity from
geo.normal_gravity at each point's own lat and h), and the Truth sampling convention (records.Truth: f_body[k]
and w_ib_body[k] carry the state from row k to row k+1, constant over the step):

* lat, lon are the DOP853 solution (rtol 1e-13) of lat' = vN / (R_N + h), lon' = vE / ((R_E + h) cos lat)
  with the analytic h(t); v_ned and h are analytic.
* f_body[k] is the *mean* over [t_k, t_k+1] of the instantaneous specific force
  f_ned = v' + (2 w_ie + w_en) x v - g_ned: the v' term exactly ((v_{k+1} - v_k) / dt, analytic), the slowly
  varying Coriolis and gravity terms by 3-point Gauss-Legendre quadrature; so dt f_body[k] is the velocity
  increment an ideal accelerometer integrates over the step (exact increments, sensors/imu.true_increments).
* w_ib_body[k] is the mean of C_bn (w_ie + w_en) over the step (constant attitude in NED).

The atmosphere fields use the ISA troposphere (sensors/atmosphere.py) with the given deviation and sea-level
pressure; airspeed_mps is the equivalent airspeed of the ground speed (still air); controls are zero;
heights are ellipsoid heights (MSL = ellipsoid, as profile.py says).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from approachsim import geo
from approachsim.glidepath import GlidePath
from approachsim.records import Truth
from approachsim.sensors import atmosphere
from approachsim.synthetic import (
    earth_rate_ned,
    euler_to_c_nb,
    euler_to_quaternion,
    gravity_ned,
    transport_rate_ned,
)

Array = np.ndarray

_RHO0 = atmosphere.P0_PA / (atmosphere.R_AIR * atmosphere.T0_K)
_GL_NODES = np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
_GL_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0  # weights of the mean over the interval (sum 1)


@dataclass(frozen=True)
class VerticalLeg:
    """One climb (dh_m > 0) or descent (dh_m < 0) between start_s and end_s (s), 1 - cos vertical acceleration."""

    start_s: float
    end_s: float
    dh_m: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.start_s) and np.isfinite(self.end_s) and self.end_s > self.start_s):
            raise ValueError(f"VerticalLeg: need finite start_s < end_s; got {self.start_s}, {self.end_s}")
        if not np.isfinite(self.dh_m):
            raise ValueError(f"VerticalLeg: dh_m must be finite; got {self.dh_m}")

    @property
    def peak_climb_mps(self) -> float:
        """Peak vertical speed 2 dh / T (m/s, up-positive)."""
        return 2.0 * self.dh_m / (self.end_s - self.start_s)

    @property
    def peak_accel_mps2(self) -> float:
        """Peak vertical acceleration magnitude 2 pi |dh| / T^2 (m/s^2)."""
        return 2.0 * math.pi * abs(self.dh_m) / (self.end_s - self.start_s) ** 2


SEED003_LEGS: tuple[VerticalLeg, ...] = (
    VerticalLeg(100.0, 160.0, 300.0),   # high manoeuvre: +300 m in 60 s (peak 10 m/s, 0.52 m/s^2), in gap 1
    VerticalLeg(220.0, 260.0, -60.0),   # low manoeuvre: -60 m in 40 s (peak 3 m/s, 0.24 m/s^2), GPS present
    VerticalLeg(340.0, 390.0, -250.0),  # high manoeuvre: -250 m in 50 s (peak 10 m/s, 0.63 m/s^2), in gap 2
    VerticalLeg(420.0, 460.0, 40.0),    # low manoeuvre: +40 m in 40 s (peak 2 m/s, 0.16 m/s^2), in gap 2
)
"""Our reading of seed 003 Fig. 3 ("high and low vertical maneuvers"; no numbers printed): level legs
between two large and two small climbs / descents, the large ones inside the GPS gaps SEED003_GAPS_S."""

SEED003_GAPS_S: tuple[tuple[float, float], ...] = ((80.0, 200.0), (320.0, 480.0))
"""GPS gaps (start, end), s, for SEED003_LEGS: each covers a large manoeuvre with level flight before and
after it (seed 003: "the existence of the vertical acceleration of the object during the period when the GPS
is not in use significantly reduces the accuracy"). Our choice; the paper gives no gap times for its
simulation (its experiment: 839-850 s and 860-885 s)."""


def vertical_profile(t_s: Array, h0_m: float, legs: tuple[VerticalLeg, ...]) -> tuple[Array, Array, Array]:
    """Height h (m), vertical speed v_up (m/s) and acceleration a_up (m/s^2) at times t_s (s), analytic."""
    t = np.asarray(t_s, dtype=float)
    h = np.full(t.shape, float(h0_m))
    v = np.zeros(t.shape)
    a = np.zeros(t.shape)
    for leg in legs:
        T = leg.end_s - leg.start_s
        s = np.clip((t - leg.start_s) / T, 0.0, 1.0)
        h = h + leg.dh_m * (s - np.sin(2.0 * np.pi * s) / (2.0 * np.pi))
        v = v + leg.dh_m / T * (1.0 - np.cos(2.0 * np.pi * s))
        a = a + np.where((s > 0.0) & (s < 1.0), leg.dh_m / T**2 * 2.0 * np.pi * np.sin(2.0 * np.pi * s), 0.0)
    return h, v, a


def vertical_manoeuvre(
    runway: geo.RunwayFrame,
    *,
    rate_hz: float,
    duration_s: float = 520.0,
    h0_m: float = 600.0,
    legs: tuple[VerticalLeg, ...] = SEED003_LEGS,
    ground_speed_mps: float = 70.0,
    track_rad: float | None = None,
    lat0_rad: float | None = None,
    lon0_rad: float | None = None,
    pitch_rad: float = math.radians(2.0),
    terrain_h_m: float | None = None,
    isa_dev_k: float = 0.0,
    sea_level_pa: float = atmosphere.P0_PA,
) -> Truth:
    """Synthetic truth of level flight with climbs / descents `legs` (module docstring: trajectory, contract).

    Samples at t = 0, 1/rate_hz, ..., duration_s; starts at (lat0, lon0) (default the runway threshold) at
    ellipsoid height h0_m, flying ground_speed_mps (m/s) along track_rad (default the runway heading).
    terrain_h_m: constant terrain ellipsoid height (default the threshold height). The runway-frame fields
    (r_rwy, gs_dev_m, loc_dev_m) are relative to `runway`, gs_dev_m to the straight glide path cone
    (approachsim.glidepath) of a 3 deg glidepath with a 15.24 m TCH.
    """
    n = int(round(duration_s * rate_hz)) + 1
    if n < 2:
        raise ValueError(f"duration_s * rate_hz must give at least 2 samples, got {duration_s} s at {rate_hz} Hz")
    dt = 1.0 / rate_hz
    t = np.arange(n) * dt
    psi = runway.heading_rad if track_rad is None else float(track_rad)
    lat0 = runway.threshold_lat_rad if lat0_rad is None else float(lat0_rad)
    lon0 = runway.threshold_lon_rad if lon0_rad is None else float(lon0_rad)
    v_n, v_e = ground_speed_mps * math.cos(psi), ground_speed_mps * math.sin(psi)

    def height(tt: Array) -> Array:
        return vertical_profile(tt, h0_m, legs)[0]

    def rhs(tt: float, y: Array) -> Array:
        lat = y[0]
        h = float(height(np.array(tt)))
        r_n, r_e = geo.radii(lat)
        return np.array([v_n / (r_n + h), v_e / ((r_e + h) * math.cos(lat))])

    # to one step past the end: the last row's f_body carries the state over [t_end, t_end + dt]
    sol = solve_ivp(rhs, (0.0, t[-1] + dt), [lat0, lon0], method="DOP853", dense_output=True, rtol=1e-13,
                    atol=1e-15, max_step=max(5.0, 10.0 * dt))
    if not sol.success:  # pragma: no cover - DOP853 on this smooth field does not fail
        raise RuntimeError(f"manoeuvre trajectory integration failed: {sol.message}")

    def state(tt: Array) -> tuple[Array, Array, Array, Array]:
        lat, lon = sol.sol(tt)
        h, v_up, _ = vertical_profile(tt, h0_m, legs)
        v = np.stack([np.full(tt.shape, v_n), np.full(tt.shape, v_e), -v_up], axis=-1)
        return lat, lon, h, v

    lat, lon, h, v_ned = state(t)
    euler = np.tile(np.array([0.0, pitch_rad, psi]), (n, 1))
    c_bn = np.swapaxes(euler_to_c_nb(euler), -1, -2)

    # interval means over [t_k, t_k + dt]: kinematic term exact, Coriolis / gravity / rates by Gauss-Legendre
    _, v_next = state(t + dt)[2:]
    dv_dt = (v_next - v_ned) / dt
    cor_g = np.zeros((n, 3))
    w_in = np.zeros((n, 3))
    for x, w in zip(_GL_NODES, _GL_WEIGHTS, strict=True):
        tq = t + 0.5 * dt * (1.0 + x)
        la, _lo, hq, vq = state(tq)
        w_ie, w_en = earth_rate_ned(la), transport_rate_ned(la, hq, vq)
        cor_g += w * (np.cross(2.0 * w_ie + w_en, vq) - gravity_ned(la, hq))
        w_in += w * (w_ie + w_en)
    f_ned = dv_dt + cor_g  # v' = f + g - (2 w_ie + w_en) x v  =>  f = v' + (2 w_ie + w_en) x v - g
    f_body = np.einsum("nij,nj->ni", c_bn, f_ned)
    w_ib_body = np.einsum("nij,nj->ni", c_bn, w_in)  # constant attitude in NED: w_ib = w_ie + w_en

    r_ecef = geo.geodetic_to_ecef(lat, lon, h)
    r_tan = runway.from_ecef(r_ecef)
    hat = runway.height_above_threshold(h)
    glidepath, tch = math.radians(3.0), 15.24
    terr = runway.threshold_h_m if terrain_h_m is None else float(terrain_h_m)
    h_geo = atmosphere.geopotential_m(h)
    p = atmosphere.static_pressure_pa(h_geo, isa_dev_k, sea_level_pa)
    t_air = atmosphere.air_temperature_k(h_geo, isa_dev_k)
    rho = p / (atmosphere.R_AIR * t_air)
    return Truth(
        t_s=t,
        lat_rad=lat,
        lon_rad=lon,
        h_m=h,
        r_ecef=r_ecef,
        v_ned=v_ned,
        q_nb=euler_to_quaternion(euler),
        euler_rad=euler,
        w_ib_body=w_ib_body,
        f_body=f_body,
        p_static_pa=p,
        t_air_k=t_air,
        h_agl_m=h - terr,
        r_rwy=np.column_stack([r_tan[:, 0], r_tan[:, 1], hat]),
        gs_dev_m=GlidePath(glidepath, tch, runway.heading_rad, runway.threshold_lat_rad).deviation_m(
            r_tan[:, 0], r_tan[:, 1], hat),
        loc_dev_m=r_tan[:, 1].copy(),
        controls=np.zeros((n, 4)),
        airspeed_mps=np.linalg.norm(v_ned, axis=-1) * np.sqrt(rho / _RHO0),
        runway=runway,
    )
