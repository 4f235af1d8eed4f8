"""SBAS protection levels from the weighted least-squares snapshot solution (RTCA DO-229 Appendix J J.1; Stanford
MAAST usr_vhpl.m):

    G_i = [-cos el_i sin az_i, -cos el_i cos az_i, -sin el_i, 1]      (east, north, up, clock; line of sight to i)
    W   = diag(1 / sigma_i^2)                                        (sigma_i the broadcast sigma of the service)
    C   = (G' W G)^-1
    d_V = sqrt(C_uu),   d_major = sqrt((d_E^2 + d_N^2) / 2 + sqrt(((d_E^2 - d_N^2) / 2)^2 + d_EN^2))
    VPL = K_V d_V,      HPL = K_H d_major                            (precision approach: K_V 5.33, K_H 6.0)

K_V,PA 5.33 is a two-sided Gaussian tail of 9.8e-8, K_H,PA 6.0 one of 2.0e-9 along the major axis (MAAST init_mops;
standards reference 1.5). The fault-free bound of a receiver that trusts its broadcast sigmas: with an SBAS the
ground system monitors the faults (UDRE, GIVE); a stand-alone receiver's snapshot has no such monitoring, and these
levels are then only the fault-free part (its integrity needs RAIM / ARAIM).

LPV-200 (standards reference 1.3): VAL 35 m, HAL 40 m; 95 % accuracy 4 m vertical, 16 m horizontal at the 200 ft DH.
"""

from __future__ import annotations

import numpy as np

from approachsim.integrity.requirements import COVARIANCE_K_H, COVARIANCE_K_V, ROWS

Array = np.ndarray

K_V_PA = COVARIANCE_K_V
"""VPL multiplier for precision approach (MAAST init_mops MOPS_KV_PA; integrity.requirements)."""
K_H_PA = COVARIANCE_K_H
"""HPL multiplier for precision approach (MAAST init_mops MOPS_KH_PA; integrity.requirements)."""
LPV200_VAL_M = ROWS["LPV-200"].val_m
"""LPV-200 vertical alert limit, m (the requirements table's row)."""
LPV200_HAL_M = ROWS["LPV-200"].lal_m
"""LPV-200 horizontal alert limit, m (the requirements table's row)."""
LPV200_VERTICAL_95_M = 4.0
"""LPV-200 vertical accuracy, 95 %, m."""
LPV200_HORIZONTAL_95_M = 16.0
"""LPV-200 horizontal accuracy, 95 %, m."""
LPV200_DH_FT = 200.0
"""LPV-200 decision height, ft."""


def geometry_enu(el_rad: Array, az_rad: Array) -> Array:
    """G (..., k, 4): rows [-cos el sin az, -cos el cos az, -sin el, 1] (east, north, up, clock), DO-229 J.1."""
    el = np.asarray(el_rad, dtype=float)
    az = np.asarray(az_rad, dtype=float)
    ce = np.cos(el)
    return np.stack([-ce * np.sin(az), -ce * np.cos(az), -np.sin(el), np.ones_like(el)], axis=-1)


def wls_covariance(el_rad: Array, az_rad: Array, used: Array, sigma_m: Array) -> Array:
    """C = (G' W G)^-1 (..., 4, 4), m^2, over the channels `used` (W = diag(1 / sigma^2), 0 for the others); nan
    where fewer than four channels are used or the geometry is singular."""
    g = geometry_enu(np.nan_to_num(el_rad), np.nan_to_num(az_rad))
    u = np.asarray(used, dtype=bool) & np.isfinite(sigma_m) & (np.asarray(sigma_m) > 0)
    w = np.where(u, 1.0 / np.where(u, np.asarray(sigma_m, dtype=float), 1.0) ** 2, 0.0)
    a = np.einsum("...ki,...k,...kj->...ij", g, w, g)
    ok = (u.sum(axis=-1) >= 4) & (np.abs(np.linalg.det(a)) > 0)
    c = np.full(a.shape, np.nan)
    c[ok] = np.linalg.inv(a[ok])
    return c


def protection_levels(el_rad: Array, az_rad: Array, used: Array, sigma_m: Array, k_v: float = K_V_PA,
                      k_h: float = K_H_PA) -> tuple[Array, Array]:
    """(VPL, HPL), m, per epoch (leading axes of the (..., k) inputs): module docstring; inf where the snapshot has
    fewer than four channels (no solution: not available)."""
    c = wls_covariance(el_rad, az_rad, used, sigma_m)
    de2, dn2, den, dv2 = c[..., 0, 0], c[..., 1, 1], c[..., 0, 1], c[..., 2, 2]
    d_major = np.sqrt((de2 + dn2) / 2.0 + np.sqrt(((de2 - dn2) / 2.0) ** 2 + den**2))
    vpl, hpl = k_v * np.sqrt(dv2), k_h * d_major
    return np.where(np.isfinite(vpl), vpl, np.inf), np.where(np.isfinite(hpl), hpl, np.inf)


def snapshot_error_enu(el_rad: Array, az_rad: Array, used: Array, sigma_m: Array, range_error_m: Array) -> Array:
    """(..., 3) east, north, up error (m) of the weighted least-squares snapshot fix whose pseudoranges carry the
    errors range_error_m (..., k) (nan for unused channels): dx = (G' W G)^-1 G' W e, the position part (the clock
    absorbs the common error). What a stand-alone SBAS receiver's position error is: the figure the WAAS
    performance reports' 95 % accuracies describe."""
    g = geometry_enu(np.nan_to_num(el_rad), np.nan_to_num(az_rad))
    u = np.asarray(used, dtype=bool) & np.isfinite(range_error_m)
    w = np.where(u, 1.0 / np.where(u, np.asarray(sigma_m, dtype=float), 1.0) ** 2, 0.0)
    c = wls_covariance(el_rad, az_rad, u, sigma_m)
    b = np.einsum("...ki,...k,...k->...i", g, w, np.where(u, range_error_m, 0.0))
    return np.einsum("...ij,...j->...i", c, b)[..., :3]


def lpv200_available(vpl_m: Array, hpl_m: Array) -> Array:
    """LPV-200 available: VPL <= 35 m and HPL <= 40 m (a service is available when its PLs are within the alert
    limits; standards reference 1.5)."""
    return (np.asarray(vpl_m) <= LPV200_VAL_M) & (np.asarray(hpl_m) <= LPV200_HAL_M)
