"""Regression comparison with statistical tolerances, and the regress command's option errors."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.campaign.regress import compare, f_band
from approachsim.cli import main

PROFILES = Path(__file__).resolve().parents[3] / "profiles"

SUMMARY = {
    "schema": "approachsim.summary/1", "profile": "p", "runs": 8, "seed": 7, "closed_loop": False,
    "decision_heights": {
        c: {"height_ft": h, "lateral_1sigma_ft": 5.0, "vertical_1sigma_ft": 2.0, "lateral_95_ft": 9.0,
            "vertical_95_ft": 3.5, "limit_lateral_1sigma_ft": 28.1, "limit_vertical_1sigma_ft": 6.8, "meets": m}
        for c, h, m in (("CAT I", 200, True), ("CAT II", 100, True), ("CAT III", 50, False))
    },
    "best_category": "CAT II",
    "failed_runs": 0,
}


def test_identical_is_clean_and_band_is_the_f_distribution():
    assert not any(d.regression for d in compare(SUMMARY, copy.deepcopy(SUMMARY)))
    lo, hi = f_band(8)
    assert lo**2 == pytest.approx(sps.f.ppf(0.0005, 8, 8)) and hi**2 == pytest.approx(sps.f.ppf(0.9995, 8, 8))
    # false-alarm rate of the band on same-distribution campaigns of 8 runs: about alpha = 1e-3
    rng = np.random.default_rng(1)
    a = np.sqrt(np.mean(rng.normal(size=(200000, 8)) ** 2, axis=1))
    b = np.sqrt(np.mean(rng.normal(size=(200000, 8)) ** 2, axis=1))
    rate = np.mean((b / a < lo) | (b / a > hi))
    assert 0.0005 < rate < 0.002


def test_shift_inside_and_outside_tolerance():
    lo, hi = f_band(8)
    new = copy.deepcopy(SUMMARY)
    new["decision_heights"]["CAT I"]["lateral_1sigma_ft"] = 5.0 * (1 + hi) / 2  # inside the band
    inside = compare(SUMMARY, new)
    assert not any(d.regression for d in inside)
    assert [d.line().split()[0] for d in inside if d.old != d.new] == ["changed"]
    new["decision_heights"]["CAT I"]["lateral_1sigma_ft"] = 5.0 * hi * 1.01
    bad = [d for d in compare(SUMMARY, new) if d.regression]
    assert [d.field for d in bad] == ["CAT I.lateral_1sigma_ft"]
    assert bad[0].line().startswith("REGRESSION CAT I.lateral_1sigma_ft: 5.0 ->")


def test_verdict_and_failures_are_regressions():
    new = copy.deepcopy(SUMMARY)
    new["decision_heights"]["CAT II"]["meets"] = False
    new["best_category"] = "CAT I"
    new["failed_runs"] = 1
    fields = {d.field for d in compare(SUMMARY, new) if d.regression}
    assert fields == {"CAT II.meets", "best_category", "failed_runs"}
    fewer = copy.deepcopy(SUMMARY)
    fewer["decision_heights"]["CAT I"]["lateral_95_ft"] = None
    assert {d.field for d in compare(SUMMARY, fewer) if d.regression} == {"CAT I.lateral_95_ft"}


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--baselines", "/nonexistent/dir"], "--baselines"),
        (["--workers", "0"], "--workers"),
        (["--runs", "0"], "--runs"),
        (["--seed", "-1"], "--seed"),
        (["--add", str(PROFILES / "default.toml")], "--add"),
        (["--update", "--add", "/nonexistent.toml"], "--add"),
        (["--mode", "x"], "--mode"),
    ],
)
def test_bad_regress_options_exit_2(argv, needle, capsys, tmp_path):
    try:
        code = main(["regress", *argv])
    except SystemExit as e:
        code = e.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err


def test_empty_and_malformed_baselines_exit_2(tmp_path, capsys):
    assert main(["regress", "--baselines", str(tmp_path)]) == 2
    (tmp_path / "x.json").write_text('{"schema": "other"}')
    assert main(["regress", "--baselines", str(tmp_path)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and "no baseline files" in err[0] and "not an approachsim.baseline/1" in err[1]


def test_committed_baselines_are_valid():
    from pathlib import Path

    from approachsim.campaign.regress import read_baseline
    from approachsim.profile import load_profile

    root = Path(__file__).resolve().parents[3]
    files = sorted((root / "baselines").glob("*.json"))
    assert files, "no committed baselines"
    for f in files:
        doc = read_baseline(f)
        prof = load_profile(root / doc["profile"])
        assert doc["summary"]["profile"] == prof.name == f.stem
        assert (doc["summary"]["runs"], doc["summary"]["seed"]) == (doc["runs"], doc["seed"])
        assert set(doc["summary"]["decision_heights"]) == {"CAT I", "CAT II", "CAT III"}
