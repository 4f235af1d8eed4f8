"""The seed pool of the consistency tool (tools/consistency_by_state.py pool_seeds, issue 38's consistency point):
on synthetic seeds whose run-averaged ratios are drawn as a consistent filter's (chi2(R d) / (R d)) it must find
nothing, and on seeds of a filter that over-claims by 20 % it must see the shift in every statistic."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("consistency_by_state", ROOT / "tools" / "consistency_by_state.py")
cb = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cb)

RUNS = 60
DOF = np.array([1.0, 1.7, 7.0])
"""Degrees of freedom per run of three states: a clock-like slow state, a position, a velocity."""


def _seeds(n_seeds: int, scale: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    n = RUNS * DOF
    r = np.random.default_rng(seed).chisquare(n, size=(n_seeds, DOF.size)) / n * scale
    return r, np.broadcast_to(DOF, r.shape).copy()


def test_consistent_seeds_pass() -> None:
    p = cb.pool_seeds(*_seeds(400, 1.0, 11), RUNS)
    # the pooled mean's standard error is sqrt(2 / (R d) / S): within 4 of them of 1
    assert np.all(np.abs(p["mean"] - 1.0) < 4.0 * np.sqrt(2.0 / (RUNS * DOF) / 400))
    assert np.allclose(p["sd_expected"], np.sqrt(2.0 / (RUNS * DOF)))
    # the seeds' spread within 15 % of sampling (S = 400: the sd's own relative sd is about 1 / sqrt(2 S) = 3.5 %)
    assert np.all(np.abs(p["sd"] / p["sd_expected"] - 1.0) < 0.15)
    assert np.all(p["outside"] <= 0.05 * 400 + 4.0 * math.sqrt(400 * 0.05 * 0.95))
    assert np.all(p["ks_p"] > 1e-3)
    assert np.allclose(p["lo"], chi2.ppf(0.025, RUNS * DOF) / (RUNS * DOF))


def test_over_claiming_filter_is_seen() -> None:
    p = cb.pool_seeds(*_seeds(40, 0.8, 12), RUNS)
    se = np.sqrt(2.0 / (RUNS * DOF) / 40) * 0.8
    assert np.all(np.abs(p["mean"] - 0.8) < 4.0 * se)
    # the velocity-like state (7 dof per run) is outside its interval at most seeds; the test's p-values vanish
    assert p["outside"][2] > 30 and p["p_outside"][2] < 1e-10 and p["ks_p"][2] < 1e-10
    assert np.all(p["ks_p"] < 0.05)


def test_seed_pass_chance_is_chi2_sampling() -> None:
    """One seed's chance of a ratio in [0.8, 1.25] for a consistent filter: chi2(R d) / (R d) drawn 200000 times
    (the frequency's sd sqrt(p (1 - p) / 200000) < 1.2e-3: 5 of them)."""
    rng = np.random.default_rng(21)
    for d in (1.0, 1.3, 5.0):
        n = RUNS * d
        r = rng.chisquare(n, 200_000) / n
        p = np.mean((r >= 0.8) & (r <= 1.25))
        assert abs(cb.seed_pass_chance(d, RUNS) - p) < 6e-3
    assert cb.seed_pass_chance(1.0, RUNS) < 0.8 < cb.seed_pass_chance(5.0, RUNS)


def _summary(ratio: float, inside: float, above: float, dof: float = 1.3) -> dict:
    return {"ratio": [ratio], "inside": [inside], "above": [above], "dof": [dof]}


def test_pooled_acceptance_averages_the_seeds() -> None:
    """The pooled acceptance judges the seeds' means: a seed outside the band does not fail a state whose mean is
    inside; a 20 % over-claim at every seed does."""
    seeds = [_summary(1.35, 0.45, 0.55), _summary(0.95, 1.0, 0.0), _summary(0.85, 1.0, 0.0), _summary(0.9, 1.0, 0.0)]
    pc = cb.pooled(seeds, 0)
    assert pc["mean"] == pytest.approx(1.0125) and pc["seeds_pass"] == 3
    assert pc["inside"] == pytest.approx(0.8625) and not cb.pooled_passes(pc)  # the one seed's epochs above
    pc = cb.pooled([_summary(1.1, 0.97, 0.03)] + seeds[1:], 0)
    assert cb.pooled_passes(pc)
    assert not cb.pooled_passes(cb.pooled([_summary(0.78, 0.9, 0.0)] * 4, 0))


def test_tables_replace_only_their_own_block() -> None:
    """The suite's two tables (per seed, pooled) each replace their own block of a document and keep the prose
    between and after them; a document without the marks gets the table appended."""
    doc = cb.with_table("intro\n", cb.TABLE_MARK, "seed table")
    doc = cb.with_table(doc + "\n## Pooled\n\nprose\n", cb.POOL_MARK, "pooled table")
    doc = cb.with_table(doc + "\nafter\n", cb.TABLE_MARK, "seed table 2")
    doc = cb.with_table(doc, cb.POOL_MARK, "pooled table 2")
    assert doc.count(cb.END_MARK) == 2 and "seed table\n" not in doc and "pooled table\n" not in doc
    assert doc.index("seed table 2") < doc.index("## Pooled") < doc.index("prose") < doc.index("pooled table 2")
    assert doc.startswith("intro\n") and doc.rstrip().endswith("after")
