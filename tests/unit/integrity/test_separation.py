"""Solution separation on a snapshot least-squares geometry (eight satellites, 1 m ranging): the fault-free PL
is exceeded at the Gaussian rate its multiplier stands for; with a satellite bias anywhere between "never
seen" and "always seen", an undetected error beyond PL_H1 is no more frequent than the missed-detection
allocation; a large bias is detected and the right satellite identified. Multipliers are chosen for rates a
Monte Carlo can see (1e-2, 1e-3); the algebra is the same at 1e-9."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import binom, norm

from approachsim.integrity.separation import identify, identify_statistic, least_squares_bank, separation

EL = np.radians([80.0, 45.0, 30.0, 25.0, 15.0, 60.0, 35.0, 20.0])
AZ = np.radians([10.0, 80.0, 160.0, 230.0, 300.0, 200.0, 120.0, 20.0])
G = np.column_stack([np.cos(EL) * np.sin(AZ), np.cos(EL) * np.cos(AZ), np.sin(EL), np.ones(EL.size)])  # e, n, u, clock
M = EL.size
W = np.ones(M)
AXES = (2, 0)  # vertical (up), lateral (east, as the cross-track axis of a north-facing runway)


def _solve(z):
    S, P = least_squares_bank(G, W)
    x = np.einsum("knm,em->ekn", S, z)  # (epochs, modes+1, n)
    var = np.stack([P[:, a, a] for a in AXES], axis=-1)  # (modes+1, 2)
    xa = x[..., list(AXES)]
    e = z.shape[0]
    return xa[:, 0], np.broadcast_to(var[0], (e, 2)), xa[:, 1:], np.broadcast_to(var[1:], (e, M, 2))


def test_fault_free_pl_exceeded_at_its_rate():
    rng = np.random.default_rng(11)
    n = 40000
    z = rng.standard_normal((n, M))  # truth 0: z = noise
    k_ff = float(norm.isf(1e-3 / 2))
    x0, p0, xk, pk = _solve(z)
    r = separation(x0, p0, xk, pk, k_ff=k_ff, k_fa=float(norm.isf(1e-3 / 2)), k_md=2.0)
    exceed = np.abs(x0) > r.pl_h0_m
    lo, hi = binom.ppf([0.0005, 0.9995], n, 1e-3)
    for a in range(2):
        assert lo <= exceed[:, a].sum() <= hi
    false_alert = r.detected.mean()
    assert false_alert < M * 2 * 1e-3 * 1.5  # M modes x 2 axes x 1e-3, union bound with margin


@pytest.mark.parametrize("bias_m", [2.0, 5.0, 8.0, 12.0])
def test_undetected_error_beyond_pl_is_rarer_than_the_missed_detection_allocation(bias_m):
    rng = np.random.default_rng(int(bias_m * 10))
    n = 20000
    p_md = 1e-2
    z = rng.standard_normal((n, M))
    z[:, 3] += bias_m
    x0, p0, xk, pk = _solve(z)
    r = separation(x0, p0, xk, pk, k_ff=float(norm.isf(1e-3 / 2)), k_fa=float(norm.isf(1e-3 / 2)),
                   k_md=float(norm.isf(p_md)))
    hmi = (~r.detected)[:, None] & (np.abs(x0) > r.pl_m)
    assert hmi.any(axis=1).mean() <= p_md  # per axis each bounded by p_md; measured far below


def test_large_bias_detected_and_identified():
    rng = np.random.default_rng(5)
    z = rng.standard_normal((2000, M))
    z[:, 4] += 60.0
    x0, p0, xk, pk = _solve(z)
    r = separation(x0, p0, xk, pk, k_ff=6.0, k_fa=5.3, k_md=3.5)
    assert r.detected.mean() > 0.999
    # identification by the full-state separation in its own metric (Baarda's w-test)
    S, P = least_squares_bank(G, W)
    x = np.einsum("knm,em->ekn", S, z)
    k = identify(x[:, 1:] - x[:, :1], P[1:] - P[:1])
    assert np.mean(k == 4) > 0.999
    # excluding it: the sub-solution without satellite 4 has an error at the noise level
    e_excl = xk[np.arange(len(z)), 4]
    assert np.sqrt(np.mean(e_excl**2)) < 5.0


def test_identification_statistic_is_baardas_w_test_squared_in_any_units():
    """Snapshot least squares: Delta_k' (P_k - P_0)^+ Delta_k equals Baarda's w-test squared of measurement k,
    w_k = r_k / sqrt((R - G P_0 G')_kk) with r = z - G x_0; unchanged when a state is rescaled (metres to
    millimetres), which a pseudo-inverse cut-off on the raw covariance would not guarantee."""
    rng = np.random.default_rng(8)
    z = rng.standard_normal((50, M))
    z[:, 2] += 8.0
    S, P = least_squares_bank(G, W)
    x = np.einsum("knm,em->ekn", S, z)
    d, pss = x[:, 1:] - x[:, :1], np.broadcast_to(P[1:] - P[:1], (len(z), M, 4, 4))
    t = identify_statistic(d, pss)
    r = z - x[:, 0] @ G.T
    qr = np.diag(np.diag(1.0 / W) - G @ P[0] @ G.T)
    np.testing.assert_allclose(t, r**2 / qr, rtol=1e-8)
    scale = np.array([1e3, 1.0, 1.0, 1e-3])  # east in mm, clock in km
    np.testing.assert_allclose(identify_statistic(d * scale, pss * np.outer(scale, scale)), t, rtol=1e-8)
    assert np.mean(np.argmax(t, axis=1) == 2) > 0.95


def test_untested_axis_neither_detects_nor_names_the_suspect() -> None:
    """A mode's separation on an axis marked untested (campaign/integrity_bank.own_ins_bank: the baro's lateral axis
    when its sub-filter runs its own INS) is no detection: a 10-sigma lateral separation of mode 0 detects with every
    axis tested and not with its lateral axis off; the vertical test and the H1 protection level are unchanged."""
    x0 = np.zeros((1, 2))
    p0 = np.ones((1, 2))
    xk = np.array([[[0.0, 10.0], [0.5, 0.0]]])
    pk = np.full((1, 2, 2), 2.0)
    every = separation(x0, p0, xk, pk, 6.0, 5.0, 3.0)
    off = separation(x0, p0, xk, pk, 6.0, 5.0, 3.0, tested=np.array([[True, False], [True, True]]))
    assert every.detected[0] and every.suspect[0] == 0
    assert not off.detected[0] and off.suspect[0] == -1
    np.testing.assert_array_equal(off.test_ratio[0, 1], every.test_ratio[0, 1])
    np.testing.assert_array_equal(off.pl_m, every.pl_m)


def test_identification_statistic_keeps_the_positive_part_of_the_separation_covariance() -> None:
    """P_ss = P_k - P_0 in floating point can have a slightly negative eigenvalue or diagonal entry; those
    directions carry no separation information and are left out (a negative eigenvalue inverted made a 118 m
    separation's statistic -8.6e15 and the bank exclude another satellite: identify_statistic's docstring).
    Mode 0: a 10-sigma separation on state 0 and 1 mm on a state whose separation variance is -1e-9 m^2 (dropped):
    100. Mode 1: P_ss with eigenvalues 2 and -5e-7, the separation along the negative one's eigenvector
    ((1, -1) / sqrt(2), 1 m) and 3 m along the positive one's: only the latter counts, 3^2 / 2."""
    d = np.array([[[10.0, 1e-3], [3.0 / np.sqrt(2.0) + 1.0 / np.sqrt(2.0), 3.0 / np.sqrt(2.0) - 1.0 / np.sqrt(2.0)]]])
    e = 1e-6
    lam_neg = 1.0 - (1.0 - e)  # the matrix below has eigenvalues (2 - e +- sqrt(e^2 + 4)) / 2, about 2 and -e / 2
    P = np.array([[[[1.0, 0.0], [0.0, -1e-9]], [[1.0, 1.0], [1.0, 1.0 - lam_neg]]]])
    w = identify_statistic(d, P)
    lam, V = np.linalg.eigh(P[0, 1])
    assert lam[0] < 0.0 < lam[1]  # the second mode's covariance is indefinite, as built
    expected_1 = float(V[:, 1] @ d[0, 1]) ** 2 / lam[1]
    # the statistic is made on the correlation scale: its positive part differs from P's by the diagonal scaling's
    # O(e) = 1e-6 turn of the eigenvectors
    np.testing.assert_allclose(w[0], [100.0, expected_1], rtol=1e-5)
    assert abs(expected_1 - 4.5) < 1e-3
    assert np.argmax(w[0]) == 0
