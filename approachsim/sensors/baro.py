"""Barometric altimeter: indicated altitude from the truth's static pressure, plus seed 001/003 errors.

    h_ind = indicated_altitude(p_static, QNH setting)          (ISA inverse, sensors/atmosphere.py)
    h_c   = h_ind + (h_ind - H_f) (c - 1)                      (temperature correction, c = 1 without one)
    h_B   = h_c + (h_c - H_f) S + B_k + v_k                    (seed 003 eq. 1 with the scale factor on the height
                                                               above the setting's reference H_f, the field; seed
                                                               001 eq. 1-2 has S = 0)

The deterministic part is physics: with the profile's ISA deviation and true sea-level pressure in the
truth's p_static and the profile's QNH setting here, a cold day or a wrong setting gives the real altimeter
error (cold-is-low, 8.3 m per hPa at sea level). With temperature_correction = "aerodrome" the air data correct the
indication above the field (geopotential elevation H_f) by c = T_f / (T0 - L H_f), T_f the reported aerodrome
temperature (sensors/atmosphere.py: the exact form of the ICAO Doc 8168 correction for the ISA+dT troposphere, left
with the METAR's rounding to a whole degree). S is a random-constant scale factor, B a first-order
Gauss-Markov bias (sigma, tau; exact discretization of seed 001 eq. 2), v white noise. Defaults are seed 001
Table 1 (sigma_B = 1 m, beta = 0.01 1/s so tau = 100 s) and seed 003 Table 1 (noise 1 m). B_k also carries
(issue 39, docs/truth.md "Barometric altimeter"): the static-source (position) error left after the air data's
correction, a second first-order Gauss-Markov process (static_source_sigma_m, static_source_tau_s), and the QNH
reporting error, a per-run constant (qnh_sigma_m: the reported QNH's error times dh/dp at the field); each is drawn
only when its sigma is not zero (a baro without them keeps its numbers). The scale factor multiplies the height above
the altimeter setting's reference (issue 39): a QNH
altimeter reads the field elevation at the field whatever its gain error (the setting is made to make it so), so a
scale error on the MSL height (seed 003's form) would put a 0.12 x 1656 m = 200 m error at a 5434 ft field's
threshold.

Optional first-order lag (lag_s > 0, the pneumatic / filter lag of the static system) on the indicated
altitude, computed statelessly so that stepwise and batch application agree: each sample is a weighted
sum of the indicated altitude over the truth rows up to its own, the exact response of
tau y' = u - y to the linearly interpolated input (first-order-hold discretization, impulse response
w_0 = b0, w_i = a^(i-1) (a b0 + b1); a = exp(-dt / tau), b0 = 1 - tau (1 - a) / dt, b1 = tau (1 - a) / dt - a),
truncated at M = ceil(10 tau / dt) rows (the dropped tail weighs e^-10; weights renormalized to sum 1) with
rows before the first repeated (the lag starts in steady state). On a steady descent at rate v it reads high
by exactly v tau.

Departure from the constant-dT atmosphere (inversion_k != 0): the static pressure the altimeter senses is JSBSim's
times exp(atmosphere.inversion_log_ratio): a surface layer colder (or warmer) than the day's standard-lapse line, the
field pressure kept. JSBSim's constant-dT air would make the aerodrome temperature correction exact; a real day's
lapse rate departs from it, and the correction, made with the (colder) surface temperature, then over-corrects.
This runs in numpy before the compiled indication, so such a baro takes the closed loop's python baro path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from approachsim import units
from approachsim.core.sensors import baro as bk
from approachsim.records import BaroSamples, Truth
from approachsim.sensors import atmosphere, base

Array = np.ndarray
_T0_OVER_LAPSE_M = atmosphere.T0_K / atmosphere.LAPSE_K_PER_M
"""T0 / L of atmosphere.indicated_altitude_m, m (the same expression)."""
_EXPONENT_INV = 1.0 / atmosphere.EXPONENT
"""R L / g0 of atmosphere.indicated_altitude_m (the same expression)."""
_NO_LAG = np.zeros(0)


@dataclass(frozen=True)
class Baro:
    """Barometric altimeter. setting_pa: the setting on the instrument, Pa (profile environment.setting_pa:
    QNH + the setting error); field_m: the field elevation z_f (m) the altimeter reads at the field with QNH, the
    setting's reference (the scale factor's) and the temperature correction's; temperature_ratio:
    c = T_f / (T0 - L z_f) (1: no correction)."""

    setting_pa: float = atmosphere.P0_PA
    rate_hz: float = 10.0
    bias_sigma_m: float = 1.0
    bias_tau_s: float = 100.0
    scale_factor_sigma: float = 0.0
    noise_sigma_m: float = 1.0
    lag_s: float = 0.0
    field_m: float = 0.0
    temperature_ratio: float = 1.0
    static_source_sigma_m: float = 0.0
    static_source_tau_s: float = 300.0
    qnh_sigma_m: float = 0.0
    """The QNH reporting error's height at the field (m, per-run constant)."""
    inversion_k: float = 0.0
    """Surface-layer departure (K colder at the field) over inversion_depth_m (module docstring); 0: none."""
    inversion_depth_m: float = 304.8
    p_field_pa: float = atmosphere.P0_PA
    """The field's static pressure (Pa) and its constant-dT temperature t_field_k (K): the departure's anchors."""
    t_field_k: float = atmosphere.T0_K
    name: str = "baro"

    fault_targets: ClassVar[tuple[tuple[str, str, str], ...]] = (("h", "h_baro_m", "noise"),)

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """series: bias (m,) m (the seed's Gauss-Markov bias + the static-source error + the QNH reporting error),
        noise (m,) m; constants: scale_factor ()."""

        def one(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            # the constants first, then one row of normals per sample: a draw over a longer time base starts with
            # the same numbers (the closed loop draws for its longest flight); the extra columns only when on
            c = g.standard_normal(2 if self.qnh_sigma_m > 0.0 else 1)
            z = g.standard_normal((m, 3 if self.static_source_sigma_m > 0.0 else 2))
            bias = base.gauss_markov(z[:, 0], self.bias_sigma_m, self.bias_tau_s, dt)
            if self.static_source_sigma_m > 0.0:
                bias = bias + base.gauss_markov(z[:, 2], self.static_source_sigma_m, self.static_source_tau_s, dt)
            if self.qnh_sigma_m > 0.0:
                bias = bias + self.qnh_sigma_m * c[1]
            return {
                "c_scale_factor": self.scale_factor_sigma * c[0],
                "bias": bias,
                "noise": self.noise_sigma_m * z[:, 1],
            }

        return base.make_errors(t_s, self.rate_hz, rng, one)

    def kernel_constants(self) -> tuple[float, float, float, float, float]:
        """(setting Pa, ISA T0 / L m, exponent R L / g0, field H_f m, c - 1): the indicated-altitude constants of the
        compiled sample (core/sensors/baro.py; core/loop/nav_row.py makes a closed loop's samples with them)."""
        return (float(self.setting_pa), _T0_OVER_LAPSE_M, _EXPONENT_INV, float(self.field_m),
                float(self.temperature_ratio) - 1.0)

    @property
    def departs(self) -> bool:
        """Whether the sensed pressure departs from the truth's (an inversion: numpy before the kernel)."""
        return self.inversion_k != 0.0

    def sensed_pressure(self, p_pa: Array) -> Array:
        """The static pressure (Pa) the altimeter senses for the truth's (JSBSim's) p_pa: p exp(inversion_log_ratio)
        (module docstring); p itself without a departure."""
        if not self.departs:
            return p_pa
        return p_pa * np.exp(atmosphere.inversion_log_ratio(p_pa, self.p_field_pa, self.t_field_k, self.inversion_k,
                                                            self.inversion_depth_m))

    def lag_weights(self, dt_s: float) -> Array:
        """The lag's impulse-response weights (M + 1,) on a truth step dt_s (s), renormalized to sum 1 (module
        docstring); empty without a lag."""
        if self.lag_s <= 0.0:
            return np.zeros(0)
        a = math.exp(-dt_s / self.lag_s)
        m = int(math.ceil(10.0 * self.lag_s / dt_s))
        b0 = 1.0 - self.lag_s * (1.0 - a) / dt_s
        b1 = self.lag_s * (1.0 - a) / dt_s - a
        w = np.concatenate([[b0], (a * b0 + b1) * a ** np.arange(m)])
        return w / w.sum()

    def apply(self, truth: Truth, errors: base.SensorErrors) -> BaroSamples:
        """Measurements at the truth rows of `errors`; compiled (core/sensors/baro.py), equal to apply_reference to
        1e-12 of the ISA scale T0 / L (4.4e-8 m; the kernel module says why not 1e-12 of the height)."""
        sf = np.asarray(errors.constants["scale_factor"], dtype=float)
        run = (lambda a: a) if errors.batched else (lambda a: a[None])
        return self.record(truth, errors.rows, errors.t_s, run(sf), run(errors.series["bias"]),
                           run(errors.series["noise"]), errors.batched)

    def record(self, truth: Truth, rows: Array, t_s: Array, sf: Array, bias: Array, noise: Array,
               batched: bool, truth_dt_s: float | None = None) -> BaroSamples:
        """The record of the samples at truth `rows` (times t_s) of R runs: scale factors sf (R,), bias and noise
        (R, m) m; batched: the run axis is kept; truth_dt_s: the truth's step for the lag (default: its first
        interval)."""
        rows = np.asarray(rows)
        if self.lag_s > 0.0:
            w = self.lag_weights(float(truth.t_s[1] - truth.t_s[0]) if truth_dt_s is None else truth_dt_s)
            p = truth.p_static_pa[np.maximum(rows[:, None] - np.arange(w.shape[0])[None, :], 0)]
        else:
            w = _NO_LAG
            p = truth.p_static_pa[rows[:, None]]
        p = self.sensed_pressure(p)
        c = np.ascontiguousarray
        out = np.empty(np.shape(bias))
        bk.baro_apply(c(p, dtype=float), *self.kernel_constants(), w, c(sf, dtype=float), c(bias, dtype=float),
                      c(noise, dtype=float), out)
        h = out if batched else out[0]
        return BaroSamples(
            t_s=t_s, h_baro_m=h, sigma_m=np.full(np.shape(t_s), self.noise_sigma_m),
            valid=np.ones(h.shape, dtype=bool), fault=np.zeros(h.shape, dtype=np.int8),
        )

    def prepare(self, errors: base.SensorErrors, clock: base.SensorErrors | None = None) -> PreparedBaro:
        """`errors` laid out for one sample at a time (base.prepare; the baro has no clock)."""
        return PreparedBaro(self, errors)

    def apply_reference(self, truth: Truth, errors: base.SensorErrors) -> BaroSamples:
        """`apply` in numpy: the readable model (module docstring) and the kernel's test oracle."""
        if self.lag_s > 0.0:
            w = self.lag_weights(float(truth.t_s[1] - truth.t_s[0]))
            idx = np.maximum(errors.rows[:, None] - np.arange(w.shape[0])[None, :], 0)
            # row-wise sum (not a matrix product: BLAS blocking would make one row differ from the batch)
            h_ind = np.sum(atmosphere.indicated_altitude_m(self.sensed_pressure(truth.p_static_pa[idx]),
                                                           self.setting_pa) * w, axis=-1)
        else:
            h_ind = atmosphere.indicated_altitude_m(self.sensed_pressure(truth.p_static_pa[errors.rows]),
                                                    self.setting_pa)
        h_ind = h_ind + (h_ind - self.field_m) * (self.temperature_ratio - 1.0)
        sf = errors.constants["scale_factor"]
        sf = sf[:, None] if errors.batched else sf
        h = h_ind + (h_ind - self.field_m) * sf + errors.series["bias"] + errors.series["noise"]
        shape = h.shape
        return BaroSamples(
            t_s=errors.t_s, h_baro_m=h, sigma_m=np.full(errors.t_s.shape, self.noise_sigma_m),
            valid=np.ones(shape, dtype=bool), fault=np.zeros(shape, dtype=np.int8),
        )

    def measure(self, truth: Truth, rng: base.RngLike, *, noise: bool = True) -> BaroSamples:
        """apply(truth, draw(truth.t_s, rng)); noise=False gives the exact indicated altitude."""
        e = self.draw(truth.t_s, rng)
        return self.apply(truth, e if noise else e.zeroed())


def temperature_note(isa_dev_k: float, field_m: float, bias_sigma_m: float, correction: str,
                     scale_sigma: float = 0.0) -> str | None:
    """A warning for a profile whose uncorrected baro's temperature error, dT / (T0 + dT - L H_f) of the height above
    the field (field_m: its geometric elevation, m; sensors/atmosphere.py), exceeds 3 sigma of its declared bias at
    1000 ft above the field: the filter then trusts a wrong height (docs/cat3.md); None when the budget covers it, the
    filter's scale-factor state does (3 scale_sigma, BaroConfig.filter_scale_sigma) or the indication is corrected."""
    if correction != "none":
        return None
    t_f = float(atmosphere.air_temperature_k(atmosphere.geopotential_m(field_m), isa_dev_k))
    if abs(isa_dev_k) / t_f <= 3.0 * scale_sigma:
        return None
    err_m = abs(isa_dev_k) / t_f * 1000.0 * units.FT
    if err_m <= 3.0 * bias_sigma_m:
        return None
    ratio = err_m / max(bias_sigma_m, 1e-9)
    return (f"ISA {isa_dev_k:+.0f} C with an uncorrected baro: its temperature error, {err_m / units.FT:.0f} ft at "
            f"1000 ft above the field, is {ratio:.0f} times the baro's declared {bias_sigma_m:g} m bias; the "
            "navigation will follow it (set [sensors.baro] temperature_correction = \"aerodrome\", or a bias_sigma_m "
            "that covers it)")


class PreparedBaro:
    """A baro's drawn errors for one sample at a time (the closed loop's damping loop reads every baro sample):
    at(truth, j) is Baro.apply(truth, errors.sample(j)) bit for bit (the same kernel on the same values), without
    rebuilding the errors of sample j."""

    def __init__(self, baro: Baro, errors: base.SensorErrors) -> None:
        run = (lambda a: a) if errors.batched else (lambda a: a[None])
        self.baro = baro
        self.errors = errors
        self.sf = np.ascontiguousarray(run(np.asarray(errors.constants["scale_factor"], dtype=float)))
        self.bias = np.ascontiguousarray(run(errors.series["bias"]), dtype=float)
        self.noise = np.ascontiguousarray(run(errors.series["noise"]), dtype=float)
        self._one: tuple | None = None
        self._truth_dt_s: float | None = None

    def truth_step_s(self, truth: Truth) -> float:
        """The truth's step (s) for the lag weights, fixed at the first call: its first interval, or, while row 1 is
        not flown yet (the closed loop's start reads the baro at row 0), the step of the draw's own grid (the errors
        were drawn on the planned truth rows): every sample of the run then uses the same weights."""
        if self._truth_dt_s is None:
            dt = float(truth.t_s[1] - truth.t_s[0]) if len(truth.t_s) > 1 else math.nan
            if not math.isfinite(dt):
                e = self.errors
                if e.rows.shape[0] < 2:
                    raise ValueError("lagged baro: the truth's step is unknown (row 1 not flown, one sample drawn)")
                dt = float(e.t_s[1] - e.t_s[0]) / float(e.rows[1] - e.rows[0])
            self._truth_dt_s = dt
        return self._truth_dt_s

    def at(self, truth: Truth, j: int) -> BaroSamples:
        """The record of sample j alone (one-sample axes)."""
        sl = slice(j, j + 1)
        e = self.errors
        dt = self.truth_step_s(truth) if self.baro.lag_s > 0.0 else None
        return self.baro.record(truth, e.rows[sl], e.t_s[sl], self.sf, self.bias[:, sl], self.noise[:, sl], e.batched,
                                dt)

    def one_constants(self, truth: Truth) -> tuple[Array, Array, tuple[float, ...], Array]:
        """h_one's lag row offsets (L,), lag weights (empty: no lag), kernel_constants and (1, 1) output, made at
        the first call (truth.t_s[1] is set once row 1 is flown)."""
        if self._one is None:
            w = self.baro.lag_weights(self.truth_step_s(truth)) if self.baro.lag_s > 0.0 else _NO_LAG
            self._one = (np.arange(max(w.shape[0], 1)), w, self.baro.kernel_constants(), np.empty((1, 1)))
        return self._one

    def h_one(self, truth: Truth, j: int) -> float:
        """The height (m) of sample j of a one-run draw: at(truth, j).h_baro_m[0] (valid: always) by the same kernel
        on the same values, without the record (the closed loop's compiled aiding epoch reads only this)."""
        lag, w, kc, out = self.one_constants(truth)
        k = int(self.errors.rows[j])
        p = self.baro.sensed_pressure(truth.p_static_pa[np.maximum(k - lag, 0)][None, :])
        bk.baro_apply(p, *kc, w, self.sf, self.bias[:, j:j + 1], self.noise[:, j:j + 1], out)
        return float(out[0, 0])
