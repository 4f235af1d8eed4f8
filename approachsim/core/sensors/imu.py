"""Compiled IMU error application (numba, cache=True): sensors/imu.py's `Imu.apply`; `Imu.apply_reference` is the
numpy oracle (tests/unit/sensors/test_sensor_kernels.py checks they agree to 1e-12 relative). The scale factor and
misalignment (I + M) d of an increment is `scaled`, once, for the batch (imu_apply) and for the closed loop's one
increment at a time (increment, core/nav/strapdown.inloop_step)."""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit


@njit(cache=True)
def scaled(m_err: np.ndarray, d0: float, d1: float, d2: float, r: int) -> float:
    """Axis r of (I + M) d: d_r + (M d)_r, M (3, 3) scale factor + misalignment, d = (d0, d1, d2) the true
    increment (rad or m/s; sensors/imu.py)."""
    d = d0 if r == 0 else (d1 if r == 1 else d2)
    return d + (m_err[r, 0] * d0 + m_err[r, 1] * d1 + m_err[r, 2] * d2)


@njit(cache=True)
def increment(m_err: np.ndarray, true_row: np.ndarray, dt: float, c: np.ndarray, out: np.ndarray) -> None:
    """One affine IMU increment (sensors/imu.py): out = d + M d + c, d = dt * true_row (the rate or specific
    force of truth sample k-1 held over the interval), M (3, 3) scale factor + misalignment, c (3,) the
    sample's bias, noise and drift terms."""
    d0, d1, d2 = dt * true_row[0], dt * true_row[1], dt * true_row[2]
    for r in range(3):
        out[r] = scaled(m_err, d0, d1, d2, r) + c[r]


@njit(cache=True)
def imu_apply(true_inc: np.ndarray, m_err: np.ndarray, bias0: np.ndarray, bias: np.ndarray, noise: np.ndarray,
              dt: float, quant: float, out: np.ndarray) -> None:
    """Increments of R runs (sensors/imu.py error model), in place into out (R, m, 3):

        out = q round((d + M d + (b0 + b_k) dt + n_k) / q)      (no rounding when q = 0)

    true_inc d (m, 3) the exact increments (shared by the runs), m_err M (R, 3, 3) scale factor + misalignment,
    bias0 b0 (R, 3) turn-on bias, bias b_k (R, m, 3) Gauss-Markov bias at each sample, noise n_k (R, m, 3)
    white noise per increment; dt (s); quant q the quantization step (rad or m/s), round half to even."""
    n_runs, m = noise.shape[0], noise.shape[1]
    for i in range(n_runs):
        for k in range(m):
            d0, d1, d2 = true_inc[k, 0], true_inc[k, 1], true_inc[k, 2]
            for r in range(3):
                v = scaled(m_err[i], d0, d1, d2, r) + (bias0[i, r] + bias[i, k, r]) * dt + noise[i, k, r]
                if quant > 0.0:
                    v = quant * np.rint(v / quant)
                out[i, k, r] = v
