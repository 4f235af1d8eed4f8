"""The compiled epoch engine: the optimal filter's epoch of one run, or of a shared-covariance class, as one call of
kernels/epoch.py, with the arrays it needs built once per navigation system and per run.

    eng = EpochEngine.of(system)                     # None when the configuration needs the generic path
    eng.epoch(X, P, phi, qd, own, ref_y, ins_y, obs, members, t_s, statuses, db)

Used when the filter is the optimal 'ekf' (no gain policy to call back), the GPS is tightly coupled, the damping
loop (if any) has constant gains and the online FDE is off: exactly the configurations NavSystem.shares_covariance
names. Everything else (robust and U-D filters, loose coupling, adaptive loops, FDE) takes the generic path of
nav/navigator.py and nav/shared.py, which is also the engine's test oracle (tests/unit/nav/test_epoch_engine.py).

Also here: `StatusBuffer`, a run's status records kept as whole epochs of arrays (the engine's) or UpdateStatus
objects (the generic path), in processing order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav.base import KalmanFilter, UpdateStatus, optimal_policy, workspace
from approachsim.nav.kernels import epoch as ke
from approachsim.nav.observations import Observations

Array = np.ndarray

_MAX_ROWS = 2 + 64 + 16
"""Rows an epoch can have: baro, radalt, GNSS channels, pseudolites (bounded by the layout below)."""


def code_name(code: int) -> str:
    """The status-log name of a row code (kernels/epoch.py): "baro", "radalt", "gps07", "pl0"."""
    if code == ke.CODE_BARO:
        return "baro"
    if code == ke.CODE_RADALT:
        return "radalt"
    if code >= ke.CODE_PL:
        return f"pl{code - ke.CODE_PL}"
    return f"gps{code - ke.CODE_GPS:02d}"


class StatusBuffer:
    """One run's status records in processing order (module docstring)."""

    def __init__(self, items: list | None = None) -> None:
        self._parts: list = list(items or [])

    def append(self, st: UpdateStatus) -> None:
        self._parts.append(st)

    def extend(self, sts: list[UpdateStatus]) -> None:
        self._parts.extend(sts)

    def add_epoch(self, codes: Array, t_s: float, nu: Array, S: Array) -> None:
        """An engine epoch: row codes (R,), innovations (R,) m, their variances (R,) m^2 (optimal: accepted,
        weight 1)."""
        self._parts.append((np.array(codes), float(t_s), np.array(nu, dtype=float), np.array(S, dtype=float)))

    def __len__(self) -> int:
        return sum(1 if isinstance(p, UpdateStatus) else len(p[0]) for p in self._parts)

    def arrays(self) -> dict[str, Array]:
        """t_s, name, innovation, variance, test_ratio, weight, accepted (u,) in processing order."""
        t, name, nu, S, w, acc = [], [], [], [], [], []
        for p in self._parts:
            if isinstance(p, UpdateStatus):
                t.append(np.array([p.t_s]))
                name.append(np.array([p.name], dtype=object))
                nu.append(np.array([p.innovation]))
                S.append(np.array([p.variance]))
                w.append(np.array([p.weight]))
                acc.append(np.array([p.accepted]))
            else:
                codes, ts, v, s = p
                k = len(codes)
                t.append(np.full(k, ts))
                name.append(np.array([code_name(int(c)) for c in codes], dtype=object))
                nu.append(v)
                S.append(s)
                w.append(np.ones(k))
                acc.append(np.ones(k, dtype=bool))

        def cat(a: list, dtype: Any) -> Array:
            return np.concatenate(a).astype(dtype) if a else np.zeros(0, dtype=dtype)

        nu_a, S_a = cat(nu, float), cat(S, float)
        return {"t_s": cat(t, float), "name": cat(name, str), "innovation": nu_a, "variance": S_a,
                "test_ratio": nu_a * nu_a / S_a if S_a.size else np.zeros(0), "weight": cat(w, float),
                "accepted": cat(acc, bool)}


@dataclass(frozen=True)
class RunDatabase:
    """A run's terrain-database error as the engine's arrays (measurements.database_arrays)."""

    dbp: Array
    db_x: Array
    db_u: Array

    @classmethod
    def of(cls, config: tdb.TerrainDbConfig, error: tdb.TerrainDbError | None) -> RunDatabase:
        return cls(*meas.database_arrays(config, error))


class EpochEngine:
    """The constants of one navigation system for kernels/epoch.class_epoch, and its scratch space."""

    def __init__(self, system: Any) -> None:
        lay = system.layout
        self.system = system
        self.lay = lay.packed
        self.tx, self.th, self.rwy = meas.terrain_arrays(system.runway, getattr(system.terrain_h, "terrain", None))
        r = system.sensors.radalt
        self.ra_pct, self.ra_floor = (r.percent_sigma, r.floor_m) if r is not None else (0.0, 0.0)
        self.channel_states = lay.has("gse")
        self.pl_states = lay.has("pmp")
        g = system.sensors.gnss
        self.code_noise_m = g.budget().code_noise_m if g is not None else 0.0
        p = system.sensors.pseudolite
        self.pl_sigma_states = float(np.sqrt(p.code_noise_m**2 + p.survey_sigma_m**2)) if p is not None else 0.0
        n = lay.n
        self.h = np.zeros(n)
        self.b = np.zeros(n)
        self.ws = workspace(n)
        self.codes = np.zeros(_MAX_ROWS, dtype=np.int64)
        self.S = np.zeros(_MAX_ROWS)
        self._nan1 = np.full(1, np.nan)
        self._none2 = np.zeros((1, 0))
        self._none3 = np.zeros((0, 3))
        self._none1 = np.zeros(0)

    @classmethod
    def of(cls, system: Any) -> EpochEngine | None:
        """The engine of `system`, or None when its configuration takes the generic path (module docstring)."""
        f = system.filter
        if not (isinstance(f, KalmanFilter) and f.policy is optimal_policy and system.shares_covariance()):
            return None
        return cls(system)

    def epoch(self, X: Array, P: Array, phi: Array, qd: Array, own: bool, ref_y: Array, ins_y: Array,
              obs: Observations, members: list[int], t_s: float, statuses: list[StatusBuffer],
              dbs: list[RunDatabase], ref_agl_m: float = 0.0) -> None:
        """One epoch of the members (indices into obs's runs) with estimates X (M, n) and covariance P, in place
        (kernels/epoch.class_epoch); each member's status records go to its buffer."""
        M = len(members)
        idx = np.asarray(members)
        baro_h = obs.baro_h_m[idx] if obs.baro_h_m is not None else np.full(M, np.nan)
        baro_r = float(obs.baro_sigma_m) ** 2 if obs.baro_h_m is not None else 0.0
        radalt_h = obs.radalt_h_m[idx] if obs.radalt_h_m is not None else np.full(M, np.nan)
        if obs.has_gnss:
            rho = np.ascontiguousarray(obs.gnss_rho_m[idx])
            r_sv, sig_nom, _ = obs.sky(members[0])
            sig = np.full(rho.shape[1], self.code_noise_m) if self.channel_states else np.asarray(sig_nom, float)
            r_sv = np.ascontiguousarray(r_sv, dtype=float)
        else:
            rho, r_sv, sig = np.zeros((M, 0)), self._none3, self._none1
        if obs.pl_rho_m is not None:
            pl_rho = np.ascontiguousarray(obs.pl_rho_m[idx])
            r_pl = np.ascontiguousarray(obs.pl_r_ecef, dtype=float)
            pl_sig = (np.full(pl_rho.shape[1], self.pl_sigma_states) if self.pl_states
                      else np.asarray(obs.pl_sigma_m, float))
        else:
            pl_rho, r_pl, pl_sig = np.zeros((M, 0)), self._none3, self._none1
        dbp = np.stack([d.dbp for d in dbs])
        db_x = dbs[0].db_x
        db_u = np.stack([d.db_u for d in dbs]) if db_x.size else np.zeros((M, 0))
        nu = np.zeros((M, _MAX_ROWS))
        k = ke.class_epoch(X, P, phi, qd, self.lay, own, ref_y, ins_y, baro_h, baro_r, radalt_h, self.ra_pct,
                           self.ra_floor, ref_agl_m, self.tx, self.th, self.rwy, dbp, db_x, db_u, rho, r_sv, sig,
                           self.channel_states, pl_rho, r_pl, pl_sig, self.pl_states, self.codes, nu, self.S,
                           self.h, self.b, self.ws)
        for j in range(M):
            statuses[j].add_epoch(self.codes[:k], t_s, nu[j, :k], self.S[:k])
