"""Open-loop flight groups in calm air share one flight (campaign/pipeline.group_flight): what makes that exact."""

from __future__ import annotations

import dataclasses
import tomllib

import numpy as np

from approachsim.campaign import pipeline
from approachsim.profile import parse_profile
from approachsim.resources import shipped_profiles

GM = {s.name: s.path for s in shipped_profiles()}["gray-maybeck"]


def _profile(**imu) -> object:
    d = tomllib.loads(GM.read_text(encoding="utf-8"))
    d["sensors"]["imu"].update(imu)
    return parse_profile(d, source=GM)


def test_a_calm_flight_does_not_depend_on_seed_or_run():
    prof = _profile()
    assert prof.environment.turbulence == "none"
    ap = pipeline._approach(prof)
    a, b = ap.fly(seed=1, run=0), ap.fly(seed=7, run=25)
    for f in dataclasses.fields(a.truth):
        x, y = getattr(a.truth, f.name), getattr(b.truth, f.name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y, equal_nan=True), f.name
    # so every group, and every case that differs only in sensors, gets the one flight
    other = _profile(grade="nav-4.0")
    assert other != prof
    assert pipeline.group_flight(prof, 1, 0) is pipeline.group_flight(other, 3, 50)
    assert np.array_equal(pipeline.group_flight(prof, 1, 0).truth.r_ecef, a.truth.r_ecef)


def test_the_shared_calm_flight_is_read_only():
    """Every group reads the one calm-air flight: a write into its arrays would reach the next group's runs, so numpy
    refuses it (pipeline._read_only)."""
    f = pipeline.group_flight(_profile(), 1, 0)
    assert not f.truth.h_m.flags.writeable and not f.truth.r_ecef.flags.writeable
    try:
        f.truth.h_m[0] = 0.0
    except ValueError:
        pass
    else:
        raise AssertionError("the shared flight's truth was writable")
