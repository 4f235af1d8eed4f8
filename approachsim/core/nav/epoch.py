"""One aiding epoch of the optimal filter as one compiled call (numba, cache=True): the prediction and every
scalar update of the epoch, for one run, for the runs of a shared-covariance class, or for N copies each its own
class; and the whole open-loop pass of such copies. Arguments grouped by what they are (core/nav/groups.py: the
rows' constants, the observations, the outputs, the error model, the scratch).

    n_rows = class_epoch(X, P, phi, qd, own, ref, ins, rows, obs, out, scr)
    n_rows = run_epoch(X, P, model, y, f_ned, held, dt, new, rows, obs, out, scr)    the per-run EKF's whole epoch
    copies_epoch(X, P3, phi_h, qd_h, which, ref, ins, chan, obs, new, rows, out, n_rows, scr)   N copies, one epoch
    shared_pass(X, P3, model, track, held, chan, ins, obs, new, rows, out, scr)     N copies, every epoch

Order of the rows (nav/rows.py): baro, radar altimeter, each GNSS channel in channel order, each channel's
carrier phase (carrier phase only), each pseudolite in unit order; a row exists when member 0's value is finite
(a class shares one schedule: nav/shared.py).

    predict    x_m <- Phi x_m (each member),  P <- Phi P Phi' + Qd                      (core/nav/kalman.py)
    each row   own (one run, the per-run EKF): h and nu = z - g(x_hat) at the run's own INS and current x_hat
               (sequential relinearization, as nav/navigator.py's per-run filters);
               shared (M runs): h and r at the reference trajectory `ref` with x_hat = 0 (the truth: nav/shared.py),
               nu_m of each member at its own INS and current x_hat_m
               S = h' P h + r ; K = P h / S ; x_m <- x_m + K nu_m ; P Joseph (O(n^2), core/nav/kalman.py)

Rows and innovations are core/nav/measurements.py's. The numpy paths (nav/navigator.py with nav/rows.py, and
nav/shared.py) are the test oracle (tests/unit/nav/test_epoch_engine.py: equal to 1e-12 relative norm-wise).

Codes of the rows written to `codes`: CODE_BARO, CODE_RADALT, CODE_GPS + channel, CODE_PL + unit, CODE_CP + channel
(a GNSS channel's carrier phase).

Carrier phase (the layout's gio and amb groups, core/nav/carrier.py): the code rows carry -1 at the channel's gio;
after every code row, each channel's carrier-phase row (nav/rows.py's order); the float ambiguities of the channels
whose arc began are reset in the epoch's Phi, Qd before the prediction (run_epoch, copies_epoch; class_epoch's
caller otherwise).

A copy's epoch (copies_epoch, and so shared_pass and core/nav/copies.bank_epochs): its model's Qd with the channel
states' entries at its own sky, its ambiguities reset at its new arcs, then class_epoch in shared mode.
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.core import geodesy as gk
from approachsim.core.jit import njit
from approachsim.core.nav import carrier as kcar
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav import kalman as kk
from approachsim.core.nav import measurements as km
from approachsim.core.nav.groups import ChannelQd, ErrorModel, Obs, Out, PassOut, Rows, Scratch, Track

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
def _update(X: np.ndarray, P: np.ndarray, h: np.ndarray, r: float, nu: np.ndarray, code: int, k: int, out: Out,
            b: np.ndarray, kc: np.ndarray) -> int:
    """The row h with noise variance r (m^2) applied to the members (`_apply`), recorded as row k of out (its code,
    the members' nu, S); returns k + 1."""
    out.S[k] = _apply(X, P, h, r, nu, b, kc)
    out.codes[k] = code
    for m in range(X.shape[0]):
        out.nu[m, k] = nu[m]
    return k + 1


@njit(cache=True)
def class_epoch(X: np.ndarray, P: np.ndarray, phi: np.ndarray, qd: np.ndarray, own: bool, ref: np.ndarray,
                ins: np.ndarray, rows: Rows, obs: Obs, out: Out, scr: Scratch, csr_ready: bool = False,
                x_ready: bool = False) -> int:
    """Predict and update the M members of a class in place (module docstring); returns the number of rows.

    X (M, n) estimates; P (n, n) the class covariance; phi, qd (n, n) the epoch's model; own: the per-run EKF
    (M = 1; ref unused) else shared rows at `ref`; ref (16,), ins (M, 16) packed INS states (core/nav/strapdown
    layout). rows: the rows' constants; obs: the members' observations (groups.Obs: the radar altimeter's sigma
    sqrt((ra_pct h)^2 + ra_floor^2) at the measured height (own) or at obs.ref_agl (shared)); out: codes (R,),
    nu (M, R), S (R,); scr: h, b, ws. csr_ready: scr.ws already holds phi's nonzeros (kalman.csr; the caller's
    previous class_epoch had this same phi), so they are not collected again (the same numbers either way).
    x_ready: X holds the members' predictions already (the per-run EKF's mean by its own model,
    core/nav/errormodel.predict_mean): phi predicts P only.
    """
    M = X.shape[0]
    n = X.shape[1]
    lay, h, b = rows.lay, scr.h, scr.b
    W, v, val, ptr, col = scr.ws
    kc = v
    # predict: x_m <- Phi x_m ; P <- Phi P Phi' + Qd
    if not csr_ready:
        kk.csr(phi, ptr, col, val)
    for m in range(M if not x_ready else 0):
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
    _ecef(ref[::1], r_ref)  # strided as ins[m] is: _ecef compiles once
    gk.c_ecef_to_ned(ref[0], ref[1], c_ref)
    k = 0
    empty_u = np.zeros(0)
    # baro
    baro_h = obs.baro_h
    if baro_h[0] == baro_h[0]:
        if own:
            nu[0], _ = km.baro(lay, X[0], ins[0, 2], baro_h[0], 0.0, h, rows.baro_ref)
        else:
            if lay[ek.L_SB] >= 0:  # the row at the reference's scale factor (the day's: obs.ref_sb)
                x0[lay[ek.L_SB]] = obs.ref_sb
            km.baro(lay, x0, ref[2], baro_h[0], 0.0, h, rows.baro_ref)
            if lay[ek.L_SB] >= 0:
                x0[lay[ek.L_SB]] = 0.0
            for m in range(M):
                nu[m] = km.baro_nu(lay, X[m], ins[m, 2], baro_h[m], rows.baro_ref)
        k = _update(X, P, h, obs.baro_r, nu, CODE_BARO, k, out, b, kc)
    # radar altimeter
    radalt_h, db_x, db_u = obs.radalt_h, obs.db_x, obs.db_u
    tx, th, rwy, dbp = rows.tx, rows.th, rows.rwy, obs.dbp
    if radalt_h[0] == radalt_h[0]:
        u0 = db_u[0] if db_x.shape[0] > 0 else empty_u
        if own:
            hr = radalt_h[0]
            nu[0], _ = km.radalt(lay, X[0], ins[0, 0], ins[0, 1], ins[0, 2], hr, 0.0, tx, th, rwy, dbp[0], db_x, u0,
                                 h)
            s2 = (rows.ra_pct * hr) ** 2 + rows.ra_floor**2
        else:  # the row at the reference (no database error: it enters only z), sigma at the reference height
            km.radalt(lay, x0, ref[0], ref[1], ref[2], obs.ref_agl, 0.0, tx, th, rwy, dbp[0], empty_u, empty_u, h)
            s2 = (rows.ra_pct * obs.ref_agl) ** 2 + rows.ra_floor**2
            for m in range(M):
                um = db_u[m] if db_x.shape[0] > 0 else empty_u
                nu[m] = km._radalt(lay, X[m], ins[m, 0], ins[m, 1], ins[m, 2], radalt_h[m], tx, th, rwy, dbp[m],
                                   db_x, um, x0, False)
        r_ra = math.sqrt(s2) ** 2  # sigma^2 as nav/rows.py: sqrt((p h)^2 + floor^2) squared
        k = _update(X, P, h, r_ra, nu, CODE_RADALT, k, out, b, kc)
    # GNSS channels. Each range row's own and shared forms are written out here, not in a helper: a helper with the
    # members' loop measured 3 us (8 %) slower per shared class epoch (in four forms; benchmarks in the commit).
    rho, r_sv, cp = obs.rho, obs.r_sv, obs.cp
    i_gio = lay[ek.L_GIO]
    for c in range(rho.shape[1]):
        if rho[0, c] != rho[0, c]:
            continue
        sv = c if rows.channel_states else -1
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
        k = _update(X, P, h, obs.sig[c] ** 2, nu, CODE_GPS + c, k, out, b, kc)
    # GNSS carrier phases (core/nav/carrier.py)
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
        k = _update(X, P, h, rows.cp_r, nu, CODE_CP + c, k, out, b, kc)
    # pseudolites
    pl_rho, r_pl = obs.pl_rho, obs.r_pl
    for c in range(pl_rho.shape[1]):
        if pl_rho[0, c] != pl_rho[0, c]:
            continue
        pl = c if rows.pl_states else -1
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
        k = _update(X, P, h, obs.pl_sig[c] ** 2, nu, CODE_PL + c, k, out, b, kc)
    return k


# run_epoch, copies_epoch and pass_epoch are thin wrappers, inlined into their compiled callers (inline="always",
# numba IR): as functions of their own each was compiled, and its whole callee tree optimized by LLVM, once more
# (about 8 s of CPU on a cold cache, core/warm.py); the arithmetic is the same, tools/*_identity.py bit for bit.
@njit(cache=True, inline="always")
def run_epoch(X: np.ndarray, P: np.ndarray, model: ErrorModel, y: np.ndarray, f_ned: np.ndarray, held: bool,
              dt: float, new: np.ndarray, rows: Rows, obs: Obs, out: Out, scr: Scratch) -> int:
    """The per-run EKF's whole epoch of one run: the error model (core/nav/errormodel.dynamics, core/nav/carrier.
    dynamics: model's constants) linearized about its INS state y (16,) (packed, core/nav/strapdown.py; with a baro
    scale-factor state at the navigation's height y[2] + X[0, dp_D], with the loop at the interval's midpoint and
    dp_D moved to its end, core/nav/errormodel.end_height) with the
    interval's mean specific force f_ned (3,) NED m/s^2 and the damping loop held or not, discretized over dt (s)
    into scr.phi, scr.qd (scratch scr.F, scr.Qc), the ambiguities of the channels with new[c] != 0 reset to
    rows.amb_prior m^2 (core/nav/carrier.reset_ambiguities; new (k,), empty without carrier phase), then
    class_epoch in own mode (X (1, n)). With a baro scale-factor state and the loop on, Phi, Qd are the EKF's
    Jacobian's and the estimate is predicted by its own model (core/nav/errormodel.loop_jacobian, predict_mean);
    scr.F is the estimate's model. Returns the number of rows, or -1 when the model is too large for the
    compiled discretization (X, P untouched: the caller takes the numpy path)."""
    F, Qc, phi, qd = scr.F, scr.Qc, scr.phi, scr.qd
    lay = model.lay
    c_bn = y[6:15].reshape(3, 3)
    h_lin = y[2]
    if lay[ek.L_SB] >= 0:  # the loop's sb coefficient at the navigation's height, with the loop the interval's
        h_nav = y[2] + X[0, lay[ek.L_DP] + 2]  # midpoint (nav/errormodel.linear_height): navigation = INS less the
        v_nav = y[5] - X[0, lay[ek.L_DV] + 2]  # estimate, its dp_D moved to the interval's end (ek.end_height)
        if lay[ek.L_AC] >= 0:
            ek.dynamics(lay, model.q, model.gse, model.gmp, y[0], ek.interval_height(lay, h_nav, v_nav, dt), y[3:6],
                        f_ned, c_bn, model.loop, held, F, Qc)
            h_nav = ek.end_height(lay, F, X[0], h_nav, dt)
        h_lin = ek.interval_height(lay, h_nav, v_nav, dt)
    ek.dynamics(lay, model.q, model.gse, model.gmp, y[0], h_lin, y[3:6], f_ned, c_bn, model.loop, held, F, Qc)
    kcar.dynamics(lay, model.gio, model.gio_tau, F, Qc)
    keep = np.empty(3)  # the covariance by the Jacobian, the estimate by its own model (ek.loop_jacobian)
    jac = ek.loop_jacobian(lay, model.loop, held, X[0, lay[ek.L_SB]] if lay[ek.L_SB] >= 0 else 0.0, F, keep)
    ok = ek.discretize(F, Qc, dt, phi, qd)
    if jac:
        ek.loop_mean(lay, keep, F)  # scr.F: the interval's model of the estimate (its rate, core/nav/output.py)
    if not ok:
        return -1
    ek.scale_channels(phi, lay[ek.L_GSE], model.gse_r)
    ek.scale_channels(phi, lay[ek.L_GIO], model.gio_r)
    kcar.reset_ambiguities(phi, qd, lay, new, rows.amb_prior)
    if jac:
        ek.predict_mean(F, phi, X[0], dt)
    return class_epoch(X, P, phi, qd, True, y, _any(y.reshape(1, 16)), rows, _any_obs(obs), _any_out(out), scr,
                       False, jac)


# One compilation of class_epoch. The bank's copies (copies_epoch) hand it the per-copy rows of their (N, E) pass
# arrays, which numba types as strided ('A' layout); the per-run epoch's own arrays are contiguous ('C'). Numba
# compiles a kernel once per argument type, so class_epoch's tree (about 3-4 s of CPU on a cold cache) was typed
# and lowered twice. A slice with an explicit step (`a[::1]`) is typed 'A' whatever it views, so run_epoch passes
# its arrays in the copies' types: the same elements, the same loops, the same bits (tools/*_identity.py).
@njit(cache=True, inline="always")
def _any(a: np.ndarray) -> np.ndarray:
    """A 2-D array as the strided ('A') view of the same elements."""
    return a[:, ::1]


@njit(cache=True, inline="always")
def _any_obs(obs: Obs) -> Obs:
    """obs with the per-member arrays as copies_epoch types them (strided views of the same elements)."""
    return Obs(obs.baro_h[::1], obs.baro_r, obs.radalt_h[::1], obs.ref_agl, obs.ref_sb, obs.dbp, obs.db_x, obs.db_u,
               obs.rho[:, ::1], obs.r_sv[:, ::1], obs.sig[::1], obs.cp[:, ::1], obs.pl_rho[:, ::1], obs.r_pl[:, ::1],
               obs.pl_sig)


@njit(cache=True, inline="always")
def _any_out(out: Out) -> Out:
    """out as copies_epoch types it (strided views of the same arrays: class_epoch writes through them)."""
    return Out(out.codes[::1], out.nu[:, ::1], out.S[::1])


@njit(cache=True)
def _any_new(new: np.ndarray) -> bool:
    """Whether any channel of new (k,) begins a carrier arc (_with_resets then changes Phi and Qd)."""
    for c in range(new.shape[0]):
        if new[c] != 0:
            return True
    return False


# Model reuse. The copies' loop (copies_epoch) gives class_epoch one model after another, mostly the same: a copy's
# Qd differs from the model's only on the channel states' diagonal, which every copy writes, and its Phi is the
# model's unless its carrier arcs reset ambiguities. So qd_tmp is copied from the model, and Phi's nonzeros
# collected (class_epoch's csr_ready), only when the model changed or the previous copy reset (its resets changed
# qd_tmp, and ws holds the reset Phi's nonzeros): the same arrays as a fresh copy each time, so the same numbers.


@njit(cache=True)
def _with_resets(phi: np.ndarray, qd: np.ndarray, lay: np.ndarray, new: np.ndarray, prior: float,
                 phi_tmp: np.ndarray) -> np.ndarray:
    """phi itself when no channel of new (k,) begins an arc, else phi_tmp holding phi with those ambiguities reset
    (core/nav/carrier.reset_ambiguities; qd, the caller's own copy, is reset in place)."""
    for c in range(new.shape[0]):
        if new[c] != 0:
            kk.copy_2d(phi_tmp, phi)
            kcar.reset_ambiguities(phi_tmp, qd, lay, new, prior)
            return phi_tmp
    return phi


@njit(cache=True, inline="always")
def _scale_states(x: np.ndarray, P: np.ndarray, ig: int, r: np.ndarray) -> None:
    """x (n,) and P (n, n) of one copy, in place, with the slow channel states' scale r (k,) (ChannelQd.gse_r):
    x <- D x, P <- D P D, D = 1 but r[c] at gse_c (Phi D = D Phi: the predict then is errormodel.scale_channels's
    D Phi)."""
    n = P.shape[0]
    for c in range(r.shape[0]):
        a = ig + c
        x[a] = x[a] * r[c]
        for j in range(n):
            P[a, j] = P[a, j] * r[c]
        for j in range(n):
            P[j, a] = P[j, a] * r[c]


@njit(cache=True, inline="always")
def copies_epoch(X: np.ndarray, P3: np.ndarray, phi_h: np.ndarray, qd_h: np.ndarray, which: np.ndarray,
                 ref: np.ndarray, ins: np.ndarray, chan: ChannelQd, obs: Obs, new: np.ndarray, rows: Rows, out: Out,
                 n_rows: np.ndarray, scr: Scratch) -> None:
    """One epoch of N copies that are each their own shared-covariance class (per-run GPS skies, the integrity bank's
    copies): copy i with X[i], P3[i] (its covariance) on the model phi_h[which[i]], qd_h[which[i]] (H, n, n) (the
    damping loop held or not, or the epoch's one model), whose GPS channel states' Qd entries are set at copy i's
    sky (chan: sigmas (N, k), factors scalars; nothing changed when k = 0) and whose ambiguities with new[i, c] != 0
    are reset to rows.amb_prior (in scr.phi_tmp, a copy of its Phi, when it has one; new (N, 0) without carrier
    phase); its INS ins[i] (16,) and its row i of every per-copy observation (obs.r_sv (N, s, 3), obs.sig (N, s));
    then class_epoch in shared mode at the reference ref (16,). Out per copy: out.codes[i], out.nu[i], out.S[i]
    (R,) and n_rows[i]. The Qd is built in scr.qd."""
    N = X.shape[0]
    lay, qd_tmp = rows.lay, scr.qd
    ig, im, io = lay[ek.L_GSE], lay[ek.L_GMP], lay[ek.L_GIO]
    last = -1  # the model whose Qd is in qd_tmp and whose Phi's nonzeros are in ws (model reuse)
    for i in range(N):
        hd = which[i]
        if last != hd:
            kk.copy_2d(qd_tmp, qd_h[hd])
        if ig >= 0:
            for c in range(chan.gse.shape[1]):
                qd_tmp[ig + c, ig + c] = chan.gse[i, c] ** 2 * chan.f_gse
                qd_tmp[im + c, im + c] = chan.gmp[i, c] ** 2 * chan.f_gmp
        if io >= 0:
            for c in range(chan.gio.shape[1]):
                qd_tmp[io + c, io + c] = chan.gio[i, c] ** 2 * chan.f_gio
        if chan.gse_r.shape[1] > 0:
            _scale_states(X[i], P3[i], ig, chan.gse_r[i])
        if chan.gio_r.shape[1] > 0:
            _scale_states(X[i], P3[i], io, chan.gio_r[i])
        reset = _any_new(new[i])
        ready = last == hd and not reset
        phi = _with_resets(phi_h[hd], qd_tmp, lay, new[i], rows.amb_prior, scr.phi_tmp)
        obs_i = Obs(obs.baro_h[i:i + 1], obs.baro_r, obs.radalt_h[i:i + 1], obs.ref_agl, obs.ref_sb, obs.dbp[i:i + 1],
                    obs.db_x,
                    obs.db_u[i:i + 1], obs.rho[i:i + 1], obs.r_sv[i], obs.sig[i], obs.cp[i:i + 1],
                    obs.pl_rho[i:i + 1], _any(obs.r_pl), obs.pl_sig)
        n_rows[i] = class_epoch(X[i:i + 1], P3[i], phi, qd_tmp, False, ref, ins[i:i + 1], rows, obs_i,
                                Out(out.codes[i], out.nu[i:i + 1], out.S[i]), scr, ready)
        last = -1 if reset else hd


@njit(cache=True, inline="always")
def pass_epoch(X: np.ndarray, P3: np.ndarray, phi_h: np.ndarray, qd_h: np.ndarray, which: np.ndarray,
               ref: np.ndarray, ins: np.ndarray, chan: ChannelQd, obs: Obs, new: np.ndarray, rows: Rows,
               out: PassOut, e: int, scr: Scratch) -> None:
    """Epoch e of a pass (shared_pass, core/nav/copies.bank_epochs): copies_epoch on the pass's arrays at e (chan,
    obs, new, ins and which with their (N, E) axes, chan's factors and obs's baro_r, ref_agl, pl_sig (E,)), then
    every copy's estimate and covariance after the epoch into out[:, e] (x, pd, pnav; p33 and pcc when kept)."""
    copies_epoch(X, P3, phi_h, qd_h, which[:, e], ref, ins[:, e],
                 ChannelQd(chan.gse[:, e], chan.gmp[:, e], chan.gio[:, e], chan.f_gse[e], chan.f_gmp[e],
                           chan.f_gio[e], chan.gse_r[:, e], chan.gio_r[:, e]),
                 Obs(obs.baro_h[:, e], obs.baro_r[e], obs.radalt_h[:, e], obs.ref_agl[e], obs.ref_sb, obs.dbp,
                     obs.db_x, obs.db_u,
                     obs.rho[:, e], obs.r_sv[:, e], obs.sig[:, e], obs.cp[:, e], obs.pl_rho[:, e], obs.r_pl,
                     obs.pl_sig[e]),
                 new[:, e], rows, Out(out.codes[:, e], out.nu[:, e], out.S[:, e]), out.n_rows[:, e], scr)
    n = X.shape[1]
    for i in range(X.shape[0]):
        P = P3[i]
        for a in range(n):
            out.x[i, e, a] = X[i, a]
            out.pd[i, e, a] = P[a, a]
        if out.p33.shape[2] > 0:
            for a in range(3):
                for c in range(3):
                    out.p33[i, e, a, c] = P[a, c]
        for a in range(9):
            for c in range(9):
                out.pnav[i, e, a, c] = P[a, c]
        if out.pcc.shape[1] > 0:
            out.pcc[i, e] = P[out.ic, out.ic]


@njit(cache=True)
def shared_pass(X: np.ndarray, P3: np.ndarray, model: ErrorModel, track: Track, held: np.ndarray, chan: ChannelQd,
                ins: np.ndarray, obs: Obs, new: np.ndarray, rows: Rows, out: PassOut, scr: Scratch) -> int:
    """The whole open-loop pass of N runs that are each their own shared-covariance class (per-run GPS skies, the
    integrity bank's copies): E epochs of copies_epoch in one call, the model along the reference made here.

    Per epoch e: F, Qc = core/nav/errormodel.dynamics and core/nav/carrier.dynamics at the reference (track: ref[e],
    ref_cbn[e], f_ref[e]; model's constants) without and (when a run's damping loop held: held (N, E) int) with the
    loop held; Phi, Qd over track.dt[e] by Van Loan; then pass_epoch: every run i as copies_epoch (chan (N, E, k)
    its channel sigmas, factors (E,); ins (N, E, 16) its INS at the epoch; obs indexed [i, e], obs.baro_r,
    obs.ref_agl, obs.pl_sig per epoch; new (N, E, k) its new carrier arcs), and its estimate and covariance after
    the epoch into out. Returns -1 - e when epoch e's model is too large for the compiled discretization (nothing of
    epoch e done), else E."""
    n = X.shape[1]
    E = track.dt.shape[0]
    phi2 = np.empty((2, n, n))
    qd2 = np.empty((2, n, n))
    for e in range(E):
        y = track.ref[e]
        any_held = False
        for i in range(held.shape[0]):
            if held[i, e] != 0:
                any_held = True
        for hd in range(2):
            if hd == 1 and not any_held:
                break
            ek.dynamics(model.lay, model.q, model.gse, model.gmp, y[0],
                        ek.interval_height(model.lay, y[2], y[5], track.dt[e]), y[3:6], track.f_ref[e],
                        track.ref_cbn[e], model.loop, hd == 1, scr.F, scr.Qc)
            kcar.dynamics(model.lay, model.gio, model.gio_tau, scr.F, scr.Qc)
            if not ek.discretize(scr.F, scr.Qc, track.dt[e], phi2[hd], qd2[hd]):
                return -1 - e
        pass_epoch(X, P3, phi2, qd2, held, y, ins, chan, obs, new, rows, out, e, scr)
    return E
