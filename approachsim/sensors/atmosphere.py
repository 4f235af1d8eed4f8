"""The ISA troposphere used by the barometric altimeter (and by the synthetic test truth).

Two directions of one model (standards.md 4.1; ICAO Doc 7488 / US Standard Atmosphere 1976, troposphere):

* the *real* atmosphere of the day: sea-level pressure p_sl and a constant temperature deviation dT from ISA,
  hydrostatic with the standard lapse rate, T(H) = T0 + dT - L H, so
  p(H) = p_sl (1 - L H / (T0 + dT)) ^ (g0 / (R L));
* what an altimeter *indicates* for a static pressure p with a setting (QNH) p_set: the ISA inverse,
  h_ind = (T0 / L) (1 - (p / p_set) ^ (R L / g0)).

H is geopotential height above mean sea level (this simulator has no geoid: MSL = ellipsoid, profile.py).
QNH is the setting with which the altimeter reads the published field elevation z_f (a geometric height above
MSL) at the field on any day, so the field's pressure is QNH's ISA pressure at the number z_f,
p_f = QNH (1 - L z_f / T0)^(g0 / (R L)) (field_pressure_pa), and the day's sea-level pressure is the one whose
ISA+dT atmosphere has p_f at the field's geopotential height H_f = r0 z_f / (r0 + z_f),
p_sl = p_f / (1 - L H_f / (T0 + dT)) ^ (g0 / (R L)) (sea_level_pressure_pa); the temperature error then grows
with the height above the field (cold-is-low), zero at the field. The indication is an ISA (geopotential) number
read as a geometric height: above the field it reads the geopotential height difference, short of the geometric
one by about 2 z_f / r0 of it (5e-4 at a 1656 m field, 0.15 m at 1000 ft above it; issue 39).
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


def sea_level_pressure_pa(qnh_pa: float, field_geopot_m: float, isa_dev_k: float = 0.0,
                          field_elevation_m: float | None = None) -> float:
    """The day's true sea-level pressure (Pa) of an ISA+dT troposphere in which an altimeter set to QNH (Pa)
    reads `field_elevation_m` (the published, geometric elevation; default: the geopotential one) at the field,
    whose geopotential height is field_geopot_m (module docstring)."""
    z_f = field_geopot_m if field_elevation_m is None else field_elevation_m
    p_field = field_pressure_pa(qnh_pa, z_f)
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


def field_pressure_pa(qnh_pa: float, field_elevation_m: float) -> float:
    """The day's static pressure at the field (Pa): QNH is the setting with which the altimeter, an ISA-inverse
    instrument, reads the published field elevation (geometric height above MSL, m) at the field
    (p_f = QNH (1 - L z_f / T0)^(g0 / (R L))); the real atmosphere holds it at the field's geopotential height."""
    return float(qnh_pa * (1.0 - LAPSE_K_PER_M * field_elevation_m / T0_K) ** EXPONENT)


def height_per_hpa_m(field_elevation_m: float) -> float:
    """dh/dp of the indication at the field (m per hPa): R T_std / (g0 p_std) at the ISA height z_f (8.32 m at sea
    level, 9.7 m at 1656 m; standards.md 4.1): what a QNH error of 1 hPa puts on the baro near the field."""
    t = T0_K - LAPSE_K_PER_M * field_elevation_m
    p = P0_PA * (t / T0_K) ** EXPONENT
    return float(R_AIR * t / (G0 * p) * 100.0)


def inversion_log_ratio(p_pa: ArrayLike, p_field_pa: float, t_field_k: float, inversion_k: float,
                        depth_m: float) -> np.ndarray:
    """ln(p_real / p) (dimensionless) of a surface layer that departs from the day's constant-dT atmosphere.

    p: static pressure (Pa) of the constant-dT atmosphere (JSBSim's), whose field pressure is p_f and field
    temperature T_f (K). The real layer keeps p_f at the field and is `inversion_k` colder there, the departure
    decreasing linearly to 0 at `depth_m` above the field (a surface-based inversion: the layer's lapse rate is
    L' = L - dT_inv / D; dT_inv < 0 a superadiabatic-warm surface layer). Geopotential height above the field from p,
    u = (T_f / L)(1 - (p / p_f)^(R L / g0)), and hydrostatics in both atmospheres:

        ln(p_real / p) = -(g0 / R) (int_0^u' dH / T_real - int_0^u' dH / T_jsb),  u' = min(max(u, 0), D)
        int_0^u' dH / T_jsb  = ln(T_f / (T_f - L u')) / L
        int_0^u' dH / T_real = ln(T_r / (T_r - L' u')) / L',  T_r = T_f - dT_inv  (u' / T_r when L' = 0)

    constant above the layer (the same temperature there: both pressures fall alike). 0 below the field."""
    p = np.asarray(p_pa, dtype=float)
    if inversion_k == 0.0 or depth_m <= 0.0:
        return np.zeros(p.shape)
    u = t_field_k / LAPSE_K_PER_M * (1.0 - (p / p_field_pa) ** (1.0 / EXPONENT))
    u = np.clip(u, 0.0, depth_m)
    l_real = LAPSE_K_PER_M - inversion_k / depth_m
    t_r = t_field_k - inversion_k
    i_jsb = np.log(t_field_k / (t_field_k - LAPSE_K_PER_M * u)) / LAPSE_K_PER_M
    if abs(l_real) < 1e-12:
        i_real = u / t_r
    else:
        i_real = np.log(t_r / (t_r - l_real * u)) / l_real
    return -(G0 / R_AIR) * (i_real - i_jsb)
