"""Issue 4, acceptance "Adaptive damping" (seed 003 Table 2 ordering): on a vertical-manoeuvre profile with GPS
gaps, altitude RMS error of the full navigation system with the 3rd-order baro loop in its three gain forms.

Paper's expected ordering (seed 003 Table 2, 100 runs, altitude rms): constant 1.11 m > tanh 0.91 m > sinh
0.78 m. This test asserts the ordering the faithful implementation gives instead, with margins from the
run-to-run spread (paired differences of the per-run mean-square errors and their standard errors).

Set-up (everything not printed in seed 003 is our choice, stated here and in approachsim/manoeuvre.py):
* truth: manoeuvre.vertical_manoeuvre (exact increments), level at 600 m, +300 m / -60 m / -250 m / +40 m
  legs (SEED003_LEGS), 520 s at 10 Hz (the IMU rate here: seed 003's receiver rate; the default profile's
  120 Hz would cost 12x the CPU), 70 m/s ground speed along the default runway heading;
* sensors: the default profile's own (nav-2.0 IMU, baro 10 Hz 1 m noise / 1 m 100 s Markov bias, tight P(Y)
  GPS best-4 at 1 Hz) through SensorSuite, without the radar altimeter (seed 003's system is INS/GPS/baro,
  and at 600-900 m the radalt would be in range and pin the height); GPS outages as `outage` faults over
  SEED003_GAPS_S = 80-200 s and 320-480 s, each covering a large manoeuvre;
* navigation: NavSystem with the profile's [nav] and baro_loop = constant / tanh / sinh at the config's
  tau = 100 s (eq. 5) and b = 0.5 /m, adaptive amplitudes C_KF = C / b (same small-signal slope as the constant
  loop, eq. 7 linearizes to eq. 3); the loop damps the INS at the IMU rate, the EKF (feed-forward, baro and
  pseudoranges; only baro in the gaps) corrects the output; shared covariance across runs (one gain per
  epoch, each run its own state and innovations); 100 runs, seed 3, the same sensor draws for all forms.

Measured (seed 3; altitude error at the 1 Hz epochs, RMS over epochs and runs; d = paired difference of the
per-run mean squares, mean +- standard error; the constant loop's filter shares one covariance across runs,
the adaptive loops' filters are per run, as NavSystem requires for their statistical linearization):

  navigation output (INS - EKF estimate; the issue's metric)   100 runs            25 runs (CI)
    altitude rms constant / tanh / sinh                        0.970/1.078/0.992   0.997/1.109/1.014 m
    d(tanh - constant)                                         +0.220 +- 0.050     +0.237 +- 0.116 m^2
    d(tanh - sinh)                                             +0.177 +- 0.053     +0.203 +- 0.121 m^2
    d(sinh - constant)                                         +0.043 +- 0.017     +0.033 +- 0.033 m^2
    (gaps only: 1.002 / 1.114 / 1.010 m; d(sinh - constant) +0.016 +- 0.016 m^2)
  loop-damped INS alone (output + the EKF's dp_D estimate)
    altitude rms constant / tanh / sinh                        1.655/4.977/1.384   1.711/4.940/1.416 m
    d(tanh - constant)                                         +22.0 +- 5.5        +21.5 +- 7.0 m^2
    d(constant - sinh)                                         +0.82 +- 0.10       +0.92 +- 0.16 m^2
    (max |error|: constant 12.2 m, tanh 56.5 m, sinh 8.9 m over 100 runs)

Finding: the navigation output orders tanh > sinh > constant (paper: constant > tanh > sinh); the loop alone orders
tanh > constant > sinh. tanh is the worst in both, sinh beats constant only before the EKF. Why (seed 003 eq. 3, 7,
16): with C_KF = C / b the adaptive correction C_KF f(b e) has the constant loop's slope at e = 0; |tanh x| <= |x|
makes the tanh loop *weaker* than the constant one at every loop error (effective gain tanh(b e) / (b e) = 0.92 at
1 m, 0.76 at 2 m, 0.48 at 4 m), and its C2 branch cannot push more than C2 / b = 6.1e-4 m/s^2 (62 micro-g, barely
above the nav-2.0 accelerometer turn-on bias, 50 micro-g 1 sigma), so the unstable channel wanders until the slow
C3 integral catches up (5 m rms, 57 m max); sinh(x) >= x makes the sinh loop stiffer (1.04 at 1 m, 1.18 at 2 m,
1.81 at 4 m), which cuts the large excursions (max 12.2 -> 8.9 m). The EKF then estimates the residual from the
same baro (and GPS outside the gaps); the constant loop is the one the filter's linear model describes exactly,
while the adaptive ones enter by statistical linearization (tanh is known over-confident: the strict xfail in
tests/integration/test_nav_loop_consistency.py), so after the filter sinh's advantage is gone and tanh's loss
remains. The paper's gains double the loop in the gaps (tanh C1KF = 0.06 = 2 C1 at an unprinted b), a different
bandwidth rather than the nonlinearity; approachsim/papers/sokolovic.py finds tanh behind constant on the paper's
own model too. Never tuned: tau and b are the profile's [nav] defaults.
"""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
import pytest

from approachsim import manoeuvre
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.suite import SensorSuite

RUNS = int(os.environ.get("ADAPTIVE_DAMPING_RUNS", "25"))
"""Runs 0 .. RUNS-1 (CI: 25, 55 s CPU measured; the issue's 100: ADAPTIVE_DAMPING_RUNS=100, 3.6 min CPU). A run's
numbers do not depend on its batch, so the CI runs are the first 25 of the 100-run experiment."""
SEED = 3
RATE_HZ = 10.0
FORMS = ("constant", "tanh", "sinh")
PAPER_RMS_M = {"constant": 1.11, "tanh": 0.91, "sinh": 0.78}
"""Seed 003 Table 2 altitude rms (m): the expected ordering constant > tanh > sinh."""


def run_forms() -> tuple[dict, dict, np.ndarray]:
    """Per form: (runs, epochs) altitude error (m, up) of the navigation output and of the loop-damped INS
    alone (output + the EKF's estimate), and the epochs' gap mask."""
    prof = load_profile("profiles/default.toml")
    rw = prof.runway.frame
    truth = manoeuvre.vertical_manoeuvre(rw, rate_hz=RATE_HZ, isa_dev_k=prof.environment.isa_dev_k,
                                         sea_level_pa=prof.environment.true_qnh_pa)
    sensors = replace(prof.sensors, radalt=None, pseudolite=None)
    faults = tuple(FaultSpec("gnss", "outage", a, b) for a, b in manoeuvre.SEED003_GAPS_S)
    recs = SensorSuite.from_config(sensors, rw, prof.environment.qnh_pa, faults).measure(
        truth, seed=SEED, runs=range(RUNS))
    assert not recs["gnss"].valid[:, (recs["gnss"].t_s >= 100.0) & (recs["gnss"].t_s < 180.0)].any()
    out, raw = {}, {}
    for form in FORMS:
        nav = NavSystem.build(replace(prof.nav, baro_loop=form), sensors, rw, prof.terrain)
        # one shared covariance is exact for the constant loop (linear error model); NavSystem filters the
        # adaptive loops per run (their statistical linearization depends on each run's estimate)
        runs = nav.run(truth, recs, [stream(SEED, r, "nav") for r in range(RUNS)],
                       shared_covariance=form == "constant")
        out[form] = -np.stack([r.true_error_nav[:, 2] for r in runs])  # h error = -dp_D
        raw[form] = -np.stack([r.true_error_nav[:, 2] + r.x[:, 2] for r in runs])  # INS = output + x_hat
    t = runs[0].t_epoch_s
    gap = np.zeros(t.shape, dtype=bool)
    for a, b in manoeuvre.SEED003_GAPS_S:
        gap |= (t >= a) & (t < b)
    return out, raw, gap


@pytest.fixture(scope="module")
def altitude_errors():
    """run_forms(), once for the module."""
    return run_forms()


def _paired(ms_a, ms_b):
    d = ms_a - ms_b
    return d.mean(), d.std(ddof=1) / np.sqrt(d.size)


@pytest.mark.slow
def test_navigation_output_altitude_rms_ordering(altitude_errors):
    """The issue's metric. Paper: constant > tanh > sinh. Faithful system: tanh > sinh > constant."""
    errs, _, _ = altitude_errors
    ms = {f: (e**2).mean(axis=1) for f, e in errs.items()}  # per-run mean square, m^2
    rms = {f: float(np.sqrt(m.mean())) for f, m in ms.items()}
    # the navigation works at all: altitude RMS at the baro's 1 m level, not a diverged vertical channel
    assert all(0.5 < r < 2.0 for r in rms.values()), rms
    d, se = _paired(ms["tanh"], ms["constant"])
    assert d > 1.5 * se, (d, se, rms)  # finding: tanh WORSE than constant (paper: better); 2.0 / 4.4 SE
    d, se = _paired(ms["tanh"], ms["sinh"])
    assert d > 1.5 * se, (d, se, rms)  # tanh worse than sinh (as the paper); 1.7 / 3.3 SE at 25 / 100 runs
    d, se = _paired(ms["sinh"], ms["constant"])
    assert d > 0.5 * se, (d, se, rms)  # finding: sinh does not beat constant (paper: best); 1.0 / 2.5 SE
    assert not (rms["constant"] > rms["tanh"] > rms["sinh"]), (rms, PAPER_RMS_M)


@pytest.mark.slow
def test_loop_damped_ins_alone_sinh_beats_constant_and_tanh_is_worst(altitude_errors):
    """Before the EKF's correction: seed 003's sinh claim holds, its tanh claim does not."""
    _, raw, _ = altitude_errors
    ms = {f: (e**2).mean(axis=1) for f, e in raw.items()}
    d, se = _paired(ms["constant"], ms["sinh"])
    assert d > 3.0 * se, (d, se)  # 5.6 / 8.3 SE at 25 / 100 runs
    d, se = _paired(ms["tanh"], ms["constant"])
    assert d > 2.5 * se, (d, se)  # 3.1 / 4.0 SE
