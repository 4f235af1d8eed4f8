"""The GNSS range-error formulas, each once, as scalar compiled functions (numba, cache=True).

Every kernel that maps an error to a channel calls these: the receiver's sky and pseudoranges and the GBAS scales
(core/sensors/gnss.py), the navigation filter's channel sigmas (core/sensors/gnss.py channel_sigmas,
gbas_channel_sigmas) and the closed loop's (core/loop/aiding.py channel_sigmas). Angles in rad, lengths in m.

    iono_obliquity     thin-shell ionospheric obliquity F(el)            RTCA DO-229 / ICAO Annex 10 F_pp, h_I 350 km
    tropo_mapping      tropospheric mapping M(el)                        RTCA DO-229 A.4.2.4
    do253_multipath_m  airframe multipath sigma_mp(el)                   RTCA DO-253 / DO-229 (Stanford MAAST)
    channel_sigmas     the filter's slow / fast channel-state sigmas     stand-alone budget (nav/noise.py)
    gbas_terms         the five GBAS-corrected residual scales           ICAO Annex 10 App. B, DO-253 (gnss/gbas.py)
    sbas_sigma_flt     SBAS fast + long-term correction sigma_flt         RTCA DO-229 App. J J.2.1 (MAAST udre2flt)
    mops_tropo_sigma_m sigma_tropo = 0.12 m M(el)                          RTCA DO-229 A.4.2.4
    sigma_air_m        airborne smoothed-code sigma_air, AAD-A / AAD-B    RTCA DO-229 J.2.4; ED-259A airborne model
    iono_free_residual_m  L1/L5 iono-free higher-order iono residual      EUROCAE ED-259A (MAAST init_mops)
    iono_free_gamma    noise amplification of the iono-free combination   (f1^4 + f2^4) / (f1^2 - f2^2)^2
    pierce_distance_m  user-to-pierce-point ground distance               RTCA DO-229 A.4.4.10.1
    service_terms, service_sigmas  a civil service's broadcast sigma_i   DO-229 App. J J.1 (sensors/gnss/service.py)

Some take cos el, sin el or the multipath curve's exponential instead of el: the closed loop gives numpy's values
of those (core/loop/aiding.py), so that its numbers are the numpy budget's to the bit; the other kernels give
math's. The readable numpy forms, the tests' oracles, are sensors/gnss/receiver.py's iono_obliquity, tropo_mapping
and do253_multipath_sigma_m, and gnss/gbas.py's GbasModel.scales.
"""

from __future__ import annotations

import math

import numpy as np

from approachsim import geo
from approachsim.core.jit import njit

A = geo.A_WGS84
RAD_TO_DEG = 180.0 / math.pi
"""numpy's degrees() factor (npy_rad2deg: x * (180 / pi)); numba's math.degrees is the same product."""
ELEVATION_FLOOR_RAD = math.radians(2.0)
"""The filter's elevation guard's floor (nav/noise.py), rad."""
IONO_SHELL_M = 350e3
"""Thin-shell ionosphere height h_I, m (Klobuchar / DO-229): the F_pp of the receiver's truth, the filter's channel
noise and the filter's zenith ionospheric states' row (core/nav/measurements.py)."""
GRADIENT_REFERENCE_EL_RAD = math.radians(5.0)
"""The elevation whose pierce distance d_5 normalizes the ionospheric field's planar gradient (sensors/gnss/
service.py: the truth's (d / d_5)^2 of its variance; the filter's gradient states per d_5)."""


@njit(cache=True)
def guard_elevation(el: float, lo: float) -> float:
    """The elevation the filter's channel noise is evaluated at (nav/noise.py): nan read as 0.5 rad, then at least
    lo (ELEVATION_FLOOR_RAD), rad."""
    e = 0.5 if el != el else el
    return e if e >= lo else lo


@njit(cache=True)
def obliquity_root(cos_el: float, shell_m: float) -> float:
    """1 / F = sqrt(1 - (R cos el / (R + h_I))^2), R the WGS-84 semi-major axis, h_I = shell_m the thin shell's
    height (m): the cosine of the zenith angle at the ionospheric pierce point."""
    x = A * cos_el / (A + shell_m)
    return math.sqrt(1.0 - x * x)


@njit(cache=True)
def iono_obliquity(cos_el: float, shell_m: float) -> float:
    """Thin-shell ionospheric obliquity F = 1 / sqrt(1 - (R cos el / (R + h_I))^2) (RTCA DO-229 / ICAO Annex 10
    F_pp, there with R_e = 6378.1363 km; here R = WGS-84 a, h_I = shell_m, 350 km): zenith delay times F = slant."""
    return 1.0 / obliquity_root(cos_el, shell_m)


@njit(cache=True)
def tropo_mapping(sin_el: float) -> float:
    """Tropospheric mapping M = 1.001 / sqrt(0.002001 + sin^2 el) (RTCA DO-229 A.4.2.4): zenith to slant delay."""
    return 1.001 / math.sqrt(0.002001 + sin_el * sin_el)


@njit(cache=True)
def do253_exponent(el_rad: float) -> float:
    """-el / 10 deg (el in degrees, numpy's order: degrees, negate, divide): the exponent of do253_multipath_m."""
    return -(el_rad * RAD_TO_DEG) / 10.0


@njit(cache=True)
def do253_curve(decay: float) -> float:
    """0.13 + 0.53 decay, m, with decay = exp(do253_exponent(el)): do253_multipath_m from its exponential."""
    return 0.13 + 0.53 * decay


@njit(cache=True)
def do253_multipath_m(el_rad: float) -> float:
    """Airframe multipath 1-sigma sigma_mp = 0.13 + 0.53 exp(-el / 10 deg), m (RTCA DO-253 / DO-229;
    Stanford MAAST init_cnmp_mops: a0 = 0.13 m, a1 = 0.53 m, theta0 = 10 deg)."""
    return do253_curve(math.exp(do253_exponent(el_rad)))


@njit(cache=True)
def channel_sigmas(cos_el: float, sin_el: float, decay: float, shell_m: float, ce2: float, iono_zenith_m: float,
                   tropo_zenith_m: float, do253: bool, mp_m: float) -> tuple[float, float]:
    """The filter's GPS channel-state 1-sigmas (m) of a stand-alone budget (receiver.GnssErrorBudget.
    channel_sigmas_m) at an elevation given by cos el, sin el and decay = exp(do253_exponent(el)):

        gse = sqrt(ce^2 + (I_z F)^2 + (T_z M)^2)       (ce2 = ce^2)
        gmp = 0.13 + 0.53 decay (do253), else mp_m
    """
    fi = iono_zenith_m * iono_obliquity(cos_el, shell_m)
    tm = tropo_zenith_m * tropo_mapping(sin_el)
    return math.sqrt(ce2 + fi * fi + tm * tm), (do253_curve(decay) if do253 else mp_m)


@njit(cache=True)
def gbas_terms(e: float, path: float, hfac: float, gad: np.ndarray, n_ref: float, aad: np.ndarray,
               shell_m: float) -> tuple[float, float, float, float, float]:
    """The five scales (m) of a GBAS-corrected channel at elevation e (rad) (gnss/gbas.py, whose GbasModel.scales
    is the oracle):

        ground  sqrt((a0 + a1 exp(-e / th0))^2 / M + a2^2), gad's row above gad[0] or at/below it
                (gad: split, a0, a1, th0, a2 above, a0, a1, th0, a2 at/below; ICAO Annex 10 App. B Table B-74)
        iono    F path, path = sigma_vig (x_air + 2 tau v_air)                     (F: iono_obliquity)
        tropo   hfac / sqrt(0.002 + sin^2 e), hfac = sigma_n h0 1e-6 |1 - exp(-dh / h0)|      (Annex 10 App. B)
        mp      do253_multipath_m(e)
        noise   a0 + a1 exp(-e / th0) (aad: a0, a1, th0; the airborne accuracy designator)
    """
    if e > gad[0]:
        a = gad[1] + gad[2] * math.exp(-e / gad[3])
        a2 = gad[4]
    else:
        a = gad[5] + gad[6] * math.exp(-e / gad[7])
        a2 = gad[8]
    sn = math.sin(e)
    return (math.sqrt(a * a / n_ref + a2 * a2), path / obliquity_root(math.cos(e), shell_m),
            hfac / math.sqrt(0.002 + sn * sn), do253_multipath_m(e), aad[0] + aad[1] * math.exp(-e / aad[2]))


# ---------------------------------------------------------------------------------------------------------------
# Civil services (sensors/gnss/service.py): the broadcast per-satellite 1-sigma of RTCA DO-229 Appendix J (SBAS L1),
# EUROCAE ED-259A (DFMC L1/L5), stand-alone L1 C/A with the Klobuchar bound, and the military L1/L2 P(Y) set.
# ---------------------------------------------------------------------------------------------------------------

MOPS_TROPO_ZENITH_M = 0.12
"""sigma_TVE, the vertical residual of the MOPS tropospheric model, m (RTCA DO-229 A.4.2.4; MAAST af_trpmops)."""
AIR_AAD_A = 0
"""air_model: multipath + AAD-A receiver noise 0.15 + 0.43 exp(-el / 6.9 deg) m."""
AIR_AAD_B = 1
"""air_model: multipath + AAD-B receiver noise 0.11 + 0.13 exp(-el / 4 deg) m."""
AIR_ED259A = 2
"""air_model: the ED-259A dual-frequency airborne model, already iono-free (gamma not applied)."""
IONO_L1 = 0
"""iono_model: single frequency, F_pp times the vertical bound (sigma_UIVE or the Klobuchar tau_vert)."""
IONO_FREE = 1
"""iono_model: iono-free combination, the higher-order residual 40 / (261 + el_deg^2) + 0.018 m."""

SERVICE_FIELDS = ("iono_model", "sigma_range_m", "sigma_vertical_iono_m", "tropo_zenith_m", "air_model", "gamma",
                  "shell_m", "range_scale", "iono_scale", "tropo_scale", "air_scale", "iono_common_weight",
                  "iono_gradient_weight", "gradient_reference_m")
"""The layout of a service's parameter vector (service_sigmas' `p`), by name (sensors/gnss/service.py packs it).
The four scales multiply the range, iono, tropo and air terms: ones for the broadcast sigmas, the nominal fractions
for the navigation filter's own error model (service.py ServiceModel.filter_params). The last three split the
single-frequency ionosphere when the navigation filter carries part of its field in states: the channel keeps the
variance share 1 - w_s - w_k + w_k (d / d_5)^2, w_s = iono_common_weight the share the states carry (the field's
common part w0 and its planar gradient wg: service.py IONO_FIELD_WEIGHTS, so the local wl is left), w_k =
iono_gradient_weight a gradient share left in the channel (0 with the gradient states), d the pierce distance,
d_5 = gradient_reference_m; w_s = 0: the whole ionosphere (the broadcast sigmas, and every filter without the
states)."""


@njit(cache=True)
def sbas_sigma_flt(sigma_udre: float, delta_udre: float, eps_fc: float, eps_rrc: float, eps_ltc: float,
                   eps_er: float, rss: bool) -> float:
    """sigma_flt, m, of the SBAS fast and long-term corrections (RTCA DO-229 App. J J.2.1; MAAST udre2flt):

        RSS_UDRE = 0:  sigma_flt = sigma_UDRE dUDRE + eps_fc + eps_rrc + eps_ltc + eps_er
        RSS_UDRE = 1:  sigma_flt = sqrt((sigma_UDRE dUDRE)^2 + eps_fc^2 + eps_rrc^2 + eps_ltc^2 + eps_er^2)

    sigma_UDRE from the broadcast UDRE index (UDRE / 3.29), dUDRE the message-27/28 factor, the eps the degradation
    terms (fast correction, range-rate correction, long-term correction, en-route), m."""
    s = sigma_udre * delta_udre
    if rss:
        return math.sqrt(s * s + eps_fc * eps_fc + eps_rrc * eps_rrc + eps_ltc * eps_ltc + eps_er * eps_er)
    return s + eps_fc + eps_rrc + eps_ltc + eps_er


@njit(cache=True)
def mops_tropo_sigma_m(sin_el: float) -> float:
    """sigma_tropo = 0.12 m x 1.001 / sqrt(0.002001 + sin^2 el), m (RTCA DO-229 A.4.2.4; MAAST af_trpmops, RTKLIB
    sbstropcorr, GPSTk MOPSTropModel)."""
    return MOPS_TROPO_ZENITH_M * tropo_mapping(sin_el)


@njit(cache=True)
def aad_noise_m(el_deg: float, air_model: int) -> float:
    """Airborne receiver noise (100 s smoothed code), m: AAD-A 0.15 + 0.43 exp(-el / 6.9 deg), AAD-B
    0.11 + 0.13 exp(-el / 4 deg) (RTCA DO-229 J.2.4 / ICAO Annex 10 App. B; MAAST init_aadb, init_cnmp_mops)."""
    if air_model == AIR_AAD_A:
        return 0.15 + 0.43 * math.exp(-el_deg / 6.9)
    return 0.11 + 0.13 * math.exp(-el_deg / 4.0)


@njit(cache=True)
def sigma_air_m(el_rad: float, air_model: int) -> float:
    """sigma_air, m, of one frequency's smoothed code: sqrt(sigma_mp^2 + sigma_noise^2), the DO-253 / DO-229 airframe
    multipath 0.13 + 0.53 exp(-el / 10 deg) and aad_noise_m (RTCA DO-229 J.2.4; MAAST af_cnmp_mops). With
    AIR_ED259A, the ED-259A dual-frequency airborne model (already iono-free):
    sqrt(0.4^2 + (0.34 + 0.40 exp(-el / 14 deg))^2) (EUROCAE ED-259A as in Stanford's ARAIM code, af_cnmp_259a)."""
    el_deg = el_rad * RAD_TO_DEG
    if air_model == AIR_ED259A:
        a = 0.34 + 0.40 * math.exp(-el_deg / 14.0)
        return math.sqrt(0.16 + a * a)
    mp = do253_multipath_m(el_rad)
    n = aad_noise_m(el_deg, air_model)
    return math.sqrt(mp * mp + n * n)


@njit(cache=True)
def iono_free_residual_m(el_rad: float) -> float:
    """The higher-order ionospheric residual of an L1/L5 iono-free combination, 40 / (261 + el_deg^2) + 0.018 m
    (EUROCAE ED-259A as in MAAST init_mops)."""
    el_deg = el_rad * RAD_TO_DEG
    return 40.0 / (261.0 + el_deg * el_deg) + 0.018


@njit(cache=True)
def iono_free_gamma(f1_hz: float, f2_hz: float) -> float:
    """Noise and multipath amplification of the iono-free combination, sqrt((f1^4 + f2^4) / (f1^2 - f2^2)^2):
    2.588 for L1/L5, 2.978 for L1/L2 (MAAST usrprocess; independent errors on the two frequencies)."""
    a, b = f1_hz * f1_hz, f2_hz * f2_hz
    return math.sqrt((a * a + b * b) / ((a - b) * (a - b)))


@njit(cache=True)
def pierce_distance_m(el_rad: float, shell_m: float) -> float:
    """Ground distance (m) from the user to the ionospheric pierce point on the thin shell at shell_m:
    R psi, psi = pi/2 - el - asin(R cos el / (R + h_I)) the Earth-central angle (RTCA DO-229 A.4.4.10.1)."""
    return A * (0.5 * math.pi - el_rad - math.asin(A * math.cos(el_rad) / (A + shell_m)))


@njit(cache=True)
def service_terms(el_rad: float, p: np.ndarray) -> tuple[float, float, float, float]:
    """The 1-sigmas (m) of one satellite at elevation el_rad of the service with parameters p (SERVICE_FIELDS):
    (range, ionosphere, troposphere, airborne), each times its scale p[7:11] (ones: the broadcast sigmas):

        range  sigma_flt (SBAS L1), sigma_DFRE (DFMC SBAS) or sigma_URA (stand-alone)
        iono   F_pp sigma_vertical (IONO_L1: sigma_UIVE, or the Klobuchar tau_vert), F_pp at h_I = shell_m
               (RTCA DO-229 J.2.3), times sqrt(1 - w_s - w_k + w_k (d / d_5)^2) when p[11] = w_s > 0 (the part the
               filter's zenith states carry; SERVICE_FIELDS), or the iono-free higher-order residual (IONO_FREE;
               ED-259A)
        tropo  tropo_zenith_m x 1.001 / sqrt(0.002001 + sin^2 el) (DO-229 A.4.2.4)
        air    gamma sigma_air (AAD-A / AAD-B; gamma 1 on L1, 2.588 L1/L5, 2.978 L1/L2) or ED-259A's"""
    if p[0] == IONO_L1:
        iono = p[2] * iono_obliquity(math.cos(el_rad), p[6])
        if p[11] > 0.0:  # the field's part in the filter's zenith states: the channel keeps the rest
            d = pierce_distance_m(el_rad, p[6]) / p[13]
            iono *= math.sqrt(1.0 - p[11] - p[12] + p[12] * d * d)
    else:
        iono = iono_free_residual_m(el_rad)
    air_model = int(p[4])
    air = sigma_air_m(el_rad, air_model)
    if air_model != AIR_ED259A:
        air *= p[5]
    return p[7] * p[1], p[8] * iono, p[9] * p[3] * tropo_mapping(math.sin(el_rad)), p[10] * air


@njit(cache=True)
def service_sigmas(el_rad: float, p: np.ndarray) -> tuple[float, float]:
    """(slow, fast) 1-sigmas (m) of one satellite (service_terms): slow = sqrt(range^2 + iono^2 + tropo^2), fast =
    air. With unit scales their RSS is DO-229's sigma_i^2 = sigma_flt^2 + sigma_UIRE^2 + sigma_air^2 + sigma_tropo^2
    (App. J J.1); with the nominal fractions, the navigation filter's channel states (nav/noise.py)."""
    r, i, t, a = service_terms(el_rad, p)
    return math.sqrt(r * r + i * i + t * t), a
