"""Published numbers the compiled kernels freeze at compile time, defined once: the stages that use them
(flight/envelope.py's stabilized-approach monitor and profile checks, flight/turbulence.py's Dryden oracle) import
them from here."""

from __future__ import annotations

from approachsim import units

# --- the stabilized-approach criteria -----------------------------------------------------------------------------
LOC_ANTENNA_PAST_THRESHOLD_M = 3300.0
"""Assumed localizer antenna position past the threshold: a 3000 m runway plus 300 m (no runway length is in
a profile); only the localizer dot's size depends on it."""
STABILIZATION_HEIGHT_M = 1000.0 * units.FT
"""FSF ALAR BN 7.1: stabilized by 1000 ft above the airport in IMC, and stay so below it."""
WATCH_HEIGHT_M = 1400.0 * units.FT
"""The monitor is fed from this height down (its 10 s means are full by 1000 ft at any sink rate below
2400 ft/min); above it the run loop skips it."""
SPEED_HIGH_MPS = 10.0 * units.KT
SPEED_LOW_MPS = 5.0 * units.KT
SINK_LIMIT_MPS = 1000.0 * units.FT / 60.0
SINK_TOLERANCE_MPS = 300.0 * units.FT / 60.0

# --- MIL-F-8785C turbulence intensity table ----------------------------------------------------------------------
POE_ALT_FT = (500.0, 1750.0, 3750.0, 7500.0, 15000.0, 25000.0, 35000.0, 45000.0, 55000.0, 65000.0, 75000.0,
              80000.0)
"""Altitudes of the high-altitude intensity table, ft (MIL-F-8785C fig. 7)."""
POE_SIGMA_FPS = (
    (3.2, 2.2, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    (4.2, 3.6, 3.3, 1.6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    (6.6, 6.9, 7.4, 6.7, 4.6, 2.7, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0),
    (8.6, 9.6, 10.6, 10.1, 8.0, 6.6, 5.0, 4.2, 2.7, 0.0, 0.0, 0.0),
    (11.8, 13.0, 16.0, 15.1, 11.6, 9.7, 8.1, 8.2, 7.9, 4.9, 3.2, 2.1),
    (15.6, 17.6, 23.0, 23.6, 22.1, 20.0, 16.0, 15.1, 12.1, 7.9, 6.2, 5.1),
    (18.7, 21.5, 28.4, 30.2, 30.7, 31.0, 25.2, 23.1, 17.5, 10.7, 8.4, 7.2),
)
"""High-altitude turbulence intensity sigma (ft/s) by probability-of-exceedance index 1..7 (rows) and altitude."""
COEFF_EVERY = 12
"""Steps between re-evaluations of the scale lengths and intensities."""
