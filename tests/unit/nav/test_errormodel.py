"""The INS error model F against the mechanization itself: a perturbed INS flown beside an unperturbed one
must grow the error that expm(F t) predicts (first-order terms), state group by state group."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim import geo, synthetic
from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav import vertical_loop as vl

NOISE = em.ErrorNoise(
    gyro_arw_rad_sqrts=1e-6, accel_vrw_mps_sqrts=1e-5, gyro_bias_rw=1e-9, accel_bias_rw=1e-7,
    baro_bias_sigma_m=1.0, baro_bias_tau_s=100.0, clock_sf=0.1, clock_sg=0.01,
)


def _truth():
    rwy = geo.RunwayFrame(np.radians(37.6), np.radians(-122.36), 4.0, np.radians(298.0))
    return synthetic.glidepath_descent(rwy, rate_hz=20.0, start_distance_m=6000.0, ground_speed_mps=70.0)


def _fly(truth, s, n, bg, ba):
    dt = float(truth.t_s[1] - truth.t_s[0])
    w, f = truth.w_ib_body, truth.f_body
    for k in range(1, n + 1):
        dth = 0.5 * dt * (w[k - 1] + w[k]) + bg * dt
        dv = 0.5 * dt * (f[k - 1] + f[k]) + ba * dt
        s = ins.step(s, dth[None], dv[None], dt)
    return s


def _errors(s, truth, k):
    c_true = ins.cbn_from_quaternion(truth.q_nb[k])
    dp = ins.position_error_ned(s.lat_rad, s.lon_rad, s.h_m, truth.lat_rad[k], truth.lon_rad[k], truth.h_m[k])[0]
    return np.concatenate([dp, s.v_ned[0] - truth.v_ned[k], ins.attitude_error(s.c_bn[0], c_true)])


@pytest.mark.parametrize(
    ("group", "k", "size"),
    [("dp", 0, 5.0), ("dp", 1, 5.0), ("dp", 2, 5.0), ("dv", 0, 0.2), ("dv", 1, 0.2), ("dv", 2, 0.2),
     ("psi", 0, 2e-4), ("psi", 1, 2e-4), ("psi", 2, 5e-4), ("bg", 0, 5e-6), ("bg", 2, 5e-6),
     ("ba", 0, 5e-3), ("ba", 2, 5e-3)],
)
def test_F_predicts_the_mechanization(group, k, size):
    """30 s along a glidepath: the INS error caused by one error source matches Phi dx to 2 % of its size."""
    truth = _truth()
    lay = em.StateLayout(baro_scale=False, clock=False)
    n_steps, dt = 600, float(truth.t_s[1] - truth.t_s[0])
    c0 = ins.cbn_from_quaternion(truth.q_nb[0])
    s0 = ins.init_state(truth.lat_rad[0], truth.lon_rad[0], truth.h_m[0], truth.v_ned[0], c0)
    dx = np.zeros(lay.n)
    dx[lay.i(group, k)] = size
    s = ins.perturb(s0, dx[None, 0:3], dx[None, 3:6], dx[None, 6:9])
    s = _fly(truth, s, n_steps, bg=dx[9:12], ba=dx[12:15])
    got = _errors(s, truth, n_steps)
    f_ned = c0 @ truth.f_body[0]
    F, _ = em.dynamics(lay, truth.lat_rad[0], truth.h_m[0], truth.v_ned[0], f_ned, c0, NOISE)
    phi, _ = em.van_loan(F, np.zeros_like(F), n_steps * dt)
    want = (phi @ dx)[:9]
    floor = np.array([0.05] * 3 + [1e-4] * 3 + [1e-7] * 3)  # second-order residue floors (m, m/s, rad)
    assert np.all(np.abs(got - want) < 0.02 * np.abs(want) + floor), (got, want)


def test_vertical_channel_time_constant():
    """The unaided vertical mode: dp_D'' = (2 g / R) dp_D, eigenvalue 1/sqrt(R / 2 g) (~ 1/566 s)."""
    lay = em.StateLayout(baro_scale=False, clock=False)
    F, _ = em.dynamics(lay, np.radians(45.0), 0.0, np.zeros(3), np.array([0, 0, -9.806]), np.eye(3), NOISE)
    ev = np.linalg.eigvals(F[np.ix_([2, 5], [2, 5])])
    tau = 1.0 / ev.real.max()
    assert tau == pytest.approx(np.sqrt(geo.A_WGS84 / (2 * 9.806)), rel=0.01)


def test_loop_closes_with_the_seed003_poles():
    """With the baro loop the (dh, dv_up, ac) block has the three poles of seed 003 eq. 4-5 at -1/tau."""
    lay = em.StateLayout(baro_scale=False, clock=False, loop=True)
    tau = 50.0
    gains = vl.constant_gains(tau)
    F, _ = em.dynamics(lay, np.radians(45.0), 0.0, np.zeros(3), np.array([0, 0, -9.806]), np.eye(3), NOISE, gains)
    idx = [2, 5, lay.i("ac")]
    ev = np.sort_complex(np.linalg.eigvals(F[np.ix_(idx, idx)]))
    # python-control's poles of seed 003 eq. 3 with this point's gravity gradient in place of 2 g0 / R0
    g = float(geo.gravity_ned(np.radians(45.0), 0.0)[2])
    dg_dh = float(geo.gravity_ned(np.radians(45.0), 10.0)[2] - geo.gravity_ned(np.radians(45.0), -10.0)[2]) / 20.0
    want = np.sort_complex(vl.closed_loop_poles(gains, g0_mps2=g, r0_m=-2.0 * g / dg_dh))
    np.testing.assert_allclose(ev, want, rtol=1e-6)
    np.testing.assert_allclose(ev.real, -1.0 / tau, rtol=0.05)  # near the triple pole at -1/tau


def test_van_loan_matches_closed_form_random_walk():
    """Integrated random walk (clock): Qd = q [[dt^3/3, dt^2/2], [dt^2/2, dt]] and Phi = [[1, dt], [0, 1]]."""
    F = np.array([[0.0, 1.0], [0.0, 0.0]])
    q = 0.3
    phi, qd = em.van_loan(F, np.diag([0.0, q]), 2.0)
    np.testing.assert_allclose(phi, [[1.0, 2.0], [0.0, 1.0]], atol=1e-14)
    np.testing.assert_allclose(qd, q * np.array([[8 / 3, 2.0], [2.0, 2.0]]), rtol=1e-12)


def test_kernel_arrays_are_each_callers_own_writable_copies():
    """kernel_noise / kernel_carrier pack once per noise object but hand every caller its own writable arrays: one
    argument type for the compiled kernels (a read-only view compiled them twice), and a write by one caller cannot
    reach the next."""
    noise = em.ErrorNoise(
        gyro_arw_rad_sqrts=1e-6, accel_vrw_mps_sqrts=1e-5, gyro_bias_rw=1e-9, accel_bias_rw=1e-7,
        baro_bias_sigma_m=1.0, baro_bias_tau_s=100.0, clock_sf=0.1, clock_sg=0.01,
        gse_sigma_m=np.array([2.0, 3.0, 4.0]), gmp_sigma_m=0.5, gio_sigma_m=np.array([1.0, 1.5, 2.0]),
    )
    q, gse, gmp = em.kernel_noise(noise, 3)
    gio, _ = em.kernel_carrier(noise, 3)
    assert all(a.flags.writeable and a.flags.c_contiguous for a in (q, gse, gmp, gio))
    np.testing.assert_array_equal(gse, [2.0, 3.0, 4.0])
    np.testing.assert_array_equal(gmp, [0.5, 0.5, 0.5])
    q0 = q.copy()
    q[:], gse[:], gmp[:], gio[:] = -1.0, -1.0, -1.0, -1.0
    q2, gse2, gmp2 = em.kernel_noise(noise, 3)
    np.testing.assert_array_equal(q2, q0)
    np.testing.assert_array_equal(gse2, [2.0, 3.0, 4.0])
    np.testing.assert_array_equal(gmp2, [0.5, 0.5, 0.5])
    np.testing.assert_array_equal(em.kernel_carrier(noise, 3)[0], [1.0, 1.5, 2.0])
