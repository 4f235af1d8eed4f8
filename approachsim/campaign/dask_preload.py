"""Dask worker preload: load approachsim's compiled kernels when a worker starts, before its first task.

    dask worker tcp://scheduler:8786 --nthreads 1 --nworkers 16 --preload approachsim.campaign.dask_preload

A worker otherwise loads the kernels, imports the stages and parses the aircraft in its first task (about 4.6 s per
worker measured in issue 42, "event loop unresponsive" in its log); with the preload it does so once at start-up,
in a thread (the worker stays responsive), and every campaign on a long-lived cluster starts at full speed.
`KernelPreload` is the same as a worker plugin, for clusters started from Python:
``client.register_plugin(KernelPreload())`` (docs/scale-out.md).
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

from approachsim.campaign.kernels import load_kernels

log = logging.getLogger("distributed.approachsim")  # under "distributed": Dask's logging config shows it


async def _load_in_thread() -> None:
    seconds = await asyncio.get_running_loop().run_in_executor(None, load_kernels)
    log.info("approachsim kernels loaded in %.1f s", seconds)


async def dask_setup(worker: Any) -> None:
    """Dask's preload hook: load the kernels in a thread of the starting worker."""
    await _load_in_thread()


try:  # the plugin base class when distributed is installed (the `dask` extra)
    from distributed.diagnostics.plugin import WorkerPlugin as _Base
except ImportError:  # pragma: no cover - without distributed the preload module is never used
    _Base = object  # type: ignore[assignment,misc]


class KernelPreload(_Base):  # type: ignore[misc,valid-type]
    """A Dask worker plugin that loads the kernels on every worker, present and future (idempotent per process)."""

    name = "approachsim-kernel-preload"

    async def setup(self, worker: Any) -> None:
        """Load the kernels in a thread of this worker."""
        await _load_in_thread()
