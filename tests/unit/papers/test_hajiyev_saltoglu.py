"""Reproduction of Hajiyev & Saltoglu (seed 000): model equations, Table 1 growth, Table 2 fault claims,
asserted from Monte Carlo numbers computed here (100 seeds)."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from approachsim.commands.reproduce import reproduce
from approachsim.papers import hajiyev_saltoglu as hs

RUNS = 100


@pytest.fixture(scope="module")
def clean() -> hs.Runs:
    return hs.simulate(hs.Section7(), seed=1, runs=RUNS, faults=False)


@pytest.fixture(scope="module")
def faulty() -> hs.Runs:
    return hs.simulate(hs.Section7(), seed=1, runs=RUNS, faults=True)


def test_transition_is_eqs_1_to_5() -> None:
    p = hs.Section7()
    F = p.transition()
    x = np.array([10.0, 0.5, 0.01, 0.002, 3.0])
    y = F @ x
    dt = 0.1
    assert y[0] == pytest.approx(10.0 + dt * 0.5)  # eq. 1
    assert y[1] == pytest.approx(0.5 + 2 * 9.89 * dt / 6372.0 * 10.0 + dt * 0.01 + dt * 0.002)  # eq. 2
    assert y[2] == pytest.approx(0.01 - dt * 0.001 * 0.01)  # eq. 3
    assert y[3] == pytest.approx(0.002 - dt * 0.005 * 0.002)  # eq. 4
    assert y[4] == pytest.approx(3.0 - dt * 0.1 * 3.0)  # eq. 5
    assert hs.H_ROW @ x == pytest.approx(10.0 - 3.0)  # eq. 8 / 12


def test_ins_error_growth_against_table1(clean: hs.Runs) -> None:
    """Printed parameters (R_I = 6372 as printed) give Table 1's exponential growth within 12 % at every row;
    R_I in metres (SI) does not grow (the unit finding in the note)."""
    rows = hs.PAPER_TABLE1["rows"]
    ours = np.array([clean.dh_ins[:, k].mean() for k, *_ in rows])
    paper = np.array([r[1] for r in rows])
    assert np.all(np.abs(ours / paper - 1.0) < 0.12)
    assert ours[-1] > 7 * ours[0]  # grows ~8x from step 50 to step 500
    si = hs.ins_error_trajectory(replace(hs.Section7(), r_i=6.372e6))
    assert si[500] < 26.0  # 23 m initial error, negligible growth in SI
    # the noise-free trajectory is the exponential of the unstable vertical channel, lambda = sqrt(2 g / R_I)
    lam = np.sqrt(2 * 9.89 / 6372.0)
    det = hs.ins_error_trajectory(hs.Section7())
    assert det[500] == pytest.approx(23.0 * np.cosh(lam * 50.0), rel=0.03)


def test_integrated_error_bounded_while_ins_grows(clean: hs.Runs) -> None:
    g = hs.bounded_vs_growing(clean)
    assert g["ins_rms_steps_400_500_m"] > 3 * g["ins_rms_steps_100_200_m"]
    assert g["integrated_rms_steps_400_500_m"] < 1.2 * g["integrated_rms_steps_100_200_m"]
    assert g["integrated_rms_max_over_steps_100_500_m"] < 0.05 * g["ins_rms_steps_400_500_m"]
    # the filter is consistent: its sigma is the Monte Carlo RMS (within the 100-run sampling error)
    assert g["integrated_rms_steps_400_500_m"] == pytest.approx(g["filter_sigma_step_500_m"], rel=0.2)


def test_faults_okf_jumps_rkf_stays(faulty: hs.Runs, clean: hs.Runs) -> None:
    """Table 2's claim: at 101/201/301/401 the OKF error jumps, the RKF's stays within 1.5x of its
    pre-fault level |e(k-1)| in >= 95 % of runs."""
    p = hs.Section7()
    j = hs.fault_jumps(faulty, p, clean)
    for k in map(str, p.fault_steps):
        assert j["RKF"][k]["fraction_within_1.5x"] >= 0.95
        assert j["OKF"][k]["jump_m"]["median"] > 100 * j["RKF"][k]["jump_m"]["median"]
        assert j["OKF"][k]["fraction_within_1.5x"] < 0.6
        assert j["RKF_detection_rate"][k] >= 0.9
    assert j["OKF"]["101"]["ratio"]["median"] > 3.0  # first fault: the OKF was settled before it
    # before the first fault the two filters are the same filter, unless the gate tripped on 3-sigma noise
    quiet = (faulty.weight_rkf[:, :101] == 1.0).all(axis=1)
    assert quiet.mean() > 0.5
    np.testing.assert_allclose(faulty.est_okf[quiet, :101], faulty.est_rkf[quiet, :101], rtol=0, atol=1e-9)


def test_rkf_equals_okf_on_fault_free_data_until_a_gate_trip(clean: hs.Runs) -> None:
    tripped = (clean.weight_rkf == 0.0).any(axis=1)
    assert tripped.mean() < 0.9  # a 3-sigma gate trips rarely on fault-free data (0.27 % per step)
    np.testing.assert_allclose(clean.est_rkf[~tripped], clean.est_okf[~tripped], rtol=0, atol=1e-9)


def test_seeding_is_reproducible_and_seed_dependent() -> None:
    p = replace(hs.Section7(), steps=120)
    a = hs.simulate(p, seed=3, runs=4, faults=True)
    b = hs.simulate(p, seed=3, runs=4, faults=True)
    c = hs.simulate(p, seed=4, runs=4, faults=True)
    np.testing.assert_array_equal(a.est_okf, b.est_okf)
    assert not np.allclose(a.est_okf, c.est_okf)
    # run i of a 4-run campaign is run i of a 2-run campaign (per-run streams)
    d = hs.simulate(p, seed=3, runs=2, faults=True)
    np.testing.assert_array_equal(a.est_rkf[:2], d.est_rkf)


@pytest.mark.slow
def test_reproduce_writes_tables_note_and_figures(tmp_path) -> None:
    result = reproduce("hajiyev-saltoglu", tmp_path, seed=1, runs=8)
    data = json.loads((tmp_path / "hajiyev-saltoglu.json").read_text())
    assert data["verdict"] == result["verdict"]
    t1, t2 = data["tables"]["table1"], data["tables"]["table2"]
    assert [r["Iterations"] for r in t1["rows"]] == [r[0] for r in hs.PAPER_TABLE1["rows"]]
    assert [r["Iterations"] for r in t2["rows"]] == [r[0] for r in hs.PAPER_TABLE2["rows"]]
    assert t1["rows"][-1]["INS abs.error (m)"]["paper"] == 212.5156
    assert "does NOT reproduce" in (tmp_path / "hajiyev-saltoglu.md").read_text() or data["verdict"]["rkf_claim_holds"]
    for name in data["figures"]:
        assert (tmp_path / name).stat().st_size > 5000
