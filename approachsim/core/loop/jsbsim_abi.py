"""The jsbsim wheel's C++ entry points for compiled code: the flight loop's reads, writes and steps without Python.

The jsbsim wheel (1.3.3) exports JSBSim's C++ symbols from its extension module. The flight loop needs three:

    double SGPropertyNode::getDoubleValue() const    _ZNK14SGPropertyNode14getDoubleValueEv
    bool   SGPropertyNode::setDoubleValue(double)    _ZN14SGPropertyNode14setDoubleValueEd
    bool   JSBSim::FGFDMExec::Run()                   _ZN6JSBSim9FGFDMExec3RunEv

They are the very functions the wheel's FGPropertyNode.get_double_value / set_double_value and FGFDMExec.run call
(JSBSim's python/jsbsim.pyx.in). Called on the C++ objects the Python wrappers hold, they do exactly what those
calls do, so a flight flown through them is bit-identical to one flown through the Python loop (flight/run.py;
tests/unit/flight/test_flight_direct.py). A non-static member function takes `this` as its first argument
(Itanium C++ ABI, the x86-64 Linux one), so compiled code calls them as plain functions (core/loop/direct.py).

The C++ objects are found in the Cython wrappers' fields (`thisptr`): a field counts when the object it points to
starts with its class's virtual-table pointer (Itanium ABI: the address of _ZTV<class> plus 16, past the
offset-to-top and the type_info pointer). Those words are read through /proc/self/mem, so a field that is not a
pointer fails the check instead of crashing. A node is then read once both ways, and the two values must be the
same bits. Anything that does not check out (another jsbsim build, another platform or Python implementation, or
APPROACHSIM_JSBSIM_DIRECT=0 in the environment) leaves the flight on the Python loop: the same numbers, slower.

Limit: a C++ exception thrown by FGFDMExec::Run inside compiled code cannot become a Python exception; it ends the
process. JSBSim 1.3.3's Run throws only when a property that a model binds late does not exist (FGPropertyValue);
the trim and the Python-side step after it run every model first and raise that error there as a Python exception.
"""

from __future__ import annotations

import ctypes
import functools
import os
import platform
import struct
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

ENV_SWITCH = "APPROACHSIM_JSBSIM_DIRECT"
"""Set to 0 to keep every flight on the Python loop."""

_GET = "_ZNK14SGPropertyNode14getDoubleValueEv"
_SET = "_ZN14SGPropertyNode14setDoubleValueEd"
_RUN = "_ZN6JSBSim9FGFDMExec3RunEv"
_VTABLE_EXEC = "_ZTVN6JSBSim9FGFDMExecE"
_VTABLE_NODE = "_ZTV14SGPropertyNode"
_VPTR_OFFSET = 16
"""Itanium C++ ABI: an object's virtual-table pointer points past the table's offset-to-top and type_info words."""
_OBJECT_HEAD = 16
"""CPython's PyObject header (reference count, type), bytes; a Cython wrapper's fields follow it."""
_WORD = 8


@dataclass(frozen=True)
class Library:
    """The addresses of the three functions and the two virtual tables, in this process."""

    get_fn: int
    set_fn: int
    run_fn: int
    vptr_exec: int
    vptr_node: int

    def exec_pointer(self, wrapper: Any) -> int | None:
        """The FGFDMExec* held by the Python FGFDMExec `wrapper`, or None when no field checks out."""
        return _checked_fields([wrapper], self.vptr_exec)[0]

    def node_pointer(self, wrapper: Any) -> int | None:
        """The SGPropertyNode* held by the Python FGPropertyNode `wrapper`, or None when no field checks out or
        its value read through the pointer differs (in bits) from wrapper.get_double_value()."""
        return self.node_pointers([wrapper])[0]

    def node_pointers(self, wrappers: Sequence[Any]) -> list[int | None]:
        """node_pointer of each of `wrappers` (their fields read in one pass over /proc/self/mem)."""
        get = _getter(self.get_fn)
        out: list[int | None] = []
        for w, p in zip(wrappers, _checked_fields(wrappers, self.vptr_node), strict=True):
            if p is not None and struct.pack("<d", get(p)) != struct.pack("<d", w.get_double_value()):
                p = None
            out.append(p)
        return out


def library(extension_path: str) -> Library | None:
    """The entry points of the jsbsim extension module at `extension_path` (already imported), or None when this
    process cannot use them (not CPython on x86-64 Linux, a symbol missing, or APPROACHSIM_JSBSIM_DIRECT=0)."""
    if os.environ.get(ENV_SWITCH, "1").strip() == "0":
        return None
    return _library(extension_path)


@functools.cache
def _library(extension_path: str) -> Library | None:
    if (sys.implementation.name != "cpython" or not sys.platform.startswith("linux")
            or platform.machine() != "x86_64" or struct.calcsize("P") != _WORD):
        return None
    try:
        lib = ctypes.CDLL(extension_path)  # the loaded module's own handle: dlopen of a loaded file
        fns = [ctypes.cast(getattr(lib, name), ctypes.c_void_p).value for name in (_GET, _SET, _RUN)]
        tables = [ctypes.addressof(ctypes.c_char.in_dll(lib, name)) for name in (_VTABLE_EXEC, _VTABLE_NODE)]
    except (OSError, AttributeError, ValueError):
        return None
    if not all(fns):
        return None
    return Library(fns[0], fns[1], fns[2], tables[0] + _VPTR_OFFSET, tables[1] + _VPTR_OFFSET)


@functools.cache
def _getter(address: int) -> Callable[[int], float]:
    """double f(void*) at `address`, callable from Python (the check of a node's pointer)."""
    return ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p)(address)


def _checked_fields(wrappers: Sequence[Any], vptr: int) -> list[int | None]:
    """For each wrapper, the one pointer among its fields whose object starts with `vptr`; None when none or
    several different ones do."""
    fields = []
    for w in wrappers:
        size = type(w).__basicsize__
        words = [struct.unpack("<Q", ctypes.string_at(id(w) + offset, _WORD))[0]
                 for offset in range(_OBJECT_HEAD, size - _WORD + 1, _WORD)]
        fields.append([p for p in words if p])
    heads = _read_words([p for f in fields for p in f])  # the first word of each field's object, one pass
    out: list[int | None] = []
    start = 0
    for f in fields:
        found = {p for p, head in zip(f, heads[start:start + len(f)], strict=True) if head == vptr}
        start += len(f)
        out.append(found.pop() if len(found) == 1 else None)
    return out


def _read_words(addresses: Sequence[int]) -> list[int | None]:
    """The 8-byte words at `addresses` of this process, None where the memory cannot be read (no crash).
    /proc/self/mem is opened per call: an inherited descriptor would read the parent's memory after a fork."""
    try:
        fd = os.open("/proc/self/mem", os.O_RDONLY)
    except OSError:
        return [None] * len(addresses)
    try:
        out: list[int | None] = []
        for a in addresses:
            try:
                b = os.pread(fd, _WORD, a)
            except (OSError, OverflowError, ValueError):
                b = b""
            out.append(struct.unpack("<Q", b)[0] if len(b) == _WORD else None)
        return out
    finally:
        os.close(fd)
