"""Every packed vector the compiled code shares, declared once from (name, width) pairs.

As PyBaMM gives each variable a named slice of the state vector, each packed float vector here is a `Layout`: its
fields in order with their widths, from which the offsets follow. The kernels read the offsets as module-level
integer constants (numba freezes them at compile time), unpacked from the layout in field order, so a field added
or widened moves every offset after it and nothing is numbered by hand anywhere else:

    READS         one JSBSim step's property reads (RAW_FIELDS, then GEAR_FIELDS near the ground), JSBSim units
    TRUTH_ROW     the flight's row buffer (flight/run.py): one Truth row per JSBSim step, SI
    INS           the packed strapdown state (core/nav/strapdown.py): lat, lon, h, v_ned, C_bn, a_comp
    IMU_POINT     the truth row's constants (flight/vectors.imu_point_constants)
    AP_PAR, AP_STATE, TB_PAR, TB_STATE, MN_PAR, MN_STATE, F_PAR, F_STATE
                  the flight step's components: autopilot, Dryden turbulence, stabilized-approach monitor, the step
    FLIGHT_PAR, FLIGHT_STATE
                  `fly_step`'s parameter and state vectors: the components' vectors concatenated (terrain and the
                  monitor's windows, of run-dependent length, end them)
    NAV_WORK      the closed loop's navigation work vector (core/loop/nav_row.py)
    SERVICE_TRUTH a GNSS service's truth shape (core/sensors/gnss.py service_errors; sensors/gnss/service.py)
    DIRECT        the addresses the compiled JSBSim calls take (core/loop/direct.py)

tests/unit/test_core_layouts.py checks the layouts against the records they pack (Truth's fields, the autopilot's
gains, the INS state).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from approachsim.core.tables import POE_ALT_FT


class Layout:
    """A packed vector's fields (name, width) in order; offsets and the total size follow from them."""

    def __init__(self, fields: Iterable[tuple[str, int]]) -> None:
        self.fields: tuple[tuple[str, int], ...] = tuple(fields)
        self._start: dict[str, int] = {}
        o = 0
        for name, width in self.fields:
            if name in self._start:
                raise ValueError(f"layout field {name!r} declared twice")
            if width < 1:
                raise ValueError(f"layout field {name!r} has width {width}")
            self._start[name] = o
            o += width
        self.size: int = o
        """The vector's length."""

    def start(self, name: str) -> int:
        """Offset of field `name`."""
        return self._start[name]

    def width(self, name: str) -> int:
        """Width of field `name`."""
        return dict(self.fields)[name]

    def slice(self, name: str) -> slice:
        """The slice of field `name`."""
        s = self._start[name]
        return slice(s, s + self.width(name))

    def starts(self) -> tuple[int, ...]:
        """Every field's offset, in field order (unpacked into the kernels' named constants)."""
        return tuple(self._start[name] for name, _ in self.fields)

    @property
    def names(self) -> tuple[str, ...]:
        """The field names in order."""
        return tuple(name for name, _ in self.fields)


def _scalars(*names: str) -> list[tuple[str, int]]:
    return [(n, 1) for n in names]


# --- one JSBSim step's reads ---------------------------------------------------------------------------------------
RAW_FIELDS = (
    "position/lat-geod-rad", "position/long-gc-rad", "position/geod-alt-ft",
    "velocities/v-north-fps", "velocities/v-east-fps", "velocities/v-down-fps",
    "attitude/phi-rad", "attitude/theta-rad", "attitude/psi-rad",
    "velocities/pi-rad_sec", "velocities/qi-rad_sec", "velocities/ri-rad_sec",
    "accelerations/pidot-rad_sec2", "accelerations/qidot-rad_sec2", "accelerations/ridot-rad_sec2",
    "forces/fbx-total-lbs", "forces/fby-total-lbs", "forces/fbz-total-lbs", "inertia/mass-slugs",
    "atmosphere/P-psf", "atmosphere/T-R", "velocities/vc-kts", "aero/beta-rad",
    "velocities/vtrue-fps",
)
"""The JSBSim properties `imu_point_row` reads, in the order of its `raw` input. JSBSim's Earth-relative body
rates (velocities/p-rad_sec, ...) are not read: `imu_point_row` derives them from the inertial ones (earth_rates)."""
GEAR_FIELDS = ("gear/unit[0]/WOW", "gear/unit[1]/WOW", "gear/unit[2]/WOW", "gear/unit[1]/AGL-ft",
               "gear/unit[2]/AGL-ft")
"""The gear state (nose, left main, right main weight on wheels; main-gear heights above the ground, ft), read
only near the ground; `fly_step`'s raw tuple is RAW_FIELDS + GEAR_FIELDS."""
GEAR_AIRBORNE = (0.0, 0.0, 0.0, math.inf, math.inf)
"""GEAR_FIELDS' values standing in for reads far from the ground (no weight on wheels, gear infinitely high)."""
READS = Layout(_scalars(*RAW_FIELDS, *GEAR_FIELDS))
(R_LAT, R_LON, R_H_FT, R_VN, R_VE, R_VD, R_PHI, R_THETA, R_PSI, R_PI, R_QI, R_RI, R_PID, R_QID, R_RID, R_FX, R_FY,
 R_FZ, R_MASS, R_P, R_T, R_VC, R_BETA, R_VT, R_WOW_NOSE, R_WOW_LEFT, R_WOW_RIGHT, R_GEAR_LEFT_FT,
 R_GEAR_RIGHT_FT) = READS.starts()
N_RAW = len(RAW_FIELDS)
N_READ = READS.size

# --- the flight's row buffer: one Truth row per step (approachsim.records.Truth's fields, SI) ---------------------
TRUTH_ROW = Layout([
    ("t_s", 1), ("lat_rad", 1), ("lon_rad", 1), ("h_m", 1), ("r_ecef", 3), ("v_ned", 3), ("q_nb", 4),
    ("euler_rad", 3), ("w_ib_body", 3), ("f_body", 3), ("p_static_pa", 1), ("t_air_k", 1), ("h_agl_m", 1),
    ("r_rwy", 3), ("gs_dev_m", 1), ("loc_dev_m", 1), ("controls", 4), ("airspeed_mps", 1),
])
(ROW_T, ROW_LAT, ROW_LON, ROW_H, ROW_R_ECEF, ROW_V_NED, ROW_Q_NB, ROW_EULER, ROW_W_IB, ROW_F_BODY, ROW_P_STATIC,
 ROW_T_AIR, ROW_H_AGL, ROW_R_RWY, ROW_GS_DEV, ROW_LOC_DEV, ROW_CONTROLS, ROW_AIRSPEED) = TRUTH_ROW.starts()
N_ROW = TRUTH_ROW.size
CONTROLS_COL = ROW_CONTROLS
"""First of the Truth row's four control columns (elevator incl. pitch trim, aileron, rudder, throttle)."""

# --- the packed INS state (ins.InsState) -------------------------------------------------------------------------
INS = Layout([("lat_rad", 1), ("lon_rad", 1), ("h_m", 1), ("v_ned", 3), ("c_bn", 9), ("a_comp", 1)])
X_LAT, X_LON, X_H, X_V, X_C_BN, X_A_COMP = INS.starts()
NX = INS.size
"""Columns of the packed INS state."""

# --- the truth row's constants --------------------------------------------------------------------------------------
IMU_POINT = Layout([
    ("lever_arm_m", 3), ("r_n_m", 1), ("r_e_m", 1), ("origin_ecef_m", 3), ("c_ecef_to_rwy_rows", 6),
    ("h_thr_m", 1), ("tan_gp", 1), ("tch_m", 1), ("x_gpi_m", 1), ("cone_a", 1), ("cone_b", 1), ("cone_c", 1),
    ("dt_s", 1),
])
(C_LEVER, C_RN, C_RE, C_ORIGIN, C_RWY, C_HTHR, C_TAN_GP, C_TCH, C_X_GPI, C_CA, C_CB, C_CC,
 C_DT) = IMU_POINT.starts()
N_CONST = IMU_POINT.size

# --- the autopilot: the gains in flight.design.AutopilotGains order, then trim, geometry, step; its state ---------
AP_GAINS = ("k_theta", "k_q", "k_gs_p", "k_gs_d", "k_gs_i", "k_v_p", "k_v_i", "tau_v_s", "k_phi", "k_p", "k_beta",
            "k_loc_p", "k_loc_d", "k_loc_i", "bank_limit_rad", "pitch_limit_rad", "tau_wind_s", "flare_height_m",
            "touchdown_sink_mps", "k_flare", "k_flare_i", "retard_height_m", "tecs", "tecs_t_h_s", "tecs_t_v_s",
            "tecs_thr_per_rad", "tecs_k_thr_damp", "tecs_k_thr_i", "tecs_k_pitch_damp", "tecs_k_pitch_i",
            "tecs_seb_ff", "tecs_spd_weight", "tecs_rate_tau_s", "tecs_sink_max_mps", "tecs_climb_max_mps",
            "tecs_vert_acc_mps2", "align_height_m", "align_tau_s", "k_r_align", "k_beta_align", "k_phi_align",
            "k_da_align", "align_bank_max_rad", "align_cas_mps", "align_sideslip_max_rad", "flare_t_path_s",
            "flare_k_v", "flare_k_gust", "flare_ge_k", "flare_ge_decay_m", "flare_ge_arp_m",
            "flare_pitch_min_rad", "flare_pitch_min_height_m")
"""flight.design.AutopilotGains fields, in the order of the autopilot parameter vector."""
AP_PAR = Layout(_scalars(*AP_GAINS, "theta0_rad", "throttle0", "cas0_mps", "cos_heading", "sin_heading",
                         "heading_rad", "tan_gp", "x_gpi_m", "cone_a", "cone_b", "cone_c", "conv_per_east_m",
                         "gear_arm_m", "dt_s"))
(AP_K_THETA, AP_K_Q, AP_K_GS_P, AP_K_GS_D, AP_K_GS_I, AP_K_V_P, AP_K_V_I, AP_TAU_V, AP_K_PHI, AP_K_P, AP_K_BETA,
 AP_K_LOC_P, AP_K_LOC_D, AP_K_LOC_I, AP_BANK_LIMIT, AP_PITCH_LIMIT, AP_TAU_WIND, AP_FLARE_H, AP_TD_SINK,
 AP_K_FLARE, AP_K_FLARE_I, AP_RETARD_H, AP_TECS, AP_T_H, AP_T_V, AP_K_THR, AP_K_TD, AP_K_TI, AP_K_PD, AP_K_PI,
 AP_SEB_FF, AP_SPD_W, AP_RATE_TAU, AP_SINK_MAX, AP_CLIMB_MAX, AP_VERT_ACC, AP_ALIGN_H, AP_ALIGN_TAU, AP_K_R_ALIGN,
 AP_K_BETA_ALIGN, AP_K_PHI_ALIGN, AP_K_DA_ALIGN, AP_ALIGN_BANK_MAX, AP_ALIGN_CAS, AP_ALIGN_BETA_MAX, AP_FLARE_T_PATH,
 AP_FLARE_K_V, AP_FLARE_K_GUST, AP_FLARE_GE_K, AP_FLARE_GE_DECAY, AP_FLARE_GE_ARP, AP_FLARE_PITCH_MIN,
 AP_FLARE_PITCH_MIN_H, AP_THETA0, AP_THR0, AP_CAS0, AP_CH, AP_SH, AP_HEADING, AP_TAN_GP,
 AP_X_GPI, AP_CONE_A, AP_CONE_B, AP_CONE_C, AP_CONV, AP_GEAR_ARM, AP_DT) = AP_PAR.starts()
N_AP_PAR = AP_PAR.size
AP_STATE = Layout(_scalars("int_d", "int_y", "e_f", "wind", "int_e", "flaring", "theta_flare0", "int_flare",
                           "theta_c", "v_lag", "int_t", "int_b", "flare_tau", "flare_h_off", "aligning",
                           "flare_sink0", "flare_v0", "surface_slope"))
(APS_INT_D, APS_INT_Y, APS_E_F, APS_WIND, APS_INT_E, APS_FLARING, APS_THETA_FLARE0, APS_INT_FLARE,
 APS_THETA_C, APS_V_LAG, APS_INT_T, APS_INT_B, APS_FLARE_TAU, APS_FLARE_H_OFF, APS_ALIGNING,
 APS_FLARE_SINK0, APS_FLARE_V0, APS_SURFACE_SLOPE) = AP_STATE.starts()
N_AP_STATE = AP_STATE.size

# --- Dryden turbulence: W20, dt, wind-axes rotation, the intensity table's altitudes and the level's row; state ---
N_POE = len(POE_ALT_FT)
"""Altitudes of MIL-F-8785C's high-altitude intensity table (core/tables.py)."""
TB_PAR = Layout([("w20_fps", 1), ("dt_s", 1), ("cos", 1), ("sin", 1), ("poe_alt_ft", N_POE),
                 ("poe_sigma_fps", N_POE)])
TB_W20, TB_DT, TB_COS, TB_SIN, TB_ALT, TB_SIGMA = TB_PAR.starts()
N_TB_PAR = TB_PAR.size
TB_STATE = Layout(_scalars("xi_u", "xi_v", "xi_w", "valid", "a_u", "b_u", "a_v", "b_v", "a_w", "b_w"))
(TBS_XI_U, TBS_XI_V, TBS_XI_W, TBS_VALID, TBS_AU, TBS_BU, TBS_AV, TBS_BV, TBS_AW, TBS_BW) = TB_STATE.starts()
N_TB_STATE = TB_STATE.size

# --- stabilized-approach monitor: parameters, state; its ring buffer [speed (n) | sink (m) | excess (m)] follows ---
MN_PAR = Layout(_scalars("tan_gp", "gs_dot_tan", "x_gp_m", "x_floor_m", "loc_dot_tan", "tch_m", "target_mps", "n",
                         "m", "cone_a", "cone_b", "cone_c"))
(MN_TAN_GP, MN_GS_DOT_TAN, MN_X_GP, MN_X_FLOOR, MN_LOC_DOT_TAN, MN_TCH, MN_TARGET, MN_N, MN_M, MN_CA, MN_CB,
 MN_CC) = MN_PAR.starts()
N_MN_PAR = MN_PAR.size
MN_STATE = Layout(_scalars("i", "j", "count", "sum_cas", "sum_sink", "sum_excess"))
(MNS_I, MNS_J, MNS_COUNT, MNS_SUM_CAS, MNS_SUM_SINK, MNS_SUM_EXCESS) = MN_STATE.starts()
N_MN_STATE = MN_STATE.size

# --- the step's own parameters and state ----------------------------------------------------------------------------
F_PAR = Layout(_scalars("pitch_trim", "stop_h_m", "land", "tan_gp", "tch_m", "mon_floor_m", "wind_n_mps",
                        "wind_e_mps", "turbulent", "n_terrain", "x_gpi_m", "cone_a", "cone_b", "cone_c",
                        "wind_varies", "wind_log", "wind_z0_m", "wind_ref_m", "wind0_n_mps", "wind0_e_mps",
                        "shear_top_m", "shear_bottom_m", "shear_n_mps", "shear_e_mps", "gear_x_m",
                        "div_vert_m", "div_lat_m"))
(F_PITCH_TRIM, F_STOP_H, F_LAND, F_TAN_GP, F_TCH, F_MON_FLOOR, F_WIND_N, F_WIND_E, F_TURBULENT,
 F_N_TERRAIN, F_X_GPI, F_CA, F_CB, F_CC, F_WIND_VARIES, F_WIND_LOG, F_WIND_Z0, F_WIND_REF, F_WIND0_N, F_WIND0_E,
 F_SHEAR_TOP, F_SHEAR_BOTTOM, F_SHEAR_N, F_SHEAR_E, F_GEAR_X, F_DIV_VERT, F_DIV_LAT) = F_PAR.starts()
N_F_PAR = F_PAR.size
F_STATE = Layout(_scalars("de", "da", "dr", "thr", "lowest_m", "td_x_m", "td_sink_mps", "mon", "mon_z_m", "mon_a",
                          "mon_b", "phi", "theta", "p", "q", "beta", "cas_mps", "h_gear_m", "tas_mps", "psi", "r",
                          "wind_n_mps", "wind_e_mps"))
(FS_DE, FS_DA, FS_DR, FS_THR, FS_LOWEST, FS_TD_X, FS_TD_SINK, FS_MON, FS_MON_Z, FS_MON_A, FS_MON_B,
 FS_PHI, FS_THETA, FS_P, FS_Q, FS_BETA, FS_CAS, FS_H_GEAR, FS_TAS, FS_PSI, FS_R, FS_WIND_N,
 FS_WIND_E) = F_STATE.starts()
N_F_STATE = F_STATE.size

# --- fly_step's vectors: the components' concatenated; the terrain profile (F_N_TERRAIN along-track distances, then
# as many heights, m) ends the parameters, the monitor's windows end the state ---------------------------------------
FLIGHT_PAR = Layout([("imu", N_CONST), ("step", N_F_PAR), ("ap", N_AP_PAR), ("tb", N_TB_PAR), ("mn", N_MN_PAR)])
P_IMU, P_STEP, P_AP, P_TB, P_MN = FLIGHT_PAR.starts()
P_TERRAIN = FLIGHT_PAR.size
FLIGHT_STATE = Layout([("step", N_F_STATE), ("ap", N_AP_STATE), ("tb", N_TB_STATE), ("mn", N_MN_STATE)])
S_STEP, S_AP, S_TB, S_MN = FLIGHT_STATE.starts()
S_RING = FLIGHT_STATE.size

# --- the closed loop's navigation work vector (core/loop/nav_row.py) ------------------------------------------------
NAV_WORK = Layout([
    ("x", NX),            # the one run's packed INS state
    ("xnav", 9),          # the estimated navigation errors in force: dp NED m, dv m/s, psi rad
    ("fsum", 3),          # C_bn dv summed since the last epoch, NED m/s
    ("bg", 3), ("ba", 3),  # bias feedback, rad/s and m/s^2 (zeros feed-forward)
    ("loop", 6),          # the damping loop: ins.loop_vector
    ("hb", 1),            # the baro height held for the next intervals, m (nan: none; the loop holds)
    ("dt", 1),            # the IMU interval, s
    ("mg", 9), ("ma", 9),  # IMU scale factor + misalignment matrices M_g, M_a, row-major
    ("crwy", 6), ("orwy", 3), ("hthr", 1),  # runway frame: C_ecef->rwy's first two rows, ECEF origin, threshold h
    ("snap", 1),          # index of the filter snapshot in force (the Navigator's)
    ("epoch_rows", 1),    # truth rows between aiding epochs
    ("any_baro", 1),      # 1 when the INS had a baro at some interval since the last epoch
    ("baro_loop", 1),     # 1 when the damping loop takes baro samples
    ("baro_kernel", 1),   # 1 when the baro samples are made here (a plain barometric altimeter), else by Python
    ("baro_excl", 1),     # 1 when the online FDE has excluded the baro (the loop holds)
    ("bset", 1), ("bt0l", 1), ("bexp", 1), ("bsf", 1),  # the baro's setting (Pa), ISA T0 / L (m), R L / g0, scale
    ("bfld", 1), ("bcm1", 1),  # temperature correction: field geopotential elevation H_f (m) and c - 1
    ("n", 1), ("m", 1), ("nbe", 1), ("nlag", 1),  # sizes of the packed arrays: rows, IMU samples, baro, lag weights
    ("hb_t", 1), ("hb_age", 1),  # the held baro sample's time (s) and its age at the interval start (s)
    ("xdot", 9),          # the rate of xnav (core/nav/output.nav_rate): m/s, m/s^2, rad/s
    ("t_est", 1),         # the time of xnav (the last epoch), s
    ("xnow", 9),          # scratch: the estimate at the row's time, xnav + (t - t_est) xdot
])
(W_X, W_XNAV, W_FSUM, W_BG, W_BA, W_LOOP, W_HB, W_DT, W_MG, W_MA, W_CRWY, W_ORWY, W_HTHR, W_SNAP, W_EPOCH_ROWS,
 W_ANY_BARO, W_BARO_LOOP, W_BARO_KERNEL, W_BARO_EXCL, W_BSET, W_BT0L, W_BEXP, W_BSF, W_BFLD, W_BCM1, W_N, W_M, W_NBE,
 W_NLAG, W_HB_T, W_HB_AGE, W_XDOT, W_T_EST, W_XNOW) = NAV_WORK.starts()
NW = NAV_WORK.size

# --- a GNSS service's truth: fractions of the broadcast sigmas and the iono field's shape (service.py) ---------------
SERVICE_TRUTH = Layout(_scalars(
    "f_range", "f_iono", "f_tropo", "f_air",  # truth 1-sigma / broadcast 1-sigma of each term
    "w_common", "w_grad", "w_local",          # square roots of the iono field's variance split (0, 0, 1: per channel)
    "grad_ref_m",                             # d_5: the pierce distance the gradient term is scaled by, m
    "tropo_common",                           # 1: one zenith tropo residual for all satellites; 0: per channel
))
(ST_F_RANGE, ST_F_IONO, ST_F_TROPO, ST_F_AIR, ST_W_COMMON, ST_W_GRAD, ST_W_LOCAL, ST_GRAD_REF,
 ST_TROPO_COMMON) = SERVICE_TRUTH.starts()
N_ST = SERVICE_TRUTH.size

# --- the compiled JSBSim calls' addresses (core/loop/direct.py) ------------------------------------------------------
WRITTEN = ("fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm", "fcs/throttle-cmd-norm[0]",
           "fcs/throttle-cmd-norm[1]", "atmosphere/gust-north-fps", "atmosphere/gust-east-fps",
           "atmosphere/gust-down-fps", "position/terrain-elevation-asl-ft")
"""The JSBSim properties the flight loop writes, in flight/fdm.py LoopIO's setters' order: elevator, aileron,
rudder, throttles (normalized), gusts north, east, down (ft/s), terrain elevation (ft)."""
WRITES = Layout(_scalars(*WRITTEN))
WRITE_DE, WRITE_DA, WRITE_DR, WRITE_THR0, WRITE_THR1, WRITE_GN, WRITE_GE, WRITE_GD, WRITE_TERRAIN = WRITES.starts()
N_WRITE = WRITES.size
DIRECT = Layout([("get", 1), ("set", 1), ("run", 1), ("exec", 1), ("write", N_WRITE), ("read", N_READ)])
D_GET, D_SET, D_RUN, D_EXEC, D_WRITE, D_READ = DIRECT.starts()
N_D = DIRECT.size
