"""MIL-F-8785C Dryden turbulence at the height above terrain: intensities, scale lengths and the statistics of
the stepped process."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim import units
from approachsim.flight.turbulence import DrydenTurbulence, scales


def test_low_altitude_scales_follow_mil_f_8785c():
    # light (W20 = 25 ft/s) at 500 ft: sigma_w = 2.5 ft/s, sigma_u = sigma_w / (0.177 + 0.000823 h)^0.4,
    # L_u = h / (0.177 + 0.000823 h)^1.2, L_w = h
    L_u, L_w, s_u, s_w = scales(500.0, 25.0, 3)
    den = 0.177 + 0.000823 * 500.0
    assert s_w == pytest.approx(2.5)
    assert s_u == pytest.approx(2.5 / den**0.4)
    assert L_u == pytest.approx(500.0 / den**1.2)
    assert L_w == 500.0


def test_high_altitude_table_and_blend():
    # index 4 (moderate) at 5000 ft: between 10.6 (3750 ft) and 10.1 (7500 ft) of MIL-F-8785C fig. 7
    L_u, L_w, s_u, s_w = scales(5000.0, 50.0, 4)
    assert (L_u, L_w) == (1750.0, 1750.0)
    assert s_u == s_w == pytest.approx(10.6 + (5000 - 3750) / (7500 - 3750) * (10.1 - 10.6))
    # 1500 ft: halfway between the low-altitude value at 1000 ft and the table at 1500 ft
    L, _, s, _ = scales(1500.0, 50.0, 4)
    assert L == pytest.approx(1375.0)
    assert s == pytest.approx(5.0 + 0.5 * (float(np.interp(1500.0, [500, 1750], [8.6, 9.6])) - 5.0))


def test_stepped_process_has_the_specified_intensity():
    """At a fixed height and speed the stationary std of each channel is sigma (within sampling error)."""
    n = 200_000
    dt = 1.0 / 120.0
    h_m = 300.0 * units.FT
    v = 230.0 * units.FPS
    turb = DrydenTurbulence("moderate", np.random.default_rng(42), n, dt, wind_to_rad=0.0)
    out = np.array([turb.step(k, h_m, v) for k in range(n)]) / units.FPS
    L_u, L_w, s_u, s_w = scales(300.0, 50.0, 4)
    # drop the first minute (start from rest); wind towards north: u = north, v = east
    std = out[7200:].std(axis=0)
    assert std[0] == pytest.approx(s_u, rel=0.15)
    assert std[1] == pytest.approx(s_u, rel=0.15)
    assert std[2] == pytest.approx(s_w, rel=0.10)
    # the vertical correlation time is L_w / V: the lag-(tau) autocorrelation of the first-order form is 1/e^2
    w = out[7200:, 2] - out[7200:, 2].mean()
    lag = int(round(L_w / 230.0 / 2.0 / dt))  # the w channel decays at 2/tau
    rho = float(np.dot(w[:-lag], w[lag:]) / np.dot(w, w))
    assert rho == pytest.approx(math.exp(-1.0), abs=0.08)


def test_same_stream_same_turbulence_and_wind_axes():
    a = DrydenTurbulence("light", np.random.default_rng(7), 500, 1 / 120, wind_to_rad=math.pi / 2)
    b = DrydenTurbulence("light", np.random.default_rng(7), 500, 1 / 120, wind_to_rad=math.pi / 2)
    ra = [a.step(k, 100.0, 70.0) for k in range(500)]
    rb = [b.step(k, 100.0, 70.0) for k in range(500)]
    assert ra == rb
    # wind blowing east: the along-wind component u appears in the east axis
    assert a.xi_u * units.FPS == pytest.approx(ra[-1][1])
    with pytest.raises(ValueError):
        DrydenTurbulence("none", np.random.default_rng(1), 10, 0.01, 0.0)
