"""An approach across the antimeridian (longitude +180 = -180 deg).

JSBSim reports longitude in (-180, 180]; the strapdown INS integrates its own longitude on past +-pi; the GNSS and
the filter work in ECEF. Every error taken from geodetic coordinates must wrap the longitude difference
(nav/ins.py position_error_ned), or an approach that crosses the antimeridian shows a 40,000 km error. The runway
here (lat 0.5 N, threshold 179.98 E, landing 300 deg true, so the east error has a lateral part) puts the crossing
2.56 km before the threshold: on a 3 nmi final the closed loop flies across it on its own navigation solution
(runway coordinates from ECEF throughout), and an open-loop campaign navigates and scores two runs across it with
the integrity bank, whose errors come from geodetic coordinates (nav/navigator.py true_error_rows). Measured, seed
1: closed loop, largest |NSE| over the flight 2.5 m lateral, 0.87 m vertical; open loop, lateral 1-sigma 4.8-5.6 ft
at the three decision heights, no misleading epoch (132 CAT II epochs). With the longitude difference left
unwrapped the open-loop test fails (66 misleading CAT II epochs).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.campaign.evaluation import evaluate_profile
from approachsim.flight.run import Approach
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.loop.errors import approach_errors
from approachsim.profile import parse_profile

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "tests" / "data" / "default-py.toml"

pytestmark = pytest.mark.slow


def _profile(start_nmi: float):
    data = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    data["runway"].update(threshold_lat_deg=0.5, threshold_lon_deg=179.98, heading_true_deg=300.0,
                          start_distance_nmi=start_nmi)
    data["environment"]["wind_from_deg"] = 300.0
    return parse_profile(data, source=DEFAULT)


def _crosses(lon_rad: np.ndarray) -> bool:
    lon = np.degrees(np.asarray(lon_rad))
    return bool(np.any(lon > 179.99) and np.any(lon < -179.99))


def test_closed_loop_flies_across_the_antimeridian_on_its_navigation():
    prof = _profile(3.0)
    src = NavInTheLoop(prof, seed=1, run=0)
    res = Approach(prof).fly(seed=1, run=0, nav_source=src)
    nav = src.result(res.truth)
    assert _crosses(res.truth.lon_rad), "the flight did not cross the antimeridian"
    assert res.termination == "reached stop height"
    assert res.reached(200.0)
    err = approach_errors(res.truth, res.guidance_r_rwy, prof.runway)
    # stand-alone GPS (best four) with the INS: metres; an unwrapped longitude: ~1e7 m
    assert np.max(np.abs(err.nse_m[:, 0])) < 30.0, np.max(np.abs(err.nse_m[:, 0]))
    assert np.max(np.abs(err.nse_m[:, 1])) < 15.0, np.max(np.abs(err.nse_m[:, 1]))
    k = int(np.argmin(np.abs(res.truth.r_rwy[:, 2] - 200.0 * units.FT)))
    sigma_v = np.sqrt(nav.solution.P_pos_ned[k, 2, 2])
    assert abs(err.nse_m[k, 1]) < 4.0 * sigma_v + 0.5, (err.nse_m[k], sigma_v)


def test_open_loop_campaign_with_the_bank_across_the_antimeridian(tmp_path: Path):
    prof = _profile(3.0)
    assert prof.evaluation.integrity_on
    ev = evaluate_profile(prof, runs=2, seed=1, mode="open",
                          out_dir=tmp_path / "am", workers=1, progress=False)
    s = ev.summary
    assert s["failed_runs"] == 0
    for cat in ("CAT I", "CAT II", "CAT III"):
        dh = s["decision_heights"][cat]
        assert dh["lateral_1sigma_ft"] < 100.0 and dh["vertical_1sigma_ft"] < 50.0, (cat, dh)
    # the bank's errors are scored against its protection levels: no misleading information fault-free
    integ = ev.details["integrity"]["categories"]
    for cat in ("CAT II", "CAT III"):
        assert integ[cat]["mi"]["count"] == 0, (cat, integ[cat]["mi"])
