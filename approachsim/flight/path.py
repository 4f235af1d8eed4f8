"""A PROFGEN-like lead-in to the final: the pattern legs, turns and level segments, flown by the approach autopilot.

Gray & Maybeck, *An integrated GPS/INS/Baro and radar altimeter system for aircraft precision approach landings*,
fly a PROFGEN profile (Musick, AFAL-TR-76-247) that "follow[s] the approach plate" of their ref. [7] (not
reproduced) for a tanker at 133 kt on a 3 deg glideslope (assumption 14). The paper gives neither the profile's
length nor its legs; `runway.lead_in = "profgen"` flies the standard shape of an ILS procedure flown from a
left-hand downwind (our gap fill, every number below), in the runway frame (x along the landing direction, y
right, z up from the threshold; a course chi is measured from +x towards +y):

    1. downwind, course 180 deg, y = -(2 R + base): a descent on the glidepath angle from START_HEIGHT_FT to
       PATTERN_HEIGHT_FT, then DOWNWIND_LEVEL_NMI level;
    2. a 90 deg left turn of radius R = TURN_RADIUS_M onto base (course 90 deg), level;
    3. base, BASE_NMI, level;
    4. a 90 deg left turn of radius R onto the final course (0 deg), level;
    5. the final: INTERMEDIATE_NMI level on the localizer, the glideslope intercept from below at
       PATTERN_HEIGHT_FT (x_gs = -(h_pattern - z_cone offset) on the cone), then the glide path to the stop height.

The autopilot (flight/autopilot.py, compiled twin core/loop/flight_step) flies only a localizer and a glide path;
`PathGuidance` makes it fly the path by handing it, as its guidance, the aircraft's true state expressed relative
to the active leg (a records.NavigationSource on the truth):

    y   = the signed cross-track distance from the leg (+ right of it; on an arc R - |r - c| for a right turn,
          |r - c| - R for a left one), y' its rate;
    y'_g = y' - phi_ff / k_loc_d,  phi_ff = sign(turn) atan(V_h^2 / (g R))   the turn's bank as feed-forward through
          the rate term (the localizer law phi_c = -(k_p y + k_d y' + k_i int y); through y' the integral does not
          wind up over a turn); 0 on straight legs;
    d   = h - h_path(s), d' = h' - h'_path(s): h_path = max(H_pattern, H_start - tan(gp) s) (s the distance flown
          along the path), the glide path cone itself once on the final past x_gs (there the guidance IS the true
          state, unchanged);
    x   = -(the path length still to fly to the threshold): a position along the straight-in the cone is evaluated at.

The reported position and NED velocity are solved so that the autopilot's own computation (its meridian-convergence
rotation and glidepath.deviation_and_rate) returns exactly (y, y'_g, d, d'), with the ground speed's magnitude kept
(the speed complement reads it). TECS then sees the path's height rate as the cone's (-tan(gp) x'), which only moves
its height-rate setpoint's clip (-5.1 / +3 m/s about the cone's sink instead of level): the level segments are
flown with d small, far from it.

Divergence: the kernel's runway-frame divergence limits (300 m from the glide path, 1500 m from the centreline) do
not apply to a pattern 7 km off the centreline; the flight loop takes them from the path (`divergence_limits_m`:
none while a lead-in is flown) and `PathGuidance` checks the same limits against the active leg (LeadInDiverged).

Open loop only: the guidance slot is the navigation source's (a closed loop flies on its own navigation solution),
over flat terrain (a [terrain] table describes the centreline only).
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.glidepath import GlidePath, deviation_and_rate
from approachsim.leadin import DIVERGED_CROSS_M, DIVERGED_VERTICAL_M, LeadIn
from approachsim.records import Truth
from approachsim.units import G0


class LeadInDiverged(RuntimeError):
    """The aircraft left the lead-in path beyond the divergence limits."""


class PathGuidance:
    """Guidance along a LeadIn for the approach autopilot (module docstring): a records.NavigationSource on the
    truth, one per flight (it keeps the active leg)."""

    def __init__(self, path: LeadIn, glidepath: GlidePath, k_loc_d: float) -> None:
        self.path = path
        self.k_loc_d = k_loc_d
        self.ch, self.sh = math.cos(glidepath.heading_rad), math.sin(glidepath.heading_rad)
        self.cone = glidepath.constants()
        lat0 = glidepath.threshold_lat_rad
        from approachsim.geo import radii

        r_e = float(radii(lat0)[1])
        self.conv_per_east_m = math.sin(lat0) / (r_e * math.cos(lat0))
        self.leg = 0
        self.s0 = [0.0]
        for g in path.legs[:-1]:
            self.s0.append(self.s0[-1] + g.length_m)
        self.phi_ff = 0.0
        """The last step's bank feed-forward, rad (for the tests)."""

    def _rates(self, x: float, y: float, vn: float, ve: float) -> tuple[float, float]:
        """Runway-frame rates (x', y') of a NED velocity at (x, y), as the autopilot computes them."""
        conv = (x * self.sh + y * self.ch) * self.conv_per_east_m
        x0 = vn * self.ch + ve * self.sh
        y0 = -vn * self.sh + ve * self.ch
        return x0 + conv * y0, y0 - conv * x0

    def _ned(self, x: float, y: float, xd: float, yd: float) -> tuple[float, float]:
        """The NED (vn, ve) whose runway-frame rates at (x, y) are (xd, yd) (the inverse of _rates)."""
        conv = (x * self.sh + y * self.ch) * self.conv_per_east_m
        k = 1.0 / (1.0 + conv * conv)
        x0, y0 = (xd - conv * yd) * k, (yd + conv * xd) * k
        return x0 * self.ch - y0 * self.sh, x0 * self.sh + y0 * self.ch

    def locate(self, x: float, y: float) -> tuple[int, float, float, float]:
        """(active leg, distance flown along the path, cross-track, course) at (x, y); advances the active leg."""
        legs = self.path.legs
        while True:
            g = legs[self.leg]
            along, cross, chi = g.locate(x, y)
            if along < g.length_m or self.leg == len(legs) - 1:
                return self.leg, self.s0[self.leg] + along, cross, chi
            self.leg += 1

    def step(self, k: int, truth: Truth) -> tuple[np.ndarray, np.ndarray]:
        """The guidance position (runway frame, m) and NED velocity (m/s) of row k (module docstring)."""
        x, y, z = (float(v) for v in truth.r_rwy[k])
        vn, ve, vd = (float(v) for v in truth.v_ned[k])
        path = self.path
        leg, s, cross, chi = self.locate(x, y)
        final = leg == len(path.legs) - 1
        if final and x >= path.x_gs_m:  # on the final past the intercept: the autopilot's own glide path
            self.phi_ff = 0.0
            return truth.r_rwy[k].copy(), truth.v_ned[k].copy()
        xd, yd = self._rates(x, y, vn, ve)
        c, sn = math.cos(chi), math.sin(chi)
        along_d, cross_d = xd * c + yd * sn, -xd * sn + yd * c
        turn = path.legs[leg].turn
        v_h2 = xd * xd + yd * yd
        self.phi_ff = turn * math.atan(v_h2 / (G0 * path.legs[leg].radius_m)) if turn else 0.0
        d = z - path.height_m(s)
        d_dot = -vd - (-path.sink_slope(s) * along_d)
        if abs(cross) > DIVERGED_CROSS_M or abs(d) > DIVERGED_VERTICAL_M:
            raise LeadInDiverged(f"lead-in diverged on leg {leg + 1} of {len(path.legs)} at {truth.t_s[k]:.1f} s: "
                                 f"{cross:.0f} m from the leg, {d:.0f} m from its height")
        b = cross_d - self.phi_ff / self.k_loc_d
        x_r, y_r = -(path.length_m - s), cross
        tan_gp, x_gpi, ca, cb, cc = self.cone
        d0, dd0 = deviation_and_rate(x_r, y_r, 0.0, along_d, b, 0.0, tan_gp, x_gpi, ca, cb, cc)
        z_dot = d_dot - dd0
        v2 = vn * vn + ve * ve + vd * vd
        a = math.sqrt(max(v2 - b * b - z_dot * z_dot, 1.0))
        d0, dd0 = deviation_and_rate(x_r, y_r, 0.0, a, b, 0.0, tan_gp, x_gpi, ca, cb, cc)
        z_dot = d_dot - dd0  # with the speed-kept along rate (the cone's slope times it)
        vn_r, ve_r = self._ned(x_r, y_r, a, b)
        return np.array([x_r, y_r, d - d0]), np.array([vn_r, ve_r, -z_dot])
