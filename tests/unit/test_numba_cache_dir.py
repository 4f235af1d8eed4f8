"""Numba's file cache is keyed by the sources of every numba module (approachsim/__init__.py): a kernel that calls
another module's kernel (flight/kernels.py -> nav/kernels/inloop.py) never runs a stale cached callee."""

from __future__ import annotations

import os
import subprocess
import sys


def _cache_dir(env: dict[str, str]) -> str:
    code = "import os, approachsim; print(os.environ.get('NUMBA_CACHE_DIR', ''))"
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
