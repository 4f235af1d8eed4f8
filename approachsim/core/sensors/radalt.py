"""Compiled radar altimeter measurement (numba, cache=True): sensors/radalt.py's `RadarAltimeter.apply`;
`RadarAltimeter.apply_reference` is the numpy oracle, equal bit for bit (the same IEEE operations in the same order;
tests/unit/sensors/test_sensor_kernels.py)."""

from __future__ import annotations

import math

import numpy as np

from approachsim.core.jit import njit


@njit(cache=True)
def radalt_apply(h_agl: np.ndarray, pitch: np.ndarray, roll: np.ndarray, bias: np.ndarray, markov: np.ndarray,
                 noise: np.ndarray, percent_sigma: float, floor2_m2: float, max_range_m: float, max_pitch_rad: float,
                 max_roll_rad: float, meas: np.ndarray, sigma: np.ndarray, valid: np.ndarray) -> None:
    """Heights of R runs at m samples, in place into meas, sigma (R, m) m and valid (R, m):

        sigma = sqrt((p h)^2 + floor^2),   h_R = h + b_r + dH_ri + sigma z_ri      (sensors/radalt.py, seed 002)

    valid where 0 <= h <= max_range_m, |pitch| <= max_pitch_rad and |roll| <= max_roll_rad (meas nan elsewhere);
    true height h_agl, pitch, roll (m,) of each sample's truth row; bias b (R,), Markov error dH and unit normals
    z (R, m); floor2_m2 = floor^2 (m^2)."""
    n_run, m = markov.shape
    for i in range(m):
        h = h_agl[i]
        x = percent_sigma * h
        s = math.sqrt(x * x + floor2_m2)
        ok = h >= 0.0 and h <= max_range_m and abs(pitch[i]) <= max_pitch_rad and abs(roll[i]) <= max_roll_rad
        for r in range(n_run):
            v = h + bias[r] + markov[r, i] + s * noise[r, i]
            meas[r, i] = v if ok else math.nan
            sigma[r, i] = s
            valid[r, i] = ok
