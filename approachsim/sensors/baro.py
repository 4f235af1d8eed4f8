"""Barometric altimeter: indicated altitude from the truth's static pressure, plus seed 001/003 errors.

    h_ind = indicated_altitude(p_static, QNH setting)          (ISA inverse, sensors/atmosphere.py)
    h_B   = h_ind (1 + S) + B_k + v_k                          (seed 003 eq. 1; seed 001 eq. 1-2 has S = 0)

The deterministic part is physics: with the profile's ISA deviation and true sea-level pressure in the
truth's p_static and the profile's QNH setting here, a cold day or a wrong setting gives the real altimeter
error (cold-is-low, 8.3 m per hPa at sea level). S is a random-constant scale factor, B a first-order
Gauss-Markov bias (sigma, tau; exact discretization of seed 001 eq. 2), v white noise. Defaults are seed 001
Table 1 (sigma_B = 1 m, beta = 0.01 1/s so tau = 100 s) and seed 003 Table 1 (noise 1 m). No static-source
(position) error and no lag: a first-order lag would make the output depend on the past trajectory, which
the stateless draw/apply split excludes (left out, see the issue report).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from approachsim.records import BaroSamples, Truth
from approachsim.sensors import atmosphere, base

Array = np.ndarray


@dataclass(frozen=True)
class Baro:
    """Barometric altimeter. setting_pa: the QNH set on the instrument (profile environment.qnh_pa), Pa."""

    setting_pa: float = atmosphere.P0_PA
    rate_hz: float = 10.0
    bias_sigma_m: float = 1.0
    bias_tau_s: float = 100.0
    scale_factor_sigma: float = 0.0
    noise_sigma_m: float = 1.0
    name: str = "baro"

    fault_targets: ClassVar[tuple[tuple[str, str, str], ...]] = (("h", "h_baro_m", "noise"),)

    def draw(self, t_s: Array, rng: base.RngLike) -> base.SensorErrors:
        """series: bias (m,) m, noise (m,) m; constants: scale_factor ()."""

        def one(g: np.random.Generator, m: int, dt: float) -> dict[str, Array]:
            c = g.standard_normal(1)
            z = g.standard_normal((m, 2))
            return {
                "c_scale_factor": self.scale_factor_sigma * c[0],
                "bias": base.gauss_markov(z[:, 0], self.bias_sigma_m, self.bias_tau_s, dt),
                "noise": self.noise_sigma_m * z[:, 1],
            }

        return base.make_errors(t_s, self.rate_hz, rng, one)

    def apply(self, truth: Truth, errors: base.SensorErrors) -> BaroSamples:
        """Measurements at the truth rows of `errors`."""
        h_ind = atmosphere.indicated_altitude_m(truth.p_static_pa[errors.rows], self.setting_pa)
        sf = errors.constants["scale_factor"]
        sf = sf[:, None] if errors.batched else sf
        h = h_ind * (1.0 + sf) + errors.series["bias"] + errors.series["noise"]
        shape = h.shape
        return BaroSamples(
            t_s=errors.t_s, h_baro_m=h, sigma_m=np.full(errors.t_s.shape, self.noise_sigma_m),
            valid=np.ones(shape, dtype=bool), fault=np.zeros(shape, dtype=np.int8),
        )

    def measure(self, truth: Truth, rng: base.RngLike, *, noise: bool = True) -> BaroSamples:
        """apply(truth, draw(truth.t_s, rng)); noise=False gives the exact indicated altitude."""
        e = self.draw(truth.t_s, rng)
        return self.apply(truth, e if noise else e.zeroed())
