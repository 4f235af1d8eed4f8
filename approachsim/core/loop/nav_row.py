"""The closed loop's per-row navigation as a compiled kernel (numba, cache=True), called by the flight loop's
compiled step (core/loop/closed_step.py) so that a closed-loop row costs no Python beyond JSBSim's reads and
writes; Python runs only at the rows where the navigation needs it (the start, a baro sample of the damping loop,
an aiding epoch: loop/closed_loop.py).

Per truth row k (k > 0), with the flight's row buffer buf (core/layouts.py TRUTH_ROW):

    IMU increment of (k-1, k]: d = dt w(k-1) (rate or specific force of truth sample k-1 held, sensors/imu.py),
                               dtheta = d + M_g d + c_g[k-1],  dv = d + M_a d + c_a[k-1]  (pre-drawn, affine)
    INS step (kernels/strapdown.py) with the baro held in the work vector (nan: the damping loop holds) and its age
                               t(k-1) - t(sample)
    rows[k] = the INS state; snap[k] = the filter snapshot in force
    guidance = INS - x_hat(t) (feed-forward) in the runway frame and NED (kernels/strapdown.guidance), x_hat(t) the
               last epoch's estimate carried to the row's time by its rate (core/nav/output.estimate_at)

The work vector nw (core/layouts.py NAV_WORK) holds the one run's INS state and the small constants; the other arrays of
the row are views of two packed arrays, fa (float64) and ia (int64) (`views`, `packed_sizes`), so that the flight
loop's compiled call takes three navigation arguments instead of twelve (unboxing an array argument costs ~0.13 us
of every one of the flight's ~31,000 calls). loop/closed_loop.py builds them and keeps the Navigator's INS state,
specific-force sum, rows and snapshot index as views of these arrays, so both see the same numbers. The numpy
oracle is NavInTheLoop.step (the generic per-row path, kept for quantized or faulted IMUs):
tests/unit/nav/test_system_closed_loop.py flies both.
"""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit
from approachsim.core.layouts import (
    NX,
    ROW_F_BODY,
    ROW_P_STATIC,
    ROW_T,
    ROW_W_IB,
    W_ANY_BARO,
    W_BA,
    W_BARO_EXCL,
    W_BARO_KERNEL,
    W_BARO_LOOP,
    W_BCM1,
    W_BEXP,
    W_BFLD,
    W_BG,
    W_BSET,
    W_BSF,
    W_BT0L,
    W_CRWY,
    W_DT,
    W_EPOCH_ROWS,
    W_FSUM,
    W_HB,
    W_HB_AGE,
    W_HB_T,
    W_HTHR,
    W_LOOP,
    W_M,
    W_MA,
    W_MG,
    W_N,
    W_NBE,
    W_NLAG,
    W_ORWY,
    W_SNAP,
    W_T_EST,
    W_X,
    W_XDOT,
    W_XNAV,
    W_XNOW,
)
from approachsim.core.nav import output as ko
from approachsim.core.nav import strapdown as sk

NAV_START, NAV_BARO, NAV_EPOCH = 1, 2, 4
"""Bits of nav_row's code: the rows at which Python must act."""


@njit(cache=True)
def baro_sample(k: int, buf: np.ndarray, nw: np.ndarray, lag_w: np.ndarray, bias: float, noise: float) -> float:
    """The barometric altimeter's sample at truth row k (core/sensors/baro.baro_apply for one run, the same
    operations in order): h_ind = (T0 / L)(1 - (p / p_set)^(R L / g0)) of the static pressure at the IMU (buf column
    ROW_P_STATIC; with a lag, the weights lag_w over rows k, k - 1, ..., clipped at 0),
    h_c = h_ind + (h_ind - H_f)(c - 1),
    h = h_c + (h_c - H_f) S + bias + noise."""
    t0l, p_set, ex = nw[W_BT0L], nw[W_BSET], nw[W_BEXP]
    if lag_w.shape[0] > 0:
        h = 0.0
        for q in range(lag_w.shape[0]):
            h += t0l * (1.0 - (buf[max(k - q, 0), ROW_P_STATIC] / p_set) ** ex) * lag_w[q]
    else:
        h = t0l * (1.0 - (buf[k, ROW_P_STATIC] / p_set) ** ex)
    h = h + (h - nw[W_BFLD]) * nw[W_BCM1]
    return h + (h - nw[W_BFLD]) * nw[W_BSF] + bias + noise


@njit(cache=True)
def nav_row(k: int, buf: np.ndarray, nw: np.ndarray, cg: np.ndarray, ca: np.ndarray, rows: np.ndarray,
            snap: np.ndarray, baro_j: np.ndarray, baro_e: np.ndarray, lag_w: np.ndarray, dth: np.ndarray,
            dv: np.ndarray) -> int:
    """Row k of the closed loop's navigation (module docstring); returns the NAV_* bits of what Python must do at
    this row (0: nothing). cg, ca (m, 3) the IMU error terms by sample; rows (n, 16) the INS rows; snap (n,) int64;
    baro_j (n,) int64 the baro sample at each row (-1: none), baro_e (m, 2) its bias and noise (m), lag_w its lag
    weights (empty: none): a plain baro's samples of the damping loop are made here (baro_sample) except at the
    start and at the epochs, where an exclusion by the online FDE may just have happened; dth, dv (1, 1, 3)
    scratch."""
    code = 0
    if k == 0:
        code = NAV_START
    else:
        dt = nw[W_DT]
        w, f = buf[k - 1, ROW_W_IB:ROW_W_IB + 3], buf[k - 1, ROW_F_BODY:ROW_F_BODY + 3]
        mg, ma = nw[W_MG:W_MG + 9], nw[W_MA:W_MA + 9]
        for r in range(3):
            d0, d1, d2 = dt * w[0], dt * w[1], dt * w[2]
            d = d0 if r == 0 else (d1 if r == 1 else d2)
            dth[0, 0, r] = d + (mg[3 * r] * d0 + mg[3 * r + 1] * d1 + mg[3 * r + 2] * d2) + cg[k - 1, r]
            e0, e1, e2 = dt * f[0], dt * f[1], dt * f[2]
            e = e0 if r == 0 else (e1 if r == 1 else e2)
            dv[0, 0, r] = e + (ma[3 * r] * e0 + ma[3 * r + 1] * e1 + ma[3 * r + 2] * e2) + ca[k - 1, r]
        hb = nw[W_HB:W_HB + 1].reshape(1, 1)
        if hb[0, 0] == hb[0, 0]:
            nw[W_ANY_BARO] = 1.0
        nw[W_HB_AGE] = buf[k - 1, ROW_T] - nw[W_HB_T]
        # row0 as np.int64, not a literal 0: numba would compile strapdown once more for the literal
        sk.strapdown(nw[W_X:W_X + NX].reshape(1, NX), dth, dv, dt, nw[W_BG:W_BG + 3].reshape(1, 3),
                     nw[W_BA:W_BA + 3].reshape(1, 3), hb, nw[W_HB_AGE:W_HB_AGE + 1], nw[W_LOOP:W_LOOP + 6],
                     nw[W_FSUM:W_FSUM + 3].reshape(1, 3), np.empty((1, 0, NX)), np.int64(0))
        if k % int(nw[W_EPOCH_ROWS]) == 0:
            code |= NAV_EPOCH
    j = baro_j[k]
    if nw[W_BARO_LOOP] != 0.0 and j >= 0:
        if nw[W_BARO_KERNEL] != 0.0 and code == 0:  # the held baro for the next intervals (nan: excluded)
            nw[W_HB] = np.nan if nw[W_BARO_EXCL] != 0.0 else baro_sample(k, buf, nw, lag_w, baro_e[j, 0],
                                                                          baro_e[j, 1])
            nw[W_HB_T] = buf[k, ROW_T]
        else:
            code |= NAV_BARO
    for q in range(NX):
        rows[k, q] = nw[W_X + q]
    snap[k] = int(nw[W_SNAP])
    return code


@njit(cache=True)
def nav_guidance(nw: np.ndarray, t: float, out: np.ndarray) -> None:
    """The guidance of the current INS state at time t (s) into out (6,): runway-frame position (m) and NED
    velocity (m/s) of the feed-forward output INS - x_hat(t) (kernels/strapdown.guidance), x_hat(t) the estimate in
    force carried to t by its rate (core/nav/output.estimate_at)."""
    c = nw[W_CRWY:W_CRWY + 6].reshape(2, 3)
    x = nw[W_XNOW:W_XNOW + 9]
    ko.estimate_at(nw[W_XNAV:W_XNAV + 9], nw[W_XDOT:W_XDOT + 9], nw[W_T_EST], t, x)
    sk.guidance(nw[W_X:W_X + NX].reshape(1, NX), x, c, nw[W_ORWY:W_ORWY + 3], nw[W_HTHR], out)


def packed_sizes(n: int, m: int, n_baro: int, n_lag: int) -> tuple[int, int]:
    """Lengths of the packed arrays fa, ia (`views`) for n truth rows, m IMU samples, n_baro baro samples and n_lag
    lag weights."""
    return 2 * 3 * m + NX * n + 6 * n + 2 * n_baro + n_lag + 6, 2 * n


@njit(cache=True)
def views(nw: np.ndarray, fa: np.ndarray, ia: np.ndarray) -> tuple:
    """The row's arrays as views of the packed fa, ia, sizes at nw[W_N], W_M, W_NBE, W_NLAG, in this order:
    fa = cg (m, 3) | ca (m, 3) | rows (n, 16) | guidance (n, 6) | baro_e (n_baro, 2) | lag_w (n_lag,) | dth (1, 1, 3)
    | dv (1, 1, 3);  ia = snap (n,) | baro_j (n,). Returns (cg, ca, rows, snap, baro_j, baro_e, lag_w, dth, dv,
    guidance): nav_row's arguments after nw, then the guidance rows."""
    n, m, nb, nl = int(nw[W_N]), int(nw[W_M]), int(nw[W_NBE]), int(nw[W_NLAG])
    o = 0
    cg = fa[o:o + 3 * m].reshape(m, 3)
    o += 3 * m
    ca = fa[o:o + 3 * m].reshape(m, 3)
    o += 3 * m
    rows = fa[o:o + NX * n].reshape(n, NX)
    o += NX * n
    guidance = fa[o:o + 6 * n].reshape(n, 6)
    o += 6 * n
    baro_e = fa[o:o + 2 * nb].reshape(nb, 2)
    o += 2 * nb
    lag_w = fa[o:o + nl]
    o += nl
    dth = fa[o:o + 3].reshape(1, 1, 3)
    dv = fa[o + 3:o + 6].reshape(1, 1, 3)
    return cg, ca, rows, ia[0:n], ia[n:2 * n], baro_e, lag_w, dth, dv, guidance
