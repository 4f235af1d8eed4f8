"""The bank with the baro and the radar altimeter as fault modes (run_bank(sensor_modes_on=True)) on a flown
approach: a 50 m baro step, misleading for the GPS-only bank (its PL never sees the baro), is detected and the baro
excluded, and the output is no longer misleading; fault-free nothing is detected.

With issue 39's physical baro the filter carries a baro bias (sigma 3.1 m) and scale factor that absorb much of a
step: a 20 m step is no longer misleading for the GPS-only bank (0 misleading epochs, measured), a 50 m one is (58).
Fault-free, the baro mode is tested on the vertical axis only and the bank with it identifies by the tested
separations (campaign/integrity_bank.tested_axes: its sub-filter runs its own INS, so P_k - P_0 is not the
separation's covariance on the lateral axis or on the full state)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from approachsim.campaign.bank_modes import BARO_MODE, RADALT_MODE
from approachsim.campaign.integrity_bank import run_bank
from approachsim.campaign.integrity_risk import flight_truth, limit_states
from approachsim.profile import load_profile
from approachsim.sensors.faults import FaultSpec

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow


def test_baro_step_detected_and_excluded_with_sensor_modes() -> None:
    prof = load_profile(ROOT / "tests" / "data" / "default-py.toml")
    truth, _, _ = flight_truth(prof, 1, 0)
    t0 = float(truth.t_s[0])
    ep, _ = run_bank(prof, truth, 1, 5, sensor_modes_on=True)
    assert BARO_MODE in ep.channels and RADALT_MODE in ep.channels
    clean = limit_states(ep, prof.evaluation, 1.0, t0)
    assert clean["cat1_detected"] == 0 and clean["cat1_mi"] == 0
    faulted = dataclasses.replace(prof, faults=(FaultSpec(sensor="baro", kind="step", start_s=150.0, target="h",
                                                          magnitude=50.0),))
    old = limit_states(run_bank(faulted, truth, 1, 5)[0], prof.evaluation, 1.0, t0)
    new = limit_states(run_bank(faulted, truth, 1, 5, sensor_modes_on=True)[0], prof.evaluation, 1.0, t0)
    assert old["cat1_mi"] > 10  # measured: 58 misleading epochs (a GPS satellite excluded in its place)
    assert new["cat1_detected"] == 1 and new["cat1_excluded"] == BARO_MODE
    # excluded, the output is the baro-less sub-filter: back to the fault-free run's largest error (measured equal)
    assert new["cat1_mi"] == 0 and new["cat1_vmax_m"] <= clean["cat1_vmax_m"] + 0.5
