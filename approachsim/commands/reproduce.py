"""`approachsim reproduce PAPER --out DIR [--seed S] [--runs N]`: rerun a seed paper's own experiment.

Each paper module provides `reproduce(out_dir: Path, *, seed: int, runs: int) -> dict`, which writes
DIR/<paper>.json (the paper's table and ours side by side), its figures and a markdown note, and returns
the JSON content. Papers are loaded lazily by name.
"""

from __future__ import annotations

import argparse
import importlib
import json
from pathlib import Path

from approachsim.config import ProfileError

PAPERS = {
    "hajiyev-saltoglu": "approachsim.papers.hajiyev_saltoglu",
    "manero-hajiyev": "approachsim.papers.manero_hajiyev",
    "sokolovic": "approachsim.papers.sokolovic",
    "chernodarov": "approachsim.papers.chernodarov",
}
"""Paper name -> module with reproduce(out_dir, *, seed, runs)."""

DEFAULT_RUNS = 100


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `reproduce` sub-command."""
    p = sub.add_parser("reproduce", help="reproduce a seed paper's experiment and tables")
    p.add_argument("paper", help=f"one of: {', '.join(PAPERS)}")
    p.add_argument("--out", required=True, type=Path, help="output directory")
    p.add_argument("--seed", type=int, default=1, help="campaign seed (default 1)")
    p.add_argument("--runs", type=int, default=DEFAULT_RUNS, help=f"Monte Carlo runs (default {DEFAULT_RUNS})")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run one reproduction and print where its results went."""
    if args.paper not in PAPERS:
        raise ProfileError(f"paper: must be one of {', '.join(PAPERS)}; got {args.paper!r}")
    if args.runs < 1:
        raise ProfileError(f"--runs: must be >= 1, got {args.runs}")
    if args.seed < 0:
        raise ProfileError(f"--seed: must be >= 0, got {args.seed}")
    module = importlib.import_module(PAPERS[args.paper])
    args.out.mkdir(parents=True, exist_ok=True)
    result = module.reproduce(args.out, seed=args.seed, runs=args.runs)
    print(json.dumps(result.get("verdict", {}), indent=2))
    print(f"wrote {args.out / (args.paper + '.json')}")
    return 0
