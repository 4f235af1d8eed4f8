"""The open-loop pass of per-run-sky runs on each run's reduced state (nav/reduced.py) against the full-layout pass
it replaces (core/nav/epoch.shared_pass, what Navigator.compiled_pass runs when the reduction does not apply): the
same estimates, covariances, measurement rows and solutions, with a baro outage that holds the damping loop and
with pseudolites. The reduction drops exact zeros and keeps every other sum's order (the module docstring): measured
equal to the last bit on this machine; asserted to the floors of tests/unit/campaign/test_bankpass.py (the same
argument for the bank's copies), the integer row codes and counts exactly."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import R_EARTH_M, R_GPS_MAX_M, assert_within, floor

from approachsim import synthetic
from approachsim.nav import reduced
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite

DEFAULT = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")
SEED = 3
RUNS = [0, 1, 2]


def _profile(kind: str):
    p = DEFAULT
    if kind == "pseudolite":
        pl = PseudoliteConfig(positions_rwy=((0.0, -150.0, 9.0), (-3000.0, 200.0, 30.0)), synchronized=False)
        p = replace(p, sensors=replace(p.sensors, pseudolite=pl))
    if kind == "baro-outage":
        p = replace(p, faults=(FaultSpec(sensor="baro", kind="outage", start_s=10.0, end_s=16.0),))
    return p


def _pass(prof, truth, reduce: bool, monkeypatch):
    calls = []
    orig = reduced.reduced_singletons

    def spy(*a, **k):
        calls.append(orig(*a, **k) if reduce else -1)
        return calls[-1]

    monkeypatch.setattr(reduced, "reduced_singletons", spy)
    suite = SensorSuite.from_profile(prof)
    errors = suite.draw(truth.t_s, SEED, RUNS)
    records = suite.apply(truth, errors)
    nav = NavSystem.from_profile(prof)
    runs = nav.run(truth, records, [stream(SEED, i, "nav") for i in RUNS], shared_covariance=True,
                   states=start_states(suite, truth, errors))
    assert len(calls) == 1 and (calls[0] > 0) == reduce  # the path asked for ran
    return runs


@pytest.mark.equality
@pytest.mark.parametrize("kind", ["default", "pseudolite", "baro-outage"])
def test_reduced_pass_equals_the_full_pass(kind, monkeypatch):
    prof = _profile(kind)
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 30.0,
                                        ground_speed_mps=70.0)
    new = _pass(prof, truth, True, monkeypatch)
    old = _pass(prof, truth, False, monkeypatch)
    for a, b in zip(new, old, strict=True):
        assert a.x.shape == b.x.shape == (a.t_epoch_s.shape[0], a.layout.n)
        np.testing.assert_array_equal(a.t_epoch_s, b.t_epoch_s)
        np.testing.assert_array_equal(a.status.name, b.status.name)
        np.testing.assert_array_equal(a.status.t_s, b.status.t_s)
        # floors as test_bankpass: an innovation K eps of its ECEF and range operands, a state K nu per update
        # (|K_i| <= sqrt(P_ii / S)), a variance K n eps of the largest, the solution an ECEF difference more
        nu = floor(8, R_EARTH_M, R_GPS_MAX_M, R_GPS_MAX_M)
        p_max = float(np.max(b.P_diag))
        s_min = float(np.min(b.status.variance))
        x_floor = nu * np.sqrt(p_max / s_min)
        cond = R_EARTH_M / 150.0 if prof.sensors.pseudolite is not None else 1.0  # a pseudolite 150 m off
        p_floor = floor(8 * a.layout.n * cond, p_max)
        assert_within(a.status.innovation, b.status.innovation, nu + x_floor, "innovations")
        assert_within(a.status.variance, b.status.variance, p_floor, "innovation variances")
        assert_within(a.x, b.x, x_floor, "estimates")
        assert_within(a.P_diag, b.P_diag, p_floor, "variances")
        assert_within(a.P_nav, b.P_nav, p_floor, "navigation covariance")
        assert_within(a.solution.r_ecef, b.solution.r_ecef, x_floor + floor(8, R_EARTH_M), "solution")
        assert_within(a.solution.P_pos_ned, b.solution.P_pos_ned, p_floor, "solution covariance")
