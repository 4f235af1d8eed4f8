"""Benchmark: U-D filter cost against the Joseph-form KF, and the batched U-D kernels against per-run filters.

Run: python benchmarks/bench_ud.py   (prints ratios; results recorded in benchmarks/RESULTS.md)
"""

from __future__ import annotations

import time

import numpy as np

from approachsim.nav.base import KalmanFilter, ScalarMeasurement
from approachsim.nav.ud import InfluenceFunction, UDFilter, robust_update_batch, thornton_predict_batch


def _time(fn, repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def single_filter(n: int = 17, steps: int = 200, meas: int = 8) -> tuple[float, float]:
    """Seconds for `steps` predict + `meas` scalar updates: Joseph KF and U-D (n states, the nav EKF's size)."""
    rng = np.random.default_rng(0)
    F = np.eye(n) + 0.01 * rng.normal(size=(n, n))
    Q = np.diag(rng.random(n) * 1e-3)
    H = rng.normal(size=(meas, n))
    z = rng.normal(size=(steps, meas))

    def run(f):
        s = f.init(np.zeros(n), np.eye(n))
        for k in range(steps):
            s = f.predict(s, F, Q)
            for j in range(meas):
                s, _ = f.update(s, ScalarMeasurement(float(z[k, j]), H[j], 0.5))

    return _time(lambda: run(KalmanFilter())), _time(lambda: run(UDFilter()))


def batched(runs: int = 100, steps: int = 500) -> tuple[float, float]:
    """Seconds for the seed-004 sized problem (2 states): per-run UDFilter objects vs the batched kernels."""
    rng = np.random.default_rng(1)
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = np.diag([1e-4, 1e-6])
    h, r = np.array([1.0, 0.0]), 1.0
    z = rng.normal(size=(runs, steps))
    inf = InfluenceFunction("gauss-laplace")
    f = UDFilter(influence=inf)

    def per_run():
        for i in range(runs):
            s = f.init(np.zeros(2), np.eye(2))
            for k in range(steps):
                s, _ = f.update(f.predict(s, F, Q), ScalarMeasurement(float(z[i, k]), h, r))

    def batch():
        x = np.zeros((runs, 2))
        U = np.broadcast_to(np.eye(2), (runs, 2, 2)).copy()
        d = np.ones((runs, 2))
        for k in range(steps):
            U, d = thornton_predict_batch(U, d, F, Q)
            x = x @ F.T
            x, U, d, *_ = robust_update_batch(x, U, d, z[:, k], h, r, inf)

    return _time(per_run, 1), _time(batch)


if __name__ == "__main__":
    kf, ud = single_filter()
    print(f"single filter, 17 states, 200 steps x 8 scalar updates: Joseph {kf:.3f} s, U-D {ud:.3f} s, "
          f"U-D / Joseph = {ud / kf:.2f}")
    loop, vec = batched()
    print(f"robust U-D, 100 runs x 500 epochs: per-run objects {loop:.2f} s, batched kernels {vec:.3f} s, "
          f"speed-up {loop / vec:.1f}x")
