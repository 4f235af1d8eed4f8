"""core/entry.py: a dispatcher's compiled entry point computes what the dispatcher does, and the guard falls back to
the dispatcher itself when numba's internals (overloads[signature].entry_point) are not there."""

from __future__ import annotations

import numpy as np
from numba import njit

from approachsim.core.entry import entry_point


@njit(cache=False)
def _axpy(a, x, y):  # noqa: ANN001, ANN202
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = a * x[i] + y[i]
    return out


def test_entry_point_is_the_compiled_function_and_equals_the_dispatcher():
    x, y = np.arange(5.0), np.ones(5)
    e = entry_point(_axpy, 2.0, x, y)
    assert e is not _axpy  # numba's internals are there: the compiled entry, not the dispatcher
    assert np.array_equal(e(2.0, x, y), _axpy(2.0, x, y))
    assert np.array_equal(e(2.0, x, y), 2.0 * x + y)  # one multiply and one add per element: exact here


class _NoInternals:
    """A dispatcher whose overloads carry no entry_point (another numba version's internals)."""

    overloads: dict = {}

    def compile(self, sig):  # noqa: ANN001, ANN201
        return None

    def __call__(self, *args):  # noqa: ANN002, ANN204
        return "dispatched"


def test_entry_point_falls_back_to_the_dispatcher():
    d = _NoInternals()
    assert entry_point(d, 1.0) is d
