"""Shared covariance: open-loop runs on one truth with the optimal filter propagate one covariance and gain per
measurement schedule, linearized along the truth, instead of one per run (NavSystem.run(..., shared_covariance)).

Runs whose available measurements (and damping-loop hold) have been the same at every epoch share one covariance;
a run whose schedule departs (a fault, an outage, a lost channel) gets its own copy from then on (`split`). A run's
covariance is thus a function of the truth and its own schedule only, and its numbers do not depend on the runs it
shares a batch with. With per-run GPS skies every run is its own class from the start (a covariance is shared only
within one sky). Phi and Qd are built once per epoch along the truth (and per hold state); each class takes the
reference rows (the measurement model at the truth, nav/rows.py) for its gains, and each run its own innovation
nu_i = z_i - g(x_hat_i) from its own rows at its own INS solution and estimate: the same measurement functions as
the per-run filters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav.base import FilterState, UpdateStatus
from approachsim.nav.observations import Observations
from approachsim.records import Truth

Array = np.ndarray


@dataclass
class SharedCovariance:
    """One P per measurement-schedule class (module docstring); mutable, lives inside one pass."""

    P: Array
    """(C, n, n) covariance of each class."""
    of_run: Array
    """(N,) class of each run."""
    f_ned_ref: Array
    """(rows, 3) the truth's specific force in NED at every row (the reference trajectory's), m/s^2."""
    epoch_rows: int
    ref_cbn: Array
    """(rows // epoch_rows + 1, 3, 3) the truth's body-to-NED matrix at every epoch row (the reference's attitude)."""
    per_run_sky: bool = False
    """The runs have their own GPS skies: every run is its own class from the start, in any batch."""
    sb_ref: float = 0.0
    """The reference's baro scale factor: the day's (sensors/states.SensorStates.sb_day), the same for every run,
    where the shared baro rows take their dp_D coefficient -(1 + sb) (a run's own estimate would make the
    covariance depend on the batch); 0 without a baro scale-factor state or realized states."""

    @classmethod
    def start(cls, runs: list, truth: Truth, m: int, epoch_rows: int, per_run_sky: bool,
              sb_ref: float = 0.0) -> SharedCovariance:
        """Classes at the start: one per run with per-run skies, else one for all (the runs' start covariance);
        sb_ref the reference's baro scale factor (the field's doc)."""
        n = len(runs)
        c_bn = ins.cbn_from_quaternion(truth.q_nb[:m + 1])
        f_ref = np.einsum("nij,nj->ni", c_bn[:m], truth.f_body[:m])
        ref_cbn = c_bn[::epoch_rows].copy()
        if per_run_sky:
            return cls(np.array([r.fs.P for r in runs], dtype=float), np.arange(n), f_ref, epoch_rows, ref_cbn, True,
                       float(sb_ref))
        return cls(np.array([runs[0].fs.P], dtype=float), np.zeros(n, dtype=int), f_ref, epoch_rows, ref_cbn, False,
                   float(sb_ref))

    @property
    def singletons(self) -> bool:
        """Every run is a class of its own (run i is class i): per-run skies, the integrity bank's copies."""
        return self.P.shape[0] == self.of_run.shape[0] and bool(np.all(self.of_run == np.arange(len(self.of_run))))

    def predict_class(self, c: int, phi: Array, qd: Array) -> None:
        """P- = Phi P+ Phi' + Qd for class c (its own model: GPS sky, damping loop held or not)."""
        P = phi @ self.P[c] @ phi.T + qd
        self.P[c] = 0.5 * (P + P.T)

    def split(self, schedule: Array) -> None:
        """Runs of one class whose schedules (rows of (N, k) bool) differ go to new classes (copies of P)."""
        if self.singletons:  # a class of one run never splits
            return
        keys: dict[tuple[int, bytes], int] = {}
        parent: list[int] = []
        of_run = np.empty_like(self.of_run)
        for i, c in enumerate(self.of_run):
            k = (int(c), schedule[i].tobytes())
            if k not in keys:
                keys[k] = len(parent)
                parent.append(int(c))
            of_run[i] = keys[k]
        if len(parent) != self.P.shape[0]:
            self.P = self.P[np.array(parent)]  # a copy of the parent's P for each new class
        self.of_run = of_run

    def classes(self) -> list[tuple[int, list[int]]]:
        """(class, its runs) for every class."""
        return [(c, [int(i) for i in np.flatnonzero(self.of_run == c)]) for c in range(self.P.shape[0])]

    def aid(self, nav: Any, s: ins.InsState, t: float, dt_epoch: float, row: int, obs: Observations,
            truth: Truth) -> ins.InsState:
        """One epoch of every run (nav: the Navigator; s its INS states): the classes' covariances and gains along
        the truth row `row` (its mean specific force over the interval), each run's state with its own
        innovations. Returns s (feedback is the Navigator's)."""
        system = nav.system
        runs = nav.runs
        lay = system.layout
        ref = ins.InsState(truth.lat_rad[row:row + 1], truth.lon_rad[row:row + 1], truth.h_m[row:row + 1],
                           truth.v_ned[row:row + 1], self.ref_cbn[row // self.epoch_rows][None], np.zeros(1))
        f_ref = self.f_ned_ref[row - self.epoch_rows:row].mean(axis=0)
        # per-run skies: every path below resets the GPS channel states' Qd to each class's own sky, so the model's
        # noise is taken at the default elevations (cached) instead of being rebuilt for run 0's sky every epoch
        noise = system.noise(None if obs.per_run_sky else obs.elevations(0))
        # the damping loop held in a run whose INS had no baro over the interval (kernels.strapdown): its own Phi,
        # Qd. Classes are split on this epoch's schedule and the hold together (splitting only copies P), so every
        # member of a class holds or none does, and then each class is predicted with its model
        held = [nav.loop_held(obs, i) for i in range(len(runs))]
        models: dict[bool, tuple[Array, Array]] = {}
        for h in sorted(set(held)):
            h_lin = em.interval_height(lay, float(ref.h_m[0]), float(ref.v_ned[0, 2]), dt_epoch)
            F, Qc = em.dynamics(lay, float(ref.lat_rad[0]), h_lin, ref.v_ned[0], f_ref, ref.c_bn[0],
                                noise, system.loop_gains(), loop_held=h)
            models[h] = em.discretize(F, Qc, dt_epoch)
            for i in range(len(runs)):  # the interval's model: the estimate's rate after the epoch (Navigator)
                if held[i] == h:
                    nav.interval_F[i] = F
        # carrier phase: the channels whose arc begins here reset their ambiguities (a class shares them: split on it)
        new = nav.arc_resets(obs)
        self.split(np.column_stack([obs.schedule(), np.array(held, dtype=bool), new]))
        if nav.engine is not None and self.singletons:  # every run its own class: one compiled call for all
            self._aid_singletons(nav, ref, t, dt_epoch, obs, held, models, new)
            return s
        if nav.engine is not None:  # the compiled epoch, class by class (nav/engine.py)
            self._aid_engine(nav, ref, t, dt_epoch, obs, held, models, new)
            return s
        # x- = Phi x+ (row by row: no batch-size-dependent BLAS path)
        X = np.stack([self._model(nav, models, held, obs, new, i, ref, dt_epoch)[0] @ r.fs.x
                      for i, r in enumerate(runs)])
        for c, members in self.classes():
            self.predict_class(c, *self._model(nav, models, held, obs, new, members[0], ref, dt_epoch))
        r_ins = ins.position_ecef(s)
        r_ref = ins.position_ecef(ref)[0]
        x0 = np.zeros(lay.n)
        if lay.has("sb"):  # the rows at the reference's scale factor
            x0[lay.i("sb")] = self.sb_ref
        eye = np.eye(lay.n)
        for c, members in self.classes():
            i0 = members[0]
            ref_rows = system.rows.epoch(ref, 0, r_ref, system.rows.reference_obs(obs, i0, float(ref.h_m[0]), r_ref),
                                         t)
            own = {i: system.rows.epoch(s, i, r_ins[i], obs, t, db_error=runs[i].db_error) for i in members}
            P = np.array(self.P[c])
            for j, rr in enumerate(ref_rows):
                m0 = rr.build(x0)
                h0, r = m0.h, m0.r
                Ph = P @ h0
                S = float(h0 @ Ph + r)  # S = h' P h + r (shared)
                K = Ph / S  # K = P h S^-1 (shared)
                for i in members:
                    row_i = own[i][j]
                    if row_i.source != rr.source:
                        raise RuntimeError(f"shared covariance: run {i} has {row_i.source.name} where its class "
                                           f"has {rr.source.name}")
                    m = row_i.build(X[i])
                    v = float(m.z - m.h @ X[i])  # nu_i = z_i - g(x_hat_i): the run's own exact difference
                    X[i] = X[i] + v * K  # x+ = x- + K nu
                    runs[i].statuses.append(UpdateStatus(m0.name, t, v, S, v * v / S, 1.0, True))
                A = eye - np.outer(K, h0)
                P = A @ P @ A.T + r * np.outer(K, K)  # Joseph form
                P = 0.5 * (P + P.T)
            self.P[c] = P
        for i, run in enumerate(runs):
            run.fs = FilterState(x=X[i], P=self.P[self.of_run[i]], memory=run.fs.memory)
        return s

    @staticmethod
    def _model(nav: Any, models: dict, held: list, obs: Observations, new: Array, i: int, ref: ins.InsState,
               dt_epoch: float) -> tuple[Array, Array]:
        """Run i's class model (phi, qd): the epoch's model for its hold, the GPS channel states' Qd at its own sky
        (per-run skies), under GBAS their scale along the reference (nav/gbas_scale.py), its new arcs reset."""
        system = nav.system
        phi, qd = models[held[i]]
        if obs.per_run_sky:
            qd = system.noise_model.channel_qd(qd, obs.elevations(i), dt_epoch)
        if nav.gbas_scale is not None and obs.has_gnss:
            phi, qd = nav.gbas_scale.apply(phi, qd, obs.elevations(i), ins.pack(ref)[0], dt_epoch,
                                           system.noise_model.noise(None))
        return nav.with_resets(phi, qd, new[i])

    def _aid_engine(self, nav: Any, ref: ins.InsState, t: float, dt_epoch: float, obs: Observations, held: list,
                    models: dict, new: Array) -> None:
        """`aid`'s predict and updates by core/nav/epoch.class_epoch in shared mode (rows at the truth), one call
        per class; the classes are already split."""
        system = nav.system
        runs = nav.runs
        ref_y = ins.pack(ref)
        r_ref = ins.position_ecef(ref)[0]
        ref_agl = float(ref.h_m[0] - system.terrain_h(r_ref))
        for c, members in self.classes():
            phi, qd = self._model(nav, models, held, obs, new, members[0], ref, dt_epoch)
            X = np.stack([runs[i].fs.x for i in members])
            P = self.P[c]  # its own array (split copies)
            ins_y = nav.x[nav.ins_of[members]]
            nav.engine.epoch(X, P, phi, qd, False, ref_y[0], ins_y, obs, members, t,
                             [runs[i].statuses for i in members], [nav.dbs[i] for i in members], ref_agl,
                             self.sb_ref)
            for j, i in enumerate(members):
                runs[i].fs = FilterState(x=X[j], P=P, memory=runs[i].fs.memory)

    def _aid_singletons(self, nav: Any, ref: ins.InsState, t: float, dt_epoch: float, obs: Observations,
                        held: list, models: dict, new: Array) -> None:
        """`_aid_engine` when every run is its own class: all runs in one core/nav/epoch.copies_epoch call (each
        its own covariance, the channel Qd at its own sky)."""
        system = nav.system
        runs = nav.runs
        ref_y = ins.pack(ref)[0]
        r_ref = ins.position_ecef(ref)[0]
        ref_agl = float(ref.h_m[0] - system.terrain_h(r_ref))
        X = np.array([r.fs.x for r in runs])
        phi2 = np.stack([models.get(False, models.get(True))[0], models.get(True, models.get(False))[0]])
        qd2 = np.stack([models.get(False, models.get(True))[1], models.get(True, models.get(False))[1]])
        nav.engine.singletons(X, self.P, phi2, qd2, np.array(held, dtype=np.int64), obs, t, dt_epoch,
                              nav.x[nav.ins_of], ref_y, ref_agl, [r.statuses for r in runs], nav.db_stack, new,
                              ref_sb=self.sb_ref)
        for i, r in enumerate(runs):
            r.fs = FilterState(x=X[i], P=self.P[i], memory=r.fs.memory)
