"""Radar altimeter: exact height above terrain, validity (range, attitude), terrain step, seed 002 noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim import synthetic, units
from approachsim.sensors.radalt import RadarAltimeter


def test_noise_false_reads_height_above_terrain_and_is_invalid_above_range(descent):
    ra = RadarAltimeter(rate_hz=1.0, max_range_m=2500 * units.FT)
    rec = ra.measure(descent, np.random.default_rng(0), noise=False)
    h = descent.h_agl_m[::20]
    inside = h <= 2500 * units.FT
    assert inside.any() and (~inside).any()
    assert np.array_equal(rec.valid, inside)
    assert np.all(np.isnan(rec.h_agl_m[~inside]))
    assert np.array_equal(rec.h_agl_m[inside], h[inside])


def test_reads_a_100_ft_terrain_step(runway):
    """Terrain 100 ft higher before x = -3000 m: the reading jumps by 100 ft where the aircraft crosses it."""
    step_ft = 100.0
    elev = runway.threshold_h_m
    tr = synthetic.glidepath_descent(
        runway, rate_hz=10.0, start_distance_m=6000.0, ground_speed_mps=70.0,
        terrain_h_m=np.array([elev + step_ft * units.FT, elev + step_ft * units.FT, elev, elev]),
        terrain_along_m=np.array([-1e5, -3000.0 - 1e-3, -3000.0, 1e3]),
    )
    rec = RadarAltimeter(rate_hz=10.0).measure(tr, np.random.default_rng(0), noise=False)
    height_above_ellipsoid = tr.h_m
    jump = np.diff(height_above_ellipsoid - rec.h_agl_m)  # = terrain height under the aircraft, differenced
    k = int(np.argmax(np.abs(jump)))
    assert -jump[k] / units.FT == pytest.approx(step_ft, abs=1e-6)
    assert tr.r_rwy[k, 0] < -3000.0 <= tr.r_rwy[k + 1, 0]
    assert np.max(np.abs(np.delete(jump, k))) < 1e-9


@pytest.mark.parametrize(("pitch_deg", "roll_deg", "ok"), [(29.0, 0.0, True), (31.0, 0.0, False),
                                                          (0.0, 44.0, True), (0.0, -46.0, False)])
def test_attitude_limits(runway, pitch_deg, roll_deg, ok):
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m + 100.0,
                              2.0, 10.0, euler_rad=(math.radians(roll_deg), math.radians(pitch_deg), 0.0),
                              terrain_h_m=runway.threshold_h_m)
    rec = RadarAltimeter(rate_hz=10.0).measure(tr, np.random.default_rng(0))
    assert np.all(rec.valid == ok)


@pytest.mark.parametrize("h_m", [5.0, 300.0])
def test_noise_is_seed_002_sigma(runway, h_m):
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m + h_m,
                              1000.0, 10.0, terrain_h_m=runway.threshold_h_m)
    ra = RadarAltimeter(rate_hz=10.0)
    rec = ra.measure(tr, [np.random.default_rng(i) for i in range(5)])
    err = rec.h_agl_m - h_m
    sigma = math.sqrt((0.01 * h_m) ** 2 + 0.5**2)
    assert err.std() == pytest.approx(sigma, rel=0.05)
    assert abs(err.mean()) < 0.05 * sigma
    assert np.allclose(rec.sigma_m, sigma)


def test_markov_error_seed_000(runway):
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m + 50.0,
                              2000.0, 1.0, terrain_h_m=runway.threshold_h_m)
    ra = RadarAltimeter(rate_hz=1.0, floor_m=0.0, percent_sigma=0.0, markov_sigma_m=2.0, markov_tau_s=50.0)
    rec = ra.measure(tr, [np.random.default_rng(i) for i in range(100)])
    x = rec.h_agl_m - 50.0
    assert x.std() == pytest.approx(2.0, rel=0.05)
    rho = np.sum(x[:, 1:] * x[:, :-1]) / np.sum(x[:, :-1] ** 2)
    assert -1.0 / np.log(rho) == pytest.approx(50.0, rel=0.05)
