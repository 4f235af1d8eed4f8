"""Fault injection: wrap any sensor so that declared faults change exactly the intended samples, and label them.

Fault kinds (profile [[faults]] `kind`; label codes in FAULT_CODES), on the sensor's value field (`target`,
default the sensor's first fault target: IMU dv, baro h, radalt h, GNSS / pseudolite pseudorange) and
optionally one `channel` (IMU axis 0-2, GNSS PRN, pseudolite unit index):

  outage  valid = False and value nan for start_s <= t < end_s (seed 002 single / double GPS outages)
  spike   the white noise of the chosen samples is multiplied by k (seed 000: k = 100 at steps 101, 201,
          301, 401): a spike of k-times the noise sigma
  iam     instantaneous abnormal measurements: + magnitude at the chosen samples (seed 001 sec. 4.1.1)
  cbm     continuous bias: + magnitude for start_s <= t < end_s (seed 001 sec. 4.1.2)
  mni     measurement-noise increment: the noise variance times `factor` in the window (seed 001 sec. 4.1.3)
  step    + magnitude from start_s on (to end_s), the abrupt failure a monitor must catch
  ramp    + rate (t - start_s) in the window: the slow drift that is the hard case for monitors

Chosen samples (spike, iam): the sensor sample numbers `steps` when given, else every `every`-th sample of
the window (counted from its first sample). Spike and MNI act on the noise (so with noise=False they change
nothing); the others are deterministic offsets. Several faults may overlap; the later one's label wins.
Faults are deterministic given the profile and draw no random numbers, so they never change another
sensor's noise or this sensor's error draws.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from approachsim.sensors import base
from approachsim.sensors.gnss.carrier import ambiguities, carrier_arcs
from approachsim.sensors.gnss.receiver import carrier_continuation, carrier_gap, carrier_last

Array = np.ndarray

FAULT_CODES: Mapping[str, int] = MappingProxyType(
    {"none": 0, "outage": 1, "spike": 2, "iam": 3, "cbm": 4, "mni": 5, "step": 6, "ramp": 7}
)
"""Label code of each fault kind (records' `fault` field)."""
FAULT_KINDS = tuple(k for k in FAULT_CODES if k != "none")


@dataclass(frozen=True)
class FaultSpec:
    """One declared fault. Times in s since the run start; magnitude in the target's units; rate per second."""

    sensor: str
    kind: str
    start_s: float = 0.0
    end_s: float = math.inf
    target: str | None = None
    channel: int | None = None
    magnitude: float = 0.0
    rate: float = 0.0
    factor: float = 1.0
    k: float = 1.0
    steps: tuple[int, ...] = ()
    every: int = 1

    def __post_init__(self) -> None:
        if self.kind not in FAULT_KINDS:
            raise ValueError(f"kind must be one of {', '.join(FAULT_KINDS)}; got {self.kind!r}")

    def sample_mask(self, index: Array, t_s: Array, dt_s: float) -> Array:
        """(m,) which of the samples (sample numbers index, times t_s) this fault touches."""
        window = (t_s >= self.start_s) & (t_s < self.end_s)
        if self.kind in ("spike", "iam"):
            if self.steps:
                return np.isin(index, np.asarray(self.steps))
            j0 = math.ceil(self.start_s / dt_s - 1e-9)  # first sample number in the window (grid from t = 0)
            return window & ((index - j0) % self.every == 0)
        return window


def _channel_mask(shape: tuple[int, ...], spec: FaultSpec, channel_index: int | None) -> Array:
    """Mask over the trailing (channel) axes of one sample's value, shape `shape`."""
    m = np.ones(shape, dtype=bool)
    if channel_index is not None and len(shape) > 0:
        m[...] = False
        m[..., channel_index] = True
    return m


@dataclass(frozen=True)
class Faulted:
    """A sensor with faults: same draw / apply / measure interface, faults applied and labelled."""

    sensor: Any
    faults: tuple[FaultSpec, ...]

    @property
    def name(self) -> str:
        """The wrapped sensor's name (its random stream and record name)."""
        return self.sensor.name

    def __getattr__(self, item: str) -> Any:
        """Every other attribute (rate_hz, grade, constellation, fault_targets, ...) is the wrapped sensor's."""
        if item == "sensor" or item.startswith("__"):
            raise AttributeError(item)
        return getattr(self.sensor, item)

    def _target(self, spec: FaultSpec) -> tuple[str, str]:
        targets = self.sensor.fault_targets
        if spec.target is None:
            return targets[0][1], targets[0][2]
        for name, fld, noise in targets:
            if name == spec.target:
                return fld, noise
        raise ValueError(f"fault target for {self.name} must be one of {[t[0] for t in targets]}, got {spec.target!r}")

    def _channel_index(self, spec: FaultSpec) -> int | None:
        """Index on the channel axis: GNSS channels by PRN, others (IMU axis, pseudolite unit) by position."""
        if spec.channel is None:
            return None
        const = getattr(self.sensor, "constellation", None)
        if const is not None:
            hits = np.flatnonzero(const.prn == spec.channel)
            if hits.size == 0:
                raise ValueError(f"fault channel: no PRN {spec.channel} in the constellation")
            return int(hits[0])
        return int(spec.channel)

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """The wrapped sensor's error draw (faults draw nothing)."""
        return self.sensor.draw(t_s, rng)

    def apply(self, truth: Any, errors: base.SensorErrors, *args: Any, **kwargs: Any) -> Any:
        """The wrapped sensor's apply with the faults of the samples in `errors` applied and labelled."""
        masks = self._masks(errors)
        rec = self.sensor.apply(truth, replace(errors, series=self._noise_faulted(errors, masks)), *args, **kwargs)
        return self._label(rec, errors.t_s, errors.batched, masks, self._carrier_start(errors))

    def _carrier_start(self, errors: base.SensorErrors) -> tuple | None:
        """The carrier arcs' start (j0 = 0, no previous sample, the ambiguity pool with a run axis) when the record
        carries carrier phase that an outage can interrupt, else None."""
        if "ambiguity" not in errors.series or not any(f.kind == "outage" for f in self.faults):
            return None
        pool = errors.series["ambiguity"]
        return (0, None, None, pool if errors.batched else pool[None])

    def prepare(self, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> PreparedFaulted:
        """`errors` laid out for one sample at a time (base.prepare): the fault masks and the noise faults of every
        sample made once, the wrapped sensor prepared on the faulted noise; at(truth, j) = apply(truth,
        errors.sample(j)[, clock=clock.sample(j)]) bit for bit (the record faults of sample j by the same code)."""
        masks = self._masks(errors)
        inner = base.prepare(self.sensor, replace(errors, series=self._noise_faulted(errors, masks)), clock)
        return PreparedFaulted(self, inner, errors, masks)

    def _masks(self, errors: base.SensorErrors) -> list[Array]:
        """(m,) per fault: the samples of `errors` it touches."""
        return [f.sample_mask(errors.index, errors.t_s, errors.dt_s) for f in self.faults]

    def _noise_faulted(self, errors: base.SensorErrors, masks: list[Array]) -> dict[str, Array]:
        """The error series with the noise faults (spike: k times, mni: sqrt(factor) times) on their samples."""
        series = dict(errors.series)
        noise_faults = [(f, m) for f, m in zip(self.faults, masks, strict=True) if f.kind in ("spike", "mni")]
        for f, m in noise_faults:
            _, noise_name = self._target(f)
            z = series[noise_name]
            per_sample = z.shape[2:] if errors.batched else z.shape[1:]
            ch = _channel_mask(per_sample, f, self._channel_index(f))
            full = m.reshape(m.shape + (1,) * len(per_sample)) & ch
            mult = math.sqrt(f.factor) if f.kind == "mni" else f.k
            series[noise_name] = np.where(full, z * mult, z)
        return series

    def _label(self, rec: Any, t_s: Array, batched: bool, masks: list[Array], carrier: tuple | None = None) -> Any:
        """The record with the value faults (iam, cbm, step, ramp, outage) of the samples at times t_s, labelled.
        carrier (_carrier_start, or the closed loop's continuation): an outage ends the carrier arcs of its channels
        and the channel begins a new arc, with a new ambiguity, when it is valid again (gnss/carrier.py)."""
        fault = np.array(rec.fault, copy=True)
        valid = np.array(rec.valid, copy=True)
        updates: dict[str, Array] = {}
        for f, m in zip(self.faults, masks, strict=True):
            fld, _ = self._target(f)
            val = np.array(updates.get(fld, getattr(rec, fld)), copy=True)
            per_sample = val.shape[2:] if batched else val.shape[1:]
            ch = _channel_mask(per_sample, f, self._channel_index(f))
            full = m.reshape(m.shape + (1,) * len(per_sample)) & ch
            if f.kind in ("iam", "cbm", "step"):
                val = np.where(full, val + f.magnitude, val)
            elif f.kind == "ramp":
                dt = (t_s - f.start_s).reshape(m.shape + (1,) * len(per_sample))
                val = np.where(full, val + f.rate * dt, val)
            updates[fld] = val
            # labels and validity live on the record's label shape (IMU: per sample; GNSS: per channel)
            lab_ndim = fault.ndim - (1 if batched else 0)
            lab = full.reshape(full.shape[:lab_ndim] + (-1,)).any(axis=-1) if full.ndim > lab_ndim else full
            fault = np.where(lab, np.int8(FAULT_CODES[f.kind]), fault).astype(np.int8)
            if f.kind == "outage":
                valid = np.where(lab, False, valid)
        if any(f.kind == "outage" for f in self.faults):
            for _, fld, _ in self.sensor.fault_targets:
                val = updates.get(fld, getattr(rec, fld))
                if val is None:  # an optional output the sensor does not produce
                    continue
                vmask = valid.reshape(valid.shape + (1,) * (val.ndim - valid.ndim))
                updates[fld] = np.where(vmask, val, np.nan)
        if carrier is not None and getattr(rec, "carrier_arc", None) is not None:
            updates["carrier_phase_m"], updates["carrier_arc"] = rearc(
                updates.get("carrier_phase_m", rec.carrier_phase_m), rec.carrier_arc, valid, batched, carrier)
        return replace(rec, fault=fault, valid=valid, **updates)

    def measure(self, truth: Any, rng: base.RngLike, *, noise: bool = True, **kwargs: Any) -> Any:
        """apply(truth, draw(truth.t_s, rng), **kwargs) with the faults; noise=False zeroes the sensor errors."""
        e = self.draw(truth.t_s, rng)
        return self.apply(truth, e if noise else e.zeroed(), **kwargs)


def rearc(phi: Array, arc: Array, valid: Array, batched: bool, carrier: tuple) -> tuple[Array, Array]:
    """Carrier phase and arcs (gnss/carrier.py) after faults left `valid`: the arcs made afresh from valid (carrier =
    (j0, prev_valid, prev_arc, pool) as carrier.carrier_arcs and carrier.ambiguities take them), and where a channel's
    arc changed, its old arc's ambiguity replaced by the new one's (nan where not valid)."""
    one = (lambda a: a) if batched else (lambda a: np.asarray(a)[None])
    j0, pv, pa, pool = carrier
    old = one(arc)
    new = carrier_arcs(one(valid), j0, pv, pa)
    p = one(phi)
    p = np.where(new == old, p, p - ambiguities(old, pool) + ambiguities(new, pool))
    return (p, new) if batched else (p[0], new[0])


class PreparedFaulted:
    """Faulted.prepare's result: the wrapped sensor's prepared errors (noise faults in) and the fault masks."""

    def __init__(self, faulted: Faulted, inner: Any, errors: base.SensorErrors, masks: list[Array]) -> None:
        self.faulted = faulted
        self.inner = inner
        self.errors = errors
        self.masks = masks
        self.carrier = faulted._carrier_start(errors)
        self._carrier: tuple | None = None
        """Carrier arcs after the outages: the state after the last sample (gnss/receiver.carrier_continuation)."""

    def at(self, truth: Any, j: int) -> Any:
        """The faulted record of sample j alone. A sample no fault touches is the wrapped sensor's record as it is:
        labelling it would change no value (its invalid values are already nan) -- except carrier arcs after an
        outage, which continue from sample to sample (in increasing order, skipped ones run first, as the
        receiver's)."""
        if self.carrier is not None:
            for jj in carrier_gap(self._carrier, j):
                self._one(truth, jj)
        return self._one(truth, j)

    def _one(self, truth: Any, j: int) -> Any:
        sl = slice(j, j + 1)
        rec = self.inner.at(truth, j)
        carrier = None
        if self.carrier is not None:
            carrier = carrier_continuation(self._carrier, j, self.carrier[3])
        elif not any(m[j] for m in self.masks):
            return rec
        rec = self.faulted._label(rec, self.errors.t_s[sl], self.errors.batched, [m[sl] for m in self.masks],
                                  carrier)
        if carrier is not None:
            self._carrier = carrier_last(j, rec.valid, rec.carrier_arc, carrier)
        return rec
