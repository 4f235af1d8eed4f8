"""The integrity-risk study's pieces without flying (campaign/integrity_risk.py): the HMI limit state agrees with the
bank's HMI count, the fault-parameter map, the modes a profile has, the totals and their verdicts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.campaign.integrity_bank import BankEpochs
from approachsim.campaign.integrity_risk import (
    MODES,
    fault_spec,
    limit_states,
    modes_for,
    pre_fault,
    sample_bins,
    totals,
)
from approachsim.campaign.preapproach import PreFault
from approachsim.evaluate.config import EvaluationConfig
from approachsim.integrity.requirements import REQUIREMENTS
from approachsim.profile import load_profile
from approachsim.resources import shipped_profile

CFG = EvaluationConfig(timeavg_settle_s=0.0)


def _epochs(rng: np.random.Generator, n: int = 120, k: int = 4, bump_m: float = 0.0) -> BankEpochs:
    """n epochs at 1 Hz down a 3 deg path from 300 m; sub-solutions with 1.2 m sigma, main 0.6 m; errors drawn,
    plus a vertical bump on all solutions over 10 epochs near the CAT I DH."""
    t = np.arange(n, dtype=float)
    h = np.linspace(300.0, 0.0, n)
    along = -h / math.tan(math.radians(3.0))
    e0 = 0.6 * rng.standard_normal((n, 2))
    ek = e0[:, None, :] + 0.9 * rng.standard_normal((n, k, 2))
    sel = (h > 65.0) & (h < 110.0)
    e0[sel, 0] += bump_m
    ek[sel, :, 0] += bump_m
    return BankEpochs(t, e0, np.full((n, 2), 0.36), ek, np.full((n, k, 2), 1.44), np.arange(k) + 3, along, h)


@pytest.mark.parametrize("bump", [0.0, 4.0, 9.0, 11.0, 20.0])
def test_hmi_limit_state_agrees_with_the_hmi_count(bump: float) -> None:
    rng = np.random.default_rng(int(bump * 10))
    out = limit_states(_epochs(rng, bump_m=bump), CFG, 1.0, 0.0)
    for key in ("cat1", "cat2", "cat3"):
        assert (out[f"{key}_hmi_g"] > 0.0) == (out[f"{key}_hmi"] > 0.0)
        assert (out[f"{key}_mi_g"] > 0.0) == (out[f"{key}_mi"] > 0.0) or out[f"{key}_available"] < out[f"{key}_epochs"]
        assert out[f"{key}_vmax_m"] >= 0.0
    if bump >= 20.0:
        assert out["cat1_hmi"] > 0  # 20 m against a 10-18 m VAL at 200-360 ft, with the PL inside it
    if bump == 0.0:
        assert out["cat1_hmi_g"] < 0.0 and out["n_z"] > 0


def test_fault_parameter_map() -> None:
    m = MODES["baro-step"]
    spec, p = fault_spec(m, np.array([0.0, 0.0]), None, None, 1, 0, (100.0, 300.0))
    assert spec.sensor == "baro" and spec.kind == "step" and spec.target == "h"
    assert p["onset_s"] == pytest.approx(200.0) and spec.magnitude == pytest.approx(10.0)  # sqrt(1 x 100)
    spec, p = fault_spec(m, np.array([-8.0, 8.0]), None, None, 1, 0, (100.0, 300.0))
    assert p["onset_s"] == pytest.approx(100.0, abs=1e-6) and spec.magnitude == pytest.approx(100.0, rel=1e-6)
    r = MODES["radalt-bias"]
    spec, p = fault_spec(r, np.array([0.0, -8.0]), None, None, 1, 0, (0.0, 10.0))
    assert spec.sensor == "radalt" and spec.magnitude == pytest.approx(0.3, rel=1e-6)
    assert MODES["sat-ramp"].dim == 3 and MODES["baro-step"].dim == 2


def test_modes_of_the_shipped_profiles() -> None:
    default = load_profile(shipped_profile("default"))
    assert [m.name for m in modes_for(default)] == ["sat-ramp", "sat-step", "baro-step", "radalt-bias"]
    cand = load_profile(shipped_profile("gbas-cat3-candidate"))
    assert "pseudolite-step" in [m.name for m in modes_for(cand)]
    with pytest.raises(ValueError, match="no pseudolite"):
        modes_for(default, ["pseudolite-step"])
    with pytest.raises(ValueError, match="unknown fault mode"):
        modes_for(default, ["gremlin"])


def _study(cond: dict[str, float | None], prior: float = 1e-5, ff: float = 1e-12, mark: str = "S") -> dict:
    fa = {"rate_per_15s_gaussian": 1e-6, "rate_per_15s_upper_mc": 1e-3, "allocation_per_15s": 8e-6}
    cats = {c: {"hmi_gaussian": ff, "hmi_gaussian_worst_run": ff, "false_alert": fa} for c in REQUIREMENTS}
    modes = {}
    for name, p in cond.items():
        if p is None:  # not estimated: only the first step's bound 0.03
            c = {"shown": False, "probability": None, "lower": 0.0, "upper": 0.03}
        else:
            c = {"shown": True, "probability": p, "lower": 0.5 * p, "upper": 2.0 * p}
        modes[name] = {"prior": prior, "prior_mark": mark, "categories": {k: dict(c) for k in REQUIREMENTS}}
    return {"fault_free": {"categories": cats}, "modes": modes}


def test_totals_and_verdicts() -> None:
    t = totals(_study({"sat-ramp": 1e-4}), 0.95)
    assert t["CAT I"]["p_hmi"] == pytest.approx(1e-12 + 1e-9)
    assert t["CAT I"]["p_hmi_upper"] == pytest.approx(1e-12 + 2e-9)
    assert t["CAT I"]["verdict"] == "shown"  # 2e-9 <= 2e-7
    assert t["CAT III"]["verdict"] == "not shown"  # lower 5e-10 < 1e-9 < upper 2e-9
    t2 = totals(_study({"sat-ramp": 1e-3}), 0.95)
    # CAT III's lower bound 5e-9 > 1e-9 is the whole approach's, not its 15 s window's: never `exceeds` (item 1)
    assert t2["CAT III"]["verdict"] == "not shown" and t2["CAT I"]["verdict"] == "shown"
    t2b = totals(_study({"sat-ramp": 0.1}), 0.95)
    assert t2b["CAT I"]["verdict"] == "exceeds"  # CAT I is per approach: lower 5e-7 > 2e-7
    t3 = totals(_study({"sat-ramp": None}), 0.95)
    assert t3["CAT I"]["verdict"] == "not shown"  # 1e-5 x 0.03 = 3e-7 > 2e-7, and nothing estimated
    assert not t3["CAT I"]["every_term_estimated"]
    assert t3["CAT I"]["p_false_alert_per_15s_gaussian"] == 1e-6 and t3["CAT I"]["false_alert_verdict"] == "shown"
    # the prior each term could carry within its equal share (two terms: the fault-free one and the ramp)
    assert t["CAT I"]["terms"]["sat-ramp"]["prior_allowed"] == pytest.approx(2e-7 / 2 / 2e-4)
    assert t3["CAT III"]["terms"]["sat-ramp"]["prior_allowed"] == pytest.approx(1e-9 / 2 / 0.03)
    assert "prior_allowed" not in t["CAT I"]["terms"]["fault_free"]


def test_assumed_priors_keep_the_verdict_not_shown() -> None:
    """A term whose prior has no source ([U]) is `not shown` whatever its bound; the category's verdict rests on the
    sourced terms (`verdict_sourced`), the assumed-prior verdict beside it; `exceeds` only from the sourced ones."""
    s = _study({"sat-ramp": 1e-4})
    s["modes"]["baro-step"] = _study({"baro-step": 1e-4}, mark="U")["modes"]["baro-step"]
    t = totals(s, 0.95)["CAT I"]
    assert t["verdict_sourced"] == "shown" and t["verdict_assumed"] == "shown"  # 4e-9 <= 2e-7 either way
    assert t["verdict"] == "not shown" and t["unsourced_terms"] == ["baro-step"]
    assert t["terms"]["baro-step"]["term_verdict"].startswith("not shown")
    assert t["p_hmi_upper_sourced"] == pytest.approx(1e-12 + 2e-9)
    big = _study({"sat-ramp": 1e-4})
    big["modes"]["baro-step"] = _study({"baro-step": 0.5}, mark="U")["modes"]["baro-step"]
    t2 = totals(big, 0.95)["CAT I"]
    assert t2["verdict_assumed"] == "exceeds" and t2["verdict"] == "not shown"  # 2.5e-6 > 2e-7 on an assumed prior


def test_onset_before_the_window_and_the_prior_per_approach() -> None:
    """Faults present before the approach (item 3): with an MFD the onset is uniform over the MFD before the
    window and the window itself; the prior per approach is the state probability x (1 + window / MFD)."""
    m = MODES["sat-step"].with_window(400.0)
    assert m.mfd_s == 3600.0 and m.pre_fraction == pytest.approx(0.9)
    assert m.prior_per_approach(400.0) == pytest.approx(1e-5 * (1.0 + 400.0 / 3600.0))
    assert m.onset(0.0, (100.0, 500.0)) == pytest.approx(100.0 - 3600.0)  # the oldest: one MFD before
    assert m.onset(0.45, (100.0, 500.0)) == pytest.approx(100.0 - 1800.0)
    assert m.onset(0.95, (100.0, 500.0)) == pytest.approx(300.0)  # the window's middle
    # Phi(u_0) uniform: the onset uniform in time over [lo - MFD, hi]
    f = np.linspace(0.0, 1.0, 100001)
    t = np.array([m.onset(x, (100.0, 500.0)) for x in f])
    assert np.all(np.diff(t) > 0) and np.allclose(np.diff(t), 4000.0 / 100000, rtol=1e-6)
    labels = [e[2] for e in m.onset_edges()]
    assert labels[0] == "present 2400-3600 s before" and labels[-1] == "window 3/3" and len(labels) == 6
    mb, ob = sample_bins(m, np.array([[-3.0, 0.0, 0.0], [1.5, 0.0, 0.0], [3.0, 0.0, 0.0]]))
    assert ob.tolist() == [0, 3, 5]  # Phi: 0.0013 (oldest third), 0.933 (window's first third), 0.9987 (last)
    b = MODES["baro-step"].with_window(400.0)
    spec, p = fault_spec(b, np.array([-3.0, 0.0]), None, None, 1, 0, (100.0, 500.0))
    assert spec.start_s == pytest.approx(100.0 - p["onset_before_window_s"])
    assert p["onset_before_window_s"] == pytest.approx(3600.0 * (1 - sps.norm.cdf(-3.0) / 0.9), rel=1e-9)
    assert pre_fault(MODES["baro-step"], {"age_at_start_s": 60.0, "channel_index": -1, "magnitude": 5.0}
                     ) == PreFault("baro", "step", 5.0, 60.0)
    assert pre_fault(MODES["baro-step"], {"age_at_start_s": 0.0, "channel_index": -1, "magnitude": 5.0}) is None
    # the faulted source's measurement row (nav/observations.Source.name): GNSS channel 7, pseudolite unit 1
    assert pre_fault(MODES["sat-ramp"], {"age_at_start_s": 5.0, "channel_index": 7, "magnitude": 0.1}).row == "gps07"
    assert pre_fault(MODES["pseudolite-step"], {"age_at_start_s": 5.0, "channel_index": 1, "magnitude": 3.0}
                     ).row == "pl1"


def test_pseudolite_unit_from_the_profile() -> None:
    cand = load_profile(shipped_profile("gbas-cat3-candidate"))
    m = MODES["pseudolite-step"]
    spec, p = fault_spec(m, np.array([0.0, 0.0, 0.9]), cand, None, 1, 0, (0.0, 10.0))
    assert spec.sensor == "pseudolite" and spec.target == "pseudorange" and p["n_channels"] == 2
    assert spec.channel == 1  # Phi(0.9) = 0.82 of two units
