"""The filter's terrain-database error: its sigmas (bias, Area 4, beyond), its along-track correlation length,
its own stream, and zero keys giving the truth terrain exactly; the filter's states and P0 follow it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
from approachsim.nav import errormodel as em
from approachsim.nav import terrain_db as tdb
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream, substream

_DEFAULT = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")
PROFILE = replace(_DEFAULT, nav=replace(_DEFAULT.nav, initial_error=replace(_DEFAULT.nav.initial_error, start="prior")))
"""The default profile with the prior start: these tests call NavSystem.start alone (no sensor states)."""
N = 2000  # realizations: the relative sd of a sigma estimate is 1 / sqrt(2 N) = 1.6 %; bounds below are 5 sd


def _draws(cfg: tdb.TerrainDbConfig, n: int = N) -> list[tdb.TerrainDbError]:
    return [tdb.draw(cfg, substream(stream(7, i, "nav"), "terrain_db")) for i in range(n)]


def test_default_sigmas_from_the_icao_90_percent_figures():
    c = tdb.TerrainDbConfig()
    assert np.hypot(c.bias_sigma_m, c.sigma_m) == pytest.approx(1.0 / 1.6449, rel=1e-4)  # Area 4: 1 m at 90 %
    assert np.hypot(c.bias_sigma_m, c.outer_sigma_m) == pytest.approx(3.0 / 1.6449, rel=1e-4)  # Area 2: 3 m
    assert c.bias_sigma_m == pytest.approx(c.sigma_m)
    assert c.sigma_at(-899.0) == c.sigma_m and c.sigma_at(100.0) == c.sigma_m and c.sigma_at(-901.0) == c.outer_sigma_m


def test_bias_and_correlated_sigmas_over_many_draws():
    c = tdb.TerrainDbConfig()
    d = _draws(c)
    bias = np.array([e.bias_m for e in d])
    assert bias.std() == pytest.approx(c.bias_sigma_m, rel=0.08)
    for x in (-300.0, -5000.0):  # Area 4 and beyond: the total error there
        e = np.array([float(r(x)) for r in d])
        assert e.std() == pytest.approx(float(np.hypot(c.bias_sigma_m, c.sigma_at(x))), rel=0.08)
        corr = np.array([float(r(x)) - r.bias_m for r in d])
        assert corr.std() == pytest.approx(float(c.sigma_at(x)), rel=0.08)
        assert abs(corr.mean()) < 5 * float(c.sigma_at(x)) / np.sqrt(N)


@pytest.mark.parametrize("lag_m", [100.0, 300.0, 600.0])
def test_along_track_correlation_is_exp_minus_lag_over_length(lag_m):
    """E[u(x) u(x + d)] = exp(-d / L) at three lags (pooled over the realizations and many x, within Area 2)."""
    c = tdb.TerrainDbConfig()
    d = _draws(c, 400)
    x = np.arange(-60000.0, -20000.0, 1000.0)  # 40 points 1 km apart (3 L: nearly independent) per realization
    a = np.concatenate([(r(x) - r.bias_m) / c.outer_sigma_m for r in d])
    b = np.concatenate([(r(x + lag_m) - r.bias_m) / c.outer_sigma_m for r in d])
    rho = float(np.mean(a * b) / np.sqrt(np.mean(a * a) * np.mean(b * b)))
    # 16000 pairs: sd of rho about (1 - rho^2) / sqrt(n) < 0.008; 5 sd
    assert rho == pytest.approx(np.exp(-lag_m / c.correlation_m), abs=0.04)


def test_zero_keys_give_the_truth_terrain_exactly():
    assert tdb.EXACT.zero and not tdb.EXACT.correlated
    assert tdb.draw(tdb.EXACT, np.random.default_rng(0)) is None
    nav = NavSystem.from_profile(PROFILE)
    exact = NavSystem.build(replace(nav.nav, terrain_database=tdb.EXACT), PROFILE.sensors, PROFILE.runway.frame,
                            PROFILE.terrain)
    truth = synthetic.glidepath_descent(PROFILE.runway.frame, rate_hz=10.0, start_distance_m=3000.0,
                                        ground_speed_mps=70.0)
    _, runs = exact.start(truth, [stream(1, r, "nav") for r in range(3)])
    assert all(r.db_error is None for r in runs)  # every lookup is terrain_h, the truth terrain
    assert not exact.layout.has("tdb")
    # the realistic default carries a realization per run, different per run
    _, runs = nav.start(truth, [stream(1, r, "nav") for r in range(3)])
    vals = [float(r.db_error(-500.0)) for r in runs]
    assert len(set(vals)) == 3 and nav.layout.has("tdb") and nav.layout.has("rab")


def test_the_database_stream_leaves_the_nav_draws_alone():
    """The initial INS errors (the nav stream's draws) are the same with and without a database error."""
    nav = NavSystem.from_profile(PROFILE)
    exact = NavSystem.build(replace(nav.nav, terrain_database=tdb.EXACT), PROFILE.sensors, PROFILE.runway.frame,
                            PROFILE.terrain)
    truth = synthetic.glidepath_descent(PROFILE.runway.frame, rate_hz=10.0, start_distance_m=3000.0,
                                        ground_speed_mps=70.0)
    s1, _ = nav.start(truth, [stream(5, r, "nav") for r in range(4)])
    s0, _ = exact.start(truth, [stream(5, r, "nav") for r in range(4)])
    assert np.array_equal(s1.h_m, s0.h_m) and np.array_equal(s1.v_ned, s0.v_ned)


def test_filter_p0_and_dynamics_of_the_radalt_states():
    nav = NavSystem.from_profile(PROFILE)
    lay, r, c = nav.layout, PROFILE.sensors.radalt, PROFILE.nav.terrain_database
    P0 = nav.initial_covariance()
    assert P0[lay.i("rab"), lay.i("rab")] == pytest.approx(r.bias_sigma_m**2 + c.bias_sigma_m**2)
    assert P0[lay.i("ram"), lay.i("ram")] == pytest.approx(r.markov_sigma_m**2)
    assert P0[lay.i("tdb"), lay.i("tdb")] == 1.0
    v = np.array([60.0, -30.0, 3.5])
    F, Qc = em.dynamics(lay, 0.65, 100.0, v, np.array([0.0, 0.0, -9.8]), np.eye(3), nav.noise(), nav.loop_gains())
    tau = c.correlation_m / np.hypot(60.0, -30.0)  # the along-track correlation length at the ground speed
    i, j, k = lay.i("rab"), lay.i("ram"), lay.i("tdb")
    assert F[i, i] == 0.0 and Qc[i, i] == 0.0
    assert F[j, j] == pytest.approx(-1.0 / r.markov_tau_s) and Qc[j, j] == pytest.approx(2 * r.markov_sigma_m**2 / 10.0)
    assert F[k, k] == pytest.approx(-1.0 / tau) and Qc[k, k] == pytest.approx(2.0 / tau)
    # no radar altimeter: no such states
    no_ra = NavSystem.build(nav.nav, replace(PROFILE.sensors, radalt=None), PROFILE.runway.frame, PROFILE.terrain)
    assert not any(no_ra.layout.has(g) for g in ("rab", "ram", "tdb"))
