"""Compiled first-order recursion of the Gauss-Markov error processes (numba, cache=True): sensors/base.py's
`gauss_markov`; `gauss_markov_reference` (scipy.signal.lfilter) is the oracle, equal bit for bit
(tests/unit/sensors/test_sensor_kernels.py)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def first_order(drive: np.ndarray, a: np.ndarray, out: np.ndarray) -> None:
    """x_0 = d_0,  x_k = d_k + a_c x_{k-1}  for every column c of drive (m, c), in place into out (m, c).

    The same two roundings per step as scipy.signal.lfilter([1], [1, -a], d) (direct form II transposed:
    y_k = b0 d_k + z, z = b1 d_{k-1} - a1 y_{k-1} with b0 = 1, b1 = 0, a1 = -a, i.e. d_k + a y_{k-1}), so the
    series are bit-identical to the filter's; samples on the outer loop, columns inner."""
    m, c = drive.shape
    if m == 0:
        return
    for j in range(c):
        out[0, j] = drive[0, j]
    for k in range(1, m):
        for j in range(c):
            out[k, j] = drive[k, j] + a[j] * out[k - 1, j]
