"""The bank with the baro and the radar altimeter as fault modes (run_bank(sensor_modes_on=True)) on a flown
approach: a 20 m baro step, misleading for the GPS-only bank (its PL never sees the baro), is detected and the baro
excluded, and the output is no longer misleading; fault-free nothing is detected."""

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


@pytest.mark.xfail(strict=True, reason=(
    "finding after the merge of issue 39's physical baro (bias state, static-source and QNH errors) with the "
    "sensor-mode bank: the fault-free run of this test alerts at CAT I (cat1_detected 1), so the baro step's "
    "exclusion cannot be judged against a clean run; the sensor modes' thresholds were set on the 1 m baro"))
def test_baro_step_detected_and_excluded_with_sensor_modes() -> None:
    prof = load_profile(ROOT / "tests" / "data" / "default-py.toml")
    truth, _, _ = flight_truth(prof, 1, 0)
    t0 = float(truth.t_s[0])
    ep, _ = run_bank(prof, truth, 1, 5, sensor_modes_on=True)
    assert BARO_MODE in ep.channels and RADALT_MODE in ep.channels
    clean = limit_states(ep, prof.evaluation, 1.0, t0)
    assert clean["cat1_detected"] == 0 and clean["cat1_mi"] == 0
    faulted = dataclasses.replace(prof, faults=(FaultSpec(sensor="baro", kind="step", start_s=150.0, target="h",
                                                          magnitude=20.0),))
    old = limit_states(run_bank(faulted, truth, 1, 5)[0], prof.evaluation, 1.0, t0)
    new = limit_states(run_bank(faulted, truth, 1, 5, sensor_modes_on=True)[0], prof.evaluation, 1.0, t0)
    assert old["cat1_detected"] == 0 and old["cat1_mi"] > 10  # measured: 92 misleading epochs, 9 m error
    assert new["cat1_detected"] == 1 and new["cat1_excluded"] == BARO_MODE
    assert new["cat1_mi"] == 0 and new["cat1_vmax_m"] < 0.5 * old["cat1_vmax_m"]
