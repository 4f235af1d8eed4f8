"""nav/noise.py under GBAS corrections: the GPS channel states' noise follows the receiver's corrected budget.

The slow state carries the ground + iono + tropo residuals (correlation time their drift-matched combination,
noise.slow_tau_s), the fast state the
airborne multipath + smoothed receiver noise (100 s); the elevation-only noise takes the distance-dependent terms at
gbas.REFERENCE_GEOMETRY; the white code noise is the 2 mm carrier-phase noise. Stand-alone ranging keeps its
formulas bit for bit."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim.nav import errormodel as em
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile, parse_profile
from approachsim.sensors.gnss import gbas as gb
from approachsim.sensors.gnss.receiver import iono_obliquity, tropo_mapping

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""
DEFAULT = PY_DEFAULT


def _nav(**gnss) -> NavSystem:
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["sensors"]["gnss"].update(gnss)
    return NavSystem.from_profile(parse_profile(d, source=DEFAULT))


@pytest.fixture(scope="module")
def navs():
    return _nav(), _nav(corrections="gbas", selection="all")


def _terms(el):
    """The default GBAS model's ground, iono, tropo sigmas at REFERENCE_GEOMETRY, from the standards' forms."""
    x, dh, v = gb.REFERENCE_GEOMETRY
    th = np.degrees(el)
    a = np.where(th > 35.0, 0.15 + 0.84 * np.exp(-th / 15.5), 0.24)
    gnd = np.sqrt(a * a / 4 + 0.04**2)
    iono = iono_obliquity(el) * 4e-6 * (x + 2 * 100.0 * v)
    tropo = 30.0 * 7350e-6 / np.sqrt(0.002 + np.sin(el) ** 2) * (1.0 - math.exp(-dh / 7350.0))
    return gnd, iono, tropo


def _written_out(el):
    """The default GBAS model's channel sigmas at REFERENCE_GEOMETRY, from the standards' tables and forms."""
    gnd, iono, tropo = _terms(el)
    th = np.degrees(el)
    mp = 0.13 + 0.53 * np.exp(-th / 10.0)
    noise = 0.11 + 0.13 * np.exp(-th / 4.0)
    return np.sqrt(gnd**2 + iono**2 + tropo**2), np.sqrt(mp**2 + noise**2)


def test_channel_noise_is_the_corrected_budget(navs):
    _, nav = navs
    el = np.radians(np.linspace(3.0, 89.0, 24))
    nz = nav.noise(el)
    gse, gmp = _written_out(el)
    np.testing.assert_allclose(nz.gse_sigma_m, gse, rtol=1e-12)
    np.testing.assert_allclose(nz.gmp_sigma_m, gmp, rtol=1e-12)
    assert nz.gmp_tau_s == 100.0
    # the slow state's tau: sum sigma^2 / sum sigma^2 / tau over the equal-solid-angle sky above 5 deg (16 points)
    sky = np.arcsin(np.linspace(math.sin(math.radians(5.0)), 1.0, 16))
    v = [t**2 for t in _terms(sky)]
    tau = sum(x.sum() for x in v) / sum(x.sum() / t for x, t in zip(v, (300.0, 1800.0, 3600.0), strict=True))
    assert nz.gse_tau_s == pytest.approx(tau, rel=1e-12) and 300.0 < tau < 1800.0
    assert nav.sensors.gnss.budget().code_noise_m == 0.002  # the white pseudorange noise of the channel-state rows
    # the arrays the compiled epoch takes and P0's channel entries are the same sigmas
    _, k_gse, k_gmp = nav.noise_model.kernel_arrays(el)
    np.testing.assert_array_equal(k_gse, nz.gse_sigma_m)
    np.testing.assert_array_equal(k_gmp, nz.gmp_sigma_m)
    p0 = np.diag(nav.initial_covariance(el))
    lay = nav.layout
    np.testing.assert_allclose(p0[lay.index["gse"]], gse**2, rtol=1e-12)
    np.testing.assert_allclose(p0[lay.index["gmp"]], gmp**2, rtol=1e-12)


def test_channel_qd_follows_the_corrected_budget_at_each_sky(navs):
    """The shared path's per-class Qd reset equals discretizing the model with that sky's GBAS noise."""
    _, nav = navs
    lay = nav.layout
    rng = np.random.default_rng(5)
    el1, el2 = np.radians(rng.uniform(3.0, 88.0, 24)), np.radians(rng.uniform(3.0, 88.0, 24))
    args = (lay, np.radians(37.6), 300.0, np.array([60.0, -20.0, 3.0]), np.array([0.0, 0.0, -9.8]), np.eye(3))
    qd1 = em.discretize(*em.dynamics(*args, nav.noise(el1), nav.loop_gains()), 1.0)[1]
    qd2 = em.discretize(*em.dynamics(*args, nav.noise(el2), nav.loop_gains()), 1.0)[1]
    np.testing.assert_allclose(nav.noise_model.channel_qd(qd1, el2, 1.0), qd2, rtol=1e-12, atol=0.0)
    k = np.arange(lay.index["gse"].start, lay.index["gse"].stop)
    tau = nav.noise(None).gse_tau_s  # the drift-matched tau (test_channel_noise_is_the_corrected_budget)
    np.testing.assert_allclose(qd2[k, k], _written_out(el2)[0] ** 2 * -np.expm1(-2.0 / tau), rtol=1e-12)


def test_corrected_channel_noise_is_lower_and_falls_with_elevation(navs):
    """Well below stand-alone ranging (whose slow state is at least the 2.4 m clock/ephemeris): under a quarter of it
    at every elevation even 10 nmi out, and lower at high elevation, for both states."""
    alone, corr = navs
    el = np.radians(np.linspace(5.0, 90.0, 24))
    a, c = alone.noise(el), corr.noise(el)
    assert np.all(np.asarray(a.gse_sigma_m) >= 2.4)
    assert np.all(np.asarray(c.gse_sigma_m) < np.asarray(a.gse_sigma_m) / 4.0)
    assert np.all(np.diff(c.gse_sigma_m) < 0.0) and np.all(np.diff(c.gmp_sigma_m) < 0.0)
    assert np.all(np.asarray(c.gmp_sigma_m) > np.asarray(a.gmp_sigma_m))  # the smoothed noise joins the multipath


def test_the_budget_takes_the_aircraft_geometry_when_given(navs):
    """What a per-epoch navigation would pass: the slow sigma grows with the distance from and the height above the
    reference point; at REFERENCE_GEOMETRY it is the elevation-only value."""
    _, nav = navs
    bud = nav.sensors.gnss.budget()
    el = np.radians(30.0)
    near = bud.channel_sigmas_m(el, 1500.0, 80.0, 70.0)[0]
    far = bud.channel_sigmas_m(el, 18520.0, 980.0, 70.0)[0]
    assert near < far
    assert bud.channel_sigmas_m(el, *gb.REFERENCE_GEOMETRY)[0] == bud.channel_sigmas_m(el)[0]


def test_compiled_channel_sigmas_equal_the_budget(navs):
    """core/sensors/gnss.gbas_channel_sigmas (for a compiled navigation epoch: per-run elevations and geometry)
    equals the budget's numpy channel_sigmas_m behind nav/noise.py's elevation guard (nan -> 0.5 rad, >= 2 deg), to
    1e-12 relative, each row independent of the others."""
    from approachsim.core.sensors import gnss as gk

    _, nav = navs
    bud = nav.sensors.gnss.budget()
    rng = np.random.default_rng(9)
    el = np.radians(rng.uniform(-5.0, 90.0, (7, 24)))
    el[2, 3] = np.nan
    x, dh, v = rng.uniform(0.0, 30e3, 7), rng.uniform(-50.0, 1500.0, 7), rng.uniform(50.0, 90.0, 7)
    gse, gmp = np.empty(el.shape), np.empty(el.shape)
    gk.gbas_channel_sigmas(el, x, dh, v, *bud.gbas.channel_kernel_args(), gse, gmp)
    guard = np.maximum(np.nan_to_num(el, nan=0.5), np.radians(2.0))
    ref = bud.channel_sigmas_m(guard, x[:, None], dh[:, None], v[:, None])
    np.testing.assert_allclose(gse, ref[0], rtol=1e-12)
    np.testing.assert_allclose(gmp, ref[1], rtol=1e-12)
    one_g, one_m = np.empty((1, 24)), np.empty((1, 24))
    gk.gbas_channel_sigmas(el[4:5], x[4:5], dh[4:5], v[4:5], *bud.gbas.channel_kernel_args(), one_g, one_m)
    np.testing.assert_array_equal(one_g[0], gse[4])
    # at REFERENCE_GEOMETRY it is the elevation-only noise nav/noise.py gives today
    ones = np.ones(7)
    gk.gbas_channel_sigmas(el, *(r * ones for r in gb.REFERENCE_GEOMETRY), *bud.gbas.channel_kernel_args(), gse, gmp)
    np.testing.assert_allclose(gse[2], nav.noise(el[2]).gse_sigma_m, rtol=1e-12)


def test_stand_alone_channel_noise_keeps_its_formula():
    """corrections = "none": sqrt(ce^2 + (I_z F)^2 + (T_z M)^2) and the DO-253 curve, bit for bit; tau the
    drift-matched sum sigma^2 / sum (sigma^2 / tau) of clock/ephemeris, iono, tropo over the 5-90 deg sky: between
    the shortest and the longest, near the clock/ephemeris's 7200 s that dominates the P(Y) budget."""
    nav = NavSystem.from_profile(load_profile(DEFAULT))
    bud = nav.sensors.gnss.budget()
    el = np.radians(np.linspace(3.0, 89.0, 24))
    nz = nav.noise(el)
    gse = np.sqrt(bud.clock_ephemeris_m**2 + (bud.iono_zenith_m * iono_obliquity(el)) ** 2
                  + (bud.tropo_zenith_m * tropo_mapping(el)) ** 2)
    np.testing.assert_array_equal(nz.gse_sigma_m, gse)
    np.testing.assert_array_equal(nz.gmp_sigma_m, 0.13 + 0.53 * np.exp(-np.degrees(el) / 10.0))
    sky = np.arcsin(np.linspace(math.sin(math.radians(5.0)), 1.0, 16))
    v = (np.full(16, bud.clock_ephemeris_m) ** 2, (bud.iono_zenith_m * iono_obliquity(sky)) ** 2,
         (bud.tropo_zenith_m * tropo_mapping(sky)) ** 2)
    taus = (bud.clock_ephemeris_tau_s, bud.iono_tau_s, bud.tropo_tau_s)
    tau = sum(x.sum() for x in v) / sum(x.sum() / t for x, t in zip(v, taus, strict=True))
    assert nz.gse_tau_s == pytest.approx(tau, rel=1e-12) and 5000.0 < tau < 7200.0
    assert bud.code_noise_m == 0.6
