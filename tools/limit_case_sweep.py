"""The limit-case sweep of docs/integrity.md "Limit case" (issue 41 item 6): over undetected faults (GPS ramp slope x
onset x satellite, GPS step, baro step, radar-altimeter bias, pseudolite step), the largest |error| / PL of the
output per category and mode, which must stay below 1 (campaign/limit_case.py).

    PYTHONPATH=. python tools/limit_case_sweep.py PROFILE [--modes M,...] [--per-decade N] [--truths T]
        [--fault-free-runs F] [--seed S] --out sweep.json
    PYTHONPATH=. python tools/limit_case_sweep.py --table A.json [B.json ...]     # the docs table from stored sweeps

Runs on one process (no pool): a grid point is one bank run, ~0.1-0.4 s of CPU.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def table(paths: list[str]) -> str:
    """The markdown table: per profile, mode and category the largest ratio, its axis and the fault named."""
    lines = ["| profile | mode | points | category | max \\|e\\| / PL (axis) | worst fault | < 1 | fault-free max |",
             "|---|---|---|---|---|---|---|---|"]
    for p in paths:
        s = json.loads(Path(p).read_text())
        for name, m in s["modes"].items():
            for cat, c in m["categories"].items():
                w = c["worst_fault"]
                who = "PRN" if name.startswith("sat-") else "unit"
                ch = "" if w["channel"] in (None, -1) else f", {who} {w['channel']:.0f}"
                fault = (f"{w['magnitude']:.3g} {w['unit']} {m['kind']}, onset {w['onset']}{ch}"
                         f"{' (detected later)' if w['detected_later'] else ' (never detected)'}")
                lines.append(f"| {s['profile']} | {name} | {m['points']} | {cat} | {c['max_ratio']:.2f} "
                             f"({c['axis']}) | {fault} | {'yes' if c['max_ratio'] < 1 else 'no'} | "
                             f"{s['fault_free'][cat]['max_ratio']:.2f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("profile", nargs="?", type=Path)
    ap.add_argument("--modes", default=None)
    ap.add_argument("--per-decade", type=int, default=3)
    ap.add_argument("--truths", type=int, default=4)
    ap.add_argument("--fault-free-runs", type=int, default=8)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--table", nargs="+", default=None)
    a = ap.parse_args(argv)
    if a.table:
        print(table(a.table))
        return 0
    if a.profile is None or a.out is None:
        ap.error("PROFILE and --out are needed (or --table)")
    from threadpoolctl import threadpool_limits

    from approachsim.campaign.limit_case import sweep
    from approachsim.profile import load_profile

    prof = load_profile(a.profile)
    with threadpool_limits(limits=1):
        res = sweep(prof, None if a.modes is None else a.modes.split(","), per_decade=a.per_decade, seed=a.seed,
                    truths=a.truths, fault_free_runs=a.fault_free_runs,
                    log=lambda s: print(s, file=sys.stderr, flush=True))
    a.out.write_text(json.dumps(res, indent=1, default=float))
    print(table([str(a.out)]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
