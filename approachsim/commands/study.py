"""`approachsim study FILE --out DIR [--workers K] [--scheduler ADDR] [--resume]`: a trade study.

Evaluates every variant of the study file (campaign/study.py documents the format) into DIR/<variant>/
(summary.json, details.json, run tables), then writes DIR/study.json, DIR/study.csv and DIR/study.png and
prints the comparison table. Bad study fields or options exit 2 with one line, before anything runs; exit 3
when not one run of any variant completed.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from approachsim.config import ProfileError

NO_RUN_COMPLETED = 3
"""Exit status when not one run of any variant completed (the evaluate command's status for the same case)."""


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `study` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "study", help="trade study: evaluate every variant of a study file and compare",
        description="Evaluates every variant of a study file (a base profile and the profile fields to vary, see\n"
        "docs/profiles.md) with the same seeds, into DIR/<variant>/ (as evaluate), then writes DIR/study.json,\n"
        "DIR/study.csv and DIR/study.png and prints the comparison. A study file is not a profile: to\n"
        "evaluate one profile use `approachsim evaluate`.",
        examples=["approachsim study studies/ins-grade-x-aids.toml --out out/study",
                  "approachsim study studies/ins-grade-x-aids.toml --out out/study --resume"],
    )
    p.add_argument("study", type=Path, help="study file (TOML)")
    p.add_argument("--out", required=True, type=Path, help="output directory")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler (tcp://host:port)")
    p.add_argument("--resume", action="store_true", help="continue an interrupted study, keeping finished runs")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Validate, run every variant (api.study_file), write and print the comparison."""
    from approachsim.api import MAX_WORKERS, require_distributed
    from approachsim.api import SCHEDULER_ADDRESS as _ADDRESS
    from approachsim.campaign.pipeline import PipelineUnavailable, require_stages
    from approachsim.campaign.study import comparison_table, load_study

    study = load_study(args.study)
    if args.workers is not None and not 1 <= args.workers <= MAX_WORKERS:
        raise ProfileError(f"--workers: must be in [1, {MAX_WORKERS}], got {args.workers}")
    if args.scheduler is not None and not _ADDRESS.match(args.scheduler):
        raise ProfileError(f"--scheduler: must be an address like tcp://host:8786, got {args.scheduler!r}")
    if args.scheduler is not None:
        require_distributed()
    if args.out.exists() and not args.out.is_dir():
        raise ProfileError(f"--out: {str(args.out)!r} exists and is not a directory")
    if args.resume and not any((args.out / v.slug / "runs.jsonl").is_file() for v in study.variants):
        raise ProfileError(
            f"--resume: no study to resume in {str(args.out)!r} (no variant has a runs.jsonl); drop --resume to start"
        )
    try:
        require_stages(study.mode)
    except PipelineUnavailable as e:
        sys.stderr.write(f"approachsim study: {e}\n")
        return 1
    from approachsim import api

    rows = api.study_file(args.study, out=args.out, workers=args.workers, scheduler=args.scheduler,
                          resume=args.resume).rows
    print(f"study {study.name}: {len(rows)} variants x {study.runs} runs, seed {study.seed}, {study.mode} loop")
    print(comparison_table(rows))
    print(f"wrote {args.out / 'study.csv'}, {args.out / 'study.json'}, {args.out / 'study.png'}")
    dead = [r["variant"] for r in rows if r["failed_runs"] >= study.runs]
    if len(dead) == len(rows):
        sys.stderr.write(f"approachsim study: no run completed in any variant (reasons: {args.out}/*/details.json)\n")
        return NO_RUN_COMPLETED
    if dead:
        sys.stderr.write(f"approachsim study: no run completed in variant(s) {', '.join(dead)}\n")
    return 0
