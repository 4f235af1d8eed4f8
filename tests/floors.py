"""Floating-point floors for the equality tests: how far two computations of one quantity may differ by rounding.

A result computed in about k floating-point operations from operands of sizes |a|, |b|, ... carries a rounding
error of at most about k * eps * (|a| + |b| + ...) (Higham, *Accuracy and Stability of Numerical Algorithms*,
ch. 3: a sum or dot product of k terms is off by at most gamma_k * sum |terms|, gamma_k ~ k eps). Two computations
of the same quantity by different instruction sequences (a numba kernel and its numpy oracle, with or without FMA,
another vector width, another BLAS kernel, another CPU) may each be off by that much, so they differ by up to
twice it. The floor is set by the operands, never by the result: the difference of two 2e7 m ranges is known to
about eps * 2e7 m = 4.4e-9 m however small the difference is, and a bound of 1e-10 times the difference is below
what double precision can promise.

Where bit-identity is a real contract (the same code path on the same machine: batch sizes, executors, resume,
a seed's draws), a test compares exactly with `assert_array_equal` and says so; it does not use these floors.

    floor(k, a, b)            k * eps * (|a| + |b|), elementwise
    assert_within(x, y, f, what)   |x - y| <= f elementwise (nan where both are nan), the excess named on failure
"""

from __future__ import annotations

import numpy as np

EPS = float(np.finfo(np.float64).eps)
"""Double-precision machine epsilon, 2.22e-16 (the unit roundoff is eps / 2)."""

R_EARTH_M = 6.4e6
"""Size of an ECEF position component or norm near the Earth's surface, m: the operand of every ECEF difference."""

R_GPS_MAX_M = 2.7e7
"""Largest GPS satellite range from the Earth's surface (26,600 km orbit radius, at the horizon ~25,800 km), m."""


def floor(k: float, *operands: object) -> np.ndarray:
    """k * eps * (|a| + |b| + ...), elementwise over broadcast operands: the rounding floor of a quantity
    computed in about k operations from those operands (module docstring)."""
    total = np.zeros(())
    for op in operands:
        total = total + np.abs(np.asarray(op, dtype=float))
    return k * EPS * total


def assert_within(actual: object, expected: object, floor_: object, what: str = "") -> None:
    """Assert |actual - expected| <= floor_ elementwise (shapes equal; nan only where both are nan)."""
    a = np.asarray(actual, dtype=float)
    b = np.asarray(expected, dtype=float)
    assert a.shape == b.shape, f"{what}: shapes {a.shape} != {b.shape}"
    na, nb = np.isnan(a), np.isnan(b)
    assert np.array_equal(na, nb), f"{what}: nan at different places"
    d = np.where(na, 0.0, np.abs(a - b))
    f = np.broadcast_to(np.asarray(floor_, dtype=float), d.shape)
    bad = d > f
    if bad.any():
        i = int(np.argmax(np.where(bad, d / np.where(f > 0, f, 1e-300), -np.inf)))
        raise AssertionError(
            f"{what}: |diff| exceeds the floor at {int(bad.sum())} of {d.size} elements; worst "
            f"{d.flat[i]:.3g} against {f.flat[i]:.3g} ({d.flat[i] / max(f.flat[i], 1e-300):.3g}x)"
        )
