"""One evaluation campaign of one profile, end to end except plotting: used by evaluate, study and regress.

run the campaign (pipeline.spec_for or a given spec) -> score all runs -> write summary.json / details.json.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from approachsim.campaign.outputs import evaluate_results, write_json
from approachsim.campaign.pipeline import PipelineSpec, spec_for
from approachsim.campaign.result import RunResult
from approachsim.campaign.runner import run_campaign
from approachsim.campaign.store import profile_digest


@dataclass(frozen=True)
class Evaluation:
    """A finished evaluation: all runs, the contract summary and the details."""

    results: list[RunResult]
    summary: dict
    details: dict
    wall_s: float


def evaluate_profile(
    profile: Any,
    *,
    runs: int,
    seed: int,
    mode: str,
    out_dir: Path,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    spec: PipelineSpec | None = None,
) -> Evaluation:
    """Run and score a campaign; writes the run store, summary.json and details.json into out_dir."""
    spec = spec if spec is not None else spec_for(profile, mode)
    meta = {"profile": profile.name, "profile_digest": profile_digest(profile), "seed": seed, "mode": mode}
    if spec.land:
        meta["land"] = True  # a landing campaign is another campaign (--resume compares it; absent otherwise)
    res = run_campaign(
        profile, seed=seed, runs=runs, group_fn=spec.group_fn, group_size=spec.group_size, out_dir=out_dir,
        meta=meta, resume=resume, workers=workers, scheduler=scheduler, progress=progress,
    )
    summary, det = evaluate_results(
        res.results, profile.evaluation, profile=profile.name, seed=seed, closed_loop=spec.closed_loop,
        land=spec.land, gnss_service=_service_label(profile),
    )
    det["wall_s"] = res.wall_s
    write_json(Path(out_dir) / "summary.json", summary)
    write_json(Path(out_dir) / "details.json", det)
    return Evaluation(res.results, summary, det, res.wall_s)


def _service_label(profile: Any) -> str | None:
    """The GNSS service's label for summary.json (sensors/gnss/service.py; "military (PPS)" named), None without."""
    g = profile.sensors.gnss
    if g is None:
        return None
    if g.service is not None:
        return g.service.label
    return f"code preset {g.code}" + (" (military, PPS)" if g.code == "P(Y)" else "")
