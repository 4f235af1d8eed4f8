"""GBAS differential corrections: the error a GBAS-corrected GPS pseudorange keeps, satellite by satellite.

A GBAS ground station (M reference receivers around a surveyed reference point near the runway) broadcasts a
pseudorange correction per satellite; the aircraft applies it to its 100 s carrier-smoothed code. The receiver
(receiver.py, `corrections = "gbas"`) then measures

    rho_i = |r_sv,i - r| + b_rx + s_gnd g_i + s_iono I_i + s_tropo T_i + s_mp m_i + s_noise n_i + w_i

with g, I, T, m, n unit-variance first-order Gauss-Markov series per channel, w white (CARRIER_NOISE_M) and the
scales (1-sigma, m) below, at
the channel's elevation theta, the aircraft's distance x_air to the reference point, its height dh above it and
its horizontal speed v_air (all from the truth). Marks as in shared/reference/integrity-envelope.md: [V] seen in
the source named, [S] only in a secondary source (named), [D] derived here, [U] not verified.

Ground (reference receivers' noise and multipath), the ground accuracy designator (GAD) curve

    s_gnd = sigma_pr_gnd(theta) = sqrt((a0 + a1 exp(-theta / theta0))^2 / M + a2^2)

  a0, a1, theta0, a2 by GAD: ICAO Annex 10 Vol I App. B Table B-74 (6th ed. 2006, p. APP B-106, as the reference's
  section 1c gives it) [V]: A 0.5, 1.65, 14.3 deg, 0.08; B 0.16, 1.07, 15.5 deg, 0.08; C above 35 deg 0.15, 0.84,
  15.5 deg, 0.04 and 5-35 deg 0.24, 0, -, 0.04 (the two C rows meet at 35 deg within 2 mm [D]). How M enters
  [S]: the receiver-specific term (a0 + a1 e^..) averages over the M independent reference receivers, the common
  term a2 does not -- the form of the Annex's 3.6.7.1.1.1 requirement as third-party GBAS code implements it
  (a MATLAB `PR_err.m` found through the code index, repository not named by it: err_gnd = sqrt(pr_gnd^2 / M +
  err_SIS^2)), consistent with the same Annex page's requirement for SBAS ranging sources, RMS_pr_gnd <= 1.8 / sqrt(M)
  m [V]. Unverified [U]: the clause's own text (whether M is M(theta), the receivers used at that elevation; here
  the installed number, 2-4: the Type 2 message codes 2, 3 or 4 receivers [V], A10-2006 aero.cn 10768_138, the
  reference's section 1c). Below 5 deg
  (a mask under 5 deg) the 5 deg row is continued (engineering choice). The curve is the designator's accuracy
  *requirement*: the residual is modelled at that limit (a ground subsystem that just meets its designator).
  Correlation: Gauss-Markov, ground_tau_s (default 300 s; engineering choice [D]): static reference antennas see
  multipath whose phase 4 pi h sin(theta) / lambda turns at 4 pi h cos(theta) theta_dot / lambda, with a reflector
  h = 2 m below the antenna, lambda = 0.19 m and a GPS elevation rate up to 1.5e-4 rad/s a period of 320 s or
  more; 100 s smoothing passes it, so the broadcast correction's error decorrelates over some 300 s.

Airborne (receiver noise and airframe multipath on the 100 s smoothed code), sigma_air^2 = sigma_multipath^2 +
sigma_noise^2 (Stanford MAAST af_cnmp_mops.m [V], reference section 8):
  s_mp = the DO-253 airframe multipath 0.13 + 0.53 exp(-theta / 10 deg) (elevation.do253_multipath_sigma_m), the
  receiver's multipath series (multipath_model = "do253" is required), correlated over multipath_tau_s;
  s_noise = the airborne accuracy designator (AAD) curve a0 + a1 exp(-theta / theta0): AAD-B 0.11, 0.13, 4 deg [V]
  (MAAST init_aadb.m / init_cnmp_mops.m, 2018 "corrected noise term to AAD-B"); AAD-A 0.15, 0.43, 6.9 deg [S] (two
  ARAIM codes, reference section 8, and the GBAS `PR_err.m` above). Sources conflict on AAD-A: MAAST HEAD init_aada.m
  (2001, "per LAAS MASPS DO-245") has 0.16 + 0.23 exp(-theta / 19.6 deg) and an older MAAST init_aadb.m 0.0741 +
  0.18 exp(-theta / 27.7 deg); chosen: the later set, the one MAAST adopted for AAD-B in 2018 and current codes use,
  the 2001 values predating the designators of the current standards. Annex 10 Att. D 7.5.7 [V] (A10-2006,
  aero.cn 10769_91): the receiver contribution a GBAS provider assumes is RMS_pr_air of AAD-A.
  Correlation: the noise of code smoothed by a first-order filter of time constant tau = 100 s is the raw white noise
  low-passed: a Gauss-Markov of time constant tau [D]. What the smoothing passes unfiltered is the carrier phase's
  own tracking noise: the white w_i, CARRIER_NOISE_M = 2 mm, the PLL thermal jitter (lambda / 2 pi) sqrt(B_n / (C/N0)
  (1 + 1 / (2 T C/N0))) (Kaplan & Hegarty, Understanding GPS, PLL thermal noise jitter [U]: the formula from memory)
  at 35 dB-Hz, B_n = 10 Hz, T = 20 ms: 0.0565 rad = 1.7 mm, rounded up [D]. It is the budget's white code noise
  under GBAS (code_noise_m: the white R of the navigation filter's pseudorange rows, which a U-D update needs
  positive).

Satellite clock and ephemeris: the same at the reference point and the aircraft, removed by the correction. The
  orbit error decorrelates with the separation (Annex 10 Att. D 7.5.9 [V]): a satellite-position error dr moves the
  range by dr . u, and the lines of sight from two points x apart differ by at most x / rho rad, so the residual is
  at most |dr| x / rho [D] (the broadcast ephemeris decorrelation parameter is such a ratio, the monitor's minimum
  detectable error over the range [S], 1library.net thesis "Integrity parameters GBAS ground system"). With a 5 m
  orbit error (twice the 2.4 m URE: the along- and cross-track components exceed the radial one), x = 20 km and the
  shortest range 20,200 km: 5 m x 20 / 20,200 = 5 mm (5 cm for an undetected 50 m error), beside s_gnd >= 0.1 m and
  sigma_air >= 0.17 m: left out. The clock error is common to both receivers (latency is covered by the broadcast
  range-rate correction): left out.

Ionosphere (the spatial gradient between the reference point and the aircraft, and the divergence the aircraft's
smoothing filter accumulated along its path):

    s_iono = F(theta) sigma_vig (x_air + 2 tau v_air)

  the GBAS form of DO-253 / Annex 10 App. B 3.6.5.5 [U: the form written from memory, its clause not read]; its
  variables -- x_air the distance between the aircraft and the reference point, v_air the aircraft's speed, the
  gradient sigma -- as a NAVIGATION (ION) paper's GBAS error model lists them after RTCA DO-245A (Table 2,
  navi.ion.org) [S]; F the thin-shell obliquity at 350 km (elevation.iono_obliquity, the
  Annex's F_pp with the WGS-84 semi-major axis for R_e = 6378.1363 km: 0.7 m apart), tau = 100 s (the smoothing time
  constant), sigma_vig default 4 mm/km, the nominal mid-latitude (CONUS) vertical gradient (Lee et al., as cited in
  GPS Solutions s10291-024-01669-9 [S]; the NAVIGATION table uses the same 0.004 m/km). x_air: the slant distance
  (the Annex's wording [U]; the horizontal distance differs by 0.14 % on a 3 deg path). Correlation: the stand-alone
  ionospheric correlation time (iono_tau_s, 30 min: the gradient field changes slowly); the scale follows the
  aircraft.

Troposphere (the refractivity left uncorrected between the reference point's height and the aircraft's):

    s_tropo = sigma_n h0 1e-6 / sqrt(0.002 + sin^2 theta) |1 - exp(-dh / h0)|

  the Annex 10 App. B GBAS form (clause number [U]; the form as `PR_err.m` above implements it [S]); dh the aircraft's
  height above the reference point (absolute value: an aircraft below a station on a hill), h0 the troposphere scale
  height, default 7350 m, that of the ITU-R P.453 exponential reference atmosphere N(h) = 315 exp(-h / 7.35 km) [U];
  sigma_n the refractivity uncertainty, default 30 N-units (engineering choice [U]: a conservative broadcast value;
  below the CAT I decision height the term is under 2 cm at every elevation above 5 deg; 10 nmi out, 985 m above the
  station, 2.8 cm at the zenith and 28 cm at 5 deg [D]). Correlation: the stand-alone tropospheric correlation time
  (tropo_tau_s, 1 h).

Nominal 1-sigma (the record's sigma_m): sqrt(s_gnd^2 + s_iono^2 + s_tropo^2 + s_mp^2 + s_noise^2 + w^2), the
Annex's sigma_i^2 = sigma_pr_gnd^2 + sigma_tropo^2 + sigma_pr_air^2 + sigma_iono^2 (and the 2 mm white).

The navigation filter's channel states (nav/noise.py): the slow state carries ground + iono + tropo (correlation time
their drift-matched combination), the fast state the airborne multipath and noise (both correlated over the
smoothing time), the white w is the pseudorange rows' R.
The iono and tropo terms depend on where the aircraft is; `channel_sigmas_m` takes that geometry: the filter's
prior P0 and elevation-only noise take the approach's start (`approach_geometry`: the profile's start distance,
glidepath, threshold crossing height and approach speed; nav/system.py), and without one REFERENCE_GEOMETRY, the
start of a 10 nmi final on a 3 deg path at 140 kt. Along the approach the filter's slow state follows the
aircraft's own geometry as the truth's does (nav/gbas_scale.py: the state's scale over each interval, since
2026-12-05; before, the filter kept the reference geometry's sigma, which over-claimed the horizontal position by a
quarter on the CAT III candidate).

`GbasModel` holds the configuration and the numpy formulas, the oracle of the compiled kernels
(core/sensors/gnss.py gbas_scales, pseudorange_sum, and gbas_channel_sigmas: the filter's channel sigmas for a
compiled navigation epoch, called with channel_kernel_args()).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from approachsim import geo, units
from approachsim.sensors.gnss.elevation import IONO_SHELL_M, do253_multipath_sigma_m, iono_obliquity

Array = np.ndarray

GAD_TABLE: Mapping[str, tuple[tuple[float, float, float, float, float], ...]] = MappingProxyType({
    "A": ((5.0, 0.5, 1.65, 14.3, 0.08),),
    "B": ((5.0, 0.16, 1.07, 15.5, 0.08),),
    "C": ((35.0, 0.15, 0.84, 15.5, 0.04), (5.0, 0.24, 0.0, 15.5, 0.04)),
})
"""Ground accuracy designators, GPS (Annex 10 App. B Table B-74): rows (theta_min deg, a0 m, a1 m, theta0 deg, a2 m),
highest elevation first; a row applies above its theta_min (the last row at and below it too). GAD-C's 5-35 deg row
has a1 = 0 (its theta0, unused, set to the other row's)."""
AAD_TABLE: Mapping[str, tuple[float, float, float]] = MappingProxyType({
    "A": (0.15, 0.43, 6.9),
    "B": (0.11, 0.13, 4.0),
})
"""Airborne accuracy designators: (a0 m, a1 m, theta0 deg) of the smoothed-code receiver noise (module docstring)."""
GADS = tuple(GAD_TABLE)
AADS = tuple(AAD_TABLE)
SMOOTHING_TAU_S = 100.0
"""The airborne carrier-smoothing time constant, s (DO-253 / Annex 10 100 s smoothing): the tau of 2 tau v_air and
the correlation time of the smoothed receiver noise."""
CARRIER_NOISE_M = 0.002
"""White noise left on the smoothed code, m: the carrier-phase tracking jitter (module docstring)."""
TROPO_MAPPING_A = 0.002
"""The GBAS tropospheric mapping 1 / sqrt(0.002 + sin^2 theta) (module docstring)."""


def approach_geometry(start_distance_m: float, glidepath_rad: float, tch_m: float,
                      speed_mps: float) -> tuple[float, float, float]:
    """(x_air m, dh m, v_air m/s) at the start of a straight-in final, the geometry of the filter's elevation-only
    channel noise and P0 (nav/noise.py): start_distance_m from the reference point (taken at the threshold), on the
    glidepath glidepath_rad with the threshold crossing height tch_m, at speed_mps."""
    return start_distance_m, start_distance_m * math.tan(glidepath_rad) + tch_m, speed_mps


REFERENCE_GEOMETRY = approach_geometry(10.0 * units.NMI, math.radians(3.0), 50.0 * units.FT, 140.0 * units.KT)
"""approach_geometry of a 10 nmi final on a 3 deg path with a 50 ft threshold crossing height at 140 kt: the
default when no approach is given (module docstring)."""


@dataclass(frozen=True)
class GbasModel:
    """A GBAS ground station and airborne equipment: designators, reference receivers, the broadcast ionospheric and
    tropospheric parameters, the ground residual's correlation time and the reference point (runway frame: along,
    cross, height above the threshold, m)."""

    gad: str = "C"
    aad: str = "B"
    reference_receivers: int = 4
    sigma_vig_per_m: float = 4e-6
    """Vertical ionospheric gradient 1-sigma, m of delay per m of separation (4 mm/km)."""
    refractivity_sigma: float = 30.0
    """Refractivity uncertainty sigma_n, N-units."""
    scale_height_m: float = 7350.0
    ground_tau_s: float = 300.0
    station_rwy_m: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if self.gad not in GAD_TABLE:
            raise ValueError(f"gad must be one of {', '.join(GADS)}; got {self.gad!r}")
        if self.aad not in AAD_TABLE:
            raise ValueError(f"aad must be one of {', '.join(AADS)}; got {self.aad!r}")
        if self.reference_receivers not in (2, 3, 4):
            raise ValueError(f"reference_receivers must be 2, 3 or 4; got {self.reference_receivers!r}")
        for name in ("sigma_vig_per_m", "refractivity_sigma"):
            if not getattr(self, name) >= 0.0:
                raise ValueError(f"{name} must be >= 0; got {getattr(self, name)!r}")
        for name in ("scale_height_m", "ground_tau_s"):
            if not getattr(self, name) > 0.0:
                raise ValueError(f"{name} must be > 0; got {getattr(self, name)!r}")

    # --- the terms (numpy: the oracle of the compiled kernels) -------------------------------------------------

    def ground_sigma_m(self, el_rad: Array) -> Array:
        """sigma_pr_gnd(theta) = sqrt((a0 + a1 exp(-theta / theta0))^2 / M + a2^2), m (Table B-74 row by elevation)."""
        th = np.degrees(np.asarray(el_rad, dtype=float))
        rows = GAD_TABLE[self.gad]
        a, a2 = _gad_row(th, rows[-1])
        for row in reversed(rows[:-1]):
            ah, a2h = _gad_row(th, row)
            a, a2 = np.where(th > row[0], ah, a), np.where(th > row[0], a2h, a2)
        return np.sqrt(a * a / self.reference_receivers + a2 * a2)

    def airborne_noise_sigma_m(self, el_rad: Array) -> Array:
        """sigma_noise(theta) = a0 + a1 exp(-theta / theta0) of the AAD, m."""
        a0, a1, th0 = AAD_TABLE[self.aad]
        return a0 + a1 * np.exp(-np.degrees(np.asarray(el_rad, dtype=float)) / th0)

    def iono_sigma_m(self, el_rad: Array, x_air_m: Array, v_air_mps: Array) -> Array:
        """sigma_iono = F(theta) sigma_vig (x_air + 2 tau v_air), m."""
        return iono_obliquity(el_rad) * self.sigma_vig_per_m * (x_air_m + 2.0 * SMOOTHING_TAU_S * v_air_mps)

    def tropo_sigma_m(self, el_rad: Array, dh_m: Array) -> Array:
        """sigma_tropo = sigma_n h0 1e-6 / sqrt(0.002 + sin^2 theta) |1 - exp(-dh / h0)|, m."""
        h0 = self.scale_height_m
        s = np.sin(np.asarray(el_rad, dtype=float))
        return (self.refractivity_sigma * h0 * 1e-6 / np.sqrt(TROPO_MAPPING_A + s * s)
                * np.abs(-np.expm1(-np.asarray(dh_m, dtype=float) / h0)))

    def scales(self, el_rad: Array, x_air_m: Array, dh_m: Array, v_air_mps: Array) -> dict[str, Array]:
        """The five scales of the module docstring (m) and `sigma`, their RSS with CARRIER_NOISE_M, broadcast over the
        arguments."""
        out = {"ground": self.ground_sigma_m(el_rad), "iono": self.iono_sigma_m(el_rad, x_air_m, v_air_mps),
               "tropo": self.tropo_sigma_m(el_rad, dh_m), "multipath": do253_multipath_sigma_m(el_rad),
               "noise": self.airborne_noise_sigma_m(el_rad)}
        out = {k: np.broadcast_to(v, np.broadcast_shapes(*(np.shape(u) for u in out.values()))) for k, v in out.items()}
        out["sigma"] = np.sqrt(out["ground"] ** 2 + out["iono"] ** 2 + out["tropo"] ** 2 + out["multipath"] ** 2
                               + out["noise"] ** 2 + CARRIER_NOISE_M**2)
        return out

    def sigma_m(self, el_rad: Array, x_air_m: Array, dh_m: Array, v_air_mps: Array) -> Array:
        """Nominal 1-sigma of the corrected pseudorange, m (the Annex's sigma_i)."""
        return self.scales(el_rad, x_air_m, dh_m, v_air_mps)["sigma"]

    def channel_sigmas_m(self, el_rad: Array, x_air_m: Array | None = None, dh_m: Array | None = None,
                         v_air_mps: Array | None = None) -> tuple[Array, Array]:
        """The navigation filter's channel-state 1-sigmas (m): slow sqrt(gnd^2 + iono^2 + tropo^2) and fast
        sqrt(mp^2 + noise^2) at el_rad; a geometry left None is REFERENCE_GEOMETRY's."""
        rx, rh, rv = REFERENCE_GEOMETRY
        x = rx if x_air_m is None else x_air_m
        dh = rh if dh_m is None else dh_m
        v = rv if v_air_mps is None else v_air_mps
        s = self.scales(el_rad, x, dh, v)
        return (np.sqrt(s["ground"] ** 2 + s["iono"] ** 2 + s["tropo"] ** 2),
                np.sqrt(s["multipath"] ** 2 + s["noise"] ** 2))

    def carrier_channel_sigmas_m(self, el_rad: Array, x_air_m: Array | None = None, dh_m: Array | None = None,
                                 v_air_mps: Array | None = None) -> tuple[Array, Array, Array]:
        """channel_sigmas_m with the ionosphere split off (carrier phase, whose ionospheric term has the opposite
        sign): slow sqrt(gnd^2 + tropo^2), iono, fast sqrt(mp^2 + noise^2), m."""
        rx, rh, rv = REFERENCE_GEOMETRY
        x = rx if x_air_m is None else x_air_m
        dh = rh if dh_m is None else dh_m
        v = rv if v_air_mps is None else v_air_mps
        s = self.scales(el_rad, x, dh, v)
        return (np.sqrt(s["ground"] ** 2 + s["tropo"] ** 2), s["iono"],
                np.sqrt(s["multipath"] ** 2 + s["noise"] ** 2))

    # --- geometry and the compiled kernels' parameters ---------------------------------------------------------

    def station_ecef(self, runway: geo.RunwayFrame) -> tuple[float, float, float]:
        """The reference point in ECEF, m: runway-frame along and cross, at the threshold's ellipsoid height plus
        the given height (as pseudolite positions, sensors/pseudolite.py)."""
        x, y, hat = self.station_rwy_m
        p = runway.to_ecef(np.array([x, y, 0.0]))
        lat, lon, _ = geo.ecef_to_geodetic(p)
        r = geo.geodetic_to_ecef(lat, lon, runway.threshold_h_m + hat)
        return float(r[0]), float(r[1]), float(r[2])

    def gad_params(self) -> Array:
        """(9,): split elevation (rad; -inf for one row), then (a0, a1, theta0 rad, a2) above it and at / below it."""
        rows = GAD_TABLE[self.gad]
        hi, lo = rows[0], rows[-1]
        split = math.radians(hi[0]) if len(rows) > 1 else -math.inf
        return np.array([split, hi[1], hi[2], math.radians(hi[3]), hi[4], lo[1], lo[2], math.radians(lo[3]), lo[4]])

    def aad_params(self) -> Array:
        """(3,): a0, a1 m, theta0 rad of the AAD curve."""
        a0, a1, th0 = AAD_TABLE[self.aad]
        return np.array([a0, a1, math.radians(th0)])

    def channel_kernel_args(self) -> tuple:
        """The constant arguments of core/sensors/gnss.gbas_channel_sigmas between the geometry and the outputs:
        gbas_channel_sigmas(el, x_air, dh, v_air, *model.channel_kernel_args(), gse, gmp)."""
        return (self.gad_params(), float(self.reference_receivers), self.aad_params(), float(self.sigma_vig_per_m),
                SMOOTHING_TAU_S, float(self.refractivity_sigma), float(self.scale_height_m), IONO_SHELL_M)


def _gad_row(th_deg: Array, row: tuple[float, float, float, float, float]) -> tuple[Array, float]:
    """(a0 + a1 exp(-theta / theta0), a2) of one Table B-74 row at elevations th_deg (deg)."""
    _, a0, a1, th0, a2 = row
    return a0 + a1 * np.exp(-th_deg / th0), a2


def station_geometry(r_ecef: Array, h_m: Array, v_ned: Array, station_ecef: Array,
                     station_h_m: float) -> tuple[Array, Array, Array]:
    """(x_air, dh, v_air) (m,) of receivers at r_ecef (m, 3) m with ellipsoid heights h_m (m,) and NED velocities
    v_ned (m, 3) m/s: slant distance to the reference point, height above it, horizontal speed."""
    d = np.asarray(r_ecef, dtype=float) - np.asarray(station_ecef, dtype=float)
    v = np.asarray(v_ned, dtype=float)
    return (np.sqrt(np.einsum("ij,ij->i", d, d)), np.asarray(h_m, dtype=float) - station_h_m,
            np.hypot(v[:, 0], v[:, 1]))
