"""Where an open-loop campaign's wall time goes: each task's wall and CPU time inside its pool worker, the parent's
CPU, and the time between the last task's return and the end of evaluate_profile.

    PYTHONPATH=. python benchmarks/task_times.py 1000                  # the default profile, with the bank
    PYTHONPATH=. python benchmarks/task_times.py 1000 --accuracy-only  # evaluation.integrity = []

Prints the tasks' wall and CPU time (mean, range), the parent's CPU, when the first and the last task came back.
Workers are forked (Linux): the timing wrapper set here before the pool starts is what they run; each appends its
tasks' times to a file of the run's temporary directory.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

ROOT = Path(__file__).resolve().parents[1]
PROFILE = ROOT / "profiles" / "default.toml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", type=int)
    ap.add_argument("--accuracy-only", action="store_true", help="without the integrity bank")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()

    from approachsim.campaign import runner
    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.profile import load_profile

    prof = load_profile(PROFILE)
    if args.accuracy_only:
        prof = dataclasses.replace(prof, evaluation=dataclasses.replace(prof.evaluation, integrity=()))
    inner = runner._run_task
    back: list[float] = []
    log = Path(tempfile.mkdtemp())

    def timed(run_fn, group_fn, profile, seed, runs):  # in the worker
        c, t = time.process_time(), time.perf_counter()
        out = inner(run_fn, group_fn, profile, seed, runs)
        with open(log / f"{os.getpid()}.txt", "a") as f:
            f.write(f"{runs[0]} {time.perf_counter() - t:.4f} {time.process_time() - c:.4f}\n")
        return out

    local = runner._local

    def returned(*a, **k):  # in the parent
        for res in local(*a, **k):
            back.append(time.perf_counter())
            yield res

    runner._run_task, runner._local = timed, returned
    with tempfile.TemporaryDirectory() as d:
        c0, t0 = time.process_time(), time.perf_counter()
        evaluate_profile(prof, runs=args.runs, seed=1, mode="open", out_dir=Path(d), workers=args.workers,
                         progress=False)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    rows = np.array([[float(v) for v in line.split()] for f in sorted(log.glob("*.txt"))
                     for line in f.read_text().splitlines()])
    shutil.rmtree(log)
    print(f"{args.runs} runs{' (accuracy only)' if args.accuracy_only else ''}: {wall:.2f} s wall; "
          f"{len(rows)} tasks, wall {rows[:, 1].mean():.3f} s mean [{rows[:, 1].min():.3f}, {rows[:, 1].max():.3f}], "
          f"CPU {rows[:, 2].mean():.3f} s mean, {rows[:, 2].sum():.1f} s in all; parent CPU {cpu:.2f} s; first task "
          f"back at {back[0] - t0:.2f} s, the last at {back[-1] - t0:.2f} s ({wall - (back[-1] - t0):.2f} s before "
          f"the end); load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
