"""Seed 002's figure of merit: time-averaged RMS error of latitude, longitude, altitude and clock bias, ft.

Gray & Maybeck (1995) Tables 3-6 give "time-averaged rms errors" in feet per error state. Each run
contributes the time average of its squared error over the approach; the campaign figure is the square
root of the mean over runs of those averages (RMS over time and runs). Latitude and longitude errors are
expressed as distances at the aircraft ((R_N + h) dlat, (R_E + h) cos(lat) dlon).
"""

from __future__ import annotations

import numpy as np

from approachsim import units
from approachsim.geo import ecef_to_geodetic, radii
from approachsim.records import NavSolution, Truth

STATES = ("latitude", "longitude", "altitude", "clock_bias")


def state_errors_m(
    truth: Truth, nav: NavSolution, clock_bias_true_m: np.ndarray | None = None
) -> dict[str, np.ndarray]:
    """Per-epoch errors (estimate - truth), m: latitude and longitude as distances, altitude, clock bias.

    clock_bias_true_m: the receiver's true clock bias (from the GNSS sensor), or None (clock error nan).
    """
    n = min(len(truth), nav.t_s.shape[0])
    lat, lon, h = ecef_to_geodetic(nav.r_ecef[:n])
    r_n, r_e = radii(truth.lat_rad[:n])
    dlon = (lon - truth.lon_rad[:n] + np.pi) % (2.0 * np.pi) - np.pi
    out = {
        "latitude": (lat - truth.lat_rad[:n]) * (r_n + truth.h_m[:n]),
        "longitude": dlon * (r_e + truth.h_m[:n]) * np.cos(truth.lat_rad[:n]),
        "altitude": h - truth.h_m[:n],
    }
    if clock_bias_true_m is None:
        out["clock_bias"] = np.full(n, np.nan)
    else:
        out["clock_bias"] = nav.clock_bias_m[:n] - np.asarray(clock_bias_true_m)[:n]
    return out


def mean_square_ft2(errors_m: dict[str, np.ndarray]) -> dict[str, float]:
    """One run's time-averaged squared error per state, ft^2 (nan where the state has no error series)."""
    return {k: float(np.mean((errors_m[k] / units.FT) ** 2)) for k in STATES}


def campaign_rms_ft(per_run_ms_ft2: dict[str, np.ndarray]) -> dict[str, float]:
    """sqrt(mean over runs of the time-averaged squared errors), ft; runs with nan are left out."""
    out = {}
    for k in STATES:
        v = np.asarray(per_run_ms_ft2[k], dtype=float)
        v = v[np.isfinite(v)]
        out[k] = float(np.sqrt(np.mean(v))) if v.size else float("nan")
    return out
