"""One evaluation campaign of one profile, end to end except plotting: used by evaluate, study, regress and the API.

run the campaign (pipeline.spec_for or a given spec) -> score all runs -> write summary.json / details.json.
A shard (`shard=(k, n)`, campaign/shards.py) runs and stores only its slice of the runs and scores nothing: the
merge of all n shards scores the whole campaign (shards.merge_shards).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from approachsim.campaign.kernels import compile_note, mark_compiled
from approachsim.campaign.outputs import evaluate_results, write_json
from approachsim.campaign.pipeline import PipelineSpec, spec_for
from approachsim.campaign.result import RunResult
from approachsim.campaign.runner import Display, run_campaign
from approachsim.campaign.shards import merge_store, read_shards, shard_runs, write_shard_record
from approachsim.campaign.store import profile_digest


@dataclass(frozen=True)
class Evaluation:
    """A finished evaluation: all runs, the contract summary and the details (a shard: its runs, summary and
    details None)."""

    results: list[RunResult]
    summary: dict | None
    details: dict | None
    wall_s: float
    warnings: tuple[str, ...] = ()
    """Lines about the executor (a Dask worker found failing every task), beside the runs."""


def grouped(profile: Any, runs: int, mode: str) -> Any:
    """The profile with its open-loop flight groups sized for a campaign of `runs` (EvaluationConfig.group_size:
    at least five groups); closed loop and a size already small enough: the profile itself."""
    size = profile.evaluation.group_size(runs)
    if mode != "open" or size == profile.evaluation.flight_group:
        return profile
    return dataclasses.replace(profile, evaluation=dataclasses.replace(profile.evaluation, flight_group=size))


def campaign_meta(profile: Any, *, seed: int, mode: str, land: bool, shard: tuple[int, int] | None = None) -> dict:
    """campaign.json's identity of a campaign (store.IDENTITY_KEYS; the number of runs is added by the runner)."""
    meta: dict[str, Any] = {"profile": profile.name, "profile_digest": profile_digest(profile), "seed": seed,
                            "mode": mode}
    if land:
        meta["land"] = True  # a landing campaign is another campaign (--resume compares it; absent otherwise)
    if shard is not None:
        meta["shard"] = [int(shard[0]), int(shard[1])]  # a shard is another campaign too (absent otherwise)
    return meta


def kind(mode: str, land: bool) -> str:
    """The kernels' kind of a campaign (kernels.compile_note): its mode, "-land" for landing runs."""
    return mode + ("-land" if land else "")


def evaluate_profile(
    profile: Any,
    *,
    runs: int,
    seed: int,
    mode: str,
    out_dir: Path | None,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    spec: PipelineSpec | None = None,
    shard: tuple[int, int] | None = None,
) -> Evaluation:
    """Run and score a campaign; writes the run store, summary.json and details.json into out_dir (out_dir None:
    nothing is written, the results stay in memory). shard (k, n): only the k-th of n slices of the runs
    (shards.shard_runs), stored in out_dir with shard.json; nothing scored."""
    profile = grouped(profile, runs, mode)
    spec = spec if spec is not None else spec_for(profile, mode)
    if not spec.closed_loop and spec.group_size != profile.evaluation.flight_group:  # a spec made before grouped
        spec = dataclasses.replace(spec, group_size=profile.evaluation.flight_group)
    meta = campaign_meta(profile, seed=seed, mode=mode, land=spec.land, shard=shard)
    only = None if shard is None else shard_runs(runs, *shard)
    res = run_campaign(
        profile, seed=seed, runs=runs, group_fn=spec.group_fn, group_size=spec.group_size, out_dir=out_dir,
        meta=meta, resume=resume, workers=workers, scheduler=scheduler, only=only,
        progress=Display(enabled=progress, warmup=compile_note(kind(mode, spec.land))),
    )
    if any(r.ok for r in res.results):
        mark_compiled(kind(mode, spec.land))
    if shard is not None:
        if out_dir is not None:
            write_shard_record(Path(out_dir), shard, only or [], res.results, res.wall_s)
        return Evaluation(res.results, None, None, res.wall_s, res.warnings)
    summary, det = score_campaign(profile, res.results, seed=seed, closed_loop=spec.closed_loop, land=spec.land,
                                  wall_s=res.wall_s, out_dir=out_dir)
    return Evaluation(res.results, summary, det, res.wall_s, res.warnings)


def score_campaign(profile: Any, results: list[RunResult], *, seed: int, closed_loop: bool, land: bool,
                   wall_s: float | None, out_dir: Path | None) -> tuple[dict, dict]:
    """(summary, details) of all the campaign's runs in run order; written to out_dir when given."""
    summary, det = evaluate_results(results, profile.evaluation, profile=profile.name, seed=seed,
                                    closed_loop=closed_loop, land=land, gnss_service=_service_label(profile))
    det["wall_s"] = wall_s
    if out_dir is not None:
        write_json(Path(out_dir) / "summary.json", summary)
        write_json(Path(out_dir) / "details.json", det)
    return summary, det


def merge_shards(profile: Any, dirs: Sequence[Path], out_dir: Path) -> Evaluation:
    """Merge the n shard directories of one campaign of `profile` into out_dir: the single campaign's run store,
    summary.json and details.json (shards.read_shards checks them; its wall_s is the shards' sum)."""
    m0, all_runs, _ = read_shards(dirs)  # the campaign's size and mode decide its flight groups (grouped)
    profile = grouped(profile, len(all_runs), str(m0["mode"]))
    meta, results, wall = read_shards(dirs, profile)
    merge_store(dirs, out_dir, meta, results)
    land = bool(meta.get("land"))
    summary, det = score_campaign(profile, results, seed=int(meta["seed"]), closed_loop=meta["mode"] == "closed",
                                  land=land, wall_s=wall, out_dir=out_dir)
    return Evaluation(results, summary, det, wall)


def _service_label(profile: Any) -> str | None:
    """The GNSS service's label for summary.json (sensors/gnss/service.py; "military (PPS)" named), None without."""
    g = profile.sensors.gnss
    if g is None:
        return None
    if g.service is not None:
        return g.service.label
    return f"code preset {g.code}" + (" (military, PPS)" if g.code == "P(Y)" else "")
