"""Profile: the typed, validated model of an approach profile file (TOML).

A profile says where (runway), what flies (aircraft), in what weather (environment, terrain), how fast
things are sampled (rates) and how many runs by default (run). Stage-specific sections (sensors, nav,
faults, evaluation) are parsed by their own stage's config module and stored here as frozen objects.
Feet, knots, nmi, degrees and hPa are read here and converted to SI once; nothing downstream sees them.

Heights: the runway elevation and terrain heights are taken as heights above the WGS-84 ellipsoid (the
simulator has no geoid: JSBSim's sea level is the ellipsoid), which matters to nothing that is scored.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from approachsim import units
from approachsim.config import ProfileError, Section
from approachsim.evaluate.config import EvaluationConfig, parse_evaluation
from approachsim.geo import RunwayFrame
from approachsim.glidepath import GlidePath
from approachsim.leadin import LEAD_INS, lead_in_of
from approachsim.nav.config import NavConfig, parse_nav
from approachsim.resources import find_aircraft_file
from approachsim.sensors import atmosphere
from approachsim.sensors.config import SensorsConfig, parse_faults, parse_sensors
from approachsim.sensors.gnss.gbas import REFERENCE_GEOMETRY, approach_geometry

TURBULENCE_LEVELS = ("none", "light", "moderate", "severe")
QNH_REPORTS = ("exact", "whole_hpa")
WIND_PROFILES = ("uniform", "log")
"""How the mean wind changes with height (environment.wind_profile; flight/wind.py)."""
RUNWAY_SLOPE_EXTENT_M = 3000.0
"""How far past the threshold the runway slope is laid into the terrain (beyond: held), m: past the 915 m long
touchdown limit with room for the rollout's first seconds."""
"""How the QNH set on the altimeter is reported (environment.qnh_report): exact (the day's QNH to the hundredth), or
whole_hpa, rounded down to the whole hectopascal as a METAR / ATIS gives it (issue 39: a reporting error of 0 to
-1 hPa, the altimeter reading up to 27 ft low at sea level)."""


@dataclass(frozen=True)
class Runway:
    """Runway threshold and approach geometry (SI)."""

    threshold_lat_rad: float
    threshold_lon_rad: float
    elevation_m: float
    heading_rad: float
    """True heading of the landing direction."""
    glidepath_rad: float
    tch_m: float
    """Threshold crossing height of the glidepath."""
    start_distance_m: float
    """Distance from the threshold (along the extended centreline) where the run starts."""
    slope: float = 0.0
    """Longitudinal slope of the runway past the threshold, rise per metre (+: rising in the landing direction);
    the terrain past the threshold (Terrain, RUNWAY_SLOPE_EXTENT_M) follows it."""
    lead_in: str = "none"
    """The flight before the final (flight/path.py LEAD_INS): "none", the straight-in from start_distance_m;
    "profgen", the PROFGEN-like pattern (downwind descent, two 90 deg turns, level segments, the glideslope
    intercept from below), flown open loop over flat terrain; start_distance_m is then unused."""

    @property
    def frame(self) -> RunwayFrame:
        """The runway frame (origin at the threshold, x along the landing direction, y right, z up)."""
        return RunwayFrame(self.threshold_lat_rad, self.threshold_lon_rad, self.elevation_m, self.heading_rad)

    def glidepath_height_m(self, along_m: np.ndarray | float, cross_m: np.ndarray | float = 0.0
                           ) -> np.ndarray | float:
        """Height above the threshold (the runway frame's z) of the straight glide path cone at runway-frame
        x = along_m (negative before), y = cross_m (approachsim.glidepath: the one geometric reference)."""
        return GlidePath.of(self).height_m(along_m, cross_m)

    @property
    def glidepath(self) -> GlidePath:
        """The straight ILS glide path cone of this runway (GPI, TCH, angle)."""
        return GlidePath.of(self)


@dataclass(frozen=True)
class AircraftChoice:
    """Which aircraft, and the profile's overrides of its approach configuration (None: aircraft default)."""

    name: str
    approach_speed_mps: float | None
    flaps_norm: float | None
    gear_down: bool
    autopilot_law: str | None = None
    """Speed and path law flown ("classic" | "tecs"; None: the aircraft file's)."""
    weight_n: float | None = None
    """Gross weight at the start of the approach, N (None: the JSBSim model as loaded; aircraft file [mass])."""
    cg_mac: float | None = None
    """Centre-of-gravity position as a fraction of the mean aerodynamic chord (None: the model as loaded)."""


@dataclass(frozen=True)
class Environment:
    """Weather. wind_from_rad is the direction the wind blows from (as pilots read it), true."""

    wind_speed_mps: float
    wind_from_rad: float
    turbulence: str
    """One of TURBULENCE_LEVELS."""
    isa_dev_k: float
    qnh_pa: float
    """The day's QNH at the field, Pa: the setting with which an altimeter reads the field elevation at the
    threshold (ISA inverse), whatever the temperature."""
    setting_pa: float = 101325.0
    """What is set on the baro altimeter: the reported QNH (the day's QNH, or with qnh_report = "whole_hpa" rounded
    down to the whole hPa) + the profile's qnh_setting_error_hPa, Pa."""
    sea_level_pa: float = 101325.0
    """The day's true sea-level pressure of the ISA+dT atmosphere that has the QNH's pressure at the field
    (sensors.atmosphere.sea_level_pressure_pa): what JSBSim's atmosphere is set to, Pa."""
    wind_profile: str = "uniform"
    """One of WIND_PROFILES: "uniform" (the wind at every height) or "log" (a logarithmic boundary layer whose
    wind at wind_reference_height_m is the profile's; flight/wind.py)."""
    wind_reference_height_m: float = 10.0
    """Height above the terrain the profile's wind is given at (the log layer's reference), m."""
    roughness_length_m: float = 0.15 * units.FT
    """Roughness length z0 of the log layer, m (MIL-F-8785C Category C: 0.15 ft; flight/wind.py)."""
    shear_top_m: float = 0.0
    """Top of the shear layer above the terrain, m."""
    shear_bottom_m: float = 0.0
    """Bottom of the shear layer above the terrain, m (the change is complete below it)."""
    shear_n_mps: float = 0.0
    """The shear layer's wind change from its top to its bottom, north component (where the air moves to), m/s."""
    shear_e_mps: float = 0.0
    """The same, east component, m/s."""
    inversion_k: float = 0.0
    """A surface layer's departure from the constant-dT atmosphere (environment.inversion_K): the air at the field is
    this much colder than the day's standard-lapse line, the departure falling linearly to 0 at inversion_depth_m
    above the field (sensors/atmosphere.py inversion_log_ratio). It acts on the baro's static pressure and the
    reported aerodrome temperature; JSBSim's flight keeps its constant-dT air (a 10 K layer changes the density by
    3.5 %, which the autopilot flies through). K."""
    inversion_depth_m: float = 1000.0 * 0.3048
    """Depth of that layer above the field, m."""

    @property
    def true_qnh_pa(self) -> float:
        """Former name of sea_level_pa (the day's true sea-level pressure), Pa."""
        return self.sea_level_pa


@dataclass(frozen=True)
class Terrain:
    """Terrain height (ellipsoid, m) against runway-frame x (m, negative before the threshold).

    In the profile: [terrain] distance_nmi (before the threshold, decreasing) and height_ft, absolute heights
    in ft above MSL (not above the field). Linear interpolation between points, held constant beyond the ends.
    Flat (no [terrain]): the runway elevation. Checked by check_terrain: it meets the runway elevation at the
    threshold and stays below the glidepath with terrain_clearance_m.
    """

    along_m: tuple[float, ...]
    height_m: tuple[float, ...]

    def height_at(self, along_m: np.ndarray | float) -> np.ndarray:
        """Terrain ellipsoid height (m) at runway-frame x = along_m."""
        return np.interp(along_m, self.along_m, self.height_m)


@dataclass(frozen=True)
class Rates:
    """Sample rates, Hz. The flight dynamics, autopilot and IMU all run at imu_hz."""

    imu_hz: float


@dataclass(frozen=True)
class RunDefaults:
    """Default Monte Carlo size, campaign seed and mode (CLI options override)."""

    runs: int
    seed: int
    mode: str
    """"closed" (each run flies on its own navigation solution) or "open" (truth shared)."""


@dataclass(frozen=True)
class Profile:
    """A validated approach profile. Build with load_profile(path) or parse_profile(dict)."""

    name: str
    description: str
    runway: Runway
    aircraft: AircraftChoice
    environment: Environment
    terrain: Terrain
    rates: Rates
    run: RunDefaults
    source: Path | None = field(default=None, compare=False)
    """The file it came from (aircraft files are looked up beside it)."""
    evaluation: EvaluationConfig = field(default_factory=EvaluationConfig)
    """How campaigns are scored ([evaluation]: decision heights, verdict limits; evaluate/config.py)."""
    sensors: SensorsConfig = field(default_factory=SensorsConfig)
    """The sensor suite ([sensors]; sensors/config.py). Default: seed 002's suite without the pseudolite."""
    faults: tuple = ()
    """Declared sensor faults ([[faults]]; sensors/faults.py FaultSpec), in profile order."""
    nav: NavConfig = field(default_factory=NavConfig)
    """The navigation system ([nav]: filter by name and its tuning, aiding rate, feedback, baro loop, initial
    INS errors; nav/config.py)."""

    def gbas_geometry(self) -> tuple[float, float, float]:
        """GBAS: (x_air m, dh m, v_air m/s) at the approach's start (gbas.approach_geometry of the start distance,
        glidepath, threshold crossing height and approach speed), where the filter's channel noise and P0 take the
        distance-dependent sigmas (nav/noise.py); gbas.REFERENCE_GEOMETRY without GBAS (unused) or with a lead-in
        (its final starts where the pattern ends)."""
        g, rwy = self.sensors.gnss, self.runway
        if g is None or g.gbas is None or rwy.lead_in != "none":
            return REFERENCE_GEOMETRY
        return approach_geometry(rwy.start_distance_m, rwy.glidepath_rad, rwy.tch_m,
                                 approach_cas_mps(self.aircraft, self.source))


def _runway(s: Section) -> Runway:
    lat = s.number("threshold_lat_deg", lo=-85.0, hi=85.0, unit="deg")
    lon = s.number("threshold_lon_deg", lo=-180.0, hi=180.0, unit="deg")
    elev = s.number("elevation_ft", lo=-1500.0, hi=15000.0, unit="ft")
    hdg = s.number("heading_true_deg", lo=0.0, hi=360.0, unit="deg")
    gp = s.number("glidepath_deg", 3.0, lo=1.0, hi=10.0, unit="deg")
    tch = s.number("tch_ft", 50.0, lo=0.0, hi=200.0, unit="ft")
    start = s.number("start_distance_nmi", 10.0, lo=1.0, hi=30.0, unit="nmi")
    slope = s.number("slope_percent", 0.0, lo=-2.0, hi=2.0, unit="% (rise in the landing direction)")
    lead_in = s.string("lead_in", "none", choices=LEAD_INS)
    s.done()
    return Runway(
        threshold_lat_rad=math.radians(lat),
        threshold_lon_rad=math.radians(lon),
        elevation_m=elev * units.FT,
        heading_rad=math.radians(hdg % 360.0),
        glidepath_rad=math.radians(gp),
        tch_m=tch * units.FT,
        start_distance_m=start * units.NMI,
        slope=slope / 100.0,
        lead_in=lead_in,
    )


def _aircraft(s: Section) -> AircraftChoice:
    name = s.string("name", "737")
    if not name or "/" in name or "\\" in name or name.startswith("."):
        raise ProfileError(f"{s.path}.name: must be a plain aircraft name (a file aircraft/<name>.toml), got {name!r}")
    speed = s.raw("approach_speed_kt", None)
    if speed is not None:
        speed = s.number("approach_speed_kt", lo=80.0, hi=200.0, unit="kt") * units.KT
    flaps = s.raw("flaps_norm", None)
    if flaps is not None:
        flaps = s.number("flaps_norm", lo=0.0, hi=1.0)
    gear = s.boolean("gear_down", True)
    law = s.raw("autopilot_law", None)
    if law is not None:
        law = s.string("autopilot_law", choices=("classic", "tecs"))
    weight = s.raw("weight_lb", None)
    if weight is not None:  # the aircraft file's [mass] range is checked where the aircraft is loaded
        weight = s.number("weight_lb", lo=0.0, lo_open=True, unit="lb") * units.LBF
    cg = s.raw("cg_percent_mac", None)
    if cg is not None:
        cg = s.number("cg_percent_mac", lo=-50.0, hi=100.0, unit="% MAC") / 100.0
    s.done()
    return AircraftChoice(name=name, approach_speed_mps=speed, flaps_norm=flaps, gear_down=gear, autopilot_law=law,
                          weight_n=weight, cg_mac=cg)


def _environment(s: Section, runway: Runway) -> Environment:
    ws = s.number("wind_speed_kt", 0.0, lo=0.0, hi=60.0, unit="kt")
    wd = s.number("wind_from_deg", 0.0, lo=0.0, hi=360.0, unit="deg")
    turb = s.string("turbulence", "none", choices=TURBULENCE_LEVELS)
    dt = s.number("isa_dev_C", 0.0, lo=-60.0, hi=40.0, unit="C")
    qnh = s.number("qnh_hPa", 1013.25, lo=900.0, hi=1100.0, unit="hPa")
    if s.has("true_qnh_hPa"):
        raise ProfileError(
            f"{s.path}.true_qnh_hPa: no longer used: the sea-level pressure follows from qnh_hPa, the field "
            "elevation and isa_dev_C; for a mis-set altimeter give qnh_setting_error_hPa"
        )
    err = s.number("qnh_setting_error_hPa", 0.0, lo=-50.0, hi=50.0, unit="hPa")
    report = s.string("qnh_report", "exact", choices=QNH_REPORTS)
    shape = s.string("wind_profile", "uniform", choices=WIND_PROFILES)
    ref = s.number("wind_reference_height_m", 10.0, lo=1.0, hi=100.0, unit="m")
    z0 = s.number("roughness_length_m", 0.15 * units.FT, lo=0.0001, hi=0.5, unit="m")
    top = s.number("shear_top_ft", 0.0, lo=0.0, hi=3000.0, unit="ft")
    bottom = s.number("shear_bottom_ft", 0.0, lo=0.0, hi=3000.0, unit="ft")
    loss = s.number("shear_headwind_loss_kt", 0.0, lo=-40.0, hi=40.0, unit="kt")
    inv_k = s.number("inversion_K", 0.0, lo=-20.0, hi=30.0, unit="K")
    inv_depth_ft = s.number("inversion_depth_ft", 1000.0, lo=1.0, hi=10000.0, unit="ft")
    s.done()
    if loss != 0.0 and not top > bottom:
        raise ProfileError(f"{s.path}.shear_top_ft: must be above shear_bottom_ft ({bottom:g} ft) for a shear, got "
                           f"{top:g}")
    if shape == "log" and not ref > z0:
        raise ProfileError(f"{s.path}.wind_reference_height_m: must be above roughness_length_m ({z0:g} m)")
    # the headwind lost from the top down: the air moving towards the landing direction by `loss`
    dn, de = loss * units.KT * math.cos(runway.heading_rad), loss * units.KT * math.sin(runway.heading_rad)
    reported = math.floor(qnh) if report == "whole_hpa" else qnh
    h_field = float(atmosphere.geopotential_m(runway.elevation_m))
    return Environment(
        wind_speed_mps=ws * units.KT,
        wind_from_rad=math.radians(wd % 360.0),
        turbulence=turb,
        isa_dev_k=dt,
        qnh_pa=qnh * units.HPA,
        setting_pa=(reported + err) * units.HPA,
        sea_level_pa=atmosphere.sea_level_pressure_pa(qnh * units.HPA, h_field, dt, runway.elevation_m),
        wind_profile=shape,
        wind_reference_height_m=ref,
        roughness_length_m=z0,
        shear_top_m=top * units.FT,
        shear_bottom_m=bottom * units.FT,
        shear_n_mps=dn,
        shear_e_mps=de,
        inversion_k=inv_k,
        inversion_depth_m=inv_depth_ft * units.FT,
    )


def _terrain(s: Section, runway: Runway) -> Terrain:
    if not s.has("distance_nmi") and not s.has("height_ft"):
        s.done()
        return _with_slope(Terrain(along_m=(0.0,), height_m=(runway.elevation_m,)), runway)
    dist = s.numbers("distance_nmi", min_len=2, unit="nmi before the threshold")
    hgt = s.numbers("height_ft", min_len=2, unit="ft")
    s.done()
    if len(dist) != len(hgt):
        raise ProfileError(
            f"{s.path}.height_ft: needs one height per distance_nmi value ({len(dist)}), got {len(hgt)}"
        )
    if any(b >= a for a, b in zip(dist, dist[1:], strict=False)):
        raise ProfileError(f"{s.path}.distance_nmi: must decrease strictly (far to near the threshold)")
    if any(h < -1500.0 or h > 15000.0 for h in hgt):
        raise ProfileError(f"{s.path}.height_ft: every height must be in [-1500, 15000] ft")
    along = tuple(-d * units.NMI for d in dist)  # distance before the threshold is negative x
    terrain = Terrain(along_m=along, height_m=tuple(h * units.FT for h in hgt))
    check_terrain(terrain, runway, s.path)
    return _with_slope(terrain, runway)


def _with_slope(terrain: Terrain, runway: Runway) -> Terrain:
    """The terrain with the runway's slope laid past the threshold: points (0, elevation) (when the terrain ends
    before it) and (RUNWAY_SLOPE_EXTENT_M, elevation + slope x extent); unchanged for a level runway."""
    if runway.slope == 0.0:
        return terrain
    along, height = list(terrain.along_m), list(terrain.height_m)
    if len(along) == 1:
        along, height = [], []
    if not along or along[-1] < 0.0:
        along.append(0.0)
        height.append(runway.elevation_m)
    along.append(RUNWAY_SLOPE_EXTENT_M)
    height.append(runway.elevation_m + runway.slope * RUNWAY_SLOPE_EXTENT_M)
    return Terrain(along_m=tuple(along), height_m=tuple(height))


TERRAIN_THRESHOLD_TOLERANCE_M = 1.0 * units.FT
"""How far the terrain may be from the runway elevation at the threshold (the heights are given in ft)."""
TERRAIN_CLEARANCE_MAX_M = 250.0 * units.FT


def terrain_clearance_m(glidepath_height_m: np.ndarray | float) -> np.ndarray:
    """Required clearance of the terrain below the glidepath (m) at a glidepath height above the threshold (m):
    half that height, at most 250 ft. This project's rule, not an obstacle assessment (PANS-OPS): it keeps the
    approach out of rising ground and the threshold on the runway (25 ft below a 50 ft threshold crossing)."""
    return np.minimum(0.5 * np.asarray(glidepath_height_m, dtype=float), TERRAIN_CLEARANCE_MAX_M)


def check_terrain(terrain: Terrain, runway: Runway, path: str = "terrain") -> None:
    """ProfileError (one line) unless the terrain meets the runway elevation at the threshold and stays below
    the glidepath by terrain_clearance_m from the start of the approach to the threshold."""
    h0 = float(terrain.height_at(0.0))
    if abs(h0 - runway.elevation_m) > TERRAIN_THRESHOLD_TOLERANCE_M:
        raise ProfileError(
            f"{path}.height_ft: {h0 / units.FT:.0f} ft at the threshold, but the runway is at "
            f"{runway.elevation_m / units.FT:.0f} ft; terrain heights are absolute (ft above MSL) and must meet "
            "the runway elevation at the threshold"
        )
    x = np.unique(np.concatenate([np.linspace(-runway.start_distance_m, 0.0, 2001),
                                  [a for a in terrain.along_m if -runway.start_distance_m <= a <= 0.0]]))
    gp = runway.elevation_m + runway.glidepath_height_m(x)
    room = gp - terrain.height_at(x) - terrain_clearance_m(gp - runway.elevation_m)
    k = int(np.argmin(room))
    if room[k] < 0.0:
        raise ProfileError(
            f"{path}.height_ft: terrain {terrain.height_at(x[k]) / units.FT:.0f} ft at {-x[k] / units.NMI:.2f} nmi "
            f"is within {terrain_clearance_m(gp[k] - runway.elevation_m) / units.FT:.0f} ft of the glidepath "
            f"({gp[k] / units.FT:.0f} ft there); terrain must stay below the glidepath by half its height above "
            "the threshold, at most 250 ft"
        )


def _rates(s: Section) -> Rates:
    imu = s.number("imu_hz", 120.0, lo=50.0, hi=1000.0, unit="Hz")
    s.done()
    return Rates(imu_hz=imu)


def _run(s: Section) -> RunDefaults:
    runs = s.integer("runs", 20, lo=1, hi=100000)
    seed = s.integer("seed", 1, lo=0, hi=2**63 - 1)
    mode = s.string("mode", "closed", choices=("closed", "open"))
    s.done()
    return RunDefaults(runs=runs, seed=seed, mode=mode)


def approach_cas_mps(aircraft: AircraftChoice, source: Path | None) -> float:
    """The approach speed (calibrated airspeed), m/s: the profile's [aircraft] approach_speed_kt, else the aircraft
    file's approach.approach_speed_kt (looked up beside source, then the shipped aircraft)."""
    if aircraft.approach_speed_mps is not None:
        return aircraft.approach_speed_mps
    path = find_aircraft_file(aircraft.name, source)
    try:
        return float(tomllib.loads(path.read_text(encoding="utf-8"))["approach"]["approach_speed_kt"]) * units.KT
    except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError):
        raise ProfileError(f"aircraft.name: {str(path)!r} has no valid approach.approach_speed_kt") from None


def _run_duration_estimate_s(runway: Runway, aircraft: AircraftChoice, env: Environment, source: Path | None) -> float:
    """Estimate (s) of a run's length, for checking fault times: the glidepath from the start distance to
    50 ft above the threshold at the approach ground speed (with a lead-in: its path length, at the TAS of its
    pattern height).

    Ground speed = TAS - headwind; TAS = CAS sqrt(rho0 / rho) (incompressible, M < 0.3) at the approach's
    mid height in the ISA atmosphere with the profile's temperature deviation. The approach speed is the
    profile's, else the aircraft file's (approachsim.resources lookup).
    """
    cas = approach_cas_mps(aircraft, source)
    tan_gp = math.tan(runway.glidepath_rad)
    h_mid = runway.elevation_m + 0.5 * runway.start_distance_m * tan_gp
    lead = lead_in_of(runway)
    if lead is not None:  # the lead-in's length at the TAS of its pattern height
        h_mid = runway.elevation_m + lead.pattern_height_m
    t_isa = 288.15 - 0.0065 * h_mid  # ISA troposphere, K
    p_ratio = (t_isa / 288.15) ** 5.25588  # p / p0
    rho_ratio = p_ratio * 288.15 / (t_isa + env.isa_dev_k)  # rho / rho0 with the temperature deviation
    tas = cas / math.sqrt(rho_ratio)
    headwind = env.wind_speed_mps * math.cos(env.wind_from_rad - runway.heading_rad)
    ground_speed = max(tas - headwind, 0.3 * tas)
    path_m = runway.start_distance_m + (runway.tch_m - 50.0 * units.FT) / tan_gp
    if lead is not None:
        path_m = lead.length_m
    return path_m / ground_speed


def parse_profile(data: dict, source: Path | None = None) -> Profile:
    """Validate a profile given as the dict TOML parsing gives; ProfileError names the first bad field."""
    top = Section(data, "")
    name = top.string("name", source.stem if source is not None else "profile")
    description = top.string("description", "")
    runway = _runway(top.section("runway", default_empty=False))
    aircraft = _aircraft(top.section("aircraft"))
    env = _environment(top.section("environment"), runway)
    terrain = _terrain(top.section("terrain"), runway)
    rates = _rates(top.section("rates"))
    run = _run(top.section("run"))
    evaluation = parse_evaluation(top.section("evaluation"))
    sensors = parse_sensors(top.section("sensors"), site_rad=(runway.threshold_lat_rad, runway.threshold_lon_rad))
    fault_items = top.sections("faults")
    duration = _run_duration_estimate_s(runway, aircraft, env, source) if fault_items else None
    faults = parse_faults(fault_items, sensors, duration_s=duration, imu_hz=rates.imu_hz)
    nav = parse_nav(top.section("nav"))
    top.done()
    if runway.lead_in != "none" and (len(terrain.along_m) > 1 or run.mode != "open"):
        raise ProfileError("runway.lead_in: the PROFGEN-like lead-in is flown open loop (run.mode = \"open\") over "
                           "flat terrain (no [terrain] table, a level runway): its pattern leaves the centreline")
    if sensors.gnss is not None and sensors.gnss.carrier is not None and not (
            nav.gps_coupling == "tight" and nav.channel_states):
        raise ProfileError("sensors.gnss.carrier_phase: needs [nav] gps_coupling = \"tight\" and channel_states = "
                           "true (the float ambiguities are per-channel filter states)")
    return Profile(
        name=name,
        description=description,
        runway=runway,
        aircraft=aircraft,
        environment=env,
        terrain=terrain,
        rates=rates,
        run=run,
        source=source,
        evaluation=evaluation,
        sensors=sensors,
        faults=faults,
        nav=nav,
    )


def load_profile(path: str | Path) -> Profile:
    """Read and validate a profile file. Missing file, bad TOML and bad fields all raise ProfileError."""
    return parse_profile(read_profile_toml(path), source=Path(path).resolve())


def read_profile_toml(path: str | Path) -> dict:
    """A profile file's TOML as a dict, not yet validated (ProfileError for a missing file, not UTF-8, bad TOML)."""
    p = Path(path)
    if not p.is_file():
        raise ProfileError(f"profile: no such file {str(p)!r}")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise ProfileError(f"profile: {str(p)!r} is not a UTF-8 text file") from None
    except tomllib.TOMLDecodeError as e:
        raise ProfileError(f"profile: {str(p)!r} is not valid TOML ({e})") from None
    return data
