"""Strapdown inertial navigation: WGS-84 local-level NED mechanization from IMU increments.

The INS integrates gyro and accelerometer increments (delta-theta, delta-v over one IMU interval, body
axes) into geodetic position (lat, lon, ellipsoid height), NED velocity relative to the Earth and the
body-to-NED attitude matrix. Earth rate, transport rate, Coriolis and gravity varying with latitude
and height (geo.gravity_ned: JSBSim's J2 gravitation + centrifugal, the simulated world's own model, so
that exact increments of JSBSim truth integrate back to that truth) are all modelled (Groves, *Principles
of GNSS, Inertial and Multisensor Integrated Navigation Systems*, 2nd ed., sec. 5.4-5.5; Titterton & Weston ch. 3).

Integration is second-order accurate in the step (the global error falls as dt^2):
    attitude  C(+) = Exp(-w_in^n dt) C(-) Exp(dtheta)                     (Groves eq. 5.47 exact form)
    velocity  v(+) = v(-) + C(-) (dv + 1/2 dtheta x dv) - 1/2 [w_in^n dt x] C(-) dv
                           + (g(h_mid) - (2 w_ie + w_en) x v_mid) dt          (Groves eq. 5.84-5.86)
    position  trapezoid / midpoint of the old and new velocity              (Groves eq. 5.38)
with w_in = w_ie + w_en evaluated at the interval midpoint. The increments are those of the IMU record:
the integral over [t_{k-1}, t_k] of the body rate / specific force (sensors/imu.py documents how the
samples k-1, k form increment k).

Every function is a plain array function over a leading run axis: a state holds (N,) / (N, 3) / (N, 3, 3)
arrays, so many Monte Carlo runs step together. The mechanization runs compiled (core/nav/strapdown.py,
numba): `propagate` steps packed (N, 16) states over many intervals in one call, `step` is one interval of it
on an InsState, and `step_reference` is the same equations in numpy, kept as the kernel's test oracle. An
optional 3rd-order baro damping loop (nav/vertical_loop.py, seed 003 eq. 3, 7) stabilizes the vertical channel.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from approachsim import geo
from approachsim.core import layouts as L
from approachsim.core.nav import strapdown as sk
from approachsim.nav import vertical_loop as vl

Array = np.ndarray


@dataclass(frozen=True)
class InsState:
    """INS navigation state of N runs (run axis first). SI; the attitude matrix maps body to NED axes.

    a_comp_mps2 is the baro loop's compensator output (m/s^2, up-positive; zero without a loop).
    """

    lat_rad: Array
    """(N,) geodetic latitude, rad."""
    lon_rad: Array
    """(N,) longitude, rad."""
    h_m: Array
    """(N,) height above the WGS-84 ellipsoid, m."""
    v_ned: Array
    """(N, 3) velocity relative to the Earth, NED, m/s."""
    c_bn: Array
    """(N, 3, 3) attitude: v_ned = c_bn @ v_body."""
    a_comp_mps2: Array
    """(N,) baro damping loop compensator (seed 003 eq. 3, delta-a), m/s^2."""


def cross(a: Array, b: Array) -> Array:
    """a x b for vectors on the last axis (..., 3); a fast stand-in for np.cross on small arrays."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def skew(v: Array) -> Array:
    """Cross-product matrices (..., 3, 3) of vectors (..., 3): skew(a) @ b = a x b."""
    v = np.asarray(v, dtype=float)
    k = np.zeros(v.shape + (3,))
    k[..., 0, 1], k[..., 0, 2] = -v[..., 2], v[..., 1]
    k[..., 1, 0], k[..., 1, 2] = v[..., 2], -v[..., 0]
    k[..., 2, 0], k[..., 2, 1] = -v[..., 1], v[..., 0]
    return k


def rotation_exp(phi: Array) -> Array:
    """Rotation matrices (..., 3, 3) Exp([phi x]) of rotation vectors phi (..., 3), rad (Rodrigues).

    Exp = cos(a) I + sin(a)/a [phi x] + (1 - cos a)/a^2 phi phi', a = |phi|.
    """
    phi = np.asarray(phi, dtype=float)
    a2 = np.einsum("...i,...i->...", phi, phi)
    small = a2 < 1e-12
    a = np.sqrt(a2)
    a_safe = np.where(small, 1.0, a)
    # sin(a)/a and (1 - cos a)/a^2, with their Taylor series near zero
    s = np.where(small, 1.0 - a2 / 6.0, np.sin(a) / a_safe)
    c = np.where(small, 0.5 - a2 / 24.0, (1.0 - np.cos(a)) / (a_safe * a_safe))
    r = (c[..., None, None] * phi[..., :, None]) * phi[..., None, :]
    cos_a = 1.0 - c * a2
    for i in range(3):
        r[..., i, i] += cos_a
    sx, sy, sz = s * phi[..., 0], s * phi[..., 1], s * phi[..., 2]
    r[..., 0, 1] -= sz
    r[..., 0, 2] += sy
    r[..., 1, 0] += sz
    r[..., 1, 2] -= sx
    r[..., 2, 0] -= sy
    r[..., 2, 1] += sx
    return r


def earth_rate_ned(lat_rad: Array) -> Array:
    """Earth rotation w_ie in NED axes (..., 3), rad/s: (W cos L, 0, -W sin L)."""
    lat = np.asarray(lat_rad, dtype=float)
    out = np.zeros(lat.shape + (3,))
    out[..., 0] = geo.OMEGA_E * np.cos(lat)
    out[..., 2] = -geo.OMEGA_E * np.sin(lat)
    return out


def transport_rate_ned(lat_rad: Array, h_m: Array, v_ned: Array) -> Array:
    """Transport rate w_en in NED axes (..., 3), rad/s (Groves eq. 5.44)."""
    r_n, r_e = geo.radii(lat_rad)
    h = np.asarray(h_m, dtype=float)
    v = np.asarray(v_ned, dtype=float)
    out = np.empty(v.shape)
    out[..., 0] = v[..., 1] / (r_e + h)
    out[..., 1] = -v[..., 0] / (r_n + h)
    out[..., 2] = -v[..., 1] * np.tan(lat_rad) / (r_e + h)
    return out


def gravity_ned(lat_rad: Array, h_m: Array) -> Array:
    """Gravity vector (J2 gravitation + centrifugal) in NED (..., 3), m/s^2: geo.gravity_ned, the model of
    the simulated world (JSBSim's), with its small north component."""
    return geo.gravity_ned(lat_rad, h_m)


def euler_from_cbn(c_bn: Array) -> Array:
    """Roll, pitch, heading (..., 3), rad, of body-to-NED matrices (zyx convention); heading in [0, 2 pi)."""
    c = np.asarray(c_bn, dtype=float)
    roll = np.arctan2(c[..., 2, 1], c[..., 2, 2])
    pitch = -np.arcsin(np.clip(c[..., 2, 0], -1.0, 1.0))
    yaw = np.mod(np.arctan2(c[..., 1, 0], c[..., 0, 0]), 2.0 * np.pi)
    return np.stack([roll, pitch, yaw], axis=-1)


def cbn_from_euler(euler_rad: Array) -> Array:
    """Body-to-NED matrices (..., 3, 3) from roll, pitch, heading (..., 3), rad (zyx convention)."""
    e = np.asarray(euler_rad, dtype=float)
    cr, sr = np.cos(e[..., 0]), np.sin(e[..., 0])
    cp, sp = np.cos(e[..., 1]), np.sin(e[..., 1])
    cy, sy = np.cos(e[..., 2]), np.sin(e[..., 2])
    return np.stack(
        [
            np.stack([cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy], axis=-1),
            np.stack([cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy], axis=-1),
            np.stack([-sp, sr * cp, cr * cp], axis=-1),
        ],
        axis=-2,
    )


def cbn_from_quaternion(q_nb: Array) -> Array:
    """Body-to-NED matrices (..., 3, 3) from quaternions (..., 4), scalar first (Truth.q_nb)."""
    q = np.asarray(q_nb, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def init_state(lat_rad: Array, lon_rad: Array, h_m: Array, v_ned: Array, c_bn: Array) -> InsState:
    """An INS state from arrays with a leading run axis (scalars / single vectors get N = 1)."""
    lat = np.atleast_1d(np.asarray(lat_rad, dtype=float)).copy()
    c = np.asarray(c_bn, dtype=float)
    return InsState(
        lat_rad=lat,
        lon_rad=np.broadcast_to(np.asarray(lon_rad, dtype=float), lat.shape).copy(),
        h_m=np.broadcast_to(np.asarray(h_m, dtype=float), lat.shape).copy(),
        v_ned=np.broadcast_to(np.asarray(v_ned, dtype=float), lat.shape + (3,)).copy(),
        c_bn=np.broadcast_to(c, lat.shape + (3, 3)).copy(),
        a_comp_mps2=np.zeros_like(lat),
    )


def perturb(state: InsState, dp_ned_m: Array, dv_ned_mps: Array, psi_rad: Array) -> InsState:
    """The state with errors added: position error dp (NED, m), velocity error dv (m/s), attitude error psi.

    Error convention (errormodel.py): INS = truth + error; attitude C_ins = (I - [psi x]) C_true, exactly
    C_ins = Exp(-psi) C_true.
    """
    dp = np.asarray(dp_ned_m, dtype=float)
    r_n, r_e = geo.radii(state.lat_rad)
    lat = state.lat_rad + dp[..., 0] / (r_n + state.h_m)
    lon = state.lon_rad + dp[..., 1] / ((r_e + state.h_m) * np.cos(state.lat_rad))
    h = state.h_m - dp[..., 2]
    c = rotation_exp(-np.asarray(psi_rad, dtype=float)) @ state.c_bn
    return replace(state, lat_rad=lat, lon_rad=lon, h_m=h, v_ned=state.v_ned + dv_ned_mps, c_bn=c)


def pack(s: InsState) -> Array:
    """The packed (N, NX) form of a state for the compiled kernel (core/layouts.py INS: lat, lon, h, v_ned,
    C_bn row-major, a_comp)."""
    n = s.lat_rad.shape[0]
    x = np.empty((n, NX))
    x[:, L.X_LAT], x[:, L.X_LON], x[:, L.X_H] = s.lat_rad, s.lon_rad, s.h_m
    x[:, L.INS.slice("v_ned")] = s.v_ned
    x[:, L.INS.slice("c_bn")] = np.asarray(s.c_bn, dtype=float).reshape(n, 9)
    x[:, L.X_A_COMP] = s.a_comp_mps2
    return x


def unpack(x: Array) -> InsState:
    """An InsState (copies) from packed rows (..., NX); a leading run axis stays the run axis."""
    x = np.asarray(x, dtype=float)
    return InsState(x[..., L.X_LAT].copy(), x[..., L.X_LON].copy(), x[..., L.X_H].copy(),
                    x[..., L.INS.slice("v_ned")].copy(),
                    x[..., L.INS.slice("c_bn")].reshape(x.shape[:-1] + (3, 3)).copy(), x[..., L.X_A_COMP].copy())


def loop_vector(loop: vl.LoopGains | None) -> Array:
    """The damping loop as the kernel's (6,) vector (form code, c1, c2, c3, b1, b2); form 0 without a loop."""
    if loop is None:
        return np.zeros(6)
    code = {"constant": sk.LOOP_CONSTANT, "tanh": sk.LOOP_TANH, "sinh": sk.LOOP_SINH}[loop.form]
    return np.array([code, loop.c1, loop.c2, loop.c3, loop.b1_per_m, loop.b2_per_m], dtype=float)


NX = L.NX
"""Columns of a packed state (pack / unpack; core/layouts.py INS)."""

_NO_OUT = np.empty((0, 0, NX))


def propagate(x: Array, dtheta_body: Array, dv_body: Array, dt_s: float, *, bias_g: Array | None = None,
              bias_a: Array | None = None, h_baro_m: Array | None = None, baro_age_s: Array | None = None,
              loop: vl.LoopGains | None = None, f_sum: Array | None = None, out: Array | None = None,
              row0: int = 0) -> Array:
    """Step packed states x (N, 16) in place over m IMU intervals with the compiled mechanization
    (kernels.strapdown.strapdown: the equations of `step_reference`); returns x.

    dtheta_body, dv_body (N, m, 3) rad, m/s; bias_g, bias_a (N, 3) rad/s, m/s^2 subtracted from the rates
    (feedback); h_baro_m (N, m) the baro height held at each interval start (with `loop`), baro_age_s (m,) the
    held sample's age there (s; None: fresh samples, age 0; `held_baro`); f_sum (N, 3) accumulates C_bn dv (NED,
    m/s) when given; out (N, rows, 16) receives the state after interval j at row row0 + j + 1 when given.
    """
    n = x.shape[0]
    dth = np.ascontiguousarray(dtheta_body, dtype=float).reshape(n, -1, 3)
    dvb = np.ascontiguousarray(dv_body, dtype=float).reshape(n, -1, 3)
    zeros = np.zeros((n, 3))
    if h_baro_m is None or loop is None:
        hb, age = np.zeros((n, 0)), np.zeros(0)
    else:
        hb = np.ascontiguousarray(h_baro_m, dtype=float).reshape(n, -1)
        age = np.zeros(hb.shape[1]) if baro_age_s is None else np.ascontiguousarray(baro_age_s, dtype=float)
        if age.shape != (hb.shape[1],):
            raise ValueError(f"baro_age_s has shape {age.shape}, the held baro {hb.shape[1]} intervals")
    lv = loop_vector(loop if h_baro_m is not None else None)
    sk.strapdown(x, dth, dvb, float(dt_s), zeros if bias_g is None else np.ascontiguousarray(bias_g, dtype=float),
                 zeros if bias_a is None else np.ascontiguousarray(bias_a, dtype=float), hb, age, lv,
                 np.zeros((n, 3)) if f_sum is None else f_sum, _NO_OUT if out is None else out, int(row0))
    return x


def held_baro(valid: Array, h_baro_m: Array, t_baro_s: Array, t_start_s: Array) -> tuple[Array, Array]:
    """The damping loop's zero-order hold of the baro: (N, m) the latest sample at or before each IMU interval
    start t_start_s (m,) (nan where that sample is invalid: an outage, a lost sensor; the loop holds), and (m,) its
    age there, t_start - t_sample (s), with which the INS takes the INS height back to the sample's time
    (kernels/strapdown.py). valid, h_baro_m (N, n_baro) or (n_baro,) the baro records at times t_baro_s (n_baro,)."""
    t_b = np.asarray(t_baro_s, dtype=float)
    t0 = np.asarray(t_start_s, dtype=float)
    idx = np.clip(np.searchsorted(t_b, t0 + 1e-9, side="right") - 1, 0, None)
    hb = np.where(np.asarray(valid, dtype=bool), np.asarray(h_baro_m, dtype=float), np.nan).reshape(-1, t_b.shape[0])
    return hb[:, idx], t0 - t_b[idx]


def step(
    s: InsState,
    dtheta_body: Array,
    dv_body: Array,
    dt_s: float,
    *,
    h_baro_m: Array | None = None,
    baro_age_s: float = 0.0,
    loop: vl.LoopGains | None = None,
) -> InsState:
    """Advance the INS by one IMU interval dt_s (s) with increments dtheta (rad) and dv (m/s), body axes (N, 3):
    the compiled kernel (`propagate`) on the state; the same result as `step_reference` to 1e-12 relative.

    With `loop` and `h_baro_m` (N,) given, the 3rd-order baro damping loop (seed 003 eq. 3 / 7) corrects
    height, vertical velocity and its compensator from the loop error e = h_ins - h_baro, the INS height taken back
    to the sample's time, baro_age_s (s) before the interval start: h_ins = h + v_D baro_age_s.
    """
    x = pack(s)
    n = x.shape[0]
    propagate(x, np.reshape(dtheta_body, (n, 1, 3)), np.reshape(dv_body, (n, 1, 3)), dt_s,
              h_baro_m=None if h_baro_m is None else np.reshape(np.asarray(h_baro_m, dtype=float), (n, 1)),
              baro_age_s=np.array([baro_age_s], dtype=float), loop=loop)
    return unpack(x)


def step_reference(
    s: InsState,
    dtheta_body: Array,
    dv_body: Array,
    dt_s: float,
    *,
    h_baro_m: Array | None = None,
    baro_age_s: float = 0.0,
    loop: vl.LoopGains | None = None,
) -> InsState:
    """`step` in numpy (the readable version and the compiled kernel's test oracle): one IMU interval dt_s (s)
    with increments dtheta (rad) and dv (m/s), body axes (N, 3), the module docstring's equations."""
    lat0, h0, v0, c0 = s.lat_rad, s.h_m, s.v_ned, s.c_bn
    dth = np.asarray(dtheta_body, dtype=float)
    dvb = np.asarray(dv_body, dtype=float)
    w_ie0 = earth_rate_ned(lat0)
    w_in0 = w_ie0 + transport_rate_ned(lat0, h0, v0)
    # specific-force increment in NED: rotation (1/2 dtheta x dv) and frame-rotation compensation (Groves 5.86)
    cdv = np.einsum("nij,nj->ni", c0, dvb + 0.5 * cross(dth, dvb))
    cdv0 = np.einsum("nij,nj->ni", c0, dvb)
    dv_f = cdv - 0.5 * dt_s * cross(w_in0, cdv0)
    # gravity and Coriolis at the predicted midpoint
    h_mid = h0 - 0.5 * dt_s * v0[:, 2]
    r_n0, _ = geo.radii(lat0)
    lat_mid = lat0 + 0.5 * dt_s * v0[:, 0] / (r_n0 + h0)
    g_mid = gravity_ned(lat_mid, h_mid)
    cor0 = cross(w_ie0 + w_in0, v0)  # (2 w_ie + w_en) x v at the interval start
    v_mid = v0 + 0.5 * (dv_f + (g_mid - cor0) * dt_s)
    cor = cross(2.0 * earth_rate_ned(lat_mid) + transport_rate_ned(lat_mid, h_mid, v_mid), v_mid)
    v1 = v0 + dv_f + (g_mid - cor) * dt_s
    a_comp = s.a_comp_mps2
    dh_loop = 0.0
    if loop is not None and h_baro_m is not None:
        # loop error e = h_ins - h_baro (seed 003 eq. 3), both at the sample's time (kernels/strapdown.py)
        e = (h0 + v0[:, 2] * baro_age_s) - np.asarray(h_baro_m, dtype=float)
        k1, k2 = vl.branch_corrections(loop, e)
        v1 = v1.copy()
        v1[:, 2] += (k2 + a_comp) * dt_s  # v_up' = ... - k2(e) - a_c  (v_D = -v_up)
        a_comp = a_comp + loop.c3 * e * dt_s  # a_c' = C3 e
        dh_loop = -k1 * dt_s  # h' = v_up - k1(e)
    # position: trapezoid of the velocity, radii at the midpoint
    v_m = 0.5 * (v0 + v1)
    h1 = h0 - dt_s * v_m[:, 2] + dh_loop
    r_n, _ = geo.radii(lat0)
    lat_mid = lat0 + 0.5 * dt_s * v_m[:, 0] / (r_n + 0.5 * (h0 + h1))
    r_n, r_e = geo.radii(lat_mid)
    hm = 0.5 * (h0 + h1)
    lat1 = lat0 + dt_s * v_m[:, 0] / (r_n + hm)
    lon1 = s.lon_rad + dt_s * v_m[:, 1] / ((r_e + hm) * np.cos(lat_mid))
    # attitude: body rotation dtheta, navigation-frame rotation w_in at the midpoint
    w_in_mid = earth_rate_ned(lat_mid) + transport_rate_ned(lat_mid, hm, v_m)
    c1 = rotation_exp(-w_in_mid * dt_s) @ c0 @ rotation_exp(dth)
    return InsState(lat1, lon1, h1, v1, c1, a_comp)


def orthonormalize(c: Array) -> Array:
    """Nearest rotation matrices (..., 3, 3) to c, by one symmetric correction C (3 I - C'C) / 2."""
    return 0.5 * c @ (3.0 * np.eye(3) - np.swapaxes(c, -1, -2) @ c)


def position_ecef(s: InsState) -> Array:
    """ECEF positions (N, 3) of the INS states, m."""
    return geo.geodetic_to_ecef(s.lat_rad, s.lon_rad, s.h_m)


def position_error_ned(lat_rad: Array, lon_rad: Array, h_m: Array, lat_true: Array, lon_true: Array,
                       h_true: Array) -> Array:
    """Position error (estimate - truth) in local NED metres (..., 3) from geodetic coordinates."""
    r_n, r_e = geo.radii(lat_true)
    dlon = np.angle(np.exp(1j * (np.asarray(lon_rad) - lon_true)))
    return np.stack(
        [
            (np.asarray(lat_rad) - lat_true) * (r_n + h_true),
            dlon * (r_e + h_true) * np.cos(lat_true),
            -(np.asarray(h_m) - h_true),
        ],
        axis=-1,
    )


def attitude_error(c_ins: Array, c_true: Array) -> Array:
    """Attitude error psi (..., 3), rad, with C_ins = (I - [psi x]) C_true (small-angle, NED axes)."""
    d = np.asarray(c_ins) @ np.swapaxes(np.asarray(c_true), -1, -2)  # = I - [psi x]
    return 0.5 * np.stack([d[..., 1, 2] - d[..., 2, 1], d[..., 2, 0] - d[..., 0, 2], d[..., 0, 1] - d[..., 1, 0]],
                          axis=-1)


def align_stationary(dtheta_body: Array, dv_body: Array, lat_rad: Array) -> Array:
    """Analytic stationary alignment (leveling + gyrocompassing, TRIAD) from increments over the alignment.

    dtheta_body, dv_body: (N, m, 3) increments of a motionless IMU (rad, m/s); lat_rad (N,) known latitude.
    The mean specific force is -g (up) and the mean rate is the Earth rate, both in body axes; the
    body-to-NED matrix follows from the NED triad of (g, w_ie, g x w_ie) (Groves eq. 5.101-5.103, Titterton
    sec. 10.2). Accelerometer biases tilt the result and the east gyro bias turns its heading, which is
    what makes a real INS drift the way its grade says. Returns (N, 3, 3).
    """
    f_b = -np.mean(np.asarray(dv_body, dtype=float), axis=-2)  # points down (gravity direction), body axes
    w_b = np.mean(np.asarray(dtheta_body, dtype=float), axis=-2)
    lat = np.asarray(lat_rad, dtype=float)
    n = np.broadcast_to(lat, f_b.shape[:-1])
    down_n = np.zeros(n.shape + (3,))
    down_n[..., 2] = 1.0
    w_n = earth_rate_ned(n)

    def triad(a: Array, b: Array) -> Array:
        t1 = a / np.linalg.norm(a, axis=-1, keepdims=True)
        t2 = cross(a, b)
        t2 = t2 / np.linalg.norm(t2, axis=-1, keepdims=True)
        return np.stack([t1, t2, cross(t1, t2)], axis=-1)  # columns t1, t2, t3

    m_b = triad(f_b, w_b)
    m_n = triad(down_n, w_n)
    return m_n @ np.swapaxes(m_b, -1, -2)  # C_bn maps body triad onto NED triad
