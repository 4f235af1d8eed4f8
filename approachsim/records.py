"""The plain data the stages exchange: frozen dataclasses of numpy arrays, axes and units documented.

Time is axis 0 of a single-flight record. Batched records (several Monte Carlo runs sharing one time
base) put the run axis first: (runs, time, ...). All SI; frames in the field names.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from typing import Any, Protocol

import numpy as np

from approachsim.geo import RunwayFrame

Array = np.ndarray


@dataclass(frozen=True)
class Truth:
    """What the aircraft really did, sampled at the IMU rate; every array has time on axis 0 (n samples).

    Kinematic quantities (position, velocity, specific force, rates) are those of the IMU location,
    which is what an IMU at that point senses; the runway-frame deviations are of the same point.
    Sampling (flight stage): f_body[k] and w_ib_body[k] are the specific force and rate that carry the
    state from row k to row k+1, constant over that step in body axes (f_body[k] is the body-axis mean over
    the step), with gravity geo.gravity_ned (approachsim/flight/fdm.py, flight/run.py, docs/truth.md).
    """

    t_s: Array
    """(n,) time since the start of the run, s."""
    lat_rad: Array
    """(n,) geodetic latitude of the IMU, rad."""
    lon_rad: Array
    """(n,) longitude of the IMU, rad."""
    h_m: Array
    """(n,) height of the IMU above the WGS-84 ellipsoid, m."""
    r_ecef: Array
    """(n, 3) IMU position, ECEF, m."""
    v_ned: Array
    """(n, 3) IMU velocity relative to the Earth, local NED axes, m/s."""
    q_nb: Array
    """(n, 4) attitude quaternion body->NED, scalar first (w, x, y, z): v_ned = q v_body q*."""
    euler_rad: Array
    """(n, 3) roll, pitch, true heading (body relative to NED), rad."""
    w_ib_body: Array
    """(n, 3) body angular rate relative to inertial space, body axes (what a gyro senses), rad/s."""
    f_body: Array
    """(n, 3) specific force at the IMU, body axes (what an accelerometer senses), m/s^2."""
    p_static_pa: Array
    """(n,) ambient static pressure at the IMU point (JSBSim's at the CG, moved hydrostatically), Pa."""
    t_air_k: Array
    """(n,) ambient (static) air temperature, K."""
    h_agl_m: Array
    """(n,) height of the IMU above the profile's terrain, m."""
    r_rwy: Array
    """(n, 3) runway frame: along (x, m past the threshold), cross (y, m right), height above threshold (m)."""
    gs_dev_m: Array
    """(n,) vertical deviation from the ideal glidepath, m (positive above)."""
    loc_dev_m: Array
    """(n,) lateral deviation from the extended centreline, m (positive right)."""
    controls: Array
    """(n, 4) elevator, aileron, rudder, throttle commands, normalized (-1..1, 0..1)."""
    airspeed_mps: Array
    """(n,) calibrated airspeed, m/s."""
    runway: RunwayFrame = field(compare=False)
    """The runway frame the r_rwy columns are in."""

    def __len__(self) -> int:
        return int(self.t_s.shape[0])

    def arrays(self) -> dict[str, Array]:
        """All array fields by name (for saving and slicing)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "runway"}

    def slice(self, sl: slice) -> Truth:
        """The record restricted to time indices `sl`."""
        return Truth(**{k: v[sl] for k, v in self.arrays().items()}, runway=self.runway)


@dataclass(frozen=True)
class NavSolution:
    """The navigation system's output for one run at the IMU rate (time on axis 0), for the IMU point.

    Feed-forward convention: output = INS - estimated error. Covariances are the filter's own claim.
    """

    t_s: Array
    """(n,) time since the start of the run, s (same time base as the Truth)."""
    r_ecef: Array
    """(n, 3) estimated position, ECEF, m."""
    v_ned: Array
    """(n, 3) estimated velocity relative to the Earth, NED, m/s."""
    euler_rad: Array
    """(n, 3) estimated roll, pitch, heading, rad."""
    P_pos_ned: Array
    """(n, 3, 3) the filter's position-error covariance in local NED axes, m^2."""
    clock_bias_m: Array
    """(n,) estimated GPS receiver clock bias, m (nan where there is no GPS clock state)."""
    clock_bias_sigma_m: Array
    """(n,) its claimed 1-sigma, m (nan where none)."""
    alert: Array | None = None
    """(n,) bool, online FDE ([nav.fde] enabled; None when off): the solution cannot be protected (its
    protection level reaches the alert limit, too few ranging sources left, or a fault nothing is left to
    exclude)."""
    flagged: Array | None = None
    """(n,) bool, online FDE: a source has been excluded (the solution runs on fewer measurements)."""
    protection_level_m: Array | None = None
    """(n, 2) online FDE: the filter's (vertical, lateral) protection level at the latest epoch, m (nan before
    the first)."""
    exclusions: tuple[ExclusionEvent, ...] = ()
    """Online FDE: every exclusion, in time order."""


@dataclass(frozen=True)
class ExclusionEvent:
    """One online FDE exclusion (nav/fde.py): when, what, by which test and how far over its threshold."""

    t_s: float
    """Epoch of the detection, s since the run start."""
    source: str
    """Excluded source: "baro", "radalt", "gps07" (GNSS channel 7 of the constellation), "pl0", "gnss" (a
    loosely coupled fix)."""
    channel: int
    """GNSS channel / pseudolite unit index (-1 for baro, radar altimeter, a loose fix)."""
    test: str
    """"chi2" (the epoch's residual test) or "sum" (the moving sum of the w-test)."""
    statistic: float
    threshold: float


class NavigationSource(Protocol):
    """Where the autopilot's guidance reads position and velocity: the truth, or the navigation solution.

    The flight loop calls step(k, truth) once per step, after writing row k of the (preallocated, being
    filled) truth arrays; the source may read rows <= k only. It returns the position (runway frame:
    along, cross, height above threshold, m) and NED velocity (m/s) that guidance should fly on.

    A source may also offer `inloop()`, returning None or an object whose arrays the flight loop's compiled step
    steps the navigation with (core/loop/nav_row.py: nw, cg, ca, rows, snap, baro_j, baro_e, lag_w, dth, dv) and whose
    act(k, truth, code) it calls at the rows the step asks for; step() is then not called (loop/closed_loop.py).
    """

    def step(self, k: int, truth: Truth) -> tuple[Array, Array]: ...


# --- sensor records (approachsim/sensors, issue 3) -------------------------------------------------------
# Sample axis first for one run; (runs, samples, ...) for the fields marked "per run" when several Monte Carlo
# runs are measured at once (t_s, index and the geometry of the ranging sources stay without a run axis
# unless the truth itself had one). valid is False where the sensor gives no measurement (out of range,
# not visible, outage); values are nan there. fault is the ground-truth fault label of each sample
# (sensors/faults.py FAULT_CODES: 0 none, 1 outage, 2 spike, 3 iam, 4 cbm, 5 mni, 6 step, 7 ramp).


@dataclass(frozen=True)
class ImuSamples:
    """Strapdown IMU output: increments over each IMU interval (t_{k-1}, t_k], body axes (sensors/imu.py)."""

    t_s: Array
    """(m,) end time t_k of each interval, s."""
    dt_s: float
    """IMU interval, s."""
    dtheta_body: Array
    """(m, 3) per run: angle increments, rad."""
    dv_body: Array
    """(m, 3) per run: velocity increments (integrated specific force), m/s."""
    valid: Array
    """(m,) per run: increment delivered."""
    fault: Array
    """(m,) per run: fault label (int8)."""


@dataclass(frozen=True)
class BaroSamples:
    """Barometric altimeter: indicated altitude above MSL with the profile's QNH setting (sensors/baro.py)."""

    t_s: Array
    """(m,) sample times, s."""
    h_baro_m: Array
    """(m,) per run: indicated altitude above mean sea level (= ellipsoid in this simulator), m."""
    sigma_m: Array
    """(m,) white-noise 1-sigma of each sample (the nominal R of a filter), m."""
    valid: Array
    """(m,) per run."""
    fault: Array
    """(m,) per run: fault label (int8)."""


@dataclass(frozen=True)
class RadaltSamples:
    """Radar altimeter: antenna height above the terrain (sensors/radalt.py)."""

    t_s: Array
    """(m,) sample times, s."""
    h_agl_m: Array
    """(m,) per run: measured height above terrain, m (nan where not valid)."""
    sigma_m: Array
    """(m,) per run: seed 002 noise 1-sigma sqrt((0.01 h)^2 + floor^2), m, at the true height."""
    valid: Array
    """(m,) per run: below maximum range and within the attitude limits."""
    fault: Array
    """(m,) per run: fault label (int8)."""


@dataclass(frozen=True)
class GnssSamples:
    """GPS code pseudoranges to the 24 nominal slots (sensors/gnss.py); channels on the last axis."""

    t_s: Array
    """(m,) receive times, s."""
    prn: Array
    """(24,) PRN of each channel (standards.md 2.1, MAAST almmops numbering)."""
    r_sv_ecef: Array
    """(m, 24, 3) satellite positions, ECEF, m (the broadcast-ephemeris position a receiver would use)."""
    pseudorange_m: Array
    """(m, 24) per run: pseudorange, m (nan where not valid)."""
    sigma_m: Array
    """(m, 24) nominal 1-sigma of each pseudorange (the UERE model at its elevation), m."""
    elevation_rad: Array
    """(m, 24) elevation of each satellite at the true antenna position, rad."""
    azimuth_rad: Array
    """(m, 24) azimuth, rad from true north, clockwise."""
    visible: Array
    """(m, 24) above the elevation mask."""
    valid: Array
    """(m, 24) per run: visible, selected (all in view or best-PDOP four) and not in an outage."""
    pdop: Array
    """(m,) PDOP of the selected set (inf when fewer than 4)."""
    clock_bias_m: Array
    """(m,) per run: true receiver clock bias in the pseudoranges (c times seconds), m."""
    clock_drift_mps: Array
    """(m,) per run: true receiver clock drift, m/s."""
    fault: Array
    """(m, 24) per run: fault label (int8)."""
    pseudorange_rate_mps: Array | None = None
    """(m, 24) per run: pseudorange rate (carrier Doppler), m/s (nan where not valid); None if not modelled."""
    epoch_offset_s: Array | None = None
    """() or (runs,): each run's constellation epoch after the profile's epoch_utc, s; None: one fixed sky.
    With per-run offsets in a batch the geometry fields (r_sv_ecef, sigma_m, elevation_rad, azimuth_rad,
    visible, pdop) also carry the leading run axis (`per_run_sky`)."""
    carrier_phase_m: Array | None = None
    """(m, 24) per run: L1 carrier phase in metres with its float ambiguity (sensors/gnss/carrier.py), nan where not
    valid; None if not modelled."""
    carrier_arc: Array | None = None
    """(m, 24) per run, int64: the carrier arc id of each channel, the sample index at which its current arc (one
    constant ambiguity) began; -1 where not valid. A changed id is a new ambiguity. None if not modelled."""
    carrier_sigma_m: float | None = None
    """Nominal 1-sigma of the carrier's fast errors (multipath and tracking noise), m; None if not modelled."""

    @property
    def per_run_sky(self) -> bool:
        """True when the geometry fields carry a leading run axis (a batch of runs, each with its own epoch)."""
        return np.ndim(self.elevation_rad) == 3

    def run(self, k: int) -> GnssSamples:
        """Run k of a batched record (every per-run field indexed; shared geometry kept)."""
        def pick(v: Any, nd: int) -> Any:
            return v[k] if v is not None and np.ndim(v) == nd else v
        sky = self.per_run_sky
        return replace(
            self, r_sv_ecef=self.r_sv_ecef[k] if sky else self.r_sv_ecef, pseudorange_m=self.pseudorange_m[k],
            sigma_m=self.sigma_m[k] if sky else self.sigma_m, elevation_rad=self.elevation_rad[k] if sky else
            self.elevation_rad, azimuth_rad=self.azimuth_rad[k] if sky else self.azimuth_rad,
            visible=self.visible[k] if sky else self.visible, valid=pick(self.valid, 3),
            pdop=self.pdop[k] if sky else self.pdop, clock_bias_m=pick(self.clock_bias_m, 2),
            clock_drift_mps=pick(self.clock_drift_mps, 2), fault=pick(self.fault, 3),
            pseudorange_rate_mps=pick(self.pseudorange_rate_mps, 3), epoch_offset_s=pick(self.epoch_offset_s, 1),
            carrier_phase_m=pick(self.carrier_phase_m, 3), carrier_arc=pick(self.carrier_arc, 3),
        )


@dataclass(frozen=True)
class PseudoliteSamples:
    """Ground pseudolite code pseudoranges (sensors/pseudolite.py); one channel per unit on the last axis."""

    t_s: Array
    """(m,) receive times, s."""
    r_pl_ecef: Array
    """(p, 3) surveyed (published) transmitter positions, ECEF, m: what the navigation system uses."""
    pseudorange_m: Array
    """(m, p) per run: pseudorange, m (nan where not valid); includes the receiver clock bias."""
    sigma_m: Array
    """(m, p) nominal 1-sigma (code noise and multipath), m."""
    elevation_rad: Array
    """(m, p) elevation of the aircraft seen from each transmitter, rad."""
    valid: Array
    """(m, p) per run: within range and above the transmitter's elevation mask, not in an outage."""
    clock_bias_m: Array
    """(m,) per run: true receiver clock bias included (same clock as the GNSS channels in a suite), m."""
    fault: Array
    """(m, p) per run: fault label (int8)."""


@dataclass(frozen=True)
class ApproachErrors:
    """Error split of one flown approach (loop/closed_loop.py), RNP convention: TSE = FTE + NSE.

    Components on the last axis: (lateral = cross-track, vertical = height above the ideal glidepath), m.
    """

    t_s: Array
    """(n,) time, s (the Truth's time base)."""
    fte_m: Array
    """(n, 2) flight technical error: deviation from the desired path of the position guidance flew on, m."""
    nse_m: Array
    """(n, 2) navigation system error in path terms: deviation of the truth minus that of the estimate, m."""
    tse_m: Array
    """(n, 2) total system error: deviation of the true position from the desired path, m."""
