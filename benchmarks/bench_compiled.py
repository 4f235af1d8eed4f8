"""Benchmarks of the compiled navigation and flight core (issue 12): prints, in one run each part, the ratios
and figures of the issue's table, with the machine's load (the machine is shared: read the ratios).

    python benchmarks/bench_compiled.py compile             # import time, first-call compile: cold vs cached
    python benchmarks/bench_compiled.py ratios [--repeat 3] # closed loop / raw JSBSim, truth flight / raw,
                                                            # the closed loop with the Navigator's epochs,
                                                            # open-loop navigation us per 120 Hz step
    python benchmarks/bench_compiled.py scaling --ns 10 100 1000   # open loop end to end: wall, peak RSS
    python benchmarks/bench_compiled.py scaling --accuracy-only --ns 10 100 1000 10000   # without the bank
    python benchmarks/bench_compiled.py dask --n 1000      # local pool vs Dask LocalCluster (Dask's defaults and
                                                            # the recommended settings): same bits, efficiency
    python benchmarks/bench_compiled.py dask --accuracy-only --skip-defaults --n 10000   # without the bank,
                                                            # recommended settings only
    python benchmarks/bench_compiled.py evaluate           # the default `approachsim evaluate` (20 closed-loop runs)

Results go in benchmarks/RESULTS.md under "Compiled core". No pass/fail: benchmarks are scripts, not tests.
"""

from __future__ import annotations

import argparse
import contextlib
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
from approachsim.loop.closed_loop import NavInTheLoop  # noqa: F401 (imports every nav and sensor kernel module)
from approachsim.core.loop import flight_step as fk
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


def bench_ratios(repeat: int, profile: Path = PROFILE) -> None:
    """Raw JSBSim stepping, the truth flight, the closed loop (flight + sensors + INS + EKF + autopilot, and its
    NavRun) and the open-loop navigation pass of the same approach, interleaved `repeat` times in one warm process;
    min and median of wall and CPU time (the machine's speed drifts: the ratios of one pass are the figures)."""
    from approachsim.flight.fdm import FDM
    from approachsim.flight.run import Approach
    from approachsim.loop.closed_loop import NavInTheLoop
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile
    from approachsim.seeding import stream, stream_int
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    print(f"ratios: {load()}")
    prof = load_profile(profile)
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
    print(f"  {Path(profile).name}, {n} steps at {prof.rates.imu_hz:g} Hz; {repeat} interleaved repeats; wall (CPU) s, "
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


def _open_loop(n: int, scheduler: str | None = None, integrity: bool = True, progress: bool = False):
    """n open-loop runs of the default profile end to end (no report); integrity False: accuracy only
    (evaluation.integrity = []: no solution-separation bank). progress: the runner's progress lines on stderr."""
    import dataclasses

    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.profile import load_profile

    prof = load_profile(PROFILE)
    if not integrity:
        prof = dataclasses.replace(prof, evaluation=dataclasses.replace(prof.evaluation, integrity=()))
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        ev = evaluate_profile(prof, runs=n, seed=1, mode="open", out_dir=Path(d), workers=None if scheduler else 2,
                              scheduler=scheduler, progress=progress)
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


DASK_RECOMMENDED = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.worker.profile.enabled": False,
}
"""The Dask settings docs/contract.md recommends for campaigns: glibc's default malloc (Dask's nannies start workers
with MALLOC_TRIM_THRESHOLD_=65536, which also fixes the mmap threshold at 128 kB: every large numpy temporary is
then a fresh mmap and its pages faulted in again, measured 15x the page faults and +20 % CPU per run) and no
statistical profiler thread sampling the task's stack every 10 ms."""


@contextlib.contextmanager
def _dask_cluster(settings: dict):
    """A LocalCluster of 2 worker processes with one thread each (as the local pool's 2 workers) under `settings`.

    The nannies write their pre-spawn environment into this process's os.environ: it is restored afterwards, so
    that each cluster's workers get exactly its own settings."""
    import dask
    from distributed import LocalCluster

    saved = dict(os.environ)
    os.environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    try:
        with dask.config.set(settings), LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                                     protocol="tcp://", host="127.0.0.1",
                                                     dashboard_address=":0") as cluster:
            yield cluster
    finally:
        os.environ.clear()
        os.environ.update(saved)


def _cpu_s(proc) -> float:
    """CPU seconds (user + system) of a psutil process and its live descendants."""
    import psutil

    total = 0.0
    for p in [proc] + proc.children(recursive=True):
        try:
            c = p.cpu_times()
            total += c.user + c.system
        except psutil.Error:
            pass
    return total


def _timed_campaign(n: int, scheduler: str | None, accuracy_only: bool) -> tuple[float, float, float, list[str]]:
    """(wall s, CPU s of the workers, CPU s of this process, per-run record digests) of one open-loop campaign.

    Workers' CPU: the local pool's children are reaped at the end (RUSAGE_CHILDREN); a LocalCluster's worker
    processes live on (psutil). This process runs the client and, for a LocalCluster, its scheduler and nannies.
    The records are kept as SHA-256 digests of their JSON lines (a 10^4-run campaign's results are ~0.9 GB
    with the integrity bank) and the campaign's results dropped."""
    import hashlib

    import psutil

    me = psutil.Process()
    kids = lambda: sum(_cpu_s(c) for c in me.children())  # noqa: E731
    ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    k0, s0 = kids(), resource.getrusage(resource.RUSAGE_SELF)
    wall, ev = _open_loop(n, scheduler, integrity=not accuracy_only, progress=True)
    k1, s1 = kids(), resource.getrusage(resource.RUSAGE_SELF)
    ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    reaped = ch1.ru_utime + ch1.ru_stime - ch0.ru_utime - ch0.ru_stime
    workers = reaped + (k1 - k0 if scheduler else 0.0)
    main = s1.ru_utime + s1.ru_stime - s0.ru_utime - s0.ru_stime
    digests = [hashlib.sha256(json.dumps(r.record(), sort_keys=True).encode()).hexdigest()
               for r in sorted(ev.results, key=lambda r: r.run)]
    return wall, workers, main, digests


def bench_dask(n: int, accuracy_only: bool, skip_defaults: bool = False) -> None:
    """The same N open-loop runs on the local pool (2 workers) and on a Dask LocalCluster (2 worker processes, one
    thread each), first with Dask's default settings, then with DASK_RECOMMENDED: every run's record must be the
    same bits; efficiency = local wall / Dask wall. CPU seconds (workers, this process) say where the time goes
    independently of the other sessions' load; progress lines go to stderr. skip_defaults: only the recommended
    settings (a third less time at N = 10^4)."""
    what = "accuracy only (evaluation.integrity = [])" if accuracy_only else "with the integrity bank (the default)"
    print(f"dask, N={n}, {what}: {load()}", flush=True)
    wall_l, cpu_l, main_l, dig_l = _timed_campaign(n, None, accuracy_only)
    print(f"  local pool (2 processes)          : {wall_l:7.1f} s wall; CPU: workers {cpu_l:7.1f} s, this process "
          f"{main_l:5.1f} s; {load()}", flush=True)
    variants = (("Dask defaults", {}), ("recommended settings", DASK_RECOMMENDED))
    for label, settings in variants[1:] if skip_defaults else variants:
        t = time.perf_counter()
        with _dask_cluster(settings) as cluster:
            start = time.perf_counter() - t
            wall_d, cpu_d, main_d, dig_d = _timed_campaign(n, cluster.scheduler_address, accuracy_only)
        print(f"  LocalCluster, {label:20s}: {wall_d:7.1f} s wall; CPU: workers {cpu_d:7.1f} s, this process (client, "
              f"scheduler, nannies) {main_d:5.1f} s; cluster start {start:.1f} s (not timed); {load()}")
        print(f"    efficiency (local wall / Dask wall) {wall_l / wall_d:.2f}, CPU ratio (local / Dask, all processes) "
              f"{(cpu_l + main_l) / (cpu_d + main_d):.2f}; records bit-identical to the local pool's: "
              f"{dig_d == dig_l}", flush=True)


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
    ap.add_argument("--profile", type=Path, default=PROFILE, help="ratios: the profile flown (default: the default)")
    ap.add_argument("--ns", type=int, nargs="+", default=[10, 100, 1000])
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--accuracy-only", action="store_true", help="scaling, dask: without the integrity bank")
    ap.add_argument("--skip-defaults", action="store_true", help="dask: only the recommended LocalCluster settings")
    args = ap.parse_args()
    if args.part == "compile":
        bench_compile()
    elif args.part == "ratios":
        bench_ratios(args.repeat, args.profile)
    elif args.part == "scaling":
        bench_scaling(args.ns, args.accuracy_only)
    elif args.part == "dask":
        bench_dask(args.n, args.accuracy_only, args.skip_defaults)
    elif args.part == "evaluate":
        bench_evaluate()
    else:
        _one(args.n_one, args.accuracy_only)


if __name__ == "__main__":
    main()
