"""Strapdown IMU: gyro and accelerometer triads delivering angle and velocity increments at the truth rate.

Increment definition (the contract the INS matches): increment k (k = 1 .. n-1) covers (t_{k-1}, t_k] and is
the body-axis rate and specific force of truth sample k-1 held over the interval,

    dtheta_true_k = dt w_ib_body[k-1],      dv_true_k = dt f_body[k-1],

which is the Truth's own sampling convention (flight/truthfile.py: "f_body[k] and w_ib_body[k] are the
specific force and inertial rate that carry the state from row k to row k+1, constant over the step"), so
the increments are exact for the JSBSim truth: a body rate constant in body axes over the step rotates the
body by exactly dtheta, and the INS's sculling term (1/2 dtheta x dv) accounts for the rotation of a
constant body-axis specific force. (For the synthetic truth, whose rates are exact at each sample and vary
by micro-units over an approach, the hold differs from the exact integral by dt^2/2 df/dt per step, which
telescopes to dt/2 (f_end - f_start) in velocity: nanometres per second.) The record's sample j is
increment k = j + 1 (t_s = truth.t_s[1:]).

Error model per axis (gyro shown; accelerometer the same with its own parameters), 1-sigma from the grade:

    dtheta_k = (I + S + M) dtheta_true_k + (b0 + b_k) dt + n_k,      then quantized if a step q > 0:
    S = diag(scale-factor errors), M = off-diagonal misalignment (random constants per run),
    b0 turn-on bias (random constant), b_k first-order Gauss-Markov bias instability (sigma, tau) sampled at
    t_k and held over the interval, n_k = ARW sqrt(dt) z_k (white rate noise integrated over the interval).
    Quantization rounds each increment to a multiple of q without carrying the residual to the next one
    (stateless, so stepwise and batch application agree; a real IMU carries it).

The errors depend only on time, so `draw` makes them once and `apply` combines them with any truth rows.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from approachsim.core.sensors import imu as sk
from approachsim.records import ImuSamples, Truth
from approachsim.sensors import base
from approachsim.sensors.presets import ImuGrade

Array = np.ndarray

_OFFDIAG = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]


def true_increments(truth: Truth, rows: Array) -> tuple[Array, Array, float]:
    """Exact (dtheta, dv) (m, 3) of the intervals ending at truth `rows` (each >= 1), and dt (s).

    dtheta = dt w_ib_body[row - 1], dv = dt f_body[row - 1] (the module docstring says why).
    """
    rows = np.asarray(rows)
    dt = float(truth.t_s[1] - truth.t_s[0])
    return dt * truth.w_ib_body[rows - 1], dt * truth.f_body[rows - 1], dt


def _matrix(diag: Array, off: Array) -> Array:
    """(3, 3) error matrix S + M from 3 scale factors and 6 misalignments."""
    m = np.diag(diag)
    for (i, j), v in zip(_OFFDIAG, off, strict=True):
        m[i, j] = v
    return m


@dataclass(frozen=True)
class Imu:
    """An IMU of a given grade at the truth rate. name is its random-stream and record name."""

    grade: ImuGrade
    name: str = "imu"

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """Error processes for the increments ending at truth rows 1 .. n-1 of time base t_s.

        series: gyro_bias (m, 3) rad/s (Gauss-Markov part), accel_bias (m, 3) m/s^2, gyro_noise (m, 3) rad
        per increment, accel_noise (m, 3) m/s per increment; constants: gyro_bias0, accel_bias0 (3,) and
        gyro_m, accel_m (3, 3) scale-factor + misalignment matrices.
        """
        g = self.grade

        def one(gen: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            c = gen.standard_normal(24)  # constants first (fixed count): prefix property
            z = gen.standard_normal((m, 12))
            return {
                "c_gyro_bias0": g.gyro_bias_radps * c[0:3],
                "c_accel_bias0": g.accel_bias_mps2 * c[3:6],
                "c_gyro_m": _matrix(g.gyro_sf * c[6:9], g.gyro_misalign_rad * c[12:18]),
                "c_accel_m": _matrix(g.accel_sf * c[9:12], g.accel_misalign_rad * c[18:24]),
                "gyro_bias": base.gauss_markov(z[:, 0:3], g.gyro_bi_radps, g.gyro_bi_tau_s, dt),
                "accel_bias": base.gauss_markov(z[:, 3:6], g.accel_bi_mps2, g.accel_bi_tau_s, dt),
                "gyro_noise": g.gyro_arw_rad_sqrts * np.sqrt(dt) * z[:, 6:9],
                "accel_noise": g.accel_vrw_mps_sqrts * np.sqrt(dt) * z[:, 9:12],
            }

        return base.make_errors(t_s, 1.0 / float(np.asarray(t_s)[1] - np.asarray(t_s)[0]), rng, one, first_row=1)

    def apply(self, truth: Truth, errors: base.SensorErrors) -> ImuSamples:
        """Increments for the samples in `errors` (truth rows errors.rows and the rows before them); computed by
        the compiled kernel (core/sensors/imu.py imu_apply), equal to `apply_reference` to 1e-12 relative."""
        return self.record(truth, errors.rows, errors.t_s, _run_axis(errors), errors.batched)

    def record(self, truth: Truth, rows: Array, t_s: Array, e: dict[str, Array], batched: bool) -> ImuSamples:
        """The record of the increments ending at truth `rows` (times t_s) from the errors `e` with a run axis
        (_run_axis: constants (R, 3[, 3]), series (R, m, 3)); batched: the run axis is kept."""
        dth_t, dv_t, dt = true_increments(truth, rows)
        g = self.grade
        c = np.ascontiguousarray

        def one(true_inc: Array, m_err: Array, b0: Array, b: Array, n: Array, q: float) -> Array:
            nz = c(n, dtype=float)
            out = np.empty(nz.shape)
            sk.imu_apply(c(true_inc, dtype=float), c(m_err, dtype=float), c(b0, dtype=float), c(b, dtype=float), nz,
                         float(dt), float(q), out)
            return out if batched else out[0]

        dth = one(dth_t, e["gyro_m"], e["gyro_bias0"], e["gyro_bias"], e["gyro_noise"], g.gyro_quant_rad)
        dv = one(dv_t, e["accel_m"], e["accel_bias0"], e["accel_bias"], e["accel_noise"], g.accel_quant_mps)
        shape = dth.shape[:-1]
        return ImuSamples(
            t_s=t_s, dt_s=dt, dtheta_body=dth, dv_body=dv,
            valid=np.ones(shape, dtype=bool), fault=np.zeros(shape, dtype=np.int8),
        )

    def prepare(self, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> PreparedImu:
        """`errors` laid out for one increment at a time (base.prepare; the IMU has no clock)."""
        return PreparedImu(self, errors)

    def apply_reference(self, truth: Truth, errors: base.SensorErrors) -> ImuSamples:
        """`apply` in numpy: the readable version of the error model (module docstring) and the kernel's test
        oracle."""
        dth_t, dv_t, dt = true_increments(truth, errors.rows)
        s, k = errors.series, errors.constants
        lead = (slice(None),) if errors.batched else ()
        gm = k["gyro_m"][lead + (None,)] if errors.batched else k["gyro_m"]
        am = k["accel_m"][lead + (None,)] if errors.batched else k["accel_m"]
        gb0 = k["gyro_bias0"][:, None, :] if errors.batched else k["gyro_bias0"]
        ab0 = k["accel_bias0"][:, None, :] if errors.batched else k["accel_bias0"]
        dth = dth_t + np.einsum("...ij,...j->...i", gm, dth_t) + (gb0 + s["gyro_bias"]) * dt + s["gyro_noise"]
        dv = dv_t + np.einsum("...ij,...j->...i", am, dv_t) + (ab0 + s["accel_bias"]) * dt + s["accel_noise"]
        if self.grade.gyro_quant_rad > 0:
            dth = self.grade.gyro_quant_rad * np.round(dth / self.grade.gyro_quant_rad)
        if self.grade.accel_quant_mps > 0:
            dv = self.grade.accel_quant_mps * np.round(dv / self.grade.accel_quant_mps)
        shape = dth.shape[:-1]
        return ImuSamples(
            t_s=errors.t_s, dt_s=dt, dtheta_body=dth, dv_body=dv,
            valid=np.ones(shape, dtype=bool), fault=np.zeros(shape, dtype=np.int8),
        )

    def measure(self, truth: Truth, rng: base.RngLike, *, noise: bool = True) -> ImuSamples:
        """apply(truth, draw(truth.t_s, rng)); noise=False gives the exact increments (no quantization)."""
        e = self.draw(truth.t_s, rng)
        if noise:
            return self.apply(truth, e)
        exact = replace(self, grade=replace(self.grade, gyro_quant_rad=0.0, accel_quant_mps=0.0))
        return exact.apply(truth, e.zeroed())

    fault_targets: ClassVar[tuple[tuple[str, str, str], ...]] = (
        ("dv", "dv_body", "accel_noise"),
        ("dtheta", "dtheta_body", "gyro_noise"),
    )
    """Fault targets: (name, record field, noise series in the same units); the first is the default."""


def _run_axis(errors: base.SensorErrors) -> dict[str, Array]:
    """Series and constants of IMU errors by name, with a run axis (views for one run)."""
    both = {**errors.series, **errors.constants}
    return both if errors.batched else {k: np.asarray(v)[None] for k, v in both.items()}


class PreparedImu:
    """An IMU's drawn errors for one increment at a time (a closed loop whose IMU is quantized: not affine):
    at(truth, j) is Imu.apply(truth, errors.sample(j)) bit for bit (the same kernel on the same values), without
    rebuilding the errors of sample j."""

    def __init__(self, imu: Imu, errors: base.SensorErrors) -> None:
        self.imu = imu
        self.errors = errors
        self.e = {k: np.ascontiguousarray(v, dtype=float) for k, v in _run_axis(errors).items()}
        self.series = tuple(errors.series)

    def at(self, truth: Truth, j: int) -> ImuSamples:
        """The record of increment sample j alone (one-sample axes)."""
        sl = slice(j, j + 1)
        e = {k: (v[:, sl] if k in self.series else v) for k, v in self.e.items()}
        return self.imu.record(truth, self.errors.rows[sl], self.errors.t_s[sl], e, self.errors.batched)
