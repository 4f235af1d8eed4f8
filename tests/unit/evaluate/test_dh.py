"""Decision-height crossing and runway-frame errors on straight-line synthetic flights."""

from __future__ import annotations

import math

import numpy as np
import pytest
from evalpairs import RWY, cross_axis_ned, make_nav, make_truth

from approachsim import units
from approachsim.evaluate.dh import at_crossing, dh_crossing, ecef_to_ned_vectors, interp_on_height, runway_errors
from approachsim.memo import TruthMemo


def test_crossing_exact_on_a_straight_line():
    hz, hat0, sink = 7.0, 700.0, 3.3
    t = np.arange(0.0, 250.0, 1.0 / hz)
    hat = hat0 - sink * t
    for dh_ft in (200.0, 100.0, 50.0, 137.3):
        dh = dh_ft * units.FT
        cr = dh_crossing(hat, dh)
        assert cr is not None
        t_star = (hat0 - dh) / sink
        # w = (h_k - dh) / (h_k - h_k+1) divides a difference of 700 m heights by 0.47 m: relative floor(4, 700) /
        # 0.47 = 1.3e-12, times the 0.14 s step, plus floor(4, 250 s): 2.4e-13 s; 1e-9 s is 4000x that
        assert at_crossing(t, cr) == pytest.approx(t_star, abs=1e-9)
        # an error linear in time is interpolated exactly: w's floor times the 1.9e-3 step of err, plus floor(4, 1.7):
        # 4e-15; 1e-12 is 250x that
        err = 1.7 - 0.013 * t
        assert at_crossing(err, cr) == pytest.approx(1.7 - 0.013 * t_star, abs=1e-12)
        assert at_crossing(hat, cr) == pytest.approx(dh, abs=1e-9)  # floor(4, 700) = 6e-13 m; 1600x


def test_first_downward_crossing_and_none():
    hat = np.array([100.0, 80.0, 55.0, 70.0, 45.0, 30.0])
    k, w = dh_crossing(hat, 60.0)
    assert (k, w) == (1, pytest.approx(20.0 / 25.0))
    assert dh_crossing(hat, 20.0) is None  # never got that low
    assert dh_crossing(np.array([10.0, 20.0, 30.0]), 15.0) is None  # climbing through is not a crossing


def test_interp_on_height_uses_first_pass_and_is_exact_on_a_line():
    t = np.arange(0.0, 130.0, 0.5)
    hat = 300.0 - 2.5 * t
    grid = np.array([250.0, 100.0, 12.25, -50.0, 400.0])
    out = interp_on_height(hat, 5.0 + 0.1 * t, grid)
    expect = 5.0 + 0.1 * (300.0 - grid[:3]) / 2.5
    # weights from 300 m heights 1.25 m apart (relative floor(4, 300) / 1.25 = 2e-13) times the 0.05 step of the
    # values, plus floor(4, 18): 2.6e-14; 1e-12 is 40x that
    np.testing.assert_allclose(out[:3], expect, rtol=0, atol=1e-12)
    assert np.isnan(out[3])  # below the lowest point flown
    assert np.isnan(out[4])  # above the start: never descended through it
    # a balloon back above 100 m after passing it does not move the 100 m value
    hat2 = np.array([120.0, 90.0, 110.0, 80.0])
    v2 = np.array([0.0, 3.0, 10.0, 20.0])
    assert interp_on_height(hat2, v2, np.array([100.0]))[0] == pytest.approx(2.0)


def test_runway_errors_map_ned_error_to_lateral_and_vertical():
    truth = make_truth(hz=2.0)
    e = 3.0 * cross_axis_ned() + np.array([0.0, 0.0, -2.0])  # 3 m right of track, 2 m high
    err = runway_errors(truth, make_nav(truth, e))
    # the runway axes are those of the threshold; at <= 4 km the local vertical tilts by < 7e-4 rad
    np.testing.assert_allclose(err.lateral_m, 3.0, atol=3e-3)
    np.testing.assert_allclose(err.vertical_m, 2.0, atol=3e-3)
    np.testing.assert_allclose(err.along_m, 0.0, atol=3e-3)
    np.testing.assert_allclose(err.hat_m, truth.h_m - RWY.threshold_h_m)  # rtol 1e-7: far above floor(2, |h|)


def test_along_track_error_is_not_lateral():
    truth = make_truth(hz=2.0)
    along = np.array([math.cos(RWY.heading_rad), math.sin(RWY.heading_rad), 0.0])
    err = runway_errors(truth, make_nav(truth, 10.0 * along))
    # local north turns by the meridian convergence (<= 1.5e-3 rad 13 km out) against the threshold's axes
    np.testing.assert_allclose(err.along_m, 10.0, atol=1e-3)
    np.testing.assert_allclose(err.lateral_m, 0.0, atol=1.5e-2)
    assert abs(err.lateral_m[-1]) < 1e-3  # near the threshold the axes agree


def test_time_base_mismatch_is_rejected():
    truth = make_truth(hz=2.0)
    nav = make_nav(truth, np.zeros(3))
    bad = type(nav)(**{**nav.__dict__, "t_s": nav.t_s + 0.25})
    with pytest.raises(ValueError, match="time base"):
        runway_errors(truth, bad)


def test_runway_errors_of_alternating_truths_equal_the_direct_rotation():
    # with a memo (approachsim/memo.py: the runs of a group share their truth's trigonometry and heights) each truth
    # has its own: a second truth of the same length, then the first again, must each get their own, bit for bit,
    # and the same as without a memo; a memo is never used for another truth
    a, b = make_truth(hz=2.0, dur_s=150.0), make_truth(hz=2.0, hat0_m=650.0, dur_s=150.0, loc_dev_m=40.0)
    assert len(a) == len(b)
    memos = {id(a): TruthMemo(a), id(b): TruthMemo(b)}
    e = 3.0 * cross_axis_ned() + np.array([0.0, 0.0, -2.0])
    for truth in (a, b, a):
        nav = make_nav(truth, e)
        err = runway_errors(truth, nav, memos[id(truth)])
        dr = nav.r_ecef - truth.r_ecef
        np.testing.assert_array_equal(err.e_ned, ecef_to_ned_vectors(dr, truth.lat_rad, truth.lon_rad))
        np.testing.assert_array_equal(err.hat_m, truth.runway.height_above_threshold(truth.h_m))
        np.testing.assert_array_equal(err.e_ned, runway_errors(truth, nav).e_ned)
    assert len(memos[id(a)]) == 1
    with pytest.raises(ValueError, match="another truth"):
        runway_errors(b, make_nav(b, e), memos[id(a)])
