"""Verdict per category: the FAA 1-sigma table (the contract's `meets`), the ICAO 95 % accuracy beside it.

meets (verdict "faa"): RMS over runs (bias included) of the lateral and of the vertical error at the
category's decision height both within the FAA 1-sigma limits. With verdict "faa+icao" the 95th
percentiles of |error| must also be within the ICAO 95 % accuracy. No completed run: not met.
best_category: the most demanding category met (CAT III > CAT II > CAT I), None when none is.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from approachsim.evaluate.limits import CATEGORIES, LIMITS, CategoryLimits
from approachsim.evaluate.stats import ErrorStats, error_stats


@dataclass(frozen=True)
class CategoryResult:
    """The scored errors of one category at its decision height, ft."""

    category: str
    height_ft: float
    lateral: ErrorStats
    vertical: ErrorStats
    limits: CategoryLimits
    meets_faa: bool
    meets_icao: bool
    meets: bool


def category_verdict(
    category: str, height_ft: float, lateral_ft: np.ndarray, vertical_ft: np.ndarray, verdict: str = "faa"
) -> CategoryResult:
    """Score one category from the per-run errors (ft) at its decision height."""
    lim = LIMITS[category]
    lat = error_stats(lateral_ft)
    ver = error_stats(vertical_ft)
    have = lat.n > 0 and ver.n > 0
    meets_faa = bool(have and lat.rms <= lim.lateral_1sigma_ft and ver.rms <= lim.vertical_1sigma_ft)
    meets_icao = bool(have and lat.p95 <= lim.lateral_95_ft and ver.p95 <= lim.vertical_95_ft)
    meets = meets_faa and (meets_icao or verdict == "faa")
    return CategoryResult(category, height_ft, lat, ver, lim, meets_faa, meets_icao, meets)


def best_category(results: Sequence[CategoryResult]) -> str | None:
    """The most demanding category met, or None."""
    met = [r.category for r in results if r.meets]
    return max(met, key=CATEGORIES.index) if met else None
