"""Unit conversions: the one place where feet, knots, nautical miles, degrees and hPa meet SI.

Everything inside the library is SI (m, s, rad, Pa, K). Convert at the edges only, with these constants.
"""

FT = 0.3048
"""Metres per foot (exact)."""
IN = 0.0254
"""Metres per inch (exact; JSBSim's structural-frame lengths)."""
NMI = 1852.0
"""Metres per nautical mile (exact)."""
KT = NMI / 3600.0
"""Metres per second per knot (exact)."""
FPS = FT
"""Metres per second per foot per second."""
HPA = 100.0
"""Pascals per hectopascal."""
PSF = 47.88025898033584
"""Pascals per pound-force per square foot."""
LBF = 4.4482216152605
"""Newtons per pound-force."""
SLUG = 14.593902937206364
"""Kilograms per slug."""
G0 = 9.80665
"""Standard gravity, m/s^2 (exact)."""
NMI_PER_H = NMI / 3600.0
"""Metres per second per (nautical mile per hour): INS drift rates are quoted in nmi/h CEP."""


def rankine_to_kelvin(t_r: float) -> float:
    """Temperature in Rankine to kelvin."""
    return t_r * 5.0 / 9.0


def c_to_k(t_c: float) -> float:
    """Temperature in degrees Celsius to kelvin."""
    return t_c + 273.15
