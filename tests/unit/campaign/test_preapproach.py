"""Faults present before the approach (campaign/preapproach.py, issue 41 item 3): the pre-approach segment's response
of the bank's copies, checked against the navigation itself.

The response is computed at the start's fixed geometry with the converged filter's fixed gain. The in-run filter,
given the same fault from the run start, is the time-varying reference: after `age` seconds its fault-induced error
must match the response of a fault of that age at the start. They differ by the geometry and gain change over the
30 s (about 2 km of approach) and by one aiding interval (the start's first epoch is one interval after the start):
measured 6 % at most for a GPS step, a GPS ramp and a baro step through the damping loop, so 15 % is the bound (a sign
or scale error in the response, a missing loop drive or a copy offset applied to the wrong state gives 100 % or
more: the baro step without the loop drive comes out with the opposite sign)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from approachsim.campaign import integrity_risk as risk
from approachsim.campaign.integrity_bank import run_bank
from approachsim.campaign.integrity_campaign import bank_profile
from approachsim.campaign.preapproach import PreFault
from approachsim.profile import load_profile
from approachsim.resources import shipped_profile
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.suite import SensorSuite

RUN = 7
AGE_S = 30.0


@pytest.fixture(scope="module")
def setting() -> tuple:
    prof = load_profile(shipped_profile("default"))
    flown = risk.flown_truth(prof, 1, 0)
    g = SensorSuite.from_profile(prof).measure(flown.truth, seed=1, runs=[RUN])["gnss"]
    idx = int(np.flatnonzero(np.asarray(g.valid)[0, 0])[0])
    return prof, flown, idx, int(np.asarray(g.prn)[idx])


def _bank(prof, flown, spec, pre):
    p2 = dataclasses.replace(prof, faults=() if spec is None else (spec,))
    ep, _ = run_bank(bank_profile(p2), flown.truth, 1, RUN, memo=flown.memo, pre=pre)
    return ep


_AFTER_39 = ("finding after the merge of issue 39's filter (the physical baro's bias state, the scale-factor column "
             "at the navigation's height, the drift-matched slow tau, the gyro axis noise) with issue 41's "
             "pre-approach segment, not yet re-derived: ")


@pytest.mark.parametrize("sensor,kind,value", [
    ("gnss", "step", 20.0),
    ("gnss", "ramp", 0.5),  # issue 38's zenith states on the SBAS default: within the bound again (it missed by 23 %)
    pytest.param("baro", "step", 10.0, marks=pytest.mark.xfail(strict=True, reason=_AFTER_39 + (
        "a 10 m baro step 30 s old moves the solution by 0.70 m only (the bias state takes it): the comparison's "
        "premise (> 1 m) fails"))),
])
def test_pre_approach_response_matches_the_filter_run_through_the_fault(setting, sensor, kind, value) -> None:
    prof, flown, idx, prn = setting
    t0 = float(flown.truth.t_s[0])
    row = f"gps{idx:02d}" if sensor == "gnss" else "baro"
    spec = FaultSpec(sensor=sensor, kind=kind, start_s=t0, target="pseudorange" if sensor == "gnss" else "h",
                     channel=prn if sensor == "gnss" else None, magnitude=value if kind == "step" else 0.0,
                     rate=value if kind == "ramp" else 0.0)
    base = _bank(prof, flown, None, None)
    inrun = _bank(prof, flown, spec, None)
    k = int(np.argmin(np.abs(inrun.t_s - (t0 + AGE_S))))
    ref = inrun.e0[k] - base.e0[k]
    pre = _bank(prof, flown, dataclasses.replace(spec, start_s=t0 - AGE_S), PreFault(row, kind, value, AGE_S))
    got = pre.e0[0] - base.e0[0]
    assert np.linalg.norm(ref) > 1.0  # the fault moved the solution (m): the comparison is not of noise
    assert np.linalg.norm(got - ref) <= 0.15 * np.linalg.norm(ref)
    if sensor == "gnss":
        # the sub-filter without the faulted satellite never saw the fault: its error is the fault-free one (to the
        # linearization about the shifted INS, sub-millimetre), while the main filter's moved by metres
        j = int(np.flatnonzero(np.asarray(pre.channels) == idx)[0])
        assert np.max(np.abs(pre.ek[0, j] - base.ek[0, j])) < 1e-3
        others = [i for i in range(len(pre.channels)) if i != j]
        assert np.linalg.norm(pre.ek[0, others[0]] - base.ek[0, others[0]]) > 0.5 * np.linalg.norm(got)


@pytest.mark.xfail(strict=True, reason=_AFTER_39 + (
    "the scale-factor column moves with the estimate, so the response to a 2x ramp is 2x to 5e-5, not 1e-6"))
def test_pre_approach_response_is_linear_in_the_fault(setting) -> None:
    prof, flown, idx, prn = setting
    t0 = float(flown.truth.t_s[0])
    base = _bank(prof, flown, None, None)
    out = []
    for rate in (0.05, 0.1):
        spec = FaultSpec(sensor="gnss", kind="ramp", start_s=t0 - 1200.0, target="pseudorange", channel=prn,
                         rate=rate)
        out.append(_bank(prof, flown, spec, PreFault(f"gps{idx:02d}", "ramp", rate, 1200.0)).e0[0] - base.e0[0])
    assert np.linalg.norm(out[0]) > 0.5
    np.testing.assert_allclose(out[1], 2.0 * out[0], rtol=1e-6, atol=1e-6)
