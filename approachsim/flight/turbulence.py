"""MIL-F-8785C Dryden turbulence evaluated at the height above the terrain, stepped once per JSBSim step.

Why not JSBSim's own milspec model: JSBSim 1.3.3 evaluates the MIL-F-8785C altitude dependence with the
altitude above sea level (FGWinds::Run calls Turbulence(in.AltitudeASL)), so at a 5434 ft runway an aircraft
700 ft above the ground gets the high-altitude intensities of the probability-of-exceedance table: measured
std 4.7 / 6.0 / 4.5 ft/s (north, east, down) against 2.4 / 2.9 / 2.0 ft/s at a sea-level runway, same level,
same height above ground. MIL-F-8785C defines the low-altitude model in height above ground. This module is
JSBSim's milspec discretization (Yeager 1998, NASA CR-1998-206937, eqs. 30-32, the MIL-STD-1797A forms),
with JSBSim's scale lengths and intensities (MIL-F-8785C sec. 3.7.2, figs. 7, 10, 11), evaluated at the
height above the profile's terrain. The turbulence velocity is written to JSBSim's user gust
atmosphere/gust-*-fps, which JSBSim adds to the wind (its own turbulence is switched off); JSBSim's
experimental turbulence body rates (Yeager eqs. 33-35) are not reproduced (read-only in JSBSim), so the
gusts act through the gust velocities only.

Levels (MIL-F-8785C fig. 7 and FGWinds' documentation): wind speed at 20 ft and probability-of-exceedance
index: light 25 ft/s (15 kt), index 3 (1e-2); moderate 50 ft/s (30 kt), index 4 (1e-3); severe 75 ft/s
(45 kt), index 6 (1e-5).

Heights, lengths and speeds are in feet and ft/s here, as in the standard's formulas; the module converts at
its boundary (step() takes and returns SI).
"""

from __future__ import annotations

import math

import numpy as np

from approachsim import units
from approachsim.core.loop.flight_step import dryden_scales
from approachsim.core.tables import COEFF_EVERY, POE_ALT_FT, POE_SIGMA_FPS  # the kernel's table, once

LEVELS = {
    "none": None,
    "light": (25.0, 3),
    "moderate": (50.0, 4),
    "severe": (75.0, 6),
}
"""Profile turbulence level -> (MIL-F-8785C wind speed at 20 ft, ft/s; probability-of-exceedance index)."""

_POE_ALT = np.asarray(POE_ALT_FT, dtype=float)
_POE_SIGMA = tuple(np.asarray(row, dtype=float) for row in POE_SIGMA_FPS)
"""The probability-of-exceedance table as the kernel takes it (heights, ft; one sigma row per index, ft/s)."""


def scales(h_ft: float, w20_fps: float, index: int) -> tuple[float, float, float, float]:
    """Scale lengths L_u, L_w (ft) and intensities sigma_u, sigma_w (ft/s) at height h_ft above ground, for the
    probability-of-exceedance index `index`: core/loop/flight_step.dryden_scales, the formula's one copy
    (MIL-F-8785C low-altitude model below 1000 ft, figs. 10, 11; above 2000 ft L = 1750 ft and sigma from the table
    of fig. 7; linear in between, as JSBSim; heights clipped at 10 ft)."""
    return dryden_scales(float(h_ft), float(w20_fps), _POE_ALT, _POE_SIGMA[index - 1])


class DrydenTurbulence:
    """Turbulence velocity of one run, one step at a time (NED, m/s): u along the mean wind, v across it, w down.

    The white-noise sequence is drawn up front from `rng` (the run's "turbulence" stream), so a run's
    turbulence depends on nothing but its seed. The readable oracle of the compiled step the flight loop runs
    (core/loop/flight_step.py dryden_step, equal to it bit for bit).
    """

    def __init__(self, level: str, rng: np.random.Generator, n_steps: int, dt_s: float, wind_to_rad: float) -> None:
        spec = LEVELS[level]
        if spec is None:
            raise ValueError("DrydenTurbulence needs a turbulence level other than 'none'")
        self.w20_fps, self.index = spec
        self.dt = dt_s
        self.nu = rng.standard_normal((n_steps, 3))
        """(n_steps, 3) the white noise nu_u, nu_v, nu_w of every step."""
        self.cos_fps = math.cos(wind_to_rad) * units.FPS
        self.sin_fps = math.sin(wind_to_rad) * units.FPS
        """cos and sin of the direction the wind blows to, times m per ft (wind axes, ft/s -> NED, m/s)."""
        self._coef: tuple[float, ...] | None = None
        self.xi_u = self.xi_v = self.xi_w = 0.0
        """Turbulence state in wind axes, ft/s."""

    def step(self, k: int, h_agl_m: float, v_true_mps: float) -> tuple[float, float, float]:
        """Advance to step k at height h_agl_m above the terrain and true airspeed v_true_mps; NED m/s.

        Yeager 1998 eqs. 30-32: xi_u' = (1 - T/tau_u) xi_u + sigma_u sqrt(2T/tau_u) nu_u, and the v, w
        channels with 2T/tau, sqrt(4T/tau); tau = L / V. The coefficients are re-evaluated every
        COEFF_EVERY steps (0.1 s at 120 Hz: the height changes by well under a metre in between).
        """
        if k % COEFF_EVERY == 0 or self._coef is None:
            L_u, L_w, sig_u, sig_w = scales(h_agl_m / units.FT, self.w20_fps, self.index)
            V = max(v_true_mps / units.FPS, 1.0)
            T = self.dt
            tu = L_u / V
            tw = L_w / V
            self._coef = (1.0 - T / tu, sig_u * math.sqrt(2.0 * T / tu), 1.0 - 2.0 * T / tu,
                          sig_u * math.sqrt(4.0 * T / tu), 1.0 - 2.0 * T / tw, sig_w * math.sqrt(4.0 * T / tw))
        au, bu, av, bv, aw, bw = self._coef
        nu_u, nu_v, nu_w = self.nu[k].tolist()
        xu = self.xi_u = au * self.xi_u + bu * nu_u
        xv = self.xi_v = av * self.xi_v + bv * nu_v
        xw = self.xi_w = aw * self.xi_w + bw * nu_w
        c, s = self.cos_fps, self.sin_fps
        # rotate from wind axes (u along the direction the wind blows to, v to its right) to NED
        return c * xu - s * xv, s * xu + c * xv, xw * units.FPS

    def state(self) -> tuple[float, ...]:
        """(xi_u, xi_v, xi_w, coefficients valid, a_u, b_u, a_v, b_v, a_w, b_w): the compiled turbulence's TBS_*
        state vector (core/loop/flight_step.py dryden_step)."""
        coef = self._coef if self._coef is not None else (0.0,) * 6
        return (self.xi_u, self.xi_v, self.xi_w, float(self._coef is not None), *coef)
