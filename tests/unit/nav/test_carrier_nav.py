"""The navigation filter with GPS carrier phase (nav/noise.py, nav/measurements.py carrier_phase, nav/navigator.py
arc resets): the layout and its prior, the carrier row's signs against its model, exact sensors give exact
navigation, a seeded open-loop campaign is NEES-consistent, the float ambiguity follows the sensor's ambiguity and is
reset at a new arc, and an exclusion removes a satellite's code and carrier together."""

from __future__ import annotations

import copy
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from approachsim import geo, synthetic
from approachsim.nav import errormodel as em
from approachsim.nav import ins, noise
from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav.config import FdeConfig, InitialError
from approachsim.nav.engine import EpochEngine
from approachsim.nav.fde import FdeState, _ranging
from approachsim.nav.observations import CP, GPS, Source
from approachsim.nav.rows import Row
from approachsim.nav.system import NavSystem
from approachsim.profile import parse_profile
from approachsim.seeding import stream
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why): carrier phase is a
code-preset option."""


def _profile(name="gbas-cat3-candidate", **gnss):
    path = PY_DEFAULT if name == "default" else PROFILES / f"{name}.toml"
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    d["sensors"]["gnss"].update(copy.deepcopy(gnss))
    return parse_profile(d, source=path)


CARRIER = _profile(carrier_phase=True)
CODE = _profile()


def test_layout_prior_and_the_split_of_the_slow_state():
    """The carrier states come after every other group (the others keep their indices); P0 of amb is the sensor's
    ambiguity spread, and gse^2 + gio^2 under carrier is the code-only gse^2 (the split keeps the total)."""
    on, off = NavSystem.from_profile(CARRIER), NavSystem.from_profile(CODE)
    lo, lf = on.layout, off.layout
    assert {g: lo.index[g] for g in lf.groups} == lf.index
    assert lo.index["gio"] == slice(lf.n, lf.n + 24) and lo.index["amb"] == slice(lf.n + 24, lf.n + 48)
    assert not off.layout.has("amb")
    el = np.radians(np.linspace(5.0, 85.0, 24))
    P_on, P_off = on.initial_covariance(el), off.initial_covariance(el)
    d_on, d_off = np.diag(P_on), np.diag(P_off)
    np.testing.assert_allclose(d_on[lo.index["amb"]], 10.0**2)
    np.testing.assert_allclose(d_on[lo.index["gse"]] + d_on[lo.index["gio"]], d_off[lf.index["gse"]], rtol=1e-12)
    assert np.all(d_on[lo.index["gio"]] > 1e-4)  # the GBAS iono residual at the reference geometry: several cm
    nz = on.noise(el)
    bud = CARRIER.sensors.gnss.budget()
    # gse without the ionosphere: the drift-matched tau of ground (300 s) and tropo (3600 s) alone
    assert nz.gio_tau_s == bud.iono_tau_s and nz.gse_tau_s == noise.slow_tau_s(bud, ionosphere=False)
    assert bud.gbas.ground_tau_s < nz.gse_tau_s < bud.tropo_tau_s
    F, Qc = em.dynamics(lo, 0.6, 100.0, np.array([70.0, 0.0, 3.0]), np.array([0.0, 0.0, -9.8]), np.eye(3), nz)
    i, a = lo.index["gio"], lo.index["amb"]
    np.testing.assert_allclose(np.diag(F)[i], -1.0 / bud.iono_tau_s)
    assert not F[a].any() and not Qc[a].any()  # random constants
    F2, Q2 = em.dynamics_reference(lo, 0.6, 100.0, np.array([70.0, 0.0, 3.0]), np.array([0.0, 0.0, -9.8]),
                                   np.eye(3), nz)
    np.testing.assert_allclose(F, F2, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(Qc, Q2, rtol=1e-12, atol=1e-30)
    assert on.noise_model.carrier_sigma_m() == pytest.approx(np.sqrt(0.01**2 * (1 + np.exp(-0.2)) /
                                                                     (1 - np.exp(-0.2)) + 0.002**2))


def test_compiled_path_and_shared_covariance_with_carrier():
    """The compiled engine carries the carrier states (nav/engine.py, kernels/carrier.py; its equality with the
    generic path: test_carrier_engine.py), so carrier phase shares the covariance as the code does."""
    on, off = NavSystem.from_profile(CARRIER), NavSystem.from_profile(CODE)
    assert off.shares_covariance() and EpochEngine.of(off) is not None
    assert on.shares_covariance() and EpochEngine.of(on) is not None and EpochEngine.of(on).carrier


def test_carrier_row_is_its_model_at_the_true_state():
    """With x_hat the true errors the carrier row's innovation is zero: phi = |r_true - r_sv| + clk + gse - gio +
    amb (the code's geometry, clock and slow error, the ionosphere with the opposite sign) -- and the code row's is
    zero for rho = ... + gse + gio + gmp. A wrong sign at any state makes it the state's value."""
    lay = NavSystem.from_profile(CARRIER).layout
    rng = np.random.default_rng(4)
    lat, lon, h = 0.65, -2.1, 300.0
    r_ins = geo.geodetic_to_ecef(lat, lon, h)
    c_en = geo.c_ecef_to_ned(lat, lon)
    r_sv = r_ins + 2.2e7 * np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
    x = np.zeros(lay.n)
    x[lay.index["dp"]] = rng.normal(0.0, 3.0, 3)
    x[lay.i("clk")] = 120.0
    k = 7
    x[lay.i("gse", k)], x[lay.i("gio", k)], x[lay.i("gmp", k)], x[lay.i("amb", k)] = 0.3, -0.2, 0.25, -7.3
    r_true = r_ins - c_en.T @ x[lay.index["dp"]]
    rng_true = float(np.linalg.norm(r_true - r_sv))
    phi = rng_true + 120.0 + 0.3 - (-0.2) + (-7.3)
    m = meas.carrier_phase(lay, x, r_ins, c_en, r_sv, phi, 0.03, 0.0, "cp07", k)
    assert abs(m.z - m.h @ x) < 1e-6
    assert m.h[lay.i("gio", k)] == 1.0 and m.h[lay.i("amb", k)] == -1.0 and m.h[lay.i("gse", k)] == -1.0
    assert m.h[lay.i("gmp", k)] == 0.0 and m.r == pytest.approx(0.03**2)
    rho = rng_true + 120.0 + 0.3 + (-0.2) + 0.25
    c = meas.pseudorange(lay, x, r_ins, c_en, r_sv, rho, 0.002, 0.0, "gps07", sv=k)
    assert abs(c.z - c.h @ x) < 1e-6 and c.h[lay.i("gio", k)] == -1.0 and c.h[lay.i("amb", k)] == 0.0
    np.testing.assert_array_equal(m.h[lay.index["dp"]], c.h[lay.index["dp"]])


def test_exact_sensors_and_no_initial_error_stay_within_1cm_with_carrier():
    """Noiseless sensors (ambiguities 0 too), no initial error: every code and carrier innovation under 1 cm."""
    p = _profile("default", carrier_phase=True)
    truth = synthetic.glidepath_descent(p.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 60.0,
                                       ground_speed_mps=70.0)
    recs = SensorSuite.from_profile(p).measure(truth, seed=3, runs=0, noise=False)
    base = NavSystem.from_profile(p)
    nav = NavSystem.build(replace(base.nav, baro_loop="none", terrain_database=tdb.EXACT,
                                  initial_error=InitialError(0.0, 0.0, 0.0, 0.0, start="prior")),
                          p.sensors, p.runway.frame, p.terrain)
    run = nav.run(truth, recs, stream(3, 0, "nav"))
    lat, lon, h = geo.ecef_to_geodetic(run.solution.r_ecef)
    dp = ins.position_error_ned(lat, lon, h, truth.lat_rad, truth.lon_rad, truth.h_m)
    assert np.max(np.linalg.norm(dp, axis=1)) < 0.01
    cp = np.char.startswith(run.status.name, "cp")
    assert cp.sum() >= 4 * 59 and np.all(run.status.accepted)
    assert np.max(np.abs(run.status.innovation)) < 0.01


RUNS = 40


def _campaign(profile, runs=RUNS):
    """`runs` seeded open-loop runs of `profile` on a 150 s synthetic glidepath, converged start, each run its own
    sky: (NEES per epoch averaged over the runs, the runs)."""
    truth = synthetic.glidepath_descent(profile.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 150.0,
                                        ground_speed_mps=70.0)
    recs, st = measure_with_states(SensorSuite.from_profile(profile), truth, seed=1, runs=list(range(runs)))
    out = NavSystem.from_profile(profile).run(truth, recs, [stream(1, r, "nav") for r in range(runs)], states=st)
    e = np.stack([r.true_error_nav for r in out])
    P = np.stack([r.P_nav for r in out])
    return np.einsum("rki,rki->rk", e, np.linalg.solve(P, e[..., None])[..., 0]).mean(axis=0), out


def _nis(runs, group):
    q = np.concatenate([r.status.test_ratio[np.char.startswith(r.status.name, group)] for r in runs])
    assert q.size > RUNS * 100, group
    return float(q.mean())


@pytest.mark.parametrize("name", ["default", "gbas-cat3-candidate"])
def test_open_loop_with_carrier_is_nees_consistent(name):
    """Seeded open-loop runs of a profile with and without carrier phase (same seeds, per-run skies, converged
    start). With carrier the run-averaged NEES of the 9 navigation errors stays under the upper 95 % chi-square
    bound at 95 % of the epochs (never overconfident) and its mean within 10 % of the code-only campaign's: both
    configurations are slightly conservative over a 150 s approach without carrier already (2026-12-05: the default
    8.0 and the GBAS candidate 7.8 for 9 dof, with carrier 8.1 and 8.2; the GBAS channel states follow the aircraft's
    geometry, nav/gbas_scale.py), and the carrier states must keep that, not trade it for confidence the filter does
    not have. The code rows' average NIS
    stays near 1; the carrier rows' is below 1 by design (their R is the multipath's white equivalent: conservative
    epoch by epoch, nav/noise.py) but not absurdly: above 0.1."""
    nees_on, runs = _campaign(_profile(name, carrier_phase=True))
    nees_off, _ = _campaign(_profile(name))
    hi = chi2.ppf(0.975, 9 * RUNS) / RUNS
    assert np.mean(nees_on <= hi) >= 0.95, nees_on.max()
    assert abs(nees_on.mean() / nees_off.mean() - 1.0) < 0.1, (nees_on.mean(), nees_off.mean())
    assert 0.7 < _nis(runs, "gps") < 1.2
    assert 0.1 < _nis(runs, "cp") < 1.0


def test_ambiguity_estimate_follows_the_sensor_and_resets_at_a_new_arc():
    """A 20 s outage of every GNSS channel: before it each float ambiguity estimate is within 1 m of the arc's true
    ambiguity (the sensor's pool at the first sample), after it within 1 m of the new arc's (the pool at the first
    sample after the outage, some 10 m away): without the reset at the new arc the estimate would stay near the old
    one. (Its variance after one epoch of the new arc is already about what 60 s of the old arc had reached: the float
    ambiguity is only as good as the code's fast errors, correlated over 100 s, let it be.)"""
    fault = FaultSpec("gnss", "outage", start_s=60.0, end_s=80.0)
    p = CARRIER
    truth = synthetic.glidepath_descent(p.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 140.0,
                                        ground_speed_mps=70.0)
    suite = SensorSuite.from_config(p.sensors, p.runway.frame, p.environment.setting_pa, (fault,))
    errors = suite.draw(truth.t_s, 2, [0, 1])
    from approachsim.sensors.states import start_states

    recs, st = suite.apply(truth, errors), start_states(suite, truth, errors)
    nav = NavSystem.from_profile(p)
    runs = nav.run(truth, recs, [stream(2, r, "nav") for r in range(2)], states=st)
    lay = nav.layout
    g = recs["gnss"]
    pool = errors.sensors["gnss"].series["ambiguity"]
    a = lay.index["amb"]
    for r, run in enumerate(runs):
        t = run.t_epoch_s
        i_before = int(np.flatnonzero(t < 60.0)[-1])
        i_end = len(t) - 1
        j_after = int(np.flatnonzero(g.t_s >= 80.0)[0])
        both = g.valid[r, j_after] & g.valid[r, int(np.flatnonzero(g.t_s < 60.0)[-1])] & g.valid[r, -1]
        assert both.sum() >= 5 and np.all(g.carrier_arc[r, j_after][both] == j_after)
        ch = np.flatnonzero(both)
        x_before, x_end = run.x[i_before, a][ch], run.x[i_end, a][ch]
        np.testing.assert_array_less(np.abs(x_before - pool[r, 0, ch]), 1.0)
        np.testing.assert_array_less(np.abs(x_end - pool[r, j_after, ch]), 1.0)
        assert np.mean(np.abs(pool[r, j_after, ch] - pool[r, 0, ch])) > 3.0  # a new ambiguity: the test can fail


def test_a_new_arc_resets_the_ambiguity_to_its_prior():
    """Navigator._new_arcs: for a channel whose arc id changed, Phi's row and column are zero and Qd holds the prior
    variance alone, so P- = Phi P+ Phi' + Qd is the prior there and uncorrelated, the estimate 0; other channels and
    states untouched; a channel without carrier this epoch keeps its last id."""
    from approachsim.nav.navigator import Navigator, RunFilter

    nav = NavSystem.from_profile(CARRIER)
    lay = nav.layout
    n = lay.n
    fake = Navigator.__new__(Navigator)
    fake.layout, fake.system = lay, nav
    run = RunFilter(None, [], np.zeros(3), np.zeros(3))
    phi, qd = np.eye(n), np.zeros((n, n))
    arc0 = np.full(24, -1)
    arc0[[2, 5, 9]] = 0
    p1, q1 = fake._new_arcs(run, arc0, phi, qd)  # the first epoch: every channel with carrier is a new arc
    arc1 = arc0.copy()
    arc1[5], arc1[9] = 40, -1  # channel 5 re-acquired at sample 40, channel 9 without carrier this epoch
    P = np.random.default_rng(1).normal(size=(n, n))
    P = P @ P.T
    x = np.ones(n)
    p2, q2 = fake._new_arcs(run, arc1, phi, qd)
    i5, i2 = lay.i("amb", 5), lay.i("amb", 2)
    Pm = p2 @ P @ p2.T + q2
    assert Pm[i5, i5] == 100.0 and np.count_nonzero(Pm[i5]) == 1 and (p2 @ x)[i5] == 0.0
    keep = np.setdiff1d(np.arange(n), [i5])
    np.testing.assert_array_equal(Pm[np.ix_(keep, keep)], P[np.ix_(keep, keep)])
    assert (p2 @ x)[i2] == 1.0 and np.all(run.arcs[[2, 5, 9]] == [0, 40, 0])
    p3, _ = fake._new_arcs(run, arc0, phi, qd)  # channel 9 back with its old id: the same arc, no reset
    assert p3[lay.i("amb", 9), lay.i("amb", 9)] == 1.0 and p3[i5, i5] == 0.0
    assert np.all(np.diag(q1)[[lay.i("amb", k) for k in (2, 5, 9)]] == 100.0)


def test_an_exclusion_removes_a_satellites_code_and_carrier():
    assert Source(CP, 7).unit == Source(GPS, 7).unit == "gps07" and Source(CP, 7).name == "cp07"
    fde = FdeState(FdeConfig(enabled=True), 1.0, None, 0.0)
    fde.excluded.add(Source(GPS, 7).unit)
    rows = [Row(Source(k, c), lambda x, k=k, c=c: meas.ScalarMeasurement(0.0, x, 1.0, Source(k, c).name))
            for k in (GPS, CP) for c in (3, 7)]
    kept = [s for s, _ in fde._rows(rows, np.zeros(2))]
    assert kept == [Source(GPS, 3), Source(CP, 3)]
    assert _ranging({Source(GPS, 3), Source(CP, 3), Source(GPS, 5)}) == 2  # one satellite's two rows: one range


def test_closed_loop_step_by_step_equals_the_open_loop_pass_with_carrier():
    """The closed-loop source (sensors applied one truth row at a time, carrier arcs continued sample by sample)
    gives the open-loop pass's navigation with carrier phase, through a GNSS outage (new arcs after it), on the GBAS
    carrier candidate: the closed loop draws for a longer flight, and every draw (the GBAS white noise from its own
    child stream, receiver.draw) is a prefix of the longer record's."""
    from approachsim.loop.closed_loop import NavInTheLoop

    path = PROFILES / "gbas-carrier-cat3-candidate.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    assert data["sensors"]["gnss"]["carrier_phase"] is True and data["sensors"]["gnss"]["corrections"] == "gbas"
    data["faults"] = [{"sensor": "gnss", "kind": "outage", "start_s": 8.0, "end_s": 12.0}]
    prof = parse_profile(data, source=path.resolve())
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=prof.rates.imu_hz, start_distance_m=70.0 * 20.0,
                                        ground_speed_mps=70.0)
    src = NavInTheLoop(prof, seed=4, run=2, max_time_s=30.0)
    for k in range(len(truth)):
        src.step(k, truth)
    closed = src.result(truth)
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=4, runs=2)
    open_ = NavSystem.from_profile(prof).run(truth, recs, stream(4, 2, "nav"), states=st)
    assert list(closed.status.name) == list(open_.status.name)
    assert sum(str(n).startswith("cp") for n in closed.status.name) >= 6 * 15  # all in view, 16 epochs with GNSS
    np.testing.assert_allclose(closed.solution.r_ecef, open_.solution.r_ecef, rtol=0, atol=1e-6)
    np.testing.assert_allclose(closed.x, open_.x, rtol=1e-6, atol=1e-6)
    arcs = recs["gnss"].carrier_arc
    assert np.any(arcs[12] == 12)  # the outage ended the arcs: new ones at its end


@pytest.mark.parametrize("nav", [{"gps_coupling": "loose"}, {"channel_states": False}])
def test_carrier_without_channel_states_fails_when_the_profile_loads(nav):
    from approachsim.config import ProfileError

    path = PROFILES / "gbas-carrier-cat3-candidate.toml"
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    d.setdefault("nav", {}).update(nav)
    with pytest.raises(ProfileError, match="carrier_phase"):
        parse_profile(d, source=path)
