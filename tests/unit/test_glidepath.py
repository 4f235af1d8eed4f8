"""The straight glide path cone (approachsim.glidepath) against its definition computed exactly in ECEF: the
elevation angle seen from the GPI above the GPI's horizontal plane."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim import geo
from approachsim.glidepath import GlidePath, deviation_and_rate

LAT, LON, ELEV = math.radians(37.6117), math.radians(-122.3581), 4.0


@pytest.mark.parametrize("heading_deg", [0.0, 45.0, 298.0])
def test_the_cone_is_the_straight_line_from_the_gpi(heading_deg):
    """Points on the runway frame's grid (x to -20 km, y +-150 m, z to 3000 ft): the deviation equals the exact
    height above the GPI's horizontal plane minus tan(gp) times the horizontal distance from the GPI, within 5 mm
    (the second-order drop's neglected terms, module docstring)."""
    frame = geo.RunwayFrame(LAT, LON, ELEV, math.radians(heading_deg))
    gp = GlidePath(math.radians(3.0), 15.24, frame.heading_rad, LAT)
    rng = np.random.default_rng(3)
    x = rng.uniform(-20000.0, 0.0, 400)
    y = rng.uniform(-150.0, 150.0, 400)
    z = rng.uniform(0.0, 915.0, 400)
    # the point: tangent-plane x, y at the threshold, z the ellipsoid height above the threshold's
    r_tan = frame.to_ecef(np.column_stack([x, y, np.zeros_like(x)]))
    lat, lon, _ = geo.ecef_to_geodetic(r_tan)
    r = geo.geodetic_to_ecef(lat, lon, ELEV + z)
    xy = frame.from_ecef(r)[:, :2]
    # exact: the GPI's local vertical and horizontal plane
    gpi = frame.to_ecef(np.array([gp.gpi_m, 0.0, 0.0]))
    lat_g, lon_g, _ = geo.ecef_to_geodetic(gpi)
    gpi = geo.geodetic_to_ecef(lat_g, lon_g, ELEV)
    c = geo.c_ecef_to_ned(lat_g, lon_g)
    ned = (r - gpi) @ c.T
    exact = -ned[:, 2] - math.tan(gp.glidepath_rad) * np.hypot(ned[:, 0], ned[:, 1])
    got = gp.deviation_m(xy[:, 0], xy[:, 1], z)
    assert np.max(np.abs(got - exact)) < 5e-3
    # the curved path it replaces is d^2 / 2R below: metres at 10-20 km
    flat = z - (gp.tch_m - xy[:, 0] * gp.tan_gp)
    far = xy[:, 0] < -10000.0
    assert np.all(flat[far] - got[far] > 7.0)


def test_gpi_tch_and_rate():
    gp = GlidePath(math.radians(3.0), 15.24, 0.3, LAT)
    assert gp.gpi_m == pytest.approx(15.24 / math.tan(math.radians(3.0)))
    assert float(gp.height_m(0.0)) == pytest.approx(15.24, abs=0.01)  # the TCH at the threshold (drop 7 mm)
    # the rate: a point moving along the cone has zero deviation rate
    t, xg, a, b, c = gp.constants()
    x, vx = -4000.0, 70.0
    z_dot = vx * (float(gp.height_m(x + 0.5)) - float(gp.height_m(x - 0.5)))
    d, d_dot = deviation_and_rate(x, 0.0, float(gp.height_m(x)), vx, 0.0, z_dot, t, xg, a, b, c)
    assert d == pytest.approx(0.0, abs=1e-9)
    assert d_dot == pytest.approx(0.0, abs=1e-6)
    # scalar form = array form
    assert d == pytest.approx(float(gp.deviation_m(x, 0.0, float(gp.height_m(x)))), abs=1e-9)
