"""Airport pseudolites: ground code transmitters near the runway, ranged by the aircraft's GPS receiver.

    rho_j = |r_PL,j^true - r| + b_rx + b_PL,j + T_j |r_PL - r| + m_j + n_j

r_PL^true = published position + survey error (random constant per run, 1-sigma per axis): the record
  carries the published position, so survey error maps into range as -u . dr (standards.md 4.3);
b_rx   the receiver clock (same as the GNSS channels when the suite passes the GNSS clock),
b_PL   the transmitter clock: when synchronized (slaved to GPS time by a GPS-disciplined oscillator) its residual
       time-sync error, a first-order Gauss-Markov per transmitter (sigma_sync, tau_sync; below), else its own
       two-state clock,
T      tropospheric residual, a random constant per run in parts per million of the range (near-horizontal
       paths: a surface refractivity of ~300 N-units gives ~300 ppm; 30 ppm 1-sigma is a 10 % model residual,
       engineering choice), m multipath Gauss-Markov, n white code noise.
Seed 002 assumed all of these negligible (their case VII-XII); the defaults here are small but not zero.

Time-sync error of a synchronized transmitter (issue 39): a GPS-disciplined transmitter holds GPS time to a few ns;
what reaches the aircraft is each transmitter's own residual (a part common to all ranges goes into the receiver
clock). sigma_sync = SYNC_SIGMA_NS (3 ns, c x 3 ns = 0.90 m): the upper end of the 1-3 ns the issue's review gives
for GPS-disciplined transmitters (a common-view / site-calibrated installation reaches about 1 ns; an uncalibrated
GPSDO is 10-20 ns to UTC, [U] no datasheet retrieved into standards.md). tau_sync = SYNC_TAU_S (600 s): the residual
of a GPS-disciplined oscillator wanders with its steering loop, whose time constant is 100-1000 s (engineering
choice in that range, [U] unsourced); any tau well above the ~150 s of a final approach makes it a near-constant per
approach, so the verdict depends on sigma, not tau. Drawn on the columns the unsynchronized clock would use (every
other error draws the same numbers whatever the sync model).
Visible when the range is within max_range_m and the aircraft is above the transmitter's elevation mask.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from approachsim import geo
from approachsim.core.sensors import pseudolite as plk
from approachsim.records import PseudoliteSamples, Truth
from approachsim.sensors import base
from approachsim.sensors.gnss.clock import C_LIGHT, ClockModel

Array = np.ndarray
SYNC_SIGMA_NS = 3.0
"""Default time-sync error 1-sigma of a synchronized (GPS-disciplined) transmitter, ns (module docstring)."""
SYNC_TAU_S = 600.0
"""Default correlation time of the time-sync error, s (module docstring)."""


@dataclass(frozen=True)
class Pseudolite:
    """One or more pseudolites at runway-frame positions (along, cross, height above threshold), m."""

    runway: geo.RunwayFrame
    positions_rwy: tuple[tuple[float, float, float], ...] = ((0.0, -150.0, 10.0),)
    synchronized: bool = True
    pl_clock: ClockModel = field(default_factory=lambda: ClockModel.named("ocxo", 30.0, 0.03))
    code_noise_m: float = 0.3
    multipath_m: float = 0.5
    multipath_tau_s: float = 30.0
    survey_sigma_m: float = 0.05
    tropo_ppm_sigma: float = 30.0
    max_range_m: float = 50e3
    mask_rad: float = math.radians(0.0)
    rate_hz: float = 1.0
    sync_sigma_m: float = SYNC_SIGMA_NS * 1e-9 * C_LIGHT
    """Synchronized transmitters' time-sync error 1-sigma, m (module docstring)."""
    sync_tau_s: float = SYNC_TAU_S
    """... its correlation time, s."""
    name: str = "pseudolite"

    fault_targets: ClassVar[tuple[tuple[str, str, str], ...]] = (("pseudorange", "pseudorange_m", "noise"),)

    @property
    def r_published_ecef(self) -> Array:
        """Published transmitter positions (p, 3), ECEF, m: runway-frame x, y and height above threshold."""
        out = []
        for x, y, hat in self.positions_rwy:
            p = self.runway.to_ecef(np.array([x, y, 0.0]))
            lat, lon, _ = geo.ecef_to_geodetic(p)
            out.append(geo.geodetic_to_ecef(lat, lon, self.runway.threshold_h_m + hat))
        return np.array(out)

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """series (m, p): multipath, noise (m), pl_clock (m: the two-state clock, or a synchronized transmitter's
        time-sync error), pl_clock_drift (m/s; zero when synchronized); constants survey (p, 3) m, tropo_ppm (p,)."""
        p = len(self.positions_rwy)

        def one(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            c = g.standard_normal(6 * p)
            z = g.standard_normal((m, 4 * p))
            clk = np.zeros((m, p))
            drift = np.zeros((m, p))
            if not self.synchronized:
                for j in range(p):
                    c0 = c[4 * p + 2 * j : 4 * p + 2 * j + 2]
                    clk[:, j], drift[:, j] = self.pl_clock.series(c0, z[:, 2 * p + 2 * j : 2 * p + 2 * j + 2], dt)
            elif self.sync_sigma_m > 0.0:  # time-sync error, Gauss-Markov on the clock's first columns
                clk = base.gauss_markov(z[:, 2 * p : 4 * p : 2], self.sync_sigma_m, self.sync_tau_s, dt)
            return {
                "c_survey": self.survey_sigma_m * c[: 3 * p].reshape(p, 3),
                "c_tropo_ppm": self.tropo_ppm_sigma * c[3 * p : 4 * p],
                "multipath": base.gauss_markov(z[:, :p], self.multipath_m, self.multipath_tau_s, dt),
                "noise": self.code_noise_m * z[:, p : 2 * p],
                "pl_clock": clk,
                "pl_clock_drift": drift,
            }

        return base.make_errors(t_s, self.rate_hz, rng, one)

    def c_ecef_to_ned(self, r_published_ecef: Array) -> Array:
        """Rotations ECEF -> local NED (p, 3, 3) at the published transmitter positions (p, 3)."""
        lat, lon, _ = geo.ecef_to_geodetic(r_published_ecef)
        return geo.c_ecef_to_ned(lat, lon)

    def apply(
        self, truth: Truth, errors: base.SensorErrors, clock: base.SensorErrors | None = None
    ) -> PseudoliteSamples:
        """Pseudoranges at the truth rows of `errors`; `clock` the receiver clock (None: zero). Compiled
        (core/sensors/pseudolite.py), equal to apply_reference to 1e-12 relative."""
        pub = self.r_published_ecef
        e = _run_axis(errors, clock)
        c_down = np.ascontiguousarray(self.c_ecef_to_ned(pub)[:, 2, :])
        return self.record(truth, errors.rows, errors.t_s, e, errors.batched, pub, c_down)

    def prepare(self, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> PreparedPseudolite:
        """`errors` (and the receiver clock on the same samples) laid out for one sample at a time (base.prepare)."""
        return PreparedPseudolite(self, errors, clock)

    def record(self, truth: Truth, rows: Array, t_s: Array, e: dict[str, Array], batched: bool, pub: Array,
               c_down: Array) -> PseudoliteSamples:
        """The record of the samples at truth `rows` (times t_s) from the errors `e` with a run axis (_run_axis:
        survey (R, p, 3), tropo_ppm (R, p), multipath, noise, pl_clock (R, m, p), bias (R, m)), the published
        positions pub (p, 3) and the down rows c_down (p, 3) of their ECEF -> NED rotations."""
        c = np.ascontiguousarray
        mp = e["multipath"]
        n_run, m, p = mp.shape
        pr, valid, el = np.empty(mp.shape), np.empty(mp.shape, dtype=bool), np.empty((m, p))
        plk.pseudolite_apply(c(truth.r_ecef[rows], dtype=float), pub, c_down, e["survey"], e["tropo_ppm"], c(mp),
                             c(e["noise"]), c(e["pl_clock"]), c(e["bias"]), float(self.max_range_m),
                             float(self.mask_rad), pr, valid, el)
        sig = math.sqrt(self.code_noise_m**2 + self.multipath_m**2)
        out = (lambda a: a) if batched else (lambda a: a[0])
        return PseudoliteSamples(
            t_s=t_s, r_pl_ecef=pub, pseudorange_m=out(pr), sigma_m=np.full(el.shape, sig), elevation_rad=el,
            valid=out(valid), clock_bias_m=np.array(out(e["bias"])), fault=np.zeros(out(pr).shape, dtype=np.int8),
        )

    def apply_reference(
        self, truth: Truth, errors: base.SensorErrors, clock: base.SensorErrors | None = None
    ) -> PseudoliteSamples:
        """`apply` in numpy: the readable model (module docstring) and the kernel's test oracle."""
        pub = self.r_published_ecef
        c_ned = self.c_ecef_to_ned(pub)
        r = truth.r_ecef[errors.rows]  # (m, 3)
        surv = errors.constants["survey"]
        true_pl = pub + surv  # (p, 3) or (runs, p, 3)
        if errors.batched:
            d = true_pl[:, None, :, :] - r[None, :, None, :]
        else:
            d = true_pl[None, :, :] - r[:, None, :]
        rng_true = np.linalg.norm(d, axis=-1)  # (..., m, p)
        tropo = errors.constants["tropo_ppm"]
        tropo = tropo[:, None, :] if errors.batched else tropo[None, :]
        s = errors.series
        shape_t = rng_true.shape[:-1]
        cb = np.zeros(shape_t) if clock is None else np.broadcast_to(clock.series["bias"], shape_t)
        pr = rng_true * (1.0 + 1e-6 * tropo) + s["multipath"] + s["noise"] + s["pl_clock"] + cb[..., None]
        # visibility from the published geometry (what the transmitter / receiver geometry is)
        dp = pub[None, :, :] - r[:, None, :]
        rng_pub = np.linalg.norm(dp, axis=-1)
        up = -np.einsum("pij,mpj->mpi", c_ned, -dp)[..., 2]  # aircraft height above the transmitter plane
        el = np.arcsin(np.clip(up / rng_pub, -1.0, 1.0))
        ok = (rng_pub <= self.max_range_m) & (el >= self.mask_rad)
        valid = np.broadcast_to(ok, pr.shape).copy()
        sig = math.sqrt(self.code_noise_m**2 + self.multipath_m**2)
        return PseudoliteSamples(
            t_s=errors.t_s, r_pl_ecef=pub, pseudorange_m=np.where(valid, pr, np.nan),
            sigma_m=np.full(el.shape, sig), elevation_rad=el, valid=valid, clock_bias_m=np.array(cb),
            fault=np.zeros(pr.shape, dtype=np.int8),
        )

    def measure(
        self, truth: Truth, rng: base.RngLike, *, noise: bool = True, clock: base.SensorErrors | None = None
    ) -> PseudoliteSamples:
        """apply(truth, draw(truth.t_s, rng), clock); noise=False gives the geometric range (plus the clock)."""
        e = self.draw(truth.t_s, rng)
        return self.apply(truth, e if noise else e.zeroed(), clock)


def _run_axis(errors: base.SensorErrors, clock: base.SensorErrors | None) -> dict[str, Array]:
    """Pseudolite errors by name with a run axis, contiguous: survey (R, p, 3), tropo_ppm (R, p), multipath, noise,
    pl_clock (R, m, p), and the receiver clock bias (R, m) (zeros without a clock)."""
    run = (lambda a: a) if errors.batched else (lambda a: np.asarray(a)[None])
    out = {k: np.ascontiguousarray(run(errors.constants[k]), dtype=float) for k in ("survey", "tropo_ppm")}
    out |= {k: np.ascontiguousarray(run(errors.series[k]), dtype=float) for k in ("multipath", "noise", "pl_clock")}
    shape = out["multipath"].shape[:2]
    out["bias"] = np.zeros(shape) if clock is None else np.ascontiguousarray(
        np.broadcast_to(clock.series["bias"], shape), dtype=float)
    return out


class PreparedPseudolite:
    """A pseudolite's drawn errors for one sample at a time: the published positions, their NED rotations and the
    errors with a run axis made once; at(truth, j) is Pseudolite.apply(truth, errors.sample(j), clock.sample(j)) bit
    for bit (the same kernel on the same values)."""

    def __init__(self, pl: Pseudolite, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> None:
        self.pl = pl
        self.errors = errors
        self.pub = np.ascontiguousarray(pl.r_published_ecef, dtype=float)
        self.c_down = np.ascontiguousarray(pl.c_ecef_to_ned(self.pub)[:, 2, :])
        self.e = _run_axis(errors, clock)

    def at(self, truth: Truth, j: int) -> PseudoliteSamples:
        """The record of sample j alone (one-sample axes; its own copy of the published positions)."""
        sl = slice(j, j + 1)
        e = {k: (v if k in ("survey", "tropo_ppm") else v[:, sl]) for k, v in self.e.items()}
        return self.pl.record(truth, self.errors.rows[sl], self.errors.t_s[sl], e, self.errors.batched,
                              self.pub.copy(), self.c_down)
