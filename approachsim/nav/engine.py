"""The compiled epoch engine: the optimal filter's epoch of one run, or of a shared-covariance class, as one call of
core/nav/epoch.py, with the arrays it needs built once per navigation system and per run.

    eng = EpochEngine.of(system)                     # None when the configuration needs the generic path
    eng.epoch(X, P, phi, qd, own, ref_y, ins_y, obs, members, t_s, statuses, db)

Used when the filter is the optimal 'ekf' (no gain policy to call back), the GPS is tightly coupled, the damping
loop (if any) has constant gains and the online FDE is off: exactly the configurations NavSystem.shares_covariance
names. With carrier phase the engine carries the carrier states too (kernels/carrier.py): the gio Gauss-Markov and
amb random constants in the model, the carrier-phase rows after the code rows, and each run's float ambiguities
reset where its carrier arc changes (`new_arcs`: the arc bookkeeping of every path, per-run, shared and compiled).
Everything else (robust and U-D filters, loose coupling, adaptive loops, FDE) takes the generic path of
nav/navigator.py and nav/shared.py, which is also the engine's test oracle (tests/unit/nav/test_epoch_engine.py,
tests/unit/nav/test_carrier_engine.py).

Also here: `StatusBuffer`, a run's status records kept as whole epochs of arrays (the engine's) or UpdateStatus
objects (the generic path), in processing order.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from approachsim.core.nav import epoch as ke
from approachsim.core.nav import groups as kg
from approachsim.core.sensors import gnss as gk
from approachsim.nav import errormodel as em
from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav.base import KalmanFilter, UpdateStatus, optimal_policy
from approachsim.nav.gbas_scale import GbasScale
from approachsim.nav.observations import Observations
from approachsim.sensors.gnss.elevation import IONO_SHELL_M

Array = np.ndarray

_MAX_ROWS = 2 + 2 * 64 + 16
"""Rows an epoch can have: baro, radalt, GNSS channels' code and carrier, pseudolites (bounded by the layout below)."""


@lru_cache(maxsize=512)
def code_name(code: int) -> str:
    """The status-log name of a row code (core/nav/epoch.py): "baro", "radalt", "gps07", "cp07", "pl0"."""
    if code == ke.CODE_BARO:
        return "baro"
    if code == ke.CODE_RADALT:
        return "radalt"
    if code >= ke.CODE_CP:
        return f"cp{code - ke.CODE_CP:02d}"
    if code >= ke.CODE_PL:
        return f"pl{code - ke.CODE_PL}"
    return f"gps{code - ke.CODE_GPS:02d}"


def new_arcs(last: Array | None, arc: Array) -> tuple[Array, Array]:
    """The carrier arcs that begin at this epoch: (new (k,) bool, where the arc id arc (k,) is valid (>= 0) and
    differs from last, the arc id of each channel at the last epoch that had its carrier (None: none yet); the
    updated last). A new arc is a new float ambiguity (sensors/gnss/carrier.py)."""
    arc = np.asarray(arc, dtype=np.int64)
    if last is None:
        last = np.full(arc.shape, -1, dtype=np.int64)
    return (arc >= 0) & (arc != last), np.where(arc >= 0, arc, last)


def stacked_new_arcs(last: Array, arc: Array) -> tuple[Array, Array]:
    """`new_arcs` over E epochs at once: last (N, k) the runs' arc ids before the first, arc (N, E, k) the ids at the
    epochs (-1 where a channel has no carrier there). Returns new (N, E, k) int64 (1: the ambiguity resets) and the
    ids after the last epoch."""
    new = np.zeros(arc.shape, dtype=np.int64)
    last = np.array(last, dtype=np.int64)
    for e in range(arc.shape[1]):
        a = arc[:, e]
        new[:, e] = (a >= 0) & (a != last)
        last = np.where(a >= 0, a, last)
    return new, last


def reset_arcs(layout: em.StateLayout, phi: Array, qd: Array, new: Array, prior: float) -> tuple[Array, Array]:
    """The epoch's Phi, Qd with the float ambiguity of every channel with new (k,) set reset to its prior (m^2): row
    and column of Phi and Qd zeroed, prior on Qd's diagonal, so P- = Phi P+ Phi' + Qd holds the prior there (copies;
    phi, qd themselves when nothing is new). The numpy twin of kernels/carrier.reset_ambiguities."""
    idx = layout.index["amb"].start + np.flatnonzero(new)
    if not idx.size:
        return phi, qd
    phi, qd = phi.copy(), qd.copy()
    phi[idx, :] = 0.0
    phi[:, idx] = 0.0
    qd[idx, :] = 0.0
    qd[:, idx] = 0.0
    qd[idx, idx] = prior
    return phi, qd


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

    def add_epochs(self, codes: Array, counts: Array, t_s: Array, nu: Array, S: Array) -> None:
        """Many engine epochs at once: codes, nu, S (E, R) of which the first counts[e] of row e are the epoch's, at
        times t_s (E,)."""
        keep = np.arange(codes.shape[1])[None, :] < np.asarray(counts)[:, None]
        t = np.broadcast_to(np.asarray(t_s, dtype=float)[:, None], codes.shape)
        self._parts.append((codes[keep], t[keep], nu[keep].astype(float), S[keep].astype(float)))

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
                t.append(np.full(k, ts) if np.ndim(ts) == 0 else np.asarray(ts, dtype=float))
                name.append(codes)  # row codes: named below, all at once
                nu.append(v)
                S.append(s)
                w.append(np.ones(k))
                acc.append(np.ones(k, dtype=bool))

        def cat(a: list, dtype: Any) -> Array:
            return np.concatenate(a).astype(dtype) if a else np.zeros(0, dtype=dtype)

        if name and all(n.dtype != object for n in name):  # engine epochs only: their codes named at once
            name = [_code_names(np.concatenate(name))]
        else:
            name = [n if n.dtype == object else np.array([code_name(int(c)) for c in n], dtype=object) for n in name]

        nu_a, S_a = cat(nu, float), cat(S, float)
        return {"t_s": cat(t, float), "name": cat(name, str), "innovation": nu_a, "variance": S_a,
                "test_ratio": nu_a * nu_a / S_a if S_a.size else np.zeros(0), "weight": cat(w, float),
                "accepted": cat(acc, bool)}


def _code_names(codes: Array) -> Array:
    """The status-log names (code_name) of row codes (k,) as an object array."""
    u, inv = np.unique(np.asarray(codes, dtype=np.int64), return_inverse=True)
    return np.array([code_name(int(c)) for c in u], dtype=object)[inv.reshape(-1)] if u.size else \
        np.zeros(0, dtype=object)


@dataclass(frozen=True)
class RunDatabase:
    """A run's terrain-database error as the engine's arrays (measurements.database_arrays), and the same on a run
    axis of length one (dbp2 (1, 4), db_u2 (1, k))."""

    dbp: Array
    db_x: Array
    db_u: Array
    dbp2: Array
    db_u2: Array

    @classmethod
    def of(cls, config: tdb.TerrainDbConfig, error: tdb.TerrainDbError | None) -> RunDatabase:
        dbp, db_x, db_u = meas.database_arrays(config, error)
        return cls(dbp, db_x, db_u, dbp[None].copy(), (db_u[None] if db_x.size else np.zeros((1, 0))).copy())


class EpochEngine:
    """The constants of one navigation system for core/nav/epoch.py (its rows' constants `rows`, core/nav/
    groups.Rows), and its scratch space `scr`."""

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
        self.scr = kg.scratch(n)
        """The kernels' work arrays (core/nav/groups.Scratch)."""
        self.h, self.b, self.ws, self.F, self.Qc, self.phi, self.qd = self.scr[:7]
        """The same arrays by name: core/loop/aiding.loop_epoch's positional arguments (nav/closed_loop.py)."""
        self.codes = np.zeros(_MAX_ROWS, dtype=np.int64)
        self.S = np.zeros(_MAX_ROWS)
        self._nan1 = np.full(1, np.nan)
        self._none2 = np.zeros((1, 0))
        self._none3 = np.zeros((0, 3))
        self._none1 = np.zeros(0)
        self._code_sig = np.full(lay.n_sv, self.code_noise_m)  # with channel states: their white code noise
        self._pl_sig = np.full(lay.n_pl, self.pl_sigma_states)  # with pseudolite states: code noise + survey
        self._nu = np.zeros((1, _MAX_ROWS))
        self._gbas = None
        self.gbas_scale = GbasScale.of(system)
        """GBAS code ranging: the channel states' scale along the approach (nav/gbas_scale.py), else None."""
        self._service = None
        if g is not None:  # the channel-noise budget of channel_sigmas
            bud = g.budget()
            self._sky_budget = (IONO_SHELL_M, bud.clock_ephemeris_m, bud.iono_zenith_m, bud.tropo_zenith_m,
                                bud.multipath_model == "do253", float(bud.multipath_m))
            if bud.gbas is not None:
                self._gbas = bud.gbas.channel_kernel_args()
            if bud.service is not None:  # a civil service's filter model (sensors/gnss/service.py)
                self._service = bud.service.filter_params()
        self.carrier = lay.has("amb")
        """Carrier phase: the rows, states and arc resets of kernels/carrier.py."""
        self.cp_r = float(system.rows.carrier_sigma_m) ** 2 if self.carrier else 0.0
        """The carrier rows' noise variance, m^2 (nav/rows.py's)."""
        self.amb_prior = float(g.carrier.ambiguity_sigma_m) ** 2 if self.carrier else 0.0
        """A float ambiguity's prior variance at a new arc, m^2 (nav/noise.py's P0 of amb)."""
        self._no_new = np.zeros(0, dtype=np.int64)
        self.loop = em.kernel_loop(system.loop_gains() if lay.has("ac") else None)
        """The damping loop's constant gains (the engine runs constant or no loops only)."""
        self.rows = kg.Rows(self.lay, self.tx, self.th, self.rwy, float(self.ra_pct), float(self.ra_floor),
                            self.channel_states, self.pl_states, self.cp_r, self.amb_prior,
                            float(system.baro_ref_m))
        """The rows' constants (core/nav/groups.Rows)."""

    def channel_sigmas(self, el: Array) -> tuple[Array, Array]:
        """The GPS channel states' slow and fast 1-sigma (m) at elevations el (N, k) rad, each element on its own:
        the receiver budget's channel_sigmas_m with nav/noise.py's elevation guard, compiled. Stand-alone:
        core/sensors/gnss.channel_sigmas; GBAS corrections: core/sensors/gnss.gbas_channel_sigmas at
        the approach's start (NoiseModel.gbas_geometry: the filter's elevation-only channel noise, as nav/noise.py
        builds it; the epochs take the aircraft's geometry from `gbas_scale` instead)."""
        el = np.ascontiguousarray(el, dtype=float)
        gse, gmp = np.empty(el.shape), np.empty(el.shape)
        if self._service is not None:
            gk.service_channel_sigmas(el, self._service, True, gse, gmp, np.empty(el.shape))
        elif self._gbas is None:
            gk.channel_sigmas(el, *self._sky_budget, gse, gmp)
        else:
            x, dh, v = (np.full(el.shape[0], g) for g in self.system.noise_model.gbas_geometry)
            gk.gbas_channel_sigmas(el, x, dh, v, *self._gbas, gse, gmp)
        return gse, gmp

    def carrier_channel_sigmas(self, el: Array) -> tuple[Array, Array, Array]:
        """Carrier phase: the GPS channel states' slow (without the ionosphere), ionospheric and fast 1-sigma (m) at
        elevations el (..., k) rad, each element on its own: nav/noise.py's floor (nan: 0.5 rad, at least 2 deg) and
        the receiver budget's carrier_channel_sigmas_m (elementwise numpy), broadcast to el's shape."""
        e = np.maximum(np.nan_to_num(np.asarray(el, dtype=float), nan=0.5), np.radians(2.0))
        out = self.system.sensors.gnss.budget().carrier_channel_sigmas_m(e)
        return tuple(np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), e.shape)) for a in out)

    @staticmethod
    def stack(dbs: list[RunDatabase]) -> tuple[Array, Array, Array]:
        """The runs' databases as (dbp (N, 4), db_x (k,), db_u (N, k)) for singletons (once per pass)."""
        db_x = dbs[0].db_x
        return (np.stack([d.dbp for d in dbs]), db_x,
                np.stack([d.db_u for d in dbs]) if db_x.size else np.zeros((len(dbs), 0)))

    @classmethod
    def of(cls, system: Any) -> EpochEngine | None:
        """The engine of `system`, or None when its configuration takes the generic path (module docstring)."""
        return cls(system) if cls.supports(system) else None

    @staticmethod
    def supports(system: Any) -> bool:
        """Whether `system` has the compiled epoch: the optimal Kalman filter on a configuration whose runs can share
        one covariance (NavSystem.shares_covariance)."""
        f = system.filter
        return isinstance(f, KalmanFilter) and f.policy is optimal_policy and system.shares_covariance()

    def _obs(self, obs: Observations, members: list[int], dbs: list[RunDatabase], ref_agl_m: float = 0.0,
             ref_sb: float = 0.0) -> kg.Obs:
        """The members' observations for core/nav/epoch.class_epoch (core/nav/groups.Obs); ref_agl_m, ref_sb: the
        shared rows' reference height above the terrain (m) and baro scale factor."""
        M = len(members)
        if M == 1:
            i = members[0]
            sl = slice(i, i + 1)
        else:
            sl = np.asarray(members)
        baro_h = obs.baro_h_m[sl] if obs.baro_h_m is not None else np.full(M, np.nan)
        baro_r = float(obs.baro_sigma_m) ** 2 if obs.baro_h_m is not None else 0.0
        radalt_h = obs.radalt_h_m[sl] if obs.radalt_h_m is not None else np.full(M, np.nan)
        if obs.has_gnss:
            rho = np.ascontiguousarray(obs.gnss_rho_m[sl])
            r_sv, sig_nom, _ = obs.sky(members[0])
            sig = self._code_sig if self.channel_states else np.ascontiguousarray(sig_nom, dtype=float)
            r_sv = np.ascontiguousarray(r_sv, dtype=float)
        else:
            rho, r_sv, sig = np.zeros((M, 0)), self._none3, self._none1
        cp = (np.ascontiguousarray(obs.gnss_phi_m[sl], dtype=float) if self.carrier and obs.gnss_phi_m is not None
              else self._none2 if M == 1 else np.zeros((M, 0)))
        if obs.pl_rho_m is not None:
            pl_rho = np.ascontiguousarray(obs.pl_rho_m[sl])
            r_pl = np.ascontiguousarray(obs.pl_r_ecef, dtype=float)
            pl_sig = self._pl_sig if self.pl_states else np.ascontiguousarray(obs.pl_sigma_m, dtype=float)
        else:
            pl_rho, r_pl, pl_sig = np.zeros((M, 0)), self._none3, self._none1
        if M == 1:
            dbp, db_x, db_u = dbs[0].dbp2, dbs[0].db_x, dbs[0].db_u2
        else:
            dbp = np.stack([d.dbp for d in dbs])
            db_x = dbs[0].db_x
            db_u = np.stack([d.db_u for d in dbs]) if db_x.size else np.zeros((M, 0))
        return kg.Obs(baro_h, baro_r, radalt_h, ref_agl_m, ref_sb, dbp, db_x, db_u, rho, r_sv, sig, cp, pl_rho, r_pl,
                      pl_sig)

    def epoch(self, X: Array, P: Array, phi: Array, qd: Array, own: bool, ref_y: Array, ins_y: Array,
              obs: Observations, members: list[int], t_s: float, statuses: list[StatusBuffer],
              dbs: list[RunDatabase], ref_agl_m: float = 0.0, ref_sb: float = 0.0, x_ready: bool = False) -> None:
        """One epoch of the members (indices into obs's runs) with estimates X (M, n) and covariance P, in place
        (core/nav/epoch.class_epoch); each member's status records go to its buffer. x_ready: X holds the
        predictions already (phi predicts P only: the per-run estimate's own model, nav/errormodel.MeanModel)."""
        M = len(members)
        o = self._obs(obs, members, dbs, ref_agl_m, ref_sb)
        if self._nu.shape[0] < M:
            self._nu = np.zeros((M, _MAX_ROWS))
        nu = self._nu[:M]
        k = ke.class_epoch(X, P, phi, qd, own, ref_y, ins_y, self.rows, o, kg.Out(self.codes, nu, self.S), self.scr,
                           False, x_ready)
        for j in range(M):
            statuses[j].add_epoch(self.codes[:k], t_s, nu[j, :k], self.S[:k])

    def own(self, X: Array, P: Array, y: Array, f_ned: Array, elevation_rad: Array | None, held: bool, dt: float,
            obs: Observations, i: int, t_s: float, statuses: StatusBuffer, db: RunDatabase,
            new: Array | None = None) -> bool:
        """The per-run EKF's whole epoch of run i (core/nav/epoch.run_epoch: its error model about its INS state y
        (16,) with the mean specific force f_ned (3,), discretized over dt, then every update), in place on X (1, n)
        and P. False when the model needs the numpy discretization (nothing changed: take the generic path). new (k,):
        carrier phase, the channels whose arc begins here (`new_arcs`; their ambiguities reset)."""
        if self.carrier:
            new = self._no_new if new is None else np.asarray(new, dtype=np.int64)
        else:
            new = self._no_new
        nu = self._nu[:1]
        k = ke.run_epoch(X, P, self.model_sigmas(elevation_rad, y, dt), y, f_ned, held, dt, new,
                         self.rows, self._obs(obs, [i], [db]), kg.Out(self.codes, nu, self.S), self.scr)
        if k < 0:
            return False
        statuses.add_epoch(self.codes[:k], t_s, nu[0, :k], self.S[:k])
        return True

    def model_sigmas(self, elevation_rad: Array | None, y: Array, dt: float) -> kg.ErrorModel:
        """A per-run epoch's error model constants: the noise arrays (NoiseModel.kernel_arrays, with carrier phase
        errormodel.kernel_carrier) and, under GBAS, the channel sigmas at the linearization point y's (16,)
        geometry with their scales over the interval dt (nav/gbas_scale.py; gse_r, gio_r (0,) otherwise)."""
        nm = self.system.noise_model
        q, gse, gmp = nm.kernel_arrays(elevation_rad)
        gio, gio_tau = (em.kernel_carrier(nm.noise(elevation_rad), self.system.layout.n_sv) if self.carrier
                        else (self._none1, 1.0))
        gse_r = gio_r = self._none1
        if self.gbas_scale is not None and elevation_rad is not None:
            el = np.asarray(elevation_rad, dtype=float).reshape(1, -1)
            n_sv = gse.shape[0]

            def c(a: Array) -> Array:
                return np.ascontiguousarray(np.broadcast_to(a[0], (n_sv,)))

            if self.carrier:
                g, i, m, r, r_io = self.gbas_scale.carrier_interval(el, y, dt)
                gse, gio, gmp, gse_r, gio_r = c(g), c(i), c(m), c(r), c(r_io)
            else:
                g, m, r = self.gbas_scale.interval(el, y, dt)
                gse, gmp, gse_r = c(g), c(m), c(r)
        return kg.ErrorModel(self.lay, q, gse, gmp, self.loop, gio, gio_tau, gse_r, gio_r)

    def singletons(self, X: Array, P3: Array, phi2: Array, qd2: Array, held: Array, obs: Observations, t_s: float,
                   dt: float, ins_y: Array, ref_y: Array, ref_agl_m: float, statuses: list[StatusBuffer],
                   db_stack: tuple[Array, Array, Array], new: Array | None = None, ref_sb: float = 0.0) -> None:
        """The shared-mode epoch of N runs each its own class (core/nav/epoch.copies_epoch), in place on X (N, n)
        and P3 (N, n, n); phi2, qd2 (2, n, n) the model without / with the damping loop held, held (N,) int; the
        GPS channel states' Qd at each run's own elevations; db_stack: the runs' databases (`stack`); new (N, k):
        carrier phase, the channels whose arc begins here in each run (`new_arcs`)."""
        N = X.shape[0]
        lay = self.system.layout
        baro_h = obs.baro_h_m if obs.baro_h_m is not None else np.full(N, np.nan)
        baro_r = float(obs.baro_sigma_m) ** 2 if obs.baro_h_m is not None else 0.0
        radalt_h = obs.radalt_h_m if obs.radalt_h_m is not None else np.full(N, np.nan)
        if obs.has_gnss:
            rho = np.ascontiguousarray(obs.gnss_rho_m)
            k = rho.shape[1]
            r_sv = np.ascontiguousarray(np.broadcast_to(obs.gnss_r_sv_ecef, (N, k, 3)), dtype=float)
            if self.channel_states:
                sig = np.ascontiguousarray(np.broadcast_to(self._code_sig, (N, k)))
            else:
                sig = np.ascontiguousarray(np.broadcast_to(obs.gnss_sigma_m, (N, k)), dtype=float)
        else:
            rho, r_sv, sig = np.zeros((N, 0)), np.zeros((N, 0, 3)), np.zeros((N, 0))
        if obs.pl_rho_m is not None:
            pl_rho = np.ascontiguousarray(obs.pl_rho_m)
            r_pl = np.ascontiguousarray(obs.pl_r_ecef, dtype=float)
            pl_sig = self._pl_sig if self.pl_states else np.ascontiguousarray(obs.pl_sigma_m, dtype=float)
        else:
            pl_rho, r_pl, pl_sig = np.zeros((N, 0)), self._none3, self._none1
        ch_gio, f_gio = np.zeros((N, 0)), 0.0
        gse_r = gio_r = np.zeros((N, 0))
        # one sky: qd2 is already at its elevations (but under GBAS at the reference geometry: set here)
        if lay.has("gse") and obs.has_gnss and (obs.per_run_sky or self.gbas_scale is not None):
            el = np.ascontiguousarray(np.broadcast_to(obs.gnss_el_rad, (N, np.shape(obs.gnss_el_rad)[-1])),
                                      dtype=float)
            nz = self.system.noise_model.noise(None)
            if self.carrier and self.gbas_scale is not None:  # the reference's geometry, gse and gio scaled apart
                ch_gse, ch_gio, ch_gmp, gse_r, gio_r = self.gbas_scale.carrier_interval(el, ref_y, dt)
                f_gio = float(-np.expm1(-2.0 * dt / nz.gio_tau_s))
            elif self.carrier:
                ch_gse, ch_gio, ch_gmp = self.carrier_channel_sigmas(el)
                f_gio = float(-np.expm1(-2.0 * dt / nz.gio_tau_s))
            elif self.gbas_scale is not None:  # at the reference's geometry, scaled over the interval
                ch_gse, ch_gmp, gse_r = self.gbas_scale.interval(el, ref_y, dt)
            else:
                ch_gse, ch_gmp = self.channel_sigmas(el)
            f_gse, f_gmp = (float(-np.expm1(-2.0 * dt / tau)) for tau in (nz.gse_tau_s, nz.gmp_tau_s))
        else:
            ch_gse = ch_gmp = np.zeros((N, 0))
            f_gse = f_gmp = 0.0
        cp = (np.ascontiguousarray(obs.gnss_phi_m, dtype=float) if self.carrier and obs.gnss_phi_m is not None
              else np.zeros((N, 0)))
        new = np.zeros((N, 0), dtype=np.int64) if new is None else np.ascontiguousarray(new, dtype=np.int64)
        dbp, db_x, db_u = db_stack
        codes = np.zeros((N, _MAX_ROWS), dtype=np.int64)
        nu = np.zeros((N, _MAX_ROWS))
        S = np.zeros((N, _MAX_ROWS))
        n_rows = np.zeros(N, dtype=np.int64)
        ke.copies_epoch(X, P3, phi2, qd2, held, ref_y, np.ascontiguousarray(ins_y),
                        kg.ChannelQd(ch_gse, ch_gmp, ch_gio, f_gse, f_gmp, f_gio, gse_r, gio_r),
                        kg.Obs(baro_h, baro_r, radalt_h, ref_agl_m, ref_sb, dbp, db_x, db_u, rho, r_sv, sig, cp, pl_rho,
                               r_pl, pl_sig), new, self.rows, kg.Out(codes, nu, S), n_rows, self.scr)
        for i in range(N):
            k = n_rows[i]
            statuses[i].add_epoch(codes[i, :k], t_s, nu[i, :k], S[i, :k])
