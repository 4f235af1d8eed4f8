"""The reduced-order filter's dropped channels (nav/reduced.py): their lone Gauss-Markov states predicted over an
epoch span in one compiled call, with the same sums as the full filter's predict (core/nav/kalman._predict_cov)."""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit
from approachsim.core.nav.groups import ChannelQd

Array = np.ndarray


@njit(cache=True)
def lone_states(f_g: Array, f_m: Array, chan: ChannelQd, drop: Array, ig: int, im: int, xg: Array, xm: Array,
                pg: Array, pm: Array, x_out: Array, pd_out: Array) -> None:
    """The dropped channels' gse / gmp states over the E epochs, in place from their start xg, xm, pg, pm (k_d,):
    each epoch x <- 0 + phi x and P <- Qd + phi (0 + phi P) (core/nav/kalman._predict_cov's sums for a lone state,
    Qd = sigma^2 f as core/nav/epoch.copies_epoch sets it; phi f_g, f_m (E,); chan the run's channel noise: sigmas
    gse, gmp (E, k), factors f_gse, f_gmp (E,), the slow states first scaled by gse_r (E, k) when it has columns,
    copies_epoch's D x, D P D); written to x_out, pd_out (E, n) at ig + drop, im + drop."""
    for e in range(f_g.shape[0]):
        for a in range(drop.shape[0]):
            c = drop[a]
            if chan.gse_r.shape[1] > 0:
                xg[a] = xg[a] * chan.gse_r[e, c]
                pg[a] = pg[a] * chan.gse_r[e, c] * chan.gse_r[e, c]
            xg[a] = 0.0 + f_g[e] * xg[a]
            xm[a] = 0.0 + f_m[e] * xm[a]
            pg[a] = chan.gse[e, c] ** 2 * chan.f_gse[e] + f_g[e] * (0.0 + f_g[e] * pg[a])
            pm[a] = chan.gmp[e, c] ** 2 * chan.f_gmp[e] + f_m[e] * (0.0 + f_m[e] * pm[a])
            x_out[e, ig + c] = xg[a]
            x_out[e, im + c] = xm[a]
            pd_out[e, ig + c] = pg[a]
            pd_out[e, im + c] = pm[a]
