"""GPS L1 carrier phase with float ambiguities: the model's parameters, its arcs and its ambiguities.

The receiver (receiver.py, `carrier_phase = true`) measures, per channel i, beside the code pseudorange,

    phi_i = |r_sv,i - r| + b_rx + A_a(i) + S_i - I_i + c_i + w_i

A_a(i)   the ambiguity lambda N of the channel's current arc a(i): N an integer number of L1 cycles (lambda =
         L1_WAVELENGTH_M), drawn once per arc as round(z sigma_A / lambda), z ~ N(0, 1) (sigma_A =
         ambiguity_sigma_m). The filter does not use the integer nature (float ambiguities); sigma_A stands for how
         far a receiver's first carrier of an arc lies from the true range once it has set the integer part from its
         code (a few code sigmas at most: 10 m by default, engineering choice; the navigation filter's prior is the
         same sigma, so it is honest whatever the value).
S_i      the slow range errors the code has with the same sign: stand-alone the satellite clock + ephemeris E_i and
         the tropospheric delay M(el) T_i; GBAS the ground residual s_gnd g_i and the tropospheric residual
         s_tropo T_i (gbas.py). The same realizations as the code's.
-I_i     the ionospheric term of the code with the opposite sign (phase advance against group delay: Misra & Enge,
         "Global Positioning System: Signals, Measurements, and Performance", 2nd ed. 2006, ch. 5 [U: from memory]):
         stand-alone -F(el) I_i, GBAS -s_iono I_i, the code's very realization.
c_i      carrier multipath, a Gauss-Markov of multipath_m (1 cm) and multipath_tau_s (5 s). Carrier multipath is
         bounded by lambda / 4 = 4.8 cm (a reflected signal of any strength shifts the phase by at most 90 deg) and is
         typically below 1 cm (Misra & Enge ch. 6; Kaplan & Hegarty, "Understanding GPS", 2nd ed. 2006, ch. 7
         [U: both from memory]). The correlation time is an engineering choice [D]: raw (unsmoothed) multipath on a
         moving aircraft decorrelates within seconds (receiver.py's docstring on the DO-253 curve), unlike the code
         multipath left after 100 s smoothing.
w_i      white carrier tracking noise, noise_m = gbas.CARRIER_NOISE_M (2 mm: the PLL thermal jitter, gbas.py).

Arcs (cycle-slip free): a channel's phase is continuous (one N) while it stays valid; an arc begins at every sample
at which the channel is valid and was not at the previous sample (a rising satellite, the end of an outage, a
re-selection) and at the first sample of the record. No cycle slips inside an arc are modelled. The record's arc
id (`carrier_arcs`) is the global sample index at which the arc began (-1 where the channel is not valid): a new arc
always has a new id, so the navigation filter resets its ambiguity state whenever the id changes. The ambiguity of
an arc is drawn ahead as a pool, one value per sample and channel (`ambiguity_m`): the arc that begins at sample j
on channel i takes pool[j, i], so a closed loop applying one sample at a time draws exactly the batch's values.

Draws (receiver.draw): the multipath, noise and ambiguity normals of the carrier come from the child stream "carrier"
of the receiver's generator (seeding.substream, which draws nothing from the parent), so receivers without carrier
phase keep their draws bit for bit, and the carrier draws of a record are the first samples of a longer record's
(a closed loop draws its errors for a longer flight than it flies).
The arithmetic is vectorized numpy over runs, samples and channels (no per-sample Python loop): no compiled kernel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from approachsim.sensors.gnss.gbas import CARRIER_NOISE_M

Array = np.ndarray

L1_WAVELENGTH_M = 299792458.0 / 1575.42e6
"""GPS L1 carrier wavelength, m (c / 1575.42 MHz = 0.1903 m; IS-GPS-200)."""


@dataclass(frozen=True)
class CarrierModel:
    """The carrier-phase error model (module docstring): multipath 1-sigma (m) and correlation time (s), white noise
    1-sigma (m), ambiguity prior 1-sigma (m)."""

    multipath_m: float = 0.01
    multipath_tau_s: float = 5.0
    noise_m: float = CARRIER_NOISE_M
    ambiguity_sigma_m: float = 10.0

    def __post_init__(self) -> None:
        for name in ("multipath_m", "noise_m", "ambiguity_sigma_m"):
            if not getattr(self, name) >= 0.0:
                raise ValueError(f"carrier {name} must be >= 0; got {getattr(self, name)!r}")
        if not self.multipath_tau_s > 0.0:
            raise ValueError(f"carrier multipath_tau_s must be > 0; got {self.multipath_tau_s!r}")
        if self.multipath_m > L1_WAVELENGTH_M / 4.0:
            raise ValueError(f"carrier multipath_m must not exceed lambda / 4 = {L1_WAVELENGTH_M / 4.0:.4f} m "
                             f"(module docstring); got {self.multipath_m!r}")

    @property
    def sigma_m(self) -> float:
        """Nominal 1-sigma of the carrier's fast errors (multipath and noise), m: the record's carrier_sigma_m."""
        return math.hypot(self.multipath_m, self.noise_m)

    def white_equivalent_sigma_m(self, dt_s: float) -> float:
        """The white-noise 1-sigma (m) a filter taking one carrier row every dt_s (s) gives the carrier's fast errors:
        the multipath's variance times (1 + a) / (1 - a), a = exp(-dt / tau) -- the variance of the mean of many
        samples of the Gauss-Markov equals that of white noise of this variance (the sum of its autocorrelation
        sigma^2 a^|k| over all lags) -- plus the white noise's."""
        a = math.exp(-dt_s / self.multipath_tau_s)
        return math.sqrt(self.multipath_m**2 * (1.0 + a) / (1.0 - a) + self.noise_m**2)

    def ambiguity_pool(self, z: Array) -> Array:
        """Ambiguities lambda N (m) from standard normals z: N = round(z sigma_A / lambda)."""
        return L1_WAVELENGTH_M * np.round(np.asarray(z, dtype=float) * (self.ambiguity_sigma_m / L1_WAVELENGTH_M))


def carrier_arcs(valid: Array, j0: int = 0, prev_valid: Array | None = None, prev_arc: Array | None = None) -> Array:
    """Arc ids (..., m, k) int64 of channels valid (..., m, k) at the global samples j0 .. j0 + m - 1 (sample axis -2):
    the global index of the sample at which the channel's current arc began, -1 where it is not valid. prev_valid,
    prev_arc (..., k): the channel's validity and arc id at sample j0 - 1 (None: j0 starts the record, every valid
    channel begins an arc there)."""
    valid = np.asarray(valid, dtype=bool)
    arc = np.full(valid.shape, -1, dtype=np.int64)
    pv = np.zeros(valid.shape[:-2] + valid.shape[-1:], dtype=bool) if prev_valid is None else np.asarray(prev_valid)
    pa = np.full(pv.shape, -1, dtype=np.int64) if prev_arc is None else np.asarray(prev_arc, dtype=np.int64)
    for i in range(valid.shape[-2]):
        v = valid[..., i, :]
        pa = np.where(v, np.where(pv, pa, j0 + i), -1)
        arc[..., i, :] = pa
        pv = v
    return arc


def ambiguities(arc: Array, pool: Array) -> Array:
    """The ambiguity (m) of each arc id in arc (R, m, k) from the pool (R, M, k) of the whole record (global sample
    axis 1): pool[r, arc, i]; nan where arc is -1."""
    a = np.asarray(arc)
    safe = np.maximum(a, 0)
    r = np.arange(a.shape[0])[:, None, None]
    i = np.arange(a.shape[2])[None, None, :]
    return np.where(a >= 0, np.asarray(pool)[r, safe, i], np.nan)
