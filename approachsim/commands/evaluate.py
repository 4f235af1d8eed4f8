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
import os
import re
import sys
from pathlib import Path

from approachsim.config import ProfileError

MAX_RUNS = 100000
MAX_WORKERS = 1024
_ADDRESS = re.compile(r"^(tcp|tls|inproc|ws|wss|ucx)://\S+$|^[A-Za-z0-9_.\-\[\]:]+:\d+$")


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
                  "approachsim evaluate profiles/default.toml --runs 50 --land --out out/landing"],
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
    p.add_argument("--no-report", action="store_true", help="skip figures and report.html")
    p.add_argument("--require", default=None, metavar="CAT",
                   help='exit 1 unless this category\'s verdict is meets ("CAT I", "CAT II" or "CAT III"): a CI gate')
    p.set_defaults(func=run)


def require_distributed() -> None:
    """--scheduler needs dask.distributed (the optional `dask` extra); ProfileError saying how to install it."""
    import importlib.util

    if importlib.util.find_spec("distributed") is None:
        raise ProfileError("--scheduler: needs dask.distributed, not installed: pip install approachsim[dask]")


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


def check_options(args: argparse.Namespace, profile) -> tuple[int, int, str, Path]:
    """Validate the options against the profile: (runs, seed, mode, out); ProfileError names the option."""
    runs = profile.run.runs if args.runs is None else args.runs
    if not 1 <= runs <= MAX_RUNS:
        raise ProfileError(f"--runs: must be in [1, {MAX_RUNS}], got {runs}")
    seed = profile.run.seed if args.seed is None else args.seed
    if not 0 <= seed < 2**63:
        raise ProfileError(f"--seed: must be in [0, 2^63), got {seed}")
    mode = profile.run.mode if args.mode is None else args.mode
    if getattr(args, "land", False) and mode != "closed":
        raise ProfileError("--land: landing runs are flown closed loop only (each run lands on its own navigation); "
                           f"use --mode closed (the mode is {mode})")
    if args.workers is not None and not 1 <= args.workers <= MAX_WORKERS:
        raise ProfileError(f"--workers: must be in [1, {MAX_WORKERS}], got {args.workers}")
    if args.scheduler is not None:
        if args.workers is not None:
            raise ProfileError("--workers: not used with --scheduler (the Dask cluster has its own workers)")
        if not _ADDRESS.match(args.scheduler):
            raise ProfileError(f"--scheduler: must be an address like tcp://host:8786, got {args.scheduler!r}")
        require_distributed()
    out = args.out if args.out is not None else Path(f"evaluate-{profile.name}")
    if out.exists() and not out.is_dir():
        raise ProfileError(f"--out: {str(out)!r} exists and is not a directory")
    if args.resume and args.overwrite:
        raise ProfileError("--overwrite: cannot be combined with --resume")
    jl = out / "runs.jsonl"
    if args.resume and not jl.is_file():
        raise ProfileError(
            f"--resume: no campaign to resume in {str(out)!r} (no runs.jsonl); drop --resume to start one"
        )
    if not args.resume and not args.overwrite and jl.is_file() and jl.stat().st_size > 0:
        raise ProfileError(
            f"--out: {str(out)!r} already holds a campaign; add --resume to continue it, --overwrite to discard it, "
            "or choose another --out"
        )
    return runs, seed, mode, out


def run(args: argparse.Namespace) -> int:
    """Run the campaign, write the outputs, print the verdict table."""
    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.campaign.outputs import verdict_table
    from approachsim.campaign.pipeline import PipelineUnavailable, spec_for
    from approachsim.profile import load_profile
    from approachsim.sensors.baro import temperature_note

    profile = load_profile(args.profile)
    runs, seed, mode, out = check_options(args, profile)
    if (b := profile.sensors.baro) is not None and (note := temperature_note(
            profile.environment.isa_dev_k, profile.runway.elevation_m, b.bias_sigma_m, b.temperature_correction)):
        sys.stderr.write(f"approachsim evaluate: note: {note}\n")
    require = parse_require(getattr(args, "require", None))
    try:
        spec = spec_for(profile, mode, land=getattr(args, "land", False))
    except PipelineUnavailable as e:
        sys.stderr.write(f"approachsim evaluate: {e}\n")
        return 1
    ev = evaluate_profile(
        profile, runs=runs, seed=seed, mode=mode, out_dir=out, workers=args.workers or os.cpu_count(),
        scheduler=args.scheduler, resume=args.resume, spec=spec,
    )
    summary, det = ev.summary, ev.details
    failed = [r for r in ev.results if not r.ok]
    if not args.no_report:
        from approachsim.report.evaluate import write_report

        write_report(out, ev.results, summary, det)
    print(verdict_table(summary, det))
    if failed:
        print(f"{len(failed)} run(s) failed; first: run {failed[0].run}: {failed[0].error}")
    print(f"wrote {out / 'summary.json'}" + ("" if args.no_report else f", {out / 'report.html'}"))
    if failed and len(failed) == len(ev.results):
        sys.stderr.write(
            f"approachsim evaluate: no run completed ({len(failed)} failed); first: run {failed[0].run}: "
            f"{failed[0].error}\n"
        )
        return 3
    if require is not None:
        v = summary["decision_heights"][require]["verdict"]
        if v != "meets":
            sys.stderr.write(f"approachsim evaluate: --require {require}: verdict is {v}, not meets\n")
            return 1
    return 0
