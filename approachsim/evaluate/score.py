"""Score one run: the per-run scalars and small fixed-size arrays a campaign stores for every run.

Scalars (SI, names carry the unit): for each category key (cat1, cat2, cat3) at its decision height the
along / lateral / vertical navigation error, VPL / HPL, the time of the crossing, and (always computed;
meaningful in closed loop) flight technical and total system error; Stanford counts (vertical and
horizontal) and availability over the approach down to that height; Gray & Maybeck's time-averaged squared
errors (ft^2) from evaluation.timeavg_settle_s on. Arrays: lateral / vertical error and VPL / HPL on a
fixed height grid (HEIGHT_GRID_FT), for the error-against-height figures. Series (kept for a few runs):
decimated per-epoch errors.

TSE, FTE, NSE (ICAO PBN, without path definition error): TSE = true deviation from the desired path
(truth loc_dev_m / gs_dev_m); e = estimate - truth (the navigation error; PBN's NSE is -e in path terms,
docs/contract.md "Signs"); FTE = the deviation guidance flew on. When the flight gives what guidance flew on
(fte_lat_m / fte_vert_m series) that is used; otherwise FTE = TSE + e in path terms (vertical: the
glidepath-deviation error gpdev = e_vertical + e_along tan(gamma), as guidance would see it).

Reference point (docs/contract.md): every error is the IMU point's, and the decision-height instant is the
true IMU height's crossing. Glidepath-deviation error: the deviation from the glidepath is
d = h - (TCH - x tan(gamma)) (runway-frame x, negative before the threshold), so its navigation error is
e_d = e_vertical + e_along tan(gamma): the along-track error couples in through tan(gamma). tan(gamma) is
taken from the truth's own deviation record (the slope of h - gs_dev against x, exact for a straight
glidepath), so scoring needs no profile.
"""

from __future__ import annotations

import math

import numpy as np

from approachsim import units
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.dh import at_crossing, dh_crossing, interp_on_height, runway_errors
from approachsim.evaluate.integrity import availability, integrity_series, stanford_regions
from approachsim.evaluate.limits import CATEGORIES, LIMITS
from approachsim.evaluate.timeavg import mean_square_ft2, state_errors_m
from approachsim.memo import TruthMemo, memoized
from approachsim.records import NavSolution, Truth

CATEGORY_KEYS = {"CAT I": "cat1", "CAT II": "cat2", "CAT III": "cat3"}
"""Column prefix of each category."""

HEIGHT_GRID_FT = np.arange(2000.0, -1.0, -20.0)
"""Heights above the threshold at which per-run error profiles are stored, ft (descending)."""

SERIES_HZ = 10.0
"""Rate of the time series kept for a subset of runs, Hz."""


class RunScoreError(ValueError):
    """A run cannot be scored (it never reached a decision height, or its solution diverged)."""


def glidepath_tan(truth: Truth, hat_m: np.ndarray) -> float:
    """tan(glidepath angle) from the truth: minus the least-squares slope of (h - gs_dev) against runway x.

    Fitted below 1000 ft above the threshold (where the decision heights are) when 10 samples are there.
    """
    n = hat_m.shape[0]
    x = truth.runway.from_ecef(truth.r_ecef[:n])[:, 0]
    y = hat_m - truth.gs_dev_m[:n]
    low = hat_m < 1000.0 * units.FT
    if np.count_nonzero(low) >= 10:
        x, y = x[low], y[low]
    return float(-np.polyfit(x, y, 1)[0])


def score_run(
    truth: Truth,
    nav: NavSolution,
    cfg: EvaluationConfig,
    *,
    clock_bias_true_m: np.ndarray | None = None,
    keep_series: bool = False,
    fte_lat_m: np.ndarray | None = None,
    fte_vert_m: np.ndarray | None = None,
    memo: TruthMemo | None = None,
) -> tuple[dict[str, float], dict[str, np.ndarray], dict[str, np.ndarray] | None]:
    """(scalars, arrays, series or None) of one run; RunScoreError when it cannot be scored. memo: the truth's
    TruthMemo (approachsim/memo.py), which the runs of an open-loop group share: the truth's trigonometry and
    glidepath slope are then made once."""
    err = runway_errors(truth, nav, memo)
    integ = integrity_series(err.e_ned, nav.P_pos_ned, cfg.k_v, cfg.k_h)
    n = err.t_s.shape[0]
    # hat_m is the truth's own first n heights above the threshold: the slope is a function of (truth, n)
    tan_gp = memoized(memo, truth, "score.glidepath_tan", n, lambda: glidepath_tan(truth, err.hat_m), keep=2)
    scalars: dict[str, float] = {}
    for cat in CATEGORIES:
        key = CATEGORY_KEYS[cat]
        dh_m = cfg.dh_m(cat)
        cr = dh_crossing(err.hat_m, dh_m)
        if cr is None:
            raise RunScoreError(
                f"the true aircraft never descended through the {cat} decision height ({cfg.dh_ft[cat]:g} ft)"
            )
        vals = {
            "t_s": at_crossing(err.t_s, cr),
            "along_m": at_crossing(err.along_m, cr),
            "lateral_m": at_crossing(err.lateral_m, cr),
            "vertical_m": at_crossing(err.vertical_m, cr),
            # the filter's own vertical 1-sigma there (issue 39: e / sigma at each DH)
            "vertical_sigma_m": at_crossing(np.sqrt(np.maximum(nav.P_pos_ned[:n, 2, 2], 0.0)), cr),
            "vpl_m": at_crossing(integ.vpl_m, cr),
            "hpl_m": at_crossing(integ.hpl_m, cr),
            "tse_lat_m": at_crossing(truth.loc_dev_m[:n], cr),
            "tse_vert_m": at_crossing(truth.gs_dev_m[:n], cr),
        }
        if not (np.isfinite(vals["lateral_m"]) and np.isfinite(vals["vertical_m"])):
            raise RunScoreError(f"navigation solution is not finite at the {cat} decision height (diverged)")
        vals["gpdev_m"] = vals["vertical_m"] + vals["along_m"] * tan_gp
        sig = vals["vertical_sigma_m"]
        vals["vertical_e_sigma"] = vals["vertical_m"] / sig if sig > 0.0 else math.nan
        vals["fte_lat_m"] = (
            vals["tse_lat_m"] + vals["lateral_m"] if fte_lat_m is None else at_crossing(fte_lat_m[:n], cr)
        )
        vals["fte_vert_m"] = (
            vals["tse_vert_m"] + vals["gpdev_m"] if fte_vert_m is None else at_crossing(fte_vert_m[:n], cr)
        )
        for k, v in vals.items():
            scalars[f"{key}_{k}"] = float(v)
        # integrity over the approach down to this decision height
        win = slice(0, cr[0] + 1)
        lim = LIMITS[cat]
        for axis, pe, pl, al in (
            ("v", integ.vpe_m[win], integ.vpl_m[win], lim.vertical_al_m),
            ("h", integ.hpe_m[win], integ.hpl_m[win], lim.horizontal_al_m),
        ):
            for region, count in stanford_regions(pe, pl, al).items():
                scalars[f"{key}_{axis}_{region}"] = float(count)
        avail = availability(integ.vpl_m[win], integ.hpl_m[win], lim.vertical_al_m, lim.horizontal_al_m)
        scalars[f"{key}_availability"] = float(np.mean(avail))
    settled = err.t_s >= err.t_s[0] + cfg.timeavg_settle_s
    if not settled.any():
        raise RunScoreError(f"run shorter than evaluation.timeavg_settle_s ({cfg.timeavg_settle_s:g} s)")
    ta = mean_square_ft2(state_errors_m(truth, nav, clock_bias_true_m, e_ned=err.e_ned), settled)
    for state, ms in ta.items():
        scalars[f"ta_{state}_ft2"] = ms
    grid_m = HEIGHT_GRID_FT * units.FT
    arrays = {
        "lateral_m": interp_on_height(err.hat_m, err.lateral_m, grid_m),
        "vertical_m": interp_on_height(err.hat_m, err.vertical_m, grid_m),
        "vpl_m": interp_on_height(err.hat_m, integ.vpl_m, grid_m),
        "hpl_m": interp_on_height(err.hat_m, integ.hpl_m, grid_m),
    }
    series = None
    if keep_series:
        dt = float(np.median(np.diff(err.t_s)))
        step = max(1, int(round(1.0 / (SERIES_HZ * dt))))
        sl = slice(0, n, step)
        series = {
            "t_s": err.t_s[sl],
            "hat_m": err.hat_m[sl],
            "along_m": err.along_m[sl],
            "lateral_m": err.lateral_m[sl],
            "vertical_m": err.vertical_m[sl],
            "vpl_m": integ.vpl_m[sl],
            "hpl_m": integ.hpl_m[sl],
            "hpe_m": integ.hpe_m[sl],
            "loc_dev_m": truth.loc_dev_m[:n][sl],
            "gs_dev_m": truth.gs_dev_m[:n][sl],
        }
    return scalars, arrays, series
