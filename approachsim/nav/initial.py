"""The converged pre-approach start of the navigation system ([nav.initial_error] start = "converged").

After GPS-aided flight the INS error is not an independent diagonal draw: it is correlated with the slow GPS
range errors, the clock, the baro bias and the IMU biases, and the filter already knows part of those. Two
steps build a start with exactly that structure.

1. Converged covariance (`converged_covariance`). P_conv is the optimal filter's a-posteriori covariance after
   converge_s seconds of aiding flown *at the start state* (the truth row: its position, velocity, attitude and
   specific force; the GNSS geometry and the sensors valid there), from today's prior P0, by iterating the
   filter's own recursion at the aiding interval:

       P- = Phi P+ Phi' + Qd                      (errormodel.dynamics + discretize)
       P+ = (I - K H) P- (I - K H)' + K R K'      K = P- H' (H P- H' + R)^-1, Joseph form

   H stacks the epoch's scalar rows valid at the start and R their (uncorrelated) noises: one batch update per
   epoch equals the filter's sequential scalar updates in exact arithmetic (to 1e-9 of the sigmas after 600 s,
   tested; 1.5e-13 measured) at a third to a fifth of the cost (benchmarks/bench_start.py: 0.14 s against
   0.66 s at the default profile's start).

   Why the recursion and not scipy.linalg.solve_discrete_are: the steady state does not exist here. Heading,
   the along-line-of-sight slow range errors against position, and the bias random walks are unobservable at
   one fixed geometry (not detectable), so the Riccati recursion has no stabilizing limit; and the question is a
   finite segment anyway (the filter has flown converge_s, not forever). The optimal filter's recursion is used
   for every filter variant: the robust gains equal it without outliers, the U-D form is the same algebra.

   converge_s = 600 s by default: ten minutes of aided flight before the final (the intermediate segment). The
   observable states settle within a few of their time constants (multipath 60 s, baro bias 100 s, clock and
   vertical channel in tens of seconds); horizontal position tends to the level the slow GPS range errors allow
   (1800 s time constant, inseparable from position at one geometry); heading and the bias random walks only
   grow. Default profile at its JSBSim start, 1-sigma N / E / D position: 60 s 3.81 / 2.66 / 1.03 m, 600 s
   4.53 / 2.84 / 0.97 m, 1800 s 4.83 / 2.92 / 0.85 m (the prior: 5 / 5 / 5 m); vertical velocity 0.023, 0.007,
   0.003 m/s (prior 0.05). Longer segments change the approach little and make the unobservable directions
   more conservative.

2. The true state and the estimate, jointly (`condition`). A converged optimal filter's error e = x - x_hat
   has covariance P_conv and is orthogonal to its estimate: E[e x_hat'] = 0, hence E[e x'] = P_conv. The
   sensor models have already drawn the sensor states x_s (sensors/states.py, prior covariance Pi_ss = the
   sensor block of P0, which the error budgets were built to match). For the jointly Gaussian (x_s, e) with
   cov(x_s) = Pi_ss and cov(e, x_s) = P_conv[:, s], conditioning (Bar-Shalom, Li & Kirubarajan, "Estimation
   with Applications to Tracking and Navigation", 2001, ch. 3: the fundamental equations of linear estimation):

       e | x_s ~ N( P_conv[:, s] Pi_ss^-1 x_s ,  P_conv - P_conv[:, s] Pi_ss^-1 P_conv[s, :] )

   The joint exists iff cov(x_hat_s) = Pi_ss - P_conv[s, s] >= 0 (checked). Then the INS true error is e_nav
   (dp, dv, psi and the loop compensator ac: the INS was reset by the pre-approach feedback, its estimate is
   0), the filter's estimate of the sensor states is x_hat_s = x_s - e_s, its covariance P_conv; and
   E[e x_hat'] = E[e x_s'] - E[e e_s'] = P_conv[:, s] - P_conv[:, s] = 0: orthogonal, as a converged filter is.

   Singular and unobservable states: states with zero prior variance are left out of s (their value is 0, so
   is e). A channel not in view at the start is never updated and stays decoupled: P_conv keeps its prior row
   exactly, and the conditioning gives e_j = x_j with zero variance (estimate 0, it keeps its prior). The
   filter models the IMU biases as random walks while the sensors' biases are stationary (turn-on constant +
   Gauss-Markov), so a bias combination the segment hardly observes can end with P_conv above its prior
   (default profile, 600 s: the vertical gyro bias direction, by 1.5 %); in those directions only the prior
   is raised to P_conv (`condition`), the draw takes e = x there, and the filter is conservative by that
   excess. The conditional covariance is factored by its eigen-decomposition (it is singular by design).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from approachsim.core.nav import kalman as kk
from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav.observations import Observations
from approachsim.sensors.states import STATE_GROUPS, SensorStates

Array = np.ndarray

NAV_GROUPS = ("dp", "dv", "psi", "ac")
"""Error-state groups that are INS states: their true value is the INS error, their start estimate 0."""

EIG_FLOOR = 1e-12
"""Eigenvalues of the conditional covariance, each state in units of its converged sigma, below this fraction of the
largest are taken as 0 (`conditioner`)."""

_PSD_TOL = 1e-9
"""Relative tolerance of the Pi_ss >= P_conv[s, s] check (eigenvalues of Pi^-1/2 P_conv Pi^-1/2 above 1)."""


def _segment(system: Any, truth: Any, obs: Observations, row: int, P0: Array, sb_ref: float = 0.0
             ) -> tuple[Array, Array, list]:
    """Phi, Qd over one aiding interval and the scalar measurement rows valid at truth row `row` (the segment
    flown at the start state), linearized at the baro scale factor sb_ref (the day's: sb_reference)."""
    lay = system.layout
    ref = ins.InsState(truth.lat_rad[row:row + 1], truth.lon_rad[row:row + 1], truth.h_m[row:row + 1],
                       truth.v_ned[row:row + 1], ins.cbn_from_quaternion(truth.q_nb[row:row + 1]), np.zeros(1))
    c_bn = ref.c_bn[0]
    f_ned = c_bn @ truth.f_body[row]
    noise = system.noise(obs.elevations(0))
    F, Qc = em.dynamics(lay, float(ref.lat_rad[0]), float(ref.h_m[0]), ref.v_ned[0], f_ned, c_bn, noise,
                        system.loop_gains())
    phi, qd = em.discretize(F, Qc, 1.0 / system.nav.aiding_rate_hz)
    r_ref = ins.position_ecef(ref)[0]
    x0 = np.zeros(lay.n)
    if lay.has("sb"):
        x0[lay.i("sb")] = sb_ref
    t = float(truth.t_s[row])
    ref_obs = system.rows.reference_obs(obs, 0, float(ref.h_m[0]), r_ref)
    # code only: the carrier's arcs begin at the approach's first sample (sensors/gnss/carrier.py), so the segment
    # flown before it has no carrier, and the float ambiguities start at their prior, uncorrelated
    ref_obs = replace(ref_obs, gnss_phi_m=None, gnss_arc=None)
    rows = [r.build(x0) for r in system.rows.epoch(ref, 0, r_ref, ref_obs, t)]
    return phi, qd, rows


def converged_covariance(system: Any, truth: Any, obs: Observations, row: int, P0: Array,
                         converge_s: float, sb_ref: float = 0.0) -> Array:
    """P_conv (n, n): the optimal filter's covariance after converge_s (s) of aiding at truth row `row` from P0,
    with the measurements available in obs (NavSystem.observations at the row; the first run's schedule), the
    model linearized at the baro scale factor sb_ref (sb_reference).

    The filter's own recursion, one scalar Joseph update per row, compiled (core/nav/kalman.riccati: the states
    never measured and not coupled evolve alone, an exact reduction); converged_covariance_reference is the same
    recursion in numpy (the test oracle)."""
    phi, qd, rows = _segment(system, truth, obs, row, P0, sb_ref)
    epochs = int(round(converge_s * system.nav.aiding_rate_hz))
    n = P0.shape[0]
    H = np.stack([m.h for m in rows]) if rows else np.zeros((0, n))  # (k, n): the epoch's scalar rows
    R = np.array([float(m.r) for m in rows])
    P = np.array(P0, dtype=float)
    kk.riccati(P, np.ascontiguousarray(phi), np.ascontiguousarray(qd), np.ascontiguousarray(H), R, epochs)
    return P


def converged_covariance_reference(system: Any, truth: Any, obs: Observations, row: int, P0: Array,
                                   converge_s: float, sb_ref: float = 0.0) -> Array:
    """converged_covariance with one Joseph update per scalar row, the filter's own sequential form: the test
    oracle and the benchmark's reference (benchmarks/bench_start.py)."""
    phi, qd, rows = _segment(system, truth, obs, row, P0, sb_ref)
    P = np.array(P0, dtype=float)
    eye = np.eye(P.shape[0])
    for _ in range(int(round(converge_s * system.nav.aiding_rate_hz))):
        P = phi @ P @ phi.T + qd
        for m in rows:
            K = P @ m.h / float(m.h @ P @ m.h + m.r)
            A = eye - np.outer(K, m.h)
            P = A @ P @ A.T + m.r * np.outer(K, K)
        P = 0.5 * (P + P.T)
    return P


def sensor_vector(layout: em.StateLayout, states: SensorStates, P0: Array) -> tuple[Array, Array]:
    """(s,) indices of the sensor states with a nonzero prior and (N, s) their realized values.

    Every layout group that is not an INS state (NAV_GROUPS) must be realized by `states`
    (sensors/states.py); a group with no realization is an error, not a silent zero."""
    idx, vals = [], []
    prior = np.diag(P0)
    for g in layout.groups:
        if g in NAV_GROUPS:
            continue
        sl = layout.index[g]
        v = states.group(g) if g in STATE_GROUPS else None
        if v is None:
            if np.all(prior[sl] == 0.0):
                continue
            raise ValueError(f"converged start: no realized sensor value for filter state group {g!r} "
                             "(add it to sensors/states.py _EXTRACT)")
        if v.shape[1] != sl.stop - sl.start:
            raise ValueError(f"converged start: state group {g!r} has {v.shape[1]} values, the filter "
                             f"{sl.stop - sl.start}")
        keep = prior[sl] > 0.0
        idx.append(np.arange(sl.start, sl.stop)[keep])
        vals.append(v[:, keep])
    if not idx:
        return np.zeros(0, dtype=int), np.zeros((states.runs, 0))
    return np.concatenate(idx), np.concatenate(vals, axis=1)


@dataclass(frozen=True)
class Conditioner:
    """The conditional law of the estimation error given the realized sensor states (`conditioner`): the mean
    operator G = P_conv[:, s] Pi^-1 (n, s), the symmetric square root L (n, n) of the conditional covariance, the
    sensor-state indices s and the excess of the Pi_ss >= P_conv[s, s] check."""

    G: Array
    L: Array
    s: Array
    excess: float

    def apply(self, x_s: Array, z: Array) -> Array:
        """Errors e (N, n) = G x_s + L z of the runs (x_s (N, s), standard normals z (N, n)), one matrix-vector
        product per run: a run's draw must not depend on the batch it shares (no batch-size-dependent BLAS path;
        the campaign relies on it)."""
        n = self.L.shape[0]
        mean = (np.stack([self.G @ xi for xi in x_s]) if len(x_s) and self.s.size
                else np.zeros((z.shape[0], n)))
        return mean + np.stack([self.L @ zi for zi in z]).reshape(mean.shape)


def conditioner(P_conv: Array, Pi_ss: Array, s: Array) -> Conditioner:
    """The law of e given x_s: e = P_conv[:, s] Pi^-1 x_s + L z, L L' = P_conv - P_conv[:, s] Pi^-1 P_conv[s, :].

    Check Pi_ss >= P_conv[s, s]: the eigenvalues lambda of W = D P_conv[s, s] D, D = diag(Pi_ss)^-1/2, must not
    exceed 1. Where they do (the filter's random-walk bias model grown past the sensors' stationary prior), the
    prior is raised to P_conv in those directions only, Pi = D^-1 V max(Lambda, 1) V' D^-1: the draw takes
    e = x there and the conditional covariance stays positive (its Schur complement)."""
    n = P_conv.shape[0]
    if not s.size:
        G, C, excess = np.zeros((n, 0)), P_conv, 0.0
    else:
        d = 1.0 / np.sqrt(np.diag(Pi_ss))
        lam, V = np.linalg.eigh(d[:, None] * P_conv[np.ix_(s, s)] * d[None, :])
        excess = max(float(lam.max()) - 1.0, 0.0)
        Pi = Pi_ss
        if excess > _PSD_TOL:
            w = np.sqrt(np.maximum(lam, 1.0))
            Pi = (V * w[None, :]) @ (V * w[None, :]).T / (d[:, None] * d[None, :])
        G = np.linalg.solve(Pi, P_conv[s, :]).T  # P_conv[:, s] Pi^-1  (n, s)
        C = P_conv - G @ P_conv[s, :]
    C = 0.5 * (C + C.T)
    # in the states' own scales: C mixes units (gyro bias variances ~1e-14 rad^2/s^2 beside the clock's 1e4 m^2), so a
    # floor relative to its largest eigenvalue zeroed whole state directions (the gyro biases' independent part: the
    # drawn estimation error came out smaller than P_conv, and the filter over-claimed the horizontal velocity by
    # 20 % over the approach, docs/consistency.md); its eigen-decomposition is taken of D^-1 C D^-1, D =
    # diag(P_conv)^1/2, each state in units of its own converged sigma, where rounding is relative to 1 everywhere
    sd = np.sqrt(np.maximum(np.diag(P_conv), 0.0))
    inv = np.divide(1.0, sd, out=np.zeros_like(sd), where=sd > 0.0)
    w, V = np.linalg.eigh(inv[:, None] * C * inv[None, :])
    scale = max(float(np.max(np.abs(w))), 1e-300)
    if w.min() < -1e-9 * scale:
        raise ValueError(f"converged start: conditional covariance not positive ({w.min():.3g})")
    # L = D V sqrt(Lambda) V' (L L' = C): V sqrt(Lambda) V' is the scaled C's symmetric square root, unique, so L
    # is continuous in C. A factor V sqrt(Lambda) alone depends on the eigenvector basis, which rounding rotates
    # freely within (near-)repeated eigenvalues: a rounding-level change of P_conv would then redraw the run.
    # Eigenvalues of the scaled C below EIG_FLOOR of the largest are rounding (C is singular by design) and taken
    # as 0: a square root turns a rounding change d of a zero eigenvalue into a sqrt(d) change of the draw
    L = sd[:, None] * ((V * np.sqrt(np.where(w > EIG_FLOOR * scale, w, 0.0))[None, :]) @ V.T)
    return Conditioner(G, L, np.asarray(s), excess)


def condition(P_conv: Array, Pi_ss: Array, s: Array, x_s: Array, z: Array) -> tuple[Array, float]:
    """Estimation errors e (N, n) given the realized sensor states x_s (N, s) at indices s, from standard
    normals z (N, n) (`conditioner` then `Conditioner.apply`), and the excess max(lambda) - 1 >= 0."""
    c = conditioner(P_conv, Pi_ss, s)
    if c.s.size and x_s.shape[1:] != (c.s.size,):
        raise ValueError(f"converged start: sensor states of shape {x_s.shape}, {c.s.size} expected per run")
    return c.apply(x_s, z), c.excess


@dataclass(frozen=True)
class Prepared:
    """What the runs of one start (row, sky, schedule, P0) share: P_conv and its Conditioner."""

    P_conv: Array
    cond: Conditioner

def sb_reference(states: SensorStates | None) -> float:
    """The baro scale factor the shared covariance is linearized at: the day's (SensorStates.sb_day, the same for
    every run on the truth), 0 without realized states or a baro (nav/shared.py SharedCovariance.sb_ref)."""
    return 0.0 if states is None or states.sb_day is None else float(states.sb_day)


def draw(system: Any, truth: Any, obs: Observations, states: SensorStates, rngs: list[np.random.Generator],
         row: int, P0: Array, prepared: Prepared | None = None) -> tuple[Array, Array, Prepared]:
    """(e (N, n) the estimation errors, x_hat (N, n) the filter's start estimates, the start's Prepared (P_conv
    (n, n) and the conditioner)) of the runs (rngs: each run's "nav" stream, n standard normals each). prepared:
    when already made for this start (it depends on the start row, its sky and schedule and P0 only)."""
    lay = system.layout
    if states.runs != len(rngs):
        raise ValueError(f"converged start: {states.runs} runs of sensor states for {len(rngs)} runs")
    s, x_s = sensor_vector(lay, states, P0)
    if prepared is None:
        P_conv = converged_covariance(system, truth, obs, row, P0, system.nav.initial_error.converge_s,
                                      sb_reference(states))
        prepared = Prepared(P_conv, conditioner(P_conv, P0[np.ix_(s, s)], s))
    if not np.array_equal(prepared.cond.s, s):
        raise ValueError("converged start: the prepared start has other sensor states than these runs")
    z = np.stack([g.standard_normal(lay.n) for g in rngs])
    e = prepared.cond.apply(x_s, z)
    x_hat = np.zeros_like(e)
    x_hat[:, s] = x_s - e[:, s]  # the INS states' estimate is 0 (reset); x_hat_s = x_s - e_s
    return e, x_hat, prepared
