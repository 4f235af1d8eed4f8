"""The compiled floor: every numba kernel of approachsim, one copy per formula.

Plain float arrays in and out, SI inside, each kernel a small pure function with the equation it implements in its
docstring, compiled with ``cache=True``. The stages above (sensors, nav, flight, integrity) hold the readable models,
the numpy oracles the kernels are tested against, and the composition; the kernels import nothing of them: only
numpy, math, and the constants of `approachsim.units` and `approachsim.geo` (import-linter contracts in
pyproject.toml: core imports no stage, and nothing outside core imports numba or llvmlite). Numba's cache is keyed
by this package's sources alone (approachsim/__init__.py), so editing a stage never recompiles a kernel.

    geodesy        WGS-84 radii, geodetic -> ECEF, the simulated world's gravity (geo.py's equations, scalar)
    entry          a dispatcher's compiled entry point, called without numba's per-call typing (numba internals)
    warm           a campaign's kernels compiled ahead on a cold cache, a share per worker (manifests/*.pkl)
    sensors/       the sensor models' error application (each sensor module's `apply`; oracle `apply_reference`)
        imu, noise, baro, radalt, pseudolite, gnss (orbits, look angles, selection, pseudoranges and rates)
        gnss_errors   each GNSS range-error formula once (DO-229 tropo mapping, iono obliquity, DO-253 multipath,
                      the filter's channel sigmas, the GBAS scales), scalar
    nav/           the navigation stage's arithmetic
        strapdown     the strapdown INS mechanization over many runs and IMU intervals (nav/ins.py)
        output        the navigation output of every row, INS - x_hat(t) (the estimate carried by its rate)
        errormodel    the error model's F, Qc and their discretization Phi, Qd (nav/errormodel.py)
        kalman        sparse predict, scalar Joseph update, shared-covariance update, the Riccati segment
        measurements  the baro, radar-altimeter and pseudorange rows with their innovations (nav/measurements.py)
        carrier       the carrier-phase states' dynamics, float-ambiguity resets and rows
        epoch         a filter epoch of one run, of a shared-covariance class or of N copies, and the whole
                      open-loop pass
        copies        the integrity bank's filter copies (campaign/bankpass.py)
        groups        the epoch kernels' grouped arguments (named tuples: rows, observations, outputs, scratch)
        reduced       the reduced-order filter's dropped channels (nav/reduced.py)
    loop/          the compiled flight loop and the closed loop inside it
        flight_step   one flight step: the IMU-point truth row, turbulence, autopilot, stabilized-approach monitor,
                      termination (flight/run.py; oracles in flight/)
        nav_row       the closed loop's navigation row inside the flight step
        aiding        the closed loop's aiding-epoch inputs and epoch (loop/closed_loop.py)
        closed_step   the flight step with the navigation row (nav_row) and the autopilot on it
        direct        the loop with JSBSim's property reads, writes and steps called from compiled code
        jsbsim_abi    the JSBSim wheel's C++ entry points, found and checked (ctypes; the guard of `direct`)

One aiding epoch of one run from preallocated arrays (what a compiled per-run loop calls):

    errormodel.dynamics(lay, q, gse, gmp, lat, h, v_ned, f_ned, c_bn, loop, held, F, Qc)
    errormodel.discretize(F, Qc, dt, phi, qd)      # False: too large for the Taylor series, use the numpy path
    kalman.predict(x, P, phi, qd, ws)
    nu, r = measurements.pseudorange(lay, x, r_ins, c_en, r_sv, rho, sigma, sv, -1, h)   # or baro, radalt
    S = kalman.update(x, P, h, nu, r, b, ws)       # optimal; kalman.gain + kalman.joseph with a gain policy
"""

import hashlib as _hashlib
import os as _os
import time as _time
from pathlib import Path as _Path


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
    """16 hex digits of a hash of the compiled floor's sources (every module under pkg/core, the only package that
    imports numba: an import-linter contract) and of the target (_numba_target). What the kernels read of the rest
    of the package (units' and geo's constants) is frozen into them at compile time, so those two modules count
    too; editing any other module keeps the cache (tests/unit/test_numba_cache_dir.py)."""
    h = _hashlib.sha256(target.encode() + b"\0")
    for f in [*sorted((pkg / "core").rglob("*.py")), pkg / "units.py", pkg / "geo.py"]:
        h.update(f.relative_to(pkg).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def _numba_cache_dir() -> None:
    """Point numba's file cache (the kernels' cache=True) at a directory named by a hash of the compiled floor
    (approachsim/core) and of the CPU target, unless NUMBA_CACHE_DIR is set already. Numba invalidates a cached
    kernel only when its own file changes, not when a kernel it calls from another module does (core/loop/
    closed_step.py calls core/loop/nav_row.py): a stale cache would run the old callee. Keyed by all their sources
    and by the CPU name and features, any change of either starts a fresh cache (about 9 MB, a minute to build),
    so a home directory shared between machines of different CPU models never loads another model's code (numba's
    own index also keys its entries by CPU: the second guard); caches unused for 14 days are removed."""
    if "NUMBA_CACHE_DIR" in _os.environ:
        return
    pkg = _Path(__file__).resolve().parent.parent
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
