"""Compile a campaign's kernels on every worker at once, each a share, on a cold numba cache.

Numba compiles a kernel the first time Python calls it with new argument types, so on a cold cache (a fresh
install, or an edit under core/) every worker of a campaign compiles the same kernels in the same order at the
same time: on 2 cores, about 60 s of CPU each, the whole first `evaluate` waiting on it. A *manifest* lists the
top-level compilations of one kind of run (the kernel, its argument types as numba typed them, and the CPU seconds
it took when recorded), recorded by tools/kernel_manifest.py from a real run on a cold cache and shipped beside this
module. Before its first task, worker k of W compiles share k of the manifest (longest first, greedy, so the shares
take about the same time) with `Dispatcher.compile`, which saves to the file cache: a kernel another worker
compiled is then loaded from disk (numba looks there before compiling), so the W workers compile in parallel
instead of W times the same. On a warm cache `compile` only loads what is there (milliseconds).

The manifest changes nothing a run computes: the same kernels with the same types, compiled earlier. A stale entry
(a kernel renamed, its argument types changed) is skipped or compiles a variant no run uses (a one-time cost on a
cold cache); tests/unit/test_core_warm.py checks the shipped manifest against a run of the default profile.
"""

from __future__ import annotations

import importlib
import pickle
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from approachsim.core.jit import entries_expected

MANIFEST_DIR = Path(__file__).parent / "manifests"


@dataclass(frozen=True)
class Entry:
    """One top-level compilation: core module, function name, numba argument types, CPU seconds when recorded."""

    module: str
    name: str
    args: tuple
    cost_s: float


def manifest_path(kind: str) -> Path:
    """The shipped manifest of a kind of run ('closed': a closed-loop evaluate with the integrity bank; 'open': the
    open loop's)."""
    return MANIFEST_DIR / f"{kind}.pkl"


def load(kind: str) -> list[Entry]:
    """The manifest of `kind`; empty when there is none or it cannot be read with this numba (then nothing is
    compiled ahead and the campaign compiles as it goes)."""
    try:
        with open(manifest_path(kind), "rb") as f:
            return [Entry(*e) for e in pickle.load(f)["entries"]]
    except (OSError, pickle.UnpicklingError, AttributeError, ImportError, EOFError, TypeError, KeyError):
        return []


def save(kind: str, entries: Sequence[Entry], numba_version: str) -> Path:
    """Write a manifest (tools/kernel_manifest.py)."""
    MANIFEST_DIR.mkdir(exist_ok=True)
    path = manifest_path(kind)
    rows = [(e.module, e.name, e.args, round(e.cost_s, 2)) for e in entries]
    with open(path, "wb") as f:
        pickle.dump({"numba": numba_version, "entries": rows}, f, protocol=4)
    return path


@contextmanager
def record() -> Iterator[list[Entry]]:
    """Collect the top-level compilations (kernels called from Python) made inside the block, with the CPU seconds
    each took including what it compiled beneath it; on a warm cache nothing compiles and the list stays empty."""
    from numba.core import event

    found: list[Entry] = []
    stack: list[tuple[Any, float]] = []

    class _Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            stack.append((ev.data["dispatcher"], time.process_time()))

        def on_end(self, ev: Any) -> None:
            disp, t0 = stack.pop()
            if not stack and disp.py_func.__module__.startswith(__package__ + "."):
                found.append(Entry(disp.py_func.__module__, disp.py_func.__name__, tuple(ev.data["args"]),
                                   time.process_time() - t0))

    listener = _Listener()
    event.register("numba:compile", listener)
    try:
        yield found
    finally:
        event.unregister("numba:compile", listener)


def shares(entries: Sequence[Entry], n: int) -> list[list[Entry]]:
    """Split entries into n shares of about equal recorded cost (longest processing time first, each to the share
    with the least so far); deterministic."""
    out: list[list[Entry]] = [[] for _ in range(max(n, 1))]
    load_s = [0.0] * len(out)
    for e in sorted(entries, key=lambda e: (-e.cost_s, e.module, e.name)):
        k = min(range(len(out)), key=lambda i: (load_s[i], i))
        out[k].append(e)
        load_s[k] += e.cost_s
    return out


def compile_entries(entries: Sequence[Entry], manifest: Sequence[Entry] | None = None) -> int:
    """Compile (or load from the file cache) each entry's kernel for its argument types; returns how many are
    ready. An entry that no longer resolves or types is skipped: the run compiles what it needs as it goes. A
    kernel of the manifest (default: entries) that a bigger one calls is compiled as its entry when first typed
    (core/jit.entries_expected), so it compiles once whichever comes first."""
    ready = 0
    with entries_expected((e.module, e.name, tuple(e.args)) for e in (entries if manifest is None else manifest)):
        for e in entries:
            try:
                disp = getattr(importlib.import_module(e.module), e.name)
                disp.compile(e.args)
                ready += 1
            except Exception:  # noqa: BLE001 - a stale entry must never stop a campaign
                continue
    return ready


def compile_share(kind: str, counter: Any, workers: int) -> None:
    """A process pool's initializer: take the next share number from counter (a multiprocessing.Value shared by
    the pool's workers) and compile that share of the `kind` manifest."""
    with counter.get_lock():
        k = counter.value
        counter.value += 1
    if k < workers:
        entries = load(kind)
        compile_entries(shares(entries, workers)[k], entries)
