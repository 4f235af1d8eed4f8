"""Free-inertial INS performance (issue 4 acceptance): stationary for 1 h after an 8-minute analytic
alignment, 200 seeded runs per seed-002 grade (sensors/presets.py), vertical channel on the 3rd-order baro loop.

* horizontal radial drift rate, CEP at 1 h (median radial error over the runs) / 1 h, within +-30 % of the
  grade's 0.4 / 2.0 / 4.0 nmi/h. With 200 runs the median scatters by about 8 % (1-sigma; the error is nearly
  one-dimensional, the east error of the north gyro bias); with the issue's 30 runs it scatters by 21 %, so
  30 runs could not decide +-30 %. Measured CEP rates, nmi/h, 200 runs per grade, campaign seeds 1 / 2 / 3 /
  4 / 5: nav-0.4 0.420 / 0.383 / 0.427 / 0.433 / 0.403; nav-2.0 2.089 / 1.964 / 1.936 / 2.109 / 1.885; nav-4.0
  4.092 / 4.105 / 3.934 / 4.071 / 4.070 (all within 9 %; the six 30-run subsets of each seed range over
  0.27-0.59, 1.41-3.12 and 2.66-6.47). The presets are derived from the grades by
  tools/calibrate_ins_grades.py, which test_presets_follow_the_grade_derivation re-runs;
* the grades and the INS against something else than themselves: the presets' CEP rates from an analytic
  free-inertial error model written here (psi-angle error equations, Schuler loop and Earth-rate coupling,
  gyrocompass / leveling steady state as the initial attitude error; Titterton & Weston, *Strapdown Inertial
  Navigation Technology*, ch. 12; covariance propagated with the presets' turn-on, Gauss-Markov and white
  terms): measured 0.403 / 2.004 / 3.998 nmi/h; and the same model's response to single deterministic biases
  reproduces the INS's own 1 h error (within 1 m of 240 m);
* the unaided vertical channel diverges with the time constant sqrt(R / 2 g);
* with the baro loop (seed 003 eq. 5 gains, tau = 100 s) the height error stays bounded: its RMS over the
  runs stays within 3x the baro 1-sigma for the whole hour.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sl

from approachsim import geo, synthetic, units
from approachsim.nav import ins
from approachsim.nav import vertical_loop as vl
from approachsim.seeding import stream
from approachsim.sensors.baro import Baro
from approachsim.sensors.imu import Imu
from approachsim.sensors.presets import DEG_PER_H, PRESETS

LAT, LON, H = np.radians(37.6), np.radians(-122.36), 100.0
RATE_HZ = 1.0  # stationary: the mechanization is exact at any rate; 1 Hz keeps 600 runs under ~30 s
T_ALIGN, T_NAV = 480.0, 3600.0
RUNS = 200
GRADES = {"nav-0.4": 0.4, "nav-2.0": 2.0, "nav-4.0": 4.0}
SEED = 1


def free_inertial_runs(seed: int, runs: int = RUNS) -> tuple[np.ndarray, np.ndarray, float]:
    """All grades' runs stepped together: radial horizontal error at 1 h (grades, runs), m; the height
    error each minute (minutes, grades * runs), m; the baro 1-sigma, m."""
    truth = synthetic.stationary(LAT, LON, H, T_ALIGN + T_NAV, RATE_HZ, euler_rad=(0.0, 0.0, np.radians(30.0)))
    dth, dv = [], []
    for gi, grade in enumerate(GRADES):
        rec = Imu(PRESETS[grade]).measure(truth, [stream(seed, gi * runs + r, "imu") for r in range(runs)])
        dth.append(rec.dtheta_body)
        dv.append(rec.dv_body)
    dth, dv = np.concatenate(dth), np.concatenate(dv)
    n = dth.shape[0]
    baro = Baro(rate_hz=RATE_HZ)
    hb = baro.measure(truth, [stream(seed, r, "baro") for r in range(n)]).h_baro_m
    m_al = int(T_ALIGN * RATE_HZ)
    c = ins.align_stationary(dth[:, :m_al], dv[:, :m_al], np.full(n, LAT))
    s = ins.init_state(np.full(n, LAT), LON, H, np.zeros(3), c)
    s = ins.replace(s, h_m=hb[:, m_al].copy())
    gains = vl.constant_gains(100.0)
    dh = []
    for k in range(m_al, dth.shape[1]):
        s = ins.step(s, dth[:, k], dv[:, k], 1.0 / RATE_HZ, h_baro_m=hb[:, k], loop=gains)
        if (k + 1 - m_al) % int(60 * RATE_HZ) == 0:
            dh.append(s.h_m - H)
    dp = ins.position_error_ned(s.lat_rad, s.lon_rad, s.h_m, LAT, LON, H)
    radial = np.hypot(dp[:, 0], dp[:, 1]).reshape(len(GRADES), runs)
    return radial, np.array(dh), float(np.hypot(baro.bias_sigma_m, baro.noise_sigma_m))


@pytest.fixture(scope="module")
def free_inertial():
    return free_inertial_runs(SEED)


@pytest.mark.slow
@pytest.mark.parametrize("grade", list(GRADES))
def test_horizontal_cep_drift_rate(free_inertial, grade):
    """The grade's CEP rate (median radial error at 1 h over 200 runs, per hour) is within +-30 % of nominal."""
    radial, _, _ = free_inertial
    gi = list(GRADES).index(grade)
    cep_rate = float(np.median(radial[gi])) / units.NMI / (T_NAV / 3600.0)
    assert cep_rate == pytest.approx(GRADES[grade], rel=0.30), (grade, cep_rate)


@pytest.mark.slow
def test_presets_follow_the_grade_derivation():
    """The seed-002 presets' gyro turn-on biases are those tools/calibrate_ins_grades.py derives from the
    grades' CEP rates with the presets' grade-common terms (rounded in presets.py to 4 decimals of deg/h)."""
    path = Path(__file__).resolve().parents[2] / "tools" / "calibrate_ins_grades.py"
    spec = importlib.util.spec_from_file_location("calibrate_ins_grades", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    eps = mod.derive()
    for grade in GRADES:
        assert PRESETS[grade].gyro_bias_radps / DEG_PER_H == pytest.approx(eps[grade], rel=0.02), (grade, eps)
    # the grades differ only in random constants (seed 002): the Gauss-Markov and noise terms are shared
    common = {(g.gyro_bi_radps, g.gyro_bi_tau_s, g.gyro_arw_rad_sqrts, g.accel_bi_mps2, g.accel_vrw_mps_sqrts)
              for g in (PRESETS[k] for k in GRADES)}
    assert len(common) == 1


@pytest.mark.slow
def test_baro_loop_bounds_the_vertical_channel(free_inertial):
    _, dh, baro_sigma = free_inertial
    rms = np.sqrt(np.mean(dh**2, axis=1))  # over runs, each minute
    assert np.all(rms < 3.0 * baro_sigma), rms
    assert rms[-10:].mean() < 1.5 * rms[5:15].mean()  # no growth from the first to the last ten minutes


def test_unaided_vertical_channel_diverges_with_sqrt_r_over_2g():
    """Exact stationary increments, 1 m initial height error, no loop: dh(t) = dh0 cosh(t / tau)."""
    rate = 1.0
    truth = synthetic.stationary(LAT, LON, H, 3000.0, rate)
    dth = 0.5 / rate * (truth.w_ib_body[1:] + truth.w_ib_body[:-1])
    dv = 0.5 / rate * (truth.f_body[1:] + truth.f_body[:-1])
    s = ins.init_state(LAT, LON, H + 1.0, np.zeros(3), ins.cbn_from_quaternion(truth.q_nb[0]))
    dh = [1.0]
    for k in range(dth.shape[0]):
        s = ins.step(s, dth[k : k + 1], dv[k : k + 1], 1.0 / rate)
        dh.append(float(s.h_m[0] - H))
    t = truth.t_s
    tau_fit = t[-1] / np.arccosh(dh[-1])
    g = float(geo.normal_gravity(LAT, H))
    dg_dh = float(geo.normal_gravity(LAT, H + 10.0) - geo.normal_gravity(LAT, H - 10.0)) / 20.0
    tau_theory = 1.0 / np.sqrt(-dg_dh)  # = sqrt(R / 2 g) with -dg/dh = 2 g / R
    assert tau_fit == pytest.approx(tau_theory, rel=0.01)
    assert tau_theory == pytest.approx(np.sqrt(geo.A_WGS84 / (2.0 * g)), rel=0.01)


OMEGA_E = 7.292115e-5
"""Earth rate, rad/s (WGS-84)."""
R_M, G_MPS2 = 6.371e6, 9.80
"""Schuler radius and gravity of the analytic model (Schuler period 84.4 min)."""
N_STATES = 19
"""Analytic model state: r_N, r_E, v_N, v_E (m, m/s), psi (3, rad), constant gyro (3) and accelerometer (3)
biases, Gauss-Markov gyro (3) and accelerometer (3) biases, all in NED."""


def _analytic_model(gyro_tau_s: float = 600.0, accel_tau_s: float = 600.0) -> tuple[np.ndarray, np.ndarray]:
    """(A, J): continuous error dynamics of a stationary INS (vertical held), psi-angle form,
        r' = v,  v' = f x psi - (g / R) r - 2 Omega x v + b_a,  psi' = -Omega x psi - b_g,
    and the alignment map psi(0) = J x of the biases seen by leveling and gyrocompassing (steady state of
    v' = 0 and the horizontal psi' = 0: psi_N = b_aE / g, psi_E = -b_aN / g, psi_D = (b_gE + Om_D psi_N) / Om_N)."""
    om = OMEGA_E * np.array([math.cos(LAT), 0.0, -math.sin(LAT)])
    wx = np.array([[0.0, -om[2], om[1]], [om[2], 0.0, -om[0]], [-om[1], om[0], 0.0]])
    A = np.zeros((N_STATES, N_STATES))
    A[0, 2] = A[1, 3] = 1.0
    A[2, 5], A[3, 4] = G_MPS2, -G_MPS2  # f x psi with f = (0, 0, -g)
    A[2, 0] = A[3, 1] = -G_MPS2 / R_M
    A[2:4, 2:4] = -2.0 * wx[:2, :2]
    A[4:7, 4:7] = -wx
    for off in (7, 13):
        A[4:7, off : off + 3] = -np.eye(3)
    for off in (10, 16):
        A[2:4, off : off + 2] = np.eye(2)
    A[13:16, 13:16] = -np.eye(3) / gyro_tau_s
    A[16:19, 16:19] = -np.eye(3) / accel_tau_s
    J = np.zeros((3, N_STATES))
    for g_i, a_i in ((7, 10), (13, 16)):
        J[0, a_i + 1] = 1.0 / G_MPS2
        J[1, a_i] = -1.0 / G_MPS2
        J[2, g_i + 1] = 1.0 / om[0]
        J[2, a_i + 1] = om[2] / (G_MPS2 * om[0])
    return A, J


def analytic_cep_rate_nmi_per_h(grade) -> float:
    """CEP rate (nmi/h) of a grade from the analytic model: initial covariance of the random constants and
    Gauss-Markov biases mapped through the alignment, the white noise averaged over the alignment (heading
    from the east ARW, tilt from the VRW), Van Loan discretization of the white and Markov driving noises,
    CEP of the 2-D Gaussian at 1 h by 400k seeded draws."""
    A, J = _analytic_model(grade.gyro_bi_tau_s, grade.accel_bi_tau_s)
    n = N_STATES
    Q = np.zeros((n, n))
    Q[4:7, 4:7] = np.eye(3) * grade.gyro_arw_rad_sqrts**2
    Q[2:4, 2:4] = np.eye(2) * grade.accel_vrw_mps_sqrts**2
    Q[13:16, 13:16] = np.eye(3) * 2.0 * grade.gyro_bi_radps**2 / grade.gyro_bi_tau_s
    Q[16:19, 16:19] = np.eye(3) * 2.0 * grade.accel_bi_mps2**2 / grade.accel_bi_tau_s
    var = np.zeros(n)
    var[7:10], var[10:13] = grade.gyro_bias_radps**2, grade.accel_bias_mps2**2
    var[13:16], var[16:19] = grade.gyro_bi_radps**2, grade.accel_bi_mps2**2
    T = np.eye(n)
    T[4:7, :] += J
    P = T @ np.diag(var) @ T.T
    om_n = OMEGA_E * math.cos(LAT)
    P[6, 6] += (grade.gyro_arw_rad_sqrts / math.sqrt(T_ALIGN) / om_n) ** 2
    P[4, 4] += (grade.accel_vrw_mps_sqrts / math.sqrt(T_ALIGN) / G_MPS2) ** 2
    P[5, 5] += (grade.accel_vrw_mps_sqrts / math.sqrt(T_ALIGN) / G_MPS2) ** 2
    dt = 60.0
    M = sl.expm(np.block([[-A, Q], [np.zeros((n, n)), A.T]]) * dt)
    F = M[n:, n:].T
    Qd = F @ M[:n, n:]
    for _ in range(int(T_NAV / dt)):
        P = F @ P @ F.T + Qd
    z = np.random.default_rng(0).standard_normal((400_000, 2)) @ np.linalg.cholesky(P[:2, :2]).T
    return float(np.median(np.linalg.norm(z, axis=1))) / units.NMI / (T_NAV / 3600.0)


@pytest.mark.parametrize("grade", list(GRADES))
def test_grades_against_the_analytic_free_inertial_model(grade):
    """The presets meet their grade in the analytic model too (within 5 %; measured within 1 %), so the
    calibration (done with the repository's INS) is confirmed by error equations that share no code with it."""
    assert analytic_cep_rate_nmi_per_h(PRESETS[grade]) == pytest.approx(GRADES[grade], rel=0.05)


def test_ins_bias_responses_match_the_analytic_model():
    """Exact stationary increments plus one constant bias at a time (body axes, 30 deg heading), the INS's own
    alignment and mechanization for 1 h (vertical held on truth), minus the unbiased run: the north / east error
    equals the analytic model's within 2 % of its size + 1 m (measured: within 1 m for 140-590 m errors)."""
    truth = synthetic.stationary(LAT, LON, H, T_ALIGN + T_NAV, RATE_HZ, euler_rad=(0.0, 0.0, np.radians(30.0)))
    dth0 = 0.5 / RATE_HZ * (truth.w_ib_body[1:] + truth.w_ib_body[:-1])
    dv0 = 0.5 / RATE_HZ * (truth.f_body[1:] + truth.f_body[:-1])
    c_bn = ins.cbn_from_quaternion(truth.q_nb[0])
    cases = [(np.zeros(3), np.zeros(3)), (np.array([1e-8, 0, 0]), np.zeros(3)), (np.array([0, 1e-8, 0]), np.zeros(3)),
             (np.array([0, 0, 1e-8]), np.zeros(3)), (np.zeros(3), np.array([5e-4, 0, 0])),
             (np.array([2e-8, -1e-8, 3e-8]), np.array([1e-4, -3e-4, 2e-4]))]
    eps = np.stack([c[0] for c in cases])
    dfb = np.stack([c[1] for c in cases])
    dth = dth0[None] + eps[:, None, :] / RATE_HZ
    dv = dv0[None] + dfb[:, None, :] / RATE_HZ
    m = int(T_ALIGN * RATE_HZ)
    n = len(cases)
    s = ins.init_state(np.full(n, LAT), LON, H, np.zeros(3), ins.align_stationary(dth[:, :m], dv[:, :m],
                                                                                    np.full(n, LAT)))
    for k in range(m, dth.shape[1]):
        s = ins.step(s, dth[:, k], dv[:, k], 1.0 / RATE_HZ)
        s = ins.replace(s, h_m=np.full(n, H), v_ned=s.v_ned * np.array([1.0, 1.0, 0.0]))
    err = ins.position_error_ned(s.lat_rad, s.lon_rad, s.h_m, LAT, LON, H)[:, :2]
    err = err[1:] - err[0]  # the unbiased run's alignment residual removed
    A, J = _analytic_model()
    phi = sl.expm(A * T_NAV)
    for e_ins, (eb, fb) in zip(err, cases[1:], strict=True):
        x = np.zeros(N_STATES)
        x[7:10], x[10:13] = c_bn @ eb, c_bn @ fb
        x[4:7] = J @ x
        e_model = (phi @ x)[:2]
        assert np.linalg.norm(e_ins - e_model) < 0.02 * np.linalg.norm(e_model) + 1.0, (eb, fb, e_ins, e_model)
