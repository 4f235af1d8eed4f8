"""approachsim: does this aircraft's navigation system meet CAT I, II or III precision-approach accuracy?

A JSBSim transport jet flies the glidepath (truth); sensor models corrupt the truth; a strapdown INS with
a baro damping loop and an error-state EKF estimates the state; the autopilot flies on that estimate; the
evaluator scores navigation error at the decision heights against the FAA/ICAO limits over Monte Carlo runs.
"""

import hashlib as _hashlib
import os as _os
import time as _time
from pathlib import Path as _Path

__version__ = "0.1.0"


def _numba_target() -> str:
    """The machine code numba will emit: LLVM target triple, CPU name and CPU features (NUMBA_CPU_NAME and
    NUMBA_CPU_FEATURES as numba reads them: a 'generic' CPU gets no features, SSE2 only, no FMA). Kernels cached for
    one CPU model must not load on another (another instruction set, or illegal instructions)."""
    try:
        import llvmlite.binding as ll
    except ImportError:  # pragma: no cover - numba's own dependency
        return "unknown"
    name = _os.environ.get("NUMBA_CPU_NAME") or ll.get_host_cpu_name()
    feats = _os.environ.get("NUMBA_CPU_FEATURES")
    if feats is None:
        feats = "" if name.lower() == "generic" else ll.get_host_cpu_features().flatten()
    return f"{ll.get_process_triple()}|{name}|{feats}"


def _numba_cache_key(pkg: _Path, target: str) -> str:
    """16 hex digits of a hash of every numba module's source under pkg and of the target (_numba_target)."""
    h = _hashlib.sha256(target.encode() + b"\0")
    for f in sorted(pkg.rglob("*.py")):
        b = f.read_bytes()
        if b"numba" in b:
            h.update(f.relative_to(pkg).as_posix().encode() + b"\0" + b + b"\0")
    return h.hexdigest()[:16]


def _numba_cache_dir() -> None:
    """Point numba's file cache (the kernels' cache=True) at a directory named by a hash of every module of this
    package that uses numba and of the CPU target, unless NUMBA_CACHE_DIR is set already. Numba invalidates a cached
    kernel only when its own file changes, not when a kernel it calls from another module does (flight/kernels.py
    calls nav/kernels/inloop.py): a stale cache would run the old callee. Keyed by all their sources and by the CPU
    name and features, any change of either starts a fresh cache (about 9 MB, a minute to build), so a home directory
    shared between machines of different CPU models never loads another model's code (numba's own index also keys
    its entries by CPU: the second guard); caches unused for 14 days are removed."""
    if "NUMBA_CACHE_DIR" in _os.environ:
        return
    pkg = _Path(__file__).resolve().parent
    root = _Path(_os.environ.get("XDG_CACHE_HOME") or _Path.home() / ".cache") / "approachsim" / "numba"
    here = root / _numba_cache_key(pkg, _numba_target())
    try:
        here.mkdir(parents=True, exist_ok=True)
        _os.utime(here)
        for old in root.iterdir():
            if old != here and _time.time() - old.stat().st_mtime > 14 * 86400:
                import shutil

                shutil.rmtree(old, ignore_errors=True)
    except OSError:
        return  # no writable cache: numba's default (next to the sources)
    _os.environ["NUMBA_CACHE_DIR"] = str(here)


_numba_cache_dir()
