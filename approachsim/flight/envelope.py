"""The approach envelope: the aircraft's approach limits (checked when a profile is flown) and the
stabilized-approach criterion (checked every step below the stabilization height while it flies).

Limits come from the aircraft file's [envelope] table (aircraft/737.toml says where each figure comes from);
a profile outside them is refused with one line naming the field and the limit (ProfileError, exit 2):

    environment.wind_speed_kt: tailwind component 20 kt exceeds the 737's 15 kt limit

Wind components are taken against the runway heading: headwind = W cos(from - heading), crosswind =
W |sin(from - heading)|. The descent the glidepath needs must also be a stabilized one: FSF's 1000 ft/min
sink-rate criterion is about the planned descent ("if an approach requires a sink rate greater than 1000 fpm, a
special briefing should be conducted"), so the profile is refused when the glidepath needs more than 1000 ft/min
at the top of the speed band (approach TAS + 10 kt at the field's density altitude, minus the headwind).

Stabilized approach (Flight Safety Foundation ALAR Briefing Note 7.1, as quoted in the project's reference notes,
with the tighter speed band +10/-5 kt of the target that this project asks for): from the stabilization
height (1000 ft above the threshold, IMC) down to the end of the run (landing runs: to the flare),

    |glidepath deviation| <= 1 dot   (ILS glide path: 1 dot = 0.0875 DDM = 0.12 x glidepath angle, ICAO
                                      Annex 10 Vol I 3.1.5.6; angular about the glide-path origin)
    |localizer deviation| <= 1 dot   (1 dot = 0.0775 DDM; 0.00145 DDM/m at the threshold, Annex 10 3.1.3.7,
                                      i.e. 53.4 m there, angular about the localizer antenna)
    -5 kt <= air-mass speed - target <= +10 kt
    sink rate <= 1000 ft/min, or within 300 ft/min of the rate the glidepath needs at the current ground speed

The speed is the aircraft's speed through the mean air mass (ground velocity minus the steady wind, as CAS
with JSBSim's CAS/TAS ratio), not the gusty instantaneous CAS: a moderate-turbulence gust moves CAS by 5-10 kt
in a second, which no autothrottle follows and stabilized-approach practice does not count (pilots add the gust
to the target instead). The speed is judged on its 3 s trailing mean, the sink rate on its 10 s trailing mean,
deviations on the instantaneous true IMU position. The 300 ft/min sink tolerance and the 10 s window are this
project's choice: moderate turbulence's vertical gusts (sigma_w = 0.1 W20 = 3 kt, MIL-F-8785C) move the sink
rate by about 300 ft/min for a few seconds about a descent that is inside the planning limit, which is not an
unstabilized approach. The glide path converges on its antenna, so below 200 ft (the CAT I decision height:
below it the approach goes on by visual reference or the CAT II/III monitors) its dot keeps the linear size it
has at 200 ft (7.3 m on 3 deg; an angular dot is 1.8 m at 50 ft).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from approachsim import units
from approachsim.config import ProfileError
from approachsim.core.loop.flight_step import MON_GLIDEPATH, MON_LOCALIZER, MON_OK, MON_SINK, MON_SPEED
from approachsim.core.tables import (  # the criteria the compiled monitor applies, defined there once
    LOC_ANTENNA_PAST_THRESHOLD_M,
    SINK_LIMIT_MPS,
    SINK_TOLERANCE_MPS,
    SPEED_HIGH_MPS,
    SPEED_LOW_MPS,
    STABILIZATION_HEIGHT_M,
)
from approachsim.glidepath import deviation_and_rate

GS_DOT_PER_GLIDEPATH = 0.12
"""ILS glide path: 1 dot (0.0875 DDM, half of full scale) is 0.12 x the glidepath angle (ICAO Annex 10 Vol I
3.1.5.6.1, nominal angular displacement sensitivity)."""
LOC_DOT_AT_THRESHOLD_M = 0.0775 / 0.00145
"""Localizer: 1 dot (0.0775 DDM) over the nominal 0.00145 DDM/m displacement sensitivity at the threshold
(ICAO Annex 10 Vol I 3.1.3.7.1): 53.4 m at the threshold, growing linearly with distance from the antenna."""
GS_DOT_FLOOR_HEIGHT_M = 200.0 * units.FT
PLANNING_SPEED_MARGIN_MPS = 10.0 * units.KT
MEAN_WINDOW_S = 3.0
SINK_WINDOW_S = 10.0
TURBULENCE_ORDER = ("none", "light", "moderate", "severe")


@dataclass(frozen=True)
class ApproachLimits:
    """An aircraft's approach limits (SI). The aircraft file's [envelope] table, ft/kt/deg there."""

    max_headwind_mps: float
    max_tailwind_mps: float
    max_crosswind_mps: float
    min_glidepath_rad: float
    max_glidepath_rad: float
    min_field_elevation_m: float
    max_field_elevation_m: float
    max_turbulence: str


def wind_components(wind_speed_mps: float, wind_from_rad: float, heading_rad: float) -> tuple[float, float]:
    """(headwind, crosswind) components of a wind blowing from wind_from_rad on a runway heading heading_rad, m/s;
    headwind negative for a tailwind, crosswind positive from the right."""
    d = wind_from_rad - heading_rad
    return wind_speed_mps * math.cos(d), wind_speed_mps * math.sin(d)


def _isa_tas_factor(elevation_m: float, isa_dev_k: float) -> float:
    """TAS / CAS at low Mach and the field's density altitude: sqrt(rho0 / rho) of the ISA troposphere with a
    temperature deviation (pressure from ISA, temperature ISA + dev)."""
    t_isa = 288.15 - 0.0065 * elevation_m
    p_ratio = (t_isa / 288.15) ** 5.25588
    rho_ratio = p_ratio * 288.15 / (t_isa + isa_dev_k)
    return 1.0 / math.sqrt(rho_ratio)


def check_envelope(profile, limits: ApproachLimits, aircraft_name: str, approach_speed_mps: float) -> None:
    """Raise ProfileError (one line: field and limit) when the profile lies outside the aircraft's limits."""
    env, rw = profile.environment, profile.runway
    hw, xw = wind_components(env.wind_speed_mps, env.wind_from_rad, rw.heading_rad)
    kt = units.KT
    who = f"the {aircraft_name}'s"
    if hw > limits.max_headwind_mps + 1e-9:
        raise ProfileError(f"environment.wind_speed_kt: headwind component {hw / kt:.0f} kt exceeds {who} "
                           f"{limits.max_headwind_mps / kt:.0f} kt limit")
    if -hw > limits.max_tailwind_mps + 1e-9:
        raise ProfileError(f"environment.wind_speed_kt: tailwind component {-hw / kt:.0f} kt exceeds {who} "
                           f"{limits.max_tailwind_mps / kt:.0f} kt limit")
    if abs(xw) > limits.max_crosswind_mps + 1e-9:
        raise ProfileError(f"environment.wind_speed_kt: crosswind component {abs(xw) / kt:.0f} kt exceeds {who} "
                           f"{limits.max_crosswind_mps / kt:.0f} kt limit")
    gp = rw.glidepath_rad
    if not limits.min_glidepath_rad - 1e-9 <= gp <= limits.max_glidepath_rad + 1e-9:
        raise ProfileError(f"runway.glidepath_deg: {math.degrees(gp):g} deg is outside {who} approach range "
                           f"{math.degrees(limits.min_glidepath_rad):g}-{math.degrees(limits.max_glidepath_rad):g} deg")
    el = rw.elevation_m
    if not limits.min_field_elevation_m - 1e-6 <= el <= limits.max_field_elevation_m + 1e-6:
        lo_ft, hi_ft = limits.min_field_elevation_m / units.FT, limits.max_field_elevation_m / units.FT
        raise ProfileError(f"runway.elevation_ft: {el / units.FT:g} ft is outside {who} field elevation range "
                           f"{lo_ft:g} to {hi_ft:g} ft")
    if TURBULENCE_ORDER.index(env.turbulence) > TURBULENCE_ORDER.index(limits.max_turbulence):
        raise ProfileError(f"environment.turbulence: {env.turbulence!r} exceeds {who} approach limit "
                           f"({limits.max_turbulence!r})")
    gs = (approach_speed_mps + PLANNING_SPEED_MARGIN_MPS) * _isa_tas_factor(el, env.isa_dev_k) - hw
    sink = gs * math.tan(gp)
    if sink > SINK_LIMIT_MPS:
        raise ProfileError(
            f"runway.glidepath_deg: {math.degrees(gp):g} deg at {gs / kt:.0f} kt ground speed needs "
            f"{sink / units.FT * 60:.0f} ft/min sink, over the 1000 ft/min stabilized-approach limit"
        )





def unstabilized_reason(result: int, z_m: float, a: float, b: float) -> str:
    """The failed criterion in words, e.g. "unstabilized at 420 ft: glidepath deviation +1.30 dots": result one of
    MON_GLIDEPATH, MON_LOCALIZER (a: the deviation in dots), MON_SPEED (a: 3 s mean speed minus the target, m/s),
    MON_SINK (a, b: 10 s mean sink rate and its excess over the glidepath's, m/s), at height z_m (m)."""
    where = f"unstabilized at {z_m / units.FT:.0f} ft"
    if result == MON_GLIDEPATH:
        return f"{where}: glidepath deviation {a:+.2f} dots"
    if result == MON_LOCALIZER:
        return f"{where}: localizer deviation {a:+.2f} dots"
    if result == MON_SPEED:
        return f"{where}: air-mass speed {a / units.KT:+.1f} kt from the target (3 s mean)"
    if result == MON_SINK:
        return (f"{where}: sink rate {a / units.FT * 60:.0f} ft/min, "
                f"{b / units.FT * 60:.0f} ft/min above the glidepath's (10 s mean)")
    raise ValueError(f"not a failed stabilized-approach criterion: {result}")


class StabilityMonitor:
    """The stabilized-approach criterion of one run (module docstring), fed every step with the true IMU state.

    step() returns None while stabilized, else the named reason, e.g. "unstabilized at 420 ft: glidepath
    deviation 1.3 dots". Re-create per run. The readable oracle of the compiled monitor (core/loop/flight_step.py
    monitor_step); check() is its step with the result as (MON_* code, figures)."""

    def __init__(self, glidepath_rad: float, tch_m: float, target_cas_mps: float, dt_s: float,
                 curvature: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        self.tan_gp = math.tan(glidepath_rad)
        self.curvature = curvature
        """The glide path cone's Earth-curvature coefficients (glidepath.GlidePath.curvature; zeros: flat Earth)."""
        self.gs_dot_rad = GS_DOT_PER_GLIDEPATH * glidepath_rad
        self.x_gp_m = tch_m / self.tan_gp  # glide-path origin past the threshold (runway frame x)
        self.x_floor_m = self.x_gp_m - GS_DOT_FLOOR_HEIGHT_M / self.tan_gp
        self.loc_dot_rad = math.atan(LOC_DOT_AT_THRESHOLD_M / LOC_ANTENNA_PAST_THRESHOLD_M)
        self.tch_m = tch_m
        self.target_mps = target_cas_mps
        self.n = max(1, int(round(MEAN_WINDOW_S / dt_s)))
        """Samples in the speed window."""
        self.m = max(1, int(round(SINK_WINDOW_S / dt_s)))
        """Samples in the sink-rate window."""
        self._cas = [0.0] * self.n
        self._j = 0
        self._sink = [0.0] * self.m
        self._excess = [0.0] * self.m
        self._sum_excess = 0.0
        self._i = 0
        self._count = 0
        self._sum_cas = 0.0
        self._sum_sink = 0.0

    def dots(self, x_m: float, y_m: float, z_m: float) -> tuple[float, float]:
        """Glidepath and localizer deviation in dots (+ above / + right) at runway-frame position (m)."""
        d = deviation_and_rate(x_m, y_m, z_m, 0.0, 0.0, 0.0, self.tan_gp, self.x_gp_m, *self.curvature)[0]
        r_gp = max(self.x_gp_m - min(x_m, self.x_floor_m), 1.0)
        gs_dots = d / (r_gp * math.tan(self.gs_dot_rad))
        r_loc = LOC_ANTENNA_PAST_THRESHOLD_M - x_m
        loc_dots = y_m / (r_loc * math.tan(self.loc_dot_rad))
        return gs_dots, loc_dots

    def step(self, x_m: float, y_m: float, z_m: float, cas_mps: float, v_down_mps: float,
             ground_speed_mps: float) -> str | None:
        """Update with one step's true position (runway frame, m), air-mass speed as CAS (m/s), down velocity and
        horizontal ground speed (m/s)."""
        result, a, b = self.check(x_m, y_m, z_m, cas_mps, v_down_mps, ground_speed_mps)
        return None if result == MON_OK else unstabilized_reason(result, z_m, a, b)

    def check(self, x_m: float, y_m: float, z_m: float, cas_mps: float, v_down_mps: float,
              ground_speed_mps: float) -> tuple[int, float, float]:
        """step() as (MON_* result, figure a, figure b): the figures of unstabilized_reason."""
        i = self._i
        excess = v_down_mps - ground_speed_mps * self.tan_gp  # sink beyond what the glidepath needs
        self._sum_cas += cas_mps - self._cas[i]
        self._sum_sink += v_down_mps - self._sink[self._j]
        self._sum_excess += excess - self._excess[self._j]
        j = self._j
        self._cas[i] = cas_mps
        self._sink[j], self._excess[j] = v_down_mps, excess
        self._i = (i + 1) % self.n
        self._j = (j + 1) % self.m
        self._count += 1
        if z_m > STABILIZATION_HEIGHT_M:
            return MON_OK, 0.0, 0.0
        gs, loc = self.dots(x_m, y_m, z_m)
        if abs(gs) > 1.0:
            return MON_GLIDEPATH, gs, 0.0
        if abs(loc) > 1.0:
            return MON_LOCALIZER, loc, 0.0
        if self._count < self.n:
            return MON_OK, 0.0, 0.0
        dv = self._sum_cas / self.n - self.target_mps
        if dv > SPEED_HIGH_MPS or dv < -SPEED_LOW_MPS:
            return MON_SPEED, dv, 0.0
        if self._count < self.m:
            return MON_OK, 0.0, 0.0
        sink, excess = self._sum_sink / self.m, self._sum_excess / self.m
        if sink > SINK_LIMIT_MPS and excess > SINK_TOLERANCE_MPS:
            return MON_SINK, sink, excess
        return MON_OK, 0.0, 0.0

    def state(self) -> tuple[float, ...]:
        """(i, j, count, speed sum, sink sum, excess sum): the compiled monitor's MNS_* state vector."""
        return (float(self._i), float(self._j), float(self._count), self._sum_cas, self._sum_sink,
                self._sum_excess)

    def windows(self) -> list[float]:
        """The speed, sink and excess windows concatenated: the compiled monitor's ring buffer."""
        return self._cas + self._sink + self._excess
