"""Where an approach starts: on the ideal glidepath at the profile's start distance, in landing configuration.

With a lead-in (runway.lead_in, flight/path.py) the start is the lead-in's first point instead: its position,
height and course, descending on the glidepath angle.

The start point is on the extended centreline (runway frame x = -start distance, y = 0) at the glidepath
height above the threshold, flying the runway heading at the approach speed (JSBSim's own CAS) along the
earth-frame flight-path angle -glidepath, in the profile's wind; solve_start finds the initial-condition
command whose JSBSim trim reaches exactly that (fdm.FDM.initialize_and_trim).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

from approachsim import geo, units
from approachsim.flight.aircraft import Aircraft
from approachsim.flight.fdm import FDM, InitialCondition, TrimError
from approachsim.flight.wind import mean_wind_ned
from approachsim.flight.wind import varies as wind_varies
from approachsim.leadin import lead_in_of
from approachsim.profile import Profile


def start_condition(profile: Profile, aircraft: Aircraft, *, still_air: bool = False,
                    along_m: float | None = None) -> InitialCondition:
    """The trimmed start of the profile's approach, on the glidepath at runway-frame x = along_m (default: the
    start distance). still_air: no wind (FGLinearization hangs with an IC wind); the day's temperature and
    pressure are kept."""
    rw = profile.runway
    frame = rw.frame
    along = -rw.start_distance_m if along_m is None else along_m
    cross, heading = 0.0, rw.heading_rad
    lead = lead_in_of(rw) if along_m is None else None
    if lead is not None:  # the lead-in's start: descending on the glidepath angle on its first leg (flight/path.py)
        along, cross, h_above, chi = lead.start
        heading = (rw.heading_rad + chi) % (2.0 * math.pi)
    lat, lon, _ = geo.ecef_to_geodetic(frame.to_ecef([along, cross, 0.0]))
    h = rw.elevation_m + (h_above if lead is not None else float(rw.glidepath_height_m(along)))
    env = profile.environment
    wind = env.wind_speed_mps
    if not still_air and wind_varies(env):  # JSBSim's steady wind is the mean wind at the start (flight/wind.py)
        wn, we = mean_wind_ned(env, h - float(profile.terrain.height_at(along)))
        wind = math.hypot(wn, we)
        wind_from = math.atan2(-we, -wn) if wind > 0.0 else env.wind_from_rad
    else:
        wind_from = env.wind_from_rad
    return InitialCondition(
        lat_rad=float(lat),
        lon_rad=float(lon),
        h_m=h,
        heading_rad=heading,
        cas_mps=aircraft.approach_speed_mps,
        gamma_rad=-rw.glidepath_rad,
        flaps_norm=aircraft.flaps_norm,
        gear_down=aircraft.gear_down,
        terrain_m=float(profile.terrain.height_at(along)),
        wind_speed_mps=0.0 if still_air else wind,
        wind_from_rad=wind_from,
        isa_dev_k=env.isa_dev_k,
        sl_pressure_pa=env.sea_level_pa,
        tanks=aircraft.tanks,
    )


CAS_TOLERANCE_MPS = 1.0 * units.KT
"""How far JSBSim's own CAS after trim may be from the approach speed (issue: within 1 kt)."""
PATH_TOLERANCE_RAD = math.radians(0.1)
"""How far the earth-frame flight-path angle after trim may be from -glidepath (within 0.1 deg)."""
_SOLVE_CAS_MPS = 0.02 * units.KT
_SOLVE_PATH_RAD = math.radians(0.002)
_MAX_ITER = 12


class StartError(RuntimeError):
    """The approach could not be started trimmed at the approach speed on the glidepath in this wind."""


def solve_start(fdm_factory: Callable[[], FDM], ic: InitialCondition) -> tuple[InitialCondition, float, float]:
    """The initial-condition command whose JSBSim trim flies at ic.cas_mps (JSBSim's own velocities/vc-kts)
    along the earth-frame flight-path angle ic.gamma_rad, in the IC's wind; with the CAS (m/s) and path
    angle (rad) JSBSim reached.

    Why an iteration: JSBSim 1.3.3's FGInitialCondition resolves ic/vc-kts and ic/gamma-rad against the IC wind
    with the wind's sign reversed (measured: a headwind component w starts the 737 at CAS + 2 w CAS/TAS, 178 KCAS
    for 140 commanded in a 20 kt headwind; a 10 kt tailwind starts it at 121 KCAS, below its flaps-full trim
    range), and its gamma is an air-mass angle. The commands are corrected by the residual (fixed-point
    iteration, x <- x + (target - reached)), starting from that measured first-order model; each trial is a fresh
    FDM, so the result depends only on the IC. Raises StartError when it does not converge."""
    target_cas, target_gamma = ic.cas_mps, ic.gamma_rad
    hw = ic.wind_speed_mps * math.cos(ic.wind_from_rad - ic.heading_rad)  # headwind component, m/s
    cmd_cas = target_cas - 2.0 * hw
    cmd_gamma = target_gamma
    cas = gamma = math.nan
    last_err = ""
    for _ in range(_MAX_ITER):
        trial = replace(ic, cas_mps=cmd_cas, gamma_rad=cmd_gamma)
        fdm = fdm_factory()
        try:
            fdm.initialize_and_trim(trial)
        except TrimError as e:  # step halfway back towards the target command and try again
            last_err = str(e)
            cmd_cas = 0.5 * (cmd_cas + target_cas)
            cmd_gamma = 0.5 * (cmd_gamma + target_gamma)
            continue
        cas, gamma = fdm.cas_and_path()
        d_cas, d_gamma = target_cas - cas, target_gamma - gamma
        if abs(d_cas) <= _SOLVE_CAS_MPS and abs(d_gamma) <= _SOLVE_PATH_RAD:
            return trial, cas, gamma
        cmd_cas += d_cas
        cmd_gamma += d_gamma
    if math.isnan(cas):
        raise TrimError(last_err or "JSBSim could not trim")
    raise StartError(
        f"could not start trimmed at {target_cas / units.KT:.1f} KCAS on a {-math.degrees(target_gamma):.2f} deg "
        f"path in this wind: JSBSim reached {cas / units.KT:.1f} KCAS, {-math.degrees(gamma):.2f} deg"
    )
