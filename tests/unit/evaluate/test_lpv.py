"""LPV-200's verdict (evaluate/lpv.py) on synthetic per-run columns: the 95 % order-statistic bounds against 4 m /
16 m, availability at the DH against 0.99, and no integrity basis without SBAS."""

from __future__ import annotations

import numpy as np

from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.lpv import lpv200_summary


def _cols(n: int, v_sigma: float, avail: float, sbas: bool, seed: int = 0) -> dict[str, np.ndarray]:
    g = np.random.default_rng(seed)
    k = int(round(avail * n))
    return {"cat1_vertical_m": v_sigma * g.standard_normal(n), "cat1_along_m": g.standard_normal(n),
            "cat1_lateral_m": g.standard_normal(n), "lpv200_vpl_m": np.full(n, 15.0), "lpv200_hpl_m": np.full(n, 10.0),
            "lpv200_avail_dh": np.r_[np.ones(k), np.zeros(n - k)], "lpv200_avail_fraction": np.ones(n),
            "lpv200_sbas": np.full(n, float(sbas))}


def test_meets_with_enough_runs() -> None:
    s = lpv200_summary(_cols(400, 0.5, 1.0, True), EvaluationConfig(), runs=400, failed_runs=0)
    assert s["verdict"] == "meets" and s["vertical_95_upper_m"] < 4.0 and s["availability_dh_lower"] >= 0.99


def test_few_runs_indeterminate_and_accuracy_fails() -> None:
    s = lpv200_summary(_cols(30, 0.5, 1.0, True), EvaluationConfig(), runs=30, failed_runs=0)
    assert s["verdict"] == "indeterminate" and s["vertical_95_upper_m"] is None  # no rank below 59 runs
    s = lpv200_summary(_cols(200, 5.0, 1.0, True), EvaluationConfig(), runs=200, failed_runs=0)
    assert s["accuracy_verdict"] == "fails" and s["verdict"] == "fails"  # 95 % of |N(0, 5 m)| is 9.8 m


def test_no_sbas_no_integrity_and_unavailable_fails() -> None:
    s = lpv200_summary(_cols(400, 0.5, 1.0, False), EvaluationConfig(), runs=400, failed_runs=0)
    assert s["integrity_basis"] is None and s["integrity_verdict"] == "fails" and s["verdict"] == "fails"
    s = lpv200_summary(_cols(400, 0.5, 0.9, True), EvaluationConfig(), runs=400, failed_runs=0)
    assert s["integrity_verdict"] == "fails"  # 360 / 400: the upper bound is below 0.99


def test_absent_without_service() -> None:
    assert lpv200_summary({"cat1_vertical_m": np.zeros(3)}, EvaluationConfig(), runs=3, failed_runs=0) is None


def test_all_available_needs_about_300_runs() -> None:
    """Every one of 200 runs available: the Clopper-Pearson lower bound is 0.985 < 0.99, so integrity is
    indeterminate and about 300 runs would decide it (0.95^(1/n) >= 0.99 from n = 299)."""
    s = lpv200_summary(_cols(200, 0.5, 1.0, True), EvaluationConfig(), runs=200, failed_runs=0)
    assert s["integrity_verdict"] == "indeterminate" and 299 <= s["runs_needed"] <= 320


def test_count_misleading_regions() -> None:
    """The integrity diagram's regions, epoch by epoch: unavailable (VPL > 35 m) never counts, an error above its
    PL is MI, above the alert limit while available HMI (which is also MI); a nan error (no fix) counts as
    available only."""
    from approachsim.evaluate.lpv import count_misleading

    v = np.array([1.0, 20.0, 36.0, 40.0, np.nan, 0.5])
    h = np.array([1.0, 1.0, 1.0, 1.0, np.nan, 41.0])
    vpl = np.array([15.0, 15.0, 34.0, 36.0, 15.0, 15.0])
    hpl = np.array([10.0, 10.0, 10.0, 10.0, 10.0, 10.0])
    # epoch 0 fine; 1 MI (20 > 15); 2 MI + HMI (36 > 35 while VPL 34); 3 unavailable; 4 available, no fix;
    # 5 MI + HMI horizontally (41 > 40)
    assert count_misleading(v, h, vpl, hpl) == (5, 3, 2)
    assert count_misleading(-v, h, vpl, hpl) == (5, 3, 2)  # |vertical|


def test_an_hmi_approach_fails_integrity_and_none_does_not_decide() -> None:
    """One run of 400 with an HMI epoch fails LPV-200's integrity (2e-7 per approach cannot hold with one in 400
    observed); with none the verdict stands on availability, and the per-approach HMI bound is Clopper-Pearson's
    (1 - 0.05^(1/400) = 0.0075 at 95 %)."""
    cols = _cols(400, 0.5, 1.0, True)
    cols.update(lpv200_available_epochs=np.full(400, 250.0), lpv200_mi_epochs=np.zeros(400),
                lpv200_hmi_epochs=np.zeros(400))
    s = lpv200_summary(cols, EvaluationConfig(), runs=400, failed_runs=0)
    assert s["verdict"] == "meets" and (s["hmi_runs"], s["mi_runs"], s["available_epochs"]) == (0, 0, 100000)
    assert abs(s["hmi_probability_upper"] - (1 - 0.05 ** (1 / 400))) < 1e-9 and s["integrity_risk"] == 2e-7
    cols["lpv200_hmi_epochs"][7] = cols["lpv200_mi_epochs"][7] = 2.0
    s = lpv200_summary(cols, EvaluationConfig(), runs=400, failed_runs=0)
    assert s["integrity_verdict"] == "fails" and s["verdict"] == "fails"
    assert (s["hmi_runs"], s["mi_runs"], s["hmi_epochs"]) == (1, 1, 2)
