"""The profile's [sensors] table and [[faults]] array, parsed strictly into frozen config objects.

Feet and degrees at this edge only (max_range_ft, mask_deg, pseudolite positions in ft); everything else is
SI with the unit in the key. A profile without [sensors] gets DEFAULT_SENSORS (seed 002's suite: 2 nmi/h
INS, baro, P-code GPS best four, radar altimeter below 3000 ft, no pseudolite). Every key is documented in
profiles/default.toml.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

from approachsim import units
from approachsim.config import ProfileError, Section
from approachsim.sensors.faults import FAULT_KINDS, FaultSpec
from approachsim.sensors.gnss.carrier import L1_WAVELENGTH_M, CarrierModel
from approachsim.sensors.gnss.clock import C_LIGHT, OSCILLATORS
from approachsim.sensors.gnss.constellation import SLOTS, parse_epoch
from approachsim.sensors.gnss.gbas import AADS, GADS, GbasModel
from approachsim.sensors.gnss.receiver import (
    CLOCK_EPHEMERIS_M,
    CODE_PRESETS,
    MULTIPATH_MODELS,
    SELECTIONS,
    SIDEREAL_DAY_S,
    GnssErrorBudget,
    make_budget,
)
from approachsim.sensors.gnss.service import AADS as SERVICE_AADS
from approachsim.sensors.gnss.service import (
    DFRE_SIGMA_M,
    FILTER_MODELS,
    GIVE_M,
    SERVICES,
    TRUTHS,
    UDRE_M,
    URA_M,
    ServiceModel,
)
from approachsim.sensors.presets import PRESETS
from approachsim.sensors.pseudolite import SYNC_SIGMA_NS, SYNC_TAU_S
from approachsim.sensors.radalt import RADALT_CORRELATED_1SIGMA_M

SENSOR_NAMES = ("imu", "baro", "radalt", "gnss", "pseudolite")
"""Sensor names: profile tables, random-stream names and record names."""


@dataclass(frozen=True)
class ImuConfig:
    """[sensors.imu]: grade preset name, optional quantization steps (rad, m/s; 0 = none)."""

    grade: str = "nav-2.0"
    gyro_quant_rad: float = 0.0
    accel_quant_mps: float = 0.0


STATIC_SOURCE_SIGMA_M = 1.5
"""Static-source (position) error left after the air data's correction, m 1-sigma [U]: standards.md 4.1 has no
approach-configuration figure (RVSM's 25 m mean / 60 m mean + 3 sigma are cruise ASE); 0.5 % of the impact pressure
at 140 kt (q_c ~ 3.2 kPa: 16 Pa, 1.3 m at the field) read as the residual of the SSEC (docs/truth.md)."""
STATIC_SOURCE_TAU_S = 300.0
"""Its correlation time, s [U]: it follows the airspeed, angle of attack and configuration, which change every few
minutes on an approach (flaps, gear, the speed schedule)."""
QNH_SIGMA_HPA = 0.3
"""The reported QNH's error, hPa 1-sigma [U]: ICAO Annex 3's operationally desirable QNH accuracy, +-0.5 hPa (not
retrieved into standards.md), read as 2 sigma, with the pressure tendency over a half-hour-old report
(1 hPa in 3 h: 0.17 hPa) in quadrature: 0.3 hPa, 2.5 m at sea level. The whole-hPa rounding:
environment.qnh_report."""
TEMPERATURE_SCALE_SIGMA = {"none": 0.12, "aerodrome": 0.025}
"""The filter's prior sigma of the day's temperature scale error on the height above the field, by
temperature_correction [U: the issue's review]: none: dT / T_f, with ISA -30 (0.116 at sea level, 0.121 at
5434 ft) inside 1 sigma; aerodrome: what a lapse rate departing from the standard leaves (a 10 K surface layer
over 1000 ft: about 0.035 at the field, falling above)."""
BIAS_TAU_CONSTANT_S = 36000.0
"""The bb state's time constant when every slow baro error is a constant (only the QNH error), s."""


@dataclass(frozen=True)
class BaroConfig:
    """[sensors.baro]: seed 001 / 003 error model (m, s, dimensionless)."""

    rate_hz: float = 10.0
    bias_sigma_m: float = 1.0
    bias_tau_s: float = 100.0
    scale_factor_sigma: float = 0.0
    noise_sigma_m: float = 1.0
    lag_s: float = 0.0
    temperature_correction: str = "none"
    """none | aerodrome: the indication corrected with the reported aerodrome temperature (sensors/atmosphere.py)."""
    static_source_sigma_m: float = STATIC_SOURCE_SIGMA_M
    static_source_tau_s: float = STATIC_SOURCE_TAU_S
    qnh_sigma_hpa: float = QNH_SIGMA_HPA
    """The reported QNH's error, hPa 1-sigma (a per-run constant; the truth converts it at the field's dh/dp)."""
    temperature_scale_sigma: float | None = None
    """The filter's prior on the day's temperature scale error of the height above the field (its sb state with
    the instrument's scale_factor_sigma); None: TEMPERATURE_SCALE_SIGMA[temperature_correction]."""

    @property
    def filter_scale_sigma(self) -> float:
        """The filter's sb prior sigma: the day's temperature scale error and the instrument's, in quadrature."""
        t = TEMPERATURE_SCALE_SIGMA[self.temperature_correction] if self.temperature_scale_sigma is None else \
            self.temperature_scale_sigma
        return math.hypot(t, self.scale_factor_sigma)

    def filter_bias(self, height_per_hpa_m: float) -> tuple[float, float]:
        """(sigma m, tau s) of the filter's one baro-bias state bb for the truth's slow errors: the seed's Gauss-Markov
        bias, the static-source error and the QNH error (dh/dp at the field height_per_hpa_m, m/hPa; a constant).
        sigma^2 is the sum of their variances; tau = sigma^2 / sum(sigma_i^2 / tau_i) makes the filter's process noise
        2 sigma^2 / tau the sum of theirs too: the state has the truth's variance and its rate of change (the
        increment over the approach), the constant taking no part in the rate."""
        parts = [(self.bias_sigma_m, self.bias_tau_s), (self.static_source_sigma_m, self.static_source_tau_s)]
        q = self.qnh_sigma_hpa * height_per_hpa_m
        var = sum(sg**2 for sg, _ in parts) + q**2
        rate = sum(sg**2 / tau for sg, tau in parts)
        if var == 0.0:
            return 0.0, self.bias_tau_s
        return math.sqrt(var), (var / rate if rate > 0.0 else BIAS_TAU_CONSTANT_S)


@dataclass(frozen=True)
class RadaltConfig:
    """[sensors.radalt]: seed 002 noise, seed 000 Markov error and a per-run bias (sensors/radalt.py gives the
    budget), maximum range (m)."""

    rate_hz: float = 1.0
    max_range_m: float = 3000.0 * units.FT
    percent_sigma: float = 0.01
    floor_m: float = 0.5
    markov_sigma_m: float = RADALT_CORRELATED_1SIGMA_M
    markov_tau_s: float = 10.0
    bias_sigma_m: float = RADALT_CORRELATED_1SIGMA_M


@dataclass(frozen=True)
class GnssConfig:
    """[sensors.gnss]: code preset, selection, mask (rad), rate, epoch (UTC ISO), receiver oscillator."""

    code: str = "P(Y)"
    selection: str = "best4"
    mask_rad: float = math.radians(5.0)
    rate_hz: float = 1.0
    epoch_utc: str = "2026-01-01T12:00:00Z"
    oscillator: str = "tcxo"
    clock_bias0_sigma_m: float = 300.0
    clock_drift0_sigma_mps: float = 3.0
    doppler: bool = False
    doppler_noise_mps: float = 0.05
    epoch: str = "per-run"
    """"per-run": each run's sky at epoch_utc + U[0, epoch_window_s) (its own "gnss_epoch" stream); "fixed":
    every run at epoch_utc."""
    epoch_window_s: float = SIDEREAL_DAY_S
    multipath_model: str = "do253"
    multipath_tau_s: float | None = None
    """None: the model's default (receiver.make_budget)."""
    clock_ephemeris: str = "current"
    corrections: str = "none"
    """"none": stand-alone ranging; "gbas": GBAS-corrected pseudoranges (sensors/gnss/gbas.py, the `gbas` model)."""
    gbas: GbasModel | None = None
    """[sensors.gnss.gbas]: the ground station and airborne equipment (set exactly when corrections = "gbas")."""
    carrier: CarrierModel | None = None
    """carrier_phase = true: L1 carrier phase with float ambiguities (sensors/gnss/carrier.py); None: code only."""
    service: ServiceModel | None = None
    """[sensors.gnss] service: a civil (or the military) GNSS service with its broadcast sigmas and their truth
    (sensors/gnss/service.py); None: the code presets (`code`)."""
    budget_scale: float = 1.0
    """Factor on every 1-sigma of the stand-alone ranging budget (clock/ephemeris, iono, tropo, multipath, code
    noise), correlation times unchanged: a study that states its GPS as a position accuracy (Gray & Maybeck's
    4 m horizontal / 5 m vertical) scales the era budget to it. 1.0: the budget as selected."""

    def budget(self) -> GnssErrorBudget:
        """The error budget these settings select (code preset, multipath model, clock/ephemeris budget, GBAS
        corrections), its 1-sigma terms times budget_scale."""
        b = make_budget(self.code, self.multipath_model, self.clock_ephemeris, self.multipath_tau_s, self.gbas,
                        self.service)
        if self.budget_scale == 1.0:
            return b
        k = self.budget_scale
        return replace(b, clock_ephemeris_m=k * b.clock_ephemeris_m, iono_zenith_m=k * b.iono_zenith_m,
                       tropo_zenith_m=k * b.tropo_zenith_m, multipath_m=k * b.multipath_m,
                       code_noise_m=k * b.code_noise_m)

    def epoch_window(self) -> float:
        """Width (s) of the per-run epoch window; 0 for a fixed epoch."""
        return self.epoch_window_s if self.epoch == "per-run" else 0.0


EPOCH_MODES = ("per-run", "fixed")
"""[sensors.gnss] epoch: one sky per run over the window, or the one epoch_utc."""
CORRECTIONS = ("none", "gbas")
"""[sensors.gnss] corrections: stand-alone ranging, or GBAS differential corrections."""


@dataclass(frozen=True)
class PseudoliteConfig:
    """[sensors.pseudolite]: units at runway-frame (along, cross, height above threshold) m; error model.

    Pseudolites are channels of the GPS receiver: they sample at the GNSS rate with its receiver clock."""

    positions_rwy: tuple[tuple[float, float, float], ...] = ((0.0, -150.0, 10.0),)
    synchronized: bool = True
    code_noise_m: float = 0.3
    multipath_m: float = 0.5
    multipath_tau_s: float = 30.0
    survey_sigma_m: float = 0.05
    tropo_ppm_sigma: float = 30.0
    max_range_m: float = 50e3
    sync_sigma_m: float = SYNC_SIGMA_NS * 1e-9 * C_LIGHT
    """A synchronized transmitter's time-sync error 1-sigma, m (c times the profile's sync_sigma_ns;
    sensors/pseudolite.py)."""
    sync_tau_s: float = SYNC_TAU_S


@dataclass(frozen=True)
class SensorsConfig:
    """The sensor suite of a profile; None: the sensor is not fitted."""

    imu: ImuConfig = field(default_factory=ImuConfig)
    baro: BaroConfig | None = field(default_factory=BaroConfig)
    radalt: RadaltConfig | None = field(default_factory=RadaltConfig)
    gnss: GnssConfig | None = field(default_factory=GnssConfig)
    pseudolite: PseudoliteConfig | None = None


DEFAULT_SENSORS = SensorsConfig()
"""The suite of a profile with no [sensors] table (seed 002 without the pseudolite)."""


FAULT_TARGETS: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {"imu": ("dv", "dtheta"), "baro": ("h",), "radalt": ("h",), "gnss": ("pseudorange", "pseudorange_rate"),
     "pseudolite": ("pseudorange",)}
)
"""Fault targets per sensor (the first is the default)."""


def _enabled(s: Section, default: bool) -> bool:
    """The table's `enabled` flag; a disabled table may hold nothing else (done() rejects other keys)."""
    return s.boolean("enabled", default)


def parse_sensors(s: Section, site_rad: tuple[float, float] | None = None) -> SensorsConfig:
    """Parse [sensors]; absent sub-tables take the defaults; `enabled = false` removes a sensor. site_rad: the
    approach's (latitude, longitude), rad (the runway threshold): a stand-alone L1 C/A service's Klobuchar bound
    depends on its geomagnetic latitude (None: 45 deg N, 0 deg E)."""
    imu_s = s.section("imu")
    grade = imu_s.string("grade", "nav-2.0", choices=tuple(PRESETS))
    imu = ImuConfig(
        grade=grade,
        gyro_quant_rad=imu_s.number("gyro_quant_rad", 0.0, lo=0.0, unit="rad"),
        accel_quant_mps=imu_s.number("accel_quant_mps", 0.0, lo=0.0, unit="m/s"),
    )
    imu_s.done()

    b = s.section("baro")
    baro = None
    if _enabled(b, True):
        baro = BaroConfig(
            rate_hz=b.number("rate_hz", 10.0, lo=0.1, hi=1000.0, unit="Hz"),
            bias_sigma_m=b.number("bias_sigma_m", 1.0, lo=0.0, unit="m"),
            bias_tau_s=b.number("bias_tau_s", 100.0, lo=0.0, lo_open=True, unit="s"),
            scale_factor_sigma=b.number("scale_factor_sigma", 0.0, lo=0.0, hi=0.5),
            noise_sigma_m=b.number("noise_sigma_m", 1.0, lo=0.0, unit="m"),
            lag_s=b.number("lag_s", 0.0, lo=0.0, hi=10.0, unit="s"),
            temperature_correction=b.string("temperature_correction", "none", choices=("none", "aerodrome")),
            static_source_sigma_m=b.number("static_source_sigma_m", STATIC_SOURCE_SIGMA_M, lo=0.0, hi=100.0,
                                           unit="m"),
            static_source_tau_s=b.number("static_source_tau_s", STATIC_SOURCE_TAU_S, lo=0.0, lo_open=True, hi=1e6,
                                         unit="s"),
            qnh_sigma_hpa=b.number("qnh_sigma_hPa", QNH_SIGMA_HPA, lo=0.0, hi=10.0, unit="hPa"),
            temperature_scale_sigma=(b.number("temperature_scale_sigma", lo=0.0, hi=0.5)
                                     if b.has("temperature_scale_sigma") else None),
        )
    b.done()

    r = s.section("radalt")
    radalt = None
    if _enabled(r, True):
        radalt = RadaltConfig(
            rate_hz=r.number("rate_hz", 1.0, lo=0.1, hi=1000.0, unit="Hz"),
            max_range_m=r.number("max_range_ft", 3000.0, lo=100.0, hi=10000.0, unit="ft") * units.FT,
            percent_sigma=r.number("percent_of_height", 1.0, lo=0.0, hi=10.0, unit="%") / 100.0,
            floor_m=r.number("floor_m", 0.5, lo=0.0, hi=10.0, unit="m"),
            markov_sigma_m=r.number("markov_sigma_m", RADALT_CORRELATED_1SIGMA_M, lo=0.0, hi=100.0, unit="m"),
            markov_tau_s=r.number("markov_tau_s", 10.0, lo=0.0, lo_open=True, hi=1e5, unit="s"),
            bias_sigma_m=r.number("bias_sigma_m", RADALT_CORRELATED_1SIGMA_M, lo=0.0, hi=100.0, unit="m"),
        )
    r.done()

    g = s.section("gnss")
    gnss = None
    if _enabled(g, True):
        epoch = g.string("epoch_utc", "2026-01-01T12:00:00Z")
        try:
            parse_epoch(epoch)
        except ValueError as e:
            raise ProfileError(f"{g.path}.epoch_utc: {e}") from None
        service = _parse_service(g, site_rad)
        gnss = GnssConfig(
            code=(code := g.string("code", "P(Y)", choices=tuple(CODE_PRESETS))),
            selection=g.string("selection", "best4" if service is None else "all", choices=SELECTIONS),
            mask_rad=math.radians(g.number("mask_deg", 5.0, lo=0.0, hi=45.0, unit="deg")),
            rate_hz=g.number("rate_hz", 1.0, lo=0.1, hi=100.0, unit="Hz"),
            epoch_utc=epoch,
            oscillator=g.string("oscillator", "tcxo", choices=tuple(OSCILLATORS)),
            clock_bias0_sigma_m=g.number("clock_bias0_sigma_m", 300.0, lo=0.0, unit="m"),
            clock_drift0_sigma_mps=g.number("clock_drift0_sigma_mps", 3.0, lo=0.0, unit="m/s"),
            doppler=g.boolean("doppler", False),
            doppler_noise_mps=g.number("doppler_noise_mps", 0.05, lo=0.0, unit="m/s"),
            epoch=g.string("epoch", "per-run", choices=EPOCH_MODES),
            epoch_window_s=g.number("epoch_window_h", SIDEREAL_DAY_S / 3600.0, lo=0.0, lo_open=True, hi=8760.0,
                                    unit="h") * 3600.0,
            multipath_model=(mp := g.string("multipath_model", "do253", choices=MULTIPATH_MODELS)),
            multipath_tau_s=g.number("multipath_tau_s", make_budget(code, mp).multipath_tau_s, lo=0.0,
                                     lo_open=True, hi=1e5, unit="s"),
            clock_ephemeris=g.string("clock_ephemeris", "current", choices=tuple(CLOCK_EPHEMERIS_M)),
            corrections=(corr := _corrections(g, service)),
            gbas=_parse_gbas(g, corr),
            carrier=_parse_carrier(g),
            budget_scale=g.number("budget_scale", 1.0, lo=0.0, lo_open=True, hi=10.0),
            service=service,
        )
        if service is not None and gnss.carrier is not None:
            raise ProfileError(f"{g.path}.carrier_phase: not modelled with a GNSS service (service is "
                               f"{service.service!r}); remove carrier_phase or service")
        if corr == "gbas" and gnss.budget_scale != 1.0:
            raise ProfileError(f"{g.path}.budget_scale: scales the stand-alone budget only (corrections is \"gbas\")")
        if gnss.epoch == "fixed" and g.has("epoch_window_h"):
            raise ProfileError(f"{g.path}.epoch_window_h: only used with epoch = \"per-run\" (epoch is \"fixed\")")
        if corr == "gbas" and mp != "do253":
            raise ProfileError(f"{g.path}.multipath_model: corrections = \"gbas\" needs \"do253\" (the airframe "
                               f"multipath of the 100 s smoothed code), got {mp!r}")
    g.done()

    p = s.section("pseudolite")
    pseudolite = None
    if _enabled(p, False):
        units_s = p.sections("units")
        pos = []
        for u in units_s:
            pos.append((
                u.number("along_ft", lo=-200000.0, hi=50000.0, unit="ft") * units.FT,
                u.number("cross_ft", lo=-50000.0, hi=50000.0, unit="ft") * units.FT,
                u.number("height_ft", 30.0, lo=-500.0, hi=2000.0, unit="ft") * units.FT,
            ))
            u.done()
        if not 1 <= len(pos) <= 2:
            raise ProfileError(f"{p.path}.units: needs one or two [[{p.path}.units]] tables, got {len(pos)}")
        pseudolite = PseudoliteConfig(
            positions_rwy=tuple(pos),
            synchronized=p.boolean("synchronized", True),
            code_noise_m=p.number("code_noise_m", 0.3, lo=0.0, unit="m"),
            multipath_m=p.number("multipath_m", 0.5, lo=0.0, unit="m"),
            multipath_tau_s=p.number("multipath_tau_s", 30.0, lo=0.0, lo_open=True, unit="s"),
            survey_sigma_m=p.number("survey_sigma_m", 0.05, lo=0.0, unit="m"),
            tropo_ppm_sigma=p.number("tropo_ppm_sigma", 30.0, lo=0.0, unit="ppm"),
            max_range_m=p.number("max_range_nmi", 27.0, lo=0.1, hi=200.0, unit="nmi") * units.NMI,
            sync_sigma_m=p.number("sync_sigma_ns", SYNC_SIGMA_NS, lo=0.0, hi=100.0, unit="ns") * 1e-9 * C_LIGHT,
            sync_tau_s=p.number("sync_tau_s", SYNC_TAU_S, lo=1.0, hi=1e6, unit="s"),
        )
    p.done()
    s.done()
    return SensorsConfig(imu=imu, baro=baro, radalt=radalt, gnss=gnss, pseudolite=pseudolite)


CODE_PRESET_KEYS = ("code", "multipath_model", "multipath_tau_s", "clock_ephemeris", "budget_scale")
"""[sensors.gnss] keys of the code presets' stand-alone budget (receiver.py), not used with a service."""
SBAS_L1_KEYS = ("udre_index", "give_index", "delta_udre", "eps_fc_m", "eps_rrc_m", "eps_ltc_m", "eps_er_m",
                "rss_udre")
"""[sensors.gnss] keys of the SBAS L1 correction model (service = "sbas-l1" only)."""


def _corrections(g: Section, service: ServiceModel | None) -> str:
    """[sensors.gnss] corrections: "none" or "gbas"; "sbas" is a service, and a service carries its corrections."""
    raw = g.raw("corrections", "none")
    if raw == "sbas":
        raise ProfileError(f"{g.path}.corrections: SBAS is a GNSS service: set service = \"sbas-l1\" (L1) or "
                           f"\"dfmc-sbas\" (L1/L5) instead")
    corr = g.string("corrections", "none", choices=CORRECTIONS)
    if service is not None and corr != "none":
        raise ProfileError(f"{g.path}.corrections: a GNSS service carries its own corrections (service is "
                           f"{service.service!r}); remove corrections")
    return corr


def _parse_service(g: Section, site_rad: tuple[float, float] | None) -> ServiceModel | None:
    """[sensors.gnss] service and its keys (sensors/gnss/service.py); a key of a model the service does not have is
    an error naming it (an SBAS correction key without an SBAS service, a code-preset key with a service)."""
    if not g.has("service"):
        for k in (*SBAS_L1_KEYS, "dfrei", "aad", "ura_m", "truth", "filter_model"):
            if g.has(k):
                raise ProfileError(f"{g.path}.{k}: only used with a GNSS service (service = "
                                   f"{' | '.join(repr(x) for x in SERVICES)}); none is set")
        return None
    name = g.string("service", choices=SERVICES)
    for k in CODE_PRESET_KEYS:
        if g.has(k):
            raise ProfileError(f"{g.path}.{k}: a code-preset key, not used with service = {name!r} (the service sets "
                               f"the signal and its error model); remove it")
    if name != "sbas-l1":
        for k in SBAS_L1_KEYS:
            if g.has(k):
                why = ("its SBAS corrections are DFMC: set dfrei" if name == "dfmc-sbas"
                       else "it has no SBAS correction model: use service = \"sbas-l1\"")
                raise ProfileError(f"{g.path}.{k}: an SBAS L1 correction key, but service is {name!r} ({why})")
    if name != "dfmc-sbas" and g.has("dfrei"):
        raise ProfileError(f"{g.path}.dfrei: a DFMC SBAS correction key, but service is {name!r} (no DFMC SBAS "
                           f"corrections: use service = \"dfmc-sbas\")")
    if name in ("sbas-l1", "dfmc-sbas") and g.has("ura_m"):
        raise ProfileError(f"{g.path}.ura_m: the stand-alone range sigma, but service {name!r} has SBAS corrections")
    dual = name in ("dfmc-sbas", "dfmc", "py-pps")
    aad = g.string("aad", "ED-259A" if name in ("dfmc-sbas", "dfmc") else "B", choices=SERVICE_AADS)
    if aad == "ED-259A" and not dual:
        raise ProfileError(f"{g.path}.aad: the ED-259A airborne model is dual-frequency; service {name!r} is single "
                           f"frequency (use \"A\" or \"B\")")
    model = ServiceModel(
        service=name,
        udre_index=g.integer("udre_index", 5, lo=0, hi=len(UDRE_M) - 1),
        give_index=g.integer("give_index", 9, lo=0, hi=len(GIVE_M) - 1),
        delta_udre=g.number("delta_udre", 1.0, lo=1.0, hi=100.0),
        eps_fc_m=g.number("eps_fc_m", 0.0, lo=0.0, hi=100.0, unit="m"),
        eps_rrc_m=g.number("eps_rrc_m", 0.0, lo=0.0, hi=100.0, unit="m"),
        eps_ltc_m=g.number("eps_ltc_m", 0.0, lo=0.0, hi=100.0, unit="m"),
        eps_er_m=g.number("eps_er_m", 0.0, lo=0.0, hi=100.0, unit="m"),
        rss_udre=g.boolean("rss_udre", False),
        dfrei=g.integer("dfrei", 4, lo=1, hi=len(DFRE_SIGMA_M)),
        aad=aad,
        ura_m=g.number("ura_m", URA_M, lo=0.0, lo_open=True, hi=100.0, unit="m"),
        truth=(truth := g.string("truth", "nominal", choices=TRUTHS)),
        filter_model=g.string("filter_model", truth, choices=FILTER_MODELS),
    )
    return model if site_rad is None else model.at_site(*site_rad)


CARRIER_KEYS = ("carrier_multipath_m", "carrier_multipath_tau_s", "carrier_noise_m", "carrier_ambiguity_sigma_m")
"""[sensors.gnss] keys of the carrier-phase model (only with carrier_phase = true)."""


def _parse_carrier(g: Section) -> CarrierModel | None:
    """[sensors.gnss] carrier_phase and its model's keys (an error without carrier_phase = true)."""
    if not g.boolean("carrier_phase", False):
        for k in CARRIER_KEYS:
            if g.has(k):
                raise ProfileError(f"{g.path}.{k}: only used with carrier_phase = true")
        return None
    d = CarrierModel()
    return CarrierModel(
        multipath_m=g.number("carrier_multipath_m", d.multipath_m, lo=0.0, hi=L1_WAVELENGTH_M / 4.0, unit="m"),
        multipath_tau_s=g.number("carrier_multipath_tau_s", d.multipath_tau_s, lo=0.0, lo_open=True, hi=1e5,
                                 unit="s"),
        noise_m=g.number("carrier_noise_m", d.noise_m, lo=0.0, hi=0.05, unit="m"),
        ambiguity_sigma_m=g.number("carrier_ambiguity_sigma_m", d.ambiguity_sigma_m, lo=0.0, lo_open=True, hi=1e4,
                                   unit="m"),
    )


def _parse_gbas(g: Section, corrections: str) -> GbasModel | None:
    """[sensors.gnss.gbas] (only with corrections = "gbas"; the table is an error otherwise)."""
    t = g.section("gbas")
    if corrections != "gbas":
        if g.has("gbas"):
            raise ProfileError(f"{t.path}: only used with corrections = \"gbas\" (corrections is {corrections!r})")
        return None
    model = GbasModel(
        gad=t.string("gad", "C", choices=GADS),
        aad=t.string("aad", "B", choices=AADS),
        reference_receivers=t.integer("reference_receivers", 4, lo=2, hi=4),
        sigma_vig_per_m=t.number("sigma_vig_mm_per_km", 4.0, lo=0.0, hi=500.0, unit="mm/km") * 1e-6,
        refractivity_sigma=t.number("refractivity_sigma", 30.0, lo=0.0, hi=255.0, unit="N-units"),
        scale_height_m=t.number("scale_height_m", 7350.0, lo=0.0, lo_open=True, hi=25500.0, unit="m"),
        ground_tau_s=t.number("ground_tau_s", 300.0, lo=0.0, lo_open=True, hi=1e5, unit="s"),
        station_rwy_m=(t.number("station_along_ft", 0.0, lo=-200000.0, hi=50000.0, unit="ft") * units.FT,
                       t.number("station_cross_ft", 0.0, lo=-50000.0, hi=50000.0, unit="ft") * units.FT,
                       t.number("station_height_ft", 0.0, lo=-500.0, hi=2000.0, unit="ft") * units.FT),
    )
    t.done()
    return model


FAULT_PARAMETERS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "outage": (), "spike": ("k", "steps", "every"), "iam": ("magnitude", "steps", "every"),
    "cbm": ("magnitude",), "mni": ("factor",), "step": ("magnitude",), "ramp": ("rate",),
})
"""The parameters each fault kind uses (besides sensor, kind, start_s, end_s, target, channel); others are errors."""
_REQUIRED: Mapping[str, tuple[str, float]] = MappingProxyType({
    "spike": ("k", 1.0), "iam": ("magnitude", 0.0), "cbm": ("magnitude", 0.0), "mni": ("factor", 1.0),
    "step": ("magnitude", 0.0), "ramp": ("rate", 0.0),
})
"""Per kind, the parameter that sets its size and the value at which the fault would change nothing."""
FAULT_UNITS: Mapping[tuple[str, str], str] = MappingProxyType({
    ("imu", "dv"): "m/s per IMU sample", ("imu", "dtheta"): "rad per IMU sample", ("baro", "h"): "m",
    ("radalt", "h"): "m", ("gnss", "pseudorange"): "m", ("gnss", "pseudorange_rate"): "m/s",
    ("pseudolite", "pseudorange"): "m",
})
"""Unit of `magnitude` per (sensor, target); `rate` is that unit per second."""


RUN_DURATION_MARGIN = 1.1
"""Faults must start before this multiple of the estimated run length (a run may end a little later than
estimated: turbulence, speed changes, a flare to touchdown); a start after it can only be a mistake."""


def _sensor_rate_hz(sensor: str, sensors: SensorsConfig, imu_hz: float) -> float:
    if sensor == "imu":
        return imu_hz
    if sensor == "pseudolite":  # pseudolites are channels of the GPS receiver
        return sensors.gnss.rate_hz if sensors.gnss is not None else 1.0
    return getattr(sensors, sensor).rate_hz


def _check_channel(f: Section, sensor: str, channel: int, sensors: SensorsConfig) -> None:
    """The channel must exist on the sensor: IMU axis 0-2, a GPS PRN of the constellation, a pseudolite unit."""
    name = f"{f.path}.channel"
    if sensor == "imu" and not 0 <= channel <= 2:
        raise ProfileError(f"{name}: the IMU has axes 0, 1, 2 (x, y, z body), got {channel}")
    if sensor in ("baro", "radalt"):
        raise ProfileError(f"{name}: the {sensor} has one channel; remove channel")
    if sensor == "gnss":
        prns = sorted(slot[3] for slot in SLOTS)
        if channel not in prns:
            raise ProfileError(f"{name}: no PRN {channel} in the constellation (PRNs {prns[0]}-{prns[-1]})")
    if sensor == "pseudolite":
        n = len(sensors.pseudolite.positions_rwy)
        if not 0 <= channel < n:
            raise ProfileError(f"{name}: pseudolite unit index must be in [0, {n - 1}] ({n} unit(s)), got {channel}")


def parse_faults(
    items: list[Section], sensors: SensorsConfig, *, duration_s: float | None = None, imu_hz: float = 120.0
) -> tuple[FaultSpec, ...]:
    """Parse [[faults]], each checked against the sensor it targets and the run it falls in.

    A fault on a sensor the suite does not fit, a channel the sensor does not have, a parameter its kind does
    not use, a missing or no-op size (magnitude 0, rate 0, factor 1, k 1), an IMU outage (the strapdown INS
    needs every IMU sample) or a start (or step) after the run's end (`duration_s`, the caller's estimate of
    the run length, with RUN_DURATION_MARGIN; None: not checked) are errors naming the field.
    """
    last_s = None if duration_s is None else RUN_DURATION_MARGIN * duration_s
    out = []
    for f in items:
        sensor = f.string("sensor", choices=SENSOR_NAMES)
        if sensor != "imu" and getattr(sensors, sensor) is None:
            raise ProfileError(f"{f.path}.sensor: {sensor!r} is not fitted (enable [sensors.{sensor}])")
        kind = f.string("kind", choices=FAULT_KINDS)
        if sensor == "imu" and kind == "outage":
            raise ProfileError(
                f"{f.path}.kind: an IMU outage is not modelled (the strapdown INS integrates every IMU sample); "
                "use step, ramp, spike, iam, cbm or mni on the IMU, or an outage of an aiding sensor"
            )
        start = f.number("start_s", 0.0, lo=0.0, unit="s")
        end = f.number("end_s", math.inf, lo=0.0, unit="s") if f.has("end_s") else math.inf
        if end <= start:
            raise ProfileError(f"{f.path}.end_s: must be after start_s ({start:g} s), got {end:g}")
        if last_s is not None and start >= last_s:
            raise ProfileError(
                f"{f.path}.start_s: must be before {last_s:.0f} s (the run lasts about {duration_s:.0f} s: start "
                f"distance at the approach ground speed), got {start:g}"
            )
        for key in ("magnitude", "rate", "factor", "k", "steps", "every"):
            if f.has(key) and key not in FAULT_PARAMETERS[kind]:
                uses = ", ".join(FAULT_PARAMETERS[kind]) or "no size parameter"
                raise ProfileError(f"{f.path}.{key}: not used by a {kind} fault (it uses {uses})")
        steps = f.raw("steps", [])
        if not isinstance(steps, list) or any(isinstance(x, bool) or not isinstance(x, int) or x < 0 for x in steps):
            raise ProfileError(f"{f.path}.steps: must be a list of sample numbers (integers >= 0), got {steps!r}")
        if steps and f.has("every"):
            raise ProfileError(f"{f.path}.every: give steps or every, not both")
        rate_hz = _sensor_rate_hz(sensor, sensors, imu_hz)
        if steps and last_s is not None and max(steps) / rate_hz >= last_s:
            raise ProfileError(
                f"{f.path}.steps: sample {max(steps)} is at {max(steps) / rate_hz:g} s, after the end of the run "
                f"(about {duration_s:.0f} s; the {sensor} samples at {rate_hz:g} Hz)"
            )
        channel = f.raw("channel", None)
        if channel is not None:
            channel = f.integer("channel", lo=0)
            _check_channel(f, sensor, channel, sensors)
        target = f.raw("target", None)
        if target is not None:
            target = f.string("target", choices=FAULT_TARGETS[sensor])
            if target == "pseudorange_rate" and not sensors.gnss.doppler:
                raise ProfileError(f"{f.path}.target: pseudorange_rate needs [sensors.gnss] doppler = true")
        if kind in _REQUIRED:
            key, noop = _REQUIRED[kind]
            if not f.has(key):
                raise ProfileError(f"{f.path}.{key}: missing (required by a {kind} fault)")
        unit = FAULT_UNITS[(sensor, target or FAULT_TARGETS[sensor][0])]
        spec = FaultSpec(
            sensor=sensor, kind=kind, start_s=start, end_s=end, target=target, channel=channel,
            magnitude=f.number("magnitude", 0.0, unit=unit), rate=f.number("rate", 0.0, unit=f"{unit} per s"),
            factor=f.number("factor", 1.0, lo=0.0, lo_open=True), k=f.number("k", 1.0, lo=0.0),
            steps=tuple(steps), every=f.integer("every", 1, lo=1),
        )
        if kind in _REQUIRED:
            key, noop = _REQUIRED[kind]
            if getattr(spec, key) == noop:
                raise ProfileError(f"{f.path}.{key}: a {kind} fault with {key} = {noop:g} changes nothing")
        f.done()
        out.append(spec)
    return tuple(out)
