"""Compiled measurement rows of the error-state filter (numba, cache=True): the baro, radar-altimeter and
pseudorange rows of nav/measurements.py (its module docstring gives the equations), for one run, written into a
caller's buffer h (n,) with the innovation returned:

    nu = z - g(x_hat)   (the EKF innovation: the linearized z_lin - h' x_hat of nav/measurements.py)

and the noise variance r (m^2). The `*_nu_many` forms give only the innovations of M runs, each at its own
estimate X[m] and INS position (the shared-covariance path), one run at a time (a run's value does not depend on
the others).

Inputs as plain arrays (nav/measurements.py builds them: `terrain_arrays`, `database_arrays`):

    lay (LAY_SIZE,)         the state layout (kernels.errormodel, StateLayout.packed)
    tx, th (k,)             the filter's terrain: ellipsoid height th (m) against runway-frame along-track x (m),
                            linear between points, held beyond the ends (profile.Terrain; flat: one point)
    rwy (6,)                the runway frame: ECEF origin (3,) m, and the ECEF -> along-track unit row (3,)
    dbp (4,)                the terrain-database error: (bias m, sigma_m, outer_sigma_m, area4_length_m)
                            (nav/terrain_db.py: sigma(x) = sigma_m for x >= -area4_length_m, else outer_sigma_m)
    db_x (k_db,), db_u      the run's unit Gauss-Markov realization on its grid (k_db = 0: no realization, e = 0);
                            db_u (k_db,) for one run, (N, k_db) in the many-run form
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.core import geodesy as gk
from approachsim.core.jit import njit
from approachsim.core.nav import errormodel as ek
from approachsim.core.sensors import gnss_errors as ge


@njit(cache=True)
def interp(x: float, xp: np.ndarray, fp: np.ndarray) -> float:
    """numpy.interp of one point (its arithmetic: fp[j] + slope (x - xp[j]), held beyond the ends)."""
    n = xp.shape[0]
    if x != x:
        return x
    if n == 1 or x <= xp[0]:
        return fp[0]
    if x >= xp[n - 1]:
        return fp[n - 1]
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xp[mid] <= x:
            lo = mid
        else:
            hi = mid
    j = lo
    if xp[j] == x:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    res = slope * (x - xp[j]) + fp[j]
    if res != res:
        res = slope * (x - xp[j + 1]) + fp[j + 1]
        if res != res and fp[j] == fp[j + 1]:
            res = fp[j]
    return res


@njit(cache=True)
def along_m(r0: float, r1: float, r2: float, rwy: np.ndarray) -> float:
    """Runway-frame along-track x (m) of an ECEF point: c_x . (r - origin) (geo.RunwayFrame.from_ecef[0])."""
    return (r0 - rwy[0]) * rwy[3] + (r1 - rwy[1]) * rwy[4] + (r2 - rwy[2]) * rwy[5]


@njit(cache=True)
def terrain_h(r0: float, r1: float, r2: float, tx: np.ndarray, th: np.ndarray, rwy: np.ndarray) -> float:
    """The filter's terrain ellipsoid height (m) under an ECEF point: th interpolated at its along-track x."""
    return interp(along_m(r0, r1, r2, rwy), tx, th)


@njit(cache=True)
def database_error(along: float, dbp: np.ndarray, db_x: np.ndarray, db_u: np.ndarray) -> tuple[float, float]:
    """(e, sigma): the run's database error e(x) = bias + sigma(x) u(x) (m; 0 without a realization) and the
    correlated 1-sigma sigma(x) (m) at along-track x (nav/terrain_db.py)."""
    sig = dbp[1] if along >= -dbp[3] else dbp[2]
    if db_x.shape[0] == 0:
        return 0.0, sig
    return dbp[0] + sig * interp(along, db_x, db_u), sig


@njit(cache=True)
def baro_nu(lay: np.ndarray, x_hat: np.ndarray, h_ins: float, h_baro: float, h_ref: float) -> float:
    """Innovation of the baro row: nu = (h_ins - h_baro) - (-dp_D - bb - (h_ins + dp_D - H_ref) sb), m, at the
    estimate (h_ins + dp_D: the navigation's height; nav/measurements.baro says why); h_ref = H_ref the
    altimeter-setting reference (the field), m."""
    dpd = x_hat[lay[ek.L_DP] + 2]
    pred = -dpd - x_hat[lay[ek.L_BB]]
    if lay[ek.L_SB] >= 0:
        pred = pred - (h_ins + dpd - h_ref) * x_hat[lay[ek.L_SB]]
    return (h_ins - h_baro) - pred


@njit(cache=True)
def baro(lay: np.ndarray, x_hat: np.ndarray, h_ins: float, h_baro: float, sigma: float, h: np.ndarray,
         h_ref: float) -> tuple[float, float]:
    """Baro altitude difference z = h_ins - h_baro (m): h = -(1 + sb_hat) at dp_D (-1 without an sb state), -1 at bb,
    -(h_ins + dp_D_hat - H_ref) at sb (into h (n,); the navigation's height, x_hat's dp_D and sb), H_ref = h_ref the
    altimeter-setting reference (m); returns (nu, r = sigma^2) (nav/measurements.baro)."""
    h[:] = 0.0
    h[lay[ek.L_DP] + 2] = -1.0
    h[lay[ek.L_BB]] = -1.0
    if lay[ek.L_SB] >= 0:
        h[lay[ek.L_DP] + 2] = -1.0 - x_hat[lay[ek.L_SB]]
        h[lay[ek.L_SB]] = -(h_ins + x_hat[lay[ek.L_DP] + 2] - h_ref)
    return baro_nu(lay, x_hat, h_ins, h_baro, h_ref), sigma**2


@njit(cache=True)
def _radalt(lay: np.ndarray, x_hat: np.ndarray, lat: float, lon: float, h_ins: float, h_agl: float,
            tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray,
            db_u: np.ndarray, h: np.ndarray, row: bool) -> float:
    """nu of the radar-altimeter row (and the row into h when `row`): nav/measurements.radalt's arithmetic."""
    cn, ce, cd = gk.ned_axes(lat, lon)  # C_en's rows: north, east, down
    r0, r1, r2 = gk.geodetic_to_ecef(lat, lon, h_ins)
    ip = lay[ek.L_DP]
    d0, d1, d2 = x_hat[ip], x_hat[ip + 1], x_hat[ip + 2]
    q0 = r0 - (cn[0] * d0 + ce[0] * d1 + cd[0] * d2)  # r_hat = r_ins - C_ne dp_hat
    q1 = r1 - (cn[1] * d0 + ce[1] * d1 + cd[1] * d2)
    q2 = r2 - (cn[2] * d0 + ce[2] * d1 + cd[2] * d2)
    t_ins = terrain_h(r0, r1, r2, tx, th, rwy)
    t_hat = terrain_h(q0, q1, q2, tx, th, rwy)
    de, ts = database_error(along_m(r0, r1, r2, rwy), dbp, db_x, db_u)
    z = (h_ins - t_ins - de) - h_agl
    g_hat = (h_ins - t_ins) - ((h_ins + d2) - t_hat)  # exact difference at x_hat
    if row:
        tn = terrain_h(q0 + 10.0 * cn[0], q1 + 10.0 * cn[1], q2 + 10.0 * cn[2], tx, th, rwy)
        ts_ = terrain_h(q0 - 10.0 * cn[0], q1 - 10.0 * cn[1], q2 - 10.0 * cn[2], tx, th, rwy)
        te = terrain_h(q0 + 10.0 * ce[0], q1 + 10.0 * ce[1], q2 + 10.0 * ce[2], tx, th, rwy)
        tw = terrain_h(q0 - 10.0 * ce[0], q1 - 10.0 * ce[1], q2 - 10.0 * ce[2], tx, th, rwy)
        h[:] = 0.0
        h[ip] = -((tn - ts_) / 20.0)  # -dT/dN, m/m
        h[ip + 1] = -((te - tw) / 20.0)  # -dT/dE
        h[ip + 2] = -1.0
    for g, c in ((ek.L_RAB, -1.0), (ek.L_RAM, -1.0), (ek.L_TDB, -ts)):
        i = lay[g]
        if i >= 0:
            if row:
                h[i] = c
            g_hat += c * x_hat[i]  # linear in the correlated-error states
    return z - g_hat


@njit(cache=True)
def radalt(lay: np.ndarray, x_hat: np.ndarray, lat: float, lon: float, h_ins: float, h_agl: float, sigma: float,
           tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray, db_x: np.ndarray, db_u: np.ndarray,
           h: np.ndarray) -> tuple[float, float]:
    """Radar altimeter: z = (h_ins - T_db(r_ins)) - h_R, T_db = T + e (the run's database at the INS position),
    g(x) = (h_ins - T(r_ins)) - (h_ins + dp_D - T(r_hat)) - rab - ram - sigma_db tdb, r_hat = r_ins - C_ne dp.

    lat, lon (rad), h_ins (m): the INS position; h_agl (m) the measured height above terrain; sigma (m) its
    noise. Row into h (n,): -dT/dN, -dT/dE (central differences over 10 m at r_hat), -1 at dp_D, -1 at rab, ram,
    -sigma_db(x) at tdb. Returns (nu, r = sigma^2)."""
    nu = _radalt(lay, x_hat, lat, lon, h_ins, h_agl, tx, th, rwy, dbp, db_x, db_u, h, True)
    return nu, sigma**2


@njit(cache=True)
def ranges(x_hat: np.ndarray, ip: int, r_ins: np.ndarray, c_en: np.ndarray,
           r_tx: np.ndarray) -> tuple[float, float, float, float, float]:
    """d_hat = r_ins - C' dp_hat - r_tx (ECEF, m; dp_hat = x_hat[ip:ip + 3] NED, C = c_en (3, 3) ECEF -> NED), its
    length |d_hat| (the range from the corrected position) and |r_ins - r_tx| (from the INS), m: the geometry of
    the pseudorange and carrier-phase rows (pseudorange; core/nav/carrier.carrier_phase)."""
    d0, d1, d2 = x_hat[ip], x_hat[ip + 1], x_hat[ip + 2]
    a0 = r_ins[0] - (c_en[0, 0] * d0 + c_en[1, 0] * d1 + c_en[2, 0] * d2) - r_tx[0]
    a1 = r_ins[1] - (c_en[0, 1] * d0 + c_en[1, 1] * d1 + c_en[2, 1] * d2) - r_tx[1]
    a2 = r_ins[2] - (c_en[0, 2] * d0 + c_en[1, 2] * d1 + c_en[2, 2] * d2) - r_tx[2]
    b0, b1, b2 = r_ins[0] - r_tx[0], r_ins[1] - r_tx[1], r_ins[2] - r_tx[2]
    return a0, a1, a2, math.sqrt(a0 * a0 + a1 * a1 + a2 * a2), math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)


@njit(cache=True)
def los_row(h: np.ndarray, ip: int, c_en: np.ndarray, a0: float, a1: float, a2: float, rng_hat: float,
            scale: float) -> None:
    """The row's position part h[ip:ip + 3] = (C e) scale, e = d_hat / |d_hat| the unit vector transmitter ->
    corrected position (ECEF; `ranges`), C = c_en ECEF -> NED: d range / d dp_NED, times scale (1 + T for a
    pseudolite's troposphere state, else 1)."""
    u0, u1, u2 = a0 / rng_hat, a1 / rng_hat, a2 / rng_hat
    for k in range(3):
        h[ip + k] = (c_en[k, 0] * u0 + c_en[k, 1] * u1 + c_en[k, 2] * u2) * scale


@njit(cache=True)
def iono_field_row(c_en: np.ndarray, a0: float, a1: float, a2: float, rng_hat: float) -> tuple[float, float, float]:
    """(F, F (d / d_5) sin az, F (d / d_5) cos az): the slant ionospheric delay per unit of the zenith field's common
    part and of its east and north planar gradient (per d_5) for a satellite whose line of sight is d_hat = (a0, a1,
    a2) (ECEF, m, satellite -> corrected position; `ranges`) of length rng_hat. F = gnss_errors.iono_obliquity
    (DO-229's F_pp at IONO_SHELL_M), d = gnss_errors.pierce_distance_m the pierce point's ground distance (d_5 at
    GRADIENT_REFERENCE_EL_RAD), el and az of the unit vector position -> satellite in NED (C = c_en ECEF -> NED):
    the zenith ionospheric states' coefficients in the code row (with the minus sign of a range error)."""
    u0, u1, u2 = a0 / rng_hat, a1 / rng_hat, a2 / rng_hat
    n = -(c_en[0, 0] * u0 + c_en[0, 1] * u1 + c_en[0, 2] * u2)  # towards the satellite
    e = -(c_en[1, 0] * u0 + c_en[1, 1] * u1 + c_en[1, 2] * u2)
    up = c_en[2, 0] * u0 + c_en[2, 1] * u1 + c_en[2, 2] * u2
    cos_el = math.sqrt(n * n + e * e)
    f = ge.iono_obliquity(cos_el, ge.IONO_SHELL_M)
    g = f * ge.pierce_distance_m(math.atan2(up, cos_el), ge.IONO_SHELL_M) / ge.pierce_distance_m(
        ge.GRADIENT_REFERENCE_EL_RAD, ge.IONO_SHELL_M)
    if cos_el == 0.0:
        return f, 0.0, 0.0
    return f, g * e / cos_el, g * n / cos_el


@njit(cache=True)
def zenith_mapping(c_en: np.ndarray, a0: float, a1: float, a2: float, rng_hat: float) -> float:
    """M(el) (gnss_errors.tropo_mapping, RTCA DO-229 A.4.2.4) of a satellite whose line of sight is d_hat = (a0, a1,
    a2) as iono_field_row's: sin el = the down component of the unit vector satellite -> position. The zenith
    tropospheric state's coefficient in the code row."""
    d = (c_en[2, 0] * a0 + c_en[2, 1] * a1 + c_en[2, 2] * a2) / rng_hat
    return ge.tropo_mapping(d)


@njit(cache=True)
def _pseudorange(lay: np.ndarray, x_hat: np.ndarray, r_ins: np.ndarray, c_en: np.ndarray, r_tx: np.ndarray,
                 rho: float, sv: int, pl: int, h: np.ndarray, row: bool) -> float:
    """nu of a pseudorange row (and the row into h when `row`): nav/measurements.pseudorange's arithmetic."""
    ip = lay[ek.L_DP]
    a0, a1, a2, rng_hat, rng_ins = ranges(x_hat, ip, r_ins, c_en, r_tx)
    lin = 0.0  # h' x_hat over the states the difference is linear in (clock and channel errors)
    ic = lay[ek.L_CLK]
    if row:
        h[:] = 0.0
    if ic >= 0:
        lin -= x_hat[ic]
        if row:
            h[ic] = -1.0
    if sv >= 0 and lay[ek.L_GSE] >= 0:
        i, j = lay[ek.L_GSE] + sv, lay[ek.L_GMP] + sv
        lin -= x_hat[i]
        lin -= x_hat[j]
        if row:
            h[i] = -1.0
            h[j] = -1.0
        i = lay[ek.L_GIZ]
        if i >= 0:  # the zenith ionospheric field at the satellite's pierce point, from the corrected position
            f0, fe, fn = iono_field_row(c_en, a0, a1, a2, rng_hat)
            lin -= f0 * x_hat[i] + fe * x_hat[i + 1] + fn * x_hat[i + 2]
            if row:
                h[i], h[i + 1], h[i + 2] = -f0, -fe, -fn
        i = lay[ek.L_GTZ]
        if i >= 0:  # the zenith troposphere times the satellite's mapping
            f = -zenith_mapping(c_en, a0, a1, a2, rng_hat)
            lin += f * x_hat[i]
            if row:
                h[i] = f
    scale = 1.0
    if pl >= 0 and lay[ek.L_PMP] >= 0:
        i, t = lay[ek.L_PMP] + pl, lay[ek.L_PTR] + pl
        lin -= x_hat[i]
        scale = 1.0 + x_hat[t]  # range (1 + T): the troposphere residual
        if row:
            h[i] = -1.0
            h[t] = -rng_hat
        k = lay[ek.L_PCLK]
        if k >= 0:
            lin -= x_hat[k + 2 * pl]
            if row:
                h[k + 2 * pl] = -1.0
        k = lay[ek.L_PSY]
        if k >= 0:
            lin -= x_hat[k + pl]
            if row:
                h[k + pl] = -1.0
    if row:  # e' (1 + T) at dp, e the unit vector transmitter -> corrected position, NED
        los_row(h, ip, c_en, a0, a1, a2, rng_hat, scale)
    z = rng_ins - rho
    g_hat = rng_ins - rng_hat * scale + lin  # exact in dp (and T), linear in the rest
    return z - g_hat


@njit(cache=True)
def pseudorange(lay: np.ndarray, x_hat: np.ndarray, r_ins: np.ndarray, c_en: np.ndarray, r_tx: np.ndarray,
                rho: float, sigma: float, sv: int, pl: int, h: np.ndarray) -> tuple[float, float]:
    """A code pseudorange rho (m) to a satellite (sv its channel, else -1) or pseudolite (pl its unit, else -1),
    tightly coupled: z = |r_ins - r_tx| - rho, g(x) = |r_ins - r_tx| - |r_ins - C' dp - r_tx| (1 + T) - clk
    - (channel errors) - F_pp (giz_0 + (d / d_5)(sin az giz_E + cos az giz_N)) - M gtz. r_ins, r_tx (3,) ECEF m;
    c_en (3, 3) ECEF -> NED at the INS position. Row into h (n,): e' (1 + T) at dp, -1 at clk and the channel's gse,
    gmp (pmp, pclk, psy), -range at ptr, and in a satellite's row minus iono_field_row's coefficients at the zenith
    ionospheric states giz and -M (zenith_mapping) at the zenith troposphere gtz. Returns (nu, sigma^2)."""
    nu = _pseudorange(lay, x_hat, r_ins, c_en, r_tx, rho, sv, pl, h, True)
    return nu, sigma**2


@njit(cache=True)
def baro_nu_many(lay: np.ndarray, X: np.ndarray, h_ins: np.ndarray, h_baro: np.ndarray, h_ref: float,
                 nu: np.ndarray) -> None:
    """nu[m] of the baro row for runs m: X (M, n) estimates, h_ins, h_baro (M,) m, h_ref the setting's reference, m."""
    for m in range(X.shape[0]):
        nu[m] = baro_nu(lay, X[m], h_ins[m], h_baro[m], h_ref)


@njit(cache=True)
def radalt_nu_many(lay: np.ndarray, X: np.ndarray, lat: np.ndarray, lon: np.ndarray, h_ins: np.ndarray,
                   h_agl: np.ndarray, tx: np.ndarray, th: np.ndarray, rwy: np.ndarray, dbp: np.ndarray,
                   db_x: np.ndarray, db_u: np.ndarray, db_row: np.ndarray, nu: np.ndarray) -> None:
    """nu[m] of the radar-altimeter row for runs m: X (M, n), the INS positions lat, lon (rad), h_ins (m) and the
    measured heights h_agl (M,) m; dbp (M, 4) each run's database parameters (bias first), db_u (N, k_db) the
    realizations of all runs and db_row (M,) the row of each run in it (any value when k_db = 0)."""
    empty = np.zeros(1)
    dummy = np.zeros(1)
    for m in range(X.shape[0]):
        u = db_u[db_row[m]] if db_x.shape[0] > 0 else empty
        nu[m] = _radalt(lay, X[m], lat[m], lon[m], h_ins[m], h_agl[m], tx, th, rwy, dbp[m], db_x, u, dummy,
                        False)


@njit(cache=True)
def pseudorange_nu_many(lay: np.ndarray, X: np.ndarray, r_ins: np.ndarray, c_en: np.ndarray, r_tx: np.ndarray,
                        rho: np.ndarray, sv: int, pl: int, nu: np.ndarray) -> None:
    """nu[m] of one channel's pseudorange row for runs m: X (M, n), r_ins (M, 3), c_en (M, 3, 3), r_tx (M, 3)
    (ECEF, m), rho (M,) m; sv / pl as `pseudorange`."""
    dummy = np.zeros(1)
    for m in range(X.shape[0]):
        nu[m] = _pseudorange(lay, X[m], r_ins[m], c_en[m], r_tx[m], rho[m], sv, pl, dummy, False)
