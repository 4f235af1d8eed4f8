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
