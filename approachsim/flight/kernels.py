"""The flight loop's per-step truth kinematics as a compiled kernel (numba, cache=True) and its numpy oracle.

JSBSim integrates the centre of gravity; the Truth record is of the IMU point (aircraft file [imu]). Per step,
from the JSBSim-read scalars (in JSBSim's units, the order of RAW_FIELDS), `imu_point_row` writes one Truth row:

    position  p_imu = p_cg + C_nb l  (geodetic offset, then ECEF and the runway frame)
    velocity  v_imu = v_cg + C_nb (w_eb x l), resolved on the IMU point's own NED axes (turned by
              t = (dE / (R_E + h), -dN / (R_N + h), -dE tan L / (R_E + h)) from the CG's)
    specific  f_imu = F/m + (R (w1 x l) - w x l) / dt            lever arm over JSBSim's rectangular-Euler step
    force           + GM/r^3 (l - 3 d_D C_nb' e_D)               gravitation gradient over the lever arm
                    + C_nb' GM/r^3 dt/2 (v_i - 3 u (u . v_i))    gravitation of the step start vs its midpoint
              then its body-axis mean over the step's rotation phi = w dt: f - c1 phi x f + c2 phi x (phi x f)
    pressure  p_imu = p_cg exp(d_D g0 / (R_air T))               hydrostatic over the CG-to-IMU height
    attitude  roll, pitch, heading of the IMU point's NED axes and its body-to-NED quaternion

(docs/truth.md and flight/run.py's module docstring say why each term is there.) The kernel is a plain function
of arrays so that it is testable without JSBSim (tests/unit/flight/test_flight_kernels.py: kernel = the vectorized
numpy `imu_point_rows_reference` to 1e-12 relative). The flight loop calls it as

    const = imu_point_constants(lever_arm_m, lat0_rad, profile.runway, dt_s)     # once per flight
    raw[:] = [gv() for gv in getters]                                              # RAW_FIELDS, JSBSim units
    terr = imu_point_row(raw, const, terrain_along_m, terrain_height_m, k * dt_s, buf[k])

which fills columns 0-30 and 35 of flight/run.py's (n, 36) row buffer (_COLS) and returns the terrain height
under the IMU (m); the controls (columns 31-34) stay the caller's.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from approachsim import geo, units
from approachsim.nav.kernels import geodesy as gk

Array = np.ndarray

RAW_FIELDS = (
    "position/lat-geod-rad", "position/long-gc-rad", "position/geod-alt-ft",
    "velocities/v-north-fps", "velocities/v-east-fps", "velocities/v-down-fps",
    "attitude/phi-rad", "attitude/theta-rad", "attitude/psi-rad",
    "velocities/pi-rad_sec", "velocities/qi-rad_sec", "velocities/ri-rad_sec",
    "velocities/p-rad_sec", "velocities/q-rad_sec", "velocities/r-rad_sec",
    "accelerations/pidot-rad_sec2", "accelerations/qidot-rad_sec2", "accelerations/ridot-rad_sec2",
    "forces/fbx-total-lbs", "forces/fby-total-lbs", "forces/fbz-total-lbs", "inertia/mass-slugs",
    "atmosphere/P-psf", "atmosphere/T-R", "velocities/vc-kts", "aero/beta-rad",
    "velocities/vtrue-fps",
)
"""The JSBSim properties `imu_point_row` reads, in the order of its `raw` (27,) input (flight/run.py's _READ)."""

R_AIR = 287.05287
"""Specific gas constant of dry air, J/(kg K) (US Standard Atmosphere 1976, JSBSim's Rdry)."""

_FT, _FPS, _KT, _PSF = units.FT, units.FPS, units.KT, units.PSF
_LBF_PER_SLUG = units.LBF / units.SLUG
_G0_OVER_R = units.G0 / R_AIR
_GM = geo.GM_JSBSIM
_OMEGA = geo.OMEGA_JSBSIM
_RANKINE = 1.8
_TWO_PI = 2.0 * math.pi

N_CONST = 18


def imu_point_constants(lever_arm_m: Array, lat0_rad: float, runway: Any, dt_s: float) -> Array:
    """The kernel's constants (18,): lever arm l (body axes, m; CG to IMU), the radii R_N, R_E (m) at lat0_rad
    (held over the approach, as flight/run.py does), the runway frame's ECEF origin (m) and the first two rows
    of its ECEF-to-runway matrix, threshold height (m), tan(glidepath), TCH (m) and the step dt_s (s).

    runway: the profile's runway (profile.Runway: .frame, .elevation_m, .glidepath_rad, .tch_m)."""
    r_n, r_e = geo.radii(lat0_rad)
    frame = runway.frame
    c = frame.c_ecef_to_rwy
    return np.array([*np.asarray(lever_arm_m, dtype=float), float(r_n), float(r_e), *frame.origin_ecef,
                     *c[0], *c[1], runway.elevation_m, math.tan(runway.glidepath_rad), runway.tch_m, dt_s],
                    dtype=float)


@njit(cache=True)
def imu_point_row(raw: Array, const: Array, along_m: Array, height_m: Array, t_s: float, out: Array) -> float:
    """Truth row of the IMU point at time t_s from one step's JSBSim reads; writes out[0:31] and out[35]
    (flight/run.py's _COLS) and returns the terrain height (m) under the IMU point (np.interp of along_m,
    height_m at the runway-frame x; height_m[0] when the terrain has one point)."""
    lat, lon, h_ft = raw[0], raw[1], raw[2]
    vn_f, ve_f, vd_f = raw[3], raw[4], raw[5]
    phi, th, psi = raw[6], raw[7], raw[8]
    pi_, qi, ri = raw[9], raw[10], raw[11]
    p, q, r = raw[12], raw[13], raw[14]
    pid, qid, rid = raw[15], raw[16], raw[17]
    fx, fy, fz, m = raw[18], raw[19], raw[20], raw[21]
    p_psf, t_r, vc_kt = raw[22], raw[23], raw[24]
    lx, ly, lz, r_n, r_e = const[0], const[1], const[2], const[3], const[4]
    ox, oy, oz = const[5], const[6], const[7]
    c00, c01, c02, c10, c11, c12 = const[8], const[9], const[10], const[11], const[12], const[13]
    h_thr, tan_gp, tch, dt = const[14], const[15], const[16], const[17]
    hdt = 0.5 * dt
    h = h_ft * _FT
    # body -> NED direction cosines from the Euler angles
    sf, cf, st, ct, sp, cp = math.sin(phi), math.cos(phi), math.sin(th), math.cos(th), math.sin(psi), math.cos(psi)
    n00, n01, n02 = ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp
    n10, n11, n12 = ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp
    n20, n21, n22 = -st, sf * ct, cf * ct
    # lever-arm terms: w_eb x l (velocity); w x l with the inertial rate (specific force)
    ux, uy, uz = q * lz - r * ly, r * lx - p * lz, p * ly - q * lx
    wx, wy, wz = qi * lz - ri * ly, ri * lx - pi_ * lz, pi_ * ly - qi * lx
    s = _LBF_PER_SLUG / m
    # (R (w1 x l) - w x l) / dt, w1 = w + dt w', R the step's body rotation (q(+) = normalize(q (1, dt w / 2)))
    ex, ey, ez = hdt * pi_, hdt * qi, hdt * ri
    ux1, uy1, uz1 = pi_ + dt * pid, qi + dt * qid, ri + dt * rid
    ax, ay, az = uy1 * lz - uz1 * ly, uz1 * lx - ux1 * lz, ux1 * ly - uy1 * lx  # w1 x l
    bx, by, bz = ey * az - ez * ay, ez * ax - ex * az, ex * ay - ey * ax  # e x (w1 x l)
    k2 = 2.0 / (1.0 + ex * ex + ey * ey + ez * ez)
    fbx = fx * s + (ax + k2 * (bx + ey * bz - ez * by) - wx) / dt
    fby = fy * s + (ay + k2 * (by + ez * bx - ex * bz) - wy) / dt
    fbz = fz * s + (az + k2 * (bz + ex * by - ey * bx) - wz) / dt
    vn = vn_f * _FPS + n00 * ux + n01 * uy + n02 * uz
    ve = ve_f * _FPS + n10 * ux + n11 * uy + n12 * uz
    vd = vd_f * _FPS + n20 * ux + n21 * uy + n22 * uz
    # IMU position: geodetic offset of C_nb l, then ECEF and runway frame
    dn = n00 * lx + n01 * ly + n02 * lz
    de = n10 * lx + n11 * ly + n12 * lz
    dd = n20 * lx + n21 * ly + n22 * lz
    lat_i = lat + dn / (r_n + h)
    lon_i = lon + de / ((r_e + h) * math.cos(lat))
    h_i = h - dd
    x_e, y_e, z_e = gk.geodetic_to_ecef(lat_i, lon_i, h_i)
    # gravitation gradient over the lever arm, GM/r^3 (l - 3 d_D C_nb' e_D) (J2 part < 1e-8 m/s^2)
    kg = _GM / (x_e * x_e + y_e * y_e + z_e * z_e) ** 1.5
    fbx += kg * (lx - 3.0 * dd * n20)
    fby += kg * (ly - 3.0 * dd * n21)
    fbz += kg * (lz - 3.0 * dd * n22)
    # gravitation of the step start vs its midpoint along the inertial velocity v_i = v + W x r
    kv = kg * hdt
    gn_, ge_, gd_ = kv * vn, kv * (ve + _OMEGA * math.sqrt(x_e * x_e + y_e * y_e)), -2.0 * kv * vd
    fbx += n00 * gn_ + n10 * ge_ + n20 * gd_
    fby += n01 * gn_ + n11 * ge_ + n21 * gd_
    fbz += n02 * gn_ + n12 * ge_ + n22 * gd_
    # body-axis mean over the step's rotation phi = w dt: f - c1 phi x f + c2 phi x (phi x f) (series)
    px, py, pz = 2.0 * ex, 2.0 * ey, 2.0 * ez
    a2 = px * px + py * py + pz * pz
    c1, c2 = 0.5 - a2 / 24.0, 1.0 / 6.0 - a2 / 120.0
    qx, qy, qz = py * fbz - pz * fby, pz * fbx - px * fbz, px * fby - py * fbx  # phi x f
    fbx, fby, fbz = (fbx - c1 * qx + c2 * (py * qz - pz * qy), fby - c1 * qy + c2 * (pz * qx - px * qz),
                     fbz - c1 * qz + c2 * (px * qy - py * qx))
    # the IMU point's own NED axes, x_imu = (I - [t x]) x_cg
    ta, tb, tc = de / (r_e + h), -dn / (r_n + h), -de * math.tan(lat) / (r_e + h)
    vn, ve, vd = vn - tb * vd + tc * ve, ve - tc * vn + ta * vd, vd - ta * ve + tb * vn
    m00, m10, m20 = n00 - tb * n20 + tc * n10, n10 - tc * n00 + ta * n20, n20 - ta * n10 + tb * n00
    m21, m22 = n21 - ta * n11 + tb * n01, n22 - ta * n12 + tb * n02
    phi_i = math.atan2(m21, m22)
    th_i = -math.asin(m20)
    dpsi = math.atan2(m10, m00) - psi
    psi_i = psi + (dpsi - _TWO_PI * np.rint(dpsi / _TWO_PI))  # psi + remainder(dpsi, 2 pi)
    # static pressure at the IMU point, hydrostatic over the CG-to-IMU height difference
    p_imu = p_psf * _PSF * math.exp(dd * _G0_OVER_R / (t_r / _RANKINE))
    dx, dy, dz = x_e - ox, y_e - oy, z_e - oz
    xr = c00 * dx + c01 * dy + c02 * dz
    yr = c10 * dx + c11 * dy + c12 * dz
    zr = h_i - h_thr
    terr = height_m[0] if height_m.shape[0] == 1 else np.interp(xr, along_m, height_m)
    # body -> NED quaternion (scalar first) from the IMU point's Euler angles
    s1, k1 = math.sin(0.5 * phi_i), math.cos(0.5 * phi_i)
    s2, k2_ = math.sin(0.5 * th_i), math.cos(0.5 * th_i)
    s3, k3 = math.sin(0.5 * psi_i), math.cos(0.5 * psi_i)
    out[0], out[1], out[2], out[3] = t_s, lat_i, lon_i, h_i
    out[4], out[5], out[6] = x_e, y_e, z_e
    out[7], out[8], out[9] = vn, ve, vd
    out[10] = k1 * k2_ * k3 + s1 * s2 * s3
    out[11] = s1 * k2_ * k3 - k1 * s2 * s3
    out[12] = k1 * s2 * k3 + s1 * k2_ * s3
    out[13] = k1 * k2_ * s3 - s1 * s2 * k3
    out[14], out[15], out[16] = phi_i, th_i, psi_i
    out[17], out[18], out[19] = pi_, qi, ri
    out[20], out[21], out[22] = fbx, fby, fbz
    out[23], out[24], out[25] = p_imu, t_r / _RANKINE, h_i - terr
    out[26], out[27], out[28] = xr, yr, zr
    out[29], out[30] = zr - (tch - xr * tan_gp), yr
    out[35] = vc_kt * _KT
    return terr


def _cross(a: Array, b: Array) -> Array:
    return np.cross(a, b)


def imu_point_rows_reference(raw: Array, const: Array, along_m: Array, height_m: Array, t_s: Array) -> Array:
    """`imu_point_row` for many steps at once in vectorized numpy (the kernel's test oracle): raw (n, 27) in
    RAW_FIELDS order, t_s (n,); returns (n, 36) rows with columns 0-30 and 35 filled (NaN elsewhere).

    Written with matrices and np.cross rather than the kernel's scalar expressions, so that it checks them."""
    raw = np.atleast_2d(np.asarray(raw, dtype=float))
    n = raw.shape[0]
    lev = const[0:3]
    r_n, r_e = const[3], const[4]
    origin = const[5:8]
    c_rwy2 = np.stack([const[8:11], const[11:14]])
    h_thr, tan_gp, tch, dt = const[14], const[15], const[16], const[17]
    lat, lon, h = raw[:, 0], raw[:, 1], raw[:, 2] * _FT
    v_cg = raw[:, 3:6] * _FPS
    eul = raw[:, 6:9]
    w_ib, w_eb, w_dot = raw[:, 9:12], raw[:, 12:15], raw[:, 15:18]
    f_cg = raw[:, 18:21] * (_LBF_PER_SLUG / raw[:, 21:22])
    cr, sr = np.cos(eul[:, 0]), np.sin(eul[:, 0])
    cp, sp = np.cos(eul[:, 1]), np.sin(eul[:, 1])
    cy, sy = np.cos(eul[:, 2]), np.sin(eul[:, 2])
    c_nb = np.stack([np.stack([cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy], -1),
                     np.stack([cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy], -1),
                     np.stack([-sp, sr * cp, cr * cp], -1)], -2)  # body -> NED, (n, 3, 3)
    l_b = np.broadcast_to(lev, (n, 3))
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
    kg = _GM / np.sum(r * r, axis=1) ** 1.5
    f = f + kg[:, None] * (l_b - 3.0 * d[:, 2:3] * c_nb[:, 2, :])
    g_ned = (kg * 0.5 * dt)[:, None] * np.stack(
        [v[:, 0], v[:, 1] + _OMEGA * np.hypot(r[:, 0], r[:, 1]), -2.0 * v[:, 2]], axis=1)
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
    p_imu = raw[:, 22] * _PSF * np.exp(d[:, 2] * _G0_OVER_R / (raw[:, 23] / _RANKINE))
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
    out[:, 23], out[:, 24], out[:, 25] = p_imu, raw[:, 23] / _RANKINE, h_i - terr
    out[:, 26], out[:, 27], out[:, 28] = xy[:, 0], xy[:, 1], zr
    out[:, 29], out[:, 30] = zr - (tch - xy[:, 0] * tan_gp), xy[:, 1]
    out[:, 35] = raw[:, 24] * _KT
    return out
