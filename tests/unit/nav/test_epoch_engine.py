"""The compiled epoch engine (nav/engine.py, kernels/epoch.py) against the generic path it replaces for the optimal
filter (nav/navigator.py's per-run filters with nav/rows.py, nav/shared.py's shared covariance): the same solutions,
status logs and filter histories to rounding, per run and shared, with per-run skies, one sky with a fault that
splits a class, a pseudolite with its states, terrain, the radar altimeter's database error and the damping loop."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
from approachsim.nav import engine
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.gnss.gbas import GbasModel
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
DEFAULT = load_profile(PROFILES / "default.toml")


def _profile(kind: str):
    p = DEFAULT
    if kind == "fixed-sky-fault":
        p = replace(p, sensors=replace(p.sensors, gnss=replace(p.sensors.gnss, epoch="fixed", selection="all")),
                    faults=(FaultSpec(sensor="baro", kind="outage", start_s=12.0, end_s=20.0),))
    if kind == "gbas":  # GBAS corrections: the channel noise from its budget (sensors/kernels/gnss.gbas_channel_sigmas)
        p = replace(p, sensors=replace(p.sensors, gnss=replace(p.sensors.gnss, corrections="gbas", gbas=GbasModel(),
                                                               selection="all")))
    if kind == "pseudolite":
        pl = PseudoliteConfig(positions_rwy=((0.0, -150.0, 9.0), (-3000.0, 200.0, 30.0)), synchronized=False)
        p = replace(p, sensors=replace(p.sensors, pseudolite=pl))
    return p


def _navigate(prof, shared: bool, generic: bool, monkeypatch):
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 30.0,
                                        ground_speed_mps=70.0)
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=4, runs=[0, 1, 2])
    if prof.sensors.gnss.epoch == "fixed":  # run 1 loses a channel it used at its 10th GNSS sample: its schedule
        g = recs["gnss"]  # departs and the shared class splits there
        valid = np.array(g.valid, dtype=bool, copy=True)
        c = int(np.flatnonzero(valid[1, 10])[0])
        valid[1, 10:, c] = False
        recs = {**recs, "gnss": replace(g, valid=valid)}
    nav = NavSystem.from_profile(prof)
    with monkeypatch.context() as m:
        if generic:
            m.setattr(engine.EpochEngine, "of", classmethod(lambda cls, system: None))
        return nav.run(truth, recs, [stream(4, r, "nav") for r in range(3)], shared_covariance=shared, states=st)


def _close(a, b, what, rtol=1e-10):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, what
    scale = np.max(np.abs(b)) + 1e-300
    assert np.max(np.abs(a - b)) <= rtol * scale, f"{what}: {np.max(np.abs(a - b)) / scale:.2e}"


@pytest.mark.parametrize("kind", ["default", "fixed-sky-fault", "pseudolite", "gbas"])
@pytest.mark.parametrize("shared", [False, True])
def test_engine_equals_the_generic_path(kind, shared, monkeypatch):
    prof = _profile(kind)
    fast = _navigate(prof, shared, False, monkeypatch)
    slow = _navigate(prof, shared, True, monkeypatch)
    for f, s in zip(fast, slow, strict=True):
        assert list(f.status.name) == list(s.status.name)
        assert len(f.status.name) > 0
        _close(f.status.innovation, s.status.innovation, "innovation")
        _close(f.status.variance, s.status.variance, "S")
        _close(f.x, s.x, "x")
        _close(f.P_diag, s.P_diag, "P diag")
        _close(f.solution.r_ecef - f.solution.r_ecef[0], s.solution.r_ecef - s.solution.r_ecef[0], "r_ecef")
        _close(f.solution.v_ned, s.solution.v_ned, "v_ned")


def test_engine_is_off_where_the_generic_path_is_needed():
    """Robust filters (a gain policy), FDE, loose coupling and adaptive loops keep the generic path."""
    for kw in ({"filter": "rkf-gate"}, {"gps_coupling": "loose"}, {"baro_loop": "tanh"}):
        nav = NavSystem.from_profile(replace(DEFAULT, nav=replace(DEFAULT.nav, **kw)))
        assert engine.EpochEngine.of(nav) is None, kw
    assert engine.EpochEngine.of(NavSystem.from_profile(DEFAULT)) is not None


@pytest.mark.parametrize("kind", ["default", "pseudolite", "baro-outage", "gbas"])
def test_whole_pass_equals_the_per_epoch_engine(kind, monkeypatch):
    """Per-run skies with the shared covariance: the whole open-loop pass in one kernel call (Navigator.compiled_pass)
    against the epoch-by-epoch engine it replaces (the same arithmetic: equal to rounding), with a damping loop held
    during a baro outage and pseudolites with their states."""
    from approachsim.nav.navigator import Navigator

    prof = _profile(kind if kind in ("pseudolite", "gbas") else "default")
    if kind == "baro-outage":
        prof = replace(prof, faults=(FaultSpec(sensor="baro", kind="outage", start_s=10.0, end_s=16.0),))
    assert prof.nav.baro_loop == "constant"
    passed = []
    orig = Navigator.compiled_pass

    def spy(self, *a, **k):
        passed.append(orig(self, *a, **k))
        return passed[-1]

    with monkeypatch.context() as m:
        m.setattr(Navigator, "compiled_pass", spy)
        whole = _navigate(prof, True, False, monkeypatch)
    assert passed == [True]
    with monkeypatch.context() as m:
        m.setattr(Navigator, "can_pass", lambda self: False)
        epochs = _navigate(prof, True, False, monkeypatch)
    for f, s in zip(whole, epochs, strict=True):
        assert list(f.status.name) == list(s.status.name)
        _close(f.status.innovation, s.status.innovation, "innovation", rtol=1e-12)
        _close(f.x, s.x, "x", rtol=1e-12)
        _close(f.P_diag, s.P_diag, "P diag", rtol=1e-12)
        _close(f.true_error_nav, s.true_error_nav, "output error", rtol=1e-12)
        np.testing.assert_array_equal(f.solution.P_pos_ned, s.solution.P_pos_ned)
