"""Shared machinery of the sensor models: the sample grid, error-process records, random helpers.

Every sensor follows the same two-step contract (sensors/__init__.py documents it for users):

    errors = sensor.draw(t_s, rng)      # error processes: functions of time only, not of the trajectory
    record = sensor.apply(truth, errors)  # truth rows + error rows -> measurement record
    sensor.measure(truth, rng, noise=True) == sensor.apply(truth, sensor.draw(truth.t_s, rng))

The sample grid: a sensor at rate f on a truth time base with step dt samples every d = round(1 / (f dt))
truth rows, sample j at truth row j d (the IMU: every row from 1 on, see imu.py). `SensorErrors` holds, for
each sample, its index j, its truth row and its time, plus the error arrays (sample axis first, or run
axis then sample axis when drawn for several runs). `take(sl)` selects samples, so a closed loop can draw
for the longest flight once and apply one sample at a time.

Prefix property: every draw makes its per-run constants first (a fixed count of normals) and then one
(samples, k) array of standard normals filled row by row, from which all time series are built by causal
recursions. Drawing for more samples therefore gives bit-identical first samples.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.signal import lfilter

from approachsim.core.sensors import noise as noise_kernels

Array = np.ndarray
RngLike = np.random.Generator | Sequence[np.random.Generator]
NOT_ERRORS = ("epoch_offset_s",)
"""Per-run constants that set the scene rather than an error (kept by SensorErrors.zeroed)."""


def is_batched(rng: RngLike) -> bool:
    """True when `rng` is a sequence of Generators (one per Monte Carlo run)."""
    if isinstance(rng, np.random.Generator):
        return False
    if isinstance(rng, Sequence) and len(rng) > 0 and all(isinstance(g, np.random.Generator) for g in rng):
        return True
    raise TypeError("rng must be a numpy.random.Generator or a non-empty sequence of them (one per run)")


def per_run(rng: RngLike, fn: Callable[[np.random.Generator], dict[str, Array]]) -> tuple[dict[str, Array], bool]:
    """Apply fn(generator) -> {name: array} to one Generator, or to each and stack on a leading run axis."""
    if not is_batched(rng):
        return fn(rng), False  # type: ignore[arg-type]
    outs = [fn(g) for g in rng]  # type: ignore[union-attr]
    return {k: np.stack([o[k] for o in outs]) for k in outs[0]}, True


def decimation(t_s: Array, rate_hz: float) -> int:
    """Truth rows per sensor sample for a sensor at rate_hz on the (uniform) truth time base t_s."""
    t = np.asarray(t_s, dtype=float)
    if t.shape[0] < 2:
        return 1
    dt = float(t[1] - t[0])
    d = int(round(1.0 / (rate_hz * dt)))
    if d < 1:
        raise ValueError(f"sensor rate {rate_hz} Hz is faster than the truth rate {1.0 / dt:g} Hz")
    return d


def gauss_markov(z: Array, sigma: float | Array, tau_s: float | Array, dt_s: float) -> Array:
    """Stationary first-order Gauss-Markov sequence from standard normals z (samples on axis 0), exact.

    x_0 = sigma z_0;  x_k = a x_{k-1} + sigma sqrt(1 - a^2) z_k,  a = exp(-dt / tau)
    (the exact discretization of dx/dt = -x / tau + w; seed 000 eq. 5 and seed 001 eq. 2 are its Euler
    form a = 1 - dt beta). sigma and tau broadcast over the trailing axes of z; tau = inf gives a random
    constant, sigma = 0 gives zeros. The recursion is compiled (core/sensors/noise.py first_order), bit-identical
    to gauss_markov_reference.
    """
    z = np.asarray(z, dtype=float)
    sigma = np.broadcast_to(np.asarray(sigma, dtype=float), z.shape[1:])
    a = np.exp(-dt_s / np.broadcast_to(np.asarray(tau_s, dtype=float), z.shape[1:]))
    # every argument C-contiguous and writeable (copies where not: a column slice of z, a broadcast sigma), so the
    # kernel compiles once, not once per layout and read-only flag (4 copies on a closed-loop run's cold cache)
    def own(x: Array) -> Array:
        return np.require(x, dtype=float, requirements=("C", "W"))

    z2 = own(z.reshape(z.shape[0], -1))
    out = np.empty(z2.shape)
    noise_kernels.first_order(z2, own(sigma.reshape(-1)), own((sigma * np.sqrt(1.0 - a * a)).reshape(-1)),
                              own(np.asarray(a).reshape(-1)), out)
    return out.reshape(z.shape)


def gauss_markov_reference(z: Array, sigma: float | Array, tau_s: float | Array, dt_s: float) -> Array:
    """gauss_markov in numpy and scipy (the oracle): the driving terms d_0 = sigma z_0, d_k = sigma sqrt(1 - a^2) z_k
    filtered by scipy.signal.lfilter([1], [1, -a]) per column."""
    z = np.asarray(z, dtype=float)
    sigma = np.broadcast_to(np.asarray(sigma, dtype=float), z.shape[1:])
    tau = np.broadcast_to(np.asarray(tau_s, dtype=float), z.shape[1:])
    a = np.exp(-dt_s / tau)
    drive = np.empty_like(z)
    drive[0] = sigma * z[0]
    drive[1:] = (sigma * np.sqrt(1.0 - a * a)) * z[1:]
    if z.ndim == 1:
        return lfilter([1.0], [1.0, -float(a)], drive)
    out = np.empty_like(drive)
    flat_a = a.reshape(-1)
    d2 = drive.reshape(z.shape[0], -1)
    o2 = out.reshape(z.shape[0], -1)
    for i, ai in enumerate(flat_a):
        o2[:, i] = lfilter([1.0], [1.0, -ai], d2[:, i])
    return out


@dataclass(frozen=True)
class SensorErrors:
    """The error processes of one sensor for one run (or several: run axis first), at its sample instants.

    index: (m,) sample numbers j on the sensor's grid; rows: (m,) truth rows of the samples; t_s: (m,) their
    times, s; dt_s: the sensor's sample interval, s. series: name -> (m, ...) or (runs, m, ...) per-sample
    errors; constants: name -> per-run constants (no sample axis; (runs, ...) when batched). Units are those
    documented by each sensor.
    """

    index: Array
    rows: Array
    t_s: Array
    dt_s: float
    series: dict[str, Array]
    constants: dict[str, Array]
    batched: bool

    def __len__(self) -> int:
        return int(self.index.shape[0])

    def take(self, sl: slice | Array) -> SensorErrors:
        """The errors of samples `sl` (a slice or index array on the sample axis); constants are kept."""
        ax = 1 if self.batched else 0
        series = {k: np.take(v, np.arange(len(self))[sl], axis=ax) for k, v in self.series.items()}
        return SensorErrors(
            index=self.index[sl], rows=self.rows[sl], t_s=self.t_s[sl], dt_s=self.dt_s, series=series,
            constants=self.constants, batched=self.batched,
        )

    def sample(self, j: int) -> SensorErrors:
        """Sample j alone, as views of the arrays (no copy): the values of take(slice(j, j + 1)), for applying one
        sample at a time (the closed loop)."""
        sl = slice(j, j + 1)
        series = {k: v[:, sl] for k, v in self.series.items()} if self.batched else {k: v[sl] for k, v in
                                                                                     self.series.items()}
        return SensorErrors(index=self.index[sl], rows=self.rows[sl], t_s=self.t_s[sl], dt_s=self.dt_s,
                            series=series, constants=self.constants, batched=self.batched)

    def zeroed(self) -> SensorErrors:
        """The same structure with every error zero (for measure(..., noise=False)); constants that are not
        errors (NOT_ERRORS: a run's GPS epoch) are kept."""
        return SensorErrors(
            index=self.index, rows=self.rows, t_s=self.t_s, dt_s=self.dt_s,
            series={k: np.zeros_like(v) for k, v in self.series.items()},
            constants={k: v if k in NOT_ERRORS else np.zeros_like(v) for k, v in self.constants.items()},
            batched=self.batched,
        )


def grid(t_s: Array, rate_hz: float, first_row: int = 0) -> tuple[Array, Array, Array, float]:
    """Sample numbers, truth rows, times and sample interval (s) of a sensor at rate_hz on time base t_s."""
    t = np.asarray(t_s, dtype=float)
    d = decimation(t, rate_hz)
    rows = np.arange(first_row, t.shape[0], d)
    dt = float(t[1] - t[0]) * d if t.shape[0] > 1 else 1.0 / rate_hz
    return np.arange(rows.shape[0]), rows, t[rows], dt


def make_errors(
    t_s: Array, rate_hz: float, rng: RngLike, draw_one: Callable[[np.random.Generator, int, float], dict[str, Array]],
    first_row: int = 0,
) -> SensorErrors:
    """Build SensorErrors: draw_one(generator, m samples, dt) returns {name: array}; names starting with
    'c_' are per-run constants, the rest per-sample series (sample axis first)."""
    index, rows, t, dt = grid(t_s, rate_hz, first_row)
    out, batched = per_run(rng, lambda g: draw_one(g, rows.shape[0], dt))
    series = {k: v for k, v in out.items() if not k.startswith("c_")}
    constants = {k[2:]: v for k, v in out.items() if k.startswith("c_")}
    return SensorErrors(
        index=index, rows=rows, t_s=t, dt_s=dt, series=series, constants=constants, batched=batched
    )


class PreparedSensor:
    """A sensor's drawn errors for applying one sample at a time: at(truth, j) is sensor.apply(truth,
    errors.sample(j)) (ranging sensors: with the receiver clock's sample j, the clock given on the same samples).
    Sensors with something to precompute define their own `prepare(errors, clock)` (GNSS: the satellite orbits;
    faults.Faulted: the fault masks); `prepare` below picks it."""

    def __init__(self, sensor: Any, errors: SensorErrors, clock: SensorErrors | None = None) -> None:
        self.sensor = sensor
        self.errors = errors
        self.clock = clock

    def at(self, truth: Any, j: int) -> Any:
        """The record of sample j alone (one-sample axes)."""
        if self.clock is None:
            return self.sensor.apply(truth, self.errors.sample(j))
        return self.sensor.apply(truth, self.errors.sample(j), clock=self.clock.sample(j))


def prepare(sensor: Any, errors: SensorErrors, clock: SensorErrors | None = None) -> Any:
    """An object whose at(truth, j) gives sensor.apply(truth, errors.sample(j)[, clock=clock.sample(j)]) bit for
    bit: the sensor's own `prepare` when it has one, else PreparedSensor. `clock`: the receiver clock on the
    sensor's samples (ranging sensors only)."""
    own = getattr(sensor, "prepare", None)
    return own(errors, clock) if own is not None else PreparedSensor(sensor, errors, clock)
