"""Compiled carrier-phase parts of the filter epoch (numba, cache=True): the carrier states' dynamics, the float
ambiguities' reset at a new arc and the carrier-phase row, for core/nav/epoch.py (nav/errormodel.py,
nav/navigator.py and nav/measurements.py give the equations; their numpy versions are the test oracle,
tests/unit/nav/test_carrier_engine.py).

    dynamics(lay, gio_sigma, gio_tau, F, Qc)      gio' = -gio / tau + w, E[w w'] = 2 sigma^2 / tau ; amb' = 0
    reset_ambiguities(phi, qd, lay, new, prior)   a new arc on channel c: row and column of amb_c zeroed in Phi and
                                                  Qd, Qd[amb_c, amb_c] = prior (P- then holds the prior there)
    nu = carrier_phase(lay, x_hat, r_ins, c_en, r_sv, phi, sv, h, row)
        z = |r_ins - r_sv| - phi ; g(x) = |r_ins - r_sv| - |r_ins - C' dp - r_sv| - clk - gse + gio - amb ;
        nu = z - g(x_hat) ; h: e' at dp, -1 at clk, gse and amb, +1 at gio (into h when `row`)

The code pseudorange row under carrier phase has -1 at gio as well (its ionosphere has the code's sign):
core/nav/epoch.class_epoch adds it to kernels/measurements.pseudorange's row.

Layout: lay[kernels.errormodel.L_GIO], lay[L_AMB] the groups' first index (-1: no carrier phase), lay[L_NSV] the
channels; gio, amb of channel c at index + c.
"""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav import measurements as km


@njit(cache=True)
def dynamics(lay: np.ndarray, gio_sigma: np.ndarray, gio_tau: float, F: np.ndarray, Qc: np.ndarray) -> None:
    """The carrier groups of F, Qc (n, n) in place, after kernels.errormodel.dynamics (which leaves them zero):
    gio first-order Gauss-Markov with 1-sigma gio_sigma (n_sv,) m and correlation time gio_tau s; amb random
    constants (zero rows). Nothing without carrier phase."""
    i0 = lay[ek.L_GIO]
    if i0 < 0:
        return
    for j in range(lay[ek.L_NSV]):
        i = i0 + j
        F[i, i] = -1.0 / gio_tau
        Qc[i, i] = 2.0 * gio_sigma[j] ** 2 / gio_tau


@njit(cache=True)
def reset_ambiguities(phi: np.ndarray, qd: np.ndarray, lay: np.ndarray, new: np.ndarray, prior: float) -> bool:
    """The float ambiguity of every channel c with new[c] != 0 (a new carrier arc) reset to its prior in the epoch's
    model, in place: Phi's and Qd's row and column of amb_c zeroed, Qd[amb_c, amb_c] = prior (m^2). Returns whether
    any channel was reset."""
    ia = lay[ek.L_AMB]
    if ia < 0:
        return False
    n = phi.shape[0]
    any_new = False
    for c in range(new.shape[0]):
        if new[c] == 0:
            continue
        any_new = True
        i = ia + c
        for j in range(n):
            phi[i, j] = 0.0
            phi[j, i] = 0.0
            qd[i, j] = 0.0
            qd[j, i] = 0.0
        qd[i, i] = prior
    return any_new


@njit(cache=True)
def carrier_phase(lay: np.ndarray, x_hat: np.ndarray, r_ins: np.ndarray, c_en: np.ndarray, r_sv: np.ndarray,
                  phi: float, sv: int, h: np.ndarray, row: bool) -> float:
    """nu = z - g(x_hat) of channel sv's carrier phase phi (m) (module docstring; nav/measurements.carrier_phase's
    arithmetic), and the row into h (n,) when `row`. r_ins, r_sv (3,) ECEF m; c_en (3, 3) ECEF -> NED at the INS."""
    ip = lay[ek.L_DP]
    a0, a1, a2, rng_hat, rng_ins = km.ranges(x_hat, ip, r_ins, c_en, r_sv)
    ic, ig, io, ia = lay[ek.L_CLK], lay[ek.L_GSE] + sv, lay[ek.L_GIO] + sv, lay[ek.L_AMB] + sv
    lin = -x_hat[ig] + x_hat[io] - x_hat[ia]  # h' x_hat over the states the difference is linear in
    if ic >= 0:
        lin -= x_hat[ic]
    if row:
        h[:] = 0.0
        if ic >= 0:
            h[ic] = -1.0
        h[ig] = -1.0
        h[io] = 1.0
        h[ia] = -1.0
        km.los_row(h, ip, c_en, a0, a1, a2, rng_hat, 1.0)
    z = rng_ins - phi
    g_hat = rng_ins - rng_hat + lin
    return z - g_hat
