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
from camphelp import dask_probe_run, synth_group, synth_run

from approachsim.campaign.result import RunResult
from approachsim.campaign.runner import plan_chunks, run_campaign
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
                       progress_stream=err)
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

    prof = load_profile(ROOT / "profiles" / "default.toml")
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
