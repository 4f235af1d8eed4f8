"""Converged-start benchmark: the 600 s covariance recursion of nav/initial.py at the default profile's start, by
the compiled Riccati kernel (core/nav/kalman.riccati: the filter's sequential scalar Joseph updates, the states never
measured and not coupled reduced exactly; what the code does) against the same recursion in numpy (the reference,
initial.converged_covariance_reference), and their largest difference in units of the sigmas.

    python benchmarks/bench_start.py [--repeat N]

Prints wall times (min of N) and the ratio; no pass/fail. Results go in benchmarks/RESULTS.md under
"Converged start".
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from approachsim import synthetic
from approachsim.nav import initial
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    prof = load_profile(ROOT / "profiles" / "default.toml")
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=10.0, start_distance_m=350.0,
                                        ground_speed_mps=70.0)
    recs, _ = measure_with_states(SensorSuite.from_profile(prof), truth, seed=2, runs=[0])
    nav = NavSystem.from_profile(prof)
    obs = nav.observations(recs, float(truth.t_s[0]), 0.025, True)
    obs = obs.run(0) if obs.per_run_sky else obs
    el = recs["gnss"].elevation_rad[0, 0] if recs["gnss"].per_run_sky else recs["gnss"].elevation_rad[0]
    P0 = nav.initial_covariance(el)
    converge_s = prof.nav.initial_error.converge_s
    tb, ts = [], []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        Pb = initial.converged_covariance(nav, truth, obs, 0, P0, converge_s)
        tb.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        Ps = initial.converged_covariance_reference(nav, truth, obs, 0, P0, converge_s)
        ts.append(time.perf_counter() - t0)
    sd = np.sqrt(np.diag(Ps))
    print(f"load average {os.getloadavg()[0]:.2f}; {nav.layout.n} states, converge_s {converge_s:g} s")
    print(f"compiled Riccati kernel (converged_covariance) {min(tb):.4f} s")
    print(f"numpy sequential rows (the reference)          {min(ts):.4f} s")
    dmax = float(np.max(np.abs(Pb - Ps) / np.outer(sd, sd)))
    print(f"ratio reference / compiled {min(ts) / min(tb):.1f}; max |dP| / (sigma sigma) {dmax:.1e}")


if __name__ == "__main__":
    main()
