"""Adaptive damping of the vertical channel (Sokolovic, Dikic & Stancic, Table 2 ordering) in the full navigation
system: a pre-registered test.

Pre-registration (fixed in this docstring before the runs below were made; the only earlier data were an
exploratory run on campaign seed 3, not used here):

* Claim under test (the paper's Table 2, altitude rms, 100 runs): constant 1.11 m > tanh 0.91 m > sinh 0.78 m.
* Statistic: for each campaign seed and each pair (a, b) of loop forms, the paired difference
  d_r = MS_a,r - MS_b,r of the per-run mean-square altitude error (m^2, over the 1 Hz epochs of run r; all forms
  see the same sensor draws of run r: common random numbers), and t = mean(d) / (std(d) / sqrt(n)).
* Significance level: two-sided alpha = 0.05 per comparison, t against the Student quantile with n - 1 degrees
  of freedom; no multiplicity correction within a seed (the campaign verdict below needs every seed to agree).
* Run count: RUNS = 20 runs per seed (runs 0..19), campaign seeds SEEDS = (101, 102, 103).
* Per-seed verdict on the ordering constant > tanh > sinh: "reproduced" if d(constant - tanh) and
  d(tanh - sinh) are both significantly > 0; "refuted" if either is significantly < 0; else "indeterminate".
  Campaign verdict: the per-seed verdict if all three seeds agree, else "indeterminate".
* Expected (from the exploratory seed-3 run): navigation output "refuted" (tanh worse than constant);
  loop-damped INS alone (before the EKF's correction): sinh better than constant, tanh worst ("refuted").
  The test fails on "reproduced" or a mixed reproduced / refuted campaign, passes on "refuted", and reports
  "indeterminate" as an xfail with its numbers (a run count that cannot decide is not a finding).
* Same filter form for all three loops: every loop is filtered per run (shared_covariance=False); the shared
  covariance the constant loop allows is not used. The confound that remains, and is part of the claim, is
  that the filter's error model is exact for the constant loop and a statistical linearization for tanh / sinh;
  it is measured here as the mean normalized altitude error e_h^2 / P_hh per form (1 for a consistent filter).

Set-up (everything the paper does not print is our choice, stated here and in approachsim/manoeuvre.py):
truth manoeuvre.vertical_manoeuvre (exact increments, SEED003_LEGS, 520 s at 10 Hz); the default profile's
sensors without radar altimeter or pseudolite, GPS outages SEED003_GAPS_S; NavSystem with the profile's [nav]
and baro_loop = constant / tanh / sinh at the profile's tau and b (never tuned).

Measured, the pre-registered run (python -m pytest tests/integration/test_nav_adaptive_damping.py -s -rx prints
this table; 233 s CPU on the 2-core CI machine). d = paired mean difference of the per-run mean squares, m^2:

  navigation output   rms c / t / s (m)     d(c - t)  t      d(t - s)  t      d(c - s)  t      verdict
    seed 101          1.094 / 1.187 / 1.096  -0.214  -1.5    +0.209  +1.2    -0.005  -0.1    indeterminate
    seed 102          0.943 / 1.099 / 0.932  -0.318  -2.2    +0.340  +2.1    +0.022  +1.1    refuted
    seed 103          0.979 / 1.155 / 0.968  -0.374  -2.0    +0.397  +2.1    +0.022  +0.6    indeterminate
    campaign: INDETERMINATE (t_crit = 2.09 at 19 dof). tanh is worse than constant in all three seeds, significant
    in one; sinh and constant are indistinguishable. The paper's ordering is reproduced in no seed.
  loop-damped INS alone
    seed 101          1.937 / 5.345 / 1.585  -24.8   -2.4    +26.1   +2.5    +1.24   +4.0    refuted
    seed 102          1.616 / 3.355 / 1.409  -8.65   -2.3    +9.27   +2.4    +0.63   +5.2    refuted
    seed 103          1.544 / 6.133 / 1.285  -35.2   -1.5    +36.0   +1.5    +0.73   +3.6    indeterminate
    campaign: INDETERMINATE; sinh below constant significant in every seed (the pre-registered sub-claim holds).
  filter confound, mean e_h^2 / P_hh of the output (c / t / s): 1.16 / 1.35 / 1.17, 0.86 / 1.17 / 0.84,
    0.93 / 1.29 / 0.91: the tanh loop's filter is 25-35 % over-confident against the other two, which agree.
    With the constant loop, the shared covariance and the per-run filter give the same output to
    -1.8e-5 +- 1.8e-5 m^2 (10 runs, seed 3), so the former test's shared/per-run difference was not a confound.

Re-run 2026-12-02 (not a new pre-registration: the same rules on today's draws). The realism defaults (converged
start, terrain database, ...) and the converged start's draw made continuous in its covariance (a symmetric square
root) changed every run's random numbers, not the claim or the rules. Navigation output: seed 101 refuted (c - t
t = -2.3), 102 and 103 indeterminate: campaign INDETERMINATE (xfail), tanh worse than constant in all three seeds.
Loop-damped INS alone: c - s t = +2.1 / +3.4 / +3.7 (critical 2.093 at 19 dof): the sub-claim "sinh below constant
in every seed" holds in seeds 102 and 103 and misses significance in seed 101 by about 0.01 in t; the test reports
it as indeterminate (an xfail with the table), as the pre-registration does for an undecided verdict.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from approachsim import manoeuvre
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILE = Path(__file__).resolve().parents[2] / "tests" / "data" / "default-py.toml"
RUNS = 20
SEEDS = (101, 102, 103)
ALPHA = 0.05
RATE_HZ = 10.0
FORMS = ("constant", "tanh", "sinh")
PAPER_RMS_M = {"constant": 1.11, "tanh": 0.91, "sinh": 0.78}
"""Table 2 altitude rms (m): the claimed ordering constant > tanh > sinh."""


@cache
def run_seed(seed: int) -> dict:
    """Per form: per-run mean-square altitude error (m^2) of the navigation output and of the loop-damped INS
    alone (output + the EKF's estimate), and the mean normalized altitude error e_h^2 / P_hh of the output."""
    prof = load_profile(PROFILE)
    rw = prof.runway.frame
    truth = manoeuvre.vertical_manoeuvre(rw, rate_hz=RATE_HZ, isa_dev_k=prof.environment.isa_dev_k,
                                         sea_level_pa=prof.environment.true_qnh_pa)
    sensors = replace(prof.sensors, radalt=None, pseudolite=None)
    faults = tuple(FaultSpec("gnss", "outage", a, b) for a, b in manoeuvre.SEED003_GAPS_S)
    recs, st = measure_with_states(SensorSuite.from_config(sensors, rw, prof.environment.qnh_pa, faults), truth,
                                   seed=seed, runs=list(range(RUNS)))
    out: dict = {"output": {}, "ins_alone": {}, "normalized": {}}
    for form in FORMS:
        nav = NavSystem.build(replace(prof.nav, baro_loop=form), sensors, rw, prof.terrain)
        runs = nav.run(truth, recs, [stream(seed, r, "nav") for r in range(RUNS)], shared_covariance=False,
                       states=st)
        e_out = np.stack([r.true_error_nav[:, 2] for r in runs])  # dp_D of the output, m
        e_ins = np.stack([r.true_error_nav[:, 2] + r.x[:, 2] for r in runs])  # INS = output + x_hat
        p_dd = np.stack([r.P_nav[:, 2, 2] for r in runs])
        out["output"][form] = (e_out**2).mean(axis=1)
        out["ins_alone"][form] = (e_ins**2).mean(axis=1)
        out["normalized"][form] = float((e_out**2 / p_dd).mean())
    return out


def paired_t(ms_a: np.ndarray, ms_b: np.ndarray) -> tuple[float, float, str]:
    """(mean d, t, relation) of d = ms_a - ms_b: '>' / '<' if |t| exceeds the two-sided ALPHA Student quantile."""
    d = ms_a - ms_b
    se = d.std(ddof=1) / np.sqrt(d.size)
    t = float(d.mean() / se)
    crit = stats.t.isf(ALPHA / 2, d.size - 1)
    return float(d.mean()), t, ">" if t > crit else "<" if t < -crit else "~"


def ordering_verdict(ms: dict[str, np.ndarray]) -> str:
    """Per-seed verdict on the claimed ordering constant > tanh > sinh (the pre-registered rule)."""
    steps = [paired_t(ms["constant"], ms["tanh"])[2], paired_t(ms["tanh"], ms["sinh"])[2]]
    if "<" in steps:
        return "refuted"
    return "reproduced" if steps == [">", ">"] else "indeterminate"


def campaign_verdict(verdicts: list[str]) -> str:
    """The common per-seed verdict, or 'indeterminate' when the seeds disagree."""
    return verdicts[0] if len(set(verdicts)) == 1 else "indeterminate"


def _table(kind: str) -> list[str]:
    lines = []
    for seed in SEEDS:
        ms = run_seed(seed)[kind]
        rms = " / ".join(f"{np.sqrt(ms[f].mean()):.3f}" for f in FORMS)
        pairs = "; ".join(f"{a}-{b} {m:+.3f} m^2 t={t:+.1f} {rel}" for a, b in
                          (("constant", "tanh"), ("tanh", "sinh"), ("constant", "sinh"))
                          for m, t, rel in [paired_t(ms[a], ms[b])])
        norm = " / ".join(f"{run_seed(seed)['normalized'][f]:.2f}" for f in FORMS)
        lines.append(f"seed {seed}: rms c/t/s {rms} m; {pairs}; verdict {ordering_verdict(ms)}; "
                     f"e_h^2/P_hh c/t/s {norm}")
    return lines


def _decide(kind: str) -> None:
    verdicts = [ordering_verdict(run_seed(s)[kind]) for s in SEEDS]
    table = "\n".join(_table(kind))
    print(f"\n{kind}:\n{table}")
    overall = campaign_verdict(verdicts)
    assert overall != "reproduced" and not {"reproduced", "refuted"} <= set(verdicts), table
    if overall == "indeterminate":
        pytest.xfail(f"indeterminate at {RUNS} runs x {len(SEEDS)} seeds: {verdicts}\n{table}")
    assert overall == "refuted", table


def test_verdict_rules_on_constructed_samples() -> None:
    """The decision rule itself, on samples whose answer is known: a clear ordering, a reversal, pure noise."""
    rng = np.random.default_rng(0)
    base = rng.normal(1.0, 0.1, RUNS)
    noise = rng.normal(0.0, 0.01, (3, RUNS))
    paper_like = {"constant": base + 0.3 + noise[0], "tanh": base + 0.15 + noise[1], "sinh": base + noise[2]}
    assert ordering_verdict(paper_like) == "reproduced"
    reversed_ = {"constant": base + noise[0], "tanh": base + 0.3 + noise[1], "sinh": base + 0.1 + noise[2]}
    assert ordering_verdict(reversed_) == "refuted"
    same = {f: base + noise[i] for i, f in enumerate(FORMS)}
    assert ordering_verdict(same) == "indeterminate"
    assert campaign_verdict(["refuted"] * 3) == "refuted"
    assert campaign_verdict(["refuted", "indeterminate", "refuted"]) == "indeterminate"


@pytest.mark.slow
def test_navigation_output_altitude_ordering_preregistered() -> None:
    """The issue's metric (navigation output). Expected: refuted (tanh worse than constant)."""
    # the navigation works at all: altitude rms at the physical baro's level (issue 39, docs/baro.md: 1 m bias,
    # 1.5 m static-source error and the QNH report's 0.3 hPa, about 2.5 m: 3.1 m together; measured 2.5-3.0 m at
    # seed 101), not diverged (the bound was 2 m with the 1 m baro before issue 39)
    for seed in SEEDS:
        rms = {k: float(np.sqrt(m.mean())) for k, m in run_seed(seed)["output"].items()}
        assert all(0.5 < v < 6.0 for v in rms.values()), (seed, rms)
    _decide("output")


@pytest.mark.slow
def test_loop_damped_ins_alone_ordering_preregistered() -> None:
    """Before the EKF's correction. Expected: refuted (tanh worst), with sinh below constant in every seed. The
    sub-claim follows the pre-registration's rule for verdicts: it fails when refuted (sinh significantly above
    constant in a seed) and reports an undecided seed as an xfail with its numbers."""
    rel = [paired_t(run_seed(seed)["ins_alone"]["constant"], run_seed(seed)["ins_alone"]["sinh"])[2]
           for seed in SEEDS]
    assert "<" not in rel, _table("ins_alone")
    if rel != [">"] * len(SEEDS):
        pytest.xfail(f"sub-claim (sinh below constant in every seed) indeterminate: {rel}\n{_table('ins_alone')}")
    _decide("ins_alone")
