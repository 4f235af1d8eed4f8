"""The filter's terrain-database error: the database differs from the truth terrain by a per-run bias and an
along-track Gauss-Markov error, with the accuracy of the ICAO terrain data areas.

    T_db(x) = T(x) + b + sigma(x) u(x),   b ~ N(0, bias_sigma^2) per run,
    u(x) unit first-order Gauss-Markov in along-track distance x (runway frame, m): E[u(x) u(x + d)] = exp(-|d| / L)

Magnitudes: ICAO Annex 15 (Appendix 8, Table A8-1, terrain data numerical requirements) gives the vertical
accuracy of terrain data at 90 % confidence: Area 4 (the radio-altimeter operating area of CAT II / III runways,
900 m before the threshold, 60 m either side of the centre line: Annex 15 10.2.4) 1 m, Area 2 (the terminal
area) 3 m. A 90 % two-sided normal bound is 1.645 sigma, so the total 1-sigma is 1 / 1.645 = 0.608 m in Area 4
and 3 / 1.645 = 1.824 m in Area 2. (The areas are verified in Annex 15's text; the 1 m / 3 m at 90 % are quoted
from Table A8-1 as commonly reproduced, not read in the table itself.) No source gives the split between a
datum-wide offset and the point-to-point error, so the Area 4 variance is split equally: bias 0.430 m (common to
both areas: one vertical reference), Area 4 correlated 0.430 m; Area 2 correlated sqrt(1.824^2 - 0.430^2) =
1.772 m. Beyond the threshold (runway, Area 3: 0.5 m at 90 %) the Area 4 figure is kept (conservative).

Correlation length L = 300 m (argued, not sourced): DEM errors are correlated over several ranges at once, from
a few grid spacings up to kilometres (Hugonnet et al., "Uncertainty analysis of digital elevation models by
spatial inference from stable terrain", 2022). We keep one short range, ten Area 2 post spacings (1 arc second,
about 30 m) = 300 m, and let the bias stand for the long-range part. It is a third of Area 4's length, so the
database error near the threshold is not averaged away over the last 900 m.

The realization is tabulated on a fixed along-track grid (GRID_X_M, spacing min(5 m, L / 20), exact
discretization exp(-dx / L)) and interpolated linearly; it is held constant outside the grid. Drawn per run from
its own stream (NavSystem: seeding.substream(nav stream, "terrain_db")): bias first, then the grid normals.
All keys zero: no error, the database is the truth terrain exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from approachsim.config import Section
from approachsim.sensors import base

Array = np.ndarray

Z90 = 1.6448536269514722
"""Two-sided 90 % point of the standard normal: 1-sigma = (90 % figure) / Z90."""
AREA4_SIGMA_M = 1.0 / Z90
AREA2_SIGMA_M = 3.0 / Z90
BIAS_SIGMA_M = AREA4_SIGMA_M / math.sqrt(2.0)
GRID_X_M = (-120_000.0, 10_000.0)
"""Along-track extent (m, runway frame) of the tabulated realization; constant beyond."""


@dataclass(frozen=True)
class TerrainDbConfig:
    """[nav.terrain_database]: the database error model (m; module docstring gives the sources)."""

    bias_sigma_m: float = BIAS_SIGMA_M
    sigma_m: float = BIAS_SIGMA_M
    """Along-track correlated 1-sigma within area4_length_m of the threshold (and past it), m."""
    outer_sigma_m: float = math.sqrt(AREA2_SIGMA_M**2 - BIAS_SIGMA_M**2)
    """The same farther out (Area 2), m."""
    area4_length_m: float = 900.0
    correlation_m: float = 300.0

    @property
    def correlated(self) -> bool:
        """Whether there is an along-track correlated error (the filter carries its state)."""
        return self.sigma_m > 0.0 or self.outer_sigma_m > 0.0

    @property
    def zero(self) -> bool:
        """No database error at all."""
        return self.bias_sigma_m == 0.0 and not self.correlated

    def sigma_at(self, along_m: Array | float) -> Array:
        """1-sigma of the correlated error (m) at runway-frame along-track x (m)."""
        x = np.asarray(along_m, dtype=float)
        return np.where(x >= -self.area4_length_m, self.sigma_m, self.outer_sigma_m)

    def grid(self) -> Array:
        """The along-track grid (m) of the realization."""
        dx = min(5.0, self.correlation_m / 20.0)
        n = int(math.ceil((GRID_X_M[1] - GRID_X_M[0]) / dx)) + 1
        return GRID_X_M[0] + dx * np.arange(n)


EXACT = TerrainDbConfig(bias_sigma_m=0.0, sigma_m=0.0, outer_sigma_m=0.0)
"""No database error: the filter's database is the truth terrain (the model before the realism defaults)."""


@dataclass(frozen=True)
class TerrainDbError:
    """One run's database error: T_db - T (m) as a function of along-track x (m)."""

    config: TerrainDbConfig
    bias_m: float
    x_m: Array
    u: Array
    """(k,) the unit Gauss-Markov at x_m."""

    def __call__(self, along_m: Array) -> Array:
        x = np.asarray(along_m, dtype=float)
        return self.bias_m + self.config.sigma_at(x) * np.interp(x, self.x_m, self.u)


def draw(config: TerrainDbConfig, rng: np.random.Generator) -> TerrainDbError | None:
    """A realization from rng (bias first, then the grid's normals); None when the model is zero."""
    if config.zero:
        return None
    bias = config.bias_sigma_m * float(rng.standard_normal())
    x = config.grid()
    u = base.gauss_markov(rng.standard_normal(x.shape[0]), 1.0, config.correlation_m, float(x[1] - x[0]))
    if not config.correlated:
        u = np.zeros_like(u)
    return TerrainDbError(config, bias, x, u)


def parse(s: Section) -> TerrainDbConfig:
    """Parse [nav.terrain_database]; absent keys take the defaults."""
    d = TerrainDbConfig()
    cfg = TerrainDbConfig(
        bias_sigma_m=s.number("bias_sigma_m", d.bias_sigma_m, lo=0.0, hi=1000.0, unit="m"),
        sigma_m=s.number("sigma_m", d.sigma_m, lo=0.0, hi=1000.0, unit="m"),
        outer_sigma_m=s.number("outer_sigma_m", d.outer_sigma_m, lo=0.0, hi=1000.0, unit="m"),
        area4_length_m=s.number("area4_length_m", d.area4_length_m, lo=0.0, hi=100_000.0, unit="m"),
        correlation_m=s.number("correlation_m", d.correlation_m, lo=1.0, hi=1e6, unit="m"),
    )
    s.done()
    return cfg
