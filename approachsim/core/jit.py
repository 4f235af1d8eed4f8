"""The compiled floor's kernel decorator: numba's njit, one compilation per argument *type*, not per constant.

When compiled code calls a kernel with a constant (`_update(..., CODE_BARO, ...)`, a `True` flag), numba types
the argument as a literal (`Literal[int](1)`) and compiles the kernel once more for each constant value: measured
on the closed loop's default profile, 12 of 180 compilations were such copies (`_pseudorange` 6 times, `_update` 6
times, `carrier_phase` 4 times, `class_epoch` twice), each with its whole call tree typed, lowered and optimized
again. `njit` here is numba's with one change: a call from compiled code is resolved for the arguments' plain
types (`numba.types.unliteral`), so every constant of a type shares one compilation; the constant is then an
ordinary argument (a branch on it is taken at run time, not pruned at compile time: none of our kernels relies on
pruning, each types with plain arguments). Calls from Python are typed by value already (never literal) and pass
unchanged. The guard: where numba's Dispatcher.get_call_template is not there, kernels are numba's plain njit
(tests/unit/test_core_jit.py).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba
from numba import types


def _plain_types(dispatcher: Any) -> Any:
    """Route the dispatcher's typing of calls from compiled code through its arguments' plain (non-literal) types."""
    resolve = getattr(dispatcher, "get_call_template", None)
    if resolve is None:  # another numba's internals: keep its own behaviour
        return dispatcher

    def get_call_template(args: tuple, kws: dict) -> Any:
        return resolve(tuple(types.unliteral(a) for a in args), {k: types.unliteral(v) for k, v in kws.items()})

    dispatcher.get_call_template = get_call_template
    return dispatcher


def njit(fn: Callable | None = None, **options: Any) -> Any:
    """numba.njit(**options) whose calls from compiled code compile once per argument type (module docstring); use as
    `@njit` or `@njit(cache=True, ...)`. An `inline="always"` kernel is typed inside its caller and never compiled on
    its own, so it is returned as numba made it."""

    def wrap(f: Callable) -> Any:
        disp = numba.njit(**options)(f)
        return disp if options.get("inline", "never") == "always" else _plain_types(disp)

    return wrap if fn is None else wrap(fn)
