"""Truth record properties that need JSBSim: in-process determinism, terrain under the approach, the IMU lever
arm, the navigation-source call contract."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import units
from approachsim.flight.run import Approach
from approachsim.profile import load_profile, parse_profile

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "tests" / "data" / "default-py.toml"


def test_runs_are_reproducible_within_one_process():
    """A run depends only on (seed, run): flying others in between changes nothing."""
    a = Approach(load_profile(DEFAULT))
    first = a.fly(seed=5, run=2, max_time_s=20.0)
    a.fly(seed=6, run=0, max_time_s=20.0)
    again = a.fly(seed=5, run=2, max_time_s=20.0)
    for name, arr in first.truth.arrays().items():
        np.testing.assert_array_equal(arr, getattr(again.truth, name), err_msg=name)
    other = a.fly(seed=5, run=3, max_time_s=20.0)
    assert not np.array_equal(first.truth.f_body, other.truth.f_body)


def test_height_above_terrain_uses_the_profile_terrain():
    data = tomllib.loads(DEFAULT.read_text())
    data["terrain"] = {"distance_nmi": [12.0, 8.0, 0.0], "height_ft": [13.0, 1013.0, 13.0]}
    profile = parse_profile(data, source=DEFAULT)
    r = Approach(profile).fly(seed=1, max_time_s=30.0)
    t = r.truth
    terrain = profile.terrain.height_at(t.r_rwy[:, 0])
    np.testing.assert_allclose(t.h_agl_m, t.h_m - terrain, atol=1e-9)
    # 10 nmi out the ridge is 500 ft high under a 3200 ft glidepath
    assert t.h_agl_m[0] == pytest.approx(t.r_rwy[0, 2] + profile.runway.elevation_m - 513 * units.FT, abs=0.5)


def test_imu_velocity_is_the_derivative_of_the_imu_position():
    """Position and velocity are both of the IMU point (9.2 m ahead of the CG): the central difference of
    r_ecef matches v_ned rotated to ECEF to a few mm/s. The lever-arm velocity C_nb (w x l) is 0.1-0.5 m/s
    in turbulence, so a missing or wrong lever-arm term would fail this by two orders of magnitude."""
    from approachsim import geo

    a = Approach(load_profile(DEFAULT))
    assert a.aircraft.imu_location_struct_m[0] < 611 * 0.0254  # ahead of the CG (x aft)
    t = a.fly(seed=1, max_time_s=30.0).truth
    dt = float(t.t_s[1] - t.t_s[0])
    v_fd = (t.r_ecef[2:] - t.r_ecef[:-2]) / (2 * dt)
    c_ne = np.swapaxes(geo.c_ecef_to_ned(t.lat_rad[1:-1], t.lon_rad[1:-1]), -1, -2)
    v_ecef = np.einsum("nij,nj->ni", c_ne, t.v_ned[1:-1])
    err = np.max(np.abs(v_fd - v_ecef))
    lever = np.max(np.abs(t.w_ib_body[:, 1])) * 9.0
    assert err < 0.02, err
    assert lever > 5 * err


class _CountingSource:
    def __init__(self):
        self.seen = []

    def step(self, k, truth):
        assert np.isfinite(truth.f_body[k]).all() and np.isfinite(truth.r_ecef[k]).all()
        if k + 1 < len(truth):
            assert np.isnan(truth.t_s[k + 1])  # rows after k are not filled yet
        self.seen.append(k)
        return truth.r_rwy[k], truth.v_ned[k]


def test_navigation_source_is_called_once_per_row_in_order():
    src = _CountingSource()
    r = Approach(load_profile(DEFAULT)).fly(seed=1, nav_source=src, max_time_s=5.0)
    assert src.seen == list(range(len(r.truth)))
    np.testing.assert_array_equal(r.guidance_r_rwy, r.truth.r_rwy)
    # the default (truth) path keeps its rows in a list: it must give the very same record
    default = Approach(load_profile(DEFAULT)).fly(seed=1, max_time_s=5.0)
    for name, arr in default.truth.arrays().items():
        np.testing.assert_array_equal(arr, getattr(r.truth, name), err_msg=name)
