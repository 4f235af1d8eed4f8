"""Compile a kind of run's kernel manifest on a fresh numba cache and report what makes compiling slow:
(1) array-valued slice assignments in core kernels (numba compiles a unicode shape-mismatch message for each,
about 3 s a process: write a loop, kalman.copy_2d); (2) kernels compiled for more than one signature, with the
arguments that differ (literal constants, array layouts, readonly arrays).

    python tools/kernel_scan.py [closed|open ...]
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import sys
import tempfile

os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp()  # cold: compile everything, so typed IR is there

from numba.core import ir, types  # noqa: E402
from numba.core.registry import CPUDispatcher  # noqa: E402

import approachsim.core as core  # noqa: E402
from approachsim.core import warm  # noqa: E402


def _dispatchers():
    for m in pkgutil.walk_packages(core.__path__, "approachsim.core."):
        mod = importlib.import_module(m.name)
        for name, obj in vars(mod).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == m.name:
                yield f"{m.name.removeprefix('approachsim.core.')}.{name}", obj


def main() -> int:
    for kind in sys.argv[1:] or ["closed"]:
        warm.compile_entries(warm.load(kind))
    setitems, multi = set(), []
    for name, disp in _dispatchers():
        sigs = list(disp.overloads)
        if len(sigs) > 1:
            diffs = [[(i, str(a)) for i, (a, b) in enumerate(zip(s, sigs[0], strict=True)) if a != b] for s in sigs[1:]]
            multi.append((name, len(sigs), diffs))
        for cres in disp.overloads.values():
            ta = getattr(cres, "type_annotation", None)
            for inst, sig in (ta.calltypes.items() if ta is not None else ()):
                if (isinstance(inst, (ir.SetItem, ir.StaticSetItem)) and sig is not None and len(sig.args) == 3
                        and isinstance(sig.args[2], types.Array)):
                    setitems.add(f"{name} line {inst.loc.line}: {sig.args[0]} <- {sig.args[2]}")
    print(f"array-valued slice assignments: {len(setitems)}")
    for s in sorted(setitems):
        print("  ", s)
    print(f"kernels with more than one signature: {len(multi)}")
    for name, n, diffs in multi:
        print(f"   {name} x{n}: " + "; ".join(str(d) for d in diffs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
