"""Seed 002's figure of merit: time-averaged RMS error of latitude, longitude, altitude and clock bias, ft.

Gray & Maybeck (1995) Tables 3-6 give "time-averaged rms errors" in feet per error state. Each run
contributes the time average of its squared error over the approach; the campaign figure is the square
root of the mean over runs of those averages (RMS over time and runs). Latitude and longitude errors are
expressed as distances at the aircraft ((R_N + h) dlat, (R_E + h) cos(lat) dlon), i.e. the north and east
components of the position error.
"""

from __future__ import annotations

import numpy as np

from approachsim import units
from approachsim.evaluate.dh import ecef_to_ned_vectors
from approachsim.records import NavSolution, Truth

STATES = ("latitude", "longitude", "altitude", "clock_bias")


def state_errors_m(
    truth: Truth, nav: NavSolution, clock_bias_true_m: np.ndarray | None = None, e_ned: np.ndarray | None = None
) -> dict[str, np.ndarray]:
    """Per-epoch errors (estimate - truth), m: latitude and longitude as distances, altitude, clock bias.

    The position error is rotated into local NED at the true position (north = latitude error as a distance,
    east = longitude error, up = altitude error; exact to |error|^2 / R, under a micrometre); e_ned may be
    passed when already computed. clock_bias_true_m: the receiver's true clock bias (from the GNSS sensor)
    on the truth's time base, or None (clock error nan).
    """
    n = min(len(truth), nav.t_s.shape[0])
    if e_ned is None:
        e_ned = ecef_to_ned_vectors(nav.r_ecef[:n] - truth.r_ecef[:n], truth.lat_rad[:n], truth.lon_rad[:n])
    out = {"latitude": e_ned[:n, 0], "longitude": e_ned[:n, 1], "altitude": -e_ned[:n, 2]}
    if clock_bias_true_m is None:
        out["clock_bias"] = np.full(n, np.nan)
    else:
        out["clock_bias"] = nav.clock_bias_m[:n] - np.asarray(clock_bias_true_m)[:n]
    return out


def mean_square_ft2(errors_m: dict[str, np.ndarray], window: np.ndarray | slice = slice(None)) -> dict[str, float]:
    """One run's time-averaged squared error per state over the samples `window`, ft^2 (nan: no series)."""
    return {k: float(np.mean((errors_m[k][window] / units.FT) ** 2)) for k in STATES}


def campaign_rms_ft(per_run_ms_ft2: dict[str, np.ndarray]) -> dict[str, float]:
    """sqrt(mean over runs of the time-averaged squared errors), ft; runs with nan are left out."""
    out = {}
    for k in STATES:
        v = np.asarray(per_run_ms_ft2[k], dtype=float)
        v = v[np.isfinite(v)]
        out[k] = float(np.sqrt(np.mean(v))) if v.size else float("nan")
    return out
