"""Campaign outputs that need no plotting: the per-run columns, summary.json, details.json, the verdict table.

summary.json follows design.md's "Output contract" exactly (evaluate/summary.py builds it); details.json
carries the intervals, ICAO columns, integrity counts and availability, FTE / TSE and seed 002's
time-averaged RMS. The verdict table is what `approachsim evaluate` prints.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from approachsim.campaign.result import RunResult
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.summary import contract_summary, details, verdicts


def columns(results: list[RunResult]) -> dict[str, np.ndarray]:
    """Per-run scalar columns over the runs that completed (run order)."""
    ok = [r for r in results if r.ok]
    names = sorted({k for r in ok for k in r.scalars})
    return {k: np.array([r.scalars.get(k, np.nan) for r in ok], dtype=float) for k in names}


def evaluate_results(
    results: list[RunResult], cfg: EvaluationConfig, *, profile: str, seed: int, closed_loop: bool
) -> tuple[dict, dict]:
    """(summary, details) of a finished campaign."""
    cols = columns(results)
    res = verdicts(cols, cfg)
    failed = sum(not r.ok for r in results)
    summary = contract_summary(
        res, profile=profile, runs=len(results), seed=seed, closed_loop=closed_loop, failed_runs=failed
    )
    det = details(cols, res, cfg)
    det["failures"] = {str(r.run): r.error for r in results if not r.ok}
    return summary, det


def write_json(path: Path, data: Any) -> None:
    """Strict JSON (no NaN), indented, newline-terminated."""
    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def _f(x: float | None, fmt: str = "6.2f") -> str:
    return "   --" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def verdict_table(summary: dict, det: dict) -> str:
    """The printed verdict: one line per category, FAA 1-sigma with limits, ICAO 95 % beside, and the verdict."""
    lines = [
        f"{summary['profile']}: {summary['runs']} runs ({summary['failed_runs']} failed), seed {summary['seed']}, "
        f"{'closed' if summary['closed_loop'] else 'open'} loop",
        f"{'category':9} {'DH ft':>6} | {'lat 1s':>7} {'limit':>6} | {'vert 1s':>7} {'limit':>6} | "
        f"{'lat 95%':>7} {'ICAO':>6} | {'vert 95%':>8} {'ICAO':>6} | meets",
    ]
    for cat, e in summary["decision_heights"].items():
        lim = det["categories"][cat]["limits_ft"]
        lines.append(
            f"{cat:9} {e['height_ft']:>6} | {_f(e['lateral_1sigma_ft'], '7.2f')} {lim['lateral_1sigma_ft']:6.1f} | "
            f"{_f(e['vertical_1sigma_ft'], '7.2f')} {lim['vertical_1sigma_ft']:6.1f} | "
            f"{_f(e['lateral_95_ft'], '7.2f')} {lim['lateral_95_ft']:6.1f} | "
            f"{_f(e['vertical_95_ft'], '8.2f')} {lim['vertical_95_ft']:6.1f} | {'YES' if e['meets'] else 'no'}"
        )
    if summary["closed_loop"]:
        for cat, c in det["categories"].items():
            lines.append(
                f"{cat:9} {summary['decision_heights'][cat]['height_ft']:>6} | RMS ft: FTE lat "
                f"{_f(c['fte_lat_ft']['rms'], '.2f')} vert {_f(c['fte_vert_ft']['rms'], '.2f')}, TSE lat "
                f"{_f(c['tse_lat_ft']['rms'], '.2f')} vert {_f(c['tse_vert_ft']['rms'], '.2f')}"
            )
    for cat, e in summary["decision_heights"].items():
        c = det["categories"][cat]
        if not e["meets"]:
            continue
        lim = c["limits_ft"]
        hi = (
            (c["lateral_ft"]["rms_hi"], lim["lateral_1sigma_ft"]),
            (c["vertical_ft"]["rms_hi"], lim["vertical_1sigma_ft"]),
        )
        if any(h is None or h > limit for h, limit in hi):
            lines.append(
                f"note: {cat} is met on the RMS of {c['lateral_ft']['n']} runs, but its 95 % upper bound (lat "
                f"{_f(hi[0][0], '.2f')}, vert {_f(hi[1][0], '.2f')} ft) exceeds a limit: run more to confirm"
            )
    ta = det.get("time_averaged_rms_ft", {})
    if ta:
        lines.append(
            "time-averaged RMS over the approach (seed 002 Tables 3-6), ft: "
            + ", ".join(f"{k.replace('_', ' ')} {_f(v, '.2f').strip()}" for k, v in ta.items())
        )
    best = summary["best_category"] or "none"
    lines.append(f"best category: {best} (FAA 1-sigma = RMS over runs, bias included; all values ft)")
    return "\n".join(lines)
