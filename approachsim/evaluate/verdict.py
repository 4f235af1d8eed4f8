"""Verdict per category from confidence bounds: `meets`, `fails` or `indeterminate`, and the runs to decide it.

Each criterion is judged on one-sided confidence bounds at the profile's evaluation.confidence (default
0.95), never on a point estimate alone:

* FAA 1-sigma (always): for the lateral and the vertical error at the category's decision height, the RMS
  over the completed runs (bias included) has a lower and an upper bound (stats.rms_bounds: Patnaik's
  noncentral chi-square fit for the upper, the zero-mean chi-square bound for the lower). The axis meets
  when its upper bound is within the FAA limit and at least stats.MIN_RUNS runs completed, fails when its
  lower bound exceeds the limit, and is indeterminate otherwise.
* ICAO 95 % accuracy (verdict = "faa+icao"): the distribution-free one-sided order-statistic bounds of the
  95th percentile of |error| (binomial(n, 0.95) ranks): meets when the upper bound is within the ICAO value
  (needs n >= 59), fails when the lower bound exceeds it.
* Shared truth (open loop): with `groups`, the RMS bounds use the effective run count of the clustered runs
  (stats.effective_runs: Kish's design effect from the between-group correlation of the error).
* Failed runs (diverged, unstabilized, never reached the decision height): they count against every
  category. With evaluation.max_failure_fraction = 0 (the default) any failed run makes the category fail
  (the observed failure rate is above the allowed zero). With an allowed fraction f > 0 the Clopper-Pearson
  one-sided bounds of the failure probability decide: upper <= f passes, lower > f fails, else
  indeterminate.

* Integrity (categories listed in evaluation.integrity; integrity_verdict): availability at the decision
  height (runs whose protection levels were inside the alert limits at their last epoch before the DH) meets
  when its Clopper-Pearson lower bound reaches the category's requirement (0.99, the lower end of ICAO
  Annex 10 Vol I Table 3.7.2.4-1's range; integrity.requirements) and fails when its upper bound is below it.
  Hazardously misleading information is counted per approach (a run), never per epoch: the ~250 filter epochs of
  one approach are strongly correlated (errors move over tens of seconds) and are not independent samples of
  anything. The integrity event of a run is HMI in its window: CAT I anywhere in the approach (its allocation is
  2e-7 per approach, 150 s); CAT II / III in the last 15 s (vertical) / 30 s (lateral) before the DH (the
  exposures of the 1e-9 allocation, DO-245A GSL D via Pullen). The HMI finding, on one-sided Clopper-Pearson
  bounds of a per-approach probability against the allocation (IntegrityRequirement.hmi_probability_allowed):
  `shown` (meets) when no run had HMI anywhere and the upper bound from the runs is within the allocation
  (conservative: the whole approach contains the window); `exceeds` (fails) only when the lower bound of the
  windowed event's probability is above it; `not shown` (indeterminate) otherwise, so HMI outside the window
  alone is at most `not shown`. With zero events the upper bound is 1 - (1 - level)^(1/n), so showing 1e-9 at
  95 % takes ln(0.05) / ln(1 - 1e-9) = 3.0e9 approaches (runs_needed).

The category fails when any criterion fails, meets when all meet, and is indeterminate otherwise.
runs_needed (indeterminate only): the completed-run count at which the bounds would likely decide it if
the point estimates stayed where they are: towards `fails` when a point estimate is beyond its limit,
towards `meets` otherwise (the largest over the criteria); None when decided or beyond reach.
best_category: the most demanding category whose verdict is `meets`, None when none is.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats as sps

from approachsim.evaluate.limits import CATEGORIES, LIMITS, CategoryLimits
from approachsim.evaluate.stats import (
    MIN_RUNS,
    ErrorStats,
    bias_ratio,
    effective_runs,
    error_stats,
    quantile_lower_rank,
    quantile_upper_rank,
    rms_bounds,
    runs_to_decide,
)

VERDICTS = ("meets", "fails", "indeterminate")
ICAO_MIN_RUNS = 59
"""Fewest runs whose largest |error| is a 95 %-confidence upper bound of the 95th percentile (0.95^59 < 0.05)."""


@dataclass(frozen=True)
class AxisVerdict:
    """One axis (lateral or vertical) of one category: bounds of its RMS (ft) and the axis verdict."""

    rms_lower_ft: float
    rms_upper_ft: float
    p95_lower_ft: float
    p95_upper_ft: float
    verdict: str
    runs_needed: int | None
    n_eff: float | None = None
    """Effective run count of the bounds (shared-truth groups, stats.effective_runs); None: independent runs."""
    shared_truth_rho: float | None = None
    """Estimated between-group correlation of the error (None: no groups; nan: too few groups to estimate)."""


HMI_FINDINGS = {"meets": "shown", "indeterminate": "not shown", "fails": "exceeds"}
"""The HMI criterion's verdict in the words of an integrity allocation."""


@dataclass(frozen=True)
class IntegrityVerdict:
    """The integrity criterion of one category: availability at the DH and HMI per approach (module docstring)."""

    availability_verdict: str
    hmi_verdict: str
    verdict: str
    runs_needed: int | None
    availability_dh_lower: float
    availability_dh_upper: float
    hmi_probability_upper: float
    """Upper bound of the per-approach probability of HMI anywhere in the approach."""
    approaches: int = 0
    """Runs (approaches) scored by the bank."""
    hmi_approaches: int = 0
    """Runs with at least one HMI epoch anywhere in the approach."""
    hmi_window_approaches: int | None = None
    """Runs with HMI inside the category's window before the DH (None: the window is the whole approach)."""
    hmi_window_lower: float = 0.0
    """Lower bound of the per-approach probability of the windowed event."""
    hmi_allowed: float = math.nan
    """The allocation the bounds are compared with (per approach, or per window before the DH)."""

    @property
    def hmi_finding(self) -> str:
        """`shown`, `not shown` or `exceeds` (module docstring)."""
        return HMI_FINDINGS[self.hmi_verdict]


def runs_to_show(allowed: float, level: float = 0.95) -> int:
    """Approaches without any event at which the Clopper-Pearson upper bound 1 - (1 - level)^(1/n) reaches
    `allowed`: ceil(ln(1 - level) / ln(1 - allowed))."""
    return int(math.ceil(math.log(1.0 - level) / math.log1p(-allowed)))


def _runs_for_availability(k: int, n: int, required: float, level: float) -> int | None:
    """Runs at which the availability's lower bound would reach `required` at the same observed fraction."""
    if n <= 0 or k / n < required:
        return None
    frac = k / n
    for m in (int(x) for x in np.unique(np.geomspace(max(n, 1), 1e7, 600).astype(int))):
        if clopper_pearson(int(math.floor(frac * m)), m, level)[0] >= required:
            return m
    return None


def integrity_verdict(available_dh: int, runs_dh: int, hmi_approaches: int, required_availability: float,
                      allowed_hmi: float, level: float = 0.95, *, hmi_window_approaches: int | None = None
                      ) -> IntegrityVerdict:
    """The integrity criterion (module docstring) from the runs available at the DH (of runs_dh, the approaches
    the bank scored), the approaches with HMI anywhere and, for a windowed category, those with HMI inside its
    window (None: the window is the whole approach). allowed_hmi: the allocation per approach (per window).
    runs_needed: approaches at which the bounds would decide towards meets at the same observed fractions (the
    HMI part: runs_to_show, with none observed)."""
    a_lo, a_hi = clopper_pearson(available_dh, runs_dh, level)
    av = "meets" if runs_dh > 0 and a_lo >= required_availability else (
        "fails" if runs_dh > 0 and a_hi < required_availability else "indeterminate")
    win = hmi_approaches if hmi_window_approaches is None else hmi_window_approaches
    h_hi = clopper_pearson(hmi_approaches, runs_dh, level)[1]
    w_lo = clopper_pearson(win, runs_dh, level)[0]
    hv = "fails" if win > 0 and w_lo > allowed_hmi else (
        "meets" if hmi_approaches == 0 and runs_dh > 0 and h_hi <= allowed_hmi else "indeterminate")
    v = _combine([av, hv])
    need = None
    if v == "indeterminate":
        needs = []
        if av == "indeterminate":
            needs.append(_runs_for_availability(available_dh, runs_dh, required_availability, level))
        if hv == "indeterminate":
            needs.append(runs_to_show(allowed_hmi, level) if hmi_approaches == 0 else None)
        need = None if not needs or any(x is None for x in needs) else max(needs)
    return IntegrityVerdict(av, hv, v, need, a_lo, a_hi, h_hi, int(runs_dh), int(hmi_approaches),
                            hmi_window_approaches, w_lo, allowed_hmi)


@dataclass(frozen=True)
class CategoryResult:
    """The scored errors of one category at its decision height, ft, and its verdict."""

    category: str
    height_ft: float
    lateral: ErrorStats
    vertical: ErrorStats
    limits: CategoryLimits
    lateral_axis: AxisVerdict
    vertical_axis: AxisVerdict
    runs: int
    failed_runs: int
    failure_verdict: str
    failure_fraction_upper: float
    verdict: str
    runs_needed: int | None
    confidence: float
    integrity: IntegrityVerdict | None = None
    """The integrity criterion when the category has integrity on (evaluation.integrity), else None."""

    @property
    def meets(self) -> bool:
        """The contract's `meets`: true exactly when the verdict is `meets`."""
        return self.verdict == "meets"


def clopper_pearson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """One-sided (lower, upper) Clopper-Pearson bounds, each at `level`, of a probability from k of n."""
    if n <= 0:
        return 0.0, 1.0
    lo = 0.0 if k == 0 else float(sps.beta.ppf(1.0 - level, k, n - k + 1))
    hi = 1.0 if k == n else float(sps.beta.ppf(level, k + 1, n - k))
    return lo, hi


def failure_verdict(failed: int, runs: int, allowed: float, level: float = 0.95) -> str:
    """Verdict of the failure criterion (module docstring)."""
    if allowed <= 0.0:
        return "fails" if failed > 0 else "meets"
    lo, hi = clopper_pearson(failed, runs, level)
    return "meets" if hi <= allowed else ("fails" if lo > allowed else "indeterminate")


def _runs_for_failures(failed: int, runs: int, allowed: float, level: float) -> int | None:
    """Runs at which the failure fraction's upper bound would reach `allowed` at the same failure rate."""
    if allowed <= 0.0 or runs <= 0:
        return None
    rate = failed / runs
    for n in (int(x) for x in np.unique(np.geomspace(max(runs, 1), 100000, 400).astype(int))):
        if clopper_pearson(int(round(rate * n)), n, level)[1] <= allowed:
            return n
    return None


def _combine(verdicts: Sequence[str]) -> str:
    if "fails" in verdicts:
        return "fails"
    return "meets" if all(v == "meets" for v in verdicts) else "indeterminate"


def axis_verdict(x_ft: np.ndarray, limit_1sigma_ft: float, limit_95_ft: float, icao: bool, level: float,
                 groups: np.ndarray | None = None) -> AxisVerdict:
    """Verdict of one axis from its per-run errors (ft, completed runs only); groups: the shared-truth group
    of each run (open loop), whose correlation lowers the effective run count of the RMS bounds."""
    x = np.asarray(x_ft, dtype=float)
    fin = np.isfinite(x)
    n_eff = rho = None
    if groups is not None:
        n_eff, rho = effective_runs(x, np.asarray(groups))
    x = x[fin]
    n = int(x.size)
    nan = float("nan")
    if n == 0:
        return AxisVerdict(nan, nan, nan, nan, "indeterminate", None, n_eff, rho)
    lo, hi = rms_bounds(x, level, n_eff)
    rms = float(np.sqrt(np.mean(x**2)))
    faa = "fails" if lo > limit_1sigma_ft else ("meets" if hi <= limit_1sigma_ft and n >= MIN_RUNS else "indeterminate")
    a = np.sort(np.abs(x))
    ru, rl = quantile_upper_rank(n, 0.95, level), quantile_lower_rank(n, 0.95, level)
    p_hi = float(a[ru - 1]) if ru is not None else math.inf
    p_lo = float(a[rl - 1]) if rl is not None else 0.0
    crit = [faa]
    if icao:
        crit.append("fails" if p_lo > limit_95_ft else ("meets" if p_hi <= limit_95_ft else "indeterminate"))
    v = _combine(crit)
    need = None
    if v == "indeterminate":
        need = runs_to_decide(rms, bias_ratio(x), limit_1sigma_ft, level)
        if need is not None and n_eff is not None and n_eff < n:
            need = int(math.ceil(need * n / n_eff))  # the same design effect
        if icao and rms < limit_1sigma_ft and float(np.percentile(a, 95.0)) <= limit_95_ft:
            need = max(need or 0, ICAO_MIN_RUNS, n + 1)
    return AxisVerdict(lo, hi, p_lo, p_hi, v, need, n_eff, rho)


def category_verdict(
    category: str,
    height_ft: float,
    lateral_ft: np.ndarray,
    vertical_ft: np.ndarray,
    verdict: str = "faa",
    *,
    runs: int | None = None,
    failed_runs: int = 0,
    max_failure_fraction: float = 0.0,
    confidence: float = 0.95,
    groups: np.ndarray | None = None,
    integrity: IntegrityVerdict | None = None,
) -> CategoryResult:
    """Score one category from the per-run errors (ft) at its decision height of the completed runs.

    runs: all runs of the campaign (completed + failed_runs; default the completed count + failed_runs).
    groups: the shared-truth group of each completed run (open loop), aligned with the error arrays.
    integrity: the category's integrity criterion (integrity_verdict) when it has integrity on, else None.
    """
    lim = LIMITS[category]
    lat = error_stats(lateral_ft, confidence)
    ver = error_stats(vertical_ft, confidence)
    icao = verdict == "faa+icao"
    la = axis_verdict(lateral_ft, lim.lateral_1sigma_ft, lim.lateral_95_ft, icao, confidence, groups)
    va = axis_verdict(vertical_ft, lim.vertical_1sigma_ft, lim.vertical_95_ft, icao, confidence, groups)
    total = (min(lat.n, ver.n) + failed_runs) if runs is None else int(runs)
    fv = failure_verdict(failed_runs, total, max_failure_fraction, confidence)
    f_hi = clopper_pearson(failed_runs, total, confidence)[1]
    v = _combine([la.verdict, va.verdict, fv] + ([integrity.verdict] if integrity is not None else []))
    need = None
    if v == "indeterminate":
        axes = [a for a in (la, va) if a.verdict == "indeterminate"]
        rms_lim = ((lat.rms, lim.lateral_1sigma_ft), (ver.rms, lim.vertical_1sigma_ft))
        beyond = [a.runs_needed for a, (r, L) in zip((la, va), rms_lim, strict=True)
                  if a.verdict == "indeterminate" and r > L and a.runs_needed is not None]
        if beyond:
            need = min(beyond)
        else:
            needs = [a.runs_needed for a in axes]
            if fv == "indeterminate":
                needs.append(_runs_for_failures(failed_runs, total, max_failure_fraction, confidence))
            if integrity is not None and integrity.verdict == "indeterminate":
                needs.append(integrity.runs_needed)  # the deciding one when the accuracy is decided
            need = None if not needs or any(x is None for x in needs) else max(needs)
    return CategoryResult(
        category, height_ft, lat, ver, lim, la, va, total, failed_runs, fv, f_hi, v, need, confidence, integrity
    )


def best_category(results: Sequence[CategoryResult]) -> str | None:
    """The most demanding category whose verdict is `meets`, or None."""
    met = [r.category for r in results if r.meets]
    return max(met, key=CATEGORIES.index) if met else None
