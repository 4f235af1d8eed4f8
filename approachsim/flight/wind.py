"""The mean wind against height: the profile's reported wind as a logarithmic boundary layer, plus a linear shear
layer (the readable oracle of core/loop/flight_step.py `mean_wind`).

Logarithmic boundary layer (neutral surface layer; the form MIL-F-8785C sec. 3.7.3.3 gives for the mean wind,
[S] through MathWorks' Aerospace Blockset "Wind Shear Model", which implements it):

    W(h) = W_ref ln(h / z0) / ln(h_ref / z0),   h clipped to [LOG_H_MIN_M, LOG_H_TOP_M]

W_ref the reported wind (the profile's wind_speed_kt) at the reference height h_ref (environment
wind_reference_height_m, default 10 m: the height surface wind is measured and reported at, WMO/ICAO practice
[U], not read here; MIL-F-8785C uses 20 ft), z0 the roughness length (default 0.15 ft = 0.046 m, MIL-F-8785C's
value for Category C, the terminal flight phases, [S] same source; open flat country with low grass is
0.01-0.05 m, Wieringa's classification [U]). The law holds from 3 ft to 1000 ft in MIL-F-8785C: heights are clipped
there, so the wind is W(1000 ft) above (1.56 W_ref with the defaults) and W(3 ft) below. Direction does not turn
with height (no Ekman veer).

Shear layer: from shear_top down to shear_bottom the headwind component changes linearly by -loss (a positive
loss is the performance-decreasing shear: a decreasing headwind or an increasing tailwind), the whole change held
below shear_bottom.

JSBSim carries the wind at the start height as its steady wind (trim.start_condition); the loop adds the difference
W(h) - W(h_start) at the CG's height above the terrain to the gusts it writes (core/loop/flight_step.py fly_step).
"""

from __future__ import annotations

import math

from approachsim import units

LOG_H_MIN_M = 3.0 * units.FT
"""Lowest height of MIL-F-8785C's log law (3 ft); heights below are clipped to it."""
LOG_H_TOP_M = 1000.0 * units.FT
"""Top of MIL-F-8785C's log law (1000 ft); the wind is held above it."""


def log_factor(h_m: float, z0_m: float, ref_m: float) -> float:
    """W(h) / W_ref of the logarithmic layer at height h_m above the terrain (m)."""
    h = min(max(h_m, LOG_H_MIN_M), LOG_H_TOP_M)
    return math.log(h / z0_m) / math.log(ref_m / z0_m)


def shear_fraction(h_m: float, top_m: float, bottom_m: float) -> float:
    """Fraction of the shear layer's change in force at height h_m: 0 above the top, 1 below the bottom."""
    if h_m >= top_m:
        return 0.0
    if h_m <= bottom_m:
        return 1.0
    return (top_m - h_m) / (top_m - bottom_m)


def mean_wind_ned(env: object, h_m: float) -> tuple[float, float]:
    """The mean wind (north, east, m/s; where the air moves to) at height h_m above the terrain in the profile's
    environment (profile.Environment)."""
    w, frm = env.wind_speed_mps, env.wind_from_rad  # type: ignore[attr-defined]
    wn, we = -w * math.cos(frm), -w * math.sin(frm)  # the reference wind, as flight/run.py packs it
    f = 1.0
    if env.wind_profile == "log":  # type: ignore[attr-defined]
        f = log_factor(h_m, env.roughness_length_m, env.wind_reference_height_m)  # type: ignore[attr-defined]
    s = shear_fraction(h_m, env.shear_top_m, env.shear_bottom_m)  # type: ignore[attr-defined]
    return wn * f + s * env.shear_n_mps, we * f + s * env.shear_e_mps  # type: ignore[attr-defined]


def varies(env: object) -> bool:
    """True when the profile's mean wind changes with height (a log layer or a shear)."""
    return env.wind_profile != "uniform" or env.shear_n_mps != 0.0 or env.shear_e_mps != 0.0  # type: ignore
