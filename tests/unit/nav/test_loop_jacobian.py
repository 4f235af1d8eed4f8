"""The per-run EKF's damping loop with a baro scale-factor state (core/nav/errormodel.loop_jacobian,
predict_mean, end_height; issue 39).

The loop error the INS sees, e = -dp_D - bb - (h_ins + dp_D - H_ref) sb, is bilinear in (dp_D, sb). The interval's
model F of the estimate gives it exactly at the estimate (F x_hat's loop part = g e(x_hat)); the covariance needs
the Jacobian de/dx at the estimate, -(1 + sb) at dp_D. Checked here against e itself, and the estimate's
prediction exp(F dt) x against scipy's matrix exponential.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from approachsim.core.nav import errormodel as ek
from approachsim.nav import errormodel as em
from approachsim.nav import vertical_loop as vl

EPS = np.finfo(float).eps
H_REF = 4.0  # m, the altimeter-setting reference (the field)
NOISE = em.ErrorNoise(
    gyro_arw_rad_sqrts=1e-6, accel_vrw_mps_sqrts=1e-5, gyro_bias_rw=1e-9, accel_bias_rw=1e-7,
    baro_bias_sigma_m=1.0, baro_bias_tau_s=100.0, clock_sf=0.1, clock_sg=0.01, baro_ref_m=H_REF,
)
LAT = np.radians(37.6)
V_NED = np.array([70.0, 0.0, 3.6])
F_NED = np.array([0.0, 0.0, -9.8])
GAINS = vl.constant_gains(100.0)
LAY = em.StateLayout(baro_scale=True, clock=True, loop=True, n_sv=4)


def _F(lay: em.StateLayout, h_m: float, held: bool = False) -> np.ndarray:
    return em.dynamics(lay, LAT, h_m, V_NED, F_NED, np.eye(3), NOISE, GAINS, loop_held=held)[0]


def _x_hat(lay: em.StateLayout, rng: np.random.Generator, sb: float) -> np.ndarray:
    x = rng.normal(0.0, 0.01, lay.n)
    x[lay.i("dp", 2)], x[lay.i("bb")], x[lay.i("sb")] = 80.0, 1.5, sb  # a hot day's baro-dragged INS
    return x


def _loop_error(lay: em.StateLayout, x: np.ndarray, h_ins: float) -> float:
    """e = -dp_D - bb - (h_ins + dp_D - H_ref) sb (m): the loop error of the true state x (h = h_ins + dp_D)."""
    dp, bb, sb = x[lay.i("dp", 2)], x[lay.i("bb")], x[lay.i("sb")]
    return -dp - bb - (h_ins + dp - H_REF) * sb


def _rows(lay: em.StateLayout) -> list[int]:
    return [lay.i("dp", 2), lay.i("dv", 2), lay.i("ac")]


@pytest.mark.parametrize("sb", [-0.094, 0.116])  # ISA +30 / -30 uncorrected
def test_the_estimates_model_gives_the_loop_error_at_the_estimate(sb):
    """(F - F_held) x_hat = (C1, C2, C3) e(x_hat) with F taken at the navigation's height h_ins + dp_D_hat: the
    estimate's model is exact in the bilinear term (F's -1 at dp_D, not the Jacobian's -(1 + sb))."""
    x = _x_hat(LAY, np.random.default_rng(1), sb)
    h_ins = 900.0
    h_nav = h_ins + x[LAY.i("dp", 2)]
    loop_part = (_F(LAY, h_nav) - _F(LAY, h_nav, held=True)) @ x
    e = _loop_error(LAY, x, h_ins)
    g = np.array([GAINS.c1, GAINS.c2, GAINS.c3])
    # a row's 3 products of g with dp (80 m), bb, h sb (~100 m): rounding eps times those operands, a few times
    tol = 8 * EPS * g * (abs(x[LAY.i("dp", 2)]) + abs(x[LAY.i("bb")]) + abs(h_nav * sb))
    np.testing.assert_array_less(np.abs(loop_part[_rows(LAY)] - g * e), tol)


@pytest.mark.parametrize("sb", [-0.094, 0.116])
def test_the_covariances_model_is_the_jacobian_of_the_loop_error(sb):
    """loop_jacobian's loop part at dp_D and sb is (C1, C2, C3) de/dx at the estimate, de/dx by a central
    difference of e (bilinear: exact but for rounding); loop_mean puts F back bit for bit."""
    x = _x_hat(LAY, np.random.default_rng(2), sb)
    h_ins = 900.0
    F = _F(LAY, h_ins + x[LAY.i("dp", 2)])
    F_held = _F(LAY, h_ins + x[LAY.i("dp", 2)], held=True)
    F_jac = em.loop_jacobian(LAY, F, GAINS, False, sb)
    assert F_jac is not None
    g = np.array([GAINS.c1, GAINS.c2, GAINS.c3])
    for col, step in ((LAY.i("dp", 2), 1e-3), (LAY.i("sb"), 1e-6)):
        xp, xm = x.copy(), x.copy()
        xp[col] += step
        xm[col] -= step
        de = (_loop_error(LAY, xp, h_ins) - _loop_error(LAY, xm, h_ins)) / (2 * step)
        # the difference quotient: e (~100 m) rounded to eps |e| in each of two evaluations, over 2 step
        tol = g * (4 * EPS * 200.0 / (2 * step) + 8 * EPS * abs(de))
        np.testing.assert_array_less(np.abs((F_jac - F_held)[_rows(LAY), col] - g * de), tol)
    assert abs((F_jac - F_held)[LAY.i("dp", 2), LAY.i("dp", 2)] + GAINS.c1 * (1 + sb)) <= 4 * EPS * GAINS.c1
    keep = np.empty(3)
    G = F.copy()
    assert ek.loop_jacobian(LAY.packed, em.kernel_loop(GAINS), False, sb, G, keep)
    np.testing.assert_array_equal(G, F_jac)
    ek.loop_mean(LAY.packed, keep, G)
    np.testing.assert_array_equal(G, F)


def test_without_the_state_the_loop_or_with_the_loop_held_the_model_is_one():
    """No bilinear term: F is the Jacobian already (loop_jacobian None / False, F untouched)."""
    for lay, held in ((LAY, True), (em.StateLayout(baro_scale=False, clock=True, loop=True), False),
                      (em.StateLayout(baro_scale=True, clock=True, loop=False), False)):
        F = em.dynamics(lay, LAT, 300.0, V_NED, F_NED, np.eye(3), NOISE, GAINS if lay.loop else None,
                        loop_held=held)[0]
        assert em.loop_jacobian(lay, F, GAINS if lay.loop else None, held, 0.1) is None


def test_end_height_moves_dp_by_its_rate():
    """h_nav + (F x)[dp_D] dt: the estimate's own change of dp_D over the interval."""
    x = _x_hat(LAY, np.random.default_rng(3), -0.094)
    F = _F(LAY, 950.0)
    rate = float(F[LAY.i("dp", 2)] @ x)
    got = ek.end_height(LAY.packed, F, x, 980.0, 1.0)
    assert abs(got - (980.0 + rate)) <= 4 * EPS * (980.0 + np.abs(F[LAY.i("dp", 2)]) @ np.abs(x))
    assert abs(rate) > 0.1  # the loop moves dp_D by tenths of a metre per second here (2.9 m/s early in a hot final)


def _expm_action_long(F: np.ndarray, x: np.ndarray, dt_s: float) -> np.ndarray:
    """exp(F dt) x in extended precision (numpy's longdouble, 64-bit mantissa on x86-64): a Taylor series over
    steps of norm <= 1/4, 60 terms: an independent reference some 2^-11 of a double's rounding."""
    A = F.astype(np.longdouble)
    y = x.astype(np.longdouble)
    steps = max(1, int(np.ceil(4.0 * np.abs(F).sum(axis=1).max() * dt_s)))
    h = np.longdouble(dt_s) / steps
    for _ in range(steps):
        term, acc = y.copy(), y.copy()
        for k in range(1, 60):
            term = (A @ term) * h / k
            acc = acc + term
        y = acc
    return y.astype(float)


@pytest.mark.parametrize("dt_s", [0.1, 1.0, 5.0])
def test_predict_mean_is_the_exponential_on_coupled_states_and_phi_on_the_rest(dt_s):
    """exp(F dt) x on the states F couples (an extended-precision series the reference); Phi's diagonal (here
    scaled, as scale_channels does) on the decoupled ones, exactly. Tolerance: the kernel's series sums terms
    bounded by exp(|F| dt) |x| elementwise, each rounded to eps of that size, over at most ~25 terms a step and
    |F dt| / 2 steps; 64 eps of the bound per step is well above that (measured: at most 7 eps of the bound) and far
    below any wrong term (a missing Taylor term at dt = 5 s is ~1e-3 of |x|)."""
    rng = np.random.default_rng(4)
    x = _x_hat(LAY, rng, 0.116)
    F = _F(LAY, 980.0)
    Qc = em.dynamics(LAY, LAT, 980.0, V_NED, F_NED, np.eye(3), NOISE, GAINS)[1]
    phi, _ = em.discretize(F, Qc, dt_s)
    gse = LAY.index["gse"]
    phi[gse.start, gse.start] *= 1.3  # a channel's scale over the interval (core/nav/errormodel.scale_channels)
    got = em.predict_mean(F, phi, x, dt_s)
    off = F.copy()
    np.fill_diagonal(off, 0.0)
    lone = ~((off != 0.0).any(axis=0) | (off != 0.0).any(axis=1))
    want = _expm_action_long(F, x, dt_s)
    bound = expm(np.abs(F) * dt_s) @ np.abs(x)
    steps = max(1, int(np.ceil(0.5 * np.abs(F).sum(axis=1).max() * dt_s)))
    tol = 64 * EPS * steps * bound
    np.testing.assert_array_less(np.abs(got - want)[~lone], tol[~lone])
    np.testing.assert_array_equal(got[lone], np.diag(phi)[lone] * x[lone])
    assert lone[gse.start] and not lone[LAY.i("dp", 2)]


@pytest.mark.parametrize("form", ["tanh", "sinh"])
def test_an_adaptive_loops_estimate_takes_its_pull_not_its_slope(form):
    """NavSystem.loop_linearization: the estimate's C1 / C2 branch terms are E[k(e)] over e ~ N(e_hat, var) (the
    statistical linearization's constant term), F's slope s times e_hat plus the offset b. Checked against the
    expectation by adaptive quadrature; on a cold day's loop error (e_hat ~ -90 m, tanh saturated) the pull is
    -C1 where s e_hat is nearly 0."""
    from dataclasses import replace

    from scipy import integrate, stats

    from approachsim.nav.base import FilterState
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile

    prof = load_profile(Path(__file__).resolve().parents[3] / "profiles" / "default.toml")
    cfg = replace(prof.nav, baro_loop=form)
    system = NavSystem.build(cfg, prof.sensors, prof.runway.frame, prof.terrain)
    lay = system.layout
    g = system.loop_gains()
    x = np.zeros(lay.n)
    x[lay.i("sb")] = 0.1 if form == "tanh" else 0.002  # sinh grows: a moderate loop error for it
    P = np.eye(lay.n) * 1e-6
    P[lay.i("dp", 2), lay.i("dp", 2)] = 0.04
    fs = FilterState(x=x, P=P)
    noise = system.noise(None)
    h_m = system.baro_ref_m + 900.0
    s, b = system.loop_linearization(fs, h_m, noise)
    e_hat = -(h_m - system.baro_ref_m) * x[lay.i("sb")]
    sd = np.sqrt((1.0 + x[lay.i("sb")]) ** 2 * 0.04 + 900.0**2 * 1e-6 + noise.baro_noise_sigma_m**2)
    for c, bb, i in ((g.c1, g.b1_per_m, lay.i("dp", 2)), (g.c2, g.b2_per_m, lay.i("dv", 2))):
        f = np.tanh if form == "tanh" else np.sinh
        want = integrate.quad(lambda e, c=c, bb=bb, f=f: c * f(bb * e) * stats.norm.pdf(e, e_hat, sd),
                              e_hat - 10 * sd, e_hat + 10 * sd, epsabs=0.0, epsrel=1e-12)[0]
        slope = s.c1 if i == lay.i("dp", 2) else s.c2
        # the 5-point Gauss-Hermite rule is exact to degree 9; its error is n! / (2n)! sd^10 f^(10)(xi), n = 5, and
        # f^(10) of c f(b e) is b^10 times f's scale here (4x for cosh over the nodes' spread), plus quad's 1e-10
        tol = 4 * math.factorial(5) / math.factorial(10) * (bb * sd) ** 10 * max(abs(want), c) + 1e-10 * c
        assert abs(slope * e_hat + b[i] - want) <= tol, (slope * e_hat + b[i], want, tol)
    if form == "tanh":
        assert abs(b[lay.i("dp", 2)] + s.c1 * e_hat + g.c1) < 1e-6 * g.c1  # saturated: the pull is -C1
        assert abs(s.c1 * e_hat) < 1e-3 * g.c1  # and the slope's share of it nearly nothing
    const = NavSystem.build(replace(prof.nav, baro_loop="constant"), prof.sensors, prof.runway.frame, prof.terrain)
    assert const.loop_linearization(fs, h_m, noise)[1] is None
