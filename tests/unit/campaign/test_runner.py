"""Campaign runner: executors agree bit for bit, failures are recorded, kill + resume loses nothing."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from camphelp import bad_worker_run, dask_probe_run, synth_group, synth_run

from approachsim.campaign.result import RunResult
from approachsim.campaign.runner import (
    RETRY_REPRODUCED_MAX,
    Display,
    missing_path_note,
    plan_chunks,
    run_campaign,
)
from approachsim.campaign.shards import merge_store, parse_shard, read_shards, shard_runs
from approachsim.campaign.store import CampaignStore
from approachsim.config import ProfileError

HERE = Path(__file__).parent
ROOT = HERE.parents[2]


def _same(a: list[RunResult], b: list[RunResult]) -> bool:
    """Bit-identical: same code path (a run's result does not depend on the executor, the pool, the chunking, the
    store's round trip or a resume: the campaign's reproducibility contract, RunResult.same_as)."""
    return len(a) == len(b) and all(x.same_as(y) for x, y in zip(a, b, strict=True))


def _run(profile, **kw):
    kw.setdefault("progress", False)
    return run_campaign(profile, seed=kw.pop("seed", 42), runs=kw.pop("runs", 24), **kw)


def test_local_pool_matches_in_process_and_disk(tmp_path):
    prof = {"series_runs": 2}
    a = _run(prof, run_fn=synth_run, workers=1)
    b = _run(prof, run_fn=synth_run, workers=2, out_dir=tmp_path, per_task=5)
    assert _same(a.results, b.results)
    assert [r.run for r in b.results] == list(range(24))
    back = CampaignStore(tmp_path).load()
    assert _same(a.results, [back[i] for i in range(24)])
    # runs differ from one another (the seed reaches each run)
    assert len({r.scalars["mean_m"] for r in a.results}) == 24
    table = pq.read_table(tmp_path / "runs.parquet").to_pydict()
    # bit-identical: parquet stores float64 as it is
    assert table["run"] == list(range(24)) and table["mean_m"][3] == a.results[3].scalars["mean_m"]
    heights = pq.read_table(tmp_path / "heights.parquet").to_pydict()
    assert len(heights["first_m"]) == 24 * 7
    assert sorted(p.name for p in (tmp_path / "series").iterdir()) == ["run_000000.parquet", "run_000001.parquet"]


def test_dask_local_cluster_is_bit_identical(tmp_path):
    import distributed  # in the test extra
    prof = {"series_runs": 1}
    local = _run(prof, run_fn=synth_run, workers=2)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, protocol="tcp://", host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = _run(prof, run_fn=synth_run, scheduler=cluster.scheduler_address, out_dir=tmp_path)
        grouped = _run(prof, group_fn=synth_group, group_size=5, scheduler=cluster.scheduler_address)
    assert _same(local.results, remote.results)
    assert _same(local.results, grouped.results)
    assert (tmp_path / "series" / "run_000000.parquet").is_file()


def test_dask_tasks_release_their_results_and_pin_blas():
    """On Dask the client releases each task once its results are fetched (a 10^4-run campaign would otherwise
    keep every result in the workers' memory until the end) and BLAS runs single-threaded inside the task, as in
    the local pool (runner.run_task)."""
    import distributed

    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://", host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        res = _run({"sleep_s": 0.1}, run_fn=dask_probe_run, per_task=1, scheduler=cluster.scheduler_address)
    held = [r.scalars["held"] for r in res.results]
    assert all(r.ok for r in res.results) and len(held) == 24
    # one worker thread runs the 24 one-run tasks in turn: unreleased, run i's task would see about i results held
    assert max(held[12:]) < 12, held
    assert {r.scalars["blas_threads"] for r in res.results} == {1.0}


def test_bad_scheduler_address_is_a_user_error():
    with pytest.raises(ProfileError, match="--scheduler"):
        _run({}, run_fn=synth_run, scheduler="tcp://127.0.0.1:9", runs=2, scheduler_timeout_s=1.0)


def test_a_raising_run_is_recorded_and_the_rest_complete(tmp_path):
    err = io.StringIO()
    res = run_campaign({"fail_runs": (3, 17)}, seed=1, runs=20, run_fn=synth_run, workers=2, out_dir=tmp_path,
                       progress=Display(stream=err))
    assert [r.run for r in res.failed] == [3, 17]
    assert res.failed[0].error == "RuntimeError: synthetic failure in run 3 (second line)"
    assert len(res.ok) == 18
    assert "20/20 runs, 2 failed" in err.getvalue()
    table = pq.read_table(tmp_path / "runs.parquet").to_pydict()
    assert table["ok"][3] is False and "synthetic failure" in table["error"][3]
    assert np.isnan(table["mean_m"][3])
    # a failing shared group fails every run of that group only
    g = _run({"fail_group": 7}, group_fn=synth_group, group_size=5, runs=12, workers=1)
    assert [r.run for r in g.failed] == [5, 6, 7, 8, 9]
    assert all(r.error == "RuntimeError: shared flight failed" for r in g.failed)


def test_a_dying_worker_loses_only_its_own_run():
    res = run_campaign({"crash_runs": (5,)}, seed=1, runs=12, run_fn=synth_run, workers=2, per_task=1,
                       progress=False)
    assert [r.run for r in res.failed] == [5]
    assert "worker process died" in res.failed[0].error
    fresh = _run({}, run_fn=synth_run, seed=1, runs=12, workers=1)
    assert all(a.same_as(b) for a, b in zip(res.results, fresh.results, strict=True) if a.run != 5)


def test_a_real_profile_travels_to_worker_processes():
    from camphelp import profile_run

    from approachsim.profile import load_profile

    prof = load_profile(ROOT / "tests" / "data" / "default-py.toml")
    res = run_campaign(prof, seed=1, runs=4, run_fn=profile_run, workers=2, per_task=1, progress=False)
    # exact: the profile's decision height passed through (a parsed 200.0)
    assert not res.failed and all(r.scalars["dh_cat1_ft"] == 200.0 for r in res.results)


def test_groups_do_not_depend_on_what_is_left():
    assert plan_chunks([0, 1, 2, 3, 4, 5, 6], workers=2, group_size=3) == [[0, 1, 2], [3, 4, 5], [6]]
    assert plan_chunks([1, 4, 5, 9], workers=2, group_size=3) == [[1], [4, 5], [9]]
    # a small campaign inside one group is split so that both workers get work
    assert plan_chunks(list(range(20)), workers=2, group_size=25) == [list(range(10)), list(range(10, 20))]
    big = plan_chunks(list(range(1000)), workers=2, group_size=25)
    assert len(big) == 40 and all(c == list(range(c[0], c[0] + 25)) and c[0] % 25 == 0 for c in big)
    chunks = plan_chunks(list(range(100)), workers=2, group_size=None)
    assert sum(chunks, []) == list(range(100)) and len(chunks) == 8


def test_kill_half_way_then_resume_equals_uninterrupted(tmp_path):
    runs, seed = 40, 9
    prof = {"sleep_s": 0.05, "series_runs": 3}
    script = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(HERE)!r})
        from camphelp import synth_run
        from approachsim.campaign.runner import run_campaign
        run_campaign({prof!r}, seed={seed}, runs={runs}, run_fn=synth_run, workers=2, per_task=2,
                     out_dir={str(tmp_path)!r}, meta={{"seed": {seed}}}, progress=False)
        """
    )
    proc = subprocess.Popen([sys.executable, "-c", script], start_new_session=True)
    jl = tmp_path / "runs.jsonl"
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        if jl.is_file() and jl.read_text().count("\n") >= 10:
            break
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    before = CampaignStore(tmp_path).load()
    assert 10 <= len(before) < runs  # killed half-way
    with open(jl, "a") as f:  # as if killed in the middle of a write
        f.write('{"run": 39, "ok": tr')
    res = run_campaign(prof, seed=seed, runs=runs, run_fn=synth_run, workers=2, out_dir=tmp_path,
                       meta={"seed": seed}, resume=True, progress=False)
    assert res.newly_run == runs - len(before)
    fresh = _run(prof | {"sleep_s": 0.0}, run_fn=synth_run, seed=seed, runs=runs, workers=1)
    assert _same(res.results, fresh.results)
    lines = jl.read_text().splitlines()
    assert sorted(json.loads(s)["run"] for s in lines) == list(range(runs))


def test_resume_refuses_another_campaign_and_can_grow(tmp_path):
    meta = {"seed": 5, "mode": "open", "profile_digest": "abc"}
    run_campaign({}, seed=5, runs=6, run_fn=synth_run, workers=1, out_dir=tmp_path, meta=meta, progress=False)
    with pytest.raises(ProfileError, match="--resume: .* different campaign \\(seed 5, now 6\\)"):
        run_campaign({}, seed=6, runs=6, run_fn=synth_run, workers=1, out_dir=tmp_path, meta={**meta, "seed": 6},
                     resume=True, progress=False)
    grown = run_campaign({}, seed=5, runs=10, run_fn=synth_run, workers=1, out_dir=tmp_path, meta=meta,
                         resume=True, progress=False)
    assert grown.newly_run == 4 and len(grown.results) == 10


def _cluster(n: int):
    import distributed

    return distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=False, protocol="tcp://",
                                    host="127.0.0.1", dashboard_address=":0")


def test_a_dask_worker_failing_every_task_is_named_and_its_tasks_rerun_elsewhere():
    """Issue 42: a worker that raises on every task (its working directory gone) took most tasks, because it failed
    each in milliseconds, and the campaign recorded them as failed runs with a bare "No such file or directory".
    Now its wholly failed tasks are rerun on the other worker, the results are those of a healthy campaign bit for
    bit, and the worker is named once with its error (which says where it happened)."""
    with _cluster(2) as cluster:
        bad = cluster.workers[1].address
        err = io.StringIO()
        res = run_campaign({"bad_worker": 1, "sleep_s": 0.02}, seed=4, runs=16, run_fn=bad_worker_run, per_task=1,
                           scheduler=cluster.scheduler_address, progress=Display(stream=err))
    healthy = _run({}, run_fn=synth_run, seed=4, runs=16, workers=1)
    assert not res.failed and _same(res.results, healthy.results)
    assert len(res.warnings) == 1, res.warnings
    w = res.warnings[0]
    assert w.startswith(f"Dask worker {bad} failed every task it ran (first: FileNotFoundError: [Errno 2] No such "
                        "file or directory (on ")
    assert "working directory" in w and w.endswith("its tasks are rerun on other workers: fix or restart that worker")
    assert f"approachsim: {w}" in err.getvalue()


def test_runs_that_fail_everywhere_stay_failed_after_a_bounded_number_of_reruns():
    """A profile whose runs all fail is not a bad worker: the runs stay failed with their own reasons, no worker is
    named, and the probes that found it out cost at most RETRY_REPRODUCED_MAX + one per worker extra runs."""
    import camphelp

    camphelp.CALLS.clear()
    with _cluster(2) as cluster:
        res = run_campaign({}, seed=4, runs=12, run_fn=camphelp.counted_fail_run, per_task=1,
                           scheduler=cluster.scheduler_address, progress=False)
    assert len(res.failed) == 12 and not res.warnings
    assert [r.error for r in res.failed] == [f"RuntimeError: diverged in run {i}" for i in range(12)]
    assert 12 + 1 <= len(camphelp.CALLS) <= 12 + RETRY_REPRODUCED_MAX + 2, camphelp.CALLS


def test_an_error_without_a_file_name_says_where(monkeypatch, tmp_path):
    assert missing_path_note(FileNotFoundError(2, "No such file or directory", "x.toml")) == ""
    assert missing_path_note(ValueError("x")) == ""
    note = missing_path_note(FileNotFoundError(2, "No such file or directory"))
    assert f"working directory {os.getcwd()!r}; the failing call named no file" in note
    gone = tmp_path / "gone"

    def no_cwd() -> str:
        raise FileNotFoundError(2, "No such file or directory")

    monkeypatch.setattr(os, "getcwd", no_cwd)
    monkeypatch.setenv("PWD", str(gone))
    note = missing_path_note(FileNotFoundError(2, "No such file or directory"))
    assert f"its working directory {str(gone)!r} no longer exists; restart the process" in note


def test_shards_partition_the_runs():
    assert [shard_runs(10, k, 3) for k in (1, 2, 3)] == [[0, 1, 2], [3, 4, 5], [6, 7, 8, 9]]
    for runs in (1, 7, 100):
        for n in range(1, min(runs, 9) + 1):
            parts = [shard_runs(runs, k, n) for k in range(1, n + 1)]
            assert sum(parts, []) == list(range(runs)) and max(map(len, parts)) - min(map(len, parts)) <= 1
    assert parse_shard("2/3") == (2, 3) and parse_shard(" 1 / 1 ") == (1, 1)
    for bad in ("0/3", "4/3", "3", "a/b", "1/0"):
        with pytest.raises(ProfileError, match="^--shard: must be K/N"):
            parse_shard(bad)
    with pytest.raises(ProfileError, match="^--shard: 5 shards for 4 runs"):
        shard_runs(4, 1, 5)


def test_three_shards_merged_equal_one_campaign_bit_for_bit(tmp_path):
    """Shards on other executors and chunkings (a local pool of 2, grouped runs) merged: the run store of the single
    campaign, file for file (runs.jsonl in run order, the single campaign's in the order runs finished)."""
    prof, seed, runs = {"series_runs": 5}, 3, 11
    meta = {"profile_digest": "d", "seed": seed, "mode": "open"}
    one = run_campaign(prof, seed=seed, runs=runs, run_fn=synth_run, workers=1, out_dir=tmp_path / "one", meta=meta,
                       progress=False)
    dirs = [tmp_path / f"shard{k}" for k in (1, 2, 3)]
    for k, d in enumerate(dirs, start=1):
        part = run_campaign(prof, seed=seed, runs=runs, group_fn=synth_group, group_size=4, workers=2, out_dir=d,
                            meta={**meta, "shard": [k, 3]}, only=shard_runs(runs, k, 3), progress=False)
        assert [r.run for r in part.results] == shard_runs(runs, k, 3)
    got_meta, results, _ = read_shards(list(reversed(dirs)))
    assert _same(results, one.results) and got_meta == meta
    merge_store(dirs, tmp_path / "merged", got_meta, results)
    a, b = tmp_path / "one", tmp_path / "merged"
    series = [f"series/run_{i:06d}.parquet" for i in range(5)]
    for name in ("runs.parquet", "heights.parquet", "campaign.json", *series):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert sorted((b / "series").iterdir()) == [b / "series" / f"run_{i:06d}.parquet" for i in range(5)]
    assert sorted((a / "runs.jsonl").read_text().splitlines()) == sorted((b / "runs.jsonl").read_text().splitlines())
    # a shard resumed is the same shard; another shard, another campaign
    run_campaign(prof, seed=seed, runs=runs, run_fn=synth_run, workers=1, out_dir=dirs[0],
                 meta={**meta, "shard": [1, 3]}, only=shard_runs(runs, 1, 3), resume=True, progress=False)
    with pytest.raises(ProfileError, match=r"different campaign \(shard \[1, 3\], now \[2, 3\]\)"):
        run_campaign(prof, seed=seed, runs=runs, run_fn=synth_run, workers=1, out_dir=dirs[0],
                     meta={**meta, "shard": [2, 3]}, only=shard_runs(runs, 2, 3), resume=True, progress=False)
    # what merge refuses, one line naming the directory
    with pytest.raises(ProfileError, match=r"shard\(s\) 3/3 missing: give all 3"):
        read_shards(dirs[:2])
    with pytest.raises(ProfileError, match=r"are both shard 1/3"):
        read_shards([dirs[0], dirs[0], dirs[2]])
    with pytest.raises(ProfileError, match=r"is not a shard"):
        read_shards([a])
    with pytest.raises(ProfileError, match=r"^SHARD_DIR: no such file .*nowhere/campaign\.json'$"):
        read_shards([tmp_path / "nowhere"])
    lines = (dirs[1] / "runs.jsonl").read_text().splitlines()
    (dirs[1] / "runs.jsonl").write_text("\n".join(lines[:-1]) + "\n")
    with pytest.raises(ProfileError, match=r"shard 2/3 in .* is unfinished \(1 of its 4 runs missing, first \d\); "
                                           r"finish it with evaluate --shard 2/3 --resume"):
        read_shards(dirs)


def test_the_dask_preload_loads_the_kernels_on_every_worker_before_a_task(monkeypatch):
    """campaign/dask_preload.py: as a worker plugin (and `dask worker --preload`), it runs kernels.load_kernels on
    each worker, in a thread (the worker's event loop stays free), before the client submits anything."""
    import threading

    from distributed import Client

    from approachsim.campaign import dask_preload

    loaded: list[tuple[str, bool]] = []

    def fake_load() -> float:
        loaded.append((threading.current_thread().name, threading.current_thread() is threading.main_thread()))
        return 0.0

    monkeypatch.setattr(dask_preload, "load_kernels", fake_load)
    with _cluster(2) as cluster, Client(cluster.scheduler_address) as client:
        client.register_plugin(dask_preload.KernelPreload())
        assert len(loaded) == 2 and not any(main for _, main in loaded)
        res = _run({}, run_fn=synth_run, runs=4, scheduler=cluster.scheduler_address)
    assert len(res.ok) == 4 and len(loaded) == 2


def test_a_task_that_cannot_start_fails_its_runs_with_the_reason_and_the_campaign_completes():
    """A task that cannot be unpickled (a worker without the package; here the scheduler, which deserializes the
    graph first in this Dask version) raises on the cluster, not in a run: its runs fail with the cluster's reason and
    where it happened (the worker's address, '?' when no worker got it), and the campaign goes on to the end."""
    from camphelp import Unloadable

    with _cluster(2) as cluster:
        addresses = {w.address for w in cluster.workers.values()}
        res = run_campaign(Unloadable(), seed=1, runs=4, run_fn=synth_run, per_task=1,
                           scheduler=cluster.scheduler_address, progress=False)
    assert [r.run for r in res.failed] == [0, 1, 2, 3] and not res.warnings
    for r in res.failed:
        head, _, rest = r.error.partition(": ")
        assert head.removeprefix("task failed on Dask worker ") in addresses | {"?"}, r.error
        assert "No module named 'approachsim'" in rest or "deserialization" in rest, r.error
