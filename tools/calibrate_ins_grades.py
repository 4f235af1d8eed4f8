"""Derive the seed-002 INS grades' gyro turn-on bias from their defining CEP rate (sensors/presets.py).

A grade "X nmi/h CEP" is read as: stationary at mid-latitude, after the INS's own stationary alignment
(ins.align_stationary, 8 min), the median horizontal radial position error at 1 h is X nmi (CEP = the radius
holding half the runs; "CEP rate" = CEP(1 h) / 1 h). Seed 002 changes only the random constants between its
three grades, so the grade-common terms (Gauss-Markov bias instability, ARW, scale factors, misalignments,
accelerometer errors) are held at their preset values and the gyro turn-on bias sigma eps is solved for:

    CEP(P_const(eps) + P_noise) = X nmi,      P = 2x2 covariance of the (north, east) error at 1 h.

* P_const: the error at 1 h is linear in each random constant (to < 1e-3 at these sizes). Its sensitivity
  to each constant (gyro / accelerometer bias per body axis, the 9 + 9 scale-factor / misalignment matrix
  elements) is measured with the repository's own alignment and INS: one noise-free stationary run per
  constant, vertical channel held on truth (as the baro loop of the test nearly does), minus the unperturbed
  run. So every coupling the mechanization has is in it. What it shows: after gyrocompassing the east gyro
  bias is cancelled by the heading error it causes and the accelerometer biases by the tilt they cause; the
  north gyro bias is not seen by the alignment and drives the east error as R eps (t - sin(w_s t) / w_s)
  (Schuler; 1.217 R eps t at 1 h); the vertical gyro bias adds a little through heading x Earth rate.
  The error is nearly one-dimensional, so CEP ~ 0.6745 sigma, not the 1.1774 sigma of a circular error.
* P_noise (common to the grades): the Gauss-Markov gyro and accelerometer bias instability and the white
  ARW / VRW, through the linear Schuler responses (gyro rate error -> R (1 - cos w_s (t - s)); accelerometer
  error -> sin(w_s (t - s)) / w_s) with the alignment's means subtracted where the alignment sees them (east
  gyro through the heading, both horizontal accelerometers through the tilt). The noise averaged over the
  alignment is the gyrocompass heading error N / (W cos L sqrt(T_align)): a constant east drift of
  N / sqrt(T_align) after it. Earth-rate cross-couplings of the noise are neglected (second order).
* CEP of a 2-D Gaussian: the radius c with P(|e| < c) = 1/2, integrated numerically on its principal axes.

Run: python tools/calibrate_ins_grades.py  (a few seconds); it prints the derivation per grade and the
turn-on biases written into presets.py. tests/integration/test_nav_free_inertial.py checks that the presets
still equal this derivation and that a Monte Carlo of the full simulation meets the grades.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq
from scipy.special import erf

from approachsim import geo, synthetic, units
from approachsim.nav import ins
from approachsim.sensors.imu import true_increments
from approachsim.sensors.presets import DEG_PER_H, PRESETS, ImuGrade

LAT, LON, H = math.radians(37.6), math.radians(-122.36), 100.0
HEADING_RAD = math.radians(30.0)
T_ALIGN_S, T_NAV_S = 480.0, 3600.0
RATE_HZ = 1.0  # stationary: the mechanization is exact at any rate
GRADES_NMI_PER_H = {"nav-0.4": 0.4, "nav-2.0": 2.0, "nav-4.0": 4.0}


def cep_2d(cov: np.ndarray) -> float:
    """CEP (m) of a zero-mean 2-D Gaussian with covariance cov (2, 2), m^2: P(radius < CEP) = 1/2."""
    s_lo, s_hi = np.sqrt(np.maximum(np.linalg.eigvalsh(cov), 1e-30))
    y = np.linspace(-8.0, 8.0, 4001) * s_lo
    pdf = np.exp(-0.5 * (y / s_lo) ** 2) / (s_lo * math.sqrt(2.0 * math.pi))

    def excess(c: float) -> float:
        x = np.sqrt(np.clip(c * c - y * y, 0.0, None))
        return float(np.trapezoid(erf(x / (s_hi * math.sqrt(2.0))) * pdf, y)) - 0.5

    return brentq(excess, 1e-6 * s_hi, 10.0 * (s_lo + s_hi))


def constant_sensitivities() -> dict[str, np.ndarray]:
    """Horizontal (north, east) error at 1 h, m, per unit of each random constant, from the repository's INS.

    Keys: gyro_bias (3 body axes, per rad/s), accel_bias (3, per m/s^2), gyro_m and accel_m (9 matrix
    elements row-major, per unit). Shape (n, 2) each.
    """
    truth = synthetic.stationary(LAT, LON, H, T_ALIGN_S + T_NAV_S, RATE_HZ, euler_rad=(0.0, 0.0, HEADING_RAD))
    dth0, dv0, dt = true_increments(truth, np.arange(1, truth.t_s.size))
    u_g, u_a, u_m = 0.01 * DEG_PER_H, 10.0 * units.G0 * 1e-6, 1e-5  # small: the response is linear
    cases: list[tuple[np.ndarray, np.ndarray]] = [(dth0, dv0)]
    for i in range(3):
        cases.append((dth0 + u_g * dt * np.eye(3)[i], dv0))
    for i in range(3):
        cases.append((dth0, dv0 + u_a * dt * np.eye(3)[i]))
    for i in range(9):
        m = u_m * np.eye(9)[i].reshape(3, 3)
        cases.append((dth0 + dth0 @ m.T, dv0))
    for i in range(9):
        m = u_m * np.eye(9)[i].reshape(3, 3)
        cases.append((dth0, dv0 + dv0 @ m.T))
    dth = np.stack([c[0] for c in cases])
    dv = np.stack([c[1] for c in cases])
    n, m_al = dth.shape[0], int(T_ALIGN_S * RATE_HZ)
    c_bn = ins.align_stationary(dth[:, :m_al], dv[:, :m_al], np.full(n, LAT))
    s = ins.init_state(np.full(n, LAT), LON, H, np.zeros(3), c_bn)
    keep_h = np.array([1.0, 1.0, 0.0])
    for k in range(m_al, dth.shape[1]):
        s = ins.step(s, dth[:, k], dv[:, k], 1.0 / RATE_HZ)
        s = replace(s, h_m=np.full(n, H), v_ned=s.v_ned * keep_h)  # vertical channel held on truth
    dp = ins.position_error_ned(s.lat_rad, s.lon_rad, s.h_m, LAT, LON, H)[:, :2]
    d = dp[1:] - dp[0]
    return {"gyro_bias": d[0:3] / u_g, "accel_bias": d[3:6] / u_a, "gyro_m": d[6:15] / u_m,
            "accel_m": d[15:24] / u_m}


def _linear_functional_var(w_align: float, w_nav: np.ndarray, sigma: float, tau_s: float, white: float,
                           dt: float) -> float:
    """Variance of  w_align * mean_{[-T_align, 0]}(x) + integral_0^T w_nav(s) x(s) ds  for x = first-order
    Gauss-Markov (sigma, tau_s) plus white noise of density `white` (units/sqrt(Hz)); w_nav on the grid."""
    n_al = int(round(T_ALIGN_S / dt))
    w = np.concatenate([np.full(n_al, w_align / T_ALIGN_S), w_nav]) * dt  # discrete weights
    t = (np.arange(w.size) + 0.5) * dt
    gm = sigma**2 * float(w @ (np.exp(-np.abs(t[:, None] - t[None, :]) / tau_s) @ w)) if sigma > 0 else 0.0
    return gm + white**2 * float(w @ w) / dt


def noise_covariance(g: ImuGrade, dt: float = 2.0) -> np.ndarray:
    """(2, 2) covariance, m^2, of the (north, east) error at 1 h from the grade's stochastic terms."""
    r = geo.A_WGS84
    ws = math.sqrt(float(geo.normal_gravity(LAT, H)) / r)
    s = (np.arange(int(round(T_NAV_S / dt))) + 0.5) * dt
    h_gyro = r * (1.0 - np.cos(ws * (T_NAV_S - s)))  # position per unit level-gyro rate error
    h_acc = np.sin(ws * (T_NAV_S - s)) / ws  # position per unit horizontal accelerometer error
    s_gyro = float(np.sum(h_gyro) * dt)  # response to a constant, = R (T - sin(ws T) / ws)
    s_acc = float(np.sum(h_acc) * dt)
    gyro = (g.gyro_bi_radps, g.gyro_bi_tau_s, g.gyro_arw_rad_sqrts)
    acc = (g.accel_bi_mps2, g.accel_bi_tau_s, g.accel_vrw_mps_sqrts)
    # north error: east gyro (alignment removes its mean through the heading) + north accelerometer (tilt)
    v_n = (_linear_functional_var(-s_gyro, h_gyro, *gyro, dt) + _linear_functional_var(-s_acc, h_acc, *acc, dt))
    # east error: north gyro (not seen by the alignment) + east accelerometer (tilt removes its mean)
    v_e = (_linear_functional_var(0.0, h_gyro, *gyro, dt) + _linear_functional_var(-s_acc, h_acc, *acc, dt))
    return np.diag([v_n, v_e])


def grade_covariance(g: ImuGrade, sens: dict[str, np.ndarray], gyro_bias_radps: float,
                     noise: np.ndarray | None = None) -> np.ndarray:
    """(2, 2) covariance, m^2, of the (north, east) error at 1 h of grade g with turn-on gyro bias sigma
    (noise: noise_covariance(g) if already computed)."""
    p = gyro_bias_radps**2 * sens["gyro_bias"].T @ sens["gyro_bias"]
    p = p + g.accel_bias_mps2**2 * sens["accel_bias"].T @ sens["accel_bias"]
    for key, diag, off in (("gyro_m", g.gyro_sf, g.gyro_misalign_rad), ("accel_m", g.accel_sf, g.accel_misalign_rad)):
        sig = np.where(np.eye(3).ravel() > 0, diag, off)
        p = p + (sens[key] * sig[:, None]).T @ (sens[key] * sig[:, None])
    return p + (noise_covariance(g) if noise is None else noise)


def derive(sens: dict[str, np.ndarray] | None = None) -> dict[str, float]:
    """Gyro turn-on bias sigma (deg/h) per seed-002 grade that gives its CEP rate; other terms as preset."""
    sens = constant_sensitivities() if sens is None else sens
    out = {}
    for name, rate in GRADES_NMI_PER_H.items():
        g = PRESETS[name]
        target = rate * units.NMI * T_NAV_S / 3600.0
        noise = noise_covariance(g)
        floor = cep_2d(grade_covariance(g, sens, 0.0, noise))
        if floor >= target:
            raise ValueError(f"{name}: the grade-common terms alone give CEP {floor / units.NMI:.3f} nmi")
        eps = brentq(lambda e, g=g, noise=noise, target=target: cep_2d(grade_covariance(g, sens, e, noise)) - target,
                     0.0, 1.0 * DEG_PER_H, xtol=1e-6 * DEG_PER_H)
        out[name] = eps / DEG_PER_H
    return out


def main() -> None:
    sens = constant_sensitivities()
    r = geo.A_WGS84
    print("sensitivity of the 1 h error to a gyro turn-on bias, per body axis (heading 30 deg), in units of R eps T:")
    print(np.round(sens["gyro_bias"] / (r * T_NAV_S), 3), "(columns north, east)")
    eps = derive(sens)
    for name, rate in GRADES_NMI_PER_H.items():
        g = PRESETS[name]
        noise = noise_covariance(g)
        p = grade_covariance(g, sens, eps[name] * DEG_PER_H, noise)
        floor = cep_2d(grade_covariance(g, sens, 0.0, noise))
        print(f"{name}: target {rate} nmi/h; grade-common terms alone: CEP {floor / units.NMI:.3f}"
              f" nmi (noise sigma N, E = {math.sqrt(noise[0, 0]) / units.NMI:.3f},"
              f" {math.sqrt(noise[1, 1]) / units.NMI:.3f} nmi);"
              f" turn-on gyro bias {eps[name]:.4f} deg/h -> sigma N, E = {math.sqrt(p[0, 0]) / units.NMI:.3f},"
              f" {math.sqrt(p[1, 1]) / units.NMI:.3f} nmi, CEP {cep_2d(p) / units.NMI:.3f} nmi"
              f" (preset now {PRESETS[name].gyro_bias_radps / DEG_PER_H:.4f} deg/h)")


if __name__ == "__main__":
    main()
