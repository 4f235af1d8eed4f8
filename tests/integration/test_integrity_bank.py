"""Solution-separation integrity on a JSBSim approach (all-in-view GPS, open loop): fault-free, the bank
detects nothing and no epoch is misleading; a 2 m/s pseudorange ramp on one satellite is detected, the right
channel is excluded before the main solution's error leaves its protection level, and the protected output
is never misleading; best-four selection protects less than all in view (its sub-filters keep three
satellites: the INS and baro carry them, the lateral PL is larger; measured 35 m against 21 m)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.campaign.integrity_bank import run_bank, score_run
from approachsim.flight.run import Approach
from approachsim.profile import parse_profile

pytestmark = pytest.mark.slow

DEFAULT = Path(__file__).resolve().parents[2] / "tests" / "data" / "default-py.toml"
DH = {"CAT I": 200 * units.FT, "CAT II": 100 * units.FT, "CAT III": 50 * units.FT}
PRN = 14


def _profile(selection: str = "all", ramp_mps: float | None = None):
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["sensors"]["gnss"]["selection"] = selection
    d["runway"]["start_distance_nmi"] = 5.0
    if ramp_mps is not None:
        d["faults"] = [{"sensor": "gnss", "kind": "ramp", "channel": PRN, "start_s": 60.0, "end_s": 500.0,
                        "rate": ramp_mps, "target": "pseudorange"}]
    return parse_profile(d, source=DEFAULT)


@pytest.fixture(scope="module")
def truth():
    return Approach(_profile()).fly(seed=1).truth


def test_fault_free_nothing_detected_nothing_misleading(truth):
    ep, _ = run_bank(_profile(), truth, seed=1, run=0)
    assert ep.ek.shape[1] >= 6
    for cat, s in score_run(ep, 1.0, 1000 * units.FT, DH).items():
        assert not s.detected.any(), cat
        assert not s.misleading.any(), cat
    assert score_run(ep, 1.0, 1000 * units.FT, DH)["CAT I"].available.all()


def test_ramp_detected_excluded_before_the_error_leaves_its_pl(truth):
    prof = _profile(ramp_mps=2.0)
    ep, _ = run_bank(prof, truth, seed=1, run=0)
    for cat, s in score_run(ep, 1.0, 1000 * units.FT, DH).items():
        assert s.detected.any(), cat
        assert s.excluded_channel >= 0
        assert not s.misleading.any(), cat  # the protected output stays inside its PL
        assert not (s.time_to_alert_s > 0.0), (cat, s.time_to_alert_s)  # detected before the PL was exceeded
    # the excluded channel is the faulted PRN's: the main error grows, the excluded sub-solution's does not
    s = score_run(ep, 1.0, 1000 * units.FT, DH)["CAT I"]
    k = int(np.nonzero(ep.channels == s.excluded_channel)[0][0])
    late = ep.t_s > 100.0
    assert np.abs(ep.ek[late, k]).max() < 0.25 * np.abs(ep.e0[late]).max()


def test_best_four_protects_less_than_all_in_view(truth):
    def lateral_pl(selection):
        ep, _ = run_bank(_profile(selection=selection), truth, seed=1, run=0)
        return float(np.median(score_run(ep, 1.0, 1000 * units.FT, DH)["CAT I"].pl_m[:, 1]))

    assert lateral_pl("best4") > 1.3 * lateral_pl("all")
