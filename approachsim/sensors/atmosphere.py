"""The ISA troposphere used by the barometric altimeter (and by the synthetic test truth).

Two directions of one model (standards.md 4.1; ICAO Doc 7488 / US Standard Atmosphere 1976, troposphere):

* the *real* atmosphere of the day: sea-level pressure p_sl and a constant temperature deviation dT from ISA,
  hydrostatic with the standard lapse rate, T(H) = T0 + dT - L H, so
  p(H) = p_sl (1 - L H / (T0 + dT)) ^ (g0 / (R L));
* what an altimeter *indicates* for a static pressure p with a setting (QNH) p_set: the ISA inverse,
  h_ind = (T0 / L) (1 - (p / p_set) ^ (R L / g0)).

H is geopotential height above mean sea level (this simulator has no geoid: MSL = ellipsoid, profile.py).
QNH is the setting with which the altimeter reads the field elevation H_f at the field on any day, so the
day's sea-level pressure is the one whose ISA+dT atmosphere has QNH's ISA pressure at H_f,
p_sl = QNH ((1 - L H_f / T0) / (1 - L H_f / (T0 + dT))) ^ (g0 / (R L)) (sea_level_pressure_pa); the
temperature error then grows with the height above the field (cold-is-low), zero at the field.
On a standard day (dT = 0, p_set = p_sl) the indication is exactly H. In a cold atmosphere the indication is
H T0 / (T0 + dT): the cold-is-low error that the PANS-OPS 4 %-per-10-C rule approximates. A setting error
dp gives dh = R T / (g0 p) dp = 8.32 m (27.3 ft) per hPa at sea level.

Temperature correction with the aerodrome temperature (the air data's or the FMS's compensation of the indication,
the exact form of the ICAO Doc 8168 cold-temperature correction for this troposphere): in ISA+dT the indicated height
above the field and the true one are in the ratio of the field's ISA temperature to its real one,
H - H_f = (h_ind - H_f) T_f / (T0 - L H_f), T_f = T0 + dT - L H_f (both lapse at L, so the ratio is exact here; a
real day's lapse rate differs). T_f is the reported aerodrome temperature, a METAR's whole degree Celsius.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

T0_K = 288.15
"""ISA sea-level temperature, K."""
P0_PA = 101325.0
"""ISA sea-level pressure, Pa."""
LAPSE_K_PER_M = 0.0065
"""ISA tropospheric lapse rate, K/m."""
G0 = 9.80665
"""Standard gravity, m/s^2 (the constant of geopotential height)."""
R_AIR = 287.05287
"""Specific gas constant of dry air, J/(kg K) (US Std Atm 1976: R* / M)."""
R_EARTH_GEOPOT_M = 6356766.0
"""Earth radius of the US Standard Atmosphere 1976 geopotential conversion, m."""
EXPONENT = G0 / (R_AIR * LAPSE_K_PER_M)
"""g0 / (R L) = 5.25588 (dimensionless)."""


def geopotential_m(z_m: ArrayLike) -> np.ndarray:
    """Geopotential height H = r0 z / (r0 + z) (m) of geometric height z (m) above MSL (US Std Atm 1976)."""
    z = np.asarray(z_m, dtype=float)
    return R_EARTH_GEOPOT_M * z / (R_EARTH_GEOPOT_M + z)


def static_pressure_pa(h_geopot_m: ArrayLike, isa_dev_k: float = 0.0, sea_level_pa: float = P0_PA) -> np.ndarray:
    """Static pressure (Pa) at geopotential height H (m) in an ISA+dT troposphere with sea-level pressure p_sl."""
    h = np.asarray(h_geopot_m, dtype=float)
    return sea_level_pa * (1.0 - LAPSE_K_PER_M * h / (T0_K + isa_dev_k)) ** EXPONENT


def sea_level_pressure_pa(qnh_pa: float, field_geopot_m: float, isa_dev_k: float = 0.0) -> float:
    """The day's true sea-level pressure (Pa) of an ISA+dT troposphere in which an altimeter set to QNH (Pa)
    reads the field's geopotential elevation (m) at the field (module docstring)."""
    p_field = qnh_pa * (1.0 - LAPSE_K_PER_M * field_geopot_m / T0_K) ** EXPONENT
    return float(p_field / (1.0 - LAPSE_K_PER_M * field_geopot_m / (T0_K + isa_dev_k)) ** EXPONENT)


def air_temperature_k(h_geopot_m: ArrayLike, isa_dev_k: float = 0.0) -> np.ndarray:
    """Static air temperature (K) at geopotential height H (m): T0 + dT - L H."""
    return T0_K + isa_dev_k - LAPSE_K_PER_M * np.asarray(h_geopot_m, dtype=float)


def indicated_altitude_m(p_static_pa: ArrayLike, setting_pa: float = P0_PA) -> np.ndarray:
    """Altimeter indication (m) for static pressure p (Pa) and altimeter setting (QNH, Pa): the ISA inverse."""
    p = np.asarray(p_static_pa, dtype=float)
    return T0_K / LAPSE_K_PER_M * (1.0 - (p / setting_pa) ** (1.0 / EXPONENT))


def reported_aerodrome_temperature_k(field_geopot_m: float, isa_dev_k: float = 0.0) -> float:
    """The aerodrome temperature a METAR reports (K): T0 + dT - L H_f rounded to a whole degree Celsius."""
    return float(np.round(air_temperature_k(field_geopot_m, isa_dev_k) - 273.15)) + 273.15


def temperature_correction_ratio(field_geopot_m: float, aerodrome_temperature_k: float) -> float:
    """T_f / (T0 - L H_f): true height above the field per indicated height above it (module docstring)."""
    return float(aerodrome_temperature_k / (T0_K - LAPSE_K_PER_M * field_geopot_m))
