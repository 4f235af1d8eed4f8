"""Radar (radio) altimeter: height of the antenna above the profile's terrain, seed 002 noise, correlated error,
validity.

    h_R = h_agl + b + dH_k + sigma(h_agl) z_k,   sigma(h) = sqrt((0.01 h)^2 + floor^2)     (seed 002, R_Truth)

White noise. Seed 002 writes R = (0.01 AGL)^2 + 0.25 without a unit for the floor. We take metres: a 0.5 m
(1.6 ft) floor. Reason: the paper's own specification, +-(3 ft + 3 %) at 3 sigma, gives a 1 ft (0.30 m) 1-sigma
floor; 0.25 ft^2 (0.5 ft = 0.15 m) would make the filter's radar altimeter twice as good as its spec, 0.25 m^2 is
conservative against it. floor_m is configurable (0.1524 reproduces the feet reading).

Correlated error (the budget split). Seed 002 spends the whole specification on white noise, which a 1 Hz
filter averages away (0.5 m to about 0.1 m by 50 ft): no installation gives that. A radar altimeter's error is
dominated by parts that do not average: the calibration of the antenna installation delay (a constant per
aircraft and flight) and the reflecting surface under the beam (slowly varying). We read the specification's
height-independent term, 3 ft at 3 sigma = 1 ft (0.3048 m) 1-sigma, as the budget of that correlated part and
keep seed 002's white noise as the sample-to-sample noise (so the total exceeds the specification: conservative;
the part a filter cannot average equals the specification's floor). RTCA DO-155 / ARINC 707 numeric limits
could not be retrieved (reference/standards.md 4.2 marks them unverified), so they are not used. The 1 ft is
split in equal variance, no source giving a finer split:
    b   per-run random constant, bias_sigma_m = 0.3048 / sqrt(2) = 0.2155 m (installation / calibration);
    dH  first-order Gauss-Markov of seed 000 eq. 5, markov_sigma_m = 0.2155 m, tau = 1 / beta = 10 s (seed 000
        section 7: tau_s = 10 s, beta = 0.1 1/s); exact discretization.
Draws: the white noise and dH come from the same (samples, 2) normals as before (columns 1 and 0), the bias
from its own child stream (seeding.substream(rng, "radalt.bias")), so no existing draw moves; bias_sigma_m =
markov_sigma_m = 0 reproduce the white-noise-only altimeter exactly.

The antenna is at the IMU point (no lever arm) and a wide-beam altimeter reads the nearest ground, so the height
is truth.h_agl_m whatever the attitude inside the limits. Valid only for 0 <= h_agl <= max range and
|pitch| <= 30 deg, |roll| <= 45 deg (seed 002's specification); the value is nan where not valid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from approachsim import units
from approachsim.core.sensors import radalt as ra
from approachsim.records import RadaltSamples, Truth
from approachsim.seeding import substream
from approachsim.sensors import base

Array = np.ndarray

RADALT_CORRELATED_1SIGMA_M = 1.0 * units.FT / math.sqrt(2.0)
"""Default 1-sigma of each correlated part (bias, Markov): seed 002's 1 ft 1-sigma floor split in equal variance."""


@dataclass(frozen=True)
class RadarAltimeter:
    """Radar altimeter; max_range_m default 2500 ft (typical), seed 002 uses it below 3000 ft."""

    rate_hz: float = 1.0
    max_range_m: float = 2500.0 * units.FT
    percent_sigma: float = 0.01
    floor_m: float = 0.5
    markov_sigma_m: float = RADALT_CORRELATED_1SIGMA_M
    markov_tau_s: float = 10.0
    bias_sigma_m: float = RADALT_CORRELATED_1SIGMA_M
    max_pitch_rad: float = math.radians(30.0)
    max_roll_rad: float = math.radians(45.0)
    name: str = "radalt"

    fault_targets: ClassVar[tuple[tuple[str, str, str], ...]] = (("h", "h_agl_m", "noise"),)

    def sigma_m(self, h_agl_m: Array) -> Array:
        """Seed 002 white-noise 1-sigma at height h (m): sqrt((0.01 h)^2 + floor^2)."""
        return np.sqrt((self.percent_sigma * np.asarray(h_agl_m)) ** 2 + self.floor_m**2)

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """series: markov (m,) m; noise (m,) unit normals (scaled by sigma(h) in apply); constant: bias, m."""

        def one(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            z = g.standard_normal((m, 2))
            bias = self.bias_sigma_m * substream(g, "radalt.bias").standard_normal()
            return {"markov": base.gauss_markov(z[:, 0], self.markov_sigma_m, self.markov_tau_s, dt), "noise": z[:, 1],
                    "c_bias": np.asarray(bias)}

        return base.make_errors(t_s, self.rate_hz, rng, one)

    def apply(self, truth: Truth, errors: base.SensorErrors) -> RadaltSamples:
        """Measurements at the truth rows of `errors`; nan and valid=False out of range or attitude limits. Compiled
        (core/sensors/radalt.py), bit-identical to apply_reference."""
        bias = np.asarray(errors.constants["bias"], dtype=float)
        run = (lambda a: a) if errors.batched else (lambda a: a[None])
        return self.record(truth, errors.rows, errors.t_s, run(bias), run(errors.series["markov"]),
                           run(errors.series["noise"]), errors.batched)

    def record(self, truth: Truth, rows: Array, t_s: Array, bias: Array, markov: Array, noise: Array,
               batched: bool) -> RadaltSamples:
        """The record of the samples at truth `rows` (times t_s) of R runs: bias (R,) m, Markov error (R, m) m and
        unit normals (R, m); batched: the run axis is kept."""
        c = np.ascontiguousarray
        shape = np.shape(markov)
        meas, sig, valid = np.empty(shape), np.empty(shape), np.empty(shape, dtype=bool)
        ra.radalt_apply(c(truth.h_agl_m[rows], dtype=float), c(truth.euler_rad[rows, 1], dtype=float),
                        c(truth.euler_rad[rows, 0], dtype=float), c(bias, dtype=float), c(markov, dtype=float),
                        c(noise, dtype=float), float(self.percent_sigma), self.floor_m**2, float(self.max_range_m),
                        float(self.max_pitch_rad), float(self.max_roll_rad), meas, sig, valid)
        run = (lambda a: a) if batched else (lambda a: a[0])
        return RadaltSamples(t_s=t_s, h_agl_m=run(meas), sigma_m=run(sig), valid=run(valid),
                             fault=np.zeros(run(meas).shape, dtype=np.int8))

    def prepare(self, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> PreparedRadalt:
        """`errors` laid out for one sample at a time (base.prepare; the altimeter has no clock)."""
        return PreparedRadalt(self, errors)

    def apply_reference(self, truth: Truth, errors: base.SensorErrors) -> RadaltSamples:
        """`apply` in numpy: the readable model (module docstring) and the kernel's test oracle."""
        r = errors.rows
        h = truth.h_agl_m[r]
        sig = self.sigma_m(h)
        ok = (
            (h >= 0.0)
            & (h <= self.max_range_m)
            & (np.abs(truth.euler_rad[r, 1]) <= self.max_pitch_rad)
            & (np.abs(truth.euler_rad[r, 0]) <= self.max_roll_rad)
        )
        bias = np.asarray(errors.constants["bias"])
        if errors.batched:
            bias = bias[:, None]
        meas = h + bias + errors.series["markov"] + sig * errors.series["noise"]
        valid = np.broadcast_to(ok, meas.shape).copy()
        meas = np.where(valid, meas, np.nan)
        return RadaltSamples(
            t_s=errors.t_s, h_agl_m=meas, sigma_m=np.broadcast_to(sig, meas.shape).copy(), valid=valid,
            fault=np.zeros(meas.shape, dtype=np.int8),
        )

    def measure(self, truth: Truth, rng: base.RngLike, *, noise: bool = True) -> RadaltSamples:
        """apply(truth, draw(truth.t_s, rng)); noise=False gives the exact height where valid."""
        e = self.draw(truth.t_s, rng)
        return self.apply(truth, e if noise else e.zeroed())


class PreparedRadalt:
    """A radar altimeter's drawn errors for one sample at a time: at(truth, j) is RadarAltimeter.apply(truth,
    errors.sample(j)) bit for bit (the same kernel on the same values)."""

    def __init__(self, ra_: RadarAltimeter, errors: base.SensorErrors) -> None:
        run = (lambda a: a) if errors.batched else (lambda a: a[None])
        self.ra = ra_
        self.errors = errors
        self.bias = np.ascontiguousarray(run(np.asarray(errors.constants["bias"], dtype=float)))
        self.markov = np.ascontiguousarray(run(errors.series["markov"]), dtype=float)
        self.noise = np.ascontiguousarray(run(errors.series["noise"]), dtype=float)
        self._out = (np.empty((1, 1)), np.empty((1, 1)), np.empty((1, 1), dtype=bool))

    def at(self, truth: Truth, j: int) -> RadaltSamples:
        """The record of sample j alone (one-sample axes)."""
        sl = slice(j, j + 1)
        e = self.errors
        return self.ra.record(truth, e.rows[sl], e.t_s[sl], self.bias, self.markov[:, sl], self.noise[:, sl],
                              e.batched)

    def h_one(self, truth: Truth, j: int) -> float:
        """The measured height (m) of sample j of a one-run draw, nan when not valid: at(truth, j)'s h_agl_m[0]
        where valid, by the same kernel on the same values, without the record (the closed loop's compiled epoch)."""
        k = int(self.errors.rows[j])
        meas, sig, valid = self._out
        r = self.ra
        ra.radalt_apply(truth.h_agl_m[k:k + 1].copy(), truth.euler_rad[k:k + 1, 1].copy(),
                        truth.euler_rad[k:k + 1, 0].copy(), self.bias, self.markov[:, j:j + 1],
                        self.noise[:, j:j + 1], float(r.percent_sigma), r.floor_m**2, float(r.max_range_m),
                        float(r.max_pitch_rad), float(r.max_roll_rad), meas, sig, valid)
        return float(meas[0, 0]) if valid[0, 0] else math.nan
