"""Bad input through the CLI: every malformed profile gives exit status 2 and exactly one line on stderr that
names the offending field; never a traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from approachsim.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOOD = (ROOT / "profiles" / "default.toml").read_text()


def _edit(old: str, new: str) -> str:
    assert old in GOOD, old
    return GOOD.replace(old, new)


CASES = [
    # (id, profile text, text the one-line message must contain)
    ("glidepath-zero", _edit("glidepath_deg = 3.0", "glidepath_deg = 0.0"), "runway.glidepath_deg"),
    ("glidepath-15", _edit("glidepath_deg = 3.0", "glidepath_deg = 15.0"), "runway.glidepath_deg"),
    ("start-beyond-30nmi", _edit("start_distance_nmi = 10.0", "start_distance_nmi = 31.0"),
     "runway.start_distance_nmi"),
    ("negative-speed", _edit('name = "737"', 'name = "737"\napproach_speed_kt = -140.0'), "aircraft.approach_speed_kt"),
    ("speed-string", _edit('name = "737"', 'name = "737"\napproach_speed_kt = "fast"'), "aircraft.approach_speed_kt"),
    ("latitude-string", _edit("threshold_lat_deg = 37.6117", 'threshold_lat_deg = "37N"'), "runway.threshold_lat_deg"),
    ("latitude-missing", _edit("threshold_lat_deg = 37.6117", ""), "runway.threshold_lat_deg"),
    ("runway-missing", GOOD.split("[runway]")[0] + "[aircraft]" + GOOD.split("[aircraft]")[1], "runway"),
    ("unknown-key", _edit("tch_ft = 50.0", "tch_ft = 50.0\ntch_m = 15.0"), "runway.tch_m"),
    ("unknown-section", GOOD + "\n[bogus_section]\nimu = 1\n", "bogus_section"),
    ("turbulence-choice", _edit('turbulence = "light"', 'turbulence = "heavy"'), "environment.turbulence"),
    ("wind-negative", _edit("wind_speed_kt = 5.0", "wind_speed_kt = -5.0"), "environment.wind_speed_kt"),
    ("isa-bool", _edit("isa_dev_C = 0.0", "isa_dev_C = true"), "environment.isa_dev_C"),
    ("qnh-out-of-range", _edit("qnh_hPa = 1013.25", "qnh_hPa = 500.0"), "environment.qnh_hPa"),
    ("imu-rate-low", _edit("imu_hz = 120.0", "imu_hz = 10.0"), "rates.imu_hz"),
    ("runs-float", _edit("runs = 20", "runs = 2.5"), "run.runs"),
    ("mode-choice", _edit('mode = "closed"', 'mode = "half"'), "run.mode"),
    ("aircraft-unknown", _edit('name = "737"', 'name = "a380"'), "aircraft.name"),
    ("aircraft-path", _edit('name = "737"', 'name = "../737"'), "aircraft.name"),
    ("terrain-mismatch", GOOD + "\n[terrain]\ndistance_nmi = [10.0, 5.0, 0.0]\nheight_ft = [100.0, 13.0]\n",
     "terrain.height_ft"),
    ("flaps-above-one", _edit('name = "737"', 'name = "737"\nflaps_norm = 1.5'), "aircraft.flaps_norm"),
    ("untrimmable-speed", _edit('name = "737"', 'name = "737"\napproach_speed_kt = 90.0'),
     "aircraft.approach_speed_kt"),
    ("not-toml", "this is [not toml\n", "not valid TOML"),
    ("not-utf8", None, "not a UTF-8"),
]


def _check(capsys_err: str, must: str) -> None:
    lines = [ln for ln in capsys_err.splitlines() if ln.strip()]
    assert len(lines) == 1, capsys_err
    assert lines[0].startswith("approachsim: error: ")
    assert must in lines[0], lines[0]
    assert "Traceback" not in capsys_err


@pytest.mark.parametrize(("case", "text", "must"), CASES, ids=[c[0] for c in CASES])
def test_malformed_profile_exits_2_with_one_line(tmp_path, capsys, case, text, must):
    path = tmp_path / "bad.toml"
    if text is None:
        path.write_bytes(b"\xff\xfe\x00 name = 1\n")
    else:
        path.write_text(text)
    assert main(["fly", str(path), "--out", str(tmp_path / "out")]) == 2
    _check(capsys.readouterr().err, must)
    assert not (tmp_path / "out").exists()  # nothing flown, nothing written


def test_missing_file_exits_2(tmp_path, capsys):
    assert main(["fly", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "out")]) == 2
    _check(capsys.readouterr().err, "no such file")


def test_bad_seed_option_exits_2(tmp_path, capsys):
    assert main(["fly", str(ROOT / "profiles" / "default.toml"), "--out", str(tmp_path), "--seed", "-3"]) == 2
    _check(capsys.readouterr().err, "--seed")


def test_through_the_console_entry_point(tmp_path):
    """The same through a separate interpreter: status 2, one line, no traceback."""
    path = tmp_path / "bad.toml"
    path.write_text(_edit("glidepath_deg = 3.0", "glidepath_deg = 0.0"))
    p = subprocess.run([sys.executable, "-m", "approachsim", "fly", str(path), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True)
    assert p.returncode == 2
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "runway.glidepath_deg" in lines[0], p.stderr
