"""Closed loop on the protected solution (issue 11): JSBSim flies the default approach (from 3 nmi, all-in-view
GPS, online FDE) with a 2 m/s pseudorange ramp on a used satellite. The FDE excludes that satellite, the
aircraft stays stabilized to 200 ft on the protected solution, and its navigation error stays inside the
protection level after the exclusion; flown again without FDE, the ramp pulls the vertical navigation error
(NSE) to several times the protected flight's."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim.flight.run import Approach
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.loop.errors import approach_errors
from approachsim.profile import parse_profile

pytestmark = pytest.mark.slow

DEFAULT = Path(__file__).resolve().parents[2] / "tests" / "data" / "default-py.toml"
PRN = 16
ONSET_S = 20.0


def _fly(fde: bool):
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["runway"]["start_distance_nmi"] = 3.0
    d["sensors"]["gnss"]["selection"] = "all"
    d["sensors"]["gnss"]["epoch"] = "fixed"  # PRN 16 is used at the default epoch_utc
    d["nav"]["fde"] = {"enabled": fde}
    d["faults"] = [{"sensor": "gnss", "kind": "ramp", "channel": PRN, "start_s": ONSET_S, "rate": 2.0,
                    "target": "pseudorange"}]
    prof = parse_profile(d, source=DEFAULT)
    src = NavInTheLoop(prof, seed=1, run=0)
    res = Approach(prof).fly(seed=1, run=0, nav_source=src)
    return prof, src, res, src.result(res.truth)


@pytest.fixture(scope="module")
def flights():
    return {fde: _fly(fde) for fde in (True, False)}


def test_ramp_excluded_and_the_approach_stays_stabilized(flights):
    prof, src, res, nav = flights[True]
    assert res.termination == "reached stop height", res.termination  # not "unstabilized at ..."
    assert res.reached(200.0)
    prn = src.suite.sensors["gnss"].constellation.prn
    ev = nav.solution.exclusions
    assert len(ev) == 1 and prn[ev[0].channel] == PRN, ev
    assert ONSET_S <= ev[0].t_s <= ONSET_S + 15.0
    # the protected navigation error inside its protection level from the exclusion on
    h = prof.runway.heading_rad
    A = np.array([[0.0, 0.0, -1.0], [-math.sin(h), math.cos(h), 0.0]])
    rows = np.searchsorted(res.truth.t_s, nav.t_epoch_s - 1e-9)
    after = nav.t_epoch_s >= ev[0].t_s
    err = np.abs(nav.true_error_nav[after, 0:3] @ A.T)
    assert np.all(err < nav.solution.protection_level_m[rows[after]])


def test_protected_navigation_is_not_pulled_by_the_ramp(flights):
    """RMS vertical NSE from the exclusion to the end: the unprotected flight's is the ramp's pull (measured
    1.38 m against 0.42 m protected, seed 1; RMS FTE 1.1 m vertical in both)."""
    t_x = flights[True][3].solution.exclusions[0].t_s

    def rms_vertical_nse(flight):
        prof, _, res, _ = flight
        err = approach_errors(res.truth, res.guidance_r_rwy, prof.runway)
        m = res.truth.t_s >= t_x
        return float(np.sqrt(np.mean(err.nse_m[m, 1] ** 2)))

    on, off = rms_vertical_nse(flights[True]), rms_vertical_nse(flights[False])
    assert off > 2.0 * on, (on, off)
