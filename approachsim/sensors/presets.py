"""IMU grade presets: every number with its unit and its source (references are standards.md section 3.1).

Engineering units here (deg/h, deg/sqrt(h), micro-g, ppm, mrad), converted once to SI by `ImuGrade.si()`.
Bias instability is modelled as a first-order Gauss-Markov process whose 1-sigma is the quoted bias-
instability number and whose correlation time is tau (the gnss-ins-sim convention [S16]); its Allan
deviation peaks at 0.618 sigma near T = 1.89 tau. ARW / VRW are white rate / acceleration noise densities.
Turn-on bias, scale factor and misalignment are random constants per run (1-sigma per axis / element).

Seed 002 (Gray & Maybeck) grades. The paper gives only CEP rates (0.4 / 2.0 / 4.0 nmi/h) and says that
only the random-constant states differ between them (not the Gauss-Markov drift states). The grade is read
as: stationary at mid-latitude (37.6 deg), after the INS's own 8-minute stationary alignment
(nav/ins.py align_stationary), the median horizontal radial error at 1 h is 0.4 / 2.0 / 4.0 nmi ("CEP rate"
= CEP(1 h) / 1 h). So:
* the grade-common terms: gyro bias instability 0.0035 deg/h (engineering choice, first-order Gauss-Markov)
  with Grewal's 600 s sensor-compensation correlation time [S17]; ARW 0.01 deg/h/sqrt(s) = 1.7e-4
  deg/sqrt(h), the gyro noise of Grewal & Andrews' 1 nmi/h budget [S17] (the navigation-grade upper bound
  0.002 deg/sqrt(h) of [S15, S16] does not fit a 0.4 nmi/h INS: averaged over an 8-minute gyrocompass
  alignment it gives a heading error N / (W_ie cos L sqrt(T)), i.e. a constant east drift N / sqrt(T) =
  0.0055 deg/h, and alone a CEP of 0.42 nmi at 1 h); accelerometer bias instability 3.6e-6 m/s^2 (0.37
  micro-g) and VRW 2.5e-5 m/s/sqrt(h) [S16]; scale factors 100 ppm gyro / 10 ppm accel [S17]; misalignment
  0.02 mrad (engineering choice, RLG class). Together they give CEP 0.24 nmi at 1 h;
* the gyro turn-on bias (random constant, 1-sigma per axis) is derived from the CEP rate by
  tools/calibrate_ins_grades.py: 0.4 -> 0.0057, 2.0 -> 0.0400, 4.0 -> 0.0804 deg/h. The script measures
  the 1-h error's sensitivity to every random constant with this repository's alignment and INS, adds the
  common terms' covariance (linear Schuler responses), and solves CEP(covariance) = grade x 1 h. Why it is
  not R eps = CEP rate (0.60 nmi/h per 0.01 deg/h, standards.md 3.2): after gyrocompassing, the east gyro
  bias is cancelled by the heading error it causes and the vertical one acts only through heading x Earth
  rate, so the north gyro bias alone drives the error, in the east direction, as R eps (t - sin(w_s t) /
  w_s) = 1.217 R eps t at 1 h (Schuler); a one-dimensional error has CEP = 0.6745 sigma (a circular one
  1.1774 sigma). Net CEP(1 h) ~ 0.82 R eps t for the coarse grades, plus the common terms, which dominate
  the 0.4 grade. tests/integration/test_nav_free_inertial.py checks these numbers against the script and a
  Monte Carlo of the full simulation against the grades (200 runs per grade, baro loop on; campaign seeds
  1-5 measured 0.38-0.43 / 1.89-2.11 / 3.93-4.11 nmi/h);
* accelerometer turn-on bias scaled from Grewal & Andrews' 1 nmi/h budget (10 micro-g at 0.03 deg/h
  [S17]): 0.4 -> 10, 2.0 -> 50, 4.0 -> 100 micro-g (engineering choice, bounded by S15's navigation-grade
  < 100 micro-g). Stationary, the alignment's leveling cancels them (tilt = -b / g): they do not set the
  free-inertial drift.

Tactical: El-Sheimy & Youssef [S15] tactical row (gyro drift 1-10 deg/h, ARW 0.02-0.05 deg/sqrt(h), accel
bias 1-5 mg): turn-on 1 deg/h and 1 mg (low end), BI 0.5 deg/h and 50 micro-g with tau = 100 s ([S16]
b_corr), ARW 0.03 deg/sqrt(h), VRW 0.03 m/s/sqrt(h) ([S16] mid-accuracy), scale factor 300 ppm,
misalignment 0.5 mrad (engineering choices).

MEMS (seed 003's InvenSense MPU-60X0 class): noise densities from the MPU-6000/6050 product specification
rev 3.4 (gyro rate noise 0.005 deg/s/sqrt(Hz) -> ARW 0.3 deg/sqrt(h); accel noise 400 micro-g/sqrt(Hz) ->
VRW 0.235 m/s/sqrt(h)); scale-factor tolerance +-3 % and cross-axis +-2 % taken as 3-sigma (1 %, 6.7 mrad);
bias instability 10 deg/h and 2e-4 m/s^2 with tau = 100 s ([S16] low-accuracy MEMS preset). The datasheet
zero-rate offset (+-20 deg/s) is removed by the power-up calibration that seed 003 applies ("biases and
scale factors ... used for inertial sensor calibration"); the residual turn-on bias is taken as 0.05 deg/s
and 10 mg (engineering choice, a few times the bias instability).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from approachsim import units

DEG_PER_H = math.radians(1.0) / 3600.0
"""rad/s per deg/h."""
DEG_PER_SQRT_H = math.radians(1.0) / 60.0
"""rad/sqrt(s) per deg/sqrt(h) (angle random walk)."""
MPS_PER_SQRT_H = 1.0 / 60.0
"""m/s/sqrt(s) per m/s/sqrt(h) (velocity random walk)."""
MICRO_G = 1e-6 * units.G0
"""m/s^2 per micro-g."""


@dataclass(frozen=True)
class ImuGrade:
    """An IMU error budget in SI: 1-sigma values per axis; tau in s; quantization steps 0 = none."""

    name: str
    gyro_bias_radps: float
    """Turn-on (run-to-run) gyro bias, rad/s."""
    gyro_bi_radps: float
    """Gyro bias instability: Gauss-Markov 1-sigma, rad/s."""
    gyro_bi_tau_s: float
    """Its correlation time, s."""
    gyro_arw_rad_sqrts: float
    """Angle random walk, rad/sqrt(s)."""
    gyro_sf: float
    """Scale-factor error, dimensionless."""
    gyro_misalign_rad: float
    """Axis misalignment (each off-diagonal element), rad."""
    accel_bias_mps2: float
    """Turn-on accelerometer bias, m/s^2."""
    accel_bi_mps2: float
    """Accelerometer bias instability: Gauss-Markov 1-sigma, m/s^2."""
    accel_bi_tau_s: float
    """Its correlation time, s."""
    accel_vrw_mps_sqrts: float
    """Velocity random walk, m/s/sqrt(s)."""
    accel_sf: float
    """Scale-factor error, dimensionless."""
    accel_misalign_rad: float
    """Axis misalignment (each off-diagonal element), rad."""
    gyro_quant_rad: float = 0.0
    """Angle-increment quantization step, rad (0: none)."""
    accel_quant_mps: float = 0.0
    """Velocity-increment quantization step, m/s (0: none)."""
    source: str = ""


def _grade(
    name: str, *, g_to_dph: float, g_bi_dph: float, g_tau_s: float, arw_dpsh: float, g_sf_ppm: float,
    g_mis_mrad: float, a_to_ug: float, a_bi_ug: float, a_tau_s: float, vrw_mpssh: float, a_sf_ppm: float,
    a_mis_mrad: float, source: str,
) -> ImuGrade:
    return ImuGrade(
        name=name,
        gyro_bias_radps=g_to_dph * DEG_PER_H,
        gyro_bi_radps=g_bi_dph * DEG_PER_H,
        gyro_bi_tau_s=g_tau_s,
        gyro_arw_rad_sqrts=arw_dpsh * DEG_PER_SQRT_H,
        gyro_sf=g_sf_ppm * 1e-6,
        gyro_misalign_rad=g_mis_mrad * 1e-3,
        accel_bias_mps2=a_to_ug * MICRO_G,
        accel_bi_mps2=a_bi_ug * MICRO_G,
        accel_bi_tau_s=a_tau_s,
        accel_vrw_mps_sqrts=vrw_mpssh * MPS_PER_SQRT_H,
        accel_sf=a_sf_ppm * 1e-6,
        accel_misalign_rad=a_mis_mrad * 1e-3,
        source=source,
    )


_SEED002_COMMON = dict(
    g_bi_dph=0.0035, g_tau_s=600.0, arw_dpsh=0.01 / 60.0, g_sf_ppm=100.0, g_mis_mrad=0.02,
    a_bi_ug=3.6e-6 / MICRO_G, a_tau_s=600.0, vrw_mpssh=2.5e-5, a_sf_ppm=10.0, a_mis_mrad=0.02,
)

PRESETS: Mapping[str, ImuGrade] = MappingProxyType({
    "nav-0.4": _grade("nav-0.4", g_to_dph=0.0057, a_to_ug=10.0, **_SEED002_COMMON,
                      source="seed 002 0.4 nmi/h CEP (medium accuracy RLG); module docstring"),
    "nav-2.0": _grade("nav-2.0", g_to_dph=0.0400, a_to_ug=50.0, **_SEED002_COMMON,
                      source="seed 002 2.0 nmi/h CEP; module docstring"),
    "nav-4.0": _grade("nav-4.0", g_to_dph=0.0804, a_to_ug=100.0, **_SEED002_COMMON,
                      source="seed 002 4.0 nmi/h CEP; module docstring"),
    "tactical": _grade("tactical", g_to_dph=1.0, g_bi_dph=0.5, g_tau_s=100.0, arw_dpsh=0.03, g_sf_ppm=300.0,
                       g_mis_mrad=0.5, a_to_ug=1000.0, a_bi_ug=50.0, a_tau_s=100.0, vrw_mpssh=0.03,
                       a_sf_ppm=300.0, a_mis_mrad=0.5, source="El-Sheimy & Youssef 2020 tactical row; gnss-ins-sim"),
    "mems": _grade("mems", g_to_dph=0.05 * 3600.0, g_bi_dph=10.0, g_tau_s=100.0, arw_dpsh=0.005 * 60.0,
                   g_sf_ppm=1e4, g_mis_mrad=20.0 / 3.0, a_to_ug=1e4, a_bi_ug=2e-4 / MICRO_G, a_tau_s=100.0,
                   vrw_mpssh=400e-6 * units.G0 * 60.0, a_sf_ppm=1e4, a_mis_mrad=20.0 / 3.0,
                   source="MPU-6000/6050 product specification rev 3.4 (seed 003); gnss-ins-sim low-accuracy"),
})
"""Grade presets by name (profile key sensors.imu.grade)."""
