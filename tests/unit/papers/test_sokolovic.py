"""Seed 003 reproduction (Sokolovic, Dikic & Stancic): Table 2 ordering over 100 seeded runs, and its findings."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim.commands.reproduce import reproduce
from approachsim.nav import vertical_loop as vl
from approachsim.papers import sokolovic as sk


@pytest.fixture(scope="module")
def runs_100() -> sk.SokolovicRuns:
    return sk.simulate(sk.SokolovicParams(), seed=2026, runs=100)


def _paired(res: sk.SokolovicRuns, a: str, b: str, q: str) -> tuple[float, float]:
    """Mean over runs of rms(a) - rms(b) per run (same noise in both: common random numbers), and its standard
    error."""
    data = res.h_err_m if q == "altitude_m" else res.vd_err_mps
    diff = np.sqrt(np.mean(data[a] ** 2, axis=1)) - np.sqrt(np.mean(data[b] ** 2, axis=1))
    return float(diff.mean()), float(diff.std(ddof=1) / np.sqrt(diff.size))


@pytest.mark.parametrize("q", ["altitude_m", "velocity_mps"])
def test_sinh_gains_beat_constant_gains_over_100_runs(runs_100: sk.SokolovicRuns, q: str) -> None:
    """Table 2: rms with sinh adaptation below the constant-gain rms (reproduced): the paired difference is
    positive by more than 3 standard errors."""
    d, se = _paired(runs_100, "constant", "sinh", q)
    assert d > 3 * se


@pytest.mark.parametrize("q", ["altitude_m", "velocity_mps"])
def test_finding_tanh_does_not_beat_constant_with_the_printed_gains(runs_100: sk.SokolovicRuns, q: str) -> None:
    """Not reproduced (finding, see sokolovic.md): tanh saturates at C1KF = 0.06 m/s, below the constant C1 e for
    |e| > 2 m, and the gap errors reach several metres: tanh's rms is above the constant one."""
    d, se = _paired(runs_100, "tanh", "constant", q)
    assert d > 3 * se
    p = sk.SokolovicParams()
    k1_tanh, _ = vl.branch_corrections(p.gains("tanh"), np.array([3.0]))
    k1_const, _ = vl.branch_corrections(p.gains("constant"), np.array([3.0]))
    assert k1_tanh[0] < k1_const[0]


def test_tanh_beats_constant_when_gap_errors_stay_small() -> None:
    """The mechanism: with a 100x lower accelerometer noise power the errors stay well below the 2 m design
    difference, where tanh (slope C1KF b = 0.06 /s) damps harder than the constant loop (0.03 /s)."""
    p = replace(sk.SokolovicParams(), accel_noise_mps2=0.005)
    t = sk.table_2(sk.simulate(p, seed=7, runs=40, forms=("constant", "tanh")))
    assert t["tanh"]["altitude_m"]["rms"]["mean"] < t["constant"]["altitude_m"]["rms"]["mean"]


def test_errors_are_gps_accurate_while_gps_is_present() -> None:
    res = sk.simulate(sk.SokolovicParams(), seed=3, runs=10, forms=("constant",))
    on = res.gps_on.copy()
    on[1:] &= res.gps_on[:-1]
    rms_on = np.sqrt(np.mean(res.h_err_m["constant"][:, on] ** 2))
    rms_gap = np.sqrt(np.mean(res.h_err_m["constant"][:, ~res.gps_on] ** 2))
    assert rms_on < 0.05  # GPS position noise 0.05 m, filtered
    assert rms_gap > 10 * rms_on


def test_printed_constant_gains_are_stable_but_not_eq5() -> None:
    p = sk.SokolovicParams()
    poles = vl.closed_loop_poles(p.gains("constant"))
    assert np.all(poles.real < 0)
    assert np.max(np.abs(poles + 0.01)) > 1e-3  # not the triple pole at -1/tau = -0.01 of eq. 5
    eq5 = vl.constant_gains(3.0 / p.gains_constant[0])
    assert eq5.c2 == pytest.approx(3.0308e-4, rel=1e-4) and eq5.c3 == pytest.approx(1e-6)
    for form in ("tanh", "sinh"):
        assert np.all(vl.closed_loop_poles(p.gains(form)).real < 0)


@pytest.mark.slow
def test_reproduce_writes_the_tables_side_by_side(tmp_path: Path) -> None:
    result = reproduce("sokolovic", tmp_path, seed=1, runs=4)
    on_disk = json.loads((tmp_path / "sokolovic.json").read_text())
    assert on_disk["table_2"]["paper"] == sk.PAPER_TABLE_2
    ours = on_disk["table_2"]["ours"]
    for form, quantities in sk.PAPER_TABLE_2.items():
        for q, cols in quantities.items():
            assert set(ours[form][q]) == set(cols)
            assert all(np.isfinite(ours[form][q][c]["mean"]) for c in cols)
    assert result["verdict"] == on_disk["verdict"]
    note = (tmp_path / "sokolovic.md").read_text()
    assert "Disagreements" in note and "tanh vs constant" in note
    for name in ("sokolovic_fig3.png", "sokolovic_fig5.png", "sokolovic_fig6.png", "sokolovic_fig7.png"):
        assert (tmp_path / name).stat().st_size > 1000
