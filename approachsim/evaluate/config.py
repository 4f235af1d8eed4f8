"""The profile's [evaluation] section: decision heights, which limits the verdict uses, integrity factors.

    [evaluation]
    dh_cat1_ft = 200         # decision heights above the threshold, ft
    dh_cat2_ft = 100
    dh_cat3_ft = 50
    verdict = "faa+icao"     # "faa+icao" (default): FAA 1-sigma table and the ICAO 95 % accuracy; "faa": FAA only
    k_v = 5.33               # protection-level factors (standards.md 1.5)
    k_h = 6.0
    series_runs = 3          # runs whose full time series are kept
    flight_group = 25        # open loop: runs sharing one flown truth (one turbulence realization); a campaign of
                             # fewer than 5 x 25 runs uses groups of runs // 5 (at least 5 groups: group_size)
    timeavg_settle_s = 10    # seed 002 time averages start this long after the run starts (filter start-up)
"""

from __future__ import annotations

from dataclasses import dataclass

from approachsim import units
from approachsim.config import ProfileError, Section
from approachsim.evaluate.limits import CATEGORIES, DEFAULT_DH_FT, K_H_PA, K_V_PA
from approachsim.evaluate.stats import MIN_GROUPS

VERDICTS = ("faa", "faa+icao")
DEFAULT_VERDICT = "faa+icao"
"""The verdict's limits by default (issue 41): the FAA 1-sigma table and ICAO Annex 10's 95 % accuracy, which at
CAT I is the tighter of the two (16 m lateral / 4 m vertical against 1.96 x the FAA 8.6 / 2.1 m); at CAT II / III the
FAA table is tighter on both axes. The ICAO criterion bounds the 95th percentile of |error| by an order statistic,
which needs at least 59 runs at 95 % confidence: below that the category is `indeterminate` (Gray & Maybeck's
reproduction keeps "faa", the table the paper scores against)."""
DEFAULT_INTEGRITY = ("CAT II", "CAT III")
"""Categories with integrity in the verdict by default (issue 11: on for CAT II / III)."""


def _integrity(s: Section) -> tuple[str, ...]:
    """evaluation.integrity: true (every category), false (none) or a list of category names."""
    v = s.raw("integrity", list(DEFAULT_INTEGRITY))
    if isinstance(v, bool):
        return tuple(CATEGORIES) if v else ()
    if not isinstance(v, list) or any(c not in CATEGORIES for c in v) or len(set(v)) != len(v):
        raise ProfileError(f"{s.path}.integrity: must be true, false or a list of distinct categories "
                           f"({', '.join(CATEGORIES)}); got {v!r}")
    return tuple(c for c in CATEGORIES if c in v)


@dataclass(frozen=True)
class EvaluationConfig:
    """How a campaign is scored (hashable: a Profile holds it). Decision heights above the threshold, ft."""

    dh_cat1_ft: float = DEFAULT_DH_FT["CAT I"]
    dh_cat2_ft: float = DEFAULT_DH_FT["CAT II"]
    dh_cat3_ft: float = DEFAULT_DH_FT["CAT III"]
    verdict: str = DEFAULT_VERDICT
    k_v: float = K_V_PA
    k_h: float = K_H_PA
    series_runs: int = 3
    flight_group: int = 25
    """Open loop: the most runs that share one flown truth; a campaign's groups: `group_size`."""
    timeavg_settle_s: float = 10.0
    """Start of Gray & Maybeck's time averages after the run start, s: leaves out the filter's start-up (the
    receiver clock is acquired at the first GPS update, from hundreds of metres of initial uncertainty)."""
    confidence: float = 0.95
    """Confidence level of each one-sided bound the verdict is decided on (evaluate/verdict.py)."""
    max_failure_fraction: float = 0.0
    """Failure probability a category tolerates; 0: any failed run fails every category (evaluate/verdict.py)."""
    integrity: tuple[str, ...] = DEFAULT_INTEGRITY
    """Categories whose verdict includes the integrity criterion (evaluate/verdict.py); when any is listed, every
    run is scored by the solution-separation bank (campaign/integrity_campaign.py) and details.json carries `integrity`
    for every category."""

    def group_size(self, runs: int) -> int:
        """Runs per open-loop flight group of a campaign of `runs`: flight_group, or fewer so that the campaign
        has at least MIN_GROUPS (5) groups (issue 41: with fewer the between-group correlation of the runs that
        share a flight cannot be estimated, and the verdict's bounds would count correlated runs as independent;
        evaluate/stats.effective_runs). 20 runs: groups of 4. Under MIN_GROUPS runs no grouping reaches it (and no
        category can meet: evaluate/verdict.MIN_RUNS), so the campaign keeps flight_group."""
        if runs < MIN_GROUPS:
            return int(self.flight_group)
        return max(1, min(int(self.flight_group), int(runs) // MIN_GROUPS))

    @property
    def integrity_on(self) -> bool:
        """Whether the campaign runs the integrity bank (any category listed)."""
        return bool(self.integrity)

    @property
    def dh_ft(self) -> dict[str, float]:
        """Category -> decision height above the threshold, ft."""
        return dict(zip(CATEGORIES, (self.dh_cat1_ft, self.dh_cat2_ft, self.dh_cat3_ft), strict=True))

    def dh_m(self, category: str) -> float:
        """Decision height of `category` above the threshold, m."""
        return self.dh_ft[category] * units.FT


def parse_evaluation(s: Section) -> EvaluationConfig:
    """Read an [evaluation] table (all keys optional); ProfileError names a bad field."""
    keys = ("dh_cat1_ft", "dh_cat2_ft", "dh_cat3_ft")
    dh = {
        c: s.number(k, DEFAULT_DH_FT[c], lo=10.0, hi=1000.0, unit="ft")
        for c, k in zip(CATEGORIES, keys, strict=True)
    }
    if not dh["CAT I"] > dh["CAT II"] > dh["CAT III"]:
        raise ProfileError(f"{s.path}.dh_cat2_ft: decision heights must decrease from CAT I to CAT III, got {dh}")
    verdict = s.string("verdict", DEFAULT_VERDICT, choices=VERDICTS)
    k_v = s.number("k_v", K_V_PA, lo=1.0, hi=20.0)
    k_h = s.number("k_h", K_H_PA, lo=1.0, hi=20.0)
    series_runs = s.integer("series_runs", 3, lo=0, hi=1000)
    flight_group = s.integer("flight_group", 25, lo=1, hi=10000)
    settle = s.number("timeavg_settle_s", 10.0, lo=0.0, hi=600.0, unit="s")
    confidence = s.number("confidence", 0.95, lo=0.5, hi=0.9999)
    max_fail = s.number("max_failure_fraction", 0.0, lo=0.0, hi=0.5)
    integrity = _integrity(s)
    s.done()
    return EvaluationConfig(
        *dh.values(), verdict=verdict, k_v=k_v, k_h=k_h, series_runs=series_runs, flight_group=flight_group,
        timeavg_settle_s=settle, confidence=confidence, max_failure_fraction=max_fail,
        integrity=integrity,
    )
