"""Compiled strapdown INS mechanization (numba, cache=True): the equations of nav/ins.py's numpy `step_reference`
(its docstring and Groves, *Principles of GNSS, Inertial and Multisensor Integrated Navigation Systems*, 2nd ed.,
sec. 5.4-5.5), stepped over many runs and many IMU intervals in one call.

State layout (one row per run, SI), the packed form of ins.InsState:

    x[i] = (lat rad, lon rad, h m, vN, vE, vD m/s, C_bn row-major (9), a_comp m/s^2)      -> (N, 16)

Per interval j (increments dtheta, dv over (t_j, t_j + dt], body axes):

    attitude  C(+) = Exp(-w_in(mid) dt) C(-) Exp(dtheta)
    velocity  v(+) = v(-) + C(-) (dv + 1/2 dtheta x dv) - 1/2 dt w_in x C(-) dv + (g(mid) - (2 w_ie + w_en) x v_mid) dt
    position  trapezoid of v(-), v(+), radii at the midpoint
    baro loop (optional, seed 003 eq. 3 / 7): e = h(-) + vD(-) a - h_baro, vD += (k2(e) + a_c) dt,
              a_c += C3 e dt, h += -k1(e) dt
    with h_baro nan (no baro: an outage, or the baro excluded by FDE) the loop holds: vD += a_c dt only

h_baro is the last baro sample, held; a (s) is its age at the interval start. The loop compares it with the INS
height at the sample's time, h(-) + vD(-) a (first order), not with the height now: on a descent the held sample is
vD a above the aircraft, and closing the loop on it biased the height high (docs/baro-loop-hold-bias.md).

Each run is stepped on its own (the run loop is outside the time loop, so the 16 state numbers stay in
registers): a run's numbers are the same in any batch, which the campaign's bit-identity needs. Vectorizing the
run loop instead would buy nothing here: the step is dominated by sin/cos/tan/sqrt, which LLVM does not vectorize
without a vector math library (and one would round differently from the scalar libm in the remainder loop,
making a run's bits depend on its batch size).
"""

from __future__ import annotations

import math

import numpy as np

from approachsim.core import geodesy as gk
from approachsim.core.jit import njit
from approachsim.core.sensors import imu as ik

NX = 16
"""Columns of the packed INS state."""

LOOP_NONE, LOOP_CONSTANT, LOOP_TANH, LOOP_SINH = 0.0, 1.0, 2.0, 3.0
"""Codes of loop[0], the baro damping loop's form; loop = (form, c1, c2, c3, b1, b2) (vertical_loop.LoopGains)."""


@njit(cache=True)
def rotation_exp(x: float, y: float, z: float) -> tuple[float, ...]:
    """Exp([phi x]) of one rotation vector (rad) as a row-major 9-tuple (Rodrigues; Taylor series below |phi| 1e-6):
    cos(a) I + sin(a)/a [phi x] + (1 - cos a)/a^2 phi phi'."""
    a2 = x * x + y * y + z * z
    if a2 < 1e-12:
        s = 1.0 - a2 / 6.0
        c = 0.5 - a2 / 24.0
    else:
        a = math.sqrt(a2)
        s = math.sin(a) / a
        c = (1.0 - math.cos(a)) / (a * a)
    ca = 1.0 - c * a2
    cx, cy, cz = c * x, c * y, c * z
    sx, sy, sz = s * x, s * y, s * z
    return (cx * x + ca, cx * y - sz, cx * z + sy,
            cy * x + sz, cy * y + ca, cy * z - sx,
            cz * x - sy, cz * y + sx, cz * z + ca)


@njit(cache=True)
def _mm(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, ...]:
    """Product of two row-major 3x3 9-tuples."""
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
            a[3] * b[0] + a[4] * b[3] + a[5] * b[6], a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
            a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@njit(cache=True)
def _w_en(lat: float, h: float, vn: float, ve: float) -> tuple[float, float, float]:
    """Transport rate (rad/s, NED): (vE / (R_E + h), -vN / (R_N + h), -vE tan L / (R_E + h)) (Groves eq. 5.44)."""
    r_n, r_e = gk.radii(lat)
    return ve / (r_e + h), -vn / (r_n + h), -ve * math.tan(lat) / (r_e + h)


@njit(cache=True)
def _branch(form: float, c: float, b: float, e: float) -> float:
    """A loop branch signal: C e (constant), C tanh(b e), C sinh(b e) (seed 003 eq. 3, 7, 16)."""
    if form == LOOP_CONSTANT:
        return c * e
    if form == LOOP_TANH:
        return c * math.tanh(b * e)
    return c * math.sinh(b * e)


@njit(cache=True)
def strapdown(x: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, dt: float, bias_g: np.ndarray,
              bias_a: np.ndarray, h_baro: np.ndarray, baro_age: np.ndarray, loop: np.ndarray, f_sum: np.ndarray,
              out: np.ndarray, row0: int) -> None:
    """Step N runs over m IMU intervals, in place.

    x (N, 16) packed states; dtheta, dv (N, m, 3) raw increments (rad, m/s); bias_g, bias_a (N, 3) rate and
    specific-force corrections (rad/s, m/s^2; the increments used are dtheta - bias_g dt, dv - bias_a dt);
    h_baro (N, m) the baro height held at each interval start (m; read only with a loop), baro_age (m,) the held
    sample's age there (s: interval start - sample time; read with h_baro); loop (6,) as
    LOOP_*; f_sum (N, 3) accumulates C(-) dv of every interval (NED, m/s); out (N, rows, 16): when rows > 0,
    the state after interval j is written to out[:, row0 + j + 1].
    """
    n_runs, m = dtheta.shape[0], dtheta.shape[1]
    form = loop[0]
    om = gk.OMEGA_E
    k = 0.5 * dt
    write = out.shape[1] > 0
    for i in range(n_runs):
        lat0, lon0, h0 = x[i, 0], x[i, 1], x[i, 2]
        vn, ve, vd = x[i, 3], x[i, 4], x[i, 5]
        c0 = (x[i, 6], x[i, 7], x[i, 8], x[i, 9], x[i, 10], x[i, 11], x[i, 12], x[i, 13], x[i, 14])
        a_comp = x[i, 15]
        bgx, bgy, bgz = bias_g[i, 0] * dt, bias_g[i, 1] * dt, bias_g[i, 2] * dt
        bax, bay, baz = bias_a[i, 0] * dt, bias_a[i, 1] * dt, bias_a[i, 2] * dt
        for j in range(m):
            tx, ty, tz = dtheta[i, j, 0] - bgx, dtheta[i, j, 1] - bgy, dtheta[i, j, 2] - bgz
            ux, uy, uz = dv[i, j, 0] - bax, dv[i, j, 1] - bay, dv[i, j, 2] - baz
            r_n0, r_e0 = gk.radii(lat0)
            cl0, sl0 = math.cos(lat0), math.sin(lat0)
            wie0 = (om * cl0, -om * sl0)  # north, down (east is zero)
            wen0 = (ve / (r_e0 + h0), -vn / (r_n0 + h0), -ve * math.tan(lat0) / (r_e0 + h0))
            win0 = (wie0[0] + wen0[0], wen0[1], wie0[1] + wen0[2])
            # specific-force increment in NED, sculling and frame-rotation terms (Groves eq. 5.84-5.86)
            rx, ry, rz = ux + 0.5 * (ty * uz - tz * uy), uy + 0.5 * (tz * ux - tx * uz), uz + 0.5 * (tx * uy - ty * ux)
            cdx = c0[0] * rx + c0[1] * ry + c0[2] * rz
            cdy = c0[3] * rx + c0[4] * ry + c0[5] * rz
            cdz = c0[6] * rx + c0[7] * ry + c0[8] * rz
            cux = c0[0] * ux + c0[1] * uy + c0[2] * uz
            cuy = c0[3] * ux + c0[4] * uy + c0[5] * uz
            cuz = c0[6] * ux + c0[7] * uy + c0[8] * uz
            f_sum[i, 0] += cux
            f_sum[i, 1] += cuy
            f_sum[i, 2] += cuz
            dfx = cdx - k * (win0[1] * cuz - win0[2] * cuy)
            dfy = cdy - k * (win0[2] * cux - win0[0] * cuz)
            dfz = cdz - k * (win0[0] * cuy - win0[1] * cux)
            # gravity and Coriolis at the predicted midpoint
            h_mid = h0 - k * vd
            lat_mid = lat0 + k * vn / (r_n0 + h0)
            gn, gd = gk.gravity_nd(lat_mid, h_mid)
            w2x, w2y, w2z = wie0[0] + win0[0], win0[1], wie0[1] + win0[2]  # 2 w_ie + w_en at the start
            cor0x, cor0y, cor0z = w2y * vd - w2z * ve, w2z * vn - w2x * vd, w2x * ve - w2y * vn
            vmx = vn + 0.5 * (dfx + (gn - cor0x) * dt)
            vmy = ve + 0.5 * (dfy + (0.0 - cor0y) * dt)
            vmz = vd + 0.5 * (dfz + (gd - cor0z) * dt)
            wm = _w_en(lat_mid, h_mid, vmx, vmy)
            wcx = 2.0 * (om * math.cos(lat_mid)) + wm[0]
            wcy = wm[1]
            wcz = 2.0 * (-om * math.sin(lat_mid)) + wm[2]
            corx, cory, corz = wcy * vmz - wcz * vmy, wcz * vmx - wcx * vmz, wcx * vmy - wcy * vmx
            v1n = vn + dfx + (gn - corx) * dt
            v1e = ve + dfy + (0.0 - cory) * dt
            v1d = vd + dfz + (gd - corz) * dt
            dh_loop = 0.0
            if form != LOOP_NONE:
                hb = h_baro[i, j]
                if hb == hb:
                    # loop error e = h_ins - h_baro (seed 003 eq. 3), both at the sample's time
                    e = (h0 + vd * baro_age[j]) - hb
                    k1 = _branch(form, loop[1], loop[4], e)
                    k2 = _branch(form, loop[2], loop[5], e)
                    v1d += (k2 + a_comp) * dt  # v_up' = ... - k2(e) - a_c  (v_D = -v_up)
                    a_comp = a_comp + loop[3] * e * dt  # a_c' = C3 e
                    dh_loop = -k1 * dt  # h' = v_up - k1(e)
                else:  # no baro (nan: an outage, or excluded by FDE): the loop holds its compensator
                    v1d += a_comp * dt
            # position: trapezoid of the velocity, radii at the midpoint
            vtn, vte, vtd = 0.5 * (vn + v1n), 0.5 * (ve + v1e), 0.5 * (vd + v1d)
            h1 = h0 - dt * vtd + dh_loop
            hm = 0.5 * (h0 + h1)
            lat_m2 = lat0 + k * vtn / (r_n0 + hm)
            r_n, r_e = gk.radii(lat_m2)
            clm = math.cos(lat_m2)
            lat1 = lat0 + dt * vtn / (r_n + hm)
            lon1 = lon0 + dt * vte / ((r_e + hm) * clm)
            # attitude: body rotation dtheta, navigation-frame rotation w_in at the midpoint
            w3 = _w_en(lat_m2, hm, vtn, vte)
            wix = om * clm + w3[0]
            wiy = 0.0 + w3[1]
            wiz = -om * math.sin(lat_m2) + w3[2]
            c0 = _mm(_mm(rotation_exp(-wix * dt, -wiy * dt, -wiz * dt), c0), rotation_exp(tx, ty, tz))
            lat0, lon0, h0, vn, ve, vd = lat1, lon1, h1, v1n, v1e, v1d
            if write:
                o = out[i, row0 + j + 1]
                o[0], o[1], o[2], o[3], o[4], o[5] = lat0, lon0, h0, vn, ve, vd
                for q in range(9):
                    o[6 + q] = c0[q]
                o[15] = a_comp
        x[i, 0], x[i, 1], x[i, 2], x[i, 3], x[i, 4], x[i, 5] = lat0, lon0, h0, vn, ve, vd
        for q in range(9):
            x[i, 6 + q] = c0[q]
        x[i, 15] = a_comp


@njit(cache=True)
def inloop_step(k: int, w_ib: np.ndarray, f_body: np.ndarray, affine: bool, imu: tuple, dtheta: np.ndarray,
                dv: np.ndarray, dt: float, bias_g: np.ndarray, bias_a: np.ndarray, h_baro: np.ndarray,
                baro_age: np.ndarray, loop: np.ndarray, x: np.ndarray, f_sum: np.ndarray) -> None:
    """The closed loop's INS step into truth row k for one run: with `affine`, the IMU increments of interval
    (k-1, k] from truth rows w_ib, f_body (n, 3) and the pre-drawn error terms imu = (m_g, m_a, c_g, c_a)
    (core/sensors/imu.increment; M (3, 3) and c (m, 3) indexed by sample k-1), else the given dtheta, dv (1, 1, 3);
    then `strapdown` on x (1, 16)."""
    m_g, m_a, c_g, c_a = imu
    if affine:
        ik.increment(m_g, w_ib[k - 1], dt, c_g[k - 1], dtheta[0, 0])
        ik.increment(m_a, f_body[k - 1], dt, c_a[k - 1], dv[0, 0])
    strapdown(x, dtheta, dv, dt, bias_g, bias_a, h_baro, baro_age, loop, f_sum, np.empty((1, 0, NX)), 0)


@njit(cache=True)
def guidance(x: np.ndarray, x_nav: np.ndarray, c_rwy: np.ndarray, o_rwy: np.ndarray, h_thr: float,
             out: np.ndarray) -> None:
    """Feed-forward navigation output for guidance: position INS - dp_hat in the runway frame (x, y along and
    across; z the height above the threshold, as Truth.r_rwy) and velocity v_INS - dv_hat (NED), into out (6,).
    x (1, 16) packed INS state, x_nav (>= 6,) the estimated errors (dp NED m, dv m/s)."""
    lat, lon, h = x[0, 0], x[0, 1], x[0, 2]
    r_n, r_e = gk.radii(lat)
    lat_c = lat - x_nav[0] / (r_n + h)
    lon_c = lon - x_nav[1] / ((r_e + h) * math.cos(lat))
    h_c = h + x_nav[2]
    ex, ey, ez = gk.geodetic_to_ecef(lat_c, lon_c, h_c)
    dx, dy, dz = ex - o_rwy[0], ey - o_rwy[1], ez - o_rwy[2]
    out[0] = c_rwy[0, 0] * dx + c_rwy[0, 1] * dy + c_rwy[0, 2] * dz
    out[1] = c_rwy[1, 0] * dx + c_rwy[1, 1] * dy + c_rwy[1, 2] * dz
    out[2] = h_c - h_thr
    out[3], out[4], out[5] = x[0, 3] - x_nav[3], x[0, 4] - x_nav[4], x[0, 5] - x_nav[5]
