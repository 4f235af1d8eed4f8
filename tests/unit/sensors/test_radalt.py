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
    # h - h_agl differenced: heights <= 400 m, ~4 roundings each: floor(4, 400, 400) = 7e-13 m; 1e-9 m (and 1e-6 ft
    # on the step) are >= 1400x that
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
    ra = RadarAltimeter(rate_hz=10.0, markov_sigma_m=0.0, bias_sigma_m=0.0)  # the white part alone
    rec = ra.measure(tr, [np.random.default_rng(i) for i in range(5)])
    err = rec.h_agl_m - h_m
    sigma = math.sqrt((0.01 * h_m) ** 2 + 0.5**2)
    assert err.std() == pytest.approx(sigma, rel=0.05)
    assert abs(err.mean()) < 0.05 * sigma
    assert np.allclose(rec.sigma_m, sigma)


def test_markov_error_seed_000(runway):
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m + 50.0,
                              2000.0, 1.0, terrain_h_m=runway.threshold_h_m)
    ra = RadarAltimeter(rate_hz=1.0, floor_m=0.0, percent_sigma=0.0, markov_sigma_m=2.0, markov_tau_s=50.0,
                        bias_sigma_m=0.0)
    rec = ra.measure(tr, [np.random.default_rng(i) for i in range(100)])
    x = rec.h_agl_m - 50.0
    assert x.std() == pytest.approx(2.0, rel=0.05)
    rho = np.sum(x[:, 1:] * x[:, :-1]) / np.sum(x[:, :-1] ** 2)
    assert -1.0 / np.log(rho) == pytest.approx(50.0, rel=0.05)


def _gens(n: int, name: str = "radalt") -> list[np.random.Generator]:
    from approachsim.seeding import stream
    return [stream(20261202, i, name) for i in range(n)]


def test_default_correlated_budget_is_the_1_ft_floor_split_in_variance():
    ra = RadarAltimeter()
    assert ra.bias_sigma_m == pytest.approx(units.FT / math.sqrt(2.0))
    assert ra.markov_sigma_m == pytest.approx(units.FT / math.sqrt(2.0))
    assert math.hypot(ra.bias_sigma_m, ra.markov_sigma_m) == pytest.approx(1.0 * units.FT)
    assert ra.markov_tau_s == 10.0  # Hajiyev & Saltoglu section 7: beta = 0.1 1/s


def test_default_bias_and_markov_statistics(runway):
    """Over 2000 seeded runs of 200 s at 1 Hz: the per-run bias has its sigma (chi-square bound, 2000 values:
    relative sd of a sigma estimate 1 / sqrt(2 n) = 1.6 %, 5 sd = 8 %), the Markov part its sigma and tau."""
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m + 30.0,
                              200.0, 1.0, terrain_h_m=runway.threshold_h_m)
    ra = RadarAltimeter(rate_hz=1.0, floor_m=0.0, percent_sigma=0.0)
    e = ra.draw(tr.t_s, _gens(2000))
    b = e.constants["bias"]
    assert b.shape == (2000,)
    assert b.std() == pytest.approx(ra.bias_sigma_m, rel=0.08)
    assert abs(b.mean()) < 5 * ra.bias_sigma_m / math.sqrt(2000)
    rec = ra.apply(tr, e)
    x = rec.h_agl_m - 30.0 - b[:, None]  # the Markov part alone
    assert x.std() == pytest.approx(ra.markov_sigma_m, rel=0.05)
    rho = np.sum(x[:, 1:] * x[:, :-1]) / np.sum(x[:, :-1] ** 2)
    assert -1.0 / np.log(rho) == pytest.approx(ra.markov_tau_s, rel=0.05)
    # the bias is constant within a run: the sample-to-sample differences carry no bias
    # allclose's 1e-8 m + 1e-5 rel against floor(4, 30) = 2.7e-14 m: a constant bias cancels, far above rounding
    assert np.allclose(np.diff(rec.h_agl_m - 30.0, axis=1), np.diff(x, axis=1))


def test_correlated_parts_do_not_move_the_white_noise_draws(runway):
    """The white noise (and the Markov normals) are the same draws with and without the correlated error: the
    bias comes from a child stream, so zero keys reproduce today's altimeter bit for bit."""
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m + 60.0,
                              100.0, 1.0, terrain_h_m=runway.threshold_h_m)
    new = RadarAltimeter().draw(tr.t_s, _gens(3))
    old = RadarAltimeter(markov_sigma_m=0.0, bias_sigma_m=0.0).draw(tr.t_s, _gens(3))
    assert np.array_equal(new.series["noise"], old.series["noise"])  # bit-identical: the same draws
    assert np.all(old.series["markov"] == 0.0) and np.all(old.constants["bias"] == 0.0)
    assert np.all(new.constants["bias"] != 0.0)
    # today's draw: z = (m, 2) normals from the stream, column 1 the white noise
    z = _gens(1)[0].standard_normal((len(new), 2))
    assert np.array_equal(old.series["noise"][0], z[:, 1])
