"""core/jit.py: a kernel called from compiled code with different constants compiles once, computes what numba's
own literal-specialized copies compute, and the guard leaves a dispatcher without numba's internals alone."""

from __future__ import annotations

import numba
import numpy as np

from approachsim.core.jit import _plain_types, njit


@njit(cache=False)
def _scaled(x, code):  # noqa: ANN001, ANN202
    return x * code if code > 1 else x - code


@njit(cache=False)
def _two_constants(x):  # noqa: ANN001, ANN202
    return _scaled(x, 1) + _scaled(x, 3)


@numba.njit(cache=False)
def _scaled_numba(x, code):  # noqa: ANN001, ANN202
    return x * code if code > 1 else x - code


@numba.njit(cache=False)
def _two_constants_numba(x):  # noqa: ANN001, ANN202
    return _scaled_numba(x, 1) + _scaled_numba(x, 3)


def test_constants_share_one_compilation():
    x = np.float64(2.5)
    assert _two_constants(x) == (x - 1) + x * 3  # exact: one subtraction, one product of small exact values
    assert len(_scaled.overloads) == 1  # both constants: the plain int64 signature
    (sig,) = _scaled.overloads
    assert not any(isinstance(a, numba.types.Literal) for a in sig)
    # numba's own njit compiles one copy per constant value (what the wrapper removes), with the same result
    assert _two_constants_numba(x) == _two_constants(x)
    assert len(_scaled_numba.overloads) == 2


def test_inline_always_is_numba_own():
    @njit(inline="always")
    def f(x):  # noqa: ANN001, ANN202
        return x + 1

    assert "get_call_template" not in vars(f)


def test_guard_keeps_a_dispatcher_without_the_internals():
    class NoInternals:
        pass

    d = NoInternals()
    assert _plain_types(d) is d
    assert not hasattr(d, "get_call_template")
