"""Compiled first-order recursion of the Gauss-Markov error processes (numba, cache=True): sensors/base.py's
`gauss_markov`; `gauss_markov_reference` (scipy.signal.lfilter) is the oracle, equal bit for bit
(tests/unit/sensors/test_sensor_kernels.py)."""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit


@njit(cache=True)
def first_order(z: np.ndarray, c0: np.ndarray, c1: np.ndarray, a: np.ndarray, out: np.ndarray) -> None:
    """x_0 = c0 z_0,  x_k = c1 z_k + a x_{k-1}  for every column of the standard normals z (m, c) (any strides), in
    place into out (m, c); per column c0 = sigma, c1 = sigma sqrt(1 - a^2), a = exp(-dt / tau) (base.gauss_markov).

    The same roundings as the oracle's drive d_k = c1 z_k followed by scipy.signal.lfilter([1], [1, -a], d)
    (direct form II transposed: y_k = b0 d_k + s, s = b1 d_{k-1} - a1 y_{k-1} with b0 = 1, b1 = 0, a1 = -a, i.e.
    d_k + a y_{k-1}), so the series are bit-identical to the filter's; samples on the outer loop, columns inner."""
    m, c = z.shape
    if m == 0:
        return
    for j in range(c):
        out[0, j] = c0[j] * z[0, j]
    for k in range(1, m):
        for j in range(c):
            out[k, j] = c1[j] * z[k, j] + a[j] * out[k - 1, j]
