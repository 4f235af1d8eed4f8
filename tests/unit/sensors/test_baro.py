"""Baro: ISA physics (cold temperature, QNH error), exact with noise=False, stochastic model."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from approachsim import synthetic, units
from approachsim.sensors import atmosphere
from approachsim.sensors.baro import Baro

LAT, LON = math.radians(37.6117), math.radians(-122.3581)


def test_standard_day_reads_geopotential_height_exactly():
    tr = synthetic.stationary(LAT, LON, 1000.0, 2.0, 10.0)
    rec = Baro().measure(tr, np.random.default_rng(0), noise=False)
    # the ISA pressure and its inverse, ~16 roundings of T0 / L = 44.3 km: floor(16, 44330) = 1.6e-10 m; 1e-6 m (here
    # and below) is 6e3x that
    assert rec.h_baro_m == pytest.approx(atmosphere.geopotential_m(1000.0), abs=1e-6)
    # geopotential vs geometric: 0.157 m at 1000 m (r0 z^2 / (r0 + z)^2)
    assert 1000.0 - rec.h_baro_m[0] == pytest.approx(0.157, abs=0.001)


def test_descent_noise_false_tracks_truth(descent):
    rec = Baro(rate_hz=1.0).measure(descent, np.random.default_rng(0), noise=False)
    rows = np.arange(0, len(descent), 20)
    assert np.allclose(rec.h_baro_m, atmosphere.geopotential_m(descent.h_m[rows]), atol=1e-6)


def test_isa_minus_15_cold_error_matches_the_pans_ops_rule():
    """Cold is low: at ISA -15 C the altimeter over-reads by dT/(T0+dT) = 5.5 % of the true height above the
    (sea-level) setting source; the PANS-OPS rule (4 % per 10 C below ISA -> 6 %) is within 10 % of it."""
    h_true = 300.0  # geopotential height above the sea-level setting source, m
    z = h_true * atmosphere.R_EARTH_GEOPOT_M / (atmosphere.R_EARTH_GEOPOT_M - h_true)  # geometric for that H
    tr = synthetic.stationary(LAT, LON, z, 1.0, 10.0, isa_dev_k=-15.0)
    rec = Baro().measure(tr, np.random.default_rng(0), noise=False)
    err_frac = (rec.h_baro_m[0] - h_true) / h_true
    # the exact ISA+dT result; a difference of two ~1000 m heights over 1000 m: floor(16, 44330) / 1000 / 0.055 =
    # 2.9e-12 relative; rel 1e-9 is 350x that
    assert err_frac == pytest.approx(15.0 / (288.15 - 15.0), rel=1e-9)
    rule = 0.04 * 15.0 / 10.0
    assert err_frac == pytest.approx(rule, rel=0.10)


def test_one_hpa_qnh_error_gives_27_to_30_ft_at_sea_level():
    tr = synthetic.stationary(LAT, LON, 0.0, 1.0, 10.0, sea_level_pa=1013.25 * units.HPA)
    right = Baro(setting_pa=1013.25 * units.HPA).measure(tr, np.random.default_rng(0), noise=False)
    wrong = Baro(setting_pa=1014.25 * units.HPA).measure(tr, np.random.default_rng(0), noise=False)
    dh_ft = (wrong.h_baro_m[0] - right.h_baro_m[0]) / units.FT
    assert 27.0 <= dh_ft <= 30.0
    assert dh_ft == pytest.approx(27.3, abs=0.1)  # R T / (g p) at ISA MSL (standards.md 4.1)


def test_bias_scale_factor_noise_statistics():
    b = Baro(rate_hz=2.0, bias_sigma_m=1.0, bias_tau_s=100.0, scale_factor_sigma=0.002, noise_sigma_m=0.5)
    tr = synthetic.stationary(LAT, LON, 500.0, 2000.0, 2.0)
    runs = [np.random.default_rng(i) for i in range(200)]
    e = b.draw(tr.t_s, runs)
    assert e.series["bias"].std() == pytest.approx(1.0, rel=0.05)
    x = e.series["bias"]  # zero-mean process: no per-run mean removal (it biases rho for 20-tau records)
    rho = np.sum(x[:, 1:] * x[:, :-1]) / np.sum(x[:, :-1] ** 2)
    assert -0.5 / np.log(rho) == pytest.approx(100.0, rel=0.05)
    assert e.constants["scale_factor"].std() == pytest.approx(0.002, rel=0.15)  # 200 values
    rec = b.apply(tr, e)
    exact = b.measure(tr, np.random.default_rng(0), noise=False).h_baro_m
    err = rec.h_baro_m - exact
    expect = e.constants["scale_factor"][:, None] * exact + e.series["bias"] + e.series["noise"]
    assert np.allclose(err, expect, atol=1e-9)  # heights <= 1000 m, ~8 roundings: floor(8, 1000) = 1.8e-12 m; 550x


@settings(derandomize=True, max_examples=200, deadline=None)
@given(h=st.floats(-400.0, 11000.0), dt_k=st.floats(-40.0, 30.0), p_sl=st.floats(95000.0, 105000.0))
def test_indicated_altitude_inverts_the_atmosphere_when_set_to_its_sea_level_pressure(h, dt_k, p_sl):
    """Round trip: on a standard-temperature day with the right QNH the indication is H exactly; with a
    temperature deviation it is H T0 / (T0 + dT) (the module docstring's closed form)."""
    p = atmosphere.static_pressure_pa(h, dt_k, p_sl)
    ind = atmosphere.indicated_altitude_m(p, p_sl)
    assert ind == pytest.approx(h * atmosphere.T0_K / (atmosphere.T0_K + dt_k), abs=1e-6)


def test_first_order_lag_reads_high_by_rate_times_lag_and_is_stateless(descent):
    lag = 1.5
    b = Baro(rate_hz=10.0, lag_s=lag)
    rec = b.measure(descent, np.random.default_rng(0), noise=False)
    plain = Baro(rate_hz=10.0).measure(descent, np.random.default_rng(0), noise=False)
    # the sink rate at each sample: down the straight glide path cone it grows by V D / R (3.7 -> 3.9 m/s over 10 nmi);
    # the lag of a ramp whose slope changes at v' = V^2 / R reads v lag - v' lag^2, 3e-4 of v lag
    v_down = np.interp(rec.t_s, descent.t_s, descent.v_ned[:, 2])
    settled = rec.t_s > 10 * lag
    # geopotential rate
    assert np.allclose(rec.h_baro_m[settled] - plain.h_baro_m[settled], v_down[settled] * lag, rtol=2e-3)
    # starts in steady state: sum_l w_l h over 301 taps of h ~ 990 m against h: floor(301, 990) = 6.6e-11 m;
    # 1e-9 m is 15x that
    assert rec.h_baro_m[0] == pytest.approx(plain.h_baro_m[0], abs=1e-9)
    e = b.draw(descent.t_s, np.random.default_rng(4))
    batch = b.apply(descent, e)
    for j in (0, 3, 500):  # bit-identical: same code path (the kernel on a one-sample slice)
        assert b.apply(descent, e.take(slice(j, j + 1))).h_baro_m[0] == batch.h_baro_m[j]
