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
        (["--add-paper", "gray-maybeck"], "--add-paper"),
        (["--update", "--add-paper", "gray-maybeck", "--mode", "open"], "--add-paper"),
        (["--add-paper", "other"], "--add-paper"),
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
    assert len(err) == 2 and "no baseline files" in err[0] and "not an approachsim.baseline/2" in err[1]


def test_committed_baselines_are_valid():
    from pathlib import Path

    from approachsim.campaign.regress import read_baseline
    from approachsim.commands.regress import PAPER_REF, baseline_profile
    from approachsim.papers.gray_maybeck import CASES
    from approachsim.profile import load_profile

    root = Path(__file__).resolve().parents[3]
    files = sorted((root / "baselines").glob("*.json"))
    assert files, "no committed baselines"
    paper = set()
    for f in files:
        doc = read_baseline(f)
        if doc["profile"].startswith(PAPER_REF):
            roman = doc["profile"][len(PAPER_REF):]
            prof = baseline_profile(doc["profile"], root)
            assert f.stem == f"gray-maybeck-{roman}" and doc["mode"] == "closed"
            assert doc["summary"]["profile"] == prof.name == f"gray-maybeck[case {roman}]"
            paper.add(roman)
        else:
            prof = load_profile(root / doc["profile"])
            assert doc["summary"]["profile"] == prof.name == f.stem
        assert (doc["summary"]["runs"], doc["summary"]["seed"]) == (doc["runs"], doc["seed"])
        assert set(doc["summary"]["decision_heights"]) == {"CAT I", "CAT II", "CAT III"}
    # the study's small-N version guards every case of Table 2
    assert paper == {c.roman for c in CASES}


def test_paper_baseline_references():
    """`paper:gray-maybeck:<case>` resolves to that case's profile (the radar altimeter of case IV, not of case
    III); any other paper reference or case is bad input naming the field."""
    from pathlib import Path

    from approachsim.commands.regress import baseline_profile
    from approachsim.config import ProfileError

    iv, iii = (baseline_profile(f"paper:gray-maybeck:{c}", Path(".")) for c in ("IV", "III"))
    assert iv.name == "gray-maybeck[case IV]" and iii.name == "gray-maybeck[case III]"
    assert iv.sensors.radalt is not None and iii.sensors.radalt is None
    for bad, needle in (("paper:other:I", "paper reference"), ("paper:gray-maybeck:XVII", "Table 2")):
        with pytest.raises(ProfileError, match=needle):
            baseline_profile(bad, Path("."))


# --- the paired (common random numbers) test of schema-/2 baselines ---------------------------------------------

def _crn(rng, trials: int, n: int, share: float, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-run errors before / after scaling one error source (variance share `share`) by `scale`; the draws
    of every source are common to both, as the per-sensor streams make them."""
    g, o = rng.normal(size=(trials, n)), rng.normal(size=(trials, n))
    return np.sqrt(share) * g + np.sqrt(1 - share) * o, scale * np.sqrt(share) * g + np.sqrt(1 - share) * o


def test_paired_false_alarm_rate_on_reshuffled_draws():
    """A reshuffle: the same model, independent draws. Nominal alpha = 1e-3 per field; the t reference is
    approximate for n = 20 (squared errors are skewed): measured 0.2 % (8 of 4000), below 0.5 %."""
    from approachsim.campaign.regress import ALPHA, paired_change

    rng = np.random.default_rng(10)
    for mu in (0.0, 1.0):  # with and without a bias
        a, b = rng.normal(mu, 1.0, (4000, 20)), rng.normal(mu, 1.0, (4000, 20))
        rate = np.mean([paired_change(x, y)["regression"] for x, y in zip(a, b, strict=True)])
        assert rate < 5 * ALPHA, (mu, rate)
    # a partial reshuffle (one source's stream redrawn) is not a change either
    g, g2, o = rng.normal(size=(3, 4000, 20))
    old, new = np.sqrt(0.8) * g + np.sqrt(0.2) * o, np.sqrt(0.8) * g2 + np.sqrt(0.2) * o
    assert np.mean([paired_change(x, y)["regression"] for x, y in zip(old, new, strict=True)]) < 5 * ALPHA


def test_paired_power_for_a_degraded_source():
    """One source carrying 80 % of the error variance (the radar altimeter at the decision heights of the
    default profile: its noise x1.1 moves the vertical 1-sigma by +6..9 %) degraded by 10 % and 2x."""
    from approachsim.campaign.regress import paired_change

    rng = np.random.default_rng(11)
    old, new = _crn(rng, 400, 20, 0.8, 1.1)  # 1-sigma +8.5 %
    power_10 = np.mean([paired_change(x, y)["regression"] for x, y in zip(old, new, strict=True)])
    old, new = _crn(rng, 400, 20, 0.8, 2.0)  # 1-sigma +67 %
    power_2x = np.mean([paired_change(x, y)["regression"] for x, y in zip(old, new, strict=True)])
    old, new = _crn(rng, 400, 20, 1.0, 1.1)  # the whole error scaled by 1.1: every run's error moves alike
    power_all = np.mean([paired_change(x, y)["regression"] for x, y in zip(old, new, strict=True)])
    assert power_all == 1.0 and power_2x > 0.99 and power_10 > 0.9, (power_10, power_2x, power_all)  # 1.0: 400 of 400
    # a change below the margin (1 %) is within tolerance however significant
    x = rng.normal(size=20)
    t = paired_change(x, 1.01 * x)
    assert t["p"] < 1e-100 and not t["regression"]
    # identical reruns: nothing changed (exact by construction: equal inputs give exact zero differences)
    assert paired_change(x, x.copy()) == {**paired_change(x, x.copy()), "L": 0.0, "p": 1.0, "regression": False}


def test_compare_paired_fields_and_run_mismatch():
    from approachsim.campaign.regress import baseline_doc, compare_paired

    rng = np.random.default_rng(12)
    errs = {c: {"lateral_ft": list(rng.normal(0, 5, 20)), "vertical_ft": list(rng.normal(0, 1, 20))}
            for c in ("CAT I", "CAT II", "CAT III")}
    per_run = {"runs": list(range(20)), **errs}
    doc = baseline_doc("p.toml", SUMMARY, runs=20, seed=7, mode="open", per_run=per_run)
    assert not any(d.regression for d in compare_paired(doc, SUMMARY, per_run))
    worse = copy.deepcopy(per_run)
    worse["CAT II"]["vertical_ft"] = [1.5 * v for v in worse["CAT II"]["vertical_ft"]]
    bad = [d for d in compare_paired(doc, SUMMARY, worse) if d.regression]
    assert len(bad) == 1 and bad[0].field.startswith("CAT II.vertical_1sigma_ft (20 paired runs, change +50.0%")
    one_failed = copy.deepcopy(per_run)
    one_failed["CAT I"]["lateral_ft"][3] = None  # left out of the pairs
    assert "19 paired runs" in compare_paired(doc, SUMMARY, one_failed)[0].field
    other = {**copy.deepcopy(per_run), "runs": list(range(1, 21))}
    assert [d.field for d in compare_paired(doc, SUMMARY, other)] == ["runs"]


def test_a_baseline_from_another_cpu_is_equal_within_the_floor_and_a_real_change_is_not():
    """The committed default baseline's per-run errors moved by another machine's rounding as measured (5.5e-5 of
    the 1-sigma per run; here up to 2e-4, random signs) pass as equal within the cross-machine floor and without a
    regression; the same baseline with one error source degraded 10 % (every CAT II vertical error x1.1) is a
    regression and not within the floor; a run that fails only in the rerun is never within the floor."""
    from approachsim.campaign.regress import CPU_FLOOR_REL, compare_paired, read_baseline, within_cpu_floor

    doc = read_baseline(PROFILES.parent / "baselines" / "default.json")
    rng = np.random.default_rng(23)
    moved = copy.deepcopy(doc["per_run"])
    for cat in ("CAT I", "CAT II", "CAT III"):
        for axis in ("lateral_ft", "vertical_ft"):
            v = np.array(moved[cat][axis], dtype=float)
            sigma = float(np.sqrt(np.mean(v**2)))
            moved[cat][axis] = list(v + rng.uniform(-2e-4, 2e-4, v.size) * sigma)
    assert 2e-4 < CPU_FLOOR_REL
    assert within_cpu_floor(doc, moved)
    assert not any(d.regression for d in compare_paired(doc, doc["summary"], moved))
    worse = copy.deepcopy(doc["per_run"])
    worse["CAT II"]["vertical_ft"] = [1.1 * v for v in worse["CAT II"]["vertical_ft"]]
    assert not within_cpu_floor(doc, worse)
    bad = [d for d in compare_paired(doc, doc["summary"], worse) if d.regression]
    assert len(bad) == 1 and bad[0].field.startswith("CAT II.vertical_1sigma_ft")
    failed = copy.deepcopy(doc["per_run"])
    failed["CAT I"]["lateral_ft"][0] = None
    assert not within_cpu_floor(doc, failed)
