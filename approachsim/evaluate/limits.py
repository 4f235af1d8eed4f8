"""Accuracy and alert limits by approach category, in feet at the decision height (the report's units).

Two tables, reported side by side:

* FAA 1-sigma accuracy at decision height, Gray & Maybeck (1995) Table 1 (standards.md 1.2, design.md):
  the contract's verdict table.
* ICAO 95 % accuracy and alert limits (standards.md 1.3 and 1.4): CAT I from Annex 10 Table 3.7.2.4-1
  (H 16 m, V 4.0 m at the strict end of the 6.0-4.0 m range; HAL 40 m, VAL 10 m, the strict end of
  15-10 m, as the FAA GLS Cat-I slide); CAT II/IIIA and CAT IIIB from the S4 table (6.9 / 2.0 m,
  17.3 / 5.3 m; 6.1 / 2.0 m, 15.5 / 5.2 m). The CAT III row uses the CAT IIIB numbers.

The ICAO "horizontal" numbers are compared with the lateral (cross-track) error at the decision height,
which is the component GBAS specifies (lateral NSE, LAL); the along-track error is reported, not scored.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

from approachsim import units

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


LIMITS = MappingProxyType(
    {
        "CAT I": CategoryLimits(28.1, 6.8, _m(16.0), _m(4.0), _m(40.0), _m(10.0)),
        "CAT II": CategoryLimits(8.6, 2.8, _m(6.9), _m(2.0), _m(17.3), _m(5.3)),
        "CAT III": CategoryLimits(6.8, 1.0, _m(6.1), _m(2.0), _m(15.5), _m(5.2)),
    }
)
"""Limits by category (read-only). FAA 1-sigma values are the paper's (ft); ICAO values converted from m."""

K_V_PA = 5.33
"""Vertical protection-level factor for precision approach (DO-229, MAAST init_mops.m; standards.md 1.5)."""
K_H_PA = 6.0
"""Horizontal protection-level factor for precision approach (DO-229, MAAST init_mops.m; standards.md 1.5)."""
