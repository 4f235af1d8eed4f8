"""The shared filter contract suite (conventions item 12): every filter in nav.registry.FILTERS must pass.

On a linear time-invariant model with one scalar measurement per step:

1. Steady-state covariance. Fed consistent data (every measurement equals the prediction, so the
   innovation is zero and no robust gate can trip), the predicted P converges to the solution X of the
   discrete algebraic Riccati equation (scipy.linalg.solve_discrete_are). Invariant for gain-weighted
   (robust) filters: an update P+ = P - w K S K' with gain weight w is exactly a Kalman update with the
   noise variance r_eff = S / w - h' P h, so X must solve the DARE with r_eff, w the weight the filter's
   paper prescribes at zero innovation (expected_weight below, written from the papers, not read from the
   filter): 1 for the optimal, U-D and gated filters and every influence function (psi'(0) = 1); for the
   adaptive RKF (Manero Contreras & Hajiyev eq. 25) w = 2 Phi(3) - 1.
2. Consistency. With truth simulated from the same model (fault-free), the Monte Carlo mean NEES at each
   step lies inside the two-sided 99 % chi^2 interval in at least 95 % of the steps (expected 99 %).
3. Zero innovation leaves the state estimate unchanged.
4. Gain weight at a given innovation. One update with normalized innovation b = nu / sqrt(S): the gated and
   adaptive RKFs give P+ = P- - w(b) K S K' (K = P- h' / S; Hajiyev & Saltoglu eq. 23, Manero Contreras &
   Hajiyev eq. 25, 29); the robust U-D filters (Chernodarov sec. 4, residual scaled by sqrt(S)) likewise
   P- - psi'(b) K S K' (P unchanged when psi' = 0). w(b) and psi'(b) are written here from the papers.
   The step-length property (no robust step longer than the Kalman one) is in test_robust_step.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are
from scipy.stats import chi2, norm

from approachsim.nav.base import ScalarMeasurement
from approachsim.nav.registry import FILTERS, make_filter
from approachsim.seeding import stream

DT_S = 1.0
F = np.array([[1.0, DT_S, 0.5 * DT_S**2], [0.0, 1.0, DT_S], [0.0, 0.0, 0.95]])
"""Position, velocity, first-order Markov acceleration (correlation time 20 s), step 1 s."""
Q = np.diag([0.0, 1e-4, 2e-3])
H_ROW = np.array([1.0, 0.0, 0.0])
R_M2 = 4.0
P0 = np.diag([100.0, 4.0, 0.04])

NAMES = sorted(FILTERS)


def _steady_state(name: str, steps: int = 400) -> tuple[np.ndarray, float]:
    """Predicted P after `steps` predict/update cycles on zero-innovation data, and the last gain weight."""
    f = make_filter(name)
    state = f.init(np.zeros(3), P0)
    weight = 1.0
    for k in range(steps):
        state = f.predict(state, F, Q)
        z = float(H_ROW @ state.x)  # consistent measurement: zero innovation
        state, status = f.update(state, ScalarMeasurement(z=z, h=H_ROW, r=R_M2, name="pos", t_s=k * DT_S))
        weight = status.weight
    state = f.predict(state, F, Q)
    return f.covariance(state), weight


def expected_weight(name: str, b: float) -> float:
    """Gain weight w (RKFs) or psi' (robust U-D) the filter's paper prescribes at normalized innovation
    b = nu / sqrt(S), written here: optimal and U-D: 1; binary gate (Hajiyev & Saltoglu eq. 23): 1 inside
    |b| <= 3, else 0; adaptive RKF (Manero Contreras & Hajiyev eq. 25): Phi(3 - b) - Phi(-3 - b); robust U-D
    (Chernodarov sec. 4), psi': Gauss 1; Laplace 1 inside 3 sigma, 0 beyond; Gauss-Laplace 1 below 2, 1/3 in
    [2, 3), 0 beyond; Huber (corner 3) min(1, 3 / |b|) (the secant slope). 'robust-ud' is Gauss-Laplace."""
    a = abs(b)
    if name in ("ekf", "ud", "robust-ud-gauss"):
        return 1.0
    if name == "rkf-gate":
        return 1.0 if a <= 3.0 else 0.0
    if name == "rkf-adaptive":
        return float(norm.cdf(3.0 - b) - norm.cdf(-3.0 - b))
    if name == "robust-ud-laplace":
        return 1.0 if a < 3.0 else 0.0
    if name in ("robust-ud-gauss-laplace", "robust-ud"):
        return 1.0 if a < 2.0 else 1.0 / 3.0 if a < 3.0 else 0.0
    if name == "robust-ud-huber":
        return min(1.0, 3.0 / a) if a > 0 else 1.0
    raise AssertionError(f"no expected weight written for filter {name!r}: add its paper's rule here")


@pytest.mark.parametrize("name", NAMES)
def test_steady_state_covariance_solves_the_dare(name: str) -> None:
    P_ss, w_reported = _steady_state(name)
    w = expected_weight(name, 0.0)
    assert w_reported == pytest.approx(w, rel=1e-12)
    s_prior = float(H_ROW @ P_ss @ H_ROW)
    r_eff = (s_prior + R_M2) / w - s_prior  # equals R_M2 when w = 1
    X = solve_discrete_are(F.T, H_ROW[:, None], Q, np.array([[r_eff]]))
    np.testing.assert_allclose(P_ss, X, rtol=1e-8, atol=1e-12)


def test_optimal_filter_steady_state_uses_the_true_noise() -> None:
    """The r_eff invariant is not vacuous: for the optimal filter it is the profile's R itself."""
    P_ss, w = _steady_state("ekf")
    assert w == 1.0
    X = solve_discrete_are(F.T, H_ROW[:, None], Q, np.array([[R_M2]]))
    np.testing.assert_allclose(P_ss, X, rtol=1e-8)


@pytest.mark.parametrize("name", NAMES)
def test_nees_within_chi2_bounds(name: str) -> None:
    runs, steps, n = 60, 100, 3
    f = make_filter(name)
    nees = np.zeros((runs, steps))
    for run in range(runs):
        rng = stream(7, run, "contract")
        x_true = rng.multivariate_normal(np.zeros(n), P0)
        state = f.init(np.zeros(n), P0)
        for k in range(steps):
            x_true = F @ x_true + rng.multivariate_normal(np.zeros(n), Q)
            z = float(H_ROW @ x_true + rng.normal(0.0, np.sqrt(R_M2)))
            state = f.predict(state, F, Q)
            state, _ = f.update(state, ScalarMeasurement(z=z, h=H_ROW, r=R_M2, name="pos"))
            e = x_true - state.x
            nees[run, k] = e @ np.linalg.solve(f.covariance(state), e)
    mean_nees = nees.mean(axis=0)
    lo, hi = chi2.ppf([0.005, 0.995], runs * n) / runs
    inside = np.mean((mean_nees >= lo) & (mean_nees <= hi))
    assert inside >= 0.95, f"{name}: mean NEES inside [{lo:.2f}, {hi:.2f}] in only {inside:.0%} of steps"


@pytest.mark.parametrize("name", NAMES)
def test_zero_innovation_leaves_the_state_unchanged(name: str) -> None:
    f = make_filter(name)
    rng = stream(3, 0, "contract-zero")
    A = rng.normal(size=(3, 3))
    state = f.init(rng.normal(size=3), A @ A.T + np.eye(3))
    meas = ScalarMeasurement(z=float(H_ROW @ state.x), h=H_ROW, r=R_M2, name="pos")
    new, status = f.update(state, meas)
    assert status.innovation == 0.0
    np.testing.assert_array_equal(new.x, state.x)


@pytest.mark.parametrize("b", [0.5, 2.5, 4.0])
@pytest.mark.parametrize("name", NAMES)
def test_gain_weight_follows_the_papers_rule_at_the_innovation(name: str, b: float) -> None:
    """The weight seen in the covariance after one update at the innovation the test sets (item 4), against the
    rule written in expected_weight (not the filter's report about itself)."""
    f = make_filter(name)
    rng = stream(5, 0, "contract-weight")
    A = rng.normal(size=(3, 3))
    P = A @ A.T + np.eye(3)
    state = f.init(rng.normal(size=3), P)
    S = float(H_ROW @ P @ H_ROW + R_M2)
    z = float(H_ROW @ state.x + b * np.sqrt(S))
    new, _ = f.update(state, ScalarMeasurement(z=z, h=H_ROW, r=R_M2, name="pos"))
    w = expected_weight(name, b)
    # every robust variant: P+ = P - w K S K' (RKF eq. 29; robust U-D with the residual scaled by sqrt(S),
    # nav/ud.py: psi' = w; the former sqrt(r) scaling, a Kalman update with r / psi', fails here at b = 2.5)
    K = P @ H_ROW / S
    expected = P - w * S * np.outer(K, K)
    np.testing.assert_allclose(f.covariance(new), expected, rtol=1e-9, atol=1e-12)
