"""The compiled engine with GPS carrier phase (nav/engine.py, kernels/carrier.py, core/nav/epoch.py) against the
generic path it replaces (nav/navigator.py's per-run filters with nav/rows.py and nav/measurements.carrier_phase,
nav/shared.py's numpy shared covariance, both with the arc resets of engine.new_arcs / reset_arcs): the same
solutions, status logs and filter histories to the rounding floors of test_epoch_engine.py (P's with the float
ambiguities' large prior in its operands), per run and shared, with per-run skies (the whole
compiled pass) and one sky, and with a channel that loses its carrier and comes back on a new arc (its ambiguity
reset, a shared class split); a run's numbers bit-identical in any batch; the kernels' carrier parts against their
numpy twins."""

from __future__ import annotations

import copy
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import R_EARTH_M, R_GPS_MAX_M, assert_within, floor
from test_epoch_engine import K_CHAIN, _floors

from approachsim import geo, synthetic
from approachsim.core.nav import carrier as kcar
from approachsim.nav import engine
from approachsim.nav import errormodel as em
from approachsim.nav import measurements as meas
from approachsim.nav.navigator import Navigator
from approachsim.nav.system import NavSystem
from approachsim.profile import parse_profile
from approachsim.seeding import stream
from approachsim.sensors.gnss.carrier import carrier_arcs
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

pytestmark = pytest.mark.equality

PROFILES = Path(__file__).resolve().parents[3] / "profiles"


def _profile(**gnss):
    path = PROFILES / "gbas-carrier-cat3-candidate.toml"
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    d["sensors"]["gnss"].update(copy.deepcopy(gnss))
    d["sensors"].pop("pseudolite", None)  # satellites only: the floors of test_epoch_engine without a near range
    # without the baro's scale-factor state (issue 39, on by default): its column (h - H_ref) ~ 170 m couples P_bb to
    # operands these satellite floors do not bound (P_bb 50 ulp apart after the run); the sb state's compiled epoch
    # against numpy is test_epoch_engine's and test_epoch_kernels'
    d["sensors"].setdefault("baro", {})["temperature_scale_sigma"] = 0.0
    return parse_profile(d, source=path)


def _records(prof, new_arc: bool, runs=(0, 1, 2)):
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 40.0,
                                        ground_speed_mps=70.0)
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=4, runs=list(runs))
    if new_arc:  # run 1 loses a channel's carrier for 3 samples from its 12th GNSS sample: a new arc after
        g = recs["gnss"]
        valid = np.array(g.valid, dtype=bool, copy=True)
        r = list(runs).index(1) if 1 in runs else None
        if r is not None:
            c = int(np.flatnonzero(valid[r, 12])[0])
            valid[r, 12:15, c] = False
        recs = {**recs, "gnss": replace(g, valid=valid, carrier_arc=carrier_arcs(valid))}
    return truth, recs, st


def _navigate(prof, shared: bool, generic: bool, monkeypatch, new_arc: bool = False, runs=(0, 1, 2)):
    truth, recs, st = _records(prof, new_arc, runs)
    nav = NavSystem.from_profile(prof)
    with monkeypatch.context() as m:
        if generic:
            m.setattr(engine.EpochEngine, "of", classmethod(lambda cls, system: None))
        return nav.run(truth, recs, [stream(4, r, "nav") for r in runs], shared_covariance=shared, states=st)


@pytest.mark.parametrize("sky", ["per-run", "fixed"])
@pytest.mark.parametrize("shared", [False, True])
def test_carrier_engine_equals_the_generic_path(sky, shared, monkeypatch):
    """Per-run skies with the shared covariance take the whole compiled pass (core/nav/epoch.shared_pass); one sky the
    compiled class epoch; per run the compiled own epoch. Each against the numpy path, with run 1's new arc."""
    prof = _profile(epoch=sky)
    fast = _navigate(prof, shared, False, monkeypatch, new_arc=True)
    slow = _navigate(prof, shared, True, monkeypatch, new_arc=True)
    for f, s in zip(fast, slow, strict=True):
        assert list(f.status.name) == list(s.status.name)
        assert any(n.startswith("cp") for n in s.status.name)
        # the same algebra in another instruction order: equal to the floors (test_epoch_engine._floors, satellites
        # only: the innovation's operands are ECEF positions and satellite ranges, the carrier's as the code's)
        fl = _floors(s, 2.0e7)
        # P_jj's update sums products of the entries P_ja, |P_ja| <= sqrt(P_jj P_aa) (Cauchy-Schwarz): with the
        # ambiguities' 100 m^2 prior in P the operands of a small P_jj are sqrt(max P_aa P_jj), not P_jj
        op = np.sqrt(np.max(s.P_diag) * np.max(s.P_diag, axis=0))
        fl["P diag"] = np.broadcast_to(floor(K_CHAIN * s.layout.n, op), s.P_diag.shape)
        assert_within(f.status.innovation, s.status.innovation, fl["innovation"], "innovation")
        assert_within(f.status.variance, s.status.variance, fl["S"], "S")
        assert_within(f.x, s.x, fl["x"], "x")
        assert_within(f.P_diag, s.P_diag, fl["P diag"], "P diag")
        assert_within(f.solution.r_ecef, s.solution.r_ecef, fl["r_ecef"], "r_ecef")
        assert_within(f.solution.v_ned, s.solution.v_ned, fl["v_ned"], "v_ned")


def test_the_new_arc_is_reset_on_the_compiled_path(monkeypatch):
    """The premise of the equality test's new arc: run 1's channel is back on a new arc id in its record, the compiled
    pass hands the kernel a reset for it (and none to the other runs after their start), and with one sky run 0's
    numbers are untouched by run 1's arc (its class split off, bit for bit)."""
    prof = _profile()
    _, recs, _ = _records(prof, True)
    arc = np.asarray(recs["gnss"].carrier_arc)
    c = int(np.flatnonzero(np.asarray(recs["gnss"].valid)[1, 11] & ~np.asarray(recs["gnss"].valid)[1, 12])[0])
    assert arc[1, 11, c] == 0 and arc[1, 15, c] == 15
    seen = []
    orig = Navigator._stacked_carrier

    def spy(self, *a, **k):
        seen.append(orig(self, *a, **k))
        return seen[-1]

    with monkeypatch.context() as m:
        m.setattr(Navigator, "_stacked_carrier", spy)
        _navigate(prof, True, False, monkeypatch, new_arc=True)
    new = seen[0][1]
    assert new[1, 14:, c].tolist()[:1] == [1] and new[1, 15:, c].sum() == 0  # epoch 14 is t = 15 s
    assert new[:, 1:].sum() == 1  # after the first epoch (every arc's start) only run 1's new arc
    fixed = _profile(epoch="fixed")
    split = _navigate(fixed, True, False, monkeypatch, new_arc=True)
    plain = _navigate(fixed, True, False, monkeypatch, new_arc=False)
    np.testing.assert_array_equal(split[0].x, plain[0].x)
    assert not np.array_equal(split[1].x, plain[1].x)


def test_carrier_runs_bit_identical_in_any_batch(monkeypatch):
    """The compiled pass with carrier: a run alone and in a batch of three (with a new arc in run 1) gives the same
    bits (same code path, same machine: exact)."""
    prof = _profile()
    batch = _navigate(prof, True, False, monkeypatch, new_arc=True)
    alone = _navigate(prof, True, False, monkeypatch, new_arc=True, runs=(1,))[0]
    np.testing.assert_array_equal(batch[1].x, alone.x)
    np.testing.assert_array_equal(batch[1].P_diag, alone.P_diag)
    np.testing.assert_array_equal(batch[1].status.innovation, alone.status.innovation)
    np.testing.assert_array_equal(batch[1].solution.r_ecef, alone.solution.r_ecef)


def test_carrier_kernels_equal_their_numpy_twins():
    """kernels/carrier.py: dynamics as errormodel._carrier_states (the same arithmetic: exact), reset_ambiguities as
    engine.reset_arcs (exact), carrier_phase's row as measurements.carrier_phase's and its innovation to the floor of
    a difference of satellite ranges."""
    nav = NavSystem.from_profile(_profile())
    lay = nav.layout
    n = lay.n
    el = np.radians(np.linspace(5.0, 85.0, 24))
    nz = nav.noise(el)
    F, Qc = em.dynamics(lay, 0.6, 100.0, np.array([70.0, 0.0, 3.0]), np.array([0.0, 0.0, -9.8]), np.eye(3), nz)
    F2, Q2 = F.copy(), Qc.copy()
    io = lay.index["gio"]
    F2[io, io] = 0.0
    Q2[io, io] = 0.0
    kcar.dynamics(lay.packed, *em.kernel_carrier(nz, lay.n_sv), F2, Q2)
    np.testing.assert_array_equal(F2, F)
    np.testing.assert_array_equal(Q2, Qc)
    rng = np.random.default_rng(2)
    phi, qd = rng.normal(size=(n, n)), rng.normal(size=(n, n))
    new = np.zeros(24, dtype=bool)
    new[[3, 17]] = True
    p1, q1 = engine.reset_arcs(lay, phi, qd, new, 100.0)
    p2, q2 = phi.copy(), qd.copy()
    assert kcar.reset_ambiguities(p2, q2, lay.packed, new.astype(np.int64), 100.0)
    np.testing.assert_array_equal(p2, p1)
    np.testing.assert_array_equal(q2, q1)
    lat, lon, hgt = 0.65, -2.1, 300.0
    r_ins = geo.geodetic_to_ecef(lat, lon, hgt)
    c_en = geo.c_ecef_to_ned(lat, lon)
    r_sv = r_ins + 2.2e7 * np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
    x = rng.normal(0.0, 2.0, n)
    phi_m = float(np.linalg.norm(r_ins - r_sv)) + 7.3
    m = meas.carrier_phase(lay, x, r_ins, c_en, r_sv, phi_m, 0.03, 0.0, "cp05", 5)
    h = np.zeros(n)
    nu = kcar.carrier_phase(lay.packed, x, r_ins, c_en, r_sv, phi_m, 5, h, True)
    assert_within(h, m.h, floor(8, m.h), "h")  # a unit vector rotated: rounding of its components
    nu_ref = m.z - m.h @ x
    assert_within(nu, nu_ref, floor(8, R_EARTH_M, R_GPS_MAX_M, R_GPS_MAX_M), "nu")


def test_arc_bookkeeping_stacked_equals_epoch_by_epoch():
    """engine.stacked_new_arcs over E epochs (the compiled pass) equals new_arcs epoch by epoch (the other paths)."""
    rng = np.random.default_rng(3)
    arc = rng.integers(-1, 4, size=(3, 30, 5)) * 10
    arc[arc < 0] = -1
    new, last = engine.stacked_new_arcs(np.full((3, 5), -1), arc)
    for i in range(3):
        prev = None
        for e in range(30):
            flags, prev = engine.new_arcs(prev, arc[i, e])
            np.testing.assert_array_equal(new[i, e].astype(bool), flags)
        np.testing.assert_array_equal(last[i], prev)


def test_the_compiled_pass_is_taken_with_carrier(monkeypatch):
    """Per-run skies, shared covariance: the carrier variant takes Navigator.compiled_pass (one kernel call)."""
    passed = []
    orig = Navigator.compiled_pass

    def spy(self, *a, **k):
        passed.append(orig(self, *a, **k))
        return passed[-1]

    monkeypatch.setattr(Navigator, "compiled_pass", spy)
    _navigate(_profile(), True, False, monkeypatch)
    assert passed == [True]
