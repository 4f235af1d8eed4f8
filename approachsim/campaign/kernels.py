"""The compiled kernels seen from a campaign: are they in numba's cache yet, and loading them before the first task.

A campaign's first runs on a fresh installation (or after a kernel changed: the cache is keyed by the compiled
floor's sources, approachsim/core/__init__.py) compile the kernels, about 1-2 min on 2 cores; later campaigns load
them from the cache in a few seconds per process. `compile_note` is what the progress display says meanwhile instead
of a time estimate drawn from the compile (issue 42: "1/20 runs, 65 s elapsed, about 1239 s left").

Whether a campaign of a kind has finished runs with this cache is recorded as an empty marker file in the cache
directory itself (`approachsim-campaign-<kind>.done`): a new cache directory (a kernel change, another CPU) has
none, so the note comes back exactly when the kernels are compiled again.

`load_kernels` runs one short open-loop and one closed-loop run of the shipped default profile in this process and
discards them: every kernel those paths call is compiled or loaded from the cache, the stage modules imported and
the 737's file parsed. The Dask worker preload (campaign/dask_preload.py) calls it when a worker starts, so a
campaign's first task on it does not pay that (about 4.6 s per worker, measured in issue 42).
"""

from __future__ import annotations

import functools
import os
import time
from pathlib import Path

COMPILE_NOTE = ("compiling the kernels (the first campaign of this kind after installing or changing approachsim: "
                "under half a minute on 2 cores for the default profile, then cached), no time estimate until the "
                "first runs finish")


def cache_dir() -> Path | None:
    """numba's cache directory of this installation's kernels (set when approachsim.core is imported), or None."""
    import approachsim.core  # noqa: F401  (sets NUMBA_CACHE_DIR: core/__init__.py)

    d = os.environ.get("NUMBA_CACHE_DIR")
    return Path(d) if d else None


def _marker(kind: str) -> Path | None:
    d = cache_dir()
    return None if d is None else d / f"approachsim-campaign-{kind}.done"


def compile_note(kind: str) -> str | None:
    """COMPILE_NOTE when no campaign of this kind ("closed", "open", "closed-land") has finished a run with the
    current kernel cache, else None."""
    m = _marker(kind)
    return None if m is None or m.is_file() else COMPILE_NOTE


def mark_compiled(kind: str) -> None:
    """Record that a campaign of this kind finished runs with the current cache (best effort)."""
    m = _marker(kind)
    if m is None:
        return
    try:
        m.touch()
    except OSError:
        pass


@functools.cache
def load_kernels() -> float:
    """Load (or compile) the kernels of the shipped default profile's closed- and open-loop runs in this process,
    once; returns the seconds it took (0 on later calls in the same process is not guaranteed: the first call's
    figure is cached)."""
    from approachsim.campaign.pipeline import closed_loop_group, open_loop_group
    from approachsim.profile import load_profile
    from approachsim.resources import shipped_profile

    t0 = time.perf_counter()
    profile = load_profile(shipped_profile("default"))
    open_loop_group(profile, 0, [0])
    closed_loop_group(profile, 0, [0])
    return time.perf_counter() - t0
