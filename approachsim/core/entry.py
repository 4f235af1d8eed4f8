"""The compiled code's own entry point of a numba dispatcher, called without numba's per-call type dispatch.

Numba's dispatcher types every argument of every call in Python (~0.35 us of a ~1.4 us fly_step call; a tuple of
arrays goes through numba's Python typeof): the flight loop makes 31,000 calls a flight and the closed loop's aiding
epoch takes ~50 arguments. `entry_point` compiles (or loads from numba's cache) the signature of one call's
arguments once and returns the compiled function's own Python entry, which unboxes the arguments without typing
them. Calls through it must pass exactly these types (dtypes, dimensions, C layout): it does not check them. The
guard: numba internals (Dispatcher.overloads[signature].entry_point); where they are not there, the dispatcher
itself (tests/unit/test_core_entry.py).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba


def entry_point(dispatcher: Any, *args: Any) -> Callable:
    """The compiled entry point of numba `dispatcher` for these arguments' types (the dispatcher itself when numba's
    internals are not there)."""
    sig = tuple(numba.typeof(a) for a in args)
    dispatcher.compile(sig)  # loads it from numba's cache when compiled before
    entry = getattr(dispatcher.overloads.get(sig), "entry_point", None)
    return dispatcher if entry is None else entry
