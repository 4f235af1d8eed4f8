"""Solution-separation integrity: detection test, exclusion and the fault-free / single-fault protection levels.

The main solution uses every measurement; sub-solution k leaves out fault mode k (one satellite, or the
pseudolite). For optimal (Kalman or least-squares) estimators on the same data the separation
Delta_k = x_k - x_0 has covariance P_k - P_0 (Brenner 1996; Blanch et al. 2012 ARAIM, ADD v4.2), so per axis
a (vertical, lateral in the approach frame):

    sigma_0 = sqrt(P_0,aa),  sigma_k = sqrt(P_k,aa),  sigma_ss,k = sqrt(P_k,aa - P_0,aa)
    detection:  |Delta_k,a| > T_k,a = K_fa sigma_ss,k        (any k, any axis)
    PL_H0,a = K_ff sigma_0
    PL_H1,a = max_k (T_k,a + K_md sigma_k)                     (|e_0| <= |e_k| + |Delta_k| undetected)
    PL_a    = max(PL_H0,a, PL_H1,a)

Exclusion after a detection: the mode whose full-state separation is largest in its own metric,
Delta_k' (P_k - P_0)^+ Delta_k (the pseudo-inverse: leaving one measurement out moves the solution along one
direction, and this statistic is then Baarda's w-test squared for that measurement, the optimal single-fault
identification), is excluded and sub-solution k becomes the output; it is protected against the fault-free case only
(PL = K_ff sigma_k) unless a second-level bank monitors it, so the solution is flagged and, when that
PL exceeds the alert limit, an alert is raised. Arrays: epochs on axis 0, modes on axis 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Array = np.ndarray


@dataclass(frozen=True)
class SeparationResult:
    """Per epoch (axis 0) and axis (last axis: 0 vertical, 1 lateral), m unless stated."""

    pl_h0_m: Array
    """(epochs, 2) K_ff sigma_0."""
    pl_h1_m: Array
    """(epochs, 2) max_k (T_k + K_md sigma_k)."""
    pl_m: Array
    """(epochs, 2) max of the two."""
    test_ratio: Array
    """(epochs, modes, 2) |Delta_k| / T_k: a detection where > 1."""
    detected: Array
    """(epochs,) bool: any mode's separation over its threshold on either axis."""
    suspect: Array
    """(epochs,) int: the mode with the largest normalized separation (-1 when none detected)."""


def separation(x0: Array, p0: Array, xk: Array, pk: Array, k_ff: float, k_fa: float, k_md: float,
               tested: Array | None = None) -> SeparationResult:
    """Solution separation on two axes. x0 (epochs, 2), p0 (epochs, 2) variances of the main solution;
    xk (epochs, modes, 2), pk (epochs, modes, 2) of the sub-solutions (each axis its own variance, m^2).
    tested (modes, 2) bool: the axes on which each mode's separation is a detection test (default every one); an
    untested axis keeps its H1 term T + K_md sigma_k but never detects nor names a suspect."""
    x0, p0 = np.asarray(x0, float), np.asarray(p0, float)
    xk, pk = np.asarray(xk, float), np.asarray(pk, float)
    sig0 = np.sqrt(np.maximum(p0, 0.0))
    sigk = np.sqrt(np.maximum(pk, 0.0))
    sig_ss = np.sqrt(np.maximum(pk - p0[:, None, :], 1e-18))
    thr = k_fa * sig_ss
    delta = xk - x0[:, None, :]
    on = np.ones(delta.shape[1:], bool) if tested is None else np.asarray(tested, bool)
    ratio = np.where(on, np.abs(delta) / thr, 0.0)
    detected = np.any(ratio > 1.0, axis=(1, 2))
    norm_sep = np.max(np.where(on, np.abs(delta) / sig_ss, 0.0), axis=2)
    suspect = np.where(detected, np.argmax(norm_sep, axis=1), -1)
    pl_h0 = k_ff * sig0
    pl_h1 = np.max(thr + k_md * sigk, axis=1)
    return SeparationResult(pl_h0, pl_h1, np.maximum(pl_h0, pl_h1), ratio, detected, suspect)


def identify(delta_full: Array, pss_full: Array) -> Array:
    """The fault mode to exclude (epochs,): argmax_k Delta_k' (P_ss,k)^+ Delta_k over the full state.
    delta_full (epochs, modes, n) = x_k - x_0; pss_full (modes, n, n) or (epochs, modes, n, n) = P_k - P_0."""
    d = np.asarray(delta_full, float)
    pinv = np.linalg.pinv(np.asarray(pss_full, float), rcond=1e-10, hermitian=True)
    if pinv.ndim == 3:
        pinv = np.broadcast_to(pinv, (d.shape[0], *pinv.shape))
    t = np.einsum("ekn,eknm,ekm->ek", d, pinv, d)
    return np.argmax(t, axis=1)


def identify_statistic(delta_full: Array, pss_full: Array, rcond: float = 1e-10) -> Array:
    """Delta_k' (P_ss,k)^+ Delta_k (epochs, modes) for delta_full (epochs, modes, n) and pss_full
    (epochs, modes, n, n), computed on the correlation scale (each state divided by its separation sigma) so
    that the pseudo-inverse's cut-off does not depend on the states' units (m, m/s, rad).

    P_ss is a covariance difference: in exact arithmetic positive semi-definite, in floating point it can have
    slightly negative eigenvalues and non-positive diagonal entries. Those directions carry no separation
    information: a state with P_ss,ii <= 0 is left out and the pseudo-inverse keeps the eigenvalues above rcond times
    the largest (the positive part). Inverting a negative eigenvalue instead made the statistic of a 118 m
    separation -8.6e15 and the bank exclude another satellite (the CAT III candidate, an 807 m pseudorange ramp
    absorbed before the approach: HMI at every epoch)."""
    d = np.asarray(delta_full, float)
    P = np.asarray(pss_full, float)
    var = np.einsum("...ii->...i", P)
    ok = var > 0.0
    sd = np.sqrt(np.where(ok, var, 1.0))
    z = np.where(ok, d / sd, 0.0)
    W = P / (sd[..., :, None] * sd[..., None, :]) * (ok[..., :, None] & ok[..., None, :])
    W = 0.5 * (W + np.swapaxes(W, -1, -2))
    lam, V = np.linalg.eigh(W)
    keep = lam > rcond * np.max(lam, axis=-1, keepdims=True)
    c = np.einsum("...nm,...n->...m", V, z)
    return np.sum(np.where(keep, c * c / np.where(keep, lam, 1.0), 0.0), axis=-1)


def least_squares_bank(G: Array, w: Array) -> tuple[Array, Array]:
    """Snapshot weighted least squares with every measurement and leaving each one out: the estimator
    matrices S (modes + 1, n, m) (mode 0: all in view; mode k: measurement k - 1 out) and covariances
    P (modes + 1, n, n), for geometry G (m, n) and weights w (m,) = 1 / sigma^2. x = S z (DO-229 App. J)."""
    G, w = np.asarray(G, float), np.asarray(w, float)
    m = G.shape[0]
    masks = np.ones((m + 1, m))
    masks[np.arange(1, m + 1), np.arange(m)] = 0.0
    S, P = [], []
    for mask in masks:
        W = np.diag(w * mask)
        cov = np.linalg.inv(G.T @ W @ G)
        S.append(cov @ G.T @ W)
        P.append(cov)
    return np.array(S), np.array(P)
