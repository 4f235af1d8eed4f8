"""The one filter interface every navigation filter implements, and the optimal Joseph-form Kalman filter.

A filter is a small strategy object; its state is a frozen `FilterState` it returns anew (filters never
mutate themselves). The interface, in textbook symbols:

    state = f.init(x0, P0)
    state = f.predict(state, F, Q)                   # x = F x ; P = F P F' + Q
    state, status = f.update(state, meas)            # one scalar measurement z = h' x + v, var(v) = r
    f.covariance(state) -> P ; state.x -> x

Variants override one hook: a robust filter changes how the gain is weighted (`GainPolicy`); the U-D
filter changes how the covariance is stored. The registry in nav/registry.py picks one by name.

KalmanFilter's predict and update run the compiled kernels of core/nav/kalman.py (sparse Phi, O(n^2) scalar
update); `predict_reference` and `joseph_reference` are the dense numpy forms, kept as their test oracle and for
the pinned ill-conditioned case of the Joseph product form (tests/unit/nav/test_ud.py).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from approachsim.core.nav import kalman as kk

Array = np.ndarray


@dataclass(frozen=True)
class FilterState:
    """Estimate x (n,) and its covariance storage: P (n, n), or for U-D filters the factors (U, d)."""

    x: Array
    P: Array | None = None
    U: Array | None = None
    d: Array | None = None
    memory: tuple = field(default=(), compare=False)
    """Per-filter scratch that survives steps (e.g. an adaptive filter's window); empty for most."""


@dataclass(frozen=True)
class ScalarMeasurement:
    """One scalar measurement z = h' x + v with var(v) = r. `name` identifies the channel ("baro", "pr07")."""

    z: float
    h: Array
    r: float
    name: str = ""
    t_s: float = float("nan")


@dataclass(frozen=True)
class UpdateStatus:
    """Per-measurement record (as PX4 keeps): innovation nu, its predicted variance S, test ratio nu^2/S,
    the gain weight applied (1 optimal, 0 rejected) and whether the measurement was used."""

    name: str
    t_s: float
    innovation: float
    variance: float
    test_ratio: float
    weight: float
    accepted: bool


class NavFilter(Protocol):
    """What every filter offers (optimal, robust, U-D): see the module docstring."""

    name: str

    def init(self, x0: Array, P0: Array) -> FilterState: ...

    def predict(self, state: FilterState, F: Array, Q: Array) -> FilterState: ...

    def update(self, state: FilterState, meas: ScalarMeasurement) -> tuple[FilterState, UpdateStatus]: ...

    def covariance(self, state: FilterState) -> Array: ...


class GainPolicy(Protocol):
    """How a filter weights the gain of one scalar update, from the normalized innovation beta = nu/sqrt(S).

    Returns (weight, psi_prime): the gain used is weight * K; psi_prime scales the covariance reduction
    (P+ = P - psi_prime K S K' in the Joseph-equivalent form). Optimal: (1, 1). Rejection: (0, 0).
    """

    def __call__(self, beta: float, name: str) -> tuple[float, float]: ...


def optimal_policy(beta: float, name: str) -> tuple[float, float]:
    """The optimal Kalman gain: weight 1, full covariance reduction."""
    return 1.0, 1.0


def predict_reference(x: Array, P: Array, F: Array, Q: Array) -> tuple[Array, Array]:
    """x = F x ; P = F P F' + Q, symmetrized: the dense numpy form (the kernels' test oracle)."""
    x = F @ x  # x- = F x+
    P = F @ P @ F.T + Q  # P- = F P+ F' + Q
    return x, 0.5 * (P + P.T)


def joseph_reference(x: Array, P: Array, h: Array, r: float, nu: float, w: float = 1.0, psi_prime: float = 1.0
                     ) -> tuple[Array, Array]:
    """One scalar update in the Joseph *product* form, dense numpy (the kernels' test oracle):
    S = h' P h + r ; K = P h / S ; x+ = x + w K nu ; Kc = (1 - sqrt(1 - psi')) K ;
    P+ = (I - Kc h') P (I - Kc h')' + r Kc Kc', symmetrized."""
    S = float(h @ (P @ h) + r)  # S = h' P h + r
    K = P @ h / S  # K = P h S^-1
    x = x + w * K * nu  # x+ = x + w K nu
    Kc = (1.0 - np.sqrt(1.0 - psi_prime)) * K  # Joseph gain giving P - psi' K S K'
    A = np.eye(len(x)) - np.outer(Kc, h)
    P = A @ P @ A.T + r * np.outer(Kc, Kc)  # Joseph form
    return x, 0.5 * (P + P.T)


_LOCAL = threading.local()


def workspace(n: int) -> tuple[Array, ...]:
    """kernels.kalman's scratch arrays for n states, one set per thread (a kernel call holds the GIL)."""
    cache = getattr(_LOCAL, "ws", None)
    if cache is None:
        cache = _LOCAL.ws = {}
    if n not in cache:
        cache[n] = kk.workspace(n)
    return cache[n]


def _square(A: Array, n: int, what: str) -> Array:
    a = np.ascontiguousarray(A, dtype=float)
    if a.shape != (n, n):
        raise ValueError(f"{what}: expected shape ({n}, {n}), got {a.shape}")
    return a


@dataclass(frozen=True)
class KalmanFilter:
    """Linear / error-state Kalman filter, covariance form, sequential scalar updates in Joseph form.

    With the default policy this is the optimal filter; robust variants pass another `policy`.
    Update (policy returns the gain weight w and the covariance-reduction factor psi' in [0, 1]):
        S = h' P h + r ; K = P h / S ; x+ = x + w K nu
        P+ = P - psi' K S K', computed in Joseph form with the gain Kc = c K, c = 1 - sqrt(1 - psi'),
        since (I - Kc h') P (I - Kc h')' + Kc r Kc' = P - c (2 - c) K S K' = P - psi' K S K'.
    Optimal (1, 1): c = 1, the usual Joseph form. Rejection (0, 0): state and P unchanged.
    The Joseph form is evaluated expanded, P - Kc b' - b Kc' + S Kc Kc' with b = P h (O(n^2), symmetric by
    construction; kernels.kalman); `joseph_reference` is the product form.
    """

    name: str = "kf"
    policy: GainPolicy = optimal_policy

    def init(self, x0: Array, P0: Array) -> FilterState:
        """State from the initial estimate x0 (n,) and covariance P0 (n, n)."""
        return FilterState(x=np.array(x0, dtype=float), P=np.array(P0, dtype=float))

    def predict(self, state: FilterState, F: Array, Q: Array) -> FilterState:
        """x = F x ; P = F P F' + Q (Q: discrete process noise), by kernels.kalman.predict (sparse F)."""
        x = np.array(state.x, dtype=float)
        n = x.shape[0]
        P = np.array(_square(state.P, n, "P"))
        kk.predict(x, P, _square(F, n, "F"), _square(Q, n, "Q"), workspace(n))  # x- = F x+ ; P- = F P+ F' + Q
        return FilterState(x=x, P=P, memory=state.memory)

    def update(self, state: FilterState, meas: ScalarMeasurement) -> tuple[FilterState, UpdateStatus]:
        """One scalar update; the policy may down-weight or reject it (kernels.kalman.gain, joseph: O(n^2))."""
        x, h = state.x, meas.h
        n = x.shape[0]
        P = _square(state.P, n, "P")
        hv = np.ascontiguousarray(h, dtype=float)
        if hv.shape != (n,):
            raise ValueError(f"measurement {meas.name!r}: h has shape {hv.shape}, the state ({n},)")
        b = np.empty(n)
        S = kk.gain(P, hv, float(meas.r), b)  # b = P h ; S = h' P h + r
        nu = float(meas.z - h @ x)  # innovation
        beta = nu / np.sqrt(S)
        w, psi_prime = self.policy(beta, meas.name)
        w, psi_prime = float(w), float(psi_prime)
        if not 0.0 <= psi_prime <= 1.0:
            raise ValueError(f"gain policy of {self.name!r}: psi_prime must be in [0, 1], got {psi_prime}")
        status = UpdateStatus(meas.name, meas.t_s, nu, S, nu * nu / S, w, w > 0.0)
        if w == 0.0 and psi_prime == 0.0:
            return state, status
        x = np.array(x, dtype=float)
        P = np.array(P)
        # x+ = x + w K nu ; P+ = P - psi' K S K' in Joseph form with Kc = (1 - sqrt(1 - psi')) K
        kk.joseph(x, P, b, S, nu, w, 1.0 - math.sqrt(1.0 - psi_prime), workspace(n))
        return FilterState(x=x, P=P, memory=state.memory), status

    def covariance(self, state: FilterState) -> Array:
        """P (n, n)."""
        return state.P
