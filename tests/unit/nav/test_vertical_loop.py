"""3rd-order baro-inertial loop (seed 003 eq. 3-5, 7, 16): gains, poles (python-control), time response."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim.nav import vertical_loop as vl


@pytest.mark.parametrize("tau_s", [10.0, 50.0, 100.0, 300.0])
def test_constant_gains_put_all_three_poles_at_minus_one_over_tau(tau_s: float) -> None:
    gains = vl.constant_gains(tau_s)
    assert gains.c1 == pytest.approx(3.0 / tau_s)
    assert gains.c2 == pytest.approx(3.0 / tau_s**2 + 2.0 * vl.G0_MPS2 / vl.R0_M)
    assert gains.c3 == pytest.approx(1.0 / tau_s**3)
    poles = vl.closed_loop_poles(gains)
    # a triple root is ill-conditioned: the roots split by ~ eps^(1/3) relative; 1e-3 of 1/tau is far tighter
    # than any wrong gain (a 1 % error in C2 moves them by several %).
    np.testing.assert_allclose(poles.real, -1.0 / tau_s, rtol=1e-3)
    np.testing.assert_allclose(poles.imag, 0.0, atol=1e-3 / tau_s)
    np.testing.assert_allclose(np.sort(np.roots(vl.characteristic_polynomial(gains)).real), np.sort(poles.real),
                               rtol=1e-3)


def test_without_the_2g_over_r_term_the_loop_would_not_have_a_triple_pole() -> None:
    tau = 100.0
    naive = vl.LoopGains(3.0 / tau, 3.0 / tau**2, 1.0 / tau**3)
    poles = vl.closed_loop_poles(naive)
    assert np.max(np.abs(poles + 1.0 / tau)) > 1e-3 / tau * 10


def test_unstable_when_c2_below_2g_over_r() -> None:
    bad = vl.LoopGains(0.03, 1.0e-6, 1.0e-9)
    assert np.max(vl.closed_loop_poles(bad).real) > 0.0


def test_adaptive_forms_linearize_to_c_times_b() -> None:
    g = vl.LoopGains(0.06, 6.2e-4, 1.2e-6, "tanh", 0.5, 0.25)
    lin = g.linearized()
    assert (lin.c1, lin.c2, lin.c3) == pytest.approx((0.03, 1.55e-4, 1.2e-6))
    e = np.array([1e-4, -2e-4])
    k1, k2 = vl.branch_corrections(g, e)
    np.testing.assert_allclose(k1, lin.c1 * e, rtol=1e-7)
    np.testing.assert_allclose(k2, lin.c2 * e, rtol=1e-7)
    # tanh saturates at C_KF, sinh grows faster than linear
    k1_big, _ = vl.branch_corrections(g, np.array([100.0]))
    assert k1_big[0] == pytest.approx(0.06)
    s = vl.LoopGains(0.017, 2e-4, 1.2e-6, "sinh", 1.0, 1.0)
    k1s, _ = vl.branch_corrections(s, np.array([5.0]))
    assert k1s[0] == pytest.approx(0.017 * np.sinh(5.0)) and k1s[0] > 0.017 * 5.0


def test_invalid_gains_name_the_field() -> None:
    with pytest.raises(ValueError, match="form"):
        vl.LoopGains(0.03, 3e-4, 1e-6, "cosh")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="c2"):
        vl.LoopGains(0.03, -3e-4, 1e-6)
    with pytest.raises(ValueError, match="tau_s"):
        vl.constant_gains(0.0)


def _fly(gains: vl.LoopGains | None, t_end_s: float, bias_mps2: float, h0_err_m: float) -> np.ndarray:
    """Stationary at 1000 m with a constant accelerometer bias; baro exact. Returns the altitude error (m)."""
    dt = 1.0
    h_true = 1000.0
    ch = vl.init_channel(np.array([h_true + h0_err_m]))
    err = []
    for _ in range(int(t_end_s / dt)):
        f_up = vl.gravity_flat_mps2(h_true) + bias_mps2
        g_ins = vl.gravity_flat_mps2(ch.h_m)
        if gains is None:  # free inertial: no loop (a loop with ~zero gains would be rejected)
            v = ch.v_up_mps + (f_up - g_ins) * dt
            ch = vl.VerticalChannel(ch.h_m + 0.5 * (ch.v_up_mps + v) * dt, v, ch.a_comp_mps2)
        else:
            ch = vl.step(ch, f_up, h_true, g_ins, dt, gains)
        err.append(ch.h_m[0] - h_true)
    return np.array(err)


def test_free_inertial_channel_diverges_with_the_schuler_like_time_constant() -> None:
    t_end = 3000.0
    err = _fly(None, t_end, 0.0, 1.0)
    # dh'' = (2 g/R) dh: dh(t) = dh0 cosh(t sqrt(2g/R))
    expected = np.cosh(t_end * np.sqrt(2 * vl.G0_MPS2 / vl.R0_M))
    assert err[-1] == pytest.approx(expected, rel=0.01)


def test_damped_channel_removes_an_accelerometer_bias_with_zero_steady_state_error() -> None:
    gains = vl.constant_gains(100.0)
    err = _fly(gains, 3000.0, 1e-3, 5.0)
    assert abs(err[-1]) < 1e-3  # integral branch: zero steady-state altitude error (m)
    assert np.max(np.abs(err)) < 10.0


@pytest.mark.parametrize("form,c1,c2", [("tanh", 0.06, 6.2e-4), ("sinh", 0.017, 2e-4)])
def test_adaptive_loops_with_the_papers_gains_converge(form: str, c1: float, c2: float) -> None:
    gains = vl.LoopGains(c1, c2, 1.2e-6, form, 1.0, 1.0)  # type: ignore[arg-type]
    assert np.max(vl.closed_loop_poles(gains).real) < 0.0
    err = _fly(gains, 5000.0, 1e-4, 2.0)
    assert abs(err[-1]) < 0.01
