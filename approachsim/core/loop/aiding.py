"""The closed loop's aiding epoch as one compiled call (numba, cache=True): the per-run EKF's whole epoch
(core/nav/epoch.run_epoch) with what the Navigator does around it at an epoch of a feed-forward run, so that an
epoch of the closed loop costs one kernel call plus the sensors' one-row records (loop/closed_loop.py `_fast_epoch`).

    k = loop_epoch(nw, X, P, e, model, held, dt, f_ned, rows, obs, out, scr, (XS, PP, PC, PD, PN, ic, XD))
                                            the groups of core/nav/groups.py

in order:

    f_ned = f_sum / dt                      the interval's mean specific force (Navigator.epoch: (f_sum / dt))
    k = run_epoch(X, P, ..., y = INS state) predict + every scalar update (core/nav/epoch.py), X (1, n), P (n, n)
    when k >= 0 (the model fitted the compiled discretization):
        XS[e] = x, PP[e] = P[0:3, 0:3], PC[e] = P[ic, ic], PD[e] = diag P, PN[e] = P[0:9, 0:9]
                                            the filter snapshot and epoch history (Navigator._snapshot(epoch=True))
        XD[e] = F x (rows 0-8, core/nav/output.nav_rate; F the interval's model, scr.F)
        f_sum <- 0;  the estimate in force x[0:9] and its rate -> the row's work vector (core/loop/nav_row.py
        W_XNAV, W_XDOT; the caller sets its time W_T_EST);
        the "baro in the interval" flag W_ANY_BARO <- 0

nw is the closed loop's work vector (core/layouts.py NAV_WORK): the INS state y at W_X, f_sum at W_FSUM.
direct_inputs makes that epoch's sensor inputs (baro, radar altimeter, GPS sky + pseudoranges, the channel guard) by
the sensors' own kernels in one call (closed_loop.py `_direct_inputs`).

Copies only, and one division: the snapshot's numbers are the same bits as the Navigator's numpy path; the oracle is
that path (NavInTheLoop with the fast epoch off): tests/unit/nav/test_closed_loop_epoch.py flies both.
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.core import layouts
from approachsim.core.jit import njit
from approachsim.core.nav import epoch as ke
from approachsim.core.nav import groups as kg
from approachsim.core.nav import output as ko
from approachsim.core.sensors import baro as bk
from approachsim.core.sensors import gnss as gk
from approachsim.core.sensors import gnss_errors as ge
from approachsim.core.sensors import radalt as rk


@njit(cache=True)
def loop_epoch(nw: np.ndarray, X: np.ndarray, P: np.ndarray, e: int, model: kg.ErrorModel, held: bool, dt: float,
               f_ned: np.ndarray, rows: kg.Rows, obs: kg.Obs, out: kg.Out, scr: kg.Scratch, hist: tuple) -> int:
    """The closed loop's epoch e (module docstring): core/nav/epoch.run_epoch on the run's INS state in the work
    vector, then the Navigator's bookkeeping: hist = (XS, PP, PC, PD, PN, ic, XD), the estimate, position block,
    clock variance, diagonal and navigation block of P after each epoch, the clock's index, and the estimate's rate
    (9,) after each epoch. Returns run_epoch's
    number of rows, or -1 (nothing changed: the model needs the numpy discretization, the caller takes the
    Navigator's path). f_ned (3,) scratch."""
    XS, PP, PC, PD, PN, ic, XD = hist
    for c in range(3):
        f_ned[c] = nw[layouts.W_FSUM + c] / dt
    y = nw[layouts.W_X:layouts.W_X + layouts.NX]
    # no carrier phase on this path (loop/paths.py sends it to the Navigator's): no new arcs
    k = ke.run_epoch(X, P, model, y, f_ned, held, dt, np.zeros(0, dtype=np.int64), rows, obs, out, scr)
    if k < 0:
        return k
    n = P.shape[0]
    for i in range(n):
        XS[e, i] = X[0, i]
        PD[e, i] = P[i, i]
    for i in range(3):
        for j in range(3):
            PP[e, i, j] = P[i, j]
    for i in range(9):
        for j in range(9):
            PN[e, i, j] = P[i, j]
    PC[e] = P[ic, ic]
    ko.nav_rate(scr.F, X[0], XD[e])
    for c in range(3):
        nw[layouts.W_FSUM + c] = 0.0
    for i in range(9):
        nw[layouts.W_XNAV + i] = X[0, i]
        nw[layouts.W_XDOT + i] = XD[e, i]
    nw[layouts.W_ANY_BARO] = 0.0
    return k


RAD_TO_DEG = 180.0 / math.pi
"""numpy's degrees() factor (npy_rad2deg: x * (180 / pi))."""


@njit(cache=True)
def channel_guard(el: np.ndarray, lo: float, g: np.ndarray, mp_arg: np.ndarray) -> None:
    """The GPS channel states' elevations as the noise model guards them (nav/noise.py): g = max(el, lo) with nan
    read as 0.5 rad, and mp_arg = -degrees(g) / 10, the argument of DO-253's multipath curve
    (core/sensors/gnss_errors.py guard_elevation, do253_exponent). numpy's operations one by one (where, maximum,
    degrees, negative, divide): exact in IEEE arithmetic, the same bits."""
    for i in range(el.shape[0]):
        e = ge.guard_elevation(el[i], lo)
        g[i] = e
        mp_arg[i] = ge.do253_exponent(e)


@njit(cache=True)
def channel_sigmas(cos_g: np.ndarray, sin_g: np.ndarray, exp_mp: np.ndarray, a_m: float, shell_m: float,
                   ce2: float, iono_zenith_m: float, tropo_zenith_m: float, do253: bool, gse: np.ndarray,
                   gmp: np.ndarray) -> None:
    """A stand-alone budget's channel sigmas (receiver.GnssErrorBudget.channel_sigmas_m, m) from numpy's cos, sin of
    the guarded elevations and exp of mp_arg (channel_guard): core/sensors/gnss_errors.channel_sigmas, gse =
    sqrt(ce^2 + (I_z F)^2 + (T_z M)^2), gmp = 0.13 + 0.53 exp (do253; else gmp is left as it is); a_m is that
    module's R (the WGS-84 a). The same operations in numpy's order (no transcendental function here: those stay
    numpy's, whose last bit numba's may not match), the same bits."""
    for i in range(cos_g.shape[0]):  # a_m: gnss_errors' R (the same WGS-84 a)
        gse[i], gmp[i] = ge.channel_sigmas(cos_g[i], sin_g[i], exp_mp[i], shell_m, ce2, iono_zenith_m,
                                           tropo_zenith_m, do253, gmp[i])


HAS_BARO = 1
"""direct_inputs' flag: the baro has a sample at the row (its height in b_hold)."""
BARO_IN = 2
"""... and it is the epoch's (its time within tol of t): baro_h = that height."""
RADALT_IN = 4
"""The radar altimeter's sample is the epoch's: radalt_h = its height (nan when not valid)."""
GNSS_IN = 8
"""The GPS sample is the epoch's: rho, r_sv_out, sig_out, el_out (and g, mp_arg when guarded) are set."""


@njit(cache=True)
def _service_pseudoranges(rng: np.ndarray, el: np.ndarray, az: np.ndarray, sel: np.ndarray, p: np.ndarray,
                          shape: np.ndarray, series: tuple, noise: np.ndarray, clk: np.ndarray, j: int,
                          scr: tuple) -> tuple[np.ndarray, np.ndarray]:
    """sensors/gnss/receiver.py service_pseudoranges and the broadcast sigma_i (ServiceModel.sigma_m, into scr[7])
    of one run's sample j on a one-sample sky: the same kernels on arrays of the same types (the sample's noise and
    clock copied into scr's contiguous scratch), so the same bits as GnssReceiver.record's."""
    one, slow, air, nz, b, gse, gmp, tot = scr
    gk.service_errors(el, az, p, shape, series, j, slow, air)
    for c in range(nz.shape[2]):
        nz[0, 0, c] = noise[0, j, c]
    b[0, 0] = clk[0, j]
    gk.service_channel_sigmas(el[0], p, False, gse, gmp, tot)
    return gk.pseudorange_sum(rng, sel, ((one, slow), (one, air), (one, nz)), b)


@njit(cache=True)
def direct_inputs(k: int, t: float, tol: float, jb: int, jr: int, jg: int, plan: np.ndarray, baro: tuple,
                  radalt: tuple, gnss: tuple, service: tuple, out: tuple, guard: tuple) -> int:
    """The closed loop's direct epoch inputs at truth row k (time t) in one call (loop/closed_loop.py
    `_direct_inputs`): the sensors' one-row kernels on the values their h_one / channels_one give them, the same
    kernels in the same order, so the same bits. Each sensor's constants, drawn errors, scratch and outputs come as
    one tuple (loop/closed_loop.py `_direct_arrays` builds them once a run):

        baro   = (p_static, b_w, b_set, b_t0l, b_exp, b_fld, b_cm1, b_sf, b_bias, b_noise, b_ts, b_p, b_out, b_hold,
                  baro_h)
        radalt = (h_agl, euler, r_bias, r_markov, r_noise, r_ts, r_pct, r_floor2, r_max, r_pitch_max, r_roll_max,
                  r_in, r_meas, r_sig, r_valid, radalt_h)
        gnss   = (r_ecef, r_sv_all, mask, mode, shell, do253, mp_m, ce2, iono_z, tropo_z, cn2, s_ce, s_iono, s_tropo,
                  s_mp, s_noise, clk, g_ts, scale, g_rx, g_sv)
        service = (on, p, shape, series, noise, (one, slow, air, nz, b, gse, gmp, tot))   a GNSS service's truth
                  (on: the pseudoranges are service_errors' instead of the stand-alone terms s_ce..s_noise; p, shape
                  the packed parameters, series the unit series, noise m; then scratch, one-sample C arrays)
        out    = (rho, r_sv_out, sig_out, el_out);  guard = (guard, lo, g, mp_arg)

        baro sample jb (-1: none): p[0, q] = p_static[max(k - q, 0)] (q < len b_p), baro_apply -> b_hold[0]; when
            |b_ts[jb] - t| <= tol: baro_h[0] = that height (else nan)                       (PreparedBaro.h_one)
        radar altimeter sample jr: radalt_apply on row k; radalt_h[0] = the height where valid and in time, else
            nan                                                                             (PreparedRadalt.h_one)
        GPS sample jg in time: sky on (r_ecef[k], r_sv_all[:, jg]) (copied to g_rx, g_sv) with the selection plan,
            pseudoranges on the series' sample jg: rho (1, 24) (nan where not selected), r_sv_out = r_sv_all[0, jg],
            sig_out = sigma (times scale when scale != 1), el_out = elevations; guard: channel_guard(el_out, lo, g,
            mp_arg)                                                                         (PreparedGnss.channels_one)
            with a service: receiver.service_pseudoranges on sample jg, sig_out the broadcast sigma_i
                                                                                            (GnssReceiver.record)

    Returns the flags HAS_BARO | BARO_IN | RADALT_IN | GNSS_IN of what was set."""
    (p_static, b_w, b_set, b_t0l, b_exp, b_fld, b_cm1, b_sf, b_bias, b_noise, b_ts, b_p, b_out, b_hold,
     baro_h) = baro
    (h_agl, euler, r_bias, r_markov, r_noise, r_ts, r_pct, r_floor2, r_max, r_pitch_max, r_roll_max, r_in, r_meas,
     r_sig, r_valid, radalt_h) = radalt
    (r_ecef, r_sv_all, mask, mode, shell, do253, mp_m, ce2, iono_z, tropo_z, cn2, s_ce, s_iono, s_tropo, s_mp,
     s_noise, clk, g_ts, scale, g_rx, g_sv) = gnss
    rho, r_sv_out, sig_out, el_out = out
    do_guard, lo, g, mp_arg = guard
    flags = 0
    baro_h[0] = math.nan
    radalt_h[0] = math.nan
    if jb >= 0:
        for q in range(b_p.shape[1]):
            i = k - q
            b_p[0, q] = p_static[i if i > 0 else 0]
        bk.baro_apply(b_p, b_set, b_t0l, b_exp, b_fld, b_cm1, b_w, b_sf, b_bias[:, jb:jb + 1],
                      b_noise[:, jb:jb + 1], b_out)
        b_hold[0] = b_out[0, 0]
        flags |= HAS_BARO
        if abs(b_ts[jb] - t) <= tol:
            baro_h[0] = b_out[0, 0]
            flags |= BARO_IN
    if jr >= 0:
        r_in[0, 0] = h_agl[k]
        r_in[1, 0] = euler[k, 1]
        r_in[2, 0] = euler[k, 0]
        rk.radalt_apply(r_in[0], r_in[1], r_in[2], r_bias, r_markov[:, jr:jr + 1], r_noise[:, jr:jr + 1], r_pct,
                        r_floor2, r_max, r_pitch_max, r_roll_max, r_meas, r_sig, r_valid)
        if abs(r_ts[jr] - t) <= tol:
            radalt_h[0] = r_meas[0, 0] if r_valid[0, 0] else math.nan
            flags |= RADALT_IN
    if jg >= 0 and abs(g_ts[jg] - t) <= tol:
        for c in range(3):
            g_rx[0, c] = r_ecef[k, c]
        for i in range(g_sv.shape[0]):
            for s_ in range(g_sv.shape[2]):
                for c in range(g_sv.shape[3]):
                    g_sv[i, 0, s_, c] = r_sv_all[i, jg, s_, c]
        rng, u, el, az, vis, sel, pdop, f_iono, m_tropo, mp_scale, sigma = gk.sky(
            g_rx, g_sv, mask, mode, plan, shell, do253, mp_m, ce2, iono_z, tropo_z, cn2)
        on, sp, shape, series, noise, scr = service
        if on:
            pr, valid = _service_pseudoranges(rng, el, az, sel, sp, shape, series, noise, clk, jg, scr)
            sigma = scr[7].reshape((1,) + scr[7].shape)
        else:
            pr, valid = gk.pseudoranges(rng, f_iono, m_tropo, mp_scale, sel, s_ce[:, jg:jg + 1],
                                        s_iono[:, jg:jg + 1], s_tropo[:, jg:jg + 1], s_mp[:, jg:jg + 1],
                                        s_noise[:, jg:jg + 1], clk[:, jg:jg + 1])
        n = pr.shape[2]
        for i in range(n):
            rho[0, i] = pr[0, 0, i] if valid[0, 0, i] else math.nan
            for c in range(3):
                r_sv_out[i, c] = r_sv_all[0, jg, i, c]
            sig_out[i] = sigma[0, 0, i] if scale == 1.0 else sigma[0, 0, i] * scale
            el_out[i] = el[0, 0, i]
        if do_guard:
            channel_guard(el_out, lo, g, mp_arg)
        flags |= GNSS_IN
    return flags
