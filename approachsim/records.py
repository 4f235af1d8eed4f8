"""The plain data the stages exchange: frozen dataclasses of numpy arrays, axes and units documented.

Time is axis 0 of a single-flight record. Batched records (several Monte Carlo runs sharing one time
base) put the run axis first: (runs, time, ...). All SI; frames in the field names.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Protocol

import numpy as np

from approachsim.geo import RunwayFrame

Array = np.ndarray


@dataclass(frozen=True)
class Truth:
    """What the aircraft really did, sampled at the IMU rate; every array has time on axis 0 (n samples).

    Kinematic quantities (position, velocity, specific force, rates) are those of the IMU location,
    which is what an IMU at that point senses; the runway-frame deviations are of the same point.
    """

    t_s: Array
    """(n,) time since the start of the run, s."""
    lat_rad: Array
    """(n,) geodetic latitude of the IMU, rad."""
    lon_rad: Array
    """(n,) longitude of the IMU, rad."""
    h_m: Array
    """(n,) height of the IMU above the WGS-84 ellipsoid, m."""
    r_ecef: Array
    """(n, 3) IMU position, ECEF, m."""
    v_ned: Array
    """(n, 3) IMU velocity relative to the Earth, local NED axes, m/s."""
    q_nb: Array
    """(n, 4) attitude quaternion body->NED, scalar first (w, x, y, z): v_ned = q v_body q*."""
    euler_rad: Array
    """(n, 3) roll, pitch, true heading (body relative to NED), rad."""
    w_ib_body: Array
    """(n, 3) body angular rate relative to inertial space, body axes (what a gyro senses), rad/s."""
    f_body: Array
    """(n, 3) specific force at the IMU, body axes (what an accelerometer senses), m/s^2."""
    p_static_pa: Array
    """(n,) ambient static pressure at the aircraft, Pa."""
    t_air_k: Array
    """(n,) ambient (static) air temperature, K."""
    h_agl_m: Array
    """(n,) height of the IMU above the profile's terrain, m."""
    r_rwy: Array
    """(n, 3) runway frame: along (x, m past the threshold), cross (y, m right), height above threshold (m)."""
    gs_dev_m: Array
    """(n,) vertical deviation from the ideal glidepath, m (positive above)."""
    loc_dev_m: Array
    """(n,) lateral deviation from the extended centreline, m (positive right)."""
    controls: Array
    """(n, 4) elevator, aileron, rudder, throttle commands, normalized (-1..1, 0..1)."""
    airspeed_mps: Array
    """(n,) calibrated airspeed, m/s."""
    runway: RunwayFrame = field(compare=False)
    """The runway frame the r_rwy columns are in."""

    def __len__(self) -> int:
        return int(self.t_s.shape[0])

    def arrays(self) -> dict[str, Array]:
        """All array fields by name (for saving and slicing)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "runway"}

    def slice(self, sl: slice) -> Truth:
        """The record restricted to time indices `sl`."""
        return Truth(**{k: v[sl] for k, v in self.arrays().items()}, runway=self.runway)


@dataclass(frozen=True)
class NavSolution:
    """The navigation system's output for one run at the IMU rate (time on axis 0), for the IMU point.

    Feed-forward convention: output = INS - estimated error. Covariances are the filter's own claim.
    """

    t_s: Array
    """(n,) time since the start of the run, s (same time base as the Truth)."""
    r_ecef: Array
    """(n, 3) estimated position, ECEF, m."""
    v_ned: Array
    """(n, 3) estimated velocity relative to the Earth, NED, m/s."""
    euler_rad: Array
    """(n, 3) estimated roll, pitch, heading, rad."""
    P_pos_ned: Array
    """(n, 3, 3) the filter's position-error covariance in local NED axes, m^2."""
    clock_bias_m: Array
    """(n,) estimated GPS receiver clock bias, m (nan where there is no GPS clock state)."""
    clock_bias_sigma_m: Array
    """(n,) its claimed 1-sigma, m (nan where none)."""


class NavigationSource(Protocol):
    """Where the autopilot's guidance reads position and velocity: the truth, or the navigation solution.

    The flight loop calls step(k, truth) once per step, after writing row k of the (preallocated, being
    filled) truth arrays; the source may read rows <= k only. It returns the position (runway frame:
    along, cross, height above threshold, m) and NED velocity (m/s) that guidance should fly on.
    """

    def step(self, k: int, truth: Truth) -> tuple[Array, Array]: ...
