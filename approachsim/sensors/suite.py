"""The sensor suite of a profile: builds each sensor from [sensors], wraps it with its [[faults]], and draws
each sensor's errors from its own named random stream (approachsim.seeding.stream(seed, run, name)).

Streams: "imu", "baro", "radalt", "gnss", "pseudolite", "receiver_clock" for the GPS receiver clock
that the GNSS and pseudolite channels share, and "gnss_epoch" for each run's constellation epoch (one uniform
draw over [sensors.gnss] epoch_window_h when epoch = "per-run"; nothing drawn when "fixed").
A sensor's output depends only on its own stream(s), the
truth and its configuration, so adding or removing a sensor leaves every other sensor's output
bit-identical (tests/unit/sensors/test_suite.py).

    suite = SensorSuite.from_profile(profile)
    records = suite.measure(truth, seed=1, runs=range(100))         # {name: record}, run axis first
    errors = suite.draw(t_longest, seed=1, runs=[7])                # closed loop: draw once ...
    recs_k = suite.apply(truth, suite.take(errors, "baro", sl))     # ... apply sample by sample
    prepared = suite.prepare(errors)                                # or: lay the draw out once per run ...
    recs_k = prepared.at(truth, k, ("baro", "gnss"))                # ... the records of the sensors sampled at row k
    baro_k = prepared.one("baro", truth, k)                         # ... one sensor's record at row k, or None

`prepared.at(truth, k, names)` gives, for each named sensor with a sample at truth row k, exactly (bit for bit) the
record `apply` gives for that one sample (tests/unit/sensors/test_prepared.py), with the work that does not depend on
the truth done once per run: the GNSS satellite orbits of every sample, the receiver clock on each ranging sensor's
samples, the fault masks and noise faults; each sample then skips the suite's bookkeeping.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from approachsim.seeding import stream
from approachsim.sensors import atmosphere, base
from approachsim.sensors.baro import Baro
from approachsim.sensors.config import SENSOR_NAMES, SensorsConfig
from approachsim.sensors.faults import Faulted, FaultSpec
from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.constellation import Constellation
from approachsim.sensors.gnss.receiver import GnssReceiver, draw_epoch_offsets, draw_receiver_clock
from approachsim.sensors.imu import Imu
from approachsim.sensors.presets import PRESETS
from approachsim.sensors.pseudolite import Pseudolite
from approachsim.sensors.radalt import RadarAltimeter

Array = np.ndarray
CLOCK_STREAM = "receiver_clock"
"""Random stream of the GPS receiver clock shared by the GNSS and pseudolite channels."""
EPOCH_STREAM = "gnss_epoch"
"""Random stream of each run's GPS constellation epoch offset."""
RANGING = ("gnss", "pseudolite")
"""Sensors whose measurements carry the receiver clock."""


def build_sensors(cfg: SensorsConfig, runway: Any, qnh_pa: float, faults: Iterable[FaultSpec] = (),
                  isa_dev_k: float = 0.0, day: tuple[float, float, float] | None = None) -> dict[str, Any]:
    """Sensor objects by name from a SensorsConfig (runway frame for pseudolites and the field elevation, QNH setting
    in Pa, the day's ISA deviation in K for the baro's reported aerodrome temperature; day: (the day's QNH in Pa,
    the surface layer's departure in K and its depth in m; profile environment), default (qnh_pa, 0, 0))."""
    grade = replace(PRESETS[cfg.imu.grade], gyro_quant_rad=cfg.imu.gyro_quant_rad,
                    accel_quant_mps=cfg.imu.accel_quant_mps)
    out: dict[str, Any] = {"imu": Imu(grade)}
    if cfg.baro is not None:
        b = cfg.baro
        # the field elevation (geometric, what the altimeter reads there with QNH): the altimeter setting's reference
        # (the scale factor's H_ref) and the temperature correction's; its geopotential height anchors the real air
        qnh_day, inv_k, inv_m = (qnh_pa, 0.0, 0.0) if day is None else day
        field_m = float(runway.threshold_h_m)
        h_f = float(atmosphere.geopotential_m(field_m))
        ratio = 1.0
        if b.temperature_correction == "aerodrome":  # the surface temperature: the layer's departure included
            ratio = atmosphere.temperature_correction_ratio(
                field_m, atmosphere.reported_aerodrome_temperature_k(h_f, isa_dev_k - inv_k))
        out["baro"] = Baro(setting_pa=qnh_pa, rate_hz=b.rate_hz, bias_sigma_m=b.bias_sigma_m,
                           bias_tau_s=b.bias_tau_s, scale_factor_sigma=b.scale_factor_sigma,
                           noise_sigma_m=b.noise_sigma_m, lag_s=b.lag_s, field_m=field_m, temperature_ratio=ratio,
                           static_source_sigma_m=b.static_source_sigma_m, static_source_tau_s=b.static_source_tau_s,
                           qnh_sigma_m=b.qnh_sigma_hpa * atmosphere.height_per_hpa_m(field_m),
                           inversion_k=inv_k, inversion_depth_m=inv_m,
                           p_field_pa=atmosphere.field_pressure_pa(qnh_day, field_m),
                           t_field_k=float(atmosphere.air_temperature_k(h_f, isa_dev_k)))
    if cfg.radalt is not None:
        r = cfg.radalt
        out["radalt"] = RadarAltimeter(rate_hz=r.rate_hz, max_range_m=r.max_range_m, percent_sigma=r.percent_sigma,
                                       floor_m=r.floor_m, markov_sigma_m=r.markov_sigma_m,
                                       markov_tau_s=r.markov_tau_s, bias_sigma_m=r.bias_sigma_m)
    gnss_rate = 1.0
    if cfg.gnss is not None:
        g = cfg.gnss
        gnss_rate = g.rate_hz
        out["gnss"] = GnssReceiver(
            constellation=Constellation.nominal(g.epoch_utc), budget=g.budget(),
            clock=ClockModel.named(g.oscillator, g.clock_bias0_sigma_m, g.clock_drift0_sigma_mps),
            mask_rad=g.mask_rad, selection=g.selection, rate_hz=g.rate_hz, doppler=g.doppler,
            doppler_noise_mps=g.doppler_noise_mps, station_ecef=None if g.gbas is None else g.gbas.station_ecef(runway),
            carrier=g.carrier,
        )
    if cfg.pseudolite is not None:
        p = cfg.pseudolite
        out["pseudolite"] = Pseudolite(
            runway=runway, positions_rwy=p.positions_rwy, synchronized=p.synchronized, code_noise_m=p.code_noise_m,
            multipath_m=p.multipath_m, multipath_tau_s=p.multipath_tau_s, survey_sigma_m=p.survey_sigma_m,
            tropo_ppm_sigma=p.tropo_ppm_sigma, max_range_m=p.max_range_m, rate_hz=gnss_rate,
            sync_sigma_m=p.sync_sigma_m, sync_tau_s=p.sync_tau_s,
        )
    faults = tuple(faults)
    for name in list(out):
        mine = tuple(f for f in faults if f.sensor == name)
        if mine:
            out[name] = Faulted(out[name], mine)
    return out


@dataclass(frozen=True)
class SuiteErrors:
    """Drawn errors of a suite: per sensor name, plus the receiver clock (None without GNSS/pseudolite)."""

    sensors: Mapping[str, base.SensorErrors]
    clock: base.SensorErrors | None


@dataclass(frozen=True)
class SensorSuite:
    """Named sensors (possibly fault-wrapped) and the receiver clock model of the ranging channels."""

    sensors: Mapping[str, Any]
    clock: ClockModel | None
    clock_rate_hz: float
    epoch_window_s: float = 0.0
    """Width of the GNSS per-run epoch window, s (0: every run at the receiver's epoch)."""

    @classmethod
    def from_config(
        cls, cfg: SensorsConfig, runway: Any, qnh_pa: float, faults: Iterable[FaultSpec] = (), isa_dev_k: float = 0.0,
        day: tuple[float, float, float] | None = None,
    ) -> SensorSuite:
        """Build from a SensorsConfig (build_sensors' arguments)."""
        sensors = build_sensors(cfg, runway, qnh_pa, faults, isa_dev_k, day)
        clock = None
        rate = 1.0
        if cfg.gnss is not None:
            clock = ClockModel.named(cfg.gnss.oscillator, cfg.gnss.clock_bias0_sigma_m, cfg.gnss.clock_drift0_sigma_mps)
            rate = cfg.gnss.rate_hz
        elif cfg.pseudolite is not None:
            clock = ClockModel()
        window = cfg.gnss.epoch_window() if cfg.gnss is not None else 0.0
        return cls(sensors=MappingProxyType(dict(sensors)), clock=clock, clock_rate_hz=rate, epoch_window_s=window)

    @classmethod
    def from_profile(cls, profile: Any) -> SensorSuite:
        """The suite of a Profile (its sensors, faults, runway, QNH setting and ISA deviation)."""
        env = profile.environment
        day = (env.qnh_pa, getattr(env, "inversion_k", 0.0), getattr(env, "inversion_depth_m", 0.0))
        return cls.from_config(profile.sensors, profile.runway.frame, env.setting_pa, profile.faults, env.isa_dev_k,
                               day)

    def without(self, *names: str) -> SensorSuite:
        """The same suite with sensors removed (the clock stays while a ranging sensor remains)."""
        keep = {k: v for k, v in self.sensors.items() if k not in names}
        has_ranging = "gnss" in keep or "pseudolite" in keep
        return SensorSuite(MappingProxyType(keep), self.clock if has_ranging else None, self.clock_rate_hz,
                           self.epoch_window_s)

    @staticmethod
    def _rng(seed: int, runs: int | Iterable[int], name: str) -> base.RngLike:
        if isinstance(runs, int | np.integer):
            return stream(seed, int(runs), name)
        return [stream(seed, int(r), name) for r in runs]

    def draw(self, t_s: Array, seed: int, runs: int | Iterable[int]) -> SuiteErrors:
        """Every sensor's errors on time base t_s from its own stream; runs: one run index or several."""
        runs = runs if isinstance(runs, int | np.integer) else list(runs)
        errs = {name: s.draw(t_s, self._rng(seed, runs, name)) for name, s in self.sensors.items()}
        if "gnss" in errs and self.epoch_window_s > 0.0:
            off = draw_epoch_offsets(self.epoch_window_s, self._rng(seed, runs, EPOCH_STREAM))
            errs["gnss"] = replace(errs["gnss"], constants={**errs["gnss"].constants, "epoch_offset_s": off})
        clock = None
        if self.clock is not None:
            clock = draw_receiver_clock(self.clock, t_s, self.clock_rate_hz, self._rng(seed, runs, CLOCK_STREAM))
        return SuiteErrors(MappingProxyType(errs), clock)

    def apply(self, truth: Any, errors: SuiteErrors, names: Iterable[str] | None = None) -> dict[str, Any]:
        """Records by sensor name (only `names` when given) from truth and drawn errors."""
        out = {}
        for name in names if names is not None else self.sensors:
            s = self.sensors[name]
            e = errors.sensors[name]
            if name in RANGING:
                clk = None if errors.clock is None else errors.clock.take(_clock_rows(errors.clock, e))
                out[name] = s.apply(truth, e, clock=clk)
            else:
                out[name] = s.apply(truth, e)
        return out

    def measure(
        self, truth: Any, seed: int, runs: int | Iterable[int], *, noise: bool = True
    ) -> dict[str, Any]:
        """apply(truth, draw(truth.t_s, seed, runs)); noise=False gives every sensor's exact value."""
        e = self.draw(truth.t_s, seed, runs)
        if not noise:
            e = SuiteErrors(
                MappingProxyType({k: v.zeroed() for k, v in e.sensors.items()}),
                None if e.clock is None else e.clock.zeroed(),
            )
        return self.apply(truth, e)

    def prepare(self, errors: SuiteErrors) -> PreparedSuite:
        """The drawn errors laid out for applying one truth row at a time (module docstring; base.prepare)."""
        prepared = {}
        grids = {}
        for name, e in errors.sensors.items():
            clk = None
            if name in RANGING and errors.clock is not None:
                clk = errors.clock.take(_clock_rows(errors.clock, e))
            prepared[name] = base.prepare(self.sensors[name], e, clk)
            grids[name] = _RowIndex.of(e.rows)
        return PreparedSuite(MappingProxyType(prepared), MappingProxyType(grids))

    @staticmethod
    def take(errors: SuiteErrors, name: str, sl: slice | Array) -> SuiteErrors:
        """The suite errors restricted to samples `sl` of sensor `name` (for sample-by-sample closed loops)."""
        return SuiteErrors(MappingProxyType({name: errors.sensors[name].take(sl)}), errors.clock)


@dataclass(frozen=True)
class _RowIndex:
    """Truth row -> sample number of a sensor's grid: rows first + j step (j < count), or a lookup when irregular."""

    first: int
    step: int
    count: int
    lookup: Mapping[int, int] | None = None

    @classmethod
    def of(cls, rows: Array) -> _RowIndex:
        rows = np.asarray(rows)
        n = int(rows.shape[0])
        if n == 0:
            return cls(0, 1, 0)
        step = int(rows[1] - rows[0]) if n > 1 else 1
        if n > 1 and (step < 1 or not np.array_equal(rows, rows[0] + step * np.arange(n))):
            return cls(0, 1, 0, MappingProxyType({int(r): j for j, r in enumerate(rows)}))
        return cls(int(rows[0]), step, n)

    def sample(self, k: int) -> int | None:
        """The sample taken at truth row k, or None."""
        if self.lookup is not None:
            return self.lookup.get(k)
        j, rem = divmod(k - self.first, self.step)
        return j if rem == 0 and 0 <= j < self.count else None


@dataclass(frozen=True)
class PreparedSuite:
    """A suite's drawn errors laid out for one truth row at a time (SensorSuite.prepare): per sensor the prepared
    errors (base.prepare) and its row -> sample index."""

    sensors: Mapping[str, Any]
    grids: Mapping[str, _RowIndex]

    def sample(self, name: str, k: int) -> int | None:
        """Sensor `name`'s sample number at truth row k, or None (no sample there, or no such sensor)."""
        g = self.grids.get(name)
        return None if g is None else g.sample(k)

    def at(self, truth: Any, k: int, names: Iterable[str] | None = None) -> dict[str, Any]:
        """Records by sensor name (only `names` when given; sensors the suite lacks are skipped) of the sensors with
        a sample at truth row k: each exactly apply(truth, <that one sample of the errors>)'s record."""
        out = {}
        for name in names if names is not None else self.sensors:
            j = self.sample(name, k)
            if j is not None:
                out[name] = self.sensors[name].at(truth, j)
        return out

    def one(self, name: str, truth: Any, k: int) -> Any:
        """Sensor `name`'s record at truth row k (as `at`), or None when it has no sample there or is not fitted."""
        j = self.sample(name, k)
        return None if j is None else self.sensors[name].at(truth, j)


def _clock_rows(clock: base.SensorErrors, e: base.SensorErrors) -> Array:
    """Positions in the clock's samples of the sensor samples in `e` (same receiver grid)."""
    pos = np.searchsorted(clock.rows, e.rows)
    if np.any(pos >= clock.rows.shape[0]) or not np.array_equal(clock.rows[np.minimum(pos, len(clock) - 1)], e.rows):
        raise ValueError("GNSS / pseudolite samples must lie on the receiver clock's sample grid")
    return pos


__all__ = ["CLOCK_STREAM", "EPOCH_STREAM", "RANGING", "SENSOR_NAMES", "PreparedSuite", "SensorSuite", "SuiteErrors",
           "build_sensors"]
