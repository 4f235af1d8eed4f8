"""Compiled GPS geometry and pseudoranges (numba, cache=True): sensors/gnss/receiver.py's `GnssReceiver.apply`.

The numpy oracle is `GnssReceiver.apply_reference` (Constellation.positions_ecef / velocities_ecef, look_angles,
best_pdop_four_reference, dops); tests/unit/sensors/test_gnss_kernels.py checks the kernels against it: values to
1e-12 relative, selections identical. Axes: skies s (one per run with per-run epochs, else one), runs r, samples i,
channels j innermost. Every value of a (sky, sample) or (run, sample) is computed by the same scalar code whatever
the batch, so a run's bits do not depend on the runs it shares a call with, and one sample applied alone equals the
same sample of a batch bit for bit.

    sv_orbits          satellite positions (and velocities) on circular Kepler orbits at each sky's sample times
    look_angles        range, line of sight, elevation and azimuth of every satellite from the receiver
    sky                look angles, visibility, selection (all / best-PDOP four / a planned four), PDOP, mappings
    pseudorange_sum    range + scaled error terms + receiver clock for every run, nan where not selected
    pseudoranges       pseudorange_sum with the stand-alone receiver's terms (clock/ephemeris, iono, tropo, mp, noise)
    channel_sigmas     the navigation filter's GPS channel-state sigmas of a stand-alone budget, element by element
    service_channel_sigmas  a civil service's channel sigmas (broadcast, or the filter's own), element by element
    service_channel_terms   a civil service's broadcast range / iono / tropo / air sigmas, pierce distance
    service_errors     a civil service's true slow (range + iono + tropo) and airborne errors per channel
    gbas_scales        the GBAS-corrected residual's scales and nominal sigma per channel (gnss/gbas.py)
    gbas_channel_sigmas the navigation filter's GPS channel-state sigmas under GBAS, element by element
    pseudorange_rates  line-of-sight range rate + clock drift + noise for every run
    best_four_epochs   the best-PDOP four at each of a stack of epochs (best_four: one epoch)
"""

from __future__ import annotations

import math

import numpy as np
from numba import literal_unroll

from approachsim import geo
from approachsim.core import geodesy as gd
from approachsim.core import layouts as L
from approachsim.core.jit import njit
from approachsim.core.sensors import gnss_errors as ge

OMEGA_E = geo.OMEGA_E
TWO_PI = 2.0 * math.pi

MODE_ALL = 0
"""Selection: every visible channel."""
MODE_BEST4 = 1
"""Selection: the best-PDOP four at every epoch."""
MODE_PLANNED = 2
"""Selection: the planned four (plan) while all four are visible, else the best-PDOP four."""


@njit(cache=True)
def sv_orbits(u0: np.ndarray, raan: np.ndarray, a_m: float, ci: float, si: float, n_mot: float, u_ep: np.ndarray,
              g_ep: np.ndarray, t_s: np.ndarray, with_v: bool, r_out: np.ndarray, v_out: np.ndarray) -> None:
    """ECEF positions r_out (S, m, k, 3), m, of k circular orbits of radius a_m and inclination (cos ci, sin si) at
    the times t_s (m,) of each sky s, and when with_v their velocities relative to the rotating Earth v_out (same
    shape), m/s (constellation.py):

        u = u0 + u_ep[s] + n t  (argument of latitude),   l = raan - (g_ep[s] + OMEGA_E t)  (node longitude, ECEF)
        r = a (cos u cos l - sin u cos i sin l,  cos u sin l + sin u cos i cos l,  sin u sin i),   v = dr/dt
    """
    ld = -OMEGA_E
    for s in range(u_ep.shape[0]):
        for i in range(t_s.shape[0]):
            t = t_s[i]
            nt = n_mot * t
            lt = g_ep[s] + OMEGA_E * t
            for j in range(u0.shape[0]):
                u = u0[j] + u_ep[s] + nt
                lam = raan[j] - lt
                cu, su = math.cos(u), math.sin(u)
                cl, sl = math.cos(lam), math.sin(lam)
                r_out[s, i, j, 0] = a_m * (cu * cl - su * ci * sl)
                r_out[s, i, j, 1] = a_m * (cu * sl + su * ci * cl)
                r_out[s, i, j, 2] = a_m * (su * si)
                if with_v:
                    v_out[s, i, j, 0] = a_m * (-su * n_mot * cl - cu * sl * ld - cu * n_mot * ci * sl
                                               - su * ci * cl * ld)
                    v_out[s, i, j, 1] = a_m * (-su * n_mot * sl + cu * cl * ld + cu * n_mot * ci * cl
                                               - su * ci * sl * ld)
                    v_out[s, i, j, 2] = a_m * (cu * n_mot * si)


@njit(cache=True)
def _look(rx: np.ndarray, c: np.ndarray, r_sv: np.ndarray, rng: np.ndarray, u: np.ndarray, el: np.ndarray,
          az: np.ndarray) -> None:
    """One epoch (constellation.look_angles): d = r_sv - r_rx, range |d|, u = d / |d| (ECEF), u_ned = C u,
    el = asin(-u_d) (clipped to [-1, 1]), az = atan2(u_e, u_n) mod 2 pi."""
    for j in range(r_sv.shape[0]):
        dx, dy, dz = r_sv[j, 0] - rx[0], r_sv[j, 1] - rx[1], r_sv[j, 2] - rx[2]
        r = math.sqrt(dx * dx + dy * dy + dz * dz)
        ux, uy, uz = dx / r, dy / r, dz / r
        rng[j] = r
        u[j, 0], u[j, 1], u[j, 2] = ux, uy, uz
        n = c[0, 0] * ux + c[0, 1] * uy + c[0, 2] * uz
        e = c[1, 0] * ux + c[1, 1] * uy + c[1, 2] * uz
        d = c[2, 0] * ux + c[2, 1] * uy + c[2, 2] * uz
        el[j] = math.asin(min(max(-d, -1.0), 1.0))
        a = math.atan2(e, n)
        if a < 0.0:
            a += TWO_PI
        elif a == 0.0:
            a = 0.0  # numpy's mod gives +0 for -0
        az[j] = a


@njit(cache=True)
def look_angles(r_rx: np.ndarray, r_sv: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Range (S, m, k) m, unit line of sight (S, m, k, 3) ECEF, elevation and azimuth (S, m, k) rad from the
    receivers r_rx (m, 3) to the satellites r_sv (S, m, k, 3) of each sky (constellation.look_angles)."""
    n_sky, m, k = r_sv.shape[0], r_sv.shape[1], r_sv.shape[2]
    rng = np.empty((n_sky, m, k))
    u = np.empty((n_sky, m, k, 3))
    el = np.empty((n_sky, m, k))
    az = np.empty((n_sky, m, k))
    c = np.empty((3, 3))
    for i in range(m):
        lat, lon = gd.geodetic_lat_lon(r_rx[i, 0], r_rx[i, 1], r_rx[i, 2])
        gd.c_ecef_to_ned(lat, lon, c)
        for s in range(n_sky):
            _look(r_rx[i], c, r_sv[s, i], rng[s, i], u[s, i], el[s, i], az[s, i])
    return rng, u, el, az


@njit(cache=True)
def best_four(u: np.ndarray, visible: np.ndarray, sel: np.ndarray, idx: np.ndarray) -> None:
    """The four visible channels of lowest PDOP at one epoch into sel (k,) (every visible one if <= 4 are).

    Lines of sight u (k, 3); idx (k,) integer work space. For the four channels 0..3 with geometry rows [-u, 1]
    (Kaplan eq. 7.46), PDOP^2 = trace of the position block of (G'G)^-1 = G^-1 G^-T. With a = u1 - u0,
    b = u2 - u0, c = u3 - u0 and p = b x c, q = c x a, r = a x b, det = a . p, the position rows of G^-1 are
    -(p, q, r) / det for channels 1..3 and (p + q + r) / det for channel 0, so

        PDOP^2 = (|p|^2 + |q|^2 + |r|^2 + |p + q + r|^2) / det^2.

    Combinations in itertools.combinations order of the visible channels; the first minimum wins (numpy's
    argmin, as best_pdop_four_reference); a coplanar set (det = 0) has infinite PDOP."""
    k = visible.shape[0]
    n = 0
    for j in range(k):
        sel[j] = False
        if visible[j]:
            idx[n] = j
            n += 1
    if n <= 4:
        for q in range(n):
            sel[idx[q]] = True
        return
    best = math.inf
    b0 = b1 = b2 = b3 = -1
    for i0 in range(n - 3):
        j0 = idx[i0]
        x0, y0, z0 = u[j0, 0], u[j0, 1], u[j0, 2]
        for i1 in range(i0 + 1, n - 2):
            j1 = idx[i1]
            ax, ay, az = u[j1, 0] - x0, u[j1, 1] - y0, u[j1, 2] - z0
            for i2 in range(i1 + 1, n - 1):
                j2 = idx[i2]
                bx, by, bz = u[j2, 0] - x0, u[j2, 1] - y0, u[j2, 2] - z0
                rx, ry, rz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx  # r = a x b
                rr = rx * rx + ry * ry + rz * rz
                for i3 in range(i2 + 1, n):
                    j3 = idx[i3]
                    cx, cy, cz = u[j3, 0] - x0, u[j3, 1] - y0, u[j3, 2] - z0
                    px, py, pz = by * cz - bz * cy, bz * cx - bx * cz, bx * cy - by * cx  # p = b x c
                    qx, qy, qz = cy * az - cz * ay, cz * ax - cx * az, cx * ay - cy * ax  # q = c x a
                    det = ax * px + ay * py + az * pz
                    sx, sy, sz = px + qx + rx, py + qy + ry, pz + qz + rz
                    num = px * px + py * py + pz * pz + qx * qx + qy * qy + qz * qz + rr + sx * sx + sy * sy + sz * sz
                    pdop2 = num / (det * det) if det != 0.0 else math.inf
                    if pdop2 < best:
                        best = pdop2
                        b0, b1, b2, b3 = j0, j1, j2, j3
    if b0 < 0:  # every set coplanar: the first one, as argmin over all-inf values
        b0, b1, b2, b3 = idx[0], idx[1], idx[2], idx[3]
    sel[b0] = sel[b1] = sel[b2] = sel[b3] = True


@njit(cache=True)
def best_four_epochs(u: np.ndarray, visible: np.ndarray, sel: np.ndarray) -> None:
    """best_four at each epoch n of u (N, k, 3), visible (N, k), into sel (N, k)."""
    idx = np.empty(visible.shape[1], dtype=np.int64)
    for i in range(visible.shape[0]):
        best_four(u[i], visible[i], sel[i], idx)


@njit(cache=True)
def pdop(u: np.ndarray, use: np.ndarray) -> float:
    """PDOP of the channels `use` (k,) with lines of sight u (k, 3): sqrt(Q00 + Q11 + Q22), Q = (G'G)^-1, rows
    [-u, 1] (Kaplan eq. 7.46; the trace is that of constellation.dops' NED block, rotation-invariant); G'G by
    Cholesky G'G = L L', Q_ii = sum_j (L^-1)_ji^2. inf with fewer than 4 channels (or a singular geometry)."""
    a = np.zeros((4, 4))
    g = np.empty(4)
    n = 0
    for j in range(use.shape[0]):
        if use[j]:
            g[0], g[1], g[2], g[3] = -u[j, 0], -u[j, 1], -u[j, 2], 1.0
            for p in range(4):
                for q in range(p + 1):
                    a[p, q] += g[p] * g[q]
            n += 1
    if n < 4:
        return math.inf
    for p in range(4):  # Cholesky, lower triangle in place
        for q in range(p + 1):
            v = a[p, q]
            for t in range(q):
                v -= a[p, t] * a[q, t]
            if p == q:
                if v <= 0.0:
                    return math.inf
                a[p, p] = math.sqrt(v)
            else:
                a[p, q] = v / a[q, q]
    li = np.zeros((4, 4))  # L^-1 by forward substitution
    for q in range(4):
        li[q, q] = 1.0 / a[q, q]
        for p in range(q + 1, 4):
            v = 0.0
            for t in range(q, p):
                v -= a[p, t] * li[t, q]
            li[p, q] = v / a[p, p]
    tr = 0.0
    for i in range(3):
        for j in range(i, 4):
            tr += li[j, i] * li[j, i]
    return math.sqrt(tr)


@njit(cache=True)
def sky(r_rx: np.ndarray, r_sv: np.ndarray, mask_rad: float, mode: int, plan: np.ndarray, shell_m: float,
        do253: bool, mp_sigma_m: float, ce2: float, iono_zenith_m: float, tropo_zenith_m: float,
        cn2: float) -> tuple[np.ndarray, ...]:
    """The geometry of every sky s and sample i (receiver.py): receivers r_rx (m, 3) m, satellites r_sv (S, m, k, 3).

    Returns range (S, m, k) m, line of sight (S, m, k, 3), elevation, azimuth (S, m, k) rad, visible
    (el >= mask_rad), selected (mode: MODE_ALL every visible; MODE_BEST4 best_four; MODE_PLANNED the sky's plan
    (S, k) while all of it is visible, else best_four), PDOP (S, m) of the selection, and per channel the
    ionospheric obliquity F = 1 / sqrt(1 - (R cos el / (R + shell_m))^2), the tropospheric mapping
    M = 1.001 / sqrt(0.002001 + sin^2 el), the multipath scale (do253: 0.13 + 0.53 exp(-el / 10 deg); else 1) and
    the nominal sigma sqrt(ce2 + (I_z F)^2 + (T_z M)^2 + sigma_mp^2 + cn2) (sigma_mp: the do253 curve, else
    mp_sigma_m)."""
    n_sky, m, k = r_sv.shape[0], r_sv.shape[1], r_sv.shape[2]
    rng = np.empty((n_sky, m, k))
    u = np.empty((n_sky, m, k, 3))
    el = np.empty((n_sky, m, k))
    az = np.empty((n_sky, m, k))
    vis = np.empty((n_sky, m, k), dtype=np.bool_)
    sel = np.empty((n_sky, m, k), dtype=np.bool_)
    pd = np.empty((n_sky, m))
    f_iono = np.empty((n_sky, m, k))
    m_tropo = np.empty((n_sky, m, k))
    mp_scale = np.empty((n_sky, m, k))
    sigma = np.empty((n_sky, m, k))
    c = np.empty((3, 3))
    idx = np.empty(k, dtype=np.int64)
    for i in range(m):
        lat, lon = gd.geodetic_lat_lon(r_rx[i, 0], r_rx[i, 1], r_rx[i, 2])
        gd.c_ecef_to_ned(lat, lon, c)
        for s in range(n_sky):
            _look(r_rx[i], c, r_sv[s, i], rng[s, i], u[s, i], el[s, i], az[s, i])
            for j in range(k):
                vis[s, i, j] = el[s, i, j] >= mask_rad
            if mode == MODE_ALL:
                for j in range(k):
                    sel[s, i, j] = vis[s, i, j]
            else:
                keep = mode == MODE_PLANNED
                if keep:
                    for j in range(k):
                        if plan[s, j] and not vis[s, i, j]:
                            keep = False
                if keep:
                    for j in range(k):
                        sel[s, i, j] = plan[s, j] and vis[s, i, j]
                else:
                    best_four(u[s, i], vis[s, i], sel[s, i], idx)
            pd[s, i] = pdop(u[s, i], sel[s, i])
            for j in range(k):
                e = el[s, i, j]
                f = ge.iono_obliquity(math.cos(e), shell_m)
                mt = ge.tropo_mapping(math.sin(e))
                if do253:
                    msc = ge.do253_multipath_m(e)
                    mps = msc
                else:
                    msc = 1.0
                    mps = mp_sigma_m
                f_iono[s, i, j] = f
                m_tropo[s, i, j] = mt
                mp_scale[s, i, j] = msc
                fi = iono_zenith_m * f
                tm = tropo_zenith_m * mt
                sigma[s, i, j] = math.sqrt(ce2 + fi * fi + tm * tm + mps * mps + cn2)
    return rng, u, el, az, vis, sel, pd, f_iono, m_tropo, mp_scale, sigma


@njit(cache=True)
def pseudorange_sum(rng: np.ndarray, sel: np.ndarray, terms: tuple, bias: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pseudoranges (R, m, k) m and validity of every run r (receiver.py; run r on sky r, or on sky 0 when there is
    one sky for all runs): the range plus each error term scaled, in the order of `terms`, plus the receiver clock:

        rho = |r_sv - r| + s_1 e_1 + s_2 e_2 + ... + b_rx      (nan where the channel is not selected)

    rng (S, m, k) and sel from `sky`; terms ((s_t (S, m, k), e_t (R, m, k)), ...) the scales (m per unit, or ones)
    and the error series; bias (R, m) the receiver clock, m. Stand-alone: `pseudoranges`; GBAS: the scales of
    gbas_scales with the unit series and the white noise (receiver.py)."""
    n_run, m = bias.shape[0], bias.shape[1]
    k = rng.shape[2]
    one_sky = rng.shape[0] == 1
    pr = np.empty((n_run, m, k))
    valid = np.empty((n_run, m, k), dtype=np.bool_)
    for r in range(n_run):
        s = 0 if one_sky else r
        for i in range(m):
            b = bias[r, i]
            for j in range(k):
                p = rng[s, i, j]
                for t in literal_unroll(terms):
                    p = p + t[0][s, i, j] * t[1][r, i, j]
                v = sel[s, i, j]
                valid[r, i, j] = v
                pr[r, i, j] = p + b if v else math.nan
    return pr, valid


@njit(cache=True)
def pseudoranges(rng: np.ndarray, f_iono: np.ndarray, m_tropo: np.ndarray, mp_scale: np.ndarray, sel: np.ndarray,
                 ce: np.ndarray, iono: np.ndarray, tropo: np.ndarray, mp: np.ndarray, noise: np.ndarray,
                 bias: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stand-alone receiver's pseudorange_sum (receiver.py):

        rho = |r_sv - r| + E + F I + M T + s_mp m + n + b_rx      (nan where the channel is not selected)

    geometry (S, m, k) from `sky`, errors ce, iono, tropo, mp, noise (R, m, k), receiver clock bias (R, m)."""
    one = np.ones(rng.shape)
    return pseudorange_sum(rng, sel, ((one, ce), (f_iono, iono), (m_tropo, tropo), (mp_scale, mp), (one, noise)),
                           bias)


@njit(cache=True)
def channel_sigmas(el: np.ndarray, shell_m: float, ce_m: float, iono_m: float, tropo_m: float, do253: bool,
                   mp_m: float, gse: np.ndarray, gmp: np.ndarray) -> None:
    """The GPS channel states' 1-sigma (m) of a stand-alone budget at elevations el (N, k) rad, into gse, gmp (N, k),
    element by element (the compiled twin of receiver.GnssErrorBudget.channel_sigmas_m behind nav/noise.py's
    elevation guard; a run's values do not depend on the batch): gnss_errors.channel_sigmas at
    el <- guard_elevation(el) (nan: 0.5 rad, at least 2 deg),

        gse = sqrt(ce^2 + (I F)^2 + (T M)^2),  gmp = 0.13 + 0.53 exp(-el / 10 deg) (DO-253) or mp_m
    """
    ce2 = ce_m * ce_m
    for i in range(el.shape[0]):
        for c in range(el.shape[1]):
            e = ge.guard_elevation(el[i, c], ge.ELEVATION_FLOOR_RAD)
            decay = math.exp(ge.do253_exponent(e)) if do253 else 0.0
            gse[i, c], gmp[i, c] = ge.channel_sigmas(math.cos(e), math.sin(e), decay, shell_m, ce2, iono_m, tropo_m,
                                                     do253, mp_m)


@njit(cache=True)
def service_channel_sigmas(el: np.ndarray, p: np.ndarray, guard: bool, gse: np.ndarray, gmp: np.ndarray,
                           total: np.ndarray) -> None:
    """A civil service's channel sigmas (m) at elevations el (N, k) rad, into gse, gmp, total (N, k), element by
    element: gnss_errors.service_sigmas (slow, fast) and their RSS (DO-229's sigma_i with the broadcast parameters;
    the navigation filter's own model with ServiceModel.filter_params' scales); with guard, el <-
    guard_elevation(el) (nav/noise.py's: nan 0.5 rad, at least 2 deg), else nan stays nan."""
    for i in range(el.shape[0]):
        for c in range(el.shape[1]):
            e = ge.guard_elevation(el[i, c], ge.ELEVATION_FLOOR_RAD) if guard else el[i, c]
            s, f = ge.service_sigmas(e, p)
            gse[i, c] = s
            gmp[i, c] = f
            total[i, c] = math.sqrt(s * s + f * f)


@njit(cache=True)
def service_channel_terms(el: np.ndarray, p: np.ndarray, out: np.ndarray) -> None:
    """A civil service's broadcast 1-sigmas per channel at elevations el (N, k) rad into out (N, k, 5): range, iono,
    tropo, air (gnss_errors.service_terms, m) and the pierce point's ground distance (gnss_errors.pierce_distance_m,
    m, at the shell p[6]); the truth model's scales (sensors/gnss/service.py)."""
    for i in range(el.shape[0]):
        for c in range(el.shape[1]):
            e = el[i, c]
            r, io, t, a = ge.service_terms(e, p)
            out[i, c, 0] = r
            out[i, c, 1] = io
            out[i, c, 2] = t
            out[i, c, 3] = a
            out[i, c, 4] = ge.pierce_distance_m(e, p[6])


@njit(cache=True)
def service_errors(el: np.ndarray, az: np.ndarray, p: np.ndarray, shape: np.ndarray, series: tuple, j0: int,
                   slow: np.ndarray, air: np.ndarray) -> None:
    """A civil service's true errors (sensors/gnss/service.py ServiceModel.truth_errors, its numpy oracle), m, of
    every run r at elevations / azimuths el, az (S, m, k) rad (run r on sky r, or on sky 0 when there is one sky),
    into slow (range + iono + tropo) and air (R, m, k). p: the broadcast parameters (SERVICE_FIELDS, unit scales);
    shape: the truth's fractions and the iono field's split (core/layouts.py SERVICE_TRUTH); series: the unit
    series (range, iono_local, air, iono_field, tropo, tropo_local) (R, M, k | 3 | 1), read at samples j0 + i. With
    the broadcast terms (r, I, T, a) = gnss_errors.service_terms(el, p) and pierce distance d:

        range  f_r r e_r
        iono   f_i I (w_c f_0 + (w_g d / d_5) (sin az f_1 + cos az f_2) + w_l e_l)   (f_0..2: the field's series)
        tropo  f_t T (e_t (common zenith) or e_tl (per channel))
        air    f_a a e_a                                               (numpy's operations in the oracle's order)"""
    s_rng, s_loc, s_air, s_fld, s_trp, s_trl = series
    n_run, m, k = slow.shape
    one_sky = el.shape[0] == 1
    fr, fi, ft, fa = shape[L.ST_F_RANGE], shape[L.ST_F_IONO], shape[L.ST_F_TROPO], shape[L.ST_F_AIR]
    wc, wg, wl = shape[L.ST_W_COMMON], shape[L.ST_W_GRAD], shape[L.ST_W_LOCAL]
    d5 = shape[L.ST_GRAD_REF]
    tc = shape[L.ST_TROPO_COMMON] != 0.0
    for r in range(n_run):
        s = 0 if one_sky else r
        for i in range(m):
            j = j0 + i
            for c in range(k):
                e = el[s, i, c]
                rt, io, tr, at = ge.service_terms(e, p)
                iono = fi * io
                g = iono * wg * ge.pierce_distance_m(e, p[6]) / d5
                a = az[s, i, c]
                di = (iono * wc * s_fld[r, j, 0] + g * math.sin(a) * s_fld[r, j, 1]
                      + g * math.cos(a) * s_fld[r, j, 2] + iono * wl * s_loc[r, j, c])
                t = ft * tr
                dt = t * s_trp[r, j, 0] if tc else t * s_trl[r, j, c]
                slow[r, i, c] = fr * rt * s_rng[r, j, c] + di + dt
                air[r, i, c] = fa * at * s_air[r, j, c]


@njit(cache=True)
def gbas_channel_sigmas(el: np.ndarray, x_air: np.ndarray, dh: np.ndarray, v_air: np.ndarray, gad: np.ndarray,
                        n_ref: float, aad: np.ndarray, sigma_vig: float, tau_s: float, sigma_n: float, h0_m: float,
                        shell_m: float, gse: np.ndarray, gmp: np.ndarray) -> None:
    """The GPS channel states' 1-sigma (m) under GBAS at elevations el (N, k) rad and each row's distance x_air, height
    dh and speed v_air relative to the reference point (N,), into gse, gmp (N, k), element by element (the compiled
    twin of receiver.GnssErrorBudget.channel_sigmas_m, with nav/noise.py's elevation guard; a row's values do not
    depend on the others):

        el <- max(el, 2 deg) (nan: 0.5 rad);  gse = sqrt(ground^2 + iono^2 + tropo^2);  gmp = sqrt(mp^2 + noise^2)
    """
    for i in range(el.shape[0]):
        path = sigma_vig * (x_air[i] + 2.0 * tau_s * v_air[i])
        hfac = sigma_n * h0_m * 1e-6 * abs(-math.expm1(-dh[i] / h0_m))
        for c in range(el.shape[1]):
            e = ge.guard_elevation(el[i, c], ge.ELEVATION_FLOOR_RAD)
            g, io, tr, mp, nz = ge.gbas_terms(e, path, hfac, gad, n_ref, aad, shell_m)
            gse[i, c] = math.sqrt(g * g + io * io + tr * tr)
            gmp[i, c] = math.sqrt(mp * mp + nz * nz)


@njit(cache=True)
def gbas_scales(el: np.ndarray, r_rx: np.ndarray, h_m: np.ndarray, v_ned: np.ndarray, station: np.ndarray,
                station_h_m: float, gad: np.ndarray, n_ref: float, aad: np.ndarray, sigma_vig: float, tau_s: float,
                sigma_n: float, h0_m: float, shell_m: float, w2: float) -> tuple[np.ndarray, ...]:
    """The GBAS-corrected residual's scales (S, m, k), m, at elevations el (S, m, k) rad, for receivers at r_rx (m, 3)
    ECEF m with ellipsoid heights h_m (m,) and NED velocities v_ned (m, 3) m/s, the reference point at `station` (3,)
    ECEF m, station_h_m high (gnss/gbas.py; its station_geometry and GbasModel.scales are the oracle): with the
    slant distance x_air = |r_rx - station|, the height dh = h_m - station_h_m and the horizontal speed
    v_air = |v_ned[:2]|,

        ground  sqrt((a0 + a1 exp(-el / th0))^2 / M + a2^2), the row above or at/below gad[0] (gad: split, a0, a1,
                th0, a2 above, a0, a1, th0, a2 at/below; angles rad)
        iono    F sigma_vig (x_air + 2 tau v_air), F = 1 / sqrt(1 - (R cos el / (R + shell_m))^2)
        tropo   sigma_n h0 1e-6 / sqrt(0.002 + sin^2 el) |1 - exp(-dh / h0)|
        mp      0.13 + 0.53 exp(-el / 10 deg) (DO-253 airframe multipath)
        noise   a0 + a1 exp(-el / th0) (aad: a0, a1, th0 rad)

    and sigma = sqrt(ground^2 + iono^2 + tropo^2 + mp^2 + noise^2 + w2) (w2: the white noise's variance)."""
    n_sky, m, k = el.shape
    s_gnd = np.empty((n_sky, m, k))
    s_iono = np.empty((n_sky, m, k))
    s_tropo = np.empty((n_sky, m, k))
    s_mp = np.empty((n_sky, m, k))
    s_noise = np.empty((n_sky, m, k))
    sigma = np.empty((n_sky, m, k))
    for s in range(n_sky):
        for i in range(m):
            dx, dy, dz = r_rx[i, 0] - station[0], r_rx[i, 1] - station[1], r_rx[i, 2] - station[2]
            x_air = math.sqrt(dx * dx + dy * dy + dz * dz)
            v_air = math.hypot(v_ned[i, 0], v_ned[i, 1])
            path = sigma_vig * (x_air + 2.0 * tau_s * v_air)
            hfac = sigma_n * h0_m * 1e-6 * abs(-math.expm1(-(h_m[i] - station_h_m) / h0_m))
            for j in range(k):
                g, io, tr, mp, nz = ge.gbas_terms(el[s, i, j], path, hfac, gad, n_ref, aad, shell_m)
                s_gnd[s, i, j] = g
                s_iono[s, i, j] = io
                s_tropo[s, i, j] = tr
                s_mp[s, i, j] = mp
                s_noise[s, i, j] = nz
                sigma[s, i, j] = math.sqrt(g * g + io * io + tr * tr + mp * mp + nz * nz + w2)
    return s_gnd, s_iono, s_tropo, s_mp, s_noise, sigma


@njit(cache=True)
def pseudorange_rates(u: np.ndarray, v_sv: np.ndarray, lat: np.ndarray, lon: np.ndarray, v_ned: np.ndarray,
                      sel: np.ndarray, drift: np.ndarray, rate_noise: np.ndarray) -> np.ndarray:
    """Pseudorange rates (R, m, k) m/s (receiver.py): u . (v_sv - v_rx) + d_rx + e, nan where not selected; line
    of sight u and satellite velocity v_sv (S, m, k, 3), receiver velocity v_rx = C_ecef_to_ned(lat, lon)' v_ned
    from the truth's lat, lon (m,) and v_ned (m, 3), clock drift (R, m), noise (R, m, k)."""
    n_run, m, k = rate_noise.shape
    one_sky = u.shape[0] == 1
    out = np.empty((n_run, m, k))
    c = np.empty((3, 3))
    v_rx = np.empty(3)
    for i in range(m):
        gd.c_ecef_to_ned(lat[i], lon[i], c)
        for q in range(3):
            v_rx[q] = c[0, q] * v_ned[i, 0] + c[1, q] * v_ned[i, 1] + c[2, q] * v_ned[i, 2]
        for r in range(n_run):
            s = 0 if one_sky else r
            for j in range(k):
                if not sel[s, i, j]:
                    out[r, i, j] = math.nan
                    continue
                rr = (u[s, i, j, 0] * (v_sv[s, i, j, 0] - v_rx[0]) + u[s, i, j, 1] * (v_sv[s, i, j, 1] - v_rx[1])
                      + u[s, i, j, 2] * (v_sv[s, i, j, 2] - v_rx[2]))
                out[r, i, j] = rr + drift[r, i] + rate_noise[r, i, j]
    return out
