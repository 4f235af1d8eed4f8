"""`approachsim fly` end to end: writes the truth file, its schema and the figures; the same seed gives a
bit-identical truth file, different seeds different turbulence; the file opens without approachsim."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from approachsim.cli import main
from approachsim.flight.truthfile import load_truth
from approachsim.records import Truth

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]


def _short_profile(tmp_path: Path) -> Path:
    """The default profile (light turbulence) started 2 nmi out; aircraft found in the repository's aircraft/."""
    text = (ROOT / "tests" / "data" / "default-py.toml").read_text()
    assert "start_distance_nmi = 10.0" in text
    path = tmp_path / "short.toml"
    path.write_text(text.replace("start_distance_nmi = 10.0", "start_distance_nmi = 2.0"))
    return path


def test_fly_writes_truth_schema_and_figures(tmp_path, capsys):
    prof = _short_profile(tmp_path)
    out = tmp_path / "out"
    assert main(["fly", str(prof), "--out", str(out), "--seed", "4"]) == 0
    printed = capsys.readouterr().out
    assert "reached stop height" in printed and "vertical RMS" in printed
    for name in ("truth.npz", "truth.json", "flight.json", "vertical.png", "lateral.png", "airspeed.png",
                 "attitude.png"):
        assert (out / name).stat().st_size > 0, name
    schema = json.loads((out / "truth.json").read_text())
    assert schema["schema"] == "approachsim.truth/1"
    z = np.load(out / "truth.npz")  # plain numpy, no approachsim needed
    truth_fields = set(Truth.__dataclass_fields__) - {"runway"}
    assert truth_fields <= set(z.files) and truth_fields <= set(schema["arrays"])
    for name in truth_fields:
        assert list(z[name].shape) == schema["arrays"][name]["shape"]
        assert schema["arrays"][name]["unit"] and schema["arrays"][name]["description"]
    t = load_truth(out / "truth.npz")
    assert t.r_rwy[-1, 2] <= 50 * 0.3048 + 1e-9 and np.all(np.isfinite(t.f_body))
    assert np.all(np.diff(t.t_s) > 0)
    flight = json.loads((out / "flight.json").read_text())
    assert flight["termination"] == "reached stop height" and flight["seed"] == 4
    assert flight["truth_samples"] == len(t) == schema["samples"]  # flight.json agrees with truth.npz
    assert 0 < flight["tracking_window_samples"] < len(t)  # the 1000-200 ft window only


def test_same_seed_bit_identical_different_seed_different_turbulence(tmp_path):
    prof = _short_profile(tmp_path)
    outs = []
    for i, seed in enumerate((5, 5, 6)):
        out = tmp_path / f"o{i}"
        # separate processes: the file must not depend on anything but profile and seed
        subprocess.run([sys.executable, "-m", "approachsim", "fly", str(prof), "--out", str(out), "--seed", str(seed),
                        "--no-figures"], check=True, capture_output=True)
        outs.append(out)
    a, b, c = ((o / "truth.npz").read_bytes() for o in outs)
    assert a == b
    assert a != c
    fa, fc = (np.load(o / "truth.npz")["f_body"] for o in (outs[0], outs[2]))
    n = min(len(fa), len(fc))
    # both start from the same trim: the difference is the turbulence, a sizeable fraction of a g
    assert np.std(fa[:n, 2] - fc[:n, 2]) > 0.2
