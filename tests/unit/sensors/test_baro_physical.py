"""The physical baro of issue 39 (docs/baro.md): the surface layer's closed form against the hydrostatic integral,
what it does to the indication and to the aerodrome correction, the filter's one bias state, and the defaults."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from approachsim import synthetic, units
from approachsim.profile import parse_profile
from approachsim.sensors import atmosphere as atm
from approachsim.sensors.config import BaroConfig
from approachsim.sensors.suite import SensorSuite


@pytest.mark.parametrize(("inv_k", "depth_m"), [(10.0, 304.8), (-4.0, 200.0), (6.5 * 0.3048, 304.8)])
def test_inversion_ratio_is_the_hydrostatic_integral(inv_k, depth_m):
    """ln(p_real / p) = -(g0 / R) int_0^min(u, D) (1 / T_real - 1 / T_jsb) dH, by quadrature; the third case has
    L' = L - dT / D = 0 (the isothermal branch)."""
    p_f, t_f = 95000.0, 280.0
    lr = atm.LAPSE_K_PER_M - inv_k / depth_m
    for u in (10.0, 150.0, depth_m, 900.0):
        p = p_f * (1.0 - atm.LAPSE_K_PER_M * u / t_f) ** atm.EXPONENT
        top = min(u, depth_m)
        num, _ = quad(lambda h: 1.0 / (t_f - inv_k - lr * h) - 1.0 / (t_f - atm.LAPSE_K_PER_M * h), 0.0, top,
                      epsabs=1e-14, epsrel=1e-12)
        want = -atm.G0 / atm.R_AIR * num
        # the closed form recovers u from p (the ISA-like inverse, ~1e-13 relative) and takes two logs: 1e-10 is a
        # thousand times that on ratios of order 1e-3
        assert float(atm.inversion_log_ratio(p, p_f, t_f, inv_k, depth_m)) == pytest.approx(want, abs=1e-10)
    assert float(atm.inversion_log_ratio(p_f * 1.01, p_f, t_f, inv_k, depth_m)) == 0.0  # below the field


def _day(inversion_k: float, correction: str):
    prof = parse_profile({
        "runway": {"threshold_lat_deg": 37.6, "threshold_lon_deg": -122.4, "elevation_ft": 13.0,
                   "heading_true_deg": 298.0},
        "environment": {"isa_dev_C": 0.0, "inversion_K": inversion_k, "inversion_depth_ft": 1000.0},
        "sensors": {"baro": {"temperature_correction": correction}},
    })
    truth = synthetic.profile_descent(prof, rate_hz=10.0)
    baro = SensorSuite.from_profile(prof).sensors["baro"]
    s = baro.measure(truth, np.random.default_rng(0), noise=False)
    h = truth.h_m[baro.draw(truth.t_s, np.random.default_rng(0)).rows]
    return s.h_baro_m - h, h - prof.runway.elevation_m


def test_a_cold_surface_layer_reads_high_and_the_correction_overcorrects():
    """A 10 K surface inversion over 1000 ft on an ISA day: uncorrected, the indication is high by
    int dT(H) / T dH, dT_inv D / (2 T) = 5.4 m above the layer; corrected with the surface's (10 K colder) reported
    temperature it is pulled low by about dT_inv / T_f of the height above the field, more than it was off."""
    base, above = _day(0.0, "none")
    raw, _ = _day(10.0, "none")
    cor, _ = _day(10.0, "aerodrome")
    d = raw - base
    hi = above > 400.0
    t = atm.T0_K
    # the closed form's 5.40 m against the linearized dT D / (2 T) = 5.29 m: 3 %; heights of the synthetic descent
    assert np.all(np.abs(d[hi] - 10.0 * 304.8 / (2.0 * t)) < 0.05 * 10.0 * 304.8 / (2.0 * t))
    low = (above > 15.0) & (above < 60.0)  # 50-200 ft: about int_0^u 10 (1 - h / D) / T dh, under 10 / (T - 10) of u
    assert np.all((d[low] > 0.0) & (d[low] < 10.0 / (t - 10.0) * above[low]))
    # the correction made with the surface temperature: T_rep / T_std = (T_std - 10) / T_std, about -3.5 % of the
    # indicated height above the field, against the layer's +5.4 m: at 3000 ft it is off by more than uncorrected
    far = above > 900.0
    assert np.all(cor[far] < -0.03 * above[far] + 6.0)
    assert np.all(np.abs(cor[far]) > np.abs(raw[far]))


def test_filter_bias_state_has_the_truths_variance_and_rate():
    """bb: sigma^2 = the sum of the slow errors' variances; 2 sigma^2 / tau = the sum of the Gauss-Markov parts'
    2 sigma_i^2 / tau_i (the constant QNH error has no rate); 8.33 m / hPa at sea level."""
    b = BaroConfig()
    dhdp = atm.height_per_hpa_m(0.0)
    assert dhdp == pytest.approx(atm.R_AIR * atm.T0_K / (atm.G0 * atm.P0_PA) * 100.0, rel=1e-12)
    sig, tau = b.filter_bias(dhdp)
    parts = [(b.bias_sigma_m, b.bias_tau_s), (b.static_source_sigma_m, b.static_source_tau_s)]
    assert sig**2 == pytest.approx(sum(s**2 for s, _ in parts) + (b.qnh_sigma_hpa * dhdp) ** 2, rel=1e-12)
    assert 2.0 * sig**2 / tau == pytest.approx(sum(2.0 * s**2 / t for s, t in parts), rel=1e-12)
    assert 2.5 < sig < 4.0 and 300.0 < tau < 3600.0  # "a few m", minutes to an hour
    # the scale-factor prior follows the correction setting; the instrument's in quadrature
    assert b.filter_scale_sigma == pytest.approx(0.12)
    assert BaroConfig(temperature_correction="aerodrome", scale_factor_sigma=0.01).filter_scale_sigma == \
        pytest.approx(math.hypot(0.025, 0.01))
    # the paper's baro (gray-maybeck): no scale state, bias as declared
    paper = BaroConfig(temperature_scale_sigma=0.0, static_source_sigma_m=0.0, qnh_sigma_hpa=0.0)
    assert paper.filter_scale_sigma == 0.0 and paper.filter_bias(dhdp) == (1.0, 100.0)


def test_the_qnh_error_is_a_per_run_constant_at_the_fields_dh_dp():
    """The drawn slow bias less the seed's Gauss-Markov part is constant within a run when the static-source error
    is off, with a spread of qnh_sigma_hPa x dh/dp over runs (2000 runs: sigma within 5 %, 3.2 standard errors)."""
    prof = parse_profile({"runway": {"threshold_lat_deg": 39.9, "threshold_lon_deg": -104.7, "elevation_ft": 5434.0,
                                     "heading_true_deg": 180.0},
                          "sensors": {"baro": {"static_source_sigma_m": 0.0, "bias_sigma_m": 0.0}}})
    baro = SensorSuite.from_profile(prof).sensors["baro"]
    t = np.arange(0.0, 20.0, 0.1)
    e = baro.draw(t, [np.random.default_rng(i) for i in range(2000)])
    b = np.asarray(e.series["bias"])
    assert np.all(b == b[:, :1])
    want = 0.3 * atm.height_per_hpa_m(5434.0 * units.FT)
    assert want == pytest.approx(2.94, abs=0.01)
    assert float(np.std(b[:, 0])) == pytest.approx(want, rel=0.05)
