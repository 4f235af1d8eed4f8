"""IBIG fusion (Manero Contreras & Hajiyev eqs. 9-10): two local filters' altitude-error estimates combined
by their altitude variances.

The local filters are the integrated baro-inertial (IBI, H = [1 0 0 0 -1]) and inertial-GPS (IIG,
H = [1 0 0 0 0]) error-state filters; each gives an estimate of the INS altitude error dH and its variance
P(1,1). Eq. 9 as printed weights each estimate by its OWN variance,

    dH_IBIG = (P1(1,1) dH_IIG + P2(1,1) dH_IBI) / (P1(1,1) + P2(1,1))      (P1: IIG, P2: IBI)

which leans towards the less certain channel. The minimum-variance combination of two estimates with
uncorrelated errors swaps the weights (each weighted by the other's variance, the fused variance then
P1 P2 / (P1 + P2)); both are offered, `weighting="paper"` (eq. 9 as printed) or `"inverse-variance"`.
Eq. 10: H_IBIG = H_INS - dH_IBIG (the paper prints dH_I(k) for the INS reading H_I(k)).
All arrays broadcast (e.g. (runs, time)); metres and m^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray

WEIGHTINGS = ("paper", "inverse-variance")


def ibig_weights(var_iig_m2: Array, var_ibi_m2: Array, weighting: str = "paper") -> tuple[Array, Array]:
    """Weights (w_iig, w_ibi), summing to 1, of the IIG and IBI estimates (eq. 9 or its inverse-variance form)."""
    var_iig, var_ibi = np.asarray(var_iig_m2, dtype=float), np.asarray(var_ibi_m2, dtype=float)
    if np.any(var_iig <= 0.0) or np.any(var_ibi <= 0.0):
        raise ValueError("ibig_weights: the altitude variances P(1,1) must be positive")
    total = var_iig + var_ibi
    if weighting == "paper":
        return var_iig / total, var_ibi / total  # eq. 9: each estimate weighted by its own P(1,1)
    if weighting == "inverse-variance":
        return var_ibi / total, var_iig / total  # minimum variance for uncorrelated errors
    raise ValueError(f"weighting: must be one of {', '.join(WEIGHTINGS)}; got {weighting!r}")


def ibig_fuse(
    dh_iig_m: Array, var_iig_m2: Array, dh_ibi_m: Array, var_ibi_m2: Array, weighting: str = "paper"
) -> tuple[Array, Array]:
    """Fused altitude-error estimate dH_IBIG (eq. 9), m, and its variance if the local errors are uncorrelated,
    m^2 (w_iig^2 P1 + w_ibi^2 P2; for the inverse-variance weighting this is P1 P2 / (P1 + P2))."""
    w_iig, w_ibi = ibig_weights(var_iig_m2, var_ibi_m2, weighting)
    dh = w_iig * np.asarray(dh_iig_m, dtype=float) + w_ibi * np.asarray(dh_ibi_m, dtype=float)  # eq. 9
    var = w_iig**2 * np.asarray(var_iig_m2, dtype=float) + w_ibi**2 * np.asarray(var_ibi_m2, dtype=float)
    return dh, var


def ibig_altitude(h_ins_m: Array, dh_ibig_m: Array) -> Array:
    """Eq. 10: the integrated altitude H_IBIG = H_INS - dH_IBIG, m."""
    return np.asarray(h_ins_m, dtype=float) - np.asarray(dh_ibig_m, dtype=float)


@dataclass(frozen=True)
class IbigFusion:
    """IBIG fusion of the IIG and IBI local filters' states, on state component `index` (0: altitude error)."""

    weighting: str = "paper"
    index: int = 0

    def __post_init__(self) -> None:
        if self.weighting not in WEIGHTINGS:
            raise ValueError(f"weighting: must be one of {', '.join(WEIGHTINGS)}; got {self.weighting!r}")

    def fuse(self, x_iig: Array, P_iig: Array, x_ibi: Array, P_ibi: Array) -> tuple[Array, Array]:
        """States (..., n) and covariances (..., n, n) of both local filters -> (dH_IBIG, its variance)."""
        i = self.index
        return ibig_fuse(x_iig[..., i], P_iig[..., i, i], x_ibi[..., i], P_ibi[..., i, i], self.weighting)
