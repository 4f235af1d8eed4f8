"""`approachsim navigate`: user mistakes exit 2 with one line naming the field (no flight is flown)."""

from __future__ import annotations

from pathlib import Path

import pytest

from approachsim.cli import main

PROFILES = Path(__file__).resolve().parents[2] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["navigate", "profiles/none.toml", "--out", "OUT"], "no such file"),
        (["navigate", str(PY_DEFAULT), "--out", "OUT", "--seed", "-1"], "--seed"),
        (["navigate", str(PY_DEFAULT), "--out", "OUT", "--run", "-2"], "--run"),
        (["navigate", "BAD", "--out", "OUT"], "nav.filter"),
        (["navigate", "TUNE", "--out", "OUT"], "nav.filter_tuning.gate"),
        (["navigate", "RATE", "--out", "OUT"], "nav.aiding_rate_hz"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, needle):
    # a minimal valid profile (every other section takes its defaults) plus one bad [nav] table
    base = ('[runway]\nthreshold_lat_deg = 37.6\nthreshold_lon_deg = -122.4\nelevation_ft = 13.0\n'
            'heading_true_deg = 298.0\n')
    bad = {"BAD": '\n[nav]\nfilter = "nope"\n', "TUNE": '\n[nav]\nfilter = "ekf"\nfilter_tuning = { gate = 3 }\n',
           "RATE": "\n[nav]\naiding_rate_hz = 0.0\n"}
    argv = list(argv)
    if argv[1] in bad:
        p = tmp_path / "bad.toml"
        p.write_text(base + bad[argv[1]], encoding="utf-8")
        argv[1] = str(p)
    argv[argv.index("OUT")] = str(tmp_path / "out")
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err


def test_bad_mode_is_an_argparse_error(capsys):
    with pytest.raises(SystemExit) as e:
        main(["navigate", str(PY_DEFAULT), "--out", "x", "--mode", "sideways"])
    assert e.value.code == 2
