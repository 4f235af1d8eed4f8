"""Compiled pseudolite ranging (numba, cache=True): sensors/pseudolite.py's `Pseudolite.apply`; `Pseudolite.
apply_reference` is the numpy oracle (tests/unit/sensors/test_sensor_kernels.py: equal to 1e-12 relative)."""

from __future__ import annotations

import math

import numpy as np

from approachsim.core.jit import njit


@njit(cache=True)
def pseudolite_apply(r_rx: np.ndarray, pub: np.ndarray, c_down: np.ndarray, survey: np.ndarray, tropo_ppm: np.ndarray,
                     multipath: np.ndarray, noise: np.ndarray, pl_clock: np.ndarray, bias: np.ndarray,
                     max_range_m: float, mask_rad: float, pr: np.ndarray, valid: np.ndarray, el: np.ndarray) -> None:
    """Pseudoranges of R runs to p transmitters at m samples (sensors/pseudolite.py), in place:

        rho = |r_PL + dr_survey - r| (1 + 1e-6 T) + m + n + b_PL + b_rx        pr (R, m, p) m, nan where not valid
        el  = asin(up / |r_PL - r|), up = the aircraft's height above the transmitter's local level,
              valid where |r_PL - r| <= max_range_m and el >= mask_rad          el (m, p) rad, valid (R, m, p)

    receivers r_rx (m, 3) and published positions pub (p, 3) ECEF m; c_down (p, 3) the down row of each transmitter's
    ECEF -> NED rotation; per run survey errors (R, p, 3) m and tropo residuals (R, p) ppm; multipath, noise and
    transmitter clock (R, m, p) m; receiver clock bias (R, m) m."""
    n_run = survey.shape[0]
    m, p = r_rx.shape[0], pub.shape[0]
    for i in range(m):
        rx, ry, rz = r_rx[i, 0], r_rx[i, 1], r_rx[i, 2]
        for q in range(p):
            dx, dy, dz = pub[q, 0] - rx, pub[q, 1] - ry, pub[q, 2] - rz
            rp = math.sqrt(dx * dx + dy * dy + dz * dz)
            up = c_down[q, 0] * dx + c_down[q, 1] * dy + c_down[q, 2] * dz
            e = math.asin(min(max(up / rp, -1.0), 1.0))
            el[i, q] = e
            ok = rp <= max_range_m and e >= mask_rad
            for r in range(n_run):
                tx = pub[q, 0] + survey[r, q, 0] - rx
                ty = pub[q, 1] + survey[r, q, 1] - ry
                tz = pub[q, 2] + survey[r, q, 2] - rz
                rt = math.sqrt(tx * tx + ty * ty + tz * tz)
                v = (rt * (1.0 + 1e-6 * tropo_ppm[r, q]) + multipath[r, i, q] + noise[r, i, q] + pl_clock[r, i, q]
                     + bias[r, i])
                pr[r, i, q] = v if ok else math.nan
                valid[r, i, q] = ok
