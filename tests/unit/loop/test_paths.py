"""loop/paths.py: the closed loop's path is chosen once per run from the configuration and the oracle switches, by
name with the reason of every part that did not take its fastest form; the campaign records it per run."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from approachsim.loop import paths
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.profile import load_profile, parse_profile

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


def _profile(name: str, **sections):
    path = PY_DEFAULT if name == "default.toml" else PROFILES / name
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    for sec, kv in sections.items():
        top, _, sub = sec.partition("__")
        tgt = d.setdefault(top, {})
        if sub:
            tgt = tgt.setdefault(sub, {})
        tgt.update(kv)
    return parse_profile(d, source=path.resolve())


@pytest.mark.parametrize("path", [PY_DEFAULT, PROFILES / "default.toml", PROFILES / "dfmc-sbas.toml"])
def test_default_profile_takes_every_fast_form(path):
    """The P(Y) file, the SBAS L1 default and DFMC SBAS: every part compiled, the epoch fused."""
    src = NavInTheLoop(load_profile(path), seed=1, run=0, max_time_s=30.0)
    p = src.path
    assert (p.row, p.epoch, p.baro, p.sigmas) == ("compiled", "fused", "compiled", "compiled")
    assert p.reasons == () and p.name == "row=compiled epoch=fused baro=compiled sigmas=compiled"
    assert src.path is p  # chosen once


@pytest.mark.parametrize(("sections", "part", "name", "why"), [
    ({"nav": {"feedback": True}}, "epoch", "generic", "feedback"),
    ({"nav__fde": {"enabled": True}}, "epoch", "generic", "FDE"),
    ({"nav": {"filter": "rkf-gate"}}, "epoch", "generic", "compiled epoch"),
    ({"sensors__imu": {"gyro_quant_rad": 1e-7}}, "row", "generic", "quantized"),
])
def test_a_slower_part_says_why(sections, part, name, why):
    src = NavInTheLoop(_profile("default.toml", **sections), seed=1, run=0, max_time_s=30.0)
    assert getattr(src.path, part) == name and why in src.path.reason(part)
    if part == "row":  # no compiled row: the flight steps the source in Python and the baro's samples come from it
        assert src.inloop() is None and src.path.baro == "python"


def test_oracle_switches_choose_the_numpy_paths():
    prof = load_profile(PY_DEFAULT)
    src = NavInTheLoop(prof, seed=1, run=0, max_time_s=30.0)
    src.direct_inputs = False
    assert src.path.epoch == "records" and "oracle" in src.path.reason("epoch")
    src = NavInTheLoop(prof, seed=1, run=0, max_time_s=30.0)
    src.fast_epochs = False
    assert src.path.epoch == "generic" and src.path.sigmas == "none"


def test_gbas_takes_the_records_and_the_numpy_sigmas():
    prof = load_profile(PROFILES / "gbas-cat3-candidate.toml")
    src = NavInTheLoop(prof, seed=1, run=0, max_time_s=30.0)
    assert src.path.epoch == "records" and "GBAS" in src.path.reason("epoch")
    assert src.path.sigmas in ("numpy", "none")


def test_open_loop_path_follows_the_shared_covariance():
    from approachsim.nav.system import NavSystem

    assert paths.open_loop_path(NavSystem.from_profile(load_profile(PY_DEFAULT))) == "epoch=shared"
    rob = NavSystem.from_profile(_profile("default.toml", nav={"filter": "rkf-gate"}))
    assert paths.open_loop_path(rob) == "epoch=generic"


@pytest.mark.slow
def test_a_closed_loop_run_records_its_path():
    """The campaign's closed-loop run carries the flight's loop and the source's path (details.json "paths")."""
    from approachsim.campaign.pipeline import closed_loop_group
    from approachsim.campaign.result import RunResult

    (r,) = closed_loop_group(load_profile(PY_DEFAULT), 1, [0])
    assert r.ok, r.error
    loop, rest = r.path.split(" ", 1)
    assert loop in ("flight=direct", "flight=python")
    assert rest == "row=compiled epoch=fused baro=compiled sigmas=compiled"
    assert RunResult.from_record(r.record()).path == r.path  # round trip through runs.jsonl
