"""Approach autopilot: glide path and localizer guidance, pitch and roll inner loops, speed; flare and decrab.

Guidance flies on the navigation source's position (runway frame) and NED velocity; the inner loops use the
aircraft's own attitude, body rates, sideslip and calibrated airspeed (AHRS and air data). The glide path is the
straight ILS cone of approachsim.glidepath (d, d' its deviation and rate). Two laws for speed and path, chosen by
the aircraft file's `law` (approachsim.flight.design checks either's linearization loop at a time):

Common to both:

    w   <- w + dt/tau_w (V_tas - |v_ground| - w)                   wind along the path (complementary filter)
    V   = V_cas (|v_ground| + w) / V_tas                           inertially smoothed CAS (= V_cas in still air)
    de  = -k_theta (theta_c - theta) + k_q q                       elevator, added to the trimmed pitch trim
    phi_c = -(k_loc_p y + k_loc_d y' + k_loc_i int y)              limited to +- bank_limit
    da  = k_phi (phi_c - phi) - k_p p                              aileron
    dr  = -k_beta beta                                             rudder (crab into the wind; FCS adds a yaw damper)

law = "classic" (glidepath to pitch, speed to throttle, each loop alone):

    theta_c = theta_0 - (k_gs_p d + k_gs_d d' + k_gs_i int d)      limited to theta_0 +- pitch_limit
    e_f <- e_f + dt/tau_v (V_c - V - e_f)                          filtered speed error (turbulence)
    thr = thr_0 + k_v_p e_f + k_v_i int e_f                        autothrottle (integral frozen at saturation)

law = "tecs" (total energy control, Lambregts 1983, in the structure of PX4's TECS by P. Riseborough, normalised
by g V so that every energy rate is a flight-path angle, rad):

    V' = (V - V_l) / tau_r,  V_l <- V_l + dt V'                    acceleration of the smoothed speed (washout)
    h'_c = clip(h'_gp - d / T_h, -sink_max, climb_max)             height-rate setpoint, h'_gp = h' - d'
    V'_c = clip((V_c - V) / T_V, +- 0.5 / K_thr)                   acceleration setpoint
    e_h = (h'_c - h') / V,  e_v = (V'_c - V') / g                  path and speed errors as angles
    E_T = e_h + e_v,  E_B = w_p e_h - w_k e_v                      total-energy and energy-balance rate errors
    T_sp = (h'_c - h'_gp) / V + V'_c / g,  B_sp = w_p (h'_c - h'_gp) / V - w_k V'_c / g   setpoints (feed-forward)
    thr = thr_0 + K_thr (T_sp + k_td E_T + k_ti int E_T)           thrust from the total energy rate
    theta_c = theta_0 + k_bff B_sp + k_pd E_B + k_pi int E_B       pitch from the energy distribution, limited to
                                                                   theta_0 +- pitch_limit and to a change of
                                                                   dt a_vert / V per step (integrals frozen there)

K_thr (throttle per rad of energy-rate) is g / (dV'/d thr) of the aircraft's linearization: PX4 scales its
throttle terms by the throttle range over the total-energy-rate range, which is the same number when thrust is
linear in throttle. w_k = clip(spd_weight, 0, 1), w_p = clip(2 - spd_weight, 0, 1). The other gains are designed
from the classic law's by approachsim.flight.design.tecs_gains (Lambregts' K_EP = k_pd, K_EI = k_pi, K_TP = K_thr
k_td, K_TI = K_thr k_ti): at fixed speed the pitch channel is the classic glidepath PID divided by the elevator's
share w_p + w_k of the distribution rate, at fixed path the thrust channel is the classic autothrottle PI, and
K_TP / K_TI = K_EP / K_EI.

Landing runs (h_gear: main-gear height above the terrain, the radio altitude) add:

* an exponential flare from flare_height (Stevens & Lewis style, approachsim's reference notes sec. 5) on the main
  gear's height: the sink-rate command h'_c = -(h_gear - h_off) / tau with tau and h_off set at flare entry from the
  sink rate s_0 there, so that the command starts at the aircraft's sink rate (continuity: h_f - h_off = tau s_0)
  and ends at the touchdown sink (h_off = -tau s_td): tau = h_f / (s_0 - s_td). The sink rate fed back is the
  guidance point's, s = v_down (the main gear's, l_g behind it, adds l_g q: a non-minimum-phase term that, fed back,
  would cancel the pitch loop's rate damping), and the pitch command feeds the commanded path forward:
      s_c = (h_gear - h_off) / tau,  e = s - s_c  (> 0: sinking too fast)
      theta_c = theta_entry + (s_0 - s_c) / V + T_theta2 s / (tau V) + k_v (V_0 - V) - k_u u_g
                - (k_v V_0 / 2) ln(k_ge(h_gear) / k_ge(h_f)) + k_flare e + k_flare_i int e
  At constant speed and angle of attack the path angle follows pitch one for one, gamma / theta = 1 / (1 + T_theta2
  s) (T_theta2 = -1 / Z_alpha', the landing linearization's), so the pitch that flies the commanded path angle
  gamma_c = -s_c / V is gamma_c + T_theta2 gamma_c' with gamma_c' = s / (tau V): the first two terms; k_v (V_0 - V)
  is the angle of attack that holds the lift as the speed V (the smoothed true airspeed) falls below its entry
  value V_0; k_u u_g (k_u = A[alpha, V] / A[alpha, alpha]) the angle of attack that holds it through the airspeed
  gust u_g = V_tas - V (the true airspeed above the inertially smoothed air-mass speed); the ln term gives back
  the angle of attack that ground effect's extra lift makes up (lift factor k_ge(h) = 1 + k_g exp(-(h + h_arp) /
  h_g), a fit to the aircraft model's ground-effect table; (k_v V_0 / 2) = C_L / C_L_alpha); the PI on e takes up
  what they leave. The throttle goes to idle below retard_height (0: thrust kept to contact). Below
  pitch_min_height the pitch command is held at least at the nose-gear floor theta_min + atan(runway slope) (the
  pitch at which the main gear touches first and takes the weight before the nose gear, with a margin: the aircraft
  file), the integral frozen while it holds, and the throttle is at idle while it holds: a flare the floor holds has
  more lift than it wants (it is fast: a tailwind's fall toward the ground raises the airspeed), so the speed the
  floor keeps off the pitch is bled rather than floated.
* a runway alignment below align_height (the 737 MAX's alignment mode engages at 450 ft radio altitude, 737 MAX
  FCOM): the rudder turns the heading onto the runway's and holds the sideslip that the crosswind then needs (the
  737 FCTM's sideslip technique: "prior to the flare the airplane centerline is aligned on or parallel to the
  runway centerline", upwind wing low; the localizer loop banks into the wind to hold the track):
  r_c = -(crab - crab_res) / tau_align,  dr = k_r_align (r - r_c) + k_beta_align beta,
  crab = psi - runway heading. k_beta_align = -N_beta / N_dr holds the sideslip (yaw moment balance),
  k_r_align = (1/tau_r + N_r) / -N_dr puts the yaw-rate loop's pole at -1/tau_r, tau_r = tau_align / 3
  (linearization derivatives; the aircraft file has them). The decrab is partial in a strong crosswind (737 MAX
  alignment mode: "Sideslip is limited to 5 degrees"): the bank that holds a sideslip beta is k_pb beta,
  k_pb = k_phi_align (V_c / V_design)^2 (the side-force balance -(Y_beta + Y_dr k_beta_align) / (g / V) of the
  linearization, proportional to the dynamic pressure), so the sideslip is limited to
  b_max = min(sideslip_max, bank_max / k_pb) (the bank allowance binds at high speed, the 5 deg below) and
  the rest of the wind correction eta = crab + beta (the air-relative track's angle to the runway, which the yaw
  manoeuvre only shares out between crab and sideslip) stays as crab: crab_res = eta - clip(eta, -b_max, b_max)
  (0 when |eta| <= b_max: the full decrab); the bank command adds k_pb beta, the aileron k_da_align beta. While
  aligning, the localizer loop steers the main gears' centre, l_g behind the guidance point, onto the centreline:
  y_g = y - l_g sin(crab), y_g' = y' - l_g cos(crab) r (in the crab that is left the gear trails downwind of
  the guidance point, 0.5 m at 3 deg).

Sign conventions of the 737 FCS: + elevator = nose down, + aileron = roll right, + rudder = nose left.
This class is the readable oracle; the flight loop runs its compiled twin (core/loop/flight_step.autopilot_step, equal
to it bit for bit: tests/unit/flight/test_flight_loop_kernels.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from approachsim.flight.design import AutopilotGains
from approachsim.geo import radii
from approachsim.glidepath import GlidePath, deviation_and_rate
from approachsim.units import G0


@dataclass(frozen=True)
class Trim:
    """The trimmed state the autopilot regulates about."""

    theta_rad: float
    throttle: float
    cas_mps: float
    """Commanded calibrated airspeed, m/s."""


@dataclass(frozen=True)
class Geometry:
    """Approach geometry the guidance needs: runway heading, glidepath angle, threshold crossing height."""

    heading_rad: float
    glidepath_rad: float
    tch_m: float
    threshold_lat_rad: float
    """Geodetic latitude of the threshold: the local north turns by the meridian convergence as the aircraft
    moves east of it (dpsi = d_east sin(lat) / (R_E cos(lat)), 0.1 deg at 10 nmi), which rotates the runway
    axes seen in the aircraft's NED frame."""


class Autopilot:
    """The approach autopilot of one run: holds its integrators and filter state (re-create per run)."""

    def __init__(self, gains: AutopilotGains, trim: Trim, geometry: Geometry, dt_s: float, *,
                 gear_arm_m: float = 0.0) -> None:
        self.g = gains
        self.gear_arm_m = gear_arm_m
        """Distance along the body x axis from the guidance point (the IMU) back to the main gears' centre, m
        (JSBSim model geometry, flight/run.Approach.gear_arm_m): the alignment steers the main gear onto the
        centreline, the flare regulates the main gear's sink rate."""
        self.trim = trim
        self.dt = dt_s
        self.heading_rad = geometry.heading_rad
        self.ch = math.cos(geometry.heading_rad)
        self.sh = math.sin(geometry.heading_rad)
        self.tan_gp = math.tan(geometry.glidepath_rad)
        self.tch_m = geometry.tch_m
        self.cone = GlidePath(geometry.glidepath_rad, geometry.tch_m, geometry.heading_rad,
                              geometry.threshold_lat_rad)
        """The straight glide path cone guidance flies (approachsim.glidepath)."""
        _, self.x_gpi_m, self.cone_a, self.cone_b, self.cone_c = self.cone.constants()
        lat0 = geometry.threshold_lat_rad
        r_e = float(radii(lat0)[1])
        self.conv_per_east_m = math.sin(lat0) / (r_e * math.cos(lat0))
        """Meridian convergence per metre east of the threshold, rad/m."""
        self.int_d = 0.0
        self.int_y = 0.0
        self.e_f = 0.0
        self._w = math.nan  # wind along the path, m/s (initialised at the first step)
        self.int_e = 0.0
        self.flaring = False
        self._theta_flare0 = 0.0
        self._int_flare = 0.0
        self._theta_c = trim.theta_rad
        self._v_lag = math.nan  # TECS: washout state of the smoothed speed, m/s
        self.int_t = 0.0  # TECS: integral of the total-energy rate error, rad s
        self.int_b = 0.0  # TECS: integral of the energy-balance rate error, rad s
        self._flare_tau = 0.0
        self._flare_h_off = 0.0
        self.aligning = False
        self._flare_sink0 = 0.0  # the sink rate at flare entry (at least touchdown sink + 0.1), m/s
        self._flare_v0 = 0.0  # the smoothed true airspeed at flare entry, m/s
        self.surface_slope = 0.0
        """Slope of the terrain under the main gear, rise per metre along the runway (the flight loop sets it each
        step on landing runs over a terrain profile): the flare's sink rate is the gear's closing speed on it."""

    def deviations(self, x: float, y: float, z: float, vn: float, ve: float, vd: float) -> tuple[float, ...]:
        """Glidepath deviation d (m, + above the cone), its rate (m/s), cross-track y (m, + right) and its rate
        (m/s)."""
        ch, sh = self.ch, self.sh
        conv = (x * sh + y * ch) * self.conv_per_east_m  # runway heading in the local NED minus at the threshold
        x0 = vn * ch + ve * sh
        y0 = -vn * sh + ve * ch
        x_dot = x0 + conv * y0  # small-angle rotation by the convergence (|conv| < 0.01 rad)
        y_dot = y0 - conv * x0
        d, d_dot = deviation_and_rate(x, y, z, x_dot, y_dot, -vd, self.tan_gp, self.x_gpi_m, self.cone_a, self.cone_b,
                                   self.cone_c)
        return d, d_dot, y, y_dot

    def step(
        self,
        x: float, y: float, z: float, vn: float, ve: float, vd: float,
        phi: float, theta: float, p: float, q: float, beta: float, cas: float, h_gear: float | None = None,
        tas: float | None = None, yaw: tuple[float, float] | None = None,
    ) -> tuple[float, float, float, float]:
        """One control step: guidance position (runway frame, m) and NED velocity (m/s), attitude (rad),
        body rates (rad/s), sideslip (rad), calibrated airspeed (m/s) -> elevator, aileron, rudder, throttle.
        h_gear: main-gear height above the terrain (m) on landing runs (the radio altitude; None: no flare).
        tas: true airspeed (m/s) for the speed complement (None: the autothrottle holds the raw CAS).
        yaw: (psi, r) true heading (rad) and yaw rate (rad/s) for the alignment (None: no alignment)."""
        g = self.g
        dt = self.dt
        v_air = cas  # the smoothed true airspeed (the air-mass speed) when TAS is given
        if tas is not None and tas > 1.0:  # inertially smoothed speed (module docstring)
            gs = math.sqrt(vn * vn + ve * ve + vd * vd)
            if self._w != self._w:
                self._w = tas - gs
            self._w += dt / g.tau_wind_s * (tas - gs - self._w)
            v_air = gs + self._w
            cas = cas * v_air / tas
        # deviations (as deviations(), inlined: this runs every step)
        ch, sh = self.ch, self.sh
        conv = (x * sh + y * ch) * self.conv_per_east_m
        x0 = vn * ch + ve * sh
        y0 = -vn * sh + ve * ch
        y_dot = y0 - conv * x0
        d, d_dot = deviation_and_rate(x, y, z, x0 + conv * y0, y_dot, -vd, self.tan_gp, self.x_gpi_m, self.cone_a,
                                   self.cone_b, self.cone_c)
        lim = g.pitch_limit_rad
        if g.tecs:
            theta_c, thr = self._tecs(d, d_dot, -vd, cas)
        else:
            # glidepath -> pitch command (integral frozen while the command is limited)
            th_off = -(g.k_gs_p * d + g.k_gs_d * d_dot + g.k_gs_i * self.int_d)
            if -lim < th_off < lim:
                self.int_d += d * dt
            else:
                th_off = lim if th_off > 0.0 else -lim
            theta_c = self.trim.theta_rad + th_off
            # autothrottle on the filtered speed error
            self.e_f += dt / g.tau_v_s * (self.trim.cas_mps - cas - self.e_f)
            thr = self.trim.throttle + g.k_v_p * self.e_f + g.k_v_i * self.int_e
            if 0.0 < thr < 1.0:
                self.int_e += self.e_f * dt
            else:
                thr = 1.0 if thr >= 1.0 else 0.0
        if h_gear is not None and (self.flaring or h_gear <= g.flare_height_m):
            # the guidance point's (module docstring: why not the main gear's), closing on a sloped surface as the
            # radio altitude sees it: h' = -vd - slope x'
            sink = vd + self.surface_slope * x0
            gust = tas - v_air if tas is not None and tas > 1.0 else 0.0  # the airspeed gust about the air mass
            theta_c, thr = self._flare(h_gear, sink, v_air, gust, thr)
        self._theta_c = theta_c
        de = -g.k_theta * (theta_c - theta) + g.k_q * q
        psi, r = yaw if yaw is not None else (math.nan, 0.0)
        aligning = h_gear is not None and yaw is not None and (self.aligning or h_gear <= g.align_height_m)
        crab = 0.0
        if aligning:
            self.aligning = True
            crab = _wrap(psi - (self.heading_rad + conv))
            # the main gears' centre, gear_arm behind the guidance point, is what the alignment puts on the
            # centreline: its cross-track and rate
            y = y - self.gear_arm_m * math.sin(crab)
            y_dot = y_dot - self.gear_arm_m * math.cos(crab) * r
        # localizer -> bank command
        phi_c = -(g.k_loc_p * y + g.k_loc_d * y_dot + g.k_loc_i * self.int_y)
        blim = g.bank_limit_rad
        if -blim < phi_c < blim:
            self.int_y += y * dt
        else:
            phi_c = blim if phi_c > 0.0 else -blim
        if aligning:
            k_pb = g.k_phi_align  # bank per sideslip at the approach speed (dynamic pressure ratio)
            if g.align_cas_mps > 0.0:
                sq = self.trim.cas_mps / g.align_cas_mps
                k_pb = k_pb * (sq * sq)
            # the sideslip limit (737 MAX: 5 deg) and the one the bank allowance admits, the smaller; the rest of
            # the wind correction (crab + beta) stays as crab
            b_max = min(g.align_sideslip_max_rad, g.align_bank_max_rad / k_pb if k_pb > 0.0 else math.inf)
            eta = crab + beta
            crab_res = eta - min(max(eta, -b_max), b_max)
            dr = g.k_r_align * (r + (crab - crab_res) / g.align_tau_s) + g.k_beta_align * beta
            da = g.k_phi * (phi_c + k_pb * beta - phi) - g.k_p * p + g.k_da_align * beta
        else:
            dr = -g.k_beta * beta
            da = g.k_phi * (phi_c - phi) - g.k_p * p
        return _clip1(de), _clip1(da), _clip1(dr), thr

    def _tecs(self, d: float, d_dot: float, h_dot: float, v: float) -> tuple[float, float]:
        """Total energy control (module docstring): pitch command and throttle from the glide path deviation d
        (m) and its rate (m/s), the height rate h' (m/s) and the smoothed speed v (m/s)."""
        g = self.g
        dt = self.dt
        if self._v_lag != self._v_lag:
            self._v_lag = v
        v_dot = (v - self._v_lag) / g.tecs_rate_tau_s
        self._v_lag += dt * v_dot
        v0 = max(v, 1.0)
        hd_gp = h_dot - d_dot
        hd_c = min(max(hd_gp - d / g.tecs_t_h_s, -g.tecs_sink_max_mps), g.tecs_climb_max_mps)
        a_lim = 0.5 * G0 / g.tecs_thr_per_rad
        vd_c = min(max((self.trim.cas_mps - v) / g.tecs_t_v_s, -a_lim), a_lim)
        wk = min(max(g.tecs_spd_weight, 0.0), 1.0)
        wp = min(max(2.0 - g.tecs_spd_weight, 0.0), 1.0)
        e_h = (hd_c - h_dot) / v0
        e_v = (vd_c - v_dot) / G0
        e_t = e_h + e_v
        e_b = wp * e_h - wk * e_v
        sp_h = (hd_c - hd_gp) / v0
        t_sp = sp_h + vd_c / G0
        b_sp = wp * sp_h - wk * vd_c / G0
        thr = self.trim.throttle + g.tecs_thr_per_rad * (t_sp + g.tecs_k_thr_damp * e_t + g.tecs_k_thr_i * self.int_t)
        if 0.0 < thr < 1.0:
            self.int_t += e_t * dt
        else:
            thr = 1.0 if thr >= 1.0 else 0.0
        th_off = g.tecs_seb_ff * b_sp + g.tecs_k_pitch_damp * e_b + g.tecs_k_pitch_i * self.int_b
        lim = g.pitch_limit_rad
        step_max = dt * g.tecs_vert_acc_mps2 / v0
        prev = self._theta_c - self.trim.theta_rad
        lo, hi = max(-lim, prev - step_max), min(lim, prev + step_max)
        if lo < th_off < hi:
            self.int_b += e_b * dt
        else:
            th_off = hi if th_off >= hi else lo
        return self.trim.theta_rad + th_off, thr

    def state(self) -> tuple[float, ...]:
        """The integrators and filters (int d, int y, e_f, wind along the path, int e_f, flaring, flare-entry pitch
        command, flare integral, last pitch command, TECS speed washout, int E_T, int E_B, flare tau, flare h_off,
        aligning, flare-entry sink rate and airspeed, surface slope): the compiled autopilot's APS_* state vector."""
        return (self.int_d, self.int_y, self.e_f, self._w, self.int_e, float(self.flaring), self._theta_flare0,
                self._int_flare, self._theta_c, self._v_lag, self.int_t, self.int_b, self._flare_tau,
                self._flare_h_off, float(self.aligning), self._flare_sink0, self._flare_v0, self.surface_slope)

    def _flare(self, h_gear: float, sink: float, v_air: float, gust: float, thr: float) -> tuple[float, float]:
        """Exponential flare with its path feed-forward (module docstring): pitch command to fly the main gear's
        sink rate `sink` (m/s, + down) onto h'_c = -(h_gear - h_off) / tau, tau and h_off from the sink rate at
        entry, at airspeed v_air (m/s) with the airspeed gust `gust` (m/s, TAS above the air-mass speed), with the
        nose-gear floor; thr the autothrottle's throttle, idle below the retard height and while the floor holds.
        Returns (pitch command, throttle)."""
        g = self.g
        if not self.flaring:
            self.flaring = True
            self._theta_flare0 = self._theta_c
            sink0 = max(sink, g.touchdown_sink_mps + 0.1)  # an entry sink below the touchdown sink: 0.1 m/s above
            self._flare_tau = max(h_gear, 0.0) / (sink0 - g.touchdown_sink_mps) if h_gear > 0.0 else 1.0
            self._flare_h_off = -self._flare_tau * g.touchdown_sink_mps
            self._flare_sink0 = sink0
            self._flare_v0 = v_air
        tau = self._flare_tau
        sink_c = (max(h_gear, 0.0) - self._flare_h_off) / tau  # the commanded sink rate
        e = sink - sink_c  # > 0: sinking too fast
        self._int_flare += e * self.dt
        v0 = max(v_air, 1.0)
        # feed-forward: the commanded path-angle change, led by the path's lag T_theta2 behind pitch
        ff = ((self._flare_sink0 - sink_c) / v0 + g.flare_t_path_s * sink / (tau * v0)
              + g.flare_k_v * (self._flare_v0 - v_air) - g.flare_k_gust * gust)
        if g.flare_ge_k > 0.0:  # the ground effect's lift since flare entry, h_entry = tau (s_0 - s_td)
            h0 = tau * (self._flare_sink0 - g.touchdown_sink_mps)
            k_ge = 1.0 + g.flare_ge_k * math.exp(-(max(h_gear, 0.0) + g.flare_ge_arp_m) / g.flare_ge_decay_m)
            k_ge0 = 1.0 + g.flare_ge_k * math.exp(-(h0 + g.flare_ge_arp_m) / g.flare_ge_decay_m)
            ff -= 0.5 * g.flare_k_v * self._flare_v0 * math.log(k_ge / k_ge0)
        theta_c = self._theta_flare0 + ff + g.k_flare * e + g.k_flare_i * self._int_flare
        # the nose-gear floor below its height (its integral frozen there); a flare held on it has more lift than it
        # wants (fast): idle while it holds
        floor = g.flare_pitch_min_rad + math.atan(self.surface_slope)
        if h_gear <= g.flare_pitch_min_height_m and theta_c < floor:
            theta_c = floor
            self._int_flare -= e * self.dt
            thr = 0.0
        if h_gear <= g.retard_height_m:
            thr = 0.0
        return theta_c, thr


def _wrap(a: float) -> float:
    """a wrapped to [-pi, pi) (written as the compiled twin computes it)."""
    a = a + math.pi
    return a - 2.0 * math.pi * math.floor(a / (2.0 * math.pi)) - math.pi


def _clip1(u: float) -> float:
    return 1.0 if u > 1.0 else (-1.0 if u < -1.0 else u)
