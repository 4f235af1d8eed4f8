"""Numba's file cache is keyed by the sources of the compiled floor (approachsim/core/__init__.py): a kernel that
calls another module's kernel (core/loop/closed_step.py -> core/loop/nav_row.py) never runs a stale cached callee,
and editing a module outside core keeps the cache (no recompilation)."""

from __future__ import annotations

import os
import subprocess
import sys


def _cache_dir(env: dict[str, str]) -> str:
    code = "import os, approachsim.core; print(os.environ.get('NUMBA_CACHE_DIR', ''))"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return out.stdout.strip()


def test_cache_dir_is_keyed_by_the_kernel_sources_and_a_preset_one_is_kept(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"} | {"XDG_CACHE_HOME": str(tmp_path)}
    d = _cache_dir(env)
    parent, key = os.path.split(d)
    assert parent == str(tmp_path / "approachsim" / "numba") and len(key) == 16 and int(key, 16) >= 0
    assert os.path.isdir(d) and _cache_dir(env) == d  # the same sources: the same cache
    stale = tmp_path / "approachsim" / "numba" / "0123456789abcdef"
    stale.mkdir()
    os.utime(stale, (0, 0))  # another version's cache, unused since 1970: removed
    assert _cache_dir(env) == d and not stale.exists()
    assert _cache_dir(env | {"NUMBA_CACHE_DIR": str(tmp_path / "mine")}) == str(tmp_path / "mine")


def test_cache_dir_is_keyed_by_the_cpu_target(tmp_path):
    """The same sources compiled for another CPU (a 'generic' target, or another model's name and features) get
    another cache directory: a home directory shared between CPU models never loads another model's kernels."""
    from pathlib import Path

    import approachsim.core

    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")} | {"XDG_CACHE_HOME": str(tmp_path)}
    env.pop("NUMBA_CACHE_DIR", None)
    host = _cache_dir(env)
    generic = _cache_dir(env | {"NUMBA_CPU_NAME": "generic"})
    other = _cache_dir(env | {"NUMBA_CPU_NAME": "skylake", "NUMBA_CPU_FEATURES": "+sse2,+avx2,+fma"})
    assert len({host, generic, other}) == 3
    assert _cache_dir(env | {"NUMBA_CPU_NAME": "generic"}) == generic  # and stable for one target
    pkg = Path(approachsim.core.__file__).resolve().parents[1]
    a = approachsim.core._numba_cache_key(pkg, "x86_64-unknown-linux-gnu|haswell|+avx2,+fma")
    b = approachsim.core._numba_cache_key(pkg, "x86_64-unknown-linux-gnu|haswell|+avx2,-fma")
    assert a != b  # one feature differs: another key


_KERNEL = """
import numba

@numba.njit(cache=True)
def axpy(a, x, y):
    return a * x + y
"""


def _cache_hits(tmp_path, env: dict[str, str]) -> int:
    """Run the cached toy kernel in a fresh process; how many of its signatures numba loaded from the cache."""
    code = "import toykernel; toykernel.axpy(2.0, 3.0, 4.0); print(len(toykernel.axpy.stats.cache_hits))"
    out = subprocess.run([sys.executable, "-c", code], env=env | {"PYTHONPATH": str(tmp_path)}, capture_output=True,
                         text=True, check=True, cwd=tmp_path)
    return int(out.stdout.strip())


def test_numba_does_not_load_a_kernel_cached_for_another_cpu(tmp_path):
    """The second guard, for a NUMBA_CACHE_DIR set by hand and shared: numba's index keys every cached kernel by the
    target CPU name and features, so a kernel cached for the generic target is compiled anew for this CPU, and
    loaded again for the generic target."""
    (tmp_path / "toykernel.py").write_text(_KERNEL, encoding="utf-8")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")}
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "shared-cache")
    generic = env | {"NUMBA_CPU_NAME": "generic"}
    assert _cache_hits(tmp_path, generic) == 0  # compiled and saved for the generic target
    assert _cache_hits(tmp_path, generic) == 1  # loaded for the same target
    assert _cache_hits(tmp_path, env) == 0  # this CPU: not the generic kernel, compiled anew
    assert _cache_hits(tmp_path, env) == 1


def test_editing_a_stage_keeps_the_cache_and_editing_core_starts_a_fresh_one(tmp_path):
    """The cache key covers core/ (and the units and geo constants the kernels freeze) alone: a copy of the package
    with a stage module edited (loop/closed_loop.py, flight/run.py: the loop's wiring) has the same key, so the
    first evaluate after such an edit loads every kernel from the cache; an edited kernel module gets a new key."""
    import shutil
    from pathlib import Path

    import approachsim.core

    src = Path(approachsim.core.__file__).resolve().parents[1]
    pkg = tmp_path / "approachsim"
    shutil.copytree(src, pkg, ignore=shutil.ignore_patterns("__pycache__", "data"))
    target = "x86_64-unknown-linux-gnu|haswell|+avx2,+fma"
    key = approachsim.core._numba_cache_key(pkg, target)
    assert key == approachsim.core._numba_cache_key(src, target)
    for stage in ("loop/closed_loop.py", "flight/run.py", "sensors/baro.py", "campaign/integrity_bank.py"):
        with (pkg / stage).open("a", encoding="utf-8") as f:
            f.write("\n# edited\n")
        assert approachsim.core._numba_cache_key(pkg, target) == key, stage
    numba_users = [p.relative_to(pkg).as_posix() for p in pkg.rglob("*.py")
                   if "import numba" in p.read_text(encoding="utf-8") or "from numba" in p.read_text(encoding="utf-8")]
    assert numba_users and all(p.startswith("core/") for p in numba_users), numba_users
    with (pkg / "core/nav/kalman.py").open("a", encoding="utf-8") as f:
        f.write("\n# edited\n")
    assert approachsim.core._numba_cache_key(pkg, target) != key
