"""U-D filter (Bierman / Thornton-MWGS) and the robust U-D of Chernodarov sec. 4."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from approachsim.config import ProfileError
from approachsim.nav.base import KalmanFilter, ScalarMeasurement, joseph_reference
from approachsim.nav.registry import FILTERS, make_filter
from approachsim.nav.ud import (
    InfluenceFunction,
    UDFilter,
    bierman_update,
    mwgs,
    mwgs_robust_update,
    thornton_predict,
    ud_factor,
)

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


def _spd(rng: np.random.Generator, n: int) -> np.ndarray:
    A = rng.normal(size=(n, n))
    return A @ A.T + np.eye(n)


@pytest.mark.parametrize("seed", range(5))
def test_ud_factor_and_mwgs_round_trip(seed: int) -> None:
    rng = np.random.default_rng(seed)
    P = _spd(rng, 6)
    U, d = ud_factor(P)
    assert np.allclose(np.tril(U, -1), 0.0) and np.allclose(np.diag(U), 1.0)
    np.testing.assert_allclose((U * d) @ U.T, P, rtol=1e-12, atol=1e-12)
    W = rng.normal(size=(6, 9))
    dw = rng.random(9)
    U2, d2 = mwgs(W, dw)
    np.testing.assert_allclose((U2 * d2) @ U2.T, (W * dw) @ W.T, rtol=1e-12, atol=1e-12)


@settings(derandomize=True, max_examples=100, deadline=None)
@given(st.integers(1, 8), st.integers(0, 2**32 - 1), st.floats(-6.0, 6.0))
def test_update_then_factors_are_a_valid_covariance(n: int, seed: int, log_r: float) -> None:
    """Invariant (any size, any noise level over 12 decades): after a Thornton predict and a Bierman update the
    factors are unit upper triangular with d >= 0, and U D U' equals the covariance-form result."""
    rng = np.random.default_rng(seed)
    U, d = ud_factor(_spd(rng, n))
    F = np.eye(n) + 0.3 * rng.normal(size=(n, n))
    Q = np.diag(rng.random(n))
    U, d = thornton_predict(U, d, F, Q)
    P = (U * d) @ U.T
    h, r = rng.normal(size=n), 10.0**log_r
    U2, d2, K, S = bierman_update(U, d, h, r)
    assert np.all(d2 >= 0.0) and np.allclose(np.diag(U2), 1.0) and np.all(np.tril(U2, -1) == 0.0)
    P_ref = P - np.outer(P @ h, P @ h) / (h @ P @ h + r)
    np.testing.assert_allclose((U2 * d2) @ U2.T, P_ref, rtol=1e-8, atol=1e-10 * np.max(np.abs(P)))
    np.testing.assert_allclose(K, P @ h / S, rtol=1e-8, atol=1e-12)


def test_ud_factor_of_a_singular_matrix_gives_zero_pivots() -> None:
    Q = np.diag([0.0, 2.0, 0.0])
    U, d = ud_factor(Q)
    np.testing.assert_array_equal(d, [0.0, 2.0, 0.0])
    np.testing.assert_allclose((U * d) @ U.T, Q)


@pytest.mark.parametrize("seed", range(4))
def test_plain_ud_agrees_with_joseph_kalman_filter_to_1e_9(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    n = 6
    F = np.eye(n) + 0.05 * rng.normal(size=(n, n))
    B = rng.normal(size=(n, n))
    Q = 0.05 * B @ B.T
    kf, ud = KalmanFilter(), UDFilter()
    s_kf, s_ud = kf.init(np.zeros(n), _spd(rng, n)), ud.init(np.zeros(n), _spd(np.random.default_rng(100 + seed), n))
    s_kf = kf.init(np.zeros(n), ud.covariance(s_ud))
    for k in range(60):
        s_kf, s_ud = kf.predict(s_kf, F, Q), ud.predict(s_ud, F, Q)
        for j in range(3):
            m = ScalarMeasurement(float(rng.normal()), rng.normal(size=n), float(0.2 + rng.random()), f"m{j}", k)
            s_kf, st_kf = kf.update(s_kf, m)
            s_ud, st_ud = ud.update(s_ud, m)
            assert st_ud.innovation == pytest.approx(st_kf.innovation, rel=1e-9, abs=1e-12)
            assert st_ud.variance == pytest.approx(st_kf.variance, rel=1e-9)
            assert st_ud.weight == pytest.approx(1.0)
    P_kf, P_ud = s_kf.P, ud.covariance(s_ud)
    assert np.max(np.abs(P_ud - P_kf)) / np.max(np.abs(P_kf)) < 1e-9
    assert np.max(np.abs(s_ud.x - s_kf.x)) / np.max(np.abs(s_kf.x)) < 1e-9


def _exact_posterior(H: list[list[Fraction]], r: Fraction) -> np.ndarray:
    """(I + H' H / r)^-1 in exact rational arithmetic (P0 = I), as floats."""
    n = 3
    M = [[Fraction(int(i == j)) + sum(H[k][i] * H[k][j] for k in range(len(H))) / r for j in range(n)]
         for i in range(n)]
    A = [row + [Fraction(int(i == j)) for j in range(n)] for i, row in enumerate(M)]
    for c in range(n):
        p = next(i for i in range(c, n) if A[i][c] != 0)
        A[c], A[p] = A[p], A[c]
        A[c] = [v / A[c][c] for v in A[c]]
        for i in range(n):
            if i != c:
                A[i] = [a - A[i][c] * b for a, b in zip(A[i], A[c], strict=True)]
    return np.array([[float(v) for v in row[n:]] for row in A])


def test_pinned_ill_conditioned_case_ud_stays_positive_definite_where_joseph_does_not() -> None:
    """Kalman's ill-conditioned example (Grewal & Andrews): P0 = I, h1 = [1 1 1], h2 = [1 1 1+delta],
    r = delta^2 with delta = 1e-6 (so 1 + r rounds badly). Exact P has eigenvalues ~ (1.7e-13, 0.75, 1).
    The Joseph *product* form (I - K h') P (I - K h')' + r K K' is called explicitly (base.joseph_reference):
    the filter evaluates the same algebra expanded (kernels.kalman), whose rounding on this case is another."""
    delta = 1e-6
    H = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0 + delta]])
    r = delta**2
    ud = UDFilter()
    x_j, P_j = np.zeros(3), np.eye(3)
    s_ud = ud.init(np.zeros(3), np.eye(3))
    for row in H:
        x_j, P_j = joseph_reference(x_j, P_j, row, r, 0.0)
        s_ud, _ = ud.update(s_ud, ScalarMeasurement(0.0, row, r))
    exact = _exact_posterior([[Fraction(v) for v in row] for row in H], Fraction(r))
    lam_exact = np.linalg.eigvalsh(exact)
    assert lam_exact[0] > 0.0
    assert np.min(np.linalg.eigvalsh(P_j)) < 0.0  # the Joseph product form has lost definiteness
    assert np.all(s_ud.d > 0.0)  # U-D: P = U D U' with D > 0 is positive definite by construction
    lam_ud = np.linalg.eigvalsh(ud.covariance(s_ud))
    np.testing.assert_allclose(lam_ud[1:], lam_exact[1:], rtol=1e-6)
    np.testing.assert_allclose(s_ud.d[0], np.linalg.det(exact) / np.linalg.det(exact[1:, 1:]), rtol=1e-3)


@pytest.mark.parametrize("psi_prime", [1.0, 1.0 / 3.0, 0.0])
def test_papers_literal_mwgs_robust_update_equals_bierman_with_inflated_noise(psi_prime: float) -> None:
    rng = np.random.default_rng(7)
    U, d = ud_factor(_spd(rng, 5))
    h, r = rng.normal(size=5), 0.7
    U1, d1, K1 = mwgs_robust_update(U, d, h, r, psi_prime)
    P = (U * d) @ U.T
    expected = P if psi_prime == 0.0 else P - np.outer(P @ h, P @ h) / (h @ P @ h + r / psi_prime)
    np.testing.assert_allclose((U1 * d1) @ U1.T, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(K1, P @ h / (psi_prime * (h @ P @ h) + r), rtol=1e-12)
    if psi_prime > 0:
        U2, d2, K2, S = bierman_update(U, d, h, r / psi_prime)
        np.testing.assert_allclose((U2 * d2) @ U2.T, expected, rtol=1e-12, atol=1e-12)
        assert S == pytest.approx(h @ P @ h + r / psi_prime)


def test_influence_functions_as_the_paper_defines_them() -> None:
    g, lap, gl = InfluenceFunction("gauss"), InfluenceFunction("laplace"), InfluenceFunction("gauss-laplace")
    hub = InfluenceFunction("huber", huber_k=2.0)
    assert g(7.0, 7.0) == (7.0, 1.0)
    assert lap(1.0, 1.0) == (1.0, 1.0) and lap(-5.0, -5.0) == (-1.0, 0.0)  # psi_l = sign, psi'_l = 0
    assert gl(1.5, 1.5) == (1.5, 1.0)
    assert gl(2.4, 2.4) == pytest.approx((0.8, 1.0 / 3.0))  # psi_lg = beta/3 near the 3-sigma tolerance
    assert gl(9.0, 9.0) == (1.0, 0.0)
    assert hub(1.0, 1.0) == (1.0, 1.0) and hub(-4.0, -4.0) == pytest.approx((-2.0, 0.5))
    with pytest.raises(ValueError, match="inner"):
        InfluenceFunction("gauss-laplace", inner=3.5)


@pytest.mark.parametrize("name", ["robust-ud-gauss", "robust-ud-laplace", "robust-ud-gauss-laplace", "robust-ud-huber"])
def test_robust_ud_bounds_the_effect_of_an_outlier(name: str) -> None:
    f = make_filter(name)
    P0 = np.diag([4.0, 1.0])
    s = f.init(np.zeros(2), P0)
    h, r = np.array([1.0, 0.0]), 1.0
    s0, st0 = f.update(s, ScalarMeasurement(0.0, h, r))
    np.testing.assert_array_equal(s0.x, 0.0)  # zero innovation leaves the state unchanged
    s1, st1 = f.update(s, ScalarMeasurement(50.0, h, r))  # a 22-sigma outlier
    optimal = 4.0 / 5.0 * 50.0
    if name == "robust-ud-gauss":
        assert s1.x[0] == pytest.approx(optimal) and st1.weight == pytest.approx(1.0)
    else:  # bounded influence: a 10x larger outlier moves the estimate less than 2x as far
        s2, _ = f.update(s, ScalarMeasurement(500.0, h, r))
        assert abs(s1.x[0]) < 0.5 * optimal and st1.weight < 0.5
        assert abs(s2.x[0]) < 2.0 * abs(s1.x[0])
        assert np.all(np.linalg.eigvalsh(f.covariance(s1)) > 0.0)


@pytest.mark.parametrize("name", ["ud", "robust-ud-gauss-laplace", "robust-ud-huber", "robust-ud-laplace"])
def test_steady_state_covariance_equals_the_dare_with_consistent_data(name: str) -> None:
    """Linear model, measurements equal to the prediction (no residual): P- converges to scipy's DARE."""
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = np.diag([0.01, 0.02])
    h, r = np.array([1.0, 0.0]), 0.5
    f = make_filter(name)
    s = f.init(np.zeros(2), 10.0 * np.eye(2))
    for _ in range(300):
        s = f.predict(s, F, Q)
        s, _ = f.update(s, ScalarMeasurement(float(h @ s.x), h, r))
    P_pred = f.covariance(f.predict(s, F, Q))
    P_dare = scipy.linalg.solve_discrete_are(F.T, h[:, None], Q, np.array([[r]]))
    np.testing.assert_allclose(P_pred, P_dare, rtol=1e-9)


def test_registry_has_the_ud_variants_and_checks_their_tuning() -> None:
    for name in ("ud", "robust-ud", "robust-ud-gauss", "robust-ud-laplace", "robust-ud-gauss-laplace",
                 "robust-ud-huber"):
        assert name in FILTERS
        assert make_filter(name).name == name
    assert make_filter("robust-ud", influence="huber", huber_k=1.5).influence.huber_k == 1.5
    with pytest.raises(ProfileError, match="nav.filter_tuning.gain"):
        make_filter("ud", gain=2)
    with pytest.raises(ProfileError, match="nav.filter_tuning.influence"):
        make_filter("robust-ud", influence="cauchy")
    with pytest.raises(ProfileError, match="nav.filter_tuning.huber_k"):
        make_filter("robust-ud-gauss-laplace", huber_k=2.0)
    with pytest.raises(ProfileError, match="nav.filter_tuning.outer"):
        make_filter("robust-ud-laplace", outer="three")
    with pytest.raises(ProfileError, match="nav.filter_tuning.inner"):
        make_filter("robust-ud-gauss-laplace", inner=3.0)


@pytest.mark.parametrize("kind", ["gauss", "laplace", "gauss-laplace", "huber"])
def test_batched_kernels_equal_the_single_filter(kind: str) -> None:
    """The Monte Carlo kernels (runs axis) give exactly what UDFilter gives run by run, outliers included."""
    from approachsim.nav.ud import robust_update_batch, thornton_predict_batch

    rng = np.random.default_rng(11)
    n, runs = 3, 6
    F = np.eye(n) + 0.1 * rng.normal(size=(n, n))
    Q = np.diag([0.01, 0.0, 0.02])
    h, r = np.array([1.0, 0.5, 0.0]), 0.3
    inf = InfluenceFunction(kind)  # type: ignore[arg-type]
    f = UDFilter(influence=inf)
    states = [f.init(np.zeros(n), _spd(rng, n)) for _ in range(runs)]
    x = np.array([s.x for s in states])
    U = np.array([s.U for s in states])
    d = np.array([s.d for s in states])
    for _ in range(20):
        z = rng.normal(size=runs) * np.where(rng.random(runs) < 0.3, 20.0, 1.0)
        states = [f.update(f.predict(s, F, Q), ScalarMeasurement(float(zz), h, r))[0] for s, zz in zip(states, z,
                                                                                                       strict=True)]
        U, d = thornton_predict_batch(U, d, F, Q)
        x = x @ F.T
        x, U, d, *_ = robust_update_batch(x, U, d, z, h, r, inf)
    for i, s in enumerate(states):
        np.testing.assert_allclose(x[i], s.x, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose((U[i] * d[i]) @ U[i].T, f.covariance(s), rtol=1e-10, atol=1e-12)


def test_ud_variants_run_inside_the_navigation_system_named_in_the_profile() -> None:
    """Drop-in: the nav system built with filter = 'ud' gives the EKF's solution and covariance (only the
    covariance storage differs); the robust variant runs and stays close on clean data."""
    from dataclasses import replace

    from approachsim import synthetic
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile
    from approachsim.seeding import stream
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    profile = load_profile(PY_DEFAULT)
    truth = synthetic.glidepath_descent(profile.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 20,
                                        ground_speed_mps=70.0)
    recs, st = measure_with_states(SensorSuite.from_profile(profile), truth, seed=3, runs=0)
    base = NavSystem.from_profile(profile).nav
    sols = {}
    for name in ("ekf", "ud", "robust-ud-gauss-laplace"):
        system = NavSystem.build(replace(base, filter=name), profile.sensors, profile.runway.frame, profile.terrain)
        sols[name] = system.run(truth, recs, stream(3, 0, "nav"), states=st).solution
    scale = np.max(np.abs(sols["ekf"].P_pos_ned))
    assert np.max(np.abs(sols["ud"].P_pos_ned - sols["ekf"].P_pos_ned)) < 1e-9 * scale
    np.testing.assert_allclose(sols["ud"].r_ecef, sols["ekf"].r_ecef, rtol=0, atol=1e-6)
    assert np.max(np.abs(sols["robust-ud-gauss-laplace"].r_ecef - sols["ekf"].r_ecef)) < 5.0
