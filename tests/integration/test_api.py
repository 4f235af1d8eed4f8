"""The Python API (approachsim.api): docs/api.md's examples and the worked trade study run, a variant built in code
gives the same summary.json as the same profile written as TOML and run by the command line, and importing the
package stays light."""

from __future__ import annotations

import doctest
import json
import runpy
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import approachsim as asim
from approachsim.cli import main

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow


def test_import_is_light_and_the_api_is_loaded_on_first_use():
    code = ("import sys, approachsim; light = 'numpy' not in sys.modules and 'approachsim.api' not in sys.modules; "
            "f = approachsim.load_profile; print(light, 'approachsim.api' in sys.modules, f.__module__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}).stdout.split()
    assert out == ["True", "True", "approachsim.api"]
    import approachsim.api

    assert set(asim.API) <= set(dir(asim)) and set(asim.API) == set(approachsim.api.__all__)
    with pytest.raises(AttributeError):
        asim.no_such_name  # noqa: B018


def test_load_profile_by_name_or_file_and_variants_are_validated(tmp_path):
    by_name = asim.load_profile("default")
    by_file = asim.load_profile(ROOT / "profiles" / "default.toml")
    assert by_name.profile == by_file.profile and by_name.name == "default"
    with pytest.raises(asim.ProfileError, match=r"^profile: no such file 'nope', nor a shipped profile \(default, "):
        asim.load_profile("nope")
    v = by_name.with_settings({"environment.wind_speed_kt": 15.0, "run.mode": "open"})
    assert v.name == "default[wind_speed_kt=15,mode=open]"
    assert v.profile.environment.wind_speed_mps == pytest.approx(15.0 * 1852.0 / 3600.0, rel=1e-12)
    assert v.settings == (("environment.wind_speed_kt", 15.0), ("run.mode", "open"))
    assert by_name.get("environment.wind_speed_kt") == 5.0 and v.get("environment.wind_speed_kt") == 15.0
    # a variant of a variant keeps both settings; the base is untouched
    w = v.with_settings({"environment.turbulence": "none"}, name="calm")
    assert (w.name, w.profile.environment.turbulence, w.profile.environment.wind_speed_mps) == (
        "calm", "none", v.profile.environment.wind_speed_mps)
    assert by_name.profile.environment.turbulence == "light"
    for settings, needle in (
        ({"environment.wind_speed_kt": 99.0}, r"environment\.wind_speed_kt: must be in \[0, 60\] \(kt\), got 99"),
        ({"environment.no_such_key": 1}, r"environment\.no_such_key"),
        ({"runway.elevation_ft.x": 1}, r"'elevation_ft' is not a table"),
    ):
        with pytest.raises(asim.ProfileError, match=needle):
            by_name.with_settings(settings)


def test_a_variant_in_code_gives_the_summary_of_the_same_toml(tmp_path, capsys):
    """The API and the command line on the same profile: one built in code, one written as TOML (an edited copy of the
    shipped default), both 3 open-loop runs: summary.json byte for byte, details.json but its wall time."""
    text = (ROOT / "profiles" / "default.toml").read_text()
    text = text.replace('name = "default"', 'name = "gusty"', 1).replace("wind_speed_kt = 5.0", "wind_speed_kt = 12.0")
    text = text.replace('grade = "nav-2.0"', 'grade = "nav-0.4"')
    toml = tmp_path / "gusty.toml"
    toml.write_text(text + "\n[evaluation]\nintegrity = false\nflight_group = 2\n")
    assert main(["evaluate", str(toml), "--runs", "3", "--seed", "5", "--mode", "open", "--workers", "1",
                 "--out", str(tmp_path / "cli"), "--no-report"]) == 0
    variant = asim.load_profile("default").with_settings(
        {"environment.wind_speed_kt": 12.0, "sensors.imu.grade": "nav-0.4", "evaluation.integrity": False,
         "evaluation.flight_group": 2}, name="gusty")
    ev = asim.evaluate_profile(variant, runs=3, seed=5, mode="open", workers=1, out=tmp_path / "api", progress=False)
    cli_summary = (tmp_path / "cli" / "summary.json").read_bytes()
    assert (tmp_path / "api" / "summary.json").read_bytes() == cli_summary
    assert json.loads(cli_summary) == ev.summary and ev.summary["runs"] == 3 and ev.summary["profile"] == "gusty"
    assert ev.summary["decision_heights"]["CAT I"]["lateral_1sigma_ft"] > 0.0
    details = [json.loads((tmp_path / d / "details.json").read_text()) for d in ("cli", "api")]
    for d in details:
        d.pop("wall_s")
    assert details[0] == details[1]
    # the DataFrames are the Parquet files' tables
    pd.testing.assert_frame_equal(ev.runs, pd.read_parquet(tmp_path / "cli" / "runs.parquet"))
    pd.testing.assert_frame_equal(ev.heights, pd.read_parquet(tmp_path / "cli" / "heights.parquet"))
    assert list(ev.runs["run"]) == [0, 1, 2] and ev.heights.shape[0] == 3 * 101
    # in memory: the same numbers, nothing written
    mem = asim.evaluate_profile(variant, runs=3, seed=5, mode="open", workers=1, progress=False)
    assert mem.summary == ev.summary and mem.out_dir is None
    assert mem.verdict_rows()[0]["lateral_1sigma_ft"] == ev.summary["decision_heights"]["CAT I"]["lateral_1sigma_ft"]


def test_docs_api_examples_run():
    """docs/api.md's examples, as written there (Python's doctest)."""
    res = doctest.testfile(str(ROOT / "docs" / "api.md"), module_relative=False,
                           optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert res.attempted >= 20 and res.failed == 0, res


def test_worked_trade_study(capsys):
    """docs/examples/trade_study.py with 2 runs per variant: 4 variants on the same random numbers; SBAS L1
    corrections take the lateral error at the decision heights from stand-alone L1 C/A's (its Klobuchar ionosphere:
    4.6-4.9 ft at 2 runs since the filter carries the ionospheric field's common part and gradient as states, ~9 ft
    before; studies/gnss-services/RESULTS.md) down to under 3 ft with either INS (1.0-1.2 ft)."""
    ns = runpy.run_path(str(ROOT / "docs" / "examples" / "trade_study.py"))
    st = ns["main"](runs=2, seed=1, workers=1)
    assert [r["variant"] for r in st.rows] == ["nav-0.4+stand-alone", "nav-0.4+sbas", "nav-4.0+stand-alone",
                                                "nav-4.0+sbas"]
    t = st.table
    for grade in ("nav-0.4", "nav-4.0"):
        for cat in ("CATI", "CATII", "CATIII"):
            alone, sbas = (t.loc[f"{grade}+{s}", f"{cat}_lateral_1sigma_ft"] for s in ("stand-alone", "sbas"))
            assert sbas < 3.0 < alone, (grade, cat, sbas, alone)
    assert all(ev.summary["runs"] == 2 and ev.failed_runs == 0 for ev in st.evaluations.values())
    assert "nav-4.0+sbas" in capsys.readouterr().out


def test_the_study_command_and_the_api_give_the_same_comparison(tmp_path, capsys):
    """`approachsim study FILE` (a thin layer over api.study_file) and api.study with the same variants in code: the
    same comparison rows, every number equal (2 variants x 2 open-loop runs)."""
    f = tmp_path / "wind.toml"
    f.write_text('profile = "default"\nruns = 2\nseed = 4\nmode = "open"\n'
                 '[axes]\n"environment.wind_speed_kt" = [0, 20]\n'
                 '[[variant]]\nname = "acc"\nset = { "evaluation.integrity" = false }\n')
    assert main(["study", str(f), "--out", str(tmp_path / "cli"), "--workers", "1"]) == 0
    rows = json.loads((tmp_path / "cli" / "study.json").read_text())["comparison"]
    st = asim.study("default", {"acc": {"evaluation.integrity": False}},
                    axes={"environment.wind_speed_kt": [0, 20]}, runs=2, seed=4, mode="open", workers=1,
                    progress=False)
    assert [r["variant"] for r in rows] == ["wind_speed_kt=0", "wind_speed_kt=20", "acc"] and st.rows == rows
    assert (tmp_path / "cli" / "study.png").is_file() and (tmp_path / "cli" / "acc" / "summary.json").is_file()
    assert st.evaluations["acc"].profile.settings == (("evaluation.integrity", False),)
    assert st.rows[0]["CATI_lateral_1sigma_ft"] != st.rows[1]["CATI_lateral_1sigma_ft"]  # the wind reaches the runs
