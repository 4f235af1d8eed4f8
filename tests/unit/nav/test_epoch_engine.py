"""The compiled epoch engine (nav/engine.py, core/nav/epoch.py) against the generic path it replaces for the optimal
filter (nav/navigator.py's per-run filters with nav/rows.py, nav/shared.py's shared covariance): the same solutions,
status logs and filter histories to rounding, per run and shared, with per-run skies, one sky with a fault that
splits a class, a pseudolite with its states, terrain, the radar altimeter's database error and the damping loop."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import R_EARTH_M, R_GPS_MAX_M, assert_within, floor

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

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""
DEFAULT = load_profile(PY_DEFAULT)
# without issue 39's baro scale-factor state: its column -(h_ins + dp_D_hat - H_ref) moves with the estimate, so
# x's rounding floor enters S and P of the two paths (S: 2 dh sqrt(P_sb S), Cauchy-Schwarz; P's propagation through
# the loop and the Joseph update not worked out: up to 245x these floors, gbas). The sb row's kernel against numpy
# is test_epoch_kernels'; the closed loop's paths with it, test_closed_loop_epoch's.
DEFAULT = replace(DEFAULT, sensors=replace(DEFAULT.sensors, baro=replace(DEFAULT.sensors.baro,
                                                                          temperature_scale_sigma=0.0)))


def _profile(kind: str):
    p = DEFAULT
    if kind == "fixed-sky-fault":
        p = replace(p, sensors=replace(p.sensors, gnss=replace(p.sensors.gnss, epoch="fixed", selection="all")),
                    faults=(FaultSpec(sensor="baro", kind="outage", start_s=12.0, end_s=20.0),))
    if kind == "gbas":  # GBAS corrections: the channel noise from its budget (core/sensors/gnss.gbas_channel_sigmas)
        p = replace(p, sensors=replace(p.sensors, gnss=replace(p.sensors.gnss, corrections="gbas", gbas=GbasModel(),
                                                               selection="all")))
    if kind == "sbas":  # SBAS L1, the nominal filter model: the zenith ionospheric field and troposphere states
        p = replace(p, sensors=replace(p.sensors, gnss=load_profile(PROFILES / "sbas-lpv200.toml").sensors.gnss))
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
        if prof.sensors.gnss.service is not None:
            assert nav.layout.has("giz") and nav.layout.has("gtz")
        return nav.run(truth, recs, [stream(4, r, "nav") for r in range(3)], shared_covariance=shared, states=st)


K_CHAIN = 8
"""Operations on the longest path from the large operands to a compared quantity, doubled for two independent
computations: the ECEF difference r_ins - r_tx (1), the norm's squares, sum and root (3), z - |..| (1), h x (1)."""


def _floors(run, d_min_m: float) -> dict[str, np.ndarray]:
    """Rounding floors of two computations of one run by different instruction sequences (tests/floors.py).

    innovation: a satellite pseudorange's is z - |r_ins - r_tx| with r_ins, r_tx ECEF and z a range, operands up to
    |r_ins| + 2 x 2.7e7 m: K eps of that is 1.1e-7 m; every other row is taken against a state that carries that
    floor from earlier ranges, so one floor for all rows. x: state i moves by K_i nu per update, |K_i| <= sqrt(P_ii
    / S) (Cauchy-Schwarz on K = P h / S), and each update contracts what earlier ones left (I - K h): the innovation
    floor times sqrt(max P_ii / min S). P and S: sums of n-term products of P's entries (n states, Higham's
    gamma_n): K n eps of the largest P_ii (S: of the largest S) times the conditioning of the rows' directions, 1 for
    a satellite's line of sight and |r_ecef| / d for a transmitter at d m (a pseudolite's unit vector is a difference
    of 6.4e6 m ECEF vectors divided by its range), per epoch. The Riccati recursion contracts earlier rounding only
    in the directions the updates observe: a variance the aiding holds near constant (the horizontal velocity's)
    carries each epoch's rounding forward, so P's floor at epoch e is the epochs' sum, (e + 1) times that (measured
    on the default: dv_N's difference grows 1.06e-17 -> 1.19e-17 over epochs 23-29, 1.1x the one-epoch floor).
    r_ecef: K eps |r_ecef| plus the position states' floor; v_ned: the velocity states'."""
    nu = floor(K_CHAIN, R_EARTH_M, R_GPS_MAX_M, R_GPS_MAX_M)
    x = nu * np.sqrt(np.max(run.P_diag, axis=0) / float(np.min(run.status.variance)))
    cond = max(1.0, R_EARTH_M / d_min_m)
    lay = run.layout
    dp, dv = lay.index["dp"], lay.index["dv"]
    return {
        "innovation": np.broadcast_to(nu, run.status.innovation.shape), "x": np.broadcast_to(x, run.x.shape),
        "S": np.broadcast_to(floor(K_CHAIN * lay.n * cond, np.max(run.status.variance)), run.status.variance.shape),
        "P diag": floor(K_CHAIN * lay.n * cond, np.max(run.P_diag, axis=0))
        * np.arange(1.0, run.P_diag.shape[0] + 1.0)[:, None],
        "r_ecef": floor(K_CHAIN, run.solution.r_ecef) + np.max(x[dp]),
        "v_ned": np.full(run.solution.v_ned.shape, np.max(x[dv])),
    }


def _d_min(prof) -> float:
    """The smallest distance between the aircraft and a ranging transmitter over the flight, m (satellites: 2e7)."""
    pl = prof.sensors.pseudolite
    if pl is None:
        return 2.0e7
    # the synthetic glidepath flies the centreline: no pseudolite comes closer than its cross-track offset
    return max(10.0, float(min(abs(p[1]) for p in pl.positions_rwy)))


@pytest.mark.parametrize("kind", ["default", "fixed-sky-fault", "pseudolite", "gbas", "sbas"])
@pytest.mark.parametrize("shared", [False, True])
def test_engine_equals_the_generic_path(kind, shared, monkeypatch):
    prof = _profile(kind)
    fast = _navigate(prof, shared, False, monkeypatch)
    slow = _navigate(prof, shared, True, monkeypatch)
    for f, s in zip(fast, slow, strict=True):
        assert list(f.status.name) == list(s.status.name)
        assert len(f.status.name) > 0
        # the same algebra in another instruction order (a compiled epoch vs numpy rows): equal to the floors
        fl = _floors(s, _d_min(prof))
        assert_within(f.status.innovation, s.status.innovation, fl["innovation"], "innovation")
        assert_within(f.status.variance, s.status.variance, fl["S"], "S")
        assert_within(f.x, s.x, fl["x"], "x")
        assert_within(f.P_diag, s.P_diag, fl["P diag"], "P diag")
        assert_within(f.solution.r_ecef, s.solution.r_ecef, fl["r_ecef"], "r_ecef")
        assert_within(f.solution.v_ned, s.solution.v_ned, fl["v_ned"], "v_ned")


def test_engine_is_off_where_the_generic_path_is_needed():
    """Robust filters (a gain policy), FDE, loose coupling and adaptive loops keep the generic path."""
    for kw in ({"filter": "rkf-gate"}, {"gps_coupling": "loose"}, {"baro_loop": "tanh"}):
        nav = NavSystem.from_profile(replace(DEFAULT, nav=replace(DEFAULT.nav, **kw)))
        assert engine.EpochEngine.of(nav) is None, kw
    assert engine.EpochEngine.of(NavSystem.from_profile(DEFAULT)) is not None


@pytest.mark.parametrize("kind", ["default", "pseudolite", "baro-outage", "gbas", "sbas"])
def test_whole_pass_equals_the_per_epoch_engine(kind, monkeypatch):
    """Per-run skies with the shared covariance: the whole open-loop pass in one kernel call (Navigator.compiled_pass)
    against the epoch-by-epoch engine it replaces (the same arithmetic: equal to rounding), with a damping loop held
    during a baro outage and pseudolites with their states."""
    from approachsim.nav.navigator import Navigator

    prof = _profile(kind if kind in ("pseudolite", "gbas", "sbas") else "default")
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
        # the same kernels composed in one call or epoch by epoch: inlining may contract other products into FMAs,
        # so equal to the same floors as the generic path (measured equal to the last bit on two CPUs)
        fl = _floors(s, _d_min(prof))
        assert_within(f.status.innovation, s.status.innovation, fl["innovation"], "innovation")
        assert_within(f.x, s.x, fl["x"], "x")
        assert_within(f.P_diag, s.P_diag, fl["P diag"], "P diag")
        # (pos, vel, att) error: the first nine states' floors, the position's after a 6.4e6 m ECEF difference
        out_floor = fl["x"][0, 0:9] + np.repeat([floor(K_CHAIN, R_EARTH_M), 0.0, 0.0], 3)
        assert_within(f.true_error_nav, s.true_error_nav, out_floor, "output error")
        pp = s.solution.P_pos_ned
        assert_within(f.solution.P_pos_ned, pp, floor(K_CHAIN * s.layout.n, np.max(np.abs(pp))), "P_pos_ned")
