"""One aiding epoch of the optimal filter as one compiled call (numba, cache=True): the prediction and every
scalar update of the epoch, for one run or for the runs of a shared-covariance class.

    n_rows = class_epoch(X, P, phi, qd, lay, own, ref, ins, <observations>, codes, nu_out, S_out, h, b, ws)

Order of the rows (nav/rows.py): baro, radar altimeter, each GNSS channel in channel order, each channel's
carrier phase (carrier phase only), each pseudolite in unit order; a row exists when member 0's value is finite
(a class shares one schedule: nav/shared.py).

    predict    x_m <- Phi x_m (each member),  P <- Phi P Phi' + Qd                      (core/nav/kalman.py)
    each row   own (one run, the per-run EKF): h and nu = z - g(x_hat) at the run's own INS and current x_hat
               (sequential relinearization, as nav/navigator.py's per-run filters);
               shared (M runs): h and r at the reference trajectory `ref` with x_hat = 0 (the truth: nav/shared.py),
               nu_m of each member at its own INS and current x_hat_m
               S = h' P h + r ; K = P h / S ; x_m <- x_m + K nu_m ; P Joseph (O(n^2), core/nav/kalman.py)

Rows and innovations are kernels/measurements.py's. The numpy paths (nav/navigator.py with nav/rows.py, and
nav/shared.py) are the test oracle (tests/unit/nav/test_epoch_engine.py: equal to 1e-12 relative norm-wise).

Codes of the rows written to `codes`: CODE_BARO, CODE_RADALT, CODE_GPS + channel, CODE_PL + unit, CODE_CP + channel
(a GNSS channel's carrier phase).

Carrier phase (the layout's gio and amb groups, kernels/carrier.py): the code rows carry -1 at the channel's gio;
after every code row, each channel's carrier-phase row (nav/rows.py's order); the float ambiguities of the channels
whose arc began are reset in the epoch's Phi, Qd before the prediction (own_epoch, singleton_epochs, shared_pass;
class_epoch's caller otherwise).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from approachsim.core import geodesy as gk
from approachsim.core.nav import carrier as kcar
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav import kalman as kk
from approachsim.core.nav import measurements as km

CODE_BARO, CODE_RADALT, CODE_GPS, CODE_PL, CODE_CP = 0, 1, 100, 200, 300
"""Row codes (module docstring)."""


@njit(cache=True)
def _ecef(y: np.ndarray, r: np.ndarray) -> None:
    """ECEF position (m) of the packed INS state y (16,) into r (3,)."""
    r[0], r[1], r[2] = gk.geodetic_to_ecef(y[0], y[1], y[2])


@njit(cache=True)
def _apply(X: np.ndarray, P: np.ndarray, h: np.ndarray, r: float, nu: np.ndarray, b: np.ndarray,
           kc: np.ndarray) -> float:
    """S = h' P h + r; x_m += K nu_m (K = P h / S); P Joseph (c = 1). Returns S."""
    S = kk.gain(P, h, r, b)
    n = P.shape[0]
    for m in range(X.shape[0]):
        v = nu[m]
        for i in range(n):
            X[m, i] = X[m, i] + (b[i] / S) * v
    kk._joseph_cov(P, b, S, 1.0, kc)
    return S


@njit(cache=True)
def class_epoch(X: np.ndarray, P: np.ndarray, phi: np.ndarray, qd: np.ndarray, lay: np.ndarray, own: bool,
                ref: np.ndarray, ins: np.ndarray,
                baro_h: np.ndarray, baro_r: float,
                radalt_h: np.ndarray, ra_pct: float, ra_floor: float, ref_agl: float,
                tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
                db_u: np.ndarray,
                rho: np.ndarray, r_sv: np.ndarray, sig: np.ndarray, channel_states: bool,
                cp: np.ndarray, cp_r: float,
                pl_rho: np.ndarray, r_pl: np.ndarray, pl_sig: np.ndarray, pl_states: bool,
                codes: np.ndarray, nu_out: np.ndarray, S_out: np.ndarray,
                h: np.ndarray, b: np.ndarray, ws: tuple, csr_ready: bool = False) -> int:
    """Predict and update the M members of a class in place (module docstring); returns the number of rows.

    X (M, n) estimates; P (n, n) the class covariance; phi, qd (n, n) the epoch's model; lay the state layout
    (kernels.errormodel); own: the per-run EKF (M = 1; ref unused) else shared rows at `ref`; ref (16,), ins
    (M, 16) packed INS states (kernels.strapdown layout). Observations of the members: baro_h (M,) m (nan: none)
    with noise variance baro_r m^2; radalt_h (M,) m with sigma = sqrt((ra_pct h)^2 + ra_floor^2) at the measured
    height (own) or at ref_agl (shared); the filter's terrain tx, th, rwy and each member's database dbp (M, 4),
    db_x (k,), db_u (M, k) (kernels.measurements); rho (M, s) pseudoranges m (nan: none), r_sv (s, 3) ECEF m,
    sig (s,) their 1-sigma, channel_states: the rows carry the gse / gmp states; cp (M, s) carrier phases m (nan:
    none; (M, 0) without carrier phase) with noise variance cp_r m^2; pl_rho (M, p), r_pl (p, 3), pl_sig (p,),
    pl_states. Out: codes (R,), nu_out (M, R), S_out (R,); scratch h, b (n,), ws (kalman.workspace); csr_ready:
    ws already holds phi's nonzeros (kalman.csr; the caller's previous class_epoch had this same phi), so they are
    not collected again (the same numbers either way).
    """
    M = X.shape[0]
    n = X.shape[1]
    W, v, val, ptr, col = ws
    kc = v
    # predict: x_m <- Phi x_m ; P <- Phi P Phi' + Qd
    if not csr_ready:
        kk.csr(phi, ptr, col, val)
    for m in range(M):
        for i in range(n):
            acc = 0.0
            for p in range(ptr[i], ptr[i + 1]):
                acc += val[p] * X[m, col[p]]
            b[i] = acc
        for i in range(n):
            X[m, i] = b[i]
    kk._predict_cov(P, qd, W, ptr, col, val)
    x0 = np.zeros(n)
    nu = np.empty(M)
    r_ins = np.empty(3)
    r_ref = np.empty(3)
    c_ins = np.empty((3, 3))
    c_ref = np.empty((3, 3))
    _ecef(ref, r_ref)
    gk.c_ecef_to_ned(ref[0], ref[1], c_ref)
    k = 0
    empty_u = np.zeros(0)
    # baro
    if baro_h[0] == baro_h[0]:
        if own:
            nu[0], _ = km.baro(lay, X[0], ins[0, 2], baro_h[0], 0.0, h)
        else:
            km.baro(lay, x0, ref[2], baro_h[0], 0.0, h)
            for m in range(M):
                nu[m] = km.baro_nu(lay, X[m], ins[m, 2], baro_h[m])
        S_out[k] = _apply(X, P, h, baro_r, nu, b, kc)
        codes[k] = CODE_BARO
        for m in range(M):
            nu_out[m, k] = nu[m]
        k += 1
    # radar altimeter
    if radalt_h[0] == radalt_h[0]:
        u0 = db_u[0] if db_x.shape[0] > 0 else empty_u
        if own:
            hr = radalt_h[0]
            nu[0], _ = km.radalt(lay, X[0], ins[0, 0], ins[0, 1], ins[0, 2], hr, 0.0, tx, th, rwy, dbp[0], db_x, u0,
                                 h)
            s2 = (ra_pct * hr) ** 2 + ra_floor**2
        else:  # the row at the reference (no database error: it enters only z), sigma at the reference height
            km.radalt(lay, x0, ref[0], ref[1], ref[2], ref_agl, 0.0, tx, th, rwy, dbp[0], empty_u, empty_u, h)
            s2 = (ra_pct * ref_agl) ** 2 + ra_floor**2
            for m in range(M):
                um = db_u[m] if db_x.shape[0] > 0 else empty_u
                nu[m] = km._radalt(lay, X[m], ins[m, 0], ins[m, 1], ins[m, 2], radalt_h[m], tx, th, rwy, dbp[m],
                                   db_x, um, x0, False)
        r_ra = math.sqrt(s2) ** 2  # sigma^2 as nav/rows.py: sqrt((p h)^2 + floor^2) squared
        S_out[k] = _apply(X, P, h, r_ra, nu, b, kc)
        codes[k] = CODE_RADALT
        for m in range(M):
            nu_out[m, k] = nu[m]
        k += 1
    # GNSS channels
    i_gio = lay[ek.L_GIO]
    for c in range(rho.shape[1]):
        if rho[0, c] != rho[0, c]:
            continue
        sv = c if channel_states else -1
        if own:
            _ecef(ins[0], r_ins)
            gk.c_ecef_to_ned(ins[0, 0], ins[0, 1], c_ins)
            nu[0] = km._pseudorange(lay, X[0], r_ins, c_ins, r_sv[c], rho[0, c], sv, -1, h, True)
        else:
            km._pseudorange(lay, x0, r_ref, c_ref, r_sv[c], rho[0, c], sv, -1, h, True)
            for m in range(M):
                _ecef(ins[m], r_ins)
                gk.c_ecef_to_ned(ins[m, 0], ins[m, 1], c_ins)
                nu[m] = km._pseudorange(lay, X[m], r_ins, c_ins, r_sv[c], rho[m, c], sv, -1, x0, False)
        if i_gio >= 0 and sv >= 0:  # carrier phase: the code's ionosphere is the gio state, -1 in the row
            h[i_gio + c] = -1.0
            for m in range(M):
                nu[m] = nu[m] + X[m, i_gio + c]
        S_out[k] = _apply(X, P, h, sig[c] ** 2, nu, b, kc)
        codes[k] = CODE_GPS + c
        for m in range(M):
            nu_out[m, k] = nu[m]
        k += 1
    # GNSS carrier phases (kernels/carrier.py)
    for c in range(cp.shape[1]):
        if cp[0, c] != cp[0, c]:
            continue
        if own:
            _ecef(ins[0], r_ins)
            gk.c_ecef_to_ned(ins[0, 0], ins[0, 1], c_ins)
            nu[0] = kcar.carrier_phase(lay, X[0], r_ins, c_ins, r_sv[c], cp[0, c], c, h, True)
        else:
            kcar.carrier_phase(lay, x0, r_ref, c_ref, r_sv[c], cp[0, c], c, h, True)
            for m in range(M):
                _ecef(ins[m], r_ins)
                gk.c_ecef_to_ned(ins[m, 0], ins[m, 1], c_ins)
                nu[m] = kcar.carrier_phase(lay, X[m], r_ins, c_ins, r_sv[c], cp[m, c], c, x0, False)
        S_out[k] = _apply(X, P, h, cp_r, nu, b, kc)
        codes[k] = CODE_CP + c
        for m in range(M):
            nu_out[m, k] = nu[m]
        k += 1
    # pseudolites
    for c in range(pl_rho.shape[1]):
        if pl_rho[0, c] != pl_rho[0, c]:
            continue
        pl = c if pl_states else -1
        if own:
            _ecef(ins[0], r_ins)
            gk.c_ecef_to_ned(ins[0, 0], ins[0, 1], c_ins)
            nu[0] = km._pseudorange(lay, X[0], r_ins, c_ins, r_pl[c], pl_rho[0, c], -1, pl, h, True)
        else:
            km._pseudorange(lay, x0, r_ref, c_ref, r_pl[c], pl_rho[0, c], -1, pl, h, True)
            for m in range(M):
                _ecef(ins[m], r_ins)
                gk.c_ecef_to_ned(ins[m, 0], ins[m, 1], c_ins)
                nu[m] = km._pseudorange(lay, X[m], r_ins, c_ins, r_pl[c], pl_rho[m, c], -1, pl, x0, False)
        S_out[k] = _apply(X, P, h, pl_sig[c] ** 2, nu, b, kc)
        codes[k] = CODE_PL + c
        for m in range(M):
            nu_out[m, k] = nu[m]
        k += 1
    return k


@njit(cache=True)
def own_epoch(X: np.ndarray, P: np.ndarray, lay: np.ndarray, q: np.ndarray, gse: np.ndarray, gmp: np.ndarray,
              loop: np.ndarray, held: bool, dt: float, f_ned: np.ndarray, y: np.ndarray, F: np.ndarray,
              Qc: np.ndarray, phi: np.ndarray, qd: np.ndarray,
              baro_h: np.ndarray, baro_r: float,
              radalt_h: np.ndarray, ra_pct: float, ra_floor: float,
              tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
              db_u: np.ndarray,
              rho: np.ndarray, r_sv: np.ndarray, sig: np.ndarray, channel_states: bool,
              cp: np.ndarray, cp_r: float,
              pl_rho: np.ndarray, r_pl: np.ndarray, pl_sig: np.ndarray, pl_states: bool,
              gio: np.ndarray, gio_tau: float, new: np.ndarray, amb_prior: float,
              codes: np.ndarray, nu_out: np.ndarray, S_out: np.ndarray,
              h: np.ndarray, b: np.ndarray, ws: tuple) -> int:
    """The per-run EKF's whole epoch of one run: the error model linearized about its INS state y (16,) (packed,
    kernels/strapdown.py) with the interval's mean specific force f_ned (3,) NED m/s^2 (kernels.errormodel
    dynamics: lay, q, gse, gmp, loop, held as there; carrier phase: gio (n_sv,) m and gio_tau s, kernels.carrier),
    discretized over dt (s) into phi, qd (scratch F, Qc), the ambiguities of the channels with new[c] != 0 reset
    to amb_prior m^2 (kernels.carrier.reset_ambiguities; new (k,), empty without carrier phase), then class_epoch in
    own mode (X (1, n), the observation arguments as there). Returns the number of rows, or -1 when the model is
    too large for the compiled discretization (X, P untouched: the caller takes the numpy path)."""
    c_bn = y[6:15].reshape(3, 3)
    ek.dynamics(lay, q, gse, gmp, y[0], y[2], y[3:6], f_ned, c_bn, loop, held, F, Qc)
    kcar.dynamics(lay, gio, gio_tau, F, Qc)
    if not ek.discretize(F, Qc, dt, phi, qd):
        return -1
    kcar.reset_ambiguities(phi, qd, lay, new, amb_prior)
    return class_epoch(X, P, phi, qd, lay, True, y, y.reshape(1, 16), baro_h, baro_r, radalt_h, ra_pct, ra_floor,
                       0.0, tx, th, rwy, dbp, db_x, db_u, rho, r_sv, sig, channel_states, cp, cp_r, pl_rho, r_pl,
                       pl_sig, pl_states, codes, nu_out, S_out, h, b, ws)


@njit(cache=True)
def singleton_epochs(X: np.ndarray, P3: np.ndarray, phi2: np.ndarray, qd2: np.ndarray, held: np.ndarray,
                     ch_gse: np.ndarray, ch_gmp: np.ndarray, f_gse: float, f_gmp: float, qd_tmp: np.ndarray,
                     lay: np.ndarray, ref: np.ndarray, ref_agl: float, ins: np.ndarray,
                     baro_h: np.ndarray, baro_r: float,
                     radalt_h: np.ndarray, ra_pct: float, ra_floor: float,
                     tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
                     db_u: np.ndarray,
                     rho: np.ndarray, r_sv: np.ndarray, sig: np.ndarray, channel_states: bool,
                     cp: np.ndarray, cp_r: float,
                     pl_rho: np.ndarray, r_pl: np.ndarray, pl_sig: np.ndarray, pl_states: bool,
                     ch_gio: np.ndarray, f_gio: float, new: np.ndarray, amb_prior: float, phi_tmp: np.ndarray,
                     codes: np.ndarray, nu_out: np.ndarray, S_out: np.ndarray, n_rows: np.ndarray,
                     h: np.ndarray, b: np.ndarray, ws: tuple) -> None:
    """class_epoch in shared mode for N runs that are each their own class (per-run GPS skies, the integrity bank's
    copies): run i with X[i], P3[i] (its covariance), the model phi2[held[i]], qd2[held[i]] (the damping loop held
    or not) whose GPS channel states' Qd entries are sigma^2 (1 - exp(-2 dt / tau)) at run i's elevations
    (ch_gse, ch_gmp (N, k) sigmas, m; f_gse, f_gmp the factors; nothing changed when k = 0), its INS ins[i] and
    observations row i of every per-run array (r_sv (N, s, 3), sig (N, s), cp (N, s)); the rows at the reference
    ref (16,) as class_epoch. Carrier phase: the gio states' Qd entries likewise from ch_gio (N, k) and f_gio, and
    run i's ambiguities with new[i, c] != 0 reset to amb_prior (in phi_tmp (n, n), a copy of its Phi, when it has
    one; new (N, 0) and ch_gio (N, 0) without carrier phase). Out per run: codes[i], nu_out[i], S_out[i] (R,) and
    n_rows[i]."""
    N = X.shape[0]
    ig, im, io = lay[ek.L_GSE], lay[ek.L_GMP], lay[ek.L_GIO]
    last = -1  # the model (held) whose Qd is in qd_tmp and whose Phi's nonzeros are in ws (model reuse)
    for i in range(N):
        hd = held[i]
        if last != hd:
            qd_tmp[:, :] = qd2[hd]
        if ig >= 0:
            for c in range(ch_gse.shape[1]):
                qd_tmp[ig + c, ig + c] = ch_gse[i, c] ** 2 * f_gse
                qd_tmp[im + c, im + c] = ch_gmp[i, c] ** 2 * f_gmp
        if io >= 0:
            for c in range(ch_gio.shape[1]):
                qd_tmp[io + c, io + c] = ch_gio[i, c] ** 2 * f_gio
        reset = _any_new(new[i])
        ready = last == hd and not reset
        phi = _with_resets(phi2[hd], qd_tmp, lay, new[i], amb_prior, phi_tmp)
        n_rows[i] = class_epoch(X[i:i + 1], P3[i], phi, qd_tmp, lay, False, ref, ins[i:i + 1],
                                baro_h[i:i + 1], baro_r, radalt_h[i:i + 1], ra_pct, ra_floor, ref_agl, tx, th, rwy,
                                dbp[i:i + 1], db_x, db_u[i:i + 1], rho[i:i + 1], r_sv[i], sig[i], channel_states,
                                cp[i:i + 1], cp_r, pl_rho[i:i + 1], r_pl, pl_sig, pl_states, codes[i],
                                nu_out[i:i + 1], S_out[i], h, b, ws, ready)
        last = -1 if reset else hd


@njit(cache=True)
def _any_new(new: np.ndarray) -> bool:
    """Whether any channel of new (k,) begins a carrier arc (_with_resets then changes Phi and Qd)."""
    for c in range(new.shape[0]):
        if new[c] != 0:
            return True
    return False


# Model reuse. The copies' loops (singleton_epochs, shared_pass, copies.bank_epochs_carrier) give class_epoch one
# model after another, mostly the same: a copy's Qd differs from the model's only on the channel states' diagonal,
# which every copy writes, and its Phi is the model's unless its carrier arcs reset ambiguities. So qd_tmp is copied
# from the model, and Phi's nonzeros collected (class_epoch's csr_ready), only when the model changed or the
# previous copy reset (its resets changed qd_tmp, and ws holds the reset Phi's nonzeros): the same arrays as a fresh
# copy each time, so the same numbers.


@njit(cache=True)
def _with_resets(phi: np.ndarray, qd: np.ndarray, lay: np.ndarray, new: np.ndarray, prior: float,
                 phi_tmp: np.ndarray) -> np.ndarray:
    """phi itself when no channel of new (k,) begins an arc, else phi_tmp holding phi with those ambiguities reset
    (kernels.carrier.reset_ambiguities; qd, the caller's own copy, is reset in place)."""
    for c in range(new.shape[0]):
        if new[c] != 0:
            phi_tmp[:, :] = phi
            kcar.reset_ambiguities(phi_tmp, qd, lay, new, prior)
            return phi_tmp
    return phi


@njit(cache=True)
def shared_pass(X: np.ndarray, P3: np.ndarray, lay: np.ndarray, q: np.ndarray, gse: np.ndarray, gmp: np.ndarray,
                loop: np.ndarray, dt: np.ndarray, ref: np.ndarray, ref_cbn: np.ndarray, f_ref: np.ndarray,
                ref_agl: np.ndarray, held: np.ndarray, ch_gse: np.ndarray, ch_gmp: np.ndarray, f_gse: np.ndarray,
                f_gmp: np.ndarray, ins: np.ndarray,
                baro_h: np.ndarray, baro_r: np.ndarray,
                radalt_h: np.ndarray, ra_pct: float, ra_floor: float,
                tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
                db_u: np.ndarray,
                rho: np.ndarray, r_sv: np.ndarray, sig: np.ndarray, channel_states: bool,
                cp: np.ndarray, cp_r: float,
                pl_rho: np.ndarray, r_pl: np.ndarray, pl_sig: np.ndarray, pl_states: bool,
                gio: np.ndarray, gio_tau: float, ch_gio: np.ndarray, f_gio: np.ndarray, new: np.ndarray,
                amb_prior: float,
                codes: np.ndarray, nu_out: np.ndarray, S_out: np.ndarray, n_rows: np.ndarray,
                x_out: np.ndarray, p33_out: np.ndarray, pcc_out: np.ndarray, pd_out: np.ndarray,
                pnav_out: np.ndarray, ic: int, h: np.ndarray, b: np.ndarray, ws: tuple) -> int:
    """The whole open-loop pass of N runs that are each their own shared-covariance class (per-run GPS skies, the
    integrity bank's copies): E epochs of singleton_epochs in one call, the model along the reference made here.

    Per epoch e: F, Qc = kernels.errormodel.dynamics at the reference (ref (E, 16) packed truth rows, ref_cbn (E, 3,
    3), f_ref (E, 3) the interval's mean specific force NED m/s^2; lay, q, gse, gmp, loop the model's arrays), without
    and (when a run's damping loop held: held (N, E) int) with the loop held; Phi, Qd over dt[e] (s) by Van Loan; then
    every run i as singleton_epochs (ch_gse, ch_gmp (N, E, k) its channel sigmas, f_gse, f_gmp (E,) their factors;
    ins (N, E, 16) its INS at the epoch; the observations indexed [i, e]: baro_h (N, E) with baro_r (E,) m^2, radalt_h
    (N, E), rho (N, E, s), r_sv (N, E, s, 3), sig (N, E, s), pl_rho (N, E, p), pl_sig (E, p); ref_agl (E,) m; db
    per run). Carrier phase (kernels/carrier.py; empty arrays without): the gio states in the model (gio (n_sv,) m,
    gio_tau s) with their Qd entries at run i's sky from ch_gio (N, E, k) and f_gio (E,), cp (N, E, s) the carrier
    phases with variance cp_r m^2, and run i's ambiguities with new[i, e, c] != 0 reset to amb_prior m^2. Out per
    run and epoch: codes, nu_out, S_out (N, E, R), n_rows (N, E), and after the epoch's updates x_out (N, E, n),
    p33_out (N, E, 3, 3), pcc_out (N, E) (P[ic, ic]), pd_out (N, E, n), pnav_out (N, E, 9, 9). Returns -1 - e when
    epoch e's model is too large for the compiled discretization (nothing of epoch e done), else E."""
    N, n = X.shape
    E = dt.shape[0]
    F = np.empty((n, n))
    Qc = np.empty((n, n))
    phi2 = np.empty((2, n, n))
    qd2 = np.empty((2, n, n))
    qd_tmp = np.empty((n, n))
    phi_tmp = np.empty((n, n))
    ig, im, io = lay[ek.L_GSE], lay[ek.L_GMP], lay[ek.L_GIO]
    for e in range(E):
        y = ref[e]
        any_held = False
        for i in range(N):
            if held[i, e] != 0:
                any_held = True
        for hd in range(2):
            if hd == 1 and not any_held:
                break
            ek.dynamics(lay, q, gse, gmp, y[0], y[2], y[3:6], f_ref[e], ref_cbn[e], loop, hd == 1, F, Qc)
            kcar.dynamics(lay, gio, gio_tau, F, Qc)
            if not ek.discretize(F, Qc, dt[e], phi2[hd], qd2[hd]):
                return -1 - e
        last = -1  # model reuse (above _with_resets), within the epoch: its models are new
        for i in range(N):
            hd = held[i, e]
            if last != hd:
                qd_tmp[:, :] = qd2[hd]
            if ig >= 0:
                for c in range(ch_gse.shape[2]):
                    qd_tmp[ig + c, ig + c] = ch_gse[i, e, c] ** 2 * f_gse[e]
                    qd_tmp[im + c, im + c] = ch_gmp[i, e, c] ** 2 * f_gmp[e]
            if io >= 0:
                for c in range(ch_gio.shape[2]):
                    qd_tmp[io + c, io + c] = ch_gio[i, e, c] ** 2 * f_gio[e]
            reset = _any_new(new[i, e])
            ready = last == hd and not reset
            phi = _with_resets(phi2[hd], qd_tmp, lay, new[i, e], amb_prior, phi_tmp)
            P = P3[i]
            n_rows[i, e] = class_epoch(X[i:i + 1], P, phi, qd_tmp, lay, False, y, ins[i, e:e + 1],
                                       baro_h[i, e:e + 1], baro_r[e], radalt_h[i, e:e + 1], ra_pct, ra_floor,
                                       ref_agl[e], tx, th, rwy, dbp[i:i + 1], db_x, db_u[i:i + 1], rho[i, e:e + 1],
                                       r_sv[i, e], sig[i, e], channel_states, cp[i, e:e + 1], cp_r,
                                       pl_rho[i, e:e + 1], r_pl, pl_sig[e], pl_states, codes[i, e],
                                       nu_out[i, e:e + 1], S_out[i, e], h, b, ws, ready)
            last = -1 if reset else hd
            for a in range(n):
                x_out[i, e, a] = X[i, a]
                pd_out[i, e, a] = P[a, a]
            for a in range(3):
                for c in range(3):
                    p33_out[i, e, a, c] = P[a, c]
            for a in range(9):
                for c in range(9):
                    pnav_out[i, e, a, c] = P[a, c]
            pcc_out[i, e] = P[ic, ic]
    return E
