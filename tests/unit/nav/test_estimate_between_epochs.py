"""The navigation output between aiding epochs carries the filter's estimate forward by its rate
(core/nav/output.nav_rate, estimate_at): x(t) = x_k + (t - t_k) F x_k, the first-order term of Phi(t - t_k) x_k. Held
instead, the output lags the INS's drift over the interval (the KDEN ISA +30 case: the damping loop drags the INS at
-sb v_D toward a scale-factor-biased baro). Checked against the exact transition expm(F tau) of the same model."""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from approachsim.core.nav import output as ko
from approachsim.nav import errormodel as em
from approachsim.nav import vertical_loop as vl

EPS = np.finfo(float).eps
NOISE = em.ErrorNoise(
    gyro_arw_rad_sqrts=1e-6, accel_vrw_mps_sqrts=1e-5, gyro_bias_rw=1e-9, accel_bias_rw=1e-7,
    baro_bias_sigma_m=1.0, baro_bias_tau_s=100.0, clock_sf=0.1, clock_sg=0.01, baro_ref_m=1656.0,
)
LAY = em.StateLayout(baro_scale=True, clock=True, loop=True)
GAINS = vl.constant_gains(100.0)  # the default loop (nav.baro_loop_tau_s)


def _model() -> np.ndarray:
    """F (1/s) on a 3 deg final 300 m above a 5434 ft (1656 m) field at 140 kt, level wings."""
    return em.dynamics(LAY, math.radians(39.86), 1656.0 + 300.0, np.array([72.0, 0.0, 3.8]),
                       np.array([0.0, 0.0, -9.8]), np.eye(3), NOISE, GAINS)[0]


def _estimate(rng: np.random.Generator) -> np.ndarray:
    """An estimate at the scale of a converged filter's: dp ~ 1 m, dv ~ 0.1 m/s, psi ~ 1 mrad, biases, sb ~ 0.1."""
    x = np.zeros(LAY.n)
    x[LAY.index["dp"]] = rng.normal(0.0, 1.0, 3)
    x[LAY.index["dv"]] = rng.normal(0.0, 0.1, 3)
    x[LAY.index["psi"]] = rng.normal(0.0, 1e-3, 3)
    x[LAY.index["bg"]] = rng.normal(0.0, 1e-6, 3)
    x[LAY.index["ba"]] = rng.normal(0.0, 1e-3, 3)
    x[LAY.i("bb")] = rng.normal(0.0, 3.0)
    x[LAY.i("sb")] = -0.098  # an uncorrected ISA +30 day at this field (docs/baro.md)
    x[LAY.i("ac")] = rng.normal(0.0, 1e-3)
    return x


def test_rate_is_the_models_navigation_rows_times_the_estimate():
    """nav_rate = F[0:9, :] x, each row summed in column order: against the exactly rounded sum (math.fsum), within
    n eps of the sum of the products' magnitudes (n - 1 additions, each rounding by at most eps of the partial sum)."""
    F = _model()
    rng = np.random.default_rng(5)
    for _ in range(20):
        x = _estimate(rng)
        out = np.zeros(9)
        ko.nav_rate(F, x, out)
        for i in range(9):
            terms = F[i] * x
            assert abs(out[i] - math.fsum(terms)) <= LAY.n * EPS * np.abs(terms).sum()
    assert out[2] != 0.0 and out[5] != 0.0  # the vertical channel moves: dv_D, the loop's sb column


def test_carried_estimate_follows_the_exact_transition_over_an_interval():
    """Over tau <= 1 s the carried estimate x + tau F x differs from expm(F tau) x by the second-order remainder,
    at most tau^2 / 2 |F^2 x| e^(tau |F|) per element; the held estimate x by the whole drift tau |F x|. At tau = 1
    the drift of dp_D is the estimated dv_D plus the loop's pull, tenths of a metre: the carried one must be within
    the remainder's bound and at least 50x closer on every position row."""
    F = _model()
    rng = np.random.default_rng(8)
    norm = np.abs(F).sum(axis=1).max()
    for _ in range(10):
        x = _estimate(rng)
        xd = np.zeros(9)
        ko.nav_rate(F, x, xd)
        for tau in (0.25, 0.5, 1.0):
            exact = (expm(F * tau) @ x)[0:9]
            carried = np.zeros(9)
            ko.estimate_at(x, xd, 10.0, 10.0 + tau, carried)
            bound = 0.5 * tau**2 * np.abs(F @ (F @ x))[0:9] * math.exp(tau * norm) + 1e3 * EPS * np.abs(x[0:9])
            assert np.all(np.abs(carried - exact) <= bound)
        assert abs(carried[2] - exact[2]) * 20.0 < abs(x[2] - exact[2])


def test_at_the_epoch_the_output_is_the_estimate():
    """tau = 0 (the epoch's own row): x + 0 * xd is x, bit for bit."""
    x = _estimate(np.random.default_rng(2))
    xd = np.full(9, 0.3)
    out = np.zeros(9)
    ko.estimate_at(x, xd, 12.0, 12.0, out)
    assert np.array_equal(out, x[0:9])
