"""Trade-study files: expansion into variants, one-line errors for every bad field, the comparison."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from approachsim import units
from approachsim.campaign.pipeline import PipelineSpec
from approachsim.campaign.result import RunResult
from approachsim.campaign.study import comparison_table, load_study, run_study
from approachsim.cli import main
from approachsim.config import ProfileError
from approachsim.profile import load_profile
from approachsim.seeding import stream

ROOT = Path(__file__).resolve().parents[3]
BASE = ROOT / "tests" / "data" / "default-py.toml"


def _write(tmp_path: Path, body: str) -> Path:
    p = tmp_path / "study.toml"
    p.write_text(f'profile = "{BASE}"\n' + body)
    return p


def test_axes_and_variants_expand_and_apply(tmp_path):
    s = load_study(_write(tmp_path, """
name = "wind x turbulence"
runs = 4
seed = 3
mode = "open"
[axes]
"environment.wind_speed_kt" = [0, 15]
environment.turbulence = ["none", "moderate"]
[[variant]]
name = "calm"
set = { "environment.wind_speed_kt" = 0, environment = { turbulence = "none" } }
"""))
    assert (s.runs, s.seed, s.mode) == (4, 3, "open")
    assert len(s.variants) == 5
    names = [v.name for v in s.variants]
    assert names[:4] == ["turbulence=none,wind_speed_kt=0", "turbulence=none,wind_speed_kt=15",
                         "turbulence=moderate,wind_speed_kt=0", "turbulence=moderate,wind_speed_kt=15"]
    v = s.variants[3]
    assert v.profile.environment.turbulence == "moderate"
    assert v.profile.environment.wind_speed_mps == pytest.approx(15 * units.KT)
    assert s.variants[4].profile.environment.turbulence == "none" and s.variants[4].name == "calm"
    assert v.profile.runway == s.variants[0].profile.runway  # the base is untouched elsewhere


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ("runs = 0\n[axes]\n'environment.wind_speed_kt' = [0]\n", "runs"),
        ("seed = -2\n[axes]\n'environment.wind_speed_kt' = [0]\n", "seed"),
        ("mode = 'both'\n[axes]\n'environment.wind_speed_kt' = [0]\n", "mode"),
        ("name = 3\n[axes]\n'environment.wind_speed_kt' = [0]\n", "name"),
        ("colour = 'red'\n[axes]\n'environment.wind_speed_kt' = [0]\n", "colour: unknown key"),
        ("axes = 5\n", "axes"),
        ("[axes]\n'environment.wind_speed_kt' = 5\n", "axes.environment.wind_speed_kt"),
        ("[axes]\n'environment.wind_speed_kt' = []\n", "axes.environment.wind_speed_kt"),
        ("[axes]\n'environment.wind_speed_kt' = [0, 99]\n", "environment.wind_speed_kt: must be in"),
        ("[axes]\n'environment.turbulence' = ['hurricane']\n", "environment.turbulence"),
        ("[axes]\n'environment.gusts' = [1]\n", "environment.gusts: unknown key"),
        ("[axes]\n'name.x' = [1]\n", "'name' is not a table"),
        ("[[variant]]\nname = 'a'\n", "variant[0].set: missing"),
        ("[[variant]]\nname = 'a'\nset = {}\n", "variant[0].set"),
        ("[[variant]]\nname = 'a'\nset = {'rates.imu_hz' = 'fast'}\nextra = 1\n", "variant[0].extra"),
        ("[[variant]]\nname = 'a'\nset = {'rates.imu_hz' = 'fast'}\n", "rates.imu_hz"),
        ("[[variant]]\nname = 'a'\nset = {'rates.imu_hz' = 100}\n[[variant]]\nname = 'a'\n"
         "set = {'rates.imu_hz' = 200}\n", "two variants are named 'a'"),
        ("", "needs [axes] or at least one [[variant]]"),
    ],
)
def test_every_bad_study_field_is_one_line_exit_2(tmp_path, capsys, body, needle):
    p = _write(tmp_path, body)
    with pytest.raises(ProfileError, match=None) as e:
        load_study(p)
    assert needle in str(e.value), str(e.value)
    assert main(["study", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err


def test_bad_study_file_and_options(tmp_path, capsys):
    assert main(["study", str(tmp_path / "none.toml"), "--out", str(tmp_path)]) == 2
    (tmp_path / "x.toml").write_text("profile = 'nope.toml'\n")
    assert main(["study", str(tmp_path / "x.toml"), "--out", str(tmp_path)]) == 2
    (tmp_path / "y.toml").write_text("profile = [\n")
    assert main(["study", str(tmp_path / "y.toml"), "--out", str(tmp_path)]) == 2
    good = _write(tmp_path, "[axes]\n'environment.wind_speed_kt' = [0]\n")
    assert main(["study", str(good), "--out", str(tmp_path / "o"), "--workers", "0"]) == 2
    assert main(["study", str(good), "--out", str(tmp_path / "o"), "--scheduler", "no address"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 5
    assert "none.toml" in err[0] and "nope.toml" in err[1] and "TOML" in err[2]
    assert "--workers" in err[3] and "--scheduler" in err[4]


def _wind_error_group(profile, seed, runs):
    """Synthetic scored runs whose lateral error grows with the profile's wind (for the comparison only)."""
    out = []
    for i in runs:
        rng = stream(seed, i, "synthetic")
        sig = 0.5 + profile.environment.wind_speed_mps
        sc = {}
        for key in ("cat1", "cat2", "cat3"):
            sc[f"{key}_lateral_m"] = float(rng.normal(0.0, sig))
            sc[f"{key}_vertical_m"] = float(rng.normal(0.0, 0.1))
        out.append(RunResult(run=i, ok=True, scalars=sc))
    return out


def test_run_study_writes_the_comparison(tmp_path):
    # 60 runs: the default verdict (faa+icao) bounds the 95th percentile from 59 runs
    s = load_study(_write(tmp_path, "runs = 60\n[axes]\n'environment.wind_speed_kt' = [0, 20]\n"))
    rows = run_study(s, tmp_path / "o", workers=1, progress=False,
                     spec_fn=lambda prof, mode: PipelineSpec(_wind_error_group, 10, False))
    assert [r["variant"] for r in rows] == ["wind_speed_kt=0", "wind_speed_kt=20"]
    calm, windy = rows
    assert calm["CATI_lateral_1sigma_ft"] < windy["CATI_lateral_1sigma_ft"]
    # 20 kt -> sigma 10.8 m = 35 ft > 28.1 ft: CAT I not met; calm 0.5 m = 1.6 ft lateral, 0.33 ft vertical: CAT III
    assert (calm["best_category"], windy["best_category"]) == ("CAT III", "none")
    doc = json.loads((tmp_path / "o" / "study.json").read_text())
    assert doc["variants"][1]["set"] == {"environment.wind_speed_kt": 20}
    assert (tmp_path / "o" / "study.csv").read_text().count("\n") == 3
    assert json.loads((tmp_path / "o" / "wind_speed_kt=20" / "summary.json").read_text())["runs"] == 60
    table = comparison_table(rows)
    assert table.splitlines()[1].startswith("wind_speed_kt=0") and "CAT III" in table
    assert math.isfinite(windy["CATIII_vertical_1sigma_ft"])


def test_the_example_study_file_is_valid():
    s = load_study(ROOT / "studies" / "ins-grade-x-aids.toml")
    assert [v.profile.sensors.imu.grade for v in s.variants] == ["nav-0.4", "nav-2.0", "nav-4.0", "nav-2.0"]
    assert [v.profile.sensors.pseudolite is not None for v in s.variants] == [False, False, False, True]


def test_every_shipped_study_file_is_valid():
    """Every file in studies/ loads (each variant's profile validated); the realism study's last variant is the
    default profile itself and its first the earlier error models."""
    for p in sorted((ROOT / "studies").glob("*.toml")):
        assert load_study(p).variants, p
    s = load_study(ROOT / "studies" / "realism-defaults.toml")
    assert [v.name[0] for v in s.variants] == list("ABCDEFGH")
    base = load_profile(ROOT / "tests" / "data" / "default-py.toml")
    assert s.variants[-1].profile.sensors == base.sensors and s.variants[-1].profile.nav == base.nav
    assert s.variants[0].profile.nav.baro_loop == "none" and s.variants[0].profile.sensors.gnss.epoch == "fixed"
