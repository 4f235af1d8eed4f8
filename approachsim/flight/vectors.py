"""The flight loop kernel's inputs from the readable models, and the numpy oracles of its truth row.

`flight_vectors` packs one flight's parameter and state vectors for core/loop/flight_step.py's `fly_step` (the
IMU-point constants, the autopilot, turbulence and stabilized-approach monitor from their oracles, the terrain
profile); `imu_point_rows_reference` and `earth_rates_reference` are the vectorized numpy versions of the
kernel's truth row (tests/unit/flight/test_flight_kernels.py compares them).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from approachsim import geo, units
from approachsim.core import layouts, tables
from approachsim.core.loop import flight_step as fk
from approachsim.glidepath import GlidePath, cone_height

Array = np.ndarray


def imu_point_constants(lever_arm_m: Array, lat0_rad: float, runway: Any, dt_s: float) -> Array:
    """The kernel's constants (22,): lever arm l (body axes, m; CG to IMU), the radii R_N, R_E (m) at lat0_rad
    (held over the approach, as flight/run.py does), the runway frame's ECEF origin (m) and the first two rows
    of its ECEF-to-runway matrix, threshold height (m), tan(glidepath), TCH (m), the glide path cone's GPI (m)
    and curvature coefficients a, b, c (1/m; approachsim.glidepath.GlidePath.constants) and the step dt_s (s).

    runway: the profile's runway (profile.Runway: .frame, .elevation_m, .glidepath_rad, .tch_m, .heading_rad,
    .threshold_lat_rad)."""
    r_n, r_e = geo.radii(lat0_rad)
    frame = runway.frame
    c = frame.c_ecef_to_rwy
    _, x_gpi, ca, cb, cc = GlidePath.of(runway).constants()
    return np.array([*np.asarray(lever_arm_m, dtype=float), float(r_n), float(r_e), *frame.origin_ecef,
                     *c[0], *c[1], runway.elevation_m, math.tan(runway.glidepath_rad), runway.tch_m,
                     x_gpi, ca, cb, cc, dt_s], dtype=float)


def _cross(a: Array, b: Array) -> Array:
    return np.cross(a, b)


def earth_rates_reference(raw: Array) -> Array:
    """JSBSim's Earth-relative body rates p, q, r (velocities/p-rad_sec, ...) from reads in RAW_FIELDS order, (n, 3)
    rad/s: w_eb = w_ib - C_nb' w_ie, w_ie = Omega (cos L, 0, -sin L) in JSBSim's local NED, whose latitude is the
    geodetic one (FGLocation's local frame), Omega = geo.OMEGA_JSBSIM; C_nb from the Euler angles.

    JSBSim computes vPQR = vPQRi - Ti2b (0, 0, Omega) (FGPropagate::Run) with Ti2b from its ECI quaternion, which
    it renormalizes only when |1 - |q|| reaches 1e-10 (FGQuaternion::Normalize): its Ti2b is scaled by |q|^2, so
    its p, q, r differ from these by up to 2e-10 Omega = 1.5e-14 rad/s (tests/integration/test_flight_reads.py)."""
    raw = np.atleast_2d(np.asarray(raw, dtype=float))
    lat, phi, th, psi = raw[:, 0], raw[:, 6], raw[:, 7], raw[:, 8]
    w_ie = fk.OMEGA_JSBSIM * np.stack([np.cos(lat), np.zeros_like(lat), -np.sin(lat)], axis=1)
    cr, sr, cp, sp, cy, sy = np.cos(phi), np.sin(phi), np.cos(th), np.sin(th), np.cos(psi), np.sin(psi)
    c_nb = np.stack([np.stack([cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy], -1),
                     np.stack([cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy], -1),
                     np.stack([-sp, sr * cp, cr * cp], -1)], -2)
    return raw[:, 9:12] - np.einsum("nji,nj->ni", c_nb, w_ie)


def imu_point_rows_reference(raw: Array, const: Array, along_m: Array, height_m: Array, t_s: Array) -> Array:
    """`imu_point_row` for many steps at once in vectorized numpy (the kernel's test oracle): raw (n, 24) in
    RAW_FIELDS order, t_s (n,); returns (n, 36) rows with columns 0-30 and 35 filled (NaN elsewhere).

    Written with matrices and np.cross rather than the kernel's scalar expressions, so that it checks them."""
    raw = np.atleast_2d(np.asarray(raw, dtype=float))
    n = raw.shape[0]
    lev = const[0:3]
    r_n, r_e = const[3], const[4]
    origin = const[5:8]
    c_rwy2 = np.stack([const[8:11], const[11:14]])
    h_thr, dt = const[14], const[21]
    lat, lon, h = raw[:, 0], raw[:, 1], raw[:, 2] * units.FT
    v_cg = raw[:, 3:6] * units.FPS
    eul = raw[:, 6:9]
    w_ib, w_dot = raw[:, 9:12], raw[:, 12:15]
    f_cg = raw[:, 15:18] * (fk.LBF_PER_SLUG / raw[:, 18:19])
    cr, sr = np.cos(eul[:, 0]), np.sin(eul[:, 0])
    cp, sp = np.cos(eul[:, 1]), np.sin(eul[:, 1])
    cy, sy = np.cos(eul[:, 2]), np.sin(eul[:, 2])
    c_nb = np.stack([np.stack([cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy], -1),
                     np.stack([cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy], -1),
                     np.stack([-sp, sr * cp, cr * cp], -1)], -2)  # body -> NED, (n, 3, 3)
    l_b = np.broadcast_to(lev, (n, 3))
    w_eb = earth_rates_reference(raw)
    e = 0.5 * dt * w_ib
    a = _cross(w_ib + dt * w_dot, l_b)  # w1 x l
    b = _cross(e, a)
    k2 = 2.0 / (1.0 + np.sum(e * e, axis=1))
    rot_a = a + k2[:, None] * (b + _cross(e, b))  # R (w1 x l), R = rotation by the quaternion (1, e)
    f = f_cg + (rot_a - _cross(w_ib, l_b)) / dt
    v = v_cg + np.einsum("nij,nj->ni", c_nb, _cross(w_eb, l_b))
    d = np.einsum("nij,j->ni", c_nb, lev)  # C_nb l, NED
    lat_i = lat + d[:, 0] / (r_n + h)
    lon_i = lon + d[:, 1] / ((r_e + h) * np.cos(lat))
    h_i = h - d[:, 2]
    r = geo.geodetic_to_ecef(lat_i, lon_i, h_i)
    kg = fk.GM_JSBSIM / np.sum(r * r, axis=1) ** 1.5
    f = f + kg[:, None] * (l_b - 3.0 * d[:, 2:3] * c_nb[:, 2, :])
    g_ned = (kg * 0.5 * dt)[:, None] * np.stack(
        [v[:, 0], v[:, 1] + fk.OMEGA_JSBSIM * np.hypot(r[:, 0], r[:, 1]), -2.0 * v[:, 2]], axis=1)
    f = f + np.einsum("nji,nj->ni", c_nb, g_ned)  # C_nb' g
    phi_v = 2.0 * e
    a2 = np.sum(phi_v * phi_v, axis=1)[:, None]
    pf = _cross(phi_v, f)
    f = f - (0.5 - a2 / 24.0) * pf + (1.0 / 6.0 - a2 / 120.0) * _cross(phi_v, pf)
    t = np.stack([d[:, 1] / (r_e + h), -d[:, 0] / (r_n + h), -d[:, 1] * np.tan(lat) / (r_e + h)], axis=1)
    v = v - _cross(t, v)  # (I - [t x]) v
    m_nb = c_nb - _cross(t[:, None, :], c_nb.transpose(0, 2, 1)).transpose(0, 2, 1)  # (I - [t x]) C_nb by column
    roll = np.arctan2(m_nb[:, 2, 1], m_nb[:, 2, 2])
    pitch = -np.arcsin(m_nb[:, 2, 0])
    yaw = eul[:, 2] + np.remainder(np.arctan2(m_nb[:, 1, 0], m_nb[:, 0, 0]) - eul[:, 2] + np.pi, 2.0 * np.pi) - np.pi
    p_imu = raw[:, 19] * units.PSF * np.exp(d[:, 2] * fk.G0_OVER_R_AIR / (raw[:, 20] / fk.RANKINE_PER_K))
    xy = (r - origin) @ c_rwy2.T
    zr = h_i - h_thr
    terr = np.full(n, height_m[0]) if len(height_m) == 1 else np.interp(xy[:, 0], along_m, height_m)
    hr, hp, hy = 0.5 * roll, 0.5 * pitch, 0.5 * yaw
    q = np.stack([np.cos(hr) * np.cos(hp) * np.cos(hy) + np.sin(hr) * np.sin(hp) * np.sin(hy),
                  np.sin(hr) * np.cos(hp) * np.cos(hy) - np.cos(hr) * np.sin(hp) * np.sin(hy),
                  np.cos(hr) * np.sin(hp) * np.cos(hy) + np.sin(hr) * np.cos(hp) * np.sin(hy),
                  np.cos(hr) * np.cos(hp) * np.sin(hy) - np.sin(hr) * np.sin(hp) * np.cos(hy)], axis=1)
    out = np.full((n, 36), np.nan)
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = t_s, lat_i, lon_i, h_i
    out[:, 4:7], out[:, 7:10], out[:, 10:14] = r, v, q
    out[:, 14], out[:, 15], out[:, 16] = roll, pitch, yaw
    out[:, 17:20], out[:, 20:23] = w_ib, f
    out[:, 23], out[:, 24], out[:, 25] = p_imu, raw[:, 20] / fk.RANKINE_PER_K, h_i - terr
    out[:, 26], out[:, 27], out[:, 28] = xy[:, 0], xy[:, 1], zr
    out[:, 29] = zr - cone_height(xy[:, 0], xy[:, 1], const[15], *const[17:21])
    out[:, 30] = xy[:, 1]
    out[:, 35] = raw[:, 21] * units.KT
    return out


def autopilot_arrays(ap: Any) -> tuple[Array, Array]:
    """(parameters, state) of the compiled autopilot (AP_*, APS_*) from its oracle (flight/autopilot.Autopilot)."""
    par = [getattr(ap.g, name) for name in layouts.AP_GAINS]
    par += [ap.trim.theta_rad, ap.trim.throttle, ap.trim.cas_mps, ap.ch, ap.sh, ap.heading_rad, ap.tan_gp,
            ap.x_gpi_m, ap.cone_a, ap.cone_b, ap.cone_c, ap.conv_per_east_m, ap.gear_arm_m, ap.dt]
    return np.array(par, dtype=float), np.array(ap.state(), dtype=float)


def dryden_arrays(turb: Any) -> tuple[Array, Array]:
    """(parameters, state) of the compiled turbulence (TB_*, TBS_*) from its oracle
    (flight/turbulence.DrydenTurbulence); its noise is turb.nu."""
    par = [turb.w20_fps, turb.dt, turb.cos_fps, turb.sin_fps, *tables.POE_ALT_FT, *tables.POE_SIGMA_FPS[turb.index - 1]]
    return np.array(par, dtype=float), np.array(turb.state(), dtype=float)


def monitor_arrays(mon: Any) -> tuple[Array, Array, Array]:
    """(parameters, state, windows) of the compiled stabilized-approach monitor (MN_*, MNS_*, the ring buffer)
    from its oracle (flight/envelope.StabilityMonitor)."""
    par = [mon.tan_gp, math.tan(mon.gs_dot_rad), mon.x_gp_m, mon.x_floor_m, math.tan(mon.loc_dot_rad), mon.tch_m,
           mon.target_mps, float(mon.n), float(mon.m), *mon.curvature]
    return np.array(par, dtype=float), np.array(mon.state(), dtype=float), np.array(mon.windows(), dtype=float)


def flight_vectors(const: Array, ap: Any, mon: Any, turb: Any | None, terrain_along_m: Array,
                   terrain_height_m: Array, *, pitch_trim: float, stop_height_m: float, land: bool,
                   monitor_floor_m: float, wind_ned_mps: tuple[float, float], wind: Any | None = None,
                   jsbsim_wind_ned_mps: tuple[float, float] = (0.0, 0.0), gear_x_m: float = 0.0,
                   divergence_m: tuple[float, float] = (fk.DIVERGED_VERTICAL_M, fk.DIVERGED_LATERAL_M)
                   ) -> tuple[Array, Array]:
    """fly_step's (par, st) for one flight: the IMU-point constants (imu_point_constants), the autopilot, monitor
    and turbulence (None: calm air) of the run (their oracles, fresh), the terrain profile (along-track distances
    and heights, m), the trimmed pitch trim (the elevator column of the Truth controls adds it), the stop height
    above the threshold (m; -inf: none), landing run (flare, touchdown), the height above the threshold the
    monitor stops at (m) and the steady wind (north, east, m/s; the air moves with it). wind: the profile's
    environment when its mean wind varies with height (flight/wind.py; None: it does not), then
    jsbsim_wind_ned_mps is JSBSim's steady wind (the mean wind at the start) and wind_ned_mps the reference wind;
    gear_x_m: the main gear's distance behind the IMU along the runway (landing runs: the terrain under it);
    divergence_m: the termination's limits on the distance from the glide path and from the centreline, m
    (inf: none, while a lead-in's own guidance checks its path, flight/path.py)."""
    ap_par, ap_st = autopilot_arrays(ap)
    mn_par, mn_st, ring = monitor_arrays(mon)
    if turb is not None:
        tb_par, tb_st = dryden_arrays(turb)
    else:
        tb_par, tb_st = np.zeros(layouts.N_TB_PAR), np.zeros(layouts.N_TB_STATE)
    fpar = np.zeros(layouts.N_F_PAR)
    fpar[layouts.F_PITCH_TRIM], fpar[layouts.F_STOP_H], fpar[layouts.F_LAND] = pitch_trim, stop_height_m, float(land)
    fpar[layouts.F_TAN_GP], fpar[layouts.F_TCH] = ap.tan_gp, ap.tch_m
    fpar[layouts.F_X_GPI], fpar[layouts.F_CA] = ap.x_gpi_m, ap.cone_a
    fpar[layouts.F_CB], fpar[layouts.F_CC] = ap.cone_b, ap.cone_c
    fpar[layouts.F_MON_FLOOR] = monitor_floor_m
    fpar[layouts.F_WIND_N], fpar[layouts.F_WIND_E] = wind_ned_mps[0], wind_ned_mps[1]
    fpar[layouts.F_TURBULENT] = float(turb is not None)
    fpar[layouts.F_GEAR_X] = gear_x_m
    fpar[layouts.F_DIV_VERT], fpar[layouts.F_DIV_LAT] = divergence_m
    fpar[layouts.F_SHEAR_TOP], fpar[layouts.F_SHEAR_BOTTOM] = -math.inf, -math.inf  # no shear: never in force
    if wind is not None:
        fpar[layouts.F_WIND_VARIES] = 1.0
        fpar[layouts.F_WIND_LOG] = float(wind.wind_profile == "log")
        fpar[layouts.F_WIND_Z0], fpar[layouts.F_WIND_REF] = wind.roughness_length_m, wind.wind_reference_height_m
        fpar[layouts.F_WIND0_N], fpar[layouts.F_WIND0_E] = jsbsim_wind_ned_mps
        if wind.shear_n_mps != 0.0 or wind.shear_e_mps != 0.0:
            fpar[layouts.F_SHEAR_TOP], fpar[layouts.F_SHEAR_BOTTOM] = wind.shear_top_m, wind.shear_bottom_m
            fpar[layouts.F_SHEAR_N], fpar[layouts.F_SHEAR_E] = wind.shear_n_mps, wind.shear_e_mps
    fpar[layouts.F_N_TERRAIN] = len(terrain_along_m)
    fst = np.zeros(layouts.N_F_STATE)
    fst[layouts.FS_THR] = ap.trim.throttle  # the trimmed controls are in force at row 0
    fst[layouts.FS_LOWEST] = math.inf
    fst[layouts.FS_TD_X] = fst[layouts.FS_TD_SINK] = math.nan
    fst[layouts.FS_WIND_N], fst[layouts.FS_WIND_E] = (jsbsim_wind_ned_mps if wind is not None else wind_ned_mps)
    par = np.concatenate([np.asarray(const, dtype=float), fpar, ap_par, tb_par, mn_par,
                          np.asarray(terrain_along_m, dtype=float), np.asarray(terrain_height_m, dtype=float)])
    st = np.concatenate([fst, ap_st, tb_st, mn_st, ring])
    return par, st

