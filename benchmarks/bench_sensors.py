"""Benchmark: time to generate every sensor stream of the default profile's suite for N Monte Carlo runs.

    python benchmarks/bench_sensors.py [--runs 1000] [--chunk 25] [--jsbsim] [--profile profiles/default.toml]

Truth: the JSBSim approach of the profile (--jsbsim, flown once, run 0) or, by default, the synthetic
constant-velocity test truth of the same profile (approachsim.synthetic.profile_descent; same rates and
about the same length). Runs are measured in chunks (all sensors of `chunk` runs at once, run axis first;
memory grows with the chunk) and nothing is kept. Prints seconds per sensor and in total, milliseconds per
run, and the ratio of simulated flight time to wall time. Not a test: results go to benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.gnss.receiver import draw_receiver_clock
from approachsim.sensors.suite import CLOCK_STREAM, SensorSuite, SuiteErrors


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", type=Path, default=Path(__file__).resolve().parents[1] / "profiles" / "default.toml")
    ap.add_argument("--runs", type=int, default=1000)
    ap.add_argument("--chunk", type=int, default=25)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jsbsim", action="store_true", help="fly the JSBSim truth once instead of the synthetic one")
    args = ap.parse_args()
    prof = load_profile(args.profile)
    t0 = time.perf_counter()
    if args.jsbsim:
        from approachsim.flight.run import Approach

        truth = Approach(prof).fly(seed=args.seed, run=0).truth
        kind = "JSBSim"
    else:
        from approachsim import synthetic

        truth = synthetic.profile_descent(prof)
        kind = "synthetic"
    t_truth = time.perf_counter() - t0
    suite = SensorSuite.from_profile(prof)
    per = {name: 0.0 for name in suite.sensors}
    per["receiver_clock"] = 0.0
    samples = {}
    t_start = time.perf_counter()
    for r0 in range(0, args.runs, args.chunk):
        runs = list(range(r0, min(args.runs, r0 + args.chunk)))
        for name in suite.sensors:
            t1 = time.perf_counter()
            clock = None
            if name in ("gnss", "pseudolite"):
                t2 = time.perf_counter()
                clock = draw_receiver_clock(suite.clock, truth.t_s, suite.clock_rate_hz,
                                            [stream(args.seed, r, CLOCK_STREAM) for r in runs])
                per["receiver_clock"] += time.perf_counter() - t2
            errs = suite.sensors[name].draw(truth.t_s, [stream(args.seed, r, name) for r in runs])
            rec = suite.apply(truth, SuiteErrors({name: errs}, clock), names=[name])[name]
            per[name] += time.perf_counter() - t1
            samples[name] = rec.t_s.shape[0]
    total = time.perf_counter() - t_start
    flight_s = float(truth.t_s[-1])
    print(f"profile {prof.name}: {kind} truth, {len(truth)} samples at {prof.rates.imu_hz:g} Hz, "
          f"{flight_s:.0f} s of flight (truth built in {t_truth:.1f} s)")
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} CPUs visible, numpy {np.__version__}")
    ms = 1000 * total / args.runs
    print(f"{args.runs} runs in chunks of {args.chunk}: {total:.1f} s total, {ms:.1f} ms per run, "
          f"{flight_s * args.runs / total:.0f}x real time")
    for name, s in per.items():
        note = "; clock time included" if name in ("gnss", "pseudolite") else ""
        print(f"  {name:15s} {s:7.2f} s  ({samples.get(name, '-')} samples per run{note})")


if __name__ == "__main__":
    main()
