"""The GNSS range-error formulas, each once, as scalar compiled functions (numba, cache=True).

Every kernel that maps an error to a channel calls these: the receiver's sky and pseudoranges and the GBAS scales
(core/sensors/gnss.py), the navigation filter's channel sigmas (core/sensors/gnss.py channel_sigmas,
gbas_channel_sigmas) and the closed loop's (core/loop/aiding.py channel_sigmas). Angles in rad, lengths in m.

    iono_obliquity     thin-shell ionospheric obliquity F(el)            RTCA DO-229 / ICAO Annex 10 F_pp, h_I 350 km
    tropo_mapping      tropospheric mapping M(el)                        RTCA DO-229 A.4.2.4
    do253_multipath_m  airframe multipath sigma_mp(el)                   RTCA DO-253 / DO-229 (Stanford MAAST)
    channel_sigmas     the filter's slow / fast channel-state sigmas     stand-alone budget (nav/noise.py)
    gbas_terms         the five GBAS-corrected residual scales           ICAO Annex 10 App. B, DO-253 (gnss/gbas.py)

Some take cos el, sin el or the multipath curve's exponential instead of el: the closed loop gives numpy's values
of those (core/loop/aiding.py), so that its numbers are the numpy budget's to the bit; the other kernels give
math's. The readable numpy forms, the tests' oracles, are sensors/gnss/receiver.py's iono_obliquity, tropo_mapping
and do253_multipath_sigma_m, and gnss/gbas.py's GbasModel.scales.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from approachsim import geo

A = geo.A_WGS84
RAD_TO_DEG = 180.0 / math.pi
"""numpy's degrees() factor (npy_rad2deg: x * (180 / pi)); numba's math.degrees is the same product."""
ELEVATION_FLOOR_RAD = math.radians(2.0)
"""The filter's elevation guard's floor (nav/noise.py), rad."""


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
