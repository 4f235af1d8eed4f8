"""Benchmark: the batched robust-KF core (nav.robust.update_batch) against the per-run filter objects.

Runs Hajiyev & Saltoglu's 5-state model (seed 000, section 7) with the binary-gate and adaptive RKFs,
100 runs x 500 steps, both ways; checks they agree and prints the wall-time ratio. Not a test.
Usage: python benchmarks/robust_batch.py [runs]
"""

from __future__ import annotations

import sys
import time

import numpy as np

from approachsim.nav.base import ScalarMeasurement
from approachsim.nav.robust import AdaptivePolicy, GatePolicy, adaptive_filter, gate_filter, predict_batch, update_batch
from approachsim.papers.hajiyev_saltoglu import H_ROW, Section7
from approachsim.seeding import stream


def main(runs: int = 100) -> None:
    p = Section7()
    F, Q = p.transition(), p.process_noise()
    z = np.stack([stream(1, r, "bench").normal(size=p.steps) * np.sqrt(p.r_m2) for r in range(runs)])
    P0 = np.diag(np.square(p.x0))
    for policy, make in ((GatePolicy(), gate_filter), (AdaptivePolicy(), adaptive_filter)):
        t0 = time.perf_counter()
        x, P = np.zeros((runs, 5)), np.tile(P0, (runs, 1, 1))
        for k in range(p.steps):
            x, P = predict_batch(x, P, F, Q)
            x, P, _, _ = update_batch(x, P, z[:, k], H_ROW, p.r_m2, policy)
        t_batch = time.perf_counter() - t0
        t0 = time.perf_counter()
        f = make()
        xs = []
        for r in range(runs):
            s = f.init(np.zeros(5), P0)
            for k in range(p.steps):
                s = f.predict(s, F, Q)
                s, _ = f.update(s, ScalarMeasurement(float(z[r, k]), H_ROW, p.r_m2))
            xs.append(s.x)
        t_obj = time.perf_counter() - t0
        agree = np.max(np.abs(np.array(xs) - x))
        print(f"{type(policy).__name__}: {runs} runs x {p.steps} steps: batched {t_batch:.3f} s, per-run objects "
              f"{t_obj:.3f} s, ratio {t_obj / t_batch:.1f}x, max |x difference| {agree:.1e}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100)
