"""Protection levels: the one formula the online FDE (nav/fde.py) and the offline solution-separation bank
(integrity/separation.py, campaign/integrity_bank.py) share, and the single-epoch separation of a measurement left out.

Per approach axis a (vertical, lateral), with the K factors of integrity.requirements (one allocation for both):

    PL_H0,a = K_ff sigma_0,a
    PL_H1,a = max_k (T_k,a + K_md sigma_k,a)          |e_0| <= (the fault's largest undetected effect) + K_md sigma
    PL_a    = max(PL_H0,a, PL_H1,a)

What differs between the two users is the fault hypothesis and its detector, hence T_k and sigma_k:

* offline bank: fault mode k persists over the run and sub-filter k never uses it; the detector is the
  separation test |Delta_k| > K_fa sigma_ss,k, so T_k = K_fa sigma_ss,k and sigma_k is the sub-filter's own
  (e_0 = e_k - Delta_k; Blanch et al. 2012, ARAIM ADD).
* online FDE: a bias on measurement j arriving at this epoch; the detector is the epoch's chi-square residual
  test, whose missed detection at P_md is the non-centrality lambda, so the largest undetected bias
  b_j = sqrt(lambda / (S^-1)_jj) moves the output by T_j = |a' K_j| b_j = sqrt(lambda) sigma_ss,j, and the
  fault-free part is the full solution's own error, sigma_k = sigma_0 (the slope method, Brown 1992).

sigma_ss,j = |a' K_j| / sqrt((S^-1)_jj) is the separation sigma of the sub-solution that leaves measurement j out
of this epoch's batch update (K = P- H' S^-1 the batch gain): x_0 - x_j = K_j (S^-1 nu)_j / (S^-1)_jj, so
P_j - P_0 = K_j K_j' / (S^-1)_jj -- the offline bank's P_k - P_0 at the first epoch a mode is left out
(tests/unit/integrity/test_protection.py checks it against the explicit sub-filter).
"""

from __future__ import annotations

import numpy as np

Array = np.ndarray


def protection_levels(sig0: Array, t: Array, sig_k: Array, k_ff: float, k_md: float) -> tuple[Array, Array, Array]:
    """(PL_H0, PL_H1, PL), m, per axis (module docstring). sig0 (..., 2): the output's sigma; t, sig_k
    (..., modes, 2): each mode's largest undetected effect on the output and its fault-free sigma (broadcastable).
    PL_H1 is inf where there is no mode (nothing to detect a fault with)."""
    pl_h0 = k_ff * np.asarray(sig0, float)
    h1 = np.asarray(t, float) + k_md * np.asarray(sig_k, float)
    pl_h1 = np.max(h1, axis=-2) if h1.shape[-2] else np.full(pl_h0.shape, np.inf)
    return pl_h0, pl_h1, np.maximum(pl_h0, pl_h1)


def epoch_shift(axes: Array, gain: Array, s_inv_diag: Array, lam: float = 1.0) -> Array:
    """(modes = measurements, axes) output shift |a' K_j| sqrt(lam / (S^-1)_jj), m: with lam = 1 the separation
    sigma sigma_ss,j of the sub-solution without measurement j at this epoch; with the residual test's
    non-centrality lambda, T_j. axes (2, 3) NED -> (up, right); gain (3, m) the position rows of the batch gain
    P- H' S^-1; s_inv_diag (m,) the diagonal of S^-1."""
    slope = np.abs(np.asarray(axes, float) @ np.asarray(gain, float))  # (2, m): output shift per metre of bias
    return (slope * np.sqrt(lam / np.asarray(s_inv_diag, float))).T
