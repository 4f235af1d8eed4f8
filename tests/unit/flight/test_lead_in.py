"""The PROFGEN-like lead-in (flight/path.py, runway.lead_in = "profgen"): its geometry, and one JSBSim flight of it
on the approach autopilot through the turns, level segments, the descent and the glideslope intercept."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from approachsim import leadin as fp
from approachsim import units
from approachsim.config import ProfileError
from approachsim.flight.path import PathGuidance
from approachsim.flight.run import Approach
from approachsim.profile import parse_profile
from approachsim.resources import shipped_profiles

GM = {s.name: s.path for s in shipped_profiles()}["gray-maybeck"]


def _profile(lead_in: str = "profgen", **runway) -> object:
    d = tomllib.loads(GM.read_text(encoding="utf-8"))
    d["runway"].update(lead_in=lead_in, **runway)
    return parse_profile(d, source=GM)


def test_legs_join_and_end_on_the_final_at_the_threshold():
    prof = _profile()
    lead = fp.profgen(prof.runway)
    for a, b in zip(lead.legs, lead.legs[1:], strict=False):
        x, y, chi = a.end()
        assert (x, y) == pytest.approx((b.x0, b.y0), abs=1e-6)
        assert math.remainder(chi - b.chi0_rad, 2.0 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert lead.legs[-1].end() == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    # two 90 deg left turns, the downwind on the reciprocal of the final
    assert [g.turn for g in lead.legs] == [0, -1, 0, -1, 0]
    assert lead.legs[0].chi0_rad == pytest.approx(math.pi)
    # the intercept: the cone at the pattern height on the centreline; the straight line gives 7.69 nmi on 3 deg
    # (2500 ft - 50 ft TCH), the cone's Earth drop x^2 / 2R (15 m at 14 km) puts it 15 / tan(3 deg) = 290 m closer
    assert float(prof.runway.glidepath_height_m(lead.x_gs_m)) == pytest.approx(lead.pattern_height_m, abs=1e-6)
    straight = (2500.0 - 50.0) * units.FT / math.tan(math.radians(3.0))
    drop = straight**2 / (2.0 * 6.371e6) / math.tan(math.radians(3.0))
    assert -lead.x_gs_m == pytest.approx(straight - drop, abs=20.0)
    # the vertical path: descent on the glidepath angle, then level
    assert lead.height_m(0.0) == pytest.approx(fp.START_HEIGHT_FT * units.FT)
    assert lead.height_m(1e5) == lead.pattern_height_m


def test_locate_on_an_arc_signs_the_cross_track_and_sweeps():
    g = fp.Leg(0.0, 0.0, 0.0, 0.5 * math.pi * 1000.0, turn=-1, radius_m=1000.0)  # left turn: centre at (0, -1000)
    assert g.center == pytest.approx((0.0, -1000.0))
    a, c, chi = g.locate(0.0, 10.0)  # 10 m right of the arc's start (outside a left turn)
    assert (a, c, chi) == pytest.approx((0.0, 10.0, 0.0), abs=1e-9)
    a, c, chi = g.locate(990.0 * math.sin(0.3), -1000.0 + 990.0 * math.cos(0.3))  # 10 m inside, 0.3 rad in
    assert (a, c, chi) == pytest.approx((300.0, -10.0, -0.3), abs=1e-6)


def test_profile_errors_name_the_field():
    with pytest.raises(ProfileError, match="runway.lead_in"):
        _profile("spiral")
    d = tomllib.loads(GM.read_text(encoding="utf-8"))
    d["runway"]["lead_in"] = "profgen"
    d["run"]["mode"] = "closed"
    with pytest.raises(ProfileError, match="runway.lead_in: .*open loop"):
        parse_profile(d, source=GM)


@pytest.fixture(scope="module")
def flown():
    prof = _profile()
    ap = Approach(prof, stop_height_m=180.0 * units.FT)
    return prof, ap.lead_in, ap.fly(seed=1, run=0)


def test_jsbsim_flies_the_pattern_on_the_autopilot(flown):
    """Tolerances from the autopilot: entering an arc the bank builds from 0 to phi_ff = atan(V^2 / (g R)) (12.3 deg)
    over the roll loop's ~3 s, while the path curves away at V^2 / R = 2.0 m/s^2: 0.5 x 2.0 x 3^2 = 9 m off it before
    the localizer law takes over; bound 30 m (3x). A level-off from the 3 deg descent (3.6 m/s sink) at TECS's
    vertical acceleration limit overshoots by a few metres; bound 15 m on every level segment. Headings on the
    straight legs within 1 deg of the leg's course (calm air: no crab)."""
    prof, lead, result = flown
    assert result.termination == "reached stop height"
    tr = result.truth
    r, e = tr.r_rwy, tr.euler_rad
    guide = PathGuidance(lead, prof.runway.glidepath, 0.05)
    legs, cross, dz = np.zeros(len(r), int), np.zeros(len(r)), np.full(len(r), np.nan)
    for k in range(len(r)):
        leg, s, c, _ = guide.locate(r[k, 0], r[k, 1])
        legs[k], cross[k] = leg, c
        if not (leg == 4 and r[k, 0] >= lead.x_gs_m):
            dz[k] = r[k, 2] - lead.height_m(s)
    assert sorted(set(legs.tolist())) == [0, 1, 2, 3, 4]  # every leg flown, in order
    assert np.all(np.diff(legs) >= 0)
    assert np.max(np.abs(cross)) < 30.0
    level = np.isfinite(dz) & (r[:, 2] < fp.START_HEIGHT_FT * units.FT - 1.0)
    assert np.max(np.abs(dz[np.isfinite(dz)])) < 15.0 and level.sum() > 120 * 200  # > 200 s on the path's height
    hdg = prof.runway.heading_rad
    for leg in (0, 2, 4):
        mid = np.flatnonzero(legs == leg)[len(np.flatnonzero(legs == leg)) // 2]
        want = hdg + lead.legs[leg].chi0_rad
        assert abs(math.remainder(e[mid, 2] - want, 2.0 * math.pi)) < math.radians(1.0), leg
    for leg in (1, 3):  # mid-turn bank: the coordinated turn's, left
        mid = np.flatnonzero(legs == leg)[len(np.flatnonzero(legs == leg)) // 2]
        v2 = tr.v_ned[mid, 0] ** 2 + tr.v_ned[mid, 1] ** 2
        assert e[mid, 0] == pytest.approx(-math.atan(v2 / (units.G0 * fp.TURN_RADIUS_M)), abs=math.radians(1.5))
    # the final below 1000 ft: on the localizer and the glide path as the straight-in flies them (the ILS monitor's
    # 1 dot is ~60 m laterally there)
    low = r[:, 2] < 1000.0 * units.FT
    assert np.max(np.abs(r[low, 1])) < 10.0
    assert np.max(np.abs(tr.gs_dev_m[low])) < 5.0
    # the flight's length: the path's at about the approach speed (TAS above it aloft)
    assert tr.t_s[-1] == pytest.approx(lead.length_m / (133.0 * units.KT), rel=0.1)
