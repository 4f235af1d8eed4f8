"""Bad input through the CLI: every malformed profile gives exit status 2 and exactly one line on stderr that
names the offending field; never a traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from approachsim.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOOD = (ROOT / "tests" / "data" / "default-py.toml").read_text()


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
    assert main(["fly", str(ROOT / "tests" / "data" / "default-py.toml"), "--out", str(tmp_path), "--seed", "-3"]) == 2
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


def _fault(body: str, extra: str = "") -> str:
    return GOOD + extra + "\n[[faults]]\n" + body + "\n"


FAULT_CASES = [
    # (id, profile text, text the one-line message must contain)
    ("imu-outage", _fault('sensor = "imu"\nkind = "outage"\nstart_s = 100.0\nend_s = 120.0'), "faults[0].kind"),
    ("imu-channel-5", _fault('sensor = "imu"\nkind = "step"\nchannel = 5\nmagnitude = 0.01\nstart_s = 100.0'),
     "faults[0].channel"),
    ("gnss-prn-77", _fault('sensor = "gnss"\nkind = "step"\nchannel = 77\nmagnitude = 30.0\nstart_s = 100.0'),
     "faults[0].channel: no PRN 77"),
    ("gnss-outage-after-the-run", _fault('sensor = "gnss"\nkind = "outage"\nstart_s = 5000.0\nend_s = 5060.0'),
     "faults[0].start_s: must be before 286 s (the run lasts about 260 s"),
    ("baro-step-without-magnitude", _fault('sensor = "baro"\nkind = "step"\nstart_s = 100.0'),
     "faults[0].magnitude: missing (required by a step fault)"),
    ("baro-step-zero-magnitude", _fault('sensor = "baro"\nkind = "step"\nstart_s = 100.0\nmagnitude = 0.0'),
     "faults[0].magnitude: a step fault with magnitude = 0 changes nothing"),
    ("ramp-without-rate", _fault('sensor = "radalt"\nkind = "ramp"\nstart_s = 100.0'), "faults[0].rate: missing"),
    ("mni-factor-one", _fault('sensor = "baro"\nkind = "mni"\nstart_s = 100.0\nfactor = 1.0'), "faults[0].factor"),
    ("spike-without-k", _fault('sensor = "radalt"\nkind = "spike"\nsteps = [10, 20]'), "faults[0].k: missing"),
    ("outage-with-magnitude", _fault('sensor = "gnss"\nkind = "outage"\nstart_s = 100.0\nmagnitude = 5.0'),
     "faults[0].magnitude: not used by a outage fault"),
    ("baro-channel", _fault('sensor = "baro"\nkind = "step"\nchannel = 0\nmagnitude = 5.0'), "faults[0].channel"),
    ("spike-step-after-the-run", _fault('sensor = "radalt"\nkind = "spike"\nk = 100.0\nsteps = [10, 900]'),
     "faults[0].steps: sample 900"),
    ("steps-and-every", _fault('sensor = "radalt"\nkind = "iam"\nmagnitude = 3.0\nsteps = [10]\nevery = 5'),
     "faults[0].every"),
    ("pseudolite-unit-3", _fault(
        'sensor = "pseudolite"\nkind = "step"\nchannel = 3\nmagnitude = 5.0',
        "\n[sensors.pseudolite]\nenabled = true\n[[sensors.pseudolite.units]]\nalong_ft = 0.0\ncross_ft = -500.0\n"
        "height_ft = 30.0\n"), "faults[0].channel: pseudolite unit index must be in [0, 0]"),
    ("doppler-target-without-doppler",
     _fault('sensor = "gnss"\nkind = "step"\ntarget = "pseudorange_rate"\nmagnitude = 0.5'), "faults[0].target"),
    ("unfitted-sensor", _fault('sensor = "pseudolite"\nkind = "outage"'), "faults[0].sensor"),
]


@pytest.mark.parametrize("command", ["sense", "navigate", "evaluate"])
@pytest.mark.parametrize(("case", "text", "must"), FAULT_CASES, ids=[c[0] for c in FAULT_CASES])
def test_fault_misspecification_exits_2_with_one_line(tmp_path, capsys, command, case, text, must):
    """Every fault mistake is caught when the profile loads, before anything flies, by every command."""
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main([command, str(path), "--out", str(tmp_path / "out")]) == 2
    _check(capsys.readouterr().err, must)
    assert not (tmp_path / "out").exists()


def test_fault_specifications_that_are_right_still_load(tmp_path):
    """The checks reject mistakes only: a fault of each kind on its sensor, inside the run, loads."""
    from approachsim.profile import load_profile

    ok = [
        'sensor = "gnss"\nkind = "outage"\nstart_s = 150.0\nend_s = 210.0',
        'sensor = "gnss"\nkind = "step"\nchannel = 24\nmagnitude = 30.0\nstart_s = 100.0',
        'sensor = "imu"\nkind = "step"\nchannel = 2\nmagnitude = 0.001\nstart_s = 100.0',
        'sensor = "baro"\nkind = "ramp"\nrate = 0.1\nstart_s = 200.0',
        'sensor = "radalt"\nkind = "spike"\nk = 100.0\nsteps = [101, 201]',
        'sensor = "baro"\nkind = "mni"\nfactor = 4.0\nstart_s = 100.0\nend_s = 150.0',
        'sensor = "baro"\nkind = "iam"\nmagnitude = 20.0\nstart_s = 100.0\nevery = 10',
        'sensor = "gnss"\nkind = "cbm"\nmagnitude = 10.0\nstart_s = 250.0',  # late, but inside a 260 s run
    ]
    path = tmp_path / "ok.toml"
    path.write_text(GOOD + "".join(f"\n[[faults]]\n{b}\n" for b in ok))
    assert len(load_profile(path).faults) == len(ok)
