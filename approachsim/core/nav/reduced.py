"""The reduced-order filter's dropped channels (nav/reduced.py): their lone Gauss-Markov states predicted over an
epoch span in one compiled call, with the same sums as the full filter's predict (core/nav/kalman._predict_cov)."""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit

Array = np.ndarray


@njit(cache=True)
def lone_states(f_g: Array, f_m: Array, ch_gse: Array, ch_gmp: Array, f_gse: Array, f_gmp: Array, gse_r: Array,
                drop: Array, ig: int, im: int, xg: Array, xm: Array, pg: Array, pm: Array, x_out: Array,
                pd_out: Array) -> None:
    """The dropped channels' gse / gmp states over the E epochs, in place from their start xg, xm, pg, pm (k_d,):
    each epoch x <- 0 + phi x and P <- Qd + phi (0 + phi P) (core/nav/kalman._predict_cov's sums for a lone state,
    Qd = sigma^2 f as core/nav/epoch.copies_epoch sets it; phi f_g, f_m (E,), the sigmas ch_gse, ch_gmp (E, k)
    of the run, factors f_gse, f_gmp (E,)), the slow states first scaled by gse_r (E, k) when it has columns
    (copies_epoch's D x, D P D); written to x_out, pd_out (E, n) at ig + drop, im + drop."""
    for e in range(f_g.shape[0]):
        for a in range(drop.shape[0]):
            c = drop[a]
            if gse_r.shape[1] > 0:
                xg[a] = xg[a] * gse_r[e, c]
                pg[a] = pg[a] * gse_r[e, c] * gse_r[e, c]
            xg[a] = 0.0 + f_g[e] * xg[a]
            xm[a] = 0.0 + f_m[e] * xm[a]
            pg[a] = ch_gse[e, c] ** 2 * f_gse[e] + f_g[e] * (0.0 + f_g[e] * pg[a])
            pm[a] = ch_gmp[e, c] ** 2 * f_gmp[e] + f_m[e] * (0.0 + f_m[e] * pm[a])
            x_out[e, ig + c] = xg[a]
            x_out[e, im + c] = xm[a]
            pd_out[e, ig + c] = pg[a]
            pd_out[e, im + c] = pm[a]
