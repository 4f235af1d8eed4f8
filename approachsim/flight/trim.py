"""Where an approach starts: on the ideal glidepath at the profile's start distance, in landing configuration.

The start point is on the extended centreline (runway frame x = -start distance, y = 0) at the glidepath
height above the threshold, flying the runway heading at the approach speed with flight-path angle
-glidepath (relative to the air mass); JSBSim then trims it (fdm.FDM.initialize_and_trim).
"""

from __future__ import annotations

from approachsim import geo
from approachsim.flight.aircraft import Aircraft
from approachsim.flight.fdm import InitialCondition
from approachsim.profile import Profile


def start_condition(profile: Profile, aircraft: Aircraft, *, still_air: bool = False,
                    along_m: float | None = None) -> InitialCondition:
    """The trimmed start of the profile's approach, on the glidepath at runway-frame x = along_m (default: the
    start distance). still_air: no wind (FGLinearization hangs with an IC wind); the day's temperature and
    pressure are kept."""
    rw = profile.runway
    frame = rw.frame
    along = -rw.start_distance_m if along_m is None else along_m
    lat, lon, _ = geo.ecef_to_geodetic(frame.to_ecef([along, 0.0, 0.0]))
    h = rw.elevation_m + float(rw.glidepath_height_m(along))
    env = profile.environment
    return InitialCondition(
        lat_rad=float(lat),
        lon_rad=float(lon),
        h_m=h,
        heading_rad=rw.heading_rad,
        cas_mps=aircraft.approach_speed_mps,
        gamma_rad=-rw.glidepath_rad,
        flaps_norm=aircraft.flaps_norm,
        gear_down=aircraft.gear_down,
        terrain_m=float(profile.terrain.height_at(along)),
        wind_speed_mps=0.0 if still_air else env.wind_speed_mps,
        wind_from_rad=env.wind_from_rad,
        isa_dev_k=env.isa_dev_k,
        sl_pressure_pa=env.true_qnh_pa,
    )
