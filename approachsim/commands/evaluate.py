"""`approachsim evaluate PROFILE [--runs N] [--seed S] [--out DIR] [--mode closed|open] [--land] [--workers K]
[--scheduler ADDR] [--resume | --overwrite] [--no-report] [--require CAT]`: the Monte Carlo evaluation of
a profile against CAT I / II / III; with --land (closed loop) every run also flies the flare to touchdown and the
touchdown dispersion is scored against the autoland touchdown criteria (evaluate/touchdown.py, docs/touchdown.md).

Writes DIR/summary.json (design.md's output contract), DIR/details.json (intervals, ICAO columns,
integrity, FTE / TSE, time-averaged RMS), DIR/runs.parquet (one row per run), DIR/heights.parquet (per-run
error profiles against height), DIR/series/ (time series of the first evaluation.series_runs runs),
DIR/runs.jsonl + DIR/campaign.json (the resumable record), the figures and DIR/report.html; prints the
verdict table. Exit status (docs/contract.md): 0 the campaign ran; 1 the --require'd category's verdict is
not `meets` (or a pipeline stage is missing, with one line); 2 bad input, one line naming the field; 3 no run
completed, with one line giving the first failure's reason.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from approachsim.config import ProfileError

if TYPE_CHECKING:  # pragma: no cover
    from approachsim.api import CampaignOptions

def register(sub: argparse._SubParsersAction) -> None:
    """Add the `evaluate` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "evaluate", help="Monte Carlo evaluation of a profile against FAA CAT I/II/III",
        description="Runs the profile's Monte Carlo campaign and scores the navigation error at each decision height\n"
        "against the FAA 1-sigma limits (README: the verdict). Writes DIR/summary.json (docs/contract.md),\n"
        "details.json, runs.parquet, heights.parquet, series/, runs.jsonl + campaign.json (for --resume), the\n"
        "figures and report.html, and prints the verdict table.",
        examples=["approachsim evaluate profiles/default.toml --runs 4 --out out/quick",
                  "approachsim evaluate ~/approaches/default.toml --runs 200 --out out/full --workers 2",
                  "approachsim evaluate ~/approaches/default.toml --out out/full --resume",
                  "approachsim evaluate profiles/default.toml --runs 50 --land --out out/landing",
                  "approachsim evaluate profiles/default.toml --runs 300 --shard 2/3 --out out/shard2"],
    )
    p.add_argument("profile", type=Path, help="approach profile (TOML)")
    p.add_argument("--runs", type=int, default=None, help="Monte Carlo runs (default: the profile's run.runs)")
    p.add_argument("--seed", type=int, default=None, help="campaign seed (default: the profile's run.seed)")
    p.add_argument("--out", type=Path, default=None, help="output directory (default: evaluate-<profile name>)")
    p.add_argument("--mode", choices=("closed", "open"), default=None,
                   help="closed: each run flies on its own navigation; open: truth shared (default: profile)")
    p.add_argument("--land", action="store_true",
                   help="closed loop: fly every run on through the flare to touchdown and score the touchdown "
                        "dispersion (details.json touchdown, docs/touchdown.md)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler (tcp://host:port)")
    p.add_argument("--resume", action="store_true", help="continue the campaign in --out, keeping finished runs")
    p.add_argument("--overwrite", action="store_true", help="start afresh in --out, discarding a campaign there")
    p.add_argument("--shard", default=None, metavar="K/N",
                   help="run only shard K of N (a contiguous slice of the runs, the same seeds as the whole "
                        "campaign) into --out; merge the N shard directories with `approachsim merge`")
    p.add_argument("--no-report", action="store_true", help="skip figures and report.html")
    p.add_argument("--require", default=None, metavar="CAT",
                   help='exit 1 unless this category\'s verdict is meets ("CAT I", "CAT II" or "CAT III"): a CI gate')
    p.set_defaults(func=run)


def parse_require(text: str | None) -> str | None:
    """The category named by --require ("CAT II", "cat ii", "CAT2", "cat-2" ...); ProfileError otherwise."""
    if text is None:
        return None
    from approachsim.evaluate.limits import CATEGORIES

    t = re.sub(r"[\s_\-]+", "", text).upper()
    roman = {"1": "I", "2": "II", "3": "III"}
    if t.startswith("CAT") and t[3:] in roman:
        t = "CAT" + roman[t[3:]]
    for c in CATEGORIES:
        if t == c.replace(" ", ""):
            return c
    raise ProfileError(f"--require: must be one of {', '.join(repr(c) for c in CATEGORIES)}, got {text!r}")


def check_options(args: argparse.Namespace, profile: Any) -> CampaignOptions:
    """Validate the options against the profile (api.check_campaign with the options' names); ProfileError names the
    option."""
    from approachsim.api import check_campaign

    out = args.out if args.out is not None else Path(f"evaluate-{profile.name}")
    o = check_campaign(profile, runs=args.runs, seed=args.seed, mode=args.mode, land=getattr(args, "land", False),
                       workers=args.workers, scheduler=args.scheduler, out=out, resume=args.resume,
                       overwrite=args.overwrite, shard=getattr(args, "shard", None), prefix="--")
    if o.shard is not None and getattr(args, "require", None) is not None:
        raise ProfileError("--require: a shard has no verdict; give --require to `approachsim merge`")
    return o


def run(args: argparse.Namespace) -> int:
    """Run the campaign (api.evaluate_profile), write the outputs, print the verdict table."""
    from approachsim import api
    from approachsim.campaign.pipeline import PipelineUnavailable
    from approachsim.sensors.baro import temperature_note

    spec = api.ProfileSpec.from_file(args.profile)
    profile = spec.profile
    o = check_options(args, profile)
    if (b := profile.sensors.baro) is not None and (note := temperature_note(
            profile.environment.isa_dev_k, profile.runway.elevation_m, b.bias_sigma_m, b.temperature_correction,
            b.filter_scale_sigma)):
        sys.stderr.write(f"approachsim evaluate: note: {note}\n")
    require = parse_require(getattr(args, "require", None))
    try:
        res = api.evaluate_profile(spec, runs=o.runs, seed=o.seed, mode=o.mode, land=o.land, out=o.out,
                                   workers=o.workers, scheduler=o.scheduler, resume=o.resume, overwrite=args.overwrite,
                                   shard=o.shard, report=not args.no_report and o.shard is None)
    except PipelineUnavailable as e:
        sys.stderr.write(f"approachsim evaluate: {e}\n")
        return 1
    if o.shard is not None:
        return report_shard(res, o.shard, o.out, args.profile)
    return report_campaign(res, o.out, report=not args.no_report, require=require, command="evaluate")


def report_shard(res: Any, shard: tuple[int, int], out: Path, profile_path: Path) -> int:
    """Print what a shard did and how to merge; 3 when none of its runs completed."""
    failed = [r for r in res.results if not r.ok]
    first, last = res.results[0].run, res.results[-1].run
    print(f"shard {shard[0]}/{shard[1]}: runs {first}-{last}, {len(res.results) - len(failed)} completed, "
          f"{len(failed)} failed; wrote {out}")
    print(f"merge the {shard[1]} shard directories with: approachsim merge {profile_path} SHARD_DIR... --out DIR")
    if failed and len(failed) == len(res.results):
        sys.stderr.write(f"approachsim evaluate: no run of shard {shard[0]}/{shard[1]} completed; first: run "
                         f"{failed[0].run}: {failed[0].error}\n")
        return 3
    return 0


def report_campaign(res: Any, out: Path, *, report: bool, require: str | None, command: str) -> int:
    """Print the verdict table and the paths; the exit status (docs/contract.md: 3 no run completed, 1 the
    --require'd category not met, else 0)."""
    from approachsim.campaign.outputs import verdict_table

    summary, det = res.summary, res.details
    failed = [r for r in res.results if not r.ok]
    print(verdict_table(summary, det))
    if failed:
        print(f"{len(failed)} run(s) failed; first: run {failed[0].run}: {failed[0].error}")
    print(f"wrote {out / 'summary.json'}" + (f", {out / 'report.html'}" if report else ""))
    if failed and len(failed) == len(res.results):
        sys.stderr.write(
            f"approachsim {command}: no run completed ({len(failed)} failed); first: run {failed[0].run}: "
            f"{failed[0].error}\n"
        )
        return 3
    if require is not None:
        v = summary["decision_heights"][require]["verdict"]
        if v != "meets":
            sys.stderr.write(f"approachsim {command}: --require {require}: verdict is {v}, not meets\n")
            return 1
    return 0
