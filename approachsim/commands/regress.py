"""`approachsim regress [--baselines DIR] [--update] [--workers K] [--out DIR]`: profile regressions.

Runs every committed baseline (DIR/*.json, default baselines/: a profile, a small run count, a fixed seed
and mode, the summary and the per-run errors at each decision height) with the same seeds and judges the
paired per-run changes (campaign/regress.py: common random numbers, the test, its false-alarm rate and
power). Prints a readable diff; exits 1 on a regression. --update reruns them and rewrites
the baselines; `--update --add PROFILE` creates a baseline for a new profile (--runs, --seed, --mode).

`--update --add-paper gray-maybeck` creates the small-N version of Gray & Maybeck's study: one baseline per case of
its Table 2 (baselines/gray-maybeck-<case>.json, profile reference `paper:gray-maybeck:<case>`, closed loop, 10 runs
unless --runs), so that the regression run guards the study's verdict pattern (Tables 7-8: a changed verdict or
best category of any case is a regression) and each case's per-run errors; the pattern is printed beside the
paper's after the comparison.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path
from typing import Any

from approachsim.config import ProfileError

DEFAULT_DIR = Path("baselines")
PAPER_REF = "paper:gray-maybeck:"
"""Profile reference of a Gray & Maybeck case baseline: the prefix, then the case's roman numeral."""
PAPER_RUNS = 10
"""Runs per case of the study's baselines (--add-paper without --runs): 16 closed-loop campaigns, about 1 min on
2 cores, the verdict pattern at small N (the paired test's power per case is lower than the profiles' 20-run
baselines: campaign/regress.py)."""


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
    p.add_argument("--add-paper", choices=("gray-maybeck",), default=None,
                   help="with --update: create the small-N study baselines (one per case of Gray & Maybeck's Table 2, "
                   f"closed loop, {PAPER_RUNS} runs each unless --runs)")
    p.add_argument("--runs", type=int, default=None,
                   help="runs of a new baseline (--add; default 20: the paired test's power, campaign/regress.py; "
                   f"--add-paper: {PAPER_RUNS})")
    p.add_argument("--seed", type=int, default=7, help="seed of a new baseline (--add; default 7)")
    p.add_argument("--mode", choices=("closed", "open"), default=None,
                   help="mode of a new baseline (--add; default open; --add-paper: closed, as the study)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--out", type=Path, default=None, help="keep the campaign outputs here (default: temporary)")
    p.set_defaults(func=run)


def _check(args: argparse.Namespace) -> list[Path]:
    from approachsim.api import MAX_WORKERS

    if args.workers is not None and not 1 <= args.workers <= MAX_WORKERS:
        raise ProfileError(f"--workers: must be in [1, {MAX_WORKERS}], got {args.workers}")
    if args.runs is not None and not 1 <= args.runs <= 10000:
        raise ProfileError(f"--runs: must be in [1, 10000], got {args.runs}")
    if args.seed < 0:
        raise ProfileError(f"--seed: must be >= 0, got {args.seed}")
    if args.add is not None:
        if not args.update:
            raise ProfileError("--add: only with --update (it writes a new baseline)")
        if not args.add.is_file():
            raise ProfileError(f"--add: no such profile {str(args.add)!r}")
    if args.add_paper is not None:
        if not args.update:
            raise ProfileError("--add-paper: only with --update (it writes new baselines)")
        if args.mode == "open":
            raise ProfileError("--add-paper: the study is flown closed loop (drop --mode open)")
    if args.out is not None and args.out.exists() and not args.out.is_dir():
        raise ProfileError(f"--out: {str(args.out)!r} exists and is not a directory")
    adding = args.add is not None or args.add_paper is not None
    if not args.baselines.is_dir():
        if adding:
            return []
        raise ProfileError(f"--baselines: no such directory {str(args.baselines)!r}")
    files = sorted(args.baselines.glob("*.json"))
    if not files and not adding:
        raise ProfileError(f"--baselines: no baseline files (*.json) in {str(args.baselines)!r}")
    return files


def run(args: argparse.Namespace) -> int:
    """Run the baselines; compare or update."""
    from approachsim.campaign.evaluation import evaluate_profile
    from approachsim.campaign.outputs import write_json
    from approachsim.campaign.pipeline import PipelineUnavailable, require_stages
    from approachsim.campaign.regress import (
        CPU_FLOOR_REL,
        SCHEMA,
        baseline_doc,
        compare,
        compare_paired,
        per_run_errors,
        read_baseline,
        within_cpu_floor,
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
        jobs.append((target, rel, args.runs or 20, args.seed, args.mode or "open", None))
    if args.add_paper is not None:
        from approachsim.papers.gray_maybeck import CASES

        for case in CASES:
            jobs.append((args.baselines / f"gray-maybeck-{case.roman}.json", PAPER_REF + case.roman,
                         args.runs or PAPER_RUNS, args.seed, "closed", None))
    jobs = list({job[0].resolve(): job for job in jobs}.values())  # a new baseline replaces the file it rewrites
    # profile paths are relative to the directory holding the baselines directory (the repository root)
    base_root = args.baselines.resolve().parent
    profiles = [(job, baseline_profile(job[1], base_root)) for job in jobs]  # all validated before running
    try:
        require_stages()
    except PipelineUnavailable as e:
        sys.stderr.write(f"approachsim regress: {e}\n")
        return 1
    failed = 0
    pattern: dict[str, str | None] = {}
    with tempfile.TemporaryDirectory(prefix="approachsim-regress-") as tmp:
        root = args.out or Path(tmp)
        for (path, prof_path, runs, seed, mode, doc), profile in profiles:
            ev = evaluate_profile(profile, runs=runs, seed=seed, mode=mode, out_dir=root / path.stem,
                                  workers=args.workers, progress=False)
            per_run = per_run_errors(ev.results)
            if prof_path.startswith(PAPER_REF):
                pattern[prof_path[len(PAPER_REF):]] = ev.summary["best_category"]
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
            if bad:
                state = "REGRESSION"
            elif not changed:
                state = "ok, identical"
            elif doc["schema"] == SCHEMA and within_cpu_floor(doc, per_run):
                state = f"ok, equal within the cross-machine floor (every run within {CPU_FLOOR_REL:g} of its 1-sigma)"
            else:
                state = "ok, changed within tolerance"
            print(f"{path.stem}: {state} ({runs} runs, seed {seed}, {mode} loop)")
            for d in diffs if bad else changed:
                print("  " + d.line())
    if pattern:
        print(study_pattern(pattern))
    return 1 if failed else 0


def baseline_profile(ref: str, base_root: Path) -> Any:
    """The Profile a baseline's `profile` names: a path relative to base_root (the repository root), or
    `paper:gray-maybeck:<case>`, that case of Gray & Maybeck's Table 2 (papers/gray_maybeck.case_profile);
    ProfileError naming the baseline's field otherwise."""
    from approachsim.profile import load_profile

    if ref.startswith("paper:"):
        if not ref.startswith(PAPER_REF):
            raise ProfileError(f"--baselines: profile {ref!r}: the only paper reference is {PAPER_REF}<case>")
        from approachsim.papers.gray_maybeck import case_profile, select_cases

        (case,) = select_cases([ref[len(PAPER_REF):]])
        return case_profile(case)
    return load_profile(base_root / ref)


def study_pattern(best: dict[str, str | None]) -> str:
    """One line per case of Gray & Maybeck's study rerun: our best category at the baselines' run count beside
    Tables 7-8's."""
    from approachsim.papers.gray_maybeck import CASES, PAPER_BEST

    lines = ["Gray & Maybeck study (small-N baselines): best category, ours / the paper's Tables 7-8"]
    for case in CASES:
        if case.roman in best:
            ours, paper = best[case.roman] or "none", PAPER_BEST[case.number] or "none"
            lines.append(f"  case {case.roman:>4}: {ours:8s} / {paper}")
    return "\n".join(lines)
