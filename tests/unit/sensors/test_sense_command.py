"""`approachsim sense` on the synthetic truth: files, schema, fault labels; bad options exit 2."""

from __future__ import annotations

import json

import numpy as np

from approachsim.cli import main

PROFILE = """
name = "short"
[runway]
threshold_lat_deg = 37.6117
threshold_lon_deg = -122.3581
elevation_ft = 13.0
heading_true_deg = 298.0
start_distance_nmi = 1.0
[rates]
imu_hz = 50.0
[sensors.pseudolite]
enabled = true
[[sensors.pseudolite.units]]
along_ft = 1000.0
cross_ft = -500.0
[[faults]]
sensor = "baro"
kind = "cbm"
start_s = 5.0
end_s = 10.0
magnitude = 20.0
[[faults]]
sensor = "gnss"
kind = "outage"
start_s = 12.0
end_s = 15.0
"""


def test_sense_writes_streams_schema_and_labels(tmp_path, capsys):
    prof = tmp_path / "short.toml"
    prof.write_text(PROFILE)
    out = tmp_path / "out"
    assert main(["sense", str(prof), "--out", str(out), "--synthetic", "--seed", "3", "--no-figures"]) == 0
    schema = json.loads((out / "sensors.json").read_text())
    assert set(schema["streams"]) == {"imu", "baro", "radalt", "gnss", "pseudolite", "receiver_clock"}
    baro = np.load(out / "sensors" / "baro.npz")
    w = (baro["t_s"] >= 5.0) & (baro["t_s"] < 10.0)
    assert np.all(baro["fault"][w] == 4) and not baro["fault"][~w].any()
    gnss = np.load(out / "sensors" / "gnss.npz")
    o = (gnss["t_s"] >= 12.0) & (gnss["t_s"] < 15.0)
    assert not gnss["valid"][o].any() and gnss["valid"][~o].any()
    assert (out / "truth.npz").is_file() and (out / "sensors" / "pseudolite.csv").is_file()
    assert "fault-labelled" in capsys.readouterr().out


def test_bad_seed_exits_2(tmp_path, capsys):
    prof = tmp_path / "short.toml"
    prof.write_text(PROFILE)
    assert main(["sense", str(prof), "--out", str(tmp_path / "o"), "--synthetic", "--seed", "-1"]) == 2
    assert "--seed" in capsys.readouterr().err
