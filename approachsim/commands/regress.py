"""`approachsim regress [--baselines DIR] [--update] [--workers K] [--out DIR]`: profile regressions.

Runs every committed baseline (DIR/*.json, default baselines/: a profile, a small run count, a fixed seed
and mode, the summary and the per-run errors at each decision height) with the same seeds and judges the
paired per-run changes (campaign/regress.py: common random numbers, the test, its false-alarm rate and
power). Prints a readable diff; exits 1 on a regression. --update reruns them and rewrites
the baselines; `--update --add PROFILE` creates a baseline for a new profile (--runs, --seed, --mode).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from approachsim.config import ProfileError

DEFAULT_DIR = Path("baselines")


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `regress` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "regress", help="rerun the committed profile baselines and compare with tolerances",
        description="Reruns every committed baseline (small campaigns with fixed seeds) and compares the results\n"
        "with the stored ones within statistical tolerances; --update rewrites them.",
        examples=["approachsim regress", "approachsim regress --update --add profiles/hot-high-crosswind.toml"],
    )
    p.add_argument("--baselines", type=Path, default=DEFAULT_DIR, help="baseline directory (default baselines/)")
    p.add_argument("--update", action="store_true", help="rewrite the baselines from new runs")
    p.add_argument("--add", type=Path, default=None, help="with --update: create a baseline for this profile")
    p.add_argument("--runs", type=int, default=20,
                   help="runs of a new baseline (--add; default 20: the paired test's power, campaign/regress.py)")
    p.add_argument("--seed", type=int, default=7, help="seed of a new baseline (--add; default 7)")
    p.add_argument("--mode", choices=("closed", "open"), default="open", help="mode of a new baseline (--add)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--out", type=Path, default=None, help="keep the campaign outputs here (default: temporary)")
    p.set_defaults(func=run)


def _check(args: argparse.Namespace) -> list[Path]:
    from approachsim.commands.evaluate import MAX_WORKERS

    if args.workers is not None and not 1 <= args.workers <= MAX_WORKERS:
        raise ProfileError(f"--workers: must be in [1, {MAX_WORKERS}], got {args.workers}")
    if not 1 <= args.runs <= 10000:
        raise ProfileError(f"--runs: must be in [1, 10000], got {args.runs}")
    if args.seed < 0:
        raise ProfileError(f"--seed: must be >= 0, got {args.seed}")
    if args.add is not None:
        if not args.update:
            raise ProfileError("--add: only with --update (it writes a new baseline)")
        if not args.add.is_file():
            raise ProfileError(f"--add: no such profile {str(args.add)!r}")
    if args.out is not None and args.out.exists() and not args.out.is_dir():
        raise ProfileError(f"--out: {str(args.out)!r} exists and is not a directory")
    if not args.baselines.is_dir():
        if args.add is not None:
            return []
        raise ProfileError(f"--baselines: no such directory {str(args.baselines)!r}")
    files = sorted(args.baselines.glob("*.json"))
    if not files and args.add is None:
        raise ProfileError(f"--baselines: no baseline files (*.json) in {str(args.baselines)!r}")
    return files


def run(args: argparse.Namespace) -> int:
    """Run the baselines; compare or update."""
    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.campaign.outputs import write_json
    from approachsim.campaign.pipeline import PipelineUnavailable, require_stages
    from approachsim.campaign.regress import (
        SCHEMA,
        baseline_doc,
        compare,
        compare_paired,
        per_run_errors,
        read_baseline,
    )
    from approachsim.profile import load_profile

    files = _check(args)
    jobs = []
    for f in files:
        try:
            doc = read_baseline(f)
        except ValueError as e:
            raise ProfileError(f"--baselines: {e}") from None
        jobs.append((f, doc["profile"], doc["runs"], doc["seed"], doc["mode"], doc))
    if args.add is not None:
        target = args.baselines / f"{load_profile(args.add).name}.json"
        try:
            rel = str(args.add.resolve().relative_to(args.baselines.resolve().parent))
        except ValueError:
            rel = str(args.add.resolve())
        jobs.append((target, rel, args.runs, args.seed, args.mode, None))
    # profile paths are relative to the directory holding the baselines directory (the repository root)
    base_root = args.baselines.resolve().parent
    profiles = [(job, load_profile(base_root / job[1])) for job in jobs]  # all validated before running
    try:
        require_stages()
    except PipelineUnavailable as e:
        sys.stderr.write(f"approachsim regress: {e}\n")
        return 1
    failed = 0
    with tempfile.TemporaryDirectory(prefix="approachsim-regress-") as tmp:
        root = args.out or Path(tmp)
        for (path, prof_path, runs, seed, mode, doc), profile in profiles:
            ev = evaluate_profile(profile, runs=runs, seed=seed, mode=mode, out_dir=root / path.stem,
                                  workers=args.workers, progress=False)
            per_run = per_run_errors(ev.results)
            if args.update:
                args.baselines.mkdir(parents=True, exist_ok=True)
                write_json(path, baseline_doc(prof_path, ev.summary, runs=runs, seed=seed, mode=mode, per_run=per_run))
                print(f"updated {path} (best category {ev.summary['best_category'] or 'none'})")
                continue
            if doc["schema"] == SCHEMA:
                diffs = compare_paired(doc, ev.summary, per_run)
            else:
                print(f"{path.stem}: old baseline without per-run errors: summary-only F-band test (regenerate it "
                      "with --update)")
                diffs = compare(doc["summary"], ev.summary)
            bad = [d for d in diffs if d.regression]
            failed += bool(bad)
            changed = [d for d in diffs if d.old != d.new]
            state = "REGRESSION" if bad else ("ok, changed within tolerance" if changed else "ok, identical")
            print(f"{path.stem}: {state} ({runs} runs, seed {seed}, {mode} loop)")
            for d in diffs if bad else changed:
                print("  " + d.line())
    return 1 if failed else 0
