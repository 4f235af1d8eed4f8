"""The compiled floor's kernel decorator: numba's njit, one compilation per argument *type*, not per constant, and
kernels called only from compiled code compiled as linkable code only.

Constants. When compiled code calls a kernel with a constant (`_update(..., CODE_BARO, ...)`, a `True` flag), numba
types the argument as a literal (`Literal[int](1)`) and compiles the kernel once more for each constant value:
measured on the closed loop's default profile, 12 of 180 compilations were such copies (`_pseudorange` 6 times,
`_update` 6 times, `carrier_phase` 4 times, `class_epoch` twice), each with its whole call tree typed, lowered and
optimized again. Here a call from compiled code is resolved for the arguments' plain types (`numba.types.unliteral`),
so every constant of a type shares one compilation; the constant is then an ordinary argument (a branch on it is
taken at run time, not pruned at compile time: none of our kernels relies on pruning, each types with plain
arguments). Calls from Python are typed by value already (never literal) and pass unchanged.

Callees. Numba compiles a kernel called from compiled code as if Python could call it: a Python wrapper and a C
wrapper, its module with its callee tree linked in optimized by the full pipeline, machine code emitted; then the
caller links that module and optimizes the tree again, so a function at depth k of a call tree is optimized and
emitted k times (on the closed loop's cold compile, 127 of 177 code libraries are such callees: 5 s of module
optimization and 5 s of machine code of 56 s). Here a compilation typed from compiled code (an *internal*
overload) gets no wrappers, no module optimization and no machine code: its library only holds the linkable module
(function-level optimized, as numba leaves each function before linking), and the caller that Python calls (an
*entry*) optimizes and emits the whole tree once, as it does today on top of the optimized copies. The arithmetic
is the same instructions (no fast-math anywhere: tools/*_identity.py bit for bit). An internal overload is not
callable from Python: it stays out of numba's Python dispatch table, and a Python call (or core/entry.py,
core/warm.py) with its types compiles the kernel again as an entry; internal overloads are saved to the numba
cache under their own file names ("internal-..."), so an entry never loads one. A cached entry's machine code holds
its linked callees, so a warm run loads entries only, as before.

The guard: where numba's internals used here are not there (Dispatcher.get_call_template; for the callees:
Dispatcher.add_overload/_compiler/_cache, the codegen's library class with _finalize_final_module, caching's
CompileResultCacheImpl), kernels fall back to numba's own behaviour (tests/unit/test_core_jit.py).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any

import numba
from numba import types

try:  # numba internals for the internal overloads; absent ones leave numba's own behaviour
    from llvmlite import binding as _ll
    from numba.core import caching as _caching
    from numba.core import codegen as _codegen
    from numba.core import sigutils as _sigutils

    _INTERNALS = all((hasattr(_codegen, "JITCodeLibrary"),
                      hasattr(_codegen.CPUCodeLibrary, "_finalize_final_module"),
                      hasattr(_codegen.CPUCodeLibrary, "_optimize_final_module"),
                      hasattr(_caching, "CompileResultCacheImpl"), hasattr(_caching, "FunctionCache")))
except ImportError:  # pragma: no cover - another numba
    _INTERNALS = False

_ENV_PREFIX = "_ZN08NumbaEnv"  # numba's Environment globals (BaseContext.declare_env_global)
INTERNAL_PREFIX = "internal"  # the numba cache's file-name prefix of internal overloads


class _Compiling(threading.local):
    """Per thread: how many calls from compiled code are being typed (> 0: a compilation starting now is internal),
    and the internal compilations under way, innermost last, each [qualified name, its library made, dispatcher]."""

    def __init__(self) -> None:
        self.depth = 0
        self.frames: list[list] = []
        self.entries: frozenset = frozenset()  # (module, name, argument types) Python calls too: entries_expected


@contextmanager
def entries_expected(keys: Iterable[tuple[str, str, tuple]]) -> Iterator[None]:
    """Within the block (this thread), a kernel typed from compiled code whose (module, function name, argument
    types) is in keys is compiled as the entry Python will call (numba's own compile: loaded from the file cache when
    there, else compiled with its wrappers and saved), not as an internal overload. core/warm.py compiles a
    manifest's entries in this block: a kernel that Python calls and a bigger kernel calls too is then typed and
    lowered once, not once inside its caller and again for Python (cold cache, 2 to 3 s of CPU each for
    errormodel.dynamics and discretize). The caller links the entry's library as plain numba does: the same
    instructions (tools/*_identity.py)."""
    old = _STATE.entries
    _STATE.entries = frozenset(keys)
    try:
        yield
    finally:
        _STATE.entries = old


_STATE = _Compiling()


def _plain_types(dispatcher: Any) -> Any:
    """Route the dispatcher's typing of calls from compiled code through its arguments' plain (non-literal) types,
    counting the nesting (internal overloads)."""
    resolve = getattr(dispatcher, "get_call_template", None)
    if resolve is None:  # another numba's internals: keep its own behaviour
        return dispatcher

    def get_call_template(args: tuple, kws: dict) -> Any:
        _STATE.depth += 1
        try:
            return resolve(tuple(types.unliteral(a) for a in args),
                           {k: types.unliteral(v) for k, v in kws.items()})
        finally:
            _STATE.depth -= 1

    dispatcher.get_call_template = get_call_template
    return dispatcher


if _INTERNALS:
    class _InternalLibrary(_codegen.JITCodeLibrary):
        """A code library that is only ever linked into callers: its module is not optimized at finalize (the
        caller optimizes the tree it links) and the execution engine gets only its Environment globals (numba sets
        them at load), no machine code."""

        def _optimize_final_module(self) -> None:
            return

        def _finalize_final_module(self) -> None:
            full = self._final_module
            self._finalize_dynamic_globals()
            self._verify_declare_only_symbols()
            lines = [str(gv) for gv in full.global_variables if gv.name.startswith(_ENV_PREFIX)]
            stub = _ll.parse_assembly("\n".join(lines))
            stub.triple, stub.data_layout, stub.name = full.triple, full.data_layout, full.name
            self._final_module = stub
            try:
                super()._finalize_final_module()
            finally:
                self._final_module = full

    class _InternalCacheImpl(_caching.CompileResultCacheImpl):
        """numba's cache of compile results, under file names of their own."""

        def get_filename_base(self, fullname: str, abiflags: str) -> str:
            return f"{INTERNAL_PREFIX}-{super().get_filename_base(fullname, abiflags)}"

    class _InternalCache(_caching.FunctionCache):
        _impl_class = _InternalCacheImpl


def _hook_codegen(codegen: Any) -> None:
    """Make the codegen create an _InternalLibrary for the innermost internal compilation's own library."""
    if getattr(codegen, "_internal_hooked", False):
        return
    create = codegen.create_library

    def create_library(name: str, **kwargs: Any) -> Any:
        frame = _STATE.frames[-1] if _STATE.frames else None
        if frame is not None and not frame[1] and frame[0] == name:
            frame[1] = True
            return _InternalLibrary(codegen, name, **kwargs)
        return create(name, **kwargs)

    codegen.create_library = create_library
    codegen._internal_hooked = True


def _internal_overloads(dispatcher: Any) -> Any:
    """Compile the dispatcher's overloads typed from compiled code as internal ones (module docstring)."""
    needed = ("compile", "add_overload", "overloads", "_compiler", "_cache", "targetctx", "py_func")
    if not _INTERNALS or not all(hasattr(dispatcher, a) for a in needed) \
            or not hasattr(dispatcher._compiler, "_customize_flags"):
        return dispatcher
    compile_, add_overload_ = dispatcher.compile, dispatcher.add_overload
    customize_ = dispatcher._compiler._customize_flags
    internal: set[tuple] = set()  # argument types of the internal overloads
    caches: list = []  # the internal cache, made on first use

    def mine() -> bool:  # the innermost compilation under way is an internal one of this dispatcher
        return bool(_STATE.frames) and _STATE.frames[-1][2] is dispatcher

    def compile(sig: Any) -> Any:  # noqa: A001 - numba's name
        args = tuple(_sigutils.normalize_signature(sig)[0])
        if not _STATE.depth:  # from Python: an internal overload has no Python entry, compile it as an entry
            if args in internal:
                internal.discard(args)
                del dispatcher.overloads[args]
            return compile_(sig)
        if args in dispatcher.overloads:
            return dispatcher.overloads[args].entry_point
        if (dispatcher.py_func.__module__, dispatcher.py_func.__name__, args) in _STATE.entries:
            return compile_(sig)  # Python calls it too (entries_expected): compile or load it as that entry
        codegen = dispatcher.targetctx.codegen()
        if not isinstance(codegen, _codegen.JITCPUCodegen):  # another target: numba's own
            return compile_(sig)
        _hook_codegen(codegen)
        cache = dispatcher._cache
        if isinstance(cache, _caching.FunctionCache):
            if not caches:
                caches.append(_InternalCache(dispatcher.py_func))
            dispatcher._cache = caches[0]
        _STATE.frames.append([dispatcher.py_func.__qualname__, False, dispatcher])
        try:
            return compile_(sig)
        finally:
            _STATE.frames.pop()
            dispatcher._cache = cache

    def add_overload(cres: Any) -> None:
        if not mine():
            return add_overload_(cres)
        args = tuple(cres.signature.args)
        dispatcher.overloads[args] = cres  # for typing and linking only: not in the Python dispatch table
        internal.add(args)
        return None

    def customize_flags(flags: Any) -> Any:
        flags = customize_(flags)
        if mine():
            flags.no_cpython_wrapper = True
            flags.no_cfunc_wrapper = True
        return flags

    dispatcher.compile = compile
    dispatcher.add_overload = add_overload
    dispatcher._compiler._customize_flags = customize_flags
    return dispatcher


def _fast_flag_values() -> bool:
    """Make numba's TargetConfig.values (the compile flags as a dict) build the dict from the class's defaults
    merged with the options set, instead of calling one property per option. Numba hashes and compares the flags
    on every typing of a call to an overloaded function (typing.templates: the flags are in the implementation
    cache's key, each hash and comparison building values() anew: about 370 000 times, ~3 s of CPU, on a closed
    loop's cold compile). The dict is the same (keys, order, values: an option's property returns its set value
    or its default), so every hash, comparison and compilation is. Returns whether installed: the guard leaves
    numba's own where TargetConfig is not built as this numba's (options of Option with a default, _values)."""
    try:
        from numba.core import targetconfig as tc
    except ImportError:  # pragma: no cover - another numba
        return False
    cls = getattr(tc, "TargetConfig", None)
    option = getattr(tc, "Option", None)
    if cls is None or option is None or "_values" not in getattr(cls, "__slots__", ()) \
            or not isinstance(getattr(option, "default", None), property) or not hasattr(cls, "values"):
        return False
    if getattr(cls.values, "_approachsim_fast", False):
        return True
    defaults: dict[type, dict[str, Any]] = {}  # per TargetConfig class: its options' defaults, in options order

    def values(self: Any) -> dict[str, Any]:
        kind = type(self)
        d = defaults.get(kind)
        if d is None:
            d = defaults[kind] = {k: o.default for k, o in kind.options.items()}
        return {**d, **self._values}

    values._approachsim_fast = True  # type: ignore[attr-defined]
    values.__doc__ = cls.values.__doc__
    cls.values = values
    return True


FAST_FLAG_VALUES = _fast_flag_values()


def njit(fn: Callable | None = None, **options: Any) -> Any:
    """numba.njit(**options) whose calls from compiled code compile once per argument type and as internal
    overloads (module docstring); use as `@njit` or `@njit(cache=True, ...)`. An `inline="always"` kernel is typed
    inside its caller and never compiled on its own, so it is returned as numba made it."""

    def wrap(f: Callable) -> Any:
        disp = numba.njit(**options)(f)
        if options.get("inline", "never") == "always":
            return disp
        return _internal_overloads(_plain_types(disp))

    return wrap if fn is None else wrap(fn)
