"""Sokolovic, Dikic & Stancic reproduction: Table 2 ordering over 100 seeded runs, its findings, and the model
against an independent reference (the covariance of the linear constant-gain loop propagated through a GPS gap,
written here from the paper's eq. 3, not the package's code)."""

from __future__ import annotations

import copy
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sl

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


def _reference_gap_mean_square(p: sk.SokolovicParams) -> float:
    """Expected mean-square altitude error over a GPS gap of the constant-gain loop (eq. 3), from its own
    continuous model discretized exactly: state [dh, dv, da_c, B, b_acc],
        dh' = dv - C1 e,  dv' = (2 g / R) dh - C2 e - da_c + b_acc + w_a,  da_c' = C3 e,  B' = -B / tau + w_B,
    e = dh - B - v_B; per-sample accelerometer noise w_a and baro noise v_B (Table 1), the gap starting from the
    GPS-reset state (dh = dv = da_c = 0). P(k+1) = Phi P Phi' + Q, averaged over the gap's samples."""
    c1, c2, c3 = p.gains_constant
    dt = p.dt_s
    A = np.zeros((5, 5))
    A[0, :] = [-c1, 1, 0, c1, 0]
    A[1, :] = [2 * 9.80665 / 6.371e6 - c2, 0, -1, c2, 1]
    A[2, :] = [c3, 0, 0, -c3, 0]
    A[3, 3] = -1 / p.baro_tau_s
    phi = sl.expm(A * dt)
    g_baro = np.array([c1, c2, -c3, 0, 0]) * dt
    g_acc = np.array([0, dt, 0, 0, 0])
    Q = np.outer(g_baro, g_baro) * p.baro_noise_m**2 + np.outer(g_acc, g_acc) * p.accel_noise_mps2**2
    Q[3, 3] = p.baro_bias_m**2 * (1 - np.exp(-2 * dt / p.baro_tau_s))
    P = np.diag([0.0, 0.0, 0.0, p.baro_bias_m**2, p.accel_bias_mps2**2])
    var = []
    a, b = p.gps_gaps_s[0]
    # every gap the same length: one reference (exact: differences of whole seconds < 2^53 are exact)
    assert all(g[1] - g[0] == b - a for g in p.gps_gaps_s)
    for _ in range(int(round((b - a) / dt))):
        P = phi @ P @ phi.T + Q
        var.append(P[0, 0])
    return float(np.mean(var))


def test_constant_loop_gap_errors_match_the_reference_covariance(runs_100: sk.SokolovicRuns) -> None:
    """The Monte Carlo mean-square altitude error in the gaps (per run, then over 100 runs) equals the reference
    covariance's, within 3 standard errors of the 100-run mean (measured: 7.37 m^2 reference)."""
    p = sk.SokolovicParams()
    gap = ~runs_100.gps_on
    ms = (runs_100.h_err_m["constant"][:, gap] ** 2).mean(axis=1)
    ref = _reference_gap_mean_square(p)
    se = ms.std(ddof=1) / np.sqrt(ms.size)
    assert abs(ms.mean() - ref) < 3 * se, (ms.mean(), se, ref)


def test_tanh_saturation_crossover_is_analytic() -> None:
    """C1KF tanh(b e) = C1 e at e* solving tanh(x) = (C1 / (C1KF b)) x; for |e| > C1KF / C1 the constant
    correction exceeds tanh's largest: the 2.0 m the note compares the gap errors with."""
    from scipy.optimize import brentq

    p = sk.SokolovicParams()
    c1, c1kf = p.gains_constant[0], p.gains_tanh[0]
    x = brentq(lambda x: np.tanh(x) - c1 / (c1kf * p.b_per_m) * x, 0.5, 10.0)
    assert 0.0 < x / p.b_per_m < c1kf / c1 == pytest.approx(2.0)
    k1, _ = vl.branch_corrections(p.gains("tanh"), np.array([x / p.b_per_m, 5.0]))
    assert k1[0] == pytest.approx(c1 * x / p.b_per_m, rel=1e-9)  # the package's branch crosses C1 e there
    assert k1[1] < c1 * 5.0


def _fake_runs(offsets: dict[str, float], runs: int = 30) -> sk.SokolovicRuns:
    rng = np.random.default_rng(4)
    base = rng.normal(0.0, 1.0, (runs, 50))
    t = np.arange(50.0)
    res = sk.SokolovicRuns(t, np.ones(50, dtype=bool))
    for f, k in offsets.items():
        res.h_err_m[f] = base * k + 0.01 * rng.normal(size=base.shape)
        res.vd_err_mps[f] = 0.1 * res.h_err_m[f]
    return res


def test_verdict_against_constructed_runs() -> None:
    """The verdict's ordering on runs whose answer is known: the paper's order, its reverse, no difference."""
    v = sk.verdict(_fake_runs({"constant": 1.3, "tanh": 1.15, "sinh": 1.0}))
    assert v["altitude_rms_order_constant_tanh_sinh"] and v["velocity_rms_order_constant_tanh_sinh"]
    assert v["altitude_paired_m"]["constant-sinh"]["relation"] == ">"
    v = sk.verdict(_fake_runs({"constant": 1.0, "tanh": 1.3, "sinh": 1.15}))
    assert not v["altitude_rms_order_constant_tanh_sinh"]
    assert v["altitude_paired_m"]["constant-tanh"]["relation"] == "<"
    v = sk.verdict(_fake_runs({"constant": 1.0, "tanh": 1.0, "sinh": 1.0}))
    assert {c["relation"] for c in v["altitude_paired_m"].values()} == {"~"}


@pytest.mark.slow
def test_reproduce_writes_the_tables_side_by_side(tmp_path: Path) -> None:
    result = reproduce("sokolovic", tmp_path, seed=1, runs=4)
    on_disk = json.loads((tmp_path / "sokolovic.json").read_text())
    ours = on_disk["table_2"]["ours"]
    for form, quantities in sk.PAPER_TABLE_2.items():
        for q, cols in quantities.items():
            assert set(ours[form][q]) == set(cols)
            assert all(np.isfinite(ours[form][q][c]["mean"]) for c in cols)
    note = (tmp_path / "sokolovic.md").read_text()
    assert "Disagreements" in note and "tanh vs constant" in note
    for name in ("sokolovic_fig3.png", "sokolovic_fig5.png", "sokolovic_fig6.png", "sokolovic_fig7.png"):
        assert (tmp_path / name).stat().st_size > 1000
    # the note's findings follow the numbers: force the paper's ordering and the opposite into the verdict
    for rel, tanh_words, verb in ((">", "tanh's altitude errors are smaller than", "reproduces"),
                                  ("<", "tanh's altitude errors are larger than", "does NOT reproduce")):
        r = copy.deepcopy(result)
        for key in ("constant-tanh", "tanh-sinh", "constant-sinh"):
            r["verdict"]["altitude_paired_m"][key]["relation"] = rel
        r["verdict"]["altitude_rms_order_constant_tanh_sinh"] = rel == ">"
        text = sk.note(r, [])
        assert tanh_words in text, rel
        assert f"altitude: Table 2's order constant > tanh > sinh {verb}" in text, rel
