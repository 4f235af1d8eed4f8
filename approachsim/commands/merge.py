"""`approachsim merge PROFILE SHARD_DIR... --out DIR [--no-report] [--require CAT]`: the N shards of one campaign
(`approachsim evaluate PROFILE --runs R --shard K/N --out SHARD_DIR`, e.g. a SLURM job array) merged into the single
campaign's outputs, bit for bit (campaign/shards.py): DIR/summary.json, details.json, runs.parquet, heights.parquet,
series/, runs.jsonl + campaign.json (a campaign `evaluate --resume` continues), the figures and report.html; prints
the verdict table. Exit statuses as `evaluate`'s (docs/contract.md); a shard missing, unfinished or of another
campaign is bad input (2), one line naming its directory.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `merge` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "merge", help="merge the shards of a campaign (evaluate --shard K/N) into its single outputs",
        description="Merges the N shard directories of one campaign (written by `approachsim evaluate PROFILE\n"
        "--shard K/N --out SHARD_DIR`, e.g. the tasks of a SLURM job array) into DIR: the outputs the single\n"
        "campaign writes, bit for bit (details.json's wall_s is the shards' sum), and prints the verdict table.\n"
        "Recipes: docs/scale-out.md.",
        examples=["approachsim merge profiles/default.toml out/shard-1 out/shard-2 out/shard-3 --out out/full",
                  "approachsim merge profiles/default.toml out/shard-* --out out/full --require \"CAT II\""],
    )
    p.add_argument("profile", type=Path, help="the approach profile the shards ran (TOML)")
    p.add_argument("shards", type=Path, nargs="+", metavar="SHARD_DIR", help="the directory of every shard")
    p.add_argument("--out", required=True, type=Path, help="output directory of the merged campaign")
    p.add_argument("--no-report", action="store_true", help="skip figures and report.html")
    p.add_argument("--require", default=None, metavar="CAT",
                   help='exit 1 unless this category\'s verdict is meets ("CAT I", "CAT II" or "CAT III")')
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Merge, write, print the verdict table."""
    from approachsim import api
    from approachsim.commands.evaluate import parse_require, report_campaign

    spec = api.ProfileSpec.from_file(args.profile)
    require = parse_require(args.require)
    res = api.merge(spec, args.shards, args.out, report=not args.no_report)
    return report_campaign(res, args.out, report=not args.no_report, require=require, command="merge")
