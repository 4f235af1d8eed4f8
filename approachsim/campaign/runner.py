"""The generic Monte Carlo campaign runner: local process pool by default, an existing Dask cluster on request.

A campaign is N runs of a picklable per-run function `run_fn(profile, seed, run_index) -> RunResult`
(or, where runs share work, a group function `group_fn(profile, seed, run_indices) -> list[RunResult]`,
called on fixed, executor-independent groups of consecutive run indices). Every run draws its randomness
from (seed, run_index) only (approachsim.seeding), so the result of a run does not depend on the executor,
the worker, the chunking or on resuming: local and Dask results are bit-identical.

A run that raises is recorded as failed with its error and the campaign goes on. Results are appended to
the store as each task finishes, so `resume=True` after an interruption reruns only what had not finished.
"""

from __future__ import annotations

import copyreg
import math
import multiprocessing
import os
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, TextIO

from threadpoolctl import threadpool_limits

from approachsim.campaign.result import RunResult
from approachsim.campaign.store import CampaignStore
from approachsim.config import ProfileError
from approachsim.core.warm import compile_share

RunFn = Callable[[Any, int, int], RunResult]
GroupFn = Callable[[Any, int, Sequence[int]], list[RunResult]]


class SchedulerError(ProfileError):
    """The Dask scheduler address cannot be reached (a user mistake: exit 2)."""


def make_mappingproxy(d: dict) -> MappingProxyType:
    """Rebuild a read-only mapping after unpickling."""
    return MappingProxyType(d)


def _reduce_mappingproxy(m: MappingProxyType) -> tuple:
    return make_mappingproxy, (dict(m),)


def register_pickling() -> None:
    """Let read-only mappings (types.MappingProxyType, used in frozen configs) be pickled to workers.

    Profiles travel to worker processes and Dask workers by pickle; the standard library cannot pickle a
    mappingproxy. This registers the obvious reduction (rebuild from a dict copy) with copyreg; idempotent.
    """
    copyreg.pickle(MappingProxyType, _reduce_mappingproxy)


def _one_line(e: BaseException) -> str:
    """`Type: message` on one line; an OSError that names no file says what it could not find (issue 42: a Dask
    worker whose working directory had been deleted failed every task with a bare "[Errno 2] No such file or
    directory")."""
    return f"{type(e).__name__}: {' '.join(str(e).split())}{missing_path_note(e)}"


def missing_path_note(e: BaseException) -> str:
    """'' unless `e` is an OSError without a file name; then where the error happened, in words: the working
    directory when it no longer exists (os.getcwd fails), else the working directory and that the failing call gave
    no path."""
    if not isinstance(e, OSError) or e.filename is not None:
        return ""
    import socket

    host = socket.gethostname()
    try:
        cwd = os.getcwd()
    except OSError:
        gone = os.environ.get("PWD", "?")
        return (f" (on {host}, process {os.getpid()}: its working directory {gone!r} no longer exists; restart the "
                "process from an existing directory)")
    return f" (on {host}, process {os.getpid()}, working directory {cwd!r}; the failing call named no file)"


def run_task(run_fn: RunFn | None, group_fn: GroupFn | None, profile: Any, seed: int, runs: Sequence[int]) -> list:
    """Execute a chunk of runs in the worker; every failure becomes a failed RunResult (never an exception).

    BLAS runs single-threaded in the task (threadpoolctl): the campaign already uses every core with one worker
    per core, and an idle OpenBLAS thread spins on a core the other worker needs (measured: a flight's CPU time
    1.2x its wall time with the default two BLAS threads, equal with one)."""
    with threadpool_limits(limits=1):
        return _run_task(run_fn, group_fn, profile, seed, runs)


def _run_task(run_fn: RunFn | None, group_fn: GroupFn | None, profile: Any, seed: int, runs: Sequence[int]) -> list:
    if group_fn is not None:
        try:
            out = list(group_fn(profile, seed, list(runs)))
        except Exception as e:  # the group's shared work failed: every run of it fails with that reason
            return [RunResult.failed(i, _one_line(e)) for i in runs]
        got = {r.run for r in out}
        missing = [RunResult.failed(i, "group function returned no result for this run") for i in runs if i not in got]
        return out + missing
    results = []
    for i in runs:
        try:
            r = run_fn(profile, seed, i)
            if not isinstance(r, RunResult) or r.run != i:
                raise TypeError(f"run function must return RunResult(run={i}), got {r!r:.80}")
        except Exception as e:
            r = RunResult.failed(i, _one_line(e))
        results.append(r)
    return results


PLAIN_INTERVAL_S = 10.0
"""Seconds between the plain progress lines written when stderr is not a terminal (a log file, CI)."""


@dataclass
class Progress:
    """Campaign progress on stderr: done / total runs, failures, elapsed and remaining time.

    On a terminal: a tqdm bar redrawn in place. Otherwise (redirected to a log, CI): one plain line at the start,
    then at most one every PLAIN_INTERVAL_S seconds, and one at the end, never a carriage return. `label` names
    what runs (a study's variant).
    """

    total: int
    done: int = 0
    failed: int = 0
    stream: TextIO | None = None
    enabled: bool = True
    label: str = ""
    interval_s: float = PLAIN_INTERVAL_S
    warmup: str | None = None
    """Said instead of a time estimate until the first runs finish (the kernels being compiled: kernels.py), after
    which the estimate counts only the time since those first runs finished (so the compile does not inflate it)."""
    _t0: float = 0.0
    _last: float = -1.0
    _start_done: int = 0
    _bar: Any = None
    _t_first: float | None = None
    _first_done: int = 0

    def _stream(self) -> TextIO:
        return self.stream or sys.stderr

    def _is_tty(self) -> bool:
        isatty = getattr(self._stream(), "isatty", None)
        try:
            return bool(isatty and isatty())
        except ValueError:  # a closed stream
            return False

    def start(self) -> None:
        """Start the clock and show the initial state."""
        self._t0 = time.monotonic()
        self._start_done = self.done
        if not self.enabled:
            return
        if self._is_tty():
            if self.warmup and self.done < self.total:  # the bar (and its rate) starts once the first runs finish
                s = self._stream()
                s.write(f"{self.label or 'runs'}: {self.done}/{self.total} runs, {self.warmup}\n")
                s.flush()
            else:
                self._open_bar()
        else:
            self.draw(force=True)

    def _open_bar(self) -> None:
        from tqdm import tqdm

        self._bar = tqdm(total=self.total, initial=self.done, desc=self.label or "runs", unit="run",
                         file=self._stream(), dynamic_ncols=True, leave=True, smoothing=0.1)
        self._bar.set_postfix_str(f"{self.failed} failed", refresh=True)
        if self.done >= self.total:
            self._close()

    def update(self, results: Sequence[RunResult]) -> None:
        """Count finished runs (failed ones too) and redraw."""
        self.done += len(results)
        self.failed += sum(not r.ok for r in results)
        if self._t_first is None:
            self._t_first = time.monotonic()
            self._first_done = self.done
            if self.warmup and self.enabled and self._is_tty():
                self._open_bar()
                return
        if self._bar is not None:
            self._bar.set_postfix_str(f"{self.failed} failed", refresh=False)
            self._bar.update(len(results))
            if self.done >= self.total:
                self._close()
        else:
            self.draw()

    def _close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def line(self) -> str:
        """The plain progress line: '<label>: 3/20 runs, 0 failed, 12 s elapsed, about 68 s left'."""
        now = time.monotonic()
        el = now - self._t0
        new = self.done - self._start_done
        eta = el / new * (self.total - self.done) if new > 0 else float("nan")
        left = "done" if self.done >= self.total else (f"about {eta:.0f} s left" if math.isfinite(eta) else "")
        if self.warmup and self.done < self.total:
            if self._t_first is None:
                left = self.warmup
            elif self.done > self._first_done:  # the rate since the first runs finished: the compile left out
                eta = (now - self._t_first) / (self.done - self._first_done) * (self.total - self.done)
                left = f"about {eta:.0f} s left"
            else:
                left = f"kernels ready after {self._t_first - self._t0:.0f} s, time estimate after the next runs"
        head = f"{self.label}: " if self.label else ""
        tail = f", {left}" if left else ""
        return f"{head}{self.done}/{self.total} runs, {self.failed} failed, {el:.0f} s elapsed{tail}"

    def draw(self, force: bool = False) -> None:
        """Plain mode: write a line when forced, at the end, or when interval_s has passed since the last one."""
        if not self.enabled or self._bar is not None:
            return
        now = time.monotonic()
        if not force and self.done < self.total and now - self._last < self.interval_s:
            return
        self._last = now
        s = self._stream()
        s.write(self.line() + "\n")
        s.flush()


def plan_chunks(todo: Sequence[int], *, workers: int, group_size: int | None, per_task: int | None = None) -> list:
    """Split the runs to do into tasks of consecutive runs, never crossing a group (g*size .. (g+1)*size-1).

    Tasks hold per_task runs (default: enough for about 4 tasks per worker, at most 32, at most a group), so a
    small campaign still uses every worker while a large one keeps whole groups together.
    """
    todo = sorted(todo)
    if per_task is None:
        per_task = max(1, min(32, math.ceil(len(todo) / (4 * max(workers, 1)))))
        if group_size:
            per_task = max(per_task, math.ceil(len(todo) / max(workers, 1)))
    if group_size:
        per_task = min(per_task, group_size)
    chunks: list[list[int]] = []
    for i in todo:
        if chunks and len(chunks[-1]) < per_task and (not group_size or chunks[-1][0] // group_size == i // group_size):
            chunks[-1].append(i)
        else:
            chunks.append([i])
    return chunks


CRASH = "worker process died while running this run's task (a crash or out of memory)"


def kernels_of(fn: Any) -> str | None:
    """The kernel manifest (core/warm.py) a run or group function names in its `kernels` attribute, looking through
    functools.partial; None: it names none."""
    return getattr(fn, "kernels", None) or getattr(getattr(fn, "func", None), "kernels", None)


def _pool_round(tasks: list, workers: int, args: tuple, ctx) -> Iterator[tuple[list, list[RunResult] | None]]:
    """Run tasks on a fresh pool; yields (task, results) or (task, None) for tasks lost to a dead worker.

    When the campaign's function names a kernel manifest, each worker first compiles its share of it
    (core/warm.py): on a cold numba cache the workers compile in parallel instead of each compiling everything."""
    run_fn, group_fn, profile, seed = args
    n = min(workers, len(tasks))
    kind = kernels_of(group_fn or run_fn)
    warm: dict[str, Any] = {}
    if kind is not None and n > 1 and ctx is not None:
        warm = {"initializer": compile_share, "initargs": (kind, ctx.Value("i", 0), n)}
    with ProcessPoolExecutor(max_workers=n, mp_context=ctx, **warm) as pool:
        futures = {pool.submit(run_task, run_fn, group_fn, profile, seed, t): t for t in tasks}
        while futures:
            finished, _ = wait(futures, return_when=FIRST_COMPLETED)
            for f in finished:
                t = futures.pop(f)
                try:
                    yield t, f.result()
                except BrokenProcessPool:
                    yield t, None


def _local(tasks: list, workers: int, args: tuple) -> Iterator[list[RunResult]]:
    run_fn, group_fn, profile, seed = args
    if workers <= 1 or len(tasks) <= 1:
        for t in tasks:
            yield run_task(run_fn, group_fn, profile, seed, t)
        return
    ctx = multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None
    # a worker that dies (segfault, OOM kill) breaks the pool and every task in flight: rerun those on a new
    # pool, and what breaks it again alone, one task at a time, so only the culprit's runs are lost
    lost: list = []
    for t, res in _pool_round(tasks, workers, args, ctx):
        if res is None:
            lost.append(t)
        else:
            yield res
    again: list = []
    if lost:
        for t, res in _pool_round(lost, workers, args, ctx):
            if res is None:
                again.append(t)
            else:
                yield res
    for t in again:
        for _, res in _pool_round([t], 1, args, ctx):
            yield res if res is not None else [RunResult.failed(i, CRASH) for i in t]


def _connect(address: str, timeout_s: float):
    """A dask.distributed Client on an existing scheduler; SchedulerError (exit 2) when it cannot connect."""
    try:
        from distributed import Client
    except ImportError as e:  # pragma: no cover - distributed is a declared dependency
        raise SchedulerError(f"--scheduler: dask.distributed is not installed ({e})") from None
    try:
        return Client(address, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError, ValueError) as e:
        raise SchedulerError(f"--scheduler: cannot connect to {address!r} ({_one_line(e)})") from None


def _dask_task(run_fn: RunFn | None, group_fn: GroupFn | None, profile: Any, seed: int,
               runs: Sequence[int]) -> tuple[str, list]:
    """run_task on a Dask worker: (the worker's address, the results), so the client can tell a worker that fails
    every task from runs that fail on their own (_WorkerHealth)."""
    from distributed import get_worker

    try:
        where = str(get_worker().address)
    except ValueError:  # pragma: no cover - not on a worker (a client-side fallback)
        where = "?"
    return where, run_task(run_fn, group_fn, profile, seed, runs)


RETRY_REPRODUCED_MAX = 2
"""Probes (_WorkerHealth) that may fail on another worker too before wholly failed tasks are taken as the runs' own
failures (a profile whose approaches fail) and stored as they come, without reruns."""


@dataclass
class _WorkerHealth:
    """Which Dask workers fail every task they get (issue 42: workers whose working directory was gone failed each
    task in milliseconds and so took 238 of 256 runs, all recorded as failed).

    A task whose runs all failed, on a worker that has not completed a run yet, is suspect. The first such task of a
    worker is rerun on another worker (a probe) and the worker's next ones are held back until the probe answers:
    when the probe completes runs, the worker is bad (named on stderr once, with its first error) and its held and
    later wholly failed tasks are all rerun elsewhere; when the probe fails too, the failures are the runs' own
    (counted: after RETRY_REPRODUCED_MAX of them nothing is probed any more), its result and the held tasks are
    stored, or the next held task probes again. A campaign whose runs all fail costs at most RETRY_REPRODUCED_MAX
    plus one per worker extra tasks; a healthy one none."""

    ok: dict[str, int] = field(default_factory=dict)
    """Tasks with a completed run, per worker."""
    bad: dict[str, str] = field(default_factory=dict)
    """Workers found failing every task: their first error."""
    first_error: dict[str, str] = field(default_factory=dict)
    probing: set[str] = field(default_factory=set)
    """Workers with a probe in flight."""
    held: dict[str, list] = field(default_factory=dict)
    """Per worker under probe, its wholly failed tasks waiting for the probe's answer: (task, results)."""
    reproduced: int = 0

    def first(self, worker: str, t: list, res: list[RunResult]) -> str:
        """What to do with a task's results from its first run: "store", "rerun" (elsewhere), "probe" (rerun
        elsewhere, the worker's probe) or "hold"."""
        if any(r.ok for r in res):
            self.ok[worker] = self.ok.get(worker, 0) + 1
            return "store"
        if not res:
            return "store"
        self.first_error.setdefault(worker, str(res[0].error))
        if worker in self.bad:
            return "rerun"
        if self.ok.get(worker, 0) > 0 or self.reproduced >= RETRY_REPRODUCED_MAX:
            return "store"
        if worker in self.probing:
            self.held.setdefault(worker, []).append((t, res))
            return "hold"
        self.probing.add(worker)
        return "probe"

    def answer(self, probed: str, where: str, res: list[RunResult]) -> tuple[str | None, list]:
        """A probe of worker `probed` came back from worker `where`: (the line naming `probed` when it is found bad,
        else None; its held tasks to act on: rerun them when bad, else store them or probe again)."""
        self.probing.discard(probed)
        if any(r.ok for r in res):
            self.ok[where] = self.ok.get(where, 0) + 1
            new = probed not in self.bad
            self.bad[probed] = self.first_error.get(probed, "?")
            line = (f"Dask worker {probed} failed every task it ran (first: {self.bad[probed]}); its tasks are rerun "
                    "on other workers: fix or restart that worker") if new else None
            return line, self.held.pop(probed, [])
        self.reproduced += 1
        return None, self.held.pop(probed, [])


def _erred_on(client: Any, key: Any) -> str:
    """The worker a Dask task erred on (the scheduler's record), '?' when it cannot be told."""
    def find(dask_scheduler: Any, key: Any = key) -> str:
        ts = dask_scheduler.tasks.get(key)
        where = getattr(ts, "erred_on", None) if ts is not None else None
        return next(iter(where)) if where else "?"

    try:
        return str(client.run_on_scheduler(find))
    except Exception:  # noqa: BLE001 - best effort: the message then says '?'
        return "?"


def _dask(client: Any, tasks: list, args: tuple, warn: Callable[[str], None]) -> Iterator[list[RunResult]]:
    """Submit every task, yield each task's results as it finishes and release it on the cluster.

    A finished task's results stay in its worker's memory while the client holds its future: releasing each
    one once fetched keeps the workers' memory flat (with the integrity bank a run's result is about 90 kB,
    most of it its dense integrity histograms: 0.9 GB per 10^4 runs otherwise held on the workers until the end).
    BLAS is pinned to one thread inside every task by run_task, on Dask workers as in the local pool.
    A worker that fails every task it gets is found and its tasks rerun on the others (_WorkerHealth); a task that
    raises on the worker outside the runs (it cannot be unpickled there, say) counts as wholly failed, its runs'
    reason naming the worker."""
    from distributed import as_completed

    try:
        run_fn, group_fn, profile, seed = args
        health = _WorkerHealth()
        origin: dict[Any, tuple[list, str | None]] = {}
        pending = as_completed()

        def submit(t: list, avoid: set[str], probe_of: str | None = None) -> bool:
            kw: dict[str, Any] = {}
            if avoid:
                others = [w for w in client.scheduler_info().get("workers", {}) if w not in avoid]
                if not others:
                    return False
                kw = {"workers": others, "allow_other_workers": False}
            f = client.submit(_dask_task, run_fn, group_fn, profile, seed, t, pure=False, **kw)
            origin[f] = (t, probe_of)
            pending.add(f)
            return True

        for t in tasks:
            submit(t, set())
        for f in pending:
            t, probe_of = origin.pop(f)
            try:
                worker, res = f.result()
            except Exception as e:  # noqa: BLE001 - the task itself raised on the worker
                worker = _erred_on(client, f.key)
                res = [RunResult.failed(i, f"task failed on Dask worker {worker}: {_one_line(e)}") for i in t]
            f.release()
            if probe_of is not None:
                line, held = health.answer(probe_of, worker, res)
                if line is not None:
                    warn(line)
                yield res
                for i, (ht, hres) in enumerate(held):
                    if probe_of in health.bad:
                        if not submit(ht, {probe_of, *health.bad}):
                            yield hres
                    elif i == 0 and health.reproduced < RETRY_REPRODUCED_MAX:
                        health.probing.add(probe_of)
                        health.held[probe_of] = held[1:]
                        if not submit(ht, {probe_of, *health.bad}, probe_of):
                            health.probing.discard(probe_of)
                            yield from (r for _, r in health.held.pop(probe_of, []))
                            yield hres
                        break
                    else:
                        yield hres
                continue
            action = health.first(worker, t, res)
            if action == "rerun" and submit(t, {worker, *health.bad}):
                continue
            if action == "probe":
                if submit(t, {worker, *health.bad}, worker):
                    continue
                health.probing.discard(worker)
            if action == "hold":
                continue
            yield res
        for held in health.held.values():  # nothing left to answer them (cannot happen: a probe is in flight)
            for _, hres in held:
                yield hres
    finally:
        client.close()


@dataclass(frozen=True)
class Display:
    """How a campaign shows its progress: enabled, the stream (None: stderr), the campaign's label (empty: the
    profile's name) and the words shown until the first runs finish (Progress.warmup, e.g. that kernels compile)."""

    enabled: bool = True
    stream: TextIO | None = None
    label: str = ""
    warmup: str | None = None


@dataclass(frozen=True)
class CampaignResult:
    """All runs of a campaign in run order (0..runs-1); newly_run counts the runs executed this time."""

    results: list[RunResult]
    newly_run: int
    wall_s: float
    warnings: tuple[str, ...] = ()
    """What went wrong beside the runs (a Dask worker found failing every task), one line each."""

    @property
    def failed(self) -> list[RunResult]:
        return [r for r in self.results if not r.ok]

    @property
    def ok(self) -> list[RunResult]:
        return [r for r in self.results if r.ok]


def run_campaign(
    profile: Any,
    *,
    seed: int,
    runs: int,
    run_fn: RunFn | None = None,
    group_fn: GroupFn | None = None,
    group_size: int | None = None,
    out_dir: Path | None = None,
    meta: Mapping[str, Any] | None = None,
    resume: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    per_task: int | None = None,
    progress: bool | Display = True,
    scheduler_timeout_s: float = 10.0,
    only: Sequence[int] | None = None,
) -> CampaignResult:
    """Run runs 0..runs-1 (those not already in out_dir when resuming) and return them all, in order.

    only: run just these run indices of the campaign of `runs` (a shard, campaign/shards.py); they draw the same
    random numbers as in the whole campaign, and only they are returned and stored. progress: whether to show it, or
    a Display (its stream, label and warmup words).

    Exactly one of run_fn / group_fn (with group_size). workers: local processes (default all cores; 1 runs
    in this process). scheduler: address of an existing Dask scheduler instead of the local pool.
    The progress display names the campaign by Display.label (default: the profile's name, which for a study
    variant is "<base>[<variant>]").
    """
    if (run_fn is None) == (group_fn is None):
        raise ValueError("give exactly one of run_fn and group_fn")
    show = progress if isinstance(progress, Display) else Display(enabled=progress)
    if group_fn is not None and not group_size:
        raise ValueError("group_fn needs group_size")
    workers = workers or os.cpu_count() or 1
    register_pickling()
    # connect first: a bad address fails before any output is written or an existing store is touched
    client = _connect(scheduler, scheduler_timeout_s) if scheduler else None
    store = CampaignStore(out_dir) if out_dir is not None else None
    done: dict[int, RunResult] = {}
    if store is not None:
        done = store.start({**(meta or {}), "runs": runs}, resume=resume)
    wanted = list(range(runs)) if only is None else sorted(set(only))
    if wanted and not 0 <= wanted[0] <= wanted[-1] < runs:
        raise ValueError(f"only: run indices must be in [0, {runs}), got {wanted[0]}..{wanted[-1]}")
    keep = set(wanted)
    done = {i: r for i, r in done.items() if i in keep}
    todo = [i for i in wanted if i not in done]
    tasks = plan_chunks(todo, workers=workers, group_size=group_size if group_fn else None, per_task=per_task)
    # a group function gets some runs of one group: a run's result must not depend on which others it gets
    bar = Progress(total=len(wanted), done=len(done), failed=sum(not r.ok for r in done.values()),
                   stream=show.stream, enabled=show.enabled, label=show.label or str(getattr(profile, "name", "")),
                   warmup=show.warmup if todo else None)
    t0 = time.monotonic()
    bar.start()
    args = (run_fn, group_fn, profile, seed)
    warnings: list[str] = []

    def warn(line: str) -> None:
        warnings.append(line)
        s = show.stream or sys.stderr
        s.write(f"approachsim: {line}\n")
        s.flush()

    source = _dask(client, tasks, args, warn) if client is not None else _local(tasks, workers, args)
    newly = 0
    for chunk in source:
        if store is not None:
            store.append(chunk)
        for r in chunk:
            done[r.run] = r
        newly += len(chunk)
        bar.update(chunk)
    results = [done[i] for i in wanted]
    if store is not None:
        store.write_tables(results)
    return CampaignResult(results=results, newly_run=newly, wall_s=time.monotonic() - t0, warnings=tuple(warnings))
