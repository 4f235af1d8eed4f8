"""Campaign benchmarks: runner overhead and scaling, scoring cost, and the end-to-end pipeline where it exists.

    python benchmarks/bench_campaign.py [--quick] [--open-runs N] [--closed-runs N]

A. Runner: a synthetic run (a fixed ~5 ms numpy workload) through the local pool (2 workers) for
   N = 10, 100, 1000: wall time, per-run time (flat means linear cost), parent peak RSS growth per run
   (flat means results stream to disk, not memory); the same 1000 runs on a Dask LocalCluster (2 processes).
B. Scoring: score_run on a 31,500-epoch (120 Hz, 4.4 min) synthetic approach, per run.
C. Pipeline (only when approachsim.campaign.pipeline.require_stages() passes): the default profile,
   open loop N runs end to end (fly once per group, sensors, INS, filter, scoring) on 2 workers, and closed
   loop runs per minute with its ratio to flying the same approaches on truth (raw JSBSim + autopilot).
Prints numbers and ratios; no pass/fail. Results go in benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "unit" / "evaluate"))

from approachsim.campaign.result import RunResult  # noqa: E402
from approachsim.campaign.runner import run_campaign  # noqa: E402
from approachsim.seeding import stream  # noqa: E402


def work_run(profile: dict, seed: int, run: int) -> RunResult:
    """A fixed numpy workload (~5 ms) standing for one run; scalars and a 101-point array like a scored run."""
    rng = stream(seed, run, "bench")
    a = rng.normal(size=(profile["n"], 3))
    for _ in range(profile["reps"]):
        a = np.sin(a) + 0.1 * a
    return RunResult(run=run, ok=True, scalars={f"s{i}": float(a[i, 0]) for i in range(60)},
                     arrays={"x": a[:101, 0].copy(), "y": a[:101, 1].copy()})


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def bench_runner(ns: list[int]) -> None:
    prof = {"n": 20000, "reps": 8}
    t = time.perf_counter()
    for i in range(20):
        work_run(prof, 0, i)
    one = (time.perf_counter() - t) / 20
    print(f"A. runner: synthetic run {one * 1e3:.1f} ms in-process (2-worker floor: {one / 2 * 1e3:.1f} ms)")
    for n in ns:
        with tempfile.TemporaryDirectory() as d:
            rss0 = _rss_mb()
            t = time.perf_counter()
            run_campaign(prof, seed=1, runs=n, run_fn=work_run, workers=2, out_dir=Path(d), progress=False)
            wall = time.perf_counter() - t
            rss1 = _rss_mb()
        print(f"   local pool, 2 workers, N={n:5d}: {wall:7.2f} s, {wall / n * 1e3:6.2f} ms/run "
              f"({wall / n / (one / 2):4.2f}x the 2-core floor), parent peak RSS +{rss1 - rss0:6.1f} MB "
              f"({(rss1 - rss0) / n * 1024:6.1f} kB/run)")
    try:
        from distributed import LocalCluster
    except ImportError:
        return
    n = ns[-1]
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, protocol="tcp://", host="127.0.0.1",
                      dashboard_address=":0") as cluster, tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        run_campaign(prof, seed=1, runs=n, run_fn=work_run, scheduler=cluster.scheduler_address, out_dir=Path(d),
                     progress=False)
        wall = time.perf_counter() - t
    print(f"   Dask LocalCluster, 2 processes, N={n}: {wall:7.2f} s, {wall / n * 1e3:6.2f} ms/run")


def bench_scoring() -> None:
    from evalpairs import make_nav, make_truth

    from approachsim.evaluate.config import EvaluationConfig
    from approachsim.evaluate.score import score_run

    truth = make_truth(hz=120.0, hat0_m=1000.0, sink_mps=3.8)
    nav = make_nav(truth, np.array([1.0, 2.0, 0.5]))
    cfg = EvaluationConfig()
    score_run(truth, nav, cfg)
    t = time.perf_counter()
    k = 20
    for _ in range(k):
        score_run(truth, nav, cfg)
    dt = (time.perf_counter() - t) / k
    print(f"B. scoring: {len(truth)} epochs per run: {dt * 1e3:.1f} ms/run (1000 runs on 2 cores: {dt * 500:.1f} s)")


def bench_pipeline(n_open: int, n_closed: int) -> None:
    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.campaign.pipeline import PipelineUnavailable, require_stages
    from approachsim.profile import load_profile

    try:
        require_stages()
    except PipelineUnavailable as e:
        print(f"C. pipeline: not run ({e})")
        return
    prof = load_profile(ROOT / "profiles" / "default.toml")
    closed_core_s = None
    for mode, n in (("open", n_open), ("closed", n_closed)):
        if n <= 0:
            continue
        try:
            require_stages(mode)
        except PipelineUnavailable as e:
            print(f"C. pipeline {mode} loop: not run ({e})")
            continue
        with tempfile.TemporaryDirectory() as d:
            t = time.perf_counter()
            ev = evaluate_profile(prof, runs=n, seed=1, mode=mode, out_dir=Path(d), workers=2, progress=False)
            wall = time.perf_counter() - t
        failed = sum(not r.ok for r in ev.results)
        print(f"C. pipeline {mode} loop, default profile, N={n}, 2 workers: {wall:.1f} s "
              f"({wall / n * 1e3:.0f} ms/run, {60 * n / wall:.0f} runs/min), {failed} failed, "
              f"best {ev.summary['best_category']}")
        if mode == "closed":
            closed_core_s = 2.0 * wall / n
    if closed_core_s is None:
        return
    from approachsim.flight.run import Approach

    a = Approach(prof)
    a.fly(seed=1, run=0)
    t = time.perf_counter()
    for i in range(3):
        a.fly(seed=1, run=i)
    raw = (time.perf_counter() - t) / 3
    print(f"   raw flight on truth (JSBSim + autopilot): {raw:.2f} s/run on one core; closed-loop run "
          f"{closed_core_s:.2f} core-s/run: ratio {closed_core_s / raw:.1f} (goal <= 2)")


def profile_group(n: int) -> None:
    """cProfile of one open-loop group (n runs sharing one flight of the default profile), in this process."""
    import cProfile
    import pstats

    from approachsim.campaign.pipeline import open_loop_group
    from approachsim.profile import load_profile

    prof = load_profile(ROOT / "profiles" / "default.toml")
    pr = cProfile.Profile()
    t = time.perf_counter()
    pr.enable()
    res = open_loop_group(prof, 1, list(range(n)))
    pr.disable()
    print(f"D. one open-loop group of {n} runs in one process: {time.perf_counter() - t:.1f} s (under cProfile), "
          f"{sum(r.ok for r in res)} ok")
    pstats.Stats(pr).sort_stats("cumulative").print_stats(30)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="runner N up to 100 only")
    ap.add_argument("--open-runs", type=int, default=1000, help="open-loop pipeline runs (default 1000)")
    ap.add_argument("--closed-runs", type=int, default=20, help="closed-loop pipeline runs (default 20; 0: skip)")
    ap.add_argument("--pipeline-only", action="store_true", help="skip the runner (A) and scoring (B) parts")
    ap.add_argument("--profile-group", type=int, default=0, metavar="N",
                    help="only profile one open-loop group of N runs (cProfile, cumulative) and exit")
    args = ap.parse_args()
    if args.profile_group:
        profile_group(args.profile_group)
        return
    if not args.pipeline_only:
        bench_runner([10, 100] if args.quick else [10, 100, 1000])
        bench_scoring()
    bench_pipeline(args.open_runs, args.closed_runs)


if __name__ == "__main__":
    main()
