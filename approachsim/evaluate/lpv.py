"""LPV-200 (SBAS approach to a 200 ft decision height) judged beside the FAA categories: accuracy and integrity.

Per run (campaign/pipeline.py, from the receiver's record and the CAT I crossing): the horizontal (along and
lateral, radial) and vertical navigation errors at the 200 ft decision height, the SBAS protection levels of the
weighted least-squares snapshot with the broadcast sigmas there (integrity/sbas.py: VPL = 5.33 d_V,
HPL = 6.0 d_major) and whether LPV-200 was available there (VPL <= 35 m and HPL <= 40 m) and over the approach
before it (the fraction of GNSS epochs available).

Over the runs, on one-sided confidence bounds as the CAT verdicts (evaluate/verdict.py):

* accuracy: the distribution-free order-statistic bounds of the 95th percentile of |vertical| and of the horizontal
  radial error against 4 m and 16 m (ICAO Annex 10 Vol I Table 3.7.2.4-1, LPV-200 row): meets when the upper bound
  is within (needs >= 59 runs), fails when the lower bound exceeds it;
* integrity: availability at the DH, Clopper-Pearson bounds of the runs available against 0.99 (the lower end of
  Annex 10's range, as the CAT integrity criterion); only an SBAS service has an integrity basis (the ground
  system's monitoring behind the broadcast UDRE / GIVE / DFRE); a stand-alone receiver's WLS levels are the
  fault-free part only, so its LPV-200 integrity fails ("integrity_basis": null);
* misleading information against the SBAS protection levels, per run over the approach down to the DH
  (count_misleading): an epoch is available when VPL <= VAL and HPL <= HAL; misleading (MI) when the GNSS-only
  WLS fix's error exceeds its protection level there (|vertical| > VPL or horizontal > HPL), hazardously misleading
  (HMI) when it exceeds the alert limit (|vertical| > VAL or horizontal > HAL) while available (the Stanford
  integrity diagram's regions). The PLs bound that snapshot fix, not the blended navigation solution. A run with an
  HMI epoch is an HMI approach; one observed at a simulated run count contradicts the 2e-7 per approach flatly, so
  it fails the integrity verdict; none cannot show 2e-7 (about 1.5e7 runs would), which rests on the SBAS ground
  monitoring (the integrity basis), so it does not make the verdict indeterminate;
* failed runs count against it as against every category (evaluation.max_failure_fraction).

The verdict combines them as the categories' do: fails if any fails, meets if all meet, else indeterminate.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.stats import quantile_lower_rank, quantile_upper_rank
from approachsim.evaluate.verdict import ICAO_MIN_RUNS, _runs_for_availability, clopper_pearson, failure_verdict
from approachsim.integrity.requirements import ROWS
from approachsim.integrity.sbas import (
    LPV200_DH_FT,
    LPV200_HAL_M,
    LPV200_HORIZONTAL_95_M,
    LPV200_VAL_M,
    LPV200_VERTICAL_95_M,
)

REQUIRED_AVAILABILITY = 0.99
"""Availability at the DH the integrity criterion asks for (integrity.requirements' CAT I value)."""
INTEGRITY_RISK = ROWS["LPV-200"].integrity_risk
"""LPV-200's integrity risk per approach (2e-7; the requirements table's row)."""


def count_misleading(vertical_m: np.ndarray, horizontal_m: np.ndarray, vpl_m: np.ndarray,
                     hpl_m: np.ndarray) -> tuple[int, int, int]:
    """(available, MI, HMI) epoch counts of one run (module docstring): the GNSS-only WLS fix's vertical and
    horizontal radial errors (m) against its VPL / HPL (m) per epoch; an epoch with no fix (nan error) counts as
    available only."""
    v, h = np.abs(np.asarray(vertical_m, dtype=float)), np.asarray(horizontal_m, dtype=float)
    vpl, hpl = np.asarray(vpl_m, dtype=float), np.asarray(hpl_m, dtype=float)
    avail = (vpl <= LPV200_VAL_M) & (hpl <= LPV200_HAL_M)
    with np.errstate(invalid="ignore"):
        mi = avail & ((v > vpl) | (h > hpl))
        hmi = avail & ((v > LPV200_VAL_M) | (h > LPV200_HAL_M))
    return int(avail.sum()), int(mi.sum()), int(hmi.sum())


def _num(x: float) -> float | None:
    return float(x) if x is not None and math.isfinite(x) else None


def _p95_bounds(x: np.ndarray, level: float) -> tuple[float, float, float]:
    """(95th percentile, lower bound, upper bound) of |x| (order statistics; inf / 0 where no rank exists)."""
    a = np.sort(np.abs(x[np.isfinite(x)]))
    n = int(a.size)
    if n == 0:
        return math.nan, 0.0, math.inf
    ru, rl = quantile_upper_rank(n, 0.95, level), quantile_lower_rank(n, 0.95, level)
    return (float(np.percentile(a, 95.0)), float(a[rl - 1]) if rl is not None else 0.0,
            float(a[ru - 1]) if ru is not None else math.inf)


def _axis(p_lo: float, p_hi: float, limit: float) -> str:
    return "fails" if p_lo > limit else ("meets" if p_hi <= limit else "indeterminate")


def _runs_needed(verdict: str, acc: list[str], integ: str, k: int, n: int, level: float) -> int | None:
    """Runs at which the bounds would likely decide an indeterminate verdict at the same observed rates: the 59 the
    95th percentile's order statistic needs, and the runs at which availability's lower bound would reach 0.99 (about
    299 with every run available); None when decided or out of reach."""
    if verdict != "indeterminate":
        return None
    needs = []
    if "indeterminate" in acc:
        needs.append(max(ICAO_MIN_RUNS, n + 1))
    if integ == "indeterminate":
        needs.append(_runs_for_availability(k, n, REQUIRED_AVAILABILITY, level))
    return None if not needs or any(x is None for x in needs) else max(needs)


def _total(columns: Mapping[str, np.ndarray], key: str) -> int | None:
    """Sum of a per-run count column over the runs that have it (None: no run has it)."""
    x = np.asarray(columns.get(key, np.full(1, np.nan)), dtype=float)
    x = x[np.isfinite(x)]
    return int(x.sum()) if x.size else None


def _misleading(columns: Mapping[str, np.ndarray], level: float) -> tuple[int | None, int | None, float]:
    """(runs with MI, runs with HMI, one-sided Clopper-Pearson upper bound of the per-approach HMI probability) over
    the runs with the counts (None, None, nan without them)."""
    mi = np.asarray(columns.get("lpv200_mi_epochs", np.full(1, np.nan)), dtype=float)
    hmi = np.asarray(columns.get("lpv200_hmi_epochs", np.full(1, np.nan)), dtype=float)
    ok = np.isfinite(hmi)
    if not ok.any():
        return None, None, math.nan
    k = int((hmi[ok] > 0).sum())
    return int((mi[ok] > 0).sum()), k, clopper_pearson(k, int(ok.sum()), level)[1]


def lpv200_summary(columns: Mapping[str, np.ndarray], cfg: EvaluationConfig, *, runs: int,
                   failed_runs: int) -> dict | None:
    """summary.json "lpv200" from the per-run columns (module docstring); None when the runs carry no LPV-200
    columns (a receiver without a GNSS service: no broadcast sigmas to bound with) or the CAT I decision height
    is not 200 ft."""
    if "lpv200_vpl_m" not in columns or cfg.dh_ft.get("CAT I") != LPV200_DH_FT:
        return None
    level = cfg.confidence
    ver = np.asarray(columns["cat1_vertical_m"], dtype=float)
    hor = np.hypot(np.asarray(columns["cat1_along_m"], dtype=float), np.asarray(columns["cat1_lateral_m"], float))
    v95, v_lo, v_hi = _p95_bounds(ver, level)
    h95, h_lo, h_hi = _p95_bounds(hor, level)
    acc = [_axis(v_lo, v_hi, LPV200_VERTICAL_95_M), _axis(h_lo, h_hi, LPV200_HORIZONTAL_95_M)]
    avail = np.asarray(columns["lpv200_avail_dh"], dtype=float)
    avail = avail[np.isfinite(avail)]
    k, n = int(avail.sum()), int(avail.size)
    a_lo, a_hi = clopper_pearson(k, n, level)
    sbas = bool(np.nanmax(columns.get("lpv200_sbas", np.zeros(1)))) if n else False
    mi_runs, hmi_runs, hmi_p_hi = _misleading(columns, level)
    if not sbas or hmi_runs:
        integ = "fails"
    else:
        integ = "meets" if n and a_lo >= REQUIRED_AVAILABILITY else (
            "fails" if n and a_hi < REQUIRED_AVAILABILITY else "indeterminate")
    fv = failure_verdict(failed_runs, runs, cfg.max_failure_fraction, level)
    parts = [*acc, integ, fv]
    verdict = "fails" if "fails" in parts else ("meets" if all(p == "meets" for p in parts) else "indeterminate")
    vpl = np.asarray(columns["lpv200_vpl_m"], dtype=float)
    hpl = np.asarray(columns["lpv200_hpl_m"], dtype=float)
    frac = np.asarray(columns.get("lpv200_avail_fraction", np.full(1, np.nan)), dtype=float)
    snap_v = np.asarray(columns.get("lpv200_snapshot_vertical_m", np.full(1, np.nan)), dtype=float)
    snap_h = np.asarray(columns.get("lpv200_snapshot_horizontal_m", np.full(1, np.nan)), dtype=float)
    sv95 = float(np.percentile(np.abs(snap_v[np.isfinite(snap_v)]), 95.0)) if np.isfinite(snap_v).any() else None
    sh95 = float(np.percentile(snap_h[np.isfinite(snap_h)], 95.0)) if np.isfinite(snap_h).any() else None
    return {
        "height_ft": int(LPV200_DH_FT),
        "integrity_basis": "SBAS (RTCA DO-229 App. J protection levels)" if sbas else None,
        "vertical_95_m": _num(v95), "vertical_95_upper_m": _num(v_hi),
        "horizontal_95_m": _num(h95), "horizontal_95_upper_m": _num(h_hi),
        "limit_vertical_95_m": LPV200_VERTICAL_95_M, "limit_horizontal_95_m": LPV200_HORIZONTAL_95_M,
        "vpl_median_m": _num(float(np.nanmedian(vpl))) if vpl.size else None,
        "hpl_median_m": _num(float(np.nanmedian(hpl))) if hpl.size else None,
        "val_m": LPV200_VAL_M, "hal_m": LPV200_HAL_M,
        "availability_dh": _num(k / n) if n else None, "availability_dh_lower": _num(a_lo),
        "availability_approach_mean": _num(float(np.nanmean(frac))) if np.isfinite(frac).any() else None,
        "required_availability": REQUIRED_AVAILABILITY,
        "available_epochs": _total(columns, "lpv200_available_epochs"),
        "mi_epochs": _total(columns, "lpv200_mi_epochs"), "hmi_epochs": _total(columns, "lpv200_hmi_epochs"),
        "mi_runs": mi_runs, "hmi_runs": hmi_runs, "hmi_probability_upper": _num(hmi_p_hi),
        "integrity_risk": INTEGRITY_RISK,
        "snapshot_vertical_95_m": sv95, "snapshot_horizontal_95_m": sh95,
        "accuracy_verdict": "fails" if "fails" in acc else ("meets" if acc == ["meets", "meets"] else "indeterminate"),
        "integrity_verdict": integ,
        "verdict": verdict,
        "meets": verdict == "meets",
        "runs_needed": _runs_needed(verdict, acc, integ, k, n, level),
    }
