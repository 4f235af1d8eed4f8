"""Issue 40's dispersed conditions in the flight loop: the mean wind against height (flight/wind.py, its kernel
core/loop/flight_step.mean_wind), the runway slope (terrain, flare, touchdown scoring), the weight and CG loaded
through the JSBSim tanks (aircraft file [mass]), and the profile keys' one-line errors."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.config import ProfileError
from approachsim.core import layouts
from approachsim.core.loop import flight_step as fk
from approachsim.flight import wind
from approachsim.flight.aircraft import load_aircraft
from approachsim.flight.fdm import FDM
from approachsim.flight.run import Approach
from approachsim.flight.trim import start_condition
from approachsim.profile import RUNWAY_SLOPE_EXTENT_M, parse_profile

ROOT = Path(__file__).resolve().parents[3]
DEFAULT = ROOT / "profiles" / "default.toml"
BASE = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))


def _profile(**sections):
    d = copy.deepcopy(BASE)
    for sec, kv in sections.items():
        d.setdefault(sec, {}).update(kv)
    return parse_profile(d, source=DEFAULT)


def _fpar(env) -> np.ndarray:
    """fly_step's F_* parameters of the wind, as flight_vectors packs them."""
    fpar = np.zeros(layouts.N_F_PAR)
    w = env.wind_speed_mps
    fpar[layouts.F_WIND_N], fpar[layouts.F_WIND_E] = -w * math.cos(env.wind_from_rad), -w * math.sin(env.wind_from_rad)
    fpar[layouts.F_WIND_LOG] = float(env.wind_profile == "log")
    fpar[layouts.F_WIND_Z0], fpar[layouts.F_WIND_REF] = env.roughness_length_m, env.wind_reference_height_m
    fpar[layouts.F_SHEAR_TOP], fpar[layouts.F_SHEAR_BOTTOM] = env.shear_top_m, env.shear_bottom_m
    fpar[layouts.F_SHEAR_N], fpar[layouts.F_SHEAR_E] = env.shear_n_mps, env.shear_e_mps
    return fpar


def test_mean_wind_kernel_equals_the_oracle_and_the_log_law():
    env = _profile(environment={"wind_speed_kt": 15.0, "wind_from_deg": 250.0, "wind_profile": "log",
                                "shear_top_ft": 300.0, "shear_bottom_ft": 100.0,
                                "shear_headwind_loss_kt": 8.0}).environment
    fpar = _fpar(env)
    for h in np.concatenate([[0.0, 0.5, 3.0 * units.FT, 10.0], np.linspace(1.0, 600.0, 301)]):
        assert fk.mean_wind(fpar, h) == wind.mean_wind_ned(env, h), h  # same IEEE operations: bit for bit
    # the log law: the reference wind at the reference height, MIL-F-8785C's ratio at 1000 ft, held above
    flat = _profile(environment={"wind_speed_kt": 15.0, "wind_profile": "log"}).environment
    w10 = math.hypot(*wind.mean_wind_ned(flat, 10.0))
    assert w10 == pytest.approx(15.0 * units.KT, rel=1e-12)
    z0 = 0.15 * units.FT
    top = math.log(1000.0 * units.FT / z0) / math.log(10.0 / z0)  # 1.634
    assert math.hypot(*wind.mean_wind_ned(flat, 304.8)) / w10 == pytest.approx(top, rel=1e-12)
    assert wind.mean_wind_ned(flat, 2000.0) == wind.mean_wind_ned(flat, 1000.0 * units.FT)
    # the shear: the headwind along the runway falls by the loss from top to bottom (the log part held equal)
    rwy = _profile().runway.heading_rad
    sh = _profile(environment={"wind_speed_kt": 0.0, "shear_top_ft": 300.0, "shear_bottom_ft": 100.0,
                               "shear_headwind_loss_kt": 8.0}).environment

    def head(h: float) -> float:
        n, e = wind.mean_wind_ned(sh, h)
        return -(n * math.cos(rwy) + e * math.sin(rwy))  # headwind: air moving against the landing direction

    assert head(400.0 * units.FT) == 0.0
    assert head(200.0 * units.FT) == pytest.approx(-4.0 * units.KT, rel=1e-12)
    assert head(50.0 * units.FT) == pytest.approx(-8.0 * units.KT, rel=1e-12)
    # uniform: the reference vector itself at every height
    uni = _profile(environment={"wind_speed_kt": 12.0}).environment
    assert not wind.varies(uni)
    assert fk.mean_wind(_fpar(uni), 123.0) == (_fpar(uni)[layouts.F_WIND_N], _fpar(uni)[layouts.F_WIND_E])


def test_jsbsim_trims_in_the_mean_wind_at_the_start_height():
    p = _profile(environment={"wind_speed_kt": 10.0, "wind_from_deg": 298.0, "wind_profile": "log"})
    ic = start_condition(p, load_aircraft(p))
    h = ic.h_m - ic.terrain_m
    assert ic.wind_speed_mps == pytest.approx(math.hypot(*wind.mean_wind_ned(p.environment, h)), rel=1e-12)
    assert ic.wind_speed_mps / (10.0 * units.KT) == pytest.approx(1.634, abs=0.001)  # above 1000 ft: the top
    assert math.degrees(ic.wind_from_rad) % 360.0 == pytest.approx(298.0, abs=1e-9)


@pytest.mark.parametrize("sections, field", [
    ({"environment": {"wind_profile": "power"}}, "environment.wind_profile"),
    ({"environment": {"shear_top_ft": 100.0, "shear_bottom_ft": 200.0, "shear_headwind_loss_kt": 5.0}},
     "environment.shear_top_ft"),
    ({"environment": {"roughness_length_m": 2.0}}, "environment.roughness_length_m"),
    ({"runway": {"slope_percent": 3.0}}, "runway.slope_percent"),
    ({"aircraft": {"cg_percent_mac": "aft"}}, "aircraft.cg_percent_mac"),
])
def test_bad_condition_keys_name_their_field(sections, field):
    with pytest.raises(ProfileError) as e:
        _profile(**sections)
    msg = str(e.value)
    assert msg.startswith(field + ":") and "\n" not in msg


@pytest.mark.parametrize("aircraft, field", [
    ({"weight_lb": 130000.0}, "aircraft.weight_lb"),  # above the 114,000 lb landing weight
    ({"weight_lb": 88000.0, "cg_percent_mac": 10.0}, "aircraft.cg_percent_mac"),  # needs a load ahead of the nose
])
def test_weight_and_cg_outside_the_aircraft_file_are_errors(aircraft, field):
    with pytest.raises(ProfileError) as e:
        load_aircraft(_profile(aircraft=aircraft))
    assert str(e.value).startswith(field + ":") and "\n" not in str(e.value)


@pytest.mark.parametrize("weight_lb, cg_pct", [(114000.0, 10.0), (95000.0, 30.0), (107000.0, 20.0)])
def test_the_tank_loading_gives_jsbsim_the_weight_and_cg(weight_lb, cg_pct):
    p = _profile(aircraft={"weight_lb": weight_lb, "cg_percent_mac": cg_pct})
    ac = load_aircraft(p)
    m = ac.mass
    # the speed scales with sqrt(W): the reference speed's lift coefficient at any weight
    assert ac.approach_speed_mps == pytest.approx(140.0 * units.KT * math.sqrt(weight_lb / 107000.0), rel=1e-12)
    fdm = FDM(ac.jsbsim_model, 1.0 / 120.0)
    fdm.initialize_and_trim(start_condition(p, ac))
    # JSBSim's own mass properties after the trim's step: the weight less one step's fuel flow (< 1 lb), the CG
    # moved by that fuel (< 0.01 in)
    assert fdm["inertia/weight-lbs"] == pytest.approx(weight_lb, abs=1.0)
    assert fdm["inertia/cg-x-in"] == pytest.approx(m.cg_x_in(cg_pct / 100.0), abs=0.01)


def test_the_runway_slope_is_in_the_terrain_past_the_threshold():
    p = _profile(runway={"slope_percent": 1.0})
    rw, t = p.runway, p.terrain
    assert t.height_at(-500.0) == rw.elevation_m  # before the threshold: as the profile had it
    assert t.height_at(900.0) == pytest.approx(rw.elevation_m + 9.0, abs=1e-9)
    assert t.height_at(5000.0) == pytest.approx(rw.elevation_m + 0.01 * RUNWAY_SLOPE_EXTENT_M, abs=1e-9)
    assert _profile().terrain.along_m == (0.0,)  # a level runway leaves the terrain (and every flight) as it was


def test_the_flare_lands_on_a_sloped_runway_at_its_closing_speed():
    """Calm air, no turbulence: on a 1 % upslope the runway rises towards the aircraft at s V = 0.65 m/s, twice
    the touchdown sink aimed at. A flare blind to it would touch down with the closing speed moved by about that
    much; flown on the gear's closing speed (radio altitude), the touchdown closing speed stays within a quarter
    of it of the level runway's, on either slope, and the touching gear is at the sloped surface."""
    got = {}
    for slope in (0.0, 1.0, -1.0):
        ap = Approach(_profile(runway={"slope_percent": slope}, environment={"wind_speed_kt": 0.0,
                                                                             "turbulence": "none"}), land=True)
        res = ap.fly(seed=1, run=0)
        assert res.termination == "touchdown", res.termination
        from approachsim.evaluate.touchdown import touchdown_scalars

        sc = touchdown_scalars(res.truth, ap.main_gear_lever_arms_m, ap.ground_contact_m, slope=slope / 100.0)
        assert abs(sc["td_gear_height_m"]) < 0.03  # JSBSim's weight on wheels at first compression, on the slope
        got[slope] = sc["td_sink_mps"]
    s_v = 0.01 * 70.0
    assert abs(got[1.0] - got[0.0]) < 0.25 * s_v and abs(got[-1.0] - got[0.0]) < 0.25 * s_v, got
