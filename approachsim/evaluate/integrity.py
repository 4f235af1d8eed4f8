"""Protection levels from the filter covariance, Stanford-diagram counts and availability by category.

VPL = K_V sqrt(P_DD), HPL = K_H d_major with d_major the semi-major axis of the horizontal error ellipse
(DO-229 Appendix J as in MAAST usr_vhpl.m; standards.md 1.5):

    d_major = sqrt( (d_N^2 + d_E^2)/2 + sqrt( ((d_N^2 - d_E^2)/2)^2 + d_NE^2 ) )

Stanford regions (standards.md 1.6), per epoch, with position error PE, protection level PL, alert AL:
unavailable PL >= AL; otherwise normal PE <= PL; MI PL < PE <= AL; HMI PE > AL (an integrity event).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray

REGIONS = ("normal", "mi", "hmi", "unavailable", "unavailable_mi")
"""Stanford-diagram regions counted; unavailable_mi (PL >= AL and PE > PL) is a subset of unavailable."""


def protection_levels(p_pos_ned: Array, k_v: float, k_h: float) -> tuple[Array, Array]:
    """(VPL, HPL), m, from position covariances (..., 3, 3) in NED, m^2 (DO-229 App. J, MAAST usr_vhpl)."""
    p = np.asarray(p_pos_ned, dtype=float)
    d_n2, d_e2, d_ne = p[..., 0, 0], p[..., 1, 1], p[..., 0, 1]
    d_v = np.sqrt(np.maximum(p[..., 2, 2], 0.0))
    d_major = np.sqrt((d_n2 + d_e2) / 2.0 + np.sqrt(((d_n2 - d_e2) / 2.0) ** 2 + d_ne**2))
    return k_v * d_v, k_h * d_major


def stanford_regions(pe: Array, pl: Array, al: float) -> dict[str, int]:
    """Counts of epochs in each Stanford region for errors `pe` and protection levels `pl` against `al`."""
    pe = np.abs(np.asarray(pe, dtype=float))
    pl = np.asarray(pl, dtype=float)
    ok = np.isfinite(pe) & np.isfinite(pl)
    pe, pl = pe[ok], pl[ok]
    unavailable = pl >= al
    avail = ~unavailable
    return {
        "normal": int(np.count_nonzero(avail & (pe <= pl))),
        "mi": int(np.count_nonzero(avail & (pe > pl) & (pe <= al))),
        "hmi": int(np.count_nonzero(avail & (pe > pl) & (pe > al))),
        "unavailable": int(np.count_nonzero(unavailable)),
        "unavailable_mi": int(np.count_nonzero(unavailable & (pe > pl))),
    }


@dataclass(frozen=True)
class IntegritySeries:
    """Per-epoch integrity quantities of one run (time on axis 0), m."""

    vpl_m: Array
    hpl_m: Array
    vpe_m: Array
    """|vertical error|."""
    hpe_m: Array
    """horizontal radial error (N, E)."""


def integrity_series(e_ned: Array, p_pos_ned: Array, k_v: float, k_h: float) -> IntegritySeries:
    """Protection levels and position errors per epoch from the NED error (n, 3) and covariance (n, 3, 3)."""
    n = e_ned.shape[0]
    vpl, hpl = protection_levels(p_pos_ned[:n], k_v, k_h)
    return IntegritySeries(
        vpl_m=vpl, hpl_m=hpl, vpe_m=np.abs(e_ned[:, 2]), hpe_m=np.hypot(e_ned[:, 0], e_ned[:, 1])
    )


def availability(vpl_m: Array, hpl_m: Array, val_m: float, hal_m: float) -> Array:
    """Per-epoch availability of a category: HPL <= HAL and VPL <= VAL (standards.md 1.5, EGNOS)."""
    return (np.asarray(vpl_m) <= val_m) & (np.asarray(hpl_m) <= hal_m)
