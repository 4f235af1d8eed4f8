"""Robust Kalman filters of Hajiyev & Saltoglu (gate, eqs. 20-24) and Manero Contreras & Hajiyev (adaptive,
eqs. 20-30): the weighting functions, the exact P updates the papers print, and the batched array core."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from approachsim.config import ProfileError
from approachsim.nav.base import KalmanFilter, ScalarMeasurement, optimal_policy
from approachsim.nav.registry import make_filter
from approachsim.nav.robust import (
    AdaptivePolicy,
    GatePolicy,
    adaptive_filter,
    adaptive_probability,
    gate_filter,
    gate_weight,
    predict_batch,
    update_batch,
)
from approachsim.seeding import stream

H_ROW = np.array([1.0, 0.0, 0.0, 0.0, -1.0])


def _random_state(seed: int, n: int = 5) -> tuple[np.ndarray, np.ndarray]:
    rng = stream(seed, 0, "robust-test")
    A = rng.normal(size=(n, n))
    return rng.normal(size=n), A @ A.T + 0.5 * np.eye(n)


def _innovation_for(beta: float, x: np.ndarray, P: np.ndarray, r: float) -> float:
    """The measurement whose normalized innovation is beta."""
    S = H_ROW @ P @ H_ROW + r
    return float(H_ROW @ x + beta * np.sqrt(S))


def test_gate_weight_is_one_inside_the_region_and_zero_outside() -> None:
    beta = np.array([-3.5, -3.0, -1.0, 0.0, 2.999, 3.0, 3.001, 10.0])
    np.testing.assert_array_equal(gate_weight(beta, 3.0), [0, 1, 1, 1, 1, 1, 0, 0])


@pytest.mark.parametrize("beta", [0.0, 0.7, -1.5, 3.0, 4.2, -6.0])
def test_adaptive_probability_is_the_integral_of_eq_25(beta: float) -> None:
    integral, _ = quad(lambda t: np.exp(-((t - beta) ** 2) / 2.0) / np.sqrt(2.0 * np.pi), -3.0, 3.0)
    assert float(adaptive_probability(beta)) == pytest.approx(integral, abs=1e-12)


def test_adaptive_probability_landmarks() -> None:
    assert float(adaptive_probability(0.0)) == pytest.approx(0.99730020, abs=1e-8)  # 2 Phi(3) - 1
    assert float(adaptive_probability(3.0)) == pytest.approx(0.5, abs=1e-8)
    b = np.linspace(0, 10, 101)
    p = adaptive_probability(b)
    assert np.all(np.diff(p) < 0)  # decreasing with |beta|
    np.testing.assert_allclose(p, adaptive_probability(-b), rtol=0, atol=1e-15)  # symmetric


def test_gate_outside_region_keeps_extrapolation_and_predicted_p() -> None:
    """Hajiyev & Saltoglu eqs. 23-24: x(k/k) = x(k/k-1) and P(k) = P(k/k-1) outside Omega."""
    x, P = _random_state(1)
    f = gate_filter(3.0)
    state = f.init(x, P)
    new, status = f.update(state, ScalarMeasurement(_innovation_for(3.2, x, P, 2.0), H_ROW, 2.0, "ra"))
    assert not status.accepted and status.weight == 0.0
    np.testing.assert_array_equal(new.x, x)
    np.testing.assert_array_equal(new.P, P)


def test_gate_inside_region_is_the_optimal_update() -> None:
    """Eq. 24, first line: P(k) = (I - K H) P(k/k-1), x(k/k) = x + K Delta (eqs. 14-18)."""
    x, P = _random_state(2)
    r = 2.0
    meas = ScalarMeasurement(_innovation_for(2.9, x, P, r), H_ROW, r, "ra")
    new, status = gate_filter(3.0).update(gate_filter().init(x, P), meas)
    assert status.accepted and status.weight == 1.0
    S = H_ROW @ P @ H_ROW + r
    K = P @ H_ROW / S
    np.testing.assert_allclose(new.x, x + K * (meas.z - H_ROW @ x), rtol=1e-12)
    np.testing.assert_allclose(new.P, (np.eye(5) - np.outer(K, H_ROW)) @ P, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("beta", [0.3, 2.5, 3.0, 4.0, 7.0])
def test_adaptive_update_is_eqs_22_to_29(beta: float) -> None:
    """K_A = p K (eq. 23), x = x + K_A Delta (eq. 22), P = (I - K_A H) P(k/k-1) (eq. 29)."""
    x, P = _random_state(3)
    r = 9.0
    meas = ScalarMeasurement(_innovation_for(beta, x, P, r), H_ROW, r, "baro")
    new, status = adaptive_filter().update(adaptive_filter().init(x, P), meas)
    S = H_ROW @ P @ H_ROW + r
    p = float(adaptive_probability(beta))
    K_A = p * P @ H_ROW / S
    assert status.weight == pytest.approx(p, rel=1e-12)
    np.testing.assert_allclose(new.x, x + K_A * (meas.z - H_ROW @ x), rtol=1e-12)
    P_paper = (np.eye(5) - np.outer(K_A, H_ROW)) @ P
    np.testing.assert_allclose(new.P, P_paper, rtol=1e-9, atol=1e-11)
    # and it differs from the Joseph form with the scaled gain, P - p(2-p) K S K', whenever 0 < p < 1
    K = P @ H_ROW / S
    joseph_scaled = P - p * (2 - p) * S * np.outer(K, K)
    if 1e-6 < p < 1 - 1e-6:
        assert not np.allclose(new.P, joseph_scaled, rtol=1e-9, atol=1e-11)


def test_optimal_policy_still_the_textbook_update() -> None:
    """base.KalmanFilter with the default policy is unchanged by the psi' extension."""
    x, P = _random_state(4)
    meas = ScalarMeasurement(1.7, H_ROW, 3.0, "z")
    new, _ = KalmanFilter().update(KalmanFilter().init(x, P), meas)
    S = H_ROW @ P @ H_ROW + 3.0
    K = P @ H_ROW / S
    np.testing.assert_allclose(new.P, P - S * np.outer(K, K), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("policy", [optimal_policy, GatePolicy(2.0), AdaptivePolicy(3.0)])
def test_batch_core_matches_the_filter_object(policy) -> None:
    runs, n = 6, 5
    rng = stream(5, 0, "batch")
    F = np.eye(n) + 0.1 * rng.normal(size=(n, n))
    B = rng.normal(size=(n, n))
    Q = 0.01 * B @ B.T
    xs, Ps = zip(*[_random_state(10 + i) for i in range(runs)], strict=True)
    x, P = np.array(xs), np.array(Ps)
    z = rng.normal(scale=3.0, size=runs)
    r = np.linspace(0.5, 3.0, runs)
    xb, Pb = predict_batch(x, P, F, Q)
    xb, Pb, w, beta = update_batch(xb, Pb, z, H_ROW, r, policy)
    f = KalmanFilter(policy=policy)
    for i in range(runs):
        s = f.predict(f.init(x[i], P[i]), F, Q)
        s, status = f.update(s, ScalarMeasurement(float(z[i]), H_ROW, float(r[i])))
        np.testing.assert_allclose(xb[i], s.x, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(Pb[i], s.P, rtol=1e-12, atol=1e-12)
        assert w[i] == pytest.approx(status.weight, rel=1e-14)
        assert beta[i] == pytest.approx(status.innovation / np.sqrt(status.variance), rel=1e-12)
    assert set(np.unique(w)) <= {0.0, 1.0} or isinstance(policy, AdaptivePolicy)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("inf"), float("nan"), "3", True])
def test_bad_bound_is_refused(bad) -> None:
    with pytest.raises(ValueError, match="bound"):
        GatePolicy(bad)
    with pytest.raises(ValueError, match="bound"):
        AdaptivePolicy(bad)


@pytest.mark.parametrize("name", ["rkf-gate", "rkf-adaptive"])
def test_registry_builds_and_checks_tuning(name: str) -> None:
    f = make_filter(name, bound=2.5)
    assert f.name == name and f.policy.bound == 2.5
    with pytest.raises(ProfileError, match=r"nav\.filter_tuning\.bound"):
        make_filter(name, bound=-2)
    with pytest.raises(ProfileError, match=r"nav\.filter_tuning\.gate"):
        make_filter(name, gate=3.0)


@settings(derandomize=True, max_examples=60, deadline=None)
@given(beta=st.floats(-30.0, 30.0), seed=st.integers(0, 10_000), bound=st.floats(0.5, 6.0))
def test_robust_updates_keep_p_symmetric_psd_and_never_above_the_prediction(beta: float, seed: int, bound: float):
    """For any innovation, P+ is symmetric positive semi-definite and P- - P+ is PSD (no covariance growth)."""
    x, P = _random_state(seed)
    r = 4.0
    meas = ScalarMeasurement(_innovation_for(beta, x, P, r), H_ROW, r, "z")
    for f in (gate_filter(bound), adaptive_filter(bound)):
        new, _ = f.update(f.init(x, P), meas)
        np.testing.assert_allclose(new.P, new.P.T, rtol=0, atol=1e-12)
        assert np.linalg.eigvalsh(new.P).min() > -1e-9
        assert np.linalg.eigvalsh(P - new.P).min() > -1e-9
