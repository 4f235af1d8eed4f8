"""The one sign convention of the navigation error (docs/contract.md, "Signs: navigation error and NSE"): the
evaluator's error e = estimate - truth and the PBN split TSE = FTE + NSE of nav/closed_loop.approach_errors,
so NSE = -e in path terms, and the evaluator's FTE = TSE + e is the same identity."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from approachsim import geo, synthetic
from approachsim.nav.closed_loop import approach_errors
from approachsim.profile import load_profile

PROFILE = load_profile(Path(__file__).resolve().parents[3] / "profiles" / "default.toml")


def test_nse_is_minus_the_navigation_error_in_path_terms():
    rw = PROFILE.runway
    truth = synthetic.glidepath_descent(rw.frame, rate_hz=10.0, start_distance_m=3000.0, ground_speed_mps=70.0,
                                        glidepath_rad=rw.glidepath_rad, tch_m=rw.tch_m)
    rng = np.random.default_rng(4)
    e = rng.normal(0.0, [30.0, 5.0, 2.0], size=(len(truth.t_s), 3))  # along, lateral, up error of the estimate, m
    estimate = truth.r_rwy + e  # what guidance flew on
    err = approach_errors(truth, estimate, rw)
    tan_gp = math.tan(rw.glidepath_rad)
    e_path = np.stack([e[:, 1], e[:, 2] + e[:, 0] * tan_gp], axis=1)  # e in path terms: e_d = e_up + e_x tan(gp)
    # runway-frame numbers of <= 3000 m: floor 8 eps 3000 = 5e-12 m, so 1e-9 m holds on any CPU (and 1e-12 for the
    # identity TSE = FTE + NSE, sums of path deviations of tens of m)
    np.testing.assert_allclose(err.nse_m, -e_path, atol=1e-9)
    np.testing.assert_allclose(err.tse_m, err.fte_m + err.nse_m, atol=1e-12)
    # the evaluator's identity FTE = TSE + e (evaluate/score.py) on the same numbers
    np.testing.assert_allclose(err.fte_m, err.tse_m + e_path, atol=1e-9)
    # and TSE is the truth's own deviation record
    np.testing.assert_allclose(err.tse_m[:, 1], geo.glidepath_deviation_m(truth.r_rwy[:, 0], truth.r_rwy[:, 2],
                                                                          rw.tch_m, tan_gp), atol=0)
