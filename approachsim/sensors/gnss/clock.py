"""Two-state clock (bias, drift) from Allan-variance coefficients (standards.md 2.4; Brown & Hwang).

    b' = d + w_f,  d' = w_g,   S_f = h0 / 2,  S_g = 2 pi^2 h_-2
    Q(dt) = c^2 [[S_f dt + S_g dt^3 / 3, S_g dt^2 / 2], [S_g dt^2 / 2, S_g dt]]         (m^2, m^2/s, m^2/s^2)

Exact discretization: x_k = [[1, dt], [0, 1]] x_{k-1} + w_k, w_k ~ N(0, Q(dt)) drawn as L z_k (L = chol Q).
Bias in metres (c times seconds), drift in m/s. The initial bias and drift are random constants per run
(the offset the receiver has not yet solved for). Flicker (h_-1) is not in the two-state model.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

Array = np.ndarray

C_LIGHT = 299792458.0
"""Speed of light, m/s."""

OSCILLATORS: Mapping[str, tuple[float, float, float]] = MappingProxyType({
    "tcxo": (2e-19, 7e-21, 2e-20),
    "ocxo": (8e-20, 2e-21, 4e-23),
    "rubidium": (2e-20, 7e-24, 4e-29),
})
"""(h0, h_-1, h_-2) Allan coefficients: Brown & Hwang 3rd ed. p. 430 via navtk (standards.md 2.4 Set A)."""


@dataclass(frozen=True)
class ClockModel:
    """Two-state clock: Allan coefficients h0 (s), h_-2 (1/s); initial 1-sigma bias (m) and drift (m/s)."""

    h0: float = OSCILLATORS["tcxo"][0]
    h_m2: float = OSCILLATORS["tcxo"][2]
    bias0_sigma_m: float = 300.0
    drift0_sigma_mps: float = 3.0

    @classmethod
    def named(cls, oscillator: str, bias0_sigma_m: float = 300.0, drift0_sigma_mps: float = 3.0) -> ClockModel:
        """A clock with one of OSCILLATORS' coefficient sets."""
        h0, _, hm2 = OSCILLATORS[oscillator]
        return cls(h0=h0, h_m2=hm2, bias0_sigma_m=bias0_sigma_m, drift0_sigma_mps=drift0_sigma_mps)

    def q(self, dt_s: float) -> Array:
        """Discrete process-noise covariance Q(dt) (2, 2) in m^2, m^2/s, m^2/s^2."""
        sf = self.h0 / 2.0
        sg = 2.0 * math.pi**2 * self.h_m2
        c2 = C_LIGHT**2
        return c2 * np.array([[sf * dt_s + sg * dt_s**3 / 3.0, sg * dt_s**2 / 2.0], [sg * dt_s**2 / 2.0, sg * dt_s]])

    def series(self, c0: Array, z: Array, dt_s: float) -> tuple[Array, Array]:
        """Bias (m,) m and drift (m,) m/s from 2 initial normals c0 and (m, 2) step normals z (row 0 unused)."""
        l_chol = np.linalg.cholesky(self.q(dt_s))
        w = z @ l_chol.T  # (m, 2)
        w[0] = 0.0
        d = self.drift0_sigma_mps * c0[1] + np.cumsum(w[:, 1])
        step = np.empty_like(d)
        step[0] = 0.0
        step[1:] = dt_s * d[:-1] + w[1:, 0]
        b = self.bias0_sigma_m * c0[0] + np.cumsum(step)
        return b, d
