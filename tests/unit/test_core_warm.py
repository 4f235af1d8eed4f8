"""The kernel manifest (core/warm.py): shares that balance, stale entries skipped, a pool initializer that compiles
its share, and the shipped closed-loop manifest equal to what a closed-loop run of the default profile compiles."""

from __future__ import annotations

import functools
import importlib
import multiprocessing
from pathlib import Path

import numba
import numpy as np
import pytest

from approachsim.campaign.pipeline import closed_loop_group, open_loop_group
from approachsim.campaign.runner import kernels_of
from approachsim.cli import main
from approachsim.core import geodesy, warm

ROOT = Path(__file__).resolve().parents[2]


def _entries(costs: list[float]) -> list[warm.Entry]:
    return [warm.Entry("approachsim.core.geodesy", f"k{i}", (), c) for i, c in enumerate(costs)]


def test_shares_hold_every_entry_once_and_balance() -> None:
    costs = [13.5, 12.2, 10.6, 9.3, 5.0, 3.5, 2.9, 1.9, 1.8, 1.3, 1.0, 0.7, 0.3, 0.3, 0.2]
    for n in (1, 2, 3, 16):
        sh = warm.shares(_entries(costs), n)
        assert len(sh) == n
        assert sorted(e.name for s in sh for e in s) == sorted(f"k{i}" for i in range(len(costs)))
        loads = [sum(e.cost_s for e in s) for s in sh]
        # greedy longest-first: no share exceeds another by more than the largest single entry
        assert max(loads) - min(loads) <= max(costs)
    assert warm.shares(_entries(costs), 2) == warm.shares(list(reversed(_entries(costs))), 2)  # deterministic


def test_compile_entries_skips_what_no_longer_resolves_or_types() -> None:
    f8 = numba.types.float64
    good = warm.Entry("approachsim.core.geodesy", "radii", (f8,), 0.1)
    stale = [warm.Entry("approachsim.core.geodesy", "no_such_kernel", (f8,), 0.1),
             warm.Entry("approachsim.core.no_such_module", "radii", (f8,), 0.1),
             warm.Entry("approachsim.core.geodesy", "radii", (numba.types.unicode_type,), 0.1)]
    assert warm.compile_entries([*stale, good]) == 1
    assert (f8,) in geodesy.radii.signatures


def test_pool_initializer_compiles_its_share_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    f8 = numba.types.float64
    arr = numba.types.Array(f8, 2, "C")
    monkeypatch.setattr(warm, "MANIFEST_DIR", tmp_path)
    warm.save("t", [warm.Entry("approachsim.core.geodesy", "radii", (f8,), 2.0),
                    warm.Entry("approachsim.core.geodesy", "c_ecef_to_ned", (f8, f8, arr), 1.0)], numba.__version__)
    assert [e.name for e in warm.load("t")] == ["radii", "c_ecef_to_ned"]
    counter = multiprocessing.get_context("fork").Value("i", 0)
    warm.compile_share("t", counter, 2)  # share 0: the costlier entry
    warm.compile_share("t", counter, 2)  # share 1
    warm.compile_share("t", counter, 2)  # a third worker of two shares: nothing
    assert counter.value == 3
    assert (f8,) in geodesy.radii.signatures and (f8, f8, arr) in geodesy.c_ecef_to_ned.signatures
    assert warm.load("missing") == []


def test_closed_loop_group_names_its_manifest() -> None:
    assert kernels_of(closed_loop_group) == "closed"
    assert kernels_of(open_loop_group) == "open"
    assert kernels_of(functools.partial(closed_loop_group, land=True)) == "closed"
    assert kernels_of(np.mean) is None


@pytest.mark.parametrize("kind", ["closed", "open"])
def test_shipped_manifest_is_what_a_run_compiles(kind: str, tmp_path: Path) -> None:
    """Every entry of core/manifests/<kind>.pkl is a signature a run of the default profile in that mode uses: an
    entry whose call site changed types would compile, on every cold cache, a variant no run uses. When this fails,
    rerun tools/kernel_manifest.py <kind>."""
    entries = warm.load(kind)
    assert len(entries) >= 10
    assert sum(e.cost_s for e in entries) > 10.0
    code = main(["evaluate", str(ROOT / "profiles" / "default.toml"), "--runs", "1", "--workers", "1",
                 "--seed", "1", "--no-report", "--mode", kind, "--out", str(tmp_path / "e")])
    assert code in (0, 1)
    stale = [f"{e.module}.{e.name}{e.args}" for e in entries
             if e.args not in getattr(importlib.import_module(e.module), e.name).signatures]
    assert not stale, f"stale manifest entries (rerun tools/kernel_manifest.py {kind}): {stale}"
