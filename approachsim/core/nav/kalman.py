"""Compiled Kalman-filter epoch kernels (numba, cache=True): the covariance-form predict and the scalar Joseph
update of nav/base.py's KalmanFilter, a shared-covariance update for many runs, and the Riccati recursion of a
fixed-geometry segment (nav/initial.py), all in place on plain arrays and exploiting the sparsity of the error
model (Phi is block diagonal with a diagonal tail; h has a handful of nonzeros).

Every kernel works on arrays the caller owns; the scratch space is one tuple from `workspace(n)`:

    ws = (W (n, n), v (n,), val (n * n,), ptr (n + 1,) int64, col (n * n,) int64)

Equations (textbook symbols; the dense numpy forms in nav/base.py, predict_reference / joseph_reference, are the
test oracle, tests/unit/nav/test_epoch_kernels.py):

    predict   x <- Phi x ;  P <- Phi P Phi' + Qd  (symmetric)               Phi P Phi' = Phi W', W = Phi P
    update    b = P h ; S = h' b + r ; K = b / S ; x <- x + w K nu ; Kc = c K
              P <- P - Kc b' - b Kc' + S Kc Kc'                          (= (I - Kc h') P (I - Kc h')' + r Kc Kc')
              with c = 1 - sqrt(1 - psi'): P - psi' K S K' (base.GainPolicy); optimal w = c = 1

The update is O(n^2) (the Joseph product form is O(n^3)) and touches only the rows and columns where b is
nonzero (states uncorrelated with the measured ones keep their entries exactly). It is symmetric by construction:
the (i, j) and (j, i) entries are the same sums of the same products. A run's numbers are computed by scalar
loops in a fixed order: they do not depend on any batch.
"""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit


def workspace(n: int) -> tuple[np.ndarray, ...]:
    """Scratch arrays for the kernels of an n-state filter (module docstring): allocate once per filter size."""
    return (np.empty((n, n)), np.empty(n), np.empty(n * n), np.empty(n + 1, dtype=np.int64),
            np.empty(n * n, dtype=np.int64))


@njit(cache=True)
def copy_2d(dst: np.ndarray, src: np.ndarray) -> None:
    """dst[:, :] = src, element by element (same shape). A loop, not a slice assignment: numba compiles an
    array-valued slice assignment with a shape-mismatch message built from unicode joins, about 3 s of compile
    per process and per caller that links it, for a check the callers' equal shapes never need."""
    for i in range(dst.shape[0]):
        for j in range(dst.shape[1]):
            dst[i, j] = src[i, j]


@njit(cache=True)
def csr(A: np.ndarray, ptr: np.ndarray, col: np.ndarray, val: np.ndarray) -> None:
    """Row-compressed nonzeros of A (n, n): row i's are col[ptr[i]:ptr[i + 1]] with values val[...]."""
    n = A.shape[0]
    k = 0
    for i in range(n):
        ptr[i] = k
        for j in range(n):
            a = A[i, j]
            if a != 0.0:
                col[k] = j
                val[k] = a
                k += 1
    ptr[n] = k


@njit(cache=True)
def row_sums(i: int, ptr: np.ndarray, col: np.ndarray, val: np.ndarray, B: np.ndarray, out: np.ndarray) -> None:
    """out[i, :] += sum over row i's nonzeros p of val[p] B[col[p], :], added one p after another in p's order;
    four p per pass over the row (the same additions in the same order as one p per pass: the same numbers, with
    a quarter of the loads and stores of out's row)."""
    n = B.shape[1]
    p = ptr[i]
    e = ptr[i + 1]
    while p + 4 <= e:
        a0, a1, a2, a3 = val[p], val[p + 1], val[p + 2], val[p + 3]
        l0, l1, l2, l3 = col[p], col[p + 1], col[p + 2], col[p + 3]
        for j in range(n):
            out[i, j] = (((out[i, j] + a0 * B[l0, j]) + a1 * B[l1, j]) + a2 * B[l2, j]) + a3 * B[l3, j]
        p += 4
    while p < e:
        a = val[p]
        l = col[p]
        for j in range(n):
            out[i, j] = out[i, j] + a * B[l, j]
        p += 1


@njit(cache=True)
def _predict_cov(P: np.ndarray, qd: np.ndarray, W: np.ndarray, ptr: np.ndarray, col: np.ndarray,
                 val: np.ndarray) -> None:
    """P <- Phi P Phi' + Qd (its upper triangle mirrored), Phi given row-compressed (ptr, col, val)."""
    n = P.shape[0]
    for i in range(n):  # W = Phi P
        for j in range(n):
            W[i, j] = 0.0
        row_sums(i, ptr, col, val, P, W)
    for i in range(n):  # W <- W' = P Phi'
        for j in range(i + 1, n):
            t = W[i, j]
            W[i, j] = W[j, i]
            W[j, i] = t
    for i in range(n):  # P = Phi W' + Qd
        for j in range(n):
            P[i, j] = qd[i, j]
        row_sums(i, ptr, col, val, W, P)
    for i in range(n):  # the upper triangle, mirrored
        for j in range(i + 1, n):
            P[j, i] = P[i, j]


@njit(cache=True)
def predict(x: np.ndarray, P: np.ndarray, phi: np.ndarray, qd: np.ndarray, ws: tuple) -> None:
    """x <- Phi x ; P <- Phi P Phi' + Qd, in place (x (n,), P (n, n) symmetric, Phi, Qd (n, n) over the epoch,
    the states' units). Products over the nonzeros of Phi: O(nnz(Phi) n)."""
    W, v, val, ptr, col = ws
    n = x.shape[0]
    csr(phi, ptr, col, val)
    for i in range(n):
        acc = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            acc += val[p] * x[col[p]]
        v[i] = acc
    for i in range(n):
        x[i] = v[i]
    _predict_cov(P, qd, W, ptr, col, val)


@njit(cache=True)
def predict_cov(P: np.ndarray, phi: np.ndarray, qd: np.ndarray, ws: tuple) -> None:
    """P <- Phi P Phi' + Qd in place (P (n, n) symmetric): `predict` without a state (a shared covariance)."""
    W, _, val, ptr, col = ws
    csr(phi, ptr, col, val)
    _predict_cov(P, qd, W, ptr, col, val)


@njit(cache=True)
def gain(P: np.ndarray, h: np.ndarray, r: float, b: np.ndarray) -> float:
    """b = P h (n,) and returns S = h' P h + r, for a measurement row h (n,) (mostly zeros) of noise variance r:
    b summed over P's columns at h's nonzeros."""
    n = P.shape[0]
    for i in range(n):
        b[i] = 0.0
    for l in range(n):
        c = h[l]
        if c != 0.0:
            for i in range(n):
                b[i] += P[i, l] * c
    hb = 0.0
    for l in range(n):
        if h[l] != 0.0:
            hb += h[l] * b[l]
    return hb + r


@njit(cache=True)
def _joseph_cov(P: np.ndarray, b: np.ndarray, S: float, c: float, kc: np.ndarray) -> None:
    """P <- P - Kc b' - b Kc' + S Kc Kc', Kc = c b / S, on the rows where b is nonzero (elsewhere the change is
    zero: the other rows keep their entries, and in the rows updated the columns where b = 0 add exact zeros)."""
    n = P.shape[0]
    for i in range(n):
        kc[i] = c * (b[i] / S)
    for i in range(n):
        bi = b[i]
        if bi != 0.0:
            ki = kc[i]
            for j in range(n):
                P[i, j] = P[i, j] - (ki * b[j] + bi * kc[j]) + (ki * kc[j]) * S


@njit(cache=True)
def joseph(x: np.ndarray, P: np.ndarray, b: np.ndarray, S: float, nu: float, w: float, c: float,
           ws: tuple) -> None:
    """The scalar update after `gain` (b = P h, S), in place: x <- x + w K nu, K = b / S;
    P <- P - Kc b' - b Kc' + S Kc Kc', Kc = c K (c = 1 - sqrt(1 - psi'); module docstring). nu = z - h' x (the
    innovation, the row's units)."""
    kc = ws[1]
    n = x.shape[0]
    if w != 0.0:
        for i in range(n):
            x[i] = x[i] + w * (b[i] / S) * nu
    if c != 0.0:
        _joseph_cov(P, b, S, c, kc)


@njit(cache=True)
def update(x: np.ndarray, P: np.ndarray, h: np.ndarray, nu: float, r: float, b: np.ndarray, ws: tuple) -> float:
    """The optimal scalar update (w = c = 1) in place: `gain` then `joseph`; returns S = h' P h + r (P before).
    h (n,) the row, nu = z - h' x its innovation, r its noise variance; b (n,) receives P h (before)."""
    S = gain(P, h, r, b)
    joseph(x, P, b, S, nu, 1.0, 1.0, ws)
    return S


@njit(cache=True)
def shared_update(X: np.ndarray, nu: np.ndarray, P: np.ndarray, h: np.ndarray, r: float, b: np.ndarray,
                  ws: tuple) -> float:
    """One optimal scalar update of a covariance P (n, n) shared by M runs, in place: K = P h / S from the
    shared P; each run m's state X[m] (M, n) takes its own innovation nu[m] (its z - g(x_hat_m)):
    X[m] <- X[m] + nu[m] K, row by row (a run's numbers do not depend on M); P Joseph as `update`. Returns S."""
    kc = ws[1]
    S = gain(P, h, r, b)
    n = P.shape[0]
    for i in range(n):
        kc[i] = b[i] / S
    for m in range(X.shape[0]):
        for i in range(n):
            X[m, i] = X[m, i] + nu[m] * kc[i]
    _joseph_cov(P, b, S, 1.0, kc)
    return S


@njit(cache=True)
def riccati(P: np.ndarray, phi: np.ndarray, qd: np.ndarray, H: np.ndarray, R: np.ndarray, epochs: int) -> None:
    """The optimal filter's covariance over `epochs` epochs of a fixed model, in place on P (n, n):

        P- = Phi P+ Phi' + Qd ;  then for each row h_k of H (k, n), r_k = R[k]:  P <- Joseph update (c = 1)

    (nav/initial.converged_covariance_reference's recursion). Exact reduction: a state j that is never measured
    (H[:, j] = 0) and not coupled (row and column j of Phi, Qd and P zero off the diagonal) keeps that form,
    P_jj <- Phi_jj P_jj Phi_jj + Qd_jj, untouched by the updates (its gain is 0); the rest run the full recursion.
    """
    n = P.shape[0]
    alone = np.ones(n, dtype=np.bool_)
    for i in range(n):
        for k in range(H.shape[0]):
            if H[k, i] != 0.0:
                alone[i] = False
        for j in range(n):
            if i != j and (phi[i, j] != 0.0 or qd[i, j] != 0.0 or P[i, j] != 0.0):
                alone[i] = False
                alone[j] = False
    m = 0
    idx = np.empty(n, dtype=np.int64)
    for i in range(n):
        if not alone[i]:
            idx[m] = i
            m += 1
    for i in range(n):
        if alone[i]:
            p, f, q = P[i, i], phi[i, i], qd[i, i]
            for _ in range(epochs):
                p = f * p * f + q
            P[i, i] = p
    if m == 0:
        return
    Pr = np.empty((m, m))
    pr = np.empty((m, m))
    qr = np.empty((m, m))
    Hr = np.empty((H.shape[0], m))
    for a in range(m):
        for c in range(m):
            Pr[a, c] = P[idx[a], idx[c]]
            pr[a, c] = phi[idx[a], idx[c]]
            qr[a, c] = qd[idx[a], idx[c]]
        for k in range(H.shape[0]):
            Hr[k, a] = H[k, idx[a]]
    W = np.empty((m, m))
    ptr = np.empty(m + 1, dtype=np.int64)
    col = np.empty(m * m, dtype=np.int64)
    val = np.empty(m * m)
    csr(pr, ptr, col, val)
    b = np.empty(m)
    kc = np.empty(m)
    for _ in range(epochs):
        _predict_cov(Pr, qr, W, ptr, col, val)
        for k in range(H.shape[0]):
            S = gain(Pr, Hr[k], R[k], b)
            _joseph_cov(Pr, b, S, 1.0, kc)
    for a in range(m):
        for c in range(m):
            P[idx[a], idx[c]] = Pr[a, c]
