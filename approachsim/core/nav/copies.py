"""Copies of a filter on a given model (numba, cache=True): core/nav/epoch.shared_pass with the model given; the
integrity bank's main and sub-filters, and one run's filter on its reduced state (nav/reduced.py).

    bank_epochs(X, P3, phi, qd, lay, ch_gse, ch_gmp, f_gse, f_gmp, ref, ref_agl, ins, <observations>, ...)

shared_pass makes each epoch's model (F, Qc at the reference, Phi, Qd by Van Loan) itself, once per call; the bank
calls it once per run, so every run of an open-loop flight group made the same models again (they depend on the
shared truth only). Here Phi and Qd (E, n, n) come in, made once per truth on the full layout and cut to the run's
reduced state (nav/reduced.py `models`, `cut`); the rest is shared_pass's loop: per epoch and copy, the channel
states' Qd at the copy's sky, then core/nav/epoch.class_epoch in shared mode (the same function, so the same
arithmetic). tests/unit/integrity/test_bankpass.py: equal to shared_pass bit for bit.

One compiled loop, bank_epochs_carrier (shared_pass's carrier step: the gio states' Qd at each copy's sky, its
ambiguities reset at its new arcs, the carrier rows); bank_epochs calls it with no carrier channels. With carrier
phase the models are carrier_models (`models` plus kernels/carrier.dynamics); tests/unit/integrity/
test_bankpass_carrier.py.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from approachsim.core.nav import carrier as kcar
from approachsim.core.nav import epoch as ke
from approachsim.core.nav import errormodel as ek


def bank_epochs(X: np.ndarray, P3: np.ndarray, phi: np.ndarray, qd: np.ndarray, lay: np.ndarray,
                ch_gse: np.ndarray, ch_gmp: np.ndarray, f_gse: np.ndarray, f_gmp: np.ndarray,
                ref: np.ndarray, ref_agl: np.ndarray, ins: np.ndarray,
                baro_h: np.ndarray, baro_r: np.ndarray,
                radalt_h: np.ndarray, ra_pct: float, ra_floor: float,
                tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
                db_u: np.ndarray,
                rho: np.ndarray, r_sv: np.ndarray, sig: np.ndarray, channel_states: bool,
                pl_rho: np.ndarray, r_pl: np.ndarray, pl_sig: np.ndarray, pl_states: bool,
                codes: np.ndarray, nu_out: np.ndarray, S_out: np.ndarray, n_rows: np.ndarray,
                x_out: np.ndarray, pd_out: np.ndarray, pnav_out: np.ndarray,
                h: np.ndarray, b: np.ndarray, ws: tuple) -> None:
    """Every epoch of every copy (core/nav/epoch.shared_pass's loop) with the epoch's model phi[e], qd[e] (E, n, n)
    given (the damping loop held or not as the copies' INS: the bank's copies share one), without carrier phase:
    bank_epochs_carrier with no carrier channels (no carrier rows, no ionosphere states, no arcs: the same
    arithmetic). Arguments as shared_pass (ch_gse, ch_gmp (N, E, k), f_gse, f_gmp (E,), ref (E, 16), ref_agl (E,),
    ins (N, E, 16), the observations indexed [i, e]); out per copy and epoch: codes, nu_out, S_out (N, E, R),
    n_rows (N, E), x_out (N, E, n), pd_out (N, E, n) and pnav_out (N, E, 9, 9) after the epoch's updates."""
    N, E = X.shape[0], phi.shape[0]
    none = np.zeros((N, E, 0))
    bank_epochs_carrier(X, P3, phi, qd, lay, ch_gse, ch_gmp, f_gse, f_gmp, ref, ref_agl, ins, baro_h, baro_r,
                        radalt_h, ra_pct, ra_floor, tx, th, rwy, dbp, db_x, db_u, rho, r_sv, sig, channel_states,
                        none, 0.0, pl_rho, r_pl, pl_sig, pl_states, none, np.zeros(E), np.zeros((N, E, 0), np.int64),
                        0.0, codes, nu_out, S_out, n_rows, x_out, pd_out, pnav_out, h, b, ws)


@njit(cache=True)
def models(lay: np.ndarray, q: np.ndarray, gse: np.ndarray, gmp: np.ndarray, loop: np.ndarray, dt: np.ndarray,
           ref: np.ndarray, ref_cbn: np.ndarray, f_ref: np.ndarray, held: np.ndarray, phi: np.ndarray,
           qd: np.ndarray) -> int:
    """Phi, Qd (E, n, n) of every epoch at the reference, as shared_pass makes them (kernels/errormodel.dynamics
    at ref[e] (E, 16) with ref_cbn[e], f_ref[e], the damping loop held where held[e] != 0, then discretize over
    dt[e]). Returns E, or -1 - e when epoch e's model is too large for the compiled discretization."""
    E = dt.shape[0]
    n = phi.shape[1]
    F = np.empty((n, n))
    Qc = np.empty((n, n))
    for e in range(E):
        y = ref[e]
        ek.dynamics(lay, q, gse, gmp, y[0], y[2], y[3:6], f_ref[e], ref_cbn[e], loop, held[e] != 0, F, Qc)
        if not ek.discretize(F, Qc, dt[e], phi[e], qd[e]):
            return -1 - e
    return E


@njit(cache=True)
def carrier_models(lay: np.ndarray, q: np.ndarray, gse: np.ndarray, gmp: np.ndarray, loop: np.ndarray,
                   dt: np.ndarray, ref: np.ndarray, ref_cbn: np.ndarray, f_ref: np.ndarray, held: np.ndarray,
                   gio: np.ndarray, gio_tau: float, phi: np.ndarray, qd: np.ndarray) -> int:
    """`models` with the carrier states (core/nav/epoch.shared_pass's model under carrier phase): after kernels.
    errormodel.dynamics, kernels.carrier.dynamics (gio Gauss-Markov of 1-sigma gio (n_sv,) m and correlation time
    gio_tau s; amb random constants), then discretize over dt[e]. Returns E, or -1 - e as `models`."""
    E = dt.shape[0]
    n = phi.shape[1]
    F = np.empty((n, n))
    Qc = np.empty((n, n))
    for e in range(E):
        y = ref[e]
        ek.dynamics(lay, q, gse, gmp, y[0], y[2], y[3:6], f_ref[e], ref_cbn[e], loop, held[e] != 0, F, Qc)
        kcar.dynamics(lay, gio, gio_tau, F, Qc)
        if not ek.discretize(F, Qc, dt[e], phi[e], qd[e]):
            return -1 - e
    return E


@njit(cache=True)
def bank_epochs_carrier(X: np.ndarray, P3: np.ndarray, phi: np.ndarray, qd: np.ndarray, lay: np.ndarray,
                        ch_gse: np.ndarray, ch_gmp: np.ndarray, f_gse: np.ndarray, f_gmp: np.ndarray,
                        ref: np.ndarray, ref_agl: np.ndarray, ins: np.ndarray,
                        baro_h: np.ndarray, baro_r: np.ndarray,
                        radalt_h: np.ndarray, ra_pct: float, ra_floor: float,
                        tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
                        db_u: np.ndarray,
                        rho: np.ndarray, r_sv: np.ndarray, sig: np.ndarray, channel_states: bool,
                        cp: np.ndarray, cp_r: float,
                        pl_rho: np.ndarray, r_pl: np.ndarray, pl_sig: np.ndarray, pl_states: bool,
                        ch_gio: np.ndarray, f_gio: np.ndarray, new: np.ndarray, amb_prior: float,
                        codes: np.ndarray, nu_out: np.ndarray, S_out: np.ndarray, n_rows: np.ndarray,
                        x_out: np.ndarray, pd_out: np.ndarray, pnav_out: np.ndarray,
                        h: np.ndarray, b: np.ndarray, ws: tuple) -> None:
    """`bank_epochs` under carrier phase: core/nav/epoch.shared_pass's per-copy step with the carrier states, in its
    order. Per epoch e and copy i: Qd = qd[e] with the channel states' entries at the copy's sky (ch_gse, ch_gmp,
    then the ionosphere's ch_gio (N, E, k) m times f_gio[e] = 1 - exp(-2 dt / tau_gio)), the ambiguities of the
    channels with new[i, e, c] != 0 (a new carrier arc: engine.stacked_new_arcs) reset to amb_prior m^2 in Phi
    (a copy) and Qd (kernels/carrier.reset_ambiguities), then class_epoch in shared mode with the carrier phases
    cp (N, E, k) m of variance cp_r m^2. Other arguments and outputs as `bank_epochs`."""
    N, n = X.shape
    E = phi.shape[0]
    qd_tmp = np.empty((n, n))
    phi_tmp = np.empty((n, n))
    ig, im, io = lay[ek.L_GSE], lay[ek.L_GMP], lay[ek.L_GIO]
    for e in range(E):
        y = ref[e]
        same = False  # qd_tmp and ws hold epoch e's model, no resets since (core/nav/epoch.py, model reuse)
        for i in range(N):
            if not same:
                qd_tmp[:, :] = qd[e]
            if ig >= 0:
                for c in range(ch_gse.shape[2]):
                    qd_tmp[ig + c, ig + c] = ch_gse[i, e, c] ** 2 * f_gse[e]
                    qd_tmp[im + c, im + c] = ch_gmp[i, e, c] ** 2 * f_gmp[e]
            if io >= 0:
                for c in range(ch_gio.shape[2]):
                    qd_tmp[io + c, io + c] = ch_gio[i, e, c] ** 2 * f_gio[e]
            reset = ke._any_new(new[i, e])
            ready = same and not reset
            phi_e = ke._with_resets(phi[e], qd_tmp, lay, new[i, e], amb_prior, phi_tmp)
            P = P3[i]
            n_rows[i, e] = ke.class_epoch(X[i:i + 1], P, phi_e, qd_tmp, lay, False, y, ins[i, e:e + 1],
                                          baro_h[i, e:e + 1], baro_r[e], radalt_h[i, e:e + 1], ra_pct, ra_floor,
                                          ref_agl[e], tx, th, rwy, dbp[i:i + 1], db_x, db_u[i:i + 1],
                                          rho[i, e:e + 1], r_sv[i, e], sig[i, e], channel_states, cp[i, e:e + 1],
                                          cp_r, pl_rho[i, e:e + 1], r_pl, pl_sig[e], pl_states, codes[i, e],
                                          nu_out[i, e:e + 1], S_out[i, e], h, b, ws, ready)
            same = not reset
            for a in range(n):
                x_out[i, e, a] = X[i, a]
                pd_out[i, e, a] = P[a, a]
            for a in range(9):
                for c in range(9):
                    pnav_out[i, e, a, c] = P[a, c]
