"""Aircraft approach configuration: aircraft/<name>.toml (JSBSim model name, approach speed, flaps, gear, IMU
location, autopilot gains), read strictly and converted to SI.

Lookup of `<name>.toml` (approachsim.resources): beside the profile (``<dir>/aircraft``, ``<dir>/../aircraft``),
then $APPROACHSIM_AIRCRAFT_PATH, then the installed package's data. Errors name the file and field (ProfileError).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from approachsim import resources, units
from approachsim.config import ProfileError, Section
from approachsim.flight.design import LAWS, AutopilotGains
from approachsim.flight.envelope import TURBULENCE_ORDER, ApproachLimits
from approachsim.profile import Profile

IN = units.IN
"""Metres per inch (exact)."""


@dataclass(frozen=True)
class Aircraft:
    """An aircraft's approach configuration, SI."""

    name: str
    jsbsim_model: str
    approach_speed_mps: float
    """Calibrated approach speed, m/s."""
    flaps_norm: float
    gear_down: bool
    engine_lag_s: float
    """First-order throttle-to-thrust lag used in the loop design, s."""
    imu_location_struct_m: tuple[float, float, float]
    """IMU location in JSBSim's structural frame (x aft, y right, z up), m."""
    gains: AutopilotGains
    source: Path
    limits: ApproachLimits
    """The approach limits of the aircraft file's [envelope] table (flight.envelope)."""
    ground_contact: GroundContact | None = None
    """The aircraft file's [ground_contact] table (None: no ground-contact criterion)."""
    mass: Mass | None = None
    """The aircraft file's [mass] table (None: the JSBSim model as loaded, no weight or CG choice)."""
    tanks: tuple[tuple[float, float], ...] = ()
    """The JSBSim tank loading that gives the profile's weight and CG: (contents lb, station x in) per tank
    (Mass.tank_loading; empty: the model as loaded)."""


@dataclass(frozen=True)
class Mass:
    """Weight and balance of the JSBSim model and the aircraft's landing limits (aircraft file [mass]). The model
    has no payload stations: a chosen weight and CG is loaded as its tanks' contents (wing tanks first, each up to
    its capacity, then the centre tank) with every tank's mass moved to the one station x that puts the CG where
    asked (JSBSim's propulsion/tank[i]/x-position); the tanks' y and z stay as modelled."""

    empty_weight_lb: float
    empty_cg_x_in: float
    loaded_weight_lb: float
    """The model as loaded (empty + its tanks' contents): the weight approach_speed_kt is for."""
    loaded_cg_x_in: float
    """The model's CG as loaded, in."""
    tank_capacity_lb: tuple[float, ...]
    """Capacity per tank, in JSBSim's tank order (wing tanks first, then the centre tank)."""
    tank_x_in: tuple[float, ...]
    """Each tank's modelled station (its drain location), in."""
    lemac_x_in: float
    mac_in: float
    min_landing_weight_lb: float
    max_landing_weight_lb: float
    cg_fwd_mac: float
    cg_aft_mac: float
    """The CG range dispersions draw from, fractions of the MAC."""
    station_range_in: tuple[float, float]
    """The stations a load may be placed at (the fuselage), in."""

    @property
    def loaded_cg_mac(self) -> float:
        """The model's CG as loaded, fraction of the MAC."""
        return (self.loaded_cg_x_in - self.lemac_x_in) / self.mac_in

    def cg_x_in(self, cg_mac: float) -> float:
        """Station of a CG given as a fraction of the MAC, in."""
        return self.lemac_x_in + cg_mac * self.mac_in

    def cg_range_mac(self, weight_lb: float) -> tuple[float, float]:
        """The CG range (fractions of the MAC) loadable at a gross weight: [cg_fwd_mac, cg_aft_mac] within what the
        load placed anywhere in station_range_in reaches."""
        load = weight_lb - self.empty_weight_lb
        ends = [((self.empty_weight_lb * self.empty_cg_x_in + load * x) / weight_lb - self.lemac_x_in) / self.mac_in
                for x in self.station_range_in]
        return max(self.cg_fwd_mac, min(ends)), min(self.cg_aft_mac, max(ends))

    def tank_loading(self, weight_lb: float, cg_mac: float) -> tuple[tuple[float, float], ...]:
        """(contents lb, station x in) per tank for the gross weight and CG; ValueError when the weight exceeds the
        tanks or the CG needs a station outside station_range_in."""
        load = weight_lb - self.empty_weight_lb
        if not 0.0 < load <= sum(self.tank_capacity_lb):
            raise ValueError(f"{weight_lb:.0f} lb is outside the model's {self.empty_weight_lb:.0f} lb empty weight "
                             f"plus {sum(self.tank_capacity_lb):.0f} lb of tank capacity")
        x = (weight_lb * self.cg_x_in(cg_mac) - self.empty_weight_lb * self.empty_cg_x_in) / load
        lo, hi = self.station_range_in
        if not lo <= x <= hi:
            raise ValueError(f"a CG at {100.0 * cg_mac:.1f} % MAC needs the {load:.0f} lb load at station {x:.0f} in, "
                             f"outside the fuselage ({lo:.0f}-{hi:.0f} in)")
        out, left = [], load
        caps = self.tank_capacity_lb
        wings = min(load / 2.0, caps[0], caps[1])
        for i, (cap, d) in enumerate(zip(caps, self.tank_x_in, strict=True)):
            c = wings if i < 2 else min(left, cap)
            left -= c
            # JSBSim puts a tank's mass at drain + (contents / capacity) (location - drain) (FGTank::GetXYZ; the
            # drain is the modelled location): the location that puts it at x
            out.append((c, d + (x - d) * cap / c if c > 0.0 else d))
        return tuple(out)


@dataclass(frozen=True)
class GroundContact:
    """Points of the right wing that touch the runway first in a banked touchdown (the left wing's are their
    mirror), in JSBSim's structural frame (x aft, y right, z up), m, and the main gear's strut compression at which
    the contact bank is taken, m (aircraft file [ground_contact])."""

    points_struct_m: tuple[tuple[float, float, float], ...]
    names: tuple[str, ...]
    gear_compression_m: float


def aircraft_dirs(profile: Profile | None) -> list[Path]:
    """Directories searched for aircraft files, in order (approachsim.resources.aircraft_dirs)."""
    return resources.aircraft_dirs(None if profile is None else profile.source)


def find_aircraft_file(name: str, profile: Profile | None = None) -> Path:
    """The aircraft file for `name`; ProfileError (naming aircraft.name) when none exists."""
    return resources.find_aircraft_file(name, None if profile is None else profile.source)


def _gains(s: Section) -> AutopilotGains:
    def pos(key: str) -> float:
        return s.number(key, lo=0.0)

    def pos_default(key: str) -> float:
        return s.number(key, 0.0, lo=0.0)

    g = AutopilotGains(
        k_theta=pos("k_theta"),
        k_q=pos("k_q"),
        k_gs_p=pos("k_gs_p"),
        k_gs_d=pos("k_gs_d"),
        k_gs_i=pos("k_gs_i"),
        k_v_p=pos("k_v_p"),
        k_v_i=pos("k_v_i"),
        tau_v_s=s.number("tau_v_s", lo=0.0, lo_open=True, unit="s"),
        tau_wind_s=s.number("tau_wind_s", 20.0, lo=0.0, hi=600.0, lo_open=True, unit="s"),
        k_phi=pos("k_phi"),
        k_p=pos("k_p"),
        k_beta=pos("k_beta"),
        k_loc_p=pos("k_loc_p"),
        k_loc_d=pos("k_loc_d"),
        k_loc_i=pos("k_loc_i"),
        bank_limit_rad=math.radians(s.number("bank_limit_deg", lo=0.0, hi=35.0, lo_open=True, unit="deg")),
        pitch_limit_rad=math.radians(s.number("pitch_limit_deg", lo=0.0, hi=20.0, lo_open=True, unit="deg")),
        flare_height_m=s.number("flare_height_ft", lo=10.0, hi=200.0, unit="ft") * units.FT,
        touchdown_sink_mps=s.number("touchdown_sink_fps", lo=0.0, hi=10.0, unit="ft/s") * units.FPS,
        k_flare=pos("k_flare"),
        k_flare_i=pos("k_flare_i"),
        retard_height_m=s.number("retard_height_ft", lo=0.0, hi=200.0, unit="ft") * units.FT,
        tecs=s.string("law", "classic", choices=LAWS) == "tecs",
        tecs_t_h_s=s.number("tecs_t_h_s", 5.0, lo=0.0, hi=60.0, lo_open=True, unit="s"),
        tecs_t_v_s=s.number("tecs_t_v_s", 5.0, lo=0.0, hi=60.0, lo_open=True, unit="s"),
        tecs_thr_per_rad=s.number("tecs_thr_per_rad", 3.44, lo=0.0, hi=100.0, lo_open=True),
        tecs_k_thr_damp=s.number("tecs_k_thr_damp", 0.05, lo=0.0),
        tecs_k_thr_i=s.number("tecs_k_thr_i", 0.05, lo=0.0),
        tecs_k_pitch_damp=s.number("tecs_k_pitch_damp", 0.1, lo=0.0),
        tecs_k_pitch_i=s.number("tecs_k_pitch_i", 0.1, lo=0.0),
        tecs_seb_ff=s.number("tecs_seb_ff", 1.0, lo=0.0),
        tecs_spd_weight=s.number("tecs_spd_weight", 1.0, lo=0.0, hi=2.0),
        tecs_rate_tau_s=s.number("tecs_rate_tau_s", 0.4, lo=0.0, hi=10.0, lo_open=True, unit="s"),
        tecs_sink_max_mps=s.number("tecs_sink_max_fpm", 1000.0, lo=0.0, hi=3000.0, lo_open=True, unit="ft/min")
        * units.FT / 60.0,
        tecs_climb_max_mps=s.number("tecs_climb_max_fpm", 600.0, lo=0.0, hi=6000.0, lo_open=True, unit="ft/min")
        * units.FT / 60.0,
        tecs_vert_acc_mps2=s.number("tecs_vert_acc_mps2", 7.0, lo=0.0, hi=50.0, lo_open=True, unit="m/s^2"),
        align_height_m=s.number("align_height_ft", 0.0, lo=0.0, hi=500.0, unit="ft") * units.FT,
        align_tau_s=s.number("align_tau_s", 1.5, lo=0.0, hi=20.0, lo_open=True, unit="s"),
        k_r_align=pos_default("k_r_align"),
        k_beta_align=pos_default("k_beta_align"),
        k_phi_align=pos_default("k_phi_align"),
        k_da_align=pos_default("k_da_align"),
        align_bank_max_rad=math.radians(s.number("align_bank_max_deg", math.inf, lo=0.0, hi=90.0, lo_open=True,
                                                 unit="deg")),
        align_cas_mps=s.number("align_design_cas_kt", 0.0, lo=0.0, hi=300.0, unit="kt") * units.KT,
        align_sideslip_max_rad=math.radians(s.number("align_sideslip_max_deg", math.inf, lo=0.0, hi=30.0,
                                                     lo_open=True, unit="deg")),
        flare_t_path_s=s.number("flare_t_path_s", 0.0, lo=0.0, hi=10.0, unit="s"),
        flare_k_v=s.number("flare_k_v", 0.0, lo=0.0, hi=1.0),
        flare_k_gust=s.number("flare_k_gust", 0.0, lo=0.0, hi=1.0),
        flare_ge_k=s.number("flare_ge_k", 0.0, lo=0.0, hi=1.0),
        flare_ge_decay_m=s.number("flare_ge_decay_ft", 1.0 / units.FT, lo=0.0, hi=500.0, lo_open=True, unit="ft")
        * units.FT,
        flare_ge_arp_m=s.number("flare_ge_arp_ft", 0.0, lo=0.0, hi=50.0, unit="ft") * units.FT,
        flare_pitch_min_rad=math.radians(s.number("flare_pitch_min_deg", -90.0, lo=-90.0, hi=10.0, unit="deg")),
        flare_pitch_min_height_m=s.number("flare_pitch_min_height_ft", 0.0, lo=0.0, hi=200.0, unit="ft") * units.FT,
    )
    s.done()
    return g


def _ground_contact(s: Section) -> GroundContact:
    names = ("nacelle", "wingtip")
    pts = tuple(tuple(s.number(f"{n}_{c}_in", unit="in") * IN for c in "xyz") for n in names)
    comp = s.number("gear_compression_in", 0.0, lo=0.0, hi=40.0, unit="in") * IN
    s.done()
    for n, p in zip(names, pts, strict=True):
        if p[1] <= 0.0:
            raise ProfileError(f"{s.path}.{n}_y_in: must be positive (the right wing's point)")
    return GroundContact(points_struct_m=pts, names=names, gear_compression_m=comp)  # type: ignore[arg-type]


def _limits(s: Section) -> ApproachLimits:
    kt, ft = units.KT, units.FT
    lim = ApproachLimits(
        max_headwind_mps=s.number("max_headwind_kt", lo=0.0, hi=60.0, unit="kt") * kt,
        max_tailwind_mps=s.number("max_tailwind_kt", lo=0.0, hi=30.0, unit="kt") * kt,
        max_crosswind_mps=s.number("max_crosswind_kt", lo=0.0, hi=60.0, unit="kt") * kt,
        min_glidepath_rad=math.radians(s.number("min_glidepath_deg", lo=1.0, hi=10.0, unit="deg")),
        max_glidepath_rad=math.radians(s.number("max_glidepath_deg", lo=1.0, hi=10.0, unit="deg")),
        min_field_elevation_m=s.number("min_field_elevation_ft", lo=-2000.0, hi=15000.0, unit="ft") * ft,
        max_field_elevation_m=s.number("max_field_elevation_ft", lo=-2000.0, hi=15000.0, unit="ft") * ft,
        max_turbulence=s.string("max_turbulence", choices=TURBULENCE_ORDER),
    )
    s.done()
    if lim.min_glidepath_rad > lim.max_glidepath_rad:
        raise ProfileError(f"{s.path}.min_glidepath_deg: must not exceed max_glidepath_deg")
    if lim.min_field_elevation_m > lim.max_field_elevation_m:
        raise ProfileError(f"{s.path}.min_field_elevation_ft: must not exceed max_field_elevation_ft")
    return lim


def _mass(s: Section) -> Mass:
    lb = "lb"
    m = Mass(
        empty_weight_lb=s.number("empty_weight_lb", lo=0.0, lo_open=True, unit=lb),
        empty_cg_x_in=s.number("empty_cg_x_in", unit="in"),
        loaded_weight_lb=s.number("loaded_weight_lb", lo=0.0, lo_open=True, unit=lb),
        loaded_cg_x_in=s.number("loaded_cg_x_in", unit="in"),
        tank_capacity_lb=s.numbers("tank_capacity_lb", min_len=3, unit=lb),
        tank_x_in=s.numbers("tank_x_in", min_len=3, unit="in"),
        lemac_x_in=s.number("lemac_x_in", unit="in"),
        mac_in=s.number("mac_in", lo=0.0, lo_open=True, unit="in"),
        min_landing_weight_lb=s.number("min_landing_weight_lb", lo=0.0, lo_open=True, unit=lb),
        max_landing_weight_lb=s.number("max_landing_weight_lb", lo=0.0, lo_open=True, unit=lb),
        cg_fwd_mac=s.number("cg_fwd_percent_mac", lo=-50.0, hi=100.0, unit="% MAC") / 100.0,
        cg_aft_mac=s.number("cg_aft_percent_mac", lo=-50.0, hi=100.0, unit="% MAC") / 100.0,
        station_range_in=tuple(s.numbers("station_range_in", min_len=2, unit="in")[:2]),  # type: ignore[arg-type]
    )
    s.done()
    if not m.min_landing_weight_lb <= m.max_landing_weight_lb:
        raise ProfileError(f"{s.path}.min_landing_weight_lb: must not exceed max_landing_weight_lb")
    if len(m.tank_x_in) != len(m.tank_capacity_lb):
        raise ProfileError(f"{s.path}.tank_x_in: needs one station per tank_capacity_lb value")
    if not m.cg_fwd_mac <= m.cg_aft_mac:
        raise ProfileError(f"{s.path}.cg_fwd_percent_mac: must not exceed cg_aft_percent_mac")
    return m


def parse_aircraft(data: dict, source: Path) -> Aircraft:
    """Validate the dict of an aircraft file."""
    top = Section(data, "")
    name = top.string("name")
    top.string("description", "")
    model = top.section("model", default_empty=False)
    jsbsim_model = model.string("jsbsim_model")
    model.done()
    ap = top.section("approach", default_empty=False)
    speed = ap.number("approach_speed_kt", lo=80.0, hi=200.0, unit="kt") * units.KT
    flaps = ap.number("flaps_norm", lo=0.0, hi=1.0)
    gear = ap.boolean("gear_down")
    lag = ap.number("engine_lag_s", lo=0.0, hi=10.0, lo_open=True, unit="s")
    ap.done()
    imu = top.section("imu", default_empty=False)
    loc = tuple(imu.number(f"location_{c}_in", unit="in") * IN for c in "xyz")
    imu.done()
    gains = _gains(top.section("autopilot", default_empty=False))
    limits = _limits(top.section("envelope", default_empty=False))
    contact = _ground_contact(top.section("ground_contact")) if top.has("ground_contact") else None
    mass = _mass(top.section("mass")) if top.has("mass") else None
    top.done()
    return Aircraft(
        name=name,
        jsbsim_model=jsbsim_model,
        approach_speed_mps=speed,
        flaps_norm=flaps,
        gear_down=gear,
        engine_lag_s=lag,
        imu_location_struct_m=loc,  # type: ignore[arg-type]
        gains=gains,
        source=source,
        limits=limits,
        ground_contact=contact,
        mass=mass,
    )


def load_aircraft(profile: Profile) -> Aircraft:
    """The profile's aircraft with the profile's overrides (approach speed, flaps, gear) applied."""
    path = find_aircraft_file(profile.aircraft.name, profile)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as e:
        raise ProfileError(f"aircraft.name: {str(path)!r} is not valid TOML ({e})") from None
    try:
        ac = parse_aircraft(data, path)
    except ProfileError as e:
        raise ProfileError(f"aircraft file {path.name}: {e}") from None
    choice = profile.aircraft
    speed, tanks = ac.approach_speed_mps, ()
    if choice.weight_n is not None or choice.cg_mac is not None:
        speed, tanks = _loading(ac, choice)
    return Aircraft(
        name=ac.name,
        jsbsim_model=ac.jsbsim_model,
        approach_speed_mps=speed if choice.approach_speed_mps is None else choice.approach_speed_mps,
        flaps_norm=ac.flaps_norm if choice.flaps_norm is None else choice.flaps_norm,
        gear_down=choice.gear_down,
        engine_lag_s=ac.engine_lag_s,
        imu_location_struct_m=ac.imu_location_struct_m,
        gains=ac.gains if choice.autopilot_law is None else dataclasses.replace(
            ac.gains, tecs=choice.autopilot_law == "tecs"),
        source=ac.source,
        limits=ac.limits,
        ground_contact=ac.ground_contact,
        mass=ac.mass,
        tanks=tanks,
    )


def _loading(ac: Aircraft, choice: object) -> tuple[float, tuple[tuple[float, float], ...]]:
    """The approach speed and tank loading for the profile's weight and CG (aircraft.weight_lb,
    aircraft.cg_percent_mac; either one alone keeps the model's other): the file's approach speed scaled by
    sqrt(W / W_loaded), the reference speed's constant lift coefficient (1.23 V_s1g at any weight)."""
    m = ac.mass
    if m is None:
        raise ProfileError(f"aircraft.weight_lb: the aircraft file {ac.source.name} has no [mass] table")
    w_lb = m.loaded_weight_lb if choice.weight_n is None else choice.weight_n / units.LBF  # type: ignore[attr-defined]
    if not m.min_landing_weight_lb <= w_lb <= m.max_landing_weight_lb:
        raise ProfileError(f"aircraft.weight_lb: must be in [{m.min_landing_weight_lb:g}, {m.max_landing_weight_lb:g}] "
                           f"lb (aircraft file [mass] landing weights), got {w_lb:g}")
    cg = choice.cg_mac  # type: ignore[attr-defined]
    if cg is None:
        cg = m.loaded_cg_mac
    try:
        tanks = m.tank_loading(w_lb, cg)
    except ValueError as e:
        raise ProfileError(f"aircraft.cg_percent_mac: {e}") from None
    return ac.approach_speed_mps * math.sqrt(w_lb / m.loaded_weight_lb), tanks
