"""The flare diagnosis's estimators (tools/flare_diagnosis.py, issue 40) on synthetic data: the split of a
touchdown sink into the time-indexed mean and the first-passage weighting (Rice), and the Dryden spectra it
drives the linear model with."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np

from approachsim import units

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("flare_diagnosis", ROOT / "tools" / "flare_diagnosis.py")
fd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fd)


def _rows(sinks_mps: np.ndarray) -> list[dict]:
    n = len(fd.HEIGHTS_FT)
    return [{"termination": "touchdown", "gear": [s] * n, "imu": [s] * n, "lq": [0.0] * n, "td_gear": s,
             "td_imu": s, "td_pitch_rad": 0.07, "td_cas_mps": 66.0, "td_x_m": 580.0, "entry_sink": 3.7,
             "before": [s] * len(fd.BEFORE_S)} for s in sinks_mps]


def test_the_first_passage_split_recovers_the_time_mean_and_rice():
    """A stationary sink process N(mu, s) in time, sampled where the gear crosses a height (each time sample
    weighted by its sink: dh = s dt), has the contact mean mu + s^2 / mu; its harmonic mean is mu again. Seeded;
    200,000 crossings put the standard error of each mean below 0.004 ft/s, the tolerance 0.02 ft/s (5 se)."""
    rng = np.random.default_rng(40)
    mu, sd = 2.35 * units.FPS, 1.14 * units.FPS
    t = rng.normal(mu, sd, 2_000_000)
    t = t[t > 0.05 * mu]  # a descending gear (the truncation moves mu by < 1e-4 ft/s at 2 sd)
    crossed = rng.choice(t, size=200_000, p=t / t.sum())
    out = fd.summary(_rows(crossed), 2.0 * units.FPS)
    mu_t, s_t = t.mean() / units.FPS, t.std() / units.FPS
    assert math.isclose(out["td_sink_fps"]["mean"], mu_t + s_t**2 / mu_t, abs_tol=0.02)
    assert math.isclose(out["heights"][-1]["gear_time_mean"], mu_t, abs_tol=0.02)
    assert math.isclose(out["tracking_bias_fps"], mu_t - 2.0, abs_tol=0.02)
    assert math.isclose(out["first_passage_fps"], s_t**2 / mu_t, abs_tol=0.02)
    assert math.isclose(out["miss_fps"], out["tracking_bias_fps"] + out["first_passage_fps"], abs_tol=1e-9)


def test_the_dryden_spectra_carry_their_variances():
    """One-sided MIL-F-8785C spectra integrate to sigma_u^2 and sigma_w^2 (light: W20 15 kt, sigma_w = 0.1 W20,
    sigma_u = sigma_w / (0.177 + 0.000823 h)^0.4); the tail beyond 1e4 rad/s holds < 0.1 % of either."""
    w = np.logspace(-5, 4, 200_000)
    h = 25.0
    phi_u, phi_w = fd.dryden_psd(w, h, 66.0)
    s_w = 0.1 * 15.0 * units.KT
    s_u = s_w / (0.177 + 0.000823 * h) ** 0.4
    assert math.isclose(np.trapezoid(phi_u, w), s_u**2, rel_tol=2e-3)
    assert math.isclose(np.trapezoid(phi_w, w), s_w**2, rel_tol=2e-3)


def test_the_retard_model_and_the_pitch_command_gain():
    """The retard analysis on the default profile's landing linearization: after a one-unit throttle cut the CG
    sinks from the first 0.1 s and faster each second for 7 s with the speed feed-forward alone (the pitch loop
    lags and droops under the ramping command); the step feed-forward that nulls the height lost at 5.3 s leaves
    it there within 1 mm. The pitch command gain, a closed form, equals an independent linear solve of the
    constant-path trim (alpha = theta, q = 0) for a speed change: the moment balance, the elevator of the
    proportional loop and the lift balance with the elevator's own lift, solved for the command, within 1e-9."""
    from approachsim.flight.run import Approach
    from approachsim.profile import load_profile

    ap = Approach(load_profile(ROOT / "profiles" / "default.toml"))
    lin, g = ap.linearization, ap.aircraft.gains
    h_dot = fd.retard_response(lin, g, 0.0, np.array([0.1]))[0]
    t = np.arange(1.0, 8.0)
    sink = fd.retard_response(lin, g, 0.0, t)
    assert h_dot < 0.0 and np.all(np.diff(sink) < 0.0)
    c = fd.retard_feed_forward(lin, g, 5.3)
    tt = np.linspace(0.0, 5.3, 401)
    assert abs(np.trapezoid(fd.retard_response(lin, g, c, tt), tt)) < 1e-3
    # the constant-path trim: unknowns alpha (= theta), de, theta_c for a speed change dv
    m_a, m_de = lin.A[3, 1], lin.B[3, 2]
    a_av, a_aa, a_at, b_ade = lin.A[1, 0] / units.FT, lin.A[1, 1], lin.A[1, 2], lin.B[1, 2]
    dv = -1.0
    m = np.array([[m_a + lin.A[3, 2], m_de, 0.0],  # moment: M_alpha alpha + M_theta theta + M_de de = 0
                  [-g.k_theta, 1.0, g.k_theta],  # de = -k_theta (theta_c - theta)
                  [a_aa + a_at, b_ade, 0.0]])  # lift: A_aV dv + (A_aa + A_at) alpha + B_a,de de = 0
    alpha, de, theta_c = np.linalg.solve(m, [0.0, 0.0, -a_av * dv])
    alpha_bare = -a_av * dv / (a_aa + a_at)  # what flare_k_v intends: k_v (V_0 - V)
    assert math.isclose(alpha_bare / theta_c, fd.pitch_command_gain(lin, g), rel_tol=1e-9)
