"""The navigation system: strapdown INS + error-state filter over sensor records, as one composable object.

    nav = NavSystem.from_profile(profile)
    run = nav.run(truth, records, rng)               # records: {name: record} from sensors.suite
    run.solution (NavSolution), run.status (StatusLog), run.x, run.P_diag (filter history at the epochs)

NavSystem holds the configuration and the models built from it: the error-state layout, the filter (by name,
nav/registry.py), the noise model from the sensors' error budgets (nav/noise.py), the measurement rows
(nav/rows.py) with the filter's terrain database, and the damping-loop gains. It starts runs (`start`: INS errors
and filter states) and passes them over whole records (`run`) through the navigation step object
(nav/navigator.py), which the closed loop (loop/closed_loop.py) steps row by row instead.

The INS integrates every IMU increment; at each aiding epoch (nav.aiding_rate_hz) the filter predicts with the
discretized error model (errormodel.dynamics + discretize, linearized about the INS solution) and takes every
available scalar measurement in turn (baro, radar altimeter below its range, each valid pseudorange, each
pseudolite range), each giving an UpdateStatus. Output (seed 002 feed-forward) = INS - estimated error; with
`feedback` the estimate is fed back into the INS (and the IMU bias estimates into the increments) and the
corresponding error states reset to zero.

The start ([nav.initial_error] start): "converged" (default) draws the INS error and the filter's sensor-state
estimates jointly with the run's realized sensor errors from the filter's covariance after a pre-approach aided
segment (nav/initial.py; `run(..., states=sensors.states.start_states(...))`); "prior" draws the INS errors
from the diagonal prior alone.

Several Monte Carlo runs can share one call: the INS is stepped for all of them at once (run axis first); each run
has its own filter state, or with `shared_covariance` one covariance and gain per measurement schedule
(nav/shared.py: open-loop runs on one truth, optimal filter).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.memo import TruthMemo, memoized
from approachsim.nav import errormodel as em
from approachsim.nav import initial, ins
from approachsim.nav import terrain_db as tdb
from approachsim.nav import vertical_loop as vl
from approachsim.nav.base import FilterState, NavFilter
from approachsim.nav.config import DEFAULT_NAV, NavConfig
from approachsim.nav.fde import RESET_GROUPS, FdeState
from approachsim.nav.navigator import Navigator, NavRun, RunFilter, StatusLog
from approachsim.nav.noise import NoiseModel
from approachsim.nav.observations import Observations
from approachsim.nav.rows import MeasurementRows, TerrainDatabase
from approachsim.nav.shared import SharedCovariance
from approachsim.records import Truth
from approachsim.seeding import substream
from approachsim.sensors.config import DEFAULT_SENSORS, SensorsConfig
from approachsim.sensors.gnss.gbas import REFERENCE_GEOMETRY
from approachsim.sensors.states import SensorStates

Array = np.ndarray

__all__ = ["NavRun", "NavSystem", "StatusLog", "TerrainDatabase"]

PREPARED_KEEP = 64
"""Converged starts a truth's memo keeps (NavSystem._prepared: one per run's sky; a flight group has 25 runs)."""


def _radalt_states(sensors: SensorsConfig, nav: NavConfig) -> dict[str, bool]:
    """StateLayout flags of the radalt / database error states: present with the radar altimeter only, each when
    its error model is not zero."""
    r, d = sensors.radalt, nav.terrain_database
    if r is None:
        return {}
    return {"radalt_bias": r.bias_sigma_m > 0.0 or d.bias_sigma_m > 0.0, "radalt_markov": r.markov_sigma_m > 0.0,
            "terrain_db": d.correlated}


def layout_for(nav: NavConfig, sensors: SensorsConfig) -> em.StateLayout:
    """The error-state layout of a navigation configuration (errormodel.StateLayout)."""
    n_sv = 24 if sensors.gnss is not None and nav.channel_states and nav.gps_coupling == "tight" else 0
    n_pl = len(sensors.pseudolite.positions_rwy) if sensors.pseudolite is not None and nav.channel_states else 0
    carrier = sensors.gnss is not None and sensors.gnss.carrier is not None
    if carrier and not n_sv:
        raise ValueError("[sensors.gnss] carrier_phase needs tight GPS coupling with channel states ([nav] "
                         "gps_coupling = \"tight\", channel_states = true): the float ambiguities are channel states")
    return em.StateLayout(
        baro_scale=sensors.baro is not None and sensors.baro.filter_scale_sigma > 0.0,
        clock=(sensors.gnss is not None and nav.gps_coupling == "tight") or sensors.pseudolite is not None,
        loop=nav.baro_loop != "none",
        n_sv=n_sv,
        n_pl=n_pl,
        pl_clock=n_pl > 0 and not sensors.pseudolite.synchronized,
        pl_sync=n_pl > 0 and sensors.pseudolite.synchronized and sensors.pseudolite.sync_sigma_m > 0.0,
        carrier=carrier,
        iono_zenith=bool(n_sv) and sensors.gnss.service is not None and sensors.gnss.service.iono_zenith_state,
        tropo_zenith=bool(n_sv) and sensors.gnss.service is not None and sensors.gnss.service.tropo_zenith_state,
        **_radalt_states(sensors, nav),
    )


@dataclass(frozen=True)
class NavSystem:
    """INS + filter configured from a profile's [nav] and [sensors] (+ the runway and terrain)."""

    nav: NavConfig
    sensors: SensorsConfig
    runway: geo.RunwayFrame
    terrain_h: Callable[[Array], Array]
    """Terrain ellipsoid height (m) at ECEF points (..., 3): the filter's terrain database."""
    filter: NavFilter = field(compare=False)
    layout: em.StateLayout = field(compare=False)
    turbulence: str = "none"
    """The environment's turbulence level: the gyro axis errors' process noise (nav/noise.py gyro_axis_q)."""
    gbas_geometry: tuple[float, float, float] = REFERENCE_GEOMETRY
    """GBAS: the approach's start (x_air m, dh m, v_air m/s; gbas.approach_geometry), where the filter's channel
    noise and P0 take the distance-dependent sigmas (nav/noise.py)."""
    noise_model: NoiseModel = field(init=False, compare=False, repr=False)
    rows: MeasurementRows = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "noise_model", NoiseModel(self.sensors, self.nav, self.layout, self.baro_ref_m,
                                                                 self.turbulence, self.gbas_geometry))
        object.__setattr__(self, "rows", MeasurementRows(self.layout, self.sensors, self.nav, self.runway,
                                                         self.terrain_h))

    @classmethod
    def build(cls, nav: NavConfig = DEFAULT_NAV, sensors: SensorsConfig = DEFAULT_SENSORS,
              runway: geo.RunwayFrame | None = None, terrain: Any = None, turbulence: str = "none",
              gbas_geometry: tuple[float, float, float] = REFERENCE_GEOMETRY) -> NavSystem:
        """From configs; runway defaults to a frame at SFO 28R, terrain to flat at the threshold height; turbulence
        the environment's level (nav/noise.py SF_DRIFT_Q); gbas_geometry the approach's start (GBAS only)."""
        rwy = runway or geo.RunwayFrame(np.radians(37.6117), np.radians(-122.3581), 4.0, np.radians(298.0))
        return cls(nav=nav, sensors=sensors, runway=rwy, terrain_h=TerrainDatabase(rwy, terrain),
                   filter=nav.make_filter(), layout=layout_for(nav, sensors), turbulence=turbulence,
                   gbas_geometry=gbas_geometry)

    @classmethod
    def from_profile(cls, profile: Any) -> NavSystem:
        """The navigation system of a Profile (its [nav], [sensors], runway and terrain). A value: systems of equal
        profiles are equal (and hash alike), so what a truth's memo keeps for one serves the other (`_prepared`)."""
        nav = getattr(profile, "nav", DEFAULT_NAV)
        env = getattr(profile, "environment", None)
        geometry = profile.gbas_geometry() if hasattr(profile, "gbas_geometry") else REFERENCE_GEOMETRY
        return cls.build(nav, profile.sensors, profile.runway.frame, profile.terrain,
                         turbulence=getattr(env, "turbulence", "none"), gbas_geometry=geometry)

    @property
    def baro_ref_m(self) -> float:
        """The baro scale factor's reference H_ref (m): the altimeter-setting reference, the field (the runway
        threshold's height; the truth's is the same elevation, geopotential: sensors/suite.py)."""
        return float(self.runway.threshold_h_m)

    # --- models -------------------------------------------------------------------------------------------

    def noise(self, elevation_rad: Array | None = None) -> em.ErrorNoise:
        """Process noise from the sensors' error budgets, the GPS channels at elevation_rad (nav/noise.py)."""
        return self.noise_model.noise(elevation_rad)

    def initial_covariance(self, elevation_rad: Array | None = None) -> Array:
        """P0 (nav/noise.py NoiseModel.initial_covariance)."""
        return self.noise_model.initial_covariance(elevation_rad)

    def loop_gains(self) -> vl.LoopGains | None:
        """The INS damping-loop gains (None without a loop)."""
        return self.nav.loop_gains()

    def _loop_error_nodes(self, fs: FilterState, h_m: float, noise: em.ErrorNoise) -> tuple[float, Array, Array]:
        """(e_hat, e, w): the loop error at the estimate, e_hat = -dp_D - bb - (h - H_ref) sb (h the navigation's
        height h_m: exact at the estimate, core/nav/errormodel.loop_jacobian), and the 5-point Gauss-Hermite nodes e
        and weights w (summing to 1) of e ~ N(e_hat, var), var = the Jacobian row's P variance (de/d(dp_D) =
        -(1 + sb)) + the baro noise."""
        lay = self.layout
        row = np.zeros(lay.n)
        row[lay.i("dp", 2)] = -1.0
        row[lay.i("bb")] = -1.0
        if lay.has("sb"):
            row[lay.i("sb")] = -(h_m - self.baro_ref_m)
        e_hat = float(row @ fs.x)
        if lay.has("sb"):
            row[lay.i("dp", 2)] = -(1.0 + float(fs.x[lay.i("sb")]))
        P = self.filter.covariance(fs)
        sd = float(np.sqrt(row @ P @ row + noise.baro_noise_sigma_m**2))
        z, w = np.polynomial.hermite_e.hermegauss(5)
        return e_hat, e_hat + sd * z, w / w.sum()

    def loop_slopes(self, fs: FilterState, h_m: float, noise: em.ErrorNoise) -> vl.LoopGains | None:
        """The damping loop as the error model sees it (`loop_linearization`'s gains)."""
        return self.loop_linearization(fs, h_m, noise)[0]

    def loop_linearization(self, fs: FilterState, h_m: float, noise: em.ErrorNoise
                           ) -> tuple[vl.LoopGains | None, Array | None]:
        """(gains, b): the damping loop as the error model sees it. Constant gains as they are, b None. For the
        adaptive tanh / sinh forms the *statistical linearization* of each branch over the loop error
        e ~ N(e_hat, var) (`_loop_error_nodes`; 5-point Gauss-Hermite): the slopes s = E[dk/de] (the gains, F's and
        so the covariance's; the small-signal slope alone makes the filter claim a sigma it does not have once
        |b e| ~ 1: tanh saturates, sinh grows), and the constant term b (n,), E[k1(e)] - s1 e_hat at dp_D (m/s) and
        E[k2(e)] - s2 e_hat at dv_D (m/s^2), the estimate's pull beyond s e_hat (nav/errormodel.MeanModel adds it
        to F x): with the loop error tens of metres (an uncorrected cold day) tanh's pull is saturated at C while
        s e_hat is near 0."""
        g = self.loop_gains()
        if g is None or g.form == "constant":
            return g, None
        e_hat, e, w = self._loop_error_nodes(fs, h_m, noise)

        def slope(c: float, b: float) -> float:
            d = 1.0 / np.cosh(b * e) ** 2 if g.form == "tanh" else np.cosh(b * e)  # d/de f(b e) / b
            return float(c * b * (w @ d))

        s = vl.LoopGains(slope(g.c1, g.b1_per_m), slope(g.c2, g.b2_per_m), g.c3)
        k1, k2 = vl.branch_corrections(g, e)
        b = np.zeros(self.layout.n)
        b[self.layout.i("dp", 2)] = float(w @ k1) - s.c1 * e_hat
        b[self.layout.i("dv", 2)] = float(w @ k2) - s.c2 * e_hat
        return s, b

    def shares_covariance(self) -> bool:
        """Whether runs on one truth can share one covariance (`run(..., shared_covariance=True)`): the optimal
        'ekf' filter, tightly coupled GPS (the loose fix's covariance depends on each run's ranges), and a baro
        loop the error model sees with constant gains (the adaptive forms linearize about each run's
        estimate). Decided from the configuration alone, so a campaign picks it once per profile. With carrier
        phase too: a class splits where its runs' carrier arcs begin at different epochs (nav/shared.py), and the
        compiled epoch (nav/engine.py, which needs this too) carries the carrier states."""
        g = self.loop_gains()
        return (self.nav.filter == "ekf" and self.nav.gps_coupling == "tight" and not self.nav.fde.enabled
                and (g is None or g.form == "constant"))

    # --- the start -----------------------------------------------------------------------------------------

    def start(self, truth: Truth, rngs: list[np.random.Generator], row: int = 0,
              elevation_rad: Array | None = None, *, obs: Observations | None = None,
              states: SensorStates | None = None, elevation_per_run: Array | None = None,
              memo: TruthMemo | None = None) -> tuple[ins.InsState, list[RunFilter]]:
        """INS states of len(rngs) runs at truth row `row` with their initial errors, and their filters
        (elevation_rad: the GPS channels' elevations at the start, for their P0).

        [nav.initial_error] start = "prior": INS errors drawn from P0's navigation block, zero estimates, P0.
        "converged" (nav/initial.py): obs, the observations at the row (`observations`, run axis first; the
        first run's schedule is flown), and states, the runs' realized sensor errors there
        (sensors/states.py), are required; runs with one sky start with the same converged covariance.
        elevation_per_run (N, k): each run's own GPS sky at the start (the prior start's P0 per run). memo: the
        truth's TruthMemo, which keeps each sky's converged start (`_prepared`)."""
        n = len(rngs)
        c_true = ins.cbn_from_quaternion(truth.q_nb[row])
        s = ins.init_state(np.full(n, truth.lat_rad[row]), truth.lon_rad[row], truth.h_m[row], truth.v_ned[row],
                           c_true)
        dbs = self._terrain_errors(rngs)
        if self.nav.initial_error.start == "prior":
            P0 = self.initial_covariance(elevation_rad)
            sd = np.sqrt(np.diag(P0)[:9])
            e = np.stack([sd * g.standard_normal(9) for g in rngs])  # INS errors after alignment + cruise
            s = ins.perturb(s, e[:, 0:3], e[:, 3:6], e[:, 6:9])
            Ps = [P0] * n
            if elevation_per_run is not None:  # each run's P0 at its own sky (the INS errors do not depend on it)
                Ps = [self.initial_covariance(elevation_per_run[i]) for i in range(n)]
            runs = [RunFilter(self.filter.init(np.zeros(self.layout.n), Ps[i]), [], np.zeros(3), np.zeros(3),
                              self._fde(), dbs[i]) for i in range(n)]
            return s, runs
        if obs is None or states is None:
            raise ValueError("the converged start ([nav.initial_error] start = 'converged') needs the "
                             "observations and the realized sensor states at the start row "
                             "(SensorSuite.draw + sensors.states.start_states)")
        states = self._with_database_states(states, dbs, truth, row)
        if obs.per_run_sky:  # each run its own GPS sky: its own P0 and converged covariance, flown on the
            # schedule of the first run with that sky (the integrity bank's copies share the main filter's start)
            first: dict[bytes, int] = {}
            prep: dict[bytes, initial.Prepared] = {}  # one converged start per sky (bank copies share their run's)
            draws = []
            for i, g in enumerate(rngs):
                key = obs.elevations(i).tobytes()
                i0 = first.setdefault(key, i)
                P0 = self.initial_covariance(obs.elevations(i))
                if key not in prep:
                    prep[key] = self._prepared(truth, obs.run(i0), row, P0, states.take(i), memo)
                d = initial.draw(self, truth, obs.run(i0), states.take(i), [g], row, P0, prep[key])
                draws.append(d)
            e = np.concatenate([d[0] for d in draws])
            x_hat = np.concatenate([d[1] for d in draws])
            P_convs = [d[2].P_conv for d in draws]
        else:
            e, x_hat, prepared = initial.draw(self, truth, obs, states, list(rngs), row,
                                              self.initial_covariance(elevation_rad))
            P_convs = [prepared.P_conv] * n
        s = ins.perturb(s, e[:, 0:3], e[:, 3:6], e[:, 6:9])
        if self.layout.has("ac"):
            s = replace(s, a_comp_mps2=e[:, self.layout.i("ac")])  # ac error = the INS compensator (truth 0)
        runs = [RunFilter(self.filter.init(x_hat[i], P_convs[i]), [], np.zeros(3), np.zeros(3), self._fde(), dbs[i])
                for i in range(n)]
        return s, runs

    def _prepared(self, truth: Truth, obs: Observations, row: int, P0: Array, states: SensorStates,
                  memo: TruthMemo | None = None) -> initial.Prepared:
        """The converged start's P_conv and conditioner (initial.Prepared) of one run's sky and schedule. With the
        truth's memo it is made once for the same inputs (an integrity bank that starts its run again, off the
        group's pass, finds it there instead of repeating the 600 s Riccati recursion and the eigen-decompositions):
        keyed by this system (a value: nav/sensors/runway/terrain) and the bytes of everything else initial.draw
        reads (the row, P0, the run's observations at the row, the sensor states' indices, the day's baro scale)."""
        s_idx, _ = initial.sensor_vector(self.layout, states, P0)
        sb_ref = initial.sb_reference(states)
        parts = [np.asarray(P0, dtype=float).tobytes(), str(row).encode(), np.asarray(s_idx).tobytes(),
                 repr(sb_ref).encode()]
        for f in fields(obs):
            v = getattr(obs, f.name)
            parts.append(f.name.encode())
            parts.append(repr(v.shape).encode() + v.tobytes() if isinstance(v, np.ndarray) else repr(v).encode())
        key = (self, hashlib.blake2b(b"\0".join(parts), digest_size=20).digest())

        def make() -> initial.Prepared:
            P_conv = initial.converged_covariance(self, truth, obs, row, P0, self.nav.initial_error.converge_s, sb_ref)
            return initial.Prepared(P_conv, initial.conditioner(P_conv, P0[np.ix_(s_idx, s_idx)], s_idx))

        return memoized(memo, truth, "system.prepared", key, make, keep=PREPARED_KEEP)

    def _fde(self) -> FdeState | None:
        """A run's online FDE state ([nav.fde] enabled), else None."""
        if not self.nav.fde.enabled:
            return None
        reset = (np.concatenate([np.atleast_1d(np.arange(self.layout.n)[self.layout.index[g]]) for g in RESET_GROUPS])
                 if self.nav.feedback else None)
        return FdeState(self.nav.fde, self.nav.aiding_rate_hz, reset, self.runway.heading_rad)

    def _terrain_errors(self, rngs: list[np.random.Generator]) -> list[tdb.TerrainDbError | None]:
        """Each run's terrain database = the truth terrain + its own error realization e(x), drawn from the child
        stream "terrain_db" of its nav stream (the nav stream's own draws are untouched); None entries without a
        radar altimeter or with a zero error model. The filter looks its database up at the INS position: e enters
        the radalt difference as e(x_ins), carried by the rab / tdb states (its own along-track gradient, not
        differentiable for a Gauss-Markov field, is not linearized: the INS's slowly varying along-track error only
        shifts where the field is sampled, which leaves u(x_ins(t)) a Gauss-Markov of the same time constant)."""
        cfg = self.nav.terrain_database
        if self.sensors.radalt is None or cfg.zero:
            return [None] * len(rngs)
        return [tdb.draw(cfg, substream(g, "terrain_db")) for g in rngs]

    def _with_database_states(self, states: SensorStates, dbs: list, truth: Truth, row: int) -> SensorStates:
        """The realized radalt-difference states with the database's part added: rab = altimeter bias +
        database bias (both enter the difference with the same sign), tdb = the database's unit Gauss-Markov
        u at the start's along-track position (nav/terrain_db.py)."""
        if all(d is None for d in dbs):
            return states
        n = len(dbs)
        kw: dict[str, Array] = {}
        if self.layout.has("rab"):
            base_ = np.zeros(n) if states.rab is None else np.asarray(states.rab, dtype=float).reshape(n)
            kw["rab"] = base_ + np.array([0.0 if d is None else d.bias_m for d in dbs])
        if self.layout.has("tdb"):
            x0 = float(self.runway.from_ecef(truth.r_ecef[row])[0])
            kw["tdb"] = np.array([0.0 if d is None else float(np.interp(x0, d.x_m, d.u)) for d in dbs])
        return replace(states, **kw)

    # --- over whole records ----------------------------------------------------------------------------------

    @staticmethod
    def observations(records: Mapping[str, Any], t: float, tol: float, batched: bool) -> Observations:
        """The measurements available at time t from whole records (nav/observations.py)."""
        return Observations.at(records, t, tol, batched)

    def run(self, truth: Truth, records: Mapping[str, Any], rngs: np.random.Generator | list[np.random.Generator],
            *, shared_covariance: bool = False, states: SensorStates | None = None, copies: bool = False,
            keep: dict | None = None, memo: TruthMemo | None = None) -> NavRun | list[NavRun]:
        """Navigate over whole records (open loop: the truth is only read at row 0, at the epochs for the error
        history and, with the shared covariance, as the reference trajectory).

        records: {"imu": ImuSamples, "baro": ..., ...} of one run (rngs a Generator) or of len(rngs) runs
        (run axis first, rngs a list). Returns one NavRun, or a list. shared_covariance (several runs, optimal
        'ekf' only): one covariance and gain per measurement schedule (nav/shared.py), several times faster.
        states: the runs' realized sensor errors at truth row 0 (sensors.states.start_states), needed by the
        converged start. copies: the runs are copies of one run (the same IMU and baro records and start draws:
        the integrity bank's sub-filters, which differ only in the measurements they use): the INS is integrated
        once for all of them (feed-forward only; checked). keep: a dict that receives what the runs' integrity
        banks reuse (campaign/bankpass.py, open loop): "start" [(x_hat (n,), P (n, n))] each run's filter start,
        "db" its terrain-database error, "ins_epoch_rows" (N, E, 16) the INS states at the aiding epochs (rows
        epoch_rows, 2 epoch_rows, ...; packed, kernels/strapdown.py), "epoch_rows", "feed_forward", "sb_ref" the
        shared covariance's baro scale factor (initial.sb_reference). memo: the
        truth's TruthMemo (approachsim/memo.py), owned by the caller that shares the truth among runs (the campaign's
        open-loop group): the converged starts and the reduced pass's epoch models are kept there for the runs'
        integrity banks.
        """
        records = tuned_records(records, self.nav.gps_sigma_scale)
        if shared_covariance and not self.shares_covariance():
            raise ValueError("shared_covariance needs the optimal 'ekf' filter (robust filters gate per run), "
                             "tight GPS coupling and a constant-gain or no baro loop")
        batched = isinstance(rngs, list)
        gens = rngs if batched else [rngs]
        imu = records["imu"]
        dth = imu.dtheta_body if batched else imu.dtheta_body[None]
        dvb = imu.dv_body if batched else imu.dv_body[None]
        m = dth.shape[1]
        dt = float(imu.dt_s)
        epoch_rows = max(1, int(round(1.0 / dt / self.nav.aiding_rate_hz)))
        tol = 0.25 * dt
        gnss = records.get("gnss")
        sky = gnss is not None and batched and bool(gnss.per_run_sky)
        obs0 = Observations.at(records, float(truth.t_s[0]), tol, batched)
        # the GPS channels' elevations at the first GNSS sample (P0 of the channel states)
        el0 = None if gnss is None else (gnss.elevation_rad[:, 0] if sky else gnss.elevation_rad[0])
        s, runs = self.start(truth, gens, elevation_rad=None if el0 is None else (el0[0] if sky else el0), obs=obs0,
                             states=states, elevation_per_run=el0 if sky else None, memo=memo)
        sb_ref = initial.sb_reference(states)
        shared = (SharedCovariance.start(runs, truth, m, epoch_rows, obs0.per_run_sky, sb_ref) if shared_covariance
                  else None)
        ins_of = None
        if copies:  # one INS for all: every copy must start from the same INS state on the same increments (the
            # IMU record may hold one run for all)
            x0 = ins.pack(s)
            if self.nav.feedback or not (np.all(x0 == x0[:1]) and np.all(dth == dth[:1]) and np.all(dvb == dvb[:1])):
                raise ValueError("run(copies=True): the runs are not copies of one feed-forward run (their start, "
                                 "increments or feedback differ)")
            s, ins_of = ins.unpack(x0[:1]), np.zeros(len(gens), dtype=int)
            dth, dvb = dth[:1], dvb[:1]
        if keep is not None:
            keep["start"] = [(np.array(r.fs.x, dtype=float), np.array(self.filter.covariance(r.fs), dtype=float))
                             for r in runs]
            keep["db"] = [r.db_error for r in runs]
            keep["sb_ref"] = sb_ref
        nav = Navigator(self, s, runs, float(truth.t_s[0]), m + 1, shared=shared, ins_of=ins_of)
        if keep is not None:
            keep["feed_forward"] = not self.nav.feedback
            keep["epoch_rows"] = epoch_rows
        baro = records.get("baro")
        hb_full = age = None
        if self.loop_gains() is not None and baro is not None:
            # an invalid sample (outage, a lost sensor) is no baro: nan, and the loop holds (kernels.strapdown)
            # zero-order hold of the latest baro sample at each IMU interval start (truth rows 0 .. m-1), and its age
            hb_full, age = ins.held_baro(baro.valid, baro.h_baro_m, baro.t_s, truth.t_s[:m])
            if copies:
                if not np.all((hb_full == hb_full[:1]) | (np.isnan(hb_full) & np.isnan(hb_full[:1]))):
                    raise ValueError("run(copies=True): the copies' baro records differ")
                hb_full = hb_full[:1]
        if nav.can_pass() and nav.compiled_pass(records, truth, batched, dth, dvb, dt, hb_full, epoch_rows, age,
                                                memo=memo):
            if keep is not None:
                keep["ins_epoch_rows"] = nav.rows[:, epoch_rows::epoch_rows].copy()
                if nav.reduced_runs is not None:
                    keep["reduced_runs"] = nav.reduced_runs
            results = nav.results(truth, solutions={0} if copies else True)
            return results if batched else results[0]
        # the compiled INS steps every run over the rows between two epochs in one call; a run's numbers do not
        # depend on the batch it shares (the campaign relies on it: kernels/strapdown.py)
        j0 = 0
        while j0 < m:
            j1 = min(m, (j0 // epoch_rows + 1) * epoch_rows)  # rows j0 + 1 .. j1; j1 an epoch unless the end
            nav.propagate(dth[:, j0:j1], dvb[:, j0:j1], dt, None if hb_full is None else hb_full[:, j0:j1], j0,
                          None if age is None else age[j0:j1])
            if j1 % epoch_rows == 0:
                obs = Observations.at(records, float(truth.t_s[j1]), tol, batched)
                if hb_full is not None:  # the loop held where the kernel had no baro over the whole interval
                    obs = obs.with_loop_held(np.all(np.isnan(hb_full[:, j0:j1]), axis=1)[nav.ins_of])
                nav.epoch(j1, float(truth.t_s[j1]), obs, truth)
                if hb_full is not None:  # a baro excluded by FDE no longer drives that run's damping loop
                    for i, r in enumerate(runs):
                        if r.baro_excluded():
                            if copies:
                                raise ValueError("run(copies=True): a copy's FDE excluded the baro (its INS differs)")
                            hb_full[i, j1:] = np.nan
            j0 = j1
        if keep is not None:
            keep["ins_epoch_rows"] = nav.rows[:, epoch_rows::epoch_rows].copy()
        results = nav.results(truth, solutions={0} if copies else True)  # copies: the main filter's solution only
        return results if batched else results[0]


def tuned_records(records: Mapping[str, Any], gps_sigma_scale: float) -> Mapping[str, Any]:
    """The records as the filter weighs them: the GNSS record's nominal pseudorange 1-sigma times gps_sigma_scale
    ([nav] gps_sigma_scale, R tuning without channel states); the same mapping when the scale is 1."""
    g = records.get("gnss")
    if g is None or gps_sigma_scale == 1.0:
        return records
    return {**records, "gnss": replace(g, sigma_m=np.asarray(g.sigma_m) * gps_sigma_scale)}
