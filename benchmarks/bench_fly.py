"""Benchmark: wall time of one default approach (closed loop on truth, Truth record filled at 120 Hz) and its
ratio to raw JSBSim stepping of the same number of steps from the same trimmed start, no autopilot, no
turbulence (approachsim computes the turbulence itself, so it is part of the approach's cost).

Run: python benchmarks/bench_fly.py [--repeat 7] [--cprofile]. Prints the min and median of the interleaved
repeats, their ratio (issue 12's goal: <= 1.5) and the machine's load average before and after; --cprofile adds
the profile of one flight (where the time left goes).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import time
from pathlib import Path

from approachsim.flight.fdm import FDM
from approachsim.flight.run import Approach
from approachsim.flight.trim import start_condition
from approachsim.flight.turbulence import LEVELS
from approachsim.profile import load_profile
from approachsim.seeding import stream_int

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--profile", default=str(ROOT / "profiles" / "default.toml"))
    ap.add_argument("--cprofile", action="store_true", help="also print the cProfile of one flight")
    args = ap.parse_args()
    load0 = os.getloadavg()
    profile = load_profile(args.profile)
    approach = Approach(profile)
    approach.fly(seed=1)  # warm up (imports, first FGFDMExec)
    fly_s, raw_s, raw_turb_s = [], [], []
    fly_cpu, raw_cpu = [], []
    n = 0
    for i in range(args.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        r = approach.fly(seed=1, run=i)
        fly_s.append(time.perf_counter() - t0)
        fly_cpu.append(time.process_time() - c0)
        n = len(r.truth)
        fdm = FDM(approach.aircraft.jsbsim_model, approach.dt_s)
        t0, c0 = time.perf_counter(), time.process_time()
        fdm.initialize_and_trim(start_condition(profile, approach.aircraft))
        fdm.set_seed(stream_int(1, i, "turbulence"))
        step = fdm.run
        for _ in range(n - 1):
            step()
        raw_s.append(time.perf_counter() - t0)
        raw_cpu.append(time.process_time() - c0)
        # second baseline: raw stepping with JSBSim's own milspec turbulence at the same level (what a flight
        # using JSBSim's turbulence model would pay for it inside run())
        fdm = FDM(approach.aircraft.jsbsim_model, approach.dt_s)
        t0 = time.perf_counter()
        fdm.initialize_and_trim(start_condition(profile, approach.aircraft))
        fdm.set_seed(stream_int(1, i, "turbulence"))
        if profile.environment.turbulence != "none":
            w20_fps, index = LEVELS[profile.environment.turbulence]
            fdm["atmosphere/turb-type"] = 3
            fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20_fps
            fdm["atmosphere/turbulence/milspec/severity"] = index
        step = fdm.run
        for _ in range(n - 1):
            step()
        raw_turb_s.append(time.perf_counter() - t0)
    hz = profile.rates.imu_hz
    print(f"profile {profile.name}: {n} steps at {hz:g} Hz = {n / hz:.1f} s of flight; {args.repeat} interleaved pairs")
    for label, pick in (("min", min), ("median", statistics.median)):
        fly, raw = pick(fly_s), pick(raw_s)
        print(f"{label:6s}: approach (FDM build + trim + closed loop + truth) {fly:.3f} s "
              f"({fly / n * 1e6:.1f} us/step, {n / hz / fly:.0f}x real time); raw JSBSim (trim + run()) "
              f"{raw:.3f} s ({raw / n * 1e6:.1f} us/step); ratio {fly / raw:.2f} (goal <= 1.5)")
    print(f"pairwise ratios: {', '.join(f'{f / r:.2f}' for f, r in zip(fly_s, raw_s, strict=True))}")
    fc, rc = min(fly_cpu), min(raw_cpu)
    print(f"CPU time (process_time, less sensitive to the machine's load): approach {fc:.3f} s, raw {rc:.3f} s, "
          f"ratio {fc / rc:.2f}")
    rt = statistics.median(raw_turb_s)
    print(f"raw JSBSim with its own milspec turbulence: median {rt:.3f} s ({rt / n * 1e6:.1f} us/step); "
          f"approach / that: {statistics.median(fly_s) / rt:.2f}")
    load1 = os.getloadavg()
    print(f"load average (1, 5, 15 min): before {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, "
          f"after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f} (2 cores)")
    if args.cprofile:
        prof = cProfile.Profile()
        prof.runcall(approach.fly, seed=1, run=args.repeat)
        pstats.Stats(prof).sort_stats("tottime").print_stats(12)

if __name__ == "__main__":
    main()
