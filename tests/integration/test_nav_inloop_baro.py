"""The compiled closed loop's own baro samples (core/loop/nav_row.baro_sample, which feed the damping loop while
JSBSim flies) equal the sensor model's (sensors/baro.py), with the aerodrome-temperature correction on a cold day at
a high field: the navigation of a flown closed-loop approach is recomputed row by row through NavInTheLoop.step (the
Python path, samples from Baro.record) over the flown truth, and must agree to rounding."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim.flight.run import Approach
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.profile import parse_profile

PROFILES = Path(__file__).resolve().parents[2] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("correction", ["aerodrome", "none"])
def test_inloop_baro_samples_equal_the_sensor_models(correction):
    path = PY_DEFAULT
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["runway"]["start_distance_nmi"] = 3.0
    data["runway"]["elevation_ft"] = 5434.0
    data["environment"]["isa_dev_C"] = -25.0
    data["sensors"]["baro"]["temperature_correction"] = correction
    assert data["nav"]["baro_loop"] == "constant"
    prof = parse_profile(data, source=path.resolve())
    src = NavInTheLoop(prof, seed=3, run=1)
    assert src.inloop() is not None  # the compiled row makes the damping loop's baro samples
    res = Approach(prof).fly(seed=3, run=1, nav_source=src, max_time_s=40.0)
    flown = src.result(res.truth)
    again = NavInTheLoop(prof, seed=3, run=1)
    for k in range(len(res.truth)):
        again.step(k, res.truth)
    stepped = again.result(res.truth)
    assert len(res.truth) > 40 * 100
    # the same filter on baro samples computed two ways (the compiled in-loop sample and Baro.record), which differ
    # by their floor(16, T0 / L) = 1.6e-10 m; a stable filter passes a measurement difference on with a gain of at
    # most 1, so the solutions differ by about that, plus a few roundings of the 6.4e6 m position (1.4e-9 m each):
    # 1e-6 m is ~100x floor(8, 6.4e6) + floor(16, T0 / L) = 1.1e-8 m
    np.testing.assert_allclose(flown.solution.r_ecef, stepped.solution.r_ecef, rtol=0, atol=1e-6)
    np.testing.assert_allclose(flown.x, stepped.x, rtol=1e-6, atol=1e-6)  # the error states: the same argument
