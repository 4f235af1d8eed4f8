"""Profile loading: the shipped profiles load and convert to SI; malformed input raises ProfileError naming
the field (the CLI path is tested in tests/integration/test_cli_bad_input.py)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.config import ProfileError
from approachsim.profile import load_profile, parse_profile

ROOT = Path(__file__).resolve().parents[2]
PROFILES = sorted((ROOT / "profiles").glob("*.toml"))


def _default() -> dict:
    return tomllib.loads((ROOT / "profiles" / "default.toml").read_text())


def test_the_issue_profiles_are_shipped():
    names = {p.stem for p in PROFILES}
    assert {"default", "gray-maybeck", "hot-high-crosswind"} <= names


@pytest.mark.parametrize("path", PROFILES, ids=[p.stem for p in PROFILES])
def test_every_shipped_profile_loads(path):
    p = load_profile(path)
    assert p.source == path.resolve()
    assert 0 < p.runway.glidepath_rad < math.radians(10)


def test_default_profile_in_si():
    p = load_profile(ROOT / "profiles" / "default.toml")
    assert p.runway.glidepath_rad == pytest.approx(math.radians(3.0))
    assert p.runway.start_distance_m == pytest.approx(10 * 1852.0)
    assert p.runway.tch_m == pytest.approx(50 * 0.3048)
    assert p.environment.wind_speed_mps == pytest.approx(5 * 1852 / 3600)
    assert p.environment.turbulence == "light"
    assert p.environment.sea_level_pa == pytest.approx(101325.0)
    assert p.rates.imu_hz >= 100.0  # the issue: truth at >= 100 Hz


def test_hot_high_crosswind_is_what_the_issue_asks():
    p = load_profile(ROOT / "profiles" / "hot-high-crosswind.toml")
    assert p.runway.elevation_m >= 5000 * units.FT
    assert p.environment.isa_dev_k == pytest.approx(20.0)
    cross = p.environment.wind_speed_mps * abs(math.sin(p.environment.wind_from_rad - p.runway.heading_rad))
    assert cross == pytest.approx(15 * units.KT, rel=1e-6)
    assert p.environment.turbulence == "moderate"
    assert p.runway.glidepath_rad == pytest.approx(math.radians(3.2))


def test_gray_maybeck_speed_and_glideslope():
    p = load_profile(ROOT / "profiles" / "gray-maybeck.toml")
    assert p.aircraft.approach_speed_mps == pytest.approx(133 * units.KT)
    assert p.runway.glidepath_rad == pytest.approx(math.radians(3.0))


def test_glidepath_geometry():
    p = load_profile(ROOT / "profiles" / "default.toml")
    rw = p.runway
    # the straight cone from the GPI (approachsim.glidepath), in the height above the threshold's ellipsoid
    # height: TCH - x tan 3 plus the Earth's drop below the GPI's horizontal plane, (x - x_gpi)^2 / (2 R)
    x_gpi = rw.tch_m / math.tan(math.radians(3))
    assert rw.glidepath_height_m(0.0) == pytest.approx(rw.tch_m + x_gpi**2 / (2 * 6.371e6), abs=1e-4)
    # 1 nmi before the threshold on a 3 deg path: TCH + 1852 tan 3 = 15.24 + 97.06 m, + 0.36 m of drop
    want = 15.24 + 1852 * math.tan(math.radians(3)) + (1852 + x_gpi) ** 2 / (2 * 6.371e6)
    assert rw.glidepath_height_m(-1852.0) == pytest.approx(want, abs=2e-3)  # R: 6371 km against the radii here


def test_terrain_default_flat_and_table():
    p = load_profile(ROOT / "profiles" / "default.toml")
    assert p.terrain.height_at(-5000.0) == pytest.approx(p.runway.elevation_m)
    d = _default()
    d["terrain"] = {"distance_nmi": [10.0, 2.0, 0.0], "height_ft": [500.0, 100.0, 13.0]}
    t = parse_profile(d).terrain
    assert t.height_at(-6 * 1852.0) == pytest.approx(300 * 0.3048)
    assert t.height_at(-20 * 1852.0) == pytest.approx(500 * 0.3048)  # held beyond the ends
    np.testing.assert_allclose(t.height_at(np.array([0.0, 100.0])), 13 * 0.3048)  # rtol 1e-7 of a held end value


@pytest.mark.parametrize(
    ("section", "key", "value", "field"),
    [
        ("runway", "glidepath_deg", 0.0, "runway.glidepath_deg"),
        ("runway", "glidepath_deg", 15.0, "runway.glidepath_deg"),
        ("runway", "start_distance_nmi", 30.5, "runway.start_distance_nmi"),
        ("runway", "heading_true_deg", "north", "runway.heading_true_deg"),
        ("aircraft", "approach_speed_kt", -1.0, "aircraft.approach_speed_kt"),
        ("aircraft", "gear_down", "yes", "aircraft.gear_down"),
        ("environment", "turbulence", "extreme", "environment.turbulence"),
        ("environment", "wind_from_deg", 400.0, "environment.wind_from_deg"),
        ("rates", "imu_hz", 5000.0, "rates.imu_hz"),
        ("run", "seed", -1, "run.seed"),
        ("runway", "surprise", 1, "runway.surprise"),
    ],
)
def test_bad_fields_name_themselves(section, key, value, field):
    d = _default()
    d[section][key] = value
    with pytest.raises(ProfileError, match=field.replace(".", r"\.")):
        parse_profile(d)


def test_missing_required_field_and_bad_files(tmp_path):
    d = _default()
    del d["runway"]["elevation_ft"]
    with pytest.raises(ProfileError, match=r"runway\.elevation_ft: missing"):
        parse_profile(d)
    with pytest.raises(ProfileError, match="no such file"):
        load_profile(tmp_path / "absent.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[runway\n")
    with pytest.raises(ProfileError, match="not valid TOML"):
        load_profile(bad)
