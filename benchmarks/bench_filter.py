"""Filter-alone benchmark (issue 5): an 18-state error-state Kalman filter over a 10-minute approach.

    python benchmarks/bench_filter.py [--runs 1000] [--batched-runs 200] [--loop-runs 4]

The problem (issue 5 "speed anchors"): 18 error states (position, velocity, attitude, gyro and accelerometer
biases, baro bias, receiver clock bias and drift; nav.errormodel's layout and F along a synthetic 3-degree
descent, Van Loan discretization), 30,000 predicts at 50 Hz and 4,200 scalar updates (7 per second: baro,
radar altimeter, five pseudoranges) per run. Phi and Qd are built once per second of the approach (600 of
them) before any timing and are the same for every method and run: the open-loop runs share one truth.

Methods (all Joseph-form covariance updates, the same numbers to rounding: checked and printed):
  filterpy   filterpy.kalman.KalmanFilter, one object per run in a Python loop (the reference; install
             filterpy for it: it is not an approachsim dependency; the column is skipped when missing)
  per-run    approachsim.nav.base.KalmanFilter objects, one per run in a Python loop
  batched    numpy batched over runs, runs on the last axis: each run keeps its own covariance (what robust,
             per-run-gated filters need); the predict is two (n x n) @ (n x n N) products
  shared     one covariance and gain for every run (NavSystem.run(..., shared_covariance=True): the optimal
             filter on a shared truth and measurement schedule), the N states as one (N, n) matrix
FLOP floor: the arithmetic of the per-run-covariance filter (predict 4 n^3 + 2 n^2, update ~10 n^2) at the
machine's measured dgemm rate on 2 threads; for `shared` its own floor (the covariance once, states per run).
Prints times per run and ratios; no pass/fail. Results go in benchmarks/RESULTS.md. The batched column's
products have an inner dimension of 18: on a shared machine run with OPENBLAS_NUM_THREADS=1 (two BLAS threads
fighting other jobs made it 10x slower here); everything runs in one process (one core).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from approachsim import synthetic
from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav.base import KalmanFilter, ScalarMeasurement
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile

DURATION_S = 600.0
PREDICT_HZ = 50.0
N_UPDATES = 7  # per second: baro, radar altimeter, five pseudoranges


def build_problem(seed: int = 1) -> dict:
    """Phi, Qd (per second of the approach), the measurement rows H (600, 7, n) and R (7,)."""
    prof = load_profile("profiles/default.toml")
    nav = NavSystem.from_profile(prof)
    lay = em.StateLayout(baro_scale=False, clock=True, loop=False, n_sv=0, n_pl=0, pl_clock=False)
    assert lay.n == 18, lay.n
    noise = nav.noise()
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=1.0, start_distance_m=70.0 * DURATION_S,
                                        ground_speed_mps=70.0)
    n_sec = int(DURATION_S)
    c_bn = ins.cbn_from_quaternion(truth.q_nb)
    f_ned = np.einsum("kij,kj->ki", c_bn, truth.f_body)
    dt = 1.0 / PREDICT_HZ
    phis, qds, phi1, q1 = [], [], [], []
    for k in range(n_sec):
        F, Qc = em.dynamics(lay, float(truth.lat_rad[k]), float(truth.h_m[k]), truth.v_ned[k], f_ned[k], c_bn[k],
                            noise)
        p, q = em.discretize(F, Qc, dt)
        phis.append(p)
        qds.append(q)
        p, q = em.discretize(F, Qc, 1.0)
        phi1.append(p)
        q1.append(q)
    rng = np.random.default_rng(seed)
    H = np.zeros((n_sec, N_UPDATES, lay.n))
    H[:, 0, lay.i("dp", 2)] = -1.0  # baro: -dp_D - bb
    H[:, 0, lay.i("bb")] = -1.0
    H[:, 1, lay.i("dp", 2)] = -1.0  # radar altimeter over flat terrain
    los = rng.normal(size=(5, 3))
    los[:, 2] = -np.abs(los[:, 2]) - 0.3  # satellites above the horizon (line of sight points up: -D)
    los /= np.linalg.norm(los, axis=1, keepdims=True)
    for k in range(n_sec):  # slowly turning geometry
        a = 2e-4 * k
        rot = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        H[k, 2:, lay.index["dp"]] = -(los @ rot.T)
        H[k, 2:, lay.i("clk")] = -1.0
    R = np.array([1.0, 1.5, 1.0, 1.0, 1.0, 1.0, 1.0]) ** 2
    P0 = nav.initial_covariance()[:18, :18].copy()
    P0[16:18, 16:18] = np.diag([30.0**2, 0.1**2])
    return {"phi": np.array(phis), "qd": np.array(qds), "phi1": np.array(phi1), "q1": np.array(q1), "H": H,
            "R": R, "P0": P0, "n": lay.n, "n_sec": n_sec, "steps_per_s": int(PREDICT_HZ)}


def measurements(pb: dict, n_runs: int, seed: int = 2) -> np.ndarray:
    """z (n_sec, 7, N): rows of a true error state drawn from P0 and propagated once per second."""
    rng = np.random.default_rng(seed)
    n = pb["n"]
    x = rng.normal(size=(n_runs, n)) @ np.linalg.cholesky(pb["P0"]).T
    z = np.empty((pb["n_sec"], N_UPDATES, n_runs))
    for k in range(pb["n_sec"]):
        x = x @ pb["phi1"][k].T + rng.normal(size=(n_runs, n)) @ np.linalg.cholesky(
            pb["q1"][k] + 1e-30 * np.eye(n)).T
        z[k] = pb["H"][k] @ x.T + np.sqrt(pb["R"])[:, None] * rng.normal(size=(N_UPDATES, n_runs))
    return z


def run_filterpy(pb: dict, z: np.ndarray, runs: int) -> np.ndarray:
    from filterpy.kalman import KalmanFilter as FPKalman

    out = np.empty((runs, pb["n"]))
    for i in range(runs):
        kf = FPKalman(dim_x=pb["n"], dim_z=1)
        kf.x = np.zeros((pb["n"], 1))
        kf.P = pb["P0"].copy()
        for k in range(pb["n_sec"]):
            phi, qd = pb["phi"][k], pb["qd"][k]
            for _ in range(pb["steps_per_s"]):
                kf.predict(F=phi, Q=qd)
            for j in range(N_UPDATES):
                kf.update(z[k, j, i], R=pb["R"][j], H=pb["H"][k, j][None, :])
        out[i] = kf.x[:, 0]
    return out


def run_per_run(pb: dict, z: np.ndarray, runs: int) -> np.ndarray:
    kf = KalmanFilter()
    out = np.empty((runs, pb["n"]))
    for i in range(runs):
        fs = kf.init(np.zeros(pb["n"]), pb["P0"])
        for k in range(pb["n_sec"]):
            phi, qd = pb["phi"][k], pb["qd"][k]
            for _ in range(pb["steps_per_s"]):
                fs = kf.predict(fs, phi, qd)
            for j in range(N_UPDATES):
                fs, _ = kf.update(fs, ScalarMeasurement(z=float(z[k, j, i]), h=pb["H"][k, j], r=float(pb["R"][j]),
                                                        name="m", t_s=float(k)))
        out[i] = fs.x
    return out


def run_batched(pb: dict, z: np.ndarray, runs: int) -> np.ndarray:
    """Per-run covariances, runs on the last axis: P (n, n, N), x (n, N)."""
    n = pb["n"]
    x = np.zeros((n, runs))
    P = np.repeat(pb["P0"][:, :, None], runs, axis=2)
    for k in range(pb["n_sec"]):
        phi, qd = pb["phi"][k], pb["qd"][k][:, :, None]
        for _ in range(pb["steps_per_s"]):
            x = phi @ x
            A = (phi @ P.reshape(n, n * runs)).reshape(n, n, runs)  # A[i, k, r] = (Phi P_r)[i, k]
            # (Phi P Phi')[l, i] = sum_k Phi[l, k] A[i, k]: the second product on A with its first two axes swapped
            P = (phi @ A.transpose(1, 0, 2).reshape(n, n * runs)).reshape(n, n, runs) + qd
        for j in range(N_UPDATES):
            h, r = pb["H"][k, j], pb["R"][j]
            Ph = (h @ P.reshape(n, n * runs)).reshape(n, runs)  # P h (P symmetric)
            S = h @ Ph + r
            K = Ph / S
            x = x + K * (z[k, j] - h @ x)
            # Joseph form (I - K h') P (I - K h')' + r K K' expanded: P - K Ph' - Ph K' + S K K'
            P = P - K[:, None, :] * Ph[None, :, :] - Ph[:, None, :] * K[None, :, :] + S * K[:, None, :] * K[None, :, :]
    return x.T


def run_shared(pb: dict, z: np.ndarray, runs: int) -> np.ndarray:
    """One covariance and gain for all runs (NavSystem.aid_shared's algebra), states as one (N, n) matrix."""
    n = pb["n"]
    X = np.zeros((runs, n))
    P = pb["P0"].copy()
    eye = np.eye(n)
    for k in range(pb["n_sec"]):
        phi, qd = pb["phi"][k], pb["qd"][k]
        phi_t = phi.T
        for _ in range(pb["steps_per_s"]):
            X = X @ phi_t
            P = phi @ P @ phi_t + qd
        for j in range(N_UPDATES):
            h, r = pb["H"][k, j], pb["R"][j]
            Ph = P @ h
            S = float(h @ Ph + r)
            K = Ph / S
            X += np.outer(z[k, j] - X @ h, K)
            A = eye - np.outer(K, h)
            P = A @ P @ A.T + r * np.outer(K, K)
    return X


def dgemm_rate() -> float:
    """Measured dgemm rate (FLOP/s) on this machine with the current BLAS threads (best of 3, 1500^3)."""
    a = np.random.default_rng(0).normal(size=(1500, 1500))
    best = np.inf
    for _ in range(3):
        t = time.perf_counter()
        a @ a
        best = min(best, time.perf_counter() - t)
    return 2.0 * 1500**3 / best


def _timed(fn, *args) -> tuple[float, np.ndarray]:
    t = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1000, help="runs of the shared-covariance filter")
    ap.add_argument("--batched-runs", type=int, default=200, help="runs of the batched per-run-covariance filter")
    ap.add_argument("--loop-runs", type=int, default=4, help="runs of the per-run Python loops")
    a = ap.parse_args()
    env = {k: os.environ.get(k, "(unset)") for k in ("OPENBLAS_CORETYPE", "OPENBLAS_NUM_THREADS")}
    print(f"{env}; building the problem ...")
    pb = build_problem()
    n, n_pred, n_upd = pb["n"], pb["n_sec"] * pb["steps_per_s"], pb["n_sec"] * N_UPDATES
    z = measurements(pb, max(a.runs, a.batched_runs, a.loop_runs))
    print(f"{n} states, {n_pred} predicts + {n_upd} scalar updates per run")
    res: dict[str, tuple[float, int, np.ndarray]] = {}
    try:
        import filterpy  # noqa: F401
        t, x = _timed(run_filterpy, pb, z, a.loop_runs)
        res["filterpy"] = (t, a.loop_runs, x)
    except ImportError:
        print("filterpy: SKIPPED (not installed; `pip install filterpy` to get the reference column)")
    for name, fn, runs in (("per-run", run_per_run, a.loop_runs), ("batched", run_batched, a.batched_runs),
                           ("shared", run_shared, a.runs)):
        t, x = _timed(fn, pb, z[:, :, :runs], runs)
        res[name] = (t, runs, x)
    rate = dgemm_rate()
    flops_run = n_pred * (4 * n**3 + 2 * n**2) + n_upd * 10 * n**2
    floor = flops_run / rate
    flops_shared = n_pred * 2 * n**2 + n_upd * 6 * n  # per run; the covariance once per campaign
    floor_shared = flops_shared / rate + (n_pred * 4 * n**3 + n_upd * 4 * n**3) / rate / a.runs
    print(f"dgemm rate {rate / 1e9:.1f} GFLOP/s; FLOP floor per run: per-run covariance {floor * 1e3:.2f} ms "
          f"({flops_run / 1e6:.0f} MFLOP), shared covariance {floor_shared * 1e3:.3f} ms")
    ref = res["per-run"][2]
    for name, (t, runs, x) in res.items():
        per = t / runs
        dev = np.max(np.abs(x[: ref.shape[0]] - ref)) if runs >= 1 else np.nan
        line = f"{name:9s} {runs:5d} runs {t:8.2f} s  {per * 1e3:9.2f} ms/run  max |x - per-run| {dev:.1e}"
        if "filterpy" in res:
            line += f"  filterpy/this {res['filterpy'][0] / res['filterpy'][1] / per:7.1f}x"
        line += f"  this/floor {per / (floor_shared if name == 'shared' else floor):6.2f}"
        print(line)


if __name__ == "__main__":
    main()
