"""The integrity-risk study's pieces without flying (campaign/integrity_risk.py): the HMI limit state agrees with the
bank's HMI count, the fault-parameter map, the modes a profile has, the totals and their verdicts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim.campaign.integrity_bank import BankEpochs
from approachsim.campaign.integrity_risk import MODES, fault_spec, limit_states, modes_for, totals
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


def _study(cond: dict[str, float | None], prior: float = 1e-5, ff: float = 1e-12) -> dict:
    fa = {"rate_per_15s_gaussian": 1e-6, "rate_per_15s_upper_mc": 1e-3, "allocation_per_15s": 8e-6}
    cats = {c: {"hmi_gaussian": ff, "hmi_gaussian_worst_run": ff, "false_alert": fa} for c in REQUIREMENTS}
    modes = {}
    for name, p in cond.items():
        if p is None:  # not estimated: only the first step's bound 0.03
            c = {"shown": False, "probability": None, "lower": 0.0, "upper": 0.03}
        else:
            c = {"shown": True, "probability": p, "lower": 0.5 * p, "upper": 2.0 * p}
        modes[name] = {"prior": prior, "categories": {k: dict(c) for k in REQUIREMENTS}}
    return {"fault_free": {"categories": cats}, "modes": modes}


def test_totals_and_verdicts() -> None:
    t = totals(_study({"sat-ramp": 1e-4}), 0.95)
    assert t["CAT I"]["p_hmi"] == pytest.approx(1e-12 + 1e-9)
    assert t["CAT I"]["p_hmi_upper"] == pytest.approx(1e-12 + 2e-9)
    assert t["CAT I"]["verdict"] == "shown"  # 2e-9 <= 2e-7
    assert t["CAT III"]["verdict"] == "not shown"  # lower 5e-10 < 1e-9 < upper 2e-9
    t2 = totals(_study({"sat-ramp": 1e-3}), 0.95)
    assert t2["CAT III"]["verdict"] == "exceeds" and t2["CAT I"]["verdict"] == "shown"
    t3 = totals(_study({"sat-ramp": None}), 0.95)
    assert t3["CAT I"]["verdict"] == "not shown"  # 1e-5 x 0.03 = 3e-7 > 2e-7, and nothing estimated
    assert not t3["CAT I"]["every_term_estimated"]
    assert t3["CAT I"]["p_false_alert_per_15s_gaussian"] == 1e-6 and t3["CAT I"]["false_alert_verdict"] == "shown"
    # the prior each term could carry within its equal share (two terms: the fault-free one and the ramp)
    assert t["CAT I"]["terms"]["sat-ramp"]["prior_allowed"] == pytest.approx(2e-7 / 2 / 2e-4)
    assert t3["CAT III"]["terms"]["sat-ramp"]["prior_allowed"] == pytest.approx(1e-9 / 2 / 0.03)
    assert "prior_allowed" not in t["CAT I"]["terms"]["fault_free"]


def test_pseudolite_unit_from_the_profile() -> None:
    cand = load_profile(shipped_profile("gbas-cat3-candidate"))
    m = MODES["pseudolite-step"]
    spec, p = fault_spec(m, np.array([0.0, 0.0, 0.9]), cand, None, 1, 0, (0.0, 10.0))
    assert spec.sensor == "pseudolite" and spec.target == "pseudorange" and p["n_channels"] == 2
    assert spec.channel == 1  # Phi(0.9) = 0.82 of two units
