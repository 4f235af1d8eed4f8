"""sensors/states.py: a run's drawn errors mapped to the filter's sensor states reproduce the realized measurement
errors at the start row (pseudorange error = gse + gmp + clk + noise, baro error = bb + sb h + noise, IMU
increment error = b dt with zero noise, pseudolite error = ptr range + pmp + pclk + clk + noise)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from approachsim import synthetic
from approachsim.profile import load_profile
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.imu import true_increments
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite, SuiteErrors

PROFILE = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")


def _setup(row: int = 0):
    cfg = replace(PROFILE.sensors, baro=replace(PROFILE.sensors.baro, scale_factor_sigma=1e-3),
                  pseudolite=PseudoliteConfig(synchronized=False, positions_rwy=((0.0, -150.0, 10.0),
                                                                                 (300.0, 150.0, 10.0))))
    suite = SensorSuite.from_config(cfg, PROFILE.runway.frame, PROFILE.environment.setting_pa)
    truth = synthetic.glidepath_descent(PROFILE.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 20.0,
                                        ground_speed_mps=70.0)
    errors = suite.draw(truth.t_s, 4, [0, 1, 2])
    # zero-noise IMU: only the biases and the scale factor / misalignment remain in the increments
    imu = errors.sensors["imu"]
    imu = replace(imu, series={**imu.series, "gyro_noise": 0.0 * imu.series["gyro_noise"],
                               "accel_noise": 0.0 * imu.series["accel_noise"]})
    errors = SuiteErrors({**errors.sensors, "imu": imu}, errors.clock)
    zero = SuiteErrors({k: v.zeroed() for k, v in errors.sensors.items()}, errors.clock.zeroed())
    return suite, truth, errors, suite.apply(truth, errors), suite.apply(truth, zero), start_states(suite, truth,
                                                                                                    errors, row)


def test_mapped_states_reproduce_the_realized_measurement_errors():
    suite, truth, errors, rec, exact, st = _setup()
    assert st.runs == 3
    g, ge = rec["gnss"], errors.sensors["gnss"]
    ok = g.valid[:, 0]
    assert ok.sum() >= 12  # four channels in each of the three runs
    pr_err = g.pseudorange_m[:, 0] - exact["gnss"].pseudorange_m[:, 0]  # exact: geometric range, zero clock
    model = st.gse + st.gmp + st.clk[:, :1] + ge.series["noise"][:, 0]
    # a difference of two 2e7 m pseudoranges: floor(4, 2.7e7, 2.7e7) = 4.8e-8 m; 1e-6 m is 20x that
    np.testing.assert_allclose(pr_err[ok], model[ok], atol=1e-6)
    # the clock state is the receiver clock of the record (bias, m) and its drift (m/s): the same draws read two
    # ways, ~4 roundings of a bias <= 1e4 m (floor(4, 1e4) = 8.9e-12 m) and of a drift <= 10 m/s (8.9e-15 m/s):
    # 1e-9 and 1e-12 are ~100x those
    np.testing.assert_allclose(st.clk[:, 0], g.clock_bias_m[:, 0], atol=1e-9)
    np.testing.assert_allclose(st.clk[:, 1], g.clock_drift_mps[:, 0], atol=1e-12)
    # baro: the filter's row h_B - h = bb + sb (h - H_ref) + v at the true height h of the sample's row, H_ref the
    # field (sensors/states.py _baro: the day's deterministic error split into bb and sb)
    b = errors.sensors["baro"]
    h = truth.h_m[b.rows[0]]
    h_f = suite.sensors["baro"].field_m
    # heights ~ 100 m from the ISA inverse (~8 roundings of T0 / L = 44.3 km: floor(8, 44330) = 7.9e-11 m); 1e-9 m
    # is 13x that
    np.testing.assert_allclose(rec["baro"].h_baro_m[:, 0] - h, st.bb + st.sb * (h - h_f) + b.series["noise"][:, 0],
                               atol=1e-9)
    # on this standard day the split holds the drawn errors: the noise-free error at the field is 0 (QNH reads the
    # field elevation, 1e-9 m as above), so bb is the drawn slow bias, and sb the drawn S up to the geopotential
    # scale 2 z / r0 (< 1e-4 here)
    np.testing.assert_allclose(st.bb, b.series["bias"][:, 0], atol=1e-9)
    np.testing.assert_allclose(st.sb, b.constants["scale_factor"], atol=1e-4)
    assert np.all(np.abs(st.sb) > 0.0)
    # IMU, zero noise: the first increment's error is the body-axis bias the filter's bg / ba states mean
    dth_t, dv_t, dt = true_increments(truth, np.array([1]))
    # increment minus the true increment, over dt: floor(8, |w| ~ 1e-4 rad/s) = 1.8e-19 rad/s and floor(8, |f| ~ 9.8
    # m/s^2) = 1.7e-14 m/s^2 (the increments' ~8 roundings, kernel imu.py); atol 1e-15 and 1e-12 are >= 60x those
    np.testing.assert_allclose((rec["imu"].dtheta_body[:, 0] - dth_t[0]) / dt, st.bg, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose((rec["imu"].dv_body[:, 0] - dv_t[0]) / dt, st.ba, rtol=1e-9, atol=1e-12)
    # pseudolites: rho - |r_pl,true - r| - clk - noise = T |r_pl,true - r| + m + b_PL
    p, pe = rec["pseudolite"], errors.sensors["pseudolite"]
    r = truth.r_ecef[0]
    true_pl = suite.sensors["pseudolite"].r_published_ecef[None] + pe.constants["survey"]
    rng = np.linalg.norm(true_pl - r, axis=-1)
    lhs = p.pseudorange_m[:, 0] - rng - st.clk[:, :1] - pe.series["noise"][:, 0]
    # ranges from 6.4e6 m ECEF positions: floor(4, 6.4e6, 6.4e6) = 1.1e-8 m; 1e-6 m is 90x that
    np.testing.assert_allclose(lhs, st.ptr * rng + st.pmp + st.pclk[:, 0::2], atol=1e-6)
    assert np.all(np.abs(st.pclk[:, 1::2]) > 0.0)  # unsynchronized: their drift is realized too


def test_one_run_drawn_alone_gets_the_run_axis_and_the_same_values():
    suite, truth, errors, _, _, st = _setup()
    one = suite.draw(truth.t_s, 4, 1)
    alone = start_states(suite, truth, one)
    assert alone.runs == 1
    # bit-identical: same code path (run 1 drawn alone and in a batch)
    np.testing.assert_array_equal(alone.gse, st.gse[1:2])
    np.testing.assert_array_equal(alone.clk, st.clk[1:2])
    np.testing.assert_array_equal(alone.bb, st.bb[1:2])
