"""Aircraft files (lookup order, strict parsing, profile overrides) and the truth file (round trip,
deterministic bytes, schema), without flying."""

from __future__ import annotations

import json
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.config import ProfileError
from approachsim.flight.aircraft import find_aircraft_file, load_aircraft, parse_aircraft
from approachsim.flight.truthfile import load_truth, save_truth
from approachsim.geo import RunwayFrame
from approachsim.profile import load_profile, parse_profile
from approachsim.records import Truth

ROOT = Path(__file__).resolve().parents[3]


def test_737_file_loads_in_si():
    ac = load_aircraft(load_profile(ROOT / "profiles" / "default.toml"))
    assert ac.jsbsim_model == "737"
    assert ac.approach_speed_mps == pytest.approx(140 * units.KT)
    assert ac.flaps_norm == 1.0 and ac.gear_down
    assert ac.gains.bank_limit_rad == pytest.approx(math.radians(15.0))
    assert ac.imu_location_struct_m[0] == pytest.approx(250 * 0.0254)


def test_profile_overrides_the_approach_speed():
    ac = load_aircraft(load_profile(ROOT / "profiles" / "gray-maybeck.toml"))
    assert ac.approach_speed_mps == pytest.approx(133 * units.KT)


def test_aircraft_beside_the_profile_directory_wins(tmp_path):
    (tmp_path / "profiles").mkdir()
    (tmp_path / "aircraft").mkdir()
    data = tomllib.loads((ROOT / "aircraft" / "737.toml").read_text())
    text = (ROOT / "aircraft" / "737.toml").read_text()
    text = text.replace("approach_speed_kt = 140.0", "approach_speed_kt = 150.0")
    (tmp_path / "aircraft" / "737.toml").write_text(text)
    shutil.copy(ROOT / "profiles" / "default.toml", tmp_path / "profiles" / "default.toml")
    p = load_profile(tmp_path / "profiles" / "default.toml")
    assert find_aircraft_file("737", p) == tmp_path / "aircraft" / "737.toml"
    assert load_aircraft(p).approach_speed_mps == pytest.approx(150 * units.KT)
    assert data["approach"]["approach_speed_kt"] == 140.0


def test_unknown_aircraft_names_the_field():
    d = tomllib.loads((ROOT / "profiles" / "default.toml").read_text())
    d["aircraft"]["name"] = "concorde-x"
    with pytest.raises(ProfileError, match=r"aircraft\.name"):
        load_aircraft(parse_profile(d, source=ROOT / "profiles" / "default.toml"))


def test_aircraft_file_is_strict():
    data = tomllib.loads((ROOT / "aircraft" / "737.toml").read_text())
    data["autopilot"]["k_thetta"] = 1.0
    with pytest.raises(ProfileError, match=r"autopilot\.k_thetta: unknown key"):
        parse_aircraft(data, Path("x.toml"))
    data = tomllib.loads((ROOT / "aircraft" / "737.toml").read_text())
    data["autopilot"]["k_q"] = -1.0
    with pytest.raises(ProfileError, match=r"autopilot\.k_q"):
        parse_aircraft(data, Path("x.toml"))


def _fake_truth(n: int = 50) -> Truth:
    rng = np.random.default_rng(3)
    shapes = {"r_ecef": 3, "v_ned": 3, "q_nb": 4, "euler_rad": 3, "w_ib_body": 3, "f_body": 3, "r_rwy": 3,
              "controls": 4}
    kw = {}
    for name in Truth.__dataclass_fields__:
        if name == "runway":
            continue
        kw[name] = rng.normal(size=(n, shapes[name]) if name in shapes else (n,))
    kw["t_s"] = np.arange(n) / 120.0
    return Truth(**kw, runway=RunwayFrame(0.6, -2.1, 4.0, 5.2))


def test_truth_file_round_trip_and_bytes(tmp_path):
    t = _fake_truth()
    a = save_truth(tmp_path / "a.npz", t, meta={"seed": 1})
    b = save_truth(tmp_path / "b.npz", t, meta={"seed": 1})
    assert a.read_bytes() == b.read_bytes()
    back = load_truth(a)
    for name, arr in t.arrays().items():
        np.testing.assert_array_equal(getattr(back, name), arr)
    assert back.runway == t.runway
    schema = json.loads(a.with_suffix(".json").read_text())
    assert schema["meta"] == {"seed": 1} and schema["samples"] == 50
    assert schema["arrays"]["f_body"]["unit"] == "m/s^2"
    assert "specific force" in schema["arrays"]["f_body"]["description"]
