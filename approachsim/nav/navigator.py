"""The navigation step object: one pass of the navigation system over N runs, used by both the open-loop pass
over whole records (NavSystem.run) and the closed loop (closed_loop.NavInTheLoop).

    nav = Navigator(system, s0, runs, t0_s, n_rows)   # INS states (N runs) + each run's filter, from NavSystem.start
    nav.propagate(dtheta, dv, dt_s, h_baro, row0)     # the compiled INS over rows row0+1 .. row0+m (open loop)
    nav.x, nav.record_row(k)                          # or: the caller steps nav.x (packed INS) itself (closed loop)
    nav.epoch(row, t_s, obs, truth)                   # the filter at an aiding epoch (predict + updates)
    runs = nav.results(truth)                         # NavRun per run: solution at every row, status log, history

At an epoch every run's filter predicts with the discretized error model (errormodel.dynamics + discretize,
linearized about the run's INS solution) and takes its available scalar rows in turn (nav/rows.py), each giving an
UpdateStatus; with the online FDE ([nav.fde]) the run's FdeState runs the epoch (nav/fde.py). With `shared` (open
loop on one truth, optimal filter) the covariance and gains are propagated along the truth once per measurement
schedule instead (nav/shared.py). Output (seed 002 feed-forward) = INS - estimated error; with feedback the
estimate is fed back into the INS (and the IMU bias estimates into the increments) and those states reset.

The record kept for the output is light: the raw INS state at every row, and per filter snapshot the estimate,
the 3x3 position block of P and the clock variance (a full (rows, n, n) P at 120 Hz would be gigabytes).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.core.nav import epoch as ke
from approachsim.core.nav import errormodel as kem
from approachsim.core.nav import groups as kg
from approachsim.core.nav import output as ko
from approachsim.memo import TruthMemo
from approachsim.nav import errormodel as em
from approachsim.nav import ins, reduced
from approachsim.nav import terrain_db as tdb
from approachsim.nav.base import FilterState, UpdateStatus
from approachsim.nav.engine import EpochEngine, RunDatabase, StatusBuffer, new_arcs, reset_arcs, stacked_new_arcs
from approachsim.nav.fde import FdeState
from approachsim.nav.gbas_scale import GbasScale
from approachsim.nav.observations import BARO, Observations
from approachsim.records import NavSolution, Truth

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
    def from_buffer(cls, buf: StatusBuffer) -> StatusLog:
        """Arrays from a run's StatusBuffer (nav/engine.py)."""
        return cls(**buf.arrays())

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

    solution: NavSolution | None
    """The solution at every row (None: not assembled, NavSystem.run(..., copies=True)'s sub-filters)."""
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
class RunFilter:
    """One run's filter bookkeeping inside a pass (mutable; never leaves the navigation package)."""

    fs: FilterState
    statuses: StatusBuffer
    """Every scalar measurement's status record (a list given here becomes a StatusBuffer)."""
    bg_fb: Array
    ba_fb: Array
    fde: FdeState | None = None
    """Online fault detection and exclusion ([nav.fde] enabled), else None."""
    db_error: tdb.TerrainDbError | None = None
    """This run's terrain-database error (None: the database is the truth terrain)."""
    arcs: Array | None = None
    """(k,) int: the carrier arc id of each GPS channel at the last epoch that had its carrier (-1: none yet;
    carrier phase only)."""

    def __post_init__(self) -> None:
        if not isinstance(self.statuses, StatusBuffer):
            self.statuses = StatusBuffer(self.statuses)

    def baro_excluded(self) -> bool:
        """The online FDE has excluded the baro."""
        return self.fde is not None and BARO in self.fde.excluded


def _valid_channels(records: Any, n_runs: int) -> Array | None:
    """(N, k) whether each run's GNSS record has a valid sample of each channel (what the integrity bank takes as
    the channels it measures), or None when the record has no run axis of n_runs."""
    g = records.get("gnss")
    valid = None if g is None else np.asarray(g.valid, dtype=bool)
    if valid is None or valid.ndim != 3 or valid.shape[0] != n_runs:
        return None
    return np.any(valid, axis=1)


def true_error_rows(o: ins.InsState, truth: Truth, rows: Array) -> Array:
    """(E, 9) output errors (dp NED, dv, psi) of states o (E,) against truth rows `rows` (E,)."""
    dp = ins.position_error_ned(o.lat_rad, o.lon_rad, o.h_m, truth.lat_rad[rows], truth.lon_rad[rows],
                                truth.h_m[rows])
    dv = o.v_ned - truth.v_ned[rows]
    psi = ins.attitude_error(o.c_bn, ins.cbn_from_quaternion(truth.q_nb[rows]))
    return np.concatenate([dp, dv, psi], axis=-1)


def true_error(o: ins.InsState, truth: Truth, row: int) -> Array:
    """(N, 9) output error (dp NED, dv, psi) against truth row `row`."""
    dp = ins.position_error_ned(o.lat_rad, o.lon_rad, o.h_m, truth.lat_rad[row], truth.lon_rad[row],
                                truth.h_m[row])
    dv = o.v_ned - truth.v_ned[row]
    psi = ins.attitude_error(o.c_bn, ins.cbn_from_quaternion(truth.q_nb[row]))
    return np.concatenate([dp, dv, psi], axis=-1)


def loop_held(layout: em.StateLayout, run: RunFilter, obs: Observations, i: int) -> bool:
    """Whether run i's damping loop held its compensator over the interval ending at this epoch: the INS kernel
    had no baro over the whole interval (obs.loop_held: an outage, invalid samples) or the run's FDE has
    excluded the baro."""
    if not layout.has("ac"):
        return False
    if run.baro_excluded():
        return True
    # what the INS kernel was given over the interval (run / the closed loop put it in obs): a baro rate
    # that does not fall on the epochs leaves obs without a baro value while the loop ran
    return bool(obs.loop_held[i]) if obs.loop_held is not None else False


class Navigator:
    """One pass of the navigation system over N runs (module docstring)."""

    def __init__(self, system: Any, s0: ins.InsState, runs: list[RunFilter], t0_s: float, n_rows: int,
                 *, shared: Any = None, ins_of: Array | None = None, rows: Array | None = None) -> None:
        self.system = system
        self.layout: em.StateLayout = system.layout
        self.runs = runs
        self.shared = shared
        """nav/shared.py SharedCovariance, or None (per-run filters)."""
        self.x = ins.pack(s0)
        """(M, 16) the packed INS states (kernels/strapdown.py), stepped by `propagate` or by the caller."""
        n = self.x.shape[0]
        self.ins_of = np.arange(len(runs)) if ins_of is None else np.asarray(ins_of, dtype=int)
        """(N,) the INS each run's filter aids: the identity, or copies of one run sharing one INS (the integrity
        bank's sub-filters, feed-forward: their INS is the same, only the filters differ)."""
        if self.ins_of.shape != (len(runs),) or self.ins_of.max(initial=0) >= n:
            raise ValueError("Navigator: ins_of must map each run to one of the INS states")
        if n != len(runs) and system.nav.feedback:
            raise ValueError("Navigator: runs share an INS only feed-forward (feedback corrects each run's INS)")
        self.rows = np.full((n, n_rows, ins.NX), np.nan) if rows is None else rows
        """(M, n_rows, 16) the INS state at every row (nan until stepped); `rows` given: the caller's array of that
        shape, nan-filled (the closed loop's, which its compiled row steps: no copy at `bind`)."""
        if self.rows.shape != (n, n_rows, ins.NX):
            raise ValueError(f"Navigator: rows must be {(n, n_rows, ins.NX)}; got {self.rows.shape}")
        self.rows[:, 0] = self.x
        self.snap = np.zeros(n_rows, dtype=int)
        self._snaps: list[tuple[Array, Array, Array]] = []
        self._rates: list[Array] = []
        """Per snapshot: each run's estimate rate (N, 9) (core/nav/output.nav_rate; zeros at the start)."""
        self._t_snap: list[float] = []
        """Per snapshot: its time (s), the t_est of core/nav/output.estimate_at."""
        self.interval_F: list[Array | None] = [None] * len(runs)
        """Each run's error model F (n, n) of the interval that ended at this epoch (set by the aiding paths)."""
        self.f_sum = np.zeros((n, 3))
        """C_bn dv accumulated since the last epoch (NED, m/s): the mean specific force of the interval."""
        self.t_last = float(t0_s)
        self._ic = self.layout.i("clk") if self.layout.has("clk") else 0
        self.engine = EpochEngine.of(system)
        self.gbas_scale = GbasScale.of(system)
        """GBAS code ranging: the channel states' scale along the approach (nav/gbas_scale.py), else None."""
        self.reduced_runs: list | None = None
        """compiled_pass on each run's reduced state: each run's nav/reduced.ReducedRun (else None)."""
        """The compiled epoch (nav/engine.py), or None: the generic path."""
        self.dbs = ([RunDatabase.of(system.nav.terrain_database, r.db_error) for r in runs]
                    if self.engine is not None else None)
        self.db_stack = EpochEngine.stack(self.dbs) if self.engine is not None else None
        self._hist: dict[str, list] = {"t": [], "row": [], "snap": [], "pd": [], "pnav": []}
        """Per epoch: time, truth row, snapshot index, each run's P diagonal (N, n) and navigation block
        (N, 9, 9); the outputs' errors are made from the rows and snapshots in `results`."""
        self._snapshot()

    @property
    def n_runs(self) -> int:
        return len(self.runs)

    @property
    def snap_index(self) -> int:
        """Index of the filter snapshot in force (what `snap` records for a row stepped now)."""
        return len(self._snaps) - 1

    def bind(self, x: Array, f_sum: Array, rows: Array, snap: Array) -> None:
        """Keep the INS state (M, 16), the specific-force sum (M, 3), the rows (M, n_rows, 16) and the snapshot
        index per row (n_rows,) in the caller's arrays from now on (their current values copied in): the closed
        loop's compiled row (core/loop/nav_row.py) steps them in place."""
        x[...] = self.x
        f_sum[...] = self.f_sum
        if rows is not self.rows:  # (the Navigator made with the caller's rows: nothing to copy)
            rows[...] = self.rows
        snap[...] = self.snap
        self.x, self.f_sum, self.rows, self.snap = x, f_sum, rows, snap

    @property
    def x_nav(self) -> Array:
        """(N, 9) the estimated navigation errors in force (dp NED m, dv m/s, psi rad)."""
        return np.stack([r.fs.x[0:9] for r in self.runs])

    # --- the INS between epochs -----------------------------------------------------------------------------

    def bias_feedback(self) -> tuple[Array, Array]:
        """(M, 3) gyro and accelerometer bias estimates fed back into the increments (zeros feed-forward)."""
        if not self.system.nav.feedback:
            z = np.zeros((self.x.shape[0], 3))
            return z, z
        return np.stack([r.bg_fb for r in self.runs]), np.stack([r.ba_fb for r in self.runs])

    def propagate(self, dtheta: Array, dv: Array, dt_s: float, h_baro: Array | None, row0: int,
                  baro_age_s: Array | None = None) -> None:
        """Step every INS over the m IMU intervals of dtheta, dv (M, m, 3) from row row0 (the compiled
        mechanization: all over all rows in one call), recording rows row0 + 1 .. row0 + m; h_baro (M, m) the baro
        held at each interval start (with the damping loop), baro_age_s (m,) its age there (s; ins.held_baro)."""
        m = dtheta.shape[1]
        bg, ba = self.bias_feedback()
        ins.propagate(self.x, dtheta, dv, dt_s, bias_g=bg, bias_a=ba, h_baro_m=h_baro, baro_age_s=baro_age_s,
                      loop=self.system.loop_gains(), f_sum=self.f_sum, out=self.rows, row0=row0)
        self.snap[row0 + 1:row0 + m + 1] = len(self._snaps) - 1

    def record_row(self, k: int) -> None:
        """Keep the current INS state as row k (closed loop: the caller stepped `x` into row k)."""
        self.rows[:, k] = self.x
        self.snap[k] = len(self._snaps) - 1

    # --- the filter at an epoch --------------------------------------------------------------------------------

    def epoch(self, row: int, t_s: float, obs: Observations, truth: Truth) -> None:
        """The aiding epoch at truth row `row` (time t_s): predict over the interval since the last epoch and
        update every run with obs; feedback corrects `x`. The truth is read at `row` only: as the reference
        trajectory of the shared covariance, and for the error history."""
        s = ins.unpack(self.x[self.ins_of])  # each run's INS state
        dt = t_s - self.t_last
        if self.shared is not None:
            s = self.shared.aid(self, s, t_s, dt, row, obs, truth)
        else:
            s = self._aid(s, t_s, dt, (self.f_sum / dt)[self.ins_of], obs)
        if self.system.nav.feedback:
            s = self._feedback(s)
            self.x[:] = ins.pack(s)
        self.f_sum[:] = 0.0
        self.t_last = t_s
        self._snapshot(epoch=True)
        self.record_row(row)
        h = self._hist
        h["t"].append(t_s)
        h["row"].append(row)
        h["snap"].append(len(self._snaps) - 1)

    def epoch_done(self, row: int, t_s: float, x: Array, p_pos: Array, p_clk: Array, p_diag: Array,
                   p_nav: Array, x_rate: Array) -> None:
        """What `epoch` keeps after an epoch its caller ran itself (the closed loop's compiled epoch,
        core/loop/aiding.py, which has reset f_sum): the snapshot x (N, n), P's position block
        (N, 3, 3), clock variance (N,), diagonal (N, n) and navigation block (N, 9, 9), the estimate's rate (N, 9),
        and the epoch's history entry (the caller records row `row` itself)."""
        self.t_last = t_s
        self._snaps.append((x, p_pos, p_clk))
        self._rates.append(x_rate)
        self._t_snap.append(t_s)
        h = self._hist
        h["pd"].append(p_diag)
        h["pnav"].append(p_nav)
        h["t"].append(t_s)
        h["row"].append(row)
        h["snap"].append(len(self._snaps) - 1)

    def rate_in_force(self) -> tuple[Array, float]:
        """(N, 9) the rate of each run's estimate in force and its time (s): core/nav/output.estimate_at's xd, t_est."""
        return self._rates[-1], self._t_snap[-1]

    def loop_held(self, obs: Observations, i: int) -> bool:
        """Whether run i's damping loop held over the interval ending at this epoch (`loop_held`)."""
        return loop_held(self.layout, self.runs[i], obs, i)

    def _aid(self, s: ins.InsState, t: float, dt_epoch: float, f_ned_mean: Array, obs: Observations
             ) -> ins.InsState:
        """Per-run filters: each run linearized about its own INS solution (f_ned_mean (N, 3): the mean specific
        force over the interval, NED m/s^2)."""
        system = self.system
        lay = self.layout
        filt = system.filter
        r_ins = None
        for i, run in enumerate(self.runs):
            held = self.loop_held(obs, i)
            new = self._arc_flags(run, obs, i)
            if self.engine is not None and run.fde is None:  # the whole epoch compiled (nav/engine.py)
                X, P = run.fs.x.copy()[None], np.array(run.fs.P, dtype=float)
                y = self.x[self.ins_of[i]]
                if self.engine.own(X, P, y, np.ascontiguousarray(f_ned_mean[i]), obs.elevations(i), held,
                                   dt_epoch, obs, i, t, run.statuses, self.dbs[i], new):
                    run.fs = FilterState(x=X[0], P=P, memory=run.fs.memory)
                    self.interval_F[i] = self.engine.F.copy()  # the kernel's scratch: the next run overwrites it
                    continue
            if r_ins is None:
                r_ins = ins.position_ecef(s)
            noise = system.noise(obs.elevations(i))
            h_lin = em.linear_height(lay, float(s.h_m[i]), run.fs.x, float(s.v_ned[i, 2]), dt_epoch)
            if lay.has("sb") and lay.has("ac"):  # dp_D_hat at the interval's end by the model's rate (run_epoch's)
                F0, _ = em.dynamics(lay, float(s.lat_rad[i]), h_lin, s.v_ned[i], f_ned_mean[i], s.c_bn[i], noise,
                                    system.loop_slopes(run.fs, h_lin, noise), loop_held=held)
                h_lin = em.linear_height(lay, float(s.h_m[i]), run.fs.x, float(s.v_ned[i, 2]), dt_epoch, F0)
            gains, pull = system.loop_linearization(run.fs, h_lin, noise)
            F, Qc = em.dynamics(lay, float(s.lat_rad[i]), h_lin, s.v_ned[i],
                                f_ned_mean[i], s.c_bn[i], noise, gains, loop_held=held)
            self.interval_F[i] = F
            # the covariance by the EKF's Jacobian, the estimate by its own model F (core/nav/errormodel.loop_jacobian)
            F_jac = em.loop_jacobian(lay, F, gains, held, float(run.fs.x[lay.i("sb")]) if lay.has("sb") else 0.0)
            phi, qd = em.discretize(F if F_jac is None else F_jac, Qc, dt_epoch)
            if self.gbas_scale is not None and obs.has_gnss:  # the channel states at the INS's geometry
                phi, qd = self.gbas_scale.apply(phi, qd, obs.elevations(i), self.x[self.ins_of[i]], dt_epoch, noise)
            if new is not None:
                phi, qd = reset_arcs(lay, phi, qd, new, self._amb_prior())
            pull = None if held else pull
            mean = None if F_jac is None and pull is None else em.MeanModel(F, dt_epoch, pull)
            if self.engine is not None and run.fde is None:  # the compiled updates on the numpy discretization
                X, P = run.fs.x.copy()[None], np.array(run.fs.P, dtype=float)
                if mean is not None:
                    X[0] = mean.predict(phi, X[0])
                y = self.x[self.ins_of[i]:self.ins_of[i] + 1]
                self.engine.epoch(X, P, phi, qd, True, y[0], y, obs, [i], t, [run.statuses], [self.dbs[i]],
                                  x_ready=mean is not None)
                run.fs = FilterState(x=X[0], P=P, memory=run.fs.memory)
                continue
            rows = system.rows.epoch(s, i, r_ins[i], obs, t, db_error=run.db_error)
            if run.fde is not None:  # predict, test, exclude, update (nav/fde.py)
                run.fs, sts = run.fde.epoch(filt, run.fs, phi, qd, rows, t, system.runway.from_ecef(r_ins[i]),
                                            mean=mean)
                run.statuses.extend(sts)
                continue
            fs = em.MeanModel.predict_state(filt, run.fs, phi, qd, mean)
            for row in rows:
                fs, st = filt.update(fs, row.build(fs.x))
                run.statuses.append(st)
            run.fs = fs
        return s

    def _new_arcs(self, run: RunFilter, arc: Array, phi: Array, qd: Array) -> tuple[Array, Array]:
        """The epoch's Phi, Qd with the float ambiguity of every GPS channel whose carrier arc id changed (a new arc:
        a new ambiguity) reset to its prior: row and column of Phi zeroed (estimate 0, no correlation kept) and
        the prior variance put in Qd, so P- = Phi P+ Phi' + Qd holds the prior there. A reset as part of the
        prediction: every filter form and the FDE's stored epochs (re-run after a rollback) take it as it is."""
        new, run.arcs = new_arcs(run.arcs, arc)
        return reset_arcs(self.layout, phi, qd, new, self._amb_prior())

    def _amb_prior(self) -> float:
        """A float ambiguity's prior variance at a new arc, m^2 (nav/noise.py's P0 of amb)."""
        return self.system.sensors.gnss.carrier.ambiguity_sigma_m ** 2

    def _arc_flags(self, run: RunFilter, obs: Observations, i: int) -> Array | None:
        """Run i's channels whose carrier arc begins at this epoch ((k,) bool, engine.new_arcs; the run's arc ids
        updated), or None (no carrier phase, or no GNSS sample at the epoch)."""
        if not self.layout.has("amb") or obs.gnss_arc is None:
            return None
        new, run.arcs = new_arcs(run.arcs, obs.gnss_arc[i])
        return new

    def with_resets(self, phi: Array, qd: Array, new: Array) -> tuple[Array, Array]:
        """Phi, Qd with the ambiguities of the channels of new (k,) bool reset (engine.reset_arcs; phi, qd
        themselves when none is new)."""
        if not np.any(new):
            return phi, qd
        return reset_arcs(self.layout, phi, qd, new, self._amb_prior())

    def arc_resets(self, obs: Observations) -> Array:
        """(N, k) bool: every run's channels whose carrier arc begins at this epoch (`_arc_flags`; (N, 0) without
        carrier phase or a GNSS sample): the shared covariance splits its classes on it and resets the ambiguities."""
        flags = [self._arc_flags(r, obs, i) for i, r in enumerate(self.runs)]
        if any(f is None for f in flags):
            return np.zeros((len(self.runs), 0), dtype=bool)
        return np.array(flags, dtype=bool).reshape(len(self.runs), -1)

    def _feedback(self, s: ins.InsState) -> ins.InsState:
        """Closed-loop correction: INS -= estimated nav error; bias estimates go to the increments; reset."""
        lay = self.layout
        x = np.stack([r.fs.x for r in self.runs])
        s = ins.perturb(s, -x[:, 0:3], -x[:, 3:6], -x[:, 6:9])
        for i, r in enumerate(self.runs):
            r.bg_fb = r.bg_fb + x[i, lay.index["bg"]]
            r.ba_fb = r.ba_fb + x[i, lay.index["ba"]]
            xn = x[i].copy()
            for g in ("dp", "dv", "psi", "bg", "ba"):
                xn[lay.index[g]] = 0.0
            r.fs = replace(r.fs, x=xn)
        return s

    # --- the whole open-loop pass compiled (shared covariance, every run its own class) -------------------------

    def can_pass(self) -> bool:
        """Whether `compiled_pass` can run this pass: the compiled epoch, the shared covariance with per-run skies
        (every run its own class from the start, whatever the batch: a run's bits do not depend on it; the integrity
        bank's copies of a run with its own sky), feed-forward (the INS does not depend on the filter)."""
        return (self.engine is not None and self.shared is not None and self.shared.per_run_sky
                and self.shared.singletons and not self.system.nav.feedback)

    def compiled_pass(self, records: Any, truth: Truth, batched: bool, dtheta: Array, dv: Array, dt_s: float,
                      h_baro: Array | None, epoch_rows: int, baro_age_s: Array | None = None,
                      memo: TruthMemo | None = None) -> bool:
        """The whole open-loop pass in two compiled calls (`can_pass`): the INS over every row, then every epoch of
        every run (core/nav/epoch.shared_pass: the per-epoch path's arithmetic, nav/shared.py's singletons). Fills
        the state `results` reads. False, with nothing changed but the INS rows, when an epoch's model is too
        large for the compiled discretization (the caller then takes the per-epoch path from the start). memo: the
        truth's TruthMemo (the reduced pass's epoch models, nav/reduced.models)."""
        system, lay, sh, eng = self.system, self.layout, self.shared, self.engine
        m = dtheta.shape[1]
        x0 = self.x.copy()
        # the INS over every row (feed-forward: the filter never acts)
        self.propagate(dtheta, dv, dt_s, h_baro, 0, baro_age_s)
        e_rows = np.arange(epoch_rows, m + 1, epoch_rows)
        N, E = self.n_runs, e_rows.shape[0]
        t_e = np.asarray(truth.t_s, dtype=float)[e_rows]
        dt = np.diff(np.concatenate([[self.t_last], t_e]))
        tol = 0.25 * dt_s
        # the damping loop held where the INS had no baro over the whole interval (as NavSystem.run's per-epoch path)
        held = np.zeros((N, E), dtype=np.int64)
        if lay.has("ac") and h_baro is not None:
            # the intervals are the consecutive blocks of epoch_rows rows before each epoch row
            blocks = np.isnan(h_baro[:, :E * epoch_rows]).reshape(h_baro.shape[0], E, epoch_rows)
            held[:, :] = np.all(blocks, axis=2)[self.ins_of]
        # the reference: the truth at the epoch rows
        ref = np.zeros((E, ins.NX))
        ref[:, 0], ref[:, 1], ref[:, 2] = truth.lat_rad[e_rows], truth.lon_rad[e_rows], truth.h_m[e_rows]
        ref[:, 3:6] = truth.v_ned[e_rows]
        ref_cbn = np.ascontiguousarray(sh.ref_cbn[e_rows // epoch_rows])
        ref[:, 6:15] = ref_cbn.reshape(E, 9)
        f_ref = np.stack([sh.f_ned_ref[r - epoch_rows:r].mean(axis=0) for r in e_rows]) if E else np.zeros((0, 3))
        r_ref = geo.geodetic_to_ecef(ref[:, 0], ref[:, 1], ref[:, 2])
        ref_agl = ref[:, 2] - system.terrain_h(r_ref) if E else np.zeros(0)
        o = _stacked_observations(records, t_e, tol, batched, N)
        per_run_sky = o["per_run_sky"]
        noise = system.noise(None if per_run_sky or o["el0"] is None else o["el0"])
        q, gse, gmp = em.kernel_noise(noise, lay.n_sv)
        loop = em.kernel_loop(system.loop_gains() if lay.has("ac") else None)
        baro_h, baro_r, radalt_h = o["baro_h"], o["baro_r"], o["radalt_h"]
        rho, r_sv, el = o["rho"], o["r_sv"], o["el"]
        k = rho.shape[2]
        sig = np.broadcast_to(eng._code_sig, (N, E, k)) if eng.channel_states else o["sig"]
        sig = np.ascontiguousarray(sig, dtype=float)
        pl_rho = o["pl_rho"]
        r_pl = o["r_pl"] if o["r_pl"] is not None else eng._none3
        # a writable copy (a read-only view is another type to compiled code: class_epoch compiled twice)
        pl_sig = np.array(np.broadcast_to(eng._pl_sig if eng.pl_states else o["pl_sig"],
                                          (E, pl_rho.shape[2])), dtype=float)
        # the channel states' Qd at each run's own sky (per-run skies; one sky: the model's own)
        ch_gio = np.zeros((N, E, 0))
        gse_r = gio_r = np.zeros((N, E, 0))
        if lay.has("gse") and k and self.gbas_scale is not None:  # GBAS: at the truth's geometry, scaled per interval
            el_all = np.broadcast_to(el, (N, E, k)).reshape(N * E, k)
            if eng.carrier:  # gse without the ionosphere, gio, each scaled by its own sigma
                sky = self.gbas_scale.carrier_interval(el_all, np.tile(ref, (N, 1)), np.tile(dt, N))
                ch_gse, ch_gio, ch_gmp, gse_r, gio_r = (a.reshape(N, E, k) for a in sky)
            else:
                sky = self.gbas_scale.interval(el_all, np.tile(ref, (N, 1)), np.tile(dt, N))
                ch_gse, ch_gmp, gse_r = (a.reshape(N, E, k) for a in sky)
        elif lay.has("gse") and per_run_sky and k and eng.carrier:  # the slow state without the ionosphere (gio)
            ch_gse, ch_gio, ch_gmp = eng.carrier_channel_sigmas(el)
        elif lay.has("gse") and per_run_sky and k:
            ch_gse, ch_gmp = eng.channel_sigmas(el.reshape(N * E, k))
            ch_gse, ch_gmp = ch_gse.reshape(N, E, k), ch_gmp.reshape(N, E, k)
        else:
            ch_gse = ch_gmp = np.zeros((N, E, 0))
        nz = system.noise_model.noise(None)
        f_gse = -np.expm1(-2.0 * dt / nz.gse_tau_s) if lay.has("gse") else np.zeros(E)
        f_gmp = -np.expm1(-2.0 * dt / nz.gmp_tau_s) if lay.has("gse") else np.zeros(E)
        cp, new, gio, gio_tau, f_gio, arcs = self._stacked_carrier(o, noise, nz, dt)
        dbp, db_x, db_u = self.db_stack
        X = np.array([r.fs.x for r in self.runs])
        P3 = sh.P.copy()
        R = eng.codes.shape[0]
        n = lay.n
        codes, nu, S = np.zeros((N, E, R), dtype=np.int64), np.zeros((N, E, R)), np.zeros((N, E, R))
        n_rows = np.zeros((N, E), dtype=np.int64)
        x_out, p33, pcc = np.zeros((N, E, n)), np.zeros((N, E, 3, 3)), np.zeros((N, E))
        pd, pnav = np.zeros((N, E, n)), np.zeros((N, E, 9, 9))
        ins_y = np.ascontiguousarray(self.rows[self.ins_of][:, e_rows])
        done = -1
        if per_run_sky and k and lay.has("gse") and not eng.carrier:  # each run on its reduced state
            args = (X, P3, lay, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, ref_agl, sh.sb_ref, held, ch_gse, ch_gmp,
                    f_gse,
                    f_gmp, gse_r, ins_y, baro_h, baro_r, radalt_h, dbp, db_x, db_u, rho, r_sv, sig, pl_rho, r_pl,
                    pl_sig)
            self.reduced_runs = []
            done = reduced.reduced_singletons(system, truth, eng, args,
                                              (codes, nu, S, n_rows, x_out, p33, pcc, pd, pnav), self._ic,
                                              self.reduced_runs, _valid_channels(records, N), memo)
            if done < 0:
                self.reduced_runs = None
        if done < 0:
            model = kg.ErrorModel(eng.lay, q, gse, gmp, loop, gio, gio_tau, eng._none1, eng._none1)
            done = ke.shared_pass(X, P3, model,
                                  kg.Track(dt, ref, ref_cbn, f_ref), held,
                                  kg.ChannelQd(ch_gse, ch_gmp, ch_gio, f_gse, f_gmp, f_gio, gse_r, gio_r), ins_y,
                                  kg.Obs(baro_h, baro_r, radalt_h, ref_agl, sh.sb_ref, dbp, db_x, db_u, rho, r_sv,
                                         sig, cp, pl_rho,
                                         r_pl, pl_sig), new, eng.rows,
                                  kg.PassOut(codes, nu, S, n_rows, x_out, pd, pnav, p33, pcc, self._ic), eng.scr)
        if done != E:
            self.x[:] = x0
            self.f_sum[:] = 0.0
            return False
        rates = _pass_rates(kg.ErrorModel(eng.lay, q, gse, gmp, loop, gio, gio_tau, eng._none1, eng._none1),
                            kg.Track(dt, ref, ref_cbn, f_ref),
                            held, x_out)
        for e in range(E):  # what the per-epoch path keeps
            self._snaps.append((x_out[:, e], p33[:, e], pcc[:, e]))
            self._rates.append(rates[:, e])
            self._t_snap.append(float(t_e[e]))
            self._hist["pd"].append(pd[:, e])
            self._hist["pnav"].append(pnav[:, e])
        self._hist["t"].extend(t_e.tolist())
        self._hist["row"].extend(e_rows.tolist())
        self._hist["snap"].extend(range(1, E + 1))
        self.snap[:] = np.searchsorted(e_rows, np.arange(self.snap.shape[0]), side="right")
        sh.P = P3
        for i, r in enumerate(self.runs):
            r.fs = FilterState(x=X[i], P=P3[i], memory=r.fs.memory)
            r.statuses.add_epochs(codes[i], n_rows[i], t_e, nu[i], S[i])
            if arcs is not None:
                r.arcs = arcs[i]
        self.t_last = float(t_e[-1]) if E else self.t_last
        return True

    def _stacked_carrier(self, o: dict, noise: em.ErrorNoise, nz: em.ErrorNoise, dt: Array) -> tuple:
        """compiled_pass's carrier-phase arguments of core/nav/epoch.shared_pass: (cp (N, E, k), new (N, E, k),
        gio (n_sv,), gio_tau, f_gio (E,), the runs' arc ids after the pass (N, k)); empty arrays and None without
        carrier phase. noise: the model's noise, nz the elevation-free one (the taus)."""
        N, E = self.n_runs, dt.shape[0]
        if not self.engine.carrier or o.get("cp") is None:
            return np.zeros((N, E, 0)), np.zeros((N, E, 0), dtype=np.int64), np.zeros(0), 1.0, np.zeros(E), None
        arc = o["arc"]
        last = np.array([np.full(arc.shape[2], -1, dtype=np.int64) if r.arcs is None else r.arcs for r in self.runs],
                        dtype=np.int64).reshape(N, arc.shape[2])
        new, arcs = stacked_new_arcs(last, arc)
        gio, gio_tau = em.kernel_carrier(noise, self.layout.n_sv)
        return o["cp"], new, gio, gio_tau, -np.expm1(-2.0 * dt / nz.gio_tau_s), arcs

    # --- output --------------------------------------------------------------------------------------------

    def _snapshot(self, epoch: bool = False) -> None:
        """Keep x, the position block of P and the clock variance: the estimate in force until the next epoch, with
        its rate F x (core/nav/output.nav_rate; F the interval's model each aiding path left in `interval_F`; zeros
        at the start) and its time t_last; at an epoch also each run's P diagonal and navigation block (the filter
        history)."""
        ic = self._ic
        xs, pp, pc, pd, pn = [], [], [], [], []
        rates = np.zeros((len(self.runs), 9))
        for i, r in enumerate(self.runs):
            if epoch:
                c = np.ascontiguousarray
                ko.nav_rate(c(self.interval_F[i], dtype=float), c(r.fs.x, dtype=float), rates[i])
                self.interval_F[i] = None
            P = self.system.filter.covariance(r.fs)
            xs.append(r.fs.x)
            pp.append(P[0:3, 0:3])
            pc.append(P[ic, ic])
            if epoch:
                pd.append(np.diagonal(P))
                pn.append(P[0:9, 0:9])
        self._snaps.append((np.array(xs), np.array(pp), np.array(pc)))
        self._rates.append(rates)
        self._t_snap.append(self.t_last)
        if epoch:
            self._hist["pd"].append(np.array(pd))
            self._hist["pnav"].append(np.array(pn))

    def results(self, truth: Truth, n_rows: int | None = None, solutions: Any = True) -> list[NavRun]:
        """Each run's NavRun over the first n_rows rows (default: all): the solution at every row (INS - x_hat(t),
        the snapshot in force carried to the row's time by its rate, core/nav/output.py), the status log and the
        epoch history. solutions: True, or a
        set of run indices whose solution is assembled (the others get None: the integrity bank's sub-filters
        need only their epoch history)."""
        n = self.rows.shape[1] if n_rows is None else int(n_rows)
        snap = self.snap[:n]
        XS = np.stack([x for x, _, _ in self._snaps])  # (snaps, runs, n_states)
        XD = np.stack(self._rates)  # (snaps, runs, 9)
        T = np.array(self._t_snap)  # (snaps,)
        t_rows = np.asarray(truth.t_s[:n], dtype=float)
        PP = np.stack([p for _, p, _ in self._snaps])  # (snaps, runs, 3, 3)
        PC = np.stack([c for _, _, c in self._snaps])  # (snaps, runs)
        lay = self.layout
        has_clk = lay.has("clk")
        ic = self._ic
        h = self._hist
        e_rows, e_snap = np.array(h["row"], dtype=int), np.array(h["snap"], dtype=int)
        out = []
        for i, r in enumerate(self.runs):
            sol = None
            if solutions is True or i in solutions:
                xs = XS[:, i]
                r_ecef, v_ned, euler = ko.corrected(self.rows[self.ins_of[i], :n], t_rows, xs, XD[:, i], T, snap)
                sol = NavSolution(
                    t_s=t_rows,
                    r_ecef=r_ecef,
                    v_ned=v_ned,
                    euler_rad=euler,
                    P_pos_ned=PP[:, i][snap],
                    clock_bias_m=xs[snap, ic] if has_clk else np.full(n, np.nan),
                    clock_bias_sigma_m=np.sqrt(PC[:, i][snap]) if has_clk else np.full(n, np.nan),
                    **(r.fde.solution_fields(snap) if r.fde is not None else {}),
                )
            xe = XS[e_snap, i]  # (E, n) the estimate after each epoch
            if e_rows.size:  # the output's error at the epochs: INS rows - x_hat against the truth rows
                o = ins.perturb(ins.unpack(self.rows[self.ins_of[i], e_rows]), -xe[:, 0:3], -xe[:, 3:6], -xe[:, 6:9])
                err = true_error_rows(o, truth, e_rows)
            else:
                err = np.zeros((0, 9))
            out.append(NavRun(
                solution=sol, status=StatusLog.from_buffer(r.statuses), t_epoch_s=np.array(h["t"]),
                x=xe, P_diag=np.array([p[i] for p in h["pd"]]).reshape(-1, lay.n),
                P_nav=np.array([p[i] for p in h["pnav"]]).reshape(-1, 9, 9), true_error_nav=err, layout=lay,
            ))
        return out


def _pass_rates(model: kg.ErrorModel, track: kg.Track, held: Array, X: Array) -> Array:
    """(N, E, 9) the rate of each run's estimate after each epoch of a compiled pass (core/nav/output.nav_rate), F
    the model core/nav/epoch.shared_pass linearized for the interval ending there (at the reference, with or without
    the loop held); X (N, E, n) the estimates after the epochs, held (N, E) int."""
    N, E, n = X.shape
    out = np.zeros((N, E, 9))
    F, Qc = np.zeros((n, n)), np.zeros((n, n))
    for e in range(E):
        y = track.ref[e]
        for hd in (0, 1):
            which = np.flatnonzero(held[:, e] == hd)
            if which.size == 0:
                continue
            kem.dynamics(model.lay, model.q, model.gse, model.gmp, y[0],
                         kem.interval_height(model.lay, y[2], y[5], track.dt[e]), y[3:6], track.f_ref[e],
                         track.ref_cbn[e], model.loop, hd == 1, F, Qc)
            for i in which:
                ko.nav_rate(F, X[i, e], out[i, e])
    return out


def _stacked_observations(records: Any, t_e: Array, tol: float, batched: bool, n_runs: int) -> dict[str, Any]:
    """The measurements of every run at every epoch time t_e (E,) as arrays with the axes (runs, epochs, ...):
    Observations.at's values for all epochs at once (nan where a record has no sample at the epoch or it is
    invalid), plus each epoch's baro variance and whether the GNSS sky is per run."""
    E = t_e.shape[0]

    def index(t_rec: Array) -> tuple[Array, Array]:  # Observations' _epoch_index for every epoch
        t_rec = np.asarray(t_rec, dtype=float)
        i = np.searchsorted(t_rec, t_e - tol)
        ok = i < t_rec.shape[0]
        j = np.minimum(i, max(t_rec.shape[0] - 1, 0))
        ok &= np.abs(t_rec[j] - t_e) <= tol if t_rec.shape[0] else False
        return j, ok

    def per_run(a: Array) -> Array:
        return np.asarray(a) if batched else np.asarray(a)[None]

    out: dict[str, Any] = {"per_run_sky": False, "el0": None, "r_pl": None, "pl_sig": None}
    nan = np.full((n_runs, E), np.nan)
    b = records.get("baro")
    out["baro_h"], out["baro_r"] = nan.copy(), np.zeros(E)
    if b is not None:
        j, ok = index(b.t_s)
        v = np.where(per_run(b.valid)[:, j], per_run(b.h_baro_m)[:, j], np.nan)
        out["baro_h"] = np.where(ok[None, :], v, np.nan)
        out["baro_r"] = np.where(ok, np.asarray(b.sigma_m, dtype=float)[j] ** 2, 0.0)
    r = records.get("radalt")
    out["radalt_h"] = nan.copy()
    if r is not None:
        j, ok = index(r.t_s)
        v = np.where(per_run(r.valid)[:, j], per_run(r.h_agl_m)[:, j], np.nan)
        out["radalt_h"] = np.where(ok[None, :], v, np.nan)
    g = records.get("gnss")
    if g is not None:
        j, ok = index(g.t_s)
        sky = batched and bool(g.per_run_sky)
        rho = np.where(per_run(g.valid)[:, j], per_run(g.pseudorange_m)[:, j], np.nan)
        out["rho"] = np.ascontiguousarray(np.where(ok[None, :, None], rho, np.nan))
        k = rho.shape[2]
        out["r_sv"] = np.ascontiguousarray(np.broadcast_to(g.r_sv_ecef[:, j] if sky else g.r_sv_ecef[j],
                                                           (n_runs, E, k, 3)), dtype=float)
        out["sig"] = np.ascontiguousarray(np.broadcast_to(g.sigma_m[:, j] if sky else g.sigma_m[j], (n_runs, E, k)),
                                          dtype=float)
        out["el"] = np.ascontiguousarray(np.broadcast_to(g.elevation_rad[:, j] if sky else g.elevation_rad[j],
                                                         (n_runs, E, k)), dtype=float)
        out["per_run_sky"] = sky
        if g.carrier_phase_m is not None:  # the carrier phase and its arc id where the channel is valid at the epoch
            okv = per_run(g.valid)[:, j] & ok[None, :, None]
            out["cp"] = np.ascontiguousarray(np.where(okv, per_run(g.carrier_phase_m)[:, j], np.nan))
            out["arc"] = np.where(okv, per_run(g.carrier_arc)[:, j], -1).astype(np.int64)
        if E and not sky:
            out["el0"] = np.asarray(g.elevation_rad[j[0]], dtype=float)
    else:
        out["rho"], out["r_sv"], out["sig"], out["el"] = (np.full((n_runs, E, 0), np.nan), np.zeros((n_runs, E, 0, 3)),
                                                          np.zeros((n_runs, E, 0)), np.zeros((n_runs, E, 0)))
    p = records.get("pseudolite")
    out["pl_rho"], out["pl_sig"] = np.full((n_runs, E, 0), np.nan), np.zeros((E, 0))
    if p is not None:
        j, ok = index(p.t_s)
        rho = np.where(per_run(p.valid)[:, j], per_run(p.pseudorange_m)[:, j], np.nan)
        out["pl_rho"] = np.ascontiguousarray(np.where(ok[None, :, None], rho, np.nan))
        out["r_pl"] = np.ascontiguousarray(p.r_pl_ecef, dtype=float)
        out["pl_sig"] = np.ascontiguousarray(np.asarray(p.sigma_m, dtype=float)[j])
    return out
