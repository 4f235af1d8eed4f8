"""Campaign summary: the contract's summary.json (design.md "Output contract") and the detailed statistics.

Input is the per-run scalar table (column -> array over the runs that completed, as score.py names them).
summary.json holds exactly the contract's keys; everything else (intervals, ICAO columns, integrity,
time-averaged RMS, FTE / TSE) goes to the details dictionary.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict

import numpy as np
from scipy import stats as sps

from approachsim import units
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.integrity import REGIONS
from approachsim.evaluate.limits import CATEGORIES
from approachsim.evaluate.score import CATEGORY_KEYS
from approachsim.evaluate.stats import error_stats
from approachsim.evaluate.timeavg import STATES, campaign_rms_ft
from approachsim.evaluate.verdict import (
    CategoryResult,
    IntegrityVerdict,
    best_category,
    category_verdict,
    integrity_verdict,
)
from approachsim.integrity.requirements import REQUIREMENTS

SCHEMA = "approachsim.summary/1"


def _num(x: float) -> float | int | None:
    """JSON-safe number: None for nan/inf, int for integral heights."""
    if x is None or not math.isfinite(x):
        return None
    return int(x) if float(x).is_integer() and abs(x) < 1e15 else float(x)


def _col(columns: Mapping[str, np.ndarray], name: str) -> np.ndarray:
    return np.asarray(columns.get(name, np.empty(0)), dtype=float)


def verdicts(
    columns: Mapping[str, np.ndarray], cfg: EvaluationConfig, *, runs: int | None = None, failed_runs: int = 0,
    groups: np.ndarray | None = None,
) -> list[CategoryResult]:
    """Score every category from the per-run table of the completed runs (errors converted to ft here).

    runs / failed_runs: the campaign's run count and its failed runs, which count against every category.
    groups: the shared-truth (flight) group of each completed run in open loop; None: independent runs.
    Integrity joins the verdict of the categories in cfg.integrity when the runs carry the bank's columns (no
    GPS receiver: no fault modes to separate, no bank, and the verdict is the accuracy one alone).
    """
    bank = any(f"{k}_int_epochs" in columns for k in CATEGORY_KEYS.values())
    out = []
    for cat in CATEGORIES:
        key = CATEGORY_KEYS[cat]
        lat = _col(columns, f"{key}_lateral_m") / units.FT
        ver = _col(columns, f"{key}_vertical_m") / units.FT
        out.append(category_verdict(
            cat, cfg.dh_ft[cat], lat, ver, cfg.verdict, runs=runs, failed_runs=failed_runs,
            max_failure_fraction=cfg.max_failure_fraction, confidence=cfg.confidence, groups=groups,
            integrity=integrity_criterion(columns, cat, cfg) if cat in cfg.integrity and bank else None,
        ))
    return out


def integrity_criterion(columns: Mapping[str, np.ndarray], category: str, cfg: EvaluationConfig) -> IntegrityVerdict:
    """The integrity criterion of `category` from the bank's per-run columns (campaign.integrity_campaign), counted
    per approach: a run with any HMI epoch is one approach with HMI (evaluate/verdict.py)."""
    key = CATEGORY_KEYS[category]
    req = REQUIREMENTS[category]
    dh = _col(columns, f"{key}_int_avail_dh")
    ok = np.isfinite(dh)
    hmi = _col(columns, f"{key}_int_hmi")
    hmi_runs = int(np.sum(hmi[ok] > 0)) if hmi.size == dh.size else int(np.sum(hmi > 0))
    window = None
    if req.hmi_window_s() is not None:  # CAT II / III: the event is HMI in the window before the DH
        hw = _col(columns, f"{key}_int_hmi_window")
        # runs stored before the window existed carry no evidence of a windowed event: never `exceeds` from them
        window = int(np.sum(hw[ok] > 0)) if hw.size == dh.size else int(np.sum(hw > 0))
    return integrity_verdict(
        int(dh[ok].sum()), int(ok.sum()), hmi_runs, req.availability, req.hmi_probability_allowed, cfg.confidence,
        hmi_window_approaches=window,
    )


def integrity_summary(v: IntegrityVerdict) -> dict:
    """summary.json `decision_heights.<CAT>.integrity` (docs/contract.md): the criterion counted per approach."""
    return {
        "verdict": v.verdict,
        "hmi": v.hmi_finding,
        "approaches": v.approaches,
        "hmi_approaches": v.hmi_approaches,
        "hmi_window_approaches": v.hmi_window_approaches,
        "hmi_probability_upper": _num(v.hmi_probability_upper),
        "hmi_window_probability_lower": _num(v.hmi_window_lower),
        "hmi_allowed": _num(v.hmi_allowed),
        "availability_dh_lower": _num(v.availability_dh_lower),
        "availability": v.availability_verdict,
    }


def contract_summary(
    results: list[CategoryResult], *, profile: str, runs: int, seed: int, closed_loop: bool, failed_runs: int,
    gnss_service: str | None = None, lpv200: dict | None = None,
) -> dict:
    """summary.json, exactly the contract's keys; gnss_service the receiver's label, lpv200 evaluate/lpv.py's
    lpv200_summary (None: no GNSS service)."""
    dhs = {}
    for r in results:
        dhs[r.category] = {
            "height_ft": _num(r.height_ft),
            "lateral_1sigma_ft": _num(r.lateral.rms),
            "vertical_1sigma_ft": _num(r.vertical.rms),
            "lateral_95_ft": _num(r.lateral.p95),
            "vertical_95_ft": _num(r.vertical.p95),
            "limit_lateral_1sigma_ft": _num(r.limits.lateral_1sigma_ft),
            "limit_vertical_1sigma_ft": _num(r.limits.vertical_1sigma_ft),
            "meets": bool(r.meets),
            "verdict": r.verdict,
            "lateral_1sigma_upper_ft": _num(r.lateral_axis.rms_upper_ft),
            "vertical_1sigma_upper_ft": _num(r.vertical_axis.rms_upper_ft),
            "runs_needed": r.runs_needed,
        }
        if r.integrity is not None:  # extension (issue 41): the integrity criterion, counted per approach
            dhs[r.category]["integrity"] = integrity_summary(r.integrity)
    return {
        "schema": SCHEMA,
        "profile": profile,
        "runs": int(runs),
        "seed": int(seed),
        "closed_loop": bool(closed_loop),
        "decision_heights": dhs,
        "best_category": best_category(results),
        "failed_runs": int(failed_runs),
        "gnss_service": gnss_service,
        "lpv200": lpv200,
    }


def _stats_ft(x_m: np.ndarray) -> dict:
    return {k: _num(v) for k, v in asdict(error_stats(x_m).scaled(1.0 / units.FT)).items()}


def _e_sigma(r: np.ndarray) -> dict:
    """RMS of the per-run vertical error / filter sigma at a DH (1 for a consistent filter; its 95 % chi-square band
    for n runs beside it), the number of runs, the mean."""
    r = r[np.isfinite(r)]
    n = int(r.size)
    if n == 0:
        return {"runs": 0, "rms": None, "mean": None, "band_95": None}
    return {"runs": n, "rms": _num(float(np.sqrt(np.mean(r**2)))), "mean": _num(float(np.mean(r))),
            "band_95": [_num(float(np.sqrt(sps.chi2.ppf(q, n) / n))) for q in (0.025, 0.975)]}


def details(columns: Mapping[str, np.ndarray], results: list[CategoryResult], cfg: EvaluationConfig,
            counts: Mapping[str, np.ndarray] | None = None, integrity_fn: Callable[..., dict] | None = None) -> dict:
    """Everything beside the contract: bounds, ICAO limits, failures, integrity, FTE / TSE, time-averaged RMS.

    integrity_fn: the campaign scoring of the solution-separation bank (campaign.integrity_campaign.campaign_integrity,
    handed in by the campaign stage: the evaluator does not import the navigation system the bank runs)."""
    cats = {}
    for r in results:
        key = CATEGORY_KEYS[r.category]
        entry = {
            "height_ft": _num(r.height_ft),
            "meets": r.meets,
            "verdict": r.verdict,
            "runs_needed": r.runs_needed,
            "confidence": r.confidence,
            "bounds_ft": {
                name: {k: _num(v) if not isinstance(v, str) and v is not None else v for k, v in asdict(a).items()}
                for name, a in (("lateral", r.lateral_axis), ("vertical", r.vertical_axis))
            },
            "failures": {
                "runs": r.runs,
                "failed_runs": r.failed_runs,
                "fraction": _num(r.failed_runs / r.runs) if r.runs else None,
                "fraction_upper": _num(r.failure_fraction_upper),
                "allowed_fraction": cfg.max_failure_fraction,
                "verdict": r.failure_verdict,
            },
            "limits_ft": {k: _num(v) for k, v in asdict(r.limits).items()},
        }
        comps = ("along", "lateral", "vertical", "gpdev", "vpl", "hpl", "fte_lat", "fte_vert", "tse_lat", "tse_vert")
        for comp in comps:
            entry[f"{comp}_ft"] = _stats_ft(_col(columns, f"{key}_{comp}_m"))
        if f"{key}_vertical_e_sigma" in columns:  # the filter's consistency at the DH (issue 39)
            entry["vertical_sigma_ft"] = _stats_ft(_col(columns, f"{key}_vertical_sigma_m"))
            entry["vertical_e_sigma"] = _e_sigma(_col(columns, f"{key}_vertical_e_sigma"))
        if f"{key}_int_epochs" in columns:  # the solution-separation bank's (integrity on)
            for c_name, name in (("vpl_dh_m", "vpl"), ("lpl_dh_m", "lpl")):
                entry[f"{name}_ft"] = _stats_ft(_col(columns, f"{key}_int_{c_name}"))
            entry.pop("hpl_ft")
            for axis, name in (("v", "vertical"), ("l", "lateral")):
                entry[f"stanford_{name}"] = {
                    reg: int(np.nansum(_col(columns, f"{key}_int_{axis}_{reg}")))
                    for reg in ("normal", "mi", "hmi", "unavailable")
                }
            n_ep = float(np.nansum(_col(columns, f"{key}_int_epochs")))
            entry["availability"] = _num(float(np.nansum(_col(columns, f"{key}_int_avail_epochs")) / n_ep))
        else:  # integrity off: the covariance K_V / K_H levels (no fault hypothesis; not integrity evidence)
            for axis, name in (("v", "vertical"), ("h", "horizontal")):
                entry[f"stanford_{name}"] = {
                    reg: int(np.nansum(_col(columns, f"{key}_{axis}_{reg}"))) for reg in REGIONS
                }
            av = _col(columns, f"{key}_availability")
            entry["availability"] = _num(float(np.mean(av))) if av.size else None
        if r.integrity is not None:
            entry["integrity_verdict"] = r.integrity.verdict
        cats[r.category] = entry
    ta = campaign_rms_ft({s: _col(columns, f"ta_{s}_ft2") for s in STATES})
    bank = any(f"{CATEGORY_KEYS[c]}_int_epochs" in columns for c in CATEGORIES)
    out = {
        "verdict_limits": cfg.verdict,
        "confidence": cfg.confidence,
        "max_failure_fraction": cfg.max_failure_fraction,
        "categories": cats,
        "time_averaged_rms_ft": {k: _num(v) for k, v in ta.items()},
    }
    if bank and integrity_fn is not None:
        out["protection_levels"] = "solution-separation bank (campaign.integrity_campaign)"
        out["integrity"] = integrity_fn(
            columns, counts or {}, cfg, verdicts={r.category: r.integrity for r in results if r.integrity})
    else:
        out.update({"protection_levels": "covariance K_V / K_H", "k_v": cfg.k_v, "k_h": cfg.k_h})
    return out


GEOMETRY_PERCENTILES = (5, 25, 50, 75, 95)
"""Percentiles of the per-run DOP / satellite-count distributions in details.json."""


def gnss_geometry(run_ids: Sequence[int], columns: Mapping[str, np.ndarray]) -> dict | None:
    """details.json "gnss_geometry": per run (completed runs, run order) the PDOP / HDOP / VDOP and the
    satellites in view / used at each decision height and the run's epoch offset (h); per category their
    distribution (percentiles, min, max) and the fraction of runs with fewer than 4 used and fewer than 5 in
    view. None without GNSS scalars (no GPS fitted)."""
    fields = ("pdop", "hdop", "vdop", "sv_visible", "sv_used")
    if not any(f"{k}_pdop" in columns for k in CATEGORY_KEYS.values()):
        return None
    per_run: dict = {"run": [int(r) for r in run_ids]}
    if "gnss_epoch_offset_h" in columns:
        per_run["epoch_offset_h"] = [_num(v) for v in columns["gnss_epoch_offset_h"]]
    dist = {}
    for cat, key in CATEGORY_KEYS.items():
        per_run[cat] = {f: [_num(v) for v in _col(columns, f"{key}_{f}")] for f in fields}
        entry = {}
        for f in fields:
            x = _col(columns, f"{key}_{f}")
            x = x[np.isfinite(x)]
            entry[f] = ({f"p{p}": _num(float(np.percentile(x, p))) for p in GEOMETRY_PERCENTILES}
                        | {"min": _num(float(x.min())), "max": _num(float(x.max()))}) if x.size else None
        used = _col(columns, f"{key}_sv_used")
        vis = _col(columns, f"{key}_sv_visible")
        entry["fraction_used_lt4"] = _num(float(np.mean(used < 4))) if used.size else None
        entry["fraction_visible_lt5"] = _num(float(np.mean(vis < 5))) if vis.size else None
        dist[cat] = entry
    return {"per_run": per_run, "categories": dist}
