"""Packaging: a wheel built from the checkout, installed into a fresh virtual environment, evaluates a profile
copied out of the package from a directory with no repository at hand (issue 13's acceptance test).

Slow (about three minutes on 2 cores: wheel build, dependency install from the package index or the machine's
wheel cache, the fresh install's numba kernels compiled, 2 closed-loop JSBSim approaches). One worker process: the
kernels compile once (about 110 s of CPU here), not once in each of two workers at the same time.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _run(cmd: list[str], cwd: Path, env: dict, timeout: float) -> subprocess.CompletedProcess:
    out = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert out.returncode == 0, f"{' '.join(cmd)} exited {out.returncode}:\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}"
    return out


@pytest.mark.slow
def test_wheel_in_fresh_venv_evaluates_a_copied_profile(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["MPLBACKEND"] = "Agg"
    wheels = tmp_path / "wheels"
    _run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "-w", str(wheels), str(ROOT)],
         cwd=tmp_path, env=env, timeout=300)
    (wheel,) = wheels.glob("approachsim-*.whl")
    venv.EnvBuilder(with_pip=True).create(tmp_path / "venv")
    bindir = tmp_path / "venv" / ("Scripts" if os.name == "nt" else "bin")
    py = bindir / "python"
    _run([str(py), "-m", "pip", "install", "--quiet", str(wheel)], cwd=tmp_path, env=env, timeout=600)
    work = tmp_path / "elsewhere"
    work.mkdir()
    exe = str(bindir / "approachsim")

    where = _run([str(py), "-c", "import approachsim; print(approachsim.__file__)"], cwd=work, env=env, timeout=60)
    assert Path(where.stdout.strip()).is_relative_to(tmp_path / "venv"), where.stdout  # the wheel, not the clone
    listing = _run([exe, "profiles"], cwd=work, env=env, timeout=60).stdout
    assert "default" in listing and "hot-high-crosswind" in listing

    _run([exe, "profiles", "init", "default", "x"], cwd=work, env=env, timeout=60)
    assert (work / "x" / "default.toml").is_file()
    _run([exe, "evaluate", "x/default.toml", "--runs", "2", "--workers", "1", "--out", "out"], cwd=work, env=env,
         timeout=600)
    summary = json.loads((work / "out" / "summary.json").read_text())
    assert summary["runs"] == 2
    assert summary["failed_runs"] == 0  # the aircraft file came from the installed package
    assert (work / "out" / "report.html").is_file()
