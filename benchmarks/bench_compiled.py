"""Benchmarks of the compiled navigation and flight core (issue 12): prints, in one run each part, the ratios
and figures of the issue's table, with the machine's load (the machine is shared: read the ratios).

    python benchmarks/bench_compiled.py compile             # import time, first-call compile: cold vs cached
    python benchmarks/bench_compiled.py ratios [--repeat 3] # closed loop / raw JSBSim, truth flight / raw,
                                                            # the closed loop with the Navigator's epochs,
                                                            # open-loop navigation us per 120 Hz step
    python benchmarks/bench_compiled.py scaling --ns 10 100 1000   # open loop end to end: wall, peak RSS
    python benchmarks/bench_compiled.py scaling --accuracy-only --ns 10 100 1000 10000   # without the bank
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

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # as the console script (cli.main);
    os.environ.setdefault(_var, "1")  # numpy is imported below, inside the parts

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


_FIRST_RUN = """
import time
t0 = time.perf_counter()
from approachsim.campaign import pipeline
from approachsim.profile import load_profile
prof = load_profile(%r)
t1 = time.perf_counter()
pipeline.closed_loop_group(prof, 1, [0])  # a closed-loop run and its integrity bank: every kernel of the campaign
t2 = time.perf_counter()
pipeline.closed_loop_group(prof, 1, [1])
t3 = time.perf_counter()
print(f"{t1 - t0:.3f} {t2 - t1:.3f} {t3 - t2:.3f}")
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
    with tempfile.TemporaryDirectory() as d:  # every kernel a closed-loop campaign run calls
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        for label in ("cold cache (compiles)", "warm cache (loads)"):
            t = time.perf_counter()
            out = subprocess.run([sys.executable, "-c", _FIRST_RUN % str(PROFILE)], env=env, capture_output=True,
                                 text=True, check=True).stdout.split()
            wall = time.perf_counter() - t
            print(f"  closed-loop run + bank, {label:22s}: import {float(out[0]):6.2f} s, first run "
                  f"{float(out[1]):6.2f} s, second run {float(out[2]):6.2f} s, process {wall:6.2f} s")
        size = sum(p.stat().st_size for p in Path(d).rglob("*") if p.is_file())
        print(f"  cache: {sum(1 for _ in Path(d).rglob('*.nbi'))} index files, {size / 1e6:.1f} MB")


def bench_ratios(repeat: int) -> None:
    """Raw JSBSim stepping, the truth flight, the closed loop (flight + sensors + INS + EKF + autopilot, and its
    NavRun) and the open-loop navigation pass of the same approach, interleaved `repeat` times in one warm process;
    min and median of wall and CPU time (the machine's speed drifts: the ratios of one pass are the figures)."""
    from approachsim.flight.fdm import FDM
    from approachsim.flight.run import Approach
    from approachsim.nav.closed_loop import NavInTheLoop
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile
    from approachsim.seeding import stream, stream_int
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    print(f"ratios: {load()}")
    prof = load_profile(PROFILE)
    a = Approach(prof)
    budget = a.time_budget_s
    a.fly(seed=1, run=99, nav_source=NavInTheLoop(prof, seed=1, run=99, max_time_s=3.0), max_time_s=3.0)  # warm up
    a.fly(seed=1, run=99, max_time_s=3.0)
    keys = ("raw", "truth", "closed", "closed_np", "nav")
    t = {k: [] for k in keys}
    c = {k: [] for k in keys}
    n = 0

    def timed(key: str, fn):  # wall and CPU time of fn()
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        t[key].append(time.perf_counter() - w0)
        c[key].append(time.process_time() - c0)
        return out

    for i in range(repeat):
        r = timed("truth", lambda i=i: a.fly(seed=1, run=i))
        n = len(r.truth)
        fdm = FDM(a.aircraft.jsbsim_model, a.dt_s)

        def raw(fdm=fdm, i=i, steps=n - 1):
            fdm.initialize_and_trim(a.start())
            fdm.set_seed(stream_int(1, i, "turbulence"))
            step = fdm.run
            for _ in range(steps):
                step()

        timed("raw", raw)

        def closed(i=i):
            src = NavInTheLoop(prof, seed=1, run=i, max_time_s=budget)
            res = a.fly(seed=1, run=i, nav_source=src)
            return src.result(res.truth)

        timed("closed", closed)

        def closed_np(i=i):  # the same with every aiding epoch on the Navigator's numpy path (the compiled epoch's
            src = NavInTheLoop(prof, seed=1, run=i, max_time_s=budget)  # oracle): what the compiled epoch saves
            src.fast_epochs = False
            res = a.fly(seed=1, run=i, nav_source=src)
            return src.result(res.truth)

        timed("closed_np", closed_np)
        recs, st = measure_with_states(SensorSuite.from_profile(prof), r.truth, seed=1, runs=i)
        nav = NavSystem.from_profile(prof)
        timed("nav", lambda nav=nav, tr=r.truth, recs=recs, st=st, i=i: nav.run(tr, recs, stream(1, i, "nav"),
                                                                               states=st))
    mn, md = min, statistics.median
    print(f"  default profile, {n} steps at {prof.rates.imu_hz:g} Hz; {repeat} interleaved repeats; wall (CPU) s, "
          f"min / median")
    for k, what in (("raw", "raw JSBSim stepping (trim + run())"), ("truth", "flown on truth (Approach.fly)"),
                    ("closed", "closed loop (JSBSim + sensors + INS + EKF + autopilot, NavRun)"),
                    ("closed_np", "  the same, aiding epochs on the Navigator's numpy path"),
                    ("nav", "open-loop navigation pass of one run (NavSystem.run)")):
        print(f"  {what:66s} {mn(t[k]):.3f} / {md(t[k]):.3f}  ({mn(c[k]):.3f} / {md(c[k]):.3f})")
    for k, goal in (("truth", 1.5), ("closed", 2.0)):
        print(f"  {k} / raw JSBSim: wall {mn(t[k]) / mn(t['raw']):.2f} (min) {md(t[k]) / md(t['raw']):.2f} (median), "
              f"CPU {mn(c[k]) / mn(c['raw']):.2f} (min)   goal <= {goal}")
    print(f"  closed / truth flight: {md(t['closed']) / md(t['truth']):.2f} (median); compiled epochs save "
          f"{(md(c['closed_np']) - md(c['closed'])) * 1e3:.0f} ms CPU per approach (median)")
    print(f"  open-loop navigation pass, one run: {mn(t['nav']) / n * 1e6:.1f} / {md(t['nav']) / n * 1e6:.1f} us per "
          f"120 Hz step (min / median)   goal <= 10")
    print(f"  {load()}")


def _open_loop(n: int, scheduler: str | None = None, integrity: bool = True):
    """n open-loop runs of the default profile end to end (no report); integrity False: accuracy only
    (evaluation.integrity = []: no solution-separation bank)."""
    import dataclasses

    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.profile import load_profile

    prof = load_profile(PROFILE)
    if not integrity:
        prof = dataclasses.replace(prof, evaluation=dataclasses.replace(prof.evaluation, integrity=()))
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        ev = evaluate_profile(prof, runs=n, seed=1, mode="open", out_dir=Path(d), workers=None if scheduler else 2,
                              scheduler=scheduler, progress=False)
        return time.perf_counter() - t, ev


def bench_scaling(ns: list[int], accuracy_only: bool) -> None:
    """Open loop end to end (flight, sensors, INS, filter, scoring, files) at each N; peak RSS of this process
    and of its largest child (a pool worker), each N in a fresh process."""
    what = "accuracy only (evaluation.integrity = [])" if accuracy_only else "with the integrity bank (the default)"
    print(f"scaling, {what}: {load()}")
    for n in ns:
        out = subprocess.run([sys.executable, __file__, "_one", str(n)] + (["--accuracy-only"] if accuracy_only else
                                                                            []),
                             capture_output=True, text=True, check=True)
        print("  " + out.stdout.strip().splitlines()[-1])


def _one(n: int, accuracy_only: bool) -> None:
    wall, ev = _open_loop(n, integrity=not accuracy_only)
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
    ap.add_argument("--accuracy-only", action="store_true", help="scaling: without the integrity bank")
    args = ap.parse_args()
    if args.part == "compile":
        bench_compile()
    elif args.part == "ratios":
        bench_ratios(args.repeat)
    elif args.part == "scaling":
        bench_scaling(args.ns, args.accuracy_only)
    elif args.part == "dask":
        bench_dask(args.n)
    elif args.part == "evaluate":
        bench_evaluate()
    else:
        _one(args.n_one, args.accuracy_only)


if __name__ == "__main__":
    main()
