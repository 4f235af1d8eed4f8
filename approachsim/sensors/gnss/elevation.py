"""How the per-satellite range errors scale with elevation: the thin-shell ionospheric obliquity, the DO-229
tropospheric mapping and the DO-253 airframe multipath curve (receiver.py's module docstring gives the sources).

The stand-alone receiver (receiver.py) and the GBAS residuals (gbas.py) both scale their terms with them, so they
live here, below both.
"""

from __future__ import annotations

import numpy as np

from approachsim import geo
from approachsim.core.sensors.gnss_errors import IONO_SHELL_M

Array = np.ndarray

__all__ = ["IONO_SHELL_M", "do253_multipath_sigma_m", "iono_obliquity", "tropo_mapping"]


def iono_obliquity(el_rad: Array) -> Array:
    """Thin-shell ionospheric obliquity factor 1 / sqrt(1 - (R cos el / (R + h_I))^2)."""
    x = geo.A_WGS84 * np.cos(el_rad) / (geo.A_WGS84 + IONO_SHELL_M)
    return 1.0 / np.sqrt(1.0 - x * x)


def tropo_mapping(el_rad: Array) -> Array:
    """Tropospheric mapping 1.001 / sqrt(0.002001 + sin^2 el) (RTCA DO-229 A.4.2.4)."""
    return 1.001 / np.sqrt(0.002001 + np.sin(el_rad) ** 2)


def do253_multipath_sigma_m(el_rad: Array) -> Array:
    """Airframe multipath 1-sigma (m): 0.13 + 0.53 exp(-el / 10 deg) (RTCA DO-253 / DO-229; MAAST init_cnmp_mops)."""
    return 0.13 + 0.53 * np.exp(-np.degrees(np.asarray(el_rad, dtype=float)) / 10.0)
