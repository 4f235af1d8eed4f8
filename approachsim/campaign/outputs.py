"""Campaign outputs that need no plotting: the per-run columns, summary.json, details.json, the verdict table.

summary.json follows design.md's "Output contract" exactly (evaluate/summary.py builds it); details.json
carries the intervals, ICAO columns, integrity counts and availability, FTE / TSE and the time-averaged RMS of
Gray & Maybeck. The verdict table is what `approachsim evaluate` prints.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from approachsim.campaign.result import RunResult
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.lpv import lpv200_summary
from approachsim.evaluate.stats import MIN_GROUPS
from approachsim.evaluate.summary import contract_summary, details, gnss_geometry, verdicts
from approachsim.evaluate.touchdown import touchdown_details, touchdown_summary


def columns(results: list[RunResult]) -> dict[str, np.ndarray]:
    """Per-run scalar columns over the runs that completed (run order)."""
    ok = [r for r in results if r.ok]
    names = sorted({k for r in ok for k in r.scalars})
    return {k: np.array([r.scalars.get(k, np.nan) for r in ok], dtype=float) for k in names}


def evaluate_results(
    results: list[RunResult], cfg: EvaluationConfig, *, profile: str, seed: int, closed_loop: bool,
    land: bool = False, gnss_service: str | None = None,
) -> tuple[dict, dict]:
    """(summary, details) of a finished campaign; land: a landing campaign, whose touchdown statistics go to
    details.json "touchdown" and their headline to summary.json "touchdown" (docs/contract.md); gnss_service: the
    receiver's GNSS service label (summary.json "gnss_service"; None: a code preset) and its "lpv200" verdict."""
    cols = columns(results)
    failed = sum(not r.ok for r in results)
    # open loop: the runs of one flight group share one flown truth (pipeline.open_loop_group)
    groups = None if closed_loop else np.array([r.run // cfg.flight_group for r in results if r.ok])
    res = verdicts(cols, cfg, runs=len(results), failed_runs=failed, groups=groups)
    summary = contract_summary(
        res, profile=profile, runs=len(results), seed=seed, closed_loop=closed_loop, failed_runs=failed,
        gnss_service=gnss_service, lpv200=lpv200_summary(cols, cfg, runs=len(results), failed_runs=failed),
    )
    # imported here: integrity_campaign imports the bank, which imports the navigation stage, and importing this
    # module must not need a stage (campaign/pipeline.py require_stages reports a missing one first)
    from approachsim.campaign.integrity_campaign import campaign_integrity, sum_counts

    det = details(cols, res, cfg, sum_counts(results), integrity_fn=campaign_integrity)
    det["failures"] = {str(r.run): r.error for r in results if not r.ok}
    paths: dict[str, list[int]] = {}
    for r in results:
        if r.path is not None:
            paths.setdefault(r.path, []).append(int(r.run))
    det["paths"] = paths
    geom = gnss_geometry([r.run for r in results if r.ok], cols)
    if geom is not None:
        det["gnss_geometry"] = geom
    if land:
        det["touchdown"] = touchdown_details(cols, runs=len(results), failed_runs=failed, level=cfg.confidence)
        summary["touchdown"] = touchdown_summary(det["touchdown"])
    return summary, det


def _shared_truth_note(det: dict) -> str:
    """The report's line on the open-loop shared-truth correction (stats.effective_runs)."""
    axes = [a for c in det["categories"].values() for a in c["bounds_ft"].values()]
    rho = [a.get("shared_truth_rho") for a in axes]
    if not rho or any(r is None for r in rho):
        return (f"fewer than {MIN_GROUPS} groups, so their correlation cannot be estimated and the bounds assume "
                "independent runs")
    neff = [a["n_eff"] for a in axes if a.get("n_eff") is not None]
    return (f"the bounds use the effective run count of the clustered runs (between-group correlation up to "
            f"{max(rho):.2f}, effective runs down to {min(neff):.0f})")


def touchdown_lines(td: dict) -> list[str]:
    """The printed touchdown block of a landing campaign: the dispersion, then per criterion its limit (with
    its source mark), the exceedances, where the limit lies in standard deviations against where it must lie,
    the normal tail's probability with its upper bound against the required one, and the outcome / verdict."""
    q = td["quantities"]

    def ms(name: str) -> str:
        e = q[name]
        return f"{_f(e.get('mean'), '.1f').strip()} +- {_f(e.get('sd'), '.1f').strip()} {e['unit']}"

    ob = q["outboard_gear_y_ft"]
    far = None if not ob.get("n") else max(abs(ob["min"]), abs(ob["max"]))
    lines = [
        f"touchdown: {td['landings']} landings of {td['runs']} runs ({td['failed_runs']} failed, counted as "
        f"exceedances); main gear {ms('x_ft')} past the threshold, centre {ms('y_ft')} right (outboard gear at most "
        f"{_f(far, '.1f').strip()} ft out), sink {ms('sink_fps')}, bank {ms('bank_deg')}, crab {ms('crab_deg')}",
        f"{'criterion':16} {'limit':>14} {'mark':>4} | {'exceed':>7} | {'z limit':>7} {'z req':>6} | "
        f"{'P normal':>9} {'upper':>9} {'required':>9} | outcome / verdict",
    ]
    for key, c in td["criteria"].items():
        n = c["normal"] or {}
        sign = {"below": "<", "above": ">", "abs_above": "|x|>"}[c["side"]]
        lines.append(
            f"{key:16} {sign + format(c['limit'], '.4g') + ' ' + c['unit']:>14} {c['mark']:>4} | "
            f"{c['exceedances']:>3}/{c['runs']:<3} | {_f(n.get('z_limit'), '7.2f')} {c['z_required']:6.2f} | "
            f"{_f(n.get('probability'), '9.1e')} {_f(n.get('probability_upper'), '9.1e')} "
            f"{c['probability_required']:9.0e} | {c['outcome']} / {c['verdict']}"
        )
    lines.append(
        f"touchdown verdict: {td['verdict']} ({td['criteria_verified']} of {len(td['criteria'])} criteria have a "
        "limit read in the standard: marks V / S / U, docs/touchdown.md; probabilities beyond the runs are a normal "
        "tail's, bounds at the campaign confidence)"
    )
    return lines


def write_json(path: Path, data: Any) -> None:
    """Strict JSON (no NaN), indented, newline-terminated."""
    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def _f(x: float | None, fmt: str = "6.2f") -> str:
    return "   --" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


HEADLINE_COLUMNS = (
    ("category", "category", None),
    ("height_ft", "DH ft", None),
    ("lateral_1sigma_ft", "lateral 1σ ft", ".2f"),
    ("lateral_1sigma_upper_ft", "upper bound", ".2f"),
    ("limit_lateral_1sigma_ft", "limit", ".1f"),
    ("lateral_verdict", "lateral", None),
    ("vertical_1sigma_ft", "vertical 1σ ft", ".2f"),
    ("vertical_1sigma_upper_ft", "upper bound", ".2f"),
    ("limit_vertical_1sigma_ft", "limit", ".1f"),
    ("vertical_verdict", "vertical", None),
    ("failures_verdict", "failed runs", None),
    ("integrity_verdict", "integrity", None),
    ("verdict", "verdict", None),
    ("runs_needed", "runs to decide", None),
)
"""The verdict contract's headline table (report.html's first table, the API's verdict rows): per category the key,
the column heading and the number format (None: as it is). The numbers are summary.json's, formatted as the printed
verdict table formats them (1-sigma and upper bounds to 0.01 ft, limits to 0.1 ft)."""


def headline_rows(summary: dict, det: dict) -> list[dict]:
    """Per category (summary.json order) the verdict contract as plain data: decision height, per axis the FAA
    1-sigma with its one-sided upper bound, the limit and that axis's verdict, the failed-runs criterion's and (when
    in the verdict) integrity's verdicts, the category's verdict and the runs that would likely decide it; the keys
    of HEADLINE_COLUMNS, the numbers summary.json's own."""
    rows = []
    for cat, e in summary["decision_heights"].items():
        c = det["categories"][cat]
        b = c["bounds_ft"]
        rows.append({
            "category": cat,
            "height_ft": e["height_ft"],
            "lateral_1sigma_ft": e["lateral_1sigma_ft"],
            "lateral_1sigma_upper_ft": e["lateral_1sigma_upper_ft"],
            "limit_lateral_1sigma_ft": e["limit_lateral_1sigma_ft"],
            "lateral_verdict": b["lateral"]["verdict"],
            "vertical_1sigma_ft": e["vertical_1sigma_ft"],
            "vertical_1sigma_upper_ft": e["vertical_1sigma_upper_ft"],
            "limit_vertical_1sigma_ft": e["limit_vertical_1sigma_ft"],
            "vertical_verdict": b["vertical"]["verdict"],
            "failures_verdict": c["failures"]["verdict"],
            "integrity_verdict": c.get("integrity_verdict"),
            "verdict": e["verdict"],
            "runs_needed": e["runs_needed"],
        })
    return rows


def verdict_table(summary: dict, det: dict) -> str:
    """The printed verdict: per category the FAA 1-sigma (RMS) with its upper confidence bound and limit, the
    ICAO 95 % beside, the verdict and the runs that would likely decide an indeterminate one."""
    conf = det.get("confidence", 0.95)
    lines = [
        f"{summary['profile']}: {summary['runs']} runs ({summary['failed_runs']} failed), seed {summary['seed']}, "
        f"{'closed' if summary['closed_loop'] else 'open'} loop",
        f"{'category':9} {'DH ft':>6} | {'lat 1s':>7} {'upper':>7} {'limit':>6} | {'vert 1s':>7} {'upper':>7} "
        f"{'limit':>6} | {'lat 95%':>7} {'ICAO':>6} | {'vert 95%':>8} {'ICAO':>6} | verdict",
    ]
    for cat, e in summary["decision_heights"].items():
        lim = det["categories"][cat]["limits_ft"]
        need = f" (~{e['runs_needed']} runs to decide)" if e.get("runs_needed") else ""
        lines.append(
            f"{cat:9} {e['height_ft']:>6} | {_f(e['lateral_1sigma_ft'], '7.2f')} "
            f"{_f(e['lateral_1sigma_upper_ft'], '7.2f')} {lim['lateral_1sigma_ft']:6.1f} | "
            f"{_f(e['vertical_1sigma_ft'], '7.2f')} {_f(e['vertical_1sigma_upper_ft'], '7.2f')} "
            f"{lim['vertical_1sigma_ft']:6.1f} | "
            f"{_f(e['lateral_95_ft'], '7.2f')} {lim['lateral_95_ft']:6.1f} | "
            f"{_f(e['vertical_95_ft'], '8.2f')} {lim['vertical_95_ft']:6.1f} | {e['verdict']}{need}"
        )
    if summary["closed_loop"]:
        for cat, c in det["categories"].items():
            lines.append(
                f"{cat:9} {summary['decision_heights'][cat]['height_ft']:>6} | RMS ft: FTE lat "
                f"{_f(c['fte_lat_ft']['rms'], '.2f')} vert {_f(c['fte_vert_ft']['rms'], '.2f')}, TSE lat "
                f"{_f(c['tse_lat_ft']['rms'], '.2f')} vert {_f(c['tse_vert_ft']['rms'], '.2f')}"
            )
    if summary["failed_runs"]:
        f = next(iter(det["categories"].values())).get("failures", {})
        allowed = f.get("allowed_fraction", 0.0)
        lines.append(
            f"failed runs count against every category: {summary['failed_runs']} of {summary['runs']}"
            + (f", allowed failure fraction {allowed:g} (upper bound {_f(f.get('fraction_upper'), '.3f').strip()})"
               if allowed else " (no failure allowed: every category fails)")
        )
    else:
        c0 = next(iter(det["categories"].values()))
        f = c0.get("failures", {})
        met = [c for c, e in summary["decision_heights"].items() if e["verdict"] == "meets"]
        if met and f.get("fraction_upper") is not None:  # a 0-failure meets: what the runs bound the failures by
            lines.append(
                f"no failed run in {summary['runs']}: {', '.join(met)} meets with a failure probability per approach "
                f"<= {_f(f['fraction_upper'], '.3g').strip()} (one-sided Clopper-Pearson, "
                f"{c0.get('confidence', 0.95):.0%}), not zero"
            )
    if not summary["closed_loop"]:
        lines.append(
            "open loop: runs of one group share one flown truth (evaluation.flight_group); "
            + _shared_truth_note(det)
            + "; closed loop gives every run its own flight"
        )
    for cat, e in det.get("integrity", {}).get("categories", {}).items():
        a, h = e["availability_dh"], e["hmi"]
        fa = e.get("false_alert")
        tt = e.get("time_to_alert")
        lines.append(
            f"integrity {cat}{' (in verdict: ' + e['verdict'] + ')' if e['in_verdict'] else ''}: available at DH "
            f"{a['available']}/{a['runs']} (bounds {_f(a['lower'], '.3f').strip()}-{_f(a['upper'], '.3f').strip()}, "
            f"required {e['requirement']['availability']:g}), MI {e['mi']['count']}, HMI {h['count']} of "
            f"{e['epochs']} epochs (rate upper {_f(h['rate_per_epoch_upper'], '.1e').strip()}, allowed "
            f"{h['rate_per_epoch_allowed']:.1e})"
            + (f", false alerts {fa['alerts']} (upper {_f(fa['rate_per_15s_upper'], '.1e').strip()} / 15 s, "
               f"allocation {fa['allocation_per_15s']:.0e})" if fa else "")
            + (f", TTA <= {tt['tta_required_s']:g} s in {tt['within_tta']}/{tt['exceeded_pl']} runs whose error "
               f"exceeded the PL, {tt['missed_detections']} missed" if tt else "")
        )
    if "touchdown" in det:
        lines.extend(touchdown_lines(det["touchdown"]))
    ta = det.get("time_averaged_rms_ft", {})
    if ta:
        lines.append(
            "time-averaged RMS over the approach, as in Gray & Maybeck's Tables 3-6 (An integrated GPS/INS/Baro and "
            "radar altimeter system for aircraft precision approach landings), ft: "
            + ", ".join(f"{k.replace('_', ' ')} {_f(v, '.2f').strip()}" for k, v in ta.items())
        )
    if summary.get("gnss_service"):
        lines.append(f"GNSS service: {summary['gnss_service']}")
    lp = summary.get("lpv200")
    if lp:
        lines.append(
            f"LPV-200 at {lp['height_ft']} ft: vert 95% {_f(lp['vertical_95_m'], '.2f').strip()} m (upper "
            f"{_f(lp['vertical_95_upper_m'], '.2f').strip()}, limit {lp['limit_vertical_95_m']:g}), hor 95% "
            f"{_f(lp['horizontal_95_m'], '.2f').strip()} m (upper {_f(lp['horizontal_95_upper_m'], '.2f').strip()}, "
            f"limit {lp['limit_horizontal_95_m']:g}), VPL/HPL median {_f(lp['vpl_median_m'], '.1f').strip()}/"
            f"{_f(lp['hpl_median_m'], '.1f').strip()} m (VAL/HAL {lp['val_m']:g}/{lp['hal_m']:g}), available at DH "
            f"{_f(lp['availability_dh'], '.3f').strip()} (lower {_f(lp['availability_dh_lower'], '.3f').strip()}), "
            f"integrity basis {lp['integrity_basis'] or 'none (stand-alone: fault-free WLS levels only)'}, "
            f"HMI approaches {lp.get('hmi_runs')} (MI {lp.get('mi_runs')}): {lp['verdict']}"
        )
    best = summary["best_category"] or "none"
    lines.append(
        f"best category: {best} (verdict on one-sided {conf:.0%} confidence bounds; FAA 1-sigma = RMS over runs, "
        "bias included; all values ft)"
    )
    return "\n".join(lines)
