"""The flight technical / navigation system / total system error split of a flown approach (RNP convention)."""

from __future__ import annotations

from typing import Any

import numpy as np

from approachsim.glidepath import GlidePath
from approachsim.records import ApproachErrors, Truth

Array = np.ndarray


def path_deviation(r_rwy: Array, runway: Any) -> Array:
    """Deviation (..., 2) of runway-frame points from the desired path: (cross-track y, height above the straight
    ILS glide path cone, approachsim.glidepath: the one geometric reference the flight and the campaign's FTE use),
    m."""
    r = np.asarray(r_rwy, dtype=float)
    return np.stack([r[..., 1], GlidePath.of(runway).deviation_rwy_m(r)], axis=-1)


def approach_errors(truth: Truth, guidance_r_rwy: Array, runway: Any) -> ApproachErrors:
    """FTE, NSE and TSE (lateral, vertical) of a flown approach (RNP convention, records.ApproachErrors).

    FTE = deviation of the position guidance flew on from the desired path; TSE = deviation of the true
    position; NSE = TSE - FTE = d(true) - d(estimate): the navigation error seen in path terms, so that
    TSE = FTE + NSE (the along-track error enters NSE through the glidepath slope).
    """
    fte = path_deviation(guidance_r_rwy, runway)
    tse = path_deviation(truth.r_rwy, runway)
    return ApproachErrors(t_s=np.asarray(truth.t_s, dtype=float), fte_m=fte, nse_m=tse - fte, tse_m=tse)
