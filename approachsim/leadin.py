"""The PROFGEN-like lead-in's geometry (runway.lead_in = "profgen"): the pattern legs before the final and its
vertical path, in the runway frame. The flight stage flies it (flight/path.py: the guidance, why each number);
profile.py sizes a run with it. Everything here is plain geometry: no aircraft, no autopilot.

Gray & Maybeck, *An integrated GPS/INS/Baro and radar altimeter system for aircraft precision approach landings*,
fly a PROFGEN profile "follow[ing] the approach plate" of their ref. [7] without giving its legs or length; the
legs below are our gap fill (flight/path.py's docstring lists them).
"""


from __future__ import annotations

import math
from dataclasses import dataclass

from approachsim import units
from approachsim.glidepath import GlidePath

LEAD_INS = ("none", "profgen")
"""runway.lead_in values: none (the straight-in final from start_distance_nmi) or the PROFGEN-like pattern."""

START_HEIGHT_FT = 3500.0
"""Height above the threshold where the lead-in starts (descending on the downwind), ft (gap fill)."""
PATTERN_HEIGHT_FT = 2500.0
"""The pattern's (intermediate) height above the threshold and the glideslope intercept height, ft (gap fill: a
typical ILS intercept altitude, 7.7 nmi out on 3 deg; below 3000 ft AGL, so the radar altimeter is in use)."""
DOWNWIND_LEVEL_NMI = 1.0
"""Level downwind after the descent, nmi (gap fill)."""
TURN_RADIUS_M = 2500.0
"""Radius of both 90 deg turns, m: about 12 deg of bank at the pattern's 140 kt TAS, inside the autopilot's 15 deg
bank limit with room for its corrections (gap fill)."""
BASE_NMI = 1.0
"""Straight base leg between the turns, nmi (gap fill)."""
INTERMEDIATE_NMI = 2.0
"""Level flight on the final course between the turn and the glideslope intercept, nmi (gap fill; TERPS asks an
intermediate segment before the final approach fix)."""
DIVERGED_CROSS_M = 1500.0
"""PathGuidance's divergence limit from the active leg (the kernel's lateral limit from the centreline), m."""
DIVERGED_VERTICAL_M = 300.0
"""PathGuidance's divergence limit from the path's height (the kernel's vertical limit), m."""


@dataclass(frozen=True)
class Leg:
    """One horizontal leg in the runway frame: a line (turn 0) or an arc (turn -1 left, +1 right) of radius_m,
    from (x0, y0) on course chi0_rad, length_m along it."""

    x0: float
    y0: float
    chi0_rad: float
    length_m: float
    turn: int = 0
    radius_m: float = 0.0

    @property
    def center(self) -> tuple[float, float]:
        """The arc's centre (on the turn's side of the start point), m."""
        n = self.turn * self.radius_m
        return self.x0 - n * math.sin(self.chi0_rad), self.y0 + n * math.cos(self.chi0_rad)

    def end(self) -> tuple[float, float, float]:
        """(x, y, course) at the leg's end."""
        if self.turn == 0:
            return (self.x0 + self.length_m * math.cos(self.chi0_rad),
                    self.y0 + self.length_m * math.sin(self.chi0_rad), self.chi0_rad)
        chi = self.chi0_rad + self.turn * self.length_m / self.radius_m
        cx, cy = self.center
        # the aircraft sits at course - turn x 90 deg as seen from the centre
        a = chi - self.turn * 0.5 * math.pi
        return cx + self.radius_m * math.cos(a), cy + self.radius_m * math.sin(a), chi

    def locate(self, x: float, y: float) -> tuple[float, float, float]:
        """(along-track distance from the leg's start, signed cross-track + right, the path's course there) of the
        point (x, y)."""
        if self.turn == 0:
            c, s = math.cos(self.chi0_rad), math.sin(self.chi0_rad)
            dx, dy = x - self.x0, y - self.y0
            return dx * c + dy * s, -dx * s + dy * c, self.chi0_rad
        cx, cy = self.center
        rx, ry = x - cx, y - cy
        dist = math.hypot(rx, ry)
        chi = math.atan2(ry, rx) + self.turn * 0.5 * math.pi
        swept = (self.turn * (chi - self.chi0_rad)) % (2.0 * math.pi)
        if swept > 1.5 * math.pi:  # just before the arc's start: a small negative sweep
            swept -= 2.0 * math.pi
        return swept * self.radius_m, self.turn * (self.radius_m - dist), chi


@dataclass(frozen=True)
class LeadIn:
    """The lead-in's legs (the last is the final, on the centreline towards the threshold) and its vertical path."""

    legs: tuple[Leg, ...]
    start_height_m: float
    pattern_height_m: float
    tan_gp: float
    x_gs_m: float
    """Runway-frame x where the glide path cone reaches the pattern height on the centreline (the intercept)."""

    @property
    def length_m(self) -> float:
        """Path length from the start to the threshold (the final leg ends at x = 0), m."""
        return float(sum(leg.length_m for leg in self.legs))

    @property
    def start(self) -> tuple[float, float, float, float]:
        """(x, y, height above the threshold, course) at the start."""
        g = self.legs[0]
        return g.x0, g.y0, self.start_height_m, g.chi0_rad

    def height_m(self, s_m: float) -> float:
        """The path's height above the threshold at distance s_m flown (before the glideslope intercept), m."""
        return max(self.pattern_height_m, self.start_height_m - self.tan_gp * s_m)

    def sink_slope(self, s_m: float) -> float:
        """-dh/ds of the path at s_m (tan(gp) on the initial descent, 0 level)."""
        return self.tan_gp if self.start_height_m - self.tan_gp * s_m > self.pattern_height_m else 0.0


def profgen(runway: object) -> LeadIn:
    """The PROFGEN-like lead-in (module docstring) of a profile.Runway."""
    gp = GlidePath.of(runway)
    tan_gp = gp.tan_gp
    h_pat = PATTERN_HEIGHT_FT * units.FT
    h0 = START_HEIGHT_FT * units.FT
    # the glideslope intercept: where the cone's height on the centreline is the pattern height (bisection)
    lo, hi = -200e3, 0.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if float(gp.height_m(mid)) > h_pat else (lo, mid)
    x_gs = 0.5 * (lo + hi)
    r = TURN_RADIUS_M
    base = BASE_NMI * units.NMI
    x_f = x_gs - INTERMEDIATE_NMI * units.NMI  # the final course's straight starts here (end of the second turn)
    descent = (h0 - h_pat) / tan_gp
    downwind = descent + DOWNWIND_LEVEL_NMI * units.NMI
    y_dw = -(2.0 * r + base)
    quarter = 0.5 * math.pi * r
    legs = (
        Leg(x_f + downwind, y_dw, math.pi, downwind),
        Leg(x_f, y_dw, math.pi, quarter, turn=-1, radius_m=r),
        Leg(x_f - r, y_dw + r, 0.5 * math.pi, base),
        Leg(x_f - r, -r, 0.5 * math.pi, quarter, turn=-1, radius_m=r),
        Leg(x_f, 0.0, 0.0, -x_f),
    )
    return LeadIn(legs, h0, h_pat, tan_gp, x_gs)


def lead_in_of(runway: object) -> LeadIn | None:
    """The runway's lead-in path (None: lead_in = "none")."""
    kind = getattr(runway, "lead_in", "none")
    return profgen(runway) if kind == "profgen" else None
