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
* the unaided vertical channel diverges with the time constant sqrt(R / 2 g);
* with the baro loop (seed 003 eq. 5 gains, tau = 100 s) the height error stays bounded: its RMS over the
  runs stays within 3x the baro 1-sigma for the whole hour.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

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
