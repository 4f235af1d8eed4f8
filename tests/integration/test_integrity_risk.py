"""`approachsim integrity-risk`: bad input is one line and exit 2; a small study on the default profile (one flown
approach, a handful of navigations) writes integrity_risk.json with every category's P(HMI), bounds, allocation and
verdict, and the run count it took."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from approachsim.cli import main

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = str(ROOT / "tests" / "data" / "default-py.toml")


@pytest.mark.parametrize("argv, needle", [
    (["--modes", "gremlin"], "--modes: unknown fault mode"),
    (["--modes", "pseudolite-step"], "no pseudolite"),
    (["--samples", "3"], "--samples"),
    (["--samples", "20", "--max-calls", "10"], "--max-calls"),
    (["--fault-free-runs", "1"], "--fault-free-runs"),
    (["--require", "CAT 4"], "--require"),
])
def test_bad_input_is_one_line_and_status_2(argv, needle, capsys, tmp_path):
    assert main(["integrity-risk", DEFAULT, "--out", str(tmp_path / "o"), *argv]) == 2
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err


@pytest.mark.slow
def test_small_study_writes_the_contract(tmp_path, capsys):
    out = tmp_path / "risk"
    status = main(["integrity-risk", DEFAULT, "--modes", "baro-step", "--samples", "10", "--max-calls", "10",
                   "--fault-free-runs", "2", "--truths", "1", "--workers", "1", "--seed", "3", "--out", str(out),
                   "--require", "CAT III"])
    assert status == 1  # 10 samples cannot show 1e-9
    r = json.loads((out / "integrity_risk.json").read_text())
    assert r["schema"] == "approachsim.integrity_risk/2" and r["samples"] == 12
    assert r["modes"]["baro-step"]["samples"] == 10 and r["fault_free"]["runs"] == 2
    for cat in ("CAT I", "CAT II", "CAT III"):
        c = r["categories"][cat]
        assert c["verdict"] in ("shown", "not shown", "exceeds")
        assert c["p_hmi_upper"] >= c["p_hmi"] >= c["p_hmi_lower"] >= 0.0
        assert c["allocation"] in (2e-7, 1e-9)
        assert c["p_hmi_upper"] >= c["p_hmi_average_upper"]
        assert c["verdict_average"] in ("shown", "not shown", "exceeds")
        sp = r["modes"]["baro-step"]["categories"][cat]["specific"]
        # two magnitude decades x (three thirds of the hour before the window + three of the window)
        assert len(sp["bins"]) == 12 and sum(b["first_step"]["samples"] for b in sp["bins"]) == 10
        assert c["unsourced_terms"] == ["baro-step"] and c["verdict"] != "shown"  # an assumed prior: not shown
        assert c["terms"]["baro-step"]["specific_upper"] >= 1e-5 * sp["worst_upper"]
    assert r["categories"]["CAT III"]["verdict"] != "shown"
    assert "CAT III" in capsys.readouterr().out
