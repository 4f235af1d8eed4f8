"""The filter's noise model: process noise and the prior covariance P0, built from the error budgets the sensors
declare (the IMU grade's preset, the baro, the GNSS code budget and receiver clock, the pseudolites, the radar
altimeter) and the navigation configuration (initial INS errors, terrain database).

    model = NoiseModel(sensors_config, nav_config, layout)
    model.noise(elevation_rad)              # errormodel.ErrorNoise, GPS channel noise at their elevations
    model.initial_covariance(elevation_rad) # P0 (n, n)

The filter knows the sensors' error budgets, not their realizations: the same budgets the sensor models draw from
(sensors/presets.py, sensors/gnss/receiver.py, sensors/gnss/clock.py), so a consistent filter is the default.
The GPS channel states' noise depends on each channel's elevation (iono obliquity, tropo mapping, DO-253
multipath); `noise` is a pure function of the configuration and the elevations and is cached per elevation vector.
The receiver's budget gives it (receiver.GnssErrorBudget.channel_sigmas_m and slow_tau_s): stand-alone, the slow
state is clock/ephemeris + iono + tropo, the fast one the multipath; with GBAS corrections (sensors/gnss/gbas.py)
the slow state is the ground + iono + tropo residual and the fast one the airborne multipath + smoothed receiver
noise (the white code noise left is the 2 mm carrier-phase noise: the budget's code_noise_m). The GBAS iono and
tropo residuals grow with the aircraft's distance from and height above the reference point; the elevation-only
noise here (and P0) takes them at the approach's start (`NoiseModel.gbas_geometry`, gbas.approach_geometry; before
2026-12-05 always at gbas.REFERENCE_GEOMETRY, the start of a 10 nmi final, so that a longer final started with its
channel variances mismatched); the epochs move the slow state to the aircraft's geometry (nav/gbas_scale.py).

Carrier phase ([sensors.gnss] carrier_phase, the layout's gio and amb states): the ionospheric part of the slow state
gets its own per-channel state gio (Gauss-Markov at iono_tau_s, sigma the iono part of the budget at the elevation)
and gse keeps the rest (its correlation time the shorter of clock/ephemeris or ground and tropo); split because the
carrier has the ionospheric error with the opposite sign of the code, which a shared state cannot carry: code minus
carrier is then 2 I + multipath - ambiguity, and with I inside gse the filter would read the slow drift of 2 I (the
GM's own variation and the GBAS scale shrinking along the approach) as a change of the constant ambiguity. The float
ambiguities amb are random constants with prior 1-sigma carrier_ambiguity_sigma_m (the sensor's own spread of an
arc's ambiguity: an honest prior), reset at every new arc (nav/navigator.py). The carrier multipath (1 cm, tau 5 s)
is measurement noise, not a state (`carrier_sigma_m`): its white equivalent sigma^2 (1 + a) / (1 - a), a = exp(-dt /
tau), at the filter's carrier interval dt, has the long-run average of the Gauss-Markov (the quantity the float
ambiguity and the position integrate), while over a few epochs it is conservative; carried as a state it would add
24 more states for errors three orders below the code's that set the position error. Measured (GBAS candidate with
carrier, 40 open-loop runs, 200 s): a 0.5 s multipath correlation time (inflation 1.3 instead of 10) leaves the
filter's vertical sigma at the end at 0.2223 m against 0.2224 m, the true RMS 0.243 against 0.244 m: the carrier's
fast error does not limit the position, so the simpler, conservative form is kept.

The slow channel state's correlation time (`slow_tau_s`). The sensor draws the slow error as a sum of independent
Gauss-Markov processes (stand-alone: clock/ephemeris 2 h, iono 30 min, tropo 1 h; GBAS: ground 300 s, iono, tropo;
a service: its range, iono and tropo terms); the filter carries their sum as one state. Its variance is their summed
variance; its time constant is the variance-weighted harmonic mean of theirs over a reference sky, so that its drift
rate 2 sigma^2 / tau is theirs (over an approach of a few minutes, much shorter than every tau, that rate, not the
shape of the autocorrelation, is what the range error does). The shortest of the three, used before, made the
default profile's filter expect the clock/ephemeris error (2.4 m of its 2.5 m at 30 deg) to drift four times as fast
as it does (1800 s for 5838 s): it over-claimed the horizontal velocity error (run-averaged e^2/P 0.82 / 0.63, N / E).
Not one state per process: the three enter every pseudorange with the same unit coefficient, so the filter cannot
separate them, and 2 x 24 more channel states would triple the channel block's cost for the one combination it
sees. Not a time constant per channel: the compiled epochs share one Phi and one Qd factor per epoch across the
channels; over the 5-90 deg sky the drift-matched tau of the default budget spans 4445-6840 s, and a truth with all
three processes at the filter's one tau changed the default profile's horizontal velocity e^2/P by 0.05 at most.

The zenith states (the layout's giz and gtz, a GNSS service under the nominal filter model: sensors/gnss/service.py,
docs/gnss-services.md). The truth draws a single-frequency ionospheric residual as ONE vertical field over the
pierce points (75 % of its variance common to all, a planar gradient 20 % at the pierce distance d_5 of a 5 deg
satellite, 5 % local), each satellite seeing it through its obliquity F_pp(el), and the tropospheric residual as
one zenith value mapped by M(el). Per-channel states with those variances but independent between channels make
the filter read the common parts as a receiver clock error of 1/n their size and over-state the channels'
differences (sbas-lpv200, 60 runs: clock e^2/P 1.61-1.76, horizontal 0.42-0.53). So the field is three states giz
(its common part at f_i sqrt(w0) sigma_vertical, its east and north gradient per d_5 at f_i sqrt(w_g)
sigma_vertical each, the field's tau: ServiceModel.filter_iono_zenith), -F_pp(el) (1, (d / d_5) sin az, (d / d_5)
cos az) in every GPS code row, d the pierce distance; the troposphere one state gtz (f_t sigma_TVE, its tau:
ServiceModel.filter_tropo_zenith), -M(el) in every code row; the channel's slow state keeps the range residual and
the field's local part F_pp f_i sigma_vertical sqrt(w_l) (gnss_errors.service_terms), so that the variances sum to
the truth's per channel. Why the gradient as states: left in the channels as independent per channel, the gradient,
whose coefficient follows the line of sight's horizontal direction and so aliases into the horizontal position,
left the horizontal over-confident (sbas-lpv200, seeds 1 / 2 / 3: dp_N 1.35 / 1.57 / 1.15; 1.19 / 1.33 / 1.01 with
the gradient states). Why the troposphere: per channel it made the DFMC filter's clock over-confident (1.53; 1.02
with gtz).

Gyro scale-factor and misalignment errors (`gyro_axis_q`): the IMU's (S + M) w_ib (random constants per run, the
grade's sigmas) is process noise, not 9 filter states. It makes the INS attitude error -int C_bn (S + M) w_ib dt.
Its first-order part -C_bn(0) (S + M) (Theta(t) - Theta(0)), Theta the integral of the body rate, is bounded (light
turbulence: Var(Theta - mean) 4.29e-4 / 6.45e-4 / 4.86e-4 rad^2, 1/e times 1.1 / 5.0 / 3.3 s: a tilt of 2-3 urad
at nav-2.0, decorrelated within seconds) and moves the aided velocity too little to matter: carried as three
Gauss-Markov states (branch i39g) it changed no pooled e^2/P by more than 0.031 and, alone, left the filter as
over-confident as no model (default profile, seeds 1-4: horizontal velocity 1.39 / 1.94). The rest is not bounded: the
mean body rate (the Earth and transport rates, the attitude's trend) times S + M is a ramp, and the rotating C_bn
rectifies the Dutch roll's roll-yaw coning into the pitch axis (Theta x S Theta', second order in the rotation).
Propagated exactly over draws of S and M on the flown truth, its variance grows as q t: the filter carries it as a
white noise of the attitude error's rate per body axis, q_k = sf^2 D_k + mis^2 E_k (SF_DRIFT_Q, measured by
tools/body_rate_psd.py --drift over 100 flights), rotated to NED. The white noise matched to the rotation's
increments over the filter's 25 s velocity-error time used before (the first-order part's, 1.4-12 times this)
over-claimed the horizontal velocity (e^2/P 0.86-0.92 pooled over 20 seeds in every case of the consistency
suite, docs/consistency.md). States would need the body rate in the compiled error dynamics (every epoch kernel's
inputs), 9 more states in every covariance, and would estimate quantities that, at 100 ppm and 0.02 mrad, the
approach's few degrees of rotation cannot observe. The accelerometer's scale factor and misalignment are in the ba
prior (under 1 g they look like a bias).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from approachsim.nav import errormodel as em
from approachsim.nav.config import NavConfig
from approachsim.sensors import atmosphere
from approachsim.sensors.config import SensorsConfig
from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.elevation import iono_obliquity, tropo_mapping
from approachsim.sensors.gnss.gbas import REFERENCE_GEOMETRY
from approachsim.sensors.gnss.receiver import GnssErrorBudget
from approachsim.sensors.presets import PRESETS

Array = np.ndarray

_CACHE_MAX = 512
"""Elevation vectors kept by `NoiseModel.noise` (one sky's epochs x runs at most)."""

SKY_SIN_EL = np.linspace(np.sin(np.radians(5.0)), 1.0, 16)
"""The reference sky of `slow_tau_s`: 16 elevations equally spaced in sin(el) from 5 deg to the zenith (equal solid
angle above the default 5 deg mask)."""

SF_DRIFT_Q: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "none": ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    "light": ((2.20e-6, 4.02e-5, 2.05e-6), (3.15e-5, 4.14e-6, 2.80e-5)),
    "moderate": ((8.81e-6, 2.07e-4, 7.02e-6), (1.63e-4, 1.53e-5, 1.48e-4)),
    "severe": ((4.46e-5, 1.05e-3, 3.55e-5), (8.25e-4, 7.75e-5, 7.49e-4)),
}
"""The unbounded part of the gyro scale-factor / misalignment attitude error as white rate noise per body axis (x, y,
z), rad^2/s per unit sf^2 (first) and per unit mis^2 (second), by turbulence level: tools/body_rate_psd.py --drift on
the default profile's 737, 100 flights (seeds 101-200, run 0; 200 unit draws of S and of M each): the exact error
-int C_bn (S + M) w_ib dt less its bounded first-order part -C_bn(0) (S + M) (Theta(t) - Theta(0)), its variance
fitted as q t over the approach, averaged over the flights (light +- 2.9e-7, 1.5e-6, 2.8e-7 and 1.2e-6, 4.2e-7,
1.1e-6; one flight's pitch figure ranges 0.4-2x the mean, skewed: the first measurement on seeds 1-6 gave 0.65 of
it). The pitch axis's sf part is the Dutch roll's coning (roll and yaw in quadrature rectify into it: Theta x S
Theta') and the ramp of the mean pitch rate; moderate / light 5.2, about the square of the rotation variance ratio, as
a second-order rectification scales. Severe, beyond the 737's approach limit, is moderate x 2.25^2 (the Dryden gust
variance ratio (75 / 50)^2, squared; engineering choice)."""

PSEUDOLITE_CLOCK = ("ocxo", 30.0, 0.03)
"""An unsynchronized pseudolite's transmitter clock: oscillator, bias and drift 1-sigma at the start (m, m/s)."""


def slow_terms(bud: GnssErrorBudget, el_rad: Array, ionosphere: bool = True,
               gbas_geometry: tuple[float, float, float] = REFERENCE_GEOMETRY) -> list[tuple[Array, float]]:
    """The slow range-error processes the sensor draws at elevations el_rad (k,), rad: [(1-sigma (k,) m, tau s)].
    Stand-alone: clock/ephemeris, F(el) I_z, M(el) T_z; GBAS: ground, iono, tropo at gbas_geometry (x_air m, dh m,
    v_air m/s: gbas.approach_geometry); a service: its broadcast range, iono and tropo terms (service.terms_m).
    ionosphere=False leaves the iono out (carrier phase, where it has its own state)."""
    if bud.gbas is not None:
        s = bud.gbas.scales(el_rad, *gbas_geometry)
        out = [(s["ground"], bud.gbas.ground_tau_s), (s["iono"], bud.iono_tau_s), (s["tropo"], bud.tropo_tau_s)]
    elif bud.service is not None:  # without the common parts the filter's zenith states carry (service.params)
        t = bud.service.terms_m(el_rad, common=bud.service.tropo_zenith_state)
        out = [(t[..., 0], bud.service.range_tau_s), (t[..., 1], bud.iono_tau_s), (t[..., 2], bud.tropo_tau_s)]
    else:
        out = [(np.full(np.shape(el_rad), bud.clock_ephemeris_m), bud.clock_ephemeris_tau_s),
               (bud.iono_zenith_m * iono_obliquity(el_rad), bud.iono_tau_s),
               (bud.tropo_zenith_m * tropo_mapping(el_rad), bud.tropo_tau_s)]
    return out if ionosphere else [out[0], out[2]]


def slow_tau_s(bud: GnssErrorBudget, ionosphere: bool = True,
               gbas_geometry: tuple[float, float, float] = REFERENCE_GEOMETRY) -> float:
    """The filter's one slow channel state's correlation time, s: the drift-matched (variance-weighted harmonic)
    combination of the processes it lumps over the reference sky SKY_SIN_EL,

        1 / tau = sum_i sum_k sigma_ik^2 / tau_i  /  sum_i sum_k sigma_ik^2   (i process, k elevation),

    so that with the summed variance the state has both the sensor's stationary variance and its mean drift rate
    E[(x(t + dt) - x(t))^2] = 2 dt sum sigma_i^2 / tau_i (dt << tau): the quantity that sets what a slow range
    error does over an approach (module docstring: why one state, not one per process or a tau per channel)."""
    terms = slow_terms(bud, np.arcsin(SKY_SIN_EL), ionosphere, gbas_geometry)
    var = sum(float(np.sum(np.square(s))) for s, _ in terms)
    rate = sum(float(np.sum(np.square(s))) / tau for s, tau in terms)
    return var / rate if rate > 0.0 else max(tau for _, tau in terms)


@dataclass(frozen=True)
class NoiseModel:
    """Process noise and P0 of a navigation configuration (module docstring)."""

    sensors: SensorsConfig
    nav: NavConfig
    layout: em.StateLayout
    baro_ref_m: float = 0.0
    """The baro scale factor's reference H_ref: the altimeter-setting reference (the field's height), m."""
    turbulence: str = "none"
    """The environment's turbulence level (SF_DRIFT_Q): the body rotation the gyro axis errors act on."""
    gbas_geometry: tuple[float, float, float] = REFERENCE_GEOMETRY
    """GBAS: (x_air m, dh m, v_air m/s) of the channel noise and P0, the approach's start (gbas.approach_geometry;
    nav/system.py); the epochs move the slow state to the aircraft's geometry (nav/gbas_scale.py)."""
    _cache: dict = field(default_factory=dict, init=False, compare=False, repr=False)

    def clock(self) -> ClockModel:
        """The receiver clock model (the GNSS receiver's oscillator; a default clock without GNSS)."""
        g = self.sensors.gnss
        if g is not None:
            return ClockModel.named(g.oscillator, g.clock_bias0_sigma_m, g.clock_drift0_sigma_mps)
        return ClockModel()

    def noise(self, elevation_rad: Array | None = None) -> em.ErrorNoise:
        """Process noise with the GPS channels at elevations elevation_rad (k,), rad (None: 30 deg); cached per
        elevation vector, its arrays read-only (shared between callers)."""
        key = None if elevation_rad is None else np.asarray(elevation_rad, dtype=float).tobytes()
        nz = self._cache.get(key)
        if nz is None:
            if len(self._cache) > _CACHE_MAX:
                self._cache.clear()
            nz = self._build(elevation_rad) if key is None else self._at_elevations(elevation_rad)
            for v in vars(nz).values():
                if isinstance(v, np.ndarray):
                    v.flags.writeable = False
            self._cache[key] = nz
        return nz

    def _channel_sigmas(self, elevation_rad: Array) -> tuple[Array, Array | float]:
        """The GPS channel states' 1-sigma (m) at elevation_rad (k,): slow range error (clock/ephemeris, mapped
        iono and tropo) and multipath (per channel under DO-253, one value under NRC 1995)."""
        el = np.maximum(np.nan_to_num(elevation_rad, nan=0.5), np.radians(2.0))
        return self.sensors.gnss.budget().channel_sigmas_m(el, *self.gbas_geometry)

    @property
    def carrier(self) -> bool:
        """The layout carries the carrier-phase states (gio, amb)."""
        return self.layout.has("amb")

    def _carrier_kw(self, el: Array) -> dict[str, Any]:
        """ErrorNoise's channel fields under carrier phase at elevations el (k,) (already floored): gse without the
        ionosphere, gio the ionosphere (module docstring)."""
        bud = self.sensors.gnss.budget()
        gse, gio, gmp = bud.carrier_channel_sigmas_m(el, *self.gbas_geometry)
        return dict(gse_sigma_m=gse, gio_sigma_m=gio, gmp_sigma_m=gmp)

    def carrier_sigma_m(self) -> float:
        """The carrier rows' white-noise 1-sigma, m: the carrier model's white equivalent at the filter's carrier
        interval, the longer of the aiding and the receiver's sample intervals (module docstring)."""
        g = self.sensors.gnss
        dt = max(1.0 / self.nav.aiding_rate_hz, 1.0 / g.rate_hz)
        return g.carrier.white_equivalent_sigma_m(dt)

    def _at_elevations(self, elevation_rad: Array) -> em.ErrorNoise:
        """The noise with the GPS channel states' sigmas at elevation_rad: the elevation-free noise (cached) with
        its channel arrays replaced (the same formulas as _build)."""
        base = self.noise(None)
        if self.sensors.gnss is None:
            return base
        if self.carrier:
            el = np.maximum(np.nan_to_num(elevation_rad, nan=0.5), np.radians(2.0))
            return replace(base, **self._carrier_kw(el))
        gse, gmp = self._channel_sigmas(elevation_rad)
        return replace(base, gse_sigma_m=gse, gmp_sigma_m=gmp)

    def kernel_arrays(self, elevation_rad: Array | None) -> tuple[Array, Array, Array]:
        """(q, gse_sigma (n_sv,), gmp_sigma (n_sv,)): errormodel.kernel_noise of noise(elevation_rad), without
        building the noise object (the compiled epoch's per-epoch input, nav/engine.py)."""
        n_sv = self.layout.n_sv
        q = em.kernel_noise(self.noise(None), n_sv)[0]  # the scalars do not depend on the elevations
        if elevation_rad is None or self.sensors.gnss is None or n_sv == 0 or self.carrier:
            return em.kernel_noise(self.noise(elevation_rad), n_sv)
        gse, gmp = self._channel_sigmas(elevation_rad)
        c = np.ascontiguousarray
        return (q, c(np.broadcast_to(np.asarray(gse, dtype=float), (n_sv,))),
                c(np.broadcast_to(np.asarray(gmp, dtype=float), (n_sv,))))

    def _build(self, elevation_rad: Array | None) -> em.ErrorNoise:
        g = PRESETS[self.sensors.imu.grade]
        b = self.sensors.baro
        kw: dict[str, Any] = {}
        if self.sensors.gnss is not None:
            bud = self.sensors.gnss.budget()
            el = np.full(24, np.radians(30.0)) if elevation_rad is None else np.nan_to_num(elevation_rad, nan=0.5)
            el = np.maximum(el, np.radians(2.0))
            # per channel at its elevation (do253: the sensor's sigma_mp), one multipath value under nrc1995
            gse, gmp = bud.channel_sigmas_m(el, *self.gbas_geometry)
            kw.update(gse_sigma_m=gse, gse_tau_s=slow_tau_s(bud, gbas_geometry=self.gbas_geometry), gmp_sigma_m=gmp,
                      gmp_tau_s=bud.multipath_tau_s)
            if self.carrier:
                kw.update(self._carrier_kw(el), gse_tau_s=slow_tau_s(bud, False, self.gbas_geometry),
                          gio_tau_s=bud.iono_tau_s)
            if self.layout.has("giz"):  # the service's common ionosphere (gse keeps the rest: filter_params)
                giz_sigma, giz_grad, giz_tau = bud.service.filter_iono_zenith()
                kw.update(giz_sigma_m=giz_sigma, giz_gradient_sigma_m=giz_grad, giz_tau_s=giz_tau)
            if self.layout.has("gtz"):  # the service's tropospheric zenith residual (gse leaves it out)
                gtz_sigma, gtz_tau = bud.service.filter_tropo_zenith()
                kw.update(gtz_sigma_m=gtz_sigma, gtz_tau_s=gtz_tau)
        if self.sensors.pseudolite is not None:
            p = self.sensors.pseudolite
            kw.update(pmp_sigma_m=p.multipath_m, pmp_tau_s=p.multipath_tau_s)
            if not p.synchronized:
                q = ClockModel.named(*PSEUDOLITE_CLOCK).q(1.0)
                kw.update(pclk_sf=q[0, 0] - q[1, 1] / 3.0, pclk_sg=q[1, 1])
            else:  # the time-sync error as the truth draws it (sensors/pseudolite.py)
                kw.update(psy_sigma_m=p.sync_sigma_m, psy_tau_s=p.sync_tau_s)
        if self.sensors.radalt is not None:
            kw.update(ram_sigma_m=self.sensors.radalt.markov_sigma_m, ram_tau_s=self.sensors.radalt.markov_tau_s,
                      tdb_correlation_m=self.nav.terrain_database.correlation_m)
        qx, qy, qz = self.gyro_axis_q()
        q1 = self.clock().q(1.0)  # Q(1 s) = [[S_f + S_g / 3, S_g / 2], [., S_g]]
        if self.nav.clock_q_scale != 1.0:  # the filter's Q tuning (nav.clock_q_scale); 1.0 leaves the bits alone
            q1 = q1 * self.nav.clock_q_scale
        # one bb state for the truth's slow baro errors (BaroConfig.filter_bias: their variance and rate); without a
        # baro there is no baro error: the state keeps 0 with zero variance (the converged start then leaves it out
        # of the realized sensor states, as a baro with no slow error does)
        bb_sigma, bb_tau = (b.filter_bias(atmosphere.height_per_hpa_m(self.baro_ref_m)) if b is not None
                            else (0.0, 100.0))
        return em.ErrorNoise(
            gyro_arw_rad_sqrts=g.gyro_arw_rad_sqrts,
            accel_vrw_mps_sqrts=g.accel_vrw_mps_sqrts,
            gyro_bias_rw=np.sqrt(2.0 * g.gyro_bi_radps**2 / g.gyro_bi_tau_s),
            accel_bias_rw=np.sqrt(2.0 * g.accel_bi_mps2**2 / g.accel_bi_tau_s),
            baro_bias_sigma_m=bb_sigma,
            baro_bias_tau_s=bb_tau,
            baro_noise_sigma_m=b.noise_sigma_m if b is not None else 1.0,
            baro_rate_hz=b.rate_hz if b is not None else 10.0,
            baro_ref_m=self.baro_ref_m,  # the loop's sb column -(h - H_ref) (it was left at 0: the MSL height)
            clock_sf=float(q1[0, 0] - q1[1, 1] / 3.0),
            clock_sg=float(q1[1, 1]),
            gyro_axis_q_x=qx, gyro_axis_q_y=qy, gyro_axis_q_z=qz,
            **kw,
        )

    def gyro_axis_q(self) -> tuple[float, float, float]:
        """White rate noise (rad^2/s) on body axes x, y, z for the gyro scale-factor and misalignment errors the
        filter has no states for: the unbounded part of the attitude error they make, S and M random constants of
        1-sigma gyro_sf and gyro_misalign_rad (the grade), q_k = sf^2 D_k + mis^2 E_k (SF_DRIFT_Q at the turbulence
        level). Why this form, and why not 9 states: module docstring."""
        g = PRESETS[self.sensors.imu.grade]
        d, e = (np.asarray(a, dtype=float) for a in SF_DRIFT_Q[self.turbulence])
        q = g.gyro_sf**2 * d + g.gyro_misalign_rad**2 * e
        return float(q[0]), float(q[1]), float(q[2])

    def channel_qd(self, qd: Array, el_rad: Array, dt_s: float) -> Array:
        """Qd with the GPS channel states' (gse, gmp: decoupled first-order Markov) entries at elevations el_rad
        (k,): sigma^2 (1 - exp(-2 dt / tau)), the closed form errormodel.discretize uses for them."""
        lay = self.layout
        if not lay.has("gse"):
            return qd
        nz = self.noise(el_rad)
        q = qd.copy()
        groups = [("gse", nz.gse_sigma_m, nz.gse_tau_s), ("gmp", nz.gmp_sigma_m, nz.gmp_tau_s)]
        if lay.has("gio"):
            groups.append(("gio", nz.gio_sigma_m, nz.gio_tau_s))
        for grp, sig, tau in groups:
            k = np.arange(lay.index[grp].start, lay.index[grp].stop)
            q[k, k] = np.broadcast_to(np.asarray(sig, dtype=float), k.shape) ** 2 * -np.expm1(-2.0 * dt_s / tau)
        return q

    def initial_covariance(self, elevation_rad: Array | None = None) -> Array:
        """P0: the profile's initial INS errors, the IMU grade's biases, the sensors' error budgets (the GPS
        channels' slow errors at their elevations elevation_rad (k,), rad, when given)."""
        lay, ie = self.layout, self.nav.initial_error
        g = PRESETS[self.sensors.imu.grade]
        nz = self.noise(elevation_rad)
        d = np.zeros(lay.n)
        d[lay.index["dp"]] = ie.position_m**2
        d[lay.index["dv"]] = ie.velocity_mps**2
        d[lay.index["psi"]] = [ie.tilt_rad**2, ie.tilt_rad**2, ie.heading_rad**2]
        d[lay.index["bg"]] = g.gyro_bias_radps**2 + g.gyro_bi_radps**2
        # scale factor and misalignment under 1 g look like a bias to a level accelerometer triad: (S + M) f_b with
        # f_b = (0, 0, -g) puts one misalignment element on each horizontal body axis (x, y) and the scale factor on
        # the vertical (z), not both on every axis
        level = np.array([9.8 * g.accel_misalign_rad, 9.8 * g.accel_misalign_rad, 9.8 * g.accel_sf])
        d[lay.index["ba"]] = g.accel_bias_mps2**2 + g.accel_bi_mps2**2 + level**2
        d[lay.i("bb")] = nz.baro_bias_sigma_m**2
        if lay.has("sb"):
            d[lay.i("sb")] = self.sensors.baro.filter_scale_sigma**2
        if lay.has("clk"):
            c = self.clock()
            d[lay.index["clk"]] = [c.bias0_sigma_m**2, c.drift0_sigma_mps**2]
        if lay.has("gse"):
            d[lay.index["gse"]] = np.broadcast_to(nz.gse_sigma_m, (lay.n_sv,)) ** 2
            d[lay.index["gmp"]] = nz.gmp_sigma_m**2
        if lay.has("giz"):
            d[lay.index["giz"]] = [nz.giz_sigma_m**2, nz.giz_gradient_sigma_m**2, nz.giz_gradient_sigma_m**2]
        if lay.has("gtz"):
            d[lay.i("gtz")] = nz.gtz_sigma_m**2
        if lay.has("amb"):
            d[lay.index["gio"]] = np.broadcast_to(nz.gio_sigma_m, (lay.n_sv,)) ** 2
            d[lay.index["amb"]] = self.sensors.gnss.carrier.ambiguity_sigma_m**2
        if lay.has("pmp"):
            p = self.sensors.pseudolite
            d[lay.index["pmp"]] = p.multipath_m**2
            d[lay.index["ptr"]] = (p.tropo_ppm_sigma * 1e-6) ** 2
            if lay.has("pclk"):
                _, b0, d0 = PSEUDOLITE_CLOCK
                d[lay.index["pclk"]] = np.tile([b0**2, d0**2], lay.n_pl)
            if lay.has("psy"):
                d[lay.index["psy"]] = nz.psy_sigma_m**2
        if lay.has("rab"):  # altimeter and database biases summed (both enter the radalt row as -1)
            d[lay.i("rab")] = self.sensors.radalt.bias_sigma_m**2 + self.nav.terrain_database.bias_sigma_m**2
        if lay.has("ram"):
            d[lay.i("ram")] = self.sensors.radalt.markov_sigma_m**2
        if lay.has("tdb"):
            d[lay.i("tdb")] = 1.0  # unit Gauss-Markov
        return np.diag(d)
