"""Every registered filter runs inside the full simulator when a profile names it (issue 6 acceptance):
JSBSim flies the default approach (from 2 nmi, to keep CI short) on the navigation solution of that filter,
reaches 200 ft, and the filter's claimed covariance covers its real error (mean NEES of the 9 navigation
states not diverged)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim.flight.run import Approach
from approachsim.nav.closed_loop import NavInTheLoop
from approachsim.nav.registry import FILTERS
from approachsim.profile import parse_profile

PROFILES = Path(__file__).resolve().parents[2] / "profiles"


@pytest.fixture(scope="module")
def approach_2nmi():
    path = PROFILES / "default.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["runway"]["start_distance_nmi"] = 2.0
    return data, path


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(FILTERS))
def test_filter_named_in_the_profile_flies_the_approach(name, approach_2nmi):
    data, path = approach_2nmi
    data = {**data, "nav": {**data.get("nav", {}), "filter": name}}
    prof = parse_profile(data, source=path.resolve())
    assert prof.nav.filter == name
    src = NavInTheLoop(prof, seed=3, run=0)
    res = Approach(prof).fly(seed=3, run=0, nav_source=src)
    assert res.termination == "reached stop height" and res.reached(200.0)
    nav = src.result(res.truth)
    e = nav.solution.r_ecef - res.truth.r_ecef
    assert np.all(np.isfinite(e))
    # position error small against the 2 nmi approach and covered by the filter's own claim
    assert np.max(np.linalg.norm(e, axis=1)) < 30.0
    p_trace = np.trace(nav.solution.P_pos_ned, axis1=1, axis2=2)
    assert np.mean(np.sum(e**2, axis=1) / p_trace) < 5.0
