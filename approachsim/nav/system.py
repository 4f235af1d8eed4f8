"""The navigation system: strapdown INS + error-state filter over sensor records, as one composable object.

    nav = NavSystem.from_profile(profile)
    run = nav.run(truth, records, rng)               # records: {name: record} from sensors.suite
    run.solution (NavSolution), run.status (StatusLog), run.x, run.P_diag (filter history at the epochs)

The INS integrates every IMU increment; at each aiding epoch (nav.aiding_rate_hz) the filter predicts with
the discretized error model (errormodel.dynamics + discretize, linearized about the INS solution) and takes
every available scalar measurement in turn (baro, radar altimeter below its range, each valid pseudorange,
each pseudolite range), each giving an UpdateStatus. Output (seed 002 feed-forward) = INS - estimated error;
with `feedback` the estimate is fed back into the INS (and the IMU bias estimates into the increments) and
the corresponding error states reset to zero.

The start ([nav.initial_error] start): "converged" (default) draws the INS error and the filter's sensor-state
estimates jointly with the run's realized sensor errors from the filter's covariance after a pre-approach aided
segment (nav/initial.py; `run(..., states=sensors.states.start_states(...))`); "prior" draws the INS errors
from the diagonal prior alone.

The same epoch machinery serves the closed loop (closed_loop.py): `start`, `aid`, `output`, with the INS
stepped by the caller (nav/ins.py). Several Monte Carlo runs can share one call: the INS is stepped for all of
them at once (run axis first); each run has its own filter state, or with `shared_covariance` one covariance
and gain for all (open-loop runs on one truth, optimal filter).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.nav import errormodel as em
from approachsim.nav import initial, ins
from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav import vertical_loop as vl
from approachsim.nav.base import FilterState, NavFilter, UpdateStatus
from approachsim.nav.config import DEFAULT_NAV, NavConfig
from approachsim.nav.fde import RESET_GROUPS, FdeState
from approachsim.records import NavSolution, Truth
from approachsim.seeding import substream
from approachsim.sensors.config import DEFAULT_SENSORS, SensorsConfig
from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.receiver import iono_obliquity, tropo_mapping
from approachsim.sensors.presets import PRESETS
from approachsim.sensors.states import SensorStates

Array = np.ndarray


@dataclass(frozen=True)
class StatusLog:
    """Every scalar measurement's status record of one run, in processing order (1-D arrays, length u)."""

    t_s: Array
    name: Array
    """(u,) channel name ("baro", "radalt", "gps07", "pl0", ...), str."""
    innovation: Array
    variance: Array
    """(u,) predicted innovation variance S = h' P h + r."""
    test_ratio: Array
    """(u,) nu^2 / S (the NIS of a scalar)."""
    weight: Array
    accepted: Array

    @classmethod
    def from_records(cls, recs: list[UpdateStatus]) -> StatusLog:
        """Arrays from a list of UpdateStatus."""
        return cls(
            t_s=np.array([r.t_s for r in recs], dtype=float),
            name=np.array([r.name for r in recs], dtype=str),
            innovation=np.array([r.innovation for r in recs], dtype=float),
            variance=np.array([r.variance for r in recs], dtype=float),
            test_ratio=np.array([r.test_ratio for r in recs], dtype=float),
            weight=np.array([r.weight for r in recs], dtype=float),
            accepted=np.array([r.accepted for r in recs], dtype=bool),
        )


@dataclass(frozen=True)
class NavRun:
    """One run's navigation output: the solution at the IMU rate and the filter history at the epochs."""

    solution: NavSolution
    status: StatusLog
    t_epoch_s: Array
    """(e,) aiding epoch times, s."""
    x: Array
    """(e, n) estimated error state after the epoch's updates (feedback: the residual after the reset)."""
    P_diag: Array
    """(e, n) its variances."""
    P_nav: Array
    """(e, 9, 9) covariance of the navigation errors (dp, dv, psi) after the updates."""
    true_error_nav: Array | None
    """(e, 9) INS - truth error (dp NED m, dv m/s, psi rad) of the *output* at the epochs, when truth is given."""
    layout: em.StateLayout = field(compare=False)


@dataclass
class _Run:
    """Mutable per-run filter bookkeeping inside one NavSystem pass (never leaves this module)."""

    fs: FilterState
    statuses: list
    bg_fb: Array
    ba_fb: Array
    fde: FdeState | None = None
    """Online fault detection and exclusion ([nav.fde] enabled), else None."""
    db_error: tdb.TerrainDbError | None = None
    """This run's terrain-database error (None: the database is the truth terrain)."""


@dataclass
class _SharedCov:
    """Shared covariances of one `NavSystem.run(..., shared_covariance=True)` pass: one P per measurement
    schedule history (never leaves this module)."""

    P: list
    """(n, n) covariance of each class."""
    of_run: Array
    """(N,) class of each run."""

    def predict_class(self, c: int, phi: Array, qd: Array) -> None:
        """P- = Phi P+ Phi' + Qd for class c (its own model: GPS sky, damping loop held or not)."""
        P = phi @ self.P[c] @ phi.T + qd
        self.P[c] = 0.5 * (P + P.T)

    def split(self, schedule: Array) -> None:
        """Runs of one class whose schedules (rows of (N, k) bool) differ go to new classes (copies of P)."""
        keys: dict[tuple[int, bytes], int] = {}
        new_P: list = []
        of_run = np.empty_like(self.of_run)
        for i, c in enumerate(self.of_run):
            k = (int(c), schedule[i].tobytes())
            if k not in keys:
                keys[k] = len(new_P)
                new_P.append(self.P[int(c)])
            of_run[i] = keys[k]
        self.P, self.of_run = new_P, of_run

    def classes(self) -> list[tuple[int, list[int]]]:
        """(class, its runs) for every class."""
        return [(c, [int(i) for i in np.flatnonzero(self.of_run == c)]) for c in range(len(self.P))]


def _radalt_states(sensors: SensorsConfig, nav: NavConfig) -> dict[str, bool]:
    """StateLayout flags of the radalt / database error states: present with the radar altimeter only, each when
    its error model is not zero."""
    r, d = sensors.radalt, nav.terrain_database
    if r is None:
        return {}
    return {"radalt_bias": r.bias_sigma_m > 0.0 or d.bias_sigma_m > 0.0, "radalt_markov": r.markov_sigma_m > 0.0,
            "terrain_db": d.correlated}


def _epoch_index(t_rec: Array, t: float, tol: float) -> int | None:
    """Index of the record sample at time t (within tol), or None."""
    i = int(np.searchsorted(t_rec, t - tol))
    if i < t_rec.shape[0] and abs(t_rec[i] - t) <= tol:
        return i
    return None


@dataclass(frozen=True)
class TerrainDatabase:
    """The filter's terrain: ellipsoid height (m) at ECEF points (..., 3) from the profile's Terrain along the
    runway x axis (flat at the threshold height when terrain is None). A picklable callable. Each run's
    database adds its own error realization to it (nav/terrain_db.py, `_Run.db_error`)."""

    runway: geo.RunwayFrame
    terrain: Any = None

    def __call__(self, r_ecef: Array) -> Array:
        if self.terrain is None:
            return np.full(np.shape(r_ecef)[:-1], self.runway.threshold_h_m)
        return self.terrain.height_at(self.runway.from_ecef(r_ecef)[..., 0])


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
    _noise_cache: dict = field(default_factory=dict, init=False, compare=False, repr=False)
    """noise() by elevation vector: the model is a pure function of the configuration and the elevations."""

    @classmethod
    def build(cls, nav: NavConfig = DEFAULT_NAV, sensors: SensorsConfig = DEFAULT_SENSORS,
              runway: geo.RunwayFrame | None = None, terrain: Any = None) -> NavSystem:
        """From configs; runway defaults to a frame at SFO 28R, terrain to flat at the threshold height."""
        rwy = runway or geo.RunwayFrame(np.radians(37.6117), np.radians(-122.3581), 4.0, np.radians(298.0))

        terrain_h = TerrainDatabase(rwy, terrain)

        n_sv = 0
        if sensors.gnss is not None and nav.channel_states and nav.gps_coupling == "tight":
            n_sv = 24
        n_pl = len(sensors.pseudolite.positions_rwy) if sensors.pseudolite is not None and nav.channel_states else 0
        layout = em.StateLayout(
            baro_scale=sensors.baro is not None and sensors.baro.scale_factor_sigma > 0.0,
            clock=(sensors.gnss is not None and nav.gps_coupling == "tight") or sensors.pseudolite is not None,
            loop=nav.baro_loop != "none",
            n_sv=n_sv,
            n_pl=n_pl,
            pl_clock=n_pl > 0 and not sensors.pseudolite.synchronized,
            **_radalt_states(sensors, nav),
        )
        return cls(nav=nav, sensors=sensors, runway=rwy, terrain_h=terrain_h, filter=nav.make_filter(),
                   layout=layout)

    @classmethod
    def from_profile(cls, profile: Any) -> NavSystem:
        """The navigation system of a Profile (its [nav], [sensors], runway and terrain)."""
        nav = getattr(profile, "nav", DEFAULT_NAV)
        return cls.build(nav, profile.sensors, profile.runway.frame, profile.terrain)

    # --- models -------------------------------------------------------------------------------------------

    def _clock(self) -> ClockModel:
        g = self.sensors.gnss
        if g is not None:
            return ClockModel.named(g.oscillator, g.clock_bias0_sigma_m, g.clock_drift0_sigma_mps)
        return ClockModel()

    def noise(self, elevation_rad: Array | None = None) -> em.ErrorNoise:
        """Process noise from the sensor configuration (the filter knows the sensors' error budgets)."""
        key = None if elevation_rad is None else np.asarray(elevation_rad, dtype=float).tobytes()
        nz = self._noise_cache.get(key)
        if nz is None:
            if len(self._noise_cache) > 512:  # one sky's epochs x runs at most; keep memory bounded
                self._noise_cache.clear()
            nz = self._build_noise(elevation_rad)
            for v in vars(nz).values():  # shared between callers: read-only
                if isinstance(v, np.ndarray):
                    v.flags.writeable = False
            self._noise_cache[key] = nz
        return nz

    def _build_noise(self, elevation_rad: Array | None) -> em.ErrorNoise:
        g = PRESETS[self.sensors.imu.grade]
        b = self.sensors.baro
        clk = self._clock()
        kw: dict[str, Any] = {}
        if self.sensors.gnss is not None:
            bud = self.sensors.gnss.budget()
            el = np.full(24, np.radians(30.0)) if elevation_rad is None else np.nan_to_num(elevation_rad, nan=0.5)
            el = np.maximum(el, np.radians(2.0))
            kw.update(
                gse_sigma_m=np.sqrt(bud.clock_ephemeris_m**2 + (bud.iono_zenith_m * iono_obliquity(el)) ** 2
                                    + (bud.tropo_zenith_m * tropo_mapping(el)) ** 2),
                gse_tau_s=min(bud.clock_ephemeris_tau_s, bud.iono_tau_s, bud.tropo_tau_s),
                # per channel at its elevation under do253 (the sensor's sigma_mp), one value under nrc1995
                gmp_sigma_m=(bud.multipath_sigma_m(el) if bud.multipath_model == "do253" else bud.multipath_m),
                gmp_tau_s=bud.multipath_tau_s,
            )
        if self.sensors.pseudolite is not None:
            p = self.sensors.pseudolite
            kw.update(pmp_sigma_m=p.multipath_m, pmp_tau_s=p.multipath_tau_s)
            if not p.synchronized:
                pc = ClockModel.named("ocxo", 30.0, 0.03)
                q = pc.q(1.0)
                kw.update(pclk_sf=q[0, 0] - q[1, 1] / 3.0, pclk_sg=q[1, 1])
        if self.sensors.radalt is not None:
            kw.update(ram_sigma_m=self.sensors.radalt.markov_sigma_m, ram_tau_s=self.sensors.radalt.markov_tau_s,
                      tdb_correlation_m=self.nav.terrain_database.correlation_m)
        q1 = clk.q(1.0)  # Q(1 s) = [[S_f + S_g / 3, S_g / 2], [., S_g]]
        return em.ErrorNoise(
            gyro_arw_rad_sqrts=g.gyro_arw_rad_sqrts,
            accel_vrw_mps_sqrts=g.accel_vrw_mps_sqrts,
            gyro_bias_rw=np.sqrt(2.0 * g.gyro_bi_radps**2 / g.gyro_bi_tau_s),
            accel_bias_rw=np.sqrt(2.0 * g.accel_bi_mps2**2 / g.accel_bi_tau_s),
            baro_bias_sigma_m=b.bias_sigma_m if b is not None else 1.0,
            baro_bias_tau_s=b.bias_tau_s if b is not None else 100.0,
            baro_noise_sigma_m=b.noise_sigma_m if b is not None else 1.0,
            baro_rate_hz=b.rate_hz if b is not None else 10.0,
            clock_sf=float(q1[0, 0] - q1[1, 1] / 3.0),
            clock_sg=float(q1[1, 1]),
            **kw,
        )

    def initial_covariance(self, elevation_rad: Array | None = None) -> Array:
        """P0: the profile's initial INS errors, the IMU grade's biases, the sensors' error budgets (the GPS
        channels' slow errors at their elevations elevation_rad (24,), rad, when given)."""
        lay, ie = self.layout, self.nav.initial_error
        g = PRESETS[self.sensors.imu.grade]
        nz = self.noise(elevation_rad)
        d = np.zeros(lay.n)
        d[lay.index["dp"]] = ie.position_m**2
        d[lay.index["dv"]] = ie.velocity_mps**2
        d[lay.index["psi"]] = [ie.tilt_rad**2, ie.tilt_rad**2, ie.heading_rad**2]
        d[lay.index["bg"]] = g.gyro_bias_radps**2 + g.gyro_bi_radps**2
        # scale factor and misalignment under 1 g look like a bias to a level accelerometer triad
        d[lay.index["ba"]] = (g.accel_bias_mps2**2 + g.accel_bi_mps2**2
                              + (9.8 * g.accel_misalign_rad) ** 2 + (9.8 * g.accel_sf) ** 2)
        d[lay.i("bb")] = nz.baro_bias_sigma_m**2
        if lay.has("sb"):
            d[lay.i("sb")] = self.sensors.baro.scale_factor_sigma**2
        if lay.has("clk"):
            c = self._clock()
            d[lay.index["clk"]] = [c.bias0_sigma_m**2, c.drift0_sigma_mps**2]
        if lay.has("gse"):
            d[lay.index["gse"]] = np.broadcast_to(nz.gse_sigma_m, (lay.n_sv,)) ** 2
            d[lay.index["gmp"]] = nz.gmp_sigma_m**2
        if lay.has("pmp"):
            p = self.sensors.pseudolite
            d[lay.index["pmp"]] = p.multipath_m**2
            d[lay.index["ptr"]] = (p.tropo_ppm_sigma * 1e-6) ** 2
            if lay.has("pclk"):
                d[lay.index["pclk"]] = np.tile([30.0**2, 0.03**2], lay.n_pl)
        self._radalt_p0(d)
        return np.diag(d)

    # --- one pass ------------------------------------------------------------------------------------------

    def start(self, truth: Truth, rngs: list[np.random.Generator], row: int = 0,
              elevation_rad: Array | None = None, *, obs: Mapping[str, Any] | None = None,
              states: SensorStates | None = None) -> tuple[ins.InsState, list[_Run]]:
        """INS states of len(rngs) runs at truth row `row` with their initial errors, and their filters
        (elevation_rad: the GPS channels' elevations at the start, for their P0).

        [nav.initial_error] start = "prior": INS errors drawn from P0's navigation block, zero estimates, P0.
        "converged" (nav/initial.py): obs, the observations at the row (`observations`, run axis first; the
        first run's schedule is flown), and states, the runs' realized sensor errors there
        (sensors/states.py), are required; all runs start with the same converged covariance."""
        n = len(rngs)
        c_true = ins.cbn_from_quaternion(truth.q_nb[row])
        s = ins.init_state(np.full(n, truth.lat_rad[row]), truth.lon_rad[row], truth.h_m[row], truth.v_ned[row],
                           c_true)
        P0 = self.initial_covariance(elevation_rad)
        if self.nav.initial_error.start == "prior":
            sd = np.sqrt(np.diag(P0)[:9])
            e = np.stack([sd * g.standard_normal(9) for g in rngs])  # INS errors after alignment + cruise
            s = ins.perturb(s, e[:, 0:3], e[:, 3:6], e[:, 6:9])
            runs = [_Run(self.filter.init(np.zeros(self.layout.n), P0), [], np.zeros(3), np.zeros(3), self._fde())
                    for _ in rngs]
            self._attach_terrain(runs, rngs)
            return s, runs
        if obs is None or states is None:
            raise ValueError("the converged start ([nav.initial_error] start = 'converged') needs the "
                             "observations and the realized sensor states at the start row "
                             "(SensorSuite.draw + sensors.states.start_states)")
        dbs = self._terrain_errors(rngs)
        states = self._with_database_states(states, dbs, truth, row)
        if obs.get("gnss_sky"):  # each run its own GPS sky: its own P0 and converged covariance, flown on the
            # schedule of the first run with that sky (the integrity bank's copies share the main filter's start)
            el0 = np.asarray(obs["gnss_el"])
            first = {}
            for i in range(n):
                first.setdefault(el0[i].tobytes(), i)
            draws = [initial.draw(self, truth, self._run_obs(obs, first[el0[i].tobytes()]), states.take(i), [g], row,
                                  self.initial_covariance(el0[i])) for i, g in enumerate(rngs)]
            e = np.concatenate([d[0] for d in draws])
            x_hat = np.concatenate([d[1] for d in draws])
            P_convs = [d[2] for d in draws]
        else:
            e, x_hat, P_conv = initial.draw(self, truth, dict(obs), states, list(rngs), row, P0)
            P_convs = [P_conv] * n
        s = ins.perturb(s, e[:, 0:3], e[:, 3:6], e[:, 6:9])
        if self.layout.has("ac"):
            s = replace(s, a_comp_mps2=e[:, self.layout.i("ac")])  # ac error = the INS compensator (truth 0)
        runs = [_Run(self.filter.init(x_hat[i], P_convs[i]), [], np.zeros(3), np.zeros(3), self._fde(), dbs[i])
                for i in range(n)]
        return s, runs

    @staticmethod
    def _run_obs(obs: Mapping[str, Any], i: int) -> dict[str, Any]:
        """The observations of run i alone (run axis of length 1; a per-run GPS sky as one shared sky)."""
        out: dict[str, Any] = dict(obs)
        for k in ("baro_h", "radalt_h", "gnss_rho", "pl_rho"):
            if k in obs:
                out[k] = np.asarray(obs[k])[i:i + 1]
        if obs.get("gnss_sky"):
            out.update(gnss_sky=False, gnss_rsv=obs["gnss_rsv"][i], gnss_sigma=obs["gnss_sigma"][i],
                       gnss_el=obs["gnss_el"][i])
        return out

    def _fde(self) -> FdeState | None:
        """A run's online FDE state ([nav.fde] enabled), else None."""
        if not self.nav.fde.enabled:
            return None
        reset = (np.concatenate([np.atleast_1d(np.arange(self.layout.n)[self.layout.index[g]]) for g in RESET_GROUPS])
                 if self.nav.feedback else None)
        return FdeState(self.nav.fde, self.nav.aiding_rate_hz, reset, self.runway.heading_rad)

    def loop_slopes(self, fs: FilterState, h_m: float, noise: em.ErrorNoise) -> vl.LoopGains | None:
        """The damping loop as the error model sees it: constant gains as they are; for the adaptive tanh /
        sinh forms the *statistical linearization* E[dk/de] of each branch over the loop error
        e ~ N(e_hat, var), e_hat = -dp_D - bb - S h from the estimate, var = its variance + the baro noise
        (5-point Gauss-Hermite). The small-signal slope alone makes the filter claim a sigma it does not have
        once |b e| ~ 1 (tanh saturates, sinh grows)."""
        g = self.loop_gains()
        if g is None or g.form == "constant":
            return g
        lay = self.layout
        row = np.zeros(lay.n)
        row[lay.i("dp", 2)] = -1.0
        row[lay.i("bb")] = -1.0
        if lay.has("sb"):
            row[lay.i("sb")] = -h_m
        P = self.filter.covariance(fs)
        e_hat = float(row @ fs.x)
        sd = float(np.sqrt(row @ P @ row + noise.baro_noise_sigma_m**2))
        z, w = np.polynomial.hermite_e.hermegauss(5)
        e = e_hat + sd * z
        w = w / w.sum()

        def slope(c: float, b: float) -> float:
            d = 1.0 / np.cosh(b * e) ** 2 if g.form == "tanh" else np.cosh(b * e)  # d/de f(b e) / b
            return float(c * b * (w @ d))

        return vl.LoopGains(slope(g.c1, g.b1_per_m), slope(g.c2, g.b2_per_m), g.c3)

    def _loop_held(self, obs: Mapping[str, Any], run: _Run, i: int) -> bool:
        """Whether run i's damping loop held its compensator over the interval ending at this epoch: the INS kernel
        had no baro over the whole interval (obs["loop_held"]: an outage, invalid samples) or the run's FDE has
        excluded the baro."""
        if not self.layout.has("ac"):
            return False
        if run.fde is not None and "baro" in run.fde.excluded:
            return True
        # what the INS kernel was given over the interval (run / the closed loop put it in obs): a baro rate
        # that does not fall on the epochs leaves obs without baro_h while the loop ran
        held = obs.get("loop_held")
        return bool(held[i]) if held is not None else False

    def loop_gains(self) -> vl.LoopGains | None:
        """The INS damping-loop gains (None without a loop)."""
        return self.nav.loop_gains()

    def aid(
        self,
        s: ins.InsState,
        runs: list[_Run],
        t: float,
        dt_epoch: float,
        f_ned_mean: Array,
        obs: Mapping[str, Any],
    ) -> ins.InsState:
        """One aiding epoch for every run: predict over dt_epoch, then each available measurement in turn.

        f_ned_mean (N, 3): mean specific force over the interval (NED, m/s^2). obs: per-run observation
        dicts made by `observations` (values with a leading run axis). Returns the INS state (changed only
        with feedback).
        """
        lay = self.layout
        sky = bool(obs.get("gnss_sky"))  # each run its own GPS sky: its own channel noise
        noise = None if sky else self.noise(obs.get("gnss_el"))
        r_ins = ins.position_ecef(s)
        for i, run in enumerate(runs):
            if sky:
                noise = self.noise(obs["gnss_el"][i])
            gains = self.loop_slopes(run.fs, float(s.h_m[i]), noise)
            F, Qc = em.dynamics(lay, float(s.lat_rad[i]), float(s.h_m[i]), s.v_ned[i], f_ned_mean[i], s.c_bn[i],
                                noise, gains, loop_held=self._loop_held(obs, run, i))
            phi, qd = em.discretize(F, Qc, dt_epoch)
            if run.fde is not None:  # predict, test, exclude, update (nav/fde.py)
                run.fs, sts = run.fde.epoch(self.filter, run.fs, phi, qd,
                                            self._measurements(s, i, r_ins[i], run.fs, obs, t,
                                                               db_error=run.db_error), t,
                                            self.runway.from_ecef(r_ins[i]))
                run.statuses.extend(sts)
                continue
            fs = self.filter.predict(run.fs, phi, qd)
            for m in self._measurements(s, i, r_ins[i], fs, obs, t, db_error=run.db_error):
                fs, st = self.filter.update(fs, m(fs.x))
                run.statuses.append(st)
            run.fs = fs
        if self.nav.feedback:
            s = self._feedback(s, runs)
        return s

    def shares_covariance(self) -> bool:
        """Whether runs on one truth can share one covariance (`run(..., shared_covariance=True)`): the optimal
        'ekf' filter, tightly coupled GPS (the loose fix's covariance depends on each run's ranges), and a baro
        loop the error model sees with constant gains (the adaptive forms linearize about each run's
        estimate). Decided from the configuration alone, so a campaign picks it once per profile."""
        g = self.loop_gains()
        return (self.nav.filter == "ekf" and self.nav.gps_coupling == "tight" and not self.nav.fde.enabled
                and (g is None or g.form == "constant"))

    def aid_shared(
        self,
        s: ins.InsState,
        runs: list[_Run],
        t: float,
        dt_epoch: float,
        ref: ins.InsState,
        f_ned_ref: Array,
        obs: Mapping[str, Any],
        cov: _SharedCov,
    ) -> ins.InsState:
        """`aid` for open-loop runs on one truth with the optimal filter: the covariance and the gains are
        propagated along the reference trajectory `ref` (the truth, one row; f_ned_ref (3,) its mean
        specific force over the interval, NED m/s^2) once per *measurement schedule* instead of once per run,
        and each run's state takes its own innovation nu_i = z_i - g(x_hat_i) (issue 5 speed notes).

        Runs whose available measurements have been the same at every epoch share one covariance; a run
        whose schedule departs (a fault, an outage, a lost channel) gets its own copy from then on. A run's
        covariance is thus a function of the truth and its own schedule only, and its numbers do not depend
        on the runs it shares a batch with. Phi and Qd are built once per epoch.
        """
        lay = self.layout
        sky = bool(obs.get("gnss_sky"))  # per-run skies: every run is its own class (run()), Qd per class
        noise = self.noise(obs["gnss_el"][0] if sky else obs.get("gnss_el"))
        # the damping loop held in a run whose INS had no baro over the interval (kernels.strapdown): its own Phi,
        # Qd. Classes are split on this epoch's schedule and the hold together (splitting only copies P), so every
        # member of a class holds or none does, and then each class is predicted with its model
        held = [self._loop_held(obs, r, i) for i, r in enumerate(runs)]
        models: dict[bool, tuple[Array, Array]] = {}
        for h in sorted(set(held)):
            F, Qc = em.dynamics(lay, float(ref.lat_rad[0]), float(ref.h_m[0]), ref.v_ned[0], f_ned_ref,
                                ref.c_bn[0], noise, self.loop_gains(), loop_held=h)
            models[h] = em.discretize(F, Qc, dt_epoch)
        # x- = Phi x+ (row by row: no batch-size-dependent BLAS path)
        X = np.stack([models[held[i]][0] @ r.fs.x for i, r in enumerate(runs)])
        cov.split(np.column_stack([self._schedule(obs, len(runs)), np.array(held, dtype=bool)]))
        for c, members in cov.classes():
            phi, qd = models[held[members[0]]]
            cov.predict_class(c, phi, self._channel_qd(qd, obs["gnss_el"][members[0]], dt_epoch) if sky else qd)
        r_ins = ins.position_ecef(s)
        r_ref = ins.position_ecef(ref)[0]
        x0 = np.zeros(lay.n)
        for c, members in cov.classes():
            i0 = members[0]
            ref_obs = self._reference_obs(obs, i0, ref, r_ref)
            rows = [b(x0) for b in self._measurements(ref, 0, r_ref, runs[i0].fs, ref_obs, t)]
            idx = np.array(members)
            c_en = geo.c_ecef_to_ned(s.lat_rad[idx], s.lon_rad[idx])
            P = cov.P[c]
            for m0 in rows:
                h0, r = m0.h, m0.r
                Ph = P @ h0
                S = float(h0 @ Ph + r)  # S = h' P h + r (shared)
                K = Ph / S  # K = P h S^-1 (shared)
                nu = self._innovations(m0.name, X[idx], idx, s, r_ins[idx], c_en, obs,
                                       db_error=[runs[i].db_error for i in members])  # z - g(x_hat_i)
                X[idx] = X[idx] + nu[:, None] * K[None, :]  # x+ = x- + K nu (row by row)
                for i, v in zip(members, nu.tolist(), strict=True):
                    runs[i].statuses.append(UpdateStatus(m0.name, t, v, S, v * v / S, 1.0, True))
                A = np.eye(lay.n) - np.outer(K, h0)
                P = A @ P @ A.T + r * np.outer(K, K)  # Joseph form
                P = 0.5 * (P + P.T)
            cov.P[c] = P
        for i, run in enumerate(runs):
            run.fs = FilterState(x=X[i], P=cov.P[cov.of_run[i]], memory=run.fs.memory)
        if self.nav.feedback:
            s = self._feedback(s, runs)
        return s

    def _channel_qd(self, qd: Array, el_rad: Array, dt_s: float) -> Array:
        """Qd with the GPS channel states' (gse, gmp: decoupled first-order Markov) entries at elevations el_rad
        (24,): sigma^2 (1 - exp(-2 dt / tau)), the closed form errormodel.discretize uses for them."""
        lay = self.layout
        if not lay.has("gse"):
            return qd
        nz = self.noise(el_rad)
        q = qd.copy()
        for grp, sig, tau in (("gse", nz.gse_sigma_m, nz.gse_tau_s), ("gmp", nz.gmp_sigma_m, nz.gmp_tau_s)):
            k = np.arange(lay.index[grp].start, lay.index[grp].stop)
            q[k, k] = np.broadcast_to(np.asarray(sig, dtype=float), k.shape) ** 2 * -np.expm1(-2.0 * dt_s / tau)
        return q

    def _innovations(self, name: str, X: Array, idx: Array, s: ins.InsState, r_ins: Array, c_en: Array,
                     obs: Mapping[str, Any], db_error: list | None = None) -> Array:
        """Innovations nu = z - g(x_hat) (m) of measurement `name` for runs idx at once, X (M, n) their
        estimates: the exact differences of nav.measurements (baro, radalt, pseudorange) evaluated at each
        run's x_hat, elementwise (a run's value does not depend on the others'). db_error: each run's
        terrain-database error (None: none)."""
        lay = self.layout
        h_ins = s.h_m[idx]
        if name == "baro":
            pred = -X[:, lay.i("dp", 2)] - X[:, lay.i("bb")]  # h' x: -dp_D - bb - h sb
            if lay.has("sb"):
                pred = pred - h_ins * X[:, lay.i("sb")]
            return (h_ins - obs["baro_h"][idx]) - pred
        dp = X[:, lay.index["dp"]]
        # corrected position r_hat = r_ins - C_ne dp_hat, written out (C_ne = C_en'): no batch-size-dependent path
        r_hat = r_ins - (c_en[:, 0, :] * dp[:, 0:1] + c_en[:, 1, :] * dp[:, 1:2] + c_en[:, 2, :] * dp[:, 2:3])
        if name == "radalt":  # (h_ins - T_db(ins) - h_R) - g(x_hat): T_db(ins) = T(ins) + e(x_ins),
            # g = (h_ins - T(ins)) - (h_ins + dp_D - T(r_hat)) - rab - ram - s tdb
            return ((h_ins + dp[:, 2]) - self.terrain_h(r_hat) - self._db_offsets(r_ins, db_error)
                    - obs["radalt_h"][idx] + self._radalt_state_terms(X, r_ins))
        if name.startswith("gps"):
            k = int(name[3:])
            d = r_hat - (obs["gnss_rsv"][idx, k] if obs.get("gnss_sky") else obs["gnss_rsv"][k])
            rng_hat = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2 + d[:, 2] ** 2)
            nu = rng_hat - obs["gnss_rho"][idx, k]  # |r_hat - r_sv| - rho + clk + gse + gmp
            if lay.has("clk"):
                nu = nu + X[:, lay.i("clk")]
            if lay.has("gse"):
                nu = nu + X[:, lay.i("gse", k)] + X[:, lay.i("gmp", k)]
            return nu
        if name.startswith("pl"):
            k = int(name[2:])
            d = r_hat - obs["pl_r"][k]
            rng_hat = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2 + d[:, 2] ** 2)
            if lay.has("ptr"):
                rng_hat = rng_hat * (1.0 + X[:, lay.i("ptr", k)])
            nu = rng_hat - obs["pl_rho"][idx, k]  # range (1 + T) - rho + clk + pmp + pclk
            if lay.has("clk"):
                nu = nu + X[:, lay.i("clk")]
            if lay.has("pmp"):
                nu = nu + X[:, lay.i("pmp", k)]
            if lay.has("pclk"):
                nu = nu + X[:, lay.i("pclk", 2 * k)]
            return nu
        raise ValueError(f"no shared-covariance innovation for measurement {name!r}")

    @staticmethod
    def _schedule(obs: Mapping[str, Any], n_runs: int) -> Array:
        """(N, k) which measurements each run has at this epoch (baro, radalt, each GPS channel, each
        pseudolite): runs with equal rows take the same scalar updates in the same order."""
        cols = [np.zeros((n_runs, 0), dtype=bool)]
        for key in ("baro_h", "radalt_h", "gnss_rho", "pl_rho"):
            if key in obs:
                cols.append(np.isfinite(np.asarray(obs[key], dtype=float)).reshape(n_runs, -1))
        return np.concatenate(cols, axis=1)

    def _reference_obs(self, obs: Mapping[str, Any], i: int, ref: ins.InsState, r_ref: Array) -> dict[str, Any]:
        """Observations of run i's schedule as seen from the reference trajectory (one row): the values that
        only decide which rows exist are kept, the radar altimeter's sigma is taken at the reference height
        above the terrain database (the measured height would make it differ by run)."""
        out: dict[str, Any] = dict(obs)
        if "baro_h" in obs:
            out["baro_h"] = np.asarray(obs["baro_h"])[i:i + 1]
        if "radalt_h" in obs:
            ok = np.isfinite(obs["radalt_h"][i])
            agl = float(ref.h_m[0] - self.terrain_h(r_ref))
            out["radalt_h"] = np.array([agl if ok else np.nan])
        if "gnss_rho" in obs:
            out["gnss_rho"] = np.asarray(obs["gnss_rho"])[i:i + 1]
        if obs.get("gnss_sky"):  # run i's own sky, as a shared one for the reference rows
            out.update(gnss_sky=False, gnss_rsv=obs["gnss_rsv"][i], gnss_sigma=obs["gnss_sigma"][i],
                       gnss_el=obs["gnss_el"][i])
        if "pl_rho" in obs:
            out["pl_rho"] = np.asarray(obs["pl_rho"])[i:i + 1]
        return out

    def _measurements(self, s: ins.InsState, i: int, r_ins: Array, fs: FilterState, obs: Mapping[str, Any],
                      t: float, db_error: tdb.TerrainDbError | None = None) -> list[Callable[[Array], Any]]:
        """Row builders for run i at this epoch (each takes the current x_hat: sequential relinearization);
        db_error: run i's terrain-database error (None: the database is the truth terrain)."""
        lay = self.layout
        lat, lon, h = float(s.lat_rad[i]), float(s.lon_rad[i]), float(s.h_m[i])
        out: list[Callable[[Array], Any]] = []
        if "baro_h" in obs and np.isfinite(obs["baro_h"][i]):
            hb, sb = float(obs["baro_h"][i]), float(obs["baro_sigma"])
            out.append(lambda x: meas.baro(lay, h, hb, sb, t))
        if "radalt_h" in obs and np.isfinite(obs["radalt_h"][i]):
            hr = float(obs["radalt_h"][i])
            sr = float(np.sqrt((self.sensors.radalt.percent_sigma * hr) ** 2 + self.sensors.radalt.floor_m**2))
            along = float(self.runway.from_ecef(r_ins)[0])
            ts = float(self.nav.terrain_database.sigma_at(along))
            de = 0.0 if db_error is None else float(db_error(along))
            out.append(lambda x: meas.radalt(lay, x, lat, lon, h, hr, sr, self.terrain_h, t, tdb_sigma_m=ts,
                                             db_error_m=de))
        c_en = geo.c_ecef_to_ned(lat, lon)
        sky = bool(obs.get("gnss_sky"))
        if "gnss_rho" in obs and self.nav.gps_coupling == "loose":
            fix = meas.gps_fix(r_ins, obs["gnss_rsv"][i] if sky else obs["gnss_rsv"], obs["gnss_rho"][i],
                               obs["gnss_sigma"][i] if sky else obs["gnss_sigma"])
            if fix is not None:
                r_fix, cov = fix
                glat, glon, gh = geo.ecef_to_geodetic(r_fix)
                dz = ins.position_error_ned(lat, lon, h, glat, glon, gh)  # INS - GPS, NED
                sd = np.sqrt(np.diag(c_en @ cov @ c_en.T))
                for m in meas.gps_position(lay, dz, sd, t):
                    out.append(lambda x, m=m: m)
        elif "gnss_rho" in obs:
            rho, r_sv = obs["gnss_rho"][i], obs["gnss_rsv"][i] if sky else obs["gnss_rsv"]
            bud = self.sensors.gnss.budget()
            sig = bud.code_noise_m if lay.has("gse") else (obs["gnss_sigma"][i] if sky else obs["gnss_sigma"])
            for k in np.flatnonzero(np.isfinite(rho)):
                sk = float(sig if np.isscalar(sig) else sig[k])
                out.append(lambda x, k=k, sk=sk, rk=float(rho[k]), rs=r_sv[k]: meas.pseudorange(
                    lay, x, r_ins, c_en, rs, rk, sk, t, f"gps{k:02d}", sv=int(k) if lay.has("gse") else None))
        if "pl_rho" in obs:
            rho, r_pl = obs["pl_rho"][i], obs["pl_r"]
            p = self.sensors.pseudolite
            for k in np.flatnonzero(np.isfinite(rho)):
                if lay.has("pmp"):
                    sk = float(np.sqrt(p.code_noise_m**2 + p.survey_sigma_m**2))
                else:
                    sk = float(obs["pl_sigma"][k])
                out.append(lambda x, k=k, sk=sk, rk=float(rho[k]), rp=r_pl[k]: meas.pseudorange(
                    lay, x, r_ins, c_en, rp, rk, sk, t, f"pl{k}", pl=int(k) if lay.has("pmp") else None))
        return out

    # --- radar altimeter and terrain database errors (rab, ram, tdb) ------------------------------------------

    def _radalt_p0(self, d: Array) -> None:
        """P0 of the radalt / database states into the diagonal d (in place): rab the altimeter and database bias
        variances summed, ram the Markov variance (stationary), tdb 1 (unit Gauss-Markov)."""
        lay = self.layout
        if lay.has("rab"):
            d[lay.i("rab")] = self.sensors.radalt.bias_sigma_m**2 + self.nav.terrain_database.bias_sigma_m**2
        if lay.has("ram"):
            d[lay.i("ram")] = self.sensors.radalt.markov_sigma_m**2
        if lay.has("tdb"):
            d[lay.i("tdb")] = 1.0

    def _attach_terrain(self, runs: list[_Run], rngs: list[np.random.Generator]) -> None:
        """Each run's terrain database = the truth terrain + its own error realization e(x), drawn from the child
        stream "terrain_db" of its nav stream (the nav stream's own draws are untouched). No radar altimeter or a
        zero error model: no error. The filter looks its database up at the INS position: e enters the radalt
        difference as e(x_ins), carried by the rab / tdb states (its own along-track gradient, not differentiable
        for a Gauss-Markov field, is not linearized: the INS's slowly varying along-track error only shifts where
        the field is sampled, which leaves u(x_ins(t)) a Gauss-Markov of the same time constant)."""
        for r, e in zip(runs, self._terrain_errors(rngs), strict=True):
            r.db_error = e

    def _terrain_errors(self, rngs: list[np.random.Generator]) -> list[tdb.TerrainDbError | None]:
        """Each run's terrain-database error realization (`_attach_terrain`); None entries without one."""
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

    def _tdb_sigma(self, r_ecef: Array) -> Array:
        """The database's correlated 1-sigma (m) at ECEF points (..., 3): the H coefficient of the tdb state."""
        return self.nav.terrain_database.sigma_at(self._along_m(r_ecef))

    def _along_m(self, r_ecef: Array) -> Array:
        """Runway-frame along-track distance (m) of ECEF points (..., 3), one point at a time: a run's value must
        not depend on the batch it shares (no batch-size-dependent matrix product)."""
        r = np.asarray(r_ecef, dtype=float)
        flat = [float(self.runway.from_ecef(ri)[0]) for ri in r.reshape(-1, 3)]
        return np.array(flat).reshape(r.shape[:-1])

    def _db_offsets(self, r_ins: Array, db_error: list | None) -> Array:
        """Each run's terrain-database error (M,) at its INS position r_ins (M, 3), m (0 without one)."""
        if db_error is None or all(e is None for e in db_error):
            return np.zeros(r_ins.shape[0])
        x = self._along_m(r_ins)
        return np.array([0.0 if e is None else float(e(xi)) for e, xi in zip(db_error, x, strict=True)])

    def _radalt_state_terms(self, X: Array, r_ins: Array) -> Array:
        """rab + ram + sigma_db(x) tdb (M,) of estimates X (M, n): what the radalt innovation adds back."""
        lay = self.layout
        out = np.zeros(X.shape[0])
        if lay.has("rab"):
            out = out + X[:, lay.i("rab")]
        if lay.has("ram"):
            out = out + X[:, lay.i("ram")]
        if lay.has("tdb"):
            out = out + self._tdb_sigma(r_ins) * X[:, lay.i("tdb")]
        return out

    def _feedback(self, s: ins.InsState, runs: list[_Run]) -> ins.InsState:
        """Closed-loop correction: INS -= estimated nav error; bias estimates go to the increments; reset."""
        lay = self.layout
        x = np.stack([r.fs.x for r in runs])
        s = ins.perturb(s, -x[:, 0:3], -x[:, 3:6], -x[:, 6:9])
        for i, r in enumerate(runs):
            r.bg_fb = r.bg_fb + x[i, lay.index["bg"]]
            r.ba_fb = r.ba_fb + x[i, lay.index["ba"]]
            xn = x[i].copy()
            for g in ("dp", "dv", "psi", "bg", "ba"):
                xn[lay.index[g]] = 0.0
            r.fs = replace(r.fs, x=xn)
        return s

    def output(self, s: ins.InsState, runs: list[_Run]) -> tuple[ins.InsState, Array, Array]:
        """Corrected solution (feed-forward: INS - x_hat) and each run's P (n, n) and x_hat (N, n)."""
        x = np.stack([r.fs.x for r in runs])
        P = np.stack([self.filter.covariance(r.fs) for r in runs])
        return ins.perturb(s, -x[:, 0:3], -x[:, 3:6], -x[:, 6:9]), P, x

    # --- over whole records ----------------------------------------------------------------------------------

    @staticmethod
    def observations(records: Mapping[str, Any], t: float, tol: float, batched: bool) -> dict[str, Any]:
        """The measurements available at time t from full records (values with a leading run axis)."""
        obs: dict[str, Any] = {}

        def per_run(a: Array) -> Array:
            return a if batched else a[None]

        b = records.get("baro")
        if b is not None and (j := _epoch_index(b.t_s, t, tol)) is not None:
            h = per_run(b.h_baro_m)[:, j]
            obs["baro_h"] = np.where(per_run(b.valid)[:, j], h, np.nan)
            obs["baro_sigma"] = float(b.sigma_m[j])
        r = records.get("radalt")
        if r is not None and (j := _epoch_index(r.t_s, t, tol)) is not None:
            obs["radalt_h"] = np.where(per_run(r.valid)[:, j], per_run(r.h_agl_m)[:, j], np.nan)
        g = records.get("gnss")
        if g is not None and (j := _epoch_index(g.t_s, t, tol)) is not None:
            obs["gnss_rho"] = np.where(per_run(g.valid)[:, j], per_run(g.pseudorange_m)[:, j], np.nan)
            sky = batched and g.per_run_sky  # each run its own constellation epoch: (N, ...) geometry
            obs["gnss_rsv"] = g.r_sv_ecef[:, j] if sky else g.r_sv_ecef[j]
            obs["gnss_sigma"] = g.sigma_m[:, j] if sky else g.sigma_m[j]
            obs["gnss_el"] = g.elevation_rad[:, j] if sky else g.elevation_rad[j]
            obs["gnss_sky"] = sky
        p = records.get("pseudolite")
        if p is not None and (j := _epoch_index(p.t_s, t, tol)) is not None:
            obs["pl_rho"] = np.where(per_run(p.valid)[:, j], per_run(p.pseudorange_m)[:, j], np.nan)
            obs["pl_r"] = p.r_pl_ecef
            obs["pl_sigma"] = p.sigma_m[j]
        return obs

    def run(self, truth: Truth, records: Mapping[str, Any], rngs: np.random.Generator | list[np.random.Generator],
            *, shared_covariance: bool = False, states: SensorStates | None = None) -> NavRun | list[NavRun]:
        """Navigate over whole records (open loop: the truth is only read at row 0 and for the error history).

        records: {"imu": ImuSamples, "baro": ..., ...} of one run (rngs a Generator) or of len(rngs) runs
        (run axis first, rngs a list). Returns one NavRun, or a list. shared_covariance (several runs, optimal
        'ekf' only): one covariance and gain for all runs at each epoch (`aid_shared`), several times faster;
        epochs where the runs' measurement sets differ fall back to per-run filtering. states: the runs'
        realized sensor errors at truth row 0 (sensors.states.start_states), needed by the converged start.
        """
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
        rate = 1.0 / dt
        epoch_rows = max(1, int(round(rate / self.nav.aiding_rate_hz)))
        gnss = records.get("gnss")
        sky = gnss is not None and batched and gnss.per_run_sky
        obs0 = self.observations(records, float(truth.t_s[0]), 0.25 * dt, batched)
        s, runs = self.start(truth, gens, elevation_rad=None if gnss is None else
                             (gnss.elevation_rad[0, 0] if sky else gnss.elevation_rad[0]), obs=obs0, states=states)
        n_runs = len(gens)
        if sky and self.nav.initial_error.start == "prior":  # each run's P0 at its own sky (start() did the
            for i, r in enumerate(runs):  # converged start per sky; the prior's INS errors do not depend on it)
                r.fs = self.filter.init(np.zeros(self.layout.n), self.initial_covariance(gnss.elevation_rad[i, 0]))
        cov = None
        if shared_covariance:  # the reference trajectory (truth) and its specific force in NED, per row
            # per-run skies: one class per run from the start (a covariance is shared only within one sky)
            cov = (_SharedCov([r.fs.P for r in runs], np.arange(n_runs)) if sky
                   else _SharedCov([runs[0].fs.P], np.zeros(n_runs, dtype=int)))
            f_ned_ref = np.einsum("nij,nj->ni", ins.cbn_from_quaternion(truth.q_nb[:m]), truth.f_body[:m])
        gains = self.loop_gains()
        baro = records.get("baro")
        hb_full = None
        if gains is not None and baro is not None:
            # an invalid sample (outage, a lost sensor) is no baro: nan, and the loop holds (kernels.strapdown)
            hb = np.where(baro.valid, baro.h_baro_m, np.nan)
            hb = hb if batched else hb[None]
            # zero-order hold of the latest baro sample at each IMU interval start (truth rows 0 .. m-1)
            idx = np.clip(np.searchsorted(baro.t_s, truth.t_s[:m] + 1e-9, side="right") - 1, 0, None)
            hb_full = hb[:, idx]
        n_out = m + 1
        # raw INS rows (packed, ins.pack) and, per row, the filter snapshot in force; corrected (INS - x_hat)
        # after the pass
        rows = np.empty((n_runs, n_out, ins.sk.NX))
        snap = np.zeros(n_out, dtype=int)
        snaps: list[tuple[Array, Array]] = []
        t_ep, xs, pds, pnav, terr = [], [], [], [], []
        lay = self.layout
        has_clk = lay.has("clk")
        ic = lay.i("clk") if has_clk else 0

        def snapshot() -> None:  # x, the position block of P and the clock variance: what the output needs
            P = np.stack([self.filter.covariance(r.fs) for r in runs])
            snaps.append((np.stack([r.fs.x for r in runs]), P[:, 0:3, 0:3].copy(), P[:, ic, ic].copy()))

        snapshot()
        xk = ins.pack(s)
        rows[:, 0] = xk
        f_sum = np.zeros((n_runs, 3))
        t_last = float(truth.t_s[0])
        zeros3 = np.zeros((n_runs, 3))
        # the compiled INS steps every run over the rows between two epochs in one call; a run's numbers do not
        # depend on the batch it shares (the campaign relies on it: kernels/strapdown.py)
        j0 = 0
        while j0 < m:
            j1 = min(m, (j0 // epoch_rows + 1) * epoch_rows)  # rows j0 + 1 .. j1; j1 an epoch unless the end
            bg = np.stack([r.bg_fb for r in runs]) if self.nav.feedback else zeros3
            ba = np.stack([r.ba_fb for r in runs]) if self.nav.feedback else zeros3
            ins.propagate(xk, dth[:, j0:j1], dvb[:, j0:j1], dt, bias_g=bg, bias_a=ba,
                          h_baro_m=None if hb_full is None else hb_full[:, j0:j1], loop=gains, f_sum=f_sum,
                          out=rows, row0=j0)
            snap[j0 + 1:j1 + 1] = len(snaps) - 1
            row = j1
            if row % epoch_rows == 0:
                t = float(truth.t_s[row])
                s = ins.unpack(xk)
                obs = self.observations(records, t, 0.25 * dt, batched)
                if hb_full is not None:  # the loop held where the kernel had no baro over the whole interval
                    obs["loop_held"] = np.all(np.isnan(hb_full[:, j0:j1]), axis=1)
                if cov is not None:  # the per-run filters linearize about each run's INS (shared: the truth)
                    ref = ins.InsState(truth.lat_rad[row:row + 1], truth.lon_rad[row:row + 1],
                                       truth.h_m[row:row + 1], truth.v_ned[row:row + 1],
                                       ins.cbn_from_quaternion(truth.q_nb[row:row + 1]), np.zeros(1))
                    f_ref = f_ned_ref[row - epoch_rows:row].mean(axis=0)
                    s = self.aid_shared(s, runs, t, t - t_last, ref, f_ref, obs, cov)
                else:
                    s = self.aid(s, runs, t, t - t_last, f_sum / (t - t_last), obs)
                f_sum[:] = 0.0
                t_last = t
                if hb_full is not None:  # a baro excluded by FDE no longer drives that run's damping loop
                    for i, r in enumerate(runs):
                        if r.fde is not None and "baro" in r.fde.excluded:
                            hb_full[i, row:] = np.nan
                snapshot()
                o, P, x = self.output(s, runs)
                t_ep.append(t)
                xs.append(x)
                pds.append(np.diagonal(P, axis1=1, axis2=2))
                pnav.append(P[:, 0:9, 0:9])
                terr.append(self._true_error(o, truth, row))
                xk = ins.pack(s)  # feedback may have corrected it
                rows[:, row] = xk
                snap[row] = len(snaps) - 1
            j0 = j1
        X = np.stack([x for x, _, _ in snaps])[snap]  # (n_out, runs, n)
        PP = np.stack([p for _, p, _ in snaps])  # (snaps, runs, 3, 3)
        PC = np.stack([c for _, _, c in snaps])  # (snaps, runs)
        results = []
        for i, r in enumerate(runs):
            xi = X[:, i]
            o = ins.perturb(ins.unpack(rows[i]), -xi[:, 0:3], -xi[:, 3:6], -xi[:, 6:9])
            p_pos = PP[:, i][snap]  # the small blocks only: (rows, n, n) would be GBs at 120 Hz
            clk_sd = np.sqrt(PC[:, i][snap]) if has_clk else np.full(n_out, np.nan)
            sol = NavSolution(
                t_s=np.asarray(truth.t_s[:n_out], dtype=float),
                r_ecef=geo.geodetic_to_ecef(o.lat_rad, o.lon_rad, o.h_m),
                v_ned=o.v_ned,
                euler_rad=ins.euler_from_cbn(o.c_bn),
                P_pos_ned=p_pos,
                clock_bias_m=xi[:, ic] if has_clk else np.full(n_out, np.nan),
                clock_bias_sigma_m=clk_sd,
                **(r.fde.solution_fields(snap) if r.fde is not None else {}),
            )
            results.append(NavRun(
                solution=sol, status=StatusLog.from_records(r.statuses), t_epoch_s=np.array(t_ep),
                x=np.array([x[i] for x in xs]), P_diag=np.array([p[i] for p in pds]),
                P_nav=np.array([p[i] for p in pnav]), true_error_nav=np.array([e[i] for e in terr]),
                layout=lay,
            ))
        return results if batched else results[0]

    @staticmethod
    def _true_error(o: ins.InsState, truth: Truth, row: int) -> Array:
        """(N, 9) output error (dp NED, dv, psi) against truth row `row`."""
        dp = ins.position_error_ned(o.lat_rad, o.lon_rad, o.h_m, truth.lat_rad[row], truth.lon_rad[row],
                                    truth.h_m[row])
        dv = o.v_ned - truth.v_ned[row]
        psi = ins.attitude_error(o.c_bn, ins.cbn_from_quaternion(truth.q_nb[row]))
        return np.concatenate([dp, dv, psi], axis=-1)
