"""`approachsim reproduce PAPER --out DIR [--seed S] [--runs N]`: rerun a seed paper's own experiment.

The command composes the two stages: the paper module (`approachsim.papers.<name>`) computes and returns
(`compute(*, seed, runs) -> (result, data)`) and its note module writes (`note(result, figures) -> str`,
`headline(result) -> list[str]`: the paper module itself, but for gray-maybeck's papers/gray_maybeck_note.py, which
sits above its paper module), the report module (`approachsim.report.papers_<name>`) draws the figures from
`data`; this command writes
DIR/<paper>.json (the paper's tables and ours side by side), DIR/<paper>.md (the reproduction note) and the
figures, and prints a short summary and the paths. Papers are loaded lazily by name.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from approachsim.config import ProfileError

PAPERS = {
    "hajiyev-saltoglu": ("approachsim.papers.hajiyev_saltoglu", "approachsim.report.papers_hajiyev_saltoglu",
                         "approachsim.papers.hajiyev_saltoglu"),
    "manero-hajiyev": ("approachsim.papers.manero_hajiyev", "approachsim.report.papers_manero_hajiyev",
                       "approachsim.papers.manero_hajiyev"),
    "sokolovic": ("approachsim.papers.sokolovic", "approachsim.report.papers_sokolovic",
                  "approachsim.papers.sokolovic"),
    "chernodarov": ("approachsim.papers.chernodarov", "approachsim.report.papers_chernodarov",
                    "approachsim.papers.chernodarov"),
    "gray-maybeck": ("approachsim.papers.gray_maybeck", "approachsim.report.papers_gray_maybeck",
                     "approachsim.papers.gray_maybeck_note"),
}
"""Paper name -> (module that computes, module that draws, module that writes the note and headline)."""

DEFAULT_RUNS = 100
"""Runs when --runs is not given and the paper module has no DEFAULT_RUNS of its own."""


def _figure_writer(name: str) -> Callable[[Any, Path], list[str]]:
    """The report module's figure function for paper `name`, as f(data, out_dir) -> file names."""
    rep = importlib.import_module(PAPERS[name][1])
    if name == "hajiyev-saltoglu":
        return lambda d, out: [f.name for f in rep.plot_all(out, *d)]
    if name == "manero-hajiyev":
        return lambda d, out: [f.name for f in rep.plot_all(out, *d)]
    if name == "chernodarov":
        return lambda d, out: rep.write_figures(*d, out)
    return lambda d, out: rep.write_figures(d, out)


def reproduce(name: str, out_dir: Path, *, seed: int, runs: int, cases: list[str] | None = None,
              closed: bool = False, sensitivity_runs: int | None = None, trajectory: str = "final") -> dict:
    """Compute paper `name`'s reproduction, draw its figures, write DIR/<name>.json and DIR/<name>.md; return
    the JSON content (with the figure names under "figures"). A paper whose compute() takes out_dir (its
    campaigns' run stores) and cases (a subset of its cases) gets them; closed and sensitivity_runs go to a
    paper that has them (gray-maybeck: our closed-loop study instead of the faithful variant, and the
    sensitivity table's runs), trajectory too (gray-maybeck: "profgen", the PROFGEN-like lead-in variant)."""
    paper = importlib.import_module(PAPERS[name][0])
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    params = inspect.signature(paper.compute).parameters
    extra: dict[str, Any] = {}
    if "out_dir" in params:
        extra["out_dir"] = out_dir
    if "evaluate" in params:  # a paper that flies campaigns: the command hands it the campaign stage
        from approachsim.campaign.evaluation import evaluate_profile
        from approachsim.campaign.outputs import columns

        extra.update(evaluate=evaluate_profile, columns=columns)
    if cases:
        if "cases" not in params:
            raise ProfileError(f"--cases: {name} has no cases to choose from (gray-maybeck has)")
        extra["cases"] = cases
    for key, val, flag in (("closed", closed, "--closed"), ("sensitivity_runs", sensitivity_runs, "--sensitivity"),
                           ("trajectory", trajectory if trajectory != "final" else None, "--trajectory")):
        if val:
            if key not in params:
                raise ProfileError(f"{flag}: {name} has no such option (gray-maybeck has)")
            extra[key] = val
    result, data = paper.compute(seed=seed, runs=runs, **extra)
    figures = _figure_writer(name)(data, out_dir)
    result["figures"] = figures
    (out_dir / f"{name}.json").write_text(json.dumps(result, indent=2))
    (out_dir / f"{name}.md").write_text(importlib.import_module(PAPERS[name][2]).note(result, figures))
    return result


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `reproduce` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "reproduce", help="reproduce a source paper's experiment and tables",
        description="Runs one source paper's own experiment (its models and numbers) and writes DIR/PAPER.md (the "
                    "note: our tables beside the paper's, every finding chosen from the computed numbers), "
                    "DIR/PAPER.json and the figures; prints the headline findings. Papers: hajiyev-saltoglu "
                    "(Hajiyev & Saltoglu), manero-hajiyev (Manero Contreras & Hajiyev), sokolovic (Sokolovic, "
                    "Dikic & Stancic), chernodarov (Chernodarov), gray-maybeck (Gray & Maybeck, An integrated "
                    "GPS/INS/Baro and radar altimeter system for aircraft precision approach landings: the 16 cases "
                    "of its Table 2, 15 runs each by default; by default the faithful variant, open loop on a "
                    "flown truth with the paper's own GPS budget, tuning and initial errors; --closed: our "
                    "closed-loop study; --sensitivity N: the sensitivity table of the gap fills at N runs).",
        examples=["approachsim reproduce sokolovic --out out/sokolovic",
                  "approachsim reproduce hajiyev-saltoglu --out out/hs --runs 200 --seed 3",
                  "approachsim reproduce gray-maybeck --out out/gm --cases II,X --runs 5",
                  "approachsim reproduce gray-maybeck --out out/gm-closed --closed",
                  "approachsim reproduce gray-maybeck --out out/gm --runs 1000 --sensitivity 200"],
    )
    p.add_argument("paper", help=f"one of: {', '.join(PAPERS)}")
    p.add_argument("--out", required=True, type=Path, help="output directory")
    p.add_argument("--seed", type=int, default=1, help="campaign seed (default 1)")
    p.add_argument("--runs", type=int, default=None,
                   help=f"Monte Carlo runs (default: the paper's, gray-maybeck 15 per case; else {DEFAULT_RUNS})")
    p.add_argument("--cases", default=None,
                   help="gray-maybeck only: comma-separated subset of Table 2's cases, e.g. II,X (default all 16)")
    p.add_argument("--closed", action="store_true",
                   help="gray-maybeck only: our closed-loop study (the regress baselines' cases) instead of the "
                        "faithful variant")
    p.add_argument("--trajectory", choices=("final", "profgen"), default="final",
                   help="gray-maybeck only: final (the straight 10 nmi final, default) or profgen (the PROFGEN-like "
                        "lead-in with turns and level segments, the filter from its start, the swept tuning)")
    p.add_argument("--sensitivity", type=int, default=None, metavar="N",
                   help="gray-maybeck only: also the sensitivity table of the faithful variant's gap fills, N runs "
                        "per row and case (paired: the same seed and runs)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run one reproduction; print its headline findings and where the files went."""
    if args.paper not in PAPERS:
        raise ProfileError(f"paper: must be one of {', '.join(PAPERS)}; got {args.paper!r}")
    paper = importlib.import_module(PAPERS[args.paper][0])
    runs = args.runs if args.runs is not None else getattr(paper, "DEFAULT_RUNS", DEFAULT_RUNS)
    if runs < 1:
        raise ProfileError(f"--runs: must be >= 1, got {runs}")
    if args.seed < 0:
        raise ProfileError(f"--seed: must be >= 0, got {args.seed}")
    cases = [c for c in args.cases.split(",") if c.strip()] if args.cases else None
    if args.sensitivity is not None and args.sensitivity < 2:
        raise ProfileError(f"--sensitivity: must be >= 2 runs, got {args.sensitivity}")
    result = reproduce(args.paper, args.out, seed=args.seed, runs=runs, cases=cases, closed=args.closed,
                       sensitivity_runs=args.sensitivity, trajectory=args.trajectory)
    print(f"{args.paper}: {runs} runs, seed {args.seed}")
    for line in importlib.import_module(PAPERS[args.paper][2]).headline(result):
        print(f"  {line}")
    print(f"wrote {args.out / (args.paper + '.md')} (the note), {args.out / (args.paper + '.json')} (all numbers) "
          f"and {len(result['figures'])} figure(s) in {args.out}")
    return 0
