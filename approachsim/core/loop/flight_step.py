"""The flight loop's per-step work as compiled kernels (numba, cache=True): one call per JSBSim step does all that
is not a JSBSim read or write. Each piece has a readable oracle it is tested against (tests/unit/flight/).

The truth row. JSBSim integrates the centre of gravity; the Truth record is of the IMU point (aircraft file
[imu]). Per step, from the JSBSim-read scalars (in JSBSim's units, the order of RAW_FIELDS), `imu_point_row`
writes one Truth row:

    rates     w_eb = w_ib - C_nb' w_ie(L)                         JSBSim's p, q, r (earth_rates_reference)
    position  p_imu = p_cg + C_nb l  (geodetic offset, then ECEF and the runway frame)
    velocity  v_imu = v_cg + C_nb (w_eb x l), resolved on the IMU point's own NED axes (turned by
              t = (dE / (R_E + h), -dN / (R_N + h), -dE tan L / (R_E + h)) from the CG's)
    specific  f_imu = F/m + (R (w1 x l) - w x l) / dt            lever arm over JSBSim's rectangular-Euler step
    force           + GM/r^3 (l - 3 d_D C_nb' e_D)               gravitation gradient over the lever arm
                    + C_nb' GM/r^3 dt/2 (v_i - 3 u (u . v_i))    gravitation of the step start vs its midpoint
              then its body-axis mean over the step's rotation phi = w dt: f - c1 phi x f + c2 phi x (phi x f)
    pressure  p_imu = p_cg exp(d_D g0 / (R_air T))               hydrostatic over the CG-to-IMU height
    attitude  roll, pitch, heading of the IMU point's NED axes and its body-to-NED quaternion

(docs/truth.md and flight/run.py's module docstring say why each term is there; oracle: the vectorized numpy
`imu_point_rows_reference`, to 1e-12 relative.)

The rest of the step: `dryden_step` (oracle flight/turbulence.DrydenTurbulence), `autopilot_step`
(flight/autopilot.Autopilot), `monitor_step` (flight/envelope.StabilityMonitor), `termination`, composed by
`fly_step` (and `fly_control`, the autopilot on a navigation source's guidance). Parameters and state are plain
float vectors built from the oracles (flight_vectors); flight/run.py calls

    par, st = flight_vectors(imu_point_constants(...), autopilot, monitor, turbulence, terrain..., ...)  # per run
    code, de, da, dr, thr, gust_n, gust_e, gust_d, terrain_ft, read_gear = fly_step(k, reads, buf, nu, par, st, guided)

which fills row k of flight/run.py's (n, 36) row buffer (_COLS; the controls in columns 31-34).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from approachsim import geo, units
from approachsim.core import geodesy as gk
from approachsim.core.jit import njit
from approachsim.core.layouts import (
    AP_ALIGN_BANK_MAX,
    AP_ALIGN_BETA_MAX,
    AP_ALIGN_CAS,
    AP_ALIGN_H,
    AP_ALIGN_TAU,
    AP_BANK_LIMIT,
    AP_CAS0,
    AP_CH,
    AP_CLIMB_MAX,
    AP_CONE_A,
    AP_CONE_B,
    AP_CONE_C,
    AP_CONV,
    AP_DT,
    AP_FLARE_GE_ARP,
    AP_FLARE_GE_DECAY,
    AP_FLARE_GE_K,
    AP_FLARE_H,
    AP_FLARE_K_GUST,
    AP_FLARE_K_V,
    AP_FLARE_PITCH_MIN,
    AP_FLARE_PITCH_MIN_H,
    AP_FLARE_T_PATH,
    AP_GEAR_ARM,
    AP_HEADING,
    AP_K_BETA,
    AP_K_BETA_ALIGN,
    AP_K_DA_ALIGN,
    AP_K_FLARE,
    AP_K_FLARE_I,
    AP_K_GS_D,
    AP_K_GS_I,
    AP_K_GS_P,
    AP_K_LOC_D,
    AP_K_LOC_I,
    AP_K_LOC_P,
    AP_K_P,
    AP_K_PD,
    AP_K_PHI,
    AP_K_PHI_ALIGN,
    AP_K_PI,
    AP_K_Q,
    AP_K_R_ALIGN,
    AP_K_TD,
    AP_K_THETA,
    AP_K_THR,
    AP_K_TI,
    AP_K_V_I,
    AP_K_V_P,
    AP_PITCH_LIMIT,
    AP_RATE_TAU,
    AP_RETARD_H,
    AP_SEB_FF,
    AP_SH,
    AP_SINK_MAX,
    AP_SPD_W,
    AP_T_H,
    AP_T_V,
    AP_TAN_GP,
    AP_TAU_V,
    AP_TAU_WIND,
    AP_TD_SINK,
    AP_TECS,
    AP_THETA0,
    AP_THR0,
    AP_VERT_ACC,
    AP_X_GPI,
    APS_ALIGNING,
    APS_E_F,
    APS_FLARE_H_OFF,
    APS_FLARE_SINK0,
    APS_FLARE_TAU,
    APS_FLARE_V0,
    APS_FLARING,
    APS_INT_B,
    APS_INT_D,
    APS_INT_E,
    APS_INT_FLARE,
    APS_INT_T,
    APS_INT_Y,
    APS_SURFACE_SLOPE,
    APS_THETA_C,
    APS_THETA_FLARE0,
    APS_V_LAG,
    APS_WIND,
    C_CA,
    C_CB,
    C_CC,
    C_DT,
    C_HTHR,
    C_LEVER,
    C_ORIGIN,
    C_RE,
    C_RN,
    C_RWY,
    C_TAN_GP,
    C_X_GPI,
    CONTROLS_COL,
    F_CA,
    F_CB,
    F_CC,
    F_DIV_LAT,
    F_DIV_VERT,
    F_GEAR_X,
    F_LAND,
    F_MON_FLOOR,
    F_N_TERRAIN,
    F_PITCH_TRIM,
    F_SHEAR_BOTTOM,
    F_SHEAR_E,
    F_SHEAR_N,
    F_SHEAR_TOP,
    F_STOP_H,
    F_TAN_GP,
    F_TURBULENT,
    F_WIND0_E,
    F_WIND0_N,
    F_WIND_E,
    F_WIND_LOG,
    F_WIND_N,
    F_WIND_REF,
    F_WIND_VARIES,
    F_WIND_Z0,
    F_X_GPI,
    FS_BETA,
    FS_CAS,
    FS_DA,
    FS_DE,
    FS_DR,
    FS_H_GEAR,
    FS_LOWEST,
    FS_MON,
    FS_MON_A,
    FS_MON_B,
    FS_MON_Z,
    FS_P,
    FS_PHI,
    FS_PSI,
    FS_Q,
    FS_R,
    FS_TAS,
    FS_TD_SINK,
    FS_TD_X,
    FS_THETA,
    FS_THR,
    FS_WIND_E,
    FS_WIND_N,
    GEAR_AIRBORNE,
    MN_CA,
    MN_CB,
    MN_CC,
    MN_GS_DOT_TAN,
    MN_LOC_DOT_TAN,
    MN_M,
    MN_N,
    MN_TAN_GP,
    MN_TARGET,
    MN_X_FLOOR,
    MN_X_GP,
    MNS_COUNT,
    MNS_I,
    MNS_J,
    MNS_SUM_CAS,
    MNS_SUM_EXCESS,
    MNS_SUM_SINK,
    N_AP_PAR,
    N_AP_STATE,
    N_CONST,
    N_F_PAR,
    N_F_STATE,
    N_MN_PAR,
    N_MN_STATE,
    N_POE,
    N_TB_PAR,
    N_TB_STATE,
    P_AP,
    P_IMU,
    P_MN,
    P_STEP,
    P_TB,
    P_TERRAIN,
    R_BETA,
    R_FX,
    R_FY,
    R_FZ,
    R_GEAR_LEFT_FT,
    R_GEAR_RIGHT_FT,
    R_H_FT,
    R_LAT,
    R_LON,
    R_MASS,
    R_P,
    R_PHI,
    R_PI,
    R_PID,
    R_PSI,
    R_QI,
    R_QID,
    R_RI,
    R_RID,
    R_T,
    R_THETA,
    R_VC,
    R_VD,
    R_VE,
    R_VN,
    R_VT,
    R_WOW_LEFT,
    R_WOW_NOSE,
    R_WOW_RIGHT,
    ROW_AIRSPEED,
    ROW_EULER,
    ROW_F_BODY,
    ROW_GS_DEV,
    ROW_H,
    ROW_H_AGL,
    ROW_LAT,
    ROW_LOC_DEV,
    ROW_LON,
    ROW_P_STATIC,
    ROW_Q_NB,
    ROW_R_ECEF,
    ROW_R_RWY,
    ROW_T,
    ROW_T_AIR,
    ROW_V_NED,
    ROW_W_IB,
    S_AP,
    S_MN,
    S_RING,
    S_STEP,
    S_TB,
    TB_ALT,
    TB_COS,
    TB_DT,
    TB_SIGMA,
    TB_SIN,
    TB_W20,
    TBS_AU,
    TBS_AV,
    TBS_AW,
    TBS_BU,
    TBS_BV,
    TBS_BW,
    TBS_VALID,
    TBS_XI_U,
    TBS_XI_V,
    TBS_XI_W,
)
from approachsim.core.tables import (
    COEFF_EVERY,
    LOC_ANTENNA_PAST_THRESHOLD_M,
    SINK_LIMIT_MPS,
    SINK_TOLERANCE_MPS,
    SPEED_HIGH_MPS,
    SPEED_LOW_MPS,
    STABILIZATION_HEIGHT_M,
    WATCH_HEIGHT_M,
)

Array = np.ndarray

R_AIR = 287.05287
"""Specific gas constant of dry air, J/(kg K) (US Standard Atmosphere 1976, JSBSim's Rdry)."""

_FT, _FPS, _KT, _PSF = units.FT, units.FPS, units.KT, units.PSF
LBF_PER_SLUG = units.LBF / units.SLUG
_G0 = units.G0
G0_OVER_R_AIR = units.G0 / R_AIR
GM_JSBSIM = geo.GM_JSBSIM
OMEGA_JSBSIM = geo.OMEGA_JSBSIM
RANKINE_PER_K = 1.8
_TWO_PI = 2.0 * math.pi

MON_OK, MON_GLIDEPATH, MON_LOCALIZER, MON_SPEED, MON_SINK = range(5)
"""Results of one monitor step: stabilized, or which criterion failed (`monitor_step` returns these with two
figures, flight/envelope.py `unstabilized_reason` words them)."""




@njit(cache=True)
def cone_deviation(x: float, y: float, z: float, x_dot: float, y_dot: float, z_dot: float, tan_gp: float,
                   x_gpi: float, a: float, b: float, c: float) -> tuple[float, float]:
    """Glidepath deviation from the straight cone (m, + above) and its rate (m/s) of a runway-frame point (x, y,
    z) moving at (x', y', z'): approachsim.glidepath's z - z_cone(x, y), z_cone = tan(gp) r + a dx^2 + b dx y +
    c y^2, dx = x - x_gpi, r = sqrt(dx^2 + y^2) before the GPI (-r past it); its oracle is
    glidepath.GlidePath.deviation_m (tests/unit/flight/test_flight_kernels.py)."""
    dx = x - x_gpi
    r = math.sqrt(dx * dx + y * y)
    s = 1.0 if dx <= 0.0 else -1.0
    d = z - (s * tan_gp * r + a * dx * dx + b * dx * y + c * y * y)
    if r > 0.0:
        drx, dry = s * tan_gp * dx / r, s * tan_gp * y / r
    else:
        drx, dry = -tan_gp, 0.0
    d_dot = z_dot - (drx + 2.0 * a * dx + b * y) * x_dot - (dry + b * dx + 2.0 * c * y) * y_dot
    return d, d_dot


@njit(cache=True)
def imu_point_row(raw: Array, const: Array, along_m: Array, height_m: Array, t_s: float, out: Array) -> float:
    """Truth row of the IMU point at time t_s from one step's JSBSim reads; writes out[0:31] and out[35]
    (flight/run.py's _COLS) and returns the terrain height (m) under the IMU point (np.interp of along_m,
    height_m at the runway-frame x; height_m[0] when the terrain has one point). raw: an array or a tuple."""
    return _imu_point(raw, const, along_m, height_m, t_s, out)[0]


@njit(cache=True)
def _imu_point(raw: Any, const: Array, along_m: Array, height_m: Array, t_s: float,
               out: Array) -> tuple[float, float, float, float]:
    """imu_point_row, returning (terrain height (m), the CG's Earth-relative body rates p, q, r (rad/s))."""
    lat, lon, h_ft = raw[R_LAT], raw[R_LON], raw[R_H_FT]
    vn_f, ve_f, vd_f = raw[R_VN], raw[R_VE], raw[R_VD]
    phi, th, psi = raw[R_PHI], raw[R_THETA], raw[R_PSI]
    pi_, qi, ri = raw[R_PI], raw[R_QI], raw[R_RI]
    pid, qid, rid = raw[R_PID], raw[R_QID], raw[R_RID]
    fx, fy, fz, m = raw[R_FX], raw[R_FY], raw[R_FZ], raw[R_MASS]
    p_psf, t_r, vc_kt = raw[R_P], raw[R_T], raw[R_VC]
    lx, ly, lz, r_n, r_e = const[C_LEVER], const[C_LEVER + 1], const[C_LEVER + 2], const[C_RN], const[C_RE]
    ox, oy, oz = const[C_ORIGIN], const[C_ORIGIN + 1], const[C_ORIGIN + 2]
    c00, c01, c02 = const[C_RWY], const[C_RWY + 1], const[C_RWY + 2]
    c10, c11, c12 = const[C_RWY + 3], const[C_RWY + 4], const[C_RWY + 5]
    h_thr, tan_gp, dt = const[C_HTHR], const[C_TAN_GP], const[C_DT]
    hdt = 0.5 * dt
    h = h_ft * _FT
    # body -> NED direction cosines from the Euler angles
    sf, cf, st, ct, sp, cp = math.sin(phi), math.cos(phi), math.sin(th), math.cos(th), math.sin(psi), math.cos(psi)
    n00, n01, n02 = ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp
    n10, n11, n12 = ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp
    n20, n21, n22 = -st, sf * ct, cf * ct
    # Earth-relative body rates w_eb = w_ib - C_nb' w_ie (earth_rates)
    s_lat, c_lat = math.sin(lat), math.cos(lat)
    wn_e, wd_e = OMEGA_JSBSIM * c_lat, -OMEGA_JSBSIM * s_lat
    p, q, r = pi_ - (n00 * wn_e + n20 * wd_e), qi - (n01 * wn_e + n21 * wd_e), ri - (n02 * wn_e + n22 * wd_e)
    # lever-arm terms: w_eb x l (velocity); w x l with the inertial rate (specific force)
    ux, uy, uz = q * lz - r * ly, r * lx - p * lz, p * ly - q * lx
    wx, wy, wz = qi * lz - ri * ly, ri * lx - pi_ * lz, pi_ * ly - qi * lx
    s = LBF_PER_SLUG / m
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
    lon_i = lon + de / ((r_e + h) * c_lat)
    h_i = h - dd
    x_e, y_e, z_e = gk.geodetic_to_ecef(lat_i, lon_i, h_i)
    # gravitation gradient over the lever arm, GM/r^3 (l - 3 d_D C_nb' e_D) (J2 part < 1e-8 m/s^2)
    r2 = x_e * x_e + y_e * y_e + z_e * z_e
    kg = GM_JSBSIM / (r2 * math.sqrt(r2))
    fbx += kg * (lx - 3.0 * dd * n20)
    fby += kg * (ly - 3.0 * dd * n21)
    fbz += kg * (lz - 3.0 * dd * n22)
    # gravitation of the step start vs its midpoint along the inertial velocity v_i = v + W x r
    kv = kg * hdt
    gn_, ge_, gd_ = kv * vn, kv * (ve + OMEGA_JSBSIM * math.sqrt(x_e * x_e + y_e * y_e)), -2.0 * kv * vd
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
    ta, tb, tc = de / (r_e + h), -dn / (r_n + h), -de * (s_lat / c_lat) / (r_e + h)
    vn, ve, vd = vn - tb * vd + tc * ve, ve - tc * vn + ta * vd, vd - ta * ve + tb * vn
    m00, m10, m20 = n00 - tb * n20 + tc * n10, n10 - tc * n00 + ta * n20, n20 - ta * n10 + tb * n00
    m21, m22 = n21 - ta * n11 + tb * n01, n22 - ta * n12 + tb * n02
    phi_i = math.atan2(m21, m22)
    th_i = -math.asin(m20)
    dpsi = math.atan2(m10, m00) - psi
    psi_i = psi + (dpsi - _TWO_PI * np.rint(dpsi / _TWO_PI))  # psi + remainder(dpsi, 2 pi)
    # static pressure at the IMU point, hydrostatic over the CG-to-IMU height difference
    p_imu = p_psf * _PSF * math.exp(dd * G0_OVER_R_AIR / (t_r / RANKINE_PER_K))
    dx, dy, dz = x_e - ox, y_e - oy, z_e - oz
    xr = c00 * dx + c01 * dy + c02 * dz
    yr = c10 * dx + c11 * dy + c12 * dz
    zr = h_i - h_thr
    terr = height_m[0] if height_m.shape[0] == 1 else np.interp(xr, along_m, height_m)
    # body -> NED quaternion (scalar first) from the IMU point's Euler angles
    s1, k1 = math.sin(0.5 * phi_i), math.cos(0.5 * phi_i)
    s2, k2_ = math.sin(0.5 * th_i), math.cos(0.5 * th_i)
    s3, k3 = math.sin(0.5 * psi_i), math.cos(0.5 * psi_i)
    out[ROW_T], out[ROW_LAT], out[ROW_LON], out[ROW_H] = t_s, lat_i, lon_i, h_i
    out[ROW_R_ECEF], out[ROW_R_ECEF + 1], out[ROW_R_ECEF + 2] = x_e, y_e, z_e
    out[ROW_V_NED], out[ROW_V_NED + 1], out[ROW_V_NED + 2] = vn, ve, vd
    out[ROW_Q_NB] = k1 * k2_ * k3 + s1 * s2 * s3
    out[ROW_Q_NB + 1] = s1 * k2_ * k3 - k1 * s2 * s3
    out[ROW_Q_NB + 2] = k1 * s2 * k3 + s1 * k2_ * s3
    out[ROW_Q_NB + 3] = k1 * k2_ * s3 - s1 * s2 * k3
    out[ROW_EULER], out[ROW_EULER + 1], out[ROW_EULER + 2] = phi_i, th_i, psi_i
    out[ROW_W_IB], out[ROW_W_IB + 1], out[ROW_W_IB + 2] = pi_, qi, ri
    out[ROW_F_BODY], out[ROW_F_BODY + 1], out[ROW_F_BODY + 2] = fbx, fby, fbz
    out[ROW_P_STATIC], out[ROW_T_AIR], out[ROW_H_AGL] = p_imu, t_r / RANKINE_PER_K, h_i - terr
    out[ROW_R_RWY], out[ROW_R_RWY + 1], out[ROW_R_RWY + 2] = xr, yr, zr
    out[ROW_GS_DEV] = cone_deviation(xr, yr, zr, 0.0, 0.0, 0.0, tan_gp, const[C_X_GPI], const[C_CA], const[C_CB],
                                     const[C_CC])[0]
    out[ROW_LOC_DEV] = yr
    out[ROW_AIRSPEED] = vc_kt * _KT
    return terr, p, q, r


# --- the flight loop's per-step kernel: turbulence, autopilot, stabilized-approach monitor, termination -----------
# Parameters and state live in plain float vectors; the names below are their indices. Each component has its own
# small vectors (filled by its readable oracle: flight/turbulence.DrydenTurbulence, flight/autopilot.Autopilot,
# flight/envelope.StabilityMonitor, method kernel_arrays()), and `fly_step` gets them concatenated (offsets P_*,
# S_*), so one compiled call per step does everything that is not a JSBSim read or write.

LOW_READ_HEIGHT_M = 100.0
"""IMU height above the terrain below which the gear state counts (the gear hangs about 4 m below it): above it
`fly_step` takes the gear as GEAR_AIRBORNE, whatever it was given."""
GEAR_READ_MARGIN_M = 30.0
"""`fly_step` asks for the gear reads at the next step from LOW_READ_HEIGHT_M + this margin down, so that they are
there whenever the IMU is below LOW_READ_HEIGHT_M (at any vertical speed below margin / dt: 3600 m/s at 120 Hz)."""

TERM_NONE, TERM_STOP, TERM_TOUCHDOWN, TERM_SHORT, TERM_GROUND, TERM_DIVERGED, TERM_UNSTABLE = range(7)
"""`fly_step`'s termination codes (flight/run.termination_reason words them)."""
DIVERGED_BANK_RAD = 1.0
DIVERGED_VERTICAL_M = 300.0
DIVERGED_LATERAL_M = 1500.0
"""A run has diverged beyond these: bank, distance from the glidepath, from the centreline (the last two are the
default of the parameters F_DIV_VERT, F_DIV_LAT: a lead-in, flight/path.py, checks them against its own path)."""


@njit(cache=True)
def _clip1(u: float) -> float:
    return 1.0 if u > 1.0 else (-1.0 if u < -1.0 else u)


@njit(cache=True)
def _tecs(par: Array, st: Array, d: float, d_dot: float, h_dot: float, v: float) -> tuple[float, float]:
    """Total energy control (flight/autopilot.Autopilot._tecs, the oracle): pitch command and throttle."""
    dt = par[AP_DT]
    if st[APS_V_LAG] != st[APS_V_LAG]:
        st[APS_V_LAG] = v
    v_dot = (v - st[APS_V_LAG]) / par[AP_RATE_TAU]
    st[APS_V_LAG] += dt * v_dot
    v0 = max(v, 1.0)
    hd_gp = h_dot - d_dot
    hd_c = min(max(hd_gp - d / par[AP_T_H], -par[AP_SINK_MAX]), par[AP_CLIMB_MAX])
    a_lim = 0.5 * _G0 / par[AP_K_THR]
    vd_c = min(max((par[AP_CAS0] - v) / par[AP_T_V], -a_lim), a_lim)
    wk = min(max(par[AP_SPD_W], 0.0), 1.0)
    wp = min(max(2.0 - par[AP_SPD_W], 0.0), 1.0)
    e_h = (hd_c - h_dot) / v0
    e_v = (vd_c - v_dot) / _G0
    e_t = e_h + e_v
    e_b = wp * e_h - wk * e_v
    sp_h = (hd_c - hd_gp) / v0
    t_sp = sp_h + vd_c / _G0
    b_sp = wp * sp_h - wk * vd_c / _G0
    thr = par[AP_THR0] + par[AP_K_THR] * (t_sp + par[AP_K_TD] * e_t + par[AP_K_TI] * st[APS_INT_T])
    if 0.0 < thr < 1.0:
        st[APS_INT_T] += e_t * dt
    else:
        thr = 1.0 if thr >= 1.0 else 0.0
    th_off = par[AP_SEB_FF] * b_sp + par[AP_K_PD] * e_b + par[AP_K_PI] * st[APS_INT_B]
    lim = par[AP_PITCH_LIMIT]
    step_max = dt * par[AP_VERT_ACC] / v0
    prev = st[APS_THETA_C] - par[AP_THETA0]
    lo, hi = max(-lim, prev - step_max), min(lim, prev + step_max)
    if lo < th_off < hi:
        st[APS_INT_B] += e_b * dt
    else:
        th_off = hi if th_off >= hi else lo
    return par[AP_THETA0] + th_off, thr


@njit(cache=True)
def autopilot_step(par: Array, st: Array, guide: tuple, air: tuple) -> tuple[float, float, float, float]:
    """One autopilot step (flight/autopilot.Autopilot.step, the oracle, whose module docstring has the laws):
    guide = (x, y, z, vn, ve, vd), the guidance position (runway frame, m) and NED velocity (m/s); air = (phi,
    theta, p, q, beta, cas, h_gear, tas, psi, r), the aircraft's attitude (rad), body rates (rad/s), sideslip (rad),
    CAS (m/s), main-gear height (m; nan: no flare), TAS (m/s; nan: no speed complement), true heading (rad; nan:
    no decrab) and yaw rate (rad/s) -> elevator, aileron, rudder, throttle. par: AP_* parameters, st: APS_* state
    (updated)."""
    x, y, z, vn, ve, vd = guide
    phi, theta, p, q, beta, cas, h_gear, tas, psi, r = air
    dt = par[AP_DT]
    v_air = cas  # the smoothed true airspeed (the air-mass speed) when TAS is given
    if tas > 1.0:  # inertially smoothed speed
        gs = math.sqrt(vn * vn + ve * ve + vd * vd)
        if st[APS_WIND] != st[APS_WIND]:
            st[APS_WIND] = tas - gs
        st[APS_WIND] += dt / par[AP_TAU_WIND] * (tas - gs - st[APS_WIND])
        v_air = gs + st[APS_WIND]
        cas = cas * v_air / tas
    # glidepath (cone) and cross-track deviations, the runway axes turned by the meridian convergence
    ch, sh = par[AP_CH], par[AP_SH]
    conv = (x * sh + y * ch) * par[AP_CONV]
    x0 = vn * ch + ve * sh
    y0 = -vn * sh + ve * ch
    y_dot = y0 - conv * x0
    d, d_dot = cone_deviation(x, y, z, x0 + conv * y0, y_dot, -vd, par[AP_TAN_GP], par[AP_X_GPI], par[AP_CONE_A],
                              par[AP_CONE_B], par[AP_CONE_C])
    lim = par[AP_PITCH_LIMIT]
    if par[AP_TECS] != 0.0:
        theta_c, thr = _tecs(par, st, d, d_dot, -vd, cas)
    else:
        # glidepath -> pitch command (integral frozen while the command is limited)
        th_off = -(par[AP_K_GS_P] * d + par[AP_K_GS_D] * d_dot + par[AP_K_GS_I] * st[APS_INT_D])
        if -lim < th_off < lim:
            st[APS_INT_D] += d * dt
        else:
            th_off = lim if th_off > 0.0 else -lim
        theta_c = par[AP_THETA0] + th_off
        # autothrottle on the filtered speed error (integral frozen at saturation)
        st[APS_E_F] += dt / par[AP_TAU_V] * (par[AP_CAS0] - cas - st[APS_E_F])
        thr = par[AP_THR0] + par[AP_K_V_P] * st[APS_E_F] + par[AP_K_V_I] * st[APS_INT_E]
        if 0.0 < thr < 1.0:
            st[APS_INT_E] += st[APS_E_F] * dt
        else:
            thr = 1.0 if thr >= 1.0 else 0.0
    landing = h_gear == h_gear
    if landing and (st[APS_FLARING] != 0.0 or h_gear <= par[AP_FLARE_H]):
        # exponential flare on the main gear: h'_c = -(h_gear - h_off) / tau, tau and h_off from the entry sink
        # (continuity); the commanded path angle fed forward, led by T_theta2
        td = par[AP_TD_SINK]
        sink = vd + st[APS_SURFACE_SLOPE] * x0  # the main gear's closing speed on a sloped surface (radio altitude)
        if st[APS_FLARING] == 0.0:
            st[APS_FLARING] = 1.0
            st[APS_THETA_FLARE0] = st[APS_THETA_C]
            sink0 = max(sink, td + 0.1)
            st[APS_FLARE_TAU] = max(h_gear, 0.0) / (sink0 - td) if h_gear > 0.0 else 1.0
            st[APS_FLARE_H_OFF] = -st[APS_FLARE_TAU] * td
            st[APS_FLARE_SINK0] = sink0
            st[APS_FLARE_V0] = v_air
        tau = st[APS_FLARE_TAU]
        sink_c = (max(h_gear, 0.0) - st[APS_FLARE_H_OFF]) / tau
        e = sink - sink_c
        st[APS_INT_FLARE] += e * dt
        v0 = max(v_air, 1.0)
        ff = ((st[APS_FLARE_SINK0] - sink_c) / v0 + par[AP_FLARE_T_PATH] * sink / (tau * v0)
              + par[AP_FLARE_K_V] * (st[APS_FLARE_V0] - v_air)
              - par[AP_FLARE_K_GUST] * ((tas - v_air) if tas > 1.0 else 0.0))
        if par[AP_FLARE_GE_K] > 0.0:  # the ground effect's lift since flare entry, h_entry = tau (s_0 - s_td)
            h0 = tau * (st[APS_FLARE_SINK0] - td)
            k_ge = 1.0 + par[AP_FLARE_GE_K] * math.exp(-(max(h_gear, 0.0) + par[AP_FLARE_GE_ARP])
                                                       / par[AP_FLARE_GE_DECAY])
            k_ge0 = 1.0 + par[AP_FLARE_GE_K] * math.exp(-(h0 + par[AP_FLARE_GE_ARP]) / par[AP_FLARE_GE_DECAY])
            ff -= 0.5 * par[AP_FLARE_K_V] * st[APS_FLARE_V0] * math.log(k_ge / k_ge0)
        theta_c = st[APS_THETA_FLARE0] + ff + par[AP_K_FLARE] * e + par[AP_K_FLARE_I] * st[APS_INT_FLARE]
        # the nose-gear floor below its height: the pitch above the runway's own with which the main gear touches
        # first and takes the weight before the nose gear, with its margin (aircraft file); the integral frozen there.
        # A flare held on it has more lift than it wants (fast: a shear's airspeed gain): the throttle is at idle
        # while it holds, and the speed the floor keeps off the pitch is bled instead of floated
        floor = par[AP_FLARE_PITCH_MIN] + math.atan(st[APS_SURFACE_SLOPE])
        if h_gear <= par[AP_FLARE_PITCH_MIN_H] and theta_c < floor:
            theta_c = floor
            st[APS_INT_FLARE] -= e * dt
            thr = 0.0
        if h_gear <= par[AP_RETARD_H]:
            thr = 0.0
    st[APS_THETA_C] = theta_c
    de = -par[AP_K_THETA] * (theta_c - theta) + par[AP_K_Q] * q
    aligning = landing and psi == psi and (st[APS_ALIGNING] != 0.0 or h_gear <= par[AP_ALIGN_H])
    crab = 0.0
    if aligning:
        st[APS_ALIGNING] = 1.0
        crab = psi - (par[AP_HEADING] + conv) + math.pi
        crab = crab - _TWO_PI * math.floor(crab / _TWO_PI) - math.pi
        # the main gears' centre, gear_arm behind the guidance point, onto the centreline
        y = y - par[AP_GEAR_ARM] * math.sin(crab)
        y_dot = y_dot - par[AP_GEAR_ARM] * math.cos(crab) * r
    # localizer -> bank command
    phi_c = -(par[AP_K_LOC_P] * y + par[AP_K_LOC_D] * y_dot + par[AP_K_LOC_I] * st[APS_INT_Y])
    blim = par[AP_BANK_LIMIT]
    if -blim < phi_c < blim:
        st[APS_INT_Y] += y * dt
    else:
        phi_c = blim if phi_c > 0.0 else -blim
    if aligning:
        # runway alignment: yaw-rate command -crab / tau_align; the rudder, bank and aileron that hold the sideslip
        k_pb = par[AP_K_PHI_ALIGN]  # bank per sideslip at the approach speed (dynamic pressure ratio)
        if par[AP_ALIGN_CAS] > 0.0:
            sq = par[AP_CAS0] / par[AP_ALIGN_CAS]
            k_pb = k_pb * (sq * sq)
        # the sideslip limit and the one the bank allowance admits, the smaller; the rest of the wind correction
        # (crab + beta) stays as crab
        b_max = min(par[AP_ALIGN_BETA_MAX], par[AP_ALIGN_BANK_MAX] / k_pb if k_pb > 0.0 else math.inf)
        eta = crab + beta
        crab_res = eta - min(max(eta, -b_max), b_max)
        dr = par[AP_K_R_ALIGN] * (r + (crab - crab_res) / par[AP_ALIGN_TAU]) + par[AP_K_BETA_ALIGN] * beta
        da = (par[AP_K_PHI] * (phi_c + k_pb * beta - phi) - par[AP_K_P] * p
              + par[AP_K_DA_ALIGN] * beta)
    else:
        dr = -par[AP_K_BETA] * beta
        da = par[AP_K_PHI] * (phi_c - phi) - par[AP_K_P] * p
    return _clip1(de), _clip1(da), _clip1(dr), thr


@njit(cache=True)
def dryden_scales(h_ft: float, w20_fps: float, alt_ft: Array, sigma_fps: Array) -> tuple[float, float, float, float]:
    """Scale lengths L_u, L_w (ft) and intensities sigma_u, sigma_w (ft/s) at height h_ft above the ground
    (flight/turbulence.scales calls it): MIL-F-8785C low-altitude model below 1000 ft, the level's
    probability-of-exceedance row sigma_fps at alt_ft above 2000 ft, linear in between; heights clipped at 10 ft."""
    h = max(h_ft, 10.0)
    if h <= 1000.0:
        den = 0.177 + 0.000823 * h
        sig_w = 0.1 * w20_fps
        return h / den**1.2, h, sig_w / den**0.4, sig_w
    # piecewise-linear interpolation of the table, held at its ends
    n = alt_ft.shape[0]
    if h <= alt_ft[0]:
        sig_hi = sigma_fps[0]
    else:
        i = 0
        while i < n and alt_ft[i] <= h:  # bisect_right
            i += 1
        if i >= n:
            sig_hi = sigma_fps[n - 1]
        else:
            x0, x1 = alt_ft[i - 1], alt_ft[i]
            sig_hi = sigma_fps[i - 1] + (h - x0) / (x1 - x0) * (sigma_fps[i] - sigma_fps[i - 1])
    if h <= 2000.0:
        f = (h - 1000.0) / 1000.0
        L = 1000.0 + f * 750.0
        s = 0.1 * w20_fps + f * (sig_hi - 0.1 * w20_fps)
        return L, L, s, s
    return 1750.0, 1750.0, sig_hi, sig_hi


@njit(cache=True)
def dryden_step(par: Array, st: Array, nu: Array, k: int, h_agl_m: float,
                v_true_mps: float) -> tuple[float, float, float]:
    """Turbulence velocity at step k (NED, m/s) at height h_agl_m above the terrain and true airspeed v_true_mps
    (flight/turbulence.DrydenTurbulence.step, the oracle): Yeager 1998 eqs. 30-32,
        xi_u <- (1 - T/tau_u) xi_u + sigma_u sqrt(2T/tau_u) nu_u,  xi_v, xi_w with 2T/tau, sqrt(4T/tau), tau = L / V,
    the coefficients re-evaluated every COEFF_EVERY steps; nu (n, 3) the run's white noise. par: TB_*, st: TBS_*."""
    if k % COEFF_EVERY == 0 or st[TBS_VALID] == 0.0:
        L_u, L_w, sig_u, sig_w = dryden_scales(h_agl_m / _FT, par[TB_W20], par[TB_ALT:TB_ALT + N_POE],
                                               par[TB_SIGMA:TB_SIGMA + N_POE])
        V = max(v_true_mps / _FPS, 1.0)
        T = par[TB_DT]
        tu = L_u / V
        tw = L_w / V
        st[TBS_AU], st[TBS_BU] = 1.0 - T / tu, sig_u * math.sqrt(2.0 * T / tu)
        st[TBS_AV], st[TBS_BV] = 1.0 - 2.0 * T / tu, sig_u * math.sqrt(4.0 * T / tu)
        st[TBS_AW], st[TBS_BW] = 1.0 - 2.0 * T / tw, sig_w * math.sqrt(4.0 * T / tw)
        st[TBS_VALID] = 1.0
    xu = st[TBS_XI_U] = st[TBS_AU] * st[TBS_XI_U] + st[TBS_BU] * nu[k, 0]
    xv = st[TBS_XI_V] = st[TBS_AV] * st[TBS_XI_V] + st[TBS_BV] * nu[k, 1]
    xw = st[TBS_XI_W] = st[TBS_AW] * st[TBS_XI_W] + st[TBS_BW] * nu[k, 2]
    c, s = par[TB_COS], par[TB_SIN]
    # from wind axes (u along the direction the wind blows to, v to its right) to NED
    return c * xu - s * xv, s * xu + c * xv, xw * _FPS


@njit(cache=True)
def monitor_step(par: Array, st: Array, ring: Array, x_m: float, y_m: float, z_m: float, cas_mps: float,
                 v_down_mps: float, ground_speed_mps: float) -> tuple[int, float, float]:
    """One step of the stabilized-approach monitor (flight/envelope.StabilityMonitor.step, the oracle, whose module
    docstring has the criterion): true position (runway frame, m), air-mass speed as CAS, down velocity and
    horizontal ground speed (m/s) -> (MON_* result, its two figures): glidepath / localizer deviation in dots,
    3 s mean speed minus the target (m/s), or the 10 s mean sink rate and its excess over the glidepath's (m/s).
    par: MN_*, st: MNS_*, ring: the speed, sink and excess windows (updated)."""
    n, m = int(par[MN_N]), int(par[MN_M])
    i, j = int(st[MNS_I]), int(st[MNS_J])
    excess = v_down_mps - ground_speed_mps * par[MN_TAN_GP]  # sink beyond what the glidepath needs
    st[MNS_SUM_CAS] += cas_mps - ring[i]
    st[MNS_SUM_SINK] += v_down_mps - ring[n + j]
    st[MNS_SUM_EXCESS] += excess - ring[n + m + j]
    ring[i] = cas_mps
    ring[n + j], ring[n + m + j] = v_down_mps, excess
    st[MNS_I] = (i + 1) % n
    st[MNS_J] = (j + 1) % m
    st[MNS_COUNT] += 1.0
    if z_m > STABILIZATION_HEIGHT_M:
        return MON_OK, 0.0, 0.0
    # deviations in dots: the glide path's angular dot held at its 200 ft size below, the localizer's angular
    d = cone_deviation(x_m, y_m, z_m, 0.0, 0.0, 0.0, par[MN_TAN_GP], par[MN_X_GP], par[MN_CA], par[MN_CB],
                       par[MN_CC])[0]
    r_gp = max(par[MN_X_GP] - min(x_m, par[MN_X_FLOOR]), 1.0)
    gs_dots = d / (r_gp * par[MN_GS_DOT_TAN])
    loc_dots = y_m / ((LOC_ANTENNA_PAST_THRESHOLD_M - x_m) * par[MN_LOC_DOT_TAN])
    if abs(gs_dots) > 1.0:
        return MON_GLIDEPATH, gs_dots, 0.0
    if abs(loc_dots) > 1.0:
        return MON_LOCALIZER, loc_dots, 0.0
    if st[MNS_COUNT] < n:
        return MON_OK, 0.0, 0.0
    dv = st[MNS_SUM_CAS] / n - par[MN_TARGET]
    if dv > SPEED_HIGH_MPS or dv < -SPEED_LOW_MPS:
        return MON_SPEED, dv, 0.0
    if st[MNS_COUNT] < m:
        return MON_OK, 0.0, 0.0
    sink, excess = st[MNS_SUM_SINK] / m, st[MNS_SUM_EXCESS] / m
    if sink > SINK_LIMIT_MPS and excess > SINK_TOLERANCE_MPS:
        return MON_SINK, sink, excess
    return MON_OK, 0.0, 0.0


@njit(cache=True)
def termination(fpar: Array, fst: Array, mpar: Array, mst: Array, ring: Array, imu: tuple, h_agl: float,
                phi: float, wow: tuple, v_cg: tuple, cas: float, tas: float) -> int:
    """Why the run ends at this step (TERM_*; TERM_NONE: it goes on), checked in this order on the true state:
    the IMU at the stop height; (landing runs) a main gear on the ground with the nose gear in the air: touchdown,
    short of the threshold when x < 0; anything else on the ground or the IMU at the terrain; divergence (bank,
    distance from the glidepath or the centreline); below WATCH_HEIGHT_M (above the flare on landing runs) the
    stabilized-approach monitor, fed the speed through the mean air mass (CG ground velocity minus the mean
    wind at the CG's height, fst[FS_WIND_N], fst[FS_WIND_E]) as CAS with JSBSim's CAS/TAS ratio. imu = (x, y, z,
    vn, ve, vd): the IMU's position (runway frame, m) and NED velocity (m/s); h_agl its height above the terrain
    (m); phi the bank (rad); wow = (nose, left, right) JSBSim's weight-on-wheels; v_cg the CG's NED velocity, CAS
    and TAS in m/s. fpar, fst: the step's F_* parameters and FS_* state (touchdown and monitor figures are stored
    there)."""
    x, y, z, vn, ve, vd = imu
    wow_nose, wow_left, wow_right = wow
    vn_cg, ve_cg, vd_cg = v_cg
    if z <= fpar[F_STOP_H]:
        return TERM_STOP
    if fpar[F_LAND] != 0.0 and (wow_left > 0.0 or wow_right > 0.0) and wow_nose == 0.0:
        fst[FS_TD_X], fst[FS_TD_SINK] = x, vd
        return TERM_TOUCHDOWN if x >= 0.0 else TERM_SHORT
    if wow_nose > 0.0 or wow_left > 0.0 or wow_right > 0.0 or h_agl <= 0.0:
        return TERM_GROUND
    dev = cone_deviation(x, y, z, 0.0, 0.0, 0.0, fpar[F_TAN_GP], fpar[F_X_GPI], fpar[F_CA], fpar[F_CB], fpar[F_CC])[0]
    if (abs(phi) > DIVERGED_BANK_RAD or abs(dev) > fpar[F_DIV_VERT]
            or abs(y) > fpar[F_DIV_LAT]):
        return TERM_DIVERGED
    if fpar[F_MON_FLOOR] < z < WATCH_HEIGHT_M:
        an, ae = vn_cg - fst[FS_WIND_N], ve_cg - fst[FS_WIND_E]
        v_air = math.sqrt(an * an + ae * ae + vd_cg ** 2)
        result, a, b = monitor_step(mpar, mst, ring, x, y, z, v_air * cas / tas, vd, math.sqrt(vn * vn + ve * ve))
        if result != MON_OK:
            fst[FS_MON], fst[FS_MON_Z], fst[FS_MON_A], fst[FS_MON_B] = result, z, a, b
            return TERM_UNSTABLE
    return TERM_NONE


LOG_H_MIN_M = 3.0 * _FT
LOG_H_TOP_M = 1000.0 * _FT
"""The log law's height range (MIL-F-8785C: 3 ft to 1000 ft; flight/wind.py, the oracle)."""


@njit(cache=True)
def mean_wind(fpar: Array, h_m: float) -> tuple[float, float]:
    """The mean wind (north, east, m/s) at height h_m above the terrain (flight/wind.mean_wind_ned, the oracle):
    the reference wind (F_WIND_N, F_WIND_E) times ln(h / z0) / ln(h_ref / z0) (h clipped to 3-1000 ft) when
    F_WIND_LOG, plus the shear layer's change (F_SHEAR_N, F_SHEAR_E) times its fraction in force at h."""
    f = 1.0
    if fpar[F_WIND_LOG] != 0.0:
        h = min(max(h_m, LOG_H_MIN_M), LOG_H_TOP_M)
        f = math.log(h / fpar[F_WIND_Z0]) / math.log(fpar[F_WIND_REF] / fpar[F_WIND_Z0])
    top, bottom = fpar[F_SHEAR_TOP], fpar[F_SHEAR_BOTTOM]
    if h_m >= top:
        s = 0.0
    elif h_m <= bottom:
        s = 1.0
    else:
        s = (top - h_m) / (top - bottom)
    return fpar[F_WIND_N] * f + s * fpar[F_SHEAR_N], fpar[F_WIND_E] * f + s * fpar[F_SHEAR_E]


@njit(cache=True)
def _terrain_at(x: float, along: Array, height: Array) -> float:
    """Terrain height (m) at runway-frame x (np.interp of the profile; its one height when flat)."""
    return height[0] if height.shape[0] == 1 else np.interp(x, along, height)


@njit(cache=True)
def _control(par: Array, st: Array, row: Array, guide: tuple, air: tuple) -> tuple[float, float, float, float]:
    """The autopilot on guidance `guide` (x, y, z, vn, ve, vd) and the aircraft's `air` (autopilot_step); the
    commands go into the row and the step's state."""
    de, da, dr, thr = autopilot_step(par[P_AP:P_AP + N_AP_PAR], st[S_AP:S_AP + N_AP_STATE], guide, air)
    row[CONTROLS_COL] = de + par[P_STEP + F_PITCH_TRIM]
    row[CONTROLS_COL + 1], row[CONTROLS_COL + 2], row[CONTROLS_COL + 3] = da, dr, thr
    st[S_STEP + FS_DE], st[S_STEP + FS_DA], st[S_STEP + FS_DR], st[S_STEP + FS_THR] = de, da, dr, thr
    return de, da, dr, thr


@njit(cache=True)
def fly_step(k: int, raw: Any, buf: Array, nu: Array, par: Array, st: Array,
             guided: bool) -> tuple[int, float, float, float, float, float, float, float, float, bool]:
    """Step k of the flight loop after JSBSim's step k: everything that is not a JSBSim read or write.

    raw: the reads, RAW_FIELDS + GEAR_FIELDS (a tuple; the gear as GEAR_AIRBORNE when not read), JSBSim units.
    Writes Truth row buf[k] (imu_point_row; the controls in force), then steps the turbulence at the CG's height
    above the terrain (dryden_step, noise nu) and checks `termination` (incl. the monitor); with guided (the
    autopilot flies on the truth) and no termination it runs the autopilot on row k (else `fly_control` does, on
    the navigation source's guidance). par, st: the parameter and state vectors (P_*, S_* offsets; the terrain
    profile and the monitor's windows at their ends: flight_vectors builds them).

    Returns (TERM_* code, elevator, aileron, rudder, throttle (the commands to set for the next step; the ones in
    force when not guided), gust north, east, down (ft/s, for JSBSim's atmosphere/gust-*-fps: the turbulence plus
    the mean wind's change with height, flight/wind.py), terrain height under the IMU (under the main gear on
    landing runs; ft, for position/terrain-elevation-asl-ft), whether to read the gear at the next step).
    """
    row = buf[k]
    fpar, fst = par[P_STEP:P_STEP + N_F_PAR], st[S_STEP:S_STEP + N_F_STATE]
    nt = int(fpar[F_N_TERRAIN])
    terr, p, q, r = _imu_point(raw, par[P_IMU:P_IMU + N_CONST], par[P_TERRAIN:P_TERRAIN + nt],
                            par[P_TERRAIN + nt:P_TERRAIN + 2 * nt], k * par[P_IMU + C_DT], row)
    vn_f, ve_f, vd_f, phi, theta = raw[R_VN], raw[R_VE], raw[R_VD], raw[R_PHI], raw[R_THETA]
    cas, beta, tas = raw[R_VC] * _KT, raw[R_BETA], raw[R_VT] * _FPS
    vn, ve, vd = row[ROW_V_NED], row[ROW_V_NED + 1], row[ROW_V_NED + 2]
    xr, yr, zr = row[ROW_R_RWY], row[ROW_R_RWY + 1], row[ROW_R_RWY + 2]
    h_agl = row[ROW_H] - terr
    if h_agl < LOW_READ_HEIGHT_M:  # the gear counts near the ground only
        w0, w1, w2 = raw[R_WOW_NOSE], raw[R_WOW_LEFT], raw[R_WOW_RIGHT]
        g1_ft, g2_ft = raw[R_GEAR_LEFT_FT], raw[R_GEAR_RIGHT_FT]
    else:
        w0, w1, w2, g1_ft, g2_ft = GEAR_AIRBORNE
    near = h_agl < LOW_READ_HEIGHT_M + GEAR_READ_MARGIN_M
    gn = ge = gd = 0.0
    if fpar[F_TURBULENT] != 0.0:  # turbulence for the next step, at the CG's height above the terrain
        tn, te, td = dryden_step(par[P_TB:P_TB + N_TB_PAR], st[S_TB:S_TB + N_TB_STATE], nu, k,
                                 raw[R_H_FT] * _FT - terr, tas)
        gn, ge, gd = tn / _FPS, te / _FPS, td / _FPS
    if fpar[F_WIND_VARIES] != 0.0:  # the mean wind at the CG's height less JSBSim's steady wind, as a gust
        wn, we = mean_wind(fpar, raw[R_H_FT] * _FT - terr)
        fst[FS_WIND_N], fst[FS_WIND_E] = wn, we
        gn += (wn - fpar[F_WIND0_N]) / _FPS
        ge += (we - fpar[F_WIND0_E]) / _FPS
    terr_w = terr  # the terrain JSBSim's ground plane takes: under the main gear on landing runs over a profile
    if fpar[F_LAND] != 0.0 and nt > 1:
        along, height = par[P_TERRAIN:P_TERRAIN + nt], par[P_TERRAIN + nt:P_TERRAIN + 2 * nt]
        x_g = xr - fpar[F_GEAR_X]
        terr_w = _terrain_at(x_g, along, height)
        # the surface's slope under the main gear (central difference over 2 m), for the flare's closing speed
        st[S_AP + APS_SURFACE_SLOPE] = 0.5 * (_terrain_at(x_g + 1.0, along, height)
                                              - _terrain_at(x_g - 1.0, along, height))
    # the controls of the previous step act on this row until replaced
    row[CONTROLS_COL] = fst[FS_DE] + fpar[F_PITCH_TRIM]
    row[CONTROLS_COL + 1], row[CONTROLS_COL + 2], row[CONTROLS_COL + 3] = fst[FS_DA], fst[FS_DR], fst[FS_THR]
    if zr < fst[FS_LOWEST]:
        fst[FS_LOWEST] = zr
    code = termination(fpar, fst, par[P_MN:P_MN + N_MN_PAR], st[S_MN:S_MN + N_MN_STATE], st[S_RING:],
                       (xr, yr, zr, vn, ve, vd), h_agl, phi, (w0, w1, w2), (vn_f * _FPS, ve_f * _FPS, vd_f * _FPS),
                       cas, tas)
    h_gear = min(g1_ft, g2_ft) * _FT if fpar[F_LAND] != 0.0 else math.nan
    # the inner loops' inputs of this step (fly_control's, when a navigation source guides)
    fst[FS_PHI], fst[FS_THETA], fst[FS_P], fst[FS_Q], fst[FS_BETA] = phi, theta, p, q, beta
    fst[FS_CAS], fst[FS_H_GEAR], fst[FS_TAS] = cas, h_gear, tas
    psi = raw[R_PSI] if fpar[F_LAND] != 0.0 else math.nan
    fst[FS_PSI], fst[FS_R] = psi, r
    if guided and code == TERM_NONE:
        de, da, dr, thr = _control(par, st, row, (xr, yr, zr, vn, ve, vd),
                                   (phi, theta, p, q, beta, cas, h_gear, tas, psi, r))
    else:
        de, da, dr, thr = fst[FS_DE], fst[FS_DA], fst[FS_DR], fst[FS_THR]
    return code, de, da, dr, thr, gn, ge, gd, terr_w / _FT, near


@njit(cache=True)
def fly_control(k: int, guidance: Array, buf: Array, par: Array, st: Array) -> tuple[float, float, float, float]:
    """The autopilot of step k on a navigation source's guidance (k, 0:6): runway-frame position (m) and NED
    velocity (m/s), after fly_step(..., guided=False); returns elevator, aileron, rudder, throttle to set."""
    g = guidance[k]
    s = st[S_STEP:S_STEP + N_F_STATE]
    return _control(par, st, buf[k], (g[0], g[1], g[2], g[3], g[4], g[5]),
                    (s[FS_PHI], s[FS_THETA], s[FS_P], s[FS_Q], s[FS_BETA], s[FS_CAS], s[FS_H_GEAR], s[FS_TAS],
                     s[FS_PSI], s[FS_R]))


@njit(cache=True)
def split_rows(buf: Array, n: int, cols: Array, outs: Any) -> None:
    """outs[f][k, j] = buf[k, cols[f] + j] for rows k < n: the row buffer's fields as contiguous arrays, in one pass
    over its rows (a column-by-column copy reads the whole buffer once per field). outs: a tuple of (n, w) arrays."""
    for k in range(n):
        row = buf[k]
        for f in range(len(outs)):
            o = outs[f]
            c = cols[f]
            for j in range(o.shape[1]):
                o[k, j] = row[c + j]
