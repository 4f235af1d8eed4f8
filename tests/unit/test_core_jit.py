"""core/jit.py: a kernel called from compiled code with different constants compiles once, computes what numba's
own literal-specialized copies compute; a kernel typed from compiled code is an internal overload (optimized once,
inside the entry Python calls; no machine code of its own; cached apart); the guards leave a dispatcher without
numba's internals alone."""

from __future__ import annotations

import os
import re
import subprocess
import sys

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


# internal overloads: a three-level chain of plain arithmetic (no numba helper libraries), each level its own kernel


@njit(cache=False)
def _leaf(x):  # noqa: ANN001, ANN202
    return x * 3.0 + 1.0


@njit(cache=False)
def _middle(x):  # noqa: ANN001, ANN202
    return _leaf(x) * 0.5


@njit(cache=False)
def _top(x):  # noqa: ANN001, ANN202
    return _middle(x) - 2.0


@numba.njit(cache=False)
def _leaf_numba(x):  # noqa: ANN001, ANN202
    return x * 3.0 + 1.0


@numba.njit(cache=False)
def _middle_numba(x):  # noqa: ANN001, ANN202
    return _leaf_numba(x) * 0.5


@numba.njit(cache=False)
def _top_numba(x):  # noqa: ANN001, ANN202
    return _middle_numba(x) - 2.0


def _module_optimizations(monkeypatch, call) -> int:  # noqa: ANN001
    """How many code libraries run numba's module optimization while `call()` compiles."""
    from numba.core import codegen

    runs = []
    optimize = codegen.CPUCodeLibrary._optimize_final_module

    def counted(self):  # noqa: ANN001, ANN202
        runs.append(self.name)
        return optimize(self)

    monkeypatch.setattr(codegen.CPUCodeLibrary, "_optimize_final_module", counted)
    call()
    return len(runs)


def test_callees_are_optimized_once_inside_the_entry(monkeypatch):
    x = 2.0
    # numba's own: each level's module is optimized (with its callees linked in), then again inside its caller
    assert _module_optimizations(monkeypatch, lambda: _top_numba(x)) == 3
    assert _module_optimizations(monkeypatch, lambda: _top(x)) == 1  # the entry's, over the linked tree
    assert _top(x) == _top_numba(x) == (x * 3.0 + 1.0) * 0.5 - 2.0  # exact: small binary fractions
    sig = (numba.types.float64,)
    for callee in (_middle, _leaf):
        cres = callee.overloads[sig]
        assert type(cres.library).__name__ == "_InternalLibrary"
        # no machine code of its own: neither the function nor a Python wrapper is in the execution engine
        assert cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name) == 0
        assert cres.library.get_pointer_to_function(cres.fndesc.llvm_cpython_wrapper_name) == 0


def test_a_python_call_of_an_internal_overload_compiles_an_entry():
    @njit(cache=False)
    def leaf(x):  # noqa: ANN001, ANN202
        return x * 3.0 + 1.0

    @njit(cache=False)
    def top(x):  # noqa: ANN001, ANN202
        return leaf(x) * 0.5

    assert top(2.0) == 3.5
    (cres,) = leaf.overloads.values()
    assert type(cres.library).__name__ == "_InternalLibrary"
    assert leaf(2.0) == 7.0  # from Python: compiled again, with its wrapper, into numba's dispatch table
    (cres,) = leaf.overloads.values()
    assert type(cres.library).__name__ == "JITCodeLibrary"
    assert top(2.0) == 3.5


_CACHED = '''
from approachsim.core.jit import njit

@njit(cache=True)
def leaf(x):
    return x * 3.0 + 1.0

@njit(cache=True)
def top(x):
    return leaf(x) * 0.5
'''

_RUN = '''
import sys
sys.path.insert(0, sys.argv[1])
import chain
print(chain.top(2.0), len(chain.leaf.overloads), chain.leaf(2.0))
'''


def test_a_cached_entry_runs_without_its_callees(tmp_path):
    """The entry's cached machine code holds its linked callees: a fresh process loads it and never compiles or
    loads the callee; the callee's internal overload is cached under its own file names, never loaded for Python."""
    (tmp_path / "chain.py").write_text(_CACHED)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}

    def run() -> str:
        return subprocess.run([sys.executable, "-c", _RUN, str(tmp_path)], env=env, capture_output=True, text=True,
                              check=True).stdout.split()

    # cold: top compiled with leaf internal (not in the dispatcher until Python calls it, then an entry)
    assert run() == ["3.5", "1", "7.0"]
    names = sorted(re.sub(r"-\d+\.py.*", "", p.name) for p in (tmp_path / "cache").rglob("*.nbi"))
    assert names == ["chain.leaf", "chain.top", "internal-chain.leaf"], names
    # warm: top loaded from the cache, leaf untouched until called from Python (then its entry from the cache)
    assert run() == ["3.5", "0", "7.0"]


def test_guard_keeps_a_dispatcher_without_the_callee_internals():
    from approachsim.core.jit import _internal_overloads

    class NoInternals:
        pass

    d = NoInternals()
    assert _internal_overloads(d) is d
    assert not hasattr(d, "compile")


# entries_expected: a kernel Python calls too, met first inside a caller, is compiled once, as that entry


def _leaf_and_caller():  # noqa: ANN202
    """Two fresh kernels (no overloads yet): leaf(x) = 5 x - 1 and caller(x) = leaf(x) + 0.25."""

    @njit(cache=False)
    def leaf(x):  # noqa: ANN001, ANN202
        return x * 5.0 - 1.0

    @njit(cache=False)
    def caller(x):  # noqa: ANN001, ANN202
        return leaf(x) + 0.25

    return leaf, caller


def _compilations(call) -> list[str]:  # noqa: ANN001
    """The names of the kernels numba compiles (not loads) while `call()` runs."""
    from numba.core import event

    names: list[str] = []

    class Listener(event.Listener):
        def on_start(self, ev):  # noqa: ANN001, ANN202
            names.append(ev.data["dispatcher"].py_func.__name__)

        def on_end(self, ev):  # noqa: ANN001, ANN202
            pass

    listener = Listener()
    event.register("numba:compile", listener)
    try:
        call()
    finally:
        event.unregister("numba:compile", listener)
    return names


def test_an_expected_entry_typed_from_compiled_code_compiles_once():
    from approachsim.core.jit import entries_expected

    x = 1.5
    leaf, caller = _leaf_and_caller()
    key = (leaf.py_func.__module__, "leaf", (numba.types.float64,))
    with entries_expected([key]):
        assert _compilations(lambda: caller.compile((numba.types.float64,))) == ["caller", "leaf"]
    # the leaf is already the entry Python calls: no second compilation, the same numbers
    assert _compilations(lambda: leaf(x)) == []
    assert leaf(x) == x * 5.0 - 1.0
    assert caller(x) == (x * 5.0 - 1.0) + 0.25  # exact: small binary fractions
    # without it (the default), the leaf met inside a caller is an internal overload and Python compiles it again
    leaf, caller = _leaf_and_caller()
    assert _compilations(lambda: caller(x)) == ["caller", "leaf"]
    assert _compilations(lambda: leaf(x)) == ["leaf"]


def _values_by_property(cfg) -> dict:  # noqa: ANN001
    """TargetConfig.values as numba writes it: one property per option."""
    return {k: getattr(cfg, k) for k in cfg.options}


def test_fast_flag_values_equal_numba_own():
    from numba.core.compiler import Flags

    from approachsim.core.jit import FAST_FLAG_VALUES

    assert FAST_FLAG_VALUES  # this numba's TargetConfig is the one the fast path is written for
    default = Flags()
    custom = Flags()
    custom.release_gil = True
    custom.boundscheck = True
    custom.no_cpython_wrapper = True
    custom.error_model = "numpy"
    copied = Flags(copy_from=custom)
    for cfg in (default, custom, copied):
        fast, own = cfg.values(), _values_by_property(cfg)
        assert list(fast.items()) == list(own.items())  # keys, order and values
        assert hash(cfg) == hash(tuple(sorted(own)))  # numba's __hash__: over the sorted option names
    assert custom == copied and custom != default
    assert hash(custom) == hash(copied)


def test_fast_flag_values_guard(monkeypatch):
    from numba.core import targetconfig as tc

    from approachsim.core import jit

    class Plain:  # a config class not built as numba's TargetConfig: no _values slot
        def values(self) -> dict:
            return {}

    monkeypatch.setattr(tc, "TargetConfig", Plain)
    assert jit._fast_flag_values() is False
    assert not getattr(Plain.values, "_approachsim_fast", False)
