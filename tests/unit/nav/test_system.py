"""NavSystem over sensor records: exact sensors and no initial error give centimetre navigation; the
status log and the NavSolution have the documented shapes; feedback and feed-forward agree."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from approachsim import geo, synthetic
from approachsim.nav import ins
from approachsim.nav import terrain_db as tdb
from approachsim.nav.config import InitialError
from approachsim.nav.registry import FILTERS
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""

PROFILE = load_profile(PY_DEFAULT)


def _truth(duration_s=60.0):
    return synthetic.glidepath_descent(PROFILE.runway.frame, rate_hz=20.0, start_distance_m=70.0 * duration_s,
                                       ground_speed_mps=70.0)


def _system(**nav_kw):
    """The default profile's navigation with nav_kw changed; no damping loop unless asked: a noise-free
    altimeter still reads the ISA geopotential height (0.15 m below the geometric height at 1000 m, h^2 / R),
    which the loop would pull an exactly started INS to."""
    nav = NavSystem.from_profile(PROFILE)
    nav_kw.setdefault("baro_loop", "none")
    return NavSystem.build(replace(nav.nav, **nav_kw), PROFILE.sensors, PROFILE.runway.frame, PROFILE.terrain)


@pytest.mark.parametrize("feedback", [False, True])
def test_noiseless_sensors_and_no_initial_error_stay_within_1cm(feedback):
    truth = _truth()
    recs = SensorSuite.from_profile(PROFILE).measure(truth, seed=3, runs=0, noise=False)
    nav = _system(initial_error=InitialError(0.0, 0.0, 0.0, 0.0, start="prior"), feedback=feedback,
                  terrain_database=tdb.EXACT)
    run = nav.run(truth, recs, stream(3, 0, "nav"))
    sol = run.solution
    lat, lon, h = geo.ecef_to_geodetic(sol.r_ecef)
    dp = ins.position_error_ned(lat, lon, h, truth.lat_rad, truth.lon_rad, truth.h_m)
    assert np.max(np.linalg.norm(dp, axis=1)) < 0.01
    assert np.max(np.linalg.norm(sol.v_ned - truth.v_ned, axis=1)) < 0.001
    assert np.all(run.status.accepted)
    assert np.max(np.abs(run.status.innovation)) < 0.01  # exact sensors: the INS predicts every measurement


def test_solution_and_status_shapes_and_names():
    truth = _truth(20.0)
    recs, st = measure_with_states(SensorSuite.from_profile(PROFILE), truth, seed=3, runs=0)
    run = _system().run(truth, recs, stream(3, 0, "nav"), states=st)
    n = len(truth)
    assert run.solution.r_ecef.shape == (n, 3) and run.solution.P_pos_ned.shape == (n, 3, 3)
    assert run.t_epoch_s.shape == (20,) and run.x.shape == (20, run.layout.n)
    names = set(run.status.name)
    assert "baro" in names and "radalt" in names and any(s.startswith("gps") for s in names)
    # every status: S > 0 and the test ratio is nu^2 / S (not nu^2 * S)
    np.testing.assert_allclose(run.status.test_ratio, run.status.innovation**2 / run.status.variance)
    assert np.all(run.status.variance > 0)


def test_batched_runs_equal_single_runs():
    truth = _truth(10.0)
    suite = SensorSuite.from_profile(PROFILE)
    nav = _system()
    recs2, st2 = measure_with_states(suite, truth, seed=5, runs=[0, 1])
    recs1, st1 = measure_with_states(suite, truth, seed=5, runs=1)
    both = nav.run(truth, recs2, [stream(5, r, "nav") for r in (0, 1)], states=st2)
    one = nav.run(truth, recs1, stream(5, 1, "nav"), states=st1)
    # bit-identical: a run's numbers must not depend on the batch it shares (campaign/pipeline.py relies on it)
    np.testing.assert_array_equal(both[1].solution.r_ecef, one.solution.r_ecef)
    np.testing.assert_array_equal(both[1].x, one.x)


def test_loose_coupling_uses_position_fixes():
    """gps_coupling = "loose": three position scalars per epoch from a least-squares fix, no clock state, and
    exact sensors give an exact fix (innovations at the centimetre level)."""
    truth = _truth(10.0)
    recs = SensorSuite.from_profile(PROFILE).measure(truth, seed=3, runs=0, noise=False)
    nav = _system(gps_coupling="loose", initial_error=InitialError(0.0, 0.0, 0.0, 0.0, start="prior"))
    assert not nav.layout.has("clk") and not nav.layout.has("gse")
    run = nav.run(truth, recs, stream(3, 0, "nav"))
    names = list(run.status.name)
    assert names.count("gps_N") == 10 and not any(n.startswith("gps0") for n in names)
    m = np.char.startswith(run.status.name, "gps_")
    assert np.max(np.abs(run.status.innovation[m])) < 0.01


def test_shared_covariance_matches_per_run_filters():
    """Open-loop runs on one truth: one shared covariance/gain (linearized along the shared truth) gives the per-run
    estimates to a small fraction of their sigma, the same status records, and is refused for robust filters."""
    truth = _truth(20.0)
    suite = SensorSuite.from_profile(PROFILE)
    recs, st = measure_with_states(suite, truth, seed=6, runs=[0, 1, 2])
    nav = _system()
    rngs = [stream(6, r, "nav") for r in range(3)]
    per = nav.run(truth, recs, rngs, states=st)
    shared = nav.run(truth, recs, [stream(6, r, "nav") for r in range(3)], shared_covariance=True, states=st)
    for a, b in zip(per, shared, strict=True):
        sd = np.sqrt(a.P_diag)
        assert np.max(np.abs(a.x - b.x) / sd) < 0.2  # gains linearized along the truth (measured 0.06)
        assert list(a.status.name) == list(b.status.name)
        np.testing.assert_allclose(b.status.variance, a.status.variance, rtol=0.1)  # measured: within 4.6 %
    with pytest.raises(ValueError, match="optimal"):
        _system(filter="rkf-gate").run(truth, recs, rngs, shared_covariance=True, states=st)


NEES_RUNS = 20


@pytest.mark.parametrize("name", sorted(FILTERS))
def test_every_registered_filter_is_drop_in(name):
    """Each filter of the registry runs the navigation (U-D ones store no P: the system asks covariance()) and
    is consistent: at each of the 8 epochs the NEES of the 9 navigation errors averaged over 20 runs lies inside
    the two-sided 99.9 % bounds chi2(9 R) / R (R = 20: [6.2, 12.5]; 8 epochs, family level >= 99 % by
    Bonferroni). Measured: 9.8-10.8 for every filter (ekf 10.5 at the first epoch); a filter over-confident by
    a factor 1.3 in variance (ANEES ~13.4) fails."""
    truth = _truth(8.0)
    runs = range(NEES_RUNS)
    recs, st = measure_with_states(SensorSuite.from_profile(PROFILE), truth, seed=2, runs=runs)
    out = _system(filter=name).run(truth, recs, [stream(2, r, "nav") for r in runs], states=st)
    for run in out:
        assert run.x.shape == (8, run.layout.n) and np.all(np.isfinite(run.P_nav))
    e = np.stack([r.true_error_nav for r in out])
    P = np.stack([r.P_nav for r in out])
    anees = np.einsum("rki,rki->rk", e, np.linalg.solve(P, e[..., None])[..., 0]).mean(axis=0)
    lo, hi = chi2.ppf([0.0005, 0.9995], 9 * NEES_RUNS) / NEES_RUNS
    assert np.all((anees >= lo) & (anees <= hi)), (anees, lo, hi)
