"""GPS code pseudoranges to the nominal constellation, with the error budget of standards.md 2.3.

    rho_i = |r_sv,i - r| + b_rx + E_i + F(el_i) I_i + M(el_i) T_i + m_i + n_i

b_rx   receiver clock bias (two-state, clock.py; passed in so GNSS and pseudolites share one receiver clock),
E_i    satellite clock + ephemeris error, Gauss-Markov (sigma, 2 h),
I_i    zenith ionospheric residual, Gauss-Markov (30 min), mapped by the thin-shell obliquity F(el) at 350 km,
T_i    zenith tropospheric residual, Gauss-Markov (1 h), mapped by the DO-229 1.001 / sqrt(0.002001 + sin^2 el),
m_i    multipath, Gauss-Markov (60 s), n_i code noise, white.
Correlation times are engineering choices (the budgets give only 1-sigma), documented here and configurable.

Presets (1-sigma, m; NRC 1995 Table C-1 [S11]):
  P(Y) (PPS, dual frequency): clock/ephemeris 3.6, multipath 1.8, noise 0.6, atmospheric 0.7 split as
        iono zenith 0.3 and tropo zenith 0.2 (Kaplan's 0.2 m tropo residual), which RSS to 0.7 m at 30 deg;
        UERE 4.1 m.
  C/A (SPS, SA off): clock/ephemeris 3.6, multipath 1.2, noise 0.6, atmospheric 7.0 as iono zenith 4.0
        (7.0 m slant at 30 deg, F = 1.75) and tropo zenith 0.2; UERE 8.0 m.

Selectable on top of a preset (make_budget; the profile's [sensors.gnss] multipath_model and clock_ephemeris):
  multipath "nrc1995": the preset's elevation-independent Gauss-Markov (1.8 m P(Y), 60 s);
            "do253":   the RTCA DO-253 / DO-229 airframe multipath curve sigma_mp(el) = 0.13 + 0.53 exp(-el / 10 deg)
            m (Stanford MAAST init_cnmp_mops.m, A0 = 0.13 m, A1 = 0.53 m, theta0 = 10 deg; reference
            integrity-envelope.md 8), a unit Gauss-Markov scaled by sigma_mp at each channel's elevation. Its
            correlation time defaults to 100 s: the curve bounds the multipath left in the 100 s carrier-smoothed
            code of DO-253 / DO-229 airborne receivers, and the smoothing filter, not the few seconds in which raw
            airframe multipath decorrelates on a moving aircraft, sets the correlation of that residual
            (multipath_tau_s; a shorter time lets the navigation filter average it down faster).
            The AAD-B receiver-noise curve 0.11 + 0.13 exp(-el / 4 deg) is not adopted here: it describes smoothed code
            noise correlated over the same 100 s, whereas the code noise here is the preset's white raw-code noise
            (GBAS corrections, below, do adopt the AAD curves, on the smoothed code they describe).
  clock/ephemeris "nrc1995": the preset's 3.6 m (1995 constellation);
            "current": 2.4 m, the GPS URE (accuracy / continuity sigma) of the draft ICAO Annex 10 default ARAIM
            integrity support data, June 2024, as set in Stanford's MAAST for ARAIM (main_maast_araim.m,
            isd.ure_gps = 2.4 m, Blanch et al.); a conservative modern figure: the measured GPS signal-in-space
            URE RMS of recent years is lower still (Renfro et al., "An Analysis of Global Positioning System
            (GPS) Standard Positioning Service Performance for 2019", ARL:UT TR-SGL-20-02, 2020).

Corrections (the profile's [sensors.gnss] corrections): "none" is the stand-alone model above; "gbas" (gbas.py)
replaces every term but the receiver clock by the residual of a GBAS-corrected, 100 s carrier-smoothed code:

    rho_i = |r_sv,i - r| + b_rx + s_gnd g_i + s_iono I_i + s_tropo T_i + s_mp m_i + s_noise n_i + w_i

g (ground, ground_tau_s), I (iono_tau_s), T (tropo_tau_s), m (multipath_tau_s), n (the 100 s smoothing) unit
Gauss-Markov series drawn from the same standard normals, in the same columns, as the stand-alone clock/ephemeris,
iono, tropo, multipath and noise (common random numbers between the two); the scales at each channel's elevation and
the aircraft's distance, height and speed relative to the GBAS reference point (station_ecef). w is the 2 mm white
carrier-phase noise the smoothing passes (gbas.CARRIER_NOISE_M, budget code_noise_m), from normals drawn after all
the others. The record's sigma_m is the corrected nominal sigma there.

Services (the profile's [sensors.gnss] service; service.py gives the models and their sources): SBAS L1, DFMC SBAS,
DFMC, stand-alone L1 C/A and the military P(Y) replace the code presets by

    rho_i = |r_sv,i - r| + b_rx + s_r R_i + F(el_i) V(ipp_i) + s_t T + s_a A_i + w_i

R the per-satellite range residual (SBAS correction / broadcast ephemeris and clock), V the vertical ionospheric
residual at the satellite's pierce point, one field (common part, planar gradient, local part) seen through the
obliquity F (the iono-free services: the higher-order residual per channel), T one tropospheric zenith residual
mapped by M(el), A the 100 s smoothed airborne error, w the 2 mm carrier noise; the scales are fractions of the
broadcast sigmas (truth = "nominal") or the broadcast sigmas themselves with every term per channel (truth =
"broadcast"). The record's sigma_m is then DO-229's broadcast sigma_i, which the filter and the SBAS protection
levels (integrity/sbas.py) use.

Epoch: every run's sky is the constellation at epoch_utc + its own offset (errors.constants["epoch_offset_s"],
drawn by the sensor suite from the run's "gnss_epoch" stream); a batch of runs with offsets gives per-run geometry
(r_sv_ecef, elevation, azimuth, visible, valid, sigma, pdop with a leading run axis). No offset: one sky.

Satellite positions are those at the receive time (no light-time or Sagnac terms): the record carries them,
so a navigation filter that uses the record's r_sv_ecef sees exactly the modelled geometry.
Pseudorange rate (optional, doppler=True): rho_dot_i = u_i . (v_sv,i - v_rx) + d_rx + e_i, the geometric
range rate (SV velocity relative to the rotating Earth, receiver velocity from the truth's v_ned) plus the
receiver clock drift and white noise e (doppler_noise_mps, default 0.05 m/s: carrier-derived Doppler of a
typical receiver, engineering choice); the slow range errors' rates are neglected. Off by default; its noise
columns are drawn only when on, so receivers without it keep their exact draws (switching it on reshuffles
that receiver's pseudorange noise, reproducibly).
Carrier phase (optional, carrier_phase = true; carrier.py gives the model, its sources and its arcs):
    phi_i = |r_sv,i - r| + b_rx + lambda N_a(i) + S_i - I_i + c_i + w_i
lambda N_a(i) the float ambiguity of the channel's current arc (a new one whenever the channel becomes valid after not
being valid: rising satellite, end of an outage (faults.py re-arcs after outages), re-selection; no cycle slips within
an arc), S_i the slow errors the code has with the same sign (stand-alone E + M T, GBAS s_gnd g + s_tropo T: the same
realizations), I_i the code's ionospheric term, here with the opposite sign, c_i the carrier multipath (Gauss-Markov,
1 cm, 5 s), w_i white tracking noise (2 mm). The record adds carrier_phase_m, carrier_arc (the sample index at which
the arc began, -1 where invalid) and carrier_sigma_m. Its normals are drawn after all the others (receivers without
it keep their draws bit for bit: they come from the child stream "carrier" of the receiver's, seeding.substream);
`prepare(...).at` continues the arcs from sample to sample (samples in order).
Selection: "all" (every SV above the mask) or "best4" (the four of lowest PDOP, seed 002, chosen afresh at
each epoch). Channels are the 24 slots, in SLOTS order; invisible or unselected channels are nan and invalid.

Computation: `apply` runs the compiled kernels of core/sensors/gnss.py (orbits, look angles, selection, PDOP,
pseudoranges) over every sky and sample at once; `apply_reference` (with `geometry`, `best_pdop_four_reference`)
is the readable numpy version and the kernels' test oracle (values to 1e-12 relative, selections identical).
`prepare(errors, clock)` lays one run's (or batch's) errors out for sample-at-a-time application in a closed
loop: the satellite positions of every sample are computed once, and `.at(truth, j)` gives exactly the record
`apply(truth, <sample j of errors>, <its clock sample>)` gives, bit for bit.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from approachsim import geo
from approachsim.core.sensors import gnss as gk
from approachsim.records import GnssSamples, Truth
from approachsim.seeding import substream
from approachsim.sensors import base
from approachsim.sensors.gnss.carrier import CarrierModel, ambiguities, carrier_arcs
from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.constellation import Constellation, dops, look_angles
from approachsim.sensors.gnss.elevation import IONO_SHELL_M, do253_multipath_sigma_m, iono_obliquity, tropo_mapping
from approachsim.sensors.gnss.gbas import CARRIER_NOISE_M, SMOOTHING_TAU_S, GbasModel, station_geometry
from approachsim.sensors.gnss.service import AIR_TAU_S, IONO_TAU_S, TROPO_TAU_S, ServiceModel
from approachsim.sensors.gnss.service import SERIES as SERVICE_SERIES

Array = np.ndarray

MULTIPATH_MODELS = ("do253", "nrc1995")
"""Multipath models (module docstring)."""
CLOCK_EPHEMERIS_M: Mapping[str, float] = MappingProxyType({"current": 2.4, "nrc1995": 3.6})
"""Satellite clock + ephemeris 1-sigma (m) by budget name (module docstring gives the sources)."""
DO253_MULTIPATH_TAU_S = 100.0
"""Default correlation time of the DO-253 multipath, s: the 100 s carrier-smoothing time constant (docstring)."""
SIDEREAL_DAY_S = 86164.0905
"""Mean sidereal day, s (23.934 h): the GPS ground tracks repeat about once per sidereal day."""

SELECTIONS = ("best4", "best4-fixed", "all")
"""Satellite selection. best4: the best-PDOP four at every epoch. best4-fixed: seed 002's one planned set for
the approach, the best-PDOP four (at the run start) among the satellites that stay above the mask for
fixed_hold_s seen from the start position (truth row 0 only: stateless), kept while all four are in view,
with per-epoch best4 at any epoch where one is not. all: every satellite in view."""


@dataclass(frozen=True)
class GnssErrorBudget:
    """1-sigma (m) and correlation times (s) of the per-satellite errors."""

    clock_ephemeris_m: float
    iono_zenith_m: float
    tropo_zenith_m: float
    multipath_m: float
    code_noise_m: float
    clock_ephemeris_tau_s: float = 7200.0
    iono_tau_s: float = 1800.0
    tropo_tau_s: float = 3600.0
    multipath_tau_s: float = 60.0
    multipath_model: str = "nrc1995"
    """"nrc1995": multipath_m at every elevation; "do253": sigma_mp(el) (multipath_m unused)."""
    gbas: GbasModel | None = None
    """GBAS corrections (gbas.py): every stand-alone term above but the multipath curve is replaced, code_noise_m is
    the white carrier-phase noise left on the smoothed code (make_budget); None: stand-alone ranging."""

    service: ServiceModel | None = None
    """A civil (or military) GNSS service (service.py): broadcast sigmas for the filter and the protection levels,
    truth drawn from correlated processes they overbound; every stand-alone field above is then unused but
    code_noise_m, the white carrier-phase noise left on the 100 s smoothed code (make_budget). None: the code
    presets."""

    @property
    def corrections(self) -> str:
        """"none" or "gbas"."""
        return "none" if self.gbas is None else "gbas"

    def multipath_sigma_m(self, el_rad: Array) -> Array:
        """1-sigma multipath (m) at elevation el_rad (rad) of this budget's model."""
        if self.multipath_model == "do253":
            return do253_multipath_sigma_m(el_rad)
        return np.full(np.shape(el_rad), self.multipath_m)

    @property
    def slow_tau_s(self) -> float:
        """Correlation time (s) of the navigation filter's slow channel state: the shortest of the slow terms'
        (stand-alone: clock/ephemeris, iono, tropo; GBAS: ground, iono, tropo residuals)."""
        if self.service is not None:
            return self.service.slow_tau_s
        first = self.clock_ephemeris_tau_s if self.gbas is None else self.gbas.ground_tau_s
        return min(first, self.iono_tau_s, self.tropo_tau_s)

    @property
    def slow_tau_no_iono_s(self) -> float:
        """Correlation time (s) of the slow channel state when the ionosphere has its own (carrier phase): the
        shorter of clock/ephemeris (GBAS: ground) and tropo."""
        first = self.clock_ephemeris_tau_s if self.gbas is None else self.gbas.ground_tau_s
        return min(first, self.tropo_tau_s)

    def carrier_channel_sigmas_m(self, el_rad: Array, x_air_m: Array | None = None, dh_m: Array | None = None,
                                 v_air_mps: Array | None = None) -> tuple[Array, Array, Array | float]:
        """channel_sigmas_m with the ionosphere split off (the navigation filter's states under carrier phase): the
        slow range error without it, the ionospheric error, the fast one, m. Stand-alone sqrt(ce^2 + (T_z M)^2),
        I_z F; GBAS sqrt(gnd^2 + tropo^2), iono (gbas.GbasModel.carrier_channel_sigmas_m)."""
        if self.gbas is not None:
            return self.gbas.carrier_channel_sigmas_m(el_rad, x_air_m, dh_m, v_air_mps)
        if self.service is not None:
            raise ValueError("carrier phase is not modelled with a GNSS service (sensors/gnss/service.py)")
        slow = np.sqrt(self.clock_ephemeris_m**2 + (self.tropo_zenith_m * tropo_mapping(el_rad)) ** 2)
        gmp = self.multipath_sigma_m(el_rad) if self.multipath_model == "do253" else self.multipath_m
        return slow, self.iono_zenith_m * iono_obliquity(el_rad), gmp

    def channel_sigmas_m(self, el_rad: Array, x_air_m: Array | None = None, dh_m: Array | None = None,
                         v_air_mps: Array | None = None) -> tuple[Array, Array | float]:
        """The navigation filter's channel-state 1-sigmas (m) at elevations el_rad (rad): the slow range error and
        the fast one (nav/noise.py).

        Stand-alone: slow sqrt(ce^2 + (I_z F)^2 + (T_z M)^2), fast the multipath (per channel under do253, the one
        value multipath_m under nrc1995); the geometry arguments are not used. GBAS: gbas.GbasModel.channel_sigmas_m
        at the aircraft's distance x_air_m, height dh_m above and speed v_air_mps relative to the reference point
        (None: gbas.REFERENCE_GEOMETRY)."""
        if self.gbas is not None:
            return self.gbas.channel_sigmas_m(el_rad, x_air_m, dh_m, v_air_mps)
        if self.service is not None:  # the filter's own model (service.py), nav/noise.py's guard already applied
            return self.service.filter_channel_sigmas_m(el_rad)
        gse = np.sqrt(self.clock_ephemeris_m**2 + (self.iono_zenith_m * iono_obliquity(el_rad)) ** 2
                      + (self.tropo_zenith_m * tropo_mapping(el_rad)) ** 2)
        gmp = self.multipath_sigma_m(el_rad) if self.multipath_model == "do253" else self.multipath_m
        return gse, gmp


def make_budget(code: str, multipath_model: str = "nrc1995", clock_ephemeris: str = "nrc1995",
                multipath_tau_s: float | None = None, gbas: GbasModel | None = None,
                service: ServiceModel | None = None) -> GnssErrorBudget:
    """The code preset with the chosen multipath model and clock/ephemeris budget (module docstring); tau None:
    the model's default (preset 60 s for nrc1995, DO253_MULTIPATH_TAU_S for do253). With `gbas` the GBAS-corrected
    budget (gbas.py): the stand-alone fields are kept (unused by the sensor), code_noise_m is the white carrier-phase
    noise left on the smoothed code (gbas.CARRIER_NOISE_M) and the airframe multipath must be "do253". With `service`
    (service.py) the service's budget: code_noise_m the same carrier-phase noise, the multipath time the 100 s
    smoothing (the stand-alone fields are kept, unused)."""
    if multipath_model not in MULTIPATH_MODELS:
        raise ValueError(f"multipath_model must be one of {', '.join(MULTIPATH_MODELS)}; got {multipath_model!r}")
    if clock_ephemeris not in CLOCK_EPHEMERIS_M:
        raise ValueError(f"clock_ephemeris must be one of {', '.join(CLOCK_EPHEMERIS_M)}; got {clock_ephemeris!r}")
    if gbas is not None and multipath_model != "do253":
        raise ValueError(f"GBAS corrections need the do253 airframe multipath of the smoothed code; got "
                         f"multipath_model {multipath_model!r}")
    b = CODE_PRESETS[code]
    if multipath_tau_s is None:
        multipath_tau_s = DO253_MULTIPATH_TAU_S if multipath_model == "do253" else b.multipath_tau_s
    b = replace(b, multipath_model=multipath_model, clock_ephemeris_m=CLOCK_EPHEMERIS_M[clock_ephemeris],
                multipath_tau_s=multipath_tau_s)
    if service is not None:
        if gbas is not None:
            raise ValueError("a GNSS service carries its own corrections: no GBAS with it")
        return replace(b, code_noise_m=CARRIER_NOISE_M, multipath_tau_s=AIR_TAU_S, iono_tau_s=IONO_TAU_S,
                       tropo_tau_s=TROPO_TAU_S, clock_ephemeris_tau_s=service.range_tau_s, service=service)
    return b if gbas is None else replace(b, code_noise_m=CARRIER_NOISE_M, gbas=gbas)


def draw_epoch_offsets(window_s: float, rng: base.RngLike) -> Array:
    """Per-run epoch offsets (s), uniform on [0, window_s): one draw from each run's own generator."""
    if base.is_batched(rng):
        return np.array([g.uniform(0.0, window_s) for g in rng])  # type: ignore[union-attr]
    return np.array(rng.uniform(0.0, window_s))  # type: ignore[union-attr]


CODE_PRESETS: Mapping[str, GnssErrorBudget] = MappingProxyType({
    "P(Y)": GnssErrorBudget(clock_ephemeris_m=3.6, iono_zenith_m=0.3, tropo_zenith_m=0.2, multipath_m=1.8,
                            code_noise_m=0.6),
    "C/A": GnssErrorBudget(clock_ephemeris_m=3.6, iono_zenith_m=4.0, tropo_zenith_m=0.2, multipath_m=1.2,
                           code_noise_m=0.6),
})
"""Receiver code presets (module docstring gives the sources)."""


def best_pdop_four(u_los: Array, visible: Array) -> Array:
    """Selection mask (n, k): per epoch the four visible channels of lowest PDOP (all visible if < 4); compiled
    (core/sensors/gnss.py best_four), the same selection as best_pdop_four_reference."""
    sel = np.zeros(np.shape(visible), dtype=bool)
    gk.best_four_epochs(np.ascontiguousarray(u_los, dtype=float), np.ascontiguousarray(visible, dtype=bool), sel)
    return sel


def best_pdop_four_reference(u_los: Array, visible: Array) -> Array:
    """best_pdop_four in numpy (the oracle): PDOP^2 = trace of the position block of inv(G'G) for every combination
    of four visible channels (itertools order), the first minimum (argmin)."""
    n, k = visible.shape
    sel = np.zeros((n, k), dtype=bool)
    for i in range(n):
        idx = np.flatnonzero(visible[i])
        if idx.size <= 4:
            sel[i, idx] = True
            continue
        combos = np.array(list(itertools.combinations(idx, 4)))
        g = np.concatenate([-u_los[i, combos], np.ones(combos.shape + (1,))], axis=-1)  # (c, 4, 4)
        q = np.linalg.inv(np.einsum("cki,ckj->cij", g, g))
        pdop2 = q[:, 0, 0] + q[:, 1, 1] + q[:, 2, 2]
        sel[i, combos[int(np.argmin(pdop2))]] = True
    return sel


def draw_receiver_clock(clock: ClockModel, t_s: Array, rate_hz: float, rng: base.RngLike) -> base.SensorErrors:
    """A receiver clock realization at rate_hz on time base t_s: series bias (m,) m, drift (m,) m/s."""

    def one(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
        c0 = g.standard_normal(2)
        b, d = clock.series(c0, g.standard_normal((m, 2)), dt)
        return {"bias": b, "drift": d}

    return base.make_errors(t_s, rate_hz, rng, one)


@dataclass(frozen=True)
class GnssReceiver:
    """GPS receiver: constellation, code preset, mask, selection, rate; the clock model it carries."""

    constellation: Constellation = field(default_factory=Constellation.nominal)
    budget: GnssErrorBudget = field(default_factory=lambda: CODE_PRESETS["P(Y)"])
    clock: ClockModel = field(default_factory=ClockModel)
    mask_rad: float = math.radians(5.0)
    selection: str = "best4"
    rate_hz: float = 1.0
    doppler: bool = False
    doppler_noise_mps: float = 0.05
    fixed_hold_s: float = 1800.0
    station_ecef: tuple[float, float, float] | None = None
    """The GBAS reference point, ECEF m (needed with a GBAS budget: gbas.GbasModel.station_ecef)."""
    carrier: CarrierModel | None = None
    """Carrier phase with float ambiguities (carrier.py); None: code only."""
    name: str = "gnss"

    fault_targets: ClassVar[tuple[tuple[str, str, str], ...]] = (
        ("pseudorange", "pseudorange_m", "noise"),
        ("pseudorange_rate", "pseudorange_rate_mps", "rate_noise"),
        ("carrier_phase", "carrier_phase_m", "carrier_noise"),
    )

    def __post_init__(self) -> None:
        if self.selection not in SELECTIONS:
            raise ValueError(f"selection must be one of {', '.join(SELECTIONS)}; got {self.selection!r}")
        if self.budget.gbas is not None and self.station_ecef is None:
            raise ValueError("a GBAS budget needs station_ecef, the reference point (GbasModel.station_ecef)")
        h = math.nan
        if self.station_ecef is not None:
            h = float(geo.ecef_to_geodetic(np.asarray(self.station_ecef, dtype=float))[2])
        object.__setattr__(self, "_station_h_m", h)
        g = self.budget.gbas
        # gbas_scales' constant arguments after the truth's (core/sensors/gnss.py), made once
        object.__setattr__(self, "_gbas_args", None if g is None else (
            np.asarray(self.station_ecef, dtype=float), h, g.gad_params(), float(g.reference_receivers),
            g.aad_params(), float(g.sigma_vig_per_m), SMOOTHING_TAU_S, float(g.refractivity_sigma),
            float(g.scale_height_m), IONO_SHELL_M, self.budget.code_noise_m**2))

    @property
    def station_h_m(self) -> float:
        """Ellipsoid height of the GBAS reference point, m (nan without one)."""
        return self._station_h_m  # type: ignore[attr-defined]

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """series (m, 24) m: clock_ephemeris, iono_zenith, tropo_zenith, multipath, noise (+ rate_noise m/s);
        multipath is unit-sigma under the do253 model (apply scales it by sigma_mp at the channel's elevation).
        GBAS budget: ground, iono, tropo, multipath, noise, all unit-sigma Gauss-Markov (apply scales them; module
        docstring), from the same standard normals as the stand-alone series in the same place, and white (m), the
        carrier-phase noise, from the child stream "gbas_white" (seeding.substream: the closed loop, which draws for a
        longer flight, sees the same white noise as the open loop at every sample). With carrier phase (carrier.py):
        carrier_multipath (m), carrier_noise (m) and ambiguity (m, the pool of arc ambiguities) from the child stream
        "carrier" of the receiver's generator (seeding.substream): its own draws stay as they are, and the carrier's
        draws for a shorter record are the first samples of a longer record's (the closed loop draws for a longer
        flight)."""
        b = self.budget
        k = self.constellation.prn.shape[0]

        mp_sigma = 1.0 if b.multipath_model == "do253" else b.multipath_m  # do253: scaled by sigma_mp(el) in apply

        def one(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            out = code(g, m, dt)
            c = self.carrier
            if c is not None:  # from a child stream: the receiver's draws untouched, a prefix of a longer record's
                zc = substream(g, "carrier").standard_normal((m, 3 * k))
                out |= {"carrier_multipath": base.gauss_markov(zc[:, 0:k], c.multipath_m, c.multipath_tau_s, dt),
                        "carrier_noise": c.noise_m * zc[:, k : 2 * k], "ambiguity": c.ambiguity_pool(zc[:, 2 * k :])}
            return out

        def code(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            if b.service is not None:
                return service(g, m, dt)
            z = g.standard_normal((m, (6 if self.doppler else 5) * k))
            extra = {"rate_noise": self.doppler_noise_mps * z[:, 5 * k : 6 * k]} if self.doppler else {}
            if b.gbas is not None:
                return extra | {
                    # a child stream: the others' draws stay the same, and a shorter record's are a prefix of a longer's
                    "white": b.code_noise_m * substream(g, "gbas_white").standard_normal((m, k)),
                    "ground": base.gauss_markov(z[:, 0:k], 1.0, b.gbas.ground_tau_s, dt),
                    "iono": base.gauss_markov(z[:, k : 2 * k], 1.0, b.iono_tau_s, dt),
                    "tropo": base.gauss_markov(z[:, 2 * k : 3 * k], 1.0, b.tropo_tau_s, dt),
                    "multipath": base.gauss_markov(z[:, 3 * k : 4 * k], 1.0, b.multipath_tau_s, dt),
                    "noise": base.gauss_markov(z[:, 4 * k : 5 * k], 1.0, SMOOTHING_TAU_S, dt),
                }
            return extra | {
                "clock_ephemeris": base.gauss_markov(z[:, 0:k], b.clock_ephemeris_m, b.clock_ephemeris_tau_s, dt),
                "iono_zenith": base.gauss_markov(z[:, k : 2 * k], b.iono_zenith_m, b.iono_tau_s, dt),
                "tropo_zenith": base.gauss_markov(z[:, 2 * k : 3 * k], b.tropo_zenith_m, b.tropo_tau_s, dt),
                "multipath": base.gauss_markov(z[:, 3 * k : 4 * k], mp_sigma, b.multipath_tau_s, dt),
                "noise": b.code_noise_m * z[:, 4 * k : 5 * k],
            }

        def service(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            # service.py: unit Gauss-Markov series, scaled at each channel's elevation in apply
            sv = b.service
            z = g.standard_normal((m, (4 if self.doppler else 3) * k + 4))
            extra = {"rate_noise": self.doppler_noise_mps * z[:, 3 * k + 4:]} if self.doppler else {}
            return extra | {
                "range": base.gauss_markov(z[:, 0:k], 1.0, sv.range_tau_s, dt),
                "iono_local": base.gauss_markov(z[:, k:2 * k], 1.0, IONO_TAU_S, dt),
                "air": base.gauss_markov(z[:, 2 * k:3 * k], 1.0, AIR_TAU_S, dt),
                "iono_field": base.gauss_markov(z[:, 3 * k:3 * k + 3], 1.0, IONO_TAU_S, dt),
                "tropo": base.gauss_markov(z[:, 3 * k + 3:3 * k + 4], 1.0, TROPO_TAU_S, dt),
                # per-channel tropo (truth = "broadcast" only) from a child stream: the other draws stay as they are
                "tropo_local": base.gauss_markov(substream(g, "service_tropo").standard_normal((m, k)), 1.0,
                                                 TROPO_TAU_S, dt),
                # a child stream, as GBAS's white noise: a shorter record's draws are a longer one's prefix
                "noise": b.code_noise_m * substream(g, "service_white").standard_normal((m, k)),
            }

        return base.make_errors(t_s, self.rate_hz, rng, one)

    def draw_clock(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """The receiver clock at this receiver's samples: series bias (m,) m and drift (m,) m/s."""
        return draw_receiver_clock(self.clock, t_s, self.rate_hz, rng)

    def geometry_constellation(self, epoch_offset_s: float = 0.0) -> Constellation:
        """The constellation epoch_offset_s (s) after the receiver's epoch (a run's own sky)."""
        if epoch_offset_s == 0.0:
            return self.constellation
        return replace(self.constellation, epoch_s=self.constellation.epoch_s + float(epoch_offset_s))

    def geometry(self, truth: Truth, rows: Array, t_s: Array, epoch_offset_s: float = 0.0) -> dict[str, Array]:
        """Satellite positions, ranges, lines of sight, look angles, visibility, selection and DOPs, with the
        constellation epoch_offset_s (s) after the receiver's epoch (the run's own sky); numpy (apply_reference's
        geometry, the oracle of the compiled sky kernel)."""
        const = self.geometry_constellation(epoch_offset_s)
        r_rx = truth.r_ecef[rows]
        r_sv = const.positions_ecef(t_s)
        rng_m, u, el, az = look_angles(r_rx, r_sv)
        visible = el >= self.mask_rad
        lat, lon, _ = geo.ecef_to_geodetic(r_rx)
        c_ned = geo.c_ecef_to_ned(lat, lon)
        if self.selection == "all":
            sel = visible
        elif self.selection == "best4":
            sel = best_pdop_four_reference(u, visible)
        else:  # best4-fixed: planned at the run start (truth row 0) for the next fixed_hold_s
            t_plan = truth.t_s[0] + np.arange(0.0, self.fixed_hold_s + 1.0, 60.0)
            r0 = np.repeat(truth.r_ecef[:1], t_plan.shape[0], axis=0)
            _, u0, el0, _ = look_angles(r0, const.positions_ecef(t_plan))
            stays = np.all(el0 >= self.mask_rad, axis=0, keepdims=True)
            first = best_pdop_four_reference(u0[:1], stays)[0]
            keep = np.all(visible[:, first], axis=1)
            sel = np.where(keep[:, None], first[None, :] & visible, False)
            if not np.all(keep):
                sel[~keep] = best_pdop_four_reference(u[~keep], visible[~keep])
        _, pdop, _, _ = dops(u, sel, c_ned)
        out = {"r_sv": r_sv, "range": rng_m, "u": u, "el": el, "az": az, "visible": visible, "sel": sel,
               "pdop": pdop}
        if self.doppler:
            out["v_sv"] = const.velocities_ecef(t_s)
        return out

    def geometries(self, truth: Truth, errors: base.SensorErrors) -> dict[str, Array]:
        """geometry() at the samples of `errors`: one sky without an epoch offset; with per-run offsets
        (constants["epoch_offset_s"], (runs,)) each run's own, stacked on a leading run axis (numpy reference)."""
        off = errors.constants.get("epoch_offset_s")
        if off is None or np.ndim(off) == 0:
            return self.geometry(truth, errors.rows, errors.t_s, 0.0 if off is None else float(off))
        per = [self.geometry(truth, errors.rows, errors.t_s, float(o)) for o in np.asarray(off)]
        return {k: np.stack([g[k] for g in per]) for k in per[0]}

    def station_geometry(self, truth: Truth, rows: Array) -> tuple[Array, Array, Array]:
        """(x_air, dh, v_air) (m,) at truth `rows`: slant distance to the GBAS reference point (m), height above it
        (m), horizontal speed (m/s) (gbas.station_geometry; nan without a reference point)."""
        if self.station_ecef is None:
            nan = np.full(np.shape(rows), np.nan)
            return nan, nan, nan
        return station_geometry(truth.r_ecef[rows], truth.h_m[rows], truth.v_ned[rows],
                                np.asarray(self.station_ecef), self.station_h_m)

    def channel_errors(self, series: Mapping[str, Array], el_rad: Array, x_air_m: Array | None = None,
                       dh_m: Array | None = None, v_air_mps: Array | None = None,
                       az_rad: Array | None = None) -> tuple[Array, Array]:
        """The realized errors (m) of the navigation filter's slow and fast channel states (sensors/states.py) from
        one sample's error series (name -> (..., 24)) at elevations el_rad (rad): stand-alone E + F I + M T and the
        (scaled) multipath; GBAS s_gnd g + s_iono I + s_tropo T and s_mp m + s_noise n at the aircraft's geometry
        (x_air_m, dh_m, v_air_mps, broadcast against el_rad); a service (service.py): range + iono + tropo and the
        airborne error, at the azimuths az_rad too (the iono field's gradient); under the nominal filter model, whose
        zenith states carry them (ServiceModel.iono_zenith_state, tropo_zenith_state), the slow error without the
        ionospheric field's common part and the tropospheric zenith residual (F_pp(el) iono_zenith_error and M(el)
        tropo_zenith_error)."""
        b = self.budget
        if b.service is not None:
            r, io, tr, air = b.service.truth_errors(series, el_rad, az_rad, common=not b.service.tropo_zenith_state)
            return r + io + tr, air
        if b.gbas is None:
            slow = series["clock_ephemeris"] + iono_obliquity(el_rad) * series["iono_zenith"] + (
                tropo_mapping(el_rad) * series["tropo_zenith"])
            mp = series["multipath"]
            return slow, (mp * b.multipath_sigma_m(el_rad) if b.multipath_model == "do253" else mp)
        sc = b.gbas.scales(el_rad, x_air_m, dh_m, v_air_mps)
        return (sc["ground"] * series["ground"] + sc["iono"] * series["iono"] + sc["tropo"] * series["tropo"],
                sc["multipath"] * series["multipath"] + sc["noise"] * series["noise"])

    def iono_zenith_error(self, series: Mapping[str, Array]) -> Array:
        """The realized value (m) of the navigation filter's zenith ionospheric state from one sample's error series:
        the common part of the service's vertical residual field (service.ServiceModel.truth_iono_zenith_m), (...,)."""
        return self.budget.service.truth_iono_zenith_m(series)

    def tropo_zenith_error(self, series: Mapping[str, Array]) -> Array:
        """The realized value (m) of the navigation filter's zenith tropospheric state from one sample's error series
        (service.ServiceModel.truth_tropo_zenith_m), (...,)."""
        return self.budget.service.truth_tropo_zenith_m(series)

    def carrier_channel_errors(self, series: Mapping[str, Array], el_rad: Array, x_air_m: Array | None = None,
                               dh_m: Array | None = None, v_air_mps: Array | None = None) -> tuple[Array, Array, Array]:
        """channel_errors with the ionosphere split off (carrier phase: the filter's gse, gio, gmp), m: stand-alone
        E + M T, F I and the multipath; GBAS s_gnd g + s_tropo T, s_iono I and s_mp m + s_noise n."""
        b = self.budget
        slow, fast = self.channel_errors(series, el_rad, x_air_m, dh_m, v_air_mps)
        if b.gbas is None:
            slow = series["clock_ephemeris"] + tropo_mapping(el_rad) * series["tropo_zenith"]
            return slow, iono_obliquity(el_rad) * series["iono_zenith"], fast
        sc = b.gbas.scales(el_rad, x_air_m, dh_m, v_air_mps)
        return sc["ground"] * series["ground"] + sc["tropo"] * series["tropo"], sc["iono"] * series["iono"], fast

    def sigma_m(self, el_rad: Array, x_air_m: Array | None = None, dh_m: Array | None = None,
                v_air_mps: Array | None = None) -> Array:
        """Nominal 1-sigma pseudorange error at elevation el (m): RSS of the budget with its mappings (GBAS: of the
        corrected residual at the aircraft's geometry, broadcast against el_rad; gbas.GbasModel.sigma_m)."""
        b = self.budget
        if b.gbas is not None:
            return b.gbas.sigma_m(el_rad, x_air_m, dh_m, v_air_mps)
        if b.service is not None:  # DO-229's broadcast sigma_i (service.py)
            return b.service.sigma_m(el_rad)
        return np.sqrt(
            b.clock_ephemeris_m**2 + (b.iono_zenith_m * iono_obliquity(el_rad)) ** 2
            + (b.tropo_zenith_m * tropo_mapping(el_rad)) ** 2 + b.multipath_sigma_m(el_rad) ** 2
            + b.code_noise_m**2
        )

    @staticmethod
    def skies(errors: base.SensorErrors) -> tuple[Array, bool]:
        """The epoch offsets (S,) s of the skies of `errors` and whether they are per run (S = runs, the record's
        geometry then has a leading run axis) or one sky for all runs (S = 1; offset 0 without one)."""
        off = errors.constants.get("epoch_offset_s")
        if off is None:
            return np.zeros(1), False
        if np.ndim(off) == 0:
            return np.array([float(off)]), False
        offs = np.asarray(off, dtype=float)
        runs = next(iter(errors.series.values())).shape[0] if errors.batched else 1
        if not errors.batched or offs.shape != (runs,):
            raise ValueError(f"per-run epoch offsets {offs.shape} need errors batched over as many runs ({runs})")
        return offs, True

    def plan(self, truth: Truth, offsets_s: Array) -> Array:
        """The planned four (S, 24) of best4-fixed on each sky (offsets_s (S,) s): the best-PDOP four at truth row 0
        among the satellites that stay above the mask over fixed_hold_s seen from there (sampled every 60 s);
        all False for the other selections."""
        k = self.constellation.prn.shape[0]
        if self.selection != "best4-fixed":
            return np.zeros((np.shape(offsets_s)[0], k), dtype=bool)
        t_plan = truth.t_s[0] + np.arange(0.0, self.fixed_hold_s + 1.0, 60.0)
        r0 = np.ascontiguousarray(np.repeat(truth.r_ecef[:1], t_plan.shape[0], axis=0), dtype=float)
        r_sv, _ = self.constellation.orbits(t_plan, offsets_s)
        _, u, el, _ = gk.look_angles(r0, r_sv)
        stays = np.ascontiguousarray(np.all(el >= self.mask_rad, axis=1))
        first = np.zeros(stays.shape, dtype=bool)
        gk.best_four_epochs(np.ascontiguousarray(u[:, 0]), stays, first)
        return first

    def apply(
        self, truth: Truth, errors: base.SensorErrors, clock: base.SensorErrors | None = None
    ) -> GnssSamples:
        """Pseudoranges at the truth rows of `errors`; `clock` from draw_clock (None: a zero receiver clock).
        Compiled (core/sensors/gnss.py); equal to apply_reference to 1e-12 relative, the same selections."""
        offs, per_run = self.skies(errors)
        r_sv, v_sv = self.constellation.orbits(errors.t_s, offs, self.doppler)
        series = _run_axis(errors)
        bias, drift = _clock_arrays(clock, next(iter(series.values())).shape[:2])
        return self.record(truth, errors.rows, errors.t_s, r_sv, v_sv, self.plan(truth, offs), series, bias, drift,
                           per_run, errors.batched, errors.constants.get("epoch_offset_s"),
                           None if self.carrier is None else (0, None, None, series["ambiguity"]))

    def record(self, truth: Truth, rows: Array, t_s: Array, r_sv: Array, v_sv: Array | None, plan: Array,
               series: Mapping[str, Array], bias: Array, drift: Array, per_run: bool, batched: bool,
               epoch_offset_s: Array | None, carrier: tuple | None = None) -> GnssSamples:
        """The record of samples at truth `rows` (times t_s) from the satellites r_sv (and velocities v_sv) (S, m, 24,
        3) of S skies, best4-fixed's plan (S, 24), the error series (R, m, 24) by name and the receiver clock bias
        and drift (R, m); per_run: the geometry keeps its sky axis; batched: the run axis is kept. carrier (with
        carrier phase): (j0, prev_valid, prev_arc, pool): the global index of the first sample, the channels'
        validity and arc id at the sample before (None at the record's start; carrier.carrier_arcs) and the
        ambiguity pool of the whole record (R, M, 24)."""
        b = self.budget
        mode = {"all": gk.MODE_ALL, "best4": gk.MODE_BEST4, "best4-fixed": gk.MODE_PLANNED}[self.selection]
        c = np.ascontiguousarray
        r_rx = c(truth.r_ecef[rows], dtype=float)
        rng, u, el, az, vis, sel, pdop, f_iono, m_tropo, mp_scale, sigma = gk.sky(
            r_rx, c(r_sv), float(self.mask_rad), mode, c(plan), IONO_SHELL_M,
            b.multipath_model == "do253", float(b.multipath_m), b.clock_ephemeris_m**2, float(b.iono_zenith_m),
            float(b.tropo_zenith_m), b.code_noise_m**2)
        if b.service is not None:  # service.py: the correlated truth; the record's sigma the broadcast sigma_i
            pr, valid = service_pseudoranges(b.service, rng, el, az, sel, series, bias, 0)
            sigma = b.service.sigma_m(el)
        elif b.gbas is None:
            pr, valid = gk.pseudoranges(rng, f_iono, m_tropo, mp_scale, sel, c(series["clock_ephemeris"]),
                                        c(series["iono_zenith"]), c(series["tropo_zenith"]), c(series["multipath"]),
                                        c(series["noise"]), c(bias))
            if self.carrier is not None:  # the carrier's slow errors with the code's sign, and its iono term
                slow, iono = (series["clock_ephemeris"] + m_tropo * series["tropo_zenith"],
                              f_iono * series["iono_zenith"])
        else:
            s_gnd, s_iono, s_tropo, s_mp, s_noise, sigma = gk.gbas_scales(
                el, r_rx, c(truth.h_m[rows], dtype=float), c(truth.v_ned[rows], dtype=float),
                *self._gbas_args)  # type: ignore[attr-defined]
            terms = tuple((sc, c(series[n])) for sc, n in ((s_gnd, "ground"), (s_iono, "iono"), (s_tropo, "tropo"),
                                                           (s_mp, "multipath"), (s_noise, "noise"),
                                                           (np.ones(rng.shape), "white")))
            pr, valid = gk.pseudorange_sum(rng, sel, terms, c(bias))
            if self.carrier is not None:
                slow, iono = s_gnd * series["ground"] + s_tropo * series["tropo"], s_iono * series["iono"]
        phi = arc = None
        if self.carrier is not None:
            j0, prev_valid, prev_arc, pool = carrier  # type: ignore[misc]
            arc = carrier_arcs(valid, j0, prev_valid, prev_arc)
            # phi = range + b_rx + lambda N + S - I + c + w  (carrier.py)
            phi = (rng + slow - iono + series["carrier_multipath"] + series["carrier_noise"] + bias[..., None]
                   + ambiguities(arc, pool))
        prr = None
        if self.doppler:
            prr = gk.pseudorange_rates(u, c(v_sv), c(truth.lat_rad[rows], dtype=float),
                                       c(truth.lon_rad[rows], dtype=float), c(truth.v_ned[rows], dtype=float), sel,
                                       c(drift), c(series["rate_noise"]))
        sky = (lambda a: a) if per_run else (lambda a: a[0])
        run = (lambda a: a) if batched else (lambda a: a[0])
        return GnssSamples(
            t_s=t_s, prn=self.constellation.prn, r_sv_ecef=sky(r_sv), pseudorange_m=run(pr), sigma_m=sky(sigma),
            elevation_rad=sky(el), azimuth_rad=sky(az), visible=sky(vis), valid=run(valid), pdop=sky(pdop),
            clock_bias_m=np.array(run(bias)), clock_drift_mps=np.array(run(drift)),
            fault=np.zeros(run(pr).shape, dtype=np.int8), pseudorange_rate_mps=None if prr is None else run(prr),
            epoch_offset_s=epoch_offset_s, carrier_phase_m=None if phi is None else run(phi),
            carrier_arc=None if arc is None else run(arc),
            carrier_sigma_m=None if self.carrier is None else self.carrier.sigma_m,
        )

    def prepare(self, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> PreparedGnss:
        """`errors` (and the receiver clock at the same samples) laid out for one sample at a time (closed loop)."""
        return PreparedGnss(self, errors, clock)

    def apply_reference(
        self, truth: Truth, errors: base.SensorErrors, clock: base.SensorErrors | None = None
    ) -> GnssSamples:
        """`apply` in numpy: the readable model (module docstring) and the compiled kernels' test oracle."""
        geo_ = self.geometries(truth, errors)
        s = errors.series
        el = geo_["el"]
        geom: tuple[Array | None, ...] = (None, None, None)
        if self.budget.service is not None:
            r_, io, tr, air = self.budget.service.truth_errors(s, el, geo_["az"])
            pr = geo_["range"] + r_ + io + tr + air + s["noise"]
        elif self.budget.gbas is not None:
            geom = tuple(a[:, None] for a in self.station_geometry(truth, errors.rows))  # (m, 1) against (.., m, k)
            sc = self.budget.gbas.scales(el, *geom)
            pr = (geo_["range"] + sc["ground"] * s["ground"] + sc["iono"] * s["iono"] + sc["tropo"] * s["tropo"]
                  + sc["multipath"] * s["multipath"] + sc["noise"] * s["noise"] + s["white"])
        else:
            mp = (s["multipath"] * do253_multipath_sigma_m(el) if self.budget.multipath_model == "do253"
                  else s["multipath"])
            pr = (
                geo_["range"] + s["clock_ephemeris"] + iono_obliquity(el) * s["iono_zenith"]
                + tropo_mapping(el) * s["tropo_zenith"] + mp + s["noise"]
            )
        shape_t = pr.shape[:-1]
        if clock is None:
            cb = np.zeros(shape_t)
            cd = np.zeros(shape_t)
        else:
            cb = np.broadcast_to(clock.series["bias"], shape_t)
            cd = np.broadcast_to(clock.series["drift"], shape_t)
        pr = pr + cb[..., None]
        valid = np.broadcast_to(geo_["sel"], pr.shape).copy()
        phi = arc = None
        if self.carrier is not None:  # phi = range + b_rx + lambda N + S - I + c + w (carrier.py)
            if self.budget.gbas is not None:
                slow, iono = sc["ground"] * s["ground"] + sc["tropo"] * s["tropo"], sc["iono"] * s["iono"]
            else:
                slow = s["clock_ephemeris"] + tropo_mapping(el) * s["tropo_zenith"]
                iono = iono_obliquity(el) * s["iono_zenith"]
            run_axis = valid if errors.batched else valid[None]
            arc = carrier_arcs(run_axis)
            pool = s["ambiguity"] if errors.batched else s["ambiguity"][None]
            amb = ambiguities(arc, pool)
            arc, amb = (arc, amb) if errors.batched else (arc[0], amb[0])
            phi = np.where(valid, geo_["range"] + slow - iono + s["carrier_multipath"] + s["carrier_noise"]
                           + cb[..., None] + amb, np.nan)
        prr = None
        if self.doppler:
            r = errors.rows
            lat, lon = truth.lat_rad[r], truth.lon_rad[r]
            v_rx = np.einsum("nji,nj->ni", geo.c_ecef_to_ned(lat, lon), truth.v_ned[r])  # NED -> ECEF
            rr = np.einsum("...ki,...ki->...k", geo_["u"], geo_["v_sv"] - v_rx[:, None, :])
            cd_ = np.zeros(shape_t) if clock is None else np.broadcast_to(clock.series["drift"], shape_t)
            prr = np.where(valid, rr + cd_[..., None] + s["rate_noise"], np.nan)
        return GnssSamples(
            t_s=errors.t_s, prn=self.constellation.prn, r_sv_ecef=geo_["r_sv"],
            pseudorange_m=np.where(valid, pr, np.nan), sigma_m=self.sigma_m(el, *geom), elevation_rad=el,
            azimuth_rad=geo_["az"], visible=geo_["visible"], valid=valid, pdop=geo_["pdop"],
            clock_bias_m=np.array(cb), clock_drift_mps=np.array(cd), fault=np.zeros(pr.shape, dtype=np.int8),
            pseudorange_rate_mps=prr, epoch_offset_s=errors.constants.get("epoch_offset_s"), carrier_phase_m=phi,
            carrier_arc=arc, carrier_sigma_m=None if self.carrier is None else self.carrier.sigma_m,
        )

    def measure(
        self, truth: Truth, rng: base.RngLike, *, noise: bool = True, clock_rng: base.RngLike | None = None
    ) -> GnssSamples:
        """apply(truth, draw(t, rng), draw_clock(t, clock_rng)); no clock_rng: a zero receiver clock.

        noise=False zeroes every error including the clock: pseudorange = geometric range.
        """
        e = self.draw(truth.t_s, rng)
        c = None if clock_rng is None else self.draw_clock(truth.t_s, clock_rng)
        if not noise:
            e = e.zeroed()
            c = None if c is None else c.zeroed()
        return self.apply(truth, e, c)


def service_pseudoranges(sv: ServiceModel, rng: Array, el: Array, az: Array, sel: Array,
                         series: Mapping[str, Array], bias: Array, j0: int) -> tuple[Array, Array]:
    """A service's pseudoranges (R, m, k) m and validity (core/sensors/gnss.py service_errors, pseudorange_sum) from
    the sky's range, elevation, azimuth and selection (S, m, k) and the unit series (R, M, ...) read at samples
    j0 + i, receiver clock bias (R, m) m: rho = |r_sv - r| + slow + air + noise + b_rx."""
    c = np.ascontiguousarray
    full = (bias.shape[0],) + rng.shape[1:]
    slow, air = np.empty(full), np.empty(full)
    gk.service_errors(el, az, sv.params(), sv.truth_shape(), tuple(c(series[n]) for n in SERVICE_SERIES), j0, slow,
                      air)
    noise = c(series["noise"][:, j0:j0 + full[1]])
    one = np.ones(rng.shape)
    # the bias writeable (a read-only one typed a second compilation of the kernel on a cold cache)
    return gk.pseudorange_sum(rng, sel, ((one, slow), (one, air), (one, noise)),
                              np.require(bias, dtype=float, requirements=("C", "W")))


def service_group(sv: ServiceModel | None, series: Mapping[str, Array], k: int) -> tuple:
    """core/loop/aiding.py direct_inputs' `service` group: (on, broadcast parameters, truth shape, the unit series
    (1, M, ...), the noise series (1, M, k) m, scratch of one-sample C arrays for k channels); `on` False with
    empty arrays of the same types when sv is None."""
    c = np.ascontiguousarray
    k = k if sv is not None else 0
    scratch = (np.ones((1, 1, k)), np.empty((1, 1, k)), np.empty((1, 1, k)), np.empty((1, 1, k)), np.empty((1, 1)),
               np.empty((1, k)), np.empty((1, k)), np.empty((1, k)))
    if sv is None:
        return (False, np.zeros(0), np.zeros(0), tuple(np.zeros((1, 0, 0)) for _ in SERVICE_SERIES),
                np.zeros((1, 0, 0)), scratch)
    return (True, sv.params(), sv.truth_shape(), tuple(c(series[n]) for n in SERVICE_SERIES), c(series["noise"]),
            scratch)


def _run_axis(errors: base.SensorErrors) -> dict[str, Array]:
    """The error series of `errors` with a run axis: name -> (R, m, ...) (a view for one run)."""
    return dict(errors.series) if errors.batched else {k: v[None] for k, v in errors.series.items()}


def _clock_arrays(clock: base.SensorErrors | None, shape: tuple[int, ...]) -> tuple[Array, Array]:
    """Receiver clock bias (m) and drift (m/s) broadcast to `shape` (R, m): zeros without a clock."""
    if clock is None:
        return np.zeros(shape), np.zeros(shape)
    return (np.ascontiguousarray(np.broadcast_to(clock.series["bias"], shape)),
            np.ascontiguousarray(np.broadcast_to(clock.series["drift"], shape)))


class PreparedGnss:
    """A receiver's drawn errors laid out for one sample at a time (the closed loop's 1 Hz epochs).

    The satellite positions (and velocities) of every sample of every sky, the error series with a run axis and
    the receiver clock at the GNSS samples are made once; best4-fixed's plan once per truth start (row 0).
    at(truth, j) is GnssReceiver.apply(truth, errors.sample(j), clock.sample(j)), bit for bit: the same kernels
    on the same values (tests/unit/sensors/test_prepared.py)."""

    def __init__(self, rx: GnssReceiver, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> None:
        self.rx = rx
        self.errors = errors
        self.offsets, self.per_run = rx.skies(errors)
        self.r_sv, self.v_sv = rx.constellation.orbits(errors.t_s, self.offsets, rx.doppler)
        self.series = _run_axis(errors)
        self.bias, self.drift = _clock_arrays(clock, next(iter(self.series.values())).shape[:2])
        self.epoch_offset_s = errors.constants.get("epoch_offset_s")
        self._plan_at: tuple[float, bytes] | None = None
        self._plan = np.zeros((self.offsets.shape[0], rx.constellation.prn.shape[0]), dtype=bool)
        self._carrier: tuple | None = None
        """(j, valid, arc, state before j) of the last sample given (carrier phase: the arcs continue from it)."""
        self._direct: tuple | None = None
        """channels_one's constants (made at its first call)."""

    def plan(self, truth: Truth) -> Array:
        """best4-fixed's plan for this truth's start (kept while row 0 is the same)."""
        if self.rx.selection != "best4-fixed":
            return self._plan
        key = (float(truth.t_s[0]), truth.r_ecef[0].tobytes())
        if key != self._plan_at:
            self._plan, self._plan_at = self.rx.plan(truth, self.offsets), key
        return self._plan

    def at(self, truth: Truth, j: int) -> GnssSamples:
        """The record of sample j alone (one-sample axes, as apply on errors.sample(j)). With carrier phase the
        arcs continue from the previous sample's: samples come in increasing order (the last one may be given
        again), samples skipped since the last one are run first (their validity decides the arcs), so at(truth, j)
        equals sample j of apply's record."""
        if self.rx.carrier is not None:
            for jj in carrier_gap(self._carrier, j):
                self._one(truth, jj)
        return self._one(truth, j)

    def _one(self, truth: Truth, j: int) -> GnssSamples:
        sl = slice(j, j + 1)
        e = self.errors
        carrier = None
        if self.rx.carrier is not None:
            carrier = carrier_continuation(self._carrier, j, self.series["ambiguity"])
        rec = self.rx.record(
            truth, e.rows[sl], e.t_s[sl], self.r_sv[:, sl], None if self.v_sv is None else self.v_sv[:, sl],
            self.plan(truth), {k: v[:, sl] for k, v in self.series.items()}, self.bias[:, sl], self.drift[:, sl],
            self.per_run, e.batched, self.epoch_offset_s, carrier)
        if carrier is not None:
            self._carrier = carrier_last(j, rec.valid, rec.carrier_arc, carrier)
        return rec

    def direct_constants(self) -> tuple[int, tuple, tuple[Array, ...]]:
        """channels_one's selection mode, sky constants (shell m, do253, multipath m, ce^2, I_z, T_z, code noise^2)
        and error series (clock_ephemeris, iono_zenith, tropo_zenith, multipath, noise), made at the first call;
        ValueError unless a one-run, one-sky, stand-alone code receiver."""
        if self._direct is None:
            rx, e = self.rx, self.errors
            if rx.budget.gbas is not None or rx.carrier is not None or self.per_run or e.batched:
                raise ValueError("channels_one: a one-run code receiver without GBAS only")
            b = rx.budget
            if b.service is None:
                series = tuple(self.series[n] for n in ("clock_ephemeris", "iono_zenith", "tropo_zenith", "multipath",
                                                        "noise"))
            else:  # the service's series go by direct_service
                series = tuple(np.zeros((1, 0, 0)) for _ in range(5))
            self._direct = ({"all": gk.MODE_ALL, "best4": gk.MODE_BEST4, "best4-fixed": gk.MODE_PLANNED}[rx.selection],
                         (IONO_SHELL_M, b.multipath_model == "do253", float(b.multipath_m), b.clock_ephemeris_m**2,
                          float(b.iono_zenith_m), float(b.tropo_zenith_m), b.code_noise_m**2), series)
        return self._direct

    def direct_service(self) -> tuple:
        """core/loop/aiding.py direct_inputs' `service` group for this receiver (service_group)."""
        return service_group(self.rx.budget.service, self.series, self.r_sv.shape[2])

    @staticmethod
    def no_service() -> tuple:
        """direct_inputs' `service` group of a receiver without a service (service_group: off)."""
        return service_group(None, {}, 0)

    def channels_one(self, truth: Truth, j: int) -> tuple[Array, Array, Array, Array, Array]:
        """Sample j of a one-run, one-sky, stand-alone code receiver (no GBAS, no carrier phase) without the record:
        at(truth, j)'s pseudorange_m (1, 24) m, valid (1, 24), r_sv_ecef[0] (24, 3) m, sigma_m[0] (24,) m and
        elevation_rad[0] (24,) rad, by the same kernels (gk.sky, gk.pseudoranges) on the same values (the closed
        loop's compiled aiding epoch reads only these)."""
        rx, e = self.rx, self.errors
        mode, consts, series = self.direct_constants()
        k = int(e.rows[j])
        sl = slice(j, j + 1)
        rng, u, el, az, vis, sel, pdop, f_iono, m_tropo, mp_scale, sigma = gk.sky(
            truth.r_ecef[k:k + 1].copy(), np.ascontiguousarray(self.r_sv[:, sl]), float(rx.mask_rad), mode,
            self.plan(truth), *consts)
        pr, valid = gk.pseudoranges(rng, f_iono, m_tropo, mp_scale, sel, *(np.ascontiguousarray(a[:, sl])
                                                                           for a in series),
                                    np.ascontiguousarray(self.bias[:, sl]))
        return pr[0], valid[0], self.r_sv[0, j], sigma[0, 0], el[0, 0]


def carrier_gap(last: tuple | None, j: int) -> range:
    """The samples between the last one given (carrier_continuation's `last`) and j, to be run before j."""
    return range(0 if last is None else last[0] + 1, j)


def carrier_continuation(last: tuple | None, j: int, pool: Array) -> tuple:
    """record()'s carrier argument (j, valid and arc at j - 1, pool) for sample j after the last sample given, `last`
    = (j_last, valid, arc, the state before j_last) (None: none yet, j must be 0). The same j again (a repeated
    epoch) starts from the state before it."""
    if last is None or j == 0:
        if j != 0:
            raise ValueError(f"carrier phase: samples are taken in order from 0; got {j} first")
        return (0, None, None, pool)
    j_last, valid, arc, before = last
    if j == j_last:
        return (j, *before, pool)
    if j != j_last + 1:
        raise ValueError(f"carrier phase: samples are taken in increasing order (skipped ones run first: "
                         f"carrier_gap); got {j} after {j_last}")
    return (j, valid, arc, pool)


def carrier_last(j: int, valid: Array, arc: Array, carrier: tuple) -> tuple:
    """The state after sample j of a one-sample record (its valid and arc, sample axis dropped; carrier: the
    argument it was made with) for carrier_continuation."""
    _, pv, pa, _ = carrier
    return (j, np.asarray(valid)[..., -1, :], np.asarray(arc)[..., -1, :], (pv, pa))
