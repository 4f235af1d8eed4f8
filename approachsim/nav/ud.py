"""U-D factorized Kalman filter (Bierman update, Thornton / MWGS propagation) and its robust variant.

The covariance is stored as P = U diag(d) U' (U unit upper triangular, d >= 0), never formed during the
filter steps, so it stays symmetric and non-negative where the covariance form loses definiteness
(Bierman 1977). Only the covariance storage differs from the Joseph-form `KalmanFilter` of nav/base.py: with
the Gauss influence function both give the same x and P (to round-off) on well-conditioned problems.

Robust variant (Chernodarov, sec. 4, eq. 3 and the Joseph-Bierman update), with the residual scaled by its
predicted standard deviation alpha_j = sqrt(S_j), S_j = h' P h + r:
    v_j = z_j - H_j m_{j-1};  b_j = v_j / sqrt(S_j);  psi_j = psi(b_j);  psi'_j = psi'(b_j)
    m_j = m_{j-1} + K_j sqrt(S_j) psi_j,                K_j = P h / S_j (the Kalman gain)
    P_j = P - psi'_j K_j S_j K_j'       (Bierman: r_eff = S_j / psi'_j - h'Ph = r / psi' + h'Ph (1/psi' - 1))
so that psi = b (Gauss) is exactly the Kalman update, psi = b / 3 (Gauss-Laplace band) a third of it, and no
influence function takes a longer step than the Kalman one: |sqrt(S) psi(b)| <= |v| for every |psi(b)| <= |b|.
The paper's own scaling alpha_j = sqrt(r_j) (step P h alpha psi(v / alpha) / (f V psi' + alpha^2)) does not
have that property: with h' P h >> r (tightly coupled GPS with channel states) its Laplace step P h sign(v) /
sqrt(r) exceeds the Kalman step (scalar P = 100 m^2, r = 1 m^2, a 3.1 sigma innovation: Kalman 31 m, paper 100 m), so
an influence function meant to bound an outlier's effect made it worse; `mwgs_robust_update` keeps the paper's
literal MWGS covariance form (alpha = sqrt(r)) for the tests to compare.

Influence functions (psi, psi'), evaluated at b_j:
    gauss          psi = beta, psi' = 1                                  (everywhere)
    laplace        Gauss for |b| < outer; psi = sign(beta), psi' = 0     (off-design, |b| >= outer)
    gauss-laplace  Gauss for |b| < inner; psi = beta / 3, psi' = 1/3     (inner <= |b| < outer, the
                   vicinity of the 3-sigma tolerance); Laplace beyond outer. The paper's approximation
                   psi_lg = beta / 3 of eq. 7-10 reaches psi_l = 1 at |beta| = 3.
    huber          psi = beta for |b| <= k, psi = beta k / |b| beyond (Huber 1981), with the secant slope
                   psi' = psi / beta (our choice: with Huber's derivative psi' = 0 the gain would jump to
                   P h / r at the corner; the secant keeps the update a consistent noise inflation).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from approachsim.config import ProfileError
from approachsim.nav.base import FilterState, ScalarMeasurement, UpdateStatus

Array = np.ndarray

Influence = Literal["gauss", "laplace", "gauss-laplace", "huber"]
INFLUENCES: tuple[str, ...] = ("gauss", "laplace", "gauss-laplace", "huber")


# --------------------------------------------------------------------------------------------------------------
# factorization kernels (plain array functions)


def ud_factor(P: Array) -> tuple[Array, Array]:
    """P (n, n) symmetric non-negative -> (U unit upper triangular (n, n), d (n,)) with P = U diag(d) U'.

    Zero (or round-off negative) pivots give d = 0 and a zero column above the diagonal.
    """
    P = np.array(P, dtype=float)
    n = P.shape[0]
    U = np.eye(n)
    d = np.zeros(n)
    for j in range(n - 1, -1, -1):
        d[j] = P[j, j]
        if d[j] > 0.0:
            U[:j, j] = P[:j, j] / d[j]
            P[:j, :j] -= d[j] * np.outer(U[:j, j], U[:j, j])
        else:
            d[j] = 0.0
    return U, d


def mwgs(W: Array, dw: Array) -> tuple[Array, Array]:
    """Modified weighted Gram-Schmidt (Bierman 1977; Thornton): W (n, m), weights dw (m,) >= 0
    -> (U (n, n) unit upper, d (n,)) with U diag(d) U' = W diag(dw) W'."""
    W = np.array(W, dtype=float)
    n = W.shape[0]
    U = np.eye(n)
    d = np.zeros(n)
    for k in range(n - 1, -1, -1):
        c = dw * W[k]
        d[k] = float(W[k] @ c)
        if d[k] > 0.0:
            U[:k, k] = (W[:k] @ c) / d[k]
            W[:k] -= np.outer(U[:k, k], W[k])
        else:
            d[k] = 0.0
    return U, d


def thornton_predict(U: Array, d: Array, F: Array, Q: Array) -> tuple[Array, Array]:
    """P- = F P F' + Q on U-D factors: MWGS of W = [F U : G], D = diag(d, q) with Q = G diag(q) G' (Chernodarov
    eq. 3, prediction; G, q from the U-D factorization of Q)."""
    G, q = ud_factor(Q)
    W = np.hstack([F @ U, G])
    return mwgs(W, np.concatenate([d, q]))


def bierman_update(U: Array, d: Array, h: Array, r: float) -> tuple[Array, Array, Array, float]:
    """Bierman's scalar measurement update of P = U diag(d) U' with z = h' x + v, var(v) = r > 0.

    Returns (U+, d+, K, S): the updated factors, the Kalman gain K = P h / S and S = h' P h + r.
    Bierman's column recursion, with its running sums written as cumulative sums (same additions, same order):
        f = U' h, v = D f, alpha_j = r + sum_{i<=j} f_i v_i, d+_j = d_j alpha_{j-1} / alpha_j,
        b_j = sum_{i<=j} U[:, i] v_i, U+[:, j] = U[:, j] - f_j / alpha_{j-1} b_{j-1}, K = b_n / alpha_n.
    """
    f = U.T @ h  # f = U' h
    v = d * f  # v = D f
    alpha = r + np.cumsum(f * v)  # alpha_j = alpha_{j-1} + f_j v_j
    alpha_prev = np.concatenate([[r], alpha[:-1]])
    B = np.cumsum(U * v, axis=1)  # b_j (column j); zero below row j since U is unit upper triangular
    B_prev = np.concatenate([np.zeros((len(d), 1)), B[:, :-1]], axis=1)
    U_new = U + B_prev * (-f / alpha_prev)  # U+_j = U_j + lambda_j b_{j-1}, lambda_j = -f_j / alpha_{j-1}
    d_new = d * alpha_prev / alpha
    return U_new, d_new, B[:, -1] / alpha[-1], float(alpha[-1])


def mwgs_robust_update(U: Array, d: Array, h: Array, r: float, psi_prime: float) -> tuple[Array, Array, Array]:
    """The paper's literal robust covariance update (Chernodarov sec. 4): f = h'U, V = D f',
    a2 = f V psi' + r, K = U V / a2, MWGS{[K f psi' - U : K], diag(D, r psi')} -> (U+, d+); returns (U+, d+, K)."""
    f = h @ U
    V = d * f
    a2 = float(f @ V) * psi_prime + r
    K = U @ V / a2
    W = np.hstack([np.outer(K, f) * psi_prime - U, K[:, None]])
    U_new, d_new = mwgs(W, np.concatenate([d, [r * psi_prime]]))
    return U_new, d_new, K


# --------------------------------------------------------------------------------------------------------------
# influence functions


@dataclass(frozen=True)
class InfluenceFunction:
    """psi(beta), psi'(beta) of seed 004 sec. 4; the branch is chosen on b = v / sqrt(S) (see module doc).

    kind: one of INFLUENCES; outer: the 3-sigma tolerance of eq. 6 (Laplace beyond it); inner: start of the
    Gauss-Laplace band (gauss-laplace only); huber_k: Huber's corner (huber only). All in units of sigma.
    """

    kind: Influence = "gauss"
    outer: float = 3.0
    inner: float = 2.0
    huber_k: float = 3.0

    def __post_init__(self) -> None:
        if self.kind not in INFLUENCES:
            raise ValueError(f"influence: must be one of {', '.join(INFLUENCES)}; got {self.kind!r}")
        for name in ("outer", "inner", "huber_k"):
            value = getattr(self, name)
            if not isinstance(value, int | float) or not np.isfinite(value) or value <= 0.0:
                raise ValueError(f"{name}: must be a positive number of sigmas; got {value!r}")
        if self.inner >= self.outer:
            raise ValueError(f"inner: must be below outer ({self.outer}); got {self.inner!r}")

    def __call__(self, beta: float, b: float) -> tuple[float, float]:
        """(psi, psi') at the scaled residual beta, branch chosen by b = v / sqrt(S) (the filter passes beta = b)."""
        psi, dpsi = self.arrays(np.asarray(beta, float), np.asarray(b, float))
        return float(psi), float(dpsi)

    def arrays(self, beta: Array, b: Array) -> tuple[Array, Array]:
        """Vectorized (psi, psi') for arrays beta = v / alpha and b = v / sqrt(S) of one shape."""
        ab = np.abs(b)
        one = np.ones_like(beta)
        if self.kind == "gauss":
            return beta * one, one
        if self.kind == "huber":
            w = np.where(ab <= self.huber_k, 1.0, self.huber_k / np.maximum(ab, self.huber_k))
            return beta * w, w
        psi, dpsi = beta * one, one
        if self.kind == "gauss-laplace":
            band = (ab >= self.inner) & (ab < self.outer)
            psi, dpsi = np.where(band, beta / 3.0, psi), np.where(band, 1.0 / 3.0, dpsi)  # psi_lg = beta / 3
        out = ab >= self.outer  # Laplace: psi = sign(beta), psi' = 0
        return np.where(out, np.sign(beta), psi), np.where(out, 0.0, dpsi)


# --------------------------------------------------------------------------------------------------------------
# batched kernels: many independent filters (Monte Carlo runs) at once; U (runs, n, n), d (runs, n), x (runs, n)


def mwgs_batch(W: Array, dw: Array) -> tuple[Array, Array]:
    """`mwgs` over a leading runs axis: W (runs, n, m), dw (runs, m) -> U (runs, n, n), d (runs, n)."""
    W = np.array(W, dtype=float)
    R, n, _ = W.shape
    U = np.broadcast_to(np.eye(n), (R, n, n)).copy()
    d = np.zeros((R, n))
    for k in range(n - 1, -1, -1):
        c = dw * W[:, k]
        dk = np.einsum("rm,rm->r", W[:, k], c)
        pos = dk > 0.0
        safe = np.where(pos, dk, 1.0)
        col = np.where(pos[:, None], np.einsum("rim,rm->ri", W[:, :k], c) / safe[:, None], 0.0)
        U[:, :k, k] = col
        W[:, :k] -= col[:, :, None] * W[:, k, None, :]
        d[:, k] = np.where(pos, dk, 0.0)
    return U, d


def thornton_predict_batch(U: Array, d: Array, F: Array, Q: Array) -> tuple[Array, Array]:
    """`thornton_predict` over runs (F, Q shared): MWGS of [F U : G], diag(d, q)."""
    G, q = ud_factor(Q)
    R = U.shape[0]
    W = np.concatenate([np.einsum("ij,rjk->rik", F, U), np.broadcast_to(G, (R, *G.shape))], axis=2)
    return mwgs_batch(W, np.concatenate([d, np.broadcast_to(q, (R, q.size))], axis=1))


def bierman_update_batch(U: Array, d: Array, h: Array, r: Array) -> tuple[Array, Array]:
    """`bierman_update` over runs: h (n,) shared, r (runs,) > 0 (np.inf leaves that run's factors unchanged)."""
    f = np.einsum("rji,j->ri", U, h)  # f = U' h
    v = d * f
    keep = ~np.isfinite(r)
    r0 = np.where(keep, 1.0, r)
    alpha = r0[:, None] + np.cumsum(f * v, axis=1)
    alpha_prev = np.concatenate([r0[:, None], alpha[:, :-1]], axis=1)
    B = np.cumsum(U * v[:, None, :], axis=2)
    B_prev = np.concatenate([np.zeros((*B.shape[:2], 1)), B[:, :, :-1]], axis=2)
    U_new = U + B_prev * (-f / alpha_prev)[:, None, :]
    d_new = d * alpha_prev / alpha
    return np.where(keep[:, None, None], U, U_new), np.where(keep[:, None], d, d_new)


def robust_update_batch(
    x: Array, U: Array, d: Array, z: Array, h: Array, r: float, influence: InfluenceFunction
) -> tuple[Array, Array, Array, Array, Array, Array]:
    """`UDFilter.update` over runs with one shared h (n,) and r; z (runs,).

    Returns (x+, U+, d+, innovation, S, weight), the last three (runs,).
    """
    f = np.einsum("rji,j->ri", U, h)
    hph = np.einsum("ri,ri->r", f, d * f)
    S = hph + r  # S = h' P h + r
    nu = z - x @ h  # v = z - h' x
    sqrt_s = np.sqrt(S)
    b = nu / sqrt_s
    psi, dpsi = influence.arrays(b, b)
    Ph = np.einsum("rij,rj->ri", U, d * f)
    x_new = x + Ph * (psi / sqrt_s)[:, None]  # m+ = m + K sqrt(S) psi(b), K = P h / S
    with np.errstate(divide="ignore", invalid="ignore"):
        weight = np.where(nu == 0.0, 1.0, psi / b)
        r_eff = np.where(dpsi > 0.0, r / dpsi + hph * (1.0 / dpsi - 1.0), np.inf)  # P+ = P - psi' K S K'
    U_new, d_new = bierman_update_batch(U, d, h, r_eff)
    return x_new, U_new, d_new, nu, S, weight


# --------------------------------------------------------------------------------------------------------------
# the filter


@dataclass(frozen=True)
class UDFilter:
    """NavFilter on U-D factors (state.U, state.d; state.P is None). Gauss influence: the plain U-D filter."""

    name: str = "ud"
    influence: InfluenceFunction = InfluenceFunction()

    def init(self, x0: Array, P0: Array) -> FilterState:
        """State from x0 (n,) and P0 (n, n), P0 stored as its U-D factors."""
        U, d = ud_factor(0.5 * (np.asarray(P0, float) + np.asarray(P0, float).T))
        return FilterState(x=np.array(x0, dtype=float), U=U, d=d)

    def predict(self, state: FilterState, F: Array, Q: Array) -> FilterState:
        """x- = F x+ ; P- = F P+ F' + Q by Thornton's MWGS (Chernodarov eq. 3)."""
        U, d = thornton_predict(state.U, state.d, np.asarray(F, float), np.asarray(Q, float))
        return FilterState(x=F @ state.x, U=U, d=d, memory=state.memory)

    def update(self, state: FilterState, meas: ScalarMeasurement) -> tuple[FilterState, UpdateStatus]:
        """One scalar robust update (Chernodarov sec. 4, residual scaled by sqrt(S); module docstring)."""
        x, U, d, h, r = state.x, state.U, state.d, np.asarray(meas.h, float), float(meas.r)
        f = U.T @ h
        hph = float(f @ (d * f))  # h' P h
        S = hph + r  # S = h' P h + r
        nu = float(meas.z - h @ x)  # innovation v_j = z_j - H_j m_{j-1}
        b = nu / np.sqrt(S)  # normalized innovation
        psi, dpsi = self.influence(b, b)
        step = (U @ (d * f)) * (psi / np.sqrt(S))  # K sqrt(S) psi(b), K = P h / S
        weight = 1.0 if nu == 0.0 else float(psi / b)
        status = UpdateStatus(meas.name, meas.t_s, nu, S, nu * nu / S, weight, True)
        if dpsi > 0.0:
            # P+ = P - psi' K S K': r_eff = S / psi' - h'Ph, written so that psi' = 1 gives r exactly
            U, d, _, _ = bierman_update(U, d, h, r / dpsi + hph * (1.0 / dpsi - 1.0))
        return FilterState(x=x + step, U=U, d=d, memory=state.memory), status

    def covariance(self, state: FilterState) -> Array:
        """P = U diag(d) U' (n, n)."""
        return (state.U * state.d) @ state.U.T


# --------------------------------------------------------------------------------------------------------------
# registry factories (profile tuning checked here; errors name the field)

_TUNING_KEYS = {
    "gauss": (),
    "laplace": ("outer",),
    "gauss-laplace": ("inner", "outer"),
    "huber": ("huber_k",),
}


def make_ud(**tuning: object) -> UDFilter:
    """The plain U-D filter (registry name 'ud'); it takes no tuning."""
    if tuning:
        raise ProfileError(f"nav.filter_tuning.{sorted(tuning)[0]}: unknown key (the plain 'ud' takes no tuning)")
    return UDFilter(name="ud")


def make_robust_ud(influence: object = "gauss-laplace", *, name: str = "robust-ud", **tuning: object) -> UDFilter:
    """The robust U-D filter with influence function `influence` and its keys (outer, inner, huber_k; sigma)."""
    if influence not in INFLUENCES:
        raise ProfileError(f"nav.filter_tuning.influence: must be one of {', '.join(INFLUENCES)}; got {influence!r}")
    allowed = _TUNING_KEYS[str(influence)]
    for key, value in sorted(tuning.items()):
        if key not in allowed:
            raise ProfileError(
                f"nav.filter_tuning.{key}: unknown key for influence {influence!r}"
                f" (allowed: {', '.join(allowed) or 'none'})"
            )
        if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 < float(value) < float("inf"):
            raise ProfileError(f"nav.filter_tuning.{key}: must be a positive number of sigma; got {value!r}")
    try:
        fn = InfluenceFunction(str(influence), **{k: float(v) for k, v in tuning.items()})  # type: ignore[arg-type]
    except ValueError as e:
        raise ProfileError(f"nav.filter_tuning.{e}") from None
    return UDFilter(name=name, influence=fn)
