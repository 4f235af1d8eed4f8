"""Every registered filter runs inside the full simulator when a profile names it (issue 6 acceptance):
JSBSim flies the default approach (from 2 nmi, to keep CI short) on the navigation solution of that filter,
reaches 200 ft, and the filter's claimed position covariance covers its real error.

Consistency on one flown run per filter: the position NEES e' P^-1 e (3 dof, P the solution's NED position
covariance) at the IMU samples, averaged over the run. Its samples are strongly correlated in time, so the
bound is the one that holds whatever the correlation: a time average of chi2(3) samples exceeds the single
sample's 99.9 % quantile chi2_3(0.999) = 16.3 with probability at most about 0.1 % (convex order of the mean
of exchangeable variables). Expected 3; a filter over-confident by a factor 5.4 in variance fails. The
position error itself is bounded by 6 of the filter's own sigmas at every sample (per axis), not by a fixed
30 m. Measured (seed 3, run 0, every filter): mean NEES 4.57-4.72, max 2.3 sigma, max 13.1 m (python -m
pytest ... -s prints them)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from approachsim import geo
from approachsim.flight.run import Approach
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.nav.registry import FILTERS
from approachsim.profile import parse_profile

PROFILES = Path(__file__).resolve().parents[2] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


@pytest.fixture(scope="module")
def approach_2nmi():
    path = PY_DEFAULT
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
    lat, lon, h = geo.ecef_to_geodetic(res.truth.r_ecef)
    e_ned = np.einsum("nij,nj->ni", geo.c_ecef_to_ned(lat, lon), e)
    P = nav.solution.P_pos_ned
    nees = np.einsum("ni,ni->n", e_ned, np.linalg.solve(P, e_ned[..., None])[..., 0])
    z = np.abs(e_ned) / np.sqrt(np.diagonal(P, axis1=1, axis2=2))
    print(f"{name}: mean position NEES {nees.mean():.2f} (expected 3), max |e|/sigma {z.max():.2f}, "
          f"max |e| {np.max(np.linalg.norm(e, axis=1)):.2f} m")
    assert nees.mean() < chi2.ppf(0.999, 3), nees.mean()
    assert np.all(z < 6.0), z.max()
