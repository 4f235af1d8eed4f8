"""The one sign convention of the navigation error (docs/contract.md, "Signs: navigation error and NSE"): the
evaluator's error e = estimate - truth and the PBN split TSE = FTE + NSE of loop/closed_loop.approach_errors
against the straight glide path cone, so NSE = -e in path terms (to the cone's first order), and the evaluator's
FTE = TSE + e is the same identity."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from approachsim import synthetic
from approachsim.loop.errors import approach_errors
from approachsim.profile import load_profile

PROFILE = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")


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
    # The desired path is the straight ILS cone (approachsim/glidepath.py): its height slope is -tan(gp) only to
    # first order. Away from it by the Earth's curvature under the cone (the drop's slope, D / R at D m from the
    # GPI) and the cone's lateral term (tan(gp) y / r at r m), the linear path-terms map e_up + e_x tan(gp) is off
    # by at most that slope times the error, plus the second-order e^2 / (2 R) (bound below, 2x for the neglected
    # terms). Lateral: exact (runway-frame numbers of <= 3000 m: floor 8 eps 3000 = 5e-12 m, 1e-9 m holds).
    gp = rw.glidepath
    x, y = truth.r_rwy[:, 0], truth.r_rwy[:, 1]
    dist = np.hypot(gp.gpi_m - x, y)
    r_n = 6.3e6  # the smaller Earth radius of curvature (meridian, at the equator)
    bound = 2.0 * ((dist / r_n) * (np.abs(e[:, 0]) + np.abs(e[:, 1]))
                   + tan_gp * (np.abs(y) + np.abs(e[:, 1])) * np.abs(e[:, 1]) / np.maximum(dist, 100.0)
                   + (e[:, 0] ** 2 + e[:, 1] ** 2) / r_n)
    np.testing.assert_allclose(err.nse_m[:, 0], -e_path[:, 0], atol=1e-9)
    off = np.abs(err.nse_m[:, 1] + e_path[:, 1])
    assert np.all(off <= bound), np.max(off / bound)
    assert np.max(off) > 1e-3  # the cone is not the tangent-plane line
    # the sign itself: NSE = d(truth) - d(estimate), each the cone deviation
    np.testing.assert_allclose(err.nse_m[:, 1], gp.deviation_rwy_m(truth.r_rwy) - gp.deviation_rwy_m(estimate),
                               atol=1e-9)
    np.testing.assert_allclose(err.tse_m, err.fte_m + err.nse_m, atol=1e-12)  # sums of tens of m: floor 1e-14
    # the evaluator's identity FTE = TSE + e (evaluate/score.py) holds to the same first order
    assert np.all(np.abs(err.fte_m[:, 1] - (err.tse_m[:, 1] + e_path[:, 1])) <= bound + 1e-9)
    # and TSE is the truth's deviation from the cone
    np.testing.assert_allclose(err.tse_m[:, 1], gp.deviation_rwy_m(truth.r_rwy), atol=0)
