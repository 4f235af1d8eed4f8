"""A run's realized sensor errors at one truth row, in the units and sign of the navigation filter's error states.

    errors = suite.draw(truth.t_s, seed, runs)
    records = suite.apply(truth, errors)
    states = start_states(suite, truth, errors, row=0)        # SensorStates, run axis first

Each field is one filter state group (nav/errormodel.py StateLayout names), the value the filter would have to
estimate exactly at `row`; None when the suite has no such sensor. Signs follow the measurement rows
(nav/measurements.py): every state is the error the sensor *adds* to its measurement.

    gse  (N, 24) m    clock/ephemeris + F(el) iono + M(el) tropo of each GPS channel (receiver.py), el at `row`;
                      GBAS corrections: the ground + iono + tropo residuals (gbas.py)
    gmp  (N, 24) m    multipath of each channel; GBAS: the airborne multipath + smoothed receiver noise
    gio  (N, 24) m    with carrier phase only: the ionospheric part of the code's slow error (F I; GBAS s_iono I),
                      which gse then leaves out (the carrier sees it with the opposite sign)
    amb  (N, 24) m    with carrier phase only: the float ambiguity of an arc beginning at the row's sample (the
                      receiver's pool entry there: exactly the ambiguity of every channel valid at the record's first
                      sample, where every arc begins; gnss/carrier.py)
    giz  (N,)   m     a single-frequency service's common zenith ionospheric residual (service.py, the field's
                      common part), which gse then leaves out (it holds F_pp(el) giz: receiver.channel_errors)
    gtz  (N,)   m     a service's tropospheric zenith residual (nominal filter model), which gse then leaves out
    clk  (N, 2)       receiver clock bias (m) and drift (m/s) (clock.py; shared by GPS and pseudolites)
    bb   (N,)   m     baro slow bias (the drawn Gauss-Markov + static-source + QNH errors) + the day's deterministic
                      offset at the field; sb (N,) the scale factor on the height above the field: the drawn S and
                      the day's temperature / inversion / geopotential error (`_baro`: the filter's split of them)
    bg   (N, 3) rad/s gyro bias in body axes as the INS sees it over the increment after `row`: turn-on +
                      Gauss-Markov + (S + M) w_ib (scale factor / misalignment at the true rate, imu.py)
    ba   (N, 3) m/s^2 the same for the accelerometers with (S + M) f_body (the filter's ba lumps them, P0)
    pmp  (N, p) m     pseudolite multipath; ptr (N, p) tropo residual as a fraction of the range
    pclk (N, 2p)      pseudolite transmitter clock bias (m) and drift (m/s) pairs (unsynchronized)
    psy  (N, p)  m    a synchronized pseudolite's time-sync error (pseudolite.py; the pl_clock series then)
    rab  (N,)   m     radar-altimeter bias (radalt.py); NavSystem.start adds the terrain database's bias
    ram  (N,)   m     radar-altimeter Gauss-Markov error
    tdb  (N,)         the terrain database's unit along-track Gauss-Markov at the start (NavSystem.start: the
                      database error is the navigation system's own draw, nav/terrain_db.py)

The sample of each sensor taken for `row` is the last one at or before it (the IMU: the increment starting at
it). White noise (code, baro, IMU ARW / VRW) is not a state and is left out. A new state group is one field
here and one entry in `_EXTRACT`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from approachsim.sensors import atmosphere, base
from approachsim.sensors.gnss.constellation import look_angles

Array = np.ndarray


@dataclass(frozen=True)
class SensorStates:
    """Realized sensor error states of N runs at truth row `row` (module docstring: fields, units, signs)."""

    row: int
    gse: Array | None = None
    gmp: Array | None = None
    clk: Array | None = None
    bb: Array | None = None
    sb: Array | None = None
    bg: Array | None = None
    ba: Array | None = None
    pmp: Array | None = None
    ptr: Array | None = None
    pclk: Array | None = None
    psy: Array | None = None
    rab: Array | None = None
    ram: Array | None = None
    tdb: Array | None = None
    gio: Array | None = None
    amb: Array | None = None
    giz: Array | None = None
    gtz: Array | None = None
    sb_day: float | None = None
    """The day's deterministic baro scale factor at the row (sb without the drawn S: temperature, inversion,
    geopotential height; the same for every run on the truth): the shared covariance's linearization point of the
    baro's dp_D coefficient -(1 + sb) (nav/measurements.baro), None without a baro."""

    @property
    def runs(self) -> int:
        """Number of runs N."""
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, np.ndarray):
                return int(v.shape[0])
        return 0

    def group(self, name: str) -> Array | None:
        """(N, k) values of state group `name` (None when not realized: no such sensor or no such group)."""
        v = getattr(self, name, None) if name in STATE_GROUPS else None
        return None if v is None else np.asarray(v, dtype=float).reshape(v.shape[0], -1)

    def take(self, i: int) -> SensorStates:
        """The states of run i alone (run axis kept, length 1)."""
        kw = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("row", "sb_day")}
        return SensorStates(self.row, **{k: None if v is None else v[i:i + 1] for k, v in kw.items()},
                            sb_day=self.sb_day)


STATE_GROUPS = tuple(f.name for f in fields(SensorStates) if f.name not in ("row", "sb_day"))
"""The filter state groups a SensorStates can carry."""


@dataclass(frozen=True)
class _At:
    """What an extractor sees: the suite, the truth, the drawn errors (batched) and the start row."""

    suite: Any
    truth: Any
    errors: Any
    row: int

    def sample(self, name: str) -> tuple[base.SensorErrors, int] | None:
        """(errors of sensor `name`, its sample index for the row), or None without that sensor."""
        e = self.errors.sensors.get(name) if name != "clock" else self.errors.clock
        if e is None:
            return None
        if not e.batched:  # one run drawn alone (the closed loop): give it the run axis
            e = replace(e, series={k: v[None] for k, v in e.series.items()},
                        constants={k: np.asarray(v)[None] for k, v in e.constants.items()}, batched=True)
        j = int(np.searchsorted(e.rows, self.row, side="right")) - 1
        if name == "imu":
            j = int(np.searchsorted(e.rows, self.row + 1))  # the increment (row, row + 1]
        return e, min(max(j, 0), len(e) - 1)


def _series(at: _At, sensor: str, key: str) -> Array | None:
    s = at.sample(sensor)
    if s is None:
        return None
    e, j = s
    return np.asarray(e.series[key])[:, j]


def _gnss_el(at: _At, e: base.SensorErrors, j: int) -> Array:
    """Elevations (rad) of the 24 channels at sample j: (24,) on one sky, (N, 24) on per-run skies."""
    return _gnss_look(at, e, j)[0]


def _gnss_look(at: _At, e: base.SensorErrors, j: int) -> tuple[Array, Array]:
    """Elevations and azimuths (rad) of the 24 channels at sample j: (24,) on one sky, (N, 24) on per-run skies."""
    rx = at.suite.sensors["gnss"]
    r = at.truth.r_ecef[e.rows[j]][None]
    off = e.constants.get("epoch_offset_s")  # each run its own sky (receiver.py): elevations per run
    offs = np.zeros(1) if off is None else np.atleast_1d(np.asarray(off, dtype=float))
    look = [look_angles(r, rx.geometry_constellation(o).positions_ecef(e.t_s[j:j + 1])) for o in offs]
    el, az = np.stack([a[2][0] for a in look]), np.stack([a[3][0] for a in look])
    return (el[0], az[0]) if off is None else (el, az)


def _channels(at: _At) -> tuple[Array, ...] | None:
    """(gse, gmp) of each channel, m: the receiver's channel_errors of the drawn series at the sample's elevations
    and (GBAS) the aircraft's geometry relative to the reference point (receiver.py); with carrier phase (gse, gmp,
    gio), gse without the ionosphere (carrier_channel_errors)."""
    s = at.sample("gnss")
    if s is None:
        return None
    e, j = s
    rx = at.suite.sensors["gnss"]
    el, az = _gnss_look(at, e, j)
    ser = {k: np.asarray(v)[:, j] for k, v in e.series.items() if k != "rate_noise"}
    geom = rx.station_geometry(at.truth, e.rows[j:j + 1]) if rx.budget.gbas is not None else (None, None, None)
    if getattr(rx, "carrier", None) is not None:
        slow, iono, fast = rx.carrier_channel_errors(ser, el, *geom)
        return slow, fast, iono
    return rx.channel_errors(ser, el, *geom, az_rad=az)


def _gio(at: _At) -> Array | None:
    c = _channels(at)
    return None if c is None or len(c) < 3 else c[2]


def _zenith(at: _At, kind: str) -> Array | None:
    """The zenith ionospheric ("iono": the field's common part) or tropospheric ("tropo") residual (N,), m, of a
    service whose filter carries it (receiver.py iono_zenith_error, tropo_zenith_error); None otherwise."""
    s = at.sample("gnss")
    if s is None:
        return None
    rx = at.suite.sensors["gnss"]
    sv = getattr(getattr(rx, "budget", None), "service", None)
    if sv is None or not (sv.iono_zenith_state if kind == "iono" else sv.tropo_zenith_state):
        return None
    e, j = s
    key = "iono_field" if kind == "iono" else "tropo"
    ser = {key: np.asarray(e.series[key])[:, j]}
    return rx.iono_zenith_error(ser) if kind == "iono" else rx.tropo_zenith_error(ser)


def _amb(at: _At) -> Array | None:
    s = at.sample("gnss")
    if s is None or "ambiguity" not in s[0].series:
        return None
    e, j = s
    return np.asarray(e.series["ambiguity"])[:, j]


def _gmp(at: _At) -> Array | None:
    """Multipath of each channel, m: the drawn series, scaled by sigma_mp(el) under the do253 model (its series
    is unit-sigma, receiver.py); GBAS: with the smoothed receiver noise."""
    c = _channels(at)
    return None if c is None else c[1]


def _gse(at: _At) -> Array | None:
    c = _channels(at)
    return None if c is None else c[0]


def _clk(at: _At) -> Array | None:
    s = at.sample("clock")
    if s is None:
        return None
    e, j = s
    return np.stack([np.asarray(e.series["bias"])[:, j], np.asarray(e.series["drift"])[:, j]], axis=-1)


def _imu(at: _At, kind: str) -> Array | None:
    s = at.sample("imu")
    if s is None:
        return None
    e, j = s
    inc = at.truth.w_ib_body[at.row] if kind == "gyro" else at.truth.f_body[at.row]
    m = np.asarray(e.constants[f"{kind}_m"])  # (N, 3, 3) scale factor + misalignment
    return (np.asarray(e.constants[f"{kind}_bias0"]) + np.asarray(e.series[f"{kind}_bias"])[:, j]
            + np.einsum("nij,j->ni", m, inc))


def _baro(at: _At, drawn_scale: bool = True) -> tuple[Array, Array] | None:
    """(bb, sb) (N,) of the filter's baro row h_B = h + bb + sb (h - H_ref) + v at the sample's truth row: the
    deterministic error of the day (temperature, an inversion, a QNH rounding or setting error, geopotential height;
    sensors/baro.py) split as the filter sees it, b0 = the noise-free indication at the field less its elevation
    into bb with the drawn slow errors, the rest of the noise-free error at the row (with the drawn scale factor S)
    into sb. Exact at the row by construction; the split is the line through the field and the row. drawn_scale
    False: the drawn S left out (SensorStates.sb_day: the day's part alone, the same for every run)."""
    s = at.sample("baro")
    if s is None:
        return None
    e, j = s
    sensor = at.suite.sensors["baro"]
    baro = getattr(sensor, "sensor", sensor)  # a Faulted baro's own model
    sf = np.asarray(e.constants["scale_factor"], dtype=float).reshape(-1)
    if not drawn_scale:
        sf = np.zeros(1)
    k = int(e.rows[j])
    dt = None
    if baro.lag_s > 0.0:  # the truth's step; at the closed loop's start (row 1 not flown) the draw's grid gives it
        t = at.truth.t_s
        dt = float(t[1] - t[0]) if len(t) > 1 else math.nan
        if not math.isfinite(dt):
            dt = float(e.t_s[1] - e.t_s[0]) / float(e.rows[1] - e.rows[0])
    zero = np.zeros((sf.shape[0], 1))
    h_s = baro.record(at.truth, e.rows[j:j + 1], e.t_s[j:j + 1], sf, zero, zero, True, dt).h_baro_m[:, 0]
    h_ind = float(atmosphere.indicated_altitude_m(baro.sensed_pressure(np.asarray(baro.p_field_pa)),
                                                  baro.setting_pa))
    b0 = h_ind * baro.temperature_ratio - baro.field_m * (baro.temperature_ratio - 1.0) - baro.field_m
    h = float(at.truth.h_m[k])
    above = h - baro.field_m
    sb = (h_s - h - b0) / above if abs(above) > 1.0 else sf
    return np.asarray(e.series["bias"], dtype=float)[:, j] + b0, sb


def _ptr(at: _At) -> Array | None:
    s = at.sample("pseudolite")
    return None if s is None else 1e-6 * np.asarray(s[0].constants["tropo_ppm"])


def _pclk(at: _At) -> Array | None:
    s = at.sample("pseudolite")
    if s is None:
        return None
    e, j = s
    b, d = np.asarray(e.series["pl_clock"])[:, j], np.asarray(e.series["pl_clock_drift"])[:, j]
    return np.stack([b, d], axis=-1).reshape(b.shape[0], -1)  # (bias, drift) pairs per transmitter


_EXTRACT: dict[str, Callable[[_At], Array | None]] = {
    "gse": _gse,
    "gmp": _gmp,
    "clk": _clk,
    "bb": lambda at: None if (b := _baro(at)) is None else b[0],
    "sb": lambda at: None if (b := _baro(at)) is None else b[1],
    "bg": lambda at: _imu(at, "gyro"),
    "ba": lambda at: _imu(at, "accel"),
    "pmp": lambda at: _series(at, "pseudolite", "multipath"),
    "ptr": _ptr,
    "pclk": _pclk,
    "psy": lambda at: _series(at, "pseudolite", "pl_clock"),
    "rab": lambda at: None if at.sample("radalt") is None else np.asarray(
        at.sample("radalt")[0].constants["bias"], dtype=float).reshape(-1),
    "ram": lambda at: _series(at, "radalt", "markov"),
    "tdb": lambda at: None,  # filled by NavSystem.start from its database draw
    "gio": _gio,
    "amb": _amb,
    "giz": lambda at: _zenith(at, "iono"),
    "gtz": lambda at: _zenith(at, "tropo"),
}
"""Filter state group -> its realized value from the drawn errors (one entry per group)."""


def start_states(suite: Any, truth: Any, errors: Any, row: int = 0) -> SensorStates:
    """The realized sensor error states at truth row `row` of the runs in `errors` (SuiteErrors from
    SensorSuite.draw; run axis first, length 1 when drawn for one run)."""
    at = _At(suite, truth, errors, int(row))
    day = _baro(at, drawn_scale=False)
    return SensorStates(int(row), **{g: _EXTRACT[g](at) for g in STATE_GROUPS},
                        sb_day=None if day is None else float(day[1][0]))





def measure_with_states(suite: Any, truth: Any, seed: int, runs: Any, row: int = 0) -> tuple[dict[str, Any],
                                                                                            SensorStates]:
    """(suite.measure(truth, seed, runs), start_states at `row`) from one draw: what NavSystem.run needs."""
    errors = suite.draw(truth.t_s, seed, runs)
    return suite.apply(truth, errors), start_states(suite, truth, errors, row)
__all__ = ["STATE_GROUPS", "SensorStates", "measure_with_states", "start_states"]
