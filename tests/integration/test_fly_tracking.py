"""Tracking acceptance (issue 2): the closed-loop 737 follows the glidepath and localizer between 1000 ft and
200 ft above the threshold, truth navigation.

- default profile, light turbulence, 10 seeds: vertical RMS <= 5 ft and lateral RMS <= 10 ft in every seed;
- default profile in calm air: <= 1 ft both;
- hot-high-crosswind: reaches 50 ft, vertical RMS <= 10 ft, lateral RMS <= 20 ft;
- a biased navigation source moves the aircraft off the path by the bias (guidance really flies on it).

The vertical deviation is recomputed here from the runway geometry in ECEF (independent of the truth's
`gs_dev_m`, which approachsim.glidepath computes from the runway-frame coordinates with a second-order Earth
curvature): the threshold point and its local vertical from the WGS-84 formulas, the along-track distance
x = (r - r_thr) . u_along, the ellipsoid height by fixed-point iteration (Hofmann-Wellenhof, Lichtenegger & Wasle,
*GNSS*, eq. 5.48). The glide path is the straight ILS cone from the GPI (TCH / tan(gamma) past the threshold):
height above the GPI's horizontal plane minus tan(gamma) times the horizontal distance from the GPI, the GPI's
vertical turned from the threshold's by x_gpi / R (R = 6371 km: a 0.5 % radius error moves the result by 2 cm at
10 km). Until issue 25 the glidepath held the height above the threshold's ellipsoid height at tch - x tan(gamma),
which follows the Earth's curvature, (x - x_gpi)^2 / (2 R) below the cone: the calm default approach flew 3.7 ft
RMS / 7.7 ft max low against the straight line over 1000-200 ft.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.flight.run import Approach, TruthSource, tracking_stats
from approachsim.profile import load_profile, parse_profile

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]


A_WGS84_M = 6378137.0
E2_WGS84 = 6.69437999014e-3


def _ecef(lat: float, lon: float, h: float) -> np.ndarray:
    n = A_WGS84_M / math.sqrt(1.0 - E2_WGS84 * math.sin(lat) ** 2)
    return np.array([(n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
                     (n * (1.0 - E2_WGS84) + h) * math.sin(lat)])


def _height_m(r: np.ndarray) -> np.ndarray:
    """Ellipsoid height of ECEF points (n, 3) by fixed-point iteration on the latitude, m."""
    p = np.hypot(r[:, 0], r[:, 1])
    lat = np.arctan2(r[:, 2], p * (1.0 - E2_WGS84))
    for _ in range(8):
        n = A_WGS84_M / np.sqrt(1.0 - E2_WGS84 * np.sin(lat) ** 2)
        h = p / np.cos(lat) - n
        lat = np.arctan2(r[:, 2], p * (1.0 - E2_WGS84 * n / (n + h)))
    return h


def glidepath_deviation(r_ecef: np.ndarray, runway) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(height above threshold, deviation from the straight glide path cone, deviation from the old path that
    followed the Earth's curvature), m, from ECEF positions and the runway's threshold, heading, glidepath angle
    and TCH."""
    lat, lon = runway.threshold_lat_rad, runway.threshold_lon_rad
    r_thr = _ecef(lat, lon, runway.elevation_m)
    up = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
    north = np.array([-math.sin(lat) * math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat)])
    east = np.array([-math.sin(lon), math.cos(lon), 0.0])
    u_along = math.cos(runway.heading_rad) * north + math.sin(runway.heading_rad) * east
    tan_gp = math.tan(runway.glidepath_rad)
    x = (r_ecef - r_thr) @ u_along
    path = runway.tch_m - x * tan_gp
    hat = _height_m(r_ecef) - runway.elevation_m
    x_gpi = runway.tch_m / tan_gp
    tilt = x_gpi / 6.371e6  # the GPI's vertical, turned towards the landing direction
    up_g = (up + tilt * u_along) / math.hypot(1.0, tilt)
    r_gpi = r_thr + x_gpi * u_along - 0.5 * x_gpi * tilt * up  # on the ellipsoid (7 mm below the tangent plane)
    v = r_ecef - r_gpi
    h_g = v @ up_g
    horiz = np.linalg.norm(v - np.outer(h_g, up_g), axis=1)
    return hat, h_g - tan_gp * horiz, hat - path


def _segment_rms_ft(r_ecef: np.ndarray, runway) -> tuple[float, float, float]:
    """RMS deviation (ft) from the straight glide path cone and from the old curved path, and max from the cone,
    while the aircraft is between 1000 ft and 200 ft above the threshold."""
    hat, dev_line, dev = glidepath_deviation(r_ecef, runway)
    sel = (hat <= 1000.0 * units.FT) & (hat >= 200.0 * units.FT)
    return (float(np.sqrt(np.mean(dev_line[sel] ** 2)) / units.FT), float(np.sqrt(np.mean(dev[sel] ** 2)) / units.FT),
            float(np.max(np.abs(dev_line[sel])) / units.FT))


def _calm_default():
    src = ROOT / "tests" / "data" / "default-py.toml"
    data = tomllib.loads(src.read_text())
    data["environment"].update(turbulence="none", wind_speed_kt=0.0)
    return parse_profile(data, source=src)


def test_default_light_turbulence_ten_seeds():
    profile = load_profile(ROOT / "tests" / "data" / "default-py.toml")
    approach = Approach(profile)
    seed = profile.run.seed
    rows = []
    for run in range(10):
        r = approach.fly(seed=seed, run=run)
        s = tracking_stats(r, profile)
        rows.append((run, r.termination, s["vertical_rms_ft"], s["lateral_rms_ft"]))
        print(f"run {run}: {r.termination}, vertical RMS {s['vertical_rms_ft']:.2f} ft, "
              f"lateral RMS {s['lateral_rms_ft']:.2f} ft")
        assert r.termination == "reached stop height"
        assert s["samples"] > 5000  # the whole 800 ft segment was flown (about 80 s at 120 Hz)
        assert _segment_rms_ft(r.truth.r_ecef, profile.runway)[0] <= 5.0  # from the ECEF geometry
        assert s["lateral_rms_ft"] <= 10.0
    # turbulence is really there: the seeds differ
    assert len({round(v, 6) for _, _, v, _ in rows}) == 10


def test_default_calm_air_within_one_foot():
    profile = _calm_default()
    r = Approach(profile).fly(seed=1)
    s = tracking_stats(r, profile)
    rms, rms_old, max_cone = _segment_rms_ft(r.truth.r_ecef, profile.runway)
    print(s, f"ECEF geometry: {rms:.2f} ft RMS, {max_cone:.2f} ft max from the cone; old curved path {rms_old:.2f} ft")
    assert r.termination == "reached stop height"
    assert rms <= 1.0
    assert s["lateral_rms_ft"] <= 1.0
    # the truth's recorded deviation is the geometric one within the two curvature models' 2 cm (|x| < 10 km)
    _, dev_cone, dev_old = glidepath_deviation(r.truth.r_ecef, profile.runway)
    x = r.truth.r_rwy[:, 0]
    near = np.abs(x) < 10_000.0
    np.testing.assert_allclose(r.truth.gs_dev_m[near], dev_cone[near], rtol=0, atol=0.02)
    # the old path lies (x - x_gpi)^2 / (2 R) below the cone
    x_gpi = profile.runway.tch_m / math.tan(profile.runway.glidepath_rad)
    assert np.max(np.abs((dev_old - dev_cone) - (x - x_gpi) ** 2 / (2 * 6.371e6))[near]) < 0.03


def test_hot_high_crosswind_reaches_50_ft():
    profile = load_profile(ROOT / "profiles" / "hot-high-crosswind.toml")
    r = Approach(profile).fly(seed=profile.run.seed, run=0)
    s = tracking_stats(r, profile)
    print(r.termination, r.lowest_height_ft, s)
    assert r.reached(50.0)
    assert s["vertical_rms_ft"] <= 10.0
    assert s["lateral_rms_ft"] <= 20.0
    # 15 kt direct crosswind: the aircraft crabs (heading off the runway heading by ~6 deg into the wind)
    sel = r.truth.r_rwy[:, 2] < 1000 * units.FT
    psi = r.truth.euler_rad[sel, 2] - profile.runway.heading_rad
    crab = np.degrees(np.angle(np.mean(np.exp(1j * psi))))
    tas = np.mean(r.truth.airspeed_mps[sel]) * 1.1  # 5434 ft, ISA +20: TAS about 1.1 CAS
    # wind from the left (west) of a north runway: nose left by about asin(crosswind / TAS) = 5 deg
    assert crab == pytest.approx(-np.degrees(np.arcsin(profile.environment.wind_speed_mps / tas)), abs=1.5)


class _BiasedSource:
    """Navigation that reports the aircraft 10 m higher than it is."""

    def step(self, k, truth):
        return truth.r_rwy[k] + np.array([0.0, 0.0, 10.0]), truth.v_ned[k]


def test_guidance_flies_on_the_navigation_source():
    profile = _calm_default()
    approach = Approach(profile)
    base = approach.fly(seed=1)
    explicit = approach.fly(seed=1, nav_source=TruthSource())
    np.testing.assert_array_equal(base.truth.r_rwy, explicit.truth.r_rwy)
    biased = approach.fly(seed=1, nav_source=_BiasedSource())
    t = biased.truth
    sel = (t.r_rwy[:, 2] < 1000 * units.FT) & (t.r_rwy[:, 2] > 200 * units.FT)
    # guidance holds its estimate on the path, so the true aircraft is 10 m low
    assert np.mean(t.gs_dev_m[sel]) == pytest.approx(-10.0, abs=0.5)
    fte = biased.guidance_r_rwy[sel, 2] - np.asarray(profile.runway.glidepath_height_m(biased.guidance_r_rwy[sel, 0]))
    assert np.sqrt(np.mean(fte**2)) < 1.0
    np.testing.assert_allclose(biased.guidance_r_rwy[:, 2] - t.r_rwy[:, 2], 10.0)


def test_calm_landing_flares_to_a_touchdown_in_the_zone():
    """Landing run: the flare brings the main gear down in the touchdown zone at the flare law's own touchdown
    sink, within 0.3 ft/s in still air. The feed-forwards carry the nominal flare (path, speed, ground effect) and
    the slow PI (0.65 rad/s crossover, below the gust band) takes up only part of what they miss: measured 1.77 ft/s
    here and 1.89 ft/s at 20 kt crosswind (docs/touchdown.md sec. 4); the 0.5 ft/s goal of issue 40 is for the
    turbulent mean, whose first-passage weighting adds 0.3-0.6 ft/s, so a calm miss beyond 0.3 ft/s would leave it
    no room. The earlier slow loop with the retard at 25 ft landed here at 3.3-3.5 ft/s."""
    profile = _calm_default()
    approach = Approach(profile, land=True)
    r = approach.fly(seed=1)
    print(r.termination, r.touchdown_x_m / units.FT, r.touchdown_sink_mps / units.FPS)
    assert r.termination == "touchdown"  # main gear first (nose-gear contact is "ground contact")
    assert 1000.0 <= r.touchdown_x_m / units.FT <= 3000.0  # FAA touchdown zone: the first 3000 ft
    target = approach.aircraft.gains.touchdown_sink_mps
    assert abs(r.touchdown_sink_mps - target) / units.FPS <= 0.3  # ft/s; 10 ft/s is a hard landing
    # the flare raised the nose above the approach attitude
    t = r.truth
    assert t.euler_rad[-1, 1] > np.median(t.euler_rad[:, 1]) + np.radians(1.0)


def test_calm_tailwind_landing_lands_main_gear_first_above_the_floor():
    """The 10 kt tailwind limit condition (logarithmic boundary layer, z0 0.15 ft) in still air: the tailwind falls
    off toward the ground, the airspeed rises through the flare (143.9 kt at 50 ft against the 140 kt target) and the
    flare's speed, gust and ground-effect feed-forwards take the pitch down to 0.67 deg at touchdown with thrust
    kept. The nose-gear floor (aircraft file flare_pitch_min_deg, held below flare_pitch_min_height_ft with the
    throttle at idle while it holds) lands it main gear first above the floor, at the law's touchdown sink within
    0.5 ft/s (1.92 measured), in the touchdown zone; with the floor taken out the same flight touches down below it
    (the check can fail)."""
    import dataclasses

    src = ROOT / "tests" / "data" / "default-py.toml"
    data = tomllib.loads(src.read_text())
    data["environment"].update(wind_speed_kt=10.0, wind_from_deg=(data["runway"]["heading_true_deg"] + 180.0) % 360,
                               turbulence="none", wind_profile="log")
    approach = Approach(parse_profile(data, source=src), land=True)
    g = approach.aircraft.gains
    r = approach.fly(seed=1)
    pitch = r.truth.euler_rad[-1, 1]
    print(r.termination, r.touchdown_x_m / units.FT, r.touchdown_sink_mps / units.FPS, math.degrees(pitch))
    assert r.termination == "touchdown"  # main gear first (nose-gear contact is "ground contact")
    assert pitch >= g.flare_pitch_min_rad
    assert abs(r.touchdown_sink_mps - g.touchdown_sink_mps) / units.FPS <= 0.5
    assert 1000.0 <= r.touchdown_x_m / units.FT <= 3000.0
    approach.aircraft = dataclasses.replace(approach.aircraft, gains=dataclasses.replace(
        g, flare_pitch_min_rad=-math.pi / 2.0))
    r = approach.fly(seed=1)
    print("no floor:", r.termination, math.degrees(r.truth.euler_rad[-1, 1]))
    assert r.truth.euler_rad[-1, 1] < g.flare_pitch_min_rad


def test_crosswind_landing_is_decrabbed_at_touchdown():
    """20 kt direct crosswind from the right, light turbulence, three seeded landings: the decrab leaves a drift
    (wheel-slip) angle of at most 5 deg at the main gear (before issue 25: 8.7 +- 1.1 deg over 1000 landings, all
    above 5 deg), the crab the partial decrab leaves (the wind correction asin(crosswind / V) beyond the sideslip
    limit, 8.1 - 5.0 = 3.1 deg at 140 kt; 4.0 +- 0.55 deg over 200 landings, [2.7, 5.6]) within 2 deg, the bank below
    the 12 deg wing-tip criterion, and the main gear on the runway's touchdown zone, within 10 ft of the centreline
    (the alignment from 450 ft steers the main gear onto it: -1.95 +- 1.22 ft over 200 landings, [-5.4, 2.0])."""
    src = ROOT / "tests" / "data" / "default-py.toml"
    data = tomllib.loads(src.read_text())
    data["environment"].update(wind_speed_kt=20.0, wind_from_deg=(data["runway"]["heading_true_deg"] + 90.0) % 360)
    approach = Approach(parse_profile(data, source=src), land=True)
    g, v = approach.aircraft.gains, approach.aircraft.approach_speed_mps
    b_max = min(g.align_sideslip_max_rad, g.align_bank_max_rad / (g.k_phi_align * (v / g.align_cas_mps) ** 2))
    crab_res_deg = math.degrees(math.asin(approach.profile.environment.wind_speed_mps / v) - b_max)
    for run in range(3):
        r = approach.fly(seed=1, run=run)
        print(r.termination, r.touchdown_x_m / units.FT, r.touchdown_y_m / units.FT,
              math.degrees(r.touchdown_drift_rad), math.degrees(r.touchdown_crab_rad))
        assert r.termination == "touchdown"
        assert abs(math.degrees(r.touchdown_drift_rad)) <= 5.0
        assert math.degrees(r.touchdown_crab_rad) == pytest.approx(crab_res_deg, abs=2.0)
        assert abs(math.degrees(r.truth.euler_rad[-1, 0])) < 12.0
        assert 1000.0 <= r.touchdown_x_m / units.FT <= 3000.0
        assert abs(r.touchdown_y_m) < 15.0  # m: the lateral criterion in use (docs/touchdown.md)
        assert abs(r.touchdown_y_m / units.FT) < 10.0  # 6.6 sd of the 200 landings' spread from their mean
