"""A synthetic, picklable per-run function for the campaign runner tests (no flight, no filter).

Its "profile" is a plain dict: sleep_s (per run), fail_runs (indices that raise), series_runs.
"""

from __future__ import annotations

import os
import time

import numpy as np

from approachsim.campaign.result import RunResult
from approachsim.seeding import stream


def synth_run(profile: dict, seed: int, run: int) -> RunResult:
    """A run whose numbers come only from stream(seed, run, 'synthetic')."""
    rng = stream(seed, run, "synthetic")
    x = rng.normal(1.0, 2.0, 200)
    if run in profile.get("fail_runs", ()):
        raise RuntimeError(f"synthetic failure in run {run}\n(second line)")
    if run in profile.get("crash_runs", ()):
        os._exit(3)  # a worker process that dies (as a segfault or an OOM kill would)
    time.sleep(profile.get("sleep_s", 0.0))
    keep = run < profile.get("series_runs", 0)
    return RunResult(
        run=run,
        ok=True,
        scalars={"mean_m": float(x.mean()), "rms_m": float(np.sqrt(np.mean(x**2))), "nan_m": float("nan")},
        arrays={"first_m": x[:7].copy()},
        series={"t_s": np.arange(20.0), "x_m": x[:20].copy()} if keep else None,
    )


def synth_group(profile: dict, seed: int, runs: list[int]) -> list[RunResult]:
    """The same runs computed as a group (as open loop shares one flight per group)."""
    if profile.get("fail_group") in runs:
        raise RuntimeError("shared flight failed")
    return [synth_run(profile, seed, i) for i in runs]


def profile_run(profile, seed: int, run: int) -> RunResult:
    """A run that reads the (real) profile it was sent: the evaluation decision height and a nav field."""
    return RunResult(run=run, ok=True, scalars={"dh_cat1_ft": profile.evaluation.dh_cat1_ft,
                                                 "n_tuning": float(len(getattr(profile, "nav", {}).__dict__))})


def dask_probe_run(profile: dict, seed: int, run: int) -> RunResult:
    """A run on a Dask worker that reports what its task sees: the results its worker holds (tasks finished and
    not yet released by the client) and the BLAS libraries' thread count inside the task."""
    from distributed import get_worker
    from threadpoolctl import threadpool_info

    time.sleep(profile.get("sleep_s", 0.0))
    blas = [p["num_threads"] for p in threadpool_info() if p.get("user_api") == "blas"]
    return RunResult(run=run, ok=True, scalars={"held": float(len(get_worker().data)),
                                                "blas_threads": float(max(blas, default=1))})


def bad_worker_run(profile: dict, seed: int, run: int) -> RunResult:
    """synth_run, except on the Dask worker named profile["bad_worker"], where every run raises the bare
    FileNotFoundError a worker whose working directory was deleted raises (issue 42), in a millisecond."""
    from distributed import get_worker

    if get_worker().name == profile["bad_worker"]:
        raise FileNotFoundError(2, "No such file or directory")
    time.sleep(profile.get("sleep_s", 0.0))
    return synth_run(profile, seed, run)


CALLS: list[int] = []
"""Runs started by counted_fail_run in this process (Dask workers in threads of the test process)."""


def counted_fail_run(profile: dict, seed: int, run: int) -> RunResult:
    """A run that always fails (its own failure, on any worker), counted in CALLS."""
    CALLS.append(run)
    raise RuntimeError(f"diverged in run {run}")


def _cannot_load() -> None:
    raise ImportError("No module named 'approachsim' (this worker's environment)")


class Unloadable:
    """A "profile" a worker cannot unpickle: the task fails on the worker before any run starts (a worker without the
    package installed)."""

    def __reduce__(self):
        return _cannot_load, ()
