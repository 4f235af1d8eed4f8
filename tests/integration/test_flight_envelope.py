"""The approach envelope, flown in JSBSim: every combination of the envelope design flies from the start to
50 ft within the flight-technical-error limits; profiles outside the aircraft's limits are refused with one
line; a flight made to fail ends with its reason and a non-zero exit; terrain is checked and read; JSBSim's
atmosphere is the hydrostatic one the baro model inverts.

Limits between 1000 and 200 ft above the threshold (true IMU state, deviations from the runway geometry):
vertical RMS <= 5 ft (light) / 10 ft (moderate), lateral <= 10 / 20 ft, speed through the mean air mass
within +-5 kt of the target (3 s mean; the instantaneous gusty CAS is reported in docs/envelope.md), fitted
flight-path angle within 0.1 deg of the glidepath, 50 ft reached within 300 ft along-track of where the
glidepath puts it. Every one of the 28 combinations passes on its seeded flight (docs/envelope.md has the
figures; a sweep of four seeds per combination is in the aircraft file's autopilot comments).
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.config import ProfileError
from approachsim.flight.envelope_study import admissible, cases, measure, profile_dict
from approachsim.flight.fdm import FDM
from approachsim.flight.run import Approach
from approachsim.profile import parse_profile
from approachsim.sensors import atmosphere as atm

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "tests" / "data" / "default-py.toml"
BASE = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
LIMITS = {"light": (5.0, 10.0), "moderate": (10.0, 20.0)}


def _params():
    out = []
    for c in cases():
        out.append(pytest.param(c, id=f"{c.index:02d}-{c.wind.replace(' ', '')}-{c.turbulence}"))
    return out


@pytest.mark.parametrize("case", _params())
def test_every_envelope_combination_flies_inside_the_limits(case):
    c = admissible(BASE, case, DEFAULT)
    approach = Approach(parse_profile(profile_dict(BASE, c), source=DEFAULT))
    m = measure(approach, seed=1000 + c.index)
    assert m["ok"], m["termination"]
    v_lim, l_lim = LIMITS[c.turbulence]
    assert m["vertical_rms_ft"] <= v_lim, m
    assert m["lateral_rms_ft"] <= l_lim, m
    assert -5.0 <= m["airmass_err_min_kt"] and m["airmass_err_max_kt"] <= 5.0, m
    assert abs(m["path_err_deg"]) <= 0.1, m
    assert abs(m["x50_err_ft"]) <= 300.0, m


def test_the_design_covers_every_level():
    cs = [admissible(BASE, c, DEFAULT) for c in cases()]
    assert len(cs) >= 24
    assert {c.wind for c in cs} >= {"headwind 10 kt", "headwind 20 kt", "headwind 25 kt", "crosswind 15 kt",
                                     "crosswind 25 kt", "tailwind 15 kt", "calm"}
    assert {c.turbulence for c in cs} == {"light", "moderate"}
    assert {c.isa_dev_c for c in cs} == {-30.0, 0.0, 30.0}
    assert {c.elevation_ft for c in cs} == {0.0, 5000.0, 8000.0}
    assert {c.glidepath_deg for c in cs} == {2.5, 3.0, 3.5}


def _prof(**env):
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["runway"].update(env.pop("runway", {}))
    d["environment"].update(env)
    return d


@pytest.mark.parametrize(("edit", "field", "words"), [
    ({"wind_speed_kt": 20.0, "wind_from_deg": 118.0}, "environment.wind_speed_kt", "tailwind component 20 kt"),
    ({"wind_speed_kt": 35.0, "wind_from_deg": 28.0}, "environment.wind_speed_kt", "crosswind component 35 kt"),
    ({"wind_speed_kt": 30.0, "wind_from_deg": 298.0}, "environment.wind_speed_kt", "headwind component 30 kt"),
    ({"runway": {"glidepath_deg": 7.0}}, "runway.glidepath_deg", "7 deg"),
    ({"runway": {"elevation_ft": 10000.0}}, "runway.elevation_ft", "10000 ft"),
    ({"turbulence": "severe"}, "environment.turbulence", "severe"),
    ({"runway": {"elevation_ft": 8000.0, "glidepath_deg": 3.5}, "isa_dev_C": 30.0, "wind_speed_kt": 10.0,
      "wind_from_deg": 118.0}, "runway.glidepath_deg", "ft/min"),
])
def test_outside_the_envelope_is_refused_naming_the_limit(edit, field, words):
    with pytest.raises(ProfileError) as e:
        Approach(parse_profile(_prof(**edit), source=DEFAULT))
    assert str(e.value).startswith(field)
    assert words in str(e.value)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("command", ["fly", "evaluate"])
def test_outside_the_envelope_exits_2_through_the_cli(tmp_path, command):
    """fly refuses it; evaluate refuses it before any run (not as one failed run per worker, exit 3)."""
    text = DEFAULT.read_text(encoding="utf-8").replace("wind_speed_kt = 5.0", "wind_speed_kt = 20.0").replace(
        "wind_from_deg = 300.0", "wind_from_deg = 118.0")
    prof = tmp_path / "profiles" / "tail15.toml"
    prof.parent.mkdir()
    prof.write_text(text, encoding="utf-8")
    (tmp_path / "aircraft").mkdir()
    (tmp_path / "aircraft" / "737.toml").write_text((ROOT / "aircraft" / "737.toml").read_text(), encoding="utf-8")
    extra = ["--runs", "2", "--no-report"] if command == "evaluate" else []
    r = subprocess.run([sys.executable, "-m", "approachsim", command, str(prof), "--out", str(tmp_path / "o"), *extra],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "tailwind component 20 kt exceeds the 737's 15 kt limit" in lines[0]


def test_a_flight_made_to_fail_ends_with_its_reason_and_exit_3(tmp_path):
    """Glidepath gains x 0.1 (the classic law's and TECS's pitch channel, whichever the file flies): the aircraft
    drifts off the glidepath below 1000 ft; the stabilized-approach monitor ends the flight, `fly` writes its
    outputs and exits 3 saying why."""
    ac = (ROOT / "aircraft" / "737.toml").read_text(encoding="utf-8")
    for key in ("k_gs_p", "k_gs_d", "k_gs_i", "tecs_k_pitch_damp", "tecs_k_pitch_i"):
        ac, n = re.subn(rf"^{key} = ([0-9.eE+-]+)", lambda m, k=key: f"{k} = {float(m.group(1)) * 0.1:.6g}", ac,
                        count=1, flags=re.M)
        assert n == 1, key
    ac = ac.replace('name = "737"', 'name = "737weak"', 1)
    (tmp_path / "aircraft").mkdir()
    (tmp_path / "aircraft" / "737weak.toml").write_text(ac, encoding="utf-8")
    (tmp_path / "profiles").mkdir()
    (tmp_path / "profiles" / "737weak.toml").write_text(ac, encoding="utf-8")  # also beside the profile
    text = DEFAULT.read_text(encoding="utf-8").replace('name = "737"', 'name = "737weak"').replace(
        'turbulence = "light"', 'turbulence = "moderate"').replace("start_distance_nmi = 10.0",
                                                                   "start_distance_nmi = 6.0")
    prof = tmp_path / "profiles" / "weak.toml"
    prof.write_text(text, encoding="utf-8")
    r = subprocess.run([sys.executable, "-m", "approachsim", "fly", str(prof), "--out", str(tmp_path / "o"),
                        "--no-figures"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 3, r.stdout + r.stderr
    assert "failed approach: unstabilized at" in r.stderr
    assert (tmp_path / "o" / "flight.json").is_file()


def test_terrain_ridge_and_valley_are_read_by_the_radar_altimeter():
    """A 600 ft ridge and a 250 ft valley under the approach: the radar altimeter (seed noise on) reads the
    height above them within its noise (normalized residual mean ~0, RMS ~1 over the samples in range)."""
    from approachsim.sensors.suite import SensorSuite

    d = _prof(turbulence="none")
    d["runway"]["start_distance_nmi"] = 6.0
    d["terrain"] = {"distance_nmi": [6.0, 4.0, 3.5, 3.0, 2.5, 2.0, 1.5, 0.0],
                    "height_ft": [13.0, 13.0, 613.0, 13.0, 13.0, -237.0, 13.0, 13.0]}
    prof = parse_profile(d, source=DEFAULT)
    res = Approach(prof).fly(seed=3)
    assert res.ok, res.termination
    tr = res.truth
    agl_geom = tr.h_m - prof.terrain.height_at(tr.r_rwy[:, 0])
    np.testing.assert_allclose(tr.h_agl_m, agl_geom, atol=1e-6)
    assert agl_geom.max() - agl_geom.min() > 0.0
    rec = SensorSuite.from_profile(prof).measure(tr, seed=3, runs=[0])["radalt"]
    rows = np.searchsorted(tr.t_s, rec.t_s)
    meas = np.asarray(rec.h_agl_m)[0]
    ok = np.asarray(rec.valid)[0] & np.isfinite(meas)
    z = (meas[ok] - agl_geom[rows][ok]) / np.asarray(rec.sigma_m)[0][ok]
    assert z.size > 60
    assert abs(z.mean()) < 4.0 / math.sqrt(z.size)
    assert 0.75 < np.sqrt(np.mean(z**2)) < 1.25
    x = tr.r_rwy[rows][ok, 0] / units.NMI
    over_ridge = (x > -3.6) & (x < -3.4)
    over_valley = (x > -2.1) & (x < -1.9)
    h_gp = prof.runway.glidepath_height_m(tr.r_rwy[rows][ok, 0])
    assert np.all(meas[ok][over_ridge] < h_gp[over_ridge] - 150.0)  # reads the ridge, ~600 ft less
    assert np.all(meas[ok][over_valley] > h_gp[over_valley] + 50.0)  # reads the valley, ~250 ft more


@pytest.mark.parametrize(("elevation_ft", "isa_dev_c"), [(0.0, -30.0), (5000.0, 30.0), (8000.0, 0.0)])
def test_jsbsim_atmosphere_is_the_hydrostatic_model(elevation_ft, isa_dev_c):
    """JSBSim's static pressure at the trimmed start equals sensors.atmosphere's ISA+dT pressure with the
    profile's sea-level pressure (the truth the baro model inverts), and an altimeter set to QNH reads the
    (geometric) field elevation at the field."""
    d = _prof(isa_dev_C=isa_dev_c, qnh_hPa=1002.0, runway={"elevation_ft": elevation_ft})
    prof = parse_profile(d, source=DEFAULT)
    a = Approach(prof)
    fdm = FDM(a.aircraft.jsbsim_model, a.dt_s)
    fdm.initialize_and_trim(a.start())
    h = atm.geopotential_m(fdm["position/geod-alt-ft"] * units.FT)
    p_model = atm.static_pressure_pa(h, prof.environment.isa_dev_k, prof.environment.sea_level_pa)
    assert fdm["atmosphere/P-psf"] * units.PSF == pytest.approx(float(p_model), rel=2e-5)
    h_field = atm.geopotential_m(prof.runway.elevation_m)
    p_field = atm.static_pressure_pa(h_field, prof.environment.isa_dev_k, prof.environment.sea_level_pa)
    # QNH is set so that the altimeter reads the published (geometric) field elevation at the field (issue 39,
    # docs/baro.md), not its geopotential height
    assert float(atm.indicated_altitude_m(p_field, prof.environment.setting_pa)) == pytest.approx(
        prof.runway.elevation_m, abs=1e-6)
