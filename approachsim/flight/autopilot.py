"""Approach autopilot: glideslope and localizer guidance, pitch and roll inner loops, autothrottle.

Guidance flies on the navigation source's position (runway frame) and NED velocity; the inner loops use the
aircraft's own attitude, body rates, sideslip and calibrated airspeed (AHRS and air data). The laws, whose
linearization approachsim.flight.design checks loop at a time (gains from the aircraft file):

    d   = h - h_gp(x),  d' = -v_down + x' tan(gp)                  glidepath deviation (m, + above) and rate
    theta_c = theta_0 - (k_gs_p d + k_gs_d d' + k_gs_i int d)      limited to theta_0 +- pitch_limit
    de  = -k_theta (theta_c - theta) + k_q q                       elevator, added to the trimmed pitch trim
    w   <- w + dt/tau_w (V_tas - |v_ground| - w)                   wind along the path (complementary filter)
    V   = V_cas (|v_ground| + w) / V_tas                           inertially smoothed CAS (= V_cas in still air)
    e_f <- e_f + dt/tau_v (V_c - V - e_f)                          filtered speed error (turbulence)
    thr = thr_0 + k_v_p e_f + k_v_i int e_f                        autothrottle (integral frozen at saturation)
    y, y' = cross-track deviation (m, + right) and its rate
    phi_c = -(k_loc_p y + k_loc_d y' + k_loc_i int y)              limited to +- bank_limit
    da  = k_phi (phi_c - phi) - k_p p                              aileron
    dr  = -k_beta beta                                             rudder (crab into the wind; FCS adds a yaw damper)

Landing runs add a flare below flare_height (main-gear height h_g): theta_c = theta_entry + k_flare e +
k_flare_i int e, e = -(h_g / tau_flare + sink_td) - h', and the throttle to idle below retard_height.

Sign conventions of the 737 FCS: + elevator = nose down, + aileron = roll right, + rudder = nose left.
This class is the readable oracle; the flight loop runs its compiled twin (flight/kernels.py autopilot_step, equal
to it bit for bit: tests/unit/flight/test_flight_loop_kernels.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from approachsim.flight.design import AutopilotGains
from approachsim.geo import radii


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

    def __init__(self, gains: AutopilotGains, trim: Trim, geometry: Geometry, dt_s: float) -> None:
        self.g = gains
        self.trim = trim
        self.dt = dt_s
        self.ch = math.cos(geometry.heading_rad)
        self.sh = math.sin(geometry.heading_rad)
        self.tan_gp = math.tan(geometry.glidepath_rad)
        self.tch_m = geometry.tch_m
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

    def deviations(self, x: float, y: float, z: float, vn: float, ve: float, vd: float) -> tuple[float, ...]:
        """Glidepath deviation d (m, + above), its rate (m/s), cross-track y (m, + right) and its rate (m/s)."""
        ch, sh = self.ch, self.sh
        conv = (x * sh + y * ch) * self.conv_per_east_m  # runway heading in the local NED minus at the threshold
        x0 = vn * ch + ve * sh
        y0 = -vn * sh + ve * ch
        x_dot = x0 + conv * y0  # small-angle rotation by the convergence (|conv| < 0.01 rad)
        y_dot = y0 - conv * x0
        d = z - (self.tch_m - x * self.tan_gp)
        d_dot = -vd + x_dot * self.tan_gp
        return d, d_dot, y, y_dot

    def step(
        self,
        x: float, y: float, z: float, vn: float, ve: float, vd: float,
        phi: float, theta: float, p: float, q: float, beta: float, cas: float, h_gear: float | None = None,
        tas: float | None = None,
    ) -> tuple[float, float, float, float]:
        """One control step: guidance position (runway frame, m) and NED velocity (m/s), attitude (rad),
        body rates (rad/s), sideslip (rad), calibrated airspeed (m/s) -> elevator, aileron, rudder, throttle.
        h_gear: main-gear height above the terrain (m) on landing runs (the radio altitude; None: no flare).
        tas: true airspeed (m/s) for the speed complement (None: the autothrottle holds the raw CAS)."""
        g = self.g
        dt = self.dt
        if tas is not None and tas > 1.0:  # inertially smoothed speed (module docstring)
            gs = math.sqrt(vn * vn + ve * ve + vd * vd)
            if self._w != self._w:
                self._w = tas - gs
            self._w += dt / g.tau_wind_s * (tas - gs - self._w)
            cas = cas * (gs + self._w) / tas
        # deviations (as deviations(), inlined: this runs every step)
        ch, sh = self.ch, self.sh
        conv = (x * sh + y * ch) * self.conv_per_east_m
        x0 = vn * ch + ve * sh
        y0 = -vn * sh + ve * ch
        d = z - (self.tch_m - x * self.tan_gp)
        d_dot = -vd + (x0 + conv * y0) * self.tan_gp
        y_dot = y0 - conv * x0
        # glidepath -> pitch command (integral frozen while the command is limited)
        th_off = -(g.k_gs_p * d + g.k_gs_d * d_dot + g.k_gs_i * self.int_d)
        lim = g.pitch_limit_rad
        if -lim < th_off < lim:
            self.int_d += d * dt
        else:
            th_off = lim if th_off > 0.0 else -lim
        theta_c = self.trim.theta_rad + th_off
        if h_gear is not None and (self.flaring or h_gear <= g.flare_height_m):
            theta_c, thr_flare = self._flare(h_gear, -vd, theta_c)
        else:
            thr_flare = None
        self._theta_c = theta_c
        de = -g.k_theta * (theta_c - theta) + g.k_q * q
        # autothrottle on the filtered speed error
        self.e_f += dt / g.tau_v_s * (self.trim.cas_mps - cas - self.e_f)
        thr = self.trim.throttle + g.k_v_p * self.e_f + g.k_v_i * self.int_e
        if 0.0 < thr < 1.0:
            self.int_e += self.e_f * dt
        else:
            thr = 1.0 if thr >= 1.0 else 0.0
        if thr_flare is not None:
            thr = min(thr, thr_flare)
        # localizer -> bank command
        phi_c = -(g.k_loc_p * y + g.k_loc_d * y_dot + g.k_loc_i * self.int_y)
        blim = g.bank_limit_rad
        if -blim < phi_c < blim:
            self.int_y += y * dt
        else:
            phi_c = blim if phi_c > 0.0 else -blim
        da = g.k_phi * (phi_c - phi) - g.k_p * p
        dr = -g.k_beta * beta
        return _clip1(de), _clip1(da), _clip1(dr), thr

    def state(self) -> tuple[float, ...]:
        """The integrators and filters (int d, int y, e_f, wind along the path, int e_f, flaring, flare-entry pitch
        command, flare integral, last pitch command): the compiled autopilot's APS_* state vector."""
        return (self.int_d, self.int_y, self.e_f, self._w, self.int_e, float(self.flaring), self._theta_flare0,
                self._int_flare, self._theta_c)

    def _flare(self, h_gear: float, h_dot: float, theta_c_path: float) -> tuple[float, float]:
        """Flare: pitch command from the sink-rate error to h'_c = -(h_gear / tau + sink_td), starting from
        the pitch command at flare entry; throttle limit (1 above the retard height, then idle)."""
        g = self.g
        if not self.flaring:
            self.flaring = True
            self._theta_flare0 = self._theta_c
        e = -(max(h_gear, 0.0) / g.flare_tau_s + g.touchdown_sink_mps) - h_dot  # > 0: sinking too fast
        self._int_flare += e * self.dt
        theta_c = self._theta_flare0 + g.k_flare * e + g.k_flare_i * self._int_flare
        thr_limit = 1.0 if h_gear > g.retard_height_m else 0.0
        return theta_c, thr_limit


def _clip1(u: float) -> float:
    return 1.0 if u > 1.0 else (-1.0 if u < -1.0 else u)
