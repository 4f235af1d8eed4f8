"""The aiding interval's error model with a baro scale-factor state is taken at the interval's midpoint height
(core/nav/errormodel.interval_height): the damping loop's sb coefficient -(h - H_ref) follows the height along the
interval, and Phi = exp(F dt) with F held must integrate it. Checked against the exact transition of the
time-varying F(t) of a steady descent (a fine product of sub-interval exponentials)."""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from approachsim.core.nav import errormodel as ek
from approachsim.nav import errormodel as em
from approachsim.nav import vertical_loop as vl

NOISE = em.ErrorNoise(
    gyro_arw_rad_sqrts=1e-6, accel_vrw_mps_sqrts=1e-5, gyro_bias_rw=1e-9, accel_bias_rw=1e-7,
    baro_bias_sigma_m=1.0, baro_bias_tau_s=100.0, clock_sf=0.1, clock_sg=0.01, baro_ref_m=4.0,
)
LAT = np.radians(37.6)
F_NED = np.array([0.0, 0.0, -9.8])
V_D = 3.6  # m/s down: a 3 deg final at 140 kt
DT = 1.0
GAINS = vl.constant_gains(100.0)  # the default loop (nav.baro_loop_tau_s)


def _F(lay: em.StateLayout, h_m: float) -> np.ndarray:
    return em.dynamics(lay, LAT, h_m, np.array([70.0, 0.0, V_D]), F_NED, np.eye(3), NOISE, GAINS)[0]


def test_without_the_scale_factor_state_or_the_loop_the_height_is_the_given_one():
    """Only the loop's sb column moves with h at this scale: without the state or without the loop (the CAT III
    candidates: sb, no loop) the model is taken where it was, bit for bit."""
    x = np.zeros(em.StateLayout(baro_scale=True, clock=False, loop=False).n)
    x[2] = 2.0
    for sb, loop in ((False, True), (True, False), (False, False)):
        lay = em.StateLayout(baro_scale=sb, clock=False, loop=loop)
        assert em.interval_height(lay, 300.0, V_D, DT) == 300.0
        assert ek.interval_height(lay.packed, 300.0, V_D, DT) == 300.0
        assert em.linear_height(lay, 300.0, x[:lay.n], V_D, DT) == (302.0 if sb else 300.0)


def test_with_it_the_midpoint_of_a_steady_descent():
    lay = em.StateLayout(baro_scale=True, clock=False, loop=True)
    assert em.interval_height(lay, 300.0, V_D, DT) == 300.0 + 0.5 * V_D * DT
    x = np.zeros(lay.n)
    x[lay.i("dp", 2)], x[lay.i("dv", 2)] = 2.0, 0.4  # the navigation's height and velocity: INS less the error
    assert em.linear_height(lay, 300.0, x, V_D, DT) == 302.0 + 0.5 * (V_D - 0.4) * DT


def test_the_midpoint_model_integrates_the_loops_scale_factor_column():
    """The sb column of Phi (dp_D, dv_D, ac rows) over one interval ending at 300 m: exact (the time-varying F of
    h(t) = h_end + V_D (dt - t), 4000 sub-steps) against F held at the midpoint and at the end. Held at the end it
    is short by C1 sb V_D dt^2 / 2 in dp_D (0.054 m per unit sb); at the midpoint the error is Magnus's
    [F', F] dt^3 / 12 term, of order C1^2 V_D dt^3 / 12 (3e-4): the midpoint must be over 50x closer."""
    lay = em.StateLayout(baro_scale=True, clock=False, loop=True)
    isb, rows = lay.i("sb"), [lay.i("dp", 2), lay.i("dv", 2), lay.i("ac")]
    h_end, n = 300.0, 4000
    exact = np.eye(lay.n)
    for k in range(n):  # t from 0 to dt: h(t) from h_end + V_D dt down to h_end
        t = (k + 0.5) * DT / n
        exact = expm(_F(lay, h_end + V_D * (DT - t)) * DT / n) @ exact
    mid = expm(_F(lay, em.interval_height(lay, h_end, V_D, DT)) * DT)
    end = expm(_F(lay, h_end) * DT)
    err_mid = np.abs(mid[rows, isb] - exact[rows, isb]).max()
    err_end = np.abs(end[rows, isb] - exact[rows, isb]).max()
    c1 = GAINS.c1
    assert abs(err_end - c1 * V_D * DT**2 / 2.0) < 0.05 * c1 * V_D * DT**2 / 2.0  # the end's shortfall as derived
    assert err_mid < err_end / 50.0
