"""IMU: exact increments with noise=False, stepwise = batch, prefix property, Allan-deviation recovery."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import least_squares

from approachsim import synthetic
from approachsim.sensors.imu import Imu
from approachsim.sensors.presets import PRESETS


def test_noise_false_is_the_held_truth_sample(descent):
    rec = Imu(PRESETS["mems"]).measure(descent, np.random.default_rng(0), noise=False)
    dt = descent.t_s[1] - descent.t_s[0]
    assert rec.dt_s == dt
    assert np.array_equal(rec.t_s, descent.t_s[1:])  # bit-identical: the truth's times sliced
    # exact by construction: zeroed errors add exact zeros to the same products dt * w, dt * f (x + 0 = x in any
    # rounding)
    assert np.array_equal(rec.dtheta_body, dt * descent.w_ib_body[:-1])
    assert np.array_equal(rec.dv_body, dt * descent.f_body[:-1])
    assert rec.valid.all() and not rec.fault.any()


def test_stepwise_apply_equals_batch_bit_for_bit(descent):
    imu = Imu(PRESETS["tactical"])
    e = imu.draw(descent.t_s, np.random.default_rng(7))
    batch = imu.apply(descent, e)
    for j in (0, 1, 100, len(e) - 1):  # bit-identical: same code path (the kernel on a one-sample slice)
        one = imu.apply(descent, e.take(slice(j, j + 1)))
        assert np.array_equal(one.dtheta_body[0], batch.dtheta_body[j])
        assert np.array_equal(one.dv_body[0], batch.dv_body[j])
    assert np.array_equal(imu.measure(descent, np.random.default_rng(7)).dv_body, batch.dv_body)


def test_prefix_property_and_run_axis(descent):
    imu = Imu(PRESETS["nav-2.0"])
    short = descent.slice(slice(0, 500))
    a = imu.measure(short, np.random.default_rng(3))
    b = imu.measure(descent, np.random.default_rng(3))
    # bit-identical: same code path (a record's prefix, a run of a batch)
    assert np.array_equal(a.dv_body, b.dv_body[:499])
    assert np.array_equal(a.dtheta_body, b.dtheta_body[:499])
    many = imu.measure(short, [np.random.default_rng(s) for s in (9, 3)])
    assert many.dv_body.shape == (2, 499, 3)
    assert np.array_equal(many.dv_body[1], a.dv_body)


def test_turn_on_bias_and_scale_factor_statistics():
    """Run-to-run constants have their 1-sigma (5 %): 4000 runs of a 1 s stationary record."""
    g = PRESETS["tactical"]
    imu = Imu(g)
    t = np.arange(3) * 0.5
    e = imu.draw(t, [np.random.default_rng(i) for i in range(4000)])
    assert e.constants["gyro_bias0"].std() == pytest.approx(g.gyro_bias_radps, rel=0.05)
    assert e.constants["accel_bias0"].std() == pytest.approx(g.accel_bias_mps2, rel=0.05)
    gm = e.constants["gyro_m"]
    assert np.diagonal(gm, axis1=1, axis2=2).std() == pytest.approx(g.gyro_sf, rel=0.05)
    assert gm[:, 0, 1].std() == pytest.approx(g.gyro_misalign_rad, rel=0.05)


def _avar_overlapping(y: np.ndarray, dt: float, ms: np.ndarray) -> np.ndarray:
    """Overlapping Allan variance of rate samples y (series, samples) at cluster sizes ms, pooled over series."""
    x = np.concatenate([np.zeros((y.shape[0], 1)), np.cumsum(y, axis=1) * dt], axis=1)
    out = []
    for m in ms:
        tau = m * dt
        d = x[:, 2 * m :] - 2 * x[:, m:-m] + x[:, : -2 * m]
        out.append(np.mean(d * d) / (2 * tau * tau))
    return np.array(out)


def _avar_model(tau: np.ndarray, n_arw: float, sigma: float, tc: float) -> np.ndarray:
    """Allan variance of white rate noise (N^2 / T) plus a first-order Gauss-Markov bias (sigma, tc)."""
    x = tau / tc
    gm = 2 * sigma**2 * tc / tau * (1 - (3 - 4 * np.exp(-x) + np.exp(-2 * x)) / (2 * x))
    return n_arw**2 / tau + gm


# Record length (correlation times) and runs. The MEMS accelerometer's white noise is so strong
# (VRW^2 = 1.9 x 2 sigma^2 tau) that its Gauss-Markov bump in the Allan curve is only ~15 % above the white
# noise line: separating the two to 10 % takes 8x the data (32 runs x 400 tau; with 8 x 200 tau the fit
# scatters by ~20 %, measured). The other grades' bumps stand clear.
_ALLAN_DATA = {"nav-0.4": (200, 8), "nav-2.0": (200, 8), "nav-4.0": (200, 8), "tactical": (200, 8), "mems": (400, 32)}


@pytest.mark.parametrize("grade", list(_ALLAN_DATA))
def test_allan_deviation_recovers_arw_and_bias_instability(grade):
    """Static IMU on the synthetic stationary truth at 1 Hz, runs x 3 axes pooled: fitting N^2/T + Gauss-
    Markov to the overlapping Allan variance gives ARW / VRW and the bias-instability sigma within 10 %
    for gyros and accelerometers."""
    g = PRESETS[grade]
    dt = 1.0
    tc = max(g.gyro_bi_tau_s, g.accel_bi_tau_s)
    n_tau, runs = _ALLAN_DATA[grade]
    n = int(n_tau * tc)
    truth = synthetic.stationary(math.radians(37.6), math.radians(-122.4), 4.0, n * dt, 1.0 / dt)
    rec = Imu(g).measure(truth, [np.random.default_rng(100 + i) for i in range(runs)])
    ms = np.unique(np.round(np.logspace(0, np.log10(n / 8), 30)).astype(int))
    tau = ms * dt
    for inc, n_true, s_true, tc_true in (
        (rec.dtheta_body, g.gyro_arw_rad_sqrts, g.gyro_bi_radps, g.gyro_bi_tau_s),
        (rec.dv_body, g.accel_vrw_mps_sqrts, g.accel_bi_mps2, g.accel_bi_tau_s),
    ):
        y = np.moveaxis(inc / dt, -1, 1).reshape(-1, inc.shape[1])  # (runs * axes, samples)
        avar = _avar_overlapping(y, dt, ms)

        def resid(p, avar=avar):
            return np.log(_avar_model(tau, *np.exp(p))) - np.log(avar)

        p0 = np.log([np.sqrt(avar[0] * tau[0]), np.sqrt(avar.max() * 2), tau[len(tau) // 2]])
        fit = least_squares(resid, p0)
        n_fit, s_fit, tc_fit = np.exp(fit.x)
        assert n_fit == pytest.approx(n_true, rel=0.10)
        assert s_fit == pytest.approx(s_true, rel=0.10)
        assert tc_fit == pytest.approx(tc_true, rel=0.5)  # loosely: the bump sits at the right time scale


def test_quantization_rounds_each_increment(descent):
    from dataclasses import replace

    q_th, q_v = 1e-6, 1e-4
    imu = Imu(replace(PRESETS["mems"], gyro_quant_rad=q_th, accel_quant_mps=q_v))
    rec = imu.measure(descent, np.random.default_rng(2))
    raw = Imu(PRESETS["mems"]).measure(descent, np.random.default_rng(2))
    # q n / q for |n| ~ 1e2..1e4: floor(2, 1e4) = 4.4e-12; 1e-6 is 2e5x that
    assert np.allclose(rec.dtheta_body / q_th, np.round(rec.dtheta_body / q_th), rtol=0, atol=1e-6)
    # |q rint(v / q) - v| <= q / 2 plus the floor of the two roundings, floor(2, |v| <= 1 m/s) = 4.4e-16 m/s; the
    # slack 1e-9 q / 2 = 5e-14 m/s is 100x that
    assert np.max(np.abs(rec.dv_body - raw.dv_body)) <= 0.5 * q_v * (1 + 1e-9)
    exact = imu.measure(descent, np.random.default_rng(2), noise=False)  # exact by construction, as in the first test
    assert np.array_equal(exact.dv_body, (descent.t_s[1] - descent.t_s[0]) * descent.f_body[:-1])
