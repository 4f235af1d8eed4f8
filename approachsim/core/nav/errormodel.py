"""Compiled INS error model (numba, cache=True): the continuous dynamics F, G Q G' of nav/errormodel.py's
`dynamics_reference` (its module docstring gives the equations) filled from plain arrays, and their
discretization Phi, Qd over the aiding interval (`discretize_reference`).

Inputs as plain arrays (nav/errormodel.py builds them once per frozen StateLayout / ErrorNoise object):

    lay (LAY_SIZE,) int64    lay[L_n] the state count, lay[L_<group>] the group's first index (-1: absent),
                             lay[L_NSV], lay[L_NPL] the GPS channels and pseudolites with their own states
    q (Q_SIZE,) float64      the scalar noise strengths and correlation times of errormodel.ErrorNoise (SI),
                             at the indices Q_*
    gse_sigma, gmp_sigma (n_sv,)  per-channel slow range error and multipath 1-sigma, m
    loop (LOOP_SIZE,)        (present 1/0, C1, C2, C3): the damping loop's linearized gains (vertical_loop)

Discretization (Van Loan 1978): with M = [[-F, Qc], [0, F']] dt, expm(M) = [[Phi^-1, Phi^-1 Qd], [0, Phi']].
States that are decoupled (their F, Qc rows and columns zero off the diagonal) are discretized in closed form,
Phi = exp(a dt), Qd = q (exp(2 a dt) - 1) / (2 a) (q dt when a = 0); the coupled rest, one connected component
at a time, by the scaling and squaring of errormodel._expm: an 8th-order Taylor series of expm(M dt / 2^s),
s = max(0, ceil(log2(|M|_1 / 0.25))), then s squarings. The squarings are done on the blocks that matter: with
E(t) = [[Phi(t)^-1, Phi(t)^-1 Qd(t)], [0, Phi(t)']], squaring E(t) is

    Phi(2t) = Phi(t)^2 ,  Qd(2t) = Phi(t) Qd(t) Phi(t)' + Qd(t)

(the (1, 2) block of E(t)^2 is Phi^-2 Qd + Phi^-1 Qd Phi' = Phi(2t)^-1 Qd(2t)), which needs neither the
(1, 1) block nor the inverse. Products skip the zero entries of Phi (its rows of random walks and driving
Markov states are a single diagonal entry), which does not change a sum.
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.core import geodesy as gk
from approachsim.core.jit import njit
from approachsim.core.nav import kalman as kk

L_N, L_DP, L_DV, L_PSI, L_BG, L_BA, L_BB, L_SB, L_CLK, L_AC = range(10)
L_GSE, L_GMP, L_PMP, L_PTR, L_PCLK, L_RAB, L_RAM, L_TDB, L_NSV, L_NPL = range(10, 20)
L_GIO, L_AMB = 20, 21
"""The carrier-phase groups' first index (-1 absent): after every other group (kernels/carrier.py)."""
L_PSY = 22
"""The synchronized pseudolites' time-sync error group psy (-1 absent)."""
L_GIZ = 23
"""The zenith ionospheric states giz (3: the field's common part, its east and north planar gradient per d_5; -1
absent): a single-frequency service's ionospheric residual field, in every GPS code row times the satellite's
F_pp (1, (d / d_5) sin az, (d / d_5) cos az) (core/nav/measurements.py)."""
L_GTZ = 24
"""The zenith tropospheric state gtz (-1 absent): a service's tropospheric zenith residual, in every GPS code row
times the satellite's mapping M(el) (core/nav/measurements.py)."""
LAY_SIZE = 25
LAY_GROUPS = ("dp", "dv", "psi", "bg", "ba", "bb", "sb", "clk", "ac", "gse", "gmp", "pmp", "ptr", "pclk", "rab",
              "ram", "tdb")
"""Group names in the order of lay[1:18]."""

Q_ARW, Q_VRW, Q_BG_RW, Q_BA_RW, Q_BB_SIGMA, Q_BB_TAU, Q_BARO_SIGMA, Q_BARO_RATE = range(8)
Q_CLK_SF, Q_CLK_SG, Q_GSE_TAU, Q_GMP_TAU, Q_PMP_SIGMA, Q_PMP_TAU, Q_PCLK_SF, Q_PCLK_SG = range(8, 16)
Q_RAM_SIGMA, Q_RAM_TAU, Q_TDB_L, Q_BARO_REF, Q_PSY_SIGMA, Q_PSY_TAU = range(16, 22)
Q_GAX = 22
"""q[Q_GAX + k]: the gyro scale-factor / misalignment white rate noise of body axis k, rad^2/s (nav/noise.py)."""
Q_GIZ_SIGMA, Q_GIZ_GRADIENT_SIGMA, Q_GIZ_TAU, Q_GTZ_SIGMA, Q_GTZ_TAU = 25, 26, 27, 28, 29
"""The zenith ionospheric states' 1-sigma (common, each gradient component; m) and correlation time (s), the zenith
tropospheric state's."""
Q_SIZE = 30
Q_FIELDS = ("gyro_arw_rad_sqrts", "accel_vrw_mps_sqrts", "gyro_bias_rw", "accel_bias_rw", "baro_bias_sigma_m",
            "baro_bias_tau_s", "baro_noise_sigma_m", "baro_rate_hz", "clock_sf", "clock_sg", "gse_tau_s",
            "gmp_tau_s", "pmp_sigma_m", "pmp_tau_s", "pclk_sf", "pclk_sg", "ram_sigma_m", "ram_tau_s",
            "tdb_correlation_m", "baro_ref_m", "psy_sigma_m", "psy_tau_s", "gyro_axis_q_x", "gyro_axis_q_y",
            "gyro_axis_q_z", "giz_sigma_m", "giz_gradient_sigma_m", "giz_tau_s", "gtz_sigma_m", "gtz_tau_s")
"""errormodel.ErrorNoise field of each q[Q_*], in index order."""

LOOP_SIZE = 4

EXPM_THETA = 0.25
"""Scaling target of the Taylor series: |M dt / 2^s|_1 <= 0.25 (errormodel._expm)."""
EXPM_MAX_NORM = 1e3
"""Above this 1-norm of M the wrapper falls back to errormodel.discretize_reference (scipy's expm)."""


@njit(cache=True)
def _markov(F: np.ndarray, Qc: np.ndarray, i0: int, k: int, sigma: np.ndarray, tau: float) -> None:
    """k first-order Gauss-Markov states from i0: x' = -x / tau + w, E[w w'] = 2 sigma^2 / tau."""
    for j in range(k):
        i = i0 + j
        F[i, i] = -1.0 / tau
        Qc[i, i] = 2.0 * sigma[j] ** 2 / tau


@njit(cache=True)
def scale_channels(phi: np.ndarray, i0: int, r: np.ndarray) -> None:
    """A channel group's scale over an interval on its Phi (n, n), in place: Phi[i0 + c, i0 + c] times r[c]
    (r (k,): the slow states from lay[L_GSE], the ionosphere states from lay[L_GIO]; nothing when k = 0). A
    Gauss-Markov error of a time-varying 1-sigma S(t), x = S u with u of unit variance: x(t + dt) = (S(t + dt) /
    S(t)) exp(-dt / tau) x(t) + w, Var w = S(t + dt)^2 (1 - exp(-2 dt / tau)) (the GBAS residual's scale follows
    the aircraft: sensors/gnss/gbas.py)."""
    for c in range(r.shape[0]):
        phi[i0 + c, i0 + c] *= r[c]


@njit(cache=True)
def dynamics(lay: np.ndarray, q: np.ndarray, gse_sigma: np.ndarray, gmp_sigma: np.ndarray, lat: float, h: float,
             v: np.ndarray, f: np.ndarray, c_bn: np.ndarray, loop: np.ndarray, held: bool, F: np.ndarray,
             Qc: np.ndarray) -> None:
    """Fill F (n, n) (1/s) and Qc = G Q G' (n, n) (the states' units squared per s) about a nav state.

    lat (rad), h (m), v (3,) NED m/s, f (3,) specific force NED m/s^2, c_bn (3, 3) body to NED: the INS solution.
    held: the damping loop held (no baro over the interval): only ac acts. Equations: errormodel's docstring,
        dp' = F_pp dp + dv ; dv' = [f x] psi + C ba - (2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en) - (dg/dh) dp_D
        psi' = -w_in x psi + dw_in - C bg ; sensor states random constants / walks / Gauss-Markov ;
        loop e = -dp_D - bb - (h - H_ref) sb: dp_D' += C1 e, dv_D' += C2 e + ac, ac' = C3 e,
        Qc += g g' sigma_b^2 / rate; Qc[psi, psi] += C diag(q[Q_GAX:Q_GAX + 3]) C' (gyro axis errors, body axes).
    """
    F[:, :] = 0.0
    Qc[:, :] = 0.0
    ip, iv, ia = lay[L_DP], lay[L_DV], lay[L_PSI]
    r_n, r_e = gk.radii(lat)
    rn, re = r_n + h, r_e + h
    tl, cl, sl = math.tan(lat), math.cos(lat), math.sin(lat)
    vn, ve, vd = v[0], v[1], v[2]
    om = gk.OMEGA_E
    # position error kinematics (errormodel: fp)
    for k in range(3):
        F[ip + k, iv + k] = 1.0
    F[ip, ip] = -vd / rn
    F[ip, ip + 2] = vn / rn
    F[ip + 1, ip] = ve * tl / rn
    F[ip + 1, ip + 1] = -vd / re - tl * vn / rn
    F[ip + 1, ip + 2] = ve / re
    # Jacobians of w_in wrt dp, dv (errormodel._dw_in)
    d_dp = np.zeros((3, 3))
    d_dv = np.zeros((3, 3))
    d_dp[0, 0] = -om * sl / rn
    d_dp[2, 0] = -om * cl / rn
    d_dv[0, 1] = 1.0 / re
    d_dp[0, 2] = ve / re**2
    d_dv[1, 0] = -1.0 / rn
    d_dp[1, 2] = -vn / rn**2
    d_dv[2, 1] = -tl / re
    d_dp[2, 0] += -ve / (re * cl**2 * rn)
    d_dp[2, 2] = -ve * tl / re**2
    wie = (om * cl, 0.0, -om * sl)
    wen = (ve / re, -vn / rn, -ve * tl / re)
    win = (wie[0] + wen[0], wie[1] + wen[1], wie[2] + wen[2])
    die = np.zeros((3, 3))
    die[0, 0] = -om * sl / rn
    die[2, 0] = -om * cl / rn
    # M = 2 die + (d_dp - die): v x M is F[V, P]; w2 = 2 w_ie + w_en
    vx = ((0.0, -vd, ve), (vd, 0.0, -vn), (-ve, vn, 0.0))
    w2 = (2.0 * wie[0] + wen[0], 2.0 * wie[1] + wen[1], 2.0 * wie[2] + wen[2])
    for r in range(3):
        for c in range(3):
            a = 0.0
            b = 0.0
            for k in range(3):
                a += vx[r][k] * d_dv[k, c]
                b += vx[r][k] * (2.0 * die[k, c] + (d_dp[k, c] - die[k, c]))
            F[iv + r, iv + c] = a
            F[iv + r, ip + c] = b
    # F[V, V] = -[w2 x] + v x dw_en/dv
    F[iv, iv + 1] += w2[2]
    F[iv, iv + 2] += -w2[1]
    F[iv + 1, iv] += -w2[2]
    F[iv + 1, iv + 2] += w2[0]
    F[iv + 2, iv] += w2[1]
    F[iv + 2, iv + 1] += -w2[0]
    # [f x] psi
    F[iv, ia + 1], F[iv, ia + 2] = -f[2], f[1]
    F[iv + 1, ia], F[iv + 1, ia + 2] = f[2], -f[0]
    F[iv + 2, ia], F[iv + 2, ia + 1] = -f[1], f[0]
    _, gd_up = gk.gravity_nd(lat, h + 10.0)
    _, gd_dn = gk.gravity_nd(lat, h - 10.0)
    F[iv + 2, ip + 2] += -((gd_up - gd_dn) / 20.0)
    ibg, iba = lay[L_BG], lay[L_BA]
    for r in range(3):
        for c in range(3):
            F[iv + r, iba + c] = c_bn[r, c]
            F[ia + r, ip + c] = d_dp[r, c]
            F[ia + r, iv + c] = d_dv[r, c]
            F[ia + r, ibg + c] = -c_bn[r, c]
    # attitude: -[w_in x]
    F[ia, ia + 1], F[ia, ia + 2] = win[2], -win[1]
    F[ia + 1, ia], F[ia + 1, ia + 2] = -win[2], win[0]
    F[ia + 2, ia], F[ia + 2, ia + 1] = win[1], -win[0]
    # sensor error states
    ibb = lay[L_BB]
    F[ibb, ibb] = -1.0 / q[Q_BB_TAU]
    Qc[ibb, ibb] = 2.0 * q[Q_BB_SIGMA] ** 2 / q[Q_BB_TAU]
    for k in range(3):
        Qc[iv + k, iv + k] = q[Q_VRW] ** 2
        Qc[ia + k, ia + k] = q[Q_ARW] ** 2
    for r in range(3):
        for c in range(3):
            Qc[ia + r, ia + c] += (c_bn[r, 0] * c_bn[c, 0] * q[Q_GAX] + c_bn[r, 1] * c_bn[c, 1] * q[Q_GAX + 1]
                                   + c_bn[r, 2] * c_bn[c, 2] * q[Q_GAX + 2])
    for k in range(3):
        Qc[ibg + k, ibg + k] = q[Q_BG_RW] ** 2
        Qc[iba + k, iba + k] = q[Q_BA_RW] ** 2
    ic = lay[L_CLK]
    if ic >= 0:
        F[ic, ic + 1] = 1.0
        Qc[ic, ic] = q[Q_CLK_SF]
        Qc[ic + 1, ic + 1] = q[Q_CLK_SG]
    if lay[L_GSE] >= 0:
        _markov(F, Qc, lay[L_GSE], lay[L_NSV], gse_sigma, q[Q_GSE_TAU])
        _markov(F, Qc, lay[L_GMP], lay[L_NSV], gmp_sigma, q[Q_GMP_TAU])
    one = np.empty(1)
    if lay[L_PMP] >= 0:
        for j in range(lay[L_NPL]):
            one[0] = q[Q_PMP_SIGMA]
            _markov(F, Qc, lay[L_PMP] + j, 1, one, q[Q_PMP_TAU])
    if lay[L_PCLK] >= 0:
        for j in range(lay[L_NPL]):
            i = lay[L_PCLK] + 2 * j
            F[i, i + 1] = 1.0
            Qc[i, i] = q[Q_PCLK_SF]
            Qc[i + 1, i + 1] = q[Q_PCLK_SG]
    if lay[L_PSY] >= 0:
        for j in range(lay[L_NPL]):
            one[0] = q[Q_PSY_SIGMA]
            _markov(F, Qc, lay[L_PSY] + j, 1, one, q[Q_PSY_TAU])
    if lay[L_RAM] >= 0:
        one[0] = q[Q_RAM_SIGMA]
        _markov(F, Qc, lay[L_RAM], 1, one, q[Q_RAM_TAU])
    if lay[L_GIZ] >= 0:
        giz = np.empty(3)
        giz[0], giz[1], giz[2] = q[Q_GIZ_SIGMA], q[Q_GIZ_GRADIENT_SIGMA], q[Q_GIZ_GRADIENT_SIGMA]
        _markov(F, Qc, lay[L_GIZ], 3, giz, q[Q_GIZ_TAU])
    if lay[L_GTZ] >= 0:
        one[0] = q[Q_GTZ_SIGMA]
        _markov(F, Qc, lay[L_GTZ], 1, one, q[Q_GTZ_TAU])
    if lay[L_TDB] >= 0:
        one[0] = 1.0
        _markov(F, Qc, lay[L_TDB], 1, one, q[Q_TDB_L] / max(math.hypot(vn, ve), 1.0))
    iac = lay[L_AC]
    if iac >= 0:
        i_h, i_v = ip + 2, iv + 2  # dp_D = -dh, dv_D = -dv_up
        F[i_v, iac] += 1.0
        if not held:  # loop error e = -dp_D - bb - (h - H_ref) sb (nav/errormodel.dynamics_reference: why -1)
            isb = lay[L_SB]
            for row, g in ((i_h, loop[1]), (i_v, loop[2]), (iac, loop[3])):
                F[row, i_h] += g * -1.0
                F[row, ibb] += g * -1.0
                if isb >= 0:
                    F[row, isb] += g * -(h - q[Q_BARO_REF])
            gv = (-loop[1], -loop[2], -loop[3])
            idx = (i_h, i_v, iac)
            s2 = q[Q_BARO_SIGMA] ** 2
            for a in range(3):
                for b in range(3):
                    Qc[idx[a], idx[b]] += gv[a] * gv[b] * s2 / q[Q_BARO_RATE]


@njit(cache=True)
def interval_height(lay: np.ndarray, h_m: float, v_down_mps: float, dt_s: float) -> float:
    """The height (m) an aiding interval's dynamics are taken at, from the height h_m and the down velocity
    v_down_mps at the interval's end (dt_s long): with a baro scale-factor state and the damping loop (lay[L_SB],
    lay[L_AC] >= 0) the interval's midpoint, h + v_D dt / 2; else h (nothing else in F moves with h at this
    scale). The damping loop's sb coefficient -(h - H_ref) follows the height
    through the interval (3.6 m per 1 s interval on a 3 deg final at 140 kt), and Phi = exp(F dt) with F held takes
    it where F is taken: at the end the filter would give the loop sb (h_end - H_ref) when the INS's loop saw
    sb (h(t) - H_ref), short by sb v_D dt / 2 on every interval (0.21 m of loop error at ISA -30 uncorrected, the
    same sign in every run: the filter's vertical velocity over-confident, docs/consistency.md). At the midpoint
    F is the interval's mean for a steady descent (the midpoint rule, second order in dt)."""
    if lay[L_SB] < 0 or lay[L_AC] < 0:
        return h_m
    return h_m + 0.5 * dt_s * v_down_mps


@njit(cache=True)
def end_height(lay: np.ndarray, F: np.ndarray, x: np.ndarray, h_nav: float, dt_s: float) -> float:
    """The navigation's height (m) at the end of an aiding interval of dt_s: h_nav = h_ins + dp_D_hat, the INS height
    at the interval's end with the estimate x (n,) of its start, plus the estimate's own change over it,
    dp_D_hat' dt = (F x)[dp_D] dt (F the interval's model). The damping loop drags the INS toward a baro off by
    sb (h - H_ref), and the estimate follows: 2.9 m of dp_D per 1 s interval early on a final at ISA +30
    uncorrected, so h_ins(end) + dp_D_hat(start) is off by as much, a loop error of sb times that in the model
    (0.27 m at S = -0.094, the same sign in every run: the per-run filter's height over-confident, issue 39)."""
    i = lay[L_DP] + 2
    rate = 0.0
    for j in range(F.shape[1]):
        rate += F[i, j] * x[j]
    return h_nav + rate * dt_s


@njit(cache=True)
def loop_jacobian(lay: np.ndarray, loop: np.ndarray, held: bool, sb: float, F: np.ndarray,
                  keep: np.ndarray) -> bool:
    """The interval's model F (n, n) of the estimate made the EKF's Jacobian at the estimate's baro scale factor sb,
    in place: the damping loop's rows (dp_D, dv_D, ac with gains loop[1], loop[2], loop[3]) take -g sb more at
    dp_D, their old entries into keep (3,) (`loop_mean` puts them back). Returns whether F changed: a baro
    scale-factor state and the loop on and not held.

    The loop error the INS sees, e = -dp_D - bb - (h_ins + dp_D - H_ref) sb, is bilinear in (dp_D, sb). F writes
    it with -1 at dp_D and -(h_nav - H_ref) at sb, h_nav = h_ins + dp_D_hat: F x_hat is then e(x_hat) exactly, the
    EKF's predicted mean. Its Jacobian de/d(dp_D) is -(1 + sb): the covariance's error dynamics need it (with -1
    the filter gives a height error the loop's gain without the scale factor, and on a hot day, S = -0.094, the
    estimate carries a loop error of sb times its own 0.5 m height error: e^2/P 1.47 against 0.95 with the
    Jacobian, 20 open-loop runs, issue 39)."""
    iac = lay[L_AC]
    if iac < 0 or lay[L_SB] < 0 or held:
        return False
    i_h = lay[L_DP] + 2
    rows = (i_h, lay[L_DV] + 2, iac)
    for k in range(3):
        keep[k] = F[rows[k], i_h]
        F[rows[k], i_h] += loop[k + 1] * -sb
    return True


@njit(cache=True)
def loop_mean(lay: np.ndarray, keep: np.ndarray, F: np.ndarray) -> None:
    """F's loop rows at dp_D back to the mean's model (keep: `loop_jacobian`'s saved entries), in place."""
    i_h = lay[L_DP] + 2
    F[i_h, i_h] = keep[0]
    F[lay[L_DV] + 2, i_h] = keep[1]
    F[lay[L_AC], i_h] = keep[2]


@njit(cache=True)
def predict_mean(F: np.ndarray, phi: np.ndarray, x: np.ndarray, dt: float) -> None:
    """x (n,) <- the estimate's prediction over dt (s) by its own model F (n, n), in place, where the covariance
    takes another Phi (`loop_jacobian`): exp(F dt) x on the states F couples, Phi x on the others (the decoupled
    states: Phi's row there is its diagonal, which carries the interval's per-state changes, scale_channels and
    carrier.reset_ambiguities, that F does not).

    exp(F dt) x by its Taylor series (Al-Mohy & Higham's expmv idea, plain): s = ceil(|F dt|_inf / 2) equal steps,
    so that a step's term k is at most 2 / k of term k - 1; the terms of a step added until every state's is within
    2^-53 of its running sum (at most 40 terms: 2^40 / 40! < 1e-35 of the first). Half-norm steps took twice the
    time (50 against 24 us on the default's 75 states, ||F||_inf 16 from the specific force) and rounded no better."""
    n = x.shape[0]
    norm = 0.0
    nnz = 0
    for i in range(n):
        r = 0.0
        for j in range(n):
            if F[i, j] != 0.0:
                r += abs(F[i, j])
                nnz += 1
        norm = max(norm, r)
    ptr = np.empty(n + 1, dtype=np.int64)
    col = np.empty(max(nnz, 1), dtype=np.int64)
    val = np.empty(max(nnz, 1))
    kk.csr(F, ptr, col, val)
    x0 = x.copy()
    term = np.empty(n)
    nxt = np.empty(n)
    steps = max(1, int(math.ceil(0.5 * norm * dt)))
    h = dt / steps
    for _ in range(steps):
        for i in range(n):
            term[i] = x[i]
        for k in range(1, 41):
            for i in range(n):
                acc = 0.0
                for p in range(ptr[i], ptr[i + 1]):
                    acc += val[p] * term[col[p]]
                nxt[i] = acc * h / k
            done = True
            for i in range(n):
                term[i] = nxt[i]
                x[i] += term[i]
                if abs(term[i]) > 1.1102230246251565e-16 * abs(x[i]):
                    done = False
            if done:
                break
    for i in range(n):
        lone = True
        for j in range(n):
            if j != i and (F[i, j] != 0.0 or F[j, i] != 0.0):
                lone = False
                break
        if lone:
            x[i] = phi[i, i] * x0[i]


@njit(cache=True)
def _find(parent: np.ndarray, i: int) -> int:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@njit(cache=True)
def _taylor_van_loan(A: np.ndarray, Q: np.ndarray, phi: np.ndarray, qd: np.ndarray) -> None:
    """Phi0 = sum_{k<=8} A^k / k! and Qd0 = Phi0 E12, E12 the (1, 2) block of sum_{k<=8} M0^k / k!,
    M0 = [[-A, Q], [0, A']] (A = F t0, Q = Qc t0; t0 the scaled step); Qd0 symmetrized, into phi, qd.

    Blocks of T_k = M0^k / k!: T11_k = (-A)^k / k!, T22_k = (A')^k / k!, T12_k = (T11_{k-1} Q + T12_{k-1} A') / k.
    With G_k = A^k / k! and U_k = T12_k' (Q = Q'): U_k = ((-1)^(k-1) Q G_{k-1}' + A U_{k-1}) / k, Phi0 = sum G_k;
    the products run over the nonzeros of A and Q (row-compressed), along contiguous rows.
    """
    m = A.shape[0]
    a_ptr = np.empty(m + 1, dtype=np.int64)
    a_col = np.empty(m * m, dtype=np.int64)
    a_val = np.empty(m * m)
    q_ptr = np.empty(m + 1, dtype=np.int64)
    q_col = np.empty(m * m, dtype=np.int64)
    q_val = np.empty(m * m)
    kk.csr(A, a_ptr, a_col, a_val)
    kk.csr(Q, q_ptr, q_col, q_val)
    G = np.eye(m)  # G_{k-1}
    U = np.zeros((m, m))  # U_{k-1}
    E12t = np.zeros((m, m))  # sum U_k = E12'
    W = np.empty((m, m))
    phi[:, :] = 0.0
    for i in range(m):
        phi[i, i] = 1.0
    sign = 1.0  # (-1)^(k-1)
    for k in range(1, 9):
        # W = sign Q G' + A U ; (Q G')[i, j] = sum_l Q[i, l] G[j, l]
        for i in range(m):
            for j in range(m):
                W[i, j] = 0.0
            for p in range(q_ptr[i], q_ptr[i + 1]):
                c = sign * q_val[p]
                l = q_col[p]
                for j in range(m):
                    W[i, j] += c * G[j, l]
            kk.row_sums(i, a_ptr, a_col, a_val, U, W)
        for i in range(m):
            for j in range(m):
                U[i, j] = W[i, j] / k
                E12t[i, j] += U[i, j]
        # G_k = A G_{k-1} / k
        for i in range(m):
            for j in range(m):
                W[i, j] = 0.0
            kk.row_sums(i, a_ptr, a_col, a_val, G, W)
        for i in range(m):
            for j in range(m):
                G[i, j] = W[i, j] / k
                phi[i, j] += G[i, j]
        sign = -sign
    # Qd0 = Phi0 E12 ; E12[l, j] = E12t[j, l]
    for i in range(m):
        for j in range(m):
            acc = 0.0
            for l in range(m):
                acc += phi[i, l] * E12t[j, l]
            qd[i, j] = acc
    _symmetrize(qd)


@njit(cache=True)
def _symmetrize(X: np.ndarray) -> None:
    """X <- (X + X') / 2 (in place)."""
    m = X.shape[0]
    for i in range(m):
        for j in range(i + 1, m):
            s = 0.5 * (X[i, j] + X[j, i])
            X[i, j] = s
            X[j, i] = s


@njit(cache=True)
def _square(phi: np.ndarray, qd: np.ndarray, W: np.ndarray, P2: np.ndarray, ptr: np.ndarray, col: np.ndarray,
            val: np.ndarray) -> None:
    """One squaring of the Van Loan exponential in blocks: Qd <- Phi Qd Phi' + Qd (symmetrized), Phi <- Phi^2,
    in place. Phi Qd Phi' = Phi W' with W = Phi Qd (Qd symmetric). W, P2 (m, m), ptr, col, val: scratch."""
    m = phi.shape[0]
    kk.csr(phi, ptr, col, val)
    for i in range(m):  # W = Phi Qd ; P2 = Phi Phi, along the nonzeros of Phi's rows
        for j in range(m):
            W[i, j] = 0.0
            P2[i, j] = 0.0
        kk.row_sums(i, ptr, col, val, qd, W)
        kk.row_sums(i, ptr, col, val, phi, P2)
    for i in range(m):  # W <- W'
        for j in range(i + 1, m):
            t = W[i, j]
            W[i, j] = W[j, i]
            W[j, i] = t
    for i in range(m):  # Qd += Phi W'
        kk.row_sums(i, ptr, col, val, W, qd)
    _symmetrize(qd)
    kk.copy_2d(phi, P2)


@njit(cache=True)
def van_loan(F: np.ndarray, Qc: np.ndarray, dt: float, phi: np.ndarray, qd: np.ndarray) -> bool:
    """Phi = expm(F dt) and Qd = int_0^dt Phi(s) Qc Phi(s)' ds (m, m) into phi, qd by Van Loan's method with
    errormodel._expm's Taylor series and scaling (module docstring). False (phi, qd untouched) when the 1-norm
    of M = [[-F, Qc], [0, F']] dt exceeds EXPM_MAX_NORM or is not finite: the caller falls back to the numpy path."""
    m = F.shape[0]
    norm = 0.0
    for j in range(m):  # column sums of |M|: column j of [-F; 0] and column j of [Qc; F']
        s1 = 0.0
        s2 = 0.0
        for i in range(m):
            s1 += abs(F[i, j]) * dt
            s2 += abs(Qc[i, j]) * dt
        for i in range(m):
            s2 += abs(F[j, i]) * dt
        if not (s1 <= EXPM_MAX_NORM and s2 <= EXPM_MAX_NORM):  # too large, or not finite
            return False
        norm = max(norm, s1, s2)
    s = max(0, int(math.ceil(math.log2(max(norm, 1e-300) / EXPM_THETA))))
    t0 = dt / 2.0**s
    A = F * t0
    Q = Qc * t0
    _taylor_van_loan(A, Q, phi, qd)
    W = np.empty((m, m))
    P2 = np.empty((m, m))
    ptr = np.empty(m + 1, dtype=np.int64)
    col = np.empty(m * m, dtype=np.int64)
    val = np.empty(m * m)
    for _ in range(s):
        _square(phi, qd, W, P2, ptr, col, val)
    return True


@njit(cache=True)
def discretize(F: np.ndarray, Qc: np.ndarray, dt: float, phi: np.ndarray, qd: np.ndarray) -> bool:
    """Phi, Qd (n, n) over dt (s) into phi, qd: decoupled states in closed form, each connected component of the
    coupled rest by `van_loan` (module docstring). Returns False when a component's Van Loan matrix is too large
    for the Taylor series (norm > EXPM_MAX_NORM): the caller must use errormodel.discretize_reference.

        lone state (a = F_ii, q = Qc_ii):  Phi_ii = exp(a dt), Qd_ii = q (exp(2 a dt) - 1) / (2 a)  (q dt, a = 0)
    """
    n = F.shape[0]
    parent = np.arange(n)
    coupled = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        for j in range(n):
            if i != j and (F[i, j] != 0.0 or Qc[i, j] != 0.0):
                coupled[i] = True
                coupled[j] = True
                a, b = _find(parent, i), _find(parent, j)
                if a != b:
                    parent[max(a, b)] = min(a, b)
    phi[:, :] = 0.0
    qd[:, :] = 0.0
    for i in range(n):
        if not coupled[i]:
            a = F[i, i]
            phi[i, i] = math.exp(a * dt)
            qd[i, i] = Qc[i, i] * (dt if a == 0.0 else math.expm1(2.0 * a * dt) / (2.0 * a))
    idx = np.empty(n, dtype=np.int64)
    for root in range(n):
        if not coupled[root] or _find(parent, root) != root:
            continue
        m = 0
        for i in range(root, n):
            if coupled[i] and _find(parent, i) == root:
                idx[m] = i
                m += 1
        Fc = np.empty((m, m))
        Qcc = np.empty((m, m))
        for a in range(m):
            for b in range(m):
                Fc[a, b] = F[idx[a], idx[b]]
                Qcc[a, b] = Qc[idx[a], idx[b]]
        pc = np.empty((m, m))
        qc = np.empty((m, m))
        if not van_loan(Fc, Qcc, dt, pc, qc):
            return False
        for a in range(m):
            for b in range(m):
                phi[idx[a], idx[b]] = pc[a, b]
                qd[idx[a], idx[b]] = qc[a, b]
    return True
