"""Navigation error in the runway frame, and its value when the true aircraft crosses a decision height.

Error = navigation estimate - truth (the IMU point), from the ECEF difference dr = r_nav - r_true:
along and cross track by the runway rotation (design.md's runway frame, y right), vertical by the local
NED axes at the true position (up = -D), the axes of the filter's P_pos_ned. The decision-height instant
is the first time the TRUE height above the threshold descends through the DH, linearly interpolated
between the two samples that bracket it; the errors there are interpolated with the same weight.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from approachsim.memo import TruthMemo, memoized
from approachsim.records import NavSolution, Truth

Array = np.ndarray


@dataclass(frozen=True)
class RunwayErrors:
    """Per-epoch navigation error of one run (time on axis 0), m; estimate minus truth."""

    t_s: Array
    """(n,) time, s."""
    hat_m: Array
    """(n,) true height above the threshold, m."""
    along_m: Array
    """(n,) along-track error (runway x), m."""
    lateral_m: Array
    """(n,) cross-track error (runway y, right positive), m."""
    vertical_m: Array
    """(n,) vertical error (local up), m."""
    e_ned: Array
    """(n, 3) error in local NED axes at the true position, m."""


def runway_errors(truth: Truth, nav: NavSolution, memo: TruthMemo | None = None) -> RunwayErrors:
    """Per-epoch error of `nav` against `truth` (same time base; nav may be shorter if it stopped). memo: the
    truth's TruthMemo (its trigonometry and heights then made once for the runs that share it)."""
    n = min(len(truth), nav.t_s.shape[0])
    if n < 2:
        raise ValueError(f"navigation solution has {n} samples; need at least 2")
    if not np.allclose(nav.t_s[:n], truth.t_s[:n], rtol=0.0, atol=1e-6):
        raise ValueError("navigation solution and truth are not on the same time base")
    dr = nav.r_ecef[:n] - truth.r_ecef[:n]
    sl, cl, so, co, hat = memoized(memo, truth, "dh.truth_terms", n, lambda: _truth_terms(truth, n), keep=2)
    e_ned = _rotate_ned(dr, sl, cl, so, co)
    e_rwy = dr @ truth.runway.c_ecef_to_rwy.T
    return RunwayErrors(
        t_s=truth.t_s[:n], hat_m=hat, along_m=e_rwy[:, 0], lateral_m=e_rwy[:, 1], vertical_m=-e_ned[:, 2], e_ned=e_ned
    )


def _truth_terms(truth: Truth, n: int) -> tuple[Array, Array, Array, Array, Array]:
    """sin / cos of the truth's first n latitudes and longitudes and its heights above the threshold (kept in the
    truth's TruthMemo when the caller has one: the runs of a group share their truth)."""
    lat, lon = truth.lat_rad[:n], truth.lon_rad[:n]
    return np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon), truth.runway.height_above_threshold(truth.h_m[:n])


def ecef_to_ned_vectors(d_ecef: Array, lat_rad: Array, lon_rad: Array) -> Array:
    """Rotate ECEF vectors (n, 3) into the local NED axes at (lat, lon) per row (geo.c_ecef_to_ned, unrolled)."""
    return _rotate_ned(d_ecef, np.sin(lat_rad), np.cos(lat_rad), np.sin(lon_rad), np.cos(lon_rad))


def _rotate_ned(d_ecef: Array, sl: Array, cl: Array, so: Array, co: Array) -> Array:
    """ecef_to_ned_vectors with the sines and cosines of latitude (sl, cl) and longitude (so, co) given."""
    x, y, z = d_ecef[:, 0], d_ecef[:, 1], d_ecef[:, 2]
    t = co * x + so * y
    return np.stack([-sl * t + cl * z, -so * x + co * y, -cl * t - sl * z], axis=-1)


def dh_crossing(hat_m: Array, dh_m: float) -> tuple[int, float] | None:
    """First downward crossing of height `dh_m` by the series `hat_m`: (k, w) with the crossing at k + w.

    hat_m[k] >= dh_m > hat_m[k+1] and w = (hat_m[k] - dh_m) / (hat_m[k] - hat_m[k+1]) in [0, 1).
    None when the series never descends through dh_m (a run that stopped above it).
    """
    h = np.asarray(hat_m, dtype=float)
    above = h[:-1] >= dh_m
    below = h[1:] < dh_m
    idx = np.flatnonzero(above & below)
    if idx.size == 0:
        return None
    k = int(idx[0])
    w = float((h[k] - dh_m) / (h[k] - h[k + 1]))
    return k, w


def at_crossing(series: Array, crossing: tuple[int, float]) -> Array:
    """Value of `series` (time on axis 0) at the crossing k + w, linear interpolation."""
    k, w = crossing
    return (1.0 - w) * series[k] + w * series[k + 1]


def interp_on_height(hat_m: Array, values: Array, grid_m: Array) -> Array:
    """`values` against a descending-height grid `grid_m`, from the first pass of each height (nan if never).

    The descent is made monotonic by taking the running minimum of the height, so a balloon above a grid
    height does not count twice: the value is the one at the first downward crossing of each height.
    """
    h = np.asarray(hat_m, dtype=float)
    h_min = np.minimum.accumulate(h)
    # the first index at which the height falls below each grid height (where its running minimum does)
    order = -h_min  # nondecreasing
    k1 = np.searchsorted(order, -np.asarray(grid_m, dtype=float), side="right")
    out = np.full(np.shape(grid_m) + np.shape(values)[1:], np.nan)
    ok = (k1 > 0) & (k1 < h_min.shape[0])
    k1o = k1[ok]
    k0 = k1o - 1
    h0, h1 = h[k0], h[k1o]  # h[k0] >= g > h[k1]: the first downward crossing is between them
    g = np.asarray(grid_m, dtype=float)[ok]
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(h0 > h1, (h0 - g) / (h0 - h1), 0.0)
    w = w.reshape(w.shape + (1,) * (np.ndim(values) - 1))
    out[ok] = (1.0 - w) * values[k0] + w * values[k1o]
    return out
