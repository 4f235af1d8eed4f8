"""Autopilot loop design check: the landing-configuration linearization closed with the autopilot, loop at a time.

The plant is JSBSim's FGLinearization of the trimmed aircraft in still air (states Vt, alpha, theta, q, beta,
phi, p, psi, r, lat, lon, alt; inputs throttle, aileron, elevator, rudder commands), converted to SI. The
latitude, longitude and altitude states are dropped (they feed nothing back at these time scales) and replaced
by the guidance states the autopilot closes on: glidepath deviation d (m), its integral, cross-track y (m), its
integral, the filtered airspeed perturbation and its integral, and a first-order engine lag between the
throttle command and the thrust the linearization sees (the linearization has no engine state; the lag is the
aircraft file's `engine_lag_s`, measured from a throttle step).

The control laws are the same as autopilot.py's, linearized (no limits); the classic law:

    theta_c = theta_0 - (k_gs_p d + k_gs_d d' + k_gs_i int d)              glidepath  -> pitch command
    de      = -k_theta (theta_c - theta) + k_q q                           pitch      -> elevator (+ = nose down)
    thr     = thr_0 + k_v_p e_f + k_v_i int e_f,  e_f = lowpass(V_c - V)   autothrottle
    phi_c   = -(k_loc_p y + k_loc_d y' + k_loc_i int y)                    localizer  -> bank command
    da      = k_phi (phi_c - phi) - k_p p                                  roll       -> aileron (+ = roll right)
    dr      = -k_beta beta                                                 sideslip   -> rudder (+ = nose left)

or, with gains.tecs, the total energy control law of autopilot.py (thrust from the total-energy rate error,
pitch from the energy-distribution rate error, the speed derivative by a washout), in the same states; its gains
come from the classic ones by `tecs_gains` (the derivation is in its docstring).

Each loop is broken at one point with every other loop closed (the classical loop-at-a-time check):
"elevator", "throttle", "aileron", "rudder" at the actuator commands, "glidepath" at theta_c and "localizer"
at phi_c. `loop_margins` returns python-control's gain and phase margins of each broken loop L(s); the
closed-loop system must be stable for them to mean anything, which `closed_loop_poles` shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from approachsim import units

if TYPE_CHECKING:  # python-control imports matplotlib.pyplot (~0.5 s): loaded where a loop is analysed
    import control

Array = np.ndarray

LAWS = ("classic", "tecs")
"""The speed and path laws the autopilot can fly (aircraft file `[autopilot] law`, profile `aircraft.autopilot_law`)."""

LOOPS = ("elevator", "throttle", "aileron", "rudder", "glidepath", "localizer")
"""The break points of the loop-at-a-time margin check."""

# indices into the 12-state JSBSim linearization
_VT, _ALPHA, _THETA, _Q, _BETA, _PHI, _P, _PSI, _R, _LAT, _LON, _ALT = range(12)
_THR, _DA, _DE, _DR = range(4)


@dataclass(frozen=True)
class AutopilotGains:
    """Autopilot gains and filter constants, SI (rad, m, s; surface and throttle commands normalized)."""

    k_theta: float
    """Elevator per pitch-attitude error, 1/rad."""
    k_q: float
    """Elevator per pitch rate, s/rad."""
    k_gs_p: float
    """Pitch command per glidepath deviation, rad/m."""
    k_gs_d: float
    """Pitch command per glidepath deviation rate, rad s/m."""
    k_gs_i: float
    """Pitch command per integrated glidepath deviation, rad/(m s)."""
    k_v_p: float
    """Throttle per filtered airspeed error, s/m."""
    k_v_i: float
    """Throttle per integrated filtered airspeed error, 1/m."""
    tau_v_s: float
    """Time constant of the first-order filter on the airspeed error, s."""
    k_phi: float
    """Aileron per bank error, 1/rad."""
    k_p: float
    """Aileron per roll rate, s/rad."""
    k_beta: float
    """Rudder per sideslip, 1/rad."""
    k_loc_p: float
    """Bank command per cross-track deviation, rad/m."""
    k_loc_d: float
    """Bank command per cross-track rate, rad s/m."""
    k_loc_i: float
    """Bank command per integrated cross-track deviation, rad/(m s)."""
    bank_limit_rad: float
    """Bank command limit, rad."""
    pitch_limit_rad: float
    """Limit of the pitch command's departure from the trim pitch, rad."""
    tau_wind_s: float = 20.0
    """Autothrottle speed complement: time constant of the low-pass on TAS - ground speed (the wind along the
    path); the speed fed back is ground speed + that wind, so gusts shorter than this do not move the throttle
    (inertially smoothed speed, as transport autothrottles use). In still air it equals the airspeed."""
    flare_height_m: float = 50.0 * units.FT
    """Main-gear height above the terrain where the flare starts (landing runs only), m."""
    touchdown_sink_mps: float = 2.0 * units.FPS
    """Sink rate the flare aims to touch down with, m/s."""
    k_flare: float = 0.05
    """Pitch command per sink-rate error in the flare, rad s/m."""
    k_flare_i: float = 0.02
    """Pitch command per integrated sink-rate error in the flare, rad/m."""
    retard_height_m: float = 25.0 * units.FT
    """Main-gear height where the throttle goes to idle in the flare, m."""
    tecs: bool = False
    """Speed and path law: True the total energy control law (TECS), False the classic one (autopilot.py).
    The TECS defaults below are PX4's (for an aircraft file without TECS gains); the 737 file's are tecs_gains'."""
    tecs_t_h_s: float = 5.0
    """TECS height time constant T_h: height-rate setpoint h'_gp - d / T_h, s (PX4 FW_T_ALT_TC)."""
    tecs_t_v_s: float = 5.0
    """TECS speed time constant T_V: acceleration setpoint (V_c - V) / T_V, s (PX4 FW_T_TAS_TC)."""
    tecs_thr_per_rad: float = 3.44
    """TECS K_thr: throttle per rad of total-energy rate (g / (dV'/d throttle) of the linearization)."""
    tecs_k_thr_damp: float = 0.05
    """TECS throttle damping on the total-energy rate error, in units of K_thr (PX4 FW_T_THR_DAMPING)."""
    tecs_k_thr_i: float = 0.05
    """TECS throttle integral of the total-energy rate error, 1/s in units of K_thr (PX4 FW_T_I_GAIN_THR)."""
    tecs_k_pitch_damp: float = 0.1
    """TECS pitch damping: rad of pitch per rad of energy-balance rate error (PX4 FW_T_PTCH_DAMP)."""
    tecs_k_pitch_i: float = 0.1
    """TECS pitch integral of the energy-balance rate error, 1/s (PX4 FW_T_I_GAIN_PIT)."""
    tecs_seb_ff: float = 1.0
    """TECS pitch feed-forward of the energy-balance rate setpoint (PX4 FW_T_SEB_R_FF)."""
    tecs_spd_weight: float = 1.0
    """TECS speed weighting: 1 balances height and speed (PX4 FW_T_SPDWEIGHT)."""
    tecs_rate_tau_s: float = 0.4
    """TECS washout time constant of the speed derivative, s (PX4 FW_T_STE_R_TC)."""
    tecs_sink_max_mps: float = 1000.0 * units.FT / 60.0
    """TECS height-rate setpoint floor (maximum sink), m/s."""
    tecs_climb_max_mps: float = 3.0
    """TECS height-rate setpoint ceiling (maximum climb), m/s (PX4 FW_T_CLMB_R_SP)."""
    tecs_vert_acc_mps2: float = 7.0
    """TECS pitch-command rate limit as a vertical acceleration: dt a / V per step, m/s^2 (PX4 FW_T_VERT_ACC)."""
    align_height_m: float = 0.0
    """Main-gear height below which the decrab aligns the heading with the runway (landing runs), m; 0: none."""
    align_tau_s: float = 1.5
    """Decrab time constant: yaw-rate command -crab / tau, s."""
    k_r_align: float = 0.0
    """Decrab rudder per yaw-rate error, s/rad."""
    k_beta_align: float = 0.0
    """Decrab rudder per sideslip (the rudder that holds it), 1/rad."""
    k_phi_align: float = 0.0
    """Decrab bank command per sideslip (the bank whose side force balances it), rad/rad."""
    k_da_align: float = 0.0
    """Decrab aileron per sideslip (the aileron that holds the dihedral roll moment), 1/rad."""
    align_bank_max_rad: float = math.inf
    """Decrab bank allowance: the largest bank the held sideslip may need, rad; the sideslip is limited to
    align_bank_max / (k_phi_align (V_c / align_cas)^2) and the rest of the wind correction stays as crab
    (inf: full decrab)."""
    align_cas_mps: float = 0.0
    """Calibrated airspeed of the linearization k_phi_align comes from, m/s (the bank per sideslip scales with the
    dynamic pressure: k_phi_align (V_c / align_cas)^2 at the approach speed V_c; 0: not scheduled)."""
    align_sideslip_max_rad: float = math.inf
    """Decrab sideslip limit, rad (the 737 MAX alignment mode's 5 deg): the sideslip is limited to the smaller of
    this and the bank allowance's align_bank_max / k_pb; the rest of the wind correction stays as crab."""
    flare_t_path_s: float = 0.0
    """Flare feed-forward: the flight-path lag behind pitch at constant speed, T_theta2 = -1 / Z_alpha' (the
    landing linearization's alpha-row alpha coefficient), s; the pitch command leads the commanded path angle by
    it (0: no lead term). The path-angle change itself is always fed forward."""
    flare_k_v: float = 0.0
    """Flare feed-forward: pitch per airspeed lost since flare entry at constant lift and path angle,
    A_alpha,V / (A_alpha,alpha + A_alpha,theta) of the landing linearization, rad s/m (0: none)."""
    flare_k_gust: float = 0.0
    """Flare feed-forward: pitch per airspeed gust (true airspeed above the inertially smoothed air-mass speed) at
    constant lift, A_alpha,V / A_alpha,alpha of the landing linearization (Z_V / Z_alpha), rad s/m (0: none)."""
    flare_ge_k: float = 0.0
    """Flare feed-forward of ground effect: the lift factor's rise at the ground, k_ge(h) = 1 + flare_ge_k
    exp(-h_arp / flare_ge_decay_m) (a fit to the JSBSim model's kCLge table), h_arp the aerodynamic reference
    point's height (the main gear's plus flare_ge_arp_m); the pitch command gives back the angle of attack that
    the extra lift makes up, (k_v V_0 / 2) ln(k_ge(h) / k_ge(h_entry)) (0: none)."""
    flare_ge_decay_m: float = 1.0
    """Height over which the ground-effect lift factor's rise falls by e, m."""
    flare_ge_arp_m: float = 0.0
    """Height of the aerodynamic reference point above the main gear's contact point, m."""
    flare_pitch_min_rad: float = -math.pi / 2.0
    """Floor of the flare's pitch command above the runway surface's own pitch, rad."""
    flare_pitch_min_height_m: float = 0.0
    """Main-gear height below which the floor holds, m."""


@dataclass(frozen=True)
class Linearization:
    """The FGLinearization of the trimmed aircraft (JSBSim units, as JSBSim gives them) and its trim point."""

    A: Array
    """(12, 12) system matrix, states Vt (ft/s), alpha, theta, q, beta, phi, p, psi, r (rad, rad/s), lat, lon,
    alt (ft)."""
    B: Array
    """(12, 4) input matrix, inputs throttle, aileron, elevator, rudder commands (normalized)."""
    vt_mps: float
    """Trim true airspeed, m/s."""
    gamma_rad: float
    """Trim flight-path angle, rad."""


@dataclass(frozen=True)
class ClosedLoop:
    """The linear closed loop with one loop broken: x' = A x + B w, u = C x (u: the controller's output at the
    break, w: what the plant receives there). The loop transfer function is L = -C (sI - A)^-1 B."""

    A: Array
    B: Array
    C: Array


def _si_plant(lin: Linearization) -> tuple[Array, Array, list[int]]:
    """The linearization in SI (Vt m/s, alt m) and the indices of the 9 rigid-body states kept
    (Vt, alpha, theta, q, beta, phi, p, psi, r); the altitude row gives h' for the glidepath deviation."""
    keep = [_VT, _ALPHA, _THETA, _Q, _BETA, _PHI, _P, _PSI, _R]
    scale = np.ones(12)
    scale[_VT] = units.FPS
    scale[_ALT] = units.FT
    a_si = (scale[:, None] * lin.A) / scale[None, :]
    b_si = scale[:, None] * lin.B
    return a_si, b_si, keep


def closed_loop(lin: Linearization, g: AutopilotGains, glidepath_rad: float, engine_lag_s: float,
                break_at: str | None) -> ClosedLoop:
    """The linear aircraft + autopilot with the loop `break_at` (one of LOOPS, or None) opened.

    State: 9 rigid-body states, then d, int d, y, int y, v_f, int e_f, engine thrust state (16 in all).
    """
    if break_at is not None and break_at not in LOOPS:
        raise ValueError(f"break_at must be one of {LOOPS} or None, got {break_at!r}")
    a_si, b_si, keep = _si_plant(lin)
    n_r = len(keep)
    iD, iZD, iY, iZY, iVF, iZV, iENG = range(n_r, n_r + 7)
    n = n_r + 7
    ix = {s: i for i, s in enumerate(keep)}
    v0 = lin.vt_mps
    gs = math.tan(glidepath_rad) * math.cos(lin.gamma_rad)

    # rows of the signals as linear functions of the state (controller outputs before the break)
    def row() -> Array:
        return np.zeros(n)

    # d' = h' + tan(gp) x', x' ~ cos(gamma0) Vt: the altitude-rate row of the linearization plus the path term
    d_dot = row()
    d_dot[:n_r] = a_si[_ALT, keep]
    d_dot[ix[_VT]] += gs
    y_dot = row()  # y' = V0 (psi + beta): ground track relative to the runway heading
    y_dot[ix[_PSI]] = v0
    y_dot[ix[_BETA]] = v0

    theta_c = row()  # perturbation of the pitch command
    thr = row()
    if g.tecs:
        # TECS (autopilot.py), linearized without its limits. States reused: iZD int E_B, iVF the speed washout
        # V_l, iZV int E_T. V' = (Vt - V_l) / tau_r; h' = the altitude row; h'_gp = h' - d'.
        g0 = units.G0
        v_dot = row()
        v_dot[ix[_VT]] = 1.0 / g.tecs_rate_tau_s
        v_dot[iVF] = -1.0 / g.tecs_rate_tau_s
        vd_c = row()
        vd_c[ix[_VT]] = -1.0 / g.tecs_t_v_s
        sp_h = row()  # (h'_c - h'_gp) / V = -d / (T_h V)
        sp_h[iD] = -1.0 / (g.tecs_t_h_s * v0)
        e_h = sp_h - d_dot / v0  # (h'_c - h') / V
        e_v = (vd_c - v_dot) / g0
        wk = min(max(g.tecs_spd_weight, 0.0), 1.0)
        wp = min(max(2.0 - g.tecs_spd_weight, 0.0), 1.0)
        e_t = e_h + e_v
        e_b = wp * e_h - wk * e_v
        t_sp = sp_h + vd_c / g0
        b_sp = wp * sp_h - wk * vd_c / g0
        theta_c = g.tecs_seb_ff * b_sp + g.tecs_k_pitch_damp * e_b
        theta_c[iZD] += g.tecs_k_pitch_i
        thr = g.tecs_thr_per_rad * (t_sp + g.tecs_k_thr_damp * e_t)
        thr[iZV] += g.tecs_thr_per_rad * g.tecs_k_thr_i
    else:
        theta_c[iD] = -g.k_gs_p
        theta_c -= g.k_gs_d * d_dot
        theta_c[iZD] = -g.k_gs_i
        thr[iVF] = -g.k_v_p  # e_f = -v_f (speed error = command - speed)
        thr[iZV] = g.k_v_i
    phi_c = row()
    phi_c[iY] = -g.k_loc_p
    phi_c -= g.k_loc_d * y_dot
    phi_c[iZY] = -g.k_loc_i

    # signals: the outer-loop commands, possibly replaced by the break input w
    w_theta = break_at == "glidepath"
    w_phi = break_at == "localizer"
    theta_c_used = row() if w_theta else theta_c
    phi_c_used = row() if w_phi else phi_c
    # elevator: de = -k_theta (theta_c - theta) + k_q q, plus -k_theta w when the glidepath loop is broken
    de = -g.k_theta * theta_c_used
    de[ix[_THETA]] += g.k_theta
    de[ix[_Q]] += g.k_q
    da = g.k_phi * phi_c_used
    da[ix[_PHI]] -= g.k_phi
    da[ix[_P]] -= g.k_p
    dr = row()
    dr[ix[_BETA]] = -g.k_beta

    ctrl = {"elevator": de, "throttle": thr, "aileron": da, "rudder": dr}
    A = np.zeros((n, n))
    Bw = np.zeros((n, 1))
    # plant inputs: throttle goes through the engine lag; surfaces act at once
    b_thr, b_da, b_de, b_dr = (b_si[keep, j] for j in range(4))
    A[:n_r, :n_r] = a_si[np.ix_(keep, keep)]
    A[:n_r, iENG] += b_thr
    for name, b in (("aileron", b_da), ("elevator", b_de), ("rudder", b_dr)):
        if break_at == name:
            Bw[:n_r, 0] += b
        else:
            A[:n_r, :] += np.outer(b, ctrl[name])
    if w_theta:  # the pitch loop receives theta_c = w
        Bw[:n_r, 0] += b_de * (-g.k_theta)
    if w_phi:
        Bw[:n_r, 0] += b_da * g.k_phi
    A[iD, :] = d_dot
    A[iY, :] = y_dot
    A[iZY, iY] = 1.0
    if g.tecs:
        A[iZD, :] = e_b
        A[iVF, :] = v_dot
        A[iZV, :] = e_t
    else:
        A[iZD, iD] = 1.0
        A[iVF, ix[_VT]] = 1.0 / g.tau_v_s
        A[iVF, iVF] = -1.0 / g.tau_v_s
        A[iZV, iVF] = -1.0
    A[iENG, iENG] = -1.0 / engine_lag_s
    if break_at == "throttle":
        Bw[iENG, 0] = 1.0 / engine_lag_s
    else:
        A[iENG, :] += thr / engine_lag_s
    if break_at is None:
        C = np.zeros((1, n))
    else:
        C = {"glidepath": theta_c, "localizer": phi_c}.get(break_at, ctrl.get(break_at))[None, :]
    return ClosedLoop(A=A, B=Bw, C=C)


def loop_transfer(cl: ClosedLoop) -> control.StateSpace:
    """L(s) of a broken loop, sign chosen for python-control's negative-feedback convention."""
    import control

    return control.ss(cl.A, cl.B, -cl.C, np.zeros((1, 1)))


@dataclass(frozen=True)
class LoopMargin:
    """Margins of one broken loop: worst gain margin (dB, either direction), worst phase margin (deg),
    gain-crossover frequency (rad/s)."""

    loop: str
    gm_db: float
    pm_deg: float
    wc_rad_s: float


def margins(L: control.StateSpace) -> tuple[float, float, float]:
    """Worst gain margin (dB, up or down), worst phase margin (deg) and the first gain crossover (rad/s)."""
    import control

    with np.errstate(over="ignore", invalid="ignore"):  # polynomial root finding on high-gain test loops
        gm, pm, _sm, wpc, wgc, _wms = control.stability_margins(L, returnall=True)
    gm = np.atleast_1d(np.asarray(gm, dtype=float))
    pm = np.atleast_1d(np.asarray(pm, dtype=float))
    wgc = np.atleast_1d(np.asarray(wgc, dtype=float))
    gm_db = float(np.min(np.abs(20.0 * np.log10(gm[np.isfinite(gm) & (gm > 0)])))) if np.any(
        np.isfinite(gm) & (gm > 0)) else math.inf
    pm_deg = float(np.min(np.abs(pm))) if pm.size else math.inf
    wc = float(np.min(wgc)) if wgc.size else math.nan
    return gm_db, pm_deg, wc


def loop_margins(lin: Linearization, g: AutopilotGains, glidepath_rad: float, engine_lag_s: float) -> list[LoopMargin]:
    """Gain and phase margin of every loop in LOOPS, broken one at a time with the others closed."""
    out = []
    for name in LOOPS:
        gm_db, pm_deg, wc = margins(loop_transfer(closed_loop(lin, g, glidepath_rad, engine_lag_s, name)))
        out.append(LoopMargin(loop=name, gm_db=gm_db, pm_deg=pm_deg, wc_rad_s=wc))
    return out


def bank_per_sideslip(lin: Linearization) -> float:
    """Bank angle (rad) per rad of steady sideslip held by the rudder, from the lateral trim equations of the
    linearization: the rudder that balances the yaw moment, k_beta = -N_beta / N_dr, and the bank whose gravity
    component balances the side force, phi / beta = -(Y_beta + Y_dr k_beta) / (g cos(theta) / V) (the beta row's
    phi coefficient). The decrab's k_phi_align; proportional to the dynamic pressure at a given weight."""
    a, b = lin.A, lin.B
    k_beta = -a[_R, _BETA] / b[_R, _DR]
    return float(-(a[_BETA, _BETA] + b[_BETA, _DR] * k_beta) / a[_BETA, _PHI])


def closed_loop_poles(lin: Linearization, g: AutopilotGains, glidepath_rad: float, engine_lag_s: float) -> Array:
    """Eigenvalues of the fully closed linear loop (all real parts must be negative), 1/s."""
    return np.linalg.eigvals(closed_loop(lin, g, glidepath_rad, engine_lag_s, None).A)


def tecs_gains(g: AutopilotGains, vt_mps: float, spd_weight: float) -> dict[str, float]:
    """TECS gains designed from the classic law's loop-shaped ones (the aircraft file's TECS section holds them,
    evaluated at the default profile's trim TAS vt_mps): {field of AutopilotGains: value}.

    Lambregts' structure (Lambregts, "Functional integration of vertical flight path and speed control using energy
    principles", 1983; Faleiro & Lambregts, "Analysis and tuning of a 'Total Energy Control System' control law
    using eigenstructure assignment", 1999): thrust = K_TP (total-energy rate) + K_TI int(its error), elevator (here
    the pitch command) = K_EP (distribution rate) + K_EI int(its error), rates as angles (gamma +- V'/g); in
    autopilot.py's notation K_TP = K_thr k_td, K_TI = K_thr k_ti, K_EP = k_pd, K_EI = k_pi, and the path and speed
    errors enter through h'_c = h'_gp - d / T_h and V'_c = (V_c - V) / T_V. The published TSRV 737 gains (Bruce,
    NASA-CR-178285, 1987) were not found, so the gains are derived here, in three steps:

    1. Pitch at fixed speed. With e_v = 0 the pitch command is -(k_pd d' + (k_pi + k_pd / T_h) d + (k_pi / T_h)
       int d) / V (seb_ff = 0): the classic glidepath PID when k_pd = k_gs_d V, k_pi + k_pd / T_h = k_gs_p V and
       k_pi / T_h = k_gs_i V; T_h is the larger root of k_gs_i V T^2 - k_gs_p V T + k_pd = 0 (integral-dominated,
       as Lambregts' integral on the error; the smaller root puts the same PID in the setpoint path instead).
    2. The elevator's share. At constant thrust V'/g = -dgamma in the short term (point mass), so the elevator moves
       the distribution rate w_p gamma - w_k V'/g by (w_p + w_k) dgamma: k_pd and k_pi are divided by w_p + w_k
       (with w_k = 0, path priority, they are the classic law's; with equal weights, half).
    3. Thrust at fixed path. With e_h = 0 the throttle is K_thr / g ((1 + k_td) / T_V + k_ti) e + K_thr k_ti / (g
       T_V) int e + K_thr k_td / g e' for a speed error e: the classic autothrottle's PI when the first two are
       k_v_p and k_v_i; Lambregts' K_TP / K_TI = K_EP / K_EI (equal proportional-to-integral ratios of the two
       channels, which keeps their responses alike) fixes k_td, and T_V is again the larger root.
    """
    wk = min(max(spd_weight, 0.0), 1.0)
    wp = min(max(2.0 - spd_weight, 0.0), 1.0)
    v = vt_mps
    k_pd = g.k_gs_d * v
    a, b = g.k_gs_i * v, g.k_gs_p * v
    t_h = (b + math.sqrt(b * b - 4.0 * a * k_pd)) / (2.0 * a)
    k_pi = a * t_h
    share = wp + wk
    k_pd, k_pi = k_pd / share, k_pi / share
    p, i = g.k_v_p * units.G0 / g.tecs_thr_per_rad, g.k_v_i * units.G0 / g.tecs_thr_per_rad
    k_td = 0.0
    for _ in range(200):  # fixed point of k_td = (k_pd / k_pi) k_ti(k_td); contracts (ratio ~0.6 per pass)
        t_v = (p + math.sqrt(p * p - 4.0 * i * (1.0 + k_td))) / (2.0 * i)
        k_td_new = k_pd / k_pi * i * t_v
        if abs(k_td_new - k_td) < 1e-12:
            break
        k_td = k_td_new
    t_v = (p + math.sqrt(p * p - 4.0 * i * (1.0 + k_td))) / (2.0 * i)
    return {"tecs_t_h_s": t_h, "tecs_k_pitch_damp": k_pd, "tecs_k_pitch_i": k_pi, "tecs_seb_ff": 0.0,
            "tecs_t_v_s": t_v, "tecs_k_thr_damp": k_td, "tecs_k_thr_i": i * t_v, "tecs_spd_weight": spd_weight}
