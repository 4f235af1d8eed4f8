"""Benchmarks of the compiled navigation and flight core (issue 12): prints, in one run each part, the ratios
and figures of the issue's table, with the machine's load (the machine is shared: read the ratios).

    python benchmarks/bench_compiled.py compile             # import time, first-call compile: cold vs cached
    python benchmarks/bench_compiled.py ratios [--repeat 3] # closed loop / raw JSBSim, truth flight / raw,
                                                            # open-loop navigation us per 120 Hz step
    python benchmarks/bench_compiled.py scaling --ns 10 100 1000   # open loop end to end: wall, peak RSS
    python benchmarks/bench_compiled.py dask --n 1000      # local pool vs Dask LocalCluster: same bits, efficiency
    python benchmarks/bench_compiled.py evaluate           # the default `approachsim evaluate` (20 closed-loop runs)

Results go in benchmarks/RESULTS.md under "Compiled core". No pass/fail: benchmarks are scripts, not tests.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROFILE = ROOT / "profiles" / "default.toml"


def load() -> str:
    return "load average " + ", ".join(f"{v:.2f}" for v in os.getloadavg())


def rss_mb(who: int) -> float:
    return resource.getrusage(who).ru_maxrss / 1024.0


_FIRST_CALL = """
import time, numpy as np
t0 = time.perf_counter()
from approachsim.nav import ins
from approachsim.nav.closed_loop import NavInTheLoop  # noqa: F401 (imports every nav and sensor kernel module)
from approachsim.flight import kernels as fk
t1 = time.perf_counter()
s = ins.init_state(0.6, -2.1, 100.0, [60.0, 0.0, 3.0], np.eye(3))
ins.propagate(ins.pack(s), np.zeros((1, 2, 3)), np.zeros((1, 2, 3)), 1 / 120)
t2 = time.perf_counter()
print(f"{t1 - t0:.3f} {t2 - t1:.3f}")
"""


def bench_compile() -> None:
    """Import time of the kernel modules and the first strapdown call, with an empty numba cache and again
    with the cache it left (two fresh processes each)."""
    print(f"compile: {load()}")
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        for label in ("cold cache (compiles)", "warm cache (loads)", "warm cache (loads)"):
            t = time.perf_counter()
            out = subprocess.run([sys.executable, "-c", _FIRST_CALL], env=env, capture_output=True, text=True,
                                 check=True).stdout.split()
            wall = time.perf_counter() - t
            print(f"  {label:22s}: import {float(out[0]):6.2f} s, first propagate {float(out[1]):6.2f} s, "
                  f"process {wall:6.2f} s")
        size = sum(p.stat().st_size for p in Path(d).rglob("*") if p.is_file())
        print(f"  cache: {sum(1 for _ in Path(d).rglob('*.nbi'))} index files, {size / 1e6:.1f} MB")


def bench_ratios(repeat: int) -> None:
    """Closed loop, truth flight, raw JSBSim (same steps), open-loop navigation pass; warm (compiled) process."""
    from approachsim.flight.fdm import FDM
    from approachsim.flight.run import Approach
    from approachsim.flight.trim import start_condition
    from approachsim.nav.closed_loop import NavInTheLoop
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile
    from approachsim.seeding import stream, stream_int
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    print(f"ratios: {load()}")
    prof = load_profile(PROFILE)
    a = Approach(prof)
    a.fly(seed=1, run=99, nav_source=NavInTheLoop(prof, seed=1, run=99, max_time_s=3.0), max_time_s=3.0)  # warm up
    closed, truth_fly, raw, nav = [], [], [], []
    n = 0
    for i in range(repeat):
        t0 = time.perf_counter()
        res = a.fly(seed=1, run=i, nav_source=NavInTheLoop(prof, seed=1, run=i))
        closed.append(time.perf_counter() - t0)
        n = len(res.truth)
        t0 = time.perf_counter()
        r = a.fly(seed=1, run=i)
        truth_fly.append(time.perf_counter() - t0)
        fdm = FDM(a.aircraft.jsbsim_model, a.dt_s)
        t0 = time.perf_counter()
        fdm.initialize_and_trim(start_condition(prof, a.aircraft))
        fdm.set_seed(stream_int(1, i, "turbulence"))
        step = fdm.run
        for _ in range(len(r.truth) - 1):
            step()
        raw.append(time.perf_counter() - t0)
        recs, st = measure_with_states(SensorSuite.from_profile(prof), r.truth, seed=1, runs=i)
        t0 = time.perf_counter()
        NavSystem.from_profile(prof).run(r.truth, recs, stream(1, i, "nav"), states=st)
        nav.append((time.perf_counter() - t0) / len(r.truth))
    mn, md = min, statistics.median
    print(f"  default profile, {n} steps at {prof.rates.imu_hz:g} Hz; min / median of {repeat}")
    print(f"  closed loop (JSBSim + sensors + INS + EKF + autopilot): {mn(closed):.2f} / {md(closed):.2f} s")
    print(f"  flown on truth (Approach.fly):                         {mn(truth_fly):.2f} / {md(truth_fly):.2f} s")
    print(f"  raw JSBSim stepping (trim + run()):                    {mn(raw):.2f} / {md(raw):.2f} s")
    print(f"  closed / raw JSBSim: {mn(closed) / mn(raw):.1f} (min) {md(closed) / md(raw):.1f} (median)  goal <= 2")
    print(f"  truth flight / raw:  {mn(truth_fly) / mn(raw):.1f} (min) {md(truth_fly) / md(raw):.1f} (median)"
          f"  goal <= 1.5")
    print(f"  closed / truth flight: {md(closed) / md(truth_fly):.2f} (median)")
    print(f"  open-loop navigation pass, one run: {mn(nav) * 1e6:.1f} / {md(nav) * 1e6:.1f} us per step  goal <= 10")
    print(f"  {load()}")


def _open_loop(n: int, scheduler: str | None = None):
    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.profile import load_profile

    prof = load_profile(PROFILE)
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        ev = evaluate_profile(prof, runs=n, seed=1, mode="open", out_dir=Path(d), workers=None if scheduler else 2,
                              scheduler=scheduler, progress=False)
        return time.perf_counter() - t, ev


def bench_scaling(ns: list[int]) -> None:
    """Open loop end to end (flight, sensors, INS, filter, scoring, files) at each N; peak RSS of this process
    and of its largest child (a pool worker), each N in a fresh process."""
    print(f"scaling: {load()}")
    for n in ns:
        out = subprocess.run([sys.executable, __file__, "_one", str(n)], capture_output=True, text=True, check=True)
        print("  " + out.stdout.strip().splitlines()[-1])


def _one(n: int) -> None:
    wall, ev = _open_loop(n)
    failed = sum(not r.ok for r in ev.results)
    print(f"N={n:6d}: {wall:7.1f} s ({wall / n * 1e3:6.1f} ms/run), {failed} failed, best "
          f"{ev.summary['best_category']}; peak RSS parent {rss_mb(resource.RUSAGE_SELF):6.0f} MB, largest worker "
          f"{rss_mb(resource.RUSAGE_CHILDREN):6.0f} MB; {load()}")


def bench_dask(n: int) -> None:
    """The same N open-loop runs on the local pool (2 workers) and on a Dask LocalCluster (2 worker processes,
    one thread each): every run's record must be the same bits; efficiency = local wall / Dask wall."""
    from distributed import LocalCluster

    print(f"dask: {load()}")
    wall_l, ev_l = _open_loop(n)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, protocol="tcp://", host="127.0.0.1",
                      dashboard_address=":0") as cluster:
        wall_d, ev_d = _open_loop(n, cluster.scheduler_address)

    def records(ev):
        return [json.dumps(r.record(), sort_keys=True) for r in sorted(ev.results, key=lambda r: r.run)]

    same = records(ev_l) == records(ev_d)
    print(f"  N={n}: local pool {wall_l:.1f} s, Dask LocalCluster {wall_d:.1f} s, efficiency {wall_l / wall_d:.2f}; "
          f"records bit-identical: {same}; {load()}")


def bench_evaluate() -> None:
    print(f"evaluate: {load()}")
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        subprocess.run(["approachsim", "evaluate", str(PROFILE), "--out", d], check=True, capture_output=True)
        wall = time.perf_counter() - t
    print(f"  approachsim evaluate profiles/default.toml (20 closed-loop runs, figures, report): {wall:.1f} s "
          f"(goal <= 15 s); peak RSS largest process {rss_mb(resource.RUSAGE_CHILDREN):.0f} MB; {load()}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("part", choices=["compile", "ratios", "scaling", "dask", "evaluate", "_one"])
    ap.add_argument("n_one", nargs="?", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ns", type=int, nargs="+", default=[10, 100, 1000])
    ap.add_argument("--n", type=int, default=1000)
    args = ap.parse_args()
    if args.part == "compile":
        bench_compile()
    elif args.part == "ratios":
        bench_ratios(args.repeat)
    elif args.part == "scaling":
        bench_scaling(args.ns)
    elif args.part == "dask":
        bench_dask(args.n)
    elif args.part == "evaluate":
        bench_evaluate()
    else:
        _one(args.n_one)


if __name__ == "__main__":
    main()
