"""Robust Kalman filters of the Hajiyev papers, as gain policies of the one KalmanFilter of nav/base.py.

Both variants change only how the gain of a scalar update is weighted, from the normalized innovation
beta = nu / sqrt(S) (S = h' P h + r), so they are `GainPolicy` objects (conventions item 3):

* `GatePolicy`, the binary-gate RKF of Hajiyev & Saltoglu eqs. 20-24: p(1/k) = 1 if |beta| <= bound
  (beta inside the confidence region Omega), else 0: the estimate keeps the extrapolation
  x(k/k) = x(k/k-1) (eq. 23) and P stays the predicted P(k/k-1) (eq. 24).
* `AdaptivePolicy`, the adaptive RKF of Manero Contreras & Hajiyev eqs. 20-30: the gain is scaled,
  K_A = p(1/k) K (eq. 23), with p(1/k) the probability mass inside [-bound, bound] of a normal density
  centred on the current normalized innovation with unit spread (eq. 25), and P(k/k) = (I - K_A H) P(k/k-1)
  (eq. 29), i.e. P - p K S K' (the policy returns psi' = p; base.KalmanFilter computes that in Joseph form).

The array core (`gate_weight`, `adaptive_probability`, `predict_batch`, `update_batch`) runs many Monte
Carlo runs at once (run axis first: x (runs, n), P (runs, n, n)); the classes are thin shells over it and
`update_batch` performs exactly the arithmetic of `KalmanFilter.update` (a test checks it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from approachsim.nav.base import GainPolicy, KalmanFilter

Array = np.ndarray

DEFAULT_BOUND = 3.0
"""Half-width of the confidence region Omega for the normalized innovation (N(0,1) under normal operation).
Manero Contreras & Hajiyev eq. 25 integrates over [-3, 3]; Hajiyev & Saltoglu do not print their Omega,
we use the same 3-sigma region (0.27 % false-rejection rate on fault-free data)."""


def gate_weight(beta: Array | float, bound: float = DEFAULT_BOUND) -> Array:
    """p(1/k) of the binary gate (Hajiyev & Saltoglu eq. 22): 1 where |beta| <= bound, 0 outside."""
    return np.where(np.abs(beta) <= bound, 1.0, 0.0)


def adaptive_probability(beta: Array | float, bound: float = DEFAULT_BOUND) -> Array:
    """p(1/k) of Manero Contreras & Hajiyev eq. 25, dimensionless in [0, 1).

    p = 1/(sqrt(2 pi) sigma) * integral_{-b}^{b} exp(-(t - beta_hat)^2 / (2 sigma^2)) dt
      = Phi((b - beta_hat)/sigma) - Phi((-b - beta_hat)/sigma),
    with beta_hat the current normalized innovation (eq. 27) and sigma = 1, its spread under normal
    operation (eq. 21: N(0, 1)). At beta = 0, p = 2 Phi(3) - 1 = 0.9973; at |beta| = 3, p = 0.5.
    """
    beta = np.asarray(beta, dtype=float)
    return ndtr(bound - beta) - ndtr(-bound - beta)


def _check_bound(bound: float) -> float:
    if isinstance(bound, bool) or not isinstance(bound, int | float) or not np.isfinite(bound) or bound <= 0:
        raise ValueError(f"bound: must be a positive finite number (confidence half-width in sigma); got {bound!r}")
    return float(bound)


@dataclass(frozen=True)
class GatePolicy:
    """Binary-gate RKF (Hajiyev & Saltoglu eqs. 21-24): weight and covariance factor both p(1/k) in {0, 1}."""

    bound: float = DEFAULT_BOUND
    """Confidence region Omega = [-bound, bound] for the normalized innovation, in sigma."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "bound", _check_bound(self.bound))

    def __call__(self, beta: Array | float, name: str = "") -> tuple[Array, Array]:
        """(p, p): p = 1 keeps the optimal update, p = 0 keeps x(k/k-1) and P(k/k-1) (eqs. 23-24)."""
        p = gate_weight(beta, self.bound)
        return p, p


@dataclass(frozen=True)
class AdaptivePolicy:
    """Adaptive RKF (Manero Contreras & Hajiyev eqs. 20-30): K_A = p(1/k) K and P = (I - K_A H) P(k/k-1)."""

    bound: float = DEFAULT_BOUND
    """Integration limits [-bound, bound] of eq. 25, in sigma of the normalized innovation."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "bound", _check_bound(self.bound))

    def __call__(self, beta: Array | float, name: str = "") -> tuple[Array, Array]:
        """(p, p): gain weight p(1/k) (eq. 23) and covariance reduction P - p K S K' (eq. 29)."""
        p = adaptive_probability(beta, self.bound)
        return p, p


def gate_filter(bound: float = DEFAULT_BOUND, name: str = "rkf-gate") -> KalmanFilter:
    """The binary-gate robust KF (Hajiyev & Saltoglu eqs. 20-24) with the NavFilter interface."""
    return KalmanFilter(name=name, policy=GatePolicy(bound))


def adaptive_filter(bound: float = DEFAULT_BOUND, name: str = "rkf-adaptive") -> KalmanFilter:
    """The adaptive robust KF (Manero Contreras & Hajiyev eqs. 20-30) with the NavFilter interface."""
    return KalmanFilter(name=name, policy=AdaptivePolicy(bound))


def predict_batch(x: Array, P: Array, F: Array, Q: Array) -> tuple[Array, Array]:
    """Batched prediction over runs: x (runs, n), P (runs, n, n); F, Q (n, n).

    x(k/k-1) = F x(k-1/k-1) (eq. 17 / 24); P(k/k-1) = F P F' + Q (eq. 19 / 30, Q = G Q G').
    """
    x = x @ F.T  # x- = F x+
    P = F @ P @ F.T + Q  # P- = F P+ F' + Q
    return x, 0.5 * (P + np.swapaxes(P, -1, -2))


def update_batch(
    x: Array, P: Array, z: Array, h: Array, r: float | Array, policy: GainPolicy, name: str = ""
) -> tuple[Array, Array, Array, Array]:
    """Batched scalar update over runs with a gain policy; the arithmetic of base.KalmanFilter.update.

    x (runs, n), P (runs, n, n), z (runs,) measurement, h (n,) row of H, r scalar or (runs,) noise variance, m^2.
    Returns (x+, P+, w, beta): the gain weight w = p(1/k) (runs,) and the normalized innovation beta (runs,).
        S = h' P h + r ; nu = z - h' x ; beta = nu / sqrt(S) ; K = P h / S ; x+ = x + w K nu
        P+ = P - psi' K S K' (Joseph form with gain (1 - sqrt(1 - psi')) K)
    """
    r = np.broadcast_to(np.asarray(r, dtype=float), z.shape)
    Ph = P @ h  # (runs, n)
    S = Ph @ h + r  # S = h' P h + R
    nu = z - x @ h  # Delta(k) = z - H x(k/k-1)
    beta = nu / np.sqrt(S)  # normalized innovation
    w, psi_prime = policy(beta, name)
    w = np.broadcast_to(np.asarray(w, dtype=float), z.shape)
    psi_prime = np.broadcast_to(np.asarray(psi_prime, dtype=float), z.shape)
    if np.any((psi_prime < 0.0) | (psi_prime > 1.0)):
        raise ValueError("gain policy: psi_prime must be in [0, 1]")
    K = Ph / S[:, None]  # K = P H' S^-1
    x = x + (w * nu)[:, None] * K  # x+ = x- + p K Delta
    Kc = (1.0 - np.sqrt(1.0 - psi_prime))[:, None] * K
    A = np.eye(x.shape[-1]) - Kc[:, :, None] * h[None, None, :]
    P_new = A @ P @ np.swapaxes(A, -1, -2) + r[:, None, None] * (Kc[:, :, None] * Kc[:, None, :])  # Joseph
    P_new = 0.5 * (P_new + np.swapaxes(P_new, -1, -2))
    untouched = (w == 0.0) & (psi_prime == 0.0)
    P_new[untouched] = P[untouched]  # rejected: P stays P(k/k-1) exactly (eq. 24)
    return x, P_new, w, beta
