"""Compiled barometric altimeter measurement (numba, cache=True): sensors/baro.py's `Baro.apply`; `Baro.apply_reference`
is the numpy oracle (tests/unit/sensors/test_sensor_kernels.py). They agree to 1e-12 of the ISA scale T0 / L
(44.3 km, i.e. 4.4e-8 m): the indication (T0 / L)(1 - x^e) cancels near sea level, so one rounding of the power
(libm here, numpy's SIMD power there) can be 1e-11 m, a larger part of a small height than 1e-12."""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit


@njit(cache=True)
def baro_apply(p_static: np.ndarray, setting_pa: float, t0_over_lapse_m: float, exponent: float, field_m: float,
               ratio_m1: float, weights: np.ndarray, sf: np.ndarray, bias: np.ndarray, noise: np.ndarray,
               out: np.ndarray) -> None:
    """Baro heights of R runs at m samples, in place into out (R, m), m:

        h_ind = (T0 / L) (1 - (p / p_set)^(R L / g0))        (ISA inverse, sensors/atmosphere.py)
        h_c   = h_ind + (h_ind - H_f) (c - 1)                  (temperature correction; c - 1 = 0: none)
        h     = h_c + (h_c - H_f) S_r + B_ri + v_ri            (sensors/baro.py: the scale factor on the height above
                                                               the altimeter-setting reference H_f, the field)

    p_static (m, n) the static pressure (Pa) of each sample's truth row (column 0) and, with a lag, of the n - 1 rows
    before it; weights (n,) the lag's impulse response (h_ind = sum_l w_l h_ind(p_il), in l order), empty without a
    lag; t0_over_lapse_m = T0 / L (m), exponent = R L / g0; field_m = H_f (m) the field's geopotential elevation (the
    setting's reference), ratio_m1 = c - 1; scale factor sf
    (R,), bias and noise (R, m) m."""
    m = p_static.shape[0]
    lagged = weights.shape[0] > 0
    for i in range(m):
        if lagged:
            h = 0.0
            for q in range(weights.shape[0]):
                h += t0_over_lapse_m * (1.0 - (p_static[i, q] / setting_pa) ** exponent) * weights[q]
        else:
            h = t0_over_lapse_m * (1.0 - (p_static[i, 0] / setting_pa) ** exponent)
        h = h + (h - field_m) * ratio_m1
        for r in range(sf.shape[0]):
            out[r, i] = h + (h - field_m) * sf[r] + bias[r, i] + noise[r, i]
