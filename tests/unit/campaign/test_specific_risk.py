"""Specific risk (campaign/integrity_risk.py, "Specific risk"): P(HMI | magnitude bin, onset bin) with
Clopper-Pearson bounds from the estimator's samples, and the verdict on prior x the worst bin's upper bound. Synthetic
samples only (no flight): a fault whose HMI lies in one magnitude band and onset third."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.campaign.integrity_risk import MODES, ONSET_BINS, sample_bins, specific_risk, totals
from approachsim.integrity import rare
from approachsim.integrity.requirements import REQUIREMENTS

STEP = MODES["sat-step"]  # 1-100 m, log-uniform: two decades


def _band_hmi(u: np.ndarray, lo: float = 20.0, hi: float = 60.0) -> np.ndarray:
    """HMI iff the step is within [lo, hi) m and the onset in the last third of the window."""
    mag = np.array([STEP.magnitude(float(x)) for x in u[:, 1]])
    return (mag >= lo) & (mag < hi) & (sps.norm.cdf(u[:, 0]) >= 2.0 / 3.0)


def test_magnitude_edges_are_decades() -> None:
    assert STEP.magnitude_edges() == pytest.approx([1.0, 10.0, 100.0])
    assert MODES["sat-ramp"].magnitude_edges() == pytest.approx([0.01, 0.1, 1.0, 5.0])
    assert MODES["radalt-bias"].magnitude_edges() == pytest.approx([0.3, 3.0, 30.0])
    assert STEP.magnitude_fraction(1.0, 10.0) == pytest.approx(0.5)
    mb, ob = sample_bins(STEP, np.array([[-3.0, -3.0, 0.0], [0.0, 0.0, 0.0], [3.0, 3.0, 0.0]]))
    assert mb.tolist() == [0, 1, 1] and ob.tolist() == [0, 1, 2]  # Phi(0) = 0.5: magnitude 10 m, middle third


def test_cp_bounds_are_clopper_pearson_and_monotone() -> None:
    # effective counts at integers are the exact Clopper-Pearson bounds (scipy.stats.beta)
    for k, n in [(0, 33), (3, 33), (33, 33), (7, 200)]:
        assert rare.clopper_pearson_eff(k, n, 0.95) == pytest.approx(rare.clopper_pearson(k, n, 0.95))
    assert rare.clopper_pearson(0, 33, 0.95)[1] == pytest.approx(1.0 - 0.05 ** (1.0 / 33))  # 0.087
    assert rare.clopper_pearson(3, 33, 0.95)[1] == pytest.approx(sps.beta.ppf(0.95, 4, 30))
    # upper and lower rise with the hits at fixed n; at a fixed proportion the interval narrows as n grows
    ups = [rare.clopper_pearson_eff(k, 40.0, 0.95)[1] for k in np.linspace(0, 40, 81)]
    los = [rare.clopper_pearson_eff(k, 40.0, 0.95)[0] for k in np.linspace(0, 40, 81)]
    assert np.all(np.diff(ups) >= 0) and np.all(np.diff(los) >= 0)
    widths = [np.subtract(*rare.clopper_pearson_eff(0.1 * n, n, 0.95)[::-1]) for n in (10, 30, 100, 300, 1000)]
    assert np.all(np.diff(widths) < 0)
    # fewer samples without a hit: a wider (larger) upper bound
    assert [rare.clopper_pearson(0, n, 0.95)[1] for n in (5, 20, 80)] == sorted(
        [rare.clopper_pearson(0, n, 0.95)[1] for n in (5, 20, 80)], reverse=True)


def test_weighted_conditional_equal_weights_is_exact_cp() -> None:
    ind = np.array([True] * 4 + [False] * 16)
    r = rare.weighted_conditional(ind, np.full(20, 3.7), 0.95)
    assert r["n_eff"] == pytest.approx(20) and r["probability"] == pytest.approx(0.2)
    assert (r["lower"], r["upper"]) == pytest.approx(rare.clopper_pearson(4, 20, 0.95))
    # unequal weights: fewer effective samples, so a wider interval
    w = np.r_[np.full(10, 1.0), np.full(10, 9.0)]
    ind2 = np.r_[[True] * 2 + [False] * 8, [True] * 2 + [False] * 8]  # still 20 % by weight
    r2 = rare.weighted_conditional(ind2, w, 0.95)
    assert r2["probability"] == pytest.approx(0.2) and r2["n_eff"] < 20
    assert r2["upper"] - r2["lower"] > r["upper"] - r["lower"]
    assert rare.weighted_conditional(np.zeros(0, bool), np.zeros(0), 0.95)["upper"] == 1.0


def _study(specific: dict, avg_k: int, n: int, prior: float) -> dict:
    fa = {"rate_per_15s_gaussian": 1e-6, "rate_per_15s_upper_mc": 1e-3, "allocation_per_15s": 8e-6}
    cats = {c: {"hmi_gaussian": 1e-12, "hmi_gaussian_worst_run": 1e-12, "false_alert": fa} for c in REQUIREMENTS}
    lo, hi = rare.clopper_pearson(avg_k, n, 0.95)
    c = {"shown": True, "probability": avg_k / n, "lower": lo, "upper": hi, "specific": specific}
    return {"fault_free": {"categories": cats}, "modes": {"sat-step": {"prior": prior,
                                                                        "categories": {k: c for k in REQUIREMENTS}}}}


def test_one_band_average_shown_worst_bin_not_shown() -> None:
    """HMI only for a 20-60 m step with a late onset: the average over the log-uniform 1-100 m and the window is
    log(3) / log(100) / 3 = 0.080, the late 10-100 m bin's log(3) / log(10) = 0.48. With a prior of 1e-6 the average
    (x prior: 8.7e-8) is within CAT I's 2e-7; the worst bin (x prior: about 5e-7) is not."""
    rng = np.random.default_rng(41)
    u = rng.standard_normal((6000, 3))
    hit = _band_hmi(u)
    sp = specific_risk(STEP, u, hit, 0.95)
    assert len(sp["bins"]) == 2 * ONSET_BINS
    ns = [b["first_step"]["samples"] for b in sp["bins"]]
    assert sum(ns) == 6000 and min(ns) > 800  # about 1000 per bin
    wb = sp["bins"][sp["worst_bin"]]
    assert wb["magnitude"] == pytest.approx([10.0, 100.0]) and wb["onset_third"] == 3 and wb["from"] == "first_step"
    assert wb["lower"] <= math.log(3) / math.log(10) <= wb["upper"]
    assert (wb["lower"], wb["upper"]) == pytest.approx(
        rare.clopper_pearson(wb["first_step"]["hits"], wb["first_step"]["samples"], 0.95))
    assert all(b["upper"] < 0.01 for i, b in enumerate(sp["bins"]) if i != sp["worst_bin"])  # 0 of ~1000

    t = totals(_study(sp, int(hit.sum()), hit.size, 1e-6), 0.95)["CAT I"]
    assert t["verdict_average"] == "shown" and t["p_hmi_average_upper"] <= 2e-7
    assert t["verdict"] == "not shown" and t["p_hmi_upper"] > 2e-7
    term = t["terms"]["sat-step"]
    assert term["upper"] <= 2e-7 and not term["specific_shown"]
    assert term["specific_upper"] == pytest.approx(1e-6 * wb["upper"])
    assert term["worst_bin"]["magnitude"] == pytest.approx([10.0, 100.0])
    assert term["prior_allowed"] < term["prior_allowed_average"]


def test_few_samples_per_bin_give_wide_bounds() -> None:
    """200 first-step samples over 6 bins (about 33 each) and no HMI: every bin bounded by about 0.09, so a prior
    of 1e-5 x 0.09 = 9e-7 is not shown at CAT I even though no sample failed."""
    u = np.random.default_rng(7).standard_normal((200, 3))
    sp = specific_risk(STEP, u, np.zeros(200, bool), 0.95)
    assert 20 < sp["first_step_samples_per_bin"]["min"] <= sp["first_step_samples_per_bin"]["max"] < 50
    n_min = sp["first_step_samples_per_bin"]["min"]
    assert sp["worst_upper"] == pytest.approx(1.0 - 0.05 ** (1.0 / n_min))
    assert totals(_study(sp, 0, 200, 1e-5), 0.95)["CAT I"]["verdict"] == "not shown"


def test_last_step_weighted_where_it_has_more_effective_samples() -> None:
    """An importance sample concentrated on large late steps (u ~ N((2, 1.5), I), weights phi / h): the late
    10-100 m bin takes its figure from the weighted conditional (larger effective size than the first step's ~30),
    and that conditional's bounds hold the exact 0.477 (n_eff about 460 of 3500 samples)."""
    rng = np.random.default_rng(0)  # over seeds 0-39 the bounds missed 0.477 2 (lower) and 3 (upper) times of 40
    first = rng.standard_normal((200, 3))
    mu = np.array([2.0, 1.5, 0.0])
    last = mu + rng.standard_normal((4000, 3))
    w = np.exp(sps.multivariate_normal(np.zeros(3)).logpdf(last) - sps.multivariate_normal(mu).logpdf(last))
    sp = specific_risk(STEP, first, _band_hmi(first), 0.95, last, _band_hmi(last), w)
    late_big = next(b for b in sp["bins"] if b["magnitude"][0] == pytest.approx(10.0) and b["onset_third"] == 3)
    assert late_big["from"] == "last_step_weighted"
    assert late_big["last_step"]["n_eff"] > late_big["first_step"]["samples"]
    assert late_big["lower"] <= math.log(3) / math.log(10) <= late_big["upper"]
    early_small = next(b for b in sp["bins"] if b["magnitude"][0] == pytest.approx(1.0) and b["onset_third"] == 1)
    assert early_small["from"] == "first_step"  # the proposal hardly visits it


def test_first_step_needed_per_bin() -> None:
    """Zero HMI in 200 samples: the average needs 299 first-step runs at a 1e-5 prior and CAT I's equal share 1e-7
    (two terms), the specific risk 299 in every bin, 6 x 299 = 1794 with two decades and three onset thirds."""
    u = np.random.default_rng(7).standard_normal((200, 3))
    sp = specific_risk(STEP, u, np.zeros(200, bool), 0.95)
    term = totals(_study(sp, 0, 200, 1e-5), 0.95)["CAT I"]["terms"]["sat-step"]
    n = math.ceil(math.log(0.05) / math.log1p(-1e-7 / 1e-5))
    assert n == 299 and term["first_step_needed_specific"] == 6 * n
