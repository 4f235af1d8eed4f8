"""The navigation output at every IMU row as a compiled kernel (numba, cache=True): the feed-forward correction
of the raw INS rows by the filter estimate in force at each row, to ECEF position, NED velocity and Euler angles.

For row j at time t_j with the packed INS state y_j (kernels/strapdown.py layout) and the estimate in force,
x = X[s] + (t_j - T[s]) XD[s], s = snap[j] (error = INS - truth: dp NED m, dv m/s, psi rad; `estimate_at`), the
output is INS - x (nav/ins.py `perturb` with -x):

    lat = lat_ins - dp_N / (R_N + h),  lon = lon_ins - dp_E / ((R_E + h) cos lat_ins),  h = h_ins + dp_D
    v = v_ins - dv,   C_bn = Exp([psi x]) C_ins  (C_ins = (I - [psi x]) C_true)
    r_ecef = geodetic_to_ecef(lat, lon, h),  roll = atan2(C21, C22), pitch = -asin(C20), heading = atan2(C10, C00)
    (heading in [0, 2 pi))

The estimate between aiding epochs: X[s] is the filter's estimate after the epoch at T[s], XD[s] = F X[s] its rate
(rows 0-8, `nav_rate`) with F the error model the filter linearized for the interval that ended at T[s]
(core/nav/errormodel.dynamics, or nav/errormodel.py's on the numpy paths): the first-order propagation
x(t) = Phi(t - T) x ~ (I + F (t - T)) x of the estimated error over the next interval (<= 1 s), the same for the
closed loop's guidance (core/loop/nav_row.py). Held instead, the output lagged the INS's drift between epochs
(e.g. -sb v_D, the damping loop dragging the INS toward a scale-factor-biased baro: 0.35 m/s on a KDEN ISA +30
day). The covariance is the epoch's (P+ at T[s]; its growth over an interval is the process noise's).

The numpy oracle is ins.perturb + geo.geodetic_to_ecef + ins.euler_from_cbn (tests/unit/nav/test_nav_kernels.py).
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.core import geodesy as gk
from approachsim.core.jit import njit
from approachsim.core.nav.strapdown import _mm, rotation_exp

_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def nav_rate(F: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """The rate of the estimated navigation errors, out (9,) = F[0:9, :] x (m/s, m/s^2, rad/s), F (n, n) the error
    model (1/s) and x (n,) the estimate: each row's sum in column order."""
    for i in range(9):
        a = 0.0
        for j in range(x.shape[0]):
            a += F[i, j] * x[j]
        out[i] = a


@njit(cache=True)
def estimate_at(x: np.ndarray, xd: np.ndarray, t_est: float, t: float, out: np.ndarray) -> None:
    """The estimated navigation errors (9,) at time t (s) into out: x + (t - t_est) xd, from the estimate x (>= 9,)
    at t_est and its rate xd (9,) (`nav_rate`)."""
    tau = t - t_est
    for i in range(9):
        out[i] = x[i] + tau * xd[i]


@njit(cache=True)
def corrected_rows(rows: np.ndarray, t: np.ndarray, X: np.ndarray, XD: np.ndarray, T: np.ndarray, snap: np.ndarray,
                   r_ecef: np.ndarray, v_ned: np.ndarray, euler: np.ndarray) -> None:
    """Fill r_ecef, v_ned, euler (m, 3) (m, m/s, rad) from the raw INS rows (m, 16) at times t (m,) s and the
    estimates X (s, >= 9), their rates XD (s, 9) and times T (s,) in force at each row (snap (m,) int, indices into
    X): the module docstring's equations."""
    x = np.empty(9)
    for j in range(rows.shape[0]):
        s = snap[j]
        estimate_at(X[s], XD[s], T[s], t[j], x)
        rot = rotation_exp(x[6], x[7], x[8])
        lat, lon, h = rows[j, 0], rows[j, 1], rows[j, 2]
        r_n, r_e = gk.radii(lat)
        lat_c = lat - x[0] / (r_n + h)
        lon_c = lon - x[1] / ((r_e + h) * math.cos(lat))
        h_c = h + x[2]
        ex, ey, ez = gk.geodetic_to_ecef(lat_c, lon_c, h_c)
        r_ecef[j, 0], r_ecef[j, 1], r_ecef[j, 2] = ex, ey, ez
        v_ned[j, 0], v_ned[j, 1], v_ned[j, 2] = rows[j, 3] - x[3], rows[j, 4] - x[4], rows[j, 5] - x[5]
        c0 = (rows[j, 6], rows[j, 7], rows[j, 8], rows[j, 9], rows[j, 10], rows[j, 11], rows[j, 12], rows[j, 13],
              rows[j, 14])
        c = _mm(rot, c0)
        euler[j, 0] = math.atan2(c[7], c[8])
        euler[j, 1] = -math.asin(min(max(c[6], -1.0), 1.0))
        euler[j, 2] = math.atan2(c[3], c[0]) % _TWO_PI


def corrected(rows: np.ndarray, t_s: np.ndarray, X: np.ndarray, XD: np.ndarray, T_s: np.ndarray, snap: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(r_ecef, v_ned, euler) (m, 3) of `corrected_rows` for raw INS rows (m, 16) at times t_s (m,), estimates
    X (s, n), their rates XD (s, 9) and times T_s (s,), snap (m,)."""
    m = rows.shape[0]
    r, v, e = np.empty((m, 3)), np.empty((m, 3)), np.empty((m, 3))
    c = np.ascontiguousarray
    corrected_rows(c(rows, dtype=float), c(t_s, dtype=float), c(X, dtype=float), c(XD, dtype=float),
                   c(T_s, dtype=float), c(snap, dtype=np.int64), r, v, e)
    return r, v, e
