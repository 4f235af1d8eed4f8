"""Shipped profiles and aircraft lookup (approachsim.resources) and the `profiles` command, without flying."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from approachsim import resources, units
from approachsim.cli import main
from approachsim.config import ProfileError
from approachsim.flight.aircraft import load_aircraft
from approachsim.profile import load_profile

ROOT = Path(__file__).resolve().parents[2]


def _faster_737(dir_: Path, speed_kt: float) -> Path:
    dir_.mkdir(parents=True, exist_ok=True)
    text = (resources.AIRCRAFT_DIR / "737.toml").read_text().replace("approach_speed_kt = 140.0",
                                                                      f"approach_speed_kt = {speed_kt}")
    (dir_ / "737.toml").write_text(text)
    return dir_ / "737.toml"


def test_shipped_profiles_are_the_repository_profiles():
    names = [s.name for s in resources.shipped_profiles()]
    assert names == sorted(p.stem for p in (ROOT / "profiles").glob("*.toml"))
    assert "default" in names
    for s in resources.shipped_profiles():
        load_profile(s.path)  # every shipped profile is valid


def test_a_profile_alone_in_a_directory_flies_the_packaged_aircraft(tmp_path, monkeypatch):
    monkeypatch.delenv(resources.AIRCRAFT_PATH_ENV, raising=False)
    (tmp_path / "default.toml").write_text((resources.PROFILES_DIR / "default.toml").read_text())
    ac = load_aircraft(load_profile(tmp_path / "default.toml"))
    assert ac.source == resources.AIRCRAFT_DIR / "737.toml"
    assert ac.approach_speed_mps == pytest.approx(140.0 * units.KT)


@pytest.mark.parametrize("where", ["aircraft", "../aircraft"])
def test_aircraft_beside_the_profile_wins(tmp_path, monkeypatch, where):
    monkeypatch.delenv(resources.AIRCRAFT_PATH_ENV, raising=False)
    prof_dir = tmp_path / "p"
    prof_dir.mkdir()
    (prof_dir / "default.toml").write_text((resources.PROFILES_DIR / "default.toml").read_text())
    own = _faster_737((prof_dir / where).resolve(), 150.0)
    ac = load_aircraft(load_profile(prof_dir / "default.toml"))
    assert ac.source == own
    assert ac.approach_speed_mps == pytest.approx(150.0 * units.KT)


def test_environment_variable_directory_comes_before_the_package(tmp_path, monkeypatch):
    own = _faster_737(tmp_path / "mine", 145.0)
    monkeypatch.setenv(resources.AIRCRAFT_PATH_ENV, str(tmp_path / "empty") + ":" + str(tmp_path / "mine"))
    (tmp_path / "w").mkdir()
    (tmp_path / "w" / "default.toml").write_text((resources.PROFILES_DIR / "default.toml").read_text())
    ac = load_aircraft(load_profile(tmp_path / "w" / "default.toml"))
    assert ac.source == own
    assert ac.approach_speed_mps == pytest.approx(145.0 * units.KT)


def test_missing_aircraft_names_the_field_and_the_places_searched(tmp_path, monkeypatch):
    monkeypatch.delenv(resources.AIRCRAFT_PATH_ENV, raising=False)
    with pytest.raises(ProfileError, match=r"^aircraft\.name: no aircraft file a380\.toml in .*shipped: 737"):
        resources.find_aircraft_file("a380", tmp_path / "x.toml")


def test_profiles_list_and_init(tmp_path, capsys):
    assert main(["profiles"]) == 0
    out = capsys.readouterr().out
    assert "default" in out and "gray-maybeck" in out
    assert main(["profiles", "init", "hot-high-crosswind", str(tmp_path / "d")]) == 0
    copied = tmp_path / "d" / "hot-high-crosswind.toml"
    shipped = (ROOT / "profiles" / "hot-high-crosswind.toml").read_text()
    assert tomllib.loads(copied.read_text()) == tomllib.loads(shipped)
    capsys.readouterr()
    assert main(["profiles", "init", "hot-high-crosswind", str(tmp_path / "d")]) == 2  # no silent overwrite
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--force" in err[0]
    assert main(["profiles", "init", "hot-high-crosswind", str(tmp_path / "d"), "--force"]) == 0
    assert main(["profiles", "init", "nonesuch", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "NAME: no shipped profile 'nonesuch'" in err[-1]
