"""nav/gbas_scale.py: the GBAS channel states follow the aircraft's geometry along the approach.

The slow channel error under GBAS is S(el, G(t)) u(t), u of unit variance, G = (x_air, dh, v_air) the aircraft's
slant distance to the reference point, height above it and horizontal speed (sensors/gnss/gbas.py). The filter's
transition x <- r exp(-dt / tau) x + w, r = S(G(t)) / S(G(t - dt)), Var w = S(G(t))^2 (1 - exp(-2 dt / tau)) must
keep the state's variance at S(G(t))^2 along a flown path; the geometry must be the truth's; the copies' D P D form
must equal the per-run D Phi form."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import geo
from approachsim.core.nav import epoch as ke
from approachsim.core.nav import errormodel as ek
from approachsim.nav.gbas_scale import GbasScale
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.sensors.gnss import gbas as gb

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
EPS = np.finfo(float).eps


@pytest.fixture(scope="module")
def system() -> NavSystem:
    return NavSystem.from_profile(load_profile(PROFILES / "gbas-cat3-candidate.toml"))


@pytest.fixture(scope="module")
def scale(system) -> GbasScale:
    s = GbasScale.of(system)
    assert s is not None
    return s


def _geodetic(runway: geo.RunwayFrame, t: np.ndarray) -> np.ndarray:
    """(lat, lon, h) (n, 3) of a straight 3 deg final at 70 m/s from 10 nmi before the threshold to 50 ft over it."""
    along = -10.0 * 1852.0 + 70.0 * t
    up = -along * math.tan(math.radians(3.0)) + 15.24
    r = runway.to_ecef(np.column_stack([along, np.zeros_like(t), up]))
    return np.column_stack(geo.ecef_to_geodetic(r))


def _rows(runway: geo.RunwayFrame, t: np.ndarray) -> np.ndarray:
    """Packed navigation rows (n, 16) on that path: lat, lon, h and the NED velocity as their time derivative
    (central differences over 1 ms: truncation (1e-3 s)^2 times the path's third derivative, nil)."""
    p = _geodetic(runway, t)
    d = (_geodetic(runway, t + 1e-3) - _geodetic(runway, t - 1e-3)) / 2e-3
    r_n, r_e = geo.radii(p[:, 0])
    y = np.zeros((t.size, 16))
    y[:, 0:3] = p
    y[:, 3] = (r_n + p[:, 2]) * d[:, 0]
    y[:, 4] = (r_e + p[:, 2]) * np.cos(p[:, 0]) * d[:, 1]
    y[:, 5] = -d[:, 2]
    y[:, 6:15] = np.eye(3).ravel()
    return y


def test_geometry_is_the_truths(system, scale) -> None:
    """G(t) from a navigation row equals the truth's (gbas.station_geometry on the same ECEF point)."""
    t = np.arange(0.0, 260.0, 10.0)
    y = _rows(system.runway, t)
    now, _ = scale.geometry(y, 1.0)
    r = geo.geodetic_to_ecef(y[:, 0], y[:, 1], y[:, 2])
    x, dh, v = gb.station_geometry(r, y[:, 2], y[:, 3:6], scale.station_ecef, scale.station_h_m)
    # the same formulas on the same numbers: rounding of a 2e4 m difference of 6.4e6 m coordinates
    np.testing.assert_allclose(now[:, 0], x, rtol=0, atol=64 * EPS * 6.4e6)
    np.testing.assert_array_equal(now[:, 1], dh)
    np.testing.assert_array_equal(now[:, 2], v)
    assert now[0, 0] == pytest.approx(math.hypot(18520.0, 985.8), rel=1e-3) and now[-1, 0] < 1100.0


def test_geometry_a_second_back_is_the_paths(system, scale) -> None:
    """G(t - dt) from the row's position moved back along its velocity is the path's own point a second earlier:
    the straight ECEF line bends in NED by v^2 dt^2 / (2 R) = 4e-4 m over 1 s at 70 m/s."""
    t = np.arange(1.0, 260.0, 13.0)
    _, before = scale.geometry(_rows(system.runway, t), 1.0)
    exact, _ = scale.geometry(_rows(system.runway, t - 1.0), 1.0)
    np.testing.assert_allclose(before[:, :2], exact[:, :2], rtol=0, atol=1e-2)


def test_sigmas_are_the_budgets(system, scale) -> None:
    """The compiled channel sigmas at a geometry are the budget's numpy formulas (gbas.GbasModel)."""
    el = np.radians(np.array([[5.0, 12.0, 30.0, 60.0, 88.0]] * 3))
    geom = np.array([[18520.0, 985.0, 70.0], [5000.0, 260.0, 68.0], [300.0, 15.0, 65.0]])
    gse, gmp = scale.sigmas(el, geom)
    model = system.sensors.gnss.budget().gbas
    g, m = model.channel_sigmas_m(el, geom[:, :1], geom[:, 1:2], geom[:, 2:3])
    np.testing.assert_allclose(gse, g, rtol=16 * EPS)
    np.testing.assert_allclose(gmp, m, rtol=16 * EPS)


def test_the_state_variance_follows_the_geometry(system, scale) -> None:
    """P <- r^2 a^2 P + S(G(t))^2 (1 - a^2) from S(G(t0))^2 stays S(G(t))^2 along the flown path (the geometry a
    second back within 1e-2 m, of a term's x_air + 2 tau v_air >= 1.4e4 m: 7e-7 a step, 260 steps), and the high
    satellites' slow sigma shrinks toward the threshold (the ionospheric term with the distance)."""
    tau = system.noise_model.noise(None).gse_tau_s
    a2 = math.exp(-2.0 / tau)
    t = np.arange(0.0, 261.0, 1.0)
    y = _rows(system.runway, t)
    el = np.radians(np.array([[8.0, 25.0, 45.0, 75.0]]))
    p = scale.sigmas(el, scale.geometry(y[:1], 1.0)[0])[0][0] ** 2
    for k in range(1, t.size):
        gse, _, r = scale.interval(el, y[k], 1.0)
        p = r[0] ** 2 * a2 * p + gse[0] ** 2 * (1.0 - a2)
        np.testing.assert_allclose(p, gse[0] ** 2, rtol=3e-4)
    first = scale.sigmas(el, scale.geometry(y[:1], 1.0)[0])[0][0]
    assert np.all(gse[0] / first < 0.8) and np.all(gse[0] / first > 0.2)


def test_copies_scale_equals_the_per_run_scale(system) -> None:
    """The copies' D P D before the predict (core/nav/epoch._scale_states) equals the per-run D Phi
    (core/nav/errormodel.scale_channels): Phi's channel rows and columns hold only their diagonal."""
    n, ig, k = system.layout.n, system.layout.i("gse"), system.layout.n_sv
    rng = np.random.default_rng(5)
    phi = np.eye(n) + 0.01 * rng.standard_normal((n, n))
    phi[ig:ig + k, :] = 0.0
    phi[:, ig:ig + k] = 0.0
    phi[np.arange(ig, ig + k), np.arange(ig, ig + k)] = 0.999
    a = rng.standard_normal((n, n))
    P = a @ a.T + n * np.eye(n)
    x = rng.standard_normal(n)
    r = 1.0 - 0.01 * rng.random(k)
    phi_s = phi.copy()
    ek.scale_channels(phi_s, ig, r)
    x2, P2 = x.copy(), P.copy()
    ke._scale_states(x2, P2, ig, r)
    # the same products in another order: eps times the operands' size (|Phi| |P| |Phi| over n terms)
    tol = 8 * n * EPS * np.abs(phi).max() ** 2 * np.abs(P).max()
    np.testing.assert_allclose(phi @ P2 @ phi.T, phi_s @ P @ phi_s.T, rtol=0, atol=tol)
    np.testing.assert_allclose(phi @ x2, phi_s @ x, rtol=0, atol=4 * n * EPS * np.abs(phi).max() * np.abs(x).max())


def test_only_gbas_is_scaled() -> None:
    """Stand-alone GPS has no GBAS scale."""
    assert GbasScale.of(NavSystem.from_profile(load_profile(PROFILES / "default.toml"))) is None


def test_carrier_phase_scales_the_ionosphere_and_the_rest_apart() -> None:
    """With carrier phase the ionosphere states (gio) and the slow states without it (gse: ground and troposphere)
    each keep their own variance at G(t) along the path; no gradient (sigma_vig 0): the ionosphere's scale is 1."""
    nav = NavSystem.from_profile(load_profile(PROFILES / "gbas-carrier-cat3-candidate.toml"))
    sc = GbasScale.of(nav)
    assert nav.layout.has("gio") and sc is not None and sc.carrier
    nz = nav.noise_model.noise(None)
    a_se, a_io = math.exp(-2.0 / nz.gse_tau_s), math.exp(-2.0 / nz.gio_tau_s)
    t = np.arange(0.0, 261.0, 1.0)
    y = _rows(nav.runway, t)
    el = np.radians(np.array([[8.0, 25.0, 45.0, 75.0]]))
    gse, gio, _, _, _ = sc.carrier_interval(el, y[0], 1.0)
    p_se, p_io = gse[0] ** 2, gio[0] ** 2
    first = gse[0], gio[0]
    for k in range(1, t.size):
        gse, gio, _, r, r_io = sc.carrier_interval(el, y[k], 1.0)
        p_se = r[0] ** 2 * a_se * p_se + gse[0] ** 2 * (1.0 - a_se)
        p_io = r_io[0] ** 2 * a_io * p_io + gio[0] ** 2 * (1.0 - a_io)
        # the back-step's geometry error (<= 1e-2 m a step, one sign on this path) over the ionospheric term's
        # x_air + 2 tau v_air >= 1.4e4 m: <= 7e-7 a step, 2e-4 over 260 steps
        np.testing.assert_allclose(p_se, gse[0] ** 2, rtol=3e-4)
        np.testing.assert_allclose(p_io, gio[0] ** 2, rtol=3e-4)
    # the ionosphere with the distance (x_air + 2 tau v_air: 3.3e4 -> 1.5e4 m); the rest with the troposphere's height
    # term, most at low elevation (28 cm at 5 deg 10 nmi out, nil over the threshold), the ground term unchanged
    assert np.all(gio[0] / first[1] < 0.6)
    assert np.all(gse[0] < first[0]) and np.all(gse[0] / first[0] > 0.5) and gse[0][-1] / first[0][-1] > 0.9
    flat = GbasScale(sc.station_ecef, sc.station_h_m, sc.kernel_args, sc.lay,
                     replace(sc.model, sigma_vig_per_m=0.0), True)
    _, gio0, _, _, r_io0 = flat.carrier_interval(el, y[100], 1.0)
    assert np.all(gio0 == 0.0) and np.all(r_io0 == 1.0)


def test_p0_at_the_approach_start():
    """P0's GBAS channel variances are the budget's at the approach's own start (gbas.approach_geometry of the
    profile's start distance, glidepath, TCH and speed): the shipped 10 nmi candidate's is REFERENCE_GEOMETRY
    exactly (its figures unchanged), a 25 nmi final's has the larger distance-dependent ionospheric term."""
    base = load_profile(PROFILES / "gbas-cat3-candidate.toml")
    assert base.gbas_geometry() == gb.REFERENCE_GEOMETRY
    far = replace(base, runway=replace(base.runway, start_distance_m=25.0 * 1852.0))
    g = far.gbas_geometry()
    x = 25.0 * 1852.0
    assert g == (x, x * math.tan(base.runway.glidepath_rad) + base.runway.tch_m, 140.0 * 1852.0 / 3600.0)
    el = np.radians(np.linspace(6.0, 85.0, 24))  # one elevation per channel
    bud = base.sensors.gnss.budget()
    for prof, geom in ((base, gb.REFERENCE_GEOMETRY), (far, g)):
        sys_ = NavSystem.from_profile(prof)
        assert sys_.noise_model.gbas_geometry == geom
        p0 = sys_.noise_model.initial_covariance(el)
        gse = np.diag(p0)[sys_.layout.index["gse"]]
        want = bud.channel_sigmas_m(el, *geom)[0] ** 2
        np.testing.assert_allclose(gse, want, rtol=4 * EPS, atol=0)  # the same numpy formula: a few roundings
    near_s = bud.channel_sigmas_m(el, *gb.REFERENCE_GEOMETRY)[0]
    far_s = bud.channel_sigmas_m(el, *g)[0]
    assert np.all(far_s > near_s)  # sigma_iono grows with x_air (Annex 10 App. B)
