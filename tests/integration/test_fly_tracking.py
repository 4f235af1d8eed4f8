"""Tracking acceptance (issue 2): the closed-loop 737 follows the glidepath and localizer between 1000 ft and
200 ft above the threshold, truth navigation.

- default profile, light turbulence, 10 seeds: vertical RMS <= 5 ft and lateral RMS <= 10 ft in every seed;
- default profile in calm air: <= 1 ft both;
- hot-high-crosswind: reaches 50 ft, vertical RMS <= 10 ft, lateral RMS <= 20 ft;
- a biased navigation source moves the aircraft off the path by the bias (guidance really flies on it).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.flight.run import Approach, TruthSource, tracking_stats
from approachsim.profile import load_profile, parse_profile

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]


def _calm_default():
    src = ROOT / "profiles" / "default.toml"
    data = tomllib.loads(src.read_text())
    data["environment"].update(turbulence="none", wind_speed_kt=0.0)
    return parse_profile(data, source=src)


def test_default_light_turbulence_ten_seeds():
    profile = load_profile(ROOT / "profiles" / "default.toml")
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
        assert s["vertical_rms_ft"] <= 5.0
        assert s["lateral_rms_ft"] <= 10.0
    # turbulence is really there: the seeds differ
    assert len({round(v, 6) for _, _, v, _ in rows}) == 10


def test_default_calm_air_within_one_foot():
    profile = _calm_default()
    r = Approach(profile).fly(seed=1)
    s = tracking_stats(r, profile)
    print(s)
    assert r.termination == "reached stop height"
    assert s["vertical_rms_ft"] <= 1.0
    assert s["lateral_rms_ft"] <= 1.0


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
    """Landing run: the flare brings the main gear down in the touchdown zone with a normal sink rate."""
    profile = _calm_default()
    r = Approach(profile, land=True).fly(seed=1)
    print(r.termination, r.touchdown_x_m / units.FT, r.touchdown_sink_mps / units.FPS)
    assert r.termination == "touchdown"  # main gear first (nose-gear contact is "ground contact")
    assert 1000.0 <= r.touchdown_x_m / units.FT <= 3000.0  # FAA touchdown zone: the first 3000 ft
    assert 0.5 <= r.touchdown_sink_mps / units.FPS <= 6.0  # ft/s; 10 ft/s is a hard landing
    # the flare raised the nose above the approach attitude
    t = r.truth
    assert t.euler_rad[-1, 1] > np.median(t.euler_rad[:, 1]) + np.radians(1.0)
