"""Synthetic test truth: analytic, exactly kinematically consistent Truth records for tests and benchmarks.

NOT a flight model and not a stand-in for the JSBSim truth (approachsim.flight): there is no aircraft, no
autopilot, no wind, no turbulence. These records exist so that sensor, INS and filter tests have a truth whose
specific force and body rates are *exactly* those of its position/velocity/attitude history under the same
WGS-84 NED mechanization equations that a strapdown INS integrates. Two trajectories:

``stationary``  the IMU at rest on the Earth at a fixed lat/lon/height and attitude.
``glidepath_descent``  straight, unaccelerated descent down the straight glide path cone
    (approachsim.glidepath: the line from the glide path intercept point at the glide path angle above its
    horizontal plane) toward a RunwayFrame: constant ECEF velocity, wings level, constant attitude relative to
    the local NED frame.

How each is consistent (the contract an INS test can rely on; Groves 2nd ed. eq. 5.44-5.56, NED frame):

* Gravity is the vector g_ned = geo.gravity_ned(lat, h) (JSBSim's J2 gravitation plus centrifugal, the
  one model of the simulated world and the INS; a few 1e-5 m/s^2 off the local vertical), evaluated at
  each sample's own lat and h.
* Earth rate w_ie_ned = OMEGA_E (cos lat, 0, -sin lat); transport rate
  w_en_ned = (vE / (R_E + h), -vN / (R_N + h), -vE tan(lat) / (R_E + h)) with geo.radii at the sample's lat.
* Position is the straight line r_ecef(t) = r_end + v_e (t - t_end), lat/lon/h its exact geodetic coordinates
  (geo.ecef_to_geodetic), so lat/lon/h/r_ecef are the exact trajectory of that velocity, not a linearization.
* Velocity is constant in ECEF (v_e), so its NED components turn with the NED frame: v_ned = C_en' v_e and
  v_ned' = -w_en x v_ned (C_en' ' = -[w_en x] C_en'). The velocity equation
  v_ned' = C_bn f_body + g_ned - (2 w_ie + w_en) x v_ned then gives the specific force at each sample exactly:
  f_ned = v_ned' + (2 w_ie + w_en) x v_ned - g_ned = 2 w_ie x v_ned - g_ned, f_body = C_nb' f_ned.
  (Stationary: v = 0, f_body = C_nb' (0, 0, -g): the accelerometers read 1 g up.)
* Attitude is constant relative to NED (C_nb' = 0 in the NED frame), so the body turns with the NED frame
  relative to inertial space: w_ib_body = C_nb' (w_ie + w_en) (stationary: C_nb' w_ie, Earth rate).

Both w_ib_body and f_body therefore vary only through lat, h and the turning of v_ned (micro-rad/s and
micro-g over an approach), so the IMU's increments (sensors/imu.py: the sample at the start of each interval held
over it) differ from the exact integral by dt^2/2 df/dt per step, which telescopes to dt/2 (f_end - f_start),
nanometres per second of velocity over a 10 nmi approach.

The glidepath deviation gs_dev_m is taken against the straight cone (approachsim.glidepath, the one glide path
reference; before issue 25's follow-up these records flew and scored a path parallel to the ellipsoid, which
curves d^2 / (2 R) below the cone: 27 m at 10 nmi). The atmosphere fields use the ISA troposphere with the
given ISA deviation and sea-level pressure (sensors/atmosphere.py); airspeed_mps is the equivalent airspeed of
the ground speed (still air); controls are zero. Heights are ellipsoid heights and MSL is the ellipsoid (no
geoid, as profile.py says).
"""

from __future__ import annotations

import math

import numpy as np

from approachsim import geo
from approachsim.glidepath import GlidePath
from approachsim.records import Truth
from approachsim.sensors import atmosphere

Array = np.ndarray

_RHO0 = atmosphere.P0_PA / (atmosphere.R_AIR * atmosphere.T0_K)


def euler_to_c_nb(euler_rad: Array) -> Array:
    """Body-to-NED rotation matrices (..., 3, 3) from roll, pitch, heading (..., 3), rad (ZYX order)."""
    e = np.asarray(euler_rad, dtype=float)
    cr, sr = np.cos(e[..., 0]), np.sin(e[..., 0])
    cp, sp = np.cos(e[..., 1]), np.sin(e[..., 1])
    cy, sy = np.cos(e[..., 2]), np.sin(e[..., 2])
    c = np.empty(e.shape[:-1] + (3, 3))
    c[..., 0, 0] = cp * cy
    c[..., 0, 1] = sr * sp * cy - cr * sy
    c[..., 0, 2] = cr * sp * cy + sr * sy
    c[..., 1, 0] = cp * sy
    c[..., 1, 1] = sr * sp * sy + cr * cy
    c[..., 1, 2] = cr * sp * sy - sr * cy
    c[..., 2, 0] = -sp
    c[..., 2, 1] = sr * cp
    c[..., 2, 2] = cr * cp
    return c


def euler_to_quaternion(euler_rad: Array) -> Array:
    """Body-to-NED quaternions (..., 4), scalar first, from roll, pitch, heading (..., 3), rad (ZYX order)."""
    e = np.asarray(euler_rad, dtype=float) / 2.0
    cr, sr = np.cos(e[..., 0]), np.sin(e[..., 0])
    cp, sp = np.cos(e[..., 1]), np.sin(e[..., 1])
    cy, sy = np.cos(e[..., 2]), np.sin(e[..., 2])
    return np.stack(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ],
        axis=-1,
    )


def earth_rate_ned(lat_rad: Array) -> Array:
    """Earth rotation rate in NED axes (..., 3), rad/s: OMEGA_E (cos lat, 0, -sin lat)."""
    lat = np.asarray(lat_rad, dtype=float)
    return geo.OMEGA_E * np.stack([np.cos(lat), np.zeros_like(lat), -np.sin(lat)], axis=-1)


def transport_rate_ned(lat_rad: Array, h_m: Array, v_ned: Array) -> Array:
    """Transport rate w_en in NED axes (..., 3), rad/s (Groves eq. 5.44), radii from geo.radii."""
    lat = np.asarray(lat_rad, dtype=float)
    h = np.asarray(h_m, dtype=float)
    v = np.asarray(v_ned, dtype=float)
    r_n, r_e = geo.radii(lat)
    return np.stack(
        [v[..., 1] / (r_e + h), -v[..., 0] / (r_n + h), -v[..., 1] * np.tan(lat) / (r_e + h)], axis=-1
    )


def gravity_ned(lat_rad: Array, h_m: Array) -> Array:
    """Gravity vector in NED (..., 3), m/s^2: geo.gravity_ned (JSBSim's J2 gravitation + centrifugal)."""
    return geo.gravity_ned(lat_rad, h_m)


def _time_base(duration_s: float, rate_hz: float) -> Array:
    n = int(round(duration_s * rate_hz)) + 1
    if n < 2:
        raise ValueError(f"duration_s * rate_hz must give at least 2 samples, got {duration_s} s at {rate_hz} Hz")
    return np.arange(n) / rate_hz


def _assemble(
    t_s: Array,
    lat: Array,
    lon: Array,
    h: Array,
    v_ned: Array,
    euler: Array,
    runway: geo.RunwayFrame,
    terrain_h_m: Array,
    glidepath_rad: float,
    tch_m: float,
    isa_dev_k: float,
    sea_level_pa: float,
    *,
    r_ecef: Array | None = None,
    constant_ecef_velocity: bool = False,
) -> Truth:
    """Truth fields from a trajectory with constant attitude relative to NED and a velocity constant in NED (at
    rest) or, constant_ecef_velocity, constant in ECEF (the straight line: v_ned' = -w_en x v_ned)."""
    n = t_s.shape[0]
    c_nb = euler_to_c_nb(euler)
    c_bn = np.swapaxes(c_nb, -1, -2)
    w_ie = earth_rate_ned(lat)
    w_en = transport_rate_ned(lat, h, v_ned)
    # constant attitude in NED: the body turns with the NED frame, w_ib = w_ie + w_en (resolved in body)
    w_ib_body = np.einsum("nij,nj->ni", c_bn, w_ie + w_en)
    # v_ned' = f_ned + g_ned - (2 w_ie + w_en) x v  =>  f_ned = v_ned' + (2 w_ie + w_en) x v - g_ned
    f_ned = np.cross(2.0 * w_ie + w_en, v_ned) - gravity_ned(lat, h)
    if constant_ecef_velocity:
        f_ned = f_ned - np.cross(w_en, v_ned)
    f_body = np.einsum("nij,nj->ni", c_bn, f_ned)
    if r_ecef is None:
        r_ecef = geo.geodetic_to_ecef(lat, lon, h)
    r_tan = runway.from_ecef(r_ecef)
    hat = runway.height_above_threshold(h)
    r_rwy = np.column_stack([r_tan[:, 0], r_tan[:, 1], hat])
    cone = GlidePath(glidepath_rad, tch_m, runway.heading_rad, runway.threshold_lat_rad)
    gs_dev = cone.deviation_m(r_tan[:, 0], r_tan[:, 1], hat)
    h_geo = atmosphere.geopotential_m(h)
    p = atmosphere.static_pressure_pa(h_geo, isa_dev_k, sea_level_pa)
    t_air = atmosphere.air_temperature_k(h_geo, isa_dev_k)
    rho = p / (atmosphere.R_AIR * t_air)
    eas = np.linalg.norm(v_ned, axis=-1) * np.sqrt(rho / _RHO0)
    return Truth(
        t_s=t_s,
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
        h_agl_m=h - terrain_h_m,
        r_rwy=r_rwy,
        gs_dev_m=gs_dev,
        loc_dev_m=r_tan[:, 1].copy(),
        controls=np.zeros((n, 4)),
        airspeed_mps=eas,
        runway=runway,
    )


def stationary(
    lat_rad: float,
    lon_rad: float,
    h_m: float,
    duration_s: float,
    rate_hz: float,
    *,
    euler_rad: tuple[float, float, float] = (0.0, 0.0, 0.0),
    runway: geo.RunwayFrame | None = None,
    terrain_h_m: float | None = None,
    isa_dev_k: float = 0.0,
    sea_level_pa: float = atmosphere.P0_PA,
) -> Truth:
    """Synthetic truth of an IMU at rest at (lat, lon, h) with fixed roll, pitch, heading (rad).

    Samples at t = 0, 1/rate_hz, ..., duration_s. f_body = C_nb' (0, 0, -g(lat, h)); w_ib_body = C_nb' w_ie.
    runway defaults to a frame at the point with the given heading; terrain_h_m (ellipsoid, m) to that
    frame's threshold height; the glidepath fields assume 3 deg and a 15 m threshold crossing height.
    """
    t = _time_base(duration_s, rate_hz)
    n = t.shape[0]
    rwy = runway if runway is not None else geo.RunwayFrame(lat_rad, lon_rad, h_m, euler_rad[2])
    terr = rwy.threshold_h_m if terrain_h_m is None else terrain_h_m
    return _assemble(
        t,
        np.full(n, float(lat_rad)),
        np.full(n, float(lon_rad)),
        np.full(n, float(h_m)),
        np.zeros((n, 3)),
        np.tile(np.asarray(euler_rad, dtype=float), (n, 1)),
        rwy,
        np.full(n, float(terr)),
        math.radians(3.0),
        15.0,
        isa_dev_k,
        sea_level_pa,
    )


def glidepath_descent(
    runway: geo.RunwayFrame,
    *,
    rate_hz: float,
    start_distance_m: float = 18520.0,
    end_distance_m: float = 0.0,
    glidepath_rad: float = math.radians(3.0),
    tch_m: float = 15.24,
    ground_speed_mps: float = 70.0,
    pitch_rad: float = math.radians(2.0),
    terrain_h_m: float | Array | None = None,
    terrain_along_m: Array | None = None,
    isa_dev_k: float = 0.0,
    sea_level_pa: float = atmosphere.P0_PA,
) -> Truth:
    """Synthetic truth of an unaccelerated straight descent down the glide path cone toward `runway`.

    The path is the straight line of the cone (approachsim.glidepath) in the vertical plane of the centreline:
    from the glide path intercept point (GPI: TCH / tan(gp) past the threshold on the centreline, at the
    threshold's ellipsoid height) back along the runway direction at the glide path angle above the GPI's
    horizontal plane. It is flown at the constant ECEF velocity whose horizontal part at the GPI is
    ground_speed_mps (m/s) towards the GPI, wings level at pitch_rad and the runway heading, for the time that
    speed needs for start - end distance, ending on the line end_distance_m before the threshold (runway-frame
    x = -end_distance_m to < 1 mm; height above the threshold the cone's there: tch_m + end tan(gp) + the Earth's
    drop under the GPI's horizontal plane). The line is on the cone: gs_dev_m is the cone's second-order
    approximation error (< 5 mm, tests/unit/test_glidepath.py) and loc_dev_m below 1 mm.

    Terrain: a constant ellipsoid height (terrain_h_m scalar, default the threshold height), or heights
    terrain_h_m at runway-frame x = terrain_along_m (linear interpolation, as profile.Terrain).
    """
    if end_distance_m >= start_distance_m:
        raise ValueError("end_distance_m must be less than start_distance_m")
    duration = (start_distance_m - end_distance_m) / ground_speed_mps
    t = _time_base(duration, rate_hz)
    psi = runway.heading_rad
    tan_gp = math.tan(glidepath_rad)
    x_gpi = tch_m / tan_gp
    # the GPI and its local vertical: NED axes there, the runway direction in its horizontal plane
    lat_g, lon_g, _ = geo.ecef_to_geodetic(runway.to_ecef(np.array([x_gpi, 0.0, 0.0])))
    gpi = geo.geodetic_to_ecef(lat_g, lon_g, runway.threshold_h_m)
    c_ecef_to_ned_g = geo.c_ecef_to_ned(lat_g, lon_g)
    u = c_ecef_to_ned_g @ runway.c_ecef_to_rwy[0]  # runway x axis in the GPI's NED
    u_h = np.array([u[0], u[1], 0.0]) / math.hypot(u[0], u[1])
    # the line: ned = -D u_h - (0, 0, D tan gp) at horizontal distance D before the GPI; velocity V (u_h + tan gp down)
    d_end = x_gpi + end_distance_m
    r_end = gpi + c_ecef_to_ned_g.T @ (-d_end * u_h - np.array([0.0, 0.0, d_end * tan_gp]))
    v_e = c_ecef_to_ned_g.T @ (ground_speed_mps * (u_h + np.array([0.0, 0.0, tan_gp])))
    r_ecef = r_end + (t - t[-1])[:, None] * v_e
    lat, lon, h = geo.ecef_to_geodetic(r_ecef)
    n = t.shape[0]
    v_ned = np.einsum("nij,j->ni", geo.c_ecef_to_ned(lat, lon), v_e)
    r_tan = runway.from_ecef(r_ecef)
    if terrain_h_m is None:
        terr = np.full(n, runway.threshold_h_m)
    elif terrain_along_m is None:
        terr = np.full(n, float(np.asarray(terrain_h_m)))
    else:
        terr = np.interp(r_tan[:, 0], np.asarray(terrain_along_m, dtype=float), np.asarray(terrain_h_m, dtype=float))
    return _assemble(
        t,
        lat,
        lon,
        h,
        v_ned,
        np.tile(np.array([0.0, pitch_rad, psi]), (n, 1)),
        runway,
        terr,
        glidepath_rad,
        tch_m,
        isa_dev_k,
        sea_level_pa,
        r_ecef=r_ecef,
        constant_ecef_velocity=True,
    )


def profile_descent(profile, *, rate_hz: float | None = None, ground_speed_mps: float = 70.0) -> Truth:
    """glidepath_descent for a Profile: its runway, glidepath, TCH, start distance, terrain and atmosphere.

    Flies to the threshold at the profile's IMU rate unless rate_hz is given. Still air: the profile's wind
    and turbulence are ignored (synthetic test truth, not a flight).
    """
    rw = profile.runway
    return glidepath_descent(
        rw.frame,
        rate_hz=profile.rates.imu_hz if rate_hz is None else rate_hz,
        start_distance_m=rw.start_distance_m,
        glidepath_rad=rw.glidepath_rad,
        tch_m=rw.tch_m,
        ground_speed_mps=ground_speed_mps,
        terrain_h_m=np.asarray(profile.terrain.height_m),
        terrain_along_m=np.asarray(profile.terrain.along_m),
        isa_dev_k=profile.environment.isa_dev_k,
        sea_level_pa=profile.environment.sea_level_pa,
    )
