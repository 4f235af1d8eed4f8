"""The ILS glide path as a straight cone: the one geometric reference of the approach.

An ILS glide path is the cone of constant elevation angle seen from the glide path antenna: apex at the glide
path intercept point (GPI) on the runway centreline, axis the local vertical there, half-angle 90 deg minus the
glide path angle (ICAO Annex 10 Vol. I 3.1.5: the glide path is "that locus of points in the vertical plane
containing the runway centre line at which the DDM is zero ... the straight line"; the reference datum is the
threshold crossing height, TCH). Geometry of this module:

    x_gpi = TCH / tan(gp)                                  GPI, m past the threshold (on the centreline)
    h_cone(x, y) = tan(gp) sqrt((x_gpi - x)^2 + y^2)       cone height above the GPI's horizontal plane, m
    drop(x, y)   = n^2 / (2 R_N) + e^2 / (2 R_E)           the ellipsoid below that plane at the point, m
                   (n, e) = the point's north and east offsets from the GPI, R_N, R_E the radii at the threshold
    z_cone(x, y) = h_cone(x, y) + drop(x, y)               the cone in the runway frame's height coordinate z
    d = z - z_cone(x, y)                                   glidepath deviation, m (+ above the cone)

x, y are runway-frame coordinates (the threshold's tangent plane, x along the landing direction, y right) and z
the height above the threshold's ellipsoid height, which decision heights are measured in (geo.RunwayFrame).
Before this module the glidepath was z = TCH - x tan(gp): a path parallel to the ellipsoid, which curves down
with the Earth, d^2 / (2 R) below the straight line (2.6 m = 8.6 ft at 1000 ft above the threshold on 3 deg).

Accuracy of the second-order drop (tests/unit/test_glidepath.py against the exact ECEF projection on the GPI's
vertical): below 5 mm out to 20 km and 3000 ft; the neglected terms are of order d^3 e^2 / R^2 and z d^2 / R^2.
The lateral term of the cone (y^2 tan(gp) / (2 r) at range r) is 0.2 mm for 30 m off the centreline at 2 km.

Past the GPI (x > x_gpi, only the flare is there) the cone rises again; `z_cone` continues the straight line
instead (the sign of x_gpi - x is kept), so the deviation stays continuous through the GPI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from approachsim import geo

Array = NDArray[np.float64]


@dataclass(frozen=True)
class GlidePath:
    """A straight ILS glide path cone: angle, TCH and the runway's heading and threshold latitude (for the Earth's
    curvature under it). Build it with `GlidePath.of(runway)` from a profile.Runway."""

    glidepath_rad: float
    tch_m: float
    heading_rad: float
    threshold_lat_rad: float

    @classmethod
    def of(cls, runway: object) -> GlidePath:
        """The glide path of a profile.Runway (.glidepath_rad, .tch_m, .heading_rad, .threshold_lat_rad)."""
        return cls(float(runway.glidepath_rad), float(runway.tch_m), float(runway.heading_rad),  # type: ignore[attr-defined]
                   float(runway.threshold_lat_rad))  # type: ignore[attr-defined]

    @property
    def tan_gp(self) -> float:
        """tan(glide path angle)."""
        return math.tan(self.glidepath_rad)

    @property
    def gpi_m(self) -> float:
        """Glide path intercept point, m past the threshold: TCH / tan(gp)."""
        return self.tch_m / self.tan_gp

    @property
    def curvature(self) -> tuple[float, float, float]:
        """(a, b, c) of drop = a dx^2 + b dx dy + c dy^2 (1/m) in runway axes from the GPI: the ellipsoid's normal
        curvature, n^2 / (2 R_N) + e^2 / (2 R_E) with n = dx cos h - dy sin h, e = dx sin h + dy cos h."""
        r_n, r_e = geo.radii(self.threshold_lat_rad)
        kn, ke = 0.5 / float(r_n), 0.5 / float(r_e)
        ch, sh = math.cos(self.heading_rad), math.sin(self.heading_rad)
        return kn * ch * ch + ke * sh * sh, 2.0 * (ke - kn) * ch * sh, kn * sh * sh + ke * ch * ch

    def constants(self) -> tuple[float, float, float, float, float]:
        """(tan gp, x_gpi, a, b, c): what the compiled kernels need (cone_deviation)."""
        a, b, c = self.curvature
        return self.tan_gp, self.gpi_m, a, b, c

    def height_m(self, along_m: ArrayLike, cross_m: ArrayLike = 0.0) -> Array:
        """z_cone: the cone's height in the runway frame's z (m above the threshold's ellipsoid height) at
        runway-frame x = along_m, y = cross_m (m)."""
        t, xg, a, b, c = self.constants()
        return cone_height(np.asarray(along_m, dtype=float), np.asarray(cross_m, dtype=float), t, xg, a, b, c)

    def deviation_m(self, along_m: ArrayLike, cross_m: ArrayLike, height_m: ArrayLike) -> Array:
        """Glidepath deviation (m, + above the cone) of runway-frame points (x, y, z)."""
        return np.asarray(height_m, dtype=float) - self.height_m(along_m, cross_m)

    def deviation_rwy_m(self, r_rwy: ArrayLike) -> Array:
        """deviation_m of runway-frame points (..., 3)."""
        r = np.asarray(r_rwy, dtype=float)
        return self.deviation_m(r[..., 0], r[..., 1], r[..., 2])


def cone_height(x: Array, y: Array, tan_gp: float, x_gpi: float, a: float, b: float, c: float) -> Array:
    """z_cone (module docstring) from the constants of GlidePath.constants(); numpy (the compiled kernels write
    the same expression in scalars)."""
    dx = x - x_gpi
    r = np.sign(-dx) * np.hypot(dx, y)
    r = np.where(dx == 0.0, np.abs(y), r)
    return tan_gp * r + (a * dx * dx + b * dx * y + c * y * y)


def deviation_and_rate(x: float, y: float, z: float, x_dot: float, y_dot: float, z_dot: float, tan_gp: float,
                       x_gpi: float, a: float, b: float, c: float) -> tuple[float, float]:
    """Glidepath deviation from the cone (m, + above) and its rate (m/s) of one runway-frame point (x, y, z) moving
    at (x', y', z'), constants as GlidePath.constants(): the scalar form the autopilot and the stabilized-approach
    monitor use (core/loop/flight_step.cone_deviation compiles these lines). Past the GPI the straight line goes on."""
    dx = x - x_gpi
    rr = math.sqrt(dx * dx + y * y)
    s = 1.0 if dx <= 0.0 else -1.0
    d = z - (s * tan_gp * rr + a * dx * dx + b * dx * y + c * y * y)
    if rr > 0.0:
        drx, dry = s * tan_gp * dx / rr, s * tan_gp * y / rr
    else:
        drx, dry = -tan_gp, 0.0
    d_dot = z_dot - (drx + 2.0 * a * dx + b * y) * x_dot - (dry + b * dx + 2.0 * c * y) * y_dot
    return d, d_dot
