"""The GNSS services a civil operator flies today, and the military one of Gray & Maybeck: their broadcast
per-satellite sigmas (what a certified receiver weights with and bounds with) and the truth that those sigmas
overbound.

Services ([sensors.gnss] service; the names say the signal and the augmentation):

    "sbas-l1"    GPS L1 C/A with SBAS L1 corrections (RTCA DO-229 Appendix J; WAAS / EGNOS LPV, LPV-200):
                 sigma_i^2 = sigma_flt^2 + (F_pp sigma_UIVE)^2 + sigma_air^2 + sigma_tropo^2
    "dfmc-sbas"  GPS L1/L5 iono-free with DFMC SBAS corrections (EUROCAE ED-259A):
                 sigma_i^2 = sigma_DFRE^2 + sigma_iono,HO^2 + (gamma sigma_air)^2 + sigma_tropo^2, gamma 2.588
    "dfmc"       GPS L1/L5 iono-free stand-alone (no SBAS): the DFMC model with the broadcast URA for the range term
    "l1ca"       GPS L1 C/A stand-alone with the broadcast Klobuchar model:
                 sigma_i^2 = sigma_URA^2 + (F_pp tau_vert)^2 + sigma_air^2 + sigma_tropo^2
    "py-pps"     GPS L1/L2 P(Y) iono-free, a MILITARY receiver (Precise Positioning Service; not a civil
                 certification basis: L2 is not an aeronautical radio-navigation band): the stand-alone model with
                 gamma 2.978 on the smoothed code's noise and multipath

The formulas live once, compiled, in core/sensors/gnss_errors.py (service_terms, service_sigmas); this module holds
the tables, picks the parameters and packs them (ServiceModel.params, gnss_errors.SERVICE_FIELDS).

Broadcast terms:
  sigma_flt      from the UDRE index (MOPS sigma^2_UDRE table, about (UDRE / 3.29)^2), times dUDRE (message
                 27/28, 1 inside the service volume) plus the degradation terms eps_fc, eps_rrc, eps_ltc, eps_er
                 added linearly or RSS by the RSS_UDRE flag (DO-229 J.2.1; MAAST udre2flt). Default UDRE index 5
                 (3.0 m) and GIVE index 9 (3.0 m): MAAST's constant-index study default (maast_no_gui.m), a
                 conservative mid-service-volume WAAS broadcast (interior CONUS UDREs and GIVEs are mostly
                 smaller), and the values of the reference sigma table the unit test holds the formulas to.
  sigma_UIVE     from the GIVE index (same table form), one value for the four surrounding IGPs (a constant-index
                 study, as MAAST's), mapped by F_pp = [1 - (R_e cos el / (R_e + 350 km))^2]^-1/2.
  sigma_DFRE     from the DFRE index (DFREI 1-15, MAAST init_L5mops); default 4 (1.0 m): of the order of the L1
                 default's sigma_flt (0.91 m) for the same satellite clock and orbit monitoring.
  sigma_URA      the broadcast URA of a stand-alone receiver, 2.4 m (the GPS URA of the draft ICAO Annex 10
                 default ARAIM integrity support data, June 2024, as Stanford's MAAST for ARAIM sets it).
  tau_vert       DO-229's bound on the Klobuchar residual by geomagnetic latitude: 9 m (|phi_m| <= 20 deg), 4.5 m
                 (20-55 deg), 6 m (> 55 deg) (GPSTk MOPSWeight::sigma2iono; the max with (T_iono / 5)^2 is not
                 taken: the broadcast Klobuchar coefficients are not modelled, and F_pp tau_vert is the larger
                 term at mid latitudes). phi_m at the runway threshold by the Klobuchar model's own dipole
                 approximation phi_m = phi + 0.064 cos(lambda - 1.617) (semicircles; IS-GPS-200 20.3.3.5.2.5).
  sigma_tropo    0.12 m x 1.001 / sqrt(0.002001 + sin^2 el) (DO-229 A.4.2.4).
  sigma_air      sqrt(sigma_mp^2 + sigma_noise^2), multipath 0.13 + 0.53 exp(-el / 10 deg), noise by the airborne
                 accuracy designator (AAD-A 0.15 + 0.43 exp(-el / 6.9 deg), AAD-B 0.11 + 0.13 exp(-el / 4 deg));
                 dual frequency: gamma x that, or the ED-259A airborne model sqrt(0.4^2 + (0.34 + 0.40 exp(-el /
                 14 deg))^2) (aad = "ED-259A", the DFMC services' default).

Truth (sensors/gnss/receiver.py draws it): the broadcast sigmas are overbounds (they must bound the tails of every
satellite's error at 1e-7), so the errors a receiver sees are smaller. The truth is drawn from correlated
processes at a fraction of each broadcast term ([sensors.gnss] truth = "nominal"; "broadcast" draws every term at
its full broadcast sigma and independent per channel, a worst case):

  range    per satellite, Gauss-Markov; SBAS correction residual (fast + long-term) 0.3 sigma_flt / sigma_DFRE,
           tau 600 s; stand-alone broadcast clock and ephemeris 0.3 sigma_URA (0.72 m: the measured GPS signal-in-
           space URE RMS of recent years is 0.5-0.7 m, Renfro et al., "An Analysis of Global Positioning System
           (GPS) Standard Positioning Service Performance for 2019", ARL:UT TR-SGL-20-02), tau 2 h.
  iono     ONE vertical residual field over the pierce points, mapped by each satellite's F_pp: a common part
           (variance 0.75), a planar gradient (0.20 at the pierce distance of a 5 deg satellite, growing as
           (d / d_5)^2) and a local part per pierce point (0.05), each Gauss-Markov, tau 30 min; so the channels'
           iono errors are strongly correlated (mostly common mode, which the clock absorbs except for F_pp's
           spread), not independent. SBAS residual 0.3 sigma_UIVE (WAAS's GIVE bounds the post-fit residual of
           the planar-fit vertical delay estimate at 1e-7); Klobuchar residual 0.5 tau_vert (the broadcast model
           removes about half of the RMS delay, Navipedia "Klobuchar Ionospheric Model", and tau_vert is the
           bound, not the RMS); iono-free: the higher-order residual at 0.5, per channel.
  tropo    ONE zenith residual of the MOPS model, common to the satellites, mapped by M(el): 0.5 x 0.12 m,
           tau 1 h.
  air      per satellite, Gauss-Markov at the 100 s smoothing time: 0.7 sigma_air (the AAD curves bound the
           airborne smoothed-code error distribution's tails).
  white    the 2 mm carrier-phase noise the 100 s smoothing passes (as under GBAS).

The range and iono fractions 0.3 are a modelling choice argued from published WAAS performance: the FAA William
J. Hughes Technical Center's WAAS Performance Analysis Report #10 (Nov 2004) gives 95 % vertical errors of
1.0-1.8 m against 95 % VPLs of 25-43 m at its sites; with VPL = 5.33 sigma_V that is a true vertical sigma about
0.11-0.18 of the broadcast one. A range-domain 0.3 with the correlated iono field gives a position ratio within a
factor two of that on the conservative side (docs/profiles.md gives the measured figures).

Filter ([sensors.gnss] filter_model, default the truth's): the protection levels weight with the broadcast sigmas
(DO-229 requires it of the PLs); the hybrid INS/GNSS navigation filter carries its own model of the nominal error
processes: per channel a slow state at sqrt((f_r range)^2 + (f_i iono)^2 + (f_t tropo)^2) and a fast one at
f_a air, the f the truth's fractions (filter_params). A filter weighting with the overbounds cannot be consistent
against what they overbound (docs/gnss-services.md gives the argument and the measured e^2/P).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType

import numpy as np

from approachsim.core import layouts
from approachsim.core.sensors import gnss as gk
from approachsim.core.sensors import gnss_errors as ge
from approachsim.sensors.gnss.elevation import IONO_SHELL_M

Array = np.ndarray

SERVICES = ("sbas-l1", "dfmc-sbas", "dfmc", "l1ca", "py-pps")
"""[sensors.gnss] service names (module docstring)."""
SBAS_SERVICES = ("sbas-l1", "dfmc-sbas")
"""The services with SBAS corrections (and SBAS protection levels)."""
MILITARY = ("py-pps",)
"""Military services (labelled so in reports)."""
SERVICE_LABELS: Mapping[str, str] = MappingProxyType({
    "sbas-l1": "SBAS L1 (GPS L1 C/A + SBAS, RTCA DO-229)",
    "dfmc-sbas": "DFMC SBAS (GPS L1/L5 iono-free + SBAS, EUROCAE ED-259A)",
    "dfmc": "DFMC stand-alone (GPS L1/L5 iono-free, no SBAS)",
    "l1ca": "stand-alone L1 C/A (GPS SPS + Klobuchar)",
    "py-pps": "P(Y) L1/L2 iono-free, military (PPS)",
})
"""The service's name in reports."""

K_UDRE = 3.29
"""sigma = UDRE / 3.29 and sigma = GIVE / 3.29 (the 99.9 % bound; MAAST init_mops, RTKLIB varfcorr / varicorr)."""
UDRE_M = (0.75, 1.0, 1.25, 1.75, 2.25, 3.0, 3.75, 4.5, 5.25, 6.0, 7.5, 15.0, 50.0, 150.0)
"""UDRE by UDRE index 0-13, m (RTCA DO-229 Table A-6 as in MAAST init_mops; 14 'not monitored', 15 'do not use'
are not usable and not accepted)."""
GIVE_M = (0.3, 0.6, 0.9, 1.2, 1.5, 1.8, 2.1, 2.4, 2.7, 3.0, 3.6, 4.5, 6.0, 15.0)
"""GIVE by GIVE index 0-13, m (RTCA DO-229 Table A-17 as in MAAST init_mops; 14, 15 not usable)."""
UDRE_SIGMA2_M2 = (0.0520, 0.0924, 0.1444, 0.2830, 0.4678, 0.8315, 1.2992, 1.8709, 2.5465, 3.3260, 5.1968, 20.787,
                  230.97, 2078.7)
"""sigma^2_UDRE by UDRE index 0-13, m^2: the standard's table (MAAST init_mops, RTKLIB varfcorr), which the
receiver uses (about (UDRE / 3.29)^2, rounded as printed)."""
GIVE_SIGMA2_M2 = (0.0084, 0.0333, 0.0749, 0.1331, 0.2079, 0.2994, 0.4075, 0.5322, 0.6735, 0.8315, 1.1974, 1.8709,
                  3.3260, 20.787)
"""sigma^2_GIVE by GIVE index 0-13, m^2 (the same sources; RTKLIB varicorr)."""
DFRE_SIGMA_M = (0.625, 0.75, 0.875, 1.0, 1.125, 1.5, 1.75, 2.0, 2.25, 2.5, 3.0, 3.5, 4.0, 7.0, 10.0)
"""sigma_DFRE by DFRE index 1-15, m (EUROCAE ED-259A as in MAAST init_L5mops)."""
URA_M = 2.4
"""Broadcast URA of a stand-alone receiver, m (module docstring)."""
F_L1_HZ, F_L2_HZ, F_L5_HZ = 1575.42e6, 1227.60e6, 1176.45e6
"""GPS carrier frequencies, Hz (IS-GPS-200, IS-GPS-705)."""
AADS = ("A", "B", "ED-259A")
"""Airborne models: AAD-A, AAD-B (single frequency; x gamma on dual), the ED-259A dual-frequency model."""
TRUTHS = ("nominal", "broadcast")
"""Truth draws: at the argued fractions of the broadcast sigmas, or at the broadcast sigmas."""
FILTER_MODELS = ("nominal", "broadcast")
"""The navigation filter's own channel error model: the nominal error processes (the truth's fractions of the
broadcast sigmas) or the broadcast sigmas; the protection levels use the broadcast sigmas either way."""

TRUTH_FRACTIONS: Mapping[str, tuple[float, float, float, float]] = MappingProxyType({
    "sbas-l1": (0.3, 0.3, 0.5, 0.7),
    "dfmc-sbas": (0.3, 0.5, 0.5, 0.7),
    "dfmc": (0.3, 0.5, 0.5, 0.7),
    "l1ca": (0.3, 0.5, 0.5, 0.7),
    "py-pps": (0.3, 0.5, 0.5, 0.7),
})
"""Truth 1-sigma / broadcast 1-sigma of (range, iono, tropo, air) under truth = "nominal" (module docstring)."""
RANGE_TAU_S: Mapping[str, float] = MappingProxyType({"sbas-l1": 600.0, "dfmc-sbas": 600.0, "dfmc": 7200.0,
                                                    "l1ca": 7200.0, "py-pps": 7200.0})
"""Correlation time of the range term's residual, s: SBAS correction residual 600 s (the fast corrections are
refreshed every 6 s but their residual follows the long-term corrections' slow orbit/clock error, minutes;
engineering choice); broadcast ephemeris/clock 2 h (the stand-alone budget's)."""
IONO_TAU_S = 1800.0
"""Correlation time of the ionospheric residual field, s (the stand-alone budget's iono_tau_s)."""
TROPO_TAU_S = 3600.0
"""Correlation time of the tropospheric zenith residual, s."""
AIR_TAU_S = 100.0
"""Correlation time of the airborne smoothed-code error, s: the 100 s carrier-smoothing time constant."""
IONO_FIELD_WEIGHTS = (0.75, 0.20, 0.05)
"""Variance split of the unit ionospheric field: common, planar gradient (at the 5 deg pierce distance), local."""
SERIES = ("range", "iono_local", "air", "iono_field", "tropo", "tropo_local")
"""The truth's unit series in core/sensors/gnss.py service_errors' order (receiver.py draws them, and "noise")."""
GRADIENT_REFERENCE_EL_RAD = ge.GRADIENT_REFERENCE_EL_RAD
"""The elevation whose pierce distance d_5 normalizes the gradient term ((d / d_5)^2 of its variance)."""


def geomagnetic_latitude_rad(lat_rad: float, lon_rad: float) -> float:
    """Geomagnetic latitude (rad) by the Klobuchar model's dipole approximation phi_m = phi + 0.064 cos(lambda -
    1.617), angles in semicircles (IS-GPS-200 20.3.3.5.2.5)."""
    phi, lam = lat_rad / math.pi, lon_rad / math.pi
    return (phi + 0.064 * math.cos(math.pi * (lam - 1.617))) * math.pi


def klobuchar_tau_vert_m(mag_lat_rad: float) -> float:
    """DO-229's vertical bound on the Klobuchar residual by geomagnetic latitude, m: 9 (|phi_m| <= 20 deg), 4.5
    (20-55 deg), 6 (> 55 deg) (GPSTk MOPSWeight::sigma2iono)."""
    a = abs(math.degrees(mag_lat_rad))
    return 9.0 if a <= 20.0 else (4.5 if a <= 55.0 else 6.0)


@dataclass(frozen=True)
class ServiceModel:
    """A civil (or military) GNSS service: its broadcast-sigma parameters and its truth (module docstring)."""

    service: str
    udre_index: int = 5
    give_index: int = 9
    delta_udre: float = 1.0
    eps_fc_m: float = 0.0
    eps_rrc_m: float = 0.0
    eps_ltc_m: float = 0.0
    eps_er_m: float = 0.0
    rss_udre: bool = False
    dfrei: int = 4
    aad: str | None = None
    """"A" | "B" | "ED-259A"; None: "ED-259A" for the DFMC services, "B" for the others."""
    ura_m: float = URA_M
    truth: str = "nominal"
    filter_model: str | None = None
    """"nominal" | "broadcast": the navigation filter's channel error model; None: the truth's (module docstring)."""
    site_lat_rad: float = math.radians(45.0)
    """The approach's location (the runway threshold; profile.py sets it): the Klobuchar bound's geomagnetic
    latitude."""
    site_lon_rad: float = 0.0

    def __post_init__(self) -> None:
        if self.service not in SERVICES:
            raise ValueError(f"service must be one of {', '.join(SERVICES)}; got {self.service!r}")
        if self.aad is None:
            object.__setattr__(self, "aad", "ED-259A" if self.service in ("dfmc-sbas", "dfmc") else "B")
        if not 0 <= self.udre_index < len(UDRE_M):
            raise ValueError(f"udre_index must be in [0, {len(UDRE_M) - 1}]; got {self.udre_index}")
        if not 0 <= self.give_index < len(GIVE_M):
            raise ValueError(f"give_index must be in [0, {len(GIVE_M) - 1}]; got {self.give_index}")
        if not 1 <= self.dfrei <= len(DFRE_SIGMA_M):
            raise ValueError(f"dfrei must be in [1, {len(DFRE_SIGMA_M)}]; got {self.dfrei}")
        if self.aad not in AADS:
            raise ValueError(f"aad must be one of {', '.join(AADS)}; got {self.aad!r}")
        if self.truth not in TRUTHS:
            raise ValueError(f"truth must be one of {', '.join(TRUTHS)}; got {self.truth!r}")
        if self.filter_model is None:
            object.__setattr__(self, "filter_model", self.truth)
        if self.filter_model not in FILTER_MODELS:
            raise ValueError(f"filter_model must be one of {', '.join(FILTER_MODELS)}; got {self.filter_model!r}")

    @property
    def sbas(self) -> bool:
        """SBAS corrections (and SBAS protection levels)."""
        return self.service in SBAS_SERVICES

    @property
    def military(self) -> bool:
        """A military (PPS) service."""
        return self.service in MILITARY

    @property
    def label(self) -> str:
        """The service's name in reports."""
        return SERVICE_LABELS[self.service]

    @property
    def dual_frequency(self) -> bool:
        """An iono-free combination (first-order ionosphere removed)."""
        return self.service in ("dfmc-sbas", "dfmc", "py-pps")

    def gamma(self) -> float:
        """Noise and multipath amplification of the service's code combination: 1 (L1), 2.588 (L1/L5), 2.978
        (L1/L2) (gnss_errors.iono_free_gamma)."""
        if not self.dual_frequency:
            return 1.0
        return ge.iono_free_gamma(F_L1_HZ, F_L2_HZ if self.service == "py-pps" else F_L5_HZ)

    def sigma_flt_m(self) -> float:
        """SBAS L1's sigma_flt, m (gnss_errors.sbas_sigma_flt of the UDRE index and the degradation terms)."""
        return ge.sbas_sigma_flt(math.sqrt(UDRE_SIGMA2_M2[self.udre_index]), self.delta_udre, self.eps_fc_m,
                                 self.eps_rrc_m, self.eps_ltc_m, self.eps_er_m, self.rss_udre)

    def sigma_range_m(self) -> float:
        """The range term's broadcast 1-sigma, m: sigma_flt (SBAS L1), sigma_DFRE (DFMC SBAS), sigma_URA (else)."""
        if self.service == "sbas-l1":
            return self.sigma_flt_m()
        if self.service == "dfmc-sbas":
            return DFRE_SIGMA_M[self.dfrei - 1]
        return self.ura_m

    def sigma_vertical_iono_m(self) -> float:
        """The vertical ionospheric bound, m: sigma_UIVE (SBAS L1), the Klobuchar tau_vert (L1 C/A), 0 (iono-free)."""
        if self.service == "sbas-l1":
            return math.sqrt(GIVE_SIGMA2_M2[self.give_index])
        if self.service == "l1ca":
            return klobuchar_tau_vert_m(geomagnetic_latitude_rad(self.site_lat_rad, self.site_lon_rad))
        return 0.0

    def air_model(self) -> int:
        """gnss_errors' airborne model code of `aad`."""
        return {"A": ge.AIR_AAD_A, "B": ge.AIR_AAD_B, "ED-259A": ge.AIR_ED259A}[str(self.aad)]

    def params(self, scales: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0), common: bool = False) -> Array:
        """The packed parameter vector of gnss_errors.service_terms (SERVICE_FIELDS order): the broadcast sigmas, or
        with `scales` on the (range, iono, tropo, air) terms; common: without what the navigation filter's zenith
        states carry (iono_zenith_state, tropo_zenith_state): the ionosphere's common part on a single frequency and
        the whole tropospheric residual (the tropo scale 0)."""
        w0, wg, _ = IONO_FIELD_WEIGHTS if common and not self.dual_frequency else (0.0, 0.0, 0.0)
        w0, wg = w0 + wg, 0.0  # the common part and the planar gradient are the filter's states: the local part left
        vals = {"iono_model": ge.IONO_FREE if self.dual_frequency else ge.IONO_L1,
                "sigma_range_m": self.sigma_range_m(), "sigma_vertical_iono_m": self.sigma_vertical_iono_m(),
                "tropo_zenith_m": ge.MOPS_TROPO_ZENITH_M, "air_model": self.air_model(), "gamma": self.gamma(),
                "shell_m": IONO_SHELL_M, "range_scale": scales[0], "iono_scale": scales[1],
                "tropo_scale": 0.0 if common else scales[2], "air_scale": scales[3], "iono_common_weight": w0,
                "iono_gradient_weight": wg, "gradient_reference_m": self.gradient_reference_m()}
        return np.array([float(vals[k]) for k in ge.SERVICE_FIELDS])

    def filter_fractions(self) -> tuple[float, float, float, float]:
        """The navigation filter's channel sigmas / broadcast sigmas of (range, iono, tropo, air): the nominal
        truth's fractions (filter_model = "nominal") or ones ("broadcast")."""
        return (1.0, 1.0, 1.0, 1.0) if self.filter_model == "broadcast" else TRUTH_FRACTIONS[self.service]

    @property
    def iono_zenith_state(self) -> bool:
        """Whether the navigation filter carries the common part of the ionospheric residual field as one zenith
        state (mapped by each satellite's F_pp): a single-frequency service (SBAS L1, stand-alone L1 C/A: both draw
        the residual as one vertical field over the pierce points) with the nominal filter model. Not iono-free
        (DFMC, P(Y): the higher-order residual is per channel), not the broadcast model (every term per channel)."""
        return not self.dual_frequency and self.filter_model == "nominal"

    @property
    def tropo_zenith_state(self) -> bool:
        """Whether the navigation filter carries the tropospheric residual as one zenith state (mapped by each
        satellite's M(el)): the nominal filter model, whose truth draws it as one zenith value common to the
        satellites (the broadcast model: per channel)."""
        return self.filter_model == "nominal"

    def filter_params(self) -> Array:
        """The packed parameters of the navigation filter's channel error model (params at filter_fractions; without
        the common parts its zenith states carry, under the nominal model)."""
        return self.params(self.filter_fractions(), common=self.tropo_zenith_state)

    def filter_iono_zenith(self) -> tuple[float, float, float]:
        """The navigation filter's zenith ionospheric states (iono_zenith_state): the 1-sigma (m) of the vertical
        residual field's common part f_i sqrt(w0) sigma_vertical and of each planar-gradient component (east,
        north) per d_5, f_i sqrt(wg) sigma_vertical (the truth's terms, at the filter's fraction f_i), and their
        correlation time, s (the field's, IONO_TAU_S)."""
        w0, wg, _ = IONO_FIELD_WEIGHTS
        s = self.filter_fractions()[1] * self.sigma_vertical_iono_m()
        return s * math.sqrt(w0), s * math.sqrt(wg), IONO_TAU_S

    def filter_tropo_zenith(self) -> tuple[float, float]:
        """The navigation filter's zenith tropospheric state (tropo_zenith_state): its 1-sigma f_t sigma_TVE, m (the
        truth's zenith residual of the MOPS model, at the filter's fraction), and correlation time TROPO_TAU_S, s."""
        return self.filter_fractions()[2] * ge.MOPS_TROPO_ZENITH_M, TROPO_TAU_S

    def at_site(self, lat_rad: float, lon_rad: float) -> ServiceModel:
        """This service at the approach's location (the Klobuchar bound's geomagnetic latitude)."""
        return replace(self, site_lat_rad=float(lat_rad), site_lon_rad=float(lon_rad))

    def truth_fractions(self) -> tuple[float, float, float, float]:
        """Truth / broadcast 1-sigma of (range, iono, tropo, air): TRUTH_FRACTIONS, or ones (truth = broadcast)."""
        return (1.0, 1.0, 1.0, 1.0) if self.truth == "broadcast" else TRUTH_FRACTIONS[self.service]

    @property
    def range_tau_s(self) -> float:
        """Correlation time of the range residual, s."""
        return RANGE_TAU_S[self.service]

    @property
    def slow_tau_s(self) -> float:
        """The navigation filter's slow channel state's correlation time, s: the shortest of the slow terms'."""
        return min(self.range_tau_s, IONO_TAU_S, TROPO_TAU_S)

    # ---- broadcast sigmas (the compiled formulas, gnss_errors) ----

    def channel_sigmas_m(self, el_rad: Array, guard: bool = True) -> tuple[Array, Array, Array]:
        """(slow, fast, total) broadcast 1-sigmas (m) at elevations el_rad (any shape), rad: the navigation filter's
        channel states and DO-229's sigma_i (gnss_errors.service_sigmas); guard: nav/noise.py's elevation guard."""
        el = np.asarray(el_rad, dtype=float)
        e2 = np.ascontiguousarray(el.reshape(-1, el.shape[-1]) if el.ndim else el.reshape(1, 1))
        out = tuple(np.empty(e2.shape) for _ in range(3))
        gk.service_channel_sigmas(e2, self.params(), guard, *out)
        return tuple(o.reshape(el.shape) for o in out)  # type: ignore[return-value]

    def filter_channel_sigmas_m(self, el_rad: Array) -> tuple[Array, Array]:
        """(slow, fast) 1-sigmas (m) of the navigation filter's channel states at elevations el_rad (already guarded
        by nav/noise.py), rad: its own error model (filter_params), not the broadcast one."""
        el = np.asarray(el_rad, dtype=float)
        e2 = np.ascontiguousarray(el.reshape(-1, el.shape[-1]) if el.ndim else el.reshape(1, 1))
        out = tuple(np.empty(e2.shape) for _ in range(3))
        gk.service_channel_sigmas(e2, self.filter_params(), False, *out)
        return out[0].reshape(el.shape), out[1].reshape(el.shape)

    def sigma_m(self, el_rad: Array) -> Array:
        """DO-229's sigma_i (m) at elevations el_rad, rad (no guard: nan stays nan)."""
        return self.channel_sigmas_m(el_rad, guard=False)[2]

    def terms_m(self, el_rad: Array, common: bool = False) -> Array:
        """(..., 5): the broadcast range, iono, tropo, air 1-sigmas (m) and the pierce distance (m) at el_rad; common:
        the ionosphere without its common part (params)."""
        el = np.asarray(el_rad, dtype=float)
        e2 = np.ascontiguousarray(el.reshape(-1, el.shape[-1]))
        out = np.empty(e2.shape + (5,))
        gk.service_channel_terms(e2, self.params(common=common), out)
        return out.reshape(el.shape + (5,))

    # ---- truth ----

    def gradient_reference_m(self) -> float:
        """d_5: the pierce distance of a 5 deg satellite, m (the iono gradient term's unit)."""
        return float(ge.pierce_distance_m(GRADIENT_REFERENCE_EL_RAD, IONO_SHELL_M))

    def truth_shape(self) -> Array:
        """The packed truth shape of core/sensors/gnss.py service_errors (core/layouts.py SERVICE_TRUTH): the truth's
        fractions, the iono field's variance split as square roots ((0, 0, 1) when every term is per channel:
        truth = "broadcast", or the iono-free higher-order residual), d_5 and whether the tropo is one zenith
        residual (truth_scales gives the same scales in numpy)."""
        fr, fi, ft, fa = self.truth_fractions()
        w0, wg, _ = IONO_FIELD_WEIGHTS
        correlated = not (self.truth == "broadcast" or self.dual_frequency)
        vals = {"f_range": fr, "f_iono": fi, "f_tropo": ft, "f_air": fa,
                "w_common": math.sqrt(w0) if correlated else 0.0, "w_grad": math.sqrt(wg) if correlated else 0.0,
                "w_local": math.sqrt(1.0 - w0 - wg) if correlated else 1.0,
                "grad_ref_m": self.gradient_reference_m(), "tropo_common": 0.0 if self.truth == "broadcast" else 1.0}
        return np.array([float(vals[n]) for n in layouts.SERVICE_TRUTH.names])

    def truth_scales(self, el_rad: Array, az_rad: Array) -> dict[str, Array]:
        """The truth's per-channel scales (m per unit series) at elevations / azimuths (..., k), rad: range, air,
        tropo (common zenith) and tropo_local (per channel), and the iono field's common, east and north gradient and
        local scales (times the field's unit series; module docstring). truth = "broadcast" is the filter's own
        model: every term independent per channel at its broadcast sigma."""
        fr, fi, ft, fa = self.truth_fractions()
        t = self.terms_m(el_rad)
        w0, wg, wl = IONO_FIELD_WEIGHTS
        iono = fi * t[..., 1]
        tropo = ft * t[..., 2]
        zero = np.zeros_like(iono)
        if self.truth == "broadcast" or self.dual_frequency:
            # the filter's own model (every term independent per channel), or the higher-order residual
            common = grad = zero
            local = iono
        else:
            g = iono * math.sqrt(wg) * t[..., 4] / self.gradient_reference_m()
            common, local = iono * math.sqrt(w0), iono * math.sqrt(1.0 - w0 - wg)
            grad = g
        tropo_c, tropo_l = (zero, tropo) if self.truth == "broadcast" else (tropo, zero)
        az = np.asarray(az_rad, dtype=float)
        return {"range": fr * t[..., 0], "tropo": tropo_c, "tropo_local": tropo_l, "air": fa * t[..., 3],
                "iono_common": common, "iono_east": grad * np.sin(az), "iono_north": grad * np.cos(az),
                "iono_local": local}

    def truth_errors(self, series: Mapping[str, Array], el_rad: Array, az_rad: Array | None,
                     common: bool = True) -> tuple[Array, Array, Array, Array]:
        """The true range, iono, tropo and airborne errors (m) of the channels at elevations / azimuths (..., k), rad,
        from the unit series (receiver.py draw: range, iono_local, air (..., k), iono_field (..., 3): common, east,
        north; tropo (..., 1)), sample axes matching el_rad's (truth_scales; module docstring). common=False: without
        the ionospheric field's common part and gradient and the tropospheric zenith residual (what the filter's
        channel states carry beside its zenith states: truth_iono_zenith_m, truth_tropo_zenith_m)."""
        if az_rad is None:
            raise ValueError("a service's truth needs the satellites' azimuths (the iono field's gradient)")
        sc = self.truth_scales(el_rad, az_rad)
        f = np.asarray(series["iono_field"])
        iono = sc["iono_local"] * series["iono_local"]
        if common:
            iono = (sc["iono_common"] * f[..., 0:1] + sc["iono_east"] * f[..., 1:2] + sc["iono_north"] * f[..., 2:3]
                    + iono)
        tropo = sc["tropo_local"] * series["tropo_local"]
        if common:
            tropo = sc["tropo"] * series["tropo"] + tropo
        return sc["range"] * series["range"], iono, tropo, sc["air"] * series["air"]

    def truth_iono_zenith_m(self, series: Mapping[str, Array]) -> Array:
        """The realized vertical ionospheric field's common part and planar gradient (east, north, per d_5), m
        (..., 3): f_i sigma_vertical (sqrt(w0), sqrt(wg), sqrt(wg)) times the field's unit series (receiver.py draw:
        iono_field): the values of the filter's zenith states, each channel's truth_errors iono holding F_pp(el)
        (common + (d / d_5) (sin az east + cos az north)) of them (zeros when the truth has no field: iono-free or
        truth = "broadcast")."""
        f = np.asarray(series["iono_field"])
        if self.truth == "broadcast" or self.dual_frequency:
            return np.zeros_like(f)
        w0, wg, _ = IONO_FIELD_WEIGHTS
        return self.truth_fractions()[1] * self.sigma_vertical_iono_m() * np.sqrt([w0, wg, wg]) * f

    def truth_tropo_zenith_m(self, series: Mapping[str, Array]) -> Array:
        """The realized tropospheric zenith residual, m (...,): f_t sigma_TVE times the unit series (receiver.py draw:
        tropo[..., 0]): the value of the filter's zenith tropospheric state (0 under truth = "broadcast", whose
        troposphere is per channel)."""
        t = np.asarray(series["tropo"])[..., 0]
        if self.truth == "broadcast":
            return np.zeros_like(t)
        return self.truth_fractions()[2] * ge.MOPS_TROPO_ZENITH_M * t
