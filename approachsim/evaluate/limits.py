"""Accuracy and alert limits by approach category, in feet at the decision height (the report's units).

Two tables, reported side by side:

* FAA 1-sigma accuracy at decision height, Gray & Maybeck (1995) Table 1 (standards.md 1.2, design.md):
  the contract's verdict table.
* ICAO 95 % accuracy (standards.md 1.3 and 1.4): CAT I from Annex 10 Table 3.7.2.4-1 (H 16 m, V 4.0 m at the
  strict end of the 6.0-4.0 m range); CAT II/IIIA and CAT IIIB from the S4 table (6.9 / 2.0 m; 6.1 / 2.0 m).
  The CAT III row uses the CAT IIIB numbers.
* Alert limits at the decision height: from the one requirements table, integrity.requirements.REQUIREMENTS
  (CAT I 40 / 10 m, Annex 10; CAT II / III 17 / 10 m, DO-245A GSL D/E), the same numbers the integrity bank
  scores against. Before issue 41 this module carried the older LAAS performance-type limits (CAT II 17.3 / 5.3 m,
  CAT III 15.5 / 5.2 m); they moved the covariance-only Stanford counts and availability of details.json (integrity
  off) and the alert-limit lines of the report's figures, nothing else.
* K_V_PA / K_H_PA: the covariance-only protection-level factors (SBAS DO-229 App. J), from the same table
  (integrity.requirements.COVARIANCE_K_V / _H): used with integrity off, not integrity evidence.

The ICAO "horizontal" numbers are compared with the lateral (cross-track) error at the decision height,
which is the component GBAS specifies (lateral NSE, LAL); the along-track error is reported, not scored.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

from approachsim import units
from approachsim.integrity.requirements import COVARIANCE_K_H, COVARIANCE_K_V, REQUIREMENTS

CATEGORIES = ("CAT I", "CAT II", "CAT III")
"""Approach categories, least to most demanding."""

DEFAULT_DH_FT = MappingProxyType({"CAT I": 200.0, "CAT II": 100.0, "CAT III": 50.0})
"""Default decision heights above the threshold, ft (design.md)."""


@dataclass(frozen=True)
class CategoryLimits:
    """One category's limits, ft. *_1sigma: FAA table; *_95: ICAO 95 % accuracy; *_al: ICAO alert limits."""

    lateral_1sigma_ft: float
    vertical_1sigma_ft: float
    lateral_95_ft: float
    vertical_95_ft: float
    horizontal_al_ft: float
    vertical_al_ft: float

    @property
    def horizontal_al_m(self) -> float:
        """Horizontal alert limit, m."""
        return self.horizontal_al_ft * units.FT

    @property
    def vertical_al_m(self) -> float:
        """Vertical alert limit, m."""
        return self.vertical_al_ft * units.FT


def _m(x_m: float) -> float:
    return x_m / units.FT


def _al(cat: str) -> tuple[float, float]:
    """(horizontal, vertical) alert limit at the DH, ft, from the one requirements table."""
    r = REQUIREMENTS[cat]
    return _m(r.lal_m), _m(r.val_m)


LIMITS = MappingProxyType(
    {
        "CAT I": CategoryLimits(28.1, 6.8, _m(16.0), _m(4.0), *_al("CAT I")),
        "CAT II": CategoryLimits(8.6, 2.8, _m(6.9), _m(2.0), *_al("CAT II")),
        "CAT III": CategoryLimits(6.8, 1.0, _m(6.1), _m(2.0), *_al("CAT III")),
    }
)
"""Limits by category (read-only). FAA 1-sigma values are the paper's (ft); ICAO values converted from m; alert
limits from integrity.requirements."""

K_V_PA = COVARIANCE_K_V
"""Vertical covariance-only protection-level factor (integrity.requirements.COVARIANCE_K_V)."""
K_H_PA = COVARIANCE_K_H
"""Horizontal covariance-only protection-level factor (integrity.requirements.COVARIANCE_K_H)."""
