"""integrity.protection: the one PL formula of the online FDE and the offline bank; the single-epoch separation of
a measurement left out equals the explicit sub-solution's (P_j - P_0 = K_j K_j' / (S^-1)_jj)."""

from __future__ import annotations

import numpy as np
import pytest
from floors import EPS, assert_within

from approachsim.integrity.protection import epoch_shift, protection_levels
from approachsim.integrity.requirements import REQUIREMENTS


def _case(seed: int, m: int = 7, n: int = 9) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A predicted covariance P- (n, n) over position (m), clock and five other states, GNSS-like rows H (m, n)
    (unit lines of sight on the position, 1 on the clock), R, a predicted state and measurements."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n))
    P = a @ a.T + np.diag(np.r_[25.0, 25.0, 25.0, 100.0, np.ones(n - 4)])
    los = rng.normal(size=(m, 3))
    los /= np.linalg.norm(los, axis=1)[:, None]
    H = np.zeros((m, n))
    H[:, 0:3] = -los
    H[:, 3] = 1.0
    R = np.diag(rng.uniform(0.2, 2.0, m) ** 2)
    x = rng.normal(size=n)
    z = H @ x + rng.normal(size=m) * 3.0
    return P, H, R, x, z


def _update(P: np.ndarray, H: np.ndarray, R: np.ndarray, x: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, ...]:
    S = H @ P @ H.T + R
    K = P @ H.T @ np.linalg.inv(S)
    return x + K @ (z - H @ x), P - K @ H @ P, K, S


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_single_epoch_separation_is_the_sub_solutions(seed: int) -> None:
    P, H, R, x, z = _case(seed)
    x0, P0, K, S = _update(P, H, R, x, z)
    s_inv = np.linalg.inv(S)
    nu = z - H @ x
    cond = float(np.linalg.cond(S))
    m, n = H.shape
    # P0 and P_j are each formed in about 2 (m + n) operations per entry through an inverse of S, which amplifies
    # their relative rounding by up to cond(S); the operands are of the size of P- (their difference is smaller)
    f = 4.0 * (m + n) * cond * EPS * float(np.max(np.abs(P)))
    for j in range(m):
        keep = np.arange(m) != j
        xj, Pj, _, _ = _update(P, H[keep], R[np.ix_(keep, keep)], x, z[keep])
        Kj = K[:, j]
        assert_within(Pj - P0, np.outer(Kj, Kj) / s_inv[j, j], f, f"P_{j} - P_0")
        assert_within(x0 - xj, Kj * (s_inv @ nu)[j] / s_inv[j, j],
                      f * float(np.max(np.abs(nu))) / np.sqrt(float(np.min(np.diag(P)))), f"x_0 - x_{j}")
    # and epoch_shift gives its sigma on the approach axes
    axes = np.array([[0.0, 0.0, -1.0], [-np.sin(0.3), np.cos(0.3), 0.0]])
    sig_ss = epoch_shift(axes, K[0:3], np.diag(s_inv))
    for j in range(m):
        keep = np.arange(m) != j
        Pj = _update(P, H[keep], R[np.ix_(keep, keep)], x, z[keep])[1]
        d = np.einsum("ai,ij,aj->a", axes, (Pj - P0)[0:3, 0:3], axes)
        assert_within(sig_ss[j] ** 2, d, 2.0 * f, f"sigma_ss of measurement {j}")


def test_protection_levels_formula_and_the_online_form() -> None:
    req = REQUIREMENTS["CAT II"]
    k_ff, k_md = req.k_ff(), req.k_md()
    sig0 = np.array([1.0, 2.0])
    t = np.array([[3.0, 1.0], [0.5, 9.0]])
    sig_k = np.array([[1.5, 2.1], [1.1, 2.5]])
    h0, h1, pl = protection_levels(sig0, t, sig_k, k_ff, k_md)
    assert np.array_equal(h0, k_ff * sig0)
    expected = [max(3.0 + k_md * 1.5, 0.5 + k_md * 1.1), max(1.0 + k_md * 2.1, 9.0 + k_md * 2.5)]
    assert np.array_equal(h1, np.array(expected))
    assert np.array_equal(pl, np.maximum(h0, h1))
    # no mode: nothing detects a fault, no H1 protection
    assert np.all(np.isinf(protection_levels(sig0, np.zeros((0, 2)), np.zeros((0, 2)), k_ff, k_md)[1]))
    # the online form (sigma_k = sigma_0 for every measurement) is bit-identical to max_j T_j + K_md sigma_0, the
    # formula nav/fde.py had before it called this one (rounding is monotone, so max(t + c) = max(t) + c exactly)
    rng = np.random.default_rng(5)
    for _ in range(200):
        t = rng.lognormal(size=(8, 2))
        s = rng.lognormal(size=2)
        assert np.array_equal(protection_levels(s, t, s[None, :], k_ff, k_md)[1], np.max(t, axis=0) + k_md * s)
