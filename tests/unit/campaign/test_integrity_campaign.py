"""Integrity scoring on constructed bank epochs and constructed campaign columns: known PLs, errors and alert
limits give known availability, MI / HMI counts and Stanford regions; the campaign bounds are the
Clopper-Pearson / Poisson ones; the verdict's integrity criterion blocks `meets` and decides `fails`."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.campaign.integrity_bank import BankEpochs
from approachsim.campaign.integrity_campaign import (
    NB,
    STANFORD_EDGES_M,
    campaign_integrity,
    poisson_upper,
    run_integrity,
    stanford_counts,
    stanford_hist,
)
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.verdict import category_verdict, integrity_verdict
from approachsim.integrity.requirements import REQUIREMENTS

CFG = EvaluationConfig(timeavg_settle_s=0.0)


def _epochs(n=100, sig_main=1.0, sig_sub=1.2, e0=None, ek=None, k=4):
    """n epochs at 1 Hz descending from 1000 m to 0 along a 3 deg path; constant variances."""
    t = np.arange(n, dtype=float)
    h = np.linspace(300.0, 0.0, n)
    along = -h / math.tan(math.radians(3.0))
    e0 = np.zeros((n, 2)) if e0 is None else e0
    ek = np.zeros((n, k, 2)) if ek is None else ek
    return BankEpochs(t, e0, np.full((n, 2), sig_main**2), ek, np.full((n, k, 2), sig_sub**2),
                      np.arange(k) + 3, along, h)


def test_stanford_counts_and_hist_on_known_points():
    err = np.array([0.5, 2.0, 20.0, 5.0, 50.0])
    pl = np.array([1.0, 1.0, 1.0, 30.0, 30.0])
    al = np.full(5, 10.0)
    assert stanford_counts(err, pl, al) == {"normal": 1, "mi": 1, "hmi": 1, "unavailable": 2}
    h = stanford_hist(err, pl).reshape(NB, NB)
    assert h.sum() == 5
    i = np.searchsorted(STANFORD_EDGES_M, 20.0, side="right") - 1
    j = np.searchsorted(STANFORD_EDGES_M, 1.0, side="right") - 1
    assert h[i, j] == 1


def test_fault_free_constructed_run_counts():
    ep = _epochs()
    s, counts, _ = run_integrity(ep, CFG, epoch_hz=1.0, t0_s=0.0)
    req = REQUIREMENTS["CAT I"]
    # PL_H1 = K_fa sigma_ss + K_md sigma_k, sigma_ss = sqrt(1.44 - 1)
    k_fa = req.k_fa(1.0, 2 * 4)
    pl_h1 = k_fa * math.sqrt(0.44) + req.k_md(4) * 1.2  # K_md with the 4 modes (issue 41)
    assert s["cat1_int_vpl_dh_m"] == pytest.approx(max(pl_h1, req.k_ff() * 1.0))
    n1 = int(np.sum(ep.height_m >= 200 * 0.3048))
    assert s["cat1_int_epochs"] == n1
    # CAT I VAL 10 m at the DH: PL ~ 7.8 m < 10 m on both axes (LAL 40 m): every epoch available
    assert s["cat1_int_avail_epochs"] == n1 and s["cat1_int_avail_dh"] == 1.0
    assert s["cat1_int_mi"] == 0 and s["cat1_int_hmi"] == 0 and s["cat1_int_detect_events"] == 0
    assert counts["cat1_stanford_v"].sum() == n1
    assert "cat1_int_onset_s" not in s


def test_misleading_and_hazardous_epochs_are_counted_at_epochs():
    n = 100
    e0 = np.zeros((n, 2))
    e0[10:13, 0] = 9.0  # > PL (7.8 m), < VAL (10 m): MI, not HMI (sub-solutions carry the same error)
    e0[76:78, 0] = 14.0  # > VAL (about 10.9 m at 225 ft, Table B-69) while available: HMI (and MI)
    ek = np.repeat(e0[:, None, :], 4, axis=1)  # every sub-solution has it: no separation, no detection
    s, _, _ = run_integrity(_epochs(e0=e0, ek=ek), CFG, epoch_hz=1.0, t0_s=0.0)
    assert s["cat1_int_mi"] == 5 and s["cat1_int_hmi"] == 2
    assert s["cat1_int_v_mi"] == 3 and s["cat1_int_v_hmi"] == 2
    assert s["cat1_int_detect_epochs"] == 0


def test_fault_detected_excluded_and_time_to_alert():
    n = 100
    e0 = np.zeros((n, 2))
    e0[30:, 0] = 0.5 * (np.arange(n - 30) + 1)  # 0.5 m/s ramp in the main solution from t = 30 s
    ek = np.repeat(e0[:, None, :], 4, axis=1)
    ek[:, 2, :] = 0.0  # sub-filter 2 leaves the faulted channel out: it stays clean
    s, _, _ = run_integrity(_epochs(e0=e0, ek=ek), CFG, epoch_hz=1.0, t0_s=0.0, onset_s=30.0, fault_ch=5)
    req = REQUIREMENTS["CAT I"]
    thr = req.k_fa(1.0, 8) * math.sqrt(0.44)  # detection when |Delta| = ramp > K_fa sigma_ss
    t_det = 30 + math.floor(thr / 0.5)
    assert s["cat1_int_t_detect_s"] == t_det
    assert s["cat1_int_delay_s"] == t_det - 30
    assert s["cat1_int_excluded_channel"] == 5 and s["cat1_int_right"] == 1.0
    # the main error passes its PL (max(PL_H0, PL_H1)) after the detection: detected before (tta < 0)
    pl = max(req.k_ff(), thr + req.k_md(4) * 1.2)
    t_exceed = 30 + math.floor(pl / 0.5)
    assert s["cat1_int_tta_s"] == pytest.approx(t_det - t_exceed)
    assert s["cat1_int_exceeded"] == 1.0 and s["cat1_int_missed"] == 0.0
    assert s["cat1_int_mi"] == 0  # the output after the exclusion is the clean sub-solution


def _columns(runs=400, avail_dh=None, hmi=0, detect=0):
    cols = {}
    for key in ("cat1", "cat2", "cat3"):
        cols[f"{key}_int_epochs"] = np.full(runs, 250.0)
        cols[f"{key}_int_avail_epochs"] = np.full(runs, 240.0)
        dh = np.ones(runs) if avail_dh is None else avail_dh
        cols[f"{key}_int_avail_dh"] = dh
        cols[f"{key}_int_mi"] = np.zeros(runs)
        h = np.zeros(runs)
        h[:hmi] = 1.0
        cols[f"{key}_int_hmi"] = h
        d = np.zeros(runs)
        d[:detect] = 1.0
        cols[f"{key}_int_detect_events"] = d
    return cols


def test_campaign_bounds_are_clopper_pearson_and_poisson():
    cols = _columns(runs=400, detect=2)
    out = campaign_integrity(cols, {}, CFG)["categories"]["CAT II"]
    n_ep = 400 * 250
    assert out["availability"]["fraction"] == pytest.approx(240 / 250)
    assert out["availability"]["lower"] == pytest.approx(sps.beta.ppf(0.05, 400 * 240, n_ep - 400 * 240 + 1))
    assert out["availability_dh"]["lower"] == pytest.approx(0.05 ** (1 / 400))  # all 400 available
    assert out["hmi"]["count"] == 0
    assert out["hmi"]["rate_per_epoch_upper"] == pytest.approx(1 - 0.05 ** (1 / n_ep))
    fa = out["false_alert"]
    windows = n_ep / 15.0
    assert fa["alerts"] == 2 and fa["rate_per_15s"] == pytest.approx(2 / windows)
    assert fa["rate_per_15s_upper"] == pytest.approx(sps.chi2.ppf(0.95, 6) / 2 / windows)
    assert poisson_upper(0, 0.95) == pytest.approx(-math.log(0.05))


def test_campaign_counts_per_approach():
    """Issue 41 item 4: MI, HMI and false alerts counted per approach, with Clopper-Pearson bounds on runs; the
    false-alert allocation over the approach's scored time; a run of 250 epochs with 3 HMI epochs is one approach."""
    cols = _columns(runs=400, detect=2)
    cols["cat2_int_hmi"][:2] = [3.0, 1.0]  # two approaches with HMI, four epochs
    cols["cat2_int_modes"] = np.full(400, 9.0)
    out = campaign_integrity(cols, {}, CFG)["categories"]["CAT II"]
    assert out["hmi"]["count"] == 4 and out["hmi"]["runs_with"] == 2 and out["hmi"]["approaches"] == 400
    assert out["hmi"]["probability_per_approach_lower"] == pytest.approx(sps.beta.ppf(0.05, 2, 399))
    assert out["hmi"]["probability_per_approach_upper"] == pytest.approx(sps.beta.ppf(0.95, 3, 398))
    assert out["hmi"]["allowed_per_approach"] == 1e-9
    fa = out["false_alert"]
    assert fa["runs_with"] == 2 and fa["probability_per_approach_upper"] == pytest.approx(sps.beta.ppf(0.95, 3, 398))
    # 250 s scored per approach at 1 Hz: 1 - (1 - 8e-6)^(250 / 15) = 1.333e-4
    assert fa["allocation_per_approach"] == pytest.approx(1 - (1 - 8e-6) ** (250 / 15), rel=1e-9)
    req = out["requirement"]
    assert req["n_modes"] == 9 and req["p_md"] == pytest.approx(1e-9 / 4 / (7.5 * 9 * 1e-5))
    assert req["hmi_window_s"] == [15.0, 30.0] and "not GAST-D" in req["model"]


def test_integrity_verdict_cases():
    """Counted per approach (issue 41 item 4): the allocation is per approach, so the bound is on runs."""
    allowed = REQUIREMENTS["CAT II"].hmi_probability_allowed
    assert allowed == 1e-9
    # 20 runs all available at the DH, no HMI: lower bound 0.86 < 0.99 and 20 approaches cannot bound 1e-9
    v = integrity_verdict(20, 20, 0, 0.99, allowed)
    assert (v.availability_verdict, v.hmi_verdict, v.verdict) == ("indeterminate", "indeterminate", "indeterminate")
    assert v.hmi_finding == "not shown"
    # approaches, not epochs: 1 - 0.05^(1/n) <= 1e-9 at n = ln(0.05) / ln(1 - 1e-9) = 2.996e9 (was 1.8e8 runs when
    # 250 epochs a run counted as independent samples)
    assert v.runs_needed == math.ceil(math.log(0.05) / math.log1p(-1e-9))
    assert 2.99e9 < v.runs_needed < 3.0e9
    assert v.hmi_probability_upper == pytest.approx(1 - 0.05 ** (1 / 20))
    # 5 of 20 available: upper bound below 0.99 -> fails
    assert integrity_verdict(5, 20, 0, 0.99, allowed).verdict == "fails"
    # one approach with HMI (CAT I: the window is the approach): lower bound 1 - 0.95^(1/20) = 2.6e-3 > 1e-9
    v = integrity_verdict(20, 20, 1, 0.99, allowed)
    assert v.hmi_verdict == "fails" and v.hmi_finding == "exceeds"
    assert v.hmi_window_lower == pytest.approx(1 - 0.95 ** (1 / 20))
    # a loose allowance a campaign can reach: meets
    v = integrity_verdict(400, 400, 0, 0.99, 1e-2)
    assert v.verdict == "meets" and v.runs_needed is None and v.hmi_finding == "shown"
    # availability alone undecided: runs_needed is where 0.05^(1/n) reaches 0.99
    v = integrity_verdict(100, 100, 0, 0.99, 1e-1)
    assert v.availability_verdict == "indeterminate" and v.runs_needed == pytest.approx(299, abs=3)


def test_integrity_blocks_meets_and_decides_runs_needed():
    rng = np.random.default_rng(3)
    lat, ver = rng.normal(0, 1.0, 200), rng.normal(0, 0.3, 200)  # far inside the CAT I limits (28.1 / 6.8 ft)
    assert category_verdict("CAT I", 200, lat, ver).verdict == "meets"
    undecided = integrity_verdict(100, 100, 0, 0.99, 1e-1)
    r = category_verdict("CAT I", 200, lat, ver, integrity=undecided)
    assert r.verdict == "indeterminate" and not r.meets
    assert r.runs_needed == undecided.runs_needed  # the deciding criterion
    r = category_verdict("CAT I", 200, lat, ver, integrity=integrity_verdict(5, 20, 0, 0.99, 1e-1))
    assert r.verdict == "fails"
    r = category_verdict("CAT I", 200, lat, ver, integrity=integrity_verdict(400, 400, 0, 0.99, 1e-2))
    assert r.verdict == "meets"


def test_run_result_counts_round_trip_sparse():
    import json

    from approachsim.campaign.integrity_campaign import sum_counts
    from approachsim.campaign.result import RunResult

    h = np.zeros(NB * NB)
    h[[3, 700, 1599]] = [2.0, 5.0, 1.0]
    r = RunResult(run=4, ok=True, scalars={"x": 1.0}, counts={"cat1_stanford_v": h})
    line = r.json_line()
    assert len(json.loads(line)["counts"]["cat1_stanford_v"]["index"]) == 3  # sparse on disk
    back = RunResult.from_record(json.loads(line))
    assert back.same_as(r) and np.array_equal(back.counts["cat1_stanford_v"], h)
    assert "counts" not in RunResult(run=1, ok=True, scalars={"x": 1.0}).record()  # integrity off: unchanged
    total = sum_counts([r, back, RunResult.failed(5, "x")])
    assert np.array_equal(total["cat1_stanford_v"], 2 * h)


@pytest.mark.parametrize(("value", "expected"), [
    (None, ("CAT II", "CAT III")), (True, ("CAT I", "CAT II", "CAT III")), (False, ()),
    (["CAT III", "CAT I"], ("CAT I", "CAT III")),
])
def test_evaluation_integrity_key(value, expected):
    from approachsim.config import Section
    from approachsim.evaluate.config import parse_evaluation

    cfg = parse_evaluation(Section({} if value is None else {"integrity": value}, "evaluation"))
    assert cfg.integrity == expected and cfg.integrity_on == bool(expected)


@pytest.mark.parametrize("value", ["CAT II", ["CAT IV"], ["CAT I", "CAT I"], 1])
def test_evaluation_integrity_bad_value_names_the_field(value):
    from approachsim.config import ProfileError, Section
    from approachsim.evaluate.config import parse_evaluation

    with pytest.raises(ProfileError, match=r"evaluation\.integrity"):
        parse_evaluation(Section({"integrity": value}, "evaluation"))


def test_integrity_figures_from_a_constructed_faulted_campaign():
    from approachsim.campaign.result import RunResult
    from approachsim.report.integrity import integrity_figures, integrity_rows

    n = 100
    e0 = np.zeros((n, 2))
    e0[30:, 0] = 0.5 * (np.arange(n - 30) + 1)
    ek = np.repeat(e0[:, None, :], 4, axis=1)
    ek[:, 2, :] = 0.0
    grid = np.arange(600.0, -1.0, -6.0)
    s, counts, arrays = run_integrity(_epochs(e0=e0, ek=ek), CFG, epoch_hz=1.0, t0_s=0.0, onset_s=30.0,
                                      fault_ch=5, height_grid_m=grid)
    results = [RunResult(run=i, ok=True, scalars=s, arrays=arrays, counts=counts) for i in range(3)]
    cols = {k: np.full(3, v) for k, v in s.items()}
    det = {"integrity": campaign_integrity(cols, {k: 3 * v for k, v in counts.items()}, CFG)}
    tt = det["integrity"]["categories"]["CAT II"]["time_to_alert"]
    assert tt["detected"] == 3 and tt["within_tta"] == 3 and tt["missed_detections"] == 0
    figs = integrity_figures(results, det)
    assert set(figs) == {"integrity_stanford", "integrity_availability", "integrity_tta"}
    assert len(figs["integrity_stanford"].axes) == 7  # 2 axes x 3 categories + the colour bar
    assert len(integrity_rows(det)) == 3


def test_summary_json_extension_carries_the_per_approach_integrity():
    """summary.json decision_heights.<CAT>.integrity (docs/contract.md): only where integrity is in the verdict."""
    from approachsim.evaluate.summary import contract_summary

    rng = np.random.default_rng(5)
    lat, ver = rng.normal(0, 1.0, 50), rng.normal(0, 0.3, 50)
    iv = integrity_verdict(50, 50, 0, 0.99, 1e-9)
    rs = [category_verdict("CAT I", 200, lat, ver), category_verdict("CAT II", 100, lat, ver, integrity=iv)]
    s = contract_summary(rs, profile="p", runs=50, seed=1, closed_loop=True, failed_runs=0)
    assert "integrity" not in s["decision_heights"]["CAT I"]
    e = s["decision_heights"]["CAT II"]["integrity"]
    assert e["hmi"] == "not shown" and e["approaches"] == 50 and e["hmi_approaches"] == 0
    assert e["hmi_probability_upper"] == pytest.approx(1 - 0.05 ** (1 / 50)) and e["hmi_allowed"] == 1e-9
    assert s["decision_heights"]["CAT II"]["runs_needed"] == iv.runs_needed > 2.99e9


def _spike_run(before_dh_s: float, axis: int = 0, size_m: float = 12.0):
    """One constructed run (300 epochs at 1 Hz, 900 m to 0 at 3 m/s, clean sub-filters so nothing is detected,
    PL ~ 9 m < the 10 m VAL and 17 m LAL: available) with one epoch's error beyond the CAT III alert limit on
    `axis`, `before_dh_s` before the last epoch above the CAT III DH (50 ft)."""
    n = 300
    ep = _epochs(n=n)
    ep = BankEpochs(ep.t_s, ep.e0, ep.p0, ep.ek, ep.pk, ep.channels, -np.linspace(900.0, 0.0, n) / math.tan(
        math.radians(3.0)), np.linspace(900.0, 0.0, n))
    last = int(np.flatnonzero(ep.height_m >= CFG.dh_m("CAT III"))[-1])
    e0 = np.zeros((n, 2))
    e0[last - int(before_dh_s), axis] = size_m + (0.0 if axis == 0 else 8.0)  # 12 m > VAL 10; 20 m > LAL 17
    ek = np.repeat(e0[:, None, :], 4, axis=1)  # every sub-solution carries it: no separation, no detection
    ep = BankEpochs(ep.t_s, e0, ep.p0, ek, ep.pk, ep.channels, ep.along_m, ep.height_m)
    s, _, _ = run_integrity(ep, CFG, epoch_hz=1.0, t0_s=0.0)
    return s


def _verdict_of(runs: list[dict], cat: str):
    from approachsim.evaluate.summary import integrity_criterion

    cols = {k: np.array([r[k] for r in runs]) for k in runs[0]}
    return integrity_criterion(cols, cat, CFG)


@pytest.mark.parametrize("axis", [0, 1])
def test_hmi_outside_the_window_is_not_shown_never_exceeds(axis):
    """Issue 41 acceptance: HMI only at DH - 100 s gives CAT III `not shown`, never `exceeds` (per-epoch counting
    called it `fails`); inside the window (DH - 5 s) it gives `exceeds`, the lower bound of 20 of 20 approaches,
    0.05^(1/20) = 0.86, being above 1e-9. CAT I counts per approach: HMI at DH - 100 s (still above CAT I's DH)
    beyond its scaled alert limit is its event."""
    far = _spike_run(100.0, axis)
    assert far["cat3_int_hmi"] == 1 and far["cat3_int_avail_epochs"] == far["cat3_int_epochs"]
    assert far["cat3_int_hmi_window"] == 0 and far["cat3_int_detect_epochs"] == 0
    v = _verdict_of([far] * 20, "CAT III")
    assert v.hmi_finding == "not shown" and v.hmi_verdict == "indeterminate"
    assert v.hmi_approaches == 20 and v.hmi_window_approaches == 0 and v.runs_needed is None
    # CAT I counts per approach, against its alert limit scaled with height (Table B-69: 34 m at 1030 ft here)
    assert _verdict_of([far] * 20, "CAT I").hmi_approaches == 0
    if axis == 0:
        big = _spike_run(100.0, axis, 50.0)
        assert big["cat1_int_hmi_window"] == 1 and _verdict_of([big] * 20, "CAT I").hmi_finding == "exceeds"
    near = _spike_run(5.0, axis)
    assert near["cat3_int_hmi_window"] == 1
    v = _verdict_of([near] * 20, "CAT III")
    assert v.hmi_finding == "exceeds" and v.verdict == "fails"
    assert v.hmi_window_lower == pytest.approx(0.05 ** (1 / 20)) and v.hmi_window_lower > 1e-9
    # the lateral window is 30 s, the vertical 15 s: at DH - 20 s only a lateral HMI is inside
    mid = _spike_run(20.0, axis)
    assert mid["cat3_int_hmi_window"] == float(axis == 1)
