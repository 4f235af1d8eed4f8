"""Navigation benchmarks: one closed-loop default approach (JSBSim + sensors + INS + EKF + autopilot) against
flying the same approach on truth and against raw JSBSim stepping of the same number of steps; plus the
open-loop navigation pass alone and its per-step split.

    python benchmarks/bench_nav.py [--repeat N] [--profile PATH]

Prints wall times and ratios (product goal: closed loop / raw JSBSim <= 2); no pass/fail. Results go in
benchmarks/RESULTS.md under "Navigation".
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from approachsim.flight.fdm import FDM
from approachsim.flight.run import Approach
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream, stream_int
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--profile", default=str(ROOT / "profiles" / "default.toml"))
    args = ap.parse_args()
    profile = load_profile(args.profile)
    approach = Approach(profile)
    approach.fly(seed=1)  # warm up
    closed, truth_fly, raw, open_nav, sensors = [], [], [], [], []
    n = 0
    for i in range(args.repeat):
        t0 = time.perf_counter()
        src = NavInTheLoop(profile, seed=1, run=i, max_time_s=approach.time_budget_s)
        res = approach.fly(seed=1, run=i, nav_source=src)
        src.result(res.truth)
        closed.append(time.perf_counter() - t0)
        print(f"run {i}: closed loop {res.termination}, lowest {res.lowest_height_ft:.0f} ft, {closed[-1]:.1f} s")
        n = len(res.truth)
        t0 = time.perf_counter()
        r = approach.fly(seed=1, run=i)
        truth_fly.append(time.perf_counter() - t0)
        fdm = FDM(approach.aircraft.jsbsim_model, approach.dt_s)
        t0 = time.perf_counter()
        fdm.initialize_and_trim(approach.start())
        fdm.set_seed(stream_int(1, i, "turbulence"))
        step = fdm.run
        for _ in range(n - 1):
            step()
        raw.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        recs, st = measure_with_states(SensorSuite.from_profile(profile), r.truth, seed=1, runs=i)
        sensors.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        NavSystem.from_profile(profile).run(r.truth, recs, stream(1, i, "nav"), states=st)
        open_nav.append(time.perf_counter() - t0)
    med = statistics.median
    hz = profile.rates.imu_hz
    print(f"profile {profile.name}: {n} steps at {hz:g} Hz = {n / hz:.1f} s of flight; median of {args.repeat}")
    print(f"  closed loop (JSBSim + sensors + INS + EKF + autopilot): {med(closed):.2f} s "
          f"({med(closed) / n * 1e6:.0f} us/step)")
    print(f"  same approach flown on truth (Approach.fly):            {med(truth_fly):.2f} s")
    print(f"  raw JSBSim stepping (trim + run()):                     {med(raw):.2f} s")
    print(f"  ratio closed / raw JSBSim: {med(closed) / med(raw):.1f}   closed / truth flight: "
          f"{med(closed) / med(truth_fly):.1f}   (product goal <= 2)")
    print(f"  open loop: sensors {med(sensors):.2f} s, navigation pass {med(open_nav):.2f} s "
          f"({med(open_nav) / n * 1e6:.0f} us/step)")


if __name__ == "__main__":
    main()
