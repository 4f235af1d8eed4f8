"""Weak scaling of a campaign: the local process pool and a Dask LocalCluster at K workers against one worker.

    python benchmarks/scaling.py [--workers 2] [--closed-per-worker 8] [--open-per-worker 50] [--no-dask]

The shipped default profile (integrity bank on), seed 1. For each mode: one worker runs n runs in this process (the
reference: wall t1, CPU c1), then K workers run K n runs on the local pool (forked from this process) and on a Dask
LocalCluster of K worker processes (one thread each, the settings docs/contract.md recommends, KernelPreload
registered before the clock: a long-lived cluster's steady state). The kernels are loaded in this process before any
clock starts (kernels.load_kernels), so the pool's forks inherit them. Efficiency: wall t1 / tK (1.0: K workers do K
times the work in the same time; meaningful on an otherwise idle machine) and CPU K c1 / cK (work per CPU second, CPU
counted in this process, its reaped children and the Dask workers). Prints Markdown rows for benchmarks/RESULTS.md,
with the load average (1 min) before and after each campaign.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import time

import approachsim as asim
from approachsim.campaign.kernels import load_kernels


def _cpu() -> float:
    s = resource.getrusage(resource.RUSAGE_SELF)
    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def _worker_cpu() -> float:
    """CPU seconds of the calling process (run on each Dask worker by client.run)."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _timed(label: str, fn, client=None) -> tuple[float, float, dict]:
    """(wall s, CPU s of this process, its reaped children and the Dask workers, the summary) of one campaign."""
    load0 = os.getloadavg()[0]
    w0 = sum(client.run(_worker_cpu).values()) if client is not None else 0.0
    c0, t0 = _cpu(), time.perf_counter()
    summary = fn()
    wall, cpu = time.perf_counter() - t0, _cpu() - c0
    if client is not None:
        cpu += sum(client.run(_worker_cpu).values()) - w0
    load1 = os.getloadavg()[0]
    print(f"| {label} | {wall:.1f} | {cpu:.1f} | {load0:.1f} -> {load1:.1f} |", flush=True)
    return wall, cpu, summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--closed-per-worker", type=int, default=8)
    ap.add_argument("--open-per-worker", type=int, default=50)
    ap.add_argument("--no-dask", action="store_true")
    a = ap.parse_args()
    k = a.workers
    print(f"{platform.node()}: {os.cpu_count()} cores, {platform.processor() or platform.machine()}; "
          f"kernels loaded in {load_kernels():.1f} s")
    p = asim.load_profile("default")
    cluster = client = None
    if not a.no_dask:
        import dask
        from distributed import Client, LocalCluster

        from approachsim.campaign.dask_preload import KernelPreload

        dask.config.set({"distributed.worker.profile.enabled": False,
                         "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None})
        cluster = LocalCluster(n_workers=k, threads_per_worker=1, processes=True, dashboard_address=":0")
        client = Client(cluster)
        client.register_plugin(KernelPreload())
    print("| campaign | wall s | CPU s (this process, its children, the Dask workers) | load 1 min before -> after |")
    print("|---|---|---|---|")
    rows = []
    for mode, n in (("closed", a.closed_per_worker), ("open", a.open_per_worker)):
        t1, c1, s1 = _timed(f"{mode} loop, {n} runs, 1 worker", lambda mode=mode, n=n: asim.evaluate_profile(
            p, runs=n, mode=mode, workers=1, progress=False).summary)
        tk, ck, sk = _timed(f"{mode} loop, {k * n} runs, local pool of {k}",
                            lambda mode=mode, n=n: asim.evaluate_profile(
                                p, runs=k * n, mode=mode, workers=k, progress=False).summary)
        td = cd = None
        if client is not None:
            td, cd, sd = _timed(f"{mode} loop, {k * n} runs, Dask LocalCluster of {k}",
                                lambda mode=mode, n=n: asim.evaluate_profile(
                                    p, runs=k * n, mode=mode, scheduler=cluster.scheduler_address,
                                    progress=False).summary, client)
            assert sd == sk, "Dask and the local pool differ"
        rows.append((mode, n, t1, c1, tk, ck, td, cd))
    print()
    print("Efficiency: wall t1 / tK (K workers doing K times the runs; meaningful on an otherwise idle machine) and "
          "CPU K c1 / cK (the work per CPU second, what is left to compare on a loaded machine).")
    print()
    print("| mode | runs per worker | pool: wall eff. | pool: CPU eff. | Dask: wall eff. | Dask: CPU eff. | "
          "Dask / pool, CPU |")
    print("|---|---|---|---|---|---|---|")
    for mode, n, t1, c1, tk, ck, td, cd in rows:
        dask_cols = "-- | -- | --" if td is None else f"{t1 / td:.2f} | {k * c1 / cd:.2f} | {ck / cd:.2f}"
        print(f"| {mode} | {n} | {t1 / tk:.2f} | {k * c1 / ck:.2f} | {dask_cols} |")
    if client is not None:
        client.close()
        cluster.close()


if __name__ == "__main__":
    main()
